/* testgt.c — see testgt.h. */
#include "support/testgt.h"
#include "support/harness.h"
#include "geo/geo_area.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static mesh *read_mesh(const char *rel)
{
    char err[512];
    mesh *m = NULL;
    if (mesh_read(harness_data_path(rel), &m, err, sizeof err))
        FAILF("%s", err);
    return m;
}

/* ids of rel; fails the test unless there are n of them (n < 0: any). */
static int *read_ids(const char *rel, int base, int nv, int n, int *count)
{
    char err[512];
    int *ids, len;
    if (lmk_read_ids(harness_data_path(rel), base, nv, TESTGT_MAX_LINES, &ids, &len, err, sizeof err))
        FAILF("%s", err);
    if (len == 0)
        FAILF("%s: no vertex ids", rel);
    if (n >= 0 && len != n)
        FAILF("%s: %d lines, expected %d", rel, len, n);
    if (count)
        *count = len;
    return ids;
}

static void pick_landmarks(testgt *g, int nl)
{
    g->L.n = nl;
    g->L.src = malloc(sizeof(int) * (size_t)nl);
    g->L.tgt = malloc(sizeof(int) * (size_t)nl);
    double *d = malloc(sizeof(double) * (size_t)g->n);
    if (!g->L.src || !g->L.tgt || !d)
        FAILF("out of memory");
    for (int k = 0; k < g->n; k++)
        d[k] = INFINITY;
    int pick = 0;
    for (int r = 0; r < nl; r++) {
        g->L.src[r] = g->src[pick];
        g->L.tgt[r] = g->tgt[pick];
        const double *x = g->S->v + 3 * g->src[pick];
        int best = 0;
        for (int k = 0; k < g->n; k++) {
            const double *y = g->S->v + 3 * g->src[k];
            double e = sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                            (x[2] - y[2]) * (x[2] - y[2]));
            if (e < d[k])
                d[k] = e;
            if (d[k] > d[best])
                best = k;
        }
        pick = best;
    }
    free(d);
}

void testgt_vts(testgt *g, const char *dir, const char *a, const char *b, int nl)
{
    memset(g, 0, sizeof *g);
    char p[1024];
    snprintf(p, sizeof p, "%s/%s.off", dir, a);
    g->S = read_mesh(p);
    snprintf(p, sizeof p, "%s/%s.off", dir, b);
    g->T = read_mesh(p);
    snprintf(p, sizeof p, "%s/corres/%s.vts", dir, a);
    g->src = read_ids(p, 1, g->S->nv, -1, &g->n);
    snprintf(p, sizeof p, "%s/corres/%s.vts", dir, b);
    g->tgt = read_ids(p, 1, g->T->nv, g->n, NULL);
    snprintf(p, sizeof p, "%s/corres/%s.sym.vts", dir, b);
    if (access(harness_data_path(p), F_OK) == 0)
        g->tgt_sym = read_ids(p, 1, g->T->nv, g->n, NULL);
    pick_landmarks(g, nl);
}

void testgt_vertex_list(testgt *g, const char *S_rel, const char *T_rel, const char *gt_rel,
                        int nl)
{
    memset(g, 0, sizeof *g);
    g->S = read_mesh(S_rel);
    g->T = read_mesh(T_rel);
    g->n = g->S->nv;
    g->tgt = read_ids(gt_rel, 0, g->T->nv, g->n, NULL);
    g->src = malloc(sizeof(int) * (size_t)g->n);
    if (!g->src)
        FAILF("out of memory");
    for (int k = 0; k < g->n; k++)
        g->src[k] = k;
    pick_landmarks(g, nl);
}

void testgt_faust(testgt *g, int nl)
{
    testgt_vts(g, "faust_r/vtx_5k", "tr_reg_000", "tr_reg_001", nl);
}

void testgt_close(testgt *g)
{
    mesh_free(g->S);
    mesh_free(g->T);
    free(g->src);
    free(g->tgt);
    free(g->tgt_sym);
    free(g->L.src);
    free(g->L.tgt);
}

double testgt_identity_error(const mesh *S, const mesh *T, const bmap *P)
{
    double e = 0;
    for (int v = 0; v < S->nv; v++) {
        const int *f = T->f + 3 * P->face[v];
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double x = 0;
            for (int c = 0; c < 3; c++)
                x += P->w[3 * v + c] * T->v[3 * f[c] + k];
            d2 += (x - T->v[3 * v + k]) * (x - T->v[3 * v + k]);
        }
        e += sqrt(d2);
    }
    return e / (S->nv * sqrt(geo_total_area(T)));
}

lmk_set *testgt_pid_landmarks(const char *pid_rel, const mesh *S, const mesh *T)
{
    char err[1024];
    int *ids, n;
    if (lmk_read_ids(harness_data_path(pid_rel), 0, S->nv, 1000, &ids, &n, err, sizeof err))
        FAILF("%s", err);
    long *ls = malloc(sizeof(long) * ((size_t)n + 1));
    if (!ls)
        FAILF("out of memory");
    for (int r = 0; r < n; r++)
        ls[r] = ids[r];
    lmk_set *L = NULL;
    if (lmk_from_arrays(ls, ls, n, 0, "source", "target", S, T, &L, err, sizeof err))
        FAILF("%s", err);
    free(ls);
    free(ids);
    return L;
}
