/* test_runtime_range.c -- the range-checking build's checks fire (issue 16
 * item 9): sn_internal.h's SN_RANGE asserts the bounds NUMERICS.md derives
 * for every rounding shift and accumulator conversion. The hook records
 * instead of aborting, so each broken bound can be seen to be caught and
 * each valid extreme to pass. (tests/fuzz/range_fail.c, the aborting hook,
 * runs the hostile-blob suite through this build: test_runtime_fuzz_range.) */
#define SN_RANGE_CHECK 1
#include "sn_test.h"
#include "sn_internal.h"

static int g_fails;
static const char *g_what;
void sn_range_fail(const char *what, const char *file, int line, long long value);
void sn_range_fail(const char *what, const char *file, int line, long long value) {
    (void)file; (void)line; (void)value;
    g_fails++;
    g_what = what;
}

static int fires(int before) { return g_fails > before; }

int main(void) {
    uint32_t sat = 0;
    int n;
    (void)t_seed;
    n = g_fails; (void)sn_rshr64(1, 62);
    T_CHECK(!fires(n), "shift by 62 is within the bound");
    n = g_fails; (void)sn_rshr64(1, 63);
    T_CHECK(fires(n), "shift by 63 caught (the frac_P + k = 72 shift of issue 16 would be): %s", g_what ? g_what : "-");
    n = g_fails; (void)sn_rshr64((int64_t)1 << 62, 62);
    T_CHECK(!fires(n), "2^62 rounded by 62: no overflow");
    n = g_fails; (void)sn_rshr64(INT64_MAX - 5, 4);
    T_CHECK(fires(n), "a rounding add past INT64_MAX caught");
    n = g_fails; (void)sn_out((int64_t)1 << 62, 30, &sat);
    T_CHECK(!fires(n), "an accumulator of 2^62 converts");
    n = g_fails; (void)sn_out(INT64_MAX / 2 * 2 - 1, 30, &sat);
    T_CHECK(fires(n), "an accumulator beyond 2^62.5 caught before sn_out rounds it");
    T_CHECK(SN_WITHIN((int64_t)1 << 60, 60) && !SN_WITHIN(((int64_t)1 << 60) + 1, 60) && SN_WITHIN(-((int64_t)1 << 60), 60),
            "SN_WITHIN is |x| <= 2^b");
    return T_END();
}
