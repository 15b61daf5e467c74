/* proj_hd.c — the box hierarchy of proj__hd.h: patches split top-down by
 * medians of the faces' 3-D box centres along their widest coordinate,
 * boxes in R^d fitted bottom-up per call, queried depth-first nearer child
 * first with the boxes' squared distance as the lower bound (exact: a
 * face's closest point lies in its box, and a node's box holds its
 * faces'). */
#include "proj/proj.h"
#include "proj/proj__hd.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define HD_LEAF  16    /* faces per leaf at most */
#define HD_STACK 128  /* the depth is at most log2(nf) + 1 <= 32: two entries a level */
#define HD_STEP  8    /* box_bound tests its partial sum every HD_STEP coordinates */

typedef struct hd_span { int node, lo, hi; } hd_span;          /* a build step */
typedef struct hd_visit { int node; double bound; } hd_visit;  /* a query step */

/* Nodes in preorder (a node's children follow it, the second after the
 * first); the boxes proj__hd_fit writes: nf face boxes in tree order, then
 * nnode node boxes, each the low corner then the high one. */
struct proj__hd {
    int nf, nnode;
    const int *f;     /* nf by 3, the caller's */
    int *order;       /* nf: the faces in tree order */
    int *kid;         /* nnode: first child, -1: a leaf */
    int *first, *count; /* nnode: the node's slice of order */
};

void proj__hd_free(proj__hd *h)
{
    if (!h)
        return;
    free(h->order);
    free(h->kid);
    free(h->first);
    free(h->count);
    free(h);
}

/* Reorders ord[lo..hi) with its keys so that position mid holds the key of
 * rank mid - lo, smaller ones before it, larger after (Hoare's selection,
 * middle pivot: deterministic). */
static void select_median(double *key, int *ord, int lo, int hi, int mid)
{
    hi--;
    while (lo < hi) {
        double p = key[lo + (hi - lo) / 2];
        int i = lo, j = hi;
        while (i <= j) {
            while (key[i] < p)
                i++;
            while (key[j] > p)
                j--;
            if (i <= j) {
                double tk = key[i];
                key[i] = key[j], key[j] = tk;
                int to = ord[i];
                ord[i] = ord[j], ord[j] = to;
                i++, j--;
            }
        }
        if (mid <= j)
            hi = j;
        else if (mid >= i)
            lo = i;
        else
            return;
    }
}

proj__hd *proj__hd_new(const double *V, const int *f, int nf)
{
    proj__hd *h = calloc(1, sizeof *h);
    size_t n1 = (size_t)(nf > 0 ? nf : 1), maxnode = 2 * n1;
    double *cen = malloc(sizeof(double) * 3 * n1), *key = malloc(sizeof(double) * n1);
    if (h) {
        h->nf = nf, h->f = f;
        h->order = malloc(sizeof(int) * n1);
        h->kid = malloc(sizeof(int) * maxnode);
        h->first = malloc(sizeof(int) * maxnode);
        h->count = malloc(sizeof(int) * maxnode);
    }
    if (!h || !cen || !key || !h->order || !h->kid || !h->first || !h->count) {
        free(cen);
        free(key);
        proj__hd_free(h);
        return NULL;
    }
    for (int t = 0; t < nf; t++) {   /* twice the box centre: the order is all that matters */
        h->order[t] = t;
        const int *v = f + 3 * (size_t)t;
        for (int k = 0; k < 3; k++) {
            double a = V[3 * v[0] + k], b = V[3 * v[1] + k], c = V[3 * v[2] + k];
            cen[3 * (size_t)t + k] = fmin(a, fmin(b, c)) + fmax(a, fmax(b, c));
        }
    }
    hd_span stack[HD_STACK];
    int top = 0;
    h->nnode = 1;
    stack[top++] = (hd_span){ 0, 0, nf };
    while (top > 0) {
        hd_span s = stack[--top];
        h->first[s.node] = s.lo, h->count[s.node] = s.hi - s.lo, h->kid[s.node] = -1;
        if (s.hi - s.lo <= HD_LEAF || top + 2 > HD_STACK)
            continue;
        double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
        for (int i = s.lo; i < s.hi; i++)
            for (int k = 0; k < 3; k++) {
                double c = cen[3 * (size_t)h->order[i] + k];
                lo[k] = fmin(lo[k], c), hi[k] = fmax(hi[k], c);
            }
        int axis = 0;
        for (int k = 1; k < 3; k++)
            if (hi[k] - lo[k] > hi[axis] - lo[axis])
                axis = k;
        for (int i = s.lo; i < s.hi; i++)
            key[i] = cen[3 * (size_t)h->order[i] + axis];
        int mid = s.lo + (s.hi - s.lo) / 2;
        select_median(key, h->order, s.lo, s.hi, mid);
        int k0 = h->nnode;
        h->nnode += 2;
        h->kid[s.node] = k0;
        stack[top++] = (hd_span){ k0 + 1, mid, s.hi };
        stack[top++] = (hd_span){ k0, s.lo, mid };
    }
    free(cen);
    free(key);
    return h;
}

size_t proj__hd_box_size(const proj__hd *h, int d)
{
    return 2 * (size_t)d * ((size_t)h->nf + (size_t)h->nnode);
}

void proj__hd_fit(const proj__hd *h, int d, const double *Z, double *box)
{
    size_t w = 2 * (size_t)d;
    double *nbox = box + w * (size_t)h->nf;
    #pragma omp parallel for schedule(static)
    for (int i = 0; i < h->nf; i++) {
        const int *v = h->f + 3 * (size_t)h->order[i];
        double *lo = box + w * i, *hi = lo + d;
        for (int k = 0; k < d; k++) {
            double a = Z[(size_t)d * v[0] + k], b = Z[(size_t)d * v[1] + k], c = Z[(size_t)d * v[2] + k];
            double l = a < b ? a : b, u = a < b ? b : a;
            lo[k] = c < l ? c : l;
            hi[k] = c > u ? c : u;
        }
    }
    for (int n = h->nnode - 1; n >= 0; n--) {   /* children after parents: bottom-up */
        double *lo = nbox + w * n, *hi = lo + d;
        const double *src = h->kid[n] < 0 ? box + w * h->first[n] : nbox + w * h->kid[n];
        int m = h->kid[n] < 0 ? h->count[n] : 2;
        for (int k = 0; k < d; k++)
            lo[k] = INFINITY, hi[k] = -INFINITY;
        for (int i = 0; i < m; i++) {
            const double *b = src + w * i;
            for (int k = 0; k < d; k++) {
                lo[k] = b[k] < lo[k] ? b[k] : lo[k];
                hi[k] = b[d + k] > hi[k] ? b[d + k] : hi[k];
            }
        }
    }
}

/* Four doubles at any 8-byte alignment (GCC's and Clang's vectors; two
 * SSE2 registers on the baseline target). */
typedef double hd_v4 __attribute__((vector_size(32), aligned(8)));
typedef long long hd_m4 __attribute__((vector_size(32), aligned(8)));

/* The squared distance from q to the box (lo, then hi), or a partial sum
 * of it at least best as soon as one reaches best: the caller only asks
 * whether it is below best. Four coordinates a step, without branches
 * (only one of lo − q and q − hi can be positive, as lo <= hi); the sum
 * is tested every eight. */
static double box_bound(int d, const double *q, const double *lo, double best)
{
    const double *hi = lo + d;
    const hd_v4 zero = { 0, 0, 0, 0 };
    double c = 0;
    int k = 0;
    for (; k + HD_STEP <= d; k += HD_STEP) {
        hd_v4 acc = zero;
        for (int j = k; j < k + HD_STEP; j += 4) {
            hd_v4 x = *(const hd_v4 *)(q + j);
            hd_v4 a = *(const hd_v4 *)(lo + j) - x, b = x - *(const hd_v4 *)(hi + j);
            hd_v4 e = (hd_v4)((hd_m4)a & (a > zero)) + (hd_v4)((hd_m4)b & (b > zero));
            acc += e * e;
        }
        c += (acc[0] + acc[1]) + (acc[2] + acc[3]);
        if (!(c < best))
            return c;
    }
    for (; k < d; k++) {
        double e = q[k] < lo[k] ? lo[k] - q[k] : q[k] > hi[k] ? q[k] - hi[k] : 0;
        c += e * e;
    }
    return c;
}

void proj__hd_closest(const proj__hd *h, int d, const double *Z, const double *box,
                      const double *q, int *face, double *best, double bary[3])
{
    size_t w = 2 * (size_t)d;
    const double *nbox = box + w * (size_t)h->nf;
    hd_visit stack[HD_STACK];
    int top = 0;
    if (h->nf <= 0)
        return;
    double b0 = box_bound(d, q, nbox, *best);
    if (b0 < *best)
        stack[top++] = (hd_visit){ 0, b0 };
    while (top > 0) {
        hd_visit s = stack[--top];
        if (!(s.bound < *best))
            continue;
        if (h->kid[s.node] < 0) {
            for (int i = h->first[s.node]; i < h->first[s.node] + h->count[s.node]; i++) {
                if (!(box_bound(d, q, box + w * i, *best) < *best))
                    continue;
                const int *v = h->f + 3 * (size_t)h->order[i];
                double b[3];
                double c = proj_point_triangle(d, q, Z + (size_t)d * v[0],
                                               Z + (size_t)d * v[1], Z + (size_t)d * v[2], b);
                if (c < *best) {
                    *best = c;
                    *face = h->order[i];
                    bary[0] = b[0], bary[1] = b[1], bary[2] = b[2];
                }
            }
            continue;
        }
        int a = h->kid[s.node], b = a + 1;
        double ba = box_bound(d, q, nbox + w * a, *best);
        double bb = box_bound(d, q, nbox + w * b, *best);
        if (ba > bb) {
            int t = a;
            a = b, b = t;
            double tb = ba;
            ba = bb, bb = tb;
        }
        /* the farther child below the nearer, so the nearer is searched first */
        if (bb < *best)
            stack[top++] = (hd_visit){ b, bb };
        if (ba < *best)
            stack[top++] = (hd_visit){ a, ba };
    }
}
