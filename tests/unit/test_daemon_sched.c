/* test_daemon_sched.c — the scheduler module (daemon/sched.c) driven
 * directly: priority first, fair share between users, then age; plus one
 * check through the real daemon that a second user's job overtakes the
 * first user's queue. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "mcd.h"

#include <signal.h>
#include <string.h>

static uint64_t next(sched *s, const char *want_user)
{
    char user[AUTH_MAX_USER];
    uint64_t id = sched_next(s, user);
    if (want_user && strcmp(user, want_user) != 0)
        FAILF("job %llu of %s started, expected one of %s", (unsigned long long)id, user, want_user);
    return id;
}

TEST(one_users_many_jobs_do_not_starve_another_users_one)
{
    sched *s = sched_new();
    CHECK(s != NULL);
    for (uint64_t id = 1; id <= 6; id++)
        CHECK_INT(sched_add(s, id, "alice", 0), 0);
    CHECK_INT(next(s, "alice"), 1);            /* alice's first runs on the one slot */
    CHECK_INT(sched_add(s, 7, "bob", 0), 0);   /* bob arrives with one job */
    sched_done(s, "alice");
    CHECK_INT(next(s, "bob"), 7);              /* bob: never served, goes before alice's 2nd */
    sched_done(s, "bob");
    for (uint64_t id = 2; id <= 6; id++) {     /* then alice's in age order */
        CHECK_INT(next(s, "alice"), id);
        sched_done(s, "alice");
    }
    CHECK_INT(sched_next(s, (char[AUTH_MAX_USER]){0}), 0);
    sched_free(s);
}

TEST(fewer_running_jobs_wins_then_least_recent_service)
{
    sched *s = sched_new();
    for (uint64_t id = 1; id <= 4; id++)
        sched_add(s, id, "alice", 0);
    sched_add(s, 10, "bob", 0);
    sched_add(s, 11, "bob", 0);
    sched_add(s, 20, "carol", 0);
    /* three slots: one job per user before anyone gets a second */
    uint64_t a = next(s, NULL), b = next(s, NULL), c = next(s, NULL);
    CHECK_INT(a, 1);
    CHECK_INT(b, 10);
    CHECK_INT(c, 20);
    CHECK_INT(sched_user_running(s, "alice"), 1);
    sched_done(s, "carol");                    /* carol's ends: alice served before bob */
    CHECK_INT(next(s, "alice"), 2);
    sched_done(s, "bob");                      /* bob has 0 running now, alice 2 */
    CHECK_INT(next(s, "bob"), 11);
    CHECK_INT(sched_queued(s), 2);
    CHECK_INT(sched_user_pending(s, "alice"), 2);
    sched_free(s);
}

TEST(priority_goes_first_then_age_and_removed_jobs_never_start)
{
    sched *s = sched_new();
    sched_add(s, 1, "alice", 0);
    sched_add(s, 2, "bob", 5);
    sched_add(s, 3, "alice", 5);
    sched_add(s, 4, "alice", -1);
    CHECK_INT(sched_remove(s, 3), 0);
    CHECK_INT(sched_remove(s, 3), -1);
    CHECK_INT(next(s, "bob"), 2);              /* priority 5 */
    CHECK_INT(next(s, "alice"), 1);            /* priority 0 */
    CHECK_INT(next(s, "alice"), 4);            /* priority -1 */
    CHECK_INT(sched_queued(s), 0);
    sched_free(s);
}

TEST_T(daemon_starts_second_users_job_before_first_users_third, 90)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "fair", NULL);
    mc_client *a = testdaemon_client(&d, TESTDAEMON_ALICE), *b = testdaemon_client(&d, TESTDAEMON_BOB);
    uint64_t ids[6], bid;
    int rc;
    /* alice's first job is long, so that bob's SUBMIT is stored while it
     * runs however slow the machine: the order is then the scheduler's */
    for (int i = 0; i < 6; i++) {
        ids[i] = testdaemon_submit(a, 150, i == 0, 0, &rc);
        CHECK_INT(rc, 0);
    }
    bid = testdaemon_submit(b, 3, 0, 0, &rc);
    CHECK_INT(rc, 0);
    CHECK_INT(testdaemon_wait_state(b, bid, -1, 60), MC_COMPLETED);
    mc_job_status bs, a3;
    CHECK_INT(mc_status(b, bid, &bs), 0);
    /* alice's third started (running, or on a loaded machine already done) */
    for (int i = 0; i < 60 * 50; i++) {
        CHECK_INT(mc_status(a, ids[2], &a3), 0);
        if (a3.state != MC_PENDING)
            break;
        usleep(20000);
    }
    CHECK(a3.state == MC_RUNNING || a3.state == MC_COMPLETED);
    CHECK(bs.start_ms > 0 && a3.start_ms > 0);
    if (!(bs.start_ms < a3.start_ms))
        FAILF("bob's job started at %lld, alice's third at %lld", (long long)bs.start_ms, (long long)a3.start_ms);
    mc_close(a);
    mc_close(b);
    testdaemon_stop(&d, SIGTERM);
}
