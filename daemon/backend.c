/* backend.c — the bk_ dispatch (backend.h): picks the configured backend's
 * operations once at start and forwards to them; plus the PROGRESS decoding
 * both backends share (the records go to job_progress). Knows nothing about how a backend runs a job. */
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
void bk_drain(mcd *d) { ops_of(d)->drain(d); }
int bk_busy(const mcd *d) { return ops_of(d)->busy(d); }
int bk_nslots(const mcd *d) { return ops_of(d)->nslots(d); }
const char *bk_name(const mcd *d) { return ops_of(d)->name; }

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
    changed[0] = '\0';
    /* the backend itself is chosen once */
    bk_note_change(strcmp(n->backend, d->conf.backend) != 0, "backend", changed, sz);
    memcpy(n->backend, d->conf.backend, sizeof n->backend);
    ops_of(d)->keep_on_reload(d, n, changed, sz);
}

void bk_note_change(int differs, const char *name, char *changed, size_t sz)
{
    size_t len = strlen(changed);
    if (differs && len + 1 < sz)
        snprintf(changed + len, sz - len, "%s%s", len ? ", " : "", name);
}

int bk_progress_take(mcd *d, uint64_t id, proto_buf *in)
{
    int n = 0;
    while (in->len) {
        proto_msg m;
        size_t used = 0;
        char err[256];
        int rc = proto_decode(in->data, in->len, BK_MAX_PROGRESS_FRAME, &m, &used, err, sizeof err);
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
        job_progress(d, &p);
        n++;
    }
    return n;
}
