/* geo_csr.c — the CSR matrix; see geo_csr.h. No solvers here. */
#include "geo/geo_csr.h"

#include <stdlib.h>

geo_csr *geo_csr_new(int n, int nnz)
{
    if (n < 0 || nnz < 0)
        return NULL;
    geo_csr *a = calloc(1, sizeof *a);
    if (!a)
        return NULL;
    a->n = n;
    a->row_start = calloc((size_t)n + 1, sizeof *a->row_start);
    a->col = malloc(((size_t)nnz + 1) * sizeof *a->col);
    a->val = malloc(((size_t)nnz + 1) * sizeof *a->val);
    if (!a->row_start || !a->col || !a->val) {
        geo_csr_free(a);
        return NULL;
    }
    return a;
}

void geo_csr_free(geo_csr *a)
{
    if (!a)
        return;
    free(a->row_start);
    free(a->col);
    free(a->val);
    free(a);
}

void geo_csr_mul(const geo_csr *a, const double *x, int ncols, double *y)
{
    for (int i = 0; i < a->n; i++)
        for (int c = 0; c < ncols; c++) {
            double s = 0;
            for (int k = a->row_start[i]; k < a->row_start[i + 1]; k++)
                s += a->val[k] * x[(size_t)a->col[k] * ncols + c];
            y[(size_t)i * ncols + c] = s;
        }
}

double geo_csr_get(const geo_csr *a, int i, int j)
{
    int lo = a->row_start[i], hi = a->row_start[i + 1];
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (a->col[mid] == j)
            return a->val[mid];
        if (a->col[mid] < j)
            lo = mid + 1;
        else
            hi = mid;
    }
    return 0;
}
