/* sb_util.c -- error message, allocation, CRC-32, clock. */
#include "sb.h"
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static char sb_err_[2048];

const char *sb_error(void) { return sb_err_; }

int sb_fail(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(sb_err_, sizeof sb_err_, fmt, ap);
    va_end(ap);
    return -1;
}

void *sb_alloc(size_t n)
{
    void *p = calloc(n ? n : 1, 1);
    if (!p) { fprintf(stderr, "sinew-bake: out of memory\n"); exit(2); }
    return p;
}

/* CRC-32 as in zlib/PNG: reflected polynomial 0xEDB88320, init and final xor ~0. */
uint32_t sb_crc32(const unsigned char *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    size_t i;
    int k;
    for (i = 0; i < n; i++) {
        c ^= p[i];
        for (k = 0; k < 8; k++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return c ^ 0xFFFFFFFFu;
}

double sb_now(void) { return (double)clock() / (double)CLOCKS_PER_SEC; }
