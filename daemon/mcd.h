/* mcd.h — meshcorrd's types and the functions each subsystem exports (one
 * header for the program, as beanstalkd has). Subsystems, one file each:
 *
 *   conf.c   conf_   options from the command line and a `key = value` file
 *   dlog.c   dlog_   leveled log lines on stderr
 *   auth.c   auth_   tokens file (TCP, hashed) and peer credentials (Unix socket)
 *   throttle.c throttle_ failed logins per address: growing waits
 *   fds.c    fds_    the descriptor budget: free, reserved, the TCP floor
 *   token.c  token_  `meshcorrd token new|hash`
 *   store.c  store_  SQLite job rows (WAL) and spool directories: durability
 *   wlock.c  wlock_  a job's worker lock: two workers of one job never run
 *   sched.c  sched_  which pending job runs next (priority, fairness, age)
 *   job.c    job_    a job's life once stored: start, progress, end, pending cancel
 *   backend.c bk_    where jobs run (backend.h): `local` or `slurm`
 *   wsup.c   wsup_   the local backend: worker processes, progress pipe, exit
 *   bk_slurm.c       the slurm backend: sbatch/squeue/scancel, re-attach
 *   bk_prog.c        progress connections from workers on Slurm nodes
 *   bk_cmd.c         external commands run without blocking the loop
 *   srv.c    srv_    libuv loop, listeners, connections, bounded buffers
 *   tls.c    tls_    GnuTLS credentials and one session per tls: connection
 *   req.c    req_    one handler per request type, WATCH fan-out
 *   snap.c   snap_   the status snapshot: STATS and the dashboards read it
 *   dash.c   dash_   listening sockets of the dashboard servers
 *   mbus.c   mbus_   Modbus TCP input registers, in a thread of their own
 *   metrics.c metrics_ Prometheus text over HTTP (libmicrohttpd's thread)
 *   notify.c notify_ sd_notify: READY, STATUS, RELOADING, STOPPING
 *   drain.c  drain_  SIGTERM/SIGINT: the graceful shutdown
 *   reload.c reload_ SIGHUP: options and tokens read again
 *   priv.c   priv_   started as root: bind, then run as --user for good
 *   main.c          main(): wires the above together
 *
 * The DESIGN rule every module keeps: an acknowledged job is never lost.
 * SUBMIT_OK goes out only after the spool file is fsynced and the row is
 * committed; a job leaves the store only by DELETE or result expiry; a
 * running job interrupted by anything but its own end goes back to PENDING.
 *
 * Threads: everything runs in the libuv loop thread except store_submit
 * and the read of a result.frame, which req.c runs in libuv's thread pool
 * (their after callbacks are back on the loop), and the Modbus and metrics
 * servers, which read the published snapshot (snap_read) in their own
 * threads. dlog may be called from any thread. */
#ifndef MCD_H
#define MCD_H
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <uv.h>
#include "proto.h"
#include "spool.h"

/* ---- conf_ ---------------------------------------------------------------- */
#define CONF_MAX_LISTEN 8
#define CONF_PATH 4096
#define CONF_DEFAULT_MAX_QUEUE 1000
#define CONF_DEFAULT_MAX_JOBS_PER_USER 100
#define CONF_DEFAULT_MAX_VERTICES 2000000
#define CONF_DEFAULT_JOB_TIMEOUT_S 86400
#define CONF_DEFAULT_RESULT_TTL_S (7 * 86400)
#define CONF_DEFAULT_MAX_OUTPUT (8u << 20)   /* bytes queued to one slow client */
#define CONF_HELLO_MAX_FRAME 65536           /* frame limit before HELLO succeeds */
#define CONF_KILL_GRACE_S 5                  /* SIGTERM -> SIGKILL */
#define CONF_DEFAULT_SLURM_MAX_JOBS 100
#define CONF_DEFAULT_SLURM_POLL_MS 5000
/* --worker-memory-mb not given: CONF_WORKER_MEMORY_SHARE of the physical
 * memory split between the slots, at least CONF_WORKER_MEMORY_MIN_MB
 * (conf_worker_memory_mb); 0 given: no limit */
#define CONF_WORKER_MEMORY_AUTO 0xFFFFFFFFu
#define CONF_WORKER_MEMORY_SHARE 0.75
#define CONF_WORKER_MEMORY_MIN_MB 1024
/* Connections (srv.c): caps, timeouts, and the descriptors kept free. */
#define CONF_DEFAULT_MAX_CONNECTIONS 512          /* client connections in all */
#define CONF_DEFAULT_MAX_CONNECTIONS_PER_USER 64  /* sessions of one user (admins exempt) */
#define CONF_DEFAULT_MAX_UNAUTHENTICATED 64       /* TCP connections that have not done HELLO */
#define CONF_DEFAULT_MAX_UNAUTH_PER_ADDRESS 8     /* of them from one address (IPv6: one /64) or local uid */
#define CONF_DEFAULT_ADMIN_RESERVE 32             /* descriptors beyond fd-reserve for Unix and admins */
#define CONF_DEFAULT_HELLO_TIMEOUT_S 10           /* accept -> HELLO done */
#define CONF_DEFAULT_REQUEST_TIMEOUT_S 300        /* first byte of a frame -> its last */
#define CONF_DEFAULT_IDLE_TIMEOUT_S 600           /* a session with nothing going on */
#define CONF_DEFAULT_MAX_REQUEST_MEMORY (1u << 30) /* bytes of request frames being received, all clients */
/* Fair limits per user (req.c, srv.c admit): stored bytes, the spool, watches, RESULTs. */
#define CONF_DEFAULT_MAX_BYTES_PER_USER (2ll << 30)  /* spool bytes of one user's jobs and results */
#define CONF_SPOOL_SHARE_PERCENT 80               /* --max-spool-bytes 0: this much of the state file system */
#define CONF_DEFAULT_MAX_WATCHES_PER_SESSION 64   /* live WATCHes of one connection */
#define CONF_DEFAULT_MAX_RESULT_SENDS 16          /* RESULT replies being read or sent, all clients */
#define CONF_DEFAULT_MAX_RESULT_SENDS_PER_USER 4  /* ... of one user */
#define CONF_FD_RESERVE_BASE 32                   /* --fd-reserve 0: this many ... */
#define CONF_FD_RESERVE_PER_SLOT 4                /* ... plus this many per backend slot */

#define CONF_HOST 256
/* A dashboard server's address (--modbus, --metrics); port -1 = off. */
typedef struct conf_endpoint {
    char host[CONF_HOST];         /* as the user gave it; 127.0.0.1 when only a port was */
    int port;
} conf_endpoint;

typedef struct mcd_conf {
    char listen[CONF_MAX_LISTEN][CONF_PATH]; /* "unix:PATH", "tcp:HOST:PORT" or "tls:HOST:PORT" */
    int nlisten;
    char tls_cert[CONF_PATH];     /* PEM certificate chain of tls: listeners and --metrics; "" = none */
    char tls_key[CONF_PATH];      /* its private key */
    int insecure_tcp;             /* a tcp: listener may bind a non-loopback address */
    char state_dir[CONF_PATH];
    char tokens[CONF_PATH];       /* "" = no TCP users */
    char worker[CONF_PATH];       /* "" = meshcorr-worker next to meshcorrd */
    char validator[CONF_PATH];    /* "" = meshcorr-validate next to meshcorrd */
    char port_file[CONF_PATH];    /* "" = none; else bound TCP addresses, one a line */
    int workers;                  /* worker slots (>= 1) */
    int threads_per_worker;       /* 0 = the worker's default */
    uint32_t worker_memory_mb;    /* address-space limit per worker; 0 = none;
                                     CONF_WORKER_MEMORY_AUTO = not given */
    char user[CONF_PATH];         /* --user: run as this user once bound ("" = as started) */
    uint32_t max_frame, max_vertices, max_landmarks;
    uint32_t max_jobs_per_user, max_queue;
    uint32_t job_timeout_s, result_ttl_s;
    uint32_t max_output;          /* output bytes queued per connection */
    uint32_t max_request_memory;  /* bytes of frames being received, all connections */
    uint32_t max_request_memory_per_user; /* ... of one user's connections; 0 = a quarter of the above */
    long max_bytes_per_user;      /* spool bytes of one user's jobs (their rows' bytes summed) */
    long max_spool_bytes;         /* spool bytes of all jobs; 0 = CONF_SPOOL_SHARE_PERCENT of the file system */
    uint32_t max_watches_per_session; /* live WATCHes of one connection */
    uint32_t max_result_sends, max_result_sends_per_user; /* RESULTs read or sent at once */
    uint32_t max_connections, max_connections_per_user, max_unauthenticated;
    uint32_t max_unauth_per_address, admin_reserve;
    uint32_t hello_timeout_s, request_timeout_s, idle_timeout_s;   /* 0 = none */
    uint32_t fd_reserve;          /* descriptors kept free under RLIMIT_NOFILE; 0 = automatic */
    long admin_uid;               /* Unix-socket uid treated as admin; -1 none (root always) */
    int log_level;                /* DLOG_* */
    conf_endpoint modbus;         /* Modbus TCP input registers (MODBUS.md) */
    conf_endpoint metrics;        /* Prometheus text over HTTP, GET /metrics */
    /* where jobs run (backend.h): "local" worker slots or "slurm" */
    char backend[CONF_PATH];
    char slurm_partition[CONF_PATH], slurm_account[CONF_PATH];
    char slurm_time[CONF_PATH];   /* sbatch --time ("" = the partition's default) */
    int slurm_cpus;               /* --cpus-per-task (also the worker's --threads) */
    char slurm_mem[CONF_PATH];    /* --mem, e.g. "4G" ("" = the partition's default) */
    int slurm_max_jobs;           /* meshcorr jobs in Slurm at once */
    char slurm_extra[CONF_PATH];  /* more sbatch arguments, split on blanks */
    char slurm_spool[CONF_PATH];  /* <state-dir>/spool as the nodes see it ("" = same path) */
    char slurm_worker[CONF_PATH]; /* meshcorr-worker on the nodes ("" = --worker's path) */
    char slurm_progress[CONF_PATH];   /* HOST:PORT the progress listener binds */
    char slurm_progress_host[CONF_PATH]; /* host the workers connect to ("" = bind host) */
    uint32_t slurm_poll_ms;       /* squeue/progress-file period */
} mcd_conf;

void conf_init(mcd_conf *c);
/* Applies argv (argv[0] skipped); --config FILE is read where it appears, so
 * later options override it. 0, 1 when --help was given (usage printed), or
 * -1 with the detail in err. */
int conf_parse_args(mcd_conf *c, int argc, char **argv, char *err, size_t errsz);
/* One option by its long name without dashes ("max-queue", "5"). */
int conf_set(mcd_conf *c, const char *key, const char *value, char *err, size_t errsz);
void conf_usage(FILE *fp);
/* The meshcorr-worker program (--worker, or next to meshcorrd) into buf. */
const char *conf_worker_path(const mcd_conf *c, char *buf, size_t sz);
/* The meshcorr-validate program (--validator, or next to meshcorrd). */
const char *conf_validator_path(const mcd_conf *c, char *buf, size_t sz);
/* The worker's --max-faces for the configured --max-vertices. */
unsigned long long conf_max_faces(const mcd_conf *c);
/* The workers' address-space limit in MB, 0 = none: --worker-memory-mb, or
 * when not given CONF_WORKER_MEMORY_SHARE of the physical memory over
 * nslots, at least CONF_WORKER_MEMORY_MIN_MB. */
uint32_t conf_worker_memory_mb(const mcd_conf *c, int nslots);
/* SIGHUP: appends ", name" (or "name" first) to changed when the option
 * differs (a subsystem naming what it applies only at start). */
void conf_note_change(int differs, const char *name, char *changed, size_t sz);
/* A file option's path with a leading ${CREDENTIALS_DIRECTORY} replaced by
 * that variable (systemd's LoadCredential=), into out: 0, or -1 with err
 * naming the option (what) when the variable is unset or the path too long. */
int conf_credential_path(const char *what, const char *path, char *out, size_t sz, char *err, size_t errsz);

/* ---- priv_ ---------------------------------------------------------------- */
/* The --user meshcorrd drops to when started as root (priv.c). */
typedef struct priv_user {
    int active;                   /* 0: not root, nothing to drop */
    uid_t uid;
    gid_t gid;
    char name[256];
} priv_user;
/* Resolves --user; refuses root without it, root as --user, and another
 * user's name when not started as root. 0 or -1 with the reason in err. */
int priv_init(const mcd_conf *c, priv_user *u, char *err, size_t errsz);
/* Makes state_dir USER's (created, or an empty one taken over; a used one
 * of another owner is refused) and USER the effective user, root staying
 * the real one: the store is opened and the backend set up as USER. */
int priv_become(const priv_user *u, const char *state_dir, char *err, size_t errsz);
/* Root effective again, to bind the listeners. */
int priv_bind_begin(const priv_user *u, char *err, size_t errsz);
/* USER for good (groups, gid, uid; root cannot be regained, checked). */
int priv_drop(const priv_user *u, char *err, size_t errsz);
void priv_keep_on_reload(const mcd_conf *o, mcd_conf *n, char *changed, size_t sz);

/* ---- dlog_ ---------------------------------------------------------------- */
enum { DLOG_ERROR, DLOG_WARN, DLOG_INFO, DLOG_DEBUG };
void dlog_set_level(int level);
void dlog(int level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* ---- auth_ ---------------------------------------------------------------- */
#define AUTH_MAX_USER 256
#define AUTH_MAX_LINE 1023            /* bytes of one tokens-file line, newline excluded */
#define AUTH_HASH_LEN 32              /* SHA-256 */
#define AUTH_TOKEN_PREFIX "mc_"       /* the tokens `meshcorrd token new` makes */
#define AUTH_NEW_TOKEN_BYTES 24       /* their randomness (getrandom): 192 bits */
#define AUTH_NEW_TOKEN_LEN (3 + 4 * AUTH_NEW_TOKEN_BYTES / 3)   /* prefix and base64url */
typedef struct auth_tokens auth_tokens;
/* Lines `sha256:HEX user [admin]`; '#' comments. The path may start with
 * ${CREDENTIALS_DIRECTORY}; without one, $CREDENTIALS_DIRECTORY/tokens if it
 * exists, else an empty table. Refuses a file not owned by the daemon's
 * user or root, writable by group or others, readable by others, and any
 * line that is not exactly that form (over AUTH_MAX_LINE, a NUL, a
 * plaintext token, a token twice), naming the file and line. */
int auth_tokens_load(const char *path, auth_tokens **out, char *err, size_t errsz);
void auth_tokens_free(auth_tokens *t);
int auth_tokens_count(const auth_tokens *t);
const char *auth_tokens_path(const auth_tokens *t);   /* the file read, "" none */
/* SHA-256 of a token: 0, or -1. */
int auth_token_hash(const char *token, uint8_t out[AUTH_HASH_LEN]);
void auth_hash_hex(const uint8_t h[AUTH_HASH_LEN], char hex[2 * AUTH_HASH_LEN + 1]);
/* 0 and the user for a known token's hash, -1 otherwise. */
int auth_token_user(const auth_tokens *t, const uint8_t hash[AUTH_HASH_LEN], char user[AUTH_MAX_USER],
                    int *admin);
/* A user name the tokens file may hold: 0, or -1 with why. */
int auth_user_ok(const char *user, char *err, size_t errsz);
/* A new random token (AUTH_TOKEN_PREFIX, AUTH_NEW_TOKEN_BYTES from getrandom). */
int auth_token_new(char tok[AUTH_NEW_TOKEN_LEN + 1], char *err, size_t errsz);
/* The Unix-socket peer's uid from SO_PEERCRED; root and admin_uid are admin. 0 or -1. */
int auth_peer_uid(int fd, long admin_uid, unsigned long *uid, int *admin);
/* The Unix-socket peer's user from SO_PEERCRED; root and admin_uid are admin. */
int auth_peer_user(int fd, long admin_uid, char user[AUTH_MAX_USER], int *admin,
                   char *err, size_t errsz);

/* ---- throttle_: failed logins per address (throttle.c) ---------------------- */
#define THROTTLE_FREE_FAILS 5         /* failed HELLOs an address may make in a row, */
#define THROTTLE_REFILL_S 12          /* one more for every this many quiet seconds; */
#define THROTTLE_BASE_BLOCK_S 2       /* then its HELLOs are refused this long, doubling */
#define THROTTLE_MAX_BLOCK_S 600      /* with each further failure up to this */
#define THROTTLE_LOG_PERIOD_S 10      /* at most one line per address in this time */
#define THROTTLE_MAX_ADDRS 4096       /* addresses followed at once; the quietest go first */
/* Loop thread, now_ms: the loop's clock. 0 when peer may try a token now;
 * else the seconds it must wait (the HELLO is refused unchecked, counted). */
uint32_t throttle_check(const char *peer, uint64_t now_ms);
/* A HELLO from peer failed (why: "unknown token"): counted, and logged
 * with the address at once for the first of a burst, then summed up. */
void throttle_fail(const char *peer, const char *client, const char *why, uint64_t now_ms);
/* Writes the sums of bursts due and forgets addresses gone quiet. */
void throttle_sweep(uint64_t now_ms);

/* ---- fds_: the descriptor budget (fds.c) ------------------------------------ */
/* Descriptors still free under the soft RLIMIT_NOFILE (INT32_MAX when that
 * cannot be told, 0 when none). */
long fds_free(void);
/* Kept for the workers, the database and the spool (--fd-reserve, or 32 +
 * 4 per slot of the backend's nslots). */
long fds_reserve(const mcd_conf *c, int nslots);
/* Below this many free descriptors no TCP client (nor Slurm progress
 * connection) is taken: the reserve plus --admin-reserve, kept for the Unix
 * socket and admin sessions. */
long fds_tcp_floor(const mcd_conf *c, int nslots);

/* ---- store_ --------------------------------------------------------------- */
typedef struct store store;
typedef struct store_job {
    uint64_t id;
    char user[AUTH_MAX_USER];
    char label[PROTO_MAX_STRING + 1];
    char reason[PROTO_MAX_STRING + 1];
    int32_t priority;
    int state;                    /* enum proto_state */
    int64_t submit_ms, start_ms, end_ms;
    uint32_t outer, total;        /* latest outer iteration, planned */
    char slurm_id[32];            /* Slurm job of the current run; "" none */
    int64_t progress_off;         /* bytes of spool/<id>/progress.frames already taken */
    int verdict;                  /* the map's quality (metric_verdict), -1 not known */
    double flipped, collapsed;    /* its fractions of flipped/collapsed faces; NaN not known */
    double fraction, eta_s;       /* latest progress: the whole job's share done, seconds left; NaN not known */
} store_job;
typedef int (*store_job_fn)(void *ctx, const store_job *j);          /* non-zero stops */
typedef int (*store_progress_fn)(void *ctx, const proto_progress *p); /* non-zero stops */

/* Threads: store_submit may run in any thread, several at once, alongside
 * the loop thread's calls (it has a SQLite connection of its own); every
 * other store_ function belongs to the event loop thread. */
int64_t store_now_ms(void);
/* Opens (creating) <dir>/jobs.db and <dir>/spool. */
int store_open(const char *dir, store **out, char *err, size_t errsz);
/* SIGHUP: keeps n's state-dir at the running one o (conf_note_change). */
void store_keep_on_reload(const mcd_conf *o, mcd_conf *n, char *changed, size_t sz);
/* NULL ok; never while a store_submit runs. */
void store_close(store *s);
/* After a restart: every worker a previous daemon left running is killed
 * (found by its job's worker lock, wlock_), an unfinished local job whose
 * worker had written a valid result.frame is COMPLETED with it (adopted, not
 * run again), other RUNNING jobs go back to PENDING, spool dirs without a
 * row are removed, unfinished rows without job.frame become FAILED, and
 * ended jobs that did not complete lose a job.frame left behind.
 * Unfinished jobs with a Slurm job id are left as they are with keep_slurm
 * (the Slurm backend re-attaches), else they go back to PENDING too. */
int store_recover(store *s, int keep_slurm, char *err, size_t errsz);
/* Durable insert: spool/<id>/job.frame (fsynced) and the row, committed
 * together; *id is the committed row's. Any thread (it blocks on the disk:
 * the daemon calls it from libuv's thread pool); frame is only read. */
int store_submit(store *s, const char *user, const char *label, int32_t priority,
                 uint32_t total, const char *params, const void *frame, size_t len,
                 uint64_t *id, char *err, size_t errsz);
int store_get(store *s, uint64_t id, store_job *out);  /* 0, PROTO_ENOT_FOUND, or error */
int store_set_running(store *s, uint64_t id, int64_t start_ms, long pid);
/* PENDING clears the run's times; a terminal state sets end_ms and counts
 * it, and, for any end but COMPLETED, removes job.frame once committed (the
 * row and its reason stay until expiry; such a job has no RESULT). */
int store_set_state(store *s, uint64_t id, int state, const char *reason);
int store_add_progress(store *s, uint64_t id, const proto_progress *p);
/* The Slurm job running it ("" none) and how much of progress.frames is read. */
int store_set_slurm(store *s, uint64_t id, const char *slurm_id, int64_t progress_off);
int store_set_reason(store *s, uint64_t id, const char *reason);
/* The returned map's quality, from its result.frame's metrics. */
int store_set_quality(store *s, uint64_t id, int verdict, double flipped, double collapsed);
/* One more run of job id ended in a worker crash: the count after it. */
int store_add_crash(store *s, uint64_t id, uint32_t *crashes);
/* 1 when spool/<id>/result.frame is a whole, valid RESULT_OK frame of job id
 * (CRCs checked); 0 otherwise, with why in why. Reads the whole file. */
int store_result_ok(store *s, uint64_t id, char *why, size_t wsz);
/* Any thread (reads the file only): spool/<id>/result.frame read and
 * decoded into m, which points into *buf (the caller frees both): 0, or
 * PROTO_EINTERNAL with why (nothing to free). */
int store_result_read(const store *s, uint64_t id, proto_msg *m, uint8_t **buf, char *why, size_t wsz);
/* The quality a decoded RESULT_OK's metrics give (the worker's
 * quality_verdict, flipped_fraction, collapsed_fraction): -1 / NaN when
 * absent. */
void store_result_quality(const proto_msg *m, int *verdict, double *flipped, double *collapsed);
/* Drops a previous run's history and result files before a (re)run. */
int store_clear_run(store *s, uint64_t id);
int store_latest_progress(store *s, uint64_t id, proto_progress *out); /* 0 or NOT_FOUND */
int store_history(store *s, uint64_t id, uint32_t from_outer, store_progress_fn fn, void *ctx);
/* user NULL = every user; jobs with id > after_id in id order, at most max. */
int store_list(store *s, const char *user, uint32_t state_mask, uint64_t after_id,
               uint32_t max, store_job_fn fn, void *ctx);
/* PENDING jobs not handed to Slurm yet. */
int store_each_pending(store *s, store_job_fn fn, void *ctx);
/* PENDING or RUNNING jobs that have a Slurm job id. */
int store_each_slurm(store *s, store_job_fn fn, void *ctx);
/* Terminal jobs that ended before before_ms. */
int store_each_expired(store *s, int64_t before_ms, store_job_fn fn, void *ctx);
int store_delete(store *s, uint64_t id);
/* Bytes the spool holds for user's jobs (NULL: everyone's): the sum of the
 * rows' byte counts, which store_ keeps as each job's counted files
 * (job.frame, result.frame, error.frame, progress files) change: the
 * frame at submit, the run's files at its end or re-run. 0 or error. */
int store_bytes(store *s, const char *user, int64_t *bytes);
void store_counters(store *s, uint64_t *completed, uint64_t *failed, uint64_t *cancelled);
/* <dir>/spool/<id>[/file] into buf. */
const char *store_spool_path(const store *s, uint64_t id, const char *file, char *buf, size_t sz);
int store_is_terminal(int state);

/* ---- wlock_ --------------------------------------------------------------- */
#define WLOCK_HELD 1
#define WLOCK_RECOVER_WAIT_MS 5000    /* recovery: a killed orphan lets go within this */
#define WLOCK_START_WAIT_MS 200       /* a start that finds an orphan: the loop waits at most this */
/* Opens (creating) path and takes its lock: 0 with *fd (close-on-exec)
 * locked, WLOCK_HELD when another process holds it, or -errno. */
int wlock_take(const char *path, int *fd);
/* The worker's pid into the locked file, for people (nothing reads it back). */
void wlock_note_pid(int fd, long pid);
/* SIGKILLs every process that holds path's lock and waits, at most wait_ms,
 * until it is free: the number of processes killed (0: it was free), or -1
 * when it is still held. Blocks the caller for that long. */
int wlock_kill_holders(const char *path, int wait_ms);

/* ---- sched_ --------------------------------------------------------------- */
typedef struct sched sched;
sched *sched_new(void);
void sched_free(sched *s);
int sched_add(sched *s, uint64_t id, const char *user, int32_t priority); /* 0 or -1 nomem */
int sched_remove(sched *s, uint64_t id);   /* a pending job leaves: 0, or -1 not queued */
/* The next job to start (removed from the queue; its user counts one more
 * running job); 0 when the queue is empty. */
uint64_t sched_next(sched *s, char user[AUTH_MAX_USER]);
void sched_done(sched *s, const char *user);        /* one of user's running jobs ended */
uint32_t sched_queued(const sched *s);              /* pending, all users */
/* Jobs that start before pending job id in the order as it stands (the
 * running counts and last starts as they are now); -1 when id is not queued. */
int64_t sched_ahead(const sched *s, uint64_t id);
uint32_t sched_user_pending(const sched *s, const char *user);
uint32_t sched_user_running(const sched *s, const char *user);

/* ---- snap_ ---------------------------------------------------------------- */
/* The daemon's state in figures: the one place they are computed (STATS,
 * the Modbus registers and /metrics all come from snap_collect). */
typedef struct snap_slot {
    uint64_t job_id;              /* 0 = idle */
    uint8_t state;                /* PROTO_SLOT_* */
    uint8_t has_progress;         /* the fields below are set */
    uint8_t stage;                /* PROTO_STAGE_* of the latest progress record */
    uint32_t outer, total;        /* outer iteration, planned */
    double energy;                /* total energy: both directions summed */
    double beta;                  /* mismatch weight */
    uint32_t elapsed_s;           /* wall time since the job started */
    double fraction;              /* the whole job's share done, 0..1; NaN not known */
    double eta_s;                 /* its seconds left; NaN not known */
} snap_slot;

typedef struct mcd_snapshot {
    uint32_t seq;                 /* published snapshots so far (wraps) */
    uint32_t uptime_s;            /* since the daemon started */
    uint32_t queued, running, workers;
    uint64_t completed, failed, cancelled;
    uint32_t nslots;              /* the backend's slots: workers or slurm-max-jobs */
    snap_slot *slots;             /* nslots, owned by whoever allocated the snapshot */
} mcd_snapshot;

typedef struct snap snap;
#define MCD_MAX_DEVICES 16
typedef struct mcd mcd;
#define SNAP_PERIOD_MS 200        /* the published snapshot's refresh */

/* Loop thread: the snapshot state and a timer publishing every SNAP_PERIOD_MS. */
int snap_init(mcd *d, char *err, size_t errsz);
/* Loop thread: the figures now; out->slots holds bk_nslots() entries (the
 * backend's slot count, fixed at start), fewer if out has less room. */
void snap_collect(mcd *d, mcd_snapshot *out);
/* Loop thread: a worker's progress record (kept for its slot's figures). */
void snap_progress(mcd *d, const proto_progress *p);
void snap_close(mcd *d);          /* stops the timer (the loop can end) */
void snap_free(snap *s);          /* after the readers are stopped; NULL ok */
/* Any thread: a copy of the latest published snapshot; out->slots holds
 * snap_nslots() entries. */
void snap_read(snap *s, mcd_snapshot *out);
uint32_t snap_nslots(const snap *s);
mcd_snapshot *snap_alloc(uint32_t nslots);   /* zeroed; NULL on no memory */
void snap_release(mcd_snapshot *m);          /* NULL ok */

/* ---- dash_ ---------------------------------------------------------------- */
/* A listening TCP socket (close-on-exec, non-blocking) on e: the fd, or -1
 * with the detail in err. */
int dash_listen(const conf_endpoint *e, const char *what, char *err, size_t errsz);
/* SIGHUP: keeps n's dashboard endpoints (modbus, metrics) at the running o. */
void dash_keep_on_reload(const mcd_conf *o, mcd_conf *n, char *changed, size_t sz);

/* ---- mbus_ ---------------------------------------------------------------- */
/* MODBUS.md is the register map. 32-bit values: high word first. */
#define MBUS_SLOT_BASE 16         /* slot i's block starts at 16 + 20 i */
#define MBUS_SLOT_STRIDE 20
#define MBUS_MAX_CLIENTS 8        /* more are accepted and closed at once */
#define MBUS_FRAME_TIMEOUT_MS 500 /* a request must arrive whole within this */
#define MBUS_IDLE_TIMEOUT_S 60    /* a connection without a request is closed */
typedef struct mbus mbus;
void mbus_put_u32(uint16_t r[2], uint32_t v);
void mbus_put_f32(uint16_t r[2], float v);
/* Registers for a snapshot: MBUS_SLOT_BASE + MBUS_SLOT_STRIDE * nslots of them. */
size_t mbus_nregs(uint32_t nslots);
void mbus_fill(const mcd_snapshot *s, uint16_t *regs);
/* Binds conf.modbus and starts the server thread; 0, or -1 with err. */
int mbus_start(const conf_endpoint *e, snap *s, mbus **out, char *err, size_t errsz);
void mbus_stop(mbus *m);          /* joins the thread; NULL ok */

/* ---- tls_ ----------------------------------------------------------------- */
/* TLS 1.2 at least, 1.3 preferred; no renegotiation (tls.c). */
#define TLS_PRIORITY "NORMAL:-VERS-ALL:+VERS-TLS1.3:+VERS-TLS1.2"
#define TLS_MAX_FILE (1u << 20)   /* bytes of a --tls-cert or --tls-key file */
#define TLS_MAX_INPUT (1u << 20)  /* ciphertext fed to a session and not yet taken */
typedef struct tls_creds tls_creds;
typedef struct tls_conn tls_conn;
/* Start: checks that every tls: listener has --tls-cert and --tls-key and
 * reads them into d->tls (NULL without them). 0, or -1 with err naming the
 * option and the file. */
int tls_init(mcd *d, char *err, size_t errsz);
/* SIGHUP: the files read again; a pair that loads serves the connections
 * accepted from now on (1), one that does not keeps the running pair and
 * is logged (0, as when TLS is off). */
int tls_reload(mcd *d);
void tls_close(mcd *d);           /* drops d->tls; live sessions keep theirs */
/* SIGHUP: turning TLS on or off and --insecure-tcp wait for the next start. */
void tls_keep_on_reload(const mcd_conf *o, mcd_conf *n, char *changed, size_t sz);
/* The certificate chain and key as PEM text (libmicrohttpd takes them so),
 * owned by t. */
const char *tls_creds_cert_pem(const tls_creds *t);
const char *tls_creds_key_pem(const tls_creds *t);
/* A session's records go out through push(ctx, bytes, len): 0, or -1 when
 * they cannot be queued. */
typedef int (*tls_push_fn)(void *ctx, const void *data, size_t len);
/* A server session on creds (a reference is held until tls_conn_free);
 * peer names the client in log lines. 0 or -1. */
int tls_conn_new(tls_creds *creds, const char *peer, tls_push_fn push, void *ctx, tls_conn **out);
void tls_conn_free(tls_conn *t);  /* NULL ok */
const char *tls_conn_peer(const tls_conn *t);
int tls_conn_ready(const tls_conn *t);    /* 1 once the handshake is done */
/* Ciphertext from the peer, kept until the calls below take it; more than
 * TLS_MAX_INPUT waiting is an error. 0 or -1 with msg. */
int tls_conn_feed(tls_conn *t, const void *data, size_t len, char *msg, size_t msgsz);
/* Runs the handshake on what was fed: 1 done, 0 waiting for the peer, -1
 * failed (the reason in msg; an alert is pushed for the peer). */
int tls_conn_handshake(tls_conn *t, char *msg, size_t msgsz);
/* Appends the plaintext of every whole record fed to out: 0, 1 when the
 * peer closed the session (close_notify), -1 on an error (msg; a
 * renegotiation request is one). */
int tls_conn_read(tls_conn *t, proto_buf *out, char *msg, size_t msgsz);
/* Seals len bytes into records pushed out: 0 or -1 with msg. */
int tls_conn_write(tls_conn *t, const void *data, size_t len, char *msg, size_t msgsz);
/* Pushes close_notify once; 1 when it did, 0 when not (before the
 * handshake, or already sent). */
int tls_conn_bye(tls_conn *t);
/* "TLS1.3 AES-256-GCM" of a ready session into buf. */
const char *tls_conn_desc(const tls_conn *t, char *buf, size_t sz);

/* ---- metrics_ ------------------------------------------------------------- */
typedef struct metrics metrics;
/* Serves HTTPS with tls's certificate and key when tls is not NULL. */
int metrics_start(const conf_endpoint *e, const tls_creds *tls, snap *s, metrics **out, char *err, size_t errsz);
/* SIGHUP: new connections get tls's certificate (the listening socket
 * stays); 0, or -1 with err (the running one goes on). */
int metrics_set_tls(metrics *m, const tls_creds *tls, char *err, size_t errsz);
void metrics_stop(metrics *m);    /* NULL ok */

/* ---- the daemon ------------------------------------------------------------ */
typedef struct conn conn;
typedef struct wsup_slot wsup_slot;
typedef struct req_watch req_watch;
typedef struct req_submit req_submit;
typedef struct bk_ops bk_ops;
/* "Something you wait for may have finished" (a drain's callbacks). */
typedef void (*mcd_idle_fn)(mcd *d);

struct mcd {
    uv_loop_t *loop;
    mcd_conf conf;
    auth_tokens *tokens;
    store *store;
    sched *sched;
    wsup_slot *slots;             /* conf.workers of them */
    conn *conns;                  /* every open connection */
    req_watch *watches;           /* every live WATCH */
    req_submit *submits;          /* SUBMITs being stored in the thread pool */
    uint32_t work_inflight;       /* req_ work items queued and not yet done */
    int drained;                  /* the drain has closed everything */
    uv_handle_t **listeners;
    int nlisteners;
    uv_signal_t sigterm, sigint;
    int draining;                 /* shutdown started: no new work */
    snap *snap;                   /* the status snapshot */
    mbus *mbus;                   /* NULL unless --modbus */
    metrics *metrics;             /* NULL unless --metrics */
    tls_creds *tls;               /* NULL unless --tls-cert and --tls-key */
    const bk_ops *bk;             /* the backend (backend.h) */
    int argc;                     /* the command line, parsed again on SIGHUP */
    char **argv;
    uv_signal_t sighup;
    uv_timer_t notify_timer;      /* STATUS= updates */
    /* compute devices a worker can use (devices.c), for STATS */
    char devices[MCD_MAX_DEVICES][192];
    int ndevices;
};

/* ---- job_: one owner of a job's life (job.c) ----------------------------- */
/* Who hears of a job's progress and end (req.c: the watchers). */
typedef struct job_listener {
    void (*progress)(mcd *d, const proto_progress *p);
    void (*ended)(mcd *d, uint64_t id);     /* its terminal state is in the store */
    void (*queue)(mcd *d);                  /* the queue's order may have changed: a job
                                               started, ended, or left it */
} job_listener;
void job_init(mcd *d);            /* before the backend starts */
void job_listen(mcd *d, const job_listener *l);
void job_close(mcd *d);           /* drained: ends not recorded yet are left to recovery */
/* (Re)starts the result-expiry sweep from d->conf.result_ttl_s: a sweep
 * now, then every minute (or every result-ttl when shorter). */
void job_sweep_start(mcd *d);
/* A backend started job id (pid: its worker's, 0 when not local). */
void job_running(mcd *d, uint64_t id, long pid);
/* Decodes the whole PROGRESS frames at the front of in (a worker's pipe or
 * connection, or a progress file), consumes them, and stores and fans out
 * each as job id's. Returns the number taken, or -1 at a frame that is not
 * a valid PROGRESS (in is then reset; the caller ignores the rest of that
 * stream). */
#define JOB_MAX_PROGRESS_FRAME 4096
int job_progress_take(mcd *d, uint64_t id, proto_buf *in);
/* A run of job id (user's; counted: the scheduler counts it as running)
 * ended in state: terminal, recorded (retried while the store refuses it),
 * then END to the watchers; or PENDING: back to the scheduler. */
void job_ended(mcd *d, uint64_t id, const char *user, int counted, int state, const char *reason);
/* What the run's files say: result.frame is there; the state its
 * error.frame gives (reason "CODE: message"), or -1 without one. */
int job_has_result(mcd *d, uint64_t id);
int job_error_end(mcd *d, uint64_t id, char *reason, size_t rsz);
/* A pending job (not handed to a backend) is cancelled: out of the queue,
 * CANCELLED in the store, END to its watchers. 0 or PROTO_ESTORAGE. */
int job_cancel_pending(mcd *d, uint64_t id);

/* ---- dev_: the devices a worker sees, asked once of the worker program ---- */
/* Runs `meshcorr-worker --list-devices` in the background; until it answers
 * (or if it fails) STATS shows "cpu:N". */
void dev_probe(mcd *d);
/* The device lines into out (at most max); their number. */
int dev_list(const mcd *d, const char **out, int max);

/* ---- notify_ -------------------------------------------------------------- */
void notify_ready(mcd *d);        /* READY=1 and the first STATUS=; starts the timer */
void notify_reloading(void);
void notify_reloaded(void);
void notify_stopping(mcd *d);
void notify_close(mcd *d);        /* stops the STATUS= timer */

/* ---- token_: `meshcorrd token new|hash` (token.c) ------------------------- */
/* argv[0] is "token"; the exit status. */
int token_main(int argc, char **argv);

/* ---- reload_ -------------------------------------------------------------- */
void reload_init(mcd *d, int argc, char **argv);  /* SIGHUP handler */
void reload_close(mcd *d);

/* ---- val_: a SUBMIT checked in a sandboxed child (val.c) ------------------- */
#define VAL_BASE_MEMORY_MB 1024u  /* plus 256 bytes per allowed vertex of both meshes */
#define VAL_MAX_CPU_S      30u    /* CPU seconds for decoding and checking a pair */
typedef struct val_conf {         /* a copy taken on the loop, for the thread pool */
    char validator[CONF_PATH + 64];
    unsigned max_vertices;
    unsigned long long max_faces;
    unsigned max_memory_mb, max_cpu_s;
    unsigned worker_memory_mb;    /* the worker's limit: a job estimated over it is refused; 0 none */
} val_conf;
void val_conf_of(const mcd *d, val_conf *vc);
/* Runs meshcorr-validate on the SUBMIT frame[len] and waits for
 * it (thread-pool side; blocks its thread only). 0 when the job can run;
 * else the code (BAD_MESH, BAD_LANDMARKS, BAD_PARAMS, ...) with the message
 * naming the blob or field in msg; PROTO_EINTERNAL when the check itself
 * could not run. *ms and *cpu_ms (may be NULL): the wall time it took and
 * the child's CPU time. */
int val_submit(const val_conf *vc, const void *frame, size_t len, double *ms, double *cpu_ms, char *msg,
               size_t msz);

/* ---- srv_ ----------------------------------------------------------------- */
int srv_listen(mcd *d, char *err, size_t errsz);
void srv_stop_listening(mcd *d);
void srv_close_all(mcd *d);
/* SIGHUP: keeps n's listeners and port file at the running o. */
void srv_keep_on_reload(const mcd_conf *o, mcd_conf *n, char *changed, size_t sz);
/* Queues one encoded message; a connection over conf.max_output is paused
 * (replies) or, with drop_if_full (WATCH frames), dropped. 0 or -1 dropped. */
int srv_send(conn *c, const proto_msg *m, int drop_if_full);
/* ERROR frame; close_after: close once it is written. */
void srv_send_error(conn *c, uint32_t request_id, int code, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* Stops reading and closes once the queued output is written. */
void srv_close_soon(conn *c);

/* What req_ needs to know about a connection. */
#define SRV_MAX_PEER 64
typedef struct conn_auth {
    int authed, admin, is_unix;
    char user[AUTH_MAX_USER];
    char peer[SRV_MAX_PEER];      /* who connects, for logs and the per-address caps: "127.0.0.1",
                                   * "2001:db8:1:2::/64" (IPv6 by /64), "uid 1000" (Unix socket) */
    int by_token;                 /* logged in with a token: its hash follows (SIGHUP checks it) */
    uint8_t token_hash[AUTH_HASH_LEN];
} conn_auth;
conn_auth *srv_conn_auth(conn *c);
mcd *srv_conn_daemon(conn *c);
int srv_conn_fd(conn *c);
/* The request being handled goes on in the thread pool: c stops being read,
 * the frame given to req_handle stays valid, and c's memory stays valid
 * (even if it closes) until the matching srv_conn_release, which consumes
 * that frame and handles whatever the client sent meanwhile. Loop thread. */
void srv_conn_hold(conn *c);
void srv_conn_release(conn *c);
int srv_conn_open(const conn *c);     /* not closed or closing: replies can go out */
/* HELLO, once the user is known and before HELLO_OK: 0 when the session
 * may go on, else PROTO_EBUSY with the reason in msg (logged here): non-admin
 * sessions are at --max-connections, or the user already has
 * --max-connections-per-user (admins are never refused either way). */
int srv_conn_admit_user(conn *c, char *msg, size_t msgsz);
/* fn(c, ctx) for every open session (after HELLO); fn may end it. */
void srv_each_session(mcd *d, void (*fn)(conn *c, void *ctx), void *ctx);
/* Ends a session from the server's side: ERROR code (request id 0) with
 * why, a warning naming the connection and user, and a close. */
void srv_end_session(conn *c, int code, const char *why);
/* With a TCP listener and no token, a warning: no TCP user can log in. */
void srv_note_tokens(mcd *d);
/* Closed, or the client has hung up (EOF or an error waits on the socket). */
int srv_conn_hung_up(conn *c);

/* ---- drain_: the graceful shutdown (drain.c) ------------------------------ */
void drain_start(mcd *d, int sig);    /* SIGTERM/SIGINT: stop accepting, hand the runs back */

/* ---- req_ ----------------------------------------------------------------- */
/* Handles one decoded request; frame/len are its raw bytes (SUBMIT spools them). */
void req_handle(conn *c, const proto_msg *m, const void *frame, size_t len);
void req_init(mcd *d);                                /* listens to job.c for the watchers */
/* A drain: idle(d) is called each time one of the requests in the thread
 * pool (d->work_inflight) finishes from now on. */
void req_quiesce(mcd *d, mcd_idle_fn idle);
void req_conn_closed(mcd *d, conn *c);                /* forget its watches and RESULTs */
void req_conn_sent(mcd *d, conn *c);                  /* c's output is written whole: its RESULTs end */
int req_conn_watching(const mcd *d, const conn *c);   /* 1: a WATCH of c is live */

#endif
