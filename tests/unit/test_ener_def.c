/* test_ener_def.c — the deformation energy over whole meshes: gradient
 * against finite differences on a real mesh (mild and violent deformations
 * with collapsed and folded faces), W(X) = 0 with zero gradient, rigid
 * invariance, the closed form under uniform scaling, agreement with the
 * single-edge kernel, thread-count determinism, admissible edges, and the
 * construction errors. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "ener/ener_def.h"
#include "geo/geo_edges.h"

#include <omp.h>
#include <string.h>

typedef struct fixture {
    mesh *X;
    geo_edges E;
    ener_def *d;
    double *Y, *g, *tmp;
    double mean_edge, area;
} fixture;

static void fixture_open(fixture *fx, mesh *X, ener_def_params p)
{
    char err[256];
    memset(fx, 0, sizeof *fx);
    fx->X = X;
    CHECK(X != NULL);
    if (geo_edges_build(X, &fx->E, err, sizeof err) != 0)
        FAILF("geo_edges_build: %s", err);
    fx->d = ener_def_new(X, &fx->E, &p, err, sizeof err);
    if (!fx->d)
        FAILF("ener_def_new: %s", err);
    size_t n = 3 * (size_t)X->nv;
    fx->Y = malloc(n * sizeof(double));
    fx->g = malloc(n * sizeof(double));
    fx->tmp = malloc(n * sizeof(double));
    CHECK(fx->Y && fx->g && fx->tmp);
    memcpy(fx->Y, X->v, n * sizeof(double));
    double sum = 0.0;
    for (int e = 0; e < fx->E.ne; e++) {
        const double *a = X->v + 3 * fx->E.ev[2 * e], *b = X->v + 3 * fx->E.ev[2 * e + 1];
        sum += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                    (a[2] - b[2]) * (a[2] - b[2]));
    }
    fx->mean_edge = sum / fx->E.ne;
    for (int t = 0; t < X->nf; t++) {
        const double *a = X->v + 3 * X->f[3 * t], *b = X->v + 3 * X->f[3 * t + 1];
        const double *c = X->v + 3 * X->f[3 * t + 2];
        double u[3], v[3];
        for (int k = 0; k < 3; k++) {
            u[k] = b[k] - a[k];
            v[k] = c[k] - a[k];
        }
        double n0 = u[1] * v[2] - u[2] * v[1], n1 = u[2] * v[0] - u[0] * v[2];
        double n2 = u[0] * v[1] - u[1] * v[0];
        fx->area += 0.5 * sqrt(n0 * n0 + n1 * n1 + n2 * n2);
    }
}

static void fixture_close(fixture *fx)
{
    ener_def_free(fx->d);
    geo_edges_close(&fx->E);
    mesh_free(fx->X);
    free(fx->Y);
    free(fx->g);
    free(fx->tmp);
}

static mesh *read_mesh(const char *rel)
{
    char err[256];
    mesh *m = NULL;
    if (mesh_read(harness_data_path(rel), &m, err, sizeof err) != 0)
        FAILF("%s: %s", rel, err);
    return m;
}

static double rnd(unsigned long long *s) { return 2.0 * testmesh_rand(s) - 1.0; }

static void perturb(fixture *fx, double amount, unsigned long long seed)
{
    for (int i = 0; i < 3 * fx->X->nv; i++)
        fx->Y[i] = fx->X->v[i] + amount * fx->mean_edge * rnd(&seed);
}

static double eval_at(fixture *fx, const double *Y)
{
    return ener_def_eval(fx->d, Y, NULL, NULL, NULL);
}

static double gmax(const fixture *fx)
{
    double m = 0.0;
    for (int i = 0; i < 3 * fx->X->nv; i++)
        m = fmax(m, fabs(fx->g[i]));
    return m;
}

/* Central differences of ener_def_eval on n random coordinates (plus the
 * listed vertices' coordinates) and along one random direction; errors
 * relative to the largest gradient component. */
static void check_fd(fixture *fx, int n, const int *verts, int nverts,
                     unsigned long long seed, double tol)
{
    const int nc = 3 * fx->X->nv;
    ener_def_eval(fx->d, fx->Y, fx->g, NULL, NULL);
    double scale = gmax(fx), h = 1e-6 * fx->mean_edge;
    CHECK(isfinite(scale) && scale > 0.0);
    for (int q = 0; q < n + 3 * nverts; q++) {
        int c = q < n ? (int)(testmesh_rand(&seed) * nc) : 3 * verts[(q - n) / 3] + (q - n) % 3;
        memcpy(fx->tmp, fx->Y, nc * sizeof(double));
        fx->tmp[c] = fx->Y[c] + h;
        double ep = eval_at(fx, fx->tmp), step = fx->tmp[c];
        fx->tmp[c] = fx->Y[c] - h;
        double em = eval_at(fx, fx->tmp);
        step -= fx->tmp[c];
        double fd = (ep - em) / step;
        if (!(fabs(fd - fx->g[c]) <= tol * scale))
            FAILF("coordinate %d: analytic %.12g, finite difference %.12g (scale %g)",
                  c, fx->g[c], fd, scale);
    }
    /* directional derivative along a random unit direction */
    double *dir = malloc(nc * sizeof(double)), norm = 0.0, dot = 0.0;
    CHECK(dir != NULL);
    for (int i = 0; i < nc; i++) {
        dir[i] = rnd(&seed);
        norm += dir[i] * dir[i];
    }
    norm = sqrt(norm);
    for (int i = 0; i < nc; i++) {
        dir[i] /= norm;
        dot += dir[i] * fx->g[i];
    }
    for (int i = 0; i < nc; i++)
        fx->tmp[i] = fx->Y[i] + h * dir[i];
    double ep = eval_at(fx, fx->tmp);
    for (int i = 0; i < nc; i++)
        fx->tmp[i] = fx->Y[i] - h * dir[i];
    double em = eval_at(fx, fx->tmp);
    double fd = (ep - em) / (2.0 * h);
    double gnorm = 0.0;
    for (int i = 0; i < nc; i++)
        gnorm += fx->g[i] * fx->g[i];
    if (!(fabs(fd - dot) <= tol * sqrt(gnorm)))
        FAILF("directional derivative: analytic %.12g, finite difference %.12g (|g| %g)",
              dot, fd, sqrt(gnorm));
    free(dir);
}

TEST_T(gradient_matches_finite_differences_on_perturbed_real_mesh, 60)
{
    fixture fx;
    fixture_open(&fx, read_mesh("shrec07_bim/Meshes/386.off"),
                 (ener_def_params){1.0, 1.0, ENER_LOG_EPS_DEFAULT, NULL});
    CHECK_INT(fx.X->nv, 2087);
    perturb(&fx, 0.1, 3);
    double wm, wb;
    ener_def_eval(fx.d, fx.Y, fx.g, &wm, &wb);
    CHECK(wm > 0.0 && wb > 0.0);
    check_fd(&fx, 50, NULL, 0, 17, 1e-6);
    fixture_close(&fx);
}

/* Moves vertex v onto its neighbour across face t's corner, reflects
 * another vertex through its opposite edge in one of its faces. Returns the
 * vertices moved in moved[]. */
static int violent_deformation(fixture *fx, int moved[8])
{
    const int *f = fx->X->f;
    int n = 0;
    for (int q = 0; q < 3; q++) { /* collapse an edge of three faces */
        int t = 97 * q + 11;
        int a = f[3 * t], b = f[3 * t + 1];
        memcpy(fx->Y + 3 * a, fx->Y + 3 * b, 3 * sizeof(double));
        moved[n++] = a;
    }
    {   /* collapse a face to a point */
        int t = 1501;
        for (int k = 1; k < 3; k++)
            memcpy(fx->Y + 3 * f[3 * t + k], fx->Y + 3 * f[3 * t], 3 * sizeof(double));
        moved[n++] = f[3 * t + 1];
        moved[n++] = f[3 * t + 2];
    }
    for (int q = 0; q < 2; q++) { /* reflect a vertex through its opposite edge */
        int t = 2203 + 401 * q;
        int a = f[3 * t], b = f[3 * t + 1], c = f[3 * t + 2];
        double *ya = fx->Y + 3 * a, *yb = fx->Y + 3 * b, *yc = fx->Y + 3 * c;
        double m[3], u[3], uu = 0.0, s = 0.0;
        for (int k = 0; k < 3; k++) {
            u[k] = yc[k] - yb[k];
            uu += u[k] * u[k];
        }
        for (int k = 0; k < 3; k++)
            s += (ya[k] - yb[k]) * u[k];
        for (int k = 0; k < 3; k++) {
            m[k] = yb[k] + s / uu * u[k];  /* foot of a on line bc */
            ya[k] = 2.0 * m[k] - ya[k];
        }
        moved[n++] = a;
    }
    return n;
}

TEST_T(gradient_matches_finite_differences_with_collapsed_and_folded_faces, 60)
{
    /* ε large enough that a step of h keeps collapsed faces on the tangent line */
    fixture fx;
    fixture_open(&fx, read_mesh("shrec07_bim/Meshes/386.off"),
                 (ener_def_params){1.0, 1.0, 1e-2, NULL});
    perturb(&fx, 0.05, 5);
    int moved[8];
    int nm = violent_deformation(&fx, moved);
    int all = fx.E.ne - geo_edges_boundary_count(&fx.E);
    int adm = ener_def_update_admissible(fx.d, fx.Y);
    CHECK(adm < all && adm > all - 40);
    double e = ener_def_eval(fx.d, fx.Y, fx.g, NULL, NULL);
    CHECK(isfinite(e));
    for (int i = 0; i < 3 * fx.X->nv; i++)
        CHECK(isfinite(fx.g[i]));
    check_fd(&fx, 30, moved, nm, 23, 1e-6);
    fixture_close(&fx);
}

TEST(energy_and_gradient_vanish_at_the_reference)
{
    fixture fx;
    fixture_open(&fx, read_mesh("shrec07_bim/Meshes/386.off"),
                 (ener_def_params){20.0, 0.5, ENER_LOG_EPS_DEFAULT, NULL});
    double wm, wb;
    double e = ener_def_eval(fx.d, fx.Y, fx.g, &wm, &wb);
    CHECK_NEAR(e, 0.0, 1e-12 * fx.area * 20.0);
    CHECK_NEAR(wb, 0.0, 1e-20);
    /* gradient per coordinate on the scale of α·(vertex area)/(edge length) */
    double gscale = 20.0 * fx.area / fx.X->nv / fx.mean_edge;
    CHECK(gmax(&fx) < 1e-12 * gscale);
    fixture_close(&fx);

    fixture_open(&fx, testmesh_icosphere(3), (ener_def_params){1.0, 1.0, ENER_LOG_EPS_DEFAULT, NULL});
    CHECK_NEAR(ener_def_eval(fx.d, fx.Y, fx.g, NULL, NULL), 0.0, 1e-13);
    CHECK(gmax(&fx) < 1e-13);
    fixture_close(&fx);
}

/* With every face's reference metric grown by 4, the membrane energy and
 * its gradient vanish at twice the reference mesh (bending is unchanged by
 * scale) and not at the reference itself. */
TEST(a_grown_reference_rests_at_the_grown_mesh)
{
    mesh *X = testmesh_icosphere(3);
    CHECK(X != NULL);
    double *four = malloc(sizeof(double) * (size_t)X->nf);
    CHECK(four != NULL);
    for (int t = 0; t < X->nf; t++)
        four[t] = 4.0;
    fixture fx;
    fixture_open(&fx, X, (ener_def_params){1.0, 1.0, ENER_LOG_EPS_DEFAULT, four});
    free(four);   /* ener_def_new keeps no pointer to it */
    CHECK(ener_def_eval(fx.d, fx.Y, fx.g, NULL, NULL) > 0.1);
    for (int i = 0; i < 3 * X->nv; i++)
        fx.Y[i] = 2 * X->v[i];
    CHECK_NEAR(ener_def_eval(fx.d, fx.Y, fx.g, NULL, NULL), 0.0, 1e-12);
    CHECK(gmax(&fx) < 1e-12);
    fixture_close(&fx);
}

/* Rotation from a unit quaternion. */
static void rotation(unsigned long long *s, double R[9])
{
    double q[4], n = 0.0;
    for (int k = 0; k < 4; k++) {
        q[k] = rnd(s);
        n += q[k] * q[k];
    }
    n = sqrt(n);
    double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
                   2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                   2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)};
    memcpy(R, r, sizeof r);
}

TEST(energy_invariant_and_gradient_covariant_under_rigid_motion)
{
    fixture fx;
    fixture_open(&fx, read_mesh("shrec07_bim/Meshes/386.off"),
                 (ener_def_params){2.0, 0.3, ENER_LOG_EPS_DEFAULT, NULL});
    perturb(&fx, 0.1, 7);
    const int nv = fx.X->nv;
    double e0 = ener_def_eval(fx.d, fx.Y, fx.g, NULL, NULL);
    double *g0 = malloc(3 * (size_t)nv * sizeof(double));
    CHECK(g0 != NULL);
    memcpy(g0, fx.g, 3 * (size_t)nv * sizeof(double));
    double scale = gmax(&fx);
    unsigned long long s = 99;
    double R[9], t[3] = {0.3, -1.2, 2.5};
    rotation(&s, R);
    for (int i = 0; i < nv; i++)
        for (int r = 0; r < 3; r++) {
            const double *y = fx.Y + 3 * i;
            fx.tmp[3 * i + r] = R[3 * r] * y[0] + R[3 * r + 1] * y[1] + R[3 * r + 2] * y[2] + t[r];
        }
    double e1 = ener_def_eval(fx.d, fx.tmp, fx.g, NULL, NULL);
    CHECK_NEAR(e1, e0, 1e-10 * fabs(e0));
    for (int i = 0; i < nv; i++)
        for (int r = 0; r < 3; r++) {
            const double *g = g0 + 3 * i;
            double want = R[3 * r] * g[0] + R[3 * r + 1] * g[1] + R[3 * r + 2] * g[2];
            CHECK_NEAR(fx.g[3 * i + r], want, 1e-9 * scale);
        }
    free(g0);
    fixture_close(&fx);
}

TEST(uniform_scaling_gives_closed_form_membrane_and_zero_bending)
{
    fixture fx;
    fixture_open(&fx, read_mesh("shrec07_bim/Meshes/386.off"),
                 (ener_def_params){3.0, 5.0, ENER_LOG_EPS_DEFAULT, NULL});
    const double scales[3] = {0.5, 1.3, 2.0};
    for (int q = 0; q < 3; q++) {
        double s = scales[q], s2 = s * s;
        for (int i = 0; i < 3 * fx.X->nv; i++)
            fx.Y[i] = s * fx.X->v[i];
        double wm, wb;
        double e = ener_def_eval(fx.d, fx.Y, NULL, &wm, &wb);
        /* W(s²·I) = ½·2s² + ¼·s⁴ − ¾·log s⁴ − 5/4 */
        double w = s2 + 0.25 * s2 * s2 - 0.75 * log(s2 * s2) - 1.25;
        CHECK_NEAR(wm, fx.area * w, 1e-10 * fx.area * w);
        CHECK_NEAR(wb, 0.0, 1e-20);
        CHECK_NEAR(e, 3.0 * wm + 5.0 * wb, 1e-12 * e);
    }
    fixture_close(&fx);
}

TEST(bending_sum_equals_the_single_edge_kernel_over_interior_edges)
{
    /* ener_def's per-face normal passes against ener_bending_edge called per
     * edge with (i, j, k) and (j, i, l) taken from the faces. */
    fixture fx;
    fixture_open(&fx, read_mesh("shrec07_bim/Meshes/386.off"),
                 (ener_def_params){1.0, 1.0, ENER_LOG_EPS_DEFAULT, NULL});
    perturb(&fx, 0.2, 9);
    double wb;
    ener_def_eval(fx.d, fx.Y, NULL, NULL, &wb);
    const int *f = fx.X->f;
    double sum = 0.0;
    for (int e = 0; e < fx.E.ne; e++) {
        int t1 = fx.E.ef[2 * e], t2 = fx.E.ef[2 * e + 1];
        if (t2 < 0)
            continue;
        int c = 0;
        while (f[3 * t1 + c] != fx.E.eo[2 * e])
            c++;
        int i = f[3 * t1 + (c + 1) % 3], j = f[3 * t1 + (c + 2) % 3], k = f[3 * t1 + c];
        int l = fx.E.eo[2 * e + 1];
        const double *X = fx.X->v;
        double xi[3], xj[3];
        memcpy(xi, X + 3 * i, sizeof xi);
        memcpy(xj, X + 3 * j, sizeof xj);
        /* reference cos θ̂ through the kernel: (1 − cos)² with weight 1 */
        double n1[3], n2[3], a[3], b[3], cc[3];
        for (int q = 0; q < 3; q++) {
            a[q] = xj[q] - xi[q];
            b[q] = X[3 * k + q] - xi[q];
            cc[q] = X[3 * l + q] - xj[q];
        }
        n1[0] = a[1] * b[2] - a[2] * b[1];
        n1[1] = a[2] * b[0] - a[0] * b[2];
        n1[2] = a[0] * b[1] - a[1] * b[0];
        n2[0] = -(a[1] * cc[2] - a[2] * cc[1]); /* (xi − xj) × (xl − xj) */
        n2[1] = -(a[2] * cc[0] - a[0] * cc[2]);
        n2[2] = -(a[0] * cc[1] - a[1] * cc[0]);
        double cref = (n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2]) /
                      sqrt((n1[0] * n1[0] + n1[1] * n1[1] + n1[2] * n1[2]) *
                           (n2[0] * n2[0] + n2[1] * n2[1] + n2[2] * n2[2]));
        double la[3] = {a[0], a[1], a[2]};
        double l2 = la[0] * la[0] + la[1] * la[1] + la[2] * la[2];
        double area1 = 0.5 * sqrt(n1[0] * n1[0] + n1[1] * n1[1] + n1[2] * n1[2]);
        double area2 = 0.5 * sqrt(n2[0] * n2[0] + n2[1] * n2[1] + n2[2] * n2[2]);
        sum += ener_bending_edge(cref, 3.0 * l2 / (area1 + area2), fx.Y + 3 * i, fx.Y + 3 * j,
                                 fx.Y + 3 * k, fx.Y + 3 * l, NULL);
    }
    CHECK(wb > 0.0);
    CHECK_NEAR(wb, sum, 1e-12 * sum);
    fixture_close(&fx);
}

TEST(same_bits_with_one_and_two_threads)
{
    fixture fx;
    fixture_open(&fx, read_mesh("shrec07_bim/Meshes/386.off"),
                 (ener_def_params){20.0, 0.1, ENER_LOG_EPS_DEFAULT, NULL});
    perturb(&fx, 0.3, 11);
    omp_set_dynamic(0);
    omp_set_num_threads(1);
    double wm1, wb1, wm2, wb2;
    double e1 = ener_def_eval(fx.d, fx.Y, fx.g, &wm1, &wb1);
    memcpy(fx.tmp, fx.g, 3 * (size_t)fx.X->nv * sizeof(double));
    omp_set_num_threads(2);
    double e2 = ener_def_eval(fx.d, fx.Y, fx.g, &wm2, &wb2);
    CHECK(memcmp(&e1, &e2, sizeof e1) == 0);
    CHECK(memcmp(&wm1, &wm2, sizeof wm1) == 0);
    CHECK(memcmp(&wb1, &wb2, sizeof wb1) == 0);
    CHECK(memcmp(fx.tmp, fx.g, 3 * (size_t)fx.X->nv * sizeof(double)) == 0);
    omp_set_num_threads(3);
    CHECK_INT(ener_def_update_admissible(fx.d, fx.Y),
              fx.E.ne - geo_edges_boundary_count(&fx.E));
    double e3 = ener_def_eval(fx.d, fx.Y, fx.g, NULL, NULL);
    CHECK(memcmp(&e1, &e3, sizeof e1) == 0);
    CHECK(memcmp(fx.tmp, fx.g, 3 * (size_t)fx.X->nv * sizeof(double)) == 0);
    fixture_close(&fx);
}

TEST(collapsing_a_face_makes_its_edges_inadmissible)
{
    fixture fx;
    fixture_open(&fx, testmesh_icosphere(2), (ener_def_params){1.0, 1.0, ENER_LOG_EPS_DEFAULT, NULL});
    const int all = fx.E.ne; /* closed: every edge is interior */
    CHECK_INT(ener_def_update_admissible(fx.d, fx.Y), all);
    /* collapse face 10 onto its first corner: the faces around the two moved
     * corners that contain an edge to the first one degenerate too */
    const int *f = fx.X->f;
    int t = 10;
    for (int k = 1; k < 3; k++)
        memcpy(fx.Y + 3 * f[3 * t + k], fx.Y + 3 * f[3 * t], 3 * sizeof(double));
    /* expected count from an independent area test per face */
    char *deg = calloc(fx.X->nf, 1);
    CHECK(deg != NULL);
    for (int u = 0; u < fx.X->nf; u++) {
        const double *a = fx.Y + 3 * f[3 * u], *b = fx.Y + 3 * f[3 * u + 1];
        const double *c = fx.Y + 3 * f[3 * u + 2];
        deg[u] = (a[0] == b[0] && a[1] == b[1] && a[2] == b[2]) ||
                 (a[0] == c[0] && a[1] == c[1] && a[2] == c[2]) ||
                 (b[0] == c[0] && b[1] == c[1] && b[2] == c[2]);
    }
    CHECK(deg[t]);
    int want = 0;
    for (int e = 0; e < fx.E.ne; e++)
        want += !deg[fx.E.ef[2 * e]] && !deg[fx.E.ef[2 * e + 1]];
    CHECK(want <= all - 3);
    CHECK_INT(ener_def_update_admissible(fx.d, fx.Y), want);
    double wm, wb;
    double e = ener_def_eval(fx.d, fx.Y, fx.g, &wm, &wb);
    CHECK(isfinite(e) && isfinite(wb) && wm > 0.0);
    for (int i = 0; i < 3 * fx.X->nv; i++)
        CHECK(isfinite(fx.g[i]));
    /* restoring the reference makes every edge admissible again */
    CHECK_INT(ener_def_update_admissible(fx.d, fx.X->v), all);
    free(deg);
    fixture_close(&fx);
}

/* A sliver keeps its area but not its shape: stretching a face's third
 * corner far along its first edge leaves the area above the area rule, yet
 * its three edges must leave the bending term (ENER_SLIVER_MIN). */
TEST(a_sliver_face_makes_its_edges_inadmissible)
{
    fixture fx;
    fixture_open(&fx, testmesh_icosphere(2), (ener_def_params){1.0, 1.0, ENER_LOG_EPS_DEFAULT, NULL});
    const int all = fx.E.ne;
    const int *f = fx.X->f;
    const int t = 10;
    double *y0 = fx.Y + 3 * f[3 * t], *y1 = fx.Y + 3 * f[3 * t + 1], *y2 = fx.Y + 3 * f[3 * t + 2];
    /* y2 := y0 + 1e6·(y1 − y0) + 1e-6·(y2 − y0): area grows (×1), edges ×1e6 */
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = y1[k] - y0[k];
        e2[k] = y2[k] - y0[k];
    }
    for (int k = 0; k < 3; k++)
        y2[k] = y0[k] + 1e6 * e1[k] + e2[k];
    /* neighbours of the stretched corner change too: count independently */
    int want = 0;
    for (int e = 0; e < fx.E.ne; e++) {
        int ok = 1;
        for (int side = 0; side < 2; side++) {
            const int u = fx.E.ef[2 * e + side];
            const double *a = fx.Y + 3 * f[3 * u], *b = fx.Y + 3 * f[3 * u + 1];
            const double *c = fx.Y + 3 * f[3 * u + 2];
            double p[3], q[3], r[3];
            for (int k = 0; k < 3; k++) { p[k] = b[k] - a[k]; q[k] = c[k] - a[k]; r[k] = c[k] - b[k]; }
            double n[3] = {p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]};
            double s2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            double l = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + q[0] * q[0] + q[1] * q[1] + q[2] * q[2]
                     + r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            ok &= s2 > 1e-10 * l * l;
        }
        want += ok;
    }
    CHECK(want <= all - 3);
    CHECK_INT(ener_def_update_admissible(fx.d, fx.Y), want);
    fixture_close(&fx);
}

TEST(construction_refuses_degenerate_reference_and_bad_parameters)
{
    char err[256];
    mesh *m = testmesh_icosphere(1);
    geo_edges E;
    CHECK_INT(geo_edges_build(m, &E, err, sizeof err), 0);
    ener_def_params bad = {-1.0, 1.0, ENER_LOG_EPS_DEFAULT, NULL};
    CHECK(ener_def_new(m, &E, &bad, err, sizeof err) == NULL);
    CHECK_STR_HAS(err, "alpha = -1");
    bad = (ener_def_params){1.0, 1.0, 0.0, NULL};
    CHECK(ener_def_new(m, &E, &bad, err, sizeof err) == NULL);
    CHECK_STR_HAS(err, "log_eps");
    ener_def_params ok = {1.0, 1.0, ENER_LOG_EPS_DEFAULT, NULL};
    memcpy(m->v + 3 * m->f[3 * 4 + 1], m->v + 3 * m->f[3 * 4], 3 * sizeof(double));
    CHECK(ener_def_new(m, &E, &ok, err, sizeof err) == NULL);
    CHECK_STR_HAS(err, "zero area in the reference mesh");
    CHECK_STR_HAS(err, ener_strerror(ENER_EDEGENERATE));
    ener_def_free(NULL);
    geo_edges_close(&E);
    mesh_free(m);
}
