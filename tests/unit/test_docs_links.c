/* test_docs_links.c — the documents point at things that exist: in
 * README.md, every .md file of docs/, daemon/README.md, workers/WORKER.md and
 * protocol/PROTOCOL.md, every relative link target ([text](path), resolved
 * from the document's folder) and every backticked repository path
 * (`daemon/srv.c`, `workers/corr/`, or a glob: a path that starts with
 * one of the repository's top folders) names a file
 * or folder of this checkout; every backticked `function_name()` of
 * docs/architecture.md is defined somewhere in the sources (a C definition,
 * a macro, or a Python def). Fenced code blocks are not read: they hold
 * commands, whose paths test_readme runs. Each test prints every stale
 * reference as FILE:LINE before it fails. */
#include "support/harness.h"

#include <ctype.h>
#include <dirent.h>
#include <glob.h>
#include <string.h>
#include <sys/stat.h>

#define MAX_DOCS 64
#define MAX_PATH 512

/* The folders a backticked path must start with to be checked as one. */
static const char *const top_folders[] = {"client-c/", "daemon/", "deploy/", "docs/",
                                          "protocol/", "tests/",  "workers/"};
/* The folders whose sources define the functions architecture.md names. */
static const char *const source_folders[] = {"client-c", "daemon", "protocol", "workers", "tests"};

/* path's whole contents, NUL-terminated, malloc()ed; NULL when unreadable. */
static char *slurp(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return NULL;
    char *b = NULL;
    if (fseek(fp, 0, SEEK_END) == 0) {
        long n = ftell(fp);
        rewind(fp);
        if (n >= 0 && (b = malloc((size_t)n + 1)) && fread(b, 1, (size_t)n, fp) == (size_t)n)
            b[n] = '\0';
        else {
            free(b);
            b = NULL;
        }
    }
    fclose(fp);
    return b;
}

/* The documents this test reads, into docs[] (malloc()ed paths); their number. */
static int doc_list(char *docs[MAX_DOCS])
{
    static const char *const fixed[] = {"README.md", "daemon/README.md", "workers/WORKER.md",
                                        "protocol/PROTOCOL.md"};
    int n = 0;
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++)
        docs[n++] = strdup(fixed[i]);
    DIR *d = opendir("docs");
    if (!d)
        FAILF("docs/: cannot open (run the tests from the repository's root)");
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t l = strlen(e->d_name);
        if (l > 3 && strcmp(e->d_name + l - 3, ".md") == 0) {
            CHECK(n < MAX_DOCS);
            char p[MAX_PATH];
            snprintf(p, sizeof p, "docs/%s", e->d_name);
            docs[n++] = strdup(p);
        }
    }
    closedir(d);
    return n;
}

/* text with its fenced code blocks (``` ... ```) blanked to spaces, so
 * offsets (and line numbers) stay those of the file. */
static void blank_fences(char *text)
{
    int in = 0;
    for (char *line = text; *line;) {
        char *end = strchr(line, '\n');
        size_t len = end ? (size_t)(end - line) : strlen(line);
        const char *s = line;
        while (*s == ' ')
            s++;
        int fence = strncmp(s, "```", 3) == 0;
        if (in || fence)
            memset(line, ' ', len);
        if (fence)
            in = !in;
        if (!end)
            break;
        line = end + 1;
    }
}

static int line_of(const char *text, const char *at)
{
    int n = 1;
    for (const char *p = text; p < at; p++)
        n += *p == '\n';
    return n;
}

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* 1 when the pattern (a path or a glob) names something in the checkout. */
static int path_found(const char *path)
{
    if (!strpbrk(path, "*?["))
        return exists(path);
    glob_t g;
    int rc = glob(path, 0, NULL, &g);
    globfree(&g);
    return rc == 0;
}

/* Calls fn(doc, text, start, len) for every inline code span of text (fences blanked). */
typedef int (*span_fn)(const char *doc, const char *text, const char *s, size_t n);
static int each_span(const char *doc, const char *text, span_fn fn)
{
    int bad = 0;
    for (const char *p = text; (p = strchr(p, '`'));) {
        size_t ticks = strspn(p, "`");
        const char *s = p + ticks, *q = s;
        for (; (q = strchr(q, '`')); q += strspn(q, "`"))
            if (strspn(q, "`") == ticks)
                break;
        if (!q)
            break;
        bad += fn(doc, text, s, (size_t)(q - s));
        p = q + ticks;
    }
    return bad;
}

static int check_path_span(const char *doc, const char *text, const char *s, size_t n)
{
    char path[MAX_PATH];
    if (n == 0 || n >= sizeof path)
        return 0;
    memcpy(path, s, n);
    path[n] = '\0';
    if (strpbrk(path, " \t\n<>$") || strstr(path, "..."))
        return 0;            /* a command line or a placeholder such as <FILE>: not a path */
    int top = 0;
    for (size_t i = 0; i < sizeof top_folders / sizeof top_folders[0]; i++)
        top |= strncmp(path, top_folders[i], strlen(top_folders[i])) == 0;
    if (!top)
        return 0;
    char *colon = strchr(path, ':');                  /* daemon/srv.c:473 */
    if (colon && isdigit((unsigned char)colon[1]))
        *colon = '\0';
    if (path_found(path))
        return 0;
    printf("  %s:%d: `%s` names no file of the repository\n", doc, line_of(text, s), path);
    return 1;
}

static int check_links(const char *doc, const char *text)
{
    char dir[MAX_PATH];
    snprintf(dir, sizeof dir, "%s", doc);
    char *slash = strrchr(dir, '/');
    if (slash)
        slash[1] = '\0';
    else
        dir[0] = '\0';
    int bad = 0;
    for (const char *p = text; (p = strstr(p, "](")); p += 2) {
        const char *t = p + 2;
        size_t n = strcspn(t, ")# \n");
        if (n == 0 || memchr(t, ':', n))              /* an anchor, a URL, mailto: */
            continue;
        char path[2 * MAX_PATH];
        snprintf(path, sizeof path, "%s%.*s", dir, (int)n, t);
        if (!exists(path)) {
            printf("  %s:%d: link target %.*s (%s) does not exist\n", doc, line_of(text, p), (int)n, t, path);
            bad++;
        }
    }
    return bad;
}

/* Each document's text, read and fenced blocks blanked, through fn; the
 * number of stale references found. */
static int each_doc(int (*fn)(const char *doc, const char *text))
{
    char *docs[MAX_DOCS];
    int n = doc_list(docs), bad = 0;
    for (int i = 0; i < n; i++) {
        char *text = slurp(docs[i]);
        if (!text)
            FAILF("%s: cannot read", docs[i]);
        blank_fences(text);
        bad += fn(docs[i], text);
        free(text);
        free(docs[i]);
    }
    return bad;
}

static int check_paths(const char *doc, const char *text) { return each_span(doc, text, check_path_span); }

TEST(relative_links_of_the_docs_name_existing_files)
{
    int bad = each_doc(check_links);
    fflush(stdout);
    if (bad)
        FAILF("%d link(s) to files that do not exist (listed above)", bad);
}

TEST(backticked_repository_paths_of_the_docs_exist)
{
    int bad = each_doc(check_paths);
    fflush(stdout);
    if (bad)
        FAILF("%d backticked path(s) that name no file (listed above)", bad);
}

/* ---- the functions architecture.md names ---------------------------------- */

typedef struct names {
    char **v;
    size_t n, cap;
} names;

static void names_add(names *s, const char *name, size_t len)
{
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 1024;
        s->v = realloc(s->v, s->cap * sizeof *s->v);
        CHECK(s->v);
    }
    CHECK((s->v[s->n++] = strndup(name, len)));
}

static int is_ident(int c) { return isalnum(c) || c == '_'; }

/* The names text defines: NAME(...) followed by '{' (a C function),
 * "#define NAME(" and "def NAME(". */
static void definitions(const char *text, names *out)
{
    for (const char *p = strchr(text, '('); p; p = strchr(p + 1, '(')) {
        const char *b = p;
        while (b > text && is_ident((unsigned char)b[-1]))
            b--;
        if (b == p || isdigit((unsigned char)*b))
            continue;
        const char *pre = b;
        while (pre > text && (pre[-1] == ' ' || pre[-1] == '\t'))
            pre--;
        if ((pre - text >= 7 && strncmp(pre - 7, "#define", 7) == 0) ||
            (pre - text >= 3 && strncmp(pre - 3, "def", 3) == 0)) {
            names_add(out, b, (size_t)(p - b));
            continue;
        }
        int depth = 0;
        const char *q = p;
        for (int k = 0; *q && k < 4000; q++, k++) {
            depth += (*q == '(') - (*q == ')');
            if (depth == 0)
                break;
        }
        if (*q != ')')
            continue;
        q++;
        for (;;) {                                    /* blanks and comments before the body */
            while (isspace((unsigned char)*q))
                q++;
            if (q[0] == '/' && q[1] == '*' && strstr(q + 2, "*/"))
                q = strstr(q + 2, "*/") + 2;
            else if (q[0] == '/' && q[1] == '/' && strchr(q, '\n'))
                q = strchr(q, '\n');
            else
                break;
        }
        if (*q == '{')
            names_add(out, b, (size_t)(p - b));
    }
}

static int has_ext(const char *name, const char *const *exts)
{
    size_t l = strlen(name);
    for (; *exts; exts++) {
        size_t e = strlen(*exts);
        if (l > e && strcmp(name + l - e, *exts) == 0)
            return 1;
    }
    return 0;
}

static void scan_tree(const char *dir, names *out)
{
    static const char *const exts[] = {".c", ".cpp", ".h", ".cl", ".py", NULL};
    DIR *d = opendir(dir);
    if (!d)
        FAILF("%s: cannot open", dir);
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.')
            continue;
        char path[MAX_PATH];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        struct stat st;
        if (lstat(path, &st))
            continue;
        if (S_ISDIR(st.st_mode)) {
            scan_tree(path, out);
        } else if (S_ISREG(st.st_mode) && has_ext(e->d_name, exts)) {
            char *text = slurp(path);
            if (!text)
                FAILF("%s: cannot read", path);
            definitions(text, out);
            free(text);
        }
    }
    closedir(d);
}

static int cmp_name(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

static names defined;

static int check_function_span(const char *doc, const char *text, const char *s, size_t n)
{
    if (n < 3 || strncmp(s + n - 2, "()", 2) != 0)
        return 0;
    for (size_t i = 0; i < n - 2; i++)
        if (!is_ident((unsigned char)s[i]))
            return 0;
    char name[256];
    if (n - 2 >= sizeof name)
        return 0;
    memcpy(name, s, n - 2);
    name[n - 2] = '\0';
    const char *key = name;
    if (bsearch(&key, defined.v, defined.n, sizeof *defined.v, cmp_name))
        return 0;
    printf("  %s:%d: `%s()` is defined nowhere in %s, %s, %s, %s or %s\n", doc, line_of(text, s), name,
           source_folders[0], source_folders[1], source_folders[2], source_folders[3], source_folders[4]);
    return 1;
}

TEST(functions_architecture_md_names_are_defined)
{
    for (size_t i = 0; i < sizeof source_folders / sizeof source_folders[0]; i++)
        scan_tree(source_folders[i], &defined);
    qsort(defined.v, defined.n, sizeof *defined.v, cmp_name);
    const char *doc = "docs/architecture.md";
    char *text = slurp(doc);
    if (!text)
        FAILF("%s: cannot read", doc);
    blank_fences(text);
    int checked = 0;
    for (const char *p = text; (p = strstr(p, "()`")); p++)
        checked++;
    if (checked < 20)
        FAILF("%s names only %d functions as `name()`: the tour names the functions it passes through", doc,
              checked);
    int bad = each_span(doc, text, check_function_span);
    free(text);
    fflush(stdout);
    if (bad)
        FAILF("%d function name(s) of %s defined nowhere (listed above)", bad, doc);
}
