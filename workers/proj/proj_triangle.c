/* proj_triangle.c — the exact closest point on one triangle in R^d, and the
 * module's error strings. Pure arithmetic in double: no allocation, no BVH.
 *
 * Ericson's Voronoi-region method ("Real-Time Collision Detection" §5.1.5)
 * uses only dot products, so it holds in any dimension: three vertex
 * regions, three edge regions, then the interior. A triangle whose Gram
 * determinant vanishes (collinear or coincident vertices) has no interior;
 * its closest point is the best of its three edges. */
#include "proj/proj.h"

#include <math.h>

/* Below this sin² of the angle at a (Gram determinant over |ab|²|ac|²) the
 * interior formula loses its digits; the edges then bound the triangle to
 * within its height, at most about 1e-7 of its size. */
#define PROJ_DEGENERATE_SIN2 1e-14

static double dot_diff(int d, const double *x, const double *o, const double *y,
                       const double *p)
{
    double s = 0;
    for (int k = 0; k < d; k++)
        s += (x[k] - o[k]) * (y[k] - p[k]);
    return s;
}

static double cost_at(int d, const double *q, const double *a, const double *b,
                      const double *c, const double w[3])
{
    double s = 0;
    for (int k = 0; k < d; k++) {
        double r = q[k] - (w[0] * a[k] + w[1] * b[k] + w[2] * c[k]);
        s += r * r;
    }
    return s;
}

/* Parameter t in [0, 1] of the closest point a + t(b − a) to q. */
static double segment_t(int d, const double *q, const double *a, const double *b)
{
    double ll = dot_diff(d, b, a, b, a);
    if (!(ll > 0))
        return 0;
    double t = dot_diff(d, q, a, b, a) / ll;
    return t < 0 ? 0 : t > 1 ? 1 : t;
}

static double best_edge(int d, const double *q, const double *a, const double *b,
                        const double *c, double bary[3])
{
    const double *v[3] = { a, b, c };
    double best = INFINITY;
    for (int e = 0; e < 3; e++) {
        int i = e, j = (e + 1) % 3;
        double t = segment_t(d, q, v[i], v[j]);
        double w[3] = { 0, 0, 0 };
        w[i] = 1 - t;
        w[j] = t;
        double cst = cost_at(d, q, a, b, c, w);
        if (cst < best) {
            best = cst;
            bary[0] = w[0], bary[1] = w[1], bary[2] = w[2];
        }
    }
    return best;
}

double proj_point_triangle(int d, const double *q, const double *a,
                           const double *b, const double *c, double bary[3])
{
    double abab = dot_diff(d, b, a, b, a), acac = dot_diff(d, c, a, c, a);
    double abac = dot_diff(d, b, a, c, a);
    double gram = abab * acac - abac * abac;
    if (!(gram > PROJ_DEGENERATE_SIN2 * abab * acac))
        return best_edge(d, q, a, b, c, bary);

    double d1 = dot_diff(d, b, a, q, a), d2 = dot_diff(d, c, a, q, a);
    if (d1 <= 0 && d2 <= 0) {                     /* vertex region a */
        bary[0] = 1, bary[1] = 0, bary[2] = 0;
        return cost_at(d, q, a, b, c, bary);
    }
    double d3 = dot_diff(d, b, a, q, b), d4 = dot_diff(d, c, a, q, b);
    if (d3 >= 0 && d4 <= d3) {                    /* vertex region b */
        bary[0] = 0, bary[1] = 1, bary[2] = 0;
        return cost_at(d, q, a, b, c, bary);
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {          /* edge region ab */
        double v = d1 / (d1 - d3);
        bary[0] = 1 - v, bary[1] = v, bary[2] = 0;
        return cost_at(d, q, a, b, c, bary);
    }
    double d5 = dot_diff(d, b, a, q, c), d6 = dot_diff(d, c, a, q, c);
    if (d6 >= 0 && d5 <= d6) {                    /* vertex region c */
        bary[0] = 0, bary[1] = 0, bary[2] = 1;
        return cost_at(d, q, a, b, c, bary);
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {          /* edge region ac */
        double w = d2 / (d2 - d6);
        bary[0] = 1 - w, bary[1] = 0, bary[2] = w;
        return cost_at(d, q, a, b, c, bary);
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) { /* edge region bc */
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        bary[0] = 0, bary[1] = 1 - w, bary[2] = w;
        return cost_at(d, q, a, b, c, bary);
    }
    /* Interior: va + vb + vc is the Gram determinant, positive here; each
     * is positive too, but rounding may leave one a hair below zero. */
    va = va > 0 ? va : 0, vb = vb > 0 ? vb : 0, vc = vc > 0 ? vc : 0;
    double den = va + vb + vc;
    bary[1] = vb / den;
    bary[2] = vc / den;
    bary[0] = va / den;
    return cost_at(d, q, a, b, c, bary);
}
