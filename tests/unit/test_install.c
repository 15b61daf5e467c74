/* test_install.c — `make install` into a folder of one's own: the public
 * headers under include/meshcorr/ (a program builds with <meshcorr.h>
 * through pkg-config and with <meshcorr/meshcorr.h> from the include
 * folder), pkg-config's version the project's, and the documentation in
 * share/doc/meshcorr where the installed unit's Documentation= points. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testrun.h"

#include <string.h>
#include <unistd.h>

static char out[1 << 16];

static const char prog[] =
    "#include HEADER\n"
    "#include <stdio.h>\n"
    "int main(void)\n"
    "{\n"
    "    mc_job_spec s;\n"
    "    mc_job_spec_init(&s);\n"
    "    printf(\"%s %u %d\\n\", MC_DEFAULT_SERVER, s.iterations, PROTO_MIN_LANDMARKS);\n"
    "    return 0;\n"
    "}\n";

TEST_T(install_puts_headers_in_include_meshcorr_and_docs_where_the_unit_points, 240)
{
    char dest[600], root[700], path[1200];
    snprintf(dest, sizeof dest, "%s/dest", harness_tmpdir());
    snprintf(root, sizeof root, "%s/opt/mc", dest);
    int rc = testrunf(out, sizeof out, "env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s install DESTDIR=%s "
                      "PREFIX=/opt/mc 2>&1", dest);
    if (rc)
        FAILF("make install failed (%d):\n%s", rc, out);
    static const char *const files[] = {"include/meshcorr/meshcorr.h", "include/meshcorr/proto_params.h",
                                        "share/doc/meshcorr/README.md", "share/doc/meshcorr/protocol/PROTOCOL.md",
                                        "share/doc/meshcorr/daemon/README.md", "share/doc/meshcorr/daemon/MODBUS.md"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", root, files[i]);
        if (access(path, R_OK) != 0)
            FAILF("make install did not install %s", path);
    }
    snprintf(path, sizeof path, "%s/include/meshcorr.h", root);
    CHECK(access(path, F_OK) != 0);                     /* not loose in include/ */
    /* every file: Documentation= of the installed unit is there */
    snprintf(path, sizeof path, "%s/lib/systemd/system/meshcorrd.service", root);
    char *unit = (char *)testfile_read(path, &(size_t){0});
    char *doc = strstr(unit, "\nDocumentation=");
    CHECK(doc);
    doc += strlen("\nDocumentation=");
    int nfiles = 0;
    for (char *w = strtok(strndup(doc, strcspn(doc, "\n")), " "); w; w = strtok(NULL, " ")) {
        if (strncmp(w, "file:", 5) != 0)
            continue;
        CHECK(strncmp(w + 5, "/opt/mc/share/doc/meshcorr/", 27) == 0);
        snprintf(path, sizeof path, "%s%s", dest, w + 5);
        if (access(path, R_OK) != 0)
            FAILF("the unit's Documentation= names %s, which make install did not put there", w);
        nfiles++;
    }
    CHECK(nfiles >= 1);
    free(unit);
    /* pkg-config: the version of VERSION, and a program built both ways */
    size_t vlen;
    char *version = (char *)testfile_read("VERSION", &vlen);
    version[strcspn(version, "\n")] = '\0';
    CHECK_INT(testrunf(out, sizeof out, "PKG_CONFIG_PATH=%s/lib/pkgconfig PKG_CONFIG_SYSROOT_DIR=%s "
                       "pkg-config --modversion meshcorr", root, dest), 0);
    CHECK_INT(strncmp(out, version, strlen(version)), 0);
    free(version);
    char src[700], bin[700];
    snprintf(src, sizeof src, "%s", testfile_text("prog.c", prog));
    snprintf(bin, sizeof bin, "%s/prog", harness_tmpdir());
    rc = testrunf(out, sizeof out, "PKG_CONFIG_PATH=%s/lib/pkgconfig PKG_CONFIG_SYSROOT_DIR=%s "
                  "cc -std=c11 -Wall -Werror '-DHEADER=<meshcorr.h>' -o %s %s "
                  "$(PKG_CONFIG_PATH=%s/lib/pkgconfig PKG_CONFIG_SYSROOT_DIR=%s pkg-config --cflags meshcorr) "
                  "-L%s/lib -lmeshcorr 2>&1", root, dest, bin, src, root, dest, root);
    if (rc)
        FAILF("building with <meshcorr.h> and pkg-config's Cflags failed:\n%s", out);
    rc = testrunf(out, sizeof out, "cc -std=c11 -Wall -Werror '-DHEADER=<meshcorr/meshcorr.h>' -I%s/include -o %s "
                  "%s -L%s/lib -lmeshcorr 2>&1", root, bin, src, root);
    if (rc)
        FAILF("building with <meshcorr/meshcorr.h> failed:\n%s", out);
    CHECK_INT(testrunf(out, sizeof out, "LD_LIBRARY_PATH=%s/lib %s", root, bin), 0);
    CHECK_STR_HAS(out, "unix:/run/meshcorr/meshcorrd.sock 600 3\n");
}
