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
 * closed connection is a no-op).
 *
 * DESIGN: idle clients never cost an acknowledged job, and nobody who has
 * not logged in can keep anyone else out. Budgets are separate: TCP
 * connections that have not done HELLO are at most --max-unauthenticated
 * in all and --max-unauthenticated-per-address from one address (an IPv4
 * address or IPv6 /64; on the Unix socket a local uid, root and
 * --admin-uid exempt), and
 * when a new one arrives over either cap the OLDEST such connection (of
 * that address, or of all) is closed in its place, so a client that does
 * its HELLO at once always gets in; sessions (after HELLO) count against
 * --max-connections and --max-connections-per-user, admins against
 * neither. Descriptors are budgeted in tiers (fds.c): the Unix socket is
 * served while more than --fd-reserve are free (kept for the workers: their
 * pipes, the database, the spool), a TCP client only while more than
 * --admin-reserve beyond that are free, or in the place of the oldest TCP
 * connection without HELLO. A refused or displaced client is told why
 * (ERROR BUSY, request id 0), the refusal is logged with the address, and
 * the connection lingers a moment (reading and dropping what the client
 * sends) so the ERROR is read rather than lost to a reset; TCP ones linger
 * only while few do. A timer cuts connections that hold resources for
 * nothing: no HELLO within --hello-timeout, a frame still incomplete
 * --request-timeout after its first byte, or a session with nothing going
 * on (no request in flight, no live WATCH, nothing unread, no byte from
 * the client) for --idle-timeout; each gets ERROR TIMED_OUT and a log line.
 * What clients have half sent is bounded in all: a frame counts against
 * --max-request-memory from its header to its end (admit), and against its
 * user's share of it, one that does not fit is refused BUSY the same way,
 * and a buffer grown for a large frame is freed once it is done. A
 * connection whose output has been written whole tells req.c
 * (req_conn_sent): its RESULTs end there.
 *
 * DESIGN: a tls: listener's connections carry the same frames inside a
 * GnuTLS session (tls.c). What libuv reads is fed to the session and the
 * plaintext it yields goes to the framing code as a plain connection's
 * bytes would; what the framing code queues in `out` is sealed into records
 * (tls_out) once the handshake is done, and those are what uv_write sends.
 * Every bound above holds over TLS: queued output counts the records, the
 * read stops as for a plain connection, a half-done handshake is an
 * unauthenticated connection (cut by --hello-timeout, counted under
 * --max-unauthenticated), and a refused client completes its handshake to
 * read its ERROR. A failed handshake is logged with the peer's address and
 * GnuTLS's reason, and the connection closes after the alert. A plain tcp:
 * listener binds loopback only unless --insecure-tcp says otherwise. */
#include "mcd.h"
#include "backend.h"

#include <arpa/inet.h>
#include <errno.h>
#include <poll.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#define SRV_SWEEP_MS 250           /* how often the connection timeouts are checked */
#define SRV_REFUSE_LINGER_MS 2000  /* a refused connection waits this long for the client's EOF */
#define SRV_MAX_LINGER 64          /* displaced or TCP refused connections lingering at once; more close at once */

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
    int refused;              /* told BUSY: input dropped, closed soon */
    int unix_admin;           /* Unix socket, root or --admin-uid: no per-uid cap */
    uint64_t refused_ms;      /* loop time of the refusal */
    uint64_t accepted_ms;     /* loop time of the accept */
    uint64_t frame_ms;        /* when the incomplete frame in `in` began; 0: none */
    uint64_t active_ms;       /* last byte read, write done or request finished */
    size_t admitted;          /* the incomplete frame's length, counted in admitted_total */
    tls_conn *tls;            /* a tls: listener's session; in and out hold plaintext */
    proto_buf tls_out;        /* records sealed, not yet handed to uv_write */
};

/* Bytes of the frames being received (admitted, not yet consumed), all
 * connections: at most conf.max_request_memory (one loop). */
static size_t admitted_total;

static uv_timer_t sweep_timer;     /* the connection timeouts (one loop) */
static int sweep_on;

/* The tls: listeners (one loop). */
static const uv_handle_t *tls_listeners[CONF_MAX_LISTEN];
static int ntls_listeners;

conn_auth *srv_conn_auth(conn *c) { return &c->auth; }
mcd *srv_conn_daemon(conn *c) { return c->d; }

int srv_conn_fd(conn *c)
{
    uv_os_fd_t fd = -1;
    return uv_fileno(&c->u.h, &fd) == 0 ? fd : -1;
}

static size_t queued(const conn *c)
{
    return c->inflight + c->out.len + c->tls_out.len;
}

/* The frame at the front of c->in is consumed (or c is gone): its bytes
 * leave the count, and a buffer grown for a large frame is given back. */
#define SRV_KEEP_INPUT_CAP (1u << 20)
static void frame_done(conn *c)
{
    admitted_total -= c->admitted;
    c->admitted = 0;
    if (c->in.len == 0 && c->in.cap > SRV_KEEP_INPUT_CAP) {
        proto_buf_free(&c->in);
        proto_buf_init(&c->in);
    }
}

static void conn_free(conn *c)
{
    admitted_total -= c->admitted;
    c->admitted = 0;
    proto_buf_free(&c->in);
    proto_buf_free(&c->out);
    proto_buf_free(&c->tls_out);
    tls_conn_free(c->tls);
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

static void srv_close(conn *c)
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
static int tls_goodbye(conn *c);

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
    c->active_ms = uv_now(c->d->loop);
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
    if (!c->writing)
        req_conn_sent(c->d, c);        /* all written: the RESULTs it was sending end */
    if (c->closing)
        return;
    if (!c->writing && c->close_after_write) {
        if (!tls_goodbye(c))
            srv_close(c);
        return;
    }
    if (c->paused && queued(c) <= c->d->conf.max_output / 2) {
        c->paused = 0;
        if (c->frame_ms)               /* the request clock stood while we did not read */
            c->frame_ms = c->active_ms;
        update_reading(c);
        process_input(c);
    }
}

/* TLS: the plaintext queued in c->out becomes records in c->tls_out once
 * the handshake is done (before, it waits). 0 when that failed and c is
 * closed. */
static int seal(conn *c)
{
    if (!tls_conn_ready(c->tls) || c->out.len == 0)
        return 1;
    char msg[256];
    int rc = tls_conn_write(c->tls, c->out.data, c->out.len, msg, sizeof msg);
    proto_buf_free(&c->out);
    if (rc || c->tls_out.err) {
        dlog(DLOG_WARN, "conn %lu (tls %s): TLS: %s: closing", c->id, tls_conn_peer(c->tls),
             rc ? msg : "out of memory for the output");
        srv_close(c);
        return 0;
    }
    return 1;
}

static int tls_push(void *ctx, const void *data, size_t len)
{
    conn *c = ctx;
    proto_buf_put(&c->tls_out, data, len);
    return c->tls_out.err ? -1 : 0;
}

static void flush(conn *c)
{
    /* while a write is in flight frames gather in out (over TLS: sealed
     * together into fewer records once it is done) */
    if (c->writing || c->closing || (c->tls && !seal(c)))
        return;
    proto_buf *src = c->tls ? &c->tls_out : &c->out;
    if (src->len == 0)
        return;
    c->wdata = src->data;
    c->inflight = src->len;
    proto_buf_init(src);               /* the bytes now belong to the write */
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
    if (!c->writing && !tls_goodbye(c))
        srv_close(c);
}

/* A closing TLS connection says close_notify after its last record: 1
 * when the caller has nothing more to do (it is being written, and
 * on_write closes after it; or c is closed already), 0 when the caller
 * closes c now. */
static int tls_goodbye(conn *c)
{
    if (!c->tls || c->closing || !tls_conn_ready(c->tls))
        return 0;
    if (!seal(c))
        return 1;                      /* closed on the failure */
    if (!tls_conn_bye(c->tls))
        return 0;                      /* said before */
    flush(c);
    return c->writing || c->closing;
}

/* Byte-stream errors: ERROR, then close once it is written. */
static void fatal_error(conn *c, uint32_t request_id, int code, const char *msg)
{
    dlog(DLOG_WARN, "conn %lu (%s): %s: %s: closing", c->id, c->auth.authed ? c->auth.user : "-",
         proto_err_name(code), msg);
    srv_send_error(c, request_id, code, "%s", msg);
    srv_close_soon(c);
}

/* Bytes admitted for user's connections (an incomplete frame each). */
static size_t admitted_of(const mcd *d, const char *user)
{
    size_t n = 0;
    for (const conn *o = d->conns; o; o = o->next)
        if (o->auth.authed && strcmp(o->auth.user, user) == 0)
            n += o->admitted;
    return n;
}

/* One user's share of --max-request-memory (--max-request-memory-per-user,
 * 0: a quarter of the total). */
static size_t user_share(const mcd_conf *k)
{
    return k->max_request_memory_per_user ? k->max_request_memory_per_user : k->max_request_memory / 4;
}

/* A frame's header is in and the rest is coming: its length counts
 * against max-request-memory from now until it is consumed, and, after
 * HELLO, against its user's share; a frame that does not fit is refused
 * BUSY (the client may send it again later) and the connection closed, so
 * what the daemon buffers stays bounded whatever the number of clients.
 * One user's declarations never take more than a share, and admins and
 * the Unix socket may use the last share of the total, which the others'
 * declarations cannot take: nobody's stalled uploads lock out everyone
 * else (an unauthenticated connection can only declare
 * CONF_HELLO_MAX_FRAME). */
static void admit(conn *c, const proto_hdr *hdr)
{
    const mcd_conf *k = &c->d->conf;
    size_t flen = PROTO_HDR_SIZE + (size_t)hdr->payload_len, cap = k->max_request_memory;
    size_t share = user_share(k), mine = c->auth.authed ? admitted_of(c->d, c->auth.user) : 0;
    int reserved = c->auth.authed && (c->auth.admin || c->auth.is_unix);
    size_t open_to_all = cap > share ? cap - share : 0;
    char msg[512] = "";
    if (admitted_total + flen > (reserved ? cap : open_to_all))
        snprintf(msg, sizeof msg, "the server is receiving %zu bytes of requests already; this %zu-byte %s does"
                 " not fit under max-request-memory %zu%s: send it again later", admitted_total, flen,
                 proto_type_name(hdr->type), cap, reserved ? "" : " less the admins' reserve (one user's share)");
    else if (c->auth.authed && mine + flen > share)
        snprintf(msg, sizeof msg, "user %s is sending %zu bytes of requests already; this %zu-byte %s does not fit"
                 " under max-request-memory-per-user %zu: send it again once those are in", c->auth.user, mine,
                 flen, proto_type_name(hdr->type), share);
    if (msg[0]) {
        dlog(DLOG_WARN, "conn %lu (%s): BUSY: %s: closing", c->id, c->auth.authed ? c->auth.user : "-", msg);
        srv_send_error(c, hdr->request_id, PROTO_EBUSY, "%s", msg);
        /* like a refusal at accept: what else it sends is dropped until its
         * EOF or the linger time, so it reads the ERROR rather than a reset */
        c->refused = 1;
        c->refused_ms = uv_now(c->d->loop);
        c->frame_ms = 0;
        proto_buf_free(&c->in);
        proto_buf_init(&c->in);
        return;
    }
    c->admitted = flen;
    admitted_total += flen;
}

static void process_input(conn *c)
{
    while (!c->closing && !c->close_after_write && !c->paused && !c->holds && c->in.len) {
        size_t limit = c->auth.authed ? c->d->conf.max_frame : CONF_HELLO_MAX_FRAME;
        proto_hdr hdr = {0};           /* a bad magic or header CRC leaves it unread: request id 0 */
        char err[512];
        int rc = proto_frame_scan(c->in.data, c->in.len, limit, &hdr, err, sizeof err);
        if (rc == PROTO_NEED_MORE) {
            if (c->in.len >= PROTO_HDR_SIZE && !c->admitted)
                admit(c, &hdr);
            return;
        }
        if (rc < 0) {
            fatal_error(c, hdr.request_id, rc, err);
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
        frame_done(c);
        c->frame_ms = c->in.len ? uv_now(c->d->loop) : 0;
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
    frame_done(c);
    c->active_ms = uv_now(c->d->loop);
    c->frame_ms = c->in.len ? c->active_ms : 0;
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

/* TLS: ciphertext read from the client goes to its session (the handshake,
 * then records); the plaintext is appended to c->in for the framing. */
static void tls_input(conn *c, const void *data, size_t n)
{
    char msg[512];
    const char *peer = tls_conn_peer(c->tls);
    if (c->refused && tls_conn_ready(c->tls))
        return;                        /* a refused client's requests are dropped */
    if (tls_conn_feed(c->tls, data, n, msg, sizeof msg) != 0) {
        dlog(DLOG_WARN, "conn %lu (tls %s): %s: closing", c->id, peer, msg);
        srv_close(c);
        return;
    }
    if (!tls_conn_ready(c->tls)) {
        int rc = tls_conn_handshake(c->tls, msg, sizeof msg);
        flush(c);                      /* the handshake's records; a refusal's ERROR once sealed */
        if (c->closing)
            return;
        if (rc < 0) {
            dlog(DLOG_WARN, "conn %lu (tls %s): TLS handshake failed: %s: closing", c->id, peer, msg);
            srv_close_soon(c);         /* after the alert */
            return;
        }
        if (rc == 0)
            return;
        char desc[64];
        dlog(DLOG_DEBUG, "conn %lu (tls %s): TLS handshake done: %s", c->id, peer,
             tls_conn_desc(c->tls, desc, sizeof desc));
        if (c->refused)
            return;
    }
    size_t before = c->in.len;
    int rc = tls_conn_read(c->tls, &c->in, msg, sizeof msg);
    if (c->in.len > before) {
        c->active_ms = uv_now(c->d->loop);
        if (before == 0)
            c->frame_ms = c->active_ms;
    }
    if (rc < 0) {
        dlog(DLOG_WARN, "conn %lu (tls %s): TLS: %s: closing", c->id, peer, msg);
        flush(c);                      /* an alert */
        srv_close_soon(c);
        return;
    }
    flush(c);                          /* records the session answers with itself (a key update) */
    if (c->closing)
        return;
    process_input(c);
    if (rc == 1 && !c->closing)        /* close_notify: the client is done, as at EOF */
        srv_close(c);
}

static void on_read(uv_stream_t *s, ssize_t n, const uv_buf_t *buf)
{
    conn *c = s->data;
    if (n < 0) {
        if (n != UV_EOF)
            dlog(DLOG_INFO, "conn %lu: read: %s", c->id, uv_strerror((int)n));
        else if (c->tls && !tls_conn_ready(c->tls) && !c->refused)
            dlog(DLOG_INFO, "conn %lu (tls %s): the client left during the TLS handshake", c->id,
                 tls_conn_peer(c->tls));
        srv_close(c);
        return;
    }
    if (n == 0 || c->closing || c->close_after_write)
        return;
    if (c->tls) {
        tls_input(c, buf->base, (size_t)n);
        return;
    }
    if (c->refused)
        return;                        /* a refused client's bytes are dropped */
    c->active_ms = uv_now(c->d->loop);
    if (c->in.len == 0)
        c->frame_ms = c->active_ms;
    proto_buf_put(&c->in, buf->base, (size_t)n);
    if (c->in.err) {
        fatal_error(c, 0, PROTO_ENOMEM, "out of memory for the request");
        return;
    }
    process_input(c);
}

/* sa's address as text into ip (64 bytes); its port. */
static int addr_name(const struct sockaddr_storage *sa, char ip[64])
{
    if (sa->ss_family == AF_INET6) {
        uv_ip6_name((const struct sockaddr_in6 *)sa, ip, 64);
        return ntohs(((const struct sockaddr_in6 *)sa)->sin6_port);
    }
    uv_ip4_name((const struct sockaddr_in *)sa, ip, 64);
    return ntohs(((const struct sockaddr_in *)sa)->sin_port);
}

/* A connection accepted on a tls: listener gets its session: 0, or -1
 * (logged) when it cannot. */
static int conn_tls_start(conn *c)
{
    struct sockaddr_storage sa;
    int len = sizeof sa, port = 0;
    char ip[64] = "?", peer[80];
    if (uv_tcp_getpeername(&c->u.tcp, (struct sockaddr *)&sa, &len) == 0)
        port = addr_name(&sa, ip);
    snprintf(peer, sizeof peer, strchr(ip, ':') ? "[%s]:%d" : "%s:%d", ip, port);
    if (!c->d->tls || tls_conn_new(c->d->tls, peer, tls_push, c, &c->tls) != 0) {
        dlog(DLOG_ERROR, "conn %lu (tls %s): cannot start a TLS session: closing", c->id, peer);
        return -1;
    }
    dlog(DLOG_DEBUG, "conn %lu (tls %s): TLS session started", c->id, peer);
    return 0;
}

static int is_tls_listener(const uv_stream_t *server)
{
    for (int i = 0; i < ntls_listeners; i++)
        if (tls_listeners[i] == (const uv_handle_t *)server)
            return 1;
    return 0;
}

/* Who connects, into c->auth.peer: the IPv4 address, an IPv6 address's
 * /64 (one host has a whole /64 to pick from), or "uid N" on the Unix
 * socket (and whether that uid is root or --admin-uid). */
static void peer_of(conn *c)
{
    char *out = c->auth.peer;
    snprintf(out, SRV_MAX_PEER, "?");
    if (c->auth.is_unix) {
        unsigned long uid;
        if (auth_peer_uid(srv_conn_fd(c), c->d->conf.admin_uid, &uid, &c->unix_admin) == 0)
            snprintf(out, SRV_MAX_PEER, "uid %lu", uid);
        return;
    }
    struct sockaddr_storage sa;
    int len = sizeof sa;
    if (uv_tcp_getpeername(&c->u.tcp, (struct sockaddr *)&sa, &len) != 0)
        return;
    if (sa.ss_family == AF_INET) {
        inet_ntop(AF_INET, &((struct sockaddr_in *)&sa)->sin_addr, out, SRV_MAX_PEER);
    } else if (sa.ss_family == AF_INET6) {
        struct in6_addr a = ((struct sockaddr_in6 *)&sa)->sin6_addr;
        if (IN6_IS_ADDR_V4MAPPED(&a)) {
            inet_ntop(AF_INET, &a.s6_addr[12], out, SRV_MAX_PEER);
            return;
        }
        memset(&a.s6_addr[8], 0, 8);
        char ip[INET6_ADDRSTRLEN];
        inet_ntop(AF_INET6, &a, ip, sizeof ip);
        snprintf(out, SRV_MAX_PEER, "%s/64", ip);
    }
}

/* What the accept decides on, c itself not counted. */
typedef struct census {
    uint32_t unauth_tcp;      /* TCP connections before HELLO */
    uint32_t unauth_here;     /* connections before HELLO from c's peer, on c's kind of socket */
    uint32_t lingering;       /* refused connections not closed yet */
    conn *oldest_here;        /* the oldest of unauth_here */
    conn *oldest_tcp;         /* the oldest of unauth_tcp */
} census;

static void count_conns(const conn *c, census *k)
{
    memset(k, 0, sizeof *k);
    for (conn *o = c->d->conns; o; o = o->next) {
        if (o == c || o->closing || o->close_after_write)
            continue;
        if (o->refused) {
            k->lingering++;
            continue;
        }
        if (o->auth.authed)
            continue;
        if (!o->auth.is_unix) {
            k->unauth_tcp++;
            if (!k->oldest_tcp || o->accepted_ms <= k->oldest_tcp->accepted_ms)
                k->oldest_tcp = o;
        }
        if (o->auth.is_unix == c->auth.is_unix && strcmp(o->auth.peer, c->auth.peer) == 0) {
            k->unauth_here++;
            if (!k->oldest_here || o->accepted_ms <= k->oldest_here->accepted_ms)
                k->oldest_here = o;
        }
    }
}

/* Refusals, logged at most once a second per reason (a flood of clients
 * gives one line a second, with the number it stands for). */
enum { REFUSE_FDS, REFUSE_TOTAL, REFUSE_UNAUTH, REFUSE_ADDR, REFUSE_USER, REFUSE_KINDS };
static void log_refusal(const mcd *d, int kind, const char *what, const char *verb, const char *why)
{
    static uint64_t last_ms[REFUSE_KINDS];
    static unsigned long held_back[REFUSE_KINDS];
    uint64_t now = uv_now(d->loop);
    if (last_ms[kind] && now - last_ms[kind] < 1000) {
        held_back[kind]++;
        return;
    }
    if (held_back[kind])
        dlog(DLOG_WARN, "%s %s: %s (and %lu more like it in the last second)", what, verb, why, held_back[kind]);
    else
        dlog(DLOG_WARN, "%s %s: %s", what, verb, why);
    last_ms[kind] = now;
    held_back[kind] = 0;
}

/* c is told BUSY with why and closed: after a short linger (so it reads the
 * ERROR), or at once when descriptors are short or too many TCP
 * connections linger already. */
static void refuse(conn *c, int kind, const char *verb, const char *why, int linger)
{
    char what[SRV_MAX_PEER + 64];
    snprintf(what, sizeof what, "conn %lu (%s %s)", c->id, c->auth.is_unix ? "unix" : "tcp", c->auth.peer);
    log_refusal(c->d, kind, what, verb, why);
    c->refused = 1;
    c->refused_ms = uv_now(c->d->loop);
    c->frame_ms = 0;
    admitted_total -= c->admitted;     /* half a HELLO it sent is dropped */
    c->admitted = 0;
    proto_buf_free(&c->in);
    proto_buf_init(&c->in);
    srv_send_error(c, 0, PROTO_EBUSY, "server busy: %s; retry later", why);
    if (linger)
        update_reading(c);             /* until the client's EOF, or the linger time */
    else
        srv_close(c);
}

/* The oldest TCP connection without HELLO makes room for c: 0, or -1 when
 * there is none. */
static int displace(conn *victim, int kind, const char *why, long left, long floor)
{
    if (!victim)
        return -1;
    census k;
    count_conns(victim, &k);
    char msg[320];
    snprintf(msg, sizeof msg, "%s; the oldest connection without HELLO makes room for a newer one", why);
    refuse(victim, kind, "closed", msg, k.lingering < SRV_MAX_LINGER && left > floor);
    return 0;
}

static void on_connection(uv_stream_t *server, int status)
{
    mcd *d = server->data;
    static unsigned long next_id = 1;
    if (status < 0) {
        dlog(DLOG_WARN, "accept: %s", uv_strerror(status));
        return;
    }
    /* the descriptors, before the accept takes one */
    long left = fds_free(), reserve = fds_reserve(&d->conf, bk_nslots(d));
    long floor = fds_tcp_floor(&d->conf, bk_nslots(d));
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
    if (uv_accept(server, &c->u.s) != 0 || (is_tls_listener(server) && conn_tls_start(c) != 0)) {
        uv_close(&c->u.h, on_closed);
        return;
    }
    c->next = d->conns;
    if (d->conns)
        d->conns->prev = c;
    d->conns = c;
    c->accepted_ms = c->active_ms = uv_now(d->loop);
    peer_of(c);
    const mcd_conf *k = &d->conf;
    census n;
    count_conns(c, &n);
    char why[256];
    if (c->auth.is_unix) {
        if (left <= reserve) {
            snprintf(why, sizeof why, "%ld file descriptor(s) left under RLIMIT_NOFILE, %ld kept for the workers "
                     "(--fd-reserve)", left, reserve);
            refuse(c, REFUSE_FDS, "refused", why, left > reserve / 2);
            return;
        }
        if (!c->unix_admin && n.unauth_here >= k->max_unauth_per_address) {
            snprintf(why, sizeof why, "%u connections without HELLO from %s, the limit "
                     "(--max-unauthenticated-per-address)", n.unauth_here, c->auth.peer);
            displace(n.oldest_here, REFUSE_ADDR, why, left, reserve);
        }
    } else {
        if (left <= floor) {
            snprintf(why, sizeof why, "%ld file descriptor(s) left under RLIMIT_NOFILE, %ld kept for the workers "
                     "(--fd-reserve) and %u more for the Unix socket and admins (--admin-reserve)", left, reserve,
                     k->admin_reserve);
            if (displace(n.oldest_tcp, REFUSE_FDS, why, left, floor)) {
                refuse(c, REFUSE_FDS, "refused", why, left > reserve && n.lingering < SRV_MAX_LINGER);
                return;
            }
            count_conns(c, &n);
        }
        if (n.unauth_here >= k->max_unauth_per_address) {
            snprintf(why, sizeof why, "%u connections without HELLO from %s, the limit "
                     "(--max-unauthenticated-per-address)", n.unauth_here, c->auth.peer);
            displace(n.oldest_here, REFUSE_ADDR, why, left, floor);
        } else if (n.unauth_tcp >= k->max_unauthenticated) {
            snprintf(why, sizeof why, "%u TCP connections without HELLO, the limit (--max-unauthenticated)",
                     n.unauth_tcp);
            displace(n.oldest_tcp, REFUSE_UNAUTH, why, left, floor);
        }
    }
    dlog(DLOG_DEBUG, "conn %lu: accepted (%s %s)", c->id, c->auth.is_unix ? "unix" : "tcp", c->auth.peer);
    update_reading(c);
}

int srv_conn_admit_user(conn *c, char *msg, size_t msgsz)
{
    const mcd *d = c->d;
    if (c->auth.admin)
        return 0;
    uint32_t all = 0, mine = 0;
    for (const conn *o = d->conns; o; o = o->next)
        if (o != c && !o->closing && !o->refused && o->auth.authed && !o->auth.admin) {
            all++;
            mine += strcmp(o->auth.user, c->auth.user) == 0;
        }
    int kind;
    if (all >= d->conf.max_connections) {
        kind = REFUSE_TOTAL;
        snprintf(msg, msgsz, "server busy: %u sessions open, the limit (--max-connections; admins exempt); "
                 "retry later", all);
    } else if (mine >= d->conf.max_connections_per_user) {
        kind = REFUSE_USER;
        snprintf(msg, msgsz, "server busy: user %s has %u sessions, the limit (--max-connections-per-user); "
                 "retry later", c->auth.user, mine);
    } else {
        return 0;
    }
    char what[AUTH_MAX_USER + SRV_MAX_PEER + 64];
    snprintf(what, sizeof what, "conn %lu (user %s, %s)", c->id, c->auth.user, c->auth.peer);
    log_refusal(d, kind, what, "refused", msg);
    return PROTO_EBUSY;
}

void srv_each_session(mcd *d, void (*fn)(conn *c, void *ctx), void *ctx)
{
    conn *next;
    for (conn *c = d->conns; c; c = next) {
        next = c->next;                /* fn may close c (srv_close unlinks it) */
        if (c->auth.authed && !c->closing && !c->close_after_write)
            fn(c, ctx);
    }
}

void srv_end_session(conn *c, int code, const char *why)
{
    dlog(DLOG_WARN, "conn %lu (user %s%s, %s): session ended: %s", c->id, c->auth.user,
         c->auth.admin ? ", admin" : "", c->auth.peer, why);
    srv_send_error(c, 0, code, "%s", why);
    srv_close_soon(c);
}

void srv_note_tokens(mcd *d)
{
    int tcp = 0;
    for (int i = 0; i < d->conf.nlisten; i++)
        tcp |= strncmp(d->conf.listen[i], "tcp:", 4) == 0;
    const char *path = auth_tokens_path(d->tokens);
    if (!tcp)
        return;
    if (auth_tokens_count(d->tokens) == 0)
        dlog(DLOG_WARN, "TCP listener without a token (%s%s): no TCP user can log in; make one with "
             "`meshcorrd token new USER`", path[0] ? "no line in " : "no --tokens file", path);
    else
        dlog(DLOG_INFO, "%d token(s) from %s", auth_tokens_count(d->tokens), path);
}

/* ERROR TIMED_OUT (request id 0), a log line, and a close once it is written. */
static void time_out(conn *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void time_out(conn *c, const char *fmt, ...)
{
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    dlog(DLOG_WARN, "conn %lu (%s): %s: closing", c->id, c->auth.authed ? c->auth.user : "-", msg);
    srv_send_error(c, 0, PROTO_ETIMED_OUT, "%s", msg);
    srv_close_soon(c);
}

/* Bytes the frame begun in c->in will have, or 0 while its header is incomplete. */
static size_t frame_size(const conn *c)
{
    if (c->in.len < PROTO_HDR_SIZE)
        return 0;
    const uint8_t *p = c->in.data + 12;  /* payload len, little-endian */
    return PROTO_HDR_SIZE + ((size_t)p[0] | (size_t)p[1] << 8 | (size_t)p[2] << 16 | (size_t)p[3] << 24);
}

static void on_sweep(uv_timer_t *t)
{
    mcd *d = t->data;
    const mcd_conf *k = &d->conf;
    uint64_t now = uv_now(d->loop);
    throttle_sweep(now);
    conn *next;
    for (conn *c = d->conns; c; c = next) {
        next = c->next;                /* srv_close unlinks c */
        if (c->closing || c->close_after_write)
            continue;
        if (c->refused) {
            if (now - c->refused_ms >= SRV_REFUSE_LINGER_MS)
                srv_close(c);
        } else if (!c->auth.authed && k->hello_timeout_s && now - c->accepted_ms >= 1000ull * k->hello_timeout_s) {
            if (c->tls && !tls_conn_ready(c->tls))
                time_out(c, "TLS handshake with %s not done within %u s (--hello-timeout)", tls_conn_peer(c->tls),
                         k->hello_timeout_s);
            else
                time_out(c, "no HELLO within %u s (--hello-timeout)", k->hello_timeout_s);
        } else if (c->frame_ms && !c->holds && !c->paused &&
                   now - c->frame_ms >= 1000ull * k->request_timeout_s && k->request_timeout_s) {
            size_t want = frame_size(c);
            if (want)
                time_out(c, "request frame incomplete after %u s, %zu of %zu bytes (--request-timeout)",
                         k->request_timeout_s, c->in.len, want);
            else
                time_out(c, "request frame incomplete after %u s, %zu header bytes (--request-timeout)",
                         k->request_timeout_s, c->in.len);
        } else if (c->auth.authed && k->idle_timeout_s && !c->holds && !c->in.len && !queued(c) &&
                   now - c->active_ms >= 1000ull * k->idle_timeout_s && !req_conn_watching(d, c)) {
            time_out(c, "idle for %u s (--idle-timeout)", k->idle_timeout_s);
        }
    }
}

static void sweep_stop(void)
{
    if (sweep_on)
        uv_close((uv_handle_t *)&sweep_timer, NULL);
    sweep_on = 0;
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

/* 127.0.0.0/8, ::1, or 127.0.0.0/8 mapped into IPv6. */
static int is_loopback(const struct sockaddr_storage *sa)
{
    if (sa->ss_family == AF_INET)
        return (ntohl(((const struct sockaddr_in *)sa)->sin_addr.s_addr) >> 24) == 127;
    const struct in6_addr *a = &((const struct sockaddr_in6 *)sa)->sin6_addr;
    return IN6_IS_ADDR_LOOPBACK(a) || (IN6_IS_ADDR_V4MAPPED(a) && a->s6_addr[12] == 127);
}

/* A tcp: listener (tls 0) or a tls: one: scheme:HOST:PORT, HOST numeric. */
static int listen_tcp(mcd *d, const char *hostport, int tls, uv_handle_t **out, FILE *portfp,
                      char *err, size_t errsz)
{
    char host[256];
    const char *scheme = tls ? "tls" : "tcp";
    const char *colon = strrchr(hostport, ':');
    if (!colon || colon == hostport || (size_t)(colon - hostport) >= sizeof host)
        return snprintf(err, errsz, "%s:%s: expected %s:HOST:PORT", scheme, hostport, scheme), -1;
    memcpy(host, hostport, (size_t)(colon - hostport));
    host[colon - hostport] = '\0';
    if (host[0] == '[' && host[strlen(host) - 1] == ']') {
        memmove(host, host + 1, strlen(host));
        host[strlen(host) - 1] = '\0';
    }
    char *e;
    long port = strtol(colon + 1, &e, 10);
    if (*e || port < 0 || port > 65535)
        return snprintf(err, errsz, "%s:%s: bad port", scheme, hostport), -1;
    struct sockaddr_storage sa;
    if (uv_ip4_addr(host, (int)port, (struct sockaddr_in *)&sa) != 0 &&
        uv_ip6_addr(host, (int)port, (struct sockaddr_in6 *)&sa) != 0)
        return snprintf(err, errsz, "%s:%s: '%s' is not a numeric IP address", scheme, hostport, host), -1;
    if (!tls && !is_loopback(&sa)) {
        if (!d->conf.insecure_tcp)
            return snprintf(err, errsz, "tcp:%s is not loopback: tokens would cross the network in clear; use "
                            "tls:HOST:PORT with --tls-cert/--tls-key, or --insecure-tcp to allow it", hostport), -1;
        dlog(DLOG_WARN, "tcp:%s is not loopback: tokens, meshes and maps cross the network in clear "
             "(--insecure-tcp)", hostport);
    }
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
        return snprintf(err, errsz, "%s:%s: %s", scheme, hostport, uv_strerror(rc)), -1;
    if (tls)
        tls_listeners[ntls_listeners++] = (uv_handle_t *)t;
    struct sockaddr_storage bound;
    int len = sizeof bound;
    uv_tcp_getsockname(t, (struct sockaddr *)&bound, &len);
    char ip[64];
    int bport = addr_name(&bound, ip);
    dlog(DLOG_INFO, "listening on %s:%s:%d", scheme, ip, bport);
    if (portfp)
        fprintf(portfp, "%s:%s:%d\n", scheme, ip, bport);
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
    struct rlimit rl;
    if (getrlimit(RLIMIT_NOFILE, &rl) == 0)
        dlog(DLOG_INFO, "file descriptors: soft limit %llu, %ld kept for the workers, %u more for the Unix socket "
             "and admins; at most %u non-admin sessions (%u per user), %u TCP connections before HELLO (%u per "
             "address)", (unsigned long long)rl.rlim_cur, fds_reserve(&d->conf, bk_nslots(d)),
             d->conf.admin_reserve, d->conf.max_connections, d->conf.max_connections_per_user,
             d->conf.max_unauthenticated, d->conf.max_unauth_per_address);
    for (int i = 0; i < d->conf.nlisten && !rc; i++) {
        const char *a = d->conf.listen[i];
        uv_handle_t *h = NULL;
        rc = strncmp(a, "unix:", 5) == 0 ? listen_unix(d, a + 5, &h, err, errsz)
                                         : listen_tcp(d, a + 4, strncmp(a, "tls:", 4) == 0, &h, portfp, err, errsz);
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
    if (!rc && !sweep_on) {
        uv_timer_init(d->loop, &sweep_timer);
        sweep_timer.data = d;
        uv_timer_start(&sweep_timer, on_sweep, SRV_SWEEP_MS, SRV_SWEEP_MS);
        sweep_on = 1;
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
    ntls_listeners = 0;
    if (!d->conns)
        sweep_stop();              /* else the timeouts go on until srv_close_all */
}

void srv_close_all(mcd *d)
{
    sweep_stop();
    while (d->conns)
        srv_close(d->conns);
}

/* The listeners are bound once, and the port file written once. */
void srv_keep_on_reload(const mcd_conf *o, mcd_conf *n, char *changed, size_t sz)
{
    int differs = n->nlisten != o->nlisten;
    for (int i = 0; !differs && i < n->nlisten; i++)
        differs = strcmp(n->listen[i], o->listen[i]) != 0;
    conf_note_change(differs, "listen", changed, sz);
    conf_note_change(strcmp(n->port_file, o->port_file) != 0, "port-file", changed, sz);
    memcpy(n->listen, o->listen, sizeof n->listen);
    n->nlisten = o->nlisten;
    memcpy(n->port_file, o->port_file, sizeof n->port_file);
}
