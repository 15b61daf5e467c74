/* dlog.c — meshcorrd's log: one line per event on stderr, lines above the
 * configured level dropped. Each line starts with its syslog priority in the
 * sd-daemon convention (`<3>` error, `<4>` warning, `<6>` info, `<7>` debug)
 * that journald reads; the UTC time follows unless stderr is the journal's
 * stream ($JOURNAL_STREAM), which stamps lines itself. No other output.
 *
 * DESIGN: one event is one line. Messages carry what clients sent (names,
 * labels, users, their messages), so the whole formatted message goes
 * through stresc (workers/util/stresc.h): a newline, an ESC or a `<3>` after
 * a line break can never forge a line or a priority, whichever call site
 * forgot to think of it. */
#include "mcd.h"
#include "util/stresc.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

/* Set on the loop (start, SIGHUP), read by any thread: dlog is called from
 * the thread pool (store_submit) and the dashboard threads too. Each line is
 * one fprintf, which stdio locks, so lines never interleave. */
static int level_max = DLOG_INFO;

void dlog_set_level(int level)
{
    __atomic_store_n(&level_max, level, __ATOMIC_RELAXED);
}

void dlog(int level, const char *fmt, ...)
{
    static const char *names[] = {"error", "warn", "info", "debug"};
    static const int prio[] = {3, 4, 6, 7};
    if (level > __atomic_load_n(&level_max, __ATOMIC_RELAXED))
        return;
    char raw[2048], line[STRESC_SIZE(sizeof raw)];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(raw, sizeof raw, fmt, ap);
    va_end(ap);
    stresc(raw, line, sizeof line);
    if (getenv("JOURNAL_STREAM")) {
        fprintf(stderr, "<%d>%s: %s\n", prio[level], names[level], line);
        return;
    }
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    struct tm tm;
    gmtime_r(&ts.tv_sec, &tm);
    char when[32];
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%S", &tm);
    fprintf(stderr, "<%d>%s.%03ldZ meshcorrd %s: %s\n", prio[level], when, ts.tv_nsec / 1000000,
            names[level], line);
}
