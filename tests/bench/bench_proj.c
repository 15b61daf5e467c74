/* bench_proj.c — one ECTM projection pass 381 → 390 (unit areas, first
 * outer iteration: Y = P·X̃ and Ỹ = Q·X from the demo's HOT maps): brute
 * force against the Embree query, unseeded and seeded with the previous
 * assignment (the HOT map's faces), on 1 and 2 threads. Brute force runs on
 * a 500-row subset and is extrapolated. Fails only if a result differs from
 * brute force; never on time. */
#include "support/harness.h"
#include "proj/proj.h"
#include "map/bmap.h"

#include <omp.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static mesh *load_unit_area(const char *rel)
{
    char err[512];
    mesh *m = NULL;
    if (mesh_read(harness_data_path(rel), &m, err, sizeof err) != 0)
        FAILF("%s", err);
    double area = 0;
    for (int t = 0; t < m->nf; t++) {
        const double *a = m->v + 3 * m->f[3 * t], *b = m->v + 3 * m->f[3 * t + 1],
                     *c = m->v + 3 * m->f[3 * t + 2];
        double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
        double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
        double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2],
               z = u[0] * v[1] - u[1] * v[0];
        area += 0.5 * sqrt(x * x + y * y + z * z);
    }
    for (int i = 0; i < 3 * m->nv; i++)
        m->v[i] /= sqrt(area);
    return m;
}

static bmap *load_map(const char *rel, const mesh *s, const mesh *t)
{
    char err[512];
    bmap *P = NULL;
    if (bmap_read(harness_data_path(rel), s, t, &P, err, sizeof err) != 0)
        FAILF("%s", err);
    return P;
}

TEST_T(projection_pass_381_390, 600)
{
    mesh *X = load_unit_area("shrec07_bim/Meshes/381.off");
    mesh *Xt = load_unit_area("shrec07_bim/Meshes/390.off");
    bmap *P = load_map("ectm_demo_381_390/init_381_to_390.map", X, Xt);
    bmap *Qm = load_map("ectm_demo_381_390/init_390_to_381.map", Xt, X);
    int n = X->nv, nt = Xt->nv, d = 6;
    double *Y = malloc(sizeof(double) * 3 * n), *Yt = malloc(sizeof(double) * 3 * nt);
    bmap_apply(P, Xt->f, Xt->v, 3, Y);
    bmap_apply(Qm, X->f, X->v, 3, Yt);
    char err[512];
    double t0 = now();
    proj_tree *tree = proj_tree_new(Xt, err, sizeof err);
    if (!tree)
        FAILF("%s", err);
    printf("proj: BVH over %d target triangles built in %.1f ms\n", Xt->nf, 1e3 * (now() - t0));

    const int nsub = 500, stride = n / nsub;
    double *Z = malloc(sizeof(double) * d * nt), *Q = malloc(sizeof(double) * d * n);
    double *Qs = malloc(sizeof(double) * d * nsub);
    int *f = malloc(sizeof(int) * n), *fs = malloc(sizeof(int) * nsub);
    double *w = malloc(sizeof(double) * 3 * n), *ws = malloc(sizeof(double) * 3 * nsub);
    double *c = malloc(sizeof(double) * n), *cs = malloc(sizeof(double) * nsub);
    double params[2][2] = { { 500, 1e4 }, { 1e5, 1e4 } };
    int bad = 0;
    for (int pi = 0; pi < 2; pi++) {
        double sb = sqrt(params[pi][0]), sg = sqrt(params[pi][1]);
        for (int j = 0; j < nt; j++)
            for (int k = 0; k < 3; k++) {
                Z[d * j + k] = sb * Xt->v[3 * j + k];
                Z[d * j + 3 + k] = sg * Yt[3 * j + k];
            }
        for (int i = 0; i < n; i++)
            for (int k = 0; k < 3; k++) {
                Q[d * i + k] = sb * Y[3 * i + k];
                Q[d * i + 3 + k] = sg * X->v[3 * i + k];
            }
        for (int s = 0; s < nsub; s++)
            memcpy(Qs + d * s, Q + (size_t)d * s * stride, sizeof(double) * d);
        for (int threads = 1; threads <= 2; threads++) {
            omp_set_num_threads(threads);
            t0 = now();
            proj_closest_brute(Xt, d, Z, nsub, Qs, fs, ws, cs);
            double tb = (now() - t0) * n / nsub;
            for (int i = 0; i < n; i++)
                f[i] = -1;
            t0 = now();
            proj_closest(tree, d, Z, sb, n, Q, f, w, c);
            double te = now() - t0;
            for (int s = 0; s < nsub; s++)
                bad += f[s * stride] != fs[s] &&
                       !(fabs(c[s * stride] - cs[s]) <= fmax(1e-12 * cs[s], 1e-15));
            memcpy(f, P->face, sizeof(int) * n);
            t0 = now();
            proj_closest(tree, d, Z, sb, n, Q, f, w, c);
            double tsd = now() - t0;
            for (int s = 0; s < nsub; s++)
                bad += f[s * stride] != fs[s] &&
                       !(fabs(c[s * stride] - cs[s]) <= fmax(1e-12 * cs[s], 1e-15));
            printf("proj 381->390 rows=%d d=6 beta=%g gamma=%g, %d thread%s: brute %.2f s "
                   "(%d-row subset, extrapolated), embree %.1f ms (%.0fx), seeded %.1f ms (%.0fx)\n",
                   n, params[pi][0], params[pi][1], threads, threads > 1 ? "s" : "", tb, nsub,
                   1e3 * te, tb / te, 1e3 * tsd, tb / tsd);
        }
    }
    if (bad)
        FAILF("%d rows differ from brute force", bad);
    free(Z), free(Q), free(Qs), free(f), free(fs), free(w), free(ws), free(c), free(cs);
    free(Y), free(Yt);
    bmap_free(P), bmap_free(Qm);
    proj_tree_free(tree);
    mesh_free(X), mesh_free(Xt);
}
