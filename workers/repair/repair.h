/* repair.h — input mesh repair: a mesh as a user has it (non-manifold
 * vertices and edges, unwelded seams, degenerate or duplicate faces,
 * unreferenced vertices, stray pieces, faces turned the wrong way) made
 * into one the optimizer can use, with the index maps that carry the
 * engine's results back to the user's own vertex and face indexing.
 *
 * The steps, in this order (one file each):
 *   repair_weld.c     vertices at the same position (exactly) become one
 *   repair_faces.c    faces that repeat a vertex or have zero area
 *                     (mesh_check.h's rule), then faces with the vertex set
 *                     of an earlier face, are removed
 *   repair_orient.c   faces turned against their neighbours are flipped
 *                     (piece by piece, the larger-area side kept); an edge
 *                     that cannot be made consistent is cut
 *   repair_split.c    edges with more than two faces are cut, then every
 *                     vertex gets one copy per fan of faces around it; a
 *                     weld that made a pinch is undone here, so welds stay
 *                     only where they keep the mesh manifold
 *   repair_components.c  the largest piece (by area) is kept, or the pieces
 *                     the caller names; vertices of the others and
 *                     unreferenced ones are carried by the nearest kept
 *                     vertex
 *   repair_pairs.c    which kept piece goes with which, by the landmarks
 *                     (the engine then matches each pair on its own)
 *   repair_index.c    results back into the user's indexing, landmarks and
 *                     uploaded maps into the engine's
 * Holes stay boundaries (the engine handles open meshes).
 *
 * What cannot be repaired (a face index out of range, a NaN or infinite
 * coordinate, no face left) is REPAIR_EMESH with the reason.
 *
 * Ownership: repair_mesh_run fills a repair_mesh the caller closes with
 * repair_mesh_close (a zeroed one is accepted). */
#ifndef REPAIR_H
#define REPAIR_H
#include <stddef.h>
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "util/errlist.h"

#define REPAIR_ERRORS(X)                                                 \
    X(REPAIR_OK,      0, "ok", NONE)                                     \
    X(REPAIR_EMESH,  -1, "the mesh cannot be repaired", MESH)            \
    X(REPAIR_ENOMEM, -2, "out of memory", NOMEM)                         \
    X(REPAIR_EMAP,   -3, "a given map lands where the repair removed faces", MAP)

ERRLIST_ENUM(repair, REPAIR_ERRORS);

/* The counts of one mesh's repair: X(member, text for a person). The one
 * list: the struct, the result's record (metric keys "repair.source.NAME",
 * "repair.target.NAME"), the CLI's lines and the Python record come from it. */
#define REPAIR_COUNTS(X)                                                          \
    X(welded, "vertices welded to another at the same position")                  \
    X(split_vertices, "vertex copies made where faces formed more than one fan")  \
    X(split_edges, "non-manifold edges cut (more than two faces)")                \
    X(flipped_faces, "faces flipped to agree with their neighbours")              \
    X(degenerate_faces, "degenerate (zero-area) faces removed")                   \
    X(duplicate_faces, "duplicate faces removed")                                 \
    X(unreferenced, "vertices in no face (as given or once theirs were removed), carried by the nearest point")                              \
    X(pieces, "pieces left out of the match")       \
    X(piece_vertices, "vertices on those pieces, carried by the nearest point")

typedef struct repair_counts {
#define REPAIR_MEMBER(name, text) int name;
    REPAIR_COUNTS(REPAIR_MEMBER)
#undef REPAIR_MEMBER
} repair_counts;

/* 1 when c records any repair. */
int repair_counts_any(const repair_counts *c);
/* One line per non-zero count, "PREFIX: N TEXT\n", into out (truncated to
 * outsz); the number of lines. */
int repair_counts_text(const repair_counts *c, const char *prefix, char *out, size_t outsz);

typedef struct repair_mesh {
    mesh *m;          /* the mesh the engine uses (owned)                      */
    int nv_user;      /* the user's vertex and face counts                     */
    int nf_user;
    int *vert;        /* m->nv: the user vertex each vertex stands for: the
                         first user vertex whose row it is (a welded group's
                         first; a copy the split made, the vertex whose
                         faces it carries)                                     */
    int *face;        /* m->nf: the user face each face is                     */
    unsigned char *corner; /* m->nf by 3: the corner of the user face each
                              corner stands for (faces may be flipped)        */
    int *rep;         /* nv_user: the first user vertex of u's welded group    */
    int *row;         /* nv_user: the vertex of m that gives user vertex u its
                         row: a copy of u, or for a dropped u the nearest kept
                         vertex                                                */
    unsigned char *carried; /* nv_user: 1 when u was dropped (row is another
                               point's)                                        */
    int npieces;      /* the pieces of the repaired surface, kept or not   */
    int *piece;       /* m->nv: the piece of each vertex                       */
    repair_counts n;
} repair_mesh;

/* Repairs u into out (every step above; a mesh that needs nothing comes
 * out with the same vertices and faces in the same order and all counts
 * 0). The pieces kept: with keep NULL the largest; else piece p (of
 * out->npieces, numbered by decreasing area, as a first run with
 * REPAIR_ALL_PIECES tells them) when keep[p] is non-zero, or every piece
 * when keep is REPAIR_ALL_PIECES. name prefixes messages. REPAIR_OK,
 * REPAIR_EMESH or REPAIR_ENOMEM. */
extern const unsigned char REPAIR_ALL_PIECES[];
int repair_mesh_run(const mesh *u, const char *name, const unsigned char *keep, repair_mesh *out,
                    char *err, size_t errsz);
void repair_mesh_close(repair_mesh *r);
/* What no repair fixes, the first check of repair_mesh_run: a face index
 * out of range, a NaN or infinite coordinate. REPAIR_OK or REPAIR_EMESH. */
int repair_mesh_check(const mesh *u, const char *name, char *err, size_t errsz);

/* --- the steps (used by repair_mesh_run; declared for the tests) --- */

/* repair_weld.c: rep[i] = the smallest vertex index at exactly v[i]'s
 * position; returns how many vertices got another's index, or -1 without
 * memory. */
int repair_weld(const mesh *u, int *rep);

/* repair_faces.c: keeps the faces f (nf by 3, in place, order kept) that
 * neither repeat a vertex nor have zero area (positions v) and whose vertex
 * set no earlier face has; id[] (the user face of each) follows. Returns
 * the new face count; *degenerate, *duplicate: the removed ones; -1
 * without memory. */
int repair_faces(const double *v, int nv, int *f, int *id, int nf, int *degenerate,
                 int *duplicate);

/* repair_orient.c: flips faces (two corners swapped, in f) so that every
 * edge with two faces is run once each way, each piece keeping the
 * orientation of the larger part of its area. *conflicts: edges left run
 * the same way (a one-sided piece); repair_split cuts them. Returns the
 * faces flipped, -1 without memory. */
int repair_orient(const double *v, int nv, int *f, int nf, int *conflicts);

/* repair_split.c: faces f over nv vertices with edges of more than two
 * faces or two faces the same way cut, each vertex split into one copy
 * per fan: *out_f (nf by 3, new vertex ids) and *out_vert (the old vertex
 * of each new one), *out_nv new vertices. *split_edges: edges cut,
 * *split_vertices: copies beyond the first. -1 without memory. */
int repair_split(int nv, const int *f, int nf, int **out_f, int **out_vert, int *out_nv,
                 int *split_edges, int *split_vertices);

/* repair_components.c: the faces' pieces (connected through shared
 * vertices), numbered by decreasing area: piece[t] of each face, 0 the
 * largest. Returns the number of pieces, -1 without memory. */
int repair_components(const double *v, int nv, const int *f, int nf, int *piece);

/* repair_pairs.c: the pieces landmarks pair. Landmark k joins piece
 * ps[k] of the first mesh (ns pieces) and piece pt[k] of the second (nt);
 * -1 leaves it out. Piece s gets pair[s] = t when all its landmarks land
 * on piece t, at least min of them, and no other piece's all do; else -1.
 * Returns the number of pairs, -1 without memory. */
int repair_pieces_pair(const int *ps, const int *pt, int n, int ns, int nt, int min, int *pair);

/* repair_components.c: for each of the nq query points q (nq by 3), the
 * index of the nearest of the np points p (np >= 1), Euclidean. -1 without
 * memory. */
int repair_nearest(const double *p, int np, const double *q, int nq, int *out);

/* --- index maps (repair_index.c) --- */

/* The engine's map P from the repaired S onto the repaired T as the user's:
 * one row per user vertex of S (its row vertex's row), faces and weights
 * on T's user faces (corners matched through the welds). NULL without
 * memory. */
bmap *repair_map_to_user(const repair_mesh *S, const repair_mesh *T, const bmap *P);
/* points (S->m->nv by 3) as one row per user vertex (its row vertex's);
 * malloc()ed, NULL without memory. */
double *repair_points_to_user(const repair_mesh *S, const double *points);
/* A user's map P (rows: S's user vertices, faces: T's user faces) in the
 * engine's indexing: row r is user vertex vert[r]'s. REPAIR_EMAP naming
 * name, the row and the face when a row lands on a face the repair
 * removed; REPAIR_ENOMEM. */
int repair_map_from_user(const repair_mesh *S, const repair_mesh *T, const bmap *P,
                         const char *name, bmap **out, char *err, size_t errsz);
/* Landmark pairs in the user's indexing (n pairs) in the engine's: pairs
 * whose vertex was dropped (carried) or that repeat a source vertex after
 * the welds are left out. Writes the kept pairs to src_out, tgt_out (room
 * for n) and returns how many. */
int repair_landmarks(const repair_mesh *S, const repair_mesh *T, const int *src, const int *tgt,
                     int n, int *src_out, int *tgt_out);

#endif
