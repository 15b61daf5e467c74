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
 * file, which the backend reads).
 *
 * DESIGN: idle connections cannot use up the daemon. The listener binds
 * loopback unless --slurm-progress says otherwise; at most
 * BK_PROG_MAX_UNIDENTIFIED connections may wait for their hello line (a
 * newer one closes the oldest), each at most BK_PROG_HELLO_TIMEOUT_S; and a
 * connection is taken only above the descriptor floor of TCP clients
 * (fds_tcp_floor), so what the Unix socket, admins and the workers need
 * stays free. Refusals are logged with the peer's address, at most one line
 * a second. */
#include "backend.h"

#include <arpa/inet.h>
#include <stdlib.h>
#include <string.h>

#define BK_PROG_MAX_HELLO 128
#define BK_PROG_MAX_UNIDENTIFIED 16    /* connections waiting for their hello line */
#define BK_PROG_HELLO_TIMEOUT_S 10     /* from the connect to the hello line */
#define BK_PROG_SWEEP_MS 1000

typedef struct prog_conn prog_conn;
struct prog_conn {
    uv_tcp_t tcp;
    bk_prog *p;
    prog_conn *next;
    uint64_t job_id;               /* 0 until the hello line is accepted */
    proto_buf in;
    int closing;
    uint64_t accepted_ms;
    char peer[SRV_MAX_PEER];       /* the worker's address, for the log */
};

struct bk_prog {
    mcd *d;
    uv_tcp_t listener;
    int listening;
    uv_timer_t sweep;              /* the hello timeout */
    int sweeping;
    int handles;                   /* open: the listener, the timer; p is freed after both */
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
    if (!nl) {
        if (c->in.len > BK_PROG_MAX_HELLO)
            dlog(DLOG_WARN, "progress connection from %s: no hello line in %d bytes: closed", c->peer,
                 BK_PROG_MAX_HELLO);
        return c->in.len > BK_PROG_MAX_HELLO ? -1 : 0;
    }
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
        dlog(DLOG_WARN, "progress connection from %s: malformed hello line: closed", c->peer);
        return -1;
    }
    const char *want = id ? c->p->secret(c->p->ctx, id) : NULL;
    if (!want || !secret_eq(want, secret)) {
        dlog(DLOG_WARN, "progress connection from %s for job %llu: %s: closed", c->peer, id,
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

/* At most one line a second for refused or cut connections, with the
 * number of those not logged. */
static void log_cut(uint64_t now, const char *peer, const char *why)
{
    static uint64_t last_ms;
    static unsigned long held_back;
    if (last_ms && now - last_ms < 1000) {
        held_back++;
        return;
    }
    if (held_back)
        dlog(DLOG_WARN, "progress connection from %s closed: %s (and %lu more in the last second)", peer, why,
             held_back);
    else
        dlog(DLOG_WARN, "progress connection from %s closed: %s", peer, why);
    last_ms = now;
    held_back = 0;
}

static void peer_of(prog_conn *c)
{
    struct sockaddr_storage sa;
    int len = sizeof sa;
    snprintf(c->peer, sizeof c->peer, "?");
    if (uv_tcp_getpeername(&c->tcp, (struct sockaddr *)&sa, &len) != 0)
        return;
    if (sa.ss_family == AF_INET)
        inet_ntop(AF_INET, &((struct sockaddr_in *)&sa)->sin_addr, c->peer, sizeof c->peer);
    else if (sa.ss_family == AF_INET6)
        inet_ntop(AF_INET6, &((struct sockaddr_in6 *)&sa)->sin6_addr, c->peer, sizeof c->peer);
}

/* Waiting for their hello line: how many, and the oldest. */
static int unidentified(const bk_prog *p, prog_conn **oldest)
{
    int n = 0;
    *oldest = NULL;
    for (prog_conn *c = p->conns; c; c = c->next)
        if (!c->job_id && !c->closing) {
            n++;
            if (!*oldest || c->accepted_ms <= (*oldest)->accepted_ms)
                *oldest = c;
        }
    return n;
}

static void on_sweep(uv_timer_t *t)
{
    bk_prog *p = t->data;
    uint64_t now = uv_now(p->d->loop);
    prog_conn *next;
    for (prog_conn *c = p->conns; c; c = next) {
        next = c->next;
        if (!c->job_id && now - c->accepted_ms >= 1000ull * BK_PROG_HELLO_TIMEOUT_S) {
            char why[64];
            snprintf(why, sizeof why, "no hello line within %d s", BK_PROG_HELLO_TIMEOUT_S);
            log_cut(now, c->peer, why);
            conn_close(c);
        }
    }
}

static void on_connection(uv_stream_t *server, int status)
{
    bk_prog *p = server->data;
    if (status < 0)
        return;
    const mcd_conf *cf = &p->d->conf;
    long left = fds_free(), floor = fds_tcp_floor(cf, cf->slurm_max_jobs);
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
    c->accepted_ms = uv_now(p->d->loop);
    peer_of(c);
    c->next = p->conns;
    p->conns = c;
    char why[192];
    prog_conn *oldest;
    int n = unidentified(p, &oldest) - 1;      /* c is one of them */
    if (left <= floor) {
        snprintf(why, sizeof why, "%ld file descriptor(s) left under RLIMIT_NOFILE, %ld kept for the workers, "
                 "the Unix socket and admins", left, floor);
        log_cut(c->accepted_ms, c->peer, why);
        conn_close(c);
        return;
    }
    if (n >= BK_PROG_MAX_UNIDENTIFIED && oldest && oldest != c) {
        snprintf(why, sizeof why, "%d connections without a hello line, the limit: the oldest makes room", n);
        log_cut(c->accepted_ms, oldest->peer, why);
        conn_close(oldest);
    }
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
    p->handles = 1;
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
    uv_timer_init(d->loop, &p->sweep);
    p->sweep.data = p;
    p->sweeping = 1;
    p->handles++;
    uv_timer_start(&p->sweep, on_sweep, BK_PROG_SWEEP_MS, BK_PROG_SWEEP_MS);
    dlog(DLOG_INFO, "slurm: progress listener on %s:%d (at most %d connections without a hello line, %d s "
         "each)", host, *port, BK_PROG_MAX_UNIDENTIFIED, BK_PROG_HELLO_TIMEOUT_S);
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

static void on_listener_closed(uv_handle_t *h)
{
    bk_prog *p = h->data;
    if (--p->handles == 0)
        free(p);
}

void bk_prog_close(bk_prog *p)
{
    if (!p)
        return;
    while (p->conns)
        conn_close(p->conns);
    if (p->sweeping)
        uv_close((uv_handle_t *)&p->sweep, on_listener_closed);
    uv_close((uv_handle_t *)&p->listener, on_listener_closed);
}
