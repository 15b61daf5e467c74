/* fold.h — repair of the folds of a map: the flipped and collapsed
 * triangles (metric_fold_faces' rule) of a barycentric map P from S onto T
 * are relaxed away, in the spirit of the thesis' one-ring relaxation
 * (§3.4.7):
 *
 *   region  the vertices of the bad faces, grown by `rings` rings of faces;
 *   relax   each region vertex's image y_v (a point of T) <- the mean of
 *           its neighbours' images (uniform weights: on a flat patch with
 *           a fixed convex boundary, Tutte's theorem makes the result
 *           fold-free), then projected back onto T (closest point, exact,
 *           proj.h); `iterations` times, the images outside the region
 *           fixed;
 *   accept  the relaxed rows replace P's only when the map then has fewer
 *           bad faces than before, so a repair never makes a map worse.
 *
 * Landmark source vertices (when given) stay where P sends them. What it
 * cannot undo: a part mirrored as a whole (its boundary is mapped the
 * wrong way round, so no relaxation inside it is fold-free) and a thin tip
 * whose image collapsed onto its base (the relaxation keeps it collapsed).
 * Reads no files. */
#ifndef FOLD_H
#define FOLD_H
#include <stddef.h>
#include "map/bmap.h"
#include "mesh/mesh.h"

#define FOLD_ERRORS(X)                                                       \
    X(FOLD_OK,      0, "ok")                                                 \
    X(FOLD_EINVAL, -1, "invalid argument (map, meshes or parameters)")       \
    X(FOLD_ENOMEM, -2, "out of memory")                                      \
    X(FOLD_EPROJ,  -3, "projection onto the target failed")

enum fold_error {
#define FOLD_ENUM(name, val, msg) name = val,
    FOLD_ERRORS(FOLD_ENUM)
#undef FOLD_ENUM
};
const char *fold_strerror(int code);

typedef struct fold_params {
    int rings;        /* growth of the region around the bad faces  (>= 0) */
    int iterations;   /* relaxation sweeps                          (>= 1) */
} fold_params;
/* rings = 2, iterations = 400. */
void fold_params_init(fold_params *p);

typedef struct fold_report {
    int bad_before, bad_after;   /* flipped + collapsed faces             */
    int region;                  /* vertices relaxed                       */
    int accepted;                /* 1: P was changed                        */
} fold_report;

/* Repairs P (S -> T) in place. fixed: nfixed source vertices that keep
 * their rows (landmarks), or NULL. Returns FOLD_OK (rep filled; P unchanged
 * unless rep->accepted), FOLD_EINVAL, FOLD_ENOMEM or FOLD_EPROJ (P
 * unchanged). */
int fold_repair(const mesh *S, const mesh *T, const int *fixed, int nfixed,
                const fold_params *p, bmap *P, fold_report *rep);

#endif
