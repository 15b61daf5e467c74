/* stresc.h — one escaping rule for text that came from someone else (a
 * client's name, a job label, a user name, a server's message) before it
 * reaches a log line or a terminal: nothing in the result can start a new
 * log line, move the cursor, change colours or reorder what is shown.
 *
 * Kept as they are: printable ASCII and well-formed UTF-8 of printable
 * characters. Written as \xNN, byte by byte: control characters (newline,
 * carriage return, ESC, ...), DEL, C1 controls (U+0080..U+009F), the
 * bidirectional and line/paragraph separator marks (U+200E, U+200F,
 * U+2028..U+202E, U+2066..U+2069) and every byte that is not part of
 * well-formed UTF-8. A backslash is written as \\ so the result reads back
 * unambiguously. */
#ifndef STRESC_H
#define STRESC_H
#include <stddef.h>
#include <stdint.h>

/* Bytes stresc needs for n input bytes in the worst case, terminator included. */
#define STRESC_SIZE(n) (4 * (size_t)(n) + 1)

/* s escaped into out[outsz] (always terminated; cut at a whole escape when
 * it does not fit); returns out. s NULL reads as "". */
char *stresc(const char *s, char *out, size_t outsz);
/* The same for the first n bytes of s (which may hold NUL bytes: \x00). */
char *stresc_n(const char *s, size_t n, char *out, size_t outsz);
/* The character at s[0..n) (n >= 1): its bytes in *len and code point in
 * *cp (a byte that is not well-formed UTF-8: 1, and its value); 1 when
 * stresc shows it as it is, 0 when it escapes it (a backslash is shown,
 * doubled). For other escaping syntaxes (JSON) with the same rule. */
int stresc_char(const char *s, size_t n, size_t *len, uint32_t *cp);

#endif
