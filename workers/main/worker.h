/* worker.h — meshcorr-worker, the process that runs one spooled job for the
 * daemon, and meshcorr-validate, the short-lived check of a SUBMIT before it
 * is accepted (the contract of both is workers/WORKER.md). Declarations
 * shared by their files (prefix wrk_); this folder is not part of the engine
 * library; outside these two programs only libmeshcorr-engine.so
 * (client-c/local/mc_match.c) links the job's mapping (worker_job.c,
 * worker_result.c, worker_progress.c), to run a job in-process as a
 * worker does.
 * meshcorr-validate is worker_validate.c with worker_job.c and worker_cli.c
 * only, so it loads Draco and none of the engine's solvers.
 *
 * Every function that can fail returns 0 or a negative PROTO_E* code (the
 * code that goes into error.frame) with a message naming the field in the
 * caller's err buffer. */
#ifndef WORKER_H
#define WORKER_H
#include <stddef.h>
#include <stdint.h>
#include <sys/resource.h>
#include "proto.h"
#include "spool.h"        /* file names and exit statuses: SPOOL_* */
#include "corr/corr.h"
#include "sandbox/sandbox.h"

typedef struct wrk_limits {
    int max_vertices, max_faces;   /* per mesh, checked while decoding */
    int threads;                   /* ectm_params.threads (0: by the job's size,
                                      ompenv_threads_for) */
} wrk_limits;

/* A job ready for corr_run; everything owned (wrk_job_close). S, T, L, P0
 * and Q0 are the client's, in its indexing; fix holds the repaired pair
 * when a mesh needed repair (corr_fix_open), and wrk_job_input gives the
 * engine that. */
typedef struct wrk_job {
    mesh *S, *T;
    lmk_set *L;                    /* NULL when the SUBMIT has no landmarks */
    bmap *P0, *Q0;                 /* NULL when absent */
    ectm_params params;
    rhm_params rhm;                /* for landmark jobs */
    corr_chain stages;            /* the chain, DDM's basis and mode as sent */
    int ddm_k;
    corr_ddm_mode ddm_mode;
    int repair;                    /* the parameter repair: 1 yes, 0 no */
    corr_fix fix;
} wrk_job;

/* worker_job.c — the one mapping from a SUBMIT to a job: decodes both Draco
 * meshes (BAD_MESH naming "source mesh"/"target mesh", over the limits
 * included), checks and with the parameter repair repairs them
 * (corr_fix_open, after the landmarks and maps are read in the client's
 * indexing, which it translates; BAD_MESH), checks and maps the
 * parameters onto ectm_params and rhm_params (corr_params_from_job, i.e.
 * proto_params_check: BAD_PARAMS naming the field), checks that there are
 * landmarks or a map (and q only with p, bijective), builds the landmark set
 * (lmk_from_arrays: BAD_LANDMARKS) and the initial maps (bmap_check_row:
 * BAD_MAP), and the sizes the meshes bound (corr_check_sizes: DDM's and
 * ZoomOut's bases, BAD_PARAMS). Each code is the wire code of the kind of
 * the failure (proto_kind.h, corr_wire_code). On error job is left closed. */
int wrk_job_from_submit(const proto_submit *s, const wrk_limits *lim, wrk_job *job,
                        char *err, size_t errsz);
void wrk_job_close(wrk_job *job);
/* A map from the wire (a SUBMIT's initial map, a RESULT's P or Q) checked
 * against its meshes (one row per vertex of from, faces of to, weights of a
 * point on the face): *out NULL when w is absent; else 0, or BAD_MAP's wire
 * code naming name and the row. */
int wrk_map_of(const proto_map *w, const char *name, const mesh *from, const mesh *to, bmap **out, char *err,
               size_t errsz);
/* The job as corr_run's input (pointers into job; the meshes named
 * "source mesh" and "target mesh", as in every message of a job): the
 * repaired pair when there is one. */
void wrk_job_input(const wrk_job *job, corr_input *in);

/* worker_io.c — the spool files. wrk_frame_read reads path whole and decodes
 * one frame of the given type (enum proto_type) filling it exactly (*buf holds the payload m borrows from; free
 * it after proto_msg_free). I/O errors are PROTO_ESTORAGE. wrk_frame_write
 * encodes m and writes dir/name atomically: name.tmp, fsync, rename, fsync
 * of dir; the .tmp is removed on failure. */
int wrk_frame_read(const char *path, int type, unsigned char **buf, proto_msg *m, char *err, size_t errsz);
int wrk_frame_write(const char *dir, const char *name, const proto_msg *m, char *err, size_t errsz);

/* worker_progress.c — PROGRESS frames (request id 0) on a pipe, or on a TCP
 * connection to meshcorrd (Slurm nodes, --progress-tcp) that falls back to
 * appending them to DIR/progress.frames when it cannot be made or breaks.
 * fd < 0 and no file: no progress. A pipe's first write error closes it for
 * good (the daemon is gone); the job always carries on. */
#define WRK_PROGRESS_HELLO "MCPROGRESS"      /* daemon/backend.h, bk_prog_ */
#define WRK_SECRET_MAX 128
typedef struct wrk_progress {
    int fd;
    uint64_t job_id;
    char file[4096];               /* fallback: "" none, else DIR/progress.frames */
} wrk_progress;
/* Connects to host:port (a TCP stream, send timeout set) and sends the hello
 * line with job_id and the secret read from secret_file; on any failure
 * pg->fd stays -1 and the frames go to pg->file. Reasons go to stderr. */
void wrk_progress_connect(wrk_progress *pg, const char *hostport, const char *secret_file);
/* The record of cp (corr_progress_record) as job job_id's, elapsed seconds
 * since the worker started. */
void wrk_progress_fill(const corr_progress *cp, uint64_t job_id, double elapsed, proto_progress *out);
void wrk_progress_send(wrk_progress *pg, const corr_progress *cp, double elapsed);

/* worker_result.c — the RESULT_OK message of a finished job: P, Q
 * (bijective), the deformed source as Draco (our order-keeping encoder) and
 * the metrics (WORKER.md lists the keys). res is the engine's result; when
 * the job's meshes were repaired, the maps and the deformed mesh go out in
 * the client's indexing (corr_fix_to_user), the metrics are the repaired
 * pair's, and the repair's counts follow them (WRK_REPAIR_KEYS). On a
 * chain RHM then ECTM, RHM's maps go out too (rhm_p, rhm_q) with their
 * quality under the keys rhm_NAME and whether ECTM's reference took their
 * scale, ectm_scaled_reference (WRK_RHM_KEYS). The message borrows
 * from r. */
#define WRK_BASE_METRICS 12
#define WRK_RHM_KEYS 5
#define WRK_REPAIR_KEYS (2 * (0 REPAIR_COUNTS(WRK_ONE)))
#define WRK_ONE(name, text) + 1
typedef struct wrk_result {
    proto_msg msg;
    proto_map_row *p, *q, *rhm_p, *rhm_q;
    unsigned char *deformed;
    proto_metric metrics[WRK_BASE_METRICS + WRK_REPAIR_KEYS + WRK_RHM_KEYS];
} wrk_result;
int wrk_result_build(const wrk_job *job, const ectm_result *res, uint64_t job_id,
                     double elapsed, wrk_result *r, char *err, size_t errsz);
void wrk_result_close(wrk_result *r);

/* worker_picture.c — `--picture FILE`: the picture of a finished job's map
 * P (render_map_png, as `meshcorr eval --out-png` draws it) from DIR's
 * job.frame and result.frame, for the web UI's job page. The meshes are
 * decoded in the sandbox, as for a run; FILE is written as FILE.tmp, then
 * renamed. The exit status: SPOOL_EXIT_OK, or 1 with the reason on stderr. */
int wrk_picture(const char *dir, uint64_t job_id, const wrk_limits *lim, const char *out);

/* The limits the worker sets whatever the daemon passes (WORKER.md,
 * "Sandbox"): its largest file is one frame (result.frame), it needs few
 * descriptors; --max-cpu-s is at most WRK_MAX_CPU_S, and a run that uses it
 * up gets SIGXCPU, then SIGKILL WRK_CPU_GRACE_S CPU seconds later. */
#define WRK_MAX_FILE_BYTES ((rlim_t)PROTO_MAX_FRAME)
#define WRK_MAX_FILES 1024
#define WRK_MAX_CPU_S (1ull << 40)
#define WRK_CPU_GRACE_S 10

/* worker_cli.c — shared by both programs' mains. wrk_parse_num: the decimal
 * s of option --opt in [lo, hi], or -1 with a message naming prog and the
 * option. wrk_setlimit: resource limit res to v (soft and hard), or -1 with
 * a message. wrk_error_msg: m as the ERROR message of code, its text msg cut
 * to the wire's string limit on a UTF-8 boundary into text (m borrows it). */
int wrk_parse_num(const char *prog, const char *opt, const char *s, unsigned long long lo,
                  unsigned long long hi, unsigned long long *out);
int wrk_setlimit(const char *prog, int res, const char *what, rlim_t v);
/* The options both programs take, by getopt's letter: 'v' --max-vertices
 * and 'f' --max-faces into lim, 'm' --max-memory-mb into *memory_mb; -1
 * with a message when arg is out of range. */
int wrk_limit_option(const char *prog, int opt, const char *arg, wrk_limits *lim,
                     unsigned long long *memory_mb);
void wrk_error_msg(proto_msg *m, int code, const char *msg, char text[PROTO_MAX_STRING + 1]);
/* RLIMIT_CPU: soft cpu_s (SIGXCPU), hard WRK_CPU_GRACE_S later (SIGKILL). */
int wrk_setlimit_cpu(const char *prog, rlim_t cpu_s);
/* What both programs set before they read their input: no core file, files
 * of at most max_file bytes, max_files descriptors, and RLIMIT_NPROC at half
 * the system's task ids (the limit counts every process and thread of the
 * user, the daemon's included: it keeps a runaway from taking them all). */
int wrk_base_limits(const char *prog, rlim_t max_file, rlim_t max_files);
/* The worker's sandbox profile (sandbox.h) for a job: the OpenCL one when
 * its backend is opencl or auto (both set PoCL up), else the CPU one. */
sbx_profile wrk_sandbox_profile(const proto_submit *s);

/* worker_devices.c — `--list-devices`: "cpu:N" and every OpenCL device with
 * fp64, one per line on stdout; 0 when printed. */
int wrk_list_devices(int threads);

#endif
