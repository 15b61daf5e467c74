/* fold_tube.c — the tube placement of fold__patch.h: depth from a patch's
 * boundary (Dijkstra), the tube chart (the angle of a harmonic height's
 * conjugate, the radius of a depth share), and a region laid inside its
 * boundary's images by matching depth shares along the part, so that a
 * long part's end is not crowded toward a point as a harmonic disk map
 * crowds it. */
#include "fold/fold__patch.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The bounds of the tube chart's radial rate (radius_of). */
#define FOLD__TUBE_LAMBDA_MIN 0.5
#define FOLD__TUBE_LAMBDA_MAX 30.0

/* Binary min-heap of (key, vertex) with lazy deletion. */
typedef struct heap {
    int n;
    double *key;
    int *v;
} heap;

static void heap_push(heap *h, double key, int v)
{
    int i = h->n++;
    while (i > 0) {
        int up = (i - 1) / 2;
        if (h->key[up] <= key)
            break;
        h->key[i] = h->key[up];
        h->v[i] = h->v[up];
        i = up;
    }
    h->key[i] = key;
    h->v[i] = v;
}

static void heap_pop(heap *h, double *key, int *v)
{
    *key = h->key[0];
    *v = h->v[0];
    double k = h->key[--h->n];
    int x = h->v[h->n], i = 0;
    for (;;) {
        int c = 2 * i + 1;
        if (c >= h->n)
            break;
        if (c + 1 < h->n && h->key[c + 1] < h->key[c])
            c++;
        if (h->key[c] >= k)
            break;
        h->key[i] = h->key[c];
        h->v[i] = h->v[c];
        i = c;
    }
    h->key[i] = k;
    h->v[i] = x;
}

int fold__depth(const mesh *m, const fold__patch *p, int *loc, double *depth)
{
    int nv = p->nv, rc = -1;
    size_t ne = 6 * (size_t)p->nf + 1, nheap = ne + (size_t)nv;   /* relaxations, and the boundary */
    int *start = calloc((size_t)nv + 2, sizeof(int)), *adj = malloc(sizeof(int) * ne);
    heap h = { 0, malloc(sizeof(double) * nheap), malloc(sizeof(int) * nheap) };
    if (!start || !adj || !h.key || !h.v)
        goto out;
    for (int i = 0; i < nv; i++)
        loc[p->verts[i]] = i;
    for (int q = 0; q < p->nf; q++)
        for (int k = 0; k < 3; k++)
            start[loc[m->f[3 * p->faces[q] + k]] + 1] += 2;
    for (int i = 0; i < nv; i++)
        start[i + 1] += start[i];
    int *fill = malloc(sizeof(int) * ((size_t)nv + 1));
    if (!fill)
        goto out;
    memcpy(fill, start, sizeof(int) * (size_t)nv);
    for (int q = 0; q < p->nf; q++) {
        const int *f = m->f + 3 * p->faces[q];
        for (int k = 0; k < 3; k++) {
            int a = loc[f[k]];
            adj[fill[a]++] = loc[f[(k + 1) % 3]];
            adj[fill[a]++] = loc[f[(k + 2) % 3]];
        }
    }
    free(fill);
    for (int i = 0; i < nv; i++) {
        depth[i] = i < p->nb ? 0 : INFINITY;
        if (i < p->nb)
            heap_push(&h, 0, i);
    }
    while (h.n) {
        double d;
        int a;
        heap_pop(&h, &d, &a);
        if (d > depth[a])
            continue;
        const double *x = m->v + 3 * p->verts[a];
        for (int k = start[a]; k < start[a + 1]; k++) {
            int b = adj[k];
            const double *y = m->v + 3 * p->verts[b];
            double e = d + sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                                (x[2] - y[2]) * (x[2] - y[2]));
            if (e < depth[b]) {
                depth[b] = e;
                heap_push(&h, e, b);
            }
        }
    }
    rc = 0;
out:
    for (int i = 0; i < nv; i++)
        loc[p->verts[i]] = -1;
    free(start);
    free(adj);
    free(h.key);
    free(h.v);
    return rc;
}

typedef struct rank {
    double x;
    int i;
} rank;

static int cmp_rank(const void *a, const void *b)
{
    const rank *x = a, *y = b;
    return (x->x > y->x) - (x->x < y->x);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The chart's radius at depth share s (0 on the boundary, 1 at the
 * deepest vertex): (e^(-lambda s) - e^(-lambda)) / (1 - e^(-lambda)), which
 * falls from 1 to 0; with lambda the part's depth over its boundary's
 * radius it spaces the rings as a conformal map of a tube would (the
 * triangles keep their shape: a linear radius squeezes a long part's
 * rings against the circle and its first ring's triangles fold against
 * the circle's curve), ending at the centre instead of at e^(-lambda). */
static double radius_of(double s, double lambda)
{
    return (exp(-lambda * s) - exp(-lambda)) / -expm1(-lambda);
}

/* The depth share at radius r: radius_of's inverse. */
static double share_of(double r, double lambda)
{
    double e = exp(-lambda);
    return fmin(1, fmax(0, -log(r * (1 - e) + e) / lambda));
}

int fold__tube_chart(const mesh *m, const geo_edges *E, const fold__patch *p, int *loc,
                     const double *depth, double *uv, double *lambda)
{
    int nv = p->nv, nf = p->nf, tip = 0, rc = -1;
    for (int i = 1; i < nv; i++)
        if (depth[i] > depth[tip])
            tip = i;
    double dmax = depth[tip];
    if (tip < p->nb || !(dmax > 0) || !isfinite(dmax))
        return 1;
    double len = 0;
    for (int i = 0; i < p->nb; i++) {
        const double *a = m->v + 3 * p->verts[i], *b = m->v + 3 * p->verts[(i + 1) % p->nb];
        len += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                    (a[2] - b[2]) * (a[2] - b[2]));
    }
    if (!(len > 0))
        return 1;
    *lambda = fmin(FOLD__TUBE_LAMBDA_MAX, fmax(FOLD__TUBE_LAMBDA_MIN, dmax / (len / (2 * M_PI))));
    double *u2 = malloc(sizeof(double) * 2 * ((size_t)nv + 1)), *u = malloc(sizeof(double) * ((size_t)nv + 1));
    double *theta = malloc(sizeof(double) * ((size_t)nf + 1)), *flux = malloc(sizeof(double) * ((size_t)nv + 1));
    double *t = malloc(sizeof(double) * ((size_t)nv + 1));
    unsigned char *pin = calloc((size_t)nv + 1, 1);
    rank *byu = malloc(sizeof(rank) * ((size_t)nv + 1));
    if (!u2 || !u || !theta || !flux || !t || !pin || !byu)
        goto out;
    /* height: harmonic, 0 on the boundary and 1 at the deepest vertex */
    for (int i = 0; i < nv; i++) {
        u2[2 * i] = i < p->nb ? 0 : i == tip ? 1 : 0.5;
        u2[2 * i + 1] = 0;
        pin[i] = i < p->nb || i == tip;
    }
    if (fold__harmonic(m, E, p, pin, NULL, loc, u2))
        goto out;
    for (int i = 0; i < nv; i++)
        u[i] = u2[2 * i];
    /* angle: its conjugate, which turns once round the deepest vertex by
     * the flux into it; per vertex, the mean direction of its faces' */
    if ((rc = fold__conjugate(m, E, p, u, loc, theta, flux))) {
        rc = rc < 0 ? -1 : 1;
        goto out;
    }
    rc = 1;
    double turn = flux[tip];
    if (!(fabs(turn) > 0))
        goto out;
    for (int i = 0; i < nv; i++)
        u2[2 * i] = u2[2 * i + 1] = 0;
    for (int i = 0; i < nv; i++)
        loc[p->verts[i]] = i;
    for (int q = 0; q < nf; q++) {
        double a = 2 * M_PI * theta[q] / turn;
        for (int k = 0; k < 3; k++) {
            int i = loc[m->f[3 * p->faces[q] + k]];
            u2[2 * i] += cos(a);
            u2[2 * i + 1] += sin(a);
        }
    }
    /* radius: of a depth share, the k-th largest height taking the k-th
     * largest share (depth / the deepest's), so that the end of a long
     * part is not crowded as a harmonic map crowds it */
    for (int i = 0; i < nv; i++) {
        byu[i].x = u[i];
        byu[i].i = i;
        t[i] = depth[i] / dmax;
    }
    qsort(byu, (size_t)nv, sizeof(rank), cmp_rank);
    qsort(t, (size_t)nv, sizeof(double), cmp_double);
    double area = 0;
    for (int k = 0; k < nv; k++) {
        int i = byu[k].i;
        double r = radius_of(t[k], *lambda), d = hypot(u2[2 * i], u2[2 * i + 1]);
        uv[2 * i] = d > 0 ? r * u2[2 * i] / d : 0;
        uv[2 * i + 1] = d > 0 ? r * u2[2 * i + 1] / d : 0;
    }
    uv[2 * tip] = uv[2 * tip + 1] = 0;
    /* oriented as the mesh */
    for (int q = 0; q < nf; q++) {
        const int *f = m->f + 3 * p->faces[q];
        const double *a = uv + 2 * loc[f[0]], *b = uv + 2 * loc[f[1]], *c = uv + 2 * loc[f[2]];
        area += (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    }
    for (int i = 0; i < nv; i++)
        loc[p->verts[i]] = -1;
    if (area < 0)
        for (int i = 0; i < nv; i++)
            uv[2 * i + 1] = -uv[2 * i + 1];
    rc = 0;
out:
    free(u2);
    free(u);
    free(theta);
    free(flux);
    free(t);
    free(pin);
    free(byu);
    return rc;
}

/* The angle of z, unwrapped to follow prev: within (prev - pi, prev + pi]. */
static double unwrap(double a, double prev)
{
    while (a <= prev - M_PI)
        a += 2 * M_PI;
    while (a > prev + M_PI)
        a -= 2 * M_PI;
    return a;
}

/* Whether the angles a[0..n), each unwrapped to follow the one before,
 * close once round: their steps, the last back to the first included,
 * add up to 2 pi. */
static int turns_once(const double *a, int n)
{
    double close = unwrap(a[0], a[n - 1]) - a[n - 1];
    return fabs(a[n - 1] - a[0] + close - 2 * M_PI) < 1e-6;
}

/* a[0..n) replaced by its least-squares nondecreasing fit (pool adjacent
 * violators), then made increasing by a share of a turn per step that is
 * far below any step of a ring; 1 when it then spans a whole turn or
 * more, 0 else, -1 when out of memory. */
static int monotone(double *a, int n)
{
    double *mean = malloc(sizeof(double) * ((size_t)n + 1));
    int *len = malloc(sizeof(int) * ((size_t)n + 1)), m = 0;
    if (!mean || !len) {
        free(mean);
        free(len);
        return -1;
    }
    for (int i = 0; i < n; i++) {
        mean[m] = a[i];
        len[m++] = 1;
        while (m > 1 && mean[m - 2] > mean[m - 1]) {
            mean[m - 2] = (mean[m - 2] * len[m - 2] + mean[m - 1] * len[m - 1]) / (len[m - 2] + len[m - 1]);
            len[m - 2] += len[m - 1];
            m--;
        }
    }
    for (int k = 0, i = 0; k < m; k++)
        for (int j = 0; j < len[k]; j++, i++)
            a[i] = mean[k] + 1e-9 * i;
    free(mean);
    free(len);
    return a[n - 1] - a[0] >= 2 * M_PI ? 1 : 0;
}

int fold__tube_fit(const fold__patch *p, const double *own, double lambda_own, double lambda,
                   double *uv)
{
    int nb = p->nb, rc = 1;
    double *phi = malloc(sizeof(double) * ((size_t)nb + 1)), *ang = malloc(sizeof(double) * ((size_t)nb + 1));
    double *mod = malloc(sizeof(double) * ((size_t)nb + 1));
    if (!phi || !ang || !mod) {
        rc = -1;
        goto out;
    }
    /* the boundary's angles in the patch's own placement (increasing: a
     * fold-free placement) and its images' about the chart's centre,
     * which must turn once round the same way */
    for (int b = 0; b < nb; b++) {
        phi[b] = atan2(own[2 * b + 1], own[2 * b]);
        ang[b] = atan2(uv[2 * b + 1], uv[2 * b]);
        mod[b] = share_of(hypot(uv[2 * b], uv[2 * b + 1]), lambda);   /* the images' shares */
        if (!(mod[b] < 1))
            goto out;
        if (b) {
            phi[b] = unwrap(phi[b], phi[b - 1]);
            ang[b] = unwrap(ang[b], ang[b - 1]);
            if (!(phi[b] > phi[b - 1]))
                goto out;
        }
    }
    if (nb < 3 || !turns_once(phi, nb) || !turns_once(ang, nb))
        goto out;
    /* a ring whose image steps back here and there (folded along it) is
     * followed inside by its increasing fit (pool-adjacent-violators),
     * so the fold stays at the ring instead of running down a wedge */
    int mr = monotone(ang, nb);
    if (mr) {
        rc = mr < 0 ? -1 : 1;
        goto out;
    }
    for (int i = nb; i < p->nv; i++) {
        double s = share_of(hypot(own[2 * i], own[2 * i + 1]), lambda_own);
        double a = atan2(own[2 * i + 1], own[2 * i]);
        /* the boundary segment [b, b+1] (the last wraps to 0) holding a */
        a = unwrap(a, phi[0] + M_PI);          /* in (phi[0], phi[0] + 2 pi] */
        int b = 0;
        while (b + 1 < nb && phi[b + 1] <= a)
            b++;
        double p0 = phi[b], p1 = b + 1 < nb ? phi[b + 1] : phi[0] + 2 * M_PI;
        double a0 = ang[b], a1 = b + 1 < nb ? ang[b + 1] : ang[0] + 2 * M_PI;
        double m0 = mod[b], m1 = mod[b + 1 < nb ? b + 1 : 0];
        double f = p1 > p0 ? (a - p0) / (p1 - p0) : 0;
        f = fmin(1, fmax(0, f));
        double A = a0 + f * (a1 - a0), tb = m0 + f * (m1 - m0);
        double r = radius_of(tb + s * (1 - tb), lambda);
        uv[2 * i] = r * cos(A);
        uv[2 * i + 1] = r * sin(A);
    }
    rc = 0;
out:
    free(phi);
    free(ang);
    free(mod);
    return rc;
}
