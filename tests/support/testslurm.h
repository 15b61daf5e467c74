/* testslurm.h — a private single-node Slurm for the Slurm backend's tests and
 * benchmark. A test binary calls testslurm_enter() first thing (from a
 * constructor): it re-executes the binary inside a new pid + network + mount
 * namespace under tests/slurm/run-in-slurm.sh, which starts munged,
 * slurmctld and slurmd under a temporary directory (loopback only), runs the
 * binary's tests there one after the other against that one Slurm, and stops
 * Slurm in bounded time. Where the namespace cannot be made or Slurm is not
 * installed, the binary runs as is and testslurm_need() SKIPs with the
 * reason. Test code only. */
#ifndef TESTSLURM_H
#define TESTSLURM_H
#include <stdint.h>
#include "support/testdaemon.h"

/* Re-executes argv inside the namespace (does not return) unless already
 * inside or impossible (then records why and returns). */
void testslurm_enter(int argc, char **argv);
/* SKIPs (no namespace / Slurm) or FAILs (Slurm did not start) the test
 * unless the private Slurm is up. */
void testslurm_need(void);
/* Starts meshcorrd with the slurm backend (1 CPU per job, 300 ms polls,
 * progress on 127.0.0.1) plus args (NULL-terminated, or NULL). */
void testslurm_daemon(testdaemon *d, const char *name, const char *const *args);
/* The Slurm jobs (any state) named meshcorr-<tag>-<id> of daemon d's state
 * directory (the tag is read from its log), -1 when squeue fails. */
int testslurm_count(const testdaemon *d, uint64_t id);
/* Slurm's state of job id of daemon d ("" when not listed) into buf. */
const char *testslurm_state(const testdaemon *d, uint64_t id, char *buf, size_t sz);

#endif
