/* test_testgt.c — ground-truth files: the id-list reader (lmk_read_ids, used
 * by meshcorr eval and the test support) on small files (integers, floats,
 * first column, comments, both bases, each refusal) and the two loaders of
 * support/testgt.h on the real pairs. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testgt.h"

#include <string.h>

static const struct {
    const char *text;
    int base, nv;
    int n;              /* -1: refused */
    int ids[4];
    const char *msg;    /* part of the refusal */
} cases[] = {
    { "3\n1\n2\n", 0, 5, 3, {3, 1, 2}, NULL },
    { "1\n5\n", 1, 5, 2, {0, 4}, NULL },
    { "7.529000000000000000e+03\n0.000000000000000000e+00\n", 0, 8000, 2, {7529, 0}, NULL },
    { "12 0.1 0.2 0.3\n4 1 2 3\n", 0, 13, 2, {12, 4}, NULL },      /* BIM "id x y z" */
    { "# a comment\n\n  4\r\n\t2\n", 0, 5, 2, {4, 2}, NULL },
    { "2\n0\n", 1, 5, -1, {0}, ":2: vertex 0 out of range [1, 5]" },
    { "5\n", 0, 5, -1, {0}, ":1: vertex 5 out of range [0, 4]" },
    { "1\n2.5\n", 0, 5, -1, {0}, ":2: not a vertex id" },
    { "x\n", 0, 5, -1, {0}, ":1: not a vertex id" },
    { "-1\n", 0, 5, -1, {0}, "out of range" },
};

TEST(read_ids_takes_integers_floats_and_first_columns_and_names_the_bad_line)
{
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const char *path = testfile_text("gt.txt", cases[c].text);
        int *ids = NULL, n = -7;
        char err[512] = "";
        int rc = lmk_read_ids(path, cases[c].base, cases[c].nv, 100, &ids, &n, err, sizeof err);
        if (cases[c].n < 0) {
            CHECK(rc < 0);
            CHECK(ids == NULL);
            CHECK_STR_HAS(err, cases[c].msg);
            CHECK_STR_HAS(err, "gt.txt");
            continue;
        }
        if (rc)
            FAILF("case %zu: %s", c, err);
        CHECK_INT(n, cases[c].n);
        for (int k = 0; k < n; k++)
            CHECK_INT(ids[k], cases[c].ids[k]);
        free(ids);
    }
    int *ids = NULL, n;
    char err[512];
    CHECK_INT(lmk_read_ids("/nonexistent/gt.vts", 0, 5, 100, &ids, &n, err, sizeof err), LMK_EIO);
    CHECK_STR_HAS(err, "cannot open");
    const char *three = testfile_text("gt3.txt", "0\n1\n2\n");
    CHECK_INT(lmk_read_ids(three, 0, 5, 2, &ids, &n, err, sizeof err), LMK_ECOUNT);
    CHECK_STR_HAS(err, "more than 2 lines");
    CHECK_INT(lmk_read_ids(three, 0, 5, 3, &ids, &n, err, sizeof err), LMK_OK);
    CHECK_INT(n, 3);
    free(ids);
}

static void check_landmarks(const testgt *g, int nl)
{
    CHECK_INT(g->L.n, nl);
    for (int r = 0; r < nl; r++) {
        int line = -1;
        for (int k = 0; k < g->n && line < 0; k++)
            if (g->src[k] == g->L.src[r] && g->tgt[k] == g->L.tgt[r])
                line = k;
        CHECK(line >= 0);   /* each landmark is a GT pair */
        for (int q = 0; q < r; q++)
            CHECK(g->L.src[q] != g->L.src[r]);
    }
}

TEST(vts_pair_loads_direct_and_symmetric_ground_truth)
{
    testgt g;
    testgt_faust(&g, 12);
    CHECK_INT(g.n, 5000);
    CHECK(g.tgt_sym != NULL);
    int differ = 0;
    for (int k = 0; k < g.n; k++)
        differ += g.tgt_sym[k] != g.tgt[k];
    CHECK(differ > g.n / 2);   /* the mirror image, not a copy */
    CHECK_INT(g.L.src[0], g.src[0]);
    check_landmarks(&g, 12);
    testgt_close(&g);

    testgt_vts(&g, "tosca_r_isometric/vtx_5k", "cat0", "cat1", 12);
    CHECK_INT(g.n, 5000);
    CHECK(g.tgt_sym != NULL);
    check_landmarks(&g, 12);
    testgt_close(&g);
}

/* homerA -> homerB are nearly aligned: with the ids read 0-based, every
 * vertex lands within 0.075 of the bounding-box diagonal of its GT image
 * (measured); read one off, the farthest lands 0.5 away. */
TEST(vertex_list_loads_one_target_per_source_vertex)
{
    testgt g;
    testgt_vertex_list(&g, "cartoon_elasticbasis/homerA.obj", "cartoon_elasticbasis/homerB.obj",
                       "cartoon_elasticbasis/gt_homerA_homerB.txt", 12);
    CHECK_INT(g.n, g.S->nv);
    CHECK(g.tgt_sym == NULL);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int v = 0; v < g.T->nv; v++)
        for (int c = 0; c < 3; c++) {
            lo[c] = fmin(lo[c], g.T->v[3 * v + c]);
            hi[c] = fmax(hi[c], g.T->v[3 * v + c]);
        }
    double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
    double worst = 0;
    for (int k = 0; k < g.n; k++) {
        CHECK_INT(g.src[k], k);
        const double *x = g.S->v + 3 * g.src[k], *y = g.T->v + 3 * g.tgt[k];
        double d = sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                        (x[2] - y[2]) * (x[2] - y[2]));
        worst = fmax(worst, d / diag);
    }
    printf("  homerA -> homerB: farthest GT image %.4f of the diagonal\n", worst);
    CHECK(worst < 0.15);
    check_landmarks(&g, 12);
    testgt_close(&g);
}
