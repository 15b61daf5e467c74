/* repair.c — repair_mesh_run: the steps of repair.h in their order, the
 * repaired mesh built from what they keep, each user vertex's row, and the
 * counts; the counts' lines. */
#include "repair/repair.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int repair_counts_any(const repair_counts *c)
{
#define REPAIR_ANY(name, text) if (c->name) return 1;
    REPAIR_COUNTS(REPAIR_ANY)
#undef REPAIR_ANY
    return 0;
}

int repair_counts_text(const repair_counts *c, const char *prefix, char *out, size_t outsz)
{
    int lines = 0;
    size_t used = 0;
    if (outsz)
        out[0] = '\0';
#define REPAIR_LINE(name, text)                                                         \
    if (c->name) {                                                                      \
        lines++;                                                                        \
        if (used < outsz) {                                                             \
            int w = snprintf(out + used, outsz - used, "%s: %d %s\n", prefix, c->name, text); \
            used += w > 0 ? (size_t)w : 0;                                              \
        }                                                                               \
    }
    REPAIR_COUNTS(REPAIR_LINE)
#undef REPAIR_LINE
    return lines;
}

void repair_mesh_close(repair_mesh *r)
{
    if (!r)
        return;
    mesh_free(r->m);
    free(r->vert);
    free(r->face);
    free(r->corner);
    free(r->rep);
    free(r->row);
    free(r->carried);
    free(r->piece);
    memset(r, 0, sizeof *r);
}

int repair_mesh_check(const mesh *u, const char *name, char *err, size_t errsz)
{
    for (int t = 0; t < u->nf; t++)
        for (int k = 0; k < 3; k++) {
            int x = u->f[3 * (size_t)t + k];
            if (x < 0 || x >= u->nv)
                return errbuf_set(err, errsz, REPAIR_EMESH,
                                  "%s: face %d has vertex index %d, out of range [0, %d): "
                                  "cannot be repaired", name, t, x, u->nv);
        }
    for (int i = 0; i < 3 * u->nv; i++)
        if (!isfinite(u->v[i]))
            return errbuf_set(err, errsz, REPAIR_EMESH,
                              "%s: vertex %d has a NaN or infinite coordinate: cannot be repaired",
                              name, i / 3);
    return REPAIR_OK;
}

const unsigned char REPAIR_ALL_PIECES[1];

/* Which of the m faces sf (in pieces, piece[t] each) are kept (keep), and
 * the vertices of the snv that kept faces use, renumbered in order (renum,
 * -1 for the others); counts the pieces dropped, *kf faces and *kv vertices
 * kept. */
static void mark_kept(const unsigned char *pick, const int *piece, int pieces, const int *sf, int m,
                      int snv, unsigned char *keep, int *renum, int *kf, int *kv, repair_counts *n)
{
    for (int p = 0; p < pieces; p++)
        n->pieces += !(pick == REPAIR_ALL_PIECES || (pick ? pick[p] != 0 : p == 0));
    for (int t = 0; t < m; t++)
        keep[t] = pick == REPAIR_ALL_PIECES || (pick ? pick[piece[t]] != 0 : piece[t] == 0);
    for (int i = 0; i < snv; i++)
        renum[i] = -1;
    *kf = *kv = 0;
    for (int t = 0; t < m; t++)
        if (keep[t]) {
            (*kf)++;
            for (int k = 0; k < 3; k++)
                renum[sf[3 * (size_t)t + k]] = 0;
        }
    for (int i = 0; i < snv; i++)
        if (renum[i] == 0)
            renum[i] = (*kv)++;
}

/* The repaired mesh out->m from the kept faces (kf of them, kv vertices),
 * with each row's split vertex (vert), each face's user face (face) and
 * each row's piece; -1 out of memory. */
static int build_kept(const mesh *u, const int *sf, const int *svert, int snv, int m,
                      const unsigned char *keep, const int *piece, const int *id, const int *renum,
                      int kv, int kf, repair_mesh *out)
{
    if (!(out->m = mesh_new(kv, kf)) || !(out->vert = malloc(sizeof(int) * ((size_t)kv + 1))) ||
        !(out->face = malloc(sizeof(int) * ((size_t)kf + 1))) ||
        !(out->corner = malloc(3 * (size_t)kf + 1)) ||
        !(out->piece = malloc(sizeof(int) * ((size_t)kv + 1))))
        return -1;
    for (int i = 0; i < snv; i++)
        if (renum[i] >= 0) {
            out->vert[renum[i]] = svert[i];
            memcpy(out->m->v + 3 * (size_t)renum[i], u->v + 3 * (size_t)svert[i], 3 * sizeof(double));
        }
    for (int t = 0, j = 0; t < m; t++)
        if (keep[t]) {
            for (int k = 0; k < 3; k++) {
                out->m->f[3 * (size_t)j + k] = renum[sf[3 * (size_t)t + k]];
                out->piece[renum[sf[3 * (size_t)t + k]]] = piece[t];
            }
            out->face[j++] = id[t];
        }
    return 0;
}

/* Each user vertex's row: the copy its own faces use (out->row, -1 for a
 * vertex no kept face uses), each corner's place in its user face, the
 * count of user vertices that share a row, and each copy's user vertex
 * (out->vert): the first whose row it is, so that the copies of a weld the
 * split undid stand for the vertices given; -1 out of memory. */
static int user_rows(const mesh *u, repair_mesh *out)
{
    const int nv = u->nv, kv = out->m->nv, kf = out->m->nf;
    int *owner = malloc(sizeof *owner * ((size_t)kv + 1));
    if (!owner)
        return -1;
    for (int i = 0; i < kv; i++)
        owner[i] = -1;
    for (int i = 0; i < nv; i++)
        out->row[i] = -1;
    for (int t = 0; t < kf; t++) {
        const int *uf = u->f + 3 * (size_t)out->face[t];
        for (int k = 0; k < 3; k++) {
            int r = out->m->f[3 * (size_t)t + k];
            for (int j = 0; j < 3; j++) {
                int uv = uf[j];
                if (out->rep[uv] != out->vert[r])
                    continue;
                out->corner[3 * (size_t)t + k] = (unsigned char)j;
                if (out->row[uv] < 0)
                    out->row[uv] = r;
                if (owner[r] < 0)
                    owner[r] = uv;
            }
        }
    }
    for (int i = 0; i < nv; i++)
        if (out->row[i] >= 0 && owner[out->row[i]] != i)
            out->n.welded++;
    for (int i = 0; i < kv; i++)
        owner[i] = -1;
    for (int i = 0; i < nv; i++)
        if (out->row[i] >= 0 && owner[out->row[i]] < 0)
            owner[out->row[i]] = out->vert[out->row[i]] = i;
    free(owner);
    return 0;
}

/* Dropped vertices (no row yet): carried by the nearest kept vertex,
 * counted as unreferenced or as on a dropped piece by whether one of the m
 * faces that survived the clean-up (user faces id) uses them; -1 out of
 * memory. */
static int carry_dropped(const mesh *u, const int *id, int m, repair_mesh *out)
{
    const int nv = u->nv;
    repair_counts *n = &out->n;
    int nd = 0;
    for (int i = 0; i < nv; i++)
        nd += out->row[i] < 0;
    if (!nd)
        return 0;
    double *q = malloc(sizeof *q * (3 * (size_t)nd + 1));
    int *near = malloc(sizeof *near * ((size_t)nd + 1));
    unsigned char *in_face = calloc((size_t)nv + 1, 1);
    if (!q || !near || !in_face) {
        free(q);
        free(near);
        free(in_face);
        return -1;
    }
    for (int t = 0; t < m; t++)
        for (int k = 0; k < 3; k++)
            in_face[u->f[3 * (size_t)id[t] + k]] = 1;
    for (int i = 0, j = 0; i < nv; i++)
        if (out->row[i] < 0)
            memcpy(q + 3 * (size_t)j++, u->v + 3 * (size_t)i, 3 * sizeof(double));
    int nrc = repair_nearest(out->m->v, out->m->nv, q, nd, near);
    for (int i = 0, j = 0; !nrc && i < nv; i++)
        if (out->row[i] < 0) {
            out->row[i] = near[j++];
            out->carried[i] = 1;
            if (!in_face[i])
                n->unreferenced++;
            else
                n->piece_vertices++;
        }
    free(q);
    free(near);
    free(in_face);
    return nrc ? -1 : 0;
}

int repair_mesh_run(const mesh *u, const char *name, const unsigned char *pick, repair_mesh *out,
                    char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    int rc = repair_mesh_check(u, name, err, errsz);
    if (rc)
        return rc;
    const int nv = u->nv, nf = u->nf;
    repair_counts *n = &out->n;
    out->nv_user = nv;
    out->nf_user = nf;
    int *f = malloc(sizeof *f * (3 * (size_t)nf + 1));
    int *id = malloc(sizeof *id * ((size_t)nf + 1));
    int *sf = NULL, *svert = NULL, snv = 0;
    unsigned char *keep = malloc((size_t)nf + 1);
    int *piece = malloc(sizeof *piece * ((size_t)nf + 1));
    int *renum = NULL;
    out->rep = malloc(sizeof *out->rep * ((size_t)nv + 1));
    out->row = malloc(sizeof *out->row * ((size_t)nv + 1));
    out->carried = calloc((size_t)nv + 1, 1);
    if (!f || !id || !keep || !piece || !out->rep || !out->row || !out->carried)
        goto nomem;

    /* weld, then the faces on the welded vertices */
    if (repair_weld(u, out->rep) < 0)
        goto nomem;
    for (int c = 0; c < 3 * nf; c++)
        f[c] = out->rep[u->f[c]];
    for (int t = 0; t < nf; t++)
        id[t] = t;
    int m = repair_faces(u->v, nv, f, id, nf, &n->degenerate_faces, &n->duplicate_faces);
    if (m < 0)
        goto nomem;
    if (m == 0) {
        rc = errbuf_set(err, errsz, REPAIR_EMESH,
                        "%s: no face is left once the degenerate and duplicate ones are removed: "
                        "cannot be repaired", name);
        goto fail;
    }
    int conflicts;
    if ((n->flipped_faces = repair_orient(u->v, nv, f, m, &conflicts)) < 0 ||
        repair_split(nv, f, m, &sf, &svert, &snv, &n->split_edges, &n->split_vertices))
        goto nomem;
    (void)conflicts;     /* cut by repair_split, counted in split_edges */

    /* the pieces kept; their vertices renumbered in order */
    int pieces = repair_components(u->v, snv, sf, m, piece);
    if (pieces < 0 || !(renum = malloc(sizeof *renum * ((size_t)snv + 1))))
        goto nomem;
    out->npieces = pieces;
    int kf, kv;
    mark_kept(pick, piece, pieces, sf, m, snv, keep, renum, &kf, &kv, n);
    if (kf == 0) {
        rc = errbuf_set(err, errsz, REPAIR_EMESH, "%s: none of its %d pieces is kept", name, pieces);
        goto fail;
    }
    if (build_kept(u, sf, svert, snv, m, keep, piece, id, renum, kv, kf, out) ||
        user_rows(u, out) || carry_dropped(u, id, m, out))
        goto nomem;
    rc = REPAIR_OK;
    goto done;
nomem:
    rc = errbuf_set(err, errsz, REPAIR_ENOMEM, "%s: out of memory repairing a mesh of %d vertices",
                    name, nv);
fail:
    repair_mesh_close(out);
done:
    free(f);
    free(id);
    free(sf);
    free(svert);
    free(keep);
    free(piece);
    free(renum);
    return rc;
}
