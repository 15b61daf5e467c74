/* mesh.c — the mesh type's lifetime, error strings and the by-extension
 * dispatch of mesh_read/mesh_write. Format code lives in mesh_<fmt>.c. */
#include "mesh/mesh.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

mesh *mesh_new(int nv, int nf)
{
    if (nv < 0 || nf < 0 || nv > MESH_MAX_VERTICES || nf > MESH_MAX_FACES)
        return NULL;
    mesh *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    m->nv = nv;
    m->nf = nf;
    m->v = calloc((size_t)nv * 3 + 1, sizeof *m->v);
    m->f = calloc((size_t)nf * 3 + 1, sizeof *m->f);
    if (!m->v || !m->f) {
        mesh_free(m);
        return NULL;
    }
    return m;
}

void mesh_free(mesh *m)
{
    if (!m)
        return;
    free(m->v);
    free(m->f);
    free(m);
}

mesh *mesh_copy(const mesh *m)
{
    mesh *c = mesh_new(m->nv, m->nf);
    if (!c)
        return NULL;
    memcpy(c->v, m->v, sizeof *m->v * 3 * (size_t)m->nv);
    memcpy(c->f, m->f, sizeof *m->f * 3 * (size_t)m->nf);
    c->polygons = m->polygons;
    return c;
}

typedef int (*reader_fn)(const char *, mesh **, char *, size_t);
typedef int (*writer_fn)(const char *, const mesh *, char *, size_t);

static const struct {
    const char *ext;
    reader_fn read;
    writer_fn write;
} formats[] = {
    { ".off", mesh_read_off, mesh_write_off },
    { ".obj", mesh_read_obj, mesh_write_obj },
    { ".ply", mesh_read_ply, mesh_write_ply },
    { ".drc", mesh_read_drc, mesh_write_drc },
};

static int find_format(const char *path)
{
    const char *dot = strrchr(path, '.');
    if (!dot)
        return -1;
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; i++)
        if (strcasecmp(dot, formats[i].ext) == 0)
            return (int)i;
    return -1;
}

int mesh_read(const char *path, mesh **out, char *err, size_t errsz)
{
    *out = NULL;
    int k = find_format(path);
    if (k < 0)
        return errbuf_set(err, errsz, MESH_EFORMAT,
                          "%s: unknown mesh format (expected .off, .obj, .ply or .drc)", path);
    return formats[k].read(path, out, err, errsz);
}

int mesh_write(const char *path, const mesh *m, char *err, size_t errsz)
{
    int k = find_format(path);
    if (k < 0)
        return errbuf_set(err, errsz, MESH_EFORMAT,
                          "%s: unknown mesh format (expected .off, .obj, .ply or .drc)", path);
    return formats[k].write(path, m, err, errsz);
}
