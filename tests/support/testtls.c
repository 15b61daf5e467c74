/* testtls.c — test certificates made with certtool (testtls.h). Test code
 * only. */
#include "support/testtls.h"
#include "support/harness.h"
#include "support/testrun.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static char out[8192];

static void write_template(const char *path, const char *text)
{
    FILE *fp = fopen(path, "w");
    if (!fp || fputs(text, fp) < 0 || fclose(fp) != 0)
        FAILF("cannot write %s", path);
}

static void new_key(const char *key)
{
    if (testrunf(out, sizeof out, "certtool --generate-privkey --key-type=ecdsa --no-text --outfile '%s' 2>&1",
                 key) != 0)
        FAILF("certtool --generate-privkey failed (install gnutls-bin: deploy/install-deps.sh):\n%s", out);
}

void testtls_ca(const char *dir, const char *cn, const char *ca, const char *ca_key)
{
    char tmpl[800], text[512];
    snprintf(tmpl, sizeof tmpl, "%s/ca.tmpl", dir);
    snprintf(text, sizeof text, "cn = \"%s\"\nca\ncert_signing_key\nexpiration_days = 2\n", cn);
    write_template(tmpl, text);
    new_key(ca_key);
    if (testrunf(out, sizeof out, "certtool --generate-self-signed --load-privkey '%s' --template '%s' --no-text "
                 "--outfile '%s' 2>&1", ca_key, tmpl, ca) != 0)
        FAILF("certtool --generate-self-signed failed:\n%s", out);
}

void testtls_issue(const char *dir, const char *ca, const char *ca_key, const char *dns, const char *cert,
                   const char *key)
{
    char tmpl[800], text[512];
    snprintf(tmpl, sizeof tmpl, "%s/server.tmpl", dir);
    snprintf(text, sizeof text, "cn = \"%s\"\ndns_name = \"%s\"\ntls_www_server\nsigning_key\n"
             "encryption_key\nexpiration_days = 2\n", dns, dns);
    write_template(tmpl, text);
    new_key(key);
    if (testrunf(out, sizeof out, "certtool --generate-certificate --load-privkey '%s' --load-ca-certificate '%s' "
                 "--load-ca-privkey '%s' --template '%s' --no-text --outfile '%s' 2>&1", key, ca, ca_key, tmpl,
                 cert) != 0)
        FAILF("certtool --generate-certificate failed:\n%s", out);
}

void testtls_make(testtls *t, const char *name)
{
    snprintf(t->dir, sizeof t->dir, "%s/%s", harness_tmpdir(), name);
    mkdir(t->dir, 0700);
    snprintf(t->ca, sizeof t->ca, "%s/ca.pem", t->dir);
    snprintf(t->ca_key, sizeof t->ca_key, "%s/ca.key", t->dir);
    snprintf(t->cert, sizeof t->cert, "%s/server.pem", t->dir);
    snprintf(t->key, sizeof t->key, "%s/server.key", t->dir);
    snprintf(t->other_ca, sizeof t->other_ca, "%s/other-ca.pem", t->dir);
    snprintf(t->other_ca_key, sizeof t->other_ca_key, "%s/other-ca.key", t->dir);
    testtls_ca(t->dir, "meshcorr test CA", t->ca, t->ca_key);
    testtls_issue(t->dir, t->ca, t->ca_key, "localhost", t->cert, t->key);
    testtls_ca(t->dir, "some other CA", t->other_ca, t->other_ca_key);
}

void testtls_daemon_args(const testtls *t, const char **args, int *k)
{
    args[(*k)++] = "--listen";
    args[(*k)++] = "tls:127.0.0.1:0";
    args[(*k)++] = "--tls-cert";
    args[(*k)++] = t->cert;
    args[(*k)++] = "--tls-key";
    args[(*k)++] = t->key;
}
