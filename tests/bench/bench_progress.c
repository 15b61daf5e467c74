/* bench_progress.c — the whole job's progress (corr__plan.h) against the
 * clock on real jobs, and the figures behind the cost table of
 * workers/corr/corr_plan.c (docs/decisions.md, 2026-12-06):
 *
 * - icosphere_642: the icosphere pair of tests/support/testdaemon at level 3
 *   (642 vertices each, the target scaled and bent), 6 identity landmarks;
 * - cow_camel_demo: make demo's pair (cow 2904, camel 9770 vertices) with
 *   deploy/demo's 33 landmark pairs;
 * - shrec07_381_393: SHREC'07 four-legged 381 -> 393 with the BIM
 *   landmarks (Corrs/381.vts, 393.vts);
 * - centaur_coarse_to_fine: TOSCA centaur0 -> centaur1 (15768 vertices
 *   each: over twice the coarse size, so decimated), Corrs/centaur.pid's
 *   landmarks;
 * - gorilla_man_ddm_ectm and gorilla_man_ddm_rhm_ectm: TOSCA_r gorilla_01 ->
 *   man_01 from the published BCICP map, stages ddm,ectm and ddm,rhm,ectm.
 *
 * Each job runs with meshcorr match's defaults (--iterations=K and
 * --rhm-iterations=R shorten them; --only=NAME runs one). Per job it
 * prints every step's measured seconds and its cost per 1000 vertices (the
 * table's unit) next to the table's, then how well the fraction follows
 * the clock: the largest |fraction - t/T| over the records and the time
 * left the records at 25, 50 and 75 % of the run predicted against the
 * time that was left. Prints figures, never fails on time. */
#include "support/harness.h"
#include "support/testcowcamel.h"
#include "support/testgt.h"
#include "support/testmesh.h"
#include "corr/corr.h"
#include "corr/corr__plan.h"
#include "map/vmap.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAX_RECORDS 4096

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct record {
    double t, fraction, eta;
    int stage, outer, total;
} record;

typedef struct run_log {
    double t0;
    int n;
    record r[MAX_RECORDS];
} run_log;

static int on_progress(void *ctx, const corr_progress *p)
{
    run_log *l = ctx;
    if (l->n < MAX_RECORDS) {
        proto_progress w;
        corr_progress_record(p, &w);
        l->r[l->n++] = (record){now() - l->t0, p->fraction, p->eta_s, p->stage, (int)w.outer, (int)w.total};
    }
    return 0;
}

/* A step of the run as the records show it: from the record before its
 * first to its last. */
typedef struct seen {
    const char *phase;
    double secs;
    int units, kv_nv;
} seen;

static void print_step(const char *phase, double secs, int units, int nv)
{
    corr__phase ph = CORR__NPHASES;
    for (int k = 0; k < CORR__NPHASES; k++)
        if (strcmp(corr__phase_name((corr__phase)k), phase) == 0)
            ph = (corr__phase)k;
    double per = units > 0 && nv > 0 ? secs / units / (nv / 1000.0) : NAN;
    printf("    %-10s %8.2f s  %4d unit(s) on %6d vertices: %.4f s per 1000 vertices (table %.4f)\n", phase,
           secs, units, nv, per, ph < CORR__NPHASES ? corr__plan_cost(ph, 1000) : NAN);
}

/* The steps of a landmark or map chain from its records; nv: the pair's
 * vertices, nc: the coarse pair's (coarse to fine), 0 without; from_maps:
 * RHM starts from the given (or denoised) maps. */
static void print_steps(const run_log *l, double total, int nv, int nc, int from_maps)
{
    int i = 0, runs = 0, ectm_runs = 0, repairs = 0;
    double prev = 0;
    while (i < l->n) {
        const record *r = &l->r[i];
        int j = i;
        if (r->stage == CORR_STAGE_START) {
            print_step(from_maps ? "start_maps" : runs++ ? "start_fmap" : "start", r->t - prev, 1, nc ? nc : nv);
            prev = r->t;
            i++;
            continue;
        }
        if (r->stage == CORR_STAGE_REPAIR && r->outer == 0) {
            while (j + 1 < l->n && l->r[j + 1].stage == CORR_STAGE_REPAIR && l->r[j + 1].outer == 0)
                j++;
            const record *e = j + 1 < l->n ? &l->r[j + 1] : r;
            /* the coarse pair's two repairs, then the carry to the meshes and the last */
            int on = nc && repairs < 2 ? nc : nv;
            print_step(i > 0 && l->r[i - 1].stage == CORR_STAGE_ECTM ? "repair_relax" : "repair", e->t - r->t, 1,
                       on);
            repairs++;
            prev = e->t;
            i = j + 2;
            continue;
        }
        while (j + 1 < l->n && l->r[j + 1].stage == r->stage)
            j++;
        int units = r->stage == CORR_STAGE_DDM ? l->r[j].outer : l->r[j].outer - (r->stage == CORR_STAGE_ECTM
                                                                                      ? r->outer - 1 : 0);
        const char *name = r->stage == CORR_STAGE_RHM ? "rhm" : r->stage == CORR_STAGE_ECTM ? "ectm" : "ddm";
        int on = nv;
        if (r->stage == CORR_STAGE_ECTM && nc && ectm_runs++ == 0)
            on = nc;
        else if (r->stage == CORR_STAGE_RHM && nc)
            on = nc;
        print_step(name, l->r[j].t - prev, units, on);
        prev = l->r[j].t;
        i = j + 1;
    }
    printf("    %-10s %8.2f s  (after the last record)\n", "end", total - prev);
}

/* How the fraction follows the clock, and what the time left said. */
static void print_fit(const run_log *l, double total)
{
    double worst = 0, at = 0;
    for (int i = 0; i < l->n; i++) {
        double d = fabs(l->r[i].fraction - l->r[i].t / total);
        if (d > worst) {
            worst = d;
            at = l->r[i].t / total;
        }
    }
    printf("    fraction vs time: largest |fraction - t/T| %.3f (at t/T = %.2f)\n", worst, at);
    for (int q = 1; q <= 3; q++) {
        const record *best = NULL;
        for (int i = 0; i < l->n; i++)
            if (!best || fabs(l->r[i].t - q * total / 4) < fabs(best->t - q * total / 4))
                best = &l->r[i];
        if (best)
            printf("    at t/T = %.2f: fraction %.3f, time left said %.1f s, was %.1f s\n", best->t / total,
                   best->fraction, best->eta, total - best->t);
    }
}

static void run_job(const char *name, const corr_input *in, int coarse_nv)
{
    const char *only = harness_option("only");
    if (only && strcmp(only, name) != 0)
        return;
    ectm_params p;
    ectm_params_init(&p);
    rhm_params rp = *in->rhm;
    const char *o = harness_option("iterations");
    if (o)
        p.iterations = atoi(o);
    if ((o = harness_option("rhm-iterations")))
        rp.iterations = atoi(o);
    p.threads = rp.threads = omp_get_max_threads();
    corr_input job = *in;
    job.rhm = &rp;
    static run_log l;
    memset(&l, 0, sizeof l);
    l.t0 = now();
    ectm_result res = {0};
    char err[1024];
    if (corr_run(&job, &p, on_progress, &l, &res, err, sizeof err))
        FAILF("%s: %s", name, err);
    double total = now() - l.t0;
    int nv = in->S->nv + in->T->nv;
    printf("%s: %d + %d vertices, %d threads, RHM %d, ECTM %d iterations: %.1f s, %d records\n", name,
           in->S->nv, in->T->nv, p.threads, rp.iterations, p.iterations, total, l.n);
    if (coarse_nv) {       /* the decimation reports nothing: timed apart, once more */
        corr_coarse c;
        double t = now();
        if (corr_coarse_open(&job, &c, err, sizeof err))
            FAILF("%s: %s", name, err);
        print_step("decimate", now() - t, 1, nv);
        printf("    (the start below includes the decimation)\n");
        corr_coarse_close(&c);
    }
    print_steps(&l, total, nv, coarse_nv, in->P0 != NULL);
    print_fit(&l, total);
    fflush(stdout);
    ectm_result_close(&res);
}

static rhm_params defaults(void)
{
    rhm_params rp;
    rhm_params_init(&rp);
    return rp;
}

TEST_T(stage_costs_and_the_fraction_against_the_clock, 3600)
{
    rhm_params rp = defaults();
    {   /* the icosphere pair of the daemon's tests, at level 3 */
        mesh *S = testmesh_icosphere(3), *T = testmesh_icosphere(3);
        for (int i = 0; i < T->nv; i++) {
            double *x = &T->v[3 * i];
            x[0] *= 1.3;
            x[2] += 0.15 * x[0] * x[0];
        }
        lmk_set L = {6, (int[]){0, 1, 2, 3, 4, 5}, (int[]){0, 1, 2, 3, 4, 5}};
        corr_input in = {S, T, "ico", "ico bent", &L, NULL, NULL, &rp, CORR_CHAIN_ALL, 0, CORR_DDM_AUTO};
        run_job("icosphere_642", &in, 0);
        mesh_free(S);
        mesh_free(T);
    }
    {
        mesh *cow, *camel;
        lmk_set *L;
        testcowcamel_load(&cow, &camel, &L);
        corr_input in = {cow, camel, "cow", "camel", L, NULL, NULL, &rp, CORR_CHAIN_ALL, 0, CORR_DDM_AUTO};
        run_job("cow_camel_demo", &in, 0);
        lmk_free(L);
        mesh_free(cow);
        mesh_free(camel);
    }
    {
        mesh *S = testmesh_read("shrec07_bim/Meshes/381.off"), *T = testmesh_read("shrec07_bim/Meshes/393.off");
        lmk_set *L = NULL;
        char a[512], b[512], err[512];
        snprintf(a, sizeof a, "%s", harness_data_path("shrec07_bim/Corrs/381.vts"));
        snprintf(b, sizeof b, "%s", harness_data_path("shrec07_bim/Corrs/393.vts"));
        if (lmk_read_lists(a, b, 0, S, T, &L, err, sizeof err))
            FAILF("%s", err);
        corr_input in = {S, T, "381", "393", L, NULL, NULL, &rp, CORR_CHAIN_ALL, 0, CORR_DDM_AUTO};
        run_job("shrec07_381_393", &in, 0);
        lmk_free(L);
        mesh_free(S);
        mesh_free(T);
    }
    {
        mesh *S = testmesh_read("tosca_hires/Meshes/centaur0.off");
        mesh *T = testmesh_read("tosca_hires/Meshes/centaur1.off");
        lmk_set *L = testgt_pid_landmarks("tosca_hires/Corrs/centaur.pid", S, T);
        corr_input in = {S, T, "centaur0", "centaur1", L, NULL, NULL, &rp, CORR_CHAIN_ALL, 0, CORR_DDM_AUTO};
        int c = rp.coarse, nc = (S->nv > 2 * c ? c : S->nv) + (T->nv > 2 * c ? c : T->nv);
        run_job("centaur_coarse_to_fine", &in, nc);
        lmk_free(L);
        mesh_free(S);
        mesh_free(T);
    }
    {
        testgt g;
        testgt_vts(&g, "tosca_r_nonisometric/vtx_5k", "8_gorilla_01", "8_man_01", 3);
        bmap *P0 = NULL;
        char err[1024];
        if (vmap_read(harness_data_path("tosca_r_nonisometric/vtx_5k/maps_baseline/WKSini_direct_BCICP/"
                                        "8_gorilla_01_8_man_01.map"),
                      VMAP_BASE_AUTO, g.S, g.T, &P0, NULL, err, sizeof err))
            FAILF("%s", err);
        corr_input in = {g.S, g.T, "gorilla_01", "man_01", NULL, P0, NULL, &rp, CORR_CHAIN_DDM_ECTM, 0,
                         CORR_DDM_AUTO};
        run_job("gorilla_man_ddm_ectm", &in, 0);
        in.stages = CORR_CHAIN_DDM_RHM_ECTM;
        run_job("gorilla_man_ddm_rhm_ectm", &in, 0);
        bmap_free(P0);
        testgt_close(&g);
    }
}
