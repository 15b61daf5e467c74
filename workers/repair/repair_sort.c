/* repair_sort.c — the sort the repair steps use: a stable bottom-up merge
 * sort with a context for the comparison. Not glibc's qsort: for large
 * arrays it asks the kernel for the machine's memory (sysinfo), a system
 * call the daemon's sandboxed validator does not allow. */
#include "repair/repair__sort.h"

#include <stdlib.h>
#include <string.h>

int repair__sort(void *base, size_t n, size_t sz,
                 int (*cmp)(const void *, const void *, void *), void *ctx)
{
    if (n < 2)
        return 0;
    char *a = base, *b = malloc(n * sz);
    if (!b)
        return -1;
    char *src = a, *dst = b;
    for (size_t w = 1; w < n; w *= 2) {
        for (size_t lo = 0; lo < n; lo += 2 * w) {
            size_t mid = lo + w < n ? lo + w : n, hi = lo + 2 * w < n ? lo + 2 * w : n;
            size_t i = lo, j = mid, k = lo;
            while (i < mid && j < hi) {
                if (cmp(src + j * sz, src + i * sz, ctx) < 0)
                    memcpy(dst + k++ * sz, src + j++ * sz, sz);
                else
                    memcpy(dst + k++ * sz, src + i++ * sz, sz);
            }
            memcpy(dst + k * sz, src + i * sz, (mid - i) * sz);
            k += mid - i;
            memcpy(dst + k * sz, src + j * sz, (hi - j) * sz);
        }
        char *t = src;
        src = dst;
        dst = t;
    }
    if (src != a)
        memcpy(a, src, n * sz);
    free(b);
    return 0;
}
