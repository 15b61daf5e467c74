/* corr_record.c — a stage report as the wire's progress record
 * (proto_progress, PROTOCOL.md's PROGRESS): the one mapping that the
 * worker sends to the daemon and `meshcorr match` prints, so a job's
 * progress reads the same run locally or through meshcorrd. */
#include "corr/corr.h"

#include <math.h>
#include <string.h>

void corr_progress_record(const corr_progress *cp, proto_progress *out)
{
    memset(out, 0, sizeof *out);
    out->stage = (uint8_t)cp->stage;
    out->elapsed_s = cp->elapsed;
    out->fraction = isnan(cp->fraction) ? NAN : fmin(1, fmax(0, cp->fraction));
    out->eta_s = cp->eta_s >= 0 && isfinite(cp->eta_s) ? cp->eta_s : NAN;
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
    } else if (cp->ddm) {  /* directions done of total, each one's deblurring objective */
        const corr_ddm_report *d = cp->ddm;
        out->outer = (uint32_t)d->done;
        out->total = (uint32_t)d->total;
        out->beta = d->mode;               /* the denoising that runs (PROTOCOL.md) */
        out->gamma = d->round_trip;        /* auto's round trip, NaN when none */
        for (int k = 0; k < 2; k++)
            out->terms[k][PROTO_TERM_MISMATCH] = out->terms[k][PROTO_TERM_ENERGY] = d->cost[k];
    } else if (cp->repair) {  /* maps repaired of total */
        out->outer = (uint32_t)cp->repair->done;
        out->total = (uint32_t)cp->repair->total;
    } else if (cp->ectm) {
        const ectm_report *r = cp->ectm;
        out->outer = (uint32_t)r->outer;
        out->total = (uint32_t)r->total;
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
}
