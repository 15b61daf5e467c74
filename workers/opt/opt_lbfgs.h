/* opt_lbfgs.h — the quasi-Newton inner solver of ECTM: L-BFGS (the
 * two-loop recursion) with backtracking Armijo line search, a bounded
 * iteration count, and correction pairs that can be kept from one solve to
 * the next (opt_memory), because ECTM solves a slowly changing objective
 * 2·K times and a cold start throws away what the last solve learnt.
 * (Debian's liblbfgs keeps its pairs inside one lbfgs() call and has no way
 * to start from given pairs; that is why this solver is our own.)
 *
 * The solver allocates nothing per iteration; x is updated in place to the
 * last accepted point. Trial points whose energy or gradient is not finite
 * are rejected by the line search. A non-zero return of the per-iteration
 * callback: OPT_ITER_CANCEL cancels (that is how a job is cancelled),
 * OPT_ITER_CHANGED says the objective itself changed at x (ECTM's
 * admissible edge set): f and g are evaluated again there, the pairs kept. */
#ifndef OPT_LBFGS_H
#define OPT_LBFGS_H
#include "util/errlist.h"

#define OPT_ERRORS(X)                                                         \
    X(OPT_OK,          0, "ok")                                               \
    X(OPT_ECANCELED,  -1, "cancelled by the progress callback")               \
    X(OPT_ENOMEM,     -2, "out of memory")                                    \
    X(OPT_EPARAM,     -3, "invalid solver parameter")                         \
    X(OPT_ENONFINITE, -4, "energy or gradient is not finite")

ERRLIST_ENUM(opt, OPT_ERRORS);

#define OPT_ITER_GO       0
#define OPT_ITER_CHANGED  1
#define OPT_ITER_CANCEL  -1

/* Returns f(x) and writes the gradient into g (n values). */
typedef double (*opt_eval_fn)(void *ctx, const double *x, double *g, int n);
/* After each accepted iteration (iter counts from 1). */
typedef int (*opt_iter_fn)(void *ctx, const double *x, double fx, double gnorm, int iter);

typedef struct opt_params {
    int max_iter;       /* accepted iterations at most (default 50, >= 1)  */
    double gtol;        /* stop when |g| < gtol·max(1, |x|) (default 1e-8, > 0) */
    int memory;         /* correction pairs of a solve without opt_memory
                           (default 6, >= 1)                               */
    double rel_decrease; /* stop when an iteration lowers f by less than this
                           fraction of the decrease since the solve began
                           (default 0: never, >= 0, < 1)                   */
    int max_restarts;   /* retries along −g after a failed line search
                           before giving up (default 2, >= 0)              */
} opt_params;

void opt_params_init(opt_params *p);

typedef struct opt_stats {
    int iterations;     /* accepted iterations */
    int evaluations;    /* energy + gradient evaluations */
    int restarts;       /* steps along −g instead of the L-BFGS direction
                           (a failed line search, an uphill direction)     */
    int changes;        /* OPT_ITER_CHANGED answers of the callback */
    int converged;      /* gradient tolerance reached */
    int stalled;        /* stopped by rel_decrease */
    int last_at_x;      /* the last evaluation was at the returned x (not a
                           rejected trial), so what eval left in its ctx
                           describes x */
    double f;           /* energy at the returned x */
} opt_stats;

/* Correction pairs (s, y) for n unknowns, kept across opt_minimize calls,
 * and the solver's scratch vectors. One owner; not for two solves at once. */
typedef struct opt_memory opt_memory;
opt_memory *opt_memory_new(int n, int pairs);   /* NULL: out of memory or bad sizes */
void opt_memory_free(opt_memory *m);            /* NULL is fine */
/* The objective's Hessian changed by c·diag(d) (d: n values), as when the
 * weight of a quadratic term Σ d_i (x_i − t_i)²/2 changes by c: each kept y
 * gains c·d⊙s, which keeps the pairs exact for that term. */
void opt_memory_add_diagonal(opt_memory *m, const double *d, double c);
int opt_memory_pairs(const opt_memory *m);      /* pairs held now */

/* Minimises from x (n values, updated in place). iter may be NULL. mem:
 * the pairs to start from and to keep (its n must be n), or NULL for a
 * cold solve with p->memory pairs. */
int opt_minimize(int n, double *x, opt_eval_fn eval, opt_iter_fn iter, void *ctx,
                 const opt_params *p, opt_memory *mem, opt_stats *st);

#endif
