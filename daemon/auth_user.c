/* auth_user.c — the one rule for a user name, wherever one is given: the
 * tokens file, `meshcorrd token new`, --notify-url. Apart from auth.c so
 * that the configuration can check a name without depending on the tokens'
 * loading (which asks the configuration where the file is). */
#include "mcd.h"
#include "util/errbuf.h"

#include <string.h>

int auth_user_ok(const char *user, char *err, size_t errsz)
{
    size_t n = strlen(user);
    if (n == 0 || n >= AUTH_MAX_USER)
        return errbuf_set(err, errsz, -1, "a user name has 1 to %d bytes", AUTH_MAX_USER - 1);
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)user[i];
        if (c <= ' ' || c >= 0x7F || c == '#')
            return errbuf_set(err, errsz, -1, "a user name is printable ASCII without blanks or '#' (byte %zu is "
                              "0x%02x)", i, c);
    }
    if (strcmp(user, PROTO_LIST_ALL_USERS) == 0)
        return errbuf_set(err, errsz, -1, "the user name %s means every user in LIST", PROTO_LIST_ALL_USERS);
    return 0;
}
