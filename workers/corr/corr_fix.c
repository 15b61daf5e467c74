/* corr_fix.c — a job's meshes checked and, where needed, repaired before
 * it runs, and its result carried back to the user's indexing (corr.h,
 * corr_fix_open). Combines repair.h's steps; computes no geometry itself.
 * Apart from corr.c so that the daemon's validator links it without the
 * stages; the way back (corr_fix_back.c) is apart for the same reason. */
#include "corr/corr.h"
#include "mesh/mesh_check.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

void corr_fix_close(corr_fix *fx)
{
    if (!fx)
        return;
    repair_mesh_close(&fx->S);
    repair_mesh_close(&fx->T);
    free(fx->L.src);
    free(fx->L.tgt);
    bmap_free(fx->P0);
    bmap_free(fx->Q0);
    memset(fx, 0, sizeof *fx);
}

/* 1 when m can be used as given, 0 when not, -1 without memory. */
static int usable(const mesh *m, const char *name, char *err, size_t errsz)
{
    mesh_check_report rep;
    if (mesh_check_run(m, &rep, err, errsz)) {
        errbuf_set(err, errsz, KIND_ENOMEM, "%s: out of memory checking the mesh", name);
        return -1;
    }
    return mesh_check_usable(&rep);
}

/* One mesh's repair (the pieces keep names, NULL: the largest), then the
 * engine's own check of what came out; pieces are allowed, each is
 * matched with its pair (corr_run). */
static int repair_one(const mesh *u, const char *name, const unsigned char *keep, repair_mesh *r,
                      char *err, size_t errsz)
{
    int rc = repair_mesh_run(u, name, keep, r, err, errsz);
    if (rc)
        return corr_from_repair(rc);
    mesh_check_report rep;
    char lines[2048];
    if (mesh_check_run(r->m, &rep, lines, sizeof lines))
        return errbuf_set(err, errsz, KIND_ENOMEM, "%s: out of memory checking the repair", name);
    rep.components = rep.components > 1 ? 1 : rep.components;
    if (mesh_check_usable(&rep))
        return KIND_OK;
    mesh_check_problems(&rep, name, lines, sizeof lines);
    return errbuf_set(err, errsz, KIND_EMESH, "%s: still not usable after the repair:\n%s", name,
                      lines);
}

/* The pieces to keep when the landmarks pair pieces of the two meshes
 * (repair_pieces_pair): those pairs, each matched on its own; *ks, *kt
 * stay NULL (the largest piece of each) when they pair none. */
static int choose_pieces(const corr_input *user, unsigned char **ks, unsigned char **kt, char *err,
                         size_t errsz)
{
    *ks = *kt = NULL;
    repair_mesh a, b;
    int rc = repair_mesh_run(user->S, user->S_name, REPAIR_ALL_PIECES, &a, err, errsz);
    if (rc)
        return corr_from_repair(rc);
    if ((rc = repair_mesh_run(user->T, user->T_name, REPAIR_ALL_PIECES, &b, err, errsz))) {
        repair_mesh_close(&a);
        return corr_from_repair(rc);
    }
    int n = user->L->n;
    int *ps = malloc(sizeof(int) * ((size_t)n + 1)), *pt = malloc(sizeof(int) * ((size_t)n + 1));
    int *pair = malloc(sizeof(int) * ((size_t)a.npieces + 1));
    if (!ps || !pt || !pair) {
        rc = errbuf_set(err, errsz, KIND_ENOMEM, "out of memory pairing the meshes' pieces");
        goto out;
    }
    if (a.npieces < 2 && b.npieces < 2)
        goto out;
    for (int k = 0; k < n; k++) {
        int s = user->L->src[k], t = user->L->tgt[k];
        ps[k] = a.carried[s] ? -1 : a.piece[a.row[s]];
        pt[k] = b.carried[t] ? -1 : b.piece[b.row[t]];
    }
    int pairs = repair_pieces_pair(ps, pt, n, a.npieces, b.npieces, PROTO_MIN_LANDMARKS, pair);
    if (pairs < 0) {
        rc = errbuf_set(err, errsz, KIND_ENOMEM, "out of memory pairing the meshes' pieces");
        goto out;
    }
    if (pairs == 0)
        goto out;
    if (!(*ks = calloc((size_t)a.npieces, 1)) || !(*kt = calloc((size_t)b.npieces, 1))) {
        free(*ks);
        *ks = NULL;
        rc = errbuf_set(err, errsz, KIND_ENOMEM, "out of memory pairing the meshes' pieces");
        goto out;
    }
    for (int p = 0; p < a.npieces; p++)
        if (pair[p] >= 0) {
            (*ks)[p] = 1;
            (*kt)[pair[p]] = 1;
        }
out:
    free(ps);
    free(pt);
    free(pair);
    repair_mesh_close(&a);
    repair_mesh_close(&b);
    return rc;
}

int corr_fix_open(const corr_input *user, int repair, corr_fix *fx, corr_input *in, char *err,
                  size_t errsz)
{
    memset(fx, 0, sizeof *fx);
    *in = *user;
    int us = usable(user->S, user->S_name, err, errsz), ut;
    if (us < 0 || (ut = usable(user->T, user->T_name, err, errsz)) < 0)
        return KIND_ENOMEM;
    if (us && ut)
        return KIND_OK;
    if (!repair)     /* the refusal names every problem of the first bad mesh */
        return us ? corr_validate(user->T, user->T_name, err, errsz)
                  : corr_validate(user->S, user->S_name, err, errsz);
    int rc;
    unsigned char *ks = NULL, *kt = NULL;    /* the pieces kept; NULL: the largest */
    fx->repaired = 1;
    if (!user->P0 && user->L && user->L->n >= PROTO_MIN_LANDMARKS &&
        (rc = choose_pieces(user, &ks, &kt, err, errsz)))
        goto fail;
    rc = repair_one(user->S, user->S_name, ks, &fx->S, err, errsz);
    if (!rc)
        rc = repair_one(user->T, user->T_name, kt, &fx->T, err, errsz);
    free(ks);
    free(kt);
    if (rc)
        goto fail;
    in->S = fx->S.m;
    in->T = fx->T.m;
    if (user->L && user->L->n) {
        int n = user->L->n;
        if (!(fx->L.src = malloc(sizeof(int) * (size_t)n)) ||
            !(fx->L.tgt = malloc(sizeof(int) * (size_t)n))) {
            rc = errbuf_set(err, errsz, KIND_ENOMEM, "landmarks: out of memory");
            goto fail;
        }
        fx->L.n = repair_landmarks(&fx->S, &fx->T, user->L->src, user->L->tgt, n, fx->L.src,
                                   fx->L.tgt);
        in->L = &fx->L;
    }
    if (user->P0 && (rc = repair_map_from_user(&fx->S, &fx->T, user->P0, "initial map p", &fx->P0,
                                               err, errsz))) {
        rc = corr_from_repair(rc);
        goto fail;
    }
    if (user->Q0 && (rc = repair_map_from_user(&fx->T, &fx->S, user->Q0, "initial map q", &fx->Q0,
                                               err, errsz))) {
        rc = corr_from_repair(rc);
        goto fail;
    }
    in->P0 = fx->P0;
    in->Q0 = fx->Q0;
    return KIND_OK;
fail:
    corr_fix_close(fx);
    *in = *user;
    return rc;
}
