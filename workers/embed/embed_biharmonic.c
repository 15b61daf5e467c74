/* embed_biharmonic.c — the smooth extension of an embedding known at a few
 * vertices to the whole mesh: the minimiser of the discrete biharmonic
 * energy tr(Zᵀ L M⁻¹ L Z) with those rows fixed (one sparse SPD solve,
 * chol.h); see embed.h. Takes the operators as given (geod.h's
 * intrinsic Delaunay L and M); computes no distance. */
#include "embed/embed.h"
#include "chol/chol.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

int embed_biharmonic(const geo_csr *L, const double *mass, const int *fixed, int k,
                     const double *Y, int dim, double *Z, char *err, size_t errsz)
{
    int n = L->n, rc = EMBED_ENOMEM;
    int *row = malloc((size_t)n * sizeof *row);      /* vertex -> free row, or -1 - fixed index */
    double *acc = calloc((size_t)n, sizeof *acc);    /* one row of K, scattered */
    int *mark = malloc((size_t)n * sizeof *mark), *cols = malloc((size_t)n * sizeof *cols);
    chol *A = NULL;
    double *bx = NULL;   /* right-hand sides, then the solution: nf by dim, column-major */
    char detail[256] = "";
    if (!row || !acc || !mark || !cols) {
        errbuf_set(err, errsz, rc, "out of memory");
        goto out;
    }
    for (int v = 0; v < n; v++)
        row[v] = 0, mark[v] = -1;
    for (int a = 0; a < k; a++)
        row[fixed[a]] = -1 - a;
    int nf = 0;
    for (int v = 0; v < n; v++)
        if (row[v] >= 0)
            row[v] = nf++;
    for (int a = 0; a < k; a++)
        memcpy(Z + (size_t)fixed[a] * dim, Y + (size_t)a * dim, (size_t)dim * sizeof *Z);
    if (nf == 0) {
        rc = EMBED_OK;
        goto out;
    }
    /* K = L M⁻¹ L, row by row (2-ring pattern); upper triangle of the free
     * block into A, the fixed columns into the right-hand side */
    size_t cap = 0;
    for (int v = 0; v < n; v++)
        for (int p = L->row_start[v]; p < L->row_start[v + 1]; p++) {
            int l = L->col[p];
            cap += (size_t)(L->row_start[l + 1] - L->row_start[l]);
        }
    /* CHOLMOD's own choice of ordering */
    if (!(bx = calloc((size_t)nf * dim, sizeof *bx)) ||
        chol_new(nf, cap, CHOL_ORDER_CHOLMOD, &A, detail, sizeof detail) != CHOL_OK) {
        errbuf_set(err, errsz, rc, "out of memory for the %d-row biharmonic system", nf);
        goto out;
    }
    for (int v = 0; v < n; v++) {
        if (row[v] < 0)
            continue;
        int nc = 0;
        for (int p = L->row_start[v]; p < L->row_start[v + 1]; p++) {
            int l = L->col[p];
            double w = mass[l] > 0 ? L->val[p] / mass[l] : 0;
            for (int q = L->row_start[l]; q < L->row_start[l + 1]; q++) {
                int u = L->col[q];
                if (mark[u] != v) {
                    mark[u] = v;
                    acc[u] = 0;
                    cols[nc++] = u;
                }
                acc[u] += w * L->val[q];
            }
        }
        qsort(cols, (size_t)nc, sizeof *cols, cmp_int);
        int c = row[v];
        for (int q = 0; q < nc; q++) {
            int u = cols[q];
            if (row[u] >= 0) {
                if (row[u] <= c)
                    chol_add(A, row[u], c, acc[u]);
            } else {
                const double *y = Y + (size_t)(-1 - row[u]) * dim;
                for (int d = 0; d < dim; d++)
                    bx[(size_t)d * nf + c] -= acc[u] * y[d];
            }
        }
    }
    int crc = chol_assemble(A, CHOL_DIAG_KEEP, NULL, detail, sizeof detail);
    if (crc == CHOL_OK && (crc = chol_factorise(A, detail, sizeof detail)) == CHOL_OK)
        crc = chol_solve(A, bx, dim, bx, detail, sizeof detail);
    if (crc != CHOL_OK) {
        rc = errbuf_set(err, errsz, crc == CHOL_ENOMEM ? EMBED_ENOMEM : EMBED_ESOLVE,
                        "biharmonic extension: %s (is every component sampled?)", detail);
        goto out;
    }
    const double *x = bx;
    for (int v = 0; v < n; v++)
        if (row[v] >= 0)
            for (int d = 0; d < dim; d++)
                Z[(size_t)v * dim + d] = x[(size_t)d * nf + row[v]];
    rc = EMBED_OK;
out:
    chol_free(A);
    free(bx);
    free(row);
    free(acc);
    free(mark);
    free(cols);
    return rc;
}
