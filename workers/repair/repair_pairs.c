/* repair_pairs.c — which piece of one mesh goes with which piece of the
 * other, by the landmarks (repair.h): a piece whose landmarks all land on
 * one piece of the other mesh, enough of them, and no other piece's. */
#include "repair/repair.h"

#include <stdlib.h>

int repair_pieces_pair(const int *ps, const int *pt, int n, int ns, int nt, int min, int *pair)
{
    int *to = malloc(sizeof *to * ((size_t)ns + 1)), *cnt = calloc((size_t)ns + 1, sizeof *cnt);
    int *claims = calloc((size_t)nt + 1, sizeof *claims);
    if (!to || !cnt || !claims) {
        free(to);
        free(cnt);
        free(claims);
        return -1;
    }
    for (int s = 0; s < ns; s++)
        to[s] = -2;                             /* no landmark yet */
    for (int k = 0; k < n; k++) {
        int s = ps[k], t = pt[k];
        if (s < 0 || t < 0)
            continue;
        if (to[s] == -2)
            to[s] = t;
        else if (to[s] != t)
            to[s] = -1;                         /* landmarks on two pieces: no pair */
        cnt[s]++;
    }
    for (int s = 0; s < ns; s++)
        if (to[s] >= 0 && cnt[s] >= min)
            claims[to[s]]++;
    int pairs = 0;
    for (int s = 0; s < ns; s++) {
        pair[s] = to[s] >= 0 && cnt[s] >= min && claims[to[s]] == 1 ? to[s] : -1;
        pairs += pair[s] >= 0;
    }
    free(to);
    free(cnt);
    free(claims);
    return pairs;
}
