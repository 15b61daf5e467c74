/* test_client_match.c — mc_match, the in-process job of
 * libmeshcorr-engine.so.1 (loaded with dlopen, as a binding does): the same
 * icosphere job through a real meshcorrd and through mc_match gives the
 * same maps bit for bit (RHM's too, through mc_match_stages), the same
 * metrics and the same progress records; a progress callback that returns
 * non-zero ends the job MC_ECANCELLED; refusals carry the server's codes
 * and messages; the library exports mc_match and mc_match_stages and `make
 * install-lib` installs it. And mc_read_mesh, the reader Python's
 * read_mesh uses: the file's arrays in its order. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testrun.h"
#include "mesh/mesh.h"
#include "meshcorr.h"

#include <dlfcn.h>
#include <signal.h>
#include <string.h>
#include <sys/stat.h>

#define ENGINE_SO "build/libmeshcorr-engine.so.1"

typedef int (*match_fn)(const mc_job_spec *, int, unsigned, mc_progress_fn, void *, mc_job_result *, char *,
                        size_t);

typedef int (*match_stages_fn)(const mc_job_spec *, int, unsigned, mc_progress_fn, void *,
                               mc_job_result *, mc_stage_maps *, char *, size_t);

/* The engine library's export `name`. */
static void *engine_symbol(const char *name)
{
    void *h = dlopen(ENGINE_SO, RTLD_NOW | RTLD_LOCAL);
    if (!h)
        FAILF("dlopen %s: %s", ENGINE_SO, dlerror());
    void *f = dlsym(h, name);
    CHECK(f != NULL);
    return f;
}

static match_fn load_match(void)
{
    return (match_fn)(uintptr_t)engine_symbol("mc_match");
}

/* The icosphere job of testdaemon_submit (162 vertices, 6 landmarks). */
typedef struct job {
    mc_job_spec spec;
    unsigned char *sb, *tb;
    uint32_t lm[12];
} job;

static void job_open(job *j, int iterations)
{
    mesh *S, *T;
    testdaemon_pair(0, &S, &T);
    mc_job_spec_init(&j->spec);
    j->sb = testdaemon_encode(S, &j->spec.source_len);
    j->tb = testdaemon_encode(T, &j->spec.target_len);
    mesh_free(S);
    mesh_free(T);
    for (int i = 0; i < 12; i++)
        j->lm[i] = (uint32_t)(i / 2);
    j->spec.source = j->sb;
    j->spec.target = j->tb;
    j->spec.landmarks = j->lm;
    j->spec.nlandmarks = 6;
    j->spec.iterations = (uint32_t)iterations;
    j->spec.beta_ramp = (uint32_t)iterations;
    j->spec.inner_iterations = 10;
    j->spec.rhm_iterations = 3;
    j->spec.stop_change = 0;
}

static void job_close(job *j)
{
    free(j->sb);
    free(j->tb);
}

#define MAX_RECORDS 64
typedef struct records {
    int n;
    mc_progress p[MAX_RECORDS];
    int stop_at;               /* return 1 at this record (1-based); 0 never */
} records;

static int keep(void *ctx, const mc_progress *p)
{
    records *r = ctx;
    if (r->n < MAX_RECORDS)
        r->p[r->n] = *p;
    r->n++;
    return r->stop_at && r->n == r->stop_at;
}

static void check_same_map(const mc_map_row *a, const mc_map_row *b, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++)
        if (a[i].face != b[i].face || memcmp(a[i].w, b[i].w, sizeof a[i].w) != 0)
            FAILF("row %u: face %u (%.17g %.17g %.17g) against %u (%.17g %.17g %.17g)", i, a[i].face, a[i].w[0],
                  a[i].w[1], a[i].w[2], b[i].face, b[i].w[0], b[i].w[1], b[i].w[2]);
}

TEST_T(in_process_job_gives_the_daemons_maps_metrics_and_progress, 180)
{
    testdaemon_need_worker();
    match_fn match = load_match();
    job j;
    job_open(&j, 4);
    testdaemon d;
    testdaemon_start(&d, "match", NULL);
    mc_client *c = testdaemon_client(&d, NULL);
    uint64_t id = 0;
    CHECK_INT(mc_submit(c, &j.spec, &id), 0);
    records wr = {0}, mr = {0};
    int end = -1;
    CHECK_INT(mc_watch(c, id, 0, keep, &wr, &end, NULL, 0), 0);
    CHECK_INT(end, MC_COMPLETED);
    unsigned all = MC_WANT_P | MC_WANT_Q | MC_WANT_DEFORMED | MC_WANT_METRICS;
    mc_job_result rs, rl;
    CHECK_INT(mc_result(c, id, all, &rs), 0);
    char err[1024];
    int rc = match(&j.spec, 0, all, keep, &mr, &rl, err, sizeof err);
    if (rc)
        FAILF("mc_match: %s (%s)", mc_err_name(rc), err);

    CHECK_INT(rl.np, rs.np);
    CHECK_INT(rl.nq, rs.nq);
    CHECK_INT(rl.np, 162);
    check_same_map(rl.p, rs.p, rl.np);
    check_same_map(rl.q, rs.q, rl.nq);
    CHECK_INT(rl.deformed_len, rs.deformed_len);
    CHECK(memcmp(rl.deformed, rs.deformed, rl.deformed_len) == 0);
    CHECK_INT(rl.nmetrics, rs.nmetrics);
    for (uint32_t i = 0; i < rl.nmetrics; i++) {
        CHECK_INT(strcmp(rl.metric_keys[i], rs.metric_keys[i]), 0);
        if (strcmp(rl.metric_keys[i], "elapsed_s") != 0 && rl.metric_values[i] != rs.metric_values[i])
            FAILF("metric %s: %.17g in process, %.17g from the daemon", rl.metric_keys[i], rl.metric_values[i],
                  rs.metric_values[i]);
    }
    /* the same records (the daemon's carry the job id and its clock) */
    CHECK_INT(mr.n, wr.n);
    CHECK(mr.n > 4 && mr.n <= MAX_RECORDS);
    for (int i = 0; i < mr.n; i++) {
        const mc_progress *a = &mr.p[i], *b = &wr.p[i];
        CHECK_INT(a->job_id, 0);
        int same = a->stage == b->stage && a->outer == b->outer && a->total == b->total &&
                   a->beta == b->beta && a->gamma == b->gamma && a->fraction == b->fraction &&
                   a->ahead == b->ahead;
        for (int s = 0; s < 2; s++)
            same = same && a->inner[s] == b->inner[s] && a->membrane[s] == b->membrane[s] &&
                   a->bending[s] == b->bending[s] && a->mismatch[s] == b->mismatch[s] &&
                   a->reverse[s] == b->reverse[s] && a->energy[s] == b->energy[s];
        if (!same)
            FAILF("progress record %d differs: stage %d outer %u energy %.17g, the daemon's stage %d outer %u "
                  "energy %.17g", i, a->stage, a->outer, a->energy[0], b->stage, b->outer, b->energy[0]);
    }
    /* ECTM's 4 iterations, then the repair of its maps ends the job */
    CHECK_INT(mr.p[mr.n - 1].stage, MC_STAGE_REPAIR);
    CHECK(mr.p[mr.n - 1].fraction == 1);
    int last_ectm = mr.n - 1;
    while (last_ectm >= 0 && mr.p[last_ectm].stage != MC_STAGE_ECTM)
        last_ectm--;
    CHECK(last_ectm >= 0);
    CHECK_INT(mr.p[last_ectm].outer, 4);
    /* RHM's maps: mc_match_stages gives the daemon's (mc_result_stage) */
    match_stages_fn match_stages = (match_stages_fn)(uintptr_t)engine_symbol("mc_match_stages");
    mc_stage_maps ss, sl;
    mc_job_result r2;
    CHECK_INT(mc_result_stage(c, id, "rhm", &ss), 0);
    rc = match_stages(&j.spec, 0, MC_WANT_P, NULL, NULL, &r2, &sl, err, sizeof err);
    if (rc)
        FAILF("mc_match_stages: %s (%s)", mc_err_name(rc), err);
    CHECK_INT(sl.np, 162);
    CHECK_INT(sl.np, ss.np);
    CHECK_INT(sl.nq, ss.nq);
    check_same_map(sl.p, ss.p, sl.np);
    check_same_map(sl.q, ss.q, sl.nq);
    check_same_map(r2.p, rs.p, r2.np);
    mc_stage_maps_free(&ss);
    mc_stage_maps_free(&sl);
    mc_result_free(&r2);
    mc_result_free(&rs);
    mc_result_free(&rl);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
    job_close(&j);
}

TEST(progress_callback_returning_non_zero_ends_the_job_cancelled)
{
    match_fn match = load_match();
    job j;
    job_open(&j, 50);
    records r = {0};
    r.stop_at = 3;
    mc_job_result out;
    char err[512];
    CHECK_INT(match(&j.spec, 1, MC_WANT_P, keep, &r, &out, err, sizeof err), MC_ECANCELLED);
    CHECK_STR_HAS(err, "cancelled by the progress callback");
    CHECK_INT(r.n, 3);
    CHECK(out.p == NULL && out.np == 0);
    mc_result_free(&out);
    job_close(&j);
}

/* The same bad jobs to the daemon and to mc_match: the same code, and the
 * daemon's message (which the client prefixes with the code's name). */
TEST_T(refusals_have_the_servers_codes_and_messages, 120)
{
    testdaemon_need_worker();
    match_fn match = load_match();
    testdaemon d;
    testdaemon_start(&d, "refuse", NULL);
    mc_client *c = testdaemon_client(&d, NULL);
    for (int k = 0; k < 3; k++) {
        job j;
        job_open(&j, 2);
        if (k == 0)
            j.lm[5] = 500;                    /* target vertex 500 of 162 */
        else if (k == 1)
            j.spec.iterations = 0;
        else
            j.lm[2] = 0;                      /* source vertex 0 twice */
        uint64_t id = 0;
        int rs = mc_submit(c, &j.spec, &id);
        char server[1300], err[1024];
        snprintf(server, sizeof server, "%s", mc_errmsg(c));
        mc_job_result out;
        int rl = match(&j.spec, 0, MC_WANT_P, NULL, NULL, &out, err, sizeof err);
        CHECK_INT(rl, rs);
        CHECK(rl == MC_EBAD_LANDMARKS || rl == MC_EBAD_PARAMS);
        char want[1300];
        snprintf(want, sizeof want, "%s: %s", mc_err_name(rl), err);
        CHECK_INT(strcmp(server, want), 0);
        mc_result_free(&out);
        job_close(&j);
    }
    job j;
    job_open(&j, 2);
    mc_job_result out;
    char err[512];
    CHECK_INT(match(&j.spec, -1, MC_WANT_P, NULL, NULL, &out, err, sizeof err), MC_EARG);
    CHECK_STR_HAS(err, "threads = -1");
    j.spec.source = NULL;
    CHECK_INT(match(&j.spec, 0, MC_WANT_P, NULL, NULL, &out, err, sizeof err), MC_EARG);
    CHECK_INT(match(&j.spec, 0, MC_WANT_P, NULL, NULL, NULL, err, sizeof err), MC_EARG);
    job_close(&j);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(engine_library_exports_mc_match_and_mc_match_stages_and_installs_beside_libmeshcorr, 180)
{
    char out[8192], path[800];
    CHECK_INT(testrunf(out, sizeof out, "nm -D --defined-only " ENGINE_SO " | awk '$2 == \"T\" { print $3 }'"), 0);
    CHECK_INT(strcmp(out, "mc_match@@MESHCORR_ENGINE_1\nmc_match_stages@@MESHCORR_ENGINE_1.1\n"), 0);
    CHECK_INT(testrunf(out, sizeof out, "env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s install-lib "
                       "DESTDIR=%s/dest PREFIX=/opt/mc 2>&1", harness_tmpdir()), 0);
    snprintf(path, sizeof path, "%s/dest/opt/mc/lib/libmeshcorr-engine.so.1", harness_tmpdir());
    struct stat st;
    CHECK(stat(path, &st) == 0 && (st.st_mode & 0111));
    CHECK_INT(testrunf(out, sizeof out, "readelf -d %s", path), 0);
    CHECK_STR_HAS(out, "Library soname: [libmeshcorr-engine.so.1]");
}

TEST(read_mesh_gives_the_files_arrays_in_its_order)
{
    mesh *S, *T;
    testdaemon_pair(0, &S, &T);
    static const char *const ext[] = {"off", "obj", "ply", "drc"};
    for (int k = 0; k < 4; k++) {
        char path[700], err[512];
        snprintf(path, sizeof path, "%s/t.%s", harness_tmpdir(), ext[k]);
        CHECK_INT(mesh_write(path, T, err, sizeof err), 0);
        double *v = NULL;
        int *f = NULL, nv = 0, nf = 0;
        if (mc_read_mesh(path, &v, &nv, &f, &nf, err, sizeof err))
            FAILF("mc_read_mesh %s: %s", path, err);
        CHECK_INT(nv, T->nv);
        CHECK_INT(nf, T->nf);
        CHECK(memcmp(f, T->f, sizeof(int) * 3 * (size_t)nf) == 0);
        CHECK(memcmp(v, T->v, sizeof(double) * 3 * (size_t)nv) == 0);   /* every format round-trips doubles */
        free(v);
        free(f);
    }
    char err[512], path[700];
    double *v = (double *)1;
    int *f = (int *)1, nv = 1, nf = 1;
    snprintf(path, sizeof path, "%s/none.off", harness_tmpdir());
    CHECK_INT(mc_read_mesh(path, &v, &nv, &f, &nf, err, sizeof err), MC_EFILE);
    CHECK_STR_HAS(err, "none.off");
    CHECK(v == NULL && f == NULL && nv == 0 && nf == 0);
    CHECK_INT(mc_read_mesh(path, NULL, &nv, &f, &nf, err, sizeof err), MC_EARG);
    mesh_free(S);
    mesh_free(T);
}
