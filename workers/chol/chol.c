/* chol.c — the CHOLMOD bridge: triplets to an upper-triangular symmetric
 * matrix under a diagonal rule, its factorisation and solves; see chol.h. */
#include "chol/chol.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <suitesparse/cholmod.h>

struct chol {
    int n;
    cholmod_common cc;
    cholmod_triplet *T;             /* the entries until chol_assemble */
    cholmod_sparse *A;              /* upper triangle (stype 1), sorted */
    cholmod_factor *F;
    cholmod_dense *b, *x, *y, *e;   /* right-hand sides, solution, solve workspaces */
    int factorised;                 /* F holds the current values' factor */
};

int chol_new(int n, size_t cap, enum chol_order order, chol **out, char *err, size_t errsz)
{
    *out = NULL;
    if (n < 1)
        return errbuf_set(err, errsz, CHOL_EINVAL, "a %d by %d matrix", n, n);
    chol *c = calloc(1, sizeof *c);
    if (!c)
        return errbuf_set(err, errsz, CHOL_ENOMEM, "out of memory for a %d-row matrix", n);
    c->n = n;
    cholmod_start(&c->cc);
    c->cc.print = 0;
    if (order == CHOL_ORDER_AMD) {
        c->cc.nmethods = 1;
        c->cc.method[0].ordering = CHOLMOD_AMD;
        c->cc.postorder = 1;
    }
    /* room for one diagonal entry per row besides the caller's */
    if (!(c->T = cholmod_allocate_triplet((size_t)n, (size_t)n, cap + (size_t)n, 1, CHOLMOD_REAL,
                                          &c->cc))) {
        chol_free(c);
        return errbuf_set(err, errsz, CHOL_ENOMEM, "out of memory for %zu entries of a %d-row "
                          "matrix", cap, n);
    }
    *out = c;
    return CHOL_OK;
}

void chol_free(chol *c)
{
    if (!c)
        return;
    cholmod_free_triplet(&c->T, &c->cc);
    cholmod_free_sparse(&c->A, &c->cc);
    cholmod_free_factor(&c->F, &c->cc);
    cholmod_free_dense(&c->b, &c->cc);
    cholmod_free_dense(&c->x, &c->cc);
    cholmod_free_dense(&c->y, &c->cc);
    cholmod_free_dense(&c->e, &c->cc);
    cholmod_finish(&c->cc);
    free(c);
}

/* Appends one entry; the caller checked the room. */
static void put(cholmod_triplet *T, int i, int j, double x)
{
    size_t k = T->nnz++;
    ((int *)T->i)[k] = i;
    ((int *)T->j)[k] = j;
    ((double *)T->x)[k] = x;
}

int chol_add(chol *c, int i, int j, double x)
{
    /* the last n places are kept for the diagonal rule */
    if (!c->T || i < 0 || j < 0 || i >= c->n || j >= c->n || c->T->nnz + (size_t)c->n >= c->T->nzmax)
        return CHOL_EINVAL;
    put(c->T, i, j, x);
    return CHOL_OK;
}

int chol_assemble(chol *c, enum chol_diag rule, const double *d, char *err, size_t errsz)
{
    if (!c->T || (rule != CHOL_DIAG_KEEP && !d))
        return errbuf_set(err, errsz, CHOL_EINVAL, "assembling: %s",
                          c->T ? "the diagonal rule needs its values" : "already assembled");
    if (rule != CHOL_DIAG_KEEP)
        for (int j = 0; j < c->n; j++)
            put(c->T, j, j, d[j]);
    /* sorted columns, duplicates summed, lower entries moved to their mirror */
    c->A = cholmod_triplet_to_sparse(c->T, c->T->nnz, &c->cc);
    if (!c->A)
        return errbuf_set(err, errsz, c->cc.status == CHOLMOD_OUT_OF_MEMORY ? CHOL_ENOMEM : CHOL_EINVAL,
                          "assembling a %d-row matrix: CHOLMOD status %d", c->n, c->cc.status);
    cholmod_free_triplet(&c->T, &c->cc);
    if (rule == CHOL_DIAG_SHIFT_UNIT) {
        const int *cp = c->A->p, *ri = c->A->i;
        double *x = c->A->x;
        for (int j = 0; j < c->n; j++) {   /* upper and sorted: the diagonal ends column j */
            double *dj = &x[cp[j + 1] - 1];
            if (cp[j + 1] > cp[j] && ri[cp[j + 1] - 1] == j && !(*dj != 0))
                *dj = 1;
        }
    }
    return CHOL_OK;
}

void chol_csc(chol *c, const int **colstart, const int **row, double **val)
{
    *colstart = c->A ? c->A->p : NULL;
    *row = c->A ? c->A->i : NULL;
    *val = c->A ? c->A->x : NULL;
}

/* The code of a CHOLMOD failure, its detail in err. */
static int failed(chol *c, const char *what, char *err, size_t errsz)
{
    int st = c->cc.status;
    if (st == CHOLMOD_OUT_OF_MEMORY)
        return errbuf_set(err, errsz, CHOL_ENOMEM, "%s: CHOLMOD ran out of memory (%d rows)", what,
                          c->n);
    if (st == CHOLMOD_NOT_POSDEF)
        return errbuf_set(err, errsz, CHOL_ENOTPD, "%s: not positive definite at column %d of %d "
                          "(CHOLMOD status %d)", what, c->F ? (int)c->F->minor : -1, c->n, st);
    return errbuf_set(err, errsz, CHOL_EFACTOR, "%s failed (CHOLMOD status %d)", what, st);
}

int chol_analyse(chol *c, char *err, size_t errsz)
{
    if (!c->A)
        return errbuf_set(err, errsz, CHOL_EINVAL, "analysing: the matrix is not assembled");
    if (c->F)
        return CHOL_OK;
    if (!(c->F = cholmod_analyze(c->A, &c->cc)) || c->cc.status != CHOLMOD_OK) {
        int rc = failed(c, "analysing", err, errsz);
        cholmod_free_factor(&c->F, &c->cc);
        return rc;
    }
    return CHOL_OK;
}

int chol_factorise(chol *c, char *err, size_t errsz)
{
    int rc = chol_analyse(c, err, errsz);
    if (rc != CHOL_OK)
        return rc;
    c->factorised = 0;
    if (!cholmod_factorize(c->A, c->F, &c->cc) || c->cc.status != CHOLMOD_OK)
        return failed(c, "factorising", err, errsz);
    c->factorised = 1;
    return CHOL_OK;
}

int chol_solve(chol *c, const double *b, int ncol, double *x, char *err, size_t errsz)
{
    if (!c->factorised || ncol < 1)
        return errbuf_set(err, errsz, CHOL_EINVAL, "solving: %s",
                          ncol < 1 ? "no right-hand side" : "the matrix is not factorised");
    size_t n = (size_t)c->n, len = n * (size_t)ncol;
    if (c->b && c->b->ncol != (size_t)ncol)
        cholmod_free_dense(&c->b, &c->cc);
    if (!c->b && !(c->b = cholmod_allocate_dense(n, (size_t)ncol, n, CHOLMOD_REAL, &c->cc)))
        return failed(c, "solving", err, errsz);
    double *bx = c->b->x;
    for (size_t k = 0; k < len; k++)
        bx[k] = b[k];
    if (!cholmod_solve2(CHOLMOD_A, c->F, c->b, NULL, &c->x, NULL, &c->y, &c->e, &c->cc) ||
        c->cc.status != CHOLMOD_OK)
        return failed(c, "solving", err, errsz);
    const double *sx = c->x->x;
    for (size_t k = 0; k < len; k++)
        x[k] = sx[k];
    return CHOL_OK;
}

int chol_n(const chol *c) { return c->n; }
int chol_status(const chol *c) { return c->cc.status; }
