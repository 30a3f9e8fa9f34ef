/*
 * test.h - the tiny assertion kit shared by the unit tests: CHECK records a
 * failure and goes on, REQUIRE stops the test, SKIP exits with 77 (ctest skip).
 */
#ifndef PK_TEST_H
#define PK_TEST_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <unistd.h>

static int test_failures;

#define CHECK(cond)                                                              \
    do {                                                                         \
        if (!(cond)) {                                                           \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
            test_failures++;                                                     \
        }                                                                        \
    } while (0)

#define CHECKF(cond, ...)                                                        \
    do {                                                                         \
        if (!(cond)) {                                                           \
            fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                        \
            fputc('\n', stderr);                                                 \
            test_failures++;                                                     \
        }                                                                        \
    } while (0)

#define REQUIRE(cond)                                                            \
    do {                                                                         \
        if (!(cond)) {                                                           \
            fprintf(stderr, "%s:%d: REQUIRE failed: %s\n", __FILE__, __LINE__, #cond); \
            exit(1);                                                             \
        }                                                                        \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                    \
    CHECKF(fabs((double)(a) - (double)(b)) <= (tol), "%.9g vs %.9g (tol %g)", (double)(a), (double)(b), (double)(tol))

#define SKIP(...)                                                                \
    do {                                                                         \
        fprintf(stderr, "SKIP: " __VA_ARGS__);                                   \
        fputc('\n', stderr);                                                     \
        exit(77);                                                                \
    } while (0)

static inline int test_done(const char *name)
{
    if (test_failures) {
        fprintf(stderr, "%s: %d check(s) failed\n", name, test_failures);
        return 1;
    }
    printf("%s: ok\n", name);
    return 0;
}

/* Path of a file in ../shared, or SKIP when the shared folder is absent. */
static inline const char *shared_path(char *buf, size_t n, const char *rel)
{
    snprintf(buf, n, "%s/%s", PK_SHARED_DIR, rel);
    if (access(buf, R_OK) != 0) SKIP("%s is not there (../shared is absent)", buf);
    return buf;
}

#endif
