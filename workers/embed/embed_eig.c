/* embed_eig.c — the top eigenpairs of a small dense symmetric matrix via
 * LAPACK dsyevr; see embed.h. Knows nothing about meshes or distances. */
#include "embed/embed.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int syevr(char jobz, char range, int n, double *a, int il, int iu, int *found,
                 double *w, double *z, int *isuppz)
{
    double vl = 0, vu = 0, abstol = 0, wq;
    int lwork = -1, liwork = -1, iq, info = 0, ldz = n > 1 ? n : 1;
    info = LAPACKE_dsyevr_work(LAPACK_COL_MAJOR, jobz, range, 'U', n, a, n, vl, vu, il, iu, abstol,
                               found, w, z, ldz, isuppz, &wq, lwork, &iq, liwork);
    if (info != 0)
        return EMBED_EEIGEN;
    lwork = (int)wq;
    liwork = iq;
    double *work = malloc((size_t)lwork * sizeof *work);
    int *iwork = malloc((size_t)liwork * sizeof *iwork);
    if (!work || !iwork) {
        free(work);
        free(iwork);
        return EMBED_ENOMEM;
    }
    info = LAPACKE_dsyevr_work(LAPACK_COL_MAJOR, jobz, range, 'U', n, a, n, vl, vu, il, iu, abstol,
                               found, w, z, ldz, isuppz, work, lwork, iwork, liwork);
    free(work);
    free(iwork);
    return info == 0 ? EMBED_OK : EMBED_EEIGEN;
}

int embed_top_eigenpairs(const double *A, int n, int m, double *w, double *V,
                         double *all_w)
{
    if (n < 1 || m < 1 || m > n)
        return EMBED_EINVAL;
    int rc = EMBED_ENOMEM, found = 0;
    double *a = malloc((size_t)n * n * sizeof *a), *wa = malloc((size_t)n * sizeof *wa);
    double *z = malloc((size_t)n * m * sizeof *z);
    int *isuppz = malloc(2 * (size_t)n * sizeof *isuppz);
    if (!a || !wa || !z || !isuppz)
        goto out;
    if (all_w) {
        memcpy(a, A, (size_t)n * n * sizeof *a);
        if ((rc = syevr('N', 'A', n, a, 1, n, &found, all_w, z, isuppz)) != EMBED_OK)
            goto out;
    }
    memcpy(a, A, (size_t)n * n * sizeof *a); /* symmetric: row-major = column-major */
    if ((rc = syevr('V', 'I', n, a, n - m + 1, n, &found, wa, z, isuppz)) != EMBED_OK)
        goto out;
    if (found != m) {
        rc = EMBED_EEIGEN;
        goto out;
    }
    for (int i = 0; i < m; i++) { /* LAPACK: ascending; we: descending */
        const double *zc = z + (size_t)(m - 1 - i) * n;
        int big = 0;
        for (int r = 1; r < n; r++)
            if (fabs(zc[r]) > fabs(zc[big]))
                big = r;
        double sg = zc[big] < 0 ? -1 : 1;
        w[i] = wa[m - 1 - i];
        for (int r = 0; r < n; r++)
            V[(size_t)r * m + i] = sg * zc[r];
    }
    rc = EMBED_OK;
out:
    free(a);
    free(wa);
    free(z);
    free(isuppz);
    return rc;
}
