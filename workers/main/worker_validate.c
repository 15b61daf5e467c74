/* worker_validate.c — meshcorr-validate, the daemon's check of a SUBMIT
 * before it answers SUBMIT_OK (PROTOCOL.md, SUBMIT). Reads one SUBMIT frame
 * from its stdin, builds the job exactly as a run would
 * (wrk_job_from_submit: the parameters by the one validator, both meshes
 * decoded by Draco and checked by corr_validate, the landmarks against the
 * decoded vertex counts, the maps' rows, and, given the worker's memory
 * limit, the job's estimated peak memory: corr_cost_bytes) and runs
 * nothing. The daemon starts
 * it as a short-lived process under memory and CPU-time limits, so that
 * Draco (which throws and aborts on malformed input) never runs inside the
 * daemon. A program of its own, not a mode of meshcorr-worker: it links
 * worker_job.c and the engine's checks only (Draco, no solver libraries),
 * so it loads in about half the time, once per SUBMIT. */
#include "main/worker.h"
#include "util/errbuf.h"

#include <errno.h>
#include <getopt.h>
#include <malloc.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define PROG "meshcorr-validate"

/* Reads exactly n bytes; 0, or -1 at EOF or on error. */
static int read_all(int fd, void *buf, size_t n)
{
    size_t got = 0;
    while (got < n) {
        ssize_t r = read(fd, (char *)buf + got, n - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            return -1;
        got += (size_t)r;
    }
    return 0;
}

static int write_error(int fd, int code, const char *msg)
{
    proto_msg m;
    char text[PROTO_MAX_STRING + 1];
    wrk_error_msg(&m, code, msg, text);
    proto_buf b;
    proto_buf_init(&b);
    int rc = proto_msg_encode(&b, &m, NULL, 0);
    for (size_t off = 0; rc == 0 && off < b.len;) {
        ssize_t w = write(fd, b.data + off, b.len - off);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            rc = -1;
        else
            off += (size_t)w;
    }
    proto_buf_free(&b);
    return rc;
}

/* bytes as people read them: "137 GB", "6.9 TB", "450 MB" (decimal units) */
static const char *human_bytes(double b, char *buf, size_t sz)
{
    static const char *const unit[] = {"bytes", "kB", "MB", "GB", "TB", "PB"};
    int u = 0;
    while (b >= 1000 && u < 5) {
        b /= 1000;
        u++;
    }
    snprintf(buf, sz, b < 10 && u ? "%.1f %s" : "%.0f %s", b, unit[u]);
    return buf;
}

/* The job's memory at its peak (corr_cost_bytes) against the worker's
 * address-space limit: 0, or PROTO_EOVER_LIMIT naming the estimate, what
 * drives it and the limit. worker_memory_mb 0: no limit, no check. */
static int check_cost(const wrk_job *job, unsigned long long worker_memory_mb, char *err, size_t errsz)
{
    if (!worker_memory_mb)
        return 0;
    corr_input in;
    wrk_job_input(job, &in);
    char what[256], est[32];
    double bytes = corr_cost_bytes(&in, &job->params, what, sizeof what);
    if (bytes <= (double)worker_memory_mb * 1048576.0)
        return 0;
    return errbuf_set(err, errsz, PROTO_EOVER_LIMIT, "job too large for a worker: about %s at its peak for %s,"
                      " over the worker's memory limit of %llu MB (--worker-memory-mb)",
                      human_bytes(bytes, est, sizeof est), what, worker_memory_mb);
}

/* meshcorr-validate, the daemon's check of a SUBMIT: reads one SUBMIT
 * frame from in_fd and builds the job from it as a run would
 * (wrk_job_from_submit), running nothing; with worker_memory_mb (0: none) a job whose estimated peak
 * memory (corr_cost_bytes) is over it is OVER_LIMIT. SPOOL_EXIT_OK when it
 * would run; else one ERROR frame (the code and the message naming the
 * blob, field or estimate) on out_fd and SPOOL_EXIT_JOB. */
static int wrk_validate(int in_fd, int out_fd, const wrk_limits *lim, unsigned long long worker_memory_mb)
{
    uint8_t hdr_bytes[PROTO_HDR_SIZE];
    unsigned char *frame = NULL;
    proto_msg m;
    proto_hdr h;
    wrk_job job;
    char err[4096] = "";
    int rc;
    memset(&m, 0, sizeof m);
    memset(&job, 0, sizeof job);
    if (read_all(in_fd, hdr_bytes, sizeof hdr_bytes)) {
        rc = errbuf_set(err, sizeof err, PROTO_ETRUNCATED, "no SUBMIT frame on the input");
        goto done;
    }
    rc = proto_frame_scan(hdr_bytes, sizeof hdr_bytes, PROTO_MAX_FRAME, &h, err, sizeof err);
    if (rc < 0)
        goto done;
    if (!(frame = malloc(PROTO_HDR_SIZE + (size_t)h.payload_len))) {
        rc = errbuf_set(err, sizeof err, PROTO_ENOMEM, "out of memory for a %u-byte SUBMIT",
                        h.payload_len);
        goto done;
    }
    memcpy(frame, hdr_bytes, sizeof hdr_bytes);
    if (read_all(in_fd, frame + PROTO_HDR_SIZE, h.payload_len)) {
        rc = errbuf_set(err, sizeof err, PROTO_ETRUNCATED, "the input ends inside the SUBMIT frame");
        goto done;
    }
    if ((rc = proto_msg_decode(&h, frame + PROTO_HDR_SIZE, &m, err, sizeof err)))
        goto done;
    if (m.type != PROTO_MSG_SUBMIT) {
        rc = errbuf_set(err, sizeof err, PROTO_EUNEXPECTED, "a %s frame, not SUBMIT",
                        proto_type_name(m.type));
        goto done;
    }
    if ((rc = wrk_job_from_submit(&m.u.submit, lim, &job, err, sizeof err)) == 0)
        rc = check_cost(&job, worker_memory_mb, err, sizeof err);
done:
    wrk_job_close(&job);
    proto_msg_free(&m);
    free(frame);
    if (rc == 0)
        return SPOOL_EXIT_OK;
    if (write_error(out_fd, rc, err))
        fprintf(stderr, PROG ": %s: %s (and the answer could not be written)\n",
                proto_err_name(rc), err);
    return SPOOL_EXIT_JOB;
}

static void usage(void)
{
    fprintf(stderr,
        "usage: " PROG " [--max-vertices N] [--max-faces N] [--max-memory-mb N] [--max-cpu-s N]\n"
        "                         [--worker-memory-mb N]\n"
        "       " PROG " --version\n"
        "Reads one SUBMIT frame on stdin and checks it as a run would, running nothing:\n"
        "exit 0 when the job would run; else one ERROR frame on stdout and exit 1.\n"
        "--worker-memory-mb: the worker's memory limit; a job whose estimated peak is\n"
        "over it is refused OVER_LIMIT (0, the default: no check).\n"
        "Exit 2: bad usage. See workers/WORKER.md.\n");
}

int main(int argc, char **argv)
{
    static const struct option opts[] = {
        {"max-vertices", required_argument, 0, 'v'}, {"max-faces", required_argument, 0, 'f'},
        {"max-memory-mb", required_argument, 0, 'm'}, {"max-cpu-s", required_argument, 0, 'C'},
        {"worker-memory-mb", required_argument, 0, 'W'}, {"help", no_argument, 0, 'h'},
        {"version", no_argument, 0, 'V'},
        {0, 0, 0, 0}};
    wrk_limits lim = { MESH_MAX_VERTICES, MESH_MAX_FACES, 0 };
    unsigned long long max_memory_mb = 0, max_cpu_s = 0, worker_memory_mb = 0;
    int c, bad = 0;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'v': case 'f': case 'm':
            bad |= wrk_limit_option(PROG, c, optarg, &lim, &max_memory_mb) != 0;
            break;
        case 'C': bad |= wrk_parse_num(PROG, "max-cpu-s", optarg, 1, 1ull << 20, &max_cpu_s) != 0; break;
        case 'W':
            bad |= wrk_parse_num(PROG, "worker-memory-mb", optarg, 0, 1ull << 40, &worker_memory_mb) != 0;
            break;
        case 'h': usage(); return SPOOL_EXIT_USAGE;
        case 'V': printf(PROG " %s\n", MC_VERSION); return 0;
        default: bad = 1;
        }
    }
    if (bad || optind != argc) {
        if (!bad)
            fprintf(stderr, PROG ": takes limits only (the frame is on stdin)\n");
        usage();
        return SPOOL_EXIT_USAGE;
    }
    /* the sandbox: bounded memory and CPU time, no files written, no core
     * dumped, few descriptors, then the seccomp allow-list (sandbox.h);
     * all before any input is read */
    signal(SIGPIPE, SIG_IGN);
    /* the two meshes' buffers come and go: keep freed memory for reuse
     * instead of an mmap and its page faults per large buffer */
    mallopt(M_MMAP_THRESHOLD, 64 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
    if ((max_memory_mb && wrk_setlimit(PROG, RLIMIT_AS, "--max-memory-mb", (rlim_t)max_memory_mb << 20)) ||
        (max_cpu_s && wrk_setlimit(PROG, RLIMIT_CPU, "--max-cpu-s", (rlim_t)max_cpu_s)) ||
        wrk_base_limits(PROG, 0, 16))
        return SPOOL_EXIT_USAGE;
    char err[256];
    if (sbx_enter(SBX_VALIDATOR, PROG, err, sizeof err)) {
        fprintf(stderr, PROG ": %s\n", err);
        return SPOOL_EXIT_USAGE;
    }
    return wrk_validate(STDIN_FILENO, STDOUT_FILENO, &lim, worker_memory_mb);
}
