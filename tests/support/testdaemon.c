/* testdaemon.c — starting, stopping and feeding the real meshcorrd in
 * tests (see testdaemon.h). Test code only. */
#include "support/testdaemon.h"
#include "support/harness.h"
#include "support/testmesh.h"
#include "mesh/mesh.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <gnutls/crypto.h>
#include <gnutls/gnutls.h>
#include <pwd.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define DAEMON "build/meshcorrd"
#define WORKER "build/meshcorr-worker"

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

void testdaemon_need_worker(void)
{
    if (access(WORKER, X_OK) != 0)
        SKIP("%s not built (the worker branch provides it)", WORKER);
}

const char *testdaemon_user(void)
{
    return geteuid() == 0 ? TESTDAEMON_USER : NULL;
}

void testdaemon_give(const char *path)
{
    if (geteuid() != 0)
        return;
    struct passwd *pw = getpwnam(TESTDAEMON_USER);
    if (!pw)
        FAILF("no user %s to run meshcorrd as (tests run as root): deploy/install-deps.sh creates it",
              TESTDAEMON_USER);
    if (chown(path, pw->pw_uid, pw->pw_gid) != 0)
        FAILF("chown %s to %s: %s", path, TESTDAEMON_USER, strerror(errno));
}

/* Run as root: the daemon's --user is TESTDAEMON_USER, and the harness's
 * directory and d's (its socket, port file and tokens) are that user's, so
 * it can reach its state directory and read its files on SIGHUP after the
 * drop. NULL when not root (the daemon runs as the test does). */
static const char *run_as(const testdaemon *d, const char *tokens)
{
    const char *mine[] = {harness_tmpdir(), d->dir, tokens};
    for (size_t i = 0; i < sizeof mine / sizeof mine[0]; i++)
        testdaemon_give(mine[i]);
    return testdaemon_user();
}

#define READY "meshcorrd ready:"

int testdaemon_log_count(const testdaemon *d, const char *what)
{
    FILE *fp = fopen(d->log, "r");
    if (!fp)
        return 0;
    char line[4096];
    int n = 0;
    while (fgets(line, sizeof line, fp))
        n += strstr(line, what) != NULL;
    fclose(fp);
    return n;
}

void testdaemon_start(testdaemon *d, const char *name, const char *const *args)
{
    snprintf(d->dir, sizeof d->dir, "%s/%s", harness_tmpdir(), name);
    snprintf(d->state, sizeof d->state, "%s/state", d->dir);
    snprintf(d->log, sizeof d->log, "%s/meshcorrd.log", d->dir);
    snprintf(d->unix_addr, sizeof d->unix_addr, "unix:%s/sock", d->dir);
    mkdir(d->dir, 0700);
    char tokens[640], port[640], listen_unix[640];
    snprintf(tokens, sizeof tokens, "%s/tokens", d->dir);
    snprintf(port, sizeof port, "%s/port", d->dir);
    snprintf(listen_unix, sizeof listen_unix, "%s", d->unix_addr);
    char lines[3][256], text[1024];
    testdaemon_token_line(TESTDAEMON_ALICE, "alice", 0, lines[0], sizeof lines[0]);
    testdaemon_token_line(TESTDAEMON_BOB, "bob", 0, lines[1], sizeof lines[1]);
    testdaemon_token_line(TESTDAEMON_ADMIN, "boss", 1, lines[2], sizeof lines[2]);
    snprintf(text, sizeof text, "# sha256:HEX user [admin]\n%s\n%s\n%s\n", lines[0], lines[1], lines[2]);
    testdaemon_write_tokens(tokens, text);
    FILE *fp;
    unlink(port);
    const char *argv[64];
    int k = 0;
    argv[k++] = DAEMON;
    argv[k++] = "--state-dir"; argv[k++] = d->state;
    argv[k++] = "--listen";    argv[k++] = listen_unix;
    argv[k++] = "--listen";    argv[k++] = "tcp:127.0.0.1:0";
    argv[k++] = "--port-file"; argv[k++] = port;
    argv[k++] = "--tokens";    argv[k++] = tokens;
    argv[k++] = "--log-level"; argv[k++] = "debug";
    argv[k++] = "--threads-per-worker"; argv[k++] = "1";
    const char *user = run_as(d, tokens);
    if (user) {
        argv[k++] = "--user";  argv[k++] = user;
    }
    for (int i = 0; args && args[i] && k < 62; i++)
        argv[k++] = args[i];
    argv[k] = NULL;
    int ready = testdaemon_log_count(d, READY);
    fflush(stdout);
    fflush(stderr);
    pid_t parent = getpid();
    d->pid = fork();
    if (d->pid < 0)
        FAILF("fork: %s", strerror(errno));
    if (d->pid == 0) {
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent)
            _exit(127);
        int fd = open(d->log, O_WRONLY | O_CREAT | O_APPEND, 0600);
        if (fd >= 0) {
            dup2(fd, 2);
            close(fd);
        }
        /* as a service manager starts it: the daemon sets the OpenMP wait
         * policy its workers inherit (the harness's own would hide a
         * re-exec per job, bench_daemon's small job) */
        unsetenv("OMP_WAIT_POLICY");
        execv(DAEMON, (char **)argv);
        _exit(127);
    }
    for (int i = 0; i < 1000; i++) {      /* up to 10 s */
        fp = fopen(port, "r");
        if (fp) {
            /* the tcp: listener's line first, then those of args */
            int ok = fscanf(fp, "%63s", d->tcp_addr) == 1;
            char more[64];
            d->tls_addr[0] = '\0';
            while (ok && fscanf(fp, "%63s", more) == 1)
                if (!d->tls_addr[0] && strncmp(more, "tls:", 4) == 0)
                    snprintf(d->tls_addr, sizeof d->tls_addr, "%s", more);
            fclose(fp);
            /* the port file is written with the binds, before the drop from
             * root: the daemon is started once it says it is ready */
            if (ok && testdaemon_log_count(d, READY) > ready)
                return;
        }
        int st;
        if (waitpid(d->pid, &st, WNOHANG) == d->pid)
            FAILF("meshcorrd exited at start (status %d); log %s", st, d->log);
        sleep_ms(10);
    }
    FAILF("meshcorrd did not write its port file and say it is ready; log %s", d->log);
}

void testdaemon_token_line(const char *token, const char *user, int admin, char *line, size_t sz)
{
    unsigned char h[32];
    if (gnutls_hash_fast(GNUTLS_DIG_SHA256, token, strlen(token), h) != 0)
        FAILF("gnutls_hash_fast failed");
    int n = snprintf(line, sz, "sha256:");
    for (int i = 0; i < 32; i++)
        n += snprintf(line + n, sz - (size_t)n, "%02x", h[i]);
    snprintf(line + n, sz - (size_t)n, " %s%s", user, admin ? " admin" : "");
}

void testdaemon_write_tokens(const char *path, const char *text)
{
    char tmp[1100];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    size_t n = strlen(text);
    if (fd < 0 || fchmod(fd, 0600) != 0 || write(fd, text, n) != (ssize_t)n || close(fd) != 0)
        FAILF("cannot write %s: %s", tmp, strerror(errno));
    testdaemon_give(tmp);                  /* the daemon reads it again, as its user, on SIGHUP */
    if (rename(tmp, path) != 0)
        FAILF("rename %s: %s", path, strerror(errno));
}

/* "exit status N" / "killed by signal N (NAME)" for a wait status. */
static const char *status_text(int st, char *buf, size_t sz)
{
    if (WIFEXITED(st))
        snprintf(buf, sz, "exit status %d", WEXITSTATUS(st));
    else if (WIFSIGNALED(st))
        snprintf(buf, sz, "killed by signal %d (%s)%s", WTERMSIG(st), strsignal(WTERMSIG(st)),
                 WCOREDUMP(st) ? ", core dumped" : "");
    else
        snprintf(buf, sz, "wait status %#x", st);
    return buf;
}

/* The daemon's wait status once it has exited, waiting at most ms; -1 if it
 * still runs. */
static int reap(testdaemon *d, int ms)
{
    int st;
    for (int i = 0; i <= ms / 10; i++) {
        if (waitpid(d->pid, &st, WNOHANG) == d->pid) {
            d->pid = 0;
            return st;
        }
        if (i < ms / 10)
            sleep_ms(10);
    }
    return -1;
}

void testdaemon_stop(testdaemon *d, int sig)
{
    char what[128];
    if (d->pid <= 0)
        FAILF("testdaemon_stop: meshcorrd is not running");
    if (sig)
        kill(d->pid, sig);
    int st = reap(d, 20000);
    if (st == -1) {
        kill(d->pid, SIGKILL);
        waitpid(d->pid, &st, 0);
        d->pid = 0;
        FAILF("meshcorrd did not exit within 20 s of signal %d; log %s", sig, d->log);
    }
    if (!WIFEXITED(st) || WEXITSTATUS(st) != 0)
        FAILF("meshcorrd stopped with signal %d ended with %s, not exit status 0; log %s", sig,
              status_text(st, what, sizeof what), d->log);
}

void testdaemon_kill(testdaemon *d)
{
    char what[128];
    if (d->pid <= 0)
        FAILF("testdaemon_kill: meshcorrd is not running");
    int st = reap(d, 0);
    if (st != -1)
        FAILF("meshcorrd had already ended (%s) before the test's SIGKILL; log %s",
              status_text(st, what, sizeof what), d->log);
    kill(d->pid, SIGKILL);
    waitpid(d->pid, &st, 0);
    d->pid = 0;
    if (!WIFSIGNALED(st) || WTERMSIG(st) != SIGKILL)
        FAILF("meshcorrd ended with %s, not by the test's SIGKILL; log %s", status_text(st, what, sizeof what),
              d->log);
}

int testdaemon_prlimit(const testdaemon *d, int resource, const struct rlimit *new_limit, struct rlimit *old_limit)
{
    if (prlimit(d->pid, resource, new_limit, old_limit) == 0)
        return 0;
    if (errno != EPERM || geteuid() != 0)
        return -1;
    struct passwd *pw = getpwnam(TESTDAEMON_USER);
    int fd[2];
    if (!pw || pipe(fd) != 0)
        return -1;
    pid_t pid = fork();
    if (pid == 0) {
        struct { int rc, err; struct rlimit old; } r = {0, 0, {0, 0}};
        if (setgid(pw->pw_gid) != 0 || setuid(pw->pw_uid) != 0 ||
            prlimit(d->pid, resource, new_limit, &r.old) != 0)
            r.rc = -1, r.err = errno;
        _exit(write(fd[1], &r, sizeof r) == (ssize_t)sizeof r ? 0 : 1);
    }
    close(fd[1]);
    struct { int rc, err; struct rlimit old; } r = {-1, EIO, {0, 0}};
    ssize_t n = pid > 0 ? read(fd[0], &r, sizeof r) : -1;
    close(fd[0]);
    if (pid > 0)
        waitpid(pid, NULL, 0);
    if (n != (ssize_t)sizeof r)
        r.rc = -1, r.err = EIO;
    if (r.rc == 0 && old_limit)
        *old_limit = r.old;
    errno = r.err;
    return r.rc;
}

mc_client *testdaemon_client(const testdaemon *d, const char *token)
{
    mc_client *c = NULL;
    char err[1024];
    int rc = mc_connect(token ? d->tcp_addr : d->unix_addr, token, &c, err, sizeof err);
    if (rc)
        FAILF("mc_connect(%s): %s (%s)", token ? d->tcp_addr : d->unix_addr, mc_strerror(rc), err);
    mc_set_timeout(c, 20000);
    return c;
}

static int cmdline_has_job(pid_t pid, uint64_t id)
{
    char path[64], cmd[8192], want[32];
    snprintf(path, sizeof path, "/proc/%d/cmdline", (int)pid);
    int fd = open(path, O_RDONLY);
    if (fd < 0)
        return 0;
    ssize_t n = read(fd, cmd, sizeof cmd - 1);
    close(fd);
    if (n <= 0)
        return 0;
    cmd[n] = '\0';
    snprintf(want, sizeof want, "%llu", (unsigned long long)id);
    for (ssize_t i = 0; i < n; i += (ssize_t)strlen(cmd + i) + 1)
        if (strcmp(cmd + i, "--job-id") == 0 && i + 9 < n && strcmp(cmd + i + 9, want) == 0)
            return 1;
    return 0;
}

/* The --job argument of process pid into dir ("" none); its state letter. */
static char job_dir_of(pid_t pid, char *dir, size_t sz)
{
    char path[64], cmd[8192], stat[512];
    dir[0] = '\0';
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    FILE *fp = fopen(path, "r");
    char state = '?';
    if (!fp)
        return state;
    if (fgets(stat, sizeof stat, fp)) {
        char *rp = strrchr(stat, ')');
        if (rp && rp[1])
            state = rp[2];
    }
    fclose(fp);
    snprintf(path, sizeof path, "/proc/%d/cmdline", (int)pid);
    int fd = open(path, O_RDONLY);
    if (fd < 0)
        return state;
    ssize_t n = read(fd, cmd, sizeof cmd - 1);
    close(fd);
    if (n <= 0)
        return state;
    cmd[n] = '\0';
    for (ssize_t i = 0; i < n; i += (ssize_t)strlen(cmd + i) + 1)
        if (strcmp(cmd + i, "--job") == 0 && i + 6 < n) {
            snprintf(dir, sz, "%s", cmd + i + 6);
            break;
        }
    return state;
}

/* Counts (and sends sig to, unless 0) every live process whose --job is in
 * d's spool and, with id > 0, is job id's directory. */
static int each_worker(const testdaemon *d, uint64_t id, int sig)
{
    char want[700], prefix[700], dir[4096];
    snprintf(want, sizeof want, "%s/spool/%llu", d->state, (unsigned long long)id);
    snprintf(prefix, sizeof prefix, "%s/spool/", d->state);
    int n = 0;
    DIR *dp = opendir("/proc");
    struct dirent *de;
    while (dp && (de = readdir(dp))) {
        pid_t pid = (pid_t)atoi(de->d_name);
        if (pid <= 0 || job_dir_of(pid, dir, sizeof dir) == 'Z' || !dir[0])
            continue;
        if (id ? strcmp(dir, want) == 0 : strncmp(dir, prefix, strlen(prefix)) == 0) {
            n++;
            if (sig)
                kill(pid, sig);
        }
    }
    if (dp)
        closedir(dp);
    return n;
}

int testdaemon_live_workers(const testdaemon *d, uint64_t id)
{
    return each_worker(d, id, 0);
}

int testdaemon_kill_workers(const testdaemon *d)
{
    return each_worker(d, 0, SIGKILL);
}

pid_t testdaemon_worker_pid(const testdaemon *d, uint64_t id)
{
    for (int tries = 0; tries < 1000; tries++) {
        DIR *dp = opendir("/proc");
        struct dirent *de;
        while (dp && (de = readdir(dp))) {
            pid_t pid = (pid_t)atoi(de->d_name);
            char path[64], stat[512];
            if (pid <= 0)
                continue;
            snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
            FILE *fp = fopen(path, "r");
            if (!fp)
                continue;
            int ppid = -1;
            if (fgets(stat, sizeof stat, fp)) {
                char *rp = strrchr(stat, ')');
                if (rp)
                    sscanf(rp + 2, "%*c %d", &ppid);
            }
            fclose(fp);
            if (ppid == d->pid && cmdline_has_job(pid, id)) {
                closedir(dp);
                return pid;
            }
        }
        if (dp)
            closedir(dp);
        sleep_ms(10);
    }
    return -1;
}

int testdaemon_wait_state(mc_client *c, uint64_t id, int state, int timeout_s)
{
    mc_job_status s;
    for (int i = 0; i < timeout_s * 50; i++) {
        int rc = mc_status(c, id, &s);
        if (rc)
            FAILF("STATUS %llu: %s (%s)", (unsigned long long)id, mc_strerror(rc), mc_errmsg(c));
        if (state >= 0 ? s.state == state : s.state >= MC_COMPLETED)
            return s.state;
        sleep_ms(20);
    }
    FAILF("job %llu still %s after %d s (wanted %s; reason '%s')", (unsigned long long)id,
          mc_state_name(s.state), timeout_s, state >= 0 ? mc_state_name(state) : "a final state", s.reason);
    return -1;
}

unsigned char *testdaemon_encode(const mesh *m, size_t *len)
{
    unsigned char *buf = NULL;
    char err[512];
    if (mc_encode_mesh(m->v, m->nv, m->f, m->nf, &buf, len, err, sizeof err))
        FAILF("mc_encode_mesh: %s", err);
    return buf;
}

void testdaemon_pair(int long_job, mesh **S, mesh **T)
{
    testdaemon_sphere_pair(long_job ? 3 : 2, S, T);
}

void testdaemon_sphere_pair(int level, mesh **S, mesh **T)
{
    *S = testmesh_icosphere(level);
    *T = testmesh_icosphere(level);
    if (!*S || !*T)
        FAILF("testmesh_icosphere(%d) failed", level);
    for (int i = 0; i < (*T)->nv; i++) {        /* an ellipsoid, a little bent */
        double *x = &(*T)->v[3 * i];
        x[0] *= 1.3;
        x[2] += 0.15 * x[0] * x[0];
    }
}

uint64_t testdaemon_submit(mc_client *c, int iterations, int long_job, int32_t priority, int *rc)
{
    mesh *S, *T;
    testdaemon_pair(long_job, &S, &T);
    mc_job_spec spec;
    mc_job_spec_init(&spec);
    size_t sl, tl;
    unsigned char *sb = testdaemon_encode(S, &sl), *tb = testdaemon_encode(T, &tl);
    static const uint32_t lm[] = {0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5};
    spec.source = sb;
    spec.source_len = sl;
    spec.target = tb;
    spec.target_len = tl;
    spec.landmarks = lm;
    spec.nlandmarks = 6;
    spec.iterations = (uint32_t)iterations;
    spec.inner_iterations = long_job ? 50 : 10;
    spec.beta_ramp = iterations > 1 ? iterations : 1;
    spec.rhm_iterations = 3;
    spec.stop_change = 0;
    spec.priority = priority;
    spec.label = long_job ? "long icosphere job" : "quick icosphere job";
    uint64_t id = 0;
    *rc = mc_submit(c, &spec, &id);
    free(sb);
    free(tb);
    mesh_free(S);
    mesh_free(T);
    return id;
}

static mc_map_row *rows_of(const bmap *P)
{
    mc_map_row *r = calloc((size_t)P->n + 1, sizeof *r);
    CHECK(r != NULL);
    for (int i = 0; i < P->n; i++) {
        r[i].face = (uint32_t)P->face[i];
        memcpy(r[i].w, &P->w[3 * i], sizeof r[i].w);
    }
    return r;
}

void testdaemon_demo_open(testdaemon_demo *dm, uint32_t iterations)
{
    static const char *const rel[4] = {
        "shrec07_bim/Meshes/381.off", "shrec07_bim/Meshes/390.off",
        "ectm_demo_381_390/init_381_to_390.map", "ectm_demo_381_390/init_390_to_381.map"};
    char path[4][600], err[1024];
    for (int i = 0; i < 4; i++)
        snprintf(path[i], sizeof path[i], "%s", harness_data_path(rel[i]));
    memset(dm, 0, sizeof *dm);
    mc_job_spec *s = &dm->spec;
    mc_job_spec_init(s);
    if (mc_encode_mesh_file(path[0], &dm->sb, &s->source_len, err, sizeof err) ||
        mc_encode_mesh_file(path[1], &dm->tb, &s->target_len, err, sizeof err) ||
        mesh_read_drc_mem(dm->sb, s->source_len, MESH_MAX_VERTICES, MESH_MAX_FACES, "381", &dm->S,
                          err, sizeof err) ||
        mesh_read_drc_mem(dm->tb, s->target_len, MESH_MAX_VERTICES, MESH_MAX_FACES, "390", &dm->T,
                          err, sizeof err) ||
        bmap_read(path[2], dm->S, dm->T, &dm->P0, err, sizeof err) ||
        bmap_read(path[3], dm->T, dm->S, &dm->Q0, err, sizeof err))
        FAILF("%s", err);
    s->source = dm->sb;
    s->target = dm->tb;
    s->p = dm->pr = rows_of(dm->P0);
    s->np = (uint32_t)dm->P0->n;
    s->q = dm->qr = rows_of(dm->Q0);
    s->nq = (uint32_t)dm->Q0->n;
    s->iterations = iterations;
    s->stop_change = 0;
    s->label = "demo 381 -> 390";
}

void testdaemon_demo_close(testdaemon_demo *dm)
{
    free(dm->sb);
    free(dm->tb);
    free(dm->pr);
    free(dm->qr);
    bmap_free(dm->P0);
    bmap_free(dm->Q0);
    mesh_free(dm->S);
    mesh_free(dm->T);
    memset(dm, 0, sizeof *dm);
}

int testdaemon_log_has(const testdaemon *d, const char *what)
{
    return testdaemon_log_count(d, what) > 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double testdaemon_checked_ms(const testdaemon *d, double *cpu_ms)
{
    FILE *fp = fopen(d->log, "r");
    CHECK(fp != NULL);
    char line[8192];
    double v[256], c[256];
    int n = 0;
    while (n < 256 && fgets(line, sizeof line, fp)) {
        const char *at = strstr(line, "checked in ");
        if (at && sscanf(at, "checked in %lf ms (%lf ms CPU)", &v[n], &c[n]) == 2)
            n++;
    }
    fclose(fp);
    CHECK(n > 0);
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    qsort(c, (size_t)n, sizeof *c, cmp_double);
    *cpu_ms = c[n / 2];
    return v[n / 2];
}

uint64_t testdaemon_submit_ok(mc_client *c, int iterations, int long_job, int32_t priority)
{
    int rc;
    uint64_t id = testdaemon_submit(c, iterations, long_job, priority, &rc);
    if (rc)
        FAILF("SUBMIT: %s (%s)", mc_strerror(rc), mc_errmsg(c));
    CHECK(id > 0);
    return id;
}

void testdaemon_sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}
