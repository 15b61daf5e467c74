/* geod_voronoi.h — geodesic Voronoi cells of a landmark set: for every
 * vertex the landmark nearest to it by heat-method distance (geod.h), with
 * the per-landmark distance fields kept, since the RHM initialisation needs
 * them as well as the cells.
 *
 * Each landmark's field is computed from that landmark alone
 * (geod_all_pairs_from), not from a multi-source solve. Ties go to the
 * lower landmark index; a landmark's own vertex always lies in its own cell.
 * Ownership: geod_voronoi_new returns an object owning all its arrays,
 * freed with geod_voronoi_free (NULL accepted). */
#ifndef GEOD_VORONOI_H
#define GEOD_VORONOI_H
#include "geod/geod.h"

#define GEOD_VORONOI_MAX_LANDMARKS 100000

typedef struct geod_voronoi {
    int nl;          /* landmarks */
    int nv;          /* vertices */
    int *landmarks;  /* nl: vertex of each landmark (a copy) */
    int *cell;       /* nv: index 0..nl-1 of the nearest landmark */
    double *nearest; /* nv: distance to that landmark */
    double *dist;    /* nl by nv: row a = distances from landmarks[a] */
} geod_voronoi;

/* Errors: GEOD_EINVAL (nl < 1 or over GEOD_VORONOI_MAX_LANDMARKS, a vertex
 * out of range, the same vertex twice), GEOD_ENOMEM, GEOD_EFACTOR. */
int geod_voronoi_new(geod_solver *s, const int *landmarks, int nl,
                     geod_voronoi **out, char *err, size_t errsz);
void geod_voronoi_free(geod_voronoi *v);

#endif
