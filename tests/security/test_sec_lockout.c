/* test_sec_lockout.c — attacks that try to keep everyone out of a real
 * meshcorrd without logging in: hundreds of idle TCP sockets (one byte
 * each) from one loopback address or from many, TCP clients at the
 * descriptor limit, and idle sockets on the Slurm progress listener. Each
 * time the Unix socket, an admin's TCP session from the attacker's own
 * address and a user from another address must still be served (HELLO_OK
 * and an answer to STATS or LIST), and the log must name the limit. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testraw.h"
#include "meshcorr.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#define NIDLE 300

/* Raises this process's descriptor limit to hold n more sockets. */
static void room_for(int n)
{
    struct rlimit rl;
    CHECK(getrlimit(RLIMIT_NOFILE, &rl) == 0);
    rlim_t want = (rlim_t)n + 256;
    if (rl.rlim_cur >= want)
        return;
    if (rl.rlim_max != RLIM_INFINITY && rl.rlim_max < want)
        SKIP("the test needs %llu descriptors; the hard limit is %llu", (unsigned long long)want,
             (unsigned long long)rl.rlim_max);
    rl.rlim_cur = want;
    CHECK(setrlimit(RLIMIT_NOFILE, &rl) == 0);
}

/* n idle TCP sockets, each from the source address src(i), each having
 * sent one byte (the first of a frame's magic). */
static void open_idle(const testdaemon *d, int *fds, int n, const char *(*src)(int i))
{
    for (int i = 0; i < n; i++) {
        fds[i] = testraw_tcp(d->tcp_addr, src(i));
        testraw_send(fds[i], "M", 1);
    }
}

static const char *from_one(int i)
{
    (void)i;
    return "127.0.0.1";
}

static const char *from_many(int i)
{
    static char ip[32];
    snprintf(ip, sizeof ip, "127.0.0.%d", 10 + i % 50);   /* 50 addresses, 6 sockets each */
    return ip;
}

/* The Unix socket, an admin over TCP (from 127.0.0.1, where the attack
 * comes from too) and alice over TCP from 127.0.0.2 are each served at once. */
static void everyone_is_served(const testdaemon *d)
{
    double t0 = testraw_now();
    char err[1024];
    mc_client *u = NULL;
    int rc = mc_connect(d->unix_addr, NULL, &u, err, sizeof err);
    if (rc)
        FAILF("the Unix socket refused root: %s (%s)", mc_strerror(rc), err);
    mc_server_stats st;
    CHECK_INT(mc_stats(u, &st), 0);
    mc_stats_free(&st);
    mc_close(u);

    mc_client *boss = NULL;
    rc = mc_connect(d->tcp_addr, TESTDAEMON_ADMIN, &boss, err, sizeof err);
    if (rc)
        FAILF("the admin's TCP session was refused: %s (%s)", mc_strerror(rc), err);
    mc_job_info *jobs = NULL;
    uint32_t n = 0;
    CHECK_INT(mc_list(boss, NULL, 0, &jobs, &n), 0);
    free(jobs);
    mc_close(boss);

    int fd = testraw_tcp(d->tcp_addr, "127.0.0.2");
    int code = 0;
    int type = testraw_hello(fd, TESTDAEMON_ALICE, "test_sec_lockout", &code, err, sizeof err, 5);
    if (type != PROTO_MSG_HELLO_OK)
        FAILF("alice from 127.0.0.2 was not let in: %s %s", type < 0 ? "no answer" : proto_err_name(code), err);
    CHECK_INT(testraw_ask(fd, PROTO_MSG_STATS, 7, 5), PROTO_MSG_STATS_OK);
    close(fd);
    double took = testraw_now() - t0;
    printf("  Unix socket, admin from 127.0.0.1 and alice from 127.0.0.2 served in %.2f s\n", took);
    CHECK(took < 3);
}

/* Sockets of fds the server neither refused (ERROR BUSY waiting to be
 * read) nor closed: those it keeps as connections waiting for HELLO. */
static int still_open(int *fds, int n)
{
    int open = 0;
    for (int i = 0; i < n; i++) {
        struct pollfd pf = {fds[i], POLLIN, 0};
        open += poll(&pf, 1, 0) == 0;
    }
    return open;
}

/* NIDLE idle sockets from src(i), twice over (the attacker reconnects):
 * each time everyone is served, at most max_open of them are kept, and the
 * log names the cap (log_has). */
static void idle_attack(const char *name, const char *(*src)(int i), const char *from, int max_open,
                        const char *log_has)
{
    room_for(NIDLE);
    static const char *const args[] = {"--hello-timeout", "60", NULL};
    testdaemon d;
    testdaemon_start(&d, name, args);
    static int fds[NIDLE];
    for (int round = 0; round < 2; round++) {
        open_idle(&d, fds, NIDLE, src);
        testdaemon_sleep_ms(500);
        everyone_is_served(&d);
        int open = still_open(fds, NIDLE);
        printf("  round %d: %d of %d idle sockets from %s still open\n", round + 1, open, NIDLE, from);
        CHECK(open <= max_open);
        for (int i = 0; i < NIDLE; i++)
            close(fds[i]);
    }
    CHECK(testdaemon_log_has(&d, log_has));
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(idle_tcp_sockets_from_one_address_lock_no_one_out, 90)
{
    idle_attack("one_address", from_one, "127.0.0.1", 8,
                "connections without HELLO from 127.0.0.1, the limit (--max-unauthenticated-per-address)");
}

TEST_T(idle_tcp_sockets_from_many_addresses_lock_no_one_out, 90)
{
    idle_attack("many_addresses", from_many, "50 addresses", 64,
                "TCP connections without HELLO, the limit (--max-unauthenticated)");
}

/* With the per-address and total caps lifted, idle TCP clients run into the
 * descriptor floor: the daemon at 256 descriptors stops taking them while
 * fd-reserve + admin-reserve are free, so the Unix socket is still served,
 * and an admin's TCP client takes the place of the oldest idle one. */
TEST_T(idle_tcp_sockets_at_the_descriptor_limit_leave_the_unix_socket_and_admins_served, 90)
{
    room_for(NIDLE);
    static const char *const args[] = {"--hello-timeout", "60", "--max-unauthenticated", "100000",
                                       "--max-unauthenticated-per-address", "100000", NULL};
    testdaemon d;
    testdaemon_start(&d, "fd_floor", args);
    struct rlimit low = {256, 256};
    if (testdaemon_prlimit(&d, RLIMIT_NOFILE, &low, NULL) != 0)
        FAILF("prlimit: %s", strerror(errno));
    static int fds[NIDLE];
    open_idle(&d, fds, NIDLE, from_one);
    testdaemon_sleep_ms(500);
    int held = testraw_fd_count(d.pid);
    printf("  the daemon holds %d descriptors of 256 after %d idle TCP clients\n", held, NIDLE);
    CHECK(held > 0 && held <= 200);   /* fd-reserve (32 + 4) and admin-reserve (32) of 256 stay free */
    char err[1024];
    mc_client *u = NULL;
    int rc = mc_connect(d.unix_addr, NULL, &u, err, sizeof err);
    if (rc)
        FAILF("the Unix socket refused root: %s (%s)", mc_strerror(rc), err);
    mc_server_stats st;
    CHECK_INT(mc_stats(u, &st), 0);
    mc_stats_free(&st);
    mc_client *boss = NULL;
    rc = mc_connect(d.tcp_addr, TESTDAEMON_ADMIN, &boss, err, sizeof err);
    if (rc)
        FAILF("the admin's TCP session was refused: %s (%s)", mc_strerror(rc), err);
    CHECK_INT(mc_ping(boss), 0);
    CHECK(testdaemon_log_has(&d, "more for the Unix socket and admins (--admin-reserve)"));
    mc_close(boss);
    mc_close(u);
    for (int i = 0; i < NIDLE; i++)
        close(fds[i]);
    testdaemon_stop(&d, SIGTERM);
}

/* The port of the Slurm progress listener from the daemon's log, and its
 * host in host (the listener binds loopback unless configured). */
static int progress_port(const testdaemon *d, char *host, size_t hsz)
{
    for (int i = 0; i < 500; i++) {
        FILE *fp = fopen(d->log, "r");
        char line[4096];
        while (fp && fgets(line, sizeof line, fp)) {
            const char *at = strstr(line, "slurm: progress listener on ");
            char h[64];
            int port;
            if (at && sscanf(at, "slurm: progress listener on %63[^:]:%d", h, &port) == 2) {
                fclose(fp);
                snprintf(host, hsz, "%s", h);
                return port;
            }
        }
        if (fp)
            fclose(fp);
        testdaemon_sleep_ms(20);
    }
    FAILF("no progress listener in %s", d->log);
    return -1;
}

#define NPROG 600

TEST_T(idle_sockets_on_the_slurm_progress_listener_are_capped_and_cut, 90)
{
    room_for(NPROG);
    static const char *const args[] = {"--backend", "slurm", "--slurm-max-jobs", "4", "--slurm-poll-ms", "3600000",
                                       NULL};
    testdaemon d;
    testdaemon_start(&d, "progress", args);
    char host[64], addr[128];
    int port = progress_port(&d, host, sizeof host);
    CHECK_STR_HAS(host, "127.0.0.1");               /* loopback unless configured */
    snprintf(addr, sizeof addr, "tcp:127.0.0.1:%d", port);
    struct rlimit low = {256, 256};
    if (testdaemon_prlimit(&d, RLIMIT_NOFILE, &low, NULL) != 0)
        FAILF("prlimit: %s", strerror(errno));
    static int fds[NPROG];
    for (int i = 0; i < NPROG; i++)
        fds[i] = testraw_tcp(addr, NULL);
    testdaemon_sleep_ms(500);
    int held = testraw_fd_count(d.pid);
    printf("  the daemon holds %d descriptors after %d idle progress connections\n", held, NPROG);
    CHECK(held > 0 && held < 120);
    char err[1024];
    mc_client *u = NULL;
    int rc = mc_connect(d.unix_addr, NULL, &u, err, sizeof err);
    if (rc)
        FAILF("the Unix socket refused root: %s (%s)", mc_strerror(rc), err);
    mc_server_stats st;
    CHECK_INT(mc_stats(u, &st), 0);
    mc_stats_free(&st);
    mc_close(u);
    /* the ones still open are cut when they have not identified themselves in time */
    double t0 = testraw_now();
    int open = 0;
    for (int i = 0; i < NPROG; i++) {
        double left = 15 - (testraw_now() - t0);
        open += !testraw_closed_within(fds[i], left > 0.05 ? left : 0.05);
    }
    printf("  %d progress connections still open %.1f s later\n", open, testraw_now() - t0);
    CHECK_INT(open, 0);
    CHECK(testdaemon_log_has(&d, "progress connection from 127.0.0.1 closed: "));
    for (int i = 0; i < NPROG; i++)
        close(fds[i]);
    testdaemon_stop(&d, SIGTERM);
}
