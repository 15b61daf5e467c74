/* fold_repair.c — see fold.h: the region of bad faces, its relaxation with
 * re-projection onto the target, and the accept-if-better rule. */
#include "fold/fold.h"
#include "metric/metric.h"
#include "proj/proj.h"

#include <stdlib.h>
#include <string.h>

/* The fraction of the way to the neighbours' mean a sweep moves an image:
 * short steps keep it near the surface, so the projection does not jump
 * to the far side of a thin part (a paw's sole onto its top). */
#ifndef FOLD__STEP
#define FOLD__STEP 0.5
#endif

const char *fold_strerror(int code)
{
    switch (code) {
#define FOLD_STR(name, val, msg) case name: return msg;
        FOLD_ERRORS(FOLD_STR)
#undef FOLD_STR
    }
    return "unknown fold repair error";
}

void fold_params_init(fold_params *p)
{
    p->rings = 2;
    p->iterations = 400;
}

/* Vertex adjacency of m as CSR (start: nv + 1, nbr): each edge once per
 * side, so an edge shared by two faces is listed twice (a weight of 2 for
 * interior edges, 1 on a boundary: uniform enough). */
static int adjacency(const mesh *m, int **start, int **nbr)
{
    *start = calloc((size_t)m->nv + 1, sizeof(int));
    *nbr = malloc(sizeof(int) * (size_t)m->nf * 6 + 1);
    if (!*start || !*nbr)
        return -1;
    for (int t = 0; t < m->nf; t++)
        for (int k = 0; k < 3; k++)
            (*start)[m->f[3 * t + k] + 1] += 2;
    for (int v = 0; v < m->nv; v++)
        (*start)[v + 1] += (*start)[v];
    int *at = malloc(sizeof(int) * ((size_t)m->nv + 1));
    if (!at)
        return -1;
    memcpy(at, *start, sizeof(int) * (size_t)m->nv);
    for (int t = 0; t < m->nf; t++)
        for (int k = 0; k < 3; k++) {
            int v = m->f[3 * t + k];
            (*nbr)[at[v]++] = m->f[3 * t + (k + 1) % 3];
            (*nbr)[at[v]++] = m->f[3 * t + (k + 2) % 3];
        }
    free(at);
    return 0;
}

int fold_repair(const mesh *S, const mesh *T, const int *fixed, int nfixed,
                const fold_params *p, bmap *P, fold_report *rep)
{
    memset(rep, 0, sizeof *rep);
    if (!S || !T || !P || !p || P->n != S->nv || p->rings < 0 || p->iterations < 1 || nfixed < 0)
        return FOLD_EINVAL;
    int nv = S->nv, nf = S->nf, rc = FOLD_ENOMEM;
    unsigned char *kind = malloc((size_t)nf + 1), *in = calloc((size_t)nv + 1, 1);
    int *start = NULL, *nbr = NULL, *list = NULL, *face = NULL;
    double *Y = NULL, *Yn = NULL, *w = NULL;
    proj_tree *tree = NULL;
    if (!kind || !in)
        goto out;
    int bad = metric_fold_faces(S, T, P, kind);
    if (bad < 0)
        goto out;
    rep->bad_before = rep->bad_after = bad;
    rc = FOLD_OK;
    if (bad == 0)
        goto out;
    rc = FOLD_ENOMEM;
    /* the region: vertices of bad faces, then `rings` rings of faces */
    for (int t = 0; t < nf; t++)
        if (kind[t])
            for (int k = 0; k < 3; k++)
                in[S->f[3 * t + k]] = 1;
    for (int r = 0; r < p->rings; r++) {
        for (int t = 0; t < nf; t++) {
            const int *f = S->f + 3 * t;
            if (in[f[0]] == 1 || in[f[1]] == 1 || in[f[2]] == 1)
                for (int k = 0; k < 3; k++)
                    if (!in[f[k]])
                        in[f[k]] = 2;
        }
        for (int v = 0; v < nv; v++)
            in[v] = in[v] ? 1 : 0;
    }
    for (int k = 0; k < nfixed; k++)
        if (fixed[k] >= 0 && fixed[k] < nv)
            in[fixed[k]] = 0;
    int n = 0;
    if (!(list = malloc(sizeof(int) * (size_t)nv)))
        goto out;
    for (int v = 0; v < nv; v++)
        if (in[v])
            list[n++] = v;
    rep->region = n;
    Y = malloc(sizeof(double) * 3 * (size_t)nv);
    Yn = malloc(sizeof(double) * 3 * (size_t)n + 1);
    face = malloc(sizeof(int) * (size_t)n + 1);
    w = malloc(sizeof(double) * 3 * (size_t)n + 1);
    if (!Y || !Yn || !face || !w || adjacency(S, &start, &nbr))
        goto out;
    if (!(tree = proj_tree_new(T, NULL, 0))) {
        rc = FOLD_EPROJ;
        goto out;
    }
    bmap_apply(P, T->f, T->v, 3, Y);
    for (int k = 0; k < n; k++)
        face[k] = P->face[list[k]];
    for (int it = 0; it < p->iterations; it++) {
        for (int k = 0; k < n; k++) {
            int v = list[k];
            double s[3] = {0, 0, 0};
            for (int q = start[v]; q < start[v + 1]; q++)
                for (int d = 0; d < 3; d++)
                    s[d] += Y[3 * (size_t)nbr[q] + d];
            int deg = start[v + 1] - start[v];
            for (int d = 0; d < 3; d++) {
                double y = Y[3 * (size_t)v + d];
                Yn[3 * k + d] = deg ? y + FOLD__STEP * (s[d] / deg - y) : y;
            }
        }
        if (proj_closest(tree, 3, T->v, 1, n, Yn, face, w, NULL)) {
            rc = FOLD_EPROJ;
            goto out;
        }
        for (int k = 0; k < n; k++) {
            const int *tf = T->f + 3 * face[k];
            for (int d = 0; d < 3; d++)
                Y[3 * (size_t)list[k] + d] = w[3 * k] * T->v[3 * tf[0] + d] +
                                             w[3 * k + 1] * T->v[3 * tf[1] + d] +
                                             w[3 * k + 2] * T->v[3 * tf[2] + d];
        }
    }
    /* accept when better: try the relaxed rows on a copy */
    bmap *R = bmap_new(P->n, P->nt);
    if (!R)
        goto out;
    memcpy(R->face, P->face, sizeof(int) * (size_t)P->n);
    memcpy(R->w, P->w, sizeof(double) * 3 * (size_t)P->n);
    for (int k = 0; k < n; k++) {
        R->face[list[k]] = face[k];
        memcpy(R->w + 3 * (size_t)list[k], w + 3 * k, 3 * sizeof(double));
    }
    int after = metric_fold_faces(S, T, R, kind);
    if (after >= 0 && after < bad) {
        memcpy(P->face, R->face, sizeof(int) * (size_t)P->n);
        memcpy(P->w, R->w, sizeof(double) * 3 * (size_t)P->n);
        rep->bad_after = after;
        rep->accepted = 1;
    }
    bmap_free(R);
    rc = after < 0 ? FOLD_ENOMEM : FOLD_OK;
out:
    proj_tree_free(tree);
    free(kind);
    free(in);
    free(start);
    free(nbr);
    free(list);
    free(face);
    free(Y);
    free(Yn);
    free(w);
    return rc;
}
