/* web_json.c — JSON text for the web API: strings escaped by the one
 * escaping rule of util/stresc (what a log line would escape is a \u
 * escape here), numbers with null for what JSON cannot spell. */
#include "web.h"
#include "util/stresc.h"

#include <math.h>
#include <string.h>

void web_json_str(FILE *fp, const char *s)
{
    fputc('"', fp);
    size_t n = s ? strlen(s) : 0;
    for (size_t i = 0; i < n;) {
        size_t len;
        uint32_t cp;
        int keep = stresc_char(s + i, n - i, &len, &cp);
        if (s[i] == '"' || s[i] == '\\')
            fprintf(fp, "\\%c", s[i]);
        else if (keep)
            fwrite(s + i, 1, len, fp);
        else
            fprintf(fp, "\\u%04x", (unsigned)(cp & 0xFFFF));
        i += len;
    }
    fputc('"', fp);
}

void web_json_num(FILE *fp, double v)
{
    if (isfinite(v))
        fprintf(fp, "%.17g", v);
    else
        fputs("null", fp);
}
