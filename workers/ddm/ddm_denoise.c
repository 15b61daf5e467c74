/* ddm_denoise.c — DDM denoising: the given map's functional map
 * C = Psi1^T M1 P0 Psi2 (ddm_functional_map), then deblurring; see ddm.h. */
#include "ddm/ddm.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

int ddm_functional_map(const lbo_basis *b1, const double *m1, const lbo_basis *b2, const mesh *T,
                       const bmap *P, int k1, int k2, double *C, char *err, size_t errsz)
{
    if (k1 < 1 || k1 > b1->k || k2 < 1 || k2 > b2->k || !m1)
        return errbuf_set(err, errsz, DDM_EINVAL,
                          "functional map of a map: basis sizes %d, %d (the bases hold %d, %d)%s",
                          k1, k2, b1->k, b2->k, m1 ? "" : ", no source mass");
    if (P->n != b1->nv || P->nt != T->nv || T->nv != b2->nv)
        return errbuf_set(err, errsz, DDM_EINVAL,
                          "functional map of a map: map %d by %d for meshes of %d and %d vertices",
                          P->n, P->nt, b1->nv, T->nv);
    for (int i = 0; i < P->n; i++)
        if (P->face[i] < 0 || P->face[i] >= T->nf)
            return errbuf_set(err, errsz, DDM_EINVAL, "functional map of a map: row %d: face %d of %d",
                              i, P->face[i], T->nf);
    double *y = malloc((size_t)k2 * sizeof *y);
    if (!y)
        return errbuf_set(err, errsz, DDM_ENOMEM, "functional map of a map: out of memory");
    memset(C, 0, (size_t)k1 * k2 * sizeof *C);
    for (int i = 0; i < P->n; i++) {   /* C += psi1_i^T m1_i (P Psi2)_i */
        const int *fv = T->f + 3 * (size_t)P->face[i];
        for (int c = 0; c < k2; c++)
            y[c] = 0;
        for (int q = 0; q < 3; q++) {
            double w = P->w[3 * (size_t)i + q];
            const double *p2 = b2->phi + (size_t)fv[q] * b2->k;
            for (int c = 0; c < k2; c++)
                y[c] += w * p2[c];
        }
        const double *p1 = b1->phi + (size_t)i * b1->k;
        for (int a = 0; a < k1; a++)
            for (int c = 0; c < k2; c++)
                C[(size_t)a * k2 + c] += p1[a] * m1[i] * y[c];
    }
    free(y);
    return DDM_OK;
}

int ddm_denoise(const lbo_basis *b1, const double *m1, const lbo_basis *b2, const mesh *T,
                const bmap *P0, int k1, int k2, bmap *P, ddm_stats *stats, char *err,
                size_t errsz)
{
    if (k1 < 1 || k1 > b1->k || k2 < 1 || k2 > b2->k || !m1)
        return errbuf_set(err, errsz, DDM_EINVAL,
                          "denoising: basis sizes %d, %d (the bases hold %d, %d)%s", k1, k2,
                          b1->k, b2->k, m1 ? "" : ", no source mass");
    if (P0->n != b1->nv || P0->nt != T->nv || T->nv != b2->nv)
        return errbuf_set(err, errsz, DDM_EINVAL,
                          "denoising: input map %d by %d for meshes of %d and %d vertices",
                          P0->n, P0->nt, b1->nv, T->nv);
    for (int i = 0; i < P0->n; i++)
        if (P0->face[i] < 0 || P0->face[i] >= T->nf)
            return errbuf_set(err, errsz, DDM_EINVAL, "denoising: input map row %d: face %d of %d",
                              i, P0->face[i], T->nf);
    double *C = malloc((size_t)k1 * k2 * sizeof *C);
    if (!C)
        return errbuf_set(err, errsz, DDM_ENOMEM, "denoising: out of memory");
    int rc = ddm_functional_map(b1, m1, b2, T, P0, k1, k2, C, err, errsz);
    if (!rc)
        rc = ddm_deblur(b1, m1, b2, T, C, k1, k2, P, stats, err, errsz);
    free(C);
    return rc;
}
