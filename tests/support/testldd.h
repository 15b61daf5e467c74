/* testldd.h — what a shared object links: fails the test when `ldd PATH`
 * lists a library beyond libc, libm, libdraco, the C++ runtime (libstdc++,
 * libgcc_s), the dynamic loader and the vdso, or one it cannot find (the
 * slim libmeshcorr a laptop installs: no engine library). Test code only. */
#ifndef TESTLDD_H
#define TESTLDD_H
void testldd_check_slim(const char *path);
/* The same with more libraries allowed: their names' prefixes separated
 * by blanks ("libgomp.so. libseccomp.so."). */
void testldd_check_slim_and(const char *path, const char *also);
#endif
