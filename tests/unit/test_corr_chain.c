/* test_corr_chain.c — the pipeline's stage chains (corr.h): reading
 * "ddm,rhm,ectm" and refusing chains out of order with the reason; which
 * chains the inputs allow; on TOSCA gorilla_01 -> man_01 from the published
 * BCICP vertex map: the ddm stage returns exactly ddm_denoise's map, the
 * ddm,ectm chain reports DDM then every ECTM iteration and keeps the
 * map's error, and ddm,rhm runs RHM from the denoised map with no
 * landmarks; ddm_mode auto denoises BCICP's map and its reverse (which
 * agree) together and BIM's (one direction flipped) each alone; RHM from
 * a given map stays near it by its anchors; ECTM's folded maps are
 * repaired on ddm,rhm,ectm (only those folded) and not on ddm,ectm;
 * a chain RHM then ECTM keeps RHM's maps as stages rhm returns them;
 * make demo's job (cow -> camel from landmarks) returns both maps within
 * the fold targets (at most 0.1 % flipped and none collapsed forward; 2 %
 * and 0.5 % back). */
#include "support/harness.h"
#include "support/testcowcamel.h"
#include "support/testddm.h"
#include "support/testgt.h"
#include "support/testmesh.h"
#include "corr/corr.h"
#include "ddm/ddm.h"
#include "geod/geod.h"
#include "lbo/lbo.h"
#include "map/vmap.h"
#include "metric/metric.h"

#include <math.h>
#include <string.h>

TEST(chains_parse_in_order_and_out_of_order_is_refused_with_the_reason)
{
    static const struct { const char *text; int value; } ok[] = {
        {"all", CORR_CHAIN_ALL}, {"rhm", CORR_CHAIN_RHM}, {"ectm", CORR_CHAIN_ECTM},
        {"ddm", CORR_CHAIN_DDM}, {"ddm,ectm", CORR_CHAIN_DDM_ECTM},
        {"ddm,rhm", CORR_CHAIN_DDM_RHM}, {"ddm,rhm,ectm", CORR_CHAIN_DDM_RHM_ECTM},
        {"rhm,ectm", CORR_CHAIN_RHM_ECTM}};
    char err[512], name[64];
    for (size_t k = 0; k < sizeof ok / sizeof ok[0]; k++) {
        corr_chain s = (corr_chain)-1;
        if (corr_chain_parse(ok[k].text, &s, err, sizeof err))
            FAILF("%s: %s", ok[k].text, err);
        CHECK_INT(s, ok[k].value);
        /* the same names as the job parameter's values (the wire, --help) */
        CHECK(proto_param_value_name(PROTO_P_stages, (unsigned)s, name, sizeof name));
        CHECK(strcmp(name, ok[k].text) == 0);
    }
    static const struct { const char *text, *msg; } bad[] = {
        {"ectm,ddm", "ectm before ddm: stages run in the order ddm, rhm, ectm"},
        {"rhm,ddm,ectm", "rhm before ddm"},
        {"ectm,rhm", "ectm before rhm"},
        {"ddm,ddm", "ddm is named twice"},
        {"ddm,fmap", "'fmap' is not a stage (ddm, rhm, ectm, or all)"},
        {"all,ectm", "all stands alone"},
        {"", "'' is not a stage"},
        {"ddm,", "'' is not a stage"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        corr_chain s;
        err[0] = '\0';
        CHECK_INT(corr_chain_parse(bad[k].text, &s, err, sizeof err), -1);
        CHECK_STR_HAS(err, bad[k].msg);
    }
}

TEST(chains_the_inputs_cannot_run_are_refused)
{
    char err[512];
    /* all: RHM then ECTM from landmarks, ECTM alone on a map */
    CHECK(corr_chain_run(CORR_CHAIN_ALL, 0) == (CORR_RUN_RHM | CORR_RUN_ECTM));
    CHECK(corr_chain_run(CORR_CHAIN_ALL, 1) == CORR_RUN_ECTM);
    CHECK_INT(corr_chain_check(CORR_CHAIN_ALL, 0, 0, 6, 0, 0, 0, err, sizeof err), 0);
    CHECK_INT(corr_chain_check(CORR_CHAIN_DDM_RHM_ECTM, 1, 1, 0, 0, 0, 0, err, sizeof err), 0);
    CHECK_INT(corr_chain_check(CORR_CHAIN_RHM, 1, 0, 0, 0, 0, 0, err, sizeof err), 0);
    CHECK_INT(corr_chain_check(CORR_CHAIN_DDM, 1, 1, 0, 0, 0, CORR_DDM_BIJECTIVE, err, sizeof err), 0);
    CHECK_INT(corr_chain_check(CORR_CHAIN_ECTM, 1, 0, 0, 0, 0, CORR_DDM_BIJECTIVE, err, sizeof err),
              0);                                  /* no DDM stage: the mode is not used */
    CHECK_INT(corr_chain_check(CORR_CHAIN_DDM, 1, 0, 0, 0, 0, CORR_DDM_AUTO, err, sizeof err),
              0);                                  /* auto without a reverse map: plain */
    /* each refusal with its kind: a chain that does not fit the inputs is
     * PARAMS, missing landmarks LANDMARKS, a reverse map alone MAP */
    static const struct { int s, map, rev, nl, inj; double gamma; int mode; const char *msg; int kind; } bad[] = {
        {CORR_CHAIN_DDM_ECTM, 0, 0, 6, 0, 0, 0, "the DDM stage denoises a given map", KIND_EPARAMS},
        {CORR_CHAIN_DDM, 0, 0, 6, 0, 0, 0, "the DDM stage denoises a given map", KIND_EPARAMS},
        {CORR_CHAIN_ECTM, 0, 0, 6, 0, 0, 0, "the ECTM stage alone needs an initial map", KIND_EPARAMS},
        {CORR_CHAIN_ALL, 0, 0, 0, 0, 0, 0, "neither an initial map nor landmarks", KIND_ELANDMARKS},
        {CORR_CHAIN_RHM_ECTM, 0, 0, 2, 0, 0, 0, "at least 3 landmark pairs, got 2", KIND_ELANDMARKS},
        {CORR_CHAIN_DDM_RHM, 1, 0, 0, 0, 0.5, 0, "weak landmark term (rhm_landmark_weight 0.5) needs landmarks",
         KIND_EPARAMS},
        {CORR_CHAIN_DDM_ECTM, 1, 1, 0, 1, 0, 0, "reverse map needs the bijective model", KIND_EPARAMS},
        {CORR_CHAIN_RHM, 0, 1, 6, 0, 0, 0, "reverse map needs an initial map", KIND_EMAP},
        {CORR_CHAIN_DDM_ECTM, 1, 0, 0, 0, 0, CORR_DDM_BIJECTIVE, "it needs an initial reverse map too",
         KIND_EPARAMS},
        {CORR_CHAIN_DDM, 1, 1, 0, 0, 0, 3, "ddm_mode value 3", KIND_EPARAMS},
        {8, 1, 0, 0, 0, 0, 0, "stages value 8", KIND_EPARAMS}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        err[0] = '\0';
        CHECK_INT(corr_chain_check((corr_chain)bad[k].s, bad[k].map, bad[k].rev, bad[k].nl,
                                    bad[k].inj, bad[k].gamma, (corr_ddm_mode)bad[k].mode, err,
                                    sizeof err), bad[k].kind);
        CHECK_STR_HAS(err, bad[k].msg);
    }
}

typedef struct stage_log {
    int n, stage[1024], outer[1024], total[1024];
    double ddm_cost;
} stage_log;

static int record(void *ctx, const corr_progress *p)
{
    stage_log *l = ctx;
    if (l->n < 1024) {
        l->stage[l->n] = p->stage;
        l->outer[l->n] = p->ectm ? p->ectm->outer : p->rhm ? p->rhm->iteration
                       : p->ddm ? p->ddm->done : p->repair ? p->repair->done : 0;
        l->total[l->n] = p->ectm ? p->ectm->total : 0;
        l->n++;
    }
    if (p->ddm && p->ddm->done)
        l->ddm_cost = p->ddm->cost[p->ddm->done - 1];
    return 0;
}

static double mean_error(const testgt *g, const bmap *P)
{
    char err[256];
    geod_solver *s = NULL;
    if (geod_solver_new(g->T, 0, &s, err, sizeof err))
        FAILF("%s", err);
    double e = testddm_mean_error(s, g->T, P, g->src, g->tgt, g->n);
    geod_solver_free(s);
    return e;
}

/* The published map of METHOD from 8_A onto 8_B (TOSCA_r non-isometric),
 * on the meshes S (8_A) and T (8_B). */
static bmap *published_map(const mesh *S, const mesh *T, const char *method, int base,
                           const char *a, const char *b)
{
    char rel[256], err[1024] = "";
    snprintf(rel, sizeof rel, "tosca_r_nonisometric/vtx_5k/maps_baseline/%s/8_%s_8_%s.map",
             method, a, b);
    bmap *P = NULL;
    if (vmap_read(harness_data_path(rel), base, S, T, &P, NULL, err, sizeof err))
        FAILF("%s", err);
    return P;
}

TEST_T(ddm_then_ectm_on_the_bcicp_map_of_gorilla_to_man, 300)
{
    testgt g;
    testgt_vts(&g, "tosca_r_nonisometric/vtx_5k", "8_gorilla_01", "8_man_01", 3);
    char err[1024] = "";
    bmap *P0 = published_map(g.S, g.T, "WKSini_direct_BCICP", VMAP_BASE_AUTO, "gorilla_01", "man_01");
    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 4;
    p.beta_ramp = 4;
    p.inner_iterations = 10;
    rhm_params rp;
    rhm_params_init(&rp);
    rp.iterations = 3;
    int k = CORR_DDM_K;             /* ddm_k 0: the default */

    /* ddm alone: the map ddm_denoise makes from the same bases */
    corr_input in = {g.S, g.T, "gorilla_01", "man_01", NULL, P0, NULL, &rp, CORR_CHAIN_DDM, 0, CORR_DDM_PLAIN};
    ectm_result r = {0};
    stage_log l = {0};
    if (corr_run(&in, &p, record, &l, &r, err, sizeof err))
        FAILF("%s", err);
    CHECK_INT(l.n, 2);                 /* start, then the one direction (no Q given) */
    CHECK_INT(l.stage[0], CORR_STAGE_DDM);
    CHECK_INT(l.outer[0], 0);
    CHECK_INT(l.outer[1], 1);
    CHECK(r.P && !r.Q && !r.Y);
    geod_solver *sS = NULL, *sT = NULL;
    lbo_basis bS, bT;
    if (geod_solver_new(g.S, 0, &sS, err, sizeof err) || geod_solver_new(g.T, 0, &sT, err, sizeof err) ||
        lbo_eigenpairs(geod_solver_laplacian(sS), geod_solver_mass(sS), g.S->nv, k, &bS, err, sizeof err) ||
        lbo_eigenpairs(geod_solver_laplacian(sT), geod_solver_mass(sT), g.T->nv, k, &bT, err, sizeof err))
        FAILF("%s", err);
    bmap *D = bmap_new(g.S->nv, g.T->nv);
    ddm_stats st;
    if (ddm_denoise(&bS, geod_solver_mass(sS), &bT, g.T, P0, k, k, D, &st, err, sizeof err))
        FAILF("%s", err);
    for (int i = 0; i < D->n; i++) {
        CHECK_INT(r.P->face[i], D->face[i]);
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(r.P->w[3 * i + c], D->w[3 * i + c], 1e-12);
    }
    CHECK_NEAR(l.ddm_cost, st.cost, 1e-12 * st.cost);
    double e0 = mean_error(&g, P0), ed = mean_error(&g, r.P);
    ectm_result_close(&r);

    /* ddm,ectm: DDM's reports, then ECTM's 4 iterations from D */
    in.stages = CORR_CHAIN_DDM_ECTM;
    memset(&l, 0, sizeof l);
    if (corr_run(&in, &p, record, &l, &r, err, sizeof err))
        FAILF("%s", err);
    CHECK_INT(l.n, 2 + 4);
    CHECK_INT(l.stage[1], CORR_STAGE_DDM);
    for (int i = 2; i < l.n; i++) {
        CHECK_INT(l.stage[i], CORR_STAGE_ECTM);
        CHECK_INT(l.outer[i], i - 1);
    }
    CHECK(r.P && r.Q && r.Y);
    double ee = mean_error(&g, r.P);
    metric_summary m0, m1;
    CHECK_INT(metric_summarize(g.S, g.T, P0, &m0), 0);
    CHECK_INT(metric_summarize(g.S, g.T, r.P, &m1), 0);
    printf("  error: BCICP %.4f, ddm %.4f, ddm,ectm (4 iterations) %.4f; median conformal %.3f -> %.3f\n",
           e0, ed, ee, m0.median_conformal, m1.median_conformal);
    CHECK(ed <= e0 + 0.005);
    CHECK(ee <= e0 + 0.01);
    CHECK(m1.median_conformal < 0.5 * m0.median_conformal);
    ectm_result_close(&r);

    /* ddm,rhm: RHM from the denoised map, no landmarks, its 3 iterations */
    in.stages = CORR_CHAIN_DDM_RHM;
    memset(&l, 0, sizeof l);
    if (corr_run(&in, &p, record, &l, &r, err, sizeof err))
        FAILF("%s", err);
    CHECK_INT(l.n, 2 + 1 + 3 + 2);    /* ... and the repair of RHM's maps: its start and end */
    CHECK_INT(l.stage[2], CORR_STAGE_START);
    CHECK_INT(l.stage[5], CORR_STAGE_RHM);
    CHECK_INT(l.outer[5], 3);
    CHECK_INT(l.stage[6], CORR_STAGE_REPAIR);
    CHECK_INT(l.outer[6], 0);
    CHECK_INT(l.stage[7], CORR_STAGE_REPAIR);
    CHECK_INT(l.outer[7], 2);
    CHECK(r.P && r.Q && !r.Y);
    printf("  ddm,rhm (3 iterations): error %.4f\n", mean_error(&g, r.P));
    ectm_result_close(&r);

    /* a basis larger than the mesh allows names the parameter */
    in.stages = CORR_CHAIN_DDM;
    in.ddm_k = 4999;
    CHECK_INT(corr_run(&in, &p, NULL, NULL, &r, err, sizeof err), KIND_EPARAMS);
    CHECK_STR_HAS(err, "params.ddm_k = 4999");

    bmap_free(D);
    lbo_basis_close(&bS);
    lbo_basis_close(&bT);
    geod_solver_free(sS);
    geod_solver_free(sT);
    bmap_free(P0);
    testgt_close(&g);
}

typedef struct ddm_choice {
    int reports, mode;
    double round_trip;
} ddm_choice;

static int record_choice(void *ctx, const corr_progress *p)
{
    ddm_choice *c = ctx;
    if (p->ddm && c->reports++ == 0) {   /* the stage's first report says what runs */
        c->mode = p->ddm->mode;
        c->round_trip = p->ddm->round_trip;
    }
    return 0;
}

/* The published pair P0 (gorilla_01 -> man_01), Q0 (back) of one method. */
static void published_pair(const testgt *g, const char *method, int base, bmap **P0, bmap **Q0)
{
    *P0 = published_map(g->S, g->T, method, base, "gorilla_01", "man_01");
    *Q0 = published_map(g->T, g->S, method, base, "man_01", "gorilla_01");
}

TEST_T(ddm_auto_denoises_an_agreeing_pair_together_and_a_disagreeing_one_apart, 300)
{
    testgt g;
    testgt_vts(&g, "tosca_r_nonisometric/vtx_5k", "8_gorilla_01", "8_man_01", 3);
    char err[1024] = "";
    ectm_params p;
    ectm_params_init(&p);
    corr_input in = {g.S, g.T, "gorilla_01", "man_01", NULL, NULL, NULL, NULL, CORR_CHAIN_DDM, 0,
                     CORR_DDM_AUTO};
    ectm_result r = {0}, plain = {0};

    /* BIM's two maps disagree wholesale (gorilla_01 -> man_01 is flipped
     * left to right, its reverse is not): each is denoised alone, the same
     * maps as plain's */
    bmap *P0 = NULL, *Q0 = NULL;
    published_pair(&g, "BIM", 0, &P0, &Q0);
    in.P0 = P0;
    in.Q0 = Q0;
    ddm_choice c = {0, -1, 0};
    if (corr_run(&in, &p, record_choice, &c, &r, err, sizeof err))
        FAILF("%s", err);
    printf("  BIM: round trip %.4f -> %s\n", c.round_trip, c.mode ? "bijective" : "plain");
    CHECK_INT(c.mode, CORR_DDM_PLAIN);
    CHECK(c.round_trip > CORR_DDM_AUTO_ROUND_TRIP);
    CHECK_INT(c.reports, 3);                /* the start, then each direction */
    in.ddm_mode = CORR_DDM_PLAIN;
    if (corr_run(&in, &p, NULL, NULL, &plain, err, sizeof err))
        FAILF("%s", err);
    CHECK(r.P && r.Q && plain.P && plain.Q);
    for (int i = 0; i < r.P->n; i++)
        CHECK_INT(r.P->face[i], plain.P->face[i]);
    for (int i = 0; i < r.Q->n; i++)
        CHECK_INT(r.Q->face[i], plain.Q->face[i]);
    ectm_result_close(&r);
    ectm_result_close(&plain);
    bmap_free(P0);
    bmap_free(Q0);

    /* BCICP's agree: denoised together, one report when both are done,
     * and the denoised pair is as consistent as the given one */
    published_pair(&g, "WKSini_direct_BCICP", 1, &P0, &Q0);
    in.P0 = P0;
    in.Q0 = Q0;
    in.ddm_mode = CORR_DDM_AUTO;
    c = (ddm_choice){0, -1, 0};
    if (corr_run(&in, &p, record_choice, &c, &r, err, sizeof err))
        FAILF("%s", err);
    double rt0 = NAN, rt1 = NAN;
    CHECK_INT(metric_round_trip(g.S, g.T, P0, Q0, &rt0), 0);
    CHECK_INT(metric_round_trip(g.S, g.T, r.P, r.Q, &rt1), 0);
    printf("  BCICP: round trip %.4f -> %s; denoised pair's round trip %.4f (given %.4f)\n",
           c.round_trip, c.mode ? "bijective" : "plain", rt1, rt0);
    CHECK_INT(c.mode, CORR_DDM_BIJECTIVE);
    CHECK(c.round_trip <= CORR_DDM_AUTO_ROUND_TRIP && c.round_trip >= rt0);
    CHECK_INT(c.reports, 2);                /* the start, then both together */
    CHECK(rt1 <= 1.5 * rt0);
    ectm_result_close(&r);

    /* with no reverse map auto is plain, and says it did not choose */
    in.Q0 = NULL;
    c = (ddm_choice){0, -1, 0};
    if (corr_run(&in, &p, record_choice, &c, &r, err, sizeof err))
        FAILF("%s", err);
    CHECK_INT(c.mode, CORR_DDM_PLAIN);
    CHECK(isnan(c.round_trip));
    ectm_result_close(&r);
    bmap_free(P0);
    bmap_free(Q0);
    testgt_close(&g);
}

/* RHM from a given map is held to it by its anchors (rhm.h, RHM_ANCHORS):
 * the published BCICP pair gorilla_01 <-> woman_01, denoised together by
 * DDM (0.0502), then RHM with no landmarks: measured 0.0476 with the
 * anchors, 0.0627 without (rp.anchor 0: nothing holds RHM to the map, it
 * drifts above the input's 0.0527). */
TEST_T(rhm_from_a_given_map_is_held_to_it_by_its_anchors, 300)
{
    testgt g;
    testgt_vts(&g, "tosca_r_nonisometric/vtx_5k", "8_gorilla_01", "8_woman_01", 3);
    char err[1024] = "";
    bmap *P0 = published_map(g.S, g.T, "WKSini_direct_BCICP", VMAP_BASE_AUTO, "gorilla_01", "woman_01");
    bmap *Q0 = published_map(g.T, g.S, "WKSini_direct_BCICP", VMAP_BASE_AUTO, "woman_01", "gorilla_01");
    ectm_params p;
    ectm_params_init(&p);
    rhm_params rp;
    rhm_params_init(&rp);
    CHECK(rp.anchor > 0 && rp.anchors > 0);
    double e0 = mean_error(&g, P0), e[2];
    for (int k = 0; k < 2; k++) {
        if (k)
            rp.anchor = 0;
        corr_input in = {g.S, g.T, "gorilla_01", "woman_01", NULL, P0, Q0, &rp,
                         CORR_CHAIN_DDM_RHM, 0, CORR_DDM_AUTO};
        ectm_result r = {0};
        if (corr_run(&in, &p, NULL, NULL, &r, err, sizeof err))
            FAILF("%s", err);
        e[k] = mean_error(&g, r.P);
        ectm_result_close(&r);
    }
    printf("  BCICP %.4f; ddm,rhm with anchors %.4f, without %.4f\n", e0, e[0], e[1]);
    CHECK(e[0] < e0);
    CHECK(e[1] > e[0] + 0.005);
    bmap_free(P0);
    bmap_free(Q0);
    testgt_close(&g);
}

/* The bad share (flipped plus collapsed) of the map P from A onto B. */
static double bad_share(const mesh *A, const mesh *B, const bmap *P)
{
    metric_summary m;
    CHECK_INT(metric_summarize(A, B, P, &m), 0);
    return m.flipped_fraction + m.collapsed_fraction;
}

static int same_map(const bmap *a, const bmap *b)
{
    return a->n == b->n && !memcmp(a->face, b->face, sizeof(int) * (size_t)a->n) &&
           !memcmp(a->w, b->w, sizeof(double) * 3 * (size_t)a->n);
}

/* The RHM maps a chain RHM then ECTM keeps beside ECTM's (rhm_P, rhm_Q)
 * are, bit for bit, what stages rhm returns for the same job: on a small
 * sphere pair as given, and on a larger one over twice the coarse size (the decimated
 * pair's RHM maps carried back and repaired). Q only for the bijective
 * model; a chain without RHM keeps none. */
TEST_T(rhm_then_ectm_keeps_the_rhm_maps_stages_rhm_returns, 300)
{
    static int lv[6] = {0, 1, 2, 3, 4, 5};
    lmk_set L = {6, lv, lv};
    rhm_params rp;
    rhm_params_init(&rp);
    rp.iterations = 6;
    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 3;
    p.beta_ramp = 3;
    p.inner_iterations = 5;
    char err[1024];
    for (int k = 0; k < 3; k++) {
        mesh *S = testmesh_icosphere(k == 1 ? 4 : 3), *T = testmesh_icosphere(k == 1 ? 4 : 3);
        for (int i = 0; i < T->nv; i++) {
            double *x = &T->v[3 * i];
            x[0] *= 1.3;
            x[2] += 0.15 * x[0] * x[0];
        }
        rp.coarse = k == 1 ? 500 : 0;       /* 2562 vertices: decimated to 500 */
        p.model = k == 2 ? ECTM_INJECTIVE : ECTM_BIJECTIVE;
        corr_input in = {S, T, "s", "t", &L, NULL, NULL, &rp, CORR_CHAIN_ALL, 0, CORR_DDM_PLAIN};
        CHECK_INT(corr_coarse_wanted(&in), k == 1);
        ectm_result all = {0}, rhm = {0};
        if (corr_run(&in, &p, NULL, NULL, &all, err, sizeof err))
            FAILF("%s", err);
        in.stages = CORR_CHAIN_RHM;
        if (corr_run(&in, &p, NULL, NULL, &rhm, err, sizeof err))
            FAILF("%s", err);
        CHECK(all.rhm_P && rhm.P && !rhm.rhm_P);
        CHECK(same_map(all.rhm_P, rhm.P));
        CHECK(!same_map(all.rhm_P, all.P));          /* ECTM moved it */
        if (p.model == ECTM_BIJECTIVE)
            CHECK(all.rhm_Q && same_map(all.rhm_Q, rhm.Q));
        else
            CHECK(!all.rhm_Q && !all.Q);
        ectm_result_close(&all);
        ectm_result_close(&rhm);
        mesh_free(S);
        mesh_free(T);
    }
}

/* Which of ECTM's maps a given map's chain repairs (corr_run): through RHM
 * (ddm,rhm,ectm), each map that ECTM leaves folded (metric_verdict: over
 * 5 % flipped plus collapsed) and only those, exactly as corr_repair does
 * it; from the given map itself (ddm,ectm), none, folded or not. The
 * published BCICP map gorilla_01 -> man_02 (no reverse given), ECTM's 30
 * iterations with β ramped over them: ECTM run by hand from the chain's
 * own inputs (ddm,rhm's maps, DDM's map) must leave a map folded for the
 * rule to be tested, and the test says so when it does not. */
TEST_T(a_given_maps_chain_repairs_ectms_folded_maps_only_through_rhm, 300)
{
    testgt g;
    testgt_vts(&g, "tosca_r_nonisometric/vtx_5k", "8_gorilla_01", "8_man_02", 3);
    char err[1024] = "";
    bmap *P0 = published_map(g.S, g.T, "WKSini_direct_BCICP", VMAP_BASE_AUTO, "gorilla_01", "man_02");
    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 30;
    p.beta_ramp = 30;
    rhm_params rp;
    rhm_params_init(&rp);
    corr_input in = {g.S, g.T, "gorilla_01", "man_02", NULL, P0, NULL, &rp,
                     CORR_CHAIN_DDM_RHM, 0, CORR_DDM_AUTO};
    ectm_landmarks none = {NULL, NULL, 0};

    /* through RHM: ECTM by hand from ddm,rhm's maps, then the chain */
    ectm_result r = {0}, e = {0}, c = {0};
    if (corr_run(&in, &p, NULL, NULL, &r, err, sizeof err) ||
        ectm_run(g.S, g.T, r.P, r.Q, &none, &p, NULL, NULL, &e, err, sizeof err))
        FAILF("%s", err);
    double fP = bad_share(g.S, g.T, e.P), fQ = bad_share(g.T, g.S, e.Q);
    printf("  ddm,rhm then ECTM: bad %.2f %% forward, %.2f %% reverse\n", 100 * fP, 100 * fQ);
    if (metric_verdict(fP, 0) == METRIC_VERDICT_OK && metric_verdict(fQ, 0) == METRIC_VERDICT_OK)
        FAILF("ECTM from ddm,rhm's maps left no map folded: the rule is not tested");
    fold_report rep[2];
    if (corr_repair(&in, metric_verdict(fP, 0) ? e.P : NULL, metric_verdict(fQ, 0) ? e.Q : NULL, 1,
                    rep, err, sizeof err))
        FAILF("%s", err);
    in.stages = CORR_CHAIN_DDM_RHM_ECTM;
    if (corr_run(&in, &p, NULL, NULL, &c, err, sizeof err))
        FAILF("%s", err);
    CHECK(same_map(c.P, e.P));
    CHECK(same_map(c.Q, e.Q));
    double gP = bad_share(g.S, g.T, c.P), gQ = bad_share(g.T, g.S, c.Q);
    printf("  ddm,rhm,ectm returns: bad %.2f %% forward, %.2f %% reverse\n", 100 * gP, 100 * gQ);
    CHECK_INT(metric_verdict(gP, 0), METRIC_VERDICT_OK);
    CHECK_INT(metric_verdict(gQ, 0), METRIC_VERDICT_OK);
    ectm_result_close(&r);
    ectm_result_close(&e);
    ectm_result_close(&c);

    /* from the given map: ECTM by hand from DDM's map, then the chain */
    in.stages = CORR_CHAIN_DDM;
    if (corr_run(&in, &p, NULL, NULL, &r, err, sizeof err) ||
        ectm_run(g.S, g.T, r.P, NULL, &none, &p, NULL, NULL, &e, err, sizeof err))
        FAILF("%s", err);
    fP = bad_share(g.S, g.T, e.P);
    printf("  ddm then ECTM: bad %.2f %% forward\n", 100 * fP);
    if (metric_verdict(fP, 0) == METRIC_VERDICT_OK)
        FAILF("ECTM from DDM's map left it unfolded: the rule is not tested");
    in.stages = CORR_CHAIN_DDM_ECTM;
    if (corr_run(&in, &p, NULL, NULL, &c, err, sizeof err))
        FAILF("%s", err);
    CHECK(same_map(c.P, e.P));
    CHECK(same_map(c.Q, e.Q));
    ectm_result_close(&r);
    ectm_result_close(&e);
    ectm_result_close(&c);
    bmap_free(P0);
    testgt_close(&g);
}

/* A pair over twice the coarse size (job parameter coarse, 6000 by
 * default) from landmarks: TOSCA wolf0 -> wolf2
 * (tosca_hires, 4344 vertices, the 21 landmarks of Corrs/wolf.pid) split
 * 1-to-4 (17370 vertices; the shipped vertices keep their indices, so the
 * identity is their ground truth — not the midpoints', as the two meshes'
 * face lists differ in 240 faces). The chain runs on the decimated pair
 * (RHM, then ECTM: its iterations and the input pair's counted as one
 * run of at most twice the iterations, so a progress bar does not restart), the maps come back on the input meshes with ECTM's
 * deformation of them, near the identity and unfolded; stages rhm stops
 * after the coarse RHM's maps are carried back. */
TEST_T(landmark_chain_on_a_fine_pair_runs_coarse_to_fine, 900)
{
    if (!harness_data_dir())
        SKIP("../shared/data is absent");
    mesh *S0 = testmesh_read("tosca_hires/Meshes/wolf0.off");
    mesh *T0 = testmesh_read("tosca_hires/Meshes/wolf2.off");
    mesh *S = testmesh_subdivided(S0), *T = testmesh_subdivided(T0);
    CHECK(S && T);
    char err[1024];
    lmk_set *L = testgt_pid_landmarks("tosca_hires/Corrs/wolf.pid", S, T);
    ectm_params p;
    ectm_params_init(&p);
    rhm_params rp;
    rhm_params_init(&rp);
    corr_input in = { S, T, "wolf0", "wolf2", L, NULL, NULL, &rp, CORR_CHAIN_ALL, 0,
                      CORR_DDM_PLAIN };
    CHECK(S->nv > 2 * rp.coarse && corr_coarse_wanted(&in));
    ectm_result r = {0};
    stage_log l = {0};
    if (corr_run(&in, &p, record, &l, &r, err, sizeof err))
        FAILF("%s", err);
    int ectm = 0, rhm = 0;
    for (int i = 0; i < l.n; i++) {
        if (l.stage[i] == CORR_STAGE_ECTM) {
            ectm++;
            CHECK_INT(l.outer[i], ectm);                 /* 1 .. 2K, no restart */
            CHECK_INT(l.total[i], 2 * p.iterations);
        }
        rhm += l.stage[i] == CORR_STAGE_RHM;
    }
    printf("  ectm: %d outer iterations over both runs, of at most %d\n", ectm, 2 * p.iterations);
    CHECK(ectm > ECTM_STOP_WINDOW && ectm <= 2 * p.iterations);   /* each run stops once settled */
    CHECK(rhm >= rp.min_iterations);
    CHECK(r.P && r.Q && r.Y);
    CHECK_INT(r.P->n, S->nv);
    CHECK_INT(r.Q->n, T->nv);
    bmap shipped = *r.P;        /* the rows of the shipped vertices */
    shipped.n = S0->nv;
    metric_summary m;
    CHECK_INT(metric_summarize(S, T, r.P, &m), 0);
    double e = testgt_identity_error(S, T, &shipped);
    printf("  all: error %.4f, flipped %.2f %%, collapsed %.2f %%\n", e, 100 * m.flipped_fraction,
           100 * m.collapsed_fraction);
    CHECK(e < 0.015);   /* against the identity; the last digits move with rounding */
    CHECK(m.flipped_fraction < 0.01);
    CHECK(m.collapsed_fraction < 0.005);
    ectm_result_close(&r);

    in.stages = CORR_CHAIN_RHM;
    memset(&l, 0, sizeof l);
    if (corr_run(&in, &p, record, &l, &r, err, sizeof err))
        FAILF("%s", err);
    for (int i = 0; i < l.n; i++)
        CHECK(l.stage[i] != CORR_STAGE_ECTM);
    CHECK(r.P && r.Q && !r.Y);
    CHECK_INT(r.P->n, S->nv);
    shipped = *r.P;
    shipped.n = S0->nv;
    e = testgt_identity_error(S, T, &shipped);
    printf("  rhm: error %.4f\n", e);
    CHECK(e < 0.03);
    ectm_result_close(&r);
    rp.coarse = 0;                  /* off: the chain runs on the meshes as given */
    CHECK(!corr_coarse_wanted(&in));
    lmk_free(L);
    mesh_free(S);
    mesh_free(T);
    mesh_free(S0);
    mesh_free(T0);
}

/* make demo's job as the engine runs it: cow -> camel from the demo's 16
 * landmarks, every stage with the defaults. The fold targets for it: the
 * map returned at most 0.1 % of its triangles flipped and none collapsed,
 * the reverse map at most 2 % and 0.5 %: what a regression of the fold
 * repair and relaxation shows first. */
TEST_T(make_demos_job_returns_both_maps_within_the_fold_targets, 600)
{
    mesh *S, *T;
    lmk_set *L;
    testcowcamel_load(&S, &T, &L);
    ectm_params p;
    ectm_params_init(&p);
    rhm_params rp;
    rhm_params_init(&rp);
    corr_input in = { S, T, "cow.off", "camel.off", L, NULL, NULL, &rp, CORR_CHAIN_ALL, 0,
                      CORR_DDM_PLAIN };
    ectm_result r = {0};
    char err[1024];
    if (corr_run(&in, &p, NULL, NULL, &r, err, sizeof err))
        FAILF("%s", err);
    metric_summary m, q;
    CHECK_INT(metric_summarize(S, T, r.P, &m), 0);
    CHECK_INT(metric_summarize(T, S, r.Q, &q), 0);
    printf("  cow -> camel: %.2f %% flipped, %.2f %% collapsed; back: %.2f %%, %.2f %%\n",
           100 * m.flipped_fraction, 100 * m.collapsed_fraction, 100 * q.flipped_fraction,
           100 * q.collapsed_fraction);
    CHECK(m.flipped_fraction <= 0.001);
    CHECK(m.collapsed_fraction == 0);
    CHECK(q.flipped_fraction <= 0.02);
    CHECK(q.collapsed_fraction <= 0.005);
    for (int k = 0; k < L->n; k++) {  /* each landmark lands on its target vertex */
        const int *f = T->f + 3 * r.P->face[L->src[k]];
        const double *w = r.P->w + 3 * L->src[k], *y = T->v + 3 * L->tgt[k];
        double d2 = 0;
        for (int d = 0; d < 3; d++) {
            double x = w[0] * T->v[3 * f[0] + d] + w[1] * T->v[3 * f[1] + d] + w[2] * T->v[3 * f[2] + d];
            d2 += (x - y[d]) * (x - y[d]);
        }
        CHECK(d2 < 1e-12);
    }
    ectm_result_close(&r);
    lmk_free(L);
    mesh_free(S);
    mesh_free(T);
}

/* The finishing policy's table covers every stage and chain: RHM's and
 * carried maps are always repaired and not relaxed; ECTM's are repaired and
 * relaxed in the landmark pipeline, only when folded on a given map's chain
 * through RHM, never when ECTM starts from the given map. */
TEST(the_finishing_policy_says_which_maps_get_the_fold_repair)
{
    mesh *S = testmesh_icosphere(1), *T = testmesh_icosphere(1);
    bmap *I = bmap_new(S->nv, T->nv);
    CHECK(S && T && I);
    for (int v = 0; v < S->nv; v++) {   /* the identity: no fold */
        for (int t = 0; t < T->nf; t++)
            for (int k = 0; k < 3; k++)
                if (T->f[3 * t + k] == v) {
                    I->face[v] = t;
                    I->w[3 * v] = I->w[3 * v + 1] = I->w[3 * v + 2] = 0;
                    I->w[3 * v + k] = 1;
                }
    }
    corr_input lm = { .S = S, .T = T }, given = { .S = S, .T = T, .P0 = I };
    for (int rhm = 0; rhm < 2; rhm++) {
        bmap *P = I, *Q = I;
        CHECK_INT(corr_finish_select(&lm, CORR_AFTER_RHM, rhm, &P, &Q), 0);
        CHECK(P == I && Q == I);
        CHECK_INT(corr_finish_select(&given, CORR_AFTER_CARRY, rhm, &P, &Q), 0);
        CHECK(P == I && Q == I);
        CHECK_INT(corr_finish_select(&lm, CORR_AFTER_ECTM, rhm, &P, &Q), 1);
        CHECK(P == I && Q == I);
    }
    bmap *P = I, *Q = NULL;
    CHECK_INT(corr_finish_select(&given, CORR_AFTER_ECTM, 1, &P, &Q), 1);
    CHECK(P == NULL && Q == NULL);      /* not folded: left as it is */
    bmap *C = bmap_new(S->nv, T->nv);   /* every vertex onto one point: collapsed */
    CHECK(C != NULL);
    for (int v = 0; v < S->nv; v++) {
        C->face[v] = 0;
        C->w[3 * v] = 1;
        C->w[3 * v + 1] = C->w[3 * v + 2] = 0;
    }
    P = C;
    CHECK_INT(corr_finish_select(&given, CORR_AFTER_ECTM, 1, &P, &Q), 1);
    CHECK(P == C && Q == NULL);
    P = C;
    CHECK_INT(corr_finish_select(&given, CORR_AFTER_ECTM, 0, &P, &Q), 0);
    CHECK(P == NULL && Q == NULL);
    bmap_free(C);
    bmap_free(I);
    mesh_free(S);
    mesh_free(T);
}
