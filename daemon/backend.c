/* backend.c — the bk_ dispatch (backend.h): picks the configured backend's
 * operations once at start and forwards to them, and the one cancel rule
 * (the backend stops what it has, the queue drops what it does not).
 * Knows nothing about how a backend runs a job. */
#include "backend.h"

#include <string.h>

static const bk_ops *ops_of(const mcd *d)
{
    return d->bk ? d->bk : &bk_local;
}

int bk_init(mcd *d, char *err, size_t errsz)
{
    d->bk = strcmp(d->conf.backend, "slurm") == 0 ? &bk_slurm : &bk_local;
    return d->bk->init(d, err, errsz);
}

void bk_schedule(mcd *d) { ops_of(d)->schedule(d); }
int bk_cancel(mcd *d, uint64_t id) { return ops_of(d)->cancel(d, id); }
void bk_drain(mcd *d, mcd_idle_fn idle) { ops_of(d)->drain(d, idle); }
int bk_busy(const mcd *d) { return ops_of(d)->busy(d); }
int bk_nslots(const mcd *d) { return ops_of(d)->nslots(d); }
const char *bk_name(const mcd *d) { return ops_of(d)->name; }

int bk_cancel_job(mcd *d, const store_job *j)
{
    if (!store_is_terminal(j->state) && bk_cancel(d, j->id) == 0) {
        /* the backend has it (running, or queued in Slurm) and stops it */
        dlog(DLOG_INFO, "job %llu: cancel requested from the %s backend", (unsigned long long)j->id, bk_name(d));
        return 0;
    }
    if (j->state == PROTO_STATE_PENDING)
        return job_cancel_pending(d, j->id);
    return PROTO_EBAD_STATE;
}

void bk_slot_info(const mcd *d, int i, uint8_t *state, uint64_t *job_id)
{
    ops_of(d)->slot_info(d, i, state, job_id);
}

int bk_health(const mcd *d, char *msg, size_t sz)
{
    return ops_of(d)->health(d, msg, sz);
}

void bk_close(mcd *d)
{
    if (d->bk)
        d->bk->close(d);
}

void bk_keep_on_reload(const mcd *d, mcd_conf *n, char *changed, size_t sz)
{
    /* the backend itself is chosen once */
    conf_note_change(strcmp(n->backend, d->conf.backend) != 0, "backend", changed, sz);
    memcpy(n->backend, d->conf.backend, sizeof n->backend);
    ops_of(d)->keep_on_reload(d, n, changed, sz);
}
