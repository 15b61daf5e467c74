/* testcowcamel.c — see testcowcamel.h. */
#include "support/testcowcamel.h"
#include "support/harness.h"

#include <stdio.h>
#include <stdlib.h>

void testcowcamel_load(mesh **cow, mesh **camel, lmk_set **L)
{
    char cmd[1024], p[512], err[512];
    snprintf(cmd, sizeof cmd, "tar -xzf %s -C %s --strip-components=2 data/meshes/cow.off "
             "data/meshes/camel.off", TESTCOWCAMEL_ARCHIVE, harness_tmpdir());
    if (system(cmd))
        FAILF("%s: cannot extract cow.off and camel.off (package libcgal-demo)",
              TESTCOWCAMEL_ARCHIVE);
    snprintf(p, sizeof p, "%s/cow.off", harness_tmpdir());
    if (mesh_read(p, cow, err, sizeof err))
        FAILF("%s", err);
    snprintf(p, sizeof p, "%s/camel.off", harness_tmpdir());
    if (mesh_read(p, camel, err, sizeof err) ||
        lmk_read_pairs(TESTCOWCAMEL_LANDMARKS, 0, *cow, *camel, L, err, sizeof err))
        FAILF("%s", err);
}
