/* testrun.h — running a shell command from a test (the real build/meshcorr,
 * make, cc) and keeping what it printed. Test code only. */
#ifndef TESTRUN_H
#define TESTRUN_H
#include <stddef.h>

/* Runs cmd with /bin/sh; out gets its stdout (append 2>&1 to cmd for stderr
 * too), truncated to outsz - 1 bytes and NUL-terminated. Returns the exit
 * status, or -1 when it died of a signal. Fails the test when it cannot
 * start the shell. */
int testrun(const char *cmd, char *out, size_t outsz);
/* The same with printf-style arguments forming the command. */
int testrunf(char *out, size_t outsz, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

#endif
