/* testcowcamel.h — make demo's pair for tests and benchmarks: cow.off and
 * camel.off from Debian's libcgal-demo archive, extracted into the test's
 * directory (harness_tmpdir), and the demo's landmark pairs
 * (deploy/demo/cow-camel.landmarks: the test runs from the repository's
 * root). Test code only. FAILs the caller when the archive is missing
 * (deploy/install-deps.sh installs libcgal-demo). */
#ifndef TESTCOWCAMEL_H
#define TESTCOWCAMEL_H
#include "lmk/lmk.h"
#include "mesh/mesh.h"

#define TESTCOWCAMEL_ARCHIVE "/usr/share/doc/libcgal-dev/data.tar.gz"
#define TESTCOWCAMEL_LANDMARKS "deploy/demo/cow-camel.landmarks"

void testcowcamel_load(mesh **cow, mesh **camel, lmk_set **L);

#endif
