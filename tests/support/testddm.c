/* testddm.c — the brute-force projection DDM is checked against; see
 * testddm.h. */
#include "support/testddm.h"

#include "support/harness.h"
#include "lmk/lmk.h"
#include "metric/metric.h"

#include <math.h>
#include <stdlib.h>

/* |x - b|^2 for x = (1 - s - t) a0 + s a1 + t a2 in R^k. */
double testddm_dist2(const double *a0, const double *a1, const double *a2, double s, double t,
                     const double *b, int k)
{
    double d = 0;
    for (int j = 0; j < k; j++) {
        double x = (1 - s - t) * a0[j] + s * a1[j] + t * a2[j] - b[j];
        d += x * x;
    }
    return d;
}

/* Brute force: the least |x - b|^2 over every point x of every face, each
 * face by all candidates of the convex problem: the interior stationary
 * point if inside, the projection onto each edge line clamped to the edge,
 * and the corners. */
double testddm_brute_force(const double *A, int k, const mesh *T, const double *b)
{
    double best = INFINITY;
    for (int f = 0; f < T->nf; f++) {
        const double *c[3] = {A + (size_t)T->f[3 * f] * k, A + (size_t)T->f[3 * f + 1] * k,
                              A + (size_t)T->f[3 * f + 2] * k};
        for (int q = 0; q < 3; q++)
            best = fmin(best, testddm_dist2(c[q], c[q], c[q], 0, 0, b, k));
        for (int q = 0; q < 3; q++) {   /* edge c[q] -> c[q+1] */
            const double *p = c[q], *r = c[(q + 1) % 3];
            double num = 0, den = 0;
            for (int j = 0; j < k; j++) {
                num += (b[j] - p[j]) * (r[j] - p[j]);
                den += (r[j] - p[j]) * (r[j] - p[j]);
            }
            double u = den > 0 ? num / den : 0;
            u = u < 0 ? 0 : u > 1 ? 1 : u;
            best = fmin(best, testddm_dist2(p, r, r, u, 0, b, k));
        }
        double e11 = 0, e12 = 0, e22 = 0, r1 = 0, r2 = 0;
        for (int j = 0; j < k; j++) {
            double e1 = c[1][j] - c[0][j], e2 = c[2][j] - c[0][j], d = b[j] - c[0][j];
            e11 += e1 * e1; e12 += e1 * e2; e22 += e2 * e2;
            r1 += e1 * d; r2 += e2 * d;
        }
        double det = e11 * e22 - e12 * e12;
        if (det > 0) {
            double s = (r1 * e22 - r2 * e12) / det, t = (r2 * e11 - r1 * e12) / det;
            if (s >= 0 && t >= 0 && s + t <= 1)
                best = fmin(best, testddm_dist2(c[0], c[1], c[2], s, t, b, k));
        }
    }
    return best;
}

double testddm_row_cost(const bmap *P, int i, const double *A, int k, const mesh *T,
                        const double *b)
{
    const int *fv = T->f + 3 * P->face[i];
    const double *w = P->w + 3 * i;
    return testddm_dist2(A + (size_t)fv[0] * k, A + (size_t)fv[1] * k, A + (size_t)fv[2] * k,
                         w[1], w[2], b, k);
}

bmap *testddm_vertex_map(const char *path, int base, const mesh *S, const mesh *T)
{
    char err[256] = "";
    int *ids = NULL, n = 0;
    if (lmk_read_ids(path, base, T->nv, S->nv, &ids, &n, err, sizeof err))
        FAILF("%s", err);
    if (n != S->nv)
        FAILF("%s: %d lines for %d source vertices", path, n, S->nv);
    bmap *P = bmap_new(S->nv, T->nv);
    int *vf = malloc(3 * (size_t)T->nv * sizeof *vf);
    for (int q = 3 * T->nf - 1; q >= 0; q--)
        vf[T->f[q]] = q;
    for (int i = 0; i < n; i++) {
        P->face[i] = vf[ids[i]] / 3;
        for (int c = 0; c < 3; c++)
            P->w[3 * i + c] = c == vf[ids[i]] % 3;
    }
    free(vf);
    free(ids);
    return P;
}

double testddm_mean_error(geod_solver *sT, const mesh *T, const bmap *P, const int *src,
                          const int *tgt, int n)
{
    double *e = malloc(n * sizeof *e), m = 0;
    const bmap *maps[1] = {P};
    if (metric_geodesic_errors(sT, T, maps, 1, src, tgt, n, e))
        FAILF("geodesic errors failed");
    for (int p = 0; p < n; p++)
        m += e[p] / n;
    free(e);
    return m;
}
