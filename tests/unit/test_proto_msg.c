/* test_proto_msg.c — message payloads: round trip of every type (full and
 * minimal), and each decode refusal with its error code. */
#include "support/harness.h"
#include "support/protosample.h"
#include "proto.h"

#include <math.h>
#include <string.h>

static proto_buf frame;   /* the frame under test (zeroed = initialised) */

static void encode(int type, int variant)
{
    char err[256] = "";
    proto_msg m;
    proto_buf_free(&frame);
    protosample_fill(type, variant, &m);
    if (proto_msg_encode(&frame, &m, err, sizeof err) != 0)
        FAILF("encoding %s: %s", proto_type_name(type), err);
}

static uint8_t *payload(void) { return frame.data + PROTO_HDR_SIZE; }

/* Rewrites the header after a payload length change. */
static void set_payload_len(uint32_t len)
{
    proto_hdr h;
    CHECK(proto_frame_scan(frame.data, PROTO_HDR_SIZE, 0, &h, NULL, 0) >= 0);
    h.payload_len = len;
    proto_frame_put_header(frame.data, &h);
    frame.len = PROTO_HDR_SIZE + (size_t)len;
}

/* Decodes the frame under test expecting `code`; err must mention `has`. */
static void expect(int code, const char *has)
{
    char err[256] = "";
    proto_msg m;
    size_t used;
    int rc = proto_decode(frame.data, frame.len, 0, &m, &used, err, sizeof err);
    if (rc != code)
        FAILF("decode gave %s (%s), expected %s", proto_err_name(rc), err, proto_err_name(code));
    if (has)
        CHECK_STR_HAS(err, has);
    proto_msg zero;
    memset(&zero, 0, sizeof zero);
    CHECK(memcmp(&m, &zero, sizeof m) == 0);   /* refused messages are left zeroed */
}

TEST(every_message_type_round_trips_full_and_minimal)
{
    for (int v = 0; v < 2; v++)
        for (int t = 1; t <= PROTO_MSG_LAST; t++) {
            proto_msg in, out;
            size_t used;
            char err[256] = "";
            encode(t, v);
            protosample_fill(t, v, &in);
            CHECK_INT(proto_decode(frame.data, frame.len, 0, &out, &used, err, sizeof err), PROTO_READY);
            CHECK_INT(used, frame.len);
            const char *d = protosample_diff(&in, &out);
            if (d)
                FAILF("%s variant %d differs in %s", proto_type_name(t), v, d);
            proto_msg_free(&out);
            CHECK_INT(out.type, 0);
            proto_buf_free(&frame);
        }
}

TEST(decoded_blobs_and_strings_point_into_the_payload)
{
    proto_msg m;
    size_t used;
    encode(PROTO_MSG_SUBMIT, 0);
    CHECK_INT(proto_decode(frame.data, frame.len, 0, &m, &used, NULL, 0), PROTO_READY);
    const uint8_t *lo = frame.data, *hi = frame.data + frame.len;
    CHECK(m.u.submit.source.data > lo && m.u.submit.source.data < hi);
    CHECK((const uint8_t *)m.u.submit.label > lo && (const uint8_t *)m.u.submit.label < hi);
    CHECK_INT(strlen(m.u.submit.label), PROTO_MAX_STRING);
    CHECK(m.u.submit.landmarks != NULL);
    CHECK((const uint8_t *)m.u.submit.landmarks < lo || (const uint8_t *)m.u.submit.landmarks >= hi);
    proto_msg_free(&m);
}

TEST(free_accepts_null_and_zeroed_messages)
{
    proto_msg m;
    memset(&m, 0, sizeof m);
    proto_msg_free(NULL);
    proto_msg_free(&m);
    proto_msg_free(&m);
    CHECK_INT(m.type, 0);
}

TEST(truncated_payload_is_refused)
{
    encode(PROTO_MSG_SUBMIT, 0);
    set_payload_len((uint32_t)(frame.len - PROTO_HDR_SIZE - 10));
    expect(PROTO_ETRUNCATED, "label");
    encode(PROTO_MSG_PROGRESS, 0);
    set_payload_len((uint32_t)(frame.len - PROTO_HDR_SIZE - 1));
    expect(PROTO_ETRUNCATED, NULL);
}

TEST(count_exceeding_remaining_bytes_is_refused)
{
    proto_msg s;
    protosample_fill(PROTO_MSG_SUBMIT, 0, &s);
    size_t at = 8 + s.u.submit.source.len + 8 + s.u.submit.target.len;  /* landmark count */
    encode(PROTO_MSG_SUBMIT, 0);
    CHECK_INT(proto_le32(payload() + at), 40);
    proto_set_le32(payload() + at, 60000);   /* under the limit, more than is there */
    expect(PROTO_ETRUNCATED, "landmarks count 60000");

    encode(PROTO_MSG_LIST_OK, 0);
    proto_set_le32(payload(), 4000);
    expect(PROTO_ETRUNCATED, "job list count 4000");
}

TEST(count_over_its_limit_is_refused)
{
    proto_msg s;
    protosample_fill(PROTO_MSG_SUBMIT, 0, &s);
    size_t at = 8 + s.u.submit.source.len + 8 + s.u.submit.target.len;
    encode(PROTO_MSG_SUBMIT, 0);
    proto_set_le32(payload() + at, PROTO_MAX_LANDMARKS + 1);
    expect(PROTO_EOVER_LIMIT, "PROTO_MAX_LANDMARKS");

    encode(PROTO_MSG_SUBMIT, 0);
    proto_set_le32(payload(), 0xFFFFFFFFu);     /* source mesh length */
    expect(PROTO_EOVER_LIMIT, "PROTO_MAX_MESH_BYTES");

    encode(PROTO_MSG_STATS_OK, 0);
    proto_set_le32(payload() + 36, PROTO_MAX_SLOTS + 1);
    expect(PROTO_EOVER_LIMIT, "PROTO_MAX_SLOTS");

    encode(PROTO_MSG_HELLO, 1);
    proto_set_le32(payload() + 2, PROTO_MAX_STRING + 1);   /* token length */
    expect(PROTO_EOVER_LIMIT, "PROTO_MAX_STRING");
}

TEST(bad_checksum_on_blob_landmarks_or_map_is_refused)
{
    encode(PROTO_MSG_SUBMIT, 0);
    payload()[8 + 100] ^= 0x10;              /* a byte inside the source mesh */
    expect(PROTO_EBAD_CHECKSUM, "source mesh");

    proto_msg s;
    protosample_fill(PROTO_MSG_SUBMIT, 0, &s);
    size_t lm = 8 + s.u.submit.source.len + 8 + s.u.submit.target.len;
    encode(PROTO_MSG_SUBMIT, 0);
    payload()[lm + 8 + 17] ^= 1;             /* inside the landmarks */
    expect(PROTO_EBAD_CHECKSUM, "landmarks");

    size_t p = lm + 8 + 40 * 8;
    encode(PROTO_MSG_SUBMIT, 0);
    payload()[p + 8 + 28 * 50 + 12] ^= 0x80; /* a weight of row 50 of P */
    expect(PROTO_EBAD_CHECKSUM, "initial map P");

    encode(PROTO_MSG_RESULT_OK, 0);
    payload()[8 + 4] ^= 0xFF;                /* the CRC field of P itself */
    expect(PROTO_EBAD_CHECKSUM, "map P");
}

/* RHM's maps are RESULT_OK's trailing part: without them the payload
 * ends after the metrics, as a reader that does not know them expects;
 * with them it is the same bytes and then the two maps. A RESULT asking
 * for them (what 16) is known; a bit above is not. */
TEST(result_ok_carries_rhm_maps_only_as_a_trailing_part)
{
    proto_msg m;
    protosample_fill(PROTO_MSG_RESULT_OK, 0, &m);
    proto_result_ok *u = &m.u.result_ok;
    proto_map rp = u->rhm_p, rq = u->rhm_q;
    CHECK(rp.n && rq.n);
    u->rhm_p = u->rhm_q = (proto_map){ NULL, 0 };
    proto_buf without, with;
    proto_buf_init(&without);
    proto_buf_init(&with);
    char err[256];
    CHECK_INT(proto_msg_encode(&without, &m, err, sizeof err), 0);
    u->rhm_p = rp;
    u->rhm_q = rq;
    CHECK_INT(proto_msg_encode(&with, &m, err, sizeof err), 0);
    size_t maps = 2 * (4 + 4) + 28 * ((size_t)rp.n + rq.n);  /* count, CRC, rows */
    CHECK_INT(with.len, without.len + maps);
    CHECK(!memcmp(with.data + PROTO_HDR_SIZE, without.data + PROTO_HDR_SIZE,
                  without.len - PROTO_HDR_SIZE));
    proto_msg out;
    size_t used;
    CHECK_INT(proto_decode(without.data, without.len, 0, &out, &used, err, sizeof err), PROTO_READY);
    CHECK(out.u.result_ok.rhm_p.n == 0 && out.u.result_ok.rhm_q.n == 0);
    proto_msg_free(&out);
    proto_buf_free(&without);
    proto_buf_free(&with);

    proto_msg q = { .type = PROTO_MSG_RESULT };
    q.u.result = (proto_result){ 5, PROTO_WANT_P | PROTO_WANT_STAGE_RHM };
    proto_buf_init(&with);
    CHECK_INT(proto_msg_encode(&with, &q, err, sizeof err), 0);
    proto_buf_free(&with);
    q.u.result.what = 32;
    proto_buf_init(&with);
    CHECK_INT(proto_msg_encode(&with, &q, err, sizeof err), PROTO_EBAD_FRAME);
    proto_buf_free(&with);
}

TEST(bad_strings_are_refused)
{
    /* HELLO minimal: u16 version, token (u32 0, NUL), client (u32 0, NUL) */
    static const struct { const char *bytes; size_t n; } bad[] = {
        { "a\0b", 3 },           /* NUL inside */
        { "\xC0\x80", 2 },       /* overlong NUL */
        { "\xED\xA0\x80", 3 },   /* surrogate */
        { "\xF4\x90\x80\x80", 4 }, /* past U+10FFFF */
        { "ab\xE2\x82", 4 },     /* cut multi-byte sequence */
        { "\xFF", 1 },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        proto_buf_init(&frame);
        uint8_t hdr[PROTO_HDR_SIZE] = { 0 };
        proto_buf_put(&frame, hdr, sizeof hdr);
        proto_buf_put_u16(&frame, PROTO_VERSION);
        proto_buf_put_u32(&frame, (uint32_t)bad[i].n);
        proto_buf_put(&frame, bad[i].bytes, bad[i].n);
        proto_buf_put_u8(&frame, 0);
        proto_buf_put_u32(&frame, 0);
        proto_buf_put_u8(&frame, 0);
        proto_hdr h = { PROTO_VERSION, PROTO_MSG_HELLO, 0, 1, (uint32_t)(frame.len - PROTO_HDR_SIZE) };
        proto_frame_put_header(frame.data, &h);
        expect(PROTO_EBAD_STRING, "token");
        proto_buf_free(&frame);
    }
    encode(PROTO_MSG_END, 1);                /* u64 job, u8 state, u32 0, terminator */
    payload()[13] = 'x';                     /* terminator replaced */
    expect(PROTO_EBAD_STRING, "terminator");
}

TEST(unknown_message_type_is_refused)
{
    encode(PROTO_MSG_PING, 0);
    proto_hdr h = { PROTO_VERSION, 200, 0, 1, 0 };
    proto_frame_put_header(frame.data, &h);
    expect(PROTO_EBAD_TYPE, "200");
    proto_hdr g = { PROTO_VERSION, PROTO_MSG_PING, 0, 0, 0 };
    CHECK_INT(proto_msg_decode(&(proto_hdr){ PROTO_VERSION, 0, 0, 0, 0 }, "", &(proto_msg){ 0 }, NULL, 0),
              PROTO_EBAD_TYPE);
    CHECK_INT(proto_msg_decode(&g, "", &(proto_msg){ 0 }, NULL, 0), PROTO_OK);
}

TEST(trailing_garbage_after_a_message_is_refused)
{
    encode(PROTO_MSG_SUBMIT_OK, 0);
    proto_buf_put_u8(&frame, 0xAB);
    set_payload_len(9);
    expect(PROTO_ETRAILING, "1 bytes");
    encode(PROTO_MSG_PING, 0);
    proto_buf_put(&frame, "xyz", 3);
    set_payload_len(3);
    expect(PROTO_ETRAILING, "PING");
}

TEST(out_of_range_enums_and_bits_are_refused)
{
    encode(PROTO_MSG_STATUS_OK, 0);
    payload()[8] = PROTO_STATE_LAST + 1;     /* job state */
    expect(PROTO_EBAD_FRAME, "job state");
    encode(PROTO_MSG_RESULT, 0);
    payload()[8] = 0x20;                     /* unknown `what` bit */
    expect(PROTO_EBAD_FRAME, "what");
    encode(PROTO_MSG_ERROR, 0);
    proto_set_le32(payload(), 5);            /* error codes are negative */
    expect(PROTO_EBAD_FRAME, "not negative");
    encode(PROTO_MSG_LIST, 1);
    payload()[0] = 0x80;                     /* state mask bit 7: no such state */
    expect(PROTO_EBAD_FRAME, "state mask");
}

TEST(encoder_refuses_what_the_decoder_would_and_leaves_buffer_unchanged)
{
    char err[256] = "", big[PROTO_MAX_STRING + 2];
    proto_buf b;
    proto_msg m;
    proto_buf_init(&b);
    protosample_fill(PROTO_MSG_PING, 0, &m);
    CHECK_INT(proto_msg_encode(&b, &m, NULL, 0), 0);
    size_t len = b.len;

    memset(big, 'x', sizeof big - 1);
    big[sizeof big - 1] = 0;
    protosample_fill(PROTO_MSG_HELLO, 0, &m);
    m.u.hello.client = big;
    CHECK_INT(proto_msg_encode(&b, &m, err, sizeof err), PROTO_EOVER_LIMIT);
    CHECK_STR_HAS(err, "client name");
    CHECK_INT(b.len, len);

    m.u.hello.client = "\xC3";
    CHECK_INT(proto_msg_encode(&b, &m, NULL, 0), PROTO_EBAD_STRING);
    protosample_fill(PROTO_MSG_SUBMIT, 0, &m);
    m.u.submit.nlandmarks = PROTO_MAX_LANDMARKS + 1;
    CHECK_INT(proto_msg_encode(&b, &m, NULL, 0), PROTO_EOVER_LIMIT);
    protosample_fill(PROTO_MSG_SUBMIT, 0, &m);
    m.u.submit.params.model = 2;
    CHECK_INT(proto_msg_encode(&b, &m, NULL, 0), PROTO_EBAD_FRAME);
    m.type = 0;
    CHECK_INT(proto_msg_encode(&b, &m, NULL, 0), PROTO_EBAD_TYPE);
    CHECK_INT(b.len, len);
    CHECK_INT(b.err, 0);
    proto_buf_free(&b);
}

TEST(error_names_and_messages_come_from_one_list)
{
    CHECK(strcmp(proto_err_name(PROTO_EBAD_CHECKSUM), "BAD_CHECKSUM") == 0);
    CHECK(strcmp(proto_err_name(PROTO_ESHUTTING_DOWN), "SHUTTING_DOWN") == 0);
    CHECK(strcmp(proto_strerror(PROTO_EQUEUE_FULL), "queue full, job refused") == 0);
    CHECK(strcmp(proto_err_name(-999), "UNKNOWN") == 0);
    CHECK(strcmp(proto_strerror(-999), "unknown error") == 0);
    CHECK(strcmp(proto_type_name(PROTO_MSG_RESULT_OK), "RESULT_OK") == 0);
    CHECK(proto_type_name(0) == NULL);
    CHECK(strcmp(proto_state_name(PROTO_STATE_OUT_OF_MEMORY), "OUT_OF_MEMORY") == 0);
    CHECK(strcmp(proto_stage_name(PROTO_STAGE_RHM), "rhm") == 0);
    CHECK(strcmp(proto_stage_name(PROTO_STAGE_INIT), "init") == 0);
    CHECK(proto_stage_name(PROTO_STAGE_LAST + 1) == NULL);
    CHECK(strcmp(proto_slot_name(PROTO_SLOT_BUSY), "busy") == 0);
    for (int c = 0; c >= PROTO_EOVER_QUOTA; c--)
        CHECK(strcmp(proto_err_name(c), "UNKNOWN") != 0);
}

/* PROGRESS's whole-job fields: a fraction outside [0, 1] or a time left
 * that is negative or infinite is refused both ways (NaN means not known);
 * the stages of version 5 have their names. */
TEST(progress_fraction_and_time_left_are_checked_both_ways)
{
    encode(PROTO_MSG_PROGRESS, 0);
    size_t at = 8 + 1 + 4 + 4 + 2 * (4 + 5 * 8) + 3 * 8;   /* the fraction's offset */
    uint64_t bits;
    double v = 1.5;
    memcpy(&bits, &v, 8);
    for (int k = 0; k < 8; k++)
        payload()[at + k] = (uint8_t)(bits >> (8 * k));
    expect(PROTO_EBAD_FRAME, "fraction 1.5");
    encode(PROTO_MSG_PROGRESS, 0);
    v = -2;
    memcpy(&bits, &v, 8);
    for (int k = 0; k < 8; k++)
        payload()[at + 8 + k] = (uint8_t)(bits >> (8 * k));
    expect(PROTO_EBAD_FRAME, "eta_s -2");

    proto_msg m;
    protosample_fill(PROTO_MSG_PROGRESS, 1, &m);        /* fraction 0, eta_s NaN: fine */
    proto_buf b;
    proto_buf_init(&b);
    CHECK_INT(proto_msg_encode(&b, &m, NULL, 0), 0);
    m.u.progress.fraction = -0.25;
    CHECK_INT(proto_msg_encode(&b, &m, NULL, 0), PROTO_EBAD_FRAME);
    m.u.progress.fraction = 1;
    m.u.progress.eta_s = INFINITY;
    CHECK_INT(proto_msg_encode(&b, &m, NULL, 0), PROTO_EBAD_FRAME);
    proto_buf_free(&b);
    CHECK(strcmp(proto_stage_name(PROTO_STAGE_REPAIR), "repair") == 0);
    CHECK(strcmp(proto_stage_name(PROTO_STAGE_QUEUED), "queued") == 0);
    CHECK_INT(PROTO_VERSION, 6);
}
