/* metric_curvature.c — the mean-curvature error of a map (metric.h):
 * curvatures of both meshes at unit area, by one neighbourhood fit,
 * compared through P. */
#include "metric/metric.h"
#include "geo/geo_area.h"
#include "geo/geo_curvature.h"
#include "geo/geo_edges.h"
#include "geo/geo_normals.h"
#include "util/errbuf.h"

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
 * `radius` (unit-area scale); mass: unit-area lumped mass (may be NULL).
 * METRIC_OK, METRIC_ENOMEM or METRIC_EMESH with "name: why" in err. */
static int unit_curvature(const mesh *m, const char *name, const geo_edges *e, double radius,
                          double *H, double *mass, char *err, size_t errsz)
{
    double *vn = malloc(sizeof(double) * 3 * (size_t)m->nv);
    double s = geo_total_area(m), k = sqrt(s);   /* H scales as 1/length */
    char why[256];
    if (!vn)
        return errbuf_set(err, errsz, METRIC_ENOMEM, "out of memory");
    geo_vertex_normals(m, vn);
    int rc = geo_mean_curvature_fit(m, e, vn, radius * k, H, why, sizeof why);
    if (rc) {
        rc = errbuf_set(err, errsz, rc == GEO_ENOMEM ? METRIC_ENOMEM : METRIC_EMESH,
                        "%s: mean curvature: %s", name, why);
        goto out;
    }
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

/* The edge table of m, or METRIC_ENOMEM / METRIC_EMESH ("name: why"). */
static int edges_of(const mesh *m, const char *name, geo_edges *e, char *err, size_t errsz)
{
    char why[256];
    int rc = geo_edges_build(m, e, why, sizeof why);
    if (rc)
        return errbuf_set(err, errsz, rc == GEO_ENOMEM ? METRIC_ENOMEM : METRIC_EMESH, "%s: %s", name, why);
    return METRIC_OK;
}

int metric_curvature_error(const mesh *S, const mesh *T, const bmap *P, double *out, char *err,
                           size_t errsz)
{
    double *H = malloc(sizeof(double) * (size_t)S->nv), *ms = malloc(sizeof(double) * (size_t)S->nv);
    double *Ht = malloc(sizeof(double) * (size_t)T->nv), *PH = malloc(sizeof(double) * (size_t)S->nv);
    geo_edges es = {0}, et = {0};
    int rc = METRIC_ENOMEM;
    *out = NAN;
    if (!H || !ms || !Ht || !PH) {
        errbuf_set(err, errsz, rc, "out of memory");
        goto out;
    }
    if ((rc = edges_of(S, "source mesh", &es, err, errsz)) || (rc = edges_of(T, "target mesh", &et, err, errsz)))
        goto out;
    double radius = METRIC_CURVATURE_EDGES * fmax(unit_edge(S, &es), unit_edge(T, &et));
    if ((rc = unit_curvature(S, "source mesh", &es, radius, H, ms, err, errsz)) ||
        (rc = unit_curvature(T, "target mesh", &et, radius, Ht, NULL, err, errsz)))
        goto out;
    bmap_apply(P, T->f, Ht, 1, PH);
    double sum = 0;
    for (int v = 0; v < S->nv; v++)
        sum += ms[v] * (PH[v] - H[v]) * (PH[v] - H[v]);
    *out = sqrt(sum);
    rc = METRIC_OK;
out:
    geo_edges_close(&es);
    geo_edges_close(&et);
    free(H);
    free(ms);
    free(Ht);
    free(PH);
    return rc;
}
