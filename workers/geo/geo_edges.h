/* geo_edges.h — the edge table of a manifold triangle mesh and the
 * vertex -> incident elements lists the per-element-then-gather engine uses.
 *
 * Edges are numbered in order of (min vertex, max vertex). For edge e:
 *   ev[2e], ev[2e+1]  its two vertices, ev[2e] < ev[2e+1]
 *   ef[2e], ef[2e+1]  the faces on each side; ef[2e+1] = -1 on a boundary
 *   eo[2e], eo[2e+1]  the vertex opposite e in ef[2e] / ef[2e+1] (-1 if none)
 * fe[3t+k] is the edge of face t opposite its corner k (between corners k+1, k+2).
 * Building fails (GEO_ENONMANIFOLD) when an edge has more than two faces:
 * callers validate with mesh_check first and report there. Owned by the
 * struct; geo_edges_close frees (zeroed or NULL-filled structs are fine). */
#ifndef GEO_EDGES_H
#define GEO_EDGES_H
#include "mesh/mesh.h"
#include "util/errlist.h"

#define GEO_ERRORS(X)                                                      \
    X(GEO_OK,            0, "ok")                                          \
    X(GEO_ENOMEM,       -1, "out of memory")                               \
    X(GEO_ENONMANIFOLD, -2, "edge with more than two faces")               \
    X(GEO_EDEGENERATE,  -3, "degenerate geometry")                     \
    X(GEO_EMISMATCH,    -4, "edge table built from another mesh")

ERRLIST_ENUM(geo, GEO_ERRORS);
const char *geo_strerror(int code);

typedef struct geo_edges {
    int ne;     /* number of edges */
    int nv, nf; /* of the mesh it was built from */
    int *ev;    /* ne by 2 */
    int *ef;    /* ne by 2 */
    int *eo;    /* ne by 2 */
    int *fe;    /* nf by 3 */
    /* vertex -> incident faces, CSR: faces of vertex i are
     * vf_face[vf_start[i] .. vf_start[i+1]), with the corner index of i in
     * that face in vf_corner[]. Sorted by face: gathers are deterministic. */
    int *vf_start, *vf_face, *vf_corner;
} geo_edges;

int geo_edges_build(const mesh *m, geo_edges *out, char *err, size_t errsz);
void geo_edges_close(geo_edges *e);
/* Number of edges with a single face. */
int geo_edges_boundary_count(const geo_edges *e);

#endif
