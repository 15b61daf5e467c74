/* init_affine.h — an initial map from landmarks alone: the affine map of R³
 * that best sends the source landmarks onto the target landmarks (least
 * squares), applied to every source vertex, followed by the closest point on
 * the target surface. Crude where the shapes differ in pose, but smooth and
 * landmark-consistent: ECTM starts from it. Needs at least 4 landmark pairs
 * whose source positions are not coplanar. */
#ifndef INIT_AFFINE_H
#define INIT_AFFINE_H
#include <stddef.h>
#include "lmk/lmk.h"
#include "map/bmap.h"
#include "mesh/mesh.h"

#define INIT_ERRORS(X)                                                        \
    X(INIT_OK,           0, "ok")                                             \
    X(INIT_EDEGENERATE, -1, "landmarks do not span 3-D space")                \
    X(INIT_ENOMEM,      -2, "out of memory")

enum init_error {
#define INIT_ENUM(name, val, msg) name = val,
    INIT_ERRORS(INIT_ENUM)
#undef INIT_ENUM
};

/* A (3×3, row-major) and t such that A·x + t fits the landmark pairs. */
int init_affine_fit(const mesh *S, const mesh *T, const lmk_set *L,
                    double A[9], double t[3], char *err, size_t errsz);
/* The map P (S->nv rows onto T's faces) described above. */
int init_affine_map(const mesh *S, const mesh *T, const lmk_set *L,
                    bmap **out, char *err, size_t errsz);

#endif
