/* cli_job.h — the job options `meshcorr match` (in-process) and
 * `meshcorr submit` (through meshcorrd) share: inputs (landmarks or initial
 * maps) and every job parameter, parsed once, with the same names, checks
 * and messages; the parameters' options, help and checks are generated
 * from the one list PROTO_PARAMS (protocol/proto_params.h). Commands add
 * their own options (outputs, progress, server) around CLI_JOB_OPTIONS and
 * pass unknown codes to cli_job_option. */
#ifndef CLI_JOB_H
#define CLI_JOB_H
#include <getopt.h>
#include <stdio.h>
#include "proto.h"
#include "ectm/ectm.h"
#include "lmk/lmk.h"
#include "map/bmap.h"
#include "map/vmap.h"
#include "rhm/rhm.h"

enum cli_job_code {
    CLI_O_INIT = 2000, CLI_O_INIT_REVERSE, CLI_O_LANDMARKS, CLI_O_SOURCE_LANDMARKS,
    CLI_O_TARGET_LANDMARKS, CLI_O_ONE_BASED, CLI_O_PRESET, CLI_O_DEVICE, CLI_O_INIT_BASE,
    CLI_O_PARAM = 2100          /* + PROTO_P_*: one option per row of PROTO_PARAMS */
};

/* The job parameters' options come from the one list (proto_params.h):
 * --model, --alpha, ..., --backend; BOOL rows take no argument. */
#define CLI_ARG_ENUM required_argument
#define CLI_ARG_BOOL no_argument
#define CLI_ARG_U32  required_argument
#define CLI_ARG_F64  required_argument
#define CLI_ARG_STR  required_argument
#define CLI_JOB_PARAM_OPTION(name, cli, type, ...) {cli, CLI_ARG_##type, 0, CLI_O_PARAM + PROTO_P_##name},
#define CLI_JOB_OPTIONS                                                                     \
    PROTO_PARAMS(CLI_JOB_PARAM_OPTION)                                                      \
    {"init", required_argument, 0, CLI_O_INIT},                                             \
    {"init-reverse", required_argument, 0, CLI_O_INIT_REVERSE},                             \
    {"init-base", required_argument, 0, CLI_O_INIT_BASE},                                   \
    {"landmarks", required_argument, 0, CLI_O_LANDMARKS},                                   \
    {"source-landmarks", required_argument, 0, CLI_O_SOURCE_LANDMARKS},                     \
    {"target-landmarks", required_argument, 0, CLI_O_TARGET_LANDMARKS},                     \
    {"one-based", no_argument, 0, CLI_O_ONE_BASED},                                         \
    {"preset", required_argument, 0, CLI_O_PRESET},                                         \
    {"device", required_argument, 0, CLI_O_DEVICE}

/* Prints the job options' help: inputs, then one line per parameter of the
 * list (argument, meaning, default, range). */
void cli_job_usage(FILE *fp);

typedef struct cli_job {
    proto_params w;                          /* the job's parameters (the one list) */
    const char *device;                      /* --device, or NULL */
    char backend[32 + PROTO_MAX_DEVICE];     /* w.backend with the device: "NAME:DEVICE" */
    const char *init, *init_rev;             /* initial map files, or NULL */
    const char *lmk_pairs, *lmk_src, *lmk_tgt; /* landmark files, or NULL  */
    int one_based;
    int init_base;                           /* vertex-map --init files: 0, 1, VMAP_BASE_AUTO */
} cli_job;

/* Defaults; --preset paper anywhere in argv applies first, so explicit
 * weights win whatever their position. */
void cli_job_init(cli_job *j, int argc, char **argv);
/* 1: c was a job option and arg is good; -1: it was, and arg is bad (the
 * message, naming cmd and the option, is printed); 0: not a job option. */
int cli_job_option(cli_job *j, const char *cmd, int c, const char *arg);
/* After parsing: 0, or -1 with a message (no inputs, half a landmark pair,
 * parameters out of range: proto_params_check, the server's own check).
 * Joins --device into w.backend. */
int cli_job_check(cli_job *j, const char *cmd);
/* The engine's parameters of the job (corr_params_from_job); -1 with a
 * message when they are out of range (not after cli_job_check). */
int cli_job_engine(const cli_job *j, const char *cmd, int threads, ectm_params *p, rhm_params *r);
/* A line on stderr when the file at path had polygon faces (m->polygons):
 * the faces a map names on it are the triangles they were split into. */
void cli_job_note_polygons(const char *cmd, const char *path, const mesh *m);
/* Reads the landmark set (or NULL) and the initial maps (or NULL) against
 * the two meshes; -1 with the reader's message printed. An initial map is
 * a meshcorr-map 1 file or a vertex map (vmap.h; base --init-base, else
 * vmap.h's rule); landmarks given with a map are read too (RHM's weak
 * landmark term and fold repair use them). */
int cli_job_load(const cli_job *j, const char *cmd, const mesh *S, const mesh *T,
                 lmk_set **L, bmap **P0, bmap **Q0);

/* Parameter i's default as the help writes it ("cpu", "bijective", "off",
 * "300") into buf; returns buf. */
const char *cli_param_default(int i, char *buf, size_t size);

#endif
