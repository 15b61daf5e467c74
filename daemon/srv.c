/* srv.c — the libuv side of meshcorrd: listeners (Unix socket, TCP),
 * connections, framing, and bounded output.
 *
 * DESIGN: the loop never waits for a client. Each connection has a read
 * buffer fed to proto_frame_scan (the header is checked, and the frame size
 * against the limit, before the buffer grows for a payload; the limit is
 * CONF_HELLO_MAX_FRAME until HELLO succeeds) and an output buffer holding at
 * most --max-output bytes: past it a connection stops being read (replies
 * wait for the client), and a connection receiving WATCH frames is dropped.
 * A frame that breaks the byte stream (bad magic, header CRC, version, type,
 * flags, size) gets ERROR, a log line and a close; a payload that does not
 * decode gets ERROR and the connection stays usable (PROTOCOL.md, Errors).
 * Requests themselves are req.c's business.
 *
 * DESIGN: one request at a time per connection. A handler that continues a
 * request in the thread pool (SUBMIT, RESULT) calls srv_conn_hold: the
 * connection stops being read, its frame stays where it is in the read
 * buffer, and the next request waits until srv_conn_release, so replies go
 * out in request order and one client queues at most one work item. A held
 * connection may still close (the client leaves, a write fails, a drain):
 * its memory is freed only when the handle is closed and every hold is
 * released, so an after-work callback may always look at it (srv_send to a
 * closed connection is a no-op). */
#include "mcd.h"

#include <errno.h>
#include <poll.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

struct conn {
    union { uv_handle_t h; uv_stream_t s; uv_tcp_t tcp; uv_pipe_t pipe; } u;
    mcd *d;
    conn *next, *prev;
    unsigned long id;
    conn_auth auth;
    proto_buf in;             /* bytes read, not yet a whole frame */
    proto_buf out;            /* encoded frames not yet handed to uv_write */
    uv_write_t wreq;
    uint8_t *wdata;           /* the buffer of the write in flight */
    size_t inflight;
    int writing, closing, close_after_write, paused;
    int reading;              /* uv_read_start is in effect */
    int holds;                /* srv_conn_hold not yet released: work in flight */
    size_t held_len;          /* bytes of in.data the held request's frame takes */
    int handle_closed;        /* uv_close finished: free once holds is 0 */
};

conn_auth *srv_conn_auth(conn *c) { return &c->auth; }
mcd *srv_conn_daemon(conn *c) { return c->d; }

int srv_conn_fd(conn *c)
{
    uv_os_fd_t fd = -1;
    return uv_fileno(&c->u.h, &fd) == 0 ? fd : -1;
}

static size_t queued(const conn *c)
{
    return c->inflight + c->out.len;
}

static void conn_free(conn *c)
{
    proto_buf_free(&c->in);
    proto_buf_free(&c->out);
    free(c->wdata);
    free(c);
}

static void on_closed(uv_handle_t *h)
{
    conn *c = h->data;
    c->handle_closed = 1;
    if (c->holds == 0)
        conn_free(c);
}

void srv_close(conn *c)
{
    if (c->closing)
        return;
    c->closing = 1;
    req_conn_closed(c->d, c);
    if (c->prev)
        c->prev->next = c->next;
    else
        c->d->conns = c->next;
    if (c->next)
        c->next->prev = c->prev;
    dlog(DLOG_DEBUG, "conn %lu: closed", c->id);
    uv_close(&c->u.h, on_closed);
}

static void process_input(conn *c);
static void on_alloc(uv_handle_t *h, size_t suggested, uv_buf_t *buf);
static void on_read(uv_stream_t *s, ssize_t n, const uv_buf_t *buf);
static void flush(conn *c);

/* Reads while nothing stops it: a close under way, output over the limit
 * (paused), or a request whose work is in flight (holds). */
static void update_reading(conn *c)
{
    int want = !c->closing && !c->close_after_write && !c->paused && !c->holds;
    if (want && !c->reading) {
        int rc = uv_read_start(&c->u.s, on_alloc, on_read);
        if (rc) {
            dlog(DLOG_INFO, "conn %lu: read: %s", c->id, uv_strerror(rc));
            srv_close(c);
            return;
        }
        c->reading = 1;
    } else if (!want && c->reading) {
        uv_read_stop(&c->u.s);
        c->reading = 0;
    }
}

static void on_write(uv_write_t *w, int status)
{
    conn *c = w->data;
    free(c->wdata);
    c->wdata = NULL;
    c->inflight = 0;
    c->writing = 0;
    if (c->closing)
        return;
    if (status < 0) {
        dlog(DLOG_INFO, "conn %lu: write: %s", c->id, uv_strerror(status));
        srv_close(c);
        return;
    }
    flush(c);
    if (c->closing)
        return;
    if (!c->writing && c->close_after_write) {
        srv_close(c);
        return;
    }
    if (c->paused && queued(c) <= c->d->conf.max_output / 2) {
        c->paused = 0;
        update_reading(c);
        process_input(c);
    }
}

static void flush(conn *c)
{
    if (c->writing || c->closing || c->out.len == 0)
        return;
    c->wdata = c->out.data;
    c->inflight = c->out.len;
    proto_buf_init(&c->out);           /* the bytes now belong to the write */
    uv_buf_t b = uv_buf_init((char *)c->wdata, (unsigned)c->inflight);
    c->wreq.data = c;
    c->writing = 1;
    int rc = uv_write(&c->wreq, &c->u.s, &b, 1, on_write);
    if (rc) {
        c->writing = 0;
        dlog(DLOG_INFO, "conn %lu: write: %s", c->id, uv_strerror(rc));
        srv_close(c);
    }
}

int srv_send(conn *c, const proto_msg *m, int drop_if_full)
{
    if (c->closing)
        return -1;
    char err[256];
    int rc = proto_msg_encode(&c->out, m, err, sizeof err);
    if (rc) {
        dlog(DLOG_ERROR, "conn %lu: cannot encode %s: %s", c->id, proto_type_name(m->type), err);
        if (m->type != PROTO_MSG_ERROR) {
            srv_send_error(c, m->request_id, rc == PROTO_ENOMEM ? PROTO_ENOMEM : PROTO_EINTERNAL,
                           "cannot encode the reply: %s", err);
            return 0;
        }
        srv_close(c);
        return -1;
    }
    if (queued(c) > c->d->conf.max_output) {
        if (drop_if_full) {
            dlog(DLOG_WARN, "conn %lu (%s): %zu bytes unread by a watcher, over --max-output %u: dropped",
                 c->id, c->auth.user, queued(c), c->d->conf.max_output);
            srv_close(c);
            return -1;
        }
        c->paused = 1;
        update_reading(c);
    }
    flush(c);
    return 0;
}

void srv_send_error(conn *c, uint32_t request_id, int code, const char *fmt, ...)
{
    if (c->closing)
        return;
    char msg[PROTO_MAX_STRING + 1];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    /* keep the message valid UTF-8 if vsnprintf cut a multi-byte sequence */
    size_t n = strlen(msg);
    while (n > 0 && ((unsigned char)msg[n - 1] & 0xC0) == 0x80)
        n--;
    if (n > 0 && (unsigned char)msg[n - 1] >= 0xC0)
        msg[n - 1] = '\0';
    proto_msg m;
    memset(&m, 0, sizeof m);
    m.type = PROTO_MSG_ERROR;
    m.request_id = request_id;
    m.u.error.code = code;
    m.u.error.message = msg;
    char err[256];
    if (proto_msg_encode(&c->out, &m, err, sizeof err) == 0) {
        flush(c);
    } else {
        m.u.error.message = proto_strerror(code);
        if (proto_msg_encode(&c->out, &m, err, sizeof err) == 0)
            flush(c);
    }
}

void srv_close_soon(conn *c)
{
    if (c->closing)
        return;
    c->close_after_write = 1;
    update_reading(c);
    if (!c->writing)
        srv_close(c);
}

/* Byte-stream errors: ERROR, then close once it is written. */
static void fatal_error(conn *c, uint32_t request_id, int code, const char *msg)
{
    dlog(DLOG_WARN, "conn %lu (%s): %s: %s: closing", c->id, c->auth.authed ? c->auth.user : "-",
         proto_err_name(code), msg);
    srv_send_error(c, request_id, code, "%s", msg);
    srv_close_soon(c);
}

static void process_input(conn *c)
{
    while (!c->closing && !c->close_after_write && !c->paused && !c->holds && c->in.len) {
        size_t limit = c->auth.authed ? c->d->conf.max_frame : CONF_HELLO_MAX_FRAME;
        proto_hdr hdr;
        char err[512];
        int rc = proto_frame_scan(c->in.data, c->in.len, limit, &hdr, err, sizeof err);
        if (rc == PROTO_NEED_MORE)
            return;
        if (rc < 0) {
            fatal_error(c, c->in.len >= PROTO_HDR_SIZE ? hdr.request_id : 0, rc, err);
            return;
        }
        size_t flen = PROTO_HDR_SIZE + (size_t)hdr.payload_len;
        proto_msg m;
        rc = proto_msg_decode(&hdr, c->in.data + PROTO_HDR_SIZE, &m, err, sizeof err);
        if (rc) {
            dlog(DLOG_WARN, "conn %lu: %s %s: %s", c->id, proto_type_name(hdr.type), proto_err_name(rc), err);
            srv_send_error(c, hdr.request_id, rc, "%s", err);
        } else {
            req_handle(c, &m, c->in.data, flen);
            proto_msg_free(&m);
            if (c->holds) {
                /* the frame stays in place for the work (nothing is read
                 * meanwhile); srv_conn_release consumes it */
                c->held_len = flen;
                return;
            }
        }
        proto_buf_consume(&c->in, flen);
    }
}

void srv_conn_hold(conn *c)
{
    c->holds++;
    update_reading(c);
}

void srv_conn_release(conn *c)
{
    if (c->holds <= 0) {
        dlog(DLOG_ERROR, "conn %lu: released more often than held", c->id);
        return;
    }
    if (--c->holds > 0)
        return;
    if (c->handle_closed) {
        conn_free(c);
        return;
    }
    if (c->closing)
        return;                        /* on_closed frees it */
    proto_buf_consume(&c->in, c->held_len);
    c->held_len = 0;
    update_reading(c);
    process_input(c);                  /* requests that arrived meanwhile */
}

int srv_conn_open(const conn *c)
{
    return !c->closing;
}

int srv_conn_hung_up(conn *c)
{
    if (c->closing)
        return 1;
    struct pollfd p = {srv_conn_fd(c), POLLRDHUP, 0};
    return p.fd >= 0 && poll(&p, 1, 0) > 0 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR));
}

static void on_alloc(uv_handle_t *h, size_t suggested, uv_buf_t *buf)
{
    (void)h;
    (void)suggested;
    static char chunk[65536];    /* one loop thread: one read at a time */
    *buf = uv_buf_init(chunk, sizeof chunk);
}

static void on_read(uv_stream_t *s, ssize_t n, const uv_buf_t *buf)
{
    conn *c = s->data;
    if (n < 0) {
        if (n != UV_EOF)
            dlog(DLOG_INFO, "conn %lu: read: %s", c->id, uv_strerror((int)n));
        srv_close(c);
        return;
    }
    if (n == 0 || c->closing || c->close_after_write)
        return;
    proto_buf_put(&c->in, buf->base, (size_t)n);
    if (c->in.err) {
        fatal_error(c, 0, PROTO_ENOMEM, "out of memory for the request");
        return;
    }
    process_input(c);
}

static void on_connection(uv_stream_t *server, int status)
{
    mcd *d = server->data;
    static unsigned long next_id = 1;
    if (status < 0) {
        dlog(DLOG_WARN, "accept: %s", uv_strerror(status));
        return;
    }
    conn *c = calloc(1, sizeof *c);
    if (!c) {
        dlog(DLOG_ERROR, "accept: out of memory");
        return;
    }
    c->d = d;
    c->id = next_id++;
    proto_buf_init(&c->in);
    proto_buf_init(&c->out);
    c->auth.is_unix = server->type == UV_NAMED_PIPE;
    if (c->auth.is_unix)
        uv_pipe_init(d->loop, &c->u.pipe, 0);
    else
        uv_tcp_init(d->loop, &c->u.tcp);
    c->u.h.data = c;
    if (uv_accept(server, &c->u.s) != 0) {
        uv_close(&c->u.h, on_closed);
        return;
    }
    c->next = d->conns;
    if (d->conns)
        d->conns->prev = c;
    d->conns = c;
    dlog(DLOG_DEBUG, "conn %lu: accepted (%s)", c->id, c->auth.is_unix ? "unix" : "tcp");
    update_reading(c);
}

static int listen_unix(mcd *d, const char *path, uv_handle_t **out, char *err, size_t errsz)
{
    struct stat st;
    if (lstat(path, &st) == 0 && S_ISSOCK(st.st_mode))
        unlink(path);                 /* a stale socket of a previous run */
    uv_pipe_t *p = calloc(1, sizeof *p);
    if (!p)
        return snprintf(err, errsz, "out of memory"), -1;
    uv_pipe_init(d->loop, p, 0);
    p->data = d;
    *out = (uv_handle_t *)p;
    int rc = uv_pipe_bind(p, path);
    if (!rc) {
        chmod(path, 0666);            /* any local user; SO_PEERCRED names them */
        rc = uv_listen((uv_stream_t *)p, 128, on_connection);
    }
    if (rc)
        return snprintf(err, errsz, "unix:%s: %s", path, uv_strerror(rc)), -1;
    dlog(DLOG_INFO, "listening on unix:%s", path);
    return 0;
}

static int listen_tcp(mcd *d, const char *hostport, uv_handle_t **out, FILE *portfp,
                      char *err, size_t errsz)
{
    char host[256];
    const char *colon = strrchr(hostport, ':');
    if (!colon || colon == hostport || (size_t)(colon - hostport) >= sizeof host)
        return snprintf(err, errsz, "tcp:%s: expected tcp:HOST:PORT", hostport), -1;
    memcpy(host, hostport, (size_t)(colon - hostport));
    host[colon - hostport] = '\0';
    if (host[0] == '[' && host[strlen(host) - 1] == ']') {
        memmove(host, host + 1, strlen(host));
        host[strlen(host) - 1] = '\0';
    }
    char *e;
    long port = strtol(colon + 1, &e, 10);
    if (*e || port < 0 || port > 65535)
        return snprintf(err, errsz, "tcp:%s: bad port", hostport), -1;
    struct sockaddr_storage sa;
    if (uv_ip4_addr(host, (int)port, (struct sockaddr_in *)&sa) != 0 &&
        uv_ip6_addr(host, (int)port, (struct sockaddr_in6 *)&sa) != 0)
        return snprintf(err, errsz, "tcp:%s: '%s' is not a numeric IP address", hostport, host), -1;
    uv_tcp_t *t = calloc(1, sizeof *t);
    if (!t)
        return snprintf(err, errsz, "out of memory"), -1;
    uv_tcp_init(d->loop, t);
    t->data = d;
    *out = (uv_handle_t *)t;
    int rc = uv_tcp_bind(t, (struct sockaddr *)&sa, 0);
    if (!rc)
        rc = uv_listen((uv_stream_t *)t, 128, on_connection);
    if (rc)
        return snprintf(err, errsz, "tcp:%s: %s", hostport, uv_strerror(rc)), -1;
    struct sockaddr_storage bound;
    int len = sizeof bound;
    uv_tcp_getsockname(t, (struct sockaddr *)&bound, &len);
    char ip[64];
    int bport;
    if (bound.ss_family == AF_INET6) {
        uv_ip6_name((struct sockaddr_in6 *)&bound, ip, sizeof ip);
        bport = ntohs(((struct sockaddr_in6 *)&bound)->sin6_port);
    } else {
        uv_ip4_name((struct sockaddr_in *)&bound, ip, sizeof ip);
        bport = ntohs(((struct sockaddr_in *)&bound)->sin_port);
    }
    dlog(DLOG_INFO, "listening on tcp:%s:%d", ip, bport);
    if (portfp)
        fprintf(portfp, "tcp:%s:%d\n", ip, bport);
    return 0;
}

int srv_listen(mcd *d, char *err, size_t errsz)
{
    d->listeners = calloc((size_t)d->conf.nlisten, sizeof *d->listeners);
    if (!d->listeners)
        return snprintf(err, errsz, "out of memory"), -1;
    FILE *portfp = NULL;
    char tmp[CONF_PATH + 8];
    if (d->conf.port_file[0]) {
        snprintf(tmp, sizeof tmp, "%s.tmp", d->conf.port_file);
        if (!(portfp = fopen(tmp, "w")))
            return snprintf(err, errsz, "%s: %s", tmp, strerror(errno)), -1;
    }
    int rc = 0;
    for (int i = 0; i < d->conf.nlisten && !rc; i++) {
        const char *a = d->conf.listen[i];
        uv_handle_t *h = NULL;
        rc = strncmp(a, "unix:", 5) == 0 ? listen_unix(d, a + 5, &h, err, errsz)
                                         : listen_tcp(d, a + 4, &h, portfp, err, errsz);
        if (h)
            d->listeners[d->nlisteners++] = h;
    }
    if (portfp) {
        /* written whole, then renamed: a reader never sees half a file */
        if (fclose(portfp) != 0 && !rc) {
            snprintf(err, errsz, "%s: %s", tmp, strerror(errno));
            rc = -1;
        }
        if (!rc && rename(tmp, d->conf.port_file) != 0) {
            snprintf(err, errsz, "%s: %s", d->conf.port_file, strerror(errno));
            rc = -1;
        }
    }
    return rc;
}

static void free_handle(uv_handle_t *h)
{
    free(h);
}

void srv_stop_listening(mcd *d)
{
    for (int i = 0; i < d->nlisteners; i++) {
        uv_handle_t *h = d->listeners[i];
        if (h->type == UV_NAMED_PIPE) {
            char path[CONF_PATH];
            size_t len = sizeof path;
            if (uv_pipe_getsockname((uv_pipe_t *)h, path, &len) == 0)
                unlink(path);
        }
        uv_close(h, free_handle);
    }
    d->nlisteners = 0;
}

void srv_close_all(mcd *d)
{
    while (d->conns)
        srv_close(d->conns);
}
