/* fold_chart.c — the chart of a region (fold.h, "chart"): the target
 * faces its pinned vertices land in, grown to one hole-free disk and placed
 * in the unit disk by its harmonic map; and the plane and target points
 * that the remap reads through it. */
#include "fold/fold__repair.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A chart may take at most this share of the target's faces: beyond that
 * the map is wrong on a whole part (a limb), which a local repair cannot
 * decide. */
#define FOLD__MAX_CHART 0.5
#define FOLD__CHART_RINGS 2       /* rings round the boundary image, at least */
/* ... and at most (FOLD__MAX_CHART bounds it as well): the ring round a
 * thin part and the part's end kept beyond it can land a long way apart on
 * the target (a pair of glasses' arms: a low cap would leave no chart and no
 * repair at all) */
#define FOLD__CHART_MAX_RINGS 30

/* Whether the region's vertex i places the chart: its boundary and kept
 * holes, and for a remap that drags the landmarks (c->drag_landmarks) its
 * landmarks too: the drag must reach their images, and these may lie
 * beyond what the boundary's image encloses (a limb whose boundary lands high
 * on the target's limb while its landmarks' images lie far down it).
 * A free remap's chart leaves them out: their images may lie far inside
 * the part the boundary encloses (a limb's tip), and they get their rows
 * back anyway. */
static int anchored(const fold__ctx *c, const fold__patch *pS, int i)
{
    return i < pS->nb || c->keep[pS->verts[i]] || (c->drag_landmarks && c->fixed[pS->verts[i]]);
}

int fold__chart(fold__ctx *c, const fold__patch *pS, fold__patch *pT, double **uvT)
{
    const mesh *T = c->T;
    *uvT = NULL;
    /* the faces the boundary (and the kept holes) land in, grown until they
     * are one piece: a band round the boundary's image, whose holes then
     * fill with what lies inside it. Inner vertices' images do not count:
     * those that jumped elsewhere are re-mapped anyway. */
    memset(c->tin, 0, (size_t)T->nf);
    for (int i = 0; i < pS->nv; i++)
        if (anchored(c, pS, i))
            c->tin[c->R->face[pS->verts[i]]] = 1;
    int n = 0, best = 0;
    for (int r = 0; r < FOLD__CHART_MAX_RINGS; r++) {
        fold__grow(T, c->tin, 1, c->tmark);
        if (r + 1 < FOLD__CHART_RINGS)
            continue;
        if ((n = fold__components(&c->ET, c->tin, c->tcomp)) < 0)
            return -1;
        best = c->tcomp[c->R->face[pS->verts[0]]];
        int one = 1;
        for (int i = 0; i < pS->nv && one; i++)
            if (anchored(c, pS, i))
                one = c->tcomp[c->R->face[pS->verts[i]]] == best;
        if (one)
            break;
        best = -1;
    }
    if (best < 0)
        return 1;                  /* the boundary's image is torn apart */
    for (int t = 0; t < T->nf; t++)
        c->tin[t] = c->tcomp[t] == best;
    int size = fold__fill_holes(&c->ET, c->tin);
    if (size < 0)
        return -1;
    if (size > FOLD__MAX_CHART * T->nf)
        return 1;
    int rc = fold__disk(T, &c->ET, c->tin, c->tloc, pT);
    if (rc)
        return rc;
    double *uv = malloc(sizeof(double) * (2 * (size_t)pT->nv + 1));
    if (!uv || fold__disk_place(T, &c->ET, pT, c->tloc, uv)) {
        free(uv);
        fold__patch_close(pT);
        return -1;
    }
    *uvT = uv;
    return 0;
}

double fold__area2(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

void fold__point(const mesh *T, int face, const double *w, double *x)
{
    const int *tf = T->f + 3 * face;
    for (int d = 0; d < 3; d++)
        x[d] = w[0] * T->v[3 * tf[0] + d] + w[1] * T->v[3 * tf[1] + d] + w[2] * T->v[3 * tf[2] + d];
}

int fold__locate(const fold__patch *pT, const int *corner, const double *uvT, const double *x,
                 double bw[3])
{
    int bf = -1;
    double bmin = -INFINITY;
    for (int q = 0; q < pT->nf; q++) {
        const double *a = uvT + 2 * corner[3 * q], *b = uvT + 2 * corner[3 * q + 1],
                     *d = uvT + 2 * corner[3 * q + 2];
        double A = fold__area2(a, b, d);
        if (!(fabs(A) > 0))
            continue;
        double w[3] = { fold__area2(x, b, d) / A, fold__area2(a, x, d) / A, fold__area2(a, b, x) / A };
        double m = fmin(w[0], fmin(w[1], w[2]));
        if (m > bmin) {
            bmin = m;
            bf = q;
            memcpy(bw, w, 3 * sizeof(double));
            if (m >= 0)
                break;
        }
    }
    if (bf >= 0) {
        double sum = 0;
        for (int k = 0; k < 3; k++)
            sum += bw[k] = fmax(bw[k], 0);
        for (int k = 0; k < 3; k++)
            bw[k] /= sum;
    }
    return bf;
}
