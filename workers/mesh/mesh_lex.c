/* mesh_lex.c — see mesh_lex.h. No format knowledge here. */
#include "mesh/mesh_lex.h"
#include "mesh/mesh.h"
#include "util/errbuf.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int mesh_lex_slurp(const char *path, long long limit, char **buf, size_t *len,
                   char *err, size_t errsz)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return errbuf_set(err, errsz, MESH_EIO, "%s: cannot open: %s", path, strerror(errno));
    if (fseek(fp, 0, SEEK_END) != 0) {
        fclose(fp);
        return errbuf_set(err, errsz, MESH_EIO, "%s: cannot seek", path);
    }
    long size = ftell(fp);
    rewind(fp);
    if (size < 0) {
        fclose(fp);
        return errbuf_set(err, errsz, MESH_EIO, "%s: cannot tell size", path);
    }
    if ((long long)size > limit) {
        fclose(fp);
        return errbuf_set(err, errsz, MESH_ELIMIT, "%s: file is %ld bytes, over the limit of %lld",
                          path, size, limit);
    }
    char *b = malloc((size_t)size + 1);
    if (!b) {
        fclose(fp);
        return errbuf_set(err, errsz, MESH_ENOMEM, "%s: out of memory for %ld bytes", path, size);
    }
    size_t got = fread(b, 1, (size_t)size, fp);
    fclose(fp);
    if (got != (size_t)size) {
        free(b);
        return errbuf_set(err, errsz, MESH_EIO, "%s: short read", path);
    }
    b[size] = '\0';
    *buf = b;
    *len = (size_t)size;
    return MESH_OK;
}

void mesh_lex_init(mesh_lex *lx, const char *buf, size_t len, int hash_comments)
{
    lx->buf = lx->p = buf;
    lx->end = buf + len;
    lx->line = 1;
    lx->hash_comments = hash_comments;
}

static int is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

static size_t take(mesh_lex *lx, const char **tok)
{
    const char *s = lx->p;
    while (lx->p < lx->end && !is_space(*lx->p) && *lx->p != '\n' && *lx->p != '\0'
           && !(lx->hash_comments && *lx->p == '#'))
        lx->p++;
    *tok = s;
    return (size_t)(lx->p - s);
}

size_t mesh_lex_next(mesh_lex *lx, const char **tok)
{
    for (;;) {
        while (lx->p < lx->end && is_space(*lx->p))
            lx->p++;
        if (lx->p >= lx->end || *lx->p == '\0')
            return 0;
        if (*lx->p == '\n') {
            lx->line++;
            lx->p++;
            continue;
        }
        if (lx->hash_comments && *lx->p == '#') {
            mesh_lex_skip_line(lx);
            continue;
        }
        return take(lx, tok);
    }
}

size_t mesh_lex_next_inline(mesh_lex *lx, const char **tok)
{
    while (lx->p < lx->end && is_space(*lx->p))
        lx->p++;
    if (lx->p >= lx->end || *lx->p == '\n' || *lx->p == '\0'
        || (lx->hash_comments && *lx->p == '#'))
        return 0;
    return take(lx, tok);
}

void mesh_lex_skip_line(mesh_lex *lx)
{
    while (lx->p < lx->end && *lx->p != '\n')
        lx->p++;
}

static int mesh_lex_parse_double(const char *t, size_t n, double *out)
{
    if (n == 0 || n > 63)
        return -1;
    char tmp[64];
    memcpy(tmp, t, n);
    tmp[n] = '\0';
    char *e;
    errno = 0;
    double d = strtod(tmp, &e);
    if (*e != '\0')
        return -1;
    *out = d;
    return 0;
}

int mesh_lex_parse_long(const char *t, size_t n, long *out)
{
    if (n == 0 || n > 31)
        return -1;
    char tmp[32];
    memcpy(tmp, t, n);
    tmp[n] = '\0';
    char *e;
    errno = 0;
    long v = strtol(tmp, &e, 10);
    if (*e != '\0' || errno == ERANGE)
        return -1;
    *out = v;
    return 0;
}

int mesh_lex_double(mesh_lex *lx, double *out)
{
    const char *t;
    size_t n = mesh_lex_next(lx, &t);
    return mesh_lex_parse_double(t, n, out);
}

int mesh_lex_double_inline(mesh_lex *lx, double *out)
{
    const char *t;
    size_t n = mesh_lex_next_inline(lx, &t);
    return mesh_lex_parse_double(t, n, out);
}

int mesh_lex_long(mesh_lex *lx, long *out)
{
    const char *t;
    size_t n = mesh_lex_next(lx, &t);
    return mesh_lex_parse_long(t, n, out);
}
