/* test_client_null.c — libmeshcorr given no client: every call that takes an
 * mc_client refuses NULL with MC_EARG (a binding's closed client passes
 * NULL), the getters answer as for no user, the void calls do nothing, and
 * NULL out-pointers of a live client are refused too: never a crash. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "meshcorr.h"

#include <signal.h>
#include <string.h>

TEST(every_call_on_a_null_client_is_refused_with_MC_EARG)
{
    mc_job_spec spec;
    mc_job_spec_init(&spec);
    mc_job_status st;
    mc_job_info *jobs = NULL;
    uint32_t n = 7;
    mc_job_result res;
    mc_server_stats stats;
    uint64_t id = 0;
    int end = -1;
    char reason[64];
    CHECK_INT(mc_submit(NULL, &spec, &id), MC_EARG);
    CHECK_INT(mc_status(NULL, 1, &st), MC_EARG);
    CHECK_INT(mc_list(NULL, NULL, 0, &jobs, &n), MC_EARG);
    CHECK_INT(mc_watch(NULL, 1, 0, NULL, NULL, &end, reason, sizeof reason), MC_EARG);
    CHECK_INT(mc_result(NULL, 1, MC_WANT_P, &res), MC_EARG);
    CHECK_INT(mc_cancel(NULL, 1), MC_EARG);
    CHECK_INT(mc_delete(NULL, 1), MC_EARG);
    CHECK_INT(mc_stats(NULL, &stats), MC_EARG);
    CHECK_INT(mc_ping(NULL), MC_EARG);
    CHECK_INT(mc_send_raw(NULL, "x", 1), MC_EARG);
    CHECK_STR_HAS(mc_errmsg(NULL), "no client");
    CHECK_INT(strcmp(mc_user(NULL), ""), 0);
    CHECK_INT(mc_is_admin(NULL), 0);
    mc_set_timeout(NULL, 5);
    mc_interrupt(NULL);
    mc_close(NULL);
    mc_job_spec_init(NULL);
    CHECK_INT(mc_state_parse(NULL), -1);
    char err[128];
    CHECK_INT(mc_connect("unix:/nonexistent", NULL, NULL, err, sizeof err), MC_EARG);
    CHECK_STR_HAS(err, "out is NULL");
}

TEST(null_out_pointers_of_a_live_client_are_refused_naming_the_call)
{
    testdaemon d;
    testdaemon_start(&d, "null", NULL);
    mc_client *c = testdaemon_client(&d, NULL);
    mc_job_spec spec;
    mc_job_spec_init(&spec);
    CHECK_INT(mc_submit(c, &spec, NULL), MC_EARG);
    CHECK_STR_HAS(mc_errmsg(c), "mc_submit");
    CHECK_INT(mc_status(c, 1, NULL), MC_EARG);
    CHECK_STR_HAS(mc_errmsg(c), "mc_status");
    CHECK_INT(mc_list(c, NULL, 0, NULL, NULL), MC_EARG);
    CHECK_INT(mc_result(c, 1, MC_WANT_P, NULL), MC_EARG);
    CHECK_INT(mc_stats(c, NULL), MC_EARG);
    CHECK_INT(mc_send_raw(c, NULL, 4), MC_EARG);
    CHECK_INT(mc_ping(c), 0);                 /* the connection is still good */
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
