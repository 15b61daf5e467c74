/* geod__solver.h — internal (geod__): the solver's state, shared by
 * geod_solver.c (building and factorising) and geod_distances.c (solving).
 * Not part of the public geod_ API. */
#ifndef GEOD__SOLVER_H
#define GEOD__SOLVER_H
#include "geod/geod.h"
#include "chol/chol.h"
#include "geo/geo_csr.h"

struct geod_solver {
    int nv, nf;
    double t;                /* heat time */
    int *f;                  /* nf by 3: the intrinsic Delaunay triangles (geod__idt.h) */
    double *grad;            /* nf by 6: gradients of the 3 hat functions in each
                                triangle's own plane frame, 0 on degenerate faces */
    double *area;            /* nf */
    int flips;               /* edges flipped to make the triangulation Delaunay */
    geo_csr *L;              /* its cotan Laplacian (both triangles) */
    double *mass;            /* nv: its lumped mass */
    int *comp;               /* nv: connected component of each vertex */
    int ncomp;
    int n_interior;          /* vertices not on the boundary (all when closed) */
    int *interior;           /* n_interior: their vertex indices, ascending; NULL when closed */
    chol *heat;              /* M + t L, factorised */
    chol *heat_dir;          /* interior block of M + t L; NULL when closed */
    chol *poisson;           /* L + eps M */
};

#endif
