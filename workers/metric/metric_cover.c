/* metric_cover.c — how far a map is from a bijection (metric.h): the share
 * of the target it covers and the round trip through a reverse map. */
#include "metric/metric.h"
#include "geo/geo_area.h"

#include <math.h>
#include <stdlib.h>

double metric_coverage(const mesh *T, const bmap *P, double radius)
{
    double *img = malloc(sizeof(double) * 3 * ((size_t)P->n + 1));
    double *mass = malloc(sizeof(double) * ((size_t)T->nv + 1));
    double covered = 0, total = 0;
    if (!img || !mass) {
        free(img);
        free(mass);
        return NAN;
    }
    bmap_apply(P, T->f, T->v, 3, img);
    geo_vertex_areas(T, mass);
    double r = radius * sqrt(geo_total_area(T)), r2 = r * r;
    #pragma omp parallel for reduction(+:covered, total) schedule(static)
    for (int v = 0; v < T->nv; v++) {
        const double *x = T->v + 3 * v;
        int hit = 0;
        for (int k = 0; k < P->n && !hit; k++) {
            const double *y = img + 3 * k;
            double d2 = (x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                        (x[2] - y[2]) * (x[2] - y[2]);
            hit = d2 <= r2;
        }
        total += mass[v];
        covered += hit ? mass[v] : 0;
    }
    free(img);
    free(mass);
    return total > 0 ? covered / total : NAN;
}

int metric_round_trip(const mesh *S, const mesh *T, const bmap *P, const bmap *Q, double *out)
{
    double *PX = malloc(sizeof(double) * 3 * (size_t)S->nv);
    double *QPX = malloc(sizeof(double) * 3 * (size_t)T->nv);
    double *mass = malloc(sizeof(double) * (size_t)T->nv);
    *out = NAN;
    if (!PX || !QPX || !mass) {
        free(PX);
        free(QPX);
        free(mass);
        return -1;
    }
    bmap_apply(P, T->f, T->v, 3, PX);
    bmap_apply(Q, S->f, PX, 3, QPX);
    geo_vertex_areas(T, mass);
    double s = geo_total_area(T), sum = 0;
    for (int v = 0; v < T->nv; v++) {
        double d2 = 0;
        for (int c = 0; c < 3; c++)
            d2 += (QPX[3 * v + c] - T->v[3 * v + c]) * (QPX[3 * v + c] - T->v[3 * v + c]);
        sum += mass[v] * d2;
    }
    /* unit area: mass / s, squared lengths / s */
    *out = sqrt(sum / (s * s));
    free(PX);
    free(QPX);
    free(mass);
    return 0;
}
