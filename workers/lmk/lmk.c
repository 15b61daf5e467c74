/* lmk.c — landmark files: parsing and validation (see lmk.h). Knows nothing
 * about how landmarks are used. */
#include "lmk/lmk.h"
#include "util/errbuf.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *lmk_strerror(int code)
{
    switch (code) {
#define LMK_STR(name, val, msg, kind) case name: return msg;
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
 * line is ignored), as written in the file, into a growing array. */
static int read_columns(const char *path, int cols, long **vals, int *rows,
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
        if (n == PROTO_MAX_LANDMARKS) {
            rc = errbuf_set(err, errsz, LMK_ECOUNT, "%s:%ld: more than %d landmarks",
                            path, lineno, PROTO_MAX_LANDMARKS);
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
            if (e == p || errno == ERANGE || !(fabs(d) < 1e15) || d != (double)(long)d) {
                rc = errbuf_set(err, errsz, LMK_EPARSE,
                                "%s:%ld: column %d is not a vertex index", path, lineno, c + 1);
                goto out;
            }
            v[(size_t)n * cols + c] = (long)d;
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

static lmk_set *set_new(long n)
{
    lmk_set *l = calloc(1, sizeof *l);
    if (!l)
        return NULL;
    l->n = (int)n;
    l->src = malloc(sizeof(int) * ((size_t)n + 1));
    l->tgt = malloc(sizeof(int) * ((size_t)n + 1));
    if (!l->src || !l->tgt) {
        lmk_free(l);
        return NULL;
    }
    return l;
}

int lmk_from_arrays(const long *src, const long *tgt, long n, int one_based,
                    const char *src_name, const char *tgt_name, const mesh *S, const mesh *T,
                    lmk_set **out, char *err, size_t errsz)
{
    *out = NULL;
    long base = one_based ? 1 : 0;
    if (n < PROTO_MIN_LANDMARKS)
        return errbuf_set(err, errsz, LMK_ECOUNT, "%s: %ld landmark pairs, at least %d are needed",
                          src_name, n, PROTO_MIN_LANDMARKS);
    if (n > PROTO_MAX_LANDMARKS)
        return errbuf_set(err, errsz, LMK_ECOUNT, "%s: %ld landmark pairs, at most %d are allowed",
                          src_name, n, PROTO_MAX_LANDMARKS);
    for (long k = 0; k < n; k++) {
        if (src[k] < base || src[k] - base >= S->nv)
            return errbuf_set(err, errsz, LMK_ERANGE,
                              "%s: landmark %ld: source vertex %ld out of range [%ld, %ld]",
                              src_name, k + 1, src[k], base, S->nv - 1 + base);
        if (tgt[k] < base || tgt[k] - base >= T->nv)
            return errbuf_set(err, errsz, LMK_ERANGE,
                              "%s: landmark %ld: target vertex %ld out of range [%ld, %ld]",
                              tgt_name, k + 1, tgt[k], base, T->nv - 1 + base);
    }
    lmk_set *l = set_new(n);
    int *first = malloc(sizeof(int) * ((size_t)S->nv + 1)); /* landmark using each vertex */
    if (!l || !first) {
        lmk_free(l);
        free(first);
        return errbuf_set(err, errsz, LMK_ENOMEM, "%s: out of memory", src_name);
    }
    for (int i = 0; i < S->nv; i++)
        first[i] = -1;
    int rc = LMK_OK;
    for (long k = 0; k < n; k++) {
        int s = (int)(src[k] - base);
        if (first[s] >= 0) {
            rc = errbuf_set(err, errsz, LMK_EDUP,
                            "%s: landmarks %d and %ld both use source vertex %ld",
                            src_name, first[s] + 1, k + 1, src[k]);
            break;
        }
        first[s] = (int)k;
        l->src[k] = s;
        l->tgt[k] = (int)(tgt[k] - base);
    }
    free(first);
    if (rc) {
        lmk_free(l);
        return rc;
    }
    *out = l;
    return LMK_OK;
}

int lmk_read_pairs(const char *path, int one_based, const mesh *S, const mesh *T,
                   lmk_set **out, char *err, size_t errsz)
{
    *out = NULL;
    long *v = NULL;
    int n = 0;
    int rc = read_columns(path, 2, &v, &n, err, errsz);
    if (rc)
        return rc;
    long *a = malloc(sizeof(long) * ((size_t)n + 1)), *b = malloc(sizeof(long) * ((size_t)n + 1));
    if (!a || !b) {
        rc = errbuf_set(err, errsz, LMK_ENOMEM, "%s: out of memory", path);
    } else {
        for (int k = 0; k < n; k++) {
            a[k] = v[2 * k];
            b[k] = v[2 * k + 1];
        }
        rc = lmk_from_arrays(a, b, n, one_based, path, path, S, T, out, err, errsz);
    }
    free(a);
    free(b);
    free(v);
    return rc;
}

int lmk_read_lists(const char *src_path, const char *tgt_path, int one_based,
                   const mesh *S, const mesh *T, lmk_set **out, char *err, size_t errsz)
{
    *out = NULL;
    long *a = NULL, *b = NULL;
    int na = 0, nb = 0;
    int rc = read_columns(src_path, 1, &a, &na, err, errsz);
    if (rc)
        return rc;
    if ((rc = read_columns(tgt_path, 1, &b, &nb, err, errsz)))
        goto out;
    if (na != nb) {
        rc = errbuf_set(err, errsz, LMK_ECOUNT, "%s has %d landmarks but %s has %d",
                        src_path, na, tgt_path, nb);
        goto out;
    }
    rc = lmk_from_arrays(a, b, na, one_based, src_path, tgt_path, S, T, out, err, errsz);
out:
    free(a);
    free(b);
    return rc;
}
