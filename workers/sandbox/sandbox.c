/* sandbox.c — no_new_privs and the seccomp allow-lists of meshcorr-validate
 * and meshcorr-worker (sandbox.h). One table lists every call of every
 * profile, with the condition on its arguments where they matter (memory
 * protections, clone flags, whom a signal or a limit targets).
 * docs/decisions.md has the measurements behind each group. */
#include "sandbox/sandbox.h"
#include "util/errbuf.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/sched.h>
#include <seccomp.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <unistd.h>

#define V (1u << SBX_VALIDATOR)
#define W (1u << SBX_WORKER)
#define O (1u << SBX_WORKER_OPENCL)
#define ALL (V | W | O)
#define WORKERS (W | O)

/* What a rule asks of the call's arguments. */
enum {
    C_ANY,        /* nothing */
    C_NOT_WX,     /* mmap: prot not both PROT_WRITE and PROT_EXEC */
    C_NOT_X,      /* mprotect: prot without PROT_EXEC */
    C_THREAD,     /* clone: CLONE_THREAD (a thread of this process) */
    C_VFORK,      /* clone: CLONE_VM | CLONE_VFORK (posix_spawn) */
    C_SELF,       /* kill, tgkill: this process */
    C_ZERO,       /* prlimit64, sched_setaffinity: pid 0, this process */
    C_EMPTY_PATH, /* newfstatat: AT_EMPTY_PATH, i.e. fstat */
};

/* A call allowed (err 0), or answered with errno err without being
 * executed, in the profiles of the mask, when its arguments meet cond. */
typedef struct sbx__rule {
    int nr;
    unsigned profiles;
    int err;
    int cond;
} sbx__rule;

static const sbx__rule sbx__rules[] = {
    /* memory: the heap, large buffers (mremap: realloc of a mapped one),
     * thread stacks. W^X but for OpenCL jobs: no mapping both writable and
     * executable, none made executable later (libraries are mapped
     * executable from their files); a GPU driver may JIT into such memory */
    {SCMP_SYS(mmap), V | W, 0, C_NOT_WX},
    {SCMP_SYS(mmap), O, 0, C_ANY},
    {SCMP_SYS(mprotect), V | W, 0, C_NOT_X},
    {SCMP_SYS(mprotect), O, 0, C_ANY},
    {SCMP_SYS(brk), ALL, 0, C_ANY},
    {SCMP_SYS(munmap), ALL, 0, C_ANY},
    {SCMP_SYS(mremap), ALL, 0, C_ANY},
    {SCMP_SYS(madvise), ALL, 0, C_ANY},
    /* descriptors the program holds: the validator's stdin/stdout pipes and
     * stderr; the worker's job, answer and progress files, its progress
     * pipe or socket. writev: glibc's fatal messages (abort on a corrupt
     * heap). fstat: stdio sizing its buffers; the validator looks up no
     * name */
    {SCMP_SYS(read), ALL, 0, C_ANY},
    {SCMP_SYS(write), ALL, 0, C_ANY},
    {SCMP_SYS(writev), ALL, 0, C_ANY},
    {SCMP_SYS(close), ALL, 0, C_ANY},
    {SCMP_SYS(fstat), ALL, 0, C_ANY},
    {SCMP_SYS(newfstatat), V, 0, C_EMPTY_PATH},
    {SCMP_SYS(fsync), WORKERS, 0, C_ANY},
    /* files by name: libraries Embree/TBB load at their first use (pread64:
     * the loader reading their headers), /proc and /sys files they size
     * themselves by, the answer written atomically (name.tmp, fsync,
     * rename; unlink on failure). The validator opens nothing: a library
     * probing a file there gets EPERM and copes */
    {SCMP_SYS(openat), WORKERS, 0, C_ANY},
    {SCMP_SYS(openat), V, EPERM, C_ANY},
    {SCMP_SYS(open), V, EPERM, C_ANY},
    {SCMP_SYS(newfstatat), WORKERS, 0, C_ANY},
    {SCMP_SYS(pread64), WORKERS, 0, C_ANY},
    {SCMP_SYS(rename), WORKERS, 0, C_ANY},
    {SCMP_SYS(unlink), WORKERS, 0, C_ANY},
    /* PoCL: its kernel cache (directories, temporary files synced and
     * renamed into place), the paths of its headers and of the linker */
    {SCMP_SYS(mkdir), O, 0, C_ANY},
    {SCMP_SYS(getdents64), O, 0, C_ANY},
    {SCMP_SYS(access), O, 0, C_ANY},
    {SCMP_SYS(faccessat2), O, 0, C_ANY},
    {SCMP_SYS(readlink), O, 0, C_ANY},
    {SCMP_SYS(getcwd), O, 0, C_ANY},
    {SCMP_SYS(lseek), O, 0, C_ANY},
    {SCMP_SYS(fcntl), O, 0, C_ANY},
    {SCMP_SYS(fdatasync), O, 0, C_ANY},
    {SCMP_SYS(chmod), O, 0, C_ANY},
    {SCMP_SYS(umask), O, 0, C_ANY},
    {SCMP_SYS(uname), O, 0, C_ANY},
    {SCMP_SYS(getuid), O, 0, C_ANY},
    {SCMP_SYS(sigaltstack), O, 0, C_ANY},
    /* PoCL links each kernel with /usr/bin/ld (posix_spawn: clone with
     * CLONE_VM|CLONE_VFORK, then execve; the linker runs under this filter
     * too and needs what a new program does) */
    {SCMP_SYS(clone), O, 0, C_VFORK},
    {SCMP_SYS(execve), O, 0, C_ANY},
    {SCMP_SYS(wait4), O, 0, C_ANY},
    {SCMP_SYS(arch_prctl), O, 0, C_ANY},
    {SCMP_SYS(set_tid_address), O, 0, C_ANY},
    {SCMP_SYS(getrusage), O, 0, C_ANY},
    /* threads (OpenMP, TBB for Embree, PoCL's device threads; in the
     * validator too: a thread has no power its process lacks), no other
     * process. clone3's flags sit in memory the filter cannot read: ENOSYS
     * makes glibc use clone */
    {SCMP_SYS(clone), ALL, 0, C_THREAD},
    {SCMP_SYS(clone3), ALL, ENOSYS, C_ANY},
    {SCMP_SYS(futex), ALL, 0, C_ANY},
    {SCMP_SYS(set_robust_list), ALL, 0, C_ANY},
    {SCMP_SYS(rseq), ALL, 0, C_ANY},
    {SCMP_SYS(sched_yield), ALL, 0, C_ANY},
    {SCMP_SYS(sched_getaffinity), ALL, 0, C_ANY},
    {SCMP_SYS(sched_setaffinity), WORKERS, 0, C_ZERO},
    {SCMP_SYS(exit), ALL, 0, C_ANY},
    {SCMP_SYS(exit_group), ALL, 0, C_ANY},
    /* signals: SIGTERM's handler (cancel), abort(), the SIGSYS handler.
     * Signals and limits of this process only: the daemon and the other
     * workers run as the same user */
    {SCMP_SYS(tgkill), ALL, 0, C_SELF},
    {SCMP_SYS(kill), ALL, 0, C_SELF},
    {SCMP_SYS(prlimit64), ALL, 0, C_ZERO},
    {SCMP_SYS(rt_sigaction), ALL, 0, C_ANY},
    {SCMP_SYS(rt_sigprocmask), ALL, 0, C_ANY},
    {SCMP_SYS(rt_sigreturn), ALL, 0, C_ANY},
    {SCMP_SYS(restart_syscall), ALL, 0, C_ANY},
    /* time (where the vDSO cannot answer), sleeps of spin-wait back-offs,
     * ids, randomness (malloc, LLVM), the machine's memory (TBB) */
    {SCMP_SYS(clock_gettime), ALL, 0, C_ANY},
    {SCMP_SYS(clock_getres), ALL, 0, C_ANY},
    {SCMP_SYS(gettimeofday), ALL, 0, C_ANY},
    {SCMP_SYS(nanosleep), ALL, 0, C_ANY},
    {SCMP_SYS(clock_nanosleep), ALL, 0, C_ANY},
    {SCMP_SYS(getpid), ALL, 0, C_ANY},
    {SCMP_SYS(gettid), ALL, 0, C_ANY},
    {SCMP_SYS(getrandom), ALL, 0, C_ANY},
    {SCMP_SYS(sysinfo), WORKERS, 0, C_ANY},
    /* isatty() and friends: no terminal. A GPU driver talks to its device
     * node through ioctl (PoCL and its linker ask only TCGETS) */
    {SCMP_SYS(ioctl), V | W, ENOTTY, C_ANY},
    {SCMP_SYS(ioctl), O, 0, C_ANY},
};

/* Adds rule r (its condition's comparisons) to ctx: 0 or a negative errno. */
static int sbx__add(scmp_filter_ctx ctx, const sbx__rule *r)
{
    static const scmp_datum_t not_wx[] = {0, PROT_WRITE, PROT_EXEC};
    const scmp_datum_t wx = PROT_WRITE | PROT_EXEC;
    uint32_t act = r->err ? SCMP_ACT_ERRNO((unsigned)r->err) : SCMP_ACT_ALLOW;
    int rc = 0;
    if (r->nr < 0)
        return 0;                 /* a call this architecture does not have */
    switch (r->cond) {
    case C_NOT_WX:
        for (size_t i = 0; !rc && i < sizeof not_wx / sizeof not_wx[0]; i++)
            rc = seccomp_rule_add(ctx, act, r->nr, 1, SCMP_A2(SCMP_CMP_MASKED_EQ, wx, not_wx[i]));
        return rc;
    case C_NOT_X:
        return seccomp_rule_add(ctx, act, r->nr, 1, SCMP_A2(SCMP_CMP_MASKED_EQ, PROT_EXEC, 0));
    case C_THREAD:
        return seccomp_rule_add(ctx, act, r->nr, 1, SCMP_A0(SCMP_CMP_MASKED_EQ, CLONE_THREAD, CLONE_THREAD));
    case C_VFORK:
        return seccomp_rule_add(ctx, act, r->nr, 1,
                                SCMP_A0(SCMP_CMP_MASKED_EQ, CLONE_VM | CLONE_VFORK, CLONE_VM | CLONE_VFORK));
    case C_SELF:
        return seccomp_rule_add(ctx, act, r->nr, 1, SCMP_A0(SCMP_CMP_EQ, (scmp_datum_t)getpid()));
    case C_ZERO:
        return seccomp_rule_add(ctx, act, r->nr, 1, SCMP_A0(SCMP_CMP_EQ, 0));
    case C_EMPTY_PATH:
        return seccomp_rule_add(ctx, act, r->nr, 1, SCMP_A3(SCMP_CMP_MASKED_EQ, AT_EMPTY_PATH, AT_EMPTY_PATH));
    default:
        return seccomp_rule_add(ctx, act, r->nr, 0);
    }
}

static const char *sbx__prog = "sandbox";
static const char *sbx__profile = "";

/* Appends s to buf at *n (bounded). Async-signal-safe. */
static void sbx__put(char *buf, size_t sz, size_t *n, const char *s)
{
    while (*s && *n + 1 < sz)
        buf[(*n)++] = *s++;
}

/* A refused call: one line on stderr, then death by SIGSYS once this
 * handler returns (the signal stays blocked until then). Async-signal-safe
 * calls only, every one of them in each profile's list. */
static void sbx__on_sigsys(int sig, siginfo_t *si, void *uc)
{
    (void)sig, (void)uc;
    char num[16], line[512];
    size_t k = sizeof num - 1, n = 0;
    unsigned v = (unsigned)si->si_syscall;
    num[k] = '\0';
    do
        num[--k] = (char)('0' + v % 10);
    while ((v /= 10) && k);
    sbx__put(line, sizeof line, &n, sbx__prog);
    sbx__put(line, sizeof line, &n, ": sandbox (");
    sbx__put(line, sizeof line, &n, sbx__profile);
    sbx__put(line, sizeof line, &n, "): system call ");
    sbx__put(line, sizeof line, &n, num + k);
    sbx__put(line, sizeof line, &n, " is not allowed (`scmp_sys_resolver ");
    sbx__put(line, sizeof line, &n, num + k);
    sbx__put(line, sizeof line, &n, "` names it): killed\n");
    ssize_t w = write(STDERR_FILENO, line, n);
    (void)w;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = SIG_DFL;
    sigaction(SIGSYS, &sa, NULL);
    raise(SIGSYS);
}

const char *sbx_profile_name(sbx_profile profile)
{
    switch (profile) {
    case SBX_VALIDATOR: return "validator";
    case SBX_WORKER: return "worker";
    case SBX_WORKER_OPENCL: return "worker-opencl";
    }
    return NULL;
}

int sbx_enter(sbx_profile profile, const char *prog, char *err, size_t errsz)
{
    const char *name = sbx_profile_name(profile);
    if (!name)
        return errbuf_set(err, errsz, SBX_EPROFILE, "sandbox: no profile %d", (int)profile);
    if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0 || prctl(PR_GET_NO_NEW_PRIVS, 0, 0, 0, 0) != 1)
        return errbuf_set(err, errsz, SBX_ENNP, "sandbox: prctl(PR_SET_NO_NEW_PRIVS): %s", strerror(errno));
    sbx__prog = prog ? prog : "sandbox";
    sbx__profile = name;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_sigaction = sbx__on_sigsys;
    sa.sa_flags = SA_SIGINFO;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGSYS, &sa, NULL);

    /* unlisted calls trap into the handler above; a call of another
     * architecture (int 0x80 on x86_64) kills at once */
    scmp_filter_ctx ctx = seccomp_init(SCMP_ACT_TRAP);
    if (!ctx)
        return errbuf_set(err, errsz, SBX_EFILTER, "sandbox: seccomp_init failed");
    int rc = seccomp_attr_set(ctx, SCMP_FLTATR_CTL_TSYNC, 1);
    if (rc == 0)
        rc = seccomp_attr_set(ctx, SCMP_FLTATR_ACT_BADARCH, SCMP_ACT_KILL_PROCESS);
    for (size_t i = 0; rc == 0 && i < sizeof sbx__rules / sizeof sbx__rules[0]; i++)
        if (sbx__rules[i].profiles & (1u << profile))
            rc = sbx__add(ctx, &sbx__rules[i]);
    if (rc == 0)
        rc = seccomp_load(ctx);
    seccomp_release(ctx);
    if (rc)
        return errbuf_set(err, errsz, SBX_EFILTER, "sandbox: the %s filter: %s", name, strerror(-rc));
    return SBX_OK;
}

int sbx_calls(sbx_profile profile, void (*fn)(void *ctx, const char *name), void *ctx)
{
    if (!sbx_profile_name(profile))
        return SBX_EPROFILE;
    for (size_t i = 0; i < sizeof sbx__rules / sizeof sbx__rules[0]; i++) {
        if (!(sbx__rules[i].profiles & (1u << profile)) || sbx__rules[i].nr < 0)
            continue;
        char *name = seccomp_syscall_resolve_num_arch(SCMP_ARCH_NATIVE, sbx__rules[i].nr);
        if (name)
            fn(ctx, name);
        free(name);
    }
    return SBX_OK;
}
