/* test_vmap.c — vertex-to-vertex maps as initial maps (map/vmap.h): the
 * published BIM (0-based) and BCICP (1-based) maps of TOSCA gorilla_01 ->
 * man_01 read as barycentric maps that put every source vertex exactly on
 * its target vertex; the base rule (a 0 -> 0-based, nv -> 1-based, neither
 * -> refused as ambiguous, an explicit base wins); vmap_read_any telling
 * the two formats apart; every refusal naming file and line. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testmesh.h"
#include "map/bmap.h"
#include "map/vmap.h"

#include <stdlib.h>
#include <string.h>

/* The point P puts source vertex i on, against target vertex v. */
static void check_at_vertex(const bmap *P, int i, const mesh *T, int v)
{
    const int *f = T->f + 3 * P->face[i];
    double x[3] = {0, 0, 0};
    for (int c = 0; c < 3; c++)
        for (int d = 0; d < 3; d++)
            x[d] += P->w[3 * i + c] * T->v[3 * f[c] + d];
    for (int d = 0; d < 3; d++)
        if (x[d] != T->v[3 * v + d])
            FAILF("row %d: not exactly at target vertex %d", i, v);
}

/* Reads the ids of a vertex-map file for the comparison (no vmap code). */
static int *raw_ids(const char *path, int n)
{
    FILE *fp = fopen(path, "r");
    CHECK(fp);
    int *ids = malloc(sizeof(int) * (size_t)n);
    for (int i = 0; i < n; i++)
        CHECK(fscanf(fp, "%d", &ids[i]) == 1);
    fclose(fp);
    return ids;
}

TEST(published_bim_and_bcicp_maps_put_each_vertex_on_its_target_vertex)
{
    mesh *S = testmesh_read("tosca_r_nonisometric/vtx_5k/8_gorilla_01.off");
    mesh *T = testmesh_read("tosca_r_nonisometric/vtx_5k/8_man_01.off");
    static const char *const rel[2] = {
        "tosca_r_nonisometric/vtx_5k/maps_baseline/BIM/8_gorilla_01_8_man_01.map",
        "tosca_r_nonisometric/vtx_5k/maps_baseline/WKSini_direct_BCICP/8_gorilla_01_8_man_01.map"};
    char err[512] = "";
    for (int base = 0; base < 2; base++) {
        const char *path = harness_data_path(rel[base]);
        bmap *P = NULL;
        int used = -1;
        if (vmap_read(path, base, S, T, &P, &used, err, sizeof err))
            FAILF("%s", err);
        CHECK_INT(used, base);
        CHECK_INT(P->n, S->nv);
        CHECK_INT(P->nt, T->nv);
        int *ids = raw_ids(path, S->nv);
        for (int i = 0; i < S->nv; i++) {
            CHECK(P->face[i] >= 0 && P->face[i] < T->nf);
            check_at_vertex(P, i, T, ids[i] - base);
        }
        free(ids);
        bmap_free(P);
    }
    /* the BCICP map holds vertex 5000 = nv: auto says 1-based */
    bmap *P = NULL;
    int used = -1;
    CHECK_INT(vmap_read(harness_data_path(rel[1]), VMAP_BASE_AUTO, S, T, &P, &used, err, sizeof err), 0);
    CHECK_INT(used, 1);
    bmap_free(P);
    /* this BIM map holds neither 0 nor 5000 (it is 0-based, from 49 to 4999):
     * auto refuses, naming the file and the option */
    CHECK_INT(vmap_read(harness_data_path(rel[0]), VMAP_BASE_AUTO, S, T, &P, NULL, err, sizeof err),
              BMAP_EPARSE);
    CHECK_STR_HAS(err, "8_gorilla_01_8_man_01.map: neither 0 nor 5000");
    CHECK_STR_HAS(err, "--init-base");
    CHECK(P == NULL);
    /* vmap_read_any reads the same file as a vertex map with the base given */
    CHECK_INT(vmap_read_any(harness_data_path(rel[0]), 0, S, T, &P, err, sizeof err), 0);
    CHECK_INT(P->n, S->nv);
    bmap_free(P);
    mesh_free(S);
    mesh_free(T);
}

/* The base rule on small files over an icosphere (12 vertices, level 0). */
TEST(base_rule_zero_means_0_based_nv_means_1_based)
{
    mesh *m = testmesh_icosphere(0);
    CHECK_INT(m->nv, 12);
    char err[512] = "";
    bmap *P = NULL;
    int used = -1;
    /* a 0 present: 0-based, row 0 on vertex 0 */
    const char *z = testfile_text("zero.txt", "0\n1\n2\n3\n4\n5\n6\n7\n8\n9\n10\n11\n");
    CHECK_INT(vmap_read(z, VMAP_BASE_AUTO, m, m, &P, &used, err, sizeof err), 0);
    CHECK_INT(used, 0);
    for (int i = 0; i < 12; i++)
        check_at_vertex(P, i, m, i);
    bmap_free(P);
    /* 12 present, no 0: 1-based; '#' lines, blank lines and integral
     * floats are fine */
    const char *o = testfile_text("one.txt", "# from MATLAB\n12\n1\n2.0\n3\n\n4\n5\n6\n7\n8\n9\n"
                                           "1.0e+01\n11\n");
    CHECK_INT(vmap_read(o, VMAP_BASE_AUTO, m, m, &P, &used, err, sizeof err), 0);
    CHECK_INT(used, 1);
    check_at_vertex(P, 0, m, 11);
    check_at_vertex(P, 1, m, 0);
    check_at_vertex(P, 10, m, 9);
    bmap_free(P);
    /* an explicit base wins over the rule: the same file 0-based is out of
     * range at its first line (12 >= 12) */
    CHECK_INT(vmap_read(o, 0, m, m, &P, NULL, err, sizeof err), BMAP_ERANGE);
    CHECK_STR_HAS(err, "one.txt:2: target vertex 12 out of range [0, 11]");
    mesh_free(m);
}

TEST(bad_vertex_maps_are_refused_naming_file_and_line)
{
    mesh *m = testmesh_icosphere(0);
    char err[512] = "";
    bmap *P = NULL;
    static const struct {
        const char *name, *text;
        int base, rc;
        const char *msg;
    } cases[] = {
        {"short.txt", "0\n1\n2\n", VMAP_BASE_AUTO, BMAP_ESIZE,
         "short.txt:3: 3 entries, expected 12 (one target vertex per source vertex)"},
        {"long.txt", "0\n1\n2\n3\n4\n5\n6\n7\n8\n9\n10\n11\n3\n", VMAP_BASE_AUTO, BMAP_ESIZE,
         "long.txt:13: more than 12 entries"},
        {"frac.txt", "0\n1\n2\n3.5\n4\n5\n6\n7\n8\n9\n10\n11\n", VMAP_BASE_AUTO, BMAP_EPARSE,
         "frac.txt:4: '3.5' is not a target vertex index"},
        {"word.txt", "0\n1\n2\n3\nfive\n5\n6\n7\n8\n9\n10\n11\n", VMAP_BASE_AUTO, BMAP_EPARSE,
         "word.txt:5: 'five' is not a target vertex index"},
        {"two.txt", "0 1\n1\n2\n3\n4\n5\n6\n7\n8\n9\n10\n11\n", VMAP_BASE_AUTO, BMAP_EPARSE,
         "two.txt:1: '0 1' is not a target vertex index"},
        {"high.txt", "0\n1\n2\n3\n4\n5\n6\n7\n8\n9\n10\n12\n", VMAP_BASE_AUTO, BMAP_ERANGE,
         "high.txt:12: target vertex 12 out of range [0, 11] (0-based"},
        {"neg.txt", "0\n1\n2\n-3\n4\n5\n6\n7\n8\n9\n10\n11\n", VMAP_BASE_AUTO, BMAP_ERANGE,
         "neg.txt:4: target vertex -3 out of range"},
        {"zero1.txt", "0\n1\n2\n3\n4\n5\n6\n7\n8\n9\n10\n11\n", 1, BMAP_ERANGE,
         "zero1.txt:1: target vertex 0 out of range [1, 12] (1-based"},
        {"ambig.txt", "1\n1\n2\n3\n4\n5\n6\n7\n8\n9\n10\n11\n", VMAP_BASE_AUTO, BMAP_EPARSE,
         "ambig.txt: neither 0 nor 12 among the indices"},
        {"empty.txt", "", VMAP_BASE_AUTO, BMAP_ESIZE, "empty.txt:0: 0 entries, expected 12"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const char *p = testfile_text(cases[k].name, cases[k].text);
        int rc = vmap_read(p, cases[k].base, m, m, &P, NULL, err, sizeof err);
        if (rc != cases[k].rc)
            FAILF("%s: rc %d, expected %d (%s)", cases[k].name, rc, cases[k].rc, err);
        CHECK_STR_HAS(err, cases[k].msg);
        CHECK(P == NULL);
    }
    CHECK_INT(vmap_read("/nonexistent/v.map", VMAP_BASE_AUTO, m, m, &P, NULL, err, sizeof err),
              BMAP_EIO);
    CHECK_STR_HAS(err, "/nonexistent/v.map: cannot open");
    mesh_free(m);
}

/* vmap_read_any: the meshcorr-map 1 header means bmap_read (its own
 * refusals), anything else a vertex map. */
TEST(read_any_tells_barycentric_from_vertex_maps)
{
    mesh *m = testmesh_icosphere(0);
    char err[512] = "", text[1024];
    bmap *P = NULL;
    int o = snprintf(text, sizeof text, "# meshcorr-map 1\n12 12\n");
    for (int i = 0; i < 12; i++)
        o += snprintf(text + o, sizeof text - (size_t)o, "0 1 0 0\n");
    CHECK_INT(vmap_read_any(testfile_text("b.map", text), VMAP_BASE_AUTO, m, m, &P, err, sizeof err), 0);
    CHECK_INT(P->face[5], 0);
    bmap_free(P);
    CHECK_INT(vmap_read_any(testfile_text("bad.map", "# meshcorr-map 1\n12 11\n"), VMAP_BASE_AUTO, m, m,
                            &P, err, sizeof err), BMAP_ESIZE);
    CHECK_STR_HAS(err, "bad.map:2: map is for 12 -> 11 vertices");
    CHECK_INT(vmap_read_any(testfile_text("v.map", "0\n1\n2\n3\n4\n5\n6\n7\n8\n9\n10\n11\n"),
                            VMAP_BASE_AUTO, m, m, &P, err, sizeof err), 0);
    check_at_vertex(P, 7, m, 7);
    bmap_free(P);
    mesh_free(m);
}
