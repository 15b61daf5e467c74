/* test_lmk.c — landmark and vertex-id files: the one reader's layouts
 * (pairs, lists, BIM .vts and .pid), its one index-base rule (BIM .vts
 * positions checked against the mesh), and refusals naming file and line. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testmesh.h"
#include "lmk/lmk.h"

#include <stdlib.h>
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

TEST(refuses_index_out_of_range_naming_file_line_landmark_and_range)
{
    mesh *m = sphere();
    const char *p = testfile_text("r.txt", "0 1\n2 3\n4 162\n6 7\n");
    lmk_set *l = NULL;
    char err[256];
    CHECK_INT(lmk_read_pairs(p, 0, m, m, &l, err, sizeof err), LMK_ERANGE);
    CHECK_STR_HAS(err, "r.txt:3: landmark 3: target vertex 162 out of range [0, 161]");
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
    CHECK_STR_HAS(err, "junk.txt:2: not a vertex id in column 2 ('x')");
    p = testfile_text("frac.txt", "0 1.5\n");
    CHECK_INT(lmk_read_pairs(p, 0, m, m, &l, err, sizeof err), LMK_EPARSE);
    char b[512];
    snprintf(b, sizeof b, "%s", testfile_text("b.txt", "1\n2\n3\n"));
    p = testfile_text("a.txt", "1\n2\n3\n4\n");
    CHECK_INT(lmk_read_lists(p, b, 0, m, m, &l, err, sizeof err), LMK_ECOUNT);
    CHECK_STR_HAS(err, "has 4 landmarks but");
    CHECK_INT(lmk_read_pairs("/nonexistent/x", 0, m, m, &l, err, sizeof err), LMK_EIO);
    /* a file with no line to read is refused as such, not taken for a layout */
    p = testfile_text("empty.txt", "");
    CHECK_INT(lmk_read_pairs(p, 0, m, m, &l, err, sizeof err), LMK_ECOUNT);
    CHECK_STR_HAS(err, "empty.txt: no vertex ids");
    p = testfile_text("comments.txt", "# source target\n\n");
    CHECK_INT(lmk_read_lists(p, p, 0, m, m, &l, err, sizeof err), LMK_ECOUNT);
    CHECK_STR_HAS(err, "comments.txt: no vertex ids");
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

/* A BIM .pid or .vts file is no pairs file: refused naming the file, the
 * line, the column count and what the file looks like, not read as
 * (first column, second column) pairs. A pairs file is no list either. */
TEST(pairs_reader_refuses_bim_pid_and_vts_files_naming_what_they_look_like)
{
    mesh *m = sphere();
    lmk_set *l = NULL;
    char err[512];
    const char *p = testfile_text("a.pid", "# from BIM\n  26 0 0 0\n  17 0 0 0\n  100 0 0 0\n");
    CHECK_INT(lmk_read_pairs(p, LMK_BASE_DEFAULT, m, m, &l, err, sizeof err), LMK_ELAYOUT);
    CHECK_STR_HAS(err, "a.pid:2: 4 columns: this looks like a BIM .pid file (point ids with barycentric "
                  "coordinates); landmark pairs are `source_vertex target_vertex` a line");
    CHECK(l == NULL);
    p = testfile_text("a.vts", "26 0.5 0.25 1\n17 0 0 0\n100 1 2 3\n");
    CHECK_INT(lmk_read_pairs(p, LMK_BASE_DEFAULT, m, m, &l, err, sizeof err), LMK_ELAYOUT);
    CHECK_STR_HAS(err, "a.vts:1: 4 columns: this looks like a BIM .vts file (vertex ids with their positions)");
    p = testfile_text("ids.txt", "1\n2\n3\n");
    CHECK_INT(lmk_read_pairs(p, LMK_BASE_DEFAULT, m, m, &l, err, sizeof err), LMK_ELAYOUT);
    CHECK_STR_HAS(err, "ids.txt:1: 1 column: this looks like a list of vertex ids");
    char pairs[512];
    snprintf(pairs, sizeof pairs, "%s", testfile_text("pairs.txt", "0 1\n2 3\n4 5\n"));
    p = testfile_text("b.txt", "1\n2\n3\n");
    CHECK_INT(lmk_read_lists(pairs, p, LMK_BASE_DEFAULT, m, m, &l, err, sizeof err), LMK_ELAYOUT);
    CHECK_STR_HAS(err, "pairs.txt:1: 2 columns: this looks like a file of `source_vertex target_vertex` pairs");
    int *ids = NULL, n = 0;
    CHECK_INT(lmk_read_ids_on(pairs, LMK_BASE_DEFAULT, m, 100, &ids, &n, err, sizeof err), LMK_ELAYOUT);
    CHECK(ids == NULL);
    /* other column counts, and a count that changes */
    p = testfile_text("three.txt", "1 2 3\n");
    CHECK_INT(lmk_read_pairs(p, LMK_BASE_DEFAULT, m, m, &l, err, sizeof err), LMK_ELAYOUT);
    CHECK_STR_HAS(err, "three.txt:1: 3 columns: not a layout meshcorr reads");
    p = testfile_text("mixed.txt", "0 1\n2 3\n4 5 6 7\n");
    CHECK_INT(lmk_read_pairs(p, LMK_BASE_DEFAULT, m, m, &l, err, sizeof err), LMK_EPARSE);
    CHECK_STR_HAS(err, "mixed.txt:3: 4 columns, but line 1 has 2");
    mesh_free(m);
}

/* The real BIM files: SHREC'07 glasses 52 and 58. The positions on every
 * line of their .vts files are the 0-based vertex's, so the default base
 * is 0, a base of 1 is refused as contradicted, the landmark lists and
 * the id reader (eval's ground truth) give the same ids, and those are the
 * file's first column as written. */
TEST(bim_vts_files_are_read_0_based_by_their_positions_by_every_reader)
{
    char a[512], b[512], err[512];
    snprintf(a, sizeof a, "%s", harness_data_path("shrec07_bim/Corrs/52.vts"));
    snprintf(b, sizeof b, "%s", harness_data_path("shrec07_bim/Corrs/58.vts"));
    mesh *S = NULL, *T = NULL;
    CHECK_INT(mesh_read(harness_data_path("shrec07_bim/Meshes/52.off"), &S, err, sizeof err), 0);
    CHECK_INT(mesh_read(harness_data_path("shrec07_bim/Meshes/58.off"), &T, err, sizeof err), 0);
    lmk_set *l = NULL;
    CHECK_INT(lmk_read_lists(a, b, LMK_BASE_DEFAULT, S, T, &l, err, sizeof err), 0);
    int *ia = NULL, *ib = NULL, na = 0, nb = 0;
    CHECK_INT(lmk_read_ids_on(a, LMK_BASE_DEFAULT, S, 100, &ia, &na, err, sizeof err), 0);
    CHECK_INT(lmk_read_ids_on(b, LMK_BASE_DEFAULT, T, 100, &ib, &nb, err, sizeof err), 0);
    CHECK_INT(na, l->n);
    CHECK_INT(nb, l->n);
    FILE *fp = fopen(a, "r");
    CHECK(fp);
    for (int k = 0; k < l->n; k++) {
        int id;
        double x[3];
        CHECK(fscanf(fp, "%d %lf %lf %lf", &id, &x[0], &x[1], &x[2]) == 4);
        CHECK_INT(l->src[k], id);
        CHECK_INT(ia[k], id);
        CHECK_INT(ib[k], l->tgt[k]);
        for (int d = 0; d < 3; d++)   /* the vertex the line names is where the line says */
            CHECK_NEAR(S->v[3 * id + d], x[d], 1e-6);
    }
    fclose(fp);
    lmk_free(l);
    free(ia);
    free(ib);
    CHECK_INT(lmk_read_lists(a, b, 1, S, T, &l, err, sizeof err), LMK_EBASE);
    CHECK_STR_HAS(err, "52.vts: read 1-based, but the position on each line is that of its vertex read "
                  "0-based");
    CHECK_INT(lmk_read_ids_on(b, 1, T, 100, &ib, &nb, err, sizeof err), LMK_EBASE);
    CHECK_STR_HAS(err, "the file is 0-based");
    mesh_free(S);
    mesh_free(T);
}

/* A .vts file written 1-based (its positions those of id - 1) is read
 * 1-based under the default rule; a base of 0 given for it is refused; one
 * whose positions fit no base (another mesh's) keeps the base as given. */
TEST(vts_positions_decide_the_base_and_unfitting_positions_keep_the_given_one)
{
    mesh *m = sphere();
    char text[1024] = "", err[512];
    int o = 0, ids_at[4] = {0, 7, 33, 161};
    for (int k = 0; k < 4; k++) {
        const double *x = m->v + 3 * ids_at[k];
        o += snprintf(text + o, sizeof text - (size_t)o, "%d %.9f %.9f %.9f\n", ids_at[k] + 1, x[0], x[1], x[2]);
    }
    const char *p = testfile_text("one.vts", text);
    int *ids = NULL, n = 0;
    CHECK_INT(lmk_read_ids_on(p, LMK_BASE_DEFAULT, m, 100, &ids, &n, err, sizeof err), 0);
    CHECK_INT(n, 4);
    for (int k = 0; k < 4; k++)
        CHECK_INT(ids[k], ids_at[k]);
    free(ids);
    CHECK_INT(lmk_read_ids_on(p, 0, m, 100, &ids, &n, err, sizeof err), LMK_EBASE);
    CHECK_STR_HAS(err, "one.vts: read 0-based, but the position on each line is that of its vertex read "
                  "1-based (line 1: vertex 0): the file is 1-based");
    /* the id-count-only reader cannot check: the default base is 0 */
    CHECK_INT(lmk_read_ids(p, LMK_BASE_DEFAULT, m->nv, 100, &ids, &n, err, sizeof err), LMK_ERANGE);
    p = testfile_text("other.vts", "3 9 9 9\n5 9 9 9\n");
    CHECK_INT(lmk_read_ids_on(p, 1, m, 100, &ids, &n, err, sizeof err), 0);
    CHECK_INT(ids[0], 2);
    free(ids);
    CHECK_INT(lmk_read_ids_on(p, LMK_BASE_DEFAULT, m, 100, &ids, &n, err, sizeof err), 0);
    CHECK_INT(ids[0], 3);
    free(ids);
    mesh_free(m);
}

/* Under the default base an id equal to the vertex count says the file
 * looks 1-based (BCICP's lists are); given base 1, the file reads. */
TEST(default_base_refuses_an_id_at_the_vertex_count_saying_the_file_looks_1_based)
{
    mesh *m = sphere();
    const char *p = testfile_text("bcicp.vts", "5\n162\n1\n");
    int *ids = NULL, n = 0;
    char err[512];
    CHECK_INT(lmk_read_ids_on(p, LMK_BASE_DEFAULT, m, 100, &ids, &n, err, sizeof err), LMK_ERANGE);
    CHECK_STR_HAS(err, "bcicp.vts:2: vertex 162 out of range [0, 161]: 0-based ids end below the vertex "
                  "count, so the file looks 1-based");
    CHECK_INT(lmk_read_ids_on(p, 1, m, 100, &ids, &n, err, sizeof err), 0);
    CHECK_INT(ids[1], 161);
    free(ids);
    /* told 0-based, the refusal is plain */
    CHECK_INT(lmk_read_ids_on(p, 0, m, 100, &ids, &n, err, sizeof err), LMK_ERANGE);
    CHECK(strstr(err, "looks 1-based") == NULL);
    mesh_free(m);
}
