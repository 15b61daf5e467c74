/* mesh_lex.h — a whitespace tokenizer over a whole text file in memory, with
 * line numbers for error messages. Shared by the OFF, OBJ and ASCII PLY
 * readers. It does not know any format; '#' comments are the caller's choice. */
#ifndef MESH_LEX_H
#define MESH_LEX_H
#include <stddef.h>

typedef struct mesh_lex {
    const char *buf, *end, *p;
    long line;          /* 1-based line of the last token returned */
    int hash_comments;  /* skip '#' to end of line */
} mesh_lex;

/* Reads a whole file (NUL-terminated) into *buf, refusing files over limit. */
int mesh_lex_slurp(const char *path, long long limit, char **buf, size_t *len,
                   char *err, size_t errsz);
void mesh_lex_init(mesh_lex *lx, const char *buf, size_t len, int hash_comments);
/* Next token: returns its length (0 at end of input), *tok points into buf. */
size_t mesh_lex_next(mesh_lex *lx, const char **tok);
/* Next token on the same line only (0 when the line has no more tokens). */
size_t mesh_lex_next_inline(mesh_lex *lx, const char **tok);
/* Skips the rest of the current line. */
void mesh_lex_skip_line(mesh_lex *lx);
/* Parse helpers: 0 on success. Doubles must be finite-or-not per caller. */
int mesh_lex_double(mesh_lex *lx, double *out);
int mesh_lex_long(mesh_lex *lx, long *out);
/* The same on the current line only (-1 when the line has no more tokens). */
int mesh_lex_double_inline(mesh_lex *lx, double *out);
/* Parses exactly the n characters at t as a base-10 long. */
int mesh_lex_parse_long(const char *t, size_t n, long *out);

#endif
