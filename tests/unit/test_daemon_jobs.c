/* test_daemon_jobs.c — a job's life through the real meshcorrd, the real
 * meshcorr-worker and libmeshcorr: submit, watch, result identical to the
 * in-process pipeline, cancel (pending and running), worker crash, daemon
 * SIGKILL and graceful shutdown (the job runs again and completes). */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "corr/corr.h"
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "meshcorr.h"

#include <signal.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

typedef struct watch_log {
    int n;
    uint32_t outer[64];
    double energy[64];
} watch_log;

static int on_progress(void *ctx, const mc_progress *p)
{
    watch_log *w = ctx;
    if (w->n < 64) {
        w->outer[w->n] = p->outer;
        w->energy[w->n] = p->energy[0] + p->energy[1];
        w->n++;
    }
    return 0;
}

static uint64_t submit_ok(mc_client *c, int iterations, int long_job, int32_t priority)
{
    int rc;
    uint64_t id = testdaemon_submit(c, iterations, long_job, priority, &rc);
    if (rc)
        FAILF("SUBMIT: %s (%s)", mc_strerror(rc), mc_errmsg(c));
    CHECK(id > 0);
    return id;
}

TEST_T(submitted_job_streams_energies_and_completes, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "quick", NULL);
    mc_client *c = testdaemon_client(&d, NULL);
    uint64_t id = submit_ok(c, 3, 0, 0);
    watch_log w = {0};
    int state = -1;
    char reason[1100];
    int rc = mc_watch(c, id, 0, on_progress, &w, &state, reason, sizeof reason);
    if (rc)
        FAILF("WATCH: %s (%s)", mc_strerror(rc), mc_errmsg(c));
    if (state != MC_COMPLETED)
        FAILF("job ended %s: %s", mc_state_name(state), reason);
    int last = 0, ectm = 0;
    for (int i = 0; i < w.n; i++) {
        CHECK(w.outer[i] >= (uint32_t)last);
        last = (int)w.outer[i];
        if (w.outer[i] > 0) {
            CHECK(isfinite(w.energy[i]) && w.energy[i] > 0);
            ectm++;
        }
    }
    CHECK_INT(ectm, 3);
    CHECK_INT(last, 3);
    /* a second watch from iteration 2 replays only the tail, then END */
    watch_log tail = {0};
    CHECK_INT(mc_watch(c, id, 2, on_progress, &tail, &state, reason, sizeof reason), 0);
    CHECK_INT(state, MC_COMPLETED);
    CHECK_INT(tail.n, 2);
    CHECK_INT(tail.outer[0], 2);
    mc_job_result r;
    CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q | MC_WANT_METRICS, &r), 0);
    CHECK_INT(r.np, 162);
    CHECK_INT(r.nq, 162);
    CHECK(r.nmetrics > 0);
    mc_result_free(&r);
    mc_close(c);
    CHECK(WIFEXITED(testdaemon_stop(&d, SIGTERM)));
}
