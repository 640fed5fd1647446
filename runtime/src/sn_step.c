/* sn_step.c -- one step (runtime/NUMERICS.md "One step"): the stages in
 * order. The linearized backward Euler of seed 000 §4.2 with the skeleton
 * eliminated (seed 000 eq. 17-18) and the skeletal warping of seed 003 §3.3
 * applied per cell as an element energy (conservative; K~ = sum R S R^T is
 * its exact Jacobian).
 *
 * Every loop is bounded by blob counts or the iteration count: the cost of a
 * step is known before it runs.
 */
#include "sn_blended.h"
#include "sn_adapt.h"

sn_status sn_step(sn_instance *inst) {
    sn_ihdr *h;
    uint32_t sat = 0;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    sn_frames(h, &sat);
    sn_skeleton(h, &sat);
    sn_crease_step(h, &sat);
    if (h->mode == SN_MODE_BLENDED) sn_blended_solve(h, &sat); /* seed 000 §4.5 (sn_blended.c) */
    else sn_solve(h, &sat);
    sn_limits(h, &sat);
    sn_adapt_step(h, &sat); /* level 1's active set for the next step (seed 000 §4.7, sn_adapt.c) */
    sn_segments_step(h, &sat);
    sn_forces_clear(h);
    sn_health(h, sat);
    h->saturations = sn_count(h->saturations, sat);
    h->steps = sn_count(h->steps, 1);
    return SN_OK;
}
