/* draco_bridge.h — the only door to Draco (C++): decode a .drc buffer into
 * plain arrays, encode plain arrays into a .drc buffer, and nothing else.
 *
 * Every exception Draco may throw (1.5.5 throws std::bad_alloc on some tiny
 * malformed inputs) is caught in draco_bridge.cpp and turned into an error
 * code with a message in the caller's err buffer.
 *
 * Vertex order: dracob_encode uses Draco's sequential connectivity method and
 * adds an int32 GENERIC attribute, marked by the attribute metadata entry
 * name = "meshcorr_vertex_index", holding each point's original index.
 * dracob_decode puts every point back at that index (it must be a
 * permutation of 0..n-1, or the buffer is refused). A buffer without the
 * attribute (written by another tool) keeps Draco's decoded order.
 *
 * Ownership: on success *v, *f (decode) and *buf (encode) are malloc()ed and
 * the caller free()s them; on failure they are set to NULL. */
#ifndef DRACO_BRIDGE_H
#define DRACO_BRIDGE_H
#include <stddef.h>
#include "util/errlist.h"

#ifdef __cplusplus
extern "C" {
#endif

#define DRACOB_ERRORS(X)                                                  \
    X(DRACOB_OK,       0, "ok")                                           \
    X(DRACOB_EARG,    -1, "invalid argument")                             \
    X(DRACOB_ELIMIT,  -2, "size over a limit")                            \
    X(DRACOB_EDECODE, -3, "malformed Draco buffer")                       \
    X(DRACOB_EKIND,   -4, "not a triangle mesh")                          \
    X(DRACOB_EENCODE, -5, "Draco encoding failed")                        \
    X(DRACOB_ENOMEM,  -6, "out of memory")

ERRLIST_ENUM(dracob, DRACOB_ERRORS);

/* Largest buffer dracob_decode accepts, checked before Draco sees it. */
#define DRACOB_MAX_BUFFER_BYTES (1LL << 30)
/* Metadata entry that marks our original-vertex-index attribute. */
#define DRACOB_INDEX_METADATA_NAME "name"
#define DRACOB_INDEX_METADATA_VALUE "meshcorr_vertex_index"

/* Decodes a triangle mesh: *v is nv by 3 doubles, *f is nf by 3 0-based
 * indices, all checked in range. Point clouds are refused (DRACOB_EKIND);
 * more than max_points points or max_faces faces gives DRACOB_ELIMIT. */
int dracob_decode(const unsigned char *buf, size_t len, int max_points, int max_faces,
                  double **v, int *nv, int **f, int *nf, char *err, size_t errsz);

/* quantization_bits of dracob_encode that keeps every position exactly. */
#define DRACOB_LOSSLESS 0

/* Encodes nv by 3 positions and nf by 3 faces. Positions: DRACOB_LOSSLESS
 * stores them unquantized and decodes them bit for bit (NaN, -0 and
 * denormals included): as float32 when every coordinate is a float
 * exactly, else as float64; 1..30 quantizes each coordinate to that many
 * bits over the bounding box (16 is Draco's usual: an error up to about bbox /
 * 2^17, and about half the size of lossless).
 * Indices must be in range. */
int dracob_encode(const double *v, int nv, const int *f, int nf, int quantization_bits,
                  unsigned char **buf, size_t *len, char *err, size_t errsz);

#ifdef __cplusplus
}
#endif
#endif
