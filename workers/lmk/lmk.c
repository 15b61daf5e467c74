/* lmk.c — landmark sets: the one validation rule (lmk_from_arrays) and the
 * pairs and lists readers on top of the file reader (lmk_file.c). Knows
 * nothing about how landmarks are used. */
#include "lmk/lmk_int.h"
#include "util/errbuf.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lmk_free(lmk_set *l)
{
    if (!l)
        return;
    free(l->src);
    free(l->tgt);
    free(l);
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

/* What a pairs reader and a list reader say they want, after what a file
 * in another layout looks like. */
#define LMK_WANT_PAIRS "landmark pairs are `source_vertex target_vertex` a line"
#define LMK_WANT_LIST "a list holds one vertex id a line (or BIM .vts `id x y z` / .pid `id 0 0 0` lines)"

int lmk_read_pairs(const char *path, int base, const mesh *S, const mesh *T,
                   lmk_set **out, char *err, size_t errsz)
{
    *out = NULL;
    lmk__file f;
    int rc = lmk__file_read(path, PROTO_MAX_LANDMARKS, &f, err, errsz);
    if (rc)
        return rc;
    long *a = malloc(sizeof(long) * ((size_t)f.n + 1)), *b = malloc(sizeof(long) * ((size_t)f.n + 1));
    int ba = 0, bb = 0;
    if (f.layout != LMK__PAIRS)
        rc = lmk__file_refuse(path, &f, LMK_WANT_PAIRS, err, errsz);
    else if (!a || !b)
        rc = errbuf_set(err, errsz, LMK_ENOMEM, "%s: out of memory", path);
    else if (!(rc = lmk__file_ids(path, &f, 0, base, NULL, S->nv, "source vertex", 1, a, &ba, err, errsz)) &&
             !(rc = lmk__file_ids(path, &f, 1, base, NULL, T->nv, "target vertex", 1, b, &bb, err, errsz)))
        rc = lmk_from_arrays(a, b, f.n, ba, path, path, S, T, out, err, errsz);
    free(a);
    free(b);
    lmk__file_close(&f);
    return rc;
}

/* One list of a landmark pair of files: its ids as written and their base. */
static int read_list(const char *path, int base, const mesh *m, const char *what, lmk__file *f,
                     long **ids, int *b, char *err, size_t errsz)
{
    *ids = NULL;
    int rc = lmk__file_read(path, PROTO_MAX_LANDMARKS, f, err, errsz);
    if (rc)
        return rc;
    if (f->layout == LMK__PAIRS)
        return lmk__file_refuse(path, f, LMK_WANT_LIST, err, errsz);
    if (!(*ids = malloc(sizeof(long) * ((size_t)f->n + 1))))
        return errbuf_set(err, errsz, LMK_ENOMEM, "%s: out of memory", path);
    return lmk__file_ids(path, f, 0, base, m, m->nv, what, 1, *ids, b, err, errsz);
}

int lmk_read_lists(const char *src_path, const char *tgt_path, int base,
                   const mesh *S, const mesh *T, lmk_set **out, char *err, size_t errsz)
{
    *out = NULL;
    lmk__file fa, fb;
    memset(&fb, 0, sizeof fb);
    long *a = NULL, *b = NULL;
    int ba = 0, bb = 0;
    int rc = read_list(src_path, base, S, "source vertex", &fa, &a, &ba, err, errsz);
    if (rc || (rc = read_list(tgt_path, base, T, "target vertex", &fb, &b, &bb, err, errsz)))
        goto out;
    if (fa.n != fb.n) {
        rc = errbuf_set(err, errsz, LMK_ECOUNT, "%s has %d landmarks but %s has %d",
                        src_path, fa.n, tgt_path, fb.n);
        goto out;
    }
    /* files at different bases (a .vts beside a 1-based list): the set is
     * built from 0-based ids; else from the ids as written, for messages */
    for (int k = 0; ba != bb && k < fa.n; k++) {
        a[k] -= ba;
        b[k] -= bb;
    }
    rc = lmk_from_arrays(a, b, fa.n, ba == bb ? ba : 0, src_path, tgt_path, S, T, out, err, errsz);
out:
    free(a);
    free(b);
    lmk__file_close(&fa);
    lmk__file_close(&fb);
    return rc;
}
