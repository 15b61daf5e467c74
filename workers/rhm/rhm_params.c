/* rhm_params.c — RHM parameters (defaults of the authors' release, checks,
 * the β schedule), error strings and the result's destructor. */
#include "rhm/rhm.h"
#include "embed/embed.h"
#include "proto.h"
#include "util/errbuf.h"

#include <math.h>
#include <string.h>

/* The job parameters' defaults and ranges are the rows of PROTO_PARAMS
 * (proto_params.h) whose ENGINE column is RHM; the rest is RHM's own. */
#define RHM_ROW_RHM(x) x
#define RHM_ROW_ECTM(x)
#define RHM_ROW_NONE(x)
_Static_assert(EMBED_MAX_DIM == PROTO_RHM_MAX_DIM, "rhm_dim's max in PROTO_PARAMS is EMBED_MAX_DIM");
_Static_assert((int)RHM_START_VORONOI == (int)PROTO_START_VORONOI &&
                   (int)RHM_START_FMAP == (int)PROTO_START_FMAP, "start values");

void rhm_params_init(rhm_params *p)
{
    memset(p, 0, sizeof *p);
#define RHM_DEFAULT(name, cli, type, dflt, lo, hi, fl, eng, efield, ...) \
    RHM_ROW_##eng(p->efield = dflt;)
    PROTO_PARAMS(RHM_DEFAULT)
#undef RHM_DEFAULT
    p->beta_step = 5e-3;
    p->beta_ramp = 100;
    p->min_iterations = 110;
    p->stop_change = 1e-9;
    p->anchor = RHM_ANCHOR_WEIGHT;
    p->anchors = RHM_ANCHORS;
}

int rhm_params_check(const rhm_params *p, char *err, size_t errsz)
{
#define RHM_CHECK(name, cli, type, dflt, lo, hi, fl, eng, efield, ...)                      \
    RHM_ROW_##eng(if (proto_param_check(PROTO_P_##name, (double)p->efield, err, errsz)) \
                      return KIND_EPARAMS;)
    PROTO_PARAMS(RHM_CHECK)
#undef RHM_CHECK
#define NEED(cond, field, what)                                                     \
    if (!(cond))                                                                    \
        return errbuf_set(err, errsz, KIND_EPARAMS, "RHM parameter %s must be %s", field, what)
    NEED(isfinite(p->beta_step) && p->beta_step > 0, "beta-step", "a finite number > 0");
    NEED(p->beta_ramp >= 1, "beta-ramp", "an integer >= 1");
    NEED(p->min_iterations >= 1, "min-iterations", "an integer >= 1");
    NEED(isfinite(p->stop_change) && p->stop_change >= 0, "stop-change", "a finite number >= 0");
    NEED(isfinite(p->anchor) && p->anchor >= 0, "anchor", "a finite number >= 0");
    NEED(p->anchors >= 0, "anchors", "an integer >= 0");
    NEED(p->threads >= 0 && p->threads <= 1024, "threads", "an integer in [0, 1024]");
#undef NEED
    return KIND_OK;
}

double rhm_beta(const rhm_params *p, int k)
{
    return p->beta_step * (double)(k < p->beta_ramp ? k : p->beta_ramp);
}

void rhm_result_close(rhm_result *r)
{
    if (!r)
        return;
    bmap_free(r->P12);
    bmap_free(r->P21);
    r->P12 = r->P21 = NULL;
}
