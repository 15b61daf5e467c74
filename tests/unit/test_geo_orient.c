/* test_geo_orient.c — the signed angle between two gradients
 * (geo_orient.h): its closed form on a flat disk and on the unit sphere,
 * and the sign a reflection gives it. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "geo/geo_normals.h"
#include "geo/geo_orient.h"

#include <stdlib.h>
#include <string.h>

TEST(flat_disk_gives_the_sine_of_the_angle_and_a_reflection_negates_it)
{
    mesh *m = testmesh_disk(12);
    double *n = malloc(sizeof(double) * 3 * (size_t)m->nv);
    double *f = malloc(sizeof(double) * (size_t)m->nv), *o = malloc(sizeof(double) * (size_t)m->nv);
    geo_vertex_normals(m, n);
    double up = n[2] > 0 ? 1 : -1;   /* the disk's side by its corner order */
    /* f = x, g = x cos 30° + y sin 30°: sin∠(∇f, ∇g) = sin 30° about the normal */
    double *g = malloc(sizeof(double) * (size_t)m->nv);
    for (int v = 0; v < m->nv; v++) {
        f[v] = m->v[3 * v];
        g[v] = cos(M_PI / 6) * m->v[3 * v] + sin(M_PI / 6) * m->v[3 * v + 1];
    }
    CHECK(geo_gradient_sine(m, f, 1, g, 1, o) == 0);
    for (int v = 0; v < m->nv; v++)
        CHECK_NEAR(o[v], up * 0.5, 1e-12);
    /* the same functions carried onto the mirror image: the sign flips */
    mesh *r = testmesh_mirrored(m);
    double *orr = malloc(sizeof(double) * (size_t)m->nv);
    CHECK(geo_gradient_sine(r, f, 1, g, 1, orr) == 0);
    for (int v = 0; v < m->nv; v++)
        CHECK_NEAR(orr[v], -o[v], 1e-12);
    /* strides: the same values read from an interleaved array */
    double *fg = malloc(sizeof(double) * 2 * (size_t)m->nv);
    for (int v = 0; v < m->nv; v++) {
        fg[2 * v] = f[v];
        fg[2 * v + 1] = g[v];
    }
    CHECK(geo_gradient_sine(m, fg, 2, fg + 1, 2, orr) == 0);
    for (int v = 0; v < m->nv; v++)
        CHECK_NEAR(orr[v], o[v], 1e-12);
    free(fg);
    free(orr);
    mesh_free(r);
    free(g);
    free(f);
    free(o);
    free(n);
    mesh_free(m);
}

/* On the unit sphere with f = x, g = y: ∇f = e_x − n_x n, ∇g = e_y − n_y n,
 * so ⟨n, ∇f × ∇g⟩ = n_z and o = n_z / √((1 − n_x²)(1 − n_y²)). */
TEST(unit_sphere_matches_the_closed_form)
{
    mesh *m = testmesh_icosphere(4);
    double *f = malloc(sizeof(double) * (size_t)m->nv), *g = malloc(sizeof(double) * (size_t)m->nv);
    double *o = malloc(sizeof(double) * (size_t)m->nv);
    for (int v = 0; v < m->nv; v++) {
        f[v] = m->v[3 * v];
        g[v] = m->v[3 * v + 1];
    }
    CHECK(geo_gradient_sine(m, f, 1, g, 1, o) == 0);
    double worst = 0;
    int checked = 0;
    for (int v = 0; v < m->nv; v++) {
        const double *x = m->v + 3 * v;
        if (fabs(x[0]) > 0.8 || fabs(x[1]) > 0.8)
            continue;   /* near ±e_x, ±e_y a gradient vanishes */
        double want = x[2] / sqrt((1 - x[0] * x[0]) * (1 - x[1] * x[1]));
        worst = fmax(worst, fabs(o[v] - want));
        checked++;
    }
    printf("  %d vertices, max |o - closed form| = %.4f\n", checked, worst);
    CHECK(checked > m->nv / 2);
    CHECK(worst < 0.02);
    free(f);
    free(g);
    free(o);
    mesh_free(m);
}
