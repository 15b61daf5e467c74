/* proto_params.h — the ONE list of a job's parameters. Everything else is
 * generated from PROTO_PARAMS: the wire struct proto_params and its codec
 * (proto_msg.c: wire order = list order), the checks (proto_params_check:
 * the one validator the daemon, the worker and the CLI call), the client's
 * mc_job_spec fields and defaults (meshcorr.h, mc_client.c), the engine's
 * defaults and range checks (ectm_params, rhm_params: the ENGINE column),
 * the CLI options and their --help lines (cli_job.c), and the parameter
 * table of protocol/PROTOCOL.md (`make doc-params`; test_proto_params checks
 * it is current). To add a parameter, add a row here (at the end: the wire
 * order is the list order, and a new field is a new PROTOCOL_VERSION).
 *
 * Only macros and constants: no code, no includes but <math.h> (INFINITY),
 * so the public header meshcorr.h, the codec and the engine can all include
 * it without pulling anything else in.
 *
 * Columns of X(name, cli, TYPE, default, min, max, flags, ENGINE, field, values, help):
 *   name     the wire field and C member name
 *   cli      the command-line option (--cli)
 *   TYPE     ENUM (u8, a value of `values`), BOOL (u8 0/1), U32, F64 (finite
 *            f64), STR (str; its default is "")
 *   default  the value of mc_job_spec_init, `meshcorr match` and the engine
 *   min, max the closed range, or open at an end with PROTO_PARAM_OPEN_MIN /
 *            PROTO_PARAM_OPEN_MAX; F64 values must also be finite
 *   flags    PROTO_PARAM_* bits; PROTO_PARAM_ZERO_DEFAULT: 0 on the wire
 *            means the default (kept from protocol version 1's first
 *            clients, which sent 0 for "the release's RHM value");
 *            PROTO_PARAM_ZERO_OFF: 0 is a value besides [min, max] (the
 *            feature off)
 *   ENGINE   ECTM (field of ectm_params), RHM (of rhm_params) or NONE
 *   values   ENUM: the value names "a|b" (0, 1, ...); STR: the accepted words
 *   help     one line for --help and PROTOCOL.md */
#ifndef PROTO_PARAMS_H
#define PROTO_PARAMS_H
#include <math.h>

/* Landmark pairs of a SUBMIT, a landmark file, an RHM start: one rule. */
#define PROTO_MIN_LANDMARKS 3        /* three pairs fix orientation: fewer leave the start
                                        map free to mirror the shape */
#define PROTO_MAX_LANDMARKS 65536   /* landmark pairs (the codec's count limit too) */
#define PROTO_MAX_DEVICE    127      /* bytes of ":DEVICE" in backend, the colon excluded */
#define PROTO_RHM_MAX_DIM   64       /* rhm_dim's max: the embedding's (EMBED_MAX_DIM) */
#define PROTO_DDM_MAX_K     300      /* ddm_k's max: the eigenpairs' (LBO_MAX_K) */
#define PROTO_ZOOMOUT_MIN   51       /* zoomout's min besides 0 (off): START_FMAP_K + 1 */
#define PROTO_ZOOMOUT_MAX   300      /* zoomout's max: the eigenpairs' (LBO_MAX_K) */
#define PROTO_COARSE_MIN    500      /* coarse's min besides 0 (off) */
#define PROTO_COARSE_MAX    10000000 /* coarse's max */

#define PROTO_PARAM_OPEN_MIN     1u
#define PROTO_PARAM_OPEN_MAX     2u
#define PROTO_PARAM_ZERO_DEFAULT 4u
#define PROTO_PARAM_ZERO_OFF 8u

#define PROTO_PARAMS(X)                                                                          \
    X(model, "model", ENUM, 0, 0, 1, 0, ECTM, model, "bijective|injective",                      \
      "energy model: bijective (maps P and Q) or injective (P only)")                            \
    X(partial, "partial", BOOL, 0, 0, 1, 0, ECTM, partial, "",                                   \
      "partial matching: no rescaling to unit area (alpha / source area, beta / both areas)")    \
    X(alpha, "alpha", F64, 20, 0, INFINITY, PROTO_PARAM_OPEN_MIN, ECTM, alpha, "",               \
      "membrane weight alpha of W_def = alpha W_mem + eta W_bnd")                                \
    X(eta, "eta", F64, 2e-3 / 3, 0, INFINITY, 0, ECTM, eta, "",                                  \
      "bending weight eta")                                                                      \
    X(beta0, "beta0", F64, 500, 0, INFINITY, PROTO_PARAM_OPEN_MIN, ECTM, beta0, "",              \
      "mismatch weight beta at outer iteration 1")                                               \
    X(beta1, "beta1", F64, 1e5, 0, INFINITY, PROTO_PARAM_OPEN_MIN, ECTM, beta1, "",              \
      "largest beta, from outer iteration beta_ramp on")                                         \
    X(beta_ramp, "beta-ramp", U32, 200, 1, 1000000, 0, ECTM, beta_ramp, "",                      \
      "outer iterations of the linear ramp beta0 -> beta1 (1: beta1 throughout)")                \
    X(gamma, "gamma", F64, 1e4, 0, INFINITY, 0, ECTM, gamma, "",                                 \
      "reverse-map weight gamma (bijective model)")                                              \
    X(iterations, "iterations", U32, 600, 1, 1000000, 0, ECTM, iterations, "",                   \
      "ECTM: outer iterations K at most (the RHM stage before it has its own count, rhm_iterations)") \
    X(inner_iterations, "inner-iterations", U32, 50, 1, 100000, 0, ECTM, inner_iterations, "",  \
      "ECTM: L-BFGS iterations per Y-step at most")                                              \
    X(tolerance, "tolerance", F64, 1e-8, 0, INFINITY, PROTO_PARAM_OPEN_MIN, ECTM, tolerance, "", \
      "L-BFGS gradient tolerance")                                                               \
    X(stop_change, "stop-change", F64, 0.1, 0, INFINITY, 0, ECTM, stop_change, "",               \
      "ECTM: stop once the energy fell by under this share in 100 outer iterations at one beta (0: run all)") \
    X(rhm_iterations, "rhm-iterations", U32, 200, 1, 1000000, PROTO_PARAM_ZERO_DEFAULT, RHM,     \
      iterations, "", "RHM: at most this many iterations (not ECTM's: that count is iterations)") \
    X(rhm_dim, "rhm-dim", U32, 8, 3, PROTO_RHM_MAX_DIM, PROTO_PARAM_ZERO_DEFAULT, RHM, dim, "",                 \
      "RHM embedding dimension m")                                                               \
    X(rhm_alpha, "rhm-alpha", F64, 5e-4, 0, 1,                                                   \
      PROTO_PARAM_OPEN_MIN | PROTO_PARAM_OPEN_MAX | PROTO_PARAM_ZERO_DEFAULT, RHM, alpha, "",    \
      "RHM harmonic vs reversibility weight")                                                    \
    X(rhm_landmark_weight, "rhm-landmark-weight", F64, 0, 0, INFINITY, 0, RHM, gamma, "",        \
      "RHM weak landmark term weight (0: off)")                                                  \
    X(start, "start", ENUM, 3, 0, 3, 0, RHM, start, "distances|voronoi|fmap|auto",               \
      "start map from landmarks (before RHM): distances to the landmarks, the thesis' geodesic " \
      "Voronoi cells, a functional map from landmark descriptors made precise by DDM, or auto: " \
      "distances, and when RHM's maps from it are folded (over 5 % of the triangles flipped or " \
      "collapsed) the functional map too, the less folded kept")                                \
    X(backend, "backend", STR, 0, 0, 0, 0, NONE, backend, "cpu|opencl|auto",                     \
      "elastic energy on the CPU, an OpenCL device, or auto (a GPU, else the CPU); "             \
      "\"\" = the server's default (cpu); on the wire optionally :DEVICE")                     \
    X(stages, "stages", ENUM, 0, 0, 7, 0, NONE, stages,                                          \
      "all|rhm|ectm|ddm|ddm,ectm|ddm,rhm|ddm,rhm,ectm|rhm,ectm",                                 \
      "stages run, always in the order ddm, rhm, ectm: all = RHM then ECTM from landmarks, "     \
      "ECTM alone on a given map; ddm (denoising through the map's functional map) needs a "     \
      "given map; rhm starts from landmarks or from the given (or denoised) map")                \
    X(ddm_k, "ddm-k", U32, 0, 0, PROTO_DDM_MAX_K, 0, NONE, ddm_k, "",                            \
      "DDM basis size: eigenfunctions per mesh (0: min(100, vertices - 2); at most vertices - 2)") \
    X(ddm_mode, "ddm-mode", ENUM, 2, 0, 2, 0, NONE, ddm_mode, "plain|bijective|auto",            \
      "DDM denoising: plain (each given map alone), bijective (the map p and its reverse q "     \
      "denoised together, each made consistent with the other's functional map; needs q), or "  \
      "auto: bijective when q is given and p and q agree (round trip at most 0.1 of the "       \
      "shape's size), else plain")                                                             \
    X(zoomout, "zoomout", U32, 0, PROTO_ZOOMOUT_MIN, PROTO_ZOOMOUT_MAX, PROTO_PARAM_ZERO_OFF,    \
      RHM, zoomout, "",                                                                          \
      "start fmap (and auto's second run): ZoomOut from the start's 50 basis functions to this " \
      "many per mesh before DDM deblurring (0: off; else more than 50 and at most vertices - 2)") \
    X(coarse, "coarse", U32, 6000, PROTO_COARSE_MIN, PROTO_COARSE_MAX, PROTO_PARAM_ZERO_OFF, RHM,   \
      coarse, "",                                                                                \
      "coarse to fine, from landmarks: a mesh over twice this many vertices is decimated to "   \
      "this many, the chain runs on the decimated pair, its maps come back to the meshes and "  \
      "ECTM finishes them there (0: off, every stage on the meshes as given)")                \
    X(repair, "repair", ENUM, 0, 0, 1, 0, NONE, repair, "yes|no",                              \
      "input mesh repair: a mesh the optimizer cannot use as given (non-manifold, unwelded, "   \
      "degenerate or duplicate faces, stray pieces) is repaired, the repairs listed in the "    \
      "result and the maps returned in the mesh's own vertex indexing; no: such a mesh is "     \
      "refused (docs/repair.md)")

#endif
