/* testldd.h — what a shared object links: fails the test when `ldd PATH`
 * lists a library beyond libc, libm, libdraco, the C++ runtime (libstdc++,
 * libgcc_s), the dynamic loader and the vdso, or one it cannot find (the
 * slim libmeshcorr a laptop installs: no engine library). Test code only. */
#ifndef TESTLDD_H
#define TESTLDD_H
/* libmeshcorr: GnuTLS (its tls: addresses) and the libraries GnuTLS loads
 * are allowed too. */
void testldd_check_slim(const char *path);
/* The list above without GnuTLS, and more libraries allowed: their names'
 * prefixes separated by blanks ("libgomp.so. libseccomp.so."). */
void testldd_check_slim_and(const char *path, const char *also);
#endif
