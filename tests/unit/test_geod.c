/* test_geod.c — heat-method geodesic distances against closed forms (unit
 * sphere: arccos; flat disk: Euclidean), convergence under refinement,
 * multi-source = min of single sources, Voronoi cells, and invariants on a
 * real FAUST mesh (near-symmetry, triangle inequality), and the intrinsic
 * Delaunay operators on a badly sheared grid. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "geod/geod.h"
#include "geod/geod_voronoi.h"

#include <math.h>
#include <string.h>

typedef struct { double max_rel, mean_rel, max_abs; } errs;

/* Errors of dist against the exact distance from vertex src; relative
 * errors over vertices at distance >= 5 h (near the source the relative
 * error of any discretisation blows up), absolute everywhere. */
static errs compare(const mesh *m, const double *dist, int src, int sphere, double h)
{
    errs e = {0, 0, 0};
    int n = 0;
    const double *p = m->v + 3 * src;
    for (int i = 0; i < m->nv; i++) {
        const double *q = m->v + 3 * i;
        double exact;
        if (sphere) {
            double c = p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
            exact = acos(c > 1 ? 1 : c < -1 ? -1 : c);
        } else {
            exact = hypot(q[0] - p[0], q[1] - p[1]);
        }
        double a = fabs(dist[i] - exact);
        if (a > e.max_abs)
            e.max_abs = a;
        if (exact >= 5 * h) {
            double r = a / exact;
            if (r > e.max_rel)
                e.max_rel = r;
            e.mean_rel += r;
            n++;
        }
    }
    e.mean_rel /= n;
    return e;
}

static errs run_one(mesh *m, int src, int sphere, double h)
{
    char err[256] = "";
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, err, sizeof err);
    if (!s)
        FAILF("solver: %s", err);
    double *d = malloc(m->nv * sizeof *d);
    CHECK_INT(geod_distances(s, &src, 1, d), GEOD_OK);
    CHECK_NEAR(d[src], 0, 0);
    errs e = compare(m, d, src, sphere, h);
    free(d);
    geod_solver_free(s);
    return e;
}

/* Measured (t = h^2): L4 max rel 0.044, mean rel 0.010, max abs 0.029;
 * L5 max rel 0.046, mean rel 0.0067, max abs 0.019. */
TEST(sphere_distances_match_arccos_and_converge)
{
    mesh *m4 = testmesh_icosphere(4), *m5 = testmesh_icosphere(5);
    errs e4 = run_one(m4, 0, 1, 0.05), e5 = run_one(m5, 0, 1, 0.025);
    printf("  sphere L4: max rel %.4f mean rel %.4f max abs %.4f\n", e4.max_rel, e4.mean_rel, e4.max_abs);
    printf("  sphere L5: max rel %.4f mean rel %.4f max abs %.4f\n", e5.max_rel, e5.mean_rel, e5.max_abs);
    CHECK(e4.max_rel < 0.06 && e5.max_rel < 0.06);
    CHECK(e4.mean_rel < 0.015 && e5.mean_rel < 0.01);
    CHECK(e5.mean_rel < 0.8 * e4.mean_rel);
    CHECK(e5.max_abs < 0.8 * e4.max_abs);
    mesh_free(m4);
    mesh_free(m5);
}

/* Measured: centre source max rel 0.030 (both), mean rel 0.011 -> 0.0064,
 * max abs 0.011 -> 0.0054; off-centre source (the boundary matters) max rel
 * 0.055 / 0.056, mean rel 0.016 -> 0.012, max abs 0.025 -> 0.018. With
 * Neumann alone the off-centre max rel was 0.11 / 0.08. */
TEST(disk_distances_match_euclidean_and_converge)
{
    mesh *a = testmesh_disk(16), *b = testmesh_disk(32);
    errs ea = run_one(a, 0, 0, 1.0 / 16), eb = run_one(b, 0, 0, 1.0 / 32);
    printf("  disk 16 centre: max rel %.4f mean rel %.4f max abs %.4f\n", ea.max_rel, ea.mean_rel, ea.max_abs);
    printf("  disk 32 centre: max rel %.4f mean rel %.4f max abs %.4f\n", eb.max_rel, eb.mean_rel, eb.max_abs);
    CHECK(ea.max_rel < 0.04 && eb.max_rel < 0.04);
    CHECK(eb.mean_rel < 0.8 * ea.mean_rel && eb.max_abs < 0.6 * ea.max_abs);
    /* an off-centre source: first vertex of ring rings/2 */
    int sa = 1 + 3 * 8 * 7, sb = 1 + 3 * 16 * 15;
    CHECK_NEAR(hypot(a->v[3 * sa], a->v[3 * sa + 1]), 0.5, 1e-12);
    CHECK_NEAR(hypot(b->v[3 * sb], b->v[3 * sb + 1]), 0.5, 1e-12);
    ea = run_one(a, sa, 0, 1.0 / 16);
    eb = run_one(b, sb, 0, 1.0 / 32);
    printf("  disk 16 off: max rel %.4f mean rel %.4f max abs %.4f\n", ea.max_rel, ea.mean_rel, ea.max_abs);
    printf("  disk 32 off: max rel %.4f mean rel %.4f max abs %.4f\n", eb.max_rel, eb.mean_rel, eb.max_abs);
    CHECK(ea.max_rel < 0.07 && eb.max_rel < 0.07);
    CHECK(ea.mean_rel < 0.02 && eb.mean_rel < 0.9 * ea.mean_rel && eb.max_abs < 0.9 * ea.max_abs);
    mesh_free(a);
    mesh_free(b);
}

TEST(multi_source_is_min_of_single_sources_and_zero_at_sources)
{
    mesh *m = testmesh_icosphere(4);
    char err[256] = "";
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, err, sizeof err);
    if (!s)
        FAILF("%s", err);
    int src[3] = {0, 700, 1900};
    double *multi = malloc(m->nv * sizeof *multi), *single = malloc(3 * m->nv * sizeof *single);
    CHECK_INT(geod_distances(s, src, 3, multi), GEOD_OK);
    CHECK_INT(geod_all_pairs_from(s, src, 3, single), GEOD_OK);
    double maxdiff = 0;
    for (int i = 0; i < m->nv; i++) {
        double mn = fmin(single[i], fmin(single[m->nv + i], single[2 * m->nv + i]));
        maxdiff = fmax(maxdiff, fabs(multi[i] - mn));
    }
    printf("  max |multi - min(single)| = %.4f\n", maxdiff);
    /* measured 0.087 (~1.7 h): where two fronts meet, the multi-source heat
     * field is blurred over a band of width ~ sqrt(t) = h */
    CHECK(maxdiff < 0.1);
    for (int k = 0; k < 3; k++) {
        CHECK(multi[src[k]] == 0);
        CHECK(single[k * m->nv + src[k]] == 0);
    }
    /* a field from the batch equals the single-source call */
    CHECK_INT(geod_distances(s, &src[1], 1, multi), GEOD_OK);
    for (int i = 0; i < m->nv; i++)
        CHECK_NEAR(multi[i], single[m->nv + i], 1e-9);
    free(multi);
    free(single);
    geod_solver_free(s);
    mesh_free(m);
}

TEST(bad_sources_are_refused)
{
    mesh *m = testmesh_icosphere(2);
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, NULL, 0);
    CHECK(s != NULL);
    double *d = malloc(m->nv * sizeof *d);
    int bad = m->nv, neg = -1, ok = 0;
    CHECK_INT(geod_distances(s, &bad, 1, d), GEOD_EINVAL);
    CHECK_INT(geod_distances(s, &neg, 1, d), GEOD_EINVAL);
    CHECK_INT(geod_distances(s, &ok, 0, d), GEOD_EINVAL);
    CHECK(strcmp(geod_strerror(GEOD_EINVAL), "invalid argument") == 0);
    free(d);
    geod_solver_free(s);
    geod_solver_free(NULL);
    mesh_free(m);
}

TEST(other_components_are_infinitely_far)
{
    mesh *a = testmesh_icosphere(2);
    mesh *m = mesh_new(2 * a->nv, 2 * a->nf);
    for (int i = 0; i < a->nv; i++)
        for (int d = 0; d < 3; d++) {
            m->v[3 * i + d] = a->v[3 * i + d];
            m->v[3 * (a->nv + i) + d] = a->v[3 * i + d] + (d == 0 ? 3 : 0);
        }
    for (int t = 0; t < 3 * a->nf; t++) {
        m->f[t] = a->f[t];
        m->f[3 * a->nf + t] = a->f[t] + a->nv;
    }
    char err[256] = "";
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, err, sizeof err);
    if (!s)
        FAILF("%s", err);
    double *d = malloc(m->nv * sizeof *d);
    int src = 5;
    CHECK_INT(geod_distances(s, &src, 1, d), GEOD_OK);
    for (int i = 0; i < a->nv; i++)
        CHECK(isfinite(d[i]) && d[i] < 3.5);
    for (int i = a->nv; i < m->nv; i++)
        CHECK(isinf(d[i]));
    int two[2] = {5, a->nv + 5};
    CHECK_INT(geod_distances(s, two, 2, d), GEOD_OK);
    for (int i = 0; i < a->nv; i++)
        CHECK_NEAR(d[i], d[a->nv + i], 1e-9);
    free(d);
    geod_solver_free(s);
    mesh_free(m);
    mesh_free(a);
}

TEST(voronoi_cells_cover_and_own_their_landmarks)
{
    mesh *m = testmesh_icosphere(4);
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, NULL, 0);
    CHECK(s != NULL);
    int lm[7] = {3, 100, 999, 1500, 2000, 2561, 42};
    geod_voronoi *v = NULL;
    char err[256] = "";
    CHECK_INT(geod_voronoi_new(s, lm, 7, &v, err, sizeof err), GEOD_OK);
    CHECK_INT(v->nl, 7);
    int count[7] = {0};
    for (int i = 0; i < m->nv; i++) {
        CHECK(v->cell[i] >= 0 && v->cell[i] < 7);
        count[v->cell[i]]++;
        for (int a = 0; a < 7; a++)
            CHECK(v->nearest[i] <= v->dist[(size_t)a * m->nv + i]);
    }
    for (int a = 0; a < 7; a++) {
        CHECK_INT(v->cell[lm[a]], a);
        CHECK(v->dist[(size_t)a * m->nv + lm[a]] == 0);
        CHECK(count[a] > 0);
    }
    geod_voronoi_free(v);
    int dup[2] = {4, 4};
    CHECK_INT(geod_voronoi_new(s, dup, 2, &v, err, sizeof err), GEOD_EINVAL);
    CHECK_STR_HAS(err, "both vertex 4");
    CHECK(v == NULL);
    geod_solver_free(s);
    mesh_free(m);
}

TEST(voronoi_of_antipodal_landmarks_halves_the_sphere)
{
    mesh *m = testmesh_icosphere(4);
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, NULL, 0);
    CHECK(s != NULL);
    int anti = 0;
    for (int i = 1; i < m->nv; i++) {
        double c = m->v[0] * m->v[3 * i] + m->v[1] * m->v[3 * i + 1] + m->v[2] * m->v[3 * i + 2];
        double cb = m->v[0] * m->v[3 * anti] + m->v[1] * m->v[3 * anti + 1] + m->v[2] * m->v[3 * anti + 2];
        if (c < cb)
            anti = i;
    }
    int lm[2] = {0, anti};
    geod_voronoi *v = NULL;
    CHECK_INT(geod_voronoi_new(s, lm, 2, &v, NULL, 0), GEOD_OK);
    int n0 = 0, wrong = 0;
    for (int i = 0; i < m->nv; i++) {
        n0 += v->cell[i] == 0;
        double c = m->v[0] * m->v[3 * i] + m->v[1] * m->v[3 * i + 1] + m->v[2] * m->v[3 * i + 2];
        wrong += fabs(c) > 0.05 && (c > 0) != (v->cell[i] == 0); /* off the equator band */
    }
    printf("  cell 0 has %d of %d vertices; %d misplaced off the equator\n", n0, m->nv, wrong);
    CHECK(fabs(n0 - 0.5 * m->nv) < 0.03 * m->nv);
    CHECK_INT(wrong, 0);
    geod_voronoi_free(v);
    geod_solver_free(s);
    mesh_free(m);
}

TEST(faust_distances_nearly_symmetric_and_metric)
{
    mesh *m = NULL;
    char err[256] = "";
    if (mesh_read(harness_data_path("faust_r/vtx_5k/tr_reg_000.off"), &m, err, sizeof err))
        FAILF("%s", err);
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, err, sizeof err);
    if (!s)
        FAILF("%s", err);
    enum { K = 20 };
    int src[K];
    unsigned long long st = 7;
    for (int k = 0; k < K; k++)
        src[k] = (int)(testmesh_rand(&st) * m->nv);
    double *d = malloc((size_t)K * m->nv * sizeof *d);
    CHECK_INT(geod_all_pairs_from(s, src, K, d), GEOD_OK);
    for (size_t i = 0; i < (size_t)K * m->nv; i++)
        CHECK(isfinite(d[i]) && d[i] >= 0);
    double diam = 0, maxasym = 0, maxviol = 0;
    for (size_t i = 0; i < (size_t)K * m->nv; i++)
        diam = fmax(diam, d[i]);
#define D(a, b) d[(size_t)(a) * m->nv + src[b]]
    for (int a = 0; a < K; a++)
        for (int b = 0; b < K; b++) {
            if (a == b || src[a] == src[b])
                continue;
            double asym = fabs(D(a, b) - D(b, a)) / fmax(D(a, b), D(b, a));
            if (D(a, b) > 0.1 * diam)
                maxasym = fmax(maxasym, asym);
            for (int c = 0; c < K; c++) /* d(a,c) <= d(a,b) + d(b,c) */
                maxviol = fmax(maxviol, (D(a, c) - D(a, b) - D(b, c)) / diam);
        }
#undef D
    printf("  diameter %.4f, max asymmetry %.4f, max triangle violation %.4f of diameter\n",
           diam, maxasym, maxviol);
    CHECK(maxasym < 0.05);
    CHECK(maxviol < 0.02);
    free(d);
    geod_solver_free(s);
    mesh_free(m);
}

/* A flat n by n grid sheared by s per row, each cell split along its long
 * diagonal: every triangle has an angle near 160 degrees, most edges are
 * not Delaunay. */
static mesh *sheared_grid(int n, double s, double h)
{
    mesh *m = mesh_new(n * n, 2 * (n - 1) * (n - 1));
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double *p = m->v + 3 * (j * n + i);
            p[0] = (i + s * j) / (n - 1);
            p[1] = h * j / (n - 1);
            p[2] = 0;
        }
    int t = 0;
    for (int j = 0; j + 1 < n; j++)
        for (int i = 0; i + 1 < n; i++) {
            int a = j * n + i, b = a + 1, c = a + n + 1, d = a + n;
            int f[6] = {a, b, c, a, c, d};
            memcpy(m->f + 6 * t++, f, sizeof f);
        }
    return m;
}

/* On the intrinsic Delaunay triangulation every cotan weight is >= 0, the
 * operators keep their invariants (L 1 = 0, symmetric, mass sums to the
 * area), a Delaunay mesh needs no flip, and on the sheared grid distances
 * stay close to the Euclidean ones. Measured: 25 by 25 grid, shear 0.9:
 * 576 flips; from the corner max abs error 0.0192 (the far corner is 1.9
 * away), max rel 0.0173 (vertices >= 0.2 away). The heat method on the
 * mesh's own cotan Laplacian (negative weights; this project before the
 * flips) gave max abs 1.81 and max rel 1.00 on the same grid. */
TEST(intrinsic_delaunay_operators_and_distances_on_a_sheared_grid)
{
    mesh *m = sheared_grid(25, 0.9, 0.5), *ico = testmesh_icosphere(3);
    char err[256] = "";
    geod_solver *s = NULL, *si = NULL;
    geod_solver_new(m, 0, &s, err, sizeof err);
    geod_solver_new(ico, 0, &si, err, sizeof err);
    if (!s || !si)
        FAILF("%s", err);
    CHECK_INT(geod_solver_flips(si), 0);
    CHECK(geod_solver_flips(s) > 100);
    const geo_csr *L = geod_solver_laplacian(s);
    const double *mass = geod_solver_mass(s);
    double area = 0, worst_row = 0, worst_sym = 0, worst_off = 0;
    for (int i = 0; i < m->nv; i++) {
        double row = 0;
        area += mass[i];
        for (int p = L->row_start[i]; p < L->row_start[i + 1]; p++) {
            row += L->val[p];
            if (L->col[p] != i) {
                worst_off = fmax(worst_off, L->val[p]);
                worst_sym = fmax(worst_sym, fabs(L->val[p] - geo_csr_get(L, L->col[p], i)));
            }
        }
        worst_row = fmax(worst_row, fabs(row));
    }
    CHECK(worst_off <= 1e-12);
    CHECK(worst_row < 1e-9 && worst_sym < 1e-12);
    CHECK_NEAR(area, 0.5, 1e-12); /* the parallelogram: base 1, height 0.5 */
    double *d = malloc(m->nv * sizeof *d), maxabs = 0, maxrel = 0;
    int src = 0;
    CHECK_INT(geod_distances(s, &src, 1, d), GEOD_OK);
    for (int i = 0; i < m->nv; i++) {
        double ex = hypot(m->v[3 * i], m->v[3 * i + 1]), a = fabs(d[i] - ex);
        maxabs = fmax(maxabs, a);
        if (ex >= 0.2)
            maxrel = fmax(maxrel, a / ex);
    }
    printf("  %d flips; max abs %.4f, max rel %.4f\n", geod_solver_flips(s), maxabs, maxrel);
    CHECK(maxabs < 0.03 && maxrel < 0.03);
    free(d);
    geod_solver_free(s);
    geod_solver_free(si);
    mesh_free(m);
    mesh_free(ico);
}
