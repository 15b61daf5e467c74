/* fmap_deformation.c — functional deformation fields D_V (the Lie
 * derivative of the metric along an extrinsic vector field as an operator
 * on functions), reduced to a Laplace–Beltrami basis; see fmap.h. */
#include "fmap/fmap.h"
#include "geo/geo_normals.h"
#include "geo/geo_tri.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

int fmap_deformation_operator(const mesh *m, const double *V, const lbo_basis *b, int k,
                              double *D, char *err, size_t errsz)
{
    if (k < 1 || k > b->k || b->nv != m->nv)
        return errbuf_set(err, errsz, FMAP_EINVAL,
                          "deformation operator: k = %d for a basis of %d on %d vertices (mesh %d)",
                          k, b->k, b->nv, m->nv);
    double *G = malloc(3 * (size_t)k * sizeof *G);   /* 3 by k: grad psi_a on one triangle */
    if (!G)
        return errbuf_set(err, errsz, FMAP_ENOMEM, "deformation operator: out of memory");
    memset(D, 0, (size_t)k * k * sizeof *D);
    for (int t = 0; t < m->nf; t++) {
        double cr[3];
        if (geo__face_cross(m, t, cr))
            continue;
        const int *f = m->f + 3 * (size_t)t;
        double n[3], g[3][3];   /* hat gradients */
        double a2 = geo__hat_gradients(m, t, cr, n, g);
        /* dV = sum_c V_c grad phi_c^T (3 by 3); S = dV + dV^T */
        double S[3][3];
        for (int r = 0; r < 3; r++)
            for (int q = 0; q < 3; q++) {
                double s = 0;
                for (int c = 0; c < 3; c++)
                    s += V[3 * (size_t)f[c] + r] * g[c][q] + V[3 * (size_t)f[c] + q] * g[c][r];
                S[r][q] = s;
            }
        for (int q = 0; q < 3; q++)
            for (int a = 0; a < k; a++) {
                double s = 0;
                for (int c = 0; c < 3; c++)
                    s += b->phi[(size_t)f[c] * b->k + a] * g[c][q];
                G[q * k + a] = s;
            }
        double area = 0.5 * a2;
        for (int a = 0; a < k; a++) {
            double SG[3];   /* S grad psi_a */
            for (int r = 0; r < 3; r++)
                SG[r] = S[r][0] * G[a] + S[r][1] * G[k + a] + S[r][2] * G[2 * k + a];
            for (int c = 0; c < k; c++)
                D[(size_t)a * k + c] += area * (SG[0] * G[c] + SG[1] * G[k + c] + SG[2] * G[2 * k + c]);
        }
    }
    free(G);
    for (int a = 0; a < k; a++)   /* exact symmetry (S is symmetric; sums may round apart) */
        for (int c = a + 1; c < k; c++)
            D[(size_t)a * k + c] = D[(size_t)c * k + a] =
                0.5 * (D[(size_t)a * k + c] + D[(size_t)c * k + a]);
    return FMAP_OK;
}

int fmap_normal_operator(const mesh *m, const lbo_basis *b, int k, double *D, char *err,
                         size_t errsz)
{
    double *N = malloc(3 * (size_t)m->nv * sizeof *N);
    if (!N)
        return errbuf_set(err, errsz, FMAP_ENOMEM, "normal operator: out of memory");
    geo_vertex_normals(m, N);
    int rc = fmap_deformation_operator(m, N, b, k, D, err, errsz);
    free(N);
    return rc;
}
