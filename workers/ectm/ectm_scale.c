/* ectm_scale.c — the regional area scale of an initial map, for the
 * membrane's reference metric (ectm_params.scale_reference).
 *
 * A pair that differs in the share of the area its parts take (a
 * caricature's head, a bird's wings) is penalised by a membrane that keeps
 * each face's area: ECTM then moves a good map away from the right points.
 * Given an initial map that keeps areas well on the whole (corr_scale.c
 * decides), the reference metric of each face is grown by the area factor
 * the map gives its region: the log of each face's image area over its own
 * (both meshes at unit area), clamped, smoothed by rounds of face -> vertex
 * -> face averaging so that only the regional scale remains, and centred
 * so that the total area stays. */
#include "ectm/ectm.h"
#include "geo/geo_area.h"
#include "mesh/mesh_check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Rounds of averaging: each reaches about one ring further, so 50 keep
 * the scale of parts and lose that of single faces. */
#define SCALE_ROUNDS 50
/* Bound on a face's area factor before the logs are averaged: an image
 * face collapsed to a point must not dominate its region. */
#define SCALE_CLAMP 16.0

/* One round: each vertex takes the area-weighted mean of its faces' r,
 * each face the mean of its corners'. */
static void smooth_round(const mesh *X, const double *a, double *r, double *vs, double *vw)
{
    memset(vs, 0, sizeof(double) * (size_t)X->nv);
    memset(vw, 0, sizeof(double) * (size_t)X->nv);
    for (int t = 0; t < X->nf; t++)
        for (int k = 0; k < 3; k++) {
            vs[X->f[3 * (size_t)t + k]] += a[t] * r[t];
            vw[X->f[3 * (size_t)t + k]] += a[t];
        }
    for (int t = 0; t < X->nf; t++) {
        double m = 0;
        for (int k = 0; k < 3; k++) {
            int v = X->f[3 * (size_t)t + k];
            m += vw[v] > 0 ? vs[v] / vw[v] : 0;
        }
        r[t] = m / 3;
    }
}

double *ectm_area_scale(const mesh *X, const mesh *Y, const bmap *P)
{
    size_t nf = (size_t)X->nf, nv = (size_t)X->nv;
    double *r = malloc(sizeof(double) * (nf + 1)), *a = malloc(sizeof(double) * (nf + 1));
    double *vs = malloc(sizeof(double) * (nv + 1)), *vw = malloc(sizeof(double) * (nv + 1));
    double *img = malloc(sizeof(double) * (3 * nv + 1));
    if (!r || !a || !vs || !vw || !img) {
        free(r);
        r = NULL;
        goto out;
    }
    bmap_apply(P, Y->f, Y->v, 3, img);   /* X's vertices on Y */
    double AX = geo_total_area(X), AY = geo_total_area(Y);
    geo_face_areas(X, a);
    for (size_t t = 0; t < nf; t++) {
        double q = (mesh_face_area(img, X->f + 3 * t, NULL) / AY) / (a[t] / AX);
        q = q > 1.0 / SCALE_CLAMP ? q : 1.0 / SCALE_CLAMP;   /* NaN too */
        r[t] = log(q < SCALE_CLAMP ? q : SCALE_CLAMP);
    }
    for (int it = 0; it < SCALE_ROUNDS; it++)
        smooth_round(X, a, r, vs, vw);
    double ms = 0, mw = 0;
    for (size_t t = 0; t < nf; t++) {
        ms += a[t] * r[t];
        mw += a[t];
    }
    for (size_t t = 0; t < nf; t++)
        r[t] = exp(r[t] - ms / mw);
out:
    free(a);
    free(vs);
    free(vw);
    free(img);
    return r;
}
