/* test_daemon_async.c — the daemon's disk work (storing a SUBMIT, reading a
 * result) runs in libuv's thread pool while the loop goes on serving: many
 * SUBMITs from several clients at once with PINGs in between, all
 * acknowledged with distinct ids and all durable across a SIGKILL; the
 * per-user and queue limits exact with SUBMITs still being stored; a client
 * that hangs up right after sending SUBMIT leaves a stored job that runs,
 * and a daemon that keeps serving; a SIGTERM while SUBMITs are being stored
 * still acknowledges them. Black-box, through the real meshcorrd. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testmesh.h"
#include "mesh/mesh.h"
#include "meshcorr.h"
#include "proto.h"

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <sqlite3.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- many SUBMITs at once ------------------------------------------------- */

#define NCLIENTS 6
#define NSUBMITS 8

typedef struct submitter {
    const testdaemon *d;
    const char *token;            /* NULL: the Unix socket */
    uint64_t ids[NSUBMITS];
    int rc[NSUBMITS], ping_rc;
    char err[256];
} submitter;

static void *submit_thread(void *arg)
{
    submitter *s = arg;
    mc_client *c = NULL;
    int rc = mc_connect(s->token ? s->d->tcp_addr : s->d->unix_addr, s->token, &c, s->err, sizeof s->err);
    if (rc) {
        for (int k = 0; k < NSUBMITS; k++)
            s->rc[k] = rc;
        return NULL;
    }
    mc_set_timeout(c, 30000);
    for (int k = 0; k < NSUBMITS; k++) {
        s->ids[k] = testdaemon_submit(c, 2, 0, 0, &s->rc[k]);
        if (s->rc[k])
            snprintf(s->err, sizeof s->err, "%s", mc_errmsg(c));
        if (!s->ping_rc)
            s->ping_rc = mc_ping(c);          /* the same connection, between SUBMITs */
    }
    mc_close(c);
    return NULL;
}

typedef struct pinger {
    const testdaemon *d;
    volatile int stop;
    int n, rc;
    double max_s;
} pinger;

static void *ping_thread(void *arg)
{
    pinger *p = arg;
    mc_client *c = NULL;
    char err[256];
    if ((p->rc = mc_connect(p->d->unix_addr, NULL, &c, err, sizeof err)) != 0)
        return NULL;
    mc_set_timeout(c, 30000);
    while (!p->stop && !p->rc) {
        double t0 = now_s();
        p->rc = mc_ping(c);
        double dt = now_s() - t0;
        if (dt > p->max_s)
            p->max_s = dt;
        p->n++;
    }
    mc_close(c);
    return NULL;
}

/* The jobs.db row of job id exists and spool/<id>/job.frame is there,
 * unless the job has ended without completing (its input is removed then,
 * its row kept). */
static int stored(const testdaemon *d, uint64_t id)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/jobs.db", d->state);
    sqlite3 *db;
    if (sqlite3_open(path, &db) != SQLITE_OK) {
        sqlite3_close(db);
        return 0;
    }
    sqlite3_stmt *st;
    int row = 0, ended = 0;
    if (sqlite3_prepare_v2(db, "SELECT state IN ('PENDING', 'RUNNING', 'COMPLETED') FROM jobs WHERE id = ?", -1,
                           &st, NULL) == SQLITE_OK) {
        sqlite3_bind_int64(st, 1, (sqlite3_int64)id);
        row = sqlite3_step(st) == SQLITE_ROW;
        ended = row && sqlite3_column_int(st, 0) == 0;
        sqlite3_finalize(st);
    }
    sqlite3_close(db);
    struct stat sb;
    snprintf(path, sizeof path, "%s/spool/%llu/job.frame", d->state, (unsigned long long)id);
    return row && (ended || (stat(path, &sb) == 0 && sb.st_size > 0));
}

/* Six clients (Unix socket and TCP, three users) submit eight jobs each at
 * once, pinging between SUBMITs, while a seventh pings all the time. The
 * worker is /bin/true, so finished jobs write to the store from the loop
 * while SUBMITs commit from the thread pool. */
TEST_T(concurrent_submits_are_all_acknowledged_with_distinct_ids_and_survive_sigkill, 120)
{
    testdaemon d;
    const char *args[] = {"--worker", "/bin/true", "--workers", "2", NULL};
    testdaemon_start(&d, "concurrent", args);
    static const char *tokens[NCLIENTS] = {NULL, TESTDAEMON_ALICE, TESTDAEMON_BOB, TESTDAEMON_ADMIN, NULL,
                                           TESTDAEMON_ALICE};
    static submitter subs[NCLIENTS];
    pthread_t th[NCLIENTS], pt;
    pinger p = {&d, 0, 0, 0, 0};
    CHECK_INT(pthread_create(&pt, NULL, ping_thread, &p), 0);
    double t0 = now_s();
    for (int i = 0; i < NCLIENTS; i++) {
        subs[i].d = &d;
        subs[i].token = tokens[i];
        CHECK_INT(pthread_create(&th[i], NULL, submit_thread, &subs[i]), 0);
    }
    for (int i = 0; i < NCLIENTS; i++)
        pthread_join(th[i], NULL);
    double secs = now_s() - t0;
    p.stop = 1;
    pthread_join(pt, NULL);
    CHECK_INT(p.rc, 0);
    CHECK(p.n > 0);
    for (int i = 0; i < NCLIENTS; i++) {
        CHECK_INT(subs[i].ping_rc, 0);
        for (int k = 0; k < NSUBMITS; k++) {
            if (subs[i].rc[k])
                FAILF("client %d SUBMIT %d: %s (%s)", i, k, mc_strerror(subs[i].rc[k]), subs[i].err);
            CHECK(subs[i].ids[k] > 0);
            for (int j = 0; j <= i; j++)
                for (int l = 0; l < (j == i ? k : NSUBMITS); l++)
                    if (subs[j].ids[l] == subs[i].ids[k])
                        FAILF("job id %llu acknowledged twice", (unsigned long long)subs[i].ids[k]);
        }
    }
    printf("  %d SUBMITs from %d clients in %.2f s; %d PINGs meanwhile, slowest %.1f ms\n",
           NCLIENTS * NSUBMITS, NCLIENTS, secs, p.n, 1e3 * p.max_s);
    /* every acknowledged job is on disk, even after SIGKILL */
    testdaemon_kill(&d);
    for (int i = 0; i < NCLIENTS; i++)
        for (int k = 0; k < NSUBMITS; k++)
            if (!stored(&d, subs[i].ids[k]))
                FAILF("acknowledged job %llu not in the store after SIGKILL", (unsigned long long)subs[i].ids[k]);
    /* and the restarted daemon knows them all, with nothing else */
    testdaemon_start(&d, "concurrent", args);
    mc_client *boss = testdaemon_client(&d, TESTDAEMON_ADMIN);
    static const char *users[] = {"alice", "bob", "boss"};
    uint32_t total = 0;
    for (int u = 0; u < 3; u++) {
        mc_job_info *jobs = NULL;
        uint32_t n = 0;
        CHECK_INT(mc_list(boss, users[u], 0, &jobs, &n), 0);
        for (uint32_t j = 0; j < n; j++) {
            int seen = 0;
            for (int i = 0; i < NCLIENTS; i++)
                for (int k = 0; k < NSUBMITS; k++)
                    seen += subs[i].ids[k] == jobs[j].job_id;
            CHECK_INT(seen, 1);
        }
        total += n;
        free(jobs);
    }
    /* the Unix-socket clients' user is whoever runs the test */
    mc_client *me = testdaemon_client(&d, NULL);
    mc_job_info *jobs = NULL;
    uint32_t n = 0;
    CHECK_INT(mc_list(me, NULL, 0, &jobs, &n), 0);
    if (strcmp(mc_user(me), "alice") && strcmp(mc_user(me), "bob") && strcmp(mc_user(me), "boss"))
        total += n;
    free(jobs);
    CHECK_INT(total, NCLIENTS * NSUBMITS);
    CHECK_INT(mc_ping(me), 0);
    mc_close(me);
    mc_close(boss);
    testdaemon_stop(&d, SIGTERM);
}

/* ---- limits with SUBMITs in flight ----------------------------------------- */

#define NLIMIT_CLIENTS 4
#define NLIMIT_SUBMITS 3

typedef struct limit_run {
    const testdaemon *d;
    const char *token;
    int ok, user_limit, queue_full, other;
} limit_run;

static void *limit_thread(void *arg)
{
    limit_run *r = arg;
    mc_client *c = NULL;
    char err[256];
    if (mc_connect(r->d->tcp_addr, r->token, &c, err, sizeof err)) {
        r->other++;
        return NULL;
    }
    mc_set_timeout(c, 30000);
    for (int k = 0; k < NLIMIT_SUBMITS; k++) {
        int rc;
        testdaemon_submit(c, 2, 0, 0, &rc);
        r->ok += rc == 0;
        r->user_limit += rc == MC_EUSER_LIMIT;
        r->queue_full += rc == MC_EQUEUE_FULL;
        r->other += rc != 0 && rc != MC_EUSER_LIMIT && rc != MC_EQUEUE_FULL;
    }
    mc_close(c);
    return NULL;
}

/* Runs NLIMIT_CLIENTS connections of one user, all submitting at once;
 * sums what they got. */
static limit_run limit_burst(const testdaemon *d, const char *token)
{
    static limit_run runs[NLIMIT_CLIENTS];
    pthread_t th[NLIMIT_CLIENTS];
    for (int i = 0; i < NLIMIT_CLIENTS; i++) {
        runs[i] = (limit_run){d, token, 0, 0, 0, 0};
        CHECK_INT(pthread_create(&th[i], NULL, limit_thread, &runs[i]), 0);
    }
    limit_run sum = {d, token, 0, 0, 0, 0};
    for (int i = 0; i < NLIMIT_CLIENTS; i++) {
        pthread_join(th[i], NULL);
        sum.ok += runs[i].ok;
        sum.user_limit += runs[i].user_limit;
        sum.queue_full += runs[i].queue_full;
        sum.other += runs[i].other;
    }
    return sum;
}

/* The one slot runs bob's long job, so everything else stays pending. Many
 * SUBMITs at once must not overshoot the limits while earlier ones are
 * still being stored: alice gets exactly --max-jobs-per-user, and bob (one
 * running) exactly what fills --max-queue. */
TEST_T(user_limit_and_full_queue_hold_exactly_with_many_submits_in_flight, 90)
{
    testdaemon_need_worker();
    testdaemon d;
    const char *args[] = {"--max-jobs-per-user", "4", "--max-queue", "6", NULL};
    testdaemon_start(&d, "limits", args);
    mc_client *bob = testdaemon_client(&d, TESTDAEMON_BOB);
    int rc;
    uint64_t run = testdaemon_submit(bob, 1000, 1, 0, &rc);
    CHECK_INT(rc, 0);
    testdaemon_wait_state(bob, run, MC_RUNNING, 20);
    limit_run a = limit_burst(&d, TESTDAEMON_ALICE);
    CHECK_INT(a.other, 0);
    CHECK_INT(a.ok, 4);
    CHECK_INT(a.user_limit, NLIMIT_CLIENTS * NLIMIT_SUBMITS - 4);
    limit_run b = limit_burst(&d, TESTDAEMON_BOB);
    CHECK_INT(b.other, 0);
    CHECK_INT(b.ok, 2);                         /* 4 + 2 pending = --max-queue */
    CHECK_INT(b.queue_full, NLIMIT_CLIENTS * NLIMIT_SUBMITS - 2);
    /* the store holds exactly what was acknowledged */
    mc_client *boss = testdaemon_client(&d, TESTDAEMON_ADMIN);
    mc_job_info *jobs = NULL;
    uint32_t n = 0;
    CHECK_INT(mc_list(boss, "alice", 0, &jobs, &n), 0);
    CHECK_INT(n, 4);
    free(jobs);
    CHECK_INT(mc_list(boss, "bob", 0, &jobs, &n), 0);
    CHECK_INT(n, 3);
    free(jobs);
    mc_server_stats st;
    CHECK_INT(mc_stats(boss, &st), 0);
    CHECK_INT(st.queued, 6);
    mc_stats_free(&st);
    CHECK_INT(mc_cancel(bob, run), 0);
    mc_close(boss);
    mc_close(bob);
    testdaemon_stop(&d, SIGTERM);
}

/* ---- a client that hangs up right after SUBMIT ----------------------------- */

static int sock_unix(const testdaemon *d)
{
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    snprintf(sa.sun_path, sizeof sa.sun_path, "%s", d->unix_addr + 5);
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0)
        FAILF("connect %s: %s", sa.sun_path, strerror(errno));
    return fd;
}

static void send_msg(int fd, proto_msg *m)
{
    proto_buf b;
    char err[256];
    proto_buf_init(&b);
    if (proto_msg_encode(&b, m, err, sizeof err))
        FAILF("encode: %s", err);
    for (size_t off = 0; off < b.len;) {
        ssize_t w = write(fd, b.data + off, b.len - off);
        if (w <= 0)
            FAILF("write: %s", strerror(errno));
        off += (size_t)w;
    }
    proto_buf_free(&b);
}

static void read_exact(int fd, void *buf, size_t n)
{
    for (size_t off = 0; off < n;) {
        ssize_t r = read(fd, (char *)buf + off, n - off);
        if (r <= 0)
            FAILF("read: %s", r ? strerror(errno) : "EOF");
        off += (size_t)r;
    }
}

/* HELLO on a raw Unix-socket connection (peer credentials); waits for HELLO_OK. */
static int raw_session(const testdaemon *d)
{
    int fd = sock_unix(d);
    proto_msg m;
    memset(&m, 0, sizeof m);
    m.type = PROTO_MSG_HELLO;
    m.request_id = 1;
    m.u.hello = (proto_hello){PROTO_VERSION, "", "test_daemon_async"};
    send_msg(fd, &m);
    uint8_t hdr[PROTO_HDR_SIZE];
    read_exact(fd, hdr, sizeof hdr);
    proto_hdr h;
    char err[256];
    if (proto_frame_scan(hdr, sizeof hdr, PROTO_MAX_FRAME, &h, err, sizeof err) < 0)
        FAILF("HELLO reply: %s", err);
    CHECK_INT(h.type, PROTO_MSG_HELLO_OK);
    uint8_t *payload = malloc(h.payload_len + 1);
    CHECK(payload != NULL);
    read_exact(fd, payload, h.payload_len);
    free(payload);
    return fd;
}

/* A SUBMIT of the icosphere pair (the same job testdaemon_submit sends). */
static void sphere_submit(proto_msg *m, unsigned char **sb, unsigned char **tb, const char *label)
{
    mesh *S = testmesh_icosphere(2), *T = testmesh_icosphere(2);
    CHECK(S && T);
    for (int i = 0; i < T->nv; i++) {
        double *x = &T->v[3 * i];
        x[0] *= 1.3;
        x[2] += 0.15 * x[0] * x[0];
    }
    size_t sl, tl;
    char err[256];
    CHECK_INT(mc_encode_mesh(S->v, S->nv, S->f, S->nf, sb, &sl, err, sizeof err), 0);
    CHECK_INT(mc_encode_mesh(T->v, T->nv, T->f, T->nf, tb, &tl, err, sizeof err), 0);
    mesh_free(S);
    mesh_free(T);
    static proto_landmark lm[6] = {{0, 0}, {1, 1}, {2, 2}, {3, 3}, {4, 4}, {5, 5}};
    mc_job_spec s;
    mc_job_spec_init(&s);
    memset(m, 0, sizeof *m);
    m->type = PROTO_MSG_SUBMIT;
    m->request_id = 2;
    proto_submit *u = &m->u.submit;
    u->source = (proto_blob){*sb, (uint32_t)sl};
    u->target = (proto_blob){*tb, (uint32_t)tl};
    u->landmarks = lm;
    u->nlandmarks = 6;
    proto_params *p = &u->params;
    p->model = (uint8_t)s.model;
    p->alpha = s.alpha;
    p->eta = s.eta;
    p->beta0 = s.beta0;
    p->beta1 = s.beta1;
    p->beta_ramp = 2;
    p->gamma = s.gamma;
    p->iterations = 2;
    p->inner_iterations = 10;
    p->tolerance = s.tolerance;
    p->stop_change = 0;
    p->rhm_iterations = 3;
    p->rhm_dim = s.rhm_dim;
    p->rhm_alpha = s.rhm_alpha;
    p->rhm_landmark_weight = s.rhm_landmark_weight;
    p->backend = "";
    u->label = label;
}

TEST_T(client_that_hangs_up_right_after_submit_leaves_a_stored_job_that_runs, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "hangup", NULL);
    proto_msg m;
    unsigned char *sb, *tb;
    sphere_submit(&m, &sb, &tb, "hung up after SUBMIT");
    for (int round = 0; round < 3; round++) {
        int fd = raw_session(&d);
        send_msg(fd, &m);
        close(fd);                              /* never reads SUBMIT_OK */
    }
    free(sb);
    free(tb);
    /* the daemon serves on; the three jobs were stored, queued, and run */
    mc_client *c = testdaemon_client(&d, NULL);
    CHECK_INT(mc_ping(c), 0);
    mc_job_info *jobs = NULL;
    uint32_t n = 0;
    double t0 = now_s();
    do {
        free(jobs);
        jobs = NULL;
        CHECK_INT(mc_list(c, NULL, 0, &jobs, &n), 0);
    } while (n < 3 && now_s() - t0 < 10 && usleep(20000) == 0);
    CHECK_INT(n, 3);
    for (uint32_t j = 0; j < n; j++) {
        CHECK(strcmp(jobs[j].label, "hung up after SUBMIT") == 0);
        CHECK_INT(testdaemon_wait_state(c, jobs[j].job_id, -1, 30), MC_COMPLETED);
    }
    free(jobs);
    mc_close(c);
    /* the log says so when the hang-up came before the store finished (it
     * nearly always does: the store fsyncs) */
    printf("  log names a job stored for a client that hung up: %s\n",
           testdaemon_log_has(&d, "hung up before SUBMIT_OK") ? "yes" : "no (SUBMIT_OK was sent before the hang-up)");
    c = testdaemon_client(&d, TESTDAEMON_BOB);
    CHECK_INT(mc_ping(c), 0);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* SIGTERM while SUBMITs are being stored: each is acknowledged (or refused
 * as SHUTTING_DOWN if it came after the signal), and what was acknowledged
 * is there after the restart. */
typedef struct term_run {
    const testdaemon *d;
    uint64_t ids[64];
    int n, last_rc;
} term_run;

static void *term_submit_thread(void *arg)
{
    term_run *r = arg;
    mc_client *c = NULL;
    char err[256];
    if (mc_connect(r->d->unix_addr, NULL, &c, err, sizeof err))
        return NULL;
    mc_set_timeout(c, 30000);
    while (r->n < 64) {
        int rc;
        uint64_t id = testdaemon_submit(c, 2, 0, 0, &rc);
        if (rc) {
            r->last_rc = rc;
            break;
        }
        r->ids[r->n++] = id;
    }
    mc_close(c);
    return NULL;
}

TEST_T(sigterm_while_submits_are_stored_acknowledges_them_and_keeps_them, 60)
{
    testdaemon d;
    const char *args[] = {"--worker", "/bin/true", "--max-jobs-per-user", "1000", NULL};
    testdaemon_start(&d, "term", args);
    static term_run runs[3];
    pthread_t th[3];
    for (int i = 0; i < 3; i++) {
        runs[i].d = &d;
        CHECK_INT(pthread_create(&th[i], NULL, term_submit_thread, &runs[i]), 0);
    }
    usleep(150000);
    CHECK_INT(kill(d.pid, SIGTERM), 0);
    for (int i = 0; i < 3; i++)
        pthread_join(th[i], NULL);
    testdaemon_stop(&d, 0);                /* no second signal: wait for the exit */
    CHECK(testdaemon_log_has(&d, "drained: no worker running, no request in the thread pool"));
    int acked = 0;
    for (int i = 0; i < 3; i++) {
        /* the SUBMIT after the last one acknowledged failed: refused or cut off */
        CHECK(runs[i].n == 64 || runs[i].last_rc != 0);
        for (int k = 0; k < runs[i].n; k++, acked++)
            if (!stored(&d, runs[i].ids[k]))
                FAILF("acknowledged job %llu not in the store after SIGTERM", (unsigned long long)runs[i].ids[k]);
    }
    printf("  %d SUBMITs acknowledged before the drain closed the connections\n", acked);
    CHECK(acked > 0);
}
