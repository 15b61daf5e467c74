/* geo_csr.h — a plain compressed-sparse-row matrix of doubles, the form in
 * which geo_ hands out sparse operators (the cotan Laplacian) to the solvers.
 *
 * Row i holds col[row_start[i] .. row_start[i+1]) with strictly increasing
 * column indices and the matching val[]. Square (n by n); symmetric matrices
 * store both triangles. Ownership: geo_csr_new allocates the struct and its
 * three arrays in one owner; geo_csr_free frees them (NULL accepted). */
#ifndef GEO_CSR_H
#define GEO_CSR_H

typedef struct geo_csr {
    int n;           /* rows = columns */
    int *row_start;  /* n + 1; row_start[n] = number of stored entries */
    int *col;        /* row_start[n] */
    double *val;     /* row_start[n] */
} geo_csr;

/* An n by n matrix with room for nnz entries, row_start zeroed; NULL on out
 * of memory or a negative size. */
geo_csr *geo_csr_new(int n, int nnz);
void geo_csr_free(geo_csr *a);

/* y = A x for ncols right-hand sides at once: x and y are n by ncols,
 * row-major (ncols = 3 multiplies a vertex-position array). y must not alias x. */
void geo_csr_mul(const geo_csr *a, const double *x, int ncols, double *y);

/* A(i, j), 0 when not stored (binary search in row i). */
double geo_csr_get(const geo_csr *a, int i, int j);

#endif
