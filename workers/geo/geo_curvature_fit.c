/* geo_curvature_fit.c — mean curvature from the shape operator fitted to
 * the variation of the normals over a neighbourhood; see geo_curvature.h. */
#include "geo/geo_curvature.h"
#include "geo/geo_tri.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>

/* A unit vector u orthogonal to unit n, and v = n x u. */
static void tangent_frame(const double *n, double *u, double *v)
{
    double a[3] = {1, 0, 0};
    if (fabs(n[0]) > 0.6) {
        a[0] = 0;
        a[1] = 1;
    }
    double d = geo__dot(a, n);
    for (int k = 0; k < 3; k++)
        u[k] = a[k] - d * n[k];
    double l = sqrt(geo__dot(u, u));
    for (int k = 0; k < 3; k++)
        u[k] /= l;
    v[0] = n[1] * u[2] - n[2] * u[1];
    v[1] = n[2] * u[0] - n[0] * u[2];
    v[2] = n[0] * u[1] - n[1] * u[0];
}

/* Solves the symmetric 3 by 3 system A x = b (Cramer); 0 when singular. */
static int solve3(const double A[6], const double b[3], double x[3])
{
    /* A = [a0 a1 a2; a1 a3 a4; a2 a4 a5] */
    double c0 = A[3] * A[5] - A[4] * A[4], c1 = A[2] * A[4] - A[1] * A[5], c2 = A[1] * A[4] - A[2] * A[3];
    double det = A[0] * c0 + A[1] * c1 + A[2] * c2;
    double scale = fabs(A[0]) + fabs(A[3]) + fabs(A[5]);
    if (!(fabs(det) > 1e-12 * scale * scale * scale))
        return 0;
    double c4 = A[0] * A[5] - A[2] * A[2], c5 = A[1] * A[2] - A[0] * A[4], c8 = A[0] * A[3] - A[1] * A[1];
    x[0] = (c0 * b[0] + c1 * b[1] + c2 * b[2]) / det;
    x[1] = (c1 * b[0] + c4 * b[1] + c5 * b[2]) / det;
    x[2] = (c2 * b[0] + c5 * b[1] + c8 * b[2]) / det;
    return 1;
}

int geo_mean_curvature_fit(const mesh *m, const geo_edges *e, const double *vn, double radius,
                           double *H, char *err, size_t errsz)
{
    if (e->nv != m->nv || e->nf != m->nf)
        return errbuf_set(err, errsz, GEO_EMISMATCH, "edge table is of a mesh with %d vertices and %d faces; "
                          "mesh has %d and %d", e->nv, e->nf, m->nv, m->nf);
    if (!(radius > 0) || !isfinite(radius))
        return errbuf_set(err, errsz, GEO_EDEGENERATE, "neighbourhood radius %g is not a positive number", radius);
    int *stamp = malloc(sizeof(int) * (size_t)m->nv), *queue = malloc(sizeof(int) * (size_t)m->nv);
    if (!stamp || !queue) {
        free(stamp);
        free(queue);
        return errbuf_set(err, errsz, GEO_ENOMEM, "out of memory for the neighbourhoods (%d vertices)", m->nv);
    }
    for (int i = 0; i < m->nv; i++)
        stamp[i] = -1;
    double r2 = radius * radius, s2 = 2 * (radius / 2) * (radius / 2);
    for (int i = 0; i < m->nv; i++) {
        const double *pi = m->v + 3 * (size_t)i, *ni = vn + 3 * (size_t)i;
        H[i] = 0;
        if (geo__dot(ni, ni) == 0)
            continue;
        double u[3], v[3], A[6] = {0}, b[3] = {0};
        tangent_frame(ni, u, v);
        /* breadth-first over the faces, through vertices inside the ball;
         * the one ring always counts, so every vertex has a fit */
        int head = 0, tail = 0;
        queue[tail++] = i;
        stamp[i] = i;
        while (head < tail) {
            int w = queue[head++];
            for (int k = e->vf_start[w]; k < e->vf_start[w + 1]; k++) {
                const int *t = m->f + 3 * (size_t)e->vf_face[k];
                for (int c = 0; c < 3; c++) {
                    int j = t[c];
                    if (stamp[j] == i)
                        continue;
                    const double *pj = m->v + 3 * (size_t)j, *nj = vn + 3 * (size_t)j;
                    double dp[3] = {pj[0] - pi[0], pj[1] - pi[1], pj[2] - pi[2]};
                    double d2 = geo__dot(dp, dp);
                    if (w != i && d2 > r2)
                        continue;
                    stamp[j] = i;
                    if (d2 <= r2)
                        queue[tail++] = j;
                    if (geo__dot(nj, nj) == 0)
                        continue;
                    double dn[3] = {nj[0] - ni[0], nj[1] - ni[1], nj[2] - ni[2]};
                    double au = geo__dot(dp, u), av = geo__dot(dp, v);
                    double bu = geo__dot(dn, u), bv = geo__dot(dn, v);
                    double wt = exp(-d2 / s2);
                    /* rows (au, av, 0) . (s11, s12, s22) = bu and (0, au, av) . s = bv */
                    A[0] += wt * au * au;
                    A[1] += wt * au * av;
                    A[3] += wt * (av * av + au * au);
                    A[4] += wt * au * av;
                    A[5] += wt * av * av;
                    b[0] += wt * au * bu;
                    b[1] += wt * (av * bu + au * bv);
                    b[2] += wt * av * bv;
                }
            }
        }
        double s[3];
        if (solve3(A, b, s))
            H[i] = 0.5 * (s[0] + s[2]);
    }
    free(stamp);
    free(queue);
    return GEO_OK;
}
