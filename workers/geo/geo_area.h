/* geo_area.h — triangle areas, the lumped (barycentric) mass, and the
 * unit-area normalisation of a mesh with its inverse.
 *
 * Shapes: a mesh has nv vertices and nf faces (mesh.h). Output arrays are
 * allocated by the caller. Degenerate faces (collinear or repeated corners)
 * simply have area ~0; nothing here fails on them. Only geometry: the edge
 * table, normals and the Laplacian live in their own files. */
#ifndef GEO_AREA_H
#define GEO_AREA_H
#include "mesh/mesh.h"

#include <stddef.h>

/* area: nf. area[t] = |(p1 - p0) x (p2 - p0)| / 2 >= 0. */
void geo_face_areas(const mesh *m, double *area);

/* Sum of the face areas. */
double geo_total_area(const mesh *m);

/* mass: nv. The lumped mass matrix diagonal: mass[i] = 1/3 of the areas of
 * the faces around vertex i (0 for an unreferenced vertex), so that
 * sum(mass) = total area. */
void geo_vertex_areas(const mesh *m, double *mass);

/* The similarity that geo_normalize_area applied: x' = (x - centroid) * scale. */
typedef struct geo_scaling {
    double scale;       /* 1 / sqrt(original total area) */
    double centroid[3]; /* area-weighted centroid of the original surface */
} geo_scaling;

/* Scales m in place to total area 1 about its area-weighted centroid
 * (sum over faces of area * face barycentre / total area), which moves to
 * the origin. Writes what it did into *s. Fails with GEO_EDEGENERATE (m left
 * unchanged) when the total area is zero or not finite. */
int geo_normalize_area(mesh *m, geo_scaling *s, char *err, size_t errsz);

/* The inverse: p (np by 3, e.g. a mesh's v, or points computed on the
 * normalised mesh) in place from normalised to original coordinates,
 * x = x' / scale + centroid. */
void geo_denormalize(const geo_scaling *s, double *p, int np);

#endif
