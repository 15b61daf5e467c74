/* test_corr_progress.c — the whole job's progress (corr__plan.h): every
 * report carries the fraction of the whole job done, weighted by each
 * step's expected cost from the one table, never falling, from the first
 * report (a real one: the start map's) to 1 at the last; the time left is
 * known once some of the job is done; a second RHM run (start auto) and
 * coarse to fine's two ECTM runs are parts of one fraction; ECTM's
 * iterations past the first at which its stop rule may end the run count
 * in full once a run reaches them; and the two
 * iteration counts belong to their stages (--iterations is ECTM's, RHM's is
 * rhm_iterations). */
#include "support/harness.h"
#include "support/testmesh.h"
#include "support/testrun.h"
#include "corr/corr.h"
#include "corr/corr__plan.h"

#include <math.h>
#include <string.h>

typedef struct log {
    int n;
    corr_stage stage[4096];
    int outer[4096], total[4096];
    double fraction[4096], eta[4096], energy[4096];
} log_t;

static int record(void *ctx, const corr_progress *p)
{
    log_t *l = ctx;
    if (l->n < 4096) {
        proto_progress w;
        corr_progress_record(p, &w);
        l->stage[l->n] = p->stage;
        l->outer[l->n] = (int)w.outer;
        l->total[l->n] = (int)w.total;
        l->fraction[l->n] = p->fraction;
        l->eta[l->n] = p->eta_s;
        l->energy[l->n] = w.terms[0][PROTO_TERM_ENERGY] + w.terms[1][PROTO_TERM_ENERGY];
        l->n++;
    }
    return 0;
}

/* The fraction rises from the first report to 1 at the last, never falls;
 * the time left is a time from the first report on. */
static void check_whole_job(const log_t *l)
{
    CHECK(l->n >= 2);
    CHECK(l->fraction[0] > 0 && l->fraction[0] < 1);
    for (int i = 1; i < l->n; i++)
        if (l->fraction[i] < l->fraction[i - 1])
            FAILF("record %d (%s %d/%d): fraction %.6f fell from %.6f", i, proto_stage_name(l->stage[i]),
                  l->outer[i], l->total[i], l->fraction[i], l->fraction[i - 1]);
    CHECK(l->fraction[l->n - 1] == 1);
    for (int i = 0; i < l->n; i++)
        CHECK(isfinite(l->eta[i]) && l->eta[i] >= 0);
    CHECK(l->eta[l->n - 1] == 0);
}

/* The icosphere pair (the target scaled and bent) at level lv, 6
 * identity landmarks. */
static void pair(int lv, mesh **S, mesh **T)
{
    *S = testmesh_icosphere(lv);
    *T = testmesh_icosphere(lv);
    for (int i = 0; i < (*T)->nv; i++) {
        double *x = &(*T)->v[3 * i];
        x[0] *= 1.3;
        x[2] += 0.15 * x[0] * x[0];
    }
}

static int lsrc[6] = {0, 1, 2, 3, 4, 5};

TEST_T(a_landmark_jobs_fraction_rises_over_every_stage_to_one, 120)
{
    mesh *S, *T;
    pair(2, &S, &T);
    lmk_set L = {6, lsrc, lsrc};
    rhm_params rp;
    rhm_params_init(&rp);
    rp.iterations = 12;
    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 9;
    p.beta_ramp = 9;
    p.inner_iterations = 10;
    corr_input in = {S, T, "s", "t", &L, NULL, NULL, &rp, CORR_CHAIN_ALL, 0, CORR_DDM_AUTO};
    static log_t l;
    memset(&l, 0, sizeof l);
    ectm_result r;
    char err[512];
    if (corr_run(&in, &p, record, &l, &r, err, sizeof err))
        FAILF("%s", err);
    /* the first report is a real one: the start map with its energies,
     * never a record of zeros before it */
    CHECK_INT(l.stage[0], CORR_STAGE_START);
    CHECK(l.energy[0] > 0);
    check_whole_job(&l);
    /* each stage counts its own iterations: RHM to rhm_iterations, ECTM to
     * iterations */
    int rhm_total = 0, ectm_total = 0, repairs = 0;
    for (int i = 0; i < l.n; i++) {
        if (l.stage[i] == CORR_STAGE_RHM)
            rhm_total = l.total[i];
        if (l.stage[i] == CORR_STAGE_ECTM)
            ectm_total = l.total[i];
        repairs += l.stage[i] == CORR_STAGE_REPAIR;
    }
    CHECK_INT(rhm_total, 12);
    CHECK_INT(ectm_total, 9);
    CHECK_INT(repairs, 4);   /* RHM's maps and ECTM's: a start and an end each */
    /* the fraction after the start map is the start's expected share of
     * the job: its cost over the sum of the planned steps' */
    int nv = S->nv + T->nv;
    double second = corr__plan_cost(CORR__START_FMAP, nv) + 12 * corr__plan_cost(CORR__RHM, nv) +
                    corr__plan_cost(CORR__REPAIR, nv);   /* start auto's second run, maybe */
    double total = corr__plan_cost(CORR__START, nv) + 12 * corr__plan_cost(CORR__RHM, nv) +
                   corr__plan_cost(CORR__REPAIR, nv) + CORR__RERUN_SHARE * second +
                   9 * corr__plan_cost(CORR__ECTM, nv) + corr__plan_cost(CORR__REPAIR_RELAX, nv);
    CHECK_NEAR(l.fraction[0], corr__plan_cost(CORR__START, nv) / total, 1e-9);
    ectm_result_close(&r);
    mesh_free(S);
    mesh_free(T);
}

/* Reports fed by hand to the plan of a start-auto job: the second RHM run
 * that may follow the first is weighted by how often it runs until RHM
 * decides; then it counts in full, or goes; either way the fraction goes on
 * from where it was, never falling, to 1. */
static void feed_rhm(corr__plan *pl, double *t, double *last)
{
    rhm_report h = {0};
    h.total = 4;
    for (int k = 0; k <= 4; k++) {
        h.iteration = k;
        corr_progress cp = {.stage = k ? CORR_STAGE_RHM : CORR_STAGE_START, .rhm = &h, .elapsed = *t += 1};
        corr__plan_update(pl, &cp);
        CHECK(cp.fraction >= *last && cp.fraction < 1);
        *last = cp.fraction;
    }
}

static void feed_repair(corr__plan *pl, double *t, double *last)
{
    corr_repair_report rr = {0, 2};
    for (int d = 0; d <= 2; d += 2) {
        rr.done = d;
        corr_progress cp = {.stage = CORR_STAGE_REPAIR, .repair = &rr, .elapsed = *t += 1};
        corr__plan_update(pl, &cp);
        CHECK(cp.fraction >= *last);
        *last = cp.fraction;
    }
}

/* ECTM's reports from..upto fed by hand. */
static void feed_ectm(corr__plan *pl, int from, int upto, double *t, double *last)
{
    ectm_report e = {0};
    e.total = upto;
    for (int k = from; k <= upto; k++) {
        e.outer = k;
        corr_progress cp = {.stage = CORR_STAGE_ECTM, .ectm = &e, .elapsed = *t += 1};
        corr__plan_update(pl, &cp);
        if (cp.fraction < *last || cp.fraction >= 1)
            FAILF("ectm %d: fraction %.6f after %.6f", k, cp.fraction, *last);
        *last = cp.fraction;
    }
}

static lmk_set six = {6, lsrc, lsrc};

/* The level-1 icosphere pair, 6 landmarks, RHM's 4 iterations, ECTM's
 * defaults: a job whose plan the tests feed by hand. */
static corr_input small_job(mesh **S, mesh **T, rhm_params *rp, ectm_params *p)
{
    pair(1, S, T);
    rhm_params_init(rp);
    rp->iterations = 4;
    ectm_params_init(p);
    return (corr_input){*S, *T, "s", "t", &six, NULL, NULL, rp, CORR_CHAIN_ALL, 0, CORR_DDM_AUTO};
}

TEST(start_autos_second_rhm_run_continues_the_fraction_whether_it_runs_or_not)
{
    mesh *S, *T;
    rhm_params rp;
    ectm_params p;
    corr_input in = small_job(&S, &T, &rp, &p);
    CHECK_INT(rp.start, RHM_START_AUTO);
    p.iterations = 3;
    for (int again = 0; again < 2; again++) {
        corr__plan pl;
        corr__plan_build(&pl, &in, &p, &rp);
        CHECK_INT(pl.n, 5 + 3);           /* and the second run's start, iterations and repair */
        double last = 0, t = 0;
        feed_rhm(&pl, &t, &last);
        feed_repair(&pl, &t, &last);
        double before = pl.last;
        corr__plan_rerun(&pl, again);
        CHECK_INT(pl.n, again ? 8 : 5);
        CHECK(pl.last == before);
        if (again) {
            feed_rhm(&pl, &t, &last);
            feed_repair(&pl, &t, &last);
        }
        feed_ectm(&pl, 1, 3, &t, &last);
        feed_repair(&pl, &t, &last);
        CHECK(last == 1);
        CHECK(pl.last == 1);
    }
    mesh_free(S);
    mesh_free(T);
}

/* ECTM with its stop rule: its iterations up to the first at which the
 * rule may end the run count in full, those beyond it to the cap at
 * CORR__BEYOND_SHARE, so that a run that ends there (most do) ends near
 * the fraction the plan gave it; a run that goes on counts them in full
 * from there, the fraction never falling, to 1 either way. */
TEST(ectm_iterations_past_the_first_possible_stop_count_once_a_run_reaches_them)
{
    mesh *S, *T;
    rhm_params rp;
    ectm_params p;
    corr_input in = small_job(&S, &T, &rp, &p);
    rp.start = RHM_START_DISTANCES;
    CHECK_INT(p.iterations, 600);
    CHECK_INT(ectm_first_stop(&p), 300);
    int nv = S->nv + T->nv;
    for (int on = 0; on < 2; on++) {
        corr__plan pl;
        corr__plan_build(&pl, &in, &p, &rp);
        CHECK_INT(pl.n, 6);   /* start, RHM, repair, ECTM to 300, beyond, repair */
        CHECK_INT(pl.s[3].count, 300);
        CHECK_INT(pl.s[4].count, 300);
        CHECK(pl.s[4].beyond && !pl.s[3].beyond);
        double last = 0, t = 0;
        feed_rhm(&pl, &t, &last);
        feed_repair(&pl, &t, &last);
        feed_ectm(&pl, 1, 300, &t, &last);
        /* at the first possible stop: all but the beyond share and the last repair */
        double ectm = corr__plan_cost(CORR__ECTM, nv), relax = corr__plan_cost(CORR__REPAIR_RELAX, nv);
        double total = corr__plan_cost(CORR__START, nv) + 4 * corr__plan_cost(CORR__RHM, nv) +
                       corr__plan_cost(CORR__REPAIR, nv) + 300 * ectm +
                       CORR__BEYOND_SHARE * 300 * ectm + relax;
        CHECK_NEAR(last, (total - CORR__BEYOND_SHARE * 300 * ectm - relax) / total, 1e-9);
        if (on) {
            double at300 = last;
            feed_ectm(&pl, 301, 450, &t, &last);
            CHECK(!pl.s[4].beyond);
            CHECK_NEAR(pl.s[4].done, 0.5, 1e-12);
            CHECK(last > at300);
        }
        feed_repair(&pl, &t, &last);
        CHECK(last == 1);
    }
    mesh_free(S);
    mesh_free(T);
}

TEST_T(coarse_to_fine_runs_both_ectm_runs_in_one_fraction, 300)
{
    mesh *S, *T;
    pair(4, &S, &T);               /* 2562 vertices each: over twice the coarse size */
    lmk_set L = {6, lsrc, lsrc};
    rhm_params rp;
    rhm_params_init(&rp);
    rp.iterations = 5;
    rp.coarse = 500;
    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 4;
    p.beta_ramp = 4;
    p.inner_iterations = 10;
    corr_input in = {S, T, "s", "t", &L, NULL, NULL, &rp, CORR_CHAIN_ALL, 0, CORR_DDM_AUTO};
    CHECK(corr_coarse_wanted(&in));
    static log_t l;
    memset(&l, 0, sizeof l);
    ectm_result r;
    char err[512];
    if (corr_run(&in, &p, record, &l, &r, err, sizeof err))
        FAILF("%s", err);
    check_whole_job(&l);
    int last_ectm = 0, repairs = 0;
    double at_coarse_end = -1;
    for (int i = 0; i < l.n; i++) {
        if (l.stage[i] == CORR_STAGE_ECTM) {
            CHECK_INT(l.total[i], 8);
            last_ectm = l.outer[i];
            if (l.outer[i] == 4)
                at_coarse_end = l.fraction[i];
        }
        repairs += l.stage[i] == CORR_STAGE_REPAIR;
    }
    CHECK_INT(last_ectm, 8);
    CHECK_INT(repairs, 8);   /* RHM's and ECTM's on the coarse pair, the carried maps, ECTM's last */
    /* the fine ECTM on 5124 vertices costs more than the coarse on 1000: the
     * coarse chain is done well before half the job */
    CHECK(at_coarse_end > 0 && at_coarse_end < 0.5);
    ectm_result_close(&r);
    mesh_free(S);
    mesh_free(T);
}

TEST(each_iteration_count_names_its_stage_in_the_help)
{
    static char out[1 << 16];
    CHECK_INT(testrun("build/meshcorr match --help 2>&1", out, sizeof out), 0);
    CHECK_STR_HAS(out, "ECTM: outer iterations K at most (the RHM stage before it has its own count, rhm_iterations)");
    CHECK_STR_HAS(out, "RHM: at most this many iterations (not ECTM's: that count is iterations)");
}
