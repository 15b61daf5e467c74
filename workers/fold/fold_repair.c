/* fold_repair.c — see fold.h: the regions of bad faces, each re-mapped
 * through a chart of the target by harmonic maps (fold__patch.h), and the
 * accept-if-better rule per region. */
#include "fold/fold.h"
#include "fold/fold__patch.h"
#include "fold/fold__kinds.h"
#include "geo/geo_area.h"
#include "geo/geo_tri.h"
#include "metric/metric.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A region (hole-filled) may take at most this share of the source's
 * faces, and its chart this share of the target's: beyond that the map is
 * wrong on a whole part (a limb), which a local repair cannot decide. */
#define FOLD__MAX_REGION 0.25
#define FOLD__MAX_CHART 0.5
#define FOLD__CHART_RINGS 2       /* rings round the boundary image, at least */
/* ... and at most (FOLD__MAX_CHART bounds it as well): the ring round a
 * thin part and the part's end kept beyond it can land a long way apart on
 * the target (a pair of glasses' arms: a low cap would leave no chart and no
 * repair at all) */
#define FOLD__CHART_MAX_RINGS 30
/* A remap with the landmarks free counts only when it puts each of them
 * at most this far (in the chart's unit disk) from its image: farther, it
 * contradicts the landmark, and restoring the landmark's row leaves its
 * neighbourhood mapped elsewhere. */
#define FOLD__MAX_SHIFT 0.25
/* A remap may move a vertex whose faces were all good at most this
 * multiple of the diameter of the image of what the region pins (its
 * boundary and kept holes): the map was right there, and a remap that
 * carries it farther spreads the region over a larger part the boundary
 * encloses (a foot's ring round a long leg). The boundary alone is too
 * small a measure for a band round a thin part with its end kept: its
 * ring is as wide as the part, and the band's vertices slide along it. */
#define FOLD__MAX_MOVE 1.0
/* The reweighting of a region's harmonic map toward its target's area
 * (balance): rounds, and the power of the area ratio each applies. */
#define FOLD__BALANCE_ROUNDS 8
#define FOLD__BALANCE_STEP 0.5
/* A region deeper than this many times its boundary's radius is a part's
 * end (tube_like): re-mapped by the tube placement as well (fold__patch.h),
 * which wins a tie. */
#define FOLD__TUBE_DEPTH 2.0
#define FOLD__DRAG_STEPS 200      /* steps of a landmark's drag, at most */
#define FOLD__DRAG_HALVINGS 8     /* of a step that would fold the placement */
/* The passes run again from `rings` while a round of them lowers the
 * count, this many rounds at most: a region refused at first (its chart
 * crossed a neighbour's folds) is often taken once the neighbour is
 * repaired. make demo's maps: 128 bad faces after one round, 95 after a
 * second run of the repair on its output. */
#define FOLD__ROUNDS 3

const char *fold_strerror(int code)
{
    switch (code) {
#define FOLD_STR(name, val, msg, kind) case name: return msg;
        FOLD_ERRORS(FOLD_STR)
#undef FOLD_STR
    }
    return "unknown fold repair error";
}

void fold_params_init(fold_params *p)
{
    p->rings = 2;
    p->passes = 4;
}

/* What one repair call works with. */
typedef struct ctx {
    const mesh *S, *T;
    double area_S, area_T;        /* total areas */
    geo_edges ES, ET;
    const unsigned char *fixed;   /* S->nv: landmark vertices */
    int drag_landmarks;           /* remap drags the landmarks to their images */
    int tube;                     /* remap by the tube placement (tube_like regions) */
    double shift;                 /* remap's farthest free landmark from its
                                     image, in the chart's unit disk */
    unsigned char *badv;          /* S->nv: vertices of bad faces (pass) */
    unsigned char *tubed;         /* S->nv: placed by a tube remap (kept) */
    unsigned char *keep;          /* S->nv: the region's vertices that keep
                                     their rows (those of its filled holes) */
    bmap *R;                      /* the map being repaired */
    unsigned char *tin, *tmark;   /* T->nf, T->nv scratch */
    int *tcomp, *tloc, *sloc;     /* T->nf, T->nv (-1), S->nv (-1) */
} ctx;

/* Whether the region's vertex i is pinned where it is mapped: its boundary
 * and the holes filled in (their faces were not bad: a limb's end beyond a
 * bad band round it keeps its map, and only the band is re-mapped, so the
 * harmonic map never crowds a long tube's end into a point). Landmarks are
 * not pinned: a pin folds the harmonic map round it when it is not where
 * that map would put it. They move with the others and get their rows back
 * afterwards; with c->drag_landmarks the placement is then dragged so that
 * each lands at its image (drag). Each region is re-mapped both ways and
 * the accept rule keeps the better. */
static int pinned(const ctx *c, const fold__patch *pS, int i)
{
    return i < pS->nb || c->keep[pS->verts[i]];
}

/* Whether the region's vertex i places the chart: its boundary and kept
 * holes, and for a remap that drags the landmarks (c->drag_landmarks) its
 * landmarks too: the drag must reach their images, and these may lie
 * beyond what the boundary's image encloses (a limb whose boundary lands high
 * on the target's limb while its landmarks' images lie far down it).
 * A free remap's chart leaves them out: their images may lie far inside
 * the part the boundary encloses (a limb's tip), and they get their rows
 * back anyway. */
static int anchored(const ctx *c, const fold__patch *pS, int i)
{
    return i < pS->nb || c->keep[pS->verts[i]] || (c->drag_landmarks && c->fixed[pS->verts[i]]);
}

/* The chart: patch pT of T placed in the unit disk (uvT, 2 per vertex),
 * oriented as T. Returns 0, 1 when it is no disk or too large, -1 (memory). */
static int chart(ctx *c, const fold__patch *pS, fold__patch *pT, double **uvT)
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

/* Signed area of the triangle a, b, c of the plane, doubled. */
static double area2(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* A point of T: row v of the map (face, w). */
static void point(const mesh *T, int face, const double *w, double *x)
{
    const int *tf = T->f + 3 * face;
    for (int d = 0; d < 3; d++)
        x[d] = w[0] * T->v[3 * tf[0] + d] + w[1] * T->v[3 * tf[1] + d] + w[2] * T->v[3 * tf[2] + d];
}

/* The chart face holding plane point x: the one whose smallest barycentric
 * coordinate is largest (inside when >= 0), its coordinates clamped to the
 * face in bw. Returns the chart face, -1 when none has area. */
static int locate(const fold__patch *pT, const int *corner, const double *uvT, const double *x,
                  double bw[3])
{
    int bf = -1;
    double bmin = -INFINITY;
    for (int q = 0; q < pT->nf; q++) {
        const double *a = uvT + 2 * corner[3 * q], *b = uvT + 2 * corner[3 * q + 1],
                     *d = uvT + 2 * corner[3 * q + 2];
        double A = area2(a, b, d);
        if (!(fabs(A) > 0))
            continue;
        double w[3] = { area2(x, b, d) / A, area2(a, x, d) / A, area2(a, b, x) / A };
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
static int balance(ctx *c, const fold__patch *pS, const unsigned char *pin, const fold__patch *pT,
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
            int q = locate(pT, corner, uvT, uv + 2 * i, bw);
            if (q < 0)
                goto out;
            point(T, pT->faces[q], bw, img + 3 * i);
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
            lr[q] = log(fmax(b, 1e-300) / fmax(a, 1e-300));
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
            double g = exp(FOLD__BALANCE_STEP * fmax(-20, fmin(20, lr[q] - mean)));
            scale[q] = fmin(1e4, fmax(1e-4, scale[q] * g));
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

/* The region's faces folded in the placement uv (not of positive area,
 * the chart being oriented as T). */
static int placed_folds(ctx *c, const fold__patch *pS, const double *uv)
{
    int n = 0;
    for (int i = 0; i < pS->nv; i++)
        c->sloc[pS->verts[i]] = i;
    for (int q = 0; q < pS->nf; q++) {
        const int *f = c->S->f + 3 * pS->faces[q];
        n += !(area2(uv + 2 * c->sloc[f[0]], uv + 2 * c->sloc[f[1]], uv + 2 * c->sloc[f[2]]) > 0);
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
static int drag(ctx *c, const fold__patch *pS, const unsigned char *pin, const double *lm, double *uv)
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
            if (!(len > 1e-12))
                break;
            double R = INFINITY;
            for (int i = 0; i < pS->nv; i++)
                if (i != l && (pin[i] || c->fixed[pS->verts[i]]))
                    R = fmin(R, hypot(uv[2 * i] - a[0], uv[2 * i + 1] - a[1]));
            R *= 0.9;
            if (!(R > 0) || !isfinite(R))
                break;
            double f = fmin(1, R / 3 / len);
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

/* Re-maps the inner vertices of region pS (see fold.h) in c->R. Returns 0,
 * 1 when it cannot (no chart), -1 when out of memory. */
static int remap(ctx *c, const fold__patch *pS)
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
    if ((rc = chart(c, pS, &pT, &uvT)))
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
    for (int i = 0; i < pT.nv; i++)
        c->tloc[pT.verts[i]] = i;
    for (int q = 0; q < pT.nf; q++)
        for (int k = 0; k < 3; k++)
            corner[3 * q + k] = c->tloc[T->f[3 * pT.faces[q] + k]];
    /* the chart is oriented as T when its faces have positive area */
    double sa = 0;
    for (int q = 0; q < pT.nf; q++)
        sa += area2(uvT + 2 * corner[3 * q], uvT + 2 * corner[3 * q + 1], uvT + 2 * corner[3 * q + 2]);
    if (sa < 0)
        for (int i = 0; i < pT.nv; i++)
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
            rc = 1;
            for (int j = 0; j < pT.nv; j++)
                c->tloc[pT.verts[j]] = -1;
            goto out;
        }
    }
    for (int i = 0; i < pT.nv; i++)
        c->tloc[pT.verts[i]] = -1;
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
               balance(c, pS, pin, &pT, corner, uvT, uv))
        goto out;
    if (c->drag_landmarks && drag(c, pS, pin, lm, uv))
        goto out;
    c->shift = 0;
    for (int i = 0; i < pS->nv; i++)
        if (!pin[i] && c->fixed[pS->verts[i]])
            c->shift = fmax(c->shift, hypot(uv[2 * i] - lm[2 * i], uv[2 * i + 1] - lm[2 * i + 1]));
    /* read the inner vertices back through the chart */
    for (int i = 0; i < pS->nv; i++) {
        int v = pS->verts[i];
        if (pin[i] || c->fixed[v])
            continue;
        double bw[3];
        int bf = locate(&pT, corner, uvT, uv + 2 * i, bw);
        if (bf < 0)
            continue;
        c->R->face[v] = pT.faces[bf];
        memcpy(c->R->w + 3 * v, bw, sizeof bw);
    }
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

/* The remaps each region gets in a pass: by harmonic maps (disk) or by
 * the tube placement (tube_like regions only), each with the landmarks
 * dragged to their images or free. */
enum { MODE_DISK_DRAGGED, MODE_DISK_FREE, MODE_TUBE_DRAGGED, MODE_TUBE_FREE, MODES };

/* One region taken in a pass: its patch, which of its vertices are kept
 * (c->keep), the rows it had, and the rows of each of its remaps. */
typedef struct taken {
    fold__patch p;
    unsigned char *kept;
    int *face, *mface[MODES];
    double *w, *mw[MODES];
    double shift[MODES];          /* c->shift of each remap */
    int far[MODES];               /* moved_far of each remap */
    int tube;                     /* a part's end, re-mapped by the tube placement */
} taken;

/* Rows of the region's vertices: from the map into face/w (save) or back. */
static void rows(bmap *R, const fold__patch *p, int *face, double *w, int save)
{
    for (int i = 0; i < p->nv; i++) {
        int v = p->verts[i];
        if (save) {
            face[i] = R->face[v];
            memcpy(w + 3 * i, R->w + 3 * v, 3 * sizeof(double));
        } else {
            R->face[v] = face[i];
            memcpy(R->w + 3 * v, w + 3 * i, 3 * sizeof(double));
        }
    }
}

/* Remaps every taken region the way of mode; -1 when out of memory. */
static int remap_all(ctx *c, taken *tk, int ntaken, int mode)
{
    c->drag_landmarks = mode == MODE_DISK_DRAGGED || mode == MODE_TUBE_DRAGGED;
    c->tube = mode == MODE_TUBE_DRAGGED || mode == MODE_TUBE_FREE;
    for (int k = 0; k < ntaken; k++) {
        for (int i = 0; i < tk[k].p.nv; i++)
            c->keep[tk[k].p.verts[i]] = tk[k].kept[i];
        c->shift = 0;
        int rc = remap(c, &tk[k].p);
        if (rc < 0)
            return -1;
        tk[k].shift[mode] = c->shift;
        if (c->tube && rc == 0)
            tk[k].tube = 1;
    }
    return 0;
}

/* The region's bad faces (flipped, crowded or collapsed), a collapsed one
 * counted as more than all the faces it has: a remap that trades flips for
 * collapse never counts as better; one that crowds a part (a harmonic map
 * of a long part) counts each crowded face as bad. */
static long badness(const fold__patch *p, const unsigned char *kind)
{
    long n = 0;
    for (int q = 0; q < p->nf; q++)
        n += kind[p->faces[q]] == METRIC_FACE_COLLAPSED ? p->nf + 1 : kind[p->faces[q]] != 0;
    return n;
}

/* Whether the region's remap (its rows in c->R against its old rows)
 * moved a vertex with good faces farther than FOLD__MAX_MOVE times the
 * diameter of the boundary's image (a box's diagonal). */
static int moved_far(const ctx *c, const taken *r)
{
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    double far = 0, x[3], y[3];
    for (int i = 0; i < r->p.nv; i++) {
        if (i >= r->p.nb && !r->kept[i])
            continue;
        point(c->T, r->face[i], r->w + 3 * i, x);
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], x[d]);
            hi[d] = fmax(hi[d], x[d]);
        }
    }
    for (int i = r->p.nb; i < r->p.nv; i++) {
        int v = r->p.verts[i];
        if (c->badv[v])
            continue;
        point(c->T, r->face[i], r->w + 3 * i, x);
        point(c->T, c->R->face[v], c->R->w + 3 * v, y);
        far = fmax(far, (x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                            (x[2] - y[2]) * (x[2] - y[2]));
    }
    double diam2 = (hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                   (hi[2] - lo[2]) * (hi[2] - lo[2]);
    return far > FOLD__MAX_MOVE * FOLD__MAX_MOVE * diam2;
}

/* One pass with regions grown by `rings`: returns the new number of bad
 * faces (kind updated), or -1 when out of memory. */
static int pass(ctx *c, int rings, unsigned char *kind, int bad, fold_report *rep)
{
    const mesh *S = c->S;
    int nf = S->nf, nv = S->nv, rc = -1, ntaken = 0;
    unsigned char *in = malloc((size_t)nf + 1), *cin = malloc((size_t)nf + 1);
    unsigned char *mark = malloc((size_t)nv + 1), *claimed = calloc((size_t)nv + 1, 1);
    unsigned char *km = malloc((MODES + 1) * ((size_t)nf + 1));   /* each mode's kinds, then the new */
    int *comp = malloc(sizeof(int) * ((size_t)nf + 1));
    taken *tk = NULL;
    if (!in || !cin || !mark || !claimed || !km || !comp)
        goto out;
    memset(c->badv, 0, (size_t)nv);
    for (int t = 0; t < nf; t++) {
        in[t] = kind[t] != 0;
        for (int j = 0; j < 3 && in[t]; j++)
            c->badv[S->f[3 * t + j]] = 1;
    }
    fold__grow(S, in, rings, mark);
    int n = fold__components(&c->ES, in, comp);
    if (n < 0 || !(tk = calloc((size_t)n + 1, sizeof(taken))))
        goto out;
    for (int k = 0; k < n; k++) {
        for (int t = 0; t < nf; t++)
            cin[t] = comp[t] == k;
        /* kept: what the holes fill in that no region's (grown) bad faces
         * touch; another region inside a hole (a collapsed tip beyond a
         * flipped band) is re-mapped with this one, not pinned folded */
        memset(c->keep, 1, (size_t)nv);
        for (int t = 0; t < nf; t++)
            if (in[t])
                for (int j = 0; j < 3; j++)
                    c->keep[S->f[3 * t + j]] = 0;
        int size = fold__fill_holes(&c->ES, cin);
        if (size < 0)
            goto out;
        if (size > FOLD__MAX_REGION * nf)
            continue;
        taken *r = tk + ntaken;
        int d = fold__disk(S, &c->ES, cin, c->sloc, &r->p);
        if (d < 0)
            goto out;
        if (d)
            continue;
        int clash = 0;
        for (int i = 0; i < r->p.nv && !clash; i++)
            clash = claimed[r->p.verts[i]];
        if (clash) {             /* overlaps a region taken already: next pass */
            fold__patch_close(&r->p);
            continue;
        }
        size_t m = (size_t)r->p.nv + 1;
        r->kept = malloc(m);
        r->face = malloc(sizeof(int) * m);
        r->w = malloc(sizeof(double) * 3 * m);
        ntaken++;
        if (!r->kept || !r->face || !r->w)
            goto out;
        for (int md = 0; md < MODES; md++)
            if (!(r->mface[md] = malloc(sizeof(int) * m)) || !(r->mw[md] = malloc(sizeof(double) * 3 * m)))
                goto out;
        for (int i = 0; i < r->p.nv; i++) {
            r->kept[i] = c->keep[r->p.verts[i]];
            claimed[r->p.verts[i]] = 1;
        }
        rows(c->R, &r->p, r->face, r->w, 1);
    }
    /* each region re-mapped each way (its rows and kinds kept per mode) */
    for (int md = 0; md < MODES; md++) {
        if (remap_all(c, tk, ntaken, md) || fold__kinds(S, c->T, c->R, km + (size_t)md * nf) < 0)
            goto out;
        for (int k = 0; k < ntaken; k++) {
            tk[k].far[md] = moved_far(c, tk + k);
            rows(c->R, &tk[k].p, tk[k].mface[md], tk[k].mw[md], 1);
            rows(c->R, &tk[k].p, tk[k].face, tk[k].w, 0);
        }
    }
    unsigned char *knew = km + (size_t)MODES * nf;
    memcpy(knew, kind, (size_t)nf);
    for (int k = 0; k < ntaken; k++) {
        taken *r = tk + k;
        long before = badness(&r->p, kind), v[MODES];
        for (int md = 0; md < MODES; md++)   /* a remap that moved good parts far never wins */
            v[md] = r->far[md] && md < MODE_TUBE_DRAGGED ? LONG_MAX : badness(&r->p, km + (size_t)md * nf);
        /* per placement, the dragged landmarks unless the free ones do
         * better and stay near their images; then the tube's on a tie */
        int disk = v[MODE_DISK_DRAGGED] <= v[MODE_DISK_FREE] ||
                           r->shift[MODE_DISK_FREE] > FOLD__MAX_SHIFT ? MODE_DISK_DRAGGED : MODE_DISK_FREE;
        int tube = v[MODE_TUBE_DRAGGED] <= v[MODE_TUBE_FREE] ||
                           r->shift[MODE_TUBE_FREE] > FOLD__MAX_SHIFT ? MODE_TUBE_DRAGGED : MODE_TUBE_FREE;
        int tubed = 0;
        for (int i = r->p.nb; i < r->p.nv && !tubed; i++)
            tubed = c->tubed[r->p.verts[i]];
        int won = v[tube] <= v[disk] || r->tube || tubed ? tube : disk;
        if (v[won] < before) {
            rows(c->R, &r->p, r->mface[won], r->mw[won], 0);
            for (int i = r->p.nb; i < r->p.nv && won >= MODE_TUBE_DRAGGED; i++)
                c->tubed[r->p.verts[i]] = 1;
            rep->regions++;
            rep->region += r->p.nv - r->p.nb;
            for (int q = 0; q < r->p.nf; q++)
                knew[r->p.faces[q]] = km[(size_t)won * nf + r->p.faces[q]];
        }
    }
    bad = 0;
    for (int t = 0; t < nf; t++)
        bad += (kind[t] = knew[t]) != 0;
    rc = bad;
out:
    if (tk)
        for (int k = 0; k < ntaken; k++) {
            fold__patch_close(&tk[k].p);
            free(tk[k].kept);
            free(tk[k].face);
            free(tk[k].w);
            for (int md = 0; md < MODES; md++) {
                free(tk[k].mface[md]);
                free(tk[k].mw[md]);
            }
        }
    free(tk);
    free(in);
    free(cin);
    free(mark);
    free(claimed);
    free(km);
    free(comp);
    return rc;
}

int fold_repair(const mesh *S, const mesh *T, const int *fixed, int nfixed,
                const fold_params *p, bmap *P, fold_report *rep)
{
    memset(rep, 0, sizeof *rep);
    if (!fold__map_ok(S, T, P) || !p || p->rings < 0 || p->passes < 1 || nfixed < 0)
        return FOLD_EINVAL;
    ctx c = { .S = S, .T = T, .area_S = geo_total_area(S), .area_T = geo_total_area(T) };
    int rc = FOLD_ENOMEM;
    unsigned char *kind = malloc((size_t)S->nf + 1), *fx = calloc((size_t)S->nv + 1, 1);
    c.keep = malloc((size_t)S->nv + 1);
    c.tin = malloc((size_t)T->nf + 1);
    c.tmark = malloc((size_t)T->nv + 1);
    c.tcomp = malloc(sizeof(int) * ((size_t)T->nf + 1));
    c.tloc = malloc(sizeof(int) * ((size_t)T->nv + 1));
    c.sloc = malloc(sizeof(int) * ((size_t)S->nv + 1));
    c.R = bmap_new(P->n, P->nt);
    c.badv = malloc((size_t)S->nv + 1);
    c.tubed = calloc((size_t)S->nv + 1, 1);
    if (!c.badv || !c.tubed || !kind || !fx || !c.keep || !c.tin || !c.tmark || !c.tcomp || !c.tloc || !c.sloc || !c.R)
        goto out;
    for (int v = 0; v < T->nv; v++)
        c.tloc[v] = -1;
    for (int v = 0; v < S->nv; v++)
        c.sloc[v] = -1;
    for (int k = 0; k < nfixed; k++)
        if (fixed[k] >= 0 && fixed[k] < S->nv)
            fx[fixed[k]] = 1;
    c.fixed = fx;
    memcpy(c.R->face, P->face, sizeof(int) * (size_t)P->n);
    memcpy(c.R->w, P->w, sizeof(double) * 3 * (size_t)P->n);
    int bad;
    if ((rc = fold__open(S, T, P, kind, &c.ES, &c.ET, rep, &bad)) || bad == 0)
        goto out;
    for (int round = 0; round < FOLD__ROUNDS && bad > 0; round++) {
        int start = bad;
        for (int k = 0; k < p->passes && bad > 0; k++)
            if ((bad = pass(&c, p->rings + 2 * k, kind, bad, rep)) < 0) {
                rc = FOLD_ENOMEM;
                goto out;
            }
        if (bad >= start)
            break;
    }
    if (bad < rep->bad_before) {
        memcpy(P->face, c.R->face, sizeof(int) * (size_t)P->n);
        memcpy(P->w, c.R->w, sizeof(double) * 3 * (size_t)P->n);
        rep->bad_after = bad;
        rep->accepted = 1;
    }
out:
    geo_edges_close(&c.ES);
    geo_edges_close(&c.ET);
    bmap_free(c.R);
    free(c.badv);
    free(c.tubed);
    free(kind);
    free(fx);
    free(c.keep);
    free(c.tin);
    free(c.tmark);
    free(c.tcomp);
    free(c.tloc);
    free(c.sloc);
    return rc;
}
