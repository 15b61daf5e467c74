/* geo_orient.c — see geo_orient.h. */
#include "geo/geo_orient.h"
#include "geo/geo_tri.h"

#include <stdlib.h>
#include <string.h>

/* ∇h on a face with corners p and c = (p1 − p0) × (p2 − p0):
 * ∇h = Σ_k h_k (c × e_k) / |c|², e_k = p_{k+2} − p_{k+1} the edge opposite
 * corner k. */
static void face_gradient(const double *const p[3], const double c[3], double c2,
                          const double h[3], double out[3])
{
    memset(out, 0, 3 * sizeof(double));
    for (int k = 0; k < 3; k++) {
        double e[3], r[3];
        geo__sub(p[(k + 2) % 3], p[(k + 1) % 3], e);
        geo__cross(c, e, r);
        for (int d = 0; d < 3; d++)
            out[d] += h[k] * r[d] / c2;
    }
}

int geo_gradient_sine(const mesh *m, const double *f, int fs, const double *g, int gs,
                      double *o)
{
    double *w = calloc((size_t)m->nv + 1, sizeof(double));
    if (!w)
        return -1;
    memset(o, 0, sizeof(double) * (size_t)m->nv);
    for (int t = 0; t < m->nf; t++) {
        const double *p[3];
        double c[3];
        if (geo__face_cross(m, t, c))
            continue;
        geo__corners(m, t, p);
        const int *fv = m->f + 3 * (size_t)t;
        double c2 = geo__dot(c, c), a = 0.5 * sqrt(c2);
        double hf[3], hg[3], gf[3], gg[3], x[3];
        for (int k = 0; k < 3; k++) {
            hf[k] = f[(size_t)fv[k] * (size_t)fs];
            hg[k] = g[(size_t)fv[k] * (size_t)gs];
            w[fv[k]] += a;
        }
        face_gradient(p, c, c2, hf, gf);
        face_gradient(p, c, c2, hg, gg);
        double nf = sqrt(geo__dot(gf, gf)), ng = sqrt(geo__dot(gg, gg));
        if (!(nf > 0) || !(ng > 0))
            continue;
        geo__cross(gf, gg, x);
        double s = geo__dot(x, c) / (sqrt(c2) * nf * ng);
        for (int k = 0; k < 3; k++)
            o[fv[k]] += a * s;
    }
    for (int v = 0; v < m->nv; v++)
        if (w[v] > 0)
            o[v] /= w[v];
    free(w);
    return 0;
}
