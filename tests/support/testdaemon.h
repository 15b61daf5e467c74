/* testdaemon.h — the real build/meshcorrd for black-box tests: started with
 * its own state directory under harness_tmpdir(), a Unix socket and a TCP
 * listener on 127.0.0.1 (a free port the daemon picks and writes to its
 * port file; a test may add a tls: listener, tests/support/testtls.h), and
 * a tokens file (hashed, mode 0600) with three users:
 *   TESTDAEMON_ALICE (user alice), TESTDAEMON_BOB (user bob),
 *   TESTDAEMON_ADMIN (user boss, admin).
 * The daemon dies with the test process (PR_SET_PDEATHSIG). Jobs it runs:
 * icosphere pairs, quick or long. A test run as root starts it with
 * --user TESTDAEMON_USER (meshcorrd refuses root without --user), the
 * test's directories given to that user (deploy/install-deps.sh creates
 * it). Test code only. */
#ifndef TESTDAEMON_H
#define TESTDAEMON_H
#include <sys/types.h>
#include "meshcorr.h"
#include "map/bmap.h"
#include "mesh/mesh.h"

#define TESTDAEMON_ALICE "tok-alice-0123456789"
#define TESTDAEMON_BOB   "tok-bob-0123456789"
#define TESTDAEMON_ADMIN "tok-boss-0123456789"
#define TESTDAEMON_USER  "meshcorr"

typedef struct testdaemon {
    pid_t pid;
    char dir[512];             /* harness_tmpdir()/name */
    char state[600];           /* dir/state */
    char unix_addr[600];       /* "unix:dir/sock" */
    char tcp_addr[64];         /* "tcp:127.0.0.1:PORT" */
    char tls_addr[64];         /* "tls:127.0.0.1:PORT" of the first tls: listener in args; "" none */
    char log[600];             /* the daemon's stderr (appended across restarts) */
} testdaemon;

/* The tokens-file line of token: "sha256:HEX user[ admin]" (SHA-256 by
 * GnuTLS, not by the daemon's code). */
void testdaemon_token_line(const char *token, const char *user, int admin, char *line, size_t sz);
/* Writes text to path (mode 0600, replaced whole by a rename). */
void testdaemon_write_tokens(const char *path, const char *text);
/* SKIPs the test when build/meshcorr-worker has not been built. */
void testdaemon_need_worker(void);
/* Starts meshcorrd (args: extra options, NULL-terminated, or NULL) and waits
 * until it listens; with the same name again, restarts on the same state.
 * Fails the test when it cannot. */
void testdaemon_start(testdaemon *d, const char *name, const char *const *args);
/* Sends sig (0: none, the daemon is already shutting down) and waits for
 * its exit, at most 20 s (then SIGKILL). Fails the test unless meshcorrd
 * exited with status 0: a daemon that dies by a signal or exits non-zero at
 * any point before it is stopped fails the test that stops it. */
void testdaemon_stop(testdaemon *d, int sig);
/* A crash: SIGKILLs the daemon and reaps it. Fails the test when it had
 * already died (by a signal or an exit) before the SIGKILL. */
void testdaemon_kill(testdaemon *d);
/* TESTDAEMON_USER when the test runs as root (the --user a meshcorrd the
 * test starts by hand must be given), else NULL. */
const char *testdaemon_user(void);
/* When the test runs as root: path (a file or folder the daemon reads, or
 * a folder on the way to one) becomes TESTDAEMON_USER's; else nothing. */
void testdaemon_give(const char *path);
/* prlimit(2) on the daemon (a test's way to shrink its descriptors). The
 * daemon runs as TESTDAEMON_USER when the test is root, and root may lack
 * CAP_SYS_RESOURCE (a container): then a child of the test that takes the
 * daemon's user does it. 0, or -1 with errno set. */
struct rlimit;
int testdaemon_prlimit(const testdaemon *d, int resource, const struct rlimit *new_limit, struct rlimit *old_limit);
/* A connected client: token NULL = the Unix socket (peer credentials), else
 * TCP with that token. Fails the test when it cannot connect. */
mc_client *testdaemon_client(const testdaemon *d, const char *token);
/* 1 when a line of the daemon's log contains what. */
int testdaemon_log_has(const testdaemon *d, const char *what);
/* How many lines of the daemon's log contain what. */
int testdaemon_log_count(const testdaemon *d, const char *what);
/* Medians of the daemon log's "checked in X ms (Y ms CPU)" figures, one per
 * SUBMIT check: X, and Y in *cpu_ms (fails the test when there is none). */
double testdaemon_checked_ms(const testdaemon *d, double *cpu_ms);
/* Pid of the meshcorr-worker the daemon runs for job id, or -1 (waits up to
 * 10 s for it to appear). */
pid_t testdaemon_worker_pid(const testdaemon *d, uint64_t id);
/* Live (not zombie) meshcorr-worker processes of job id of d's state
 * directory, whoever their parent is (orphans of a killed daemon count). */
int testdaemon_live_workers(const testdaemon *d, uint64_t id);
/* SIGKILLs every process working in d's spool (cleanup of a test that
 * leaves orphans behind); the number killed. */
int testdaemon_kill_workers(const testdaemon *d);
/* Polls STATUS until the job is in `state` (or, with state < 0, in any final
 * state); fails the test after timeout_s. Returns the state. */
int testdaemon_wait_state(mc_client *c, uint64_t id, int state, int timeout_s);
/* Submits an icosphere job (level 2, 162 vertices; the target scaled and
 * bent a little), 6 identity landmarks; iterations outer iterations, no
 * early stop. long_job: level 3 (642 vertices), for jobs to cancel or kill. */
/* The pair of those jobs, as meshes (mesh_free both): level 2 (162
 * vertices), long_job level 3; fails the test on error. */
void testdaemon_pair(int long_job, mesh **S, mesh **T);
/* The same pair at any icosphere level (6: 40962 vertices). */
void testdaemon_sphere_pair(int level, mesh **S, mesh **T);
/* m as Draco bytes (mc_encode_mesh, malloc'd; fails the test on error). */
unsigned char *testdaemon_encode(const mesh *m, size_t *len);
uint64_t testdaemon_submit(mc_client *c, int iterations, int long_job, int32_t priority, int *rc);
/* testdaemon_submit that fails the test unless SUBMIT_OK came back with an id. */
uint64_t testdaemon_submit_ok(mc_client *c, int iterations, int long_job, int32_t priority);
/* Sleeps ms milliseconds. */
void testdaemon_sleep_ms(int ms);

/* The authors' demo pair 381 -> 390 with its HOT initial maps, as a client
 * sends it (spec: Draco bytes, maps P and Q, `iterations` outer iterations,
 * no early stop) and as the worker sees it (S, T decoded from those Draco
 * bytes; P0, Q0 read against them), to compare a daemon's job with corr_run
 * in process. SKIPs the test without the data folder. */
typedef struct testdaemon_demo {
    mc_job_spec spec;
    mesh *S, *T;
    bmap *P0, *Q0;
    unsigned char *sb, *tb;     /* owned by the struct, as are the map rows */
    mc_map_row *pr, *qr;
} testdaemon_demo;
void testdaemon_demo_open(testdaemon_demo *dm, uint32_t iterations);
void testdaemon_demo_close(testdaemon_demo *dm);

#endif
