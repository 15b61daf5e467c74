/* testwire.c — raw protocol connections to a testdaemon (testwire.h).
 * Test code only. */
#include "support/testwire.h"
#include "support/harness.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

double testwire_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int testwire_connect(const testdaemon *d, const char *token)
{
    int fd;
    if (!token) {
        struct sockaddr_un sa = {.sun_family = AF_UNIX};
        snprintf(sa.sun_path, sizeof sa.sun_path, "%s", d->unix_addr + strlen("unix:"));
        fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        if (fd < 0 || connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0)
            FAILF("connect %s: %s", sa.sun_path, strerror(errno));
        return fd;
    }
    const char *hp = d->tcp_addr + strlen("tcp:"), *colon = strrchr(hp, ':');
    char host[64];
    CHECK(colon && (size_t)(colon - hp) < sizeof host);
    memcpy(host, hp, (size_t)(colon - hp));
    host[colon - hp] = '\0';
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons((uint16_t)atoi(colon + 1))};
    CHECK(inet_pton(AF_INET, host, &sa.sin_addr) == 1);
    fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0)
        FAILF("connect %s: %s", d->tcp_addr, strerror(errno));
    return fd;
}

void testwire_send(int fd, const void *p, size_t n)
{
    while (n) {
        ssize_t w = send(fd, p, n, MSG_NOSIGNAL);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            FAILF("send: %s", w < 0 ? strerror(errno) : "nothing sent");
        p = (const char *)p + w;
        n -= (size_t)w;
    }
}

void testwire_send_msg(int fd, const proto_msg *m)
{
    proto_buf b;
    proto_buf_init(&b);
    char err[256];
    if (proto_msg_encode(&b, m, err, sizeof err))
        FAILF("encode %s: %s", proto_type_name(m->type), err);
    testwire_send(fd, b.data, b.len);
    proto_buf_free(&b);
}

void testwire_send_header(int fd, int type, uint32_t request_id, uint32_t payload_len)
{
    uint8_t h[PROTO_HDR_SIZE];
    proto_hdr hdr = {PROTO_VERSION, (uint8_t)type, 0, request_id, payload_len};
    proto_frame_put_header(h, &hdr);
    testwire_send(fd, h, sizeof h);
}

/* n bytes within the deadline: 0, 1 at EOF, -1 at the deadline. */
static int recv_all(int fd, uint8_t *p, size_t n, double deadline)
{
    while (n) {
        int ms = (int)((deadline - testwire_now()) * 1000);
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

void testwire_read_msg(int fd, proto_msg *m, uint8_t **buf, size_t max_frame, double timeout_s)
{
    double deadline = testwire_now() + timeout_s;
    uint8_t hdr[PROTO_HDR_SIZE];
    int rc = recv_all(fd, hdr, sizeof hdr, deadline);
    if (rc)
        FAILF("no frame within %.1f s (%s)", timeout_s, rc > 0 ? "EOF" : "nothing came");
    proto_hdr h;
    char err[512];
    if (proto_frame_scan(hdr, sizeof hdr, max_frame, &h, err, sizeof err) < 0)
        FAILF("reply header: %s", err);
    *buf = malloc((size_t)h.payload_len + 1);
    CHECK(*buf != NULL);
    if (recv_all(fd, *buf, h.payload_len, deadline))
        FAILF("payload of %u bytes did not arrive within %.1f s", h.payload_len, timeout_s);
    if (proto_msg_decode(&h, *buf, m, err, sizeof err))
        FAILF("reply: %s", err);
}

void testwire_expect_error(int fd, uint32_t rid, int code, const char *what, double timeout_s)
{
    proto_msg m;
    uint8_t *buf;
    testwire_read_msg(fd, &m, &buf, 1 << 20, timeout_s);
    if (m.type != PROTO_MSG_ERROR)
        FAILF("got %s, expected ERROR %s", proto_type_name(m.type), proto_err_name(code));
    if (m.u.error.code != code)
        FAILF("got ERROR %s (%s), expected %s", proto_err_name(m.u.error.code), m.u.error.message,
              proto_err_name(code));
    CHECK_STR_HAS(m.u.error.message, what);
    CHECK_INT(m.request_id, rid);
    proto_msg_free(&m);
    free(buf);
}

int testwire_session(const testdaemon *d, const char *token)
{
    int fd = testwire_connect(d, token);
    proto_msg m = {.type = PROTO_MSG_HELLO, .request_id = 1};
    m.u.hello = (proto_hello){PROTO_VERSION, token ? token : "", "testwire"};
    testwire_send_msg(fd, &m);
    uint8_t *buf;
    testwire_read_msg(fd, &m, &buf, 1 << 20, 10);
    if (m.type != PROTO_MSG_HELLO_OK)
        FAILF("HELLO: got %s%s%s", proto_type_name(m.type), m.type == PROTO_MSG_ERROR ? ": " : "",
              m.type == PROTO_MSG_ERROR ? m.u.error.message : "");
    proto_msg_free(&m);
    free(buf);
    return fd;
}
