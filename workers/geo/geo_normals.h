/* geo_normals.h — unit face normals and area-weighted unit vertex normals.
 *
 * Orientation follows the corner order (right-hand rule: (p1-p0) x (p2-p0)),
 * so a consistently oriented closed mesh with counter-clockwise faces seen
 * from outside gets outward normals. Degenerate faces (geo_tri.h rule:
 * collinear or repeated corners) get the zero vector; a vertex whose
 * weighted sum is zero (unreferenced, or only degenerate faces) too.
 * Output arrays are allocated by the caller. */
#ifndef GEO_NORMALS_H
#define GEO_NORMALS_H
#include "mesh/mesh.h"

/* n: nf by 3, unit length or zero. */
void geo_face_normals(const mesh *m, double *n);

/* n: nv by 3. Normalised sum of the incident faces' unit normals weighted by
 * their areas (equivalently, of their cross products). */
void geo_vertex_normals(const mesh *m, double *n);

#endif
