/* meshcorr.h — libmeshcorr, the C client of meshcorrd. Shared:
 * libmeshcorr.so.1 (`pkg-config --cflags --libs meshcorr` after make
 * install), which exports mc_* only. Static: libmeshcorr.a, then
 * libmcengine.a, libmcproto.a and the libraries in meshcorr.pc's
 * Libs.private (the Makefile's LDLIBS).
 *
 * One mc_client is one connection (Unix socket or TCP), authenticated at
 * mc_connect, used by one thread at a time. Every call is blocking: requests
 * wait at most the client's timeout (mc_set_timeout, default 30 s); mc_watch
 * waits as long as the job runs.
 *
 * Errors: every function returns 0 or a negative code. Codes from -1 to -99
 * are the server's refusals (the protocol's error list: MC_ENOT_FOUND is
 * PROTO_ENOT_FOUND, ...); -100 and below are this library's own (MC_E* below).
 * mc_strerror describes any code, mc_err_name names it; mc_errmsg(client)
 * gives the detail of the client's last failed call (the server's message,
 * or the system error).
 *
 * Ownership: mc_connect returns a client freed by mc_close (NULL ok).
 * Arrays a call fills are malloc()ed and released with one call each:
 * mc_result_free(&r) for everything in an mc_job_result, mc_stats_free(&s)
 * for an mc_server_stats (both accept zeroed structs), free(jobs) for
 * mc_list. Draco bytes from mc_encode_mesh[_file] are free()d by the caller.
 * Inputs (mc_job_spec and what it points to) stay the caller's. */
#ifndef MESHCORR_H
#define MESHCORR_H
#include <stddef.h>
#include <stdint.h>
#include "proto_params.h"   /* PROTO_PARAMS: the job parameters, installed with this header */

#ifdef __cplusplus
extern "C" {
#endif

#define MC_ERRORS(X)                                                        \
    X(MC_EARG,     -100, "invalid argument")                                \
    X(MC_EADDRESS, -101, "bad server address")                              \
    X(MC_ECONNECT, -102, "cannot connect to the server")                    \
    X(MC_EIO,      -103, "connection failed")                               \
    X(MC_ETIMEOUT, -104, "timed out waiting for the server")                \
    X(MC_EPROTO,   -105, "the server's reply does not follow the protocol") \
    X(MC_ENOMEM,   -106, "out of memory")                                   \
    X(MC_EFILE,    -107, "cannot read or encode the file")                  \
    X(MC_ETLS,     -108, "TLS failed: the server's certificate is not trusted, or no TLS session")

enum mc_error {
    MC_OK = 0,
    /* the server's codes, the same numbers as the protocol's */
    MC_EUNAUTHORIZED = -13, MC_EFORBIDDEN = -14, MC_ENOT_FOUND = -15,
    MC_EBAD_STATE = -16, MC_EQUEUE_FULL = -17, MC_EUSER_LIMIT = -18,
    MC_EBAD_MESH = -19, MC_EBAD_LANDMARKS = -20, MC_EBAD_PARAMS = -21,
    MC_ECANCELLED = -25,       /* mc_match: stopped by its progress callback */
    MC_EBUSY = -26,            /* a connection limit: retry later (at connect) */
    MC_ETIMED_OUT = -27,       /* the server cut a silent, slow or idle connection */
    MC_EOVER_QUOTA = -28,      /* SUBMIT: the user's stored bytes, or the spool's, would pass its quota */
    MC_EBAD_MAP = -29,         /* an initial map that does not fit the meshes */
    MC_ENUMERIC = -30,         /* a stage of the job failed numerically (mc_match; a job's reason) */
#define MC_ENUM(name, val, msg) name = val,
    MC_ERRORS(MC_ENUM)
#undef MC_ENUM
};
const char *mc_strerror(int code);
/* The project's version, "MAJOR.MINOR.PATCH" (the VERSION file of the
 * source tree the library was built from). */
const char *mc_version(void);
/* The code's name: "BAD_PARAMS" (the protocol's name of a server code), "MC_EARG"
 * (this library's); "UNKNOWN" for others. */
const char *mc_err_name(int code);
/* The server code a failed job's reason starts with: a job that failed in
 * its worker ends with the reason "NAME: message", NAME the code's name
 * (mc_err_name: "NUMERIC", "BAD_MESH", ...; PROTOCOL.md, Errors: the
 * kinds of a job's failure). 0 when the reason starts with no code's name
 * (a timeout, a crash, a cancel before the job ran; NULL too). */
int mc_reason_error(const char *reason);

/* Job states (Slurm's names) and stages, as in the protocol. */
enum mc_state { MC_PENDING, MC_RUNNING, MC_COMPLETED, MC_FAILED, MC_CANCELLED, MC_TIMEOUT,
                MC_OUT_OF_MEMORY };
const char *mc_state_name(int state);          /* "COMPLETED"; NULL when unknown */
int mc_state_parse(const char *name);          /* state, or -1 */
const char *mc_stage_name(int stage);          /* "rhm" (MC_STAGE_*); NULL when unknown */
enum mc_model { MC_BIJECTIVE = 0, MC_INJECTIVE = 1 };

/* RESULT parts. */
#define MC_WANT_P        1u
#define MC_WANT_Q        2u
#define MC_WANT_DEFORMED 4u
#define MC_WANT_METRICS  8u

typedef struct mc_client mc_client;

typedef struct mc_map_row {    /* a point on face `face` of the other mesh */
    uint32_t face;
    double w[3];               /* barycentric weights */
} mc_map_row;

typedef struct mc_job_spec {
    const unsigned char *source; size_t source_len;   /* Draco bytes (mc_encode_mesh[_file]) */
    const unsigned char *target; size_t target_len;
    const uint32_t *landmarks; uint32_t nlandmarks;   /* nlandmarks (src, tgt) pairs, 2n ids */
    const mc_map_row *p; uint32_t np;                 /* optional initial map, np = source vertices */
    const mc_map_row *q; uint32_t nq;                 /* optional reverse map (bijective) */
    /* The job's parameters: one member per row of the one list PROTO_PARAMS
     * (proto_params.h: name, type, default, range, meaning; `meshcorr
     * params` prints it), in its order: model (MC_BIJECTIVE, MC_INJECTIVE),
     * partial, alpha, eta, beta0, beta1, beta_ramp, gamma, iterations,
     * inner_iterations, tolerance, stop_change, rhm_iterations, rhm_dim,
     * rhm_alpha, rhm_landmark_weight, start (MC_START_*), backend
     * (NULL or "" = the server's default; "cpu", "opencl", "auto",
     * optionally ":DEVICE", a platform or device name part), stages
     * (MC_STAGES_*), ddm_k, ddm_mode (MC_DDM_PLAIN, MC_DDM_BIJECTIVE),
     * zoomout, coarse, repair (0 yes: repair a mesh the optimizer cannot
     * use as given; 1 no: refuse it). */
#define MC_PARAM_CTYPE_ENUM int
#define MC_PARAM_CTYPE_BOOL int
#define MC_PARAM_CTYPE_U32  uint32_t
#define MC_PARAM_CTYPE_F64  double
#define MC_PARAM_CTYPE_STR  const char *
#define MC_PARAM_MEMBER(name, cli, type, ...) MC_PARAM_CTYPE_##type name;
    PROTO_PARAMS(MC_PARAM_MEMBER)
#undef MC_PARAM_MEMBER
    int32_t priority;          /* higher runs first */
    const char *label;         /* NULL = "" */
} mc_job_spec;

/* Every parameter its default (the list's, those of `meshcorr match`); no
 * meshes, no landmarks. */
void mc_job_spec_init(mc_job_spec *s);

/* The parameter list as data, for callers that walk it at run time (the
 * Python package) rather than compile against PROTO_PARAMS: rows 0 to
 * mc_param_count() - 1 in list order; NULL (type -1) out of range. The
 * strings are static. */
enum mc_param_type { MC_PARAM_ENUM, MC_PARAM_BOOL, MC_PARAM_U32, MC_PARAM_F64, MC_PARAM_STR };
int mc_param_count(void);
const char *mc_param_name(int i);              /* "inner_iterations": the member's name */
const char *mc_param_cli(int i);               /* "inner-iterations": meshcorr's --option */
int mc_param_type(int i);                      /* enum mc_param_type */
const char *mc_param_values(int i);            /* ENUM, STR: "bijective|injective"; else "" */
const char *mc_param_help(int i);
/* sizeof(mc_job_spec): a binding that lays the struct out from the list
 * checks its layout against it. */
size_t mc_job_spec_size(void);
/* Sets the member named name (or its option name) from text as `meshcorr
 * submit --OPTION text` parses it: a number, a value name of an ENUM
 * ("injective"), "0"/"1" for a BOOL; a STR keeps the pointer, so text must
 * outlive s. Only parses: the server checks ranges at mc_submit (a bad
 * value is refused there with its message). An unknown name or a value
 * that does not parse: MC_EARG, detail in err. */
int mc_job_spec_set(mc_job_spec *s, const char *name, const char *text, char *err, size_t errsz);

enum { MC_START_DISTANCES = 0, MC_START_VORONOI = 1, MC_START_FMAP = 2, MC_START_AUTO = 3 };
/* MC_STAGE_INIT is not sent by servers from protocol version 5 on;
 * MC_STAGE_QUEUED is a pending job's record: its place in the queue. */
enum { MC_STAGE_START = 0, MC_STAGE_RHM = 1, MC_STAGE_ECTM = 2, MC_STAGE_INIT = 3, MC_STAGE_DDM = 4,
       MC_STAGE_REPAIR = 5, MC_STAGE_QUEUED = 6 };
/* Values of the stages parameter (PROTO_PARAMS; `meshcorr submit --stages`). */
enum { MC_STAGES_ALL = 0, MC_STAGES_RHM = 1, MC_STAGES_ECTM = 2, MC_STAGES_DDM = 3,
       MC_STAGES_DDM_ECTM = 4, MC_STAGES_DDM_RHM = 5, MC_STAGES_DDM_RHM_ECTM = 6,
       MC_STAGES_RHM_ECTM = 7 };
/* Values of ddm_mode: each given map denoised alone, p and q together, or
 * auto (the default): together when q is given and agrees with p. */
enum { MC_DDM_PLAIN = 0, MC_DDM_BIJECTIVE = 1, MC_DDM_AUTO = 2 };

/* For stages start and rhm the five terms are RHM's (PROTOCOL.md,
 * PROGRESS): membrane = Dirichlet, bending = landmark, mismatch, reverse.
 * fraction and eta_s are the whole job's: every stage weighted by its
 * expected cost. */
typedef struct mc_progress {
    uint64_t job_id;
    int stage;                 /* MC_STAGE_*: 0 start, 1 rhm, 2 ectm, 3 init, 4 ddm,
                                  5 repair, 6 queued */
    uint32_t outer, total;     /* the stage's iteration, planned */
    uint32_t inner[2];         /* L-BFGS iterations: [0] source side, [1] target side */
    double membrane[2], bending[2], mismatch[2], reverse[2], energy[2];
    double beta, gamma, elapsed_s;
    double fraction;           /* of the whole job done, 0 to 1; NaN not known */
    double eta_s;              /* seconds left; NaN not known */
    uint32_t ahead;            /* MC_STAGE_QUEUED: jobs that start before it */
} mc_progress;

/* How good a COMPLETED job's map is, as its worker measured it. */
typedef struct mc_quality {
    int verdict;               /* MC_QUALITY_*; MC_QUALITY_UNKNOWN before COMPLETED */
    double flipped, collapsed; /* fractions of source faces; NaN when not known */
} mc_quality;
#define MC_QUALITY_UNKNOWN  (-1)
#define MC_QUALITY_OK       0  /* neither of the below */
#define MC_QUALITY_FOLDED   1  /* flipped + collapsed > 5 % */
#define MC_QUALITY_REVERSED 2  /* more than 50 % flipped: orientation reversed */
/* "unknown", "ok", "folded", "reversed". */
const char *mc_quality_name(int verdict);

typedef struct mc_job_status {
    uint64_t job_id;
    int state;
    int32_t priority;
    char user[256];
    char label[1025];
    char reason[1025];         /* why it failed or was cancelled; may be "" */
    int64_t submit_ms, start_ms, end_ms;   /* Unix ms; 0 = not yet */
    int has_progress;
    mc_progress progress;      /* the latest, when has_progress */
    mc_quality quality;        /* how good the map is, once COMPLETED */
} mc_job_status;

typedef struct mc_job_info {   /* one LIST row */
    uint64_t job_id;
    int state;
    int32_t priority;
    int64_t submit_ms;
    char user[256];
    char label[1025];
    uint32_t outer, total;
    mc_quality quality;
    double fraction, eta_s;    /* the latest progress record's; NaN not known */
    uint32_t ahead;            /* PENDING: jobs that start before it */
} mc_job_info;

typedef struct mc_job_result {
    mc_map_row *p; uint32_t np;          /* source -> target, one row per source vertex */
    mc_map_row *q; uint32_t nq;          /* target -> source (bijective) */
    unsigned char *deformed; size_t deformed_len;  /* Draco: the deformed source */
    char **metric_keys; double *metric_values; uint32_t nmetrics;
} mc_job_result;
void mc_result_free(mc_job_result *r);

typedef struct mc_server_stats {
    uint32_t queued, running, workers;
    uint64_t completed, failed, cancelled;
    uint32_t nslots;
    uint64_t *slot_job;                  /* nslots job ids (0 = idle or not yours) */
    int *slot_state;                     /* 0 idle, 1 starting, 2 busy, 3 draining */
    char devices[8][128]; uint32_t ndevices;
    char backend[16];                    /* "local" or "slurm" */
    int backend_ok;                      /* 0: jobs stay PENDING; backend_status says why */
    char backend_status[1024];
} mc_server_stats;
void mc_stats_free(mc_server_stats *s);

/* The address clients use when none is given ($MESHCORR_SERVER first): the
 * socket the shipped meshcorrd.conf and unit (RuntimeDirectory=meshcorr)
 * listen on. */
#define MC_DEFAULT_SERVER "unix:/run/meshcorr/meshcorrd.sock"
/* address: "unix:PATH", "tls:HOST:PORT" or "tcp:HOST:PORT" (HOST a name or
 * numeric address). token: NULL or "" on a Unix socket (the server asks the
 * kernel who you are); the user's token on TCP. Sends HELLO; a refused token
 * is MC_EUNAUTHORIZED. Detail in err.
 * tls: the server's certificate must chain to a CA of $MESHCORR_CA (a PEM
 * file) when set, else of the system's trust store, and must name HOST (a
 * DNS name, or an IP address the certificate lists); TLS 1.2 at least. A
 * certificate that fails, or a server that speaks no TLS, is MC_ETLS. */
int mc_connect(const char *address, const char *token, mc_client **out, char *err, size_t errsz);
/* mc_connect trusting the CAs of ca_file (PEM) for a tls: address instead
 * of $MESHCORR_CA and the system's store (NULL or "": as mc_connect). */
int mc_connect_ca(const char *address, const char *token, const char *ca_file, mc_client **out, char *err,
                  size_t errsz);
void mc_close(mc_client *c);
void mc_set_timeout(mc_client *c, int ms);     /* <= 0: wait forever */
const char *mc_errmsg(const mc_client *c);     /* detail of the last failure; "" after success */
const char *mc_user(const mc_client *c);       /* the user the server took us for */
int mc_is_admin(const mc_client *c);

int mc_submit(mc_client *c, const mc_job_spec *spec, uint64_t *job_id);
int mc_status(mc_client *c, uint64_t job_id, mc_job_status *out);
/* Own jobs (user NULL), another user's (admin), or every user's (user
 * MC_LIST_ALL_USERS, admin); state_mask: bit s = state s, 0 = all. Every
 * page is fetched; *jobs is free()d by the caller. */
#define MC_LIST_ALL_USERS "*"       /* PROTO_LIST_ALL_USERS */
int mc_list(mc_client *c, const char *user, uint32_t state_mask, mc_job_info **jobs, uint32_t *n);
/* Replays progress from outer iteration from_outer, then follows the job
 * live, calling cb (may be NULL) for each record until the job ends; then
 * *end_state is its final state and reason (may be NULL) its reason. A
 * non-zero return of cb stops the watch and is returned; the client is then
 * unusable (the server keeps streaming to it): close it. */
typedef int (*mc_progress_fn)(void *ctx, const mc_progress *p);
int mc_watch(mc_client *c, uint64_t job_id, uint32_t from_outer, mc_progress_fn cb, void *ctx,
             int *end_state, char *reason, size_t reasonsz);
int mc_result(mc_client *c, uint64_t job_id, unsigned what, mc_job_result *out);
/* A stage's maps from before the final ones: for stage "rhm", the
 * reversible harmonic maps that ECTM started from, on a job whose chain
 * ran RHM then ECTM (np = nq = 0 on another job: for a chain ending at
 * RHM, mc_result's maps are RHM's). Rows as in mc_job_result; q only for
 * the bijective model. MC_EARG for another stage name; a server that
 * does not know the request answers MC_EBAD_FRAME. Free with
 * mc_stage_maps_free (accepts a zeroed struct). */
typedef struct mc_stage_maps {
    mc_map_row *p; uint32_t np;          /* the stage's source -> target map */
    mc_map_row *q; uint32_t nq;          /* its target -> source map (bijective) */
} mc_stage_maps;
int mc_result_stage(mc_client *c, uint64_t job_id, const char *stage, mc_stage_maps *out);
void mc_stage_maps_free(mc_stage_maps *m);
int mc_cancel(mc_client *c, uint64_t job_id);
int mc_delete(mc_client *c, uint64_t job_id);
int mc_stats(mc_client *c, mc_server_stats *out);
int mc_ping(mc_client *c);

/* The one call another thread may make on a client while a call on it
 * blocks (mc_watch waiting for progress): shuts the connection down, so
 * that call returns MC_EIO at once. The client is then unusable: close it
 * once that call has returned. NULL ok. */
void mc_interrupt(mc_client *c);

/* Sends raw bytes as they are (testing and tools): one request, and waits
 * for one reply frame of any kind; returns its error code if it is ERROR. */
int mc_send_raw(mc_client *c, const void *bytes, size_t len);

/* A mesh file (.off .obj .ply, or .drc sent as it is) as Draco bytes with
 * the user's vertex order kept (the engine's order-preserving encoder) and
 * every position exactly as read: the server computes on the same doubles
 * as `meshcorr match` does and returns the same map, bit for bit. *bytes is
 * malloc()ed. */
int mc_encode_mesh_file(const char *path, unsigned char **bytes, size_t *len, char *err, size_t errsz);
/* The same from arrays in memory: v is nv by 3 doubles (x y z per vertex),
 * f is nf by 3 0-based vertex indices (counter-clockwise), both read only and
 * still the caller's. The Draco bytes keep vertex i as vertex i (landmark
 * ids and maps refer to it) and every position bit for bit (float32 when
 * all are floats, else float64). *bytes is malloc()ed: free() it once
 * mc_submit has returned. Bad sizes or indices: MC_EARG. */
int mc_encode_mesh(const double *v, int nv, const int *f, int nf, unsigned char **bytes, size_t *len,
                   char *err, size_t errsz);

/* Draco bytes (a result's deformed mesh) as arrays: *v nv by 3 doubles,
 * *f nf by 3 0-based indices, both malloc()ed, free() them. Bytes that do
 * not decode to a triangle mesh: MC_EFILE. */
int mc_decode_mesh(const unsigned char *bytes, size_t len, double **v, int *nv, int **f, int *nf, char *err,
                   size_t errsz);

/* A mesh file (.off .obj .ply .drc, by extension) as arrays, read by the
 * engine's readers as mc_encode_mesh_file reads it (vertex order kept,
 * each polygon face split into triangles where it stands): *v nv by 3
 * doubles, *f nf by 3 0-based indices, both malloc()ed, free() them. A
 * file that cannot be opened or read: MC_EFILE, the file named in err. */
int mc_read_mesh(const char *path, double **v, int *nv, int **f, int *nf, char *err, size_t errsz);

/* Landmark files as an mc_job_spec's landmarks, read by the engine's one
 * reader as `meshcorr match` and `meshcorr submit` read them. With
 * target_path NULL, path is a pairs file (--landmarks: `source_vertex
 * target_vertex` a line); else path and target_path are a source and a
 * target list (--source-landmarks, --target-landmarks: one vertex id a
 * line, or BIM .vts `id x y z` / .pid `id 0 0 0` lines; line k of one goes
 * with line k of the other). Ids are 0-based unless one_based
 * (--one-based). sv is snv by 3 source positions, tv tnv by 3 target
 * positions (mc_read_mesh's arrays; read only): the ids must be vertices of
 * their mesh, no source vertex twice, PROTO_MIN_LANDMARKS to
 * PROTO_MAX_LANDMARKS pairs, and a .vts file's positions must be its
 * vertices'. *landmarks is malloc()ed: *n (source, target) pairs, 2 * *n
 * 0-based ids; free() it. A file that cannot be read: MC_EFILE; one the
 * reader refuses: MC_EBAD_LANDMARKS; both with the file (and the line) in
 * err. Version MESHCORR_1.4. */
int mc_read_landmarks(const char *path, const char *target_path, int one_based, const double *sv, int snv,
                      const double *tv, int tnv, uint32_t **landmarks, uint32_t *n, char *err, size_t errsz);

/* Position coding of the two calls below: MC_QUANTIZATION_LOSSLESS (what
 * the calls above use) or 1..MC_QUANTIZATION_MAX_BITS bits per coordinate
 * over the bounding box. Quantizing trades the server's exact view of the
 * mesh for size: each coordinate moves by up to half a step, about
 * bbox / 2^(bits + 1), and the blob shrinks, but the server then computes on
 * other positions than `meshcorr match` reads and its map differs
 * (docs/decisions.md, "Lossless positions by default"). */
#define MC_QUANTIZATION_LOSSLESS 0
#define MC_QUANTIZATION_MAX_BITS 30
/* mc_encode_mesh_file with quantization_bits; a .drc file is sent as it is
 * whatever quantization_bits says (its author chose its coding). Bits out
 * of range: MC_EARG. */
int mc_encode_mesh_file_quantized(const char *path, int quantization_bits, unsigned char **bytes,
                                  size_t *len, char *err, size_t errsz);
/* mc_encode_mesh with quantization_bits. */
int mc_encode_mesh_quantized(const double *v, int nv, const int *f, int nf, int quantization_bits,
                             unsigned char **bytes, size_t *len, char *err, size_t errsz);

/* In-process jobs: libmeshcorr-engine.so.1 (link -lmeshcorr-engine; it
 * holds the engine, libmeshcorr.so holds none). Runs the job of spec in
 * this process as a meshcorrd worker runs it: the same SUBMIT checks
 * (meshes decoded and validated, landmarks, parameters: the server's codes
 * and messages, MC_EBAD_PARAMS ...), the same engine, and the same answer
 * in out as mc_result gives for that job (the parts `what` names: MC_WANT_*;
 * mc_result_free). threads: OpenMP threads, 0 = by the pair's size as the
 * worker does. cb (may be NULL) gets each progress record as mc_watch
 * delivers it (job_id 0); a non-zero return stops the job: MC_ECANCELLED. Detail of a failure in err. Blocks
 * until the job ends; one job per call, calls from several threads at once
 * share OpenMP's thread count. */
int mc_match(const mc_job_spec *spec, int threads, unsigned what, mc_progress_fn cb, void *ctx,
             mc_job_result *out, char *err, size_t errsz);
/* mc_match, and in *stage (not NULL) RHM's maps that ECTM started from,
 * as mc_result_stage gives them for the same job on a server (np = nq = 0
 * when the chain did not run RHM then ECTM); free with mc_stage_maps_free.
 * libmeshcorr-engine.so.1, version MESHCORR_ENGINE_1.1. */
int mc_match_stages(const mc_job_spec *spec, int threads, unsigned what, mc_progress_fn cb,
                    void *ctx, mc_job_result *out, mc_stage_maps *stage, char *err, size_t errsz);

#ifdef __cplusplus
}
#endif
#endif
