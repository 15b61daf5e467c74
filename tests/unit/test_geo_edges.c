/* test_geo_edges.c — the edge table: Euler characteristic, opposite
 * vertices, boundary edges, sorted incidence lists, non-manifold refusal. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "geo/geo_edges.h"

#include <string.h>

static void check_table(const mesh *m, const geo_edges *e)
{
    for (int t = 0; t < m->nf; t++)
        for (int k = 0; k < 3; k++) {
            int ed = e->fe[3 * t + k];
            int i = m->f[3 * t + (k + 1) % 3], j = m->f[3 * t + (k + 2) % 3];
            CHECK((e->ev[2 * ed] == i && e->ev[2 * ed + 1] == j) ||
                  (e->ev[2 * ed] == j && e->ev[2 * ed + 1] == i));
            int side = e->ef[2 * ed] == t ? 0 : 1;
            CHECK_INT(e->ef[2 * ed + side], t);
            CHECK_INT(e->eo[2 * ed + side], m->f[3 * t + k]);
        }
    for (int i = 0; i < m->nv; i++)
        for (int s = e->vf_start[i]; s < e->vf_start[i + 1]; s++) {
            CHECK_INT(m->f[3 * e->vf_face[s] + e->vf_corner[s]], i);
            if (s > e->vf_start[i])
                CHECK(e->vf_face[s - 1] < e->vf_face[s]);
        }
}

TEST(edges_icosphere_euler_2_no_boundary)
{
    mesh *m = testmesh_icosphere(3);
    geo_edges e;
    CHECK_INT(geo_edges_build(m, &e, NULL, 0), 0);
    CHECK_INT(m->nv - e.ne + m->nf, 2);
    CHECK_INT(geo_edges_boundary_count(&e), 0);
    check_table(m, &e);
    geo_edges_close(&e);
    mesh_free(m);
}

TEST(edges_torus_euler_0)
{
    mesh *m = testmesh_torus(2, 0.5, 24, 12);
    geo_edges e;
    CHECK_INT(geo_edges_build(m, &e, NULL, 0), 0);
    CHECK_INT(m->nv - e.ne + m->nf, 0);
    check_table(m, &e);
    geo_edges_close(&e);
    mesh_free(m);
}

TEST(edges_disk_has_one_boundary_ring)
{
    mesh *m = testmesh_disk(6);
    geo_edges e;
    CHECK_INT(geo_edges_build(m, &e, NULL, 0), 0);
    CHECK_INT(m->nv - e.ne + m->nf, 1);
    CHECK_INT(geo_edges_boundary_count(&e), 36);
    check_table(m, &e);
    geo_edges_close(&e);
    mesh_free(m);
}

TEST(edges_refuse_non_manifold_edge_with_message)
{
    mesh *m = mesh_new(5, 3);
    int f[9] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
    memcpy(m->f, f, sizeof f);
    geo_edges e;
    char err[256];
    CHECK_INT(geo_edges_build(m, &e, err, sizeof err), GEO_ENONMANIFOLD);
    CHECK_STR_HAS(err, "edge (0, 1) has 3 faces");
    geo_edges_close(&e);
    mesh_free(m);
}

TEST(edges_real_mesh_closed_genus0)
{
    char err[256];
    mesh *m = NULL;
    CHECK_INT(mesh_read(harness_data_path("shrec07_bim/Meshes/390.off"), &m, err, sizeof err), 0);
    geo_edges e;
    CHECK_INT(geo_edges_build(m, &e, err, sizeof err), 0);
    CHECK_INT(m->nv - e.ne + m->nf, 2);
    check_table(m, &e);
    geo_edges_close(&e);
    mesh_free(m);
}
