/* bench_submit_check.c — what checking a SUBMIT before SUBMIT_OK costs
 * (meshcorr-validate in a sandboxed child: both meshes decoded by
 * Draco and checked, landmarks and maps against them): the round trip to
 * SUBMIT_OK of the 10K-vertex-class pair 381 -> 390 (6938 + 9239 vertices,
 * with its initial maps) through a daemon with the real programs, against a
 * daemon whose worker and validator programs are /bin/true (the check is
 * then a spawn that does nothing), and the check's own wall time from the daemon's log. Each
 * job is cancelled and ended before the next SUBMIT so nothing runs while
 * one is timed. Prints figures from one run, never fails on time. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "meshcorr.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define NSUBMIT 9

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

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp);
    return v[n / 2];
}

/* Median SUBMIT round trip in ms through a daemon started with args. */
static double round_trips(const char *name, const char *const *args, testdaemon_demo *dm,
                          testdaemon *d)
{
    testdaemon_start(d, name, args);
    mc_client *c = testdaemon_client(d, TESTDAEMON_ALICE);
    double rt[NSUBMIT];
    for (int k = 0; k < NSUBMIT; k++) {
        uint64_t id;
        double t0 = now();
        if (mc_submit(c, &dm->spec, &id))
            FAILF("SUBMIT: %s", mc_errmsg(c));
        rt[k] = 1e3 * (now() - t0);
        mc_cancel(c, id);                    /* refused when it has ended already: fine */
        testdaemon_wait_state(c, id, -1, 60);
    }
    mc_close(c);
    testdaemon_stop(d, SIGTERM);   /* fails unless the daemon exits 0 */
    return median(rt, NSUBMIT);
}

TEST_T(submit_check_of_a_10k_vertex_pair, 600)
{
    testdaemon_need_worker();
    testdaemon_demo dm;
    testdaemon_demo_open(&dm, 1);
    dm.spec.inner_iterations = 1;
    testdaemon d, base;
    double with = round_trips("bench-check", NULL, &dm, &d);
    const char *args[] = {"--worker", "/bin/true", "--validator", "/bin/true", NULL};
    double without = round_trips("bench-check-true", args, &dm, &base);
    double cpu, cpu_true, check = testdaemon_checked_ms(&d, &cpu),
           spawn = testdaemon_checked_ms(&base, &cpu_true);
    printf("SUBMIT 381 -> 390 with maps (%zu + %zu Draco bytes), median of %d:\n"
           "  round trip to SUBMIT_OK: %.1f ms checked, %.1f ms with /bin/true as the check\n"
           "  added by the check: %.1f ms (round trips, ratio %.2f); the check itself %.1f ms wall,\n"
           "  %.1f ms CPU in the child (/bin/true: %.1f ms, %.1f ms CPU)\n",
           dm.spec.source_len, dm.spec.target_len, NSUBMIT, with, without, with - without, with / without,
           check, cpu, spawn, cpu_true);
    testdaemon_demo_close(&dm);
}
