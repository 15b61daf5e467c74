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
#include "util/errlist.h"

#define DDM_ERRORS(X)                                                       \
    X(DDM_OK,      0, "ok", NONE)                                             \
    X(DDM_ENOMEM, -1, "out of memory", NOMEM)                                 \
    X(DDM_EINVAL, -2, "invalid argument", INTERNAL)

ERRLIST_ENUM(ddm, DDM_ERRORS);

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

/* The core of ddm_deblur for any embedding: per row i of B (n1 by d), the
 * point of T embedded in R^d by A (T->nv by d, row j = vertex j) nearest
 * to it, with the same bound and exact face problems; P: bmap_new(n1,
 * T->nv); stats->cost = sum_i m1_i |B_i - P_i A|^2 (m1 may be NULL: 0).
 * ddm_deblur is A = Psi2 (k2 columns), B = Psi1 C; ddm_denoise_bijective
 * stacks a second block of columns on both. DDM_EINVAL for d < 1, n1 < 1,
 * P of another size, a face index out of range. */
int ddm_nearest_points(const double *A, int d, const mesh *T, const double *B, int n1,
                       const double *m1, bmap *P, ddm_stats *stats, char *err, size_t errsz);

/* The functional map of a pointwise map: C (k1 by k2) = Psi1^T M1 P Psi2
 * (Psi1^+ = Psi1^T M1), P: n1 rows onto T (barycentric). m1 required.
 * DDM_EINVAL for k out of a basis, P of another size, a face out of
 * range; DDM_ENOMEM. */
int ddm_functional_map(const lbo_basis *b1, const double *m1, const lbo_basis *b2, const mesh *T,
                       const bmap *P, int k1, int k2, double *C, char *err, size_t errsz);

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

/* Bijective (consistent) denoising of a pair of maps, P0: M1 -> M2 and
 * Q0: M2 -> M1 (ddm_bijective.c). The thesis' chapter 2 gives the
 * one-way denoising; its chapter 3 compares with "the consistency
 * extension of DND" [EBC17] and defines reversibility as the composition
 * T21(T12(p)) staying at p (eq. 3.6). Here that term is added to eq. 2.5
 * in the functional form of the other direction's map, so each step stays
 * DDM's exact row-separable projection:
 *
 *   E(P, Q) = (1 - alpha) (s2/s1 |Psi1 C12 - P Psi2|^2_M1 + s1/s2 |Psi2 C21 - Q Psi1|^2_M2)
 *           + alpha (|P Psi2 D21(Q) - Psi1|^2_M1 + |Q Psi1 D12(P) - Psi2|^2_M2)
 *
 * (s1, s2 the areas, sums of m1, m2: the terms are dimensionless, so E
 * does not change when a mesh is scaled; at unit areas they are 1)
 * with C12 = Psi1^T M1 P0 Psi2 and C21 = Psi2^T M2 Q0 Psi1 the input maps'
 * functional maps (the data, k by k), and D21(Q) = Psi2^T M2 Q Psi1,
 * D12(P) = Psi1^T M1 P Psi2 the current maps' functional maps: Psi2 D21 is
 * Q Psi1 without its high frequencies, so the second line asks P Q and
 * Q P to be the identity on the first k functions (and D12 D21 ~ I).
 * Starting from plain denoising (ddm_denoise of each map), each of
 * `iterations` rounds solves P with Q fixed: the nearest point of M2
 * embedded by [sqrt(1-alpha) Psi2 | sqrt(alpha) Psi2 D21] to
 * [sqrt(1-alpha) Psi1 C12 | sqrt(alpha) Psi1] (ddm_nearest_points, exact
 * per row), then Q with the new P the same way. alpha = 0 is
 * ddm_denoise's pair of maps; each step minimises its own rows exactly,
 * but D12(P) also moves Q's term, so E is reported, not guaranteed to
 * fall (energy[r], r = 0..iterations: E after plain denoising and after
 * each round; may be NULL). k: the basis size on both meshes; m1, m2 the
 * lumped masses (required); T: M2, S: M1 (faces). P, Q:
 * bmap_new(n1, n2), bmap_new(n2, n1). Errors: DDM_EINVAL (k out of a
 * basis, alpha outside [0, 1), iterations < 0, maps of the wrong sizes or
 * with a face out of range, a missing mass), DDM_ENOMEM. */
/* alpha = 0.8: the value the thesis' chapter 3 ran "the consistency extension
 * of DND" with; test_ddm.c checks that it gives consistent maps on the BIM
 * maps of TOSCA gorilla_01 <-> man_01. */
#define DDM_BIJ_ALPHA_DEFAULT 0.8
#define DDM_BIJ_ITERATIONS_DEFAULT 3
int ddm_denoise_bijective(const lbo_basis *b1, const double *m1, const mesh *S,
                          const lbo_basis *b2, const double *m2, const mesh *T, const bmap *P0,
                          const bmap *Q0, int k, double alpha, int iterations, bmap *P, bmap *Q,
                          double *energy, char *err, size_t errsz);

#endif
