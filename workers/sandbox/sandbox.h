/* sandbox.h — the sandbox the programs that decode and solve untrusted jobs
 * (meshcorr-validate, meshcorr-worker) enter once their set-up is done and
 * before they touch the job's bytes: no_new_privs, then a seccomp allow-list
 * of system calls for every thread of the process.
 *
 * A system call outside the profile's list is not executed: the process
 * writes one line naming the call's number to stderr and dies by SIGSYS (a
 * worker's crash, for the daemon). A few calls that libraries only probe
 * and do without are answered with an error instead (clone3: ENOSYS, so
 * glibc falls back to clone, whose flags the filter can check; ioctl:
 * ENOTTY; the validator's opens: EPERM). docs/decisions.md says what each
 * group of calls is there for and how the lists were measured;
 * workers/WORKER.md describes what the sandboxed programs may do.
 *
 * Engine-side code: no daemon knowledge, no allocation the caller owns. */
#ifndef SANDBOX_H
#define SANDBOX_H
#include <stddef.h>

typedef enum sbx_profile {
    SBX_VALIDATOR,      /* meshcorr-validate: read stdin, write stdout/stderr,
                           memory, threads; opens nothing */
    SBX_WORKER,         /* meshcorr-worker, CPU backend: also files (the
                           libraries it loads late, its answer in the spool) */
    SBX_WORKER_OPENCL,  /* a worker whose job asks for OpenCL: also PoCL's
                           kernel cache and the linker PoCL runs, device
                           ioctls, and no W^X rule (a GPU driver may JIT) */
} sbx_profile;

enum {
    SBX_OK = 0,
    SBX_EPROFILE = -1,  /* not a profile */
    SBX_ENNP = -2,      /* prctl(PR_SET_NO_NEW_PRIVS) failed */
    SBX_EFILTER = -3,   /* the seccomp filter could not be built or loaded */
};

/* Enters the sandbox: no_new_privs, a SIGSYS handler that names a refused
 * call (prog starts its line; kept, not copied), then profile's filter for
 * every thread (seccomp TSYNC). There is no way back. 0, or a negative
 * SBX_E* with the detail in err. */
int sbx_enter(sbx_profile profile, const char *prog, char *err, size_t errsz);

/* Calls fn with the name of every call profile lets through or answers
 * (once per rule: a call with two rules comes twice), for checks against
 * the other filters a process may run under (the service unit's
 * SystemCallFilter=: the strictest answer of all filters wins). 0, or
 * SBX_EPROFILE. sbx_enter itself needs prctl and seccomp besides. */
int sbx_calls(sbx_profile profile, void (*fn)(void *ctx, const char *name), void *ctx);

/* "validator", "worker", "worker-opencl"; NULL for another value. */
const char *sbx_profile_name(sbx_profile profile);

#endif
