/* bk_cmd.c — runs one external command (sbatch, squeue, scancel, ...) from
 * the loop without blocking it: uv_spawn with stdout and stderr on pipes read
 * as they come, a timer that SIGKILLs it past its time, and one callback when
 * the process has exited and both pipes are closed. Output past
 * BK_CMD_MAX_OUTPUT is dropped (the command still runs to its end). Knows
 * nothing about Slurm. */
#include "backend.h"

#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct cmd_out {
    char *buf;
    size_t len;
} cmd_out;

struct bk_cmd {
    uv_process_t proc;
    uv_pipe_t pipes[2];            /* stdout, stderr */
    uv_timer_t timer;
    cmd_out out[2];
    int open_handles, status, killed, spawned;
    char what[300];
    bk_cmd_fn fn;
    void *ctx;
};

const char *bk_cmd_which(const char *name, char *buf, size_t sz)
{
    if (strchr(name, '/'))
        return access(name, X_OK) == 0 ? snprintf(buf, sz, "%s", name), buf : NULL;
    const char *path = getenv("PATH");
    if (!path)
        return NULL;
    while (*path) {
        const char *colon = strchr(path, ':');
        size_t n = colon ? (size_t)(colon - path) : strlen(path);
        snprintf(buf, sz, "%.*s/%s", (int)n, n ? path : ".", name);
        if (access(buf, X_OK) == 0)
            return buf;
        path += n + (colon != NULL);
    }
    return NULL;
}

static void on_closed(uv_handle_t *h)
{
    bk_cmd *c = h->data;
    if (--c->open_handles > 0)
        return;
    const char *err = c->out[1].buf;
    char why[320];
    if (!c->spawned || c->killed) {
        snprintf(why, sizeof why, "%s", c->killed ? "killed: it ran past its time limit" : c->what);
        err = why;
    }
    c->fn(c->ctx, c->status, c->out[0].buf, err);
    free(c->out[0].buf);
    free(c->out[1].buf);
    free(c);
}

static void close_all(bk_cmd *c)
{
    uv_handle_t *hs[] = {(uv_handle_t *)&c->proc, (uv_handle_t *)&c->pipes[0],
                         (uv_handle_t *)&c->pipes[1], (uv_handle_t *)&c->timer};
    for (size_t i = 0; i < 4; i++)
        if (!uv_is_closing(hs[i]))
            uv_close(hs[i], on_closed);
}

static void maybe_done(bk_cmd *c)
{
    /* done when the process has exited and both pipes reached EOF */
    if (c->status != -2 && !uv_is_active((uv_handle_t *)&c->pipes[0]) &&
        !uv_is_active((uv_handle_t *)&c->pipes[1]))
        close_all(c);
}

static void on_alloc(uv_handle_t *h, size_t suggested, uv_buf_t *buf)
{
    (void)h;
    (void)suggested;
    static char chunk[16384];      /* one loop thread: one read at a time */
    *buf = uv_buf_init(chunk, sizeof chunk);
}

static void on_read(uv_stream_t *st, ssize_t n, const uv_buf_t *buf)
{
    bk_cmd *c = st->data;
    cmd_out *o = &c->out[st == (uv_stream_t *)&c->pipes[0] ? 0 : 1];
    if (n > 0) {
        size_t take = (size_t)n;
        if (o->len + take > BK_CMD_MAX_OUTPUT)
            take = BK_CMD_MAX_OUTPUT - o->len;
        memcpy(o->buf + o->len, buf->base, take);
        o->len += take;
        o->buf[o->len] = '\0';
        return;
    }
    if (n < 0) {
        uv_read_stop(st);
        maybe_done(c);
    }
}

static void on_exit_cb(uv_process_t *p, int64_t status, int sig)
{
    bk_cmd *c = p->data;
    c->status = sig ? -1 : (int)status;
    uv_timer_stop(&c->timer);
    maybe_done(c);
}

static void on_timeout(uv_timer_t *t)
{
    bk_cmd *c = t->data;
    c->killed = 1;
    uv_process_kill(&c->proc, SIGKILL);
}

int bk_cmd_run(uv_loop_t *loop, char *const argv[], uint64_t timeout_ms, bk_cmd_fn fn, void *ctx)
{
    bk_cmd *c = calloc(1, sizeof *c);
    if (!c)
        return -1;
    for (int i = 0; i < 2; i++)
        if (!(c->out[i].buf = calloc(1, BK_CMD_MAX_OUTPUT + 1))) {
            free(c->out[0].buf);
            free(c);
            return -1;
        }
    c->fn = fn;
    c->ctx = ctx;
    c->status = -2;                /* running */
    c->proc.data = c->timer.data = c->pipes[0].data = c->pipes[1].data = c;
    uv_pipe_init(loop, &c->pipes[0], 0);
    uv_pipe_init(loop, &c->pipes[1], 0);
    uv_timer_init(loop, &c->timer);
    c->open_handles = 4;
    uv_stdio_container_t stdio[3];
    stdio[0].flags = UV_IGNORE;
    stdio[1].flags = UV_CREATE_PIPE | UV_WRITABLE_PIPE;
    stdio[1].data.stream = (uv_stream_t *)&c->pipes[0];
    stdio[2].flags = UV_CREATE_PIPE | UV_WRITABLE_PIPE;
    stdio[2].data.stream = (uv_stream_t *)&c->pipes[1];
    uv_process_options_t opt;
    memset(&opt, 0, sizeof opt);
    opt.file = argv[0];
    opt.args = (char **)argv;
    opt.exit_cb = on_exit_cb;
    opt.stdio = stdio;
    opt.stdio_count = 3;
    int rc = uv_spawn(loop, &c->proc, &opt);
    if (rc) {
        /* the process handle must still be closed; the callback says why */
        snprintf(c->what, sizeof c->what, "cannot run %s: %s", argv[0], uv_strerror(rc));
        c->status = -1;
        close_all(c);
        return 0;
    }
    c->spawned = 1;
    uv_read_start((uv_stream_t *)&c->pipes[0], on_alloc, on_read);
    uv_read_start((uv_stream_t *)&c->pipes[1], on_alloc, on_read);
    uv_timer_start(&c->timer, on_timeout, timeout_ms, 0);
    return 0;
}
