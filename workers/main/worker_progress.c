/* worker_progress.c — corr_progress -> PROGRESS frames on the daemon's pipe
 * (see worker.h). A frame is 149 bytes, under PIPE_BUF, so each write is
 * atomic. Never fails the job. */
#include "main/worker.h"

#include <errno.h>
#include <string.h>
#include <unistd.h>

void wrk_progress_fill(const corr_progress *cp, uint64_t job_id, int total, double elapsed,
                       proto_progress *out)
{
    memset(out, 0, sizeof *out);
    out->job_id = job_id;
    out->total = (uint32_t)total;
    out->elapsed_s = elapsed;
    switch (cp->stage) {
    case CORR_STAGE_ECTM: out->stage = PROTO_STAGE_ECTM; break;
    case CORR_STAGE_VORONOI: out->stage = PROTO_STAGE_VORONOI; break;
    case CORR_STAGE_RHM: out->stage = PROTO_STAGE_RHM; break;
    default: out->stage = PROTO_STAGE_INIT; break;
    }
    if (cp->rhm) {  /* RHM's terms in the slots PROTOCOL.md names */
        const rhm_report *h = cp->rhm;
        out->outer = (uint32_t)h->iteration;
        out->total = (uint32_t)h->total;
        out->beta = h->beta;
        for (int d = 0; d < 2; d++) {
            out->terms[d][PROTO_TERM_MEMBRANE] = h->dir[d].dirichlet;
            out->terms[d][PROTO_TERM_BENDING] = h->dir[d].landmark;
            out->terms[d][PROTO_TERM_MISMATCH] = h->dir[d].mismatch;
            out->terms[d][PROTO_TERM_REVERSE] = h->dir[d].reverse;
            out->terms[d][PROTO_TERM_ENERGY] = h->dir[d].dirichlet + h->dir[d].landmark
                                             + h->dir[d].mismatch + h->dir[d].reverse;
        }
        return;
    }
    const ectm_report *r = cp->ectm;
    if (!r)
        return;
    out->outer = (uint32_t)r->outer;
    out->beta = r->beta;
    out->gamma = r->gamma;
    for (int d = 0; d < 2; d++) {
        out->inner[d] = (uint32_t)r->dir[d].inner_iterations;
        out->terms[d][PROTO_TERM_MEMBRANE] = r->dir[d].w_mem;
        out->terms[d][PROTO_TERM_BENDING] = r->dir[d].w_bnd;
        out->terms[d][PROTO_TERM_MISMATCH] = r->dir[d].mismatch;
        out->terms[d][PROTO_TERM_REVERSE] = r->dir[d].reverse;
        out->terms[d][PROTO_TERM_ENERGY] = r->dir[d].energy;
    }
}

void wrk_progress_send(wrk_progress *pg, const corr_progress *cp, double elapsed)
{
    if (pg->fd < 0)
        return;
    proto_msg m;
    memset(&m, 0, sizeof m);
    m.type = PROTO_MSG_PROGRESS;
    wrk_progress_fill(cp, pg->job_id, pg->total, elapsed, &m.u.progress);
    proto_buf b;
    proto_buf_init(&b);
    if (proto_msg_encode(&b, &m, NULL, 0) != 0) {
        pg->fd = -1;
        goto done;
    }
    const uint8_t *p = b.data;
    size_t n = b.len;
    while (n) {
        ssize_t w = write(pg->fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            pg->fd = -1;                           /* daemon gone: stop, carry on */
            goto done;
        }
        p += w;
        n -= (size_t)w;
    }
done:
    proto_buf_free(&b);
}
