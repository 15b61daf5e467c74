/* geo_orient.h — the signed angle between the gradients of two functions
 * on a surface, the orientation-sensitive descriptor of a map's start:
 *
 *   o(t) = ⟨n_t, ∇f × ∇g⟩ / (|∇f| |∇g|) = sin of the angle from ∇f to ∇g,
 *
 * per face t (f, g piecewise linear, n_t the unit normal by the corner
 * order, geo_normals.h), then per vertex the area-weighted mean of its
 * faces. In [-1, 1]. An orientation-preserving isometry keeps it; a
 * reflection (a mirrored map: front onto back, left onto right) negates
 * it, while distances to landmarks cannot tell the two apart. Faces where
 * either gradient vanishes or that are degenerate contribute 0.
 * Output arrays are allocated by the caller. */
#ifndef GEO_ORIENT_H
#define GEO_ORIENT_H
#include "mesh/mesh.h"

/* f, g: nv values each, read with the strides fs, gs (f[v * fs]); o: nv.
 * Returns 0, or -1 when out of memory (o is then untouched). */
int geo_gradient_sine(const mesh *m, const double *f, int fs, const double *g, int gs,
                      double *o);

#endif
