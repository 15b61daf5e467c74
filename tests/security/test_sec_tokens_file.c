/* test_sec_tokens_file.c — the tokens file as an attacker finds it, with
 * the real meshcorrd: `meshcorrd token new` makes random tokens whose
 * hashed line logs in; a plaintext token line, a line over 1023 bytes
 * (whose tail would otherwise be a token of its own), a NUL byte, and a
 * file others can read, its group can write or someone else owns are each
 * refused at start, naming the file and line or the chmod/chown to run;
 * the file may come as a systemd credential ($CREDENTIALS_DIRECTORY); a
 * TCP listener without tokens warns that no TCP user can log in. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testrun.h"
#include "meshcorr.h"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <pwd.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define DAEMON "build/meshcorrd"

static char out[1 << 16];

/* `meshcorrd token new USER [--admin]`: the token and the line it prints. */
static void token_new(const char *user, int admin, char *tok, size_t tsz, char *line, size_t lsz)
{
    int rc = testrunf(out, sizeof out, DAEMON " token new %s%s 2>/dev/null", user, admin ? " --admin" : "");
    CHECK_INT(rc, 0);
    char *nl = strchr(out, '\n');
    CHECK(nl != NULL);
    *nl = '\0';
    CHECK(strlen(out) < tsz && strcspn(nl + 1, "\n") < lsz);
    memcpy(tok, out, strlen(out) + 1);
    size_t n = strcspn(nl + 1, "\n");
    memcpy(line, nl + 1, n);
    line[n] = '\0';
}

/* A tokens file of text at dir/name with mode; its path in path. */
static void write_file(const char *dir, const char *name, const void *text, size_t n, mode_t mode, char *path,
                       size_t psz)
{
    snprintf(path, psz, "%s/%s", dir, name);
    unlink(path);                                 /* a new file: ours, whoever owned the last */
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    CHECK(fd >= 0);
    CHECK(write(fd, text, n) == (ssize_t)n);
    CHECK_INT(fchmod(fd, mode), 0);
    close(fd);
    testdaemon_give(path);                        /* the daemon's user reads it */
}

/* meshcorrd with tokens file path must refuse to start: exit 1, and its
 * stderr (in out) has every one of what[]. */
static void refused_at_start(const char *path, const char *const *what)
{
    char state[600];
    snprintf(state, sizeof state, "%s/state-refused", harness_tmpdir());
    testdaemon_give(harness_tmpdir());
    const char *user = testdaemon_user();
    int rc = testrunf(out, sizeof out, "timeout 10 " DAEMON " %s%s --state-dir %s --listen tcp:127.0.0.1:0 --tokens %s 2>&1",
                      user ? "--user " : "", user ? user : "", state, path);
    printf("  %s\n", strstr(out, "error: ") ? strstr(out, "error: ") : out);
    CHECK_INT(rc, 1);
    for (int i = 0; what[i]; i++)
        CHECK_STR_HAS(out, what[i]);
}

TEST_T(token_new_prints_a_random_token_and_a_hashed_line_that_logs_in, 60)
{
    char t1[128], l1[256], t2[128], l2[256];
    token_new("carol", 0, t1, sizeof t1, l1, sizeof l1);
    token_new("dave", 1, t2, sizeof t2, l2, sizeof l2);
    printf("  token %.6s... line %.16s... %s\n", t1, l1, strchr(l1, ' '));
    CHECK(strncmp(t1, "mc_", 3) == 0 && strlen(t1) >= 3 + 22);     /* >= 128 bits in base64url */
    CHECK(strcmp(t1, t2) != 0);
    CHECK(strncmp(l1, "sha256:", 7) == 0 && strlen(l1) == 7 + 64 + strlen(" carol"));
    CHECK(strstr(l1, t1 + 3) == NULL);                             /* no part of the token in the line */
    CHECK_STR_HAS(l2, " dave admin");
    /* `token hash` gives the same line for a token on standard input */
    CHECK_INT(testrunf(out, sizeof out, "printf '%%s\\n' '%s' | " DAEMON " token hash carol", t1), 0);
    out[strcspn(out, "\n")] = '\0';
    CHECK(strcmp(out, l1) == 0);

    char text[600], path[700];
    snprintf(text, sizeof text, "# made by meshcorrd token new\n%s\n%s\n", l1, l2);
    write_file(harness_tmpdir(), "tokens", text, strlen(text), 0600, path, sizeof path);
    const char *args[] = {"--tokens", path, NULL};
    testdaemon d;
    testdaemon_start(&d, "token_new", args);
    mc_client *c = testdaemon_client(&d, t1);
    CHECK(strcmp(mc_user(c), "carol") == 0 && !mc_is_admin(c));
    mc_close(c);
    c = testdaemon_client(&d, t2);
    CHECK(strcmp(mc_user(c), "dave") == 0 && mc_is_admin(c));
    mc_close(c);
    char err[1024];
    CHECK_INT(mc_connect(d.tcp_addr, l1 + 7, &c, err, sizeof err), MC_EUNAUTHORIZED);   /* the hash is no token */
    CHECK(!testdaemon_log_has(&d, t1) && !testdaemon_log_has(&d, t2));
    testdaemon_stop(&d, SIGTERM);
}

TEST(a_plaintext_token_line_is_refused_naming_the_file_and_line)
{
    char path[700];
    static const char text[] = "# old style\nsecret-token-of-alice alice\n";
    write_file(harness_tmpdir(), "tokens", text, sizeof text - 1, 0600, path, sizeof path);
    char where[800];
    snprintf(where, sizeof where, "%s:2: a plaintext token", path);
    const char *what[] = {where, "meshcorrd token hash", "meshcorrd token new", NULL};
    refused_at_start(path, what);
    CHECK(strstr(out, "secret-token-of-alice") == NULL);
}

/* The line of an admin token hidden past byte 1023 of a comment: read in
 * 1024-byte pieces it would be a line of its own. */
TEST(an_overlong_line_is_an_error_and_never_split_into_a_second_token)
{
    char line[256], text[2048], path[700];
    testdaemon_token_line("mc_hidden-admin", "mallory", 1, line, sizeof line);
    memset(text, 0, sizeof text);
    text[0] = '#';
    memset(text + 1, 'a', 1022);
    snprintf(text + 1023, sizeof text - 1023, "%s\n", line);
    write_file(harness_tmpdir(), "tokens", text, strlen(text), 0600, path, sizeof path);
    char where[800];
    snprintf(where, sizeof where, "%s:1: line of %zu bytes, over the limit of 1023", path, strlen(text) - 1);
    const char *what[] = {where, NULL};
    refused_at_start(path, what);

    static const char nul[] = "# a NUL\n\0sha256:00 x\n";
    write_file(harness_tmpdir(), "tokens-nul", nul, sizeof nul - 1, 0600, path, sizeof path);
    snprintf(where, sizeof where, "%s:2: a NUL byte in the line", path);
    const char *what2[] = {where, NULL};
    refused_at_start(path, what2);
}

TEST(a_tokens_file_others_can_read_or_change_is_refused_with_the_fix)
{
    char line[256], text[512], path[700], chmod_cmd[800];
    testdaemon_token_line("mc_x", "alice", 0, line, sizeof line);
    snprintf(text, sizeof text, "%s\n", line);

    write_file(harness_tmpdir(), "tokens", text, strlen(text), 0644, path, sizeof path);
    snprintf(chmod_cmd, sizeof chmod_cmd, "chmod o-r %s", path);
    const char *world_readable[] = {"mode 0644: readable by others", chmod_cmd, NULL};
    refused_at_start(path, world_readable);

    write_file(harness_tmpdir(), "tokens", text, strlen(text), 0666, path, sizeof path);
    snprintf(chmod_cmd, sizeof chmod_cmd, "chmod g-w,o-rw %s", path);
    const char *writable[] = {"mode 0666: writable by its group and readable and writable by others", chmod_cmd,
                              NULL};
    refused_at_start(path, writable);

    if (geteuid() == 0) {                         /* only root can give a file away */
        write_file(harness_tmpdir(), "tokens", text, strlen(text), 0600, path, sizeof path);
        CHECK_INT(chown(path, 4242, 4242), 0);
        const char *owner[] = {"owned by uid 4242, neither meshcorrd's user", "chown", NULL};
        refused_at_start(path, owner);
    }

    /* the group may read it (root:meshcorr 0640) */
    write_file(harness_tmpdir(), "tokens", text, strlen(text), 0640, path, sizeof path);
    if (geteuid() == 0) {
        struct passwd *pw = getpwnam(TESTDAEMON_USER);
        CHECK(pw != NULL);
        CHECK_INT(chown(path, 0, pw->pw_gid), 0);     /* root's, the daemon's group */
    }
    const char *args[] = {"--tokens", path, NULL};
    testdaemon d;
    testdaemon_start(&d, "mode_0640", args);
    mc_client *c = testdaemon_client(&d, "mc_x");
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* systemd's LoadCredential=tokens:... puts the file in $CREDENTIALS_DIRECTORY:
 * `tokens = ${CREDENTIALS_DIRECTORY}/tokens` finds it, and so does no
 * tokens option at all. */
TEST_T(the_tokens_file_is_found_as_a_systemd_credential, 60)
{
    char dir[600], line[256], text[512], path[700];
    snprintf(dir, sizeof dir, "%s/credentials", harness_tmpdir());
    CHECK_INT(mkdir(dir, 0500 | 0200), 0);
    testdaemon_token_line("mc_credential", "erin", 0, line, sizeof line);
    snprintf(text, sizeof text, "%s\n", line);
    write_file(dir, "tokens", text, strlen(text), 0400, path, sizeof path);
    testdaemon_give(dir);                         /* systemd makes the folder the service user's too */
    CHECK_INT(setenv("CREDENTIALS_DIRECTORY", dir, 1), 0);
    const char *explicit_args[] = {"--tokens", "${CREDENTIALS_DIRECTORY}/tokens", NULL};
    const char *default_args[] = {"--tokens", "", NULL};
    const char *const *runs[] = {explicit_args, default_args};
    for (int i = 0; i < 2; i++) {
        testdaemon d;
        testdaemon_start(&d, i ? "credential_default" : "credential", runs[i]);
        mc_client *c = testdaemon_client(&d, "mc_credential");
        CHECK(strcmp(mc_user(c), "erin") == 0);
        mc_close(c);
        CHECK(testdaemon_log_has(&d, path));
        testdaemon_stop(&d, SIGTERM);
    }
}

TEST_T(a_tcp_listener_without_tokens_warns_that_no_tcp_user_can_log_in, 60)
{
    const char *args[] = {"--tokens", "", NULL};
    testdaemon d;
    testdaemon_start(&d, "no_tokens", args);
    CHECK(testdaemon_log_has(&d, "no TCP user can log in"));
    char err[1024];
    mc_client *c = NULL;
    CHECK_INT(mc_connect(d.tcp_addr, TESTDAEMON_ALICE, &c, err, sizeof err), MC_EUNAUTHORIZED);
    testdaemon_stop(&d, SIGTERM);
}
