/* test_ectm.c — the ECTM alternating optimisation: parameters, monotone
 * energy at fixed β, the stop rule, cancellation, injective and partial models, and the
 * authors' own demo input (SHREC'07 381 -> 390, HOT initial maps) against
 * their published result. */
#include "support/harness.h"
#include "ectm/ectm.h"
#include "geo/geo_area.h"
#include "metric/metric.h"
#include "support/testdemo.h"
#include "support/testmesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct trace {
    int n;
    double energy[700];
    double beta[700];
    int cancel_at;
} trace;

static int record(void *ctx, const ectm_report *r)
{
    trace *t = ctx;
    if (t->n < 700) {
        t->energy[t->n] = r->energy;
        t->beta[t->n] = r->beta;
        t->n++;
    }
    CHECK(r->dir[0].inner_iterations <= 50);
    CHECK(isfinite(r->dir[0].w_mem) && isfinite(r->dir[0].w_bnd));
    CHECK(r->elapsed >= 0);
    return t->cancel_at && r->outer >= t->cancel_at;
}

TEST(params_defaults_are_released_code_values)
{
    ectm_params p;
    ectm_params_init(&p);
    CHECK_NEAR(p.alpha, 20, 0);
    CHECK_NEAR(p.eta, 2e-3 / 3, 1e-18);
    CHECK_NEAR(ectm_beta(&p, 1), 500, 1e-9);
    CHECK_NEAR(ectm_beta(&p, 2), 1000, 1e-9);
    CHECK_NEAR(ectm_beta(&p, 100), 50000, 1e-6);
    CHECK_NEAR(ectm_beta(&p, 200), 1e5, 1e-9);
    CHECK_NEAR(ectm_beta(&p, 300), 1e5, 1e-9);
    CHECK_NEAR(p.gamma, 1e4, 0);
    CHECK_INT(p.iterations, 600);
    CHECK_NEAR(p.stop_change, 0.1, 0);
    ectm_params_paper(&p);
    CHECK_NEAR(ectm_beta(&p, 1), 1e3, 1e-9);
    CHECK_NEAR(ectm_beta(&p, 200), 2e5, 1e-9);
    CHECK_NEAR(p.gamma, 2e4, 0);
}

TEST(params_check_names_the_bad_field)
{
    ectm_params p;
    char err[256];
    ectm_params_init(&p);
    p.alpha = -1;
    CHECK_INT(ectm_params_check(&p, err, sizeof err), KIND_EPARAMS);
    CHECK_STR_HAS(err, "alpha");
    ectm_params_init(&p);
    p.gamma = NAN;
    CHECK_INT(ectm_params_check(&p, err, sizeof err), KIND_EPARAMS);
    CHECK_STR_HAS(err, "gamma");
    ectm_params_init(&p);
    p.beta_ramp = 0;
    CHECK_INT(ectm_params_check(&p, err, sizeof err), KIND_EPARAMS);
    CHECK_STR_HAS(err, "beta_ramp = 0: out of range [1, 1000000]");
}

TEST(map_sized_for_other_meshes_is_refused)
{
    testdemo d;
    testdemo_load(&d);
    ectm_params p;
    ectm_params_init(&p);
    ectm_result r;
    char err[256];
    CHECK_INT(ectm_run(d.T, d.S, d.P0, NULL, NULL, &p, NULL, NULL, &r, err, sizeof err), KIND_EMAP);
    CHECK_STR_HAS(err, "6938 -> 9239");
    testdemo_free(&d);
}

/* The identity of a mesh onto itself or onto a copy scaled as a whole
 * gives every face the factor 1; onto a copy whose upper half is grown,
 * the upper faces get the larger factors, and the total area stays. */
TEST(area_scale_follows_the_maps_regional_area)
{
    mesh *X = testmesh_icosphere(3), *Y = mesh_copy(X), *Z = mesh_copy(X);
    bmap *I = testmesh_identity(X);
    CHECK(X && Y && Z && I);
    for (int i = 0; i < 3 * Y->nv; i++)
        Y->v[i] *= 3;
    for (int v = 0; v < Z->nv; v++)
        if (Z->v[3 * v + 2] > 0)
            for (int k = 0; k < 3; k++)
                Z->v[3 * v + k] *= 1 + Z->v[3 * v + 2];
    double *s1 = ectm_area_scale(X, X, I), *s3 = ectm_area_scale(X, Y, I);
    double *sz = ectm_area_scale(X, Z, I);
    double *a = malloc(sizeof(double) * (size_t)X->nf);
    CHECK(s1 && s3 && sz && a);
    geo_face_areas(X, a);
    double up = 0, wu = 0, down = 0, wd = 0, total = 0, w = 0;
    for (int t = 0; t < X->nf; t++) {
        CHECK(fabs(s1[t] - 1) < 1e-9 && fabs(s3[t] - 1) < 1e-9);
        double zc = (X->v[3 * X->f[3 * t] + 2] + X->v[3 * X->f[3 * t + 1] + 2] +
                     X->v[3 * X->f[3 * t + 2] + 2]) / 3;
        if (zc > 0.5)
            up += a[t] * sz[t], wu += a[t];
        else if (zc < -0.5)
            down += a[t] * sz[t], wd += a[t];
        total += a[t] * log(sz[t]);
        w += a[t];
    }
    printf("  grown upper half: factor %.3f above z = 0.5, %.3f below z = -0.5\n", up / wu,
           down / wd);
    CHECK(up / wu > 1.5 * (down / wd));
    CHECK(fabs(total / w) < 1e-9);
    free(a);
    free(s1);
    free(s3);
    free(sz);
    bmap_free(I);
    mesh_free(X);
    mesh_free(Y);
    mesh_free(Z);
}

TEST_T(energy_never_increases_at_fixed_beta, 300)
{
    testdemo d;
    testdemo_load(&d);
    ectm_params p;
    ectm_params_init(&p);
    p.beta0 = p.beta1 = 5e4;
    p.iterations = 6;
    trace t = {0};
    ectm_result r;
    char err[256];
    if (ectm_run(d.S, d.T, d.P0, d.Q0, NULL, &p, record, &t, &r, err, sizeof err))
        FAILF("%s", err);
    CHECK_INT(t.n, 6);
    for (int k = 1; k < t.n; k++) {
        printf("  outer %d energy %.12g\n", k + 1, t.energy[k]);
        if (t.energy[k] > t.energy[k - 1] * (1 + 1e-9))
            FAILF("energy rose from %.12g to %.12g at outer iteration %d",
                  t.energy[k - 1], t.energy[k], k + 1);
    }
    ectm_result_close(&r);
    testdemo_free(&d);
}

/* The identity of a sphere onto a copy stretched along z: the energy
 * settles within the first iterations. The stop rule waits until β has
 * been constant for a whole window (ramp 50, so iteration 150), then stops
 * at its first look; stop_change 0 runs every iteration. */
TEST_T(stop_rule_ends_a_settled_run_after_one_window_at_constant_beta, 300)
{
    mesh *X = testmesh_icosphere(2), *Y = mesh_copy(X);
    CHECK(X && Y);
    for (int v = 0; v < Y->nv; v++)
        Y->v[3 * v + 2] *= 1.3;
    bmap *I = testmesh_identity(X);
    CHECK(I != NULL);
    ectm_params p;
    ectm_params_init(&p);
    p.threads = 1;
    p.beta_ramp = 50;
    p.iterations = 400;
    trace t = {0};
    ectm_result r;
    char err[256];
    if (ectm_run(X, Y, I, I, NULL, &p, record, &t, &r, err, sizeof err))
        FAILF("%s", err);
    printf("  stopped after %d of %d iterations, energy %.9g -> %.9g over the last %d\n", t.n,
           p.iterations, t.energy[t.n - 1 - ECTM_STOP_WINDOW], t.energy[t.n - 1], ECTM_STOP_WINDOW);
    CHECK_INT(t.n, 50 + ECTM_STOP_WINDOW);
    CHECK_INT(ectm_first_stop(&p), t.n);   /* what the job's progress plans on */
    CHECK_INT(r.last.outer, t.n);
    CHECK(t.energy[t.n - 1 - ECTM_STOP_WINDOW] - t.energy[t.n - 1] < p.stop_change * t.energy[t.n - 1]);
    ectm_result_close(&r);

    p.stop_change = 0;
    p.iterations = 180;
    memset(&t, 0, sizeof t);
    if (ectm_run(X, Y, I, I, NULL, &p, record, &t, &r, err, sizeof err))
        FAILF("%s", err);
    CHECK_INT(t.n, 180);
    CHECK_INT(ectm_first_stop(&p), 180);
    ectm_result_close(&r);
    bmap_free(I);
    mesh_free(X);
    mesh_free(Y);
}

/* The first iteration at which the stop rule may end a run: a window
 * after β stops growing, or the cap when that comes later. */
TEST(first_possible_stop_is_a_window_after_the_ramp_within_the_cap)
{
    ectm_params p;
    ectm_params_init(&p);
    CHECK_INT(ectm_first_stop(&p), p.beta_ramp + ECTM_STOP_WINDOW);
    CHECK(!ectm_stop_may_end(&p, p.beta_ramp + ECTM_STOP_WINDOW - 1));
    p.beta_ramp = 1;
    CHECK_INT(ectm_first_stop(&p), ECTM_STOP_WINDOW + 1);
    p.iterations = 80;
    CHECK_INT(ectm_first_stop(&p), 80);
    ectm_params_init(&p);
    p.stop_change = 0;
    CHECK_INT(ectm_first_stop(&p), p.iterations);
}

TEST_T(progress_callback_cancels_run, 300)
{
    testdemo d;
    testdemo_load(&d);
    ectm_params p;
    ectm_params_init(&p);
    trace t = {0};
    t.cancel_at = 2;
    ectm_result r;
    char err[256];
    CHECK_INT(ectm_run(d.S, d.T, d.P0, d.Q0, NULL, &p, record, &t, &r, err, sizeof err), KIND_ECANCELLED);
    CHECK_INT(t.n, 2);
    CHECK(r.P == NULL);
    CHECK_STR_HAS(err, "cancelled");
    testdemo_free(&d);
}

TEST_T(injective_model_runs_and_improves_area_distortion, 300)
{
    testdemo d;
    testdemo_load(&d);
    ectm_params p;
    ectm_params_init(&p);
    p.model = ECTM_INJECTIVE;
    p.iterations = 15;
    trace t = {0};
    ectm_result r;
    char err[256];
    if (ectm_run(d.S, d.T, d.P0, NULL, NULL, &p, record, &t, &r, err, sizeof err))
        FAILF("%s", err);
    CHECK(r.Q == NULL && r.Yt == NULL);
    metric_summary m0, m1;
    CHECK_INT(metric_summarize(d.S, d.T, d.P0, &m0), 0);
    CHECK_INT(metric_summarize(d.S, d.T, r.P, &m1), 0);
    printf("  area distortion %.3f -> %.3f\n", m0.mean_abs_log_area, m1.mean_abs_log_area);
    CHECK(m1.mean_abs_log_area < m0.mean_abs_log_area);
    ectm_result_close(&r);
    testdemo_free(&d);
}

TEST_T(missing_reverse_map_is_built_by_nearest_neighbour, 300)
{
    testdemo d;
    testdemo_load(&d);
    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 2;
    ectm_result r;
    char err[256];
    if (ectm_run(d.S, d.T, d.P0, NULL, NULL, &p, NULL, NULL, &r, err, sizeof err))
        FAILF("%s", err);
    CHECK(r.Q != NULL);
    CHECK_INT(r.Q->n, d.T->nv);
    for (int j = 0; j < r.Q->n; j++) {
        CHECK(r.Q->face[j] >= 0 && r.Q->face[j] < d.S->nf);
        CHECK_NEAR(r.Q->w[3 * j] + r.Q->w[3 * j + 1] + r.Q->w[3 * j + 2], 1.0, 1e-9);
    }
    ectm_result_close(&r);
    testdemo_free(&d);
}

TEST_T(partial_matching_keeps_scale_and_runs, 300)
{
    testdemo d;
    testdemo_load(&d);
    ectm_params p;
    ectm_params_init(&p);
    p.partial = 1;
    p.iterations = 2;
    ectm_result r;
    char err[256];
    if (ectm_run(d.S, d.T, d.P0, d.Q0, NULL, &p, NULL, NULL, &r, err, sizeof err))
        FAILF("%s", err);
    CHECK(r.P && r.Q);
    CHECK(isfinite(r.last.energy));
    ectm_result_close(&r);
    testdemo_free(&d);
}

/* The authors' demo, full length with the released code's parameters: the
 * final map must land far closer to their result than the initial map. */
TEST_T(demo_381_390_matches_authors_result, 1800)
{
    testdemo d;
    testdemo_load(&d);
    ectm_params p;
    ectm_params_init(&p);
    trace t = {0};
    ectm_result r;
    char err[256];
    if (ectm_run(d.S, d.T, d.P0, d.Q0, NULL, &p, record, &t, &r, err, sizeof err))
        FAILF("%s", err);
    double uv0 = testdemo_uv_distance(&d, d.P0), uv1 = testdemo_uv_distance(&d, r.P);
    metric_summary m0, m1;
    CHECK_INT(metric_summarize(d.S, d.T, d.P0, &m0), 0);
    CHECK_INT(metric_summarize(d.S, d.T, r.P, &m1), 0);
    printf("  uv distance to the authors' result: initial %.4f, final %.4f\n", uv0, uv1);
    printf("  mean |log area ratio|: initial %.3f, final %.3f\n", m0.mean_abs_log_area, m1.mean_abs_log_area);
    printf("  median conformal distortion: initial %.3f, final %.3f\n", m0.median_conformal, m1.median_conformal);
    printf("  flipped %.2f%%, collapsed %.2f%%; time %.1f s (projection %.1f s, L-BFGS %.1f s)\n",
           100 * m1.flipped_fraction, 100 * m1.collapsed_fraction, r.last.elapsed,
           r.last.t_project, r.last.t_solve);
    printf("  outer iterations run: %d of at most %d\n", r.last.outer, p.iterations);
    CHECK_INT(r.last.outer, 300);        /* the released code's count: the stop rule ends it there */
    CHECK_NEAR(uv0, 0.0447, 0.0005);     /* the README's figure for the initial map */
    CHECK(uv1 < uv0 / 4);
    CHECK(uv1 <= 0.005);                 /* the authors' map (0.0024: their code re-run) */
    CHECK(m1.mean_abs_log_area < 0.75 * m0.mean_abs_log_area);
    ectm_result_close(&r);
    testdemo_free(&d);
}
