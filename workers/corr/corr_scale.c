/* corr_scale.c — when ECTM's membrane takes the regional area scale of the
 * maps it starts from (ectm_params.scale_reference, ectm_scale.c).
 *
 * A smooth map from RHM (median conformal distortion at most
 * CORR_SCALE_MAX_CONFORMAL on both maps) places each region where the
 * landmarks and the intrinsic embedding say, and its area ratios are the
 * pair's own: ECTM then keeps them instead of pulling every part back to its
 * source area. A rougher map's area ratios are its own errors, which a
 * scaled membrane would keep; from such a map ECTM runs with the source's
 * metric, which corrects them on near-isometric pairs. */
#include "corr/corr.h"
#include "metric/metric.h"

/* The median conformal distortion up to which a start map counts as smooth. */
#define CORR_SCALE_MAX_CONFORMAL 0.02

static int smooth(const mesh *A, const mesh *B, const bmap *P)
{
    metric_summary m;
    return !metric_summarize(A, B, P, &m) && m.median_conformal <= CORR_SCALE_MAX_CONFORMAL;
}

int corr_scale_reference(const corr_input *in, const bmap *P, const bmap *Q)
{
    return smooth(in->S, in->T, P) && (!Q || smooth(in->T, in->S, Q));
}
