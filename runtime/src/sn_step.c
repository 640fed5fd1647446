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
#include "sn_detail.h"

static void step(sn_ihdr *h) {
    uint32_t sat = 0;
    sn_frames(h, &sat);
    sn_skeleton(h, &sat);
    sn_crease_step(h, &sat);
    if (h->mode == SN_MODE_BLENDED && !h->v.cut) sn_blended_solve(h, &sat); /* seed 000 §4.5 (sn_blended.c); the cut level steps warped */
    else sn_solve(h, &sat);
    sn_limits(h, &sat);
    sn_adapt_step(h, &sat); /* level 1's active set for the next step (seed 000 §4.7, sn_adapt.c) */
    sn_detail_adapt_step(h); /* the cut level's active details for the next step (stage 3, sn_detail_adapt.c) */
    sn_segments_step(h, &sat);
    sn_forces_clear(h);
    sn_health(h, sat);
    h->saturations = sn_count(h->saturations, sat);
    h->steps = sn_count(h->steps, 1);
}

sn_status sn_step(sn_instance *inst) {
    sn_ihdr *h;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    if (h->v.flags & SN_VIEW_SHARED) return SN_ERR_MEMORY; /* its scratch is the caller's: sn_step_with */
    step(h); /* the scratch arrays inside the instance */
    return SN_OK;
}

sn_status sn_step_with(sn_instance *inst, void *workspace, size_t bytes) {
    sn_ihdr *h;
    size_t need;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    if (!(h->v.flags & SN_VIEW_SHARED)) return sn_step(inst); /* sn_instance_init's: its own scratch */
    if (!workspace) return SN_ERR_NULL;
    if (((uintptr_t)workspace & 7u) != 0) return SN_ERR_ALIGN;
    need = sn_blend_offset(h);
    if (h->mode == SN_MODE_BLENDED) { /* sized for the larger level, as sn_workspace_size */
        sn_view t;
        uint32_t nV, nF, nC;
        sn_view_init(&t, (const sn_blob *)(const void *)h->lod_base);
        sn_level_counts(&t, &nV, &nF, &nC);
        need += sn_blended_bytes(nF, nC);
    }
    if (bytes < need) return SN_ERR_MEMORY;
    {   /* the workspace's address for the step's duration (sn_ws), then none:
         * between calls the instance holds no pointer to memory it does not own */
        unsigned char *ws = (unsigned char *)workspace, *none = NULL;
        memcpy((unsigned char *)h + SN_WS_SLOT, &ws, sizeof ws);
        step(h);
        memcpy((unsigned char *)h + SN_WS_SLOT, &none, sizeof none);
    }
    return SN_OK;
}
