/* test_sec_unit.c — deploy/meshcorrd.service as systemd judges it: its
 * overall exposure under `systemd-analyze security --offline=true` is at
 * most 3.0, and its SystemCallFilter= lets through every call the workers'
 * and the validator's own allow-lists let through (the strictest answer of
 * all filters wins, so one the unit refuses would fail every job). Both
 * skipped where systemd-analyze is missing. */
#include "support/harness.h"
#include "support/testrun.h"
#include "sandbox/sandbox.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define UNIT "deploy/meshcorrd.service"
#define UNIT_MAX_EXPOSURE 3.0

static void need_analyze(void)
{
    char out[256];
    if (testrun("systemd-analyze --version >/dev/null 2>&1", out, sizeof out) != 0)
        SKIP("systemd-analyze is not installed (deploy/install-deps.sh: systemd)");
}

TEST(unit_exposure_is_at_most_3_0)
{
    need_analyze();
    static char out[1 << 16];
    int rc = testrunf(out, sizeof out, "systemd-analyze security --offline=true --no-pager %s 2>&1", UNIT);
    const char *at = strstr(out, "Overall exposure level for meshcorrd.service:");
    if (!at)
        FAILF("systemd-analyze security (exit %d) printed no overall exposure:\n%s", rc, out);
    double level = strtod(at + strlen("Overall exposure level for meshcorrd.service:"), NULL);
    printf("  %s: overall exposure %.1f (at most %.1f)\n", UNIT, level, UNIT_MAX_EXPOSURE);
    if (!(level <= UNIT_MAX_EXPOSURE))
        FAILF("exposure %.1f > %.1f; what counts:\n%s", level, UNIT_MAX_EXPOSURE, out);
}

/* A set of system call names. */
typedef struct names {
    char **v;
    size_t n, cap;
} names;

static int names_has(const names *s, const char *name)
{
    for (size_t i = 0; i < s->n; i++)
        if (strcmp(s->v[i], name) == 0)
            return 1;
    return 0;
}

static void names_add(names *s, const char *name)
{
    if (names_has(s, name))
        return;
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 256;
        s->v = realloc(s->v, s->cap * sizeof *s->v);
        CHECK(s->v != NULL);
    }
    s->v[s->n] = strdup(name);
    CHECK(s->v[s->n] != NULL);
    s->n++;
}

/* Adds the calls of item (a call, or an @group systemd-analyze expands,
 * groups inside it too) to s. */
static void expand(names *s, const char *item)
{
    if (item[0] != '@') {
        names_add(s, item);
        return;
    }
    static char out[1 << 16];
    if (testrunf(out, sizeof out, "systemd-analyze syscall-filter --no-pager '%s' 2>&1", item) != 0)
        FAILF("systemd-analyze syscall-filter %s: %s", item, out);
    char *copy = strdup(out), *save = NULL;
    CHECK(copy != NULL);
    int first = 1;
    for (char *line = strtok_r(copy, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        line += strspn(line, " \t");
        if (first || !line[0] || line[0] == '#') {   /* the group's own name, its description */
            first = 0;
            continue;
        }
        expand(s, line);
    }
    free(copy);
}

/* The unit's SystemCallFilter= lines: allowed minus denied (~ lines). */
static void unit_filter(names *allowed, names *denied)
{
    FILE *fp = fopen(UNIT, "r");
    CHECK(fp != NULL);
    char line[1024];
    while (fgets(line, sizeof line, fp)) {
        if (strncmp(line, "SystemCallFilter=", 17) != 0)
            continue;
        char *v = line + 17, *save = NULL;
        names *into = allowed;
        if (*v == '~') {
            into = denied;
            v++;
        }
        for (char *t = strtok_r(v, " \t\n", &save); t; t = strtok_r(NULL, " \t\n", &save))
            expand(into, t);
    }
    fclose(fp);
}

typedef struct check_ctx {
    const names *allowed, *denied;
    const char *profile;
    int missing;
} check_ctx;

static void check_call(void *ctx, const char *name)
{
    check_ctx *c = ctx;
    if (names_has(c->allowed, name) && !names_has(c->denied, name))
        return;
    fprintf(stderr, "  %s refuses %s, which the %s profile needs\n", UNIT, name, c->profile);
    c->missing++;
}

TEST(unit_system_call_filter_lets_through_every_call_of_the_workers_sandbox)
{
    need_analyze();
    names allowed = {0}, denied = {0};
    unit_filter(&allowed, &denied);
    CHECK(allowed.n > 100);
    check_ctx c = {&allowed, &denied, "", 0};
    static const sbx_profile profiles[] = {SBX_VALIDATOR, SBX_WORKER, SBX_WORKER_OPENCL};
    for (size_t i = 0; i < sizeof profiles / sizeof profiles[0]; i++) {
        c.profile = sbx_profile_name(profiles[i]);
        CHECK_INT(sbx_calls(profiles[i], check_call, &c), 0);
        check_call(&c, "prctl");        /* sbx_enter: no_new_privs ... */
        check_call(&c, "seccomp");      /* ... and the filter */
    }
    if (c.missing)
        FAILF("%d call(s) of the sandbox profiles refused by the unit's SystemCallFilter=", c.missing);
    for (size_t i = 0; i < allowed.n; i++)
        free(allowed.v[i]);
    for (size_t i = 0; i < denied.n; i++)
        free(denied.v[i]);
    free(allowed.v);
    free(denied.v);
}
