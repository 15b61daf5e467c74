/* repair_faces.c — faces the optimizer cannot use are removed (repair.h):
 * a face that repeats a vertex or whose area is zero up to rounding (below
 * 1e-12 times its longest edge squared, mesh_check.h's rule) makes the
 * elastic energy's reference metric singular; a second face on the same
 * three vertices makes an edge non-manifold. The first of duplicates stays. */
#include "repair/repair.h"
#include "repair/repair__sort.h"
#include "mesh/mesh_check.h"

#include <stdlib.h>
#include <string.h>

typedef struct tri { int s[3]; int t; } tri;

static int tri_cmp(const void *a, const void *b, void *ctx)
{
    (void)ctx;
    const tri *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->s[k] != y->s[k])
            return x->s[k] < y->s[k] ? -1 : 1;
    return (x->t > y->t) - (x->t < y->t);
}

static void sort3(int *s)
{
    int t;
    if (s[0] > s[1]) { t = s[0]; s[0] = s[1]; s[1] = t; }
    if (s[1] > s[2]) { t = s[1]; s[1] = s[2]; s[2] = t; }
    if (s[0] > s[1]) { t = s[0]; s[0] = s[1]; s[1] = t; }
}

int repair_faces(const double *v, int nv, int *f, int *id, int nf, int *ndegenerate,
                 int *nduplicate)
{
    (void)nv;
    *ndegenerate = *nduplicate = 0;
    unsigned char *drop = calloc((size_t)nf + 1, 1);
    tri *k = malloc(sizeof *k * ((size_t)nf + 1));
    if (!drop || !k) {
        free(drop);
        free(k);
        return -1;
    }
    int nk = 0;
    for (int t = 0; t < nf; t++) {
        int dg;
        mesh_face_area(v, f + 3 * (size_t)t, &dg);
        if (dg) {
            drop[t] = 1;
            ++*ndegenerate;
            continue;
        }
        memcpy(k[nk].s, f + 3 * (size_t)t, sizeof k[nk].s);
        sort3(k[nk].s);
        k[nk++].t = t;
    }
    if (repair__sort(k, (size_t)nk, sizeof *k, tri_cmp, NULL)) {
        free(drop);
        free(k);
        return -1;
    }
    for (int i = 1; i < nk; i++)
        if (memcmp(k[i].s, k[i - 1].s, sizeof k[i].s) == 0) {   /* sorted by face: later one */
            drop[k[i].t] = 1;
            ++*nduplicate;
        }
    int n = 0;
    for (int t = 0; t < nf; t++) {
        if (drop[t])
            continue;
        memmove(f + 3 * (size_t)n, f + 3 * (size_t)t, 3 * sizeof *f);
        id[n++] = id[t];
    }
    free(drop);
    free(k);
    return n;
}
