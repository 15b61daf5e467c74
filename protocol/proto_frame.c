/* proto_frame.c — the 20-byte frame header: writing it, and scanning the
 * start of a receive buffer incrementally ("need more", "ready", or an
 * error). The declared length is checked against the limit here, before any
 * caller allocates for the payload. Never allocates, no I/O. */
#include "proto.h"
#include "proto_int.h"

void proto_frame_put_header(uint8_t out[PROTO_HDR_SIZE], const proto_hdr *h)
{
    proto_set_le32(out, PROTO_MAGIC);
    out[4] = h->version;
    out[5] = h->type;
    out[6] = (uint8_t)h->flags;
    out[7] = (uint8_t)(h->flags >> 8);
    proto_set_le32(out + 8, h->request_id);
    proto_set_le32(out + 12, h->payload_len);
    proto_set_le32(out + 16, proto_crc32c(0, out, 16));
}

int proto_frame_scan(const void *buf, size_t len, size_t max_frame,
                     proto_hdr *hdr, char *err, size_t errsz)
{
    const uint8_t *p = buf;
    static const uint8_t magic[4] = { 'M', 'C', 'R', 'P' };
    for (size_t i = 0; i < 4 && i < len; i++)
        if (p[i] != magic[i])
            return proto__errf(err, errsz, PROTO_EBAD_MAGIC,
                               "byte %zu of the frame is 0x%02x, not the magic \"MCRP\"", i, p[i]);
    if (len < PROTO_HDR_SIZE)
        return PROTO_NEED_MORE;

    uint32_t crc = proto_crc32c(0, p, 16);
    if (crc != proto_le32(p + 16))
        return proto__errf(err, errsz, PROTO_EBAD_CHECKSUM,
                           "frame header CRC32C is 0x%08x, computed 0x%08x", proto_le32(p + 16), crc);
    hdr->version = p[4];
    hdr->type = p[5];
    hdr->flags = proto_le16(p + 6);
    hdr->request_id = proto_le32(p + 8);
    hdr->payload_len = proto_le32(p + 12);
    if (hdr->version != PROTO_VERSION)
        return proto__errf(err, errsz, PROTO_EBAD_VERSION,
                           "frame has protocol version %u, this side speaks %u",
                           hdr->version, PROTO_VERSION);
    if (!proto_type_name(hdr->type))
        return proto__errf(err, errsz, PROTO_EBAD_TYPE, "unknown message type %u", hdr->type);
    if (hdr->flags != 0)
        return proto__errf(err, errsz, PROTO_EBAD_FRAME,
                           "frame flags 0x%04x set; version %u defines none", hdr->flags, PROTO_VERSION);
    if (max_frame == 0 || max_frame > PROTO_MAX_FRAME)
        max_frame = PROTO_MAX_FRAME;
    uint64_t total = (uint64_t)PROTO_HDR_SIZE + hdr->payload_len;
    if (total > max_frame)
        return proto__errf(err, errsz, PROTO_ETOO_LARGE,
                           "frame of %llu bytes over the maximum of %zu (PROTO_MAX_FRAME %u)",
                           (unsigned long long)total, max_frame, PROTO_MAX_FRAME);
    if (len - PROTO_HDR_SIZE < hdr->payload_len)
        return PROTO_NEED_MORE;
    return PROTO_READY;
}
