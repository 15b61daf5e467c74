/* worker_cli.c — what the two programs of this folder (meshcorr-worker and
 * meshcorr-validate) share around their main: their options' numbers, their
 * resource limits, and the ERROR message each writes for a refused job. */
#include "main/worker.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int wrk_parse_num(const char *prog, const char *opt, const char *s, unsigned long long lo,
                  unsigned long long hi, unsigned long long *out)
{
    char *e;
    errno = 0;
    unsigned long long v = strtoull(s, &e, 10);
    if (*s < '0' || *s > '9' || *e || errno || v < lo || v > hi) {
        fprintf(stderr, "%s: --%s: '%s' is not an integer in [%llu, %llu]\n", prog, opt, s, lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

int wrk_setlimit(const char *prog, int res, const char *what, rlim_t v)
{
    struct rlimit rl = { v, v };
    if (setrlimit(res, &rl) == 0)
        return 0;
    fprintf(stderr, "%s: %s: setrlimit: %s\n", prog, what, strerror(errno));
    return -1;
}

int wrk_limit_option(const char *prog, int opt, const char *arg, wrk_limits *lim,
                     unsigned long long *memory_mb)
{
    unsigned long long v;
    switch (opt) {
    case 'v':
        if (wrk_parse_num(prog, "max-vertices", arg, 3, MESH_MAX_VERTICES, &v))
            return -1;
        lim->max_vertices = (int)v;
        return 0;
    case 'f':
        if (wrk_parse_num(prog, "max-faces", arg, 1, MESH_MAX_FACES, &v))
            return -1;
        lim->max_faces = (int)v;
        return 0;
    default:
        return wrk_parse_num(prog, "max-memory-mb", arg, 1, 1ull << 24, memory_mb);
    }
}

void wrk_error_msg(proto_msg *m, int code, const char *msg, char text[PROTO_MAX_STRING + 1])
{
    memset(m, 0, sizeof *m);
    m->type = PROTO_MSG_ERROR;
    m->u.error.code = code;
    size_t n = strlen(msg);
    if (n > PROTO_MAX_STRING) {              /* cut on a UTF-8 character boundary */
        n = PROTO_MAX_STRING;
        while (n && ((unsigned char)msg[n] & 0xC0) == 0x80)
            n--;
    }
    memcpy(text, msg, n);
    text[n] = '\0';
    m->u.error.message = text;
}

int wrk_setlimit_cpu(const char *prog, rlim_t cpu_s)
{
    struct rlimit old, rl = { cpu_s, cpu_s + WRK_CPU_GRACE_S };
    if (getrlimit(RLIMIT_CPU, &old) == 0 && old.rlim_max != RLIM_INFINITY && old.rlim_max < rl.rlim_max) {
        rl.rlim_max = old.rlim_max;          /* a lower limit inherited stays */
        rl.rlim_cur = cpu_s < old.rlim_max ? cpu_s : old.rlim_max;
    }
    if (setrlimit(RLIMIT_CPU, &rl) == 0)
        return 0;
    fprintf(stderr, "%s: --max-cpu-s: setrlimit: %s\n", prog, strerror(errno));
    return -1;
}

/* The smaller of kernel.pid_max and kernel.threads-max; 0 when unreadable. */
static unsigned long long system_tasks(void)
{
    static const char *const files[] = {"/proc/sys/kernel/pid_max", "/proc/sys/kernel/threads-max"};
    unsigned long long least = 0, v;
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        FILE *fp = fopen(files[i], "r");
        if (!fp)
            continue;
        if (fscanf(fp, "%llu", &v) == 1 && v > 0 && (!least || v < least))
            least = v;
        fclose(fp);
    }
    return least;
}

/* Limit res to at most v, soft and hard; a lower limit inherited stays
 * (raising one needs a privilege the programs do not have). */
static int lower_limit(const char *prog, int res, const char *what, rlim_t v)
{
    struct rlimit rl;
    if (getrlimit(res, &rl) == 0 && rl.rlim_max != RLIM_INFINITY && rl.rlim_max < v)
        v = rl.rlim_max;
    return wrk_setlimit(prog, res, what, v);
}

int wrk_base_limits(const char *prog, rlim_t max_file, rlim_t max_files)
{
    unsigned long long tasks = system_tasks() / 2;
    return lower_limit(prog, RLIMIT_CORE, "core size", 0) ||
           lower_limit(prog, RLIMIT_FSIZE, "file size", max_file) ||
           lower_limit(prog, RLIMIT_NOFILE, "descriptors", max_files) ||
           (tasks && lower_limit(prog, RLIMIT_NPROC, "tasks", (rlim_t)tasks)) ? -1 : 0;
}

sbx_profile wrk_sandbox_profile(const proto_submit *s)
{
    const char *b = s->params.backend ? s->params.backend : "";
    return strncmp(b, "opencl", 6) == 0 || strncmp(b, "auto", 4) == 0 ? SBX_WORKER_OPENCL : SBX_WORKER;
}
