/* mc_wire.c — mc_job_spec -> SUBMIT, PROGRESS -> mc_progress, RESULT_OK ->
 * mc_job_result (see mc__wire.h): one mapping for the client and the
 * in-process job. No I/O. */
#include "mc__wire.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* meshcorr.h's names of the server's codes are the protocol's numbers. */
#define MC_SAME(name) ((int)MC_E##name == (int)PROTO_E##name)
_Static_assert(MC_SAME(UNAUTHORIZED) && MC_SAME(FORBIDDEN) && MC_SAME(NOT_FOUND) && MC_SAME(BAD_STATE) &&
                   MC_SAME(QUEUE_FULL) && MC_SAME(USER_LIMIT) && MC_SAME(BAD_MESH) && MC_SAME(BAD_LANDMARKS) &&
                   MC_SAME(BAD_PARAMS) && MC_SAME(CANCELLED) && MC_SAME(BUSY) && MC_SAME(TIMED_OUT) &&
                   MC_SAME(OVER_QUOTA) && MC_SAME(BAD_MAP) && MC_SAME(NUMERIC),
               "one numbering of the server's codes");
#undef MC_SAME

int mc__submit_of(const mc_job_spec *s, proto_submit *m, char *err, size_t errsz)
{
    if (!s || !s->source || !s->target || s->source_len > UINT32_MAX || s->target_len > UINT32_MAX) {
        snprintf(err, errsz, "the job needs source and target Draco bytes");
        return MC_EARG;
    }
    memset(m, 0, sizeof *m);
    m->source = (proto_blob){s->source, (uint32_t)s->source_len};
    m->target = (proto_blob){s->target, (uint32_t)s->target_len};
    m->landmarks = (proto_landmark *)s->landmarks;   /* (src, tgt) u32 pairs: the same layout */
    m->nlandmarks = s->nlandmarks;
    m->p = (proto_map){(proto_map_row *)s->p, s->np};
    m->q = (proto_map){(proto_map_row *)s->q, s->nq};
    proto_params *p = &m->params;
    /* one assignment per row of the list; an int that does not fit a u8
     * becomes 255, which the server refuses naming the field */
#define MC_WIRE_U8(v) (uint8_t)((v) < 0 || (v) > 255 ? 255 : (v))
#define MC_WIRE_ENUM(name) p->name = MC_WIRE_U8(s->name);
#define MC_WIRE_BOOL(name) p->name = MC_WIRE_U8(s->name);
#define MC_WIRE_U32(name)  p->name = s->name;
#define MC_WIRE_F64(name)  p->name = s->name;
#define MC_WIRE_STR(name)  p->name = s->name ? s->name : "";
#define MC_WIRE(name, cli, type, ...) MC_WIRE_##type(name)
    PROTO_PARAMS(MC_WIRE)
#undef MC_WIRE
    m->priority = s->priority;
    m->label = s->label ? s->label : "";
    return 0;
}

void mc__progress_of(mc_progress *o, const proto_progress *p)
{
    o->job_id = p->job_id;
    o->stage = p->stage;
    o->outer = p->outer;
    o->total = p->total;
    for (int d = 0; d < 2; d++) {
        o->inner[d] = p->inner[d];
        o->membrane[d] = p->terms[d][PROTO_TERM_MEMBRANE];
        o->bending[d] = p->terms[d][PROTO_TERM_BENDING];
        o->mismatch[d] = p->terms[d][PROTO_TERM_MISMATCH];
        o->reverse[d] = p->terms[d][PROTO_TERM_REVERSE];
        o->energy[d] = p->terms[d][PROTO_TERM_ENERGY];
    }
    o->beta = p->beta;
    o->gamma = p->gamma;
    o->elapsed_s = p->elapsed_s;
    o->fraction = p->fraction;
    o->eta_s = p->eta_s;
    o->ahead = p->ahead;
}

void mc_result_free(mc_job_result *r)
{
    if (!r)
        return;
    free(r->p);
    free(r->q);
    free(r->deformed);
    for (uint32_t i = 0; r->metric_keys && i < r->nmetrics; i++)
        free(r->metric_keys[i]);
    free(r->metric_keys);
    free(r->metric_values);
    memset(r, 0, sizeof *r);
}

static int copy_map(const proto_map *m, mc_map_row **out, uint32_t *n)
{
    *n = m->n;
    *out = NULL;
    if (!m->n)
        return 0;
    if (!(*out = malloc((size_t)m->n * sizeof **out)))
        return -1;
    for (uint32_t i = 0; i < m->n; i++) {
        (*out)[i].face = m->rows[i].face;
        memcpy((*out)[i].w, m->rows[i].w, sizeof (*out)[i].w);
    }
    return 0;
}

int mc__result_of(const proto_result_ok *r, unsigned what, mc_job_result *out)
{
    memset(out, 0, sizeof *out);
    static const proto_map none;
    int bad = copy_map(what & MC_WANT_P ? &r->p : &none, &out->p, &out->np) ||
              copy_map(what & MC_WANT_Q ? &r->q : &none, &out->q, &out->nq);
    if (!bad && (what & MC_WANT_DEFORMED) && r->deformed.len) {
        out->deformed_len = r->deformed.len;
        bad = !(out->deformed = malloc(r->deformed.len));
        if (!bad)
            memcpy(out->deformed, r->deformed.data, r->deformed.len);
    }
    if (!bad && (what & MC_WANT_METRICS) && r->nmetrics) {
        out->metric_keys = calloc(r->nmetrics, sizeof *out->metric_keys);
        out->metric_values = calloc(r->nmetrics, sizeof *out->metric_values);
        bad = !out->metric_keys || !out->metric_values;
        for (uint32_t i = 0; !bad && i < r->nmetrics; i++) {
            bad = !(out->metric_keys[i] = strdup(r->metrics[i].key));
            out->metric_values[i] = r->metrics[i].value;
            out->nmetrics = i + 1;
        }
    }
    if (bad) {
        mc_result_free(out);
        return MC_ENOMEM;
    }
    return 0;
}

void mc_stage_maps_free(mc_stage_maps *m)
{
    if (!m)
        return;
    free(m->p);
    free(m->q);
    memset(m, 0, sizeof *m);
}

int mc__stage_of(const proto_result_ok *r, mc_stage_maps *out)
{
    memset(out, 0, sizeof *out);
    if (copy_map(&r->rhm_p, &out->p, &out->np) || copy_map(&r->rhm_q, &out->q, &out->nq)) {
        mc_stage_maps_free(out);
        return MC_ENOMEM;
    }
    return 0;
}
