/* adapt_hostile.c -- adaptation's preconditioner scales on a hostile level map.
 *
 * sn_adapt.c scales() sums, per level-1 source vertex, the lumped masses of
 * the inactive detail vertices that fold into it (P^T m). On a baked lattice
 * a source takes at most 26 of them; a blob the validator accepts may map
 * every level-1 vertex into one level-0 cell (LEVEL_UP only needs a cell
 * index and coordinates in range) with every mass at its limit 2^27. This
 * program does that to cow_adapt.blob for each level-0 cell in turn (all
 * detail vertices near the cell's corner 0, masses 2^27), validates it
 * (built without the checksum) and turns level 1 and adaptation on and
 * steps: linked against the ASan + UBSan runtime objects with
 * -fno-sanitize-recover, a signed overflow aborts it. The scales' int32 sum
 * overflowed at cell 28 before it saturated (2147287424 + 4193920). Checks:
 * each patched blob is accepted (else the test proves nothing) and steps.
 * Fixed flavour (the sum is an int32 there; float's stays below 2^43).
 *   usage: test_runtime_adapt_hostile [BLOB]   (default $BUILD/level/cow_adapt.blob)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sn_test.h"
#include "sn_internal.h"

int main(int argc, char **argv) {
    char path[512];
    const char *bd = getenv("BUILD");
    size_t nb = 0;
    unsigned char *orig, *raw;
    const sn_blob *b;
    sn_view top, f;
    uint32_t c, nC, i, k, tried = 0, accepted = 0, moved = 0;
    (void)t_seed; /* deterministic: no random inputs */
    if (argc > 1) snprintf(path, sizeof path, "%s", argv[1]);
    else snprintf(path, sizeof path, "%s/level/cow_adapt.blob", bd ? bd : "build");
    orig = t_read_file(path, &nb);
    if (!orig || sn_blob_validate(orig, nb, &b) != SN_OK) { T_CHECK(0, "cannot read or validate %s", path); return T_END(); }
    sn_view_init(&top, b);
    sn_view_init(&f, (const sn_blob *)(const void *)top.sec[SN_SEC_LEVEL_BLOB]);
    nC = top.nC;
    raw = malloc(nb + 8);
    for (c = 0; c < nC && raw; c++) {
        size_t n;
        void *mem;
        sn_instance *inst;
        sn_stats st;
        unsigned char *up, *ml;
        memcpy(raw, orig, nb);
        up = raw + (top.sec[SN_SEC_LEVEL_UP] - orig);
        ml = raw + (f.sec[SN_SEC_MLUMP] - orig);
        for (i = 0; i < f.nF; i++) {
            unsigned char *e = up + (size_t)i * SN_ELEM_LEVEL_MAP;
            int32_t m = (int32_t)1 << 27;
            if (sn_rd_u16(e + 2) % 32768u || sn_rd_u16(e + 4) % 32768u || sn_rd_u16(e + 6) % 32768u) { /* a detail vertex */
                e[0] = (unsigned char)(c & 255u); e[1] = (unsigned char)(c >> 8);
                for (k = 1; k < 4; k++) { e[2 * k] = 1; e[2 * k + 1] = 0; } /* t = 1/32768: corner 0's weight ~ 1 */
                moved++;
            }
            memcpy(ml + (size_t)i * SN_REAL_BYTES, &m, 4);
        }
        tried++;
        if (sn_blob_validate(raw, nb, &b) != SN_OK) continue;
        accepted++;
        n = sn_instance_size(b);
        mem = malloc(n);
        if (!mem || sn_instance_init(mem, n, b, &inst) != SN_OK) { T_CHECK(0, "cell %u: init", c); free(mem); continue; }
        (void)sn_set_lod(inst, 1);
        (void)sn_set_adapt(inst, 1);
        for (i = 0; i < 3; i++) sn_step(inst);
        sn_get_stats(inst, &st);
        T_CHECK(st.steps == 3, "cell %u: 3 steps (%u)", c, st.steps);
        free(mem);
    }
    printf("  figure: %u level-0 cells tried, %u patched blobs accepted, %u detail vertices moved per blob\n", tried, accepted,
           tried ? moved / tried : 0);
    T_CHECK(accepted == tried && tried > 0, "every patched blob accepted (%u of %u): the map and masses are in range", accepted, tried);
    free(raw); free(orig);
    return T_END();
}
