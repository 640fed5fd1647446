/* sn_kernels_m4_ic.c -- Cortex-M4 (ARMv7E-M) vertex steps of the fused
 * IC(0) sweeps (sn_precond.c ic_fused; sn_kernels_ic.h declares them),
 * fixed flavour, in Thumb-2: the work each sweep does at its vertex j
 * besides the block products (sn_m4_ic_cols / sn_m4_ic_rows):
 *   sn_m4_icf_y  forward:  y_j = sn_out(R_j^T r_j - acc_j)
 *   sn_m4_icb_z  backward: z'_j = sn_out(sn_out(D_j^-1 y_j, sh) - l_j)
 *                stored to zq_j, then z_j = R_j z'_j (0 < sh < 32)
 * each value and clamp count the C kernels' (sn_k_rot_t / sn_k_rot's
 * sn_k_rot_out1, sn_k_sym_out's sn_k_out_w, sn_k_sub3a's sn_k_sub_w,
 * sn_kernels_rot.h): the same SMULL / SMLAL int64 sums, the same rounding
 * and clamp tests on the two words. GCC's C for the two (the fused C
 * sweeps) kept its values in memory between the kernels: ~300 instructions
 * a vertex, here ~200 (runtime/KERNELS_M4.md "M4 round 5a"). */
#include "sn_kernels.h"
/* outside the #if: tools/amalgamate.sh inlines a header at its first include only */
#include "sn_kernels_ic.h"

#if defined(SN_KERNELS_M4)
typedef char sn_m4_icv_layout_[SN_REAL_BYTES == 4 && SN_LIM == 0x10000000 ? 1 : -1]; /* P's int32 entries, the clamp's immediates */

/* forward: r0 R_j, r1 r_j, r2 acc_j, r3 y_j, [sp] sat */
__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_icf_y,\"ax\",%progbits\n"
    /* component k: t = rot_out1(R[k] v0 + R[3+k] v1 + R[6+k] v2) (the
     * rounded shift by 30: an int32, |sum| < 3 2^58), then y_k =
     * sub_w(t, acc_k) */
    ".macro snfy k\n"
    "ldr   r7, [r0, #(4 * \\k)]\n"
    "ldr   r8, [r0, #(12 + 4 * \\k)]\n"
    "ldr   r9, [r0, #(24 + 4 * \\k)]\n"
    "smull r10, r11, r7, r4\n"
    "smlal r10, r11, r8, r5\n"
    "smlal r10, r11, r9, r6\n"
    "adds  r10, r10, #0x20000000\n"
    "adc   r11, r11, #0\n"
    "lsr   r10, r10, #30\n"
    "orr   r10, r10, r11, lsl #2\n"     /* t */
    "add   r7, r10, #0x10000000\n"
    "cmp   r7, #0x20000000\n"
    "bls   1f\n"                        /* |t| <= SN_LIM */
    "ldr   r7, [sp, #36]\n"
    "ldr   r8, [r7]\n"
    "adds  r8, r8, #1\n"
    "str   r8, [r7]\n"
    "cmp   r10, #0\n"
    "ite   gt\n"
    "movgt r10, #0x10000000\n"
    "movle r10, #0xF0000000\n"
    "1:\n"
    "ldrd  r8, r9, [r2, #(8 * \\k)]\n"
    "subs  r8, r10, r8\n"
    "asr   r7, r10, #31\n"
    "sbc   r9, r7, r9\n"                /* d = t - acc_k */
    "add   r7, r8, #0x10000000\n"
    "cmp   r7, #0x20000000\n"
    "bhi   2f\n"
    "cmp   r9, r8, asr #31\n"
    "beq   3f\n"                        /* d an int32 within +-SN_LIM */
    "2:\n"
    "ldr   r7, [sp, #36]\n"
    "ldr   r10, [r7]\n"
    "adds  r10, r10, #1\n"
    "str   r10, [r7]\n"
    "cmp   r9, #0\n"
    "ite   lt\n"
    "movlt r8, #0xF0000000\n"
    "movge r8, #0x10000000\n"
    "3:\n"
    "str   r8, [r3, #(4 * \\k)]\n"
    ".endm\n"
    ".align 2\n"
    ".global sn_m4_icf_y\n"
    ".thumb_func\n"
    ".type sn_m4_icf_y, %function\n"
    "sn_m4_icf_y:\n"
    "push  {r4-r11, lr}\n"              /* sat at [sp, #36] */
    "ldm   r1, {r4, r5, r6}\n"          /* r_j */
    "snfy 0\n"
    "snfy 1\n"
    "snfy 2\n"
    "pop   {r4-r11, pc}\n"
    ".size sn_m4_icf_y, .-sn_m4_icf_y\n"
    ".purgem snfy\n"
    ".popsection\n");

/* backward: r0 P_j, r1 z_j (y_j in, z_j out), r2 l, r3 zq_j, [sp] R_j,
 * [sp, #4] sh, [sp, #8] sat */
__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_icb_z,\"ax\",%progbits\n"
    /* component k: w = out_w(P[a] y0 + P[b] y1 + P[c] y2, sh) (the
     * rounding term bit = 2^(sh-1), the shift on the two words), then
     * z'_k = sub_w(w, l_k) to zq_j */
    ".macro snbz k, a, b, c\n"
    "ldr   r7, [r0, #\\a]\n"
    "smull r8, r9, r7, r4\n"
    "ldr   r7, [r0, #\\b]\n"
    "smlal r8, r9, r7, r5\n"
    "ldr   r7, [r0, #\\c]\n"
    "smlal r8, r9, r7, r6\n"
    "adds  r8, r8, r12\n"
    "adc   r9, r9, #0\n"
    "lsr   r8, r8, r10\n"
    "lsl   r7, r9, r11\n"
    "orr   r8, r8, r7\n"
    "asr   r9, r9, r10\n"               /* (lo, hi) of the shifted sum */
    "add   r7, r8, #0x10000000\n"
    "cmp   r7, #0x20000000\n"
    "bhi   1f\n"
    "cmp   r9, r8, asr #31\n"
    "beq   2f\n"
    "1:\n"
    "ldr   r7, [sp, #44]\n"
    "ldr   lr, [r7]\n"
    "adds  lr, lr, #1\n"
    "str   lr, [r7]\n"
    "cmp   r9, #0\n"
    "ite   lt\n"
    "movlt r8, #0xF0000000\n"
    "movge r8, #0x10000000\n"
    "2:\n"                              /* w */
    "ldrd  r7, r9, [r2, #(8 * \\k)]\n"
    "subs  r7, r8, r7\n"
    "asr   lr, r8, #31\n"
    "sbc   r9, lr, r9\n"                /* d = w - l_k */
    "add   lr, r7, #0x10000000\n"
    "cmp   lr, #0x20000000\n"
    "bhi   3f\n"
    "cmp   r9, r7, asr #31\n"
    "beq   4f\n"
    "3:\n"
    "ldr   lr, [sp, #44]\n"
    "ldr   r8, [lr]\n"
    "adds  r8, r8, #1\n"
    "str   r8, [lr]\n"
    "cmp   r9, #0\n"
    "ite   lt\n"
    "movlt r7, #0xF0000000\n"
    "movge r7, #0x10000000\n"
    "4:\n"
    "str   r7, [r3, #(4 * \\k)]\n"
    ".endm\n"
    /* component k of z_j: rot_out1(R[3k] z'0 + R[3k+1] z'1 + R[3k+2] z'2) */
    ".macro snbr k\n"
    "ldr   r7, [r0, #(12 * \\k)]\n"
    "ldr   r8, [r0, #(12 * \\k + 4)]\n"
    "ldr   r9, [r0, #(12 * \\k + 8)]\n"
    "smull r10, r11, r7, r4\n"
    "smlal r10, r11, r8, r5\n"
    "smlal r10, r11, r9, r6\n"
    "adds  r10, r10, #0x20000000\n"
    "adc   r11, r11, #0\n"
    "lsr   r10, r10, #30\n"
    "orr   r10, r10, r11, lsl #2\n"
    "add   r7, r10, #0x10000000\n"
    "cmp   r7, #0x20000000\n"
    "bls   1f\n"
    "ldr   r7, [sp, #44]\n"
    "ldr   r8, [r7]\n"
    "adds  r8, r8, #1\n"
    "str   r8, [r7]\n"
    "cmp   r10, #0\n"
    "ite   gt\n"
    "movgt r10, #0x10000000\n"
    "movle r10, #0xF0000000\n"
    "1:\n"
    "str   r10, [r1, #(4 * \\k)]\n"
    ".endm\n"
    ".align 2\n"
    ".global sn_m4_icb_z\n"
    ".thumb_func\n"
    ".type sn_m4_icb_z, %function\n"
    "sn_m4_icb_z:\n"
    "push  {r4-r11, lr}\n"              /* R_j at [sp, #36], sh #40, sat #44 */
    "ldm   r1, {r4, r5, r6}\n"          /* y_j */
    "ldr   r10, [sp, #40]\n"            /* sh */
    "rsb   r11, r10, #32\n"
    "sub   r12, r10, #1\n"
    "mov   lr, #1\n"
    "lsl   r12, lr, r12\n"              /* bit = 2^(sh-1) */
    /* P: xx yy zz xy xz yz (bytes 0..20): rows (xx xy xz) (xy yy yz) (xz yz zz) */
    "snbz 0, 0, 12, 16\n"
    "snbz 1, 12, 4, 20\n"
    "snbz 2, 16, 20, 8\n"
    "ldm   r3, {r4, r5, r6}\n"          /* z'_j */
    "ldr   r0, [sp, #36]\n"             /* R_j */
    "snbr 0\n"
    "snbr 1\n"
    "snbr 2\n"
    "pop   {r4-r11, pc}\n"
    ".size sn_m4_icb_z, .-sn_m4_icb_z\n"
    ".purgem snbz\n"
    ".purgem snbr\n"
    ".popsection\n");

#else
typedef int sn_kernels_m4_ic_unused_; /* ISO C: no empty translation unit */
#endif
