/* mesh_check.h — validation of a mesh as read from a file: counts, topology
 * and every problem that would make the optimizer fail or lie. Works on
 * broken meshes (non-manifold, bad indices, NaN): it builds its own
 * half-edge sort and never uses geo_edges, which refuses non-manifold input.
 *
 * Definitions: an edge is an unordered vertex pair used by a face; a
 * boundary edge has one face, a non-manifold edge more than two. A vertex is
 * non-manifold when its faces form more than one fan (faces joined through
 * the edges at that vertex). A face is degenerate when it repeats a vertex or
 * its area is below 1e-12 times its longest edge squared (zero up to
 * rounding). Duplicate faces use the same vertex set. Orientation is
 * inconsistent on an edge whose two faces traverse it the same way.
 * Components are sets of faces connected through shared vertices; boundary loops are connected sets
 * of boundary edges. chi = V - E + F with V the referenced vertices; genus
 * = (2 - chi - boundary loops) / 2 when the mesh is manifold and in one
 * piece, else -1. Faces with bad indices are left out of everything else;
 * faces repeating a vertex are left out of the edge table.
 *
 * The optimizer needs a mesh with none of the problems listed (see
 * mesh_check_usable): zero-area faces make the reference metric of the
 * elastic energy singular, unreferenced vertices make the mass matrix
 * singular, so both are refused too. */
#ifndef MESH_CHECK_H
#define MESH_CHECK_H
#include "mesh/mesh.h"
#include <stddef.h>
#include "util/errlist.h"

#define MESH_CHECK_ERRORS(X)                                         \
    X(MESH_CHECK_OK,      0, "ok")                                   \
    X(MESH_CHECK_ENOMEM, -1, "out of memory")

ERRLIST_ENUM(mesh_check, MESH_CHECK_ERRORS);

typedef struct mesh_check_report {
    /* counts */
    int nv, nf, ne;
    int components;        /* faces connected through shared vertices */
    int boundary_loops;
    long euler;            /* chi = V - E + F */
    int genus;             /* -1 when not defined (see above) */
    double area;           /* total area of the valid faces */
    double bbox_min[3], bbox_max[3];  /* over finite vertices; 0 if none */
    /* problems: a count and the first instance (-1 when count is 0) */
    int bad_index_faces, first_bad_index_face;
    int nonfinite_vertices, first_nonfinite_vertex;
    int nonmanifold_edges, first_nonmanifold_edge[2];      /* its vertices */
    int nonmanifold_vertices, first_nonmanifold_vertex;
    int degenerate_faces, first_degenerate_face;
    int duplicate_faces, first_duplicate_pair[2];          /* two faces */
    int unreferenced_vertices, first_unreferenced_vertex;
    int inconsistent_edges, first_inconsistent_edge[2];    /* its vertices */
} mesh_check_report;

/* Fills *r. Returns MESH_CHECK_OK or MESH_CHECK_ENOMEM (detail in err). */
int mesh_check_run(const mesh *m, mesh_check_report *r, char *err, size_t errsz);
/* 1 when the optimizer can use the mesh: faces present and no problem at all
 * (including more than one component). */
int mesh_check_usable(const mesh_check_report *r);
/* Writes one line per problem, each starting with "path: ", into out
 * (truncated to outsz); returns the number of problem lines. */
int mesh_check_problems(const mesh_check_report *r, const char *path, char *out, size_t outsz);
/* The area of the face f (three indices into the positions v, three doubles
 * a vertex); when degenerate is not NULL, whether the face is degenerate by
 * the rule above. */
double mesh_face_area(const double *v, const int *f, int *degenerate);

#endif
