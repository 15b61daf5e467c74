/* corr_params.c — a job's parameters (proto_params, the wire form of the one
 * list PROTO_PARAMS) to the engine's ectm_params and rhm_params and back,
 * generated from the list's ENGINE column: the one mapping the worker, the
 * CLI and the tests use. */
#include "corr/corr.h"
#include "proto.h"
#include "util/errbuf.h"

#include <stdio.h>
#include <string.h>

/* ENGINE column -> the struct a row's field lives in. */
#define CORR_DST_ECTM(p, r) p
#define CORR_DST_RHM(p, r) r
#define CORR_HAS_ECTM(x) x
#define CORR_HAS_RHM(x) x
#define CORR_HAS_NONE(x)

int corr_params_from_job(const proto_params *w, int threads, ectm_params *p, rhm_params *r,
                         char *err, size_t errsz)
{
    ectm_params_init(p);
    rhm_params_init(r);
    if (proto_params_check(w, err, errsz))
        return KIND_EPARAMS;
    /* in range now: counts fit an int; a 0 that means the default keeps it */
#define CORR_FROM(name, cli, type, dflt, lo, hi, fl, eng, efield, ...)                      \
    CORR_HAS_##eng(if (!(((fl) & PROTO_PARAM_ZERO_DEFAULT) && w->name == 0))               \
                       CORR_DST_##eng(p, r)->efield = w->name;)
    PROTO_PARAMS(CORR_FROM)
#undef CORR_FROM
    p->threads = r->threads = threads;
    if (w->backend[0]) {                 /* "NAME[:DEVICE]", lengths checked above */
        size_t n = strcspn(w->backend, ":");
        snprintf(p->backend, sizeof p->backend, "%.*s", (int)n, w->backend);
        snprintf(p->device, sizeof p->device, "%s", w->backend[n] ? w->backend + n + 1 : "");
    }
    return KIND_OK;
}

void corr_params_to_job(const ectm_params *p, const rhm_params *r, proto_params *w, char *backend,
                        size_t bsz)
{
    rhm_params rdef;
    if (!r) {
        rhm_params_init(&rdef);
        r = &rdef;
    }
#define CORR_TO(name, cli, type, dflt, lo, hi, fl, eng, efield, ...) \
    CORR_HAS_##eng(w->name = CORR_DST_##eng(p, r)->efield;)
    PROTO_PARAMS(CORR_TO)
#undef CORR_TO
    if (backend) {
        snprintf(backend, bsz, "%s%s%s", p->backend, p->device[0] ? ":" : "", p->device);
        w->backend = backend;
    }
}
