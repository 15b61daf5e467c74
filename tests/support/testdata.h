/* testdata.h — the list of every .off file under the shared data folder
 * (harness_data_dir), for tests that check invariants on all real meshes.
 * Test code only. SKIPs the calling test when the folder is absent. */
#ifndef TESTDATA_H
#define TESTDATA_H

/* Sorted absolute-or-relative paths; *n set to their count (0 possible).
 * Caller frees with testdata_free. */
char **testdata_off_files(int *n);
void testdata_free(char **paths, int n);

#endif
