/* fold__patch.h — internal to fold/: a patch is a set of faces of a mesh
 * that is a topological disk (one boundary loop, Euler characteristic 1);
 * the repair works in one on the source (the region it re-maps) and one on
 * the target (the chart the region is re-mapped into). Here: the face-set
 * operations that make one (grow, split into components, fill holes, check
 * the disk) and the harmonic placement of a patch in the plane. */
#ifndef FOLD__PATCH_H
#define FOLD__PATCH_H
#include "geo/geo_edges.h"
#include "mesh/mesh.h"

typedef struct fold__patch {
    int nf, *faces;   /* the mesh's faces in the patch                     */
    int nv, *verts;   /* its vertices; the first nb are the boundary loop,
                         in the order the faces' orientation runs along it */
    int nb;
} fold__patch;
void fold__patch_close(fold__patch *p);

/* Adds to the face set in[] (0/1 per face of m) every face sharing a
 * vertex with it, `rings` times. scratch: nv bytes. */
void fold__grow(const mesh *m, unsigned char *in, int rings, unsigned char *scratch);

/* Labels the faces with in[t] by edge-connected component: comp[t] in
 * 0..count-1, -1 for faces outside. Returns count, -1 when out of memory. */
int fold__components(const geo_edges *E, const unsigned char *in, int *comp);

/* Fills the holes of the face set in[]: every edge-connected component of
 * the faces outside it, except the one with the most faces, joins it.
 * Returns the set's new size, -1 when out of memory. */
int fold__fill_holes(const geo_edges *E, unsigned char *in);

/* The patch of the face set in[] when it is a disk; 0, 1 when it is not
 * one (more than one boundary loop, a pinched vertex, a handle, or no
 * boundary), -1 when out of memory. loc: nv ints, all -1 on entry and on
 * return. */
int fold__disk(const mesh *m, const geo_edges *E, const unsigned char *in, int *loc,
               fold__patch *out);

/* The harmonic placement of patch p of m in the plane: uv (2 per patch
 * vertex, in p->verts' order) is given for the vertices with pin[k] set
 * (pin: p->nv bytes; the boundary loop must be pinned) and solved for the
 * others, each the weighted mean of its neighbours with the cotangent
 * weights of m's geometry clamped positive (Tutte's theorem: a fold-free
 * placement when the boundary is convex and nothing inside is pinned),
 * each edge's weight times the mean of scale[] over its faces in the
 * patch when scale (p->nf values, > 0) is not NULL: any positive weights
 * keep Tutte's guarantee. Preconditioned conjugate gradients, from uv's
 * values as the first guess. loc as for fold__disk. Returns 0, -1 when out
 * of memory. */
int fold__harmonic(const mesh *m, const geo_edges *E, const fold__patch *p,
                   const unsigned char *pin, const double *scale, int *loc, double *uv);

#endif
