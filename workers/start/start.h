/* start.h — RHM's start from landmarks (p_r on M1, q_r on M2, r = 1..nl):
 * the maps P12, P21 that RHM (rhm.h) iterates from, three kinds and a rule
 * among them:
 *  - distances (start_distances.c): every vertex described by its geodesic
 *    distances to the landmarks of its side, divided by √(area); P12 row v
 *    = the closest point to v's description on M2 with M2's descriptions as
 *    vertex coordinates (an exact projection in R^nl, proj.h), P21 the same
 *    the other way. Not the thesis' start: it is ours, because the Voronoi
 *    start below collapses every cell to a point and a limb's turn about its
 *    axis is then left to chance (docs/decisions.md, "RHM's start:
 *    distances, then the functional map").
 *  - voronoi (start_voronoi.c, thesis §3.3.2): P12 sends every vertex of a
 *    geodesic Voronoi cell of M1 (centres: source landmarks) to the cell's
 *    target landmark; P21 sends every vertex v of M2 to the source landmark
 *    whose target landmark is nearest to v in M2's embedding (the nearest
 *    neighbour of v among the images T12(V1), which are exactly the target
 *    landmarks; ties to the lower landmark index).
 *  - fmap (start_fmap.c): a functional map from the landmarks' descriptors
 *    (Δ + D_N commutativity, fmap.h), made precise by DDM's deblurring.
 *  - auto (the default, start_choose.c): distances first; the pipeline
 *    (corr_rhm, corr.h) repairs RHM's maps and, when they come out folded,
 *    runs the functional-map start too and keeps the less folded pair.
 * RHM then sets X_ij = P_ij X_j. The kinds are RHM_START_* (rhm.h), the
 * job parameter start. This module reads no files. */
#ifndef START_H
#define START_H
#include <stddef.h>
#include "rhm/rhm.h"

/* Basis size of the functional-map start (the k of fmap's tests and
 * figures), capped by what a small mesh has; ZoomOut (rhm_params.zoomout)
 * grows it from there. */
#define START_FMAP_K 50

/* The distances start describes a vertex by its distances to the
 * landmarks / √area and, for r = 0..nl−1, START_ORIENT_WEIGHT times the
 * sine of the angle from ∇d_r to ∇d_{(r+1) mod nl} (geo_orient.h): the
 * features a mirrored match negates. The weight is about a quarter of a
 * typical distance at unit area: enough to tell a shape's front from its
 * back when the distances cannot, small enough to leave the distances in
 * charge elsewhere. */
#define START_ORIENT_WEIGHT 0.25

/* The three kinds. Each fills side[0].P (P12) and side[1].P (P21), sized
 * by RHM; errors are RHM_* codes with the detail in err. */
int start_distances(rhm_side side[2], char *err, size_t errsz);
int start_voronoi(rhm_side side[2], char *err, size_t errsz);
/* zoomout: ZoomOut's final basis size (rhm_params.zoomout); 0: off. */
int start_fmap(rhm_side side[2], int zoomout, char *err, size_t errsz);

/* The start of kind p->start (auto: distances) into side[0].P and
 * side[1].P: an rhm_start_fn. */
int start_maps(const rhm_params *p, rhm_side side[2], char *err, size_t errsz);

/* RHM from the landmark pairs L (at least PROTO_MIN_LANDMARKS) started by
 * start_maps: rhm_run_start with out->start the kind that ran. Arguments
 * and errors as rhm_run_start. */
int start_run(const mesh *S, const mesh *T, const lmk_set *L, const rhm_params *p,
              rhm_progress_fn progress, void *ctx, rhm_result *out, char *err, size_t errsz);

/* The rule of auto. start_first: the kind to run first for the job
 * parameter start (auto: distances; any other: itself). start_second: the
 * kind to run next when the first run's repaired maps have the folded
 * fraction folded (metric.h), or -1 for none: the functional map when
 * start is auto and metric_verdict calls the fraction worse than OK.
 * start_keep_second: whether the second run's maps, with their folded
 * fraction, replace the first's (strictly less folded). */
int start_first(int start);
int start_second(int start, double folded);
int start_keep_second(double folded_first, double folded_second);

#endif
