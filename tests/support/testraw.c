/* testraw.c — see testraw.h. Test code only. */
#include "support/testraw.h"
#include "support/harness.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

double testraw_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int testraw_tcp(const char *addr, const char *src)
{
    const char *colon = strrchr(addr, ':');
    if (strncmp(addr, "tcp:", 4) != 0 || !colon)
        FAILF("testraw_tcp: '%s' is not tcp:HOST:PORT", addr);
    char host[64];
    snprintf(host, sizeof host, "%.*s", (int)(colon - addr - 4), addr + 4);
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons((uint16_t)atoi(colon + 1))};
    if (inet_pton(AF_INET, host, &sa.sin_addr) != 1)
        FAILF("testraw_tcp: '%s' is not an IPv4 address", host);
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0)
        FAILF("socket: %s", strerror(errno));
    if (src) {
        struct sockaddr_in me = {.sin_family = AF_INET};
        if (inet_pton(AF_INET, src, &me.sin_addr) != 1 || bind(fd, (struct sockaddr *)&me, sizeof me) != 0)
            FAILF("bind %s: %s", src, strerror(errno));
    }
    if (connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0)
        FAILF("connect %s from %s: %s", addr, src ? src : "any", strerror(errno));
    return fd;
}

int testraw_unix(const char *addr)
{
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    snprintf(sa.sun_path, sizeof sa.sun_path, "%s", addr + strlen("unix:"));
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0)
        FAILF("connect %s: %s", sa.sun_path, strerror(errno));
    return fd;
}

void testraw_send(int fd, const void *p, size_t n)
{
    if (send(fd, p, n, MSG_NOSIGNAL) != (ssize_t)n)
        FAILF("send: %s", strerror(errno));
}

void testraw_send_msg(int fd, const proto_msg *m)
{
    proto_buf b;
    proto_buf_init(&b);
    char err[256];
    if (proto_msg_encode(&b, m, err, sizeof err))
        FAILF("encode: %s", err);
    testraw_send(fd, b.data, b.len);
    proto_buf_free(&b);
}

int testraw_recv(int fd, uint8_t *p, size_t n, double deadline)
{
    while (n) {
        int ms = (int)((deadline - testraw_now()) * 1000);
        struct pollfd pf = {fd, POLLIN, 0};
        if (ms <= 0 || poll(&pf, 1, ms) <= 0)
            return -1;
        ssize_t r = recv(fd, p, n, 0);
        if (r <= 0)
            return 1;
        p += r;
        n -= (size_t)r;
    }
    return 0;
}

int testraw_read_msg(int fd, proto_msg *m, uint8_t **buf, double timeout_s)
{
    double deadline = testraw_now() + timeout_s;
    uint8_t hdr[PROTO_HDR_SIZE];
    int rc = testraw_recv(fd, hdr, sizeof hdr, deadline);
    if (rc)
        return rc;
    proto_hdr h;
    char err[512];
    if (proto_frame_scan(hdr, sizeof hdr, 1 << 24, &h, err, sizeof err) < 0)
        FAILF("reply header: %s", err);
    *buf = malloc(h.payload_len + 1);
    CHECK(*buf);
    if (testraw_recv(fd, *buf, h.payload_len, deadline)) {
        free(*buf);
        return 1;
    }
    if (proto_msg_decode(&h, *buf, m, err, sizeof err))
        FAILF("reply: %s", err);
    return 0;
}

int testraw_hello(int fd, const char *token, const char *client, int *code, char *msg, size_t msgsz,
                  double timeout_s)
{
    proto_msg m = {.type = PROTO_MSG_HELLO, .request_id = 1};
    m.u.hello = (proto_hello){PROTO_VERSION, token ? token : "", client};
    testraw_send_msg(fd, &m);
    uint8_t *buf;
    if (testraw_read_msg(fd, &m, &buf, timeout_s))
        return -1;
    int type = m.type;
    if (code)
        *code = type == PROTO_MSG_ERROR ? m.u.error.code : 0;
    if (msg)
        snprintf(msg, msgsz, "%s", type == PROTO_MSG_ERROR ? m.u.error.message : "");
    proto_msg_free(&m);
    free(buf);
    return type;
}

int testraw_ask(int fd, int type, uint32_t request_id, double timeout_s)
{
    proto_msg m;
    memset(&m, 0, sizeof m);
    m.type = (uint8_t)type;
    m.request_id = request_id;
    testraw_send_msg(fd, &m);
    uint8_t *buf;
    if (testraw_read_msg(fd, &m, &buf, timeout_s))
        return -1;
    int got = m.type;
    proto_msg_free(&m);
    free(buf);
    return got;
}

int testraw_closed_within(int fd, double timeout_s)
{
    double deadline = testraw_now() + timeout_s;
    uint8_t b[4096];
    for (;;) {
        int ms = (int)((deadline - testraw_now()) * 1000);
        struct pollfd pf = {fd, POLLIN, 0};
        if (poll(&pf, 1, ms > 0 ? ms : 0) <= 0)
            return 0;
        if (recv(fd, b, sizeof b, 0) <= 0)
            return 1;
    }
}

int testraw_fd_count(int pid)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/%d/fd", pid);
    DIR *d = opendir(path);
    if (!d)
        return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        n += e->d_name[0] != '.';
    closedir(d);
    return n;
}
