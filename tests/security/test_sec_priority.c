/* test_sec_priority.c — the priority a user states cannot jump the fair
 * share: a user's SUBMIT with a priority above 0 (2147483647, the top) is
 * refused FORBIDDEN naming the field and who may raise it, and logged;
 * nothing is stored; users may lower their priority, and an admin may
 * raise it. Real daemon, real client library. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "meshcorr.h"

#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

TEST_T(a_user_cannot_raise_a_jobs_priority_but_may_lower_it_and_an_admin_may_raise_it, 120)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "prio", NULL);
    mc_client *alice = testdaemon_client(&d, TESTDAEMON_ALICE), *boss = testdaemon_client(&d, TESTDAEMON_ADMIN);
    int rc;
    uint64_t id = testdaemon_submit(alice, 2, 0, INT32_MAX, &rc);
    if (rc != MC_EFORBIDDEN)
        FAILF("alice's SUBMIT at priority %d: %s (%s), job %llu: the top priority was taken", INT32_MAX,
              mc_strerror(rc), rc ? mc_errmsg(alice) : "accepted", (unsigned long long)id);
    CHECK_STR_HAS(mc_errmsg(alice), "priority = 2147483647");
    CHECK_STR_HAS(mc_errmsg(alice), "alice");
    CHECK_STR_HAS(mc_errmsg(alice), "only an admin may raise it");
    CHECK(testdaemon_log_has(&d, "SUBMIT from alice refused (FORBIDDEN): priority 2147483647"));
    testdaemon_submit(alice, 2, 0, 1, &rc);
    CHECK_INT(rc, MC_EFORBIDDEN);
    mc_job_info *jobs = NULL;
    uint32_t n = 9;
    CHECK_INT(mc_list(alice, NULL, 0, &jobs, &n), 0);
    CHECK_INT(n, 0);                                   /* nothing stored */
    free(jobs);
    /* lowering is every user's right; raising an admin's */
    uint64_t low = testdaemon_submit_ok(alice, 2, 0, -7);
    uint64_t top = testdaemon_submit_ok(boss, 2, 0, INT32_MAX);
    mc_job_status s;
    CHECK_INT(mc_status(alice, low, &s), 0);
    CHECK_INT(s.priority, -7);
    CHECK_INT(mc_status(boss, top, &s), 0);
    CHECK_INT(s.priority, INT32_MAX);
    CHECK_INT(testdaemon_wait_state(alice, low, -1, 60), MC_COMPLETED);
    CHECK_INT(testdaemon_wait_state(boss, top, -1, 60), MC_COMPLETED);
    mc_close(alice);
    mc_close(boss);
    testdaemon_stop(&d, SIGTERM);
}
