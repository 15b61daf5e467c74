/* test_web.c — meshcorrd's web UI and JSON API in a real browser, black-box:
 * the real daemon on loopback with --http on a free port and two worker
 * slots, jobs submitted by two users with the real client library (alice: a
 * long job that runs and a quick one that completes; bob: one job), then
 * tests/web/test_web.py drives Debian's headless chromium through
 * chromedriver (python3-selenium) as alice: a wrong token refused, the
 * list, the running job's plot gaining points, the completed job's quality
 * and maps, bob's job 404 on the page and the API, no resource from
 * anywhere but the daemon, a cancel. Its screenshots land in build/web-shots/.
 * Here: the failed login is in the daemon's log with the address, the
 * cancel reached the store, a token taken out of the tokens file (SIGHUP)
 * no longer logs in, and the daemon exits cleanly. Skipped without
 * chromium, chromedriver or selenium (deploy/install-deps.sh installs them). */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testhttp.h"
#include "support/testrun.h"
#include "meshcorr.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

/* GET path from 127.0.0.1:port with a Bearer token: the HTTP status. */
static int api_status(int port, const char *path, const char *token)
{
    char hdr[256], resp[4096];
    snprintf(hdr, sizeof hdr, "Authorization: Bearer %s\r\n", token);
    int status = testhttp_request(port, "GET", path, hdr, NULL, resp, sizeof resp, 5000);
    if (status <= 0)
        FAILF("GET %s: no HTTP answer: %.100s", path, resp);
    return status;
}

static void need_browser(void)
{
    char out[256];
    if (access("/usr/bin/chromium", X_OK) || access("/usr/bin/chromedriver", X_OK) ||
        testrun("/usr/bin/python3 -c 'import selenium' 2>&1", out, sizeof out) != 0)
        SKIP("chromium, chromedriver or python3-selenium missing (deploy/install-deps.sh)\n");
}

TEST_T(browser_logs_in_sees_own_jobs_plot_result_and_cancels, 300)
{
    testdaemon_need_worker();
    need_browser();
    int port = testhttp_free_port();
    char http[16];
    snprintf(http, sizeof http, "%d", port);
    const char *args[] = {"--http", http, "--workers", "2", NULL};
    testdaemon d;
    testdaemon_start(&d, "web", args);
    mc_client *alice = testdaemon_client(&d, TESTDAEMON_ALICE);
    mc_client *bob = testdaemon_client(&d, TESTDAEMON_BOB);
    uint64_t done = testdaemon_submit_ok(alice, 5, 0, 0);
    uint64_t other = testdaemon_submit_ok(bob, 5, 0, 0);
    testdaemon_wait_state(alice, done, MC_COMPLETED, 120);
    testdaemon_wait_state(bob, other, MC_COMPLETED, 120);
    /* long enough to run through the whole browser session; it is cancelled */
    uint64_t running = testdaemon_submit_ok(alice, 100000, 1, 0);
    testdaemon_wait_state(alice, running, MC_RUNNING, 60);

    static char out[1 << 16];
    int rc = testrunf(out, sizeof out,
                      "/usr/bin/python3 tests/web/test_web.py --url http://127.0.0.1:%d --token %s"
                      " --wrong-token tok-nobody-0123456789 --running %llu --done %llu --other %llu"
                      " --shots build/web-shots 2>&1",
                      port, TESTDAEMON_ALICE, (unsigned long long)running, (unsigned long long)done,
                      (unsigned long long)other);
    printf("%s", out);
    if (rc != 0) {
        testrunf(out, sizeof out, "tail -n 25 %s", d.log);
        FAILF("tests/web/test_web.py exited %d; the daemon's log ends:\n%s", rc, out);
    }
    CHECK(testdaemon_log_has(&d, "login from 127.0.0.1 refused: unknown token (client 'web')"));
    CHECK(testdaemon_log_has(&d, "web login: alice from 127.0.0.1"));
    CHECK_INT(testdaemon_wait_state(alice, running, MC_CANCELLED, 30), MC_CANCELLED);

    /* a token taken out of the tokens file (and a SIGHUP) logs its web user out */
    CHECK_INT(api_status(port, "/api/v1/jobs", TESTDAEMON_ALICE), 200);
    char tokens[640], line[256];
    snprintf(tokens, sizeof tokens, "%s/tokens", d.dir);
    testdaemon_token_line(TESTDAEMON_BOB, "bob", 0, line, sizeof line);
    testdaemon_write_tokens(tokens, line);
    CHECK(kill(d.pid, SIGHUP) == 0);
    for (int i = 0; i < 100 && !testdaemon_log_has(&d, "reload: tokens read"); i++)
        testdaemon_sleep_ms(50);
    CHECK_INT(api_status(port, "/api/v1/jobs", TESTDAEMON_ALICE), 401);
    CHECK_INT(api_status(port, "/api/v1/jobs", TESTDAEMON_BOB), 200);
    mc_close(alice);
    mc_close(bob);
    testdaemon_stop(&d, SIGTERM);
}
