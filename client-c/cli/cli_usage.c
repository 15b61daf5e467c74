/* cli_usage.c — what every subcommand does with a mistake on its command
 * line (see cli.h): one line naming it, a suggestion when a name was
 * mistyped, and a pointer to the subcommand's --help instead of the whole
 * help; and outputs checked before any work starts. */
#include "cli/cli.h"

#include <errno.h>
#include <libgen.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define CLI_SUGGEST_MAX 4          /* names listed when a prefix fits several */
#define CLI_NAME_MAX 64            /* bytes of a name compared for suggestions */

static void vsay(const char *cmd, const char *fmt, va_list ap)
{
    fprintf(stderr, "meshcorr%s%s: ", cmd && *cmd ? " " : "", cmd ? cmd : "");
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
}

int cli_usage_see(const char *cmd)
{
    if (cmd && *cmd)
        fprintf(stderr, "see `meshcorr %s --help`\n", cmd);
    else
        fprintf(stderr, "see `meshcorr --help`\n");
    return CLI_EXIT_USAGE;
}

/* The error line alone: cli_getopt's callers add the pointer to --help. */
static void say(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void say(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsay(cmd, fmt, ap);
    va_end(ap);
}

int cli_usage_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsay(cmd, fmt, ap);
    va_end(ap);
    return cli_usage_see(cmd);
}

/* Optimal string alignment distance (Levenshtein with transpositions) of
 * a and b, both at most CLI_NAME_MAX bytes. */
static int distance(const char *a, const char *b)
{
    size_t n = strlen(a), m = strlen(b);
    if (n > CLI_NAME_MAX || m > CLI_NAME_MAX)
        return CLI_NAME_MAX;
    int d[CLI_NAME_MAX + 1][CLI_NAME_MAX + 1];
    for (size_t i = 0; i <= n; i++)
        d[i][0] = (int)i;
    for (size_t j = 0; j <= m; j++)
        d[0][j] = (int)j;
    for (size_t i = 1; i <= n; i++)
        for (size_t j = 1; j <= m; j++) {
            int cost = a[i - 1] != b[j - 1];
            int v = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < v)
                v = d[i][j - 1] + 1;
            if (d[i - 1][j - 1] + cost < v)
                v = d[i - 1][j - 1] + cost;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] && d[i - 2][j - 2] + 1 < v)
                v = d[i - 2][j - 2] + 1;
            d[i][j] = v;
        }
    return d[n][m];
}

const char *cli_suggest(const char *word, const char *const *names, int n, const char *prefix, char *buf,
                        size_t sz)
{
    buf[0] = '\0';
    size_t wl = strlen(word);
    int nprefix = 0;
    for (int i = 0; i < n; i++)
        nprefix += wl > 0 && strncmp(names[i], word, wl) == 0;
    if (nprefix > 0) {              /* the start of one or more names */
        size_t o = 0;
        int k = 0;
        for (int i = 0; i < n && k < CLI_SUGGEST_MAX && o < sz; i++) {
            if (strncmp(names[i], word, wl) != 0)
                continue;
            const char *sep = k == 0 ? "" : (k == nprefix - 1 || k == CLI_SUGGEST_MAX - 1) ? " or " : ", ";
            o += (size_t)snprintf(buf + o, sz - o, "%s%s%s", sep, prefix, names[i]);
            k++;
        }
        return buf;
    }
    /* else the nearest name, if near enough to be a slip of the keys */
    int best = -1, bd = 0, limit = wl <= 3 ? 1 : wl <= 6 ? 2 : 3;
    for (int i = 0; i < n; i++) {
        int dd = distance(word, names[i]);
        if (dd <= limit && (best < 0 || dd < bd)) {
            best = i;
            bd = dd;
        }
    }
    if (best < 0)
        return NULL;
    snprintf(buf, sz, "%s%s", prefix, names[best]);
    return buf;
}

/* The option word of argv as typed, without "--" and "=value". */
static void typed_name(const char *tok, char *name, size_t sz)
{
    if (strncmp(tok, "--", 2) == 0)
        tok += 2;
    snprintf(name, sz, "%.*s", (int)strcspn(tok, "="), tok);
}

static void suggest_option(const char *cmd, const char *what, const char *name, const struct option *opts)
{
    const char *names[256];
    int n = 0;
    for (; opts[n].name && n < 256; n++)
        names[n] = opts[n].name;
    char buf[512];
    const char *s = cli_suggest(name, names, n, "--", buf, sizeof buf);
    say(cmd, "%s --%s%s%s%s", what, name, s ? "; did you mean " : "", s ? s : "", s ? "?" : "");
}

int cli_getopt(const char *cmd, int argc, char **argv, const struct option *opts)
{
    opterr = 0;
    int idx = -1;
    int c = getopt_long(argc, argv, ":h", opts, &idx);
    if (c == -1)
        return -1;
    /* the word the option came in: argv[optind - 1], or before its
     * separate argument */
    const char *tok = optind > 0 && optind - 1 < argc ? argv[optind - 1] : "";
    if (c != '?' && c != ':' && idx >= 0 && opts[idx].has_arg == required_argument && optarg &&
        optarg == argv[optind - 1] && optind >= 2)
        tok = argv[optind - 2];
    char name[CLI_NAME_MAX + 1];
    typed_name(tok, name, sizeof name);
    if (c == ':') {
        say(cmd, "%s needs a value", tok);
        return '?';
    }
    if (c == '?') {
        if (optopt && optopt < 256 && strncmp(tok, "--", 2) != 0) {
            say(cmd, "unknown option -%c", optopt);
            return '?';
        }
        for (int i = 0; opts[i].name; i++)   /* a flag given a value */
            if (strcmp(opts[i].name, name) == 0 && opts[i].has_arg == no_argument) {
                say(cmd, "--%s takes no value", name);
                return '?';
            }
        suggest_option(cmd, "unknown option", name, opts);
        return '?';
    }
    /* getopt_long takes a unique start of a name as the name; we do not,
     * so that a new option never changes what an old command line means */
    if (idx >= 0 && strncmp(tok, "--", 2) == 0 && strcmp(name, opts[idx].name) != 0) {
        say(cmd, "unknown option --%s; did you mean --%s?", name, opts[idx].name);
        return '?';
    }
    return c;
}

int cli_output_check(const char *cmd, const char *opt, const char *path)
{
    struct stat st;
    if (!path)
        return 0;
    if (!*path) {
        fprintf(stderr, "meshcorr %s: %s: an empty file name\n", cmd, opt);
        return -1;
    }
    if (stat(path, &st) == 0) {
        if (S_ISDIR(st.st_mode)) {
            fprintf(stderr, "meshcorr %s: %s %s: a folder; give a file name\n", cmd, opt, path);
            return -1;
        }
        if (access(path, W_OK) != 0) {
            fprintf(stderr, "meshcorr %s: %s %s: cannot write: %s\n", cmd, opt, path, strerror(errno));
            return -1;
        }
        return 0;
    }
    if (errno != ENOENT) {
        fprintf(stderr, "meshcorr %s: %s %s: %s\n", cmd, opt, path, strerror(errno));
        return -1;
    }
    char *copy = strdup(path);
    if (!copy) {
        fprintf(stderr, "meshcorr %s: out of memory\n", cmd);
        return -1;
    }
    const char *dir = dirname(copy);
    int rc = 0;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "meshcorr %s: %s %s: the folder %s does not exist\n", cmd, opt, path, dir);
        rc = -1;
    } else if (access(dir, W_OK | X_OK) != 0) {
        fprintf(stderr, "meshcorr %s: %s %s: cannot write in the folder %s: %s\n", cmd, opt, path, dir,
                strerror(errno));
        rc = -1;
    }
    free(copy);
    return rc;
}

int cli_out_stage(const char *cmd, const char *arg, const char **rhm, const char **rhm_rev)
{
    const char *eq = strchr(arg, '=');
    if (!eq || !eq[1])
        return cli_usage_error(cmd, "--out-stage: '%s' is not NAME=FILE (rhm=P.map, "
                               "rhm-reverse=Q.map)", arg), -1;
    size_t n = (size_t)(eq - arg);
    if (n == 3 && !strncmp(arg, "rhm", 3))
        *rhm = eq + 1;
    else if (n == 11 && !strncmp(arg, "rhm-reverse", 11))
        *rhm_rev = eq + 1;
    else
        return cli_usage_error(cmd, "--out-stage: '%.*s' is not a stage's map (rhm, rhm-reverse)",
                               (int)n, arg), -1;
    return 0;
}
