/* blob_patch.c -- set one header real of a blob and fix its CRC-32, for
 * tests that need a blob the host tool would not write but the validator
 * accepts (tests/scripts/test_player_timestep.sh). Offsets from
 * runtime/src/sn_format.h; flavour from the blob (fixed: the value is
 * stored in the field's Q format, float32: as is).
 *   blob_patch IN OUT timestep VALUE      (h, seconds; fixed Q16.16)
 * Exit 0 on success, 2 on bad use. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

#include "sn_format.h"
#include "sb.h" /* sb_crc32: the host tool's CRC-32 (tools/sb_util.c) */

static uint32_t rd32(const unsigned char *p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static void wr32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)v; p[1] = (unsigned char)(v >> 8); p[2] = (unsigned char)(v >> 16); p[3] = (unsigned char)(v >> 24);
}

int main(int argc, char **argv) {
    FILE *f;
    long n;
    unsigned char *b;
    double v;
    uint32_t total, u;
    if (argc != 5 || strcmp(argv[3], "timestep") != 0) {
        fprintf(stderr, "usage: blob_patch IN OUT timestep VALUE\n");
        return 2;
    }
    v = strtod(argv[4], NULL);
    if (!(f = fopen(argv[1], "rb"))) { perror(argv[1]); return 2; }
    fseek(f, 0, SEEK_END); n = ftell(f); fseek(f, 0, SEEK_SET);
    b = malloc((size_t)n);
    if (!b || n < SN_HEADER_BYTES || fread(b, 1, (size_t)n, f) != (size_t)n) { fprintf(stderr, "%s: cannot read a blob\n", argv[1]); return 2; }
    fclose(f);
    if (b[SN_H_FLAVOUR] == SN_FLAVOUR_FLOAT32) {
        float x = (float)v;
        memcpy(&u, &x, 4);
    } else if (b[SN_H_FLAVOUR] == SN_FLAVOUR_FIXED) {
        double q = floor(v * 65536.0 + 0.5);
        if (q < -2147483648.0 || q > 2147483647.0) { fprintf(stderr, "%g s does not fit Q16.16\n", v); return 2; }
        u = (uint32_t)(int32_t)q;
    } else { fprintf(stderr, "%s: flavour %u not supported\n", argv[1], b[SN_H_FLAVOUR]); return 2; }
    wr32(b + SN_H_REALS + 4 * SN_R_TIMESTEP, u);
    total = rd32(b + SN_H_TOTAL_SIZE);
    if (total < 16 || total > (uint32_t)n) { fprintf(stderr, "%s: bad total_size\n", argv[1]); return 2; }
    wr32(b + SN_H_CRC32, sb_crc32(b + 16, total - 16));
    if (!(f = fopen(argv[2], "wb")) || fwrite(b, 1, (size_t)n, f) != (size_t)n) { perror(argv[2]); return 2; }
    fclose(f);
    free(b);
    return 0;
}
