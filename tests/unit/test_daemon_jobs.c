/* test_daemon_jobs.c — a job's life through the real meshcorrd, the real
 * meshcorr-worker and libmeshcorr: submit, watch, result identical to the
 * in-process pipeline, cancel (pending and running), worker crash, daemon
 * SIGKILL and graceful shutdown (the job runs again and completes). */
#include "support/harness.h"
#include "metric/metric.h"
#include "support/testdaemon.h"
#include "corr/corr.h"
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "meshcorr.h"

#include <signal.h>
#include <sqlite3.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

typedef struct watch_log {
    int n;
    int stage[64];
    uint32_t outer[64];
    double energy[64], fraction[64];
} watch_log;

static int on_progress(void *ctx, const mc_progress *p)
{
    watch_log *w = ctx;
    if (w->n < 64) {
        w->stage[w->n] = p->stage;
        w->outer[w->n] = p->outer;
        w->energy[w->n] = p->energy[0] + p->energy[1];
        w->fraction[w->n] = p->fraction;
        w->n++;
    }
    return 0;
}

TEST_T(submitted_job_streams_energies_and_completes, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "quick", NULL);
    mc_client *c = testdaemon_client(&d, NULL);
    uint64_t id = testdaemon_submit_ok(c, 3, 0, 0);
    watch_log w = {0};
    int state = -1;
    char reason[1100];
    int rc = mc_watch(c, id, 0, on_progress, &w, &state, reason, sizeof reason);
    if (rc)
        FAILF("WATCH: %s (%s)", mc_strerror(rc), mc_errmsg(c));
    if (state != MC_COMPLETED)
        FAILF("job ended %s: %s", mc_state_name(state), reason);
    /* stages in order (start, rhm, repair, ectm, repair), iterations rising
     * in each; the first record is the start map's, with its energies; the
     * whole job's fraction never falls and is 1 at the end */
    int last = 0, ectm = 0, rhm = 0, last_ectm = 0;
    CHECK_INT(w.stage[0], MC_STAGE_START);
    CHECK(isfinite(w.energy[0]) && w.energy[0] > 0);
    for (int i = 0; i < w.n; i++) {
        if (i > 0 && w.stage[i] != w.stage[i - 1])
            last = 0;
        CHECK(w.outer[i] >= (uint32_t)last);
        CHECK(i == 0 || w.fraction[i] >= w.fraction[i - 1]);
        CHECK(w.stage[i] != MC_STAGE_INIT);
        last = (int)w.outer[i];
        rhm += w.stage[i] == MC_STAGE_RHM;
        if (w.stage[i] == MC_STAGE_ECTM) {
            CHECK(isfinite(w.energy[i]) && w.energy[i] > 0);
            ectm++;
            last_ectm = (int)w.outer[i];
        }
    }
    CHECK_INT(rhm, 3);
    CHECK_INT(ectm, 3);
    CHECK_INT(last_ectm, 3);
    CHECK_INT(w.stage[w.n - 1], MC_STAGE_REPAIR);   /* the repair of ECTM's maps ends the job */
    CHECK(w.fraction[w.n - 1] == 1);
    /* a second watch from iteration 2 replays only the tail of each stage
     * (RHM 2, 3 and ECTM 2, 3), then END */
    watch_log tail = {0};
    CHECK_INT(mc_watch(c, id, 2, on_progress, &tail, &state, reason, sizeof reason), 0);
    CHECK_INT(state, MC_COMPLETED);
    int tail_ectm = 0;
    for (int i = 0; i < tail.n; i++) {
        CHECK(tail.outer[i] >= 2);
        tail_ectm += tail.stage[i] == MC_STAGE_ECTM;
    }
    CHECK_INT(tail_ectm, 2);
    mc_job_result r;
    CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q | MC_WANT_METRICS, &r), 0);
    CHECK_INT(r.np, 162);
    CHECK_INT(r.nq, 162);
    CHECK(r.nmetrics > 0);
    /* the quality summary of both maps travels with the result, and its
     * verdict is the one rule (metric_verdict) applied to the worse map */
    double q[6] = {NAN, NAN, NAN, NAN, NAN, NAN};
    static const char *const keys[6] = { "flipped_fraction", "collapsed_fraction",
                                         "reverse_flipped_fraction", "reverse_collapsed_fraction",
                                         "quality_verdict", "median_conformal" };
    for (uint32_t i = 0; i < r.nmetrics; i++)
        for (int k = 0; k < 6; k++)
            if (!strcmp(r.metric_keys[i], keys[k]))
                q[k] = r.metric_values[i];
    for (int k = 0; k < 6; k++)
        if (!isfinite(q[k]))
            FAILF("RESULT_OK metric %s missing or not finite", keys[k]);
    printf("  flipped %.2f %% / %.2f %%, collapsed %.2f %% / %.2f %%, verdict %g\n", 100 * q[0],
           100 * q[2], 100 * q[1], 100 * q[3], q[4]);
    int vp = metric_verdict(q[0], q[1]), vq = metric_verdict(q[2], q[3]);
    CHECK_INT(q[4], vp > vq ? vp : vq);
    /* the job's row says the same from the moment it reads COMPLETED:
     * STATUS and LIST carry the verdict and the source map's fractions */
    mc_job_status st;
    CHECK_INT(mc_status(c, id, &st), 0);
    CHECK_INT(st.quality.verdict, (int)q[4]);
    CHECK(st.quality.flipped == q[0] && st.quality.collapsed == q[1]);
    mc_job_info *jobs;
    uint32_t nj;
    CHECK_INT(mc_list(c, NULL, 0, &jobs, &nj), 0);
    CHECK_INT(nj, 1);
    CHECK_INT(jobs[0].quality.verdict, (int)q[4]);
    CHECK(jobs[0].quality.flipped == q[0] && jobs[0].quality.collapsed == q[1]);
    free(jobs);
    /* a job that has not completed has no quality yet */
    uint64_t pending = testdaemon_submit_ok(c, 100000, 0, 0);
    CHECK_INT(mc_status(c, pending, &st), 0);
    CHECK_INT(st.quality.verdict, MC_QUALITY_UNKNOWN);
    CHECK(isnan(st.quality.flipped));
    CHECK_INT(mc_cancel(c, pending), 0);
    mc_result_free(&r);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* The map the daemon returns is the in-process pipeline's map on the same
 * Draco-decoded meshes, initial maps and parameters (the demo pair 381 -> 390,
 * 3 outer iterations, one thread on both sides). */
static void check_same_map(const mc_map_row *got, uint32_t n, const bmap *want)
{
    CHECK_INT(n, want->n);
    for (int i = 0; i < want->n; i++) {
        if (got[i].face != (uint32_t)want->face[i])
            FAILF("row %d: face %u, in-process %d", i, got[i].face, want->face[i]);
        for (int k = 0; k < 3; k++)
            CHECK_NEAR(got[i].w[k], want->w[3 * i + k], 1e-12);
    }
}

TEST_T(result_is_the_in_process_map_on_the_demo_pair, 120)
{
    testdaemon_need_worker();
    testdaemon_demo dm;
    testdaemon_demo_open(&dm, 3);
    char err[1024];
    testdaemon d;
    testdaemon_start(&d, "demo", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id;
    int rc = mc_submit(c, &dm.spec, &id);
    if (rc)
        FAILF("SUBMIT: %s", mc_errmsg(c));

    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 3;
    p.threads = 1;
    ectm_result want = {0};
    corr_input in = {dm.S, dm.T, "381", "390", NULL, dm.P0, dm.Q0, NULL, CORR_CHAIN_ALL, 0, CORR_DDM_PLAIN };
    if (corr_run(&in, &p, NULL, NULL, &want, err, sizeof err))
        FAILF("corr_run: %s", err);

    int state = -1;
    char reason[1100];
    CHECK_INT(mc_watch(c, id, 0, NULL, NULL, &state, reason, sizeof reason), 0);
    if (state != MC_COMPLETED)
        FAILF("job ended %s: %s", mc_state_name(state), reason);
    mc_job_result r;
    CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q, &r), 0);
    check_same_map(r.p, r.np, want.P);
    check_same_map(r.q, r.nq, want.Q);
    CHECK(r.deformed == NULL);   /* not asked */
    mc_result_free(&r);
    ectm_result_close(&want);
    testdaemon_demo_close(&dm);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* state of job id in the daemon's database, read directly (daemon stopped) */
static int db_state(const testdaemon *d, uint64_t id, char *out, size_t n)
{
    char path[700];
    snprintf(path, sizeof path, "%s/jobs.db", d->state);
    sqlite3 *db;
    sqlite3_stmt *st;
    out[0] = '\0';
    if (sqlite3_open(path, &db) != SQLITE_OK)
        return -1;
    int rc = -1;
    if (sqlite3_prepare_v2(db, "SELECT state FROM jobs WHERE id = ?", -1, &st, NULL) == SQLITE_OK) {
        sqlite3_bind_int64(st, 1, (sqlite3_int64)id);
        if (sqlite3_step(st) == SQLITE_ROW) {
            snprintf(out, n, "%s", (const char *)sqlite3_column_text(st, 0));
            rc = 0;
        }
        sqlite3_finalize(st);
    }
    sqlite3_close(db);
    return rc;
}

TEST_T(acknowledged_job_survives_daemon_sigkill_and_completes_after_restart, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "sigkill", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id = testdaemon_submit_ok(c, 200, 0, 0);
    testdaemon_wait_state(c, id, MC_RUNNING, 10);
    mc_close(c);
    testdaemon_kill(&d);
    char state[32];
    CHECK_INT(db_state(&d, id, state, sizeof state), 0);
    CHECK(strcmp(state, "RUNNING") == 0 || strcmp(state, "COMPLETED") == 0);
    testdaemon_start(&d, "sigkill", NULL);
    c = testdaemon_client(&d, TESTDAEMON_ALICE);
    CHECK_INT(testdaemon_wait_state(c, id, -1, 40), MC_COMPLETED);
    mc_job_result r;
    CHECK_INT(mc_result(c, id, MC_WANT_P, &r), 0);
    CHECK_INT(r.np, 162);
    mc_result_free(&r);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(graceful_shutdown_requeues_the_running_job_and_next_start_completes_it, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "drain", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id = testdaemon_submit_ok(c, 1000, 0, 0);
    testdaemon_wait_state(c, id, MC_RUNNING, 10);
    mc_job_status s;
    do {                                   /* let it get into the optimisation */
        CHECK_INT(mc_status(c, id, &s), 0);
    } while (!s.has_progress || s.progress.outer < 2);
    testdaemon_stop(&d, SIGTERM);
    mc_close(c);
    char state[32];
    CHECK_INT(db_state(&d, id, state, sizeof state), 0);
    CHECK_STR_HAS(state, "PENDING");
    testdaemon_start(&d, "drain", NULL);
    c = testdaemon_client(&d, TESTDAEMON_ALICE);
    int end = -1;
    char reason[1100];
    CHECK_INT(mc_watch(c, id, 0, NULL, NULL, &end, reason, sizeof reason), 0);
    if (end != MC_COMPLETED)
        FAILF("job ended %s: %s", mc_state_name(end), reason);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* A poison job: the first crash re-queues it, the second fails it. */
TEST_T(job_whose_worker_is_killed_twice_fails_as_crashed_twice_and_daemon_keeps_serving, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "crash", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id = testdaemon_submit_ok(c, 100000, 1, 0);
    uint64_t next = testdaemon_submit_ok(c, 3, 0, 0);
    testdaemon_wait_state(c, id, MC_RUNNING, 10);
    pid_t w = testdaemon_worker_pid(&d, id);
    CHECK(w > 0);
    CHECK_INT(kill(w, SIGKILL), 0);
    pid_t w2 = -1;                      /* the job runs again in a new worker */
    for (int i = 0; i < 50 && (w2 < 0 || w2 == w); i++)
        w2 = testdaemon_worker_pid(&d, id);
    CHECK(w2 > 0 && w2 != w);
    CHECK_INT(kill(w2, SIGKILL), 0);
    CHECK_INT(testdaemon_wait_state(c, id, -1, 20), MC_FAILED);
    mc_job_status s;
    CHECK_INT(mc_status(c, id, &s), 0);
    CHECK_STR_HAS(s.reason, "worker crashed twice");
    CHECK_STR_HAS(s.reason, "signal 9");
    CHECK_INT(testdaemon_wait_state(c, next, -1, 30), MC_COMPLETED);
    CHECK_INT(mc_ping(c), 0);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(cancel_ends_running_and_pending_jobs_cancelled, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "cancel", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t run = testdaemon_submit_ok(c, 100000, 1, 0);
    uint64_t wait = testdaemon_submit_ok(c, 100000, 1, 0);
    testdaemon_wait_state(c, run, MC_RUNNING, 10);
    CHECK_INT(mc_cancel(c, wait), 0);          /* pending: at once */
    mc_job_status s;
    CHECK_INT(mc_status(c, wait, &s), 0);
    CHECK_INT(s.state, MC_CANCELLED);
    CHECK_INT(s.start_ms, 0);
    CHECK_INT(mc_cancel(c, run), 0);           /* running: SIGTERM to its worker */
    int end = -1;
    char reason[1100];
    CHECK_INT(mc_watch(c, run, 1u << 30, NULL, NULL, &end, reason, sizeof reason), 0);
    CHECK_INT(end, MC_CANCELLED);
    CHECK_STR_HAS(reason, "cancel");
    CHECK_INT(mc_cancel(c, run), MC_EBAD_STATE);   /* nothing left to cancel */
    CHECK_STR_HAS(mc_errmsg(c), "CANCELLED");
    CHECK_INT(mc_delete(c, run), 0);
    CHECK_INT(mc_status(c, run, &s), MC_ENOT_FOUND);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
