/* auth.c — who a connection is: a token from the tokens file (TCP), or the
 * peer's uid from SO_PEERCRED (Unix socket). Holds the token table; knows
 * nothing about jobs or the protocol beyond the user name it returns. */
#include "mcd.h"
#include "util/errbuf.h"

#include <errno.h>
#include <pwd.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/types.h>

#define AUTH_MAX_TOKEN 256

struct auth_tokens {
    struct auth_entry { char token[AUTH_MAX_TOKEN], user[AUTH_MAX_USER]; int admin; } *e;
    int n;
};

void auth_tokens_free(auth_tokens *t)
{
    if (!t)
        return;
    free(t->e);
    free(t);
}

int auth_tokens_load(const char *path, auth_tokens **out, char *err, size_t errsz)
{
    *out = NULL;
    auth_tokens *t = calloc(1, sizeof *t);
    if (!t)
        return errbuf_set(err, errsz, -1, "out of memory");
    if (!path || !*path) {
        *out = t;
        return 0;
    }
    FILE *fp = fopen(path, "r");
    if (!fp) {
        auth_tokens_free(t);
        return errbuf_set(err, errsz, -1, "%s: %s", path, strerror(errno));
    }
    char line[1024];
    int lineno = 0, rc = 0, cap = 0;
    while (fgets(line, sizeof line, fp)) {
        lineno++;
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        char tok[AUTH_MAX_TOKEN], user[AUTH_MAX_USER], flag[16] = "", extra[2];
        int k = sscanf(line, "%255s %255s %15s %1s", tok, user, flag, extra);
        if (k <= 0)
            continue;
        if (k < 2 || k > 3 || (k == 3 && strcmp(flag, "admin") != 0)) {
            rc = errbuf_set(err, errsz, -1, "%s:%d: expected `token user [admin]`", path, lineno);
            break;
        }
        if (t->n == cap) {
            cap = cap ? 2 * cap : 16;
            void *e = realloc(t->e, (size_t)cap * sizeof *t->e);
            if (!e) {
                rc = errbuf_set(err, errsz, -1, "out of memory");
                break;
            }
            t->e = e;
        }
        strcpy(t->e[t->n].token, tok);
        strcpy(t->e[t->n].user, user);
        t->e[t->n].admin = k == 3;
        t->n++;
    }
    fclose(fp);
    if (rc) {
        auth_tokens_free(t);
        return rc;
    }
    *out = t;
    return 0;
}

/* Compares without an early exit, so the time taken does not tell how many
 * leading bytes of a guessed token were right. */
static int same_token(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    unsigned diff = la != lb;
    for (size_t i = 0; i < la; i++)
        diff |= (unsigned char)a[i] ^ (unsigned char)b[i < lb ? i : 0];
    return diff == 0;
}

int auth_token_user(const auth_tokens *t, const char *token, char user[AUTH_MAX_USER], int *admin)
{
    int found = -1;
    for (int i = 0; t && i < t->n; i++)
        if (same_token(token, t->e[i].token) && found < 0)
            found = i;
    if (found < 0 || !*token)
        return -1;
    strcpy(user, t->e[found].user);
    *admin = t->e[found].admin;
    return 0;
}

int auth_peer_user(int fd, long admin_uid, char user[AUTH_MAX_USER], int *admin,
                   char *err, size_t errsz)
{
    struct ucred cr;
    socklen_t len = sizeof cr;
    if (getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cr, &len) != 0)
        return errbuf_set(err, errsz, -1, "SO_PEERCRED: %s", strerror(errno));
    struct passwd pw, *res = NULL;
    char buf[4096];
    if (getpwuid_r(cr.uid, &pw, buf, sizeof buf, &res) == 0 && res)
        snprintf(user, AUTH_MAX_USER, "%s", pw.pw_name);
    else
        snprintf(user, AUTH_MAX_USER, "uid%lu", (unsigned long)cr.uid);
    *admin = cr.uid == 0 || (admin_uid >= 0 && (long)cr.uid == admin_uid);
    return 0;
}
