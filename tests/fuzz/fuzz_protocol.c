/* fuzz_protocol.c — the protocol decoder against hostile bytes. A bounded,
 * deterministic mutation loop over valid frames of every type (byte flips,
 * truncations, length-field edits, random bytes, spliced frames): decoding
 * must return READY, NEED_MORE or a known error code, never crash or read
 * outside the buffer (each input sits in its own exactly-sized allocation
 * so ASan/valgrind catch an overread), and anything it accepts must encode
 * again. Built with -DFUZZ_LIBFUZZER (clang -fsanitize=fuzzer, without the
 * harness) it is a libFuzzer target instead. */
#include "support/protosample.h"
#include "proto.h"

#include <stdlib.h>
#include <string.h>

/* Decodes data[0..n) from a private copy; returns the code. */
static int decode_one(const uint8_t *data, size_t n)
{
    uint8_t *copy = malloc(n ? n : 1);
    if (!copy)
        abort();
    memcpy(copy, data, n);
    proto_msg m;
    size_t used;
    char err[256];
    int rc = proto_decode(copy, n, 0, &m, &used, err, sizeof err);
    if (rc == PROTO_READY) {
        proto_buf b;
        proto_buf_init(&b);
        if (used > n || proto_msg_encode(&b, &m, err, sizeof err) != 0)
            abort();  /* accepted a frame it cannot write back */
        proto_buf_free(&b);
        proto_msg_free(&m);
    } else if (rc != PROTO_NEED_MORE && strcmp(proto_err_name(rc), "UNKNOWN") == 0) {
        abort();
    }
    free(copy);
    return rc;
}

/* Rewrites the header CRC so mutations reach the payload decoder. */
static void fix_header(uint8_t *f, size_t n)
{
    if (n >= PROTO_HDR_SIZE)
        proto_set_le32(f + 16, proto_crc32c(0, f, 16));
}

#ifdef FUZZ_LIBFUZZER
/* As given, and again with the header CRC made valid (else a mutation
 * rarely gets past the header). */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
    decode_one(data, n);
    if (n >= PROTO_HDR_SIZE && n <= 1u << 20) {
        uint8_t *f = malloc(n);
        if (!f)
            abort();
        memcpy(f, data, n);
        fix_header(f, n);
        decode_one(f, n);
        free(f);
    }
    return 0;
}
#else
#include "support/harness.h"

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static uint32_t next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 32);
}

static proto_buf seeds[2 * PROTO_MSG_LAST];
static int nseeds;

static void make_seeds(void)
{
    for (int v = 0; v < 2; v++)
        for (int t = 1; t <= PROTO_MSG_LAST; t++) {
            proto_msg m;
            protosample_fill(t, v, &m);
            proto_buf_init(&seeds[nseeds]);
            CHECK_INT(proto_msg_encode(&seeds[nseeds], &m, NULL, 0), 0);
            nseeds++;
        }
}

/* One mutant of seed s into out (capacity cap); returns its length. */
static size_t mutate(const proto_buf *s, uint8_t *out, size_t cap)
{
    size_t n = s->len < cap ? s->len : cap;
    memcpy(out, s->data, n);
    int fix = next() % 4 != 0;   /* mostly keep the header valid */
    switch (next() % 6) {
    case 0:                      /* flip 1..8 random bits */
        for (uint32_t k = 1 + next() % 8; k--;) {
            size_t i = next() % n;
            out[i] ^= (uint8_t)(1u << next() % 8);
        }
        break;
    case 1:                      /* truncate */
        n = next() % (n + 1);
        break;
    case 2: {                    /* set a u32 in the payload (counts, lengths) */
        static const uint32_t vals[] = { 0, 1, 2, 255, 65535, 65536, 65537, 0x7FFFFFFFu,
                                         0x80000000u, 0xFFFFFFFFu, PROTO_MAX_STRING + 1 };
        if (n >= PROTO_HDR_SIZE + 4) {
            size_t i = PROTO_HDR_SIZE + next() % (n - PROTO_HDR_SIZE - 3);
            proto_set_le32(out + i, vals[next() % (sizeof vals / sizeof vals[0])]);
        }
        break;
    }
    case 3:                      /* the payload length field */
        proto_set_le32(out + 12, next() % 2 ? next() : (uint32_t)(n - PROTO_HDR_SIZE) + next() % 9 - 4);
        break;
    case 4:                      /* a run of random bytes */
        for (size_t i = next() % n, k = 1 + next() % 64; i < n && k--; i++)
            out[i] = (uint8_t)next();
        break;
    default:                     /* garbage appended inside the frame */
        if (n + 16 <= cap) {
            for (int k = 0; k < 16; k++)
                out[n + (size_t)k] = (uint8_t)next();
            proto_set_le32(out + 12, (uint32_t)(n + 16 - PROTO_HDR_SIZE));
            n += 16;
        }
        break;
    }
    if (fix)
        fix_header(out, n);
    return n;
}

TEST_T(fuzz_mutated_frames_of_every_type_decode_safely, 60)
{
    make_seeds();
    size_t cap = 0;
    for (int i = 0; i < nseeds; i++)
        cap = seeds[i].len > cap ? seeds[i].len : cap;
    cap += 16;
    uint8_t *buf = malloc(cap);
    CHECK(buf);
    long counts[3] = { 0 };   /* ready, need more, refused */
    for (int round = 0; round < 300000; round++) {
        const proto_buf *s = &seeds[next() % (uint32_t)nseeds];
        size_t n = mutate(s, buf, cap);
        int rc = decode_one(buf, n);
        counts[rc == PROTO_READY ? 0 : rc == PROTO_NEED_MORE ? 1 : 2]++;
    }
    printf("  ready %ld, need more %ld, refused %ld\n", counts[0], counts[1], counts[2]);
    CHECK(counts[2] > 150000);   /* the mutations do reach the refusals */
    CHECK(counts[0] > 1000);     /* and some still decode (e.g. flipped floats) */
    free(buf);
}

TEST_T(fuzz_random_bytes_behind_a_valid_header_decode_safely, 60)
{
    uint8_t buf[PROTO_HDR_SIZE + 256];
    long refused = 0;
    for (int round = 0; round < 100000; round++) {
        size_t len = next() % 257;
        proto_hdr h = { PROTO_VERSION, (uint8_t)(1 + next() % PROTO_MSG_LAST), 0, next(), (uint32_t)len };
        proto_frame_put_header(buf, &h);
        for (size_t i = 0; i < len; i++)
            buf[PROTO_HDR_SIZE + i] = (uint8_t)(next() % 4 ? next() % 4 : next());
        refused += decode_one(buf, PROTO_HDR_SIZE + len) < 0;
    }
    CHECK(refused > 0);
}

TEST_T(fuzz_random_bytes_without_a_header_are_refused_or_wait, 60)
{
    uint8_t buf[64];
    for (int round = 0; round < 100000; round++) {
        size_t len = next() % sizeof buf;
        for (size_t i = 0; i < len; i++)
            buf[i] = (uint8_t)next();
        if (len >= 4 && memcmp(buf, "MCRP", 4) != 0)
            CHECK_INT(decode_one(buf, len), PROTO_EBAD_MAGIC);
        else
            decode_one(buf, len);
    }
}
#endif
