/* worker_progress.c — corr_progress -> PROGRESS frames on the daemon's pipe
 * or TCP connection, or appended to the spool's progress.frames (see
 * worker.h). A frame is 169 bytes, under PIPE_BUF, so each pipe write and
 * each O_APPEND write is atomic. Never fails the job. */
#include "main/worker.h"

#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#define WRK_PROGRESS_TIMEOUT_S 10   /* connect and each send, then the file */

void wrk_progress_connect(wrk_progress *pg, const char *hostport, const char *secret_file)
{
    char host[256], secret[WRK_SECRET_MAX + 2] = "";
    const char *colon = strrchr(hostport, ':');
    FILE *fp = fopen(secret_file, "r");
    if (fp) {
        if (!fgets(secret, sizeof secret, fp))
            secret[0] = '\0';
        fclose(fp);
    }
    secret[strcspn(secret, "\r\n")] = '\0';
    if (!secret[0]) {
        fprintf(stderr, "meshcorr-worker: --secret-file %s: no secret: progress goes to %s\n", secret_file,
                pg->file);
        return;
    }
    if (!colon || colon == hostport || (size_t)(colon - hostport) >= sizeof host) {
        fprintf(stderr, "meshcorr-worker: --progress-tcp %s: expected HOST:PORT\n", hostport);
        return;
    }
    memcpy(host, hostport, (size_t)(colon - hostport));
    host[colon - hostport] = '\0';
    struct addrinfo hints, *ai = NULL;
    memset(&hints, 0, sizeof hints);
    hints.ai_socktype = SOCK_STREAM;
    int rc = getaddrinfo(host, colon + 1, &hints, &ai);
    if (rc) {
        fprintf(stderr, "meshcorr-worker: --progress-tcp %s: %s: progress goes to %s\n", hostport,
                gai_strerror(rc), pg->file);
        return;
    }
    int fd = -1;
    for (struct addrinfo *a = ai; a && fd < 0; a = a->ai_next) {
        fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
        if (fd < 0)
            continue;
        struct timeval tv = {WRK_PROGRESS_TIMEOUT_S, 0};
        setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);   /* bounds connect() too */
        if (connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
            close(fd);
            fd = -1;
        }
    }
    freeaddrinfo(ai);
    if (fd < 0) {
        fprintf(stderr, "meshcorr-worker: --progress-tcp %s: cannot connect: progress goes to %s\n",
                hostport, pg->file);
        return;
    }
    char line[64 + WRK_SECRET_MAX];
    int n = snprintf(line, sizeof line, WRK_PROGRESS_HELLO " %llu %s\n", (unsigned long long)pg->job_id, secret);
    if (send(fd, line, (size_t)n, MSG_NOSIGNAL) != n) {
        close(fd);
        fprintf(stderr, "meshcorr-worker: --progress-tcp %s: hello failed: progress goes to %s\n", hostport,
                pg->file);
        return;
    }
    pg->fd = fd;
}

/* Appends the frame to the fallback file; 0 or -1. */
static int append_file(const wrk_progress *pg, const uint8_t *p, size_t n)
{
    int fd = open(pg->file, O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0600);
    if (fd < 0)
        return -1;
    ssize_t w = write(fd, p, n);
    close(fd);
    return w == (ssize_t)n ? 0 : -1;
}

void wrk_progress_fill(const corr_progress *cp, uint64_t job_id, double elapsed, proto_progress *out)
{
    corr_progress_record(cp, out);
    out->job_id = job_id;
    out->elapsed_s = elapsed;
}

void wrk_progress_send(wrk_progress *pg, const corr_progress *cp, double elapsed)
{
    if (pg->fd < 0 && !pg->file[0])
        return;
    proto_msg m;
    memset(&m, 0, sizeof m);
    m.type = PROTO_MSG_PROGRESS;
    wrk_progress_fill(cp, pg->job_id, elapsed, &m.u.progress);
    proto_buf b;
    proto_buf_init(&b);
    if (proto_msg_encode(&b, &m, NULL, 0) != 0) {
        pg->fd = -1;
        goto done;
    }
    const uint8_t *p = b.data;
    size_t n = b.len;
    while (n && pg->fd >= 0) {
        ssize_t w = write(pg->fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            if (pg->file[0]) {                     /* a TCP stream: the file from now on */
                close(pg->fd);
                fprintf(stderr, "meshcorr-worker: progress connection lost (%s): progress goes to %s\n",
                        w < 0 ? strerror(errno) : "closed", pg->file);
            }
            pg->fd = -1;                           /* daemon gone: stop, carry on */
            break;
        }
        p += w;
        n -= (size_t)w;
    }
    /* the whole frame again: the daemon drops a half frame of a broken stream */
    if (pg->fd < 0 && pg->file[0] && append_file(pg, b.data, b.len) != 0)
        pg->file[0] = '\0';
done:
    proto_buf_free(&b);
}
