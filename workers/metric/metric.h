/* metric.h — quality measures of a map, computed per source triangle from
 * the source mesh and the mapped positions of its vertices (e.g. P·X̃):
 *   area distortion        log(a_t / â_t)
 *   conformal distortion   σ₁/σ₂ + σ₂/σ₁ − 2 of the linear map of triangle t
 * Areas are compared after scaling both meshes to unit total area, which the
 * caller passes as the two total areas. A triangle whose image is collapsed
 * (zero area) has area distortion −inf and conformal distortion +inf;
 * metric_summary counts those apart. Then per map: mean-curvature error,
 * coverage of the target, round trip, and geodesic error to a ground truth
 * (definitions at each function). Every measure is taken with both meshes
 * scaled to unit area. Functions returning int allocate their scratch and
 * return METRIC_ENOMEM (-1) when out of memory; one that needs more of a
 * mesh than the caller checked (its edge table) says why in a caller's
 * buffer (METRIC_EMESH); nothing here reads files. */
#ifndef METRIC_H
#define METRIC_H
#include "geod/geod.h"
#include "map/bmap.h"
#include "mesh/mesh.h"

#include <stddef.h>
#include "util/errlist.h"

#define METRIC_ERRORS(X)                                                    \
    X(METRIC_OK,      0, "ok")                                              \
    X(METRIC_ENOMEM, -1, "out of memory")                                   \
    X(METRIC_EMESH,  -2, "a mesh is not usable for this measure (not manifold)")

ERRLIST_ENUM(metric, METRIC_ERRORS);

/* logratio: nf values. src_area, img_area_total: total areas used for the
 * unit-area normalisation of source and image (the target's total area). */
void metric_area_distortion(const mesh *S, const double *img, double src_area,
                            double tgt_area, double *logratio);
/* conf: nf values (0 for a similarity). */
void metric_conformal_distortion(const mesh *S, const double *img, double *conf);

typedef struct metric_summary {
    double mean_abs_log_area;   /* over non-collapsed triangles */
    double median_conformal;    /* over non-collapsed triangles */
    double mean_conformal;      /* over non-collapsed triangles */
    double flipped_fraction;    /* image triangle's normal opposite to the
                                   target's normal where it lands            */
    double collapsed_fraction;  /* image area below 1e-12 of the source's     */
} metric_summary;

/* Per source face t of the map P from S onto T, the rule metric_summarize
 * counts by: kind[t] = METRIC_FACE_COLLAPSED when its image's area is below
 * 1e-12 of the source face's (unit-area scale) or its conformal distortion
 * is not finite, METRIC_FACE_FLIPPED when the image's normal is opposite to
 * the target's vertex normals interpolated where its corners land, else
 * METRIC_FACE_OK. Returns the number of faces not OK, or -1 when out of
 * memory. */
enum { METRIC_FACE_OK = 0, METRIC_FACE_FLIPPED = 1, METRIC_FACE_COLLAPSED = 2 };
int metric_fold_faces(const mesh *S, const mesh *T, const bmap *P, unsigned char *kind);
/* That rule on face t alone, for a caller that moves one image at a time:
 * img the images P·X̃ (3 per source vertex, P's rows), tn T's vertex
 * normals (geo_vertex_normals), src_area and tgt_area the total areas;
 * lr (may be NULL) gets the face's log area ratio (unit-area scale). */
int metric_face_kind(const mesh *S, const mesh *T, const bmap *P, const double *img,
                     const double *tn, double src_area, double tgt_area, int t, double *lr);

/* What that rule compares for face t: n, the normal of its image (img's
 * corners, unnormalised), and m, the sum of the target's vertex normals tn
 * interpolated where its corners land. */
void metric_face_normals(const mesh *S, const mesh *T, const bmap *P, const double *img,
                         const double *tn, int t, double n[3], double m[3]);

/* The verdict a result carries (the one rule for the worker and the
 * clients): METRIC_VERDICT_REVERSED when more than half of the triangles
 * are flipped (the map reverses orientation: a shape mirrored front onto
 * back or left onto right), METRIC_VERDICT_FOLDED when flipped plus
 * collapsed exceed METRIC_FOLDED_MAX, else METRIC_VERDICT_OK. */
#define METRIC_FOLDED_MAX 0.05
enum { METRIC_VERDICT_OK = 0, METRIC_VERDICT_FOLDED = 1, METRIC_VERDICT_REVERSED = 2 };
int metric_verdict(double flipped_fraction, double collapsed_fraction);
/* "" for OK, else a sentence for the user, e.g. "the map reverses
 * orientation (63.2 % of its triangles are flipped)". */
void metric_verdict_text(int verdict, double flipped_fraction, double collapsed_fraction,
                         char *buf, size_t bufsz);

/* Summary of the map P from S onto T (images P·X̃). Returns 0, or -1 when
 * out of memory (out is then NaN-filled). */
int metric_summarize(const mesh *S, const mesh *T, const bmap *P, metric_summary *out);

/* The mean-curvature error ‖P·H̃ − H‖_X with H, H̃ the mean curvatures of
 * S and T after scaling each to unit area, and the norm weighted by S's
 * unit-area lumped mass: √(Σ_i m_i (PH̃ − H)_i²). The curvatures are the
 * neighbourhood fit of geo_curvature.h (the paper's estimator, [KSNS07])
 * with one radius for both meshes: METRIC_CURVATURE_EDGES mean edge
 * lengths of the coarser one (at unit area), so two triangulations of one
 * shape compare at the same scale (test_geo_curvature bounds the fit's error
 * on a jittered sphere). Not the cotan formula: its per-vertex noise on
 * irregular meshes, uncorrelated between S and T, would dominate the figure,
 * so that an exact map scores nearly what a rough one does. */
#define METRIC_CURVATURE_EDGES 3.0
/* METRIC_OK; METRIC_ENOMEM, or METRIC_EMESH for a mesh without an edge
 * table (an edge of more than two faces: "source mesh: ...") or a fit that
 * fails, with why in err (*out NaN). */
int metric_curvature_error(const mesh *S, const mesh *T, const bmap *P, double *out, char *err,
                           size_t errsz);

/* Coverage of the target by the map P: the fraction of T's area (lumped
 * vertex masses) at target vertices lying within `radius` (unit-area
 * scale, e.g. METRIC_COVER_RADIUS) of a mapped source vertex P·X̃. 1 for a
 * map whose image is spread over the whole target at that resolution; a map
 * that collapses onto a region covers little. NAN when out of memory. */
#define METRIC_COVER_RADIUS 0.05
double metric_coverage(const mesh *T, const bmap *P, double radius);

/* The round trip T -> S -> T: ‖Q·(P·X̃) − X̃‖_X̃, the target-mass-weighted
 * RMS distance (unit-area target) between each target vertex and where Q
 * then P take it. Q maps T to S. */
int metric_round_trip(const mesh *S, const mesh *T, const bmap *P, const bmap *Q, double *out);

/* Geodesic error to a ground truth: for pair k (source vertex src[k],
 * target vertex tgt[k]), the geodesic distance on T from tgt[k] to P's image
 * of src[k], as the barycentric interpolation at that point of the
 * heat-method distance field from tgt[k] (gT: T's solver), divided by
 * √(area of T). err: nmaps by n, row a for maps[a] (the fields are shared,
 * so scoring several maps together costs one field per distinct tgt).
 * Returns 0, -1 when out of memory, or the geod error code. */
int metric_geodesic_errors(geod_solver *gT, const mesh *T, const bmap *const *maps, int nmaps,
                           const int *src, const int *tgt, int n, double *err);

/* curve[s] = fraction of the n errors <= tmax·s/(nsteps − 1), s = 0..nsteps−1. */
void metric_error_curve(const double *err, int n, double tmax, int nsteps, double *curve);

#endif
