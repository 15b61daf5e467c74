/* test_man.c — the man pages in deploy/man: each passes `mandoc -T lint`
 * and renders with `man -l` without a warning; every option of each
 * `meshcorr` subcommand's --help and of `meshcorrd --help` is in its page
 * (and meshcorr(1) names no option the program lacks); meshcorrd.conf(5)
 * has every daemon option and every key of deploy/meshcorrd.conf;
 * libmeshcorr(3) names every function, type and constant of meshcorr.h;
 * meshcorr(1)'s job parameter list is `meshcorr params --mdoc`. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testrun.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#define MESHCORR "build/meshcorr"
#define MESHCORRD "build/meshcorrd"

static const char *const pages[] = {"deploy/man/meshcorr.1", "deploy/man/libmeshcorr.3",
                                    "deploy/man/meshcorrd.conf.5", "deploy/man/meshcorrd.8"};
#define NPAGES (sizeof pages / sizeof pages[0])

static char out[1 << 18];

/* page rendered as plain text by mandoc (overstrike bold and underline
 * removed), malloc()ed. */
static char *render(const char *page)
{
    char *t = malloc(sizeof out);
    CHECK(t != NULL);
    if (testrunf(t, sizeof out, "mandoc -T ascii %s", page) != 0)
        FAILF("mandoc -T ascii %s failed (install mandoc: deploy/install-deps.sh)", page);
    char *w = t;
    for (const char *r = t; *r; r++) {
        if (r[1] == '\b' && r[2]) {
            r++;
            continue;
        }
        *w++ = *r;
    }
    *w = '\0';
    return t;
}

static int optchar(int c) { return isalnum(c) || c == '-'; }

/* 1 when text holds word (an option "--x" or a name) with no option or
 * name character on either side. */
static int has_word(const char *text, const char *word, size_t n)
{
    for (const char *p = text; (p = strstr(p, word)); p++) {
        int before = p > text && (optchar((unsigned char)p[-1]) || p[-1] == '_');
        int after = optchar((unsigned char)p[n]) || p[n] == '_';
        if (!before && !after && strlen(word) == n)
            return 1;
    }
    return 0;
}

/* Calls fn(ctx, "--opt") for every long option named in text. */
static void each_option(const char *text, void (*fn)(void *, const char *), void *ctx)
{
    for (const char *p = text; (p = strstr(p, "--")); ) {
        if ((p > text && optchar((unsigned char)p[-1])) || !islower((unsigned char)p[2])) {
            p += 2;
            continue;
        }
        size_t n = 2;
        while (optchar((unsigned char)p[n]))
            n++;
        while (p[n - 1] == '-')
            n--;
        char opt[64];
        CHECK(n < sizeof opt);
        memcpy(opt, p, n);
        opt[n] = '\0';
        fn(ctx, opt);
        p += n;
    }
}

/* The lines of rendered text from the one that is exactly `head` up to the
 * next heading at its indentation or less (sections start in column 0,
 * subsections in column 3, text further in), malloc()ed, or NULL. */
static char *section(const char *text, const char *head)
{
    size_t hl = strlen(head), indent = strspn(head, " ");
    for (const char *p = text; *p; p += strcspn(p, "\n") + (p[strcspn(p, "\n")] == '\n')) {
        if (strncmp(p, head, hl) != 0 || p[hl] != '\n')
            continue;
        const char *e = p + hl + 1;
        while (*e) {
            size_t in = strspn(e, " ");
            if (in <= indent && e[in] != '\n' && e[in])
                break;
            e += strcspn(e, "\n");
            e += *e == '\n';
        }
        char *s = strndup(p, (size_t)(e - p));
        CHECK(s != NULL);
        return s;
    }
    return NULL;
}

TEST(every_page_passes_mandoc_lint)
{
    for (size_t i = 0; i < NPAGES; i++) {
        int rc = testrunf(out, sizeof out, "mandoc -T lint -W warning %s 2>&1", pages[i]);
        if (rc != 0 || out[0])
            FAILF("mandoc -T lint -W warning %s (exit %d; install mandoc: deploy/install-deps.sh):\n%s",
                  pages[i], rc, out);
    }
}

TEST(every_page_renders_with_man_without_warnings)
{
    for (size_t i = 0; i < NPAGES; i++) {
        /* stderr only: the page itself goes to /dev/null. C.UTF-8 is in
         * every Debian (a missing locale would warn of its own). */
        int rc = testrunf(out, sizeof out, "LC_ALL=C.UTF-8 MANWIDTH=80 man --warnings=all -l %s 2>&1 >/dev/null",
                          pages[i]);
        if (rc != 0 || out[0])
            FAILF("man --warnings=all -l %s (exit %d; install man-db):\n%s", pages[i], rc, out);
        CHECK_INT(testrunf(out, sizeof out, "LC_ALL=C.UTF-8 MANWIDTH=80 man -l %s 2>/dev/null", pages[i]), 0);
        CHECK(strlen(out) > 500);
    }
}

typedef struct opt_check {
    const char *what;                 /* whose help, for the message */
    const char *const *places;        /* rendered texts, NULL-terminated */
    int missing;
} opt_check;

static void need_option(void *ctx, const char *opt)
{
    opt_check *c = ctx;
    for (int i = 0; c->places[i]; i++)
        if (has_word(c->places[i], opt, strlen(opt)))
            return;
    fprintf(stderr, "  %s: %s is not in the man page\n", c->what, opt);
    c->missing++;
}

/* The subcommands `meshcorr --help` lists, into names; their count. */
static int subcommands(char names[32][16])
{
    static char help[1 << 14];
    CHECK_INT(testrun(MESHCORR " --help", help, sizeof help), 0);
    const char *p = strstr(help, "commands:\n");
    CHECK(p != NULL);
    int n = 0;
    for (p = strchr(p, '\n') + 1; strncmp(p, "  ", 2) == 0 && n < 32; p = strchr(p, '\n') + 1) {
        CHECK(sscanf(p, " %15s", names[n]) == 1);
        n++;
    }
    CHECK(n >= 10);
    return n;
}

TEST(meshcorr_page_has_every_option_of_each_help_in_its_section)
{
    char *page = render("deploy/man/meshcorr.1");
    char *server = section(page, "SERVER OPTIONS"), *job = section(page, "JOB OPTIONS");
    CHECK(server && job);
    CHECK_INT(testrun(MESHCORR " --help", out, sizeof out), 0);
    const char *const top[] = {page, NULL};
    opt_check c = {"meshcorr --help", top, 0};
    each_option(out, need_option, &c);
    char names[32][16];
    int n = subcommands(names);
    for (int i = 0; i < n; i++) {
        char head[600], what[600];
        snprintf(head, sizeof head, "   meshcorr %s", names[i]);
        char *sec = section(page, head);
        if (!sec)
            FAILF("meshcorr(1) has no subsection \"meshcorr %s\"", names[i]);
        if (testrunf(out, sizeof out, MESHCORR " %s --help", names[i]) != 0)
            FAILF("meshcorr %s --help did not exit 0:\n%s", names[i], out);
        snprintf(what, sizeof what, "meshcorr %s --help", names[i]);
        const char *const places[] = {sec, server, job, NULL};
        c.what = what;
        c.places = places;
        each_option(out, need_option, &c);
        free(sec);
    }
    if (c.missing)
        FAILF("%d option(s) of --help missing from deploy/man/meshcorr.1", c.missing);
    free(server);
    free(job);
    free(page);
}

static void known_option(void *ctx, const char *opt)
{
    opt_check *c = ctx;
    if (!has_word(c->places[0], opt, strlen(opt))) {
        fprintf(stderr, "  meshcorr(1) names %s, which no --help of meshcorr lists\n", opt);
        c->missing++;
    }
}

TEST(meshcorr_page_names_no_option_the_program_lacks)
{
    char *page = render("deploy/man/meshcorr.1");
    static char all[1 << 18];
    size_t len = 0;
    CHECK_INT(testrun(MESHCORR " --help", all, sizeof all), 0);
    len = strlen(all);
    char names[32][16];
    int n = subcommands(names);
    for (int i = 0; i < n; i++) {
        CHECK_INT(testrunf(out, sizeof out, MESHCORR " %s --help", names[i]), 0);
        CHECK(len + strlen(out) < sizeof all);
        strcpy(all + len, out);
        len += strlen(out);
    }
    const char *const places[] = {all, NULL};
    opt_check c = {"meshcorr(1)", places, 0};
    each_option(page, known_option, &c);
    if (c.missing)
        FAILF("deploy/man/meshcorr.1 names %d option(s) meshcorr does not have", c.missing);
    free(page);
}

TEST(meshcorr_page_holds_the_parameter_list)
{
    size_t len;
    char *page = (char *)testfile_read("deploy/man/meshcorr.1", &len);
    page = realloc(page, len + 1);
    page[len] = '\0';
    const char *begin = strstr(page, ".\\\" params:begin"), *end = strstr(page, ".\\\" params:end");
    CHECK(begin && end && begin < end);
    begin = strchr(begin, '\n') + 1;
    CHECK_INT(testrun(MESHCORR " params --mdoc", out, sizeof out), 0);
    if ((size_t)(end - begin) != strlen(out) || memcmp(begin, out, strlen(out)) != 0)
        FAILF("meshcorr(1)'s job parameter list is not `meshcorr params --mdoc`: run make doc-params");
    free(page);
}

TEST(meshcorrd_page_has_every_option_of_its_help)
{
    char *page = render("deploy/man/meshcorrd.8");
    CHECK_INT(testrun(MESHCORRD " --help", out, sizeof out), 0);
    const char *const places[] = {page, NULL};
    opt_check c = {"meshcorrd --help", places, 0};
    each_option(out, need_option, &c);
    if (c.missing)
        FAILF("%d option(s) of meshcorrd --help missing from deploy/man/meshcorrd.8", c.missing);
    free(page);
}

/* 1 when the mdoc source documents key as `.It Ic key`. */
static int conf_page_has(const char *src, const char *key)
{
    char want[96];
    snprintf(want, sizeof want, "\n.It Ic %s", key);
    for (const char *p = src; (p = strstr(p, want)); p++)
        if (p[strlen(want)] == ' ' || p[strlen(want)] == '\n')
            return 1;
    return 0;
}

TEST(conf_page_has_every_daemon_option_and_every_key_of_the_example)
{
    size_t len;
    char *src = (char *)testfile_read("deploy/man/meshcorrd.conf.5", &len);
    src = realloc(src, len + 1);
    src[len] = '\0';
    static char help[1 << 16];
    CHECK_INT(testrun(MESHCORRD " --help", help, sizeof help), 0);
    int missing = 0, keys = 0;
    for (const char *p = strstr(help, "\n  --"); p; p = strstr(p + 1, "\n  --")) {
        char key[64];
        CHECK(sscanf(p + 5, "%63s", key) == 1);
        keys++;
        if (!conf_page_has(src, key)) {
            fprintf(stderr, "  meshcorrd --%s has no `.It Ic %s` in meshcorrd.conf(5)\n", key, key);
            missing++;
        }
    }
    CHECK(keys >= 30);
    /* deploy/meshcorrd.conf's keys, set or commented out */
    char *conf = (char *)testfile_read("deploy/meshcorrd.conf", &len);
    conf = realloc(conf, len + 1);
    conf[len] = '\0';
    int ckeys = 0;
    for (char *line = strtok(conf, "\n"); line; line = strtok(NULL, "\n")) {
        char key[64], eq;
        if (sscanf(line, "#%63[a-z-] %c", key, &eq) != 2 && sscanf(line, "%63[a-z-] %c", key, &eq) != 2)
            continue;
        if (eq != '=')
            continue;
        ckeys++;
        char opt[80];
        snprintf(opt, sizeof opt, "--%s", key);
        if (!has_word(help, opt, strlen(opt))) {
            fprintf(stderr, "  deploy/meshcorrd.conf: '%s' is no option of meshcorrd\n", key);
            missing++;
        }
        if (!conf_page_has(src, key)) {
            fprintf(stderr, "  deploy/meshcorrd.conf: '%s' is not in meshcorrd.conf(5)\n", key);
            missing++;
        }
    }
    CHECK(ckeys >= 20);
    if (missing)
        FAILF("%d key(s) missing", missing);
    free(conf);
    free(src);
}

TEST(libmeshcorr_page_names_everything_meshcorr_h_declares)
{
    size_t len;
    char *h = (char *)testfile_read("client-c/meshcorr.h", &len);
    h = realloc(h, len + 1);
    h[len] = '\0';
    /* comments out: only what the header declares counts */
    for (char *p = h; (p = strstr(p, "/*"));) {
        char *e = strstr(p + 2, "*/");
        CHECK(e != NULL);
        memset(p, ' ', (size_t)(e + 2 - p));
    }
    char *page = render("deploy/man/libmeshcorr.3");
    int missing = 0, names = 0;
    for (char *p = h; *p; p++) {
        if ((strncmp(p, "mc_", 3) != 0 && strncmp(p, "MC_", 3) != 0) || (p > h && (isalnum((unsigned char)p[-1]) || p[-1] == '_')))
            continue;
        size_t n = 3;
        while (isalnum((unsigned char)p[n]) || p[n] == '_')
            n++;
        char name[80];
        CHECK(n < sizeof name);
        memcpy(name, p, n);
        name[n] = '\0';
        p += n - 1;
        /* the header's own helper macros for the parameter members */
        if (!strncmp(name, "MC_PARAM_", 9) || !strcmp(name, "MC_ENUM"))
            continue;
        names++;
        if (!has_word(page, name, n)) {
            fprintf(stderr, "  %s is not in libmeshcorr(3)\n", name);
            missing++;
        }
    }
    CHECK(names >= 60);
    if (missing)
        FAILF("%d name(s) of client-c/meshcorr.h missing from deploy/man/libmeshcorr.3", missing);
    free(page);
    free(h);
}
