/* val.c — the check of a SUBMIT before SUBMIT_OK: the frame goes through a
 * pipe to meshcorr-validate, a short-lived child that decodes
 * both meshes with Draco and builds the job exactly as a run would
 * (workers/main/worker_validate.c), under an address-space and a CPU-time
 * limit, so a mesh that crashes or exhausts Draco costs a child, never the
 * daemon.
 *
 * DESIGN: val_submit runs in libuv's thread pool (req.c's SUBMIT work, before
 * store_submit) and blocks only that thread. The child is started with
 * posix_spawn (DESIGN: never a plain fork after threads), every descriptor
 * but its stdin/stdout pipes closed, an empty signal mask and default
 * signal actions, and reaped by its pid (libuv reaps only its own
 * children's pids). Holds no daemon state: val_conf is a copy taken on the
 * loop. */
#include "mcd.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char **environ;

#define VAL_MAX_REPLY  (PROTO_HDR_SIZE + PROTO_MAX_STRING + 64)  /* one ERROR frame */

void val_conf_of(const mcd *d, val_conf *vc)
{
    char buf[CONF_PATH + 64];
    memset(vc, 0, sizeof *vc);
    snprintf(vc->validator, sizeof vc->validator, "%s", conf_validator_path(&d->conf, buf, sizeof buf));
    vc->max_vertices = d->conf.max_vertices;
    vc->max_faces = conf_max_faces(&d->conf);
    /* a decoded mesh is well under 256 bytes a vertex (Draco's buffers,
     * positions, faces, the check's tables); the worker's limit when one
     * was given */
    uint32_t wm = d->conf.worker_memory_mb;
    vc->max_memory_mb = wm && wm != CONF_WORKER_MEMORY_AUTO
                            ? wm
                            : VAL_BASE_MEMORY_MB + (unsigned)(2ull * d->conf.max_vertices * 256 >> 20);
    vc->max_cpu_s = VAL_MAX_CPU_S;
    vc->worker_memory_mb = d->conf.worker_memory_mb;
}

static int write_all(int fd, const void *p, size_t n)
{
    while (n) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return -1;          /* EPIPE: the child stopped reading (it answered early) */
        p = (const char *)p + w;
        n -= (size_t)w;
    }
    return 0;
}

/* The validator's answer from fd (its stdout) into reply, up to
 * VAL_MAX_REPLY bytes; the bytes read. */
static size_t read_reply(int fd, uint8_t *reply)
{
    size_t got = 0;
    for (;;) {
        ssize_t r = read(fd, reply + got, VAL_MAX_REPLY - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        got += (size_t)r;
        if (got == VAL_MAX_REPLY)
            break;
    }
    return got;
}

/* What the validator's wait status st and its answer reply (got bytes)
 * say: 0 (the meshes can run), the ERROR it wrote, BAD_MESH for a mesh
 * that crashed it or ran out of CPU time, else INTERNAL; msg says why. */
static int verdict(const val_conf *vc, int st, const uint8_t *reply, size_t got, char *msg, size_t msz)
{
    int rc = PROTO_EINTERNAL;
    if (WIFEXITED(st) && WEXITSTATUS(st) == 0)
        return 0;
    if (WIFEXITED(st) && WEXITSTATUS(st) == 1) {
        proto_msg m;
        size_t used;
        char derr[256];
        if (proto_decode(reply, got, VAL_MAX_REPLY, &m, &used, derr, sizeof derr) == PROTO_READY &&
            m.type == PROTO_MSG_ERROR) {
            rc = m.u.error.code;
            snprintf(msg, msz, "%s", m.u.error.message);
            proto_msg_free(&m);
        } else {
            snprintf(msg, msz, "the meshes cannot be checked: the validator's answer does not decode");
        }
    } else if (WIFSIGNALED(st) && (WTERMSIG(st) == SIGXCPU || WTERMSIG(st) == SIGKILL)) {
        rc = PROTO_EBAD_MESH;
        snprintf(msg, msz, "the meshes could not be decoded and checked within %u s of CPU time",
                 vc->max_cpu_s);
    } else if (WIFSIGNALED(st)) {
        rc = PROTO_EBAD_MESH;        /* Draco aborted or crashed on these bytes */
        snprintf(msg, msz, "a mesh crashed the decoder (%s) while it was checked", strsignal(WTERMSIG(st)));
    } else {
        snprintf(msg, msz, "the meshes cannot be checked: %s exited %d", vc->validator,
                 WIFEXITED(st) ? WEXITSTATUS(st) : -1);
    }
    return rc;
}

int val_submit(const val_conf *vc, const void *frame, size_t len, double *ms, double *cpu_ms, char *msg,
               size_t msz)
{
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    if (cpu_ms)
        *cpu_ms = 0;
    char maxv[24], maxf[24], mem[24], cpu[24], wmem[24];
    snprintf(maxv, sizeof maxv, "%u", vc->max_vertices);
    snprintf(maxf, sizeof maxf, "%llu", vc->max_faces);
    snprintf(mem, sizeof mem, "%u", vc->max_memory_mb);
    snprintf(cpu, sizeof cpu, "%u", vc->max_cpu_s);
    snprintf(wmem, sizeof wmem, "%u", vc->worker_memory_mb);
    char *argv[] = { (char *)vc->validator, "--max-vertices", maxv, "--max-faces", maxf,
                     "--max-memory-mb", mem, "--max-cpu-s", cpu, "--worker-memory-mb", wmem, NULL };
    int in[2] = {-1, -1}, out[2] = {-1, -1}, rc = PROTO_EINTERNAL;
    pid_t pid = -1;
    posix_spawn_file_actions_t fa;
    posix_spawnattr_t at;
    posix_spawn_file_actions_init(&fa);
    posix_spawnattr_init(&at);
    if (pipe2(in, O_CLOEXEC) || pipe2(out, O_CLOEXEC)) {
        snprintf(msg, msz, "the meshes cannot be checked: pipe: %s", strerror(errno));
        goto done;
    }
    sigset_t none, dflt;
    sigemptyset(&none);
    sigemptyset(&dflt);
    sigaddset(&dflt, SIGPIPE);
    sigaddset(&dflt, SIGTERM);
    sigaddset(&dflt, SIGINT);
    sigaddset(&dflt, SIGHUP);
    sigaddset(&dflt, SIGXCPU);
    int e;
    if ((e = posix_spawn_file_actions_adddup2(&fa, in[0], STDIN_FILENO)) ||
        (e = posix_spawn_file_actions_adddup2(&fa, out[1], STDOUT_FILENO)) ||
        (e = posix_spawn_file_actions_addclosefrom_np(&fa, STDERR_FILENO + 1)) ||
        (e = posix_spawnattr_setsigmask(&at, &none)) || (e = posix_spawnattr_setsigdefault(&at, &dflt)) ||
        (e = posix_spawnattr_setflags(&at, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF)) ||
        (e = posix_spawn(&pid, vc->validator, &fa, &at, argv, environ))) {
        snprintf(msg, msz, "the meshes cannot be checked: cannot start %s: %s", vc->validator,
                 strerror(e));
        goto done;
    }
    close(in[0]);
    close(out[1]);
    in[0] = out[1] = -1;
    write_all(in[1], frame, len);    /* a short write is the child's early answer, read below */
    close(in[1]);
    in[1] = -1;
    uint8_t reply[VAL_MAX_REPLY];
    size_t got = read_reply(out[0], reply);
    int st = 0;
    struct rusage ru;
    memset(&ru, 0, sizeof ru);
    while (wait4(pid, &st, 0, &ru) < 0 && errno == EINTR)
        ;
    if (cpu_ms)
        *cpu_ms = 1e3 * (double)(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
                  1e-3 * (double)(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
    rc = verdict(vc, st, reply, got, msg, msz);
done:
    for (int i = 0; i < 2; i++) {
        if (in[i] >= 0)
            close(in[i]);
        if (out[i] >= 0)
            close(out[i]);
    }
    posix_spawn_file_actions_destroy(&fa);
    posix_spawnattr_destroy(&at);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (ms)
        *ms = 1e3 * (double)(t1.tv_sec - t0.tv_sec) + 1e-6 * (double)(t1.tv_nsec - t0.tv_nsec);
    return rc;
}
