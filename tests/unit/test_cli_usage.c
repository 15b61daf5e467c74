/* test_cli_usage.c — the real build/meshcorr meeting a mistake on its
 * command line: one line naming it (with the option or command probably
 * meant, the option as the user typed it and its true range) and a pointer
 * to the subcommand's --help, exit 2; outputs refused before any work; and
 * every program's --version printing the one project version. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testrun.h"

#include <string.h>

static char out[1 << 16];

/* Runs `build/meshcorr ARGS` with stdout thrown away: its exit status,
 * stderr in out. */
static int err_of(const char *args)
{
    return testrunf(out, sizeof out, "build/meshcorr %s 2>&1 >/dev/null", args);
}

static int lines(const char *s)
{
    int n = 0;
    for (; *s; s++)
        n += *s == '\n';
    return n;
}

/* The usage error: exactly the line `first` (a part of it) and the pointer
 * to cmd's --help, exit 2. */
static void expect_usage_error(const char *args, const char *first, const char *cmd)
{
    int rc = err_of(args);
    if (rc != 2 || lines(out) != 2)
        FAILF("meshcorr %s: exit %d, %d lines, expected 2 and a two-line usage error:\n%s", args, rc, lines(out),
              out);
    CHECK_STR_HAS(out, first);
    char see[128];
    if (cmd)
        snprintf(see, sizeof see, "\nsee `meshcorr %s --help`\n", cmd);
    else
        snprintf(see, sizeof see, "\nsee `meshcorr --help`\n");
    CHECK_STR_HAS(out, see);
}

TEST(usage_errors_are_one_line_and_a_pointer_to_help_with_the_name_meant)
{
    expect_usage_error("match a.off b.off --iteration 5 --out p.map",
                       "meshcorr match: unknown option --iteration; did you mean --iterations?", "match");
    expect_usage_error("match a.off b.off --beta 5 --out p.map",
                       "unknown option --beta; did you mean --beta0, --beta1 or --beta-ramp?", "match");
    expect_usage_error("match a.off b.off --ouput p.map", "unknown option --ouput; did you mean --out?", "match");
    expect_usage_error("lsit", "meshcorr: unknown command 'lsit'; did you mean list?", NULL);
    expect_usage_error("", "meshcorr: no command given", NULL);
    expect_usage_error("status 3 --jsno", "meshcorr status: unknown option --jsno; did you mean --json?", "status");
    expect_usage_error("eval a b c --json=1", "meshcorr eval: --json takes no value", "eval");
    expect_usage_error("submit a b --landmarks", "meshcorr submit: --landmarks needs a value", "submit");
    expect_usage_error("list --state runing", "--state: 'runing' is not a job state; did you mean RUNNING?", "list");
    expect_usage_error("match a.off --landmarks l.txt --out p.map",
                       "meshcorr match: need SOURCE and TARGET mesh files (1 given)", "match");
    expect_usage_error("watch", "meshcorr watch: need one job id (0 given)", "watch");
    expect_usage_error("params --mark", "unknown option '--mark'; did you mean --markdown?", "params");
    /* the help itself is no error */
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr match --help"), 0);
    CHECK(lines(out) > 20);
}

/* A parameter out of range is named as the option the user typed, with
 * its whole range from the one list (not the wire's name, not u32's). */
TEST(parameter_errors_name_the_option_and_its_true_range)
{
    expect_usage_error("match a.off b.off --landmarks l.txt --out p.map --iterations 0",
                       "meshcorr match: --iterations 0: out of range [1, 1000000]", "match");
    expect_usage_error("match a.off b.off --landmarks l.txt --out p.map --iterations -1",
                       "meshcorr match: --iterations: '-1' is not an integer in [1, 1000000]", "match");
    expect_usage_error("submit a.off b.off --landmarks l.txt --zoomout 20",
                       "meshcorr submit: --zoomout 20: out of range [51, 300]; or 0 = off", "submit");
    CHECK(strstr(out, "params.") == NULL);
    expect_usage_error("match a.off b.off --landmarks l.txt --out p.map --threads 99999",
                       "--threads: '99999' is not an integer in [0, 4096]", "match");
}

/* Outputs are checked before the work: a missing folder or a folder given
 * as a file is refused at once, before the meshes are even read. */
TEST(outputs_into_a_missing_folder_are_refused_before_any_work)
{
    char s[512], t[512], lmk[700], args[4096];
    snprintf(s, sizeof s, "%s", harness_data_path("tosca_hires/Meshes/wolf0.off"));
    snprintf(t, sizeof t, "%s", harness_data_path("tosca_hires/Meshes/wolf1.off"));
    snprintf(lmk, sizeof lmk, "%s", testfile_text("l.txt", "0 0\n100 100\n2000 2000\n4000 4000\n"));
    const char *d = harness_tmpdir();
    snprintf(args, sizeof args, "match %s %s --landmarks %s --out %s/p.map --out-reverse %s/no/such/q.map", s, t,
             lmk, d, d);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr %s 2>&1", args), 2);
    CHECK_STR_HAS(out, "meshcorr match: --out-reverse ");
    CHECK_STR_HAS(out, "/no/such/q.map: the folder ");
    CHECK_STR_HAS(out, "/no/such does not exist");
    CHECK(strstr(out, "stage") == NULL && strstr(out, "rhm") == NULL);       /* nothing ran */
    snprintf(args, sizeof args, "match %s %s --landmarks %s --out %s", s, t, lmk, d);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr %s 2>&1", args), 2);
    CHECK_STR_HAS(out, ": a folder; give a file name");
    snprintf(args, sizeof args, "eval %s %s %s --out-png %s/none/p.png", s, t,
             harness_data_path("ectm_demo_381_390/init_381_to_390.map"), d);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr %s 2>&1", args), 2);
    CHECK_STR_HAS(out, "meshcorr eval: --out-png ");
    CHECK(strstr(out, "conformal") == NULL);
    snprintf(args, sizeof args, "convert %s %s/none/w.ply", s, d);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr %s 2>&1", args), 2);
    CHECK_STR_HAS(out, "/none does not exist");
}

/* meshcorr, meshcorrd, meshcorr-worker and meshcorr-validate print the
 * one version of the file VERSION. */
TEST(every_program_prints_the_one_project_version)
{
    size_t len;
    char *v = (char *)testfile_read("VERSION", &len);
    CHECK(len > 1 && v[len - 1] == '\n');
    v[len - 1] = '\0';
    static const char *const progs[] = {"meshcorr", "meshcorrd", "meshcorr-worker", "meshcorr-validate"};
    for (int i = 0; i < 4; i++) {
        CHECK_INT(testrunf(out, sizeof out, "build/%s --version", progs[i]), 0);
        char want[256];
        snprintf(want, sizeof want, "%s %s\n", progs[i], v);
        if (strcmp(out, want) != 0)
            FAILF("%s --version printed \"%s\", expected \"%s\"", progs[i], out, want);
    }
    free(v);
}
