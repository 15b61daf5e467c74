/* test_daemon_faults.c — meshcorrd under crash faults, black-box with the
 * real daemon, worker and client: the daemon SIGKILLed right after it
 * spawned workers, round after round, never leaves two live workers of one
 * job (nor more than --workers); a job whose worker finished while the
 * daemon was down is COMPLETED from its result.frame, not run again; a full
 * state file system (a small tmpfs the test mounts in a mount namespace of
 * its own) refuses SUBMIT with STORAGE and loses nothing acknowledged, and
 * the daemon goes on answering STATUS, RESULT and LIST; a worker that could
 * not store its answer (exit 4) is a passing condition, not a crash, and
 * so is a worker start that fails for want of descriptors. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "meshcorr.h"
#include "proto.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* Orphans must not outlive a failed test (they would run for hours). */
static testdaemon *cleanup_daemon;
static void kill_leftovers(void)
{
    if (!cleanup_daemon)
        return;
    if (cleanup_daemon->pid > 0)          /* first the daemon: it would start more */
        kill(cleanup_daemon->pid, SIGKILL);
    for (int i = 0; i < 100 && testdaemon_kill_workers(cleanup_daemon) > 0; i++)
        testdaemon_sleep_ms(10);
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
        ids[i] = testdaemon_submit_ok(c, 100000, 1, 0);          /* hours each: they run through every round */
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
                testdaemon_sleep_ms(round % 8 / 3 + 1);
        }
        testdaemon_kill(&d);
        testdaemon_start(&d, "spawnkill", args);
        testdaemon_sleep_ms(round % 8);
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
        testdaemon_sleep_ms(20);
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
    uint64_t id = testdaemon_submit_ok(c, 30, 0, 0);
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
        testdaemon_sleep_ms(20);
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

/* Fills the file system of dir with one file: bytes written. */
static long long fill_fs(const char *dir, char *path, size_t psz)
{
    snprintf(path, psz, "%s/filler", dir);
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd < 0)
        FAILF("%s: %s", path, strerror(errno));
    static char chunk[65536];
    memset(chunk, 0x5a, sizeof chunk);
    long long total = 0;
    for (size_t n = sizeof chunk; n >= 1; n /= 16) {
        ssize_t w;
        while ((w = write(fd, chunk, n)) > 0)
            total += w;
        if (w < 0 && errno != ENOSPC)
            FAILF("filling %s: %s", path, strerror(errno));
    }
    close(fd);
    return total;
}

/* spool/.new-* directories: SUBMITs being stored, or left by a failed one. */
static int count_new_dirs(const char *spool)
{
    DIR *dp = opendir(spool);
    if (!dp)
        FAILF("%s: %s", spool, strerror(errno));
    int n = 0;
    struct dirent *de;
    while ((de = readdir(dp)))
        n += strncmp(de->d_name, ".new-", 5) == 0;
    closedir(dp);
    return n;
}

TEST_T(submit_on_a_full_disk_is_refused_as_storage_and_nothing_acknowledged_is_lost, 120)
{
    testdaemon_need_worker();
    /* the state directory on an 8 MB tmpfs, in a mount namespace of this
     * test process (and the daemon it starts) only */
    if (unshare(CLONE_NEWNS) != 0)
        SKIP("cannot make a mount namespace: %s (needs CAP_SYS_ADMIN)", strerror(errno));
    CHECK_INT(mount(NULL, "/", NULL, MS_REC | MS_PRIVATE, NULL), 0);
    char dir[700], state[800];
    snprintf(dir, sizeof dir, "%s/full", harness_tmpdir());
    snprintf(state, sizeof state, "%s/state", dir);
    CHECK_INT(mkdir(dir, 0700), 0);
    CHECK_INT(mkdir(state, 0700), 0);
    if (mount("tmpfs", state, "tmpfs", MS_NOSUID | MS_NODEV, "size=8m,mode=0700") != 0)
        SKIP("cannot mount a tmpfs: %s", strerror(errno));
    static testdaemon d;
    const char *args[] = {"--workers", "1", NULL};
    testdaemon_start(&d, "full", args);
    cleanup_daemon = &d;
    atexit(kill_leftovers);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t done = testdaemon_submit_ok(c, 2, 0, 0);
    CHECK_INT(testdaemon_wait_state(c, done, -1, 60), MC_COMPLETED);
    uint64_t running = testdaemon_submit_ok(c, 100000, 1, 0);
    testdaemon_wait_state(c, running, MC_RUNNING, 30);
    uint64_t pending = testdaemon_submit_ok(c, 2, 0, 0);
    char filler[900];
    long long filled = fill_fs(state, filler, sizeof filler);
    /* every SUBMIT now: STORAGE, naming the full disk; nothing stored */
    for (int i = 0; i < 5; i++) {
        int rc;
        uint64_t id = testdaemon_submit(c, 2, 0, 0, &rc);
        if (rc != PROTO_ESTORAGE)
            FAILF("SUBMIT %d on a full disk: %s (%s), job %llu", i, mc_strerror(rc), mc_errmsg(c),
                  (unsigned long long)id);
        CHECK_STR_HAS(mc_errmsg(c), "No space left on device");
        CHECK_STR_HAS(mc_errmsg(c), "job not stored");
    }
    char spool[900];
    snprintf(spool, sizeof spool, "%s/spool", state);
    CHECK_INT(count_new_dirs(spool), 0);        /* the refused frames were removed */
    /* still answering: STATUS, RESULT, LIST, STATS */
    mc_job_status s;
    CHECK_INT(mc_status(c, done, &s), 0);
    CHECK_INT(s.state, MC_COMPLETED);
    CHECK_INT(mc_status(c, running, &s), 0);
    CHECK_INT(s.state, MC_RUNNING);
    CHECK_INT(mc_status(c, pending, &s), 0);
    CHECK_INT(s.state, MC_PENDING);
    mc_job_result r;
    CHECK_INT(mc_result(c, done, MC_WANT_P | MC_WANT_Q, &r), 0);
    CHECK_INT(r.np, 162);
    mc_result_free(&r);
    mc_job_info *jobs = NULL;
    uint32_t n = 0;
    CHECK_INT(mc_list(c, NULL, 0, &jobs, &n), 0);
    CHECK_INT(n, 3);
    free(jobs);
    mc_server_stats st;
    CHECK_INT(mc_stats(c, &st), 0);
    mc_stats_free(&st);
    CHECK(testdaemon_log_has(&d, "No space left on device"));
    /* a cancel while full: the end is recorded once the store can take it,
     * and the pending job does not start a run whose answer has no room */
    CHECK_INT(mc_cancel(c, running), 0);
    char waiting[128];
    snprintf(waiting, sizeof waiting, "job %llu: waiting to start: the state file system is full",
             (unsigned long long)pending);
    for (int i = 0; i < 500 && !testdaemon_log_has(&d, waiting); i++)
        testdaemon_sleep_ms(20);
    CHECK(testdaemon_log_has(&d, waiting));     /* (the store cannot take that reason now) */
    CHECK_INT(mc_status(c, pending, &s), 0);
    CHECK_INT(s.state, MC_PENDING);
    /* space again: everything acknowledged runs on, and SUBMIT works */
    CHECK_INT(unlink(filler), 0);
    CHECK_INT(testdaemon_wait_state(c, running, -1, 30), MC_CANCELLED);
    CHECK_INT(testdaemon_wait_state(c, pending, -1, 90), MC_COMPLETED);
    uint64_t after = testdaemon_submit_ok(c, 2, 0, 0);
    CHECK_INT(testdaemon_wait_state(c, after, -1, 60), MC_COMPLETED);
    printf("  %lld bytes filled the 8 MB tmpfs; 5 SUBMITs refused as STORAGE, 3 jobs kept;%s\n", filled,
           testdaemon_log_has(&d, "cannot record its end") ? " the cancel's end was recorded once space came back"
                                                            : " the cancel's end fitted in the store");
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
    umount2(state, MNT_DETACH);
}

/* A worker that exits 4 (WORKER.md: no answer could be stored, a full
 * disk) has not crashed and the job has not failed: it goes back to the
 * queue, starts pause for a while, and it is tried again, as often as it
 * takes (here a script that always exits 4). */
TEST_T(worker_that_cannot_store_its_answer_requeues_the_job_without_counting_a_crash, 60)
{
    char script[700];
    snprintf(script, sizeof script, "%s/no-answer.sh", harness_tmpdir());
    FILE *fp = fopen(script, "w");
    CHECK(fp != NULL);
    /* SUBMIT's check is the real meshcorr-validate; every run exits 4 */
    fprintf(fp, "#!/bin/sh\n"
                "echo 'meshcorr-worker: cannot write result.frame: No space left on device' >&2\nexit 4\n");
    fclose(fp);
    CHECK_INT(chmod(script, 0755), 0);
    testdaemon d;
    const char *args[] = {"--worker", script, NULL};
    testdaemon_start(&d, "noanswer", args);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id = testdaemon_submit_ok(c, 2, 0, 0);
    char started[64];
    snprintf(started, sizeof started, "job %llu: started on slot", (unsigned long long)id);
    for (int i = 0; i < 1500 && log_count(&d, started) < 3; i++)
        testdaemon_sleep_ms(10);
    CHECK(log_count(&d, started) >= 3);         /* two crashes would have failed it */
    mc_job_status s;
    CHECK_INT(mc_status(c, id, &s), 0);
    if (s.state != MC_PENDING && s.state != MC_RUNNING)
        FAILF("job %llu is %s: %s", (unsigned long long)id, mc_state_name(s.state), s.reason);
    CHECK(testdaemon_log_has(&d, "re-queued: the worker could not store its answer"));
    CHECK(!testdaemon_log_has(&d, "crash"));
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

static int open_fds(pid_t pid)
{
    char dir[64];
    snprintf(dir, sizeof dir, "/proc/%d/fd", (int)pid);
    DIR *dp = opendir(dir);
    if (!dp)
        return -1;
    int n = 0;
    struct dirent *de;
    while ((de = readdir(dp)))
        n += de->d_name[0] != '.';
    closedir(dp);
    return n;
}

/* A bare connection to the daemon's Unix socket that says nothing. */
static int idle_connection(const testdaemon *d)
{
    struct sockaddr_un a = {.sun_family = AF_UNIX};
    snprintf(a.sun_path, sizeof a.sun_path, "%s", d->unix_addr + strlen("unix:"));
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    CHECK(fd >= 0);
    if (connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

#define IDLE_CONNS 60

/* Idle clients hold every descriptor the daemon may open (its limit cut to
 * what it has open plus 16). A queued job whose turn comes then cannot get
 * its worker's pipe: that is a passing condition, so the job waits in the
 * queue and runs once descriptors are free again, it never ends FAILED. */
TEST_T(worker_start_without_descriptors_waits_and_the_job_completes_later, 90)
{
    testdaemon_need_worker();
    testdaemon d;
    const char *args[] = {"--workers", "1", NULL};
    testdaemon_start(&d, "nofile", args);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t running = testdaemon_submit_ok(c, 100000, 1, 0);
    testdaemon_wait_state(c, running, MC_RUNNING, 30);
    uint64_t queued = testdaemon_submit_ok(c, 2, 0, 0);
    int base = open_fds(d.pid);
    CHECK(base > 0);
    struct rlimit old, rl;
    CHECK_INT(testdaemon_prlimit(&d, RLIMIT_NOFILE, NULL, &old), 0);
    rl = (struct rlimit){(rlim_t)base + 16, old.rlim_max};       /* the soft limit */
    CHECK_INT(testdaemon_prlimit(&d, RLIMIT_NOFILE, &rl, NULL), 0);
    int idle[IDLE_CONNS], nidle = 0;
    for (int i = 0; i < IDLE_CONNS; i++)
        if ((idle[nidle] = idle_connection(&d)) >= 0)
            nidle++;
    for (int i = 0; i < 200 && open_fds(d.pid) < base + 16; i++)
        testdaemon_sleep_ms(10);
    int at_limit = open_fds(d.pid);
    /* the running job ends: the queued one's turn, with no descriptor free */
    CHECK_INT(mc_cancel(c, running), 0);
    CHECK_INT(testdaemon_wait_state(c, running, -1, 30), MC_CANCELLED);
    testdaemon_sleep_ms(1500);
    mc_job_status s;
    CHECK_INT(mc_status(c, queued, &s), 0);
    if (s.state != MC_PENDING && s.state != MC_RUNNING && s.state != MC_COMPLETED)
        FAILF("queued job %llu ended %s while descriptors ran out: %s", (unsigned long long)queued,
              mc_state_name(s.state), s.reason);
    int waited = testdaemon_log_has(&d, "waiting to start: cannot start worker");
    for (int i = 0; i < nidle; i++)
        close(idle[i]);
    CHECK_INT(testdaemon_prlimit(&d, RLIMIT_NOFILE, &old, NULL), 0);
    int end = testdaemon_wait_state(c, queued, -1, 60);
    CHECK_INT(mc_status(c, queued, &s), 0);
    if (end != MC_COMPLETED)
        FAILF("queued job %llu ended %s: %s", (unsigned long long)queued, mc_state_name(end), s.reason);
    printf("  daemon at %d of %d descriptors (%d idle clients); the queued job %s, then COMPLETED\n",
           at_limit, base + 16, nidle, waited ? "waited for descriptors" : "found one");
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
