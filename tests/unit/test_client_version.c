/* test_client_version.c — one version for the project: mc_version() is the
 * top-level VERSION file ("MAJOR.MINOR.PATCH"), and `make install-lib`
 * writes the same into meshcorr.pc. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testrun.h"
#include "meshcorr.h"

#include <stdio.h>
#include <string.h>

TEST(mc_version_is_the_version_file)
{
    char *v = (char *)testfile_read("VERSION", &(size_t){0});
    v[strcspn(v, "\n")] = '\0';
    unsigned a, b, c;
    char end;
    CHECK_INT(sscanf(v, "%u.%u.%u%c", &a, &b, &c, &end), 3);
    CHECK_INT(strcmp(mc_version(), v), 0);
    free(v);
}

TEST_T(installed_pkg_config_file_carries_the_version, 180)
{
    char out[8192], path[800];
    CHECK_INT(testrunf(out, sizeof out, "env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s install-lib "
                       "DESTDIR=%s/dest PREFIX=/opt/mc 2>&1", harness_tmpdir()), 0);
    snprintf(path, sizeof path, "%s/dest/opt/mc/lib/pkgconfig/meshcorr.pc", harness_tmpdir());
    char *pc = (char *)testfile_read(path, &(size_t){0});
    char want[64];
    snprintf(want, sizeof want, "\nVersion: %s\n", mc_version());
    CHECK_STR_HAS(pc, want);
    free(pc);
}
