/* proto_crc32c.c — CRC32C (Castagnoli, reflected polynomial 0x82F63B78),
 * byte-at-a-time table lookup. The table is a compile-time constant built by
 * the macros below, so there is no initialisation and no mutable state.
 * Must not allocate or depend on the CPU (no SSE4.2 path). */
#include "proto.h"

#define CRC_POLY 0x82F63B78u
#define CRC_R(c) (((c) >> 1) ^ (((c) & 1u) ? CRC_POLY : 0u))
#define CRC_T(n) CRC_R(CRC_R(CRC_R(CRC_R(CRC_R(CRC_R(CRC_R(CRC_R((uint32_t)(n)))))))))
#define CRC_T4(n)   CRC_T(n), CRC_T((n) + 1), CRC_T((n) + 2), CRC_T((n) + 3)
#define CRC_T16(n)  CRC_T4(n), CRC_T4((n) + 4), CRC_T4((n) + 8), CRC_T4((n) + 12)
#define CRC_T64(n)  CRC_T16(n), CRC_T16((n) + 16), CRC_T16((n) + 32), CRC_T16((n) + 48)

static const uint32_t crc_table[256] = {
    CRC_T64(0), CRC_T64(64), CRC_T64(128), CRC_T64(192)
};

uint32_t proto_crc32c(uint32_t crc, const void *data, size_t n)
{
    const uint8_t *p = data;
    crc = ~crc;
    for (size_t i = 0; i < n; i++)
        crc = crc_table[(crc ^ p[i]) & 0xFFu] ^ (crc >> 8);
    return ~crc;
}
