/* embed.h — a Euclidean embedding of a mesh's vertices whose distances
 * approximate geodesic (heat-method, geod.h) distances, by landmark MDS (de
 * Silva & Tenenbaum 2004), and the numbers that say how well it does.
 *
 * Steps of embed_lmds: k landmarks by farthest-point sampling on the
 * geodesic distances (embed_farthest_points); their k by k distances,
 * symmetrised ((d(a,b) + d(b,a)) / 2), squared and double-centred,
 * B = -1/2 J D2 J; the top dim eigenpairs of B (LAPACK dsyevr); then every
 * vertex x triangulated with the pseudo-inverse formula
 *     z(x)_i = -1/2 v_i^T (d2(x) - mean column of D2) / sqrt(lambda_i),
 * which puts each landmark at its classical-MDS position. A coordinate whose
 * eigenvalue is not positive (the distances are not Euclidean in that many
 * dimensions) is set to 0. Deterministic: fixed start vertex, ties to the
 * lowest index, eigenvector signs fixed (largest component positive).
 *
 * Shapes: Z is nv by dim, row-major, caller-allocated. The mesh must be
 * connected (every distance finite): otherwise EMBED_EDISCONNECTED. */
#ifndef EMBED_H
#define EMBED_H
#include "geod/geod.h"

#include <stddef.h>

#define EMBED_DIM_DEFAULT 8
#define EMBED_MAX_DIM 64
#define EMBED_MIN_LANDMARKS 50         /* default k = max(3 dim, 50), capped at nv */
#define EMBED_QUALITY_SOURCES 16       /* random vertex pairs for the quality sample: */
#define EMBED_QUALITY_TARGETS 64       /* sources x targets */

#define EMBED_ERRORS(X)                                                     \
    X(EMBED_OK,            0, "ok")                                         \
    X(EMBED_ENOMEM,       -1, "out of memory")                              \
    X(EMBED_EINVAL,       -2, "invalid argument")                           \
    X(EMBED_EGEOD,        -3, "geodesic distances failed")                  \
    X(EMBED_EDISCONNECTED,-4, "mesh not connected")                         \
    X(EMBED_EEIGEN,       -5, "eigen-solver failed")

enum embed_error {
#define EMBED_ENUM(name, val, msg) name = val,
    EMBED_ERRORS(EMBED_ENUM)
#undef EMBED_ENUM
};
const char *embed_strerror(int code);

/* stress = sqrt(sum (d_emb - d_geo)^2 / sum d_geo^2); corr = Pearson
 * correlation of d_emb with d_geo. */
typedef struct embed_quality {
    int landmarks;          /* k used */
    double stress_landmarks, corr_landmarks;  /* over the k (k-1) / 2 landmark pairs */
    int pairs_sample;       /* random vertex pairs measured (source != target) */
    double stress_sample, corr_sample;        /* d_geo: field of the pair's source */
    double eigen_kept;      /* sum of the kept eigenvalues / sum of |all eigenvalues| */
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
 * (geodesically) from pts[0..j-1] (lowest index on ties). fields: k by nv,
 * row j = distances from pts[j] (the fields the sampling needed anyway).
 * Errors as embed_lmds. */
int embed_farthest_points(geod_solver *s, int start, int k, int *pts, double *fields,
                          char *err, size_t errsz);

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
