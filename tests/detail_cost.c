/* detail_cost.c -- what the details would add to a step, measured before the
 * step calls them (runtime/LEVELS.md §3 "Details on the cut level"): REPS
 * passes of stage 2's per-cell kernels over every cell with every detail
 * active, as the mat-vec would run them (stiffness without the extras'
 * columns, then the mass). Run under callgrind with REPS 0 and 20: the
 * difference / 20 is one mat-vec's detail share.
 *
 *   usage: detail_cost DETAILS.blob REPS   (tests/level.mk: build/tests/detail_cost)
 */
#include "sinew.h"
#include "sn_instance.h"
#include "sn_detail.h"
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    FILE *f;
    long n;
    unsigned char *b;
    const sn_blob *blob = NULL;
    sn_view v;
    uint32_t e, rep, reps, j, sat = 0;
    sn_q yc[24], yd[SN_CUT_MAXX][3];
    sn_acc lc[24], ld[3 * SN_CUT_MAXX], mc[24], md[3 * SN_CUT_MAXX];
    volatile sn_acc sink = 0;
    if (argc != 3 || !(f = fopen(argv[1], "rb"))) { fprintf(stderr, "usage: detail_cost DETAILS.blob REPS\n"); return 2; }
    fseek(f, 0, SEEK_END); n = ftell(f); fseek(f, 0, SEEK_SET);
    b = malloc((size_t)n);
    if (!b || fread(b, 1, (size_t)n, f) != (size_t)n || sn_blob_validate(b, (size_t)n, &blob) != SN_OK) { fprintf(stderr, "bad blob\n"); return 1; }
    fclose(f);
    sn_view_init(&v, blob);
    if (sn_level_sec_count(&v, SN_SEC_CELLD) == 0) { fprintf(stderr, "no details\n"); return 1; }
    reps = (uint32_t)atoi(argv[2]);
    for (j = 0; j < 24; j++) yc[j] = (sn_q)(j + 1);
    for (j = 0; j < 3 * SN_CUT_MAXX; j++) yd[j / 3][j % 3] = (sn_q)(j + 7);
    for (rep = 0; rep < reps; rep++)
        for (e = 0; e < v.nC; e++) {
            for (j = 0; j < 24; j++) lc[j] = mc[j] = 0;
            sn_detail_cell_mul(&v, e, 0x7FFFFu, yc, NULL, (const sn_q(*)[3])yd, lc, ld, &sat);
            sn_detail_cell_mass(&v, e, 0x7FFFFu, yc, NULL, (const sn_q(*)[3])yd, mc, md);
            sink += lc[0] + ld[0] + mc[0] + md[0];
        }
    printf("detail_cost: %u cells, %u passes, %u clamps\n", v.nC, reps, sat);
    free(b);
    return 0;
}
