/* mesh_drc.c — .drc (Draco) reader and writer: file bytes in and out, the
 * coding itself through draco_bridge.h. Written files use
 * MESH_DRC_QUANTIZATION_BITS (lossless) and keep the vertex order (see mesh.h). The
 * _mem entry points do the same on buffers (the worker's SUBMIT blobs). */
#include "mesh/mesh.h"
#include "mesh/draco_bridge.h"
#include "mesh/mesh_lex.h"
#include "util/errbuf.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int mesh_read_drc_mem(const void *buf, size_t len, int max_nv, int max_nf, const char *name,
                      mesh **out, char *err, size_t errsz)
{
    *out = NULL;
    double *v = NULL;
    int *f = NULL, nv = 0, nf = 0;
    char derr[512] = "";
    int drc = dracob_decode((const unsigned char *)buf, len, max_nv, max_nf, &v, &nv, &f, &nf,
                            derr, sizeof derr);
    if (drc) {
        int rc = drc == DRACOB_ELIMIT ? MESH_ELIMIT : drc == DRACOB_ENOMEM ? MESH_ENOMEM : MESH_EDRACO;
        return errbuf_set(err, errsz, rc, "%s: %s", name, derr);
    }
    mesh *m = calloc(1, sizeof *m);
    if (!m) {
        free(v);
        free(f);
        return errbuf_set(err, errsz, MESH_ENOMEM, "%s: out of memory", name);
    }
    m->nv = nv;
    m->nf = nf;
    m->v = v;
    m->f = f;
    *out = m;
    return MESH_OK;
}

int mesh_encode_drc(const mesh *m, unsigned char **buf, size_t *len, char *err, size_t errsz)
{
    char derr[512] = "";
    if (dracob_encode(m->v, m->nv, m->f, m->nf, MESH_DRC_QUANTIZATION_BITS, buf, len,
                      derr, sizeof derr))
        return errbuf_set(err, errsz, MESH_EDRACO, "%s", derr);
    return MESH_OK;
}

int mesh_read_drc(const char *path, mesh **out, char *err, size_t errsz)
{
    *out = NULL;
    char *buf = NULL;
    size_t len = 0;
    int rc = mesh_lex_slurp(path, DRACOB_MAX_BUFFER_BYTES, &buf, &len, err, errsz);
    if (rc)
        return rc;
    rc = mesh_read_drc_mem(buf, len, MESH_MAX_VERTICES, MESH_MAX_FACES, path, out, err, errsz);
    free(buf);
    return rc;
}

int mesh_write_drc(const char *path, const mesh *m, char *err, size_t errsz)
{
    unsigned char *buf = NULL;
    size_t len = 0;
    char derr[512] = "";
    if (mesh_encode_drc(m, &buf, &len, derr, sizeof derr))
        return errbuf_set(err, errsz, MESH_EDRACO, "%s: %s", path, derr);
    int rc = MESH_OK;
    FILE *fp = fopen(path, "wb");
    if (!fp) {
        rc = errbuf_set(err, errsz, MESH_EIO, "%s: cannot create: %s", path, strerror(errno));
    } else {
        size_t put = fwrite(buf, 1, len, fp);
        if (fclose(fp) != 0 || put != len)
            rc = errbuf_set(err, errsz, MESH_EIO, "%s: write failed: %s", path, strerror(errno));
    }
    free(buf);
    return rc;
}
