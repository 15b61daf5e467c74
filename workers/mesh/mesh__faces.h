/* mesh__faces.h — internal to workers/mesh: the faces a text or PLY reader
 * collects, triangles and polygons alike, in the file's order. A polygon
 * (more than 3 corners) keeps its place and is split into triangles once
 * every position is known (mesh__faces_finish), since an OBJ face may name
 * a vertex the file lists after it. */
#ifndef MESH__FACES_H
#define MESH__FACES_H
#include "mesh/mesh.h"

#include <stddef.h>

/* The most corners one face may have: ear clipping takes time growing with
 * the cube of a polygon's corners at worst, and no modelling tool or
 * scanner writes faces near this. */
#define MESH_MAX_FACE_CORNERS 1024

typedef struct mesh__faces {
    int *tri;          /* ntri by 3: the triangles, a polygon's slots zero until finished */
    long ntri, cap;    /* triangles (slots) and room, in triangles */
    int *corner;       /* the polygons' corners, one after the other */
    long ncorner, cap_corner;
    long *poly;        /* per polygon: its first slot, its first corner, its corner count */
    long npoly, cap_poly;
} mesh__faces;

/* Room for about n triangles up front (the file's face count; 0: none). */
void mesh__faces_init(mesh__faces *F, long n);
void mesh__faces_free(mesh__faces *F);
/* Adds a face of k >= 3 corners (checked by the caller, in range).
 * MESH_ENOMEM, or MESH_ELIMIT past MESH_MAX_FACES triangles. */
int mesh__faces_add(mesh__faces *F, const int *c, int k);
/* The message for mesh__faces_add's rc at path's line (0: no line). */
int mesh__faces_error(int rc, const char *path, long line, char *err, size_t errsz);
/* m->f and m->nf from F (F is emptied), each polygon split into triangles
 * by m's positions; m->polygons counts them. MESH_ENOMEM. */
int mesh__faces_finish(mesh__faces *F, mesh *m);

#endif
