/* bench_web.c — the web UI's cost to the job server: one long job running,
 * first watched by 1 browser, then by 50, each doing what the job page does
 * when it polls (GET /api/v1/jobs/ID every second and the history from
 * where it left off; the page and its script once at the start), while a
 * protocol client measures STATUS round trips. Per phase: the event loop
 * thread's CPU (ms per second, /proc/PID/task/PID/stat), the whole
 * daemon's CPU (the HTTP threads included), STATUS and HTTP latencies
 * (median, 99th percentile); then the ratios of 50 watchers to 1. Prints
 * figures, never fails on time. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testhttp.h"
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

#define WATCHERS 50
#define PHASE_S 10
#define MAX_SAMPLES 20000

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* CPU seconds (user + system) of /proc/<pid>/stat or .../task/<tid>/stat. */
static double cpu_s(const char *path)
{
    FILE *fp = fopen(path, "r");
    CHECK(fp != NULL);
    char buf[1024];
    size_t n = fread(buf, 1, sizeof buf - 1, fp);
    fclose(fp);
    buf[n] = '\0';
    const char *p = strrchr(buf, ')');
    CHECK(p != NULL);
    unsigned long long ut = 0, st = 0;
    CHECK(sscanf(p + 2, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &ut, &st) == 2);
    return (double)(ut + st) / (double)sysconf(_SC_CLK_TCK);
}

typedef struct samples {
    pthread_mutex_t mu;
    double v[MAX_SAMPLES];
    int n;
} samples;

static void add(samples *s, double v)
{
    pthread_mutex_lock(&s->mu);
    if (s->n < MAX_SAMPLES)
        s->v[s->n++] = v;
    pthread_mutex_unlock(&s->mu);
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double quantile(samples *s, double q)
{
    if (!s->n)
        return 0;
    qsort(s->v, (size_t)s->n, sizeof s->v[0], cmp);
    return s->v[(int)(q * (s->n - 1))];
}

/* One GET with the token; the body into out (NUL-terminated); the status. */
static int get(int port, const char *path, char *out, size_t osz)
{
    return testhttp_request(port, "GET", path, "Authorization: Bearer " TESTDAEMON_ALICE "\r\n", NULL, out, osz,
                            10000);
}

typedef struct watcher {
    pthread_t t;
    int port;
    uint64_t job;
    volatile int *stop;
    samples *http;
    int errors;
} watcher;

static void *watch(void *arg)
{
    watcher *w = arg;
    size_t bsz = 16u << 20;       /* a whole history answer (5000 records) fits */
    char *body = malloc(bsz), path[128];
    CHECK(body != NULL);
    snprintf(path, sizeof path, "/jobs/%llu", (unsigned long long)w->job);
    if (get(w->port, path, body, bsz) != 200 || get(w->port, "/static/job.js", body, bsz) != 200)
        w->errors++;
    unsigned long long after = 0;
    while (!*w->stop) {
        double t0 = now();
        snprintf(path, sizeof path, "/api/v1/jobs/%llu", (unsigned long long)w->job);
        int a = get(w->port, path, body, bsz);
        add(w->http, now() - t0);
        snprintf(path, sizeof path, "/api/v1/jobs/%llu/history?after=%llu", (unsigned long long)w->job, after);
        double t1 = now();
        int b = get(w->port, path, body, bsz);
        add(w->http, now() - t1);
        const char *next = strstr(body, "],\"next\":");
        if (next)
            next += 2;
        if (next)
            after = strtoull(next + 7, NULL, 10);
        if (a != 200 || b != 200)
            w->errors++;
        double left = 1.0 - (now() - t0);
        if (left > 0)
            testdaemon_sleep_ms((int)(1000 * left));
    }
    free(body);
    return NULL;
}

typedef struct phase {
    double loop_ms_per_s, all_ms_per_s;
    double status_med, status_p99, http_med, http_p99;
    int errors, requests;
} phase;

static void run_phase(const testdaemon *d, mc_client *c, int port, uint64_t job, int nwatchers, phase *out)
{
    static samples http, status;
    http.n = status.n = 0;
    pthread_mutex_init(&http.mu, NULL);
    pthread_mutex_init(&status.mu, NULL);
    volatile int stop = 0;
    static watcher w[WATCHERS];
    for (int i = 0; i < nwatchers; i++) {
        w[i] = (watcher){0, port, job, &stop, &http, 0};
        CHECK(pthread_create(&w[i].t, NULL, watch, &w[i]) == 0);
    }
    testdaemon_sleep_ms(4000);                /* every watcher has loaded its page and whole history */
    char loop[64], all[64];
    snprintf(loop, sizeof loop, "/proc/%d/task/%d/stat", (int)d->pid, (int)d->pid);
    snprintf(all, sizeof all, "/proc/%d/stat", (int)d->pid);
    pthread_mutex_lock(&http.mu);
    http.n = 0;                               /* the window's requests only */
    pthread_mutex_unlock(&http.mu);
    double c0 = cpu_s(loop), a0 = cpu_s(all), t0 = now();
    while (now() - t0 < PHASE_S) {
        mc_job_status st;
        double s0 = now();
        CHECK_INT(mc_status(c, job, &st), 0);
        add(&status, now() - s0);
        testdaemon_sleep_ms(50);
    }
    double dt = now() - t0;
    out->loop_ms_per_s = 1000 * (cpu_s(loop) - c0) / dt;
    out->all_ms_per_s = 1000 * (cpu_s(all) - a0) / dt;
    out->requests = http.n;
    stop = 1;
    out->errors = 0;
    for (int i = 0; i < nwatchers; i++) {
        pthread_join(w[i].t, NULL);
        out->errors += w[i].errors;
    }
    out->status_med = 1000 * quantile(&status, 0.5);
    out->status_p99 = 1000 * quantile(&status, 0.99);
    out->http_med = 1000 * quantile(&http, 0.5);
    out->http_p99 = 1000 * quantile(&http, 0.99);
}

static void print_phase(const char *name, const phase *p)
{
    printf("  %-11s loop thread %6.1f ms CPU/s, daemon %6.1f ms CPU/s; STATUS median %.2f ms, p99 %.2f ms; "
           "HTTP %d requests in %d s, median %.2f ms, p99 %.2f ms; %d errors\n",
           name, p->loop_ms_per_s, p->all_ms_per_s, p->status_med, p->status_p99, p->requests, PHASE_S,
           p->http_med, p->http_p99, p->errors);
}

static double ratio(double a, double b)
{
    return b > 0 ? a / b : 0;
}

TEST_T(web_page_and_api_under_50_watchers_of_one_running_job, 300)
{
    testdaemon_need_worker();
    int port = testhttp_free_port();
    char http[16];
    snprintf(http, sizeof http, "%d", port);
    const char *args[] = {"--http", http, "--workers", "1", NULL};
    testdaemon d;
    testdaemon_start(&d, "bench-web", args);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t job = testdaemon_submit_ok(c, 100000, 1, 0);
    testdaemon_wait_state(c, job, MC_RUNNING, 60);
    testdaemon_sleep_ms(2000);
    phase idle, busy;
    run_phase(&d, c, port, job, 1, &idle);
    run_phase(&d, c, port, job, WATCHERS, &busy);
    printf("  one job running (642-vertex icosphere pair), %d s per phase:\n", PHASE_S);
    print_phase("1 watcher", &idle);
    print_phase("50 watchers", &busy);
    printf("  50 watchers / 1: loop thread CPU %.2fx, daemon CPU %.2fx, STATUS median %.2fx, p99 %.2fx, "
           "HTTP median %.2fx, p99 %.2fx\n",
           ratio(busy.loop_ms_per_s, idle.loop_ms_per_s), ratio(busy.all_ms_per_s, idle.all_ms_per_s),
           ratio(busy.status_med, idle.status_med), ratio(busy.status_p99, idle.status_p99),
           ratio(busy.http_med, idle.http_med), ratio(busy.http_p99, idle.http_p99));
    CHECK_INT(mc_cancel(c, job), 0);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
