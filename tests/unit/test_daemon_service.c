/* test_daemon_service.c — meshcorrd as a service facing bad or greedy
 * clients: bad token, garbage bytes, an oversized frame header, other
 * users' jobs, admin visibility, QUEUE_FULL and USER_LIMIT refusals, and a
 * watcher that never reads. The daemon must answer, log, close that one
 * connection, and keep serving everyone else. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "proto.h"
#include "meshcorr.h"

#include <errno.h>
#include <signal.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

TEST_T(bad_token_is_unauthorized_and_good_ones_name_the_user, 30)
{
    testdaemon d;
    testdaemon_start(&d, "auth", NULL);
    mc_client *c = NULL;
    char err[512];
    CHECK_INT(mc_connect(d.tcp_addr, "not-a-token", &c, err, sizeof err), MC_EUNAUTHORIZED);
    CHECK(c == NULL);
    CHECK_STR_HAS(err, "UNAUTHORIZED");
    CHECK_INT(mc_connect(d.tcp_addr, "", &c, err, sizeof err), MC_EUNAUTHORIZED);
    c = testdaemon_client(&d, TESTDAEMON_BOB);
    CHECK(strcmp(mc_user(c), "bob") == 0);
    CHECK(!mc_is_admin(c));
    mc_close(c);
    c = testdaemon_client(&d, TESTDAEMON_ADMIN);
    CHECK(strcmp(mc_user(c), "boss") == 0);
    CHECK(mc_is_admin(c));
    CHECK_INT(mc_ping(c), 0);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(garbage_bytes_get_an_error_and_a_close_and_the_daemon_keeps_serving, 30)
{
    testdaemon d;
    testdaemon_start(&d, "garbage", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE), *other = testdaemon_client(&d, NULL);
    static const char http[] = "GET / HTTP/1.1\r\nHost: x\r\n\r\n";
    CHECK_INT(mc_send_raw(c, http, sizeof http - 1), -2);   /* BAD_MAGIC */
    CHECK_STR_HAS(mc_errmsg(c), "BAD_MAGIC");
    CHECK(mc_ping(c) != 0);                                  /* that connection is closed */
    CHECK_INT(mc_ping(other), 0);
    mc_close(c);
    /* a frame whose payload does not decode: ERROR, the connection stays */
    c = testdaemon_client(&d, TESTDAEMON_ALICE);
    proto_hdr h = {PROTO_VERSION, PROTO_MSG_STATUS, 0, 77, 3};
    uint8_t frame[PROTO_HDR_SIZE + 3] = {0};
    proto_frame_put_header(frame, &h);
    CHECK_INT(mc_send_raw(c, frame, sizeof frame), PROTO_ETRUNCATED);
    CHECK_INT(mc_ping(c), 0);
    mc_close(c);
    mc_close(other);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(oversized_frame_header_is_refused_before_its_payload_arrives, 30)
{
    testdaemon d;
    static const char *const args[] = {"--max-frame", "1048576", NULL};
    testdaemon_start(&d, "toolarge", args);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    /* claims 3.9 GiB; only the 20 header bytes are ever sent, and the
     * refusal comes back at once */
    proto_hdr h = {PROTO_VERSION, PROTO_MSG_SUBMIT, 0, 5, 0xF0000000u};
    uint8_t hdr[PROTO_HDR_SIZE];
    proto_frame_put_header(hdr, &h);
    CHECK_INT(mc_send_raw(c, hdr, sizeof hdr), PROTO_ETOO_LARGE);
    CHECK_STR_HAS(mc_errmsg(c), "TOO_LARGE");
    mc_close(c);
    c = testdaemon_client(&d, TESTDAEMON_ALICE);         /* the daemon is unaffected */
    CHECK_INT(mc_ping(c), 0);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(other_users_jobs_are_not_found_and_admin_sees_all, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "visibility", NULL);
    mc_client *a = testdaemon_client(&d, TESTDAEMON_ALICE), *b = testdaemon_client(&d, TESTDAEMON_BOB),
              *boss = testdaemon_client(&d, TESTDAEMON_ADMIN);
    int rc;
    uint64_t id = testdaemon_submit(a, 2, 0, 0, &rc);
    CHECK_INT(rc, 0);
    mc_job_status s;
    CHECK_INT(mc_status(b, id, &s), MC_ENOT_FOUND);
    CHECK_STR_HAS(mc_errmsg(b), "no job");
    CHECK_INT(mc_cancel(b, id), MC_ENOT_FOUND);
    CHECK_INT(mc_delete(b, id), MC_ENOT_FOUND);
    mc_job_result r;
    CHECK_INT(mc_result(b, id, MC_WANT_P, &r), MC_ENOT_FOUND);
    CHECK_INT(mc_watch(b, id, 0, NULL, NULL, NULL, NULL, 0), MC_ENOT_FOUND);
    CHECK_INT(mc_status(b, id + 1000, &s), MC_ENOT_FOUND);  /* same answer as for no job */
    mc_job_info *jobs;
    uint32_t n;
    CHECK_INT(mc_list(b, NULL, 0, &jobs, &n), 0);
    CHECK_INT(n, 0);
    free(jobs);
    CHECK_INT(mc_list(b, "alice", 0, &jobs, &n), MC_EFORBIDDEN);
    CHECK_INT(testdaemon_wait_state(boss, id, -1, 30), MC_COMPLETED);   /* admin: status of alice's job */
    CHECK_INT(mc_status(boss, id, &s), 0);
    CHECK(strcmp(s.user, "alice") == 0);
    CHECK_INT(mc_list(boss, "alice", 1u << MC_COMPLETED, &jobs, &n), 0);
    CHECK_INT(n, 1);
    CHECK_INT(jobs[0].job_id, id);
    CHECK_INT(jobs[0].outer, 2);
    free(jobs);
    CHECK_INT(mc_list(a, NULL, 1u << MC_PENDING, &jobs, &n), 0);   /* state filter */
    CHECK_INT(n, 0);
    free(jobs);
    mc_server_stats st;
    CHECK_INT(mc_stats(boss, &st), 0);
    CHECK_INT(st.workers, 1);
    CHECK_INT(st.completed, 1);
    CHECK_INT(st.nslots, 1);
    mc_stats_free(&st);
    mc_close(a);
    mc_close(b);
    mc_close(boss);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(full_queue_and_user_limit_refuse_with_messages_and_store_nothing, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    static const char *const args[] = {"--max-queue", "3", "--max-jobs-per-user", "2", NULL};
    testdaemon_start(&d, "limits", args);
    mc_client *a = testdaemon_client(&d, TESTDAEMON_ALICE), *b = testdaemon_client(&d, TESTDAEMON_BOB),
              *boss = testdaemon_client(&d, TESTDAEMON_ADMIN);
    int rc;
    uint64_t run = testdaemon_submit(a, 1000, 1, 0, &rc);   /* runs on the one slot */
    CHECK_INT(rc, 0);
    testdaemon_wait_state(a, run, MC_RUNNING, 10);
    testdaemon_submit(a, 3, 0, 0, &rc);                      /* alice: 2 unfinished */
    CHECK_INT(rc, 0);
    testdaemon_submit(a, 3, 0, 0, &rc);
    CHECK_INT(rc, MC_EUSER_LIMIT);
    CHECK_STR_HAS(mc_errmsg(a), "2 unfinished jobs (limit 2)");
    testdaemon_submit(b, 3, 0, 0, &rc);                      /* pending: 3 = the queue's length */
    CHECK_INT(rc, 0);
    testdaemon_submit(b, 3, 0, 0, &rc);
    CHECK_INT(rc, 0);
    testdaemon_submit(boss, 3, 0, 0, &rc);
    CHECK_INT(rc, MC_EQUEUE_FULL);
    CHECK_STR_HAS(mc_errmsg(boss), "queue full");
    mc_job_info *jobs;
    uint32_t n;
    CHECK_INT(mc_list(boss, "boss", 0, &jobs, &n), 0);
    CHECK_INT(n, 0);                                        /* the refused job was not stored */
    free(jobs);
    CHECK_INT(mc_cancel(a, run), 0);
    mc_close(a);
    mc_close(b);
    mc_close(boss);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(watcher_that_never_reads_is_dropped_while_others_are_served, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    static const char *const args[] = {"--max-output", "4096", NULL};
    testdaemon_start(&d, "slow", args);
    mc_client *c = testdaemon_client(&d, NULL);
    int rc;
    uint64_t id = testdaemon_submit(c, 3, 0, 0, &rc);
    CHECK_INT(rc, 0);
    CHECK_INT(testdaemon_wait_state(c, id, -1, 30), MC_COMPLETED);

    /* a raw connection: HELLO, then WATCH after WATCH, never reading */
    int fd = socket(AF_UNIX, SOCK_STREAM, 0);
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    CHECK(strlen(d.unix_addr + 5) < sizeof sa.sun_path);
    memcpy(sa.sun_path, d.unix_addr + 5, strlen(d.unix_addr + 5) + 1);
    CHECK_INT(connect(fd, (struct sockaddr *)&sa, sizeof sa), 0);
    proto_buf b;
    proto_buf_init(&b);
    proto_msg m;
    memset(&m, 0, sizeof m);
    m.type = PROTO_MSG_HELLO;
    m.u.hello = (proto_hello){PROTO_VERSION, "", "slow test client"};
    CHECK_INT(proto_msg_encode(&b, &m, NULL, 0), 0);
    memset(&m, 0, sizeof m);
    m.type = PROTO_MSG_WATCH;
    m.u.watch = (proto_watch){id, 0};
    for (int i = 0; i < 20000; i++) {
        m.request_id = (uint32_t)i + 1;
        CHECK_INT(proto_msg_encode(&b, &m, NULL, 0), 0);
    }
    size_t sent = 0;
    while (sent < b.len) {
        ssize_t w = send(fd, b.data + sent, b.len - sent, MSG_NOSIGNAL);
        if (w <= 0)
            break;                     /* the daemon closed it */
        sent += (size_t)w;
    }
    proto_buf_free(&b);
    /* meanwhile, others are served */
    mc_client *other = testdaemon_client(&d, TESTDAEMON_BOB);
    CHECK_INT(mc_ping(other), 0);
    CHECK_INT(mc_ping(c), 0);
    /* now read what the daemon had sent before dropping us: it ends in EOF,
     * well before the replies to 20000 WATCHes (each at least 4 frames) */
    size_t got = 0;
    char buf[65536];
    ssize_t r;
    while ((r = recv(fd, buf, sizeof buf, 0)) > 0)
        got += (size_t)r;
    CHECK(r == 0 || errno == ECONNRESET);
    CHECK(got < 20000u * 4 * 149);
    close(fd);
    CHECK_INT(mc_ping(other), 0);
    mc_close(other);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
