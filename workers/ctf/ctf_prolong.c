/* ctf_prolong.c — a map between two coarse meshes carried to the fine
 * meshes they were made from (ctf.h): each fine source vertex located on
 * the coarse source, its image interpolated from the coarse images of
 * that face's corners, and that point projected onto the fine target
 * (proj.h, exact closest points in R^3). */
#include "ctf/ctf.h"
#include "proj/proj.h"
#include "util/errbuf.h"

#include <errno.h>
#include <stdlib.h>

int ctf_prolong(const mesh *Sc, const mesh *Tc, const bmap *Pc, const mesh *S, const mesh *T,
                bmap **out, char *err, size_t errsz)
{
    *out = NULL;
    if (Pc->n != Sc->nv || Pc->nt != Tc->nv)
        return errbuf_set(err, errsz, CTF_EINPUT, "the coarse map is sized %d -> %d, the coarse "
                          "meshes %d -> %d", Pc->n, Pc->nt, Sc->nv, Tc->nv);
    int rc = CTF_ENOMEM;
    proj_tree *ts = NULL, *tt = NULL;
    int *face = malloc(sizeof(int) * (size_t)S->nv);
    double *bary = malloc(sizeof(double) * 3 * (size_t)S->nv);
    double *Yc = malloc(sizeof(double) * 3 * (size_t)Sc->nv);
    double *Y = malloc(sizeof(double) * 3 * (size_t)S->nv);
    bmap *P = bmap_new(S->nv, T->nv);
    char detail[256];
    if (!face || !bary || !Yc || !Y || !P)
        goto fail;
    if (!(ts = proj_tree_new(Sc, detail, sizeof detail)) ||
        !(tt = proj_tree_new(T, detail, sizeof detail))) {
        rc = errbuf_set(err, errsz, errno == ENOMEM ? CTF_ENOMEM : CTF_EFAILED,
                        "projection tree: %s", detail);
        goto fail;
    }
    for (int v = 0; v < S->nv; v++)
        face[v] = P->face[v] = -1;
    if (proj_closest(ts, 3, Sc->v, 1, S->nv, S->v, face, bary, NULL))
        goto fail;
    bmap_apply(Pc, Tc->f, Tc->v, 3, Yc);
    for (int v = 0; v < S->nv; v++) {
        const int *f = Sc->f + 3 * face[v];
        for (int c = 0; c < 3; c++)
            Y[3 * v + c] = bary[3 * v] * Yc[3 * f[0] + c] + bary[3 * v + 1] * Yc[3 * f[1] + c] +
                           bary[3 * v + 2] * Yc[3 * f[2] + c];
    }
    if (proj_closest(tt, 3, T->v, 1, S->nv, Y, P->face, P->w, NULL))
        goto fail;
    *out = P;
    P = NULL;
    rc = CTF_OK;
fail:
    if (rc == CTF_ENOMEM)
        errbuf_set(err, errsz, CTF_ENOMEM, "out of memory");
    proj_tree_free(ts);
    proj_tree_free(tt);
    free(face);
    free(bary);
    free(Yc);
    free(Y);
    bmap_free(P);
    return rc;
}
