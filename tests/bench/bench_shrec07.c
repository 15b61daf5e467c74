/* bench_shrec07.c — map quality from landmarks alone, the way a user gets
 * it: one pair per SHREC'07 class of ../shared/data/shrec07_bim (the
 * even-numbered BIM landmarks, 0-based line 0, 2, 4, ..., given; the
 * odd-numbered ones held out and scored), plus TOSCA wolf0 -> wolf2
 * (tosca_r_isometric: the same connectivity; all 21 landmarks of
 * tosca_hires/Corrs/wolf.pid given; dense identity ground truth scored),
 * and make demo's job: cow -> camel from Debian's libcgal-demo
 * (/usr/share/doc/libcgal-dev/data.tar.gz, extracted into the test's
 * directory) with deploy/demo/cow-camel.landmarks, all 16 given, none
 * held out (no ground truth): its folds are the figure (run from the
 * repository's root). Its row is left out of the job-time statistics.
 *
 * Stages as meshcorr match runs them with its defaults: the start map,
 * RHM and the fold repair of its maps (corr_rhm; the line after it names
 * the start kept; the rhm row is the kept map before its repair, the time
 * of both in that row), ECTM from the repaired maps with the given
 * landmarks pinned, and the repair of its maps. A pair with a mesh over
 * twice the coarse size runs these on decimated copies (corr_coarse_open),
 * each stage's map carried to the input meshes to be scored.
 *
 * Prints, per pair and stage, both meshes at unit area: held-out error
 * (mean geodesic distance on the target from each held-out source
 * landmark's image to its target landmark, / sqrt(target area); wolf: over
 * all vertices against the identity), flipped and collapsed triangles (%,
 * metric_summarize), mean-curvature error ‖PH̃ − H‖ (metric.h's
 * neighbourhood fit) and its ratio to the stage's input, mean |log area
 * ratio| and median conformal distortion over non-collapsed triangles,
 * wall time of the stage. Then, per pair, whether it meets the targets:
 * flipped <= 2 %, collapsed <= 0.5 %, full error <= RHM's + 0.003, area
 * distortion below ECTM's input's (the repaired map), error <= 0.05; over
 * the classes: curvature ratio <= 0.75 in at least 8, median error <=
 * 0.035; wolf: error <= 0.01 and flipped <= 1 %. Then how precisely each
 * SHREC'07 pair's landmarks are placed (landmark_mirror_gap: on shapes
 * posed symmetrically, the held-out error's floor). Last, the job time per
 * pair, its median, and the exponent of a least-squares fit of log time
 * against log(source + target vertices) per stage. Each pair runs in its
 * own process (support/testapart.h). Prints figures, never fails on
 * quality. What these figures showed is in docs/decisions.md, "The SHREC'07
 * landmark benchmark: what it showed".
 *
 * Options: --pairs=A,B (labels), --ectm-iterations=K, --stop=start|rhm|repair
 * (the last stage to run), --out-dir=DIR (writes DIR/LABEL.STAGE.map for
 * ../shared/tools' pictures), any job parameter of the one list
 * (proto_params.h) by its CLI name instead of its default, for comparing
 * (--eta=E, --alpha, --beta0, --beta1, --gamma, --start=NAME,
 * --rhm-landmark-weight=G, ...; checked as a job's), --per-landmark=1
 * (after each SHREC'07 pair's rows, each held-out landmark's error per
 * stage, by its 0-based line in the .vts), --within-given=1 (only the
 * given landmarks, every other one of them given and the rest scored:
 * lines 0, 4, 8, ... given and 2, 6, 10, ... scored, the wolf's 21 by odd
 * and even; what a job could measure of itself), --from-exact=1 (the
 * SHREC'07 pairs only: the start and RHM from every landmark, the held-out
 * ones too, with landmark weight 100, so that RHM's maps land on them;
 * ECTM and its repair from those maps with the given ones, as in a job). */
#include "support/harness.h"
#include "support/testapart.h"
#include "support/testcowcamel.h"
#include "support/testfit.h"
#include "corr/corr.h"
#include "embed/embed.h"
#include "geo/geo_area.h"
#include "metric/metric.h"
#include "rhm/rhm__problem.h"
#include "start/start.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct pair_spec {
    const char *label;
    int a, b;               /* SHREC'07 ids; 0: the wolf pair; -1: make demo's */
} pair_spec;

static const pair_spec pairs[] = {
    { "glasses", 52, 58 },   { "airplane", 73, 74 }, { "ant", 81, 83 },
    { "teddy", 162, 165 },   { "hand", 184, 185 },   { "plier", 203, 214 },
    { "fish", 222, 226 },    { "bird", 241, 245 },   { "human", 1, 2 },
    { "armadillo", 293, 298 }, { "fourleg", 381, 393 }, { "wolf0-wolf2", 0, 0 },
    { "cow-camel", -1, -1 },
};
#define NPAIRS ((int)(sizeof pairs / sizeof pairs[0]))

enum { START, RHM, REPAIR, ECTM, NSTAGES };
static const char *const stage_name[NSTAGES] = { "start", "rhm", "repair", "ectm" };

#define EXACT_LANDMARK_WEIGHT 100   /* --from-exact: RHM's landmark weight */
#define HELD_SHOWN 32   /* held-out landmarks --per-landmark prints (SHREC'07: at most 18) */

typedef struct pair_fig {
    int nS, nT, given, held;
    int nmaps;
    double err[NSTAGES], curv[NSTAGES], secs[NSTAGES];
    double lerr[NSTAGES][HELD_SHOWN];  /* --per-landmark: the first HELD_SHOWN held out */
    metric_summary ms[NSTAGES];
    double mirror[2];        /* SHREC'07: landmark_mirror_gap of source, target */
    char why[1024];          /* non-empty: the run stopped there */
} pair_fig;

typedef struct pair_job {
    const pair_spec *ps;
    const ectm_params *ectm;   /* the job parameters: defaults, and those given */
    const rhm_params *rhm;
    int last;               /* the last stage to run (--stop) */
    const char *out_dir;    /* --out-dir: each stage's map is written there */
    int within_given;       /* --within-given */
    int from_exact;         /* --from-exact */
} pair_job;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static mesh *read_mesh(const char *rel)
{
    char err[512];
    mesh *m = NULL;
    if (mesh_read(harness_data_path(rel), &m, err, sizeof err))
        FAILF("%s", err);
    return m;
}

static int *read_ids(const char *rel, int nv, int *n)
{
    char err[512];
    int *ids;
    if (lmk_read_ids(harness_data_path(rel), 0, nv, 1000000, &ids, n, err, sizeof err))
        FAILF("%s", err);
    return ids;
}

static int on_progress(void *ctx, const corr_progress *p)
{
    (void)ctx;
    if (p->stage == CORR_STAGE_ECTM && p->ectm->outer % 100 == 0) {
        printf("    ectm %d/%d, %.0f s\n", p->ectm->outer, p->ectm->total, p->ectm->elapsed);
        fflush(stdout);
    }
    return 0;
}

/* How precisely the class's landmarks are placed on mesh m (ids: its
 * landmarks, n of them; cls: the SHREC'07 class): the plane that fits the
 * symmetry of Corrs/<cls>.sym.info (normal: the main direction of the
 * differences between the landmarks of its pairs; through the mean of
 * their midpoints and of the landmarks it fixes), and the mean distance
 * from each paired landmark's mirror image to its partner, / sqrt(area).
 * On a shape posed symmetrically that is about the held-out error a
 * perfect map would score: two independent placements of one point. NAN
 * without pairs. */
static double landmark_mirror_gap(const mesh *m, const int *ids, int n, int cls)
{
    char rel[64];
    snprintf(rel, sizeof rel, "shrec07_bim/Corrs/%d.sym.info", cls);
    FILE *fp = fopen(harness_data_path(rel), "r");
    if (!fp)
        FAILF("%s: %s", rel, strerror(errno));
    int pa[64], pb[64], fixed[64], np = 0, nf = 0;
    char line[128];
    while (fgets(line, sizeof line, fp)) {
        int a, b, k = sscanf(line, "%d %d", &a, &b);
        if (k >= 1 && (a < 0 || a >= n || (k == 2 && (b < 0 || b >= n))))
            FAILF("%s: line \"%.*s\" names a landmark outside 0..%d", rel,
                  (int)strcspn(line, "\n"), line, n - 1);
        if (k == 2 && np < 64)
            pa[np] = a, pb[np++] = b;
        else if (k == 1 && nf < 64)
            fixed[nf++] = a;
    }
    fclose(fp);
    if (!np)
        return NAN;
    const double *v = m->v;
    double C[9] = {0}, nrm[3], w[1];
    for (int i = 0; i < np; i++) {
        double d[3];
        for (int c = 0; c < 3; c++)
            d[c] = v[3 * ids[pa[i]] + c] - v[3 * ids[pb[i]] + c];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                C[3 * r + c] += d[r] * d[c];
    }
    if (embed_top_eigenpairs(C, 3, 1, w, nrm, NULL))
        FAILF("%s: the symmetry plane's normal", rel);
    double off = 0;
    for (int i = 0; i < np; i++)
        for (int c = 0; c < 3; c++)
            off += 0.5 * (v[3 * ids[pa[i]] + c] + v[3 * ids[pb[i]] + c]) * nrm[c];
    for (int i = 0; i < nf; i++)
        for (int c = 0; c < 3; c++)
            off += v[3 * ids[fixed[i]] + c] * nrm[c];
    off /= np + nf;
    double gap = 0;
    for (int i = 0; i < np; i++) {
        const double *a = v + 3 * ids[pa[i]], *b = v + 3 * ids[pb[i]];
        double h = a[0] * nrm[0] + a[1] * nrm[1] + a[2] * nrm[2] - off, d2 = 0;
        for (int c = 0; c < 3; c++) {
            double x = a[c] - 2 * h * nrm[c] - b[c];
            d2 += x * x;
        }
        gap += sqrt(d2);
    }
    return gap / (np * sqrt(geo_total_area(m)));
}

static void run_pair(const void *arg, void *out)
{
    const pair_job *job = arg;
    const pair_spec *ps = job->ps;
    pair_fig *fig = out;
    memset(fig, 0, sizeof *fig);
    char p[256], S_name[64], T_name[64];
    mesh *S, *T;
    int *ls, *lt, n;
    if (ps->a < 0) {
        lmk_set *D = NULL;
        testcowcamel_load(&S, &T, &D);
        snprintf(S_name, sizeof S_name, "cow.off");
        snprintf(T_name, sizeof T_name, "camel.off");
        n = D->n;
        ls = malloc(sizeof(int) * (size_t)n);
        lt = malloc(sizeof(int) * (size_t)n);
        memcpy(ls, D->src, sizeof(int) * (size_t)n);
        memcpy(lt, D->tgt, sizeof(int) * (size_t)n);
        lmk_free(D);
    } else if (ps->a) {
        snprintf(S_name, sizeof S_name, "%d.off", ps->a);
        snprintf(T_name, sizeof T_name, "%d.off", ps->b);
        snprintf(p, sizeof p, "shrec07_bim/Meshes/%d.off", ps->a);
        S = read_mesh(p);
        snprintf(p, sizeof p, "shrec07_bim/Meshes/%d.off", ps->b);
        T = read_mesh(p);
        int nb;
        snprintf(p, sizeof p, "shrec07_bim/Corrs/%d.vts", ps->a);
        ls = read_ids(p, S->nv, &n);
        snprintf(p, sizeof p, "shrec07_bim/Corrs/%d.vts", ps->b);
        lt = read_ids(p, T->nv, &nb);
        if (nb != n)
            FAILF("%s: %d landmarks, %d.vts has %d", p, nb, ps->a, n);
        fig->mirror[0] = landmark_mirror_gap(S, ls, n, (ps->a + 19) / 20);
        fig->mirror[1] = landmark_mirror_gap(T, lt, n, (ps->b + 19) / 20);
    } else {
        snprintf(S_name, sizeof S_name, "wolf0.off");
        snprintf(T_name, sizeof T_name, "wolf2.off");
        S = read_mesh("tosca_r_isometric/vtx_5k/wolf0.off");
        T = read_mesh("tosca_r_isometric/vtx_5k/wolf2.off");
        ls = read_ids("tosca_hires/Corrs/wolf.pid", S->nv, &n);
        lt = read_ids("tosca_hires/Corrs/wolf.pid", T->nv, &n);
    }
    fig->nS = S->nv;
    fig->nT = T->nv;
    /* given: even lines (SHREC'07; the wolf and the demo: all); held: odd
     * lines (the wolf: every vertex; the demo: none). --within-given: only
     * the lines given above, every other one of them given and the rest
     * held out (what a job could score itself on) */
    long gs[256], gt[256];
    int step = ps->a > 0 ? 2 : 1, w = job->within_given ? 2 : 1;
    int dense = !ps->a && w == 1;      /* the wolf against its identity */
    for (int k = 0; k < n && fig->given < 256; k += step * w) {
        gs[fig->given] = ls[k];
        gt[fig->given++] = lt[k];
    }
    int hs_n = 0, *hs = malloc(sizeof(int) * ((size_t)(dense ? S->nv : n) + 1));
    int *ht = malloc(sizeof(int) * ((size_t)(dense ? S->nv : n) + 1));
    if (dense)
        for (int v = 0; v < S->nv; v++)
            hs[hs_n] = ht[hs_n] = v, hs_n++;
    else if (w > 1 || ps->a > 0)
        for (int k = w > 1 ? step : 1; k < n; k += step * w) {   /* between the given ones */
            hs[hs_n] = ls[k];
            ht[hs_n++] = lt[k];
        }
    fig->held = hs_n;
    for (int a = 0; a < NSTAGES; a++)
        fig->err[a] = fig->curv[a] = NAN;

    char err[1024] = "";
    lmk_set *L = NULL, *L_all = NULL;
    int *g_src = NULL, *g_tgt = NULL;     /* --from-exact: ECTM's landmarks */
    rhm__problem *pb = NULL;
    rhm_result rr = {0};
    ectm_result er = {0};
    bmap *rhm_P = NULL, *fine[NSTAGES] = {0};    /* fine: the maps carried (coarse to fine) */
    corr_coarse cc = {0};
    geod_solver *geodT = NULL;
    double *e = NULL;
    if (lmk_from_arrays(gs, gt, fig->given, 0, S_name, T_name, S, T, &L, err, sizeof err) ||
        corr_validate(S, S_name, err, sizeof err) || corr_validate(T, T_name, err, sizeof err))
        goto out;
    rhm_params rp = *job->rhm;
    ectm_params ep = *job->ectm;
    /* --from-exact: the start and RHM from every landmark, held-out ones
     * too, held by weight EXACT_LANDMARK_WEIGHT (their maps land on them);
     * ECTM from those maps with the given ones, as in a job */
    if (job->from_exact) {
        long as[256], at[256];
        int na = 0;
        for (int k = 0; k < n && na < 256; k++, na++)
            as[na] = ls[k], at[na] = lt[k];
        if (lmk_from_arrays(as, at, na, 0, S_name, T_name, S, T, &L_all, err, sizeof err))
            goto out;
        rp.gamma = EXACT_LANDMARK_WEIGHT;
    }

    /* a pair over twice the coarse size (12 000): the stages run on the decimated
     * copies as corr_run's, each stage's map carried to the input meshes
     * to be scored (the last one repaired there too, as corr_run does) */
    corr_input in0 = { S, T, S_name, T_name, L_all ? L_all : L, NULL, NULL, &rp, CORR_CHAIN_ALL,
                       0, CORR_DDM_PLAIN };
    double t0 = now();
    int coarse = corr_coarse_wanted(&in0);
    if (coarse && corr_coarse_open(&in0, &cc, err, sizeof err))
        goto out;
    const corr_input *ri = coarse ? &cc.in : &in0;     /* the pair the stages run on */
    if (coarse) {
        printf("  %s: coarse to fine, stages on %d -> %d vertices\n", ps->label, ri->S->nv,
               ri->T->nv);
        fflush(stdout);
    }
    if (rhm__problem_new(ri->S, ri->T, ri->L, &rp, &pb, err, sizeof err) ||
        rhm__start(pb, start_maps, err, sizeof err))
        goto out;
    fig->secs[START] = now() - t0;
    const bmap *maps[NSTAGES] = { pb->side[0].P, NULL, NULL, NULL };
    fig->nmaps = 1;
    if (job->last == START)
        goto score;

    /* the pipeline's calls one by one (corr_run): RHM, the fold repair, ECTM */
    corr_input in = *ri;
    /* RHM and its repair (with start auto's second run when the first
     * stays folded): corr_rhm, timed as one; the RHM row is its kept
     * forward map before the repair */
    t0 = now();
    fold_report rep[2];
    if (corr_rhm(&in, &rp, NULL, NULL, &rr, &rhm_P, rep, err, sizeof err))
        goto score;
    fig->secs[RHM] = now() - t0;
    fig->secs[REPAIR] = 0;
    maps[fig->nmaps++] = rhm_P;
    char kept[32];
    proto_param_value_name(PROTO_P_start, (unsigned)rr.start, kept, sizeof kept);
    printf("  %s: rhm and repair %.0f s, from the %s start; repair %d -> %d bad faces (%d "
           "vertices re-mapped, %d moved alone), reverse %d -> %d\n", ps->label, fig->secs[RHM],
           kept, rep[0].bad_before, rep[0].bad_after, rep[0].region, rep[0].relaxed,
           rep[1].bad_before, rep[1].bad_after);
    fflush(stdout);
    if (job->last == RHM)
        goto score;
    maps[fig->nmaps++] = rr.P12;
    if (job->last == REPAIR)
        goto score;

    /* the given landmarks (of the pair the stages run on), as corr_run's
     * ECTM gets them in a job from landmarks: pinned in its P/Q-steps
     * (--from-exact: ri->L holds all of the pair's; the given ones are
     * taken from it with gs and gt's stride) */
    lmk_set Lg = *ri->L;
    if (L_all) {
        g_src = malloc(sizeof(int) * (size_t)n);
        g_tgt = malloc(sizeof(int) * (size_t)n);
        if (!g_src || !g_tgt)
            FAILF("out of memory");
        Lg = (lmk_set){ 0, g_src, g_tgt };
        for (int k = 0; k < ri->L->n; k += step * w, Lg.n++)
            g_src[Lg.n] = ri->L->src[k], g_tgt[Lg.n] = ri->L->tgt[k];
    }
    corr_input ing = in, in0g = in0;     /* ECTM's repairs: with the given ones */
    ing.L = &Lg;
    in0g.L = L;
    corr_input in2 = { ri->S, ri->T, S_name, T_name, &Lg, rr.P12, rr.P21, &rp, CORR_CHAIN_ECTM, 0,
                       CORR_DDM_PLAIN };
    t0 = now();
    ep.scale_reference = corr_scale_reference(&ing, rr.P12, rr.P21);   /* as the pipeline's */
    if (corr_run(&in2, &ep, on_progress, NULL, &er, err, sizeof err))
        goto score;
    /* from landmarks, corr_run repairs ECTM's maps too (a run from given
     * maps, as in2 is, does not): the same call */
    if (corr_repair(&ing, er.P, er.Q, 1, rep, err, sizeof err))
        FAILF("%s", err);
    maps[fig->nmaps++] = er.P;
    if (coarse) {   /* carried, repaired, finished by ECTM on the input pair, repaired */
        bmap *cP, *cQ;
        ectm_result fr = {0};
        if (corr_coarse_carry(&in0g, &cc, er.P, er.Q, 1, &cP, &cQ, err, sizeof err))
            FAILF("%s", err);
        corr_input in3 = { S, T, S_name, T_name, L, cP, cQ, &rp, CORR_CHAIN_ECTM, 0,
                           CORR_DDM_PLAIN };
        ep.scale_reference = corr_scale_reference(&in0g, cP, cQ);
        if (corr_run(&in3, &ep, on_progress, NULL, &fr, err, sizeof err))
            FAILF("%s", err);
        if (corr_repair(&in0g, fr.P, fr.Q, 1, rep, err, sizeof err))
            FAILF("%s", err);
        fine[fig->nmaps - 1] = fr.P;
        fr.P = NULL;
        ectm_result_close(&fr);
        bmap_free(cP);
        bmap_free(cQ);
    }
    fig->secs[ECTM] = now() - t0;

score:
    for (int a = 0; coarse && a < fig->nmaps; a++) {
        if (!fine[a] && corr_coarse_carry(&in0, &cc, maps[a], NULL, 0, &fine[a], NULL, err,
                                          sizeof err))
            FAILF("%s", err);
        maps[a] = fine[a];
    }
    if (coarse && geod_solver_new(T, 0, &geodT, err, sizeof err))
        FAILF("%s", err);
    for (int a = 0; a < fig->nmaps && job->out_dir; a++) {
        snprintf(p, sizeof p, "%s/%s.%s.map", job->out_dir, ps->label, stage_name[a]);
        if (bmap_write(p, maps[a], stage_name[a], err, sizeof err))
            FAILF("%s", err);
    }
    e = malloc(sizeof(double) * ((size_t)fig->nmaps * (size_t)hs_n + 1));
    if (!e)
        FAILF("out of memory");
    if (hs_n && metric_geodesic_errors(coarse ? geodT : pb->side[1].geod, T, maps, fig->nmaps, hs, ht, hs_n, e))
        FAILF("%s: geodesic errors failed", ps->label);
    for (int a = 0; a < fig->nmaps; a++) {
        double s = 0;
        for (int k = 0; k < hs_n; k++)
            s += e[(size_t)a * hs_n + k];
        fig->err[a] = hs_n ? s / hs_n : NAN;   /* the demo: nothing held out */
        for (int k = 0; ps->a && k < hs_n && k < HELD_SHOWN; k++)
            fig->lerr[a][k] = e[(size_t)a * hs_n + k];
        if (metric_summarize(S, T, maps[a], &fig->ms[a]))
            FAILF("out of memory");
        if (metric_curvature_error(S, T, maps[a], &fig->curv[a], err, sizeof err))
            FAILF("curvature error: %s", err);
    }
out:
    snprintf(fig->why, sizeof fig->why, "%s", err);
    for (int a = 0; a < NSTAGES; a++)
        bmap_free(fine[a]);
    geod_solver_free(geodT);
    corr_coarse_close(&cc);
    free(e);
    bmap_free(rhm_P);
    ectm_result_close(&er);
    rhm_result_close(&rr);
    rhm__problem_free(pb);
    lmk_free(L);
    lmk_free(L_all);
    free(g_src);
    free(g_tgt);
    free(ls);
    free(lt);
    free(hs);
    free(ht);
    mesh_free(S);
    mesh_free(T);
}

static void print_header(void)
{
    printf("%-12s %-11s %5s %-6s %8s %7s %7s %8s %6s %7s %8s %7s\n", "pair", "V S->T", "lmk",
           "stage", "held err", "flip %", "coll %", "curv err", "ratio", "|log a|", "conf med",
           "time s");
}

static void print_rows(const pair_spec *ps, const pair_fig *f)
{
    char v[32], lm[16];
    snprintf(v, sizeof v, "%d->%d", f->nS, f->nT);
    snprintf(lm, sizeof lm, "%d/%d", f->given, ps->a ? f->held : 0);
    for (int a = 0; a < f->nmaps; a++) {
        char ratio[16] = "-";
        if (a > START)
            snprintf(ratio, sizeof ratio, "%.2f", f->curv[a] / f->curv[a - 1]);
        char held[16] = "-";          /* the demo: nothing held out */
        if (!isnan(f->err[a]))
            snprintf(held, sizeof held, "%.4f", f->err[a]);
        const metric_summary *m = &f->ms[a];
        printf("%-12s %-11s %5s %-6s %8s %7.2f %7.2f %8.3f %6s %7.3f %8.3f %7.1f\n", ps->label,
               v, lm, stage_name[a], held, 100 * m->flipped_fraction,
               100 * m->collapsed_fraction, f->curv[a], ratio, m->mean_abs_log_area,
               m->median_conformal, f->secs[a]);
    }
    if (f->why[0]) {
        char one[1024];
        snprintf(one, sizeof one, "%s", f->why);
        for (char *c = one; *c; c++)
            if (*c == '\n')
                *c = ' ';
        printf("%-12s error after %s: %s\n", ps->label, f->nmaps ? stage_name[f->nmaps - 1] : "loading", one);
    }
}

/* --per-landmark: held-out landmark k is line 2k + 1 of the pair's .vts. */
static void print_landmarks(const pair_spec *ps, const pair_fig *f)
{
    if (ps->a <= 0 || !f->nmaps)
        return;
    printf("%-12s held-out landmarks (.vts line):", ps->label);
    for (int a = 0; a < f->nmaps; a++)
        printf(" %7s", stage_name[a]);
    printf("\n");
    for (int k = 0; k < f->held && k < HELD_SHOWN; k++) {
        printf("%-12s   line %2d %21s", ps->label, 2 * k + 1, "");
        for (int a = 0; a < f->nmaps; a++)
            printf(" %7.4f", f->lerr[a][k]);
        printf("\n");
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The targets, pair by pair and over the classes. */
static void print_targets(const int *ran, const pair_fig *figs)
{
    int classes = 0, ratio_ok = 0, all = 0;
    double errs[NPAIRS];
    printf("\ntargets (full pipeline): flipped <= 2 %%, collapsed <= 0.5 %%, error <= RHM + 0.003, "
           "|log a| below ECTM's input's, error <= 0.05 (wolf: <= 0.01, flipped <= 1 %%; cow-camel: flipped "
           "and collapsed)\n");
    for (int i = 0; i < NPAIRS; i++) {
        const pair_fig *f = &figs[i];
        if (!ran[i])
            continue;
        if (f->nmaps < NSTAGES) {
            printf("  %-12s no full map\n", pairs[i].label);
            continue;
        }
        const metric_summary *m = &f->ms[ECTM], *r = &f->ms[ECTM - 1];   /* ECTM's input */
        int wolf = !pairs[i].a, demo = pairs[i].a < 0;
        int flip = m->flipped_fraction <= (wolf ? 0.01 : 0.02);
        int coll = m->collapsed_fraction <= 0.005;
        int keep = f->err[ECTM] <= f->err[RHM] + 0.003;
        int area = m->mean_abs_log_area < r->mean_abs_log_area;
        int acc = f->err[ECTM] <= (wolf ? 0.01 : 0.05);
        if (demo) {       /* make demo: flipped and collapsed only */
            printf("  %-12s %s  flipped %s  collapsed %s\n", pairs[i].label,
                   flip && coll ? "MET " : "open", flip ? "ok" : "NO", coll ? "ok" : "NO");
            continue;
        }
        int ok = flip && coll && (wolf || (keep && area)) && acc;
        all += ok;
        if (!wolf) {
            errs[classes++] = f->err[ECTM];
            ratio_ok += f->curv[ECTM] / f->curv[ECTM - 1] <= 0.75;
        }
        printf("  %-12s %s  flipped %s  collapsed %s  error-vs-rhm %s  area %s  accuracy %s\n",
               pairs[i].label, ok ? "MET " : "open", flip ? "ok" : "NO", coll ? "ok" : "NO",
               wolf ? "-" : keep ? "ok" : "NO", wolf ? "-" : area ? "ok" : "NO", acc ? "ok" : "NO");
    }
    if (classes) {
        qsort(errs, (size_t)classes, sizeof *errs, cmp_double);
        double med = classes % 2 ? errs[classes / 2] : 0.5 * (errs[classes / 2 - 1] + errs[classes / 2]);
        printf("  pairs meeting every per-pair target: %d; classes with curvature ratio <= 0.75: "
               "%d of %d (target 8 of 11); median held-out error %.4f (target <= 0.035)\n",
               all, ratio_ok, classes, med);
    }
}

/* landmark_mirror_gap of each SHREC'07 pair that ran, four to a line. */
static void print_placement(const int *ran, const pair_fig *figs)
{
    int k = 0;
    for (int i = 0; i < NPAIRS; i++) {
        if (!ran[i] || pairs[i].a <= 0 || !figs[i].nS)
            continue;
        if (!k)
            printf("\nthe landmarks' own placement (a paired landmark's mirror image across "
                   "the class's symmetry plane from its partner, mean / sqrt(area), source / "
                   "target; on shapes posed symmetrically about what a perfect map's held-out "
                   "error is):\n");
        printf("  %-10s %.4f / %.4f%s", pairs[i].label, figs[i].mirror[0], figs[i].mirror[1],
               ++k % 4 ? "" : "\n");
    }
    if (k % 4)
        printf("\n");
}

/* Job times and their growth with the pair's size. */
static void print_cost(const int *ran, const pair_fig *figs)
{
    /* the series fitted: three stages (the repair is timed with RHM) and the job */
    enum { NSERIES = 4 };
    static const char *const what[NSERIES] = { "start", "rhm+repair", "ectm+repair", "job" };
    double x[NPAIRS], y[NSERIES][NPAIRS], job[NPAIRS];
    int n = 0;
    for (int i = 0; i < NPAIRS; i++) {
        const pair_fig *f = &figs[i];
        if (!ran[i] || f->nmaps < NSTAGES || pairs[i].a < 0)   /* the SHREC'07 pairs and the wolf */
            continue;
        const double secs[NSERIES] = { f->secs[START], f->secs[RHM], f->secs[ECTM],
                                       f->secs[START] + f->secs[RHM] + f->secs[ECTM] };
        x[n] = (double)(f->nS + f->nT);
        for (int a = 0; a < NSERIES; a++)
            y[a][n] = secs[a];
        job[n++] = secs[NSERIES - 1];
    }
    if (n < 2)
        return;
    printf("\ncost against size over %d pairs, time ~ (source + target vertices)^e:", n);
    for (int a = 0; a < NSERIES; a++)
        printf(" %s e = %.2f%s", what[a], testfit_exponent(x, y[a], n), a + 1 < NSERIES ? ";" : "");
    qsort(job, (size_t)n, sizeof *job, cmp_double);
    printf("\njob time (start + rhm + ectm stages): median %.1f s, from %.1f to %.1f s "
           "(target: median <= 20 s)\n",
           n % 2 ? job[n / 2] : 0.5 * (job[n / 2 - 1] + job[n / 2]), job[0], job[n - 1]);
}

TEST_T(shrec07_classes_from_landmarks, 86400)
{
    if (!harness_data_dir())
        SKIP("../shared/data is absent");
    const char *o_it = harness_option("ectm-iterations"), *o_pairs = harness_option("pairs");
    const char *o_stop = harness_option("stop"), *o_out = harness_option("out-dir");
    const char *o_pl = harness_option("per-landmark");
    int per_landmark = o_pl && atoi(o_pl) != 0;
    const char *o_wg = harness_option("within-given");
    int within_given = o_wg && atoi(o_wg) != 0;
    const char *o_fe = harness_option("from-exact");
    int from_exact = o_fe && atoi(o_fe) != 0;
    /* every job parameter by its CLI name (--eta=0.1, --start=fmap, ...),
     * parsed, checked and mapped to the engine as a job's are;
     * --ectm-iterations is --iterations */
    proto_params w;
    char perr[256];
    proto_params_init(&w);
    for (int i = 0; i < PROTO_NPARAMS; i++) {
        const char *o = harness_option(proto_param_infos[i].cli);
        if (o && proto_param_parse(&w, i, o, perr, sizeof perr))
            FAILF("--%s: %s", proto_param_infos[i].cli, perr);
    }
    if (o_it && proto_param_parse(&w, PROTO_P_iterations, o_it, perr, sizeof perr))
        FAILF("--ectm-iterations: %s", perr);
    ectm_params ep;
    rhm_params rp;
    if (corr_params_from_job(&w, 0, &ep, &rp, perr, sizeof perr))
        FAILF("%s", perr);
    int last = ECTM;
    if (o_stop)
        last = !strcmp(o_stop, "start") ? START : !strcmp(o_stop, "rhm") ? RHM
                                       : !strcmp(o_stop, "repair") ? REPAIR : -1;
    if (last < 0)
        FAILF("--stop takes start, rhm or repair");
    int dflt = (int)proto_param_infos[PROTO_P_iterations].dflt;
    printf("landmarks -> start -> RHM -> ECTM, meshcorr match's defaults, ECTM %d outer "
           "iterations%s; %s\n", ep.iterations, ep.iterations != dflt ? " (not the default)" : "",
           harness_data_dir());
    if (from_exact)
        printf("--from-exact: start and RHM from every landmark, held-out ones too (landmark "
               "weight %g), ECTM and its repair from the given ones\n",
               (double)EXACT_LANDMARK_WEIGHT);
    static pair_fig figs[NPAIRS];
    int ran[NPAIRS] = {0};
    for (int i = 0; i < NPAIRS; i++) {
        if (!harness_list_has(o_pairs, pairs[i].label) || (from_exact && pairs[i].a <= 0))
            continue;     /* --from-exact: the pairs with landmarks held out */
        pair_job job = { &pairs[i], &ep, &rp, last, o_out, within_given, from_exact };
        char why[256];
        if (testapart_run(run_pair, &job, &figs[i], sizeof figs[i], why, sizeof why))
            snprintf(figs[i].why, sizeof figs[i].why, "%s", why);
        ran[i] = 1;
        print_header();
        print_rows(&pairs[i], &figs[i]);
        if (per_landmark)
            print_landmarks(&pairs[i], &figs[i]);
        fflush(stdout);
    }
    printf("\nheld err: mean geodesic error of the held-out landmarks / sqrt(target area) "
           "(wolf: every vertex against the identity); ratio: curvature error over the stage "
           "before's; |log a|, conf med over non-collapsed triangles\n");
    print_header();
    for (int i = 0; i < NPAIRS; i++)
        if (ran[i])
            print_rows(&pairs[i], &figs[i]);
    print_targets(ran, figs);
    print_placement(ran, figs);
    print_cost(ran, figs);
}
