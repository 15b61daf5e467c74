/* testtls.h — certificates for the TLS tests and benchmarks, made with
 * GnuTLS's certtool (gnutls-bin, deploy/install-deps.sh) in the test's own
 * temporary directory: a CA, a server certificate it signs for the host
 * name "localhost" only (no IP address), and a second CA that signed
 * nothing the daemon holds. ECDSA P-256 keys, valid for two days. Test code
 * only. */
#ifndef TESTTLS_H
#define TESTTLS_H

typedef struct testtls {
    char dir[600];             /* harness_tmpdir()/name */
    char ca[700], ca_key[700]; /* the test CA (PEM) and its key */
    char cert[700], key[700];  /* the server's certificate (DNS localhost) and key */
    char other_ca[700], other_ca_key[700];  /* an unrelated CA */
} testtls;

/* Makes all of them; fails the test when certtool cannot. */
void testtls_make(testtls *t, const char *name);
/* A self-signed CA named cn: ca (PEM) and ca_key. */
void testtls_ca(const char *dir, const char *cn, const char *ca, const char *ca_key);
/* A server certificate for the DNS name dns, signed by ca/ca_key: cert, key. */
void testtls_issue(const char *dir, const char *ca, const char *ca_key, const char *dns, const char *cert,
                   const char *key);
/* Appends "--listen tls:127.0.0.1:0 --tls-cert CERT --tls-key KEY" to args
 * at *k (testdaemon_start's extra options; d->tls_addr then names it). */
void testtls_daemon_args(const testtls *t, const char **args, int *k);

#endif
