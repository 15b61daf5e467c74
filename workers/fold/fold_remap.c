/* fold_remap.c — one region re-mapped (fold.h, "remap" and "tube"): its
 * images placed in the chart, its inner vertices placed by its harmonic
 * map (balanced) or by the tube placement, the landmarks dragged when
 * asked, and the inner vertices read back through the chart. */
#include "fold/fold__repair.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A region deeper than this many times its boundary's radius is a part's
 * end (tube_like): re-mapped by the tube placement as well (fold__patch.h),
 * which wins a tie. */
#define FOLD__TUBE_DEPTH 2.0

/* Whether the region's vertex i is pinned where it is mapped: its boundary
 * and the holes filled in (their faces were not bad: a limb's end beyond a
 * bad band round it keeps its map, and only the band is re-mapped, so the
 * harmonic map never crowds a long tube's end into a point). Landmarks are
 * not pinned: a pin folds the harmonic map round it when it is not where
 * that map would put it. They move with the others and get their rows back
 * afterwards; with c->drag_landmarks the placement is then dragged so that
 * each lands at its image (drag). Each region is re-mapped both ways and
 * the accept rule keeps the better. */
static int pinned(const fold__ctx *c, const fold__patch *pS, int i)
{
    return i < pS->nb || c->keep[pS->verts[i]];
}

/* Whether region p (depth: its vertices' depth, fold__depth) is a part's
 * end: deeper than FOLD__TUBE_DEPTH times the radius of the circle as
 * long as its boundary (a disk's depth is once its radius, a hemisphere's
 * 1.6 times). */
static int tube_like(const mesh *S, const fold__patch *p, const double *depth)
{
    double len = 0, deepest = 0;
    for (int i = 0; i < p->nb; i++) {
        const double *a = S->v + 3 * p->verts[i], *b = S->v + 3 * p->verts[(i + 1) % p->nb];
        len += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                    (a[2] - b[2]) * (a[2] - b[2]));
    }
    for (int i = 0; i < p->nv; i++)
        deepest = fmax(deepest, depth[i]);
    return deepest > FOLD__TUBE_DEPTH * len / (2 * M_PI);
}

/* The chart's corners (corner: its faces' chart vertices) and, in uv, the
 * region's images in the chart, its pinned vertices in pin; the chart
 * turned over (uvT) when it is not oriented as T. Returns 0, or 1 when a
 * pinned vertex's image (or a dragged landmark's) lies outside the chart. */
static int images_in_chart(fold__ctx *c, const fold__patch *pS, const fold__patch *pT, double *uvT,
                           int *corner, double *uv, unsigned char *pin)
{
    const mesh *T = c->T;
    for (int i = 0; i < pT->nv; i++)
        c->tloc[pT->verts[i]] = i;
    for (int q = 0; q < pT->nf; q++)
        for (int k = 0; k < 3; k++)
            corner[3 * q + k] = c->tloc[T->f[3 * pT->faces[q] + k]];
    /* the chart is oriented as T when its faces have positive area */
    double sa = 0;
    for (int q = 0; q < pT->nf; q++)
        sa += fold__area2(uvT + 2 * corner[3 * q], uvT + 2 * corner[3 * q + 1], uvT + 2 * corner[3 * q + 2]);
    if (sa < 0)
        for (int i = 0; i < pT->nv; i++)
            uvT[2 * i + 1] = -uvT[2 * i + 1];
    /* the images in the chart (an inner vertex's outside it starts at 0);
     * the boundary and the kept holes pinned there */
    for (int i = 0; i < pS->nv; i++) {
        int v = pS->verts[i], f = c->R->face[v];
        uv[2 * i] = uv[2 * i + 1] = 0;
        pin[i] = c->tube ? i < pS->nb : pinned(c, pS, i);
        /* the image's corners in the chart, by their weights (an image
         * on a face across the chart's edge: its corners inside,
         * renormalised; none inside: outside the chart) */
        double win = 0;
        for (int k = 0; k < 3; k++) {
            int j = c->tloc[T->f[3 * f + k]];
            if (j < 0)
                continue;
            win += c->R->w[3 * v + k];
            uv[2 * i] += c->R->w[3 * v + k] * uvT[2 * j];
            uv[2 * i + 1] += c->R->w[3 * v + k] * uvT[2 * j + 1];
        }
        if (win > 0) {
            uv[2 * i] /= win;
            uv[2 * i + 1] /= win;
            continue;
        }
        if (pin[i] || (c->drag_landmarks && c->fixed[v])) {   /* outside the chart */
            for (int j = 0; j < pT->nv; j++)
                c->tloc[pT->verts[j]] = -1;
            return 1;
        }
    }
    for (int i = 0; i < pT->nv; i++)
        c->tloc[pT->verts[i]] = -1;
    return 0;
}

/* Reads the region's inner vertices (neither pinned nor landmarks) back
 * from their places uv through the chart into c->R. */
static void read_back(fold__ctx *c, const fold__patch *pS, const fold__patch *pT, const int *corner,
                      const double *uvT, const double *uv, const unsigned char *pin)
{
    for (int i = 0; i < pS->nv; i++) {
        int v = pS->verts[i];
        if (pin[i] || c->fixed[v])
            continue;
        double bw[3];
        int bf = fold__locate(pT, corner, uvT, uv + 2 * i, bw);
        if (bf < 0)
            continue;
        c->R->face[v] = pT->faces[bf];
        memcpy(c->R->w + 3 * v, bw, sizeof bw);
    }
}

int fold__remap(fold__ctx *c, const fold__patch *pS)
{
    const mesh *T = c->T;
    fold__patch pT = {0};
    double *uvT = NULL, *dS = NULL, *own = NULL, *dT = NULL;
    double *uv = NULL, *lm = NULL;
    unsigned char *pin = NULL;
    int *corner = NULL;
    int rc = -1;
    double lambda_T = 1;
    if (c->tube) {
        if (!(dS = malloc(sizeof(double) * ((size_t)pS->nv + 1))) || fold__depth(c->S, pS, c->sloc, dS))
            goto out;
        if (!tube_like(c->S, pS, dS)) {
            rc = 1;
            goto out;
        }
    }
    if ((rc = fold__chart(c, pS, &pT, &uvT)))
        goto out;
    rc = -1;
    if (c->tube) {
        /* the chart by depth: its deepest vertex (the part's end) at the centre */
        if (!(dT = malloc(sizeof(double) * ((size_t)pT.nv + 1))) || fold__depth(T, &pT, c->tloc, dT))
            goto out;
        if ((rc = fold__tube_chart(T, &c->ET, &pT, c->tloc, dT, uvT, &lambda_T)))
            goto out;
        rc = -1;
    }
    uv = malloc(sizeof(double) * 2 * ((size_t)pS->nv + 1));
    lm = malloc(sizeof(double) * 2 * ((size_t)pS->nv + 1));
    pin = malloc((size_t)pS->nv + 1);
    corner = malloc(sizeof(int) * 3 * ((size_t)pT.nf + 1));
    if (!uv || !lm || !pin || !corner)
        goto out;
    if ((rc = images_in_chart(c, pS, &pT, uvT, corner, uv, pin)))
        goto out;
    rc = -1;
    memcpy(lm, uv, sizeof(double) * 2 * (size_t)pS->nv);
    if (c->tube) {
        /* the region's own tube chart, fitted inside its boundary's images */
        if (!(own = malloc(sizeof(double) * 2 * ((size_t)pS->nv + 1))))
            goto out;
        double lambda_S;
        if ((rc = fold__tube_chart(c->S, &c->ES, pS, c->sloc, dS, own, &lambda_S)) ||
            (rc = fold__tube_fit(pS, own, lambda_S, lambda_T, uv)))
            goto out;
        rc = -1;
    } else if (fold__harmonic(c->S, &c->ES, pS, pin, NULL, c->sloc, uv) ||
               fold__balance(c, pS, pin, &pT, corner, uvT, uv))
        goto out;
    if (c->drag_landmarks && fold__drag(c, pS, pin, lm, uv))
        goto out;
    c->shift = 0;
    for (int i = 0; i < pS->nv; i++)
        if (!pin[i] && c->fixed[pS->verts[i]])
            c->shift = fmax(c->shift, hypot(uv[2 * i] - lm[2 * i], uv[2 * i + 1] - lm[2 * i + 1]));
    read_back(c, pS, &pT, corner, uvT, uv, pin);
    rc = 0;
out:
    free(uv);
    free(lm);
    free(pin);
    free(corner);
    free(uvT);
    free(dS);
    free(dT);
    free(own);
    fold__patch_close(&pT);
    return rc;
}
