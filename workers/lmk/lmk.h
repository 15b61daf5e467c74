/* lmk.h — landmark pairs (source vertex, target vertex) and the files of
 * vertex ids they and ground truths come in: one reader, one base rule.
 *
 * Layouts (told apart by the number of columns, the same on every line;
 * '#' starts a comment, blank lines are skipped; ids may be written as
 * floats within 1e-6 of an integer):
 *   pairs     "source_vertex target_vertex"            (lmk_read_pairs)
 *   ids       one vertex id a line (BCICP/FAUST .vts, cartoon ground truth)
 *   BIM .vts  "id x y z": the id and that vertex's position
 *   BIM .pid  "id 0 0 0": point ids with (zero) barycentric coordinates
 * A list (lmk_read_lists, lmk_read_ids*) takes ids, .vts or .pid lines; a
 * file in a layout the reader does not take is refused naming its file,
 * line, column count and what it looks like (LMK_ELAYOUT).
 *
 * Index base, the same rule for every reader: base 0 or 1 as the caller
 * says, or LMK_BASE_DEFAULT: 0-based (the BIM benchmark's .vts and .pid,
 * pairs and most lists; BCICP/FAUST .vts lists are 1-based and need base
 * 1). Where a BIM .vts file is read against its mesh the positions decide:
 * LMK_BASE_DEFAULT takes the base at which every line's position is its
 * vertex's (0 for every BIM file), and a base given that the positions
 * contradict (they are every line's vertex at the other base) is refused
 * (LMK_EBASE); positions that fit neither base (a rescaled mesh) leave the
 * base as given, or 0. Under LMK_BASE_DEFAULT an id equal to the vertex
 * count is refused with the hint that the file looks 1-based.
 *
 * Landmark sets are validated against the meshes: index in range, no
 * duplicate source landmark, at least PROTO_MIN_LANDMARKS pairs, at most
 * PROTO_MAX_LANDMARKS; errors name the file and line. lmk_from_arrays is
 * that one rule for pairs from anywhere (the file readers and the worker's
 * wire landmarks both go through it).
 * Ownership: lmk_read_pairs/lists and lmk_from_arrays return a set freed
 * with lmk_free (NULL ok); lmk_read_ids* return a malloc()ed array. */
#ifndef LMK_H
#define LMK_H
#include <stddef.h>
#include "mesh/mesh.h"
#include "util/errlist.h"

#include "proto_params.h"   /* PROTO_MIN_LANDMARKS, PROTO_MAX_LANDMARKS: the one rule */

#define LMK_BASE_DEFAULT (-1)      /* the base rule above */
#define LMK_MAX_LINE 4096          /* bytes of one line of a landmark or id file */
#define LMK_POSITION_TOL 1e-5      /* a .vts position is its vertex's within this
                                      fraction of the mesh's bounding-box diagonal */

#define LMK_ERRORS(X)                                                     \
    X(LMK_OK,        0, "ok", NONE)                                             \
    X(LMK_EIO,      -1, "cannot read the landmark file", IO)                    \
    X(LMK_EPARSE,   -2, "malformed landmark file", LANDMARKS)                   \
    X(LMK_ERANGE,   -3, "landmark index out of range", LANDMARKS)               \
    X(LMK_EDUP,     -4, "duplicate source landmark", LANDMARKS)                 \
    X(LMK_ECOUNT,   -5, "wrong number of landmarks", LANDMARKS)                 \
    X(LMK_ENOMEM,   -6, "out of memory", NOMEM)                                 \
    X(LMK_ELAYOUT,  -7, "the file is not in a layout this reader takes", LANDMARKS) \
    X(LMK_EBASE,    -8, "the file's positions contradict the index base", LANDMARKS)

ERRLIST_ENUM(lmk, LMK_ERRORS);

typedef struct lmk_set {
    int n;      /* number of pairs */
    int *src;   /* n source vertex indices (0-based) */
    int *tgt;   /* n target vertex indices (0-based) */
} lmk_set;

void lmk_free(lmk_set *l);
/* Builds a set from n pairs as given (1-based when one_based) and validates
 * it: PROTO_MIN_LANDMARKS <= n <= PROTO_MAX_LANDMARKS, each index in range for its mesh,
 * no source vertex used twice. Messages start with src_name or tgt_name and
 * count landmarks from 1: "NAME: landmark 3: source vertex 9999 out of range
 * [0, 6937]". */
int lmk_from_arrays(const long *src, const long *tgt, long n, int one_based,
                    const char *src_name, const char *tgt_name, const mesh *S, const mesh *T,
                    lmk_set **out, char *err, size_t errsz);
/* A pairs file; base 0, 1 or LMK_BASE_DEFAULT. */
int lmk_read_pairs(const char *path, int base, const mesh *S, const mesh *T,
                   lmk_set **out, char *err, size_t errsz);
/* Two lists, line k of one <-> line k of the other; each file's base by
 * the rule (BIM .vts positions checked against S and T). */
int lmk_read_lists(const char *src_path, const char *tgt_path, int base,
                   const mesh *S, const mesh *T, lmk_set **out, char *err, size_t errsz);

/* A list of vertex ids of mesh m (ground truth and the like; no landmark
 * rule, duplicates are fine), BIM .vts positions checked against m: at
 * most max lines; *ids 0-based, malloc()ed, *n entries. LMK_OK, or an
 * LMK_E* code with the file and line in err (*ids is then NULL). */
int lmk_read_ids_on(const char *path, int base, const mesh *m, int max, int **ids, int *n,
                    char *err, size_t errsz);
/* The same with only the vertex count known: .vts positions are not
 * checked (LMK_BASE_DEFAULT is then 0 for every layout). */
int lmk_read_ids(const char *path, int base, int nv, int max, int **ids, int *n,
                 char *err, size_t errsz);

#endif
