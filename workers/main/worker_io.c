/* worker_io.c — the spool files of one job: reading job.frame whole and
 * writing result.frame / error.frame atomically (see worker.h). Knows frames,
 * not what is in them. */
#include "main/worker.h"
#include "util/errbuf.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int wrk_frame_read(const char *path, int type, unsigned char **buf, proto_msg *m, char *err, size_t errsz)
{
    *buf = NULL;
    memset(m, 0, sizeof *m);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: cannot open: %s", path, strerror(errno));
    int rc = 0;
    unsigned char *b = NULL;
    struct stat st;
    if (fstat(fd, &st) != 0) {
        rc = errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: cannot stat: %s", path, strerror(errno));
        goto done;
    }
    if (st.st_size > (off_t)PROTO_MAX_FRAME) {
        rc = errbuf_set(err, errsz, PROTO_ETOO_LARGE, "%s: %lld bytes, over PROTO_MAX_FRAME (%u)",
                        path, (long long)st.st_size, PROTO_MAX_FRAME);
        goto done;
    }
    size_t len = (size_t)st.st_size, got = 0;
    if (!(b = malloc(len + 1))) {
        rc = errbuf_set(err, errsz, PROTO_ENOMEM, "%s: out of memory for %zu bytes", path, len);
        goto done;
    }
    while (got < len) {
        ssize_t n = read(fd, b + got, len - got);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            rc = errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: read failed after %zu of %zu bytes: %s",
                            path, got, len, n < 0 ? strerror(errno) : "file shrank");
            goto done;
        }
        got += (size_t)n;
    }
    size_t used = 0;
    char detail[512] = "";
    rc = proto_decode(b, len, PROTO_MAX_FRAME, m, &used, detail, sizeof detail);
    if (rc == PROTO_NEED_MORE) {
        rc = errbuf_set(err, errsz, PROTO_ETRUNCATED, "%s: file ends inside the frame (%zu bytes)",
                        path, len);
    } else if (rc < 0) {
        errbuf_set(err, errsz, rc, "%s: %s", path, detail);
    } else if (used != len) {
        rc = errbuf_set(err, errsz, PROTO_ETRAILING, "%s: %zu bytes after the frame",
                        path, len - used);
    } else if (m->type != type) {
        rc = errbuf_set(err, errsz, PROTO_EUNEXPECTED, "%s: holds a %s message, not %s",
                        path, proto_type_name(m->type), proto_type_name(type));
    }
done:
    close(fd);
    if (rc) {
        proto_msg_free(m);
        free(b);
        return rc;
    }
    *buf = b;
    return 0;
}

static int write_all(int fd, const uint8_t *p, size_t n)
{
    while (n) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return -1;
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

int wrk_frame_write(const char *dir, const char *name, const proto_msg *m, char *err, size_t errsz)
{
    proto_buf b;
    proto_buf_init(&b);
    char detail[512] = "";
    int rc = proto_msg_encode(&b, m, detail, sizeof detail);
    if (rc) {
        errbuf_set(err, errsz, rc, "%s: cannot encode: %s", name, detail);
        proto_buf_free(&b);
        return rc;
    }
    char tmp[4096], dst[4096];
    snprintf(tmp, sizeof tmp, "%s/%s.tmp", dir, name);
    snprintf(dst, sizeof dst, "%s/%s", dir, name);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
        rc = errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: cannot create: %s", tmp, strerror(errno));
        goto done;
    }
    if (write_all(fd, b.data, b.len) != 0 || fsync(fd) != 0) {
        rc = errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: write failed: %s", tmp, strerror(errno));
        close(fd);
        unlink(tmp);
        goto done;
    }
    if (close(fd) != 0 || rename(tmp, dst) != 0) {
        rc = errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: cannot finish: %s", dst, strerror(errno));
        unlink(tmp);
        goto done;
    }
    int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd < 0 || fsync(dfd) != 0) {    /* not durable: take it back, all or nothing */
        rc = errbuf_set(err, errsz, PROTO_ESTORAGE, "%s: cannot sync the directory: %s", dir,
                        strerror(errno));
        unlink(dst);
    }
    if (dfd >= 0)
        close(dfd);
done:
    proto_buf_free(&b);
    return rc;
}
