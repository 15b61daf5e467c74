/* test_geo_area.c — face areas against closed forms and Heron's formula,
 * lumped mass, normals, and the unit-area normalisation with its inverse,
 * on generated meshes and every real mesh in the data folder. */
#include "support/harness.h"
#include "support/testdata.h"
#include "support/testmesh.h"
#include "geo/geo_area.h"
#include "geo/geo_edges.h"
#include "geo/geo_normals.h"

#include <string.h>

static double sum(const double *x, int n)
{
    double s = 0;
    for (int i = 0; i < n; i++)
        s += x[i];
    return s;
}

/* Mass sums to the total area; normalising gives area 1 with the centroid
 * at the origin, and denormalising restores every coordinate. */
static void check_mass_and_normalisation(const mesh *m, const char *name)
{
    double *mass = malloc(sizeof(double) * m->nv);
    geo_vertex_areas(m, mass);
    double area = geo_total_area(m);
    if (!(fabs(sum(mass, m->nv) - area) <= 1e-12 * area))
        FAILF("%s: sum of mass %.17g != total area %.17g", name, sum(mass, m->nv), area);
    for (int i = 0; i < m->nv; i++)
        CHECK(mass[i] >= 0);

    mesh *c = mesh_copy(m);
    geo_scaling s;
    char err[256];
    CHECK_INT(geo_normalize_area(c, &s, err, sizeof err), 0);
    CHECK_NEAR(s.scale, 1 / sqrt(area), 1e-12 / sqrt(area));
    if (!(fabs(geo_total_area(c) - 1) <= 1e-12))
        FAILF("%s: normalised area %.17g", name, geo_total_area(c));
    geo_scaling again;
    CHECK_INT(geo_normalize_area(c, &again, err, sizeof err), 0);
    for (int d = 0; d < 3; d++)
        CHECK_NEAR(again.centroid[d], 0, 1e-12);
    CHECK_NEAR(again.scale, 1, 1e-12);
    geo_denormalize(&again, c->v, c->nv);
    geo_denormalize(&s, c->v, c->nv);
    double ext = 0, diff = 0;
    for (int i = 0; i < 3 * m->nv; i++) {
        ext = fmax(ext, fabs(m->v[i]));
        diff = fmax(diff, fabs(c->v[i] - m->v[i]));
    }
    if (!(diff <= 1e-12 * ext))
        FAILF("%s: denormalise moved a coordinate by %g (extent %g)", name, diff, ext);
    mesh_free(c);
    free(mass);
}

TEST(area_flat_disk_equals_inscribed_polygon)
{
    for (int rings = 1; rings <= 10; rings += 3) {
        mesh *m = testmesh_disk(rings);
        int n = 6 * rings;
        double polygon = 0.5 * n * sin(2 * M_PI / n);
        CHECK_NEAR(geo_total_area(m), polygon, 1e-13);
        check_mass_and_normalisation(m, "disk");
        mesh_free(m);
    }
}

TEST(area_icosahedron_matches_closed_form)
{
    mesh *m = testmesh_icosphere(0);
    double a = 4 / sqrt(10 + 2 * sqrt(5)); /* edge of the unit-circumradius icosahedron */
    double *fa = malloc(sizeof(double) * m->nf);
    geo_face_areas(m, fa);
    for (int t = 0; t < m->nf; t++)
        CHECK_NEAR(fa[t], sqrt(3) / 4 * a * a, 1e-14);
    CHECK_NEAR(geo_total_area(m), 5 * sqrt(3) * a * a, 1e-13);
    free(fa);
    mesh_free(m);
}

TEST(area_icosphere_converges_to_4pi_quadratically)
{
    double prev_gap = 0;
    for (int level = 1; level <= 4; level++) {
        mesh *m = testmesh_icosphere(level);
        double gap = 4 * M_PI - geo_total_area(m);
        CHECK(gap > 0); /* inscribed: every face lies inside the sphere */
        if (level > 1) {
            double ratio = prev_gap / gap; /* h halves: gap / 4 */
            if (!(ratio > 3.5 && ratio < 4.5))
                FAILF("level %d: gap %g, ratio %g", level, gap, ratio);
        }
        if (level >= 2)
            check_mass_and_normalisation(m, "icosphere");
        prev_gap = gap;
        mesh_free(m);
    }
}

TEST(area_torus_converges_to_4pi2_R_r)
{
    double R = 2, r = 0.5, prev = INFINITY;
    for (int n = 12; n <= 96; n *= 2) {
        mesh *m = testmesh_torus(R, r, 2 * n, n);
        double rel = fabs(geo_total_area(m) / (4 * M_PI * M_PI * R * r) - 1);
        CHECK(rel < prev / 3);
        prev = rel;
        if (n == 24)
            check_mass_and_normalisation(m, "torus");
        mesh_free(m);
    }
    CHECK(prev < 2e-3);
}

TEST(area_cross_product_agrees_with_heron)
{
    mesh *m = testmesh_torus(3, 1, 40, 17);
    unsigned long long st = 12345;
    for (int i = 0; i < 3 * m->nv; i++)
        m->v[i] += 0.05 * (testmesh_rand(&st) - 0.5);
    double *fa = malloc(sizeof(double) * m->nf);
    geo_face_areas(m, fa);
    for (int t = 0; t < m->nf; t++) {
        double l[3];
        for (int k = 0; k < 3; k++) {
            const double *p = m->v + 3 * m->f[3 * t + (k + 1) % 3], *q = m->v + 3 * m->f[3 * t + (k + 2) % 3];
            l[k] = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
        }
        /* Kahan's stable Heron: sort a >= b >= c */
        for (int i = 0; i < 2; i++)
            for (int j = 0; j < 2 - i; j++)
                if (l[j] < l[j + 1]) { double x = l[j]; l[j] = l[j + 1]; l[j + 1] = x; }
        double a = l[0], b = l[1], c = l[2];
        double heron = 0.25 * sqrt((a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c)));
        CHECK_NEAR(fa[t], heron, 1e-12 * heron);
    }
    free(fa);
    mesh_free(m);
}

TEST(normals_unit_outward_on_sphere_and_up_on_disk)
{
    mesh *m = testmesh_icosphere(3);
    double *fn = malloc(sizeof(double) * 3 * m->nf), *vn = malloc(sizeof(double) * 3 * m->nv);
    geo_face_normals(m, fn);
    geo_vertex_normals(m, vn);
    for (int t = 0; t < m->nf; t++) {
        double *n = fn + 3 * t, c[3] = {0, 0, 0};
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++)
                c[d] += m->v[3 * m->f[3 * t + k] + d] / 3;
        CHECK_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1, 1e-14);
        CHECK(n[0] * c[0] + n[1] * c[1] + n[2] * c[2] > 0.99 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]));
    }
    for (int i = 0; i < m->nv; i++) { /* the vertex itself is the exact normal */
        double *n = vn + 3 * i, *p = m->v + 3 * i;
        CHECK_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1, 1e-14);
        CHECK(n[0] * p[0] + n[1] * p[1] + n[2] * p[2] > 0.9995); /* within 1.8 degrees */
    }
    free(fn); free(vn);
    mesh_free(m);

    m = testmesh_disk(5);
    fn = malloc(sizeof(double) * 3 * m->nf);
    vn = malloc(sizeof(double) * 3 * m->nv);
    geo_face_normals(m, fn);
    geo_vertex_normals(m, vn);
    for (int t = 0; t < m->nf; t++)
        CHECK(fn[3 * t] == 0 && fn[3 * t + 1] == 0 && fn[3 * t + 2] == 1);
    for (int i = 0; i < m->nv; i++)
        CHECK(vn[3 * i] == 0 && vn[3 * i + 1] == 0 && vn[3 * i + 2] == 1);
    free(fn); free(vn);
    mesh_free(m);
}

TEST(degenerate_faces_have_zero_area_and_zero_normal)
{
    /* face 0 collinear, face 1 with a repeated corner, face 2 fine */
    mesh *m = mesh_new(5, 3);
    double v[15] = {0, 0, 0, 1, 1, 1, 3, 3, 3, 1, 0, 0, 0, 1, 0};
    int f[9] = {0, 1, 2, 0, 3, 3, 0, 3, 4};
    memcpy(m->v, v, sizeof v);
    memcpy(m->f, f, sizeof f);
    double fa[3], fn[9], vn[15];
    geo_face_areas(m, fa);
    geo_face_normals(m, fn);
    geo_vertex_normals(m, vn);
    CHECK_NEAR(fa[0], 0, 1e-15);
    CHECK(fa[1] == 0);
    CHECK_NEAR(fa[2], 0.5, 1e-15);
    for (int d = 0; d < 6; d++)
        CHECK(fn[d] == 0);
    CHECK(fn[6] == 0 && fn[7] == 0 && fn[8] == 1);
    for (int d = 0; d < 3; d++) /* vertices 1, 2 touch only the collinear face */
        CHECK(vn[3 + d] == 0 && vn[6 + d] == 0);
    CHECK(vn[2] == 1);
    mesh_free(m);
}

TEST(normalize_refuses_zero_area_and_leaves_mesh_alone)
{
    mesh *m = mesh_new(3, 1);
    double v[9] = {0, 0, 0, 1, 0, 0, 2, 0, 0};
    int f[3] = {0, 1, 2};
    memcpy(m->v, v, sizeof v);
    memcpy(m->f, f, sizeof f);
    geo_scaling s;
    char err[256];
    CHECK_INT(geo_normalize_area(m, &s, err, sizeof err), GEO_EDEGENERATE);
    CHECK_STR_HAS(err, "total area");
    CHECK(memcmp(m->v, v, sizeof v) == 0);
    mesh_free(m);
}

TEST_T(area_mass_and_normalisation_on_every_real_mesh, 60)
{
    int n;
    char **paths = testdata_off_files(&n);
    int checked = 0;
    for (int i = 0; i < n; i++) {
        mesh *m = NULL;
        char err[256];
        if (mesh_read(paths[i], &m, err, sizeof err) != 0)
            continue; /* not a mesh this reader takes: other tests cover I/O */
        check_mass_and_normalisation(m, paths[i]);
        checked++;
        mesh_free(m);
    }
    printf("  %d of %d .off files checked\n", checked, n);
    CHECK(checked > 0);
    testdata_free(paths, n);
}
