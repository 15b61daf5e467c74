/* repair_split.c — non-manifold edges and vertices are split (repair.h).
 * Face corners are joined across every edge with exactly two faces that
 * run it in opposite directions; an edge with more faces (or two the same
 * way) joins nothing and becomes a boundary of each of them. The corners
 * of a vertex then fall into fans, and each fan becomes a vertex of its
 * own: a pinched vertex becomes two, and a weld that pinched two surfaces
 * together comes apart again. New vertices are numbered by old vertex,
 * then fan, so a mesh that needs nothing keeps its numbering. */
#include "repair/repair.h"
#include "repair/repair__edges.h"

#include <stdlib.h>

static int find(int *par, int x)
{
    while (par[x] != x) {
        par[x] = par[par[x]];
        x = par[x];
    }
    return x;
}

static void join(int *par, int x, int y)
{
    x = find(par, x);
    y = find(par, y);
    if (x != y)
        par[x < y ? y : x] = x < y ? x : y;
}

int repair_split(int nv, const int *f, int nf, int **out_f, int **out_vert, int *out_nv,
                 int *split_edges, int *split_vertices)
{
    int nh = 3 * nf, rc = -1;
    *out_f = *out_vert = NULL;
    *split_edges = *split_vertices = 0;
    repair__half *h = repair__edges(f, nf);
    int *par = malloc(sizeof *par * ((size_t)nh + 1));
    int *first = malloc(sizeof *first * ((size_t)nv + 2));   /* per vertex: its first new id */
    int *fans = calloc((size_t)nv + 2, sizeof *fans);
    int *id = malloc(sizeof *id * ((size_t)nh + 1));          /* per root corner: new vertex */
    int *nf_ = malloc(sizeof *nf_ * ((size_t)nh + 1));
    int *vert = NULL;
    if (!h || !par || !first || !fans || !id || !nf_)
        goto out;
    for (int c = 0; c < nh; c++)
        par[c] = c;
    for (int i = 0; i < nh;) {
        int j = repair__edge_end(h, nh, i);
        if (j - i == 2 && h[i].fwd != h[i + 1].fwd) {
            /* corners of a in both faces, and of b */
            int ta = h[i].t, ka = h[i].k, tb = h[i + 1].t, kb = h[i + 1].k;
            /* face t runs corner k -> k+1: the corner of vertex a is k when fwd */
            int a1 = 3 * ta + (h[i].fwd ? ka : (ka + 1) % 3);
            int b1 = 3 * ta + (h[i].fwd ? (ka + 1) % 3 : ka);
            int a2 = 3 * tb + (h[i + 1].fwd ? kb : (kb + 1) % 3);
            int b2 = 3 * tb + (h[i + 1].fwd ? (kb + 1) % 3 : kb);
            join(par, a1, a2);
            join(par, b1, b2);
        } else if (j - i >= 2) {
            ++*split_edges;
        }
        i = j;
    }
    for (int c = 0; c < nh; c++)
        if (find(par, c) == c)
            fans[f[c]]++;
    int n = 0, used = 0;
    for (int v = 0; v < nv; v++) {
        first[v] = n;
        n += fans[v];
        if (fans[v]) {
            used++;
            fans[v] = 0;      /* now: fans numbered so far */
        }
    }
    *split_vertices = n - used;
    if (!(vert = malloc(sizeof *vert * ((size_t)n + 1))))
        goto out;
    for (int c = 0; c < nh; c++)            /* roots come first in their sets */
        if (find(par, c) == c) {
            id[c] = first[f[c]] + fans[f[c]]++;
            vert[id[c]] = f[c];
        }
    for (int c = 0; c < nh; c++)
        nf_[c] = id[find(par, c)];
    *out_f = nf_;
    *out_vert = vert;
    *out_nv = n;
    nf_ = vert = NULL;
    rc = 0;
out:
    free(h);
    free(par);
    free(first);
    free(fans);
    free(id);
    free(nf_);
    free(vert);
    return rc;
}
