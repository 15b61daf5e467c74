/* test_web_hook.c — --notify-url, black-box: the real daemon with a URL for
 * alice (a listener this test runs on loopback, answering 204) and one for
 * bob (a socket that accepts into its backlog and never answers), a job of
 * each through the real client. alice's note comes once, with the job's id,
 * user and final state, within 2 s of its end although bob's listener is
 * being retried meanwhile; the daemon answers STATUS at once all along; bob's
 * failures are logged and retried. Also the option's checks (no https, a
 * user and a host required). */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "mcd.h"
#include "meshcorr.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

/* A loopback listening socket and its port. */
static int listen_any(int *port)
{
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    struct sockaddr_in a = {0};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t l = sizeof a;
    if (fd < 0 || bind(fd, (struct sockaddr *)&a, sizeof a) || listen(fd, 16) ||
        getsockname(fd, (struct sockaddr *)&a, &l))
        FAILF("listen: %s", strerror(errno));
    *port = ntohs(a.sin_port);
    return fd;
}

/* The listener: each POST's body kept, with the time it came. */
typedef struct listener {
    int fd;
    pthread_mutex_t mu;
    int n;
    char bodies[8][2048];
    double at[8];
} listener;

static void *serve(void *arg)
{
    listener *L = arg;
    for (;;) {
        int c = accept(L->fd, NULL, NULL);
        if (c < 0)
            return NULL;
        char req[8192];
        size_t got = 0;
        char *body = NULL;
        long want = -1;
        while (got < sizeof req - 1) {
            struct pollfd p = {c, POLLIN, 0};
            if (poll(&p, 1, 5000) != 1)
                break;
            ssize_t r = read(c, req + got, sizeof req - 1 - got);
            if (r <= 0)
                break;
            got += (size_t)r;
            req[got] = '\0';
            if (!body && (body = strstr(req, "\r\n\r\n"))) {
                body += 4;
                const char *cl = strcasestr(req, "Content-Length:");
                want = cl ? strtol(cl + 15, NULL, 10) : 0;
            }
            if (body && (long)(req + got - body) >= want)
                break;
        }
        static const char ok[] = "HTTP/1.1 204 No Content\r\nConnection: close\r\n\r\n";
        if (write(c, ok, sizeof ok - 1) < 0) { /* the daemon retries */ }
        close(c);
        pthread_mutex_lock(&L->mu);
        if (body && L->n < 8) {
            snprintf(L->bodies[L->n], sizeof L->bodies[L->n], "%s", body);
            L->at[L->n++] = now_s();
        }
        pthread_mutex_unlock(&L->mu);
    }
}

TEST_T(a_jobs_end_is_posted_once_and_a_dead_listener_delays_nothing, 120)
{
    testdaemon_need_worker();
    listener L = {.mu = PTHREAD_MUTEX_INITIALIZER};
    int port, dead_port;
    L.fd = listen_any(&port);
    int dead = listen_any(&dead_port);       /* never accepted, never answered */
    pthread_t t;
    CHECK(pthread_create(&t, NULL, serve, &L) == 0);
    char a[128], b[128];
    snprintf(a, sizeof a, "alice=http://127.0.0.1:%d/hooks/alice", port);
    snprintf(b, sizeof b, "bob=http://127.0.0.1:%d/dead", dead_port);
    const char *args[] = {"--notify-url", a, "--notify-url", b, "--workers", "2", NULL};
    testdaemon d;
    testdaemon_start(&d, "hook", args);
    mc_client *alice = testdaemon_client(&d, TESTDAEMON_ALICE);
    mc_client *bob = testdaemon_client(&d, TESTDAEMON_BOB);
    uint64_t jb = testdaemon_submit_ok(bob, 5, 0, 0);
    testdaemon_wait_state(bob, jb, MC_COMPLETED, 60);
    uint64_t ja = testdaemon_submit_ok(alice, 5, 0, 0);
    testdaemon_wait_state(alice, ja, MC_COMPLETED, 60);
    double ended = now_s();

    /* alice's note arrives while bob's listener holds a delivery */
    int n = 0;
    for (double t0 = now_s(); now_s() - t0 < 10 && !n; testdaemon_sleep_ms(20)) {
        pthread_mutex_lock(&L.mu);
        n = L.n;
        pthread_mutex_unlock(&L.mu);
    }
    CHECK_INT(n, 1);
    printf("  alice's note came %.0f ms after her job was seen COMPLETED\n", 1000 * (L.at[0] - ended));
    CHECK(L.at[0] - ended < 2.0);
    char want[64];
    snprintf(want, sizeof want, "\"id\":%llu,", (unsigned long long)ja);
    CHECK_STR_HAS(L.bodies[0], want);
    CHECK_STR_HAS(L.bodies[0], "\"user\":\"alice\"");
    CHECK_STR_HAS(L.bodies[0], "\"state\":\"COMPLETED\"");
    CHECK_STR_HAS(L.bodies[0], "\"quality\":{\"verdict\":");

    /* the loop answers at once while bob's deliveries wait for an answer */
    double worst = 0;
    for (int i = 0; i < 20; i++) {
        double t0 = now_s();
        mc_job_status st;
        CHECK_INT(mc_status(bob, jb, &st), 0);
        if (now_s() - t0 > worst)
            worst = now_s() - t0;
        testdaemon_sleep_ms(100);
    }
    printf("  STATUS round trip at most %.1f ms while bob's listener was being tried\n", 1000 * worst);
    CHECK(worst < 0.5);

    /* once per job: nothing more came, and bob's failure was retried */
    testdaemon_sleep_ms(3000);
    pthread_mutex_lock(&L.mu);
    CHECK_INT(L.n, 1);
    pthread_mutex_unlock(&L.mu);
    for (int i = 0; i < 100 && !testdaemon_log_has(&d, "again in 1 s"); i++)
        testdaemon_sleep_ms(100);
    char dead_url[96];
    snprintf(dead_url, sizeof dead_url, "job %llu: notifying http://127.0.0.1:%d/dead failed (no answer within",
             (unsigned long long)jb, dead_port);
    CHECK(testdaemon_log_has(&d, dead_url));
    mc_close(alice);
    mc_close(bob);
    testdaemon_stop(&d, SIGTERM);
    shutdown(L.fd, SHUT_RDWR);
    close(L.fd);
    pthread_join(t, NULL);
    close(dead);
}

TEST(notify_url_takes_admin_given_http_urls_only)
{
    mcd_conf c;
    char err[512];
    conf_init(&c);
    CHECK_INT(conf_set(&c, "notify-url", "alice=http://hooks.example:8080/x", err, sizeof err), 0);
    CHECK_INT(c.nnotify, 1);
    CHECK(conf_set(&c, "notify-url", "bob=https://hooks.example/x", err, sizeof err) != 0);
    CHECK_STR_HAS(err, "no https");
    CHECK(conf_set(&c, "notify-url", "http://hooks.example/x", err, sizeof err) != 0);
    CHECK_STR_HAS(err, "USER=URL");
    CHECK(conf_set(&c, "notify-url", "bob=http://:80/x", err, sizeof err) != 0);
    CHECK_STR_HAS(err, "no host");
    CHECK(conf_set(&c, "notify-url", "bob=http://h:99999/", err, sizeof err) != 0);
    CHECK_STR_HAS(err, "port");
    CHECK(conf_set(&c, "notify-url", "alice=http://other/", err, sizeof err) != 0);
    CHECK_STR_HAS(err, "has a URL already");
    hook_url u;
    CHECK_INT(hook_url_parse("http://[::1]:9/p?q=1", &u, err, sizeof err), 0);
    CHECK(!strcmp(u.host, "::1") && !strcmp(u.port, "9") && !strcmp(u.path, "/p?q=1"));
    CHECK_INT(hook_url_parse("http://h", &u, err, sizeof err), 0);
    CHECK(!strcmp(u.port, "80") && !strcmp(u.path, "/"));
}
