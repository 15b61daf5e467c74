/* geod.h — geodesic distances on a triangle mesh by the heat method (Crane,
 * Weischedel, Wardetzky 2013), with the two sparse factorisations made once
 * per mesh and reused for any number of sources.
 *
 * Method: the mesh's triangulation is first flipped to its intrinsic
 * Delaunay triangulation (same vertices, edges kept as lengths; see
 * geod__idt.h for why: on meshes with obtuse triangles the plain cotan
 * operators made distances collapse far from the source). On it, with M
 * the lumped mass and L the cotan Laplacian (positive semi-definite, every
 * edge weight >= 0), per call: one backward-Euler heat step
 * (M + t L) u = delta_sources, t = t_factor * h^2 with h the mesh's mean
 * edge length; per triangle X = -grad u / |grad u|; per vertex the
 * integrated divergence of X; then the Poisson problem L phi = -div X,
 * shifted so that the sources sit at 0 (see geod_distances for the exact
 * rule).
 *
 * Numerical choices:
 *  - Poisson regularisation: L is singular (constants per connected
 *    component), so the factorised matrix is L + eps M with
 *    eps * mean(M_ii) = GEOD_POISSON_REG * mean(L_ii). This shifts every
 *    non-constant mode by a relative ~1e-10 * nv (negligible) and gives each
 *    component one small, safely positive pivot; the constant part it leaves
 *    is removed by the shift.
 *  - Boundary: on a mesh with boundary the heat step is the average of the
 *    Neumann solution (the full system) and the Dirichlet one (u = 0 on
 *    boundary vertices, a third factorisation of the interior block), as the
 *    paper recommends: Neumann alone bends distances towards the boundary,
 *    Dirichlet alone away from it. The Poisson step is Neumann.
 *  - Disconnected meshes: a vertex whose connected component holds no
 *    source gets INFINITY. Degenerate faces (zero area) contribute nothing.
 *
 * Accuracy: tests/unit/test_geod.c bounds the error against exact distances on
 * icospheres and a flat disk (t_factor = 1); the error shrinks as the mesh is
 * refined. Multi-source fields are less accurate where the fronts of two
 * sources meet, and the sources are brought to 0 by a plain mean shift
 * (docs/decisions.md, "Heat-method geodesics").
 *
 * Ownership and threads: the solver borrows the mesh (it must outlive the
 * solver, unchanged) and owns its factorisations. Calls on one solver must
 * not overlap (CHOLMOD workspace is per solver); separate solvers are
 * independent. Results are deterministic (fixed AMD ordering, serial sums
 * in a fixed order). Double precision throughout. */
#ifndef GEOD_H
#define GEOD_H
#include "geo/geo_csr.h"
#include "mesh/mesh.h"

#include <stddef.h>
#include "util/errlist.h"

#define GEOD_T_FACTOR_DEFAULT 1.0  /* t = 1 * h^2, the paper's choice */
#define GEOD_POISSON_REG 1e-10     /* relative regularisation of L, see above */
#define GEOD_BATCH 32              /* right-hand sides solved together */

#define GEOD_ERRORS(X)                                                      \
    X(GEOD_OK,          0, "ok", NONE)                                        \
    X(GEOD_ENOMEM,     -1, "out of memory", NOMEM)                            \
    X(GEOD_EINVAL,     -2, "invalid argument", INTERNAL)                      \
    X(GEOD_EMESH,      -3, "mesh unusable for geodesics", MESH)               \
    X(GEOD_EFACTOR,    -4, "sparse factorisation or solve failed", NUMERIC)

ERRLIST_ENUM(geod, GEOD_ERRORS);
const char *geod_strerror(int code);

typedef struct geod_solver geod_solver;

/* Builds the operators of m and factorises (M + t L), L + eps M and, when m
 * has a boundary, the interior block of (M + t L); *out = the solver.
 * t_factor <= 0 means GEOD_T_FACTOR_DEFAULT. Returns GEOD_OK, or with *out
 * NULL and the detail in err: GEOD_EMESH (a non-manifold edge, zero total
 * area or zero mean edge length), GEOD_EFACTOR (a failed factorisation),
 * GEOD_ENOMEM (including CHOLMOD running out of memory). */
int geod_solver_new(const mesh *m, double t_factor, geod_solver **out, char *err, size_t errsz);
void geod_solver_free(geod_solver *s);

int geod_solver_nv(const geod_solver *s);
/* The operators the distances are computed with, borrowed (valid while s
 * lives): the cotan Laplacian of the intrinsic Delaunay triangulation (nv
 * by nv, both triangles, positive semi-definite, every off-diagonal entry
 * <= 0) and its lumped mass (nv). Other modules may build on them (the
 * embedding's biharmonic extension). */
const geo_csr *geod_solver_laplacian(const geod_solver *s);
const double *geod_solver_mass(const geod_solver *s);
/* Edges flipped to make that triangulation Delaunay (0: the mesh was). */
int geod_solver_flips(const geod_solver *s);

/* dist: nv. Geodesic distance from every vertex to the nearest of the nsrc
 * sources (the heat starts from all of them at once). Shift rule: per
 * connected component, phi minus the mean of phi over that component's
 * sources, then clamped at 0 below, and each source set to exactly 0.
 * Errors: GEOD_EINVAL (nsrc < 1, a source out of range), GEOD_ENOMEM,
 * GEOD_EFACTOR; dist is then unspecified. Duplicated sources are allowed. */
int geod_distances(geod_solver *s, const int *sources, int nsrc, double *dist);

/* out: k by nv, row a = geod_distances from sources[a] alone. Solved
 * GEOD_BATCH sources at a time (the cheap way to get many fields). */
int geod_all_pairs_from(geod_solver *s, const int *sources, int k, double *out);

#endif
