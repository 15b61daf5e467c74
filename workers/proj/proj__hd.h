/* proj__hd.h — internal: a bounding-volume hierarchy over the target's
 * triangles for the projections in R^d whose three leading coordinates see
 * too little of the distance for the 3-D Embree tree to prune (RHM's
 * P-steps in R^{2m}, the distances start in R^{2l}). Nothing outside
 * workers/proj/ includes this.
 *
 * Why a box hierarchy in R^d works where the 3-D bound does not: the
 * embedded target is a surface, of dimension two whatever d is, so the
 * boxes of a hierarchy of surface patches shrink as the patches do, while
 * the 3-D ball of radius √best around a row holds a number of faces that
 * grows with the mesh's resolution (the residual in the other d − 3
 * coordinates does not shrink with it).
 *
 * The patches (the hierarchy's shape) come from the tree's 3-D positions,
 * once per proj_tree; each projection call then fits the boxes in R^d to
 * its Z (the embedding moves from call to call, the patches need not): a
 * pass over the faces and the nodes instead of a build. Any patches give
 * exact answers; compact ones prune well wherever the embedding is a
 * continuous function on the surface. */
#ifndef PROJ__HD_H
#define PROJ__HD_H
#include <stddef.h>

typedef struct proj__hd proj__hd;

/* The hierarchy over the nf faces f (nf by 3 vertex indices, kept as a
 * pointer: alive while the hierarchy is) of the 3-D positions V: median
 * splits of the faces' box centres along their widest coordinate.
 * Single-threaded, so the same input gives the same hierarchy. NULL when
 * out of memory. */
proj__hd *proj__hd_new(const double *V, const int *f, int nf);
void proj__hd_free(proj__hd *h);

/* Doubles proj__hd_fit writes for dimension d. */
size_t proj__hd_box_size(const proj__hd *h, int d);
/* The boxes in R^d of every face and node for vertex coordinates Z (row
 * v: d values) into box (proj__hd_box_size doubles). Parallel (OpenMP). */
void proj__hd_fit(const proj__hd *h, int d, const double *Z, double *box);

/* The closest point of q (d values) on the faces embedded by Z, with the
 * boxes fitted to Z: on entry *face and *best may hold a face and its cost
 * (the search keeps it unless a face costs strictly less) or -1 and +inf;
 * on return the winner, its squared distance and barycentric weights.
 * Thread-safe. */
void proj__hd_closest(const proj__hd *h, int d, const double *Z, const double *box,
                      const double *q, int *face, double *best, double bary[3]);

#endif
