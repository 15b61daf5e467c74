/* embed_fit.c — how well embedded distances fit geodesic ones: stress and
 * Pearson correlation; see embed.h. Pure arithmetic on given pairs. */
#include "embed/embed.h"

#include <math.h>

void embed_distance_fit(const double *d_geo, const double *d_emb, int n,
                        double *stress, double *corr)
{
    double se = 0, sg = 0, mg = 0, me = 0;
    for (int i = 0; i < n; i++) {
        se += (d_emb[i] - d_geo[i]) * (d_emb[i] - d_geo[i]);
        sg += d_geo[i] * d_geo[i];
        mg += d_geo[i];
        me += d_emb[i];
    }
    mg /= n;
    me /= n;
    double cge = 0, cgg = 0, cee = 0;
    for (int i = 0; i < n; i++) {
        double g = d_geo[i] - mg, e = d_emb[i] - me;
        cge += g * e;
        cgg += g * g;
        cee += e * e;
    }
    *stress = sg > 0 ? sqrt(se / sg) : NAN;
    *corr = cgg > 0 && cee > 0 ? cge / sqrt(cgg * cee) : NAN;
}
