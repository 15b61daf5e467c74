/* lmk.c — landmark files: parsing and validation (see lmk.h). Knows nothing
 * about how landmarks are used. */
#include "lmk/lmk.h"
#include "util/errbuf.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *lmk_strerror(int code)
{
    switch (code) {
#define LMK_STR(name, val, msg) case name: return msg;
        LMK_ERRORS(LMK_STR)
#undef LMK_STR
    }
    return "unknown landmark error";
}

void lmk_free(lmk_set *l)
{
    if (!l)
        return;
    free(l->src);
    free(l->tgt);
    free(l);
}

/* Reads `cols` integers per data line (first `cols` columns; the rest of the
 * line is ignored) into a growing array. Returns rows read or a negative code. */
static int read_columns(const char *path, int cols, int one_based, long **vals, int *rows,
                        char *err, size_t errsz)
{
    FILE *fp = fopen(path, "r");
    if (!fp)
        return errbuf_set(err, errsz, LMK_EIO, "%s: cannot open: %s", path, strerror(errno));
    char line[4096];
    long lineno = 0;
    int n = 0, cap = 0, rc = LMK_OK;
    long *v = NULL;
    while (fgets(line, sizeof line, fp)) {
        lineno++;
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        char *p = line;
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
            p++;
        if (*p == '\0')
            continue;
        if (n == LMK_MAX_PAIRS) {
            rc = errbuf_set(err, errsz, LMK_ECOUNT, "%s:%ld: more than %d landmarks",
                            path, lineno, LMK_MAX_PAIRS);
            goto out;
        }
        if (n == cap) {
            cap = cap ? 2 * cap : 64;
            long *nv = realloc(v, sizeof(long) * (size_t)cap * (size_t)cols);
            if (!nv) {
                rc = errbuf_set(err, errsz, LMK_ENOMEM, "%s: out of memory", path);
                goto out;
            }
            v = nv;
        }
        for (int c = 0; c < cols; c++) {
            char *e;
            errno = 0;
            double d = strtod(p, &e);
            if (e == p || errno == ERANGE || d != (double)(long)d) {
                rc = errbuf_set(err, errsz, LMK_EPARSE,
                                "%s:%ld: column %d is not a vertex index", path, lineno, c + 1);
                goto out;
            }
            long idx = (long)d - (one_based ? 1 : 0);
            v[(size_t)n * cols + c] = idx;
            p = e;
        }
        n++;
    }
out:
    fclose(fp);
    if (rc) {
        free(v);
        return rc;
    }
    *vals = v;
    *rows = n;
    return LMK_OK;
}

static int check_set(lmk_set *l, const char *spath, const char *tpath, int one_based,
                     const mesh *S, const mesh *T, char *err, size_t errsz)
{
    int base = one_based ? 1 : 0;
    if (l->n < LMK_MIN_PAIRS)
        return errbuf_set(err, errsz, LMK_ECOUNT, "%s: %d landmark pairs, at least %d are needed",
                          spath, l->n, LMK_MIN_PAIRS);
    for (int k = 0; k < l->n; k++) {
        if (l->src[k] < 0 || l->src[k] >= S->nv)
            return errbuf_set(err, errsz, LMK_ERANGE,
                              "%s: landmark %d: source vertex %d out of range [%d, %d]",
                              spath, k + 1, l->src[k] + base, base, S->nv - 1 + base);
        if (l->tgt[k] < 0 || l->tgt[k] >= T->nv)
            return errbuf_set(err, errsz, LMK_ERANGE,
                              "%s: landmark %d: target vertex %d out of range [%d, %d]",
                              tpath, k + 1, l->tgt[k] + base, base, T->nv - 1 + base);
        for (int j = 0; j < k; j++)
            if (l->src[j] == l->src[k])
                return errbuf_set(err, errsz, LMK_EDUP,
                                  "%s: landmarks %d and %d both use source vertex %d",
                                  spath, j + 1, k + 1, l->src[k] + base);
    }
    return LMK_OK;
}

static lmk_set *set_new(int n)
{
    lmk_set *l = calloc(1, sizeof *l);
    if (!l)
        return NULL;
    l->n = n;
    l->src = malloc(sizeof(int) * ((size_t)n + 1));
    l->tgt = malloc(sizeof(int) * ((size_t)n + 1));
    if (!l->src || !l->tgt) {
        lmk_free(l);
        return NULL;
    }
    return l;
}

static int clamp_int(long v) { return v < -1 ? -1 : v > 2147483647L ? 2147483647 : (int)v; }

int lmk_read_pairs(const char *path, int one_based, const mesh *S, const mesh *T,
                   lmk_set **out, char *err, size_t errsz)
{
    *out = NULL;
    long *v = NULL;
    int n = 0;
    int rc = read_columns(path, 2, one_based, &v, &n, err, errsz);
    if (rc)
        return rc;
    lmk_set *l = set_new(n);
    if (!l) {
        free(v);
        return errbuf_set(err, errsz, LMK_ENOMEM, "%s: out of memory", path);
    }
    for (int k = 0; k < n; k++) {
        l->src[k] = clamp_int(v[2 * k]);
        l->tgt[k] = clamp_int(v[2 * k + 1]);
    }
    free(v);
    if ((rc = check_set(l, path, path, one_based, S, T, err, errsz))) {
        lmk_free(l);
        return rc;
    }
    *out = l;
    return LMK_OK;
}

int lmk_read_lists(const char *src_path, const char *tgt_path, int one_based,
                   const mesh *S, const mesh *T, lmk_set **out, char *err, size_t errsz)
{
    *out = NULL;
    long *a = NULL, *b = NULL;
    int na = 0, nb = 0;
    int rc = read_columns(src_path, 1, one_based, &a, &na, err, errsz);
    if (rc)
        return rc;
    if ((rc = read_columns(tgt_path, 1, one_based, &b, &nb, err, errsz))) {
        free(a);
        return rc;
    }
    lmk_set *l = NULL;
    if (na != nb) {
        rc = errbuf_set(err, errsz, LMK_ECOUNT, "%s has %d landmarks but %s has %d",
                        src_path, na, tgt_path, nb);
        goto out;
    }
    if (!(l = set_new(na))) {
        rc = errbuf_set(err, errsz, LMK_ENOMEM, "out of memory");
        goto out;
    }
    for (int k = 0; k < na; k++) {
        l->src[k] = clamp_int(a[k]);
        l->tgt[k] = clamp_int(b[k]);
    }
    if ((rc = check_set(l, src_path, tgt_path, one_based, S, T, err, errsz)))
        goto out;
    *out = l;
    l = NULL;
out:
    lmk_free(l);
    free(a);
    free(b);
    return rc;
}
