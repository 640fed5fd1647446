/* sn_health.c -- steps 8-9: per-vertex distance limits from the skinned
 * position (the skin constraints engines use) and the health report
 * (runtime/NUMERICS.md). */
#include "sn_instance.h"

/* Skinned (rigidly warped) position s_i = R_i x_i + c_i of lattice vertex i. */
void sn_skinned(const sn_ihdr *h, uint32_t i, sn_q s[3], uint32_t *sat) {
    const sn_q *R = CARR(h, o_R, sn_q);
    const unsigned char *rest = h->v.sec[SN_SEC_REST];
    sn_q x[3], rx[3], c[3];
    uint32_t k;
    for (k = 0; k < 3; k++) x[k] = rd_real(rest, 3 * i + k);
    sn_rot(R + 9 * i, x, rx, sat);
    sn_vertex_origin(h, i, c);
    for (k = 0; k < 3; k++) s[k] = sn_add(rx[k], c[k], sat);
}

void sn_limits(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *lim = v->sec[SN_SEC_LIMIT];
    sn_q *pos = ARR(h, o_pos, sn_q), *vel = ARR(h, o_vel, sn_q);
    uint32_t i, k, n = 0;
    for (i = 0; i < v->nL; i++) { /* nL is 0 or nF: a blob-fixed count */
        sn_q L = rd_real(lim, i), s[3], d[3];
        sn_len2 d2;
        if (!(L > 0)) continue;
        sn_skinned(h, i, s, sat);
        for (k = 0; k < 3; k++) d[k] = sn_add(pos[3 * i + k], -s[k], sat);
        d2 = sn_norm2(d);
#if defined(SN_FLOAT)
        if (d2 > L * L) {
            float f = L * sn_frsqrt(d2);
            for (k = 0; k < 3; k++) {
                sn_q pn = s[k] + d[k] * f;
                vel[3 * i + k] = sn_add(vel[3 * i + k], pn - pos[3 * i + k], sat);
                pos[3 * i + k] = pn;
            }
            n++;
        }
#else
        if (d2 > (uint64_t)((int64_t)L * L)) {
            /* p = s + d L / |d|, rounded to nearest; |d| > L >= 1 */
            int64_t len = (int64_t)sn_isqrt64(d2);
            for (k = 0; k < 3; k++) {
                int64_t num = (int64_t)d[k] * L, off;
                sn_q pn;
                off = num >= 0 ? (num + len / 2) / len : -((-num + len / 2) / len);
                pn = sn_add(s[k], (sn_q)off, sat);
                vel[3 * i + k] = sn_add(vel[3 * i + k], sn_add(pn, -pos[3 * i + k], sat), sat);
                pos[3 * i + k] = pn;
            }
            n++;
        }
#endif
    }
    h->limit_clamps = n;
    if (n) h->limit_steps = sn_count(h->limit_steps, 1);
}

/* Twice the internal energy (fixed: Q32) -> joules, public units. */
void sn_set_energy(sn_ihdr *h, sn_acc e2) {
#if defined(SN_FLOAT)
    h->energy = 0.5f * e2 * h->v.energy;
#else
    /* e2 (Q32) * ENERGY (Q frac_E) / 2 -> Q16.16: shift 17 + frac_E, after
     * normalizing e2 to 31 bits so the product fits */
    int n = bitlen64(e2 > 0 ? (uint64_t)e2 : 0u), sh = 17 + h->v.frac_E;
    int64_t m = e2 > 0 ? e2 : 0, p;
    if (n > 31) { m >>= (n - 31); sh -= n - 31; }
    p = m * (int64_t)h->v.energy; /* < 2^62 */
    if (sh > 62) p = 0;           /* below half an LSB of Q16.16 */
    else if (sh >= 0) p = sn_rshr64(p, sh);
    else p = bitlen64((uint64_t)p) - sh > 62 ? INT32_MAX : p * ((int64_t)1 << -sh);
    h->energy = clamp32(p);
#endif
    if (h->energy > h->energy_max) h->energy_max = h->energy;
}

void sn_health(sn_ihdr *h, uint32_t step_clamps) {
    const sn_view *v = &h->v;
    const sn_q *pos = CARR(h, o_pos, sn_q);
    const unsigned char *ml = v->sec[SN_SEC_MLUMP];
#if defined(SN_FLOAT)
    const sn_q mmin = 1.0f / 16.0f;
#else
    /* 1/16 in Q frac_M; any int32 is below it past Q35 (a hostile blob) */
    const sn_q mmin = v->frac_M >= 35 ? INT32_MAX : (sn_q)(((int64_t)1 << v->frac_M) >> 4);
#endif
    uint32_t i, k, local = 0;
    sn_len2 m2 = 0;
    sn_real disp;
    for (i = 0; i < v->nF; i++) {
        sn_q s[3], d[3];
        sn_len2 d2;
        /* only vertices that carry flesh: the lumped mass of an all-air
         * vertex is ~1e-3 of an interior one (bake weight `air`), and its
         * sag says nothing about the surface */
        if (rd_real(ml, i) < mmin) continue;
        sn_skinned(h, i, s, &local);
        for (k = 0; k < 3; k++) d[k] = sn_add(pos[3 * i + k], -s[k], &local);
        d2 = sn_norm2(d);
        m2 = d2 > m2 ? d2 : m2;
    }
#if defined(SN_FLOAT)
    disp = m2 > 0.0f ? m2 * sn_frsqrt(m2) / v->cell : 0.0f;
#else
    /* |d| (Q22) / cell (Q22) in Q16.16; |d| < 2^30, cell >= 1 */
    disp = clamp32(((int64_t)sn_isqrt64(m2) << 16) / v->cell);
#endif
    h->disp = disp;
    if (disp > h->disp_max) h->disp_max = disp;
    if (step_clamps != 0 || disp > v->disp_bound) h->bound_steps = sn_count(h->bound_steps, 1);
}
