/* test_daemon_faults.c — meshcorrd under crash faults, black-box with the
 * real daemon, worker and client: the daemon SIGKILLed right after it
 * spawned workers, round after round, never leaves two live workers of one
 * job (nor more than --workers); a job whose worker finished while the
 * daemon was down is COMPLETED from its result.frame, not run again. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "meshcorr.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

static uint64_t submit_ok(mc_client *c, int iterations, int long_job)
{
    int rc;
    uint64_t id = testdaemon_submit(c, iterations, long_job, 0, &rc);
    if (rc)
        FAILF("SUBMIT: %s (%s)", mc_strerror(rc), mc_errmsg(c));
    return id;
}

/* Orphans must not outlive a failed test (they would run for hours). */
static testdaemon *cleanup_daemon;
static void kill_leftovers(void)
{
    if (!cleanup_daemon)
        return;
    if (cleanup_daemon->pid > 0)          /* first the daemon: it would start more */
        kill(cleanup_daemon->pid, SIGKILL);
    for (int i = 0; i < 100 && testdaemon_kill_workers(cleanup_daemon) > 0; i++)
        sleep_ms(10);
}

/* Lines of the daemon's log containing what. */
static int log_count(const testdaemon *d, const char *what)
{
    FILE *fp = fopen(d->log, "r");
    char line[8192];
    int n = 0;
    while (fp && fgets(line, sizeof line, fp))
        n += strstr(line, what) != NULL;
    if (fp)
        fclose(fp);
    return n;
}

#define SPAWN_ROUNDS 40
#define SPAWN_JOBS 3

/* The daemon spawns its workers the moment it is up (and starts listening
 * just before): each round SIGKILLs it 0 to 7 ms after that, so over the
 * rounds the kill falls before, during and after the spawn and the row's
 * update. An orphan it leaves still runs its job; the next daemon must end
 * it before running that job again. The invariant is sampled right after
 * each start, when a second worker of a job would be running. */
TEST_T(daemon_killed_right_after_spawning_never_leaves_two_workers_of_one_job, 300)
{
    testdaemon_need_worker();
    static testdaemon d;
    const char *args[] = {"--workers", "2", NULL};
    testdaemon_start(&d, "spawnkill", args);
    cleanup_daemon = &d;
    atexit(kill_leftovers);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t ids[SPAWN_JOBS];
    for (int i = 0; i < SPAWN_JOBS; i++)
        ids[i] = submit_ok(c, 100000, 1);          /* hours each: they run through every round */
    mc_close(c);
    int most = 0;
    for (int round = 0; round < SPAWN_ROUNDS; round++) {
        for (int k = 0; k <= 3; k++) {
            int total = 0;
            for (int i = 0; i < SPAWN_JOBS; i++) {
                int n = testdaemon_live_workers(&d, ids[i]);
                if (n > 1)
                    FAILF("round %d: %d live workers of job %llu at once", round, n, (unsigned long long)ids[i]);
                total += n;
            }
            if (total > 2)
                FAILF("round %d: %d live workers with --workers 2", round, total);
            most = total > most ? total : most;
            if (k < 3)
                sleep_ms(round % 8 / 3 + 1);
        }
        testdaemon_kill(&d);
        testdaemon_start(&d, "spawnkill", args);
        sleep_ms(round % 8);
    }
    /* the last daemon runs two of them, once each */
    c = testdaemon_client(&d, TESTDAEMON_ALICE);
    for (int tries = 0; tries < 500; tries++) {
        mc_server_stats st;
        CHECK_INT(mc_stats(c, &st), 0);
        uint32_t running = st.running;
        mc_stats_free(&st);
        if (running == 2)
            break;
        sleep_ms(20);
    }
    int total = 0;
    for (int i = 0; i < SPAWN_JOBS; i++) {
        int n = testdaemon_live_workers(&d, ids[i]);
        CHECK(n <= 1);
        total += n;
    }
    CHECK_INT(total, 2);
    int killed = log_count(&d, "a previous daemon left running");
    printf("  %d kill -9 rounds; at most %d workers at once; %d orphan kill(s) logged at recovery\n",
           SPAWN_ROUNDS, most, killed);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
    CHECK_INT(testdaemon_kill_workers(&d), 0);  /* the drain ended every worker */
}

/* A worker whose daemon died finishes its job and writes result.frame;
 * the next daemon takes that result (the worker writes it atomically; the
 * daemon checks it whole) instead of running the job a second time. */
TEST_T(result_a_worker_finished_while_the_daemon_was_down_is_adopted_not_rerun, 120)
{
    testdaemon_need_worker();
    static testdaemon d;
    testdaemon_start(&d, "adopt", NULL);
    cleanup_daemon = &d;
    atexit(kill_leftovers);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id = submit_ok(c, 30, 0);
    mc_job_status s;
    do {                                        /* into the optimisation */
        CHECK_INT(mc_status(c, id, &s), 0);
        CHECK(s.state == MC_PENDING || s.state == MC_RUNNING);
    } while (!s.has_progress);
    mc_close(c);
    testdaemon_kill(&d);
    CHECK_INT(testdaemon_live_workers(&d, id), 1);   /* the orphan goes on */
    char path[1200];
    struct stat st;
    snprintf(path, sizeof path, "%s/spool/%llu/result.frame", d.state, (unsigned long long)id);
    for (int i = 0; i < 3000 && testdaemon_live_workers(&d, id) > 0; i++)
        sleep_ms(20);
    CHECK_INT(testdaemon_live_workers(&d, id), 0);
    if (stat(path, &st) != 0)
        FAILF("the orphan worker ended without %s", path);
    testdaemon_start(&d, "adopt", NULL);
    c = testdaemon_client(&d, TESTDAEMON_ALICE);
    CHECK_INT(mc_status(c, id, &s), 0);
    if (s.state != MC_COMPLETED)
        FAILF("job %llu is %s after the restart (reason '%s'), not COMPLETED from its result.frame",
              (unsigned long long)id, mc_state_name(s.state), s.reason);
    CHECK_STR_HAS(s.reason, "result adopted");
    CHECK(testdaemon_log_has(&d, "result adopted"));
    char started[64];
    snprintf(started, sizeof started, "job %llu: started on slot", (unsigned long long)id);
    CHECK_INT(log_count(&d, started), 1);       /* the first daemon's start only */
    mc_job_result r;
    CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q, &r), 0);
    CHECK_INT(r.np, 162);
    CHECK_INT(r.nq, 162);
    mc_result_free(&r);
    mc_server_stats stats;
    CHECK_INT(mc_stats(c, &stats), 0);
    CHECK_INT(stats.completed, 1);
    mc_stats_free(&stats);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
