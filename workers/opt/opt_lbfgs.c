/* opt_lbfgs.c — see opt_lbfgs.h. A thin driver around liblbfgs: restarts,
 * cancellation and statistics. No energy knowledge here. */
#include "opt/opt_lbfgs.h"

#include <lbfgs.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

const char *opt_strerror(int code)
{
    switch (code) {
#define OPT_STR(name, val, msg) case name: return msg;
        OPT_ERRORS(OPT_STR)
#undef OPT_STR
    }
    return "unknown solver error";
}

void opt_params_init(opt_params *p)
{
    p->max_iter = 50;
    p->gtol = 1e-8;
    p->memory = 6;
    p->max_restarts = 2;
}

typedef struct run {
    opt_eval_fn eval;
    opt_iter_fn iter;
    void *ctx;
    opt_stats *st;
    int iter_base;      /* iterations done in earlier restarts */
    int budget;         /* iterations left for this lbfgs() call */
    int wants_restart;
    int cancelled;
    int nonfinite;
    int broken;         /* liblbfgs accepted a non-finite point */
    double *good;       /* the last accepted point with a finite energy */
    int n;
} run;

static lbfgsfloatval_t eval_cb(void *inst, const lbfgsfloatval_t *x, lbfgsfloatval_t *g,
                               const int n, const lbfgsfloatval_t step)
{
    (void)step;
    run *r = inst;
    r->st->evaluations++;
    double f = r->eval(r->ctx, x, g, n);
    /* Let the line search back off: an infinite energy is a rejected step.
     * A non-finite gradient is rejected too: liblbfgs 1.10 takes a NaN
     * gradient norm for convergence and a NaN direction for a good step. */
    int bad = !isfinite(f);
    for (int i = 0; i < n && !bad; i++)
        bad = !isfinite(g[i]);
    if (bad) {
        r->nonfinite++;
        return INFINITY;
    }
    return f;
}

static int progress_cb(void *inst, const lbfgsfloatval_t *x, const lbfgsfloatval_t *g,
                       const lbfgsfloatval_t fx, const lbfgsfloatval_t xnorm,
                       const lbfgsfloatval_t gnorm, const lbfgsfloatval_t step,
                       int n, int k, int ls)
{
    (void)g; (void)xnorm; (void)step; (void)n; (void)ls;
    run *r = inst;
    /* liblbfgs 1.10's backtracking accepts a step when its Armijo test
     * compares with NaN (a NaN search direction, after a zero curvature
     * pair): the new point is NaN with f = +inf. Stop there; the driver goes
     * back to the last good point and resets the memory. */
    if (!isfinite(fx)) {
        r->broken = 1;
        return 1;
    }
    memcpy(r->good, x, sizeof *x * (size_t)r->n);
    r->st->iterations = r->iter_base + k;
    r->st->f = fx;
    if (r->iter) {
        int v = r->iter(r->ctx, x, fx, gnorm, r->iter_base + k);
        if (v == OPT_ITER_CANCEL) {
            r->cancelled = 1;
            return 1;
        }
        if (v == OPT_ITER_RESTART) {
            r->wants_restart = 1;
            return 1;
        }
    }
    return 0;
}

int opt_minimize(int n, double *x, opt_eval_fn eval, opt_iter_fn iter, void *ctx,
                 const opt_params *p, opt_stats *st)
{
    if (n <= 0 || p->max_iter < 1 || !(p->gtol > 0) || p->memory < 1 || p->max_restarts < 0)
        return OPT_EPARAM;
    memset(st, 0, sizeof *st);
    lbfgsfloatval_t *xx = lbfgs_malloc(n);
    double *good = malloc(sizeof *good * (size_t)n);
    if (!xx || !good) {
        lbfgs_free(xx);
        free(good);
        return OPT_ENOMEM;
    }
    memcpy(xx, x, sizeof *x * (size_t)n);
    memcpy(good, x, sizeof *x * (size_t)n);

    lbfgs_parameter_t lp;
    lbfgs_parameter_init(&lp);
    lp.m = p->memory;
    lp.epsilon = p->gtol;
    lp.linesearch = LBFGS_LINESEARCH_BACKTRACKING_ARMIJO;
    lp.max_linesearch = 40;

    run r = { eval, iter, ctx, st, 0, 0, 0, 0, 0, 0, good, n };
    int failures = 0, rc = OPT_OK;
    for (;;) {
        r.budget = p->max_iter - r.iter_base;
        if (r.budget <= 0)
            break;
        lp.max_iterations = r.budget;
        r.wants_restart = 0;
        r.broken = 0;
        lbfgsfloatval_t fx = 0;
        int ret = lbfgs(n, xx, &fx, eval_cb, progress_cb, &r, &lp);
        r.iter_base = st->iterations;
        if (r.broken) {
            memcpy(xx, good, sizeof *x * (size_t)n);
            if (failures++ >= p->max_restarts)
                break;
            st->restarts++;
            continue;
        }
        if (ret == LBFGS_SUCCESS || ret == LBFGS_ALREADY_MINIMIZED) {
            st->converged = 1;
            st->f = fx;
            break;
        }
        if (r.cancelled) {
            rc = OPT_ECANCELED;
            break;
        }
        if (ret == LBFGSERR_OUTOFMEMORY) {
            rc = OPT_ENOMEM;
            break;
        }
        if (ret == LBFGSERR_MAXIMUMITERATION) {
            st->f = fx;
            break;
        }
        if (r.wants_restart) {   /* requested by the caller: not a failure */
            st->restarts++;
            continue;
        }
        if (!isfinite(fx) && st->iterations == 0 && r.nonfinite) {
            rc = OPT_ENONFINITE;
            break;
        }
        /* Line search failed (rounding, minimum step, too many trials):
         * liblbfgs left xx at the last accepted point. Reset and retry. */
        st->f = fx;
        if (failures++ >= p->max_restarts)
            break;
        st->restarts++;
    }
    memcpy(x, xx, sizeof *x * (size_t)n);
    lbfgs_free(xx);
    free(good);
    return rc;
}
