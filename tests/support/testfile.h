/* testfile.h — writing test input files: bytes into a named file in this
 * test's temporary directory. Test code only. */
#ifndef TESTFILE_H
#define TESTFILE_H
#include <stddef.h>

/* Writes len bytes to harness_tmpdir()/name; returns the path (static buffer,
 * overwritten by the next call). Fails the test when it cannot write. */
const char *testfile_write(const char *name, const void *data, size_t len);
/* The same for a NUL-terminated text. */
const char *testfile_text(const char *name, const char *text);
/* Reads a whole file into a malloc()ed buffer (*len bytes); fails the test
 * when it cannot. */
unsigned char *testfile_read(const char *path, size_t *len);

#endif
