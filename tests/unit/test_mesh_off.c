/* test_mesh_off.c — OFF reading and writing: counts, order, polygons, the
 * COFF / NOFF / STOFF variants, refusals. */
#include "support/harness.h"
#include "mesh/mesh.h"

#include <string.h>

static const char *write_file(const char *name, const char *text)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", harness_tmpdir(), name);
    FILE *fp = fopen(path, "w");
    CHECK(fp);
    fputs(text, fp);
    fclose(fp);
    return path;
}

TEST(off_reads_real_mesh_with_counts)
{
    char err[512];
    mesh *m = NULL;
    CHECK_INT(mesh_read(harness_data_path("shrec07_bim/Meshes/381.off"), &m, err, sizeof err), 0);
    CHECK_INT(m->nv, 6938);
    CHECK_INT(m->nf, 13872);
    mesh_free(m);
}

TEST(off_round_trip_keeps_order_and_positions)
{
    char err[512];
    mesh *m = NULL, *m2 = NULL;
    CHECK_INT(mesh_read(harness_data_path("sumner_pyfm/lion-00.off"), &m, err, sizeof err), 0);
    char out[512];
    snprintf(out, sizeof out, "%s/x.off", harness_tmpdir());
    CHECK_INT(mesh_write(out, m, err, sizeof err), 0);
    CHECK_INT(mesh_read(out, &m2, err, sizeof err), 0);
    CHECK_INT(m2->nv, m->nv);
    CHECK_INT(m2->nf, m->nf);
    CHECK(memcmp(m->v, m2->v, sizeof(double) * 3 * m->nv) == 0);
    CHECK(memcmp(m->f, m2->f, sizeof(int) * 3 * m->nf) == 0);
    mesh_free(m);
    mesh_free(m2);
}

TEST(off_refuses_index_out_of_range_naming_line)
{
    char err[512];
    mesh *m = NULL;
    const char *p = write_file("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_EINVAL);
    CHECK(m == NULL);
    CHECK_STR_HAS(err, "bad.off:6");
    CHECK_STR_HAS(err, "out of range");
}

TEST(off_splits_a_quad_in_its_place_and_refuses_a_face_of_two)
{
    char err[512];
    mesh *m = NULL;
    const char *p = write_file("quad.off", "OFF\n5 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n"
                                           "3 0 4 1\n4 0 1 2 3\n3 3 4 0\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_OK);
    CHECK_INT(m->nf, 4);
    CHECK_INT(m->polygons, 1);
    const int want[] = { 0, 4, 1, 0, 1, 2, 0, 2, 3, 3, 4, 0 };   /* the quad's two where it stood */
    for (int i = 0; i < 12; i++)
        CHECK_INT(m->f[i], want[i]);
    mesh_free(m);
    m = NULL;
    p = write_file("two.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n1 1 0\n2 0 1\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_EPARSE);
    CHECK(m == NULL);
    CHECK_STR_HAS(err, "two.off:6: face 0 has 2 vertices; a face needs 3");
}

TEST(off_refuses_counts_larger_than_file)
{
    char err[512];
    mesh *m = NULL;
    const char *p = write_file("huge.off", "OFF\n19000000 1 0\n0 0 0\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_EPARSE);
    CHECK_STR_HAS(err, "more than the file holds");
}

TEST(off_refuses_truncated_vertex)
{
    char err[512];
    mesh *m = NULL;
    const char *p = write_file("trunc.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1\n");
    CHECK(mesh_read(p, &m, err, sizeof err) < 0);
    CHECK_STR_HAS(err, "vertex 2");
}

TEST(off_reads_colour_normal_and_texture_variants_and_names_a_header_it_does_not)
{
    char err[512];
    mesh *m = NULL;
    const char *p = write_file("c.off", "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n"
                                         "0 1 0 0 0 255 255\n3 0 1 2 10 20 30\n");
    CHECK_INT(mesh_read_off(p, &m, err, sizeof err), MESH_OK);
    CHECK_INT(m->nv, 3);
    CHECK_NEAR(m->v[3 * 2 + 1], 1.0, 0);
    CHECK_INT(m->f[2], 2);
    mesh_free(m);
    m = NULL;
    p = write_file("n.off", "STCNOFF 3 1 0\n0 0 0 0 0 1 1 1 1 1 0 0\n1 0 0 0 0 1 1 1 1 1 1 0\n"
                            "0 1 0 0 0 1 1 1 1 1 0 1\n3 0 1 2\n");
    CHECK_INT(mesh_read_off(p, &m, err, sizeof err), MESH_OK);
    CHECK_NEAR(m->v[3 * 1], 1.0, 0);
    mesh_free(m);
    m = NULL;
    p = write_file("four.off", "4OFF\n3 1 0\n0 0 0 1\n1 0 0 1\n0 1 0 1\n3 0 1 2\n");
    CHECK_INT(mesh_read_off(p, &m, err, sizeof err), MESH_EPARSE);
    CHECK(m == NULL);
    CHECK_STR_HAS(err, "four.off:1: expected the header \"OFF\"");
    CHECK_STR_HAS(err, "got \"4OFF\"");
}
