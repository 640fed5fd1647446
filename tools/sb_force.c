/* sb_force.c -- external-force share profiles (seed 004 ch. 4 applied to
 * the lattice): which part of an applied force each level takes (fine
 * lattice, coarse regions of 2, 4 and 8 cells, the rigid level returned to
 * the game), per free vertex from the description's 'shares_region' rules
 * at rest positions (later rules override; the first profile elsewhere). */
#include "sb.h"
#include <stdlib.h>
#include <string.h>

int sb_force_build(const sb_desc *d, sb_model *o) {
    int i, k;
    o->max_forces = d->force_slots;
    o->max_cons = d->max_cons;
    o->max_cols = d->max_cols;
    o->max_contacts = d->max_contacts;
    o->nprof = d->nshares;
    o->prof = NULL;
    o->vprof = NULL;
    if (d->nshares == 0) {
        if (d->nsr) return sb_fail("%s: shares_region without a 'shares' profile", d->path);
        return 0;
    }
    o->prof = sb_alloc(sizeof *o->prof * (size_t)d->nshares);
    for (i = 0; i < d->nshares; i++)
        for (k = 0; k < 5; k++) o->prof[i][k] = d->shares[i].s[k];
    o->vprof = sb_alloc((size_t)(o->nf ? o->nf : 1));
    for (i = 0; i < o->nf; i++) {
        o->vprof[i] = 0;
        for (k = 0; k < d->nsr; k++)
            if (sb_region_has(o, &d->srules[k].r, o->x + 3 * i)) o->vprof[i] = (unsigned char)d->srules[k].prof;
    }
    return 0;
}

void sb_force_free(sb_model *o) {
    free(o->prof); free(o->vprof);
    o->prof = NULL; o->vprof = NULL; o->nprof = 0;
}
