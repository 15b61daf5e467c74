/* harness.c — runs each registered test in a forked child, in a process
 * group of its own (what it leaves running is killed after it), under alarm();
 * prints "PASS|FAIL|SKIP <binary>.<test>" lines. Holds no test logic. */
#include "support/harness.h"
#include "util/ompenv.h"

#include <ftw.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#define HARNESS_MAX_TESTS 512

static struct { const char *name; harness_fn fn; int timeout; } tests[HARNESS_MAX_TESTS];
static int ntests;
static int opt_argc;
static char **opt_argv;

void harness_register(const char *name, harness_fn fn, int timeout_s)
{
    if (ntests == HARNESS_MAX_TESTS) {
        fprintf(stderr, "harness: more than %d tests in one binary\n", HARNESS_MAX_TESTS);
        exit(2);
    }
    tests[ntests].name = name;
    tests[ntests].fn = fn;
    tests[ntests].timeout = timeout_s;
    ntests++;
}

const char *harness_data_dir(void)
{
    static char dir[4096];
    const char *env = getenv("MESHCORR_DATA");
    struct stat st;
    if (env && *env) {
        snprintf(dir, sizeof dir, "%s", env);
    } else {
        snprintf(dir, sizeof dir, "../shared/data");
    }
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return NULL;
    return dir;
}

const char *harness_data_path(const char *rel)
{
    static char path[8192];
    const char *dir = harness_data_dir();
    if (!dir)
        SKIP("../shared/data is absent");
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    return path;
}

const char *harness_option(const char *name)
{
    size_t len = strlen(name);
    for (int a = 1; a < opt_argc; a++) {
        const char *s = opt_argv[a];
        if (strncmp(s, "--", 2) == 0 && strncmp(s + 2, name, len) == 0 && s[2 + len] == '=')
            return s + 3 + len;
    }
    return NULL;
}

int harness_list_has(const char *list, const char *item)
{
    if (!list)
        return 1;
    size_t n = strlen(item);
    for (const char *p = list; (p = strstr(p, item)); p += n)
        if ((p == list || p[-1] == ',') && (p[n] == ',' || p[n] == '\0'))
            return 1;
    return 0;
}

static char tmp_dir[256];

const char *harness_tmpdir(void)
{
    if (!tmp_dir[0]) {
        /* mkdtemp replaces the six X with a unique suffix */
        snprintf(tmp_dir, sizeof tmp_dir, "/tmp/meshcorr-test-XXXXXX");
        if (!mkdtemp(tmp_dir))
            FAILF("mkdtemp failed");
    }
    return tmp_dir;
}

static int remove_entry(const char *path, const struct stat *sb, int flag, struct FTW *ftw)
{
    (void)sb, (void)flag, (void)ftw;
    remove(path);
    return 0;
}

static int run_one(const char *prog, int i)
{
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid < 0) {
        perror("fork");
        return 1;
    }
    if (pid == 0) {
        setpgid(0, 0);
        alarm((unsigned)tests[i].timeout);
        tests[i].fn();
        fflush(stdout);
        /* a passing test's files go with it; a failing one's stay to be read */
        if (tmp_dir[0])
            nftw(tmp_dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
        _exit(0);
    }
    setpgid(pid, pid);               /* the test's own process group (either side may win) */
    int st = 0;
    while (waitpid(pid, &st, 0) < 0) {}
    /* What the test left running (a worker of a daemon that a failed test
     * never stopped: workers outlive their daemon by design) goes with it,
     * so it cannot spin through the tests after it. */
    kill(-pid, SIGKILL);
    if (WIFEXITED(st) && WEXITSTATUS(st) == 0) {
        printf("PASS %s.%s\n", prog, tests[i].name);
        return 0;
    }
    if (WIFEXITED(st) && WEXITSTATUS(st) == HARNESS_SKIP_CODE) {
        printf("SKIP %s.%s\n", prog, tests[i].name);
        return 0;
    }
    if (WIFSIGNALED(st) && WTERMSIG(st) == SIGALRM)
        printf("FAIL %s.%s (timeout after %d s)\n", prog, tests[i].name, tests[i].timeout);
    else if (WIFSIGNALED(st))
        printf("FAIL %s.%s (signal %d)\n", prog, tests[i].name, WTERMSIG(st));
    else
        printf("FAIL %s.%s (exit %d)\n", prog, tests[i].name, WEXITSTATUS(st));
    return 1;
}

int main(int argc, char **argv)
{
    ompenv_ensure_passive(argv);
    const char *prog = strrchr(argv[0], '/') ? strrchr(argv[0], '/') + 1 : argv[0];
    opt_argc = argc;
    opt_argv = argv;
    int failed = 0, ran = 0, named = 0;
    for (int a = 1; a < argc; a++)
        named += strncmp(argv[a], "--", 2) != 0;
    for (int i = 0; i < ntests; i++) {
        if (named) {  /* run only the named tests */
            int want = 0;
            for (int a = 1; a < argc; a++)
                want |= strcmp(argv[a], tests[i].name) == 0;
            if (!want)
                continue;
        }
        failed += run_one(prog, i);
        ran++;
    }
    if (ran == 0 && named) {
        fprintf(stderr, "%s: no test named like that\n", prog);
        return 2;
    }
    return failed ? 1 : 0;
}
