/* test_sec_web.c — attacks on the web UI of a real meshcorrd (--http), with
 * raw HTTP requests:
 * - guessing tokens on the login form: after a few failures the address's
 *   logins are refused unchecked (429), a right token included, and its
 *   protocol HELLOs too (one throttle for both); the log names the address;
 * - the session cookie is HttpOnly, SameSite=Strict, expiring, and a forged
 *   or stale cookie logs in nobody;
 * - a cancel with the cookie but without the session's CSRF token is
 *   refused (403) and the job runs on; with it, it is cancelled;
 * - another user's job is 404 on its page and in every API call, as a job
 *   that does not exist, and is not in the list;
 * - every answer carries the Content-Security-Policy. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testhttp.h"
#include "support/testraw.h"
#include "mcd.h"
#include "meshcorr.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

/* One request (headers: extra lines ending in \r\n, may be ""): the whole
 * answer in a static buffer, its status in *status. */
static const char *request(int port, const char *method, const char *path, const char *headers, const char *body,
                           int *status)
{
    static char resp[1 << 16];
    *status = testhttp_request(port, method, path, headers, body, resp, sizeof resp, 5000);
    if (*status <= 0)
        FAILF("%s %s: no HTTP answer: %.100s", method, path, resp);
    return resp;
}

/* The value of header name (case as MHD writes it) into out. */
static int header(const char *resp, const char *name, char *out, size_t sz)
{
    char want[64];
    snprintf(want, sizeof want, "\r\n%s: ", name);
    const char *h = strcasestr(resp, want);
    if (!h)
        return -1;
    h += strlen(want);
    size_t n = strcspn(h, "\r\n");
    snprintf(out, sz, "%.*s", (int)(n < sz ? n : sz - 1), h);
    return 0;
}

/* Logs in with token: the session cookie "mc_session=ID" into cookie. */
static void login(int port, const char *token, char *cookie, size_t sz)
{
    char body[128], set[512];
    int st;
    snprintf(body, sizeof body, "token=%s", token);
    const char *r = request(port, "POST", "/login", "Content-Type: application/x-www-form-urlencoded\r\n", body, &st);
    CHECK_INT(st, 303);
    CHECK(header(r, "Set-Cookie", set, sizeof set) == 0);
    snprintf(cookie, sz, "%.*s", (int)strcspn(set, ";"), set);
}

TEST_T(guessing_on_the_login_form_is_throttled_with_the_protocol_and_logged, 60)
{
    int port = testhttp_free_port();
    char http[16];
    snprintf(http, sizeof http, "%d", port);
    const char *args[] = {"--http", http, NULL};
    testdaemon d;
    testdaemon_start(&d, "web-guess", args);
    int st, checked = 0, refused = 0;
    for (int i = 0; i < 12; i++) {
        char body[64];
        snprintf(body, sizeof body, "token=mc_guess-%06d", i);
        const char *r = request(port, "POST", "/login", "", body, &st);
        if (st == 401) {
            checked++;
        } else if (st == 429) {
            refused++;
            CHECK_STR_HAS(r, "Too many failed logins from 127.0.0.1");
        } else {
            FAILF("guess %d: status %d", i, st);
        }
        CHECK(!strcasestr(r, "Set-Cookie"));
    }
    /* the login page with its message is the page whole, nothing after it */
    const char *page = request(port, "POST", "/login", "", "token=mc_guess-x", &st);
    size_t plen = strlen(page);
    CHECK(plen > 16 && !strcmp(page + plen - 15, "</body></html>\n"));
    checked += st == 401;
    refused += st == 429;
    printf("  13 guesses on the form: %d checked, %d refused unchecked\n", checked, refused);
    CHECK(checked <= THROTTLE_FREE_FAILS + 1 && refused >= 13 - THROTTLE_FREE_FAILS - 1);
    /* the right token from that address waits too, on the form, the API and the protocol */
    char body[64];
    snprintf(body, sizeof body, "token=%s", TESTDAEMON_ALICE);
    request(port, "POST", "/login", "", body, &st);
    CHECK_INT(st, 429);
    char authz[128];
    snprintf(authz, sizeof authz, "Authorization: Bearer %s\r\n", TESTDAEMON_ALICE);
    request(port, "GET", "/api/v1/jobs", authz, NULL, &st);
    CHECK_INT(st, 429);
    int fd = testraw_tcp(d.tcp_addr, "127.0.0.1");
    char msg[1200];
    int code = 0, type = testraw_hello(fd, TESTDAEMON_ALICE, "after-web-guesses", &code, msg, sizeof msg, 5);
    close(fd);
    CHECK_INT(type, PROTO_MSG_ERROR);
    CHECK_INT(code, PROTO_EBUSY);
    CHECK_STR_HAS(msg, "too many failed logins from 127.0.0.1");
    CHECK(testdaemon_log_has(&d, "login from 127.0.0.1 refused: unknown token (client 'web')"));
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(cookies_csrf_other_users_jobs_and_the_csp, 120)
{
    testdaemon_need_worker();
    int port = testhttp_free_port();
    char http[16];
    snprintf(http, sizeof http, "%d", port);
    const char *args[] = {"--http", http, "--workers", "2", NULL};
    testdaemon d;
    testdaemon_start(&d, "web-sec", args);
    mc_client *alice = testdaemon_client(&d, TESTDAEMON_ALICE);
    mc_client *bob = testdaemon_client(&d, TESTDAEMON_BOB);
    uint64_t mine = testdaemon_submit_ok(alice, 100000, 1, 0);
    uint64_t theirs = testdaemon_submit_ok(bob, 5, 0, 0);
    testdaemon_wait_state(alice, mine, MC_RUNNING, 60);
    testdaemon_wait_state(bob, theirs, MC_COMPLETED, 60);

    /* the cookie's attributes */
    char body[64], set[512], cookie[256], hdr[512];
    int st;
    snprintf(body, sizeof body, "token=%s", TESTDAEMON_ALICE);
    const char *r = request(port, "POST", "/login", "", body, &st);
    CHECK_INT(st, 303);
    CHECK(header(r, "Set-Cookie", set, sizeof set) == 0);
    CHECK_STR_HAS(set, "HttpOnly");
    CHECK_STR_HAS(set, "SameSite=Strict");
    CHECK_STR_HAS(set, "Max-Age=");
    CHECK_STR_HAS(set, "Path=/");
    CHECK(header(r, "Content-Security-Policy", hdr, sizeof hdr) == 0);
    CHECK_STR_HAS(hdr, "default-src 'none'");
    login(port, TESTDAEMON_ALICE, cookie, sizeof cookie);
    CHECK(strlen(cookie) == strlen("mc_session=") + 64);

    /* a forged cookie logs in nobody */
    request(port, "GET", "/api/v1/jobs",
            "Cookie: mc_session=0000000000000000000000000000000000000000000000000000000000000000\r\n", NULL, &st);
    CHECK_INT(st, 401);
    request(port, "GET", "/", "Cookie: mc_session=x\r\n", NULL, &st);
    CHECK_INT(st, 303);

    /* the session's CSRF token */
    snprintf(hdr, sizeof hdr, "Cookie: %s\r\n", cookie);
    r = request(port, "GET", "/api/v1/session", hdr, NULL, &st);
    CHECK_INT(st, 200);
    const char *c = strstr(r, "\"csrf\":\"");
    CHECK(c != NULL);
    char csrf[64];
    snprintf(csrf, sizeof csrf, "%.*s", (int)strcspn(c + 8, "\""), c + 8);
    CHECK_INT((int)strlen(csrf), 32);

    /* a cancel with the cookie alone, or a wrong token, is refused; the job runs on */
    char path[128];
    snprintf(path, sizeof path, "/api/v1/jobs/%llu/cancel", (unsigned long long)mine);
    request(port, "POST", path, hdr, "", &st);
    CHECK_INT(st, 403);
    char bad[600];
    snprintf(bad, sizeof bad, "Cookie: %s\r\nX-CSRF-Token: 0123456789abcdef0123456789abcdef\r\n", cookie);
    request(port, "POST", path, bad, "", &st);
    CHECK_INT(st, 403);
    testdaemon_sleep_ms(500);
    mc_job_status js;
    CHECK_INT(mc_status(alice, mine, &js), 0);
    CHECK_INT(js.state, MC_RUNNING);

    /* bob's job: 404 everywhere for alice, and not listed */
    static const char *const tails[] = {"", "/history", "/quality", "/maps/p", "/picture", "/events"};
    for (size_t i = 0; i < sizeof tails / sizeof tails[0]; i++) {
        snprintf(path, sizeof path, "/api/v1/jobs/%llu%s", (unsigned long long)theirs, tails[i]);
        request(port, "GET", path, hdr, NULL, &st);
        if (st != 404)
            FAILF("alice's GET %s: %d, not 404", path, st);
        snprintf(path, sizeof path, "/api/v1/jobs/999999%s", tails[i]);
        request(port, "GET", path, hdr, NULL, &st);
        CHECK_INT(st, 404);
    }
    snprintf(path, sizeof path, "/api/v1/jobs/%llu/cancel", (unsigned long long)theirs);
    snprintf(bad, sizeof bad, "Cookie: %s\r\nX-CSRF-Token: %s\r\n", cookie, csrf);
    request(port, "POST", path, bad, "", &st);
    CHECK_INT(st, 404);
    snprintf(path, sizeof path, "/jobs/%llu", (unsigned long long)theirs);
    request(port, "GET", path, hdr, NULL, &st);
    CHECK_INT(st, 404);
    r = request(port, "GET", "/api/v1/jobs?user=bob", hdr, NULL, &st);
    CHECK_INT(st, 200);
    char theirs_id[32];
    snprintf(theirs_id, sizeof theirs_id, "\"id\":%llu,", (unsigned long long)theirs);
    CHECK(!strstr(r, theirs_id));
    CHECK(!strstr(r, "\"user\":\"bob\""));

    /* with the CSRF token the cancel goes through the loop */
    snprintf(path, sizeof path, "/api/v1/jobs/%llu/cancel", (unsigned long long)mine);
    request(port, "POST", path, bad, "", &st);
    CHECK_INT(st, 202);
    CHECK_INT(testdaemon_wait_state(alice, mine, MC_CANCELLED, 30), MC_CANCELLED);
    request(port, "POST", path, bad, "", &st);
    CHECK_INT(st, 409);

    /* logout ends the session: the same cookie logs in nobody */
    request(port, "POST", "/logout", bad, "", &st);
    CHECK_INT(st, 303);
    request(port, "GET", "/api/v1/jobs", hdr, NULL, &st);
    CHECK_INT(st, 401);
    mc_close(alice);
    mc_close(bob);
    testdaemon_stop(&d, SIGTERM);
}
