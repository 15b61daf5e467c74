/* fmap_orientation.c — the orientation-aware operator of a descriptor
 * (Ren, Poulenard, Wonka, Ovsjanikov 2018, "Continuous and
 * orientation-preserving correspondences via functional maps"),
 * F_f(g) = <n, grad f x grad g>, reduced to a Laplace–Beltrami basis, for
 * several descriptor columns at once; see fmap.h. */
#include "fmap/fmap.h"
#include "geo/geo_tri.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

int fmap_orientation_operators(const mesh *m, const lbo_basis *b, const double *F, int nd,
                               const int *cols, int no, int k, double *O, char *err,
                               size_t errsz)
{
    if (k < 1 || k > b->k || b->nv != m->nv || no < 0)
        return errbuf_set(err, errsz, FMAP_EINVAL,
                          "orientation operators: k = %d for a basis of %d on %d vertices "
                          "(mesh %d), %d operators", k, b->k, b->nv, m->nv, no);
    for (int d = 0; d < no; d++)
        if (cols[d] < 0 || cols[d] >= nd)
            return errbuf_set(err, errsz, FMAP_EINVAL,
                              "orientation operators: column %d of %d descriptors", cols[d], nd);
    memset(O, 0, (size_t)no * k * k * sizeof *O);
    int fail = 0;
    /* one operator per thread at a time: every sum runs over the faces in
     * order, so the result does not depend on the thread count */
#pragma omp parallel
    {
        double *u = malloc(2 * (size_t)k * sizeof *u), *w = u ? u + k : NULL;
        if (!u)
            fail = 1;
#pragma omp for schedule(dynamic)
        for (int d = 0; d < no; d++) {
            if (!u)
                continue;
            double *Od = O + (size_t)d * k * k;
            for (int t = 0; t < m->nf; t++) {
                double cr[3];
                if (geo__face_cross(m, t, cr))
                    continue;
                const int *f = m->f + 3 * (size_t)t;
                double n[3], g[3][3], gf[3] = {0, 0, 0};
                /* the hat gradients, and grad f */
                double a2 = geo__hat_gradients(m, t, cr, n, g);
                for (int c = 0; c < 3; c++) {
                    double fc = F[(size_t)f[c] * nd + cols[d]];
                    for (int q = 0; q < 3; q++)
                        gf[q] += fc * g[c][q];
                }
                /* s_c = area <n, grad f x grad phi_c>: F_f of the hat function of corner c */
                double s[3];
                for (int c = 0; c < 3; c++) {
                    double x[3];
                    geo__cross(gf, g[c], x);
                    s[c] = 0.5 * a2 * geo__dot(n, x);
                }
                /* int_t psi_a F_f(psi_b) = area mean_c(psi_a) (F_f psi_b)_t */
                const double *r0 = b->phi + (size_t)f[0] * b->k, *r1 = b->phi + (size_t)f[1] * b->k,
                             *r2 = b->phi + (size_t)f[2] * b->k;
                for (int a = 0; a < k; a++) {
                    u[a] = (r0[a] + r1[a] + r2[a]) / 3;
                    w[a] = s[0] * r0[a] + s[1] * r1[a] + s[2] * r2[a];
                }
                for (int a = 0; a < k; a++) {
                    double *row = Od + (size_t)a * k, ua = u[a];
                    for (int c = 0; c < k; c++)
                        row[c] += ua * w[c];
                }
            }
        }
        free(u);
    }
    if (fail)
        return errbuf_set(err, errsz, FMAP_ENOMEM, "orientation operators: out of memory");
    return FMAP_OK;
}
