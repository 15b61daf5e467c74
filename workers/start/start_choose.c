/* start_choose.c — the choice among the starts (start.h): the kind a job
 * parameter start runs, RHM from landmarks started that way, and the rule
 * of auto (distances first, the functional map when the first maps come
 * out folded, the less folded kept). */
#include "start/start.h"
#include "metric/metric.h"

int start_maps(const rhm_params *p, rhm_side side[2], char *err, size_t errsz)
{
    return p->start == RHM_START_VORONOI ? start_voronoi(side, err, errsz)
         : p->start == RHM_START_FMAP    ? start_fmap(side, p->zoomout, err, errsz)
                                         : start_distances(side, err, errsz);
}

int start_run(const mesh *S, const mesh *T, const lmk_set *L, const rhm_params *p,
              rhm_progress_fn progress, void *ctx, rhm_result *out, char *err, size_t errsz)
{
    int rc = rhm_run_start(S, T, L, p, start_maps, progress, ctx, out, err, errsz);
    if (!rc)
        out->start = start_first(p->start);
    return rc;
}

int start_first(int start)
{
    return start == RHM_START_AUTO ? RHM_START_DISTANCES : start;
}

int start_second(int start, double folded)
{
    return start == RHM_START_AUTO && metric_verdict(folded, 0) != METRIC_VERDICT_OK
               ? RHM_START_FMAP : -1;
}

int start_keep_second(double folded_first, double folded_second)
{
    return folded_second < folded_first;
}
