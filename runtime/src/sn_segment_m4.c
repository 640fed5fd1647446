/* sn_segment_m4.c -- Cortex-M4 (Thumb-2, DSP): level 0's sheet-node star
 * projection and pair projection (sn_segment_sweep.c star(), pair_core(),
 * seed 004 §3.2) in assembly, the same integers and clamp counts. GCC's C
 * kept the ends' sums, the mean and the shares in stack slots around a
 * call of the turn (turn_m4) per end: ~130 instructions of bookkeeping an
 * end (NUMERICS.md "Segment sweeps, round 2"). Here, per end a slot of 8
 * words (struct seg_m4_star e[]: its segment's words, P then d, its turn
 * factor, t) moved by LDM/STM:
 *  star: 1. per end the segment's words, +-kf1 and P = G + r30s(+-half, u)
 *     (SMMULR of +-4 half); 2. the sums in int64 register pairs (ADDS/ADC
 *     of the sign) and the mean sum round(2^30/k) >> 30 (UMULL + MLA: the
 *     sum's low word unsigned, its high word signed; |sum| < 2^32, so the
 *     mean < 2^31 is the shift's low word), clamped and counted (sn_out);
 *     3. per end d = seg_out(m - P), t = r30s(d, omega gamma) with the
 *     others' sum l -= t in registers, the last end's t = l limited to
 *     2^29 (int32: three shares <= 2^29 each);
 *  pair: the two ends, d = seg_out(P_b - P_a), t = r30s(d, omega gamma/2),
 *     the second end's slot -d, -t (pair_core's signs), +-kf0;
 *  then for each slot (.Lsnm4_moves) turn_m4's turn (its bias and 31 - sh
 *  from the operands, the limited e in d's registers) and G + t by seg_out.
 * Every clamp is counted where the C counts it (the rare paths out of
 * line); the turn's limiter and the last share's are not (seg_lim).
 * Coarse levels (each segment's own half, words 12-14) keep the C. */
#include "sn_segment.h"

#if defined(SEG_M4)
typedef char sn_m4_star_layout_[offsetof(struct seg_m4_star, sh) == 12 && offsetof(struct seg_m4_star, rs) == 16 &&
                                        offsetof(struct seg_m4_star, ls) == 28 &&
                                        offsetof(struct seg_m4_star, plast) == 36 &&
                                        offsetof(struct seg_m4_star, slot) == 52 &&
                                        offsetof(struct seg_m4_star, gh) == 60 &&
                                        offsetof(struct seg_m4_star, e) == 64 && sizeof(struct seg_m4_slot) == 32 &&
                                        offsetof(struct seg_m4_slot, f) == 16 && SEG_W == 16 && SN_LIM == (1 << 28)
                                    ? 1
                                    : -1];

/* seg_out of register R (|v| <= 2^28, else clamped and counted), T a free
 * register: the test in line, the clamp out of line at label L */
#define M4S_OUT(R, T, L)                 \
    "add   " T ", " R ", #0x10000000\n"  \
    "cmp   " T ", #0x20000000\n"         \
    "bhi   " L "f\n"                     \
    L "0:\n"
/* its rare path: ls + 1 (T free), R = R > 0 ? 2^28 : -2^28, back */
#define M4S_OUT_SLOW(R, T, L)            \
    L ":\n"                              \
    "ldr   " T ", [r0, #28]\n"           \
    "add   " T ", " T ", #1\n"           \
    "str   " T ", [r0, #28]\n"           \
    "cmp   " R ", #0\n"                  \
    "mov   " R ", #0x10000000\n"         \
    "it    le\n"                         \
    "rsble " R ", " R ", #0\n"           \
    "b     " L "0b\n"
/* the mean of the sum LO:HI (inv in lr: sum inv >> 30, rounded) into M */
#define M4S_MEAN(LO, HI, M, L)                   \
    "umull r10, r11, " LO ", lr\n"               \
    "mla   r11, " HI ", lr, r11\n"               \
    "adds  r10, r10, #0x20000000\n"              \
    "adc   r11, r11, #0\n"                       \
    "lsr   r10, r10, #30\n"                      \
    "orr   " M ", r10, r11, lsl #2\n"            \
    M4S_OUT(M, "r12", L)
/* t = r30s(D, g1n) (g1n in r12) into D, l -= t */
#define M4S_SHARE(D, LS)                         \
    "lsl   " D ", " D ", #2\n"                   \
    "smmulr " D ", " D ", r12\n"                 \
    "sub   " LS ", " LS ", " D "\n"
/* the last end's t = l limited to +-2^29 (seg_lim, not counted), in place */
#define M4S_LAST(LS, L)                          \
    "add   r10, " LS ", #0x20000000\n"           \
    "cmp   r10, #0x40000000\n"                   \
    "bls   " L "f\n"                             \
    "cmp   " LS ", #0\n"                         \
    "mov   " LS ", #0x20000000\n"                \
    "it    le\n"                                 \
    "rsble " LS ", " LS ", #0\n"                 \
    L ":\n"
/* turn_m4's SEG_DOTU: r10 = 4 r30(d . u) (d in r2-r4, u in r7-r9) */
#define M4S_DOTU                                 \
    "mov   r10, #0x20000000\n"                   \
    "mov   r11, #0\n"                            \
    "smlal r10, r11, r2, r7\n"                   \
    "smlal r10, r11, r3, r8\n"                   \
    "smlal r10, r11, r4, r9\n"                   \
    "lsr   r10, r10, #30\n"                      \
    "orr   r10, r10, r11, lsl #2\n"              \
    "lsl   r10, r10, #2\n"
/* turn_m4's SEG_E: D = seg_lim(seg_rsh(D kf, sh, bias), 2^28), kf in r5,
 * sh in r6, 31 - sh in lr; the clamp out of line (L) */
#define M4S_E(D, L)                              \
    "ldr   r10, [r0, #20]\n"                     \
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
/* turn_m4's SEG_U: X = r30(X f) (f in r10) */
#define M4S_U(X)                                 \
    "mov   r11, #0x20000000\n"                   \
    "mov   r12, #0\n"                            \
    "smlal r11, r12, " X ", r10\n"               \
    "lsr   r11, r11, #30\n"                      \
    "orr   " X ", r11, r12, lsl #2\n"
/* P = G + r30s(h, u) of an end: G in G0-G2, u in U0-U2, h in H; P in G0-G2 */
#define M4S_P(G0, G1, G2, U0, U1, U2, H)         \
    "smmulr " U0 ", " H ", " U0 "\n"             \
    "add   " G0 ", " G0 ", " U0 "\n"             \
    "smmulr " U1 ", " H ", " U1 "\n"             \
    "add   " G1 ", " G1 ", " U1 "\n"             \
    "smmulr " U2 ", " H ", " U2 "\n"             \
    "add   " G2 ", " G2 ", " U2 "\n"

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
    /* 1. per end: slot r11 = {S_j, P, f} (r1 seg, r2 sgn) */
    "ldr   r1, [r0, #40]\n"
    "ldr   r2, [r0, #44]\n"
    "ldr   r3, [r0, #48]\n"
    "add   r3, r0, r3, lsl #5\n"
    "add   r3, r3, #32\n"            /* e + 32 (k - 1) */
    "str   r3, [r0, #36]\n"
    "add   r11, r0, #64\n"
    "1:\n"
    "ldr   r3, [r1], #4\n"
    "ldr   r12, [r0, #0]\n"
    "add   r3, r12, r3, lsl #6\n"    /* S + SEG_W seg[j] */
    "ldm   r3, {r4-r9}\n"            /* G, u */
    "ldr   r10, [r0, #4]\n"
    "ldr   lr, [r0, #8]\n"
    "ldr   r12, [r2], #4\n"
    "cmp   r12, #0\n"
    "itt   lt\n"
    "rsblt r10, r10, #0\n"
    "rsblt lr, lr, #0\n"
    M4S_P("r4", "r5", "r6", "r7", "r8", "r9", "r10")
    "mov   r7, lr\n"
    "stm   r11, {r3-r7}\n"
    "add   r11, r11, #32\n"
    "ldr   r12, [r0, #36]\n"
    "cmp   r11, r12\n"
    "bls   1b\n"
    /* 2. the sums r1:r2 r3:r4 r5:r6, the mean r7-r9 */
    "movs  r1, #0\n"
    "movs  r2, #0\n"
    "movs  r3, #0\n"
    "movs  r4, #0\n"
    "movs  r5, #0\n"
    "movs  r6, #0\n"
    "add   r11, r0, #64\n"
    "2:\n"
    "ldm   r11, {r7-r10}\n"
    "adds  r1, r1, r8\n"
    "adc   r2, r2, r8, asr #31\n"
    "adds  r3, r3, r9\n"
    "adc   r4, r4, r9, asr #31\n"
    "adds  r5, r5, r10\n"
    "adc   r6, r6, r10, asr #31\n"
    "add   r11, r11, #32\n"
    "cmp   r11, r12\n"
    "bls   2b\n"
    "ldr   lr, [r0, #32]\n"
    M4S_MEAN("r1", "r2", "r7", "11")
    M4S_MEAN("r3", "r4", "r8", "12")
    M4S_MEAN("r5", "r6", "r9", "13")
    /* 3. per end d (over P) and t; l in r4-r6, g1n r12, the last slot lr */
    "movs  r4, #0\n"
    "movs  r5, #0\n"
    "movs  r6, #0\n"
    "add   r11, r0, #64\n"
    "ldr   r12, [r0, #24]\n"
    "ldr   lr, [r0, #36]\n"
    "3:\n"
    "add   r10, r11, #4\n"
    "ldm   r10, {r1-r3}\n"
    "sub   r1, r7, r1\n"
    M4S_OUT("r1", "r10", "21")
    "sub   r2, r8, r2\n"
    M4S_OUT("r2", "r10", "22")
    "sub   r3, r9, r3\n"
    M4S_OUT("r3", "r10", "23")
    "add   r10, r11, #4\n"
    "stm   r10, {r1-r3}\n"
    "cmp   r11, lr\n"
    "beq   4f\n"
    M4S_SHARE("r1", "r4")
    M4S_SHARE("r2", "r5")
    M4S_SHARE("r3", "r6")
    "add   r10, r11, #20\n"
    "stm   r10, {r1-r3}\n"
    "add   r11, r11, #32\n"
    "b     3b\n"
    "4:\n"
    M4S_LAST("r4", "41")
    M4S_LAST("r5", "42")
    M4S_LAST("r6", "43")
    "add   r10, r11, #20\n"
    "stm   r10, {r4-r6}\n"
    "add   r6, r0, #64\n"
    /* the moves of the slots r6 .. plast */
    ".Lsnm4_moves:\n"
    "ldm   r6!, {r1-r5}\n"           /* S_j, d, f */
    "str   r6, [r0, #52]\n"
    "ldrd  r6, lr, [r0, #12]\n"      /* sh, 31 - sh */
    "ldrd  r7, r8, [r1, #12]\n"
    "ldr   r9, [r1, #20]\n"
    /* the turn (turn_m4): d_perp = d - r30s(du, u) */
    M4S_DOTU
    "smmulr r11, r10, r7\n"
    "sub   r2, r2, r11\n"
    "smmulr r11, r10, r8\n"
    "sub   r3, r3, r11\n"
    "smmulr r11, r10, r9\n"
    "sub   r4, r4, r11\n"
    M4S_E("r2", "51")
    M4S_E("r3", "52")
    M4S_E("r4", "53")
    /* x = u + e - r30s(eu, u) */
    M4S_DOTU
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
    M4S_U("r7")
    M4S_U("r8")
    M4S_U("r9")
    "strd  r7, r8, [r1, #12]\n"
    "str   r9, [r1, #20]\n"
    /* G + t */
    "ldr   r6, [r0, #52]\n"
    "ldm   r6!, {r2-r4}\n"
    "ldrd  r7, r8, [r1]\n"
    "ldr   r9, [r1, #8]\n"
    "add   r7, r7, r2\n"
    M4S_OUT("r7", "r12", "61")
    "add   r8, r8, r3\n"
    M4S_OUT("r8", "r12", "62")
    "add   r9, r9, r4\n"
    M4S_OUT("r9", "r12", "63")
    "strd  r7, r8, [r1]\n"
    "str   r9, [r1, #8]\n"
    "ldr   r10, [r0, #36]\n"
    "cmp   r6, r10\n"
    "bls   .Lsnm4_moves\n"
    "pop   {r4-r11, pc}\n"
    /* the rare paths */
    M4S_OUT_SLOW("r7", "r12", "11")
    M4S_OUT_SLOW("r8", "r12", "12")
    M4S_OUT_SLOW("r9", "r12", "13")
    M4S_OUT_SLOW("r1", "r10", "21")
    M4S_OUT_SLOW("r2", "r10", "22")
    M4S_OUT_SLOW("r3", "r10", "23")
    M4S_E_SLOW("r2", "51")
    M4S_E_SLOW("r3", "52")
    M4S_E_SLOW("r4", "53")
    M4S_OUT_SLOW("r7", "r12", "61")
    M4S_OUT_SLOW("r8", "r12", "62")
    M4S_OUT_SLOW("r9", "r12", "63")
    ".size sn_m4_star, .-sn_m4_star\n"
    /* the pair: r1 a, r2 b, r3 signs; slots e[0] (a) and e[1] (b) */
    ".align 2\n"
    ".global sn_m4_pair\n"
    ".thumb_func\n"
    ".type sn_m4_pair, %function\n"
    "sn_m4_pair:\n"
    "push  {r4-r11, lr}\n"
    "ldr   r12, [r0, #0]\n"
    "add   r1, r12, r1, lsl #6\n"
    "add   r2, r12, r2, lsl #6\n"
    "ldr   r10, [r0, #4]\n"          /* 4 half */
    "ldr   lr, [r0, #56]\n"          /* kf0 */
    "mov   r11, r10\n"
    "mov   r12, lr\n"
    "tst   r3, #1\n"
    "itt   ne\n"
    "rsbne r11, r10, #0\n"
    "rsbne r12, lr, #0\n"
    "str   r1, [r0, #64]\n"
    "str   r12, [r0, #80]\n"
    "tst   r3, #2\n"
    "itt   ne\n"
    "rsbne r10, r10, #0\n"
    "rsbne lr, lr, #0\n"
    "str   r2, [r0, #96]\n"
    "str   lr, [r0, #112]\n"
    "ldm   r1, {r4-r9}\n"
    M4S_P("r4", "r5", "r6", "r7", "r8", "r9", "r11")
    "ldm   r2, {r7-r9, r11, r12, lr}\n"
    M4S_P("r7", "r8", "r9", "r11", "r12", "lr", "r10")
    "sub   r1, r7, r4\n"
    M4S_OUT("r1", "r12", "71")
    "sub   r2, r8, r5\n"
    M4S_OUT("r2", "r12", "72")
    "sub   r3, r9, r6\n"
    M4S_OUT("r3", "r12", "73")
    "ldr   r12, [r0, #60]\n"         /* omega gamma / 2 */
    "lsl   r4, r1, #2\n"
    "smmulr r4, r4, r12\n"
    "lsl   r5, r2, #2\n"
    "smmulr r5, r5, r12\n"
    "lsl   r6, r3, #2\n"
    "smmulr r6, r6, r12\n"
    "add   r10, r0, #68\n"
    "stm   r10, {r1-r3}\n"
    "add   r10, r0, #84\n"
    "stm   r10, {r4-r6}\n"
    "rsb   r1, r1, #0\n"
    "rsb   r2, r2, #0\n"
    "rsb   r3, r3, #0\n"
    "rsb   r4, r4, #0\n"
    "rsb   r5, r5, #0\n"
    "rsb   r6, r6, #0\n"
    "add   r10, r0, #100\n"
    "stm   r10, {r1-r3}\n"
    "add   r10, r0, #116\n"
    "stm   r10, {r4-r6}\n"
    "add   r10, r0, #96\n"
    "str   r10, [r0, #36]\n"
    "add   r6, r0, #64\n"
    "b     .Lsnm4_moves\n"
    M4S_OUT_SLOW("r1", "r12", "71")
    M4S_OUT_SLOW("r2", "r12", "72")
    M4S_OUT_SLOW("r3", "r12", "73")
    ".size sn_m4_pair, .-sn_m4_pair\n"
    /* an attachment's pins (r1 T; seg, sgn, plast set): per slot P = G +-
     * r30s(half, u) from the positive half (end_of), clamped; d = T - P
     * (QSUB, then sn_add's clamp); t = r30s(d, omega gamma), clamped; +-kf1 */
    ".align 2\n"
    ".global sn_m4_pins\n"
    ".thumb_func\n"
    ".type sn_m4_pins, %function\n"
    "sn_m4_pins:\n"
    "push  {r4-r11, lr}\n"
    "ldr   r2, [r0, #40]\n"
    "ldr   r3, [r0, #44]\n"
    "ldr   r10, [r0, #4]\n"
    "add   r11, r0, #64\n"
    "8:\n"
    "ldr   r12, [r2], #4\n"
    "ldr   lr, [r0, #0]\n"
    "add   lr, lr, r12, lsl #6\n"
    "str   lr, [r11]\n"
    "ldm   lr, {r4-r9}\n"
    "smmulr r7, r10, r7\n"
    "smmulr r8, r10, r8\n"
    "smmulr r9, r10, r9\n"
    "ldr   lr, [r0, #8]\n"
    "ldr   r12, [r3], #4\n"
    "cmp   r12, #0\n"
    "itttt le\n"
    "rsble r7, r7, #0\n"
    "rsble r8, r8, #0\n"
    "rsble r9, r9, #0\n"
    "rsble lr, lr, #0\n"
    "str   lr, [r11, #16]\n"
    "add   r4, r4, r7\n"
    M4S_OUT("r4", "r12", "81")
    "add   r5, r5, r8\n"
    M4S_OUT("r5", "r12", "82")
    "add   r6, r6, r9\n"
    M4S_OUT("r6", "r12", "83")
    "ldm   r1, {r7-r9}\n"
    "qsub  r4, r7, r4\n"
    M4S_OUT("r4", "r12", "84")
    "qsub  r5, r8, r5\n"
    M4S_OUT("r5", "r12", "85")
    "qsub  r6, r9, r6\n"
    M4S_OUT("r6", "r12", "86")
    "add   r12, r11, #4\n"
    "stm   r12, {r4-r6}\n"
    "ldr   r12, [r0, #24]\n"
    "lsl   r7, r4, #2\n"
    "smmulr r7, r7, r12\n"
    M4S_OUT("r7", "lr", "87")
    "lsl   r8, r5, #2\n"
    "smmulr r8, r8, r12\n"
    M4S_OUT("r8", "lr", "88")
    "lsl   r9, r6, #2\n"
    "smmulr r9, r9, r12\n"
    M4S_OUT("r9", "lr", "89")
    "add   r12, r11, #20\n"
    "stm   r12, {r7-r9}\n"
    "add   r11, r11, #32\n"
    "ldr   r12, [r0, #36]\n"
    "cmp   r11, r12\n"
    "bls   8b\n"
    "add   r6, r0, #64\n"
    "b     .Lsnm4_moves\n"
    M4S_OUT_SLOW("r4", "r12", "81")
    M4S_OUT_SLOW("r5", "r12", "82")
    M4S_OUT_SLOW("r6", "r12", "83")
    M4S_OUT_SLOW("r4", "r12", "84")
    M4S_OUT_SLOW("r5", "r12", "85")
    M4S_OUT_SLOW("r6", "r12", "86")
    M4S_OUT_SLOW("r7", "lr", "87")
    M4S_OUT_SLOW("r8", "lr", "88")
    M4S_OUT_SLOW("r9", "lr", "89")
    ".size sn_m4_pins, .-sn_m4_pins\n"

    ".popsection\n");
#else
typedef int sn_segment_m4_empty_; /* ISO C: a translation unit declares something */
#endif
