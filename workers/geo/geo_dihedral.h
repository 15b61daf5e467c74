/* geo_dihedral.h — per edge, the cosine of the angle between the unit
 * normals of its two faces, <n_t, n_t'>: 1 where the surface is flat across
 * the edge, 0 at a right-angle fold, -1 where the two faces fold flat onto
 * each other. (The interior dihedral angle is pi minus that angle.)
 *
 * By convention a boundary edge (one face) gets 1, as if flat, and so does
 * an edge next to a degenerate face (zero normal, geo_normals.h): neither
 * has a bending angle to measure. */
#ifndef GEO_DIHEDRAL_H
#define GEO_DIHEDRAL_H
#include "geo/geo_edges.h"

/* fn: nf by 3 unit face normals (geo_face_normals) of the mesh e was built
 * from. cosines: ne, in [-1, 1]. */
void geo_dihedral_cosines(const geo_edges *e, const double *fn, double *cosines);

#endif
