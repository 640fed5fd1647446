/* sn_kernels_neon.c -- ARM NEON kernels of sn_kernels.h (aarch64; armhf
 * built with -mfpu=neon), fixed flavour.
 *
 * cell_mul: a corner's sum as x,y in one int64x2 and z as an int64x2 of
 * two partial sums plus one scalar. Block (a,b) = B:
 *   VLD3 of B0..B5 de-interleaves the first two rows into the columns
 *   (B0,B3) (B1,B4) (B2,B5); VLD1 gives (B6,B7); B8 alone.
 *   L_a.xy += (B0,B3) u_b.x + (B1,B4) u_b.y + (B2,B5) u_b.z   (VMLAL by scalar)
 *   L_a.z  += (B6,B7) . (u_b.x, u_b.y) + B8 u_b.z
 *   L_b.xy += (B0,B1) u_a.x + (B3,B4) u_a.y + (B6,B7) u_a.z   (B^T u_a)
 *   L_b.z  += (B2,B5) . (u_a.x, u_a.y) + B8 u_a.z
 * B is the block decoded to int32 (sn_k_blk: int16 mantissa times 2^e, or
 * the diagonal's 6 int32). Exact int32 x int32 -> int64 products (SMLAL),
 * the same sums as the scalar reference in another order (sn_kernels.h,
 * NUMERICS.md). */
#include "sn_kernels.h"
#include "sn_instance.h" /* bitlen64 */

#if defined(SN_KERNELS_NEON)
#include <arm_neon.h>

void sn_k_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l) {
    int64x2_t xy[8], zz[8];
    int64_t z1[8];
    uint32_t i, j;
    for (i = 0; i < nf; i++) {
        xy[i] = vdupq_n_s64(0);
        zz[i] = vdupq_n_s64(0);
        z1[i] = 0;
    }
    for (i = 0; i < nf; i++) {
        const uint32_t a = fc[i];
        int32_t B[9], Bb[9]; /* the blocks decoded (sn_k_blk) */
        const int32_t ua0 = u[3 * i], ua1 = u[3 * i + 1], ua2 = u[3 * i + 2];
        const int32x2_t ua01 = vld1_s32(u + 3 * i);
        int32x2x3_t c;
        int32x2_t r2;
        sn_k_blk(K, a, a, B);
        c = vld3_s32(B);
        r2 = vld1_s32(B + 6);
        int64x2_t axy = xy[i], az = zz[i];
        int64_t az1 = z1[i];
        /* diagonal block (a,a), stored in full: L_a += B u_a */
        axy = vmlal_n_s32(axy, c.val[0], ua0);
        axy = vmlal_n_s32(axy, c.val[1], ua1);
        axy = vmlal_n_s32(axy, c.val[2], ua2);
        az = vmlal_s32(az, r2, ua01);
        az1 += (int64_t)B[8] * ua2;
        for (j = i + 1; j < nf; j++) {
            const int32x2_t ub01 = vld1_s32(u + 3 * j);
            const int32_t ub2 = u[3 * j + 2];
            sn_k_blk(K, a, fc[j], Bb);
            c = vld3_s32(Bb);
            r2 = vld1_s32(Bb + 6);
            axy = vmlal_n_s32(axy, c.val[0], vget_lane_s32(ub01, 0));
            axy = vmlal_n_s32(axy, c.val[1], vget_lane_s32(ub01, 1));
            axy = vmlal_n_s32(axy, c.val[2], ub2);
            az = vmlal_s32(az, r2, ub01);
            az1 += (int64_t)Bb[8] * ub2;
            xy[j] = vmlal_n_s32(xy[j], vld1_s32(Bb), ua0);
            xy[j] = vmlal_n_s32(xy[j], vld1_s32(Bb + 3), ua1);
            xy[j] = vmlal_n_s32(xy[j], r2, ua2);
            zz[j] = vmlal_s32(zz[j], c.val[2], ua01);
            z1[j] += (int64_t)Bb[8] * ua2;
        }
        xy[i] = axy;
        zz[i] = az;
        z1[i] = az1;
    }
    for (i = 0; i < nf; i++) {
        l[3 * i] = vgetq_lane_s64(xy[i], 0);
        l[3 * i + 1] = vgetq_lane_s64(xy[i], 1);
        l[3 * i + 2] = vgetq_lane_s64(zz[i], 0) + vgetq_lane_s64(zz[i], 1) + z1[i];
        SN_RANGE(SN_WITHIN(l[3 * i], 60) && SN_WITHIN(l[3 * i + 1], 60) && SN_WITHIN(l[3 * i + 2], 60),
                 "cell row beyond 24 * 2^55", l[3 * i + 2]);
    }
}

/* the right-hand side's two products: two calls (the block decode is a few
 * vector instructions here) */
void sn_k_cell_mul2(const unsigned char *K, const sn_q u1[24], const sn_q u2[24], sn_acc l1[24], sn_acc l2[24],
                    uint32_t rows2) {
    static const uint8_t all8[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    (void)rows2; /* every row of l2 */
    sn_k_cell_mul(K, all8, 8, u1, l1);
    sn_k_cell_mul(K, all8, 8, u2, l2);
}

/* Block-floating dot product: magnitudes ORed 4 lanes at a time (VABS of a
 * clamped int32 has the bits of the scalar's uint32 magnitude); then two
 * vertices = 6 products as 3 pairs (VMULL.S32), each rounded by VRSHL with
 * the negated shift s + k of its vertex: (x + 2^(sh-1)) >> sh, exactly the
 * scalar rounding (sh = 0 leaves x). */
int64_t sn_k_dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n, int *e) {
    uint32_t i, k, oa = 0, ob = 0, nv = n / 3;
    int s;
    int64_t sum;
    uint32x4_t va = vdupq_n_u32(0), vb = vdupq_n_u32(0);
    int64x2_t acc = vdupq_n_s64(0);
    for (i = 0; i + 4 <= n; i += 4) {
        va = vorrq_u32(va, vreinterpretq_u32_s32(vabsq_s32(vld1q_s32(a + i))));
        vb = vorrq_u32(vb, vreinterpretq_u32_s32(vabsq_s32(vld1q_s32(b + i))));
    }
    oa = vgetq_lane_u32(va, 0) | vgetq_lane_u32(va, 1) | vgetq_lane_u32(va, 2) | vgetq_lane_u32(va, 3);
    ob = vgetq_lane_u32(vb, 0) | vgetq_lane_u32(vb, 1) | vgetq_lane_u32(vb, 2) | vgetq_lane_u32(vb, 3);
    s = sn_k_dot_scale(a, b, i, n, oa, ob);
    for (i = 0; i + 2 <= nv; i += 2) {
        const sn_q *pa = a + 3 * i, *pb = b + 3 * i;
        const int64x1_t n0 = vdup_n_s64(-(int64_t)(s + kk[i])), n1 = vdup_n_s64(-(int64_t)(s + kk[i + 1]));
        acc = vaddq_s64(acc, vrshlq_s64(vmull_s32(vld1_s32(pa), vld1_s32(pb)), vcombine_s64(n0, n0)));
        acc = vaddq_s64(acc, vrshlq_s64(vmull_s32(vld1_s32(pa + 2), vld1_s32(pb + 2)), vcombine_s64(n0, n1)));
        acc = vaddq_s64(acc, vrshlq_s64(vmull_s32(vld1_s32(pa + 4), vld1_s32(pb + 4)), vcombine_s64(n1, n1)));
    }
    sum = vgetq_lane_s64(acc, 0) + vgetq_lane_s64(acc, 1);
    for (; i < nv; i++) {
        int sh = s + kk[i];
        int64_t half = sh > 0 ? (int64_t)1 << (sh - 1) : 0;
        for (k = 3 * i; k < 3 * i + 3; k++) sum += ((int64_t)a[k] * b[k] + half) >> sh;
    }
    *e = s;
    return sum;
}

/* CG updates, 4 values per iteration: VMULL by s (exact), VRSHL by -sh
 * (sn_rshr64's rounding), VQMOVN to int32 (a value beyond int32 saturates,
 * still beyond SN_LIM: clamped and counted the same), the clamp and count
 * in int32 lanes (a compare mask is -1: subtracting it counts), + a
 * (|a|, |q| <= 2^28: no overflow), clamp and count again; tail scalar. */
void sn_k_axpy(sn_q *out, const sn_q *a, sn_q s, const sn_q *x, uint32_t n, int sh, uint32_t *sat) {
    const int64x2_t vsh = vdupq_n_s64(-(int64_t)sh);
    const int32x4_t lim = vdupq_n_s32(SN_LIM), nlim = vdupq_n_s32(-SN_LIM);
    uint32x4_t c = vdupq_n_u32(0);
    uint32_t i;
    for (i = 0; i + 4 <= n; i += 4) {
        const int32x4_t xv = vld1q_s32(x + i);
        int32x4_t q = vcombine_s32(vqmovn_s64(vrshlq_s64(vmull_n_s32(vget_low_s32(xv), s), vsh)),
                                   vqmovn_s64(vrshlq_s64(vmull_n_s32(vget_high_s32(xv), s), vsh)));
        c = vsubq_u32(c, vorrq_u32(vcgtq_s32(q, lim), vcltq_s32(q, nlim)));
        q = vaddq_s32(vmaxq_s32(vminq_s32(q, lim), nlim), vld1q_s32(a + i));
        c = vsubq_u32(c, vorrq_u32(vcgtq_s32(q, lim), vcltq_s32(q, nlim)));
        vst1q_s32(out + i, vmaxq_s32(vminq_s32(q, lim), nlim));
    }
    *sat += vgetq_lane_u32(c, 0) + vgetq_lane_u32(c, 1) + vgetq_lane_u32(c, 2) + vgetq_lane_u32(c, 3);
    for (; i < n; i++) out[i] = sn_add(a[i], sn_mulq(s, x[i], sh, sat), sat);
}

const char *sn_kernels_name(void) { return "neon"; }

#else
typedef int sn_kernels_neon_unused_; /* ISO C: no empty translation unit */
#endif
