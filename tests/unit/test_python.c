/* test_python.c — the Python package meshcorr (client-c/python) against a
 * real meshcorrd: each test starts the daemon (Unix socket and TCP with
 * tokens), writes the icosphere pair and runs one case of
 * tests/python/test_meshcorr.py with Debian's /usr/bin/python3 over
 * build/libmeshcorr.so.1. A case fails when the script exits non-zero, and
 * the test fails when the daemon died or exits non-zero. Last, `make
 * install PREFIX=tmp` (no root) and README's example script run from
 * PYTHONPATH against the installed library, whose ldd is slim. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testfile.h"
#include "support/testldd.h"
#include "support/testmesh.h"
#include "support/testrun.h"
#include "mesh/mesh.h"

#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define PYTHON "/usr/bin/python3"

static char out[1 << 16];

/* SKIPs without Debian's python3 and python3-numpy (deploy/install-deps.sh). */
static void need_python(void)
{
    if (testrun(PYTHON " -c 'import numpy' 2>&1", out, sizeof out) != 0)
        SKIP(PYTHON " with numpy is not installed (apt-get install python3-numpy)");
}

/* The icosphere pair of test_cli_remote (the target an ellipsoid, a little
 * bent) and its 6 identity landmarks, named in MESHCORR_TEST_* for the script. */
static void write_inputs(const testdaemon *d)
{
    mesh *S = testmesh_icosphere(2), *T = testmesh_icosphere(2);
    CHECK(S && T);
    for (int i = 0; i < T->nv; i++) {
        double *x = &T->v[3 * i];
        x[0] *= 1.3;
        x[2] += 0.15 * x[0] * x[0];
    }
    char src[600], tgt[600], err[512];
    snprintf(src, sizeof src, "%s/s.off", harness_tmpdir());
    snprintf(tgt, sizeof tgt, "%s/t.off", harness_tmpdir());
    CHECK_INT(mesh_write(src, S, err, sizeof err), 0);
    CHECK_INT(mesh_write(tgt, T, err, sizeof err), 0);
    mesh_free(S);
    mesh_free(T);
    setenv("MESHCORR_TEST_SRC", src, 1);
    setenv("MESHCORR_TEST_TGT", tgt, 1);
    setenv("MESHCORR_TEST_LMK", testfile_text("pairs.lmk", "0 0\n1 1\n2 2\n3 3\n4 4\n5 5\n"), 1);
    setenv("MESHCORR_TEST_DIR", harness_tmpdir(), 1);
    setenv("MESHCORR_TEST_UNIX", d->unix_addr, 1);
    setenv("MESHCORR_TEST_TCP", d->tcp_addr, 1);
    setenv("MESHCORR_TEST_ALICE", TESTDAEMON_ALICE, 1);
    setenv("MESHCORR_TEST_BOB", TESTDAEMON_BOB, 1);
    unsetenv("MESHCORR_SERVER");
    unsetenv("MESHCORR_TOKEN");
}

static void run_case(const char *name)
{
    testdaemon_need_worker();
    need_python();
    testdaemon d;
    testdaemon_start(&d, "py", NULL);
    write_inputs(&d);
    int rc = testrunf(out, sizeof out,
                      "MESHCORR_LIB=build/libmeshcorr.so.1 PYTHONPATH=client-c/python PYTHONDONTWRITEBYTECODE=1 " PYTHON
                      " tests/python/test_meshcorr.py %s 2>&1", name);
    if (rc != 0) {
        fprintf(stderr, "%s", out);
        FAILF("test_meshcorr.py %s exited %d", name, rc);
    }
    char done[128];
    snprintf(done, sizeof done, "ok %s\n", name);
    CHECK_STR_HAS(out, done);
    testdaemon_stop(&d, SIGTERM);          /* fails unless the daemon exits 0 */
}

TEST_T(submit_from_files_watch_and_result_match_the_cli, 120)
{
    run_case("files_watch_result_same_as_cli");
}

TEST_T(submit_from_numpy_arrays_gives_the_map_of_the_files, 120)
{
    run_case("arrays_same_map_as_files");
}

TEST_T(cancel_while_watching_ends_the_job_cancelled, 120)
{
    run_case("cancel");
}

TEST_T(over_tcp_other_users_jobs_are_invisible_and_a_bad_token_is_refused, 120)
{
    run_case("tokens_over_tcp");
}

TEST_T(bad_mesh_landmarks_and_parameters_are_refused_with_the_message, 120)
{
    run_case("bad_input_refused");
}

TEST_T(a_vertex_map_file_refined_by_ddm_then_ectm_streams_the_ddm_stage, 120)
{
    run_case("vertex_map_refined_by_ddm_then_ectm");
}

TEST_T(a_job_failing_numerically_has_the_numeric_error_as_its_error, 120)
{
    run_case("failed_job_error_is_its_kind");
}

TEST_T(progress_dicts_have_the_clis_names_and_the_whole_jobs_fraction, 120)
{
    run_case("progress_keys_are_the_clis");
}

TEST_T(installed_package_runs_the_readme_example_against_meshcorrd, 240)
{
    testdaemon_need_worker();
    need_python();
    char *readme = (char *)testfile_read("README.md", &(size_t){0});
    CHECK_STR_HAS(readme, "make install-python PREFIX=");
    CHECK_STR_HAS(readme, "client-c/python/examples/submit_pair.py");
    free(readme);
    char dest[600], repo[512], path[800], site[800];
    CHECK(getcwd(repo, sizeof repo));
    snprintf(dest, sizeof dest, "%s/inst", harness_tmpdir());
    /* the whole install into a folder of one's own, as a laptop user does:
     * no root (the config goes to PREFIX/etc) */
    int rc = testrunf(out, sizeof out, "env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s install PREFIX=%s 2>&1",
                      dest);
    if (rc)
        FAILF("make install PREFIX=%s failed (%d):\n%s", dest, rc, out);
    snprintf(path, sizeof path, "%s/etc/meshcorr/meshcorrd.conf", dest);
    CHECK(access(path, R_OK) == 0);
    snprintf(path, sizeof path, "%s/lib/libmeshcorr.so.1", dest);
    testldd_check_slim(path);
    CHECK_INT(testrunf(out, sizeof out, "ls -d %s/lib/python3*/dist-packages", dest), 0);
    snprintf(site, sizeof site, "%.*s", (int)strcspn(out, "\n"), out);

    testdaemon d;
    testdaemon_start(&d, "py-inst", NULL);
    write_inputs(&d);
    /* from elsewhere than the source tree, without MESHCORR_LIB: the
     * installed package and the library its _libpath.py names */
    char env[2000];
    snprintf(env, sizeof env, "cd %s && env -u MESHCORR_LIB PYTHONDONTWRITEBYTECODE=1 MESHCORR_SERVER=%s "
             "PYTHONPATH=%s " PYTHON, harness_tmpdir(), d.unix_addr, site);
    CHECK_INT(testrunf(out, sizeof out, "%s -c 'import meshcorr, meshcorr._lib as l; "
                       "print(meshcorr.__file__); print(l.lib._name)' 2>&1", env), 0);
    CHECK_STR_HAS(out, site);
    CHECK_STR_HAS(out, path);
    char map[700];
    snprintf(map, sizeof map, "%s/example.map", harness_tmpdir());
    rc = testrunf(out, sizeof out, "%s %s/client-c/python/examples/submit_pair.py %s %s %s %s 3 2>&1", env, repo,
                  getenv("MESHCORR_TEST_SRC"), getenv("MESHCORR_TEST_TGT"), getenv("MESHCORR_TEST_LMK"), map);
    if (rc)
        FAILF("submit_pair.py exited %d:\n%s", rc, out);
    CHECK_STR_HAS(out, "\nectm    3/3 energy ");
    CHECK_STR_HAS(out, "COMPLETED: 162 rows written to ");
    char *text = (char *)testfile_read(map, &(size_t){0});
    CHECK_STR_HAS(text, "# meshcorr-map 1\n# meshcorrd job 1\n162 162\n");
    free(text);
    testdaemon_stop(&d, SIGTERM);
}
