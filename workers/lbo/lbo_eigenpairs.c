/* lbo_eigenpairs.c — the first k Laplace–Beltrami eigenpairs by
 * shift-invert Lanczos: CHOLMOD factorisation of L - sigma M, ARPACK
 * dsaupd/dseupd in mode 3; see lbo.h. */
#include "lbo/lbo.h"
#include "util/errbuf.h"

#include <arpack/arpack.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <suitesparse/cholmod.h>

void lbo_basis_close(lbo_basis *b)
{
    if (!b)
        return;
    free(b->lambda);
    free(b->phi);
    memset(b, 0, sizeof *b);
}

int lbo_basis_first(const lbo_basis *b, int k, lbo_basis *out)
{
    memset(out, 0, sizeof *out);
    if (k < 1 || k > b->k)
        return LBO_EINVAL;
    out->lambda = malloc((size_t)k * sizeof *out->lambda);
    out->phi = malloc((size_t)b->nv * k * sizeof *out->phi);
    if (!out->lambda || !out->phi) {
        lbo_basis_close(out);
        return LBO_ENOMEM;
    }
    out->nv = b->nv;
    out->k = k;
    memcpy(out->lambda, b->lambda, (size_t)k * sizeof *out->lambda);
    for (int i = 0; i < b->nv; i++)
        memcpy(out->phi + (size_t)i * k, b->phi + (size_t)i * b->k, (size_t)k * sizeof *out->phi);
    out->restarts = b->restarts;
    out->op_solves = b->op_solves;
    return LBO_OK;
}

/* The upper triangle of L - sigma M as a CHOLMOD symmetric (stype 1)
 * matrix; a row whose diagonal comes out 0 (a vertex without area or
 * edges) gets 1: it is decoupled and the matrix stays definite. */
static cholmod_sparse *shifted(const geo_csr *L, const double *mass, double sigma,
                               cholmod_common *cc)
{
    int n = L->n;
    size_t nnz = 0;
    for (int j = 0; j < n; j++)
        for (int p = L->row_start[j]; p < L->row_start[j + 1]; p++)
            nnz += L->col[p] <= j;
    cholmod_sparse *A = cholmod_allocate_sparse(n, n, nnz + n, 1, 1, 1, CHOLMOD_REAL, cc);
    if (!A)
        return NULL;
    int *cp = A->p, *ri = A->i;
    double *x = A->x;
    size_t at = 0;
    for (int j = 0; j < n; j++) {   /* column j of the upper triangle = row j's entries c <= j */
        cp[j] = (int)at;
        int diag = 0;
        for (int p = L->row_start[j]; p < L->row_start[j + 1]; p++) {
            int c = L->col[p];
            if (c > j)
                continue;
            ri[at] = c;
            x[at] = L->val[p];
            if (c == j) {
                x[at] -= sigma * mass[j];
                if (!(x[at] != 0))
                    x[at] = 1;
                diag = 1;
            }
            at++;
        }
        if (!diag) {   /* columns sorted: the diagonal is the last entry */
            ri[at] = j;
            x[at++] = -sigma * mass[j] != 0 ? -sigma * mass[j] : 1;
        }
    }
    cp[n] = (int)at;
    return A;
}

/* xorshift in [-1, 1): the fixed start vector. */
static double start_value(unsigned long long *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return 2.0 * (double)(*s >> 11) / 9007199254740992.0 - 1.0;
}

typedef struct op {
    cholmod_common *cc;
    cholmod_factor *F;
    cholmod_dense *b, *x, *y, *e;   /* right-hand side, solution, solve workspaces */
    const double *mass;
    int n, solves;
} op;

/* out = (L - sigma M)^-1 in. */
static int op_solve(op *o, const double *in, double *out)
{
    memcpy(o->b->x, in, (size_t)o->n * sizeof *in);
    if (!cholmod_solve2(CHOLMOD_A, o->F, o->b, NULL, &o->x, NULL, &o->y, &o->e, o->cc))
        return 0;
    memcpy(out, o->x->x, (size_t)o->n * sizeof *out);
    o->solves++;
    return 1;
}

/* The ARPACK reverse-communication loop and the Ritz vectors; z: n by k,
 * column-major (ARPACK's layout), d: k. */
static int lanczos(op *o, int k, double sigma, double *d, double *z, int *restarts,
                   char *err, size_t errsz)
{
    int n = o->n, ncv = 2 * k + 1 > k + 32 ? 2 * k + 1 : k + 32;
    if (ncv > n)
        ncv = n;
    int lworkl = ncv * (ncv + 8), rc = LBO_ENOMEM;
    double *resid = malloc((size_t)n * sizeof *resid), *v = malloc((size_t)n * ncv * sizeof *v);
    double *workd = malloc(3 * (size_t)n * sizeof *workd);
    double *workl = malloc((size_t)lworkl * sizeof *workl), *tmp = malloc((size_t)n * sizeof *tmp);
    a_int *select = calloc((size_t)ncv, sizeof *select);
    if (!resid || !v || !workd || !workl || !tmp || !select) {
        errbuf_set(err, errsz, LBO_ENOMEM, "out of memory for %d Lanczos vectors of %d", ncv, n);
        goto out;
    }
    unsigned long long seed = 0x9e3779b97f4a7c15ULL;
    for (int i = 0; i < n; i++)
        resid[i] = start_value(&seed);
    a_int ido = 0, info = 1, iparam[11] = {0}, ipntr[14] = {0};
    iparam[0] = 1;                  /* exact shifts */
    iparam[2] = LBO_MAX_RESTARTS;
    iparam[6] = 3;                  /* shift-invert, B = M */
    for (;;) {
        dsaupd_c(&ido, "G", n, "LM", k, 0.0, resid, ncv, v, n, iparam, ipntr, workd, workl,
                 lworkl, &info);
        double *x = workd + ipntr[0] - 1, *y = workd + ipntr[1] - 1;
        if (ido == -1) {            /* y = OP x = (L - sigma M)^-1 M x */
            for (int i = 0; i < n; i++)
                tmp[i] = o->mass[i] * x[i];
            if (!op_solve(o, tmp, y))
                goto solve_failed;
        } else if (ido == 1) {      /* y = OP x with M x given */
            if (!op_solve(o, workd + ipntr[2] - 1, y))
                goto solve_failed;
        } else if (ido == 2) {      /* y = M x */
            for (int i = 0; i < n; i++)
                y[i] = o->mass[i] * x[i];
        } else {
            break;
        }
    }
    *restarts = iparam[2];
    if (info == 1 || (info == 0 && iparam[4] < k)) {
        rc = errbuf_set(err, errsz, LBO_ENOCONV, "%d of %d eigenpairs converged in %d restarts",
                        (int)iparam[4], k, (int)iparam[2]);
        goto out;
    }
    if (info != 0) {
        rc = errbuf_set(err, errsz, LBO_EARPACK, "dsaupd info %d (n %d, k %d, ncv %d)",
                        (int)info, n, k, ncv);
        goto out;
    }
    dseupd_c(1, "A", select, d, z, n, sigma, "G", n, "LM", k, 0.0, resid, ncv, v, n, iparam,
             ipntr, workd, workl, lworkl, &info);
    if (info != 0) {
        rc = errbuf_set(err, errsz, LBO_EARPACK, "dseupd info %d (n %d, k %d)", (int)info, n, k);
        goto out;
    }
    rc = LBO_OK;
    goto out;
solve_failed:
    rc = errbuf_set(err, errsz, LBO_EFACTOR, "CHOLMOD solve failed (status %d)", o->cc->status);
out:
    free(resid);
    free(v);
    free(workd);
    free(workl);
    free(tmp);
    free(select);
    return rc;
}

/* Sorts the k pairs by lambda, writes phi row-major with the sign rule. */
static int store(const double *d, const double *z, int n, int k, lbo_basis *b)
{
    int *order = malloc((size_t)k * sizeof *order);
    if (!order)
        return 0;
    for (int j = 0; j < k; j++)
        order[j] = j;
    for (int a = 1; a < k; a++)     /* insertion sort: k <= 300, ARPACK's order is near */
        for (int c = a; c > 0 && d[order[c]] < d[order[c - 1]]; c--) {
            int t = order[c];
            order[c] = order[c - 1];
            order[c - 1] = t;
        }
    for (int j = 0; j < k; j++) {
        const double *col = z + (size_t)n * order[j];
        int imax = 0;
        for (int i = 1; i < n; i++)
            if (fabs(col[i]) > fabs(col[imax]))
                imax = i;
        double s = col[imax] < 0 ? -1 : 1;
        b->lambda[j] = d[order[j]];
        for (int i = 0; i < n; i++)
            b->phi[(size_t)i * k + j] = s * col[i];
    }
    free(order);
    return 1;
}

int lbo_eigenpairs(const geo_csr *L, const double *mass, int nv, int k, lbo_basis *out,
                   char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    if (!L || !mass || L->n != nv || nv < 1)
        return errbuf_set(err, errsz, LBO_EINVAL, "eigenpairs: Laplacian of size %d for %d vertices",
                          L ? L->n : -1, nv);
    if (k < 1 || k > LBO_MAX_K || k > nv - 2)
        return errbuf_set(err, errsz, LBO_EINVAL,
                          "eigenpairs: k = %d, must be in 1..%d (and at most %d for %d vertices)",
                          k, LBO_MAX_K, nv - 2, nv);
    double msum = 0, lsum = 0;
    for (int i = 0; i < nv; i++) {
        if (!(mass[i] >= 0) || !isfinite(mass[i]))
            return errbuf_set(err, errsz, LBO_EINVAL, "eigenpairs: mass of vertex %d is %g",
                              i, mass[i]);
        msum += mass[i];
        lsum += geo_csr_get(L, i, i);
    }
    if (!(msum > 0) || !(lsum > 0) || !isfinite(lsum))
        return errbuf_set(err, errsz, LBO_EINVAL, "eigenpairs: total mass %g, trace of L %g",
                          msum, lsum);
    double sigma = LBO_SHIFT_REL * lsum / msum;

    int rc = LBO_ENOMEM;
    cholmod_common cc;
    cholmod_start(&cc);
    cc.print = 0;
    cc.nmethods = 1;                /* AMD only: deterministic */
    cc.method[0].ordering = CHOLMOD_AMD;
    cc.postorder = 1;
    op o = {.cc = &cc, .mass = mass, .n = nv};
    cholmod_sparse *A = shifted(L, mass, sigma, &cc);
    double *d = malloc((size_t)k * sizeof *d), *z = malloc((size_t)nv * k * sizeof *z);
    out->lambda = malloc((size_t)k * sizeof *out->lambda);
    out->phi = malloc((size_t)nv * k * sizeof *out->phi);
    if (!A || !d || !z || !out->lambda || !out->phi ||
        !(o.b = cholmod_allocate_dense(nv, 1, nv, CHOLMOD_REAL, &cc))) {
        rc = errbuf_set(err, errsz, LBO_ENOMEM, "out of memory for %d eigenpairs of %d vertices",
                        k, nv);
        goto out;
    }
    o.F = cholmod_analyze(A, &cc);
    if (!o.F || !cholmod_factorize(A, o.F, &cc) || cc.status != CHOLMOD_OK) {
        rc = errbuf_set(err, errsz, cc.status == CHOLMOD_OUT_OF_MEMORY ? LBO_ENOMEM : LBO_EFACTOR,
                        "factorising L - sigma M failed (CHOLMOD status %d)", cc.status);
        goto out;
    }
    if ((rc = lanczos(&o, k, sigma, d, z, &out->restarts, err, errsz)) != LBO_OK)
        goto out;
    if (!store(d, z, nv, k, out)) {
        rc = errbuf_set(err, errsz, LBO_ENOMEM, "out of memory sorting eigenpairs");
        goto out;
    }
    out->nv = nv;
    out->k = k;
    out->op_solves = o.solves;
out:
    cholmod_free_dense(&o.b, &cc);
    cholmod_free_dense(&o.x, &cc);
    cholmod_free_dense(&o.y, &cc);
    cholmod_free_dense(&o.e, &cc);
    cholmod_free_factor(&o.F, &cc);
    cholmod_free_sparse(&A, &cc);
    cholmod_finish(&cc);
    free(d);
    free(z);
    if (rc != LBO_OK)
        lbo_basis_close(out);
    return rc;
}
