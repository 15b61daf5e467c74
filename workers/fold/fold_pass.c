/* fold_pass.c — one pass of the repair (fold.h, "region" and "accept"):
 * the bad faces grown into hole-filled disk regions, each re-mapped every
 * way (disk or tube, landmarks dragged or free), and a region's new rows
 * kept only when better. */
#include "fold/fold__repair.h"
#include "fold/fold__kinds.h"
#include "metric/metric.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A region (hole-filled) may take at most this share of the source's
 * faces: beyond that the map is wrong on a whole part (a limb), which a
 * local repair cannot decide. */
#define FOLD__MAX_REGION 0.25
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
static int remap_all(fold__ctx *c, taken *tk, int ntaken, int mode)
{
    c->drag_landmarks = mode == MODE_DISK_DRAGGED || mode == MODE_TUBE_DRAGGED;
    c->tube = mode == MODE_TUBE_DRAGGED || mode == MODE_TUBE_FREE;
    for (int k = 0; k < ntaken; k++) {
        for (int i = 0; i < tk[k].p.nv; i++)
            c->keep[tk[k].p.verts[i]] = tk[k].kept[i];
        c->shift = 0;
        int rc = fold__remap(c, &tk[k].p);
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
static int moved_far(const fold__ctx *c, const taken *r)
{
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    double far = 0, x[3], y[3];
    for (int i = 0; i < r->p.nv; i++) {
        if (i >= r->p.nb && !r->kept[i])
            continue;
        fold__point(c->T, r->face[i], r->w + 3 * i, x);
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], x[d]);
            hi[d] = fmax(hi[d], x[d]);
        }
    }
    for (int i = r->p.nb; i < r->p.nv; i++) {
        int v = r->p.verts[i];
        if (c->badv[v])
            continue;
        fold__point(c->T, r->face[i], r->w + 3 * i, x);
        fold__point(c->T, c->R->face[v], c->R->w + 3 * v, y);
        far = fmax(far, (x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                            (x[2] - y[2]) * (x[2] - y[2]));
    }
    double diam2 = (hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                   (hi[2] - lo[2]) * (hi[2] - lo[2]);
    return far > FOLD__MAX_MOVE * FOLD__MAX_MOVE * diam2;
}

static void taken_free(taken *tk, int ntaken)
{
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
}

/* The regions of a pass: the bad faces of kind grown by `rings`, split
 * into components, each hole-filled and taken when it is a disk of at
 * most FOLD__MAX_REGION of the faces that overlaps no region taken
 * before it; c->badv marks the bad faces' vertices. *tk (*ntaken of them)
 * holds each with its kept vertices and its rows, even on failure (the
 * caller frees it). Returns 0, or -1 when out of memory. */
static int take_regions(fold__ctx *c, int rings, const unsigned char *kind, taken **tkp,
                        int *ntaken)
{
    const mesh *S = c->S;
    int nf = S->nf, nv = S->nv, rc = -1;
    unsigned char *in = malloc((size_t)nf + 1), *cin = malloc((size_t)nf + 1);
    unsigned char *mark = malloc((size_t)nv + 1), *claimed = calloc((size_t)nv + 1, 1);
    int *comp = malloc(sizeof(int) * ((size_t)nf + 1));
    taken *tk = NULL;
    *ntaken = 0;
    if (!in || !cin || !mark || !claimed || !comp)
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
        taken *r = tk + *ntaken;
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
        (*ntaken)++;
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
    rc = 0;
out:
    *tkp = tk;
    free(in);
    free(cin);
    free(mark);
    free(claimed);
    free(comp);
    return rc;
}

/* The accept rule's choice among region r's remaps (km: each mode's face
 * kinds, nf per mode): their badness in v, and the remap that wins. */
static int winner(const fold__ctx *c, const taken *r, const unsigned char *km, int nf, long v[MODES])
{
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
    return v[tube] <= v[disk] || r->tube || tubed ? tube : disk;
}

int fold__pass(fold__ctx *c, int rings, unsigned char *kind, int bad, fold_report *rep)
{
    const mesh *S = c->S;
    int nf = S->nf, rc = -1, ntaken = 0;
    unsigned char *km = malloc((MODES + 1) * ((size_t)nf + 1));   /* each mode's kinds, then the new */
    taken *tk = NULL;
    if (!km || take_regions(c, rings, kind, &tk, &ntaken))
        goto out;
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
        int won = winner(c, r, km, nf, v);
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
    taken_free(tk, ntaken);
    free(km);
    return rc;
}
