/* mc_client.c — libmeshcorr's connection and requests: connect (Unix
 * socket, TCP, or TCP with TLS), HELLO, one request at a time with blocking
 * I/O under a timeout, replies decoded by the protocol codec and copied into
 * the public structs of meshcorr.h. Holds no mesh code (mc_mesh.c) and no
 * command-line code (cli/).
 *
 * TLS (GnuTLS): the server's certificate is verified against the CA file
 * given (mc_connect_ca, else $MESHCORR_CA) or else the system's trust store,
 * and must name the host of the address; TLS 1.2 at least. The session runs
 * over the same non-blocking send/recv and poll as a plain connection, so
 * every wait keeps the client's timeout. */
#include "mc__wire.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <gnutls/gnutls.h>
#include <gnutls/x509.h>
#include <netdb.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#define MC_DEFAULT_TIMEOUT_MS 30000
#define MC_MAX_REPLY PROTO_MAX_FRAME
/* The versions the daemon accepts (TLS_PRIORITY in daemon/mcd.h). */
#define MC_TLS_PRIORITY "NORMAL:-VERS-ALL:+VERS-TLS1.3:+VERS-TLS1.2"

struct mc_client {
    int fd;
    gnutls_session_t tls;      /* NULL: a plain connection */
    gnutls_certificate_credentials_t cred;
    int timeout_ms;
    uint32_t next_rid;
    char user[256];
    int admin;
    char errmsg[1200];
    uint8_t *rbuf;             /* the last reply frame; decoded messages borrow from it */
    size_t rcap;
};

const char *mc_strerror(int code)
{
    switch (code) {
#define MC_CASE(name, val, msg) case val: return msg;
    MC_ERRORS(MC_CASE)
#undef MC_CASE
    default: return proto_strerror(code);
    }
}

const char *mc_err_name(int code)
{
    switch (code) {
#define MC_NAME(name, val, msg) case val: return #name;
    MC_ERRORS(MC_NAME)
#undef MC_NAME
    default: return proto_err_name(code);
    }
}

int mc_reason_error(const char *reason)
{
    char name[32];
    size_t n = reason ? strcspn(reason, ":") : 0;
    if (!reason || !reason[n] || n == 0 || n >= sizeof name)
        return 0;
    memcpy(name, reason, n);
    name[n] = '\0';
    return proto_err_code(name);
}

const char *mc_state_name(int state) { return proto_state_name(state); }
const char *mc_stage_name(int stage) { return proto_stage_name(stage); }

int mc_state_parse(const char *name)
{
    if (!name)
        return -1;
    for (int i = 0; i <= PROTO_STATE_LAST; i++)
        if (strcasecmp(name, proto_state_name(i)) == 0)
            return i;
    return -1;
}

static int fail(mc_client *c, int code, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->errmsg, sizeof c->errmsg, fmt, ap);
    va_end(ap);
    return code;
}

/* Every call refuses a NULL client (never connected, or one a binding has
 * closed) with MC_EARG instead of dereferencing it; the getters answer as
 * for no user. */
#define MC_NEED_CLIENT(c) do { if (!(c)) return MC_EARG; } while (0)

void mc_set_timeout(mc_client *c, int ms)
{
    if (c)
        c->timeout_ms = ms;
}
const char *mc_errmsg(const mc_client *c) { return c ? c->errmsg : "no client (NULL)"; }
const char *mc_user(const mc_client *c) { return c ? c->user : ""; }
int mc_is_admin(const mc_client *c) { return c ? c->admin : 0; }

void mc_job_spec_init(mc_job_spec *s)
{
    if (!s)
        return;
    memset(s, 0, sizeof *s);
#define MC_DEFAULT_STR(name, dflt) s->name = NULL;
#define MC_DEFAULT_NUM(name, dflt) s->name = dflt;
#define MC_DEFAULT_ENUM MC_DEFAULT_NUM
#define MC_DEFAULT_BOOL MC_DEFAULT_NUM
#define MC_DEFAULT_U32  MC_DEFAULT_NUM
#define MC_DEFAULT_F64  MC_DEFAULT_NUM
#define MC_DEFAULT(name, cli, type, dflt, ...) MC_DEFAULT_##type(name, dflt)
    PROTO_PARAMS(MC_DEFAULT)
#undef MC_DEFAULT
}

static int64_t now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

/* Waits for fd to be readable/writable before the deadline (-1: none). */
static int wait_fd(mc_client *c, short events, int64_t deadline)
{
    for (;;) {
        int ms = -1;
        if (deadline >= 0) {
            int64_t left = deadline - now_ms();
            if (left <= 0)
                return fail(c, MC_ETIMEOUT, "no answer from the server within %d ms", c->timeout_ms);
            ms = (int)left;
        }
        struct pollfd p = {c->fd, events, 0};
        int r = poll(&p, 1, ms);
        if (r > 0)
            return 0;
        if (r < 0 && errno != EINTR)
            return fail(c, MC_EIO, "poll: %s", strerror(errno));
    }
}

static int64_t deadline_of(const mc_client *c)
{
    return c->timeout_ms > 0 ? now_ms() + c->timeout_ms : -1;
}

/* TLS: which way the session waits after GNUTLS_E_AGAIN. */
static short tls_wants(const mc_client *c)
{
    return gnutls_record_get_direction(c->tls) ? POLLOUT : POLLIN;
}

/* A TLS error in the middle of the session: MC_EIO with its reason (an
 * end without close_notify is the server closing). */
static int tls_broken(mc_client *c, const char *what, ssize_t g)
{
    if (g == GNUTLS_E_PREMATURE_TERMINATION || g == GNUTLS_E_PUSH_ERROR || g == GNUTLS_E_PULL_ERROR) {
        if (errno == 0)
            errno = EPIPE;
        return fail(c, MC_EIO, "%s: %s", what, errno == EPIPE || errno == ECONNRESET || g ==
                    GNUTLS_E_PREMATURE_TERMINATION ? "the server closed the connection" : strerror(errno));
    }
    return fail(c, MC_EIO, "%s: TLS: %s", what, gnutls_strerror((int)g));
}

static int send_tls(mc_client *c, const char *p, size_t len, int64_t deadline)
{
    while (len) {
        errno = 0;
        ssize_t w = gnutls_record_send(c->tls, p, len);
        if (w > 0) {
            p += w;
            len -= (size_t)w;
        } else if (w == GNUTLS_E_AGAIN || w == GNUTLS_E_INTERRUPTED) {
            int rc = wait_fd(c, tls_wants(c), deadline);
            if (rc)
                return rc;
        } else {
            int e = errno;
            int rc = tls_broken(c, "send", w);
            errno = e ? e : EPIPE;    /* request() asks the server why (closed_reason) */
            return rc;
        }
    }
    return 0;
}

static int send_all(mc_client *c, const void *data, size_t len)
{
    int64_t deadline = deadline_of(c);
    const char *p = data;
    if (c->tls)
        return send_tls(c, p, len, deadline);
    while (len) {
        ssize_t w = send(c->fd, p, len, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (w > 0) {
            p += w;
            len -= (size_t)w;
            continue;
        }
        if (w < 0 && errno == EINTR)
            continue;
        if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            int rc = wait_fd(c, POLLOUT, deadline);
            if (rc)
                return rc;
            continue;
        }
        int e = w < 0 ? errno : EPIPE;
        int rc = fail(c, MC_EIO, "send: %s", w < 0 ? strerror(e) : "connection closed");
        errno = e;                /* request() asks the server why (closed_reason) */
        return rc;
    }
    return 0;
}

static int recv_tls(mc_client *c, char *p, size_t len, int64_t deadline)
{
    short want = POLLIN;
    while (len) {
        /* records GnuTLS has already read are not on the socket any more */
        if (!gnutls_record_check_pending(c->tls)) {
            int rc = wait_fd(c, want, deadline);
            if (rc)
                return rc;
        }
        errno = 0;
        ssize_t r = gnutls_record_recv(c->tls, p, len);
        if (r > 0) {
            p += r;
            len -= (size_t)r;
            want = POLLIN;
        } else if (r == 0) {
            return fail(c, MC_EIO, "the server closed the connection");
        } else if (r == GNUTLS_E_AGAIN || r == GNUTLS_E_INTERRUPTED) {
            want = tls_wants(c);
        } else if (!gnutls_error_is_fatal((int)r)) {
            want = POLLIN;                 /* a warning alert */
        } else {
            return tls_broken(c, "recv", r);
        }
    }
    return 0;
}

static int recv_all(mc_client *c, void *data, size_t len, int64_t deadline)
{
    char *p = data;
    if (c->tls)
        return recv_tls(c, p, len, deadline);
    while (len) {
        int rc = wait_fd(c, POLLIN, deadline);
        if (rc)
            return rc;
        ssize_t r = recv(c->fd, p, len, MSG_DONTWAIT);
        if (r > 0) {
            p += r;
            len -= (size_t)r;
        } else if (r == 0) {
            return fail(c, MC_EIO, "the server closed the connection");
        } else if (errno != EINTR && errno != EAGAIN && errno != EWOULDBLOCK) {
            return fail(c, MC_EIO, "recv: %s", strerror(errno));
        }
    }
    return 0;
}

/* Reads one frame and decodes it into m (borrowing from c->rbuf). An ERROR
 * frame is returned as its code, with its message in errmsg. */
static int read_frame(mc_client *c, proto_msg *m, int64_t deadline)
{
    uint8_t hdrb[PROTO_HDR_SIZE] = {0};
    int rc = recv_all(c, hdrb, sizeof hdrb, deadline);
    if (rc && !c->tls && hdrb[0] == 0x15 && hdrb[1] == 0x03)   /* a TLS alert record */
        return fail(c, MC_ETLS, "the server speaks TLS on this port: connect to tls:HOST:PORT");
    if (rc)
        return rc;
    proto_hdr hdr;
    char err[512];
    rc = proto_frame_scan(hdrb, sizeof hdrb, MC_MAX_REPLY, &hdr, err, sizeof err);
    if (rc < 0)
        return fail(c, MC_EPROTO, "reply header: %s", err);
    size_t flen = PROTO_HDR_SIZE + (size_t)hdr.payload_len;
    if (flen > c->rcap) {
        uint8_t *nb = realloc(c->rbuf, flen);
        if (!nb)
            return fail(c, MC_ENOMEM, "out of memory for a %zu-byte reply", flen);
        c->rbuf = nb;
        c->rcap = flen;
    }
    memcpy(c->rbuf, hdrb, PROTO_HDR_SIZE);
    if ((rc = recv_all(c, c->rbuf + PROTO_HDR_SIZE, hdr.payload_len, deadline)))
        return rc;
    rc = proto_msg_decode(&hdr, c->rbuf + PROTO_HDR_SIZE, m, err, sizeof err);
    if (rc)
        return fail(c, MC_EPROTO, "reply %s: %s", proto_type_name(hdr.type), err);
    if (m->type == PROTO_MSG_ERROR) {
        int code = m->u.error.code < 0 ? m->u.error.code : MC_EPROTO;
        fail(c, code, "%s: %s", proto_err_name(code), m->u.error.message);
        proto_msg_free(m);
        return code;
    }
    return 0;
}

/* The server closed the connection while a request went out: it may have
 * said why first (BUSY at its connection or descriptor limits, an idle
 * timeout), and that ERROR waits unread. Its code and message, else the
 * send's failure (rc, errmsg) as it was. */
#define MC_CLOSED_REASON_MS 1000
static int closed_reason(mc_client *c, int rc)
{
    char send_err[sizeof c->errmsg];
    memcpy(send_err, c->errmsg, sizeof send_err);
    proto_msg m;
    int code = read_frame(c, &m, now_ms() + MC_CLOSED_REASON_MS);
    if (code == 0) {
        proto_msg_free(&m);        /* a reply to something else: not a reason */
    } else if (code != MC_EIO && code != MC_ETIMEOUT && code != MC_EPROTO) {
        return code;               /* the server's ERROR, its message in errmsg */
    }
    memcpy(c->errmsg, send_err, sizeof send_err);
    return rc;
}

/* Sends req (request id assigned here) and reads the reply of type
 * want_type into reply. */
static int request(mc_client *c, proto_msg *req, int want_type, proto_msg *reply)
{
    c->errmsg[0] = '\0';
    if (c->fd < 0)
        return fail(c, MC_EIO, "the connection is closed");
    req->request_id = ++c->next_rid;
    proto_buf b;
    proto_buf_init(&b);
    char err[512];
    int rc = proto_msg_encode(&b, req, err, sizeof err);
    if (rc) {
        proto_buf_free(&b);
        return fail(c, rc == PROTO_ENOMEM ? MC_ENOMEM : MC_EARG, "request %s: %s",
                    proto_type_name(req->type), err);
    }
    rc = send_all(c, b.data, b.len);
    proto_buf_free(&b);
    if (rc)
        return rc == MC_EIO && (errno == EPIPE || errno == ECONNRESET) ? closed_reason(c, rc) : rc;
    if ((rc = read_frame(c, reply, deadline_of(c))))
        return rc;
    if (reply->type != want_type || reply->request_id != req->request_id) {
        rc = fail(c, MC_EPROTO, "expected %s for request %u, got %s for request %u",
                  proto_type_name(want_type), req->request_id, proto_type_name(reply->type),
                  reply->request_id);
        proto_msg_free(reply);
    }
    return rc;
}

static int connect_unix(mc_client *c, const char *path)
{
    struct sockaddr_un sa;
    memset(&sa, 0, sizeof sa);
    sa.sun_family = AF_UNIX;
    if (strlen(path) >= sizeof sa.sun_path)
        return fail(c, MC_EADDRESS, "unix:%s: path too long", path);
    strcpy(sa.sun_path, path);
    c->fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (c->fd < 0 || connect(c->fd, (struct sockaddr *)&sa, sizeof sa) != 0)
        return fail(c, MC_ECONNECT, "unix:%s: %s", path, strerror(errno));
    return 0;
}

/* scheme:HOST:PORT (tcp or tls); host receives HOST without brackets. */
static int connect_tcp(mc_client *c, const char *scheme, const char *hostport, char host[256])
{
    const char *colon = strrchr(hostport, ':');
    if (!colon || colon == hostport || (size_t)(colon - hostport) >= 256)
        return fail(c, MC_EADDRESS, "%s:%s: expected %s:HOST:PORT", scheme, hostport, scheme);
    memcpy(host, hostport, (size_t)(colon - hostport));
    host[colon - hostport] = '\0';
    if (host[0] == '[' && host[strlen(host) - 1] == ']') {
        memmove(host, host + 1, strlen(host));
        host[strlen(host) - 1] = '\0';
    }
    struct addrinfo hints, *res = NULL;
    memset(&hints, 0, sizeof hints);
    hints.ai_socktype = SOCK_STREAM;
    int g = getaddrinfo(host, colon + 1, &hints, &res);
    if (g)
        return fail(c, MC_EADDRESS, "%s:%s: %s", scheme, hostport, gai_strerror(g));
    int rc = fail(c, MC_ECONNECT, "%s:%s: no address", scheme, hostport);
    for (struct addrinfo *ai = res; ai; ai = ai->ai_next) {
        c->fd = socket(ai->ai_family, ai->ai_socktype | SOCK_CLOEXEC, ai->ai_protocol);
        if (c->fd >= 0 && connect(c->fd, ai->ai_addr, ai->ai_addrlen) == 0) {
            /* a request goes out in one send, but TLS's Finished and the
             * HELLO after it are two: Nagle would hold the second until
             * the server's delayed ACK */
            int one = 1;
            setsockopt(c->fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
            rc = 0;
            break;
        }
        rc = fail(c, MC_ECONNECT, "%s:%s: %s", scheme, hostport, strerror(errno));
        if (c->fd >= 0)
            close(c->fd);
        c->fd = -1;
    }
    freeaddrinfo(res);
    return rc;
}

static ssize_t tls_pull(gnutls_transport_ptr_t p, void *buf, size_t n)
{
    return recv(((mc_client *)p)->fd, buf, n, MSG_DONTWAIT);
}

static ssize_t tls_push(gnutls_transport_ptr_t p, const void *data, size_t n)
{
    return send(((mc_client *)p)->fd, data, n, MSG_NOSIGNAL | MSG_DONTWAIT);
}

static int is_ip(const char *host)
{
    unsigned char a[sizeof(struct in6_addr)];
    return inet_pton(AF_INET, host, a) == 1 || inet_pton(AF_INET6, host, a) == 1;
}

/* The TLS handshake on the connected c->fd: the server's certificate must
 * chain to ca (a PEM file; NULL: $MESHCORR_CA, else the system's trust
 * store) and name host. */
static int start_tls(mc_client *c, const char *hostport, const char *host, const char *ca)
{
    if (!ca || !*ca)
        ca = getenv("MESHCORR_CA");
    int g = gnutls_certificate_allocate_credentials(&c->cred);
    if (g < 0)
        return fail(c, MC_ENOMEM, "TLS: %s", gnutls_strerror(g));
    if (ca && *ca) {
        FILE *fp = fopen(ca, "r");
        if (!fp)
            return fail(c, MC_ETLS, "CA file %s: %s", ca, strerror(errno));
        fclose(fp);
        g = gnutls_certificate_set_x509_trust_file(c->cred, ca, GNUTLS_X509_FMT_PEM);
        if (g <= 0)
            return fail(c, MC_ETLS, "CA file %s: no PEM certificate in it%s%s", ca, g < 0 ? ": " : "",
                        g < 0 ? gnutls_strerror(g) : "");
    } else if (gnutls_certificate_set_x509_system_trust(c->cred) <= 0) {
        /* nothing trusted: the handshake below fails, naming the remedy */
    }
    if ((g = gnutls_init(&c->tls, GNUTLS_CLIENT | GNUTLS_NONBLOCK | GNUTLS_NO_SIGNAL)) < 0) {
        c->tls = NULL;
        return fail(c, MC_ENOMEM, "TLS: %s", gnutls_strerror(g));
    }
    const char *errpos = NULL;
    if ((g = gnutls_priority_set_direct(c->tls, MC_TLS_PRIORITY, &errpos)) < 0 ||
        (g = gnutls_credentials_set(c->tls, GNUTLS_CRD_CERTIFICATE, c->cred)) < 0 ||
        (!is_ip(host) && (g = gnutls_server_name_set(c->tls, GNUTLS_NAME_DNS, host, strlen(host))) < 0))
        return fail(c, MC_ETLS, "TLS: %s", gnutls_strerror(g));
    gnutls_session_set_verify_cert(c->tls, host, 0);
    gnutls_handshake_set_timeout(c->tls, 0);       /* the deadline below rules */
    gnutls_transport_set_ptr(c->tls, c);
    gnutls_transport_set_pull_function(c->tls, tls_pull);
    gnutls_transport_set_push_function(c->tls, tls_push);
    int64_t deadline = deadline_of(c);
    for (;;) {
        errno = 0;
        g = gnutls_handshake(c->tls);
        if (g == 0)
            return 0;
        if (g == GNUTLS_E_AGAIN || g == GNUTLS_E_INTERRUPTED) {
            int rc = wait_fd(c, tls_wants(c), deadline);
            if (rc)
                return rc == MC_ETIMEOUT ? fail(c, MC_ETIMEOUT, "no TLS handshake within %d ms", c->timeout_ms) : rc;
        } else if (gnutls_error_is_fatal(g)) {
            break;
        }
    }
    if (g == GNUTLS_E_CERTIFICATE_VERIFICATION_ERROR) {
        unsigned st = gnutls_session_get_verify_cert_status(c->tls);
        gnutls_datum_t why = {NULL, 0};
        gnutls_certificate_verification_status_print(st, GNUTLS_CRT_X509, &why, 0);
        char w[512];
        snprintf(w, sizeof w, "%s", why.data ? (const char *)why.data : "verification failed");
        for (size_t n = strlen(w); n > 0 && w[n - 1] == ' '; n--)
            w[n - 1] = '\0';
        if ((st & GNUTLS_CERT_UNEXPECTED_OWNER) && !(st & GNUTLS_CERT_SIGNER_NOT_FOUND))
            fail(c, MC_ETLS, "the server's certificate does not name the host %s: %s (connect to a name the "
                 "certificate holds)", host, w);
        else
            fail(c, MC_ETLS, "the server's certificate is not trusted: %s (give its CA with --ca or MESHCORR_CA)",
                 w);
        gnutls_free(why.data);
        return MC_ETLS;
    }
    if (g == GNUTLS_E_FATAL_ALERT_RECEIVED) {
        const char *a = gnutls_alert_get_name(gnutls_alert_get(c->tls));
        return fail(c, MC_ETLS, "the server refused the TLS handshake: %s", a ? a : "alert");
    }
    if (g == GNUTLS_E_PREMATURE_TERMINATION || g == GNUTLS_E_PULL_ERROR || g == GNUTLS_E_PUSH_ERROR)
        return fail(c, MC_ETLS, "the server closed the connection during the TLS handshake%s%s",
                    errno && errno != EAGAIN ? ": " : "", errno && errno != EAGAIN ? strerror(errno) : "");
    return fail(c, MC_ETLS, "TLS handshake failed: %s (is %s a tls: listener?)", gnutls_strerror(g), hostport);
}

int mc_connect(const char *address, const char *token, mc_client **out, char *err, size_t errsz)
{
    return mc_connect_ca(address, token, NULL, out, err, errsz);
}

int mc_connect_ca(const char *address, const char *token, const char *ca_file, mc_client **out, char *err,
                  size_t errsz)
{
    if (!out) {
        snprintf(err, errsz, "mc_connect: out is NULL");
        return MC_EARG;
    }
    *out = NULL;
    mc_client *c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(err, errsz, "out of memory");
        return MC_ENOMEM;
    }
    c->fd = -1;
    c->timeout_ms = MC_DEFAULT_TIMEOUT_MS;
    char host[256];
    int rc = 0;
    if (!address)
        rc = fail(c, MC_EADDRESS, "no server address");
    else if (strncmp(address, "unix:", 5) == 0)
        rc = connect_unix(c, address + 5);
    else if (strncmp(address, "tcp:", 4) == 0)
        rc = connect_tcp(c, "tcp", address + 4, host);
    else if (strncmp(address, "tls:", 4) == 0) {
        rc = connect_tcp(c, "tls", address + 4, host);
        if (!rc)
            rc = start_tls(c, address + 4, host, ca_file);
    } else {
        rc = fail(c, MC_EADDRESS, "'%s' is not unix:PATH, tls:HOST:PORT or tcp:HOST:PORT", address);
    }
    if (!rc) {
        proto_msg req, rep;
        memset(&req, 0, sizeof req);
        req.type = PROTO_MSG_HELLO;
        req.u.hello.version = PROTO_VERSION;
        req.u.hello.token = token ? token : "";
        req.u.hello.client = "libmeshcorr 1";
        if (!(rc = request(c, &req, PROTO_MSG_HELLO_OK, &rep))) {
            snprintf(c->user, sizeof c->user, "%s", rep.u.hello_ok.user);
            c->admin = rep.u.hello_ok.admin;
            proto_msg_free(&rep);
        }
    }
    if (rc) {
        snprintf(err, errsz, "%s", c->errmsg);
        mc_close(c);
        return rc;
    }
    *out = c;
    return 0;
}

/* The connection ends here (the client object stays). */
static void hang_up(mc_client *c)
{
    if (c->tls) {
        gnutls_bye(c->tls, GNUTLS_SHUT_WR);   /* close_notify if the socket takes it now */
        gnutls_deinit(c->tls);
        c->tls = NULL;
    }
    if (c->cred)
        gnutls_certificate_free_credentials(c->cred);
    c->cred = NULL;
    if (c->fd >= 0)
        close(c->fd);
    c->fd = -1;
}

void mc_close(mc_client *c)
{
    if (!c)
        return;
    hang_up(c);
    free(c->rbuf);
    free(c);
}

int mc_submit(mc_client *c, const mc_job_spec *s, uint64_t *job_id)
{
    MC_NEED_CLIENT(c);
    if (!job_id)
        return fail(c, MC_EARG, "mc_submit: job_id is NULL");
    proto_msg req, rep;
    memset(&req, 0, sizeof req);
    req.type = PROTO_MSG_SUBMIT;
    int rc = mc__submit_of(s, &req.u.submit, c->errmsg, sizeof c->errmsg);
    if (rc)
        return rc;
    rc = request(c, &req, PROTO_MSG_SUBMIT_OK, &rep);
    if (!rc) {
        *job_id = rep.u.submit_ok.job_id;
        proto_msg_free(&rep);
    }
    return rc;
}

static int job_request(mc_client *c, int type, int want, uint64_t id, proto_msg *rep)
{
    proto_msg req;
    memset(&req, 0, sizeof req);
    req.type = (uint8_t)type;
    req.u.status.job_id = id;
    return request(c, &req, want, rep);
}

const char *mc_quality_name(int verdict)
{
    static const char *const names[] = {"ok", "folded", "reversed"};
    return verdict >= 0 && verdict <= MC_QUALITY_REVERSED ? names[verdict] : "unknown";
}

int mc_status(mc_client *c, uint64_t id, mc_job_status *o)
{
    MC_NEED_CLIENT(c);
    if (!o)
        return fail(c, MC_EARG, "mc_status: out is NULL");
    proto_msg rep;
    int rc = job_request(c, PROTO_MSG_STATUS, PROTO_MSG_STATUS_OK, id, &rep);
    if (rc)
        return rc;
    const proto_status_ok *s = &rep.u.status_ok;
    memset(o, 0, sizeof *o);
    o->job_id = s->job_id;
    o->state = s->state;
    o->priority = s->priority;
    snprintf(o->user, sizeof o->user, "%s", s->user);
    snprintf(o->label, sizeof o->label, "%s", s->label);
    snprintf(o->reason, sizeof o->reason, "%s", s->reason);
    o->submit_ms = s->submit_ms;
    o->start_ms = s->start_ms;
    o->end_ms = s->end_ms;
    o->has_progress = s->has_progress;
    if (s->has_progress)
        mc__progress_of(&o->progress, &s->progress);
    o->quality = (mc_quality){s->quality.verdict, s->quality.flipped, s->quality.collapsed};
    proto_msg_free(&rep);
    return 0;
}

/* A request about job id whose answer is OK and carries nothing. */
static int job_request_ok(mc_client *c, int type, uint64_t id)
{
    proto_msg rep;
    int rc = job_request(c, type, PROTO_MSG_OK, id, &rep);
    if (!rc)
        proto_msg_free(&rep);
    return rc;
}

int mc_cancel(mc_client *c, uint64_t id)
{
    MC_NEED_CLIENT(c);
    return job_request_ok(c, PROTO_MSG_CANCEL, id);
}

int mc_delete(mc_client *c, uint64_t id)
{
    MC_NEED_CLIENT(c);
    return job_request_ok(c, PROTO_MSG_DELETE, id);
}

int mc_ping(mc_client *c)
{
    MC_NEED_CLIENT(c);
    proto_msg req, rep;
    memset(&req, 0, sizeof req);
    req.type = PROTO_MSG_PING;
    int rc = request(c, &req, PROTO_MSG_PONG, &rep);
    if (!rc)
        proto_msg_free(&rep);
    return rc;
}

int mc_list(mc_client *c, const char *user, uint32_t state_mask, mc_job_info **jobs, uint32_t *n)
{
    MC_NEED_CLIENT(c);
    if (!jobs || !n)
        return fail(c, MC_EARG, "mc_list: jobs or n is NULL");
    *jobs = NULL;
    *n = 0;
    uint64_t after = 0;
    for (;;) {
        proto_msg req, rep;
        memset(&req, 0, sizeof req);
        req.type = PROTO_MSG_LIST;
        req.u.list = (proto_list){state_mask, user ? user : "", 0, after};
        int rc = request(c, &req, PROTO_MSG_LIST_OK, &rep);
        if (rc) {
            free(*jobs);
            *jobs = NULL;
            *n = 0;
            return rc;
        }
        uint32_t k = rep.u.list_ok.n;
        if (k == 0) {
            proto_msg_free(&rep);
            return 0;
        }
        mc_job_info *nj = realloc(*jobs, (*n + k) * sizeof *nj);
        if (!nj) {
            proto_msg_free(&rep);
            free(*jobs);
            *jobs = NULL;
            *n = 0;
            return fail(c, MC_ENOMEM, "out of memory for the job list");
        }
        *jobs = nj;
        for (uint32_t i = 0; i < k; i++) {
            const proto_job_summary *s = &rep.u.list_ok.jobs[i];
            mc_job_info *o = &nj[*n + i];
            o->job_id = s->job_id;
            o->state = s->state;
            o->priority = s->priority;
            o->submit_ms = s->submit_ms;
            snprintf(o->user, sizeof o->user, "%s", s->user);
            snprintf(o->label, sizeof o->label, "%s", s->label);
            o->outer = s->outer;
            o->total = s->total;
            o->quality = (mc_quality){s->quality.verdict, s->quality.flipped, s->quality.collapsed};
            o->fraction = s->fraction;
            o->eta_s = s->eta_s;
            o->ahead = s->ahead;
            after = s->job_id;
        }
        *n += k;
        proto_msg_free(&rep);
    }
}

int mc_watch(mc_client *c, uint64_t id, uint32_t from_outer, mc_progress_fn cb, void *ctx,
             int *end_state, char *reason, size_t reasonsz)
{
    MC_NEED_CLIENT(c);
    proto_msg req;
    memset(&req, 0, sizeof req);
    req.type = PROTO_MSG_WATCH;
    req.u.watch = (proto_watch){id, from_outer};
    c->errmsg[0] = '\0';
    req.request_id = ++c->next_rid;
    proto_buf b;
    proto_buf_init(&b);
    char err[256];
    int rc = proto_msg_encode(&b, &req, err, sizeof err);
    if (!rc)
        rc = send_all(c, b.data, b.len);
    proto_buf_free(&b);
    if (rc)
        return rc < -99 ? rc : fail(c, MC_EARG, "WATCH: %s", err);
    for (;;) {
        proto_msg m;
        if ((rc = read_frame(c, &m, -1)))
            return rc;
        if (m.request_id != req.request_id ||
            (m.type != PROTO_MSG_PROGRESS && m.type != PROTO_MSG_END)) {
            rc = fail(c, MC_EPROTO, "unexpected %s during WATCH", proto_type_name(m.type));
            proto_msg_free(&m);
            return rc;
        }
        if (m.type == PROTO_MSG_END) {
            if (end_state)
                *end_state = m.u.end.state;
            if (reason && reasonsz)
                snprintf(reason, reasonsz, "%s", m.u.end.reason);
            proto_msg_free(&m);
            return 0;
        }
        mc_progress p;
        mc__progress_of(&p, &m.u.progress);
        proto_msg_free(&m);
        if (cb && (rc = cb(ctx, &p)) != 0) {
            hang_up(c);
            return rc;
        }
    }
}

int mc_result(mc_client *c, uint64_t id, unsigned what, mc_job_result *out)
{
    MC_NEED_CLIENT(c);
    if (!out)
        return fail(c, MC_EARG, "mc_result: out is NULL");
    memset(out, 0, sizeof *out);
    proto_msg req, rep;
    memset(&req, 0, sizeof req);
    req.type = PROTO_MSG_RESULT;
    req.u.result = (proto_result){id, what};
    int rc = request(c, &req, PROTO_MSG_RESULT_OK, &rep);
    if (rc)
        return rc;
    rc = mc__result_of(&rep.u.result_ok, ~0u, out);     /* every part the server sent */
    proto_msg_free(&rep);
    return rc ? fail(c, rc, "out of memory for the result") : 0;
}

int mc_result_stage(mc_client *c, uint64_t id, const char *stage, mc_stage_maps *out)
{
    MC_NEED_CLIENT(c);
    if (!out)
        return fail(c, MC_EARG, "mc_result_stage: out is NULL");
    memset(out, 0, sizeof *out);
    if (!stage || strcmp(stage, "rhm"))
        return fail(c, MC_EARG, "mc_result_stage: '%s' is not a stage whose maps a job keeps (rhm)",
                    stage ? stage : "(null)");
    proto_msg req, rep;
    memset(&req, 0, sizeof req);
    req.type = PROTO_MSG_RESULT;
    req.u.result = (proto_result){id, PROTO_WANT_STAGE_RHM};
    int rc = request(c, &req, PROTO_MSG_RESULT_OK, &rep);
    if (rc)
        return rc;
    rc = mc__stage_of(&rep.u.result_ok, out);
    proto_msg_free(&rep);
    return rc ? fail(c, rc, "out of memory for the stage's maps") : 0;
}

void mc_stats_free(mc_server_stats *s)
{
    if (!s)
        return;
    free(s->slot_job);
    free(s->slot_state);
    memset(s, 0, sizeof *s);
}

int mc_stats(mc_client *c, mc_server_stats *out)
{
    MC_NEED_CLIENT(c);
    if (!out)
        return fail(c, MC_EARG, "mc_stats: out is NULL");
    memset(out, 0, sizeof *out);
    proto_msg req, rep;
    memset(&req, 0, sizeof req);
    req.type = PROTO_MSG_STATS;
    int rc = request(c, &req, PROTO_MSG_STATS_OK, &rep);
    if (rc)
        return rc;
    const proto_stats_ok *s = &rep.u.stats_ok;
    out->queued = s->queued;
    out->running = s->running;
    out->workers = s->workers;
    out->completed = s->completed;
    out->failed = s->failed;
    out->cancelled = s->cancelled;
    out->slot_job = calloc(s->nslots + 1, sizeof *out->slot_job);
    out->slot_state = calloc(s->nslots + 1, sizeof *out->slot_state);
    if (!out->slot_job || !out->slot_state) {
        proto_msg_free(&rep);
        mc_stats_free(out);
        return fail(c, MC_ENOMEM, "out of memory for the statistics");
    }
    out->nslots = s->nslots;
    for (uint32_t i = 0; i < s->nslots; i++) {
        out->slot_job[i] = s->slots[i].job_id;
        out->slot_state[i] = s->slots[i].state;
    }
    for (uint32_t i = 0; i < s->ndevices && i < 8; i++)
        snprintf(out->devices[i], sizeof out->devices[i], "%s", s->devices[i]);
    out->ndevices = s->ndevices < 8 ? s->ndevices : 8;
    snprintf(out->backend, sizeof out->backend, "%s", s->backend ? s->backend : "");
    out->backend_ok = s->backend_ok;
    snprintf(out->backend_status, sizeof out->backend_status, "%s", s->backend_status ? s->backend_status : "");
    proto_msg_free(&rep);
    return 0;
}

int mc_send_raw(mc_client *c, const void *bytes, size_t len)
{
    MC_NEED_CLIENT(c);
    if (!bytes && len)
        return fail(c, MC_EARG, "mc_send_raw: bytes is NULL");
    c->errmsg[0] = '\0';
    int rc = send_all(c, bytes, len);
    if (rc)
        return rc;
    proto_msg m;
    rc = read_frame(c, &m, deadline_of(c));
    if (!rc)
        proto_msg_free(&m);
    return rc;
}

void mc_interrupt(mc_client *c)
{
    if (c && c->fd >= 0)
        shutdown(c->fd, SHUT_RDWR);     /* poll() wakes, recv() sees the end */
}
