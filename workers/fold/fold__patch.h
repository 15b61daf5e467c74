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

/* The patch in the unit disk by fold__harmonic: its boundary loop on the
 * circle by arc length, counter-clockwise in the loop's order, nothing
 * inside pinned (fold-free by Tutte's theorem). uv: 2 per patch vertex.
 * Returns 0, -1 when out of memory. */
int fold__disk_place(const mesh *m, const geo_edges *E, const fold__patch *p, int *loc, double *uv);

/* The harmonic conjugate of u (p->nv values, harmonic for fold__harmonic's
 * weights wherever it is not pinned) on the patch's faces: theta (p->nf
 * values, in p->faces' order) from 0 on the first face, each edge crossed
 * changing it by the flux of u's gradient through its dual edge (the
 * edge's weight times u's difference along it), so that it turns by the
 * total flux round a vertex where u has a source and is single-valued
 * elsewhere but for a cut; flux (p->nv values): each vertex's net flux,
 * the sum over its edges of weight times u's rise along it (0 where u is
 * harmonic). loc as for fold__disk. Returns 0, 1 when the faces are not
 * edge-connected, -1 when out of memory. */
int fold__conjugate(const mesh *m, const geo_edges *E, const fold__patch *p, const double *u,
                    int *loc, double *theta, double *flux);

/* fold_tube.c — the tube placement: a harmonic disk map crowds a long
 * part's end toward a point, exponentially in the part's length over its
 * girth, so a region and its chart laid in disks that way meet at the
 * wrong height when the two parts' proportions differ (a hoof behind a
 * ring round the leg lands up the target's leg). Placed by depth instead,
 * the region's end goes to the chart's end and each height in between to
 * the same share of the target's.
 *
 * fold__depth: each patch vertex's distance from the boundary loop along
 * the patch's edges (Dijkstra), in p->verts' order. loc as for fold__disk.
 * Returns 0, -1 when out of memory. */
int fold__depth(const mesh *m, const fold__patch *p, int *loc, double *depth);

/* The tube chart of patch p (depth: its vertices', fold__depth) in the
 * unit disk, oriented as m: the deepest vertex at the centre, the
 * boundary on the circle. Angle: the harmonic conjugate (fold__conjugate)
 * of the height u, harmonic, 0 on the boundary and 1 at the deepest
 * vertex (a disk's harmonic map crowds a long part's end below what its
 * solver resolves; u and its conjugate stay of order one). Radius: a
 * depth share s, the k-th largest u taking the k-th largest share (depth
 * over the deepest's), so a function of u alone, as one-to-one as
 * (u, angle); at share s the radius is (e^(-lambda s) - e^(-lambda)) /
 * (1 - e^(-lambda)), *lambda the patch's depth over its boundary's radius
 * (within [0.5, 30]): the rings spaced as a conformal map of a tube
 * spaces them, so its triangles keep their shape. uv: 2 per patch vertex.
 * loc as for fold__disk. Returns 0, 1 when there is no depth or no turn,
 * -1 when out of memory. */
int fold__tube_chart(const mesh *m, const geo_edges *E, const fold__patch *p, int *loc,
                     const double *depth, double *uv, double *lambda);

/* The region p laid inside the images of its boundary: own is its own
 * tube chart (fold__tube_chart, rate lambda_own), uv holds its boundary's
 * images in the target's tube chart (rate lambda; the first p->nb
 * entries) and receives the other vertices: the one at share s and angle
 * a in own goes to the target's share t_b + s (1 - t_b) at the angle of
 * the boundary's image at a, t_b the images' share there (both
 * interpolated between the loop's two vertices about a; the images'
 * angles, where they step back, by their increasing fit). One-to-one when
 * the images turn once round the centre as the loop does. Returns 0, 1
 * when they do not, -1 when out of memory. */
int fold__tube_fit(const fold__patch *p, const double *own, double lambda_own, double lambda,
                   double *uv);

#endif
