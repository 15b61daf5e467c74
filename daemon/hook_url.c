/* hook_url.c — the syntax of a --notify-url URL (http://HOST[:PORT]/PATH),
 * checked when the option is read and again when a note is sent. Apart from
 * hook.c so that the configuration checks it without depending on the
 * delivery threads (which read the job store). */
#include "mcd.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

int hook_url_parse(const char *url, hook_url *out, char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    if (strncmp(url, "http://", 7))
        return errbuf_set(err, errsz, -1, "only http://HOST[:PORT]/PATH URLs (no https)");
    const char *h = url + 7, *end;
    if (*h == '[') {
        end = strchr(h, ']');
        if (!end || end == h + 1)
            return errbuf_set(err, errsz, -1, "an IPv6 host in [ ] has no closing ]");
        if ((size_t)(end - h - 1) >= sizeof out->host)
            return errbuf_set(err, errsz, -1, "host too long");
        memcpy(out->host, h + 1, (size_t)(end - h - 1));
        end++;
    } else {
        end = h + strcspn(h, ":/");
        if (end == h || (size_t)(end - h) >= sizeof out->host)
            return errbuf_set(err, errsz, -1, "no host, or a host too long");
        memcpy(out->host, h, (size_t)(end - h));
    }
    snprintf(out->port, sizeof out->port, "80");
    if (*end == ':') {
        char *pe;
        errno = 0;
        unsigned long p = strtoul(end + 1, &pe, 10);
        if (errno || pe == end + 1 || p == 0 || p > 65535 || (*pe && *pe != '/'))
            return errbuf_set(err, errsz, -1, "the port is not 1..65535");
        snprintf(out->port, sizeof out->port, "%lu", p);
        end = pe;
    }
    if (*end && *end != '/')
        return errbuf_set(err, errsz, -1, "after the host comes :PORT or /PATH");
    if (strlen(*end ? end : "/") >= sizeof out->path)
        return errbuf_set(err, errsz, -1, "path too long");
    for (const char *c = end; *c; c++)
        if ((unsigned char)*c <= ' ' || *c == 0x7f)
            return errbuf_set(err, errsz, -1, "the path holds a blank or a control character");
    snprintf(out->path, sizeof out->path, "%s", *end ? end : "/");
    return 0;
}
