/* testhttp.c — raw HTTP requests to a test daemon (testhttp.h). */
#include "support/testhttp.h"
#include "support/harness.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

/* Ports handed out by bind(0), which the daemon's own "tcp:...:0"
 * listeners take: a port chosen here lies below them, so the daemon
 * cannot take it before the option that names it is read. */
static int ephemeral_low(void)
{
    int lo = 32768, hi;
    FILE *fp = fopen("/proc/sys/net/ipv4/ip_local_port_range", "r");
    if (fp) {
        if (fscanf(fp, "%d %d", &lo, &hi) != 2)
            lo = 32768;
        fclose(fp);
    }
    return lo;
}

int testhttp_free_port(void)
{
    int lo = 10000, hi = ephemeral_low();
    if (hi <= lo + 100)
        FAILF("free port: the ephemeral range starts at %d", hi);
    int start = lo + (int)(((unsigned)getpid() * 7919u + (unsigned)time(NULL)) % (unsigned)(hi - lo));
    for (int i = 0; i < hi - lo; i++) {
        int port = lo + (start - lo + i) % (hi - lo);
        int fd = socket(AF_INET, SOCK_STREAM, 0);
        if (fd < 0)
            FAILF("free port: %s", strerror(errno));
        struct sockaddr_in a = {0};
        a.sin_family = AF_INET;
        a.sin_port = htons((uint16_t)port);
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        int ok = !bind(fd, (struct sockaddr *)&a, sizeof a);
        close(fd);
        if (ok)
            return port;
    }
    FAILF("free port: none free in [%d, %d)", lo, hi);
    return -1;
}

int testhttp_request(int port, const char *method, const char *path, const char *headers, const char *body,
                     char *resp, size_t rsz, int timeout_ms)
{
    resp[0] = '\0';
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {0};
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || connect(fd, (struct sockaddr *)&a, sizeof a)) {
        if (fd >= 0)
            close(fd);
        return -1;
    }
    char req[4096];
    int n = snprintf(req, sizeof req, "%s %s HTTP/1.0\r\nHost: 127.0.0.1\r\n%sContent-Length: %zu\r\n\r\n%s", method,
                     path, headers, body ? strlen(body) : 0, body ? body : "");
    if (n < 0 || (size_t)n >= sizeof req || send(fd, req, (size_t)n, MSG_NOSIGNAL) != n) {
        close(fd);
        return -1;
    }
    size_t len = 0;
    while (len < rsz - 1) {
        struct pollfd p = {fd, POLLIN, 0};
        if (poll(&p, 1, timeout_ms) != 1)
            break;
        ssize_t r = read(fd, resp + len, rsz - 1 - len);
        if (r <= 0)
            break;
        len += (size_t)r;
    }
    close(fd);
    resp[len] = '\0';
    int status = 0;
    return sscanf(resp, "HTTP/1.%*d %d", &status) == 1 ? status : 0;
}

const char *testhttp_body(const char *resp)
{
    const char *b = strstr(resp, "\r\n\r\n");
    return b ? b + 4 : "";
}
