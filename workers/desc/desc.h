/* desc.h — spectral point descriptors from a Laplace–Beltrami basis
 * (lbo.h): the heat kernel signature (Sun, Ovsjanikov, Guibas 2009), the
 * wave kernel signature and the landmark-anchored wave kernel map (Aubry,
 * Schlickewei, Cremers 2011), which the thesis' DDM experiments use as
 * functional-map constraints.
 *
 * With (lambda_j, phi_j) the basis (phi M-orthonormal):
 *   HKS(x, t)    = sum_j exp(-lambda_j t) phi_j(x)^2
 *   WKS(x, e)    = C_e sum_j g_e(lambda_j) phi_j(x)^2
 *   WKM_l(x, e)  = C_e sum_j g_e(lambda_j) phi_j(l) phi_j(x)   (landmark vertex l)
 *   g_e(lambda)  = exp(-(e - log lambda)^2 / (2 sigma^2)),  C_e = 1 / sum_j g_e(lambda_j)
 * g_e is 0 for lambda_0 (lbo's spectra start with the constants) and for
 * any lambda <= DESC_ZERO_REL * lambda_max (more components: log of ~0),
 * so WKS and WKM ignore them. Identities the tests check:
 * sum_x M_x HKS(x, t) = sum_j exp(-lambda_j t) and sum_x M_x WKS(x, e) = 1.
 *
 * Defaults (the papers' choices): times log-spaced over
 * [4 ln 10 / lambda_max, 4 ln 10 / lambda_1]; sigma = DESC_WKS_SIGMA_REL
 * (log lambda_max - log lambda_1) (Aubry et al.: 7 steps of 100 energies,
 * whatever ne is: a width tied to ne's spacing makes a few energies so wide
 * that every one averages the whole spectrum and measures mesh-level
 * detail), energies evenly spaced over [log lambda_1 + 2 sigma,
 * log lambda_max - 2 sigma] (pyFM's margins). lambda_1 is the first
 * eigenvalue above the zero threshold.
 * The descriptors depend on scale: compare shapes at the same total area.
 *
 * Shapes: outputs are nv by (columns), row-major, caller-allocated; WKM's
 * columns are landmark-major (column a * ne + q = landmark a, energy q).
 * Errors: DESC_EINVAL (no eigenvalue above the zero threshold, a count < 1,
 * a landmark out of range, sigma <= 0), DESC_ENOMEM, else DESC_OK. */
#ifndef DESC_H
#define DESC_H
#include "lbo/lbo.h"
#include "util/errlist.h"

#define DESC_ZERO_REL 1e-8       /* eigenvalues below this share of the largest count as 0 */
#define DESC_WKS_SIGMA_REL 0.07  /* WKS width: share of the log-eigenvalue range */

#define DESC_ERRORS(X)                                                      \
    X(DESC_OK,      0, "ok")                                                \
    X(DESC_EINVAL, -1, "invalid argument")                                 \
    X(DESC_ENOMEM, -2, "out of memory")

ERRLIST_ENUM(desc, DESC_ERRORS);

/* t: nt default times (ascending); e: ne default energies, *sigma their width. */
int desc_hks_times(const lbo_basis *b, int nt, double *t);
int desc_wks_energies(const lbo_basis *b, int ne, double *e, double *sigma);

/* out: nv by nt. */
int desc_hks(const lbo_basis *b, const double *t, int nt, double *out);
/* out: nv by ne. */
int desc_wks(const lbo_basis *b, const double *e, int ne, double sigma, double *out);
/* out: nv by (nl * ne), landmark-major; lmk: nl vertices. */
int desc_wkm(const lbo_basis *b, const int *lmk, int nl, const double *e, int ne, double sigma,
             double *out);

#endif
