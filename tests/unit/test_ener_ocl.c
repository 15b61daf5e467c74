/* test_ener_ocl.c — the OpenCL backend of W_def against the CPU backend:
 * energy and gradient parity on real meshes (noisy, with collapsed and
 * inverted faces and inadmissible edges) and on the icosphere, admissible
 * counts, a short ECTM run giving the same maps, device choice by name,
 * `auto` falling back to the CPU, kernel build errors returned with their
 * log, and the PoCL environment set before the first OpenCL call. Every
 * test runs in its own process, so each initialises OpenCL itself (the
 * harness forks before any OpenCL call: forking after PoCL starts hangs). */
#include "support/harness.h"
#include "support/testmesh.h"
#include "ectm/ectm.h"
#include "ener/ener_backend.h"
#include "ener/ener_ocl.h"
#include "geo/geo_edges.h"
#include "map/bmap.h"

#include <string.h>
#include <sys/stat.h>

#define REL_TOL 1e-10

/* SKIPs the test unless some OpenCL device has fp64; returns whether one of
 * them is a GPU. */
static int need_fp64_device(void)
{
    ener_ocl_device dev[ENER_OCL_DEVICES_MAX];
    int n = 0, fp64 = 0, gpu = 0;
    char err[1024];
    if (ener_ocl_device_list(2, dev, ENER_OCL_DEVICES_MAX, &n, err, sizeof err))
        SKIP("no OpenCL device: %s", err);
    for (int i = 0; i < n; i++) {
        fp64 |= dev[i].fp64;
        gpu |= dev[i].fp64 && strcmp(dev[i].type, "GPU") == 0;
    }
    if (!fp64)
        SKIP("no OpenCL device with fp64 (%d devices)", n);
    return gpu;
}

static const ener_def_params PARAMS = { 20.0, 6.667e-4, 1e-20, NULL };

typedef struct pair {
    mesh *X;
    geo_edges E;
    ener_backend *cpu, *ocl;
} pair;

static void pair_open(pair *pr, mesh *X, const ener_def_params *p)
{
    char err[4096];
    memset(pr, 0, sizeof *pr);
    CHECK(X != NULL);
    pr->X = X;
    if (geo_edges_build(X, &pr->E, err, sizeof err))
        FAILF("geo_edges_build: %s", err);
    if (ener_backend_new(X, &pr->E, p, "cpu", "", 2, &pr->cpu, err, sizeof err))
        FAILF("cpu backend: %s", err);
    if (ener_backend_new(X, &pr->E, p, "opencl", "", 2, &pr->ocl, err, sizeof err))
        FAILF("opencl backend: %s", err);
    CHECK_STR_HAS(ener_backend_name(pr->ocl), "opencl: ");
    CHECK(strcmp(ener_backend_name(pr->cpu), "cpu") == 0);
}

static void pair_close(pair *pr)
{
    ener_backend_free(pr->cpu);
    ener_backend_free(pr->ocl);
    geo_edges_close(&pr->E);
    mesh_free(pr->X);
}

static double rel(double a, double b)
{
    double s = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
    return s > 0 ? fabs(a - b) / s : 0.0;
}

/* Energy terms and gradient of both backends at Y agree; with and without a
 * gradient requested. */
static void check_parity(pair *pr, const double *Y, const char *what)
{
    size_t n = 3 * (size_t)pr->X->nv;
    double *gc = malloc(n * sizeof(double)), *go = malloc(n * sizeof(double));
    CHECK(gc && go);
    int ac = ener_backend_update_admissible(pr->cpu, Y);
    int ao = ener_backend_update_admissible(pr->ocl, Y);
    CHECK_INT(ao, ac);
    double mc, bc, mo, bo;
    double ec = ener_backend_eval(pr->cpu, Y, gc, &mc, &bc);
    double eo = ener_backend_eval(pr->ocl, Y, go, &mo, &bo);
    CHECK(ener_backend_error(pr->ocl) == NULL);
    CHECK(isfinite(ec) && ec > 0);
    if (!(rel(eo, ec) <= REL_TOL && rel(mo, mc) <= REL_TOL && rel(bo, bc) <= REL_TOL))
        FAILF("%s: energy opencl %.17g (mem %.17g, bnd %.17g) vs cpu %.17g (%.17g, %.17g)",
              what, eo, mo, bo, ec, mc, bc);
    double gmax = 0, dmax = 0;
    for (size_t i = 0; i < n; i++) {
        gmax = fmax(gmax, fabs(gc[i]));
        dmax = fmax(dmax, fabs(gc[i] - go[i]));
    }
    CHECK(gmax > 0);
    if (!(dmax <= REL_TOL * gmax))
        FAILF("%s: gradient max difference %.3g, max |g| %.3g", what, dmax, gmax);
    double e2 = ener_backend_eval(pr->ocl, Y, NULL, NULL, NULL);
    CHECK_NEAR(e2, eo, 0.0);
    free(gc);
    free(go);
}

/* Y = X + noise of `amp` mean edge lengths; then, when `damage`, every
 * 97th face collapsed (a corner moved onto another) and every 89th face's
 * first corner reflected through the opposite edge's midpoint (inverted). */
static double *deformed(const mesh *X, double amp, int damage, unsigned long long seed)
{
    size_t n = 3 * (size_t)X->nv;
    double *Y = malloc(n * sizeof(double));
    CHECK(Y != NULL);
    double edge = testmesh_mean_edge(X);
    for (size_t i = 0; i < n; i++)
        Y[i] = X->v[i] + amp * edge * (2 * testmesh_rand(&seed) - 1);
    if (damage)
        for (int t = 0; t < X->nf; t++) {
            const int *f = X->f + 3 * t;
            if (t % 97 == 0)
                memcpy(Y + 3 * f[0], Y + 3 * f[1], 3 * sizeof(double));
            else if (t % 89 == 0)
                for (int k = 0; k < 3; k++)
                    Y[3 * f[0] + k] = Y[3 * f[1] + k] + Y[3 * f[2] + k] - Y[3 * f[0] + k];
        }
    return Y;
}

static mesh *read_mesh(const char *rel_path)
{
    char err[512];
    mesh *m = NULL;
    if (mesh_read(harness_data_path(rel_path), &m, err, sizeof err))
        FAILF("%s", err);
    return m;
}

static void parity_on(mesh *X, const char *name)
{
    pair pr;
    pair_open(&pr, X, &PARAMS);
    char what[128];
    /* at X both are zero up to rounding */
    double *g = malloc(3 * (size_t)X->nv * sizeof(double));
    CHECK(g != NULL);
    CHECK_NEAR(ener_backend_eval(pr.ocl, X->v, g, NULL, NULL), 0.0, 1e-9);
    for (int i = 0; i < 3 * X->nv; i++)
        CHECK_NEAR(g[i], 0.0, 1e-9);
    free(g);
    double *Y = deformed(X, 0.2, 0, 7);
    snprintf(what, sizeof what, "%s with noise", name);
    check_parity(&pr, Y, what);
    free(Y);
    Y = deformed(X, 0.2, 1, 11);
    /* the collapsed faces make some edges inadmissible */
    int all = ener_backend_update_admissible(pr.cpu, X->v);
    int adm = ener_backend_update_admissible(pr.cpu, Y);
    CHECK(adm < all);
    snprintf(what, sizeof what, "%s with collapsed and inverted faces", name);
    check_parity(&pr, Y, what);
    free(Y);
    pair_close(&pr);
}

TEST(opencl_matches_cpu_on_381_with_noise_collapsed_and_inverted_faces)
{
    need_fp64_device();
    parity_on(read_mesh("shrec07_bim/Meshes/381.off"), "381");
}

TEST(opencl_matches_cpu_on_390_with_noise_collapsed_and_inverted_faces)
{
    need_fp64_device();
    parity_on(read_mesh("shrec07_bim/Meshes/390.off"), "390");
}

TEST(opencl_matches_cpu_on_icosphere)
{
    need_fp64_device();
    parity_on(testmesh_icosphere(4), "icosphere(4)");
}

/* A reference metric grown per face (ECTM's scaled reference) reaches the
 * device as the CPU computes it. */
TEST(opencl_matches_cpu_with_a_reference_scaled_per_face)
{
    need_fp64_device();
    mesh *X = testmesh_icosphere(4);
    CHECK(X != NULL);
    double *scale = malloc(sizeof(double) * (size_t)X->nf);
    CHECK(scale != NULL);
    for (int t = 0; t < X->nf; t++)
        scale[t] = 1 + 0.5 * sin(0.01 * t);
    ener_def_params p = PARAMS;
    p.face_scale = scale;
    pair pr;
    pair_open(&pr, X, &p);
    free(scale);
    double *Y = deformed(X, 0.2, 0, 13);
    check_parity(&pr, Y, "icosphere(4) with a scaled reference");
    free(Y);
    pair_close(&pr);
}

TEST(admissible_counts_agree_as_faces_collapse)
{
    need_fp64_device();
    pair pr;
    pair_open(&pr, testmesh_icosphere(3), &PARAMS);
    size_t n = 3 * (size_t)pr.X->nv;
    double *Y = malloc(n * sizeof(double));
    CHECK(Y != NULL);
    memcpy(Y, pr.X->v, n * sizeof(double));
    int prev = ener_backend_update_admissible(pr.ocl, Y);
    CHECK_INT(prev, ener_backend_update_admissible(pr.cpu, Y));
    CHECK_INT(prev, pr.E.ne);   /* closed mesh: every edge interior and admissible */
    /* collapse faces one vertex at a time: the counts keep agreeing */
    for (int t = 0; t < 40; t++) {
        const int *f = pr.X->f + 3 * (5 * t);
        memcpy(Y + 3 * f[0], Y + 3 * f[1], 3 * sizeof(double));
        int c = ener_backend_update_admissible(pr.cpu, Y);
        CHECK_INT(ener_backend_update_admissible(pr.ocl, Y), c);
        prev = c;
    }
    CHECK(prev < pr.E.ne);
    check_parity(&pr, Y, "icosphere(3) after collapses");
    free(Y);
    pair_close(&pr);
}

typedef struct run_log {
    double energy[8];
    int n;
} run_log;

static int record(void *ctx, const ectm_report *r)
{
    run_log *l = ctx;
    if (l->n < 8)
        l->energy[l->n++] = r->energy;
    return 0;
}

TEST_T(ectm_five_iterations_give_same_maps_on_opencl_and_cpu, 300)
{
    need_fp64_device();
    char err[1024];
    mesh *S = read_mesh("shrec07_bim/Meshes/381.off"), *T = read_mesh("shrec07_bim/Meshes/390.off");
    bmap *P0 = NULL, *Q0 = NULL;
    if (bmap_read(harness_data_path("ectm_demo_381_390/init_381_to_390.map"), S, T, &P0, err,
                  sizeof err) ||
        bmap_read(harness_data_path("ectm_demo_381_390/init_390_to_381.map"), T, S, &Q0, err,
                  sizeof err))
        FAILF("%s", err);
    ectm_result r[2];
    run_log log[2] = {{{0}, 0}, {{0}, 0}};
    for (int b = 0; b < 2; b++) {
        ectm_params p;
        ectm_params_init(&p);
        p.iterations = 5;
        p.threads = 2;
        strcpy(p.backend, b ? "opencl" : "cpu");
        if (ectm_run(S, T, P0, Q0, NULL, &p, record, &log[b], &r[b], err, sizeof err))
            FAILF("%s backend: %s", p.backend, err);
    }
    CHECK_INT(log[0].n, 5);
    CHECK_INT(log[1].n, 5);
    for (int k = 0; k < 5; k++)
        if (!(rel(log[1].energy[k], log[0].energy[k]) <= 1e-6))
            FAILF("iteration %d: energy opencl %.17g, cpu %.17g", k + 1, log[1].energy[k],
                  log[0].energy[k]);
    int sameP = 0, sameQ = 0;
    for (int i = 0; i < S->nv; i++)
        sameP += r[0].P->face[i] == r[1].P->face[i];
    for (int j = 0; j < T->nv; j++)
        sameQ += r[0].Q->face[j] == r[1].Q->face[j];
    if (!(sameP >= 0.999 * S->nv && sameQ >= 0.999 * T->nv))
        FAILF("same faces: P %d of %d, Q %d of %d", sameP, S->nv, sameQ, T->nv);
    ectm_result_close(&r[0]);
    ectm_result_close(&r[1]);
    bmap_free(P0);
    bmap_free(Q0);
    mesh_free(S);
    mesh_free(T);
}

TEST(device_name_that_matches_nothing_is_refused_naming_it)
{
    need_fp64_device();
    mesh *X = testmesh_icosphere(1);
    geo_edges E;
    char err[4096];
    CHECK_INT(geo_edges_build(X, &E, err, sizeof err), 0);
    ener_backend *b = (ener_backend *)1;
    CHECK_INT(ener_backend_new(X, &E, &PARAMS, "opencl", "no-such-gpu-xyz", 2, &b, err,
                               sizeof err), ENER_ENODEVICE);
    CHECK(b == NULL);
    CHECK_STR_HAS(err, "'no-such-gpu-xyz'");
    /* `auto` with a name that matches nothing is the CPU, not an error */
    CHECK_INT(ener_backend_new(X, &E, &PARAMS, "auto", "no-such-gpu-xyz", 2, &b, err,
                               sizeof err), 0);
    CHECK(strcmp(ener_backend_name(b), "cpu") == 0);
    ener_backend_free(b);
    /* a name that does match (the platform's or the device's) is taken */
    ener_ocl_device dev[ENER_OCL_DEVICES_MAX];
    int n = 0, i = 0;
    CHECK_INT(ener_ocl_device_list(2, dev, ENER_OCL_DEVICES_MAX, &n, err, sizeof err), 0);
    while (!dev[i].fp64)
        i++;
    CHECK_INT(ener_backend_new(X, &E, &PARAMS, "opencl", dev[i].name, 2, &b, err, sizeof err), 0);
    CHECK_STR_HAS(ener_backend_name(b), dev[i].name);
    ener_backend_free(b);
    CHECK_INT(ener_backend_new(X, &E, &PARAMS, "gpu", "", 2, &b, err, sizeof err), ENER_EINVAL);
    CHECK_STR_HAS(err, "'gpu'");
    geo_edges_close(&E);
    mesh_free(X);
}

TEST(auto_takes_a_gpu_with_fp64_else_the_cpu)
{
    int gpu = need_fp64_device();
    mesh *X = testmesh_icosphere(1);
    geo_edges E;
    char err[4096];
    CHECK_INT(geo_edges_build(X, &E, err, sizeof err), 0);
    ener_backend *b = NULL;
    CHECK_INT(ener_backend_new(X, &E, &PARAMS, "auto", "", 2, &b, err, sizeof err), 0);
    if (gpu)
        CHECK_STR_HAS(ener_backend_name(b), "opencl: ");
    else
        CHECK(strcmp(ener_backend_name(b), "cpu") == 0);
    ener_backend_free(b);
    geo_edges_close(&E);
    mesh_free(X);
}

TEST(kernel_build_error_is_returned_with_the_build_log)
{
    need_fp64_device();
    char err[8192];
    CHECK_INT(ener__ocl_build_check("", "__kernel void k(__global double *x)\n"
                                        "{ x[0] = meshcorr_undefined_symbol; }\n",
                                    err, sizeof err),
              ENER_EBUILD);
    CHECK_STR_HAS(err, "build log");
    CHECK_STR_HAS(err, "meshcorr_undefined_symbol");
    CHECK_INT(ener__ocl_build_check("", "__kernel void k(__global double *x) { x[0] = 1.0; }\n",
                                    err, sizeof err),
              0);
}

TEST(pocl_cache_and_thread_count_are_set_before_first_use)
{
    const char *tmp = harness_tmpdir();
    char xdg[512], want[600];
    snprintf(xdg, sizeof xdg, "%s/cache", tmp);
    snprintf(want, sizeof want, "%s/meshcorr-pocl", xdg);
    unsetenv("POCL_CACHE_DIR");
    unsetenv("POCL_MAX_PTHREAD_COUNT");
    unsetenv("POCL_CPU_MAX_CU_COUNT");
    setenv("XDG_CACHE_HOME", xdg, 1);
    ener_ocl_device dev[ENER_OCL_DEVICES_MAX];
    int n = 0;
    char err[1024];
    int rc = ener_ocl_device_list(3, dev, ENER_OCL_DEVICES_MAX, &n, err, sizeof err);
    CHECK(getenv("POCL_CACHE_DIR") && strcmp(getenv("POCL_CACHE_DIR"), want) == 0);
    struct stat st;
    CHECK(stat(want, &st) == 0 && S_ISDIR(st.st_mode));
    CHECK(getenv("POCL_MAX_PTHREAD_COUNT") && strcmp(getenv("POCL_MAX_PTHREAD_COUNT"), "3") == 0);
    CHECK(getenv("POCL_CPU_MAX_CU_COUNT") && strcmp(getenv("POCL_CPU_MAX_CU_COUNT"), "3") == 0);
    if (rc)
        SKIP("environment checked; no OpenCL device: %s", err);
    CHECK(n >= 1);
}
