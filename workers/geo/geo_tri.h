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

#endif
