/* test_sec_guessing.c — guessing tokens against a real meshcorrd: a loop
 * of wrong HELLOs from one address, as fast as the server answers. After a
 * few tries the address must get its HELLOs refused unchecked (BUSY, "too
 * many failed logins from ADDR, retry in N s"), so the tokens checked stay
 * far below what a loop could try; the log must name the address without
 * a line per try; a real token from that address while it waits is refused
 * too (the wait tells the guesser nothing); and a user from another
 * address logs in at once. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testraw.h"
#include "meshcorr.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define GUESS_S 4.0

/* Lines of the daemon's log above debug level that contain what. */
static int log_count(const testdaemon *d, const char *what)
{
    FILE *fp = fopen(d->log, "r");
    if (!fp)
        return 0;
    char line[8192];
    int n = 0;
    while (fgets(line, sizeof line, fp))
        n += strstr(line, what) != NULL && strncmp(line, "<7>", 3) != 0;
    fclose(fp);
    return n;
}

TEST_T(a_token_guessing_loop_is_slowed_to_a_few_tries_and_logged_with_its_address, 90)
{
    testdaemon d;
    testdaemon_start(&d, "guess", NULL);
    int tries = 0, checked = 0, waiting = 0;
    char msg[1200], wait_msg[1200] = "";
    double t0 = testraw_now();
    while (testraw_now() - t0 < GUESS_S) {
        char guess[64];
        snprintf(guess, sizeof guess, "mc_guess-%06d", tries);
        int fd = testraw_tcp(d.tcp_addr, "127.0.0.1");
        int code = 0, type = testraw_hello(fd, guess, "guesser", &code, msg, sizeof msg, 5);
        close(fd);
        tries++;
        if (type != PROTO_MSG_ERROR)
            FAILF("wrong token %s: %s", guess, type < 0 ? "no answer" : proto_type_name(type));
        if (code == PROTO_EUNAUTHORIZED) {
            checked++;
        } else if (code == PROTO_EBUSY) {
            waiting++;
            snprintf(wait_msg, sizeof wait_msg, "%s", msg);
        } else {
            FAILF("wrong token %s: %s %s", guess, proto_err_name(code), msg);
        }
    }
    double rate = checked / GUESS_S;
    printf("  %d HELLOs in %.0f s: %d tokens checked (%.1f a second), %d refused unchecked: %s\n", tries, GUESS_S,
           checked, rate, waiting, wait_msg);
    CHECK(rate < 5);
    CHECK(waiting > 0);
    CHECK_STR_HAS(wait_msg, "too many failed logins from 127.0.0.1");
    CHECK_STR_HAS(wait_msg, "retry in ");

    /* a real token from that address is refused unchecked while it waits */
    int fd = testraw_tcp(d.tcp_addr, "127.0.0.1");
    int code = 0;
    CHECK_INT(testraw_hello(fd, TESTDAEMON_BOB, "guesser", &code, msg, sizeof msg, 5), PROTO_MSG_ERROR);
    CHECK_INT(code, PROTO_EBUSY);
    close(fd);

    /* another address is not affected: alice logs in at once */
    double t1 = testraw_now();
    fd = testraw_tcp(d.tcp_addr, "127.0.0.2");
    if (testraw_hello(fd, TESTDAEMON_ALICE, "alice", &code, msg, sizeof msg, 5) != PROTO_MSG_HELLO_OK)
        FAILF("alice from 127.0.0.2: %s %s", proto_err_name(code), msg);
    CHECK_INT(testraw_ask(fd, PROTO_MSG_STATS, 2, 5), PROTO_MSG_STATS_OK);
    close(fd);
    CHECK(testraw_now() - t1 < 1);

    /* the log names the address: the first failure at once, then a sum,
     * never a line per try */
    CHECK(testdaemon_log_has(&d, "login from 127.0.0.1 refused: unknown token (client 'guesser')"));
    for (int i = 0; i < 750 && !testdaemon_log_has(&d, "failed logins from 127.0.0.1 in the last"); i++)
        testdaemon_sleep_ms(20);
    CHECK(testdaemon_log_has(&d, "failed logins from 127.0.0.1 in the last"));
    int lines = log_count(&d, "127.0.0.1");
    printf("  %d log lines (debug lines aside) name 127.0.0.1\n", lines);
    CHECK(lines <= 6);
    testdaemon_stop(&d, SIGTERM);
}
