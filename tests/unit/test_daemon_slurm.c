/* test_daemon_slurm.c — meshcorrd's slurm backend against a real Slurm
 * (Debian's slurmctld, slurmd and munge), through libmeshcorr: progress
 * streamed back over TCP and, when the worker cannot connect, through the
 * spool's progress.frames; the demo pair's map identical to the local
 * backend's; CANCEL as scancel; Slurm's time limit as TIMEOUT; meshcorrd
 * SIGKILLed and restarted while Slurm runs its jobs re-attaches without
 * submitting anything twice; SIGTERM under systemd (sd_notify) exits 0 and
 * leaves the jobs in Slurm; a missing sbatch or an unreachable controller is
 * in STATS and the job stays PENDING.
 *
 * The binary re-executes itself inside a private pid + network namespace
 * where tests/slurm/run-in-slurm.sh starts ONE single-node Slurm that all
 * tests below share, run one after the other in that namespace (Slurm takes
 * seconds to start; one per test would cost more than the tests). Each test
 * still runs in its own process with its own meshcorrd and state directory.
 * Without the privileges for the namespace, or without Slurm installed,
 * every test SKIPs with the reason. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testslurm.h"
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "meshcorr.h"

#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

__attribute__((constructor(101))) static void enter_slurm(int argc, char **argv)
{
    testslurm_enter(argc, argv);
}

typedef struct watch_log {
    int n;
    uint32_t last_outer;
    int monotone, finite;
} watch_log;

/* Counts every record; follows the ECTM records' iterations (a repair's
 * record, which ends a landmark job, counts its maps instead). */
static int on_progress(void *ctx, const mc_progress *p)
{
    watch_log *w = ctx;
    if (!isfinite(p->energy[0] + p->energy[1]))
        w->finite = 0;
    w->n++;
    if (p->stage == MC_STAGE_REPAIR)
        return 0;
    if (w->n > 1 && p->outer < w->last_outer)
        w->monotone = 0;
    w->last_outer = p->outer;
    return 0;
}

/* The demo pair 381 -> 390 with its initial maps (no landmarks: ECTM only,
 * so the outer iterations only grow), no early stop. */
static uint64_t submit_demo(mc_client *c, uint32_t iterations)
{
    testdaemon_demo dm;
    testdaemon_demo_open(&dm, iterations);
    uint64_t id = 0;
    if (mc_submit(c, &dm.spec, &id))
        FAILF("SUBMIT: %s", mc_errmsg(c));
    testdaemon_demo_close(&dm);
    return id;
}

static void demo_result(mc_client *c, uint64_t id, watch_log *w, mc_job_result *r)
{
    int state = -1;
    char reason[1100];
    CHECK_INT(mc_watch(c, id, 0, on_progress, w, &state, reason, sizeof reason), 0);
    if (state != MC_COMPLETED)
        FAILF("job %llu ended %s: %s", (unsigned long long)id, mc_state_name(state), reason);
    CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q, r), 0);
}

TEST_T(slurm_job_streams_energies_and_gives_the_local_backends_map, 150)
{
    testslurm_need();
    testdaemon sd, ld;
    const char *local_args[] = {"--workers", "1", NULL};
    testslurm_daemon(&sd, "demo-slurm", NULL);
    testdaemon_start(&ld, "demo-local", local_args);
    mc_client *sc = testdaemon_client(&sd, TESTDAEMON_ALICE), *lc = testdaemon_client(&ld, TESTDAEMON_ALICE);
    uint64_t sid = submit_demo(sc, 2), lid = submit_demo(lc, 2);
    watch_log sw = {0, 0, 1, 1}, lw = {0, 0, 1, 1};
    mc_job_result sr, lr;
    demo_result(sc, sid, &sw, &sr);
    demo_result(lc, lid, &lw, &lr);
    CHECK(sw.n >= 2);                  /* both outer iterations */
    CHECK_INT(sw.n, lw.n);
    CHECK(sw.monotone && sw.finite);
    CHECK_INT(sw.last_outer, 2);
    /* the stream came over the authenticated TCP connection, not the file */
    CHECK(testdaemon_log_has(&sd, "progress connection from its worker"));
    char path[1200];
    struct stat st;
    snprintf(path, sizeof path, "%s/spool/%llu/progress.frames", sd.state, (unsigned long long)sid);
    CHECK(stat(path, &st) != 0);
    snprintf(path, sizeof path, "%s/spool/%llu/progress.secret", sd.state, (unsigned long long)sid);
    CHECK_INT(stat(path, &st), 0);
    CHECK_INT(st.st_mode & 0777, 0600);
    /* the same map, bit for bit, as the local backend's worker */
    CHECK_INT(sr.np, lr.np);
    CHECK_INT(sr.nq, lr.nq);
    CHECK(sr.np > 1000);
    for (uint32_t i = 0; i < sr.np; i++)
        if (sr.p[i].face != lr.p[i].face || memcmp(sr.p[i].w, lr.p[i].w, sizeof sr.p[i].w) != 0)
            FAILF("P row %u differs: face %u vs %u", i, sr.p[i].face, lr.p[i].face);
    for (uint32_t i = 0; i < sr.nq; i++)
        if (sr.q[i].face != lr.q[i].face || memcmp(sr.q[i].w, lr.q[i].w, sizeof sr.q[i].w) != 0)
            FAILF("Q row %u differs", i);
    CHECK_INT(testslurm_count(&sd, sid), 1);
    mc_server_stats stats;
    CHECK_INT(mc_stats(sc, &stats), 0);
    CHECK_STR_HAS(stats.backend, "slurm");
    CHECK_INT(stats.backend_ok, 1);
    CHECK_INT(stats.completed, 1);
    mc_stats_free(&stats);
    mc_result_free(&sr);
    mc_result_free(&lr);
    mc_close(sc);
    mc_close(lc);
    testdaemon_stop(&sd, SIGTERM);
    testdaemon_stop(&ld, SIGTERM);
}

TEST_T(worker_that_cannot_reach_the_daemon_reports_through_the_progress_file, 90)
{
    testslurm_need();
    testdaemon d;
    /* the workers are told 127.0.0.2, where nothing listens */
    const char *args[] = {"--slurm-progress-host", "127.0.0.2", NULL};
    testslurm_daemon(&d, "file", args);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id = testdaemon_submit_ok(c, 4, 0, 0);
    watch_log w = {0, 0, 1, 1};
    int state = -1;
    char reason[1100];
    CHECK_INT(mc_watch(c, id, 0, on_progress, &w, &state, reason, sizeof reason), 0);
    if (state != MC_COMPLETED)
        FAILF("job ended %s: %s", mc_state_name(state), reason);
    CHECK(w.n >= 4);                   /* (landmark jobs: RHM's records, then ECTM's) */
    CHECK_INT(w.last_outer, 4);
    CHECK(w.finite);
    CHECK(!testdaemon_log_has(&d, "progress connection from its worker"));
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(cancel_of_a_running_slurm_job_is_scancel_and_ends_cancelled, 90)
{
    testslurm_need();
    testdaemon d;
    testslurm_daemon(&d, "cancel", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id = testdaemon_submit_ok(c, 100000, 1, 0);
    testdaemon_wait_state(c, id, MC_RUNNING, 30);
    char st[64];
    CHECK_STR_HAS(testslurm_state(&d, id, st, sizeof st), "RUNNING");
    CHECK_INT(mc_cancel(c, id), 0);
    int end = -1;
    char reason[1100];
    CHECK_INT(mc_watch(c, id, 1u << 30, NULL, NULL, &end, reason, sizeof reason), 0);
    CHECK_INT(end, MC_CANCELLED);
    CHECK_STR_HAS(reason, "scancel");
    CHECK_STR_HAS(testslurm_state(&d, id, st, sizeof st), "CANCELLED");
    CHECK_INT(mc_cancel(c, id), MC_EBAD_STATE);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(job_over_its_slurm_time_limit_ends_timeout_with_slurms_reason, 150)
{
    testslurm_need();
    testdaemon d;
    /* one minute is Slurm's smallest limit; slurmctld checks limits every 30 s */
    const char *args[] = {"--slurm-time", "1", NULL};
    testslurm_daemon(&d, "timeout", args);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id = submit_demo(c, 100000);     /* hours */
    testdaemon_wait_state(c, id, MC_RUNNING, 30);
    int end = testdaemon_wait_state(c, id, -1, 130);
    mc_job_status s;
    CHECK_INT(mc_status(c, id, &s), 0);
    if (end != MC_TIMEOUT)
        FAILF("job ended %s: %s", mc_state_name(end), s.reason);
    CHECK_STR_HAS(s.reason, "time limit");
    CHECK_STR_HAS(s.reason, "TIMEOUT");
    char st[64];
    CHECK_STR_HAS(testslurm_state(&d, id, st, sizeof st), "TIMEOUT");
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(sigkilled_daemon_reattaches_to_its_slurm_jobs_and_submits_nothing_twice, 120)
{
    testslurm_need();
    testdaemon d;
    testslurm_daemon(&d, "restart", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t a = submit_demo(c, 25), b = submit_demo(c, 25);   /* seconds each */
    testdaemon_wait_state(c, a, MC_RUNNING, 30);
    testdaemon_wait_state(c, b, MC_RUNNING, 30);
    testdaemon_sleep_ms(500);
    mc_close(c);
    testdaemon_kill(&d);
    /* the Slurm jobs run on without meshcorrd */
    char st[64];
    CHECK_STR_HAS(testslurm_state(&d, a, st, sizeof st), "RUNNING");
    testslurm_daemon(&d, "restart", NULL);
    c = testdaemon_client(&d, TESTDAEMON_ALICE);
    CHECK(testdaemon_log_has(&d, "re-attached to Slurm job"));
    for (int i = 0; i < 2; i++) {
        uint64_t id = i ? b : a;
        watch_log w = {0, 0, 1, 1};
        int end = -1;
        char reason[1100];
        CHECK_INT(mc_watch(c, id, 0, on_progress, &w, &end, reason, sizeof reason), 0);
        if (end != MC_COMPLETED)
            FAILF("job %llu ended %s: %s", (unsigned long long)id, mc_state_name(end), reason);
        CHECK_INT(w.last_outer, 25);
        CHECK(w.monotone && w.finite);
        mc_job_result r;
        CHECK_INT(mc_result(c, id, MC_WANT_P, &r), 0);
        CHECK_INT(r.np, 6938);
        mc_result_free(&r);
        CHECK_INT(testslurm_count(&d, id), 1);   /* one sbatch per job */
    }
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* Reads notify datagrams until one contains `want` (all text kept in log). */
static int notify_wait(int fd, const char *want, char *log, size_t logsz, int timeout_ms)
{
    for (int waited = 0; waited < timeout_ms; waited += 50) {
        struct pollfd p = {fd, POLLIN, 0};
        if (poll(&p, 1, 50) <= 0)
            continue;
        char msg[1024];
        ssize_t n = recv(fd, msg, sizeof msg - 1, 0);
        if (n <= 0)
            continue;
        msg[n] = '\0';
        size_t used = strlen(log);
        snprintf(log + used, logsz - used, "%s|", msg);
        if (strstr(msg, want))
            return 1;
    }
    return 0;
}

/* The local backend's worker slots do not exist here: READY's STATUS= and
 * the STOPPING=1 of a drain must count the Slurm backend's slots (they read
 * the local pool's, which only the local backend allocates: SIGSEGV). */
TEST_T(sigterm_of_a_slurm_daemon_under_systemd_exits_0_and_its_job_completes_after_restart, 120)
{
    testslurm_need();
    char path[700];
    snprintf(path, sizeof path, "%s/notify.sock", harness_tmpdir());
    int fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    CHECK(fd >= 0);
    struct sockaddr_un a = {.sun_family = AF_UNIX};
    CHECK(strlen(path) < sizeof a.sun_path);
    strcpy(a.sun_path, path);
    unlink(path);
    CHECK_INT(bind(fd, (struct sockaddr *)&a, sizeof a), 0);
    CHECK_INT(chmod(path, 0666), 0);    /* as systemd's: the daemon may run as TESTDAEMON_USER */
    CHECK_INT(setenv("NOTIFY_SOCKET", path, 1), 0);
    testdaemon d;
    const char *args[] = {"--slurm-max-jobs", "3", NULL};
    testslurm_daemon(&d, "term", args);
    unsetenv("NOTIFY_SOCKET");
    static char log[16384];
    if (!notify_wait(fd, "READY=1", log, sizeof log, 5000))
        FAILF("no READY=1: %s", log);
    CHECK_STR_HAS(log, "STATUS=0 queued, 0 of 3 slot(s) busy");
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id = submit_demo(c, 25);           /* seconds */
    testdaemon_wait_state(c, id, MC_RUNNING, 30);
    if (!notify_wait(fd, "1 of 3 slot(s) busy", log, sizeof log, 5000))
        FAILF("no STATUS= with the job in Slurm: %s", log);
    mc_close(c);
    CHECK_INT(kill(d.pid, SIGTERM), 0);
    if (!notify_wait(fd, "STOPPING=1", log, sizeof log, 5000))
        FAILF("no STOPPING=1: %s", log);
    testdaemon_stop(&d, 0);                     /* exit status 0, no second signal */
    close(fd);
    char st[64];
    CHECK_STR_HAS(testslurm_state(&d, id, st, sizeof st), "RUNNING");
    testslurm_daemon(&d, "term", args);
    c = testdaemon_client(&d, TESTDAEMON_ALICE);
    int end = -1;
    char reason[1100];
    CHECK_INT(mc_watch(c, id, 0, NULL, NULL, &end, reason, sizeof reason), 0);
    if (end != MC_COMPLETED)
        FAILF("job ended %s: %s", mc_state_name(end), reason);
    CHECK_INT(testslurm_count(&d, id), 1);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

static void write_text(const char *path, const char *text)
{
    FILE *fp = fopen(path, "w");
    if (!fp)
        FAILF("cannot write %s", path);
    fputs(text, fp);
    fclose(fp);
}

/* slurm-max-jobs is the Slurm backend's slot count, and the status snapshot
 * is sized from it at start: a SIGHUP raising it must keep the running value
 * (with a warning), never let the snapshot index past its arrays. The daemon
 * runs with glibc's malloc checks (a canary after every block, checked when
 * it is freed), so a write past the snapshot ends it by SIGABRT. */
TEST_T(sighup_raising_slurm_max_jobs_keeps_the_slot_count_and_writes_nothing_past_it, 120)
{
    testslurm_need();
    static const char dbg[] = "/usr/lib/x86_64-linux-gnu/libc_malloc_debug.so.0";
    if (access(dbg, R_OK) == 0) {
        setenv("LD_PRELOAD", dbg, 1);
        setenv("GLIBC_TUNABLES", "glibc.malloc.check=3", 1);
    }
    char conf[700];
    snprintf(conf, sizeof conf, "%s/reload.conf", harness_tmpdir());
    write_text(conf, "slurm-max-jobs = 2\n");
    testdaemon d;
    const char *args[] = {"--config", conf, NULL};
    testslurm_daemon(&d, "reload", args);
    unsetenv("LD_PRELOAD");
    unsetenv("GLIBC_TUNABLES");
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    mc_server_stats st;
    CHECK_INT(mc_stats(c, &st), 0);
    CHECK_INT(st.nslots, 2);
    mc_stats_free(&st);
    write_text(conf, "slurm-max-jobs = 64\n");
    CHECK_INT(kill(d.pid, SIGHUP), 0);
    for (int i = 0; i < 500 && !testdaemon_log_has(&d, "reload: options applied"); i++)
        testdaemon_sleep_ms(10);
    CHECK(testdaemon_log_has(&d, "reload: options applied"));
    CHECK(testdaemon_log_has(&d, "slurm-max-jobs changed but take(s) effect at the next start only"));
    uint64_t ids[4];
    for (int i = 0; i < 4; i++)
        ids[i] = testdaemon_submit_ok(c, 2, 0, 0);
    uint32_t most = 0;
    for (int done = 0; !done;) {
        CHECK_INT(mc_stats(c, &st), 0);
        CHECK_INT(st.nslots, 2);            /* the slot count of the start */
        if (st.running > most)
            most = st.running;
        done = st.completed + st.failed + st.cancelled == 4;
        mc_stats_free(&st);
        testdaemon_sleep_ms(100);
    }
    CHECK(most >= 1 && most <= 2);          /* still at most 2 jobs in Slurm at once */
    for (int i = 0; i < 4; i++)
        CHECK_INT(testdaemon_wait_state(c, ids[i], -1, 10), MC_COMPLETED);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);           /* exit 0: no canary was overwritten */
}

TEST_T(missing_sbatch_is_in_stats_and_the_job_stays_pending, 60)
{
    testslurm_need();
    const char *path = getenv("PATH");
    char saved[4096];
    snprintf(saved, sizeof saved, "%s", path ? path : "");
    setenv("PATH", "/nonexistent", 1);        /* the daemon inherits it */
    testdaemon d;
    testslurm_daemon(&d, "nosbatch", NULL);
    setenv("PATH", saved, 1);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id = testdaemon_submit_ok(c, 2, 0, 0);
    testdaemon_sleep_ms(1500);                            /* five polls */
    mc_job_status s;
    CHECK_INT(mc_status(c, id, &s), 0);
    CHECK_INT(s.state, MC_PENDING);
    mc_server_stats stats;
    CHECK_INT(mc_stats(c, &stats), 0);
    CHECK_STR_HAS(stats.backend, "slurm");
    CHECK_INT(stats.backend_ok, 0);
    CHECK_STR_HAS(stats.backend_status, "not found in PATH");
    mc_stats_free(&stats);
    CHECK(testdaemon_log_has(&d, "not found in PATH"));
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(unreachable_controller_is_in_stats_and_the_job_stays_pending, 90)
{
    testslurm_need();
    /* the same cluster, but a controller port nothing listens on */
    char conf[1200], line[1024];
    snprintf(conf, sizeof conf, "%s/unreachable.conf", harness_tmpdir());
    FILE *in = fopen(getenv("SLURM_CONF"), "r"), *out = fopen(conf, "w");
    CHECK(in && out);
    while (fgets(line, sizeof line, in))
        fputs(strncmp(line, "SlurmctldPort=", 14) == 0 ? "SlurmctldPort=6999\n" : line, out);
    fclose(in);
    fclose(out);
    setenv("SLURM_CONF", conf, 1);
    testdaemon d;
    testslurm_daemon(&d, "noctld", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id = testdaemon_submit_ok(c, 2, 0, 0);
    mc_server_stats stats = {0};
    for (int i = 0; i < 600 && !strstr(stats.backend_status, "squeue failed"); i++) {
        mc_stats_free(&stats);
        CHECK_INT(mc_stats(c, &stats), 0);
        testdaemon_sleep_ms(100);
    }
    CHECK_INT(stats.backend_ok, 0);
    CHECK_STR_HAS(stats.backend_status, "squeue failed");
    mc_stats_free(&stats);
    mc_job_status s;
    CHECK_INT(mc_status(c, id, &s), 0);
    CHECK_INT(s.state, MC_PENDING);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
