/* test_mesh_check.c — validation: closed forms on generated meshes, the
 * README table on every real mesh, one malformed input per problem (each
 * with its message), and `meshcorr info` exit status. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testmesh.h"
#include "mesh/mesh.h"
#include "mesh/mesh_check.h"

#include <dirent.h>
#include <string.h>
#include <sys/wait.h>

static mesh_check_report check_text(const char *name, const char *text, char *lines, size_t n)
{
    char err[512];
    mesh *m = NULL;
    CHECK_INT(mesh_read(testfile_text(name, text), &m, err, sizeof err), 0);
    mesh_check_report r;
    CHECK_INT(mesh_check_run(m, &r, err, sizeof err), 0);
    mesh_check_problems(&r, name, lines, n);
    mesh_free(m);
    return r;
}

TEST(check_icosphere_genus_0_torus_genus_1_disk_one_loop)
{
    char err[256];
    mesh_check_report r;
    mesh *s = testmesh_icosphere(2), *t = testmesh_torus(2, 0.5, 20, 10), *d = testmesh_disk(4);
    CHECK_INT(mesh_check_run(s, &r, err, sizeof err), 0);
    CHECK_INT(r.euler, 2);
    CHECK_INT(r.genus, 0);
    CHECK_INT(r.boundary_loops, 0);
    CHECK_INT(r.ne, 3 * s->nf / 2);
    CHECK(mesh_check_usable(&r));
    CHECK(r.area < 4 * M_PI && r.area > 0.97 * 4 * M_PI);  /* inscribed */
    CHECK_NEAR(r.bbox_max[0], 1.0, 1e-12);
    CHECK_INT(mesh_check_run(t, &r, err, sizeof err), 0);
    CHECK_INT(r.euler, 0);
    CHECK_INT(r.genus, 1);
    CHECK(mesh_check_usable(&r));
    CHECK_INT(mesh_check_run(d, &r, err, sizeof err), 0);
    CHECK_INT(r.boundary_loops, 1);
    CHECK_INT(r.euler, 1);
    CHECK_INT(r.genus, 0);
    CHECK_INT(r.components, 1);
    CHECK(mesh_check_usable(&r));
    char lines[256];
    CHECK_INT(mesh_check_problems(&r, "disk", lines, sizeof lines), 0);
    mesh_free(s);
    mesh_free(t);
    mesh_free(d);
}

/* Columns of the README §8 table: file | V | F | loops | comps | nm e / v | chi | genus */
TEST_T(check_every_real_mesh_matches_the_data_readme_table, 60)
{
    const char *dir = harness_data_dir();
    if (!dir)
        SKIP("no data folder");
    char path[1024];
    snprintf(path, sizeof path, "%s/README.md", dir);
    FILE *fp = fopen(path, "r");
    CHECK(fp);
    char row[1024];
    int seen = 0, usable = 0;
    while (fgets(row, sizeof row, fp)) {
        char file[512];
        int V, F, loops, comps, nme, nmv, chi;
        char loopcol[64], genus[64];
        if (sscanf(row, "| data/%511s | %d | %d | %63[^|]| %d | %d / %d | %d | %63[^|]",
                   file, &V, &F, loopcol, &comps, &nme, &nmv, &chi, genus) != 9)
            continue;
        loops = atoi(loopcol);  /* "2 (76 edges)" */
        char mp[1024], err[512];
        snprintf(mp, sizeof mp, "%s/%s", dir, file);
        mesh *m = NULL;
        if (mesh_read(mp, &m, err, sizeof err))
            FAILF("%s", err);
        mesh_check_report r;
        CHECK_INT(mesh_check_run(m, &r, err, sizeof err), 0);
        if (r.nv != V || r.nf != F || r.boundary_loops != loops || r.components != comps
            || r.nonmanifold_edges != nme || r.nonmanifold_vertices != nmv || r.euler != chi
            || r.degenerate_faces || r.unreferenced_vertices || r.inconsistent_edges)
            FAILF("%s: V %d F %d loops %d comps %d nm %d/%d chi %ld degenerate %d unref %d "
                  "inconsistent %d; README says %d %d %d %d %d/%d %d", file, r.nv, r.nf,
                  r.boundary_loops, r.components, r.nonmanifold_edges, r.nonmanifold_vertices,
                  r.euler, r.degenerate_faces, r.unreferenced_vertices, r.inconsistent_edges,
                  V, F, loops, comps, nme, nmv, chi);
        if (strncmp(genus, "n/a", 3) == 0) {
            CHECK_INT(r.genus, -1);
            CHECK(!mesh_check_usable(&r));
        } else {
            CHECK_INT(r.genus, atoi(genus));
            if (!mesh_check_usable(&r))
                FAILF("%s is not usable", file);
            usable++;
        }
        seen++;
        mesh_free(m);
    }
    fclose(fp);
    CHECK(seen >= 60);
    CHECK(usable >= 60);
    printf("  %d meshes checked, %d usable\n", seen, usable);
}

TEST(check_scape_reports_one_nonmanifold_vertex_and_info_exits_1)
{
    const char *p = harness_data_path("scape/Meshes/mesh000.off");
    char err[512];
    mesh *m = NULL;
    CHECK_INT(mesh_read(p, &m, err, sizeof err), 0);
    mesh_check_report r;
    CHECK_INT(mesh_check_run(m, &r, err, sizeof err), 0);
    CHECK_INT(r.nonmanifold_vertices, 1);
    CHECK_INT(r.nonmanifold_edges, 0);
    CHECK(!mesh_check_usable(&r));
    mesh_free(m);

    char cmd[1200], out[4096] = "";
    snprintf(cmd, sizeof cmd, "build/meshcorr info %s 2>&1", p);
    FILE *pp = popen(cmd, "r");
    CHECK(pp);
    size_t n = fread(out, 1, sizeof out - 1, pp);
    out[n] = '\0';
    int st = pclose(pp);
    CHECK(WIFEXITED(st));
    CHECK_INT(WEXITSTATUS(st), 1);
    CHECK_STR_HAS(out, "vertices        12500");
    CHECK_STR_HAS(out, "mesh000.off: 1 non-manifold vertices");
    CHECK_STR_HAS(out, "first vertex 419");
}

TEST(info_exits_0_on_usable_mesh_and_1_on_unreadable_file)
{
    char cmd[1200], out[4096] = "";
    snprintf(cmd, sizeof cmd, "build/meshcorr info %s 2>&1",
             harness_data_path("tosca_hires/Meshes/horse5.off"));
    FILE *pp = popen(cmd, "r");
    CHECK(pp);
    size_t n = fread(out, 1, sizeof out - 1, pp);
    out[n] = '\0';
    int st = pclose(pp);
    CHECK_INT(WEXITSTATUS(st), 0);
    CHECK_STR_HAS(out, "boundary loops  1");
    CHECK_STR_HAS(out, "genus           0");
    const char *bad = testfile_text("garbage.off", "OFF\nx y z\n");
    snprintf(cmd, sizeof cmd, "build/meshcorr info %s 2>&1", bad);
    pp = popen(cmd, "r");
    n = fread(out, 1, sizeof out - 1, pp);
    out[n] = '\0';
    st = pclose(pp);
    CHECK_INT(WEXITSTATUS(st), 1);
    CHECK_STR_HAS(out, "garbage.off:2");
}

#define TRI "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"

TEST(check_reports_nan_coordinate)
{
    char lines[1024];
    mesh_check_report r = check_text("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n",
                                     lines, sizeof lines);
    CHECK_INT(r.nonfinite_vertices, 1);
    CHECK_INT(r.first_nonfinite_vertex, 1);
    CHECK(!mesh_check_usable(&r));
    CHECK_STR_HAS(lines, "nan.off: 1 vertices with a NaN or infinite coordinate, first vertex 1");
}

TEST(check_reports_face_index_out_of_range)
{
    char err[256], lines[1024];
    mesh *m = mesh_new(3, 2);
    const int f[6] = { 0, 1, 2, 0, 2, 7 };
    memcpy(m->f, f, sizeof f);
    m->v[3] = 1;
    m->v[7] = 1;
    mesh_check_report r;
    CHECK_INT(mesh_check_run(m, &r, err, sizeof err), 0);
    CHECK_INT(r.bad_index_faces, 1);
    CHECK_INT(r.first_bad_index_face, 1);
    CHECK(!mesh_check_usable(&r));
    mesh_check_problems(&r, "mem", lines, sizeof lines);
    CHECK_STR_HAS(lines, "mem: 1 faces with a vertex index out of range [0, 3), first face 1");
    mesh_free(m);
}

TEST(check_reports_nonmanifold_edge)
{
    char lines[1024];
    /* Three triangles on the edge 0-1. */
    mesh_check_report r = check_text("fin.off",
        "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n",
        lines, sizeof lines);
    CHECK_INT(r.nonmanifold_edges, 1);
    CHECK_INT(r.first_nonmanifold_edge[0], 0);
    CHECK_INT(r.first_nonmanifold_edge[1], 1);
    CHECK_INT(r.genus, -1);
    CHECK(!mesh_check_usable(&r));
    CHECK_STR_HAS(lines, "fin.off: 1 non-manifold edges (more than two faces), first edge 0-1");
}

TEST(check_reports_nonmanifold_vertex_of_two_cones_sharing_apex)
{
    char lines[1024];
    /* Two closed tetrahedra would share only vertex 0; use two open cones
     * (3 faces each) with apex 0. */
    mesh_check_report r = check_text("cones.off",
        "OFF\n7 6 0\n0 0 0\n1 0 1\n-1 1 1\n-1 -1 1\n1 0 -1\n-1 1 -1\n-1 -1 -1\n"
        "3 0 1 2\n3 0 2 3\n3 0 3 1\n3 0 5 4\n3 0 6 5\n3 0 4 6\n", lines, sizeof lines);
    CHECK_INT(r.nonmanifold_vertices, 1);
    CHECK_INT(r.first_nonmanifold_vertex, 0);
    CHECK_INT(r.nonmanifold_edges, 0);
    CHECK_INT(r.components, 1);
    CHECK_INT(r.boundary_loops, 2);
    CHECK(!mesh_check_usable(&r));
    CHECK_STR_HAS(lines, "cones.off: 1 non-manifold vertices");
    CHECK_STR_HAS(lines, "first vertex 0");
}

TEST(check_reports_degenerate_face)
{
    char lines[1024];
    mesh_check_report r = check_text("flat.off",
        "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n2 0 0\n3 0 1 2\n3 0 1 3\n", lines, sizeof lines);
    CHECK_INT(r.degenerate_faces, 1);
    CHECK_INT(r.first_degenerate_face, 1);
    CHECK(!mesh_check_usable(&r));
    CHECK_STR_HAS(lines, "flat.off: 1 degenerate (zero-area) faces, first face 1");
    r = check_text("rep.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 0 1\n", lines, sizeof lines);
    CHECK_INT(r.degenerate_faces, 1);
}

TEST(check_reports_duplicate_face)
{
    char lines[1024];
    mesh_check_report r = check_text("dup.off",
        "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n3 2 0 1\n", lines, sizeof lines);
    CHECK_INT(r.duplicate_faces, 1);
    CHECK_INT(r.first_duplicate_pair[0], 0);
    CHECK_INT(r.first_duplicate_pair[1], 2);
    CHECK(!mesh_check_usable(&r));
    CHECK_STR_HAS(lines, "dup.off: 1 duplicate faces (same vertex set), first pair faces 0 and 2");
}

TEST(check_reports_unreferenced_vertex)
{
    char lines[1024];
    mesh_check_report r = check_text("unref.off",
        "OFF\n4 1 0\n0 0 0\n1 0 0\n5 5 5\n0 1 0\n3 0 1 3\n", lines, sizeof lines);
    CHECK_INT(r.unreferenced_vertices, 1);
    CHECK_INT(r.first_unreferenced_vertex, 2);
    CHECK(!mesh_check_usable(&r));
    CHECK_STR_HAS(lines, "unref.off: 1 unreferenced vertices (in no face), first vertex 2");
}

TEST(check_reports_two_components)
{
    char lines[1024];
    mesh_check_report r = check_text("two.off",
        "OFF\n6 2 0\n0 0 0\n1 0 0\n0 1 0\n5 0 0\n6 0 0\n5 1 0\n3 0 1 2\n3 3 4 5\n", lines, sizeof lines);
    CHECK_INT(r.components, 2);
    CHECK_INT(r.boundary_loops, 2);
    CHECK_INT(r.genus, -1);
    CHECK(!mesh_check_usable(&r));
    CHECK_STR_HAS(lines, "two.off: 2 connected components; one is needed");
}

TEST(check_reports_inconsistent_orientation)
{
    char lines[1024];
    mesh_check_report r = check_text("flip.off",
        "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 2 3\n", lines, sizeof lines);
    CHECK_INT(r.inconsistent_edges, 1);
    CHECK_INT(r.first_inconsistent_edge[0], 1);
    CHECK_INT(r.first_inconsistent_edge[1], 2);
    CHECK(!mesh_check_usable(&r));
    CHECK_STR_HAS(lines, "flip.off: inconsistent orientation on 1 edges, first edge 1-2");
    r = check_text("tri.off", TRI, lines, sizeof lines);
    CHECK(mesh_check_usable(&r));
}
