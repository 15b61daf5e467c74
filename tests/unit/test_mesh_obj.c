/* test_mesh_obj.c — OBJ reading and writing: real meshes, corner forms,
 * relative indices, refusals naming file, line and face. */
#include "support/harness.h"
#include "support/testfile.h"
#include "mesh/mesh.h"

#include <string.h>

TEST(obj_reads_real_mesh_with_normals_and_double_slash_faces)
{
    char err[512];
    mesh *m = NULL;
    CHECK_INT(mesh_read(harness_data_path("cartoon_elasticbasis/headB.obj"), &m, err, sizeof err), 0);
    CHECK_INT(m->nv, 14118);
    CHECK_INT(m->nf, 28232);
    mesh_free(m);
    CHECK_INT(mesh_read(harness_data_path("cartoon_elasticbasis/homerA.obj"), &m, err, sizeof err), 0);
    CHECK_INT(m->nv, 5103);
    CHECK_INT(m->nf, 10202);
    mesh_free(m);
}

TEST(obj_reads_all_corner_forms_and_negative_indices)
{
    char err[512];
    mesh *m = NULL;
    const char *p = testfile_text("forms.obj",
        "# comment\no thing\nv 0 0 0\nv 1 0 0\nvt 0 0\nvn 0 0 1\nv 0 1 0\nv 1 1 0 # tail\n"
        "f 1 2 3\nf 2/1 4/1 3/1\ng part\ns off\nf 1/1/1 2/1/1 3/1/1\nf 2//1 4//1 3//1\n"
        "f -4 -3 -2\nf -3/1 -1/1 -2/1\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), 0);
    CHECK_INT(m->nv, 4);
    CHECK_INT(m->nf, 6);
    const int want[18] = { 0, 1, 2, 1, 3, 2, 0, 1, 2, 1, 3, 2, 0, 1, 2, 1, 3, 2 };
    CHECK(memcmp(m->f, want, sizeof want) == 0);
    CHECK_NEAR(m->v[3 * 3 + 0], 1.0, 0);
    CHECK_NEAR(m->v[3 * 3 + 1], 1.0, 0);
    mesh_free(m);
}

TEST(obj_round_trip_keeps_order_and_exact_positions)
{
    char err[512];
    mesh *m = NULL, *m2 = NULL;
    CHECK_INT(mesh_read(harness_data_path("faust_r/vtx_5k/tr_reg_000.off"), &m, err, sizeof err), 0);
    char out[512];
    snprintf(out, sizeof out, "%s/x.obj", harness_tmpdir());
    CHECK_INT(mesh_write(out, m, err, sizeof err), 0);
    CHECK_INT(mesh_read(out, &m2, err, sizeof err), 0);
    CHECK_INT(m2->nv, m->nv);
    CHECK_INT(m2->nf, m->nf);
    CHECK(memcmp(m->v, m2->v, sizeof(double) * 3 * m->nv) == 0);
    CHECK(memcmp(m->f, m2->f, sizeof(int) * 3 * m->nf) == 0);
    mesh_free(m);
    mesh_free(m2);
}

TEST(obj_splits_a_polygon_naming_vertices_listed_after_it)
{
    char err[512];
    mesh *m = NULL;
    /* the pentagon is concave at its 4th corner, and comes before its last vertex */
    const char *p = testfile_text("penta.obj", "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 1 0.5 0\n"
                                               "f 1/1 2/2 3/3 4/4 5/5\nf 1 2 3\nv 0 2 0\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_OK);
    CHECK_INT(m->nf, 4);
    CHECK_INT(m->polygons, 1);
    const int want[] = { 1, 2, 3, 0, 1, 3, 0, 3, 4, 0, 1, 2 };   /* ears clipped, in place */
    for (int i = 0; i < 12; i++)
        CHECK_INT(m->f[i], want[i]);
    mesh_free(m);
    m = NULL;
    p = testfile_text("two.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_EPARSE);
    CHECK(m == NULL);
    CHECK_STR_HAS(err, "two.obj:5: face 1 has 2 vertices; a face needs 3");
}

TEST(obj_refuses_index_out_of_range_and_zero_index)
{
    char err[512];
    mesh *m = NULL;
    const char *p = testfile_text("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_EINVAL);
    CHECK_STR_HAS(err, "range.obj:4");
    CHECK_STR_HAS(err, "out of range");
    p = testfile_text("rel.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_EINVAL);
    CHECK_STR_HAS(err, "rel.obj:3");
    p = testfile_text("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_EPARSE);
    CHECK_STR_HAS(err, "zero.obj:4");
}

TEST(obj_refuses_short_vertex_line)
{
    char err[512];
    mesh *m = NULL;
    const char *p = testfile_text("short.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_EPARSE);
    CHECK_STR_HAS(err, "short.obj:2");
    CHECK_STR_HAS(err, "vertex 1");
}
