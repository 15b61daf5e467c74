/* test_opt_lbfgs.c — the inner solver: converges on a quadratic and on
 * Rosenbrock, honours the iteration cap, cancels, evaluates again when the
 * objective changes, and starts warm from kept correction pairs. */
#include "support/harness.h"
#include "opt/opt_lbfgs.h"

static double quad(void *ctx, const double *x, double *g, int n)
{
    (void)ctx;
    double f = 0;
    for (int i = 0; i < n; i++) {
        double c = 1.0 + i;  /* condition number n */
        f += 0.5 * c * (x[i] - 1) * (x[i] - 1);
        g[i] = c * (x[i] - 1);
    }
    return f;
}

static double rosen(void *ctx, const double *x, double *g, int n)
{
    (void)ctx;
    double f = 0;
    for (int i = 0; i < n; i++) g[i] = 0;
    for (int i = 0; i + 1 < n; i++) {
        double a = x[i + 1] - x[i] * x[i], b = 1 - x[i];
        f += 100 * a * a + b * b;
        g[i] += -400 * a * x[i] - 2 * b;
        g[i + 1] += 200 * a;
    }
    return f;
}

TEST(lbfgs_converges_on_quadratic)
{
    double x[20] = {0};
    opt_params p;
    opt_params_init(&p);
    opt_stats st;
    CHECK_INT(opt_minimize(20, x, quad, NULL, NULL, &p, NULL, &st), OPT_OK);
    CHECK(st.converged);
    for (int i = 0; i < 20; i++)
        CHECK_NEAR(x[i], 1.0, 1e-7);
}

TEST(lbfgs_converges_on_rosenbrock_with_enough_iterations)
{
    double x[4] = {-1.2, 1, -1.2, 1};
    opt_params p;
    opt_params_init(&p);
    p.max_iter = 500;
    opt_stats st;
    CHECK_INT(opt_minimize(4, x, rosen, NULL, NULL, &p, NULL, &st), OPT_OK);
    for (int i = 0; i < 4; i++)
        CHECK_NEAR(x[i], 1.0, 1e-5);
}

TEST(lbfgs_stops_at_iteration_cap_with_lower_energy)
{
    double x[4] = {-1.2, 1, -1.2, 1}, g[4];
    double f0 = rosen(NULL, x, g, 4);
    opt_params p;
    opt_params_init(&p);
    p.max_iter = 5;
    opt_stats st;
    CHECK_INT(opt_minimize(4, x, rosen, NULL, NULL, &p, NULL, &st), OPT_OK);
    CHECK(st.iterations <= 5);
    CHECK(!st.converged);
    CHECK(rosen(NULL, x, g, 4) < f0);
    CHECK_NEAR(st.f, rosen(NULL, x, g, 4), 1e-12);
}

static int cancel_at_3(void *ctx, const double *x, double fx, double gnorm, int iter)
{
    (void)ctx; (void)x; (void)fx; (void)gnorm;
    return iter >= 3 ? OPT_ITER_CANCEL : OPT_ITER_GO;
}

TEST(lbfgs_callback_cancels)
{
    double x[4] = {-1.2, 1, -1.2, 1};
    opt_params p;
    opt_params_init(&p);
    opt_stats st;
    CHECK_INT(opt_minimize(4, x, rosen, cancel_at_3, NULL, &p, NULL, &st), OPT_ECANCELED);
    CHECK_INT(st.iterations, 3);
}

static int changed_every_4(void *ctx, const double *x, double fx, double gnorm, int iter)
{
    (void)x; (void)fx; (void)gnorm;
    int *count = ctx;
    if (iter % 4 == 0) {
        (*count)++;
        return OPT_ITER_CHANGED;
    }
    return OPT_ITER_GO;
}

TEST(lbfgs_changed_objective_is_evaluated_again_within_the_budget)
{
    double x[4] = {-1.2, 1, -1.2, 1};
    opt_params p;
    opt_params_init(&p);
    p.max_iter = 30;
    opt_stats st;
    int changes = 0;
    CHECK_INT(opt_minimize(4, x, rosen, changed_every_4, &changes, &p, NULL, &st), OPT_OK);
    CHECK(st.iterations <= 30);
    CHECK(changes >= 5);
    CHECK_INT(st.changes, changes);
    CHECK(st.evaluations >= st.iterations + changes + 1);
}

/* A sequence of quadratics whose diagonal weight grows, as ECTM's β does:
 * kept pairs, corrected by opt_memory_add_diagonal, solve each one in fewer
 * evaluations than cold solves, to the same minimiser (as far as rounding
 * of f lets the line search go). */
typedef struct ramp {
    double w;       /* weight of the moving quadratic term */
    double t;       /* its target */
} ramp;

static double ramped(void *ctx, const double *x, double *g, int n)
{
    const ramp *r = ctx;
    double f = 0;
    for (int i = 0; i < n; i++) {
        double c = 1.0 + i, e = x[i] - 1, u = x[i] - r->t;
        f += 0.5 * c * e * e + 0.5 * r->w * u * u + 0.25 * e * e * e * e;
        g[i] = c * e + r->w * u + e * e * e;
    }
    return f;
}

TEST(lbfgs_warm_memory_saves_evaluations_for_the_same_minimiser)
{
    enum { N = 40, SOLVES = 8 };
    double cold[N] = {0}, warm[N] = {0}, ones[N];
    for (int i = 0; i < N; i++)
        ones[i] = 1;
    opt_params p;
    opt_params_init(&p);
    p.max_iter = 500;
    opt_memory *m = opt_memory_new(N, p.memory);
    CHECK(m);
    int ecold = 0, ewarm = 0;
    double wprev = 0;
    for (int k = 0; k < SOLVES; k++) {
        ramp r = {10.0 * (k + 1), 0.1 * k};
        opt_stats st;
        CHECK_INT(opt_minimize(N, cold, ramped, NULL, &r, &p, NULL, &st), OPT_OK);
        ecold += st.evaluations;
        opt_memory_add_diagonal(m, ones, r.w - wprev);
        wprev = r.w;
        CHECK_INT(opt_minimize(N, warm, ramped, NULL, &r, &p, m, &st), OPT_OK);
        CHECK(opt_memory_pairs(m) > 0);
        ewarm += st.evaluations;
        for (int i = 0; i < N; i++)
            CHECK_NEAR(warm[i], cold[i], 1e-5);
    }
    printf("  %d solves: %d evaluations cold, %d warm\n", SOLVES, ecold, ewarm);
    CHECK(ewarm < ecold);
    opt_memory_free(m);
}

TEST(lbfgs_stops_when_an_iteration_gains_little_of_the_total)
{
    double x[4] = {-1.2, 1, -1.2, 1}, y[4] = {-1.2, 1, -1.2, 1}, g[4];
    double f0 = rosen(NULL, x, g, 4);
    opt_params p;
    opt_params_init(&p);
    p.max_iter = 500;
    opt_stats full, part;
    CHECK_INT(opt_minimize(4, x, rosen, NULL, NULL, &p, NULL, &full), OPT_OK);
    p.rel_decrease = 0.01;
    CHECK_INT(opt_minimize(4, y, rosen, NULL, NULL, &p, NULL, &part), OPT_OK);
    CHECK(part.stalled && !full.stalled);
    CHECK(part.iterations < full.iterations);
    CHECK(part.f < f0);
    p.rel_decrease = 1;
    CHECK_INT(opt_minimize(4, y, rosen, NULL, NULL, &p, NULL, &part), OPT_EPARAM);
}

/* A wrapped ring of pairs (more iterations than pairs), shifted by a zero
 * diagonal: the next solve must take the very same steps as from the
 * untouched copy (the pairs keep their order and values). */
TEST(lbfgs_zero_diagonal_shift_leaves_a_wrapped_memory_as_it_was)
{
    enum { N = 30 };
    double a[N] = {0}, b[N] = {0}, zero[N] = {0}, ones[N];
    for (int i = 0; i < N; i++)
        ones[i] = 1;
    opt_params p;
    opt_params_init(&p);
    p.max_iter = 9;                       /* 9 pairs into a ring of 4 */
    opt_memory *ma = opt_memory_new(N, 4), *mb = opt_memory_new(N, 4);
    CHECK(ma && mb);
    ramp r = {5.0, 0.3};
    opt_stats st;
    CHECK_INT(opt_minimize(N, a, ramped, NULL, &r, &p, ma, &st), OPT_OK);
    CHECK_INT(opt_minimize(N, b, ramped, NULL, &r, &p, mb, &st), OPT_OK);
    CHECK_INT(opt_memory_pairs(ma), 4);
    opt_memory_add_diagonal(mb, zero, 0.0);
    opt_memory_add_diagonal(mb, ones, 0.0);
    CHECK_INT(opt_memory_pairs(mb), 4);
    r.w = 6.0;
    p.max_iter = 20;
    CHECK_INT(opt_minimize(N, a, ramped, NULL, &r, &p, ma, &st), OPT_OK);
    int ea = st.evaluations;
    CHECK_INT(opt_minimize(N, b, ramped, NULL, &r, &p, mb, &st), OPT_OK);
    CHECK_INT(st.evaluations, ea);
    for (int i = 0; i < N; i++)
        CHECK(a[i] == b[i]);
    opt_memory_free(ma);
    opt_memory_free(mb);
}

TEST(lbfgs_memory_of_another_size_is_refused)
{
    double x[4] = {0};
    opt_params p;
    opt_params_init(&p);
    opt_memory *m = opt_memory_new(5, 3);
    CHECK(m);
    opt_stats st;
    CHECK_INT(opt_minimize(4, x, quad, NULL, NULL, &p, m, &st), OPT_EPARAM);
    opt_memory_free(m);
    CHECK(opt_memory_new(0, 3) == NULL);
    CHECK(opt_memory_new(4, 0) == NULL);
}

TEST(lbfgs_refuses_bad_parameters)
{
    double x[2] = {0, 0};
    opt_params p;
    opt_params_init(&p);
    p.gtol = 0;
    opt_stats st;
    CHECK_INT(opt_minimize(2, x, quad, NULL, NULL, &p, NULL, &st), OPT_EPARAM);
}

/* A gradient that turns NaN once (as a collapsing face's normal can):
 * liblbfgs 1.10 stopped there "converged" (NaN gradient norm) or, with a NaN
 * direction, accepted a NaN point. The line search rejects the point and
 * the solve goes on. */
static double quad_nan_once(void *ctx, const double *x, double *g, int n)
{
    int *calls = ctx;
    double f = quad(NULL, x, g, n);
    if (++*calls == 3)
        g[0] = NAN;
    return f;
}

TEST(lbfgs_recovers_from_a_nan_gradient)
{
    double x[20] = {0};
    opt_params p;
    opt_params_init(&p);
    opt_stats st;
    int calls = 0;
    CHECK_INT(opt_minimize(20, x, quad_nan_once, NULL, &calls, &p, NULL, &st), OPT_OK);
    for (int i = 0; i < 20; i++)
        CHECK(isfinite(x[i]));
    CHECK(isfinite(st.f));
    CHECK(st.converged);
    double g[20];
    CHECK(quad(NULL, x, g, 20) < 1e-6);
}
