/* rhm__problem.h — internal (rhm__): the state of one RHM job and its block
 * steps, shared by rhm_problem.c (set-up), rhm_given.c (start from given
 * maps), rhm_step.c (P-step, X-step, energy) and rhm_run.c (the start from
 * landmarks through an rhm_start_fn, the loop); the tests drive the steps one
 * by one. Not part of the public rhm_ API.
 *
 * Index convention: side i = 0 is M1 (the source), 1 is M2; direction i is
 * the map from side i to side j = 1 − i (P[0] = P12, P[1] = P21). */
#ifndef RHM__PROBLEM_H
#define RHM__PROBLEM_H
#include "rhm/rhm.h"
#include "chol/chol.h"
#include "geo/geo_csr.h"
#include "geod/geod.h"
#include "proj/proj.h"

typedef struct rhm__side {
    const mesh *m;          /* borrowed */
    int n;                  /* vertices */
    double s;               /* total area */
    double *mass;           /* n: lumped mass */
    geo_csr *W;             /* n by n cotan Laplacian */
    double *X;              /* n by dim: the embedding */
    geod_solver *geod;      /* heat-method solver of this side */
    proj_tree *tree;        /* BVH over this side's faces with positions X[:, 0:3] */
    int *lmk;               /* nl landmark vertices on this side */
    /* direction from this side (i) to the other (j): */
    bmap *P;                /* n rows onto the other side's faces */
    double *Xij;            /* n by dim: the split variable X_ij */
    double *anchor;         /* n by dim: the given map's image P⁰_ij X_j, or NULL */
    double *anchor_w;       /* n: the anchor term's weight per vertex: n/k at
                               the k anchors, 0 elsewhere (1 everywhere: k = 0) */
    chol *A;                /* the X-step matrix, W's pattern: analysed once,
                               its values written and factorised per X-step */
} rhm__side;

typedef struct rhm__problem {
    rhm_params p;
    int dim, nl;
    rhm__side side[2];
} rhm__problem;

/* Builds geodesic solvers, embeddings, operators, trees and the X-step
 * symbolic factorisations; the maps are left NULL (rhm__start sets
 * them). Errors as rhm_run. */
int rhm__problem_new(const mesh *S, const mesh *T, const lmk_set *L, const rhm_params *p,
                     rhm__problem **out, char *err, size_t errsz);
/* The same for a start from given maps (rhm_given.c): landmarks optional
 * (L NULL or any number; they serve the weak landmark term only). */
int rhm__problem_new_maps(const mesh *S, const mesh *T, const lmk_set *L, const rhm_params *p,
                          rhm__problem **out, char *err, size_t errsz);
void rhm__problem_free(rhm__problem *pb);

/* The anchors of side sd from its current X_ij (rhm_given.c): anchor =
 * X_ij, weight n/k at k farthest points of the embedding X (Euclidean in
 * R^m, the first at vertex 0, ties to the lower vertex), or 1 at every
 * vertex when k is 0 or at least n. KIND_OK or KIND_ENOMEM. */
int rhm__anchors_set(rhm__problem *pb, rhm__side *sd, int k);

/* The loop (rhm_run.c) from the current state, maps and X_ij set: reports
 * iteration 0, iterates, moves the maps into out. t0: rhm__now() at the
 * start of the run. */
int rhm__iterate(rhm__problem *pb, double t0, rhm_progress_fn progress, void *ctx,
                 rhm_result *out, char *err, size_t errsz);
double rhm__now(void);   /* monotonic seconds */

/* The start from landmarks (rhm.h, rhm_run_start): allocates P12, P21,
 * fills them by start through the sides' rhm_side view, sets X_ij =
 * P_ij X_j. */
int rhm__start(rhm__problem *pb, rhm_start_fn start, char *err, size_t errsz);

/* P_ij <- argmin over maps of (1−α)Ē_R(P, X_ji) + βĒ_Q(P, X_ij), row by row
 * (closest point in R^{2m}, exact, seeded with the current P_ij). why: the
 * projection tree's reason when it cannot be built. */
int rhm__step_p(rhm__problem *pb, int i, double beta, char *why, size_t whysz);
/* X_ij <- argmin over R^{n_i × m} of αĒ_D + (1−α)Ē_R(P_ji, ·) + βĒ_Q(P_ij, ·)
 * + γĒ_L [+ δĒ_A when the side has anchors]: the sparse SPD system
 * (CHOLMOD, numeric factorisation only). */
int rhm__step_x(rhm__problem *pb, int i, double beta);
/* The weighted terms of (3.11) at the current state; returns their sum.
 * The anchor term δĒ_A is counted in landmark (the weak correspondences). */
double rhm__energy(const rhm__problem *pb, double beta, rhm_terms dir[2]);

/* The projection of direction i as rhm__step_p sets it up: Z (n_j by 2m),
 * the queries Q (n_i by 2m) and the lower-bound scale s. Z and Q are
 * caller-allocated. Returns 0 when the first block is √(β/(s_i s_j))·X_j
 * (the side's fixed tree applies), 1 when it is the reversibility block
 * √(1−α)/s_i·X_ji (then first Z columns / s are the tree's positions). */
int rhm__projection_setup(const rhm__problem *pb, int i, double beta,
                          double *Z, double *Q, double *s);

#endif
