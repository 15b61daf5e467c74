/* test_geo_cache.c — the lazy cache returns exactly what the direct
 * functions compute, computes each quantity once, and keeps the first
 * error of a mesh it cannot build an edge table for. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "geo/geo_area.h"
#include "geo/geo_cache.h"
#include "geo/geo_cotan.h"
#include "geo/geo_curvature.h"
#include "geo/geo_dihedral.h"
#include "geo/geo_normals.h"

#include <string.h>

static void check_same(const double *cached, const double *direct, int n, const char *what)
{
    if (!cached)
        FAILF("%s: cache returned NULL", what);
    if (memcmp(cached, direct, sizeof(double) * n) != 0)
        FAILF("%s: cached values differ from the direct computation", what);
}

static void check_cache(const mesh *m)
{
    char err[256];
    geo_cache *c = geo_cache_new(m);
    CHECK(c != NULL);
    /* ask for the most derived quantity first: it pulls in its inputs */
    const double *H = geo_cache_mean_curvature(c);
    CHECK(H != NULL);
    CHECK(geo_cache_mean_curvature(c) == H);

    int nv = m->nv, nf = m->nf;
    double *fa = malloc(sizeof(double) * nf), *mass = malloc(sizeof(double) * nv);
    double *fn = malloc(sizeof(double) * 3 * nf), *vn = malloc(sizeof(double) * 3 * nv);
    double *Hd = malloc(sizeof(double) * nv);
    geo_face_areas(m, fa);
    geo_vertex_areas(m, mass);
    geo_face_normals(m, fn);
    geo_vertex_normals(m, vn);
    check_same(geo_cache_face_areas(c), fa, nf, "face areas");
    check_same(geo_cache_vertex_areas(c), mass, nv, "vertex areas");
    check_same(geo_cache_face_normals(c), fn, 3 * nf, "face normals");
    check_same(geo_cache_vertex_normals(c), vn, 3 * nv, "vertex normals");
    CHECK(geo_cache_total_area(c) == geo_total_area(m));

    geo_edges e;
    geo_csr *L = NULL;
    CHECK_INT(geo_edges_build(m, &e, err, sizeof err), 0);
    const geo_edges *ce = geo_cache_edges(c);
    CHECK(ce != NULL && ce->ne == e.ne);
    CHECK(memcmp(ce->ev, e.ev, sizeof(int) * 2 * e.ne) == 0);
    CHECK(memcmp(ce->ef, e.ef, sizeof(int) * 2 * e.ne) == 0);
    double *dc = malloc(sizeof(double) * e.ne), *w = malloc(sizeof(double) * e.ne);
    geo_dihedral_cosines(&e, fn, dc);
    geo_cotan_weights(m, &e, w);
    check_same(geo_cache_dihedral_cosines(c), dc, e.ne, "dihedral cosines");
    check_same(geo_cache_cotan_weights(c), w, e.ne, "cotan weights");
    CHECK_INT(geo_cotan_laplacian(m, &e, &L, err, sizeof err), 0);
    const geo_csr *cl = geo_cache_laplacian(c);
    CHECK(cl != NULL && cl->n == L->n);
    CHECK(memcmp(cl->row_start, L->row_start, sizeof(int) * (L->n + 1)) == 0);
    CHECK(memcmp(cl->col, L->col, sizeof(int) * L->row_start[L->n]) == 0);
    check_same(cl->val, L->val, L->row_start[L->n], "Laplacian");
    CHECK_INT(geo_mean_curvature(m, L, mass, vn, Hd, err, sizeof err), 0);
    check_same(H, Hd, nv, "mean curvature");

    /* the same arrays every time */
    CHECK(geo_cache_face_areas(c) == geo_cache_face_areas(c));
    CHECK(geo_cache_laplacian(c) == cl);
    CHECK(geo_cache_edges(c) == ce);
    CHECK_INT(geo_cache_error(c), 0);
    CHECK(geo_cache_errmsg(c)[0] == 0);

    free(fa); free(mass); free(fn); free(vn); free(Hd); free(dc); free(w);
    geo_csr_free(L);
    geo_edges_close(&e);
    geo_cache_free(c);
}

TEST(cache_equals_direct_computation_on_generated_meshes)
{
    mesh *ms[3] = {testmesh_icosphere(3), testmesh_torus(2, 0.5, 32, 16), testmesh_disk(6)};
    for (int i = 0; i < 3; i++) {
        check_cache(ms[i]);
        mesh_free(ms[i]);
    }
}

TEST(cache_equals_direct_computation_on_a_real_mesh)
{
    char err[256];
    mesh *m = NULL;
    CHECK_INT(mesh_read(harness_data_path("shrec07_bim/Meshes/381.off"), &m, err, sizeof err), 0);
    check_cache(m);
    mesh_free(m);
}

TEST(cache_keeps_first_error_and_still_serves_areas)
{
    mesh *m = mesh_new(5, 3);
    double v[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1};
    int f[9] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
    memcpy(m->v, v, sizeof v);
    memcpy(m->f, f, sizeof f);
    geo_cache *c = geo_cache_new(m);
    CHECK(geo_cache_laplacian(c) == NULL);
    CHECK(geo_cache_mean_curvature(c) == NULL);
    CHECK(geo_cache_dihedral_cosines(c) == NULL);
    CHECK_INT(geo_cache_error(c), GEO_ENONMANIFOLD);
    CHECK_STR_HAS(geo_cache_errmsg(c), "edge (0, 1) has 3 faces");
    CHECK(geo_cache_face_areas(c) != NULL);
    CHECK_NEAR(geo_cache_total_area(c), 1.5, 1e-15);
    geo_cache_free(c);
    geo_cache_free(NULL);
    mesh_free(m);
}
