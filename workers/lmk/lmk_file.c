/* lmk_file.c — the one reader of landmark and vertex-id files (lmk_int.h):
 * lines into numbers, the layout from the column count, and the index base
 * rule of lmk.h (a BIM .vts file's positions checked against its mesh). */
#include "lmk/lmk_int.h"
#include "util/errbuf.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LMK_MAX_COLUMNS 4          /* the widest layout: BIM "id x y z" */
#define LMK_ID_SLACK 1e-6          /* an id written as a float: this near an integer */

void lmk__file_close(lmk__file *f)
{
    if (!f)
        return;
    free(f->val);
    free(f->line);
    memset(f, 0, sizeof *f);
}

static int is_id(double d)
{
    return fabs(d) < 1e15 && fabs(d - floor(d + 0.5)) < LMK_ID_SLACK;
}

/* The words of one line (comment cut) into w; their count (may exceed max). */
static int split(char *s, char **w, int max)
{
    int n = 0;
    char *hash = strchr(s, '#');
    if (hash)
        *hash = '\0';
    for (char *tok = strtok(s, " \t\r\n\v\f,"); tok; tok = strtok(NULL, " \t\r\n\v\f,")) {
        if (n < max)
            w[n] = tok;
        n++;
    }
    return n;
}

static const char *layout_looks(lmk__layout l)
{
    switch (l) {
    case LMK__IDS: return "this looks like a list of vertex ids (one a line)";
    case LMK__PAIRS: return "this looks like a file of `source_vertex target_vertex` pairs";
    case LMK__VTS: return "this looks like a BIM .vts file (vertex ids with their positions)";
    case LMK__PID: return "this looks like a BIM .pid file (point ids with barycentric coordinates)";
    }
    return "";
}

int lmk__file_read(const char *path, int max, lmk__file *f, char *err, size_t errsz)
{
    memset(f, 0, sizeof *f);
    FILE *fp = fopen(path, "r");
    if (!fp)
        return errbuf_set(err, errsz, LMK_EIO, "%s: cannot open: %s", path, strerror(errno));
    char buf[LMK_MAX_LINE + 2];
    long lineno = 0, first = 0;
    int cap = 0, rc = LMK_OK, zero_tail = 1;
    while (fgets(buf, sizeof buf, fp)) {
        lineno++;
        size_t len = strlen(buf);
        if (len == LMK_MAX_LINE + 1 && buf[len - 1] != '\n') {
            rc = errbuf_set(err, errsz, LMK_EPARSE, "%s:%ld: line longer than %d bytes", path, lineno,
                            LMK_MAX_LINE);
            goto out;
        }
        char *w[LMK_MAX_COLUMNS];
        int cols = split(buf, w, LMK_MAX_COLUMNS);
        if (cols == 0)
            continue;
        if (!f->cols) {
            if (cols != 1 && cols != 2 && cols != 4) {
                rc = errbuf_set(err, errsz, LMK_ELAYOUT, "%s:%ld: %d columns: not a layout meshcorr "
                                "reads (one vertex id a line; `source_vertex target_vertex` pairs; "
                                "BIM .vts `id x y z`; BIM .pid `id 0 0 0`)", path, lineno, cols);
                goto out;
            }
            f->cols = cols;
            first = lineno;
        } else if (cols != f->cols) {
            rc = errbuf_set(err, errsz, LMK_EPARSE, "%s:%ld: %d column%s, but line %ld has %d", path,
                            lineno, cols, cols == 1 ? "" : "s", first, f->cols);
            goto out;
        }
        if (f->n >= max) {
            rc = errbuf_set(err, errsz, LMK_ECOUNT, "%s:%ld: more than %d lines", path, lineno, max);
            goto out;
        }
        if (f->n == cap) {
            int ncap = cap ? 2 * cap : 64;
            double *v = realloc(f->val, sizeof(double) * (size_t)ncap * (size_t)f->cols);
            if (v)
                f->val = v;
            long *l = v ? realloc(f->line, sizeof(long) * (size_t)ncap) : NULL;
            if (!l) {
                rc = errbuf_set(err, errsz, LMK_ENOMEM, "%s: out of memory", path);
                goto out;
            }
            f->line = l;
            cap = ncap;
        }
        double *row = f->val + (size_t)f->n * (size_t)f->cols;
        for (int c = 0; c < cols; c++) {
            char *e;
            errno = 0;
            double d = strtod(w[c], &e);
            int id_col = c == 0 || cols == 2;
            if (e == w[c] || *e || errno == ERANGE || !isfinite(d) || (id_col && !is_id(d))) {
                rc = errbuf_set(err, errsz, LMK_EPARSE, "%s:%ld: %s in column %d ('%.32s')", path,
                                lineno, id_col ? "not a vertex id" : "not a number", c + 1, w[c]);
                goto out;
            }
            row[c] = id_col ? floor(d + 0.5) : d;
            if (c > 0 && cols == 4 && d != 0)
                zero_tail = 0;
        }
        f->line[f->n++] = lineno;
    }
    if (ferror(fp))
        rc = errbuf_set(err, errsz, LMK_EIO, "%s: read error: %s", path, strerror(errno));
    else if (!f->n)
        rc = errbuf_set(err, errsz, LMK_ECOUNT, "%s: no vertex ids (the file is empty, or "
                        "has only comments and blank lines)", path);
    f->layout = f->cols == 1 ? LMK__IDS : f->cols == 2 ? LMK__PAIRS : zero_tail ? LMK__PID : LMK__VTS;
out:
    fclose(fp);
    if (rc)
        lmk__file_close(f);
    return rc;
}

int lmk__file_refuse(const char *path, const lmk__file *f, const char *wanted, char *err, size_t errsz)
{
    return errbuf_set(err, errsz, LMK_ELAYOUT, "%s:%ld: %d column%s: %s; %s", path,
                      f->n ? f->line[0] : 0L, f->cols, f->cols == 1 ? "" : "s", layout_looks(f->layout),
                      wanted);
}

/* 1 when every line's position is that of vertex (id - base) of m. */
static int positions_fit(const lmk__file *f, const mesh *m, int base, double tol)
{
    for (int k = 0; k < f->n; k++) {
        const double *row = f->val + 4 * (size_t)k;
        double id = row[0] - base;
        if (!(id >= 0 && id < m->nv))
            return 0;
        const double *x = m->v + 3 * (size_t)id;
        for (int d = 0; d < 3; d++)
            if (!(fabs(x[d] - row[1 + d]) <= tol))
                return 0;
    }
    return 1;
}

static double diagonal(const mesh *m)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, s = 0;
    for (int i = 0; i < m->nv; i++)
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], m->v[3 * i + d]);
            hi[d] = fmax(hi[d], m->v[3 * i + d]);
        }
    for (int d = 0; d < 3 && m->nv; d++)
        s += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    return sqrt(s);
}

/* The base of f's ids by the rule of lmk.h. */
static int choose_base(const char *path, const lmk__file *f, int base, const mesh *m, int *out,
                       char *err, size_t errsz)
{
    *out = base == LMK_BASE_DEFAULT ? 0 : base;
    if (f->layout != LMK__VTS || !m || f->n == 0)
        return LMK_OK;
    double tol = LMK_POSITION_TOL * diagonal(m);
    int fit0 = positions_fit(f, m, 0, tol), fit1 = positions_fit(f, m, 1, tol);
    if (base == LMK_BASE_DEFAULT) {
        *out = !fit0 && fit1 ? 1 : 0;
        return LMK_OK;
    }
    if (!(base ? fit1 : fit0) && (base ? fit0 : fit1))
        return errbuf_set(err, errsz, LMK_EBASE, "%s: read %d-based, but the position on each line is "
                          "that of its vertex read %d-based (line %ld: vertex %.0f): the file is "
                          "%d-based", path, base, !base, f->line[0], f->val[0] - !base, !base);
    return LMK_OK;
}

int lmk__file_ids(const char *path, const lmk__file *f, int col, int base, const mesh *m, int nv,
                  const char *what, int numbered, long *ids, int *base_out, char *err, size_t errsz)
{
    int b, rc = choose_base(path, f, base, m, &b, err, errsz);
    if (rc)
        return rc;
    for (int k = 0; k < f->n; k++) {
        double v = f->val[(size_t)k * (size_t)f->cols + (size_t)col];
        if (!(v >= b && v - b < nv)) {
            int looks_one_based = base == LMK_BASE_DEFAULT && b == 0 && v == nv;
            char nth[32] = "";
            if (numbered)
                snprintf(nth, sizeof nth, "landmark %d: ", k + 1);
            return errbuf_set(err, errsz, LMK_ERANGE, "%s:%ld: %s%s %.0f out of range [%d, %d]%s", path,
                              f->line[k], nth, what, v, b, nv - 1 + b,
                              looks_one_based ? ": 0-based ids end below the vertex count, so the "
                                                "file looks 1-based" : "");
        }
        ids[k] = (long)v;
    }
    *base_out = b;
    return LMK_OK;
}
