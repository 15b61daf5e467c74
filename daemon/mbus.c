/* mbus.c — --modbus: the status snapshot as Modbus TCP input registers
 * (function 0x04), served by one thread of its own with libmodbus building
 * the replies. The register map is daemon/MODBUS.md.
 *
 * DESIGN: read-only, and a client can never stall anything. Only 0x04 is
 * answered; every other function code (writes, holding registers, coils,
 * report slave id, unknown codes) gets ILLEGAL FUNCTION, a malformed 0x04
 * ILLEGAL DATA VALUE, and an address outside the map ILLEGAL DATA ADDRESS
 * (libmodbus, from a mapping holding input registers only). Sockets are
 * non-blocking and frames are assembled here, per client, from what poll()
 * says is readable, so the thread never waits on one client: a request not
 * whole MBUS_FRAME_TIMEOUT_MS after its first byte, a connection idle for
 * MBUS_IDLE_TIMEOUT_S, bytes that are not MBAP (protocol id, length), a
 * function code >= 0x80 or a reply the socket cannot take close that
 * connection. At most MBUS_MAX_CLIENTS connections; one more is accepted and
 * closed at once. poll() wakes every 100 ms to notice timeouts and stop.
 * The registers themselves come from mbus_fill (mbus_regs.c). Never touches
 * the daemon's state: it reads published snapshots (snap_read). */
#include "mcd.h"
#include "util/errbuf.h"

#include <errno.h>
#include <modbus/modbus.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define MBAP_LEN 7                           /* transaction, protocol, length, unit */
#define MBUS_MAX_ADU MODBUS_TCP_MAX_ADU_LENGTH
#define MBUS_POLL_MS 100

typedef struct client {
    int fd;
    uint8_t buf[2 * MBUS_MAX_ADU];
    size_t len;                              /* bytes of requests not yet answered */
    int64_t since;                           /* ms: first byte of the pending request */
    int64_t last;                            /* ms: accepted or last answered */
} client;

struct mbus {
    int lfd;
    snap *snap;
    modbus_t *ctx;                           /* a TCP context: replies only */
    modbus_mapping_t *map;
    mcd_snapshot *copy;
    client clients[MBUS_MAX_CLIENTS];
    int nclients;
    pthread_t thread;
    int started;
    atomic_int stop;
};

static int64_t now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

/* One whole request (MBAP + PDU, len bytes): 0 answered, -1 close. */
static int answer(mbus *m, int fd, const uint8_t *req, size_t len)
{
    int fc = req[MBAP_LEN];
    if (fc == 0 || fc >= 0x80)
        return -1;
    modbus_set_socket(m->ctx, fd);
    if (fc != MODBUS_FC_READ_INPUT_REGISTERS)
        return modbus_reply_exception(m->ctx, req, MODBUS_EXCEPTION_ILLEGAL_FUNCTION) < 0 ? -1 : 0;
    int nb = len == MBAP_LEN + 5 ? (req[MBAP_LEN + 3] << 8) | req[MBAP_LEN + 4] : 0;
    if (nb < 1 || nb > MODBUS_MAX_READ_REGISTERS)
        return modbus_reply_exception(m->ctx, req, MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE) < 0 ? -1 : 0;
    snap_read(m->snap, m->copy);
    mbus_fill(m->copy, m->map->tab_input_registers);
    return modbus_reply(m->ctx, req, (int)len, m->map) < 0 ? -1 : 0;
}

/* Reads what the client sent and answers each whole request: 0, or -1 close. */
static int client_read(mbus *m, client *c, int64_t now)
{
    ssize_t n = recv(c->fd, c->buf + c->len, sizeof c->buf - c->len, 0);
    if (n == 0)
        return -1;
    if (n < 0)
        return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? 0 : -1;
    if (c->len == 0)
        c->since = now;
    c->len += (size_t)n;
    while (c->len >= MBAP_LEN) {
        unsigned proto = (unsigned)(c->buf[2] << 8 | c->buf[3]), mlen = (unsigned)(c->buf[4] << 8 | c->buf[5]);
        if (proto != 0 || mlen < 2 || mlen > MBUS_MAX_ADU - 6) {
            dlog(DLOG_DEBUG, "modbus: not an MBAP header (protocol %u, length %u): closing", proto, mlen);
            return -1;
        }
        size_t flen = 6 + (size_t)mlen;
        if (c->len < flen)
            break;
        if (answer(m, c->fd, c->buf, flen))
            return -1;
        c->len -= flen;
        memmove(c->buf, c->buf + flen, c->len);
        c->since = c->last = now;
    }
    return 0;
}

static void drop(mbus *m, int i, const char *why)
{
    dlog(DLOG_DEBUG, "modbus: client fd %d: %s: closed", m->clients[i].fd, why);
    close(m->clients[i].fd);
    m->clients[i] = m->clients[--m->nclients];
}

static void accept_one(mbus *m, int64_t now)
{
    int fd = accept4(m->lfd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0)
        return;
    if (m->nclients == MBUS_MAX_CLIENTS) {
        dlog(DLOG_WARN, "modbus: %d clients already: connection refused", MBUS_MAX_CLIENTS);
        close(fd);
        return;
    }
    client *c = &m->clients[m->nclients++];
    c->fd = fd;
    c->len = 0;
    c->since = c->last = now;
}

static void *run(void *arg)
{
    mbus *m = arg;
    struct pollfd pf[MBUS_MAX_CLIENTS + 1];
    while (!atomic_load(&m->stop)) {
        int n = m->nclients;
        pf[0] = (struct pollfd){m->lfd, POLLIN, 0};
        for (int i = 0; i < n; i++)
            pf[i + 1] = (struct pollfd){m->clients[i].fd, POLLIN, 0};
        int rc = poll(pf, (nfds_t)n + 1, MBUS_POLL_MS);
        if (rc < 0 && errno != EINTR) {
            dlog(DLOG_ERROR, "modbus: poll: %s", strerror(errno));
            struct timespec ts = {0, MBUS_POLL_MS * 1000000L};
            nanosleep(&ts, NULL);
            continue;
        }
        int64_t now = now_ms();
        /* clients first, from the last (drop() moves the last one into i) */
        for (int i = n - 1; i >= 0; i--) {
            client *c = &m->clients[i];
            if (rc > 0 && (pf[i + 1].revents & (POLLIN | POLLHUP | POLLERR)) && client_read(m, c, now))
                drop(m, i, "closed, unreadable, or not Modbus");
            else if (c->len && now - c->since > MBUS_FRAME_TIMEOUT_MS)
                drop(m, i, "request incomplete after the frame timeout");
            else if (!c->len && now - c->last > MBUS_IDLE_TIMEOUT_S * 1000)
                drop(m, i, "idle");
        }
        if (rc > 0 && (pf[0].revents & POLLIN))
            accept_one(m, now);
    }
    while (m->nclients)
        drop(m, m->nclients - 1, "shutdown");
    return NULL;
}

int mbus_start(const conf_endpoint *e, snap *s, mbus **out, char *err, size_t errsz)
{
    *out = NULL;
    mbus *m = calloc(1, sizeof *m);
    if (!m)
        return errbuf_set(err, errsz, -1, "out of memory");
    m->snap = s;
    m->lfd = -1;
    uint32_t nslots = snap_nslots(s);
    if (!(m->copy = snap_alloc(nslots)) || !(m->ctx = modbus_new_tcp("127.0.0.1", MODBUS_TCP_DEFAULT_PORT)) ||
        !(m->map = modbus_mapping_new_start_address(0, 0, 0, 0, 0, 0, 0, (unsigned)mbus_nregs(nslots)))) {
        mbus_stop(m);
        return errbuf_set(err, errsz, -1, "modbus: out of memory");
    }
    if ((m->lfd = dash_listen(e, "modbus", err, errsz)) < 0) {
        mbus_stop(m);
        return -1;
    }
    int rc = pthread_create(&m->thread, NULL, run, m);
    if (rc) {
        mbus_stop(m);
        return errbuf_set(err, errsz, -1, "modbus: thread: %s", strerror(rc));
    }
    m->started = 1;
    *out = m;
    return 0;
}

void mbus_stop(mbus *m)
{
    if (!m)
        return;
    if (m->started) {
        atomic_store(&m->stop, 1);
        pthread_join(m->thread, NULL);
    }
    if (m->lfd >= 0)
        close(m->lfd);
    if (m->ctx)
        modbus_free(m->ctx);               /* the client sockets are ours, closed above */
    if (m->map)
        modbus_mapping_free(m->map);
    snap_release(m->copy);
    free(m);
}
