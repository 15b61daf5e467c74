/* req.c — one handler per request type (PROTOCOL.md, Messages) and the
 * WATCH registry. Handlers check the session, the job's visibility and state,
 * act through store_/sched_/job_/bk_, and answer through srv_send. Never
 * reads a socket, never blocks on a client. It hears of a running job's
 * progress and end from job.c (req_init listens), and fans them out.
 *
 * DESIGN: visibility — a non-admin session sees only its user's jobs, and
 * any other job is NOT_FOUND, exactly like a job that never existed, so ids
 * do not leak. SUBMIT answers SUBMIT_OK only after store_submit returned 0
 * (row committed, spool fsynced); QUEUE_FULL, USER_LIMIT and OVER_QUOTA
 * refuse before anything is stored, counting the SUBMITs still being
 * checked or stored, and so does FORBIDDEN for a user's priority above 0.
 *
 * DESIGN: fair limits per user (README, Quotas): stored bytes per user and
 * in all (check_quota, from the store's per-job byte counts), live WATCHes
 * per connection, RESULT replies in flight in all and per user (the
 * RESULT section below); each refusal names the user, the figures and the
 * option, and is logged.
 * Before the store, val_submit has a short-lived meshcorr-validate child
 * decode and check the meshes, the landmarks against
 * them, the maps and the parameters, so a job that can never run is refused
 * naming the blob or field and nothing is stored. Draco bytes are never
 * decoded in this process.
 *
 * DESIGN: the loop never waits for the disk or a child on a client's behalf.
 * SUBMIT's val_submit and store_submit (spool file, fsyncs, commit) and RESULT's read and decode of
 * result.frame run in libuv's thread pool (uv_queue_work). A work callback
 * touches only its own work item: copies of what it needs, the request's
 * frame (kept in place by srv_conn_hold) and, for SUBMIT, the store's
 * thread-safe store_submit. Its after callback, on the loop, does the rest:
 * the scheduler, the log, the reply, bk_schedule. The connection is held
 * while its work is in flight, so it is not read (one request at a time,
 * replies in order, at most one work item per client) and its memory
 * outlives a close; a client that left gets no reply, but its SUBMIT, once
 * stored, is queued and runs. d->work_inflight counts the work items; a
 * drain closes the daemon only when it is 0 (req_quiesce: told at each
 * work item's end). */
#include "backend.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/statvfs.h>
#include <unistd.h>

#define REQ_LIST_PAGE 1000
#define REQ_REFUSAL_LOG_MS 1000   /* a flood of one kind of refusal logs one line per this */

struct req_watch {
    conn *c;                      /* NULL once the connection is gone */
    uint32_t request_id;
    uint64_t job_id;
    uint32_t from_outer;
    int64_t ahead;                /* the place in the queue last sent; -1 none */
    req_watch *next;
};

static int iterating;             /* fan-out in progress: unlink watches later */
static void on_queue(mcd *d);
static mcd_idle_fn quiesced;      /* a drain waits for the work items */

static void prune(mcd *d)
{
    if (iterating)
        return;
    for (req_watch **pw = &d->watches; *pw;) {
        if (!(*pw)->c) {
            req_watch *dead = *pw;
            *pw = dead->next;
            free(dead);
        } else {
            pw = &(*pw)->next;
        }
    }
}

static void results_end(mcd *d, conn *c, int closing);

void req_conn_closed(mcd *d, conn *c)
{
    for (req_watch *w = d->watches; w; w = w->next)
        if (w->c == c)
            w->c = NULL;
    prune(d);
    results_end(d, c, 1);
}

int req_conn_watching(const mcd *d, const conn *c)
{
    for (const req_watch *w = d->watches; w; w = w->next)
        if (w->c == c)
            return 1;
    return 0;
}

static void reply(conn *c, proto_msg *m, uint32_t request_id)
{
    m->request_id = request_id;
    srv_send(c, m, 0);
}

static void reply_id(conn *c, int type, uint32_t request_id, uint64_t id)
{
    proto_msg m;
    memset(&m, 0, sizeof m);
    m.type = (uint8_t)type;
    m.u.ok.job_id = id;
    reply(c, &m, request_id);
}

/* The job if this session may see it; else NOT_FOUND already answered. */
static int visible_job(conn *c, uint32_t rid, uint64_t id, store_job *j)
{
    conn_auth *a = srv_conn_auth(c);
    int rc = store_get(srv_conn_daemon(c)->store, id, j);
    if (rc == 0 && (a->admin || strcmp(j->user, a->user) == 0))
        return 0;
    if (rc == 0 || rc == PROTO_ENOT_FOUND)
        srv_send_error(c, rid, PROTO_ENOT_FOUND, "no job %llu", (unsigned long long)id);
    else
        srv_send_error(c, rid, rc, "job store failure reading job %llu", (unsigned long long)id);
    return -1;
}

/* HELLO: the Unix socket's peer credentials, or a token, whose SHA-256 is
 * looked up (the plaintext is wiped from the request at once). An address
 * that failed too often is refused without a look at its token
 * (throttle.c); every failure is counted there and logged with the
 * address. */
static void on_hello(conn *c, const proto_msg *m)
{
    mcd *d = srv_conn_daemon(c);
    conn_auth *a = srv_conn_auth(c);
    const proto_hello *h = &m->u.hello;
    char err[256];
    if (a->authed) {
        srv_send_error(c, m->request_id, PROTO_EUNEXPECTED, "HELLO already done on this connection");
        return;
    }
    int rc;
    uint64_t now = uv_now(d->loop);
    if (a->is_unix && h->token[0] == '\0') {
        rc = auth_peer_user(srv_conn_fd(c), d->conf.admin_uid, a->user, &a->admin, err, sizeof err);
        if (rc)
            dlog(DLOG_WARN, "HELLO from %s refused: %s (client '%s')", a->peer, err, h->client);
    } else {
        uint32_t wait = throttle_check(a->peer, now);
        if (wait) {
            explicit_bzero((char *)h->token, strlen(h->token));
            srv_send_error(c, m->request_id, PROTO_EBUSY, "too many failed logins from %s: retry in %u s",
                           a->peer, wait);
            srv_close_soon(c);
            return;
        }
        int given = h->token[0] != '\0';
        rc = auth_token_hash(h->token, a->token_hash);
        explicit_bzero((char *)h->token, strlen(h->token));
        if (rc == 0 && (rc = auth_token_user(d->tokens, a->token_hash, a->user, &a->admin)) == 0) {
            a->by_token = 1;
        } else {
            snprintf(err, sizeof err, "%s", given ? "unknown token" : "no token");
            throttle_fail(a->peer, h->client, err, now);
        }
    }
    if (rc) {
        srv_send_error(c, m->request_id, PROTO_EUNAUTHORIZED, "authentication failed: %s", err);
        srv_close_soon(c);
        return;
    }
    if ((rc = srv_conn_admit_user(c, err, sizeof err)) != 0) {
        srv_send_error(c, m->request_id, rc, "%s", err);
        srv_close_soon(c);
        return;
    }
    a->authed = 1;
    dlog(DLOG_INFO, "session: user %s%s from %s, client '%s' (protocol %u)", a->user, a->admin ? " (admin)" : "",
         a->peer, h->client, h->version);
    proto_msg r;
    memset(&r, 0, sizeof r);
    r.type = PROTO_MSG_HELLO_OK;
    r.u.hello_ok.version = PROTO_VERSION;
    r.u.hello_ok.user = a->user;
    r.u.hello_ok.admin = (uint8_t)a->admin;
    r.u.hello_ok.limits = (proto_limits){d->conf.max_frame, d->conf.max_vertices, d->conf.max_landmarks,
                                         d->conf.max_jobs_per_user, d->conf.max_queue, d->conf.job_timeout_s};
    reply(c, &r, m->request_id);
}

/* What the daemon checks itself, on the loop, before the validator child
 * (val_submit) checks the rest: blobs present, the server's landmark limit,
 * and every parameter with the one validator (proto_params_check, the
 * worker's and the CLI's too). 0 or a code with msg. */
static int check_submit(const mcd *d, const proto_submit *s, char *msg, size_t msz)
{
    const mcd_conf *cf = &d->conf;
    if (s->source.len == 0 || s->target.len == 0)
        return snprintf(msg, msz, "%s mesh: no Draco bytes", s->source.len ? "target" : "source"), PROTO_EBAD_MESH;
    if (s->nlandmarks > cf->max_landmarks)
        return snprintf(msg, msz, "landmarks: %u pairs, over the server's limit (%u)", s->nlandmarks,
                        cf->max_landmarks), PROTO_EBAD_LANDMARKS;
    return proto_params_check(&s->params, msg, msz);
}

/* ---- work in the thread pool ----------------------------------------------- */

static int work_start(mcd *d, conn *c, uv_work_t *w, uv_work_cb run, uv_after_work_cb after)
{
    int rc = uv_queue_work(d->loop, w, run, after);
    if (rc)
        return rc;
    d->work_inflight++;
    srv_conn_hold(c);
    return 0;
}

/* The end of an after callback: the connection reads its next request, and
 * a drain may now be complete. */
static void work_end(mcd *d, conn *c)
{
    srv_conn_release(c);
    d->work_inflight--;
    if (quiesced)
        quiesced(d);
}

void req_quiesce(mcd *d, mcd_idle_fn idle)
{
    (void)d;
    quiesced = idle;
}

/* A SUBMIT being stored: everything store_submit needs, copied, so the
 * thread-pool side touches nothing else. */
struct req_submit {
    uv_work_t work;
    mcd *d;                       /* loop side only */
    conn *c;                      /* loop side only; held */
    req_submit *next;             /* d->submits */
    store *store;                 /* the one daemon object the work uses */
    uint32_t request_id;
    const void *frame;            /* in c's read buffer, kept by the hold */
    size_t len;
    char user[AUTH_MAX_USER];
    char label[PROTO_MAX_STRING + 1];
    int32_t priority;
    uint32_t total;
    char params[1024];            /* the parameters, for the log and the row */
    val_conf vc;                  /* the validator's program and limits */
    double val_ms, val_cpu_ms;    /* how long the check took, and its CPU time */
    int refused;                  /* rc is val_submit's: nothing was stored */
    int rc;                       /* store_submit's result, */
    uint64_t id;                  /* its job id */
    char msg[PROTO_MAX_STRING];   /* or its error */
};

/* SUBMITs of user (NULL: of everyone) still being stored. */
static uint32_t submits_in_flight(const mcd *d, const char *user)
{
    uint32_t n = 0;
    for (const req_submit *s = d->submits; s; s = s->next)
        n += !user || strcmp(s->user, user) == 0;
    return n;
}

/* Frame bytes of the SUBMITs of user (NULL: of everyone) still being stored. */
static int64_t submit_bytes_in_flight(const mcd *d, const char *user)
{
    int64_t n = 0;
    for (const req_submit *s = d->submits; s; s = s->next)
        if (!user || strcmp(s->user, user) == 0)
            n += (int64_t)s->len;
    return n;
}

/* The spool's cap: --max-spool-bytes, or CONF_SPOOL_SHARE_PERCENT of the
 * state file system's size (what stands there besides the spool is the
 * operator's); 0 when neither can be had. how (for the message) says which. */
static int64_t spool_cap(const mcd *d, char *how, size_t hsz)
{
    struct statvfs v;
    how[0] = '\0';
    if (d->conf.max_spool_bytes)
        return d->conf.max_spool_bytes;
    if (statvfs(d->conf.state_dir, &v) != 0)
        return 0;
    snprintf(how, hsz, " (%d %% of the state file system)", CONF_SPOOL_SHARE_PERCENT);
    return (int64_t)((double)v.f_blocks * (double)v.f_frsize * CONF_SPOOL_SHARE_PERCENT / 100);
}

/* The byte quotas of a SUBMIT of len bytes by user: the user's stored bytes
 * (jobs and results in the spool, and SUBMITs being stored) under
 * --max-bytes-per-user, and everyone's under the spool's cap. 0, or
 * PROTO_EOVER_QUOTA (PROTO_ESTORAGE when the store cannot count) with the
 * message in msg. */
static int check_quota(const mcd *d, const char *user, size_t len, char *msg, size_t msz)
{
    int64_t mine, all;
    if (store_bytes(d->store, user, &mine) || store_bytes(d->store, NULL, &all))
        return snprintf(msg, msz, "job store failure counting the spool's bytes; nothing stored"), PROTO_ESTORAGE;
    mine += submit_bytes_in_flight(d, user);
    all += submit_bytes_in_flight(d, NULL);
    if (mine + (int64_t)len > d->conf.max_bytes_per_user)
        return snprintf(msg, msz, "over quota: user %s stores %lld bytes of jobs and results, and this %zu-byte"
                        " SUBMIT would pass --max-bytes-per-user %ld; delete finished jobs to make room",
                        user, (long long)mine, len, d->conf.max_bytes_per_user), PROTO_EOVER_QUOTA;
    char how[64];
    int64_t cap = spool_cap(d, how, sizeof how);
    if (cap && all + (int64_t)len > cap)
        return snprintf(msg, msz, "over quota: the spool holds %lld bytes of jobs and results, and this %zu-byte"
                        " SUBMIT would pass --max-spool-bytes %lld%s; retry once jobs are deleted or expire",
                        (long long)all, len, (long long)cap, how), PROTO_EOVER_QUOTA;
    return 0;
}

static void submit_run(uv_work_t *w)      /* thread pool */
{
    req_submit *s = w->data;
    if ((s->rc = val_submit(&s->vc, s->frame, s->len, &s->val_ms, &s->val_cpu_ms, s->msg, sizeof s->msg))) {
        s->refused = 1;
        return;
    }
    s->rc = store_submit(s->store, s->user, s->label, s->priority, s->total, s->params, s->frame, s->len,
                         &s->id, s->msg, sizeof s->msg);
}

/* msg for a client: the server's own paths (a word that starts with '/'
 * or with the state directory, up to a ':' or blank) become "<path>".
 * The log keeps the whole message. */
static const char *without_paths(const mcd *d, const char *msg, char *out, size_t sz)
{
    const char *dir = d->conf.state_dir;
    size_t dl = strlen(dir), o = 0;
    for (const char *p = msg; *p && o + 8 < sz;) {
        int word_start = p == msg || p[-1] == ' ' || p[-1] == '(' || p[-1] == '\'';
        if (word_start && (*p == '/' || (dl && strncmp(p, dir, dl) == 0))) {
            p += strcspn(p, ": ),'");
            memcpy(out + o, "<path>", 6);
            o += 6;
        } else {
            out[o++] = *p++;
        }
    }
    out[o] = '\0';
    return out;
}

static void submit_done(uv_work_t *w, int status)    /* loop */
{
    req_submit *s = w->data;
    mcd *d = s->d;
    conn *c = s->c;
    for (req_submit **p = &d->submits; *p; p = &(*p)->next)
        if (*p == s) {
            *p = s->next;
            break;
        }
    if (status < 0) {                       /* never ran: nothing stored */
        s->rc = PROTO_EINTERNAL;
        snprintf(s->msg, sizeof s->msg, "the store's work was not run: %s", uv_strerror(status));
    }
    char shown[sizeof s->msg];           /* a STORAGE message without the server's paths */
    if (s->refused) {
        dlog(s->rc == PROTO_EINTERNAL ? DLOG_ERROR : DLOG_INFO, "SUBMIT from %s refused (%s, checked in %.1f ms, %.1f ms CPU): %s",
             s->user, proto_err_name(s->rc), s->val_ms, s->val_cpu_ms, s->msg);
        srv_send_error(c, s->request_id, s->rc, "%s", s->msg);
    } else if (s->rc) {
        dlog(DLOG_ERROR, "SUBMIT from %s: %s", s->user, s->msg);
        srv_send_error(c, s->request_id, s->rc, "job not stored: %s", without_paths(d, s->msg, shown, sizeof shown));
    } else {
        unsigned long long id = (unsigned long long)s->id;
        store_job j;
        /* an admin may have cancelled it by id since the commit */
        if (store_get(d->store, s->id, &j) == 0 && j.state != PROTO_STATE_PENDING)
            dlog(DLOG_INFO, "job %llu: %s before its SUBMIT_OK: not queued", id, proto_state_name(j.state));
        else if (sched_add(d->sched, s->id, s->user, s->priority))
            dlog(DLOG_ERROR, "job %llu: out of memory queueing it (it runs after a restart)", id);
        dlog(DLOG_INFO, "job %llu: submitted by %s, priority %d, label '%s', checked in %.1f ms (%.1f ms CPU), %s",
             id, s->user, s->priority, s->label, s->val_ms, s->val_cpu_ms, s->params);
        if (srv_conn_hung_up(c))
            dlog(DLOG_WARN, "job %llu: stored and queued, but the client of %s hung up before SUBMIT_OK",
                 id, s->user);
        reply_id(c, PROTO_MSG_SUBMIT_OK, s->request_id, s->id);   /* a no-op on a closed connection */
        bk_schedule(d);
        on_queue(d);              /* a job of higher priority goes before watched ones */
    }
    work_end(d, c);
    free(s);
}

static void on_submit(conn *c, const proto_msg *m, const void *frame, size_t len)
{
    mcd *d = srv_conn_daemon(c);
    conn_auth *a = srv_conn_auth(c);
    const proto_submit *s = &m->u.submit;
    char msg[PROTO_MAX_STRING];
    int rc;
    if (d->draining) {
        srv_send_error(c, m->request_id, PROTO_ESHUTTING_DOWN, "the server is shutting down; retry later");
        return;
    }
    if ((rc = check_submit(d, s, msg, sizeof msg))) {
        srv_send_error(c, m->request_id, rc, "%s", msg);
        return;
    }
    /* users may lower their priority, never raise it over others': the
     * fair share holds among equal priorities (a stated priority is kept
     * as stated or refused, never changed quietly) */
    if (s->priority > 0 && !a->admin) {
        dlog(DLOG_WARN, "SUBMIT from %s refused (FORBIDDEN): priority %d", a->user, s->priority);
        srv_send_error(c, m->request_id, PROTO_EFORBIDDEN, "priority = %d: user %s may only lower a job's priority"
                       " (priority <= 0); only an admin may raise it above 0", s->priority, a->user);
        return;
    }
    /* jobs still being stored count as pending: they will be */
    uint32_t mine = sched_user_pending(d->sched, a->user) + sched_user_running(d->sched, a->user) +
                    submits_in_flight(d, a->user);
    if (mine >= d->conf.max_jobs_per_user) {
        srv_send_error(c, m->request_id, PROTO_EUSER_LIMIT, "user %s already has %u unfinished jobs (limit %u)",
                       a->user, mine, d->conf.max_jobs_per_user);
        return;
    }
    uint32_t pending = sched_queued(d->sched) + submits_in_flight(d, NULL);
    if (pending >= d->conf.max_queue) {
        srv_send_error(c, m->request_id, PROTO_EQUEUE_FULL, "queue full: %u jobs pending (limit %u); nothing stored",
                       pending, d->conf.max_queue);
        return;
    }
    if ((rc = check_quota(d, a->user, len, msg, sizeof msg))) {
        dlog(rc == PROTO_EOVER_QUOTA ? DLOG_WARN : DLOG_ERROR, "SUBMIT from %s refused (%s): %s", a->user,
             proto_err_name(rc), msg);
        srv_send_error(c, m->request_id, rc, "%s", msg);
        return;
    }
    req_submit *w = calloc(1, sizeof *w);
    if (!w) {
        srv_send_error(c, m->request_id, PROTO_ENOMEM, "out of memory; nothing stored");
        return;
    }
    const proto_params *p = &s->params;
    char pbuf[sizeof w->params - 128];
    snprintf(w->params, sizeof w->params, "%s landmarks=%u init_p=%u init_q=%u source_bytes=%u target_bytes=%u",
             proto_params_format(p, pbuf, sizeof pbuf), s->nlandmarks, s->p.n, s->q.n, s->source.len,
             s->target.len);
    w->work.data = w;
    w->d = d;
    w->c = c;
    w->store = d->store;
    w->request_id = m->request_id;
    w->frame = frame;
    w->len = len;
    snprintf(w->user, sizeof w->user, "%s", a->user);
    snprintf(w->label, sizeof w->label, "%s", s->label);
    w->priority = s->priority;
    w->total = p->iterations;
    val_conf_of(d, &w->vc);
    if ((rc = work_start(d, c, &w->work, submit_run, submit_done))) {
        dlog(DLOG_ERROR, "SUBMIT from %s: cannot queue the store's work: %s", a->user, uv_strerror(rc));
        srv_send_error(c, m->request_id, PROTO_EINTERNAL, "job not stored: %s", uv_strerror(rc));
        free(w);
        return;
    }
    w->next = d->submits;
    d->submits = w;
}

/* The record of a pending job: its place in the queue (stage QUEUED,
 * never stored); 0 when the job is not in the queue. */
static int queued_record(mcd *d, uint64_t id, proto_progress *p)
{
    int64_t ahead = sched_ahead(d->sched, id);
    if (ahead < 0)
        return 0;
    memset(p, 0, sizeof *p);
    p->job_id = id;
    p->stage = PROTO_STAGE_QUEUED;
    p->ahead = ahead > UINT32_MAX ? UINT32_MAX : (uint32_t)ahead;
    p->fraction = 0;
    p->eta_s = NAN;
    return 1;
}

static proto_quality quality_of(const store_job *j)
{
    return (proto_quality){j->verdict, j->flipped, j->collapsed};
}

static void on_status(conn *c, const proto_msg *m)
{
    store_job j;
    if (visible_job(c, m->request_id, m->u.status.job_id, &j))
        return;
    proto_msg r;
    memset(&r, 0, sizeof r);
    r.type = PROTO_MSG_STATUS_OK;
    proto_status_ok *s = &r.u.status_ok;
    s->job_id = j.id;
    s->state = (uint8_t)j.state;
    s->priority = j.priority;
    s->user = j.user;
    s->label = j.label;
    s->reason = j.reason;
    s->submit_ms = j.submit_ms;
    s->start_ms = j.start_ms;
    s->end_ms = j.end_ms;
    mcd *d = srv_conn_daemon(c);
    s->has_progress = (j.state == PROTO_STATE_PENDING && queued_record(d, j.id, &s->progress)) ||
                      store_latest_progress(d->store, j.id, &s->progress) == 0;
    s->quality = quality_of(&j);
    reply(c, &r, m->request_id);
}

typedef struct list_ctx {
    store_job *jobs;
    uint32_t n, cap;
} list_ctx;

static int list_add(void *ctx, const store_job *j)
{
    list_ctx *l = ctx;
    if (l->n == l->cap)
        return 1;
    l->jobs[l->n++] = *j;
    return 0;
}

static void on_list(conn *c, const proto_msg *m)
{
    mcd *d = srv_conn_daemon(c);
    conn_auth *a = srv_conn_auth(c);
    const proto_list *q = &m->u.list;
    /* "" the caller's jobs; PROTO_LIST_ALL_USERS every user's (admin) */
    int all = strcmp(q->user, PROTO_LIST_ALL_USERS) == 0;
    const char *user = all ? NULL : q->user[0] ? q->user : a->user;
    if ((all || strcmp(user, a->user) != 0) && !a->admin) {
        dlog(DLOG_WARN, "%s: LIST of %s refused: not an admin", a->user, all ? "(every user)" : user);
        if (all)
            srv_send_error(c, m->request_id, PROTO_EFORBIDDEN, "only an admin may list every user's jobs (user \"%s\")",
                           PROTO_LIST_ALL_USERS);
        else
            srv_send_error(c, m->request_id, PROTO_EFORBIDDEN, "only an admin may list the jobs of user %s", user);
        return;
    }
    uint32_t max = q->max_count ? q->max_count : REQ_LIST_PAGE;
    if (max > PROTO_MAX_LIST)
        max = PROTO_MAX_LIST;
    list_ctx l = {calloc(max, sizeof(store_job)), 0, max};
    proto_job_summary *sum = calloc(max, sizeof *sum);
    if (!l.jobs || !sum) {
        srv_send_error(c, m->request_id, PROTO_ENOMEM, "out of memory for %u job summaries", max);
        goto done;
    }
    int rc = store_list(d->store, user, q->state_mask, q->after_id, max, list_add, &l);
    if (rc) {
        srv_send_error(c, m->request_id, rc, "job store failure listing jobs");
        goto done;
    }
    for (uint32_t i = 0; i < l.n; i++) {
        const store_job *j = &l.jobs[i];
        proto_progress q;
        int queued = j->state == PROTO_STATE_PENDING && queued_record(d, j->id, &q);
        sum[i] = (proto_job_summary){j->id, (uint8_t)j->state, j->priority, j->submit_ms, j->user,
                                     j->label, j->outer, j->total, quality_of(j),
                                     queued ? 0 : j->fraction, queued ? NAN : j->eta_s,
                                     queued ? q.ahead : 0};
    }
    proto_msg r;
    memset(&r, 0, sizeof r);
    r.type = PROTO_MSG_LIST_OK;
    r.u.list_ok.jobs = sum;
    r.u.list_ok.n = l.n;
    reply(c, &r, m->request_id);
done:
    free(l.jobs);
    free(sum);
}

typedef struct replay_ctx {
    conn *c;
    uint32_t request_id;
    int dropped;
} replay_ctx;

static int send_progress(conn *c, uint32_t rid, const proto_progress *p)
{
    proto_msg r;
    memset(&r, 0, sizeof r);
    r.type = PROTO_MSG_PROGRESS;
    r.request_id = rid;
    r.u.progress = *p;
    return srv_send(c, &r, 1);
}

static int replay_one(void *ctx, const proto_progress *p)
{
    replay_ctx *rc = ctx;
    if (send_progress(rc->c, rc->request_id, p))
        rc->dropped = 1;
    return rc->dropped;
}

static int send_end(conn *c, uint32_t rid, const store_job *j)
{
    proto_msg r;
    memset(&r, 0, sizeof r);
    r.type = PROTO_MSG_END;
    r.request_id = rid;
    r.u.end.job_id = j->id;
    r.u.end.state = (uint8_t)j->state;
    r.u.end.reason = j->reason;
    return srv_send(c, &r, 1);
}

/* Live WATCHes of connection c. */
static uint32_t watches_of(const mcd *d, const conn *c)
{
    uint32_t n = 0;
    for (const req_watch *w = d->watches; w; w = w->next)
        n += w->c == c;
    return n;
}

/* A refusal's log line, at most one per REQ_REFUSAL_LOG_MS for each kind
 * (a client looping on a refused request costs one line a second, with
 * how many it stands for). */
static void log_refusal(mcd *d, uint64_t *last_ms, unsigned long *held_back, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void log_refusal(mcd *d, uint64_t *last_ms, unsigned long *held_back, const char *fmt, ...)
{
    uint64_t now = uv_now(d->loop);
    if (*last_ms && now - *last_ms < REQ_REFUSAL_LOG_MS) {
        ++*held_back;
        return;
    }
    char line[PROTO_MAX_STRING + 128];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (*held_back)
        dlog(DLOG_WARN, "%s (and %lu more like it since the last line)", line, *held_back);
    else
        dlog(DLOG_WARN, "%s", line);
    *last_ms = now;
    *held_back = 0;
}

static void on_watch(conn *c, const proto_msg *m)
{
    mcd *d = srv_conn_daemon(c);
    const proto_watch *w = &m->u.watch;
    store_job j;
    if (visible_job(c, m->request_id, w->job_id, &j))
        return;
    /* each live WATCH costs the loop a visit per progress record of its
     * job: a session holds a bounded number (a finished job's WATCH ends
     * at once and is not counted) */
    uint32_t live = store_is_terminal(j.state) ? 0 : watches_of(d, c);
    if (live >= d->conf.max_watches_per_session) {
        static uint64_t last_ms;
        static unsigned long held_back;
        log_refusal(d, &last_ms, &held_back, "WATCH from %s refused (OVER_LIMIT): %u live WATCHes on its"
                    " connection (--max-watches-per-session %u)", srv_conn_auth(c)->user, live,
                    d->conf.max_watches_per_session);
        srv_send_error(c, m->request_id, PROTO_EOVER_LIMIT, "this connection has %u live WATCHes, the limit"
                       " (--max-watches-per-session %u): watch fewer jobs per connection", live,
                       d->conf.max_watches_per_session);
        return;
    }
    replay_ctx rc = {c, m->request_id, 0};
    if (store_history(d->store, j.id, w->from_outer, replay_one, &rc)) {
        srv_send_error(c, m->request_id, PROTO_ESTORAGE, "job store failure reading the history of job %llu",
                       (unsigned long long)j.id);
        return;
    }
    if (rc.dropped)
        return;
    if (store_is_terminal(j.state)) {
        send_end(c, m->request_id, &j);
        return;
    }
    req_watch *nw = calloc(1, sizeof *nw);
    if (!nw) {
        srv_send_error(c, m->request_id, PROTO_ENOMEM, "out of memory for the watch");
        return;
    }
    *nw = (req_watch){c, m->request_id, j.id, w->from_outer, -1, d->watches};
    d->watches = nw;
    proto_progress q;
    if (j.state == PROTO_STATE_PENDING && queued_record(d, j.id, &q)) {   /* where it waits */
        nw->ahead = q.ahead;
        send_progress(c, m->request_id, &q);
    }
}

/* The queue moved: each watcher of a pending job hears its new place. */
static void on_queue(mcd *d)
{
    iterating = 1;
    for (req_watch *w = d->watches; w; w = w->next) {
        proto_progress q;
        if (w->c && queued_record(d, w->job_id, &q) && q.ahead != w->ahead) {
            w->ahead = q.ahead;
            send_progress(w->c, w->request_id, &q);
        }
    }
    iterating = 0;
    prune(d);
}

static void on_job_progress(mcd *d, const proto_progress *p)
{
    snap_progress(d, p);
    iterating = 1;
    for (req_watch *w = d->watches; w; w = w->next)
        if (w->c && w->job_id == p->job_id && p->outer >= w->from_outer)
            send_progress(w->c, w->request_id, p);
    iterating = 0;
    prune(d);
}

static void on_job_ended(mcd *d, uint64_t id)
{
    store_job j;
    if (store_get(d->store, id, &j))
        return;
    iterating = 1;
    for (req_watch *w = d->watches; w; w = w->next)
        if (w->c && w->job_id == id) {
            conn *c = w->c;
            w->c = NULL;
            send_end(c, w->request_id, &j);
        }
    iterating = 0;
    prune(d);
}

void req_init(mcd *d)
{
    static const job_listener l = {on_job_progress, on_job_ended, on_queue};
    job_listen(d, &l);
}

static void on_cancel(conn *c, const proto_msg *m)
{
    mcd *d = srv_conn_daemon(c);
    store_job j;
    if (visible_job(c, m->request_id, m->u.cancel.job_id, &j))
        return;
    int rc = bk_cancel_job(d, &j);
    if (rc == PROTO_ESTORAGE) {
        srv_send_error(c, m->request_id, PROTO_ESTORAGE, "job store failure cancelling job %llu",
                       (unsigned long long)j.id);
        return;
    }
    if (rc) {
        srv_send_error(c, m->request_id, PROTO_EBAD_STATE, "job %llu is %s: nothing to cancel",
                       (unsigned long long)j.id, proto_state_name(j.state));
        return;
    }
    reply_id(c, PROTO_MSG_OK, m->request_id, j.id);
}

/* A RESULT: result.frame is read and decoded in the thread pool, the reply
 * encoded onto the connection, and then it is written out.
 *
 * DESIGN: what RESULTs hold is bounded in all and per user, not per
 * connection. A RESULT counts from the start of its read until its
 * connection's output has been written whole (req_conn_sent) or the
 * connection is gone; at most --max-result-sends count at once, and at
 * most --max-result-sends-per-user of one user's. One that does not fit
 * waits, in order of arrival, with its connection held (not read: its
 * replies keep their order), and starts when a RESULT of a user with room
 * ends; so clients that never read their replies hold at most those
 * RESULTs' bytes, and other users' RESULTs go on. The decoded result is
 * freed once the reply is encoded. */
enum { RESULT_WAITING, RESULT_READING, RESULT_SENDING };
typedef struct req_result req_result;
struct req_result {
    uv_work_t work;
    mcd *d;                       /* loop side only */
    conn *c;                      /* loop side only; held until the read is done */
    req_result *next;             /* results, in arrival order */
    int phase;                    /* RESULT_* */
    char user[AUTH_MAX_USER];     /* whose share it counts in */
    uint32_t request_id;
    uint64_t job_id;
    uint32_t what;                /* PROTO_WANT_* */
    const store *store;           /* store_result_read only (a file read) */
    uint8_t *buf;                 /* result.frame's bytes; res may point into them */
    proto_msg res;                /* the decoded RESULT_OK when rc is 0 */
    int rc;
    char err[256];
};

static req_result *results;       /* every RESULT waiting, being read or being sent */

static void result_unlink(req_result *r)
{
    for (req_result **p = &results; *p; p = &(*p)->next)
        if (*p == r) {
            *p = r->next;
            return;
        }
}

/* RESULTs being read or sent: of user, or of everyone (NULL). */
static uint32_t results_active(const char *user)
{
    uint32_t n = 0;
    for (const req_result *r = results; r; r = r->next)
        n += r->phase != RESULT_WAITING && (!user || strcmp(r->user, user) == 0);
    return n;
}

static void result_run(uv_work_t *w)      /* thread pool */
{
    req_result *r = w->data;
    r->rc = store_result_read(r->store, r->job_id, &r->res, &r->buf, r->err, sizeof r->err);
}

static void result_done(uv_work_t *w, int status);

/* Starts the waiting RESULTs that fit now, oldest first. The list is
 * walked again from its head after each start: a start that fails
 * answers, and that may close connections (req_conn_closed edits it). */
static void results_start(mcd *d)
{
    for (;;) {
        req_result *r = results;
        while (r && (r->phase != RESULT_WAITING || results_active(r->user) >= d->conf.max_result_sends_per_user))
            r = r->next;
        if (!r || results_active(NULL) >= d->conf.max_result_sends)
            return;
        r->phase = RESULT_READING;
        int rc = uv_queue_work(d->loop, &r->work, result_run, result_done);
        if (rc == 0) {
            d->work_inflight++;
            continue;
        }
        dlog(DLOG_ERROR, "job %llu: cannot queue the read of its result: %s", (unsigned long long)r->job_id,
             uv_strerror(rc));
        result_unlink(r);
        srv_send_error(r->c, r->request_id, PROTO_EINTERNAL, "the result of job %llu cannot be read",
                       (unsigned long long)r->job_id);
        srv_conn_release(r->c);
        free(r);
    }
}

static void result_done(uv_work_t *w, int status)    /* loop */
{
    req_result *r = w->data;
    mcd *d = r->d;
    conn *c = r->c;
    unsigned long long id = (unsigned long long)r->job_id;
    if (status < 0) {                       /* never ran: res was never filled */
        r->rc = PROTO_EINTERNAL;
        snprintf(r->err, sizeof r->err, "the read was not run: %s", uv_strerror(status));
    }
    store_job j;
    if (r->rc && store_get(d->store, r->job_id, &j) == PROTO_ENOT_FOUND) {
        /* deleted (DELETE, expiry) while it was read */
        srv_send_error(c, r->request_id, PROTO_ENOT_FOUND, "no job %llu", id);
    } else if (r->rc) {
        dlog(DLOG_ERROR, "job %llu: result.frame unreadable: %s", id, r->err);
        srv_send_error(c, r->request_id, PROTO_EINTERNAL, "the result of job %llu cannot be read", id);
    } else if (srv_conn_open(c)) {
        proto_msg m;
        memset(&m, 0, sizeof m);
        m.type = PROTO_MSG_RESULT_OK;
        proto_result_ok *o = &m.u.result_ok;
        const proto_result_ok *in = &r->res.u.result_ok;
        o->job_id = r->job_id;
        if (r->what & PROTO_WANT_P)
            o->p = in->p;
        if (r->what & PROTO_WANT_Q)
            o->q = in->q;
        if (r->what & PROTO_WANT_DEFORMED)
            o->deformed = in->deformed;
        if (r->what & PROTO_WANT_STAGE_RHM) {
            o->rhm_p = in->rhm_p;
            o->rhm_q = in->rhm_q;
        }
        if (r->what & PROTO_WANT_METRICS) {
            o->metrics = in->metrics;
            o->nmetrics = in->nmetrics;
        }
        reply(c, &m, r->request_id);
    }
    if (r->rc == 0)
        proto_msg_free(&r->res);
    free(r->buf);
    r->buf = NULL;
    /* the reply (or the error) is queued on c: it counts until it is
     * written, unless c is gone already (req_conn_closed has passed) */
    int sending = srv_conn_open(c);
    if (sending) {
        r->phase = RESULT_SENDING;
    } else {
        result_unlink(r);
        free(r);
    }
    work_end(d, c);
    results_start(d);
}

static void on_result(conn *c, const proto_msg *m)
{
    mcd *d = srv_conn_daemon(c);
    const proto_result *q = &m->u.result;
    store_job j;
    if (visible_job(c, m->request_id, q->job_id, &j))
        return;
    if (j.state != PROTO_STATE_COMPLETED) {
        srv_send_error(c, m->request_id, PROTO_EBAD_STATE, "job %llu is %s: results exist for COMPLETED jobs only",
                       (unsigned long long)j.id, proto_state_name(j.state));
        return;
    }
    req_result *r = calloc(1, sizeof *r);
    if (!r) {
        srv_send_error(c, m->request_id, PROTO_ENOMEM, "out of memory");
        return;
    }
    r->work.data = r;
    r->d = d;
    r->c = c;
    r->phase = RESULT_WAITING;
    snprintf(r->user, sizeof r->user, "%s", srv_conn_auth(c)->user);
    r->request_id = m->request_id;
    r->job_id = j.id;
    r->what = q->what;
    r->store = d->store;
    req_result **tail = &results;
    while (*tail)
        tail = &(*tail)->next;
    *tail = r;
    srv_conn_hold(c);                  /* nothing more is read from c until its read is done */
    uint32_t mine = results_active(r->user), all = results_active(NULL);
    if (mine >= d->conf.max_result_sends_per_user || all >= d->conf.max_result_sends)
        dlog(DLOG_INFO, "job %llu: RESULT for %s waits: %u RESULT(s) of %s and %u in all being sent"
             " (--max-result-sends-per-user %u, --max-result-sends %u)", (unsigned long long)j.id, r->user,
             mine, r->user, all, d->conf.max_result_sends_per_user, d->conf.max_result_sends);
    results_start(d);
}

/* c's RESULTs end: those being sent, and with closing (c is going) those
 * waiting too, their holds released; one being read ends in result_done.
 * Then the waiting ones that fit start. */
static void results_end(mcd *d, conn *c, int closing)
{
    int ended = 0;
    for (req_result **p = &results; *p;) {
        req_result *r = *p;
        if (r->c == c && (r->phase == RESULT_SENDING || (closing && r->phase == RESULT_WAITING))) {
            *p = r->next;
            if (r->phase == RESULT_WAITING)
                srv_conn_release(c);
            free(r);
            ended = 1;
        } else {
            p = &r->next;
        }
    }
    if (ended)
        results_start(d);
}

void req_conn_sent(mcd *d, conn *c)
{
    results_end(d, c, 0);
}

static void on_delete(conn *c, const proto_msg *m)
{
    mcd *d = srv_conn_daemon(c);
    store_job j;
    if (visible_job(c, m->request_id, m->u.del.job_id, &j))
        return;
    if (!store_is_terminal(j.state)) {
        srv_send_error(c, m->request_id, PROTO_EBAD_STATE, "job %llu is %s: cancel it first",
                       (unsigned long long)j.id, proto_state_name(j.state));
        return;
    }
    if (store_delete(d->store, j.id)) {
        srv_send_error(c, m->request_id, PROTO_ESTORAGE, "job store failure deleting job %llu",
                       (unsigned long long)j.id);
        return;
    }
    dlog(DLOG_INFO, "job %llu: deleted by %s", (unsigned long long)j.id, srv_conn_auth(c)->user);
    reply_id(c, PROTO_MSG_OK, m->request_id, j.id);
}

/* A non-admin's STATS counts that user's ended jobs still in the store, not
 * everyone's since the store was created. */
static int count_ended(void *ctx, const store_job *j)
{
    proto_stats_ok *s = ctx;
    if (j->state == PROTO_STATE_COMPLETED)
        s->completed++;
    else if (j->state == PROTO_STATE_CANCELLED)
        s->cancelled++;
    else if (store_is_terminal(j->state))
        s->failed++;
    return 0;
}

static void on_stats(conn *c, const proto_msg *m)
{
    mcd *d = srv_conn_daemon(c);
    conn_auth *a = srv_conn_auth(c);
    proto_msg r;
    memset(&r, 0, sizeof r);
    r.type = PROTO_MSG_STATS_OK;
    proto_stats_ok *s = &r.u.stats_ok;
    uint32_t nslots = (uint32_t)bk_nslots(d) > PROTO_MAX_SLOTS ? PROTO_MAX_SLOTS : (uint32_t)bk_nslots(d);
    mcd_snapshot *now = snap_alloc((uint32_t)bk_nslots(d));
    proto_slot *slots = calloc((size_t)nslots + 1, sizeof *slots);
    if (!now || !slots) {
        srv_send_error(c, m->request_id, PROTO_ENOMEM, "out of memory");
        goto done;
    }
    snap_collect(d, now);                   /* the figures the dashboards show too */
    uint32_t running = 0;
    for (uint32_t i = 0; i < nslots; i++) {
        slots[i] = (proto_slot){now->slots[i].job_id, now->slots[i].state};
        store_job j;
        if (slots[i].job_id && !a->admin &&
            (store_get(d->store, slots[i].job_id, &j) || strcmp(j.user, a->user) != 0))
            slots[i].job_id = 0;
        running += slots[i].state != PROTO_SLOT_IDLE && slots[i].job_id;
    }
    s->queued = a->admin ? now->queued : sched_user_pending(d->sched, a->user);
    s->running = a->admin ? now->running : running;
    s->workers = now->workers;
    if (a->admin) {
        s->completed = now->completed;
        s->failed = now->failed;
        s->cancelled = now->cancelled;
    } else if (store_list(d->store, a->user, 0, 0, UINT32_MAX, count_ended, s)) {
        srv_send_error(c, m->request_id, PROTO_ESTORAGE, "job store failure counting your jobs");
        goto done;
    }
    s->slots = slots;
    s->nslots = nslots;
    char dev[64];
    const char *devs[MCD_MAX_DEVICES];
    int nd = dev_list(d, devs, MCD_MAX_DEVICES);
    if (nd == 0) {                          /* the worker has not answered (yet) */
        long ncpu = d->conf.threads_per_worker ? d->conf.threads_per_worker : sysconf(_SC_NPROCESSORS_ONLN);
        snprintf(dev, sizeof dev, "cpu:%ld", ncpu);
        devs[0] = dev;
        nd = 1;
    }
    s->devices = devs;
    s->ndevices = (uint32_t)nd;
    char health[PROTO_MAX_STRING + 1];
    s->backend = bk_name(d);
    s->backend_ok = (uint8_t)bk_health(d, health, sizeof health);
    s->backend_status = health;
    reply(c, &r, m->request_id);
done:
    snap_release(now);
    free(slots);
}

void req_handle(conn *c, const proto_msg *m, const void *frame, size_t len)
{
    conn_auth *a = srv_conn_auth(c);
    if (!a->authed && m->type != PROTO_MSG_HELLO) {
        dlog(DLOG_WARN, "%s before HELLO from %s: closing", proto_type_name(m->type), a->peer);
        srv_send_error(c, m->request_id, PROTO_EUNAUTHORIZED, "%s before HELLO", proto_type_name(m->type));
        srv_close_soon(c);
        return;
    }
    dlog(DLOG_DEBUG, "%s: %s (request %u)", a->authed ? a->user : "-", proto_type_name(m->type), m->request_id);
    switch (m->type) {
    case PROTO_MSG_HELLO:  on_hello(c, m); break;
    case PROTO_MSG_SUBMIT: on_submit(c, m, frame, len); break;
    case PROTO_MSG_STATUS: on_status(c, m); break;
    case PROTO_MSG_LIST:   on_list(c, m); break;
    case PROTO_MSG_WATCH:  on_watch(c, m); break;
    case PROTO_MSG_CANCEL: on_cancel(c, m); break;
    case PROTO_MSG_RESULT: on_result(c, m); break;
    case PROTO_MSG_DELETE: on_delete(c, m); break;
    case PROTO_MSG_STATS:  on_stats(c, m); break;
    case PROTO_MSG_PING: {
        proto_msg r;
        memset(&r, 0, sizeof r);
        r.type = PROTO_MSG_PONG;
        reply(c, &r, m->request_id);
        break;
    }
    default:
        srv_send_error(c, m->request_id, PROTO_EUNEXPECTED, "%s is a reply; the server does not take it",
                       proto_type_name(m->type));
    }
}
