/* ddm.h — DDM map deblurring (thesis ch. 2, §2.2.3 and App. A.2): the
 * precise map P (vertex of M1 -> point on a face of M2) minimising
 * ||Psi1 C - P Psi2||^2_{M1} over row-stochastic barycentric P, for a
 * functional map C (k1 by k2, fmap.h's convention: Psi1 C ~ P Psi2).
 *
 * The objective separates by rows: row i is the point of M2, embedded in
 * R^k2 by the first k2 columns of Psi2, nearest to b = row i of Psi1 C.
 * Per row:
 *  - g_v = <A_v, b> for every vertex v of M2 (A = Psi2's first k2 columns),
 *    so that |A_v - b|^2 = |A_v|^2 - 2 g_v + |b|^2 and every face's
 *    quadratic in its two barycentric coordinates comes from precomputed
 *    Gram entries and three g's: O(1) per face after O(n2 k2) per row;
 *  - the bound of App. A.2: a face f can hold the minimiser only if
 *    delta_min(f) - l_max(f) <= best, delta_min the distance from b to f's
 *    nearest corner, l_max f's longest edge in R^k2, best the distance of
 *    the best point found so far (at first the nearest vertex, the
 *    thesis' Delta_min; it only shrinks, so the rule stays exact);
 *  - each remaining face solved exactly: the unconstrained stationary
 *    point when it lies inside the triangle, else the best of the three
 *    edges (each a clamped 1-D minimisation). Ties go to the lowest face.
 *
 * Results: P (n1 rows, faces of M2, weights in f's corner order) and, when
 * stats is not NULL, the faces solved against the faces there were.
 * Rows are independent (OpenMP); results do not depend on the thread count.
 * Errors: DDM_EINVAL (a k out of its basis, a face index out of range, P's
 * size not n1 by n2), DDM_ENOMEM; detail in err. */
#ifndef DDM_H
#define DDM_H
#include "lbo/lbo.h"
#include "map/bmap.h"
#include "mesh/mesh.h"

#include <stddef.h>

#define DDM_ERRORS(X)                                                       \
    X(DDM_OK,      0, "ok")                                                 \
    X(DDM_ENOMEM, -1, "out of memory")                                      \
    X(DDM_EINVAL, -2, "invalid argument")

enum ddm_error {
#define DDM_ENUM(name, val, msg) name = val,
    DDM_ERRORS(DDM_ENUM)
#undef DDM_ENUM
};
const char *ddm_strerror(int code);

typedef struct ddm_stats {
    long long faces_solved;   /* exact face problems solved, all rows */
    long long faces_total;    /* n1 * nf2 */
    double cost;              /* sum_i M1_ii |b_i - P_i Psi2|^2: the objective */
} ddm_stats;

/* m1: M1's lumped mass (for stats->cost; may be NULL, then cost is 0);
 * T: M2's faces (its vertex count must be b2->nv); P: bmap_new(b1->nv, T->nv). */
int ddm_deblur(const lbo_basis *b1, const double *m1, const lbo_basis *b2, const mesh *T,
               const double *C, int k1, int k2, bmap *P, ddm_stats *stats, char *err,
               size_t errsz);

/* DDM denoising (thesis §2.1.2, eq. 2.5): a given map P0 (n1 rows onto
 * T: barycentric, or a vertex map written as weight 1 at one corner)
 * blurred to C = Psi1^T M1 P0 Psi2 (k1 by k2: its projection on the
 * smoothest k1 functions of M1; Psi1^+ = Psi1^T M1) and deblurred into P by
 * ddm_deblur. k1 sets the smoothing: fewer functions, smoother map.
 * m1 is required here. Errors as ddm_deblur, and DDM_EINVAL for P0 of
 * another size or a face out of range. */
int ddm_denoise(const lbo_basis *b1, const double *m1, const lbo_basis *b2, const mesh *T,
                const bmap *P0, int k1, int k2, bmap *P, ddm_stats *stats, char *err,
                size_t errsz);

#endif
