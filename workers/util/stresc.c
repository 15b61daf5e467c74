/* stresc.c — see stresc.h. No allocation, no global state. */
#include "util/stresc.h"

#include <stdint.h>
#include <string.h>

/* Length of the well-formed UTF-8 sequence at s[0..n) (2 to 4), with its
 * code point in *cp; 0 when the bytes are not one (overlong, surrogate,
 * above U+10FFFF, cut short). */
static size_t utf8_seq(const unsigned char *s, size_t n, uint32_t *cp)
{
    unsigned char c = s[0];
    size_t len;
    uint32_t v, min;
    if (c >= 0xC2 && c <= 0xDF)
        len = 2, v = c & 0x1F, min = 0x80;
    else if (c >= 0xE0 && c <= 0xEF)
        len = 3, v = c & 0x0F, min = 0x800;
    else if (c >= 0xF0 && c <= 0xF4)
        len = 4, v = c & 0x07, min = 0x10000;
    else
        return 0;
    if (len > n)
        return 0;
    for (size_t i = 1; i < len; i++) {
        if ((s[i] & 0xC0) != 0x80)
            return 0;
        v = v << 6 | (s[i] & 0x3F);
    }
    if (v < min || v > 0x10FFFF || (v >= 0xD800 && v <= 0xDFFF))
        return 0;
    *cp = v;
    return len;
}

/* Code points shown escaped although they are well-formed: C1 controls,
 * and the marks that reorder or break the text around them. */
static int hidden(uint32_t cp)
{
    return (cp >= 0x80 && cp <= 0x9F) || cp == 0x200E || cp == 0x200F || (cp >= 0x2028 && cp <= 0x202E) ||
           (cp >= 0x2066 && cp <= 0x2069);
}

int stresc_char(const char *s, size_t n, size_t *len, uint32_t *cp)
{
    const unsigned char *p = (const unsigned char *)s;
    *len = 1;
    *cp = p[0];
    if (p[0] < 0x80)
        return p[0] >= 0x20 && p[0] < 0x7F;
    size_t ulen = utf8_seq(p, n, cp);
    if (!ulen) {
        *cp = p[0];
        return 0;
    }
    *len = ulen;
    return !hidden(*cp);
}

char *stresc_n(const char *s, size_t n, char *out, size_t outsz)
{
    static const char hex[] = "0123456789abcdef";
    if (!out || outsz == 0)
        return out;
    if (!s)
        n = 0;
    size_t o = 0;
    for (size_t i = 0; i < n;) {
        char piece[16];
        size_t plen = 0, take;
        uint32_t cp;
        int shown = stresc_char(s + i, n - i, &take, &cp);
        if (s[i] == '\\') {
            piece[plen++] = '\\';
            piece[plen++] = '\\';
        } else if (shown) {
            memcpy(piece, s + i, take);
            plen = take;
        } else {
            for (size_t k = 0; k < take; k++) {          /* a hidden mark: each of its bytes */
                unsigned char b = (unsigned char)s[i + k];
                piece[plen++] = '\\';
                piece[plen++] = 'x';
                piece[plen++] = hex[b >> 4];
                piece[plen++] = hex[b & 15];
            }
        }
        if (o + plen >= outsz)
            break;
        memcpy(out + o, piece, plen);
        o += plen;
        i += take;
    }
    out[o] = '\0';
    return out;
}

char *stresc(const char *s, char *out, size_t outsz)
{
    return stresc_n(s, s ? strlen(s) : 0, out, outsz);
}
