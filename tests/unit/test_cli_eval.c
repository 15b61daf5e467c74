/* test_cli_eval.c — `meshcorr eval` as a user runs it: the figures of the
 * demo maps against the demo README, a ground truth in both layouts, and
 * refusals that name the file. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testmesh.h"
#include "mesh/mesh.h"

#include <string.h>
#include <sys/wait.h>

static int run(const char *cmd, char *out, size_t outsz)
{
    char full[4096];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    CHECK(p);
    size_t n = fread(out, 1, outsz - 1, p);
    out[n] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static double field(const char *json, const char *key)
{
    char k[64];
    snprintf(k, sizeof k, "\"%s\":", key);
    const char *p = strstr(json, k);
    if (!p)
        FAILF("no %s in %s", key, json);
    return atof(p + strlen(k));
}

static char s381[512], s390[512], demo[512];

static void paths(void)
{
    snprintf(s381, sizeof s381, "%s", harness_data_path("shrec07_bim/Meshes/381.off"));
    snprintf(s390, sizeof s390, "%s", harness_data_path("shrec07_bim/Meshes/390.off"));
    snprintf(demo, sizeof demo, "%s", harness_data_path("ectm_demo_381_390"));
}

/* README: authors' final map mean |log area| 0.50, median conformal 0.27,
 * 2 % flipped, 0.16 % collapsed, 99.4 % of the target within 0.05; initial
 * map 1.01 and 0.17, nothing flipped or collapsed. */
TEST(eval_of_demo_maps_matches_the_demo_readme)
{
    paths();
    char cmd[4096], out[8192];
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s/reference_final_381_to_390.map "
             "--reverse %s/reference_final_390_to_381.map --json", s381, s390, demo, demo);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    CHECK_NEAR(field(out, "area_mean_abs_log"), 0.50, 0.06);
    CHECK_NEAR(field(out, "conformal_median"), 0.27, 0.02);
    CHECK_NEAR(field(out, "flipped"), 0.02, 0.005);
    CHECK_NEAR(field(out, "collapsed"), 0.0016, 0.0005);
    CHECK_NEAR(field(out, "coverage"), 0.994, 0.005);
    CHECK(field(out, "round_trip") < 0.02);
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s/init_381_to_390.map", s381, s390, demo);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    CHECK_STR_HAS(out, "mean |log area ratio| 1.01");
    CHECK_STR_HAS(out, "median 0.168");
    CHECK_STR_HAS(out, "flipped triangles: 0.00 %");
    CHECK_STR_HAS(out, "collapsed triangles: 0.00 %");
    CHECK_STR_HAS(out, "mean-curvature error:");
}

/* The identity map of a mesh onto itself has zero geodesic error in both
 * ground-truth layouts, and a shifted ground truth does not. */
TEST(eval_geodesic_error_against_ground_truth_layouts)
{
    const char *wolf = harness_data_path("tosca_hires/Meshes/wolf0.off");
    char w[512], cmd[4096], out[16384], map[600];
    snprintf(w, sizeof w, "%s", wolf);
    snprintf(map, sizeof map, "%s/id.map", harness_tmpdir());
    /* the identity map: vertex v as a corner of its first face, read from
     * the OFF face list */
    FILE *fp = fopen(w, "r");
    CHECK(fp);
    char line[256];
    int nv, nf, e;
    CHECK(fgets(line, sizeof line, fp) && fscanf(fp, "%d %d %d", &nv, &nf, &e) == 3);
    for (int v = 0; v < nv; v++) {
        double x, y, z;
        CHECK(fscanf(fp, "%lf %lf %lf", &x, &y, &z) == 3);
    }
    int *face = malloc(sizeof(int) * nv), *corner = malloc(sizeof(int) * nv);
    for (int v = 0; v < nv; v++)
        face[v] = -1;
    for (int t = 0; t < nf; t++) {
        int k, a[3];
        CHECK(fscanf(fp, "%d %d %d %d", &k, &a[0], &a[1], &a[2]) == 4);
        for (int q = 0; q < 3; q++)
            if (face[a[q]] < 0) {
                face[a[q]] = t;
                corner[a[q]] = q;
            }
    }
    fclose(fp);
    FILE *mp = fopen(map, "w");
    fprintf(mp, "# meshcorr-map 1\n%d %d\n", nv, nv);
    for (int v = 0; v < nv; v++)
        fprintf(mp, "%d %d %d %d\n", face[v], corner[v] == 0, corner[v] == 1, corner[v] == 2);
    fclose(mp);
    /* vertex-list written as floats, 0-based */
    char *gt = malloc((size_t)nv * 16 + 1), *p = gt;
    for (int v = 0; v < nv; v++)
        p += sprintf(p, "%.3e\n", (double)v);
    char gtp[600];
    snprintf(gtp, sizeof gtp, "%s", testfile_text("gt.txt", gt));
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s --gt %s --gt-format vertex-list --json",
             w, w, map, gtp);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    CHECK(field(out, "mean") < 1e-9);
    CHECK_STR_HAS(out, "[0.25,1]");
    /* vts pairs, 1-based, a few lines; the second list shifted by one vertex */
    char a[600];
    snprintf(a, sizeof a, "%s", testfile_text("a.vts", "1\n101\n2001\n4001\n"));
    const char *b = testfile_text("b.vts", "2\n102\n2002\n4002\n");
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s --gt %s --gt-target %s "
             "--gt-format vts-pair --gt-base 1 --json", w, w, map, a, b);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    CHECK_STR_HAS(out, "\"points\":4,");
    CHECK(field(out, "mean") > 1e-4 && field(out, "mean") < 0.05);   /* one edge away */
    free(gt);
    free(face);
    free(corner);
}

TEST(eval_refuses_wrong_ground_truth_and_map_naming_the_file)
{
    paths();
    char cmd[4096], out[8192];
    const char *g = testfile_text("short_gt.txt", "1\n2\n3\n");
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s/init_381_to_390.map --gt %s "
             "--gt-format vertex-list", s381, s390, demo, g);
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "short_gt.txt has 3 lines");
    CHECK_STR_HAS(out, "6938 vertices");
    g = testfile_text("range_gt.txt", "1\n99999\n");
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s/init_381_to_390.map --gt %s "
             "--gt-format vertex-list", s381, s390, demo, g);
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "range_gt.txt:2: vertex 99999 out of range");
    char a[600];
    snprintf(a, sizeof a, "%s", testfile_text("a.vts", "1\n2\n3\n"));
    const char *b = testfile_text("b.vts", "1\n2\n");
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s/init_381_to_390.map --gt %s "
             "--gt-target %s --gt-format vts-pair", s381, s390, demo, a, b);
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "a.vts has 3 lines but");
    /* a map sized for other meshes: the reverse map given as the forward one */
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s/init_390_to_381.map", s381, s390, demo);
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "init_390_to_381.map");
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s", s381, s390);
    CHECK_INT(run(cmd, out, sizeof out), 2);
}

/* Published vertex maps (TOSCA gorilla_01 -> man_01) are maps eval reads:
 * the BCICP map (1-based, holds 5000) with the base told by the rule (its
 * 1-based ground-truth lists with --gt-base 1), the
 * BIM map (0-based, neither 0 nor 5000) refused until --map-base 0. The
 * README's sanity figure for BCICP is a Euclidean 0.025 of the bounding
 * box; the geodesic mean over the 900 points is 0.0474 (test_ddm's). */
TEST(eval_reads_published_vertex_maps)
{
    char s0[512], s1[512], g0[512], g1[512], bim[512], bcicp[512], cmd[4096], out[16384];
    snprintf(s0, sizeof s0, "%s", harness_data_path("tosca_r_nonisometric/vtx_5k/8_gorilla_01.off"));
    snprintf(s1, sizeof s1, "%s", harness_data_path("tosca_r_nonisometric/vtx_5k/8_man_01.off"));
    snprintf(g0, sizeof g0, "%s", harness_data_path("tosca_r_nonisometric/vtx_5k/corres/8_gorilla_01.vts"));
    snprintf(g1, sizeof g1, "%s", harness_data_path("tosca_r_nonisometric/vtx_5k/corres/8_man_01.vts"));
    snprintf(bim, sizeof bim, "%s", harness_data_path("tosca_r_nonisometric/vtx_5k/maps_baseline/"
                                                      "BIM/8_gorilla_01_8_man_01.map"));
    snprintf(bcicp, sizeof bcicp, "%s", harness_data_path("tosca_r_nonisometric/vtx_5k/maps_baseline/"
                                                          "WKSini_direct_BCICP/8_gorilla_01_8_man_01.map"));
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s --gt %s --gt-target %s --gt-format vts-pair "
             "--json", s0, s1, bcicp, g0, g1);
    CHECK_INT(run(cmd, out, sizeof out), 1);            /* BCICP's lists are 1-based: said, not guessed */
    CHECK_STR_HAS(out, "8_man_01.vts:");
    CHECK_STR_HAS(out, "vertex 5000 out of range [0, 4999]: 0-based ids end below the vertex count, so "
                  "the file looks 1-based: give --gt-base 1");
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s --gt %s --gt-target %s --gt-format vts-pair "
             "--gt-base 1 --json", s0, s1, bcicp, g0, g1);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    const char *geo = strstr(out, "\"geodesic\":");
    CHECK(geo);
    CHECK_NEAR(field(geo, "mean"), 0.0474, 5e-5);
    CHECK_NEAR(field(out, "conformal_median"), 1.392, 5e-4);
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s", s0, s1, bim);
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "neither 0 nor 5000");
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s --map-base 0", s0, s1, bim);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    CHECK_STR_HAS(out, "conformal distortion: median");
}

/* A mesh eval reads but cannot measure (an edge of three faces: no edge
 * table for the curvature fit) is named with the reason, not reported as
 * "out of memory". */
TEST(eval_names_a_non_manifold_mesh_instead_of_running_out_of_memory)
{
    mesh *T = testmesh_icosphere(1), *S = testmesh_icosphere(1), *N = NULL;
    CHECK(S && T);
    /* S with one more vertex and a third face on the edge of face 0's first two corners */
    CHECK((N = mesh_new(S->nv + 1, S->nf + 1)) != NULL);
    memcpy(N->v, S->v, sizeof(double) * 3 * (size_t)S->nv);
    memcpy(N->f, S->f, sizeof(int) * 3 * (size_t)S->nf);
    N->v[3 * S->nv] = N->v[3 * S->nv + 1] = N->v[3 * S->nv + 2] = 0.5;
    N->f[3 * S->nf] = S->f[0];
    N->f[3 * S->nf + 1] = S->f[1];
    N->f[3 * S->nf + 2] = S->nv;
    char spath[600], tpath[600], err[512], out[8192], cmd[2048], *map = malloc(64 * (size_t)(N->nv + 2));
    snprintf(spath, sizeof spath, "%s/nm.off", harness_tmpdir());
    snprintf(tpath, sizeof tpath, "%s/t.off", harness_tmpdir());
    CHECK_INT(mesh_write(spath, N, err, sizeof err), 0);
    CHECK_INT(mesh_write(tpath, T, err, sizeof err), 0);
    size_t n = (size_t)sprintf(map, "# meshcorr-map 1\n%d %d\n", N->nv, T->nv);
    for (int i = 0; i < N->nv; i++)         /* every vertex onto T's vertex at face 0's corner */
        n += (size_t)sprintf(map + n, "0 1 0 0\n");
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s", spath, tpath, testfile_text("nm.map", map));
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "curvature error of");
    CHECK_STR_HAS(out, "source mesh: edge");
    CHECK_STR_HAS(out, "has 3 faces");
    CHECK(strstr(out, "out of memory") == NULL);
    free(map);
    mesh_free(N);
    mesh_free(S);
    mesh_free(T);
}

/* eval reads BIM landmark files as match does (workers/lmk: 0-based, the
 * .vts positions checked): on SHREC'07 glasses 52 -> 58 a vertex map that
 * sends every source landmark onto its target landmark scores 0 against
 * the landmarks as ground truth; a map that misses them does not; and a
 * base the files' positions contradict is refused. */
TEST(eval_scores_a_map_exact_at_the_bim_landmarks_zero)
{
    char s52[512], s58[512], a[512], b[512], cmd[4096], out[16384], err[512];
    snprintf(s52, sizeof s52, "%s", harness_data_path("shrec07_bim/Meshes/52.off"));
    snprintf(s58, sizeof s58, "%s", harness_data_path("shrec07_bim/Meshes/58.off"));
    snprintf(a, sizeof a, "%s", harness_data_path("shrec07_bim/Corrs/52.vts"));
    snprintf(b, sizeof b, "%s", harness_data_path("shrec07_bim/Corrs/58.vts"));
    mesh *S = NULL;
    CHECK_INT(mesh_read(s52, &S, err, sizeof err), 0);
    /* the vertex map: landmark k's source vertex -> its target vertex (the
     * first column of each file, as BIM writes it), every other vertex -> 0 */
    int *to = calloc((size_t)S->nv, sizeof *to);
    FILE *fa = fopen(a, "r"), *fb = fopen(b, "r");
    CHECK(to && fa && fb);
    int i, j, n = 0;
    while (fscanf(fa, "%d %*f %*f %*f", &i) == 1 && fscanf(fb, "%d %*f %*f %*f", &j) == 1) {
        to[i] = j;
        n++;
    }
    fclose(fa);
    fclose(fb);
    CHECK_INT(n, 10);
    char *text = malloc((size_t)S->nv * 12 + 1), *p = text, *q;
    for (int v = 0; v < S->nv; v++)
        p += sprintf(p, "%d\n", to[v]);
    char exact[600], off[600];
    snprintf(exact, sizeof exact, "%s", testfile_text("exact.vmap", text));
    /* the same map one vertex off at every landmark */
    p = text;
    for (int v = 0; v < S->nv; v++)
        p += sprintf(p, "%d\n", to[v] ? to[v] + 1 : 0);
    snprintf(off, sizeof off, "%s", testfile_text("off.vmap", text));
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s %s --gt %s --gt-target %s --gt-format vts-pair "
             "--json", s52, s58, exact, off, a, b);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    CHECK((q = strstr(out, "\"geodesic\":")) != NULL);
    CHECK_STR_HAS(q, "\"points\":10,");
    CHECK(field(q, "mean") == 0);
    CHECK((q = strstr(q + 1, "\"geodesic\":")) != NULL);
    CHECK(field(q, "mean") > 1e-3);
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s --gt %s --gt-target %s --gt-format vts-pair "
             "--gt-base 1", s52, s58, exact, a, b);
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "52.vts: read 1-based, but the position on each line is that of its vertex read "
                  "0-based");
    CHECK_STR_HAS(out, ": leave --gt-base out");
    free(text);
    free(to);
    mesh_free(S);
}
