/* proto_int.h — internals shared by the protocol's .c files; not for users
 * of the codec. */
#ifndef PROTO_INT_H
#define PROTO_INT_H
#include <stddef.h>

/* printf into err[errsz] when err is non-NULL and returns code. protocol/
 * depends on libc only (DESIGN.md), so it does not link workers/util's
 * errbuf_set, which does the same. */
int proto__errf(char *err, size_t errsz, int code, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

#endif
