/* test_lmk.c — landmark files and the affine landmark initialisation. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testmesh.h"
#include "init/init_affine.h"
#include "lmk/lmk.h"

#include <string.h>

static mesh *sphere(void) { return testmesh_icosphere(2); }  /* 162 vertices */

TEST(pairs_file_reads_with_comments_and_blank_lines)
{
    mesh *m = sphere();
    const char *p = testfile_text("ok.txt", "# a\n\n0 1\n2 3   # inline\n4 5\n6 7\n");
    lmk_set *l = NULL;
    char err[256];
    CHECK_INT(lmk_read_pairs(p, 0, m, m, &l, err, sizeof err), 0);
    CHECK_INT(l->n, 4);
    CHECK_INT(l->src[1], 2);
    CHECK_INT(l->tgt[3], 7);
    lmk_free(l);
    mesh_free(m);
}

TEST(one_based_lists_with_vts_layout)
{
    mesh *m = sphere();
    const char *a = testfile_text("a.vts", "1 0.1 0.2 0.3\n5 0 0 0\n9 0 0 0\n13 1 1 1\n");
    char apath[512];
    snprintf(apath, sizeof apath, "%s", a);
    const char *b = testfile_text("b.vts", "2\n6\n10\n14\n");
    lmk_set *l = NULL;
    char err[256];
    CHECK_INT(lmk_read_lists(apath, b, 1, m, m, &l, err, sizeof err), 0);
    CHECK_INT(l->n, 4);
    CHECK_INT(l->src[0], 0);
    CHECK_INT(l->tgt[3], 13);
    lmk_free(l);
    mesh_free(m);
}

TEST(refuses_index_out_of_range_naming_file_landmark_and_range)
{
    mesh *m = sphere();
    const char *p = testfile_text("r.txt", "0 1\n2 3\n4 162\n6 7\n");
    lmk_set *l = NULL;
    char err[256];
    CHECK_INT(lmk_read_pairs(p, 0, m, m, &l, err, sizeof err), LMK_ERANGE);
    CHECK_STR_HAS(err, "r.txt: landmark 3: target vertex 162 out of range [0, 161]");
    CHECK(l == NULL);
    mesh_free(m);
}

TEST(refuses_duplicate_source_landmark)
{
    mesh *m = sphere();
    const char *p = testfile_text("d.txt", "0 1\n2 3\n0 5\n6 7\n");
    lmk_set *l = NULL;
    char err[256];
    CHECK_INT(lmk_read_pairs(p, 0, m, m, &l, err, sizeof err), LMK_EDUP);
    CHECK_STR_HAS(err, "landmarks 1 and 3 both use source vertex 0");
    mesh_free(m);
}

TEST(refuses_too_few_and_unparsable_rows)
{
    mesh *m = sphere();
    lmk_set *l = NULL;
    char err[256];
    const char *p = testfile_text("few.txt", "0 1\n2 3\n");
    CHECK_INT(lmk_read_pairs(p, 0, m, m, &l, err, sizeof err), LMK_ECOUNT);
    CHECK_STR_HAS(err, "at least 4");
    p = testfile_text("junk.txt", "0 1\n2 x\n");
    CHECK_INT(lmk_read_pairs(p, 0, m, m, &l, err, sizeof err), LMK_EPARSE);
    CHECK_STR_HAS(err, "junk.txt:2: column 2");
    p = testfile_text("frac.txt", "0 1.5\n");
    CHECK_INT(lmk_read_pairs(p, 0, m, m, &l, err, sizeof err), LMK_EPARSE);
    char b[512];
    snprintf(b, sizeof b, "%s", testfile_text("b.txt", "1\n2\n3\n"));
    p = testfile_text("a.txt", "1\n2\n3\n4\n");
    CHECK_INT(lmk_read_lists(p, b, 0, m, m, &l, err, sizeof err), LMK_ECOUNT);
    CHECK_STR_HAS(err, "has 4 landmarks but");
    CHECK_INT(lmk_read_pairs("/nonexistent/x", 0, m, m, &l, err, sizeof err), LMK_EIO);
    mesh_free(m);
}

TEST(affine_fit_recovers_a_known_affine_map)
{
    mesh *S = sphere();
    mesh *T = mesh_copy(S);
    const double A[9] = {1.5, 0.2, 0, -0.1, 0.8, 0.3, 0.05, 0, 2.0}, t[3] = {1, -2, 0.5};
    for (int i = 0; i < T->nv; i++) {
        const double *x = S->v + 3 * i;
        for (int d = 0; d < 3; d++)
            T->v[3 * i + d] = A[3 * d] * x[0] + A[3 * d + 1] * x[1] + A[3 * d + 2] * x[2] + t[d];
    }
    lmk_set l = {6, (int[]){0, 11, 40, 77, 100, 150}, (int[]){0, 11, 40, 77, 100, 150}};
    double B[9], u[3];
    CHECK_INT(init_affine_fit(S, T, &l, B, u, NULL, 0), 0);
    for (int k = 0; k < 9; k++)
        CHECK_NEAR(B[k], A[k], 1e-10);
    for (int k = 0; k < 3; k++)
        CHECK_NEAR(u[k], t[k], 1e-10);
    /* The map then sends every vertex to itself (its own image is on T). */
    bmap *P = NULL;
    CHECK_INT(init_affine_map(S, T, &l, &P, NULL, 0), 0);
    double *img = malloc(sizeof(double) * 3 * S->nv);
    bmap_apply(P, T->f, T->v, 3, img);
    for (int i = 0; i < 3 * S->nv; i++)
        CHECK_NEAR(img[i], T->v[i], 1e-9);
    free(img);
    bmap_free(P);
    mesh_free(S);
    mesh_free(T);
}

TEST(affine_fit_refuses_coplanar_landmarks)
{
    mesh *m = testmesh_disk(4);
    lmk_set l = {5, (int[]){0, 3, 9, 20, 40}, (int[]){0, 3, 9, 20, 40}};
    double A[9], t[3];
    char err[256];
    CHECK_INT(init_affine_fit(m, m, &l, A, t, err, sizeof err), INIT_EDEGENERATE);
    CHECK_STR_HAS(err, "coplanar");
    mesh_free(m);
}

TEST(arrays_follow_the_file_rule_with_one_based_messages)
{
    mesh *m = testmesh_icosphere(1);   /* 42 vertices */
    lmk_set *L = NULL;
    char err[256];
    const long a[5] = { 1, 2, 3, 4, 5 }, b[5] = { 5, 4, 3, 2, 1 };
    CHECK_INT(lmk_from_arrays(a, b, 5, 1, "wire", "wire", m, m, &L, err, sizeof err), 0);
    CHECK_INT(L->n, 5);
    CHECK_INT(L->src[0], 0);
    CHECK_INT(L->tgt[0], 4);
    lmk_free(L);
    const long big[5] = { 1, 2, 3, 43, 5 };
    CHECK_INT(lmk_from_arrays(big, b, 5, 1, "wire", "wire", m, m, &L, err, sizeof err), LMK_ERANGE);
    CHECK_STR_HAS(err, "wire: landmark 4: source vertex 43 out of range [1, 42]");
    CHECK(L == NULL);
    const long dup[5] = { 1, 2, 3, 2, 5 };
    CHECK_INT(lmk_from_arrays(dup, b, 5, 0, "wire", "wire", m, m, &L, err, sizeof err), LMK_EDUP);
    CHECK_STR_HAS(err, "landmarks 2 and 4 both use source vertex 2");
    CHECK_INT(lmk_from_arrays(a, b, 3, 0, "wire", "wire", m, m, &L, err, sizeof err), LMK_ECOUNT);
    mesh_free(m);
}
