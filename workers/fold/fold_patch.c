/* fold_patch.c — the face-set operations of fold__patch.h: growing a set by
 * rings, its components, filling its holes, and the check that it is a
 * disk with its boundary loop in order. */
#include "fold/fold__patch.h"

#include <stdlib.h>
#include <string.h>

void fold__patch_close(fold__patch *p)
{
    free(p->faces);
    free(p->verts);
    memset(p, 0, sizeof *p);
}

void fold__grow(const mesh *m, unsigned char *in, int rings, unsigned char *mark)
{
    for (int r = 0; r < rings; r++) {
        memset(mark, 0, (size_t)m->nv);
        for (int t = 0; t < m->nf; t++)
            if (in[t])
                for (int k = 0; k < 3; k++)
                    mark[m->f[3 * t + k]] = 1;
        for (int t = 0; t < m->nf; t++) {
            const int *f = m->f + 3 * t;
            if (mark[f[0]] || mark[f[1]] || mark[f[2]])
                in[t] = 1;
        }
    }
}

/* The face across the edge of t opposite corner k, or -1. */
static int across(const geo_edges *E, int t, int k)
{
    int e = E->fe[3 * t + k];
    return E->ef[2 * e] == t ? E->ef[2 * e + 1] : E->ef[2 * e];
}

/* Labels the faces with in[t] == want by component (see fold__components). */
static int label(const geo_edges *E, const unsigned char *in, unsigned char want, int *comp,
                 int **sizes)
{
    int nf = E->nf, count = 0, cap = 16;
    int *stack = malloc(sizeof(int) * ((size_t)nf + 1));
    *sizes = malloc(sizeof(int) * (size_t)cap);
    if (!stack || !*sizes) {
        free(stack);
        free(*sizes);
        *sizes = NULL;
        return -1;
    }
    for (int t = 0; t < nf; t++)
        comp[t] = -1;
    for (int s = 0; s < nf; s++) {
        if ((in[s] != 0) != (want != 0) || comp[s] >= 0)
            continue;
        if (count == cap) {
            int *g = realloc(*sizes, sizeof(int) * (size_t)(cap *= 2));
            if (!g) {
                free(stack);
                free(*sizes);
                *sizes = NULL;
                return -1;
            }
            *sizes = g;
        }
        int n = 0, top = 0;
        stack[top++] = s;
        comp[s] = count;
        while (top) {
            int t = stack[--top];
            n++;
            for (int k = 0; k < 3; k++) {
                int u = across(E, t, k);
                if (u >= 0 && comp[u] < 0 && (in[u] != 0) == (want != 0)) {
                    comp[u] = count;
                    stack[top++] = u;
                }
            }
        }
        (*sizes)[count++] = n;
    }
    free(stack);
    return count;
}

int fold__components(const geo_edges *E, const unsigned char *in, int *comp)
{
    int *sizes;
    int n = label(E, in, 1, comp, &sizes);
    free(sizes);
    return n;
}

int fold__fill_holes(const geo_edges *E, unsigned char *in)
{
    int *comp = malloc(sizeof(int) * ((size_t)E->nf + 1)), *sizes = NULL;
    int n = comp ? label(E, in, 0, comp, &sizes) : -1;
    if (n < 0) {
        free(comp);
        return -1;
    }
    int big = 0;
    for (int c = 1; c < n; c++)
        if (sizes[c] > sizes[big])
            big = c;
    int size = 0;
    for (int t = 0; t < E->nf; t++) {
        if (comp[t] >= 0 && comp[t] != big)
            in[t] = 1;
        size += in[t] != 0;
    }
    free(comp);
    free(sizes);
    return size;
}

int fold__disk(const mesh *m, const geo_edges *E, const unsigned char *in, int *loc,
               fold__patch *out)
{
    memset(out, 0, sizeof *out);
    int nf = 0, nv = 0, nbe = 0, rc = -1;
    for (int t = 0; t < m->nf; t++)
        nf += in[t] != 0;
    out->faces = malloc(sizeof(int) * ((size_t)nf + 1));
    out->verts = malloc(sizeof(int) * ((size_t)nf * 3 + 1));
    int *next = malloc(sizeof(int) * ((size_t)nf * 3 + 1));
    int *order = malloc(sizeof(int) * ((size_t)nf * 3 + 1));
    if (!out->faces || !out->verts || !next || !order)
        goto fail;
    out->nf = nf;
    nf = 0;
    for (int t = 0; t < m->nf; t++) {
        if (!in[t])
            continue;
        out->faces[nf++] = t;
        for (int k = 0; k < 3; k++) {
            int v = m->f[3 * t + k];
            if (loc[v] < 0) {
                loc[v] = nv;
                out->verts[nv] = v;
                next[nv++] = -1;
            }
        }
    }
    out->nv = nv;
    rc = 1;
    /* boundary edges, directed as their face runs: a -> b */
    for (int q = 0; q < nf; q++) {
        int t = out->faces[q];
        for (int k = 0; k < 3; k++) {
            int u = across(E, t, k);
            if (u >= 0 && in[u])
                continue;
            int a = loc[m->f[3 * t + (k + 1) % 3]], b = loc[m->f[3 * t + (k + 2) % 3]];
            if (next[a] >= 0)
                goto fail;                 /* a pinched vertex */
            next[a] = b;
            nbe++;
        }
    }
    /* V - E + F = 1 with E = (3F + boundary) / 2, and a single loop */
    if (nbe == 0 || (3 * nf + nbe) % 2 || nv - (3 * nf + nbe) / 2 + nf != 1)
        goto fail;
    int first = -1;
    for (int i = 0; i < nv && first < 0; i++)
        if (next[i] >= 0)
            first = i;
    int nb = 0;
    for (int i = first; nb <= nbe; i = next[i]) {
        order[nb++] = i;
        if (next[i] == first)
            break;
        if (next[i] < 0)
            goto fail;
    }
    if (nb != nbe)
        goto fail;
    /* the loop first, then the inner vertices */
    unsigned char *onb = calloc((size_t)nv + 1, 1);
    if (!onb) {
        rc = -1;
        goto fail;
    }
    for (int i = 0; i < nb; i++)
        onb[order[i]] = 1;
    int n = nb;
    for (int i = 0; i < nv; i++)
        if (!onb[i])
            order[n++] = i;
    free(onb);
    for (int i = 0; i < nv; i++)
        next[i] = out->verts[order[i]];
    memcpy(out->verts, next, sizeof(int) * (size_t)nv);
    out->nb = nb;
    rc = 0;
fail:
    for (int i = 0; i < nv; i++)
        loc[out->verts[i]] = -1;
    free(next);
    free(order);
    if (rc)
        fold__patch_close(out);
    return rc;
}
