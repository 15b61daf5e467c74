/* test_python.c — the Python package meshcorr (client-c/python) against a
 * real meshcorrd: each test starts the daemon (Unix socket and TCP with
 * tokens), writes the icosphere pair and runs one case of
 * tests/python/test_meshcorr.py with Debian's /usr/bin/python3 over
 * build/libmeshcorr.so.1. A case fails when the script exits non-zero, and
 * the test fails when the daemon died or exits non-zero. Then the two ways
 * users install it: `make install PREFIX=tmp` (no root) with README's
 * example script and match() run from PYTHONPATH against the installed
 * libraries (libmeshcorr's ldd slim); and `pip install ./client-c/python` into a fresh venv (made
 * with --system-site-packages for Debian's numpy; offline), whose match()
 * gives a daemon's map. /usr/bin/python3 is Debian's interpreter (the one
 * with python3-numpy): pyenv's or a venv's python3 on PATH may lack numpy. */
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

/* Runs one case against a daemon started with args (NULL-terminated, or NULL). */
static void run_case_with(const char *name, const char *const *args)
{
    testdaemon_need_worker();
    need_python();
    testdaemon d;
    testdaemon_start(&d, "py", args);
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

static void run_case(const char *name)
{
    run_case_with(name, NULL);
}

TEST_T(submit_from_files_watch_and_result_match_the_cli, 120)
{
    run_case("files_watch_result_same_as_cli");
}

TEST_T(a_jobs_rhm_maps_through_python_are_the_clis, 120)
{
    run_case("rhm_stage_maps_same_as_cli");
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

TEST_T(a_closed_client_raises_value_error_from_every_method_never_segfaults, 120)
{
    run_case("closed_client_raises_value_error");
}

TEST(version_is_the_version_file_through_mc_version)
{
    run_case("version_is_the_project_version");
}

TEST_T(errors_are_the_builtin_exceptions_they_mean_with_code_and_field, 120)
{
    static const char *const args[] = {"--max-jobs-per-user", "1", NULL};
    run_case_with("errors_are_builtin_subclasses", args);
}

TEST_T(wait_and_watch_timeouts_raise_timeout_error_while_the_job_runs_on, 120)
{
    run_case("timeouts_raise_timeout_error_and_the_job_keeps_running");
}

TEST(read_mesh_gives_the_engines_arrays_for_every_format)
{
    run_case("read_mesh_gives_the_engines_arrays");
}

TEST(maps_give_nearest_vertices_and_carry_fields_exactly)
{
    run_case("maps_give_vertex_ids_and_carry_fields");
}

TEST_T(landmarks_must_be_integer_vertex_ids_named_when_refused, 120)
{
    run_case("landmarks_must_be_integer_vertex_ids");
}

TEST_T(repaired_meshes_have_the_record_on_the_result_and_repair_no_refuses, 120)
{
    run_case("repair_record_and_keyword");
}

TEST_T(a_landmark_file_path_is_read_by_the_clis_reader_and_gives_the_arrays_job, 120)
{
    run_case("landmark_files_read_by_the_clis_reader");
}

TEST_T(match_in_process_gives_the_daemons_maps_progress_and_refusals, 180)
{
    run_case("match_in_process_equals_the_daemons_job");
}

TEST(reprs_name_the_object_and_type_hints_resolve)
{
    run_case("reprs_and_type_hints");
}

TEST_T(every_python_example_of_docs_python_md_runs, 180)
{
    run_case("docs_examples_run");
}

/* The install docs/python.md gives: a venv that sees Debian's numpy, pip
 * without build isolation (offline), MESHCORR_LIB naming the built library;
 * the case runs from outside the tree with the venv's python. */
TEST_T(pip_install_into_a_fresh_venv_matches_the_daemons_map, 300)
{
    testdaemon_need_worker();
    need_python();
    if (testrun(PYTHON " -m venv --help >/dev/null 2>&1 && " PYTHON " -c 'import ensurepip, setuptools, wheel' 2>&1",
                out, sizeof out) != 0)
        SKIP("python3-venv, python3-setuptools or python3-wheel is not installed (deploy/install-deps.sh)");
    char repo[512], venv[600];
    CHECK(getcwd(repo, sizeof repo));
    snprintf(venv, sizeof venv, "%s/venv", harness_tmpdir());
    int rc = testrunf(out, sizeof out, PYTHON " -m venv --system-site-packages %s 2>&1", venv);
    if (rc)
        FAILF("python3 -m venv failed (%d):\n%s", rc, out);
    rc = testrunf(out, sizeof out, "PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1 %s/bin/pip install "
                  "--no-build-isolation ./client-c/python 2>&1", venv);
    if (rc)
        FAILF("pip install --no-build-isolation ./client-c/python failed (%d):\n%s", rc, out);
    CHECK_STR_HAS(out, "Successfully installed meshcorr-");

    testdaemon d;
    testdaemon_start(&d, "py-venv", NULL);
    write_inputs(&d);
    rc = testrunf(out, sizeof out, "cd %s && env -u PYTHONPATH MESHCORR_TEST_REPO=%s MESHCORR_LIB=%s/build/libmeshcorr.so.1 "
                  "PYTHONDONTWRITEBYTECODE=1 %s/bin/python %s/tests/python/test_meshcorr.py venv_match_equals_daemon 2>&1",
                  harness_tmpdir(), repo, repo, venv, repo);
    if (rc) {
        fprintf(stderr, "%s", out);
        FAILF("test_meshcorr.py venv_match_equals_daemon with the venv's python exited %d", rc);
    }
    CHECK_STR_HAS(out, "ok venv_match_equals_daemon\n");
    testdaemon_stop(&d, SIGTERM);
}

/* docs/python.md's install into a folder of one's own and its example
 * script, against a real daemon. */
TEST_T(installed_package_runs_the_documented_example_against_meshcorrd, 240)
{
    testdaemon_need_worker();
    need_python();
    char *doc = (char *)testfile_read("docs/python.md", &(size_t){0});
    CHECK_STR_HAS(doc, "make install-python PREFIX=");
    CHECK_STR_HAS(doc, "client-c/python/examples/submit_pair.py");
    free(doc);
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
    /* the installed engine library, next to the installed libmeshcorr: match() in-process */
    rc = testrunf(out, sizeof out, "%s -c 'import meshcorr, meshcorr._lib as l; "
                  "r = meshcorr.match(\"%s\", \"%s\", landmarks=[[i, i] for i in range(6)], iterations=2); "
                  "print(len(r.p), l.engine()._name)' 2>&1", env, getenv("MESHCORR_TEST_SRC"),
                  getenv("MESHCORR_TEST_TGT"));
    if (rc)
        FAILF("meshcorr.match from the installed package exited %d:\n%s", rc, out);
    snprintf(path, sizeof path, "162 %s/lib/libmeshcorr-engine.so.1\n", dest);
    CHECK_STR_HAS(out, path);
    testdaemon_stop(&d, SIGTERM);
}
