/* chol.h — the engine's one bridge to CHOLMOD: a symmetric sparse matrix
 * assembled from triplets with an explicit rule for its diagonal, its
 * Cholesky factorisation and solves with it. geod, lbo, embed and rhm
 * factorise through it; nothing else includes CHOLMOD for a factorisation.
 *
 * Use: chol_new (n, room for the entries, ordering) -> chol_add each entry
 * of the upper triangle -> chol_assemble (diagonal rule) -> chol_factorise
 * -> chol_solve, as often as needed -> chol_free. A matrix whose values
 * change but whose pattern does not (rhm's X-step) writes the values
 * through chol_csc and calls chol_factorise again: the ordering and
 * symbolic analysis are done once.
 *
 * Errors come back as CHOL_E* codes with the detail (the CHOLMOD status)
 * in the caller's error buffer; each code's kind (protocol/proto_kind.h)
 * is its list's fourth column. One chol is used by one thread at a time
 * (it owns its CHOLMOD workspace); separate ones are independent. */
#ifndef CHOL_H
#define CHOL_H
#include <stddef.h>
#include "util/errlist.h"

#define CHOL_ERRORS(X)                                                      \
    X(CHOL_OK,       0, "ok", NONE)                                           \
    X(CHOL_ENOMEM,  -1, "out of memory", NOMEM)                               \
    X(CHOL_EINVAL,  -2, "invalid argument", INTERNAL)                         \
    X(CHOL_ENOTPD,  -3, "matrix not positive definite", NUMERIC)              \
    X(CHOL_EFACTOR, -4, "sparse factorisation or solve failed", NUMERIC)

ERRLIST_ENUM(chol, CHOL_ERRORS);

/* The fill-reducing ordering. AMD alone is deterministic whatever METIS
 * would do; CHOLMOD's own choice tries AMD and may fall back to METIS on
 * a matrix AMD orders badly. */
enum chol_order {
    CHOL_ORDER_AMD,
    CHOL_ORDER_CHOLMOD,
};

/* What chol_assemble does to the diagonal of the summed entries. */
enum chol_diag {
    CHOL_DIAG_KEEP,     /* as the entries give it; d unused */
    CHOL_DIAG_SHIFT,    /* plus d[j] on every row (a row without a diagonal
                           entry gets one) */
    CHOL_DIAG_SHIFT_UNIT, /* plus d[j], and a diagonal that comes out 0 (or
                           NaN) becomes 1: such a row (a vertex without
                           area or edges) is decoupled and the matrix
                           stays definite */
};

typedef struct chol chol;

/* An n by n symmetric matrix with room for cap entries; *out = it.
 * CHOL_OK, CHOL_EINVAL (n < 1) or CHOL_ENOMEM. */
int chol_new(int n, size_t cap, enum chol_order order, chol **out, char *err, size_t errsz);
void chol_free(chol *c);

/* Adds x at (i, j), 0 <= i, j < n. An entry below the diagonal is added
 * to its mirror; entries at one place are summed. Up to cap entries:
 * past that, or after chol_assemble, CHOL_EINVAL. */
int chol_add(chol *c, int i, int j, double x);

/* Sums the entries into the upper-triangular compressed-column matrix and
 * applies the diagonal rule (d: n values, or NULL for CHOL_DIAG_KEEP).
 * CHOL_OK, CHOL_EINVAL or CHOL_ENOMEM. */
int chol_assemble(chol *c, enum chol_diag rule, const double *d, char *err, size_t errsz);

/* The assembled matrix's upper triangle in compressed columns: column j
 * holds rows row[colstart[j]] .. row[colstart[j + 1] - 1], ascending,
 * values val[...]. The values may be rewritten before chol_factorise. */
void chol_csc(chol *c, const int **colstart, const int **row, double **val);

/* Orders and analyses the pattern (the first time only). CHOL_OK,
 * CHOL_ENOMEM or CHOL_EFACTOR. */
int chol_analyse(chol *c, char *err, size_t errsz);

/* Factorises the current values (analysing first if not yet done).
 * CHOL_OK, CHOL_ENOTPD (CHOLMOD met a zero pivot in its simplicial LDLᵀ
 * or a pivot not positive in its supernodal LLᵀ: it does not test a
 * simplicial D for sign), CHOL_ENOMEM or CHOL_EFACTOR. */
int chol_factorise(chol *c, char *err, size_t errsz);

/* x = A^-1 b for ncol right-hand sides, both n by ncol column-major (x may
 * be b). CHOL_OK, CHOL_EINVAL (not factorised), CHOL_ENOMEM or
 * CHOL_EFACTOR. */
int chol_solve(chol *c, const double *b, int ncol, double *x, char *err, size_t errsz);

int chol_n(const chol *c);
/* CHOLMOD's status after the last call (0 when it went well): for a
 * caller's message. */
int chol_status(const chol *c);

#endif
