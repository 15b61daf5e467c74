/* fold__repair.h — internal to fold/: what one fold_repair call works
 * with (fold__ctx) and the steps of its repair, one file each:
 * fold_chart.c (the target's chart and points in it), fold_remap.c (one
 * region re-mapped), fold_balance.c (its placement reweighted toward the
 * target's area), fold_drag.c (its landmarks dragged to their images),
 * fold_pass.c (one pass over the regions and the accept rule); the rounds
 * of passes are fold_repair.c's. */
#ifndef FOLD__REPAIR_H
#define FOLD__REPAIR_H
#include "fold/fold.h"
#include "fold/fold__patch.h"
#include "geo/geo_edges.h"

/* What one repair call works with. */
typedef struct fold__ctx {
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
} fold__ctx;

/* Signed area of the triangle a, b, c of the plane, doubled. */
double fold__area2(const double *a, const double *b, const double *c);
/* A point of T: row v of the map (face, w). */
void fold__point(const mesh *T, int face, const double *w, double *x);
/* The chart face holding plane point x: the one whose smallest barycentric
 * coordinate is largest (inside when >= 0), its coordinates clamped to the
 * face in bw. Returns the chart face, -1 when none has area. */
int fold__locate(const fold__patch *pT, const int *corner, const double *uvT, const double *x,
                 double bw[3]);
/* The chart: patch pT of T placed in the unit disk (uvT, 2 per vertex),
 * oriented as T. Returns 0, 1 when it is no disk or too large, -1 (memory). */
int fold__chart(fold__ctx *c, const fold__patch *pS, fold__patch *pT, double **uvT);

/* Reweights the region pS's placement uv (pin: its pinned vertices) toward
 * its target's area in the chart pT (corner: its faces' chart vertices,
 * uvT: their places); keeps the round with the fewest bad images. 0, or
 * -1 when out of memory. */
int fold__balance(fold__ctx *c, const fold__patch *pS, const unsigned char *pin,
                  const fold__patch *pT, const int *corner, const double *uvT, double *uv);

/* Drags each free landmark of region pS from its place in uv to its
 * image's in the chart (lm), carrying its neighbourhood along. 0, or -1
 * when out of memory. */
int fold__drag(fold__ctx *c, const fold__patch *pS, const unsigned char *pin, const double *lm,
               double *uv);

/* Re-maps the inner vertices of region pS (see fold.h) in c->R. Returns 0,
 * 1 when it cannot (no chart), -1 when out of memory. */
int fold__remap(fold__ctx *c, const fold__patch *pS);

/* One pass with regions grown by `rings`: returns the new number of bad
 * faces (kind updated), or -1 when out of memory. */
int fold__pass(fold__ctx *c, int rings, unsigned char *kind, int bad, fold_report *rep);

#endif
