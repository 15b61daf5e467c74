/* test_daemon_repair.c — input mesh repair on real data end to end: SCAPE
 * mesh000 (one pinched vertex, which the optimizer cannot use as given) to
 * mesh001, every other one of the 36 BIM landmarks given and the others
 * held out, identity ground truth. Through `meshcorr match`, through a real
 * meshcorrd on loopback (`meshcorr submit --watch`, `meshcorr result`) and
 * through the Python package's in-process match(): each repairs the mesh,
 * says so, returns a row for every one of the user's 12500 vertices and
 * maps within a small error of the identity, which it prints. With repair
 * no, `meshcorr match` and the daemon's SUBMIT check refuse the mesh as
 * before. Skipped without the data folder. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testgt.h"
#include "support/testmesh.h"
#include "support/testrun.h"
#include "map/bmap.h"
#include "mesh/mesh.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define PYTHON "/usr/bin/python3"

static char out[1 << 16];
static char s_path[600], t_path[600], given[700], held[700];

/* The pair's paths and the two halves of the landmark list (.pid lines). */
static void paths(void)
{
    snprintf(s_path, sizeof s_path, "%s", harness_data_path("scape/Meshes/mesh000.off"));
    snprintf(t_path, sizeof t_path, "%s", harness_data_path("scape/Meshes/mesh001.off"));
    char pid[700];
    snprintf(pid, sizeof pid, "%s", harness_data_path("scape/Corrs/1.pid"));
    if (access(s_path, R_OK) || access(t_path, R_OK) || access(pid, R_OK))
        SKIP("SCAPE mesh000/mesh001 or Corrs/1.pid not found under the data folder");
    snprintf(given, sizeof given, "%s/given.pid", harness_tmpdir());
    snprintf(held, sizeof held, "%s/held.pid", harness_tmpdir());
    FILE *in = fopen(pid, "r"), *g = fopen(given, "w"), *h = fopen(held, "w");
    CHECK(in && g && h);
    char line[256];
    for (int k = 0; fgets(line, sizeof line, in); k++)
        fputs(line, k % 2 ? h : g);
    fclose(in);
    fclose(g);
    fclose(h);
}

/* P (a meshcorr-map file) read against the user's meshes (one row per
 * vertex of mesh000, faces of mesh001), its errors printed: the geodesic
 * error to the identity over every vertex and over the held-out landmarks
 * (meshcorr eval), and the Euclidean one (testgt_identity_error), which
 * must be small. */
static void score(const char *how, const char *P)
{
    mesh *S = testmesh_read("scape/Meshes/mesh000.off"), *T = testmesh_read("scape/Meshes/mesh001.off");
    bmap *m = NULL;
    char err[1024];
    if (bmap_read(P, S, T, &m, err, sizeof err))
        FAILF("%s: %s", how, err);
    CHECK_INT(m->n, 12500);
    double e = testgt_identity_error(S, T, m);
    char id[700];
    snprintf(id, sizeof id, "%s/identity.txt", harness_tmpdir());
    FILE *fp = fopen(id, "w");
    CHECK(fp);
    for (int i = 0; i < S->nv; i++)
        fprintf(fp, "%d\n", i);
    fclose(fp);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr eval %s %s %s --gt %s --gt-format vertex-list "
                       "2>&1 | grep 'geodesic error'", s_path, t_path, P, id), 0);
    char dense[1 << 16];
    snprintf(dense, sizeof dense, "%s", out);
    dense[strcspn(dense, "\n")] = '\0';
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr eval %s %s %s --gt %s --gt-target %s "
                       "--gt-format vts-pair 2>&1 | grep 'geodesic error'", s_path, t_path, P, held,
                       held), 0);
    out[strcspn(out, "\n")] = '\0';
    printf("  %s: identity, Euclidean: %.4f; %s; held-out landmarks: %s\n", how, e, dense, out);
    CHECK(e < 0.02);
    bmap_free(m);
    mesh_free(S);
    mesh_free(T);
}

TEST_T(scape_pinched_mesh_is_repaired_and_matched_by_meshcorr_match, 900)
{
    paths();
    char P[700];
    snprintf(P, sizeof P, "%s/match.map", harness_tmpdir());
    int rc = testrunf(out, sizeof out, "build/meshcorr match %s %s --source-landmarks %s "
                      "--target-landmarks %s --out %s --progress none 2>&1", s_path, t_path, given,
                      given, P);
    if (rc)
        FAILF("meshcorr match exited %d:\n%s", rc, out);
    CHECK_STR_HAS(out, "mesh000.off: repaired: 1 vertex copies made where faces formed more than one fan");
    score("meshcorr match", P);
}

TEST_T(scape_pinched_mesh_is_repaired_and_matched_by_the_daemon, 900)
{
    paths();
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "repair", NULL);
    int rc = testrunf(out, sizeof out, "build/meshcorr submit %s %s --source-landmarks %s "
                      "--target-landmarks %s --watch --server %s 2>&1", s_path, t_path,
                      given, given, d.unix_addr);
    if (rc)
        FAILF("meshcorr submit exited %d:\n%s", rc, out);
    unsigned long long id = strtoull(out, NULL, 10);
    CHECK(id > 0);
    char P[700];
    snprintf(P, sizeof P, "%s/daemon.map", harness_tmpdir());
    rc = testrunf(out, sizeof out, "build/meshcorr result %llu --out %s --server %s 2>&1", id, P,
                  d.unix_addr);
    if (rc)
        FAILF("meshcorr result exited %d:\n%s", rc, out);
    /* the repair's record, one metric a line */
    CHECK_STR_HAS(out, "repair_source_split_vertices 1\n");
    CHECK_STR_HAS(out, "repair_target_split_vertices 1\n");
    CHECK_STR_HAS(out, "repair_source_welded 0\n");
    score("meshcorrd", P);
    testdaemon_stop(&d, SIGTERM);          /* fails unless the daemon exits 0 */
}

TEST_T(scape_pinched_mesh_is_repaired_and_matched_by_python_in_process, 900)
{
    paths();
    if (testrun(PYTHON " -c 'import numpy' 2>&1", out, sizeof out) != 0)
        SKIP(PYTHON " with numpy is not installed (apt-get install python3-numpy)");
    char P[700];
    snprintf(P, sizeof P, "%s/python.map", harness_tmpdir());
    int rc = testrunf(out, sizeof out,
                      "MESHCORR_LIB=build/libmeshcorr.so.1 PYTHONPATH=client-c/python "
                      "PYTHONDONTWRITEBYTECODE=1 " PYTHON " tests/python/repair_scape.py %s %s %s %s 2>&1",
                      s_path, t_path, given, P);
    if (rc)
        FAILF("repair_scape.py exited %d:\n%s", rc, out);
    CHECK_STR_HAS(out, "repair: {'source': {");
    CHECK_STR_HAS(out, "'split_vertices': 1");
    score("python match()", P);
}

/* repair no: today's refusal, at once, from the CLI and the daemon's check. */
TEST_T(repair_no_refuses_the_pinched_mesh_in_match_and_at_submit, 120)
{
    paths();
    char P[700];
    snprintf(P, sizeof P, "%s/no.map", harness_tmpdir());
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr match %s %s --source-landmarks %s "
                       "--target-landmarks %s --out %s --repair no 2>&1", s_path, t_path, given, given,
                       P), 1);
    CHECK_STR_HAS(out, "mesh000.off is not usable by the optimizer");
    CHECK_STR_HAS(out, "1 non-manifold vertices (faces around them form more than one fan), first vertex 419");
    CHECK(access(P, F_OK) != 0);
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "repair-no", NULL);
    int rc = testrunf(out, sizeof out, "build/meshcorr submit %s %s --source-landmarks %s "
                      "--target-landmarks %s --repair no --server %s 2>&1", s_path, t_path, given,
                      given, d.unix_addr);
    CHECK(rc != 0);
    CHECK_STR_HAS(out, "BAD_MESH");
    CHECK_STR_HAS(out, "source mesh is not usable by the optimizer:\n  source mesh: 1 non-manifold vertices");
    char named[1600];                  /* and which file the source mesh is */
    snprintf(named, sizeof named, "meshcorr submit: the source mesh is %s, the target mesh %s", s_path, t_path);
    CHECK_STR_HAS(out, named);
    testdaemon_stop(&d, SIGTERM);
}
