/* geo_tri.h — internal (geo__) inline helpers for one triangle: edge
 * vectors, cross product, and the one rule for "degenerate" that every geo_
 * file shares. Header-only on purpose: these are a few flops each and are
 * called per face in inner loops. Not part of the public geo_ API. */
#ifndef GEO_TRI_H
#define GEO_TRI_H
#include "mesh/mesh.h"

#include <math.h>

/* A face is degenerate when |e1 x e2| <= GEO__DEGENERATE_REL * (|e1|^2 + |e2|^2),
 * i.e. its sine of the corner angle is at round-off level (collinear or
 * repeated corners). Such faces get a zero normal and no cotangent weight. */
#define GEO__DEGENERATE_REL 1e-13

static inline void geo__sub(const double *a, const double *b, double *out)
{
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}

static inline double geo__dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void geo__cross(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Corner positions of face t. */
static inline void geo__corners(const mesh *m, int t, const double **p)
{
    for (int k = 0; k < 3; k++)
        p[k] = m->v + 3 * (size_t)m->f[3 * (size_t)t + k];
}

/* (p1 - p0) x (p2 - p0) of face t: twice the area times the unit normal
 * (right-hand rule on the corner order). Returns 1 when the face is
 * degenerate by the rule above. */
static inline int geo__face_cross(const mesh *m, int t, double *c)
{
    const double *p[3];
    double e1[3], e2[3];
    geo__corners(m, t, p);
    geo__sub(p[1], p[0], e1);
    geo__sub(p[2], p[0], e2);
    geo__cross(e1, e2, c);
    double n = sqrt(geo__dot(c, c));
    return !(n > GEO__DEGENERATE_REL * (geo__dot(e1, e1) + geo__dot(e2, e2)));
}

/* The gradients of face t's three hat functions, grad phi_c =
 * n x (p_{c+2} - p_{c+1}) / (2 area), from its cross product cr
 * (geo__face_cross, not degenerate); n gets the unit normal. Returns |cr|,
 * twice the area. */
static inline double geo__hat_gradients(const mesh *m, int t, const double *cr, double *n,
                                        double g[3][3])
{
    const double *p[3];
    geo__corners(m, t, p);
    double a2 = sqrt(geo__dot(cr, cr));
    for (int q = 0; q < 3; q++)
        n[q] = cr[q] / a2;
    for (int c = 0; c < 3; c++) {
        double e[3];
        geo__sub(p[(c + 2) % 3], p[(c + 1) % 3], e);
        geo__cross(n, e, g[c]);
        for (int q = 0; q < 3; q++)
            g[c][q] /= a2;
    }
    return a2;
}

#endif
