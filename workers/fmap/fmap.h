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
 * The vertex map (fmap_vertex_map): each vertex i of M1 goes to the vertex
 * j of M2 whose spectral coordinates (row j of Psi2, first k2 columns) are
 * nearest to row i of Psi1 C, by exhaustive search (exact; n1 n2 k2 work).
 *
 * Shapes are row-major. Errors: FMAP_EINVAL (a k above a basis' size or
 * below 1, nd < 1, mu < 0), FMAP_ESOLVE (a row's system not positive
 * definite: too few descriptors and mu = 0), FMAP_ENOMEM; detail in err. */
#ifndef FMAP_H
#define FMAP_H
#include "lbo/lbo.h"
#include "lmk/lmk.h"

#include <stddef.h>

/* Weight of the Laplacian term. pyFM's 1e-3 left FAUST 000 -> 001 at 0.38
 * mean geodesic error with k = 50 (our descriptor term is not pyFM's);
 * 0.1 gave 0.053, and was also the best of 1e-3, 1e-2, 0.1 on FAUST
 * 002 -> 007 and TOSCA wolf0 -> wolf2 for k = 30, 50, 80. */
#define FMAP_MU_LAP_DEFAULT 0.1
#define FMAP_ENERGIES_DEFAULT 50   /* WKS / WKM energies */

#define FMAP_ERRORS(X)                                                      \
    X(FMAP_OK,      0, "ok")                                                \
    X(FMAP_ENOMEM, -1, "out of memory")                                     \
    X(FMAP_EINVAL, -2, "invalid argument")                                  \
    X(FMAP_ESOLVE, -3, "least-squares system singular")

enum fmap_error {
#define FMAP_ENUM(name, val, msg) name = val,
    FMAP_ERRORS(FMAP_ENUM)
#undef FMAP_ENUM
};
const char *fmap_strerror(int code);

/* F1: n1 by nd, F2: n2 by nd (corresponding columns), m1, m2 the lumped
 * masses; C: k1 by k2. */
int fmap_from_descriptors(const lbo_basis *b1, const double *m1, const double *F1,
                          const lbo_basis *b2, const double *m2, const double *F2, int nd,
                          int k1, int k2, double mu, double *C, char *err, size_t errsz);

/* *F1 (n1 by *nd) and *F2 (n2 by *nd), malloc()ed, caller frees:
 * *nd = ne * (1 + L->n) columns (WKS, then each landmark's WKM). */
int fmap_landmark_descriptors(const lbo_basis *b1, const lbo_basis *b2, const lmk_set *L,
                              int ne, double **F1, double **F2, int *nd, char *err,
                              size_t errsz);

/* map: n1 vertices of M2. */
int fmap_vertex_map(const lbo_basis *b1, const lbo_basis *b2, const double *C, int k1, int k2,
                    int *map, char *err, size_t errsz);

#endif
