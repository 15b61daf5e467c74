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
        errbuf_set(err, errsz, CORR_ENOMEM, "%s: out of memory checking the mesh", name);
        return -1;
    }
    return mesh_check_usable(&rep);
}

/* One mesh's repair, then the engine's own check of what came out. */
static int repair_one(const mesh *u, const char *name, repair_mesh *r, char *err, size_t errsz)
{
    int rc = repair_mesh_run(u, name, r, err, errsz);
    if (rc)
        return corr_from_repair(rc);
    char why[2048];
    if (corr_validate(r->m, name, why, sizeof why))
        return errbuf_set(err, errsz, CORR_EMESH, "%s: still not usable after the repair: %s", name,
                          why);
    return CORR_OK;
}

int corr_fix_open(const corr_input *user, int repair, corr_fix *fx, corr_input *in, char *err,
                  size_t errsz)
{
    memset(fx, 0, sizeof *fx);
    *in = *user;
    int us = usable(user->S, user->S_name, err, errsz), ut;
    if (us < 0 || (ut = usable(user->T, user->T_name, err, errsz)) < 0)
        return CORR_ENOMEM;
    if (us && ut)
        return CORR_OK;
    if (!repair)     /* the refusal names every problem of the first bad mesh */
        return us ? corr_validate(user->T, user->T_name, err, errsz)
                  : corr_validate(user->S, user->S_name, err, errsz);
    int rc;
    fx->repaired = 1;
    if ((rc = repair_one(user->S, user->S_name, &fx->S, err, errsz)) ||
        (rc = repair_one(user->T, user->T_name, &fx->T, err, errsz)))
        goto fail;
    in->S = fx->S.m;
    in->T = fx->T.m;
    if (user->L && user->L->n) {
        int n = user->L->n;
        if (!(fx->L.src = malloc(sizeof(int) * (size_t)n)) ||
            !(fx->L.tgt = malloc(sizeof(int) * (size_t)n))) {
            rc = errbuf_set(err, errsz, CORR_ENOMEM, "landmarks: out of memory");
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
    return CORR_OK;
fail:
    corr_fix_close(fx);
    *in = *user;
    return rc;
}
