/* test_mesh_ply.c — PLY reading (ascii, binary in either byte order, extra
 * properties and elements, polygons) and writing; refusals of truncated and oversized
 * files. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testmesh.h"
#include "mesh/mesh.h"

#include <string.h>

/* The byte order put() writes in: 0 little endian, 1 big endian. */
static int big;

/* Appends the bytes of a value of size n in put's byte order. */
static size_t put(unsigned char *b, size_t at, const void *x, int n)
{
    for (int i = 0; i < n; i++)    /* the test machine is little endian */
        b[at + (size_t)i] = ((const unsigned char *)x)[big ? n - 1 - i : i];
    return at + (size_t)n;
}

TEST(ply_reads_ascii_with_extra_properties_and_elements)
{
    char err[512];
    mesh *m = NULL;
    const char *p = testfile_text("a.ply",
        "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 4\n"
        "property float x\nproperty float y\nproperty uchar red\nproperty float z\n"
        "property list uchar float extra\n"
        "element material 1\nproperty int id\n"
        "element face 2\nproperty uchar flags\nproperty list uchar int vertex_index\n"
        "end_header\n"
        "0 0 0 0 2 9 9\n1 0 0 0 0\n1 1 255 0.5 1 7\n0 1 0 0 0\n42\n1 3 0 1 2\n0 3 0 2 3\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), 0);
    CHECK_INT(m->nv, 4);
    CHECK_INT(m->nf, 2);
    CHECK_NEAR(m->v[3 * 2 + 2], 0.5, 0);
    CHECK_NEAR(m->v[3 * 2 + 1], 1.0, 0);
    const int want[6] = { 0, 1, 2, 0, 2, 3 };
    CHECK(memcmp(m->f, want, sizeof want) == 0);
    mesh_free(m);
}

/* A binary PLY of 3 vertices (float x y z with a double between) and one
 * face (int count, uint indices, a short after), in put's byte order, is
 * read, and refused when truncated. */
static void check_binary(void)
{
    char hdr[512];
    snprintf(hdr, sizeof hdr, "ply\nformat binary_%s_endian 1.0\nelement vertex 3\n"
             "property float x\nproperty double nx\nproperty float y\nproperty float z\n"
             "element face 1\nproperty list int uint vertex_indices\nproperty short s\n"
             "end_header\n", big ? "big" : "little");
    unsigned char b[1024];
    size_t at = strlen(hdr);
    memcpy(b, hdr, at);
    for (int i = 0; i < 3; i++) {
        float x = (float)i, y = (float)(2 * i), z = -1.5f;
        double nx = 7;
        at = put(b, at, &x, 4);
        at = put(b, at, &nx, 8);
        at = put(b, at, &y, 4);
        at = put(b, at, &z, 4);
    }
    int cnt = 3;
    unsigned idx[3] = { 2, 0, 1 };
    short s = -3;
    at = put(b, at, &cnt, 4);
    for (int i = 0; i < 3; i++)
        at = put(b, at, idx + i, 4);
    at = put(b, at, &s, 2);
    char err[512];
    mesh *m = NULL;
    CHECK_INT(mesh_read(testfile_write("b.ply", b, at), &m, err, sizeof err), 0);
    CHECK_INT(m->nv, 3);
    CHECK_INT(m->nf, 1);
    CHECK_NEAR(m->v[3 * 2 + 1], 4.0, 0);
    CHECK_NEAR(m->v[3 * 1 + 2], -1.5, 0);
    CHECK_INT(m->f[0], 2);
    CHECK_INT(m->f[2], 1);
    mesh_free(m);

    /* Truncated by one byte, and cut in the vertex block. */
    CHECK(mesh_read(testfile_write("t1.ply", b, at - 1), &m, err, sizeof err) < 0);
    CHECK_STR_HAS(err, "truncated");
    CHECK(mesh_read(testfile_write("t2.ply", b, strlen(hdr) + 30), &m, err, sizeof err) < 0);
    CHECK_STR_HAS(err, "more than the file holds");
    CHECK(m == NULL);
}

TEST(ply_reads_binary_in_either_byte_order)
{
    for (big = 0; big < 2; big++)
        check_binary();
    big = 0;
}

TEST(ply_round_trip_is_exact_and_keeps_order)
{
    char err[512];
    mesh *m = NULL, *m2 = NULL;
    CHECK_INT(mesh_read(harness_data_path("shrec07_bim/Meshes/381.off"), &m, err, sizeof err), 0);
    char out[512];
    snprintf(out, sizeof out, "%s/x.ply", harness_tmpdir());
    CHECK_INT(mesh_write(out, m, err, sizeof err), 0);
    CHECK_INT(mesh_read(out, &m2, err, sizeof err), 0);
    CHECK_INT(m2->nv, 6938);
    CHECK_INT(m2->nf, 13872);
    CHECK(memcmp(m->v, m2->v, sizeof(double) * 3 * m->nv) == 0);
    CHECK(memcmp(m->f, m2->f, sizeof(int) * 3 * m->nf) == 0);
    mesh_free(m);
    mesh_free(m2);
}

TEST(ply_refuses_count_over_limit_naming_element_and_limit)
{
    char err[512];
    mesh *m = NULL;
    const char *p = testfile_text("big.ply",
        "ply\nformat binary_little_endian 1.0\nelement vertex 20000001\nproperty float x\n"
        "property float y\nproperty float z\nend_header\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_ELIMIT);
    CHECK_STR_HAS(err, "big.ply:3");
    CHECK_STR_HAS(err, "element vertex");
    CHECK_STR_HAS(err, "20000000");
    p = testfile_text("many.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 5000000\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_EPARSE);
    CHECK_STR_HAS(err, "more than the file holds");
}

TEST(ply_splits_a_quad_and_refuses_an_unknown_format_and_bad_index)
{
    char err[512];
    mesh *m = NULL;
    const char *head = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                       "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                       "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
    char text[1024];
    snprintf(text, sizeof text, "%s4 0 1 2 3\n", head);
    CHECK_INT(mesh_read(testfile_text("quad.ply", text), &m, err, sizeof err), MESH_OK);
    CHECK_INT(m->nf, 2);
    CHECK_INT(m->polygons, 1);
    mesh_free(m);
    m = NULL;
    snprintf(text, sizeof text, "%s2 0 1\n", head);
    CHECK_INT(mesh_read(testfile_text("two.ply", text), &m, err, sizeof err), MESH_EPARSE);
    CHECK_STR_HAS(err, "face 0 has 2 vertices; a face needs 3");
    snprintf(text, sizeof text, "%s3 0 1 4\n", head);
    CHECK_INT(mesh_read(testfile_text("idx.ply", text), &m, err, sizeof err), MESH_EINVAL);
    CHECK_STR_HAS(err, "out of range");
    CHECK_INT(mesh_read(testfile_text("me.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n"),
                        &m, err, sizeof err), MESH_EFORMAT);
    CHECK_STR_HAS(err, "unsupported PLY format \"binary_middle_endian\"");
}
