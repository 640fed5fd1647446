/* sn_rig.c -- rig forces (seed 003 §4): control values Theta = (alpha, beta),
 * the piecewise-linear tau maps (eq. 11 and the tau after it) and the force
 * f_rig,i = R_i sum_a tau_a(gamma_a) Q^a_i (eq. 12), added to the right-hand
 * side of step 5 (runtime/NUMERICS.md "Rig forces").
 *
 * Cost: every rig, sample and entry is visited every step; no loop exits
 * on values, so the cost is a function of the blob's counts.
 */
#include "sn_instance.h"
#include "sn_kernels_rot.h" /* the M4's sn_k_out_w, sn_k_rot */

#define CTL_ELEM SN_ELEM_CONTROLS(SN_REAL_BYTES)
#define SMP_ELEM SN_ELEM_RIG_SAMPLES(SN_REAL_BYTES)

/* tau(g) = eta_0 + sum_k (eta_k+1 - eta_k) clamp((g - g_k)/(g_k+1 - g_k), 0, 1).
 * Fixed: each term is round(d |de| / D) with its sign, d = clamp(g - g_k, 0, D),
 * D = g_k+1 - g_k <= 2^31 and |de| <= 2^31 (validated), so d |de| < 2^62:
 * exact at the samples (d = 0 or D), clamped at the ends, within 1/2 LSB
 * (Q30) of the linear interpolation between them. */
static sn_q tau(const unsigned char *smp, uint32_t n, sn_real g) {
    uint32_t k;
#if defined(SN_FLOAT)
    float eta = sn_rd_f32(smp + SN_REAL_BYTES);
    for (k = 0; k + 1 < n; k++) {
        const unsigned char *e = smp + (size_t)k * SMP_ELEM;
        float g0 = sn_rd_f32(e), g1 = sn_rd_f32(e + SMP_ELEM), d = g - g0, D = g1 - g0;
        float t = d <= 0.0f ? 0.0f : (d >= D ? 1.0f : d / D);
        eta += t * (sn_rd_f32(e + SMP_ELEM + SN_REAL_BYTES) - sn_rd_f32(e + SN_REAL_BYTES));
    }
    return eta;
#else
    int64_t eta = sn_rd_i32(smp + SN_REAL_BYTES);
    const int64_t one = (int64_t)1 << 30;
    for (k = 0; k + 1 < n; k++) {
        const unsigned char *e = smp + (size_t)k * SMP_ELEM;
        int64_t g0 = sn_rd_i32(e), D = (int64_t)sn_rd_i32(e + SMP_ELEM) - g0, d = (int64_t)g - g0;
        int64_t de = (int64_t)sn_rd_i32(e + SMP_ELEM + SN_REAL_BYTES) - sn_rd_i32(e + SN_REAL_BYTES);
        uint64_t m = (uint64_t)(de < 0 ? -de : de), t;
        d = d < 0 ? 0 : (d > D ? D : d);
        t = sn_udiv64((uint64_t)d * m + ((uint64_t)D >> 1), (uint64_t)D);
        eta += de < 0 ? -(int64_t)t : (int64_t)t;
    }
    return (int32_t)(eta > one ? one : (eta < -one ? -one : eta));
#endif
}

/* Pose controls: the twist of joint J's rotation relative to its parent
 * (conj(q_parent) q_J; the root's own rotation) about the baked axis. */
static void pose_controls(sn_ihdr *h) {
    const sn_view *v = &h->v;
    const unsigned char *c = v->sec[SN_SEC_CONTROLS];
    const sn_q *pq = CARR(h, o_pq, sn_q);
    sn_real *val = ARR(h, o_ctl, sn_real);
    uint32_t i, k;
    for (i = 0; i < v->nK; i++, c += CTL_ELEM) {
        sn_q rel[4], ax[3];
        uint32_t j = c[33];
        int32_t par;
        if (c[32] != SN_CTL_ANGLE) continue; /* a property of the blob, not of values */
        par = sn_joint_parent((const sn_blob *)(const void *)v->base, j);
        if (par < 0) {
            for (k = 0; k < 4; k++) rel[k] = pq[4 * j + k];
        } else {
            sn_q cp[4];
            const sn_q *qp = pq + 4 * (uint32_t)par;
            cp[0] = -qp[0]; cp[1] = -qp[1]; cp[2] = -qp[2]; cp[3] = qp[3];
            sn_qmul(cp, pq + 4 * j, rel);
        }
        for (k = 0; k < 3; k++) ax[k] = SN_RD_REAL(c + 40 + k * SN_REAL_BYTES);
        val[i] = sn_twist_deg(rel, ax);
    }
}

void sn_rigs(sn_ihdr *h, sn_q *b, uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *rig = v->sec[SN_SEC_RIGS], *smp = v->sec[SN_SEC_RIG_SAMPLES];
    const unsigned char *vx = v->sec[SN_SEC_RIG_VERTS], *F = v->sec[SN_SEC_RIG_FORCES];
    const sn_q *R = CARR(h, o_R, sn_q);
    const sn_real *val = CARR(h, o_ctl, sn_real);
#if !defined(SN_FLOAT)
    const uint8_t *kk = CARR(h, o_k, uint8_t);
#endif
    uint32_t a, e, c;
    pose_controls(h);
    for (a = 0; a < v->nR; a++, rig += SN_ELEM_RIGS) {
        uint32_t n = rig[2], first = sn_rd_u32(rig + 8), cnt = sn_rd_u32(rig + 12);
        sn_q eta = tau(smp + (size_t)sn_rd_u32(rig + 4) * SMP_ELEM, n, val[sn_rd_u16(rig)]);
#if !defined(SN_FLOAT)
        int frac = rig[3]; /* validated: 5..50 */
#endif
#if defined(SN_K_RIG) /* x86-64 float: the loop below in lanes (sn_kernels.h) */
        sn_k_rig(eta, F, vx, first, cnt, R, b, sat);
        continue;
#endif
        for (e = first; e < first + cnt; e++) {
            uint32_t i = sn_rd_u16(vx + 2 * e);
            sn_q t[3], f[3];
#if defined(SN_KERNELS_M4)
            { /* the shift's test once, sn_out in 32-bit words (sn_k_out_w), the rotation with
               * one-compare clamps (sn_k_rot): the same values and counts */
                const int sh = 30 + frac - SN_Q_FORCE - (int)kk[i];
                if ((uint32_t)(sh - 1) < 31u) {
                    const uint32_t bit = (uint32_t)1 << (sh - 1);
                    for (c = 0; c < 3; c++) t[c] = sn_k_out_w(sn_mul(eta, rd_real(F, 3 * e + c)), sh, bit, sat);
                } else
                    for (c = 0; c < 3; c++) t[c] = sn_out(sn_mul(eta, rd_real(F, 3 * e + c)), sh, sat);
            }
            sn_k_rot(R + 9 * i, t, f, sat);
            for (c = 0; c < 3; c++) b[3 * i + c] = sn_add(b[3 * i + c], f[c], sat);
            continue;
#endif
            for (c = 0; c < 3; c++) {
                sn_q q = rd_real(F, 3 * e + c);
#if defined(SN_FLOAT)
                t[c] = sn_out(eta * q, 0, sat);
#else
                /* Q30 * Q frac -> Q(19 + k_i): shift in [1, 61] (validator) */
                t[c] = sn_out(sn_mul(eta, q), 30 + frac - SN_Q_FORCE - (int)kk[i], sat);
#endif
            }
            sn_rot(R + 9 * i, t, f, sat); /* rest frame -> the vertex's frame */
            for (c = 0; c < 3; c++) b[3 * i + c] = sn_add(b[3 * i + c], f[c], sat);
        }
    }
}

/* ---- public API ---- */

static const unsigned char *ctl_rec(const sn_blob *blob, uint32_t c) {
    sn_view v;
    if (!blob) return NULL;
    sn_view_init(&v, blob);
    return c < v.nK ? v.sec[SN_SEC_CONTROLS] + (size_t)c * CTL_ELEM : NULL;
}

int32_t sn_find_control(const sn_blob *blob, const char *name) {
    sn_view v;
    uint32_t c, k;
    if (!blob || !name) return -1;
    sn_view_init(&v, blob);
    for (c = 0; c < v.nK; c++) {
        const unsigned char *s = v.sec[SN_SEC_CONTROLS] + (size_t)c * CTL_ELEM;
        /* stored names are NUL-terminated within 32 bytes (validated) */
        for (k = 0; s[k] && s[k] == (unsigned char)name[k]; k++) {}
        if (s[k] == (unsigned char)name[k]) return (int32_t)c;
    }
    return -1;
}

const char *sn_control_name(const sn_blob *blob, uint32_t c) {
    return (const char *)ctl_rec(blob, c);
}

int32_t sn_control_kind_of(const sn_blob *blob, uint32_t c) {
    const unsigned char *r = ctl_rec(blob, c);
    return r ? (int32_t)r[32] : -1;
}

sn_status sn_set_control(sn_instance *inst, uint32_t c, sn_real value) {
    sn_ihdr *h;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    if (c >= h->v.nK || h->v.sec[SN_SEC_CONTROLS][(size_t)c * CTL_ELEM + 32] != SN_CTL_ABSTRACT)
        return SN_ERR_ARG;
#if defined(SN_FLOAT)
    if (!(value == value) || value > 3.0e38f || value < -3.0e38f) return SN_ERR_ARG; /* NaN, inf */
#endif
    ARR(h, o_ctl, sn_real)[c] = value;
    return SN_OK;
}

sn_status sn_get_control(const sn_instance *inst, uint32_t c, sn_real *value) {
    const sn_ihdr *h;
    if (!inst || !value) return SN_ERR_NULL;
    h = chdr_of(inst);
    if (h->magic != SN_INST_MAGIC) return SN_ERR_INSTANCE;
    if (c >= h->v.nK) return SN_ERR_ARG;
    *value = CARR(h, o_ctl, sn_real)[c];
    return SN_OK;
}

/* Controls after init/reset: abstract ones at their baked value, pose ones 0. */
void sn_controls_reset(sn_ihdr *h) {
    const unsigned char *c = h->v.sec[SN_SEC_CONTROLS];
    sn_real *val = ARR(h, o_ctl, sn_real);
    uint32_t i;
    for (i = 0; i < h->v.nK; i++, c += CTL_ELEM)
        val[i] = c[32] == SN_CTL_ABSTRACT ? SN_RD_REAL(c + 40 + 3 * SN_REAL_BYTES) : 0;
}
