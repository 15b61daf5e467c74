/* fold_balance.c — a region's harmonic placement reweighted toward the
 * target's area (fold.h, "balance"), so that a long part is not crowded
 * toward a point. */
#include "fold/fold__repair.h"
#include "fold/fold__kinds.h"
#include "geo/geo_tri.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The reweighting of a region's harmonic map toward its target's area
 * (balance): rounds, and the power of the area ratio each applies. */
#define FOLD__BALANCE_ROUNDS 8
#define FOLD__BALANCE_STEP 0.5
/* An area's floor before its logarithm: a face or image of no area gets a
 * finite ratio (the crowded test catches it), far below any real area. */
#define FOLD__AREA_FLOOR 1e-300
/* A round's log-ratio, less the mean, is clamped to ±this before its
 * power: exp of it stays finite whatever a degenerate image gives. */
#define FOLD__LOG_RATIO_CLAMP 20
/* A face's weight scale stays within [1/this, this] of its cotan weights,
 * over all rounds: the harmonic system stays well conditioned. */
#define FOLD__SCALE_MAX 1e4

/* n = (b - a) x (c - a): twice the area, along the normal. */
static void tri_cross(const double *a, const double *b, const double *c, double *n)
{
    double u[3], v[3];
    geo__sub(b, a, u);
    geo__sub(c, a, v);
    geo__cross(u, v, n);
}

/* Reweights the region's placement toward its target's area: each face's
 * edge weights scaled by (its image's area ratio over the region's mean)
 * to the power FOLD__BALANCE_STEP (a crowded face's weights fall, so it
 * opens up), up to FOLD__BALANCE_ROUNDS times, each a harmonic map again
 * (any positive weights keep Tutte's guarantee: Yoshizawa, Belyaev and
 * Seidel's stretch-minimising iteration). A harmonic map crowds a long
 * part toward a point, exponentially in its length over its girth: when
 * the source's part is longer so than the target's, its vertices all land
 * in the few chart faces round the target's tip. The placement kept is
 * the round's whose images have the fewest bad faces (flipped against the
 * target faces they land in, or crowded): pinned vertices inside void the
 * guarantee, and a round can fold round them. */
int fold__balance(fold__ctx *c, const fold__patch *pS, const unsigned char *pin, const fold__patch *pT,
                   const int *corner, const double *uvT, double *uv)
{
    const mesh *S = c->S, *T = c->T;
    size_t nv = (size_t)pS->nv + 1;
    double *scale = malloc(sizeof(double) * ((size_t)pS->nf + 1));
    double *img = malloc(sizeof(double) * 3 * nv), *nrm = malloc(sizeof(double) * 3 * nv);
    double *lr = malloc(sizeof(double) * ((size_t)pS->nf + 1));
    double *best = malloc(sizeof(double) * 2 * nv);
    int rc = -1, fewest = INT_MAX;
    if (!scale || !img || !nrm || !lr || !best)
        goto out;
    rc = 0;
    for (int q = 0; q < pS->nf; q++)
        scale[q] = 1;
    for (int round = 0;; round++) {
        for (int i = 0; i < pS->nv; i++) {
            double bw[3];
            int q = fold__locate(pT, corner, uvT, uv + 2 * i, bw);
            if (q < 0)
                goto out;
            fold__point(T, pT->faces[q], bw, img + 3 * i);
            geo__face_cross(T, pT->faces[q], nrm + 3 * i);
        }
        for (int i = 0; i < pS->nv; i++)
            c->sloc[pS->verts[i]] = i;
        double mean = 0, wsum = 0;
        int bad = 0;
        for (int q = 0; q < pS->nf; q++) {
            const int *f = S->f + 3 * pS->faces[q];
            int i0 = c->sloc[f[0]], i1 = c->sloc[f[1]], i2 = c->sloc[f[2]];
            double n[3], m[3], dot = 0;
            geo__face_cross(S, pS->faces[q], m);
            tri_cross(img + 3 * i0, img + 3 * i1, img + 3 * i2, n);
            double a = sqrt(geo__dot(m, m)), b = sqrt(geo__dot(n, n));
            for (int d = 0; d < 3; d++)
                dot += n[d] * (nrm[3 * i0 + d] + nrm[3 * i1 + d] + nrm[3 * i2 + d]);
            lr[q] = log(fmax(b, FOLD__AREA_FLOOR) / fmax(a, FOLD__AREA_FLOOR));
            bad += dot < 0 || !(b / c->area_T >= FOLD__CROWDED * a / c->area_S);
            mean += a * lr[q];
            wsum += a;
        }
        for (int i = 0; i < pS->nv; i++)
            c->sloc[pS->verts[i]] = -1;
        if (bad < fewest) {
            fewest = bad;
            memcpy(best, uv, sizeof(double) * 2 * (size_t)pS->nv);
        }
        if (round == FOLD__BALANCE_ROUNDS || bad == 0)
            break;
        mean = wsum > 0 ? mean / wsum : 0;
        for (int q = 0; q < pS->nf; q++) {
            double dev = fmax(-FOLD__LOG_RATIO_CLAMP, fmin(FOLD__LOG_RATIO_CLAMP, lr[q] - mean));
            double g = exp(FOLD__BALANCE_STEP * dev);
            scale[q] = fmin(FOLD__SCALE_MAX, fmax(1 / FOLD__SCALE_MAX, scale[q] * g));
        }
        if (fold__harmonic(S, &c->ES, pS, pin, scale, c->sloc, uv)) {
            rc = -1;
            goto out;
        }
    }
out:
    if (fewest < INT_MAX)
        memcpy(uv, best, sizeof(double) * 2 * (size_t)pS->nv);
    free(scale);
    free(img);
    free(nrm);
    free(lr);
    free(best);
    return rc;
}
