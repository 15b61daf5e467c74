/* test_sec_sandbox.c — the sandbox around untrusted input and the daemon's
 * drop from root, attacked for real. A call outside a profile's allow-list
 * kills the process by SIGSYS with a line naming it (socket, fork, W+X
 * memory, signals and limits aimed at another process); what a profile
 * answers instead (clone3, ioctl, the validator's opens) does not kill. A
 * running meshcorr-worker of the real daemon shows Seccomp 2, NoNewPrivs 1
 * and finite limits in /proc, and so does meshcorr-validate while it reads
 * its frame; a CPU job and an OpenCL (PoCL) job both complete under the
 * filter, PoCL compiling and linking its kernels into a cold cache.
 * meshcorrd started as root refuses to run without --user, with it runs as
 * that user with no capability left, and so do its workers; it refuses a
 * used state directory of another owner. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testrun.h"
#include "sandbox/sandbox.h"
#include "proto.h"

#include <dirent.h>
#include <seccomp.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <pwd.h>
#include <sched.h>
#include <signal.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define VALIDATOR "build/meshcorr-validate"

/* ---- one action after sbx_enter, in a child ------------------------------ */

enum { DIES, RUNS };

typedef struct probe {
    const char *what;
    sbx_profile profile;
    int (*act)(void);       /* returns 0 when the call answered as expected */
    int expect;             /* DIES: killed by SIGSYS; RUNS: exits 0 */
    const char *call;       /* DIES: the call the SIGSYS line names (by number) */
} probe;

static int act_socket(void) { return socket(AF_INET, SOCK_STREAM, 0) >= 0 ? 0 : 1; }
static int act_fork(void)
{
    pid_t p = fork();
    if (p == 0)
        _exit(0);
    return 0;
}
static pid_t parent;                  /* the test, taken before the sandbox */
static int act_kill_parent(void) { return kill(parent, 0); }
static int act_prlimit_parent(void)
{
    struct rlimit rl;
    return prlimit(parent, RLIMIT_NOFILE, NULL, &rl);
}
static int act_wx_map(void)
{
    return mmap(NULL, 4096, PROT_READ | PROT_WRITE | PROT_EXEC, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0) == MAP_FAILED;
}
static int act_make_executable(void)
{
    void *p = mmap(NULL, 4096, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    return p == MAP_FAILED || mprotect(p, 4096, PROT_READ | PROT_EXEC) != 0;
}
static int act_execve(void)
{
    char *argv[] = {"/bin/true", NULL};
    execv("/bin/true", argv);
    return 1;
}
static int thread_arg;
static void *thread_main(void *arg) { return arg; }
static int act_thread(void)
{
    pthread_t t;
    void *out = NULL;
    return pthread_create(&t, NULL, thread_main, &thread_arg) || pthread_join(t, &out) || out != &thread_arg;
}
static int act_clone3_is_enosys(void) { return !(syscall(SYS_clone3, NULL, 0) == -1 && errno == ENOSYS); }
static int act_ioctl_is_enotty(void)
{
    struct winsize ws;
    return !(ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == -1 && errno == ENOTTY);
}
static int act_open_is_eperm(void) { return !(open("/etc/hostname", O_RDONLY) == -1 && errno == EPERM); }
static int act_open_reads(void)
{
    int fd = open("/proc/self/status", O_RDONLY);
    char buf[64];
    return fd < 0 || read(fd, buf, sizeof buf) <= 0 || close(fd) != 0;
}
static int act_wx_map_allowed(void) { return act_wx_map(); }

static const probe probes[] = {
    {"a TCP socket", SBX_WORKER, act_socket, DIES, "socket"},
    {"a TCP socket", SBX_WORKER_OPENCL, act_socket, DIES, "socket"},
    {"a TCP socket", SBX_VALIDATOR, act_socket, DIES, "socket"},
    {"fork()", SBX_WORKER, act_fork, DIES, "clone"},
    {"fork()", SBX_VALIDATOR, act_fork, DIES, "clone"},
    {"fork()", SBX_WORKER_OPENCL, act_fork, DIES, "clone"},
    {"execve()", SBX_WORKER, act_execve, DIES, "execve"},
    {"a signal to the parent", SBX_WORKER, act_kill_parent, DIES, "kill"},
    {"a signal to the parent", SBX_WORKER_OPENCL, act_kill_parent, DIES, "kill"},
    {"the parent's limits", SBX_WORKER, act_prlimit_parent, DIES, "prlimit64"},
    {"the parent's limits", SBX_VALIDATOR, act_prlimit_parent, DIES, "prlimit64"},
    {"writable executable memory", SBX_WORKER, act_wx_map, DIES, "mmap"},
    {"writable executable memory", SBX_VALIDATOR, act_wx_map, DIES, "mmap"},
    {"memory made executable", SBX_WORKER, act_make_executable, DIES, "mprotect"},
    {"threads", SBX_WORKER, act_thread, RUNS, NULL},
    {"threads", SBX_VALIDATOR, act_thread, RUNS, NULL},
    {"threads", SBX_WORKER_OPENCL, act_thread, RUNS, NULL},
    {"clone3 answered ENOSYS", SBX_WORKER, act_clone3_is_enosys, RUNS, NULL},
    {"ioctl answered ENOTTY", SBX_WORKER, act_ioctl_is_enotty, RUNS, NULL},
    {"ioctl answered ENOTTY", SBX_VALIDATOR, act_ioctl_is_enotty, RUNS, NULL},
    {"an open answered EPERM", SBX_VALIDATOR, act_open_is_eperm, RUNS, NULL},
    {"a file opened and read", SBX_WORKER, act_open_reads, RUNS, NULL},
    {"writable executable memory (a GPU driver's JIT)", SBX_WORKER_OPENCL, act_wx_map_allowed, RUNS, NULL},
};

/* Runs p in a child that entered its sandbox; its wait status, its stderr
 * into err. */
static int run_probe(const probe *p, char *err, size_t errsz)
{
    int fd[2];
    CHECK_INT(pipe(fd), 0);
    fflush(stdout);
    fflush(stderr);
    parent = getpid();
    pid_t pid = fork();
    CHECK(pid >= 0);
    if (pid == 0) {
        dup2(fd[1], STDERR_FILENO);
        close(fd[0]);
        close(fd[1]);
        char e[256];
        if (sbx_enter(p->profile, "probe", e, sizeof e)) {
            fprintf(stderr, "%s\n", e);
            _exit(3);
        }
        _exit(p->act() ? 1 : 0);
    }
    close(fd[1]);
    size_t n = 0;
    ssize_t r;
    while (n + 1 < errsz && (r = read(fd[0], err + n, errsz - 1 - n)) > 0)
        n += (size_t)r;
    err[n] = '\0';
    close(fd[0]);
    int st;
    CHECK(waitpid(pid, &st, 0) == pid);
    return st;
}

TEST(a_call_outside_the_allow_list_kills_and_what_a_profile_answers_does_not)
{
    for (size_t i = 0; i < sizeof probes / sizeof probes[0]; i++) {
        const probe *p = &probes[i];
        char err[1024], want[128];
        int st = run_probe(p, err, sizeof err);
        const char *profile = sbx_profile_name(p->profile);
        if (p->expect == DIES) {
            if (!WIFSIGNALED(st) || WTERMSIG(st) != SIGSYS)
                FAILF("%s under the %s profile: wait status %#x, not killed by SIGSYS (stderr: %s)", p->what,
                      profile, st, err);
            snprintf(want, sizeof want, "probe: sandbox (%s): system call %d is not allowed", profile,
                     seccomp_syscall_resolve_name(p->call));
            CHECK_STR_HAS(err, want);
        } else if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
            FAILF("%s under the %s profile: wait status %#x, expected exit 0 (stderr: %s)", p->what, profile,
                  st, err);
        }
    }
}

TEST(sandbox_with_no_such_profile_is_refused_before_it_changes_anything)
{
    char err[256];
    CHECK_INT(sbx_enter((sbx_profile)7, "probe", err, sizeof err), SBX_EPROFILE);
    CHECK_STR_HAS(err, "no profile 7");
    CHECK(sbx_profile_name((sbx_profile)7) == NULL);
    CHECK_INT(prctl(PR_GET_NO_NEW_PRIVS, 0, 0, 0, 0), 0);
    CHECK_INT(prctl(PR_GET_SECCOMP, 0, 0, 0, 0), 0);
}

/* ---- /proc of a sandboxed process ---------------------------------------- */

/* /proc/pid/NAME into buf; 0, or -1 when the process is gone. */
static int proc_read(pid_t pid, const char *name, char *buf, size_t sz)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/%d/%s", (int)pid, name);
    int fd = open(path, O_RDONLY);
    if (fd < 0)
        return -1;
    ssize_t n = read(fd, buf, sz - 1);
    close(fd);
    if (n <= 0)
        return -1;
    buf[n] = '\0';
    return 0;
}

/* The value after "Key:" in /proc/pid/status (its first field). */
static long long status_field(const char *status, const char *key)
{
    char want[64];
    snprintf(want, sizeof want, "\n%s:", key);
    const char *at = strstr(status, want);
    if (!at)
        FAILF("no %s in /proc/PID/status", key);
    return strtoll(at + strlen(want), NULL, 10);
}

/* Waits up to 10 s for pid's status to show Seccomp 2; its status then. */
static void wait_sandboxed(pid_t pid, char *status, size_t sz)
{
    for (int i = 0; i < 1000; i++) {
        if (proc_read(pid, "status", status, sz) != 0)
            FAILF("process %d ended before it was seen sandboxed", (int)pid);
        if (status_field(status, "Seccomp") == 2)
            return;
        testdaemon_sleep_ms(10);
    }
    FAILF("process %d not in seccomp filter mode after 10 s:\n%s", (int)pid, status);
}

/* Soft and hard value of a /proc/pid/limits line; -1 for unlimited. */
static void limit_of(const char *limits, const char *name, long long *soft, long long *hard)
{
    const char *at = strstr(limits, name);
    if (!at)
        FAILF("no '%s' in /proc/PID/limits", name);
    char s[32], h[32];
    if (sscanf(at + strlen(name), "%31s %31s", s, h) != 2)
        FAILF("cannot read '%s' in /proc/PID/limits", name);
    *soft = strcmp(s, "unlimited") == 0 ? -1 : strtoll(s, NULL, 10);
    *hard = strcmp(h, "unlimited") == 0 ? -1 : strtoll(h, NULL, 10);
}

static long cpus_here(void)
{
    cpu_set_t set;
    CHECK_INT(sched_getaffinity(0, sizeof set, &set), 0);
    return CPU_COUNT(&set);
}

/* The uid the daemon runs as in these tests: TESTDAEMON_USER's when root. */
static uid_t daemon_uid(void)
{
    if (geteuid() != 0)
        return geteuid();
    struct passwd *pw = getpwnam(TESTDAEMON_USER);
    CHECK(pw != NULL);
    return pw->pw_uid;
}

/* A long job's worker on d: submits it on c, waits until its worker is
 * sandboxed (its /proc status then in status) and returns its pid and id. */
static pid_t long_job_worker(testdaemon *d, mc_client *c, uint64_t *id, char *status, size_t sz)
{
    *id = testdaemon_submit_ok(c, 100000, 1, 0);
    pid_t pid = testdaemon_worker_pid(d, *id);
    CHECK(pid > 0);
    wait_sandboxed(pid, status, sz);
    return pid;
}

/* Cancels job id, closes c and stops d (which must exit 0). */
static void cancel_and_stop(testdaemon *d, mc_client *c, uint64_t id)
{
    CHECK_INT(mc_cancel(c, id), 0);
    CHECK_INT(testdaemon_wait_state(c, id, -1, 30), MC_CANCELLED);
    mc_close(c);
    testdaemon_stop(d, SIGTERM);
}

TEST_T(running_worker_is_sandboxed_and_limited_and_runs_as_the_daemons_user, 120)
{
    testdaemon_need_worker();
    static const char *const args[] = {"--job-timeout", "100", "--worker-memory-mb", "3000", NULL};
    testdaemon d;
    testdaemon_start(&d, "worker", args);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id;
    static char status[8192], limits[8192];
    pid_t pid = long_job_worker(&d, c, &id, status, sizeof status);
    CHECK_INT(status_field(status, "NoNewPrivs"), 1);
    CHECK_INT(status_field(status, "Uid"), daemon_uid());
    CHECK_INT(proc_read(pid, "limits", limits, sizeof limits), 0);
    long long soft, hard;
    limit_of(limits, "Max address space", &soft, &hard);
    CHECK_INT(soft, 3000ll << 20);
    limit_of(limits, "Max cpu time", &soft, &hard);
    CHECK_INT(soft, (100 + 5) * cpus_here());           /* (job-timeout + kill grace) x CPUs */
    CHECK(hard > soft);                                  /* SIGXCPU first */
    limit_of(limits, "Max file size", &soft, &hard);
    CHECK_INT(soft, PROTO_MAX_FRAME);
    limit_of(limits, "Max core file size", &soft, &hard);
    CHECK_INT(soft, 0);
    limit_of(limits, "Max open files", &soft, &hard);
    CHECK(soft > 0 && soft <= 1024);
    limit_of(limits, "Max processes", &soft, &hard);
    CHECK(soft > 0);
    cancel_and_stop(&d, c, id);
}

TEST_T(worker_address_space_is_limited_by_default_and_unlimited_only_when_0_is_given, 120)
{
    testdaemon_need_worker();
    static const char *const none[] = {"--worker-memory-mb", "0", NULL};
    for (int run = 0; run < 2; run++) {
        testdaemon d;
        testdaemon_start(&d, run ? "memory-none" : "memory-default", run ? none : NULL);
        mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
        uint64_t id;
        static char status[8192], limits[8192];
        pid_t pid = long_job_worker(&d, c, &id, status, sizeof status);
        CHECK_INT(proc_read(pid, "limits", limits, sizeof limits), 0);
        long long soft, hard;
        limit_of(limits, "Max address space", &soft, &hard);
        if (run == 0) {
            /* 3/4 of the memory over one slot, at least 1 GiB */
            long long mem = (long long)sysconf(_SC_PHYS_PAGES) * sysconf(_SC_PAGESIZE);
            long long want = mem / 4 * 3 >> 20;
            if (want < 1024)
                want = 1024;
            if (soft < 0 || llabs((soft >> 20) - want) > 1)
                FAILF("default address space %lld bytes, expected about %lld MB", soft, want);
            CHECK(testdaemon_log_has(&d, "workers run sandboxed"));
        } else {
            CHECK_INT(soft, -1);
            CHECK(testdaemon_log_has(&d, "no address-space limit (--worker-memory-mb 0)"));
        }
        cancel_and_stop(&d, c, id);
    }
}

TEST_T(validator_is_sandboxed_and_limited_while_it_reads_its_frame, 60)
{
    int in[2], out[2];
    CHECK_INT(pipe(in), 0);
    CHECK_INT(pipe(out), 0);
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    CHECK(pid >= 0);
    if (pid == 0) {
        dup2(in[0], STDIN_FILENO);
        dup2(out[1], STDOUT_FILENO);
        close(in[0]), close(in[1]), close(out[0]), close(out[1]);
        execl(VALIDATOR, VALIDATOR, "--max-memory-mb", "700", "--max-cpu-s", "30", (char *)NULL);
        _exit(127);
    }
    close(in[0]);
    close(out[1]);
    CHECK_INT(write(in[1], "MCRP", 4), 4);               /* a frame begun: it waits for the rest */
    static char status[8192], limits[8192];
    wait_sandboxed(pid, status, sizeof status);
    CHECK_INT(status_field(status, "NoNewPrivs"), 1);
    CHECK_INT(proc_read(pid, "limits", limits, sizeof limits), 0);
    long long soft, hard;
    limit_of(limits, "Max address space", &soft, &hard);
    CHECK_INT(soft, 700ll << 20);
    limit_of(limits, "Max cpu time", &soft, &hard);
    CHECK_INT(soft, 30);
    limit_of(limits, "Max file size", &soft, &hard);
    CHECK_INT(soft, 0);
    limit_of(limits, "Max core file size", &soft, &hard);
    CHECK_INT(soft, 0);
    limit_of(limits, "Max open files", &soft, &hard);
    CHECK_INT(soft, 16);
    close(in[1]);                                        /* the frame ends short: it answers */
    uint8_t reply[512];
    size_t n = 0;
    ssize_t r;
    while (n < sizeof reply && (r = read(out[0], reply + n, sizeof reply - n)) > 0)
        n += (size_t)r;
    close(out[0]);
    int st;
    CHECK(waitpid(pid, &st, 0) == pid);
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 1);
    proto_msg m;
    size_t used;
    char err[256];
    CHECK_INT(proto_decode(reply, n, sizeof reply, &m, &used, err, sizeof err), PROTO_READY);
    CHECK_INT(m.type, PROTO_MSG_ERROR);
    CHECK_INT(m.u.error.code, PROTO_ETRUNCATED);
    proto_msg_free(&m);
}

/* ---- jobs under the filter ----------------------------------------------- */

/* Files under dir whose name ends in suffix. */
static int count_files(const char *dir, const char *suffix)
{
    DIR *dp = opendir(dir);
    if (!dp)
        return 0;
    int n = 0;
    struct dirent *de;
    while ((de = readdir(dp))) {
        if (!strcmp(de->d_name, ".") || !strcmp(de->d_name, ".."))
            continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
        size_t l = strlen(de->d_name), k = strlen(suffix);
        struct stat st;
        if (lstat(path, &st) == 0 && S_ISDIR(st.st_mode))
            n += count_files(path, suffix);
        else if (l >= k && strcmp(de->d_name + l - k, suffix) == 0)
            n++;
    }
    closedir(dp);
    return n;
}

TEST_T(cpu_and_opencl_jobs_complete_under_the_filter_with_a_cold_kernel_cache, 240)
{
    testdaemon_need_worker();
    /* PoCL's cache where this test alone uses it, empty: the worker
     * compiles and links (ld, under the filter) every kernel */
    char cache[700], pocl[720];
    snprintf(cache, sizeof cache, "%s/cache", harness_tmpdir());
    snprintf(pocl, sizeof pocl, "%s/meshcorr-pocl", cache);
    CHECK_INT(setenv("XDG_CACHE_HOME", cache, 1), 0);
    unsetenv("POCL_CACHE_DIR");
    testdaemon d;
    testdaemon_start(&d, "jobs", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t cpu = testdaemon_submit_ok(c, 3, 0, 0);
    CHECK_INT(testdaemon_wait_state(c, cpu, -1, 90), MC_COMPLETED);

    mesh *S, *T;
    testdaemon_pair(0, &S, &T);
    mc_job_spec s;
    mc_job_spec_init(&s);
    size_t sl, tl;
    unsigned char *sb = testdaemon_encode(S, &sl), *tb = testdaemon_encode(T, &tl);
    static const uint32_t lm[] = {0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5};
    s.source = sb, s.source_len = sl, s.target = tb, s.target_len = tl;
    s.landmarks = lm, s.nlandmarks = 6;
    s.iterations = 3, s.beta_ramp = 3, s.rhm_iterations = 3, s.inner_iterations = 10;
    s.backend = "opencl";
    uint64_t ocl = 0;
    CHECK_INT(mc_submit(c, &s, &ocl), 0);
    int st = testdaemon_wait_state(c, ocl, -1, 180);
    mc_job_status js;
    CHECK_INT(mc_status(c, ocl, &js), 0);
    free(sb);
    free(tb);
    mesh_free(S);
    mesh_free(T);
    if (st == MC_FAILED && strstr(js.reason, "OpenCL") && !strstr(js.reason, "signal"))
        SKIP("no OpenCL device with fp64 here: %s", js.reason);
    if (st != MC_COMPLETED)
        FAILF("the OpenCL job ended %s: %s (log %s)", mc_state_name(st), js.reason, d.log);
    CHECK(!testdaemon_log_has(&d, "sandbox ("));
    int linked = count_files(pocl, ".so");
    printf("  PoCL kernels compiled and linked under the filter: %d\n", linked);
    CHECK(linked > 0);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* ---- meshcorrd and root -------------------------------------------------- */

static void need_root(void)
{
    if (geteuid() != 0)
        SKIP("not root: meshcorrd runs as the user that starts it");
}

TEST(meshcorrd_as_root_without_user_refuses_to_start_naming_the_option)
{
    need_root();
    char out[4096], state[700];
    snprintf(state, sizeof state, "%s/state", harness_tmpdir());
    int rc = testrunf(out, sizeof out, "build/meshcorrd --state-dir %s --listen unix:%s/sock 2>&1", state,
                      harness_tmpdir());
    CHECK_INT(rc, 2);
    CHECK_STR_HAS(out, "<3>");
    CHECK_STR_HAS(out, "refusing to run as root: give --user USER");
    CHECK_STR_HAS(out, "or start it as an unprivileged user");
    struct stat st;
    CHECK(stat(state, &st) != 0);                        /* nothing created */
}

TEST_T(meshcorrd_with_user_runs_as_that_user_without_capabilities_and_so_do_its_workers, 120)
{
    need_root();
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "user", NULL);
    uid_t uid = daemon_uid();
    static char status[8192];
    CHECK_INT(proc_read(d.pid, "status", status, sizeof status), 0);
    char ids[128], line[128];
    snprintf(ids, sizeof ids, "\nUid:\t%u\t%u\t%u\t%u\n", uid, uid, uid, uid);
    CHECK_STR_HAS(status, ids);                          /* real, effective, saved, fs */
    CHECK_STR_HAS(status, "\nCapPrm:\t0000000000000000\n");
    CHECK_STR_HAS(status, "\nCapEff:\t0000000000000000\n");
    snprintf(line, sizeof line, "running as %s (uid %u", TESTDAEMON_USER, uid);
    CHECK(testdaemon_log_has(&d, line));
    struct stat st;
    CHECK_INT(stat(d.state, &st), 0);
    CHECK_INT(st.st_uid, uid);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    uint64_t id;
    long_job_worker(&d, c, &id, status, sizeof status);
    CHECK_STR_HAS(status, ids);                          /* the worker's ids: the daemon's */
    CHECK_STR_HAS(status, "\nCapEff:\t0000000000000000\n");
    cancel_and_stop(&d, c, id);
}

TEST(meshcorrd_refuses_a_used_state_directory_of_another_owner)
{
    need_root();
    char state[700], file[760], out[4096];
    snprintf(state, sizeof state, "%s/state", harness_tmpdir());
    snprintf(file, sizeof file, "%s/jobs.db", state);
    CHECK_INT(mkdir(state, 0700), 0);
    int fd = open(file, O_WRONLY | O_CREAT, 0600);
    CHECK(fd >= 0);
    close(fd);
    int rc = testrunf(out, sizeof out, "build/meshcorrd --user %s --state-dir %s --listen unix:%s/sock 2>&1",
                      TESTDAEMON_USER, state, harness_tmpdir());
    CHECK_INT(rc, 1);
    char want[900];
    snprintf(want, sizeof want, "--state-dir %s belongs to uid 0, not to --user %s", state, TESTDAEMON_USER);
    CHECK_STR_HAS(out, want);
    snprintf(want, sizeof want, "chown -R %s %s", TESTDAEMON_USER, state);
    CHECK_STR_HAS(out, want);
    struct stat st;
    CHECK_INT(stat(file, &st), 0);
    CHECK_INT(st.st_uid, 0);                             /* left as it was */
}

TEST(meshcorrd_not_root_refuses_to_become_another_user)
{
    need_root();
    struct passwd *pw = getpwnam(TESTDAEMON_USER);
    CHECK(pw != NULL);
    char log[700];
    snprintf(log, sizeof log, "%s/out", harness_tmpdir());
    CHECK_INT(chown(harness_tmpdir(), pw->pw_uid, pw->pw_gid), 0);
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    CHECK(pid >= 0);
    if (pid == 0) {
        int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd < 0 || dup2(fd, STDERR_FILENO) < 0 || setgid(pw->pw_gid) != 0 || setuid(pw->pw_uid) != 0)
            _exit(126);
        char state[700], listen[720];
        snprintf(state, sizeof state, "%s/state", harness_tmpdir());
        snprintf(listen, sizeof listen, "unix:%s/sock", harness_tmpdir());
        execl("build/meshcorrd", "build/meshcorrd", "--user", "nobody", "--state-dir", state, "--listen", listen,
              (char *)NULL);
        _exit(127);
    }
    int st;
    CHECK(waitpid(pid, &st, 0) == pid);
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 2);
    char out[4096] = "";
    FILE *fp = fopen(log, "r");
    CHECK(fp != NULL);
    size_t n = fread(out, 1, sizeof out - 1, fp);
    out[n] = '\0';
    fclose(fp);
    char want[128];
    snprintf(want, sizeof want, "--user nobody: only root can become another user (running as uid %u)",
             (unsigned)pw->pw_uid);
    CHECK_STR_HAS(out, want);
}
