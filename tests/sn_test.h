/* sn_test.h -- Sinew's tiny test harness (header-only, plain C99).
 * A test program calls T_CHECK / T_NEAR as often as it likes and ends with
 * `return T_END();`, which prints the closing line "N passed, N failed"
 * that tests/run_tests.sh adds up. Random tests take their seed from
 * T_SEED() (env SN_TEST_SEED or a fixed default) and print it. */
#ifndef SN_TEST_H
#define SN_TEST_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int t_passed_, t_failed_;

/* Count a check; on failure print where and why. */
#define T_CHECK(cond, ...) do { \
    if (cond) { t_passed_++; } else { t_failed_++; \
        printf("FAIL %s:%d: ", __FILE__, __LINE__); printf(__VA_ARGS__); printf("\n"); } \
} while (0)

/* |got - want| <= tol; `why` states the justification of the tolerance. */
#define T_NEAR(got, want, tol, why) do { \
    double g_ = (double)(got), w_ = (double)(want), t_ = (double)(tol); \
    T_CHECK(fabs(g_ - w_) <= t_ && g_ == g_, "%s = %.9g, want %.9g +- %.3g (%s)", #got, g_, w_, t_, why); \
} while (0)

/* Print a figure a human reads in the log (not a check). */
#define T_FIGURE(...) do { printf("  figure: "); printf(__VA_ARGS__); printf("\n"); } while (0)

static unsigned long t_seed(void) {
    const char *s = getenv("SN_TEST_SEED");
    unsigned long v = s ? strtoul(s, NULL, 0) : 12345UL;
    printf("  seed: %lu (set SN_TEST_SEED to change)\n", v);
    return v;
}
#define T_SEED() t_seed()

/* A whole file in malloc'd memory (8 spare bytes), its size in *n; NULL if
 * it cannot be read. */
static inline void *t_read_file(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    char *p;
    long sz;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END); sz = ftell(f); fseek(f, 0, SEEK_SET);
    p = sz < 0 ? NULL : malloc((size_t)sz + 8);
    if (p && fread(p, 1, (size_t)sz, f) != (size_t)sz) { free(p); p = NULL; }
    fclose(f);
    *n = sz < 0 ? 0 : (size_t)sz;
    return p;
}

#define T_END() (printf("%d passed, %d failed\n", t_passed_, t_failed_), t_failed_ != 0)
#endif
