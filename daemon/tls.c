/* tls.c — TLS for meshcorrd (GnuTLS): the server's credentials
 * (--tls-cert, --tls-key; read again on SIGHUP) and one session per
 * connection of a tls: listener. A session does no I/O of its own: srv.c
 * feeds it what libuv read (the pull function reads that memory) and its
 * records go to a push callback that queues them for uv_write, so the
 * handshake and every record run on the loop without waiting for a client.
 *
 * DESIGN: TLS 1.2 at least, 1.3 preferred (TLS_PRIORITY), no client
 * certificates, no renegotiation: a client asking for one is cut. The
 * credentials are reference-counted (loop thread only): a pair renewed on
 * SIGHUP serves the connections accepted after it while each session keeps
 * the pair it began with; a renewed pair that does not load keeps the
 * running one. A file that cannot serve is refused naming the option and
 * the file: unreadable, no certificate, an expired certificate, a key that
 * does not parse or does not belong to the certificate. */
#include "mcd.h"
#include "util/errbuf.h"

#include <errno.h>
#include <gnutls/gnutls.h>
#include <gnutls/x509.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define TLS_RECORD_CHUNK 16384        /* plaintext bytes taken per gnutls_record_recv */
#define TLS_KEEP_INPUT 16384          /* an emptied input buffer larger than this is freed */

struct tls_creds {
    gnutls_certificate_credentials_t cred;
    gnutls_priority_t prio;
    char *cert_pem, *key_pem;         /* the pair as PEM text, for libmicrohttpd */
    int refs;                         /* d->tls and each session */
};

struct tls_conn {
    gnutls_session_t s;
    tls_creds *creds;
    tls_push_fn push;
    void *ctx;
    uint8_t *in;                      /* ciphertext fed, from in_pos to in_len not yet pulled */
    size_t in_len, in_pos, in_cap;
    int ready, said_bye;
    int first_byte;                   /* of the peer's stream (a TLS handshake starts 0x16); -1 none yet */
    char peer[64];
};

static tls_creds *creds_ref(tls_creds *t)
{
    t->refs++;
    return t;
}

static void creds_unref(tls_creds *t)
{
    if (!t || --t->refs > 0)
        return;
    if (t->cred)
        gnutls_certificate_free_credentials(t->cred);
    if (t->prio)
        gnutls_priority_deinit(t->prio);
    if (t->key_pem) {
        explicit_bzero(t->key_pem, strlen(t->key_pem));
        free(t->key_pem);
    }
    free(t->cert_pem);
    free(t);
}

const char *tls_creds_cert_pem(const tls_creds *t) { return t->cert_pem; }
const char *tls_creds_key_pem(const tls_creds *t) { return t->key_pem; }

/* The whole file (at most TLS_MAX_FILE bytes) into *out, NUL-terminated. */
static int read_file(const char *opt, const char *path, gnutls_datum_t *out, char *err, size_t errsz)
{
    out->data = NULL;
    out->size = 0;
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return errbuf_set(err, errsz, -1, "--%s %s: %s", opt, path, strerror(errno));
    struct stat st;
    if (fstat(fileno(fp), &st) != 0 || !S_ISREG(st.st_mode) || st.st_size > TLS_MAX_FILE) {
        fclose(fp);
        return errbuf_set(err, errsz, -1, "--%s %s: not a regular file of at most %u bytes", opt, path,
                          TLS_MAX_FILE);
    }
    unsigned char *buf = malloc((size_t)st.st_size + 1);
    size_t n = buf ? fread(buf, 1, (size_t)st.st_size, fp) : 0;
    int bad = !buf || ferror(fp);
    fclose(fp);
    if (bad) {
        free(buf);
        return errbuf_set(err, errsz, -1, "--%s %s: cannot read it", opt, path);
    }
    buf[n] = '\0';
    out->data = buf;
    out->size = (unsigned)n;
    return 0;
}

static void datum_wipe(gnutls_datum_t *d)
{
    if (d->data) {
        explicit_bzero(d->data, d->size);
        free(d->data);
    }
    d->data = NULL;
    d->size = 0;
}

/* "2026-01-31 12:00 UTC" */
static const char *utc(time_t t, char *buf, size_t sz)
{
    struct tm tm;
    if (t == (time_t)-1 || !gmtime_r(&t, &tm) || !strftime(buf, sz, "%Y-%m-%d %H:%M UTC", &tm))
        snprintf(buf, sz, "(unknown)");
    return buf;
}

/* A PEM copy of each of the n certificates, one after the other. */
static char *chain_pem(gnutls_x509_crt_t *crt, unsigned n)
{
    char *out = NULL;
    size_t len = 0;
    for (unsigned i = 0; i < n; i++) {
        gnutls_datum_t pem;
        if (gnutls_x509_crt_export2(crt[i], GNUTLS_X509_FMT_PEM, &pem) < 0) {
            free(out);
            return NULL;
        }
        char *grown = realloc(out, len + pem.size + 1);
        if (grown) {
            memcpy(grown + len, pem.data, pem.size);
            len += pem.size;
            grown[len] = '\0';
        } else {
            free(out);
        }
        out = grown;
        gnutls_free(pem.data);
        if (!out)
            return NULL;
    }
    return out;
}

/* Reads and checks the pair; *out holds one reference. 0, or -1 with err
 * naming the option and file at fault. */
static int creds_load(const char *cert_opt, const char *key_opt, tls_creds **out, char *err, size_t errsz)
{
    *out = NULL;
    char cert[CONF_PATH], key[CONF_PATH];
    if (conf_credential_path("--tls-cert", cert_opt, cert, sizeof cert, err, errsz) ||
        conf_credential_path("--tls-key", key_opt, key, sizeof key, err, errsz))
        return -1;
    gnutls_datum_t cd = {NULL, 0}, kd = {NULL, 0};
    gnutls_x509_crt_t *crt = NULL;
    unsigned ncrt = 0;
    gnutls_x509_privkey_t pk = NULL;
    tls_creds *t = calloc(1, sizeof *t);
    int rc = -1, g;
    if (!t) {
        errbuf_set(err, errsz, -1, "TLS: out of memory");
        goto done;
    }
    t->refs = 1;
    if (read_file("tls-cert", cert, &cd, err, errsz) || read_file("tls-key", key, &kd, err, errsz))
        goto done;
    g = gnutls_x509_crt_list_import2(&crt, &ncrt, &cd, GNUTLS_X509_FMT_PEM, 0);
    if (g < 0 || ncrt == 0) {          /* else one DER certificate */
        gnutls_free(crt);
        crt = NULL;
        ncrt = 0;
        int der = gnutls_x509_crt_list_import2(&crt, &ncrt, &cd, GNUTLS_X509_FMT_DER, 0);
        if (der < 0 || ncrt == 0) {
            errbuf_set(err, errsz, -1, "--tls-cert %s: no X.509 certificate in it (PEM or DER): %s", cert,
                       gnutls_strerror(g < 0 ? g : GNUTLS_E_NO_CERTIFICATE_FOUND));
            goto done;
        }
    }
    char when[64];
    time_t now = time(NULL), until = gnutls_x509_crt_get_expiration_time(crt[0]);
    if (until != (time_t)-1 && until < now) {
        errbuf_set(err, errsz, -1, "--tls-cert %s: the certificate expired on %s", cert, utc(until, when, sizeof when));
        goto done;
    }
    if ((g = gnutls_x509_privkey_init(&pk)) < 0 || (g = gnutls_x509_privkey_import2(pk, &kd, GNUTLS_X509_FMT_PEM,
                                                                                   NULL, 0)) < 0) {
        errbuf_set(err, errsz, -1, "--tls-key %s: not a private key meshcorrd can use (PEM or DER, not "
                   "encrypted): %s", key, gnutls_strerror(g));
        goto done;
    }
    if ((g = gnutls_certificate_allocate_credentials(&t->cred)) < 0 ||
        (g = gnutls_priority_init(&t->prio, TLS_PRIORITY, NULL)) < 0) {
        errbuf_set(err, errsz, -1, "TLS: %s", gnutls_strerror(g));
        goto done;
    }
    g = gnutls_certificate_set_x509_key(t->cred, crt, ncrt, pk);
    if (g == GNUTLS_E_CERTIFICATE_KEY_MISMATCH) {
        errbuf_set(err, errsz, -1, "--tls-key %s does not belong to the certificate in --tls-cert %s", key, cert);
        goto done;
    }
    if (g < 0) {
        errbuf_set(err, errsz, -1, "--tls-cert %s with --tls-key %s: %s", cert, key, gnutls_strerror(g));
        goto done;
    }
    gnutls_datum_t kp = {NULL, 0};
    if (!(t->cert_pem = chain_pem(crt, ncrt)) || gnutls_x509_privkey_export2(pk, GNUTLS_X509_FMT_PEM, &kp) < 0 ||
        !(t->key_pem = strndup((const char *)kp.data, kp.size))) {
        if (kp.data) {
            explicit_bzero(kp.data, kp.size);
            gnutls_free(kp.data);
        }
        errbuf_set(err, errsz, -1, "TLS: out of memory");
        goto done;
    }
    explicit_bzero(kp.data, kp.size);
    gnutls_free(kp.data);
    gnutls_datum_t dn = {NULL, 0};
    gnutls_x509_crt_get_dn3(crt[0], &dn, 0);
    time_t from = gnutls_x509_crt_get_activation_time(crt[0]);
    char since[64];
    if (from != (time_t)-1 && from > now)
        dlog(DLOG_WARN, "TLS: the certificate in %s is valid only from %s: clients refuse it until then", cert,
             utc(from, since, sizeof since));
    dlog(DLOG_INFO, "TLS: certificate %s (%u in the chain, valid until %s) from %s, key from %s",
         dn.data ? (const char *)dn.data : "(no subject)", ncrt, utc(until, when, sizeof when), cert, key);
    gnutls_free(dn.data);
    *out = t;
    t = NULL;
    rc = 0;
done:
    for (unsigned i = 0; i < ncrt; i++)
        gnutls_x509_crt_deinit(crt[i]);
    gnutls_free(crt);
    if (pk)
        gnutls_x509_privkey_deinit(pk);
    datum_wipe(&cd);
    datum_wipe(&kd);
    creds_unref(t);
    return rc;
}

int tls_init(mcd *d, char *err, size_t errsz)
{
    const mcd_conf *c = &d->conf;
    for (int i = 0; i < c->nlisten; i++)
        if (strncmp(c->listen[i], "tls:", 4) == 0 && (!c->tls_cert[0] || !c->tls_key[0]))
            return errbuf_set(err, errsz, -1, "--listen %s needs --tls-cert FILE and --tls-key FILE", c->listen[i]);
    if (!c->tls_cert[0] != !c->tls_key[0])
        return errbuf_set(err, errsz, -1, "%s without %s: give both (the certificate chain and its key)",
                          c->tls_cert[0] ? "--tls-cert" : "--tls-key", c->tls_cert[0] ? "--tls-key" : "--tls-cert");
    if (!c->tls_cert[0])
        return 0;
    return creds_load(c->tls_cert, c->tls_key, &d->tls, err, errsz);
}

int tls_reload(mcd *d)
{
    if (!d->tls)
        return 0;
    tls_creds *t;
    char err[1024];
    if (creds_load(d->conf.tls_cert, d->conf.tls_key, &t, err, sizeof err) != 0) {
        dlog(DLOG_ERROR, "reload: %s: keeping the running certificate and key", err);
        return 0;
    }
    creds_unref(d->tls);
    d->tls = t;
    dlog(DLOG_INFO, "reload: TLS certificate and key read again: new connections get them");
    return 1;
}

void tls_close(mcd *d)
{
    creds_unref(d->tls);
    d->tls = NULL;
}

void tls_keep_on_reload(const mcd_conf *o, mcd_conf *n, char *changed, size_t sz)
{
    /* the listeners and the dashboard chose TLS or not at start; new file
     * names for a running TLS are read by tls_reload */
    if (!o->tls_cert[0] != !n->tls_cert[0] || !o->tls_key[0] != !n->tls_key[0]) {
        conf_note_change(1, "tls-cert/tls-key (TLS on or off)", changed, sz);
        memcpy(n->tls_cert, o->tls_cert, sizeof n->tls_cert);
        memcpy(n->tls_key, o->tls_key, sizeof n->tls_key);
    }
    conf_note_change(n->insecure_tcp != o->insecure_tcp, "insecure-tcp", changed, sz);
    n->insecure_tcp = o->insecure_tcp;
}

/* ---- sessions ------------------------------------------------------------- */

static ssize_t pull(gnutls_transport_ptr_t p, void *buf, size_t n)
{
    tls_conn *t = p;
    size_t avail = t->in_len - t->in_pos;
    if (!avail) {
        /* all taken (GnuTLS keeps a partial record itself): an idle
         * session holds no read-sized buffer */
        if (t->in_cap > TLS_KEEP_INPUT) {
            free(t->in);
            t->in = NULL;
            t->in_cap = t->in_len = t->in_pos = 0;
        }
        gnutls_transport_set_errno(t->s, EAGAIN);
        return -1;
    }
    if (n > avail)
        n = avail;
    memcpy(buf, t->in + t->in_pos, n);
    t->in_pos += n;
    return (ssize_t)n;
}

static ssize_t push(gnutls_transport_ptr_t p, const void *data, size_t n)
{
    tls_conn *t = p;
    if (t->push(t->ctx, data, n) != 0) {
        gnutls_transport_set_errno(t->s, ENOMEM);
        return -1;
    }
    return (ssize_t)n;
}

int tls_conn_new(tls_creds *creds, const char *peer, tls_push_fn pushfn, void *ctx, tls_conn **out)
{
    *out = NULL;
    tls_conn *t = calloc(1, sizeof *t);
    if (!t)
        return -1;
    if (gnutls_init(&t->s, GNUTLS_SERVER | GNUTLS_NONBLOCK | GNUTLS_NO_SIGNAL) < 0) {
        free(t);
        return -1;
    }
    t->creds = creds_ref(creds);
    t->push = pushfn;
    t->ctx = ctx;
    t->first_byte = -1;
    snprintf(t->peer, sizeof t->peer, "%s", peer);
    if (gnutls_priority_set(t->s, creds->prio) < 0 ||
        gnutls_credentials_set(t->s, GNUTLS_CRD_CERTIFICATE, creds->cred) < 0) {
        tls_conn_free(t);
        return -1;
    }
    gnutls_certificate_server_set_request(t->s, GNUTLS_CERT_IGNORE);
    gnutls_handshake_set_timeout(t->s, 0);   /* srv.c's --hello-timeout cuts a slow handshake */
    gnutls_transport_set_ptr(t->s, t);
    gnutls_transport_set_pull_function(t->s, pull);
    gnutls_transport_set_push_function(t->s, push);
    *out = t;
    return 0;
}

void tls_conn_free(tls_conn *t)
{
    if (!t)
        return;
    gnutls_deinit(t->s);
    creds_unref(t->creds);
    free(t->in);
    free(t);
}

const char *tls_conn_peer(const tls_conn *t) { return t->peer; }
int tls_conn_ready(const tls_conn *t) { return t->ready; }

int tls_conn_feed(tls_conn *t, const void *data, size_t len, char *msg, size_t msgsz)
{
    if (t->in_pos == t->in_len)
        t->in_pos = t->in_len = 0;
    if (len && t->first_byte < 0)
        t->first_byte = *(const uint8_t *)data;
    if (t->in_len - t->in_pos + len > TLS_MAX_INPUT)
        return errbuf_set(msg, msgsz, -1, "more than %u bytes of TLS input unprocessed", TLS_MAX_INPUT);
    if (t->in_len + len > t->in_cap) {
        if (t->in_pos) {               /* what was pulled makes room */
            memmove(t->in, t->in + t->in_pos, t->in_len - t->in_pos);
            t->in_len -= t->in_pos;
            t->in_pos = 0;
        }
        if (t->in_len + len > t->in_cap) {
            uint8_t *grown = realloc(t->in, t->in_len + len);
            if (!grown)
                return errbuf_set(msg, msgsz, -1, "out of memory for TLS input");
            t->in = grown;
            t->in_cap = t->in_len + len;
        }
    }
    memcpy(t->in + t->in_len, data, len);
    t->in_len += len;
    return 0;
}

/* GnuTLS's reason for rc, with the alert the peer sent when that is it. */
static void reason(tls_conn *t, int rc, char *msg, size_t msgsz)
{
    if (rc == GNUTLS_E_FATAL_ALERT_RECEIVED) {
        const char *a = gnutls_alert_get_name(gnutls_alert_get(t->s));
        snprintf(msg, msgsz, "the client sent the alert '%s'", a ? a : "unknown");
    } else {
        snprintf(msg, msgsz, "%s (%s)", gnutls_strerror(rc), gnutls_strerror_name(rc));
    }
}

int tls_conn_handshake(tls_conn *t, char *msg, size_t msgsz)
{
    if (t->ready)
        return 1;
    int rc;
    do
        rc = gnutls_handshake(t->s);
    while (rc < 0 && rc != GNUTLS_E_AGAIN && !gnutls_error_is_fatal(rc));
    if (rc == GNUTLS_E_AGAIN)
        return 0;
    if (rc < 0) {
        reason(t, rc, msg, msgsz);
        if (t->first_byte >= 0 && t->first_byte != 0x16) {   /* not a TLS handshake record */
            size_t n = strlen(msg);
            snprintf(msg + n, msgsz - n, "; the client did not start with a TLS handshake (a plaintext client?)");
        }
        if (rc != GNUTLS_E_FATAL_ALERT_RECEIVED)
            gnutls_alert_send_appropriate(t->s, rc);
        return -1;
    }
    t->ready = 1;
    return 1;
}

int tls_conn_read(tls_conn *t, proto_buf *out, char *msg, size_t msgsz)
{
    uint8_t buf[TLS_RECORD_CHUNK];
    for (;;) {
        ssize_t r = gnutls_record_recv(t->s, buf, sizeof buf);
        if (r > 0) {
            proto_buf_put(out, buf, (size_t)r);
            if (out->err)
                return errbuf_set(msg, msgsz, -1, "out of memory for the request");
            continue;
        }
        if (r == 0)
            return 1;
        if (r == GNUTLS_E_AGAIN)
            return 0;
        if (r == GNUTLS_E_REHANDSHAKE) {
            gnutls_alert_send(t->s, GNUTLS_AL_FATAL, GNUTLS_A_NO_RENEGOTIATION);
            return errbuf_set(msg, msgsz, -1, "the client asked to renegotiate, which meshcorrd refuses");
        }
        if (!gnutls_error_is_fatal((int)r))
            continue;                  /* a warning alert, an interrupted call */
        reason(t, (int)r, msg, msgsz);
        return -1;
    }
}

int tls_conn_write(tls_conn *t, const void *data, size_t len, char *msg, size_t msgsz)
{
    const uint8_t *p = data;
    while (len) {
        ssize_t w = gnutls_record_send(t->s, p, len);
        if (w == GNUTLS_E_INTERRUPTED)
            continue;
        if (w <= 0) {
            reason(t, (int)w, msg, msgsz);
            return -1;
        }
        p += w;
        len -= (size_t)w;
    }
    return 0;
}

int tls_conn_bye(tls_conn *t)
{
    if (!t->ready || t->said_bye)
        return 0;
    t->said_bye = 1;
    return gnutls_bye(t->s, GNUTLS_SHUT_WR) == 0;
}

const char *tls_conn_desc(const tls_conn *t, char *buf, size_t sz)
{
    const char *v = gnutls_protocol_get_name(gnutls_protocol_get_version(t->s));
    const char *c = gnutls_cipher_get_name(gnutls_cipher_get(t->s));
    snprintf(buf, sz, "%s %s", v ? v : "?", c ? c : "?");
    return buf;
}
