/* test_daemon_conns.c — the real meshcorrd under idle and greedy
 * connections: with its descriptor limit taken by 1100 idle Unix clients a
 * queued job still starts and completes, and a new client is told why it is
 * refused; each connection cap refuses with BUSY and a log line (the
 * oldest TCP connection without HELLO makes room for a newer one); silent,
 * half-sent and idle clients are cut after their timeouts with TIMED_OUT,
 * while a quiet WATCH is kept. Raw sockets speak the protocol where
 * libmeshcorr would not misbehave on purpose. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "proto.h"
#include "meshcorr.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A plain connection to the daemon's Unix socket; nothing sent. */
static int raw_unix(const testdaemon *d)
{
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    snprintf(sa.sun_path, sizeof sa.sun_path, "%s", d->unix_addr + strlen("unix:"));
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0)
        FAILF("connect %s: %s", sa.sun_path, strerror(errno));
    return fd;
}

static void raw_send(int fd, const void *p, size_t n)
{
    if (send(fd, p, n, MSG_NOSIGNAL) != (ssize_t)n)
        FAILF("send: %s", strerror(errno));
}

static void raw_send_msg(int fd, const proto_msg *m)
{
    proto_buf b;
    proto_buf_init(&b);
    char err[256];
    if (proto_msg_encode(&b, m, err, sizeof err))
        FAILF("encode: %s", err);
    raw_send(fd, b.data, b.len);
    proto_buf_free(&b);
}

/* n bytes within the deadline: 0, 1 at EOF, -1 at the deadline. */
static int raw_recv(int fd, uint8_t *p, size_t n, double deadline)
{
    while (n) {
        int ms = (int)((deadline - now_s()) * 1000);
        struct pollfd pf = {fd, POLLIN, 0};
        if (ms <= 0 || poll(&pf, 1, ms) <= 0)
            return -1;
        ssize_t r = recv(fd, p, n, 0);
        if (r <= 0)
            return 1;
        p += r;
        n -= (size_t)r;
    }
    return 0;
}

/* The next frame within timeout_s (fails the test otherwise); its payload
 * stays in *buf (free() it after the message). */
static void raw_read_msg(int fd, proto_msg *m, uint8_t **buf, double timeout_s)
{
    double deadline = now_s() + timeout_s;
    uint8_t hdr[PROTO_HDR_SIZE];
    int rc = raw_recv(fd, hdr, sizeof hdr, deadline);
    if (rc)
        FAILF("no frame within %.1f s (%s)", timeout_s, rc > 0 ? "EOF" : "nothing came");
    proto_hdr h;
    char err[512];
    if (proto_frame_scan(hdr, sizeof hdr, 1 << 20, &h, err, sizeof err) < 0)
        FAILF("reply header: %s", err);
    *buf = malloc(h.payload_len + 1);
    CHECK(*buf);
    if (raw_recv(fd, *buf, h.payload_len, deadline))
        FAILF("payload of %u bytes did not arrive", h.payload_len);
    if (proto_msg_decode(&h, *buf, m, err, sizeof err))
        FAILF("reply: %s", err);
}

/* The next frame is ERROR code, its message has what, then the server closes. */
static void expect_error_then_eof(int fd, int code, const char *what, double timeout_s)
{
    proto_msg m;
    uint8_t *buf;
    raw_read_msg(fd, &m, &buf, timeout_s);
    if (m.type != PROTO_MSG_ERROR)
        FAILF("got %s, expected ERROR %s", proto_type_name(m.type), proto_err_name(code));
    CHECK_INT(m.u.error.code, code);
    CHECK_STR_HAS(m.u.error.message, what);
    CHECK_INT(m.request_id, 0);
    proto_msg_free(&m);
    free(buf);
    uint8_t b;
    CHECK_INT(raw_recv(fd, &b, 1, now_s() + 5), 1);
}

/* HELLO over the Unix socket (peer credentials), HELLO_OK read. */
static void raw_hello(int fd)
{
    proto_msg m = {.type = PROTO_MSG_HELLO, .request_id = 1};
    m.u.hello = (proto_hello){PROTO_VERSION, "", "test_daemon_conns"};
    raw_send_msg(fd, &m);
    uint8_t *buf;
    raw_read_msg(fd, &m, &buf, 10);
    CHECK_INT(m.type, PROTO_MSG_HELLO_OK);
    proto_msg_free(&m);
    free(buf);
}

/* Nothing to read on fd for `seconds` (and the connection still open). */
static void expect_quiet(int fd, double seconds)
{
    struct pollfd pf = {fd, POLLIN, 0};
    int rc = poll(&pf, 1, (int)(seconds * 1000));
    if (rc != 0)
        FAILF("the server sent or closed within %.1f s (revents %#x)", seconds, (unsigned)pf.revents);
}

#define NIDLE 1100

/* The daemon's soft and hard descriptor limits are set to 256 under it
 * (prlimit); 1100 clients connect and stay idle, half of them after HELLO,
 * half without. Those the reserve leaves room for are accepted, the rest
 * get BUSY naming the descriptors; a job queued behind a running one then
 * starts a worker and completes, and the daemon exits 0. */
TEST_T(idle_connections_at_the_descriptor_limit_never_fail_a_queued_job, 180)
{
    testdaemon_need_worker();
    struct rlimit own;
    CHECK(getrlimit(RLIMIT_NOFILE, &own) == 0);
    if (own.rlim_max != RLIM_INFINITY && own.rlim_max < NIDLE + 64)
        SKIP("the test needs %d descriptors; the hard limit is %llu", NIDLE + 64, (unsigned long long)own.rlim_max);
    if (own.rlim_cur != RLIM_INFINITY && own.rlim_cur < NIDLE + 64) {
        own.rlim_cur = NIDLE + 64;
        CHECK(setrlimit(RLIMIT_NOFILE, &own) == 0);
    }
    static const char *const args[] = {"--workers", "1", "--max-connections", "100000",
                                       "--max-connections-per-user", "100000", "--max-unauthenticated", "100000",
                                       "--hello-timeout", "0", NULL};
    testdaemon d;
    testdaemon_start(&d, "fds", args);
    struct rlimit low = {256, 256};
    if (testdaemon_prlimit(&d, RLIMIT_NOFILE, &low, NULL) != 0)
        FAILF("prlimit: %s", strerror(errno));
    mc_client *c = testdaemon_client(&d, NULL);
    int rc;
    uint64_t running = testdaemon_submit(c, 100000, 1, 0, &rc);
    CHECK_INT(rc, 0);
    testdaemon_wait_state(c, running, MC_RUNNING, 30);
    uint64_t queued = testdaemon_submit(c, 3, 0, 0, &rc);
    CHECK_INT(rc, 0);

    static mc_client *idle[NIDLE / 2];
    static int raw[NIDLE / 2];
    int accepted = 0, busy = 0;
    char err[1024], busy_msg[1024] = "";
    for (int i = 0; i < NIDLE / 2; i++) {
        raw[i] = raw_unix(&d);
        idle[i] = NULL;
        rc = mc_connect(d.unix_addr, NULL, &idle[i], err, sizeof err);
        if (rc == 0) {
            accepted++;
            mc_set_timeout(idle[i], 20000);
        } else if (rc == MC_EBUSY) {
            busy++;
            snprintf(busy_msg, sizeof busy_msg, "%s", err);
        } else {
            FAILF("client %d: %s (%s)", i, mc_strerror(rc), err);
        }
    }
    printf("  daemon at 256 descriptors: %d of %d HELLO clients accepted, %d refused BUSY (and %d raw idle "
           "connections besides)\n", accepted, NIDLE / 2, busy, NIDLE / 2);
    CHECK(accepted > 0 && busy > 0);
    CHECK_STR_HAS(busy_msg, "BUSY");
    CHECK_STR_HAS(busy_msg, "--fd-reserve");
    mc_client *late = NULL;
    CHECK_INT(mc_connect(d.unix_addr, NULL, &late, err, sizeof err), MC_EBUSY);
    CHECK_STR_HAS(err, "file descriptor(s) left under RLIMIT_NOFILE");

    /* the queued job starts a worker now, with every client still there */
    CHECK_INT(mc_cancel(c, running), 0);
    int st = testdaemon_wait_state(c, queued, -1, 90);
    if (st != MC_COMPLETED) {
        mc_job_status s;
        mc_status(c, queued, &s);
        FAILF("the queued job ended %s: %s", mc_state_name(st), s.reason);
    }
    CHECK(testdaemon_log_has(&d, "refused: "));
    CHECK(testdaemon_log_has(&d, "kept for the workers (--fd-reserve)"));
    CHECK(!testdaemon_log_has(&d, "too many open files"));
    for (int i = 0; i < NIDLE / 2; i++) {
        mc_close(idle[i]);
        close(raw[i]);
    }
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* Connect until accepted (the daemon notices closed clients a moment later). */
static mc_client *connect_soon(const testdaemon *d, const char *addr, const char *token)
{
    char err[1024];
    for (int i = 0; i < 250; i++) {
        mc_client *c = NULL;
        int rc = mc_connect(addr, token, &c, err, sizeof err);
        if (rc == 0)
            return c;
        if (rc != MC_EBUSY)
            FAILF("mc_connect: %s (%s)", mc_strerror(rc), err);
        struct timespec ts = {0, 20000000};
        nanosleep(&ts, NULL);
    }
    FAILF("still BUSY after 5 s: %s; log %s", err, d->log);
    return NULL;
}

/* A plain TCP connection to the daemon's listener; nothing sent. */
static int raw_tcp(const testdaemon *d)
{
    struct sockaddr_in sa = {.sin_family = AF_INET};
    int port = atoi(strrchr(d->tcp_addr, ':') + 1);
    sa.sin_port = htons((uint16_t)port);
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0)
        FAILF("connect %s: %s", d->tcp_addr, strerror(errno));
    return fd;
}

/* The caps, each with its BUSY and log line: TCP connections without HELLO
 * (the oldest makes room for a newer one; the Unix socket is not counted),
 * sessions per user, non-admin sessions in all (admins exempt). */
TEST_T(each_connection_cap_refuses_with_busy_and_a_log_line, 60)
{
    static const char *const args[] = {"--max-connections", "3", "--max-connections-per-user", "2",
                                       "--max-unauthenticated", "2", "--hello-timeout", "0", NULL};
    testdaemon d;
    testdaemon_start(&d, "caps", args);
    char err[1024];
    mc_client *x = NULL;
    /* two silent TCP connections use up --max-unauthenticated: a third
     * closes the oldest, which reads ERROR BUSY (request id 0) and the close */
    int t1 = raw_tcp(&d), t2 = raw_tcp(&d);
    testdaemon_sleep_ms(100);
    int t3 = raw_tcp(&d);
    expect_error_then_eof(t1, PROTO_EBUSY, "2 TCP connections without HELLO, the limit (--max-unauthenticated)", 5);
    expect_quiet(t2, 0.3);
    mc_client *u = testdaemon_client(&d, NULL);          /* the Unix socket does not count */
    CHECK_INT(mc_ping(u), 0);
    mc_close(u);
    close(t1);
    close(t2);
    close(t3);

    /* two sessions per user */
    mc_client *a1 = connect_soon(&d, d.tcp_addr, TESTDAEMON_ALICE);
    mc_client *a2 = connect_soon(&d, d.tcp_addr, TESTDAEMON_ALICE);
    CHECK_INT(mc_connect(d.tcp_addr, TESTDAEMON_ALICE, &x, err, sizeof err), MC_EBUSY);
    CHECK(x == NULL);
    CHECK_STR_HAS(err, "user alice has 2 sessions, the limit (--max-connections-per-user)");
    /* three non-admin sessions in all: the next user is refused, admins are not */
    mc_client *b1 = connect_soon(&d, d.tcp_addr, TESTDAEMON_BOB);
    CHECK_INT(mc_connect(d.tcp_addr, TESTDAEMON_BOB, &x, err, sizeof err), MC_EBUSY);
    CHECK_STR_HAS(err, "3 sessions open, the limit (--max-connections; admins exempt)");
    mc_client *boss[2] = {connect_soon(&d, d.tcp_addr, TESTDAEMON_ADMIN), connect_soon(&d, d.tcp_addr, TESTDAEMON_ADMIN)};
    CHECK_INT(mc_ping(boss[1]), 0);
    CHECK_INT(mc_ping(a1), 0);      /* those in are served */
    CHECK_INT(mc_ping(b1), 0);
    CHECK(testdaemon_log_has(&d, "closed: 2 TCP connections without HELLO, the limit (--max-unauthenticated)"));
    CHECK(testdaemon_log_has(&d, "(user alice, 127.0.0.1) refused: server busy: user alice has 2 sessions"));
    CHECK(testdaemon_log_has(&d, "refused: server busy: 3 sessions open, the limit (--max-connections"));
    /* one leaves: the next one gets in */
    mc_close(a2);
    mc_client *b2 = connect_soon(&d, d.tcp_addr, TESTDAEMON_BOB);
    CHECK_INT(mc_ping(b2), 0);
    mc_close(a1);
    mc_close(b1);
    mc_close(b2);
    mc_close(boss[0]);
    mc_close(boss[1]);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(silent_half_sent_and_idle_clients_are_cut_after_their_timeouts_and_a_quiet_watch_is_kept, 90)
{
    testdaemon_need_worker();
    static const char *const args[] = {"--workers", "1", "--hello-timeout", "1", "--request-timeout", "1",
                                       "--idle-timeout", "2", NULL};
    testdaemon d;
    testdaemon_start(&d, "timeouts", args);
    /* a job pending behind a running one: its WATCH sends its place in the
     * queue, then nothing while the queue stands still */
    mc_client *c = testdaemon_client(&d, NULL);
    int rc;
    uint64_t running = testdaemon_submit(c, 100000, 1, 0, &rc);
    CHECK_INT(rc, 0);
    uint64_t pending = testdaemon_submit(c, 3, 0, 0, &rc);
    CHECK_INT(rc, 0);
    mc_close(c);
    double t0 = now_s();
    int silent = raw_unix(&d);
    int half_hdr = raw_unix(&d), half_payload = raw_unix(&d), idle = raw_unix(&d), watcher = raw_unix(&d);
    raw_hello(half_hdr);
    raw_hello(half_payload);
    raw_hello(idle);
    raw_hello(watcher);
    /* 10 of a PING's 20 header bytes; a STATUS header and 3 of its 8 payload bytes */
    uint8_t frame[PROTO_HDR_SIZE + 8] = {0};
    proto_hdr h = {PROTO_VERSION, PROTO_MSG_PING, 0, 2, 0};
    proto_frame_put_header(frame, &h);
    raw_send(half_hdr, frame, 10);
    h = (proto_hdr){PROTO_VERSION, PROTO_MSG_STATUS, 0, 3, 8};
    proto_frame_put_header(frame, &h);
    raw_send(half_payload, frame, PROTO_HDR_SIZE + 3);

    proto_msg w = {.type = PROTO_MSG_WATCH, .request_id = 9};
    w.u.watch = (proto_watch){pending, 0};
    raw_send_msg(watcher, &w);

    expect_error_then_eof(silent, PROTO_ETIMED_OUT, "no HELLO within 1 s (--hello-timeout)", 10);
    expect_error_then_eof(half_hdr, PROTO_ETIMED_OUT,
                          "request frame incomplete after 1 s, 10 header bytes (--request-timeout)", 10);
    expect_error_then_eof(half_payload, PROTO_ETIMED_OUT,
                          "request frame incomplete after 1 s, 23 of 28 bytes (--request-timeout)", 10);
    expect_error_then_eof(idle, PROTO_ETIMED_OUT, "idle for 2 s (--idle-timeout)", 10);
    double cut = now_s() - t0;
    CHECK(cut >= 1.9);
    /* the watcher outlives the idle timeout; ending the job ends its WATCH */
    proto_msg m;
    uint8_t *buf;
    raw_read_msg(watcher, &m, &buf, 10);
    CHECK_INT(m.type, PROTO_MSG_PROGRESS);
    CHECK_INT(m.u.progress.stage, PROTO_STAGE_QUEUED);
    CHECK_INT(m.u.progress.ahead, 0);
    proto_msg_free(&m);
    free(buf);
    expect_quiet(watcher, 2.5);
    c = testdaemon_client(&d, NULL);
    CHECK_INT(mc_cancel(c, pending), 0);
    raw_read_msg(watcher, &m, &buf, 10);
    CHECK_INT(m.type, PROTO_MSG_END);
    CHECK_INT(m.request_id, 9);
    proto_msg_free(&m);
    free(buf);
    CHECK(testdaemon_log_has(&d, "(-): no HELLO within 1 s (--hello-timeout): closing"));
    CHECK(testdaemon_log_has(&d, "request frame incomplete after 1 s"));
    CHECK(testdaemon_log_has(&d, "idle for 2 s (--idle-timeout): closing"));
    CHECK_INT(mc_cancel(c, running), 0);
    mc_close(c);
    close(silent);
    close(half_hdr);
    close(half_payload);
    close(idle);
    close(watcher);
    testdaemon_stop(&d, SIGTERM);
}

/* SUBMIT header announcing payload bytes, and the first `sent` of them. */
static void raw_partial_submit(int fd, uint32_t rid, uint32_t payload, size_t sent)
{
    static uint8_t frame[PROTO_HDR_SIZE + 4096];
    proto_hdr h = {PROTO_VERSION, PROTO_MSG_SUBMIT, 0, rid, payload};
    proto_frame_put_header(frame, &h);
    raw_send(fd, frame, PROTO_HDR_SIZE + sent);
}

/* Frames being received count against --max-request-memory across all
 * clients: a large SUBMIT that does not fit is refused BUSY naming the
 * limit (with its request id) and logged, while small requests go on; the
 * bytes of a client that leaves half-way are counted no more. */
TEST_T(request_frames_being_received_are_capped_in_all, 60)
{
    /* the total alone: one user's share (test_sec_upload) set to all of it */
    static const char *const args[] = {"--max-request-memory", "1000000", "--max-request-memory-per-user",
                                       "1000000", NULL};
    testdaemon d;
    testdaemon_start(&d, "reqmem", args);
    int a = raw_unix(&d), b = raw_unix(&d), e = raw_unix(&d);
    raw_hello(a);
    raw_hello(b);
    raw_hello(e);
    raw_partial_submit(a, 5, 600000, 1000);
    expect_quiet(a, 0.3);                       /* admitted: 600020 of 1000000 bytes */
    raw_partial_submit(b, 6, 600000, 1000);
    proto_msg m;
    uint8_t *buf;
    raw_read_msg(b, &m, &buf, 10);
    CHECK_INT(m.type, PROTO_MSG_ERROR);
    CHECK_INT(m.u.error.code, PROTO_EBUSY);
    CHECK_INT(m.request_id, 6);
    CHECK_STR_HAS(m.u.error.message, "600020 bytes of requests already");
    CHECK_STR_HAS(m.u.error.message, "max-request-memory 1000000");
    printf("  refused: %s\n", m.u.error.message);
    proto_msg_free(&m);
    free(buf);
    uint8_t byte;
    CHECK_INT(raw_recv(b, &byte, 1, now_s() + 5), 1);   /* EOF follows */
    CHECK(testdaemon_log_has(&d, "does not fit under max-request-memory 1000000"));
    /* small requests still pass, and a client's status is answered */
    mc_client *c = testdaemon_client(&d, NULL);
    mc_server_stats st;
    CHECK_INT(mc_stats(c, &st), 0);
    /* a leaves half-way: its bytes are free again for e */
    close(a);
    usleep(300 * 1000);
    raw_partial_submit(e, 7, 600000, 1000);
    expect_quiet(e, 0.5);                       /* admitted */
    mc_close(c);
    close(b);
    close(e);
    testdaemon_stop(&d, SIGTERM);
}
