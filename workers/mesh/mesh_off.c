/* mesh_off.c — OFF reader and writer. Accepts "OFF" alone on its line or
 * followed by the counts, '#' comments, an edge count that is ignored.
 * Faces must be triangles: a polygon is refused with its line number.
 * Reads only; validation (ranges of values, manifoldness) is mesh_check's,
 * except face indices, which are range-checked here to keep the mesh safe. */
#include "mesh/mesh.h"
#include "mesh/mesh_lex.h"
#include "util/errbuf.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int mesh_read_off(const char *path, mesh **out, char *err, size_t errsz)
{
    char *buf = NULL;
    size_t len = 0;
    mesh *m = NULL;
    *out = NULL;
    int rc = mesh_lex_slurp(path, MESH_MAX_FILE_BYTES, &buf, &len, err, errsz);
    if (rc)
        return rc;

    mesh_lex lx;
    mesh_lex_init(&lx, buf, len, 1);
    const char *t;
    size_t n = mesh_lex_next(&lx, &t);
    if (n < 3 || memcmp(t, "OFF", 3) != 0 || n != 3) {
        rc = errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: expected the header \"OFF\"", path, lx.line);
        goto out;
    }
    long nv, nf, ne;
    if (mesh_lex_long(&lx, &nv) || mesh_lex_long(&lx, &nf) || mesh_lex_long(&lx, &ne)) {
        rc = errbuf_set(err, errsz, MESH_EPARSE,
                        "%s:%ld: expected the counts \"vertices faces edges\"", path, lx.line);
        goto out;
    }
    if (nv < 0 || nf < 0) {
        rc = errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: negative vertex or face count", path, lx.line);
        goto out;
    }
    if (nv > MESH_MAX_VERTICES || nf > MESH_MAX_FACES) {
        rc = errbuf_set(err, errsz, MESH_ELIMIT,
                        "%s:%ld: %ld vertices / %ld faces, over the limit of %d / %d",
                        path, lx.line, nv, nf, MESH_MAX_VERTICES, MESH_MAX_FACES);
        goto out;
    }
    /* Each vertex needs at least 6 bytes of text and each face 8: a count the
     * file cannot hold is refused before allocating for it. */
    if ((unsigned long long)nv * 6 + (unsigned long long)nf * 8 > len) {
        rc = errbuf_set(err, errsz, MESH_EPARSE,
                        "%s: header announces %ld vertices and %ld faces, more than the file holds",
                        path, nv, nf);
        goto out;
    }
    m = mesh_new((int)nv, (int)nf);
    if (!m) {
        rc = errbuf_set(err, errsz, MESH_ENOMEM, "%s: out of memory", path);
        goto out;
    }
    for (long i = 0; i < nv; i++) {
        for (int k = 0; k < 3; k++) {
            if (mesh_lex_double(&lx, &m->v[3 * i + k])) {
                rc = errbuf_set(err, errsz, MESH_EPARSE,
                                "%s:%ld: vertex %ld: coordinate %d is missing or not a number",
                                path, lx.line, i, k);
                goto out;
            }
        }
        mesh_lex_skip_line(&lx);  /* optional colours etc. */
    }
    for (long i = 0; i < nf; i++) {
        long deg;
        if (mesh_lex_long(&lx, &deg)) {
            rc = errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: face %ld: missing vertex count",
                            path, lx.line, i);
            goto out;
        }
        if (deg != 3) {
            rc = errbuf_set(err, errsz, MESH_EPARSE,
                            "%s:%ld: face %ld has %ld vertices; only triangles are accepted "
                            "(triangulate the mesh first)", path, lx.line, i, deg);
            goto out;
        }
        for (int k = 0; k < 3; k++) {
            long idx;
            if (mesh_lex_long(&lx, &idx)) {
                rc = errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: face %ld: index %d is missing or not an integer",
                                path, lx.line, i, k);
                goto out;
            }
            if (idx < 0 || idx >= nv) {
                rc = errbuf_set(err, errsz, MESH_EINVAL,
                                "%s:%ld: face %ld: vertex index %ld out of range [0, %ld)",
                                path, lx.line, i, idx, nv);
                goto out;
            }
            m->f[3 * i + k] = (int)idx;
        }
        mesh_lex_skip_line(&lx);
    }
    *out = m;
    m = NULL;
    rc = MESH_OK;
out:
    mesh_free(m);
    free(buf);
    return rc;
}

int mesh_write_off(const char *path, const mesh *m, char *err, size_t errsz)
{
    FILE *fp = fopen(path, "w");
    if (!fp)
        return errbuf_set(err, errsz, MESH_EIO, "%s: cannot create: %s", path, strerror(errno));
    fprintf(fp, "OFF\n%d %d 0\n", m->nv, m->nf);
    for (int i = 0; i < m->nv; i++)
        fprintf(fp, "%.17g %.17g %.17g\n", m->v[3 * i], m->v[3 * i + 1], m->v[3 * i + 2]);
    for (int i = 0; i < m->nf; i++)
        fprintf(fp, "3 %d %d %d\n", m->f[3 * i], m->f[3 * i + 1], m->f[3 * i + 2]);
    if (fclose(fp) != 0)
        return errbuf_set(err, errsz, MESH_EIO, "%s: write failed: %s", path, strerror(errno));
    return MESH_OK;
}
