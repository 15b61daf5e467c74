/* errbuf.h — writing a human-readable error detail into a caller-owned
 * buffer. Every module reports detail this way (never a global "last error");
 * the int return code stays the module's own enum. */
#ifndef ERRBUF_H
#define ERRBUF_H
#include <stddef.h>

/* printf into err[errsz] when err is non-NULL; returns `code` so callers can
 * write `return errbuf_set(err, errsz, MESH_EPARSE, "...", ...)`. */
int errbuf_set(char *err, size_t errsz, int code, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

#endif
