/* metric_curvature.c — the mean-curvature error of a map (metric.h):
 * curvatures of both meshes at unit area, by one neighbourhood fit,
 * compared through P. */
#include "metric/metric.h"
#include "geo/geo_area.h"
#include "geo/geo_curvature.h"
#include "geo/geo_edges.h"
#include "geo/geo_normals.h"

#include <math.h>
#include <stdlib.h>

/* Mean edge length of m over the square root of its area. */
static double unit_edge(const mesh *m, const geo_edges *e)
{
    double sum = 0;
    for (int k = 0; k < e->ne; k++) {
        const double *a = m->v + 3 * (size_t)e->ev[2 * k], *b = m->v + 3 * (size_t)e->ev[2 * k + 1];
        sum += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    }
    return e->ne ? sum / e->ne / sqrt(geo_total_area(m)) : 0;
}

/* H: m->nv mean curvatures of m scaled to unit area, fitted within
 * `radius` (unit-area scale); mass: unit-area lumped mass (may be NULL). */
static int unit_curvature(const mesh *m, const geo_edges *e, double radius, double *H, double *mass)
{
    double *vn = malloc(sizeof(double) * 3 * (size_t)m->nv);
    double s = geo_total_area(m), k = sqrt(s);   /* H scales as 1/length */
    int rc = -1;
    if (!vn)
        return -1;
    geo_vertex_normals(m, vn);
    if (geo_mean_curvature_fit(m, e, vn, radius * k, H, NULL, 0))
        goto out;
    for (int v = 0; v < m->nv; v++)
        H[v] *= k;
    if (mass) {
        geo_vertex_areas(m, mass);
        for (int v = 0; v < m->nv; v++)
            mass[v] /= s;
    }
    rc = 0;
out:
    free(vn);
    return rc;
}

int metric_curvature_error(const mesh *S, const mesh *T, const bmap *P, double *out)
{
    double *H = malloc(sizeof(double) * (size_t)S->nv), *ms = malloc(sizeof(double) * (size_t)S->nv);
    double *Ht = malloc(sizeof(double) * (size_t)T->nv), *PH = malloc(sizeof(double) * (size_t)S->nv);
    geo_edges es = {0}, et = {0};
    int rc = -1;
    *out = NAN;
    if (!H || !ms || !Ht || !PH || geo_edges_build(S, &es, NULL, 0) || geo_edges_build(T, &et, NULL, 0))
        goto out;
    double radius = METRIC_CURVATURE_EDGES * fmax(unit_edge(S, &es), unit_edge(T, &et));
    if (unit_curvature(S, &es, radius, H, ms) || unit_curvature(T, &et, radius, Ht, NULL))
        goto out;
    bmap_apply(P, T->f, Ht, 1, PH);
    double sum = 0;
    for (int v = 0; v < S->nv; v++)
        sum += ms[v] * (PH[v] - H[v]) * (PH[v] - H[v]);
    *out = sqrt(sum);
    rc = 0;
out:
    geo_edges_close(&es);
    geo_edges_close(&et);
    free(H);
    free(ms);
    free(Ht);
    free(PH);
    return rc;
}
