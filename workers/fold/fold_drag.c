/* fold_drag.c — a region's placement dragged so that each landmark lands
 * at its image (fold.h: the dragged remap), in steps that fold no more
 * faces than before. */
#include "fold/fold__repair.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FOLD__DRAG_STEPS 200      /* steps of a landmark's drag, at most */
#define FOLD__DRAG_HALVINGS 8     /* of a step that would fold the placement */
/* A landmark this close to its image (in the chart's unit disk) is there:
 * far below a chart face, so the drag stops. */
#define FOLD__DRAG_ARRIVED 1e-12
/* The bump's radius R is this share of the distance to the nearest pinned
 * vertex or other landmark: it vanishes short of them, so they stay put. */
#define FOLD__DRAG_RADIUS 0.9
/* A step moves the landmark at most R over this: the bump's Jacobian's
 * determinant 1 + d·grad then stays near 1/2 or more, so each step is a
 * diffeomorphism. */
#define FOLD__DRAG_REACH 3

/* The region's faces folded in the placement uv (not of positive area,
 * the chart being oriented as T). */
static int placed_folds(fold__ctx *c, const fold__patch *pS, const double *uv)
{
    int n = 0;
    for (int i = 0; i < pS->nv; i++)
        c->sloc[pS->verts[i]] = i;
    for (int q = 0; q < pS->nf; q++) {
        const int *f = c->S->f + 3 * pS->faces[q];
        n += !(fold__area2(uv + 2 * c->sloc[f[0]], uv + 2 * c->sloc[f[1]], uv + 2 * c->sloc[f[2]]) > 0);
    }
    for (int i = 0; i < pS->nv; i++)
        c->sloc[pS->verts[i]] = -1;
    return n;
}

/* Moves each landmark of the region from its place in uv to its image's
 * in the chart (lm), carrying its neighbourhood along: small steps of the
 * displacement x -> x + (1 - s^2)^2 d, s = |x - a| / R, about the
 * landmark's place a, R short of the nearest pinned vertex and of the
 * other landmarks, |d| below R / 3 so that each step is a diffeomorphism
 * (its Jacobian's determinant 1 + d·grad stays above 1/2). A landmark
 * pinned inside a harmonic map folds it round the pin when the map would
 * put it elsewhere. The triangles are coarse next to the bump, though, and
 * a step the linear triangles cannot follow folds some of them: such a
 * step is halved (FOLD__DRAG_HALVINGS times at most) until the placement
 * has no more folded faces than before it, and the landmark stays where
 * it got when no step will do (its row comes back anyway). Returns 0, or -1
 * when out of memory. */
int fold__drag(fold__ctx *c, const fold__patch *pS, const unsigned char *pin, const double *lm, double *uv)
{
    double *before = malloc(sizeof(double) * 2 * ((size_t)pS->nv + 1));
    if (!before)
        return -1;
    int folds = placed_folds(c, pS, uv);
    for (int l = 0; l < pS->nv; l++) {
        if (pin[l] || !c->fixed[pS->verts[l]])
            continue;
        for (int step = 0; step < FOLD__DRAG_STEPS; step++) {
            double a[2] = { uv[2 * l], uv[2 * l + 1] };
            double d[2] = { lm[2 * l] - a[0], lm[2 * l + 1] - a[1] };
            double len = hypot(d[0], d[1]);
            if (!(len > FOLD__DRAG_ARRIVED))
                break;
            double R = INFINITY;
            for (int i = 0; i < pS->nv; i++)
                if (i != l && (pin[i] || c->fixed[pS->verts[i]]))
                    R = fmin(R, hypot(uv[2 * i] - a[0], uv[2 * i + 1] - a[1]));
            R *= FOLD__DRAG_RADIUS;
            if (!(R > 0) || !isfinite(R))
                break;
            double f = fmin(1, R / FOLD__DRAG_REACH / len);
            d[0] *= f;
            d[1] *= f;
            memcpy(before, uv, sizeof(double) * 2 * (size_t)pS->nv);
            int moved = 0;
            for (int h = 0; h <= FOLD__DRAG_HALVINGS && !moved; h++, d[0] *= 0.5, d[1] *= 0.5) {
                for (int i = 0; i < pS->nv; i++) {
                    if (pin[i])
                        continue;
                    double s2 = ((before[2 * i] - a[0]) * (before[2 * i] - a[0]) +
                                 (before[2 * i + 1] - a[1]) * (before[2 * i + 1] - a[1])) / (R * R);
                    double phi = s2 < 1 ? (1 - s2) * (1 - s2) : 0;
                    uv[2 * i] = before[2 * i] + phi * d[0];
                    uv[2 * i + 1] = before[2 * i + 1] + phi * d[1];
                }
                int n = placed_folds(c, pS, uv);
                if ((moved = n <= folds))
                    folds = n;
            }
            if (!moved) {
                memcpy(uv, before, sizeof(double) * 2 * (size_t)pS->nv);
                break;
            }
        }
    }
    free(before);
    return 0;
}
