/* test_runtime_blob.c -- sn_blob_validate and the blob accessors.
 *
 * A hand-built minimal blob (tests/fuzz/sn_tblob.h, independent of the host
 * tool) must be accepted; then every header, section-table and content rule
 * is broken one at a time (checksum recomputed, so the rule itself is what
 * fails) and the validator must return that rule's specific status. Built
 * twice: fixed (default) and float (-DSN_FLOAT).
 */
#include <stdint.h>
#include <string.h>

#include "sn_test.h"
#include "sinew.h"
#include "sn_internal.h"
#include "fuzz/sn_tblob.h"

#define CAP 8192
typedef union { uint64_t align; unsigned char b[CAP + 16]; } tbuf;
static tbuf g_base, g_work;
static uint32_t g_total;

#if defined(SN_FLOAT)
#define FLAV "float"
#define SN_FLOAT_OR(f, i) (f)
#else
#define FLAV "fixed"
#define SN_FLOAT_OR(f, i) (i)
#endif

/* A raw value just beyond an integer bound `lim` of Q format q (fixed: lim+1;
 * float: the true value lim/2^q times 1.0001), or exactly at it. */
static void put_over(unsigned char *p, double lim, int q) {
#if defined(SN_FLOAT)
    tb_real(p, lim / ldexp(1.0, q) * 1.0001, 0);
#else
    (void)q;
    tb_u32(p, (uint32_t)(int32_t)(lim >= 0 ? lim + 1 : lim - 1));
#endif
}
static void put_at(unsigned char *p, double lim, int q) {
#if defined(SN_FLOAT)
    tb_real(p, lim / ldexp(1.0, q), 0);
#else
    (void)q;
    tb_u32(p, (uint32_t)(int32_t)lim);
#endif
}

static sn_status run(const unsigned char *b, size_t size) {
    const sn_blob *out = (const sn_blob *)1;
    sn_status s = sn_blob_validate(b, size, &out);
    if (s != SN_OK && out != NULL) return SN_STATUS_COUNT; /* must clear *out */
    if (s == SN_OK && out != (const sn_blob *)(const void *)b) return SN_STATUS_COUNT;
    return s;
}

static void expect(const char *what, sn_status got, sn_status want) {
    T_CHECK(got == want, "[%s] %s: got %s (%d), want %s (%d)", FLAV, what,
            got < SN_STATUS_COUNT ? sn_status_str(got) : "bad *out", (int)got, sn_status_str(want),
            (int)want);
}

/* Mutate a fresh copy (b), recompute the CRC, validate `size` bytes. */
#define CASE(want, what, code) do { \
    unsigned char *b = g_work.b; \
    memcpy(b, g_base.b, CAP); \
    { code; } \
    tb_fix_crc(b); \
    expect(what, run(b, g_total), want); \
} while (0)
/* Same, validating `size` bytes. */
#define CASE_SZ(want, what, size, code) do { \
    unsigned char *b = g_work.b; \
    memcpy(b, g_base.b, CAP); \
    { code; } \
    tb_fix_crc(b); \
    expect(what, run(b, size), want); \
} while (0)
/* Same without the CRC fix-up (for total_size edits and checksum tests). */
#define CASE_RAW(want, what, size, code) do { \
    unsigned char *b = g_work.b; \
    memcpy(b, g_base.b, CAP); \
    { code; } \
    expect(what, run(b, size), want); \
} while (0)

#define SEC(k) (b + tb_sec(b, k))
#define TAB(k, f) (b + SN_H_SECTIONS + 16 * (k) + 4 * (f)) /* f: 0 off, 1 size, 2 count, 3 elem */

static void test_header(void) {
    uint32_t nnz;
    expect("valid blob", run(g_base.b, g_total), SN_OK);
    expect("valid blob, larger buffer", run(g_base.b, CAP), SN_OK);
    {
        const sn_blob *o;
        expect("NULL data", sn_blob_validate(NULL, g_total, &o), SN_ERR_NULL);
        expect("NULL out", sn_blob_validate(g_base.b, g_total, NULL), SN_ERR_NULL);
    }
    memcpy(g_work.b + 4, g_base.b, g_total);
    expect("4-byte aligned data", run(g_work.b + 4, g_total), SN_ERR_ALIGN);
    expect("shorter than header", run(g_base.b, SN_HEADER_BYTES - 1), SN_ERR_TRUNCATED);
    expect("empty", run(g_base.b, 0), SN_ERR_TRUNCATED);
    expect("one byte short", run(g_base.b, g_total - 1), SN_ERR_TRUNCATED);

    CASE(SN_ERR_MAGIC, "magic", b[3] = 'X');
    CASE(SN_ERR_ENDIAN, "byte-swapped endian mark", tb_u32(b + SN_H_ENDIAN, 0x04030201u));
    CASE(SN_ERR_ENDIAN, "wrong endian mark", tb_u32(b + SN_H_ENDIAN, 0x01020305u));
    CASE(SN_ERR_VERSION, "major 1 (format 1.0)", tb_u16(b + SN_H_VER_MAJOR, 1));
    CASE(SN_ERR_VERSION, "major 2 (format 2.0, no rig sections)", tb_u16(b + SN_H_VER_MAJOR, 2));
    CASE(SN_ERR_VERSION, "major 7", tb_u16(b + SN_H_VER_MAJOR, 7));
    CASE(SN_ERR_VERSION, "major 5 (format 5.0, no level sections, larger instance layout, dense crease rows, int32 CELLK, no ICHOL: re-bake)", tb_u16(b + SN_H_VER_MAJOR, 5));
    CASE(SN_ERR_VERSION, "major 4 (re-bake)", tb_u16(b + SN_H_VER_MAJOR, 4));
    CASE(SN_ERR_VERSION, "major 3 (re-bake)", tb_u16(b + SN_H_VER_MAJOR, 3));
    CASE(SN_ERR_VERSION, "major 4 (format 4.0, no constraint section: re-bake)", tb_u16(b + SN_H_VER_MAJOR, 4));
    CASE(SN_ERR_VERSION, "major 0", tb_u16(b + SN_H_VER_MAJOR, 0));
    CASE(SN_ERR_VERSION, "byte-swapped major", tb_u16(b + SN_H_VER_MAJOR, 0x0200));
    CASE(SN_ERR_VERSION, "minor 1", tb_u16(b + SN_H_VER_MINOR, SN_FORMAT_MINOR + 1));
    CASE(SN_ERR_VERSION, "an older minor (6.0's section table is shorter)", tb_u16(b + SN_H_VER_MINOR, SN_FORMAT_MINOR - 1));
    CASE(SN_ERR_FLAVOUR, "other flavour", b[SN_H_FLAVOUR] = (unsigned char)(1 - SN_FLAVOUR));
    CASE(SN_ERR_FLAVOUR, "float64 flavour", b[SN_H_FLAVOUR] = 2);
    CASE(SN_ERR_FLAVOUR, "real size 8", b[SN_H_REAL_SIZE] = 8);
    CASE(SN_ERR_FLAVOUR, "other flavour's one",
         tb_u32(b + SN_H_ONE, SN_FLAVOUR ? SN_ONE_FIXED : SN_ONE_FLOAT32));
    CASE(SN_ERR_FLAVOUR, "one_hi of float64", tb_u32(b + SN_H_ONE_HI, SN_ONE_FLOAT64_HI));
    CASE_RAW(SN_ERR_HEADER, "total < header", g_total, tb_u32(b + SN_H_TOTAL_SIZE, 100));
    CASE_RAW(SN_ERR_TRUNCATED, "total > size", g_total, tb_u32(b + SN_H_TOTAL_SIZE, g_total + 8));
    CASE_RAW(SN_ERR_TRUNCATED, "total huge", g_total, tb_u32(b + SN_H_TOTAL_SIZE, 0xFFFFFFFFu));
    CASE(SN_ERR_HEADER, "header_size", tb_u32(b + SN_H_HEADER_SIZE, SN_HEADER_BYTES + 8));
    CASE(SN_ERR_HEADER, "n_sections", b[SN_H_NSECTIONS] = SN_SEC_COUNT - 1);
    CASE(SN_ERR_HEADER, "unknown flag bit 1", b[SN_H_FLAGS] |= 2);
    CASE(SN_ERR_HEADER, "unknown flag bit 7", b[SN_H_FLAGS] |= 0x80);
    CASE(SN_OK, "REST_MODELLED clear", b[SN_H_FLAGS] = 0);
    CASE(SN_OK, "REST_MODELLED set", b[SN_H_FLAGS] = SN_FLAG_REST_MODELLED);
    CASE(SN_ERR_HEADER, "reserved1 byte", b[SN_H_RESERVED1] = 1);
    CASE(SN_ERR_HEADER, "reserved1 byte top bit", b[SN_H_RESERVED1] = 0x80);
    CASE(SN_ERR_HEADER, "max forces > SN_MAX_FORCES", b[SN_H_MAX_FORCES] = SN_MAX_FORCES + 1);
    CASE(SN_ERR_HEADER, "max forces changed: instance bytes no longer match", b[SN_H_MAX_FORCES] = TB_NFRC + 1);
    CASE(SN_ERR_HEADER, "frac_F > 60", b[SN_H_FRAC_F] = 61);
#if !defined(SN_VALIDATE_NO_CHECKSUM)
    CASE_RAW(SN_ERR_CHECKSUM, "flipped data bit", g_total, b[g_total - 3] ^= 0x10);
    CASE_RAW(SN_ERR_CHECKSUM, "flipped header count bit", g_total, b[SN_H_N_CELLS] ^= 0x01);
    CASE_RAW(SN_ERR_CHECKSUM, "crc field", g_total, b[SN_H_CRC32] ^= 0x80);
#endif

    /* counts and settings */
    CASE(SN_ERR_HEADER, "nF = 0", tb_u32(b + SN_H_N_FREE, 0));
    CASE(SN_ERR_HEADER, "nF = nV", tb_u32(b + SN_H_N_FREE, TB_NV));
    CASE(SN_ERR_HEADER, "nF > nV", tb_u32(b + SN_H_N_FREE, TB_NV + 1));
    CASE(SN_ERR_HEADER, "nV = 65536", tb_u32(b + SN_H_N_VERTICES, 65536));
    CASE(SN_ERR_HEADER, "nJ = 0", tb_u32(b + SN_H_N_JOINTS, 0));
    CASE(SN_ERR_HEADER, "nJ = 256", tb_u32(b + SN_H_N_JOINTS, 256));
    CASE(SN_ERR_HEADER, "nS = 65536", tb_u32(b + SN_H_N_SURFACE, 65536));
    CASE(SN_ERR_HEADER, "cg default 0", tb_u16(b + SN_H_CG_DEFAULT, 0));
    CASE(SN_ERR_HEADER, "cg default > max", tb_u16(b + SN_H_CG_DEFAULT, 33));
    CASE(SN_ERR_HEADER, "cg max 257", tb_u16(b + SN_H_CG_MAX, 257));
    CASE(SN_OK, "cg max 256", tb_u16(b + SN_H_CG_MAX, 256));
    CASE(SN_OK, "cg default = max", tb_u16(b + SN_H_CG_DEFAULT, 32));
    CASE(SN_ERR_HEADER, "len_shift 25", b[SN_H_LEN_SHIFT] = 25);
    CASE(SN_ERR_HEADER, "len_shift -25", b[SN_H_LEN_SHIFT] = (unsigned char)(256 - 25));
    CASE(SN_OK, "len_shift -24", b[SN_H_LEN_SHIFT] = (unsigned char)(256 - 24));
    CASE(SN_ERR_HEADER, "frac_S 60", b[SN_H_FRAC_S] = 60);
    CASE(SN_OK, "frac_S 59", b[SN_H_FRAC_S] = 59);
    CASE(SN_ERR_HEADER, "frac_M 60", b[SN_H_FRAC_M] = 60);
    CASE(SN_ERR_HEADER, "frac_P 255", b[SN_H_FRAC_P] = 255);
    CASE(SN_ERR_HEADER, "frac_P 51", b[SN_H_FRAC_P] = 51);
    CASE(SN_OK, "frac_P 50", b[SN_H_FRAC_P] = 50);
#if defined(SN_FLOAT)
    CASE(SN_ERR_HEADER, "frac_E != 0 in a float blob", b[SN_H_FRAC_E] = 16);
#else
    CASE(SN_ERR_HEADER, "frac_E 61", b[SN_H_FRAC_E] = 61);
    CASE(SN_ERR_HEADER, "frac_E -41", b[SN_H_FRAC_E] = (unsigned char)(256 - 41));
    CASE(SN_OK, "frac_E -40", b[SN_H_FRAC_E] = (unsigned char)(256 - 40));
    CASE(SN_OK, "frac_E 60", b[SN_H_FRAC_E] = 60);
#endif
    CASE(SN_ERR_HEADER, "nC = 0", tb_u32(b + SN_H_N_CELLS, 0));
    CASE(SN_ERR_HEADER, "nC = 65536", tb_u32(b + SN_H_N_CELLS, 65536));
    CASE(SN_ERR_HEADER, "instance_bytes too small",
         tb_u32(b + SN_H_INSTANCE_BYTES, SN_INSTANCE_BYTES(TB_NV, TB_NF, TB_NJ, TB_NC, TB_NK, TB_NFRC, TB_SEGB + TB_CRB + TB_FPB, TB_CONB) - 8));
    CASE(SN_ERR_HEADER, "instance_bytes of the 1.0 formula (no per-cell memory)",
         tb_u32(b + SN_H_INSTANCE_BYTES, SN_INSTANCE_BYTES(TB_NV, TB_NF, TB_NJ, 0, TB_NK, TB_NFRC, TB_SEGB + TB_CRB + TB_FPB, TB_CONB)));
    CASE(SN_ERR_HEADER, "instance_bytes larger than the formula (a blob cannot ask for memory)",
         tb_u32(b + SN_H_INSTANCE_BYTES, 1u << 20));
    CASE(SN_ERR_HEADER, "instance_bytes without the control values",
         tb_u32(b + SN_H_INSTANCE_BYTES, SN_INSTANCE_BYTES(TB_NV, TB_NF, TB_NJ, TB_NC, 0, TB_NFRC, TB_SEGB + TB_CRB + TB_FPB, TB_CONB)));

    /* physics scalars */
#define RL(i) (b + SN_H_REALS + 4 * (i))
    /* constraint section (format 5.0): every field bounded by the arithmetic it feeds */
#define CON (b + tb_sec(b, SN_SEC_CONSTRAINTS))
    CASE(SN_ERR_VALUE, "constraints beyond SN_MAX_CONSTRAINTS", CON[0] = SN_MAX_CONSTRAINTS + 1);
    CASE(SN_ERR_VALUE, "colliders beyond SN_MAX_COLLIDERS", CON[1] = SN_MAX_COLLIDERS + 1);
    CASE(SN_ERR_VALUE, "contacts beyond SN_MAX_CONTACTS", tb_u16(CON + 2, SN_MAX_CONTACTS + 1));
    CASE(SN_ERR_VALUE, "rows beyond SN_MAX_ROWS (3 x 64 + 256 + ...)", { CON[0] = 64; tb_u16(CON + 2, 256 + 1); });
    CASE(SN_ERR_VALUE, "colliders without contact rows", tb_u16(CON + 2, 0));
    CASE(SN_ERR_VALUE, "constraint record's reserved word not 0", CON[5] = 1);
    CASE(SN_ERR_HEADER, "constraint maxima changed: instance bytes no longer the layout's", CON[0] = 1);
    CASE(SN_ERR_SECTION, "constraint record count 2", tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_CONSTRAINTS + 8, 2));
    CASE(SN_ERR_SECTION, "constraint record element size 4", tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_CONSTRAINTS + 12, 4));
    /* crease neighbourhood rows (format 6.0: sparse, owners increasing; the test blob has one row per surface vertex) */
    CASE(SN_ERR_VALUE, "crease rows 0", tb_u16(b + tb_sec(b, SN_SEC_CREASE) + 6, 0));
    CASE(SN_ERR_VALUE, "crease rows nS + 1", tb_u16(b + tb_sec(b, SN_SEC_CREASE) + 6, TB_NS + 1));
    CASE(SN_ERR_SECTION, "crease rows 2, VNBR/TNBR counts for nS rows", tb_u16(b + tb_sec(b, SN_SEC_CREASE) + 6, 2));
    CASE(SN_ERR_INDEX, "crease row owners 1, 0 (not increasing)",
         tb_u16(b + tb_sec(b, SN_SEC_CREASE_VNBR), 1); tb_u16(b + tb_sec(b, SN_SEC_CREASE_VNBR) + 4, 0));
    CASE(SN_ERR_INDEX, "crease row owners 0, 0 (repeated)", tb_u16(b + tb_sec(b, SN_SEC_CREASE_VNBR) + 4, 0));
    CASE(SN_ERR_INDEX, "crease last row's owner NONE", tb_u16(b + tb_sec(b, SN_SEC_CREASE_VNBR) + 4 * (TB_NS - 1), SN_CREASE_NONE));
    CASE(SN_ERR_INDEX, "crease last row's owner nS", tb_u16(b + tb_sec(b, SN_SEC_CREASE_VNBR) + 4 * (TB_NS - 1), TB_NS));
    CASE(SN_ERR_VALUE, "crease exclude -1 LSB", tb_real(b + tb_sec(b, SN_SEC_CREASE) + 20, -ldexp(1.0, -22), SN_Q_LEN));
    CASE(SN_ERR_VALUE, "crease exclude 2^28 + 64 LSB", tb_real(b + tb_sec(b, SN_SEC_CREASE) + 20, 64.0 + ldexp(1.0, -16), SN_Q_LEN));
    CASE(SN_OK, "crease exclude 2^28 (64 internal units)", tb_real(b + tb_sec(b, SN_SEC_CREASE) + 20, 64.0, SN_Q_LEN));
    CASE(SN_OK, "crease row 0: its owner only (tail NONE)",
         tb_u16(b + tb_sec(b, SN_SEC_CREASE_VNBR) + 2, SN_CREASE_NONE));
#undef CON
    CASE(SN_ERR_VALUE, "a1 < 0", tb_real(RL(SN_R_A1), -0.001, SN_Q_COEF));
    CASE(SN_ERR_VALUE, "a1 > 16", put_over(RL(SN_R_A1), 1 << 28, SN_Q_COEF));
    CASE(SN_OK, "a1 = 16", put_at(RL(SN_R_A1), 1 << 28, SN_Q_COEF));
    CASE(SN_OK, "a1 = 0", put_at(RL(SN_R_A1), 0, SN_Q_COEF));
    CASE(SN_ERR_VALUE, "b1 > 16", put_over(RL(SN_R_B1), 1 << 28, SN_Q_COEF));
    CASE(SN_ERR_VALUE, "b1 < 0", tb_real(RL(SN_R_B1), -0.5, SN_Q_COEF));
    CASE(SN_ERR_VALUE, "grav x > 2^27", put_over(RL(SN_R_GRAV_X), 1 << 27, SN_Q_LEN));
    CASE(SN_ERR_VALUE, "grav z < -2^27", put_over(RL(SN_R_GRAV_Z), -(1 << 27), SN_Q_LEN));
    CASE(SN_OK, "grav y = -2^27", put_at(RL(SN_R_GRAV_Y), -(1 << 27), SN_Q_LEN));
    CASE(SN_ERR_VALUE, "timestep 0", tb_real(RL(SN_R_TIMESTEP), 0.0, 16));
    CASE(SN_ERR_VALUE, "timestep < 0", tb_real(RL(SN_R_TIMESTEP), -1.0 / 60, 16));
    /* health scalars: ENERGY, CELL, DISP_BOUND > 0; reserved reals 0 */
    CASE(SN_ERR_VALUE, "ENERGY 0", tb_real(RL(SN_R_ENERGY), 0.0, 0));
    CASE(SN_ERR_VALUE, "ENERGY < 0", tb_real(RL(SN_R_ENERGY), -1.0, TB_FRAC_E));
    CASE(SN_OK, "ENERGY smallest positive (fixed: 1 LSB)", put_at(RL(SN_R_ENERGY), 1, 0));
#if defined(SN_FLOAT)
    CASE(SN_OK, "ENERGY 0.001 J per unit (a small creature)", tb_real(RL(SN_R_ENERGY), 0.001, 0));
#endif
    CASE(SN_ERR_VALUE, "CELL 0", tb_real(RL(SN_R_CELL), 0.0, SN_Q_LEN));
    CASE(SN_ERR_VALUE, "CELL < 0", tb_real(RL(SN_R_CELL), -0.5, SN_Q_LEN));
    CASE(SN_ERR_VALUE, "CELL > 2^27 (32 units)", put_over(RL(SN_R_CELL), 1 << 27, SN_Q_LEN));
    CASE(SN_OK, "CELL = 2^27", put_at(RL(SN_R_CELL), 1 << 27, SN_Q_LEN));
    CASE(SN_ERR_VALUE, "DISP_BOUND 0", tb_real(RL(SN_R_DISP_BOUND), 0.0, 16));
    CASE(SN_ERR_VALUE, "DISP_BOUND < 0", tb_real(RL(SN_R_DISP_BOUND), -2.0, 16));
    CASE(SN_OK, "DISP_BOUND 1 LSB", put_at(RL(SN_R_DISP_BOUND), 1, 16));
    CASE(SN_ERR_VALUE, "FORCE 0", tb_u32(RL(SN_R_FORCE), 0));
    CASE(SN_ERR_VALUE, "FORCE < 0", tb_real(RL(SN_R_FORCE), -1.0 / 1024, TB_FRAC_F));
    CASE(SN_ERR_VALUE, "reserved real 11", tb_u32(RL(SN_R_RESERVED11), 1));
#if defined(SN_FLOAT)
    CASE(SN_ERR_VALUE, "a1 NaN", tb_u32(RL(SN_R_A1), 0x7FC00000u));
    CASE(SN_ERR_VALUE, "grav inf", tb_u32(RL(SN_R_GRAV_X), 0x7F800000u));
    CASE(SN_ERR_VALUE, "timestep inf", tb_u32(RL(SN_R_TIMESTEP), 0x7F800000u));
    CASE(SN_ERR_VALUE, "mass scale NaN", tb_u32(RL(SN_R_MASS_SCALE), 0xFFC00000u));
    CASE(SN_ERR_VALUE, "reserved real -0.0", tb_u32(RL(SN_R_RESERVED11), 0x80000000u));
    CASE(SN_ERR_VALUE, "FORCE NaN", tb_u32(RL(SN_R_FORCE), 0x7FC00000u));
    CASE(SN_ERR_VALUE, "ENERGY NaN", tb_u32(RL(SN_R_ENERGY), 0x7FC00000u));
    CASE(SN_ERR_VALUE, "ENERGY inf", tb_u32(RL(SN_R_ENERGY), 0x7F800000u));
    CASE(SN_ERR_VALUE, "CELL NaN", tb_u32(RL(SN_R_CELL), 0x7FC00000u));
    CASE(SN_ERR_VALUE, "DISP_BOUND inf", tb_u32(RL(SN_R_DISP_BOUND), 0x7F800000u));
    CASE(SN_ERR_VALUE, "DISP_BOUND -0.0", tb_u32(RL(SN_R_DISP_BOUND), 0x80000000u));
#endif
#undef RL

    /* section table */
    nnz = tb_rd32(g_base.b + SN_H_N_OFFDIAG);
    CASE(SN_ERR_SECTION, "misaligned offset", tb_u32(TAB(SN_SEC_REST, 0), tb_sec(b, SN_SEC_REST) + 4));
    CASE(SN_ERR_SECTION, "offset inside header", tb_u32(TAB(SN_SEC_JOINTS, 0), 8));
    CASE(SN_ERR_SECTION, "overlap", tb_u32(TAB(SN_SEC_MDIAG, 0), tb_sec(b, SN_SEC_FRAMES)));
    CASE(SN_ERR_SECTION, "descending", tb_u32(TAB(SN_SEC_CELLK, 0), tb_sec(b, SN_SEC_CELLS)));
    CASE(SN_ERR_SECTION, "past the end", tb_u32(TAB(SN_SEC_TRIS, 0), g_total));
    CASE(SN_ERR_SECTION, "offset wraps", tb_u32(TAB(SN_SEC_TRIS, 0), 0xFFFFFFF8u));
    CASE(SN_ERR_SECTION, "size wraps", tb_u32(TAB(SN_SEC_TRIS, 1), 0xFFFFFFFFu));
    CASE(SN_ERR_SECTION, "count != header", tb_u32(TAB(SN_SEC_COLS, 2), nnz + 1));
    CASE(SN_ERR_SECTION, "count*elem overflow",
         tb_u32(TAB(SN_SEC_TRIS, 2), 0x80000000u); tb_u32(b + SN_H_N_TRIANGLES, 0x80000000u));
    CASE(SN_ERR_SECTION, "elem_size", tb_u32(TAB(SN_SEC_REST, 3), 16));
    CASE(SN_ERR_SECTION, "size != count*elem", tb_u32(TAB(SN_SEC_MOFF, 1), nnz * 4 - 4));
    CASE(SN_ERR_SECTION, "CELLK size != count*elem", tb_u32(TAB(SN_SEC_CELLK, 1), TB_NC * SN_ELEM_CELLK(SN_FLAVOUR, 4) - 4));
    CASE(SN_ERR_SECTION, "CELLK elem_size of a 1.0 SOFF block", tb_u32(TAB(SN_SEC_CELLK, 3), 36));
    CASE(SN_ERR_SECTION, "CFRAMES count != nC", tb_u32(TAB(SN_SEC_CFRAMES, 2), TB_NC - 1));
    CASE(SN_ERR_SECTION, "CELLK count != nC", tb_u32(TAB(SN_SEC_CELLK, 2), TB_NC + 1));
    /* LIMIT: count 0 (no limits) or nF, nothing else */
    CASE(SN_ERR_SECTION, "LIMIT count nF - 1", tb_u32(TAB(SN_SEC_LIMIT, 2), TB_NF - 1); tb_u32(TAB(SN_SEC_LIMIT, 1), 4 * (TB_NF - 1)));
    CASE(SN_ERR_SECTION, "LIMIT count nF + 1", tb_u32(TAB(SN_SEC_LIMIT, 2), TB_NF + 1); tb_u32(TAB(SN_SEC_LIMIT, 1), 4 * (TB_NF + 1)));
    CASE(SN_ERR_SECTION, "LIMIT count nV", tb_u32(TAB(SN_SEC_LIMIT, 2), TB_NV); tb_u32(TAB(SN_SEC_LIMIT, 1), 4 * TB_NV));
    CASE(SN_ERR_SECTION, "LIMIT count 0, size left", tb_u32(TAB(SN_SEC_LIMIT, 2), 0));
    CASE(SN_ERR_SECTION, "LIMIT count 0, data left as padding", tb_u32(TAB(SN_SEC_LIMIT, 2), 0); tb_u32(TAB(SN_SEC_LIMIT, 1), 0));
    CASE(SN_OK, "LIMIT empty (count 0, size 0, zero padding)", tb_drop_limit(b));
    CASE(SN_ERR_SECTION, "LIMIT elem_size 8", tb_u32(TAB(SN_SEC_LIMIT, 3), 8); tb_u32(TAB(SN_SEC_LIMIT, 2), TB_NF / 2));
    CASE(SN_ERR_SECTION, "nonzero padding", SEC(SN_SEC_ROWPTR)[4 * (TB_NF + 1)] = 1);
    {   /* trailing bytes inside total_size must be zero */
        CASE_SZ(SN_OK, "zero trailing bytes", g_total + 8, tb_u32(b + SN_H_TOTAL_SIZE, g_total + 8));
        CASE_SZ(SN_ERR_SECTION, "nonzero trailing bytes", g_total + 8,
             tb_u32(b + SN_H_TOTAL_SIZE, g_total + 8); b[g_total + 7] = 1);
    }
    /* empty triangle section: fine */
    {
        unsigned char *b = g_work.b;
        const sn_blob *blob;
        uint32_t idx[3];
        memcpy(b, g_base.b, CAP);
        tb_u32(b + SN_H_N_TRIANGLES, 0);
        tb_u32(TAB(SN_SEC_TRIS, 1), 0);
        tb_u32(TAB(SN_SEC_TRIS, 2), 0);
        memset(SEC(SN_SEC_TRIS), 0, 12);
        tb_drop_crease(b); /* crease data needs triangles */
        tb_fix_crc(b);
        expect("no triangles", sn_blob_validate(b, g_total, &blob), SN_OK);
        expect("get_triangle without triangles", sn_get_triangle(blob, 0, idx), SN_ERR_ARG);
    }
}

static void test_contents(void) {
    const uint32_t J = (uint32_t)SN_ELEM_JOINTS(4);
    uint32_t nnz = tb_rd32(g_base.b + SN_H_N_OFFDIAG), r0, r1;
    /* joints */
    CASE(SN_ERR_INDEX, "root parent 0", tb_u16(SEC(SN_SEC_JOINTS), 0));
    CASE(SN_ERR_INDEX, "self parent", tb_u16(SEC(SN_SEC_JOINTS) + J, 1));
    CASE(SN_ERR_INDEX, "second root", tb_u16(SEC(SN_SEC_JOINTS) + J, 0xFFFF));
    CASE(SN_ERR_VALUE, "joint reserved u16", tb_u16(SEC(SN_SEC_JOINTS) + J + 2, 1));
    CASE(SN_ERR_VALUE, "joint reserved u32", tb_u32(SEC(SN_SEC_JOINTS) + 4, 1));
    CASE(SN_ERR_VALUE, "joint rest > 2^27", put_over(SEC(SN_SEC_JOINTS) + J + 12, 1 << 27, SN_Q_LEN));
    CASE(SN_OK, "joint rest = -2^27", put_at(SEC(SN_SEC_JOINTS) + J + 16, -(1 << 27), SN_Q_LEN));
    /* names */
    CASE(SN_ERR_VALUE, "empty name", SEC(SN_SEC_JOINT_NAMES)[32] = 0);
    CASE(SN_ERR_VALUE, "unterminated name", memset(SEC(SN_SEC_JOINT_NAMES) + 32, 'a', 32));
    CASE(SN_OK, "31-char name", memset(SEC(SN_SEC_JOINT_NAMES) + 32, 'a', 31));
    CASE(SN_ERR_VALUE, "duplicate name", memcpy(SEC(SN_SEC_JOINT_NAMES) + 32, "root", 4));
    CASE(SN_ERR_VALUE, "garbage after NUL", SEC(SN_SEC_JOINT_NAMES)[40] = 'x');
    /* rest positions */
    CASE(SN_ERR_VALUE, "rest > 2^27", put_over(SEC(SN_SEC_REST) + 4 * 7, 1 << 27, SN_Q_LEN));
    CASE(SN_ERR_VALUE, "rest < -2^27", put_over(SEC(SN_SEC_REST) + 4 * 35, -(1 << 27), SN_Q_LEN));
    CASE(SN_OK, "rest = 2^27", put_at(SEC(SN_SEC_REST), 1 << 27, SN_Q_LEN));
    CASE(SN_OK, "len_shift 12, rest = 2^24", b[SN_H_LEN_SHIFT] = 12;
         put_at(SEC(SN_SEC_REST) + 8, 1 << 24, SN_Q_LEN));
    CASE(SN_ERR_VALUE, "len_shift 12, rest > 2^24 (16384 mesh units)", b[SN_H_LEN_SHIFT] = 12;
         put_over(SEC(SN_SEC_REST) + 8, 1 << 24, SN_Q_LEN));
    CASE(SN_ERR_VALUE, "len_shift 12, joint rest > 2^24", b[SN_H_LEN_SHIFT] = 12;
         put_over(SEC(SN_SEC_JOINTS) + J + 8, 1 << 24, SN_Q_LEN));
    /* frames */
    CASE(SN_ERR_INDEX, "bone1 >= nJ", SEC(SN_SEC_FRAMES)[0] = TB_NJ);
    CASE(SN_ERR_INDEX, "bone2 >= nJ", SEC(SN_SEC_FRAMES)[4 * 3 + 1] = 255);
    CASE(SN_ERR_VALUE, "w > 1", tb_u16(SEC(SN_SEC_FRAMES) + 4 * 2 + 2, 32769));
    CASE(SN_OK, "w = 1", tb_u16(SEC(SN_SEC_FRAMES) + 4 * 2 + 2, 32768); tb_fix_frefs(b)); /* format 6.4: its references follow */
    CASE(SN_ERR_INDEX, "skeleton bone1 != bone2", SEC(SN_SEC_FRAMES)[4 * TB_NF + 1] = 1);
    CASE(SN_ERR_VALUE, "skeleton w != 0", tb_u16(SEC(SN_SEC_FRAMES) + 4 * (TB_NV - 1) + 2, 1));
    /* matrices */
    CASE(SN_ERR_VALUE, "MDIAG > 2^27", put_over(SEC(SN_SEC_MDIAG), 1 << 27, 0));
    CASE(SN_OK, "MDIAG = 2^27", put_at(SEC(SN_SEC_MDIAG), 1 << 27, 0));

    CASE(SN_ERR_VALUE, "PRECOND > 2^27", put_over(SEC(SN_SEC_PRECOND) + 4 * 5, 1 << 27, 0));
    CASE(SN_ERR_VALUE, "MLUMP > 2^27", put_over(SEC(SN_SEC_MLUMP) + 4 * 7, 1 << 27, 0));
    CASE(SN_ERR_VALUE, "MOFF < -2^27", put_over(SEC(SN_SEC_MOFF) + 4 * (nnz - 1), -(1 << 27), 0));
    /* cell stiffness: |e| <= 2^27 everywhere in CELLK, float finite */
#if defined(SN_FLOAT)
    CASE(SN_ERR_VALUE, "CELLK first entry > 2^27", put_over(SEC(SN_SEC_CELLK), 1 << 27, 0));
    CASE(SN_ERR_VALUE, "CELLK last entry < -2^27", put_over(SEC(SN_SEC_CELLK) + 4 * (TB_NC * 324 - 1), -(1 << 27), 0));
    CASE(SN_ERR_VALUE, "CELLK cell 1 block (3,5) > 2^27", put_over(SEC(SN_SEC_CELLK) + 4 * (324 + 9 * 23 + 4), 1 << 27, 0)); /* blocks of row 3 start at 21 */
    CASE(SN_OK, "CELLK entries = +-2^27", put_at(SEC(SN_SEC_CELLK), 1 << 27, 0);
         put_at(SEC(SN_SEC_CELLK) + 4 * (TB_NC * 324 - 1), -(1 << 27), 0));
#else
    /* format 6.0: diagonal int32 |d| <= 2^27; off-diagonal int16 m != -2^15, exponent <= 12 */
#define CK(c) (SEC(SN_SEC_CELLK) + SN_CELLK_FIXED_BYTES * (c))
    CASE(SN_ERR_VALUE, "CELLK first diagonal entry > 2^27", put_over(CK(0) + SN_CELLK_DIAG, 1 << 27, 0));
    CASE(SN_ERR_VALUE, "CELLK last diagonal entry < -2^27", put_over(CK(TB_NC - 1) + SN_CELLK_DIAG + 4 * 47, -(1 << 27), 0));
    CASE(SN_OK, "CELLK diagonal entries = +-2^27", put_at(CK(0) + SN_CELLK_DIAG, 1 << 27, 0);
         put_at(CK(TB_NC - 1) + SN_CELLK_DIAG + 4 * 47, -(1 << 27), 0));
    CASE(SN_ERR_VALUE, "CELLK mantissa -2^15", tb_u16(CK(0) + SN_CELLK_OFF, 0x8000u));
    CASE(SN_ERR_VALUE, "CELLK cell 1 block (3,5) last mantissa -2^15", tb_u16(CK(1) + SN_CELLK_OFF + 18 * SN_CELLK_OFFIDX(3, 5) + 16, 0x8000u));
    CASE(SN_OK, "CELLK mantissas +-(2^15 - 1), exponent 12", tb_u16(CK(0) + SN_CELLK_OFF, 0x7FFFu);
         tb_u16(CK(TB_NC - 1) + SN_CELLK_OFF + 2 * (28 * 9 - 1), 0x8001u); CK(0)[SN_CELLK_EXP] = 12; CK(TB_NC - 1)[SN_CELLK_EXP + 27] = 12);
    CASE(SN_ERR_VALUE, "CELLK exponent 13", CK(0)[SN_CELLK_EXP] = 13);
    CASE(SN_ERR_VALUE, "CELLK last exponent 255", CK(TB_NC - 1)[SN_CELLK_EXP + 27] = 255);
#undef CK
#endif
    /* cell frames: bones < nJ, w <= 32768 */
    CASE(SN_ERR_INDEX, "CFRAMES bone1 >= nJ", SEC(SN_SEC_CFRAMES)[0] = TB_NJ);
    CASE(SN_ERR_INDEX, "CFRAMES bone2 >= nJ", SEC(SN_SEC_CFRAMES)[4 * (TB_NC - 1) + 1] = 255);
    CASE(SN_ERR_VALUE, "CFRAMES w > 32768", tb_u16(SEC(SN_SEC_CFRAMES) + 4 * (TB_NC - 1) + 2, 32769));
    CASE(SN_ERR_VALUE, "CFRAMES w 0xFFFF", tb_u16(SEC(SN_SEC_CFRAMES) + 2, 0xFFFF));
    CASE(SN_OK, "CFRAMES w = 32768", tb_u16(SEC(SN_SEC_CFRAMES) + 2, 32768));
    CASE(SN_OK, "CFRAMES bone1 = bone2", SEC(SN_SEC_CFRAMES)[1] = 0; tb_fix_frefs(b));
    /* frame references (format 6.4, sn_pose.c sn_check_frefs): every field against what it stands for */
    {
        const uint32_t none = TB_NF + TB_NC;
        uint32_t ia = none, ip = none, ib = none, i, r; /* the blob's slerping entries are free vertices and cells (w = 0 only at skeleton vertices) */
        for (i = TB_NF + TB_NC; i-- > 0;) { /* the last alias, pair and bone entries of the base blob */
            r = tb_rd32(g_base.b + tb_sec(g_base.b, SN_SEC_FREFS) + 4 * i);
            if (r == SN_FREF_BONE) ib = ib < none ? ib : i;
            else if (r & SN_FREF_PAIR) ip = ip < none ? ip : i;
            else ia = ia < none ? ia : i;
        }
        T_CHECK(ia < TB_NF && ip < none && ib == none, "test blob: an alias (%u, a free vertex), a pair (%u), no bone entry (%u)", ia, ip, ib);
#define FREF(i) (SEC(SN_SEC_FREFS) + 4 * (i))
        CASE(SN_ERR_INDEX, "FREFS alias = its own index", tb_u32(FREF(ia), ia));
        CASE(SN_ERR_INDEX, "FREFS alias after its own index", tb_u32(FREF(ia), TB_NF + TB_NC - 1 > ia ? TB_NF + TB_NC - 1 : ia + 1));
        CASE(SN_ERR_VALUE, "FREFS alias to an entry of other bytes", tb_u32(FREF(ip), ib < ip ? ib : 0));
        CASE(SN_ERR_INDEX, "FREFS pair index = nFP", tb_u32(FREF(ip), SN_FREF_PAIR | TB_NFP));
        CASE(SN_ERR_INDEX, "FREFS slerping entry marked bone", tb_u32(FREF(ip), SN_FREF_BONE));
        /* entry ia made a bone entry (w = 0): no slerp, so SN_FREF_BONE only */
        CASE(SN_ERR_VALUE, "FREFS bone entry given a pair", tb_u16(SEC(SN_SEC_FRAMES) + 4 * ia + 2, 0); tb_u32(FREF(ia), SN_FREF_PAIR));
        CASE(SN_ERR_VALUE, "FREFS bone entry given an alias", tb_u16(SEC(SN_SEC_FRAMES) + 4 * ia + 2, 0));
        CASE(SN_OK, "FREFS bone entry marked bone", tb_u16(SEC(SN_SEC_FRAMES) + 4 * ia + 2, 0); tb_u32(FREF(ia), SN_FREF_BONE));
        CASE(SN_OK, "FREFS alias computed instead (its own pair)", tb_u32(FREF(ia), SN_FREF_PAIR));
        CASE(SN_ERR_VALUE, "FPAIRS (1, 0): not the entries' bones", SEC(SN_SEC_FPAIRS)[0] = 1; SEC(SN_SEC_FPAIRS)[1] = 0);
        CASE(SN_ERR_INDEX, "FPAIRS bone1 = bone2", SEC(SN_SEC_FPAIRS)[1] = 0);
        CASE(SN_ERR_INDEX, "FPAIRS bone2 >= nJ", SEC(SN_SEC_FPAIRS)[1] = TB_NJ);
        CASE(SN_ERR_SECTION, "FREFS count nF + nC - 1", tb_u32(TAB(SN_SEC_FREFS, 2), TB_NF + TB_NC - 1);
             tb_u32(TAB(SN_SEC_FREFS, 1), 4 * (TB_NF + TB_NC - 1)));
        CASE(SN_ERR_SECTION, "FPAIRS count nJ (nJ - 1) + 1", tb_u32(TAB(SN_SEC_FPAIRS, 2), TB_NJ * (TB_NJ - 1) + 1);
             tb_u32(TAB(SN_SEC_FPAIRS, 1), 2 * (TB_NJ * (TB_NJ - 1) + 1)));
        CASE(SN_ERR_SECTION, "FPAIRS without FREFS", memset(FREF(0), 0, 4 * (TB_NF + TB_NC));
             tb_u32(TAB(SN_SEC_FREFS, 2), 0); tb_u32(TAB(SN_SEC_FREFS, 1), 0));
        CASE(SN_OK, "neither FPAIRS nor FREFS (every frame slerped alone)", memset(FREF(0), 0, 4 * (TB_NF + TB_NC));
             memset(SEC(SN_SEC_FPAIRS), 0, 2); tb_u32(TAB(SN_SEC_FREFS, 2), 0); tb_u32(TAB(SN_SEC_FREFS, 1), 0);
             tb_u32(TAB(SN_SEC_FPAIRS, 2), 0); tb_u32(TAB(SN_SEC_FPAIRS, 1), 0);
             tb_u32(b + SN_H_INSTANCE_BYTES, tb_rd32(b + SN_H_INSTANCE_BYTES) - TB_FPB));
        CASE(SN_ERR_HEADER, "instance bytes without the frame pairs' scratch",
             tb_u32(b + SN_H_INSTANCE_BYTES, tb_rd32(b + SN_H_INSTANCE_BYTES) - TB_FPB));
#undef FREF
    }
    /* limits: 0 <= L <= 2^28 (64 internal units) */
    CASE(SN_ERR_VALUE, "LIMIT < 0", tb_real(SEC(SN_SEC_LIMIT) + 4 * 3, -0.25, SN_Q_LEN));
    CASE(SN_ERR_VALUE, "LIMIT most negative", tb_u32(SEC(SN_SEC_LIMIT) + 4 * (TB_NF - 1), SN_FLOAT_OR(0xFF7FFFFFu, 0x80000000u)));
    CASE(SN_ERR_VALUE, "LIMIT > 2^28", put_over(SEC(SN_SEC_LIMIT), 1 << 28, SN_Q_LEN));
    CASE(SN_OK, "LIMIT = 2^28", put_at(SEC(SN_SEC_LIMIT), 1 << 28, SN_Q_LEN));
    CASE(SN_OK, "LIMIT 0 everywhere", memset(SEC(SN_SEC_LIMIT), 0, 4 * TB_NF));
#if defined(SN_FLOAT)
    CASE(SN_ERR_VALUE, "CELLK NaN", tb_u32(SEC(SN_SEC_CELLK) + 4 * 3, 0x7FC00001u));
    CASE(SN_ERR_VALUE, "CELLK -inf", tb_u32(SEC(SN_SEC_CELLK) + 4 * 100, 0xFF800000u));
    CASE(SN_ERR_VALUE, "LIMIT NaN", tb_u32(SEC(SN_SEC_LIMIT) + 4, 0x7FC00000u));
    CASE(SN_ERR_VALUE, "LIMIT inf", tb_u32(SEC(SN_SEC_LIMIT) + 4, 0x7F800000u));
    CASE(SN_ERR_VALUE, "rest -inf", tb_u32(SEC(SN_SEC_REST) + 4 * 3, 0xFF800000u));
#endif
    /* sparsity */
    r0 = tb_rd32(g_base.b + tb_sec(g_base.b, SN_SEC_ROWPTR) + 4);
    r1 = tb_rd32(g_base.b + tb_sec(g_base.b, SN_SEC_ROWPTR) + 8);
    CASE(SN_ERR_INDEX, "rowptr[0] != 0", tb_u32(SEC(SN_SEC_ROWPTR), 1));
    CASE(SN_ERR_INDEX, "rowptr[nF] != nnz", tb_u32(SEC(SN_SEC_ROWPTR) + 4 * TB_NF, nnz - 1));
    CASE(SN_ERR_INDEX, "rowptr decreasing", tb_u32(SEC(SN_SEC_ROWPTR) + 4, r1 + 1));
    CASE(SN_ERR_INDEX, "rowptr > nnz", tb_u32(SEC(SN_SEC_ROWPTR) + 4, nnz + 100));
    CASE(SN_ERR_INDEX, "row with more than SN_MAX_ROW_BLOCKS blocks",
         tb_u32(SEC(SN_SEC_ROWPTR) + 4, SN_MAX_ROW_BLOCKS + 1); tb_u32(SEC(SN_SEC_ROWPTR) + 8, SN_MAX_ROW_BLOCKS + 1));
    CASE(SN_ERR_INDEX, "cols not increasing", tb_u16(SEC(SN_SEC_COLS) + 2, tb_rd32(SEC(SN_SEC_COLS)) & 0xFFFF));
    CASE(SN_ERR_INDEX, "col == row", tb_u16(SEC(SN_SEC_COLS) + 2 * r0, 1)); /* row 1's first column */
    CASE(SN_ERR_INDEX, "col < row", tb_u16(SEC(SN_SEC_COLS) + 2 * r0, 0));
    CASE(SN_ERR_INDEX, "col >= nV", tb_u16(SEC(SN_SEC_COLS) + 2 * (nnz - 1), TB_NV));
    CASE(SN_ERR_INDEX, "col 0xFFFF", tb_u16(SEC(SN_SEC_COLS) + 2 * (r0 - 1), 0xFFFF));
    /* cells, embedding, triangles */
    CASE(SN_ERR_INDEX, "cell corner >= nV", tb_u16(SEC(SN_SEC_CELLS) + 2 * 13, TB_NV));
    CASE(SN_ERR_INDEX, "cell corner 0xFFFF", tb_u16(SEC(SN_SEC_CELLS) + 2 * 8, 0xFFFF));
    CASE(SN_ERR_INDEX, "repeated corner in a cell (7 = 0)", tb_u16(SEC(SN_SEC_CELLS) + 2 * 7, tb_rd32(SEC(SN_SEC_CELLS)) & 0xFFFF));
    CASE(SN_ERR_INDEX, "repeated corner in a cell (5 = 4)", tb_u16(SEC(SN_SEC_CELLS) + 16 + 2 * 5, tb_rd32(SEC(SN_SEC_CELLS) + 16 + 8) & 0xFFFF));
    CASE(SN_ERR_INDEX, "embed cell >= nC", tb_u16(SEC(SN_SEC_EMBED) + 8 * 3, TB_NC));
    CASE(SN_ERR_VALUE, "embed t > 1", tb_u16(SEC(SN_SEC_EMBED) + 8 * 1 + 6, 32769));
    CASE(SN_ERR_INDEX, "triangle index >= nS", tb_u16(SEC(SN_SEC_TRIS) + 2 * 5, TB_NS));
}

/* Rig sections (format 3.0): every rule of sn_check_rigs broken once. */
#define CTL(i) (SEC(SN_SEC_CONTROLS) + SN_ELEM_CONTROLS(4) * (i))
#define RIG(i) (SEC(SN_SEC_RIGS) + SN_ELEM_RIGS * (i))
#define SMP(i) (SEC(SN_SEC_RIG_SAMPLES) + 8 * (i))
static void test_rig_contents(void) {
    CASE(SN_ERR_VALUE, "control name empty", CTL(0)[0] = 0);
    CASE(SN_ERR_VALUE, "control name not NUL-terminated", memset(CTL(1), 'a', 32));
    CASE(SN_ERR_VALUE, "control names equal", memcpy(CTL(1), "puff", 4));
    CASE(SN_OK, "control named like a joint", memcpy(CTL(1), "tip\0", 4));
    CASE(SN_ERR_VALUE, "control kind 2", CTL(0)[32] = 2);
    CASE(SN_ERR_VALUE, "control reserved u16", CTL(1)[34] = 1);
    CASE(SN_ERR_VALUE, "control reserved u32", CTL(0)[39] = 1);
    CASE(SN_ERR_INDEX, "abstract control with a joint", CTL(0)[33] = 1);
    CASE(SN_ERR_VALUE, "abstract control with an axis", tb_real(CTL(0) + 40, 1.0, SN_Q_ROT));
    CASE(SN_ERR_VALUE, "abstract value0 beyond 16384", put_over(CTL(0) + 52, 1 << 30, 16));
    CASE(SN_OK, "abstract value0 = -16384", put_at(CTL(0) + 52, -(1 << 30), 16));
    CASE(SN_ERR_INDEX, "angle control joint >= nJ", CTL(1)[33] = TB_NJ);
    CASE(SN_ERR_VALUE, "angle control with value0", tb_real(CTL(1) + 52, 1.0, 16));
    CASE(SN_ERR_VALUE, "angle axis zero", tb_real(CTL(1) + 48, 0.0, SN_Q_ROT));
    CASE(SN_ERR_VALUE, "angle axis 2% short", tb_real(CTL(1) + 48, 0.98, SN_Q_ROT));
    CASE(SN_OK, "angle axis 0.1% short (within 2^-8 in |a|^2)", tb_real(CTL(1) + 48, 0.999, SN_Q_ROT));
    CASE(SN_ERR_VALUE, "angle axis component beyond 1", put_over(CTL(1) + 48, 1 << 30, SN_Q_ROT));
    CASE(SN_ERR_INDEX, "rig control >= nK", tb_u16(RIG(1), TB_NK));
    CASE(SN_ERR_VALUE, "rig with 0 samples", RIG(2)[2] = 0);
    CASE(SN_ERR_VALUE, "rig with 17 samples", RIG(2)[2] = 17);
#if defined(SN_FLOAT)
    CASE(SN_ERR_VALUE, "float rig frac != 0", RIG(0)[3] = 36);
    CASE(SN_ERR_VALUE, "float rig force beyond SN_RIG_FLOAT_MAX",
         tb_real(SEC(SN_SEC_RIG_FORCES) + 4, 2.0 * SN_RIG_FLOAT_MAX, 0));
    CASE(SN_ERR_VALUE, "float rig force NaN", tb_u32(SEC(SN_SEC_RIG_FORCES), 0x7FC00000u));
    CASE(SN_ERR_VALUE, "gamma inf", tb_u32(SMP(0), 0xFF800000u));
    CASE(SN_ERR_VALUE, "eta NaN", tb_u32(SMP(1) + 4, 0x7FC00000u));
#else
    CASE(SN_ERR_VALUE, "rig frac 4", RIG(0)[3] = SN_RIG_FRAC_MIN - 1);
    CASE(SN_ERR_VALUE, "rig frac 51", RIG(0)[3] = SN_RIG_FRAC_MAX + 1);
    CASE(SN_ERR_VALUE, "rig frac -1", RIG(0)[3] = 0xFF);
    CASE(SN_OK, "rig frac 5 with force INT32_MIN", RIG(0)[3] = SN_RIG_FRAC_MIN; tb_u32(SEC(SN_SEC_RIG_FORCES), 0x80000000u));
    CASE(SN_OK, "rig frac 50", RIG(0)[3] = SN_RIG_FRAC_MAX);
#endif
    CASE(SN_ERR_INDEX, "first_sample not the running sum", tb_u32(RIG(1) + 4, 2));
    CASE(SN_ERR_INDEX, "first_entry not the running sum", tb_u32(RIG(2) + 8, 5));
    CASE(SN_ERR_INDEX, "entries past the section", tb_u32(RIG(2) + 12, 2));
    CASE(SN_ERR_INDEX, "samples past the section", RIG(2)[2] = 2);
    CASE(SN_ERR_INDEX, "entries short of the section", tb_u32(RIG(2) + 12, 0));
    CASE(SN_ERR_VALUE, "gamma equal to the previous", tb_real(SMP(1), -1.0, 16));
    CASE(SN_ERR_VALUE, "gamma decreasing", tb_real(SMP(4), -10.0, 16));
    CASE(SN_OK, "gamma 1 LSB apart", put_at(SMP(1), -65535, 16));
    CASE(SN_ERR_VALUE, "gamma beyond 16384", put_over(SMP(2), 1 << 30, 16));
    CASE(SN_ERR_VALUE, "eta beyond 1", put_over(SMP(2) + 4, 1 << 30, SN_Q_ROT));
    CASE(SN_OK, "eta = -1", put_at(SMP(2) + 4, -(1 << 30), SN_Q_ROT));
    CASE(SN_ERR_INDEX, "rig vertex >= nF (a skeleton vertex)", tb_u16(SEC(SN_SEC_RIG_VERTS) + 2 * 5, TB_NF));
    CASE(SN_ERR_INDEX, "rig vertices not increasing", tb_u16(SEC(SN_SEC_RIG_VERTS) + 2 * 1, 1));
    CASE(SN_OK, "rig vertex repeated across rigs", tb_u16(SEC(SN_SEC_RIG_VERTS) + 2 * 6, 1));
    CASE(SN_ERR_SECTION, "RIG_FORCES count != RIG_VERTS count",
         tb_u32(TAB(SN_SEC_RIG_FORCES, 2), TB_NRE - 1); tb_u32(TAB(SN_SEC_RIG_FORCES, 1), 12 * (TB_NRE - 1)));
    CASE(SN_ERR_SECTION, "CONTROLS count beyond SN_MAX_CONTROLS", tb_u32(TAB(SN_SEC_CONTROLS, 2), SN_MAX_CONTROLS + 1));
    CASE(SN_ERR_SECTION, "RIGS elem_size", tb_u32(TAB(SN_SEC_RIGS, 3), 12));
}
#undef CTL
#undef RIG
#undef SMP

static void test_accessors(int len_shift) {
    unsigned char *b = g_work.b;
    const sn_blob *blob = NULL;
    sn_blob_info info;
    sn_vec3 r;
    uint32_t idx[3];
    tb_build(b, CAP, len_shift);
    expect("build with len_shift", sn_blob_validate(b, CAP, &blob), SN_OK);
    if (!blob) return;
    sn_blob_get_info(blob, &info);
    T_CHECK(info.vertices == TB_NV && info.free_vertices == TB_NF && info.cells == TB_NC &&
                info.joints == TB_NJ && info.surface_vertices == TB_NS && info.triangles == TB_NT,
            "info counts");
    T_CHECK(info.offdiag_blocks == tb_rd32(b + SN_H_N_OFFDIAG) && info.offdiag_blocks > 0, "info nnz");
    T_CHECK(info.cg_iters_default == 8 && info.cg_iters_max == 32, "info cg");
    T_CHECK(info.instance_bytes == SN_INSTANCE_BYTES(TB_NV, TB_NF, TB_NJ, TB_NC, TB_NK, TB_NFRC, TB_SEGB + TB_CRB + TB_FPB, TB_CONB), "info instance bytes");
    T_CHECK(sn_instance_size(blob) == info.instance_bytes, "sn_instance_size");
    T_CHECK(info.blob_bytes == tb_rd32(b + SN_H_TOTAL_SIZE), "info blob bytes");
#if defined(SN_FLOAT)
    T_NEAR(info.timestep, 1.0 / 60, 1e-9, "float stored value");
#else
    T_CHECK(info.timestep == 1092, "timestep Q16.16 = round(65536/60), got %d", (int)info.timestep);
#endif
    T_CHECK(sn_joint_name(blob, 0) && strcmp(sn_joint_name(blob, 0), "root") == 0, "name 0");
    T_CHECK(sn_joint_name(blob, 1) && strcmp(sn_joint_name(blob, 1), "tip") == 0, "name 1");
    T_CHECK(sn_joint_name(blob, 2) == NULL && sn_joint_name(NULL, 0) == NULL, "name out of range");
    T_CHECK(sn_joint_parent(blob, 0) == -1 && sn_joint_parent(blob, 1) == 0 &&
                sn_joint_parent(blob, 2) == -1 && sn_joint_parent(NULL, 1) == -1, "parents");
    T_CHECK(sn_find_joint(blob, "root") == 0 && sn_find_joint(blob, "tip") == 1, "find");
    T_CHECK(sn_find_joint(blob, "ro") == -1 && sn_find_joint(blob, "rootx") == -1 &&
                sn_find_joint(blob, "") == -1 && sn_find_joint(blob, NULL) == -1 &&
                sn_find_joint(NULL, "root") == -1 && sn_find_joint(blob, "Root") == -1,
            "find misses");
    T_CHECK(sn_joint_rest(blob, 1, &r) == SN_OK, "rest ok");
    /* tip at 0.5 internal units = 0.5 * 2^len_shift mesh units (exact here) */
#if defined(SN_FLOAT)
    T_NEAR(r.x, ldexp(0.5, len_shift), 0, "power-of-two scaling is exact in float");
#else
    T_CHECK(r.x == (int32_t)ldexp(0.5 * 65536, len_shift), "rest x = %d (len_shift %d)", (int)r.x, len_shift);
#endif
    T_CHECK(r.y == 0 && r.z == 0, "rest y z");
    expect("rest j out of range", sn_joint_rest(blob, 2, &r), SN_ERR_ARG);
    expect("rest NULL out", sn_joint_rest(blob, 0, NULL), SN_ERR_NULL);
    expect("triangle 1", sn_get_triangle(blob, 1, idx), SN_OK);
    T_CHECK(idx[0] == 0 && idx[1] == 2 && idx[2] == 3, "triangle 1 indices");
    expect("triangle 2", sn_get_triangle(blob, 2, idx), SN_ERR_ARG);
    expect("triangle NULL", sn_get_triangle(blob, 0, NULL), SN_ERR_NULL);
    {
        sn_view v;
        int k;
        sn_view_init(&v, blob);
        T_CHECK(v.nV == TB_NV && v.nF == TB_NF && v.nC == TB_NC && v.nL == TB_NF && v.len_shift == len_shift &&
                    v.frac_S == TB_FRAC && v.flags == SN_FLAG_REST_MODELLED && v.total == info.blob_bytes, "view header");
#if defined(SN_FLOAT)
        T_NEAR(v.cell, 0.5, 0, "view CELL");
        T_NEAR(v.disp_bound, 2.0, 0, "view DISP_BOUND");
#else
        T_CHECK(v.frac_E == TB_FRAC_E && v.cell == (1 << 21) && v.disp_bound == (2 << 16), "view health scalars");
#endif
        for (k = 0; k < SN_SEC_COUNT; k++) /* the view keeps the sections before the cut level's; sn_sec reads any */
            T_CHECK((k < SN_SEC_VIEWED ? v.sec[k] : sn_sec(&v, k)) == b + tb_sec(b, k), "view section %d", k);
    }
    T_CHECK(info.controls == TB_NK && info.rigs == TB_NR && info.rig_entries == TB_NRE, "info rig counts");
    T_CHECK(sn_find_control(blob, "puff") == 0 && sn_find_control(blob, "bend") == 1 &&
                sn_find_control(blob, "pu") == -1 && sn_find_control(blob, "tip") == -1 &&
                sn_find_control(blob, NULL) == -1 && sn_find_control(NULL, "puff") == -1, "find_control");
    T_CHECK(sn_control_name(blob, 1) && strcmp(sn_control_name(blob, 1), "bend") == 0 &&
                sn_control_name(blob, 2) == NULL && sn_control_name(NULL, 0) == NULL, "control names");
    T_CHECK(sn_control_kind_of(blob, 0) == SN_CONTROL_ABSTRACT && sn_control_kind_of(blob, 1) == SN_CONTROL_ANGLE &&
                sn_control_kind_of(blob, 2) == -1, "control kinds");
    sn_blob_get_info(NULL, &info);
    T_CHECK(info.vertices == 0 && info.blob_bytes == 0, "info of NULL blob is zero");
}

/* Fixed: public rest = internal * 2^(len_shift - 6), rounded to nearest
 * (ties toward +infinity, sn_rshr64) when len_shift < 6, exact otherwise. */
static void test_rest_rounding(void) {
#if !defined(SN_FLOAT)
    static const struct { int ls; int32_t raw; int32_t want; } c[] = {
        {0, (1 << 21) + 3, 32768},    /* +0.047 LSB -> down */
        {0, (1 << 21) + 32, 32769},   /* +0.5 LSB   -> up */
        {0, -(1 << 21) - 32, -32768}, /* -0.5 LSB   -> up (toward +infinity) */
        {0, -(1 << 21) - 33, -32769},
        {0, (1 << 21) + 33, 32769},
        {-3, 1000, 2},                /* 1000 / 512 = 1.95 */
        {6, (1 << 21) + 3, (1 << 21) + 3},
        {8, (1 << 21) + 3, 4 * ((1 << 21) + 3)},
        {-24, (1 << 27), 0},          /* 2^27 / 2^30 = 0.125 -> 0 */
    };
    size_t i;
    for (i = 0; i < sizeof c / sizeof c[0]; i++) {
        unsigned char *b = g_work.b;
        const sn_blob *blob;
        sn_vec3 r;
        tb_build(b, CAP, c[i].ls);
        tb_u32(b + tb_sec(b, SN_SEC_JOINTS) + SN_ELEM_JOINTS(4) + 8, (uint32_t)c[i].raw);
        tb_fix_crc(b);
        if (sn_blob_validate(b, CAP, &blob) != SN_OK) {
            T_CHECK(0, "rounding case %d rejected", (int)i);
            continue;
        }
        sn_joint_rest(blob, 1, &r);
        T_CHECK(r.x == c[i].want, "len_shift %d raw %d: got %d want %d", c[i].ls, (int)c[i].raw,
                (int)r.x, (int)c[i].want);
    }
#endif
}

/* The test blob is also a working asset: a few steps stay finite and unsaturated. */
static void test_steps(void) {
    static union { uint64_t a; unsigned char m[8192]; } mem;
    const sn_blob *blob;
    sn_instance *inst;
    sn_xform x[TB_NJ];
    sn_vec3 surf[TB_NS], nrm[TB_NS];
    sn_stats st;
    int j, s;
    if (sn_blob_validate(g_base.b, g_total, &blob) != SN_OK) return;
    T_CHECK(sn_instance_size(blob) <= sizeof mem.m, "instance fits");
    expect("init", sn_instance_init(mem.m, sizeof mem.m, blob, &inst), SN_OK);
    for (j = 0; j < TB_NJ; j++) {
        sn_vec3 ax = {0, 0, 0};
        ax.z = SN_FLOAT_OR(1.0f, 65536);
        x[j].rot = sn_quat_axis_angle(ax, SN_FLOAT_OR(10.0f, 10 << 16));
        x[j].pos.x = x[j].pos.y = x[j].pos.z = 0;
    }
    expect("set pose", sn_set_pose(inst, x, TB_NJ), SN_OK);
    for (s = 0; s < 10; s++) sn_step(inst);
    expect("surface", sn_get_surface(inst, surf, 0, TB_NS), SN_OK);
    expect("normals", sn_get_normals(inst, surf, nrm), SN_OK);
    sn_get_stats(inst, &st);
    T_CHECK(st.steps == 10 && st.saturations == 0, "steps %u saturations %u (float: 0; a fixed-only blow-up points at the fixed CG scalars)", st.steps, st.saturations);
    for (s = 0; s < TB_NS; s++)
        T_CHECK(surf[s].x == surf[s].x && surf[s].y == surf[s].y, "surface finite");
    T_CHECK(st.bound_steps == 0 && st.limit_steps <= st.steps && st.energy >= 0 && st.disp >= 0 &&
                st.disp_max >= st.disp && st.energy_max >= st.energy, "health stats consistent");
    /* every free vertex limited to 1 LSB (fixed) / 1e-6 units (float): gravity pulls all 8 past it */
    {
        static union { uint64_t a; unsigned char b[CAP]; } lb;
        static union { uint64_t a; unsigned char m[8192]; } mem2;
        uint32_t i;
        tb_build(lb.b, CAP, 0);
        for (i = 0; i < TB_NF; i++) tb_real(lb.b + tb_sec(lb.b, SN_SEC_LIMIT) + 4 * i, 1e-6, SN_Q_LEN);
        lb.b[SN_H_FLAGS] = 0;   /* gravity acts at the rest pose */
        tb_fix_crc(lb.b);
        if (sn_blob_validate(lb.b, CAP, &blob) != SN_OK) { T_CHECK(0, "tiny-limit blob rejected"); return; }
        expect("init (limits)", sn_instance_init(mem2.m, sizeof mem2.m, blob, &inst), SN_OK);
        for (s = 0; s < 5; s++) sn_step(inst);
        sn_get_stats(inst, &st);
        T_CHECK(st.limit_clamps == TB_NF && st.limit_steps >= 4, "tiny limits: %u clamps in the last step, %u steps", st.limit_clamps, st.limit_steps);
        /* float: p and s ~0.5 units carry ~1 ulp (6e-8) each, so |p - s| is good to
         * ~1.2e-7 units = 2.4e-7 cells beyond L / CELL; fixed: 1 LSB of Q16.16 */
        T_CHECK(st.disp <= SN_FLOAT_OR(1e-6f / 0.5f + 2.4e-7f, 1), "disp after the limit stage within L / CELL: %g", (double)st.disp);
    }
}

/* ICHOL (format 6.0, sn_tblob.h tb_add_ichol): the validator's bounds
 * (NUMERICS.md "Preconditioner"): count 0 or the free-free mass entries,
 * mantissas != -2^15, frac <= SN_ICHOL_FRAC_MAX, pad byte 0; an accepted
 * blob steps without saturations. */
#define ICASE(want, what, code) do { \
    unsigned char *b = iw.b; \
    memcpy(b, ib.b, CAP); \
    { code; } \
    tb_fix_crc(b); \
    expect(what, run(b, itot), want); \
} while (0)
static void test_ichol(void) {
    static union { uint64_t a; unsigned char b[CAP]; } ib, iw;
    static union { uint64_t a; unsigned char m[8192]; } mem;
    uint32_t itot, n, k, nnz;
    const sn_blob *blob;
    sn_instance *inst;
    sn_stats st;
    int s;
    tb_build(ib.b, CAP, 0);
    itot = tb_add_ichol(ib.b, CAP, 14);
    n = tb_rd32(ib.b + SN_H_SECTIONS + 16 * SN_SEC_ICHOL + 8);
    nnz = tb_rd32(ib.b + SN_H_N_OFFDIAG);
    T_CHECK(itot > 0 && n > 0 && n < nnz, "test blob with ICHOL: %u blocks of %u mass entries", n, nnz);
    ICASE(SN_OK, "ICHOL valid", (void)b);
    ICASE(SN_OK, "ICHOL mantissas +-(2^15-1), frac 0 and 47", for (k = 0; k < 9 * n; k++) tb_u16(SEC(SN_SEC_ICHOL) + 20 * (k / 9) + 2 * (k % 9), (k & 1) ? 0x7FFFu : 0x8001u);
          SEC(SN_SEC_ICHOL)[18] = 0; SEC(SN_SEC_ICHOL)[20 * (n - 1) + 18] = SN_ICHOL_FRAC_MAX);
    ICASE(SN_ERR_VALUE, "ICHOL mantissa -2^15", tb_u16(SEC(SN_SEC_ICHOL) + 20 * (n - 1) + 16, 0x8000u));
    ICASE(SN_ERR_VALUE, "ICHOL frac 48", SEC(SN_SEC_ICHOL)[20 * (n / 2) + 18] = SN_ICHOL_FRAC_MAX + 1);
    ICASE(SN_ERR_VALUE, "ICHOL frac 255", SEC(SN_SEC_ICHOL)[18] = 255);
    ICASE(SN_ERR_VALUE, "ICHOL pad byte", SEC(SN_SEC_ICHOL)[20 * (n - 1) + 19] = 1);
    ICASE(SN_ERR_SECTION, "ICHOL one block short", tb_u32(TAB(SN_SEC_ICHOL, 2), n - 1); tb_u32(TAB(SN_SEC_ICHOL, 1), 20 * (n - 1));
          memset(SEC(SN_SEC_ICHOL) + 20 * (n - 1), 0, 20));
    ICASE(SN_ERR_SECTION, "ICHOL count nnz + 1", tb_u32(TAB(SN_SEC_ICHOL, 2), nnz + 1); tb_u32(TAB(SN_SEC_ICHOL, 1), 20 * (nnz + 1)));
    ICASE(SN_ERR_SECTION, "ICHOL element 36 bytes", tb_u32(TAB(SN_SEC_ICHOL, 3), 36); tb_u32(TAB(SN_SEC_ICHOL, 1), 36 * n));
    if (sn_blob_validate(ib.b, itot, &blob) != SN_OK) return;
    expect("init (ICHOL)", sn_instance_init(mem.m, sizeof mem.m, blob, &inst), SN_OK);
    for (s = 0; s < 10; s++) sn_step(inst);
    sn_get_stats(inst, &st);
    T_CHECK(st.steps == 10 && st.saturations == 0, "ICHOL test blob: %u steps, %u saturations", st.steps, st.saturations);
}

/* The writers' macro equals the runtime's layout (the one source of the
 * instance size) over counts spanning every term. */
static void test_instance_size_formula(void) {
    static const uint32_t nv[] = {2, 12, 233, 65535}, nf[] = {1, 8, 126, 65534}, nj[] = {1, 2, 15, 255};
    static const uint32_t nc[] = {1, 2, 106, 65535}, nk[] = {0, 1, 3, 256};
    static const uint32_t nfr[] = {0, 1, 32}, sgb[] = {0, 88, 1234568};
    static const uint32_t cnb[] = {0, SN_CONS_BYTES(1, 0, 3), SN_CONS_BYTES(2, 1, 9), SN_CONS_BYTES(64, 16, 448)};
    static const uint32_t crb[] = {0, SN_CREASE_STATE_BYTES(4, 4), SN_CREASE_STATE_BYTES(65535, 256)};
    static const uint32_t nfp[] = {0, 1, 30, 64770}; /* frame pairs (format 6.4): none .. nJ (nJ - 1) at 255 joints */
    int a, b, c, d, e, f, bad = 0, n = 0;
    for (a = 0; a < 4; a++) for (b = 0; b < 4; b++) for (c = 0; c < 4; c++) for (d = 0; d < 4; d++) for (e = 0; e < 4; e++)
    for (f = 0; f < 3; f++) {
        if (nf[b] >= nv[a]) continue;
        n++;
        bad += SN_INSTANCE_BYTES(nv[a], nf[b], nj[c], nc[d], nk[e], nfr[f],
                                 sgb[(a + f) % 3] + crb[(c + e) % 3] + nfp[(d + e) % 4] * SN_FPAIR_BYTES, cnb[(b + e) % 4]) !=
               sn_instance_bytes(nv[a], nf[b], nj[c], nc[d], nk[e], nfr[f], sgb[(a + f) % 3], crb[(c + e) % 3], cnb[(b + e) % 4],
                                 nfp[(d + e) % 4]);
    }
    T_CHECK(n > 300 && bad == 0, "SN_INSTANCE_BYTES == the runtime layout's size for %d count sets (%d differ)", n, bad);
}

int main(void) {
    (void)t_seed; /* no random inputs here */
    printf("  flavour: %s\n", FLAV);
    g_total = tb_build(g_base.b, CAP, 0);
    T_FIGURE("%s test blob: %u bytes, header %d bytes", FLAV, g_total, SN_HEADER_BYTES);
    test_header();
    test_contents();
    test_rig_contents();
    test_accessors(0);
    test_accessors(8);
    test_accessors(-3);
    test_rest_rounding();
    test_steps();
    test_ichol();
    test_instance_size_formula();
    return T_END();
}
