/* test_geo_cotan.c — the cotan Laplacian: CSR layout, L 1 = 0, symmetry,
 * positive diagonal, positive semi-definiteness, agreement with the
 * edge-length formula, exactness on linear functions, and the Euler
 * characteristic of every test mesh and every real mesh. */
#include "support/harness.h"
#include "support/testdata.h"
#include "support/testmesh.h"
#include "geo/geo_area.h"
#include "geo/geo_cotan.h"
#include "geo/geo_edges.h"

#include <string.h>

static geo_csr *laplacian(const mesh *m, geo_edges *e)
{
    char err[256];
    geo_csr *L = NULL;
    if (geo_edges_build(m, e, err, sizeof err) != 0)
        FAILF("edges: %s", err);
    if (geo_cotan_laplacian(m, e, &L, err, sizeof err) != 0)
        FAILF("laplacian: %s", err);
    return L;
}

/* Layout, L 1 = 0, exact symmetry, positive diagonal, x^T L x >= 0. */
static void check_invariants(const mesh *m, const geo_csr *L, const char *name)
{
    CHECK_INT(L->n, m->nv);
    CHECK_INT(L->row_start[0], 0);
    double dmax = 0;
    for (int i = 0; i < L->n; i++) {
        int has_diag = 0;
        for (int k = L->row_start[i]; k < L->row_start[i + 1]; k++) {
            if (k > L->row_start[i])
                CHECK(L->col[k - 1] < L->col[k]);
            int j = L->col[k];
            CHECK(j >= 0 && j < L->n);
            if (j == i) {
                has_diag = 1;
                if (!(L->val[k] > 0))
                    FAILF("%s: L(%d,%d) = %g", name, i, i, L->val[k]);
                dmax = fmax(dmax, L->val[k]);
            } else if (geo_csr_get(L, j, i) != L->val[k]) {
                FAILF("%s: L(%d,%d) = %.17g but L(%d,%d) = %.17g", name, i, j, L->val[k],
                      j, i, geo_csr_get(L, j, i));
            }
        }
        CHECK(has_diag);
    }
    double *one = malloc(sizeof(double) * L->n), *y = malloc(sizeof(double) * L->n);
    for (int i = 0; i < L->n; i++)
        one[i] = 1;
    geo_csr_mul(L, one, 1, y);
    for (int i = 0; i < L->n; i++)
        if (!(fabs(y[i]) <= 1e-10 * dmax))
            FAILF("%s: (L 1)_%d = %g, max diagonal %g", name, i, y[i], dmax);
    unsigned long long st = 99;
    for (int trial = 0; trial < 3; trial++) {
        for (int i = 0; i < L->n; i++)
            one[i] = testmesh_rand(&st) - 0.5;
        geo_csr_mul(L, one, 1, y);
        double q = 0, scale = 0;
        for (int i = 0; i < L->n; i++) {
            q += one[i] * y[i];
            scale += fabs(one[i] * y[i]);
        }
        if (!(q >= -1e-12 * scale))
            FAILF("%s: x^T L x = %g < 0", name, q);
    }
    free(one);
    free(y);
}

/* Number of boundary loops (components of the boundary-edge graph) plus the
 * number of extra fans at pinched vertices: V - E + F + extra fans
 * = 2 - 2g - loops for one component. */
static int find(int *p, int x)
{
    while (p[x] != x)
        x = p[x] = p[p[x]];
    return x;
}

static void topology(const mesh *m, const geo_edges *e, int *loops, int *extra_fans)
{
    int *p = malloc(sizeof(int) * (m->nv + 3 * m->nf));
    int *on = calloc(m->nv, sizeof(int));
    for (int i = 0; i < m->nv; i++)
        p[i] = i;
    for (int k = 0; k < e->ne; k++)
        if (e->ef[2 * k + 1] < 0) {
            on[e->ev[2 * k]] = on[e->ev[2 * k + 1]] = 1;
            p[find(p, e->ev[2 * k])] = find(p, e->ev[2 * k + 1]);
        }
    *loops = 0;
    for (int i = 0; i < m->nv; i++)
        if (on[i] && find(p, i) == i)
            (*loops)++;
    /* fans: corners (t, k) joined across the two edges of t at its corner k */
    int *q = p;
    for (int c = 0; c < 3 * m->nf; c++)
        q[c] = c;
    for (int k = 0; k < e->ne; k++) {
        int s = e->ef[2 * k], t = e->ef[2 * k + 1];
        if (t < 0)
            continue;
        for (int side = 0; side < 2; side++) {
            int v = e->ev[2 * k + side], cs = -1, ct = -1;
            for (int c = 0; c < 3; c++) {
                if (m->f[3 * s + c] == v) cs = 3 * s + c;
                if (m->f[3 * t + c] == v) ct = 3 * t + c;
            }
            q[find(q, cs)] = find(q, ct);
        }
    }
    int fans = 0;
    for (int c = 0; c < 3 * m->nf; c++)
        fans += find(q, c) == c;
    int used = 0;
    memset(on, 0, sizeof(int) * m->nv);
    for (int c = 0; c < 3 * m->nf; c++)
        if (!on[m->f[c]]) {
            on[m->f[c]] = 1;
            used++;
        }
    *extra_fans = fans - used;
    free(p);
    free(on);
}

TEST(cotan_invariants_and_euler_on_generated_meshes)
{
    struct { mesh *m; int chi; const char *name; } cases[] = {
        {testmesh_icosphere(2), 2, "icosphere 2"},
        {testmesh_icosphere(3), 2, "icosphere 3"},
        {testmesh_icosphere(4), 2, "icosphere 4"},
        {testmesh_torus(2, 0.5, 48, 24), 0, "torus"},
        {testmesh_torus(1, 0.8, 7, 5), 0, "coarse torus with obtuse angles"},
        {testmesh_disk(8), 1, "disk"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        geo_edges e;
        geo_csr *L = laplacian(cases[c].m, &e);
        CHECK_INT(cases[c].m->nv - e.ne + cases[c].m->nf, cases[c].chi);
        check_invariants(cases[c].m, L, cases[c].name);
        geo_csr_free(L);
        geo_edges_close(&e);
        mesh_free(cases[c].m);
    }
}

TEST(cotan_matches_edge_length_formula)
{
    /* cot of the angle opposite side a = (b^2 + c^2 - a^2) / (4 area) */
    mesh *m = testmesh_torus(2, 0.7, 9, 6);
    unsigned long long st = 7;
    for (int i = 0; i < 3 * m->nv; i++)
        m->v[i] += 0.1 * (testmesh_rand(&st) - 0.5);
    int n = m->nv;
    double *dense = calloc((size_t)n * n, sizeof(double));
    double *fa = malloc(sizeof(double) * m->nf);
    geo_face_areas(m, fa);
    for (int t = 0; t < m->nf; t++)
        for (int k = 0; k < 3; k++) {
            int i = m->f[3 * t + (k + 1) % 3], j = m->f[3 * t + (k + 2) % 3], o = m->f[3 * t + k];
            double l2[3] = {0, 0, 0};
            for (int d = 0; d < 3; d++) {
                l2[0] += pow(m->v[3 * i + d] - m->v[3 * j + d], 2);
                l2[1] += pow(m->v[3 * o + d] - m->v[3 * i + d], 2);
                l2[2] += pow(m->v[3 * o + d] - m->v[3 * j + d], 2);
            }
            double w = 0.5 * (l2[1] + l2[2] - l2[0]) / (4 * fa[t]);
            dense[i * n + j] -= w; dense[j * n + i] -= w;
            dense[i * n + i] += w; dense[j * n + j] += w;
        }
    geo_edges e;
    geo_csr *L = laplacian(m, &e);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            CHECK_NEAR(geo_csr_get(L, i, j), dense[i * n + j], 1e-12 * (1 + fabs(dense[i * n + j])));
    /* the product agrees with the dense one, for three columns at once */
    double *y = malloc(sizeof(double) * 3 * n);
    geo_csr_mul(L, m->v, 3, y);
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            double s = 0;
            for (int j = 0; j < n; j++)
                s += dense[i * n + j] * m->v[3 * j + c];
            CHECK_NEAR(y[3 * i + c], s, 1e-12);
        }
    free(y); free(dense); free(fa);
    geo_csr_free(L);
    geo_edges_close(&e);
    mesh_free(m);
}

TEST(cotan_energy_of_linear_function_on_disk_is_area_times_gradient_squared)
{
    /* x^T L x = integral |grad x|^2 (twice the Dirichlet energy) exactly for
     * a linear x, including the one-sided boundary edges. */
    mesh *m = testmesh_disk(7);
    geo_edges e;
    geo_csr *L = laplacian(m, &e);
    double a = 0.7, b = -1.3, c = 2.0, area = geo_total_area(m);
    double *x = malloc(sizeof(double) * m->nv), *y = malloc(sizeof(double) * m->nv);
    for (int i = 0; i < m->nv; i++)
        x[i] = a * m->v[3 * i] + b * m->v[3 * i + 1] + c;
    geo_csr_mul(L, x, 1, y);
    double q = 0;
    for (int i = 0; i < m->nv; i++)
        q += x[i] * y[i];
    CHECK_NEAR(q, (a * a + b * b) * area, 1e-12);
    /* and L x vanishes at interior vertices (linear precision) */
    int interior = 1 + 3 * 6 * 7; /* centre + rings 1..6 */
    for (int i = 0; i < interior; i++)
        CHECK_NEAR(y[i], 0, 1e-12);
    free(x); free(y);
    geo_csr_free(L);
    geo_edges_close(&e);
    mesh_free(m);
}

TEST(cotan_refuses_edge_table_of_another_mesh)
{
    mesh *a = testmesh_icosphere(1), *b = testmesh_icosphere(2);
    geo_edges e;
    char err[256];
    CHECK_INT(geo_edges_build(a, &e, err, sizeof err), 0);
    geo_csr *L = (geo_csr *)1;
    CHECK_INT(geo_cotan_laplacian(b, &e, &L, err, sizeof err), GEO_EMISMATCH);
    CHECK(L == NULL);
    CHECK_STR_HAS(err, "edge table is for 42 vertices");
    geo_edges_close(&e);
    mesh_free(a);
    mesh_free(b);
}

TEST(cotan_degenerate_face_contributes_nothing)
{
    /* a unit right triangle plus a collinear sliver on its hypotenuse side */
    mesh *m = mesh_new(4, 2);
    double v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, -1, 0};
    int f[6] = {0, 1, 2, 1, 3, 2};
    memcpy(m->v, v, sizeof v);
    memcpy(m->f, f, sizeof f);
    geo_edges e;
    geo_csr *L = laplacian(m, &e);
    for (int k = 0; k < L->row_start[L->n]; k++)
        CHECK(isfinite(L->val[k]));
    CHECK_NEAR(geo_csr_get(L, 1, 2), 0, 1e-15); /* right angle at 0: cot = 0 */
    CHECK_NEAR(geo_csr_get(L, 0, 1), -0.5, 1e-15); /* 45 degrees at 2: cot = 1 */
    CHECK(geo_csr_get(L, 3, 3) == 0);
    geo_csr_free(L);
    geo_edges_close(&e);
    mesh_free(m);
}

TEST_T(cotan_invariants_and_euler_on_every_real_mesh, 60)
{
    int n, checked = 0;
    char **paths = testdata_off_files(&n);
    for (int i = 0; i < n; i++) {
        mesh *m = NULL;
        char err[256];
        if (mesh_read(paths[i], &m, err, sizeof err) != 0)
            continue;
        geo_edges e;
        geo_csr *L = laplacian(m, &e);
        check_invariants(m, L, paths[i]);
        int loops, extra;
        topology(m, &e, &loops, &extra);
        /* all the data meshes are one component of genus 0 (data README §8) */
        int chi = m->nv - e.ne + m->nf;
        if (chi + extra != 2 - loops)
            FAILF("%s: V - E + F = %d, %d extra fans, %d boundary loops", paths[i], chi, extra, loops);
        geo_csr_free(L);
        geo_edges_close(&e);
        mesh_free(m);
        checked++;
    }
    printf("  %d of %d .off files checked\n", checked, n);
    CHECK(checked > 0);
    testdata_free(paths, n);
}
