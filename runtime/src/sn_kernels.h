/* sn_kernels.h -- the solve's innermost kernels, one portable scalar
 * reference (sn_kernels.c) and per-ISA versions beside it
 * (sn_kernels_avx2.c, sn_kernels_neon.c, sn_kernels_m4.c), chosen at build
 * time from the compiler's target macros (make SIMD=..., runtime/runtime.mk):
 *
 *   SN_SIMD_SCALAR defined                          -> scalar reference
 *   float flavour: __AVX2__, or aarch64 NEON        -> sn_kernels_fsimd.c
 *                  (other targets, armhf included)  -> scalar reference
 *   __AVX2__ (also under AVX-512)                  -> sn_kernels_avx2.c
 *   __ARM_NEON (aarch64; armhf with -mfpu=neon)    -> sn_kernels_neon.c
 *   __ARM_FEATURE_DSP, no NEON (Cortex-M4/M7)      -> sn_kernels_m4.c
 *   anything else (SSE2-only x86-64, i686, MIPS)   -> scalar reference
 *
 * Fixed flavour: every path returns the same integers. A kernel's outputs
 * are sums of exact int32 x int32 -> int64 products with no rounding inside
 * the kernel, and every partial sum of any subset of those products is
 * bounded below 2^63 (KERNELS.md "SIMD kernels"), so any summation order
 * gives the same int64. Rounding happens only in the callers, unchanged.
 * Float flavour: float sums are not associative, so the SIMD paths compute
 * each output with the reference's operations in the reference's order
 * (lanes are outputs, never terms of one sum; no FMA): the same floats, the
 * same float hash on every path (sn_kernels_fsimd.h).
 */
#ifndef SN_KERNELS_H
#define SN_KERNELS_H

#include "sn_internal.h"
#include "sn_instance.h" /* bitlen64 */

#if defined(SN_SIMD_SCALAR)
#define SN_KERNELS_SCALAR 1
#elif defined(SN_FLOAT) && defined(__AVX2__)
#define SN_KERNELS_FAVX2 1 /* float: sn_kernels_fsimd.c, the scalar reference's bits */
#elif defined(SN_FLOAT) && defined(__aarch64__) && defined(__ARM_NEON) && SN_HOST_LE
#define SN_KERNELS_FNEON 1
#elif defined(SN_FLOAT)
#define SN_KERNELS_SCALAR 1
#elif defined(__AVX2__)
#define SN_KERNELS_AVX2 1
#elif defined(__ARM_NEON) || defined(__ARM_NEON__)
#define SN_KERNELS_NEON 1
#elif defined(__ARM_FEATURE_DSP) && defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
#define SN_KERNELS_M4 1
#else
#define SN_KERNELS_SCALAR 1
#endif

/* Offset (in reals) of stored upper block (a,b), a <= b, of a float
 * flavour cell's 36: row r holds the 8 - r blocks (r,r)..(r,7). */
#define SN_K_BLK(a, b) \
    (9u * ((uint32_t)(a) * 8u - ((uint32_t)(a) * ((uint32_t)(a) - 1u)) / 2u + ((uint32_t)(b) - (uint32_t)(a))))

/* Bytes of one cell's CELLK record in this flavour (sn_format.h). */
#if defined(SN_FLOAT)
#define SN_K_CELL_BYTES SN_ELEM_CELLK(SN_FLAVOUR_FLOAT32, SN_REAL_BYTES)
/* The float fold's operands per entry (sn_solve.c rhs_x0, SN_FOLD), plain
 * floats in this order on every path (no clamp: |v|, |x0| <= SN_FLIM and
 * c in [0, 17] keep them below 2^17.1; NUMERICS.md "The initial residual
 * folded in"); the product and the sum in two statements, never contracted
 * to an FMA:
 *   w = (v + x0) (1+b1),   y = a1 (v + x0) + x0 */
SN_INLINE sn_q sn_fold_w1(sn_q v, sn_q x0, sn_q ck) {
    const sn_q s = v + x0;
    return s * ck;
}
SN_INLINE sn_q sn_fold_y1(sn_q v, sn_q x0, sn_q a1) {
    const sn_q s = v + x0, t = s * a1;
    return t + x0;
}
#else
#define SN_K_CELL_BYTES SN_CELLK_FIXED_BYTES

/* little-endian int16 (a two's complement reinterpretation, as sn_rd_i32) */
SN_INLINE int32_t sn_k_rd_i16(const unsigned char *p) {
#if SN_HOST_LE
    int16_t v;
    memcpy(&v, p, 2);
    return v;
#else
    int32_t x = (int32_t)sn_rd_u16(p);
    return x - ((x & 0x8000) << 1);
#endif
}
/* Fixed flavour: block (a,b), a <= b, of a cell's CELLK record as 9 int32
 * entries (Q frac_S): a diagonal block from its 6 symmetric int32, an
 * off-diagonal one as m 2^e (|m| <= 2^15 - 1, e <= 12: |entry| < 2^27,
 * exact; the validator's bounds). Every kernel multiplies these integers. */
SN_INLINE void sn_k_blk(const unsigned char *K, uint32_t a, uint32_t b, int32_t B[9]) {
    if (a == b) {
        const unsigned char *d = K + SN_CELLK_DIAG + 24u * a;
        B[0] = sn_rd_i32(d);
        B[4] = sn_rd_i32(d + 4);
        B[8] = sn_rd_i32(d + 8);
        B[1] = B[3] = sn_rd_i32(d + 12);
        B[2] = B[6] = sn_rd_i32(d + 16);
        B[5] = B[7] = sn_rd_i32(d + 20);
    } else {
        const uint32_t o = SN_CELLK_OFFIDX(a, b);
        const unsigned char *m = K + SN_CELLK_OFF + 18u * o;
        const int32_t sc = (int32_t)1 << K[SN_CELLK_EXP + o];
        /* m 2^e, |.| < 2^27; written out (a loop of 9 costs a third more) */
        B[0] = sn_k_rd_i16(m) * sc; B[1] = sn_k_rd_i16(m + 2) * sc; B[2] = sn_k_rd_i16(m + 4) * sc;
        B[3] = sn_k_rd_i16(m + 6) * sc; B[4] = sn_k_rd_i16(m + 8) * sc; B[5] = sn_k_rd_i16(m + 10) * sc;
        B[6] = sn_k_rd_i16(m + 12) * sc; B[7] = sn_k_rd_i16(m + 14) * sc; B[8] = sn_k_rd_i16(m + 16) * sc;
    }
}
#endif

/* l = S^_e u over a cell's listed corners: K the cell's CELLK record (the
 * blocks (a,b) used as (a,b) and (b,a)); fc[0..nf-1] the corners, strictly
 * ascending (nf <= 8); u and l hold nf compacted corner 3-vectors (u_i
 * belongs to corner fc[i]). The mat-vec lists only free corners: the others'
 * operand is zero and their rows are dropped, so the 9 nf^2 multiply-adds
 * give the same sums as the full 24x24 product (fixed: exact zeros; float:
 * +-0 terms added to the same partial sums in the same order change no bit).
 * Fixed: entries |K| <= 2^27, |u| <= 2^28, each product < 2^55, each l < 24 * 2^55. */
void sn_k_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l);

/* l1 = S^_e u1 over all 8 corners and l2 = S^_e u2 at least at the corners
 * k with bit k of rows2 set (the right-hand side's two products: the second
 * is read only at free corners), each block decoded once; those rows are
 * the sums of two calls of sn_k_cell_mul with the 8 corners listed, in the
 * same order (float: the same bits). l2's other rows are unspecified.
 * Corner 0's operands u1_0 and u2_0 are 0 (the right-hand side's cell
 * vectors are differences from corner 0, a0): a path may skip the terms
 * they feed. */
void sn_k_cell_mul2(const unsigned char *K, const sn_q u1[24], const sn_q u2[24], sn_acc l1[24], sn_acc l2[24],
                    uint32_t rows2);

#if !defined(SN_FLOAT)
/* Fixed flavour's block-floating dot product of the CG (sn_solve.c): a
 * force-like (Q(19+k_i) per vertex i, n = 3 nv values), b velocity-like;
 * picks s so n * max|a| * max|b| < 2^62 after shifting each product right
 * by s + k_i (round half up), returns the sum and *e = s. Each product is
 * rounded alone, so the sum is exact and order-free (|sum| < 2^62). */
int64_t sn_k_dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n, int *e);

/* sn_k_dot's s, every path's: oa, ob the ORs of |a|, |b| over [0, i) (a
 * SIMD head; the OR has the bit length of the maximum, no compares), the
 * rest gathered here. */
SN_INLINE int sn_k_dot_scale(const sn_q *a, const sn_q *b, uint32_t i, uint32_t n, uint32_t oa, uint32_t ob) {
    int s;
    for (; i < n; i++) {
        oa |= a[i] < 0 ? (uint32_t)-(int64_t)a[i] : (uint32_t)a[i];
        ob |= b[i] < 0 ? (uint32_t)-(int64_t)b[i] : (uint32_t)b[i];
    }
    /* n * max|a| * max|b| < 2^62 after shifting each product right by s */
    s = bitlen64(oa) + bitlen64(ob) + bitlen64(n) - 62;
    return s < 0 ? 0 : s;
}
#endif

/* The CG's vector updates (sn_solve.c axpy, the direction update):
 * out[i] = sn_add(a[i], sn_mulq(s, x[i], sh, sat), sat); out may be a or x
 * (each entry is read before it is written). Fixed: |s x| <= 2^31 2^28,
 * |a| <= SN_LIM (a state vector) and 0 <= sh <= 62, every product rounded
 * and clamped alone (order-free; the M4's word form for sh >= 28 relies
 * on the product's bound);
 * float: out = sn_out(a + sn_out(s x)) per entry on every path (the same bits). */
#if defined(SN_KERNELS_AVX2) || defined(SN_KERNELS_NEON) || defined(SN_KERNELS_M4) || defined(SN_KERNELS_FAVX2) || defined(SN_KERNELS_FNEON)
void sn_k_axpy(sn_q *out, const sn_q *a, sn_q s, const sn_q *x, uint32_t n, int sh, uint32_t *sat);
#else /* the reference, inline as the loops it replaced */
SN_INLINE void sn_k_axpy(sn_q *out, const sn_q *a, sn_q s, const sn_q *x, uint32_t n, int sh, uint32_t *sat) {
    uint32_t i;
    for (i = 0; i < n; i++) out[i] = sn_add(a[i], sn_mulq(s, x[i], sh, sat), sat);
}
#endif

#if defined(SN_KERNELS_M4)
/* acc[0..n) = 0 (n = 3 nF: accumulators), a vertex's 24 bytes at a time
 * by STRD: the empty asm keeps GCC from turning the loop into a call of
 * newlib-nano's memset, a byte loop (~1 instruction a byte). */
SN_INLINE void sn_k_zero(sn_acc *acc, uint32_t n) {
    uint32_t i = 0;
    for (; i + 3 <= n; i += 3) {
        acc[i] = 0; acc[i + 1] = 0; acc[i + 2] = 0;
        __asm__("" : : : "memory");
    }
    for (; i < n; i++) {
        acc[i] = 0;
        __asm__("" : : : "memory");
    }
}
#define SN_K_ZERO 1

/* The mat-vec's mass pass without a mask (sn_solve.c pass_M_ff), acc
 * zeroed by the caller: per free row i, acc_i += M_ii y_i + sum over the
 * row's blocks (i,j) up to the first j >= nF of M_ij y_j, and acc_j +=
 * M_ij y_i (rp: ROWPTR, cols: COLS, md: MDIAG, mo: MOFF). Cortex-M4:
 * Thumb-2 (sn_kernels_m4.c); x86-64 AVX2 below; the portable paths keep
 * pass_M_ff's loop. */
#define SN_K_MASS_FF 1
void sn_k_mass_ff(const unsigned char *rp, const unsigned char *cols, const unsigned char *md, const unsigned char *mo,
                  const sn_q *y, sn_acc *acc, uint32_t nF);
/* The right-hand side's mass pass (sn_solve.c sn_rhs) at the skeleton
 * columns, after sn_k_mass_ff did the free ones with y = a1 v: acc_i +=
 * M_ij sn_add(coef(vel_j, a1), ds_{j-nF}) over row i's blocks with j >= nF,
 * y formed per block (the reference's values and clamp counts); requires
 * |a1| <= ONE_COEF (sn_rhs's pre). Cortex-M4 only: sn_rhs takes the
 * sn_k_mass_ff route where both exist. */
#define SN_K_MASS_SK 1
void sn_k_mass_sk(const unsigned char *rp, const unsigned char *cols, const unsigned char *mo, const sn_q *vel,
                  const sn_q *ds, sn_q a1, sn_acc *acc, uint32_t nF, uint32_t *sat);
/* cell_forces' corners 1..7 (sn_solve.c): for k = 1..7, a = cl[k], a0 =
 * cl[0], w_a = w + 3a (a < nF) or coef(v'_a, b1) (w_of, uncounted): d_k =
 * sn_k_sub3(sn_k_rot_t(R, sn_k_sub3(pos_a, pos_a0)), sn_k_sub3r(rest, 3a,
 * 3a0)), uu_k = sn_k_rot_t(R, sn_k_sub3(w_a, w0)); the reference's values
 * and clamp count. Returns the free corners' bits 1..7 (a < nF). */
#define SN_K_CORNERS 1
uint32_t sn_k_corners(const unsigned char *cl, const sn_q *pos, const sn_q *w, const sn_q *vel, uint32_t nF, sn_q b1,
                      const unsigned char *rest, const sn_q *R, const sn_q *w0, sn_q *d, sn_q *uu, uint32_t *sat);
#endif

#if defined(SN_KERNELS_AVX2)
#include <immintrin.h>
/* acc[0..n) = 0 by 32-byte stores (fixed; the float's 1.5 KB stay below
 * glibc's REP STOSB threshold). GCC made the plain loop a call of
 * glibc's memset, which runs REP STOSB above 2 KB (a fixed cow's 3 nF
 * accumulators: 3 KB): callgrind counts each byte an instruction, and the
 * call costs more than the ~100 stores in hardware. */
SN_INLINE void sn_k_zero(sn_acc *acc, uint32_t n) {
    uint32_t i = 0;
    for (; i + 4 <= n; i += 4) _mm256_storeu_si256((__m256i *)(void *)(acc + i), _mm256_setzero_si256());
    for (; i < n; i++) acc[i] = 0;
}
#define SN_K_ZERO 1

/* The mat-vec's mass pass without a mask (sn_solve.c pass_M_ff; as the
 * M4's above): x86-64 AVX2, the row's sum and acc_j's update as int64
 * lanes (sn_kernels_avx2.c; exact sums, the same integers). */
#define SN_K_MASS_FF 1
void sn_k_mass_ff(const unsigned char *rp, const unsigned char *cols, const unsigned char *md, const unsigned char *mo,
                  const sn_q *y, sn_acc *acc, uint32_t nF);
#elif defined(SN_KERNELS_FAVX2)
/* the float flavour's (sn_kernels_fsimd.c): pass_M_ff's floats */
#define SN_K_MASS_FF 1
void sn_k_mass_ff(const unsigned char *rp, const unsigned char *cols, const unsigned char *md, const unsigned char *mo,
                  const sn_q *y, sn_acc *acc, uint32_t nF);
/* The float right-hand side's loops (sn_solve.c rhs_x0, x86-64 AVX2,
 * sn_kernels_fsimd.c): 4 entries (or a vertex's 3) per operation, every
 * entry the reference's float and clamp count (sn_out: clamp to
 * +-SN_FLIM, NaN -> 0, each counted):
 *   sn_k_fold_w:  u = sn_fold_w1(v, x0, ck)                (n entries, no clamp)
 *   sn_k_fold_y:  u = sn_fold_y1(v, x0, a1)                (n entries, no clamp)
 *   sn_k_negout:  b = -sn_out(acc)                         (n entries)
 *   sn_k_mass_rhs: the mass pass with y formed per free vertex: per free
 *     row i, l = 0 + M_ii y_i, then in the row's order l += M_ij y_j and
 *     acc_j += M_ij y_i (free j), l += M_ij sn_add(coef(v_j, a1), ds_j-nF)
 *     (skeleton j: y per block), then acc_i += l
 *   sn_k_grav_rhs: per free vertex, b_i = sn_add(sn_add(b_i, sn_mulq(m_i,
 *     g_i)), -sn_out(acc_i)), g_i = sn_add(g, -R_i g) (modelled) or g
 *   sn_k_fdot:    the CG's float dot, sn_solve.c dot's order (8 partial sums) */
/* cell_stiff without a mask (sn_solve.c) on x86-64 float: acc += R S^ R^T d
 * over the cell's free corners (K its CELLK record, cl its CELLS record),
 * the same floats and counts as cell_stiff's loop (sn_kernels_fsimd.c) */
#define SN_K_CELL_STIFF 1
void sn_k_cell_stiff(const unsigned char *K, const unsigned char *cl, uint32_t nF, const sn_q *R, const sn_q *d, sn_acc *acc,
                     uint32_t *sat);
#define SN_K_FRHS 1
void sn_k_fold_w(sn_q *u, const sn_q *vel, const sn_q *x0, sn_q ck, uint32_t n);
void sn_k_fold_y(sn_q *u, const sn_q *vel, const sn_q *x0, sn_q a1, uint32_t n);
void sn_k_negout(sn_q *b, const sn_acc *acc, uint32_t n, uint32_t *sat);
void sn_k_mass_rhs(const unsigned char *rp, const unsigned char *cols, const unsigned char *md, const unsigned char *mo,
                   const sn_q *y, const sn_q *vel, const sn_q *ds, sn_q a1, sn_acc *acc, uint32_t nF, uint32_t *sat);
void sn_k_grav_rhs(sn_q *b, const sn_acc *acc, const sn_q *R, const unsigned char *ml, const sn_q g[3], int modelled,
                   uint32_t nF, uint32_t *sat);
float sn_k_fdot(const sn_q *a, const sn_q *b, uint32_t n);
/* sn_skeleton's loop after the first pose (sn_pose.c), x86-64 float: per
 * skeleton vertex i in [nF, nV) of bone b = fr[4 i], p = sn_rot(jR_b, x_i)
 * (x_i the rest position, REST), pn = sn_add(p, jT_b), vn = sn_add(pn,
 * -pos_i), ds_(i-nF) = sn_add(vn, -vel_i), vel_i = vn, pos_i = pn: a
 * vertex's 3 entries in lanes, the same floats and clamp counts */
#define SN_K_SKEL 1
void sn_k_skeleton(const sn_q *jR, const sn_q *jT, const unsigned char *fr, const unsigned char *rest, uint32_t nF,
                   uint32_t nV, sn_q *pos, sn_q *vel, sn_q *ds, uint32_t *sat);
/* sn_rigs' entries of one rig (sn_rig.c), x86-64 float: for e in
 * [first, first + cnt), vertex i = vx[e], t = sn_out(eta F_e), b_i =
 * sn_add(b_i, sn_rot(R_i, t)), in lanes, the same floats and counts */
#define SN_K_RIG 1
void sn_k_rig(sn_q eta, const unsigned char *F, const unsigned char *vx, uint32_t first, uint32_t cnt, const sn_q *R,
              sn_q *b, uint32_t *sat);
#endif

/* Which path this library was built with ("scalar", "avx2", "avx512", "neon", "m4"). */
const char *sn_kernels_name(void);

#endif /* SN_KERNELS_H */
