/* worker_main.c — meshcorr-worker's main: command line, signals, and the
 * order of one job (read job.frame, build the job, run, write result.frame
 * or error.frame). The contract with the daemon is workers/WORKER.md; the
 * pieces are in the other worker_*.c files. */
#include "main/worker.h"
#include "util/ompenv.h"

#include <fcntl.h>
#include <getopt.h>
#include <inttypes.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define PROG "meshcorr-worker"

static volatile sig_atomic_t cancel_requested;

static void on_term(int sig)
{
    (void)sig;
    cancel_requested = 1;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void usage(void)
{
    fprintf(stderr,
        "usage: meshcorr-worker --job DIR --job-id ID [--progress-fd N] [--threads N]\n"
        "                       [--max-vertices N] [--max-faces N] [--max-memory-mb N] [--max-cpu-s N]\n"
        "                       [--progress-tcp HOST:PORT --secret-file PATH]\n"
        "       meshcorr-worker --job DIR --job-id ID --picture FILE [--max-vertices N] [--max-faces N]\n"
        "                       [--max-memory-mb N] [--max-cpu-s N]\n"
        "       meshcorr-worker --list-devices [--threads N]\n"
        "       meshcorr-worker --version\n"
        "Runs the job in DIR/job.frame; writes DIR/result.frame (exit 0) or DIR/error.frame\n"
        "(exit 1, or 3 when cancelled by SIGTERM). Exit 2: bad usage; 4: neither could be written.\n"
        "--picture: the finished job's map P drawn into FILE (PNG) from DIR's job.frame and\n"
        "result.frame, as meshcorr eval --out-png draws it (exit 0, else 1).\n"
        "See workers/WORKER.md.\n");
}

typedef struct run_ctx {
    wrk_progress pg;
    double t0;
    int last_outer;
} run_ctx;

static int on_progress(void *ctx, const corr_progress *cp)
{
    run_ctx *rc = ctx;
    if (cp->ectm)
        rc->last_outer = cp->ectm->outer;
    wrk_progress_send(&rc->pg, cp, now() - rc->t0);
    return cancel_requested != 0;
}

/* Writes error.frame; returns the exit status for code. */
static int fail(const char *dir, uint64_t job_id, int code, const char *msg)
{
    fprintf(stderr, "meshcorr-worker: job %" PRIu64 ": %s: %s\n", job_id, proto_err_name(code), msg);
    proto_msg m;
    char text[PROTO_MAX_STRING + 1];
    wrk_error_msg(&m, code, msg, text);
    char err[1024];
    int cancelled = code == PROTO_ECANCELLED;
    if (wrk_frame_write(dir, SPOOL_ERROR_FRAME, &m, err, sizeof err)) {
        fprintf(stderr, "meshcorr-worker: job %" PRIu64 ": cannot write %s: %s\n", job_id,
                SPOOL_ERROR_FRAME, err);
        return cancelled ? SPOOL_EXIT_CANCELLED : SPOOL_EXIT_NO_ANSWER;
    }
    return cancelled ? SPOOL_EXIT_CANCELLED : SPOOL_EXIT_JOB;
}

/* The command line. */
typedef struct worker_opts {
    const char *dir, *progress_tcp, *secret_file;
    const char *picture;          /* --picture FILE: draw the map, run nothing */
    uint64_t job_id;
    int progress_fd;              /* -1: none */
    wrk_limits lim;
} worker_opts;

/* Reads the command line into o and sets the process's resource limits:
 * -1 to go on with the job, else the exit status (bad usage, --help,
 * --version, --list-devices). */
static int parse_options(int argc, char **argv, worker_opts *o)
{
    static const struct option opts[] = {
        {"job", required_argument, 0, 'j'},          {"job-id", required_argument, 0, 'i'},
        {"progress-fd", required_argument, 0, 'p'},  {"threads", required_argument, 0, 't'},
        {"max-vertices", required_argument, 0, 'v'}, {"max-faces", required_argument, 0, 'f'},
        {"progress-tcp", required_argument, 0, 'c'}, {"secret-file", required_argument, 0, 's'},
        {"max-memory-mb", required_argument, 0, 'm'}, {"list-devices", no_argument, 0, 'L'},
        {"max-cpu-s", required_argument, 0, 'C'},    {"help", no_argument, 0, 'h'},
        {"version", no_argument, 0, 'V'},          {"picture", required_argument, 0, 'P'},
        {0, 0, 0, 0}};
    int have_id = 0, bad = 0, list_devices = 0;
    unsigned long long max_memory_mb = 0, max_cpu_s = 0;
    *o = (worker_opts){.progress_fd = -1, .lim = { MESH_MAX_VERTICES, MESH_MAX_FACES, 0 }};
    unsigned long long v;
    int c;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'j': o->dir = optarg; break;
        case 'i':
            if (!(bad |= wrk_parse_num(PROG, "job-id", optarg, 1, UINT64_MAX, &v) != 0)) {
                o->job_id = v;
                have_id = 1;
            }
            break;
        case 'p':
            if (!(bad |= wrk_parse_num(PROG, "progress-fd", optarg, 0, 1 << 20, &v) != 0))
                o->progress_fd = (int)v;
            break;
        case 't':
            if (!(bad |= wrk_parse_num(PROG, "threads", optarg, 0, 1024, &v) != 0))
                o->lim.threads = (int)v;
            break;
        case 'v': case 'f': case 'm':
            bad |= wrk_limit_option(PROG, c, optarg, &o->lim, &max_memory_mb) != 0;
            break;
        case 'C':
            bad |= wrk_parse_num(PROG, "max-cpu-s", optarg, 1, WRK_MAX_CPU_S, &max_cpu_s) != 0;
            break;
        case 'c': o->progress_tcp = optarg; break;
        case 's': o->secret_file = optarg; break;
        case 'L': list_devices = 1; break;
        case 'P': o->picture = optarg; break;
        case 'h': usage(); return SPOOL_EXIT_USAGE;
        case 'V': printf(PROG " %s\n", MC_VERSION); return 0;
        default: bad = 1;
        }
    }
    if (!bad && list_devices)
        return wrk_list_devices(o->lim.threads) ? SPOOL_EXIT_USAGE : 0;
    if (!bad && (!o->dir || !have_id || optind != argc)) {
        fprintf(stderr, "meshcorr-worker: --job and --job-id are required, nothing else\n");
        bad = 1;
    }
    struct stat st;
    if (!bad && (stat(o->dir, &st) != 0 || !S_ISDIR(st.st_mode))) {
        fprintf(stderr, "meshcorr-worker: --job %s: not a directory\n", o->dir);
        bad = 1;
    }
    if (!bad && (!o->progress_tcp != !o->secret_file || (o->progress_tcp && o->progress_fd >= 0))) {
        fprintf(stderr, "meshcorr-worker: --progress-tcp needs --secret-file, and excludes --progress-fd\n");
        bad = 1;
    }
    if (!bad && o->progress_fd >= 0 && fcntl(o->progress_fd, F_GETFD) < 0) {
        fprintf(stderr, "meshcorr-worker: --progress-fd %d: not an open descriptor\n", o->progress_fd);
        bad = 1;
    }
    /* allocations past the limit fail (NOMEM) instead of waking the OOM killer;
     * CPU seconds past the limit end the run by SIGXCPU (a crash); the
     * largest file the worker writes is one frame; no core */
    if (!bad && ((max_memory_mb && wrk_setlimit(PROG, RLIMIT_AS, "--max-memory-mb", (rlim_t)max_memory_mb << 20)) ||
                 (max_cpu_s && wrk_setlimit_cpu(PROG, (rlim_t)max_cpu_s)) ||
                 wrk_base_limits(PROG, WRK_MAX_FILE_BYTES, WRK_MAX_FILES)))
        bad = 1;
    if (bad) {
        usage();
        return SPOOL_EXIT_USAGE;
    }
    return -1;
}

static void catch_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_term;
    sa.sa_flags = SA_RESTART;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);   /* a closed progress pipe is EPIPE, not death */
}

/* The job in o->dir, from job.frame to result.frame or error.frame; the
 * exit status. t0: when the worker started. */
static int run_job(const worker_opts *o, double t0)
{
    int status;
    char err[4096] = "", path[4096];
    unsigned char *frame = NULL;
    proto_msg sub;
    wrk_job job;
    ectm_result res;
    wrk_result out;
    run_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.pg.fd = -1;
    memset(&job, 0, sizeof job);
    memset(&res, 0, sizeof res);
    memset(&out, 0, sizeof out);
    snprintf(path, sizeof path, "%s/%s", o->dir, SPOOL_JOB_FRAME);
    int rc = wrk_frame_read(path, PROTO_MSG_SUBMIT, &frame, &sub, err, sizeof err);
    if (rc) {
        status = fail(o->dir, o->job_id, rc, err);
        goto done;
    }
    ctx.pg.fd = o->progress_fd;
    ctx.pg.job_id = o->job_id;
    ctx.t0 = t0;
    if (o->progress_tcp) {     /* a socket: before the sandbox, which allows none */
        snprintf(ctx.pg.file, sizeof ctx.pg.file, "%s/%s", o->dir, SPOOL_PROGRESS_FILE);
        wrk_progress_connect(&ctx.pg, o->progress_tcp, o->secret_file);
    }
    /* the meshes are Draco bytes from a client: decoded and solved in the
     * sandbox only, the profile by the backend the job asks for */
    if ((rc = sbx_enter(wrk_sandbox_profile(&sub.u.submit), PROG, err, sizeof err))) {
        status = fail(o->dir, o->job_id, PROTO_EINTERNAL, err);
        goto done;
    }
    if ((rc = wrk_job_from_submit(&sub.u.submit, &o->lim, &job, err, sizeof err))) {
        status = fail(o->dir, o->job_id, rc, err);
        goto done;
    }
    corr_input in;
    wrk_job_input(&job, &in);
    if (cancel_requested)
        rc = KIND_ECANCELLED;
    else
        rc = corr_run(&in, &job.params, on_progress, &ctx, &res, err, sizeof err);
    if (rc == KIND_OK && cancel_requested)
        rc = KIND_ECANCELLED;                 /* SIGTERM during the last iteration */
    if (rc == KIND_ECANCELLED)
        snprintf(err, sizeof err, "cancelled by SIGTERM after %d of %d outer iterations",
                 ctx.last_outer, job.params.iterations);
    if (rc) {
        status = fail(o->dir, o->job_id, corr_wire_code(rc), err);
        goto done;
    }
    if ((rc = wrk_result_build(&job, &res, o->job_id, now() - t0, &out, err, sizeof err))) {
        status = fail(o->dir, o->job_id, rc, err);
        goto done;
    }
    if (wrk_frame_write(o->dir, SPOOL_RESULT_FRAME, &out.msg, err, sizeof err)) {
        /* the job did not fail, its answer could not be kept (a full disk):
         * no error.frame, which would end it; it runs again */
        fprintf(stderr, "meshcorr-worker: job %" PRIu64 ": cannot write %s: %s\n", o->job_id,
                SPOOL_RESULT_FRAME, err);
        status = SPOOL_EXIT_NO_ANSWER;
        goto done;
    }
    status = SPOOL_EXIT_OK;
done:
    if (o->progress_tcp && ctx.pg.fd >= 0)
        close(ctx.pg.fd);
    wrk_result_close(&out);
    ectm_result_close(&res);
    wrk_job_close(&job);
    proto_msg_free(&sub);
    free(frame);
    return status;
}

int main(int argc, char **argv)
{
    ompenv_ensure_passive(argv);
    double t0 = now();
    worker_opts o;
    int status = parse_options(argc, argv, &o);
    if (status >= 0)
        return status;
    if (o.picture)
        return wrk_picture(o.dir, o.job_id, &o.lim, o.picture);
    catch_signals();
    return run_job(&o, t0);
}
