/* test_stresc.c — the one escaping rule for foreign text in logs and on
 * terminals (workers/util/stresc.h), table-driven: printable ASCII and
 * printable UTF-8 stay, control characters, DEL, C1 controls, bidi and
 * line-separator marks and malformed UTF-8 become \xNN, a backslash is
 * doubled, and the output is always terminated and never cut inside an
 * escape. */
#include "support/harness.h"
#include "util/stresc.h"

#include <string.h>

static const struct { const char *in, *out; } cases[] = {
    {"plain text: a-z 0-9 <3> 'quoted'", "plain text: a-z 0-9 <3> 'quoted'"},
    {"line\n<3>forged", "line\\x0a<3>forged"},
    {"cr\rtab\tesc\x1b[31m", "cr\\x0dtab\\x09esc\\x1b[31m"},
    {"del\x7f", "del\\x7f"},
    {"back\\slash", "back\\\\slash"},
    {"K\xc3\xbche \xe2\x86\x92 Kamel \xf0\x9f\x90\xaa", "K\xc3\xbche \xe2\x86\x92 Kamel \xf0\x9f\x90\xaa"},
    {"c1 \xc2\x9b" "31m", "c1 \\xc2\\x9b" "31m"},                 /* U+009B, CSI */
    {"rlo \xe2\x80\xae" "cba", "rlo \\xe2\\x80\\xae" "cba"},       /* U+202E */
    {"ls \xe2\x80\xa8", "ls \\xe2\\x80\\xa8"},                     /* U+2028 */
    {"lone \xc3", "lone \\xc3"},                                   /* cut short */
    {"overlong \xc0\xaf", "overlong \\xc0\\xaf"},
    {"surrogate \xed\xa0\x80", "surrogate \\xed\\xa0\\x80"},
    {"", ""},
};

TEST(each_kind_of_character_is_kept_or_escaped_by_the_rule)
{
    char out[256];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        stresc(cases[i].in, out, sizeof out);
        if (strcmp(out, cases[i].out) != 0)
            FAILF("case %zu: \"%s\", expected \"%s\"", i, out, cases[i].out);
    }
    CHECK(strcmp(stresc(NULL, out, sizeof out), "") == 0);
    CHECK(strcmp(stresc_n("a\0b", 3, out, sizeof out), "a\\x00b") == 0);
}

TEST(every_byte_value_escapes_to_printable_ascii_within_the_worst_case_size)
{
    char in[256], out[STRESC_SIZE(255)];
    for (int i = 0; i < 255; i++)
        in[i] = (char)(i + 1);
    stresc_n(in, 255, out, sizeof out);
    CHECK(strlen(out) < sizeof out);
    for (const char *p = out; *p; p++)
        CHECK(*p >= 0x20 && *p < 0x7f);
    CHECK(strstr(out, " !\"#") != NULL);             /* printable ASCII kept */
}

TEST(a_short_buffer_is_cut_between_escapes_and_terminated)
{
    char out[7];
    memset(out, 'z', sizeof out);
    stresc("ab\n\ncd", out, sizeof out);
    CHECK(strcmp(out, "ab\\x0a") == 0);              /* the second \x0a does not fit whole */
    char one[1] = {'z'};
    stresc("abc", one, sizeof one);
    CHECK(one[0] == '\0');
}
