/* test_sec_injection.c — what a client's strings and a broken frame make a
 * real meshcorrd show to others: an unauthenticated HELLO's client name
 * must not forge log lines (each begins with its syslog priority, so a
 * newline and "<3>" would be a forged error); a job label must not carry
 * terminal escapes into an admin's `meshcorr list` or `meshcorr status`; a
 * frame with a bad magic or header CRC must not be answered with another
 * session's request id; STATS must not show a user everyone's counters;
 * a STORAGE error must not show the client the server's paths. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testraw.h"
#include "support/testrun.h"
#include "meshcorr.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define FORGED "<3>2026-01-01T00:00:00.000Z meshcorrd error: FORGED"

/* A line of the daemon's log that starts with what. */
static int log_line_starts(const testdaemon *d, const char *what)
{
    FILE *fp = fopen(d->log, "r");
    CHECK(fp != NULL);
    char line[8192];
    int found = 0;
    while (!found && fgets(line, sizeof line, fp))
        found = strncmp(line, what, strlen(what)) == 0;
    fclose(fp);
    return found;
}

/* Bytes of the daemon's log below 0x20 other than the line ends, and ESC. */
static int log_controls(const testdaemon *d)
{
    FILE *fp = fopen(d->log, "r");
    CHECK(fp != NULL);
    int c, n = 0;
    while ((c = fgetc(fp)) != EOF)
        n += (c < 0x20 && c != '\n') || c == 0x7f;
    fclose(fp);
    return n;
}

TEST_T(a_client_name_cannot_forge_log_lines, 60)
{
    testdaemon d;
    testdaemon_start(&d, "forge", NULL);
    static const char name[] = "innocent\n" FORGED " token stolen\r\x1b[2K";
    int fd = testraw_tcp(d.tcp_addr, NULL);
    int code = 0;
    CHECK_INT(testraw_hello(fd, "no-such-token", name, &code, NULL, 0, 5), PROTO_MSG_ERROR);  /* unauthenticated */
    close(fd);
    fd = testraw_unix(d.unix_addr);
    CHECK_INT(testraw_hello(fd, NULL, name, &code, NULL, 0, 5), PROTO_MSG_HELLO_OK);          /* a session */
    close(fd);
    testdaemon_sleep_ms(200);
    CHECK(!log_line_starts(&d, FORGED));
    CHECK_INT(log_controls(&d), 0);
    CHECK(testdaemon_log_has(&d, "innocent\\x0a" FORGED " token stolen\\x0d\\x1b[2K"));
    testdaemon_stop(&d, SIGTERM);
}

/* Bytes below 0x20 other than newlines, and DEL, in text. */
static int controls(const char *text)
{
    int n = 0;
    for (const unsigned char *p = (const unsigned char *)text; *p; p++)
        n += (*p < 0x20 && *p != '\n') || *p == 0x7f;
    return n;
}

TEST_T(a_job_label_reaches_meshcorr_list_and_status_without_terminal_escapes, 90)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "label", NULL);
    mc_client *alice = testdaemon_client(&d, TESTDAEMON_ALICE);
    mesh *S, *T;
    testdaemon_pair(0, &S, &T);
    size_t sl, tl;
    unsigned char *sb = testdaemon_encode(S, &sl), *tb = testdaemon_encode(T, &tl);
    static const uint32_t lm[] = {0, 0, 1, 1, 2, 2, 3, 3};
    mc_job_spec spec;
    mc_job_spec_init(&spec);
    spec.source = sb;
    spec.source_len = sl;
    spec.target = tb;
    spec.target_len = tl;
    spec.landmarks = lm;
    spec.nlandmarks = 4;
    spec.iterations = 2;
    spec.label = "x\x1b]0;owned\x07\x1b[31mred\r\nfake line\xe2\x80\xae";   /* title, colour, newline, RLO */
    uint64_t id = 0;
    if (mc_submit(alice, &spec, &id))
        FAILF("SUBMIT: %s", mc_errmsg(alice));
    free(sb);
    free(tb);
    mesh_free(S);
    mesh_free(T);
    static char out[1 << 16];
    setenv("MESHCORR_TOKEN", TESTDAEMON_ADMIN, 1);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --user alice --server %s", d.tcp_addr), 0);
    printf("%s", out);
    CHECK_INT(controls(out), 0);
    CHECK(strstr(out, "\xe2\x80\xae") == NULL);
    CHECK_STR_HAS(out, "x\\x1b]0;owned\\x07\\x1b[31mred\\x0d\\x0afake line\\xe2\\x80\\xae");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr status %llu --server %s", (unsigned long long)id,
                       d.tcp_addr), 0);
    CHECK_INT(controls(out), 0);
    CHECK_STR_HAS(out, "label     x\\x1b]0;owned");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --json --user alice --server %s", d.tcp_addr), 0);
    CHECK_INT(controls(out), 0);
    CHECK_STR_HAS(out, "\"label\":\"x\\u001b]0;owned\\u0007\\u001b[31mred\\u000d\\u000afake line\\u202e\"");
    CHECK_INT(log_controls(&d), 0);                 /* the SUBMIT's log line has the label too */
    testdaemon_wait_state(alice, id, -1, 60);
    mc_close(alice);
    testdaemon_stop(&d, SIGTERM);
}

/* A session's request goes through with a request id; then another
 * connection sends a frame whose magic or header CRC is wrong: its ERROR
 * carries request id 0, never the other session's. */
TEST_T(a_broken_frame_is_answered_with_request_id_0_not_another_sessions, 60)
{
    testdaemon d;
    testdaemon_start(&d, "hdr", NULL);
    int a = testraw_unix(d.unix_addr);
    CHECK_INT(testraw_hello(a, NULL, "a", NULL, NULL, 0, 5), PROTO_MSG_HELLO_OK);
    for (int kind = 0; kind < 2; kind++) {
        CHECK_INT(testraw_ask(a, PROTO_MSG_PING, 0x5ec7e7u + (uint32_t)kind, 5), PROTO_MSG_PONG);
        int b = testraw_unix(d.unix_addr);
        uint8_t frame[PROTO_HDR_SIZE];
        proto_hdr h = {PROTO_VERSION, PROTO_MSG_PING, 0, 77, 0};
        proto_frame_put_header(frame, &h);
        if (kind == 0)
            memcpy(frame, "GET ", 4);                 /* not the magic */
        else
            frame[16] ^= 0x55;                        /* the header CRC */
        testraw_send(b, frame, sizeof frame);
        proto_msg m;
        uint8_t *buf;
        CHECK_INT(testraw_read_msg(b, &m, &buf, 5), 0);
        CHECK_INT(m.type, PROTO_MSG_ERROR);
        CHECK_INT(m.u.error.code, kind == 0 ? PROTO_EBAD_MAGIC : PROTO_EBAD_CHECKSUM);
        printf("  %s: request id %u\n", proto_err_name(m.u.error.code), m.request_id);
        CHECK_INT(m.request_id, 0);
        proto_msg_free(&m);
        free(buf);
        close(b);
    }
    close(a);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(stats_shows_a_user_only_their_own_counters, 90)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "stats", NULL);
    mc_client *alice = testdaemon_client(&d, TESTDAEMON_ALICE), *bob = testdaemon_client(&d, TESTDAEMON_BOB);
    mc_client *boss = testdaemon_client(&d, TESTDAEMON_ADMIN);
    uint64_t done = testdaemon_submit_ok(alice, 2, 0, 0);
    CHECK_INT(testdaemon_wait_state(alice, done, -1, 60), MC_COMPLETED);
    uint64_t gone = testdaemon_submit_ok(alice, 100000, 1, 0);
    CHECK_INT(mc_cancel(alice, gone), 0);
    testdaemon_wait_state(alice, gone, MC_CANCELLED, 60);
    uint64_t queued = testdaemon_submit_ok(alice, 100000, 1, 0);
    mc_server_stats sa, sb, sx;
    CHECK_INT(mc_stats(alice, &sa), 0);
    CHECK_INT(mc_stats(bob, &sb), 0);
    CHECK_INT(mc_stats(boss, &sx), 0);
    printf("  completed/cancelled/queued+running: alice %llu/%llu/%u, bob %llu/%llu/%u, admin %llu/%llu/%u\n",
           (unsigned long long)sa.completed, (unsigned long long)sa.cancelled, sa.queued + sa.running,
           (unsigned long long)sb.completed, (unsigned long long)sb.cancelled, sb.queued + sb.running,
           (unsigned long long)sx.completed, (unsigned long long)sx.cancelled, sx.queued + sx.running);
    CHECK(sb.completed == 0 && sb.failed == 0 && sb.cancelled == 0 && sb.queued == 0 && sb.running == 0);
    CHECK(sa.completed == 1 && sa.cancelled == 1 && sa.queued + sa.running == 1);
    CHECK(sx.completed == 1 && sx.cancelled == 1 && sx.queued + sx.running == 1);
    mc_stats_free(&sa);
    mc_stats_free(&sb);
    mc_stats_free(&sx);
    CHECK_INT(mc_cancel(alice, queued), 0);
    mc_close(alice);
    mc_close(bob);
    mc_close(boss);
    testdaemon_stop(&d, SIGTERM);
}

/* The spool replaced by a file: every SUBMIT is refused STORAGE; the client
 * reads why without a path of the server, the log has the path. */
TEST_T(a_storage_error_shows_the_client_no_server_path, 90)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "storage", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    char spool[700], away[700];
    snprintf(spool, sizeof spool, "%s/spool", d.state);
    snprintf(away, sizeof away, "%s/spool.away", d.state);
    CHECK_INT(rename(spool, away), 0);
    FILE *fp = fopen(spool, "w");
    CHECK(fp != NULL);
    fclose(fp);
    int rc;
    testdaemon_submit(c, 2, 0, 0, &rc);
    const char *msg = mc_errmsg(c);
    printf("  SUBMIT: %s: %s\n", mc_strerror(rc), msg);
    CHECK_INT(rc, PROTO_ESTORAGE);
    CHECK_STR_HAS(msg, "job not stored");
    CHECK(strstr(msg, d.dir) == NULL && strstr(msg, "/spool") == NULL);
    CHECK(testdaemon_log_has(&d, spool));
    unlink(spool);
    CHECK_INT(rename(away, spool), 0);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
