/* mesh_off.c — OFF reader and writer. Accepts "OFF" (or COFF, NOFF, STOFF:
 * what follows a vertex's x y z is skipped) alone on its line or followed
 * by the counts, '#' comments, an edge count that is ignored.
 * A polygon is split into triangles in its place (mesh_faces.c).
 * Reads only; validation (ranges of values, manifoldness) is mesh_check's,
 * except face indices, which are range-checked here to keep the mesh safe. */
#include "mesh/mesh.h"
#include "mesh/mesh__faces.h"
#include "mesh/mesh_lex.h"
#include "util/errbuf.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Whether the header word t (n bytes) is [ST][C][N]OFF: the variants with
 * texture coordinates, colours or normals after each vertex's x y z, which
 * the reader skips with the rest of the line. */
static int off_header(const char *t, size_t n)
{
    if (n < 3 || memcmp(t + n - 3, "OFF", 3) != 0)
        return 0;
    size_t i = 0;
    if (n - 3 >= 2 && memcmp(t, "ST", 2) == 0)
        i = 2;
    if (i < n - 3 && t[i] == 'C')
        i++;
    if (i < n - 3 && t[i] == 'N')
        i++;
    return i == n - 3;
}

int mesh_read_off(const char *path, mesh **out, char *err, size_t errsz)
{
    char *buf = NULL;
    size_t len = 0;
    mesh *m = NULL;
    int c[MESH_MAX_FACE_CORNERS];
    mesh__faces F;
    memset(&F, 0, sizeof F);
    *out = NULL;
    int rc = mesh_lex_slurp(path, MESH_MAX_FILE_BYTES, &buf, &len, err, errsz);
    if (rc)
        return rc;

    mesh_lex lx;
    mesh_lex_init(&lx, buf, len, 1);
    const char *t;
    size_t n = mesh_lex_next(&lx, &t);
    if (!off_header(t, n)) {
        rc = errbuf_set(err, errsz, MESH_EPARSE,
                        "%s:%ld: expected the header \"OFF\" (or COFF, NOFF, STOFF and their "
                        "combinations; 4OFF and nOFF, of other dimensions, are not read), got \"%.*s\"",
                        path, lx.line, (int)(n > 20 ? 20 : n), t);
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
    m = mesh_new((int)nv, 0);
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
    mesh__faces_init(&F, nf);
    for (long i = 0; i < nf; i++) {
        long deg;
        if (mesh_lex_long(&lx, &deg)) {
            rc = errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: face %ld: missing vertex count",
                            path, lx.line, i);
            goto out;
        }
        if (deg < 3 || deg > MESH_MAX_FACE_CORNERS) {
            rc = errbuf_set(err, errsz, MESH_EPARSE,
                            "%s:%ld: face %ld has %ld vertices; a face needs 3 to %d",
                            path, lx.line, i, deg, MESH_MAX_FACE_CORNERS);
            goto out;
        }
        for (long k = 0; k < deg; k++) {
            long idx;
            if (mesh_lex_long(&lx, &idx)) {
                rc = errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: face %ld: index %ld is missing or not an integer",
                                path, lx.line, i, k);
                goto out;
            }
            if (idx < 0 || idx >= nv) {
                rc = errbuf_set(err, errsz, MESH_EINVAL,
                                "%s:%ld: face %ld: vertex index %ld out of range [0, %ld)",
                                path, lx.line, i, idx, nv);
                goto out;
            }
            c[k] = (int)idx;
        }
        if ((rc = mesh__faces_add(&F, c, (int)deg))) {
            mesh__faces_error(rc, path, lx.line, err, errsz);
            goto out;
        }
        mesh_lex_skip_line(&lx);
    }
    if ((rc = mesh__faces_finish(&F, m))) {
        mesh__faces_error(rc, path, 0, err, errsz);
        goto out;
    }
    *out = m;
    m = NULL;
    rc = MESH_OK;
out:
    mesh__faces_free(&F);
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
