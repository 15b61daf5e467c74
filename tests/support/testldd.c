/* testldd.c — see testldd.h. */
#include "support/testldd.h"
#include "support/harness.h"
#include "support/testrun.h"

#include <string.h>

static const char *const allowed[] = {"linux-vdso.so.", "libc.so.", "libm.so.", "libdraco.so.",
                                      "libstdc++.so.", "libgcc_s.so.", "/lib64/ld-linux", "ld-linux"};

/* GnuTLS and what Debian's libgnutls30 links. */
static const char *const tls[] = {"libgnutls.so.", "libp11-kit.so.", "libidn2.so.", "libunistring.so.",
                                  "libtasn1.so.", "libnettle.so.", "libhogweed.so.", "libgmp.so.", "libffi.so."};

static int listed(const char *line, const char *const *names, size_t n)
{
    for (size_t k = 0; k < n; k++)
        if (!strncmp(line, names[k], strlen(names[k])))
            return 1;
    return 0;
}

/* 1 when line starts with one of the blank-separated prefixes of also. */
static int also_has(const char *also, const char *line)
{
    for (const char *p = also; p && *p;) {
        size_t n = strcspn(p, " ");
        if (n && strncmp(line, p, n) == 0)
            return 1;
        p += n;
        p += strspn(p, " ");
    }
    return 0;
}

static void check(const char *path, const char *also, int with_tls)
{
    static char out[1 << 14];
    int rc = testrunf(out, sizeof out, "ldd '%s' 2>&1", path);
    if (rc != 0)
        FAILF("ldd %s exited %d:\n%s", path, rc, out);
    int n = 0;
    for (char *line = strtok(out, "\n"); line; line = strtok(NULL, "\n")) {
        line += strspn(line, " \t");
        if (strstr(line, "not found"))
            FAILF("ldd %s: %s", path, line);
        if (!listed(line, allowed, sizeof allowed / sizeof *allowed) &&
            !(with_tls && listed(line, tls, sizeof tls / sizeof *tls)) && !also_has(also, line))
            FAILF("ldd %s lists %s: only libc, libm, libdraco and the C++ runtime%s%s%s may be linked", path,
                  line, with_tls ? ", GnuTLS and its libraries" : "", also ? " and " : "", also ? also : "");
        n++;
    }
    CHECK(n >= 3);                          /* libc, libdraco, the loader at least */
}

void testldd_check_slim(const char *path)
{
    check(path, NULL, 1);
}

void testldd_check_slim_and(const char *path, const char *also)
{
    check(path, also, 0);
}
