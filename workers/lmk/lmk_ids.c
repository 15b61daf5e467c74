/* lmk_ids.c — a file of vertex ids, one per line (ground-truth lists and
 * the like; see lmk.h). Knows no landmark rule: duplicates are fine. */
#include "lmk/lmk.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

int lmk_read_ids(const char *path, int base, int nv, int max, int **ids, int *n,
                 char *err, size_t errsz)
{
    *ids = NULL;
    *n = 0;
    FILE *fp = fopen(path, "r");
    if (!fp)
        return errbuf_set(err, errsz, LMK_EIO, "%s: cannot open", path);
    int cap = 1024, len = 0, line = 0, rc = LMK_ENOMEM;
    int *v = malloc(sizeof(int) * (size_t)cap);
    char buf[4096];
    while (v && fgets(buf, sizeof buf, fp)) {
        line++;
        char *p = buf, *e;
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\0' || *p == '\n' || *p == '\r' || *p == '#')
            continue;
        double x = strtod(p, &e);
        if (e == p || !(fabs(x - floor(x + 0.5)) < 1e-6)) {
            rc = errbuf_set(err, errsz, LMK_EPARSE, "%s:%d: not a vertex id", path, line);
            goto out;
        }
        double k = floor(x + 0.5) - base;
        if (!(k >= 0 && k < nv)) {
            rc = errbuf_set(err, errsz, LMK_ERANGE, "%s:%d: vertex %.0f out of range [%d, %d]", path,
                            line, k + base, base, nv - 1 + base);
            goto out;
        }
        if (len >= max) {
            rc = errbuf_set(err, errsz, LMK_ECOUNT, "%s: more than %d lines", path, max);
            goto out;
        }
        if (len == cap) {
            int *w = realloc(v, sizeof(int) * (size_t)(cap *= 2));
            if (!w) {
                free(v);
                v = NULL;
                break;
            }
            v = w;
        }
        v[len++] = (int)k;
    }
    if (!v) {
        errbuf_set(err, errsz, LMK_ENOMEM, "%s: out of memory", path);
        goto out;
    }
    *ids = v;
    *n = len;
    v = NULL;
    rc = LMK_OK;
out:
    free(v);
    fclose(fp);
    return rc;
}
