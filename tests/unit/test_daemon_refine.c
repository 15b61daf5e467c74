/* test_daemon_refine.c — refining an uploaded map through the real
 * meshcorrd, meshcorr-worker and libmeshcorr: a job with stages ddm
 * streams the ddm stage and returns the in-process pipeline's map (the
 * same Draco-decoded meshes and map); ddm,ectm streams ddm then ECTM and
 * completes, and with the reverse map uploaded too (they agree) ddm_mode
 * auto says it denoised the two together; a chain that cannot run (ddm
 * with no map) and a basis larger than the meshes allow are refused before
 * SUBMIT_OK with the reason. Icospheres of 162 vertices, the target
 * stretched and bent, the map a vertex map sent as weight-1 rows. A job
 * from landmarks (RHM then ECTM) serves RHM's maps to a RESULT that asks
 * for them (PROTO_WANT_STAGE_RHM): those the in-process chain keeps, also
 * through mc_result_stage and `meshcorr result --out-stage`. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testmesh.h"
#include "support/testraw.h"
#include "support/testrun.h"
#include "corr/corr.h"
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "meshcorr.h"

#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct watch_log {
    int n;
    int stage[256];
    uint32_t outer[256], total[256];
    double energy[256], beta[256], gamma[256];
} watch_log;

static int on_progress(void *ctx, const mc_progress *p)
{
    watch_log *w = ctx;
    if (w->n < 256) {
        w->stage[w->n] = p->stage;
        w->outer[w->n] = p->outer;
        w->total[w->n] = p->total;
        w->energy[w->n] = p->energy[0];
        w->beta[w->n] = p->beta;
        w->gamma[w->n] = p->gamma;
        w->n++;
    }
    return 0;
}

typedef struct pair {
    unsigned char *sb, *tb;
    size_t sl, tl;
    mesh *S, *T;              /* as the worker decodes them */
    bmap *P0;                 /* vertex i -> vertex i, weight 1 */
    mc_map_row *rows;
} pair;

static void pair_open(pair *p)
{
    mesh *S = testmesh_icosphere(2), *T = testmesh_icosphere(2);
    for (int i = 0; i < T->nv; i++) {
        double *x = &T->v[3 * i];
        x[0] *= 1.3;
        x[2] += 0.15 * x[0] * x[0];
    }
    p->sb = testdaemon_encode(S, &p->sl);
    p->tb = testdaemon_encode(T, &p->tl);
    mesh_free(S);
    mesh_free(T);
    char err[512];
    if (mesh_read_drc_mem(p->sb, p->sl, 1 << 20, 1 << 21, "source", &p->S, err, sizeof err) ||
        mesh_read_drc_mem(p->tb, p->tl, 1 << 20, 1 << 21, "target", &p->T, err, sizeof err))
        FAILF("%s", err);
    p->P0 = bmap_new(p->S->nv, p->T->nv);
    p->rows = calloc((size_t)p->S->nv, sizeof *p->rows);
    int *vf = malloc(sizeof(int) * (size_t)p->T->nv);
    for (int q = 3 * p->T->nf - 1; q >= 0; q--)
        vf[p->T->f[q]] = q;
    for (int i = 0; i < p->S->nv; i++) {
        p->P0->face[i] = vf[i] / 3;
        p->P0->w[3 * i + vf[i] % 3] = 1;
        p->rows[i].face = (uint32_t)(vf[i] / 3);
        p->rows[i].w[vf[i] % 3] = 1;
    }
    free(vf);
}

static void pair_close(pair *p)
{
    free(p->sb);
    free(p->tb);
    mesh_free(p->S);
    mesh_free(p->T);
    bmap_free(p->P0);
    free(p->rows);
}

static void spec_of(const pair *p, int stages, int with_map, mc_job_spec *s)
{
    mc_job_spec_init(s);
    s->source = p->sb;
    s->source_len = p->sl;
    s->target = p->tb;
    s->target_len = p->tl;
    if (with_map) {
        s->p = p->rows;
        s->np = (uint32_t)p->S->nv;
    }
    s->stages = stages;
    s->ddm_k = 30;
    s->iterations = 3;
    s->beta_ramp = 3;
    s->inner_iterations = 10;
    s->label = "refine";
}

TEST_T(submitted_ddm_job_streams_the_ddm_stage_and_returns_the_in_process_map, 120)
{
    testdaemon_need_worker();
    pair p;
    pair_open(&p);
    testdaemon d;
    testdaemon_start(&d, "refine", NULL);
    mc_client *c = testdaemon_client(&d, NULL);

    /* ddm alone */
    mc_job_spec s;
    spec_of(&p, MC_STAGES_DDM, 1, &s);
    uint64_t id = 0;
    if (mc_submit(c, &s, &id))
        FAILF("SUBMIT: %s", mc_errmsg(c));
    watch_log w = {0};
    int state = -1;
    char reason[1100];
    if (mc_watch(c, id, 0, on_progress, &w, &state, reason, sizeof reason))
        FAILF("WATCH: %s", mc_errmsg(c));
    if (state != MC_COMPLETED)
        FAILF("job ended %s: %s", mc_state_name(state), reason);
    CHECK_INT(w.n, 2);                          /* its start, then P (no Q uploaded) */
    CHECK_INT(w.stage[0], MC_STAGE_DDM);
    CHECK_INT(w.stage[1], MC_STAGE_DDM);
    CHECK_INT(w.outer[1], 1);
    CHECK_INT(w.total[1], 1);
    CHECK(w.energy[1] > 0);
    CHECK(w.beta[0] == MC_DDM_PLAIN && w.beta[1] == MC_DDM_PLAIN);   /* auto, no q: plain */
    CHECK(isnan(w.gamma[0]));                                        /* and no choice made */
    mc_job_result r;
    CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q | MC_WANT_DEFORMED, &r), 0);
    CHECK_INT(r.np, 162);
    CHECK_INT(r.nq, 0);
    CHECK(r.deformed_len > 0);                  /* the map's image P X~ */
    corr_input in = {p.S, p.T, "source", "target", NULL, p.P0, NULL, NULL, CORR_CHAIN_DDM, 30, CORR_DDM_PLAIN};
    ectm_params ep;
    ectm_params_init(&ep);
    ectm_result want = {0};
    char err[1024];
    if (corr_run(&in, &ep, NULL, NULL, &want, err, sizeof err))
        FAILF("in process: %s", err);
    for (int i = 0; i < want.P->n; i++) {
        if (r.p[i].face != (uint32_t)want.P->face[i])
            FAILF("row %d: face %u, in process %d", i, r.p[i].face, want.P->face[i]);
        for (int k = 0; k < 3; k++)
            CHECK_NEAR(r.p[i].w[k], want.P->w[3 * i + k], 1e-12);
    }
    ectm_result_close(&want);
    mc_result_free(&r);

    /* ddm,ectm with the reverse map too: ddm's report (both together:
     * the two maps agree), then ECTM's 3 iterations */
    spec_of(&p, MC_STAGES_DDM_ECTM, 1, &s);
    s.q = p.rows;                  /* the same connectivity: vertex i -> vertex i back */
    s.nq = (uint32_t)p.T->nv;
    if (mc_submit(c, &s, &id))
        FAILF("SUBMIT: %s", mc_errmsg(c));
    memset(&w, 0, sizeof w);
    if (mc_watch(c, id, 0, on_progress, &w, &state, reason, sizeof reason))
        FAILF("WATCH: %s", mc_errmsg(c));
    if (state != MC_COMPLETED)
        FAILF("job ended %s: %s", mc_state_name(state), reason);
    CHECK_INT(w.n, 5);
    CHECK_INT(w.stage[1], MC_STAGE_DDM);
    CHECK_INT(w.outer[1], 2);                   /* both directions in one report */
    CHECK(w.beta[0] == MC_DDM_BIJECTIVE && w.beta[1] == MC_DDM_BIJECTIVE);
    CHECK(w.gamma[0] >= 0 && w.gamma[0] < 1e-9);   /* the identity's round trip */
    for (int i = 2; i < 5; i++) {
        CHECK_INT(w.stage[i], MC_STAGE_ECTM);
        CHECK_INT(w.outer[i], i - 1);
    }
    CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q, &r), 0);
    CHECK_INT(r.np, 162);
    CHECK_INT(r.nq, 162);
    mc_result_free(&r);

    /* ddm without a map: refused before SUBMIT_OK, naming the parameter */
    static const uint32_t lm[] = {0, 0, 1, 1, 2, 2, 3, 3};
    spec_of(&p, MC_STAGES_DDM_ECTM, 0, &s);
    s.landmarks = lm;
    s.nlandmarks = 4;
    id = 0;
    int rc = mc_submit(c, &s, &id);
    CHECK_INT(rc, PROTO_EBAD_PARAMS);      /* the protocol's number: the stages do not fit the inputs */
    CHECK_STR_HAS(mc_errmsg(c), "params.stages: the DDM stage denoises a given map");
    CHECK_INT(id, 0);
    /* a basis larger than the decoded meshes allow (162 vertices: at most
     * 160): refused before SUBMIT_OK, naming the parameter and the limit */
    spec_of(&p, MC_STAGES_DDM, 1, &s);
    s.ddm_k = 161;
    id = 0;
    CHECK_INT(mc_submit(c, &s, &id), PROTO_EBAD_PARAMS);
    CHECK_STR_HAS(mc_errmsg(c), "params.ddm_k = 161: DDM's basis holds at most vertices - 2 = 160");
    CHECK_INT(id, 0);
    /* and ZoomOut's, from landmarks with the functional-map start */
    spec_of(&p, MC_STAGES_ALL, 0, &s);
    s.landmarks = lm;
    s.nlandmarks = 4;
    s.start = MC_START_FMAP;
    s.zoomout = 200;
    CHECK_INT(mc_submit(c, &s, &id), PROTO_EBAD_PARAMS);
    CHECK_STR_HAS(mc_errmsg(c), "params.zoomout = 200: a basis holds at most vertices - 2 = 160");
    CHECK_INT(id, 0);
    s.start = MC_START_AUTO;                   /* its second run starts from the functional map */
    CHECK_INT(mc_submit(c, &s, &id), PROTO_EBAD_PARAMS);
    CHECK_STR_HAS(mc_errmsg(c), "params.zoomout = 200");
    CHECK_INT(id, 0);
    /* the stages value is one of the list: 8 is refused by the validator */
    spec_of(&p, 8, 1, &s);
    CHECK(mc_submit(c, &s, &id) != 0);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
    pair_close(&p);
}

static void check_rows(const proto_map *m, const bmap *want, const char *what)
{
    CHECK_INT(m->n, want->n);
    for (int i = 0; i < want->n && i < (int)m->n; i++) {
        if (m->rows[i].face != (uint32_t)want->face[i])
            FAILF("%s row %d: face %u, in process %d", what, i, m->rows[i].face, want->face[i]);
        for (int k = 0; k < 3; k++)
            CHECK_NEAR(m->rows[i].w[k], want->w[3 * i + k], 1e-9);
    }
}

TEST_T(a_landmark_jobs_rhm_maps_are_served_when_asked, 120)
{
    testdaemon_need_worker();
    pair p;
    pair_open(&p);
    testdaemon d;
    testdaemon_start(&d, "stagerhm", NULL);
    mc_client *c = testdaemon_client(&d, NULL);
    static const uint32_t lm[12] = {0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5};
    mc_job_spec s;
    spec_of(&p, MC_STAGES_ALL, 0, &s);
    s.landmarks = lm;
    s.nlandmarks = 6;
    s.rhm_iterations = 4;
    uint64_t id = 0;
    if (mc_submit(c, &s, &id))
        FAILF("SUBMIT: %s", mc_errmsg(c));
    int state = -1;
    char reason[1100];
    if (mc_watch(c, id, 0, NULL, NULL, &state, reason, sizeof reason))
        FAILF("WATCH: %s", mc_errmsg(c));
    if (state != MC_COMPLETED)
        FAILF("job ended %s: %s", mc_state_name(state), reason);

    int fd = testraw_session(d.unix_addr, NULL);
    proto_msg q = { .type = PROTO_MSG_RESULT, .request_id = 7 };
    q.u.result = (proto_result){ id, PROTO_WANT_P | PROTO_WANT_STAGE_RHM };
    testraw_send_msg(fd, &q);
    proto_msg m;
    uint8_t *buf = NULL;
    CHECK_INT(testraw_read_msg(fd, &m, &buf, 30), 0);
    CHECK_INT(m.type, PROTO_MSG_RESULT_OK);
    const proto_result_ok *ok = &m.u.result_ok;

    /* the same job in process: RHM's maps beside ECTM's */
    lmk_set L = {6, (int[]){0, 1, 2, 3, 4, 5}, (int[]){0, 1, 2, 3, 4, 5}};
    rhm_params rp;
    rhm_params_init(&rp);
    rp.iterations = 4;
    ectm_params ep;
    ectm_params_init(&ep);
    ep.iterations = 3;
    ep.beta_ramp = 3;
    ep.inner_iterations = 10;
    corr_input in = {p.S, p.T, "source", "target", &L, NULL, NULL, &rp, CORR_CHAIN_ALL, 30,
                     CORR_DDM_PLAIN};
    ectm_result want = {0};
    char err[1024];
    if (corr_run(&in, &ep, NULL, NULL, &want, err, sizeof err))
        FAILF("in process: %s", err);
    check_rows(&ok->p, want.P, "P");
    check_rows(&ok->rhm_p, want.rhm_P, "RHM's P");
    check_rows(&ok->rhm_q, want.rhm_Q, "RHM's Q");
    CHECK_INT(ok->q.n, 0);                      /* not asked */
    proto_msg_free(&m);
    free(buf);

    /* not asked: RESULT_OK as before, no RHM maps */
    q.request_id = 8;
    q.u.result.what = PROTO_WANT_P | PROTO_WANT_Q;
    testraw_send_msg(fd, &q);
    CHECK_INT(testraw_read_msg(fd, &m, &buf, 30), 0);
    CHECK_INT(m.type, PROTO_MSG_RESULT_OK);
    CHECK(m.u.result_ok.rhm_p.n == 0 && m.u.result_ok.rhm_q.n == 0 && m.u.result_ok.q.n > 0);
    proto_msg_free(&m);
    free(buf);
    close(fd);

    /* libmeshcorr's mc_result_stage, and meshcorr result --out-stage */
    mc_stage_maps st;
    CHECK_INT(mc_result_stage(c, id, "rhm", &st), 0);
    CHECK_INT(st.np, (uint32_t)want.rhm_P->n);
    CHECK_INT(st.nq, (uint32_t)want.rhm_Q->n);
    for (uint32_t i = 0; i < st.np; i++) {
        CHECK_INT(st.p[i].face, (uint32_t)want.rhm_P->face[i]);
        CHECK_NEAR(st.p[i].w[0], want.rhm_P->w[3 * i], 1e-9);
    }
    mc_stage_maps_free(&st);
    CHECK_INT(mc_result_stage(c, id, "ectm", &st), MC_EARG);
    char out[8192], R[700], RQ[700];
    snprintf(R, sizeof R, "%s/r.map", harness_tmpdir());
    snprintf(RQ, sizeof RQ, "%s/rq.map", harness_tmpdir());
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr result %llu --out-stage rhm=%s "
                       "--out-stage rhm-reverse=%s --server %s 2>&1", (unsigned long long)id, R, RQ,
                       d.unix_addr), 0);
    CHECK_STR_HAS(out, "rhm_flipped_fraction ");   /* RHM's quality beside the final map's */
    CHECK_STR_HAS(out, "\nflipped_fraction ");
    bmap *fr = NULL, *fq = NULL;
    if (bmap_read(R, p.S, p.T, &fr, err, sizeof err) || bmap_read(RQ, p.T, p.S, &fq, err, sizeof err))
        FAILF("%s", err);
    CHECK(!memcmp(fr->face, want.rhm_P->face, sizeof(int) * (size_t)fr->n));
    CHECK(!memcmp(fq->face, want.rhm_Q->face, sizeof(int) * (size_t)fq->n));
    bmap_free(fr);
    bmap_free(fq);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr result %llu --out-stage ectm=%s --server %s 2>&1",
                       (unsigned long long)id, R, d.unix_addr), 2);
    CHECK_STR_HAS(out, "--out-stage: 'ectm' is not a stage's map");
    ectm_result_close(&want);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
    pair_close(&p);
}
