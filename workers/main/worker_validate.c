/* worker_validate.c — `meshcorr-worker --validate`: the daemon's check of a
 * SUBMIT before it answers SUBMIT_OK (PROTOCOL.md, SUBMIT). Reads one SUBMIT
 * frame from a descriptor, builds the job exactly as a run would
 * (wrk_job_from_submit: the parameters by the one validator, both meshes
 * decoded by Draco and checked by corr_validate, the landmarks against the
 * decoded vertex counts, the maps' rows) and runs nothing. The daemon starts
 * it as a short-lived process under memory and CPU-time limits, so that
 * Draco (which throws and aborts on malformed input) never runs inside the
 * daemon. */
#include "main/worker.h"
#include "util/errbuf.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Reads exactly n bytes; 0, or -1 at EOF or on error. */
static int read_all(int fd, void *buf, size_t n)
{
    size_t got = 0;
    while (got < n) {
        ssize_t r = read(fd, (char *)buf + got, n - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            return -1;
        got += (size_t)r;
    }
    return 0;
}

static int write_error(int fd, int code, const char *msg)
{
    proto_msg m;
    memset(&m, 0, sizeof m);
    m.type = PROTO_MSG_ERROR;
    m.u.error.code = code;
    char text[PROTO_MAX_STRING + 1];
    size_t n = strlen(msg);
    if (n > PROTO_MAX_STRING) {              /* cut on a UTF-8 character boundary */
        n = PROTO_MAX_STRING;
        while (n && ((unsigned char)msg[n] & 0xC0) == 0x80)
            n--;
    }
    memcpy(text, msg, n);
    text[n] = '\0';
    m.u.error.message = text;
    proto_buf b;
    proto_buf_init(&b);
    int rc = proto_msg_encode(&b, &m, NULL, 0);
    for (size_t off = 0; rc == 0 && off < b.len;) {
        ssize_t w = write(fd, b.data + off, b.len - off);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            rc = -1;
        else
            off += (size_t)w;
    }
    proto_buf_free(&b);
    return rc;
}

int wrk_validate(int in_fd, int out_fd, const wrk_limits *lim)
{
    uint8_t hdr_bytes[PROTO_HDR_SIZE];
    unsigned char *frame = NULL;
    proto_msg m;
    proto_hdr h;
    wrk_job job;
    char err[4096] = "";
    int rc;
    memset(&m, 0, sizeof m);
    memset(&job, 0, sizeof job);
    if (read_all(in_fd, hdr_bytes, sizeof hdr_bytes)) {
        rc = errbuf_set(err, sizeof err, PROTO_ETRUNCATED, "no SUBMIT frame on the input");
        goto done;
    }
    rc = proto_frame_scan(hdr_bytes, sizeof hdr_bytes, PROTO_MAX_FRAME, &h, err, sizeof err);
    if (rc < 0)
        goto done;
    if (!(frame = malloc(PROTO_HDR_SIZE + (size_t)h.payload_len))) {
        rc = errbuf_set(err, sizeof err, PROTO_ENOMEM, "out of memory for a %u-byte SUBMIT",
                        h.payload_len);
        goto done;
    }
    memcpy(frame, hdr_bytes, sizeof hdr_bytes);
    if (read_all(in_fd, frame + PROTO_HDR_SIZE, h.payload_len)) {
        rc = errbuf_set(err, sizeof err, PROTO_ETRUNCATED, "the input ends inside the SUBMIT frame");
        goto done;
    }
    if ((rc = proto_msg_decode(&h, frame + PROTO_HDR_SIZE, &m, err, sizeof err)))
        goto done;
    if (m.type != PROTO_MSG_SUBMIT) {
        rc = errbuf_set(err, sizeof err, PROTO_EUNEXPECTED, "a %s frame, not SUBMIT",
                        proto_type_name(m.type));
        goto done;
    }
    rc = wrk_job_from_submit(&m.u.submit, lim, &job, err, sizeof err);
done:
    wrk_job_close(&job);
    proto_msg_free(&m);
    free(frame);
    if (rc == 0)
        return SPOOL_EXIT_OK;
    if (write_error(out_fd, rc, err))
        fprintf(stderr, "meshcorr-worker --validate: %s: %s (and the answer could not be written)\n",
                proto_err_name(rc), err);
    return SPOOL_EXIT_JOB;
}
