/* repair_components.c — the pieces of a mesh, largest first, and the
 * nearest kept point for what is left out (repair.h). The engine matches
 * connected surfaces: the pieces kept are matched, a vertex on another
 * piece, or in no face, takes the map of the nearest kept vertex. */
#include "repair/repair.h"
#include "mesh/mesh_check.h"
#include "repair/repair__sort.h"

#include <math.h>
#include <stdlib.h>

static int find(int *par, int x)
{
    while (par[x] != x) {
        par[x] = par[par[x]];
        x = par[x];
    }
    return x;
}

/* A piece and its area, for the order by decreasing area (ties: the
 * piece whose first face comes first). */
typedef struct piece_area { int k; double a; } piece_area;

static int by_area(const void *x, const void *y, void *ctx)
{
    (void)ctx;
    const piece_area *p = x, *q = y;
    if (p->a != q->a)
        return p->a > q->a ? -1 : 1;
    return (p->k > q->k) - (p->k < q->k);
}

int repair_components(const double *v, int nv, const int *f, int nf, int *piece)
{
    int *par = malloc(sizeof *par * ((size_t)nv + 1));
    int *label = malloc(sizeof *label * ((size_t)nv + 1));
    int *rank = NULL;
    piece_area *pa = NULL;
    int np = 0, rc = -1;
    if (!par || !label)
        goto out;
    for (int i = 0; i < nv; i++) {
        par[i] = i;
        label[i] = -1;
    }
    for (int t = 0; t < nf; t++)
        for (int k = 1; k < 3; k++) {
            int x = find(par, f[3 * (size_t)t]), y = find(par, f[3 * (size_t)t + k]);
            if (x != y)
                par[x < y ? y : x] = x < y ? x : y;
        }
    for (int t = 0; t < nf; t++) {
        int r = find(par, f[3 * (size_t)t]);
        if (label[r] < 0)
            label[r] = np++;
    }
    if (!(pa = calloc((size_t)np + 1, sizeof *pa)) || !(rank = malloc(sizeof *rank * ((size_t)np + 1))))
        goto out;
    for (int k = 0; k < np; k++)
        pa[k].k = k;
    for (int t = 0; t < nf; t++)
        pa[label[find(par, f[3 * (size_t)t])]].a += mesh_face_area(v, f + 3 * (size_t)t, NULL);
    if (repair__sort(pa, (size_t)np, sizeof *pa, by_area, NULL))
        goto out;
    for (int i = 0; i < np; i++)
        rank[pa[i].k] = i;
    for (int t = 0; t < nf; t++)
        piece[t] = rank[label[find(par, f[3 * (size_t)t])]];
    rc = np;
out:
    free(par);
    free(label);
    free(rank);
    free(pa);
    return rc;
}

static int by_x(const void *a, const void *b, void *ctx)
{
    const double *p = ctx;
    double x = p[3 * (size_t)*(const int *)a], y = p[3 * (size_t)*(const int *)b];
    return (x > y) - (x < y);
}

/* Points sorted by x; a query walks out both ways from its x and stops
 * once the x gap alone is over the best distance found. */
int repair_nearest(const double *p, int np, const double *q, int nq, int *out)
{
    int *o = malloc(sizeof *o * ((size_t)np + 1));
    if (!o)
        return -1;
    for (int i = 0; i < np; i++)
        o[i] = i;
    if (repair__sort(o, (size_t)np, sizeof *o, by_x, (void *)p)) {
        free(o);
        return -1;
    }
    for (int j = 0; j < nq; j++) {
        const double *x = q + 3 * (size_t)j;
        int lo = 0, hi = np;                 /* first sorted point with p.x >= x.x */
        while (lo < hi) {
            int mid = lo + (hi - lo) / 2;
            if (p[3 * (size_t)o[mid]] < x[0])
                lo = mid + 1;
            else
                hi = mid;
        }
        double best = INFINITY;
        int arg = o[lo < np ? lo : np - 1];
        for (int dir = -1; dir <= 1; dir += 2)
            for (int i = dir < 0 ? lo - 1 : lo; i >= 0 && i < np; i += dir) {
                const double *y = p + 3 * (size_t)o[i];
                double dx = y[0] - x[0];
                if (dx * dx > best)
                    break;
                double d = dx * dx + (y[1] - x[1]) * (y[1] - x[1]) + (y[2] - x[2]) * (y[2] - x[2]);
                if (d < best || (d == best && o[i] < arg)) {
                    best = d;
                    arg = o[i];
                }
            }
        out[j] = arg;
    }
    free(o);
    return 0;
}
