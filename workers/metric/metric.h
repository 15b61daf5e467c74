/* metric.h — quality measures of a map, computed per source triangle from
 * the source mesh and the mapped positions of its vertices (e.g. P·X̃):
 *   area distortion        log(a_t / â_t)
 *   conformal distortion   σ₁/σ₂ + σ₂/σ₁ − 2 of the linear map of triangle t
 * Areas are compared after scaling both meshes to unit total area, which the
 * caller passes as the two total areas. A triangle whose image is collapsed
 * (zero area) has area distortion −inf and conformal distortion +inf;
 * metric_summary counts those apart. Pure functions, no allocation but the
 * caller's arrays. */
#ifndef METRIC_H
#define METRIC_H
#include "map/bmap.h"
#include "mesh/mesh.h"

/* logratio: nf values. src_area, img_area_total: total areas used for the
 * unit-area normalisation of source and image (the target's total area). */
void metric_area_distortion(const mesh *S, const double *img, double src_area,
                            double tgt_area, double *logratio);
/* conf: nf values (0 for a similarity). */
void metric_conformal_distortion(const mesh *S, const double *img, double *conf);

typedef struct metric_summary {
    double mean_abs_log_area;   /* over non-collapsed triangles */
    double median_conformal;    /* over non-collapsed triangles */
    double flipped_fraction;    /* image triangle's normal opposite to the
                                   target's normal where it lands            */
    double collapsed_fraction;  /* image area below 1e-12 of the source's     */
} metric_summary;

/* Summary of the map P from S onto T (images P·X̃). Returns 0, or -1 when
 * out of memory (out is then NaN-filled). */
int metric_summarize(const mesh *S, const mesh *T, const bmap *P, metric_summary *out);

#endif
