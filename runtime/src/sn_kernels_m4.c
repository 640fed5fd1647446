/* sn_kernels_m4.c -- Cortex-M4/M7 (ARMv7E-M, DSP extension) kernels of
 * sn_kernels.h, fixed flavour. sn_k_cell_mul's rows in Thumb-2 assembly
 * (GCC's C spilled the row sums), sn_k_cell_mul2's too (one output
 * component of both products at a time); the CG dot and axpy in C written
 * for one SMLAL per multiply-add. The same
 * exact products as the scalar reference, summed in another order
 * (sn_kernels.h, KERNELS.md "SIMD kernels"). */
#include "sn_kernels.h"
#include "sn_instance.h" /* bitlen64 */
/* outside the #if: tools/amalgamate.sh inlines a header at its first
 * include only, so under a false #if it would be lost to sn_precond.c */
#include "sn_kernels_ic.h" /* sn_k_ic_row_ref */
#include "sn_kernels_rot.h" /* sn_k_out_w */

#if defined(SN_KERNELS_M4)
#define SN_M4_S_(x) #x
#define SN_M4_S(x) SN_M4_S_(x)

/* The cell product (sn_k_cell_mul) in Thumb-2, sn_m4_cell_mul: l zeroed by
 * STRD, then row i = 0..nf-1 of the listed corners: row i's three int64
 * sums stay in r0..r5 for the whole row (from l[3i..], the transposed sums
 * of the rows above): the diagonal block (a,a), then each block (i,j),
 * j > i, decoded once (LDRSH, LSL by its exponent: m 2^e, |.| < 2^27, exact
 * in int32) and used both ways, column c at a time: s_r += B_rc b_c (SMLAL)
 * and corner j's sum t_c += B_rc a_r in r6:r7, loaded and stored once
 * (LDRD/STRD). a, the pointers and the ends live on the stack (GCC's C
 * spilled the sums: ~100 instructions a block, here 72); each row's
 * pointers (SN_CELLK_OFFIDX's base a (13 - a) / 2 - 1) are formed here, not
 * by a C loop around a call per row ("M4 round 3"). The same exact
 * products as the reference, another order (KERNELS.md "SIMD kernels"). */
void sn_m4_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l);
__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_cell_mul,\"ax\",%progbits\n"
    ".set snm1_diag, " SN_M4_S(SN_CELLK_DIAG) "\n"
    ".set snm1_off, " SN_M4_S(SN_CELLK_OFF) "\n"
    ".set snm1_exp, " SN_M4_S(SN_CELLK_EXP) "\n"
    ".align 2\n"
    ".global sn_m4_cell_mul\n"
    ".thumb_func\n"
    ".type sn_m4_cell_mul, %function\n"
    "sn_m4_cell_mul:\n"
    "push  {r4-r11, lr}\n"
    "sub   sp, sp, #48\n"          /* [sp] a0 a1 a2 fcp ub m0 e0 lend s K fci ua; l at [sp, #84] */
    "ldr   r12, [sp, #84]\n"
    "str   r0, [sp, #36]\n"
    "str   r1, [sp, #40]\n"
    "str   r3, [sp, #44]\n"
    "str   r12, [sp, #32]\n"
    "add   r4, r2, r2, lsl #1\n"
    "add   r4, r12, r4, lsl #3\n"  /* lend = l + 3 nf */
    "str   r4, [sp, #28]\n"
    "mov   r5, #0\n"
    "mov   r6, #0\n"
    "0:\n"                          /* l = 0, a corner at a time (nf >= 1) */
    "strd  r5, r6, [r12], #8\n"
    "strd  r5, r6, [r12], #8\n"
    "strd  r5, r6, [r12], #8\n"
    "cmp   r12, r4\n"
    "bne   0b\n"
    "3:\n"                          /* row i */
    "ldr   r1, [sp, #40]\n"
    "ldrb  r2, [r1], #1\n"          /* a = fc[i] */
    "str   r1, [sp, #40]\n"
    "str   r1, [sp, #12]\n"         /* fcp = fc + i + 1 */
    "ldr   r0, [sp, #36]\n"
    "rsb   r3, r2, #13\n"
    "mul   r3, r3, r2\n"
    "lsr   r3, r3, #1\n"
    "sub   r3, r3, #1\n"            /* base: SN_CELLK_OFFIDX(a, b) = base + b */
    "add   r4, r0, r3, lsl #4\n"
    "add   r4, r4, r3, lsl #1\n"
    "add   r4, r4, #snm1_off\n"
    "str   r4, [sp, #20]\n"         /* m0 = K + OFF + 18 base */
    "add   r4, r0, r3\n"
    "addw  r4, r4, #snm1_exp\n"
    "str   r4, [sp, #24]\n"         /* e0 = K + EXP + base */
    "add   r10, r2, r2, lsl #1\n"
    "add   r10, r0, r10, lsl #3\n"
    ".if snm1_diag\n"
    "add   r10, r10, #snm1_diag\n"
    ".endif\n"                      /* d = K + DIAG + 24 a */
    "ldr   r2, [sp, #44]\n"         /* ua */
    "add   r3, r2, #12\n"
    "str   r3, [sp, #16]\n"         /* ub = ua + 3 */
    "str   r3, [sp, #44]\n"         /* the next row's ua */
    "ldm   r2, {r6-r8}\n"           /* a0 a1 a2 */
    "stm   sp, {r6-r8}\n"
    "ldr   r0, [sp, #32]\n"
    "add   lr, r0, #24\n"           /* lb = l + 3 (i + 1) */
    "ldm   r0, {r0-r5}\n"           /* s0 s1 s2, lo:hi */
    "ldr   r12, [r10]\n"            /* diagonal: xx yy zz xy xz yz */
    "smlal r0, r1, r12, r6\n"
    "ldr   r12, [r10, #12]\n"
    "smlal r0, r1, r12, r7\n"
    "smlal r2, r3, r12, r6\n"
    "ldr   r12, [r10, #16]\n"
    "smlal r0, r1, r12, r8\n"
    "smlal r4, r5, r12, r6\n"
    "ldr   r12, [r10, #4]\n"
    "smlal r2, r3, r12, r7\n"
    "ldr   r12, [r10, #20]\n"
    "smlal r2, r3, r12, r8\n"
    "smlal r4, r5, r12, r7\n"
    "ldr   r12, [r10, #8]\n"
    "smlal r4, r5, r12, r8\n"
    "ldr   r12, [sp, #28]\n"
    "cmp   lr, r12\n"
    "beq   2f\n"                    /* the last row: no block (i,j) */
    "1:\n"
    "ldr   r12, [sp, #12]\n"
    "ldrb  r9, [r12], #1\n"         /* b = *fcp++ */
    "str   r12, [sp, #12]\n"
    "ldr   r12, [sp, #24]\n"
    "ldrb  r11, [r12, r9]\n"        /* e */
    "ldr   r12, [sp, #20]\n"
    "add   r10, r12, r9, lsl #4\n"
    "add   r10, r10, r9, lsl #1\n"  /* m = m0 + 18 b */
    "ldr   r12, [sp, #16]\n"
    "ldr   r9, [r12, #0]\n"        /* b_0 */
    "ldrd  r6, r7, [lr, #0]\n"     /* t = lb[0] */
    "ldrsh r8, [r10, #0]\n"
    "lsl   r8, r8, r11\n"
    "smlal r0, r1, r8, r9\n"
    "ldr   r12, [sp, #0]\n"
    "smlal r6, r7, r8, r12\n"
    "ldrsh r8, [r10, #6]\n"
    "lsl   r8, r8, r11\n"
    "smlal r2, r3, r8, r9\n"
    "ldr   r12, [sp, #4]\n"
    "smlal r6, r7, r8, r12\n"
    "ldrsh r8, [r10, #12]\n"
    "lsl   r8, r8, r11\n"
    "smlal r4, r5, r8, r9\n"
    "ldr   r12, [sp, #8]\n"
    "smlal r6, r7, r8, r12\n"
    "strd  r6, r7, [lr, #0]\n"
    "ldr   r12, [sp, #16]\n"
    "ldr   r9, [r12, #4]\n"        /* b_1 */
    "ldrd  r6, r7, [lr, #8]\n"     /* t = lb[1] */
    "ldrsh r8, [r10, #2]\n"
    "lsl   r8, r8, r11\n"
    "smlal r0, r1, r8, r9\n"
    "ldr   r12, [sp, #0]\n"
    "smlal r6, r7, r8, r12\n"
    "ldrsh r8, [r10, #8]\n"
    "lsl   r8, r8, r11\n"
    "smlal r2, r3, r8, r9\n"
    "ldr   r12, [sp, #4]\n"
    "smlal r6, r7, r8, r12\n"
    "ldrsh r8, [r10, #14]\n"
    "lsl   r8, r8, r11\n"
    "smlal r4, r5, r8, r9\n"
    "ldr   r12, [sp, #8]\n"
    "smlal r6, r7, r8, r12\n"
    "strd  r6, r7, [lr, #8]\n"
    "ldr   r12, [sp, #16]\n"
    "ldr   r9, [r12, #8]\n"        /* b_2 */
    "ldrd  r6, r7, [lr, #16]\n"     /* t = lb[2] */
    "ldrsh r8, [r10, #4]\n"
    "lsl   r8, r8, r11\n"
    "smlal r0, r1, r8, r9\n"
    "ldr   r12, [sp, #0]\n"
    "smlal r6, r7, r8, r12\n"
    "ldrsh r8, [r10, #10]\n"
    "lsl   r8, r8, r11\n"
    "smlal r2, r3, r8, r9\n"
    "ldr   r12, [sp, #4]\n"
    "smlal r6, r7, r8, r12\n"
    "ldrsh r8, [r10, #16]\n"
    "lsl   r8, r8, r11\n"
    "smlal r4, r5, r8, r9\n"
    "ldr   r12, [sp, #8]\n"
    "smlal r6, r7, r8, r12\n"
    "strd  r6, r7, [lr, #16]\n"
    "ldr   r12, [sp, #16]\n"
    "add   r12, r12, #12\n"
    "str   r12, [sp, #16]\n"        /* ub += 3 */
    "add   lr, lr, #24\n"           /* lb += 3 */
    "ldr   r12, [sp, #28]\n"
    "cmp   lr, r12\n"
    "bne   1b\n"
    "2:\n"
    "ldr   r12, [sp, #32]\n"
    "stm   r12!, {r0-r5}\n"
    "str   r12, [sp, #32]\n"
    "ldr   r11, [sp, #28]\n"
    "cmp   r12, r11\n"
    "bne   3b\n"
    "add   sp, sp, #48\n"
    "pop   {r4-r11, pc}\n"
    ".size sn_m4_cell_mul, .-sn_m4_cell_mul\n"
    ".popsection\n");

void sn_k_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l) {
    uint32_t i;
    if (nf) sn_m4_cell_mul(K, fc, nf, u, l);
    for (i = 0; i < 3 * nf; i++) SN_RANGE(SN_WITHIN(l[i], 60), "cell row beyond 24 * 2^55", l[i]);
    (void)i;
}

/* The right-hand side's two products (sn_k_cell_mul2) in Thumb-2
 * (sn_m4_cell_mul2), one output component at a time: l1[3a+r] and l2[3a+r]
 * in r10:r11 and r12:lr, over the blocks b = 1..7 (corner 0's operands are
 * 0, the contract): row r of block (a,b) (b > a), column r of block (b,a)
 * (b < a) or row r of the diagonal block, its 3 entries decoded (LDRSH, LSL
 * by the block's exponent) into r4-r6 and used for both vectors, u1_b and
 * u2_b by LDM with writeback (r1, r2 walk the corners). Everything unrolled
 * by the assembler (.macro, .if on a, b, r): the offsets are immediates,
 * no loop or pointer arithmetic. An off-diagonal entry is decoded twice
 * (once per direction) but no sum goes through memory: 15 instructions per
 * 6 multiply-adds (GCC's C of sn_kernels.c: ~124 a block, 36). Rows a
 * outside rows2 take the l1-only copy (l2's row unspecified, the contract).
 * The same exact products as the reference, summed in another order
 * (sn_kernels.h, KERNELS.md "SIMD kernels"). */
void sn_m4_cell_mul2(const unsigned char *K, const sn_q *u1, const sn_q *u2, sn_acc *l1, sn_acc *l2, uint32_t rows2);
__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_cell_mul2,\"ax\",%progbits\n"
    ".set snm2_diag, " SN_M4_S(SN_CELLK_DIAG) "\n"
    ".set snm2_off, " SN_M4_S(SN_CELLK_OFF) "\n"
    ".set snm2_exp, " SN_M4_S(SN_CELLK_EXP) "\n"
    /* one block's 3 entries for output (a, r) times u1_b [and u2_b] */
    ".macro snm2_blk a, b, r, two, first\n"
    ".if \\b == \\a\n"                      /* diagonal: xx yy zz xy xz yz */
    ".if \\r == 0\n"
    "ldr   r4, [r0, #(snm2_diag + 24 * \\a + 0)]\n"
    "ldr   r5, [r0, #(snm2_diag + 24 * \\a + 12)]\n"
    "ldr   r6, [r0, #(snm2_diag + 24 * \\a + 16)]\n"
    ".elseif \\r == 1\n"
    "ldr   r4, [r0, #(snm2_diag + 24 * \\a + 12)]\n"
    "ldr   r5, [r0, #(snm2_diag + 24 * \\a + 4)]\n"
    "ldr   r6, [r0, #(snm2_diag + 24 * \\a + 20)]\n"
    ".else\n"
    "ldr   r4, [r0, #(snm2_diag + 24 * \\a + 16)]\n"
    "ldr   r5, [r0, #(snm2_diag + 24 * \\a + 20)]\n"
    "ldr   r6, [r0, #(snm2_diag + 24 * \\a + 8)]\n"
    ".endif\n"
    ".else\n"
    ".if \\b > \\a\n"                       /* row r of block (a,b): m[3r..3r+2] */
    ".set snm2_i, \\a * (13 - \\a) / 2 - 1 + \\b\n"
    ".set snm2_m0, 6 * \\r\n"
    ".set snm2_st, 2\n"
    ".else\n"                               /* column r of block (b,a): m[r], m[3+r], m[6+r] */
    ".set snm2_i, \\b * (13 - \\b) / 2 - 1 + \\a\n"
    ".set snm2_m0, 2 * \\r\n"
    ".set snm2_st, 6\n"
    ".endif\n"
    "ldrb  r7, [r0, #(snm2_exp + snm2_i)]\n"
    "ldrsh r4, [r0, #(snm2_off + 18 * snm2_i + snm2_m0)]\n"
    "ldrsh r5, [r0, #(snm2_off + 18 * snm2_i + snm2_m0 + snm2_st)]\n"
    "ldrsh r6, [r0, #(snm2_off + 18 * snm2_i + snm2_m0 + 2 * snm2_st)]\n"
    "lsl   r4, r4, r7\n"
    "lsl   r5, r5, r7\n"
    "lsl   r6, r6, r7\n"
    ".endif\n"
    "ldm   r1!, {r7, r8, r9}\n"
    ".if \\first\n"
    "smull r10, r11, r4, r7\n"
    ".else\n"
    "smlal r10, r11, r4, r7\n"
    ".endif\n"
    "smlal r10, r11, r5, r8\n"
    "smlal r10, r11, r6, r9\n"
    ".if \\two\n"
    "ldm   r2!, {r7, r8, r9}\n"
    ".if \\first\n"
    "smull r12, lr, r4, r7\n"
    ".else\n"
    "smlal r12, lr, r4, r7\n"
    ".endif\n"
    "smlal r12, lr, r5, r8\n"
    "smlal r12, lr, r6, r9\n"
    ".endif\n"
    ".endm\n"
    /* output component (a, r): 7 blocks, the stores, the walks back */
    ".macro snm2_out a, r, two\n"
    "snm2_blk \\a, 1, \\r, \\two, 1\n"
    "snm2_blk \\a, 2, \\r, \\two, 0\n"
    "snm2_blk \\a, 3, \\r, \\two, 0\n"
    "snm2_blk \\a, 4, \\r, \\two, 0\n"
    "snm2_blk \\a, 5, \\r, \\two, 0\n"
    "snm2_blk \\a, 6, \\r, \\two, 0\n"
    "snm2_blk \\a, 7, \\r, \\two, 0\n"
    "ldr   r7, [sp, #0]\n"                  /* l1 */
    "strd  r10, r11, [r7, #(24 * \\a + 8 * \\r)]\n"
    "sub   r1, r1, #84\n"
    ".if \\two\n"
    "ldr   r7, [sp, #40]\n"                 /* l2 */
    "strd  r12, lr, [r7, #(24 * \\a + 8 * \\r)]\n"
    "sub   r2, r2, #84\n"
    ".endif\n"
    ".endm\n"
    /* row a: both products if bit a of rows2, else l1's */
    ".macro snm2_row a\n"
    "ldr   r7, [sp, #44]\n"                 /* rows2 */
    "lsls  r7, r7, #(31 - \\a)\n"
    "bpl   1f\n"
    "snm2_out \\a, 0, 1\n"
    "snm2_out \\a, 1, 1\n"
    "snm2_out \\a, 2, 1\n"
    "b     2f\n"
    "1:\n"
    "snm2_out \\a, 0, 0\n"
    "snm2_out \\a, 1, 0\n"
    "snm2_out \\a, 2, 0\n"
    "2:\n"
    ".endm\n"
    ".align 2\n"
    ".global sn_m4_cell_mul2\n"
    ".thumb_func\n"
    ".type sn_m4_cell_mul2, %function\n"
    "sn_m4_cell_mul2:\n"
    "push  {r3-r11, lr}\n"                  /* [sp] l1; l2, rows2 at [sp, #40], [sp, #44] */
    "add   r1, r1, #12\n"                   /* u1_1, u2_1: corner 0 skipped */
    "add   r2, r2, #12\n"
    "snm2_row 0\n"
    "snm2_row 1\n"
    "snm2_row 2\n"
    "snm2_row 3\n"
    "snm2_row 4\n"
    "snm2_row 5\n"
    "snm2_row 6\n"
    "snm2_row 7\n"
    "pop   {r3-r11, pc}\n"
    ".size sn_m4_cell_mul2, .-sn_m4_cell_mul2\n"
    ".purgem snm2_row\n"
    ".purgem snm2_out\n"
    ".purgem snm2_blk\n"
    ".popsection\n");

void sn_k_cell_mul2(const unsigned char *K, const sn_q u1[24], const sn_q u2[24], sn_acc l1[24], sn_acc l2[24],
                    uint32_t rows2) {
    uint32_t a;
    sn_m4_cell_mul2(K, u1, u2, l1, l2, rows2);
    for (a = 0; a < 24; a++)
        SN_RANGE(SN_WITHIN(l1[a], 60) && (!(rows2 >> (a / 3) & 1u) || SN_WITHIN(l2[a], 60)), "cell row beyond 24 * 2^55",
                 l1[a]);
    (void)a;
}

/* The IC(0) backward sweep's block rows (sn_k_ic_bwd_row, sn_kernels_ic.h) in
 * Thumb-2: l = sum of round(U_b z_cols[b]) over consecutive blocks while
 * their frac s is in 1..31 (the rounding term as the SMLAL chain's start,
 * the shift on the two words, as sn_k_ic_m4); returns where it stopped
 * (end, or a block for the reference). The sums live in the frame for the
 * whole run (LDRD/ADDS/ADC/STRD), z_i by one LDM a block: 63 instructions
 * a block against GCC's 81 (it kept l and its pointers on the stack and
 * reloaded them). The same integers: each row's rounded term is the
 * reference's, the sums exact. */
typedef char sn_m4_ic_layout_[SN_ELEM_ICHOL == 20 ? 1 : -1]; /* the stride and frac's byte 18 below */
const unsigned char *sn_m4_ic_rows(const unsigned char *b, const unsigned char *cols, const unsigned char *end,
                                   const sn_q *z, sn_acc l[4]);
__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_ic_rows,\"ax\",%progbits\n"
    /* row k: (2^(s-1) + U_k0 z0 + U_k1 z1 + U_k2 z2) >> s added to l_k */
    ".macro snic_row k\n"
    "mov   r9, r8\n"
    "mov   r10, #0\n"
    "ldrsh r11, [r0, #(6 * \\k)]\n"
    "smlal r9, r10, r11, r3\n"
    "ldrsh r11, [r0, #(6 * \\k + 2)]\n"
    "smlal r9, r10, r11, r4\n"
    "ldrsh r11, [r0, #(6 * \\k + 4)]\n"
    "smlal r9, r10, r11, r5\n"
    "lsr   r9, r9, r6\n"
    "lsl   r11, r10, r7\n"
    "orr   r9, r9, r11\n"
    "asr   r10, r10, r6\n"
    "ldrd  r12, lr, [sp, #(8 * \\k)]\n"
    "adds  r12, r12, r9\n"
    "adc   lr, lr, r10\n"
    "strd  r12, lr, [sp, #(8 * \\k)]\n"
    ".endm\n"
    ".align 2\n"
    ".global sn_m4_ic_rows\n"
    ".thumb_func\n"
    ".type sn_m4_ic_rows, %function\n"
    "sn_m4_ic_rows:\n"
    "push  {r4-r11, lr}\n"
    "sub   sp, sp, #36\n"               /* [sp] l0 l1 l2, end; the caller's l at [sp, #72] */
    "str   r2, [sp, #24]\n"
    "mov   r12, r2\n"
    "mov   r2, r3\n"                    /* z */
    "mov   r3, #0\n"
    "mov   r4, #0\n"
    "strd  r3, r4, [sp, #0]\n"
    "strd  r3, r4, [sp, #8]\n"
    "strd  r3, r4, [sp, #16]\n"
    "cmp   r0, r12\n"
    "beq   2f\n"
    "1:\n"
    "ldrh  r12, [r1], #2\n"             /* i */
    "ldrb  r6, [r0, #18]\n"             /* s = frac */
    "sub   lr, r6, #1\n"
    "cmp   lr, #30\n"
    "bhi   2f\n"                        /* s = 0 or s >= 32: the reference's block */
    "mov   r8, #1\n"
    "lsl   r8, r8, lr\n"                /* 2^(s-1) */
    "rsb   r7, r6, #32\n"
    "add   r12, r12, r12, lsl #1\n"
    "add   r12, r2, r12, lsl #2\n"
    "ldm   r12, {r3, r4, r5}\n"         /* z_i */
    "snic_row 0\n"
    "snic_row 1\n"
    "snic_row 2\n"
    "add   r0, r0, #20\n"
    "ldr   r12, [sp, #24]\n"
    "cmp   r0, r12\n"
    "bne   1b\n"
    "2:\n"
    "ldm   sp, {r3-r8}\n"
    "ldr   r12, [sp, #72]\n"
    "stm   r12, {r3-r8}\n"
    "add   sp, sp, #36\n"
    "pop   {r4-r11, pc}\n"
    ".size sn_m4_ic_rows, .-sn_m4_ic_rows\n"
    ".purgem snic_row\n"
    ".popsection\n");

/* The IC(0) forward sweep's column (sn_k_ic_fwd_col, sn_kernels_ic.h) in
 * Thumb-2: for the blocks of column j while their row i < nF and their
 * shift s = frac + k_j - k_i is in 1..31: acc_i += round(U^T y_j), each of
 * the three sums from the rounding term 2^(s-1) through three SMLAL, the
 * shift on the two words (sn_k_ic_m4's value), added to acc_i by
 * LDRD/ADDS/ADC/STRD. y_j stays in r0-r2 for the column (GCC's inlined
 * sn_k_ic_col reloaded it and the loop's bounds: 91 instructions a block,
 * here 70). Leaves in c (blk, cols) where it stopped: the column's end
 * or a skeleton row (returns 0), or a block for the reference (returns 1). */
typedef char sn_m4_icc_layout_[sizeof(struct sn_m4_icc) == 32 && SN_ELEM_ICHOL == 20 ? 1 : -1];

__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_ic_cols,\"ax\",%progbits\n"
    /* row k of U^T (column k of U: entries k, 3 + k, 6 + k) */
    ".macro snicc_row k\n"
    "mov   r8, r11\n"
    "mov   r9, #0\n"
    "ldrsh r10, [r3, #(2 * \\k)]\n"
    "smlal r8, r9, r10, r0\n"
    "ldrsh r10, [r3, #(2 * \\k + 6)]\n"
    "smlal r8, r9, r10, r1\n"
    "ldrsh r10, [r3, #(2 * \\k + 12)]\n"
    "smlal r8, r9, r10, r2\n"
    "lsr   r8, r8, r5\n"
    "lsl   r10, r9, r6\n"
    "orr   r8, r8, r10\n"
    "asr   r9, r9, r5\n"
    "ldrd  r10, r12, [r7, #(8 * \\k)]\n"
    "adds  r10, r10, r8\n"
    "adc   r12, r12, r9\n"
    "strd  r10, r12, [r7, #(8 * \\k)]\n"
    ".endm\n"
    ".align 2\n"
    ".global sn_m4_ic_cols\n"
    ".thumb_func\n"
    ".type sn_m4_ic_cols, %function\n"
    "sn_m4_ic_cols:\n"
    "push  {r4-r11, lr}\n"
    "sub   sp, sp, #4\n"               /* [sp] c */
    "str   r0, [sp]\n"
    "ldr   r3, [r0, #0]\n"            /* blk */
    "ldr   r4, [r0, #4]\n"            /* cols */
    "ldr   r12, [r0, #28]\n"
    "ldm   r12, {r0, r1, r2}\n"        /* y_j */
    "1:\n"
    "ldr   r12, [sp]\n"
    "ldr   lr, [r12, #8]\n"
    "cmp   r4, lr\n"
    "beq   9f\n"                       /* the column's end */
    "ldrh  r7, [r4]\n"                 /* i */
    "ldr   lr, [r12, #20]\n"
    "cmp   r7, lr\n"
    "bhs   9f\n"                       /* a skeleton row: the column's free blocks are done */
    "ldr   lr, [r12, #12]\n"
    "ldrb  lr, [lr, r7]\n"             /* k_i */
    "ldrb  r5, [r3, #18]\n"            /* frac */
    "ldr   r6, [r12, #24]\n"
    "add   r5, r5, r6\n"
    "sub   r5, r5, lr\n"               /* s */
    "sub   lr, r5, #1\n"
    "cmp   lr, #30\n"
    "bhi   8f\n"                       /* s <= 0 or s >= 32: the reference's block */
    "mov   r11, #1\n"
    "lsl   r11, r11, lr\n"             /* 2^(s-1) */
    "rsb   r6, r5, #32\n"
    "ldr   lr, [r12, #16]\n"
    "add   r7, r7, r7, lsl #1\n"
    "add   r7, lr, r7, lsl #3\n"       /* acc + 3 i */
    "snicc_row 0\n"
    "snicc_row 1\n"
    "snicc_row 2\n"
    "add   r3, r3, #20\n"
    "add   r4, r4, #2\n"
    "b     1b\n"
    "8:\n"
    "mov   r0, #1\n"                   /* returns 1: a block for the reference */
    "b     7f\n"
    "9:\n"
    "mov   r0, #0\n"
    "7:\n"
    "str   r3, [r12, #0]\n"
    "str   r4, [r12, #4]\n"
    "add   sp, sp, #4\n"
    "pop   {r4-r11, pc}\n"
    ".size sn_m4_ic_cols, .-sn_m4_ic_cols\n"
    ".purgem snicc_row\n"
    ".popsection\n");

/* the forward sweep's column after a block sn_m4_ic_cols left: that
 * block by the reference, then the loop again, until the column's end or a
 * skeleton row */
void sn_m4_ic_cols_rest(struct sn_m4_icc *c, uint32_t *sat) {
    while (c->cols != c->cend) {
        const uint32_t i = sn_rd_u16(c->cols);
        if (i >= c->nF) break;
        sn_k_ic_col_ref(c->blk, c->y, (int)c->blk[18] + c->kj - (int)c->kk[i], c->acc + 3 * i, sat);
        c->blk += SN_ELEM_ICHOL;
        c->cols += 2;
        if (!sn_m4_ic_cols(c)) break;
    }
}

/* sn_k_ic_bwd_row after a block the Thumb-2 loop left (s = 0 or s >= 32): that
 * block by the reference, then the loop again from the next one */
void sn_m4_ic_rows_rest(const unsigned char *b, const unsigned char *cols, const unsigned char *end, const sn_q *z,
                        sn_acc l[4], uint32_t *sat) {
    while (b != end) {
        sn_acc t[4];
        const unsigned char *p;
        sn_k_ic_row_ref(b, z + 3 * sn_rd_u16(cols), l, sat);
        b += SN_ELEM_ICHOL;
        cols += 2;
        p = sn_m4_ic_rows(b, cols, end, z, t);
        l[0] += t[0]; l[1] += t[1]; l[2] += t[2];
        cols += 2u * ((uint32_t)(p - b) / SN_ELEM_ICHOL);
        b = p;
    }
}

/* The mat-vec's mass pass over free-free blocks (sn_solve.c pass_M_ff
 * without a mask) in Thumb-2: row i's three sums l in r0-r5 from the
 * diagonal's SMULL, each block (i,j), j < nF, by m y_j into l and m y_i into
 * acc_j (LDRD/SMLAL/STRD), the row's end into acc_i. y_i on the stack,
 * y_j by pointer (GCC spilled l: ~45 instructions a block, here 30). The
 * same exact products added to the same int64 sums. */
struct sn_m4_mff {
    const unsigned char *rp, *cols, *md, *mo; /* 0, 4, 8, 12 */
    const sn_q *y;                            /* 16 */
    sn_acc *acc;                              /* 20 */
    uint32_t nF;                              /* 24 */
};
typedef char sn_m4_mff_layout_[sizeof(struct sn_m4_mff) == 28 && SN_REAL_BYTES == 4 ? 1 : -1];
void sn_m4_mass_ff(const struct sn_m4_mff *c);
__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_mass_ff,\"ax\",%progbits\n"
    ".align 2\n"
    ".global sn_m4_mass_ff\n"
    ".thumb_func\n"
    ".type sn_m4_mass_ff, %function\n"
    "sn_m4_mass_ff:\n"
    "push  {r4-r11, lr}\n"
    "sub   sp, sp, #48\n"      /* [sp] yi0 yi1 yi2, 12 end, 16 nF, 20 i, 24 rp, 28 md, 32 y, 36 cols, 40 mo */
    "ldm   r0, {r1-r7}\n"      /* rp cols md mo y acc nF */
    "str   r1, [sp, #24]\n"
    "str   r2, [sp, #36]\n"
    "str   r3, [sp, #28]\n"
    "str   r4, [sp, #40]\n"
    "str   r5, [sp, #32]\n"
    "str   r7, [sp, #16]\n"
    "mov   lr, r6\n"           /* acc */
    "mov   r0, #0\n"
    "str   r0, [sp, #20]\n"    /* i = 0 */
    "1:\n"
    "ldr   r6, [sp, #24]\n"
    "ldr   r7, [r6], #4\n"     /* e = rp[i] */
    "ldr   r8, [r6]\n"         /* end = rp[i + 1] */
    "str   r6, [sp, #24]\n"
    "ldr   r9, [sp, #36]\n"
    "add   r10, r9, r7, lsl #1\n"  /* cols + 2 e */
    "add   r8, r9, r8, lsl #1\n"
    "str   r8, [sp, #12]\n"    /* cols + 2 end */
    "ldr   r9, [sp, #40]\n"
    "add   r11, r9, r7, lsl #2\n"  /* mo + 4 e */
    "ldr   r6, [sp, #28]\n"
    "ldr   r12, [r6], #4\n"    /* md[i] */
    "str   r6, [sp, #28]\n"
    "ldr   r6, [sp, #20]\n"
    "add   r6, r6, r6, lsl #1\n"
    "ldr   r7, [sp, #32]\n"
    "add   r6, r7, r6, lsl #2\n"
    "ldm   r6, {r7, r8, r9}\n" /* y_i */
    "stm   sp, {r7, r8, r9}\n"
    "smull r0, r1, r12, r7\n"
    "smull r2, r3, r12, r8\n"
    "smull r4, r5, r12, r9\n"
    "2:\n"
    "ldr   r6, [sp, #12]\n"
    "cmp   r10, r6\n"
    "beq   3f\n"               /* the row's end */
    "ldrh  r7, [r10], #2\n"    /* j */
    "ldr   r6, [sp, #16]\n"
    "cmp   r7, r6\n"
    "bhs   3f\n"               /* a skeleton column: the row's free blocks are done */
    "ldr   r6, [r11], #4\n"    /* m */
    "add   r7, r7, r7, lsl #1\n"
    "ldr   r8, [sp, #32]\n"
    "add   r8, r8, r7, lsl #2\n"   /* y_j */
    "ldr   r9, [r8]\n"
    "smlal r0, r1, r6, r9\n"
    "ldr   r9, [r8, #4]\n"
    "smlal r2, r3, r6, r9\n"
    "ldr   r9, [r8, #8]\n"
    "smlal r4, r5, r6, r9\n"
    "add   r7, lr, r7, lsl #3\n"   /* acc_j */
    "ldr   r12, [sp, #0]\n"
    "ldrd  r8, r9, [r7, #0]\n"
    "smlal r8, r9, r6, r12\n"
    "strd  r8, r9, [r7, #0]\n"
    "ldr   r12, [sp, #4]\n"
    "ldrd  r8, r9, [r7, #8]\n"
    "smlal r8, r9, r6, r12\n"
    "strd  r8, r9, [r7, #8]\n"
    "ldr   r12, [sp, #8]\n"
    "ldrd  r8, r9, [r7, #16]\n"
    "smlal r8, r9, r6, r12\n"
    "strd  r8, r9, [r7, #16]\n"
    "b     2b\n"
    "3:\n"
    "ldr   r6, [sp, #20]\n"
    "add   r7, r6, r6, lsl #1\n"
    "add   r7, lr, r7, lsl #3\n"   /* acc_i */
    "ldrd  r8, r9, [r7, #0]\n"
    "adds  r8, r8, r0\n"
    "adc   r9, r9, r1\n"
    "strd  r8, r9, [r7, #0]\n"
    "ldrd  r8, r9, [r7, #8]\n"
    "adds  r8, r8, r2\n"
    "adc   r9, r9, r3\n"
    "strd  r8, r9, [r7, #8]\n"
    "ldrd  r8, r9, [r7, #16]\n"
    "adds  r8, r8, r4\n"
    "adc   r9, r9, r5\n"
    "strd  r8, r9, [r7, #16]\n"
    "add   r6, r6, #1\n"
    "str   r6, [sp, #20]\n"
    "ldr   r7, [sp, #16]\n"
    "cmp   r6, r7\n"
    "blo   1b\n"
    "add   sp, sp, #48\n"
    "pop   {r4-r11, pc}\n"
    ".size sn_m4_mass_ff, .-sn_m4_mass_ff\n"
    ".popsection\n");

void sn_k_mass_ff(const unsigned char *rp, const unsigned char *cols, const unsigned char *md, const unsigned char *mo,
                  const sn_q *y, sn_acc *acc, uint32_t nF) {
    struct sn_m4_mff c;
    c.rp = rp; c.cols = cols; c.md = md; c.mo = mo; c.y = y; c.acc = acc; c.nF = nF;
    if (nF) sn_m4_mass_ff(&c);
}

/* The right-hand side's mass pass at the skeleton columns (sn_solve.c
 * sn_rhs): per free row i, acc_i += sum over the row's blocks (i,j), j >=
 * nF (COLS ascend: a suffix of the row), of M_ij y_j with y_j = sn_add(coef(
 * v'_j, a1), ds_j) formed per block as the reference does (the same values
 * and clamp counts); the sums from acc_i in int32 operands (SMLAL; GCC's
 * general loop multiplied 64 x 64 and kept l on the stack). */
SN_INLINE uint32_t sn_m4_rd_u16(const unsigned char *p) {
    uint16_t v;
    memcpy(&v, p, 2); /* LDRH: little-endian, unaligned allowed */
    return v;
}
/* coef_nc(v, a1) = (v a1 + 2^23) >> 24 as one SMMULR of v and a1 2^8 for
 * |a1| < 2^23 ((v a1 2^8 + 2^31) >> 32: the same floor, a1 2^8 within
 * int32; sn_rhs's a1 = h alpha is far below): the same value */
SN_INLINE int32_t sn_m4_coef8(sn_q v, int32_t a8) {
    int32_t r;
    __asm__("smmulr %0, %1, %2" : "=r"(r) : "r"(v), "r"(a8));
    return r;
}
/* the loop, with the coefficient's product by SMMULR (fast) or
 * sn_k_coef_nc; forced inline so each call has its own code */
static inline __attribute__((always_inline)) void mass_sk_loop(const unsigned char *rp, const unsigned char *cols,
                                                               const unsigned char *mo, const sn_q *vel, const sn_q *ds,
                                                               sn_q a1, sn_acc *acc, uint32_t nF, uint32_t *sat,
                                                               int fast) {
    const uint32_t bit = (uint32_t)1 << (SN_Q_COEF - 1);
    const int32_t a8 = fast ? (int32_t)((uint32_t)a1 << 8) : 0;
    uint32_t i, ns = 0, e = sn_rd_u32(rp);
    for (i = 0; i < nF; i++, acc += 3) {
        const uint32_t end = sn_rd_u32(rp + 4 * i + 4);
        int64_t l0, l1, l2;
        while (e < end && sn_m4_rd_u16(cols + 2 * e) < nF) e++; /* the free columns */
        if (e == end) continue;
        l0 = acc[0]; l1 = acc[1]; l2 = acc[2];
        for (; e < end; e++) {
            const uint32_t j = sn_m4_rd_u16(cols + 2 * e);
            const sn_q m = rd_real(mo, e), *vj = vel + 3 * j, *dj = ds + 3 * (j - nF);
            int32_t y0 = sn_add(fast ? sn_m4_coef8(vj[0], a8) : sn_k_coef_nc(vj[0], a1, bit), dj[0], &ns);
            int32_t y1 = sn_add(fast ? sn_m4_coef8(vj[1], a8) : sn_k_coef_nc(vj[1], a1, bit), dj[1], &ns);
            int32_t y2 = sn_add(fast ? sn_m4_coef8(vj[2], a8) : sn_k_coef_nc(vj[2], a1, bit), dj[2], &ns);
            SN_K_I32(y0, y1, y2);
            l0 += sn_mul(m, y0);
            l1 += sn_mul(m, y1);
            l2 += sn_mul(m, y2);
        }
        acc[0] = l0; acc[1] = l1; acc[2] = l2;
    }
    *sat += ns; /* a count: the same total */
}
void sn_k_mass_sk(const unsigned char *rp, const unsigned char *cols, const unsigned char *mo, const sn_q *vel,
                  const sn_q *ds, sn_q a1, sn_acc *acc, uint32_t nF, uint32_t *sat) {
    if (a1 > -((int32_t)1 << 23) && a1 < ((int32_t)1 << 23)) mass_sk_loop(rp, cols, mo, vel, ds, a1, acc, nF, sat, 1);
    else mass_sk_loop(rp, cols, mo, vel, ds, a1, acc, nF, sat, 0);
}

/* cell_forces' corners 1..7 (sn_solve.c) in Thumb-2, sn_m4_corners: per
 * corner a (cl[k]) t = pos_a - pos_a0, s = w_a - w_a0 (QSUB), row i of
 * d_k = R^T t - (rest_a - rest_a0) and of uu_k = R^T s (R^T's row i from
 * the rounding term 2^29 by three SMLAL, >> 30 on the two words), each
 * difference and rotated value clamped to +-SN_LIM by one unsigned compare
 * (the clamp inline, branched over) and counted in lr. The 7 corners
 * unrolled by the assembler (.irp): offsets immediates, the pointers of a0
 * and w_a (wp[k]: w + 3a or the caller's b1 v') in the frame. The
 * reference's sn_k_sub3 / sn_k_rot_t / sn_k_sub3r values and count (GCC's
 * loop: ~210 instructions a corner, here ~160). */
struct sn_m4_cor {
    const unsigned char *cl;          /* 0: the cell's 8 corners (u16) */
    const sn_q *pos;                  /* 4 */
    const unsigned char *rest;        /* 8: REST section (int32 reals) */
    const sn_q *R;                    /* 12: the cell frame */
    const sn_q *w0;                   /* 16: w at corner 0 */
    sn_q *d, *uu;                     /* 20, 24: rows 3..23 written */
    uint32_t sat;                     /* 28: clamp count, in and out */
    const sn_q *wp[8];                /* 32: w at corner k (1..7) */
};
typedef char sn_m4_cor_layout_[sizeof(struct sn_m4_cor) == 64 && SN_REAL_BYTES == 4 ? 1 : -1];
void sn_m4_corners(struct sn_m4_cor *c);
__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_corners,\"ax\",%progbits\n"
    /* v clamped to +-SN_LIM (2^28), counted; t a scratch register */
    ".macro snc_cl v, t\n"
    "add   \\t, \\v, #0x10000000\n"
    "cmp   \\t, #0x20000000\n"
    "bls   .Lsnc\\@\n"
    "add   lr, lr, #1\n"
    "cmp   \\v, #0\n"
    "ite   gt\n"
    "movgt \\v, #0x10000000\n"
    "movle \\v, #0xF0000000\n"
    ".Lsnc\\@:\n"
    ".endm\n"
    /* r3 = row i of R^T (r0, r1, r2), rounded >> 30, clamped */
    ".macro snc_rot i\n"
    "mov   r3, #0x20000000\n"
    "mov   r4, #0\n"
    "ldr   r5, [r8, #(4 * \\i)]\n"
    "smlal r3, r4, r5, r0\n"
    "ldr   r5, [r8, #(12 + 4 * \\i)]\n"
    "smlal r3, r4, r5, r1\n"
    "ldr   r5, [r8, #(24 + 4 * \\i)]\n"
    "smlal r3, r4, r5, r2\n"
    "lsrs  r3, r3, #30\n"
    "orr   r3, r3, r4, lsl #2\n"
    "snc_cl r3, r4\n"
    ".endm\n"
    /* r0..r2 = [\\p] - [\\q] per entry, clamped */
    ".macro snc_sub3 p, q\n"
    "ldr   r0, [\\p]\n"
    "ldr   r3, [\\q]\n"
    "qsub  r0, r0, r3\n"
    "snc_cl r0, r3\n"
    "ldr   r1, [\\p, #4]\n"
    "ldr   r3, [\\q, #4]\n"
    "qsub  r1, r1, r3\n"
    "snc_cl r1, r3\n"
    "ldr   r2, [\\p, #8]\n"
    "ldr   r3, [\\q, #8]\n"
    "qsub  r2, r2, r3\n"
    "snc_cl r2, r3\n"
    ".endm\n"
    ".macro snc_corner k\n"
    "ldrh  r7, [r11, #(2 * \\k)]\n"
    "add   r7, r7, r7, lsl #1\n"   /* 3 a */
    "ldr   r6, [sp, #0]\n"
    "add   r6, r6, r7, lsl #2\n"   /* pos_a */
    "ldr   r5, [sp, #12]\n"        /* pos_a0 */
    "snc_sub3 r6, r5\n"            /* t */
    "ldr   r6, [sp, #4]\n"
    "add   r6, r6, r7, lsl #2\n"   /* rest_a */
    ".irp i, 0, 1, 2\n"
    "snc_rot \\i\n"
    "ldr   r4, [r6, #(4 * \\i)]\n"
    "ldr   r5, [r12, #(4 * \\i)]\n"
    "qsub  r4, r4, r5\n"
    "snc_cl r4, r5\n"              /* xr_i */
    "qsub  r3, r3, r4\n"
    "snc_cl r3, r5\n"
    "str   r3, [r9, #(12 * \\k + 4 * \\i)]\n"   /* d */
    ".endr\n"
    "ldr   r6, [sp, #(16 + 4 * \\k)]\n"         /* w_a */
    "ldr   r7, [sp, #8]\n"                      /* w_a0 */
    "snc_sub3 r6, r7\n"            /* s */
    ".irp i, 0, 1, 2\n"
    "snc_rot \\i\n"
    "str   r3, [r10, #(12 * \\k + 4 * \\i)]\n"  /* uu */
    ".endr\n"
    ".endm\n"
    ".align 2\n"
    ".global sn_m4_corners\n"
    ".thumb_func\n"
    ".type sn_m4_corners, %function\n"
    "sn_m4_corners:\n"
    "push  {r4-r11, lr}\n"
    "sub   sp, sp, #56\n"          /* 0 pos, 4 rest, 8 w0, 12 pos_a0, 16 wp[0..7], 48 c */
    "str   r0, [sp, #48]\n"
    "ldr   r11, [r0, #0]\n"
    "ldr   r1, [r0, #4]\n"
    "str   r1, [sp, #0]\n"
    "ldr   r2, [r0, #8]\n"
    "str   r2, [sp, #4]\n"
    "ldr   r3, [r0, #16]\n"
    "str   r3, [sp, #8]\n"
    "ldrh  r7, [r11]\n"
    "add   r7, r7, r7, lsl #1\n"   /* 3 a0 */
    "add   r1, r1, r7, lsl #2\n"
    "str   r1, [sp, #12]\n"        /* pos_a0 */
    "add   r12, r2, r7, lsl #2\n"  /* rest_a0 */
    "ldr   r8, [r0, #12]\n"
    "ldr   r9, [r0, #20]\n"
    "ldr   r10, [r0, #24]\n"
    "ldr   lr, [r0, #28]\n"
    "add   r1, r0, #32\n"
    "add   r6, sp, #16\n"
    "ldmia r1!, {r2-r5}\n"
    "stmia r6!, {r2-r5}\n"
    "ldmia r1, {r2-r5}\n"
    "stmia r6, {r2-r5}\n"
    ".irp k, 1, 2, 3, 4, 5, 6, 7\n"
    "snc_corner \\k\n"
    ".endr\n"
    "ldr   r0, [sp, #48]\n"
    "str   lr, [r0, #28]\n"
    "add   sp, sp, #56\n"
    "pop   {r4-r11, pc}\n"
    ".size sn_m4_corners, .-sn_m4_corners\n"
    ".popsection\n");

uint32_t sn_k_corners(const unsigned char *cl, const sn_q *pos, const sn_q *w, const sn_q *vel, uint32_t nF, sn_q b1,
                      const unsigned char *rest, const sn_q *R, const sn_q *w0, sn_q *d, sn_q *uu, uint32_t *sat) {
    struct sn_m4_cor c;
    sn_q ws[24];
    uint32_t k, fr = 0, dummy = 0;
    const uint32_t bit = (uint32_t)1 << (SN_Q_COEF - 1);
    const int nc = b1 <= ONE_COEF && b1 >= -ONE_COEF;
    for (k = 1; k < 8; k++) {
        const uint32_t a = sn_m4_rd_u16(cl + 2 * k);
        if (a < nF) {
            c.wp[k] = w + 3 * a;
            fr |= (uint32_t)1 << k;
        } else { /* w_of's b1 v' (its clamps counted once in sn_rhs) */
            sn_q *t = ws + 3 * k;
            if (nc) {
                t[0] = sn_k_coef_nc(vel[3 * a], b1, bit);
                t[1] = sn_k_coef_nc(vel[3 * a + 1], b1, bit);
                t[2] = sn_k_coef_nc(vel[3 * a + 2], b1, bit);
            } else
                sn_k_coef3(vel + 3 * a, b1, t, &dummy);
            c.wp[k] = t;
        }
    }
    c.wp[0] = w0;
    c.cl = cl; c.pos = pos; c.rest = rest; c.R = R; c.w0 = w0; c.d = d; c.uu = uu; c.sat = 0;
    sn_m4_corners(&c);
    *sat += c.sat;
    return fr;
}

/* The CG dot product (sn_kernels.c's reference): each product rounded alone,
 * (a b + 2^(sh-1)) >> sh. Here the rounding term is the SMLAL's starting
 * value and, for 0 < sh < 32 (sh = s + k_i, shared by a vertex's 3 terms),
 * the shift is done on the two words: the same rounded terms (sn_rshr64_var's
 * identity), summed in the same order. */
/* sn_shr64_w's value with the words joined by OR (GCC added the zero
 * high word of the low part: one ADDS #0 a term) */
SN_INLINE int64_t sn_m4_shr_or(int64_t x, int s) {
    const uint32_t lo = (uint32_t)x;
    const int32_t hi = (int32_t)(x >> 32);
    return (int64_t)(((uint64_t)(uint32_t)(hi >> s) << 32) | (lo >> s | (uint32_t)hi << (32 - s)));
}
/* Thumb-2 (sn_m4_absor, sn_m4_dot): the ORs of |a|, |b| a vertex at a
 * time (LDM, |x| as (x ^ m) - m with m = x >> 31), then per vertex sh = s
 * + k_i and each of its 3 terms from the rounding term 2^(sh-1) by SMLAL,
 * shifted on the two words (sn_m4_shr_or's value) and added to the sum in
 * r10:r11 (sh = 0 too: register shifts by 32 or more give 0, so the
 * rounding term is 0 and the high word adds nothing to the low); a vertex
 * with sh > 31 hands back to the C loop, which
 * does it as the reference and resumes (GCC's loops: 28 + 56 instructions
 * a vertex, here 22 + 43). The same rounded terms, summed exactly. */
struct sn_m4_dotc {
    const sn_q *a, *b;      /* 0, 4: the next vertex */
    const uint8_t *kk;      /* 8 */
    const sn_q *aend;       /* 12 */
    int32_t s, pad;         /* 16 */
    int64_t sum;            /* 24 */
};
typedef char sn_m4_dotc_layout_[sizeof(struct sn_m4_dotc) == 32 ? 1 : -1];
int sn_m4_dot(struct sn_m4_dotc *c);
void sn_m4_absor(const sn_q *a, const sn_q *b, uint32_t nv, uint32_t o[2]);
__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_dot,\"ax\",%progbits\n"
    ".macro snd_term\n"
    "ldr   r12, [r0], #4\n"
    "ldr   lr, [r1], #4\n"
    "mov   r8, r6\n"
    "mov   r9, #0\n"
    "smlal r8, r9, r12, lr\n"
    "lsr   r8, r8, r5\n"
    "lsl   r12, r9, r7\n"
    "orr   r8, r8, r12\n"
    "asr   r9, r9, r5\n"
    "adds  r10, r10, r8\n"
    "adc   r11, r11, r9\n"
    ".endm\n"
    ".align 2\n"
    ".global sn_m4_dot\n"
    ".thumb_func\n"
    ".type sn_m4_dot, %function\n"
    "sn_m4_dot:\n"
    "push  {r0, r4-r11, lr}\n"
    "mov   r12, r0\n"
    "ldm   r12, {r0-r4}\n"           /* a b kk aend s */
    "ldrd  r10, r11, [r12, #24]\n"
    "cmp   r0, r3\n"
    "beq   3f\n"
    "1:\n"
    "ldrb  r5, [r2], #1\n"
    "add   r5, r5, r4\n"             /* sh */
    "cmp   r5, #31\n"
    "bhi   2f\n"
    "sub   r12, r5, #1\n"
    "mov   r6, #1\n"
    "lsl   r6, r6, r12\n"            /* 2^(sh-1); sh = 0: a shift by 255 (the low byte of -1), 0 */
    "rsb   r7, r5, #32\n"            /* sh = 0: the high word shifted by 32, 0 */
    "snd_term\n"
    "snd_term\n"
    "snd_term\n"
    "cmp   r0, r3\n"
    "bne   1b\n"
    "3:\n"
    "movs  r5, #0\n"                 /* done */
    "b     4f\n"
    "2:\n"
    "sub   r2, r2, #1\n"             /* this vertex: the C loop's */
    "movs  r5, #1\n"
    "4:\n"
    "ldr   r12, [sp]\n"
    "stm   r12, {r0-r2}\n"
    "strd  r10, r11, [r12, #24]\n"
    "mov   r0, r5\n"
    "add   sp, sp, #4\n"
    "pop   {r4-r11, pc}\n"
    ".size sn_m4_dot, .-sn_m4_dot\n"
    ".align 2\n"
    ".global sn_m4_absor\n"
    ".thumb_func\n"
    ".type sn_m4_absor, %function\n"
    "sn_m4_absor:\n"                 /* r0 a, r1 b, r2 nv > 0, r3 o */
    "push  {r3-r10, lr}\n"
    "add   r2, r2, r2, lsl #1\n"
    "add   r2, r0, r2, lsl #2\n"     /* a end */
    "movs  r3, #0\n"                 /* |a| OR */
    "mov   r12, #0\n"                /* |b| OR */
    "5:\n"
    "ldm   r0!, {r4-r6}\n"
    "ldm   r1!, {r7-r9}\n"
    ".irp x, r4, r5, r6\n"
    "eor   r10, \\x, \\x, asr #31\n"
    "sub   r10, r10, \\x, asr #31\n"
    "orr   r3, r3, r10\n"
    ".endr\n"
    ".irp x, r7, r8, r9\n"
    "eor   r10, \\x, \\x, asr #31\n"
    "sub   r10, r10, \\x, asr #31\n"
    "orr   r12, r12, r10\n"
    ".endr\n"
    "cmp   r0, r2\n"
    "bne   5b\n"
    "ldr   r4, [sp]\n"
    "str   r3, [r4]\n"
    "str   r12, [r4, #4]\n"
    "add   sp, sp, #4\n"
    "pop   {r4-r10, pc}\n"
    ".size sn_m4_absor, .-sn_m4_absor\n"
    ".popsection\n");

int64_t sn_k_dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n, int *e) {
    uint32_t k, nv = n / 3, o[2] = {0, 0};
    struct sn_m4_dotc c;
    int s;
    if (nv) sn_m4_absor(a, b, nv, o);
    s = sn_k_dot_scale(a, b, 3 * nv, n, o[0], o[1]);
    c.a = a; c.b = b; c.kk = kk; c.aend = a + 3 * nv; c.s = s; c.pad = 0; c.sum = 0;
    while (c.a != c.aend && sn_m4_dot(&c)) { /* a vertex with sh > 31: the reference's terms */
        const int sh = s + *c.kk;
        const int64_t half = sh > 0 ? (int64_t)1 << (sh - 1) : 0;
        for (k = 0; k < 3; k++) c.sum += ((int64_t)c.a[k] * c.b[k] + half) >> sh;
        c.a += 3; c.b += 3; c.kk++;
    }
    *e = s;
    return c.sum;
}

/* The CG vector updates (sn_kernels.h's reference, sn_mulq then sn_add per
 * value): for 0 < sh < 32 the product starts from the rounding term and is
 * shifted on the two words, the test hoisted out of the loop (inside
 * sn_out it cost the solve +6%); the same clamps and counts. */
/* the loop below for one shift sh in 28..31 (a constant: immediate shifts) */
SN_INLINE void sn_m4_axpy_hi(sn_q *out, const sn_q *a, sn_q s, const sn_q *x, uint32_t n, const int sh, uint32_t *sat) {
    const uint32_t bit = (uint32_t)1 << (sh - 1);
    sn_q *const end = out + n;
    while (out != end) {
        const sn_q xi = *x++;
        const int64_t p = sn_mul(s, xi) + (int64_t)bit; /* SMLAL from the rounding term */
        const int32_t hi = (int32_t)(p >> 32);
        int32_t q = (int32_t)(((uint32_t)p >> sh) | ((uint32_t)hi << (32 - sh)));
        SN_RANGE(SN_WITHIN(sn_mul(s, xi), 59), "CG update product beyond 2^59", xi);
        if ((uint32_t)q + (uint32_t)SN_LIM > 2u * (uint32_t)SN_LIM) {
            (*sat)++;
            q = hi < 0 ? -SN_LIM : SN_LIM;
        }
        *out++ = sn_add(*a++, q, sat);
    }
}
void sn_k_axpy(sn_q *out, const sn_q *a, sn_q s, const sn_q *x, uint32_t n, int sh, uint32_t *sat) {
    uint32_t i;
    if (sh == 28) {
        sn_m4_axpy_hi(out, a, s, x, n, 28, sat); /* the CG's SN_Q_SCAL: immediate shifts */
    } else if (sh >= 28 && sh < 32) {
        /* the CG's shift (28): with the contract's |s x| <= 2^31 2^28
         * (sn_kernels.h), the rounded value lies in [-2^31, 2^31], so its low
         * word is it (2^31 reads as INT32_MIN: outside +-SN_LIM, clamped by
         * the high word's sign) and |v| <= SN_LIM is the one unsigned
         * compare, without sn_k_out_w's high-word test (cow_fem step -14 k) */
        sn_m4_axpy_hi(out, a, s, x, n, sh, sat);
    } else if (sh > 0 && sh < 32) {
        /* sn_k_out_w (sn_kernels_rot.h): the rounding add, the shift on the
         * two words and |v| <= SN_LIM as the low word within +-SN_LIM and
         * the high word its sign (not two 64-bit compares) */
        const uint32_t bit = (uint32_t)1 << (sh - 1);
        sn_q *const end = out + n;
        while (out != end) {
            const sn_q q = sn_k_out_w(sn_mul(s, *x++), sh, bit, sat);
            *out++ = sn_add(*a++, q, sat);
        }
    } else {
        for (i = 0; i < n; i++) out[i] = sn_add(a[i], sn_mulq(s, x[i], sh, sat), sat);
    }
}

/* sn_k_out_rot_acc (sn_kernels_rot.h) for 0 < sh < 32 in Thumb-2: t_c =
 * sn_k_out_w(l_c, sh) (the rounding add, the shift on the two words, the
 * clamp's two tests, the count in memory on the rare clamp), then acc_r +=
 * R_r0 t0 + R_r1 t1 + R_r2 t2 as one SMLAL chain from acc_r, R's row by
 * LDM (GCC: 77 instructions a call, here 60) */
__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_out_rot_acc,\"ax\",%progbits\n"
    ".macro snr_out c, t\n"
    "ldrd  r4, r5, [r2, #(8 * \\c)]\n"
    "adds  r4, r4, lr\n"
    "adc   r5, r5, #0\n"
    "lsr   r4, r4, r3\n"
    "lsl   r6, r5, r12\n"
    "orr   \\t, r4, r6\n"
    "asr   r5, r5, r3\n"
    "add   r6, \\t, #0x10000000\n"
    "cmp   r6, #0x20000000\n"
    "bhi   .Lsnr1\\@\n"
    "cmp   r5, \\t, asr #31\n"
    "beq   .Lsnr2\\@\n"
    ".Lsnr1\\@:\n"
    "ldr   r6, [sp, #36]\n"
    "ldr   r4, [r6]\n"
    "add   r4, r4, #1\n"
    "str   r4, [r6]\n"
    "cmp   r5, #0\n"
    "ite   lt\n"
    "movlt \\t, #0xF0000000\n"
    "movge \\t, #0x10000000\n"
    ".Lsnr2\\@:\n"
    ".endm\n"
    ".macro snr_row r\n"
    "ldrd  r4, r5, [r0, #(8 * \\r)]\n"
    "ldm   r1!, {r10, r11, r12}\n"
    "smlal r4, r5, r10, r7\n"
    "smlal r4, r5, r11, r8\n"
    "smlal r4, r5, r12, r9\n"
    "strd  r4, r5, [r0, #(8 * \\r)]\n"
    ".endm\n"
    ".align 2\n"
    ".global sn_m4_out_rot_acc\n"
    ".thumb_func\n"
    ".type sn_m4_out_rot_acc, %function\n"
    "sn_m4_out_rot_acc:\n"         /* r0 acc, r1 R, r2 l, r3 sh (1..31), [sp] sat */
    "push  {r4-r11, lr}\n"
    "rsb   r12, r3, #32\n"
    "sub   r6, r3, #1\n"
    "mov   lr, #1\n"
    "lsl   lr, lr, r6\n"           /* 2^(sh-1) */
    "snr_out 0, r7\n"
    "snr_out 1, r8\n"
    "snr_out 2, r9\n"
    "snr_row 0\n"
    "snr_row 1\n"
    "snr_row 2\n"
    "pop   {r4-r11, pc}\n"
    ".size sn_m4_out_rot_acc, .-sn_m4_out_rot_acc\n"
    ".popsection\n");

/* the other shifts (sn_kernels_rot.h's sn_k_out_rot_acc) */
void sn_k_out_rot_acc_c(sn_acc acc[3], const sn_q *R, const sn_acc l[3], int sh, uint32_t *sat) {
    int32_t t0, t1, t2;
    int64_t x;
    if ((uint32_t)(sh - 1) < 31u) {
        const uint32_t bit = (uint32_t)1 << (sh - 1);
        t0 = sn_k_out_w(l[0], sh, bit, sat);
        t1 = sn_k_out_w(l[1], sh, bit, sat);
        t2 = sn_k_out_w(l[2], sh, bit, sat);
    } else if ((uint32_t)(sh - 32) < 31u) { /* 32..62: some vertices' stiffness rows */
        const uint32_t blo = sh == 32 ? (uint32_t)1 << 31 : 0;
        const int32_t bhi = sh == 32 ? 0 : (int32_t)1 << ((sh - 33) & 31);
        t0 = sn_k_out_hw(l[0], sh, blo, bhi, sat);
        t1 = sn_k_out_hw(l[1], sh, blo, bhi, sat);
        t2 = sn_k_out_hw(l[2], sh, blo, bhi, sat);
    } else {
        t0 = sn_out(l[0], sh, sat);
        t1 = sn_out(l[1], sh, sat);
        t2 = sn_out(l[2], sh, sat);
    }
    SN_K_I32(t0, t1, t2);
    x = acc[0]; x += sn_mul(R[0], t0); x += sn_mul(R[1], t1); x += sn_mul(R[2], t2); acc[0] = x;
    x = acc[1]; x += sn_mul(R[3], t0); x += sn_mul(R[4], t1); x += sn_mul(R[5], t2); acc[1] = x;
    x = acc[2]; x += sn_mul(R[6], t0); x += sn_mul(R[7], t1); x += sn_mul(R[8], t2); acc[2] = x;
}

/* sn_k_sym_out (sn_kernels_rot.h) for 0 < sh < 32 in Thumb-2: D's six
 * entries and e by LDM (b 4-aligned: the PRECOND section is 8-aligned, 24
 * bytes an entry), the three sums in SMULL/SMLAL register pairs (e read
 * before out is written: out may be e), each rounded, shifted and clamped
 * as sn_k_out_w (the count in memory on the rare clamp). GCC: 70
 * instructions a call, here 53. Exact int64 sums, the same integers. */
__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_sym_out,\"ax\",%progbits\n"
    ".macro sns_out lo, hi\n"
    "adds  \\lo, \\lo, lr\n"
    "adc   \\hi, \\hi, #0\n"
    "lsr   \\lo, \\lo, r3\n"
    "lsl   r6, \\hi, r1\n"
    "orr   \\lo, \\lo, r6\n"
    "asr   \\hi, \\hi, r3\n"
    "add   r6, \\lo, #0x10000000\n"
    "cmp   r6, #0x20000000\n"
    "bhi   .Lsns1\\@\n"
    "cmp   \\hi, \\lo, asr #31\n"
    "beq   .Lsns2\\@\n"
    ".Lsns1\\@:\n"
    "ldr   r6, [sp, #36]\n"
    "ldr   r8, [r6]\n"
    "add   r8, r8, #1\n"
    "str   r8, [r6]\n"
    "cmp   \\hi, #0\n"
    "ite   lt\n"
    "movlt \\lo, #0xF0000000\n"
    "movge \\lo, #0x10000000\n"
    ".Lsns2\\@:\n"
    ".endm\n"
    ".align 2\n"
    ".global sn_m4_sym_out\n"
    ".thumb_func\n"
    ".type sn_m4_sym_out, %function\n"
    "sn_m4_sym_out:\n"            /* r0 b, r1 e, r2 out, r3 sh (1..31), [sp] sat */
    "push  {r4-r11, lr}\n"
    "ldm   r0, {r4-r9}\n"         /* xx yy zz xy xz yz */
    "ldm   r1, {r0, r1, lr}\n"    /* e0 e1 e2 */
    "smull r10, r11, r4, r0\n"    /* l0 = xx e0 + xy e1 + xz e2 */
    "smlal r10, r11, r7, r1\n"
    "smlal r10, r11, r8, lr\n"
    "smull r4, r12, r7, r0\n"     /* l1 = xy e0 + yy e1 + yz e2 */
    "smlal r4, r12, r5, r1\n"
    "smlal r4, r12, r9, lr\n"
    "smull r5, r7, r8, r0\n"      /* l2 = xz e0 + yz e1 + zz e2 */
    "smlal r5, r7, r9, r1\n"
    "smlal r5, r7, r6, lr\n"
    "mov   lr, #1\n"
    "sub   r0, r3, #1\n"
    "lsl   lr, lr, r0\n"          /* 2^(sh-1) */
    "rsb   r1, r3, #32\n"
    "sns_out r10, r11\n"
    "sns_out r4, r12\n"
    "sns_out r5, r7\n"
    "str   r10, [r2]\n"
    "str   r4, [r2, #4]\n"
    "str   r5, [r2, #8]\n"
    "pop   {r4-r11, pc}\n"
    ".size sn_m4_sym_out, .-sn_m4_sym_out\n"
    ".purgem sns_out\n"
    ".popsection\n");

/* sn_k_mix (sn_kernels_rot.h) in Thumb-2 while a vertex's shift sh = base
 * - kk is in 1..31: per value mk = sn_k_out_w(acc, sh) (the rounding add,
 * the shift on the two words, the clamp's two tests), then q = sn_out(q ck
 * + mk cm, 24) as SMULL/SMLAL, the rounding add and the shift by 24 with
 * |v| < 2^28 tested on the sum's high word alone (v >> 28 = hi >> 20 in
 * {-1, 0}); a failed test (v = 2^28 too) re-tests exactly out of line
 * (.subsection 1), where clamps are counted (lr). GCC: 102 instructions a
 * vertex, here 84. */
typedef char sn_m4_mix_layout_[sizeof(struct sn_m4_mixc) == 32 && SN_Q_COEF == 24 ? 1 : -1];
__asm__(
    ".syntax unified\n"
    ".thumb\n"
    ".pushsection .text.sn_m4_mix,\"ax\",%progbits\n"
    ".macro snx_val\n"
    "ldrd  r11, r12, [r2], #8\n"
    "adds  r11, r11, r9\n"
    "adc   r12, r12, #0\n"
    "lsr   r11, r11, r8\n"
    "lsl   r0, r12, r10\n"
    "orr   r11, r11, r0\n"
    "asr   r12, r12, r8\n"
    "add   r0, r11, #0x10000000\n"
    "cmp   r0, #0x20000000\n"
    "bhi   .Lsnxa\\@\n"
    "cmp   r12, r11, asr #31\n"
    "bne   .Lsnxa\\@\n"
    ".Lsnxb\\@:\n"
    "ldr   r0, [r1]\n"
    "smull r0, r12, r0, r6\n"
    "smlal r0, r12, r11, r7\n"
    "adds  r0, r0, #0x800000\n"
    "adc   r12, r12, #0\n"
    "lsr   r0, r0, #24\n"
    "orr   r0, r0, r12, lsl #8\n"
    "asr   r11, r12, #20\n"
    "adds  r11, r11, #1\n"
    "cmp   r11, #1\n"
    "bhi   .Lsnxc\\@\n"
    ".Lsnxd\\@:\n"
    "str   r0, [r1], #4\n"
    ".subsection 1\n"
    ".Lsnxa\\@:\n"               /* mk clamped, counted */
    "add   lr, lr, #1\n"
    "cmp   r12, #0\n"
    "ite   lt\n"
    "movlt r11, #0xF0000000\n"
    "movge r11, #0x10000000\n"
    "b     .Lsnxb\\@\n"
    ".Lsnxc\\@:\n"               /* the exact test of v (lo r0, hi r12 >> 24) */
    "asr   r12, r12, #24\n"
    "add   r11, r0, #0x10000000\n"
    "cmp   r11, #0x20000000\n"
    "bhi   .Lsnxf\\@\n"
    "cmp   r12, r0, asr #31\n"
    "beq   .Lsnxd\\@\n"
    ".Lsnxf\\@:\n"
    "add   lr, lr, #1\n"
    "cmp   r12, #0\n"
    "ite   lt\n"
    "movlt r0, #0xF0000000\n"
    "movge r0, #0x10000000\n"
    "b     .Lsnxd\\@\n"
    ".subsection 0\n"
    ".endm\n"
    ".align 2\n"
    ".global sn_m4_mix\n"
    ".thumb_func\n"
    ".type sn_m4_mix, %function\n"
    "sn_m4_mix:\n"
    "push  {r0, r4-r11, lr}\n"
    "ldm   r0, {r1-r7}\n"         /* q acc kk kend base ck cm */
    "ldr   lr, [r0, #28]\n"
    "1:\n"
    "cmp   r3, r4\n"
    "beq   9f\n"
    "ldrb  r8, [r3]\n"
    "sub   r8, r5, r8\n"          /* sh */
    "sub   r9, r8, #1\n"
    "cmp   r9, #30\n"
    "bhi   9f\n"
    "add   r3, r3, #1\n"
    "mov   r10, #1\n"
    "lsl   r9, r10, r9\n"         /* 2^(sh-1) */
    "rsb   r10, r8, #32\n"
    "snx_val\n"
    "snx_val\n"
    "snx_val\n"
    "b     1b\n"
    "9:\n"
    "ldr   r0, [sp]\n"
    "stm   r0, {r1-r3}\n"
    "str   lr, [r0, #28]\n"
    "pop   {r0, r4-r11, pc}\n"
    ".subsection 1\n"
    ".size sn_m4_mix, .-sn_m4_mix\n"
    ".subsection 0\n"
    ".purgem snx_val\n"
    ".popsection\n");

const char *sn_kernels_name(void) { return "m4"; }

#else
typedef int sn_kernels_m4_unused_; /* ISO C: no empty translation unit */
#endif
