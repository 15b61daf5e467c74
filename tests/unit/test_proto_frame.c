/* test_proto_frame.c — frame header scanning: refusals with their codes,
 * the length checked before any allocation, and the incremental decoder fed
 * one byte at a time. malloc is interposed here to count allocations. */
#include "support/harness.h"
#include "support/protosample.h"
#include "proto.h"

#include <stdio.h>
#include <string.h>

/* Counting allocator (glibc's __libc_* entry points underneath). */
void *__libc_malloc(size_t);
void *__libc_calloc(size_t, size_t);
void *__libc_realloc(void *, size_t);
static long nalloc, fail_at = -1;  /* the allocation numbered fail_at fails */
void *malloc(size_t n) { nalloc++; return __libc_malloc(n); }
void *calloc(size_t k, size_t n) { return ++nalloc == fail_at ? NULL : __libc_calloc(k, n); }
void *realloc(void *p, size_t n) { nalloc++; return __libc_realloc(p, n); }

static void header(uint8_t out[PROTO_HDR_SIZE], uint8_t version, uint8_t type,
                   uint16_t flags, uint32_t len)
{
    proto_hdr h = { version, type, flags, 7, len };
    proto_frame_put_header(out, &h);
}

TEST(frame_header_round_trips_every_field)
{
    uint8_t b[PROTO_HDR_SIZE];
    proto_hdr h = { PROTO_VERSION, PROTO_MSG_PING, 0, 0xA1B2C3D4u, 0 }, g;
    proto_frame_put_header(b, &h);
    CHECK(memcmp(b, "MCRP", 4) == 0);
    CHECK_INT(proto_frame_scan(b, sizeof b, 0, &g, NULL, 0), PROTO_READY);
    CHECK_INT(g.version, PROTO_VERSION);
    CHECK_INT(g.type, PROTO_MSG_PING);
    CHECK_INT(g.request_id, 0xA1B2C3D4u);
    CHECK_INT(g.payload_len, 0);
    CHECK_INT(b[8], 0xD4);  /* little-endian on the wire */
}

TEST(frame_refuses_bad_magic_from_the_first_byte)
{
    char err[256] = "";
    proto_hdr h;
    CHECK_INT(proto_frame_scan("G", 1, 0, &h, err, sizeof err), PROTO_EBAD_MAGIC);
    CHECK_STR_HAS(err, "magic");
    CHECK_INT(proto_frame_scan("MCRX", 4, 0, &h, NULL, 0), PROTO_EBAD_MAGIC);
    CHECK_INT(proto_frame_scan("MC", 2, 0, &h, NULL, 0), PROTO_NEED_MORE);
    CHECK_INT(proto_frame_scan("", 0, 0, &h, NULL, 0), PROTO_NEED_MORE);
    /* an HTTP request on the port is refused at once */
    CHECK_INT(proto_frame_scan("GET / HTTP/1.1\r\n\r\n", 18, 0, &h, NULL, 0), PROTO_EBAD_MAGIC);
}

TEST(frame_refuses_bad_version_with_valid_crc)
{
    char err[256] = "";
    uint8_t b[PROTO_HDR_SIZE];
    proto_hdr h;
    header(b, PROTO_VERSION + 1, PROTO_MSG_PING, 0, 0);
    CHECK_INT(proto_frame_scan(b, sizeof b, 0, &h, err, sizeof err), PROTO_EBAD_VERSION);
    char want[64];
    snprintf(want, sizeof want, "version %d", PROTO_VERSION + 1);
    CHECK_STR_HAS(err, want);
    header(b, 0, PROTO_MSG_PING, 0, 0);
    CHECK_INT(proto_frame_scan(b, sizeof b, 0, &h, NULL, 0), PROTO_EBAD_VERSION);
}

TEST(frame_refuses_header_with_bad_crc)
{
    uint8_t b[PROTO_HDR_SIZE];
    proto_hdr h;
    header(b, PROTO_VERSION, PROTO_MSG_PING, 0, 0);
    b[12] ^= 1;   /* payload length changed in transit */
    CHECK_INT(proto_frame_scan(b, sizeof b, 0, &h, NULL, 0), PROTO_EBAD_CHECKSUM);
}

TEST(frame_refuses_unknown_type_and_flags)
{
    uint8_t b[PROTO_HDR_SIZE];
    proto_hdr h;
    char err[256] = "";
    header(b, PROTO_VERSION, 0, 0, 0);
    CHECK_INT(proto_frame_scan(b, sizeof b, 0, &h, NULL, 0), PROTO_EBAD_TYPE);
    header(b, PROTO_VERSION, PROTO_MSG_LAST + 1, 0, 0);
    CHECK_INT(proto_frame_scan(b, sizeof b, 0, &h, err, sizeof err), PROTO_EBAD_TYPE);
    CHECK_STR_HAS(err, "22");
    header(b, PROTO_VERSION, PROTO_MSG_PING, 0x8000, 0);
    CHECK_INT(proto_frame_scan(b, sizeof b, 0, &h, NULL, 0), PROTO_EBAD_FRAME);
}

TEST(frame_announcing_4gib_is_refused_before_any_allocation)
{
    char err[256] = "";
    uint8_t b[PROTO_HDR_SIZE];
    proto_msg m;
    size_t used = 1;
    header(b, PROTO_VERSION, PROTO_MSG_SUBMIT, 0, 0xFFFFFFFFu);
    long before = nalloc;
    CHECK_INT(proto_decode(b, sizeof b, 0, &m, &used, err, sizeof err), PROTO_ETOO_LARGE);
    CHECK_INT(nalloc - before, 0);
    CHECK_INT(used, 0);
    CHECK_STR_HAS(err, "4294967315");
    /* the daemon's configured limit applies below the hard cap ... */
    header(b, PROTO_VERSION, PROTO_MSG_SUBMIT, 0, 2u << 20);
    CHECK_INT(proto_decode(b, sizeof b, 1u << 20, &m, &used, NULL, 0), PROTO_ETOO_LARGE);
    CHECK_INT(proto_decode(b, sizeof b, 4u << 20, &m, &used, NULL, 0), PROTO_NEED_MORE);
    /* ... and a configured limit above the hard cap does not raise it */
    header(b, PROTO_VERSION, PROTO_MSG_SUBMIT, 0, PROTO_MAX_FRAME - PROTO_HDR_SIZE + 1);
    CHECK_INT(proto_decode(b, sizeof b, (size_t)8 << 30, &m, &used, NULL, 0), PROTO_ETOO_LARGE);
    header(b, PROTO_VERSION, PROTO_MSG_SUBMIT, 0, PROTO_MAX_FRAME - PROTO_HDR_SIZE);
    CHECK_INT(proto_decode(b, sizeof b, 0, &m, &used, NULL, 0), PROTO_NEED_MORE);
    CHECK_INT(nalloc - before, 0);
}

TEST(frame_scan_reports_length_once_header_is_in)
{
    uint8_t b[PROTO_HDR_SIZE + 3];
    proto_hdr h = { 0 };
    header(b, PROTO_VERSION, PROTO_MSG_PING, 0, 3);
    CHECK_INT(proto_frame_scan(b, PROTO_HDR_SIZE - 1, 0, &h, NULL, 0), PROTO_NEED_MORE);
    CHECK_INT(proto_frame_scan(b, PROTO_HDR_SIZE, 0, &h, NULL, 0), PROTO_NEED_MORE);
    CHECK_INT(h.payload_len, 3);
    CHECK_INT(proto_frame_scan(b, sizeof b, 0, &h, NULL, 0), PROTO_READY);
}

/* Every sample frame, both variants, in one stream. */
static void encode_all(proto_buf *b, proto_msg *msgs, int *n)
{
    char err[256];
    *n = 0;
    for (int v = 0; v < 2; v++)
        for (int t = 1; t <= PROTO_MSG_LAST; t++) {
            protosample_fill(t, v, &msgs[*n]);
            if (proto_msg_encode(b, &msgs[*n], err, sizeof err) != 0)
                FAILF("encoding %s: %s", proto_type_name(t), err);
            ++*n;
        }
}

TEST(incremental_decoder_fed_one_byte_at_a_time_yields_same_frames)
{
    proto_buf stream, rx;
    proto_msg msgs[2 * PROTO_MSG_LAST];
    int n;
    proto_buf_init(&stream);
    proto_buf_init(&rx);
    encode_all(&stream, msgs, &n);
    int got = 0;
    for (size_t i = 0; i < stream.len; i++) {
        proto_buf_put(&rx, stream.data + i, 1);
        proto_msg m;
        size_t used;
        char err[256] = "";
        int rc = proto_decode(rx.data, rx.len, 0, &m, &used, err, sizeof err);
        if (rc == PROTO_NEED_MORE)
            continue;
        if (rc != PROTO_READY)
            FAILF("frame %d: %s: %s", got, proto_err_name(rc), err);
        CHECK(got < n);
        CHECK_INT(used, rx.len);
        const char *d = protosample_diff(&msgs[got], &m);
        if (d)
            FAILF("frame %d (%s) differs in %s", got, proto_type_name(m.type), d);
        proto_msg_free(&m);
        proto_buf_consume(&rx, used);
        got++;
    }
    CHECK_INT(got, n);
    CHECK_INT(rx.len, 0);
    proto_buf_free(&stream);
    proto_buf_free(&rx);
}

TEST(decoder_takes_frames_one_after_another_from_one_buffer)
{
    proto_buf stream;
    proto_msg msgs[2 * PROTO_MSG_LAST];
    int n;
    proto_buf_init(&stream);
    encode_all(&stream, msgs, &n);
    size_t at = 0;
    for (int i = 0; i < n; i++) {
        proto_msg m;
        size_t used;
        CHECK_INT(proto_decode(stream.data + at, stream.len - at, 0, &m, &used, NULL, 0), PROTO_READY);
        CHECK(protosample_diff(&msgs[i], &m) == NULL);
        proto_msg_free(&m);
        at += used;
    }
    CHECK_INT(at, stream.len);
    proto_buf_free(&stream);
}

TEST(decoder_out_of_memory_at_each_allocation_reports_nomem)
{
    proto_buf b;
    proto_msg in, m;
    size_t used;
    int failures = 0;
    proto_buf_init(&b);
    for (int t = PROTO_MSG_SUBMIT; t <= PROTO_MSG_STATS_OK; t += PROTO_MSG_STATS_OK - PROTO_MSG_SUBMIT) {
        protosample_fill(t, 0, &in);
        proto_buf_reset(&b);
        CHECK_INT(proto_msg_encode(&b, &in, NULL, 0), 0);
        for (long k = 1;; k++) {
            fail_at = nalloc + k;
            int rc = proto_decode(b.data, b.len, 0, &m, &used, NULL, 0);
            fail_at = -1;
            if (rc == PROTO_READY) {
                CHECK(protosample_diff(&in, &m) == NULL);
                proto_msg_free(&m);
                break;
            }
            CHECK_INT(rc, PROTO_ENOMEM);
            CHECK_INT(m.type, 0);
            failures++;
        }
    }
    CHECK_INT(failures, 3 + 2);   /* SUBMIT: landmarks, P, Q; STATS_OK: slots, devices */
    proto_buf_free(&b);
}
