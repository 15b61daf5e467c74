/* test_lmk.c — landmark files: layouts, index bases, refusals. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testmesh.h"
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
    CHECK_STR_HAS(err, "at least 3");
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
    CHECK_INT(lmk_from_arrays(a, b, 2, 0, "wire", "wire", m, m, &L, err, sizeof err), LMK_ECOUNT);
    mesh_free(m);
}
