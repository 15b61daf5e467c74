/* test_opt_lbfgs.c — the inner solver: converges on a quadratic and on
 * Rosenbrock, honours the iteration cap, cancels and restarts on request. */
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
    CHECK_INT(opt_minimize(20, x, quad, NULL, NULL, &p, &st), OPT_OK);
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
    CHECK_INT(opt_minimize(4, x, rosen, NULL, NULL, &p, &st), OPT_OK);
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
    CHECK_INT(opt_minimize(4, x, rosen, NULL, NULL, &p, &st), OPT_OK);
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
    CHECK_INT(opt_minimize(4, x, rosen, cancel_at_3, NULL, &p, &st), OPT_ECANCELED);
    CHECK_INT(st.iterations, 3);
}

static int restart_every_4(void *ctx, const double *x, double fx, double gnorm, int iter)
{
    (void)x; (void)fx; (void)gnorm;
    int *count = ctx;
    if (iter % 4 == 0) {
        (*count)++;
        return OPT_ITER_RESTART;
    }
    return OPT_ITER_GO;
}

TEST(lbfgs_restart_keeps_total_iteration_budget)
{
    double x[4] = {-1.2, 1, -1.2, 1};
    opt_params p;
    opt_params_init(&p);
    p.max_iter = 30;
    opt_stats st;
    int restarts = 0;
    CHECK_INT(opt_minimize(4, x, rosen, restart_every_4, &restarts, &p, &st), OPT_OK);
    CHECK(st.iterations <= 30);
    CHECK(restarts >= 5);
    CHECK_INT(st.restarts, restarts);
}

TEST(lbfgs_refuses_bad_parameters)
{
    double x[2] = {0, 0};
    opt_params p;
    opt_params_init(&p);
    p.gtol = 0;
    opt_stats st;
    CHECK_INT(opt_minimize(2, x, quad, NULL, NULL, &p, &st), OPT_EPARAM);
}

/* A gradient that turns NaN once (as a collapsing face's normal can): alone,
 * liblbfgs 1.10 stops there "converged" (NaN gradient norm) or, with a NaN
 * direction, accepts a NaN point. The driver rejects the point and goes on. */
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
    CHECK_INT(opt_minimize(20, x, quad_nan_once, NULL, &calls, &p, &st), OPT_OK);
    for (int i = 0; i < 20; i++)
        CHECK(isfinite(x[i]));
    CHECK(isfinite(st.f));
    CHECK(st.converged);
    double g[20];
    CHECK(quad(NULL, x, g, 20) < 1e-6);
}
