/* main.c -- the tiny consumer of tests/integration: a program an engine
 * programmer would write, built every way Sinew can be consumed (Makefile
 * library, CMake add_subdirectory, CMake find_package after install,
 * pkg-config, the single-file amalgamation). It steps the cow and prints
 * the state hash, which tests/scripts/test_integration.sh compares across
 * paths and with the determinism driver.
 *   consumer BLOB [STEPS]      (default 200 steps)
 * Prints "flavour: fixed|float" and "hash: <16 hex>". */
#include <stdio.h>
#include <stdlib.h>
#include "sinew.h"
#include "sn_wiggle.h"

#if defined(SINEW_CONSUMER_EXPECT_FLOAT) && !defined(SN_FLOAT)
#error "linked the float runtime but SN_FLOAT did not reach this file (sinew::runtime_float must propagate it)"
#endif
#if !defined(SINEW_CONSUMER_EXPECT_FLOAT) && defined(SN_FLOAT)
#error "SN_FLOAT is defined in a fixed-flavour consumer"
#endif

#define MAX_JOINTS 255

int main(int argc, char **argv) {
    static sn_quat local[MAX_JOINTS];
    static sn_xform xf[MAX_JOINTS];
    const sn_blob *blob;
    sn_blob_info info;
    sn_instance *inst;
    sn_status s;
    FILE *f;
    long n;
    unsigned long steps = argc > 2 ? strtoul(argv[2], NULL, 10) : 200, k;
    void *bytes, *mem;
    char hex[17];
    if (argc < 2) { fprintf(stderr, "usage: consumer BLOB [STEPS]\n"); return 2; }
    /* the blob: whole file in malloc memory (8-byte aligned) */
    f = fopen(argv[1], "rb");
    if (!f || fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) <= 0 || fseek(f, 0, SEEK_SET) != 0) {
        fprintf(stderr, "consumer: cannot read %s\n", argv[1]); return 2;
    }
    bytes = malloc((size_t)n);
    if (!bytes || fread(bytes, 1, (size_t)n, f) != (size_t)n) { fprintf(stderr, "consumer: read failed\n"); return 2; }
    fclose(f);
    s = sn_blob_validate(bytes, (size_t)n, &blob);
    if (s != SN_OK) { fprintf(stderr, "consumer: %s: %s\n", argv[1], sn_status_str(s)); return 1; }
    sn_blob_get_info(blob, &info);
    if (info.joints > MAX_JOINTS) { fprintf(stderr, "consumer: too many joints\n"); return 1; }
    /* the instance: caller-owned memory */
    mem = malloc(sn_instance_size(blob));
    if (!mem) return 2;
    s = sn_instance_init(mem, sn_instance_size(blob), blob, &inst);
    if (s != SN_OK) { fprintf(stderr, "consumer: instance: %s\n", sn_status_str(s)); return 1; }
    for (k = 0; k < steps; k++) {
        sn_wiggle_pose(blob, info.joints, (uint32_t)k, 0, local, xf);
        s = sn_set_pose(inst, xf, info.joints);
        if (s != SN_OK) { fprintf(stderr, "consumer: pose: %s\n", sn_status_str(s)); return 1; }
        sn_step(inst);
    }
    sn_wiggle_hex(sn_state_hash(inst), hex);
    printf("flavour: %s\nsteps: %lu\nhash: %s\n", SN_FLAVOUR ? "float" : "fixed", steps, hex);
    free(mem);
    free(bytes);
    return 0;
}
