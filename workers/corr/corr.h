/* corr.h — one correspondence job from inputs to maps: the pipeline that
 * `meshcorr match` runs in-process and `meshcorr-worker` runs for the daemon.
 *
 *   validate both meshes (manifold, one component, finite, no degenerate face)
 *   then the chosen stages, always in this order (corr_chain):
 *   DDM denoising of the uploaded P (and Q): the map's functional map
 *     C = Psi1^T M1 P Psi2, deblurred to a precise map (ddm.h, thesis §2.5)
 *   RHM: from landmarks (a start map, start.h) or from the uploaded or
 *     denoised maps (rhm_run_from_maps, anchored to them: rhm.h's
 *     RHM_ANCHORS), giving P and Q, whose folds are
 *     then repaired (corr_repair, fold.h)
 *   ECTM refinement, then the same fold repair of the maps it returns
 *     (the rows of bad regions change; out->Y stays ECTM's deformation):
 *     from landmarks always; on a given map's chain only after RHM, each
 *     map that is folded (metric_verdict), not when ECTM starts
 *     from the given or denoised map (docs/decisions.md, "Fold repair after
 *     ECTM")
 *
 * Stages report progress through one callback; a non-zero return cancels.
 * This module reads no files and knows no sockets: callers load meshes,
 * landmarks and maps, and write the result. */
#ifndef CORR_H
#define CORR_H
#include <stddef.h>
#include "ectm/ectm.h"
#include "fold/fold.h"
#include "lmk/lmk.h"
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "repair/repair.h"
#include "rhm/rhm.h"
#include "proto.h"

/* The pipeline returns the engine's codes by kind (util/kind.h). */
/* The wire code of a pipeline code (0 for KIND_OK): what the worker's
 * error.frame carries. */
int corr_wire_code(int code);
/* An engine module's code as the pipeline's, by the kind column of the
 * module's error list (corr_kind.c); an unknown code is KIND_EINTERNAL. */
int corr_from_fold(int rc);
int corr_from_ddm(int rc);
int corr_from_ctf(int rc);
int corr_from_geod(int rc);
int corr_from_lbo(int rc);
int corr_from_lmk(int rc);
int corr_from_bmap(int rc);
int corr_from_mesh(int rc);
int corr_from_repair(int rc);

/* A progress report's stage: the wire's list (PROTO_STAGES), so a report
 * goes out as it is. START: the start map is built (its RHM energies); RHM:
 * one report per RHM iteration; ECTM: one per ECTM outer iteration; DDM: at
 * DDM's start and per direction; REPAIR: the fold repair of a stage's maps,
 * at its start and end. INIT and QUEUED are never reported by the engine;
 * proto_stage_name() names them all. */
typedef enum corr_stage {
#define CORR_STAGE_ENUM(name, val) CORR_STAGE_##name = PROTO_STAGE_##name,
    PROTO_STAGES(CORR_STAGE_ENUM)
#undef CORR_STAGE_ENUM
} corr_stage;

/* Which stages run, the values of the job parameter stages (PROTO_PARAMS,
 * the names "ddm,ectm" etc.: proto_param_value_name). A chain always runs
 * in the order DDM, RHM, ECTM: DDM cleans a given map, RHM needs a start,
 * ECTM only refines (it cannot undo a mirrored or folded start), so it
 * comes last. all: landmarks -> start -> RHM -> ECTM, or ECTM alone on an
 * uploaded map (the meaning from before chains); rhm alone: RHM's maps are
 * the result; ectm alone: ECTM on an uploaded map. */
typedef enum corr_chain {
#define CORR_CHAIN_ENUM(name, val) CORR_CHAIN_##name = PROTO_CHAIN_##name,
    PROTO_CHAINS(CORR_CHAIN_ENUM)
#undef CORR_CHAIN_ENUM
} corr_chain;
#define CORR_RUN_DDM  1u
#define CORR_RUN_RHM  2u
#define CORR_RUN_ECTM 4u
/* The CORR_RUN_* bits of s for a job with (have_map) or without an
 * uploaded map; 0 for a value outside the list. */
unsigned corr_chain_run(corr_chain s, int have_map);
/* How the DDM stage denoises (job parameter ddm_mode): each given map on
 * its own (ddm_denoise), or P and its reverse Q together, made consistent
 * (ddm_denoise_bijective, DDM_BIJ_ALPHA_DEFAULT, DDM_BIJ_ITERATIONS_DEFAULT),
 * or auto: bijective when a reverse map is given and the two given maps
 * agree (the larger of their round trips S->T->S and T->S->T, RMS over the
 * unit-area mesh, metric_round_trip, at most CORR_DDM_AUTO_ROUND_TRIP),
 * else plain. Where the two disagree wholesale (one of them a symmetric
 * flip), making them consistent drags the good one toward the bad one. */
typedef enum corr_ddm_mode {
    CORR_DDM_PLAIN = 0, CORR_DDM_BIJECTIVE = 1, CORR_DDM_AUTO = 2
} corr_ddm_mode;
/* auto's bound on the given pair's round trip, the larger of a pair's two:
 * below it bijective denoising is used, above it the maps disagree too much
 * for it to help. 0.1 is a tenth of the shape's size: a point that comes back
 * farther has come back to another part (docs/decisions.md, "Bijective
 * denoising and its round-trip bound"). */
#define CORR_DDM_AUTO_ROUND_TRIP 0.1

/* Whether the chain can run on these inputs: 0, or an error with the
 * reason in err: KIND_EPARAMS (ddm without a map, ECTM alone without one,
 * a reverse map with the injective model, a weak landmark term without
 * landmarks, bijective DDM without a reverse map, a stages or ddm_mode
 * value outside the list; auto without a reverse map runs plain),
 * KIND_ELANDMARKS (RHM from neither a map nor at least
 * PROTO_MIN_LANDMARKS landmarks), KIND_EMAP (a reverse map without a
 * map). The worker's
 * SUBMIT check and corr_run use it. */
int corr_chain_check(corr_chain s, int have_map, int have_reverse, int nlandmarks,
                      int injective, double rhm_landmark_weight, corr_ddm_mode ddm_mode,
                      char *err, size_t errsz);
/* A --stages text as the CLI reads it: a value of the list (*out), or -1
 * with why not in err: an unknown stage, a stage named twice, or a chain
 * out of the order ddm, rhm, ectm ("ectm before ddm: ..."). */
int corr_chain_parse(const char *text, corr_chain *out, char *err, size_t errsz);

/* The DDM stage's basis size when ddm_k is 0: min(CORR_DDM_K, vertices - 2).
 * Fewer functions smooth more and cost error (tests/unit/test_ddm.c);
 * docs/decisions.md, "Bijective denoising and its round-trip bound", says how
 * the value was chosen. */
#define CORR_DDM_K 100

/* A DDM stage report: directions done of total (1: P only, 2: P and Q),
 * the basis size, and each done direction's deblurring objective
 * sum_i M1_ii |(Psi1 C)_i - P_i Psi2|^2 (ddm_stats.cost). */
typedef struct corr_ddm_report {
    int done, total, k;
    double cost[2];
    corr_ddm_mode mode;   /* the mode that runs: plain or bijective         */
    double round_trip;    /* auto with a reverse map: the pair's round trip
                           * it chose by; NAN otherwise                     */
} corr_ddm_report;

typedef struct corr_input {
    const mesh *S, *T;        /* source and target (required)               */
    const char *S_name, *T_name; /* for messages (file names or labels)     */
    const lmk_set *L;         /* landmark pairs, or NULL                     */
    const bmap *P0, *Q0;      /* uploaded initial maps, or NULL              */
    const rhm_params *rhm;    /* RHM parameters, NULL: rhm_params_init's     */
    corr_chain stages;
    int ddm_k;                /* DDM basis size; 0: min(CORR_DDM_K, nv - 2)  */
    corr_ddm_mode ddm_mode;   /* plain, or bijective (needs Q0)              */
} corr_input;

/* A REPAIR stage report: maps repaired (0 at the start) of total (1: P
 * only, 2: P and Q). */
typedef struct corr_repair_report {
    int done, total;
} corr_repair_report;

typedef struct corr_progress {
    corr_stage stage;
    const ectm_report *ectm;  /* the outer iteration's report (stage ECTM)  */
    double elapsed;           /* seconds since corr_run started             */
    const rhm_report *rhm;    /* the RHM report (stages START and RHM)      */
    const corr_ddm_report *ddm; /* the DDM report (stage DDM)               */
    const corr_repair_report *repair; /* the repair's report (stage REPAIR) */
    double fraction;          /* of the whole job done, 0..1, never falling:
                                 each stage weighted by its expected cost
                                 (corr__plan.h)                             */
    double eta_s;             /* seconds left, from the time the done
                                 fraction took; NaN while not known         */
} corr_progress;

typedef int (*corr_progress_fn)(void *ctx, const corr_progress *p);

/* p as the wire's progress record (PROTOCOL.md, PROGRESS): stage, counts,
 * the five terms of each direction in their slots, beta, gamma, the
 * fraction, the time left and elapsed (p->elapsed); job_id and ahead 0.
 * The worker sends it, `meshcorr match` prints it. */
void corr_progress_record(const corr_progress *p, proto_progress *out);

/* 0 when the optimizer can use m; else KIND_EMESH with one line per problem
 * ("name: ...") in err. */
int corr_validate(const mesh *m, const char *name, char *err, size_t errsz);

/* Input repair (repair.h), the one check of a job's meshes before it runs:
 * a mesh the optimizer can use as given is used as it is; one it cannot
 * is repaired when repair is non-zero (the job parameter repair, yes by
 * default), else refused with corr_validate's message. When either mesh is
 * repaired, both go through repair_mesh_run (a usable one comes out the
 * same), the landmarks and uploaded maps are carried into the repaired
 * indexing (repair_landmarks, repair_map_from_user) and the results back
 * (corr_fix_to_user). Pieces: without a given map, when the landmarks pair
 * pieces of the two meshes (repair_pieces_pair: at least
 * PROTO_MIN_LANDMARKS on a piece, all landing on one piece of the other
 * mesh), those pieces are kept and corr_run matches each pair on its own;
 * else the largest piece of each is kept. */
typedef struct corr_fix {
    int repaired;            /* 1 when either mesh was repaired             */
    repair_mesh S, T;        /* when repaired: both meshes' repairs          */
    lmk_set L;               /* the landmarks in the repaired indexing       */
    bmap *P0, *Q0;           /* the uploaded maps in the repaired indexing   */
} corr_fix;

/* Checks and, with repair, repairs user's meshes; *in is the job's input
 * as the engine runs it (user's own fields where nothing was repaired).
 * KIND_OK; KIND_EMESH (not usable, repair off; or beyond repair: a bad
 * index, a NaN), KIND_EMAP (an uploaded map on a removed face),
 * KIND_ENOMEM. On error fx holds nothing. */
int corr_fix_open(const corr_input *user, int repair, corr_fix *fx, corr_input *in, char *err,
                  size_t errsz);
/* The engine's result (on the repaired meshes) in the user's indexing:
 * P and Q with one row per user vertex on the user's faces, Y and Yt one
 * row per user vertex; last copied. KIND_ENOMEM. */
int corr_fix_to_user(const corr_fix *fx, const ectm_result *res, ectm_result *out, char *err,
                     size_t errsz);
void corr_fix_close(corr_fix *fx);

/* The sizes a job's meshes bound: DDM's basis (in->ddm_k, when the chain
 * runs DDM) and ZoomOut's (in->rhm->zoomout, when RHM may start from the
 * functional map: start fmap, or auto's second run) hold at most
 * vertices - 2 eigenfunctions of either mesh.
 * KIND_OK, or KIND_EPARAMS with the parameter and both meshes named.
 * corr_run checks it first; the check of a job where it is built (the
 * daemon's of a SUBMIT) calls it too, so such a job is refused before it
 * is queued. */
int corr_check_sizes(const corr_input *in, char *err, size_t errsz);

/* RHM from the landmarks as the pipeline runs it: start_run from rp, then
 * the fold repair of its maps (corr_repair, rep). Start auto (the
 * default): from the distances start, and when the repaired maps are still
 * folded (metric_verdict: over 5 % of either map's triangles flipped or
 * collapsed), RHM and the repair again from the functional-map start, the
 * maps with the fewer bad triangles kept (out->start says which).
 * Landmarks alone can leave the distances start mirrored on a part of a shape,
 * and a wrong map folds, where the functional-map start may not
 * (docs/decisions.md, "RHM's start: distances, then the functional map"). A
 * failure of the second run
 * leaves the first maps; a cancel cancels. raw (may be NULL): a copy of
 * the kept forward map before its repair (for benchmarks). progress:
 * start_run's, the second run's reports from iteration 0 again. */
int corr_rhm(const corr_input *in, const rhm_params *rp, rhm_progress_fn progress, void *ctx,
             rhm_result *out, bmap **raw, fold_report rep[2], char *err, size_t errsz);

/* The fold repair (corr_finish.c): fold_repair of P (S -> T) when it is
 * not NULL and of Q (T -> S) when it is not NULL, the landmarks fixed
 * (in->L may be NULL), with fold_params_init's values; with relax, then
 * fold_relax of each. rep[0], rep[1]: P's and Q's reports (bad_after and
 * relaxed: after fold_relax when it ran). KIND_OK, or KIND_ENOMEM,
 * KIND_EMESH or KIND_EINTERNAL (corr_from_fold). */
int corr_repair(const corr_input *in, bmap *P, bmap *Q, int relax, fold_report rep[2],
                char *err, size_t errsz);

/* The stages after which the pipeline finishes maps. */
typedef enum corr_after {
    CORR_AFTER_RHM,     /* RHM's maps, from landmarks or from given maps */
    CORR_AFTER_CARRY,   /* maps carried from the decimated pair to the meshes */
    CORR_AFTER_ECTM,    /* ECTM's maps, which the job returns */
} corr_after;
/* The finishing policy, one table in corr_finish.c: which of *P and *Q
 * (either may be NULL) get the fold repair after stage `after` of in's chain
 * (through_rhm: the chain runs RHM; in->P0: it starts from a given map).
 * Those that do not are set to NULL. Returns 1 when fold_relax follows the
 * repair (on the maps the job returns), else 0. */
int corr_finish_select(const corr_input *in, corr_after after, int through_rhm, bmap **P,
                       bmap **Q);
/* 1 when ECTM from RHM's maps P and Q (Q may be NULL) scales its membrane's
 * reference by their regional area (ectm_params.scale_reference): when they
 * keep areas well on the whole (corr_scale.c). */
int corr_scale_reference(const corr_input *in, const bmap *P, const bmap *Q);
/* The share of bad triangles (flipped plus collapsed) of the map P from A
 * onto B; 2 (worse than any) when it cannot be measured. */
double corr_folded(const mesh *A, const mesh *B, const bmap *P);

/* A job's parameters (the wire form of the one list, proto_params.h) as the
 * engine's: checked with proto_params_check (KIND_EPARAMS, "NAME = V: ..."
 * in err), a 0 that means the default left at the default, backend
 * "NAME[:DEVICE]" split into p->backend and p->device, threads into both.
 * p and r start from their _init defaults (log_eps stays ECTM's). */
int corr_params_from_job(const proto_params *w, int threads, ectm_params *p, rhm_params *r,
                         char *err, size_t errsz);
/* The inverse: w's job fields from p and r (NULL: rhm_params_init's); with
 * backend non-NULL, "NAME[:DEVICE]" is written there and w->backend points
 * at it, else w->backend is left as it is. */
void corr_params_to_job(const ectm_params *p, const rhm_params *r, proto_params *w, char *backend,
                        size_t bsz);

/* Coarse to fine (corr_coarse.c). With c = in->rhm->coarse (the job
 * parameter coarse, default 6000; 0: off), a chain from landmarks (no P0,
 * RHM runs) on a pair with a mesh over 2c vertices runs on copies of the
 * meshes decimated to c vertices (ctf_decimate, the landmark vertices
 * kept; a mesh of 2c or fewer is used as it is); its maps are carried
 * back to the input meshes (ctf_prolong) and repaired there
 * (corr_repair), and ECTM finishes them there. corr_run does this by
 * itself; the benchmarks call the steps to score each stage. */

typedef struct corr_coarse {
    mesh *S, *T;          /* the decimated copies; NULL: the input mesh itself */
    int *lsrc, *ltgt;     /* the landmark vertices on them                   */
    lmk_set L;
    corr_input in;        /* the job's input on the coarse pair               */
} corr_coarse;

/* Whether corr_run takes the coarse path for in. */
int corr_coarse_wanted(const corr_input *in);
/* Decimates in's meshes into c (c->in: the coarse pair's input, checked
 * with corr_validate). KIND_OK, KIND_ENOMEM, KIND_ENUMERIC or KIND_EINTERNAL
 * (the decimation), KIND_EMESH (a copy corr_validate refuses); on failure
 * c holds nothing. corr_run runs a job whose decimation fails other than
 * for memory on its meshes as given. */
int corr_coarse_open(const corr_input *in, corr_coarse *c, char *err, size_t errsz);
/* The coarse pair's maps Pc and (Qc, Q not NULL) Qc carried to in's meshes
 * into *P and *Q, and with repair non-zero repaired as corr_run's last step. */
int corr_coarse_carry(const corr_input *in, const corr_coarse *c, const bmap *Pc,
                      const bmap *Qc, int repair, bmap **P, bmap **Q, char *err, size_t errsz);
void corr_coarse_close(corr_coarse *c);

/* The worker's peak memory for the job in with parameters p, in bytes:
 * an estimate from the sizes (vertices and faces of both meshes, the
 * landmarks, the stages that run, the start, the coarse-to-fine size,
 * DDM's and ZoomOut's bases) that is meant to lie above what a run takes
 * and within a small factor of it (corr_cost.c says how it is counted).
 * what (may be NULL): the term that drives it, e.g. "the functional-map
 * start's landmark descriptors: 65536 landmarks on meshes of 65536 and
 * 65536 vertices (decimated from 163842 and 163842)". The daemon's SUBMIT
 * check refuses a job whose estimate is over the worker's memory limit;
 * p->backend opencl or auto adds the OpenCL runtime. */
double corr_cost_bytes(const corr_input *in, const ectm_params *p, char *what, size_t wsz);

/* Runs the pipeline: the stages of in->stages (corr_chain_check first).
 * Meshes in pieces that in->L pairs one to one (no given map) run pair by
 * pair, each pair's share of the progress by its vertices, and the maps
 * are joined (corr__pieces.h); pieces the landmarks do not pair are
 * KIND_EMESH.
 * When the chain ends before ECTM, out->P and out->Q are the last stage's
 * maps (RHM's repaired maps; DDM's denoised P, and Q when Q0 was given and
 * the model is bijective) and out->Y, out->Yt, out->last stay empty.
 * When the chain runs RHM then ECTM, out->rhm_P and (bijective) out->rhm_Q
 * are RHM's maps that ECTM started from: what the chain ending at RHM
 * returns for the same input, bit for bit (coarse to fine: carried back and
 * repaired the same way; in pieces: joined the same way). */
int corr_run(const corr_input *in, const ectm_params *p, corr_progress_fn progress,
             void *ctx, ectm_result *out, char *err, size_t errsz);

#endif
