/* opt_lbfgs.h — the quasi-Newton inner solver of ECTM: L-BFGS (Debian's
 * liblbfgs) with backtracking Armijo line search, a bounded iteration count,
 * and a memory reset + retry when the line search fails or when the caller
 * asks for one (the energy changed, e.g. the admissible edge set).
 *
 * The solver never allocates per iteration beyond what liblbfgs does; x is
 * updated in place to the best point found. A non-zero return of the
 * per-iteration callback stops the solve: OPT_ITER_CANCEL cancels (that is how
 * a job is cancelled), OPT_ITER_RESTART resets the memory and goes on. */
#ifndef OPT_LBFGS_H
#define OPT_LBFGS_H

#define OPT_ERRORS(X)                                                         \
    X(OPT_OK,          0, "ok")                                               \
    X(OPT_ECANCELED,  -1, "cancelled by the progress callback")               \
    X(OPT_ENOMEM,     -2, "out of memory")                                    \
    X(OPT_EPARAM,     -3, "invalid solver parameter")                         \
    X(OPT_ENONFINITE, -4, "energy or gradient is not finite")

enum opt_error {
#define OPT_ENUM(name, val, msg) name = val,
    OPT_ERRORS(OPT_ENUM)
#undef OPT_ENUM
};
const char *opt_strerror(int code);

#define OPT_ITER_GO       0
#define OPT_ITER_RESTART  1
#define OPT_ITER_CANCEL  -1

/* Returns f(x) and writes the gradient into g (n values). */
typedef double (*opt_eval_fn)(void *ctx, const double *x, double *g, int n);
/* After each accepted iteration (iter counts from 1 over restarts). */
typedef int (*opt_iter_fn)(void *ctx, const double *x, double fx, double gnorm, int iter);

typedef struct opt_params {
    int max_iter;       /* total iterations over all restarts (default 50, >= 1) */
    double gtol;        /* stop when |g| < gtol·max(1, |x|) (default 1e-8, > 0) */
    int memory;         /* L-BFGS correction pairs (default 6, >= 1) */
    int max_restarts;   /* retries after a line-search failure (default 2, >= 0) */
} opt_params;

void opt_params_init(opt_params *p);

typedef struct opt_stats {
    int iterations;     /* accepted iterations */
    int evaluations;    /* energy + gradient evaluations */
    int restarts;       /* memory resets (line-search failures + requested) */
    int converged;      /* gradient tolerance reached */
    double f;           /* energy at the returned x */
} opt_stats;

/* Minimises from x (n values, updated in place). iter may be NULL. */
int opt_minimize(int n, double *x, opt_eval_fn eval, opt_iter_fn iter, void *ctx,
                 const opt_params *p, opt_stats *st);

#endif
