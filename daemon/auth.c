/* auth.c — who a connection is: a token from the tokens file (TCP), or the
 * peer's uid from SO_PEERCRED (Unix socket). Holds the token table; knows
 * nothing about jobs or the protocol beyond the user name it returns.
 *
 * DESIGN: tokens exist in plaintext only with their users. The tokens file
 * holds `sha256:HEX user [admin]` lines (`meshcorrd token new` makes a
 * token and its line), the table in memory holds those digests, and a
 * HELLO's token is hashed and compared with them. A file anyone but the
 * daemon's user or root could change, or anyone at all could read, is
 * refused, and so is any line the parser would have to guess about (too
 * long, a NUL byte, a plaintext token, a token twice): a refused file keeps
 * the daemon from starting, or a reload keeps the tokens it had. */
#include "mcd.h"
#include "util/errbuf.h"

#include <errno.h>
#include <gnutls/crypto.h>
#include <gnutls/gnutls.h>
#include <pwd.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#define AUTH_HASH_PREFIX "sha256:"

struct auth_tokens {
    struct auth_entry {
        uint8_t hash[AUTH_HASH_LEN];
        char user[AUTH_MAX_USER];
        int admin, line;
    } *e;
    int n;
    char path[CONF_PATH];         /* the file read ("" none) */
};

void auth_tokens_free(auth_tokens *t)
{
    if (!t)
        return;
    if (t->e)
        explicit_bzero(t->e, (size_t)t->n * sizeof *t->e);
    free(t->e);
    free(t);
}

int auth_tokens_count(const auth_tokens *t)
{
    return t ? t->n : 0;
}

const char *auth_tokens_path(const auth_tokens *t)
{
    return t ? t->path : "";
}

int auth_token_hash(const char *token, uint8_t out[AUTH_HASH_LEN])
{
    return gnutls_hash_fast(GNUTLS_DIG_SHA256, token, strlen(token), out) == 0 ? 0 : -1;
}

void auth_hash_hex(const uint8_t h[AUTH_HASH_LEN], char hex[2 * AUTH_HASH_LEN + 1])
{
    static const char digits[] = "0123456789abcdef";
    for (int i = 0; i < AUTH_HASH_LEN; i++) {
        hex[2 * i] = digits[h[i] >> 4];
        hex[2 * i + 1] = digits[h[i] & 15];
    }
    hex[2 * AUTH_HASH_LEN] = '\0';
}

int auth_token_new(char tok[AUTH_NEW_TOKEN_LEN + 1], char *err, size_t errsz)
{
    static const char b64url[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
    uint8_t r[AUTH_NEW_TOKEN_BYTES];
    for (size_t got = 0; got < sizeof r;) {
        ssize_t k = getrandom(r + got, sizeof r - got, 0);
        if (k < 0 && errno != EINTR)
            return errbuf_set(err, errsz, -1, "getrandom: %s", strerror(errno));
        got += k > 0 ? (size_t)k : 0;
    }
    size_t o = strlen(AUTH_TOKEN_PREFIX);
    memcpy(tok, AUTH_TOKEN_PREFIX, o);
    for (size_t i = 0; i < sizeof r; i += 3) {          /* 3 bytes -> 4 characters */
        uint32_t v = (uint32_t)r[i] << 16 | (uint32_t)r[i + 1] << 8 | r[i + 2];
        for (int k = 3; k >= 0; k--)
            tok[o++] = b64url[(v >> (6 * k)) & 63];
    }
    tok[o] = '\0';
    explicit_bzero(r, sizeof r);
    return 0;
}

/* Where the tokens file is: the configured path (conf_credential_path);
 * without one, $CREDENTIALS_DIRECTORY/tokens when that file exists. ""
 * when there is none. */
static int resolve_path(const char *conf, char *out, size_t sz, char *err, size_t errsz)
{
    out[0] = '\0';
    if (conf && *conf)
        return conf_credential_path("tokens", conf, out, sz, err, errsz);
    const char *creds = getenv("CREDENTIALS_DIRECTORY");
    if (creds && *creds) {
        snprintf(out, sz, "%s/tokens", creds);
        if (access(out, F_OK) != 0)
            out[0] = '\0';
    }
    return 0;
}

/* The file's owner and mode (st), before a byte of it is believed. */
static int check_stat(const struct stat *st, const char *path, char *err, size_t errsz)
{
    if (!S_ISREG(st->st_mode))
        return errbuf_set(err, errsz, -1, "%s: not a regular file", path);
    uid_t me = geteuid();
    if (st->st_uid != me && st->st_uid != 0)
        return errbuf_set(err, errsz, -1, "%s: owned by uid %lu, neither meshcorrd's user (uid %lu) nor root: "
                          "whoever owns it can give themselves a token; run `chown %lu %s`", path,
                          (unsigned long)st->st_uid, (unsigned long)me, (unsigned long)me, path);
    mode_t bad = st->st_mode & (S_IWGRP | S_IWOTH | S_IROTH);
    if (!bad)
        return 0;
    char which[96] = "", fix[16] = "";
    const char *sep = "";
    if (st->st_mode & S_IWGRP) {
        strcat(which, "writable by its group");
        strcat(fix, "g-w");
        sep = " and ";
    }
    if (st->st_mode & (S_IWOTH | S_IROTH)) {
        strcat(which, sep);
        strcat(which, (st->st_mode & S_IWOTH) && (st->st_mode & S_IROTH) ? "readable and writable by others"
                      : st->st_mode & S_IWOTH ? "writable by others" : "readable by others");
        strcat(fix, *fix ? ",o-" : "o-");
        strcat(fix, (st->st_mode & S_IROTH) ? ((st->st_mode & S_IWOTH) ? "rw" : "r") : "w");
    }
    return errbuf_set(err, errsz, -1, "%s: mode %04o: %s (who can write it can make themselves admin; who can "
                      "read it learns the users); run `chmod %s %s`", path, (unsigned)(st->st_mode & 07777),
                      which, fix, path);
}

static int check_file(int fd, const char *path, char *err, size_t errsz)
{
    struct stat st;
    if (fstat(fd, &st) != 0)
        return errbuf_set(err, errsz, -1, "%s: %s", path, strerror(errno));
    return check_stat(&st, path, err, errsz);
}

/* "sha256:" and 64 hex digits into h; 0, or -1 not that form. */
static int parse_hash(const char *field, uint8_t h[AUTH_HASH_LEN])
{
    size_t pl = strlen(AUTH_HASH_PREFIX);
    if (strncmp(field, AUTH_HASH_PREFIX, pl) != 0 || strlen(field + pl) != 2 * AUTH_HASH_LEN)
        return -1;
    for (int i = 0; i < 2 * AUTH_HASH_LEN; i++) {
        char c = field[pl + i];
        int v = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10
              : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
        if (v < 0)
            return -1;
        if (i % 2 == 0)
            h[i / 2] = (uint8_t)(v << 4);
        else
            h[i / 2] |= (uint8_t)v;
    }
    return 0;
}

/* One line (without its newline, NUL-free) into the table; 0, or -1 with
 * err naming the line. */
static int parse_line(auth_tokens *t, int *cap, char *line, const char *path, int lineno, char *err,
                      size_t errsz)
{
    char *hash = strchr(line, '#');
    if (hash)
        *hash = '\0';
    char *f[4], *save = NULL;
    int k = 0;
    for (char *w = strtok_r(line, " \t\r\v\f", &save); w; w = strtok_r(NULL, " \t\r\v\f", &save))
        if (k < 4)
            f[k++] = w;
        else
            k = 5;
    if (k == 0)
        return 0;
    struct auth_entry e;
    memset(&e, 0, sizeof e);
    if (strncmp(f[0], AUTH_HASH_PREFIX, strlen(AUTH_HASH_PREFIX)) != 0)
        return errbuf_set(err, errsz, -1, "%s:%d: a plaintext token (the file keeps only SHA-256 hashes of "
                          "tokens): replace the line by the one `meshcorrd token hash USER [--admin]` prints "
                          "for that token on its standard input, or make a new token with `meshcorrd token new "
                          "USER`", path, lineno);
    if (parse_hash(f[0], e.hash))
        return errbuf_set(err, errsz, -1, "%s:%d: expected sha256: and %d hex digits", path, lineno,
                          2 * AUTH_HASH_LEN);
    if (k < 2 || k > 3 || (k == 3 && strcmp(f[2], "admin") != 0))
        return errbuf_set(err, errsz, -1, "%s:%d: expected `sha256:HEX user [admin]`", path, lineno);
    char why[128];
    if (auth_user_ok(f[1], why, sizeof why))
        return errbuf_set(err, errsz, -1, "%s:%d: %s", path, lineno, why);
    for (int i = 0; i < t->n; i++)
        if (memcmp(t->e[i].hash, e.hash, AUTH_HASH_LEN) == 0)
            return errbuf_set(err, errsz, -1, "%s:%d: the same token as line %d", path, lineno, t->e[i].line);
    snprintf(e.user, sizeof e.user, "%s", f[1]);
    e.admin = k == 3;
    e.line = lineno;
    if (t->n == *cap) {
        int ncap = *cap ? 2 * *cap : 16;
        void *ne = realloc(t->e, (size_t)ncap * sizeof *t->e);
        if (!ne)
            return errbuf_set(err, errsz, -1, "out of memory");
        t->e = ne;
        *cap = ncap;
    }
    t->e[t->n++] = e;
    return 0;
}

int auth_tokens_load(const char *conf_path, auth_tokens **out, char *err, size_t errsz)
{
    *out = NULL;
    auth_tokens *t = calloc(1, sizeof *t);
    if (!t)
        return errbuf_set(err, errsz, -1, "out of memory");
    if (resolve_path(conf_path, t->path, sizeof t->path, err, errsz)) {
        auth_tokens_free(t);
        return -1;
    }
    if (!t->path[0]) {
        *out = t;
        return 0;
    }
    const char *path = t->path;
    FILE *fp = fopen(path, "re");
    if (!fp) {
        struct stat st;
        if (errno == EACCES && stat(path, &st) == 0 && check_stat(&st, path, err, errsz) != 0)
            ;                              /* its owner or mode is the reason to give */
        else if (errno == EACCES)
            errbuf_set(err, errsz, -1, "%s: %s: meshcorrd reads it as uid %lu (its --user), now and at each reload: "
                       "`chown %lu %s` (mode 0600)", path, strerror(errno), (unsigned long)geteuid(),
                       (unsigned long)geteuid(), path);
        else
            errbuf_set(err, errsz, -1, "%s: %s", path, strerror(errno));
        auth_tokens_free(t);
        return -1;
    }
    int rc = check_file(fileno(fp), path, err, errsz);
    char *line = NULL;
    size_t lcap = 0;
    int lineno = 0, cap = 0;
    ssize_t n;
    while (!rc && (n = getline(&line, &lcap, fp)) >= 0) {
        lineno++;
        if (n > 0 && line[n - 1] == '\n')
            line[--n] = '\0';
        if (n > AUTH_MAX_LINE)
            rc = errbuf_set(err, errsz, -1, "%s:%d: line of %zd bytes, over the limit of %d (nothing of it is "
                            "read)", path, lineno, n, AUTH_MAX_LINE);
        else if (memchr(line, '\0', (size_t)n))
            rc = errbuf_set(err, errsz, -1, "%s:%d: a NUL byte in the line", path, lineno);
        else
            rc = parse_line(t, &cap, line, path, lineno, err, errsz);
    }
    if (!rc && ferror(fp))
        rc = errbuf_set(err, errsz, -1, "%s: %s", path, strerror(errno));
    if (line)
        explicit_bzero(line, lcap);
    free(line);
    fclose(fp);
    if (rc) {
        auth_tokens_free(t);
        return rc;
    }
    *out = t;
    return 0;
}

int auth_token_user(const auth_tokens *t, const uint8_t hash[AUTH_HASH_LEN], char user[AUTH_MAX_USER],
                    int *admin)
{
    int found = -1;
    for (int i = 0; t && i < t->n; i++)     /* every entry, no early exit */
        if (gnutls_memcmp(hash, t->e[i].hash, AUTH_HASH_LEN) == 0 && found < 0)
            found = i;
    if (found < 0)
        return -1;
    snprintf(user, AUTH_MAX_USER, "%s", t->e[found].user);
    *admin = t->e[found].admin;
    return 0;
}

int auth_peer_uid(int fd, long admin_uid, unsigned long *uid, int *admin)
{
    struct ucred cr;
    socklen_t len = sizeof cr;
    if (getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cr, &len) != 0)
        return -1;
    *uid = cr.uid;
    *admin = cr.uid == 0 || (admin_uid >= 0 && (long)cr.uid == admin_uid);
    return 0;
}

int auth_peer_user(int fd, long admin_uid, char user[AUTH_MAX_USER], int *admin,
                   char *err, size_t errsz)
{
    unsigned long uid;
    if (auth_peer_uid(fd, admin_uid, &uid, admin) != 0)
        return errbuf_set(err, errsz, -1, "SO_PEERCRED: %s", strerror(errno));
    struct passwd pw, *res = NULL;
    char buf[4096];
    if (getpwuid_r((uid_t)uid, &pw, buf, sizeof buf, &res) == 0 && res)
        snprintf(user, AUTH_MAX_USER, "%s", pw.pw_name);
    else
        snprintf(user, AUTH_MAX_USER, "uid%lu", uid);
    return 0;
}
