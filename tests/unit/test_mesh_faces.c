/* test_mesh_faces.c — polygons split into triangles by the readers
 * (mesh_faces.c), against brute force: random simple polygons, convex and
 * not, tilted in space, come out as k - 2 triangles that keep the
 * polygon's orientation and add up to its area (the shoelace formula); a
 * flat convex quad is cut along its shorter diagonal, a concave one along
 * the other; two sharply bent quads round a vertex do not both cut the
 * same diagonal; a flat-degenerate polygon still gives k - 2 triangles. */
#include "support/harness.h"
#include "support/testfile.h"
#include "mesh/mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The polygon of k corners at 2-D points xy (the plane z = 0 rotated by
 * the angles a, b) read back from an OFF file of one face. */
static mesh *read_polygon(const double *xy, int k, double a, double b, char *err, size_t errsz)
{
    char *text = malloc(64 * (size_t)k + 256);
    size_t n = (size_t)sprintf(text, "OFF\n%d 1 0\n", k);
    for (int i = 0; i < k; i++) {
        double x = xy[2 * i], y = xy[2 * i + 1];
        double y1 = cos(a) * y, z1 = sin(a) * y;                   /* about the x axis */
        double x2 = cos(b) * x + sin(b) * z1, z2 = -sin(b) * x + cos(b) * z1;   /* about y */
        n += (size_t)sprintf(text + n, "%.17g %.17g %.17g\n", x2, y1, z2);
    }
    n += (size_t)sprintf(text + n, "%d", k);
    for (int i = 0; i < k; i++)
        n += (size_t)sprintf(text + n, " %d", i);
    sprintf(text + n, "\n");
    mesh *m = NULL;
    int rc = mesh_read(testfile_text("polygon.off", text), &m, err, errsz);
    free(text);
    return rc ? NULL : m;
}

/* The triangle's area vector dotted with the unit normal nrm. */
static double signed_area(const mesh *m, int t, const double *nrm)
{
    const double *p = m->v + 3 * m->f[3 * t], *q = m->v + 3 * m->f[3 * t + 1],
                 *r = m->v + 3 * m->f[3 * t + 2];
    double u[3], v[3];
    for (int i = 0; i < 3; i++) {
        u[i] = q[i] - p[i];
        v[i] = r[i] - p[i];
    }
    double c[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
    return 0.5 * (c[0] * nrm[0] + c[1] * nrm[1] + c[2] * nrm[2]);
}

TEST(random_simple_polygons_split_into_triangles_that_tile_them)
{
    srand(7);
    char err[512];
    for (int trial = 0; trial < 200; trial++) {
        int k = 4 + rand() % 13;
        double xy[2 * 16], ang[16], area = 0;
        for (int i = 0; i < k; i++)                  /* star-shaped about 0: simple */
            ang[i] = 2 * M_PI * (i + 0.1 + 0.8 * rand() / (double)RAND_MAX) / k;
        for (int i = 0; i < k; i++) {
            double r = 0.2 + rand() / (double)RAND_MAX;
            xy[2 * i] = r * cos(ang[i]);
            xy[2 * i + 1] = r * sin(ang[i]);
        }
        for (int i = 0; i < k; i++)
            area += 0.5 * (xy[2 * i] * xy[2 * ((i + 1) % k) + 1] - xy[2 * ((i + 1) % k)] * xy[2 * i + 1]);
        double a = 3.0 * rand() / RAND_MAX, b = 3.0 * rand() / RAND_MAX;
        mesh *m = read_polygon(xy, k, a, b, err, sizeof err);
        if (!m)
            FAILF("trial %d: %s", trial, err);
        CHECK_INT(m->nf, k - 2);
        CHECK_INT(m->polygons, 1);
        /* the plane's normal, rotated as the points were */
        double nrm[3] = { sin(b) * cos(a), -sin(a), cos(b) * cos(a) };
        double sum = 0;
        for (int t = 0; t < m->nf; t++) {
            double s = signed_area(m, t, nrm);
            if (!(s > 0))
                FAILF("trial %d (k %d): triangle %d is flat or reversed (area %g)", trial, k, t, s);
            sum += s;
        }
        CHECK_NEAR(sum, area, 1e-12 * (1 + area));
        mesh_free(m);
    }
}

/* The flat quad xy, tilted by the angles a, b, is cut along 1-3. */
static void check_cut_along_1_3(const double *xy, double a, double b)
{
    char err[512];
    mesh *m = read_polygon(xy, 4, a, b, err, sizeof err);
    if (!m)
        FAILF("%s", err);
    const int want[] = { 1, 2, 3, 1, 3, 0 };
    for (int i = 0; i < 6; i++)
        CHECK_INT(m->f[i], want[i]);
    mesh_free(m);
}

TEST(a_convex_quad_is_cut_along_its_shorter_diagonal)
{
    const double kite[] = { 0, 0, 3, -0.5, 4, 0, 3, 0.5 };   /* 0-2 is 4 long, 1-3 is 1 */
    check_cut_along_1_3(kite, 0.3, 0.2);
}

TEST(a_concave_quad_is_cut_through_its_reflex_corner_though_that_diagonal_is_longer)
{
    const double dart[] = { 0, 0, 1, -3, 2, 0, 1, -0.5 };   /* reflex at 3; 0-2 is 2 long, 1-3 is 2.5 */
    check_cut_along_1_3(dart, 0.4, -0.7);
}

TEST(two_bent_quads_round_a_vertex_do_not_make_one_triangle_twice)
{
    /* Two quads of make demo's cow.off paired from its triangles round
     * vertex 2 (cow.off's 1395), bent so sharply that each alone is cut
     * along 1-3 (cow.off's 1423-1394), which gives triangle 1 2 3 twice. */
    char err[512];
    mesh *m = NULL;
    const char *p = testfile_text("bent.off", "OFF\n5 2 0\n"
                                              "0.317696 0.274306 -0.132233\n0.318424 0.263405 -0.137703\n"
                                              "0.313153 0.266184 -0.139079\n0.314267 0.26159 -0.128118\n"
                                              "0.31663 0.250333 -0.138926\n4 0 1 2 3\n4 2 1 4 3\n");
    CHECK_INT(mesh_read(p, &m, err, sizeof err), MESH_OK);
    CHECK_INT(m->nf, 4);
    for (int a = 0; a < 4; a++)
        for (int b = a + 1; b < 4; b++) {
            int same = 0;
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    same += m->f[3 * a + i] == m->f[3 * b + j];
            if (same == 3)
                FAILF("triangles %d and %d are on the same three vertices", a, b);
        }
    mesh_free(m);
}

TEST(a_polygon_with_no_area_still_gives_its_triangles)
{
    char err[512];
    const double line[] = { 0, 0, 1, 0, 2, 0, 3, 0, 1.5, 0 };
    mesh *m = read_polygon(line, 5, 0, 0, err, sizeof err);
    CHECK(m);
    CHECK_INT(m->nf, 3);
    for (int i = 0; i < 9; i++)
        CHECK(m->f[i] >= 0 && m->f[i] < 5);
    mesh_free(m);
}
