/* repair_index.c — between the user's indexing and the repaired mesh's
 * (repair.h): results go back with one row per user vertex and faces
 * numbered as the user's; landmarks and uploaded maps come in. A repaired
 * face is a user face whose corners may be copies or welded vertices and
 * whose order may be flipped: corner[] says which user corner each one is,
 * so weights follow their vertices. */
#include "repair/repair.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

bmap *repair_map_to_user(const repair_mesh *S, const repair_mesh *T, const bmap *P)
{
    bmap *out = bmap_new(S->nv_user, T->nv_user);
    if (!out)
        return NULL;
    for (int u = 0; u < S->nv_user; u++) {
        int r = S->row[u], t = P->face[r];
        out->face[u] = T->face[t];
        double *w = out->w + 3 * (size_t)u;
        for (int k = 0; k < 3; k++)
            w[T->corner[3 * (size_t)t + k]] = P->w[3 * (size_t)r + k];
    }
    return out;
}

double *repair_points_to_user(const repair_mesh *S, const double *points)
{
    double *out = malloc(sizeof *out * (3 * (size_t)S->nv_user + 1));
    if (!out)
        return NULL;
    for (int u = 0; u < S->nv_user; u++)
        memcpy(out + 3 * (size_t)u, points + 3 * (size_t)S->row[u], 3 * sizeof *out);
    return out;
}

int repair_map_from_user(const repair_mesh *S, const repair_mesh *T, const bmap *P,
                         const char *name, bmap **out, char *err, size_t errsz)
{
    *out = NULL;
    int *inv = malloc(sizeof *inv * ((size_t)T->nf_user + 1));
    bmap *Q = bmap_new(S->m->nv, T->m->nv);
    if (!inv || !Q) {
        free(inv);
        bmap_free(Q);
        return errbuf_set(err, errsz, REPAIR_ENOMEM, "%s: out of memory", name);
    }
    for (int f = 0; f < T->nf_user; f++)
        inv[f] = -1;
    for (int t = 0; t < T->m->nf; t++)
        inv[T->face[t]] = t;
    for (int r = 0; r < S->m->nv; r++) {
        int u = S->vert[r], t = inv[P->face[u]];
        if (t < 0) {
            int f = P->face[u];
            free(inv);
            bmap_free(Q);
            return errbuf_set(err, errsz, REPAIR_EMAP,
                              "%s: row %d lands on face %d, which the mesh repair removed or left "
                              "out of the match: give the map on the repaired mesh (meshcorr fix)",
                              name, u, f);
        }
        Q->face[r] = t;
        for (int k = 0; k < 3; k++)
            Q->w[3 * (size_t)r + k] = P->w[3 * (size_t)u + T->corner[3 * (size_t)t + k]];
    }
    free(inv);
    *out = Q;
    return REPAIR_OK;
}

int repair_landmarks(const repair_mesh *S, const repair_mesh *T, const int *src, const int *tgt,
                     int n, int *src_out, int *tgt_out)
{
    int kept = 0;
    for (int i = 0; i < n; i++) {
        if (S->carried[src[i]] || T->carried[tgt[i]])
            continue;
        int s = S->row[src[i]], dup = 0;
        for (int j = 0; j < kept && !dup; j++)    /* a few dozen pairs: a scan is enough */
            dup = src_out[j] == s;
        if (dup)
            continue;
        src_out[kept] = s;
        tgt_out[kept++] = T->row[tgt[i]];
    }
    return kept;
}
