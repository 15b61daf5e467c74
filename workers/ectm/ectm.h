/* ectm.h — Elastic Correspondence between Triangle Meshes (Ezuz et al. 2019):
 * the alternating optimisation of ../shared/DESIGN.md.
 *
 * Source S (X, n vertices) and target S̃ (X̃, ñ vertices). Bijective model:
 *   E_bij = W_def(X,Y) + β‖PX̃ − Y‖²_X + W_def(X̃,Ỹ) + β‖QX − Ỹ‖²_X̃
 *         + γ‖PỸ − X‖²_X + γ‖QY − X̃‖²_X̃
 * Locally injective model: E_inj = W_def(X,Y) + β‖PX̃ − Y‖²_X (no Q, Ỹ).
 * Each outer iteration k = 1..K: β_k from the schedule, then
 *   P ← projection, Y ← L-BFGS, (bijective:) Q ← projection, Ỹ ← L-BFGS.
 * With stop_change the run ends before K once the energy has settled: it
 * fell by less than that share over the last ECTM_STOP_WINDOW iterations
 * at one β. Near-isometric pairs keep moving long after β stops growing,
 * and stop later than the rest.
 * Each side's L-BFGS correction pairs are kept from one outer iteration to
 * the next (corrected for the change of β), and a Y-step ends at
 * inner_iterations or at the first iteration that gains less than 5 % of
 * what the step has gained (ectm.c, ECTM_INNER_REL_DECREASE).
 * Both meshes are scaled to unit area first (not with `partial`, which
 * instead divides α by the source area s and β by s·s̃) and the outputs are
 * returned in the input frames.
 *
 * This module knows nothing about files, sockets or processes: it takes
 * meshes and maps, reports each outer iteration through a callback (whose
 * non-zero return cancels the run) and returns maps. */
#ifndef ECTM_H
#define ECTM_H
#include <stddef.h>
#include "mesh/mesh.h"
#include "map/bmap.h"
#include "util/kind.h"

/* Outer iterations over which stop_change compares the energy. */
#define ECTM_STOP_WINDOW 100

typedef enum ectm_model { ECTM_BIJECTIVE = 0, ECTM_INJECTIVE = 1 } ectm_model;

/* The fields that are job parameters take their defaults and ranges from
 * the one list, PROTO_PARAMS (protocol/proto_params.h, ENGINE column ECTM). */
typedef struct ectm_params {
    ectm_model model;
    double alpha;          /* membrane weight                                */
    double eta;            /* bending weight                                 */
    double beta0, beta1;   /* β at k = 1 and at k >= beta_ramp               */
    int beta_ramp;         /* iterations of the linear ramp                  */
    double gamma;          /* reversibility weight, bijective only           */
    int iterations;        /* outer iterations K at most                     */
    int inner_iterations;  /* L-BFGS iterations per Y-step at most          */
    double tolerance;      /* L-BFGS gradient tolerance                      */
    double stop_change;    /* stop once the energy fell by less than this
                              share of it over the last ECTM_STOP_WINDOW
                              outer iterations at one β; 0: run K            */
    double log_eps;        /* −log extension threshold on det G       (> 0)  */
    int partial;           /* partial matching: no rescaling          (0/1)  */
    int scale_reference;   /* the membrane's reference metric takes the
                              initial maps' regional area scale
                              (ectm_area_scale; not with partial)    (0/1)  */
    int threads;           /* OpenMP threads; 0: all cores                   */
    char backend[16];      /* W_def engine: "cpu" (default; "" too), "opencl",
                              "auto" (ener_backend.h)                        */
    char device[128];      /* OpenCL platform or device name substring; "" any */
} ectm_params;

/* The authors' released code's values, which produced their published demo
 * result (../shared/data/ectm_demo_381_390/README.md): α = 20,
 * η = 6.667e-4, β = 500·min(k, 200), γ = 1e4, 50 L-BFGS iterations,
 * tolerance 1e-8, ε = 1e-20, bijective; in place of their fixed count of
 * outer iterations, the stop rule (stop_change) under a cap (iterations). */
void ectm_params_init(ectm_params *p);
/* The values the paper's text gives: α = 20, η = 1e-3, β 1e3 → 2e5 over
 * 200 iterations, γ = 2e4 (twice the released code's β and γ). */
void ectm_params_paper(ectm_params *p);
/* 0 or KIND_EPARAMS with the offending field named in err (the job
 * parameters by proto_param_check: "alpha = 0: out of range (0, inf)"). */
int ectm_params_check(const ectm_params *p, char *err, size_t errsz);
/* β at outer iteration k (1-based). */
double ectm_beta(const ectm_params *p, int k);
/* Whether the stop rule looks at outer iteration k: stop_change is on and
 * the last ECTM_STOP_WINDOW iterations ran at one β. */
int ectm_stop_may_end(const ectm_params *p, int k);
/* The first outer iteration at which the stop rule may end a run, or the
 * cap (iterations) when it cannot end one sooner. */
int ectm_first_stop(const ectm_params *p);

/* One direction's terms: 0 = source (P, Y), 1 = target (Q, Ỹ). */
typedef struct ectm_terms {
    double w_mem, w_bnd;   /* unweighted membrane and bending energies      */
    double mismatch;       /* β‖PX̃ − Y‖²_X  (resp. β‖QX − Ỹ‖²_X̃)           */
    double reverse;        /* γ‖QY − X̃‖²_X̃ (resp. γ‖PỸ − X‖²_X), the γ term
                              that depends on this direction's deformation  */
    double energy;         /* α·w_mem + η·w_bnd + mismatch + reverse        */
    int inner_iterations;  /* L-BFGS iterations of this direction's Y-step  */
    int evaluations;       /* energy + gradient evaluations of that Y-step  */
    int admissible_edges;
} ectm_terms;

typedef struct ectm_report {
    int outer, total;      /* this outer iteration (1-based) and K          */
    double beta, gamma;
    ectm_terms dir[2];     /* dir[1] is zero for the injective model        */
    double energy;         /* E_bij (or E_inj) after this iteration         */
    double elapsed;        /* seconds since the start of ectm_run           */
    double t_project, t_solve; /* cumulated seconds in P/Q-steps, Y-steps   */
} ectm_report;

/* Return non-zero to cancel the run. */
typedef int (*ectm_progress_fn)(void *ctx, const ectm_report *r);

typedef struct ectm_result {
    bmap *P;       /* source -> target                                   */
    bmap *Q;       /* target -> source (bijective; NULL for injective)   */
    double *Y;     /* n by 3: the deformed source, in the target's frame */
    double *Yt;    /* ñ by 3: the deformed target, in the source's frame (bijective) */
    ectm_report last;
    bmap *rhm_P;   /* the pipeline's (corr_run) RHM maps that ECTM started */
    bmap *rhm_Q;   /* from, for a chain RHM then ECTM; NULL from ectm_run  */
    int scaled;    /* 1 when the membrane's reference took the initial
                      maps' regional scale (ectm_params.scale_reference) */
} ectm_result;
void ectm_result_close(ectm_result *r);

/* Landmark pairs (source vertex src[k] <-> target vertex tgt[k], 0-based,
 * k < n) that the P- and Q-steps pin: after each projection, the row of
 * src[k] in P is set to the target vertex tgt[k] itself (a face of the
 * target at that vertex, weights 1 at its corner, 0 at the others) and,
 * bijective, the row of tgt[k] in Q to src[k]. A target vertex given twice
 * pins Q to the first pair's source vertex. The caller keeps the arrays. */
typedef struct ectm_landmarks {
    const int *src;   /* n source vertices, each in [0, S->nv), no repeat */
    const int *tgt;   /* n target vertices, each in [0, T->nv)           */
    int n;            /* number of pairs, >= 0                            */
} ectm_landmarks;

/* Runs the optimisation. P0 is required; Q0 may be NULL (bijective: then it
 * is built by nearest neighbour — each target vertex goes to the closest
 * point of the source's image P0·X̃). L: the landmarks to pin, or NULL (as
 * L->n = 0: none); a bad one is refused with KIND_EPARAMS before anything
 * runs, the pair and field named in err ("landmarks.src[3] = 9999 out of
 * range [0, 6938)"). The meshes must be manifold with no degenerate faces
 * (validate with mesh_check first). */
int ectm_run(const mesh *S, const mesh *T, const bmap *P0, const bmap *Q0,
             const ectm_landmarks *L, const ectm_params *p, ectm_progress_fn progress,
             void *ctx, ectm_result *out, char *err, size_t errsz);

/* Per face of X, the regional area factor the map P (X onto Y) gives it
 * (ectm_scale.c): exp of the face's log image-area ratio (both meshes at
 * unit area), smoothed over its region and centred so that X's total area
 * stays. A malloc'ed array of X->nf, NULL when out of memory. */
double *ectm_area_scale(const mesh *X, const mesh *Y, const bmap *P);

#endif
