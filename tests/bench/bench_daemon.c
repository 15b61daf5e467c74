/* bench_daemon.c — what the daemon costs a client: SUBMIT of a 10K-vertex
 * pair (Draco encoding and the round trip to SUBMIT_OK, timed apart), PING
 * round trips while large SUBMITs are stored, PROGRESS fan-out to 20 watchers of one job, and one small job through the
 * daemon against the same job run in process (corr_run), for the demo pair
 * and for a 162-vertex pair (the per-job overhead). Prints figures,
 * never fails on time. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "corr/corr.h"
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "meshcorr.h"

#include <pthread.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#define NSUBMIT 5

/* The worker and the check are /bin/true, so the jobs end at once and take
 * no CPU from the submit path being timed (bench_submit_check times the
 * check). */
TEST_T(submit_round_trip_of_a_10k_vertex_pair, 300)
{
    char s390[512], s381[512], err[1024];
    snprintf(s390, sizeof s390, "%s", harness_data_path("shrec07_bim/Meshes/390.off"));
    snprintf(s381, sizeof s381, "%s", harness_data_path("shrec07_bim/Meshes/381.off"));
    testdaemon d;
    const char *args[] = {"--worker", "/bin/true", "--validator", "/bin/true", NULL};
    testdaemon_start(&d, "bench-submit", args);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    double enc = 0, rt = 0, rt_min = 1e30;
    size_t bytes = 0;
    for (int k = 0; k < NSUBMIT; k++) {
        unsigned char *sb, *tb;
        size_t sl, tl;
        double t0 = now();
        if (mc_encode_mesh_file(s390, &sb, &sl, err, sizeof err) ||
            mc_encode_mesh_file(s381, &tb, &tl, err, sizeof err))
            FAILF("encode: %s", err);
        double t1 = now();
        mc_job_spec spec;
        mc_job_spec_init(&spec);
        spec.source = sb;
        spec.source_len = sl;
        spec.target = tb;
        spec.target_len = tl;
        static const uint32_t lm[] = {0, 0, 100, 100, 200, 200, 300, 300};
        spec.landmarks = lm;
        spec.nlandmarks = 4;
        spec.iterations = 3;
        spec.label = "bench submit";
        uint64_t id;
        if (mc_submit(c, &spec, &id))
            FAILF("SUBMIT: %s", mc_errmsg(c));
        double t2 = now();
        enc += t1 - t0;
        rt += t2 - t1;
        if (t2 - t1 < rt_min)
            rt_min = t2 - t1;
        bytes = sl + tl;
        free(sb);
        free(tb);
    }
    printf("SUBMIT 390 -> 381 (both Draco: %zu bytes): encode %.1f ms, "
           "round trip to SUBMIT_OK %.1f ms (min %.1f ms), mean of %d\n",
           bytes, 1e3 * enc / NSUBMIT, 1e3 * rt / NSUBMIT, 1e3 * rt_min, NSUBMIT);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* A client submitting large frames (random bytes as "Draco": the daemon
 * are not decoded: the check and the worker are /bin/true) while another pings:
 * how long the loop keeps a PING waiting while a SUBMIT is read and stored. */
#define BIG_SUBMIT_MB 32
#define NBIG 4

typedef struct big_pinger {
    const testdaemon *d;
    volatile int stop;
    int n, rc;
    double max_s, sum_s;
} big_pinger;

static void *big_ping_thread(void *arg)
{
    big_pinger *p = arg;
    mc_client *c = NULL;
    char err[256];
    if ((p->rc = mc_connect(p->d->unix_addr, NULL, &c, err, sizeof err)) != 0)
        return NULL;
    mc_set_timeout(c, 60000);
    while (!p->stop && !p->rc) {
        double t0 = now();
        p->rc = mc_ping(c);
        double dt = now() - t0;
        p->max_s = dt > p->max_s ? dt : p->max_s;
        p->sum_s += dt;
        p->n++;
    }
    mc_close(c);
    return NULL;
}

TEST_T(ping_round_trip_while_large_submits_are_stored, 300)
{
    testdaemon d;
    const char *args[] = {"--worker", "/bin/true", "--validator", "/bin/true", NULL};
    testdaemon_start(&d, "bench-bigsubmit", args);
    size_t half = (size_t)BIG_SUBMIT_MB << 19;
    unsigned char *blob = malloc(half);
    CHECK(blob != NULL);
    for (size_t i = 0; i < half; i++)
        blob[i] = (unsigned char)(i * 2654435761u >> 13);
    mc_job_spec spec;
    mc_job_spec_init(&spec);
    spec.source = spec.target = blob;
    spec.source_len = spec.target_len = half;
    static const uint32_t lm[] = {0, 0, 1, 1, 2, 2, 3, 3};
    spec.landmarks = lm;
    spec.nlandmarks = 4;
    spec.iterations = 3;
    spec.label = "bench large submit";
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    mc_set_timeout(c, 120000);
    big_pinger p = {&d, 0, 0, 0, 0, 0};
    pthread_t th;
    CHECK_INT(pthread_create(&th, NULL, big_ping_thread, &p), 0);
    double rt = 0;
    for (int k = 0; k < NBIG; k++) {
        uint64_t id;
        double t0 = now();
        if (mc_submit(c, &spec, &id))
            FAILF("SUBMIT: %s", mc_errmsg(c));
        rt += now() - t0;
    }
    p.stop = 1;
    pthread_join(th, NULL);
    CHECK_INT(p.rc, 0);
    printf("%d SUBMITs of %d MB: round trip to SUBMIT_OK %.0f ms (mean); PING meanwhile: %d answered,"
           " mean %.2f ms, slowest %.1f ms\n", NBIG, BIG_SUBMIT_MB, 1e3 * rt / NBIG, p.n,
           p.n ? 1e3 * p.sum_s / p.n : 0, 1e3 * p.max_s);
    free(blob);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

#define NWATCHERS 20

typedef struct watcher {
    const testdaemon *d;
    uint64_t id;
    int frames, end_state, rc;
    double t_end;
} watcher;

static int count_frame(void *ctx, const mc_progress *p)
{
    (void)p;
    ((watcher *)ctx)->frames++;
    return 0;
}

static void *watch_thread(void *arg)
{
    watcher *w = arg;
    mc_client *c = NULL;
    char err[512];
    if ((w->rc = mc_connect(w->d->unix_addr, NULL, &c, err, sizeof err)) != 0)
        return NULL;
    mc_set_timeout(c, 120000);
    w->rc = mc_watch(c, w->id, 0, count_frame, w, &w->end_state, NULL, 0);
    w->t_end = now();
    mc_close(c);
    return NULL;
}

TEST_T(progress_fan_out_to_20_watchers_of_one_job, 300)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "bench-fanout", NULL);
    mc_client *c = testdaemon_client(&d, NULL);
    int rc;
    double t0 = now();
    uint64_t id = testdaemon_submit(c, 200, 0, 0, &rc);
    if (rc)
        FAILF("SUBMIT: %s", mc_errmsg(c));
    static watcher w[NWATCHERS];
    pthread_t th[NWATCHERS];
    for (int i = 0; i < NWATCHERS; i++) {
        w[i] = (watcher){&d, id, 0, -1, 0, 0};
        CHECK_INT(pthread_create(&th[i], NULL, watch_thread, &w[i]), 0);
    }
    long total = 0;
    double first = 1e30, last = 0;
    for (int i = 0; i < NWATCHERS; i++) {
        pthread_join(th[i], NULL);
        if (w[i].rc || w[i].end_state != MC_COMPLETED)
            FAILF("watcher %d: rc %d, end %s", i, w[i].rc, mc_state_name(w[i].end_state));
        total += w[i].frames;
        first = w[i].t_end < first ? w[i].t_end : first;
        last = w[i].t_end > last ? w[i].t_end : last;
    }
    double secs = last - t0;
    printf("fan-out: %d watchers of one 200-iteration job: %ld PROGRESS frames in %.2f s "
           "(%.0f frames/s delivered, %d per watcher), END reached every watcher within %.1f ms\n",
           NWATCHERS, total, secs, (double)total / secs, w[0].frames, 1e3 * (last - first));
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* The demo pair 381 -> 390 from its initial maps, 3 outer iterations, one
 * thread on both sides: submit-to-END through the daemon against corr_run. */
TEST_T(daemon_overhead_against_the_in_process_run, 600)
{
    testdaemon_need_worker();
    testdaemon_demo dm;
    testdaemon_demo_open(&dm, 3);
    char err[1024];

    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 3;
    p.threads = 1;
    ectm_result want = {0};
    corr_input in = {dm.S, dm.T, "381", "390", NULL, dm.P0, dm.Q0, NULL, CORR_STAGES_ALL, 0, CORR_DDM_PLAIN };
    double t0 = now();
    if (corr_run(&in, &p, NULL, NULL, &want, err, sizeof err))
        FAILF("corr_run: %s", err);
    double t_local = now() - t0;
    ectm_result_close(&want);

    testdaemon d;
    testdaemon_start(&d, "bench-overhead", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    mc_set_timeout(c, 600000);
    dm.spec.label = "bench overhead";
    uint64_t id;
    t0 = now();
    if (mc_submit(c, &dm.spec, &id))
        FAILF("SUBMIT: %s", mc_errmsg(c));
    int state = -1;
    char reason[1100];
    CHECK_INT(mc_watch(c, id, 0, NULL, NULL, &state, reason, sizeof reason), 0);
    double t_daemon = now() - t0;
    if (state != MC_COMPLETED)
        FAILF("job ended %s: %s", mc_state_name(state), reason);
    mc_job_result r;
    t0 = now();
    CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q, &r), 0);
    double t_fetch = now() - t0;
    mc_result_free(&r);
    printf("381 -> 390, 3 iterations, 1 thread: in process %.2f s, through the daemon %.2f s "
           "(submit to END; ratio %.3f, overhead %.2f s); RESULT fetch of both maps %.1f ms\n",
           t_local, t_daemon, t_daemon / t_local, t_daemon - t_local, 1e3 * t_fetch);
    testdaemon_demo_close(&dm);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* A small job: the 162-vertex icosphere pair of testdaemon_submit
 * (6 landmarks, 3 RHM and 2 ECTM iterations), NSMALL times one after the
 * other through the daemon (submit to END, then RESULT), against the same
 * job's corr_run in process (one thread, as the worker picks for this
 * size). The overhead is the daemon's wall time less the in-process run:
 * spawning the worker, its decode, its threads, the result's write and
 * the round trips. The worker's own elapsed_s (from its start, decode
 * included) splits it in two, and the daemon's log gives the SUBMIT check's
 * share. */
#define NSMALL 10

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

TEST_T(small_job_overhead_through_the_daemon, 600)
{
    testdaemon_need_worker();
    char err[1024];
    mesh *S, *T;
    testdaemon_pair(0, &S, &T);                 /* testdaemon_submit's pair */
    long lm[6] = {0, 1, 2, 3, 4, 5};
    lmk_set *L = NULL;
    if (lmk_from_arrays(lm, lm, 6, 0, "S", "T", S, T, &L, err, sizeof err))
        FAILF("%s", err);
    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 2;
    p.inner_iterations = 10;
    p.beta_ramp = 2;
    p.stop_change = 0;
    p.threads = 1;
    rhm_params rp;
    rhm_params_init(&rp);
    rp.iterations = 3;
    rp.threads = 1;
    double local[NSMALL];
    for (int k = 0; k < NSMALL; k++) {
        ectm_result r = {0};
        corr_input in = { S, T, "S", "T", L, NULL, NULL, &rp, CORR_STAGES_ALL, 0, CORR_DDM_PLAIN };
        double t0 = now();
        if (corr_run(&in, &p, NULL, NULL, &r, err, sizeof err))
            FAILF("corr_run: %s", err);
        local[k] = now() - t0;
        ectm_result_close(&r);
    }

    testdaemon d;
    testdaemon_start(&d, "bench-small", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    double wall[NSMALL], worker[NSMALL], fetch[NSMALL];
    for (int k = 0; k < NSMALL; k++) {
        double t0 = now();
        uint64_t id = testdaemon_submit_ok(c, 2, 0, 0);
        int state = -1;
        char reason[1100];
        CHECK_INT(mc_watch(c, id, 0, NULL, NULL, &state, reason, sizeof reason), 0);
        if (state != MC_COMPLETED)
            FAILF("job ended %s: %s", mc_state_name(state), reason);
        mc_job_result r;
        double t1 = now();
        CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q | MC_WANT_METRICS, &r), 0);
        fetch[k] = now() - t1;
        wall[k] = now() - t0;
        worker[k] = NAN;
        for (uint32_t i = 0; i < r.nmetrics; i++)
            if (!strcmp(r.metric_keys[i], "elapsed_s"))
                worker[k] = r.metric_values[i];
        mc_result_free(&r);
    }
    qsort(local, NSMALL, sizeof(double), cmp_double);
    qsort(wall, NSMALL, sizeof(double), cmp_double);
    qsort(worker, NSMALL, sizeof(double), cmp_double);
    qsort(fetch, NSMALL, sizeof(double), cmp_double);
    int h = NSMALL / 2;
    double check_cpu, check = testdaemon_checked_ms(&d, &check_cpu);
    printf("162-vertex pair, 3 RHM + 2 ECTM iterations, %d jobs one after the other (medians): "
           "in process %.1f ms; through the daemon, submit to RESULT %.1f ms, of which the SUBMIT "
           "check %.1f ms (%.1f ms CPU), the worker's elapsed_s %.1f ms and the RESULT fetch %.1f ms; "
           "overhead %.1f ms (target <= 50 ms), ratio %.2f\n", NSMALL, 1e3 * local[h], 1e3 * wall[h],
           check, check_cpu, 1e3 * worker[h], 1e3 * fetch[h], 1e3 * (wall[h] - local[h]),
           wall[h] / local[h]);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
    lmk_free(L);
    mesh_free(S);
    mesh_free(T);
}
