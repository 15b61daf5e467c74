/* metric_geodesic.c — geodesic error of maps against a ground truth and its
 * cumulative curve (metric.h). Distance fields are computed per distinct
 * ground-truth target vertex, GEOD_BATCH at a time, and shared by all maps. */
#include "metric/metric.h"
#include "geo/geo_area.h"

#include <math.h>
#include <stdlib.h>

static int cmp_ll(const void *a, const void *b)
{
    long long x = *(const long long *)a, y = *(const long long *)b;
    return x < y ? -1 : x > y;
}

int metric_geodesic_errors(geod_solver *gT, const mesh *T, const bmap *const *maps, int nmaps,
                           const int *src, const int *tgt, int n, double *err)
{
    long long *key = malloc(sizeof(long long) * ((size_t)n + 1));
    int *order = malloc(sizeof(int) * ((size_t)n + 1));
    int *srcs = malloc(sizeof(int) * GEOD_BATCH);
    double *fields = malloc(sizeof(double) * GEOD_BATCH * (size_t)T->nv);
    int rc = -1;
    if (!key || !order || !srcs || !fields)
        goto out;
    /* pairs sorted by target vertex: each batch takes whole runs */
    for (int k = 0; k < n; k++)
        key[k] = (long long)tgt[k] << 32 | k;
    qsort(key, (size_t)n, sizeof *key, cmp_ll);
    for (int k = 0; k < n; k++)
        order[k] = (int)(key[k] & 0xffffffffLL);
    double norm = 1 / sqrt(geo_total_area(T));
    for (int k0 = 0; k0 < n;) {
        int nb = 0, k1 = k0;
        while (k1 < n && (nb < GEOD_BATCH || tgt[order[k1]] == srcs[nb - 1])) {
            if (nb == 0 || tgt[order[k1]] != srcs[nb - 1])
                srcs[nb++] = tgt[order[k1]];
            k1++;
        }
        if ((rc = geod_all_pairs_from(gT, srcs, nb, fields)))
            goto out;
        rc = -1;
        for (int b = 0, k = k0; k < k1; k++) {
            int pk = order[k];
            while (srcs[b] != tgt[pk])
                b++;
            const double *dist = fields + (size_t)b * T->nv;
            for (int a = 0; a < nmaps; a++) {
                const bmap *P = maps[a];
                const int *f = T->f + 3 * P->face[src[pk]];
                const double *w = P->w + 3 * src[pk];
                err[(size_t)a * n + pk] = norm * (w[0] * dist[f[0]] + w[1] * dist[f[1]] + w[2] * dist[f[2]]);
            }
        }
        k0 = k1;
    }
    rc = 0;
out:
    free(key);
    free(order);
    free(srcs);
    free(fields);
    return rc;
}

void metric_error_curve(const double *err, int n, double tmax, int nsteps, double *curve)
{
    for (int s = 0; s < nsteps; s++) {
        double t = nsteps > 1 ? tmax * s / (nsteps - 1) : tmax;
        int c = 0;
        for (int k = 0; k < n; k++)
            c += err[k] <= t;
        curve[s] = n ? (double)c / n : NAN;
    }
}
