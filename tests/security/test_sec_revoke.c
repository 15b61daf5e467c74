/* test_sec_revoke.c — a revoked token against a real meshcorrd: bob's
 * token is taken out of the tokens file and the daemon reloaded (SIGHUP)
 * while his session is open. His session must end at once with ERROR
 * UNAUTHORIZED ("your token was revoked", request id 0) and a log line, a
 * SUBMIT on it must not be acknowledged, and his token must not log in
 * again; a token whose admin flag is taken away ends its admin session the
 * same way; alice, whose line did not change, goes on. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testraw.h"
#include "meshcorr.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* A session over raw TCP with token: HELLO_OK read. */
static int session(const testdaemon *d, const char *token)
{
    int fd = testraw_tcp(d->tcp_addr, NULL);
    int code = 0;
    char msg[1200];
    if (testraw_hello(fd, token, "test_sec_revoke", &code, msg, sizeof msg, 5) != PROTO_MSG_HELLO_OK)
        FAILF("HELLO: %s %s", proto_err_name(code), msg);
    return fd;
}

/* The server ends fd's session: ERROR code with what (request id 0), then EOF. */
static void expect_ended(int fd, int code, const char *what)
{
    proto_msg m;
    uint8_t *buf;
    int rc = testraw_read_msg(fd, &m, &buf, 5);
    if (rc)
        FAILF("the session was not ended: %s", rc > 0 ? "EOF without an ERROR" : "nothing came in 5 s");
    CHECK_INT(m.type, PROTO_MSG_ERROR);
    CHECK_INT(m.u.error.code, code);
    CHECK_INT(m.request_id, 0);
    CHECK_STR_HAS(m.u.error.message, what);
    printf("  ended: %s\n", m.u.error.message);
    proto_msg_free(&m);
    free(buf);
    CHECK(testraw_closed_within(fd, 5));
}

/* Rewrites the daemon's tokens file with lines and waits for the reload. */
static void reload_tokens(testdaemon *d, const char *text)
{
    char path[700];
    snprintf(path, sizeof path, "%s/tokens", d->dir);
    testdaemon_write_tokens(path, text);
    int before = 0;
    FILE *fp = fopen(d->log, "r");
    char line[4096];
    while (fp && fgets(line, sizeof line, fp))
        before += strstr(line, "reload: tokens read from") != NULL;
    if (fp)
        fclose(fp);
    CHECK_INT(kill(d->pid, SIGHUP), 0);
    for (int i = 0; i < 500; i++) {
        int n = 0;
        fp = fopen(d->log, "r");
        while (fp && fgets(line, sizeof line, fp))
            n += strstr(line, "reload: tokens read from") != NULL;
        if (fp)
            fclose(fp);
        if (n > before)
            return;
        testdaemon_sleep_ms(20);
    }
    FAILF("no reload of the tokens in %s", d->log);
}

TEST_T(a_revoked_token_ends_its_open_session_at_the_reload, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "revoke", NULL);
    int bob = session(&d, TESTDAEMON_BOB), alice = session(&d, TESTDAEMON_ALICE);
    mc_client *bob2 = testdaemon_client(&d, TESTDAEMON_BOB);
    char a[256], b[256], text[1024];
    testdaemon_token_line(TESTDAEMON_ALICE, "alice", 0, a, sizeof a);
    testdaemon_token_line(TESTDAEMON_ADMIN, "boss", 1, b, sizeof b);
    snprintf(text, sizeof text, "%s\n%s\n", a, b);           /* bob's line is gone */
    reload_tokens(&d, text);
    expect_ended(bob, PROTO_EUNAUTHORIZED, "your token was revoked");
    int rc;
    uint64_t id = testdaemon_submit(bob2, 2, 0, 0, &rc);
    if (rc == 0)
        FAILF("bob's session still got SUBMIT_OK (job %llu) after his token was revoked",
              (unsigned long long)id);
    printf("  bob's SUBMIT after the reload: %s (%s)\n", mc_strerror(rc), mc_errmsg(bob2));
    mc_close(bob2);
    CHECK_INT(testraw_ask(alice, PROTO_MSG_PING, 3, 5), PROTO_MSG_PONG);
    CHECK(testdaemon_log_has(&d, "(user bob, 127.0.0.1): session ended: your token was revoked"));
    char err[1024];
    mc_client *x = NULL;
    CHECK_INT(mc_connect(d.tcp_addr, TESTDAEMON_BOB, &x, err, sizeof err), MC_EUNAUTHORIZED);
    close(bob);
    close(alice);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(a_token_that_loses_its_admin_flag_ends_its_admin_session, 60)
{
    testdaemon d;
    testdaemon_start(&d, "demote", NULL);
    int boss = session(&d, TESTDAEMON_ADMIN), alice = session(&d, TESTDAEMON_ALICE);
    char a[256], b[256], c[256], text[1024];
    testdaemon_token_line(TESTDAEMON_ALICE, "alice", 0, a, sizeof a);
    testdaemon_token_line(TESTDAEMON_BOB, "bob", 0, b, sizeof b);
    testdaemon_token_line(TESTDAEMON_ADMIN, "boss", 0, c, sizeof c);
    snprintf(text, sizeof text, "%s\n%s\n%s\n", a, b, c);      /* boss is no admin any more */
    reload_tokens(&d, text);
    expect_ended(boss, PROTO_EUNAUTHORIZED, "no longer admin");
    CHECK_INT(testraw_ask(alice, PROTO_MSG_PING, 3, 5), PROTO_MSG_PONG);
    mc_client *x = testdaemon_client(&d, TESTDAEMON_ADMIN);   /* logs in again, as a user */
    CHECK_INT(mc_is_admin(x), 0);
    mc_close(x);
    close(boss);
    close(alice);
    testdaemon_stop(&d, SIGTERM);
}
