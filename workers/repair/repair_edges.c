/* repair_edges.c — the sorted half-edge table of repair__edges.h. */
#include "repair/repair__edges.h"
#include "repair/repair__sort.h"

#include <stdlib.h>

static int half_cmp(const void *x, const void *y, void *ctx)
{
    (void)ctx;
    const repair__half *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return (p->t > q->t) - (p->t < q->t);
}

repair__half *repair__edges(const int *f, int nf)
{
    repair__half *h = malloc(sizeof *h * (3 * (size_t)nf + 1));
    if (!h)
        return NULL;
    for (int t = 0; t < nf; t++)
        for (int k = 0; k < 3; k++) {
            int x = f[3 * (size_t)t + k], y = f[3 * (size_t)t + (k + 1) % 3];
            h[3 * (size_t)t + k] = (repair__half){ x < y ? x : y, x < y ? y : x, t, k, x < y };
        }
    if (repair__sort(h, 3 * (size_t)nf, sizeof *h, half_cmp, NULL)) {
        free(h);
        return NULL;
    }
    return h;
}

int repair__edge_end(const repair__half *h, int nh, int i)
{
    int j = i + 1;
    while (j < nh && h[j].a == h[i].a && h[j].b == h[i].b)
        j++;
    return j;
}
