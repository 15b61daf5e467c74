/* cli_job.h — the job options `meshcorr match` (in-process) and
 * `meshcorr submit` (through meshcorrd) share: inputs (landmarks or initial
 * maps) and every optimizer weight, parsed once, with the same names, checks
 * and messages. Commands add their own options (outputs, progress, server)
 * around CLI_JOB_OPTIONS and pass unknown codes to cli_job_option. */
#ifndef CLI_JOB_H
#define CLI_JOB_H
#include <getopt.h>
#include "ectm/ectm.h"
#include "lmk/lmk.h"
#include "map/bmap.h"
#include "rhm/rhm.h"

enum cli_job_code {
    CLI_O_INIT = 2000, CLI_O_INIT_REVERSE, CLI_O_LANDMARKS, CLI_O_SOURCE_LANDMARKS,
    CLI_O_TARGET_LANDMARKS, CLI_O_ONE_BASED, CLI_O_MODEL, CLI_O_PRESET, CLI_O_ALPHA, CLI_O_ETA,
    CLI_O_BETA0, CLI_O_BETA1, CLI_O_BETA_RAMP, CLI_O_GAMMA, CLI_O_ITERATIONS,
    CLI_O_INNER_ITERATIONS, CLI_O_TOLERANCE, CLI_O_STOP_CHANGE, CLI_O_PARTIAL, CLI_O_BACKEND,
    CLI_O_DEVICE, CLI_O_RHM_ALPHA, CLI_O_RHM_ITERATIONS, CLI_O_RHM_DIM, CLI_O_RHM_LANDMARK_WEIGHT,
    CLI_O_RHM_START
};

#define CLI_JOB_OPTIONS                                                                     \
    {"init", required_argument, 0, CLI_O_INIT},                                             \
    {"init-reverse", required_argument, 0, CLI_O_INIT_REVERSE},                             \
    {"landmarks", required_argument, 0, CLI_O_LANDMARKS},                                   \
    {"source-landmarks", required_argument, 0, CLI_O_SOURCE_LANDMARKS},                     \
    {"target-landmarks", required_argument, 0, CLI_O_TARGET_LANDMARKS},                     \
    {"one-based", no_argument, 0, CLI_O_ONE_BASED},                                         \
    {"model", required_argument, 0, CLI_O_MODEL},                                           \
    {"preset", required_argument, 0, CLI_O_PRESET},                                         \
    {"alpha", required_argument, 0, CLI_O_ALPHA},                                           \
    {"eta", required_argument, 0, CLI_O_ETA},                                               \
    {"beta0", required_argument, 0, CLI_O_BETA0},                                           \
    {"beta1", required_argument, 0, CLI_O_BETA1},                                           \
    {"beta-ramp", required_argument, 0, CLI_O_BETA_RAMP},                                   \
    {"gamma", required_argument, 0, CLI_O_GAMMA},                                           \
    {"iterations", required_argument, 0, CLI_O_ITERATIONS},                                 \
    {"inner-iterations", required_argument, 0, CLI_O_INNER_ITERATIONS},                     \
    {"tolerance", required_argument, 0, CLI_O_TOLERANCE},                                   \
    {"stop-change", required_argument, 0, CLI_O_STOP_CHANGE},                               \
    {"partial", no_argument, 0, CLI_O_PARTIAL},                                             \
    {"backend", required_argument, 0, CLI_O_BACKEND},                                       \
    {"device", required_argument, 0, CLI_O_DEVICE},                                         \
    {"rhm-alpha", required_argument, 0, CLI_O_RHM_ALPHA},                                   \
    {"rhm-iterations", required_argument, 0, CLI_O_RHM_ITERATIONS},                         \
    {"rhm-dim", required_argument, 0, CLI_O_RHM_DIM},                                       \
    {"rhm-landmark-weight", required_argument, 0, CLI_O_RHM_LANDMARK_WEIGHT},     \
    {"rhm-start", required_argument, 0, CLI_O_RHM_START}

#define CLI_JOB_USAGE                                                                           \
    "  inputs:   --landmarks PAIRS | --source-landmarks A --target-landmarks B [--one-based]\n"  \
    "            | --init P.map [--init-reverse Q.map]\n"                                       \
    "  ECTM:     [--model bijective|injective] [--preset release|paper] [--alpha A] [--eta E]\n" \
    "            [--beta0 B] [--beta1 B] [--beta-ramp K] [--gamma G] [--iterations K]\n"        \
    "            [--inner-iterations N] [--tolerance T] [--stop-change C] [--partial]\n"        \
    "            [--backend cpu|opencl|auto] [--device NAME]\n"                                 \
    "  RHM:      [--rhm-alpha A] [--rhm-iterations K] [--rhm-dim M] [--rhm-landmark-weight G]\n" \
    "            [--rhm-start distances|voronoi]\n"                                           \
    "Defaults are the authors' released code's (--preset release): alpha 20, eta 6.667e-4,\n"    \
    "beta 500 -> 1e5 over 200 iterations, gamma 1e4, 300 iterations, 50 L-BFGS steps.\n"        \
    "Without --init, the initial maps come from the landmarks (at least 3): a start map\n"      \
    "matching each vertex's geodesic distances to the landmarks (--rhm-start voronoi: the\n"   \
    "thesis' geodesic Voronoi cells), then Reversible Harmonic Maps (alpha 5e-4, beta 5e-3\n"  \
    "min(k, 100), 8-D embedding, at most 200 iterations, landmark weight 0).\n"               \
    "--backend opencl computes the elastic energy on an OpenCL device with fp64 whose\n"        \
    "platform or device name contains NAME (see meshcorr devices); auto: a GPU, else the CPU.\n"

typedef struct cli_job {
    ectm_params p;
    rhm_params rp;
    const char *init, *init_rev;             /* initial map files, or NULL */
    const char *lmk_pairs, *lmk_src, *lmk_tgt; /* landmark files, or NULL  */
    int one_based;
} cli_job;

/* Defaults; --preset paper anywhere in argv applies first, so explicit
 * weights win whatever their position. */
void cli_job_init(cli_job *j, int argc, char **argv);
/* 1: c was a job option and arg is good; -1: it was, and arg is bad (the
 * message, naming cmd and the option, is printed); 0: not a job option. */
int cli_job_option(cli_job *j, const char *cmd, int c, const char *arg);
/* After parsing: 0, or -1 with a message (no inputs, half a landmark pair,
 * parameters out of range). */
int cli_job_check(const cli_job *j, const char *cmd);
/* Reads the landmark set (or NULL) and the initial maps (or NULL) against
 * the two meshes; -1 with the reader's message printed. */
int cli_job_load(const cli_job *j, const char *cmd, const mesh *S, const mesh *T,
                 lmk_set **L, bmap **P0, bmap **Q0);

#endif
