/* ener_bending.c — the bending term (cos θ̂ − cos θ)²·w of one interior edge
 * and its gradient w.r.t. the 12 coordinates of i, j, k, l (ener_def.h
 * states the model). Pure arithmetic on one element: no allocation, no mesh
 * access.
 *
 * c1 = (yj − yi) × (yk − yi), c2 = (yi − yj) × (yl − yj), n = c/|c|,
 * cos θ = ⟨n1, n2⟩. The derivative of a normalised vector gives
 *   ∂cos/∂c1 = (n2 − cos·n1)/|c1| =: v1,  ∂cos/∂c2 = (n1 − cos·n2)/|c2| =: v2,
 * and for c = a × b, ⟨c, v⟩ = ⟨a, b × v⟩ = ⟨b, v × a⟩, so
 *   ∂/∂a = b × v, ∂/∂b = v × a.
 * A face whose cross product is (numerically) zero has no normal: the term
 * is then 0 with a zero gradient. Callers exclude such edges beforehand
 * (ener_def_update_admissible); this only keeps the kernel finite. */
#include "ener/ener_def.h"

#include <math.h>

/* sin² of a face angle below which the face counts as having no normal. */
#define ENER_BENDING_SIN2_MIN 1e-30

static inline void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

double ener_bending_edge(double cos_ref, double weight,
                         const double *yi, const double *yj,
                         const double *yk, const double *yl, double g[12])
{
    const double a1[3] = {yj[0] - yi[0], yj[1] - yi[1], yj[2] - yi[2]};
    const double b1[3] = {yk[0] - yi[0], yk[1] - yi[1], yk[2] - yi[2]};
    const double a2[3] = {-a1[0], -a1[1], -a1[2]};
    const double b2[3] = {yl[0] - yj[0], yl[1] - yj[1], yl[2] - yj[2]};
    double c1[3], c2[3];
    cross(a1, b1, c1);
    cross(a2, b2, c2);
    const double s1 = dot(c1, c1), s2 = dot(c2, c2), aa = dot(a1, a1);
    if (!(s1 > ENER_BENDING_SIN2_MIN * aa * dot(b1, b1)) ||
        !(s2 > ENER_BENDING_SIN2_MIN * aa * dot(b2, b2))) {
        if (g)
            for (int k = 0; k < 12; k++)
                g[k] = 0.0;
        return 0.0;
    }
    const double r1 = 1.0 / sqrt(s1), r2 = 1.0 / sqrt(s2);
    const double n1[3] = {c1[0] * r1, c1[1] * r1, c1[2] * r1};
    const double n2[3] = {c2[0] * r2, c2[1] * r2, c2[2] * r2};
    const double cs = dot(n1, n2);
    const double diff = cos_ref - cs;
    if (g) {
        const double f = -2.0 * weight * diff;     /* ∂E/∂cos */
        const double f1 = f * r1, f2 = f * r2;
        const double v1[3] = {f1 * (n2[0] - cs * n1[0]), f1 * (n2[1] - cs * n1[1]),
                              f1 * (n2[2] - cs * n1[2])};
        const double v2[3] = {f2 * (n1[0] - cs * n2[0]), f2 * (n1[1] - cs * n2[1]),
                              f2 * (n1[2] - cs * n2[2])};
        double gj1[3], gk[3], gi2[3], gl[3];
        cross(b1, v1, gj1);   /* ∂/∂a1: face 1's a1 = yj − yi */
        cross(v1, a1, gk);    /* ∂/∂b1 = ∂/∂yk */
        cross(b2, v2, gi2);   /* ∂/∂a2: face 2's a2 = yi − yj */
        cross(v2, a2, gl);    /* ∂/∂b2 = ∂/∂yl */
        for (int k = 0; k < 3; k++) {
            g[k] = -gj1[k] - gk[k] + gi2[k];
            g[3 + k] = gj1[k] - gi2[k] - gl[k];
            g[6 + k] = gk[k];
            g[9 + k] = gl[k];
        }
    }
    return weight * diff * diff;
}
