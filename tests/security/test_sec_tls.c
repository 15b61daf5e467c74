/* test_sec_tls.c — attacks on the transport of a real meshcorrd with a tls:
 * listener (certificates made by certtool for the test, testtls.h), each of
 * which would work against a daemon speaking the protocol in clear. A
 * client trusting the test CA runs a job through to its result over TLS (a
 * reply over --max-output pauses the connection, which then goes on), while
 * a client trusting another CA, or expecting another host name, gets
 * MC_ETLS and never sends its token; a plaintext client gets no HELLO_OK,
 * only a logged close; a TLS 1.0 or 1.1 client and a renegotiation are
 * refused; a watcher over TLS that never reads is dropped at --max-output
 * while others are served; a handshake never finished is cut by
 * --hello-timeout and counts against --max-unauthenticated; a plain tcp:
 * listener on a non-loopback address needs --insecure-tcp; bad certificate
 * or key files stop the start naming the file; /metrics is HTTPS with the
 * same certificate; SIGHUP serves a renewed certificate to new connections
 * and keeps the running one when the new files are bad; the CLI's --ca and
 * Python's Client(ca=...) verify the same way. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testhttp.h"
#include "support/testrun.h"
#include "support/testtls.h"
#include "proto.h"
#include "meshcorr.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <gnutls/gnutls.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define DAEMON "build/meshcorrd"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Starts d with a tls: listener on t's certificate, plus extra options. */
static void start_tls_daemon(testdaemon *d, const char *name, const testtls *t, const char *const *extra)
{
    const char *args[40];
    int k = 0;
    testtls_daemon_args(t, args, &k);
    for (int i = 0; extra && extra[i] && k < 39; i++)
        args[k++] = extra[i];
    args[k] = NULL;
    testdaemon_start(d, name, args);
    if (strncmp(d->tls_addr, "tls:127.0.0.1:", 14) != 0)
        FAILF("the port file names no tls: listener (got '%s'); log %s", d->tls_addr, d->log);
}

static int port_of(const char *addr)
{
    return atoi(strrchr(addr, ':') + 1);
}

/* "tls:HOST:PORT" of d's tls: listener. */
static const char *tls_at(const testdaemon *d, const char *host, char *buf, size_t sz)
{
    snprintf(buf, sz, "tls:%s:%d", host, port_of(d->tls_addr));
    return buf;
}

static int tcp_connect(int port)
{
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || connect(fd, (struct sockaddr *)&a, sizeof a) != 0)
        FAILF("connect 127.0.0.1:%d: %s", port, strerror(errno));
    return fd;
}

/* Everything the server sends on fd until it closes, at most timeout_s:
 * the byte count (into buf, at most sz), or -1 when it did not close. */
static long read_to_eof(int fd, uint8_t *buf, size_t sz, double timeout_s)
{
    double deadline = now_s() + timeout_s;
    size_t n = 0;
    for (;;) {
        int ms = (int)((deadline - now_s()) * 1000);
        struct pollfd p = {fd, POLLIN, 0};
        if (ms <= 0 || poll(&p, 1, ms) <= 0)
            return -1;
        uint8_t sink[4096];
        ssize_t r = recv(fd, n < sz ? buf + n : sink, n < sz ? sz - n : sizeof sink, 0);
        if (r <= 0)
            return (long)n;
        if (n < sz)
            n += (size_t)r;
    }
}

/* A connection that says HELLO with alice's token, in clear. */
static int plaintext_hello(int port)
{
    int fd = tcp_connect(port);
    proto_msg m = {.type = PROTO_MSG_HELLO, .request_id = 1};
    m.u.hello = (proto_hello){PROTO_VERSION, TESTDAEMON_ALICE, "test_sec_tls plaintext"};
    proto_buf b;
    proto_buf_init(&b);
    char err[256];
    if (proto_msg_encode(&b, &m, err, sizeof err))
        FAILF("encode: %s", err);
    CHECK(send(fd, b.data, b.len, MSG_NOSIGNAL) == (ssize_t)b.len);
    proto_buf_free(&b);
    return fd;
}

/* A GnuTLS client of the test's own (blocking socket). */
typedef struct dial {
    gnutls_session_t s;
    gnutls_certificate_credentials_t cred;
    int fd;
} dial;

/* A new connection to 127.0.0.1:port with the given priority, trusting ca
 * for host: the handshake's result (0 done, or GnuTLS's error). */
static int tls_dial(dial *t, int port, const char *prio, const char *ca, const char *host)
{
    CHECK(gnutls_certificate_allocate_credentials(&t->cred) == 0);
    CHECK(gnutls_certificate_set_x509_trust_file(t->cred, ca, GNUTLS_X509_FMT_PEM) > 0);
    CHECK(gnutls_init(&t->s, GNUTLS_CLIENT | GNUTLS_NO_SIGNAL) == 0);   /* a closed peer is an error, not SIGPIPE */
    const char *errpos = NULL;
    if (gnutls_priority_set_direct(t->s, prio, &errpos) != 0)
        FAILF("priority %s refused at '%s'", prio, errpos ? errpos : "?");
    CHECK(gnutls_credentials_set(t->s, GNUTLS_CRD_CERTIFICATE, t->cred) == 0);
    gnutls_session_set_verify_cert(t->s, host, 0);
    gnutls_server_name_set(t->s, GNUTLS_NAME_DNS, host, strlen(host));
    t->fd = tcp_connect(port);
    gnutls_transport_set_int(t->s, t->fd);
    gnutls_handshake_set_timeout(t->s, 10000);
    int rc;
    do
        rc = gnutls_handshake(t->s);
    while (rc < 0 && !gnutls_error_is_fatal(rc));
    return rc;
}

static void tls_hangup(dial *t)
{
    gnutls_deinit(t->s);
    gnutls_certificate_free_credentials(t->cred);
    close(t->fd);
}

/* mc_connect_ca must fail with MC_ETLS, its message holding what. */
static void expect_tls_refusal(const char *addr, const char *ca, const char *what)
{
    mc_client *c = NULL;
    char err[1200];
    int rc = mc_connect_ca(addr, TESTDAEMON_ALICE, ca, &c, err, sizeof err);
    if (rc != MC_ETLS)
        FAILF("mc_connect_ca(%s, ca %s): %s (%s), expected MC_ETLS", addr, ca ? ca : "(none)", mc_err_name(rc),
              rc ? err : "connected");
    CHECK(c == NULL);
    CHECK_STR_HAS(err, what);
}

static mc_client *tls_client(const char *addr, const char *ca)
{
    mc_client *c = NULL;
    char err[1200];
    int rc = mc_connect_ca(addr, TESTDAEMON_ALICE, ca, &c, err, sizeof err);
    if (rc)
        FAILF("mc_connect_ca(%s, ca %s): %s (%s)", addr, ca, mc_err_name(rc), err);
    mc_set_timeout(c, 20000);
    return c;
}

/* Waits up to 10 s for a log line holding what. */
static void wait_log(const testdaemon *d, const char *what)
{
    for (int i = 0; i < 500; i++) {
        if (testdaemon_log_has(d, what))
            return;
        testdaemon_sleep_ms(20);
    }
    FAILF("no log line '%s' within 10 s; log %s", what, d->log);
}

TEST_T(a_client_trusting_the_test_ca_runs_a_job_to_its_result_over_tls, 180)
{
    testdaemon_need_worker();
    testtls t;
    testtls_make(&t, "certs");
    testdaemon d;
    /* the RESULT (2 x 162 rows of 28 bytes) is over --max-output: the
     * connection stops reading until it is written, then goes on */
    const char *extra[] = {"--max-output", "4096", NULL};
    start_tls_daemon(&d, "tls-job", &t, extra);
    char addr[128];
    unsetenv("MESHCORR_CA");
    mc_client *c = tls_client(tls_at(&d, "localhost", addr, sizeof addr), t.ca);
    CHECK(strcmp(mc_user(c), "alice") == 0);
    uint64_t id = testdaemon_submit_ok(c, 2, 0, 0);
    CHECK_INT(testdaemon_wait_state(c, id, -1, 120), MC_COMPLETED);
    mc_job_result r;
    CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q, &r), 0);
    CHECK_INT(r.np, 162);                      /* one row per source vertex, through TLS records */
    CHECK_INT(r.nq, 162);
    for (uint32_t i = 0; i < r.np; i++)
        CHECK_NEAR(r.p[i].w[0] + r.p[i].w[1] + r.p[i].w[2], 1.0, 1e-9);
    mc_result_free(&r);
    CHECK_INT(mc_ping(c), 0);
    mc_close(c);
    /* the CA from the environment, as the CLI and Python get it */
    setenv("MESHCORR_CA", t.ca, 1);
    mc_client *e = NULL;
    char err[1200];
    if (mc_connect(addr, TESTDAEMON_BOB, &e, err, sizeof err))
        FAILF("mc_connect with MESHCORR_CA: %s", err);
    CHECK_INT(mc_ping(e), 0);
    mc_close(e);
    unsetenv("MESHCORR_CA");
    CHECK(testdaemon_log_has(&d, "TLS handshake done: TLS1.3"));
    testdaemon_stop(&d, SIGTERM);
}

/* A frame through a test client's session: 0, or -1 when the session
 * ended before all of it went. */
static int tls_send_msg(dial *t, proto_msg *m)
{
    proto_buf b;
    proto_buf_init(&b);
    char err[256];
    if (proto_msg_encode(&b, m, err, sizeof err))
        FAILF("encode: %s", err);
    size_t sent = 0;
    while (sent < b.len) {
        ssize_t w = gnutls_record_send(t->s, b.data + sent, b.len - sent);
        if (w <= 0)
            break;
        sent += (size_t)w;
    }
    size_t len = b.len;
    proto_buf_free(&b);
    return sent == len ? 0 : -1;
}

TEST_T(a_watcher_over_tls_that_never_reads_is_dropped_while_others_are_served, 90)
{
    testdaemon_need_worker();
    testtls t;
    testtls_make(&t, "certs");
    testdaemon d;
    const char *extra[] = {"--max-output", "4096", NULL};
    start_tls_daemon(&d, "tls-slow-watcher", &t, extra);
    char addr[128];
    mc_client *c = tls_client(tls_at(&d, "localhost", addr, sizeof addr), t.ca);
    uint64_t id = testdaemon_submit_ok(c, 3, 0, 0);
    CHECK_INT(testdaemon_wait_state(c, id, -1, 60), MC_COMPLETED);
    /* alice again on a session of the test's own: HELLO, then WATCH after
     * WATCH of her job, never reading */
    dial w;
    CHECK_INT(tls_dial(&w, port_of(d.tls_addr), "NORMAL", t.ca, "localhost"), 0);
    proto_msg m = {.type = PROTO_MSG_HELLO, .request_id = 1};
    m.u.hello = (proto_hello){PROTO_VERSION, TESTDAEMON_ALICE, "slow TLS watcher"};
    CHECK_INT(tls_send_msg(&w, &m), 0);
    memset(&m, 0, sizeof m);
    m.type = PROTO_MSG_WATCH;
    m.u.watch = (proto_watch){id, 0};
    int i;
    for (i = 0; i < 20000; i++) {
        m.request_id = (uint32_t)i + 2;
        if (tls_send_msg(&w, &m))
            break;                     /* the daemon closed it */
    }
    /* meanwhile, others are served */
    CHECK_INT(mc_ping(c), 0);
    mc_client *other = tls_client(addr, t.ca);
    CHECK_INT(mc_ping(other), 0);
    /* what the daemon had sent before dropping it ends, well before the
     * replies to 20000 WATCHes (each at least 4 frames) */
    size_t got = 0;
    char buf[65536];
    ssize_t r;
    while ((r = gnutls_record_recv(w.s, buf, sizeof buf)) > 0)
        got += (size_t)r;
    CHECK(got < 20000u * 4 * 149);
    tls_hangup(&w);
    wait_log(&d, "unread by a watcher, over --max-output 4096: dropped");
    CHECK_INT(mc_ping(other), 0);
    mc_close(other);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST(a_client_trusting_another_ca_gets_the_tls_error_and_sends_no_token)
{
    testtls t;
    testtls_make(&t, "certs");
    testdaemon d;
    start_tls_daemon(&d, "tls-wrong-ca", &t, NULL);
    char addr[128];
    tls_at(&d, "localhost", addr, sizeof addr);
    unsetenv("MESHCORR_CA");
    expect_tls_refusal(addr, t.other_ca, "not trusted");
    expect_tls_refusal(addr, t.other_ca, "give its CA with --ca or MESHCORR_CA");
    /* no CA given: the system's trust store does not hold the test CA */
    expect_tls_refusal(addr, NULL, "not trusted");
    setenv("MESHCORR_CA", t.other_ca, 1);
    expect_tls_refusal(addr, NULL, "not trusted");
    unsetenv("MESHCORR_CA");
    /* the handshake stopped before any frame: the daemon saw no HELLO */
    CHECK(!testdaemon_log_has(&d, "user alice"));
    CHECK(!testdaemon_log_has(&d, ": HELLO (request"));
    testdaemon_stop(&d, SIGTERM);
}

TEST(a_client_expecting_another_host_name_gets_the_tls_error)
{
    testtls t;
    testtls_make(&t, "certs");
    testdaemon d;
    start_tls_daemon(&d, "tls-wrong-host", &t, NULL);
    char addr[128];
    /* the right address, but the certificate names localhost, not 127.0.0.1 */
    expect_tls_refusal(tls_at(&d, "127.0.0.1", addr, sizeof addr), t.ca, "does not name the host 127.0.0.1");
    /* a CA file that is not there is named */
    expect_tls_refusal(tls_at(&d, "localhost", addr, sizeof addr), "/nonexistent/ca.pem", "/nonexistent/ca.pem");
    testdaemon_stop(&d, SIGTERM);
}

TEST(a_plaintext_client_on_the_tls_port_gets_no_session_and_no_hello_ok)
{
    testtls t;
    testtls_make(&t, "certs");
    testdaemon d;
    start_tls_daemon(&d, "tls-plaintext", &t, NULL);
    int fd = plaintext_hello(port_of(d.tls_addr));
    uint8_t got[4096];
    long n = read_to_eof(fd, got, sizeof got, 10);
    close(fd);
    if (n < 0)
        FAILF("the daemon kept a plaintext client's connection open for 10 s");
    /* at most a TLS alert record came back: never a frame of the protocol */
    CHECK(n < 20 || memcmp(got, "MCRP", 4) != 0);
    CHECK(n == 0 || got[0] == 0x15);           /* 0x15: a TLS alert record */
    wait_log(&d, "TLS handshake failed");
    CHECK(testdaemon_log_has(&d, "(tls 127.0.0.1:"));
    CHECK(testdaemon_log_has(&d, "a plaintext client?"));
    CHECK(!testdaemon_log_has(&d, "user alice"));
    CHECK(!testdaemon_log_has(&d, ": HELLO (request"));
    /* libmeshcorr speaking tcp: to the tls: port fails too, with no session */
    mc_client *c = NULL;
    char err[1200], addr[128];
    snprintf(addr, sizeof addr, "tcp:127.0.0.1:%d", port_of(d.tls_addr));
    CHECK(mc_connect(addr, TESTDAEMON_ALICE, &c, err, sizeof err) != 0);
    /* and tls: to the plain tcp: port is a TLS error, not a session in clear */
    snprintf(addr, sizeof addr, "tls:localhost:%d", port_of(d.tcp_addr));
    expect_tls_refusal(addr, t.ca, "TLS");
    testdaemon_stop(&d, SIGTERM);
}

TEST(a_tls_1_0_or_1_1_client_is_refused_while_1_2_and_1_3_are_served)
{
    testtls t;
    testtls_make(&t, "certs");
    testdaemon d;
    start_tls_daemon(&d, "tls-downgrade", &t, NULL);
    int port = port_of(d.tls_addr);
    dial t1;
    static const char *const old[] = {"NORMAL:-VERS-ALL:+VERS-TLS1.0", "NORMAL:-VERS-ALL:+VERS-TLS1.1"};
    for (int i = 0; i < 2; i++) {
        int before = testdaemon_log_count(&d, "TLS handshake failed");
        int rc = tls_dial(&t1, port, old[i], t.ca, "localhost");
        if (rc == 0)
            FAILF("%s: the daemon completed the handshake", old[i]);
        /* the daemon itself refused the version (the client could offer it) */
        if (rc != GNUTLS_E_FATAL_ALERT_RECEIVED || gnutls_alert_get(t1.s) != GNUTLS_A_PROTOCOL_VERSION)
            FAILF("%s: handshake ended with %s (alert %s), not the server's protocol_version alert", old[i],
                  gnutls_strerror(rc), gnutls_alert_get_name(gnutls_alert_get(t1.s)));
        tls_hangup(&t1);
        for (int k = 0; k < 100 && testdaemon_log_count(&d, "TLS handshake failed") == before; k++)
            testdaemon_sleep_ms(20);
        CHECK(testdaemon_log_count(&d, "TLS handshake failed") > before);
    }
    /* the same client code with a version the daemon takes gets through */
    static const char *const good[] = {"NORMAL:-VERS-ALL:+VERS-TLS1.2", "NORMAL:-VERS-ALL:+VERS-TLS1.3"};
    for (int i = 0; i < 2; i++) {
        int rc = tls_dial(&t1, port, good[i], t.ca, "localhost");
        if (rc != 0)
            FAILF("%s: %s", good[i], gnutls_strerror(rc));
        CHECK_INT(gnutls_protocol_get_version(t1.s), i ? GNUTLS_TLS1_3 : GNUTLS_TLS1_2);
        tls_hangup(&t1);
    }
    testdaemon_stop(&d, SIGTERM);
}

TEST(a_renegotiation_is_refused_and_logged)
{
    testtls t;
    testtls_make(&t, "certs");
    testdaemon d;
    start_tls_daemon(&d, "tls-reneg", &t, NULL);
    dial t1;
    CHECK_INT(tls_dial(&t1, port_of(d.tls_addr), "NORMAL:-VERS-ALL:+VERS-TLS1.2", t.ca, "localhost"), 0);
    int rc;
    do
        rc = gnutls_handshake(t1.s);           /* a second handshake: the client renegotiates */
    while (rc < 0 && !gnutls_error_is_fatal(rc));
    if (rc == 0)
        FAILF("the daemon renegotiated");
    tls_hangup(&t1);
    wait_log(&d, "asked to renegotiate");
    testdaemon_stop(&d, SIGTERM);
}

TEST(a_handshake_never_finished_is_cut_by_the_hello_timeout)
{
    testtls t;
    testtls_make(&t, "certs");
    testdaemon d;
    const char *extra[] = {"--hello-timeout", "1", NULL};
    start_tls_daemon(&d, "tls-slow", &t, extra);
    int fd = tcp_connect(port_of(d.tls_addr));
    /* the header of a 512-byte handshake record, and nothing after it */
    static const uint8_t part[] = {0x16, 0x03, 0x01, 0x02, 0x00, 0x01};
    CHECK(send(fd, part, sizeof part, MSG_NOSIGNAL) == (ssize_t)sizeof part);
    double t0 = now_s();
    uint8_t got[256];
    long n = read_to_eof(fd, got, sizeof got, 10);
    double took = now_s() - t0;
    close(fd);
    if (n < 0)
        FAILF("a half-done handshake was kept for 10 s with --hello-timeout 1");
    CHECK(took >= 0.7 && took < 5);
    CHECK_INT(n, 0);                           /* no ERROR in clear */
    wait_log(&d, "not done within 1 s (--hello-timeout)");
    CHECK(testdaemon_log_has(&d, "TLS handshake with 127.0.0.1:"));
    testdaemon_stop(&d, SIGTERM);
}

/* Over --max-unauthenticated the oldest connection without HELLO makes
 * room (srv.c): one still in its handshake counts, and one whose handshake
 * is done reads its ERROR BUSY inside the session. */
TEST(handshaking_clients_count_as_unauthenticated_and_a_displaced_tls_client_reads_busy)
{
    testtls t;
    testtls_make(&t, "certs");
    testdaemon d;
    const char *extra[] = {"--max-unauthenticated", "2", NULL};
    start_tls_daemon(&d, "tls-unauth", &t, extra);
    int port = port_of(d.tls_addr);
    int a = tcp_connect(port);                    /* never starts its handshake */
    testdaemon_sleep_ms(100);
    dial b;                                       /* its handshake done, no HELLO */
    CHECK_INT(tls_dial(&b, port, "NORMAL", t.ca, "localhost"), 0);
    testdaemon_sleep_ms(100);
    /* alice over the cap: the oldest, a, makes room and she gets in */
    char addr[128];
    mc_client *c = tls_client(tls_at(&d, "localhost", addr, sizeof addr), t.ca);
    CHECK_INT(mc_ping(c), 0);
    uint8_t got[256];
    if (read_to_eof(a, got, sizeof got, 5) < 0)
        FAILF("the oldest handshaking client was kept over --max-unauthenticated 2");
    close(a);
    /* two more idle ones: the second displaces b, which reads why in TLS */
    int e = tcp_connect(port);
    testdaemon_sleep_ms(100);
    int f = tcp_connect(port);
    char text[512] = "";
    size_t n = 0;
    for (;;) {
        ssize_t r = gnutls_record_recv(b.s, text + n, sizeof text - 1 - n);
        if (r <= 0)
            break;
        n += (size_t)r;
    }
    for (size_t i = 0; i < n; i++)                /* the frame's header and lengths: not text */
        if (text[i] == '\0')
            text[i] = ' ';
    text[n] = '\0';
    CHECK_STR_HAS(text, "--max-unauthenticated");
    tls_hangup(&b);
    close(e);
    close(f);
    CHECK_INT(mc_ping(c), 0);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* meshcorrd run with args (a state dir under the test's directory added):
 * its exit status within 10 s (-1 if it still runs: killed), its stderr in
 * out. */
static int run_daemon(const char *name, const char *const *args, char *out, size_t outsz)
{
    char dir[700], state[800], log[800];
    snprintf(dir, sizeof dir, "%s/%s", harness_tmpdir(), name);
    snprintf(state, sizeof state, "%s/state", dir);
    snprintf(log, sizeof log, "%s/stderr", dir);
    mkdir(dir, 0700);
    testdaemon_give(harness_tmpdir());
    testdaemon_give(dir);
    const char *argv[32] = {DAEMON, "--state-dir", state};
    int k = 3;
    if (testdaemon_user()) {
        argv[k++] = "--user";
        argv[k++] = testdaemon_user();
    }
    for (int i = 0; args[i] && k < 31; i++)
        argv[k++] = args[i];
    argv[k] = NULL;
    fflush(NULL);
    pid_t pid = fork();
    CHECK(pid >= 0);
    if (pid == 0) {
        int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0600);
        if (fd >= 0)
            dup2(fd, 2);
        execv(DAEMON, (char **)argv);
        _exit(127);
    }
    int st = 0, done = 0;
    for (int i = 0; i < 1000 && !done; i++) {
        done = waitpid(pid, &st, WNOHANG) == pid;
        if (!done)
            testdaemon_sleep_ms(10);
    }
    if (!done) {
        kill(pid, SIGKILL);
        waitpid(pid, &st, 0);
    }
    FILE *fp = fopen(log, "r");
    size_t n = fp ? fread(out, 1, outsz - 1, fp) : 0;
    out[n] = '\0';
    if (fp)
        fclose(fp);
    return done && WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

TEST(a_plain_tcp_listener_off_loopback_needs_insecure_tcp)
{
    static char out[16384];
    const char *bad[] = {"--listen", "tcp:0.0.0.0:0", NULL};
    int st = run_daemon("tcp-any", bad, out, sizeof out);
    if (st <= 0)
        FAILF("meshcorrd --listen tcp:0.0.0.0:0 without --insecure-tcp: %s; stderr:\n%s",
              st ? "still running after 10 s" : "exit status 0", out);
    CHECK_STR_HAS(out, "tcp:0.0.0.0:0 is not loopback: tokens would cross the network in clear");
    CHECK_STR_HAS(out, "use tls:HOST:PORT with --tls-cert/--tls-key, or --insecure-tcp");
    /* a tls: listener without its certificate does not start either, naming the options */
    const char *nocert[] = {"--listen", "tls:127.0.0.1:0", NULL};
    CHECK(run_daemon("tls-nocert", nocert, out, sizeof out) > 0);
    CHECK_STR_HAS(out, "--listen tls:127.0.0.1:0 needs --tls-cert FILE and --tls-key FILE");
    /* loopback stays allowed (all of 127/8), and --insecure-tcp allows the rest */
    testdaemon d;
    const char *lo[] = {"--listen", "tcp:127.0.0.2:0", NULL};
    testdaemon_start(&d, "tcp-lo", lo);
    testdaemon_stop(&d, SIGTERM);
    const char *any[] = {"--listen", "tcp:0.0.0.0:0", "--insecure-tcp", NULL};
    testdaemon_start(&d, "tcp-insecure", any);
    CHECK(testdaemon_log_has(&d, "tcp:0.0.0.0:0 is not loopback: tokens, meshes and maps cross the network in clear"));
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    CHECK_INT(mc_ping(c), 0);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST(certificate_and_key_errors_stop_the_start_naming_the_file)
{
    testtls t;
    testtls_make(&t, "certs");
    static char out[16384];
    char junk[800];
    snprintf(junk, sizeof junk, "%s/junk.pem", t.dir);
    FILE *fp = fopen(junk, "w");
    CHECK(fp && fputs("not a certificate\n", fp) >= 0 && fclose(fp) == 0);
    const char *missing[] = {"--listen", "tls:127.0.0.1:0", "--tls-cert", "/nonexistent/cert.pem", "--tls-key",
                             t.key, NULL};
    CHECK(run_daemon("bad-cert-1", missing, out, sizeof out) > 0);
    CHECK_STR_HAS(out, "--tls-cert /nonexistent/cert.pem: No such file or directory");
    const char *notcert[] = {"--listen", "tls:127.0.0.1:0", "--tls-cert", junk, "--tls-key", t.key, NULL};
    CHECK(run_daemon("bad-cert-2", notcert, out, sizeof out) > 0);
    CHECK_STR_HAS(out, "--tls-cert");
    CHECK_STR_HAS(out, "no X.509 certificate in it");
    const char *notkey[] = {"--listen", "tls:127.0.0.1:0", "--tls-cert", t.cert, "--tls-key", junk, NULL};
    CHECK(run_daemon("bad-key", notkey, out, sizeof out) > 0);
    CHECK_STR_HAS(out, "--tls-key");
    CHECK_STR_HAS(out, "junk.pem: not a private key");
    /* the CA's key is a key, but not this certificate's */
    const char *mismatch[] = {"--listen", "tls:127.0.0.1:0", "--tls-cert", t.cert, "--tls-key", t.ca_key, NULL};
    CHECK(run_daemon("bad-pair", mismatch, out, sizeof out) > 0);
    CHECK_STR_HAS(out, "does not belong to the certificate in --tls-cert");
}

/* req (a whole HTTP request) over TLS to 127.0.0.1:port, trusting ca for
 * localhost: the handshake's result, and the response into resp. */
static int https_ask(int port, const char *ca, const char *req, char *resp, size_t sz)
{
    dial t;
    resp[0] = '\0';
    int rc = tls_dial(&t, port, "NORMAL", ca, "localhost");
    if (rc == 0) {
        CHECK(gnutls_record_send(t.s, req, strlen(req)) == (ssize_t)strlen(req));
        size_t n = 0;
        ssize_t r;
        while (n + 1 < sz && (r = gnutls_record_recv(t.s, resp + n, sz - 1 - n)) > 0)
            n += (size_t)r;
        resp[n] = '\0';
    }
    tls_hangup(&t);
    return rc;
}

/* GET /metrics over TLS (https_ask). */
static int https_get(int port, const char *ca, char *resp, size_t sz)
{
    return https_ask(port, ca, "GET /metrics HTTP/1.0\r\nHost: localhost\r\n\r\n", resp, sz);
}

TEST(metrics_and_web_logins_are_served_over_https_with_the_same_certificate)
{
    testtls t;
    testtls_make(&t, "certs");
    testdaemon d;
    char port[16];
    int mport = testhttp_free_port();
    snprintf(port, sizeof port, "%d", mport);
    const char *extra[] = {"--metrics", port, NULL};
    start_tls_daemon(&d, "tls-metrics", &t, extra);
    static char resp[1 << 16];
    int rc = https_get(mport, t.ca, resp, sizeof resp);
    if (rc)
        FAILF("HTTPS handshake with /metrics: %s", gnutls_strerror(rc));
    CHECK_STR_HAS(resp, "HTTP/1.1 200");
    CHECK_STR_HAS(resp, "meshcorr_queue_depth 0");
    CHECK(https_get(mport, t.other_ca, resp, sizeof resp) != 0);   /* the same certificate: not other_ca's */
    /* plain HTTP gets no metrics */
    int fd = tcp_connect(mport);
    static const char req[] = "GET /metrics HTTP/1.0\r\n\r\n";
    CHECK(send(fd, req, sizeof req - 1, MSG_NOSIGNAL) == (ssize_t)sizeof req - 1);
    long n = read_to_eof(fd, (uint8_t *)resp, sizeof resp - 1, 10);
    close(fd);
    CHECK(n >= 0);
    resp[n] = '\0';
    CHECK(strstr(resp, "meshcorr_queue_depth") == NULL);
    /* the web's login over HTTPS: its session cookie is Secure */
    char login[256];
    snprintf(login, sizeof login, "POST /login HTTP/1.0\r\nHost: localhost\r\nContent-Length: %zu\r\n\r\ntoken=%s",
             strlen("token=") + strlen(TESTDAEMON_ALICE), TESTDAEMON_ALICE);
    CHECK_INT(https_ask(mport, t.ca, login, resp, sizeof resp), 0);
    CHECK_STR_HAS(resp, "HTTP/1.1 303");
    CHECK_STR_HAS(resp, "mc_session=");
    CHECK_STR_HAS(resp, "HttpOnly; SameSite=Strict; Secure");
    testdaemon_stop(&d, SIGTERM);
}

/* path's bytes replaced by from's (written aside, then renamed). */
static void replace_file(const char *path, const char *from)
{
    char tmp[800], cmd[2000], out[512];
    snprintf(tmp, sizeof tmp, "%s.new", path);
    snprintf(cmd, sizeof cmd, "cp '%s' '%s' && mv '%s' '%s'", from, tmp, tmp, path);
    CHECK_INT(testrun(cmd, out, sizeof out), 0);
    testdaemon_give(path);            /* a reload reads it as the daemon's --user */
}

TEST_T(sighup_serves_a_renewed_certificate_and_keeps_the_old_one_when_the_new_is_bad, 120)
{
    testtls t;
    testtls_make(&t, "certs");
    /* the daemon's files are copies the test renews, in a folder its user reaches */
    testdaemon_give(t.dir);
    char cert[700], key[700], cert2[700], key2[700];
    snprintf(cert, sizeof cert, "%s/live.pem", t.dir);
    snprintf(key, sizeof key, "%s/live.key", t.dir);
    snprintf(cert2, sizeof cert2, "%s/renewed.pem", t.dir);
    snprintf(key2, sizeof key2, "%s/renewed.key", t.dir);
    replace_file(cert, t.cert);
    replace_file(key, t.key);
    testtls_issue(t.dir, t.other_ca, t.other_ca_key, "localhost", cert2, key2);
    testtls live = t;
    snprintf(live.cert, sizeof live.cert, "%s", cert);
    snprintf(live.key, sizeof live.key, "%s", key);
    testdaemon d;
    char port[16];
    int mport = testhttp_free_port();
    snprintf(port, sizeof port, "%d", mport);
    const char *extra[] = {"--metrics", port, NULL};
    start_tls_daemon(&d, "tls-reload", &live, extra);
    char addr[128];
    tls_at(&d, "localhost", addr, sizeof addr);
    mc_client *before = tls_client(addr, t.ca);
    expect_tls_refusal(addr, t.other_ca, "not trusted");

    replace_file(cert, cert2);
    replace_file(key, key2);
    kill(d.pid, SIGHUP);
    wait_log(&d, "reload: TLS certificate and key read again");
    wait_log(&d, "reload: --http serves the new certificate");
    expect_tls_refusal(addr, t.ca, "not trusted");       /* new connections get the renewed one */
    mc_client *after = tls_client(addr, t.other_ca);
    CHECK_INT(mc_ping(after), 0);
    CHECK_INT(mc_ping(before), 0);                         /* a session begun before goes on */
    static char resp[1 << 16];
    CHECK_INT(https_get(mport, t.other_ca, resp, sizeof resp), 0);
    CHECK_STR_HAS(resp, "meshcorr_queue_depth");
    CHECK(https_get(mport, t.ca, resp, sizeof resp) != 0);

    /* a bad renewal: the running pair stays */
    FILE *fp = fopen(cert, "w");
    CHECK(fp && fputs("-----BEGIN CERTIFICATE-----\ngarbage\n-----END CERTIFICATE-----\n", fp) >= 0 && fclose(fp) == 0);
    kill(d.pid, SIGHUP);
    wait_log(&d, "keeping the running certificate and key");
    mc_client *still = tls_client(addr, t.other_ca);
    CHECK_INT(mc_ping(still), 0);
    CHECK_INT(https_get(mport, t.other_ca, resp, sizeof resp), 0);
    mc_close(still);
    mc_close(after);
    mc_close(before);
    testdaemon_stop(&d, SIGTERM);
}

TEST(the_cli_and_python_take_the_ca_and_refuse_an_untrusted_server)
{
    testtls t;
    testtls_make(&t, "certs");
    testdaemon d;
    start_tls_daemon(&d, "tls-clients", &t, NULL);
    char addr[128];
    tls_at(&d, "localhost", addr, sizeof addr);
    static char out[1 << 14];
    unsetenv("MESHCORR_CA");
    unsetenv("MESHCORR_SERVER");
    /* meshcorr --ca, and MESHCORR_CA */
    if (testrunf(out, sizeof out, "build/meshcorr stats --server %s --token %s --ca '%s' 2>&1", addr,
                 TESTDAEMON_ALICE, t.ca) != 0)
        FAILF("meshcorr stats --ca: %s", out);
    CHECK_STR_HAS(out, "queued");
    if (testrunf(out, sizeof out, "MESHCORR_CA='%s' build/meshcorr stats --server %s --token %s 2>&1", t.ca, addr,
                 TESTDAEMON_ALICE) != 0)
        FAILF("meshcorr stats with MESHCORR_CA: %s", out);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr stats --server %s --token %s --ca '%s' 2>&1", addr,
                       TESTDAEMON_ALICE, t.other_ca), 1);
    CHECK_STR_HAS(out, "the server's certificate is not trusted");
    CHECK_STR_HAS(out, "give its CA with --ca or MESHCORR_CA");
    /* Python: Client(ca=...) and MeshcorrError MC_ETLS */
    if (testrun("/usr/bin/python3 -c 'import numpy' 2>&1", out, sizeof out) != 0)
        SKIP("/usr/bin/python3 with numpy is not installed (apt-get install python3-numpy)");
    static const char script[] =
        "import sys, meshcorr\n"
        "from meshcorr.errors import MeshcorrError\n"
        "addr, tok, ca, other = sys.argv[1:5]\n"
        "with meshcorr.Client(addr, tok, ca=ca) as c:\n"
        "    print('user', c.user)\n"
        "try:\n"
        "    meshcorr.Client(addr, tok, ca=other)\n"
        "    print('connected to an untrusted server')\n"
        "except MeshcorrError as e:\n"
        "    print('refused', e.name, e.message)\n";
    char path[700];
    snprintf(path, sizeof path, "%s/tls_client.py", t.dir);
    FILE *fp = fopen(path, "w");
    CHECK(fp && fputs(script, fp) >= 0 && fclose(fp) == 0);
    if (testrunf(out, sizeof out, "MESHCORR_LIB=build/libmeshcorr.so.1 PYTHONPATH=client-c/python "
                 "PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 '%s' %s %s '%s' '%s' 2>&1", path, addr,
                 TESTDAEMON_ALICE, t.ca, t.other_ca) != 0)
        FAILF("python: %s", out);
    CHECK_STR_HAS(out, "user alice");
    CHECK_STR_HAS(out, "refused MC_ETLS the server's certificate is not trusted");
    testdaemon_stop(&d, SIGTERM);
}

/* Under systemd the key reaches the service as a credential
 * (LoadCredential=): --tls-cert and --tls-key may start with
 * ${CREDENTIALS_DIRECTORY}, as --tokens may. */
TEST(the_certificate_and_key_are_found_as_systemd_credentials)
{
    testtls t;
    testtls_make(&t, "certs");
    testdaemon_give(t.dir);
    testdaemon_give(t.cert);
    testdaemon_give(t.key);
    CHECK_INT(setenv("CREDENTIALS_DIRECTORY", t.dir, 1), 0);
    const char *args[] = {"--listen", "tls:127.0.0.1:0", "--tls-cert", "${CREDENTIALS_DIRECTORY}/server.pem",
                          "--tls-key", "${CREDENTIALS_DIRECTORY}/server.key", NULL};
    testdaemon d;
    testdaemon_start(&d, "tls-credential", args);
    char addr[128];
    mc_client *c = tls_client(tls_at(&d, "localhost", addr, sizeof addr), t.ca);
    CHECK_INT(mc_ping(c), 0);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
    /* without the variable the start names it */
    unsetenv("CREDENTIALS_DIRECTORY");
    static char out[8192];
    const char *bad[] = {"--listen", "tls:127.0.0.1:0", "--tls-cert", "${CREDENTIALS_DIRECTORY}/server.pem",
                         "--tls-key", "${CREDENTIALS_DIRECTORY}/server.key", NULL};
    CHECK(run_daemon("tls-no-credentials", bad, out, sizeof out) > 0);
    CHECK_STR_HAS(out, "--tls-cert ${CREDENTIALS_DIRECTORY}/server.pem: $CREDENTIALS_DIRECTORY is not set");
}
