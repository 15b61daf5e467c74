/* test_proj.c — exact projection: the point-triangle kernel in every Voronoi
 * region (d = 3, 6, 16) against analytic answers and a minimisation over the
 * triangle, degenerate triangles, argument refusals, and the BVH query
 * against brute force on every row of the real pair SHREC'07 381 → 390
 * (every third row in d = 16). */
#include "support/harness.h"
#include "support/testmesh.h"
#include "proj/proj.h"
#include "map/bmap.h"

#include <stdlib.h>
#include <string.h>

#define DMAX 16

static unsigned long long rng = 0x9e3779b97f4a7c15ULL;
static double urand(void) { return testmesh_rand(&rng); }
static double srand1(void) { return 2 * urand() - 1; }

static double dot(int d, const double *x, const double *y)
{
    double s = 0;
    for (int k = 0; k < d; k++)
        s += x[k] * y[k];
    return s;
}

static double cost_of(int d, const double *q, const double *a, const double *b,
                      const double *c, const double w[3])
{
    double s = 0;
    for (int k = 0; k < d; k++) {
        double r = q[k] - (w[0] * a[k] + w[1] * b[k] + w[2] * c[k]);
        s += r * r;
    }
    return s;
}

/* Euclidean projection of w onto the probability simplex (sort of 3). */
static void simplex_project(double w[3])
{
    double u[3] = { w[0], w[1], w[2] };
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (u[j] > u[i]) { double x = u[i]; u[i] = u[j]; u[j] = x; }
    double cum = 0, theta = 0;
    for (int i = 0; i < 3; i++) {
        cum += u[i];
        double th = (cum - 1) / (i + 1);
        if (u[i] - th > 0)
            theta = th;
    }
    for (int i = 0; i < 3; i++)
        w[i] = w[i] - theta > 0 ? w[i] - theta : 0;
}

/* Reference: best point of a fine barycentric grid, then projected-gradient
 * descent on the simplex. Knows nothing of Voronoi regions. */
static double reference_min(int d, const double *q, const double *a, const double *b,
                            const double *c, double wbest[3])
{
    const int N = 120;
    double best = INFINITY;
    for (int i = 0; i <= N; i++)
        for (int j = 0; i + j <= N; j++) {
            double w[3] = { (double)i / N, (double)j / N, (double)(N - i - j) / N };
            double cs = cost_of(d, q, a, b, c, w);
            if (cs < best) { best = cs; memcpy(wbest, w, sizeof w); }
        }
    double L = 2 * (dot(d, a, a) + dot(d, b, b) + dot(d, c, c)) + 1e-300;
    const double *v[3] = { a, b, c };
    for (int it = 0; it < 20000; it++) {
        double r[DMAX], g[3], w[3];
        for (int k = 0; k < d; k++)
            r[k] = q[k] - (wbest[0] * a[k] + wbest[1] * b[k] + wbest[2] * c[k]);
        for (int m = 0; m < 3; m++) {
            g[m] = -2 * dot(d, v[m], r);
            w[m] = wbest[m] - g[m] / L;
        }
        simplex_project(w);
        double cs = cost_of(d, q, a, b, c, w);
        if (!(cs < best))
            break;
        best = cs;
        memcpy(wbest, w, sizeof w);
    }
    return best;
}

/* Checks the kernel's invariants and that its cost is not beaten by the
 * reference minimisation, and that the reference lands on the same cost. */
static void check_kernel(int d, const double *q, const double *a, const double *b,
                         const double *c, double w[3])
{
    double cs = proj_point_triangle(d, q, a, b, c, w);
    for (int m = 0; m < 3; m++)
        CHECK(w[m] >= 0);
    CHECK_NEAR(w[0] + w[1] + w[2], 1, 1e-14);
    double direct = cost_of(d, q, a, b, c, w);
    CHECK_NEAR(cs, direct, 1e-14 * (1 + direct));
    double wr[3] = { 1, 0, 0 };
    double ref = reference_min(d, q, a, b, c, wr);
    double scale = 1 + dot(d, q, q) + dot(d, a, a) + dot(d, b, b) + dot(d, c, c);
    CHECK(cs <= ref + 1e-13 * scale);
    CHECK(ref - cs <= 1e-8 * scale);
}

/* A random triangle in R^d with its in-plane geometry for region points. */
typedef struct tri { double a[DMAX], b[DMAX], c[DMAX]; } tri;

static void random_tri(int d, tri *t)
{
    for (int k = 0; k < d; k++) {
        t->a[k] = srand1();
        t->b[k] = srand1();
        t->c[k] = srand1();
    }
}

/* A random vector orthogonal to the triangle's plane, of length len. */
static void normal_offset(int d, const tri *t, double len, double *out)
{
    double e1[DMAX], e2[DMAX];
    for (int k = 0; k < d; k++) {
        e1[k] = t->b[k] - t->a[k];
        e2[k] = t->c[k] - t->a[k];
    }
    double n1 = sqrt(dot(d, e1, e1));
    for (int k = 0; k < d; k++)
        e1[k] /= n1;
    double p = dot(d, e2, e1);
    for (int k = 0; k < d; k++)
        e2[k] -= p * e1[k];
    double n2 = sqrt(dot(d, e2, e2));
    for (int k = 0; k < d; k++)
        e2[k] /= n2;
    for (int k = 0; k < d; k++)
        out[k] = srand1();
    double p1 = dot(d, out, e1), p2 = dot(d, out, e2);
    for (int k = 0; k < d; k++)
        out[k] -= p1 * e1[k] + p2 * e2[k];
    double nn = sqrt(dot(d, out, out));
    for (int k = 0; k < d; k++)
        out[k] *= d > 2 && nn > 0 ? len / nn : 0;
}

static void unit(int d, const double *from, const double *to, double *u)
{
    for (int k = 0; k < d; k++)
        u[k] = to[k] - from[k];
    double n = sqrt(dot(d, u, u));
    for (int k = 0; k < d; k++)
        u[k] /= n;
}

/* For each of the 7 regions, builds a point whose closest point has known
 * weights, in the plane (off = 0) and off it, and checks the kernel. */
static void check_all_regions(int d)
{
    for (int trial = 0; trial < 30; trial++) {
        tri t;
        random_tri(d, &t);
        const double *v[3] = { t.a, t.b, t.c };
        for (int off = 0; off < 2; off++) {
            double nrm[DMAX];
            normal_offset(d, &t, off ? 0.2 + urand() : 0, nrm);
            for (int m = 0; m < 3; m++) {       /* vertex regions a, b, c */
                const double *p = v[m], *o1 = v[(m + 1) % 3], *o2 = v[(m + 2) % 3];
                double u1[DMAX], u2[DMAX], q[DMAX], w[3];
                unit(d, p, o1, u1);
                unit(d, p, o2, u2);
                double h = 0.05 + urand();
                for (int k = 0; k < d; k++)
                    q[k] = p[k] - h * (u1[k] + u2[k]) + nrm[k];
                check_kernel(d, q, t.a, t.b, t.c, w);
                CHECK_NEAR(w[m], 1, 1e-12);
            }
            for (int m = 0; m < 3; m++) {       /* edge regions ab, bc, ca */
                const double *p = v[m], *r = v[(m + 1) % 3], *o = v[(m + 2) % 3];
                double e[DMAX], out[DMAX], q[DMAX], w[3];
                unit(d, p, r, e);
                for (int k = 0; k < d; k++)
                    out[k] = p[k] - o[k];
                double pe = dot(d, out, e);
                for (int k = 0; k < d; k++)
                    out[k] -= pe * e[k];
                double no = sqrt(dot(d, out, out));
                double s = 0.1 + 0.8 * urand(), h = 0.05 + urand();
                for (int k = 0; k < d; k++)
                    q[k] = (1 - s) * p[k] + s * r[k] + h * out[k] / no + nrm[k];
                check_kernel(d, q, t.a, t.b, t.c, w);
                CHECK_NEAR(w[m], 1 - s, 1e-9);
                CHECK_NEAR(w[(m + 1) % 3], s, 1e-9);
                CHECK(w[(m + 2) % 3] == 0);
            }
            double x = 0.05 + urand(), y = 0.05 + urand(), z = 0.05 + urand();
            double ws[3] = { x / (x + y + z), y / (x + y + z), z / (x + y + z) };
            double q[DMAX], w[3];                /* interior */
            for (int k = 0; k < d; k++)
                q[k] = ws[0] * t.a[k] + ws[1] * t.b[k] + ws[2] * t.c[k] + nrm[k];
            double cs = proj_point_triangle(d, q, t.a, t.b, t.c, w);
            check_kernel(d, q, t.a, t.b, t.c, w);
            for (int m = 0; m < 3; m++)
                CHECK_NEAR(w[m], ws[m], 1e-9);
            CHECK_NEAR(cs, dot(d, nrm, nrm), 1e-12);
        }
        for (int r = 0; r < 20; r++) {           /* anywhere, against the reference */
            double q[DMAX], w[3];
            for (int k = 0; k < d; k++)
                q[k] = 3 * srand1();
            check_kernel(d, q, t.a, t.b, t.c, w);
        }
    }
}

TEST(triangle_every_region_d3) { check_all_regions(3); }
TEST(triangle_every_region_d6) { check_all_regions(6); }
TEST(triangle_every_region_d16) { check_all_regions(16); }

/* Closest point on segment [a, b] (a = b allowed), by its own formula. */
static double segment_cost(int d, const double *q, const double *a, const double *b)
{
    double ab[DMAX], aq[DMAX];
    for (int k = 0; k < d; k++) {
        ab[k] = b[k] - a[k];
        aq[k] = q[k] - a[k];
    }
    double ll = dot(d, ab, ab), t = ll > 0 ? dot(d, aq, ab) / ll : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double s = 0;
    for (int k = 0; k < d; k++) {
        double r = aq[k] - t * ab[k];
        s += r * r;
    }
    return s;
}

TEST(triangle_degenerate_collinear_and_coincident)
{
    int dims[3] = { 3, 6, 16 };
    for (int di = 0; di < 3; di++) {
        int d = dims[di];
        for (int trial = 0; trial < 50; trial++) {
            double a[DMAX], u[DMAX], b[DMAX], c[DMAX], q[DMAX], w[3];
            for (int k = 0; k < d; k++) {
                a[k] = srand1();
                u[k] = srand1();
                q[k] = 2 * srand1();
            }
            /* collinear, c beyond b: the triangle is the segment [a, c] */
            for (int k = 0; k < d; k++) {
                b[k] = a[k] + u[k];
                c[k] = a[k] + 2.5 * u[k];
            }
            double cs = proj_point_triangle(d, q, a, b, c, w);
            CHECK_NEAR(cs, segment_cost(d, q, a, c), 1e-12);
            check_kernel(d, q, a, b, c, w);
            /* collinear, b in the middle listed last */
            cs = proj_point_triangle(d, q, a, c, b, w);
            CHECK_NEAR(cs, segment_cost(d, q, a, c), 1e-12);
            check_kernel(d, q, a, c, b, w);
            /* two coincident: the segment [a, c] */
            cs = proj_point_triangle(d, q, a, a, c, w);
            CHECK_NEAR(cs, segment_cost(d, q, a, c), 1e-12);
            check_kernel(d, q, a, a, c, w);
            cs = proj_point_triangle(d, q, c, a, c, w);
            CHECK_NEAR(cs, segment_cost(d, q, a, c), 1e-12);
            check_kernel(d, q, c, a, c, w);
            /* all coincident: a point */
            cs = proj_point_triangle(d, q, a, a, a, w);
            CHECK_NEAR(cs, segment_cost(d, q, a, a), 1e-12);
            check_kernel(d, q, a, a, a, w);
        }
    }
}

/* ---- the BVH query on the real pair ---- */

static mesh *load_unit_area(const char *rel)
{
    mesh *m = testmesh_read(rel);
    double area = 0;
    for (int t = 0; t < m->nf; t++) {
        const double *a = m->v + 3 * m->f[3 * t], *b = m->v + 3 * m->f[3 * t + 1],
                     *c = m->v + 3 * m->f[3 * t + 2];
        double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
        double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
        double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2],
               z = u[0] * v[1] - u[1] * v[0];
        area += 0.5 * sqrt(x * x + y * y + z * z);
    }
    double k = 1 / sqrt(area);
    for (int i = 0; i < 3 * m->nv; i++)
        m->v[i] *= k;
    return m;
}

/* Every row: the same face or the same cost (tolerance max(1e-12 c, 1e-15)),
 * a valid face, weights on the simplex and the cost they imply. */
static void check_same(const mesh *tg, int d, const double *Z, int n, const double *Q,
                       const int *fb, const double *cb, const int *f, const double *w,
                       const double *c)
{
    for (int i = 0; i < n; i++) {
        CHECK(f[i] >= 0 && f[i] < tg->nf);
        double tol = fmax(1e-12 * cb[i], 1e-15);
        if (f[i] != fb[i] && !(fabs(c[i] - cb[i]) <= tol))
            FAILF("row %d: face %d cost %.17g, brute face %d cost %.17g", i, f[i], c[i],
                  fb[i], cb[i]);
        const double *wi = w + 3 * i;
        CHECK(wi[0] >= 0 && wi[1] >= 0 && wi[2] >= 0);
        CHECK_NEAR(wi[0] + wi[1] + wi[2], 1, 1e-14);
        const int *v = tg->f + 3 * f[i];
        double direct = cost_of(d, Q + (size_t)d * i, Z + (size_t)d * v[0],
                                Z + (size_t)d * v[1], Z + (size_t)d * v[2], wi);
        CHECK_NEAR(c[i], direct, 1e-12 * (1 + direct));
    }
}

/* ECTM embedding as at the first outer iteration: Z = [√β·X̃ | √γ·Ỹ] with
 * Ỹ = Q·X + noise, queries Q = [√β·y_i | √γ·x_i] with y_i = (P·X̃)_i +
 * noise, P and Q the demo's HOT maps, x_i the source vertex. */
static void ectm_embed(const mesh *src, const mesh *tg, const double *PXt, const double *QX,
                       double beta, double gamma, double noise, unsigned long long seed,
                       double *Z, double *Q)
{
    unsigned long long st = seed;
    double sb = sqrt(beta), sg = sqrt(gamma);
    for (int j = 0; j < tg->nv; j++)
        for (int k = 0; k < 3; k++) {
            Z[6 * j + k] = sb * tg->v[3 * j + k];
            Z[6 * j + 3 + k] = sg * (QX[3 * j + k] + 0.02 * (2 * testmesh_rand(&st) - 1));
        }
    for (int i = 0; i < src->nv; i++)
        for (int k = 0; k < 3; k++) {
            Q[6 * i + k] = sb * (PXt[3 * i + k] + noise * (2 * testmesh_rand(&st) - 1));
            Q[6 * i + 3 + k] = sg * src->v[3 * i + k];
        }
}

static bmap *load_map(const char *rel, const mesh *s, const mesh *t)
{
    char err[512];
    bmap *P = NULL;
    if (bmap_read(harness_data_path(rel), s, t, &P, err, sizeof err) != 0)
        FAILF("%s", err);
    return P;
}

static void run_ectm_case(double beta, double gamma)
{
    mesh *src = load_unit_area("shrec07_bim/Meshes/381.off");
    mesh *tg = load_unit_area("shrec07_bim/Meshes/390.off");
    CHECK_INT(src->nv, 6938);
    CHECK_INT(tg->nv, 9239);
    char err[512];
    proj_tree *tree = proj_tree_new(tg, err, sizeof err);
    if (!tree)
        FAILF("%s", err);
    int n = src->nv, d = 6;
    double *Z = malloc(sizeof(double) * d * tg->nv), *Q = malloc(sizeof(double) * d * n);
    double *Qp = malloc(sizeof(double) * d * n);
    int *fb = malloc(sizeof(int) * n), *f = malloc(sizeof(int) * n), *fp = malloc(sizeof(int) * n);
    double *wb = malloc(sizeof(double) * 3 * n), *w = malloc(sizeof(double) * 3 * n);
    double *cb = malloc(sizeof(double) * n), *c = malloc(sizeof(double) * n);
    double *Zp = malloc(sizeof(double) * d * tg->nv);
    double *PXt = malloc(sizeof(double) * 3 * n), *QX = malloc(sizeof(double) * 3 * tg->nv);
    bmap *P = load_map("ectm_demo_381_390/init_381_to_390.map", src, tg);
    bmap *Qm = load_map("ectm_demo_381_390/init_390_to_381.map", tg, src);
    bmap_apply(P, tg->f, tg->v, 3, PXt);
    bmap_apply(Qm, src->f, src->v, 3, QX);

    ectm_embed(src, tg, PXt, QX, beta, gamma, 0.01, 1, Z, Q);
    proj_closest_brute(tg, d, Z, n, Q, fb, wb, cb);

    for (int i = 0; i < n; i++)
        f[i] = -1;
    CHECK_INT(proj_closest(tree, d, Z, sqrt(beta), n, Q, f, w, c), 0);
    check_same(tg, d, Z, n, Q, fb, cb, f, w, c);

    /* Seeded with the previous iteration's answer: the query's assignment
     * for other noise (as from one ECTM iteration to the next). The seed
     * is only an upper bound, so any face must do: random ones too. */
    ectm_embed(src, tg, PXt, QX, beta, gamma, 0.012, 2, Zp, Qp);
    double *wp = malloc(sizeof(double) * 3 * n);
    for (int i = 0; i < n; i++)
        fp[i] = -1;
    CHECK_INT(proj_closest(tree, d, Zp, sqrt(beta), n, Qp, fp, wp, NULL), 0);
    int moved = 0;
    for (int i = 0; i < n; i++)
        moved += fp[i] != fb[i];
    CHECK(moved > 0);
    memcpy(f, fp, sizeof(int) * n);
    CHECK_INT(proj_closest(tree, d, Z, sqrt(beta), n, Q, f, w, c), 0);
    check_same(tg, d, Z, n, Q, fb, cb, f, w, c);
    unsigned long long st = 7;
    for (int i = 0; i < n; i++)
        f[i] = (int)(testmesh_rand(&st) * tg->nf);
    CHECK_INT(proj_closest(tree, d, Z, sqrt(beta), n, Q, f, w, c), 0);
    check_same(tg, d, Z, n, Q, fb, cb, f, w, c);

    free(wp), free(PXt), free(QX);
    bmap_free(P), bmap_free(Qm);
    free(Z), free(Q), free(Qp), free(Zp), free(fb), free(f), free(fp);
    free(wb), free(w), free(cb), free(c);
    proj_tree_free(tree);
    mesh_free(src);
    mesh_free(tg);
}

TEST(closest_matches_brute_381_390_beta1e3_gamma1e4) { run_ectm_case(1e3, 1e4); }
TEST(closest_matches_brute_381_390_beta1e5_gamma1e4) { run_ectm_case(1e5, 1e4); }
TEST(closest_matches_brute_381_390_beta500_gamma0) { run_ectm_case(500, 0); }

/* The R^d search against the brute force on 381 -> 390 at unit area:
 * columns 0..2 s·X, the rest smooth functions of X (RHM-like embeddings),
 * the queries' noisy; unseeded, seeded with any face, and rotated. */
static void hd_matches_brute(int d)
{
    mesh *src = load_unit_area("shrec07_bim/Meshes/381.off");
    mesh *tg = load_unit_area("shrec07_bim/Meshes/390.off");
    char err[512];
    proj_tree *tree = proj_tree_new(tg, err, sizeof err);
    if (!tree)
        FAILF("%s", err);
    double s = 2.0, a[13][3], ph[13];
    for (int m = 0; m < 13; m++) {
        for (int k = 0; k < 3; k++)
            a[m][k] = 4 * srand1();
        ph[m] = 6 * urand();
    }
    /* every third source vertex keeps the brute force at a few seconds */
    int n = (src->nv + 2) / 3;
    double *Z = malloc(sizeof(double) * d * tg->nv), *Q = malloc(sizeof(double) * d * n);
    for (int pass = 0; pass < 2; pass++) {
        const mesh *m = pass ? src : tg;
        double *out = pass ? Q : Z;
        for (int i = 0; i < (pass ? n : m->nv); i++) {
            const double *x = m->v + 3 * (pass ? 3 * i : i);
            for (int k = 0; k < 3; k++)
                out[d * i + k] = s * x[k];
            for (int j = 0; j < d - 3; j++)
                out[d * i + 3 + j] = sin(a[j][0] * x[0] + a[j][1] * x[1] + a[j][2] * x[2] + ph[j]) +
                                     (pass ? 0.05 * srand1() : 0);
        }
    }
    int *fb = malloc(sizeof(int) * n), *f = malloc(sizeof(int) * n);
    double *wb = malloc(sizeof(double) * 3 * n), *w = malloc(sizeof(double) * 3 * n);
    double *cb = malloc(sizeof(double) * n), *c = malloc(sizeof(double) * n);
    proj_closest_brute(tg, d, Z, n, Q, fb, wb, cb);
    for (int i = 0; i < n; i++)
        f[i] = -1;
    CHECK_INT(proj_closest(tree, d, Z, s, n, Q, f, w, c), 0);
    check_same(tg, d, Z, n, Q, fb, cb, f, w, c);
    /* seeded with any face: the seed only bounds the search */
    unsigned long long st = 11;
    for (int i = 0; i < n; i++)
        f[i] = (int)(testmesh_rand(&st) * tg->nf);
    CHECK_INT(proj_closest(tree, d, Z, s, n, Q, f, w, c), 0);
    check_same(tg, d, Z, n, Q, fb, cb, f, w, c);
    /* from PROJ_HD_MIN_DIM on the search runs in R^d: the first three
     * columns need not be s·X̃ (here a rotation of every column pair, the
     * distances unchanged, so the brute force's costs still hold) */
    double *Zr = malloc(sizeof(double) * d * tg->nv), *Qr = malloc(sizeof(double) * d * n);
    for (int pass = 0; pass < 2; pass++) {
        const double *in = pass ? Q : Z;
        double *out = pass ? Qr : Zr;
        for (int i = 0; i < (pass ? n : tg->nv); i++) {
            if (d % 2)
                out[d * i + d - 1] = in[d * i + d - 1];
            for (int k = 0; k + 1 < d; k += 2) {   /* 45 degrees in each plane (k, k + 1) */
                double x = in[d * i + k], y = in[d * i + k + 1];
                out[d * i + k] = (x - y) / sqrt(2.0);
                out[d * i + k + 1] = (x + y) / sqrt(2.0);
            }
        }
    }
    for (int i = 0; i < n; i++)
        f[i] = -1;
    CHECK_INT(proj_closest(tree, d, Zr, s, n, Qr, f, w, c), 0);
    check_same(tg, d, Zr, n, Qr, fb, cb, f, w, c);
    free(Zr), free(Qr);
    free(Z), free(Q), free(fb), free(f), free(wb), free(w), free(cb), free(c);
    proj_tree_free(tree);
    mesh_free(src);
    mesh_free(tg);
}

TEST(closest_matches_brute_381_390_d16_rhm_like)
{
    hd_matches_brute(16);
}

/* a dimension the box bound's steps of eight do not divide (the distances
 * start's R^{2l} is one) */
TEST(closest_matches_brute_381_390_d11)
{
    hd_matches_brute(11);
}

TEST(closest_refuses_bad_dimension_scale_and_seed)
{
    mesh *m = testmesh_icosphere(1);
    char err[256];
    proj_tree *tree = proj_tree_new(m, err, sizeof err);
    CHECK(tree);
    double Z[3 * 42], Q[3] = { 0.1, 0.2, 2 }, w[3] = { -7, -7, -7 }, c = -7;
    memcpy(Z, m->v, sizeof(double) * 3 * m->nv);
    int f = -1;
    CHECK_INT(proj_closest(tree, 2, Z, 1, 1, Q, &f, w, &c), PROJ_EINVAL);
    CHECK_INT(proj_closest(tree, 3, Z, 0, 1, Q, &f, w, &c), PROJ_EINVAL);
    CHECK_INT(proj_closest(tree, 3, Z, -1, 1, Q, &f, w, &c), PROJ_EINVAL);
    f = m->nf;
    CHECK_INT(proj_closest(tree, 3, Z, 1, 1, Q, &f, w, &c), PROJ_EFACE);
    CHECK(w[0] == -7 && c == -7);   /* nothing written on error */
    f = -1;
    CHECK_INT(proj_closest(tree, 3, Z, 1, 1, Q, &f, w, &c), 0);
    CHECK(f >= 0 && f < m->nf);
    proj_tree_free(tree);
    proj_tree_free(NULL);
    mesh_free(m);
}

TEST(tree_refuses_bad_target_naming_it)
{
    mesh *m = testmesh_icosphere(0);
    char err[256];
    m->f[5] = m->nv;
    CHECK(proj_tree_new(m, err, sizeof err) == NULL);
    CHECK_STR_HAS(err, "face 1");
    m->f[5] = 0;
    m->v[7] = NAN;
    CHECK(proj_tree_new(m, err, sizeof err) == NULL);
    CHECK_STR_HAS(err, "vertex 2");
    mesh_free(m);
}

/* A 3-D-degenerate face (collinear in X̃) that is the unique winner
 * because its extra coordinates lift it towards the query; in d = 4 (the
 * 3-D tree) and d = 8 (the R^d hierarchy), the columns past the 4th 0. */
static void degenerate_case(int d)
{
    mesh *m = mesh_new(5, 2);
    double v[15] = { 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 1 };
    int fc[6] = { 0, 1, 2, 0, 3, 4 };
    memcpy(m->v, v, sizeof v);
    memcpy(m->f, fc, sizeof fc);
    char err[256];
    proj_tree *tree = proj_tree_new(m, err, sizeof err);
    CHECK(tree);
    double Z[5 * 8] = { 0 }, Q[8] = { 1, 0.3, 0, 5 };
    for (int j = 0; j < 5; j++)
        for (int k = 0; k < 3; k++)
            Z[d * j + k] = v[3 * j + k];
    Z[d * 1 + 3] = 5;                 /* lifts vertex 1 in the 4th column */
    int f = -1, fb;
    double w[3], wb[3], c, cb;
    CHECK_INT(proj_closest(tree, d, Z, 1, 1, Q, &f, w, &c), 0);
    proj_closest_brute(m, d, Z, 1, Q, &fb, wb, &cb);
    CHECK_INT(fb, 0);
    CHECK_INT(f, 0);
    CHECK_NEAR(c, 0.09, 1e-15);
    CHECK_NEAR(w[1], 1, 1e-15);
    CHECK_NEAR(c, cb, 1e-15);
    proj_tree_free(tree);
    mesh_free(m);
}

TEST(closest_handles_degenerate_target_faces)
{
    degenerate_case(4);
    degenerate_case(PROJ_HD_MIN_DIM);
}
