/* ener_def.h — the elastic deformation energy of ECTM and its gradient:
 *   W_def(X, Y) = α·W_mem + η·W_bnd
 * for a deformation Y (nv by 3) of a reference mesh X with the same faces.
 *
 * Membrane: W_mem = Σ_t â_t · W(G_t), â_t the reference area of face t,
 *   G_t = ĝ_t⁻¹ g_t with g_t = [e1 | −e2]ᵀ[e1 | −e2] the first fundamental
 *   form from two edges of t (the same two edges in X and Y), and
 *   W(A) = μ/2·tr A + λ/4·det A − (μ/2 + λ/4)·log det A − μ − λ/4, λ = μ = 1.
 *   W(I) = 0, ∇W(I) = 0. Below det A = ε (log_eps) the −log x term is
 *   replaced by its tangent line −log ε − (x − ε)/ε, so W stays C¹ and finite
 *   for degenerate and inverted faces.
 * Bending: W_bnd = Σ_e (cos θ̂_e − cos θ_e)² · l̂_e² / d̂_e over admissible
 *   interior edges, cos θ_e = ⟨n_t, n_t'⟩ of the unit normals of the two
 *   faces at e, l̂_e the reference edge length, d̂_e = (â_t + â_t')/3.
 *   An edge is admissible when both its faces are non-degenerate in the
 *   current Y (ener_def_update_admissible; all interior edges at creation).
 *
 * Layout: per face (membrane, unit normal) and per edge (bending, from the
 * two normals) into element-local buffers, the bending gradient taken back
 * through each face's normal into that face's corner slots, then a
 * per-vertex gather over the sorted vertex -> face lists of geo_edges:
 * deterministic (the same bits for any thread count), no atomics, OpenMP
 * threads. ener_def.c's DESIGN comment has the passes.
 *
 * Reference quantities (ĝ⁻¹, â, l̂², d̂, cos θ̂) are computed once in
 * ener_def_new. The object keeps pointers to X's faces and to the edge table
 * (the caller keeps them alive) and owns its caches and scratch buffers, so
 * one ener_def must not be evaluated from two threads at once. */
#ifndef ENER_DEF_H
#define ENER_DEF_H
#include <stddef.h>
#include "mesh/mesh.h"
#include "geo/geo_edges.h"
#include "util/errlist.h"

#define ENER_LOG_EPS_DEFAULT 1e-20

#define ENER_ERRORS(X)                                                     \
    X(ENER_OK,          0, "ok")                                           \
    X(ENER_ENOMEM,     -1, "out of memory")                                \
    X(ENER_EINVAL,     -2, "invalid argument")                             \
    X(ENER_EDEGENERATE, -3, "degenerate reference face")                   \
    X(ENER_ENODEVICE,  -4, "no usable OpenCL device")                      \
    X(ENER_EBUILD,     -5, "OpenCL kernel build failed")                   \
    X(ENER_EDEVICE,    -6, "OpenCL device error")

ERRLIST_ENUM(ener, ENER_ERRORS);
const char *ener_strerror(int code);

typedef struct ener_def_params {
    double alpha;    /* membrane weight (≥ 0) */
    double eta;      /* bending weight (≥ 0) */
    double log_eps;  /* tangent-line extension of −log below this det G (> 0) */
    const double *face_scale;  /* per face, the factor of the reference metric
                                  ĝ (its area grows by it); NULL: 1 */
} ener_def_params;

typedef struct ener_def ener_def;

/* Returns NULL (detail in err, prefixed by the ENER_E* message) on out of
 * memory, a bad parameter (α < 0, η < 0, log_eps ≤ 0, E not built from X),
 * or a degenerate reference face (zero area in X). */
ener_def *ener_def_new(const mesh *X, const geo_edges *E, const ener_def_params *p,
                       char *err, size_t errsz);
void ener_def_free(ener_def *d);

/* Marks admissible the interior edges whose two faces have non-zero area in
 * Y (area > 1e-6 of its reference area). Returns the number admissible. */
int ener_def_update_admissible(ener_def *d, const double *Y);

/* Returns α·W_mem + η·W_bnd at Y; grad (nv by 3) is overwritten with the
 * gradient when non-NULL; *w_mem and *w_bnd (may be NULL) receive the
 * unweighted terms. */
double ener_def_eval(ener_def *d, const double *Y, double *grad,
                     double *w_mem, double *w_bnd);

/* Single-element kernels, exposed for finite-difference tests. */
/* Membrane density â·W(G) of one face with reference inverse metric ginv
 * (symmetric 2×2 as {a, b, c} = [[a, b], [b, c]]) and area ahat, at corner
 * positions y0, y1, y2; g (9 values, may be NULL) receives the gradient. */
double ener_membrane_face(const double ginv[3], double ahat, double log_eps,
                          const double *y0, const double *y1, const double *y2,
                          double g[9]);
/* Bending term (cos θ̂ − cos θ)²·w of one edge (i, j) with opposite vertices
 * k (in the first face (i, j, k) order as in the mesh) and l; g (12 values:
 * i, j, k, l) may be NULL. Faces are (yi, yj, yk) and (yj, yi, yl) in
 * counter-clockwise order. */
double ener_bending_edge(double cos_ref, double weight,
                         const double *yi, const double *yj,
                         const double *yk, const double *yl, double g[12]);

#endif
