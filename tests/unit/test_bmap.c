/* test_bmap.c — barycentric maps: reading the real HOT maps 381 ↔ 390,
 * round trip, every refusal with its line number, and P·Z. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "map/bmap.h"

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

static void check_valid(const bmap *P, const mesh *tg)
{
    for (int i = 0; i < P->n; i++) {
        CHECK(P->face[i] >= 0 && P->face[i] < tg->nf);
        const double *w = P->w + 3 * i;
        CHECK(w[0] >= 0 && w[1] >= 0 && w[2] >= 0);
        CHECK_NEAR(w[0] + w[1] + w[2], 1, 4e-16);
    }
}

TEST(read_real_maps_381_390_both_directions)
{
    mesh *a = testmesh_read("shrec07_bim/Meshes/381.off"), *b = testmesh_read("shrec07_bim/Meshes/390.off");
    char err[512];
    bmap *P = NULL, *Q = NULL;
    int rc = bmap_read(harness_data_path("ectm_demo_381_390/init_381_to_390.map"), a, b, &P,
                       err, sizeof err);
    if (rc)
        FAILF("%s", err);
    CHECK_INT(P->n, 6938);
    CHECK_INT(P->nt, 9239);
    CHECK_INT(P->face[0], 10915);
    CHECK_NEAR(P->w[0], 0.233385, 1e-5);
    check_valid(P, b);
    rc = bmap_read(harness_data_path("ectm_demo_381_390/init_390_to_381.map"), b, a, &Q,
                   err, sizeof err);
    if (rc)
        FAILF("%s", err);
    CHECK_INT(Q->n, 9239);
    CHECK_INT(Q->nt, 6938);
    check_valid(Q, a);
    /* the wrong direction is refused by size */
    bmap *R = (bmap *)1;
    CHECK_INT(bmap_read(harness_data_path("ectm_demo_381_390/init_390_to_381.map"), a, b, &R,
                        err, sizeof err), BMAP_ESIZE);
    CHECK(R == NULL);
    CHECK_STR_HAS(err, "init_390_to_381.map:3");
    CHECK_STR_HAS(err, "9239 -> 6938");
    bmap_free(P);
    bmap_free(Q);
    mesh_free(a);
    mesh_free(b);
}

TEST(write_then_read_is_bit_identical)
{
    mesh *a = testmesh_read("shrec07_bim/Meshes/381.off"), *b = testmesh_read("shrec07_bim/Meshes/390.off");
    char err[512], out[512];
    bmap *P = NULL, *P2 = NULL;
    CHECK_INT(bmap_read(harness_data_path("ectm_demo_381_390/init_381_to_390.map"), a, b, &P,
                        err, sizeof err), 0);
    snprintf(out, sizeof out, "%s/rt.map", harness_tmpdir());
    CHECK_INT(bmap_write(out, P, "round trip\nsecond comment line", err, sizeof err), 0);
    CHECK_INT(bmap_read(out, a, b, &P2, err, sizeof err), 0);
    CHECK_INT(P2->n, P->n);
    CHECK_INT(P2->nt, P->nt);
    CHECK(memcmp(P->face, P2->face, sizeof(int) * P->n) == 0);
    CHECK(memcmp(P->w, P2->w, sizeof(double) * 3 * P->n) == 0);
    FILE *fp = fopen(out, "r");
    char line[256];
    CHECK(fgets(line, sizeof line, fp) && strcmp(line, "# meshcorr-map 1\n") == 0);
    CHECK(fgets(line, sizeof line, fp) && strcmp(line, "# round trip\n") == 0);
    CHECK(fgets(line, sizeof line, fp) && strcmp(line, "# second comment line\n") == 0);
    CHECK(fgets(line, sizeof line, fp) && strcmp(line, "6938 9239\n") == 0);
    fclose(fp);
    bmap_free(P);
    bmap_free(P2);
    mesh_free(a);
    mesh_free(b);
}

/* Two tiny meshes: source 2 vertices (no faces needed), target 4 vertices
 * and 2 faces. */
static void tiny(mesh **s, mesh **t)
{
    *s = mesh_new(2, 0);
    *t = mesh_new(4, 2);
    int f[6] = { 0, 1, 2, 0, 2, 3 };
    memcpy((*t)->f, f, sizeof f);
}

static void refuse(const char *name, const char *text, int code, const char *what,
                   const char *where)
{
    mesh *s, *t;
    tiny(&s, &t);
    char err[512] = "";
    bmap *P = (bmap *)1;
    int rc = bmap_read(write_file(name, text), s, t, &P, err, sizeof err);
    if (rc != code)
        FAILF("%s: code %d, expected %d; message: %s", name, rc, code, err);
    CHECK(P == NULL);
    CHECK_STR_HAS(err, where);
    CHECK_STR_HAS(err, what);
    mesh_free(s);
    mesh_free(t);
}

TEST(accepts_small_valid_map_clamping_and_renormalising)
{
    mesh *s, *t;
    tiny(&s, &t);
    char err[512];
    bmap *P = NULL;
    const char *p = write_file("ok.map", "# meshcorr-map 1\n# c\n2 4\n1 0.5 0.5 0\n"
                                         "0 -0.00005 0.50004 0.5\n");
    if (bmap_read(p, s, t, &P, err, sizeof err))
        FAILF("%s", err);
    CHECK_INT(P->face[0], 1);
    CHECK(P->w[0] == 0.5 && P->w[1] == 0.5 && P->w[2] == 0);
    CHECK(P->w[3] == 0);
    CHECK_NEAR(P->w[4] + P->w[5], 1, 1e-16);
    CHECK_NEAR(P->w[4], 0.50004 / 1.00004, 1e-15);
    bmap_free(P);
    mesh_free(s);
    mesh_free(t);
}

TEST(refuses_weights_not_summing_to_1)
{
    refuse("sum.map", "# meshcorr-map 1\n2 4\n0 1 0 0\n1 0.5 0.5 0.1\n", BMAP_EWEIGHT,
           "sum to", "sum.map:4");
}

TEST(refuses_negative_weight)
{
    refuse("neg.map", "# meshcorr-map 1\n2 4\n0 -0.1 0.6 0.5\n1 1 0 0\n", BMAP_EWEIGHT,
           "negative", "neg.map:3");
}

TEST(refuses_face_out_of_range)
{
    refuse("face.map", "# meshcorr-map 1\n# x\n2 4\n0 1 0 0\n2 1 0 0\n", BMAP_ERANGE,
           "face 2 out of range", "face.map:5");
    refuse("faceneg.map", "# meshcorr-map 1\n2 4\n-1 1 0 0\n0 1 0 0\n", BMAP_ERANGE,
           "out of range", "faceneg.map:3");
}

TEST(refuses_map_sized_for_other_meshes)
{
    refuse("size.map", "# meshcorr-map 1\n3 4\n0 1 0 0\n0 1 0 0\n0 1 0 0\n", BMAP_ESIZE,
           "3 -> 4", "size.map:2");
    refuse("sizet.map", "# meshcorr-map 1\n2 5\n0 1 0 0\n0 1 0 0\n", BMAP_ESIZE,
           "2 -> 5", "sizet.map:2");
}

TEST(refuses_truncated_and_overlong_files)
{
    refuse("trunc.map", "# meshcorr-map 1\n2 4\n0 1 0 0\n", BMAP_EPARSE,
           "after 1 of the 2 rows", "trunc.map:3");
    refuse("cut.map", "# meshcorr-map 1\n2 4\n0 1 0 0\n1 0.5 0.5\n", BMAP_EPARSE,
           "source vertex 1", "cut.map:4");
    refuse("nocount.map", "# meshcorr-map 1\n# only comments\n", BMAP_EPARSE,
           "before the counts", "nocount.map:2");
    refuse("long.map", "# meshcorr-map 1\n2 4\n0 1 0 0\n0 1 0 0\n0 1 0 0\n", BMAP_EPARSE,
           "more than the 2 rows", "long.map:5");
    refuse("junk.map", "# meshcorr-map 1\n2 4\n0 1 0 0 7\n0 1 0 0\n", BMAP_EPARSE,
           "<face> <w0> <w1> <w2>", "junk.map:3");
}

TEST(refuses_nan_weight)
{
    refuse("nan.map", "# meshcorr-map 1\n2 4\n0 1 0 0\n0 nan 0.5 0.5\n", BMAP_EWEIGHT,
           "not a finite number", "nan.map:4");
}

TEST(refuses_missing_or_wrong_header)
{
    refuse("nohdr.map", "2 4\n0 1 0 0\n0 1 0 0\n", BMAP_EPARSE, "# meshcorr-map 1",
           "nohdr.map:1");
    refuse("v2.map", "# meshcorr-map 2\n2 4\n0 1 0 0\n0 1 0 0\n", BMAP_EPARSE,
           "first line", "v2.map:1");
    refuse("empty.map", "", BMAP_EPARSE, "empty file", "empty.map:1");
}

TEST(read_refuses_missing_file_and_write_unwritable_path)
{
    mesh *s, *t;
    tiny(&s, &t);
    char err[512];
    bmap *P = NULL;
    CHECK_INT(bmap_read("/nonexistent/x.map", s, t, &P, err, sizeof err), BMAP_EIO);
    CHECK_STR_HAS(err, "/nonexistent/x.map");
    P = bmap_new(2, 4);
    CHECK_INT(bmap_write("/nonexistent/y.map", P, NULL, err, sizeof err), BMAP_EIO);
    CHECK_STR_HAS(err, "/nonexistent/y.map");
    CHECK(bmap_new(-1, 4) == NULL);
    bmap_free(P);
    bmap_free(NULL);
    mesh_free(s);
    mesh_free(t);
}

TEST(apply_identity_like_maps_returns_vertex_values)
{
    /* Each source vertex i maps to a vertex corner of a face with weight 1
     * (identity-like): P·Z returns that vertex's row of Z; a face centre
     * returns the mean of its three rows. */
    mesh *m = testmesh_icosphere(2);
    bmap *P = testmesh_identity(m);
    const int d = 5;
    double *Z = malloc(sizeof(double) * d * m->nv), *out = malloc(sizeof(double) * d * m->nv);
    for (int j = 0; j < m->nv; j++)
        for (int k = 0; k < d; k++)
            Z[d * j + k] = k < 3 ? m->v[3 * j + k] : j * 0.5 + k;
    bmap_apply(P, m->f, Z, d, out);
    for (int i = 0; i < d * m->nv; i++)
        CHECK(out[i] == Z[i]);
    for (int i = 0; i < m->nv; i++) {
        P->face[i] = i % m->nf;
        P->w[3 * i] = P->w[3 * i + 1] = P->w[3 * i + 2] = 1.0 / 3;
    }
    bmap_apply(P, m->f, Z, d, out);
    for (int i = 0; i < m->nv; i++) {
        const int *v = m->f + 3 * (i % m->nf);
        for (int k = 0; k < d; k++)
            CHECK_NEAR(out[d * i + k], (Z[d * v[0] + k] + Z[d * v[1] + k] + Z[d * v[2] + k]) / 3,
                       1e-14);
    }
    free(Z);
    free(out);
    bmap_free(P);
    mesh_free(m);
}
