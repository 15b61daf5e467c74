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
 * Start from the landmarks (p_r on M1, q_r on M2, r = 1..nl), three kinds
 * and a rule among them:
 *  - distances: every vertex described by its geodesic
 *    distances to the landmarks of its side, divided by √(area); P12 row v
 *    = the closest point to v's description on M2 with M2's descriptions as
 *    vertex coordinates (an exact projection in R^nl, proj.h), P21 the same
 *    the other way; X_ij = P_ij X_j. Not the thesis' start: it is ours,
 *    because the Voronoi start below collapses every cell to a point and a
 *    limb's turn about its axis is then left to chance (docs/decisions.md,
 *    "RHM's start: distances, then the functional map").
 *  - voronoi (§3.3.2): P12 sends every vertex of a geodesic Voronoi cell of
 *    M1 (centres: source landmarks) to the cell's target landmark; P21
 *    sends every vertex v of M2 to the source landmark whose target
 *    landmark is nearest to v in M2's embedding (the nearest neighbour of v
 *    among the images T12(V1), which are exactly the target landmarks; ties
 *    to the lower landmark index); X_ij = P_ij X_j.
 *  - fmap: a functional map from the landmarks' descriptors (Δ + D_N
 *    commutativity, fmap.h), made precise by DDM's deblurring.
 *  - auto (the default): a rule of the pipeline, which repairs RHM's
 *    maps (corr_rhm, corr.h); rhm_run runs the distances start for it.
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
 * This module reads no files. rhm_run reports the initial map (iteration 0)
 * and every iteration through a callback whose non-zero return cancels. */
#ifndef RHM_H
#define RHM_H
#include <stddef.h>
#include "lmk/lmk.h"
#include "map/bmap.h"
#include "mesh/mesh.h"

#define RHM_ERRORS(X)                                                           \
    X(RHM_OK,         0, "ok", NONE)                                          \
    X(RHM_EPARAM,    -1, "invalid parameter", PARAMS)                         \
    X(RHM_EMESH,     -2, "mesh not usable (geodesics or embedding failed)", MESH) \
    X(RHM_ELANDMARKS, -3, "landmarks do not fit the meshes", LANDMARKS)       \
    X(RHM_ENOMEM,    -4, "out of memory", NOMEM)                              \
    X(RHM_ECANCELED, -5, "cancelled", CANCELLED)                              \
    X(RHM_ENUMERIC,  -6, "numerical failure (factorisation or projection)", NUMERIC) \
    X(RHM_EMAP,      -7, "a given map does not fit the meshes", MAP)

enum rhm_error {
#define RHM_ENUM(name, val, msg, kind) name = val,
    RHM_ERRORS(RHM_ENUM)
#undef RHM_ENUM
};

/* Basis size of the functional-map start (the k of fmap's tests and
 * figures), capped by what a small mesh has; ZoomOut (rhm_params.zoomout)
 * grows it from there. */
#define RHM_FMAP_K 50

typedef enum rhm_start {
    RHM_START_DISTANCES = 0,   /* projection on distances to the landmarks  */
    RHM_START_VORONOI = 1,     /* the thesis' geodesic Voronoi map          */
    RHM_START_FMAP = 2,        /* functional map (Δ + D_N) deblurred by DDM */
    RHM_START_AUTO = 3         /* the pipeline's rule (corr_rhm); rhm_run
                                  runs distances for it                    */
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
    int zoomout;           /* start fmap: ZoomOut's final basis size; 0 off */
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
/* 0 or RHM_EPARAM with the offending field named in err (zoomout from 1 to
 * RHM_FMAP_K: ZoomOut only grows the start's basis). */
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
    double elapsed;        /* seconds since rhm_run started                 */
    double t_setup;        /* seconds in geodesics, embeddings, operators   */
    double t_project, t_solve; /* cumulated seconds in P-steps, X-steps     */
} rhm_report;

typedef int (*rhm_progress_fn)(void *ctx, const rhm_report *r);

typedef struct rhm_result {
    bmap *P12;             /* M1 -> M2 (ECTM's P0)                          */
    bmap *P21;             /* M2 -> M1 (ECTM's Q0)                          */
    rhm_report last;
    int start;             /* the start the maps came from (rhm_run: auto
                              is distances; corr_rhm: the one kept); -1
                              from given maps                             */
} rhm_result;
void rhm_result_close(rhm_result *r);

/* Runs RHM from the landmark pairs L (L->src on S = M1, L->tgt on T = M2,
 * at least PROTO_MIN_LANDMARKS), from p->start (auto: distances). The
 * meshes must be validated (manifold,
 * connected, no degenerate face). Errors: RHM_EPARAM, RHM_ELANDMARKS,
 * RHM_EMESH, RHM_ENOMEM, RHM_ECANCELED, RHM_ENUMERIC; detail in err. */
int rhm_run(const mesh *S, const mesh *T, const lmk_set *L, const rhm_params *p,
            rhm_progress_fn progress, void *ctx, rhm_result *out,
            char *err, size_t errsz);

/* RHM from given maps instead of a start from landmarks (thesis §3.3.2
 * lists a given map as an RHM input): P12 (S -> T, required) and P21
 * (T -> S, or NULL: then each vertex v of T goes to the source vertex u
 * whose image P12(u), in T's embedding, is nearest to v's, as the Voronoi
 * start's reverse does; brute force, O(n1 n2 m)); X_ij = P_ij X_j, then
 * the anchors (p->anchor, p->anchors: a farthest-point sample of each
 * side's embedding, the first at vertex 0, each held by the anchor term to
 * its start X_ij = P_ij X_j), then
 * the iterations of rhm_run. L may be NULL or hold any number of pairs:
 * landmarks serve only the weak landmark term, so p->gamma > 0 needs at
 * least one. p->start is unused. The maps are copied, not kept. Errors as
 * rhm_run; RHM_EMAP for maps sized for other meshes or with a face
 * out of range. */
int rhm_run_from_maps(const mesh *S, const mesh *T, const lmk_set *L, const bmap *P12,
                      const bmap *P21, const rhm_params *p, rhm_progress_fn progress, void *ctx,
                      rhm_result *out, char *err, size_t errsz);

#endif
