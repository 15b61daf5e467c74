/* token.c — `meshcorrd token`, the daemon's own command for tokens:
 *   token new USER [--admin]    a new random token, printed once, and its
 *                               line for the tokens file
 *   token hash [USER [--admin]] the line of a token read on standard input
 *                               (for files of plaintext tokens)
 * Standard output has only what a script takes (the token, the line);
 * what to do with them goes to standard error. Nothing is written to a
 * file: the operator adds the line and reloads. */
#include "mcd.h"

#include <stdio.h>
#include <string.h>

static int usage(FILE *fp)
{
    fprintf(fp, "usage: meshcorrd token new USER [--admin]\n"
                "       meshcorrd token hash [USER [--admin]] < TOKEN\n"
                "new: prints a new random token (shown this once) and the line for the tokens file;\n"
                "hash: prints the line (or, without USER, its sha256:HEX field) for a token read on\n"
                "standard input, e.g. to convert a file of plaintext tokens\n");
    return fp == stdout ? 0 : 2;
}

/* USER [--admin] from argv: 0, or 2 with a message. */
static int user_args(int argc, char **argv, int need, const char **user, int *admin)
{
    *user = NULL;
    *admin = 0;
    for (int i = 0; i < argc; i++) {
        if (strcmp(argv[i], "--admin") == 0)
            *admin = 1;
        else if (argv[i][0] == '-' || *user)
            return usage(stderr);
        else
            *user = argv[i];
    }
    if ((need && !*user) || (*admin && !*user))
        return usage(stderr);
    char err[160];
    if (*user && auth_user_ok(*user, err, sizeof err)) {
        fprintf(stderr, "meshcorrd token: user '%s': %s\n", *user, err);
        return 2;
    }
    return 0;
}

/* The tokens-file line of token (or its hash field alone without user). */
static int print_line(const char *token, const char *user, int admin)
{
    uint8_t h[AUTH_HASH_LEN];
    char hex[2 * AUTH_HASH_LEN + 1];
    if (auth_token_hash(token, h)) {
        fprintf(stderr, "meshcorrd token: SHA-256 failed\n");
        return 1;
    }
    auth_hash_hex(h, hex);
    if (user)
        printf("sha256:%s %s%s\n", hex, user, admin ? " admin" : "");
    else
        printf("sha256:%s\n", hex);
    return 0;
}

static int token_new(int argc, char **argv)
{
    const char *user;
    int admin, rc = user_args(argc, argv, 1, &user, &admin);
    if (rc)
        return rc;
    char tok[AUTH_NEW_TOKEN_LEN + 1], err[256];
    if (auth_token_new(tok, err, sizeof err)) {
        fprintf(stderr, "meshcorrd token new: %s\n", err);
        return 1;
    }
    fprintf(stderr, "# the token of %s%s (shown this once; give it to them for --token-file or "
                    "$MESHCORR_TOKEN):\n", user, admin ? ", admin" : "");
    printf("%s\n", tok);
    fflush(stdout);
    fprintf(stderr, "# the line for the tokens file (then SIGHUP meshcorrd; under its systemd unit, which "
                    "copies the file at start: systemctl restart meshcorrd):\n");
    rc = print_line(tok, user, admin);
    explicit_bzero(tok, sizeof tok);
    return rc;
}

static int token_hash(int argc, char **argv)
{
    const char *user;
    int admin, rc = user_args(argc, argv, 0, &user, &admin);
    if (rc)
        return rc;
    char tok[PROTO_MAX_STRING + 2];
    if (!fgets(tok, sizeof tok, stdin)) {
        fprintf(stderr, "meshcorrd token hash: no token on standard input\n");
        return 1;
    }
    size_t n = strcspn(tok, "\r\n");
    if (n > PROTO_MAX_STRING || (tok[n] == '\0' && !feof(stdin))) {
        fprintf(stderr, "meshcorrd token hash: a token has at most %d bytes\n", PROTO_MAX_STRING);
        return 1;
    }
    tok[n] = '\0';
    if (n == 0) {
        fprintf(stderr, "meshcorrd token hash: the token is empty\n");
        return 1;
    }
    rc = print_line(tok, user, admin);
    explicit_bzero(tok, sizeof tok);
    return rc;
}

int token_main(int argc, char **argv)
{
    if (argc < 2)
        return usage(stderr);
    if (strcmp(argv[1], "new") == 0)
        return token_new(argc - 2, argv + 2);
    if (strcmp(argv[1], "hash") == 0)
        return token_hash(argc - 2, argv + 2);
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)
        return usage(stdout);
    return usage(stderr);
}
