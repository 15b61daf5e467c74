/* testrun.c — shell commands from tests, with their output (testrun.h). */
#include "support/testrun.h"
#include "support/harness.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/wait.h>

int testrun(const char *cmd, char *out, size_t outsz)
{
    fflush(NULL);
    FILE *p = popen(cmd, "r");
    if (!p)
        FAILF("popen(%s) failed", cmd);
    size_t n = 0, got;
    char sink[4096];
    while ((got = fread(n + 1 < outsz ? out + n : sink, 1, n + 1 < outsz ? outsz - 1 - n : sizeof sink, p)) > 0)
        if (n + 1 < outsz)
            n += got;
    out[n] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

int testrunf(char *out, size_t outsz, const char *fmt, ...)
{
    char cmd[8192];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof cmd)
        FAILF("command too long: %.200s...", cmd);
    return testrun(cmd, out, outsz);
}
