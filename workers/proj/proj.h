/* proj.h — exact projection onto a triangle mesh embedded in R^d: the P-step
 * of ECTM (d = 6) and of RHM (d = 2m).
 *
 * The target's connectivity and its 3-D positions X̃ are fixed for a job; a
 * proj_tree holds an Embree 3 BVH over them. A projection embeds the target
 * with vertex coordinates Z (nt by d) whose first three columns are s·X̃
 * (s > 0), and for each query row q (d values) finds the closest point of
 * the embedded target. Because |q − p|² ≥ |q[0:3] − p[0:3]|² =
 * s²·dist₃(q[0:3]/s, triangle)², an Embree point query around q[0:3]/s whose
 * radius shrinks to √(best cost)/s visits every triangle that can win; the
 * previous assignment (face[i] >= 0 on entry) seeds the bound. From
 * d = PROJ_HD_MIN_DIM on, the search runs over a box hierarchy of Z in R^d
 * instead (built per call), the tree's 3-D BVH is not used and Z's first
 * columns need not be s·X̃ (the tree still gives the connectivity).
 *
 * Result: face[i], bary[3i..3i+2] (weights of the face's vertices in their
 * listed order) and cost[i] (squared R^d distance; cost may be NULL). Exact:
 * the same cost as brute force (ties may pick another face of equal cost).
 * Rows run in parallel (OpenMP) on the committed scene. Degenerate triangles
 * (zero area, in R^3 or R^d) are handled: their closest point is the best of
 * their three edges (a zero-length edge is a point).
 *
 * Ownership: proj_tree_new returns a tree freed by proj_tree_free (NULL ok);
 * it copies what it needs from target and keeps no pointer to it. */
#ifndef PROJ_H
#define PROJ_H
#include <stddef.h>
#include "mesh/mesh.h"
#include "util/errlist.h"

#define PROJ_ERRORS(X)                                                      \
    X(PROJ_OK,      0, "ok")                                                \
    X(PROJ_EINVAL, -1, "invalid argument (d < 3, s <= 0 or n < 0)")         \
    X(PROJ_EFACE,  -2, "previous assignment face index out of range")       \
    X(PROJ_EMESH,  -3, "target mesh has a bad index or non-finite vertex")  \
    X(PROJ_EEMBREE,-4, "Embree error")                                      \
    X(PROJ_ENOMEM, -5, "out of memory")

ERRLIST_ENUM(proj, PROJ_ERRORS);

#define PROJ_HD_MIN_DIM 8

typedef struct proj_tree proj_tree;

/* NULL on failure, with the reason in err and errno ENOMEM when memory ran
 * out (malloc's or Embree's: a worker under its memory limit), else EINVAL
 * (a bad target, another Embree error). */
proj_tree *proj_tree_new(const mesh *target, char *err, size_t errsz);
void proj_tree_free(proj_tree *t);

/* Returns 0, PROJ_EINVAL if d < 3, s <= 0 or n < 0, or PROJ_EFACE if an
 * entry face[i] >= target->nf (negative entries mean "no previous
 * assignment"), PROJ_ENOMEM. Nothing is written on error. */
int proj_closest(const proj_tree *t, int d, const double *Z, double s,
                 int n, const double *Q, int *face, double *bary, double *cost);

/* Reference: every row against every face. Same contract (face[] in-values
 * ignored). For tests and benchmarks. */
void proj_closest_brute(const mesh *target, int d, const double *Z,
                        int n, const double *Q, int *face, double *bary, double *cost);

/* Exact closest point to q on triangle (a, b, c) in R^d: returns the squared
 * distance and the barycentric weights of a, b, c (non-negative, sum 1). */
double proj_point_triangle(int d, const double *q, const double *a,
                           const double *b, const double *c, double bary[3]);

#endif
