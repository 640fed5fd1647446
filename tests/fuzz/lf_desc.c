/* lf_desc.c -- libFuzzer harness: the host tool's description reader
 * (tools/sb_desc.c, sb_desc_load; format tools/DESCRIPTION.md), built by
 * tests/fuzz/fuzz.mk as fuzz_desc. sb_desc_load takes a path, so each input
 * is written to a temp file first (lf_common.h). Checks besides the
 * sanitizers: an error leaves a message; a description that loads has the
 * shape the rest of the tool relies on (one root, parents resolved and
 * acyclic, counts within the arrays, every number finite). The mesh is not
 * read (sb_desc_load only resolves its path); lf_obj.c fuzzes the OBJ reader.
 */
#include "lf_common.h" /* first: it sets _POSIX_C_SOURCE */

#include <math.h>
#include "sb.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    sb_desc d;
    const char *path = lf_tmp_write(data, size);
    int i, k, roots = 0;
    if (sb_desc_load(path, &d) != 0) {
        LF_REQUIRE(sb_error() && sb_error()[0], "sb_desc_load failed without a message");
        sb_desc_free(&d);
        return 0;
    }
    LF_REQUIRE(d.nj >= 1 && d.nj <= 255 && d.nm >= 1, "%d joints, %d materials", d.nj, d.nm);
    LF_REQUIRE(d.unit > 0 && isfinite(d.unit) && d.cell > 0 && isfinite(d.cell), "unit %g cell %g", d.unit, d.cell);
    LF_REQUIRE(d.h > 0 && d.h <= 1 && d.cg_def >= 1 && d.cg_def <= d.cg_max && d.cg_max <= 256, "h %g cg %d %d", d.h,
               d.cg_def, d.cg_max);
    LF_REQUIRE(isfinite(d.alpha) && isfinite(d.beta) && d.alpha >= 0 && d.beta >= 0, "rayleigh %g %g", d.alpha, d.beta);
    for (k = 0; k < 3; k++) LF_REQUIRE(isfinite(d.g[k]) && isfinite(d.origin[k]), "gravity/origin not finite");
    for (i = 0; i < d.nj; i++) {
        int p = d.joints[i].parent, steps = 0;
        LF_REQUIRE(p >= -1 && p < d.nj && p != i, "joint %d parent %d", i, p);
        if (p < 0) roots++;
        for (k = 0; k < 3; k++) LF_REQUIRE(isfinite(d.joints[i].pos[k]), "joint %d position not finite", i);
        while (p >= 0 && steps <= d.nj) { p = d.joints[p].parent; steps++; }
        LF_REQUIRE(p < 0, "joint %d is in a parent cycle", i);
        LF_REQUIRE(memchr(d.joints[i].name, 0, SB_NAME_MAX) != NULL, "joint %d name not NUL-terminated", i);
    }
    LF_REQUIRE(roots == 1, "%d roots", roots);
    for (i = 0; i < d.nm; i++)
        LF_REQUIRE(d.mats[i].E > 0 && d.mats[i].rho > 0 && d.mats[i].nu > -1 && d.mats[i].nu < 0.5 &&
                   isfinite(d.mats[i].E) && isfinite(d.mats[i].rho), "material %d", i);
    for (i = 0; i < d.nmr; i++) LF_REQUIRE(d.mrules[i].mat >= 0 && d.mrules[i].mat < d.nm, "region rule %d material", i);
    for (i = 0; i < d.nfr; i++)
        LF_REQUIRE(d.frules[i].j1 >= 0 && d.frules[i].j1 < d.nj && d.frules[i].j2 >= 0 && d.frules[i].j2 < d.nj &&
                   d.frules[i].w >= 0 && d.frules[i].w <= 1, "frame rule %d", i);
    for (i = 0; i < d.npin; i++) LF_REQUIRE(d.pins[i].joint >= 0 && d.pins[i].joint < d.nj, "pin %d joint", i);
    for (i = 0; i < d.nlr; i++) LF_REQUIRE(d.lrules[i].dist >= 0 && isfinite(d.lrules[i].dist), "limit rule %d", i);
    sb_desc_free(&d);
    return 0;
}
