/* errbuf.c — see errbuf.h. No allocation, no global state. */
#include "util/errbuf.h"
#include <stdarg.h>
#include <stdio.h>

int errbuf_set(char *err, size_t errsz, int code, const char *fmt, ...)
{
    if (err && errsz) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errsz, fmt, ap);
        va_end(ap);
    }
    return code;
}
