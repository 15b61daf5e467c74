/* testgt.c — see testgt.h. */
#include "support/testgt.h"
#include "support/harness.h"

#include <math.h>
#include <stdlib.h>

static int *read_vts(const char *rel, int n, int nv)
{
    FILE *fp = fopen(harness_data_path(rel), "r");
    if (!fp)
        FAILF("cannot open %s", rel);
    int *ids = malloc(sizeof(int) * (size_t)n);
    for (int k = 0; k < n; k++) {
        if (fscanf(fp, "%d", &ids[k]) != 1 || ids[k] < 1 || ids[k] > nv)
            FAILF("%s: line %d unreadable", rel, k + 1);
        ids[k]--;
    }
    fclose(fp);
    return ids;
}

void testgt_faust(testgt *g, int nl)
{
    char err[512];
    const char *dir = "faust_r/vtx_5k/";
    char p[256];
    snprintf(p, sizeof p, "%str_reg_000.off", dir);
    if (mesh_read(harness_data_path(p), &g->S, err, sizeof err))
        FAILF("%s", err);
    snprintf(p, sizeof p, "%str_reg_001.off", dir);
    if (mesh_read(harness_data_path(p), &g->T, err, sizeof err))
        FAILF("%s", err);
    g->n = 5000;
    g->src = read_vts("faust_r/vtx_5k/corres/tr_reg_000.vts", g->n, g->S->nv);
    g->tgt = read_vts("faust_r/vtx_5k/corres/tr_reg_001.vts", g->n, g->T->nv);
    g->L.n = nl;
    g->L.src = malloc(sizeof(int) * (size_t)nl);
    g->L.tgt = malloc(sizeof(int) * (size_t)nl);
    double *d = malloc(sizeof(double) * (size_t)g->n);
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

void testgt_close(testgt *g)
{
    mesh_free(g->S);
    mesh_free(g->T);
    free(g->src);
    free(g->tgt);
    free(g->L.src);
    free(g->L.tgt);
}
