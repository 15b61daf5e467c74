/* bmap.c — barycentric maps: allocation, the strict reader of the
 * meshcorr-map 1 text format, the writer, and P·Z. It validates against the
 * meshes it is given; it never reads or changes the meshes themselves. */
#include "map/bmap.h"
#include "util/errbuf.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BMAP_HEADER "# meshcorr-map 1"

bmap *bmap_new(int n, int nt)
{
    if (n < 0 || nt < 0 || n > MESH_MAX_VERTICES || nt > MESH_MAX_VERTICES)
        return NULL;
    bmap *P = calloc(1, sizeof *P);
    if (!P)
        return NULL;
    P->n = n;
    P->nt = nt;
    P->face = calloc((size_t)n + 1, sizeof(int));
    P->w = calloc(3 * (size_t)n + 1, sizeof(double));
    if (!P->face || !P->w) {
        bmap_free(P);
        return NULL;
    }
    return P;
}

void bmap_free(bmap *P)
{
    if (!P)
        return;
    free(P->face);
    free(P->w);
    free(P);
}

/* True when s holds nothing but white space. */
static int blank(const char *s)
{
    s += strspn(s, " \t\r\n");
    return *s == 0;
}

static int parse_int(const char **s, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(*s, &end, 10);
    if (end == *s || errno || (*end && !strchr(" \t\r\n", *end)))
        return -1;
    *out = v;
    *s = end;
    return 0;
}

static int parse_double(const char **s, double *out)
{
    char *end;
    double v = strtod(*s, &end);
    if (end == *s || (*end && !strchr(" \t\r\n", *end)))
        return -1;
    *out = v;
    *s = end;
    return 0;
}

int bmap_check_row(long face, double w[3], int target_nf, const char *where,
                   char *err, size_t errsz)
{
    if (face < 0 || face >= target_nf)
        return errbuf_set(err, errsz, BMAP_ERANGE, "%s: face %ld out of range [0, %d)",
                          where, face, target_nf);
    for (int k = 0; k < 3; k++) {
        if (!isfinite(w[k]))
            return errbuf_set(err, errsz, BMAP_EWEIGHT, "%s: weight %d is not a finite number",
                              where, k);
        if (w[k] < -BMAP_WEIGHT_TOL)
            return errbuf_set(err, errsz, BMAP_EWEIGHT, "%s: weight %d is negative (%g)",
                              where, k, w[k]);
    }
    double sum = w[0] + w[1] + w[2];
    if (!(fabs(sum - 1) <= BMAP_WEIGHT_TOL))
        return errbuf_set(err, errsz, BMAP_EWEIGHT,
                          "%s: weights sum to %.17g, not 1 (tolerance %g)", where, sum,
                          BMAP_WEIGHT_TOL);
    /* clamp small negatives and renormalise only when the sum is off by more
     * than rounding, so a written map reads back bit-exact */
    for (int k = 0; k < 3; k++)
        w[k] = w[k] > 0 ? w[k] : 0;
    sum = w[0] + w[1] + w[2];
    if (fabs(sum - 1) > 4 * DBL_EPSILON)
        for (int k = 0; k < 3; k++)
            w[k] /= sum;
    return 0;
}

int bmap_read(const char *path, const mesh *source, const mesh *target,
              bmap **out, char *err, size_t errsz)
{
    int rc = 0;
    bmap *P = NULL;
    char *buf = NULL;
    size_t cap = 0;
    long line = 0, n = -1, nt = -1, row = 0;
    *out = NULL;
    FILE *fp = fopen(path, "r");
    if (!fp)
        return errbuf_set(err, errsz, BMAP_EIO, "%s: cannot open: %s", path, strerror(errno));

    while (getline(&buf, &cap, fp) >= 0) {
        line++;
        const char *s = buf;
        if (line == 1) {
            size_t hl = strlen(BMAP_HEADER);
            if (strncmp(s, BMAP_HEADER, hl) != 0 || !blank(s + hl)) {
                rc = errbuf_set(err, errsz, BMAP_EPARSE,
                                "%s:1: first line must be \"" BMAP_HEADER "\"", path);
                goto done;
            }
            continue;
        }
        if (n < 0) {                                /* comments, then the counts */
            if (s[0] == '#')
                continue;
            if (parse_int(&s, &n) < 0 || parse_int(&s, &nt) < 0 || !blank(s) || n < 0 || nt < 0) {
                rc = errbuf_set(err, errsz, BMAP_EPARSE,
                                "%s:%ld: expected \"<source vertices> <target vertices>\"", path, line);
                goto done;
            }
            if (n != source->nv || nt != target->nv) {
                rc = errbuf_set(err, errsz, BMAP_ESIZE,
                                "%s:%ld: map is for %ld -> %ld vertices, the meshes have %d -> %d",
                                path, line, n, nt, source->nv, target->nv);
                goto done;
            }
            P = bmap_new((int)n, (int)nt);
            if (!P) {
                rc = errbuf_set(err, errsz, BMAP_ENOMEM, "%s: out of memory for %ld rows", path, n);
                goto done;
            }
            continue;
        }
        if (row == n) {
            if (blank(s))
                continue;
            rc = errbuf_set(err, errsz, BMAP_EPARSE, "%s:%ld: more than the %ld rows announced",
                            path, line, n);
            goto done;
        }
        long f;
        double *w = P->w + 3 * row;
        if (parse_int(&s, &f) < 0 || parse_double(&s, &w[0]) < 0 || parse_double(&s, &w[1]) < 0 ||
            parse_double(&s, &w[2]) < 0 || !blank(s)) {
            rc = errbuf_set(err, errsz, BMAP_EPARSE,
                            "%s:%ld: expected \"<face> <w0> <w1> <w2>\" for source vertex %ld",
                            path, line, row);
            goto done;
        }
        char where[1024];
        snprintf(where, sizeof where, "%s:%ld", path, line);
        if ((rc = bmap_check_row(f, w, target->nf, where, err, errsz)) < 0)
            goto done;
        P->face[row++] = (int)f;
    }
    if (ferror(fp)) {
        rc = errbuf_set(err, errsz, BMAP_EIO, "%s:%ld: read error", path, line);
    } else if (line == 0) {
        rc = errbuf_set(err, errsz, BMAP_EPARSE, "%s:1: empty file, first line must be \""
                        BMAP_HEADER "\"", path);
    } else if (n < 0) {
        rc = errbuf_set(err, errsz, BMAP_EPARSE, "%s:%ld: file ends before the counts line",
                        path, line);
    } else if (row < n) {
        rc = errbuf_set(err, errsz, BMAP_EPARSE,
                        "%s:%ld: file ends after %ld of the %ld rows announced", path, line, row, n);
    }
done:
    free(buf);
    fclose(fp);
    if (rc < 0) {
        bmap_free(P);
        return rc;
    }
    *out = P;
    return 0;
}

int bmap_write(const char *path, const bmap *P, const char *comment,
               char *err, size_t errsz)
{
    FILE *fp = fopen(path, "w");
    if (!fp)
        return errbuf_set(err, errsz, BMAP_EIO, "%s: cannot create: %s", path, strerror(errno));
    fputs(BMAP_HEADER "\n", fp);
    for (const char *c = comment; c && *c;) {
        size_t len = strcspn(c, "\n");
        fprintf(fp, "# %.*s\n", (int)len, c);
        c += len + (c[len] == '\n');
    }
    fprintf(fp, "%d %d\n", P->n, P->nt);
    for (int i = 0; i < P->n; i++)
        fprintf(fp, "%d %.17g %.17g %.17g\n", P->face[i], P->w[3 * i], P->w[3 * i + 1],
                P->w[3 * i + 2]);
    int bad = ferror(fp);
    if (fclose(fp) != 0 || bad)
        return errbuf_set(err, errsz, BMAP_EIO, "%s: write failed: %s", path, strerror(errno));
    return 0;
}

void bmap_apply(const bmap *P, const int *tf, const double *Z, int d, double *out)
{
    for (int i = 0; i < P->n; i++) {
        const int *v = tf + 3 * (size_t)P->face[i];
        const double *w = P->w + 3 * (size_t)i;
        for (int k = 0; k < d; k++)
            out[(size_t)d * i + k] = w[0] * Z[(size_t)d * v[0] + k] +
                                     w[1] * Z[(size_t)d * v[1] + k] +
                                     w[2] * Z[(size_t)d * v[2] + k];
    }
}
