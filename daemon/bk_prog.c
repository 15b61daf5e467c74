/* bk_prog.c — the TCP listener Slurm workers stream their PROGRESS frames
 * to (backend.h, bk_prog_). A connection first sends one line,
 * "MCPROGRESS <job-id> <secret>\n" (at most BK_PROG_MAX_HELLO bytes); the
 * secret is checked in constant time against the one the backend wrote to
 * the job's spool; then its bytes are PROGRESS frames (job_progress_take).
 *
 * DESIGN: nothing a connection sends can do more than add progress records
 * to the one job whose secret it knows. Before the hello line is accepted
 * the connection may send BK_PROG_MAX_HELLO bytes, and a wrong line closes
 * it; one job has at most one connection (a newer one replaces it); a
 * malformed frame closes it (the worker then falls back to its progress
 * file, which the backend reads). */
#include "backend.h"

#include <stdlib.h>
#include <string.h>

#define BK_PROG_MAX_HELLO 128

typedef struct prog_conn prog_conn;
struct prog_conn {
    uv_tcp_t tcp;
    bk_prog *p;
    prog_conn *next;
    uint64_t job_id;               /* 0 until the hello line is accepted */
    proto_buf in;
    int closing;
};

struct bk_prog {
    mcd *d;
    uv_tcp_t listener;
    int listening;
    prog_conn *conns;
    bk_prog_secret_fn secret;
    void *ctx;
};

static void on_conn_closed(uv_handle_t *h)
{
    prog_conn *c = h->data;
    proto_buf_free(&c->in);
    free(c);
}

static void conn_close(prog_conn *c)
{
    if (c->closing)
        return;
    c->closing = 1;
    for (prog_conn **pc = &c->p->conns; *pc; pc = &(*pc)->next)
        if (*pc == c) {
            *pc = c->next;
            break;
        }
    uv_close((uv_handle_t *)&c->tcp, on_conn_closed);
}

static int secret_eq(const char *a, const char *b)
{
    unsigned char diff = 0;
    for (int i = 0; i < BK_SECRET_HEX; i++)
        diff |= (unsigned char)(a[i] ^ b[i]);
    return diff == 0;
}

/* 1 accepted, 0 more bytes needed, -1 refused. */
static int take_hello(prog_conn *c)
{
    char *nl = memchr(c->in.data, '\n', c->in.len);
    if (!nl)
        return c->in.len > BK_PROG_MAX_HELLO ? -1 : 0;
    size_t n = (size_t)(nl - (char *)c->in.data);
    char line[BK_PROG_MAX_HELLO + 1], secret[BK_SECRET_HEX + 2];
    unsigned long long id;
    if (n > BK_PROG_MAX_HELLO)
        return -1;
    memcpy(line, c->in.data, n);
    line[n] = '\0';
    int k = 0;
    if (sscanf(line, BK_PROG_HELLO " %llu %65s%n", &id, secret, &k) != 2 || line[k] != '\0' ||
        strlen(secret) != BK_SECRET_HEX) {
        dlog(DLOG_WARN, "progress connection: malformed hello line: closed");
        return -1;
    }
    const char *want = id ? c->p->secret(c->p->ctx, id) : NULL;
    if (!want || !secret_eq(want, secret)) {
        dlog(DLOG_WARN, "progress connection for job %llu: %s: closed", id,
             want ? "wrong secret" : "no such job running in Slurm");
        return -1;
    }
    for (prog_conn *o = c->p->conns; o; o = o->next)
        if (o != c && o->job_id == id) {
            conn_close(o);          /* a worker reconnecting: the newest wins */
            break;
        }
    c->job_id = id;
    proto_buf_consume(&c->in, n + 1);
    dlog(DLOG_DEBUG, "job %llu: progress connection from its worker", id);
    return 1;
}

static void on_alloc(uv_handle_t *h, size_t suggested, uv_buf_t *buf)
{
    (void)h;
    (void)suggested;
    static char chunk[16384];
    *buf = uv_buf_init(chunk, sizeof chunk);
}

static void on_read(uv_stream_t *st, ssize_t n, const uv_buf_t *buf)
{
    prog_conn *c = st->data;
    if (n < 0) {
        conn_close(c);
        return;
    }
    if (n == 0 || c->closing)
        return;
    proto_buf_put(&c->in, buf->base, (size_t)n);
    if (c->in.err) {
        conn_close(c);
        return;
    }
    if (!c->job_id) {
        int rc = take_hello(c);
        if (rc <= 0) {
            if (rc < 0)
                conn_close(c);
            return;
        }
    }
    if (job_progress_take(c->p->d, c->job_id, &c->in) < 0)
        conn_close(c);
}

static void on_connection(uv_stream_t *server, int status)
{
    bk_prog *p = server->data;
    if (status < 0)
        return;
    prog_conn *c = calloc(1, sizeof *c);
    if (!c)
        return;
    c->p = p;
    proto_buf_init(&c->in);
    uv_tcp_init(p->d->loop, &c->tcp);
    c->tcp.data = c;
    if (uv_accept(server, (uv_stream_t *)&c->tcp) != 0) {
        c->closing = 1;
        uv_close((uv_handle_t *)&c->tcp, on_conn_closed);
        return;
    }
    c->next = p->conns;
    p->conns = c;
    uv_read_start((uv_stream_t *)&c->tcp, on_alloc, on_read);
}

int bk_prog_listen(mcd *d, const char *hostport, bk_prog_secret_fn fn, void *ctx, bk_prog **out,
                   int *port, char *err, size_t errsz)
{
    *out = NULL;
    char host[256];
    const char *colon = strrchr(hostport, ':');
    if (!colon || colon == hostport || (size_t)(colon - hostport) >= sizeof host)
        return snprintf(err, errsz, "slurm-progress %s: expected HOST:PORT", hostport), -1;
    memcpy(host, hostport, (size_t)(colon - hostport));
    host[colon - hostport] = '\0';
    char *e;
    long pn = strtol(colon + 1, &e, 10);
    if (*e || pn < 0 || pn > 65535)
        return snprintf(err, errsz, "slurm-progress %s: bad port", hostport), -1;
    struct sockaddr_storage sa;
    if (uv_ip4_addr(host, (int)pn, (struct sockaddr_in *)&sa) != 0 &&
        uv_ip6_addr(host, (int)pn, (struct sockaddr_in6 *)&sa) != 0)
        return snprintf(err, errsz, "slurm-progress %s: '%s' is not a numeric address", hostport, host), -1;
    bk_prog *p = calloc(1, sizeof *p);
    if (!p)
        return snprintf(err, errsz, "out of memory"), -1;
    p->d = d;
    p->secret = fn;
    p->ctx = ctx;
    uv_tcp_init(d->loop, &p->listener);
    p->listener.data = p;
    p->listening = 1;
    *out = p;
    int rc = uv_tcp_bind(&p->listener, (struct sockaddr *)&sa, 0);
    if (!rc)
        rc = uv_listen((uv_stream_t *)&p->listener, 128, on_connection);
    if (rc)
        return snprintf(err, errsz, "slurm-progress %s: %s", hostport, uv_strerror(rc)), -1;
    struct sockaddr_storage bound;
    int len = sizeof bound;
    uv_tcp_getsockname(&p->listener, (struct sockaddr *)&bound, &len);
    *port = ntohs(bound.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&bound)->sin6_port
                                              : ((struct sockaddr_in *)&bound)->sin_port);
    dlog(DLOG_INFO, "slurm: progress listener on %s:%d", host, *port);
    return 0;
}

void bk_prog_forget(bk_prog *p, uint64_t id)
{
    if (!p)
        return;
    for (prog_conn *c = p->conns; c; c = c->next)
        if (c->job_id == id) {
            conn_close(c);
            return;
        }
}

int bk_prog_connected(const bk_prog *p, uint64_t id)
{
    for (prog_conn *c = p ? p->conns : NULL; c; c = c->next)
        if (c->job_id == id)
            return 1;
    return 0;
}

static void on_listener_closed(uv_handle_t *h)
{
    free(h->data);
}

void bk_prog_close(bk_prog *p)
{
    if (!p)
        return;
    while (p->conns)
        conn_close(p->conns);
    uv_close((uv_handle_t *)&p->listener, on_listener_closed);
}
