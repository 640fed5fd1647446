/* sn_force.c -- external forces and impulses on the flesh, spread over
 * levels (seed 004 ch. 4 applied to the lattice), and the rigid level's
 * share returned to the game as a wrench per joint. Placeholder. */
#include "sn_instance.h"

/* Share profiles: each share in [0, 1], summing to exactly 1 (fixed: 2^30;
 * float: within 2^-20), so a distribution never creates or loses force;
 * vertex profiles index an existing profile. */
sn_status sn_check_forces(const sn_view *v) {
    uint32_t i, k;
    if (v->nVP != 0 && v->nP == 0) return SN_ERR_SECTION;
    for (i = 0; i < v->nP; i++) {
        const unsigned char *p = v->sec[SN_SEC_SHARES] + (size_t)i * SN_ELEM_SHARES(SN_REAL_BYTES);
#if defined(SN_FLOAT)
        float sum = 0.0f;
        for (k = 0; k < SN_LEVELS; k++) {
            float x = sn_rd_f32(p + 4 * k);
            if (!(x >= 0.0f && x <= 1.0f)) return SN_ERR_VALUE; /* NaN fails too */
            sum += x;
        }
        if (!(sum >= 1.0f - 1.0f / 1048576 && sum <= 1.0f + 1.0f / 1048576)) return SN_ERR_VALUE;
#else
        int64_t sum = 0;
        for (k = 0; k < SN_LEVELS; k++) {
            int32_t x = sn_rd_i32(p + 4 * k);
            if (x < 0 || x > (int32_t)1 << 30) return SN_ERR_VALUE;
            sum += x;
        }
        if (sum != (int64_t)1 << 30) return SN_ERR_VALUE;
#endif
    }
    for (i = 0; i < v->nVP; i++)
        if (v->sec[SN_SEC_VSHARE][i] >= v->nP) return SN_ERR_INDEX;
    return SN_OK;
}

void sn_forces_rhs(sn_ihdr *h, sn_q *b, uint32_t *sat) { (void)h; (void)b; (void)sat; }

void sn_forces_clear(sn_ihdr *h) { h->n_forces = 0; }
