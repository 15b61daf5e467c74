/* bench_geod.c — heat-method geodesics (factorisation + 50 sources) on the
 * 5K-vertex FAUST mesh, against a naive edge-graph Dijkstra written here
 * only for comparison, and the accuracy of both on the unit sphere, which
 * shows why Dijkstra alone is not enough (it measures zig-zag paths along
 * edges). Prints figures; fails only when something cannot run. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "geo/geo_edges.h"
#include "geod/geod.h"

#include <math.h>
#include <stdlib.h>
#include <time.h>

#define NSRC 50

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Vertex adjacency (CSR) with edge lengths, from the edge table. */
typedef struct { int *start, *nbr; double *len; } graph;

static void graph_build(const mesh *m, const geo_edges *e, graph *g)
{
    g->start = calloc(m->nv + 1, sizeof *g->start);
    g->nbr = malloc(2 * (size_t)e->ne * sizeof *g->nbr);
    g->len = malloc(2 * (size_t)e->ne * sizeof *g->len);
    for (int k = 0; k < 2 * e->ne; k++)
        g->start[e->ev[k] + 1]++;
    for (int i = 0; i < m->nv; i++)
        g->start[i + 1] += g->start[i];
    int *at = malloc(m->nv * sizeof *at);
    for (int i = 0; i < m->nv; i++)
        at[i] = g->start[i];
    for (int k = 0; k < e->ne; k++) {
        int a = e->ev[2 * k], b = e->ev[2 * k + 1];
        const double *p = m->v + 3 * a, *q = m->v + 3 * b;
        double l = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                        (p[2] - q[2]) * (p[2] - q[2]));
        g->nbr[at[a]] = b; g->len[at[a]++] = l;
        g->nbr[at[b]] = a; g->len[at[b]++] = l;
    }
    free(at);
}

/* Dijkstra with a binary heap of (distance, vertex), lazy deletion. */
typedef struct { double d; int v; } item;

static void dijkstra(const graph *g, int nv, int src, double *dist, item *heap)
{
    for (int i = 0; i < nv; i++)
        dist[i] = INFINITY;
    int n = 0;
    dist[src] = 0;
    heap[n++] = (item){0, src};
    while (n > 0) {
        item top = heap[0], last = heap[--n];
        int i = 0; /* sift last down from the root */
        for (;;) {
            int c = 2 * i + 1;
            if (c >= n) break;
            if (c + 1 < n && heap[c + 1].d < heap[c].d) c++;
            if (heap[c].d >= last.d) break;
            heap[i] = heap[c];
            i = c;
        }
        if (n > 0) heap[i] = last;
        if (top.d > dist[top.v])
            continue;
        for (int p = g->start[top.v]; p < g->start[top.v + 1]; p++) {
            int w = g->nbr[p];
            double nd = top.d + g->len[p];
            if (nd < dist[w]) {
                dist[w] = nd;
                int j = n++; /* sift up */
                while (j > 0 && heap[(j - 1) / 2].d > nd) {
                    heap[j] = heap[(j - 1) / 2];
                    j = (j - 1) / 2;
                }
                heap[j] = (item){nd, w};
            }
        }
    }
}

TEST_T(heat_vs_dijkstra_time_faust_5k, 120)
{
    mesh *m = NULL;
    char err[256] = "";
    if (mesh_read(harness_data_path("faust_r/vtx_5k/tr_reg_000.off"), &m, err, sizeof err))
        FAILF("%s", err);
    int src[NSRC];
    unsigned long long st = 11;
    for (int k = 0; k < NSRC; k++)
        src[k] = (int)(testmesh_rand(&st) * m->nv);
    double *out = malloc((size_t)NSRC * m->nv * sizeof *out);
    double best_f = 1e300, best_s = 1e300, best_d = 1e300;
    for (int trial = 0; trial < 3; trial++) {
        double t0 = now();
        geod_solver *s = NULL;
        geod_solver_new(m, 0, &s, err, sizeof err);
        if (!s)
            FAILF("%s", err);
        double t1 = now();
        if (geod_all_pairs_from(s, src, NSRC, out) != GEOD_OK)
            FAILF("heat solve failed");
        double t2 = now();
        best_f = fmin(best_f, t1 - t0);
        best_s = fmin(best_s, t2 - t1);
        geod_solver_free(s);
    }
    geo_edges e;
    if (geo_edges_build(m, &e, err, sizeof err))
        FAILF("%s", err);
    graph g;
    graph_build(m, &e, &g);
    item *heap = malloc(2 * (size_t)e.ne * sizeof *heap + sizeof *heap);
    for (int trial = 0; trial < 3; trial++) {
        double t0 = now();
        for (int k = 0; k < NSRC; k++)
            dijkstra(&g, m->nv, src[k], out + (size_t)k * m->nv, heap);
        best_d = fmin(best_d, now() - t0);
    }
    printf("FAUST %d vertices, %d sources: heat factorisation %.1f ms + solves %.1f ms = %.1f ms "
           "(%.2f ms/source); edge Dijkstra %.1f ms (%.2f ms/source); heat/Dijkstra %.2fx\n",
           m->nv, NSRC, 1e3 * best_f, 1e3 * best_s, 1e3 * (best_f + best_s),
           1e3 * best_s / NSRC, 1e3 * best_d, 1e3 * best_d / NSRC, (best_f + best_s) / best_d);
    fflush(stdout);
    free(heap);
    free(g.start); free(g.nbr); free(g.len);
    geo_edges_close(&e);
    free(out);
    mesh_free(m);
}

TEST_T(heat_vs_dijkstra_accuracy_sphere, 120)
{
    for (int level = 3; level <= 5; level++) {
        mesh *m = testmesh_icosphere(level);
        char err[256] = "";
        geod_solver *s = NULL;
        geod_solver_new(m, 0, &s, err, sizeof err);
        if (!s)
            FAILF("%s", err);
        double *h = malloc(m->nv * sizeof *h), *d = malloc(m->nv * sizeof *d);
        int src = 0;
        if (geod_distances(s, &src, 1, h) != GEOD_OK)
            FAILF("heat solve failed");
        geo_edges e;
        if (geo_edges_build(m, &e, err, sizeof err))
            FAILF("%s", err);
        graph g;
        graph_build(m, &e, &g);
        item *heap = malloc(2 * (size_t)e.ne * sizeof *heap + sizeof *heap);
        dijkstra(&g, m->nv, src, d, heap);
        double hm = 0, hmean = 0, dm = 0, dmean = 0;
        int n = 0;
        for (int i = 0; i < m->nv; i++) {
            double c = m->v[0] * m->v[3 * i] + m->v[1] * m->v[3 * i + 1] + m->v[2] * m->v[3 * i + 2];
            double ex = acos(fmax(-1, fmin(1, c)));
            if (ex < 0.25)
                continue;
            double rh = fabs(h[i] - ex) / ex, rd = fabs(d[i] - ex) / ex;
            hm = fmax(hm, rh); hmean += rh;
            dm = fmax(dm, rd); dmean += rd;
            n++;
        }
        printf("sphere level %d (%d vertices), relative error beyond 0.25: heat max %.4f mean %.4f; "
               "Dijkstra max %.4f mean %.4f\n", level, m->nv, hm, hmean / n, dm, dmean / n);
        fflush(stdout);
        free(heap);
        free(g.start); free(g.nbr); free(g.len);
        geo_edges_close(&e);
        free(h);
        free(d);
        geod_solver_free(s);
        mesh_free(m);
    }
}
