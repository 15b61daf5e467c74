/* fold_repair.c — see fold.h: the repair's entry, its parameters and
 * errors, and the rounds of passes (fold_pass.c) over what is left. */
#include "fold/fold__repair.h"
#include "fold/fold__kinds.h"
#include "geo/geo_area.h"

#include <stdlib.h>
#include <string.h>

/* The passes run again from `rings` while a round of them lowers the
 * count, this many rounds at most: a region refused at first (its chart
 * crossed a neighbour's folds) is often taken once the neighbour is
 * repaired. */
#define FOLD__ROUNDS 3

const char *fold_strerror(int code)
{
    switch (code) { FOLD_ERRORS(ERRLIST_CASE) }
    return "unknown fold repair error";
}

void fold_params_init(fold_params *p)
{
    p->rings = 2;
    p->passes = 4;
}

int fold_repair(const mesh *S, const mesh *T, const int *fixed, int nfixed,
                const fold_params *p, bmap *P, fold_report *rep)
{
    memset(rep, 0, sizeof *rep);
    if (!fold__map_ok(S, T, P) || !p || p->rings < 0 || p->passes < 1 || nfixed < 0)
        return FOLD_EINVAL;
    fold__ctx c = { .S = S, .T = T, .area_S = geo_total_area(S), .area_T = geo_total_area(T) };
    int rc = FOLD_ENOMEM;
    unsigned char *kind = malloc((size_t)S->nf + 1), *fx = calloc((size_t)S->nv + 1, 1);
    c.keep = malloc((size_t)S->nv + 1);
    c.tin = malloc((size_t)T->nf + 1);
    c.tmark = malloc((size_t)T->nv + 1);
    c.tcomp = malloc(sizeof(int) * ((size_t)T->nf + 1));
    c.tloc = malloc(sizeof(int) * ((size_t)T->nv + 1));
    c.sloc = malloc(sizeof(int) * ((size_t)S->nv + 1));
    c.R = bmap_new(P->n, P->nt);
    c.badv = malloc((size_t)S->nv + 1);
    c.tubed = calloc((size_t)S->nv + 1, 1);
    if (!c.badv || !c.tubed || !kind || !fx || !c.keep || !c.tin || !c.tmark || !c.tcomp || !c.tloc || !c.sloc || !c.R)
        goto out;
    for (int v = 0; v < T->nv; v++)
        c.tloc[v] = -1;
    for (int v = 0; v < S->nv; v++)
        c.sloc[v] = -1;
    for (int k = 0; k < nfixed; k++)
        if (fixed[k] >= 0 && fixed[k] < S->nv)
            fx[fixed[k]] = 1;
    c.fixed = fx;
    memcpy(c.R->face, P->face, sizeof(int) * (size_t)P->n);
    memcpy(c.R->w, P->w, sizeof(double) * 3 * (size_t)P->n);
    int bad;
    if ((rc = fold__open(S, T, P, kind, &c.ES, &c.ET, rep, &bad)) || bad == 0)
        goto out;
    for (int round = 0; round < FOLD__ROUNDS && bad > 0; round++) {
        int start = bad;
        for (int k = 0; k < p->passes && bad > 0; k++)
            if ((bad = fold__pass(&c, p->rings + 2 * k, kind, bad, rep)) < 0) {
                rc = FOLD_ENOMEM;
                goto out;
            }
        if (bad >= start)
            break;
    }
    if (bad < rep->bad_before) {
        memcpy(P->face, c.R->face, sizeof(int) * (size_t)P->n);
        memcpy(P->w, c.R->w, sizeof(double) * 3 * (size_t)P->n);
        rep->bad_after = bad;
        rep->accepted = 1;
    }
out:
    geo_edges_close(&c.ES);
    geo_edges_close(&c.ET);
    bmap_free(c.R);
    free(c.badv);
    free(c.tubed);
    free(kind);
    free(fx);
    free(c.keep);
    free(c.tin);
    free(c.tmark);
    free(c.tcomp);
    free(c.tloc);
    free(c.sloc);
    return rc;
}
