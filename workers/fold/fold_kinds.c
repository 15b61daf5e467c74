/* fold_kinds.c — see fold__kinds.h: the bad faces of a map, and the
 * checks and tables the repair and the relaxation start with. */
#include "fold/fold__kinds.h"
#include "geo/geo_area.h"
#include "geo/geo_normals.h"
#include "metric/metric.h"

#include <math.h>
#include <stdlib.h>

int fold__face_kind(const mesh *S, const mesh *T, const bmap *P, const double *img,
                    const double *tn, double area_S, double area_T, int t)
{
    double lr;
    int k = metric_face_kind(S, T, P, img, tn, area_S, area_T, t, &lr);
    return k == METRIC_FACE_OK && !(lr >= log(FOLD__CROWDED)) ? FOLD__FACE_CROWDED : k;
}

int fold__kinds(const mesh *S, const mesh *T, const bmap *P, unsigned char *kind)
{
    double *img = malloc(sizeof(double) * (3 * (size_t)S->nv + 1));
    double *tn = malloc(sizeof(double) * (3 * (size_t)T->nv + 1));
    int bad = -1;
    if (img && tn) {
        bmap_apply(P, T->f, T->v, 3, img);
        geo_vertex_normals(T, tn);
        double aS = geo_total_area(S), aT = geo_total_area(T);
        bad = 0;
        for (int t = 0; t < S->nf; t++)
            bad += (kind[t] = (unsigned char)fold__face_kind(S, T, P, img, tn, aS, aT, t)) !=
                   METRIC_FACE_OK;
    }
    free(img);
    free(tn);
    return bad;
}

int fold__map_ok(const mesh *S, const mesh *T, const bmap *P)
{
    if (!S || !T || !P || P->n != S->nv || P->nt != T->nv)
        return 0;
    for (int v = 0; v < P->n; v++)
        if (P->face[v] < 0 || P->face[v] >= T->nf)
            return 0;
    return 1;
}

int fold__open(const mesh *S, const mesh *T, const bmap *P, unsigned char *kind, geo_edges *ES,
               geo_edges *ET, fold_report *rep, int *bad)
{
    if ((*bad = fold__kinds(S, T, P, kind)) < 0)
        return FOLD_ENOMEM;
    rep->bad_before = rep->bad_after = *bad;
    char err[128];
    if (*bad && (geo_edges_build(S, ES, err, sizeof err) || geo_edges_build(T, ET, err, sizeof err)))
        return FOLD_EMESH;
    return FOLD_OK;
}
