/* test_daemon_refusals.c — every SUBMIT that can never run is refused before
 * SUBMIT_OK, over the raw protocol (what any non-CLI client may send), with
 * an ERROR naming the blob or field, and nothing is stored: a landmark id
 * past the decoded vertex count, random bytes as Draco, half a Draco file,
 * a non-manifold mesh (all four checked in the sandboxed validator), and
 * parameters out of range (the one validator), and any SUBMIT when the
 * validator program is missing. The daemon keeps serving,
 * answers other clients while a check runs, runs a good job, and exits 0
 * on SIGTERM. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testmesh.h"
#include "mesh/mesh.h"
#include "proto.h"

#include <dirent.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* A raw SUBMIT of the level-2 icosphere pair (162 vertices each), 6
 * identity landmarks, the list's defaults but 2 iterations. */
typedef struct raw_submit {
    proto_msg msg;
    unsigned char *sb, *tb;
    proto_landmark lm[6];
} raw_submit;

static void raw_init(raw_submit *r)
{
    char err[256];
    memset(r, 0, sizeof *r);
    mesh *S = testmesh_icosphere(2);
    size_t sl, tl;
    CHECK_INT(mesh_encode_drc(S, &r->sb, &sl, err, sizeof err), 0);
    CHECK_INT(mesh_encode_drc(S, &r->tb, &tl, err, sizeof err), 0);
    mesh_free(S);
    r->msg.type = PROTO_MSG_SUBMIT;
    r->msg.request_id = 7;
    proto_submit *s = &r->msg.u.submit;
    s->source = (proto_blob){r->sb, (uint32_t)sl};
    s->target = (proto_blob){r->tb, (uint32_t)tl};
    for (uint32_t i = 0; i < 6; i++)
        r->lm[i] = (proto_landmark){i * 20, i * 20};
    s->landmarks = r->lm;
    s->nlandmarks = 6;
    proto_params_init(&s->params);
    s->params.iterations = 2;
    s->params.beta_ramp = 2;
    s->params.rhm_iterations = 2;
    s->label = "raw";
}

static void raw_close(raw_submit *r)
{
    free(r->sb);
    free(r->tb);
}

/* Sends r as raw bytes; returns the reply's code (0: SUBMIT_OK). */
static int raw_send(mc_client *c, const raw_submit *r)
{
    proto_buf b;
    char err[256];
    proto_buf_init(&b);
    CHECK_INT(proto_msg_encode(&b, &r->msg, err, sizeof err), 0);
    int rc = mc_send_raw(c, b.data, b.len);
    proto_buf_free(&b);
    return rc;
}

static void check_nothing_stored(const testdaemon *d)
{
    mc_client *c = testdaemon_client(d, TESTDAEMON_ADMIN);
    mc_job_info *jobs = NULL;
    uint32_t n = 99;
    CHECK_INT(mc_list(c, "alice", 0, &jobs, &n), 0);
    CHECK_INT(n, 0);
    free(jobs);
    mc_job_status js;
    CHECK_INT(mc_status(c, 1, &js), MC_ENOT_FOUND);
    mc_server_stats st;
    CHECK_INT(mc_stats(c, &st), 0);
    CHECK_INT(st.queued, 0);
    mc_stats_free(&st);
    mc_close(c);
}

/* Refused with code, and the message has both parts. */
static void expect_refusal(mc_client *c, const raw_submit *r, int code, const char *what,
                           const char *detail)
{
    int rc = raw_send(c, r);
    if (rc != code)
        FAILF("%s: got %d (%s), want %s: %s", what, rc, proto_err_name(rc), proto_err_name(code),
              mc_errmsg(c));
    printf("  %s\n", mc_errmsg(c));
    CHECK_STR_HAS(mc_errmsg(c), what);
    if (detail)
        CHECK_STR_HAS(mc_errmsg(c), detail);
}

TEST_T(meshes_and_landmarks_that_cannot_run_are_refused_naming_the_blob, 90)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "refuse-mesh", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    raw_submit r;
    raw_init(&r);
    proto_submit *s = &r.msg.u.submit;

    r.lm[3].tgt = 500;                                   /* 162 vertices: 0..161 */
    expect_refusal(c, &r, PROTO_EBAD_LANDMARKS, "landmark 4", "target vertex 500 out of range [0, 161]");
    r.lm[3].tgt = 60;

    unsigned char junk[300];
    unsigned long long seed = 99;
    for (size_t i = 0; i < sizeof junk; i++)
        junk[i] = (unsigned char)(testmesh_rand(&seed) * 256);
    proto_blob good = s->source;
    s->source = (proto_blob){junk, sizeof junk};
    expect_refusal(c, &r, PROTO_EBAD_MESH, "source mesh", NULL);
    s->source = good;

    good = s->target;
    s->target.len /= 2;                                  /* half a Draco file */
    expect_refusal(c, &r, PROTO_EBAD_MESH, "target mesh", NULL);
    s->target = good;

    /* one more face on an existing edge: three faces meet there */
    mesh *S = testmesh_icosphere(2), *N = mesh_new(S->nv + 1, S->nf + 1);
    memcpy(N->v, S->v, sizeof(double) * 3 * (size_t)S->nv);
    memcpy(N->f, S->f, sizeof(int) * 3 * (size_t)S->nf);
    N->v[3 * S->nv] = 2;
    N->v[3 * S->nv + 1] = N->v[3 * S->nv + 2] = 0;
    N->f[3 * S->nf] = S->f[0];
    N->f[3 * S->nf + 1] = S->f[1];
    N->f[3 * S->nf + 2] = S->nv;
    unsigned char *nb;
    size_t nl;
    char err[256];
    CHECK_INT(mesh_encode_drc(N, &nb, &nl, err, sizeof err), 0);
    s->source = (proto_blob){nb, (uint32_t)nl};
    s->params.repair = 1;                                /* "no": refused as it is */
    expect_refusal(c, &r, PROTO_EBAD_MESH, "source mesh", "non-manifold");
    s->params.repair = 0;
    free(nb);
    mesh_free(N);
    mesh_free(S);

    check_nothing_stored(&d);
    /* the same SUBMIT, repaired, is accepted and runs */
    raw_close(&r);
    raw_init(&r);
    CHECK_INT(raw_send(c, &r), 0);
    CHECK_INT(testdaemon_wait_state(c, 1, -1, 60), MC_COMPLETED);
    raw_close(&r);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);          /* fails unless the daemon exits 0 */
}

TEST_T(parameters_out_of_range_are_refused_naming_the_field, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "refuse-params", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    raw_submit r;
    raw_init(&r);
    proto_params *p = &r.msg.u.submit.params, keep = *p;
    p->inner_iterations = 500000;
    expect_refusal(c, &r, PROTO_EBAD_PARAMS, "inner_iterations = 500000: out of range [1, 100000]", NULL);
    *p = keep;
    p->rhm_alpha = 2;
    expect_refusal(c, &r, PROTO_EBAD_PARAMS, "rhm_alpha = 2: out of range (0, 1); 0 = the default", NULL);
    *p = keep;
    p->rhm_dim = 100000;
    expect_refusal(c, &r, PROTO_EBAD_PARAMS, "rhm_dim = 100000: out of range [3, 64]; 0 = the default", NULL);
    *p = keep;
    p->alpha = -1;
    expect_refusal(c, &r, PROTO_EBAD_PARAMS, "alpha = -1: out of range (0, inf)", NULL);
    *p = keep;
    r.msg.u.submit.nlandmarks = 2;                       /* 3 pairs at least, everywhere */
    expect_refusal(c, &r, PROTO_EBAD_LANDMARKS, "2 landmark pairs, at least 3", NULL);
    r.msg.u.submit.nlandmarks = 3;
    check_nothing_stored(&d);
    CHECK_INT(raw_send(c, &r), 0);                       /* 3 pairs are enough */
    raw_close(&r);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* Without its validator program the daemon starts, says so in its log, and
 * refuses every SUBMIT (INTERNAL, naming the program) storing nothing; it
 * keeps serving and exits 0. */
TEST_T(a_missing_validator_is_logged_and_every_submit_refused_naming_it, 60)
{
    testdaemon d;
    const char *args[] = {"--validator", "/nonexistent/meshcorr-validate", NULL};
    testdaemon_start(&d, "refuse-novalidator", args);
    CHECK(testdaemon_log_has(&d, "validator program /nonexistent/meshcorr-validate is not executable"));
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    raw_submit r;
    raw_init(&r);
    expect_refusal(c, &r, PROTO_EINTERNAL, "cannot start /nonexistent/meshcorr-validate", NULL);
    CHECK_INT(mc_ping(c), 0);
    check_nothing_stored(&d);
    raw_close(&r);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* Pid of a meshcorr-validate child of the daemon, or -1. */
static pid_t validator_pid(const testdaemon *d)
{
    DIR *dp = opendir("/proc");
    struct dirent *de;
    pid_t found = -1;
    while (dp && found < 0 && (de = readdir(dp))) {
        pid_t pid = (pid_t)atoi(de->d_name);
        char path[64], buf[4096];
        if (pid <= 0)
            continue;
        snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
        FILE *fp = fopen(path, "r");
        int ppid = -1;
        if (fp && fgets(buf, sizeof buf, fp) && strrchr(buf, ')'))
            sscanf(strrchr(buf, ')') + 2, "%*c %d", &ppid);
        if (fp)
            fclose(fp);
        if (ppid != d->pid)
            continue;
        snprintf(path, sizeof path, "/proc/%d/cmdline", (int)pid);
        if (!(fp = fopen(path, "r")))
            continue;
        size_t n = fread(buf, 1, sizeof buf - 1, fp);
        fclose(fp);
        buf[n] = '\0';
        const char *base = strrchr(buf, '/');
        if (n && strcmp(base ? base + 1 : buf, "meshcorr-validate") == 0)
            found = pid;
    }
    if (dp)
        closedir(dp);
    return found;
}

typedef struct big_submit {
    const testdaemon *d;
    raw_submit r;
    int rc;
} big_submit;

static void *big_submit_thread(void *arg)
{
    big_submit *b = arg;
    mc_client *c = testdaemon_client(b->d, TESTDAEMON_ALICE);
    mc_set_timeout(c, 120000);
    b->rc = raw_send(c, &b->r);
    mc_close(c);
    return NULL;
}

/* A SUBMIT of a 163842-vertex pair (refused at the end, for a landmark id
 * past the decoded count) keeps its validator busy long enough to be seen;
 * a PING from another client is answered while that child still runs: the
 * check blocks a thread-pool thread, never the event loop. */
TEST_T(other_clients_are_answered_while_a_submit_is_checked, 120)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "refuse-loop", NULL);
    big_submit b;
    memset(&b, 0, sizeof b);
    b.d = &d;
    b.rc = 1;
    raw_init(&b.r);
    mesh *S = testmesh_icosphere(7);
    char err[256];
    size_t len;
    free(b.r.sb);
    CHECK_INT(mesh_encode_drc(S, &b.r.sb, &len, err, sizeof err), 0);
    b.r.msg.u.submit.source = b.r.msg.u.submit.target = (proto_blob){b.r.sb, (uint32_t)len};
    b.r.lm[5].tgt = (uint32_t)S->nv;           /* found after both meshes: nothing runs */
    mesh_free(S);
    mc_client *other = testdaemon_client(&d, TESTDAEMON_BOB);
    pthread_t th;
    CHECK_INT(pthread_create(&th, NULL, big_submit_thread, &b), 0);
    pid_t v = -1;
    for (int tries = 0; tries < 20000 && v < 0; tries++) {
        v = validator_pid(&d);
        if (v < 0)
            nanosleep(&(struct timespec){0, 200000}, NULL);
    }
    CHECK(v > 0);                                       /* the check is running */
    CHECK_INT(mc_ping(other), 0);
    char path[64];
    snprintf(path, sizeof path, "/proc/%d", (int)v);
    int still = access(path, F_OK) == 0;
    pthread_join(th, NULL);
    printf("  validator %d %s when the PONG came\n", (int)v, still ? "still running" : "already gone");
    CHECK(still);
    CHECK_INT(b.rc, PROTO_EBAD_LANDMARKS);              /* and then the SUBMIT was refused */
    mc_close(other);
    raw_close(&b.r);
    testdaemon_stop(&d, SIGTERM);
}
