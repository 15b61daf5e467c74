/* fold_relax.c — see fold.h: the last step after the repair, each vertex
 * of a bad face moved alone to the nearby point of the target that leaves
 * its faces the fewest bad ones. */
#include "fold/fold.h"
#include "fold/fold__kinds.h"
#include "geo/geo_edges.h"
#include "geo/geo_area.h"
#include "geo/geo_normals.h"
#include "metric/metric.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Sweeps at most: while a vertex moves. */
#define FOLD__RELAX_SWEEPS 10

/* The points of a target face tried: its centre, and toward each corner,
 * each edge. */
static const double samples[][3] = {
    { 1.0 / 3, 1.0 / 3, 1.0 / 3 }, { 0.6, 0.2, 0.2 }, { 0.2, 0.6, 0.2 }, { 0.2, 0.2, 0.6 },
    { 0.8, 0.1, 0.1 }, { 0.1, 0.8, 0.1 }, { 0.1, 0.1, 0.8 },
    { 0.45, 0.45, 0.1 }, { 0.45, 0.1, 0.45 }, { 0.1, 0.45, 0.45 },
};
#define NSAMPLES ((int)(sizeof samples / sizeof samples[0]))

typedef struct relax {
    const mesh *S, *T;
    const geo_edges *ES, *ET;
    bmap *R;
    double *img, *tn;             /* R's images (S->nv by 3), T's vertex normals */
    double area_S, area_T;
    unsigned char *kind;
} relax;

/* Face t's kind for the repair under the current images. */
static int kind_of(const relax *r, int t)
{
    return fold__face_kind(r->S, r->T, r->R, r->img, r->tn, r->area_S, r->area_T, t);
}

/* The bad faces round vertex v, a collapsed one counting as more than all
 * of them (fold_repair's badness, on a star). */
static int star_cost(const relax *r, int v)
{
    int a = r->ES->vf_start[v], b = r->ES->vf_start[v + 1], n = 0;
    for (int i = a; i < b; i++) {
        int k = kind_of(r, r->ES->vf_face[i]);
        n += k == METRIC_FACE_COLLAPSED ? b - a + 1 : k != METRIC_FACE_OK;
    }
    return n;
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

/* Moves vertex v to its best point when that lowers its star's cost;
 * returns whether it moved. mark: T->nf bytes, all 0; list: T->nf ints. */
static int relax_vertex(relax *r, int v, unsigned char *mark, int *list)
{
    const mesh *S = r->S, *T = r->T;
    const geo_edges *ES = r->ES, *ET = r->ET;
    if (!mendable(r, v))
        return 0;
    int cost = star_cost(r, v);
    /* the faces the star's vertices land in, and those touching them */
    int n = 0;
    for (int i = ES->vf_start[v]; i < ES->vf_start[v + 1]; i++)
        for (int k = 0; k < 3; k++)
            add(r->R->face[S->f[3 * ES->vf_face[i] + k]], mark, list, &n);
    for (int m = n, i = 0; i < m; i++)
        for (int k = 0; k < 3; k++) {
            int u = T->f[3 * list[i] + k];
            for (int j = ET->vf_start[u]; j < ET->vf_start[u + 1]; j++)
                add(ET->vf_face[j], mark, list, &n);
        }
    int bf = r->R->face[v], best = cost;
    double x[3], bw[3], near = INFINITY;
    memcpy(bw, r->R->w + 3 * v, sizeof bw);
    neighbours_mean(r, v, x);
    for (int i = 0; i < n; i++)
        for (int s = 0; s < NSAMPLES; s++) {
            place(r, v, list[i], samples[s]);
            int c = star_cost(r, v);
            if (c > best || c >= cost)
                continue;
            double d = dist2(r->img + 3 * v, x);
            if (c < best || d < near) {
                best = c;
                near = d;
                bf = list[i];
                memcpy(bw, samples[s], sizeof bw);
            }
        }
    for (int i = 0; i < n; i++)
        mark[list[i]] = 0;
    place(r, v, bf, bw);
    for (int i = ES->vf_start[v]; i < ES->vf_start[v + 1]; i++)
        r->kind[ES->vf_face[i]] = (unsigned char)kind_of(r, ES->vf_face[i]);
    return best < cost;
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
                geo_total_area(T), malloc((size_t)S->nf + 1) };
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
