/* proto.h — the meshcorr wire protocol: limits, error codes, message types
 * and the pure codec (frames and messages). No I/O, no global state; the
 * spec is protocol/PROTOCOL.md and repeats every limit named here.
 *
 * Ownership. Encoders append whole frames to a caller-owned proto_buf
 * (proto_buf_init / proto_buf_free); they only read the message they are
 * given. A message filled by proto_msg_decode borrows from the payload it was
 * decoded from and owns the rest: blobs (proto_blob: Draco mesh bytes) and
 * strings (const char *, always non-NULL and NUL-terminated after decoding,
 * because the wire carries the terminator) point INTO the payload buffer,
 * which must outlive the message and stay unmodified; every array (landmarks,
 * map rows, job summaries, metrics, worker slots, device name pointers) is
 * allocated by the decoder and released by proto_msg_free, which accepts NULL
 * and zeroed messages and leaves the message zeroed. Call proto_msg_free only
 * on decoded messages; messages you build for encoding stay yours.
 *
 * Errors are negative PROTO_E* codes (the same numbers travel in ERROR
 * frames); detail such as "landmark count 70000 over PROTO_MAX_LANDMARKS
 * (65536)" goes into the caller's err buffer. Every size from the wire is
 * checked against its limit and against the bytes left before anything is
 * allocated. */
#ifndef PROTO_H
#define PROTO_H
#include <stddef.h>
#include <stdint.h>
#include "proto_params.h"

/* ---- framing ------------------------------------------------------------ */
#define PROTO_MAGIC      0x5052434Du  /* bytes "MCRP" on the wire */
#define PROTO_VERSION    6
#define PROTO_HDR_SIZE   20

/* ---- limits (PROTOCOL.md repeats each one) ------------------------------ */
#define PROTO_MAX_FRAME         (1u << 30)   /* hard cap, header included */
#define PROTO_DEFAULT_MAX_FRAME (256u << 20) /* daemon default, <= hard cap */
#define PROTO_MAX_MESH_BYTES    (256u << 20) /* one Draco blob */
#define PROTO_MAX_MAP_ROWS      (1u << 24)   /* rows of P or Q */
/* PROTO_MAX_LANDMARKS (landmark pairs) is in proto_params.h */
#define PROTO_MAX_STRING        1024u        /* bytes, terminator excluded */
#define PROTO_MAX_LIST          4096u        /* job summaries in LIST_OK */
#define PROTO_MAX_METRICS       256u         /* key/value pairs in RESULT_OK */
#define PROTO_MAX_SLOTS         1024u        /* worker slots in STATS_OK */
#define PROTO_MAX_DEVICES       64u          /* device names in STATS_OK */

/* ---- errors: one list, the same codes in C and on the wire ------------- */
#define PROTO_ERRORS(X)                                                              \
    X(PROTO_OK,             0, "OK",            "ok")                                 \
    X(PROTO_EBAD_FRAME,    -1, "BAD_FRAME",     "malformed frame or field value")     \
    X(PROTO_EBAD_MAGIC,    -2, "BAD_MAGIC",     "not a meshcorr frame (bad magic)")   \
    X(PROTO_EBAD_VERSION,  -3, "BAD_VERSION",   "unsupported protocol version")       \
    X(PROTO_EBAD_TYPE,     -4, "BAD_TYPE",      "unknown message type")               \
    X(PROTO_ETOO_LARGE,    -5, "TOO_LARGE",     "frame larger than the allowed maximum") \
    X(PROTO_ETRUNCATED,    -6, "TRUNCATED",     "payload ends inside a field")        \
    X(PROTO_ETRAILING,     -7, "TRAILING",      "bytes left after the message")       \
    X(PROTO_EOVER_LIMIT,   -8, "OVER_LIMIT",    "a count or length is over its limit") \
    X(PROTO_EBAD_CHECKSUM, -9, "BAD_CHECKSUM",  "checksum mismatch")                  \
    X(PROTO_EBAD_STRING,  -10, "BAD_STRING",    "string not UTF-8, has NUL, or lacks its terminator") \
    X(PROTO_ENOMEM,       -11, "NOMEM",         "out of memory")                      \
    X(PROTO_EUNEXPECTED,  -12, "UNEXPECTED",    "message not valid here")             \
    X(PROTO_EUNAUTHORIZED,-13, "UNAUTHORIZED",  "authentication missing or failed")   \
    X(PROTO_EFORBIDDEN,   -14, "FORBIDDEN",     "not allowed for this user")          \
    X(PROTO_ENOT_FOUND,   -15, "NOT_FOUND",     "no such job")                        \
    X(PROTO_EBAD_STATE,   -16, "BAD_STATE",     "job is not in a state that allows this") \
    X(PROTO_EQUEUE_FULL,  -17, "QUEUE_FULL",    "queue full, job refused")            \
    X(PROTO_EUSER_LIMIT,  -18, "USER_LIMIT",    "per-user job limit reached")         \
    X(PROTO_EBAD_MESH,    -19, "BAD_MESH",      "mesh does not decode or is invalid") \
    X(PROTO_EBAD_LANDMARKS,-20,"BAD_LANDMARKS", "landmarks out of range or duplicated") \
    X(PROTO_EBAD_PARAMS,  -21, "BAD_PARAMS",    "parameter out of range")             \
    X(PROTO_ESTORAGE,     -22, "STORAGE",       "job could not be stored durably")    \
    X(PROTO_EINTERNAL,    -23, "INTERNAL",      "internal server error")              \
    X(PROTO_ESHUTTING_DOWN,-24,"SHUTTING_DOWN", "server shutting down")              \
    X(PROTO_ECANCELLED,   -25, "CANCELLED",     "job cancelled")                      \
    X(PROTO_EBUSY,        -26, "BUSY",          "server at a connection limit; retry later") \
    X(PROTO_ETIMED_OUT,   -27, "TIMED_OUT",     "connection idle, or a request too slow, past its timeout") \
    X(PROTO_EOVER_QUOTA,  -28, "OVER_QUOTA",    "the user's stored bytes, or the spool's, would pass its quota") \
    X(PROTO_EBAD_MAP,     -29, "BAD_MAP",       "initial map does not fit the meshes") \
    X(PROTO_ENUMERIC,     -30, "NUMERIC",       "a stage of the job failed numerically")

enum proto_error {
#define PROTO_ENUM(sym, val, name, msg) sym = val,
    PROTO_ERRORS(PROTO_ENUM)
#undef PROTO_ENUM
};
const char *proto_strerror(int code);  /* "checksum mismatch"; unknown -> "unknown error" */
const char *proto_err_name(int code);  /* "BAD_CHECKSUM"; unknown -> "UNKNOWN" */
/* The code named name ("NUMERIC"); 0 for a name that is none of the list's. */
int proto_err_code(const char *name);
/* How a job fails: the kinds, each with its code above (proto_kind.h). */
#include "proto_kind.h"

/* ---- enumerations carried on the wire (u8) ------------------------------ */
#define PROTO_TYPES(X)                                                        \
    X(HELLO, 1) X(HELLO_OK, 2) X(SUBMIT, 3) X(SUBMIT_OK, 4) X(STATUS, 5)      \
    X(STATUS_OK, 6) X(LIST, 7) X(LIST_OK, 8) X(WATCH, 9) X(PROGRESS, 10)      \
    X(END, 11) X(CANCEL, 12) X(OK, 13) X(RESULT, 14) X(RESULT_OK, 15)         \
    X(DELETE, 16) X(STATS, 17) X(STATS_OK, 18) X(PING, 19) X(PONG, 20)        \
    X(ERROR, 21)
enum proto_type {
#define PROTO_ENUM(name, val) PROTO_MSG_##name = val,
    PROTO_TYPES(PROTO_ENUM)
#undef PROTO_ENUM
    PROTO_MSG_LAST = 21
};

/* Job states use Slurm's names. */
#define PROTO_STATES(X)                                                       \
    X(PENDING, 0) X(RUNNING, 1) X(COMPLETED, 2) X(FAILED, 3)                  \
    X(CANCELLED, 4) X(TIMEOUT, 5) X(OUT_OF_MEMORY, 6)
enum proto_state {
#define PROTO_ENUM(name, val) PROTO_STATE_##name = val,
    PROTO_STATES(PROTO_ENUM)
#undef PROTO_ENUM
    PROTO_STATE_LAST = 6
};

/* The stages a progress record names, the one list the engine's corr_stage
 * (workers/corr/corr.h), the wire, the CLI and the Python package's STAGES
 * come from. INIT is not sent from version 5 on (a job's first record is a
 * real one); QUEUED is the daemon's record of a pending job (its place in
 * the queue), never stored nor made by the engine. */
#define PROTO_STAGES(X) X(START, 0) X(RHM, 1) X(ECTM, 2) X(INIT, 3) X(DDM, 4) X(REPAIR, 5) X(QUEUED, 6)
enum proto_stage {
#define PROTO_ENUM(name, val) PROTO_STAGE_##name = val,
    PROTO_STAGES(PROTO_ENUM)
#undef PROTO_ENUM
    PROTO_STAGE_LAST = 6
};

#define PROTO_SLOTS(X) X(IDLE, 0) X(STARTING, 1) X(BUSY, 2) X(DRAINING, 3)
enum proto_slot_state {
#define PROTO_ENUM(name, val) PROTO_SLOT_##name = val,
    PROTO_SLOTS(PROTO_ENUM)
#undef PROTO_ENUM
    PROTO_SLOT_LAST = 3
};

/* values of the ENUM parameters model, start, stages and ddm_mode (their names: proto_params.h) */
enum proto_model { PROTO_MODEL_BIJECTIVE = 0, PROTO_MODEL_INJECTIVE = 1 };
/* RHM's start map from the landmarks (workers/start/start.h) */
enum proto_start { PROTO_START_DISTANCES = 0, PROTO_START_VORONOI = 1, PROTO_START_FMAP = 2 };
/* The chains of stages a job can run: the values of the ENUM parameter
 * stages, named as PROTO_PARAMS lists them ("ddm,ectm"); the engine's
 * corr_chain (workers/corr/corr.h) is this list. */
#define PROTO_CHAINS(X) X(ALL, 0) X(RHM, 1) X(ECTM, 2) X(DDM, 3) X(DDM_ECTM, 4) X(DDM_RHM, 5) \
    X(DDM_RHM_ECTM, 6) X(RHM_ECTM, 7)
enum proto_chain {
#define PROTO_ENUM(name, val) PROTO_CHAIN_##name = val,
    PROTO_CHAINS(PROTO_ENUM)
#undef PROTO_ENUM
    PROTO_CHAIN_LAST = 7
};
/* DDM denoising of the given maps (workers/ddm/ddm.h) */
enum proto_ddm_mode { PROTO_DDM_PLAIN = 0, PROTO_DDM_BIJECTIVE = 1, PROTO_DDM_AUTO = 2 };

/* Energy terms reported per direction in PROGRESS (index into terms[d][]). */
enum proto_term {
    PROTO_TERM_MEMBRANE, PROTO_TERM_BENDING, PROTO_TERM_MISMATCH,
    PROTO_TERM_REVERSE, PROTO_TERM_ENERGY, PROTO_NTERMS
};

/* RESULT's `what` bits. */
#define PROTO_WANT_P        1u
#define PROTO_WANT_Q        2u
#define PROTO_WANT_DEFORMED 4u
#define PROTO_WANT_METRICS  8u
/* RHM's maps P and Q that ECTM started from (a chain RHM then ECTM): at
 * RESULT_OK's end, only when asked, so a peer that never asks reads
 * RESULT_OK as before */
#define PROTO_WANT_STAGE_RHM 16u
#define PROTO_WANT_ALL      31u

/* Names for logs and the CLI; NULL for a value outside the list. */
const char *proto_type_name(int type);    /* "SUBMIT" */
const char *proto_state_name(int state);  /* "OUT_OF_MEMORY" */
const char *proto_stage_name(int stage);  /* "rhm"; "queued" */
const char *proto_slot_name(int slot);    /* "busy" */

/* ---- CRC32C (Castagnoli, reflected 0x82F63B78) -------------------------- */
/* Continues `crc` (start with 0) over n bytes; proto_crc32c(0,"123456789",9)
 * is 0xE3069283. */
uint32_t proto_crc32c(uint32_t crc, const void *data, size_t n);

/* ---- growable output buffer --------------------------------------------- */
typedef struct proto_buf {
    uint8_t *data;
    size_t len;   /* bytes written */
    size_t cap;   /* bytes allocated */
    int err;      /* first error (PROTO_ENOMEM), sticky; 0 while fine */
} proto_buf;

void proto_buf_init(proto_buf *b);
void proto_buf_free(proto_buf *b);          /* NULL ok; leaves b initialised */
void proto_buf_reset(proto_buf *b);         /* len = 0, err = 0, keeps memory */
/* Removes the first n bytes (a sent or consumed frame). */
void proto_buf_consume(proto_buf *b, size_t n);
/* Little-endian appends; on failure they set b->err and append nothing. */
void proto_buf_put(proto_buf *b, const void *p, size_t n);
void proto_buf_put_u8(proto_buf *b, uint8_t v);
void proto_buf_put_u16(proto_buf *b, uint16_t v);
void proto_buf_put_u32(proto_buf *b, uint32_t v);
void proto_buf_put_u64(proto_buf *b, uint64_t v);
/* Little-endian loads from at least 2/4/8 readable bytes. */
uint16_t proto_le16(const uint8_t *p);
uint32_t proto_le32(const uint8_t *p);
uint64_t proto_le64(const uint8_t *p);
void proto_set_le32(uint8_t *p, uint32_t v);

/* ---- frame header ------------------------------------------------------- */
/* Wire layout (20 bytes, little-endian):
 *   0 u32 magic  4 u8 version  5 u8 type  6 u16 flags (0)  8 u32 request id
 *  12 u32 payload length  16 u32 CRC32C of bytes 0..15 */
typedef struct proto_hdr {
    uint8_t version;
    uint8_t type;
    uint16_t flags;
    uint32_t request_id;  /* chosen by the client, echoed in every reply */
    uint32_t payload_len;
} proto_hdr;

#define PROTO_READY     0  /* a whole frame is in the buffer */
#define PROTO_NEED_MORE 1  /* not yet: read more bytes and call again */

/* Looks at the start of buf[0..len). Returns PROTO_READY (hdr filled; the
 * frame is PROTO_HDR_SIZE + hdr->payload_len bytes), PROTO_NEED_MORE (hdr
 * filled once the 20 header bytes are there, so the caller may size its
 * buffer), or a negative error: BAD_MAGIC (checked on the first bytes as
 * they arrive), BAD_CHECKSUM, BAD_VERSION, BAD_TYPE, BAD_FRAME (flags),
 * TOO_LARGE (frame over max_frame, or over PROTO_MAX_FRAME whatever
 * max_frame says; 0 means PROTO_MAX_FRAME). Never allocates. */
int proto_frame_scan(const void *buf, size_t len, size_t max_frame,
                     proto_hdr *hdr, char *err, size_t errsz);
/* Writes the 20 header bytes (version and magic included, CRC computed). */
void proto_frame_put_header(uint8_t out[PROTO_HDR_SIZE], const proto_hdr *hdr);

/* ---- messages ----------------------------------------------------------- */
typedef struct proto_blob {           /* Draco bytes; len 0 = absent */
    const uint8_t *data;
    uint32_t len;
} proto_blob;

typedef struct proto_landmark { uint32_t src, tgt; } proto_landmark;  /* vertex ids */

typedef struct proto_map_row {        /* a point on a face of the other mesh */
    uint32_t face;
    double w[3];                      /* barycentric weights */
} proto_map_row;

typedef struct proto_map {            /* one row per vertex; n 0 = absent */
    proto_map_row *rows;
    uint32_t n;
} proto_map;

typedef struct proto_limits {         /* what the server enforces */
    uint32_t max_frame, max_vertices, max_landmarks;
    uint32_t max_jobs_per_user, max_queue, max_wall_s;
} proto_limits;

/* A job's parameters: one member per PROTO_PARAMS row (proto_params.h), in
 * wire order. Decoded strings point into the payload (see above). */
#define PROTO_PARAM_CTYPE_ENUM uint8_t
#define PROTO_PARAM_CTYPE_BOOL uint8_t
#define PROTO_PARAM_CTYPE_U32  uint32_t
#define PROTO_PARAM_CTYPE_F64  double
#define PROTO_PARAM_CTYPE_STR  const char *
typedef struct proto_params {
#define PROTO_PARAM_MEMBER(name, cli, type, ...) PROTO_PARAM_CTYPE_##type name;
    PROTO_PARAMS(PROTO_PARAM_MEMBER)
#undef PROTO_PARAM_MEMBER
} proto_params;

/* Row indices: PROTO_P_alpha, ...; PROTO_NPARAMS rows. */
enum proto_param_index {
#define PROTO_PARAM_INDEX(name, ...) PROTO_P_##name,
    PROTO_PARAMS(PROTO_PARAM_INDEX)
#undef PROTO_PARAM_INDEX
    PROTO_NPARAMS
};
enum proto_param_type {
    PROTO_PARAM_ENUM, PROTO_PARAM_BOOL, PROTO_PARAM_U32, PROTO_PARAM_F64, PROTO_PARAM_STR
};
/* One row of the list as data, for code that walks it (codec, CLI, help,
 * the PROTOCOL.md table). */
typedef struct proto_param_info {
    const char *name, *cli;
    int type;                         /* enum proto_param_type */
    double dflt, min, max;
    unsigned flags;                   /* PROTO_PARAM_* */
    const char *values, *help;
    size_t offset;                    /* of the member in proto_params */
} proto_param_info;
extern const proto_param_info proto_param_infos[PROTO_NPARAMS];

/* Every member its default (backend ""). */
void proto_params_init(proto_params *p);
/* How a message names a parameter: as the wire, the C API and Python do
 * ("inner_iterations = 500000"), or as the CLI's option
 * ("--inner-iterations 500000"). */
enum proto_param_naming { PROTO_NAME_WIRE, PROTO_NAME_CLI };
/* THE validator: every field in its range (0 allowed where 0 means the
 * default), enumerations among their values, backend "" or cpu|opencl|auto
 * with an optional ":DEVICE" of at most PROTO_MAX_DEVICE bytes. 0, or
 * PROTO_EBAD_PARAMS with the field by its wire name and its whole range in
 * err: "inner_iterations = 500000: out of range [1, 100000]". */
int proto_params_check(const proto_params *p, char *err, size_t errsz);
/* The same naming the field as `naming` says (the CLI: "--iterations 0:
 * out of range [1, 1000000]"). */
int proto_params_check_as(const proto_params *p, int naming, char *err, size_t errsz);
/* The range rule of row i for one numeric value v (no 0-means-default
 * rule): 0 or PROTO_EBAD_PARAMS with "NAME = V: ..." (wire name) in err.
 * The engine checks its own copies of the fields with it. */
int proto_param_check(int i, double v, char *err, size_t errsz);
/* Numeric member i as a double (STR: 0). */
double proto_param_get(const proto_params *p, int i);
/* Sets member i from text (a number, a value name of an ENUM, "0"/"1" for
 * BOOL; STR keeps the pointer: text must outlive p). Only parses: ranges
 * are proto_params_check's. 0, or PROTO_EBAD_PARAMS with "'x' is not ..."
 * (an integer row names its whole range: "'-1' is not an integer in [1,
 * 1000000]"). */
int proto_param_parse(proto_params *p, int i, const char *text, char *err, size_t errsz);
/* Name of value v of ENUM row i ("injective"); NULL if none. */
const char *proto_param_value_name(int i, unsigned v, char *buf, size_t sz);
/* The range of row i as PROTOCOL.md writes it: "[1, 100000]", "(0, inf)",
 * "0 `bijective`, 1 `injective`" (enumerations); returns buf. */
const char *proto_param_range(int i, char *buf, size_t sz);
/* "model=bijective partial=0 alpha=20 ... backend=" into buf; returns buf. */
char *proto_params_format(const proto_params *p, char *buf, size_t sz);
/* The parameter table of PROTOCOL.md (markdown, one row per field, wire
 * order) into buf; returns the length it needs (as snprintf). */
size_t proto_params_table(char *buf, size_t sz);

typedef struct proto_progress {
    uint64_t job_id;
    uint8_t stage;                    /* enum proto_stage */
    uint32_t outer, total;            /* the stage's iteration, planned total */
    uint32_t inner[2];                /* inner iterations: [0] forward, [1] reverse */
    double terms[2][PROTO_NTERMS];    /* per direction, enum proto_term */
    double beta, gamma, elapsed_s;
    double fraction;                  /* of the whole job done, [0, 1]; NaN not known */
    double eta_s;                     /* seconds left, >= 0; NaN not known */
    uint32_t ahead;                   /* stage QUEUED: jobs that start before it; else 0 */
} proto_progress;

/* How good a COMPLETED job's map is (the worker's metrics, RESULT_OK):
 * verdict 0 ok, 1 folded, 2 orientation reversed, -1 not known (not
 * completed, or a result without them); the fractions NaN when not known. */
typedef struct proto_quality { int32_t verdict; double flipped, collapsed; } proto_quality;
typedef struct proto_job_summary {
    uint64_t job_id;
    uint8_t state;
    int32_t priority;
    int64_t submit_ms;                /* Unix time in milliseconds */
    const char *user, *label;
    uint32_t outer, total;
    proto_quality quality;
    double fraction, eta_s;           /* the latest record's (proto_progress); NaN not known */
    uint32_t ahead;                   /* PENDING: jobs that start before it; else 0 */
} proto_job_summary;

typedef struct proto_metric { const char *key; double value; } proto_metric;
typedef struct proto_slot { uint64_t job_id; uint8_t state; } proto_slot;  /* job 0 = none */

typedef struct proto_hello { uint16_t version; const char *token, *client; } proto_hello;
typedef struct proto_hello_ok {
    uint16_t version; const char *user; uint8_t admin; proto_limits limits;
} proto_hello_ok;
typedef struct proto_submit {
    proto_blob source, target;
    proto_landmark *landmarks; uint32_t nlandmarks;
    proto_map p, q;                   /* optional initial maps */
    proto_params params;
    int32_t priority;                 /* higher runs first */
    const char *label;
} proto_submit;
/* SUBMIT_OK, STATUS, CANCEL, DELETE and OK carry only a job id. */
typedef struct proto_job_ref { uint64_t job_id; } proto_job_ref;
typedef struct proto_status_ok {
    uint64_t job_id; uint8_t state; int32_t priority;
    const char *user, *label, *reason;
    int64_t submit_ms, start_ms, end_ms;  /* 0 = not yet */
    uint8_t has_progress; proto_progress progress;
    proto_quality quality;
} proto_status_ok;
#define PROTO_LIST_ALL_USERS "*"       /* LIST's user for every user's jobs (admin only) */
typedef struct proto_list {
    uint32_t state_mask;              /* bit s = state s; 0 = every state */
    const char *user;                 /* "" = me; another user or "*" (all): admin only */
    uint32_t max_count;               /* 0 = server's page size */
    uint64_t after_id;                /* ids greater than this (paging) */
} proto_list;
typedef struct proto_list_ok { proto_job_summary *jobs; uint32_t n; } proto_list_ok;
typedef struct proto_watch { uint64_t job_id; uint32_t from_outer; } proto_watch;
typedef struct proto_end { uint64_t job_id; uint8_t state; const char *reason; } proto_end;
typedef struct proto_result { uint64_t job_id; uint32_t what; } proto_result;  /* PROTO_WANT_* */
typedef struct proto_result_ok {
    uint64_t job_id;
    proto_map p, q;                   /* q absent for the injective model */
    proto_blob deformed;              /* Draco; absent unless asked */
    proto_metric *metrics; uint32_t nmetrics;
    proto_map rhm_p, rhm_q;           /* RHM's maps (PROTO_WANT_STAGE_RHM): on the
                                       * wire only when either has rows */
} proto_result_ok;
typedef struct proto_stats_ok {
    uint32_t queued, running, workers;
    uint64_t completed, failed, cancelled;
    proto_slot *slots; uint32_t nslots;
    const char **devices; uint32_t ndevices;
    const char *backend;              /* "local", "slurm" */
    uint8_t backend_ok;               /* 1 jobs can start; 0 see backend_status */
    const char *backend_status;       /* e.g. "sbatch not found in PATH" */
} proto_stats_ok;
typedef struct proto_error_msg { int32_t code; const char *message; } proto_error_msg;

typedef struct proto_msg {
    uint8_t type;                     /* enum proto_type */
    uint32_t request_id;
    union {
        proto_hello hello;       proto_hello_ok hello_ok;
        proto_submit submit;     proto_job_ref submit_ok;
        proto_job_ref status;    proto_status_ok status_ok;
        proto_list list;         proto_list_ok list_ok;
        proto_watch watch;       proto_progress progress;
        proto_end end;           proto_job_ref cancel;
        proto_job_ref ok;        proto_result result;
        proto_result_ok result_ok; proto_job_ref del;
        proto_stats_ok stats_ok; proto_error_msg error;
    } u;                              /* STATS, PING, PONG have no payload */
} proto_msg;

/* Appends one whole frame (header + payload) for m to b. Refuses what a
 * decoder would refuse (limits, bad strings, enum values) with the same
 * codes, leaving b as it was. */
int proto_msg_encode(proto_buf *b, const proto_msg *m, char *err, size_t errsz);

/* Decodes the payload of a frame whose header scanned as hdr (payload holds
 * hdr->payload_len bytes). On error m is left zeroed. */
int proto_msg_decode(const proto_hdr *hdr, const void *payload, proto_msg *m,
                     char *err, size_t errsz);

/* proto_frame_scan + proto_msg_decode on the start of buf: returns
 * PROTO_READY with *used = frame length, PROTO_NEED_MORE, or an error;
 * m is zeroed unless PROTO_READY. */
int proto_decode(const void *buf, size_t len, size_t max_frame, proto_msg *m,
                 size_t *used, char *err, size_t errsz);

void proto_msg_free(proto_msg *m);

#endif
