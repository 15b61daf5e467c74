/* metric_curvature.c — the mean-curvature error of a map (metric.h):
 * curvatures of both meshes at unit area, compared through P. */
#include "metric/metric.h"
#include "geo/geo_area.h"
#include "geo/geo_cotan.h"
#include "geo/geo_curvature.h"
#include "geo/geo_edges.h"
#include "geo/geo_normals.h"

#include <math.h>
#include <stdlib.h>

/* H: m->nv mean curvatures of m scaled to unit area; mass: unit-area lumped
 * mass (may be NULL). */
static int unit_curvature(const mesh *m, double *H, double *mass)
{
    geo_edges e = {0};
    geo_csr *L = NULL;
    double *ms = malloc(sizeof(double) * (size_t)m->nv);
    double *vn = malloc(sizeof(double) * 3 * (size_t)m->nv);
    int rc = -1;
    if (!ms || !vn || geo_edges_build(m, &e, NULL, 0) || geo_cotan_laplacian(m, &e, &L, NULL, 0))
        goto out;
    geo_vertex_areas(m, ms);
    geo_vertex_normals(m, vn);
    if (geo_mean_curvature(m, L, ms, vn, H, NULL, 0))
        goto out;
    double s = geo_total_area(m), k = sqrt(s);   /* H scales as 1/length */
    for (int v = 0; v < m->nv; v++) {
        H[v] *= k;
        if (mass)
            mass[v] = ms[v] / s;
    }
    rc = 0;
out:
    geo_edges_close(&e);
    geo_csr_free(L);
    free(ms);
    free(vn);
    return rc;
}

int metric_curvature_error(const mesh *S, const mesh *T, const bmap *P, double *out)
{
    double *H = malloc(sizeof(double) * (size_t)S->nv), *ms = malloc(sizeof(double) * (size_t)S->nv);
    double *Ht = malloc(sizeof(double) * (size_t)T->nv), *PH = malloc(sizeof(double) * (size_t)S->nv);
    int rc = -1;
    *out = NAN;
    if (!H || !ms || !Ht || !PH || unit_curvature(S, H, ms) || unit_curvature(T, Ht, NULL))
        goto out;
    bmap_apply(P, T->f, Ht, 1, PH);
    double sum = 0;
    for (int v = 0; v < S->nv; v++)
        sum += ms[v] * (PH[v] - H[v]) * (PH[v] - H[v]);
    *out = sqrt(sum);
    rc = 0;
out:
    free(H);
    free(ms);
    free(Ht);
    free(PH);
    return rc;
}
