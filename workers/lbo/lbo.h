/* lbo.h — the first k eigenpairs of the Laplace–Beltrami operator of a
 * mesh, L phi = lambda M phi, the basis functional maps, the spectral
 * descriptors and DDM work in.
 *
 * Operators: whatever symmetric positive semi-definite L (both triangles
 * stored) and positive lumped mass M the caller hands in; the engine hands
 * in the cotan Laplacian and mass of the intrinsic Delaunay triangulation
 * the geodesics use (geod_solver_laplacian / geod_solver_mass): every edge
 * weight >= 0, and the same operators for distances and spectra.
 *
 * Method: shift-invert Lanczos. CHOLMOD factorises L - sigma M once, with
 * sigma = LBO_SHIFT_REL * mean(L_ii) / mean(M_ii) < 0 (so the matrix is
 * positive definite although L is singular), and ARPACK's implicitly
 * restarted Lanczos (dsaupd/dseupd, mode 3, B = M) finds the k largest
 * 1 / (lambda - sigma), i.e. the k smallest lambda. Start vector: a fixed
 * pseudo-random one (ARPACK's own random start depends on earlier calls in
 * the process), so results are reproducible. Convergence tolerance: ARPACK's
 * machine-precision default.
 *
 * Output conventions: lambda ascending (the first is ~0 on a closed or
 * Neumann mesh: the constants; no boundary condition is imposed, so a mesh
 * with boundary gets the Neumann spectrum); phi is nv by k, row-major (row
 * i = vertex i's spectral coordinates), columns M-orthonormal
 * (phi^T M phi = I), each column's sign fixed so that its largest-magnitude
 * entry is positive (lowest vertex on ties). Within a multiple eigenvalue
 * the basis of the eigenspace is whatever Lanczos found.
 *
 * Ownership: lbo_eigenpairs fills a caller-provided lbo_basis whose arrays
 * it allocates; lbo_basis_close frees them (a zeroed or closed basis is
 * accepted). No global state; calls are independent. */
#ifndef LBO_H
#define LBO_H
#include "geo/geo_csr.h"

#include <stddef.h>
#include "util/errlist.h"

#define LBO_MAX_K 300           /* eigenpairs at most */
#define LBO_SHIFT_REL (-1e-6)   /* sigma relative to mean(L_ii) / mean(M_ii) */
#define LBO_MAX_RESTARTS 2000   /* ARPACK restarts at most */

#define LBO_ERRORS(X)                                                       \
    X(LBO_OK,        0, "ok", NONE)                                           \
    X(LBO_ENOMEM,   -1, "out of memory", NOMEM)                               \
    X(LBO_EINVAL,   -2, "invalid argument", INTERNAL)                         \
    X(LBO_EFACTOR,  -3, "sparse factorisation failed", NUMERIC)               \
    X(LBO_EARPACK,  -4, "ARPACK failed", NUMERIC)                             \
    X(LBO_ENOCONV,  -5, "eigenpairs did not converge", NUMERIC)

ERRLIST_ENUM(lbo, LBO_ERRORS);

typedef struct lbo_basis {
    int nv, k;
    double *lambda;   /* k, ascending */
    double *phi;      /* nv by k, row-major, M-orthonormal columns */
    int restarts;     /* ARPACK restarts used (iparam[2] on return) */
    int op_solves;    /* solves with the factorisation */
} lbo_basis;

/* The first k eigenpairs of L phi = lambda M phi (L: nv by nv, mass: nv,
 * every entry >= 0, at least one > 0). Errors, detail in err:
 * LBO_EINVAL (k < 1, k > LBO_MAX_K, k > nv - 2: Lanczos needs room; a
 * negative or non-finite mass; L not square of size nv), LBO_EFACTOR,
 * LBO_EARPACK (with ARPACK's info code), LBO_ENOCONV (fewer than k
 * converged within LBO_MAX_RESTARTS), LBO_ENOMEM. On error *out is zeroed. */
int lbo_eigenpairs(const geo_csr *L, const double *mass, int nv, int k, lbo_basis *out,
                   char *err, size_t errsz);
void lbo_basis_close(lbo_basis *b);
/* *out: a copy of b's first k eigenpairs (its own arrays, freed by
 * lbo_basis_close), for what must see only them (descriptors built from
 * the whole basis). LBO_EINVAL for k < 1 or k > b->k (out zeroed),
 * LBO_ENOMEM. */
int lbo_basis_first(const lbo_basis *b, int k, lbo_basis *out);

#endif
