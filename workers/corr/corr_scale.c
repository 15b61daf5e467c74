/* corr_scale.c — when ECTM's membrane takes the regional area scale of the
 * maps it starts from (ectm_params.scale_reference, ectm_scale.c).
 *
 * RHM's maps that keep areas well on the whole (their mean |log area
 * ratio|, averaged over both maps, at most CORR_SCALE_MAX_LOG_AREA) place
 * each region where the landmarks and the intrinsic embedding say, and
 * their area ratios are the pair's own: ECTM then keeps them instead of
 * pulling every part back to its source area. Maps that stretch and
 * shrink more have area ratios that are mostly their own errors, which a
 * scaled membrane would keep; from such maps ECTM runs with the source's
 * metric, which corrects them on near-isometric pairs. */
#include "corr/corr.h"
#include "metric/metric.h"

#include <math.h>

/* The mean |log area ratio| up to which RHM's area ratios are taken as
 * the pair's: a typical face within a factor of about 1.57. */
#define CORR_SCALE_MAX_LOG_AREA 0.45

/* The mean |log area ratio| of P from A onto B; +inf when it cannot be
 * measured. */
static double log_area(const mesh *A, const mesh *B, const bmap *P)
{
    metric_summary m;
    return metric_summarize(A, B, P, &m) ? INFINITY : m.mean_abs_log_area;
}

int corr_scale_reference(const corr_input *in, const bmap *P, const bmap *Q)
{
    double d = log_area(in->S, in->T, P);
    if (Q)
        d = (d + log_area(in->T, in->S, Q)) / 2;
    return d <= CORR_SCALE_MAX_LOG_AREA;
}
