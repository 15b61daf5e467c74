/* corr_pieces.c — a job in pieces, pair by pair (corr__pieces.h): the
 * pieces of each mesh (repair_components), paired by the landmarks
 * (repair_pieces_pair, the rule the input repair kept them by), cut out
 * as meshes of their own with their landmarks, and the pairs' maps put
 * back together on the whole meshes. */
#include "corr/corr__pieces.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

void corr__pieces_close(corr__pieces *pc)
{
    if (!pc)
        return;
    for (int k = 0; k < pc->n && pc->p; k++) {
        corr__piece *q = &pc->p[k];
        mesh_free(q->S);
        mesh_free(q->T);
        free(q->sv);
        free(q->tv);
        free(q->sf);
        free(q->tf);
        free(q->L.src);
        free(q->L.tgt);
    }
    free(pc->p);
    memset(pc, 0, sizeof *pc);
}

/* The faces of m whose piece is p as a mesh of its own: *out, and the
 * indices in m of its vertices (*vs) and faces (*fs); loc[v] (m->nv,
 * caller's) is set to each kept vertex's index in the piece. */
static int cut(const mesh *m, const int *piece, int p, int *loc, mesh **out, int **vs, int **fs)
{
    int nv = 0, nf = 0;
    for (int v = 0; v < m->nv; v++)
        loc[v] = -1;
    for (int t = 0; t < m->nf; t++)
        if (piece[t] == p) {
            nf++;
            for (int k = 0; k < 3; k++)
                if (loc[m->f[3 * t + k]] < 0)
                    loc[m->f[3 * t + k]] = 0;
        }
    for (int v = 0; v < m->nv; v++)
        if (loc[v] == 0)
            loc[v] = ++nv;                    /* 1-based while counting */
    if (!(*out = mesh_new(nv, nf)) || !(*vs = malloc(sizeof(int) * ((size_t)nv + 1))) ||
        !(*fs = malloc(sizeof(int) * ((size_t)nf + 1))))
        return -1;
    for (int v = 0; v < m->nv; v++)
        if (loc[v] > 0) {
            loc[v]--;
            (*vs)[loc[v]] = v;
            memcpy((*out)->v + 3 * (size_t)loc[v], m->v + 3 * (size_t)v, 3 * sizeof(double));
        }
    for (int t = 0, j = 0; t < m->nf; t++)
        if (piece[t] == p) {
            for (int k = 0; k < 3; k++)
                (*out)->f[3 * (size_t)j + k] = loc[m->f[3 * t + k]];
            (*fs)[j++] = t;
        }
    return 0;
}

int corr__pieces_open(const corr_input *in, corr__pieces *pc, char *err, size_t errsz)
{
    memset(pc, 0, sizeof *pc);
    if (!in->L || in->L->n == 0 || in->P0)
        return KIND_OK;
    const mesh *S = in->S, *T = in->T;
    int n = in->L->n, rc = KIND_OK;
    int *fs = malloc(sizeof(int) * ((size_t)S->nf + 1)), *ft = malloc(sizeof(int) * ((size_t)T->nf + 1));
    int *vps = malloc(sizeof(int) * ((size_t)S->nv + 1)), *vpt = malloc(sizeof(int) * ((size_t)T->nv + 1));
    int *ls = malloc(sizeof(int) * ((size_t)S->nv + 1)), *lt = malloc(sizeof(int) * ((size_t)T->nv + 1));
    int *ps = malloc(sizeof(int) * ((size_t)n + 1)), *pt = malloc(sizeof(int) * ((size_t)n + 1));
    int *pair = NULL;
    if (!fs || !ft || !vps || !vpt || !ls || !lt || !ps || !pt)
        goto nomem;
    int ns = repair_components(S->v, S->nv, S->f, S->nf, fs);
    int nt = repair_components(T->v, T->nv, T->f, T->nf, ft);
    if (ns < 0 || nt < 0)
        goto nomem;
    if (ns < 2 && nt < 2)
        goto out;
    for (int t = 0; t < S->nf; t++)
        for (int k = 0; k < 3; k++)
            vps[S->f[3 * t + k]] = fs[t];
    for (int t = 0; t < T->nf; t++)
        for (int k = 0; k < 3; k++)
            vpt[T->f[3 * t + k]] = ft[t];
    for (int k = 0; k < n; k++) {
        ps[k] = vps[in->L->src[k]];
        pt[k] = vpt[in->L->tgt[k]];
    }
    if (!(pair = malloc(sizeof(int) * ((size_t)ns + 1))))
        goto nomem;
    int pairs = repair_pieces_pair(ps, pt, n, ns, nt, PROTO_MIN_LANDMARKS, pair);
    if (pairs < 0)
        goto nomem;
    if (pairs != ns || pairs != nt) {
        rc = errbuf_set(err, errsz, KIND_EMESH,
                        "%s is in %d pieces and %s in %d; the landmarks pair %d of them (a pair: at "
                        "least %d landmarks on a piece, all landing on one piece of the other mesh)",
                        in->S_name, ns, in->T_name, nt, pairs, PROTO_MIN_LANDMARKS);
        goto out;
    }
    if (!(pc->p = calloc((size_t)pairs, sizeof *pc->p)))
        goto nomem;
    pc->n = pairs;
    for (int s = 0; s < ns; s++) {
        corr__piece *q = &pc->p[s];
        if (cut(S, fs, s, ls, &q->S, &q->sv, &q->sf) || cut(T, ft, pair[s], lt, &q->T, &q->tv, &q->tf))
            goto nomem;
        int m = 0;
        for (int k = 0; k < n; k++)
            m += ps[k] == s;
        if (!(q->L.src = malloc(sizeof(int) * ((size_t)m + 1))) ||
            !(q->L.tgt = malloc(sizeof(int) * ((size_t)m + 1))))
            goto nomem;
        for (int k = 0; k < n; k++)
            if (ps[k] == s) {
                q->L.src[q->L.n] = ls[in->L->src[k]];
                q->L.tgt[q->L.n++] = lt[in->L->tgt[k]];
            }
        q->in = *in;
        q->in.S = q->S;
        q->in.T = q->T;
        q->in.L = &q->L;
    }
    goto out;
nomem:
    rc = errbuf_set(err, errsz, KIND_ENOMEM, "out of memory splitting the meshes into pieces");
out:
    if (rc)
        corr__pieces_close(pc);
    free(fs);
    free(ft);
    free(vps);
    free(vpt);
    free(ls);
    free(lt);
    free(ps);
    free(pt);
    free(pair);
    return rc;
}

/* Rows of a pair's map (from piece A onto piece B) into the whole map. */
static void put_map(bmap *whole, const bmap *part, const int *av, const int *bf)
{
    for (int i = 0; i < part->n; i++) {
        whole->face[av[i]] = bf[part->face[i]];
        memcpy(whole->w + 3 * (size_t)av[i], part->w + 3 * (size_t)i, 3 * sizeof(double));
    }
}

static void put_points(double *whole, const double *part, int n, const int *av)
{
    for (int i = 0; i < n; i++)
        memcpy(whole + 3 * (size_t)av[i], part + 3 * (size_t)i, 3 * sizeof(double));
}

int corr__pieces_join(const corr_input *in, const corr__pieces *pc, const ectm_result *res,
                      ectm_result *out, char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    int nS = in->S->nv, nT = in->T->nv;
    int q = res[0].Q != NULL, y = res[0].Y != NULL, yt = res[0].Yt != NULL;
    int rp = res[0].rhm_P != NULL, rq = res[0].rhm_Q != NULL;
    if (!(out->P = bmap_new(nS, nT)) || (q && !(out->Q = bmap_new(nT, nS))) ||
        (rp && !(out->rhm_P = bmap_new(nS, nT))) || (rq && !(out->rhm_Q = bmap_new(nT, nS))) ||
        (y && !(out->Y = malloc(sizeof(double) * 3 * (size_t)nS))) ||
        (yt && !(out->Yt = malloc(sizeof(double) * 3 * (size_t)nT)))) {
        ectm_result_close(out);
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory joining the pieces' maps");
    }
    for (int k = 0; k < pc->n; k++) {
        const corr__piece *p = &pc->p[k];
        put_map(out->P, res[k].P, p->sv, p->tf);
        if (q && res[k].Q)
            put_map(out->Q, res[k].Q, p->tv, p->sf);
        if (y && res[k].Y)
            put_points(out->Y, res[k].Y, p->S->nv, p->sv);
        if (rp && res[k].rhm_P)
            put_map(out->rhm_P, res[k].rhm_P, p->sv, p->tf);
        if (rq && res[k].rhm_Q)
            put_map(out->rhm_Q, res[k].rhm_Q, p->tv, p->sf);
        if (yt && res[k].Yt)
            put_points(out->Yt, res[k].Yt, p->T->nv, p->tv);
        out->last = res[k].last;
    }
    return KIND_OK;
}
