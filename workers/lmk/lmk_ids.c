/* lmk_ids.c — a file of vertex ids, one per line (ground-truth lists and
 * the like; see lmk.h): the same reader and base rule as landmark lists,
 * without the landmark rule (duplicates are fine). */
#include "lmk/lmk_int.h"
#include "util/errbuf.h"

#include <stdlib.h>

static int read_ids(const char *path, int base, const mesh *m, int nv, int max, int **ids, int *n,
                    char *err, size_t errsz)
{
    *ids = NULL;
    *n = 0;
    lmk__file f;
    int rc = lmk__file_read(path, max, &f, err, errsz), b = 0;
    if (rc)
        return rc;
    long *v = malloc(sizeof(long) * ((size_t)f.n + 1));
    int *out = malloc(sizeof(int) * ((size_t)f.n + 1));
    if (f.layout == LMK__PAIRS)
        rc = lmk__file_refuse(path, &f, "a vertex list holds one id a line (or BIM .vts `id x y z` / "
                              ".pid `id 0 0 0` lines)", err, errsz);
    else if (!v || !out)
        rc = errbuf_set(err, errsz, LMK_ENOMEM, "%s: out of memory", path);
    else if (!(rc = lmk__file_ids(path, &f, 0, base, m, nv, "vertex", 0, v, &b, err, errsz))) {
        for (int k = 0; k < f.n; k++)
            out[k] = (int)(v[k] - b);
        *ids = out;
        *n = f.n;
        out = NULL;
    }
    free(v);
    free(out);
    lmk__file_close(&f);
    return rc;
}

int lmk_read_ids_on(const char *path, int base, const mesh *m, int max, int **ids, int *n,
                    char *err, size_t errsz)
{
    return read_ids(path, base, m, m->nv, max, ids, n, err, errsz);
}

int lmk_read_ids(const char *path, int base, int nv, int max, int **ids, int *n,
                 char *err, size_t errsz)
{
    return read_ids(path, base, NULL, nv, max, ids, n, err, errsz);
}
