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

int vmap_read(const char *path, int base, const mesh *source, const mesh *target, bmap **out,
              int *base_used, char *err, size_t errsz)
{
    *out = NULL;
    int rc = 0, n = source->nv;
    long *ids = malloc(sizeof(long) * ((size_t)n + 1)), *lines = malloc(sizeof(long) * ((size_t)n + 1));
    int *vface = malloc(sizeof(int) * ((size_t)target->nv + 1));
    char *buf = NULL;
    size_t cap = 0;
    long line = 0, count = 0;
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
            goto done;
        }
        if (count == n) {
            rc = errbuf_set(err, errsz, BMAP_ESIZE,
                            "%s:%ld: more than %d entries: the source mesh has %d vertices "
                            "(one target vertex per source vertex)", path, line, n, n);
            goto done;
        }
        has_zero |= v == 0;
        has_nv |= v == target->nv;
        lines[count] = line;
        ids[count++] = v;
    }
    if (ferror(fp)) {
        rc = errbuf_set(err, errsz, BMAP_EIO, "%s:%ld: read error", path, line);
        goto done;
    }
    if (count < n) {
        rc = errbuf_set(err, errsz, BMAP_ESIZE,
                        "%s:%ld: %ld entries, expected %d (one target vertex per source vertex)",
                        path, line, count, n);
        goto done;
    }
    if (base == VMAP_BASE_AUTO) {
        if (has_zero)
            base = 0;
        else if (has_nv)
            base = 1;
        else {
            rc = errbuf_set(err, errsz, BMAP_EPARSE,
                            "%s: neither 0 nor %d among the indices: 0- or 1-based cannot be "
                            "told; give the base (--init-base 0 or 1)", path, target->nv);
            goto done;
        }
    }
    if (base != 0 && base != 1) {
        rc = errbuf_set(err, errsz, BMAP_EPARSE, "%s: index base %d is not 0 or 1", path, base);
        goto done;
    }
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
    free(buf);
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
