/* sb_force.c -- external-force share profiles (seed 004 ch. 4 on the
 * lattice): which part of an applied force each level takes. Placeholder. */
#include "sb.h"
#include <stdlib.h>

int sb_force_build(const sb_desc *d, sb_model *o) {
    (void)d;
    o->max_forces = 8; o->nprof = 0; o->prof = NULL; o->vprof = NULL;
    return 0;
}
void sb_force_free(sb_model *o) {
    free(o->prof); free(o->vprof);
    o->prof = NULL; o->vprof = NULL; o->nprof = 0;
}
