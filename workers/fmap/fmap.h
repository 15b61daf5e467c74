/* fmap.h — functional maps between two meshes from landmarks and spectral
 * descriptors (Ovsjanikov et al. 2012), in the convention of the thesis'
 * chapter 2 (DDM):
 *
 *   C (k1 by k2) carries coefficients on M2 to coefficients on M1, so that
 *   Psi1 C ~ P Psi2 for the pointwise map P (n1 by n2, f1 = P f2), and for
 *   isometries C is nearly orthogonal and nearly commutes with the
 *   eigenvalues: Lambda1 C ~ C Lambda2.
 *
 * Least squares: with A1 = Psi1^T M1 F1 (k1 by nd), A2 = Psi2^T M2 F2
 * (k2 by nd) the coefficients of corresponding descriptor columns,
 *   C = argmin ||C A2 - A1||_F^2 + mu ||Lambda1 C - C Lambda2||_F^2.
 * The Laplacian term is sum_ab D_ab C_ab^2 with D_ab = (lambda1_a -
 * lambda2_b)^2, here divided by ||D||_F (pyFM's scaling, so mu does not
 * depend on the meshes' scale), and the problem separates by rows of C:
 * row a solves (A2 A2^T + mu diag(D_a.)) c_a^T = A2 A1_a.^T (k2 by k2,
 * LAPACK Cholesky). Each descriptor column is first divided by its M-norm
 * on its own shape (pyFM's normalisation).
 *
 * Descriptors from landmarks (fmap_landmark_descriptors): the WKS at ne
 * energies and, per landmark pair, the wave kernel map of the landmark at
 * the same energies (desc.h), energies taken from M1's spectrum and used on
 * both shapes; both meshes should be at unit area.
 *
 * Commutativity with operators (fmap_from_descriptors_normal, _oriented):
 * for an operator on functions reduced to the bases, X1 (k1 by k1) on M1
 * and X2 (k2 by k2) on M2, the term ||X1 C - C X2||_F^2 (C carries a
 * function's coefficients from M2 to M1, so applying X2 then C equals C
 * then X1). Δ and D_N (fmap_normal_operator) are preserved by isometries,
 * reflections included; the orientation operators of Ren et al. 2018
 * (fmap_orientation_operators: F_f(g) = <n, grad f x grad g> for each of a
 * few descriptors f) change sign under a reflection, so their term tells
 * a map from its mirror image.
 *
 * The vertex map (fmap_vertex_map): each vertex i of M1 goes to the vertex
 * j of M2 whose spectral coordinates (row j of Psi2, first k2 columns) are
 * nearest to row i of Psi1 C, by exhaustive search (exact; n1 n2 k2 work).
 *
 * Shapes are row-major. Errors: FMAP_EINVAL (a k above a basis' size or
 * below 1, nd < 1, a negative weight), FMAP_ESOLVE (a row's system not
 * positive definite: too few descriptors and mu = 0), FMAP_ENOMEM; detail
 * in err. */
#ifndef FMAP_H
#define FMAP_H
#include "lbo/lbo.h"
#include "lmk/lmk.h"
#include "mesh/mesh.h"

#include <stddef.h>
#include "util/errlist.h"

/* Weight of the Laplacian term, chosen on FAUST and TOSCA pairs
 * (docs/decisions.md, "Functional map weights"). */
#define FMAP_MU_LAP_DEFAULT 0.1
#define FMAP_ENERGIES_DEFAULT 50   /* WKS / WKM energies */

#define FMAP_ERRORS(X)                                                      \
    X(FMAP_OK,      0, "ok")                                                \
    X(FMAP_ENOMEM, -1, "out of memory")                                     \
    X(FMAP_EINVAL, -2, "invalid argument")                                  \
    X(FMAP_ESOLVE, -3, "least-squares system singular")

ERRLIST_ENUM(fmap, FMAP_ERRORS);

/* F1: n1 by nd, F2: n2 by nd (corresponding columns), m1, m2 the lumped
 * masses; C: k1 by k2. */
int fmap_from_descriptors(const lbo_basis *b1, const double *m1, const double *F1,
                          const lbo_basis *b2, const double *m2, const double *F2, int nd,
                          int k1, int k2, double mu, double *C, char *err, size_t errsz);

/* The same objective plus D_N commutativity (seed 2017, §8.1):
 *   + mu_n ||N1 C - C N2||_F^2 / (||N1||_F ||N2||_F),
 * N1 (k1 by k1) and N2 (k2 by k2) the reduced normal operators
 * (fmap_normal_operator). No longer row-separable: conjugate gradients on
 * the normal equations in the k1 k2 entries of C (preconditioned by their
 * diagonal), started from the Laplacian-only solution, until the residual
 * is below FMAP_CG_TOL of the right-hand side (at most FMAP_CG_MAX_ITER
 * steps; *iterations, may be NULL). mu_n = 0 gives fmap_from_descriptors'
 * result. */
/* D_N weight, chosen on FAUST pairs (test_fmap.c checks it; docs/decisions.md,
 * "Functional map weights"). */
#define FMAP_MU_NORMAL_DEFAULT 1.0
#define FMAP_CG_TOL 1e-10
#define FMAP_CG_MAX_ITER 5000
int fmap_from_descriptors_normal(const lbo_basis *b1, const double *m1, const double *F1,
                                 const double *N1, const lbo_basis *b2, const double *m2,
                                 const double *F2, const double *N2, int nd, int k1, int k2,
                                 double mu, double mu_n, double *C, int *iterations, char *err,
                                 size_t errsz);

/* The same objective plus orientation-preserving commutativity (Ren,
 * Poulenard, Wonka, Ovsjanikov 2018):
 *   + mu_o / no sum_d ||O1_d C - C O2_d||_F^2 / (||O1_d||_F ||O2_d||_F),
 * O1 (no by k1 by k1) and O2 (no by k2 by k2) the reduced orientation
 * operators of corresponding descriptors (fmap_orientation_operators). Δ
 * and D_N are blind to a reflection; O_f changes sign under one, so a
 * mirrored C (O1 C ~ -C O2) pays about 4 mu_o. The normal equations gain
 * sum_d (O1_d^T R_d - R_d O2_d^T) (O is not symmetric); same conjugate
 * gradients, tolerance and errors as fmap_from_descriptors_normal (N1, N2
 * may be NULL when mu_n = 0, O1, O2 when no = 0 or mu_o = 0). mu_o = 0 or
 * no = 0 gives fmap_from_descriptors_normal's result bit for bit. */
/* Orientation weight and the descriptors it uses: per block of
 * fmap_landmark_descriptors' columns (the WKS, each landmark's WKM) the
 * FMAP_ORIENT_ENERGIES columns fmap_orientation_columns picks. The weight is
 * the best of the values tried on SHREC'07 pairs, and the smallest of them
 * that keeps the mirrored plier of test_fmap below 10 % flipped
 * (docs/decisions.md, "Functional map weights"). */
#define FMAP_MU_ORIENT_DEFAULT 3.0
#define FMAP_ORIENT_ENERGIES 5
int fmap_from_descriptors_oriented(const lbo_basis *b1, const double *m1, const double *F1,
                                   const double *N1, const double *O1, const lbo_basis *b2,
                                   const double *m2, const double *F2, const double *N2,
                                   const double *O2, int nd, int no, int k1, int k2, double mu,
                                   double mu_n, double mu_o, double *C, int *iterations,
                                   char *err, size_t errsz);

/* The orientation-aware operator of a descriptor f (Ren et al. 2018, §4),
 *   F_f(g) = <n, grad f x grad g>   (= <J grad f, grad g>, J the rotation
 *   by +90 degrees about the outward unit normal n),
 * per face with n the face's unit normal (the right-hand rule on its
 * corner order: outward for an outward-oriented mesh) and grad f, grad g
 * the gradients of the linear interpolants, reduced to the first k basis
 * functions: O_f (k by k) = Psi^T M F_f Psi with the per-face values
 * integrated exactly, (O_f)_ab = sum_t area_t mean_{c in t}(psi_a) (F_f
 * psi_b)_t (the same as taking F_f psi_b to the vertices by area-weighted
 * averaging and weighting by the lumped mass). Properties the tests check:
 * on a closed mesh O_f is antisymmetric (J grad f is divergence-free), its
 * row and column of the constant vanish, and reflecting the mesh (faces
 * reversed so that normals stay outward) negates it; per face area_t
 * <n, grad f x grad phi_c> = (f_{c+2} - f_{c+1}) / 2 for the hat function
 * phi_c of corner c, so O_f depends on the mesh only through its faces'
 * orientation and the basis. F: nv by nd (row-major), cols: the no columns
 * f to use; O: no by k by k. Degenerate faces contribute nothing.
 * FMAP_EINVAL for k out of the basis, a basis of another size, no < 0 or a
 * column out of range. */
int fmap_orientation_operators(const mesh *m, const lbo_basis *b, const double *F, int nd,
                               const int *cols, int no, int k, double *O, char *err,
                               size_t errsz);
/* The columns of fmap_landmark_descriptors(ne energies, nl landmarks) the
 * orientation term uses: in each of the 1 + nl blocks, per energies
 * evenly spaced energy indices (all ne when per >= ne). cols: room for
 * (1 + nl) min(per, ne); returns the count. */
int fmap_orientation_columns(int ne, int nl, int per, int *cols);

/* *F1 (n1 by *nd) and *F2 (n2 by *nd), malloc()ed, caller frees:
 * *nd = ne * (1 + L->n) columns (WKS, then each landmark's WKM). */
int fmap_landmark_descriptors(const lbo_basis *b1, const lbo_basis *b2, const lmk_set *L,
                              int ne, double **F1, double **F2, int *nd, char *err,
                              size_t errsz);

/* The functional deformation field of an extrinsic vector field V (seed
 * functional-deformation-fields-2017, §4 and §6), reduced to the first k
 * basis functions: D (k by k, symmetric) = Psi^T W_V Psi, where
 *   f^T W_V h = sum_t area_t (L_V g)_t(grad f, grad h),
 *   (L_V g)(X, Y) = <dV X, Y> + <dV Y, X>,
 * the Lie derivative of the metric, per triangle with dV the (constant)
 * differential of V's linear interpolant on the mesh's own triangles and
 * grad f that of f's. (The seed's text lost its formulas; this follows its
 * definition: per-edge finite differences of V, which is what dV is on a
 * triangle.) Checks the tests make: V = positions gives L_V g = 2 g, so D =
 * 2 Psi^T L_cotan Psi; V = a rigid motion gives D = 0. With V the unit
 * vertex normals (fmap_normal_operator) L_N g = 2 II with II(X, Y) =
 * <dN X, Y> (on the unit sphere with outward normals II = g): D_N carries
 * the second fundamental form. V: nv by 3. Degenerate faces contribute
 * nothing. FMAP_EINVAL for k out of the basis or a basis of another size. */
int fmap_deformation_operator(const mesh *m, const double *V, const lbo_basis *b, int k,
                              double *D, char *err, size_t errsz);
/* fmap_deformation_operator of the area-weighted unit vertex normals. */
int fmap_normal_operator(const mesh *m, const lbo_basis *b, int k, double *D, char *err,
                         size_t errsz);

/* ZoomOut (Melzi et al. 2019, "ZoomOut: spectral upsampling for efficient
 * shape correspondence"): from C0 (k0 by k0), rounds of
 *   (a) the vertex map Pi: vertex i of M1 -> the vertex j of M2 whose
 *       first k coordinates (Psi2) are nearest to row i of Psi1 C
 *       (fmap_vertex_map's rule, the thesis' row-wise form of the
 *       spectral nearest neighbour), and
 *   (b) C <- Psi1^T M1 Pi Psi2 on k + step functions each (Psi1^+ =
 *       Psi1^T M1),
 * until k = kmax, then (a) once more. C: kmax by kmax, the last round's
 * functional map; map: n1 vertices of M2, the vertex map of C (the NN
 * map; DDM deblurring of C gives a precise one). The nearest neighbours
 * are exhaustive (exact), each row's search bounded from the start by its
 * previous round's match (n1 n2 k work at worst per round; the spectral
 * coordinates of 20 to 100 dimensions leave a k-d tree little to prune).
 * m1: M1's lumped mass. stats (may be NULL): rounds of (b), seconds in
 * the searches (a), and the coordinates they compared as a fraction of
 * brute force's n1 n2 k per search. FMAP_EINVAL
 * for k0 < 1, kmax < k0, kmax above a basis, step < 1, no mass;
 * FMAP_ENOMEM. */
#define FMAP_ZOOMOUT_STEP 1   /* the paper's: one function per round */
typedef struct fmap_zoomout_stats {
    int rounds;          /* functional maps recomputed (one per size step) */
    double nn_seconds;   /* wall seconds in the nearest-neighbour searches */
    double nn_work;      /* coordinates compared / (n1 n2 k) summed over searches */
} fmap_zoomout_stats;
int fmap_zoomout(const lbo_basis *b1, const double *m1, const lbo_basis *b2, const double *C0,
                 int k0, int kmax, int step, double *C, int *map, fmap_zoomout_stats *stats,
                 char *err, size_t errsz);

/* map: n1 vertices of M2. */
int fmap_vertex_map(const lbo_basis *b1, const lbo_basis *b2, const double *C, int k1, int k2,
                    int *map, char *err, size_t errsz);

#endif
