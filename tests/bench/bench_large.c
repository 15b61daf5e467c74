/* bench_large.c — large pairs, through corr_run's stages all
 * with meshcorr match's defaults (start auto, RHM and its repair, ECTM and
 * its repair) and the threads the machine has:
 *
 * - tosca_cat_28k_pipeline_from_21_landmarks: TOSCA cat0 -> cat1 of
 *   ../shared/data/tosca_hires (27894 vertices each, the same
 *   connectivity, dense identity ground truth), the 21 landmarks of
 *   Corrs/cat.pid given. Targets: the job <= 120 s, <= 2 GB.
 * - cost_against_size_wolf_4k_17k_69k: TOSCA wolf0 -> wolf2 (4344
 *   vertices, the same connectivity, Corrs/wolf.pid's 21 landmarks) as
 *   shipped and split 1-to-4 at the edge midpoints once and twice
 *   (testmesh_subdivided: the same surfaces, 17K and 69K vertices, the
 *   landmarks the same vertices; the identity is the ground truth of the
 *   4344 shipped vertices only: the two meshes' face lists differ in 240
 *   faces, so the midpoints of one are not the other's);
 *   each size in its own process. Then the exponent of the fit of each
 *   stage's time against the vertices (target: <= 1.2).
 *
 * Per run: the wall time of each stage (from the progress reports: the
 * start map until RHM's iteration 0, RHM and its repair until ECTM's
 * first outer iteration, ECTM and its repair to the end), the peak
 * resident memory at each of those three points (getrusage: the peak so
 * far, so the last is the job's), flipped and collapsed triangles and
 * the mean Euclidean distance from each vertex's image to its ground
 * truth over sqrt(target area), a lower bound of the geodesic error
 * (wolf: over the shipped vertices). Pairs over twice the coarse size
 * (job parameter coarse, 6000) run
 * coarse to fine (corr.h): their "start" is the decimation and the
 * coarse start, "rhm+repair" the coarse RHM, "ectm+repair" both ECTM runs.
 * Options: --ectm-iterations=K, --levels=L (the scaling test's most
 * subdivisions, default 2), --coarse=N (the job parameter; 0: every stage
 * on the meshes as given). Prints figures, never fails on time. */
#include "support/harness.h"
#include "support/testapart.h"
#include "support/testfit.h"
#include "support/testgt.h"
#include "support/testmesh.h"
#include "corr/corr.h"
#include "metric/metric.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double peak_mb(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss / 1024.0;
}

enum { START, RHM, ECTM, NSTAGES };
static const char *const stage_name[NSTAGES] = { "start", "rhm+repair", "ectm+repair" };

/* One run's figures (plain data: it comes back from a child process). */
typedef struct run_fig {
    int nv, nf, threads, ectm_iterations;
    double secs[NSTAGES], mb[NSTAGES];   /* per stage; mb: the peak at its end */
    double flipped, collapsed, err;      /* % , %, identity error */
} run_fig;

typedef struct marks {
    double t0, at[NSTAGES];   /* the job's start; each stage's end */
    double mb[NSTAGES];
} marks;

static int on_progress(void *ctx, const corr_progress *p)
{
    marks *m = ctx;
    if (p->stage == CORR_STAGE_RHM && p->rhm && m->at[START] == 0) {
        m->at[START] = now();
        m->mb[START] = peak_mb();
    }
    if (p->stage == CORR_STAGE_ECTM && m->at[RHM] == 0) {
        m->at[RHM] = now();
        m->mb[RHM] = peak_mb();
    }
    return 0;
}

/* The pipeline on S -> T (the same vertex count) from the landmark
 * vertices listed in pid_rel (given on both sides), into f; the error
 * over the first `scored` vertices (those with the identity as their
 * ground truth). */
static void run_pipeline(const mesh *S, const mesh *T, const char *pid_rel, int scored,
                         run_fig *f)
{
    char err[1024];
    lmk_set *L = testgt_pid_landmarks(pid_rel, S, T);
    ectm_params p;
    ectm_params_init(&p);
    const char *o_it = harness_option("ectm-iterations");
    if (o_it)
        p.iterations = atoi(o_it);
    p.threads = omp_get_max_threads();
    rhm_params rp;
    rhm_params_init(&rp);
    rp.threads = p.threads;
    const char *o_c = harness_option("coarse");
    if (o_c)
        rp.coarse = atoi(o_c);
    corr_input in = { S, T, "source", "target", L, NULL, NULL, &rp, CORR_STAGES_ALL, 0,
                      CORR_DDM_PLAIN };
    ectm_result r = {0};
    marks m = { now(), {0}, {0} };
    if (corr_run(&in, &p, on_progress, &m, &r, err, sizeof err))
        FAILF("corr_run: %s", err);
    m.at[ECTM] = now();
    m.mb[ECTM] = peak_mb();
    metric_summary ms;
    CHECK_INT(metric_summarize(S, T, r.P, &ms), 0);
    bmap shipped = *r.P;
    shipped.n = scored;
    *f = (run_fig){ .nv = S->nv, .nf = S->nf, .threads = p.threads,
                    .ectm_iterations = p.iterations, .flipped = 100 * ms.flipped_fraction,
                    .collapsed = 100 * ms.collapsed_fraction,
                    .err = testgt_identity_error(S, T, &shipped) };
    for (int s = 0; s < NSTAGES; s++) {
        f->secs[s] = m.at[s] - (s ? m.at[s - 1] : m.t0);
        f->mb[s] = m.mb[s];
    }
    ectm_result_close(&r);
    lmk_free(L);
}

static void print_run(const char *what, const run_fig *f)
{
    printf("%s, %d vertices, %d faces, %d threads, ECTM %d iterations:", what, f->nv, f->nf,
           f->threads, f->ectm_iterations);
    for (int s = 0; s < NSTAGES; s++)
        printf(" %s %.1f s (peak %.0f MB)%s", stage_name[s], f->secs[s], f->mb[s],
               s + 1 < NSTAGES ? "," : ";");
    printf(" job %.1f s; flipped %.2f %%, collapsed %.2f %%; mean Euclidean error to the "
           "identity / sqrt(area) %.4f\n", f->secs[START] + f->secs[RHM] + f->secs[ECTM],
           f->flipped, f->collapsed, f->err);
    fflush(stdout);
}

TEST_T(tosca_cat_28k_pipeline_from_21_landmarks, 3600)
{
    if (!harness_data_dir())
        SKIP("../shared/data is absent");
    mesh *S = testmesh_read("tosca_hires/Meshes/cat0.off");
    mesh *T = testmesh_read("tosca_hires/Meshes/cat1.off");
    run_fig f;
    run_pipeline(S, T, "tosca_hires/Corrs/cat.pid", S->nv, &f);
    print_run("cat0 -> cat1", &f);
    printf("targets: job <= 120 s, peak resident <= 2048 MB\n");
    mesh_free(S);
    mesh_free(T);
}

typedef struct scale_arg {
    int level;
} scale_arg;

static void run_level(const void *arg, void *out)
{
    int level = ((const scale_arg *)arg)->level;
    mesh *S = testmesh_read("tosca_hires/Meshes/wolf0.off");
    mesh *T = testmesh_read("tosca_hires/Meshes/wolf2.off");
    int shipped = S->nv;
    for (int l = 0; l < level; l++) {
        mesh *s = testmesh_subdivided(S), *t = testmesh_subdivided(T);
        if (!s || !t)
            FAILF("subdivision: out of memory");
        mesh_free(S);
        mesh_free(T);
        S = s;
        T = t;
    }
    run_pipeline(S, T, "tosca_hires/Corrs/wolf.pid", shipped, out);
    mesh_free(S);
    mesh_free(T);
}

TEST_T(cost_against_size_wolf_4k_17k_69k, 14400)
{
    if (!harness_data_dir())
        SKIP("../shared/data is absent");
    const char *o_lv = harness_option("levels");
    int levels = o_lv ? atoi(o_lv) : 2;
    if (levels < 1 || levels > 3)
        FAILF("--levels=%s: expected 1, 2 or 3", o_lv);
    run_fig f[4];
    double x[4], y[NSTAGES + 1][4];
    int n = 0;
    for (int l = 0; l <= levels; l++) {
        char why[256], what[64];
        scale_arg a = { l };
        if (testapart_run(run_level, &a, &f[n], sizeof f[n], why, sizeof why)) {
            printf("wolf0 -> wolf2 subdivided %d times: %s\n", l, why);
            continue;
        }
        snprintf(what, sizeof what, "wolf0 -> wolf2 subdivided %d times", l);
        print_run(what, &f[n]);
        x[n] = f[n].nv;
        for (int s = 0; s < NSTAGES; s++)
            y[s][n] = f[n].secs[s];
        y[NSTAGES][n] = f[n].secs[START] + f[n].secs[RHM] + f[n].secs[ECTM];
        n++;
    }
    printf("cost against size over %d sizes, time ~ vertices^e (target e <= 1.2):", n);
    for (int s = 0; s <= NSTAGES; s++)
        printf(" %s e = %.2f%s", s < NSTAGES ? stage_name[s] : "job",
               testfit_exponent(x, y[s], n), s < NSTAGES ? ";" : "\n");
    double mb[4];
    for (int k = 0; k < n; k++)
        mb[k] = f[k].mb[ECTM];
    printf("peak resident ~ vertices^e: e = %.2f\n", testfit_exponent(x, mb, n));
}
