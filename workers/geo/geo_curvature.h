/* geo_curvature.h — per-vertex mean curvature from the cotan
 * mean-curvature normal.
 *
 * Convention: H = (k1 + k2) / 2, the average of the principal curvatures, so
 * a sphere of radius r has H = 1/r. Discretely, with L the cotan Laplacian
 * (geo_cotan.h, positive semi-definite) and M the lumped mass (geo_area.h),
 *     M^-1 L X ~ 2 H n      (X: nv by 3 positions, n: unit normal)
 *     H_i = 1/2 |(M^-1 L X)_i| * sign(<(L X)_i, vertex normal_i>),
 * positive where the surface bends away from its normals (convex with
 * outward normals, e.g. a sphere with outward-oriented faces), negative
 * where it bends towards them. Flat interior vertices get 0. Boundary
 * vertices get whatever this formula gives there (not a curvature: the
 * one-sided cotangents leave a tangential part). A vertex with zero mass
 * or zero normal gets 0. Accuracy: with the barycentric mass, H converges
 * in the area-weighted mean square but not pointwise on irregular meshes
 * (icosphere valence-5 vertices stay ~14% off; RMS error 1.7% at level 3). */
#ifndef GEO_CURVATURE_H
#define GEO_CURVATURE_H
#include "geo/geo_csr.h"
#include "mesh/mesh.h"

#include <stddef.h>

/* L: nv by nv cotan Laplacian of m; mass: nv; vn: nv by 3 vertex normals
 * (geo_vertex_normals). H: nv. Errors: GEO_EMISMATCH (L not nv by nv),
 * GEO_ENOMEM. */
int geo_mean_curvature(const mesh *m, const geo_csr *L, const double *mass,
                       const double *vn, double *H, char *err, size_t errsz);

#endif
