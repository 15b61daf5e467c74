/* bench_refine.c — refining published maps on TOSCA_r
 * non-isometric (../shared/data/tosca_r_nonisometric: gorilla_01 <-> man_01,
 * man_02, woman_01, both directions, 900 GT points) with the pipeline's
 * stage chains (corr.h), the maps read as `meshcorr match --init` reads
 * them (map/vmap.h: BIM 0-based, BCICP 1-based):
 *  - DDM denoising (--stages ddm, ddm_k default) of every BIM and BCICP
 *    map, plain (ddm_mode plain), bijective (ddm_mode bijective, with
 *    the same method's published reverse map as q) and auto (the default,
 *    with q: bijective when the pair agrees): mean geodesic error
 *    (direct, and the BCICP protocol's smaller of direct and symmetric),
 *    median conformal distortion before and after, against the
 *    targets (error within +0.005, median conformal at most half), and the
 *    round trip T->S->T of the pair of maps (metric_round_trip: the
 *    published pair, then the denoised pair).
 *  - the BCICP map refined by each chain of --chains (default
 *    "ectm;ddm,ectm;ddm,rhm,ectm", ';'-separated) with the default weights
 *    (--ectm-iterations=K to shorten ECTM), no landmarks: error, median
 *    conformal, flipped triangles and seconds, target: lower error; with
 *    --with-reverse=yes the published reverse BCICP map goes with it (q: ECTM
 *    starts from both, and ddm_mode auto may denoise the two together).
 *
 * --ddm-table=no skips the DDM table (the chains only).
 * --ddm-k=K sets DDM's basis size (default CORR_DDM_K). --pairs=A_B,... (names as in maps_baseline, e.g. 8_gorilla_01_8_man_01)
 * picks the maps for both parts; --refine-pairs=... the maps the chains run
 * on (default: the three gorilla_01 -> X maps; "all" for all six).
 * Prints figures; fails only when something cannot run. */
#include "support/harness.h"
#include "support/testgt.h"
#include "corr/corr.h"
#include "geod/geod.h"
#include "map/vmap.h"
#include "metric/metric.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#define DIR "tosca_r_nonisometric/vtx_5k"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static const char *const pairs[6][2] = {
    {"8_gorilla_01", "8_man_01"}, {"8_gorilla_01", "8_man_02"}, {"8_gorilla_01", "8_woman_01"},
    {"8_man_01", "8_gorilla_01"}, {"8_man_02", "8_gorilla_01"}, {"8_woman_01", "8_gorilla_01"}};

typedef struct score {
    double err, err_sym, median_conformal, flipped;
} score;

static score score_of(const testgt *g, geod_solver *sT, const bmap *P)
{
    score s = {0, 0, 0, 0};
    double *e = malloc(sizeof(double) * (size_t)g->n), *es = malloc(sizeof(double) * (size_t)g->n);
    const bmap *maps[1] = {P};
    if (metric_geodesic_errors(sT, g->T, maps, 1, g->src, g->tgt, g->n, e) ||
        (g->tgt_sym && metric_geodesic_errors(sT, g->T, maps, 1, g->src, g->tgt_sym, g->n, es)))
        FAILF("geodesic errors failed");
    for (int k = 0; k < g->n; k++) {
        s.err += e[k] / g->n;
        s.err_sym += (g->tgt_sym && es[k] < e[k] ? es[k] : e[k]) / g->n;
    }
    free(e);
    free(es);
    metric_summary m;
    if (metric_summarize(g->S, g->T, P, &m))
        FAILF("metric_summarize failed");
    s.median_conformal = m.median_conformal;
    s.flipped = m.flipped_fraction;
    return s;
}

static int ddm_k;   /* --ddm-k, 0: the default */

/* The chain's P; with Q0 (and bijective DDM) its Q in *Q. */
static bmap *run_chain(const testgt *g, const bmap *P0, const bmap *Q0, corr_ddm_mode mode,
                       corr_stages st, const ectm_params *p, double *secs, bmap **Q)
{
    char err[2048] = "";
    corr_input in = {g->S, g->T, "source", "target", NULL, P0, Q0, NULL, st, ddm_k, mode};
    ectm_result r = {0};
    double t0 = now();
    if (corr_run(&in, p, NULL, NULL, &r, err, sizeof err))
        FAILF("%s", err);
    *secs = now() - t0;
    bmap *P = r.P;
    if (Q) {
        *Q = r.Q;
        r.Q = NULL;
    }
    r.P = NULL;
    ectm_result_close(&r);
    return P;
}

TEST_T(refine_published_tosca_maps, 7200)
{
    const char *o_pairs = harness_option("pairs"), *o_refine = harness_option("refine-pairs");
    const char *o_chains = harness_option("chains"), *o_it = harness_option("ectm-iterations");
    ddm_k = harness_option("ddm-k") ? atoi(harness_option("ddm-k")) : 0;
    const char *o_rev = harness_option("with-reverse");
    int with_reverse = o_rev && strcmp(o_rev, "yes") == 0;
    int table = !harness_option("ddm-table") || strcmp(harness_option("ddm-table"), "no") != 0;
    char chains[256];
    snprintf(chains, sizeof chains, "%s", o_chains ? o_chains : "ectm;ddm,ectm;ddm,rhm,ectm");
    ectm_params p;
    ectm_params_init(&p);
    if (o_it) {
        p.iterations = atoi(o_it);
        if (p.beta_ramp > p.iterations)
            p.beta_ramp = p.iterations;
    }
    if (table) {
        printf("DDM denoising (k = %d per mesh), mean geodesic error over 900 GT points (direct / "
               "smaller of direct and symmetric), median conformal distortion:\n",
               ddm_k ? ddm_k : CORR_DDM_K);
        printf("| map | DDM | error before | after | change | sym-min before | after | median "
               "conformal before | after | ratio | round trip before | after | flipped | targets |\n"
               "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
    }
    typedef struct refine_row { char name[64], chain[32]; score s, s0; double secs; } refine_row;
    refine_row rows[64];
    int nrows = 0, met[3] = {0, 0, 0}, total = 0;
    for (int q = 0; q < 6; q++) {
        char name[64];
        snprintf(name, sizeof name, "%s_%s", pairs[q][0], pairs[q][1]);
        if (!harness_list_has(o_pairs, name))
            continue;
        int refine = o_refine ? (strcmp(o_refine, "all") == 0 || harness_list_has(o_refine, name))
                              : q < 3;
        testgt g;
        testgt_vts(&g, DIR, pairs[q][0], pairs[q][1], 3);
        char err[1024] = "";
        geod_solver *sT = NULL;
        if (geod_solver_new(g.T, 0, &sT, err, sizeof err))
            FAILF("%s", err);
        bmap *bcicp = NULL, *bcicp_q = NULL;
        score s_bcicp = {0, 0, 0, 0};
        for (int method = 0; method < 2; method++) {
            char rel[256];
            snprintf(rel, sizeof rel, DIR "/maps_baseline/%s/%s.map",
                     method ? "WKSini_direct_BCICP" : "BIM", name);
            char rrel[256];               /* the same method's reverse map: q */
            snprintf(rrel, sizeof rrel, DIR "/maps_baseline/%s/%s_%s.map",
                     method ? "WKSini_direct_BCICP" : "BIM", pairs[q][1], pairs[q][0]);
            bmap *P0 = NULL, *Q0 = NULL;
            if (vmap_read(harness_data_path(rel), method, g.S, g.T, &P0, NULL, err, sizeof err) ||
                vmap_read(harness_data_path(rrel), method, g.T, g.S, &Q0, NULL, err, sizeof err))
                FAILF("%s", err);
            score a = score_of(&g, sT, P0);
            double rt0;
            if (metric_round_trip(g.S, g.T, P0, Q0, &rt0))
                FAILF("round trip failed");
            total++;
            for (int mode = 0; table && mode < 3; mode++) {   /* plain, bijective, auto */
                double secs, rt1;
                bmap *Q1 = NULL;
                bmap *P1 = run_chain(&g, P0, Q0, (corr_ddm_mode)mode, CORR_STAGES_DDM, &p, &secs, &Q1);
                score b = score_of(&g, sT, P1);
                if (metric_round_trip(g.S, g.T, P1, Q1, &rt1))
                    FAILF("round trip failed");
                int ok = b.err <= a.err + 0.005 && b.median_conformal <= 0.5 * a.median_conformal;
                met[mode] += ok;
                printf("| %s %s | %s | %.4f | %.4f | %+.4f | %.4f | %.4f | %.3f | %.3f | %.2f | %.4f | "
                       "%.4f | %.1f -> %.1f %% | %s (%.1f s) |\n", method ? "BCICP" : "BIM", name,
                       mode == 2 ? "auto" : mode ? "bijective" : "plain", a.err, b.err, b.err - a.err, a.err_sym,
                       b.err_sym, a.median_conformal, b.median_conformal,
                       b.median_conformal / a.median_conformal, rt0, rt1, 100 * a.flipped, 100 * b.flipped, ok ? "met" : "NOT met",
                       secs);
                fflush(stdout);
                bmap_free(P1);
                bmap_free(Q1);
            }
            if (method) {
                bcicp = P0;
                bcicp_q = Q0;
                s_bcicp = a;
            } else {
                bmap_free(P0);
                bmap_free(Q0);
            }
        }
        for (char *c = chains; refine && *c;) {
            size_t n = strcspn(c, ";");
            char text[32];
            snprintf(text, sizeof text, "%.*s", (int)n, c);
            c += n + (c[n] == ';');
            corr_stages st;
            if (corr_stages_parse(text, &st, err, sizeof err))
                FAILF("--chains: %s", err);
            refine_row *r = &rows[nrows < 63 ? nrows++ : 63];
            snprintf(r->name, sizeof r->name, "%s", name);
            snprintf(r->chain, sizeof r->chain, "%s", text);
            bmap *P = run_chain(&g, bcicp, with_reverse ? bcicp_q : NULL, CORR_DDM_AUTO, st, &p,
                                &r->secs, NULL);
            r->s = score_of(&g, sT, P);
            r->s0 = s_bcicp;
            printf("  (%s %s: error %.4f -> %.4f, %.0f s)\n", name, text, s_bcicp.err, r->s.err,
                   r->secs);
            fflush(stdout);
            bmap_free(P);
        }
        bmap_free(bcicp);
        bmap_free(bcicp_q);
        geod_solver_free(sT);
        testgt_close(&g);
    }
    if (table)
        printf("DDM targets met on %d of %d maps (plain), %d of %d (bijective), %d of %d (auto, the "
           "default).\n", met[0], total, met[1], total, met[2], total);
    if (nrows) {
        printf("\nThe BCICP map refined (no landmarks; ECTM %d outer iterations, RHM %s; %s):\n",
               p.iterations, "release defaults",
               with_reverse ? "with its published reverse map" : "the map alone");
        printf("| map | chain | error BCICP | after | sym-min BCICP | after | median conformal | "
               "flipped | seconds | lower error |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---|\n");
        for (int i = 0; i < nrows; i++)
            printf("| %s | %s | %.4f | %.4f | %.4f | %.4f | %.3f -> %.3f | %.1f %% | %.0f | %s |\n",
                   rows[i].name, rows[i].chain, rows[i].s0.err, rows[i].s.err, rows[i].s0.err_sym,
                   rows[i].s.err_sym, rows[i].s0.median_conformal, rows[i].s.median_conformal,
                   100 * rows[i].s.flipped, rows[i].secs, rows[i].s.err < rows[i].s0.err ? "yes" : "no");
    }
}
