/* snap.c — the status snapshot: queue depth, running jobs, end counters,
 * worker slots, each running job's latest progress, the queue's order
 * (positions for the web pages), each user's pending and running jobs and
 * the histograms of run durations and queue waits, computed in one
 * place (snap_collect) for STATS and for the dashboards (mbus.c, http.c).
 *
 * DESIGN: the loop thread owns the daemon's state; the dashboard servers run
 * in threads of their own and must never touch it. Every SNAP_PERIOD_MS the
 * loop collects a snapshot and publishes a copy under a mutex (seq + 1); the
 * other threads copy the published one out under the same mutex (snap_read)
 * and answer from their copy, so a slow client never holds the lock, and the
 * loop never waits on anything but a memcpy. The latest progress record of
 * each slot's job is kept here from the records wsup passes through req, so
 * a snapshot reads the store only when a slot changes job (and once for the
 * end counters). Nothing here talks to clients. */
#include "backend.h"
#include "mcd.h"
#include "util/errbuf.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct slot_cache {
    uint64_t job_id;              /* the job the entries below belong to */
    int64_t start_ms;
    int has_progress;
    proto_progress p;
} slot_cache;

struct snap {
    /* loop thread only */
    uint32_t nslots;              /* bk_nslots at snap_init: every array here has this many */
    slot_cache *cache;
    mcd_snapshot *scratch;
    uv_timer_t timer;
    int timer_open;
    struct timespec t0;
    uint32_t seq;
    /* shared: under mu */
    pthread_mutex_t mu;
    mcd_snapshot *board;
};

mcd_snapshot *snap_alloc(uint32_t nslots)
{
    mcd_snapshot *m = calloc(1, sizeof *m);
    if (!m || !(m->slots = calloc(nslots ? nslots : 1, sizeof *m->slots))) {
        free(m);
        return NULL;
    }
    m->nslots = nslots;
    return m;
}

void snap_release(mcd_snapshot *m)
{
    if (!m)
        return;
    free(m->slots);
    free(m);
}

/* Brings slot i's cache to the job wsup runs there now. */
static slot_cache *sync_slot(mcd *d, uint32_t i, uint8_t *state)
{
    slot_cache *c = &d->snap->cache[i];
    uint64_t job;
    bk_slot_info(d, (int)i, state, &job);
    if (c->job_id != job) {
        memset(c, 0, sizeof *c);
        c->job_id = job;
        store_job j;
        if (job && store_get(d->store, job, &j) == 0)
            c->start_ms = j.start_ms;
        if (job && store_latest_progress(d->store, job, &c->p) == 0)
            c->has_progress = 1;
    }
    return c;
}

/* Slots a snapshot covers: the backend's count, which is fixed at start (a
 * reload keeps it, bk_keep_on_reload); never more than the arrays hold. */
static uint32_t slots_of(mcd *d, uint32_t room)
{
    uint32_t n = (uint32_t)bk_nslots(d);
    if (n > d->snap->nslots)
        n = d->snap->nslots;
    return n < room ? n : room;
}

void snap_progress(mcd *d, const proto_progress *p)
{
    uint32_t n = slots_of(d, UINT32_MAX);
    for (uint32_t i = 0; i < n; i++) {
        uint8_t state;
        slot_cache *c = sync_slot(d, i, &state);
        if (c->job_id == p->job_id) {
            proto_progress kept = c->p;
            c->p = *p;
            if (p->stage == PROTO_STAGE_REPAIR && c->has_progress) {
                /* a repair has no energy of its own: the dashboards keep the
                 * last iteration's energy and beta */
                memcpy(c->p.terms, kept.terms, sizeof kept.terms);
                c->p.beta = kept.beta;
            }
            c->has_progress = 1;
        }
    }
}

void snap_collect(mcd *d, mcd_snapshot *out)
{
    int64_t now = store_now_ms();
    uint32_t running = 0, n = slots_of(d, out->nslots);
    for (uint32_t i = 0; i < n; i++) {
        snap_slot *o = &out->slots[i];
        slot_cache *c = sync_slot(d, i, &o->state);
        o->job_id = c->job_id;
        running += o->state != PROTO_SLOT_IDLE;
        o->has_progress = (uint8_t)c->has_progress;
        o->stage = c->has_progress ? c->p.stage : 0;
        o->outer = c->has_progress ? c->p.outer : 0;
        o->total = c->has_progress ? c->p.total : 0;
        o->energy = c->has_progress ? c->p.terms[0][PROTO_TERM_ENERGY] + c->p.terms[1][PROTO_TERM_ENERGY] : 0;
        o->beta = c->has_progress ? c->p.beta : 0;
        o->fraction = c->has_progress ? c->p.fraction : NAN;
        o->eta_s = c->has_progress ? c->p.eta_s : NAN;
        o->elapsed_s = c->job_id && c->start_ms && now > c->start_ms ? (uint32_t)((now - c->start_ms) / 1000) : 0;
    }
    out->nslots = n;
    out->workers = n;
    out->running = running;
    out->queued = sched_queued(d->sched);
    out->nqueue = sched_order(d->sched, out->queue, SNAP_MAX_QUEUE);
    job_times(&out->duration, &out->wait);
    out->nusers = 0;
    const char *name;
    uint32_t pending, run;
    for (uint32_t i = 0; out->nusers < SNAP_MAX_USERS && sched_user_at(d->sched, i, &name, &pending, &run) == 0; i++)
        if (pending || run) {
            snap_user *u = &out->users[out->nusers++];
            snprintf(u->name, sizeof u->name, "%s", name);
            u->pending = pending;
            u->running = run;
        }
    store_counters(d->store, &out->completed, &out->failed, &out->cancelled);
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    out->uptime_s = (uint32_t)(t.tv_sec - d->snap->t0.tv_sec);
    out->seq = d->snap->seq;
}

static void copy_snapshot(mcd_snapshot *dst, const mcd_snapshot *src)
{
    snap_slot *slots = dst->slots;
    uint32_t n = dst->nslots < src->nslots ? dst->nslots : src->nslots;
    *dst = *src;
    dst->slots = slots;
    dst->nslots = n;
    memcpy(slots, src->slots, n * sizeof *slots);
}

static void publish(mcd *d)
{
    snap *s = d->snap;
    s->seq++;
    snap_collect(d, s->scratch);
    pthread_mutex_lock(&s->mu);
    copy_snapshot(s->board, s->scratch);
    pthread_mutex_unlock(&s->mu);
}

static void on_timer(uv_timer_t *t)
{
    publish(t->data);
}

int snap_init(mcd *d, char *err, size_t errsz)
{
    snap *s = calloc(1, sizeof *s);
    if (!s)
        return errbuf_set(err, errsz, -1, "out of memory");
    d->snap = s;
    pthread_mutex_init(&s->mu, NULL);
    clock_gettime(CLOCK_MONOTONIC, &s->t0);
    uint32_t n = s->nslots = (uint32_t)bk_nslots(d);
    if (!(s->cache = calloc(n, sizeof *s->cache)) || !(s->scratch = snap_alloc(n)) || !(s->board = snap_alloc(n)))
        return errbuf_set(err, errsz, -1, "out of memory for the snapshot");
    publish(d);
    uv_timer_init(d->loop, &s->timer);
    s->timer.data = d;
    s->timer_open = 1;
    uv_timer_start(&s->timer, on_timer, SNAP_PERIOD_MS, SNAP_PERIOD_MS);
    return 0;
}

void snap_close(mcd *d)
{
    if (d->snap && d->snap->timer_open) {
        d->snap->timer_open = 0;
        uv_close((uv_handle_t *)&d->snap->timer, NULL);
    }
}

void snap_free(snap *s)
{
    if (!s)
        return;
    pthread_mutex_destroy(&s->mu);
    free(s->cache);
    snap_release(s->scratch);
    snap_release(s->board);
    free(s);
}

void snap_read(snap *s, mcd_snapshot *out)
{
    pthread_mutex_lock(&s->mu);
    copy_snapshot(out, s->board);
    pthread_mutex_unlock(&s->mu);
}

uint32_t snap_nslots(const snap *s)
{
    return s->board->nslots;
}
