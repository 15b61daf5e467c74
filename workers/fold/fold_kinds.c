/* fold_kinds.c — see fold__kinds.h: the bad faces of a map, and the
 * checks and tables the repair and the relaxation start with. */
#include "fold/fold__kinds.h"
#include "geo/geo_area.h"
#include "metric/metric.h"

#include <math.h>
#include <stdlib.h>

int fold__kinds(const mesh *S, const mesh *T, const bmap *P, unsigned char *kind)
{
    int bad = metric_fold_faces(S, T, P, kind);
    double *img = malloc(sizeof(double) * (3 * (size_t)S->nv + 1));
    double *lr = malloc(sizeof(double) * ((size_t)S->nf + 1));
    if (bad < 0 || !img || !lr) {
        free(img);
        free(lr);
        return -1;
    }
    bmap_apply(P, T->f, T->v, 3, img);
    metric_area_distortion(S, img, geo_total_area(S), geo_total_area(T), lr);
    for (int t = 0; t < S->nf; t++)
        if (kind[t] == METRIC_FACE_OK && !(lr[t] >= log(FOLD__CROWDED))) {
            kind[t] = FOLD__FACE_CROWDED;
            bad++;
        }
    free(img);
    free(lr);
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
