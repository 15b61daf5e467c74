/* test_readme.c — every command block of README.md (its ```sh blocks) runs
 * as written, in order, the way a new user runs them: `make demo` in this
 * checkout (it installs packages, so as root, as CI runs), every other
 * block as an unprivileged user (meshcorrd refuses root without --user)
 * with a home of its own, in a copy of the checkout's tracked files and of
 * the programs and libraries `make` built (so nothing is written into this
 * checkout). `make test` is the command running this test and is not run
 * again. A block fails the test when it exits non-zero (each runs under
 * sh -e); what it leaves (the maps, the picture, "the same map", the
 * Python output) is checked too. Each block runs in a session of its own,
 * killed when it ends, so a server it started never outlives it. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testfile.h"
#include "support/testrun.h"

#include <pwd.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define README "README.md"
#define MAX_BLOCKS 32

static char out[1 << 20];

/* The ```sh blocks of text, in order, into blocks[] (pointers into text,
 * each block NUL-terminated in place); their number. */
static int sh_blocks(char *text, char *blocks[MAX_BLOCKS])
{
    int n = 0;
    char *p = text;
    while ((p = strstr(p, "\n```sh\n")) != NULL) {
        p += strlen("\n```sh\n");
        char *end = strstr(p, "\n```\n");
        if (!end)
            FAILF("README.md: a ```sh block without its closing ```");
        end[1] = '\0';
        if (n == MAX_BLOCKS)
            FAILF("README.md: more than %d command blocks", MAX_BLOCKS);
        blocks[n++] = p;
        p = end + 2;
    }
    return n;
}

/* A copy of the checkout's tracked files (as they are in the work tree) and
 * of what `make` built that the README runs, at dir, owned by the user. */
static void copy_checkout(const char *dir)
{
    static const char *const built[] = {"meshcorr", "meshcorrd", "meshcorr-worker", "meshcorr-validate",
                                        "libmeshcorr.so.1", "libmeshcorr.so", "libmeshcorr-engine.so.1",
                                        "libmeshcorr-engine.so", "demo/cow.off", "demo/camel.off"};
    if (testrunf(out, sizeof out, "mkdir -p %s/build/demo && git ls-files -z | xargs -0 cp --parents -t %s 2>&1",
                 dir, dir) != 0)
        FAILF("copying the tracked files: %s", out);
    for (size_t i = 0; i < sizeof built / sizeof built[0]; i++)
        if (testrunf(out, sizeof out, "cp -P build/%s %s/build/%s 2>&1", built[i], dir, built[i]) != 0)
            FAILF("build/%s: %s (run make first)", built[i], out);
    const char *user = testdaemon_user();
    if (user && testrunf(out, sizeof out, "chown -R %s: %s 2>&1", user, dir) != 0)
        FAILF("chown %s: %s", dir, out);
}

/* Runs block (written to file) with sh -e in a session of its own, in dir,
 * as the unprivileged test user when there is one (HOME home, a plain
 * PATH), and kills what is left of the session; its exit status, its
 * output in out. */
static int run_block(const char *file, const char *dir, const char *home, int as_root)
{
    const char *user = as_root ? NULL : testdaemon_user();
    char as[256] = "";
    if (user)
        snprintf(as, sizeof as, "setpriv --reuid=%s --regid=%s --init-groups ", user, user);
    /* the session's leader is the shell: its process group is its pid */
    int rc = testrunf(out, sizeof out,
                      "cd %s && %s env -i HOME=%s PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 "
                      "TERM=dumb setsid -w sh -c 'echo $$ > %s.pid; exec sh -e %s' 2>&1; rc=$?; "
                      "kill -TERM -$(cat %s.pid) 2>/dev/null; sleep 0.2; kill -KILL -$(cat %s.pid) 2>/dev/null; "
                      "exit $rc", dir, as, home, file, file, file, file);
    return rc;
}

TEST_T(every_command_block_of_the_readme_runs_as_written, 3000)
{
    if (geteuid() != 0)
        SKIP("make demo installs Debian packages: run as root, as CI does");
    if (access("build/meshcorrd", X_OK) != 0)
        SKIP("build/meshcorrd not built");
    size_t len;
    char *text = (char *)testfile_read(README, &len);
    char *blocks[MAX_BLOCKS];
    int n = sh_blocks(text, blocks);
    CHECK(n >= 4);
    char cwd[1024], repo[1200], home[1200];
    CHECK(getcwd(cwd, sizeof cwd) != NULL);
    const char *tmp = harness_tmpdir();
    testdaemon_give(tmp);
    snprintf(repo, sizeof repo, "%s/checkout", tmp);
    snprintf(home, sizeof home, "%s/home", tmp);
    CHECK_INT(mkdir(home, 0700), 0);
    testdaemon_give(home);
    int copied = 0, ran_demo = 0;
    for (int i = 0; i < n; i++) {
        const char *b = blocks[i];
        printf("  block %d: %.*s\n", i + 1, (int)strcspn(b, "\n"), b);
        fflush(stdout);
        if (strcmp(b, "make test\n") == 0) {
            printf("  (this test's own runner: not run again)\n");
            continue;
        }
        char file[1300];
        snprintf(file, sizeof file, "%s/block-%d.sh", tmp, i + 1);
        FILE *fp = fopen(file, "w");
        CHECK(fp != NULL);
        fputs(b, fp);
        fclose(fp);
        chmod(file, 0644);
        int demo = strstr(b, "make demo") != NULL;
        if (!demo && !copied) {
            copy_checkout(repo);
            copied = 1;
        }
        int rc = run_block(file, demo ? cwd : repo, home, demo);
        if (rc != 0) {
            fprintf(stderr, "%s", out);
            FAILF("README.md block %d exited %d", i + 1, rc);
        }
        ran_demo |= demo;
        if (strstr(b, "cmp "))
            CHECK_STR_HAS(out, "the same map");
        if (strstr(b, "meshcorr.match"))
            CHECK_STR_HAS(out, "Map(");
    }
    CHECK(ran_demo);
    const char *left[] = {"meshcorr-try/cow-camel.map", "meshcorr-try/cow-camel.png", "meshcorr-try/server.map"};
    for (size_t i = 0; i < sizeof left / sizeof left[0]; i++) {
        char path[1400];
        struct stat st;
        snprintf(path, sizeof path, "%s/%s", home, left[i]);
        if (stat(path, &st) != 0 || st.st_size == 0)
            FAILF("the README's commands left no %s", path);
    }
    free(text);
}
