/* bench_large.c — issue 16's large pair: TOSCA cat0 -> cat1 of
 * ../shared/data/tosca_hires (27894 vertices each, the same connectivity,
 * dense identity ground truth), the 21 landmarks of Corrs/cat.pid given,
 * through corr_run's stages all with meshcorr match's defaults (start auto,
 * RHM and its repair, ECTM and its repair). Prints the wall time of each
 * stage (from the progress reports: the start map until RHM's iteration 0,
 * RHM until ECTM's first outer iteration, ECTM to the end, which includes
 * the last repair), the job's peak resident memory (getrusage), the
 * flipped and collapsed triangles and the mean Euclidean distance from
 * each vertex's image to its ground truth over sqrt(target area), a lower
 * bound of the geodesic error, the threads used. Targets: the job <= 120 s,
 * <= 2 GB. Options: --ectm-iterations=K. Prints figures, never fails on
 * time. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "corr/corr.h"
#include "geo/geo_area.h"
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

typedef struct marks {
    double t0, rhm0, ectm1;   /* the job's start, RHM's iteration 0, ECTM's iteration 1 */
} marks;

static int on_progress(void *ctx, const corr_progress *p)
{
    marks *m = ctx;
    if (p->stage == CORR_STAGE_RHM && p->rhm && m->rhm0 == 0)
        m->rhm0 = now();
    if (p->stage == CORR_STAGE_ECTM && m->ectm1 == 0)
        m->ectm1 = now();
    return 0;
}

TEST_T(tosca_cat_28k_pipeline_from_21_landmarks, 3600)
{
    if (!harness_data_dir())
        SKIP("../shared/data is absent");
    mesh *S = testmesh_read("tosca_hires/Meshes/cat0.off");
    mesh *T = testmesh_read("tosca_hires/Meshes/cat1.off");
    char err[1024];
    int *ids, n;
    if (lmk_read_ids(harness_data_path("tosca_hires/Corrs/cat.pid"), 0, S->nv, 1000, &ids, &n, err,
                     sizeof err))
        FAILF("%s", err);
    long ls[1000];
    for (int r = 0; r < n; r++)
        ls[r] = ids[r];
    lmk_set *L = NULL;
    if (lmk_from_arrays(ls, ls, n, 0, "cat0.off", "cat1.off", S, T, &L, err, sizeof err))
        FAILF("%s", err);
    ectm_params p;
    ectm_params_init(&p);
    const char *o_it = harness_option("ectm-iterations");
    if (o_it)
        p.iterations = atoi(o_it);
    p.threads = omp_get_max_threads();
    rhm_params rp;
    rhm_params_init(&rp);
    rp.threads = p.threads;
    corr_input in = { S, T, "cat0.off", "cat1.off", L, NULL, NULL, &rp, CORR_STAGES_ALL, 0,
                      CORR_DDM_PLAIN };
    ectm_result r = {0};
    marks m = { now(), 0, 0 };
    if (corr_run(&in, &p, on_progress, &m, &r, err, sizeof err))
        FAILF("corr_run: %s", err);
    double t1 = now();
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    metric_summary ms;
    CHECK_INT(metric_summarize(S, T, r.P, &ms), 0);
    double e = 0;
    for (int v = 0; v < S->nv; v++) {
        const int *f = T->f + 3 * r.P->face[v];
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double x = 0;
            for (int c = 0; c < 3; c++)
                x += r.P->w[3 * v + c] * T->v[3 * f[c] + k];
            d2 += (x - T->v[3 * v + k]) * (x - T->v[3 * v + k]);
        }
        e += sqrt(d2);
    }
    e /= S->nv * sqrt(geo_total_area(T));
    printf("cat0 -> cat1, %d -> %d vertices, %d landmarks, %d threads, ECTM %d iterations: "
           "start %.1f s, RHM and repair %.1f s, ECTM and repair %.1f s, job %.1f s (target <= 120 s); "
           "peak resident %.0f MB (target <= 2048); flipped %.2f %%, collapsed %.2f %%; mean "
           "Euclidean error to the identity / sqrt(area) %.4f\n",
           S->nv, T->nv, n, p.threads, p.iterations, m.rhm0 - m.t0, m.ectm1 - m.rhm0, t1 - m.ectm1,
           t1 - m.t0, ru.ru_maxrss / 1024.0, 100 * ms.flipped_fraction,
           100 * ms.collapsed_fraction, e);
    ectm_result_close(&r);
    lmk_free(L);
    free(ids);
    mesh_free(S);
    mesh_free(T);
}
