/* mesh.h — the triangle mesh type and its file input/output.
 *
 * A mesh is nv vertices (v: nv by 3 doubles, row-major) and nf triangles
 * (f: nf by 3 ints, 0-based, in the file's order). Vertex order is always the
 * user's order: readers keep the file's order and writers write it back.
 * (A .drc file written by someone else keeps Draco's decoded order, which may
 * differ from the order its author had; .drc files we write keep the order:
 * they carry an int attribute with each point's original index, marked by the
 * attribute metadata name = "meshcorr_vertex_index", and the reader puts each
 * point back at that index.)
 *
 * Ownership: mesh_new/mesh_read return a mesh the caller frees with
 * mesh_free (NULL is accepted). Errors are negative MESH_E* codes with the
 * detail (file, field, line, limit) written into the caller's err buffer.
 * This module reads and writes; validation lives in mesh_check.h. */
#ifndef MESH_H
#define MESH_H
#include <stddef.h>
#include "util/errlist.h"

/* Limits on input sizes, checked before any allocation. */
#define MESH_MAX_VERTICES 20000000
#define MESH_MAX_FACES    40000000
#define MESH_MAX_FILE_BYTES (2LL << 30)

#define MESH_ERRORS(X)                                                  \
    X(MESH_OK,       0, "ok", NONE)                                           \
    X(MESH_EIO,     -1, "cannot read or write the file", IO)                  \
    X(MESH_EPARSE,  -2, "malformed file", MESH)                               \
    X(MESH_ELIMIT,  -3, "size over a limit", MESH)                            \
    X(MESH_ENOMEM,  -4, "out of memory", NOMEM)                               \
    X(MESH_EFORMAT, -5, "unknown or unsupported format", MESH)                \
    X(MESH_EDRACO,  -6, "Draco error", MESH)                                  \
    X(MESH_EINVAL,  -7, "invalid mesh data", MESH)

ERRLIST_ENUM(mesh, MESH_ERRORS);

typedef struct mesh {
    int nv;      /* number of vertices */
    int nf;      /* number of triangles */
    double *v;   /* nv by 3 positions */
    int *f;      /* nf by 3 vertex indices, 0-based */
    int polygons; /* faces of the file with more than 3 corners, each split
                     into triangles where it stood (0 when all were triangles) */
} mesh;

/* Allocates a mesh with room for nv vertices and nf faces (contents zero).
 * Returns NULL on a bad size or out of memory. */
mesh *mesh_new(int nv, int nf);
void mesh_free(mesh *m);
mesh *mesh_copy(const mesh *m);

/* Reads by extension (.off .obj .ply .drc, case-insensitive). */
int mesh_read(const char *path, mesh **out, char *err, size_t errsz);
/* Writes by extension (.off .obj .ply .drc). */
int mesh_write(const char *path, const mesh *m, char *err, size_t errsz);

/* Position quantization of the .drc files and blobs we write: 0, lossless
 * (DRACOB_LOSSLESS: every position decodes bit for bit, float64 unless all
 * are floats). A client may ask for 1..30 bits instead (mc_encode_mesh_quantized). */
#define MESH_DRC_QUANTIZATION_BITS 0

/* Per-format entry points; mesh_read/mesh_write pick one by extension.
 * OFF, OBJ and PLY faces may be polygons: each is split into triangles in
 * its place (mesh_faces.c), so the faces of m are numbered after the split.
 * OFF and OBJ: text. OBJ: "f a", "f a/b", "f a/b/c", "f a//c", negative
 * (relative) indices; v/f lines only, everything else skipped. PLY: ascii and
 * binary in either byte order, vertex x y z of any scalar type, face list
 * vertex_indices (or vertex_index), other properties and elements skipped;
 * written as binary_little_endian with double positions (exact round trip).
 * DRC: see draco_bridge.h for the vertex-order rule. */
int mesh_read_off(const char *path, mesh **out, char *err, size_t errsz);
int mesh_write_off(const char *path, const mesh *m, char *err, size_t errsz);
int mesh_read_obj(const char *path, mesh **out, char *err, size_t errsz);
int mesh_write_obj(const char *path, const mesh *m, char *err, size_t errsz);
int mesh_read_ply(const char *path, mesh **out, char *err, size_t errsz);
int mesh_write_ply(const char *path, const mesh *m, char *err, size_t errsz);
/* Binary PLY with per-vertex colours (rgb: nv by 3 bytes; NULL: none). */
int mesh_write_ply_rgb(const char *path, const mesh *m, const unsigned char *rgb,
                       char *err, size_t errsz);
int mesh_read_drc(const char *path, mesh **out, char *err, size_t errsz);
int mesh_write_drc(const char *path, const mesh *m, char *err, size_t errsz);

/* Draco in memory (the worker's blobs): decode with at most max_nv vertices
 * and max_nf faces (MESH_ELIMIT over them); name prefixes messages
 * ("source mesh: ..."). Encode: the .drc writer's bytes, *buf malloc()ed. */
int mesh_read_drc_mem(const void *buf, size_t len, int max_nv, int max_nf, const char *name,
                      mesh **out, char *err, size_t errsz);
int mesh_encode_drc(const mesh *m, unsigned char **buf, size_t *len, char *err, size_t errsz);

#endif
