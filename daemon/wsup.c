/* wsup.c — worker supervision: --workers slots, each running at most one
 * meshcorr-worker process (workers/WORKER.md is the contract: argv, spool
 * files, progress frames on --progress-fd, exit codes).
 *
 * DESIGN: a job's end is decided from what the worker left, never from a
 * guess: result.frame -> COMPLETED; our wall-time SIGTERM -> TIMEOUT;
 * exit 3 or a cancel we sent -> CANCELLED; error.frame -> FAILED with its
 * message (OUT_OF_MEMORY for NOMEM); exit 4 (no answer could be stored: a
 * full disk) -> PENDING again, starts paused; a signal or a bare exit is a
 * crash: the job runs once more, a second crash fails it ("worker crashed
 * twice"). job.c records the end (job_ended). No job starts while the
 * state file system has less than WSUP_MIN_FREE_BYTES free, nor while its
 * worker lock is held (wlock.c); such a start, or a spawn failing for a
 * passing reason, waits in the queue while starts pause.
 * During a shutdown drain a job without result.frame goes back to PENDING,
 * so it runs again on the next start: never lost. The worker is started
 * with uv_spawn (fork + exec at once: nothing of the daemon's state runs in
 * the child) and its progress pipe is read non-blocking in the loop. A slot
 * is idle again only when the process and pipe handles are closed.
 * This is the `local` backend (backend.h); bk_local at the end is its table. */
#include "backend.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <sched.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#define WSUP_EOF_GRACE_MS 2000      /* after exit, wait this long for the pipe's EOF */
#define WSUP_MAX_CRASHES 2          /* worker crashes that fail a job */
#define WSUP_RETRY_MIN_MS 500       /* a start failed for a passing reason: the first retry */
#define WSUP_RETRY_MAX_MS 30000     /* ... and the longest wait between retries */
#define WSUP_MIN_FREE_BYTES (1u << 20)  /* free in the state file system for a run's answer */

struct wsup_slot {
    mcd *d;
    int index;
    uint8_t state;                  /* PROTO_SLOT_* */
    uint64_t job_id;
    char user[AUTH_MAX_USER];
    uv_process_t proc;
    uv_pipe_t pipe;
    uv_timer_t timer;               /* wall time, kill grace, EOF grace */
    int open_handles;               /* this run's process + pipe not yet closed */
    int exited, eof, finished;
    int64_t exit_status;
    int term_signal;
    int term_sent, timed_out, cancel_requested, requeue;
    int progress_bad;               /* a malformed frame: ignore the rest */
    proto_buf in;
};

/* Starts are paused after one failed for a passing reason (descriptors or
 * processes exhausted, a full disk, an orphan still holding the job's lock)
 * or a run that could not store its answer: the job goes back to the queue
 * and starts resume after a delay that doubles, up to WSUP_RETRY_MAX_MS,
 * until a run ends with an answer. */
static struct {
    uv_timer_t timer;
    int open, paused;
    uint64_t delay_ms;
    mcd_idle_fn drained;          /* a drain waits: told when a slot is idle again */
} R;

static void slot_finish(wsup_slot *s);
static void wsup_schedule(mcd *d);

/* A worker's CPU seconds (its --max-cpu-s): the wall time it may run,
 * SIGKILL's grace included, times the CPUs it may run on. CPU time counts
 * every thread (OpenMP's, TBB's, PoCL's), and no mix of them gets more than
 * that in that wall time, so the limit never ends a run the wall timer
 * lets finish; it ends a worker that outlived its daemon (workers do, by
 * design) after at most as much CPU as a run may take. */
static unsigned long long wsup_cpu_limit_s(const mcd *d)
{
    cpu_set_t set;
    long ncpu = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : sysconf(_SC_NPROCESSORS_ONLN);
    return ((unsigned long long)d->conf.job_timeout_s + CONF_KILL_GRACE_S) * (unsigned long long)(ncpu > 0 ? ncpu : 1);
}

static int wsup_init(mcd *d, char *err, size_t errsz)
{
    d->slots = calloc((size_t)d->conf.workers, sizeof *d->slots);
    if (!d->slots) {
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    for (int i = 0; i < d->conf.workers; i++) {
        wsup_slot *s = &d->slots[i];
        s->d = d;
        s->index = i;
        s->state = PROTO_SLOT_IDLE;
        proto_buf_init(&s->in);
        uv_timer_init(d->loop, &s->timer);
        s->timer.data = s;
    }
    uv_timer_init(d->loop, &R.timer);
    R.timer.data = d;
    R.open = 1;
    R.paused = 0;
    R.delay_ms = WSUP_RETRY_MIN_MS;
    char buf[PATH_MAX];
    const char *w = conf_worker_path(&d->conf, buf, sizeof buf);
    if (access(w, X_OK) != 0)
        dlog(DLOG_WARN, "worker program %s is not executable: jobs will fail until it is", w);
    uint32_t mem_mb = conf_worker_memory_mb(&d->conf, d->conf.workers);
    if (mem_mb)
        dlog(DLOG_INFO, "workers run sandboxed (workers/WORKER.md): address space %u MB each (--worker-memory-mb),"
             " CPU time %llu s each", mem_mb, wsup_cpu_limit_s(d));
    else
        dlog(DLOG_INFO, "workers run sandboxed (workers/WORKER.md): no address-space limit (--worker-memory-mb 0),"
             " CPU time %llu s each", wsup_cpu_limit_s(d));
    return 0;
}

static void signal_worker(wsup_slot *s, int sig)
{
    if (!s->exited && s->open_handles) {
        int rc = uv_process_kill(&s->proc, sig);
        if (rc && rc != UV_ESRCH)
            dlog(DLOG_WARN, "job %llu: kill(%d): %s", (unsigned long long)s->job_id, sig, uv_strerror(rc));
    }
}

static void on_timer(uv_timer_t *t)
{
    wsup_slot *s = t->data;
    if (s->exited) {                 /* exit seen, EOF never came: finish anyway */
        dlog(DLOG_WARN, "job %llu: progress pipe still open after the worker exited", (unsigned long long)s->job_id);
        slot_finish(s);
    } else if (!s->term_sent) {      /* wall time is up */
        dlog(DLOG_INFO, "job %llu: wall time %u s exceeded: SIGTERM", (unsigned long long)s->job_id,
             s->d->conf.job_timeout_s);
        s->timed_out = 1;
        s->term_sent = 1;
        signal_worker(s, SIGTERM);
        uv_timer_start(&s->timer, on_timer, CONF_KILL_GRACE_S * 1000, 0);
    } else {                         /* still alive after the grace period */
        dlog(DLOG_WARN, "job %llu: worker alive %d s after SIGTERM: SIGKILL", (unsigned long long)s->job_id,
             CONF_KILL_GRACE_S);
        signal_worker(s, SIGKILL);
    }
}

static void terminate(wsup_slot *s)
{
    if (s->term_sent || s->exited)
        return;
    s->term_sent = 1;
    signal_worker(s, SIGTERM);
    uv_timer_start(&s->timer, on_timer, CONF_KILL_GRACE_S * 1000, 0);
}

static void on_alloc(uv_handle_t *h, size_t suggested, uv_buf_t *buf)
{
    (void)h;
    static char chunk[65536];     /* the loop is single-threaded: one read at a time */
    (void)suggested;
    *buf = uv_buf_init(chunk, sizeof chunk);
}

static void take_progress(wsup_slot *s)
{
    if (s->progress_bad)
        return;
    int n = job_progress_take(s->d, s->job_id, &s->in);
    if (n < 0)
        s->progress_bad = 1;
    else if (n > 0 && s->state == PROTO_SLOT_STARTING)
        s->state = PROTO_SLOT_BUSY;
}

static void on_read(uv_stream_t *st, ssize_t n, const uv_buf_t *buf)
{
    wsup_slot *s = st->data;
    if (n > 0) {
        if (!s->progress_bad) {
            proto_buf_put(&s->in, buf->base, (size_t)n);
            take_progress(s);
        }
        return;
    }
    if (n == 0)
        return;
    if (n != UV_EOF)
        dlog(DLOG_WARN, "job %llu: progress pipe: %s", (unsigned long long)s->job_id, uv_strerror((int)n));
    uv_read_stop(st);
    s->eof = 1;
    if (s->exited)
        slot_finish(s);
}

static void on_exit_cb(uv_process_t *p, int64_t status, int sig)
{
    wsup_slot *s = p->data;
    s->exited = 1;
    s->exit_status = status;
    s->term_signal = sig;
    if (s->eof) {
        slot_finish(s);
    } else {
        uv_timer_stop(&s->timer);
        uv_timer_start(&s->timer, on_timer, WSUP_EOF_GRACE_MS, 0);
    }
}

static void on_handle_closed(uv_handle_t *h)
{
    wsup_slot *s = h->data;
    if (--s->open_handles > 0)
        return;
    s->state = PROTO_SLOT_IDLE;
    s->job_id = 0;
    mcd *d = s->d;
    if (d->draining) {
        if (R.drained)
            R.drained(d);             /* the drain closes once nothing else runs either */
    } else {
        wsup_schedule(d);
    }
}

/* The worker died without result.frame or error.frame: the first crash of a
 * job re-queues it, the second fails it (a poison job must not take the
 * slots down forever). The count lives in the job row. */
static int crashed(wsup_slot *s, char *reason, size_t rsz)
{
    char what[160];
    if (s->term_signal)
        snprintf(what, sizeof what, "worker killed by signal %d (%s)", s->term_signal,
                 strsignal(s->term_signal));
    else
        snprintf(what, sizeof what, "worker exited with status %lld without a result",
                 (long long)s->exit_status);
    uint32_t crashes = 1;           /* uncounted (the store is failing): not held against the job */
    if (store_add_crash(s->d->store, s->job_id, &crashes))
        dlog(DLOG_ERROR, "job %llu: cannot count its crash", (unsigned long long)s->job_id);
    if (crashes < WSUP_MAX_CRASHES) {
        snprintf(reason, rsz, "re-queued after crash %u of %d: %s", crashes, WSUP_MAX_CRASHES, what);
        return PROTO_STATE_PENDING;
    }
    snprintf(reason, rsz, "worker crashed twice: %s", what);
    return PROTO_STATE_FAILED;
}

static void pause_starts(void);

static void slot_finish(wsup_slot *s)
{
    if (s->finished)
        return;
    s->finished = 1;
    mcd *d = s->d;
    uv_timer_stop(&s->timer);
    char reason[PROTO_MAX_STRING + 1] = "";
    int state, no_answer = s->term_signal == 0 && s->exit_status == SPOOL_EXIT_NO_ANSWER;
    if (job_has_result(d, s->job_id)) {
        state = PROTO_STATE_COMPLETED;
    } else if (s->requeue) {
        state = PROTO_STATE_PENDING;
        snprintf(reason, sizeof reason, "re-queued: the daemon shut down while it ran");
    } else if (s->timed_out) {
        state = PROTO_STATE_TIMEOUT;
        snprintf(reason, sizeof reason, "wall time limit of %u s exceeded", d->conf.job_timeout_s);
    } else if (s->cancel_requested || (s->term_signal == 0 && s->exit_status == SPOOL_EXIT_CANCELLED)) {
        state = PROTO_STATE_CANCELLED;
        snprintf(reason, sizeof reason, "cancelled by request");
    } else if ((state = job_error_end(d, s->job_id, reason, sizeof reason)) >= 0) {
        /* FAILED, OUT_OF_MEMORY or CANCELLED, as the error.frame says */
    } else if (no_answer) {
        /* the worker could not keep its answer (a full disk): a passing
         * condition, not the job's fault and not a crash */
        state = PROTO_STATE_PENDING;
        snprintf(reason, sizeof reason, "re-queued: the worker could not store its answer (disk full or"
                 " I/O error; its message is in the daemon's log)");
    } else {
        state = crashed(s, reason, sizeof reason);
    }
    job_ended(d, s->job_id, s->user, 1, state, reason);
    if (no_answer && state == PROTO_STATE_PENDING)
        pause_starts();             /* longer each time, until a run ends with an answer */
    else
        R.delay_ms = WSUP_RETRY_MIN_MS;
    if (!uv_is_closing((uv_handle_t *)&s->pipe))
        uv_close((uv_handle_t *)&s->pipe, on_handle_closed);
    if (!uv_is_closing((uv_handle_t *)&s->proc))
        uv_close((uv_handle_t *)&s->proc, on_handle_closed);
}

static void on_retry(uv_timer_t *t)
{
    R.paused = 0;
    wsup_schedule(t->data);
}

static int transient_spawn_error(int uv_err)
{
    return uv_err == UV_EMFILE || uv_err == UV_ENFILE || uv_err == UV_EAGAIN || uv_err == UV_ENOMEM;
}

/* Job id could not start for a passing reason (why): back to the queue,
 * with why as its reason, and starts paused for a while. */
static void start_later(mcd *d, uint64_t id, const char *user, const char *why)
{
    char reason[PROTO_MAX_STRING + 1];
    snprintf(reason, sizeof reason, "waiting to start: %s (retried in %.1f s)", why, (double)R.delay_ms / 1000);
    dlog(DLOG_WARN, "job %llu: %s", (unsigned long long)id, reason);
    job_requeue(d, id, user, 1, reason);
    pause_starts();
}

/* No start for R.delay_ms, which doubles for the next time. */
static void pause_starts(void)
{
    R.paused = 1;
    uv_timer_start(&R.timer, on_retry, R.delay_ms, 0);
    R.delay_ms = R.delay_ms * 2 > WSUP_RETRY_MAX_MS ? WSUP_RETRY_MAX_MS : R.delay_ms * 2;
}

/* Takes job id's worker lock (wlock.c) into *fd: 0, or 1 when the job cannot
 * start now (start_later was called). A holder can only be a worker some
 * earlier daemon left that recovery could not end: it is killed first. */
static int take_worker_lock(mcd *d, uint64_t id, const char *user, int *fd)
{
    char path[CONF_PATH + 64], why[PROTO_MAX_STRING];
    store_spool_path(d->store, id, SPOOL_WORKER_LOCK, path, sizeof path);
    int rc = wlock_take(path, fd);
    if (rc == WLOCK_HELD) {
        int n = wlock_kill_holders(path, WLOCK_START_WAIT_MS);
        dlog(DLOG_WARN, "job %llu: a worker of an earlier daemon still held the job: %s",
             (unsigned long long)id, n > 0 ? "killed" : "still alive");
        rc = n >= 0 ? wlock_take(path, fd) : WLOCK_HELD;
    }
    if (rc == 0)
        return 0;
    if (rc == WLOCK_HELD)
        snprintf(why, sizeof why, "a worker of an earlier daemon still runs it");
    else
        snprintf(why, sizeof why, "cannot lock %.900s: %s", path, strerror(-rc));
    start_later(d, id, user, why);
    return 1;
}

/* The worker's command line for job id in dir; the strings live in *wa. */
typedef struct worker_args {
    char *argv[20];                /* 17 at most, and the NULL */
    char wbuf[PATH_MAX], sid[32], fd[8], thr[16], maxv[16], maxf[16], mem[16], cpu[24];
} worker_args;

static char **worker_argv(mcd *d, uint64_t id, char *dir, worker_args *wa)
{
    char **argv = wa->argv;
    snprintf(wa->sid, sizeof wa->sid, "%llu", (unsigned long long)id);
    snprintf(wa->fd, sizeof wa->fd, "%d", SPOOL_PROGRESS_FD);
    snprintf(wa->thr, sizeof wa->thr, "%d", d->conf.threads_per_worker);
    snprintf(wa->maxv, sizeof wa->maxv, "%u", d->conf.max_vertices);
    snprintf(wa->maxf, sizeof wa->maxf, "%llu", conf_max_faces(&d->conf));
    int k = 0;
    argv[k++] = (char *)conf_worker_path(&d->conf, wa->wbuf, sizeof wa->wbuf);
    argv[k++] = "--job";         argv[k++] = dir;
    argv[k++] = "--job-id";      argv[k++] = wa->sid;
    argv[k++] = "--progress-fd"; argv[k++] = wa->fd;
    argv[k++] = "--max-vertices"; argv[k++] = wa->maxv;
    argv[k++] = "--max-faces";   argv[k++] = wa->maxf;
    if (d->conf.threads_per_worker > 0) {
        argv[k++] = "--threads";
        argv[k++] = wa->thr;
    }
    uint32_t mem_mb = conf_worker_memory_mb(&d->conf, d->conf.workers);
    if (mem_mb > 0) {
        snprintf(wa->mem, sizeof wa->mem, "%u", mem_mb);
        argv[k++] = "--max-memory-mb";
        argv[k++] = wa->mem;
    }
    snprintf(wa->cpu, sizeof wa->cpu, "%llu", wsup_cpu_limit_s(d));
    argv[k++] = "--max-cpu-s";
    argv[k++] = wa->cpu;
    argv[k] = NULL;
    return argv;
}

/* Spawns argv on slot s: its output joins the daemon's log, its progress
 * comes through s->pipe, and it inherits the job's lock lock_fd (closed
 * here: the worker holds it alone). uv_spawn's code. */
static int spawn(wsup_slot *s, char **argv, int lock_fd)
{
    mcd *d = s->d;
    uv_pipe_init(d->loop, &s->pipe, 0);
    s->pipe.data = s;
    s->proc.data = s;
    s->open_handles = 2;
    uv_stdio_container_t stdio[SPOOL_LOCK_FD + 1];
    stdio[0].flags = UV_IGNORE;
    stdio[1].flags = UV_INHERIT_FD;    /* the worker's output joins our log */
    stdio[1].data.fd = 2;
    stdio[2].flags = UV_INHERIT_FD;
    stdio[2].data.fd = 2;
    stdio[SPOOL_PROGRESS_FD].flags = UV_CREATE_PIPE | UV_WRITABLE_PIPE;
    stdio[SPOOL_PROGRESS_FD].data.stream = (uv_stream_t *)&s->pipe;
    stdio[SPOOL_LOCK_FD].flags = UV_INHERIT_FD;   /* the job's lock, held from the fork on */
    stdio[SPOOL_LOCK_FD].data.fd = lock_fd;
    uv_process_options_t opt;
    memset(&opt, 0, sizeof opt);
    opt.file = argv[0];
    opt.args = argv;
    opt.exit_cb = on_exit_cb;
    opt.stdio = stdio;
    opt.stdio_count = SPOOL_LOCK_FD + 1;
    int rc = uv_spawn(d->loop, &s->proc, &opt);
    if (rc == 0)
        wlock_note_pid(lock_fd, (long)s->proc.pid);
    close(lock_fd);                    /* the worker holds the lock now, alone */
    return rc;
}

/* Starts job id on slot s: 0 when the slot took it (or it ended at once),
 * 1 when starts are paused (start_later). */
static int slot_start(wsup_slot *s, uint64_t id, const char *user)
{
    mcd *d = s->d;
    char why[256], dir[CONF_PATH + 64];
    struct statvfs v;
    /* a run on a full disk would compute for nothing: its answer has no room */
    if (statvfs(store_spool_path(d->store, id, NULL, dir, sizeof dir), &v) == 0 &&
        (unsigned long long)v.f_bavail * v.f_frsize < WSUP_MIN_FREE_BYTES) {
        snprintf(why, sizeof why, "the state file system is full (%llu KiB free, at least %u KiB wanted)",
                 (unsigned long long)v.f_bavail * v.f_frsize / 1024, WSUP_MIN_FREE_BYTES / 1024);
        start_later(d, id, user, why);
        return 1;
    }
    int lock_fd;
    if (take_worker_lock(d, id, user, &lock_fd))
        return 1;
    if (store_result_ok(d->store, id, why, sizeof why)) {
        /* a worker finished it while no daemon watched: the answer is there */
        close(lock_fd);
        job_ended(d, id, user, 1, PROTO_STATE_COMPLETED, "finished while the daemon was down: result adopted");
        return 0;
    }
    memset(&s->proc, 0, sizeof s->proc);
    s->job_id = id;
    snprintf(s->user, sizeof s->user, "%s", user);
    s->state = PROTO_SLOT_STARTING;
    s->exited = s->eof = s->finished = 0;
    s->exit_status = 0;
    s->term_signal = 0;
    s->term_sent = s->timed_out = s->cancel_requested = s->requeue = s->progress_bad = 0;
    proto_buf_reset(&s->in);
    store_clear_run(d->store, id);

    worker_args wa;
    char **argv = worker_argv(d, id, dir, &wa);

    int rc = spawn(s, argv, lock_fd);
    if (rc) {
        dlog(DLOG_ERROR, "job %llu: cannot start %s: %s", (unsigned long long)id, argv[0], uv_strerror(rc));
        /* no process: the slot is idle once both handles are closed */
        s->exited = s->eof = s->finished = 1;
        uv_close((uv_handle_t *)&s->pipe, on_handle_closed);
        uv_close((uv_handle_t *)&s->proc, on_handle_closed);
        char reason[PROTO_MAX_STRING];
        snprintf(reason, sizeof reason, "cannot start worker %s: %s", argv[0], uv_strerror(rc));
        if (transient_spawn_error(rc)) {
            start_later(d, id, user, reason);
            return 1;
        }
        job_ended(d, id, user, 1, PROTO_STATE_FAILED, reason);
        return 0;
    }
    dlog(DLOG_INFO, "job %llu: started on slot %d, worker pid %d", (unsigned long long)id, s->index, s->proc.pid);
    job_running(d, id, s->proc.pid);
    uv_read_start((uv_stream_t *)&s->pipe, on_alloc, on_read);
    uv_update_time(d->loop);     /* the wall time counts from now, not the loop's cached time */
    uv_timer_start(&s->timer, on_timer, (uint64_t)d->conf.job_timeout_s * 1000, 0);
    return 0;
}

static void wsup_schedule(mcd *d)
{
    if (d->draining || R.paused)
        return;
    for (int i = 0; i < d->conf.workers; i++) {
        wsup_slot *s = &d->slots[i];
        if (s->state != PROTO_SLOT_IDLE)
            continue;
        char user[AUTH_MAX_USER];
        uint64_t id = sched_next(d->sched, user);
        if (!id || slot_start(s, id, user))
            return;
    }
}

static int wsup_cancel(mcd *d, uint64_t id)
{
    for (int i = 0; i < d->conf.workers; i++) {
        wsup_slot *s = &d->slots[i];
        if (s->state != PROTO_SLOT_IDLE && s->job_id == id && !s->finished) {
            s->cancel_requested = 1;
            terminate(s);
            return 0;
        }
    }
    return -1;
}

static void wsup_drain(mcd *d, mcd_idle_fn idle)
{
    R.drained = idle;
    for (int i = 0; i < d->conf.workers; i++) {
        wsup_slot *s = &d->slots[i];
        if (s->state != PROTO_SLOT_IDLE && !s->finished) {
            s->requeue = 1;
            s->state = PROTO_SLOT_DRAINING;
            terminate(s);
        }
    }
}

static int wsup_busy(const mcd *d)
{
    int n = 0;
    for (int i = 0; i < d->conf.workers; i++)
        n += d->slots[i].state != PROTO_SLOT_IDLE;
    return n;
}

static void wsup_slot_info(const mcd *d, int i, uint8_t *state, uint64_t *job_id)
{
    *state = d->slots[i].state;
    *job_id = d->slots[i].job_id;
}

static void wsup_close(mcd *d)
{
    if (R.open) {
        R.open = 0;
        uv_close((uv_handle_t *)&R.timer, NULL);
    }
    if (!d->slots)
        return;
    for (int i = 0; i < d->conf.workers; i++) {
        uv_close((uv_handle_t *)&d->slots[i].timer, NULL);
        proto_buf_free(&d->slots[i].in);
    }
}

static int wsup_nslots(const mcd *d)
{
    return d->conf.workers;
}

static int wsup_health(const mcd *d, char *msg, size_t sz)
{
    char buf[PATH_MAX];
    const char *w = conf_worker_path(&d->conf, buf, sizeof buf);
    if (access(w, X_OK) != 0) {
        snprintf(msg, sz, "worker program %s is not executable", w);
        return 0;
    }
    snprintf(msg, sz, "%d worker slot(s), %d busy", d->conf.workers, wsup_busy(d));
    return 1;
}

/* The slots are allocated once. */
static void wsup_keep_on_reload(const mcd *d, mcd_conf *n, char *changed, size_t sz)
{
    conf_note_change(n->workers != d->conf.workers, "workers", changed, sz);
    n->workers = d->conf.workers;
}

const bk_ops bk_local = {
    "local", wsup_init, wsup_schedule, wsup_cancel, wsup_drain, wsup_busy,
    wsup_nslots, wsup_slot_info, wsup_health, wsup_close, wsup_keep_on_reload,
};
