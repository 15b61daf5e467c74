/* geo_curvature.h — per-vertex mean curvature: from the cotan
 * mean-curvature normal, and from a shape operator fitted over a
 * neighbourhood (the estimator the quality metric uses).
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
 * (test_geo_curvature bounds both on icospheres). */
#ifndef GEO_CURVATURE_H
#define GEO_CURVATURE_H
#include "geo/geo_csr.h"
#include "geo/geo_edges.h"
#include "mesh/mesh.h"

#include <stddef.h>

/* L: nv by nv cotan Laplacian of m; mass: nv; vn: nv by 3 vertex normals
 * (geo_vertex_normals). H: nv. Errors: GEO_EMISMATCH (L not nv by nv),
 * GEO_ENOMEM. */
int geo_mean_curvature(const mesh *m, const geo_csr *L, const double *mass,
                       const double *vn, double *H, char *err, size_t errsz);

/* H_i = (s11 + s22) / 2 of the symmetric 2 by 2 shape operator S that best
 * maps, in vertex i's tangent plane, the position differences p_j - p_i of
 * its neighbours to their normal differences n_j - n_i (weighted least
 * squares, weight exp(-2 |p_j - p_i|^2 / radius^2)): the normal-variation
 * fit of Kalogerakis et al. 2007, the estimator the elastic-matching paper
 * measures mean curvature with, without its robust reweighting. The
 * neighbours are the vertices reached over faces through vertices within
 * `radius` of p_i (so the other side of a thin part is not one), and always
 * the one ring. Same sign convention as above (a sphere of radius r with
 * outward normals: 1/r). Unlike the cotan formula it is smooth at the scale
 * of the radius, so two meshes of one shape with different triangulations
 * get nearly the same function. e: edge table of m; vn: unit vertex
 * normals. Errors: GEO_EMISMATCH (e of another mesh), GEO_EDEGENERATE
 * (radius not positive), GEO_ENOMEM. */
int geo_mean_curvature_fit(const mesh *m, const geo_edges *e, const double *vn, double radius,
                           double *H, char *err, size_t errsz);

#endif
