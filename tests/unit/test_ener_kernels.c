/* test_ener_kernels.c — the single-element kernels of the deformation
 * energy: closed forms (rigid motion, uniform scaling, flat and right-angle
 * hinges) and central finite differences of the analytic gradients on random,
 * near-degenerate, degenerate and folded elements. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "ener/ener_def.h"

#include <string.h>

static double rnd(unsigned long long *s) { return 2.0 * testmesh_rand(s) - 1.0; }

/* ĝ⁻¹ {a, b, c} and â of the triangle (x0, x1, x2), written out from the
 * definition g = [e1 | −e2]ᵀ[e1 | −e2] independently of the library. */
static void reference(const double *x0, const double *x1, const double *x2,
                      double ginv[3], double *ahat)
{
    double e1[3], e2[3], m[2][2];
    for (int k = 0; k < 3; k++) {
        e1[k] = x1[k] - x0[k];
        e2[k] = -(x2[k] - x0[k]);
    }
    m[0][0] = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    m[1][1] = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    m[0][1] = m[1][0] = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
    double det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    ginv[0] = m[1][1] / det;
    ginv[1] = -m[0][1] / det;
    ginv[2] = m[0][0] / det;
    *ahat = 0.5 * sqrt(det);
}

/* W(s·I) for the 2×2 identity scaled by s (λ = μ = 1). */
static double w_scaled_identity(double s)
{
    return 0.5 * 2.0 * s + 0.25 * s * s - 0.75 * log(s * s) - 1.25;
}

typedef struct {
    double ginv[3], ahat, log_eps;
} mem_ctx;

static double mem_eval(const mem_ctx *c, const double y[9], double g[9])
{
    return ener_membrane_face(c->ginv, c->ahat, c->log_eps, y, y + 3, y + 6, g);
}

/* Largest |analytic − central difference| over the coordinates, relative to
 * the largest gradient component (and 1, to stay meaningful near zero). */
static double mem_fd_error(const mem_ctx *c, const double y0[9], double h)
{
    double g[9], y[9], scale = 1.0, worst = 0.0;
    mem_eval(c, y0, g);
    for (int k = 0; k < 9; k++) {
        CHECK(isfinite(g[k]));
        scale = fmax(scale, fabs(g[k]));
    }
    for (int k = 0; k < 9; k++) {
        memcpy(y, y0, sizeof y);
        y[k] = y0[k] + h;
        double ep = mem_eval(c, y, NULL), step = y[k];
        y[k] = y0[k] - h;
        double em = mem_eval(c, y, NULL);
        step -= y[k]; /* the step actually taken, after rounding */
        worst = fmax(worst, fabs((ep - em) / step - g[k]));
    }
    return worst / scale;
}

static void random_tri(unsigned long long *s, double x[9])
{
    for (int k = 0; k < 9; k++)
        x[k] = rnd(s);
}

TEST(membrane_zero_under_rigid_motion_and_closed_form_under_scaling)
{
    unsigned long long s = 11;
    for (int trial = 0; trial < 50; trial++) {
        double x[9], y[9], g[9];
        mem_ctx c = {.log_eps = ENER_LOG_EPS_DEFAULT};
        random_tri(&s, x);
        reference(x, x + 3, x + 6, c.ginv, &c.ahat);
        /* rotation about z by a random angle, then a shift */
        double th = 3.0 * rnd(&s), cs = cos(th), sn = sin(th);
        for (int v = 0; v < 3; v++) {
            y[3 * v] = cs * x[3 * v] - sn * x[3 * v + 1] + 0.7;
            y[3 * v + 1] = sn * x[3 * v] + cs * x[3 * v + 1] - 2.0;
            y[3 * v + 2] = x[3 * v + 2] + 0.25;
        }
        CHECK_NEAR(mem_eval(&c, y, g), 0.0, 1e-12);
        for (int k = 0; k < 9; k++)
            CHECK_NEAR(g[k], 0.0, 1e-9 * (1.0 + c.ahat * fabs(c.ginv[0]) + c.ahat * fabs(c.ginv[2])));
        double sc = 0.5 + 2.0 * testmesh_rand(&s);
        for (int k = 0; k < 9; k++)
            y[k] = sc * x[k];
        double want = c.ahat * w_scaled_identity(sc * sc);
        CHECK_NEAR(mem_eval(&c, y, NULL), want, 1e-10 * (1.0 + fabs(want)));
    }
}

TEST(membrane_gradient_matches_finite_differences_on_random_triangles)
{
    unsigned long long s = 5;
    for (int trial = 0; trial < 200; trial++) {
        double x[9], y[9];
        mem_ctx c = {.log_eps = ENER_LOG_EPS_DEFAULT};
        random_tri(&s, x);
        random_tri(&s, y);
        reference(x, x + 3, x + 6, c.ginv, &c.ahat);
        if (!(c.ahat > 1e-3))
            continue;
        double err = mem_fd_error(&c, y, 1e-6);
        if (!(err < 1e-6))
            FAILF("trial %d: relative gradient error %g", trial, err);
    }
}

TEST(membrane_gradient_matches_finite_differences_near_degenerate)
{
    /* A sliver of height δ: det G ~ δ², far above ε, where −log dominates. */
    unsigned long long s = 7;
    for (int trial = 0; trial < 50; trial++) {
        double x[9], y[9];
        mem_ctx c = {.log_eps = ENER_LOG_EPS_DEFAULT};
        random_tri(&s, x);
        reference(x, x + 3, x + 6, c.ginv, &c.ahat);
        if (!(c.ahat > 1e-2))
            continue;
        double delta = 1e-3;
        random_tri(&s, y);
        for (int k = 0; k < 3; k++) /* y2 = midpoint of y0 y1 plus δ·random */
            y[6 + k] = 0.5 * (y[k] + y[3 + k]) + delta * rnd(&s);
        double err = mem_fd_error(&c, y, 1e-9);
        if (!(err < 1e-6))
            FAILF("trial %d: relative gradient error %g", trial, err);
    }
}

TEST(membrane_tangent_line_branch_is_finite_and_matches_finite_differences)
{
    unsigned long long s = 9;
    double x[9];
    mem_ctx c = {.log_eps = 1e-2};
    random_tri(&s, x);
    reference(x, x + 3, x + 6, c.ginv, &c.ahat);
    CHECK(c.ahat > 1e-2);
    double cases[4][9];
    random_tri(&s, cases[0]);
    for (int k = 0; k < 3; k++) {
        cases[0][6 + k] = 0.3 * cases[0][k] + 0.7 * cases[0][3 + k]; /* collinear */
        cases[0][6 + k] += 1e-4 * rnd(&s);                          /* det ≪ ε */
    }
    random_tri(&s, cases[1]);
    memcpy(cases[1] + 3, cases[1], 3 * sizeof(double));             /* y1 = y0 */
    random_tri(&s, cases[2]);
    memcpy(cases[2] + 3, cases[2], 3 * sizeof(double));             /* all three */
    memcpy(cases[2] + 6, cases[2], 3 * sizeof(double));
    random_tri(&s, cases[3]);
    for (int k = 0; k < 3; k++)                                     /* exact line */
        cases[3][6 + k] = 2.0 * cases[3][3 + k] - cases[3][k];
    for (int i = 0; i < 4; i++) {
        double g[9];
        double e = mem_eval(&c, cases[i], g);
        CHECK(isfinite(e));
        /* at det G → 0 the tangent line gives ¾·(−log ε + 1), and tr G ≥ 0 */
        CHECK(e >= c.ahat * (0.75 * (-log(c.log_eps) + 1.0) - 1.25) - 1e-12);
        double err = mem_fd_error(&c, cases[i], 1e-7);
        if (!(err < 1e-6))
            FAILF("case %d: relative gradient error %g", i, err);
    }
    /* with the default ε the degenerate gradient is still finite */
    c.log_eps = ENER_LOG_EPS_DEFAULT;
    for (int i = 0; i < 4; i++) {
        double g[9];
        CHECK(isfinite(mem_eval(&c, cases[i], g)));
        for (int k = 0; k < 9; k++)
            CHECK(isfinite(g[k]));
    }
}

TEST(membrane_is_c1_across_the_tangent_line_threshold)
{
    /* Shrink a face's height through det G = ε: energy and derivative
     * continuous at the switch. */
    double x[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, y[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    mem_ctx c = {.log_eps = 1e-2};
    reference(x, x + 3, x + 6, c.ginv, &c.ahat);
    /* det G = y[7]² here: the threshold sits at y[7] = 0.1 */
    y[7] = 0.1 * (1.0 + 1e-9);
    double ga[9], gb[9];
    double ea = mem_eval(&c, y, ga);
    y[7] = 0.1 * (1.0 - 1e-9);
    double eb = mem_eval(&c, y, gb);
    CHECK_NEAR(ea, eb, 1e-8);
    CHECK_NEAR(ga[7], gb[7], 1e-6 * fabs(ga[7]));
}

typedef struct {
    double cos_ref, weight;
} bnd_ctx;

static double bnd_eval(const bnd_ctx *c, const double y[12], double g[12])
{
    return ener_bending_edge(c->cos_ref, c->weight, y, y + 3, y + 6, y + 9, g);
}

static double bnd_fd_error(const bnd_ctx *c, const double y0[12], double h)
{
    double g[12], y[12], scale = 1e-3, worst = 0.0;
    bnd_eval(c, y0, g);
    for (int k = 0; k < 12; k++) {
        CHECK(isfinite(g[k]));
        scale = fmax(scale, fabs(g[k]));
    }
    for (int k = 0; k < 12; k++) {
        memcpy(y, y0, sizeof y);
        y[k] = y0[k] + h;
        double ep = bnd_eval(c, y, NULL), step = y[k];
        y[k] = y0[k] - h;
        double em = bnd_eval(c, y, NULL);
        step -= y[k]; /* the step actually taken, after rounding */
        worst = fmax(worst, fabs((ep - em) / step - g[k]));
    }
    return worst / scale;
}

TEST(bending_hinge_closed_forms)
{
    /* (i, j, k) = ((0,0,0), (1,0,0), (0,1,0)), n1 = +z; (j, i, l) with l below
     * the edge in the plane gives n2 = +z as well: flat, cos θ = 1. */
    double flat[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.5, -1, 0};
    bnd_ctx c = {1.0, 2.5};
    double g[12];
    CHECK_NEAR(bnd_eval(&c, flat, g), 0.0, 1e-15);
    for (int k = 0; k < 12; k++)
        CHECK_NEAR(g[k], 0.0, 1e-14);
    /* l lifted straight up: n2 = −y·(… ) ⟂ n1, cos θ = 0 -> (1 − 0)²·w */
    double right[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.5, 0, 1};
    CHECK_NEAR(bnd_eval(&c, right, NULL), 2.5, 1e-14);
    /* l folded onto k's side: cos θ = −1 -> (1 + 1)²·w */
    double folded[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.5, 1, 0};
    CHECK_NEAR(bnd_eval(&c, folded, NULL), 4.0 * 2.5, 1e-13);
    /* the reference value itself has zero energy */
    c.cos_ref = -1.0;
    CHECK_NEAR(bnd_eval(&c, folded, NULL), 0.0, 1e-15);
}

TEST(bending_gradient_matches_finite_differences)
{
    unsigned long long s = 13;
    int tested = 0;
    for (int trial = 0; trial < 300; trial++) {
        double y[12];
        for (int k = 0; k < 12; k++)
            y[k] = rnd(&s);
        if (trial % 3 == 1) /* folded: l close to k's side of the hinge */
            for (int k = 0; k < 3; k++)
                y[9 + k] = y[6 + k] + 0.05 * rnd(&s);
        if (trial % 3 == 2) /* near-degenerate second face (height 1e-3) */
            for (int k = 0; k < 3; k++)
                y[9 + k] = 0.4 * y[k] + 0.6 * y[3 + k] + 1e-3 * rnd(&s);
        bnd_ctx c = {rnd(&s), 0.5 + testmesh_rand(&s)};
        double h = trial % 3 == 2 ? 1e-9 : 1e-6;
        double err = bnd_fd_error(&c, y, h);
        if (!(err < 1e-6))
            FAILF("trial %d: relative gradient error %g", trial, err);
        tested++;
    }
    CHECK_INT(tested, 300);
}

TEST(bending_degenerate_face_gives_zero_finite_term)
{
    bnd_ctx c = {0.3, 1.0};
    double g[12];
    double coincident[12] = {0, 0, 0, 1, 0, 0, 0, 0, 0, 0.5, -1, 0.2}; /* k = i */
    CHECK_NEAR(bnd_eval(&c, coincident, g), 0.0, 0.0);
    for (int k = 0; k < 12; k++)
        CHECK_NEAR(g[k], 0.0, 0.0);
    double collinear[12] = {0, 0, 0, 1, 0, 0, 0.3, 0.5, 0.1, 2, 0, 0}; /* l on ij */
    CHECK_NEAR(bnd_eval(&c, collinear, g), 0.0, 0.0);
    double edge[12] = {1, 1, 1, 1, 1, 1, 0.3, 0.5, 0.1, 2, 0, 0};     /* i = j */
    CHECK_NEAR(bnd_eval(&c, edge, g), 0.0, 0.0);
    for (int k = 0; k < 12; k++)
        CHECK(isfinite(g[k]));
}
