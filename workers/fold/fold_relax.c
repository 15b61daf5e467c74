/* fold_relax.c — see fold.h: the last step after the repair, each vertex
 * of a bad face moved alone to the point among its neighbours' images
 * that leaves its faces the fewest bad ones, or as many turned over less. */
#include "fold/fold.h"
#include "fold/fold__kinds.h"
#include "geo/geo_edges.h"
#include "geo/geo_area.h"
#include "geo/geo_normals.h"
#include "metric/metric.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Sweeps at most: while a vertex moves. */
#define FOLD__RELAX_SWEEPS 10
/* A move that leaves as many bad faces is made when it raises the least
 * lean of the vertex's faces by this much. */
#define FOLD__RELAX_LEAN 0.05
/* The points tried for a vertex lie within this multiple of its
 * neighbours' farthest image from their mean. */
#define FOLD__RELAX_REACH 2.0
/* Target faces tried for one vertex at most, and on the fine grid. */
#define FOLD__RELAX_FACES 4096
#define FOLD__RELAX_FINE_FACES 64

/* The points of a target face tried: its centre, and toward each corner,
 * each edge ... */
static const double coarse[][3] = {
    { 1.0 / 3, 1.0 / 3, 1.0 / 3 }, { 0.6, 0.2, 0.2 }, { 0.2, 0.6, 0.2 }, { 0.2, 0.2, 0.6 },
    { 0.8, 0.1, 0.1 }, { 0.1, 0.8, 0.1 }, { 0.1, 0.1, 0.8 },
    { 0.45, 0.45, 0.1 }, { 0.45, 0.1, 0.45 }, { 0.1, 0.45, 0.45 },
};
#define NCOARSE ((int)(sizeof coarse / sizeof coarse[0]))
/* ... and, where none of those will do, a grid of 28 in each of the
 * FOLD__RELAX_FINE_FACES faces tried first (those nearest the star):
 * (4i + 1, 4j + 1, 4k + 1) / 27 for i + j + k = 6. */
#define FINE_STEPS 6
#define NFINE ((FINE_STEPS + 1) * (FINE_STEPS + 2) / 2)

typedef struct relax {
    const mesh *S, *T;
    const geo_edges *ES, *ET;
    bmap *R;
    double *img, *tn;             /* R's images (S->nv by 3), T's vertex normals */
    double area_S, area_T;
    unsigned char *kind;
    double fine[NFINE][3];        /* the fine grid's points */
} relax;

/* Face t's kind for the repair under the current images. */
static int kind_of(const relax *r, int t)
{
    return fold__face_kind(r->S, r->T, r->R, r->img, r->tn, r->area_S, r->area_T, t);
}

/* The bad faces round vertex v, a collapsed one counting as more than all
 * of them (fold_repair's badness, on a star); the count stops once it is
 * past bound. */
static int star_cost(const relax *r, int v, int bound)
{
    int a = r->ES->vf_start[v], b = r->ES->vf_start[v + 1], n = 0;
    for (int i = a; i < b && n <= bound; i++) {
        int k = kind_of(r, r->ES->vf_face[i]);
        n += k == METRIC_FACE_COLLAPSED ? b - a + 1 : k != METRIC_FACE_OK;
    }
    return n;
}

/* How far the image of face t leans from the target's normals where its
 * corners land: the cosine between its normal and their sum (-1 for a face
 * turned over flat, 1 for one lying along the target). */
static double lean(const relax *r, int t)
{
    double n[3], m[3];
    metric_face_normals(r->S, r->T, r->R, r->img, r->tn, t, n, m);
    double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), mm = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    return nn > 0 && mm > 0 ? (n[0] * m[0] + n[1] * m[1] + n[2] * m[2]) / (nn * mm) : -1;
}

/* The least lean of v's faces. */
static double star_lean(const relax *r, int v)
{
    double l = 1;
    for (int i = r->ES->vf_start[v]; i < r->ES->vf_start[v + 1]; i++)
        l = fmin(l, lean(r, r->ES->vf_face[i]));
    return l;
}

/* Row v of R set to (face, w), its image with it. */
static void place(relax *r, int v, int face, const double *w)
{
    const int *tf = r->T->f + 3 * face;
    r->R->face[v] = face;
    memcpy(r->R->w + 3 * v, w, 3 * sizeof(double));
    for (int d = 0; d < 3; d++)
        r->img[3 * v + d] = w[0] * r->T->v[3 * tf[0] + d] + w[1] * r->T->v[3 * tf[1] + d] +
                            w[2] * r->T->v[3 * tf[2] + d];
}

/* The mean of the images of v's neighbours (each counted once per face
 * of v's it shares). */
static void neighbours_mean(const relax *r, int v, double *c)
{
    int n = 0;
    c[0] = c[1] = c[2] = 0;
    for (int i = r->ES->vf_start[v]; i < r->ES->vf_start[v + 1]; i++)
        for (int k = 0; k < 3; k++) {
            int u = r->S->f[3 * r->ES->vf_face[i] + k];
            if (u == v)
                continue;
            for (int d = 0; d < 3; d++)
                c[d] += r->img[3 * u + d];
            n++;
        }
    for (int d = 0; d < 3 && n; d++)
        c[d] /= n;
}

static double dist2(const double *a, const double *b)
{
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

/* A vertex to relax, by how far its image is out of its neighbours'
 * (from their images' mean, over their spread). */
typedef struct stray {
    double by;
    int v;
} stray;

static int by_most_astray(const void *a, const void *b)
{
    const stray *x = a, *y = b;
    return x->by < y->by ? 1 : x->by > y->by ? -1 : (x->v > y->v) - (x->v < y->v);
}

static double astray(const relax *r, int v)
{
    double c[3], spread = 0;
    int n = 0;
    neighbours_mean(r, v, c);
    for (int i = r->ES->vf_start[v]; i < r->ES->vf_start[v + 1]; i++)
        for (int k = 0; k < 3; k++) {
            int u = r->S->f[3 * r->ES->vf_face[i] + k];
            if (u != v) {
                spread += dist2(r->img + 3 * u, c);
                n++;
            }
        }
    return sqrt(dist2(r->img + 3 * v, c) / (spread / (n ? n : 1) + 1e-300));
}

/* Adds target face q to the list (once: mark). */
static void add(int q, unsigned char *mark, int *list, int *n)
{
    if (!mark[q]) {
        mark[q] = 1;
        list[(*n)++] = q;
    }
}

/* Whether v's faces have a bad one to mend and a good one to mend it
 * against (a star all bad, as in a part mirrored as a whole, has none). */
static int mendable(const relax *r, int v)
{
    int bad = 0, good = 0;
    for (int i = r->ES->vf_start[v]; i < r->ES->vf_start[v + 1]; i++) {
        bad += r->kind[r->ES->vf_face[i]] != METRIC_FACE_OK;
        good += r->kind[r->ES->vf_face[i]] == METRIC_FACE_OK;
    }
    return bad && good;
}

/* The search for one vertex's point: the star's cost now, the best found
 * and where (face, weights), that point's distance from the neighbours'
 * mean x, and the least lean a point as bad as now must beat. */
typedef struct search {
    int cost, best, bf;
    double bw[3], near, blean, x[3];
} search;

/* Tries the points pts (np per face) of the n target faces for vertex v:
 * one with fewer bad faces than now, the nearest to x among the fewest;
 * failing that, one as bad that leans the star clearly less over. */
static void try_points(relax *r, int v, search *q, const int *faces, int n, const double (*pts)[3], int np)
{
    for (int i = 0; i < n; i++)
        for (int s = 0; s < np; s++) {
            place(r, v, faces[i], pts[s]);
            int c = star_cost(r, v, q->best);
            if (c > q->best || c > q->cost)
                continue;
            if (c == q->cost) {
                double l = star_lean(r, v);
                if (q->best == q->cost && l > q->blean) {
                    q->blean = l;
                    q->bf = faces[i];
                    memcpy(q->bw, pts[s], sizeof q->bw);
                }
                continue;
            }
            double d = dist2(r->img + 3 * v, q->x);
            if (c < q->best || d < q->near) {
                q->best = c;
                q->near = d;
                q->bf = faces[i];
                memcpy(q->bw, pts[s], sizeof q->bw);
            }
        }
}

/* Moves vertex v to its best point when that lowers its star's cost;
 * returns whether it moved. mark: T->nf bytes, all 0; list: T->nf ints. */
static int relax_vertex(relax *r, int v, unsigned char *mark, int *list)
{
    const mesh *S = r->S, *T = r->T;
    const geo_edges *ES = r->ES, *ET = r->ET;
    if (!mendable(r, v))
        return 0;
    int cost = star_cost(r, v, INT_MAX);
    double x[3], reach = 0;
    neighbours_mean(r, v, x);
    /* the faces the star's vertices land in, and from them every face
     * with a corner within FOLD__RELAX_REACH times the neighbours' reach
     * of their mean (a vertex belongs among its neighbours, however far
     * they spread on T) */
    int n = 0;
    for (int i = ES->vf_start[v]; i < ES->vf_start[v + 1]; i++)
        for (int k = 0; k < 3; k++) {
            int u = S->f[3 * ES->vf_face[i] + k];
            add(r->R->face[u], mark, list, &n);
            if (u != v)
                reach = fmax(reach, dist2(r->img + 3 * u, x));
        }
    for (int i = 0; i < n && n < FOLD__RELAX_FACES; i++)
        for (int k = 0; k < 3; k++) {
            int u = T->f[3 * list[i] + k];
            if (dist2(T->v + 3 * u, x) > FOLD__RELAX_REACH * FOLD__RELAX_REACH * reach)
                continue;
            for (int j = ET->vf_start[u]; j < ET->vf_start[u + 1] && n < FOLD__RELAX_FACES; j++)
                add(ET->vf_face[j], mark, list, &n);
        }
    search q = { cost, cost, r->R->face[v], { 0 }, INFINITY, 0, { x[0], x[1], x[2] } };
    memcpy(q.bw, r->R->w + 3 * v, sizeof q.bw);
    double now = star_lean(r, v);
    q.blean = now + FOLD__RELAX_LEAN;
    try_points(r, v, &q, list, n, coarse, NCOARSE);
    if (q.best == cost && !(q.blean > now + FOLD__RELAX_LEAN))
        try_points(r, v, &q, list, n < FOLD__RELAX_FINE_FACES ? n : FOLD__RELAX_FINE_FACES, r->fine, NFINE);
    for (int i = 0; i < n; i++)
        mark[list[i]] = 0;
    place(r, v, q.bf, q.bw);
    for (int i = ES->vf_start[v]; i < ES->vf_start[v + 1]; i++)
        r->kind[ES->vf_face[i]] = (unsigned char)kind_of(r, ES->vf_face[i]);
    return q.best < cost || q.blean > now + FOLD__RELAX_LEAN;
}

int fold_relax(const mesh *S, const mesh *T, const int *fixed, int nfixed, bmap *P,
               fold_report *rep)
{
    memset(rep, 0, sizeof *rep);
    if (!fold__map_ok(S, T, P) || nfixed < 0 || (nfixed && !fixed))
        return FOLD_EINVAL;
    geo_edges ES = {0}, ET = {0};
    relax r = { S, T, &ES, &ET, P, malloc(sizeof(double) * (3 * (size_t)S->nv + 1)),
                malloc(sizeof(double) * (3 * (size_t)T->nv + 1)), geo_total_area(S),
                geo_total_area(T), malloc((size_t)S->nf + 1), { { 0 } } };
    unsigned char *mark = calloc((size_t)T->nf + 1, 1), *fx = calloc((size_t)S->nv + 1, 1);
    int *list = malloc(sizeof(int) * ((size_t)T->nf + 1)), rc = FOLD_ENOMEM;
    stray *order = malloc(sizeof(stray) * ((size_t)S->nv + 1));
    if (!r.img || !r.tn || !r.kind || !mark || !fx || !list || !order)
        goto out;
    int bad;
    if ((rc = fold__open(S, T, P, r.kind, &ES, &ET, rep, &bad)) || bad == 0)
        goto out;
    for (int k = 0; k < nfixed; k++)
        if (fixed[k] >= 0 && fixed[k] < S->nv)
            fx[fixed[k]] = 1;
    bmap_apply(P, T->f, T->v, 3, r.img);
    geo_vertex_normals(T, r.tn);
    for (int i = 0, k = 0; i <= FINE_STEPS; i++)
        for (int j = 0; i + j <= FINE_STEPS; j++, k++) {
            r.fine[k][0] = (4.0 * i + 1) / (4 * FINE_STEPS + 3);
            r.fine[k][1] = (4.0 * j + 1) / (4 * FINE_STEPS + 3);
            r.fine[k][2] = (4.0 * (FINE_STEPS - i - j) + 1) / (4 * FINE_STEPS + 3);
        }
    /* each sweep the most astray first: of a vertex pushed past its
     * neighbour and that neighbour, it is the one to move */
    for (int sweep = 0; sweep < FOLD__RELAX_SWEEPS; sweep++) {
        int n = 0, m = 0;
        for (int v = 0; v < S->nv; v++)
            if (!fx[v] && mendable(&r, v))
                order[m++] = (stray){ astray(&r, v), v };
        qsort(order, (size_t)m, sizeof *order, by_most_astray);
        for (int i = 0; i < m; i++)
            n += relax_vertex(&r, order[i].v, mark, list);
        rep->relaxed += n;
        if (!n)
            break;
    }
    bad = 0;
    for (int t = 0; t < S->nf; t++)
        bad += r.kind[t] != METRIC_FACE_OK;
    rep->bad_after = bad;
    rep->accepted = rep->relaxed > 0;
out:
    geo_edges_close(&ES);
    geo_edges_close(&ET);
    free(r.img);
    free(r.tn);
    free(r.kind);
    free(mark);
    free(fx);
    free(list);
    free(order);
    return rc;
}
