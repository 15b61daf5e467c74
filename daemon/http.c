/* http.c — the HTTP endpoint (--http, alias --metrics): libmicrohttpd, a
 * thread per connection, serves GET /metrics (metrics.c, no login: what a
 * Prometheus scrape needs) and hands every other path to the web UI and
 * JSON API (web.c). Nothing here touches the daemon's loop-owned state: the
 * metrics format a copy of the published snapshot (snap_read), and web.c
 * reads the job store through a read-only SQLite connection of its own.
 * MHD bounds what clients can hold: HTTP_MAX_CONNECTIONS connections,
 * HTTP_MAX_PER_ADDRESS of one address, each closed after HTTP_TIMEOUT_S idle
 * seconds, and a request body over WEB_MAX_BODY bytes is answered 413.
 * With --tls-cert/--tls-key it is HTTPS only (MHD_USE_TLS, the same
 * certificate, key and TLS versions as the tls: listeners); a SIGHUP that
 * renews them starts a new libmicrohttpd daemon on the same listening
 * socket (the old one quiesced, then stopped), so the port never closes. */
#include "mcd.h"
#include "web.h"
#include "util/errbuf.h"

#include <microhttpd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

/* Connections, each a thread: libmicrohttpd counts a finished connection
 * until its thread is reaped, so the cap leaves room for those beside the
 * live ones (a lower cap held new connections back at 50 polling browsers). */
#define HTTP_MAX_CONNECTIONS 256
#define HTTP_MAX_PER_ADDRESS 128   /* of one client address */
#define HTTP_THREAD_STACK (512u << 10)
#define HTTP_TIMEOUT_S 10

struct http {
    struct MHD_Daemon *mhd;
    snap *snap;
    mcd_snapshot *copy;          /* for /metrics, under web's lock */
    web *web;
    int fd;                      /* the listening socket; the running daemon closes it when it stops */
    char *cert, *key;            /* PEM copies MHD reads at its start; NULL: plain HTTP */
    int ipv6;
};

/* A request's body, gathered across MHD's calls (one per connection). */
typedef struct body {
    size_t len;
    int too_big;                 /* more than WEB_MAX_BODY came: answered 413 */
    char buf[WEB_MAX_BODY + 1];  /* NUL-terminated */
} body;

static enum MHD_Result on_request(void *cls, struct MHD_Connection *conn, const char *url, const char *method,
                                  const char *version, const char *upload, size_t *upload_size, void **state)
{
    (void)version;
    http *h = cls;
    body *b = *state;
    if (!b) {                     /* the headers: the body (if any) comes in the calls that follow */
        if (!(b = calloc(1, sizeof *b)))
            return MHD_NO;
        *state = b;
        return MHD_YES;
    }
    if (*upload_size) {
        if (b->len + *upload_size > WEB_MAX_BODY)
            b->too_big = 1;
        else {
            memcpy(b->buf + b->len, upload, *upload_size);
            b->len += *upload_size;
            b->buf[b->len] = '\0';
        }
        *upload_size = 0;
        return MHD_YES;
    }
    web_req r;
    memset(&r, 0, sizeof r);
    r.conn = conn;
    r.url = url;
    r.method = method;
    r.body = b->buf;
    r.body_len = b->len;
    const union MHD_ConnectionInfo *ci = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    if (ci && ci->client_addr)
        peer_name(ci->client_addr, r.peer);
    else
        snprintf(r.peer, sizeof r.peer, "?");
    if (b->too_big)
        return web_reply_text(&r, MHD_HTTP_CONTENT_TOO_LARGE, "request body too large (limit %d bytes)\n",
                              WEB_MAX_BODY);
    if (strcmp(url, "/metrics") == 0) {
        if (strcmp(method, MHD_HTTP_METHOD_GET) != 0)
            return web_reply_text(&r, MHD_HTTP_METHOD_NOT_ALLOWED, "method not allowed: GET only\n");
        char *buf = NULL;
        size_t len = 0;
        FILE *fp = open_memstream(&buf, &len);
        if (!fp)
            return MHD_NO;
        web_lock(h->web);
        snap_read(h->snap, h->copy);
        metrics_format(fp, h->copy);
        web_unlock(h->web);
        if (fclose(fp) != 0) {
            free(buf);
            return MHD_NO;
        }
        return web_reply(&r, MHD_HTTP_OK, "text/plain; version=0.0.4; charset=utf-8", buf, len, 1);
    }
    return web_handle(h->web, &r);
}

static void on_completed(void *cls, struct MHD_Connection *conn, void **state, enum MHD_RequestTerminationCode tc)
{
    (void)cls;
    (void)conn;
    (void)tc;
    if (*state) {
        explicit_bzero(*state, sizeof(body));     /* a login's token */
        free(*state);
    }
    *state = NULL;
}

static void free_pem(char **p)
{
    if (*p) {
        explicit_bzero(*p, strlen(*p));
        free(*p);
    }
    *p = NULL;
}

/* A libmicrohttpd daemon on h->fd: HTTPS with cert and key, or HTTP when
 * they are NULL; NULL when it does not start. */
static struct MHD_Daemon *serve(http *h, const char *cert, const char *key)
{
    /* MHD_USE_ITC: a SIGHUP quiesces it, the socket goes on to a new one */
    /* a thread per connection: an event stream's reader waits for records */
    unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_THREAD_PER_CONNECTION | MHD_USE_ITC |
                     (h->ipv6 ? MHD_USE_IPv6 : 0);
    if (!cert)
        return MHD_start_daemon(flags, 0, NULL, NULL, on_request, h, MHD_OPTION_LISTEN_SOCKET, h->fd,
                                MHD_OPTION_CONNECTION_LIMIT, (unsigned)HTTP_MAX_CONNECTIONS,
                                MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)HTTP_MAX_PER_ADDRESS,
                                MHD_OPTION_THREAD_STACK_SIZE, (size_t)HTTP_THREAD_STACK,
                                MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)HTTP_TIMEOUT_S,
                                MHD_OPTION_NOTIFY_COMPLETED, on_completed, NULL, MHD_OPTION_END);
    return MHD_start_daemon(flags | MHD_USE_TLS, 0, NULL, NULL, on_request, h, MHD_OPTION_LISTEN_SOCKET, h->fd,
                            MHD_OPTION_CONNECTION_LIMIT, (unsigned)HTTP_MAX_CONNECTIONS,
                            MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)HTTP_MAX_PER_ADDRESS,
                            MHD_OPTION_THREAD_STACK_SIZE, (size_t)HTTP_THREAD_STACK,
                            MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)HTTP_TIMEOUT_S,
                            MHD_OPTION_NOTIFY_COMPLETED, on_completed, NULL,
                            MHD_OPTION_HTTPS_MEM_CERT, cert, MHD_OPTION_HTTPS_MEM_KEY, key,
                            MHD_OPTION_HTTPS_PRIORITIES, TLS_PRIORITY, MHD_OPTION_END);
}

int http_start(mcd *d, const conf_endpoint *e, const tls_creds *tls, http **out, char *err, size_t errsz)
{
    *out = NULL;
    http *h = calloc(1, sizeof *h);
    if (!h || !(h->copy = snap_alloc(snap_nslots(d->snap))) || !(h->web = web_new(d, tls != NULL))) {
        if (h)
            snap_release(h->copy);
        free(h);
        return errbuf_set(err, errsz, -1, "http: out of memory");
    }
    web_picture_init(d);
    h->snap = d->snap;
    h->fd = dash_listen(e, "http", err, errsz);
    if (h->fd < 0) {
        http_stop(h);
        return -1;
    }
    struct sockaddr_storage sa;
    socklen_t sl = sizeof sa;
    getsockname(h->fd, (struct sockaddr *)&sa, &sl);
    h->ipv6 = sa.ss_family == AF_INET6;
    if (tls && (!(h->cert = strdup(tls_creds_cert_pem(tls))) || !(h->key = strdup(tls_creds_key_pem(tls))))) {
        http_stop(h);
        return errbuf_set(err, errsz, -1, "http: out of memory");
    }
    if (tls && !MHD_is_feature_supported(MHD_FEATURE_TLS)) {
        http_stop(h);
        return errbuf_set(err, errsz, -1, "--http %s:%d: this libmicrohttpd has no TLS, and --tls-cert asks "
                          "for HTTPS", e->host, e->port);
    }
    if (!(h->mhd = serve(h, h->cert, h->key))) {
        http_stop(h);
        return errbuf_set(err, errsz, -1, "--http %s:%d: libmicrohttpd did not start%s", e->host, e->port,
                          tls ? " with the --tls-cert certificate and --tls-key key" : "");
    }
    if (tls)
        dlog(DLOG_INFO, "http over HTTPS (the --tls-cert certificate)");
    *out = h;
    return 0;
}

void http_set_tokens(http *h, const auth_tokens *t)
{
    if (h)
        web_set_tokens(h->web, t);
}

int http_set_tls(http *h, const tls_creds *tls, char *err, size_t errsz)
{
    if (!h->cert || !tls)
        return 0;                  /* plain HTTP stays plain until the next start */
    if (!strcmp(h->cert, tls_creds_cert_pem(tls)) && !strcmp(h->key, tls_creds_key_pem(tls)))
        return 0;                  /* the same pair: nothing to restart */
    char *cert = strdup(tls_creds_cert_pem(tls)), *key = strdup(tls_creds_key_pem(tls));
    if (!cert || !key) {
        free_pem(&cert);
        free_pem(&key);
        return errbuf_set(err, errsz, -1, "http: out of memory");
    }
    /* the old daemon stops taking connections; the new one listens on the
     * same socket; then the old one ends its connections and stops */
    struct MHD_Daemon *old = h->mhd;
    web_streams_end(h->web);      /* the old daemon's event streams end: its stop need not wait */
    if (MHD_quiesce_daemon(old) != h->fd) {
        free_pem(&cert);
        free_pem(&key);
        return errbuf_set(err, errsz, -1, "http: libmicrohttpd could not be quiesced");
    }
    struct MHD_Daemon *nd = serve(h, cert, key);
    if (!nd) {
        /* the old daemon no longer accepts: start it again with its own pair */
        nd = serve(h, h->cert, h->key);
        MHD_stop_daemon(old);
        h->mhd = nd;
        free_pem(&cert);
        free_pem(&key);
        if (!nd)
            dlog(DLOG_ERROR, "http: libmicrohttpd did not start again: --http is off until the next start");
        return errbuf_set(err, errsz, -1, "http: libmicrohttpd did not start with the new certificate");
    }
    MHD_stop_daemon(old);
    h->mhd = nd;
    free_pem(&h->cert);
    free_pem(&h->key);
    h->cert = cert;
    h->key = key;
    dlog(DLOG_INFO, "reload: --http serves the new certificate");
    return 0;
}

void http_stop(http *h)
{
    if (!h)
        return;
    if (h->mhd) {
        web_streams_end(h->web);   /* event streams end within WEB_STREAM_POLL_MS */
        MHD_stop_daemon(h->mhd);   /* joins its threads, closes the listening socket */
    }
    else if (h->fd >= 0)
        close(h->fd);
    free_pem(&h->cert);
    free_pem(&h->key);
    snap_release(h->copy);
    web_free(h->web);
    free(h);
}
