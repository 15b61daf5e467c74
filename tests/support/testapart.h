/* testapart.h — runs one piece of work in a child process and brings back
 * its plain-data result through a pipe, so a crash or an engine error ends
 * that piece only (benchmarks run each mesh pair this way). Test code only.
 *
 * fn(arg, out) fills out (size bytes, plain data: no pointers). When the
 * child dies or writes less than size bytes, out is zeroed and the reason
 * ("crashed (signal 11)", "failed (exit 1; message above)") is written into
 * why (whysz bytes) and testapart_run returns -1; else 0. The child gets
 * SIGKILL when the parent dies (the harness's timeout ends it too). */
#ifndef TESTAPART_H
#define TESTAPART_H
#include <stddef.h>

int testapart_run(void (*fn)(const void *arg, void *out), const void *arg, void *out,
                  size_t size, char *why, size_t whysz);

#endif
