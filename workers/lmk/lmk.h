/* lmk.h — landmark pairs (source vertex, target vertex) and their files.
 *
 * Files: either one pairs file ("source_vertex target_vertex" per line) or
 * two lists (one vertex per line, line k of one <-> line k of the other; the
 * BIM .vts layout "id x y z" is accepted: only the first column is read).
 * '#' starts a comment; blank lines are skipped. Indices are 0-based unless
 * one_based is set. Reading validates against the meshes: index in range,
 * no duplicate source landmark, at least PROTO_MIN_LANDMARKS pairs, at most
 * PROTO_MAX_LANDMARKS; errors name the file and line.
 * lmk_from_arrays is that one rule for pairs from anywhere (the file readers
 * and the worker's wire landmarks both go through it).
 * Ownership: lmk_read* and lmk_from_arrays return a set freed with lmk_free (NULL ok). */
#ifndef LMK_H
#define LMK_H
#include <stddef.h>
#include "mesh/mesh.h"

#include "proto_params.h"   /* PROTO_MIN_LANDMARKS, PROTO_MAX_LANDMARKS: the one rule */

#define LMK_ERRORS(X)                                                     \
    X(LMK_OK,        0, "ok", NONE)                                           \
    X(LMK_EIO,      -1, "cannot read the landmark file", IO)                  \
    X(LMK_EPARSE,   -2, "malformed landmark file", LANDMARKS)                 \
    X(LMK_ERANGE,   -3, "landmark index out of range", LANDMARKS)             \
    X(LMK_EDUP,     -4, "duplicate source landmark", LANDMARKS)               \
    X(LMK_ECOUNT,   -5, "wrong number of landmarks", LANDMARKS)               \
    X(LMK_ENOMEM,   -6, "out of memory", NOMEM)

enum lmk_error {
#define LMK_ENUM(name, val, msg, kind) name = val,
    LMK_ERRORS(LMK_ENUM)
#undef LMK_ENUM
};
const char *lmk_strerror(int code);

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
int lmk_read_pairs(const char *path, int one_based, const mesh *S, const mesh *T,
                   lmk_set **out, char *err, size_t errsz);
int lmk_read_lists(const char *src_path, const char *tgt_path, int one_based,
                   const mesh *S, const mesh *T, lmk_set **out, char *err, size_t errsz);

/* A list of vertex ids (ground truth and the like; no landmark rule): the
 * first column of every non-blank, non-'#' line, an integer or a float
 * within 1e-6 of one (some ground-truth files write ids as floats), minus
 * base, each in [0, nv); at most max lines. *ids: malloc()ed, *n entries.
 * LMK_OK, or LMK_EIO / LMK_EPARSE / LMK_ERANGE / LMK_ECOUNT / LMK_ENOMEM with
 * the file and line in err (*ids is then NULL). */
int lmk_read_ids(const char *path, int base, int nv, int max, int **ids, int *n,
                 char *err, size_t errsz);

#endif
