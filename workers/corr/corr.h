/* corr.h — one correspondence job from inputs to maps: the pipeline that
 * `meshcorr match` runs in-process and `meshcorr-worker` runs for the daemon.
 *
 *   validate both meshes (manifold, one component, finite, no degenerate face)
 *   initial maps: the uploaded P (and Q), or from landmarks: geodesic
 *     start map (rhm.h), then Reversible Harmonic Maps giving P and Q,
 *     whose folds are then repaired (corr_repair, fold.h)
 *   ECTM refinement, then the same fold repair of the maps it returns
 *     (the rows of bad regions change; out->Y stays ECTM's deformation)
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
#include "rhm/rhm.h"
#include "proto.h"

#define CORR_ERRORS(X)                                                          \
    X(CORR_OK,         0, "ok")                                                 \
    X(CORR_EMESH,     -1, "mesh not usable")                                    \
    X(CORR_EINPUT,    -2, "inputs do not fit together")                         \
    X(CORR_EINIT,     -3, "initial map could not be built")                     \
    X(CORR_ENOMEM,    -4, "out of memory")                                      \
    X(CORR_ECANCELED, -5, "cancelled")                                          \
    X(CORR_EFAILED,   -6, "optimisation failed")

enum corr_error {
#define CORR_ENUM(name, val, msg) name = val,
    CORR_ERRORS(CORR_ENUM)
#undef CORR_ENUM
};
const char *corr_strerror(int code);

typedef enum corr_stage {
    CORR_STAGE_INIT = 0,     /* building the initial map starts             */
    CORR_STAGE_ECTM = 1,     /* one report per ECTM outer iteration         */
    CORR_STAGE_START = 2,  /* the start map is built (its RHM energies)  */
    CORR_STAGE_RHM = 3       /* one report per RHM iteration                */
} corr_stage;
const char *corr_stage_name(corr_stage s);   /* "init", "ectm", "start", "rhm" */

/* Which stages run: all (landmarks -> start -> RHM -> ECTM, or ECTM from
 * an uploaded map), RHM only (from landmarks; its maps are the result), or
 * ECTM only (from an uploaded map). */
typedef enum corr_stages { CORR_STAGES_ALL = 0, CORR_STAGES_RHM = 1, CORR_STAGES_ECTM = 2 } corr_stages;

typedef struct corr_input {
    const mesh *S, *T;        /* source and target (required)               */
    const char *S_name, *T_name; /* for messages (file names or labels)     */
    const lmk_set *L;         /* landmark pairs, or NULL                     */
    const bmap *P0, *Q0;      /* uploaded initial maps, or NULL              */
    const rhm_params *rhm;    /* RHM parameters, NULL: rhm_params_init's     */
    corr_stages stages;
} corr_input;

typedef struct corr_progress {
    corr_stage stage;
    const ectm_report *ectm;  /* the outer iteration's report (stage ECTM)  */
    double elapsed;           /* seconds since corr_run started             */
    const rhm_report *rhm;    /* the RHM report (stages START and RHM)      */
} corr_progress;

typedef int (*corr_progress_fn)(void *ctx, const corr_progress *p);

/* 0 when the optimizer can use m; else CORR_EMESH with one line per problem
 * ("name: ...") in err. */
int corr_validate(const mesh *m, const char *name, char *err, size_t errsz);

/* The fold repair the pipeline applies to RHM's maps and to ECTM's: fold_repair of P
 * (S -> T) and, when Q is not NULL, of Q (T -> S), the landmarks fixed
 * (in->L may be NULL), with fold_params_init's values. rep[0], rep[1]:
 * P's and Q's reports. CORR_OK, CORR_ENOMEM or CORR_EINIT. */
int corr_repair(const corr_input *in, bmap *P, bmap *Q, fold_report rep[2], char *err,
                size_t errsz);

/* A job's parameters (the wire form of the one list, proto_params.h) as the
 * engine's: checked with proto_params_check (CORR_EINPUT, "params.NAME ..."
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

/* Runs the pipeline. Needs P0 or at least PROTO_MIN_LANDMARKS landmarks. With
 * stages RHM, out->P and out->Q are RHM's repaired maps and out->Y, out->Yt, out->last
 * stay empty. */
int corr_run(const corr_input *in, const ectm_params *p, corr_progress_fn progress,
             void *ctx, ectm_result *out, char *err, size_t errsz);

#endif
