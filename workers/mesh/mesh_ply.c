/* mesh_ply.c — PLY reader (ascii, binary_little_endian and
 * binary_big_endian, as older scanners write it) and writer
 * (binary_little_endian, double positions, so a round trip is exact).
 * The header is parsed into a small element/property table; elements other
 * than "vertex" and "face", and properties other than x y z and the face
 * index list, are read past and dropped. Every element count is checked
 * against the limits and against the bytes left in the file before any
 * allocation. A polygon is split into triangles in its place (mesh_faces.c). */
#include "mesh/mesh.h"
#include "mesh/mesh__faces.h"
#include "mesh/mesh_lex.h"
#include "util/errbuf.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PLY_MAX_ELEMENTS   16
#define PLY_MAX_PROPERTIES 64

enum ply_type { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 };

static const struct { const char *name; enum ply_type type; int size; } ply_types[] = {
    { "char", T_I8, 1 },   { "int8", T_I8, 1 },     { "uchar", T_U8, 1 },  { "uint8", T_U8, 1 },
    { "short", T_I16, 2 }, { "int16", T_I16, 2 },   { "ushort", T_U16, 2 }, { "uint16", T_U16, 2 },
    { "int", T_I32, 4 },   { "int32", T_I32, 4 },   { "uint", T_U32, 4 },  { "uint32", T_U32, 4 },
    { "float", T_F32, 4 }, { "float32", T_F32, 4 }, { "double", T_F64, 8 }, { "float64", T_F64, 8 },
};

typedef struct ply_prop {
    enum ply_type type;   /* scalar type, or the item type of a list */
    enum ply_type count;  /* list count type; T_NONE for a scalar */
    int role;             /* 0 skip, 1..3 x y z, 4 face indices */
} ply_prop;

typedef struct ply_elem {
    char name[32];
    long long count;
    int nprop;
    ply_prop prop[PLY_MAX_PROPERTIES];
} ply_elem;

/* ply_reader.binary: 0 for ascii, else the byte order. */
enum { PLY_LITTLE_ENDIAN = 1, PLY_BIG_ENDIAN = 2 };

typedef struct ply_reader {
    int binary;
    const unsigned char *p, *end;  /* binary cursor */
    mesh_lex lx;                   /* ascii cursor */
} ply_reader;

static int type_size(enum ply_type t)
{
    for (size_t i = 0; i < sizeof ply_types / sizeof ply_types[0]; i++)
        if (ply_types[i].type == t)
            return ply_types[i].size;
    return 0;
}

static enum ply_type type_of(const char *t, size_t n)
{
    for (size_t i = 0; i < sizeof ply_types / sizeof ply_types[0]; i++)
        if (strlen(ply_types[i].name) == n && memcmp(ply_types[i].name, t, n) == 0)
            return ply_types[i].type;
    return T_NONE;
}

static int word_is(const char *t, size_t n, const char *w)
{
    return n == strlen(w) && memcmp(t, w, n) == 0;
}

/* Reads one value of type t as a double; -1 at end of data or bad text. */
static int read_value(ply_reader *r, enum ply_type t, double *out)
{
    if (!r->binary)
        return mesh_lex_double(&r->lx, out);
    int sz = type_size(t);
    if (r->end - r->p < sz)
        return -1;
    unsigned char b[8];
    memcpy(b, r->p, (size_t)sz);
    r->p += sz;
    uint64_t u = 0;
    for (int i = 0; i < sz; i++)   /* most significant byte first */
        u = (u << 8) | b[r->binary == PLY_BIG_ENDIAN ? i : sz - 1 - i];
    switch (t) {
    case T_I8:  *out = (int8_t)u; break;
    case T_U8:  *out = (uint8_t)u; break;
    case T_I16: *out = (int16_t)u; break;
    case T_U16: *out = (uint16_t)u; break;
    case T_I32: *out = (int32_t)u; break;
    case T_U32: *out = (uint32_t)u; break;
    case T_F32: { uint32_t w = (uint32_t)u; float fl; memcpy(&fl, &w, 4); *out = fl; break; }
    case T_F64: { double d; memcpy(&d, &u, 8); *out = d; break; }
    default: return -1;
    }
    return 0;
}

/* Where an element's instance is, for messages: "line 12" or "byte 345". */
static long where(const ply_reader *r, const unsigned char *base)
{
    return r->binary ? (long)(r->p - base) : r->lx.line;
}

/* An "element NAME COUNT" line (lx after the keyword): a new entry of el,
 * its count checked against the limits. */
static int parse_element(const char *path, mesh_lex *lx, ply_elem *el, int *nel, char *err, size_t errsz)
{
    const char *t;
    size_t n;
    if (*nel == PLY_MAX_ELEMENTS)
        return errbuf_set(err, errsz, MESH_ELIMIT, "%s:%ld: more than %d elements",
                          path, lx->line, PLY_MAX_ELEMENTS);
    ply_elem *e = &el[(*nel)++];
    memset(e, 0, sizeof *e);
    n = mesh_lex_next_inline(lx, &t);
    if (n == 0 || n >= sizeof e->name)
        return errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: bad element name", path, lx->line);
    memcpy(e->name, t, n);
    n = mesh_lex_next_inline(lx, &t);
    long cnt;
    if (mesh_lex_parse_long(t, n, &cnt) || cnt < 0)
        return errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: element %s: bad count",
                          path, lx->line, e->name);
    long limit = strcmp(e->name, "vertex") == 0 ? MESH_MAX_VERTICES : MESH_MAX_FACES;
    if (cnt > limit)
        return errbuf_set(err, errsz, MESH_ELIMIT,
                          "%s:%ld: element %s has %ld items, over the limit of %ld",
                          path, lx->line, e->name, cnt, limit);
    e->count = cnt;
    return MESH_OK;
}

/* A "property TYPE NAME" or "property list COUNT ITEM NAME" line (lx after
 * the keyword): a property of the last element, with its role when it is
 * x, y, z of a vertex or a face's index list. */
static int parse_property(const char *path, mesh_lex *lx, ply_elem *el, int nel, char *err, size_t errsz)
{
    const char *t;
    size_t n;
    if (nel == 0)
        return errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: property before any element",
                          path, lx->line);
    ply_elem *e = &el[nel - 1];
    if (e->nprop == PLY_MAX_PROPERTIES)
        return errbuf_set(err, errsz, MESH_ELIMIT, "%s:%ld: element %s: more than %d properties",
                          path, lx->line, e->name, PLY_MAX_PROPERTIES);
    ply_prop *pr = &e->prop[e->nprop++];
    memset(pr, 0, sizeof *pr);
    n = mesh_lex_next_inline(lx, &t);
    if (word_is(t, n, "list")) {
        n = mesh_lex_next_inline(lx, &t);
        pr->count = type_of(t, n);
        n = mesh_lex_next_inline(lx, &t);
        pr->type = type_of(t, n);
        if (pr->count == T_NONE || pr->type == T_NONE || pr->count == T_F32 || pr->count == T_F64)
            return errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: bad list property types",
                              path, lx->line);
    } else {
        pr->type = type_of(t, n);
        if (pr->type == T_NONE)
            return errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: unknown property type \"%.*s\"",
                              path, lx->line, (int)(n > 40 ? 40 : n), t);
    }
    n = mesh_lex_next_inline(lx, &t);
    if (strcmp(e->name, "vertex") == 0 && pr->count == T_NONE && n == 1 && *t >= 'x' && *t <= 'z')
        pr->role = 1 + (*t - 'x');
    if (strcmp(e->name, "face") == 0 && pr->count != T_NONE
        && (word_is(t, n, "vertex_indices") || word_is(t, n, "vertex_index")))
        pr->role = 4;
    mesh_lex_skip_line(lx);
    return MESH_OK;
}

/* Parses the header; on success *data is the first byte after it. */
static int parse_header(const char *path, const char *buf, size_t len, ply_elem *el, int *nel,
                        int *binary, size_t *data, char *err, size_t errsz)
{
    const char *hend = NULL;
    for (size_t i = 0; i + 10 <= len; i++)
        if (memcmp(buf + i, "end_header", 10) == 0 && (i == 0 || buf[i - 1] == '\n')) {
            hend = buf + i;
            break;
        }
    if (len < 4 || memcmp(buf, "ply", 3) != 0 || (buf[3] != '\n' && buf[3] != '\r'))
        return errbuf_set(err, errsz, MESH_EPARSE, "%s:1: expected the header \"ply\"", path);
    if (!hend)
        return errbuf_set(err, errsz, MESH_EPARSE, "%s: no \"end_header\" line", path);
    const char *after = hend + 10;
    while (after < buf + len && *after != '\n')
        after++;
    if (after < buf + len)
        after++;
    *data = (size_t)(after - buf);

    mesh_lex lx;
    mesh_lex_init(&lx, buf, (size_t)(hend - buf), 0);
    const char *t;
    size_t n;
    int have_format = 0;
    *nel = 0;
    mesh_lex_next(&lx, &t); /* "ply" */
    while ((n = mesh_lex_next(&lx, &t)) > 0) {
        if (word_is(t, n, "comment") || word_is(t, n, "obj_info")) {
            mesh_lex_skip_line(&lx);
        } else if (word_is(t, n, "format")) {
            n = mesh_lex_next_inline(&lx, &t);
            if (word_is(t, n, "ascii"))
                *binary = 0;
            else if (word_is(t, n, "binary_little_endian"))
                *binary = PLY_LITTLE_ENDIAN;
            else if (word_is(t, n, "binary_big_endian"))
                *binary = PLY_BIG_ENDIAN;
            else
                return errbuf_set(err, errsz, MESH_EFORMAT,
                                  "%s:%ld: unsupported PLY format \"%.*s\" (ascii, "
                                  "binary_little_endian or binary_big_endian)", path, lx.line,
                                  (int)(n > 40 ? 40 : n), t);
            have_format = 1;
            mesh_lex_skip_line(&lx);
        } else if (word_is(t, n, "element")) {
            int rc = parse_element(path, &lx, el, nel, err, errsz);
            if (rc)
                return rc;
        } else if (word_is(t, n, "property")) {
            int rc = parse_property(path, &lx, el, *nel, err, errsz);
            if (rc)
                return rc;
        } else {
            return errbuf_set(err, errsz, MESH_EPARSE, "%s:%ld: unknown header line \"%.*s\"",
                              path, lx.line, (int)(n > 40 ? 40 : n), t);
        }
    }
    if (!have_format)
        return errbuf_set(err, errsz, MESH_EPARSE, "%s: no \"format\" line", path);
    return MESH_OK;
}

/* Which elements are the mesh (*nv vertices, *nf faces) and whether the
 * avail bytes of data after the header can hold every element announced. */
static int check_sizes(const char *path, const ply_elem *el, int nel, int binary, size_t avail,
                       long long *nv, long long *nf, char *err, size_t errsz)
{
    long long need = 0;
    int have_xyz = 0, have_faces = 0;
    *nv = *nf = 0;
    for (int i = 0; i < nel; i++) {
        const ply_elem *e = &el[i];
        if (e->nprop == 0 && e->count > 0)
            return errbuf_set(err, errsz, MESH_EPARSE, "%s: element %s has no properties", path, e->name);
        long long rec = 0;  /* least bytes one item takes */
        for (int k = 0; k < e->nprop; k++) {
            const ply_prop *pr = &e->prop[k];
            if (binary)
                rec += pr->count == T_NONE ? type_size(pr->type) : type_size(pr->count);
            else
                rec += 2;  /* a digit and a separator */
            if (pr->role >= 1 && pr->role <= 3)
                have_xyz |= 1 << (pr->role - 1);
            if (pr->role == 4)
                have_faces = 1;
        }
        need += e->count * rec;
        if (strcmp(e->name, "vertex") == 0)
            *nv = e->count;
        else if (strcmp(e->name, "face") == 0)
            *nf = e->count;
    }
    if (have_xyz != 7)
        return errbuf_set(err, errsz, MESH_EPARSE, "%s: element vertex lacks x, y or z", path);
    if (*nf > 0 && !have_faces)
        return errbuf_set(err, errsz, MESH_EPARSE,
                          "%s: element face lacks a vertex_indices list", path);
    if ((unsigned long long)need > avail)
        return errbuf_set(err, errsz, MESH_EPARSE,
                          "%s: header announces %lld vertices and %lld faces, more than the file "
                          "holds (%zu bytes of data)", path, *nv, *nf, avail);
    return MESH_OK;
}

/* The cnt items of list property pr of item j of element e; into corner
 * when it is the face index list (each index checked against nv). */
static int read_list(const char *path, ply_reader *r, const unsigned char *base, const ply_elem *e,
                     const ply_prop *pr, long long j, long cnt, long long nv, int *corner,
                     char *err, size_t errsz)
{
    int is_f = strcmp(e->name, "face") == 0;
    for (long q = 0; q < cnt; q++) {
        double x;
        if (read_value(r, pr->type, &x))
            return errbuf_set(err, errsz, MESH_EPARSE,
                              "%s: %s %lld: list item %ld missing (truncated file?) at %s %ld",
                              path, e->name, j, q, r->binary ? "byte" : "line", where(r, base));
        if (!(is_f && pr->role == 4))
            continue;
        if (!(x >= 0 && x < (double)nv) || x != (double)(long)x)
            return errbuf_set(err, errsz, MESH_EINVAL,
                              "%s: face %lld: vertex index %g out of range [0, %lld)",
                              path, j, x, nv);
        corner[q] = (int)x;
    }
    return MESH_OK;
}

/* Every item of every element, in the header's order, from r: the vertices'
 * x y z into m, the faces' indices into F (corner: room for
 * MESH_MAX_FACE_CORNERS), the rest read past. */
static int read_elements(const char *path, ply_reader *r, const unsigned char *base, const ply_elem *el,
                         int nel, long long nv, mesh *m, mesh__faces *F, int *corner, char *err,
                         size_t errsz)
{
    for (int i = 0; i < nel; i++) {
        const ply_elem *e = &el[i];
        int is_v = strcmp(e->name, "vertex") == 0, is_f = strcmp(e->name, "face") == 0;
        for (long long j = 0; j < e->count; j++) {
            for (int k = 0; k < e->nprop; k++) {
                const ply_prop *pr = &e->prop[k];
                double x;
                if (read_value(r, pr->count == T_NONE ? pr->type : pr->count, &x))
                    return errbuf_set(err, errsz, MESH_EPARSE,
                                      "%s: %s %lld: property %d missing or not a number (truncated "
                                      "file?) at %s %ld", path, e->name, j, k,
                                      r->binary ? "byte" : "line", where(r, base));
                if (pr->count == T_NONE) {
                    if (is_v && pr->role)
                        m->v[3 * j + pr->role - 1] = x;
                    continue;
                }
                if (!(x >= 0 && x <= 255 * 255))
                    return errbuf_set(err, errsz, MESH_EPARSE, "%s: %s %lld: bad list length %g",
                                      path, e->name, j, x);
                long cnt = (long)x;
                int faces = is_f && pr->role == 4;
                if (faces && (cnt < 3 || cnt > MESH_MAX_FACE_CORNERS))
                    return errbuf_set(err, errsz, MESH_EPARSE,
                                      "%s: face %lld has %ld vertices; a face needs 3 to %d", path, j,
                                      cnt, MESH_MAX_FACE_CORNERS);
                int rc = read_list(path, r, base, e, pr, j, cnt, nv, corner, err, errsz);
                if (rc)
                    return rc;
                if (faces && (rc = mesh__faces_add(F, corner, (int)cnt)))
                    return mesh__faces_error(rc, path, 0, err, errsz);
            }
        }
    }
    return MESH_OK;
}

int mesh_read_ply(const char *path, mesh **out, char *err, size_t errsz)
{
    char *buf = NULL;
    size_t len = 0, data = 0;
    mesh *m = NULL;
    ply_elem *el = NULL;
    int nel = 0, binary = 0, corner[MESH_MAX_FACE_CORNERS];
    mesh__faces F;
    memset(&F, 0, sizeof F);
    *out = NULL;
    int rc = mesh_lex_slurp(path, MESH_MAX_FILE_BYTES, &buf, &len, err, errsz);
    if (rc)
        return rc;
    el = calloc(PLY_MAX_ELEMENTS, sizeof *el);
    if (!el) {
        rc = errbuf_set(err, errsz, MESH_ENOMEM, "%s: out of memory", path);
        goto out;
    }
    rc = parse_header(path, buf, len, el, &nel, &binary, &data, err, errsz);
    if (rc)
        goto out;

    /* Sizes: which elements are the mesh, and can the file hold them all? */
    long long nv, nf;
    rc = check_sizes(path, el, nel, binary, len - data, &nv, &nf, err, errsz);
    if (rc)
        goto out;
    m = mesh_new((int)nv, 0);
    mesh__faces_init(&F, nf);
    if (!m) {
        rc = errbuf_set(err, errsz, MESH_ENOMEM, "%s: out of memory", path);
        goto out;
    }

    ply_reader r = { .binary = binary,
                     .p = (const unsigned char *)buf + data, .end = (const unsigned char *)buf + len };
    mesh_lex_init(&r.lx, buf + data, len - data, 0);
    rc = read_elements(path, &r, (const unsigned char *)buf, el, nel, nv, m, &F, corner, err, errsz);
    if (rc)
        goto out;
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
    free(el);
    free(buf);
    return rc;
}

static void put_le(FILE *fp, const void *src, int size)
{
    unsigned char b[8];
    memcpy(b, src, (size_t)size);
    /* The in-memory bytes are host order; emit them least significant first. */
    const uint16_t probe = 1;
    int little = *(const unsigned char *)&probe == 1;
    for (int i = 0; i < size; i++)
        fputc(b[little ? i : size - 1 - i], fp);
}

int mesh_write_ply(const char *path, const mesh *m, char *err, size_t errsz)
{
    return mesh_write_ply_rgb(path, m, NULL, err, errsz);
}

int mesh_write_ply_rgb(const char *path, const mesh *m, const unsigned char *rgb,
                       char *err, size_t errsz)
{
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return errbuf_set(err, errsz, MESH_EIO, "%s: cannot create: %s", path, strerror(errno));
    fprintf(fp, "ply\nformat binary_little_endian 1.0\ncomment written by meshcorr\n"
                "element vertex %d\nproperty double x\nproperty double y\nproperty double z\n%s"
                "element face %d\nproperty list uchar int vertex_indices\nend_header\n",
            m->nv, rgb ? "property uchar red\nproperty uchar green\nproperty uchar blue\n" : "",
            m->nf);
    for (int i = 0; i < m->nv; i++) {
        for (int k = 0; k < 3; k++)
            put_le(fp, &m->v[3 * i + k], 8);
        if (rgb)
            fwrite(rgb + 3 * i, 1, 3, fp);
    }
    for (int i = 0; i < m->nf; i++) {
        fputc(3, fp);
        for (int k = 0; k < 3; k++)
            put_le(fp, &m->f[3 * i + k], 4);
    }
    if (fclose(fp) != 0)
        return errbuf_set(err, errsz, MESH_EIO, "%s: write failed: %s", path, strerror(errno));
    return MESH_OK;
}
