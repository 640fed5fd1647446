/* test_bake_blob.c -- host tool: blob bytes. Determinism, header and section
 * table against sn_format.h, checksum, fixed/float/double agreement, Q ranges. */
#include "sb.h"
#include "sn_format.h"
#include "blob_seg.h"
#include "sn_test.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

static uint32_t u32(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static unsigned u16(const unsigned char *p) { return (unsigned)p[0] | (unsigned)p[1] << 8; }

/* value of real number n of a section (any flavour), fixed decoded with q fractional bits */
static double real_at(const unsigned char *b, uint32_t off, uint32_t n, int q)
{
    int fl = b[SN_H_FLAVOUR];
    const unsigned char *p = b + off + (size_t)n * (fl == 2 ? 8u : 4u);
    if (fl == 0) return ldexp((double)(int32_t)u32(p), -q);
    if (fl == 1) { float f; uint32_t u = u32(p); memcpy(&f, &u, 4); return f; }
    { double d; uint64_t u = (uint64_t)u32(p) | (uint64_t)u32(p + 4) << 32; memcpy(&d, &u, 8); return d; }
}
static uint32_t sec_off(const unsigned char *b, int k) { return u32(b + SN_H_SECTIONS + 16 * k); }
/* Fixed CELLK (BLOB.md format 6.0, read from the spec, not sn_format.h's
 * offsets): per cell i32 diag[8][6] (xx yy zz xy xz yz) at 0, i16 m[28][9]
 * at 192, u8 e[28] at 696, 724 bytes; block (a,b), a < b, is number
 * 7a - a(a-1)/2 + b - a - 1. Entry (r,c) of block (a,b), a <= b, in Q frac_S
 * integer units; *lsb its grid step (1, or 2^e). */
static double cellk_fx(const unsigned char *b, uint32_t cell, int a, int bb, int r, int c, double *lsb)
{
    const unsigned char *ck = b + sec_off(b, SN_SEC_CELLK) + 724u * cell;
    if (a == bb) {
        static const int s6[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
        *lsb = 1;
        return (double)(int32_t)u32(ck + 24 * a + 4 * s6[r][c]);
    } else {
        int o = 7 * a - a * (a - 1) / 2 + bb - a - 1;
        const unsigned char *m = ck + 192 + 18 * o + 2 * (3 * r + c);
        *lsb = ldexp(1.0, ck[696 + o]);
        return (double)(int16_t)(uint16_t)(m[0] | (m[1] << 8)) * *lsb;
    }
}
static uint32_t sec_cnt(const unsigned char *b, int k) { return u32(b + SN_H_SECTIONS + 16 * k + 8); }

static void check_structure(const sb_blob *bl, int flavour, const char *what)
{
    const unsigned char *b = bl->bytes;
    uint32_t total = u32(b + SN_H_TOTAL_SIZE), prev = SN_HEADER_BYTES, k, i;
    int rs = flavour == SB_DOUBLE ? 8 : 4;
    T_CHECK(b[0] == 'S' && b[1] == 'N' && b[2] == 'W' && b[3] == 'B', "%s: magic", what);
    T_CHECK(u32(b + SN_H_ENDIAN) == SN_ENDIAN_MARK && b[SN_H_ENDIAN] == 4, "%s: endian mark stored LE", what);
    T_CHECK(total == bl->size && total % 8 == 0, "%s: total size %u", what, (unsigned)total);
    T_CHECK(u32(b + SN_H_CRC32) == sb_crc32(b + 16, total - 16), "%s: CRC-32 of [16, total)", what);
    T_CHECK(b[SN_H_FLAVOUR] == flavour && b[SN_H_REAL_SIZE] == rs && b[SN_H_NSECTIONS] == SN_SEC_COUNT, "%s: flavour fields", what);
    T_CHECK(u32(b + SN_H_ONE) == (flavour == 0 ? SN_ONE_FIXED : flavour == 1 ? SN_ONE_FLOAT32 : 0u) &&
            u32(b + SN_H_ONE_HI) == (flavour == 2 ? SN_ONE_FLOAT64_HI : 0u), "%s: known 1.0", what);
    T_CHECK(u32(b + SN_H_INSTANCE_BYTES) == SN_INSTANCE_BYTES(u32(b + SN_H_N_VERTICES), u32(b + SN_H_N_FREE), u32(b + SN_H_N_JOINTS),
                                                            u32(b + SN_H_N_CELLS), sec_cnt(b, SN_SEC_CONTROLS), b[SN_H_MAX_FORCES], seg_state_bytes(b) + crease_state_bytes(b) + sec_cnt(b, SN_SEC_FPAIRS) * SN_FPAIR_BYTES, cons_state_bytes(b)),
            "%s: instance bytes from SN_INSTANCE_BYTES", what);
    for (k = 0; k < SN_SEC_COUNT; k++) {
        uint32_t off = sec_off(b, (int)k), size = u32(b + SN_H_SECTIONS + 16 * k + 4), cnt = sec_cnt(b, (int)k), es = u32(b + SN_H_SECTIONS + 16 * k + 12);
        T_CHECK(off % 8 == 0 && off >= prev && off + size <= total && size == cnt * es, "%s: section %u placement", what, (unsigned)k);
        for (i = prev; i < off; i++) if (b[i]) break;
        T_CHECK(i == off, "%s: zero padding before section %u", what, (unsigned)k);
        prev = off + size;
    }
    /* sparsity: columns strictly increasing and above the row */
    {
        uint32_t nF = u32(b + SN_H_N_FREE), nV = u32(b + SN_H_N_VERTICES), r, bad = 0;
        for (r = 0; r < nF; r++) {
            uint32_t a = u32(b + sec_off(b, SN_SEC_ROWPTR) + 4 * r), e = u32(b + sec_off(b, SN_SEC_ROWPTR) + 4 * r + 4), c, prevc = r;
            for (c = a; c < e; c++) { unsigned col = u16(b + sec_off(b, SN_SEC_COLS) + 2 * c); if (col <= prevc || col >= nV) bad++; prevc = col; }
        }
        T_CHECK(bad == 0, "%s: %u bad column indices", what, (unsigned)bad);
    }
}

/* ---- the blob against an independent reading of the spec ----
 * Everything below is transcribed from the prose (runtime/BLOB.md; the five
 * format-3.0 rig sections from the layout comments of runtime/src/sn_format.h,
 * which BLOB.md is to absorb) as literal numbers: it uses none of sn_format.h's
 * macros, nor the tool's CRC, so a tool and a header that drift together from
 * the spec are caught. The instance size is the README's formula ("instance
 * memory ... = 512 + 76 joints + 84 vertices + 73 free + 12 skeleton + 36
 * cells"), plus 4 bytes per control for format 3.0 (rig controls' values). */
static uint32_t spec_crc32(const unsigned char *p, size_t n)
{   /* BLOB.md "Checksum": reflected 0xEDB88320, init and final xor 0xFFFFFFFF, bitwise */
    uint32_t c = 0xFFFFFFFFu;
    size_t i;
    int k;
    for (i = 0; i < n; i++) { c ^= p[i]; for (k = 0; k < 8; k++) c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1; }
    return c ^ 0xFFFFFFFFu;
}
static void check_spec(const sb_blob *bl, int flavour, const char *what)
{
    const unsigned char *b = bl->bytes;
    const unsigned R = flavour == 2 ? 8u : 4u, NSEC = 44u;
    uint32_t total = u32(b + 16), nV = u32(b + 32), nF = u32(b + 36), nC = u32(b + 40), nJ = u32(b + 44), nS = u32(b + 48),
             nT = u32(b + 52), nnz = u32(b + 56), cgd = u16(b + 64), cgm = u16(b + 66), k, nK, nR, nsamp = 0, nent = 0, prev;
    /* section k at 176 + 16 k: {offset, size, count, elem_size}; element sizes (BLOB.md "Sections" with R = real size) */
    const uint32_t elem[44] = {8 + 3 * R, 32, 3 * R, 4, R, 6 * R, R, 4, 2, R, 16, 4, flavour == 0 ? 724u : 324 * R, R, 8, 6,
                               40 + 4 * R, 16, 2 * R, 2, 3 * R, 5 * R, 1, 20 + 9 * R, 3 * R, 8 + 3 * R, 8,
                               12 + 3 * R, 4, 2, 2, 1, 8, 8, 20, 8 + 2 * R,
                               44, flavour == 0 ? 20u : 9 * R,    /* format 6.3: CELLX, CELLXK */
                               2, 4,                              /* format 6.4: FPAIRS, FREFS */
                               8 + 2 * R, 4 + 3 * R, 44, flavour == 0 ? 24u : 10 * R};   /* format 6.5: DETAILS, DETAIL, CELLD, CELLDK */
    uint32_t want[44], inst, segB = 0, conB = 0, crB = 0, crRows = 0, nfp = 0;
    T_CHECK(memcmp(b, "SNWB", 4) == 0 && u16(b + 4) == 6 && u16(b + 6) == 5, "%s: spec: magic SNWB, version 6.5", what);
    T_CHECK(b[8] == 4 && b[9] == 3 && b[10] == 2 && b[11] == 1, "%s: spec: endian mark bytes 04 03 02 01", what);
    T_CHECK(total == bl->size && u32(b + 12) == spec_crc32(b + 16, total - 16), "%s: spec: total size, CRC-32 of [16, total)", what);
    T_CHECK(u32(b + 20) == 176 + 16 * NSEC && b[26] == NSEC, "%s: spec: header size 176 + 16 x %u sections", what, NSEC);
    T_CHECK(b[24] == flavour && b[25] == R && (b[27] & ~1u) == 0, "%s: spec: flavour %d, real size %u, flags", what, flavour, R);
    T_CHECK(u32(b + 28) == (flavour == 0 ? 0x40000000u : flavour == 1 ? 0x3F800000u : 0u) &&
            u32(b + 72) == (flavour == 2 ? 0x3FF00000u : 0u), "%s: spec: 1.0 in the flavour at 28 (and 72)", what);
    T_CHECK(nV <= 65535 && nF >= 1 && nF < nV && nC >= 1 && nC <= 65535 && nJ >= 1 && nJ <= 255 && nS <= 65535,
            "%s: spec: counts nV %u nF %u nC %u nJ %u nS %u", what, nV, nF, nC, nJ, nS);
    T_CHECK(cgd >= 1 && cgd <= cgm && cgm <= 256, "%s: spec: 1 <= cg_default %u <= cg_max %u <= 256", what, cgd, cgm);
    T_CHECK((signed char)b[68] >= -24 && (signed char)b[68] <= 24, "%s: spec: len_shift %d in -24..24", what, (signed char)b[68]);
    if (flavour == 0)
        T_CHECK(b[69] <= 59 && b[70] <= 59 && b[71] <= 50 && (signed char)b[76] >= -40 && (signed char)b[76] <= 60,
                "%s: spec: frac_S %u <= 59, frac_M %u <= 59, frac_P %u <= 50, frac_E %d in -40..60", what, b[69], b[70], b[71], (signed char)b[76]);
    else
        T_CHECK(b[69] == 0 && b[70] == 0 && b[71] == 0 && b[76] == 0, "%s: spec: float flavours store fractions 0", what);
    T_CHECK((flavour == 0 ? (signed char)b[77] >= -40 && (signed char)b[77] <= 60 : b[77] == 0) && b[78] <= 32 && b[79] == 0,
            "%s: spec: frac_F %d, max forces %u <= 32, reserved byte zero", what, (signed char)b[77], b[78]);
    {   /* physics scalars at 80 + i R: a1, b1 in [0, 16] (fixed Q24), h > 0 (Q16.16), FORCE > 0, reserved 11 zero */
        double a1 = real_at(b, 80, 0, 24), b1 = real_at(b, 80, 1, 24), h = real_at(b, 80, 5, 16);
        double fs = real_at(b, 80, 10, flavour == 0 ? (signed char)b[77] : 0), m0 = real_at(b, 80, 6, 16);
        T_CHECK(a1 >= 0 && a1 <= 16 && b1 >= 0 && b1 <= 16 && h > 0 && fs > 0 && real_at(b, 80, 11, 0) == 0,
                "%s: spec: a1 %g, b1 %g in [0, 16], h %g > 0, FORCE %g > 0, reserved real 0", what, a1, b1, h, fs);
        /* FORCE = h^2 / (m0 U unit): with ENERGY = m0 (U unit)^2 / h^2, FORCE^2 ENERGY = h^2 / m0 */
        {
            double en = real_at(b, 80, 7, flavour == 0 ? (signed char)b[76] : 0), want_ = h * h / m0;
            /* MASS_SCALE and TIMESTEP are m0 and h rounded to Q16.16: their rounding bounds the comparison */
            if (m0 < 32767) T_CHECK(fabs(fs * fs * en / want_ - 1) < ldexp(1.0, -17) * (1 / m0 + 2 / h) + 1e-6,
                                    "%s: spec: FORCE^2 ENERGY = h^2/m0 (%g vs %g)", what, fs * fs * en, want_);
        }
    }
    /* counts of the rig sections: CONTROLS nK, RIGS nR; samples and entries are the RIGS' running sums */
    nK = u32(b + 176 + 16 * 16 + 8); nR = u32(b + 176 + 16 * 17 + 8);
    for (k = 0; k < nR; k++) {
        const unsigned char *r = b + u32(b + 176 + 16 * 17) + 16 * k;
        T_CHECK(u32(r + 4) == nsamp && u32(r + 8) == nent, "%s: spec: rig %u's first sample/entry are the running sums", what, k);
        nsamp += r[2]; nent += u32(r + 12);
    }
    {
        const uint32_t w[44] = {nJ, nJ, nV, nV, nF, nF, nF, nF + 1, nnz, nnz, nC, nC, nC, 0, nS, nT, nK, nR, nsamp, nent, nent,
                                u32(b + 176 + 16 * 21 + 8), nF, u32(b + 176 + 16 * 23 + 8), 0, 0, 0, 0, 0, 0, 0,
                                0, 0, 0,    /* format 6.0: the level sections (none without 'levels 2') */
                                0,
                                0,          /* format 6.1: ADAPT, only beside a LEVEL_BLOB */
                                0, 0,       /* format 6.3: CELLX, CELLXK, only with 'levels 2 cut' */
                                0, nF + nC,    /* format 6.4: FPAIRS (below), FREFS: one per free vertex and cell */
                                0, 0, 0, 0};   /* format 6.5: the details, only with 'levels 2 cut' and 'details' */
        memcpy(want, w, sizeof want);
    }
    {   /* FPAIRS / FREFS (BLOB.md "Frame references"), over the free vertices' FRAMES entries then CFRAMES':
         * an entry slerps when bone1 != bone2 and w != 0; the pairs are its distinct (bone1, bone2), increasing
         * as bone1 256 + bone2; an entry's reference is 0xFFFFFFFF if it does not slerp, the index of the first
         * earlier entry with the same 4 bytes, else 2^31 + its pair's index */
        const unsigned char *fr = b + u32(b + 176 + 16 * 3), *cf = b + u32(b + 176 + 16 * 11);
        const unsigned char *pr = b + u32(b + 176 + 16 * 38), *rf = b + u32(b + 176 + 16 * 39);
        uint32_t i, j, seen[256 * 256 / 32], nbad = 0, np = u32(b + 176 + 16 * 38 + 8);
        memset(seen, 0, sizeof seen);
        for (i = 0; i < nF + nC; i++) {
            const unsigned char *e = i < nF ? fr + 4 * i : cf + 4 * (i - nF);
            if (e[0] != e[1] && u16(e + 2) != 0) seen[(e[0] * 256u + e[1]) / 32] |= 1u << ((e[0] * 256u + e[1]) % 32);
        }
        for (k = 0; k < 256 * 256; k++)
            if (seen[k / 32] >> (k % 32) & 1u) {
                nbad += nfp >= np || u16(pr + 2 * nfp) != (k >> 8 | (k & 255u) << 8); /* stored bone1, bone2 */
                nfp++;
            }
        want[38] = nfp;
        for (i = 0; i < nF + nC && np == nfp; i++) {
            const unsigned char *e = i < nF ? fr + 4 * i : cf + 4 * (i - nF);
            uint32_t r = 0xFFFFFFFFu;
            if (e[0] != e[1] && u16(e + 2) != 0) {
                for (j = 0; j < i; j++)
                    if (!memcmp(e, j < nF ? fr + 4 * j : cf + 4 * (j - nF), 4)) break;
                if (j < i) r = j;
                else {
                    for (k = 0; k < np; k++)
                        if (pr[2 * k] == e[0] && pr[2 * k + 1] == e[1]) break;
                    r = 0x80000000u + k;
                }
            }
            nbad += u32(rf + 4 * i) != r;
        }
        T_CHECK(nbad == 0 && np == nfp, "%s: spec: %u frame pairs (want %u), %u wrong pairs or references", what, np, nfp, nbad);
    }
    {   /* CREASE (0 or 1): its record fixes the rows (format 6.0: u16 nQ at +6) and their widths; state 14 per surface vertex + 8 per list entry; max_active rows */
        uint32_t on = u32(b + 176 + 16 * 27 + 8);
        want[27] = on > 1 ? 1 : on;
        want[28] = u32(b + 176 + 16 * 28 + 8);
        if (on == 1) {
            const unsigned char *r = b + u32(b + 176 + 16 * 27);
            want[29] = u16(r + 6) * r[4]; want[30] = u16(r + 6) * r[5];
            crB = (14u * nS + 8u * u16(r) + 7u) & ~7u;
            crRows = u16(r + 2);
        }
    }
    want[22] = u32(b + 176 + 16 * 22 + 8) == 0 ? 0 : nF;   /* VSHARE: 0 or nF */
    {   /* ICHOL (format 6.0): 0, or one 20-byte block per free-free mass entry (COLS entries < nF) */
        const unsigned char *cols = b + u32(b + 176 + 16 * 8);
        uint32_t nff = 0;
        for (k = 0; k < nnz; k++) nff += u16(cols + 2 * k) < nF;
        want[34] = u32(b + 176 + 16 * 34 + 8) == 0 ? 0 : nff;
    }
    {   /* SEGMESH: nodes and attachments are the running sums; state bytes 64 per segment + 24 per node, every level;
         * format 6.2's tail: coarse_sweeps 1..64 (= sweeps at one level), relax 32..63 with relax (1 - gamma) <= 32, u16 0 */
        uint32_t m, nodes = 0, att = 0;
        for (m = 0; m < want[23]; m++) {
            const unsigned char *r = b + u32(b + 176 + 16 * 23) + (20 + 9 * R) * m, *x = r + 16 + 9 * R;
            uint32_t side = u16(r + 4), lv = r[1], l, segs = 0, nn = 0;
            double gam = real_at(b, (uint32_t)(r + 16 - b), 1, 30);
            T_CHECK(x[0] >= 1 && x[0] <= 64 && (lv > 1 || x[0] == r[2]) && x[1] >= 32 && x[1] <= 63 && x[1] * (1 - gam) <= 32 + 1e-9 &&
                    u16(x + 2) == 0, "%s: spec: segment mesh %u: coarse_sweeps %u relax %u gamma %g", what, m, x[0], x[1], gam);
            T_CHECK(u32(r + 8) == nodes && u32(r + 12) == att, "%s: spec: segment mesh %u's first node/attachment are the running sums", what, m);
            if (r[0] == 0) { segs = side - 1; nn = side; }
            else for (l = 0; l < lv; l++) { uint32_t s_ = ((side - 1) >> l) + 1; segs += 2 * s_ * (s_ - 1) + (s_ == 2 ? 2 : 0); nn += s_ * s_; }
            nodes += r[0] == 0 ? side : side * side;
            att += u16(r + 6);
            segB += 64 * segs + 24 * nn;
        }
        want[24] = nodes; want[25] = att;
    }
    want[13] = u32(b + 176 + 16 * 13 + 8) == 0 ? 0 : nF;   /* LIMIT: 0 or nF */
    want[26] = u32(b + 176 + 16 * 26 + 8) == 0 ? 0 : 1;    /* CONSTRAINTS: 0 or 1 record {u8 constraints, u8 colliders, u16 contacts, u32 0} */
    {   /* state: 80 per constraint, 64 per collider, 136 per row, 4 per entry of the rows' lower triangle;
         * rows: 3 per constraint, 1 per contact, the crease's max_active */
        const unsigned char *r = b + u32(b + 176 + 16 * 26);
        uint32_t c0 = want[26] ? r[0] : 0, c1 = want[26] ? r[1] : 0, c2 = want[26] ? u16(r + 2) : 0, rows = 3u * c0 + c2 + crRows;
        if (want[26])
            T_CHECK(r[0] <= 64 && r[1] <= 16 && u16(r + 2) <= 256 && rows <= 512 && u32(r + 4) == 0, "%s: spec: constraint maxima in range", what);
        if (rows || c1) conB = 80u * c0 + 64u * c1 + 136u * rows + 4u * (rows * (rows + 1u) / 2u);
    }
    for (k = 0, prev = 176 + 16 * NSEC; k < NSEC; k++) {
        const unsigned char *e = b + 176 + 16 * k;
        uint32_t off = u32(e), size = u32(e + 4), cnt = u32(e + 8), es = u32(e + 12), i;
        T_CHECK(es == elem[k] && cnt == want[k] && (uint64_t)size == (uint64_t)cnt * es && off % 8 == 0 && off >= prev &&
                (uint64_t)off + size <= total, "%s: spec: section %u: offset %u size %u count %u (want %u) elem %u (want %u)",
                what, k, off, size, cnt, want[k], es, elem[k]);
        for (i = prev; i < off && i < total; i++) if (b[i]) break;
        T_CHECK(i >= off || i >= total, "%s: spec: padding before section %u is zero", what, k);
        prev = off + size;
    }
    for (k = prev; k < total; k++) if (b[k]) break;
    T_CHECK(k == total, "%s: spec: trailing padding is zero", what);
    inst = (832u + (76u + 48u) * nJ + 24u * nV + 97u * nF + 12u * (nV - nF > nF ? nV - nF : nF) + 36u * nC + 4u * nK + 64u * b[78] +
            segB + crB + 40u * nfp + 7u) & ~7u;   /* format 6.4: 40 per frame pair */
    inst = (inst + conB + 7u) & ~7u;
    T_CHECK(u32(b + 60) == inst, "%s: spec: instance bytes %u, README formula %u", what, u32(b + 60), inst);
}

/* Integer block-row sums of every cell's fixed stiffness (the 36 stored
 * blocks used as (a,b) and (b,a), as the runtime applies them) against the
 * double blob's exact row sums, rounded: the largest difference in LSBs. */
static double row_sum_error_lsb(const unsigned char *fx, const unsigned char *db, int frac)
{
    uint32_t nC = u32(fx + SN_H_N_CELLS), e;
    double worst = 0;
    for (e = 0; e < nC; e++) {
        double exact[24][3] = {{0}}, bound[8] = {0};
        int64_t isum[24][3] = {{0}};
        int a, b, r, c, n = 0;
        for (a = 0; a < 8; a++)
            for (b = a; b < 8; b++, n++)
                for (r = 0; r < 3; r++)
                    for (c = 0; c < 3; c++) {
                        uint32_t idx = 324 * e + 9 * (uint32_t)n + 3 * (uint32_t)r + (uint32_t)c;
                        double d = real_at(db, sec_off(db, SN_SEC_CELLK), idx, 0), lsb;
                        int64_t q = (int64_t)cellk_fx(fx, e, a, b, r, c, &lsb);
                        exact[3 * a + r][c] += d; isum[3 * a + r][c] += q;
                        if (b != a) { exact[3 * b + c][r] += d; isum[3 * b + c][r] += q; }
                        if (b != a && r == 0 && c == 0) { bound[a] += 0.5 * lsb; bound[b] += 0.5 * lsb; }
                    }
        /* the diagonal absorbs its row's rounded neighbours exactly; its
         * symmetrization splits their asymmetric rounding: <= half the sum of
         * the 7 neighbours' grid steps, + 0.5 (average) + 1 (the two
         * rounded exact sums) */
        for (r = 0; r < 24; r++)
            for (c = 0; c < 3; c++)
                worst = fmax(worst, fabs((double)isum[r][c] - floor(ldexp(exact[r][c], frac) + 0.5)) / (bound[r / 3] + 1.5));
    }
    return worst;
}

static double max_stored(const unsigned char *b, const int *secs, int nsec)
{
    double mx = 0;
    int s;
    uint32_t i;
    for (s = 0; s < nsec; s++) {
        uint32_t n = u32(b + SN_H_SECTIONS + 16 * secs[s] + 4) / 4;
        for (i = 0; i < n; i++) mx = fmax(mx, fabs((double)(int32_t)u32(b + sec_off(b, secs[s]) + 4 * i)));
    }
    return mx;
}

int main(void)
{
    const char *descs[3] = {"tools/examples/cow/cow.sinew", "tools/examples/limb/limb.sinew", NULL};
    int di;
    (void)t_seed;
    for (di = 0; descs[di]; di++) {
        sb_model o1, o2, o3, o4;
        sb_blob fx, fx2, fl, db;
        const char *what = descs[di];
        if (sb_bake_file(what, SB_FIXED, 1, &o1, &fx) || sb_bake_file(what, SB_FIXED, 1, &o2, &fx2) ||
            sb_bake_file(what, SB_FLOAT, 1, &o3, &fl) || sb_bake_file(what, SB_DOUBLE, 1, &o4, &db)) {
            T_CHECK(0, "bake %s: %s", what, sb_error());
            continue;
        }
        T_CHECK(fx.size == fx2.size && memcmp(fx.bytes, fx2.bytes, fx.size) == 0, "%s: two bakes give identical bytes", what);
        /* format 6.0: the fixed CELLK record is 724 bytes per cell, the float32 one 1296 */
        T_CHECK(fl.size - fx.size == (1296u - 724u) * u32(fx.bytes + SN_H_N_CELLS), "%s: float32 blob = fixed + 572 bytes per cell", what);
        check_structure(&fx, SB_FIXED, what);
        check_structure(&fl, SB_FLOAT, what);
        check_structure(&db, SB_DOUBLE, what);
        check_spec(&fx, SB_FIXED, what);
        check_spec(&fl, SB_FLOAT, what);
        check_spec(&db, SB_DOUBLE, what);
        {   /* fixed formats: the largest |entry| of each group lands in [2^26, 2^27] */
            static const int gS[1] = {SN_SEC_CELLK}, gM[3] = {SN_SEC_MDIAG, SN_SEC_MOFF, SN_SEC_MLUMP}, gP[1] = {SN_SEC_PRECOND};
            double ms = 0, mm = max_stored(fx.bytes, gM, 3), mp = max_stored(fx.bytes, gP, 1);
            uint32_t e;
            int a, bb, r, c;
            (void)gS;
            for (e = 0; e < u32(fx.bytes + SN_H_N_CELLS); e++)
                for (a = 0; a < 8; a++)
                    for (bb = a; bb < 8; bb++)
                        for (r = 0; r < 3; r++)
                            for (c = 0; c < 3; c++) {
                                double lsb;
                                ms = fmax(ms, fabs(cellk_fx(fx.bytes, e, a, bb, r, c, &lsb)));
                            }
            T_CHECK(ms >= 67108864.0 && ms <= 134217728.0, "%s: max |S| stored %.0f in [2^26, 2^27]", what, ms);
            T_CHECK(mm >= 67108864.0 && mm <= 134217728.0, "%s: max |M| stored %.0f in [2^26, 2^27]", what, mm);
            T_CHECK(mp >= 67108864.0 && mp <= 134217728.0, "%s: max |P| stored %.0f in [2^26, 2^27]", what, mp);
            T_FIGURE("%s: frac_S %d frac_M %d frac_P %d len_shift %d, fixed blob %lu bytes, double %lu bytes",
                     what, fx.frac_S, fx.frac_M, fx.frac_P, fx.len_shift, (unsigned long)fx.size, (unsigned long)db.size);
        }
        {   /* every real of every section: fixed within half an LSB of double, float32 within float rounding */
            static const int secs[8] = {SN_SEC_REST, SN_SEC_MDIAG, SN_SEC_CELLK, SN_SEC_PRECOND, SN_SEC_MLUMP, SN_SEC_MOFF, SN_SEC_LIMIT, SN_SEC_JOINTS};
            int s;
            for (s = 0; s < 8; s++) {
                int k = secs[s], q = k == SN_SEC_REST || k == SN_SEC_JOINTS || k == SN_SEC_LIMIT ? SN_Q_LEN
                                   : k == SN_SEC_CELLK ? fx.frac_S : k == SN_SEC_PRECOND ? fx.frac_P : fx.frac_M;
                uint32_t n = u32(fx.bytes + SN_H_SECTIONS + 16 * k + 4) / 4, i;
                double efx = 0, efl = 0, mx = 0, efd = 0;
                if (k == SN_SEC_JOINTS) continue;
                if (k == SN_SEC_CELLK) n = 324 * u32(fx.bytes + SN_H_N_CELLS); /* fixed: 724 bytes per cell */
                for (i = 0; i < n; i++) {
                    double d = real_at(db.bytes, sec_off(db.bytes, k), i, 0), err, lsb = 1;
                    int blk = (int)((i % 324) / 9), isdiag = blk == 0 || blk == 8 || blk == 15 || blk == 21 ||
                                                           blk == 26 || blk == 30 || blk == 33 || blk == 35;
                    if (k == SN_SEC_CELLK) { /* block number blk of row a: (a, bb) */
                        int a = 0, bb, rem = blk;
                        while (rem >= 8 - a) { rem -= 8 - a; a++; }
                        bb = a + rem;
                        err = fabs(ldexp(cellk_fx(fx.bytes, i / 324, a, bb, (int)(i % 9) / 3, (int)(i % 3), &lsb), -q) - d);
                    } else err = fabs(real_at(fx.bytes, sec_off(fx.bytes, k), i, q) - d);
                    if (k == SN_SEC_CELLK && isdiag) efd = fmax(efd, err / ldexp(0.5 * 7 * 4096 + 1.0, -q)); /* diagonal blocks of a cell */
                    else efx = fmax(efx, err / lsb);
                    efl = fmax(efl, fabs(real_at(fl.bytes, sec_off(fl.bytes, k), i, 0) - d));
                    mx = fmax(mx, fabs(d));
                }
                if (k == SN_SEC_CELLK) /* absorbs the rounding of the 7 neighbour blocks of its row (sb_blob.c cell_blocks) */
                    T_NEAR(efd, 0, 1 + 1e-9, "cell diagonal = rounded row sum - rounded neighbours, symmetrized: <= 7 half-steps of 2^12 + 1 LSB");
                T_NEAR(efx, 0, ldexp(0.5, -q) * (1 + 1e-9), "fixed = round to nearest: at most half an LSB (CELLK off-diagonal: of its block's 2^e)");
                T_NEAR(efl, 0, mx * 6e-8, "float32 rounding: 2^-24 relative to the entry, <= 2^-24 * max");
            }
        }
        {   /* translation null space survives quantization: integer block-row
             * sums equal the rounded exact ones up to the diagonal's
             * symmetrization, which splits the asymmetry of a cell row's 7
             * independently rounded neighbour blocks (<= 7 x 0.5 LSB per entry
             * pair, halved, + 0.5 for the average's rounding): bound 4 LSB.
             * Rounding each entry alone left row sums off by up to 26 LSB and a
             * slender beam 1.4% too stiff (tests/reference/README.md, finding 2). */
            double lsb = row_sum_error_lsb(fx.bytes, db.bytes, fx.frac_S);
            T_CHECK(lsb <= 1.0, "%s: fixed cell block-row sums within %.2f of their bound (half the row's neighbour grid steps + 1.5 LSB)", what, lsb);
            T_FIGURE("%s: fixed block-row sums off the rounded exact sums by at most %.2f of the bound", what, lsb);
        }
        {   /* header scalars: h, gravity in internal units per step^2 */
            double h = real_at(db.bytes, SN_H_REALS, SN_R_TIMESTEP, 0), gy = real_at(db.bytes, SN_H_REALS, SN_R_GRAV_Y, 0);
            double U = ldexp(o4.unit, db.len_shift);
            T_NEAR(gy, h * h * o4.g[1] / U, 1e-15, "g^ = h^2 g / U (NUMERICS.md), double round-off");
            T_NEAR(real_at(fx.bytes, SN_H_REALS, SN_R_GRAV_Y, SN_Q_LEN), gy, ldexp(0.5, -SN_Q_LEN), "Q22 rounding");
            /* health scalars: joules per internal energy unit m0 (U unit)^2 / h^2, cell in internal units */
            {
                double Um = ldexp(o4.unit, db.len_shift), es = db.m0 * Um * Um / (h * h);
                int fe = (signed char)fx.bytes[SN_H_FRAC_E];
                T_NEAR(real_at(db.bytes, SN_H_REALS, SN_R_ENERGY, 0), es, 1e-12 * es, "ENERGY = m0 (U unit)^2 / h^2");
                T_NEAR(real_at(fx.bytes, SN_H_REALS, SN_R_ENERGY, fe), es, ldexp(0.5, -fe), "Q frac_E rounding");
                T_CHECK(ldexp(es, fe) >= 536870912.0 && ldexp(es, fe) < 1073741824.0, "%s: ENERGY stored in [2^29, 2^30)", what);
                T_NEAR(real_at(db.bytes, SN_H_REALS, SN_R_CELL, 0), o4.c / ldexp(1.0, db.len_shift), 1e-15, "CELL = cell / U");
            }
        }
        T_CHECK(o1.nf < o1.nv && o1.nf >= 1, "%s: free and skeleton vertices present", what);
        sb_blob_free(&fx); sb_blob_free(&fx2); sb_blob_free(&fl); sb_blob_free(&db);
        sb_model_free(&o1); sb_model_free(&o2); sb_model_free(&o3); sb_model_free(&o4);
    }
    T_CHECK(sb_crc32((const unsigned char *)"123456789", 9) == 0xCBF43926u, "CRC-32 check value (zlib)");
    return T_END();
}
