/* test_sec_watch.c — one session cannot make the loop's fan-out or the
 * RESULT replies cost without bound: the 65th live WATCH on a connection
 * (--max-watches-per-session, default 64) is refused OVER_LIMIT naming the
 * option, logged, and the connection stays usable; and 32 RESULTs of one
 * user's sessions that never read their replies hold at most the user's
 * share (--max-result-sends-per-user, default 4) of replies in the
 * daemon: the others wait unread, the daemon's memory grows by a few
 * results, not by 32, bob's RESULT goes on, and every one comes once read.
 * Real daemon, raw frames for what libmeshcorr would not do. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testsec.h"
#include "support/testwire.h"
#include "meshcorr.h"

#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define NWATCH 64      /* the default --max-watches-per-session */

static void send_watch(int fd, uint32_t rid, uint64_t job, uint32_t from_outer)
{
    proto_msg m = {.type = PROTO_MSG_WATCH, .request_id = rid};
    m.u.watch = (proto_watch){job, from_outer};
    testwire_send_msg(fd, &m);
}

TEST_T(the_watches_of_one_session_are_capped_and_the_session_stays_usable, 120)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "watch", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t job = testdaemon_submit_ok(c, 100000, 1, 0);
    testdaemon_wait_state(c, job, MC_RUNNING, 30);
    /* WATCHes that want no history and no record (from_outer past every
     * one) cost the session nothing to read, only the daemon its fan-out */
    int fd = testwire_session(&d, TESTDAEMON_ALICE);
    for (uint32_t i = 0; i < NWATCH + 5; i++)
        send_watch(fd, 10 + i, job, UINT32_MAX);
    for (uint32_t i = NWATCH; i < NWATCH + 5; i++)
        testwire_expect_error(fd, 10 + i, PROTO_EOVER_LIMIT, "--max-watches-per-session 64", 10);
    CHECK(testdaemon_log_has(&d, "WATCH from alice refused (OVER_LIMIT): 64 live WATCHes on its connection"));
    /* still usable, and another session may watch */
    proto_msg m = {.type = PROTO_MSG_PING, .request_id = 99};
    testwire_send_msg(fd, &m);
    uint8_t *buf;
    testwire_read_msg(fd, &m, &buf, 1 << 20, 10);
    CHECK_INT(m.type, PROTO_MSG_PONG);
    CHECK_INT(m.request_id, 99);
    proto_msg_free(&m);
    free(buf);
    int other = testwire_session(&d, TESTDAEMON_ALICE);
    send_watch(other, 5, job, UINT32_MAX);
    /* the job's end reaches every live WATCH: 64 ENDs, then the other's */
    CHECK_INT(mc_cancel(c, job), 0);
    int ends = 0;
    while (ends < NWATCH) {
        testwire_read_msg(fd, &m, &buf, 1 << 20, 30);
        CHECK_INT(m.type, PROTO_MSG_END);
        CHECK(m.request_id >= 10 && m.request_id < 10 + NWATCH);
        ends++;
        proto_msg_free(&m);
        free(buf);
    }
    testwire_read_msg(other, &m, &buf, 1 << 20, 30);
    CHECK_INT(m.type, PROTO_MSG_END);
    CHECK_INT(m.request_id, 5);
    proto_msg_free(&m);
    free(buf);
    close(fd);
    close(other);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

#define NRESULT 32
#define SHARE 4        /* the default --max-result-sends-per-user */

/* 1 when fd has bytes to read now. */
static int readable(int fd)
{
    struct pollfd p = {fd, POLLIN, 0};
    return poll(&p, 1, 0) > 0;
}

TEST_T(unread_results_of_one_user_hold_at_most_her_share_and_others_go_on, 300)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "results", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    int rc;
    uint64_t job = testsec_submit_sphere(c, 6, MC_STAGES_RHM, 1, &rc);
    CHECK_INT(rc, 0);
    CHECK_INT(testdaemon_wait_state(c, job, -1, 240), MC_COMPLETED);
    /* one RESULT read whole first: its size, and the daemon's memory after it */
    mc_job_result r;
    CHECK_INT(mc_result(c, job, MC_WANT_P | MC_WANT_Q | MC_WANT_DEFORMED | MC_WANT_METRICS, &r), 0);
    mc_result_free(&r);
    long long size = testsec_spool_bytes(&d, job) - (long long)(2 * testsec_sphere_bytes(6));
    long long rss0 = testsec_daemon_rss(&d);
    /* NRESULT sessions of one user ask for everything and read nothing: on
     * the Unix socket (user root), whose small socket buffers leave a
     * reply of megabytes in the daemon until it is read */
    static int fds[NRESULT];
    for (int i = 0; i < NRESULT; i++) {
        fds[i] = testwire_session(&d, NULL);
        proto_msg m = {.type = PROTO_MSG_RESULT, .request_id = 1000 + (uint32_t)i};
        m.u.result = (proto_result){job, PROTO_WANT_P | PROTO_WANT_Q | PROTO_WANT_DEFORMED | PROTO_WANT_METRICS};
        testwire_send_msg(fds[i], &m);
    }
    testdaemon_sleep_ms(3000);
    int answered = 0;
    for (int i = 0; i < NRESULT; i++)
        answered += readable(fds[i]);
    long long grown = testsec_daemon_rss(&d) - rss0;
    printf("  result of %lld bytes; %d RESULTs of root unread: %d being answered, the daemon grew %.1f MB"
           " (%.1f results)\n",
           size, NRESULT, answered, grown / 1e6, (double)grown / (double)size);
    if (answered > SHARE)
        FAILF("%d of root's unread RESULTs are being answered at once (a user's share is %d)", answered, SHARE);
    CHECK_INT(answered, SHARE);
    CHECK(grown < (long long)(3 * SHARE) * size);
    CHECK(testdaemon_log_has(&d, "RESULT for root waits: 4 RESULT(s) of root"));
    /* bob's RESULTs are not behind those (he has a share of his own) */
    mc_client *b = testdaemon_client(&d, TESTDAEMON_BOB);
    uint64_t bjob = testdaemon_submit_ok(b, 2, 0, 0);
    CHECK_INT(testdaemon_wait_state(b, bjob, -1, 60), MC_COMPLETED);
    CHECK_INT(mc_result(b, bjob, MC_WANT_P, &r), 0);
    CHECK_INT(r.np, 162);
    mc_result_free(&r);
    mc_close(b);
    /* once they are read, every RESULT comes, whole, a share at a time */
    int done = 0;
    static int got[NRESULT];
    while (done < NRESULT) {
        struct pollfd p[NRESULT];
        int n = 0, idx[NRESULT];
        for (int i = 0; i < NRESULT; i++)
            if (!got[i]) {
                p[n] = (struct pollfd){fds[i], POLLIN, 0};
                idx[n++] = i;
            }
        if (poll(p, (nfds_t)n, 60000) <= 0)
            FAILF("%d of %d RESULTs never came", NRESULT - done, NRESULT);
        for (int k = 0; k < n; k++)
            if (p[k].revents) {
                proto_msg m;
                uint8_t *buf;
                testwire_read_msg(fds[idx[k]], &m, &buf, 1u << 30, 60);
                CHECK_INT(m.type, PROTO_MSG_RESULT_OK);
                CHECK_INT(m.request_id, 1000 + idx[k]);
                CHECK_INT(m.u.result_ok.p.n, 40962);
                proto_msg_free(&m);
                free(buf);
                got[idx[k]] = 1;
                done++;
            }
    }
    for (int i = 0; i < NRESULT; i++)
        close(fds[i]);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
