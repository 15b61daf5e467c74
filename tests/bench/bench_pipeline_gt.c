/* bench_pipeline_gt.c — the whole pipeline, as `meshcorr match` runs it, on
 * the real pairs of ../shared/data with dense ground truth, from 12
 * landmarks picked from that ground truth (support/testgt.h): FAUST_r
 * intra-subject 000->001 and 002->007, inter-subject 000->020 and 010->020,
 * TOSCA_r isometric cat0->cat1 (about 100 units across: the engine is
 * scale-invariant), and the cartoon pairs homerA->homerB and headA->headB.
 *
 * Stages: the start map RHM begins with (start.h: by default start auto,
 * whose first start is the geodesic distances to the landmarks, rebuilt
 * here; --start=voronoi for the thesis' Voronoi cells), RHM with
 * rhm_params_init's values (start auto: from the functional-map start too
 * when the repaired maps from distances stay folded), then ECTM with
 * ectm_params_init's values from RHM's two maps: meshcorr match's
 * defaults. RHM and ECTM run through corr_run (stages rhm, then stages ectm
 * from RHM's P and Q: the same calls as stages all); the start map is
 * rebuilt by the RHM internals (rhm__start with start_maps) that start_run
 * begins with.
 *
 * Per pair and stage, with both meshes at unit area: mean geodesic error /
 * sqrt(target area) against the direct ground truth, and where a symmetric
 * ground truth exists (.sym.vts) the BCICP figure, the mean over points of
 * min(direct, symmetric); median conformal distortion and mean |log area
 * ratio| over non-collapsed triangles (metric_summarize), and the median
 * conformal distortion over all triangles with collapsed ones as +inf;
 * flipped and collapsed triangles (%);
 * iterations and wall time of RHM and ECTM. The RHM paper reports a mean
 * geodesic error of about 0.033 on remeshed FAUST/SCAPE.
 *
 * --scale checks scale invariance: the start and RHM rows do not move;
 * ECTM's last digits do, as 300 alternations amplify rounding.
 *
 * Options (after the test name, or alone):
 *   --ectm-iterations=K   ECTM outer iterations (default: the engine's 300)
 *   --pairs=A,B,...       only these pairs (labels as in the table)
 *   --scale=S             multiply both meshes' coordinates by S first
 *                         (a check of scale invariance)
 *   --start=NAME          auto (the default), distances, voronoi or fmap
 *   --eta=E               ECTM's bending weight instead of the default
 *   --zoomout=K           the functional-map start (--start=fmap, and auto's
 *                         second run) grown by ZoomOut to K functions
 * Each pair runs in its own process (support/testapart.h): a crash or an
 * error becomes that pair's row, and the other pairs still run. The rhm
 * row is corr_run's stages rhm: RHM's maps after the pipeline's fold
 * repair (corr_repair); the rhm+ectm row is ECTM's maps after the same
 * repair, as corr_run's stages all returns them (a pair over
 * twice the job parameter coarse, headA -> headB: the start on the decimated pair
 * carried to the input meshes, the rhm row as stages rhm returns it, the
 * rhm+ectm row stages all from the landmarks, its time the whole job's).
 * Prints figures, never fails on quality. */
#include "support/harness.h"
#include "support/testapart.h"
#include "support/testgt.h"
#include "corr/corr.h"
#include "geo/geo_area.h"
#include "metric/metric.h"
#include "proto.h"
#include "rhm/rhm__problem.h"
#include "start/start.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#define NL 12   /* landmarks */

typedef struct pair_spec {
    const char *label;
    int vts;               /* 1: .vts layout (dir, a, b); 0: vertex list (S, T, gt) */
    const char *x, *y, *z;
} pair_spec;

static const pair_spec pairs[] = {
    { "faust-000-001", 1, "faust_r/vtx_5k", "tr_reg_000", "tr_reg_001" },
    { "faust-002-007", 1, "faust_r/vtx_5k", "tr_reg_002", "tr_reg_007" },
    { "faust-000-020", 1, "faust_r/vtx_5k", "tr_reg_000", "tr_reg_020" },
    { "faust-010-020", 1, "faust_r/vtx_5k", "tr_reg_010", "tr_reg_020" },
    { "tosca-cat0-cat1", 1, "tosca_r_isometric/vtx_5k", "cat0", "cat1" },
    { "homerA-homerB", 0, "cartoon_elasticbasis/homerA.obj", "cartoon_elasticbasis/homerB.obj",
      "cartoon_elasticbasis/gt_homerA_homerB.txt" },
    { "headA-headB", 0, "cartoon_elasticbasis/headA.obj", "cartoon_elasticbasis/headB.obj",
      "cartoon_elasticbasis/gt_headA_headB.txt" },
};
#define NPAIRS ((int)(sizeof pairs / sizeof pairs[0]))

enum { VORONOI, RHM, ECTM, NSTAGES };
static const char *const stage_name[NSTAGES] = { "start", "rhm", "rhm+ectm" };
static int start_kind = RHM_START_AUTO;        /* --start */

/* One pair's figures: plain data, sent from the pair's process through a pipe. */
typedef struct pair_fig {
    int nS, nT, ngt, sym;
    int nmaps;                     /* stages that produced a map */
    double geo[NSTAGES], geo_bcicp[NSTAGES];
    metric_summary ms[NSTAGES];
    double conf_all[NSTAGES];      /* median over all triangles, collapsed = +inf */
    int iters[NSTAGES];
    double secs[NSTAGES];
    char err[1024];                /* non-empty: the run stopped there */
} pair_fig;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct watch {
    const char *label;
    rhm_report rhm;
} watch;

static int on_progress(void *ctx, const corr_progress *p)
{
    watch *w = ctx;
    if (p->rhm)
        w->rhm = *p->rhm;
    if (p->stage == CORR_STAGE_ECTM && (p->ectm->outer % 50 == 0 || p->ectm->outer == 1)) {
        printf("  %s: ectm %d/%d, energy %.6g, %.0f s\n", w->label, p->ectm->outer,
               p->ectm->total, p->ectm->energy, p->ectm->elapsed);
        fflush(stdout);
    }
    return 0;
}

static double mean(const double *x, int n)
{
    double s = 0;
    for (int k = 0; k < n; k++)
        s += x[k];
    return s / n;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The median conformal distortion over all of S's triangles, a collapsed
 * one (metric_summarize's rule) counted as +inf: metric_summary's median
 * leaves collapsed triangles out, which flatters a map that collapses many
 * (RHM: 5-15 %). */
static double median_conformal_all(const mesh *S, const mesh *T, const bmap *P)
{
    double *img = malloc(sizeof(double) * 3 * (size_t)S->nv);
    double *lr = malloc(sizeof(double) * (size_t)S->nf), *cf = malloc(sizeof(double) * (size_t)S->nf);
    if (!img || !lr || !cf)
        FAILF("out of memory");
    bmap_apply(P, T->f, T->v, 3, img);
    metric_area_distortion(S, img, geo_total_area(S), geo_total_area(T), lr);
    metric_conformal_distortion(S, img, cf);
    for (int t = 0; t < S->nf; t++)
        if (!(exp(lr[t]) > 1e-12))
            cf[t] = INFINITY;
    qsort(cf, (size_t)S->nf, sizeof *cf, cmp_double);
    int n = S->nf;
    double m = n % 2 ? cf[n / 2] : 0.5 * (cf[n / 2 - 1] + cf[n / 2]);
    free(img);
    free(lr);
    free(cf);
    return m;
}

typedef struct pair_job {
    const pair_spec *ps;
    int ectm_iterations;
    double scale;
    double eta;             /* --eta: ECTM's bending weight, 0: the default */
    int zoomout;            /* --zoomout: rhm_params.zoomout, 0: off */
} pair_job;

static void run_pair(const void *arg, void *out)
{
    const pair_job *job = arg;
    const pair_spec *ps = job->ps;
    int ectm_iterations = job->ectm_iterations;
    double scale = job->scale;
    pair_fig *fig = out;
    memset(fig, 0, sizeof *fig);
    testgt g;
    if (ps->vts)
        testgt_vts(&g, ps->x, ps->y, ps->z, NL);
    else
        testgt_vertex_list(&g, ps->x, ps->y, ps->z, NL);
    for (int k = 0; k < 3 * g.S->nv; k++)
        g.S->v[k] *= scale;
    for (int k = 0; k < 3 * g.T->nv; k++)
        g.T->v[k] *= scale;
    fig->nS = g.S->nv;
    fig->nT = g.T->nv;
    fig->ngt = g.n;
    fig->sym = g.tgt_sym != NULL;
    for (int a = 0; a < NSTAGES; a++)
        fig->geo[a] = fig->geo_bcicp[a] = NAN;

    char err[1024] = "";
    const char *S_name = ps->vts ? ps->y : ps->x, *T_name = ps->vts ? ps->z : ps->y;
    lmk_set *L = NULL;
    rhm__problem *pb = NULL;
    ectm_result rr = {0}, er = {0};
    corr_coarse cc = {0};
    bmap *start = NULL;            /* coarse to fine: the start carried */
    geod_solver *geodT = NULL;
    double *e = NULL;
    /* the landmark rule of meshcorr match's files */
    long ls[NL], lt[NL];
    for (int r = 0; r < NL; r++) {
        ls[r] = g.L.src[r];
        lt[r] = g.L.tgt[r];
    }
    if (lmk_from_arrays(ls, lt, NL, 0, S_name, T_name, g.S, g.T, &L, err, sizeof err) ||
        corr_validate(g.S, S_name, err, sizeof err) || corr_validate(g.T, T_name, err, sizeof err))
        goto out;
    rhm_params rp;
    rhm_params_init(&rp);
    rp.start = start_kind;
    rp.zoomout = job->zoomout;
    ectm_params ep;
    ectm_params_init(&ep);
    if (ectm_iterations > 0)
        ep.iterations = ectm_iterations;
    if (job->eta > 0)
        ep.eta = job->eta;

    /* the start map (a pair over twice the coarse size, 12 000: on the decimated
     * pair, as corr_run makes it, carried to the input meshes), and T's
     * geodesic solver for scoring */
    corr_input in = { g.S, g.T, S_name, T_name, L, NULL, NULL, &rp, CORR_CHAIN_RHM, 0, CORR_DDM_PLAIN };
    int coarse = corr_coarse_wanted(&in);
    if (coarse && corr_coarse_open(&in, &cc, err, sizeof err))
        goto out;
    const corr_input *ri = coarse ? &cc.in : &in;
    if (rhm__problem_new(ri->S, ri->T, ri->L, &rp, &pb, err, sizeof err) ||
        rhm__start(pb, start_maps, err, sizeof err))
        goto out;
    if (coarse) {
        printf("  %s: coarse to fine, stages on %d -> %d vertices\n", ps->label, ri->S->nv,
               ri->T->nv);
        if (corr_coarse_carry(&in, &cc, pb->side[0].P, NULL, 0, &start, NULL, err, sizeof err) ||
            geod_solver_new(g.T, 0, &geodT, err, sizeof err))
            goto out;
    }
    const bmap *maps[NSTAGES] = { coarse ? start : pb->side[0].P, NULL, NULL };
    fig->nmaps = 1;

    watch w = { ps->label, {0} };
    double t0 = now();
    if (corr_run(&in, &ep, on_progress, &w, &rr, err, sizeof err))
        goto score;
    fig->secs[RHM] = now() - t0;
    fig->iters[RHM] = w.rhm.iteration;
    maps[fig->nmaps++] = rr.P;
    printf("  %s: rhm %d iterations, %.0f s\n", ps->label, w.rhm.iteration, fig->secs[RHM]);
    fflush(stdout);

    /* with the landmarks, which ECTM's P/Q-steps pin, as in stages all */
    corr_input in2 = { g.S, g.T, S_name, T_name, L, rr.P, rr.Q, &rp, CORR_CHAIN_ECTM, 0, CORR_DDM_PLAIN };
    in.stages = CORR_CHAIN_ALL;
    t0 = now();
    /* coarse to fine: the ECTM after the carried RHM maps is not the
     * pipeline's (ECTM runs on the decimated pair first), so stages all
     * from the landmarks again */
    ep.scale_reference = corr_scale_reference(&in, rr.P, rr.Q);   /* as the pipeline's */
    if (corr_run(coarse ? &in : &in2, &ep, on_progress, &w, &er, err, sizeof err))
        goto score;
    /* from landmarks, corr_run repairs ECTM's maps too (a run from given
     * maps, as in2 is, does not): the same call */
    fold_report rep[2];
    if (!coarse && corr_repair(&in, er.P, er.Q, 1, rep, err, sizeof err))
        FAILF("%s", err);
    fig->secs[ECTM] = now() - t0;
    fig->iters[ECTM] = er.last.outer;
    maps[fig->nmaps++] = er.P;

score:
    e = malloc(sizeof(double) * (size_t)fig->nmaps * (size_t)g.n * 2);
    if (!e)
        FAILF("out of memory");
    geod_solver *gT = coarse ? geodT : pb->side[1].geod;
    if (metric_geodesic_errors(gT, g.T, maps, fig->nmaps, g.src, g.tgt, g.n, e) ||
        (g.tgt_sym && metric_geodesic_errors(gT, g.T, maps, fig->nmaps, g.src,
                                             g.tgt_sym, g.n, e + (size_t)fig->nmaps * g.n)))
        FAILF("%s: geodesic errors failed", ps->label);
    for (int a = 0; a < fig->nmaps; a++) {
        double *d = e + (size_t)a * g.n;
        fig->geo[a] = mean(d, g.n);
        if (g.tgt_sym) {
            const double *s = e + ((size_t)fig->nmaps + a) * g.n;
            for (int k = 0; k < g.n; k++)
                d[k] = fmin(d[k], s[k]);
            fig->geo_bcicp[a] = mean(d, g.n);
        }
        if (metric_summarize(g.S, g.T, maps[a], &fig->ms[a]))
            FAILF("out of memory");
        fig->conf_all[a] = median_conformal_all(g.S, g.T, maps[a]);
    }
out:
    snprintf(fig->err, sizeof fig->err, "%s", err);
    bmap_free(start);
    geod_solver_free(geodT);
    corr_coarse_close(&cc);
    free(e);
    ectm_result_close(&er);
    ectm_result_close(&rr);
    rhm__problem_free(pb);
    lmk_free(L);
    testgt_close(&g);
}

static void print_header(void)
{
    printf("%-16s %-12s %5s  %-8s %8s %8s %8s %8s %8s %7s %7s %5s %8s\n", "pair", "V S->T",
           "GT", "stage", "geo err", "BCICP", "conf med", "conf all", "|log a|", "flip %",
           "coll %", "iters", "wall s");
}

static void print_rows(const pair_spec *ps, const pair_fig *f)
{
    char v[32];
    snprintf(v, sizeof v, "%d->%d", f->nS, f->nT);
    for (int a = 0; a < f->nmaps; a++) {
        char sym[16] = "-", it[16] = "-", t[16] = "-";
        if (f->sym)
            snprintf(sym, sizeof sym, "%.4f", f->geo_bcicp[a]);
        if (a > VORONOI) {
            snprintf(it, sizeof it, "%d", f->iters[a]);
            snprintf(t, sizeof t, "%.1f", f->secs[a]);
        }
        const metric_summary *m = &f->ms[a];
        printf("%-16s %-12s %5d  %-8s %8.4f %8s %8.4f %8.4f %8.4f %7.2f %7.2f %5s %8s\n",
               ps->label, v, f->ngt, stage_name[a], f->geo[a], sym, m->median_conformal,
               f->conf_all[a], m->mean_abs_log_area, 100 * m->flipped_fraction, 100 * m->collapsed_fraction, it, t);
    }
    if (f->err[0]) {
        /* one line: the engine's messages may hold several */
        char one[1024];
        snprintf(one, sizeof one, "%s", f->err);
        for (char *c = one; *c; c++)
            if (*c == '\n')
                *c = ' ';
        printf("%-16s %-12s %5d  error after %s: %s\n", ps->label, f->nS ? v : "-", f->ngt,
               f->nmaps ? stage_name[f->nmaps - 1] : "loading", one);
    }
}

TEST_T(pipeline_on_pairs_with_dense_ground_truth, 86400)
{
    if (!harness_data_dir())
        SKIP("../shared/data is absent");
    const char *o_it = harness_option("ectm-iterations"), *o_pairs = harness_option("pairs");
    const char *o_scale = harness_option("scale"), *o_start = harness_option("start");
    proto_params w;                      /* the start's names are the list's */
    char perr[256], start_name[32];
    proto_params_init(&w);
    if (o_start && proto_param_parse(&w, PROTO_P_start, o_start, perr, sizeof perr))
        FAILF("--start: %s", perr);
    start_kind = w.start;
    int iters = o_it ? atoi(o_it) : 0;
    double scale = o_scale ? atof(o_scale) : 1;
    double eta = harness_option("eta") ? atof(harness_option("eta")) : 0;
    int zoomout = harness_option("zoomout") ? atoi(harness_option("zoomout")) : 0;
    if ((o_it && iters < 1) || !(scale > 0))
        FAILF("--ectm-iterations takes a positive integer, --scale a positive number");
    ectm_params ep;
    ectm_params_init(&ep);
    printf("start (%s) -> RHM -> ECTM from %d farthest-point landmarks; RHM defaults; ECTM defaults "
           "with %d outer iterations%s; scale x%g; ZoomOut %d (0: off); %s\n",
           proto_param_value_name(PROTO_P_start, (unsigned)start_kind, start_name, sizeof start_name), NL,
           iters ? iters : ep.iterations,
           iters && iters != ep.iterations ? " (not the default)" : " (the default)", scale, zoomout,
           harness_data_dir() ? harness_data_dir() : "no data folder");
    static pair_fig figs[NPAIRS];
    int ran[NPAIRS] = {0};
    for (int i = 0; i < NPAIRS; i++) {
        if (!harness_list_has(o_pairs, pairs[i].label))
            continue;
        pair_job job = { &pairs[i], iters, scale, eta, zoomout };
        char why[256];
        if (testapart_run(run_pair, &job, &figs[i], sizeof figs[i], why, sizeof why))
            snprintf(figs[i].err, sizeof figs[i].err, "%s", why);
        ran[i] = 1;
        print_header();
        print_rows(&pairs[i], &figs[i]);
        fflush(stdout);
    }
    printf("\ngeo err: mean geodesic error / sqrt(target area) against the direct ground truth; "
           "BCICP: mean of min(direct, symmetric) per point; conf med, |log a|: median conformal "
           "distortion and mean |log area ratio| over non-collapsed triangles; conf all: median "
           "conformal distortion over all triangles, collapsed ones counted as inf\n");
    print_header();
    for (int i = 0; i < NPAIRS; i++)
        if (ran[i])
            print_rows(&pairs[i], &figs[i]);
}
