/* test_sec_quota.c — one user cannot fill the disk for everyone. A job
 * that ends without completing gives its input (job.frame) back at once,
 * so alice's SUBMIT+CANCEL loop on a small state file system stores no
 * more than her unfinished jobs and bob's SUBMIT still fits; a user's
 * stored bytes (jobs and results) are bounded by --max-bytes-per-user and
 * everyone's by --max-spool-bytes, each refusal OVER_QUOTA naming the
 * user, the bytes stored, the request's size and the option, and logged;
 * an ended job's row and reason stay, across a restart too. Real daemon,
 * real client library; the small file system is a tmpfs in a mount
 * namespace of the test's own (SKIP where that cannot be made). */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testsec.h"
#include "meshcorr.h"
#include "spool.h"

#include <errno.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

#define LEVEL 5        /* icosphere pairs of 10242 vertices: SUBMITs of about 740 kB */

static testdaemon *leftover;
static void kill_leftover(void)
{
    if (leftover && leftover->pid > 0)
        testdaemon_kill_workers(leftover);
}

TEST_T(a_submit_cancel_loop_does_not_fill_a_small_state_file_system_for_everyone, 300)
{
    testdaemon_need_worker();
    /* the state directory on a 6 MiB tmpfs, in a mount namespace of this
     * test process (and the daemon it starts) only */
    if (unshare(CLONE_NEWNS) != 0)
        SKIP("cannot make a mount namespace: %s (needs CAP_SYS_ADMIN)", strerror(errno));
    CHECK_INT(mount(NULL, "/", NULL, MS_REC | MS_PRIVATE, NULL), 0);
    char dir[700], state[800];
    snprintf(dir, sizeof dir, "%s/small", harness_tmpdir());
    snprintf(state, sizeof state, "%s/state", dir);
    CHECK_INT(mkdir(dir, 0700), 0);
    CHECK_INT(mkdir(state, 0700), 0);
    if (mount("tmpfs", state, "tmpfs", MS_NOSUID | MS_NODEV, "size=6m,mode=0700") != 0)
        SKIP("cannot mount a tmpfs: %s", strerror(errno));
    static testdaemon d;
    static const char *const args[] = {"--max-jobs-per-user", "2", NULL};
    testdaemon_start(&d, "small", args);
    leftover = &d;
    atexit(kill_leftover);
    mc_client *alice = testdaemon_client(&d, TESTDAEMON_ALICE);
    long long most = 0;
    uint64_t ids[12];
    for (int i = 0; i < 12; i++) {
        int rc;
        uint64_t id = ids[i] = testsec_submit_sphere(alice, LEVEL, MC_STAGES_RHM, 1, &rc);
        if (rc)
            FAILF("alice's SUBMIT %d of her SUBMIT+CANCEL loop: %s (%s)", i, mc_strerror(rc), mc_errmsg(alice));
        long long held = testsec_spool_bytes(&d, id);
        most = held > most ? held : most;
        CHECK_INT(mc_cancel(alice, id), 0);
        CHECK_INT(testdaemon_wait_state(alice, id, -1, 60), MC_CANCELLED);
    }
    mc_client *bob = testdaemon_client(&d, TESTDAEMON_BOB);
    int rc;
    uint64_t bid = testsec_submit_sphere(bob, LEVEL, MC_STAGES_RHM, 1, &rc);
    if (rc)
        FAILF("bob's SUBMIT after alice's loop: %s (%s)", mc_strerror(rc), mc_errmsg(bob));
    for (int i = 0; i < 12; i++) {
        if (testsec_spool_has(&d, ids[i], SPOOL_JOB_FRAME))
            FAILF("job %llu is CANCELLED and still holds its job.frame", (unsigned long long)ids[i]);
        mc_job_status s;
        CHECK_INT(mc_status(alice, ids[i], &s), 0);
        CHECK_STR_HAS(s.reason, "cancelled");       /* the row and its reason stay */
    }
    CHECK_INT(testdaemon_wait_state(bob, bid, -1, 120), MC_COMPLETED);
    printf("  12 SUBMIT+CANCEL of %lld-byte jobs on a 6 MiB state file system; bob's job completed\n", most);
    mc_close(alice);
    mc_close(bob);
    testdaemon_stop(&d, SIGTERM);
    umount2(state, MNT_DETACH);
}

/* alice's unfinished jobs in the spool: bytes of these ids' directories. */
static long long bytes_of(const testdaemon *d, const uint64_t *ids, int n)
{
    long long sum = 0;
    for (int i = 0; i < n; i++)
        sum += testsec_spool_bytes(d, ids[i]);
    return sum;
}

TEST_T(a_users_stored_bytes_are_bounded_by_her_quota_and_others_still_submit, 300)
{
    testdaemon_need_worker();
    /* room for two of alice's SUBMITs and a half */
    long long frame = 2 * (long long)testsec_sphere_bytes(LEVEL), quota = frame * 5 / 2;
    char qarg[32];
    snprintf(qarg, sizeof qarg, "%lld", quota);
    const char *args[] = {"--max-bytes-per-user", qarg, NULL};
    testdaemon d;
    testdaemon_start(&d, "quota", args);
    leftover = &d;
    atexit(kill_leftover);
    mc_client *alice = testdaemon_client(&d, TESTDAEMON_ALICE), *bob = testdaemon_client(&d, TESTDAEMON_BOB);
    /* bob's long job holds the one worker: alice's jobs stay PENDING */
    uint64_t hold = testdaemon_submit_ok(bob, 100000, 1, 0);
    testdaemon_wait_state(bob, hold, MC_RUNNING, 30);
    uint64_t ids[64];
    int n = 0, rc;
    for (int i = 0; i < 6; i++) {              /* the loop: never over the quota */
        uint64_t id = testsec_submit_sphere(alice, LEVEL, MC_STAGES_RHM, 1, &rc);
        if (rc)
            FAILF("alice's SUBMIT+CANCEL %d: %s (%s)", i, mc_strerror(rc), mc_errmsg(alice));
        ids[n++] = id;
        CHECK_INT(mc_cancel(alice, id), 0);
        CHECK_INT(testdaemon_wait_state(alice, id, -1, 30), MC_CANCELLED);
        CHECK(bytes_of(&d, ids, n) <= quota);
    }
    uint64_t kept[2];
    for (int i = 0; i < 2; i++) {               /* two pending jobs fit */
        kept[i] = ids[n++] = testsec_submit_sphere(alice, LEVEL, MC_STAGES_RHM, 1, &rc);
        if (rc)
            FAILF("alice's pending SUBMIT %d under her quota: %s (%s)", i, mc_strerror(rc), mc_errmsg(alice));
    }
    long long stored = bytes_of(&d, ids, n);
    testsec_submit_sphere(alice, LEVEL, MC_STAGES_RHM, 1, &rc);
    if (rc != MC_EOVER_QUOTA)
        FAILF("alice's third pending SUBMIT, %lld bytes stored of a %lld-byte quota: %s (%s)", stored, quota,
              mc_strerror(rc), mc_errmsg(alice));
    char want[160];
    snprintf(want, sizeof want, "user alice stores %lld bytes of jobs and results", stored);
    CHECK_STR_HAS(mc_errmsg(alice), want);
    snprintf(want, sizeof want, "--max-bytes-per-user %lld", quota);
    CHECK_STR_HAS(mc_errmsg(alice), want);
    CHECK_STR_HAS(mc_errmsg(alice), "-byte SUBMIT would pass");
    CHECK(testdaemon_log_has(&d, "SUBMIT from alice refused (OVER_QUOTA): over quota: user alice stores"));
    CHECK(bytes_of(&d, ids, n) <= quota);
    /* bob has a quota of his own */
    uint64_t bid = testsec_submit_sphere(bob, LEVEL, MC_STAGES_RHM, 1, &rc);
    if (rc)
        FAILF("bob's SUBMIT with alice at her quota: %s (%s)", mc_strerror(rc), mc_errmsg(bob));
    /* a cancel gives the room back at once */
    CHECK_INT(mc_cancel(alice, kept[0]), 0);
    CHECK_INT(testdaemon_wait_state(alice, kept[0], -1, 30), MC_CANCELLED);
    uint64_t again = testsec_submit_sphere(alice, LEVEL, MC_STAGES_RHM, 1, &rc);
    if (rc)
        FAILF("alice's SUBMIT after a cancel freed her room: %s (%s)", mc_strerror(rc), mc_errmsg(alice));
    uint64_t cancel[] = {hold, bid};
    for (int i = 0; i < 2; i++)
        CHECK_INT(mc_cancel(bob, cancel[i]), 0);
    CHECK_INT(mc_cancel(alice, kept[1]), 0);
    CHECK_INT(mc_cancel(alice, again), 0);
    mc_close(alice);
    mc_close(bob);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(the_spool_as_a_whole_is_bounded_by_max_spool_bytes, 180)
{
    testdaemon_need_worker();
    long long frame = 2 * (long long)testsec_sphere_bytes(LEVEL), cap = frame * 5 / 2;
    char carg[32];
    snprintf(carg, sizeof carg, "%lld", cap);
    const char *args[] = {"--max-spool-bytes", carg, NULL};
    testdaemon d;
    testdaemon_start(&d, "spool", args);
    mc_client *alice = testdaemon_client(&d, TESTDAEMON_ALICE), *bob = testdaemon_client(&d, TESTDAEMON_BOB);
    uint64_t hold = testdaemon_submit_ok(bob, 100000, 1, 0);
    testdaemon_wait_state(bob, hold, MC_RUNNING, 30);
    int rc;
    uint64_t a = testsec_submit_sphere(alice, LEVEL, MC_STAGES_RHM, 1, &rc);
    CHECK_INT(rc, 0);
    uint64_t b = testsec_submit_sphere(bob, LEVEL, MC_STAGES_RHM, 1, &rc);
    CHECK_INT(rc, 0);
    testsec_submit_sphere(bob, LEVEL, MC_STAGES_RHM, 1, &rc);
    if (rc != MC_EOVER_QUOTA)
        FAILF("a SUBMIT past the spool's cap of %lld bytes: %s (%s)", cap, mc_strerror(rc), mc_errmsg(bob));
    char want[96];
    snprintf(want, sizeof want, "would pass --max-spool-bytes %lld", cap);
    CHECK_STR_HAS(mc_errmsg(bob), want);
    CHECK_STR_HAS(mc_errmsg(bob), "the spool holds");
    CHECK(testdaemon_log_has(&d, "SUBMIT from bob refused (OVER_QUOTA): over quota: the spool holds"));
    CHECK_INT(mc_cancel(alice, a), 0);
    CHECK_INT(mc_cancel(bob, b), 0);
    CHECK_INT(mc_cancel(bob, hold), 0);
    mc_close(alice);
    mc_close(bob);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(an_ended_jobs_input_goes_and_its_row_stays_across_a_restart, 240)
{
    testdaemon_need_worker();
    static const char *const args[] = {"--job-timeout", "3", NULL};
    testdaemon d;
    testdaemon_start(&d, "ended", args);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t done = testdaemon_submit_ok(c, 2, 0, 0);
    CHECK_INT(testdaemon_wait_state(c, done, -1, 60), MC_COMPLETED);
    uint64_t slow = testdaemon_submit_ok(c, 100000, 1, 0);       /* past --job-timeout: TIMEOUT */
    uint64_t queued = testdaemon_submit_ok(c, 2, 0, 0);          /* cancelled while it waits */
    CHECK_INT(mc_cancel(c, queued), 0);
    CHECK_INT(testdaemon_wait_state(c, slow, -1, 60), MC_TIMEOUT);
    CHECK_INT(testdaemon_wait_state(c, queued, -1, 10), MC_CANCELLED);
    CHECK(testsec_spool_has(&d, done, SPOOL_JOB_FRAME));         /* a COMPLETED job keeps it */
    CHECK(testsec_spool_has(&d, done, SPOOL_RESULT_FRAME));
    CHECK(!testsec_spool_has(&d, slow, SPOOL_JOB_FRAME));
    CHECK(!testsec_spool_has(&d, queued, SPOOL_JOB_FRAME));
    mc_close(c);
    /* a daemon stopped between an end's commit and the removal leaves a
     * job.frame behind: put one back, as that crash would have */
    char from[800], to[800];
    snprintf(from, sizeof from, "%s/spool/%llu/%s", d.state, (unsigned long long)done, SPOOL_JOB_FRAME);
    snprintf(to, sizeof to, "%s/spool/%llu/%s", d.state, (unsigned long long)queued, SPOOL_JOB_FRAME);
    CHECK_INT(link(from, to), 0);
    testdaemon_stop(&d, SIGTERM);
    testdaemon_start(&d, "ended", args);
    c = testdaemon_client(&d, TESTDAEMON_ALICE);
    mc_job_status s;
    CHECK_INT(mc_status(c, slow, &s), 0);
    CHECK_INT(s.state, MC_TIMEOUT);                              /* not "job.frame missing": FAILED */
    CHECK_STR_HAS(s.reason, "wall time limit");
    CHECK_INT(mc_status(c, queued, &s), 0);
    CHECK_INT(s.state, MC_CANCELLED);
    CHECK_STR_HAS(s.reason, "cancelled");
    CHECK(!testsec_spool_has(&d, queued, SPOOL_JOB_FRAME));
    CHECK(testdaemon_log_has(&d, "0 job(s) without spool failed, 1 ended job(s)' input removed"));
    mc_job_result r;
    CHECK_INT(mc_result(c, done, MC_WANT_P, &r), 0);
    CHECK_INT(r.np, 162);
    mc_result_free(&r);
    CHECK_INT(mc_result(c, slow, MC_WANT_P, &r), MC_EBAD_STATE);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
