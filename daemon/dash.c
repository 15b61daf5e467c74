/* dash.c — the listening sockets of the dashboard servers (--modbus,
 * --http): HOST as the user gave it (a name or a numeric address, v4 or
 * v6), bound in the main thread before the loop starts, so a taken port
 * stops the daemon at start-up with a message. Close-on-exec: the workers
 * meshcorrd spawns must not inherit them. Serves nothing itself. */
#include "mcd.h"
#include "util/errbuf.h"

#include <netdb.h>
#include <stdio.h>
#include <string.h>
#include <errno.h>
#include <sys/socket.h>
#include <unistd.h>

int dash_listen(const conf_endpoint *e, const char *what, char *err, size_t errsz)
{
    char port[16];
    snprintf(port, sizeof port, "%d", e->port);
    struct addrinfo hints, *ai = NULL;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
    int rc = getaddrinfo(e->host, port, &hints, &ai);
    if (rc)
        return errbuf_set(err, errsz, -1, "--%s %s:%d: %s", what, e->host, e->port, gai_strerror(rc));
    int fd = -1, saved = 0;
    for (struct addrinfo *a = ai; a && fd < 0; a = a->ai_next) {
        fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a->ai_protocol);
        if (fd < 0) {
            saved = errno;
            continue;
        }
        int one = 1;
        setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        if (bind(fd, a->ai_addr, a->ai_addrlen) != 0 || listen(fd, 16) != 0) {
            saved = errno;
            close(fd);
            fd = -1;
        }
    }
    freeaddrinfo(ai);
    if (fd < 0)
        return errbuf_set(err, errsz, -1, "--%s %s:%d: %s", what, e->host, e->port, strerror(saved));
    dlog(DLOG_INFO, "%s on %s:%d", what, e->host, e->port);
    return fd;
}

static void keep_endpoint(const conf_endpoint *o, conf_endpoint *n, const char *name, char *changed, size_t sz)
{
    conf_note_change(n->port != o->port || strcmp(n->host, o->host) != 0, name, changed, sz);
    *n = *o;
}

/* The dashboard servers listen from the start to the end. */
void dash_keep_on_reload(const mcd_conf *o, mcd_conf *n, char *changed, size_t sz)
{
    keep_endpoint(&o->modbus, &n->modbus, "modbus", changed, sz);
    keep_endpoint(&o->http, &n->http, "http", changed, sz);
}
