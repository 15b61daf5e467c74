/* embed.h — a Euclidean embedding of a mesh's vertices whose distances
 * approximate geodesic (heat-method, geod.h) distances: metric MDS of a
 * farthest-point sample extended smoothly to every vertex (the recipe of
 * Panozzo et al. 2013, "Weighted averages on surfaces", which RHM follows),
 * and the numbers that say how well it does.
 *
 * Steps of embed_lmds: k landmarks by farthest-point sampling on the
 * geodesic distances (embed_farthest_points) with their k by k distances;
 * classical MDS of those (B = -1/2 J D2 J, top dim eigenpairs, LAPACK
 * dsyevr) as the start of SMACOF stress majorisation (embed_smacof; the
 * classical solution alone drops the negative eigenvalues and distorts
 * curved, branching shapes); the
 * landmark positions rotated to their principal axes (coordinate 0 varies
 * most: RHM's projection trees bound with the first three); then every other
 * vertex by the biharmonic extension (embed_biharmonic) with the solver's
 * intrinsic Delaunay operators. Deterministic: fixed start vertex, ties to
 * the lowest index, signs fixed (largest-magnitude landmark coordinate
 * positive per axis).
 *
 * Shapes: Z is nv by dim, row-major, caller-allocated. The mesh must be
 * connected (every distance finite): otherwise EMBED_EDISCONNECTED. */
#ifndef EMBED_H
#define EMBED_H
#include "geod/geod.h"

#include <stddef.h>
#include "util/errlist.h"

#define EMBED_DIM_DEFAULT 8
#define EMBED_MAX_DIM 64
#define EMBED_LANDMARKS_DEFAULT 300    /* default k, capped at nv */
#define EMBED_SMACOF_MAX_ITER 300      /* Guttman transforms at most ... */
#define EMBED_SMACOF_TOL 1e-5          /* ... or until the stress drops by less than this share */
#define EMBED_QUALITY_SOURCES 16       /* random vertex pairs for the quality sample: */
#define EMBED_QUALITY_TARGETS 64       /* sources x targets */

#define EMBED_ERRORS(X)                                                     \
    X(EMBED_OK,            0, "ok")                                         \
    X(EMBED_ENOMEM,       -1, "out of memory")                              \
    X(EMBED_EINVAL,       -2, "invalid argument")                           \
    X(EMBED_EGEOD,        -3, "geodesic distances failed")                  \
    X(EMBED_EDISCONNECTED,-4, "mesh not connected")                         \
    X(EMBED_EEIGEN,       -5, "eigen-solver failed")                       \
    X(EMBED_ESOLVE,       -6, "sparse solve failed")

ERRLIST_ENUM(embed, EMBED_ERRORS);

/* stress = sqrt(sum (d_emb - d_geo)^2 / sum d_geo^2); corr = Pearson
 * correlation of d_emb with d_geo. */
typedef struct embed_quality {
    int landmarks;          /* k used */
    double stress_landmarks, corr_landmarks;  /* over the k (k-1) / 2 landmark pairs */
    int pairs_sample;       /* random vertex pairs measured (source != target) */
    double stress_sample, corr_sample;        /* d_geo: field of the pair's source */
    double eigen_kept;      /* classical start: kept eigenvalues / sum of |all eigenvalues| */
    double stress_classical;/* the landmark stress before SMACOF */
    int smacof_iterations;
} embed_quality;

/* Z: nv by dim. dim <= 0: EMBED_DIM_DEFAULT; k <= 0: the default count;
 * start: the first landmark (vertex). q may be NULL (then no quality sample
 * is drawn: it costs EMBED_QUALITY_SOURCES more distance fields).
 * Errors: EMBED_EINVAL (dim over EMBED_MAX_DIM, k not in dim+1..nv, start
 * out of range), EMBED_EGEOD, EMBED_EDISCONNECTED, EMBED_EEIGEN,
 * EMBED_ENOMEM; detail in err. */
int embed_lmds(geod_solver *s, int dim, int k, int start, double *Z,
               embed_quality *q, char *err, size_t errsz);

/* Farthest-point sampling: pts[0] = start, pts[j] = the vertex farthest
 * (geodesically) from pts[0..j-1] (lowest index on ties). D: k by k,
 * symmetric, D[i][j] = the distance field of pts[max(i, j)] at the other
 * point. Errors as embed_lmds. */
int embed_farthest_points(geod_solver *s, int start, int k, int *pts, double *D,
                          char *err, size_t errsz);

/* SMACOF with unit weights: Y (k by dim, row-major; in: the start, out:
 * the result) moved by Guttman transforms, which never raise the raw
 * stress sum_{i<j} (|y_i - y_j| - D_ij)^2, until it drops by less than
 * tol of itself or after max_iter transforms (count in *iterations, may be
 * NULL). D: k by k symmetric. EMBED_ENOMEM or EMBED_OK. */
int embed_smacof(const double *D, int k, int dim, int max_iter, double tol, double *Y,
                 int *iterations);

/* Z (nv by dim, row-major): rows fixed[a] = Y[a] (k by dim), every other
 * row the minimiser of the biharmonic energy tr(Zᵀ L M⁻¹ L Z), L (nv by nv,
 * positive semi-definite, both triangles) and M (mass, nv) as geod.h
 * hands them out. Every connected component needs a fixed vertex.
 * Errors: EMBED_ENOMEM, EMBED_ESOLVE (detail in err). */
int embed_biharmonic(const geo_csr *L, const double *mass, const int *fixed, int k,
                     const double *Y, int dim, double *Z, char *err, size_t errsz);

/* Top m eigenpairs of the symmetric n by n matrix A (row-major, only read):
 * w: m eigenvalues, descending; V: n by m, column i the unit eigenvector of
 * w[i], sign fixed so its largest-magnitude entry is positive. If all_w is
 * not NULL it receives all n eigenvalues, ascending. EMBED_EEIGEN when
 * LAPACK fails, EMBED_ENOMEM. */
int embed_top_eigenpairs(const double *A, int n, int m, double *w, double *V,
                         double *all_w);

/* Stress and Pearson correlation (definitions above) of n distance pairs. */
void embed_distance_fit(const double *d_geo, const double *d_emb, int n,
                        double *stress, double *corr);

#endif
