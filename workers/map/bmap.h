/* bmap.h — barycentric maps: per source vertex, a point on the target mesh
 * given as a target face index and 3 barycentric weights (in the order the
 * face lists its vertices; non-negative, summing to 1). This is the map P of
 * ECTM (n by ñ sparse, 3 entries per row) and what the service returns.
 *
 * Text format (meshcorr-map 1, see ../shared/data/ectm_demo_381_390/README.md):
 *   # meshcorr-map 1
 *   # optional comment lines
 *   <n source vertices> <n target vertices>
 *   <face> <w0> <w1> <w2>        one line per source vertex
 *
 * Ownership: bmap_new/bmap_read return a map freed by bmap_free (NULL ok).
 * Errors: negative BMAP_E* codes, detail (file, line, field) in err. */
#ifndef BMAP_H
#define BMAP_H
#include <stddef.h>
#include "mesh/mesh.h"
#include "util/errlist.h"

#define BMAP_WEIGHT_TOL 1e-4   /* |sum - 1| and -w allowed when reading */

#define BMAP_ERRORS(X)                                                      \
    X(BMAP_OK,        0, "ok", NONE)                                          \
    X(BMAP_EIO,      -1, "cannot read or write the map file", IO)             \
    X(BMAP_EPARSE,   -2, "malformed map file", MAP)                           \
    X(BMAP_ESIZE,    -3, "map sized for other meshes", MAP)                   \
    X(BMAP_ERANGE,   -4, "face index out of range", MAP)                      \
    X(BMAP_EWEIGHT,  -5, "weights negative or not summing to 1", MAP)         \
    X(BMAP_ENOMEM,   -6, "out of memory", NOMEM)

ERRLIST_ENUM(bmap, BMAP_ERRORS);

typedef struct bmap {
    int n;       /* rows: source vertices */
    int nt;      /* target vertices */
    int *face;   /* n target face indices */
    double *w;   /* n by 3 weights */
} bmap;

bmap *bmap_new(int n, int nt);
void bmap_free(bmap *P);

/* Reads and validates against the two meshes: header counts equal
 * source->nv and target->nv, faces in [0, target->nf), weights >= -tol and
 * summing to 1 within BMAP_WEIGHT_TOL (then clamped and renormalised). */
int bmap_read(const char *path, const mesh *source, const mesh *target,
              bmap **out, char *err, size_t errsz);
/* The rule for one row, from a file or from the wire: face in
 * [0, target_nf), weights finite, >= -BMAP_WEIGHT_TOL and summing to 1
 * within BMAP_WEIGHT_TOL; then clamps negatives to 0 and renormalises (a
 * sum already 1 within rounding is left bit-exact). where prefixes the
 * message ("P.map:12", "initial map p: row 5"). */
int bmap_check_row(long face, double w[3], int target_nf, const char *where,
                   char *err, size_t errsz);
/* Writes the text format; comment (may be NULL, may hold several lines
 * separated by '\n') goes into '#' lines after the header line. */
int bmap_write(const char *path, const bmap *P, const char *comment,
               char *err, size_t errsz);

/* out (P->n by d) = P · Z where Z is nt by d values at the target vertices
 * and tf the target's faces (nf by 3). */
void bmap_apply(const bmap *P, const int *tf, const double *Z, int d, double *out);

#endif
