/* bench_lbo.c — time of the first k = 100 Laplace–Beltrami eigenpairs
 * (shift-invert Lanczos, lbo.h) on a 5K-vertex (FAUST tr_reg_000) and a
 * 28K-vertex mesh (TOSCA cat0), apart from building the intrinsic Delaunay
 * operators (geod_solver_new, which also makes the geodesic factorisations).
 * Best of 2 runs. --k=N changes k. Prints figures; fails only when
 * something cannot run. */
#include "support/harness.h"
#include "geod/geod.h"
#include "lbo/lbo.h"

#include <stdlib.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void bench(const char *rel)
{
    const char *ko = harness_option("k");
    int k = ko ? atoi(ko) : 100;
    mesh *m = NULL;
    char err[256] = "";
    if (mesh_read(harness_data_path(rel), &m, err, sizeof err))
        FAILF("%s", err);
    double t0 = now();
    geod_solver *s = NULL;
    if (geod_solver_new(m, 0, &s, err, sizeof err) != GEOD_OK)
        FAILF("%s", err);
    double t_ops = now() - t0, best = 1e300;
    lbo_basis b = {0};
    for (int trial = 0; trial < 2; trial++) {
        lbo_basis_close(&b);
        t0 = now();
        int rc = lbo_eigenpairs(geod_solver_laplacian(s), geod_solver_mass(s), m->nv, k, &b,
                                err, sizeof err);
        if (rc != LBO_OK)
            FAILF("eigenpairs: %s", err);
        best = fmin(best, now() - t0);
    }
    printf("%s: %d vertices, k = %d: eigenpairs %.2f s (restarts %d, solves %d; "
           "lambda_1 %.4g, lambda_%d %.4g); operators + geodesic factorisations %.2f s\n",
           rel, m->nv, k, best, b.restarts, b.op_solves, b.lambda[1], k - 1, b.lambda[k - 1],
           t_ops);
    fflush(stdout);
    lbo_basis_close(&b);
    geod_solver_free(s);
    mesh_free(m);
}

TEST_T(eigenpairs_k100_faust_5k, 300) { bench("faust_r/vtx_5k/tr_reg_000.off"); }
TEST_T(eigenpairs_k100_tosca_cat_28k, 600) { bench("tosca_hires/Meshes/cat0.off"); }
