/* lmk_int.h — inside workers/lmk: the one file reader (lmk_file.c) the
 * pairs, lists and id readers share. Not for use outside the module. */
#ifndef LMK_INT_H
#define LMK_INT_H
#include "lmk/lmk.h"

typedef enum lmk__layout {
    LMK__IDS = 1,      /* one vertex id a line */
    LMK__PAIRS,        /* "source_vertex target_vertex" */
    LMK__VTS,          /* BIM .vts "id x y z" */
    LMK__PID           /* BIM .pid "id 0 0 0" */
} lmk__layout;

typedef struct lmk__file {
    lmk__layout layout;
    int n, cols;       /* data lines, numbers on each */
    double *val;       /* n by cols numbers as written */
    long *line;        /* the file's line number of each data line */
} lmk__file;

/* Reads every data line of path (at most max) and tells its layout;
 * LMK_EIO, LMK_EPARSE (a word that is no number, a column count that
 * changes, a line over LMK_MAX_LINE), LMK_ELAYOUT (a column count no layout
 * has), LMK_ECOUNT, LMK_ENOMEM, each naming path and line. */
int lmk__file_read(const char *path, int max, lmk__file *f, char *err, size_t errsz);
void lmk__file_close(lmk__file *f);
/* LMK_ELAYOUT: "PATH:LINE: N columns: this looks like ...; " + wanted. */
int lmk__file_refuse(const char *path, const lmk__file *f, const char *wanted, char *err, size_t errsz);
/* Column col of every line as written into ids (f->n entries), each in
 * range for nv vertices at the base the rule gives (returned in *base_out;
 * m, when not NULL, holds the positions a .vts file is checked against);
 * what names the id in messages ("vertex", "source vertex"), after
 * "landmark K: " when numbered. */
int lmk__file_ids(const char *path, const lmk__file *f, int col, int base, const mesh *m, int nv,
                  const char *what, int numbered, long *ids, int *base_out, char *err, size_t errsz);

#endif
