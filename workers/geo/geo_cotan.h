/* geo_cotan.h — the cotangent Laplacian of a triangle mesh.
 *
 * Convention (positive semi-definite, "L = -Laplace-Beltrami, not divided by
 * area"): for an edge ij with opposite corner angles alpha, beta
 *     L_ij = -(cot alpha + cot beta) / 2,     L_ii = -sum_{j != i} L_ij,
 * so L 1 = 0, L is symmetric and, for x a function on the vertices,
 *     x^T L x = sum_edges w_ij (x_i - x_j)^2 = integral of |grad x|^2
 * over the piecewise-linear interpolant: twice its Dirichlet energy.
 * A boundary edge has one cotangent. Degenerate faces (geo_tri.h rule)
 * contribute nothing (their cotangents would be infinite), so an edge whose
 * faces are all degenerate is stored with 0. Obtuse angles give negative
 * cotangents: off-diagonal entries may be positive; the diagonal is
 * positive for every vertex with a non-degenerate face.
 *
 * Output: an nv by nv geo_csr (geo_csr.h) holding, per row, the diagonal and
 * one entry per incident edge, columns sorted. Caller frees with
 * geo_csr_free. */
#ifndef GEO_COTAN_H
#define GEO_COTAN_H
#include "geo/geo_csr.h"
#include "geo/geo_edges.h"
#include "mesh/mesh.h"

#include <stddef.h>

/* The Laplacian from the edge table e built from m. Errors: GEO_EMISMATCH
 * when e was built from a mesh of another size, GEO_ENOMEM. */
int geo_cotan_laplacian(const mesh *m, const geo_edges *e, geo_csr **out,
                        char *err, size_t errsz);

#endif
