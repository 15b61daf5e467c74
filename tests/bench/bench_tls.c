/* bench_tls.c — what TLS costs a client once connected: one meshcorrd
 * listening on plain TCP and on TLS (loopback both, a certificate made for
 * the run, testtls.h), and the same requests over each, alternating so
 * both see the same machine: PING round trips; SUBMIT round trips to
 * SUBMIT_OK of the 162-vertex icosphere pair and of a 2 x 2 MiB pair (the
 * check and the worker are /bin/true there, so the transport is what is
 * timed); a small job (the 162-vertex pair, 2 iterations, the real worker)
 * from SUBMIT to END and its RESULT. Prints per request the median and the
 * 90th percentile on each transport, their difference and ratio (the aim
 * is at most 2 ms more per request over TLS), and the connect time with
 * its handshake apart. Never fails on time. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testtls.h"
#include "meshcorr.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sorts v; its median and 90th percentile, in ms. */
static void stats(double *v, int n, double *med, double *p90)
{
    qsort(v, (size_t)n, sizeof *v, cmp);
    *med = 1e3 * v[n / 2];
    *p90 = 1e3 * v[(9 * n) / 10 < n ? (9 * n) / 10 : n - 1];
}

static void report(const char *what, double *tcp, double *tls, int n)
{
    double tm, t9, sm, s9;
    stats(tcp, n, &tm, &t9);
    stats(tls, n, &sm, &s9);
    printf("%s, %d each: tcp median %.3f ms (p90 %.3f), tls median %.3f ms (p90 %.3f); tls - tcp %+.3f ms "
           "(p90 %+.3f), ratio %.2f\n", what, n, tm, t9, sm, s9, sm - tm, s9 - t9, sm / tm);
}

static mc_client *dial(const char *addr, const char *ca, double *secs)
{
    mc_client *c = NULL;
    char err[1200];
    double t0 = now();
    if (mc_connect_ca(addr, TESTDAEMON_ALICE, ca, &c, err, sizeof err))
        FAILF("connect %s: %s", addr, err);
    if (secs)
        *secs = now() - t0;
    mc_set_timeout(c, 120000);
    return c;
}

/* The daemon's tls: listener by the name its certificate holds. */
static void tls_addr(const testdaemon *d, char *buf, size_t sz)
{
    snprintf(buf, sz, "tls:localhost:%s", strrchr(d->tls_addr, ':') + 1);
}

#define NCONNECT 30
#define NPING 1000
#define NSUBMIT 100
#define NBIG 12
#define BIG_BYTES (2u << 20)

TEST_T(ping_and_submit_round_trips_over_tls_and_plain_tcp, 600)
{
    testtls t;
    testtls_make(&t, "certs");
    const char *args[24];
    int k = 0;
    testtls_daemon_args(&t, args, &k);
    const char *more[] = {"--worker", "/bin/true", "--validator", "/bin/true", "--max-jobs-per-user", "100000",
                          "--max-queue", "100000", NULL};
    for (int i = 0; more[i]; i++)
        args[k++] = more[i];
    args[k] = NULL;
    testdaemon d;
    testdaemon_start(&d, "bench-tls", args);
    char saddr[128];
    tls_addr(&d, saddr, sizeof saddr);

    static double a[NPING], b[NPING];
    for (int i = 0; i < NCONNECT; i++) {
        mc_client *x = dial(d.tcp_addr, NULL, &a[i]), *y = dial(saddr, t.ca, &b[i]);
        mc_close(x);
        mc_close(y);
    }
    report("connect and HELLO (TLS: handshake, CA file read, certificate checked)", a, b, NCONNECT);

    mc_client *tcp = dial(d.tcp_addr, NULL, NULL), *tls = dial(saddr, t.ca, NULL);
    for (int i = 0; i < NPING; i++) {
        double t0 = now();
        CHECK_INT(mc_ping(tcp), 0);
        double t1 = now();
        CHECK_INT(mc_ping(tls), 0);
        a[i] = t1 - t0;
        b[i] = now() - t1;
    }
    report("PING round trip", a, b, NPING);

    for (int i = 0; i < NSUBMIT; i++) {
        double t0 = now();
        testdaemon_submit_ok(tcp, 2, 0, 0);
        double t1 = now();
        testdaemon_submit_ok(tls, 2, 0, 0);
        a[i] = t1 - t0;
        b[i] = now() - t1;
    }
    report("SUBMIT round trip, 162-vertex pair (encoding included)", a, b, NSUBMIT);

    unsigned char *blob = malloc(BIG_BYTES);
    CHECK(blob != NULL);
    for (size_t i = 0; i < BIG_BYTES; i++)
        blob[i] = (unsigned char)(i * 2654435761u >> 13);
    mc_job_spec spec;
    mc_job_spec_init(&spec);
    spec.source = spec.target = blob;
    spec.source_len = spec.target_len = BIG_BYTES;
    static const uint32_t lm[] = {0, 0, 1, 1, 2, 2, 3, 3};
    spec.landmarks = lm;
    spec.nlandmarks = 4;
    spec.label = "bench_tls big";
    for (int i = 0; i < NBIG; i++) {
        uint64_t id;
        double t0 = now();
        CHECK_INT(mc_submit(tcp, &spec, &id), 0);
        double t1 = now();
        CHECK_INT(mc_submit(tls, &spec, &id), 0);
        a[i] = t1 - t0;
        b[i] = now() - t1;
    }
    report("SUBMIT round trip, 2 x 2 MiB blobs", a, b, NBIG);
    free(blob);
    mc_close(tcp);
    mc_close(tls);
    testdaemon_stop(&d, SIGTERM);
}

#define NJOB 10

/* submit, watch to END, RESULT of both maps: the wall time. */
static double small_job(mc_client *c)
{
    double t0 = now();
    uint64_t id = testdaemon_submit_ok(c, 2, 0, 0);
    int state = -1;
    char reason[1100];
    CHECK_INT(mc_watch(c, id, 0, NULL, NULL, &state, reason, sizeof reason), 0);
    if (state != MC_COMPLETED)
        FAILF("job ended %s: %s", mc_state_name(state), reason);
    mc_job_result r;
    CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q, &r), 0);
    mc_result_free(&r);
    return now() - t0;
}

TEST_T(a_small_job_over_tls_and_plain_tcp, 600)
{
    testdaemon_need_worker();
    testtls t;
    testtls_make(&t, "certs");
    const char *args[12];
    int k = 0;
    testtls_daemon_args(&t, args, &k);
    args[k] = NULL;
    testdaemon d;
    testdaemon_start(&d, "bench-tls-job", args);
    char saddr[128];
    tls_addr(&d, saddr, sizeof saddr);
    mc_client *tcp = dial(d.tcp_addr, NULL, NULL), *tls = dial(saddr, t.ca, NULL);
    small_job(tcp);                            /* the first start of the worker program is slower */
    double a[NJOB], b[NJOB];
    for (int i = 0; i < NJOB; i++) {
        a[i] = small_job(tcp);
        b[i] = small_job(tls);
    }
    report("small job, 162-vertex pair, 3 RHM + 2 ECTM iterations: SUBMIT to END, then RESULT", a, b, NJOB);
    mc_close(tcp);
    mc_close(tls);
    testdaemon_stop(&d, SIGTERM);
}
