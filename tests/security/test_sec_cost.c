/* test_sec_cost.c — a job's cost is bounded at SUBMIT. The SUBMIT check
 * (meshcorr-validate) estimates the worker's peak memory from the decoded
 * sizes (corr_cost_bytes); real runs of meshcorr-worker on icosphere
 * pairs (few and many landmarks, each start), the demo's cow -> camel pair
 * and a SHREC'07 pair with its initial maps (ECTM, and DDM then ECTM) peak
 * below the estimate and above a quarter of it. Against a real daemon with
 * a 4096 MB worker limit, 65536 landmarks on two 163842-vertex meshes are
 * refused OVER_LIMIT naming the estimate, the limit and what drives it,
 * nothing is stored, and a small job still runs. */
#include "support/harness.h"
#include "support/testcowcamel.h"
#include "support/testdaemon.h"
#include "support/testjob.h"
#include "support/testmesh.h"
#include "corr/corr.h"
#include "meshcorr.h"
#include "proto.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#define WORKER "build/meshcorr-worker"
#define VALIDATOR "build/meshcorr-validate"
#define MB 1048576.0

extern char **environ;

/* Runs argv with stdin from in (NULL: none), stdout into a pipe whose
 * bytes go to out[0..*outlen) (out NULL: none; the validator may write no
 * file), stderr to the test's directory: its exit status, and its peak
 * resident memory in bytes in *peak (may be NULL). */
static int run(char *const argv[], const char *in, uint8_t *out, size_t *outlen, double *peak)
{
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    char errpath[600];
    snprintf(errpath, sizeof errpath, "%s/%s.stderr", harness_tmpdir(), strrchr(argv[0], '/') + 1);
    int p[2] = {-1, -1};
    if (out) {
        CHECK(pipe2(p, O_CLOEXEC) == 0);
        posix_spawn_file_actions_adddup2(&fa, p[1], 1);
    }
    if (in)
        posix_spawn_file_actions_addopen(&fa, 0, in, O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, errpath, O_WRONLY | O_CREAT | O_APPEND, 0644);
    pid_t pid;
    int e = posix_spawn(&pid, argv[0], &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (e)
        FAILF("cannot start %s: %s", argv[0], strerror(e));
    if (out) {
        close(p[1]);
        size_t got = 0;
        ssize_t r;
        while (got < *outlen && ((r = read(p[0], out + got, *outlen - got)) > 0 || (r < 0 && errno == EINTR)))
            got += r > 0 ? (size_t)r : 0;
        close(p[0]);
        *outlen = got;
    }
    int st;
    struct rusage ru;
    while (wait4(pid, &st, 0, &ru) < 0)
        CHECK(errno == EINTR);
    if (peak)
        *peak = (double)ru.ru_maxrss * 1024;
    if (!WIFEXITED(st))
        FAILF("%s ended by signal %d; see %s", argv[0], WTERMSIG(st), errpath);
    return WEXITSTATUS(st);
}

/* The validator's estimate of the job in dir: its refusal under a 1 MB
 * worker limit names it ("about 78 MB at its peak for ..."); bytes, and
 * what drives it in what. */
static double estimate(const char *dir, char *what, size_t wsz)
{
    char in[700];
    snprintf(in, sizeof in, "%s/job.frame", dir);
    char *argv[] = {VALIDATOR, "--worker-memory-mb", "1", NULL};
    static uint8_t buf[1 << 16];
    size_t n = sizeof buf, used;
    CHECK_INT(run(argv, in, buf, &n, NULL), 1);
    proto_msg m;
    char err[256];
    CHECK_INT(proto_decode(buf, n, sizeof buf, &m, &used, err, sizeof err), PROTO_READY);
    CHECK_INT(m.type, PROTO_MSG_ERROR);
    CHECK_INT(m.u.error.code, PROTO_EOVER_LIMIT);
    double v = 0;
    char unit[8] = "";
    const char *at = strstr(m.u.error.message, "about ");
    if (!at || sscanf(at, "about %lf %7s", &v, unit) != 2)
        FAILF("no estimate in \"%s\"", m.u.error.message);
    static const char *const units[] = {"bytes", "kB", "MB", "GB", "TB", "PB"};
    double scale = 0, s = 1;
    for (int u = 0; u < 6; u++, s *= 1000)
        if (strcmp(unit, units[u]) == 0)
            scale = s;
    if (!(scale > 0))
        FAILF("unit '%s' in \"%s\"", unit, m.u.error.message);
    const char *f = strstr(m.u.error.message, " at its peak for "), *e = strstr(m.u.error.message, ", over the");
    snprintf(what, wsz, "%.*s", f && e > f ? (int)(e - f - strlen(" at its peak for ")) : 1,
             f && e > f ? f + strlen(" at its peak for ") : "?");
    proto_msg_free(&m);
    return v * scale;
}

/* The job in dir run by the real worker (2 threads): its peak resident
 * memory in bytes; the run must succeed. */
static double worker_peak(const char *dir)
{
    char *argv[] = {WORKER, "--job", (char *)dir, "--job-id", "1", "--threads", "2", NULL};
    double peak;
    int rc = run(argv, NULL, NULL, NULL, &peak);
    if (rc)
        FAILF("meshcorr-worker on %s exited %d; see %s/meshcorr-worker.stderr", dir, rc, harness_tmpdir());
    return peak;
}

/* The estimate is over the run's peak and at most `few` times it. */
static void compare(const char *name, const char *dir, double few)
{
    char what[512];
    double est = estimate(dir, what, sizeof what), peak = worker_peak(dir);
    printf("  %-34s peak %7.1f MB, estimate %7.1f MB (%.2fx), driven by %s\n", name, peak / MB, est / MB,
           est / peak, what);
    if (est < peak)
        FAILF("%s: the estimate %.1f MB is under the run's peak %.1f MB", name, est / MB, peak / MB);
    if (est > few * peak)
        FAILF("%s: the estimate %.1f MB is over %g times the run's peak %.1f MB", name, est / MB, few, peak / MB);
}

/* A job directory under the test's: job.frame of the meshes at sp and tp
 * (files), nl identity or given landmark pairs, the maps p0/q0 (files or
 * NULL), few iterations of each stage, and the given start and stages. */
static const char *job_dir(const char *name, const char *sp, const char *tp, const proto_landmark *lm, unsigned nl,
                           const char *p0, const char *q0, int start, int stages)
{
    static char dir[700];
    snprintf(dir, sizeof dir, "%s/%s", harness_tmpdir(), name);
    testjob j;
    char err[1024];
    if (testjob_build(&j, sp, tp, lm, nl, p0, q0, NULL, err, sizeof err))
        FAILF("%s: %s", name, err);
    proto_params *pp = &j.msg.u.submit.params;
    pp->iterations = 3;
    pp->inner_iterations = 10;
    pp->beta_ramp = 3;
    pp->rhm_iterations = 3;
    pp->start = (uint8_t)start;
    pp->stages = (uint8_t)stages;
    if (testjob_save(&j, dir, err, sizeof err))
        FAILF("%s: %s", name, err);
    testjob_close(&j);
    return dir;
}

/* The icosphere pair of testdaemon_pair at this level, as two OFF files. */
static void sphere_files(int level, char *sp, char *tp, size_t sz)
{
    mesh *S, *T;
    testdaemon_sphere_pair(level, &S, &T);
    char err[512];
    snprintf(sp, sz, "%s/ico%dS.off", harness_tmpdir(), level);
    snprintf(tp, sz, "%s/ico%dT.off", harness_tmpdir(), level);
    if (mesh_write(sp, S, err, sizeof err) || mesh_write(tp, T, err, sizeof err))
        FAILF("%s", err);
    mesh_free(S);
    mesh_free(T);
}

static proto_landmark *identity(unsigned n)
{
    proto_landmark *lm = malloc(sizeof *lm * n);
    CHECK(lm != NULL);
    for (unsigned i = 0; i < n; i++)
        lm[i] = (proto_landmark){i, i};
    return lm;
}

#define FEW 4.0     /* "within a factor of a few" */

TEST_T(estimate_bounds_real_runs_on_icosphere_pairs, 900)
{
    char sp[600], tp[600];
    proto_landmark *lm = identity(300);
    sphere_files(2, sp, tp, sizeof sp);
    compare("162 vertices, 6 landmarks", job_dir("l2", sp, tp, lm, 6, NULL, NULL, RHM_START_AUTO, CORR_CHAIN_ALL), FEW);
    sphere_files(5, sp, tp, sizeof sp);
    compare("10242 vertices, 6 landmarks", job_dir("l5", sp, tp, lm, 6, NULL, NULL, RHM_START_AUTO, CORR_CHAIN_ALL), FEW);
    sphere_files(4, sp, tp, sizeof sp);
    compare("2562 vertices, 300 lm, distances", job_dir("l4d", sp, tp, lm, 300, NULL, NULL, RHM_START_DISTANCES, CORR_CHAIN_RHM),
            FEW);
    compare("2562 vertices, 30 lm, fmap", job_dir("l4f", sp, tp, lm, 30, NULL, NULL, RHM_START_FMAP, CORR_CHAIN_RHM), FEW);
    free(lm);
}

TEST_T(estimate_bounds_a_coarse_to_fine_run, 900)
{
    char sp[600], tp[600];
    proto_landmark *lm = identity(6);
    sphere_files(6, sp, tp, sizeof sp);
    compare("40962 vertices (coarse 6000), 6 lm", job_dir("l6", sp, tp, lm, 6, NULL, NULL, RHM_START_AUTO, CORR_CHAIN_ALL), FEW);
    free(lm);
}

TEST_T(estimate_bounds_the_demo_cow_camel_job, 900)
{
    mesh *cow, *camel;
    lmk_set *L;
    testcowcamel_load(&cow, &camel, &L);
    proto_landmark *lm = malloc(sizeof *lm * (size_t)L->n);
    CHECK(lm != NULL);
    for (int i = 0; i < L->n; i++)
        lm[i] = (proto_landmark){(uint32_t)L->src[i], (uint32_t)L->tgt[i]};
    char sp[600], tp[600];
    snprintf(sp, sizeof sp, "%s/cow.off", harness_tmpdir());
    snprintf(tp, sizeof tp, "%s/camel.off", harness_tmpdir());
    compare("cow -> camel, 16 landmarks", job_dir("cow", sp, tp, lm, (unsigned)L->n, NULL, NULL, RHM_START_AUTO, CORR_CHAIN_ALL),
            FEW);
    free(lm);
    lmk_free(L);
    mesh_free(cow);
    mesh_free(camel);
}

TEST_T(estimate_bounds_a_shrec07_pair_from_its_maps, 900)
{
    char sp[600], tp[600], p0[600], q0[600];
    snprintf(sp, sizeof sp, "%s", harness_data_path("shrec07_bim/Meshes/381.off"));
    snprintf(tp, sizeof tp, "%s", harness_data_path("shrec07_bim/Meshes/390.off"));
    snprintf(p0, sizeof p0, "%s", harness_data_path("ectm_demo_381_390/init_381_to_390.map"));
    snprintf(q0, sizeof q0, "%s", harness_data_path("ectm_demo_381_390/init_390_to_381.map"));
    compare("SHREC'07 381 -> 390, ectm", job_dir("ectm", sp, tp, NULL, 0, p0, q0, RHM_START_AUTO, CORR_CHAIN_ECTM), FEW);
    compare("SHREC'07 381 -> 390, ddm,ectm", job_dir("ddm", sp, tp, NULL, 0, p0, q0, RHM_START_AUTO, CORR_CHAIN_DDM_ECTM), FEW);
}

TEST_T(a_job_whose_estimate_passes_the_worker_limit_is_refused_at_submit, 600)
{
    testdaemon_need_worker();
    static const char *const args[] = {"--worker-memory-mb", "4096", NULL};
    testdaemon d;
    testdaemon_start(&d, "cost", args);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    /* 65536 landmark pairs on two icospheres of 163842 vertices */
    mesh *S = testmesh_icosphere(7);
    CHECK(S != NULL);
    size_t len;
    unsigned char *drc = testdaemon_encode(S, &len);
    uint32_t *lm = malloc(sizeof *lm * 2 * 65536);
    CHECK(lm != NULL);
    for (uint32_t i = 0; i < 65536; i++)
        lm[2 * i] = lm[2 * i + 1] = i;
    mc_job_spec spec;
    mc_job_spec_init(&spec);
    spec.source = spec.target = drc;
    spec.source_len = spec.target_len = len;
    spec.landmarks = lm;
    spec.nlandmarks = 65536;
    spec.label = "65536 landmarks";
    uint64_t id = 0;
    int rc = mc_submit(c, &spec, &id);
    if (rc != PROTO_EOVER_LIMIT)
        FAILF("SUBMIT of 65536 landmarks on %d-vertex meshes: %s (%s), job %llu", S->nv, mc_strerror(rc),
              rc ? mc_errmsg(c) : "accepted", (unsigned long long)id);
    printf("  refused: %s\n", mc_errmsg(c));
    CHECK_STR_HAS(mc_errmsg(c), "job too large for a worker: about ");
    CHECK_STR_HAS(mc_errmsg(c), " TB at its peak for ");
    CHECK_STR_HAS(mc_errmsg(c), "65536 landmarks on meshes of 65536 and 65536 vertices (decimated from 163842 and"
                                " 163842)");
    CHECK_STR_HAS(mc_errmsg(c), "over the worker's memory limit of 4096 MB (--worker-memory-mb)");
    CHECK(testdaemon_log_has(&d, "SUBMIT from alice refused (OVER_LIMIT"));
    mc_job_info *jobs = NULL;
    uint32_t n = 9;
    CHECK_INT(mc_list(c, NULL, 0, &jobs, &n), 0);
    CHECK_INT(n, 0);
    free(jobs);
    /* an ordinary job under the same limit runs */
    uint64_t ok = testdaemon_submit_ok(c, 2, 0, 0);
    CHECK_INT(testdaemon_wait_state(c, ok, -1, 60), MC_COMPLETED);
    free(lm);
    free(drc);
    mesh_free(S);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
