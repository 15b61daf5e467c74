/* mesh_obj.c — Wavefront OBJ reader and writer (geometry only). Reads "v"
 * and "f" lines; vn, vt, g, o, s, usemtl, l and others are skipped. Face
 * corners may be "a", "a/b", "a/b/c" or "a//c"; negative indices count back
 * from the last vertex read. A polygon is split into triangles in its place
 * once every vertex is read (mesh_faces.c). Face indices are range-checked here;
 * everything else about validity is mesh_check's. */
#include "mesh/mesh.h"
#include "mesh/mesh__faces.h"
#include "mesh/mesh_lex.h"
#include "util/errbuf.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int is_word(const char *t, size_t n, const char *w)
{
    return n == strlen(w) && memcmp(t, w, n) == 0;
}

/* First pass: the number of v and f lines, to allocate once. */
static void count_lines(const char *buf, size_t len, long *nv, long *nf)
{
    mesh_lex lx;
    mesh_lex_init(&lx, buf, len, 1);
    const char *t;
    size_t n;
    *nv = *nf = 0;
    while ((n = mesh_lex_next(&lx, &t)) > 0) {
        if (is_word(t, n, "v"))
            (*nv)++;
        else if (is_word(t, n, "f"))
            (*nf)++;
        mesh_lex_skip_line(&lx);
    }
}

int mesh_read_obj(const char *path, mesh **out, char *err, size_t errsz)
{
    char *buf = NULL;
    size_t len = 0;
    mesh *m = NULL;
    *out = NULL;
    int rc = mesh_lex_slurp(path, MESH_MAX_FILE_BYTES, &buf, &len, err, errsz);
    if (rc)
        return rc;
    long nv, nf;
    int c[MESH_MAX_FACE_CORNERS];
    mesh__faces F;
    memset(&F, 0, sizeof F);
    count_lines(buf, len, &nv, &nf);
    if (nv > MESH_MAX_VERTICES || nf > MESH_MAX_FACES) {
        rc = errbuf_set(err, errsz, MESH_ELIMIT,
                        "%s: %ld vertices / %ld faces, over the limit of %d / %d",
                        path, nv, nf, MESH_MAX_VERTICES, MESH_MAX_FACES);
        goto out;
    }
    m = mesh_new((int)nv, 0);
    mesh__faces_init(&F, nf);
    if (!m) {
        rc = errbuf_set(err, errsz, MESH_ENOMEM, "%s: out of memory", path);
        goto out;
    }
    mesh_lex lx;
    mesh_lex_init(&lx, buf, len, 1);
    const char *t;
    size_t n;
    long iv = 0, jf = 0;
    while ((n = mesh_lex_next(&lx, &t)) > 0) {
        if (is_word(t, n, "v")) {
            for (int k = 0; k < 3; k++) {
                if (mesh_lex_double_inline(&lx, &m->v[3 * iv + k])) {
                    rc = errbuf_set(err, errsz, MESH_EPARSE,
                                    "%s:%ld: vertex %ld: coordinate %d is missing or not a number",
                                    path, lx.line, iv, k);
                    goto out;
                }
            }
            iv++;
        } else if (is_word(t, n, "f")) {
            int k = 0;
            const char *w;
            size_t cn;
            while ((cn = mesh_lex_next_inline(&lx, &w)) > 0) {
                if (k == MESH_MAX_FACE_CORNERS) {
                    rc = errbuf_set(err, errsz, MESH_EPARSE,
                                    "%s:%ld: face %ld has over %d vertices", path, lx.line, jf,
                                    MESH_MAX_FACE_CORNERS);
                    goto out;
                }
                size_t in = 0;
                while (in < cn && w[in] != '/')
                    in++;
                long idx;
                if (mesh_lex_parse_long(w, in, &idx) || idx == 0) {
                    rc = errbuf_set(err, errsz, MESH_EPARSE,
                                    "%s:%ld: face %ld: corner %d \"%.*s\" is not a vertex index",
                                    path, lx.line, jf, k, (int)(cn > 40 ? 40 : cn), w);
                    goto out;
                }
                long z = idx > 0 ? idx - 1 : iv + idx;  /* negative: relative */
                if (z < 0 || z >= nv) {
                    rc = errbuf_set(err, errsz, MESH_EINVAL,
                                    "%s:%ld: face %ld: vertex index %ld out of range (%ld vertices)",
                                    path, lx.line, jf, idx, idx > 0 ? nv : iv);
                    goto out;
                }
                c[k++] = (int)z;
            }
            if (k < 3) {
                rc = errbuf_set(err, errsz, MESH_EPARSE,
                                "%s:%ld: face %ld has %d vertices; a face needs 3",
                                path, lx.line, jf, k);
                goto out;
            }
            if ((rc = mesh__faces_add(&F, c, k))) {
                mesh__faces_error(rc, path, lx.line, err, errsz);
                goto out;
            }
            jf++;
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

int mesh_write_obj(const char *path, const mesh *m, char *err, size_t errsz)
{
    FILE *fp = fopen(path, "w");
    if (!fp)
        return errbuf_set(err, errsz, MESH_EIO, "%s: cannot create: %s", path, strerror(errno));
    for (int i = 0; i < m->nv; i++)
        fprintf(fp, "v %.17g %.17g %.17g\n", m->v[3 * i], m->v[3 * i + 1], m->v[3 * i + 2]);
    for (int i = 0; i < m->nf; i++)
        fprintf(fp, "f %d %d %d\n", m->f[3 * i] + 1, m->f[3 * i + 1] + 1, m->f[3 * i + 2] + 1);
    if (fclose(fp) != 0)
        return errbuf_set(err, errsz, MESH_EIO, "%s: write failed: %s", path, strerror(errno));
    return MESH_OK;
}
