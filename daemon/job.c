/* job.c — one owner of a job's life once it is stored: its start, its
 * progress and its end are recorded here and nowhere else (the backends
 * decide from what their worker left and call these; backend.h), a pending
 * job's cancel too (a running one's is handed to its backend); and its last step, the deletion of a finished job
 * result-ttl after its end (the expiry sweep). It calls only the store and the
 * scheduler; who tells the watchers (req.c) listens (job_listen), so no
 * call goes back up; an end is also queued for its user's --notify-url (hook.c).
 *
 * DESIGN: a job's end is recorded before anyone is told. job_ended writes
 * the state to the store, then sends END to the watchers; a run to do again
 * (PENDING) goes back to the scheduler. When the store cannot take the end
 * (a full disk: SQLite says SQLITE_FULL), the end is kept here and written
 * again every JOB_RECORD_RETRY_MS until it is; meanwhile the store still
 * says RUNNING and the watchers wait, so nobody is told an end the store
 * does not have. A daemon that stops first loses nothing: the next start's
 * recovery adopts the run's result.frame or runs the job again. What the
 * files of a run say (result.frame; error.frame: FAILED, OUT_OF_MEMORY for
 * NOMEM, CANCELLED for CANCELLED) is read here for both backends.
 *
 * The way back to the queue is one (job_requeue), whoever sends a job
 * back; and what becomes of the jobs a stopped daemon left unfinished is
 * decided here too (job_recover), the store doing the writing. */
#include "backend.h"
#include "mcd.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define JOB_RECORD_RETRY_MS 1000
#define JOB_MAX_ERROR_FRAME (1 << 20)  /* an error.frame is one ERROR: a short message */

typedef struct unrecorded unrecorded;
struct unrecorded {
    uint64_t id;
    int state;
    char reason[PROTO_MAX_STRING + 1];
    unrecorded *next;
};

static struct {
    mcd *d;
    uv_timer_t timer;
    int open;
    unrecorded *ends;             /* ends the store has not taken yet, oldest first */
    uv_timer_t sweep;             /* result expiry */
    uint64_t progress_failed;     /* job whose progress the store refused (logged once) */
    job_listener l;               /* who tells the watchers (req.c) */
    snap_hist duration, wait;     /* runs: start to end; submit to start */
} J;

static void observe(snap_hist *h, double s)
{
    static const double bounds[SNAP_NBUCKETS] = SNAP_BUCKETS;
    int b = 0;
    while (b < SNAP_NBUCKETS && s > bounds[b])
        b++;
    h->bucket[b]++;
    h->count++;
    h->sum += s;
}

void job_times(snap_hist *duration, snap_hist *wait)
{
    *duration = J.duration;
    *wait = J.wait;
}

static void tell_ended(mcd *d, uint64_t id)
{
    store_job j;
    if (store_get(d->store, id, &j) == 0 && j.start_ms && j.end_ms >= j.start_ms)
        observe(&J.duration, (double)(j.end_ms - j.start_ms) / 1000);
    if (J.l.ended)
        J.l.ended(d, id);
    hook_job_ended(d, id);
}

static void tell_queue(mcd *d)
{
    if (J.l.queue)
        J.l.queue(d);
}

static void on_retry(uv_timer_t *t)
{
    (void)t;
    int left = 0;
    for (unrecorded **pu = &J.ends; *pu;) {
        unrecorded *u = *pu;
        if (store_set_state(J.d->store, u->id, u->state, u->reason) != 0) {
            left++;
            pu = &u->next;
            continue;
        }
        dlog(DLOG_INFO, "job %llu: %s recorded (the store takes writes again)", (unsigned long long)u->id,
             proto_state_name(u->state));
        *pu = u->next;
        tell_ended(J.d, u->id);
        free(u);
    }
    if (!left)
        uv_timer_stop(&J.timer);
}

void job_init(mcd *d)
{
    memset(&J, 0, sizeof J);
    J.d = d;
    uv_timer_init(d->loop, &J.timer);
    uv_timer_init(d->loop, &J.sweep);
    J.open = 1;
}

static int expire_one(void *ctx, const store_job *j)
{
    mcd *d = ctx;
    dlog(DLOG_INFO, "job %llu: %s result older than %u s: deleted", (unsigned long long)j->id,
         proto_state_name(j->state), d->conf.result_ttl_s);
    store_delete(d->store, j->id);
    return 0;
}

static void on_sweep(uv_timer_t *t)
{
    (void)t;
    mcd *d = J.d;
    store_each_expired(d->store, store_now_ms() - (int64_t)d->conf.result_ttl_s * 1000, expire_one, d);
}

void job_sweep_start(mcd *d)
{
    /* every minute, or every result-ttl when that is shorter */
    uint64_t every = d->conf.result_ttl_s < 60 ? d->conf.result_ttl_s * 1000ull : 60000;
    uv_timer_start(&J.sweep, on_sweep, 0, every);
}

void job_close(mcd *d)
{
    (void)d;
    int n = 0;
    while (J.ends) {
        unrecorded *u = J.ends;
        J.ends = u->next;
        free(u);
        n++;
    }
    if (n)
        dlog(DLOG_WARN, "%d job end(s) never reached the store: the next start recovers those jobs"
             " (a result is adopted, else they run again)", n);
    if (J.open) {
        uv_close((uv_handle_t *)&J.timer, NULL);
        uv_close((uv_handle_t *)&J.sweep, NULL);
    }
    J.open = 0;
}

void job_running(mcd *d, uint64_t id, long pid)
{
    int64_t now = store_now_ms();
    store_job j;
    if (store_get(d->store, id, &j) == 0 && j.submit_ms && now >= j.submit_ms)
        observe(&J.wait, (double)(now - j.submit_ms) / 1000);
    if (store_set_running(d->store, id, now, pid))
        dlog(DLOG_ERROR, "job %llu: cannot record it RUNNING (the store is failing)", (unsigned long long)id);
    tell_queue(d);
}

void job_listen(mcd *d, const job_listener *l)
{
    (void)d;
    J.l = *l;
}

static void progress(mcd *d, const proto_progress *p)
{
    if (store_add_progress(d->store, p->job_id, p) == 0) {
        if (J.progress_failed == p->job_id)
            J.progress_failed = 0;
    } else if (J.progress_failed != p->job_id) {
        J.progress_failed = p->job_id;
        dlog(DLOG_ERROR, "job %llu: cannot store its progress (more failures of this job's are not logged)",
             (unsigned long long)p->job_id);
    }
    if (J.l.progress)
        J.l.progress(d, p);
}

int job_progress_take(mcd *d, uint64_t id, proto_buf *in)
{
    int n = 0;
    while (in->len) {
        proto_msg m;
        size_t used = 0;
        char err[256];
        int rc = proto_decode(in->data, in->len, JOB_MAX_PROGRESS_FRAME, &m, &used, err, sizeof err);
        if (rc == PROTO_NEED_MORE)
            return n;
        if (rc != PROTO_READY || m.type != PROTO_MSG_PROGRESS) {
            dlog(DLOG_WARN, "job %llu: bad progress frame from the worker (%s): ignoring its progress",
                 (unsigned long long)id, rc ? err : proto_type_name(m.type));
            if (rc == PROTO_READY)
                proto_msg_free(&m);
            proto_buf_reset(in);
            return -1;
        }
        proto_progress p = m.u.progress;
        proto_msg_free(&m);
        proto_buf_consume(in, used);
        p.job_id = id;
        progress(d, &p);
        n++;
    }
    return n;
}

/* A terminal state into the store, then END to the watchers; kept and
 * retried while the store refuses it. */
static void record_end(mcd *d, uint64_t id, int state, const char *reason)
{
    if (store_set_state(d->store, id, state, reason) == 0) {
        tell_ended(d, id);
        return;
    }
    unrecorded *u = J.open ? calloc(1, sizeof *u) : NULL;
    if (!u) {
        dlog(DLOG_ERROR, "job %llu: cannot record its end%s: the next start recovers it", (unsigned long long)id,
             J.open ? ", and out of memory to retry" : " (shutting down)");
        return;
    }
    u->id = id;
    u->state = state;
    snprintf(u->reason, sizeof u->reason, "%s", reason);
    unrecorded **pu = &J.ends;
    while (*pu)
        pu = &(*pu)->next;
    *pu = u;
    dlog(DLOG_ERROR, "job %llu: cannot record its end (%s): retried every %d ms; it reads RUNNING until then",
         (unsigned long long)id, proto_state_name(state), JOB_RECORD_RETRY_MS);
    if (!uv_is_active((uv_handle_t *)&J.timer))
        uv_timer_start(&J.timer, on_retry, JOB_RECORD_RETRY_MS, JOB_RECORD_RETRY_MS);
}

/* A COMPLETED end waits for the map's quality, read from result.frame in
 * the thread pool (it may be megabytes), so that the row says how good the
 * map is from the moment it says COMPLETED (LIST, STATUS). */
typedef struct quality_read {
    uv_work_t work;
    mcd *d;                       /* loop side only */
    const store *store;
    uint64_t id;
    char reason[PROTO_MAX_STRING + 1];
    int verdict;
    double flipped, collapsed;
} quality_read;

static void quality_run(uv_work_t *w)     /* thread pool */
{
    quality_read *q = w->data;
    proto_msg m;
    uint8_t *buf;
    char why[256];
    if (store_result_read(q->store, q->id, &m, &buf, why, sizeof why) == 0) {
        store_result_quality(&m, &q->verdict, &q->flipped, &q->collapsed);
        proto_msg_free(&m);
        free(buf);
    }
}

static void quality_done(uv_work_t *w, int status)    /* loop */
{
    (void)status;
    quality_read *q = w->data;
    if (q->verdict >= 0 && store_set_quality(q->d->store, q->id, q->verdict, q->flipped, q->collapsed))
        dlog(DLOG_WARN, "job %llu: cannot record its map's quality", (unsigned long long)q->id);
    record_end(q->d, q->id, PROTO_STATE_COMPLETED, q->reason);
    free(q);
}

void job_ended(mcd *d, uint64_t id, const char *user, int counted, int state, const char *reason)
{
    dlog(DLOG_INFO, "job %llu: %s%s%s", (unsigned long long)id, proto_state_name(state),
         reason[0] ? ": " : "", reason);
    if (counted)
        sched_done(d->sched, user);
    if (!store_is_terminal(state)) {
        job_requeue(d, id, user, 0, reason);
        tell_queue(d);
        return;
    }
    if (counted)
        tell_queue(d);          /* one running job fewer: the fair share's order moves */
    quality_read *q = state == PROTO_STATE_COMPLETED ? calloc(1, sizeof *q) : NULL;
    if (q) {
        q->work.data = q;
        q->d = d;
        q->store = d->store;
        q->id = id;
        q->verdict = -1;
        snprintf(q->reason, sizeof q->reason, "%s", reason);
        if (uv_queue_work(d->loop, &q->work, quality_run, quality_done) == 0)
            return;
        free(q);
    }
    record_end(d, id, state, reason);
}

int job_requeue(mcd *d, uint64_t id, const char *user, int counted, const char *reason)
{
    if (counted)
        sched_done(d->sched, user);
    /* the scheduler has it even if the store cannot say so */
    if (reason && store_set_state(d->store, id, PROTO_STATE_PENDING, reason))
        dlog(DLOG_ERROR, "job %llu: cannot record it PENDING again", (unsigned long long)id);
    store_job j;
    if (store_get(d->store, id, &j) != 0 || sched_add(d->sched, id, user, j.priority) != 0) {
        dlog(DLOG_ERROR, "job %llu: cannot put it back in the queue: it runs after the next restart",
             (unsigned long long)id);
        return -1;
    }
    return 0;
}

int job_cancel_pending(mcd *d, uint64_t id)
{
    sched_remove(d->sched, id);
    if (store_set_state(d->store, id, PROTO_STATE_CANCELLED, "cancelled by request before it ran"))
        return PROTO_ESTORAGE;
    dlog(DLOG_INFO, "job %llu: CANCELLED while pending", (unsigned long long)id);
    tell_ended(d, id);
    tell_queue(d);
    return 0;
}

/* A worker's error.frame at path: its protocol error code and message
 * (msg); 0 when there is none, PROTO_EINTERNAL when it does not decode.
 * Loop thread only (one static buffer). */
static int read_error_frame(const char *path, char *msg, size_t msz)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return 0;
    static uint8_t buf[JOB_MAX_ERROR_FRAME];
    size_t n = fread(buf, 1, sizeof buf, fp);
    fclose(fp);
    proto_msg m;
    size_t used;
    char err[256];
    int code = PROTO_EINTERNAL;
    if (proto_decode(buf, n, sizeof buf, &m, &used, err, sizeof err) == PROTO_READY &&
        m.type == PROTO_MSG_ERROR) {
        code = m.u.error.code;
        snprintf(msg, msz, "%s", m.u.error.message);
    } else {
        snprintf(msg, msz, "worker wrote an unreadable error.frame");
    }
    proto_msg_free(&m);
    return code;
}

int job_has_result(mcd *d, uint64_t id)
{
    char path[CONF_PATH + 64];
    return access(store_spool_path(d->store, id, SPOOL_RESULT_FRAME, path, sizeof path), R_OK) == 0;
}

int job_error_end(mcd *d, uint64_t id, char *reason, size_t rsz)
{
    char path[CONF_PATH + 64], emsg[PROTO_MAX_STRING + 1] = "";
    int code = read_error_frame(store_spool_path(d->store, id, SPOOL_ERROR_FRAME, path, sizeof path),
                              emsg, sizeof emsg);
    if (!code)
        return -1;
    snprintf(reason, rsz, "%s: %s", proto_err_name(code), emsg);
    return code == PROTO_ENOMEM ? PROTO_STATE_OUT_OF_MEMORY
         : code == PROTO_ECANCELLED ? PROTO_STATE_CANCELLED : PROTO_STATE_FAILED;
}

/* ---- recovery after a restart ------------------------------------------- */

typedef struct left_job {
    uint64_t id;
    int state;
    int slurm;                    /* has a Slurm job id */
} left_job;

typedef struct left_jobs {
    left_job *j;
    size_t n;
    int nomem;
} left_jobs;

static int collect_left(void *ctx, const store_job *j)
{
    left_jobs *l = ctx;
    left_job *t = realloc(l->j, (l->n + 1) * sizeof *t);
    if (!t) {
        l->nomem = 1;
        return 1;
    }
    l->j = t;
    l->j[l->n++] = (left_job){j->id, j->state, j->slurm_id[0] != '\0'};
    return 0;
}

/* A worker finished job id while no daemon watched: its result.frame is
 * complete (written atomically) and, when it decodes, the job's answer;
 * running the job again would only redo the work. 1 adopted, 0 not (no
 * usable result), -1 when the store cannot record it. */
static int adopt_result(store *s, uint64_t id)
{
    char path[CONF_PATH + 64], why[256];
    if (access(store_spool_path(s, id, SPOOL_RESULT_FRAME, path, sizeof path), F_OK) != 0)
        return 0;
    proto_msg m;
    uint8_t *buf;
    if (store_result_read(s, id, &m, &buf, why, sizeof why)) {
        dlog(DLOG_WARN, "store: job %llu: result.frame left by a worker is not usable (%s): runs again",
             (unsigned long long)id, why);
        return 0;
    }
    int verdict;
    double flipped, collapsed;
    store_result_quality(&m, &verdict, &flipped, &collapsed);
    proto_msg_free(&m);
    free(buf);
    if (verdict >= 0)
        store_set_quality(s, id, verdict, flipped, collapsed);
    if (store_set_state(s, id, PROTO_STATE_COMPLETED, "finished while the daemon was down: result adopted"))
        return -1;
    dlog(DLOG_INFO, "store: job %llu: COMPLETED: its worker finished while the daemon was down; result adopted",
         (unsigned long long)id);
    return 1;
}

int job_recover(store *s, int keep_slurm, char *err, size_t errsz)
{
    int rc = store_kill_orphan_workers(s, err, errsz);
    if (rc)
        return rc;
    left_jobs l = {0};
    if (store_each_unfinished(s, collect_left, &l) || l.nomem) {
        free(l.j);
        return errbuf_set(err, errsz, PROTO_ESTORAGE, "recover: cannot read the unfinished jobs%s",
                          l.nomem ? " (out of memory)" : "");
    }
    int unslurmed = 0, adopted = 0, requeued = 0, lost = 0;
    for (size_t i = 0; i < l.n && !rc; i++) {
        left_job *j = &l.j[i];
        char path[CONF_PATH + 64];
        if (j->slurm && !keep_slurm) {      /* Slurm runs without the Slurm backend: they run here again */
            if (store_set_pending(s, j->id)) {
                rc = errbuf_set(err, errsz, PROTO_ESTORAGE, "recover: cannot re-queue Slurm jobs");
                break;
            }
            j->slurm = 0;
            j->state = PROTO_STATE_PENDING;
            unslurmed++;
        }
        if (!j->slurm) {
            int a = adopt_result(s, j->id);
            if (a < 0)
                rc = errbuf_set(err, errsz, PROTO_ESTORAGE, "recover: cannot record job %llu's adopted result",
                                (unsigned long long)j->id);
            adopted += a > 0;
            if (a)
                continue;
            if (j->state == PROTO_STATE_RUNNING) {   /* the run was cut off by the daemon's end */
                if (store_set_pending(s, j->id)) {
                    rc = errbuf_set(err, errsz, PROTO_ESTORAGE, "recover: cannot re-queue running jobs");
                    break;
                }
                j->state = PROTO_STATE_PENDING;
                requeued++;
            }
        }
        /* a Slurm run goes on without us and is re-attached by the backend;
         * any job still to start needs its input */
        if (j->state == PROTO_STATE_PENDING &&
            access(store_spool_path(s, j->id, SPOOL_JOB_FRAME, path, sizeof path), R_OK) != 0) {
            dlog(DLOG_WARN, "store: job %llu has no spool/job.frame: FAILED", (unsigned long long)j->id);
            store_set_state(s, j->id, PROTO_STATE_FAILED, "spool file job.frame missing after restart");
            lost++;
        }
    }
    free(l.j);
    if (unslurmed)
        dlog(DLOG_WARN, "store: %d job(s) handed to Slurm by an earlier run go back to the queue"
             " (backend is not slurm)", unslurmed);
    int removed, dropped;
    if (rc || (rc = store_tidy_spool(s, &removed, &dropped, err, errsz)))
        return rc;
    dlog(DLOG_INFO, "store: recovered: %d result(s) adopted, %d running job(s) re-queued, %d orphan spool"
         " dir(s) removed, %d job(s) without spool failed, %d ended job(s)' input removed", adopted, requeued,
         removed, lost, dropped);
    return 0;
}
