/* sn_segment.c -- segment meshes: chains and sheets of rigid segments joined
 * by displacement constraints (seed 004 ch. 3), with multilevel force
 * distribution on sheets (seed 004 ch. 4). Placeholder: no meshes yet. */
#include "sn_instance.h"

sn_status sn_check_segments(const sn_view *v, uint32_t *segB) {
    *segB = 0;
    if (v->nM != 0 || v->nSN != 0 || v->nSA != 0) return SN_ERR_SECTION;
    return SN_OK;
}

void sn_segments_reset(sn_ihdr *h) { (void)h; }

void sn_segments_step(sn_ihdr *h, uint32_t *sat) { (void)h; (void)sat; }

uint64_t sn_segments_hash(const sn_ihdr *h, uint64_t hsh) { (void)h; return hsh; }
