/* test_daemon_progress.c — a job's progress through the real meshcorrd, the
 * real worker, libmeshcorr and the CLI: while a job waits, WATCH, STATUS,
 * LIST, `meshcorr watch`, `status` and `list` say its place in the queue
 * and follow it as the queue moves; once it runs, the first record is a
 * real one (the start map's) and every record carries the whole job's
 * fraction, never falling, to 1 at the end; LIST and STATUS keep the last
 * record's; and the queue's records are never stored (a replay has none). */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testrun.h"
#include "meshcorr.h"

#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>

static char out[1 << 16];

typedef struct watcher {
    const testdaemon *d;
    uint64_t id;
    pthread_mutex_t mu;
    int n, end_state, rc;
    mc_progress rec[256];
} watcher;

static int on_record(void *ctx, const mc_progress *p)
{
    watcher *w = ctx;
    pthread_mutex_lock(&w->mu);
    if (w->n < 256)
        w->rec[w->n++] = *p;
    pthread_mutex_unlock(&w->mu);
    return 0;
}

static void *watch_thread(void *arg)
{
    watcher *w = arg;
    char err[256], reason[1100];
    mc_client *c = NULL;
    if ((w->rc = mc_connect(w->d->unix_addr, NULL, &c, err, sizeof err)) == 0)
        w->rc = mc_watch(c, w->id, 0, on_record, w, &w->end_state, reason, sizeof reason);
    mc_close(c);
    return NULL;
}

/* Waits until the watcher holds more than n records, at most 60 s; the
 * last one. */
static mc_progress next_record(watcher *w, int n)
{
    for (int i = 0; i < 1200; i++) {
        pthread_mutex_lock(&w->mu);
        int have = w->n;
        mc_progress last = have ? w->rec[have - 1] : (mc_progress){0};
        pthread_mutex_unlock(&w->mu);
        if (have > n)
            return last;
        testdaemon_sleep_ms(50);
    }
    FAILF("no record after %d within 60 s", n);
    return (mc_progress){0};
}

static const mc_job_info *find(const mc_job_info *jobs, uint32_t n, uint64_t id)
{
    for (uint32_t i = 0; i < n; i++)
        if (jobs[i].job_id == id)
            return &jobs[i];
    FAILF("job %llu not listed", (unsigned long long)id);
    return NULL;
}

TEST_T(a_waiting_jobs_place_in_the_queue_is_watched_listed_and_followed, 180)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "queue", NULL);          /* one worker slot */
    mc_client *c = testdaemon_client(&d, NULL);
    uint64_t a = testdaemon_submit_ok(c, 100000, 1, 0);
    testdaemon_wait_state(c, a, MC_RUNNING, 30);
    uint64_t b = testdaemon_submit_ok(c, 3, 0, 0), j = testdaemon_submit_ok(c, 3, 0, 0);

    watcher w = {.d = &d, .id = j, .mu = PTHREAD_MUTEX_INITIALIZER};
    pthread_t t;
    CHECK_INT(pthread_create(&t, NULL, watch_thread, &w), 0);
    mc_progress q = next_record(&w, 0);
    CHECK_INT(q.stage, MC_STAGE_QUEUED);
    CHECK_INT(q.ahead, 1);                        /* b goes first */
    CHECK(q.fraction == 0 && isnan(q.eta_s));

    /* STATUS and LIST say the same place */
    mc_job_status st;
    CHECK_INT(mc_status(c, j, &st), 0);
    CHECK_INT(st.state, MC_PENDING);
    CHECK(st.has_progress);
    CHECK_INT(st.progress.stage, MC_STAGE_QUEUED);
    CHECK_INT(st.progress.ahead, 1);
    mc_job_info *jobs;
    uint32_t n;
    CHECK_INT(mc_list(c, NULL, 0, &jobs, &n), 0);
    CHECK_INT(find(jobs, n, b)->ahead, 0);
    CHECK_INT(find(jobs, n, j)->ahead, 1);
    CHECK_INT(find(jobs, n, a)->ahead, 0);
    free(jobs);
    /* and the CLI */
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr status %llu --server %s", (unsigned long long)j,
                       d.unix_addr), 0);
    CHECK_STR_HAS(out, "progress  queued: 1 job ahead");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --server %s", d.unix_addr), 0);
    CHECK_STR_HAS(out, "PROGRESS");
    CHECK_STR_HAS(out, "1 ahead");
    CHECK_STR_HAS(out, "next");                   /* b's row, as watch says it */
    CHECK_INT(testrunf(out, sizeof out, "timeout 2 build/meshcorr watch %llu --server %s", (unsigned long long)j,
                       d.unix_addr), 124);
    char line[64];
    snprintf(line, sizeof line, "job %llu queued: 1 job ahead\n", (unsigned long long)j);
    CHECK_STR_HAS(out, line);

    /* the queue moves: b leaves it, and the watcher hears it at once */
    CHECK_INT(mc_cancel(c, b), 0);
    q = next_record(&w, 1);
    CHECK_INT(q.stage, MC_STAGE_QUEUED);
    CHECK_INT(q.ahead, 0);

    /* a leaves the slot: j runs; its first record is its start map's */
    int before = w.n;
    CHECK_INT(mc_cancel(c, a), 0);
    CHECK_INT(pthread_join(t, NULL), 0);
    CHECK_INT(w.rc, 0);
    CHECK_INT(w.end_state, MC_COMPLETED);
    CHECK(w.n > before + 3);
    const mc_progress *first = &w.rec[before];
    CHECK_INT(first->stage, MC_STAGE_START);
    CHECK(first->energy[0] + first->energy[1] > 0);
    CHECK(first->fraction > 0);
    for (int i = before; i < w.n; i++) {
        CHECK(w.rec[i].stage != MC_STAGE_QUEUED && w.rec[i].stage != MC_STAGE_INIT);
        CHECK(i == before || w.rec[i].fraction >= w.rec[i - 1].fraction);
        CHECK(isfinite(w.rec[i].eta_s) && w.rec[i].eta_s >= 0);
    }
    CHECK(w.rec[w.n - 1].fraction == 1);

    /* the finished job: STATUS and LIST keep its last record's share; a
     * replay has no queue records (they are never stored) */
    CHECK_INT(mc_status(c, j, &st), 0);
    CHECK(st.has_progress && st.progress.fraction == 1);
    CHECK_INT(mc_list(c, NULL, 0, &jobs, &n), 0);
    CHECK(find(jobs, n, j)->fraction == 1);
    free(jobs);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr watch %llu --progress json --server %s",
                       (unsigned long long)j, d.unix_addr), 0);
    CHECK(strstr(out, "\"stage\":\"queued\"") == NULL);
    CHECK(strstr(out, "\"stage\":\"init\"") == NULL);
    CHECK_STR_HAS(out, "\"fraction\":1,");
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* The names of the fields are one set: `meshcorr watch --progress json`
 * prints the same keys for a job run by the server as `meshcorr match
 * --progress json` prints for the same job run in process. */
TEST_T(watch_and_match_print_one_set_of_field_names, 120)
{
    testdaemon_need_worker();
    mesh *S, *T;
    testdaemon_pair(0, &S, &T);
    char src[600], tgt[600], lmk[600], pm[700], err[512];
    snprintf(src, sizeof src, "%s/s.off", harness_tmpdir());
    snprintf(tgt, sizeof tgt, "%s/t.off", harness_tmpdir());
    snprintf(lmk, sizeof lmk, "%s/l.lmk", harness_tmpdir());
    snprintf(pm, sizeof pm, "%s/p.map", harness_tmpdir());
    CHECK_INT(mesh_write(src, S, err, sizeof err), 0);
    CHECK_INT(mesh_write(tgt, T, err, sizeof err), 0);
    FILE *fp = fopen(lmk, "w");
    CHECK(fp);
    fputs("0 0\n1 1\n2 2\n3 3\n4 4\n5 5\n", fp);
    fclose(fp);
    mesh_free(S);
    mesh_free(T);
    testdaemon d;
    testdaemon_start(&d, "names", NULL);
    static const char job[] = "--iterations 3 --beta-ramp 3 --inner-iterations 10 --rhm-iterations 3";
    static char local[1 << 16];
    CHECK_INT(testrunf(local, sizeof local, "build/meshcorr match %s %s --landmarks %s --out %s %s "
                       "--progress json 2>&1 >/dev/null", src, tgt, lmk, pm, job), 0);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr submit %s %s --landmarks %s %s --server %s --watch "
                       "--progress json", src, tgt, lmk, job, d.unix_addr), 0);
    /* the same stages, each with the same keys in the same order */
    static const char *const stages[] = {"start", "rhm", "repair", "ectm"};
    for (int k = 0; k < 4; k++) {
        char key[64];
        snprintf(key, sizeof key, "\"stage\":\"%s\"", stages[k]);
        const char *l = strstr(local, key), *r = strstr(out, key);
        if (!l || !r)
            FAILF("stage %s missing: local %s, watch %s", stages[k], l ? "yes" : "no", r ? "yes" : "no");
        /* from the stage on, the key names match one by one */
        for (const char *x = l, *y = r; *x && *x != '\n' && *y && *y != '\n';) {
            const char *kx = strstr(x, "\":"), *ky = strstr(y, "\":");
            if (!kx || !ky)
                break;
            const char *sx = kx, *sy = ky;
            while (sx > x && sx[-1] != '"')
                sx--;
            while (sy > y && sy[-1] != '"')
                sy--;
            if (kx - sx != ky - sy || strncmp(sx, sy, (size_t)(kx - sx)) != 0)
                FAILF("stage %s: key %.*s locally, %.*s from the server", stages[k], (int)(kx - sx), sx,
                      (int)(ky - sy), sy);
            x = kx + 2;
            y = ky + 2;
        }
    }
    CHECK_STR_HAS(local, "{\"job\":null,\"stage\":\"start\",\"outer\":0,\"total\":3,\"fraction\":");
    testdaemon_stop(&d, SIGTERM);
}
