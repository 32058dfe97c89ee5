/* lubkit unit-test harness: one program per module (tests/unit/<module>_test.c).
 *
 *     static void test_something(void) { CHECK(x == 1); CHECK_NEAR(a, b, 1e-12); }
 *     int main(void) { RUN(test_something); return test_summary(); }
 *
 * Each RUN prints "PASS name" or "FAIL name" (with the failed checks above it); tests/run
 * counts those lines over all test programs and case tests.
 * CHECK_FATAL(expr, substring) asserts that expr raises a fatal error whose message contains
 * the substring (used for every bad-input class).
 */
#ifndef LUB_TEST_H
#define LUB_TEST_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"

static int test_failed_checks_ = 0;
static int test_passed_ = 0, test_failed_ = 0;

#define CHECK(cond)                                                                        \
    do {                                                                                   \
        if (!(cond)) {                                                                     \
            printf("  %s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);              \
            test_failed_checks_++;                                                         \
        }                                                                                  \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                              \
    do {                                                                                   \
        double a_ = (a), b_ = (b), t_ = (tol);                                             \
        if (!(fabs(a_ - b_) <= t_)) {                                                      \
            printf("  %s:%d: %s = %.17g, expected %s = %.17g within %g\n", __FILE__,       \
                   __LINE__, #a, a_, #b, b_, t_);                                          \
            test_failed_checks_++;                                                         \
        }                                                                                  \
    } while (0)

/* relative closeness |a-b| <= tol |b| */
#define CHECK_REL(a, b, tol) CHECK_NEAR(a, b, (tol) * fabs((double)(b)))

#define CHECK_STR(s, sub)                                                                  \
    do {                                                                                   \
        const char *s_ = (s), *sub_ = (sub);                                               \
        if (!s_ || !strstr(s_, sub_)) {                                                    \
            printf("  %s:%d: '%s' does not contain '%s'\n", __FILE__, __LINE__,            \
                   s_ ? s_ : "(null)", sub_);                                              \
            test_failed_checks_++;                                                         \
        }                                                                                  \
    } while (0)

/* expr must raise a fatal error whose message contains sub; the message is kept in
 * test_last_error for further checks. */
static char test_last_error[2048] __attribute__((unused));
#define CHECK_FATAL(expr, sub)                                                             \
    do {                                                                                   \
        lub_catcher c_;                                                                    \
        test_last_error[0] = '\0';                                                         \
        if (lub_error_catch(&c_) == 0) {                                                   \
            expr;                                                                          \
            lub_error_uncatch();                                                           \
            printf("  %s:%d: expected a fatal error from %s\n", __FILE__, __LINE__, #expr); \
            test_failed_checks_++;                                                         \
        } else {                                                                           \
            memcpy(test_last_error, c_.message, sizeof test_last_error);                   \
            CHECK_STR(c_.message, sub);                                                    \
        }                                                                                  \
    } while (0)

#define RUN(fn)                                                                            \
    do {                                                                                   \
        test_failed_checks_ = 0;                                                           \
        fn();                                                                              \
        if (test_failed_checks_) {                                                         \
            printf("FAIL %s\n", #fn);                                                      \
            test_failed_++;                                                                \
        } else {                                                                           \
            printf("PASS %s\n", #fn);                                                      \
            test_passed_++;                                                                \
        }                                                                                  \
        fflush(stdout);                                                                    \
    } while (0)

static inline int test_summary(void) { return test_failed_ ? 1 : 0; }

#endif
