/* testddm.h — DDM's reference: the nearest point of a mesh embedded in R^k
 * (A: nv by k, row-major; T's faces) to a point b, by brute force over
 * every face, written independently of workers/ddm (explicit vectors in
 * R^k, every candidate of each triangle problem: the interior stationary
 * point when inside, each edge's clamped projection, the corners), and
 * reading baseline vertex maps. For the DDM test and benchmark only. */
#ifndef TESTDDM_H
#define TESTDDM_H
#include "geod/geod.h"
#include "map/bmap.h"
#include "mesh/mesh.h"

/* |x - b|^2 for x = (1 - s - t) a0 + s a1 + t a2 in R^k. */
double testddm_dist2(const double *a0, const double *a1, const double *a2, double s, double t,
                     const double *b, int k);
/* The least |x - b|^2 over every point x of every face of T. */
double testddm_brute_force(const double *A, int k, const mesh *T, const double *b);
/* |b - P_i A|^2 for row i of the barycentric map P. */
double testddm_row_cost(const bmap *P, int i, const double *A, int k, const mesh *T,
                        const double *b);

/* A vertex-map file (line i: the target vertex of source vertex i, minus
 * base) as a barycentric map (weight 1 at that vertex in its lowest face);
 * fails the test when the file is unreadable or of the wrong length. */
bmap *testddm_vertex_map(const char *path, int base, const mesh *S, const mesh *T);
/* Mean geodesic error (metric_geodesic_errors) of P over n GT pairs. */
double testddm_mean_error(geod_solver *sT, const mesh *T, const bmap *P, const int *src,
                          const int *tgt, int n);

#endif
