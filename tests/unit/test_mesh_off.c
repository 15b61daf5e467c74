/* test_mesh_off.c — OFF reading and writing: counts, order, refusals. */
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

TEST(off_refuses_polygon)
{
    char err[512];
    mesh *m = NULL;
    const char *p = write_file("quad.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_EPARSE);
    CHECK_STR_HAS(err, "only triangles");
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
