/* store.c — the job store: SQLite in WAL mode (<state-dir>/jobs.db) and the
 * spool directories (<state-dir>/spool/<id>/).
 *
 * DESIGN: an acknowledged job is never lost. store_submit writes the SUBMIT
 * frame into a fresh spool/.new-XXXXXX/job.frame (fsync the file and that
 * directory), then, in one transaction with synchronous=FULL, inserts the
 * row, renames the directory to spool/<id> (fsync spool/) and commits; the
 * caller answers SUBMIT_OK only after it returned 0, with the id of the
 * committed row. A crash before the commit leaves a spool/.new-* directory
 * or a spool/<id> without a row, which store_recover removes (the client
 * never heard of that job). Ids come from AUTOINCREMENT and are never
 * reused.
 *
 * Threads: store_submit is the one function that runs in libuv's thread
 * pool (req.c), possibly several at once and concurrently with the loop's
 * calls. It uses a SQLite connection of its own (sdb), serialised by a
 * mutex, and writes the spool file before taking the mutex; WAL lets the
 * loop's connection read meanwhile, and busy_timeout makes a loop-thread
 * write wait for the submit's short commit instead of failing. Every other
 * function runs in the event loop thread only, on db. store_close must not
 * run while a store_submit does (main.c closes the store after the loop,
 * which ends only when no work is in flight).
 *
 * Progress: a PROGRESS record (history row and the job's latest energy) is
 * one transaction committed with synchronous=NORMAL, i.e. without an fsync
 * on the loop (WAL keeps the file consistent); it becomes durable with the
 * next FULL commit (any state change) or checkpoint. After a power loss the
 * last records of a job that was running may be missing; that job runs
 * again from the start anyway (store_recover). That keeps an fsync per record
 * off the loop (docs/decisions.md, "PROGRESS records without an fsync").
 *
 * Tables: jobs (one row per job; state as its Slurm name; the latest outer
 * iteration and energy), history (one row per PROGRESS record), counters
 * (jobs ended per final state since the store was created). A job handed
 * to Slurm keeps its Slurm job id in its row until it ends, so a restarted
 * daemon re-attaches to it instead of running it again. The store never
 * talks to clients or workers; its recovery only ends the workers a dead
 * daemon left, found by their jobs' worker locks (wlock.c). */
#include "mcd.h"
#include "util/errbuf.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <sqlite3.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

struct store {
    sqlite3 *db;                  /* the loop thread's connection */
    sqlite3 *sdb;                 /* store_submit's connection (thread pool), under submit_mu */
    pthread_mutex_t submit_mu;
    int mu_ready;                 /* submit_mu initialised */
    char dir[CONF_PATH];          /* never changes after store_open */
};

#define SPOOL_NEW_PREFIX ".new-"  /* spool/.new-XXXXXX: a job.frame before its row exists */
#define STORE_BUSY_MS 5000        /* how long a connection waits for the write lock */
#define STORE_MUTEX_WAITS 8       /* loop: waits on submit_mu before it sleeps instead */

/* The loop's connection found the write lock taken: nearly always by a
 * store_submit, which holds submit_mu for its whole transaction, so waiting
 * for the mutex wakes the loop the moment that commits (SQLite's own busy
 * timeout sleeps 1, 2, 5, 10 ... ms). A lock held by another process (the
 * sqlite3 shell) leaves the mutex free: then 1 ms sleeps, STORE_BUSY_MS in all. */
static int loop_busy(void *ctx, int n)
{
    store *s = ctx;
    if (n < STORE_MUTEX_WAITS) {
        pthread_mutex_lock(&s->submit_mu);
        pthread_mutex_unlock(&s->submit_mu);
        return 1;
    }
    if (n >= STORE_MUTEX_WAITS + STORE_BUSY_MS)
        return 0;
    usleep(1000);
    return 1;
}

/* store_submit's connection (a pool thread) waits for a loop-thread write:
 * those are single statements or short transactions, so poll finely. */
static int submit_busy(void *ctx, int n)
{
    (void)ctx;
    if (n >= 4 * STORE_BUSY_MS)
        return 0;
    usleep(250);
    return 1;
}

static const char schema[] =
    "CREATE TABLE IF NOT EXISTS jobs("
    " id INTEGER PRIMARY KEY AUTOINCREMENT,"
    " user TEXT NOT NULL, label TEXT NOT NULL, priority INTEGER NOT NULL,"
    " state TEXT NOT NULL, reason TEXT NOT NULL DEFAULT '',"
    " submit_ms INTEGER NOT NULL, start_ms INTEGER NOT NULL DEFAULT 0,"
    " end_ms INTEGER NOT NULL DEFAULT 0,"
    " params TEXT NOT NULL,"               /* parameter summary, for people */
    " total INTEGER NOT NULL,"             /* planned outer iterations */
    " outer_it INTEGER NOT NULL DEFAULT 0," /* latest progress */
    " energy REAL,"
    " pid INTEGER NOT NULL DEFAULT 0,"     /* worker of the current run */
    " slurm_id TEXT NOT NULL DEFAULT '',"  /* Slurm job of the current run ('' none) */
    " progress_off INTEGER NOT NULL DEFAULT 0," /* bytes of progress.frames taken */
    " crashes INTEGER NOT NULL DEFAULT 0," /* runs whose worker crashed */
    " verdict INTEGER NOT NULL DEFAULT -1," /* the map's quality_verdict; -1 not known */
    " flipped REAL, collapsed REAL,"      /* its flipped and collapsed fractions */
    " fraction REAL, eta_s REAL,"         /* latest progress: the whole job's share done, time left */
    " bytes INTEGER NOT NULL DEFAULT 0);" /* its spool files' size (spool_bytes) */
    "CREATE INDEX IF NOT EXISTS jobs_user ON jobs(user, id);"
    "CREATE TABLE IF NOT EXISTS history("
    " job INTEGER NOT NULL, stage INTEGER NOT NULL, outer_it INTEGER NOT NULL,"
    " total INTEGER NOT NULL, inner0 INTEGER NOT NULL, inner1 INTEGER NOT NULL,"
    " membrane0 REAL, bending0 REAL, mismatch0 REAL, reverse0 REAL, energy0 REAL,"
    " membrane1 REAL, bending1 REAL, mismatch1 REAL, reverse1 REAL, energy1 REAL,"
    " beta REAL, gamma REAL, elapsed_s REAL, fraction REAL, eta_s REAL);"
    "CREATE INDEX IF NOT EXISTS history_job ON history(job, outer_it);"
    "CREATE TABLE IF NOT EXISTS counters(name TEXT PRIMARY KEY, value INTEGER NOT NULL);";

#define HISTORY_COLS "stage, outer_it, total, inner0, inner1, membrane0, bending0, mismatch0," \
    " reverse0, energy0, membrane1, bending1, mismatch1, reverse1, energy1, beta, gamma, elapsed_s," \
    " fraction, eta_s"
#define JOB_COLS "id, user, label, priority, state, reason, submit_ms, start_ms, end_ms, outer_it, total," \
    " slurm_id, progress_off, verdict, flipped, collapsed, fraction, eta_s"

int64_t store_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

int store_is_terminal(int state)
{
    return state != PROTO_STATE_PENDING && state != PROTO_STATE_RUNNING;
}

static int state_from_name(const char *s)
{
    for (int i = 0; i <= PROTO_STATE_LAST; i++)
        if (strcmp(s, proto_state_name(i)) == 0)
            return i;
    return PROTO_STATE_FAILED;
}

const char *store_spool_path(const store *s, uint64_t id, const char *file, char *buf, size_t sz)
{
    if (file)
        snprintf(buf, sz, "%s/spool/%llu/%s", s->dir, (unsigned long long)id, file);
    else
        snprintf(buf, sz, "%s/spool/%llu", s->dir, (unsigned long long)id);
    return buf;
}

/* Runs one statement with optional int64/text binds given as a format:
 * 'i' int64_t, 't' const char *, 'd' double. */
static int exec_v(sqlite3 *db, const char *sql, const char *fmt, ...)
{
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK) {
        dlog(DLOG_ERROR, "store: %s: %s", sql, sqlite3_errmsg(db));
        return PROTO_ESTORAGE;
    }
    va_list ap;
    va_start(ap, fmt);
    for (int i = 0; fmt && fmt[i]; i++) {
        if (fmt[i] == 'i')
            sqlite3_bind_int64(st, i + 1, va_arg(ap, int64_t));
        else if (fmt[i] == 'd')
            sqlite3_bind_double(st, i + 1, va_arg(ap, double));
        else
            sqlite3_bind_text(st, i + 1, va_arg(ap, const char *), -1, SQLITE_TRANSIENT);
    }
    va_end(ap);
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE && rc != SQLITE_ROW) {
        dlog(DLOG_ERROR, "store: %s: %s", sql, sqlite3_errmsg(db));
        return PROTO_ESTORAGE;
    }
    return 0;
}

static int fsync_path(const char *path)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return -1;
    int rc = fsync(fd);
    close(fd);
    return rc;
}

/* Removes dir and the files in it (spool directories are flat). */
static void remove_dir(const char *dir)
{
    char path[CONF_PATH + 400];
    DIR *dp = opendir(dir);
    if (!dp)
        return;
    struct dirent *de;
    while ((de = readdir(dp)))
        if (strcmp(de->d_name, ".") && strcmp(de->d_name, "..")) {
            snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
            unlink(path);
        }
    closedir(dp);
    if (rmdir(dir) != 0)
        dlog(DLOG_WARN, "store: cannot remove %s: %s", dir, strerror(errno));
}

/* The spool files a job's bytes count: its input, its answer and its
 * progress (worker.lock and progress.secret are a few bytes and left out). */
static const char *const counted_files[] = {SPOOL_JOB_FRAME, SPOOL_RESULT_FRAME, SPOOL_ERROR_FRAME,
                                            SPOOL_PROGRESS_FILE, SPOOL_SLURM_OUT};

/* Bytes of job id's counted spool files (a stat each, no directory walk);
 * with_input 0 leaves job.frame out (it is about to go). */
static int64_t spool_bytes(const store *s, uint64_t id, int with_input)
{
    char path[CONF_PATH + 96];
    int64_t n = 0;
    struct stat st;
    for (size_t i = with_input ? 0 : 1; i < sizeof counted_files / sizeof counted_files[0]; i++)
        if (stat(store_spool_path(s, id, counted_files[i], path, sizeof path), &st) == 0)
            n += (int64_t)st.st_size;
    return n;
}

/* Removes job id's job.frame (an ended job that did not complete). */
static void drop_input(const store *s, uint64_t id)
{
    char path[CONF_PATH + 64];
    if (unlink(store_spool_path(s, id, SPOOL_JOB_FRAME, path, sizeof path)) != 0 && errno != ENOENT)
        dlog(DLOG_WARN, "store: cannot remove %s: %s", path, strerror(errno));
}

/* Counts job id's spool files again into its row's bytes. */
static int recount_bytes(store *s, uint64_t id)
{
    return exec_v(s->db, "UPDATE jobs SET bytes = ? WHERE id = ?", "ii", spool_bytes(s, id, 1), (int64_t)id);
}

/* Removes spool/<id>/ and the files in it. */
static void spool_remove(const store *s, uint64_t id)
{
    char dir[CONF_PATH + 64];
    remove_dir(store_spool_path(s, id, NULL, dir, sizeof dir));
}

/* Opens path with the pragmas every connection of the store uses and a
 * busy handler (the wait for another connection's write lock). */
static int open_db(const char *path, sqlite3 **db, int (*busy)(void *, int), void *ctx,
                   char *err, size_t errsz)
{
    char *msg = NULL;
    if (sqlite3_open_v2(path, db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, NULL) != SQLITE_OK)
        return errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: %s", path, *db ? sqlite3_errmsg(*db) : "cannot open");
    sqlite3_busy_handler(*db, busy, ctx);
    if (sqlite3_exec(*db, "PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL;", NULL, NULL, &msg) != SQLITE_OK) {
        errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: %s", path, msg ? msg : "cannot set up");
        sqlite3_free(msg);
        return PROTO_ESTORAGE;
    }
    return 0;
}

/* Every row's bytes from its spool files (a store from before the column). */
static int count_all_bytes(store *s)
{
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(s->db, "SELECT id FROM jobs", -1, &st, NULL) != SQLITE_OK)
        return PROTO_ESTORAGE;
    int rc = 0;
    while (!rc && sqlite3_step(st) == SQLITE_ROW)
        rc = recount_bytes(s, (uint64_t)sqlite3_column_int64(st, 0));
    sqlite3_finalize(st);
    return rc;
}

int store_open(const char *dir, store **out, char *err, size_t errsz)
{
    *out = NULL;
    if (!sqlite3_threadsafe())     /* two threads use two connections */
        return errbuf_set(err, errsz, PROTO_ESTORAGE, "SQLite was built without thread support");
    store *s = calloc(1, sizeof *s);
    if (!s)
        return errbuf_set(err, errsz, PROTO_ENOMEM, "out of memory");
    snprintf(s->dir, sizeof s->dir, "%s", dir);
    char path[CONF_PATH + 32];
    int rc = PROTO_ESTORAGE;
    if (pthread_mutex_init(&s->submit_mu, NULL) != 0) {
        errbuf_set(err, errsz, rc, "cannot create a mutex");
        goto fail;
    }
    s->mu_ready = 1;
    if (mkdir(dir, 0700) != 0 && errno != EEXIST) {
        errbuf_set(err, errsz, rc, "%s: %s", dir, strerror(errno));
        goto fail;
    }
    snprintf(path, sizeof path, "%s/spool", dir);
    if (mkdir(path, 0700) != 0 && errno != EEXIST) {
        errbuf_set(err, errsz, rc, "%s: %s", path, strerror(errno));
        goto fail;
    }
    snprintf(path, sizeof path, "%s/jobs.db", dir);
    if (open_db(path, &s->db, loop_busy, s, err, errsz))
        goto fail;
    char *msg = NULL;
    if (sqlite3_exec(s->db, schema, NULL, NULL, &msg) != SQLITE_OK) {
        errbuf_set(err, errsz, rc, "%s: %s", path, msg ? msg : "cannot set up");
        sqlite3_free(msg);
        goto fail;
    }
    /* stores made before the Slurm backend: add its columns (an error here
     * only says the column exists) */
    sqlite3_exec(s->db, "ALTER TABLE jobs ADD COLUMN slurm_id TEXT NOT NULL DEFAULT ''", NULL, NULL, NULL);
    sqlite3_exec(s->db, "ALTER TABLE jobs ADD COLUMN progress_off INTEGER NOT NULL DEFAULT 0", NULL, NULL, NULL);
    /* and those from before the map quality */
    sqlite3_exec(s->db, "ALTER TABLE jobs ADD COLUMN verdict INTEGER NOT NULL DEFAULT -1", NULL, NULL, NULL);
    sqlite3_exec(s->db, "ALTER TABLE jobs ADD COLUMN flipped REAL", NULL, NULL, NULL);
    sqlite3_exec(s->db, "ALTER TABLE jobs ADD COLUMN collapsed REAL", NULL, NULL, NULL);
    /* and those from before the whole job's progress */
    sqlite3_exec(s->db, "ALTER TABLE jobs ADD COLUMN fraction REAL", NULL, NULL, NULL);
    sqlite3_exec(s->db, "ALTER TABLE jobs ADD COLUMN eta_s REAL", NULL, NULL, NULL);
    sqlite3_exec(s->db, "ALTER TABLE history ADD COLUMN fraction REAL", NULL, NULL, NULL);
    sqlite3_exec(s->db, "ALTER TABLE history ADD COLUMN eta_s REAL", NULL, NULL, NULL);
    /* a jobs.db from before the byte quota gains the column, counted once
     * from the files (the ALTER succeeds only when the column is new) */
    if (sqlite3_exec(s->db, "ALTER TABLE jobs ADD COLUMN bytes INTEGER NOT NULL DEFAULT 0", NULL, NULL, NULL)
        == SQLITE_OK && count_all_bytes(s)) {
        errbuf_set(err, errsz, rc, "%s: cannot count the jobs' spool bytes", path);
        goto fail;
    }
    /* a jobs.db from before the crash count gains the column */
    sqlite3_stmt *probe;
    if (sqlite3_prepare_v2(s->db, "SELECT crashes FROM jobs LIMIT 0", -1, &probe, NULL) == SQLITE_OK) {
        sqlite3_finalize(probe);
    } else if (sqlite3_exec(s->db, "ALTER TABLE jobs ADD COLUMN crashes INTEGER NOT NULL DEFAULT 0",
                            NULL, NULL, &msg) != SQLITE_OK) {
        errbuf_set(err, errsz, rc, "%s: %s", path, msg ? msg : "cannot add the crashes column");
        sqlite3_free(msg);
        goto fail;
    }
    /* the schema exists now: the submit connection only inserts into it */
    if (open_db(path, &s->sdb, submit_busy, NULL, err, errsz))
        goto fail;
    *out = s;
    return 0;
fail:
    store_close(s);
    return rc;
}

void store_close(store *s)
{
    if (!s)
        return;
    sqlite3 *dbs[2] = {s->sdb, s->db};
    for (int i = 0; i < 2; i++)
        if (dbs[i] && sqlite3_close(dbs[i]) != SQLITE_OK)
            dlog(DLOG_ERROR, "store: close: %s", sqlite3_errmsg(dbs[i]));
    if (s->mu_ready)
        pthread_mutex_destroy(&s->submit_mu);
    free(s);
}

/* No worker a previous daemon started survives it: each job's worker lock
 * (wlock.c) is held by whatever process of that job still runs, recorded
 * in the row or not (a daemon killed between the spawn and the row's update
 * left it PENDING). */
static int kill_orphan_workers(store *s, char *err, size_t errsz)
{
    char spool[CONF_PATH + 16];
    snprintf(spool, sizeof spool, "%s/spool", s->dir);
    DIR *dp = opendir(spool);
    if (!dp)
        return errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: %s", spool, strerror(errno));
    struct dirent *de;
    while ((de = readdir(dp))) {
        char *e, path[CONF_PATH + 64];
        unsigned long long id = strtoull(de->d_name, &e, 10);
        if (de->d_name[0] == '.' || *e != '\0' || id == 0)
            continue;
        int n = wlock_kill_holders(store_spool_path(s, id, SPOOL_WORKER_LOCK, path, sizeof path), WLOCK_RECOVER_WAIT_MS);
        if (n > 0)
            dlog(DLOG_WARN, "store: job %llu: killed %d worker process(es) a previous daemon left running", id, n);
        else if (n < 0)
            dlog(DLOG_ERROR, "store: job %llu: a process still holds %s after %d ms: the job starts once it"
                 " lets go", id, path, WLOCK_RECOVER_WAIT_MS);
    }
    closedir(dp);
    return 0;
}

/* Unfinished local jobs whose worker finished while no daemon watched: the
 * result is complete (the worker writes it atomically) and valid, so it is
 * the job's answer; running the job again would only redo the work. */
static int adopt_results(store *s, int *adopted, char *err, size_t errsz)
{
    sqlite3_stmt *st;
    *adopted = 0;
    if (sqlite3_prepare_v2(s->db, "SELECT id FROM jobs WHERE state IN ('PENDING', 'RUNNING') AND slurm_id = ''",
                           -1, &st, NULL) != SQLITE_OK)
        return errbuf_set(err, errsz, PROTO_ESTORAGE, "recover: %s", sqlite3_errmsg(s->db));
    uint64_t *ids = NULL;
    size_t n = 0;
    while (sqlite3_step(st) == SQLITE_ROW) {
        uint64_t id = (uint64_t)sqlite3_column_int64(st, 0);
        char path[CONF_PATH + 64];
        if (access(store_spool_path(s, id, SPOOL_RESULT_FRAME, path, sizeof path), F_OK) != 0)
            continue;
        uint64_t *l = realloc(ids, (n + 1) * sizeof *l);
        if (l) {
            ids = l;
            ids[n++] = id;
        }
    }
    sqlite3_finalize(st);
    for (size_t i = 0; i < n; i++) {
        char why[256];
        proto_msg m;
        uint8_t *buf;
        if (store_result_read(s, ids[i], &m, &buf, why, sizeof why)) {
            dlog(DLOG_WARN, "store: job %llu: result.frame left by a worker is not usable (%s): runs again",
                 (unsigned long long)ids[i], why);
            continue;
        }
        int verdict;
        double flipped, collapsed;
        store_result_quality(&m, &verdict, &flipped, &collapsed);
        proto_msg_free(&m);
        free(buf);
        if (verdict >= 0)
            store_set_quality(s, ids[i], verdict, flipped, collapsed);
        if (store_set_state(s, ids[i], PROTO_STATE_COMPLETED, "finished while the daemon was down: result adopted")) {
            free(ids);
            return errbuf_set(err, errsz, PROTO_ESTORAGE, "recover: cannot record job %llu's adopted result",
                              (unsigned long long)ids[i]);
        }
        dlog(DLOG_INFO, "store: job %llu: COMPLETED: its worker finished while the daemon was down; result adopted",
             (unsigned long long)ids[i]);
        (*adopted)++;
    }
    free(ids);
    return 0;
}

int store_recover(store *s, int keep_slurm, char *err, size_t errsz)
{
    sqlite3_stmt *st;
    int rc = 0;
    /* 0. Slurm runs without the Slurm backend: they run here again. */
    if (!keep_slurm) {
        if ((rc = exec_v(s->db, "UPDATE jobs SET state = 'PENDING', start_ms = 0, pid = 0, outer_it = 0,"
                         " energy = NULL, fraction = NULL, eta_s = NULL, slurm_id = '', progress_off = 0"
                         " WHERE state IN ('PENDING', 'RUNNING') AND slurm_id != ''", NULL)))
            return errbuf_set(err, errsz, rc, "recover: cannot re-queue Slurm jobs");
        if (sqlite3_changes(s->db))
            dlog(DLOG_WARN, "store: %d job(s) handed to Slurm by an earlier run go back to the queue"
                 " (backend is not slurm)", sqlite3_changes(s->db));
    }
    /* 1. no worker of the previous daemon runs on; the results they
     * finished are adopted; other RUNNING jobs go back to PENDING (the run
     * was cut off by the daemon's end). Slurm runs go on without us and are
     * re-attached by the backend. */
    int adopted;
    if ((rc = kill_orphan_workers(s, err, errsz)) || (rc = adopt_results(s, &adopted, err, errsz)))
        return rc;
    if ((rc = exec_v(s->db, "UPDATE jobs SET state = 'PENDING', start_ms = 0, pid = 0, outer_it = 0,"
                     " energy = NULL, fraction = NULL, eta_s = NULL"
                     " WHERE state = 'RUNNING' AND slurm_id = ''", NULL)))
        return errbuf_set(err, errsz, rc, "recover: cannot re-queue running jobs");
    int requeued = sqlite3_changes(s->db);
    /* 2. spool directories without a committed row. */
    char spool[CONF_PATH + 16];
    snprintf(spool, sizeof spool, "%s/spool", s->dir);
    DIR *dp = opendir(spool);
    if (!dp)
        return errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: %s", spool, strerror(errno));
    struct dirent *de;
    int removed = 0;
    while ((de = readdir(dp))) {
        if (strncmp(de->d_name, SPOOL_NEW_PREFIX, strlen(SPOOL_NEW_PREFIX)) == 0) {
            /* a SUBMIT cut off before its row was inserted */
            char dir[CONF_PATH + 300];
            snprintf(dir, sizeof dir, "%s/%s", spool, de->d_name);
            remove_dir(dir);
            removed++;
            continue;
        }
        char *e;
        unsigned long long id = strtoull(de->d_name, &e, 10);
        if (de->d_name[0] == '.' || *e != '\0' || id == 0)
            continue;
        store_job j;
        if (store_get(s, id, &j) == PROTO_ENOT_FOUND) {
            spool_remove(s, id);
            removed++;
        }
    }
    closedir(dp);
    /* 3. unfinished rows whose job.frame is gone. */
    if (sqlite3_prepare_v2(s->db, "SELECT id FROM jobs WHERE state = 'PENDING'", -1, &st, NULL) != SQLITE_OK)
        return errbuf_set(err, errsz, PROTO_ESTORAGE, "recover: %s", sqlite3_errmsg(s->db));
    uint64_t *lost = NULL;
    size_t nlost = 0;
    while (sqlite3_step(st) == SQLITE_ROW) {
        uint64_t id = (uint64_t)sqlite3_column_int64(st, 0);
        char path[CONF_PATH + 64];
        if (access(store_spool_path(s, id, SPOOL_JOB_FRAME, path, sizeof path), R_OK) != 0) {
            uint64_t *l = realloc(lost, (nlost + 1) * sizeof *l);
            if (l) {
                lost = l;
                lost[nlost++] = id;
            }
        }
    }
    sqlite3_finalize(st);
    for (size_t i = 0; i < nlost; i++) {
        dlog(DLOG_WARN, "store: job %llu has no spool/job.frame: FAILED", (unsigned long long)lost[i]);
        store_set_state(s, lost[i], PROTO_STATE_FAILED, "spool file job.frame missing after restart");
    }
    free(lost);
    /* 4. ended jobs that did not complete hold no input (store_set_state
     * removes it after its commit; a daemon killed in between left it):
     * their missing job.frame is how it should be, not a loss */
    if (sqlite3_prepare_v2(s->db, "SELECT id FROM jobs WHERE state NOT IN ('PENDING', 'RUNNING', 'COMPLETED')",
                           -1, &st, NULL) != SQLITE_OK)
        return errbuf_set(err, errsz, PROTO_ESTORAGE, "recover: %s", sqlite3_errmsg(s->db));
    int dropped = 0;
    while (sqlite3_step(st) == SQLITE_ROW) {
        uint64_t id = (uint64_t)sqlite3_column_int64(st, 0);
        char path[CONF_PATH + 64];
        if (access(store_spool_path(s, id, SPOOL_JOB_FRAME, path, sizeof path), F_OK) == 0) {
            drop_input(s, id);
            recount_bytes(s, id);
            dropped++;
        }
    }
    sqlite3_finalize(st);
    dlog(DLOG_INFO, "store: recovered: %d result(s) adopted, %d running job(s) re-queued, %d orphan spool"
         " dir(s) removed, %zu job(s) without spool failed, %d ended job(s)' input removed", adopted, requeued,
         removed, nlost, dropped);
    return 0;
}

int store_bytes(store *s, const char *user, int64_t *bytes)
{
    sqlite3_stmt *st;
    *bytes = 0;
    if (sqlite3_prepare_v2(s->db, "SELECT COALESCE(SUM(bytes), 0) FROM jobs WHERE ?1 IS NULL OR user = ?1", -1,
                           &st, NULL) != SQLITE_OK)
        return PROTO_ESTORAGE;
    if (user)
        sqlite3_bind_text(st, 1, user, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        *bytes = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    return rc == SQLITE_ROW ? 0 : PROTO_ESTORAGE;
}

/* Writes len bytes of data to a new file path and fsyncs it. 0, or -1 with errno. */
static int write_file_synced(const char *path, const void *data, size_t len)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0)
        return -1;
    for (size_t off = 0; off < len;) {
        ssize_t w = write(fd, (const char *)data + off, len - off);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            int e = w < 0 ? errno : EIO;
            close(fd);
            errno = e;
            return -1;
        }
        off += (size_t)w;
    }
    if (fsync(fd) != 0) {
        int e = errno;
        close(fd);
        errno = e;
        return -1;
    }
    return close(fd);
}

int store_submit(store *s, const char *user, const char *label, int32_t priority,
                 uint32_t total, const char *params, const void *frame, size_t len,
                 uint64_t *id, char *err, size_t errsz)
{
    char spool[CONF_PATH + 16], tmpdir[CONF_PATH + 32], file[CONF_PATH + 48], dir[CONF_PATH + 64];
    uint64_t jid = 0;
    int renamed = 0;
    snprintf(spool, sizeof spool, "%s/spool", s->dir);
    snprintf(tmpdir, sizeof tmpdir, "%s/" SPOOL_NEW_PREFIX "XXXXXX", spool);
    /* 1. the frame, durable under a name no other submit uses; no lock held */
    if (!mkdtemp(tmpdir))
        return errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: %s", tmpdir, strerror(errno));
    snprintf(file, sizeof file, "%s/job.frame", tmpdir);
    if (write_file_synced(file, frame, len) != 0 || fsync_path(tmpdir) != 0) {
        errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: %s", file, strerror(errno));
        remove_dir(tmpdir);
        return PROTO_ESTORAGE;
    }
    /* 2. row, directory under its id, commit: one submit at a time on sdb */
    pthread_mutex_lock(&s->submit_mu);
    if (exec_v(s->sdb, "BEGIN IMMEDIATE", NULL)) {
        pthread_mutex_unlock(&s->submit_mu);
        remove_dir(tmpdir);
        return errbuf_set(err, errsz, PROTO_ESTORAGE, "job database busy or failing");
    }
    if (exec_v(s->sdb, "INSERT INTO jobs(user, label, priority, state, submit_ms, params, total, bytes)"
               " VALUES(?, ?, ?, 'PENDING', ?, ?, ?, ?)", "ttiitii", user, label, (int64_t)priority,
               store_now_ms(), params, (int64_t)total, (int64_t)len)) {
        errbuf_set(err, errsz, PROTO_ESTORAGE, "cannot insert the job row");
        goto fail;
    }
    jid = (uint64_t)sqlite3_last_insert_rowid(s->sdb);
    store_spool_path(s, jid, NULL, dir, sizeof dir);
    if (rename(tmpdir, dir) != 0) {
        errbuf_set(err, errsz, PROTO_ESTORAGE, "%s -> %s: %s", tmpdir, dir, strerror(errno));
        goto fail;
    }
    renamed = 1;
    if (fsync_path(spool) != 0) {
        errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: fsync: %s", spool, strerror(errno));
        goto fail;
    }
    if (exec_v(s->sdb, "COMMIT", NULL)) {
        errbuf_set(err, errsz, PROTO_ESTORAGE, "cannot commit the job row");
        goto fail;
    }
    pthread_mutex_unlock(&s->submit_mu);
    *id = jid;
    return 0;
fail:
    exec_v(s->sdb, "ROLLBACK", NULL);
    /* removed before the lock goes: the next submit may get the same id */
    remove_dir(renamed ? dir : tmpdir);
    pthread_mutex_unlock(&s->submit_mu);
    return PROTO_ESTORAGE;
}

/* A REAL column: NULL for NaN (SQLite stores NaN as NULL anyway). */
static void bind_real(sqlite3_stmt *st, int k, double v)
{
    if (isnan(v))
        sqlite3_bind_null(st, k);
    else
        sqlite3_bind_double(st, k, v);
}

/* A REAL column that may be NULL: NaN for NULL. */
static double column_real(sqlite3_stmt *st, int k)
{
    return sqlite3_column_type(st, k) == SQLITE_NULL ? NAN : sqlite3_column_double(st, k);
}

static void read_job(sqlite3_stmt *st, store_job *j)
{
    memset(j, 0, sizeof *j);
    j->id = (uint64_t)sqlite3_column_int64(st, 0);
    snprintf(j->user, sizeof j->user, "%s", (const char *)sqlite3_column_text(st, 1));
    snprintf(j->label, sizeof j->label, "%s", (const char *)sqlite3_column_text(st, 2));
    j->priority = (int32_t)sqlite3_column_int64(st, 3);
    j->state = state_from_name((const char *)sqlite3_column_text(st, 4));
    snprintf(j->reason, sizeof j->reason, "%s", (const char *)sqlite3_column_text(st, 5));
    j->submit_ms = sqlite3_column_int64(st, 6);
    j->start_ms = sqlite3_column_int64(st, 7);
    j->end_ms = sqlite3_column_int64(st, 8);
    j->outer = (uint32_t)sqlite3_column_int64(st, 9);
    j->total = (uint32_t)sqlite3_column_int64(st, 10);
    snprintf(j->slurm_id, sizeof j->slurm_id, "%s", (const char *)sqlite3_column_text(st, 11));
    j->progress_off = sqlite3_column_int64(st, 12);
    j->verdict = (int)sqlite3_column_int64(st, 13);
    j->flipped = sqlite3_column_type(st, 14) == SQLITE_NULL ? NAN : sqlite3_column_double(st, 14);
    j->collapsed = sqlite3_column_type(st, 15) == SQLITE_NULL ? NAN : sqlite3_column_double(st, 15);
    j->fraction = column_real(st, 16);
    j->eta_s = column_real(st, 17);
}

int store_get(store *s, uint64_t id, store_job *out)
{
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(s->db, "SELECT " JOB_COLS " FROM jobs WHERE id = ?", -1, &st, NULL) != SQLITE_OK)
        return PROTO_ESTORAGE;
    sqlite3_bind_int64(st, 1, (int64_t)id);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        read_job(st, out);
    sqlite3_finalize(st);
    return rc == SQLITE_ROW ? 0 : rc == SQLITE_DONE ? PROTO_ENOT_FOUND : PROTO_ESTORAGE;
}

int store_set_running(store *s, uint64_t id, int64_t start_ms, long pid)
{
    return exec_v(s->db, "UPDATE jobs SET state = 'RUNNING', start_ms = ?, pid = ?, reason = '' WHERE id = ?",
                  "iii", start_ms, (int64_t)pid, (int64_t)id);
}

int store_set_slurm(store *s, uint64_t id, const char *slurm_id, int64_t progress_off)
{
    return exec_v(s->db, "UPDATE jobs SET slurm_id = ?, progress_off = ? WHERE id = ?", "tii", slurm_id,
                  progress_off, (int64_t)id);
}

int store_set_quality(store *s, uint64_t id, int verdict, double flipped, double collapsed)
{
    return exec_v(s->db, "UPDATE jobs SET verdict = ?, flipped = ?, collapsed = ? WHERE id = ?", "iddi",
                  (int64_t)verdict, flipped, collapsed, (int64_t)id);
}

int store_set_reason(store *s, uint64_t id, const char *reason)
{
    return exec_v(s->db, "UPDATE jobs SET reason = ? WHERE id = ?", "ti", reason, (int64_t)id);
}

int store_add_crash(store *s, uint64_t id, uint32_t *crashes)
{
    int rc = exec_v(s->db, "UPDATE jobs SET crashes = crashes + 1 WHERE id = ?", "i", (int64_t)id);
    if (rc)
        return rc;
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(s->db, "SELECT crashes FROM jobs WHERE id = ?", -1, &st, NULL) != SQLITE_OK)
        return PROTO_ESTORAGE;
    sqlite3_bind_int64(st, 1, (int64_t)id);
    rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        *crashes = (uint32_t)sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    return rc == SQLITE_ROW ? 0 : rc == SQLITE_DONE ? PROTO_ENOT_FOUND : PROTO_ESTORAGE;
}

int store_set_state(store *s, uint64_t id, int state, const char *reason)
{
    if (!store_is_terminal(state))
        return exec_v(s->db, "UPDATE jobs SET state = ?, reason = ?, start_ms = 0, end_ms = 0, pid = 0,"
                      " outer_it = 0, energy = NULL, fraction = NULL, eta_s = NULL, slurm_id = '',"
                      " progress_off = 0 WHERE id = ?", "tti",
                      proto_state_name(state), reason ? reason : "", (int64_t)id);
    const char *counter = state == PROTO_STATE_COMPLETED ? "completed"
                        : state == PROTO_STATE_CANCELLED ? "cancelled" : "failed";
    /* a job that did not complete keeps its row and reason until expiry,
     * but not its input: nobody can ask for its result, so job.frame goes
     * once the end is committed and its bytes stop counting now */
    int keep_input = state == PROTO_STATE_COMPLETED;
    int rc = exec_v(s->db, "BEGIN", NULL);
    if (!rc)
        rc = exec_v(s->db, "UPDATE jobs SET state = ?, reason = ?, end_ms = ?, pid = 0, slurm_id = '', bytes = ?"
                    " WHERE id = ?", "ttiii", proto_state_name(state), reason ? reason : "", store_now_ms(),
                    spool_bytes(s, id, keep_input), (int64_t)id);
    if (!rc)
        rc = exec_v(s->db, "INSERT INTO counters(name, value) VALUES(?, 1)"
                    " ON CONFLICT(name) DO UPDATE SET value = value + 1", "t", counter);
    if (!rc)
        rc = exec_v(s->db, "COMMIT", NULL);
    if (rc) {
        exec_v(s->db, "ROLLBACK", NULL);
        return rc;
    }
    if (!keep_input)
        drop_input(s, id);
    return 0;
}

int store_add_progress(store *s, uint64_t id, const proto_progress *p)
{
    /* one transaction, committed without an fsync (see DESIGN above) */
    if (exec_v(s->db, "PRAGMA synchronous=NORMAL", NULL))
        return PROTO_ESTORAGE;
    int rc = exec_v(s->db, "BEGIN", NULL);
    sqlite3_stmt *st = NULL;
    if (!rc && sqlite3_prepare_v2(s->db, "INSERT INTO history(job, " HISTORY_COLS ") VALUES"
                                  "(?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)", -1, &st, NULL) != SQLITE_OK)
        rc = PROTO_ESTORAGE;
    if (!rc) {
        int k = 1;
        sqlite3_bind_int64(st, k++, (int64_t)id);
        sqlite3_bind_int64(st, k++, p->stage);
        sqlite3_bind_int64(st, k++, p->outer);
        sqlite3_bind_int64(st, k++, p->total);
        sqlite3_bind_int64(st, k++, p->inner[0]);
        sqlite3_bind_int64(st, k++, p->inner[1]);
        for (int d = 0; d < 2; d++)
            for (int t = 0; t < PROTO_NTERMS; t++)
                sqlite3_bind_double(st, k++, p->terms[d][t]);
        sqlite3_bind_double(st, k++, p->beta);
        sqlite3_bind_double(st, k++, p->gamma);
        sqlite3_bind_double(st, k++, p->elapsed_s);
        bind_real(st, k++, p->fraction);
        bind_real(st, k++, p->eta_s);
        rc = sqlite3_step(st) == SQLITE_DONE ? 0 : PROTO_ESTORAGE;
    }
    sqlite3_finalize(st);
    /* a repair's record has no iteration or energy of its own: the row keeps
     * the last iteration's, and takes the whole job's share */
    if (!rc && p->stage == PROTO_STAGE_REPAIR)
        rc = exec_v(s->db, "UPDATE jobs SET fraction = ?, eta_s = ? WHERE id = ?", "ddi", p->fraction, p->eta_s,
                    (int64_t)id);
    else if (!rc)
        rc = exec_v(s->db, "UPDATE jobs SET outer_it = ?, total = ?, energy = ?, fraction = ?, eta_s = ?"
                    " WHERE id = ?", "iidddi", (int64_t)p->outer, (int64_t)p->total,
                    p->terms[0][PROTO_TERM_ENERGY] + p->terms[1][PROTO_TERM_ENERGY], p->fraction, p->eta_s,
                    (int64_t)id);
    if (!rc)
        rc = exec_v(s->db, "COMMIT", NULL);
    if (rc)
        exec_v(s->db, "ROLLBACK", NULL);
    if (exec_v(s->db, "PRAGMA synchronous=FULL", NULL))
        rc = PROTO_ESTORAGE;
    return rc;
}

int store_clear_run(store *s, uint64_t id)
{
    char path[CONF_PATH + 96];
    /* never SPOOL_WORKER_LOCK: a new file would let a second worker lock it (wlock.c) */
    static const char *files[] = {SPOOL_RESULT_FRAME, SPOOL_RESULT_FRAME SPOOL_TMP_SUFFIX, SPOOL_ERROR_FRAME,
                                  SPOOL_ERROR_FRAME SPOOL_TMP_SUFFIX, SPOOL_PROGRESS_FILE, SPOOL_SECRET_FILE,
                                  SPOOL_SLURM_OUT};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++)
        unlink(store_spool_path(s, id, files[i], path, sizeof path));
    int rc = recount_bytes(s, id);
    return rc ? rc : exec_v(s->db, "DELETE FROM history WHERE job = ?", "i", (int64_t)id);
}

int store_result_read(const store *s, uint64_t id, proto_msg *m, uint8_t **bufp, char *why, size_t wsz)
{
    char path[CONF_PATH + 64];
    *bufp = NULL;
    FILE *fp = fopen(store_spool_path(s, id, SPOOL_RESULT_FRAME, path, sizeof path), "rb");
    if (!fp)
        return errbuf_set(why, wsz, PROTO_EINTERNAL, "%s", strerror(errno));
    uint8_t *buf = NULL;
    long sz = -1;
    size_t n = 0;
    if (fseek(fp, 0, SEEK_END) == 0 && (sz = ftell(fp)) > 0 && (unsigned long)sz <= PROTO_MAX_FRAME &&
        fseek(fp, 0, SEEK_SET) == 0 && (buf = malloc((size_t)sz)))
        n = fread(buf, 1, (size_t)sz, fp);
    fclose(fp);
    if (!buf)
        return errbuf_set(why, wsz, PROTO_EINTERNAL, "%s",
                          sz <= 0 ? "empty or unreadable" : "too large or out of memory");
    size_t used = 0;
    int rc = proto_decode(buf, n, PROTO_MAX_FRAME, m, &used, why, wsz);
    if (rc == PROTO_READY) {
        if (m->type != PROTO_MSG_RESULT_OK)
            rc = errbuf_set(why, wsz, PROTO_EINTERNAL, "a %s frame, not RESULT_OK", proto_type_name(m->type));
        else if (m->u.result_ok.job_id != id)
            rc = errbuf_set(why, wsz, PROTO_EINTERNAL, "the result of job %llu",
                            (unsigned long long)m->u.result_ok.job_id);
        else if (used != n)
            rc = errbuf_set(why, wsz, PROTO_EINTERNAL, "%zu bytes after the frame", n - used);
        else {
            *bufp = buf;
            return 0;
        }
        proto_msg_free(m);
    } else if (rc > 0) {
        errbuf_set(why, wsz, 0, "truncated (%zu bytes)", n);
    }
    free(buf);
    return PROTO_EINTERNAL;
}

int store_result_ok(store *s, uint64_t id, char *why, size_t wsz)
{
    proto_msg m;
    uint8_t *buf;
    if (store_result_read(s, id, &m, &buf, why, wsz))
        return 0;
    proto_msg_free(&m);
    free(buf);
    return 1;
}

void store_result_quality(const proto_msg *m, int *verdict, double *flipped, double *collapsed)
{
    *verdict = -1;
    *flipped = *collapsed = NAN;
    const proto_result_ok *r = &m->u.result_ok;
    for (uint32_t i = 0; i < r->nmetrics; i++) {
        const char *k = r->metrics[i].key;
        double v = r->metrics[i].value;
        if (!strcmp(k, "quality_verdict") && v >= 0 && v < 100)
            *verdict = (int)v;
        else if (!strcmp(k, "flipped_fraction"))
            *flipped = v;
        else if (!strcmp(k, "collapsed_fraction"))
            *collapsed = v;
    }
}

static void read_progress(sqlite3_stmt *st, uint64_t id, proto_progress *p)
{
    int k = 0;
    memset(p, 0, sizeof *p);
    p->job_id = id;
    p->stage = (uint8_t)sqlite3_column_int64(st, k++);
    p->outer = (uint32_t)sqlite3_column_int64(st, k++);
    p->total = (uint32_t)sqlite3_column_int64(st, k++);
    p->inner[0] = (uint32_t)sqlite3_column_int64(st, k++);
    p->inner[1] = (uint32_t)sqlite3_column_int64(st, k++);
    for (int d = 0; d < 2; d++)
        for (int t = 0; t < PROTO_NTERMS; t++)
            p->terms[d][t] = sqlite3_column_double(st, k++);
    p->beta = sqlite3_column_double(st, k++);
    p->gamma = sqlite3_column_double(st, k++);
    p->elapsed_s = sqlite3_column_double(st, k++);
    p->fraction = column_real(st, k++);
    p->eta_s = column_real(st, k++);
}

int store_latest_progress(store *s, uint64_t id, proto_progress *out)
{
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(s->db, "SELECT " HISTORY_COLS " FROM history WHERE job = ?"
                           " ORDER BY rowid DESC LIMIT 1", -1, &st, NULL) != SQLITE_OK)
        return PROTO_ESTORAGE;
    sqlite3_bind_int64(st, 1, (int64_t)id);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        read_progress(st, id, out);
    sqlite3_finalize(st);
    return rc == SQLITE_ROW ? 0 : PROTO_ENOT_FOUND;
}

int store_history(store *s, uint64_t id, uint32_t from_outer, store_progress_fn fn, void *ctx)
{
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(s->db, "SELECT " HISTORY_COLS " FROM history WHERE job = ? AND outer_it >= ?"
                           " ORDER BY rowid", -1, &st, NULL) != SQLITE_OK)
        return PROTO_ESTORAGE;
    sqlite3_bind_int64(st, 1, (int64_t)id);
    sqlite3_bind_int64(st, 2, from_outer);
    int rc;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        proto_progress p;
        read_progress(st, id, &p);
        if (fn(ctx, &p))
            break;
    }
    sqlite3_finalize(st);
    return rc == SQLITE_ROW || rc == SQLITE_DONE ? 0 : PROTO_ESTORAGE;
}

static int each_job(store *s, sqlite3_stmt *st, store_job_fn fn, void *ctx)
{
    int rc;
    store_job j;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        read_job(st, &j);
        if (fn(ctx, &j))
            break;
    }
    sqlite3_finalize(st);
    (void)s;
    return rc == SQLITE_ROW || rc == SQLITE_DONE ? 0 : PROTO_ESTORAGE;
}

int store_list(store *s, const char *user, uint32_t state_mask, uint64_t after_id,
               uint32_t max, store_job_fn fn, void *ctx)
{
    char sql[512] = "SELECT " JOB_COLS " FROM jobs WHERE id > ?1 AND (?2 IS NULL OR user = ?2)";
    if (state_mask) {
        strcat(sql, " AND state IN (");
        for (int i = 0, first = 1; i <= PROTO_STATE_LAST; i++)
            if (state_mask & (1u << i)) {
                strcat(sql, first ? "'" : ",'");
                strcat(sql, proto_state_name(i));
                strcat(sql, "'");
                first = 0;
            }
        strcat(sql, ")");
    }
    strcat(sql, " ORDER BY id LIMIT ?3");
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(s->db, sql, -1, &st, NULL) != SQLITE_OK)
        return PROTO_ESTORAGE;
    sqlite3_bind_int64(st, 1, (int64_t)after_id);
    if (user)
        sqlite3_bind_text(st, 2, user, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int64(st, 3, max);
    return each_job(s, st, fn, ctx);
}

int store_each_pending(store *s, store_job_fn fn, void *ctx)
{
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(s->db, "SELECT " JOB_COLS " FROM jobs WHERE state = 'PENDING' AND slurm_id = ''"
                           " ORDER BY id", -1, &st, NULL) != SQLITE_OK)
        return PROTO_ESTORAGE;
    return each_job(s, st, fn, ctx);
}

int store_each_slurm(store *s, store_job_fn fn, void *ctx)
{
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(s->db, "SELECT " JOB_COLS " FROM jobs WHERE state IN ('PENDING', 'RUNNING')"
                           " AND slurm_id != '' ORDER BY id", -1, &st, NULL) != SQLITE_OK)
        return PROTO_ESTORAGE;
    return each_job(s, st, fn, ctx);
}

int store_each_expired(store *s, int64_t before_ms, store_job_fn fn, void *ctx)
{
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(s->db, "SELECT " JOB_COLS " FROM jobs WHERE state NOT IN ('PENDING', 'RUNNING')"
                           " AND end_ms < ? ORDER BY id", -1, &st, NULL) != SQLITE_OK)
        return PROTO_ESTORAGE;
    sqlite3_bind_int64(st, 1, before_ms);
    return each_job(s, st, fn, ctx);
}

int store_delete(store *s, uint64_t id)
{
    int rc = exec_v(s->db, "BEGIN", NULL);
    if (!rc)
        rc = exec_v(s->db, "DELETE FROM history WHERE job = ?", "i", (int64_t)id);
    if (!rc)
        rc = exec_v(s->db, "DELETE FROM jobs WHERE id = ?", "i", (int64_t)id);
    if (!rc)
        rc = exec_v(s->db, "COMMIT", NULL);
    if (rc) {
        exec_v(s->db, "ROLLBACK", NULL);
        return rc;
    }
    spool_remove(s, id);
    return 0;
}

void store_counters(store *s, uint64_t *completed, uint64_t *failed, uint64_t *cancelled)
{
    *completed = *failed = *cancelled = 0;
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(s->db, "SELECT name, value FROM counters", -1, &st, NULL) != SQLITE_OK)
        return;
    while (sqlite3_step(st) == SQLITE_ROW) {
        const char *n = (const char *)sqlite3_column_text(st, 0);
        uint64_t v = (uint64_t)sqlite3_column_int64(st, 1);
        if (strcmp(n, "completed") == 0) *completed = v;
        else if (strcmp(n, "failed") == 0) *failed = v;
        else if (strcmp(n, "cancelled") == 0) *cancelled = v;
    }
    sqlite3_finalize(st);
}

/* The store is opened once. */
void store_keep_on_reload(const mcd_conf *o, mcd_conf *n, char *changed, size_t sz)
{
    conf_note_change(strcmp(n->state_dir, o->state_dir) != 0, "state-dir", changed, sz);
    memcpy(n->state_dir, o->state_dir, sizeof n->state_dir);
}
