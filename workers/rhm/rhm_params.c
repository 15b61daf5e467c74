/* rhm_params.c — RHM parameters (defaults of the authors' release, checks,
 * the β schedule), error strings and the result's destructor. */
#include "rhm/rhm.h"
#include "embed/embed.h"
#include "util/errbuf.h"

#include <math.h>
#include <string.h>

const char *rhm_strerror(int code)
{
    switch (code) {
#define RHM_STR(name, val, msg) case name: return msg;
        RHM_ERRORS(RHM_STR)
#undef RHM_STR
    }
    return "unknown RHM error";
}

const char *rhm_start_name(int start)
{
    return start == RHM_START_DISTANCES ? "distances" : start == RHM_START_VORONOI ? "voronoi" : NULL;
}

int rhm_start_parse(const char *name)
{
    for (int s = RHM_START_DISTANCES; s <= RHM_START_VORONOI; s++)
        if (strcmp(name, rhm_start_name(s)) == 0)
            return s;
    return -1;
}

void rhm_params_init(rhm_params *p)
{
    memset(p, 0, sizeof *p);
    p->start = RHM_START_DISTANCES;
    p->alpha = 5e-4;
    p->beta_step = 5e-3;
    p->beta_ramp = 100;
    p->gamma = 0;
    p->dim = EMBED_DIM_DEFAULT;
    p->iterations = 200;
    p->min_iterations = 110;
    p->stop_change = 1e-9;
}

int rhm_params_check(const rhm_params *p, char *err, size_t errsz)
{
#define NEED(cond, field, what)                                                     \
    if (!(cond))                                                                    \
        return errbuf_set(err, errsz, RHM_EPARAM, "RHM parameter %s must be %s", field, what)
    NEED(rhm_start_name(p->start) != NULL, "start", "distances or voronoi");
    NEED(isfinite(p->alpha) && p->alpha > 0 && p->alpha < 1, "alpha", "in (0, 1)");
    NEED(isfinite(p->beta_step) && p->beta_step > 0, "beta-step", "a finite number > 0");
    NEED(p->beta_ramp >= 1, "beta-ramp", "an integer >= 1");
    NEED(isfinite(p->gamma) && p->gamma >= 0, "landmark-weight", "a finite number >= 0");
    NEED(p->dim >= 3 && p->dim <= EMBED_MAX_DIM, "dim", "an integer in [3, 64]");
    NEED(p->iterations >= 1 && p->iterations <= 1000000, "iterations", "an integer in [1, 1000000]");
    NEED(p->min_iterations >= 1, "min-iterations", "an integer >= 1");
    NEED(isfinite(p->stop_change) && p->stop_change >= 0, "stop-change", "a finite number >= 0");
    NEED(p->threads >= 0 && p->threads <= 1024, "threads", "an integer in [0, 1024]");
#undef NEED
    return RHM_OK;
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
