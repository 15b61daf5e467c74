/* repair__sort.h — the repair steps' sort (repair_sort.c): base (n
 * elements of sz bytes) in the order of cmp(x, y, ctx), stable. 0, or -1
 * without memory (base unchanged). */
#ifndef REPAIR__SORT_H
#define REPAIR__SORT_H
#include <stddef.h>

int repair__sort(void *base, size_t n, size_t sz,
                 int (*cmp)(const void *, const void *, void *), void *ctx);

#endif
