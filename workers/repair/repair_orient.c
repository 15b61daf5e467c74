/* repair_orient.c — faces turned against their neighbours are flipped
 * (repair.h): a breadth-first walk over each piece through its edges with
 * two faces decides which faces must turn so that every such edge is run
 * once each way; the piece keeps the orientation of the larger part of its
 * area. A one-sided piece (a Moebius band) keeps edges run the same way;
 * repair_split cuts them. */
#include "repair/repair.h"
#include "mesh/mesh_check.h"
#include "repair/repair__edges.h"

#include <stdlib.h>

int repair_orient(const double *v, int nv, int *f, int nf, int *conflicts)
{
    (void)nv;
    *conflicts = 0;
    int nh = 3 * nf;
    repair__half *h = repair__edges(f, nf);
    int *nbr = malloc(sizeof *nbr * ((size_t)nh + 1));      /* per face edge: the face across */
    int *same = malloc(sizeof *same * ((size_t)nh + 1));    /* 1: both faces run it one way */
    signed char *flip = malloc((size_t)nf + 1);             /* -1 unvisited, 0, 1 */
    int *queue = malloc(sizeof *queue * ((size_t)nf + 1));
    int flipped = -1;
    if (!h || !nbr || !same || !flip || !queue)
        goto out;
    for (int e = 0; e < nh; e++)
        nbr[e] = -1;
    for (int i = 0; i < nh;) {
        int j = repair__edge_end(h, nh, i);
        if (j - i == 2) {
            int s = h[i].fwd == h[i + 1].fwd;
            nbr[3 * h[i].t + h[i].k] = h[i + 1].t;
            nbr[3 * h[i + 1].t + h[i + 1].k] = h[i].t;
            same[3 * h[i].t + h[i].k] = same[3 * h[i + 1].t + h[i + 1].k] = s;
        }
        i = j;
    }
    for (int t = 0; t < nf; t++)
        flip[t] = -1;
    flipped = 0;
    for (int t0 = 0; t0 < nf; t0++) {
        if (flip[t0] >= 0)
            continue;
        int head = 0, tail = 0;
        double kept = 0, turned = 0;
        flip[t0] = 0;
        queue[tail++] = t0;
        while (head < tail) {
            int t = queue[head++];
            if (flip[t])
                turned += mesh_face_area(v, f + 3 * (size_t)t, NULL);
            else
                kept += mesh_face_area(v, f + 3 * (size_t)t, NULL);
            for (int k = 0; k < 3; k++) {
                int s = nbr[3 * t + k];
                if (s < 0)
                    continue;
                int want = flip[t] ^ same[3 * t + k];
                if (flip[s] < 0) {
                    flip[s] = (signed char)want;
                    queue[tail++] = s;
                } else if (flip[s] != want && s > t) {
                    ++*conflicts;
                }
            }
        }
        int invert = turned > kept;
        for (int i = 0; i < tail; i++) {
            int t = queue[i];
            if (flip[t] ^ invert) {
                int *c = f + 3 * (size_t)t, x = c[1];
                c[1] = c[2];
                c[2] = x;
                flipped++;
            }
        }
    }
out:
    free(h);
    free(nbr);
    free(same);
    free(flip);
    free(queue);
    return flipped;
}
