/* testjob.h — job directories for meshcorr-worker tests (ours and the
 * daemon's integration tests): a SUBMIT built from mesh files (encoded with
 * our order-keeping Draco encoder), landmark pairs and/or initial map files
 * and ectm_params, written as DIR/job.frame the way the daemon spools it.
 * Test code only.
 *
 * Ownership: a testjob owns the Draco bytes, landmarks and map rows its msg
 * points at; tests may change msg (a blob length, a parameter) between
 * testjob_build and testjob_save. testjob_close frees everything (NULL ok). */
#ifndef TESTJOB_H
#define TESTJOB_H
#include <stddef.h>
#include "proto.h"
#include "ectm/ectm.h"

typedef struct testjob {
    proto_msg msg;                 /* a SUBMIT */
    unsigned char *src_drc, *tgt_drc;
    proto_landmark *landmarks;
    proto_map_row *p_rows, *q_rows;
} testjob;

/* landmarks: n 0-based (source, target) pairs or NULL; p0/q0: meshcorr-map
 * files or NULL; params: NULL for ectm_params_init (only the fields the wire
 * carries travel: log_eps and threads do not). Returns 0, or -1 with err. */
int testjob_build(testjob *j, const char *src_path, const char *tgt_path,
                  const proto_landmark *landmarks, unsigned nlandmarks, const char *p0_path,
                  const char *q0_path, const ectm_params *params, char *err, size_t errsz);
/* Creates dir if needed and writes dir/job.frame (no .tmp left behind). */
int testjob_save(const testjob *j, const char *dir, char *err, size_t errsz);
void testjob_close(testjob *j);

/* testjob_build + testjob_save + testjob_close. */
int testjob_write(const char *dir, const char *src_path, const char *tgt_path,
                  const proto_landmark *landmarks, unsigned nlandmarks, const char *p0_path,
                  const char *q0_path, const ectm_params *params, char *err, size_t errsz);

#endif
