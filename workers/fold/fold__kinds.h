/* fold__kinds.h — internal to fold/: what the repair and the relaxation
 * count as a bad face (metric_fold_faces' kinds, flipped and collapsed,
 * and a crowded one beside them), and how both start on a map. */
#ifndef FOLD__KINDS_H
#define FOLD__KINDS_H
#include "fold/fold.h"
#include "geo/geo_edges.h"

/* A face whose image (both meshes at unit area) has less than this share
 * of its own area counts as crowded: a harmonic map crowds a long part
 * toward a point, exponentially, without reaching the metric's 1e-12. */
#define FOLD__CROWDED 1e-4
enum { FOLD__FACE_CROWDED = 3 };   /* beside metric.h's METRIC_FACE_* */

/* Face t's kind under the images img (3 per source vertex, P's rows; tn:
 * T's vertex normals, area_S, area_T: the total areas): metric_face_kind,
 * and FOLD__FACE_CROWDED for an OK face whose image is crowded. */
int fold__face_kind(const mesh *S, const mesh *T, const bmap *P, const double *img,
                    const double *tn, double area_S, double area_T, int t);

/* That kind of each of P's faces (S->nf); the number not OK, or -1 when
 * out of memory. */
int fold__kinds(const mesh *S, const mesh *T, const bmap *P, unsigned char *kind);

/* Whether P is a map from S onto T (its rows on T's faces): 1 or 0. */
int fold__map_ok(const mesh *S, const mesh *T, const bmap *P);

/* The start of fold_repair and fold_relax: P's kinds into kind (S->nf),
 * their count into *bad and rep's bad_before and bad_after, and when one
 * is bad the meshes' edge tables (ES, ET zeroed on entry; geo_edges_close
 * either way). Returns FOLD_OK, FOLD_ENOMEM or FOLD_EMESH. */
int fold__open(const mesh *S, const mesh *T, const bmap *P, unsigned char *kind, geo_edges *ES,
               geo_edges *ET, fold_report *rep, int *bad);

#endif
