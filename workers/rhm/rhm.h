/* rhm.h — Reversible Harmonic Maps (Ezuz, Solomon, Ben-Chen 2019; thesis
 * chapter 3, §3.2–3.3): a pair of maps P12: M1 -> M2, P21: M2 -> M1 from a
 * handful of landmark pairs, used as ECTM's initial P and Q.
 *
 * Energy (3.11), summed over (i, j) = (1, 2) and (2, 1):
 *   α·Ē_D(X_ij) + (1−α)·Ē_R(P_ij, X_ji) + β·Ē_Q(P_ij, X_ij) [+ γ·Ē_L(X_ij)]
 *   Ē_D = (1/s_j) tr(X_ijᵀ W_i X_ij)              (harmonic energy)
 *   Ē_R = (1/s_i²) ‖P_ij X_ji − X_i‖²_{M_i}        (reversibility)
 *   Ē_Q = (1/(s_i s_j)) ‖X_ij − P_ij X_j‖²_{M_i}   (splitting)
 *   Ē_L = (1/(s_i s_j)) Σ_r M_i(a_r) ‖X_ij(a_r) − X_j(b_r)‖²   (weak
 *         landmarks (3.13), a_r on M_i and b_r on M_j; the 1/(s_i s_j) is
 *         ours, for the same scale invariance as Ē_Q)
 *   and from given maps only [+ δ·Ē_A(X_ij)], ours (rhm_run_from_maps):
 *   Ē_A = (1/(s_i s_j)) Σ_{a ∈ A_i} (n_i/|A_i|) M_i(a) ‖X_ij(a) − (P⁰_ij X_j)(a)‖²
 *         (anchors: weak landmarks whose partners are the given map's
 *         images, A_i a farthest-point sample of M_i's embedding)
 * X_i: nv_i by m embedding of M_i's geodesic distances (embed.h: SMACOF
 * of a farthest-point sample, biharmonic extension); W_i: cotan Laplacian (geo_cotan.h, xᵀWx = ∫|∇x|²); M_i: lumped
 * mass; s_i: total area. All in the meshes' own units (the energy is
 * scale-invariant as written).
 *
 * Start: the maps P12, P21 from which the iterations begin, X_ij = P_ij X_j.
 * From landmarks they come from the start module (start.h: distances,
 * Voronoi or functional-map maps, the kind p.start), through rhm_run_start,
 * which takes the start as a function; from given maps, rhm_run_from_maps.
 *
 * Iteration k = 1..K (Algorithm 3.1), β_k = beta_step·min(k, beta_ramp):
 * for i = 1, 2: P_ij <- projection, X_ij <- sparse linear solve. Each block
 * step minimises the energy over its block exactly, so at fixed β the
 * energy never increases. Stops after K iterations, or from iteration
 * min_iterations on when |E_k − E_{k−1}| < stop_change·E_{k−1}.
 *
 * Limitation seen on real shapes: a long thin part (a limb, a head on a
 * neck) whose cross-section the m-dimensional embedding squeezes can come
 * out turned about its axis (mirrored). The Voronoi start does this often; the
 * distances start keeps most parts the right way round, and landmarks on both
 * sides of such parts help either way.
 *
 * This module reads no files. rhm_run_start reports the initial map (iteration 0)
 * and every iteration through a callback whose non-zero return cancels. */
#ifndef RHM_H
#define RHM_H
#include <stddef.h>
#include "geod/geod.h"
#include "lmk/lmk.h"
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "util/kind.h"

typedef enum rhm_start {
    RHM_START_DISTANCES = 0,   /* projection on distances to the landmarks  */
    RHM_START_VORONOI = 1,     /* the thesis' geodesic Voronoi map          */
    RHM_START_FMAP = 2,        /* functional map (Δ + D_N) deblurred by DDM */
    RHM_START_AUTO = 3         /* the pipeline's rule (start.h, corr_rhm);
                                  a single run starts from distances       */
} rhm_start;
/* Their names are the values of start in PROTO_PARAMS (proto_params.h):
 * proto_param_value_name, proto_param_parse. */

/* start, alpha, gamma, dim and iterations are job parameters: their
 * defaults and ranges are PROTO_PARAMS' (protocol/proto_params.h, ENGINE
 * column RHM: start, rhm_alpha, rhm_landmark_weight, rhm_dim,
 * rhm_iterations). */
typedef struct rhm_params {
    int start;             /* RHM_START_*                                   */
    double alpha;          /* harmonic vs reversibility                     */
    double beta_step;      /* β_k = beta_step·min(k, beta_ramp)    (> 0)    */
    int beta_ramp;         /*                                      (>= 1)   */
    double gamma;          /* weak landmark weight; 0 = off                 */
    int dim;               /* embedding dimension m                         */
    int iterations;        /* at most K iterations                          */
    int min_iterations;    /* no early stop before this iteration  (>= 1)   */
    double stop_change;    /* relative energy change to stop; 0 = never     */
    int threads;           /* OpenMP threads; 0: all cores                  */
    int zoomout;           /* start fmap: ZoomOut's final basis size; 0 off
                              (start.h: from START_FMAP_K + 1)              */
    int coarse;            /* coarse to fine's vertices (corr.h); 0 off     */
    double anchor;         /* from given maps: weight δ of the anchor term
                              Ē_A (rhm_run_from_maps); 0: off       (>= 0)  */
    int anchors;           /* anchors per side; 0: every vertex     (>= 0)  */
} rhm_params;

/* The anchor term of RHM from given maps (rhm_run_from_maps), ours: δ =
 * RHM_ANCHOR_WEIGHT on RHM_ANCHORS vertices per side. Without it nothing holds
 * RHM to the map it starts from (the thesis' RHM takes a map only as its
 * start, §3.3.2, and its β ramp starts small so that a degenerate start can
 * change a lot), and from a good map it drifts. Sparse anchors leave the map
 * free to smooth between them; their weight n_i/|A_i| makes δ the weight of a
 * term over the whole mesh, a tenth of β's final value. docs/decisions.md,
 * "RHM from given maps: anchors", has the alternatives (every vertex anchored,
 * β without its ramp). */
#define RHM_ANCHOR_WEIGHT 0.05
#define RHM_ANCHORS 200

/* The authors' release: α = 5e-4, β = 5e-3·min(k, 100), γ = 0, m = 8,
 * K = 200, stop when the relative change is below 1e-9 after iteration 110;
 * start: auto (ours, see above); anchor RHM_ANCHOR_WEIGHT on RHM_ANCHORS
 * (given maps only). */
void rhm_params_init(rhm_params *p);
/* 0 or KIND_EPARAMS with the offending field named in err. */
int rhm_params_check(const rhm_params *p, char *err, size_t errsz);
double rhm_beta(const rhm_params *p, int k);

/* One direction's weighted terms: dir[0] is (i, j) = (1, 2), dir[1] (2, 1). */
typedef struct rhm_terms {
    double dirichlet;      /* α·Ē_D(X_ij)                                    */
    double reverse;        /* (1−α)·Ē_R(P_ij, X_ji)                          */
    double mismatch;       /* β·Ē_Q(P_ij, X_ij)                              */
    double landmark;       /* γ·Ē_L(X_ij)                                    */
} rhm_terms;

typedef struct rhm_report {
    int iteration, total;  /* 0 = the start map; total = K                  */
    double beta;
    rhm_terms dir[2];
    double energy;         /* sum of the eight terms                        */
    double elapsed;        /* seconds since the run started                 */
    double t_setup;        /* seconds in geodesics, embeddings, operators   */
    double t_project, t_solve; /* cumulated seconds in P-steps, X-steps     */
} rhm_report;

typedef int (*rhm_progress_fn)(void *ctx, const rhm_report *r);

typedef struct rhm_result {
    bmap *P12;             /* M1 -> M2 (ECTM's P0)                          */
    bmap *P21;             /* M2 -> M1 (ECTM's Q0)                          */
    rhm_report last;
    int start;             /* the start the maps came from (start_run: auto
                              is distances; corr_rhm: the one kept); -1
                              from given maps and from rhm_run_start       */
} rhm_result;
void rhm_result_close(rhm_result *r);

/* What a start from landmarks sees of side i (0: S = M1, 1: T = M2) and
 * fills: P, the map from side i to the other side, allocated by RHM (n
 * rows onto the other side's faces, to be set row by row). The rest is
 * RHM's set-up, borrowed for the start's duration. */
typedef struct rhm_side {
    const mesh *m;         /* the side's mesh                               */
    int n;                 /* its vertices                                  */
    double area;           /* its total area                                */
    const double *X;       /* n by dim: its embedding (row-major)           */
    int dim;               /* the embedding's dimension m                   */
    geod_solver *geod;     /* its heat-method solver (Laplacian and mass)   */
    int *lmk;              /* nl landmark vertices on this side (read only) */
    int nl;                /* landmark pairs                                */
    bmap *P;               /* to fill: side i -> side 1 − i                 */
} rhm_side;

/* Fills side[0].P (P12) and side[1].P (P21) for the parameters p; KIND_OK
 * or an RHM_* error with its detail in err. */
typedef int (*rhm_start_fn)(const rhm_params *p, rhm_side side[2], char *err, size_t errsz);

/* Runs RHM from the landmark pairs L (L->src on S = M1, L->tgt on T = M2,
 * at least PROTO_MIN_LANDMARKS): the set-up, the start maps by start (the
 * start module's start_maps from p->start: start_run), X_ij = P_ij X_j,
 * then the iterations. The meshes must be validated (manifold,
 * connected, no degenerate face). Errors: KIND_EPARAMS, KIND_ELANDMARKS,
 * KIND_EMESH, KIND_ENOMEM, KIND_ECANCELLED, KIND_ENUMERIC, or start's; detail
 * in err. out->start is -1 (start_run sets it). */
int rhm_run_start(const mesh *S, const mesh *T, const lmk_set *L, const rhm_params *p,
                  rhm_start_fn start, rhm_progress_fn progress, void *ctx, rhm_result *out,
                  char *err, size_t errsz);

/* RHM from given maps instead of a start from landmarks (thesis §3.3.2
 * lists a given map as an RHM input): P12 (S -> T, required) and P21
 * (T -> S, or NULL: then each vertex v of T goes to the source vertex u
 * whose image P12(u), in T's embedding, is nearest to v's, as the Voronoi
 * start's reverse does; brute force, O(n1 n2 m)); X_ij = P_ij X_j, then
 * the anchors (p->anchor, p->anchors: a farthest-point sample of each
 * side's embedding, the first at vertex 0, each held by the anchor term to
 * its start X_ij = P_ij X_j), then
 * the iterations of rhm_run_start. L may be NULL or hold any number of pairs:
 * landmarks serve only the weak landmark term, so p->gamma > 0 needs at
 * least one. p->start is unused. The maps are copied, not kept. Errors as
 * rhm_run_start; KIND_EMAP for maps sized for other meshes or with a face
 * out of range. */
int rhm_run_from_maps(const mesh *S, const mesh *T, const lmk_set *L, const bmap *P12,
                      const bmap *P21, const rhm_params *p, rhm_progress_fn progress, void *ctx,
                      rhm_result *out, char *err, size_t errsz);

#endif
