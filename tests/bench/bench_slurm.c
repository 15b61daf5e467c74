/* bench_slurm.c — what the Slurm backend costs against the local one: one
 * quick job alone (submit to END), then 20 quick jobs submitted at once
 * (first submit to last END), on meshcorrd with backend=local (2 worker
 * slots) and backend=slurm (a private single-node Slurm with 2 CPUs, one
 * CPU per job; testslurm.h). Each job is the small icosphere pair, 3 outer
 * iterations. Prints the figures and the per-job overhead; fails only when
 * something cannot run. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testslurm.h"
#include "meshcorr.h"

#include <signal.h>
#include <stdlib.h>
#include <time.h>

#define NJOBS 20

__attribute__((constructor(101))) static void enter_slurm(int argc, char **argv)
{
    setenv("SLURM_TEST_CPUS", "2", 0);     /* as many CPUs as local worker slots */
    testslurm_enter(argc, argv);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Seconds from the first submit to the last end of n jobs. */
static double run_jobs(const testdaemon *d, int n)
{
    mc_client *c = testdaemon_client(d, TESTDAEMON_ALICE);
    uint64_t ids[NJOBS];
    double t0 = now();
    for (int i = 0; i < n; i++) {
        int rc;
        ids[i] = testdaemon_submit(c, 3, 0, 0, &rc);
        if (rc)
            FAILF("SUBMIT: %s", mc_errmsg(c));
    }
    for (int i = 0; i < n; i++) {
        int end = -1;
        char reason[1100];
        if (mc_watch(c, ids[i], 1u << 30, NULL, NULL, &end, reason, sizeof reason) || end != MC_COMPLETED)
            FAILF("job %llu: %s %s", (unsigned long long)ids[i], mc_state_name(end), reason);
    }
    double t = now() - t0;
    mc_close(c);
    return t;
}

TEST_T(slurm_backend_overhead_against_local_20_jobs, 300)
{
    testslurm_need();
    testdaemon ld, sd;
    const char *local_args[] = {"--workers", "2", NULL};
    testdaemon_start(&ld, "bench-local", local_args);
    testslurm_daemon(&sd, "bench-slurm", NULL);
    double l1 = run_jobs(&ld, 1), s1 = run_jobs(&sd, 1);
    double ln = run_jobs(&ld, NJOBS), sn = run_jobs(&sd, NJOBS);
    printf("  one job, submit to END:   local %.2f s, slurm %.2f s (+%.2f s)\n", l1, s1, s1 - l1);
    printf("  %d jobs, first submit to last END: local %.2f s, slurm %.2f s\n", NJOBS, ln, sn);
    printf("  per job: local %.3f s, slurm %.3f s; overhead %.3f s per job\n", ln / NJOBS, sn / NJOBS,
           (sn - ln) / NJOBS);
    testdaemon_stop(&ld, SIGTERM);
    testdaemon_stop(&sd, SIGTERM);
}
