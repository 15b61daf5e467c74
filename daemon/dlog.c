/* dlog.c — meshcorrd's log: one line per event on stderr, with the time and
 * a level; lines above the configured level are dropped. No other output. */
#include "mcd.h"

#include <stdarg.h>
#include <stdio.h>
#include <time.h>

static int level_max = DLOG_INFO;

void dlog_set_level(int level)
{
    level_max = level;
}

void dlog(int level, const char *fmt, ...)
{
    static const char *names[] = {"error", "warn", "info", "debug"};
    if (level > level_max)
        return;
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    struct tm tm;
    gmtime_r(&ts.tv_sec, &tm);
    char when[32];
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%S", &tm);
    char line[2048];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    fprintf(stderr, "%s.%03ldZ meshcorrd %s: %s\n", when, ts.tv_nsec / 1000000, names[level], line);
}
