/* geo_cotan.c — cotangent weights per face corner, gathered per edge, then
 * laid out as CSR; see geo_cotan.h. Serial and in a fixed order, so the
 * matrix is bitwise reproducible. */
#include "geo/geo_cotan.h"
#include "geo/geo_tri.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>

/* w: ne. The edge weights w_e = (cot alpha + cot beta) / 2 = -L_ij. */
static void geo_cotan_weights(const mesh *m, const geo_edges *e, double *w)
{
    for (int i = 0; i < e->ne; i++)
        w[i] = 0;
    for (int t = 0; t < m->nf; t++) {
        double c[3];
        if (geo__face_cross(m, t, c))
            continue;
        double twice_area = sqrt(geo__dot(c, c));
        const double *p[3];
        geo__corners(m, t, p);
        for (int k = 0; k < 3; k++) {
            double a[3], b[3];
            geo__sub(p[(k + 1) % 3], p[k], a);
            geo__sub(p[(k + 2) % 3], p[k], b);
            /* cot = cos / sin = (a . b) / |a x b| */
            w[e->fe[3 * t + k]] += 0.5 * geo__dot(a, b) / twice_area;
        }
    }
}

int geo_cotan_laplacian(const mesh *m, const geo_edges *e, geo_csr **out,
                        char *err, size_t errsz)
{
    *out = NULL;
    if (e->nv != m->nv || e->nf != m->nf)
        return errbuf_set(err, errsz, GEO_EMISMATCH,
                          "edge table is for %d vertices, %d faces; mesh has %d, %d",
                          e->nv, e->nf, m->nv, m->nf);
    int n = m->nv;
    double *w = malloc(((size_t)e->ne + 1) * sizeof *w);
    int *lower = calloc((size_t)n + 1, sizeof *lower); /* entries left of the diagonal */
    int *fill = calloc((size_t)n + 1, sizeof *fill);   /* lower entries placed */
    int *upper = calloc((size_t)n + 1, sizeof *upper); /* upper entries placed */
    geo_csr *a = geo_csr_new(n, n + 2 * e->ne);
    if (!w || !lower || !fill || !upper || !a) {
        free(w); free(lower); free(fill); free(upper); geo_csr_free(a);
        return errbuf_set(err, errsz, GEO_ENOMEM, "out of memory building the %d by %d Laplacian", n, n);
    }
    geo_cotan_weights(m, e, w);
    for (int k = 0; k < e->ne; k++) {
        lower[e->ev[2 * k + 1]]++;
        a->row_start[e->ev[2 * k] + 1]++;
        a->row_start[e->ev[2 * k + 1] + 1]++;
    }
    for (int i = 0; i < n; i++) {
        a->row_start[i + 1] += a->row_start[i] + 1; /* + 1: the diagonal */
        int d = a->row_start[i] + lower[i];
        a->col[d] = i;
        a->val[d] = 0;
    }
    /* Edges come sorted by (min, max): row max receives its lower entries
     * in increasing column order, row min its upper entries likewise. */
    for (int k = 0; k < e->ne; k++) {
        int i = e->ev[2 * k], j = e->ev[2 * k + 1];
        int in_j = a->row_start[j] + fill[j]++;
        int in_i = a->row_start[i] + lower[i] + 1 + upper[i]++;
        a->col[in_j] = i;
        a->col[in_i] = j;
        a->val[in_j] = a->val[in_i] = -w[k];
        a->val[a->row_start[i] + lower[i]] += w[k];
        a->val[a->row_start[j] + lower[j]] += w[k];
    }
    free(w); free(lower); free(fill); free(upper);
    *out = a;
    return GEO_OK;
}
