/* proto_buf.c — the growable output buffer encoders append to, and the
 * little-endian store/load helpers. Growth is checked for overflow; a failed
 * append sets a sticky error and writes nothing. No I/O. */
#include "proto.h"

#include <stdlib.h>
#include <string.h>

void proto_buf_init(proto_buf *b)
{
    b->data = NULL;
    b->len = b->cap = 0;
    b->err = 0;
}

void proto_buf_free(proto_buf *b)
{
    if (!b)
        return;
    free(b->data);
    proto_buf_init(b);
}

void proto_buf_reset(proto_buf *b)
{
    b->len = 0;
    b->err = 0;
}

void proto_buf_consume(proto_buf *b, size_t n)
{
    if (n >= b->len) {
        b->len = 0;
        return;
    }
    memmove(b->data, b->data + n, b->len - n);
    b->len -= n;
}

/* Makes room for n more bytes; 0 or PROTO_ENOMEM (also set in b->err). */
static int buf_room(proto_buf *b, size_t n)
{
    if (b->err)
        return b->err;
    if (n > SIZE_MAX - b->len)
        return b->err = PROTO_ENOMEM;
    size_t need = b->len + n;
    if (need <= b->cap)
        return 0;
    size_t cap = b->cap ? b->cap : 256;
    while (cap < need)
        cap = cap > SIZE_MAX / 2 ? need : cap * 2;
    uint8_t *d = realloc(b->data, cap);
    if (!d)
        return b->err = PROTO_ENOMEM;
    b->data = d;
    b->cap = cap;
    return 0;
}

void proto_buf_put(proto_buf *b, const void *p, size_t n)
{
    if (n == 0 || buf_room(b, n))
        return;
    memcpy(b->data + b->len, p, n);
    b->len += n;
}

void proto_buf_put_u8(proto_buf *b, uint8_t v)
{
    proto_buf_put(b, &v, 1);
}

void proto_buf_put_u16(proto_buf *b, uint16_t v)
{
    uint8_t t[2] = { (uint8_t)v, (uint8_t)(v >> 8) };
    proto_buf_put(b, t, 2);
}

void proto_buf_put_u32(proto_buf *b, uint32_t v)
{
    uint8_t t[4];
    proto_set_le32(t, v);
    proto_buf_put(b, t, 4);
}

void proto_buf_put_u64(proto_buf *b, uint64_t v)
{
    uint8_t t[8];
    proto_set_le32(t, (uint32_t)v);
    proto_set_le32(t + 4, (uint32_t)(v >> 32));
    proto_buf_put(b, t, 8);
}

uint16_t proto_le16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

uint32_t proto_le32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

uint64_t proto_le64(const uint8_t *p)
{
    return (uint64_t)proto_le32(p) | (uint64_t)proto_le32(p + 4) << 32;
}

void proto_set_le32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}
