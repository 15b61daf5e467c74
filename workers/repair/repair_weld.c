/* repair_weld.c — vertices at the same position become one (repair.h): an
 * unwelded seam, a mesh exported face by face. Only identical positions
 * are welded: a tolerance would also close narrow gaps the shape has on
 * purpose. Whether a weld stays is repair_split's decision (a weld that
 * makes a pinch is split again). */
#include "repair/repair.h"
#include "repair/repair__sort.h"

#include <stdlib.h>

static int by_position(const void *a, const void *b, void *ctx)
{
    const double *weld_v = ctx;
    int i = *(const int *)a, j = *(const int *)b;
    int c = 0;
    for (int k = 0; k < 3 && !c; k++) {
        double x = weld_v[3 * (size_t)i + k], y = weld_v[3 * (size_t)j + k];
        c = x < y ? -1 : x > y;
    }
    return c ? c : (i > j) - (i < j);
}

int repair_weld(const mesh *u, int *rep)
{
    int *order = malloc(sizeof *order * ((size_t)u->nv + 1));
    if (!order)
        return -1;
    for (int i = 0; i < u->nv; i++)
        order[i] = rep[i] = i;
    if (repair__sort(order, (size_t)u->nv, sizeof *order, by_position, u->v)) {
        free(order);
        return -1;
    }
    int welded = 0;
    for (int a = 0; a < u->nv;) {
        int b = a + 1;
        const double *p = u->v + 3 * (size_t)order[a];
        while (b < u->nv && p[0] == u->v[3 * (size_t)order[b]] &&
               p[1] == u->v[3 * (size_t)order[b] + 1] && p[2] == u->v[3 * (size_t)order[b] + 2])
            b++;
        for (int k = a + 1; k < b; k++) {     /* order[a] is the group's smallest index */
            rep[order[k]] = order[a];
            welded++;
        }
        a = b;
    }
    free(order);
    return welded;
}
