/* test_cli_remote.c — the real build/meshcorr's remote subcommands against a
 * real meshcorrd (tests/support/testdaemon): submit prints the id alone,
 * watch prints one line per iteration and exits 0 only for a COMPLETED job,
 * result writes the maps mc_result returns, list/stats --json are JSON,
 * --token-file works over TCP and a bad token is refused in words, a
 * lossless upload gives the map `meshcorr match` gives, bit for bit, an
 * admin's list shows every user's jobs, status and result --json are the
 * Python package's fields, and the default server, bare socket paths and
 * connect errors say what to do. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testfile.h"
#include "support/testjson.h"
#include "support/testmesh.h"
#include "support/testrun.h"
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "meshcorr.h"

#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static char src[600], tgt[600], lmk[600], out[1 << 16];

/* Icosphere pair (the target an ellipsoid, a little bent) and 6 identity
 * landmarks in this test's directory. */
static void write_inputs(void)
{
    mesh *S = testmesh_icosphere(2), *T = testmesh_icosphere(2);
    CHECK(S && T);
    for (int i = 0; i < T->nv; i++) {
        double *x = &T->v[3 * i];
        x[0] *= 1.3;
        x[2] += 0.15 * x[0] * x[0];
    }
    char err[512];
    snprintf(src, sizeof src, "%s/s.off", harness_tmpdir());
    snprintf(tgt, sizeof tgt, "%s/t.off", harness_tmpdir());
    CHECK_INT(mesh_write(src, S, err, sizeof err), 0);
    CHECK_INT(mesh_write(tgt, T, err, sizeof err), 0);
    snprintf(lmk, sizeof lmk, "%s", testfile_text("pairs.lmk", "0 0\n1 1\n2 2\n3 3\n4 4\n5 5\n"));
    mesh_free(S);
    mesh_free(T);
}

#define JOB_OPTS "--iterations 4 --beta-ramp 4 --inner-iterations 10 --rhm-iterations 3"

/* `meshcorr submit` of the quick pair; returns the id it printed (stdout
 * must be the id and a newline, nothing else). */
static uint64_t submit(const testdaemon *d, const char *extra)
{
    int rc = testrunf(out, sizeof out, "build/meshcorr submit %s %s --landmarks %s " JOB_OPTS " --server %s %s",
                      src, tgt, lmk, d->unix_addr, extra);
    CHECK_INT(rc, 0);
    char *e;
    unsigned long long id = strtoull(out, &e, 10);
    if (id == 0 || strcmp(e, "\n") != 0)
        FAILF("submit printed \"%s\", not an id alone", out);
    return id;
}

TEST_T(submit_prints_the_id_watch_prints_energies_and_exits_0_and_result_writes_mc_results_maps, 90)
{
    testdaemon_need_worker();
    write_inputs();
    testdaemon d;
    testdaemon_start(&d, "d", NULL);
    uint64_t id = submit(&d, "");

    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr watch %llu --server %s", (unsigned long long)id,
                       d.unix_addr), 0);
    char last[64];
    snprintf(last, sizeof last, "job %llu COMPLETED\n", (unsigned long long)id);
    CHECK(strlen(out) > strlen(last) && strcmp(out + strlen(out) - strlen(last), last) == 0);
    int nectm = 0;
    double e4 = 0;
    for (char *l = out; *l; l = strchr(l, '\n') + 1) {
        unsigned long long jid;
        char stage[16];
        unsigned k, total;
        double e, mem, ben, mis, rev, beta;
        if (sscanf(l, "job %llu %15s iter %u/%u energy %lf membrane %lf bending %lf mismatch %lf reverse %lf "
                      "beta %lf", &jid, stage, &k, &total, &e, &mem, &ben, &mis, &rev, &beta) == 10) {
            CHECK_INT(jid, id);
            if (strcmp(stage, "ectm") == 0) {
                nectm++;
                CHECK_INT(total, 4);
                CHECK(isfinite(e) && e > 0 && mem >= 0 && ben >= 0 && mis >= 0 && rev >= 0 && beta > 0);
                if (k == 4)
                    e4 = e;
            }
        } else if (sscanf(l, "job %llu repair iter %u/%u (", &jid, &k, &total) == 3) {
            CHECK_INT(jid, id);          /* a fold repair: no energies, its maps done of total */
            CHECK(total == 2 && (k == 0 || k == 2));
        } else if (strcmp(l, last) != 0) {
            FAILF("watch line is not in the documented format: %.*s", (int)strcspn(l, "\n"), l);
        }
    }
    CHECK(nectm >= 4);
    /* the text line's energy is the sum of both directions of the JSON record */
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr watch %llu --progress json --server %s",
                       (unsigned long long)id, d.unix_addr), 0);
    char *rec = strstr(out, "\"stage\":\"ectm\",\"outer\":4,");
    CHECK(rec);
    char *es = strstr(rec, "\"energy\":"), *et = es ? strstr(es + 1, "\"energy\":") : NULL;
    CHECK(es && et);
    double sum = strtod(es + 9, NULL) + strtod(et + 9, NULL);
    CHECK_NEAR(e4, sum, 1e-3 * sum);

    char P[700], Q[700], Y[700], err[512];
    snprintf(P, sizeof P, "%s/p.map", harness_tmpdir());
    snprintf(Q, sizeof Q, "%s/q.map", harness_tmpdir());
    snprintf(Y, sizeof Y, "%s/y.ply", harness_tmpdir());
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr result %llu --out %s --out-reverse %s --out-deformed %s "
                       "--server %s 2>&1", (unsigned long long)id, P, Q, Y, d.unix_addr), 0);
    /* the quality of both maps is printed with the result */
    CHECK_STR_HAS(out, "flipped_fraction ");
    CHECK_STR_HAS(out, "reverse_collapsed_fraction ");
    CHECK_STR_HAS(out, "quality_verdict ");
    mesh *S = NULL, *T = NULL, *D = NULL;
    CHECK_INT(mesh_read(src, &S, err, sizeof err), 0);
    CHECK_INT(mesh_read(tgt, &T, err, sizeof err), 0);
    CHECK_INT(mesh_read(Y, &D, err, sizeof err), 0);
    CHECK_INT(D->nv, S->nv);
    bmap *Pm = NULL, *Qm = NULL;
    if (bmap_read(P, S, T, &Pm, err, sizeof err) || bmap_read(Q, T, S, &Qm, err, sizeof err))
        FAILF("bmap_read: %s", err);
    mc_client *c = testdaemon_client(&d, NULL);
    mc_job_result res;
    CHECK_INT(mc_result(c, id, MC_WANT_P | MC_WANT_Q, &res), 0);
    CHECK_INT(res.np, Pm->n);
    CHECK_INT(res.nq, Qm->n);
    for (uint32_t i = 0; i < res.np; i++) {
        CHECK_INT(res.p[i].face, Pm->face[i]);
        for (int k = 0; k < 3; k++)
            CHECK_NEAR(res.p[i].w[k], Pm->w[3 * i + k], 1e-15);
    }
    for (uint32_t i = 0; i < res.nq; i++)
        CHECK_INT(res.q[i].face, Qm->face[i]);
    mc_result_free(&res);
    mc_close(c);
    bmap_free(Pm);
    bmap_free(Qm);
    mesh_free(S);
    mesh_free(T);
    mesh_free(D);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(submit_watch_streams_to_the_end_and_watch_of_a_cancelled_job_exits_5_saying_why, 90)
{
    testdaemon_need_worker();
    write_inputs();
    testdaemon d;
    testdaemon_start(&d, "d", NULL);
    int rc = testrunf(out, sizeof out, "build/meshcorr submit %s %s --landmarks %s " JOB_OPTS
                      " --server %s --watch", src, tgt, lmk, d.unix_addr);
    CHECK_INT(rc, 0);
    char *e;
    unsigned long long id = strtoull(out, &e, 10);
    CHECK(id > 0 && *e == '\n');
    CHECK_STR_HAS(out, " ectm iter 4/4 energy ");
    CHECK_STR_HAS(out, " COMPLETED\n");

    mc_client *c = testdaemon_client(&d, NULL);
    uint64_t long_id = testdaemon_submit(c, 100000, 1, 0, &rc);
    CHECK_INT(rc, 0);
    testdaemon_wait_state(c, long_id, MC_RUNNING, 30);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr cancel %llu --server %s", (unsigned long long)long_id,
                       d.unix_addr), 0);
    rc = testrunf(out, sizeof out, "build/meshcorr watch %llu --server %s 2>&1 >/dev/null",
                  (unsigned long long)long_id, d.unix_addr);
    CHECK_INT(rc, 5);                   /* the kind CANCELLED's status (proto_kind.h) */
    CHECK_STR_HAS(out, "CANCELLED");
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* A daemon started on d with one quick job submitted (extra: more submit
 * options) and watched to its end; the job's id. */
static uint64_t completed_job(testdaemon *d, const char *extra)
{
    testdaemon_need_worker();
    write_inputs();
    testdaemon_start(d, "d", NULL);
    uint64_t id = submit(d, extra);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr watch %llu --server %s", (unsigned long long)id,
                       d->unix_addr), 0);
    return id;
}

TEST_T(list_and_stats_json_are_json_with_the_jobs_fields, 90)
{
    testdaemon d;
    uint64_t id = completed_job(&d, "--label 'a \"quoted\" label'");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --json --server %s", d.unix_addr), 0);
    if (!testjson_valid(out))
        FAILF("list --json is not JSON:\n%s", out);
    CHECK(out[0] == '[');
    char want[128];
    snprintf(want, sizeof want, "{\"id\":%llu,\"state\":\"COMPLETED\",", (unsigned long long)id);
    CHECK_STR_HAS(out, want);
    CHECK_STR_HAS(out, "\"outer\":4,\"total\":4");
    CHECK_STR_HAS(out, "\"label\":\"a \\\"quoted\\\" label\"");
    /* and the whole job's progress: done, nothing ahead */
    CHECK_STR_HAS(out, ",\"fraction\":1,\"eta\":0.000,\"ahead\":0}");
    /* the map's quality: this small pair maps cleanly */
    CHECK_STR_HAS(out, ",\"quality\":\"ok\",\"quality_verdict\":0,\"flipped\":");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr status %llu --server %s", (unsigned long long)id,
                       d.unix_addr), 0);
    CHECK_STR_HAS(out, "\nquality   ok: ");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --server %s", d.unix_addr), 0);
    CHECK_STR_HAS(out, " QUALITY ");
    CHECK_STR_HAS(out, " ok ");
    CHECK_STR_HAS(out, " PROGRESS ");
    CHECK_STR_HAS(out, " 4/4 ");                 /* ITER beside the PROGRESS column */
    CHECK_STR_HAS(out, " 100 % ");

    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr stats --json --server %s", d.unix_addr), 0);
    if (!testjson_valid(out))
        FAILF("stats --json is not JSON:\n%s", out);
    CHECK_STR_HAS(out, "\"completed\":1,");
    CHECK_STR_HAS(out, "\"queued\":0,");
    CHECK_STR_HAS(out, "\"slots\":[{\"state\":\"");
    CHECK(!testjson_valid("[{\"id\":1,}]") && !testjson_valid("{\"a\":1} x"));
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(token_file_authenticates_over_tcp_and_a_bad_token_fails_with_a_clear_message, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "d", NULL);
    const char *good = testfile_text("good.token", TESTDAEMON_BOB "\n");
    char goodp[700];
    snprintf(goodp, sizeof goodp, "%s", good);
    /* the file wins over a wrong $MESHCORR_TOKEN */
    CHECK_INT(testrunf(out, sizeof out, "MESHCORR_TOKEN=wrong build/meshcorr stats --json --server %s "
                       "--token-file %s 2>&1", d.tcp_addr, goodp), 0);
    CHECK(testjson_valid(out));
    const char *bad = testfile_text("bad.token", "not-a-token\n");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --server %s --token-file %s 2>&1", d.tcp_addr, bad),
              1);
    CHECK_STR_HAS(out, "refused the token (from --token-file)");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --server %s --token wrong 2>&1", d.tcp_addr), 1);
    CHECK_STR_HAS(out, "refused the token");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --server %s --token-file %s/none 2>&1", d.tcp_addr,
                       harness_tmpdir()), 1);
    CHECK_STR_HAS(out, "cannot open");
    testdaemon_stop(&d, SIGTERM);
}

/* Rows of P and R that are not the same bits (face and weights). */
static int rows_differing(const bmap *P, const bmap *R)
{
    int n = 0;
    for (int i = 0; i < P->n; i++)
        n += P->face[i] != R->face[i] || memcmp(&P->w[3 * i], &R->w[3 * i], 3 * sizeof(double)) != 0;
    return n;
}

/* Mean and largest distance between the points the maps give each source
 * vertex on T, over sqrt(area of T); returns the rows over 1e-3 of it. */
static int map_distance(const bmap *P, const bmap *R, const mesh *T, double *mean, double *max)
{
    int far = 0;
    double area = 0, sum = 0;
    *max = 0;
    for (int t = 0; t < T->nf; t++) {
        const double *a = &T->v[3 * T->f[3 * t]], *b = &T->v[3 * T->f[3 * t + 1]], *c = &T->v[3 * T->f[3 * t + 2]];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        area += 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
    for (int i = 0; i < P->n; i++) {
        double x[2][3] = {{0}};
        const bmap *M[2] = {P, R};
        for (int m = 0; m < 2; m++)
            for (int k = 0; k < 3; k++)
                for (int d = 0; d < 3; d++)
                    x[m][d] += M[m]->w[3 * i + k] * T->v[3 * T->f[3 * M[m]->face[i] + k] + d];
        double e = sqrt((x[0][0] - x[1][0]) * (x[0][0] - x[1][0]) + (x[0][1] - x[1][1]) * (x[0][1] - x[1][1]) +
                        (x[0][2] - x[1][2]) * (x[0][2] - x[1][2])) / sqrt(area);
        sum += e;
        *max = e > *max ? e : *max;
        far += e > 1e-3;
    }
    *mean = sum / P->n;
    return far;
}

#define WOLF_OPTS "--iterations 2 --beta-ramp 2 --inner-iterations 10 --rhm-iterations 3"

/* `meshcorr submit` then `meshcorr result` of job options and extra; returns the map P (and Q in *Q). */
static bmap *remote_map(const testdaemon *d, const char *s, const char *t, const char *pairs, const char *extra,
                        const mesh *S, const mesh *T, bmap **Q)
{
    char P[700], Qp[700], err[512];
    snprintf(P, sizeof P, "%s/remote.map", harness_tmpdir());
    snprintf(Qp, sizeof Qp, "%s/remote-q.map", harness_tmpdir());
    int rc = testrunf(out, sizeof out, "build/meshcorr submit %s %s --landmarks %s " WOLF_OPTS " %s --watch "
                      "--server %s 2>&1", s, t, pairs, extra, d->unix_addr);
    if (rc)
        FAILF("submit %s exited %d:\n%s", extra, rc, out);
    unsigned long long id = strtoull(out, NULL, 10);
    CHECK(id > 0);
    rc = testrunf(out, sizeof out, "build/meshcorr result %llu --out %s --out-reverse %s --server %s 2>&1", id, P,
                  Qp, d->unix_addr);
    if (rc)
        FAILF("result exited %d:\n%s", rc, out);
    bmap *Pm = NULL;
    if (bmap_read(P, S, T, &Pm, err, sizeof err) || bmap_read(Qp, T, S, Q, err, sizeof err))
        FAILF("bmap_read: %s", err);
    return Pm;
}

/* The lossless upload: the daemon computes on the very doubles `meshcorr
 * match` reads from the same files and returns its map bit for bit (wolf0
 * -> wolf1, the 21 BIM landmarks, 2 ECTM and 3 RHM iterations, one thread
 * on both sides). --quantization 16 trades that for size: its map is
 * another one. */
TEST_T(submit_returns_the_map_meshcorr_match_computes_bit_for_bit_and_quantization_changes_it, 240)
{
    testdaemon_need_worker();
    char s[600], t[600], pairs[700], P[700], Q[700], err[512];
    snprintf(s, sizeof s, "%s", harness_data_path("tosca_hires/Meshes/wolf0.off"));
    snprintf(t, sizeof t, "%s", harness_data_path("tosca_hires/Meshes/wolf1.off"));
    /* the same landmark ids on both poses (tosca_hires: identity by index) */
    FILE *fp = fopen(harness_data_path("tosca_hires/Corrs/wolf.pid"), "r");
    CHECK(fp);
    char lines[4096] = "";
    int id, n = 0;
    while (fscanf(fp, "%d %*d %*d %*d", &id) == 1)
        n += snprintf(lines + n, sizeof lines - (size_t)n, "%d %d\n", id, id);
    fclose(fp);
    CHECK(n > 0);
    snprintf(pairs, sizeof pairs, "%s", testfile_text("wolf.lmk", lines));
    snprintf(P, sizeof P, "%s/local.map", harness_tmpdir());
    snprintf(Q, sizeof Q, "%s/local-q.map", harness_tmpdir());
    int rc = testrunf(out, sizeof out, "build/meshcorr match %s %s --landmarks %s " WOLF_OPTS " --threads 1 "
                      "--progress none --out %s --out-reverse %s 2>&1", s, t, pairs, P, Q);
    if (rc)
        FAILF("match exited %d:\n%s", rc, out);
    mesh *S = NULL, *T = NULL;
    CHECK_INT(mesh_read(s, &S, err, sizeof err), 0);
    CHECK_INT(mesh_read(t, &T, err, sizeof err), 0);
    bmap *Pl = NULL, *Ql = NULL;
    if (bmap_read(P, S, T, &Pl, err, sizeof err) || bmap_read(Q, T, S, &Ql, err, sizeof err))
        FAILF("bmap_read: %s", err);

    testdaemon d;
    testdaemon_start(&d, "d", NULL);
    bmap *Qr = NULL, *Pr = remote_map(&d, s, t, pairs, "", S, T, &Qr);
    CHECK_INT(Pr->n, Pl->n);
    CHECK_INT(Qr->n, Ql->n);
    int dp = rows_differing(Pl, Pr), dq = rows_differing(Ql, Qr);
    if (dp || dq)
        FAILF("lossless upload: %d of %d rows of P and %d of %d of Q differ from meshcorr match's", dp, Pl->n, dq,
              Ql->n);

    bmap *Qq = NULL, *Pq = remote_map(&d, s, t, pairs, "--quantization 16", S, T, &Qq);
    double mean, max;
    int far = map_distance(Pl, Pq, T, &mean, &max);
    printf("  --quantization 16: %d of %d rows of P differ; mean %.3g, max %.3g of sqrt(area); %d rows over 1e-3\n",
           rows_differing(Pl, Pq), Pl->n, mean, max, far);
    CHECK(rows_differing(Pl, Pq) > 0);

    /* a .drc is sent as it is: --quantization does not apply; bits out of range */
    char drc[700];
    snprintf(drc, sizeof drc, "%s/wolf0.drc", harness_tmpdir());
    CHECK_INT(mesh_write(drc, S, err, sizeof err), 0);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr submit %s %s --landmarks %s --quantization 16 "
                       "--server %s 2>&1", drc, t, pairs, d.unix_addr), 2);
    CHECK_STR_HAS(out, "a .drc file is sent as it is");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr submit %s %s --landmarks %s --quantization 31 "
                       "--server %s 2>&1", s, t, pairs, d.unix_addr), 2);
    CHECK_STR_HAS(out, "--quantization: '31' is not a number of bits from 1 to 30");
    testdaemon_stop(&d, SIGTERM);
    bmap_free(Pl);
    bmap_free(Ql);
    bmap_free(Pr);
    bmap_free(Qr);
    bmap_free(Pq);
    bmap_free(Qq);
    mesh_free(S);
    mesh_free(T);
}

/* The rows of a `meshcorr list` table: count of lines naming user. */
static int rows_of_user(const char *table, const char *user)
{
    int n = 0;
    for (const char *l = table; *l; l = strchr(l, '\n') ? strchr(l, '\n') + 1 : l + strlen(l)) {
        unsigned long long id;
        char state[32], u[64];
        if (sscanf(l, "%llu %31s %63s", &id, state, u) == 3 && strcmp(u, user) == 0)
            n++;
    }
    return n;
}

/* alice and bob each submit; the admin's `meshcorr list` shows both with
 * their USER, `--user bob` only bob's; alice sees only hers, and her
 * `--user bob` and a LIST of every user ("*") are FORBIDDEN, logged. */
TEST_T(admin_list_shows_every_users_jobs_and_user_filters, 120)
{
    testdaemon_need_worker();
    write_inputs();
    testdaemon d;
    testdaemon_start(&d, "d", NULL);
    char extra[256];
    snprintf(extra, sizeof extra, "--server %s --token %s", d.tcp_addr, TESTDAEMON_ALICE);
    uint64_t a1 = submit(&d, extra), a2 = submit(&d, extra);
    snprintf(extra, sizeof extra, "--server %s --token %s", d.tcp_addr, TESTDAEMON_BOB);
    uint64_t b1 = submit(&d, extra);
    CHECK(a1 && a2 && b1);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --server %s --token %s 2>&1", d.tcp_addr,
                       TESTDAEMON_ADMIN), 0);
    CHECK_STR_HAS(out, " USER ");
    if (rows_of_user(out, "alice") != 2 || rows_of_user(out, "bob") != 1)
        FAILF("the admin's list does not show alice's 2 jobs and bob's 1:\n%s", out);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --json --server %s --token %s 2>&1", d.tcp_addr,
                       TESTDAEMON_ADMIN), 0);
    CHECK(testjson_valid(out));
    CHECK_STR_HAS(out, "\"user\":\"alice\"");
    CHECK_STR_HAS(out, "\"user\":\"bob\"");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --user bob --server %s --token %s 2>&1", d.tcp_addr,
                       TESTDAEMON_ADMIN), 0);
    if (rows_of_user(out, "alice") != 0 || rows_of_user(out, "bob") != 1)
        FAILF("--user bob lists other jobs than bob's:\n%s", out);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --server %s --token %s 2>&1", d.tcp_addr,
                       TESTDAEMON_ALICE), 0);
    if (rows_of_user(out, "alice") != 2 || rows_of_user(out, "bob") != 0)
        FAILF("alice's list is not her 2 jobs:\n%s", out);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --user bob --server %s --token %s 2>&1", d.tcp_addr,
                       TESTDAEMON_ALICE), 1);
    CHECK_STR_HAS(out, "only an admin may list the jobs of user bob");
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    mc_job_info *jobs = NULL;
    uint32_t n = 0;
    CHECK_INT(mc_list(c, MC_LIST_ALL_USERS, 0, &jobs, &n), MC_EFORBIDDEN);
    CHECK_STR_HAS(mc_errmsg(c), "only an admin may list every user's jobs");
    CHECK(jobs == NULL);
    CHECK_INT(mc_ping(c), 0);                    /* the session goes on */
    mc_close(c);
    CHECK(testdaemon_log_has(&d, "alice: LIST of (every user) refused: not an admin"));
    testdaemon_stop(&d, SIGTERM);
}

/* `meshcorr status --json` and `meshcorr result --json` print one JSON
 * object each, with the field names of the Python package's dicts. */
TEST_T(status_and_result_json_are_one_object_with_the_python_fields, 90)
{
    testdaemon d;
    uint64_t id = completed_job(&d, "--label lab");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr status %llu --json --server %s", (unsigned long long)id,
                       d.unix_addr), 0);
    if (!testjson_valid(out) || out[0] != '{' || strchr(out, '\n') != out + strlen(out) - 1)
        FAILF("status --json is not one JSON object on one line:\n%s", out);
    char want[64];
    snprintf(want, sizeof want, "{\"id\":%llu,\"state\":\"COMPLETED\",", (unsigned long long)id);
    CHECK_STR_HAS(out, want);
    static const char *const fields[] = {"\"priority\":", "\"user\":", "\"label\":\"lab\"", "\"reason\":",
                                         "\"submit_ms\":", "\"start_ms\":", "\"end_ms\":",
                                         "\"progress\":{\"job\":", "\"stage\":\"repair\"",
                                         "\"outer\":2,\"total\":2,\"fraction\":1,\"eta\":",
                                         "\"ahead\":0,", "\"source\":{\"membrane\":", "\"inner\":",
                                         "\"energy\":",
                                         "\"quality\":{\"verdict\":\"ok\",\"flipped\":"};
    for (size_t k = 0; k < sizeof fields / sizeof fields[0]; k++)
        CHECK_STR_HAS(out, fields[k]);
    char P[700];
    snprintf(P, sizeof P, "%s/p.map", harness_tmpdir());
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr result %llu --json --out %s --server %s",
                       (unsigned long long)id, P, d.unix_addr), 0);
    if (!testjson_valid(out) || out[0] != '{')
        FAILF("result --json is not one JSON object:\n%s", out);
    snprintf(want, sizeof want, "{\"id\":%llu,\"metrics\":{", (unsigned long long)id);
    CHECK_STR_HAS(out, want);
    CHECK_STR_HAS(out, "\"flipped_fraction\":");
    CHECK_STR_HAS(out, "\"p_rows\":162,\"q_rows\":162");
    CHECK_STR_HAS(out, "\"out\":\"");
    /* metrics alone, no file */
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr result %llu --json --server %s", (unsigned long long)id,
                       d.unix_addr), 0);
    CHECK(testjson_valid(out));
    CHECK_STR_HAS(out, "\"out\":null");
    testdaemon_stop(&d, SIGTERM);
}

/* The one default address is the socket the shipped config and unit use,
 * in the CLI (MC_DEFAULT_SERVER), the Python package and deploy/; a bare
 * path is a Unix socket; a failed connect names the address once, the
 * reason and what to do; a TCP server without a token says how to give
 * one. */
TEST_T(default_server_bare_paths_and_connect_errors_say_what_to_do, 60)
{
    testdaemon_need_worker();
    size_t len;
    char *conf = (char *)testfile_read("deploy/meshcorrd.conf", &len);
    conf = realloc(conf, len + 1);
    conf[len] = '\0';
    CHECK_STR_HAS(conf, "\nlisten = " MC_DEFAULT_SERVER "\n");
    free(conf);
    char *unit = (char *)testfile_read("deploy/meshcorrd.service", &len);
    unit = realloc(unit, len + 1);
    unit[len] = '\0';
    CHECK_STR_HAS(unit, "\nRuntimeDirectory=meshcorr\n");          /* /run/meshcorr */
    free(unit);
    char *py = (char *)testfile_read("client-c/python/meshcorr/client.py", &len);
    py = realloc(py, len + 1);
    py[len] = '\0';
    CHECK_STR_HAS(py, "return \"" MC_DEFAULT_SERVER "\"");
    free(py);
    CHECK_INT(strcmp(MC_DEFAULT_SERVER, "unix:/run/meshcorr/meshcorrd.sock"), 0);
    struct stat st;
    if (stat(MC_DEFAULT_SERVER + 5, &st) != 0) {    /* no daemon of the machine's own there */
        CHECK_INT(testrunf(out, sizeof out, "env -u MESHCORR_SERVER build/meshcorr list 2>&1"), 1);
        CHECK_STR_HAS(out, "meshcorr list: cannot connect to " MC_DEFAULT_SERVER ": No such file or directory "
                      "(is meshcorrd running there? set MESHCORR_SERVER or --server)");
    }
    CHECK_INT(testrunf(out, sizeof out, "MESHCORR_SERVER=unix:%s/none.sock build/meshcorr stats 2>&1",
                       harness_tmpdir()), 1);
    CHECK_STR_HAS(out, "cannot connect to unix:");
    char *first = strstr(out, "none.sock");
    CHECK(first && !strstr(first + 1, "none.sock"));                 /* the address once */

    testdaemon d;
    testdaemon_start(&d, "d", NULL);
    /* a bare path, absolute and relative */
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr stats --json --server %s 2>&1", d.unix_addr + 5), 0);
    CHECK(testjson_valid(out));
    char here[1024];
    CHECK(getcwd(here, sizeof here));
    CHECK_INT(testrunf(out, sizeof out, "cd %s && %s/build/meshcorr stats --json --server ./sock 2>&1", d.dir,
                       here), 0);
    CHECK(testjson_valid(out));
    /* TCP without a token */
    CHECK_INT(testrunf(out, sizeof out, "env -u MESHCORR_TOKEN build/meshcorr list --server %s 2>&1", d.tcp_addr),
              1);
    char want[2048];
    snprintf(want, sizeof want, "meshcorr list: %s needs a token: --token T, --token-file F or MESHCORR_TOKEN",
             d.tcp_addr);
    CHECK_STR_HAS(out, want);
    /* HOST:PORT without a scheme: TLS first, plain TCP for loopback */
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr list --server %s 2>&1", d.tcp_addr + 4), 1);
    snprintf(want, sizeof want, "did you mean tls:%s (or %s on loopback)?", d.tcp_addr + 4, d.tcp_addr);
    CHECK_STR_HAS(out, want);
    testdaemon_stop(&d, SIGTERM);
}
