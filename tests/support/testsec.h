/* testsec.h — what the security tests of a testdaemon measure and feed
 * it: jobs on icosphere pairs of a chosen size (their SUBMIT frames and
 * results as large as a test needs), the bytes a job holds in the spool,
 * and the daemon's resident memory. Test code only; failures fail the
 * test. */
#ifndef TESTSEC_H
#define TESTSEC_H
#include <stdint.h>
#include "meshcorr.h"
#include "support/testdaemon.h"

/* Submits a job on an icosphere pair of this level (level 6: 40962
 * vertices, a SUBMIT of about a megabyte), target bent as in
 * testdaemon_pair, 6 landmarks, stages (MC_STAGES_*), iterations outer
 * iterations and 3 RHM iterations; the code in *rc, the job id returned. */
uint64_t testsec_submit_sphere(mc_client *c, int level, int stages, int iterations, int *rc);
/* The Draco bytes of the level's icosphere (what a SUBMIT of it carries). */
size_t testsec_sphere_bytes(int level);
/* Bytes of the files in spool/<id>/ of d's state (0: no such directory). */
long long testsec_spool_bytes(const testdaemon *d, uint64_t id);
/* 1 when spool/<id>/name exists in d's state. */
int testsec_spool_has(const testdaemon *d, uint64_t id, const char *name);
/* The daemon's resident memory now, bytes (VmRSS). */
long long testsec_daemon_rss(const testdaemon *d);

#endif
