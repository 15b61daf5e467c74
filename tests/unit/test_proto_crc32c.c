/* test_proto_crc32c.c — CRC32C against the standard check value and the
 * iSCSI (RFC 3720 B.4) vectors; continuation equals one pass. */
#include "support/harness.h"
#include "proto.h"

#include <string.h>

TEST(crc32c_check_value_of_123456789)
{
    CHECK_INT(proto_crc32c(0, "123456789", 9), 0xE3069283u);
}

TEST(crc32c_of_nothing_is_zero_and_keeps_running_value)
{
    CHECK_INT(proto_crc32c(0, "", 0), 0);
    CHECK_INT(proto_crc32c(0x12345678u, NULL, 0), 0x12345678u);
}

TEST(crc32c_matches_rfc3720_vectors)
{
    uint8_t b[32];
    memset(b, 0, sizeof b);
    CHECK_INT(proto_crc32c(0, b, 32), 0x8A9136AAu);
    memset(b, 0xFF, sizeof b);
    CHECK_INT(proto_crc32c(0, b, 32), 0x62A8AB43u);
    for (int i = 0; i < 32; i++)
        b[i] = (uint8_t)i;
    CHECK_INT(proto_crc32c(0, b, 32), 0x46DD794Eu);
    for (int i = 0; i < 32; i++)
        b[i] = (uint8_t)(31 - i);
    CHECK_INT(proto_crc32c(0, b, 32), 0x113FDB5Cu);
}

TEST(crc32c_in_pieces_equals_one_pass)
{
    uint8_t b[1000];
    for (int i = 0; i < 1000; i++)
        b[i] = (uint8_t)(i * 31 + 7);
    uint32_t whole = proto_crc32c(0, b, sizeof b);
    for (size_t cut = 0; cut <= sizeof b; cut += 37)
        CHECK_INT(proto_crc32c(proto_crc32c(0, b, cut), b + cut, sizeof b - cut), whole);
}

TEST(crc32c_detects_every_single_bit_flip)
{
    uint8_t b[64];
    for (int i = 0; i < 64; i++)
        b[i] = (uint8_t)(i ^ 0x5A);
    uint32_t ref = proto_crc32c(0, b, sizeof b);
    for (int bit = 0; bit < 64 * 8; bit++) {
        b[bit / 8] ^= (uint8_t)(1u << bit % 8);
        CHECK(proto_crc32c(0, b, sizeof b) != ref);
        b[bit / 8] ^= (uint8_t)(1u << bit % 8);
    }
}
