/* level_util.h -- what the level tests share (test_runtime_level.c,
 * test_runtime_adapt.c): the flavour's real <-> double conversions and a blob
 * loader (with 8 spare bytes, so a short read never overruns). */
#ifndef SN_LEVEL_UTIL_H
#define SN_LEVEL_UTIL_H
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#if defined(SN_FLOAT)
#define D(x) ((double)(x))
#define R(x) ((float)(x))
#define FL "float"
#else
#define D(x) ((double)(x) / 65536.0)
#define R(x) ((int32_t)floor((x) * 65536.0 + 0.5))
#define FL "fixed"
#endif

static unsigned char *load(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    unsigned char *p;
    long sz;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END); sz = ftell(f); fseek(f, 0, SEEK_SET);
    p = malloc((size_t)sz + 8);
    if (p && fread(p, 1, (size_t)sz, f) != (size_t)sz) { free(p); p = NULL; }
    fclose(f);
    *n = (size_t)sz;
    return p;
}

#endif
