/* range_fail.c -- the hook of the runtime's range-checking build
 * (-DSN_RANGE_CHECK, runtime/src/sn_internal.h): a derived bound was broken,
 * so say which and where, and abort (the test harness reports the crash). */
#include <stdio.h>
#include <stdlib.h>

void sn_range_fail(const char *what, const char *file, int line, long long value);
void sn_range_fail(const char *what, const char *file, int line, long long value) {
    fprintf(stderr, "FAIL: range check: %s at %s:%d (value %lld)\n", what, file, line, value);
    fflush(stderr);
    abort();
}
