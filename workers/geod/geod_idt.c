/* geod_idt.c — the intrinsic Delaunay triangulation by edge flips (see
 * geod__idt.h): the half-edge twins from the mesh's edge table, the flip
 * loop and the triangle formulas on edge lengths. Builds no operator. */
#include "geod/geod__idt.h"
#include "geod/geod.h"
#include "geo/geo_tri.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* An edge is flipped when the cotangents of its two opposite angles sum
 * below -GEOD__FLIP_EPS (angles summing over pi by more than round-off). */
#define GEOD__FLIP_EPS 1e-12
/* At most this many flips per face: the loop provably ends (each flip
 * lowers the Dirichlet energy of the position functions), the cap only
 * guards against round-off ping-pong between near-cocircular quads. */
#define GEOD__MAX_FLIPS_PER_FACE 50

double geod__double_area(double a, double b, double c)
{
    double t;
    if (a < b) { t = a; a = b; b = t; }
    if (b < c) { t = b; b = c; c = t; }
    if (a < b) { t = a; a = b; b = t; }
    double p = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
    return p > 0 ? 0.5 * sqrt(p) : 0;
}

/* geo_tri.h's degeneracy rule in lengths: |e1 x e2| against |e1|^2 + |e2|^2. */
static int degenerate(double a, double b, double c)
{
    return !(geod__double_area(a, b, c) > GEO__DEGENERATE_REL * (b * b + c * c));
}

double geod__cot(double a, double b, double c)
{
    if (degenerate(a, b, c))
        return 0;
    return (b * b + c * c - a * a) / (2 * geod__double_area(a, b, c));
}

void geod__idt_close(geod__idt *t)
{
    if (!t)
        return;
    free(t->f);
    free(t->len);
    free(t->twin);
    memset(t, 0, sizeof *t);
}

static double cot_at(const geod__idt *T, int h)
{
    int t = h / 3, k = h % 3;
    return geod__cot(T->len[h], T->len[3 * t + (k + 1) % 3], T->len[3 * t + (k + 2) % 3]);
}

static int face_degenerate(const geod__idt *T, int t)
{
    return degenerate(T->len[3 * t], T->len[3 * t + 1], T->len[3 * t + 2]);
}

/* Flips the edge of half-edge h = 3t+k (twin 3o+k'). Before: t = (a, b, c)
 * with the edge bc opposite a, o = (d, c, b). After: t = (a, b, d),
 * o = (a, d, c), the new edge ad laid out across bc. Returns 0 when the
 * flip is not made (see the header). */
static int flip(geod__idt *T, int h)
{
    int g = T->twin[h], t = h / 3, o = g / 3, k = h % 3, j = g % 3;
    if (t == o)
        return 0;
    int k1 = 3 * t + (k + 1) % 3, k2 = 3 * t + (k + 2) % 3;
    int j1 = 3 * o + (j + 1) % 3, j2 = 3 * o + (j + 2) % 3;
    int a = T->f[h], b = T->f[k1], c = T->f[k2], d = T->f[g];
    if (a == d || T->f[j1] != c || T->f[j2] != b)
        return 0;
    int tw_ca = T->twin[k1], tw_ab = T->twin[k2], tw_bd = T->twin[j1], tw_dc = T->twin[j2];
    int outer[4] = {tw_ca, tw_ab, tw_bd, tw_dc};
    for (int q = 0; q < 4; q++)
        if (outer[q] >= 0 && (outer[q] / 3 == t || outer[q] / 3 == o))
            return 0;
    double L = T->len[h], lca = T->len[k1], lab = T->len[k2];
    double lbd = T->len[j1], ldc = T->len[j2];
    /* b at the origin, c at (L, 0), a above, d below */
    double xa = (lab * lab - lca * lca + L * L) / (2 * L);
    double xd = (lbd * lbd - ldc * ldc + L * L) / (2 * L);
    double ya = sqrt(fmax(0, lab * lab - xa * xa)), yd = -sqrt(fmax(0, lbd * lbd - xd * xd));
    double lad = hypot(xa - xd, ya - yd);
    if (!(lad > 0) || !isfinite(lad))
        return 0;
    int *ft = T->f + 3 * t, *fo = T->f + 3 * o;
    double *lt = T->len + 3 * t, *lo = T->len + 3 * o;
    int *wt = T->twin + 3 * t, *wo = T->twin + 3 * o;
    ft[0] = a, ft[1] = b, ft[2] = d;
    lt[0] = lbd, lt[1] = lad, lt[2] = lab;
    wt[0] = tw_bd, wt[1] = 3 * o + 2, wt[2] = tw_ab;
    fo[0] = a, fo[1] = d, fo[2] = c;
    lo[0] = ldc, lo[1] = lca, lo[2] = lad;
    wo[0] = tw_dc, wo[1] = tw_ca, wo[2] = 3 * t + 1;
    if (tw_bd >= 0) T->twin[tw_bd] = 3 * t;
    if (tw_ab >= 0) T->twin[tw_ab] = 3 * t + 2;
    if (tw_dc >= 0) T->twin[tw_dc] = 3 * o;
    if (tw_ca >= 0) T->twin[tw_ca] = 3 * o + 1;
    return 1;
}

int geod__idt_build(const mesh *m, const geo_edges *e, geod__idt *out)
{
    memset(out, 0, sizeof *out);
    size_t nh = 3 * (size_t)m->nf;
    int *stack = malloc(nh * sizeof *stack);
    char *queued = calloc(nh, 1);
    out->nf = m->nf;
    out->f = malloc(nh * sizeof *out->f);
    out->len = malloc(nh * sizeof *out->len);
    out->twin = malloc(nh * sizeof *out->twin);
    if (!stack || !queued || !out->f || !out->len || !out->twin) {
        free(stack);
        free(queued);
        geod__idt_close(out);
        return GEOD_ENOMEM;
    }
    memcpy(out->f, m->f, nh * sizeof *out->f);
    for (int t = 0; t < m->nf; t++)
        for (int k = 0; k < 3; k++) {
            const double *p = m->v + 3 * (size_t)m->f[3 * t + (k + 1) % 3];
            const double *q = m->v + 3 * (size_t)m->f[3 * t + (k + 2) % 3];
            double v[3];
            geo__sub(p, q, v);
            out->len[3 * t + k] = sqrt(geo__dot(v, v));
            int ed = e->fe[3 * t + k], o = e->ef[2 * ed] == t ? e->ef[2 * ed + 1] : e->ef[2 * ed];
            out->twin[3 * t + k] = -1;
            for (int j = 0; o >= 0 && j < 3; j++)
                if (e->fe[3 * o + j] == ed)
                    out->twin[3 * t + k] = 3 * o + j;
        }
    size_t top = 0;
    for (size_t h = 0; h < nh; h++)
        if (out->twin[h] > (int)h) {
            stack[top++] = (int)h;
            queued[h] = 1;
        }
    long cap = (long)GEOD__MAX_FLIPS_PER_FACE * m->nf;
    while (top > 0 && out->flips < cap) {
        int h = stack[--top];
        queued[h] = 0;
        int g = out->twin[h];
        if (g < 0 || face_degenerate(out, h / 3) || face_degenerate(out, g / 3))
            continue;
        if (!(cot_at(out, h) + cot_at(out, g) < -GEOD__FLIP_EPS) || !flip(out, h))
            continue;
        out->flips++;
        int t = h / 3, o = g / 3;
        int next[4] = {3 * t, 3 * t + 2, 3 * o, 3 * o + 1};
        for (int q = 0; q < 4; q++) {
            int x = next[q];
            if (out->twin[x] >= 0 && !queued[x] && !queued[out->twin[x]]) {
                queued[x] = 1;
                stack[top++] = x;
            }
        }
    }
    free(stack);
    free(queued);
    return 0;
}
