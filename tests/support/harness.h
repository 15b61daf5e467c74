/* harness.h — the minimal test harness: tests register themselves, each runs
 * in its own forked process with a timeout, and one line per test says
 * PASS/FAIL/SKIP. tests/run-tests.sh adds the lines up. It must not hide a
 * failure: any signal, timeout, or non-zero exit of a test is a FAIL. */
#ifndef HARNESS_H
#define HARNESS_H

#include <stdio.h>
#include <stdlib.h>
#include <math.h>

typedef void (*harness_fn)(void);
void harness_register(const char *name, harness_fn fn, int timeout_s);

/* TEST(name) { ... } — default timeout 120 s; TEST_T(name, seconds) to change. */
#define TEST_T(name, secs)                                                   \
    static void test_##name(void);                                           \
    __attribute__((constructor)) static void reg_##name(void)                \
    { harness_register(#name, test_##name, (secs)); }                        \
    static void test_##name(void)
#define TEST(name) TEST_T(name, 120)

#define HARNESS_SKIP_CODE 77
/* Ends the test as skipped, with a reason (e.g. data folder absent). */
#define SKIP(...) do { printf("  skipped: "); printf(__VA_ARGS__);           \
                       printf("\n"); fflush(stdout);                          \
                       exit(HARNESS_SKIP_CODE); } while (0)

#define FAILF(...) do { fprintf(stderr, "  %s:%d: ", __FILE__, __LINE__);     \
                        fprintf(stderr, __VA_ARGS__); fprintf(stderr, "\n");  \
                        exit(1); } while (0)
#define CHECK(cond) do { if (!(cond)) FAILF("check failed: %s", #cond); } while (0)
#define CHECK_INT(a, b) do { long long a_ = (long long)(a), b_ = (long long)(b); \
        if (a_ != b_) FAILF("%s == %lld, expected %s == %lld", #a, a_, #b, b_); } while (0)
#define CHECK_NEAR(a, b, tol) do { double a_ = (a), b_ = (b);                 \
        if (!(fabs(a_ - b_) <= (tol)))                                        \
            FAILF("%s = %.17g, expected %.17g within %g", #a, a_, b_, (double)(tol)); } while (0)
#define CHECK_STR_HAS(s, sub) do { const char *s_ = (s);                      \
        if (!s_ || !strstr(s_, (sub)))                                        \
            FAILF("message \"%s\" lacks \"%s\"", s_ ? s_ : "(null)", (sub)); } while (0)

/* Path of the shared real-mesh data folder (../shared/data relative to the
 * repository root, or $MESHCORR_DATA), or NULL when absent. */
const char *harness_data_dir(void);
/* harness_data_path("faust_r/vtx_5k/tr_reg_000.off") -> static buffer, or
 * SKIP()s the test when the data folder is absent. */
const char *harness_data_path(const char *rel);
/* The value of the command-line option --name=VALUE, or NULL when it was
 * not given (benchmarks take their knobs this way; arguments without a
 * leading "--" name the tests to run). */
const char *harness_option(const char *name);
/* 1 when list (an option's value, "a,b,c") is NULL or names item among
 * its comma-separated entries; else 0 (benchmarks' --pairs). */
int harness_list_has(const char *list, const char *item);
/* A fresh temporary directory for this test under /tmp, removed when the test
 * passes (a failing test's stays, to be looked at). */
const char *harness_tmpdir(void);

#endif
