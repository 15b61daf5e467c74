/* bench_ener.c — time of one deformation-energy evaluation (energy and
 * gradient, membrane and bending) on two SHREC'07 meshes, with 1 and 2
 * OpenMP threads, and the ratio to the 270 ns/face the authors' C++ code
 * takes. Each mesh is one harness test: it prints figures and fails only
 * when the evaluation cannot run, never on time. */
#include "support/harness.h"
#include "ener/ener_def.h"
#include "geo/geo_edges.h"
#include "mesh/mesh.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define BASELINE_NS_PER_FACE 270.0

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Best-of-5 mean ns/face over batches of evaluations lasting ~0.2 s. */
static double ns_per_face(ener_def *d, const double *Y, double *grad, int nf)
{
    double best = 1e300;
    int reps = 8;
    for (;;) { /* size a batch */
        double t0 = now();
        for (int r = 0; r < reps; r++)
            ener_def_eval(d, Y, grad, NULL, NULL);
        if (now() - t0 > 0.2)
            break;
        reps *= 2;
    }
    for (int trial = 0; trial < 5; trial++) {
        double t0 = now();
        for (int r = 0; r < reps; r++)
            ener_def_eval(d, Y, grad, NULL, NULL);
        double t = (now() - t0) / reps;
        if (t < best)
            best = t;
    }
    return 1e9 * best / nf;
}

static void bench_mesh(const char *name)
{
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s",
             harness_data_path(name[1] == '8' ? "shrec07_bim/Meshes/381.off"
                                              : "shrec07_bim/Meshes/390.off"));
    mesh *X = NULL;
    geo_edges E = {0};
    ener_def *d = NULL;
    double *Y = NULL, *grad = NULL;
    if (mesh_read(path, &X, err, sizeof err) != 0 ||
        geo_edges_build(X, &E, err, sizeof err) != 0)
        FAILF("%s: %s", path, err);
    ener_def_params p = {20.0, 6.667e-4, ENER_LOG_EPS_DEFAULT};
    d = ener_def_new(X, &E, &p, err, sizeof err);
    Y = malloc(3 * (size_t)X->nv * sizeof *Y);
    grad = malloc(3 * (size_t)X->nv * sizeof *grad);
    if (!d || !Y || !grad)
        FAILF("%s: %s", path, d ? "out of memory" : err);
    unsigned long long s = 1;
    for (int i = 0; i < 3 * X->nv; i++) { /* a small deterministic perturbation */
        s ^= s << 13; s ^= s >> 7; s ^= s << 17;
        Y[i] = X->v[i] + 1e-3 * ((double)(s >> 11) / 9007199254740992.0 - 0.5);
    }
    omp_set_dynamic(0);
    omp_set_num_threads(1);
    double t1 = ns_per_face(d, Y, grad, X->nf);
    omp_set_num_threads(2);
    double t2 = ns_per_face(d, Y, grad, X->nf);
    printf("ener_def_eval %s (%d faces): 1 thread %.1f ns/face (%.1fx faster than %.0f ns/face), "
           "2 threads %.1f ns/face (%.1fx), %.1f us per evaluation with 1 thread\n",
           name, X->nf, t1, BASELINE_NS_PER_FACE / t1, BASELINE_NS_PER_FACE, t2,
           BASELINE_NS_PER_FACE / t2, 1e-3 * t1 * X->nf);
    fflush(stdout);
    free(Y);
    free(grad);
    ener_def_free(d);
    geo_edges_close(&E);
    mesh_free(X);
}

TEST_T(ener_def_eval_time_381, 120) { bench_mesh("381"); }
TEST_T(ener_def_eval_time_390, 120) { bench_mesh("390"); }
