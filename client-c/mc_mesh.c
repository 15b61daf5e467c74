/* mc_mesh.c — libmeshcorr's mesh helpers: a mesh file, or vertex and face
 * arrays in memory, as the Draco bytes a job carries, with the engine's
 * order-preserving encoder (landmarks and maps use the file's vertex order),
 * positions lossless unless the caller asks for quantization. A .drc file is
 * sent as it is. And back: Draco bytes (a result's deformed mesh) as arrays. */
#include "meshcorr.h"
#include "mesh/draco_bridge.h"
#include "mesh/mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

_Static_assert(MC_QUANTIZATION_LOSSLESS == DRACOB_LOSSLESS, "one lossless code for the API and the bridge");

static int read_whole(const char *path, unsigned char **bytes, size_t *len, char *err, size_t errsz)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        snprintf(err, errsz, "%s: cannot open", path);
        return MC_EFILE;
    }
    int rc = MC_EFILE;
    long n = -1;
    if (fseek(fp, 0, SEEK_END) == 0 && (n = ftell(fp)) > 0 && n <= DRACOB_MAX_BUFFER_BYTES &&
        fseek(fp, 0, SEEK_SET) == 0) {
        if (!(*bytes = malloc((size_t)n)))
            rc = MC_ENOMEM;
        else if (fread(*bytes, 1, (size_t)n, fp) == (size_t)n)
            rc = 0;
    }
    fclose(fp);
    if (rc) {
        free(*bytes);
        *bytes = NULL;
        snprintf(err, errsz, "%s: cannot read (empty, unreadable or over %lld bytes)", path,
                 (long long)DRACOB_MAX_BUFFER_BYTES);
        return rc;
    }
    *len = (size_t)n;
    return 0;
}

int mc_encode_mesh_quantized(const double *v, int nv, const int *f, int nf, int quantization_bits,
                             unsigned char **bytes, size_t *len, char *err, size_t errsz)
{
    *bytes = NULL;
    *len = 0;
    if (quantization_bits < MC_QUANTIZATION_LOSSLESS || quantization_bits > MC_QUANTIZATION_MAX_BITS) {
        snprintf(err, errsz, "quantization of %d bits: expected %d (lossless) or 1 to %d", quantization_bits,
                 MC_QUANTIZATION_LOSSLESS, MC_QUANTIZATION_MAX_BITS);
        return MC_EARG;
    }
    if (!v || !f || nv < 3 || nf < 1 || nv > MESH_MAX_VERTICES || nf > MESH_MAX_FACES) {
        snprintf(err, errsz, "need 3 to %d vertices and 1 to %d faces (got %d and %d)", MESH_MAX_VERTICES,
                 MESH_MAX_FACES, nv, nf);
        return MC_EARG;
    }
    /* the server refuses them anyway: say which one here */
    for (long long i = 0; i < 3LL * nv; i++)
        if (!isfinite(v[i])) {
            snprintf(err, errsz, "vertex %lld: %c coordinate is %s", i / 3, "xyz"[i % 3],
                     isnan(v[i]) ? "NaN" : "infinite");
            return MC_EARG;
        }
    char derr[512];
    int rc = dracob_encode(v, nv, f, nf, quantization_bits, bytes, len, derr, sizeof derr);
    if (rc) {
        snprintf(err, errsz, "%s", derr);
        return rc == DRACOB_ENOMEM ? MC_ENOMEM : rc == DRACOB_EARG ? MC_EARG : MC_EFILE;
    }
    return 0;
}

int mc_encode_mesh(const double *v, int nv, const int *f, int nf, unsigned char **bytes, size_t *len,
                   char *err, size_t errsz)
{
    return mc_encode_mesh_quantized(v, nv, f, nf, MC_QUANTIZATION_LOSSLESS, bytes, len, err, errsz);
}

int mc_encode_mesh_file_quantized(const char *path, int quantization_bits, unsigned char **bytes,
                                  size_t *len, char *err, size_t errsz)
{
    *bytes = NULL;
    *len = 0;
    if (quantization_bits < MC_QUANTIZATION_LOSSLESS || quantization_bits > MC_QUANTIZATION_MAX_BITS) {
        snprintf(err, errsz, "%s: quantization of %d bits: expected %d (lossless) or 1 to %d", path,
                 quantization_bits, MC_QUANTIZATION_LOSSLESS, MC_QUANTIZATION_MAX_BITS);
        return MC_EARG;
    }
    size_t pl = strlen(path);
    if (pl > 4 && strcasecmp(path + pl - 4, ".drc") == 0)
        return read_whole(path, bytes, len, err, errsz);
    mesh *m = NULL;
    if (mesh_read(path, &m, err, errsz))
        return MC_EFILE;
    char merr[600];
    int rc = mc_encode_mesh_quantized(m->v, m->nv, m->f, m->nf, quantization_bits, bytes, len, merr,
                                      sizeof merr);
    mesh_free(m);
    if (rc)
        snprintf(err, errsz, "%s: %s", path, merr);
    return rc == MC_EARG ? MC_EFILE : rc;
}

int mc_encode_mesh_file(const char *path, unsigned char **bytes, size_t *len, char *err, size_t errsz)
{
    return mc_encode_mesh_file_quantized(path, MC_QUANTIZATION_LOSSLESS, bytes, len, err, errsz);
}

int mc_read_mesh(const char *path, double **v, int *nv, int **f, int *nf, char *err, size_t errsz)
{
    if (!v || !nv || !f || !nf) {
        snprintf(err, errsz, "mc_read_mesh: an output pointer is NULL");
        return MC_EARG;
    }
    *v = NULL;
    *f = NULL;
    *nv = *nf = 0;
    if (!path) {
        snprintf(err, errsz, "mc_read_mesh: no path");
        return MC_EARG;
    }
    mesh *m = NULL;
    int rc = mesh_read(path, &m, err, errsz);
    if (rc)
        return rc == MESH_ENOMEM ? MC_ENOMEM : MC_EFILE;
    *v = m->v;                  /* the arrays change owner: malloc()ed by the reader */
    *f = m->f;
    *nv = m->nv;
    *nf = m->nf;
    m->v = NULL;
    m->f = NULL;
    mesh_free(m);
    return 0;
}

int mc_decode_mesh(const unsigned char *bytes, size_t len, double **v, int *nv, int **f, int *nf, char *err,
                   size_t errsz)
{
    *v = NULL;
    *f = NULL;
    *nv = *nf = 0;
    if (!bytes || !len) {
        snprintf(err, errsz, "no Draco bytes");
        return MC_EARG;
    }
    char derr[512];
    int rc = dracob_decode(bytes, len, MESH_MAX_VERTICES, MESH_MAX_FACES, v, nv, f, nf, derr, sizeof derr);
    if (rc) {
        snprintf(err, errsz, "%s", derr);
        return rc == DRACOB_ENOMEM ? MC_ENOMEM : MC_EFILE;
    }
    return 0;
}
