/* vmap.c — reading vertex-to-vertex map files as barycentric maps, with
 * the index-base rule of vmap.h. */
#include "map/vmap.h"
#include "util/errbuf.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define VMAP_BMAP_HEADER "# meshcorr-map 1"

/* One entry: an integer, or a number equal to one; 0 or -1. */
static int parse_index(const char *s, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (end != s && !errno && !*(end + strspn(end, " \t\r\n"))) {
        *out = v;
        return 0;
    }
    double d = strtod(s, &end);    /* "7.529e+03", "12.0" */
    if (end == s || *(end + strspn(end, " \t\r\n")) || !isfinite(d) || d != floor(d) ||
        fabs(d) > 2e9)
        return -1;
    *out = (long)d;
    return 0;
}

/* The n indices of the file fp (path) into ids, each one's line into
 * lines; whether 0 and nt (the target's vertex count) are among them.
 * 0, or a BMAP_E* code with the file and line in err. */
static int read_ids(FILE *fp, const char *path, int n, int nt, long *ids, long *lines, int *has_zero,
                    int *has_nv, char *err, size_t errsz)
{
    char *buf = NULL;
    size_t cap = 0;
    long line = 0, count = 0;
    int rc = 0;
    while (getline(&buf, &cap, fp) >= 0) {
        line++;
        const char *s = buf + strspn(buf, " \t\r\n");
        if (!*s || *s == '#')
            continue;
        long v;
        if (parse_index(s, &v) < 0) {
            buf[strcspn(buf, "\r\n")] = '\0';
            rc = errbuf_set(err, errsz, BMAP_EPARSE,
                            "%s:%ld: '%.40s' is not a target vertex index (one integer a line)",
                            path, line, s);
            break;
        }
        if (count == n) {
            rc = errbuf_set(err, errsz, BMAP_ESIZE,
                            "%s:%ld: more than %d entries: the source mesh has %d vertices "
                            "(one target vertex per source vertex)", path, line, n, n);
            break;
        }
        *has_zero |= v == 0;
        *has_nv |= v == nt;
        lines[count] = line;
        ids[count++] = v;
    }
    free(buf);
    if (rc)
        return rc;
    if (ferror(fp))
        return errbuf_set(err, errsz, BMAP_EIO, "%s:%ld: read error", path, line);
    if (count < n)
        return errbuf_set(err, errsz, BMAP_ESIZE,
                          "%s:%ld: %ld entries, expected %d (one target vertex per source vertex)",
                          path, line, count, n);
    return 0;
}

/* *base as given, or for VMAP_BASE_AUTO the one the indices show: 0 when
 * 0 is among them, 1 when nt is. 0, or BMAP_EPARSE. */
static int index_base(int *base, int has_zero, int has_nv, const char *path, int nt, char *err,
                      size_t errsz)
{
    if (*base == VMAP_BASE_AUTO) {
        if (has_zero)
            *base = 0;
        else if (has_nv)
            *base = 1;
        else
            return errbuf_set(err, errsz, BMAP_EPARSE,
                              "%s: neither 0 nor %d among the indices: 0- or 1-based cannot be "
                              "told; give the base (--init-base 0 or 1)", path, nt);
    }
    if (*base != 0 && *base != 1)
        return errbuf_set(err, errsz, BMAP_EPARSE, "%s: index base %d is not 0 or 1", path, *base);
    return 0;
}

int vmap_read(const char *path, int base, const mesh *source, const mesh *target, bmap **out,
              int *base_used, char *err, size_t errsz)
{
    *out = NULL;
    int rc = 0, n = source->nv;
    long *ids = malloc(sizeof(long) * ((size_t)n + 1)), *lines = malloc(sizeof(long) * ((size_t)n + 1));
    int *vface = malloc(sizeof(int) * ((size_t)target->nv + 1));
    bmap *P = NULL;
    FILE *fp = NULL;
    if (!ids || !lines || !vface) {
        rc = errbuf_set(err, errsz, BMAP_ENOMEM, "%s: out of memory", path);
        goto done;
    }
    if (!(fp = fopen(path, "r"))) {
        rc = errbuf_set(err, errsz, BMAP_EIO, "%s: cannot open: %s", path, strerror(errno));
        goto done;
    }
    int has_zero = 0, has_nv = 0;
    if ((rc = read_ids(fp, path, n, target->nv, ids, lines, &has_zero, &has_nv, err, errsz)) ||
        (rc = index_base(&base, has_zero, has_nv, path, target->nv, err, errsz)))
        goto done;
    for (int v = 0; v < target->nv; v++)
        vface[v] = -1;
    for (int q = 3 * target->nf - 1; q >= 0; q--)   /* the lowest face listing v, v's corner */
        vface[target->f[q]] = q;
    if (!(P = bmap_new(n, target->nv))) {
        rc = errbuf_set(err, errsz, BMAP_ENOMEM, "%s: out of memory", path);
        goto done;
    }
    for (int i = 0; i < n; i++) {
        long v = ids[i] - base;
        if (v < 0 || v >= target->nv) {
            rc = errbuf_set(err, errsz, BMAP_ERANGE,
                            "%s:%ld: target vertex %ld out of range [%d, %d] (%d-based, the "
                            "target has %d vertices)", path, lines[i], ids[i], base,
                            target->nv - 1 + base, base, target->nv);
            goto done;
        }
        if (vface[v] < 0) {
            rc = errbuf_set(err, errsz, BMAP_ERANGE, "%s:%ld: target vertex %ld lies on no face",
                            path, lines[i], ids[i]);
            goto done;
        }
        P->face[i] = vface[v] / 3;
        for (int c = 0; c < 3; c++)
            P->w[3 * i + c] = c == vface[v] % 3;
    }
    if (base_used)
        *base_used = base;
done:
    if (fp)
        fclose(fp);
    free(ids);
    free(lines);
    free(vface);
    if (rc < 0) {
        bmap_free(P);
        return rc;
    }
    *out = P;
    return 0;
}

int vmap_read_any(const char *path, int base, const mesh *source, const mesh *target,
                  bmap **out, char *err, size_t errsz)
{
    *out = NULL;
    FILE *fp = fopen(path, "r");
    if (!fp)
        return errbuf_set(err, errsz, BMAP_EIO, "%s: cannot open: %s", path, strerror(errno));
    char first[64] = "";
    if (!fgets(first, sizeof first, fp))
        first[0] = '\0';
    fclose(fp);
    if (strncmp(first, VMAP_BMAP_HEADER, strlen(VMAP_BMAP_HEADER)) == 0)
        return bmap_read(path, source, target, out, err, errsz);
    return vmap_read(path, base, source, target, out, NULL, err, errsz);
}
