/* opt_lbfgs.c — see opt_lbfgs.h. L-BFGS as in Nocedal & Wright (Alg. 7.4,
 * two-loop recursion, H0 = sᵀy/yᵀy of the newest pair) with a backtracking
 * Armijo line search (halving, sufficient decrease 1e-4, 40 trials), liblbfgs
 * 1.10's conventions: a first step of unit
 * length along −g when no pair is held, step 1 otherwise. A pair is kept
 * only when sᵀy > 0 (Armijo alone does not guarantee it). No energy
 * knowledge here. */
#include "opt/opt_lbfgs.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define OPT_FTOL 1e-4            /* Armijo sufficient decrease */
#define OPT_MAX_LINESEARCH 40    /* trials per line search */

void opt_params_init(opt_params *p)
{
    p->max_iter = 50;
    p->gtol = 1e-8;
    p->memory = 6;
    p->rel_decrease = 0;
    p->max_restarts = 2;
}

struct opt_memory {
    int n, m;
    int count, head;     /* pairs held; slot of the next pair to write */
    double *s, *y;       /* m by n */
    double *rho, *alpha; /* m */
    double *g, *d, *xt, *gt;   /* scratch, n each */
};

opt_memory *opt_memory_new(int n, int pairs)
{
    if (n <= 0 || pairs < 1)
        return NULL;
    opt_memory *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    size_t nn = (size_t)n;
    m->n = n;
    m->m = pairs;
    m->s = malloc(sizeof(double) * nn * (size_t)pairs);
    m->y = malloc(sizeof(double) * nn * (size_t)pairs);
    m->rho = malloc(sizeof(double) * (size_t)pairs);
    m->alpha = malloc(sizeof(double) * (size_t)pairs);
    m->g = malloc(sizeof(double) * nn);
    m->d = malloc(sizeof(double) * nn);
    m->xt = malloc(sizeof(double) * nn);
    m->gt = malloc(sizeof(double) * nn);
    if (!m->s || !m->y || !m->rho || !m->alpha || !m->g || !m->d || !m->xt || !m->gt) {
        opt_memory_free(m);
        return NULL;
    }
    return m;
}

void opt_memory_free(opt_memory *m)
{
    if (!m)
        return;
    free(m->s);
    free(m->y);
    free(m->rho);
    free(m->alpha);
    free(m->g);
    free(m->d);
    free(m->xt);
    free(m->gt);
    free(m);
}

int opt_memory_pairs(const opt_memory *m)
{
    return m->count;
}

static double dot(const double *a, const double *b, int n)
{
    double s = 0;
#pragma omp simd reduction(+ : s)
    for (int i = 0; i < n; i++)
        s += a[i] * b[i];
    return s;
}

/* Slot of the k-th newest pair (k = 0: newest). */
static int slot(const opt_memory *m, int k)
{
    return ((m->head - 1 - k) % m->m + m->m) % m->m;
}

void opt_memory_add_diagonal(opt_memory *m, const double *d, double c)
{
    /* Newest first; a pair that is no curvature pair any more ends the
     * memory there (it and the older ones are dropped, the ring order
     * stays). With c·d >= 0, as for a growing weight, none is dropped. */
    for (int k = 0; k < m->count; k++) {
        int j = slot(m, k);
        const double *s = m->s + (size_t)j * m->n;
        double *y = m->y + (size_t)j * m->n;
        double ys = 0;
        for (int i = 0; i < m->n; i++) {
            y[i] += c * d[i] * s[i];
            ys += y[i] * s[i];
        }
        if (!(ys > 0) || !isfinite(ys)) {
            m->count = k;
            break;
        }
        m->rho[j] = 1.0 / ys;
    }
}

/* d = −H·g by the two-loop recursion over the pairs held; −g/|g| (a unit
 * step) when there are none or steepest is set. */
static void direction(opt_memory *m, const double *g, double gnorm, int steepest)
{
    const int n = m->n;
    double *d = m->d;
    if (m->count == 0 || steepest) {
        double c = gnorm > 0 ? 1.0 / gnorm : 1.0;
        for (int i = 0; i < n; i++)
            d[i] = -c * g[i];
        return;
    }
    /* Each pass applies one pair's update and takes the dot product the
     * next pair needs: count + 1 passes over d per loop instead of 2·count. */
    int j = slot(m, 0);
    double a = 0;
    for (int i = 0; i < n; i++) {
        d[i] = -g[i];
        a += m->s[(size_t)j * n + i] * d[i];
    }
    for (int k = 0; k < m->count; k++) {
        j = slot(m, k);
        a *= m->rho[j];
        m->alpha[j] = a;
        const double *y = m->y + (size_t)j * n;
        const double *s1 = k + 1 < m->count ? m->s + (size_t)slot(m, k + 1) * n : NULL;
        double next = 0;
        if (s1) {
#pragma omp simd reduction(+ : next)
            for (int i = 0; i < n; i++) {
                d[i] -= a * y[i];
                next += s1[i] * d[i];
            }
        } else {
            for (int i = 0; i < n; i++)
                d[i] -= a * y[i];
        }
        a = next;
    }
    j = slot(m, 0);
    const double *y0 = m->y + (size_t)j * n;
    double h0 = 1.0 / (m->rho[j] * dot(y0, y0, n));   /* sᵀy / yᵀy */
    j = slot(m, m->count - 1);
    const double *yo = m->y + (size_t)j * n;
    double b = 0;
#pragma omp simd reduction(+ : b)
    for (int i = 0; i < n; i++) {
        d[i] *= h0;
        b += yo[i] * d[i];
    }
    for (int k = m->count - 1; k >= 0; k--) {
        j = slot(m, k);
        double c = m->alpha[j] - m->rho[j] * b;
        const double *sv = m->s + (size_t)j * n;
        const double *y1 = k > 0 ? m->y + (size_t)slot(m, k - 1) * n : NULL;
        double next = 0;
        if (y1) {
#pragma omp simd reduction(+ : next)
            for (int i = 0; i < n; i++) {
                d[i] += c * sv[i];
                next += y1[i] * d[i];
            }
        } else {
            for (int i = 0; i < n; i++)
                d[i] += c * sv[i];
        }
        b = next;
    }
}

/* Stores s = xt − x, y = gt − g when sᵀy > 0 (over the oldest pair when
 * the memory is full; a pair that fails the test writes nothing). */
static void remember(opt_memory *m, const double *x, const double *g)
{
    const int n = m->n;
    double ys = 0;
#pragma omp simd reduction(+ : ys)
    for (int i = 0; i < n; i++)
        ys += (m->xt[i] - x[i]) * (m->gt[i] - g[i]);
    if (!(ys > 0) || !isfinite(ys))
        return;
    double *s = m->s + (size_t)m->head * n, *y = m->y + (size_t)m->head * n;
    for (int i = 0; i < n; i++) {
        s[i] = m->xt[i] - x[i];
        y[i] = m->gt[i] - g[i];
    }
    m->rho[m->head] = 1.0 / ys;
    m->head = (m->head + 1) % m->m;
    if (m->count < m->m)
        m->count++;
}

/* f and g at x; non-finite is reported as +inf. */
static double evaluate(opt_eval_fn eval, void *ctx, const double *x, double *g, int n,
                       opt_stats *st)
{
    st->evaluations++;
    double f = eval(ctx, x, g, n);
    int bad = !isfinite(f);
    for (int i = 0; i < n && !bad; i++)
        bad = !isfinite(g[i]);
    return bad ? INFINITY : f;
}

int opt_minimize(int n, double *x, opt_eval_fn eval, opt_iter_fn iter, void *ctx,
                 const opt_params *p, opt_memory *mem, opt_stats *st)
{
    if (n <= 0 || p->max_iter < 1 || !(p->gtol > 0) || p->memory < 1 || p->max_restarts < 0 ||
        !(p->rel_decrease >= 0 && p->rel_decrease < 1) ||
        (mem && mem->n != n))
        return OPT_EPARAM;
    memset(st, 0, sizeof *st);
    opt_memory *own = NULL;
    if (!mem && !(mem = own = opt_memory_new(n, p->memory)))
        return OPT_ENOMEM;
    double *g = mem->g, *d = mem->d, *xt = mem->xt, *gt = mem->gt;
    int rc = OPT_OK, failures = 0, steepest = 0;
    double f = evaluate(eval, ctx, x, g, n, st);
    int at_x = 1;               /* the last evaluation was at x */
    if (!isfinite(f)) {
        rc = OPT_ENONFINITE;
        goto done;
    }
    double f0 = f;
    while (st->iterations < p->max_iter) {
        double gnorm = sqrt(dot(g, g, n)), xnorm = sqrt(dot(x, x, n));
        if (gnorm < p->gtol * (xnorm > 1 ? xnorm : 1)) {
            st->converged = 1;
            break;
        }
        direction(mem, g, gnorm, steepest);
        double gd = dot(g, d, n);
        if (!(gd < 0) && !steepest) {  /* not downhill (rounding in the pairs) */
            st->restarts++;
            direction(mem, g, gnorm, steepest = 1);
            gd = dot(g, d, n);
        }
        double step = 1.0, ft = INFINITY;
        int accepted = 0;
        for (int ls = 0; ls < OPT_MAX_LINESEARCH && !accepted; ls++, step *= 0.5) {
            for (int i = 0; i < n; i++)
                xt[i] = x[i] + step * d[i];
            ft = evaluate(eval, ctx, xt, gt, n, st);
            at_x = 0;
            /* strict decrease too: near the minimum the Armijo bound
             * rounds to f and would accept steps that change nothing */
            accepted = ft <= f + OPT_FTOL * step * gd && ft < f;   /* false for +inf */
        }
        if (!accepted) {
            /* No decrease along d: with pairs, try again along −g; along
             * −g, this is as far as the line search gets (rounding). The
             * pairs stay: they serve the next solve. */
            if (steepest || mem->count == 0 || failures++ >= p->max_restarts)
                break;
            st->restarts++;
            steepest = 1;
            continue;
        }
        steepest = 0;
        int stall = f - ft < p->rel_decrease * (f0 - ft);
        remember(mem, x, g);
        memcpy(x, xt, sizeof(double) * (size_t)n);
        memcpy(g, gt, sizeof(double) * (size_t)n);
        f = ft;
        at_x = 1;
        st->iterations++;
        if (iter) {
            int v = iter(ctx, x, f, sqrt(dot(g, g, n)), st->iterations);
            if (v == OPT_ITER_CANCEL) {
                rc = OPT_ECANCELED;
                break;
            }
            if (v == OPT_ITER_CHANGED) {
                st->changes++;
                f = evaluate(eval, ctx, x, g, n, st);
                at_x = 1;
                if (!isfinite(f)) {
                    rc = OPT_ENONFINITE;
                    break;
                }
                f0 += f - ft;   /* the decrease so far is the solver's, not the change's */
            }
        }
        if (stall) {
            st->stalled = 1;
            break;
        }
    }
    if (!st->converged && rc == OPT_OK) {
        double gnorm = sqrt(dot(g, g, n)), xnorm = sqrt(dot(x, x, n));
        st->converged = gnorm < p->gtol * (xnorm > 1 ? xnorm : 1);
    }
    st->f = f;
    st->last_at_x = at_x;
done:
    opt_memory_free(own);
    return rc;
}
