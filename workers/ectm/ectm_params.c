/* ectm_params.c — ECTM's parameters (the defaults and ranges of the job
 * parameter list, the paper's values, checks, the β schedule). Apart from ectm.c so that
 * what only checks a job's parameters (the daemon's validator) links
 * without the optimisation. */
#include "ectm/ectm.h"
#include "ener/ener_def.h"
#include "proto.h"
#include "util/errbuf.h"

#include <math.h>
#include <string.h>

/* The job parameters' defaults and ranges are the rows of PROTO_PARAMS
 * (proto_params.h) whose ENGINE column is ECTM; the rest is ECTM's own. */
#define ECTM_ROW_ECTM(x) x
#define ECTM_ROW_RHM(x)
#define ECTM_ROW_NONE(x)
_Static_assert((int)ECTM_INJECTIVE == (int)PROTO_MODEL_INJECTIVE, "model values");

void ectm_params_init(ectm_params *p)
{
    memset(p, 0, sizeof *p);
#define ECTM_DEFAULT(name, cli, type, dflt, lo, hi, fl, eng, efield, ...) \
    ECTM_ROW_##eng(p->efield = dflt;)
    PROTO_PARAMS(ECTM_DEFAULT)
#undef ECTM_DEFAULT
    p->log_eps = ENER_LOG_EPS_DEFAULT;
    strcpy(p->backend, "cpu");
}

void ectm_params_paper(ectm_params *p)
{
    ectm_params_init(p);
    p->eta = 1e-3;
    p->beta0 = 1e3;
    p->beta1 = 2e5;
    p->gamma = 2e4;
}

int ectm_params_check(const ectm_params *p, char *err, size_t errsz)
{
#define ECTM_CHECK(name, cli, type, dflt, lo, hi, fl, eng, efield, ...)                      \
    ECTM_ROW_##eng(if (proto_param_check(PROTO_P_##name, (double)p->efield, err, errsz)) \
                       return KIND_EPARAMS;)
    PROTO_PARAMS(ECTM_CHECK)
#undef ECTM_CHECK
#define NEED(cond, field, what)                                                     \
    if (!(cond))                                                                    \
        return errbuf_set(err, errsz, KIND_EPARAMS, "parameter %s must be %s", field, what)
    NEED(isfinite(p->log_eps) && p->log_eps > 0 && p->log_eps < 1, "log-eps", "in (0, 1)");
    NEED(p->threads >= 0 && p->threads <= 1024, "threads", "an integer in [0, 1024]");
    NEED(memchr(p->backend, 0, sizeof p->backend) &&
         (!p->backend[0] || !strcmp(p->backend, "cpu") || !strcmp(p->backend, "opencl") ||
          !strcmp(p->backend, "auto")), "backend", "cpu, opencl or auto");
    NEED(memchr(p->device, 0, sizeof p->device), "device", "shorter than 128 bytes");
#undef NEED
    return KIND_OK;
}

double ectm_beta(const ectm_params *p, int k)
{
    if (p->beta_ramp <= 1 || k >= p->beta_ramp)
        return k >= p->beta_ramp ? p->beta1 : p->beta0;
    double t = (double)(k - 1) / (p->beta_ramp - 1);
    return p->beta0 + (p->beta1 - p->beta0) * (t < 0 ? 0 : t);
}

int ectm_stop_may_end(const ectm_params *p, int k)
{
    return p->stop_change > 0 && k > ECTM_STOP_WINDOW &&
           ectm_beta(p, k - ECTM_STOP_WINDOW) == ectm_beta(p, k);
}

int ectm_first_stop(const ectm_params *p)
{
    for (int k = 1; k < p->iterations; k++)
        if (ectm_stop_may_end(p, k))
            return k;
    return p->iterations;
}
