/* sn_segment_m4.c -- Cortex-M4 (Thumb-2, DSP): a sheet node's star projection
 * on level 0 (sn_segment_sweep.c star(), seed 004 §3.2) in one assembly
 * function, sn_m4_star, the same integers as star(): GCC's C kept the ends'
 * sums, the mean and the shares in stack slots around a call of the turn
 * (turn_m4) per end (~130 instructions of bookkeeping an end, NUMERICS.md
 * "Segment sweeps, round 2"). Here:
 *  1. per end its segment's words, its turn factor +-kf1 and its end
 *     P = G + r30s(+-half, u) (SMMULR of +-4 half), summed in int64
 *     register pairs (ADDS/ADC of the sign);
 *  2. the mean sum round(2^30/k) >> 30 (UMULL + MLA: the sum's low word
 *     unsigned, its high word signed; |sum| < 2^32, so the mean < 2^31 is
 *     the low word of the shift), clamped and counted as sn_out;
 *  3. per end d = seg_out(m - P), t = r30s(d, omega gamma) (the last end:
 *     minus the others' sum, limited to 2^29, in int32: three shares
 *     <= 2^29 each), the turn of turn_m4 (its bias and 31 - sh from the
 *     operands, the limited e written into d's register) and G + t by
 *     seg_out. Every clamp is counted where star() counts it (the rare
 *     paths out of line); the turn's limiter is not counted (seg_lim).
 * Coarse levels (each segment's own half, words 12-14) keep star(). */
#include "sn_segment.h"

#if defined(SEG_M4)
typedef char sn_m4_star_layout_[offsetof(struct seg_m4_star, ls) == 24 && offsetof(struct seg_m4_star, m) == 32 &&
                                        offsetof(struct seg_m4_star, rs) == 68 &&
                                        offsetof(struct seg_m4_star, slot) == 88 &&
                                        offsetof(struct seg_m4_star, e) == 92 && SEG_W == 16 && SN_LIM == (1 << 28)
                                    ? 1
                                    : -1];

/* seg_out of register R (|v| <= 2^28 or clamped and counted): the test in line */
#define M4S_OUT(R, L) \
    "add   r12, " R ", #0x10000000\n" \
    "cmp   r12, #0x20000000\n"        \
    "bhi   " L "f\n"                  \
    L "0:\n"
/* its rare path: ls + 1, R = R > 0 ? 2^28 : -2^28, back */
#define M4S_OUT_SLOW(R, L) \
    L ":\n"                          \
    "ldr   r12, [r0, #24]\n"         \
    "add   r12, r12, #1\n"           \
    "str   r12, [r0, #24]\n"         \
    "cmp   " R ", #0\n"              \
    "mov   " R ", #0x10000000\n"     \
    "it    le\n"                     \
    "rsble " R ", " R ", #0\n"       \
    "b     " L "0b\n"

/* phase 1, component c of an end: P = G + r30s(h, u) into the slot, summed into LO:HI */
#define M4S_END(UO, GO, PO, LO, HI)              \
    "ldr   r11, [r10, #" UO "]\n"                \
    "smmulr r11, r12, r11\n"                     \
    "ldr   lr, [r10, #" GO "]\n"                 \
    "add   r11, r11, lr\n"                       \
    "str   r11, [r3, #" PO "]\n"                 \
    "adds  " LO ", " LO ", r11\n"                \
    "adc   " HI ", " HI ", r11, asr #31\n"
/* phase 2: the mean of component LO:HI (sum inv >> 30, rounded) into m[c] */
#define M4S_MEAN(LO, HI, MO, L)                  \
    "umull r10, r11, " LO ", r1\n"               \
    "mla   r11, " HI ", r1, r11\n"               \
    "adds  r10, r10, #0x20000000\n"              \
    "adc   r11, r11, #0\n"                       \
    "lsr   r10, r10, #30\n"                      \
    "orr   r10, r10, r11, lsl #2\n"              \
    M4S_OUT("r10", L)                            \
    "str   r10, [r0, #" MO "]\n"
/* phase 3: d_c = seg_out(m_c - P_c) into D (slot in r6) */
#define M4S_GAP(D, MO, PO, L)                    \
    "ldr   r10, [r0, #" MO "]\n"                 \
    "ldr   r11, [r6, #" PO "]\n"                 \
    "sub   " D ", r10, r11\n"                    \
    M4S_OUT(D, L)
/* t_c = r30s(d_c, g1n) (g1n in r12), l_c -= t_c */
#define M4S_SHARE(D, TO, LO)                     \
    "lsl   r10, " D ", #2\n"                     \
    "smmulr r10, r10, r12\n"                     \
    "str   r10, [r0, #" TO "]\n"                 \
    "ldr   r11, [r0, #" LO "]\n"                 \
    "sub   r11, r11, r10\n"                      \
    "str   r11, [r0, #" LO "]\n"
/* the last end's t_c = l_c limited to +-2^29 (seg_lim, not counted) */
#define M4S_LAST(TO, LO, L)                      \
    "ldr   r10, [r0, #" LO "]\n"                 \
    "add   r11, r10, #0x20000000\n"              \
    "cmp   r11, #0x40000000\n"                   \
    "bls   " L "f\n"                             \
    "cmp   r10, #0\n"                            \
    "mov   r10, #0x20000000\n"                   \
    "it    le\n"                                 \
    "rsble r10, r10, #0\n"                       \
    L ":\n"                                      \
    "str   r10, [r0, #" TO "]\n"
/* turn_m4's SEG_DOTU: r10 = 4 r30(A . u) (u in r7-r9) */
#define M4S_DOTU(A0, A1, A2)                     \
    "mov   r10, #0x20000000\n"                   \
    "mov   r11, #0\n"                            \
    "smlal r10, r11, " A0 ", r7\n"               \
    "smlal r10, r11, " A1 ", r8\n"               \
    "smlal r10, r11, " A2 ", r9\n"               \
    "lsr   r10, r10, #30\n"                      \
    "orr   r10, r10, r11, lsl #2\n"              \
    "lsl   r10, r10, #2\n"
/* turn_m4's SEG_E: D = seg_lim(seg_rsh(D kf, sh, bias), 2^28), kf in r5,
 * sh in r6, 31 - sh in lr; the clamp out of line (L) */
#define M4S_E(D, L)                              \
    "ldr   r10, [r0, #16]\n"                     \
    "mov   r11, #0\n"                            \
    "smlal r10, r11, " D ", r5\n"                \
    "lsr   r10, r10, r6\n"                       \
    "lsl   r12, r11, lr\n"                       \
    "orr   " D ", r10, r12, lsl #1\n"            \
    "asr   r11, r11, r6\n"                       \
    "add   r12, " D ", #0x10000000\n"            \
    "cmp   r12, #0x20000000\n"                   \
    "bhi   " L "f\n"                             \
    "cmp   r11, " D ", asr #31\n"                \
    "bne   " L "f\n"                             \
    L "0:\n"
#define M4S_E_SLOW(D, L)                         \
    L ":\n"                                      \
    "mov   " D ", #0x10000000\n"                 \
    "cmp   r11, #0\n"                            \
    "it    lt\n"                                 \
    "rsblt " D ", " D ", #0\n"                   \
    "b     " L "0b\n"
/* turn_m4's SEG_U: u_c' = r30(x_c f) (f in r10), stored */
#define M4S_U(X, UO)                             \
    "mov   r11, #0x20000000\n"                   \
    "mov   r12, #0\n"                            \
    "smlal r11, r12, " X ", r10\n"               \
    "lsr   r11, r11, #30\n"                      \
    "orr   r11, r11, r12, lsl #2\n"              \
    "str   r11, [r1, #" UO "]\n"
/* G_c + t_c, seg_out */
#define M4S_G(GO, TO, L)                         \
    "ldr   r10, [r0, #" TO "]\n"                 \
    "ldr   r11, [r1, #" GO "]\n"                 \
    "add   r11, r11, r10\n"                      \
    M4S_OUT("r11", L)                            \
    "str   r11, [r1, #" GO "]\n"

__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_star,\"ax\",%progbits\n"
    ".align 2\n"
    ".global sn_m4_star\n"
    ".thumb_func\n"
    ".type sn_m4_star, %function\n"
    "sn_m4_star:\n"
    "push  {r4-r11, lr}\n"
    /* phase 1: r1 seg, r2 sgn, r3 slot, r4:r5 r6:r7 r8:r9 the sums */
    "ldr   r1, [r0, #76]\n"
    "ldr   r2, [r0, #80]\n"
    "ldr   r3, [r0, #84]\n"
    "add   r3, r3, r3, lsl #1\n"
    "add   r3, r0, r3, lsl #3\n"
    "add   r3, r3, #68\n"            /* e + 24 (k - 1) */
    "str   r3, [r0, #72]\n"
    "add   r3, r0, #92\n"
    "movs  r4, #0\n"
    "str   r4, [r0, #44]\n"
    "str   r4, [r0, #48]\n"
    "str   r4, [r0, #52]\n"
    "movs  r5, #0\n"
    "movs  r6, #0\n"
    "movs  r7, #0\n"
    "movs  r8, #0\n"
    "movs  r9, #0\n"
    "1:\n"
    "ldr   r10, [r1], #4\n"
    "ldr   r11, [r0, #0]\n"
    "add   r10, r11, r10, lsl #6\n"  /* S + SEG_W seg[j] */
    "str   r10, [r3, #12]\n"
    "ldr   r12, [r0, #4]\n"
    "ldr   lr, [r0, #8]\n"
    "ldr   r11, [r2], #4\n"
    "cmp   r11, #0\n"
    "itt   lt\n"
    "rsblt r12, r12, #0\n"
    "rsblt lr, lr, #0\n"
    "str   lr, [r3, #16]\n"
    M4S_END("12", "0", "0", "r4", "r5")
    M4S_END("16", "4", "4", "r6", "r7")
    M4S_END("20", "8", "8", "r8", "r9")
    "ldr   r11, [r0, #72]\n"
    "cmp   r3, r11\n"
    "add   r3, r3, #24\n"
    "bne   1b\n"
    /* phase 2: the mean */
    "ldr   r1, [r0, #28]\n"
    M4S_MEAN("r4", "r5", "32", "11")
    M4S_MEAN("r6", "r7", "36", "12")
    M4S_MEAN("r8", "r9", "40", "13")
    /* phase 3: per end; r6 its slot until the turn */
    "add   r6, r0, #92\n"
    "3:\n"
    "ldr   r1, [r6, #12]\n"
    "ldr   r5, [r6, #16]\n"
    M4S_GAP("r2", "32", "0", "21")
    M4S_GAP("r3", "36", "4", "22")
    M4S_GAP("r4", "40", "8", "23")
    "ldr   r10, [r0, #72]\n"
    "cmp   r6, r10\n"
    "beq   4f\n"
    "ldr   r12, [r0, #20]\n"
    M4S_SHARE("r2", "56", "44")
    M4S_SHARE("r3", "60", "48")
    M4S_SHARE("r4", "64", "52")
    "b     5f\n"
    "4:\n"
    M4S_LAST("56", "44", "41")
    M4S_LAST("60", "48", "42")
    M4S_LAST("64", "52", "43")
    "5:\n"
    /* the turn (turn_m4): d r2-r4, kf r5, sh r6, u r7-r9, 31 - sh in lr */
    "str   r6, [r0, #88]\n"
    "ldr   r6, [r0, #12]\n"
    "ldr   lr, [r0, #68]\n"
    "ldr   r7, [r1, #12]\n"
    "ldr   r8, [r1, #16]\n"
    "ldr   r9, [r1, #20]\n"
    M4S_DOTU("r2", "r3", "r4")
    "smmulr r11, r10, r7\n"
    "sub   r2, r2, r11\n"
    "smmulr r11, r10, r8\n"
    "sub   r3, r3, r11\n"
    "smmulr r11, r10, r9\n"
    "sub   r4, r4, r11\n"
    M4S_E("r2", "51")
    M4S_E("r3", "52")
    M4S_E("r4", "53")
    M4S_DOTU("r2", "r3", "r4")
    "smmulr r11, r10, r7\n"
    "add   r7, r7, r2\n"
    "sub   r7, r7, r11\n"
    "smmulr r11, r10, r8\n"
    "add   r8, r8, r3\n"
    "sub   r8, r8, r11\n"
    "smmulr r11, r10, r9\n"
    "add   r9, r9, r4\n"
    "sub   r9, r9, r11\n"
    /* f = (3 2^60 + 2^30 - |x|^2) >> 31 */
    "smull r10, r11, r7, r7\n"
    "smlal r10, r11, r8, r8\n"
    "smlal r10, r11, r9, r9\n"
    "rsbs  r10, r10, #0x40000000\n"
    "mov   r12, #0x30000000\n"
    "sbc   r11, r12, r11\n"
    "lsr   r10, r10, #31\n"
    "orr   r10, r10, r11, lsl #1\n"
    M4S_U("r7", "12")
    M4S_U("r8", "16")
    M4S_U("r9", "20")
    /* the translation */
    M4S_G("0", "56", "61")
    M4S_G("4", "60", "62")
    M4S_G("8", "64", "63")
    "ldr   r6, [r0, #88]\n"
    "ldr   r10, [r0, #72]\n"
    "cmp   r6, r10\n"
    "add   r6, r6, #24\n"
    "bne   3b\n"
    "pop   {r4-r11, pc}\n"
    /* the rare paths */
    M4S_OUT_SLOW("r10", "11")
    M4S_OUT_SLOW("r10", "12")
    M4S_OUT_SLOW("r10", "13")
    M4S_OUT_SLOW("r2", "21")
    M4S_OUT_SLOW("r3", "22")
    M4S_OUT_SLOW("r4", "23")
    M4S_E_SLOW("r2", "51")
    M4S_E_SLOW("r3", "52")
    M4S_E_SLOW("r4", "53")
    M4S_OUT_SLOW("r11", "61")
    M4S_OUT_SLOW("r11", "62")
    M4S_OUT_SLOW("r11", "63")
    ".size sn_m4_star, .-sn_m4_star\n"
    ".popsection\n");
#else
typedef int sn_segment_m4_empty_; /* ISO C: a translation unit declares something */
#endif
