/* sn_blob.c -- validate an untrusted blob once; read-only accessors after.
 *
 * sn_blob_validate() is the only place that checks the blob (like Lua's
 * lundump or the flatcc verifier): after SN_OK every offset, count, index and
 * number the stepping code uses is known to be in range, so the step never
 * checks again. Every read below happens only after the bytes it reads are
 * known to lie inside the caller's buffer; all size arithmetic is done so it
 * cannot wrap (compare "size - offset", products in uint64).
 *
 * Order of checks (first failure wins): NULL -> ALIGN -> TRUNCATED (shorter
 * than the header) -> MAGIC -> ENDIAN (byte-swapped mark) -> VERSION ->
 * ENDIAN (any other mark) -> FLAVOUR -> HEADER / TRUNCATED (total_size) ->
 * HEADER (header fields) -> CHECKSUM -> HEADER (counts) -> VALUE (scalars)
 * -> SECTION (table) -> INDEX / VALUE / SECTION (contents, padding).
 *
 * Numeric bounds (fixed flavour, stored integers): matrix entries
 * |e| <= 2^27 (mass, preconditioner, every cell stiffness block);
 * frac_S, frac_M <= 59 and frac_P <= 50 (the step shifts by frac - k + 3 and
 * frac_P + k - 3 with k <= 15: every shift <= 62); frac_E in [-40, 60];
 * ENERGY > 0; CELL in (0, 2^27] (Q22); DISP_BOUND > 0; limits in [0, 2^28]
 * (Q22, the state clamp); cell corners distinct; cell frames as vertex
 * frames; only known header flags; rest and joint coordinates |x| <= 2^27 (Q22: 32 internal
 * units) and at most 16384 mesh units (|x| <= 2^(36 - len_shift)); a1, b1 in [0, 2^28] (Q24: [0, 16]); |gravity| <= 2^27 (Q22);
 * timestep > 0. Float flavour: every real finite, and the same bounds as
 * true values (the stored integer divided by 2^Q of its format; matrices
 * taken at Q0): |e| <= 2^27, |x| <= min(32, 2^(14 - len_shift)), a1, b1 in [0, 16], |g| <= 32,
 * 0 < h <= 32768, reserved reals +0.0.
 */
#include "sn_internal.h"
#include "sn_adapt.h" /* sn_check_adapt, sn_adapt_bytes */
#include "sn_cut.h"   /* sn_check_cut: CELLX, CELLXK */
#include "sn_detail.h" /* sn_check_details: DETAILS, DETAIL, CELLD, CELLDK */

static const unsigned char *sn_bytes(const sn_blob *b) {
    return (const unsigned char *)(const void *)b;
}

/* CRC-32 (IEEE 802.3 / zlib, reflected poly 0xEDB88320), nibble table in ROM. */
static uint32_t sn_crc32(const unsigned char *p, uint32_t n) {
    static const uint32_t tab[16] = {
        0x00000000u, 0x1DB71064u, 0x3B6E20C8u, 0x26D930ACu, 0x76DC4190u, 0x6B6B51F4u,
        0x4DB26158u, 0x5005713Cu, 0xEDB88320u, 0xF00F9344u, 0xD6D6A3E8u, 0xCB61B38Cu,
        0x9B64C2B0u, 0x86D3D2D4u, 0xA00AE278u, 0xBDBDF21Cu};
    uint32_t c = 0xFFFFFFFFu, i;
    for (i = 0; i < n; i++) {
        c ^= p[i];
        c = (c >> 4) ^ tab[c & 15u];
        c = (c >> 4) ^ tab[c & 15u];
    }
    return ~c;
}

/* ---- one real in range (fixed: stored integer in [lo, hi]; float: finite
 * and in [lo, hi] / 2^q) ---- */
#if defined(SN_FLOAT)
int sn_real_ok(const unsigned char *p, int32_t lo, int32_t hi, int q) {
    uint32_t u = sn_rd_u32(p);
    float v, s = 1.0f / (float)((int32_t)1 << q);
    if (((u >> 23) & 0xFFu) == 0xFFu) return 0; /* inf or NaN */
    v = sn_rd_f32(p);
    return v >= (float)lo * s && v <= (float)hi * s;
}
#else
int sn_real_ok(const unsigned char *p, int32_t lo, int32_t hi, int q) {
    int32_t v = sn_rd_i32(p);
    (void)q;
    return v >= lo && v <= hi;
}
#endif

/* n consecutive reals all with |v| <= lim (float: lim / 2^q). */
static int sn_reals_ok(const unsigned char *p, uint32_t n, int32_t lim, int q) {
    uint32_t i;
    for (i = 0; i < n; i++)
        if (!sn_real_ok(p + (size_t)i * SN_REAL_BYTES, -lim, lim, q)) return 0;
    return 1;
}

/* A reserved real must be exactly zero (float: +0.0 bits). */
static int sn_real_zero(const unsigned char *p) { return sn_rd_u32(p) == 0; }

static int sn_zero_bytes(const unsigned char *p, uint32_t n) {
    uint32_t i;
    for (i = 0; i < n; i++)
        if (p[i]) return 0;
    return 1;
}

#define SN_CHK(cond, err) do { if (!(cond)) return (err); } while (0)

/* n names of 32 bytes, stride bytes apart: non-empty, NUL-terminated,
 * NUL-padded, unique (padded: equal names <=> equal 32 bytes; no memcmp: libc) */
static int sn_names_ok(const unsigned char *s, uint32_t n, uint32_t stride) {
    uint32_t i, j, k;
    for (j = 0; j < n; j++) {
        const unsigned char *a = s + (size_t)j * stride;
        for (k = 0; k < 32 && a[k]; k++) {}
        if (k == 0 || k == 32 || !sn_zero_bytes(a + k, 32 - k)) return 0;
        for (i = 0; i < j; i++) {
            const unsigned char *o = s + (size_t)i * stride;
            uint32_t diff = 0;
            for (k = 0; k < 32; k++) diff |= (uint32_t)(a[k] ^ o[k]);
            if (diff == 0) return 0;
        }
    }
    return 1;
}

/* Rig sections (format 3.0). Bounds and the arithmetic they feed (sn_rig.c):
 * control values and gammas |g| <= 2^30 (Q16.16: 16384; float the same), so
 * gamma differences fit 2^31 and the tau fraction floor(d 2^30 / D), d <= D,
 * is exact in uint64; etas |eta| <= 2^30 (Q30: 1), so eta * Q < 2^61 for any
 * int32 Q and the rounding shift 30 + frac - 19 - k (frac in [5, 50], k in
 * [0, 15]) is in [1, 61]; angle axes unit within 2^-8 (Q30), so v.a of a unit
 * quaternion stays below 2^30.1 for the twist's atan2 (any magnitude <=
 * 2^40 is accepted there); float forces |Q| <= SN_RIG_FLOAT_MAX, finite. */
static sn_status sn_check_rigs(const sn_view *v) {
    const unsigned char *s = v->sec[SN_SEC_CONTROLS];
    const int32_t G = (int32_t)1 << 30;
    uint32_t i, k, ns = 0, ne = 0;
    SN_CHK(sn_names_ok(s, v->nK, SN_ELEM_CONTROLS(SN_REAL_BYTES)), SN_ERR_VALUE);
    for (i = 0; i < v->nK; i++) {
        const unsigned char *c = s + (size_t)i * SN_ELEM_CONTROLS(SN_REAL_BYTES);
        const unsigned char *ax = c + 40, *val = c + 40 + 3 * SN_REAL_BYTES;
        uint32_t kind = c[32], joint = c[33];
        SN_CHK(kind <= SN_CTL_ANGLE && sn_rd_u16(c + 34) == 0 && sn_rd_u32(c + 36) == 0, SN_ERR_VALUE);
        if (kind == SN_CTL_ABSTRACT) {
            SN_CHK(joint == 0, SN_ERR_INDEX);
            SN_CHK(sn_real_zero(ax) && sn_real_zero(ax + SN_REAL_BYTES) && sn_real_zero(ax + 2 * SN_REAL_BYTES),
                   SN_ERR_VALUE);
            SN_CHK(sn_real_ok(val, -G, G, 16), SN_ERR_VALUE);
        } else {
            SN_CHK(joint < v->nJ, SN_ERR_INDEX);
            SN_CHK(sn_reals_ok(ax, 3, G, SN_Q_ROT) && sn_real_zero(val), SN_ERR_VALUE);
            {
#if defined(SN_FLOAT)
                float a0 = sn_rd_f32(ax), a1 = sn_rd_f32(ax + 4), a2 = sn_rd_f32(ax + 8);
                float n2 = a0 * a0 + a1 * a1 + a2 * a2;
                SN_CHK(n2 >= 1.0f - 1.0f / 256 && n2 <= 1.0f + 1.0f / 256, SN_ERR_VALUE);
#else
                int64_t a0 = sn_rd_i32(ax), a1 = sn_rd_i32(ax + 4), a2 = sn_rd_i32(ax + 8);
                int64_t n2 = a0 * a0 + a1 * a1 + a2 * a2; /* each <= 2^60 */
                const int64_t one = (int64_t)1 << 60, tol = (int64_t)1 << 52;
                SN_CHK(n2 >= one - tol && n2 <= one + tol, SN_ERR_VALUE);
#endif
            }
        }
    }
    /* rigs: samples and entries are consecutive runs in rig order */
    s = v->sec[SN_SEC_RIGS];
    for (i = 0; i < v->nR; i++) {
        const unsigned char *r = s + (size_t)i * SN_ELEM_RIGS;
        uint32_t n = r[2], cnt = sn_rd_u32(r + 12);
        int frac = r[3] < 128 ? (int)r[3] : (int)r[3] - 256;
        const unsigned char *g, *vx;
        SN_CHK(sn_rd_u16(r) < v->nK, SN_ERR_INDEX);
        SN_CHK(n >= 1 && n <= SN_RIG_MAX_SAMPLES, SN_ERR_VALUE);
#if defined(SN_FLOAT)
        SN_CHK(frac == 0, SN_ERR_VALUE);
#else
        SN_CHK(frac >= SN_RIG_FRAC_MIN && frac <= SN_RIG_FRAC_MAX, SN_ERR_VALUE);
#endif
        SN_CHK(sn_rd_u32(r + 4) == ns && n <= v->nRS - ns, SN_ERR_INDEX);
        SN_CHK(sn_rd_u32(r + 8) == ne && cnt <= v->nRE - ne, SN_ERR_INDEX);
        g = v->sec[SN_SEC_RIG_SAMPLES] + (size_t)ns * SN_ELEM_RIG_SAMPLES(SN_REAL_BYTES);
        for (k = 0; k < n; k++) {
            const unsigned char *e = g + (size_t)k * SN_ELEM_RIG_SAMPLES(SN_REAL_BYTES);
            SN_CHK(sn_real_ok(e, -G, G, 16) && sn_real_ok(e + SN_REAL_BYTES, -G, G, SN_Q_ROT), SN_ERR_VALUE);
            if (k > 0) SN_CHK(SN_RD_REAL(e) > SN_RD_REAL(e - SN_ELEM_RIG_SAMPLES(SN_REAL_BYTES)), SN_ERR_VALUE);
        }
        vx = v->sec[SN_SEC_RIG_VERTS] + 2 * (size_t)ne;
        for (k = 0; k < cnt; k++) {
            uint32_t a = sn_rd_u16(vx + 2 * k);
            SN_CHK(a < v->nF && (k == 0 || a > sn_rd_u16(vx + 2 * k - 2)), SN_ERR_INDEX);
        }
        ns += n;
        ne += cnt;
    }
    SN_CHK(ns == v->nRS && ne == v->nRE, SN_ERR_INDEX);
#if defined(SN_FLOAT)
    SN_CHK(sn_reals_ok(v->sec[SN_SEC_RIG_FORCES], 3 * v->nRE, (int32_t)SN_RIG_FLOAT_MAX, 0), SN_ERR_VALUE);
#endif
    return SN_OK;
}

static void sn_view_header(sn_view *v, const unsigned char *p);
static void sn_view_sections(sn_view *v);


/* Section contents, given a header and table already checked. */
static sn_status sn_check_contents(const sn_view *v) {
    const int32_t E = SN_ENTRY_LIM; /* 2^27 */
    /* coordinates: |x| <= 2^27 (Q22) and, in public Q16.16 mesh units,
     * |x * 2^(len_shift-6)| <= 2^30 (16384 mesh units), so public rest values
     * and their differences cannot overflow int32 */
    const int32_t X = v->len_shift > 9 ? (int32_t)1 << (36 - v->len_shift) : E;
    const unsigned char *s;
    uint32_t i, j, k;

    /* joints: parent < own index (root 0xFFFF only at 0), reserved 0, rest */
    s = v->sec[SN_SEC_JOINTS];
    for (j = 0; j < v->nJ; j++) {
        const unsigned char *e = s + (size_t)j * SN_ELEM_JOINTS(SN_REAL_BYTES);
        uint32_t par = sn_rd_u16(e);
        if (j == 0) SN_CHK(par == 0xFFFFu, SN_ERR_INDEX);
        else SN_CHK(par < j, SN_ERR_INDEX);
        SN_CHK(sn_rd_u16(e + 2) == 0 && sn_rd_u32(e + 4) == 0, SN_ERR_VALUE);
        SN_CHK(sn_reals_ok(e + 8, 3, X, SN_Q_LEN), SN_ERR_VALUE);
    }
    SN_CHK(sn_names_ok(v->sec[SN_SEC_JOINT_NAMES], v->nJ, SN_JOINT_NAME_MAX), SN_ERR_VALUE);
    SN_CHK(sn_reals_ok(v->sec[SN_SEC_REST], 3 * v->nV, X, SN_Q_LEN), SN_ERR_VALUE);
    /* frames: bones < nJ, w <= 1 (Q15); skeleton vertices rigid to bone1 */
    s = v->sec[SN_SEC_FRAMES];
    for (i = 0; i < v->nV; i++) {
        const unsigned char *f = s + (size_t)i * SN_ELEM_FRAMES;
        SN_CHK(f[0] < v->nJ && f[1] < v->nJ, SN_ERR_INDEX);
        SN_CHK(sn_rd_u16(f + 2) <= 32768u, SN_ERR_VALUE);
        if (i >= v->nF) {
            SN_CHK(f[0] == f[1], SN_ERR_INDEX);
            SN_CHK(sn_rd_u16(f + 2) == 0, SN_ERR_VALUE);
        }
    }
    /* matrices */
    SN_CHK(sn_reals_ok(v->sec[SN_SEC_MDIAG], v->nF, E, 0), SN_ERR_VALUE);
    SN_CHK(sn_reals_ok(v->sec[SN_SEC_PRECOND], 6 * v->nF, E, 0), SN_ERR_VALUE);
    SN_CHK(sn_reals_ok(v->sec[SN_SEC_MLUMP], v->nF, E, 0), SN_ERR_VALUE);
    SN_CHK(sn_reals_ok(v->sec[SN_SEC_MOFF], v->nnz, E, 0), SN_ERR_VALUE);
    /* sparsity: rowptr monotone 0..nnz; per row columns strictly increasing,
     * > row (upper triangle), < nV */
    {
        const unsigned char *rp = v->sec[SN_SEC_ROWPTR], *cols = v->sec[SN_SEC_COLS];
        SN_CHK(sn_rd_u32(rp) == 0, SN_ERR_INDEX);
        SN_CHK(sn_rd_u32(rp + 4 * (size_t)v->nF) == v->nnz, SN_ERR_INDEX);
        for (i = 0; i < v->nF; i++) {
            uint32_t a = sn_rd_u32(rp + 4 * (size_t)i), b = sn_rd_u32(rp + 4 * (size_t)i + 4);
            uint32_t prev = i;
            SN_CHK(a <= b && b <= v->nnz, SN_ERR_INDEX);
            SN_CHK(b - a <= (v->cut ? SN_MAX_ROW_BLOCKS_CUT : SN_MAX_ROW_BLOCKS), SN_ERR_INDEX);
            for (k = a; k < b; k++) {
                uint32_t c = sn_rd_u16(cols + 2 * (size_t)k);
                SN_CHK(c > prev && c < v->nV, SN_ERR_INDEX);
                prev = c;
            }
        }
    }
    /* cells: corners < nV and pairwise distinct (a cell's 24 rows are its
     * own: no vertex gets two rows of one cell); frames as FRAMES; stiffness
     * entries |e| <= 2^27 (36*9*nC fits: the section size bounded it) */
    s = v->sec[SN_SEC_CELLS];
    for (i = 0; i < v->nC; i++) {
        const unsigned char *c = s + (size_t)i * SN_ELEM_CELLS;
        for (k = 0; k < 8; k++) {
            uint32_t a = sn_rd_u16(c + 2 * k);
            SN_CHK(a < v->nV, SN_ERR_INDEX);
            for (j = 0; j < k; j++) SN_CHK(sn_rd_u16(c + 2 * j) != a, SN_ERR_INDEX);
        }
    }
    s = v->sec[SN_SEC_CFRAMES];
    for (i = 0; i < v->nC; i++) {
        const unsigned char *f = s + (size_t)i * SN_ELEM_CFRAMES;
        SN_CHK(f[0] < v->nJ && f[1] < v->nJ, SN_ERR_INDEX);
        SN_CHK(sn_rd_u16(f + 2) <= 32768u, SN_ERR_VALUE);
    }
#if defined(SN_FLOAT)
    SN_CHK(sn_reals_ok(v->sec[SN_SEC_CELLK], SN_CELL_BLOCKS * 9 * v->nC, E, 0), SN_ERR_VALUE);
#else
    /* fixed CELLK (format 6.0): diagonal int32 |d| <= 2^27; off-diagonal
     * int16 mantissas |m| <= 2^15 - 1 with exponents e <= 12, so every entry
     * m 2^e < 2^27: the bound the cell-row proof uses (NUMERICS.md) */
    s = v->sec[SN_SEC_CELLK];
    for (i = 0; i < v->nC; i++) {
        const unsigned char *c = s + (size_t)i * SN_CELLK_FIXED_BYTES;
        SN_CHK(sn_reals_ok(c + SN_CELLK_DIAG, 8 * 6, E, 0), SN_ERR_VALUE);
        for (k = 0; k < 28 * 9; k++) SN_CHK(sn_rd_u16(c + SN_CELLK_OFF + 2 * k) != 0x8000u, SN_ERR_VALUE);
        for (k = 0; k < 28; k++) SN_CHK(c[SN_CELLK_EXP + k] <= SN_CELLK_EXP_MAX, SN_ERR_VALUE);
    }
#endif
    /* limits: 0 <= L <= 2^28 (Q22: 64 internal units, the state clamp) */
    s = v->sec[SN_SEC_LIMIT];
    for (i = 0; i < v->nL; i++)
        SN_CHK(sn_real_ok(s + (size_t)i * SN_REAL_BYTES, 0, SN_LIM, SN_Q_LEN), SN_ERR_VALUE);
    /* embedding: cell < nC, trilinear coordinates in [0, 1] (Q15) */
    s = v->sec[SN_SEC_EMBED];
    for (i = 0; i < v->nS; i++) {
        const unsigned char *e = s + (size_t)i * SN_ELEM_EMBED;
        SN_CHK(sn_rd_u16(e) < v->nC, SN_ERR_INDEX);
        for (k = 1; k < 4; k++) SN_CHK(sn_rd_u16(e + 2 * k) <= 32768u, SN_ERR_VALUE);
    }
    /* triangles: surface vertex indices < nS */
    s = v->sec[SN_SEC_TRIS];
    for (i = 0; i < 3 * v->nT; i++) SN_CHK(sn_rd_u16(s + 2 * (size_t)i) < v->nS, SN_ERR_INDEX);
    return sn_check_rigs(v);
}

/* IC(0) factor (NUMERICS.md "Preconditioner"), COLS already checked: 0 or
 * one block per free-free mass entry; |m| <= 2^15 - 1 and frac <=
 * SN_ICHOL_FRAC_MAX, so a sweep's block row is < 3 (2^15 - 1) 2^28 < 2^44.6
 * and its shift frac + k_j - k_i lies in [-15, 62]: scaled up by at most
 * 2^15 (< 2^59.6) or rounded down, always a valid sn_out argument. */
static sn_status sn_check_ichol(const sn_view *v, uint32_t nic) {
    const unsigned char *s = v->sec[SN_SEC_ICHOL], *cols = v->sec[SN_SEC_COLS];
    uint32_t i, k, nff = 0;
    for (i = 0; i < v->nnz; i++) nff += sn_rd_u16(cols + 2 * (size_t)i) < v->nF;
    SN_CHK(nic == 0 || nic == nff, SN_ERR_SECTION);
    for (i = 0; i < nic; i++) {
        const unsigned char *b = s + (size_t)i * SN_ELEM_ICHOL;
        for (k = 0; k < 9; k++) SN_CHK(sn_rd_u16(b + 2 * k) != 0x8000u, SN_ERR_VALUE);
        SN_CHK(b[18] <= SN_ICHOL_FRAC_MAX && b[19] == 0, SN_ERR_VALUE);
    }
    return SN_OK;
}

/* One blob's own checks (a finer level's nested blob goes through the same:
 * sn_blob_validate calls this for the blob, then for its LEVEL_BLOB). */
static sn_status validate_one(const void *data, size_t size, sn_view *vo) {
    const unsigned char *p = (const unsigned char *)data;
    uint32_t total, cnt[SN_SEC_COUNT], prev_end, k;
    sn_view v;
    sn_status st;

    if (((uintptr_t)data & 7u) != 0) return SN_ERR_ALIGN;
    if (size < SN_HEADER_BYTES) return SN_ERR_TRUNCATED;

    /* identity: magic, byte order, version, flavour */
    if (p[0] != SN_MAGIC0 || p[1] != SN_MAGIC1 || p[2] != SN_MAGIC2 || p[3] != SN_MAGIC3)
        return SN_ERR_MAGIC;
    if (sn_rd_u32(p + SN_H_ENDIAN) == 0x04030201u) return SN_ERR_ENDIAN; /* byte-swapped */
    /* the minor too must be this reader's: 6.1's section table is longer than
     * 6.0's, so no older minor reads the same (and a flipped minor is refused) */
    if (sn_rd_u16(p + SN_H_VER_MAJOR) != SN_FORMAT_MAJOR ||
        sn_rd_u16(p + SN_H_VER_MINOR) != SN_FORMAT_MINOR)
        return SN_ERR_VERSION;
    if (sn_rd_u32(p + SN_H_ENDIAN) != SN_ENDIAN_MARK) return SN_ERR_ENDIAN;
    if (p[SN_H_FLAVOUR] != SN_FLAVOUR || p[SN_H_REAL_SIZE] != SN_REAL_BYTES ||
        sn_rd_u32(p + SN_H_ONE) != (SN_FLAVOUR == SN_FLAVOUR_FIXED ? SN_ONE_FIXED : SN_ONE_FLOAT32) ||
        sn_rd_u32(p + SN_H_ONE_HI) != 0)
        return SN_ERR_FLAVOUR;

    /* sizes and fixed header fields */
    total = sn_rd_u32(p + SN_H_TOTAL_SIZE);
    if (total < SN_HEADER_BYTES) return SN_ERR_HEADER;
    if (total > size) return SN_ERR_TRUNCATED;
    if (sn_rd_u32(p + SN_H_HEADER_SIZE) != SN_HEADER_BYTES || p[SN_H_NSECTIONS] != SN_SEC_COUNT ||
        (p[SN_H_FLAGS] & ~SN_FLAG_REST_MODELLED) != 0 || p[SN_H_RESERVED1] != 0 ||
        p[SN_H_MAX_FORCES] > SN_MAX_FORCES)
        return SN_ERR_HEADER;
#if !defined(SN_VALIDATE_NO_CHECKSUM)
    if (sn_crc32(p + 16, total - 16) != sn_rd_u32(p + SN_H_CRC32)) return SN_ERR_CHECKSUM;
#endif

    /* counts and settings (decoded by the same code the accessors use) */
    sn_view_header(&v, p);
    if (v.nV > SN_MAX_VERTICES || v.nF < 1 || v.nF >= v.nV) return SN_ERR_HEADER;
    if (v.nJ < 1 || v.nJ > SN_MAX_JOINTS || v.nS > SN_MAX_SURFACE) return SN_ERR_HEADER;
    if (v.cg_default < 1 || v.cg_default > v.cg_max || v.cg_max > SN_MAX_CG_ITERS)
        return SN_ERR_HEADER;
    /* shifts the step takes: frac_S - k + 3 and frac_M - k + 3 (k in 0..15),
     * frac_P + k - 3: all must stay <= 62 for sn_rshr64 */
    if (v.len_shift < -24 || v.len_shift > 24 || v.frac_S > 59 || v.frac_M > 59 || v.frac_P > 50 ||
        v.frac_E < -40 || v.frac_E > 60 || (SN_FLAVOUR != SN_FLAVOUR_FIXED && v.frac_E != 0) ||
        v.frac_F < -40 || v.frac_F > 60 || (SN_FLAVOUR != SN_FLAVOUR_FIXED && v.frac_F != 0))
        return SN_ERR_HEADER;
    if (v.nC < 1 || v.nC > SN_MAX_VERTICES) return SN_ERR_HEADER;

    /* physics scalars */
    {
        const unsigned char *r = p + SN_H_REALS;
        if (!sn_real_ok(r + SN_R_A1 * SN_REAL_BYTES, 0, (int32_t)1 << 28, SN_Q_COEF) ||
            !sn_real_ok(r + SN_R_B1 * SN_REAL_BYTES, 0, (int32_t)1 << 28, SN_Q_COEF) ||
            !sn_reals_ok(r + SN_R_GRAV_X * SN_REAL_BYTES, 3, SN_ENTRY_LIM, SN_Q_LEN) ||
            !sn_real_ok(r + SN_R_TIMESTEP * SN_REAL_BYTES, 0, INT32_MAX, 16) ||
            !(v.timestep > 0) ||
            !sn_real_ok(r + SN_R_MASS_SCALE * SN_REAL_BYTES, INT32_MIN, INT32_MAX, 0) ||
            !sn_real_ok(r + SN_R_ENERGY * SN_REAL_BYTES, 0, INT32_MAX, 0) || !(v.energy > 0) ||
            !sn_real_ok(r + SN_R_CELL * SN_REAL_BYTES, 1, SN_ENTRY_LIM, SN_Q_LEN) || !(v.cell > 0) ||
            !sn_real_ok(r + SN_R_DISP_BOUND * SN_REAL_BYTES, 1, INT32_MAX, 16) || !(v.disp_bound > 0) ||
            !sn_real_ok(r + SN_R_FORCE * SN_REAL_BYTES, 0, INT32_MAX, 0) || !(v.force > 0) ||
            !sn_real_zero(r + SN_R_RESERVED11 * SN_REAL_BYTES))
            return SN_ERR_VALUE;
    }

    /* section table: aligned, ascending, non-overlapping, inside total,
     * count as the header says, elem_size as the format says, size exact */
    cnt[SN_SEC_JOINTS] = v.nJ;
    cnt[SN_SEC_JOINT_NAMES] = v.nJ;
    cnt[SN_SEC_REST] = v.nV;
    cnt[SN_SEC_FRAMES] = v.nV;
    cnt[SN_SEC_MDIAG] = v.nF;
    cnt[SN_SEC_PRECOND] = v.nF;
    cnt[SN_SEC_MLUMP] = v.nF;
    cnt[SN_SEC_ROWPTR] = v.nF + 1;
    cnt[SN_SEC_COLS] = v.nnz;
    cnt[SN_SEC_MOFF] = v.nnz;
    cnt[SN_SEC_CELLS] = v.nC;
    cnt[SN_SEC_CFRAMES] = v.nC;
    cnt[SN_SEC_CELLK] = v.nC;
    cnt[SN_SEC_LIMIT] = 0; /* 0 or nF: taken from the table below */
    cnt[SN_SEC_EMBED] = v.nS;
    cnt[SN_SEC_TRIS] = v.nT;
    cnt[SN_SEC_ICHOL] = 0; /* 0 or nFF: taken from the table below */
    cnt[SN_SEC_ADAPT] = 0; /* 0 or 1: taken from the table below */
    cnt[SN_SEC_CELLX] = 0; /* 0 or nC: taken from the table below */
    cnt[SN_SEC_CELLXK] = 0; /* <= 8 x 19 nC: taken from the table below, checked with CELLX */
    cnt[SN_SEC_FPAIRS] = 0; /* <= nJ (nJ - 1): taken from the table below, checked with FREFS */
    cnt[SN_SEC_FREFS] = 0;  /* 0 or nF + nC: taken from the table below */
    cnt[SN_SEC_DETAILS] = 0; /* format 6.5, the details: 0 or 1, <= 19 nC, 0 or nC, <= 342 nC; checked together */
    cnt[SN_SEC_DETAIL] = 0;
    cnt[SN_SEC_CELLD] = 0;
    cnt[SN_SEC_CELLDK] = 0;
    /* rig sections: counts from the table, bounded (cost per step, u16/u32 indices) */
    {
        const unsigned char *t = p + SN_H_SECTIONS + 8;
        v.nK = sn_rd_u32(t + SN_SEC_CONTROLS * SN_SECTION_ENTRY);
        v.nR = sn_rd_u32(t + SN_SEC_RIGS * SN_SECTION_ENTRY);
        v.nRS = sn_rd_u32(t + SN_SEC_RIG_SAMPLES * SN_SECTION_ENTRY);
        v.nRE = sn_rd_u32(t + SN_SEC_RIG_VERTS * SN_SECTION_ENTRY);
        if (v.nK > SN_MAX_CONTROLS || v.nR > SN_MAX_RIGS || v.nRS > SN_MAX_RIGS * SN_RIG_MAX_SAMPLES ||
            v.nRE > SN_MAX_RIGS * (uint32_t)SN_MAX_VERTICES)
            return SN_ERR_SECTION;
        cnt[SN_SEC_CONTROLS] = v.nK;
        cnt[SN_SEC_RIGS] = v.nR;
        cnt[SN_SEC_RIG_SAMPLES] = v.nRS;
        cnt[SN_SEC_RIG_VERTS] = v.nRE;
        cnt[SN_SEC_RIG_FORCES] = v.nRE; /* one force per vertex entry */
        /* forces and segments (format 4.0) */
        v.nP = sn_rd_u32(t + SN_SEC_SHARES * SN_SECTION_ENTRY);
        v.nM = sn_rd_u32(t + SN_SEC_SEGMESH * SN_SECTION_ENTRY);
        v.nSN = sn_rd_u32(t + SN_SEC_SEGNODES * SN_SECTION_ENTRY);
        v.nSA = sn_rd_u32(t + SN_SEC_SEGATTACH * SN_SECTION_ENTRY);
        if (v.nP > SN_MAX_PROFILES || v.nM > SN_SEG_MAX_MESHES ||
            v.nSN > SN_SEG_MAX_MESHES * SN_SEG_MAX_SIDE * SN_SEG_MAX_SIDE ||
            v.nSA > SN_SEG_MAX_MESHES * SN_SEG_MAX_SIDE * SN_SEG_MAX_SIDE)
            return SN_ERR_SECTION;
        cnt[SN_SEC_SHARES] = v.nP;
        cnt[SN_SEC_VSHARE] = 0; /* 0 or nF: taken from the table below */
        cnt[SN_SEC_SEGMESH] = v.nM;
        cnt[SN_SEC_SEGNODES] = v.nSN;
        cnt[SN_SEC_SEGATTACH] = v.nSA;
        /* crease (format 5.0): the parameters fix the other three counts */
        {
            uint32_t ncr = sn_rd_u32(t + SN_SEC_CREASE * SN_SECTION_ENTRY);
            v.nD = sn_rd_u32(t + SN_SEC_CREASE_PAIRS * SN_SECTION_ENTRY);
            if (ncr > 1 || v.nD > SN_CREASE_MAX_PAIRS || (ncr == 0 && v.nD != 0)) return SN_ERR_SECTION;
            v.nCR = (uint16_t)ncr;
        }
        cnt[SN_SEC_CREASE] = v.nCR;
        cnt[SN_SEC_CREASE_PAIRS] = v.nD;
        cnt[SN_SEC_CREASE_VNBR] = 0;
        cnt[SN_SEC_CREASE_TNBR] = 0;
        if (v.nCR) {
            const unsigned char *ce = p + SN_H_SECTIONS + SN_SEC_CREASE * SN_SECTION_ENTRY;
            uint32_t coff = sn_rd_u32(ce);
            /* the record is read only once it lies inside the blob */
            if ((coff & 7u) != 0 || coff > total || total - coff < SN_ELEM_CREASE(SN_REAL_BYTES)) return SN_ERR_SECTION;
            v.cr_list = (uint16_t)sn_rd_u16(p + coff);
            v.cr_active = (uint16_t)sn_rd_u16(p + coff + 2);
            v.cr_nv = p[coff + 4];
            v.cr_nt = p[coff + 5];
            v.cr_nq = (uint16_t)sn_rd_u16(p + coff + 6);
            if (v.cr_nq < 1 || v.cr_nq > v.nS || v.cr_list < 1 || v.cr_list > SN_CREASE_MAX_LIST || v.cr_active < 1 || v.cr_active > v.cr_list ||
                v.cr_active > SN_CREASE_MAX_ACTIVE || v.cr_nv < 1 || v.cr_nv > SN_CREASE_MAX_NBR_V || v.cr_nt < 1 ||
                v.cr_nt > SN_CREASE_MAX_NBR_T || v.nS < 1 || v.nT < 1)
                return SN_ERR_VALUE;
            cnt[SN_SEC_CREASE_VNBR] = (uint32_t)v.cr_nq * v.cr_nv;
            cnt[SN_SEC_CREASE_TNBR] = (uint32_t)v.cr_nq * v.cr_nt;
            v.crB = SN_CREASE_STATE_BYTES(v.nS, v.cr_list);
        }
        cnt[SN_SEC_CONSTRAINTS] = 0; /* 0 or 1: taken from the table below */
        /* levels (format 6.0): counts from the table, checked against the finer level by sn_check_levels */
        cnt[SN_SEC_LEVEL_BLOB] = sn_rd_u32(t + SN_SEC_LEVEL_BLOB * SN_SECTION_ENTRY);
        cnt[SN_SEC_LEVEL_UP] = sn_rd_u32(t + SN_SEC_LEVEL_UP * SN_SECTION_ENTRY);
        cnt[SN_SEC_LEVEL_DOWN] = sn_rd_u32(t + SN_SEC_LEVEL_DOWN * SN_SECTION_ENTRY);
    }
    {
        static const uint16_t elem[SN_SEC_COUNT] = {
            SN_ELEM_JOINTS(SN_REAL_BYTES), SN_ELEM_JOINT_NAMES, SN_ELEM_REST(SN_REAL_BYTES),
            SN_ELEM_FRAMES, SN_ELEM_MDIAG(SN_REAL_BYTES),
            SN_ELEM_PRECOND(SN_REAL_BYTES), SN_ELEM_MLUMP(SN_REAL_BYTES), SN_ELEM_ROWPTR,
            SN_ELEM_COLS, SN_ELEM_MOFF(SN_REAL_BYTES), SN_ELEM_CELLS, SN_ELEM_CFRAMES,
            SN_ELEM_CELLK(SN_FLAVOUR, SN_REAL_BYTES), SN_ELEM_LIMIT(SN_REAL_BYTES), SN_ELEM_EMBED, SN_ELEM_TRIS,
            SN_ELEM_CONTROLS(SN_REAL_BYTES), SN_ELEM_RIGS, SN_ELEM_RIG_SAMPLES(SN_REAL_BYTES),
            SN_ELEM_RIG_VERTS, SN_ELEM_RIG_FORCES(SN_REAL_BYTES), SN_ELEM_SHARES(SN_REAL_BYTES),
            SN_ELEM_VSHARE, SN_ELEM_SEGMESH(SN_REAL_BYTES), SN_ELEM_SEGNODES(SN_REAL_BYTES),
            SN_ELEM_SEGATTACH(SN_REAL_BYTES), SN_ELEM_CONSTRAINTS, SN_ELEM_CREASE(SN_REAL_BYTES), SN_ELEM_CREASE_PAIRS,
            SN_ELEM_CREASE_VNBR, SN_ELEM_CREASE_TNBR, SN_ELEM_LEVEL_BLOB, SN_ELEM_LEVEL_MAP, SN_ELEM_LEVEL_MAP,
            SN_ELEM_ICHOL, SN_ELEM_ADAPT(SN_REAL_BYTES), SN_ELEM_CELLX, SN_ELEM_CELLXK(SN_FLAVOUR, SN_REAL_BYTES),
            SN_ELEM_FPAIRS, SN_ELEM_FREFS,
            SN_ELEM_DETAILS(SN_REAL_BYTES), SN_ELEM_DETAIL(SN_REAL_BYTES), SN_ELEM_CELLD, SN_ELEM_CELLDK(SN_FLAVOUR, SN_REAL_BYTES)};
        prev_end = SN_HEADER_BYTES;
        for (k = 0; k < SN_SEC_COUNT; k++) {
            const unsigned char *e = p + SN_H_SECTIONS + (size_t)k * SN_SECTION_ENTRY;
            uint32_t off = sn_rd_u32(e), sz = sn_rd_u32(e + 4);
            if ((k == SN_SEC_LIMIT || k == SN_SEC_VSHARE) && sn_rd_u32(e + 8) == v.nF) cnt[k] = v.nF; /* optional */
            if (k == SN_SEC_CONSTRAINTS && sn_rd_u32(e + 8) == 1u) cnt[k] = 1u; /* optional record */
            if (k == SN_SEC_ICHOL && sn_rd_u32(e + 8) <= v.nnz) cnt[k] = sn_rd_u32(e + 8); /* 0 or nFF: checked with COLS */
            if (k == SN_SEC_ADAPT && sn_rd_u32(e + 8) == 1u) cnt[k] = 1u; /* optional record: checked with the pair (sn_adapt.c) */
            if (k == SN_SEC_CELLX && sn_rd_u32(e + 8) == v.nC) cnt[k] = v.nC; /* optional: the cut level */
            if (k == SN_SEC_CELLXK && (uint64_t)sn_rd_u32(e + 8) <= 8u * SN_CUT_MAXX * (uint64_t)v.nC) cnt[k] = sn_rd_u32(e + 8);
            if (k == SN_SEC_FPAIRS && sn_rd_u32(e + 8) <= v.nJ * (v.nJ - 1u)) cnt[k] = sn_rd_u32(e + 8); /* distinct pairs */
            if (k == SN_SEC_FREFS && sn_rd_u32(e + 8) == v.nF + v.nC) cnt[k] = v.nF + v.nC; /* optional */
            if (k == SN_SEC_DETAILS && sn_rd_u32(e + 8) == 1u) cnt[k] = 1u;
            if (k == SN_SEC_DETAIL && (uint64_t)sn_rd_u32(e + 8) <= SN_CUT_MAXX * (uint64_t)v.nC) cnt[k] = sn_rd_u32(e + 8);
            if (k == SN_SEC_CELLD && sn_rd_u32(e + 8) == v.nC) cnt[k] = v.nC;
            if (k == SN_SEC_CELLDK && (uint64_t)sn_rd_u32(e + 8) <= SN_DETAIL_CELL_MAX * (uint64_t)v.nC) cnt[k] = sn_rd_u32(e + 8);
            if ((off & 7u) != 0 || off < prev_end || off > total || sz > total - off)
                return SN_ERR_SECTION;
            if (sn_rd_u32(e + 8) != cnt[k] || sn_rd_u32(e + 12) != elem[k] ||
                (uint64_t)cnt[k] * elem[k] != (uint64_t)sz)
                return SN_ERR_SECTION;
            /* padding since the previous section (or the header) is zero */
            if (!sn_zero_bytes(p + prev_end, off - prev_end)) return SN_ERR_SECTION;
            prev_end = off + sz;
        }
        v.nL = cnt[SN_SEC_LIMIT];
        v.nVP = cnt[SN_SEC_VSHARE];
        if (!sn_zero_bytes(p + prev_end, total - prev_end)) return SN_ERR_SECTION;
    }

    sn_view_sections(&v);
    st = sn_check_contents(&v);
    if (st != SN_OK) return st;
    st = sn_check_ichol(&v, cnt[SN_SEC_ICHOL]);
    if (st != SN_OK) return st;
    st = sn_check_cut(&v, cnt[SN_SEC_CELLX], cnt[SN_SEC_CELLXK]);
    if (st != SN_OK) return st;
    st = sn_check_frefs(&v, cnt[SN_SEC_FPAIRS], cnt[SN_SEC_FREFS]);
    if (st != SN_OK) return st;
    st = sn_check_details(&v, cnt[SN_SEC_DETAILS], cnt[SN_SEC_DETAIL], cnt[SN_SEC_CELLD], cnt[SN_SEC_CELLDK], cnt[SN_SEC_CELLX]);
    if (st != SN_OK) return st;
    st = sn_check_forces(&v);
    if (st != SN_OK) return st;
    st = sn_check_segments(&v, &v.segB);
    if (st != SN_OK) return st;
    st = sn_check_crease(&v);
    if (st != SN_OK) return st;
    st = sn_check_constraints(&v); /* after the crease record: its rows count */
    if (st != SN_OK) return st;
    *vo = v;
    return SN_OK;
}

sn_status sn_blob_validate(const void *data, size_t size, const sn_blob **out) {
    sn_view v, f;
    sn_status st;
    uint32_t nV, nF, nC;
    if (!data || !out) return SN_ERR_NULL;
    *out = NULL;
    st = validate_one(data, size, &v);
    if (st != SN_OK) return st;
    if (sn_level_sec_count(&v, SN_SEC_LEVEL_BLOB) != 0) { /* a finer level: a complete blob, then the pair (sn_level.c) */
        st = validate_one(v.sec[SN_SEC_LEVEL_BLOB], sn_level_sec_count(&v, SN_SEC_LEVEL_BLOB), &f);
        if (st != SN_OK) return st;
        st = sn_check_levels(&v, &f);
        if (st != SN_OK) return st;
        st = sn_check_adapt(&f, NULL); /* the nested level has none */
        if (st != SN_OK) return st;
        st = sn_check_adapt(&v, &f);
        if (st != SN_OK) return st;
    } else if (sn_level_sec_count(&v, SN_SEC_ADAPT) != 0) {
        return SN_ERR_SECTION;
    } else if (sn_level_sec_count(&v, SN_SEC_LEVEL_UP) != 0 || sn_level_sec_count(&v, SN_SEC_LEVEL_DOWN) != 0) {
        return SN_ERR_SECTION;
    }
    /* the instance size is the runtime's layout (one source: sn_instance.c) for the largest level's counts */
    sn_level_counts(&v, &nV, &nF, &nC);
    if (v.instance_bytes != sn_instance_bytes(nV, nF, v.nJ, nC, v.nK, v.nFrc, v.segB, v.crB, v.conB, sn_level_fpairs(&v)))
        return SN_ERR_HEADER;
    *out = (const sn_blob *)data;
    return SN_OK;
}

/* Decode header counts and scalars (no section pointers: validate calls
 * this before the offsets are known to be inside the buffer). */
static void sn_view_header(sn_view *v, const unsigned char *p) {
    const unsigned char *r = p + SN_H_REALS;
    v->base = p;
    v->nV = sn_rd_u32(p + SN_H_N_VERTICES);
    v->nF = sn_rd_u32(p + SN_H_N_FREE);
    v->nC = sn_rd_u32(p + SN_H_N_CELLS);
    v->nJ = sn_rd_u32(p + SN_H_N_JOINTS);
    v->nS = sn_rd_u32(p + SN_H_N_SURFACE);
    v->nT = sn_rd_u32(p + SN_H_N_TRIANGLES);
    v->nnz = sn_rd_u32(p + SN_H_N_OFFDIAG);
    v->cg_default = sn_rd_u16(p + SN_H_CG_DEFAULT);
    v->cg_max = sn_rd_u16(p + SN_H_CG_MAX);
    v->instance_bytes = sn_rd_u32(p + SN_H_INSTANCE_BYTES);
    v->total = sn_rd_u32(p + SN_H_TOTAL_SIZE);
    v->len_shift = p[SN_H_LEN_SHIFT] < 128 ? (int)p[SN_H_LEN_SHIFT] : (int)p[SN_H_LEN_SHIFT] - 256;
    v->frac_S = p[SN_H_FRAC_S];
    v->frac_M = p[SN_H_FRAC_M];
    v->frac_P = p[SN_H_FRAC_P];
    v->frac_E = p[SN_H_FRAC_E] < 128 ? (int)p[SN_H_FRAC_E] : (int)p[SN_H_FRAC_E] - 256;
    v->frac_F = p[SN_H_FRAC_F] < 128 ? (int)p[SN_H_FRAC_F] : (int)p[SN_H_FRAC_F] - 256;
    v->nFrc = p[SN_H_MAX_FORCES];
    v->a1 = SN_RD_REAL(r + SN_R_A1 * SN_REAL_BYTES);
    v->b1 = SN_RD_REAL(r + SN_R_B1 * SN_REAL_BYTES);
    v->grav[0] = SN_RD_REAL(r + SN_R_GRAV_X * SN_REAL_BYTES);
    v->grav[1] = SN_RD_REAL(r + SN_R_GRAV_Y * SN_REAL_BYTES);
    v->grav[2] = SN_RD_REAL(r + SN_R_GRAV_Z * SN_REAL_BYTES);
    v->timestep = SN_RD_REAL(r + SN_R_TIMESTEP * SN_REAL_BYTES);
    v->energy = SN_RD_REAL(r + SN_R_ENERGY * SN_REAL_BYTES);
    v->cell = SN_RD_REAL(r + SN_R_CELL * SN_REAL_BYTES);
    v->disp_bound = SN_RD_REAL(r + SN_R_DISP_BOUND * SN_REAL_BYTES);
    v->force = SN_RD_REAL(r + SN_R_FORCE * SN_REAL_BYTES);
    v->flags = p[SN_H_FLAGS];
    v->nL = v->nK = v->nR = v->nRS = v->nRE = 0;
    v->nP = v->nVP = v->nM = v->nSN = v->nSA = v->segB = 0;
    v->nD = v->crB = 0;
    v->nCR = v->cr_list = v->cr_active = v->cr_nv = v->cr_nt = v->cr_nq = v->ic = v->cut = 0;
    v->cr_depth = v->cr_push = 0;
    v->nCon = v->nCol = v->nCt = v->nRows = v->conB = 0;
}

static void sn_view_sections(sn_view *v) {
    int k;
    for (k = 0; k < SN_SEC_VIEWED; k++)
        v->sec[k] = v->base + sn_rd_u32(v->base + SN_H_SECTIONS + k * SN_SECTION_ENTRY);
    v->nL = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_LIMIT * SN_SECTION_ENTRY + 8);
    v->nK = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_CONTROLS * SN_SECTION_ENTRY + 8);
    v->nR = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_RIGS * SN_SECTION_ENTRY + 8);
    v->nRS = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_RIG_SAMPLES * SN_SECTION_ENTRY + 8);
    v->nRE = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_RIG_VERTS * SN_SECTION_ENTRY + 8);
    v->nP = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_SHARES * SN_SECTION_ENTRY + 8);
    v->nVP = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_VSHARE * SN_SECTION_ENTRY + 8);
    v->ic = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_ICHOL * SN_SECTION_ENTRY + 8) != 0;
    v->cut = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_CELLX * SN_SECTION_ENTRY + 8) != 0;
    v->nM = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_SEGMESH * SN_SECTION_ENTRY + 8);
    v->nSN = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_SEGNODES * SN_SECTION_ENTRY + 8);
    v->nSA = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_SEGATTACH * SN_SECTION_ENTRY + 8);
    v->nCR = (uint16_t)(sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_CREASE * SN_SECTION_ENTRY + 8) != 0); /* validated: 0 or 1 */
    v->nD = sn_rd_u32(v->base + SN_H_SECTIONS + SN_SEC_CREASE_PAIRS * SN_SECTION_ENTRY + 8);
    if (v->nCR) { /* parameters (validate: read once the record is known to be inside the blob) */
        const unsigned char *c = v->sec[SN_SEC_CREASE];
        v->cr_list = (uint16_t)sn_rd_u16(c);
        v->cr_active = (uint16_t)sn_rd_u16(c + 2);
        v->cr_nv = c[4];
        v->cr_nt = c[5];
        v->cr_nq = (uint16_t)sn_rd_u16(c + 6);
        v->cr_depth = SN_RD_REAL(c + 12);
        v->cr_push = SN_RD_REAL(c + 12 + SN_REAL_BYTES);
        v->crB = SN_CREASE_STATE_BYTES(v->nS, v->cr_list);
    }
    sn_view_constraints(v);
}

/* Decode a blob that sn_blob_validate() accepted (no checks). */
void sn_view_init(sn_view *v, const sn_blob *blob) {
    uint32_t m;
    sn_view_header(v, sn_bytes(blob));
    sn_view_sections(v);
    for (m = 0; m < v->nM; m++) { /* segment state bytes (validated records) */
        const unsigned char *r = v->sec[SN_SEC_SEGMESH] + (size_t)m * SN_ELEM_SEGMESH(SN_REAL_BYTES);
        uint32_t segs, nodes;
        sn_seg_counts(r[0], sn_rd_u16(r + 4), r[1], &segs, &nodes);
        v->segB += SN_SEG_SEG_BYTES * segs + SN_SEG_NODE_BYTES * nodes;
    }
}

/* ---- accessors of a validated blob (NULL blob -> neutral answer) ---- */

void sn_blob_get_info(const sn_blob *blob, sn_blob_info *info) {
    sn_view v;
    if (!info) return;
    memset(info, 0, sizeof *info);
    if (!blob) return;
    sn_view_init(&v, blob);
    info->vertices = v.nV;
    info->free_vertices = v.nF;
    info->cells = v.nC;
    info->joints = v.nJ;
    info->surface_vertices = v.nS;
    info->triangles = v.nT;
    info->offdiag_blocks = v.nnz;
    info->cg_iters_default = v.cg_default;
    info->cg_iters_max = v.cg_max;
    info->instance_bytes = v.instance_bytes + sn_adapt_bytes(&v) + sn_detail_bytes(&v); /* == sn_instance_size */
    info->blob_bytes = v.total;
    info->timestep = v.timestep;
    info->controls = v.nK;
    info->rigs = v.nR;
    info->rig_entries = v.nRE;
    info->force_slots = v.nFrc;
    info->force_profiles = v.nP;
    info->max_constraints = v.nCon;
    info->max_colliders = v.nCol;
    info->max_contacts = v.nCt;
    info->max_rows = v.nRows;
}

static const unsigned char *sn_section(const sn_blob *blob, int k) {
    const unsigned char *p = sn_bytes(blob);
    return p + sn_rd_u32(p + SN_H_SECTIONS + k * SN_SECTION_ENTRY);
}

static uint32_t sn_njoints(const sn_blob *blob) {
    return sn_rd_u32(sn_bytes(blob) + SN_H_N_JOINTS);
}

const char *sn_joint_name(const sn_blob *blob, uint32_t j) {
    if (!blob || j >= sn_njoints(blob)) return NULL;
    return (const char *)(sn_section(blob, SN_SEC_JOINT_NAMES) + (size_t)j * SN_JOINT_NAME_MAX);
}

int32_t sn_joint_parent(const sn_blob *blob, uint32_t j) {
    uint32_t par;
    if (!blob || j >= sn_njoints(blob)) return -1;
    par = sn_rd_u16(sn_section(blob, SN_SEC_JOINTS) + (size_t)j * SN_ELEM_JOINTS(SN_REAL_BYTES));
    return par == 0xFFFFu ? -1 : (int32_t)par;
}

/* Internal Q22 (internal units) -> public Q16.16 mesh units:
 * public = internal * 2^(len_shift - 6). Exact when len_shift >= 6 (then
 * never saturating: the validator bounds public rest values to 2^30);
 * rounded to nearest (ties toward +infinity, sn_rshr64) otherwise.
 * Float: multiplied by 2^len_shift (exact). */
sn_status sn_joint_rest(const sn_blob *blob, uint32_t j, sn_vec3 *out) {
    const unsigned char *e;
    sn_real r[3];
    int k, ls;
    if (!blob || !out) return SN_ERR_NULL;
    if (j >= sn_njoints(blob)) return SN_ERR_ARG;
    e = sn_section(blob, SN_SEC_JOINTS) + (size_t)j * SN_ELEM_JOINTS(SN_REAL_BYTES) + 8;
    ls = sn_bytes(blob)[SN_H_LEN_SHIFT];
    if (ls >= 128) ls -= 256;
    for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
        float x = sn_rd_f32(e + 4 * k), f = ls >= 0 ? 2.0f : 0.5f;
        int i, n = ls >= 0 ? ls : -ls;
        for (i = 0; i < n; i++) x *= f;
        r[k] = x;
#else
        int64_t x = sn_rd_i32(e + 4 * k);
        int sh = ls - (SN_Q_LEN - SN_LEN_FRAC);
        x = sh >= 0 ? x * ((int64_t)1 << sh) : sn_rshr64(x, -sh);
        r[k] = (int32_t)(x > INT32_MAX ? INT32_MAX : (x < -INT32_MAX ? -INT32_MAX : x));
#endif
    }
    out->x = r[0];
    out->y = r[1];
    out->z = r[2];
    return SN_OK;
}

int32_t sn_find_joint(const sn_blob *blob, const char *name) {
    const unsigned char *names;
    uint32_t j, n, k;
    if (!blob || !name) return -1;
    n = sn_njoints(blob);
    names = sn_section(blob, SN_SEC_JOINT_NAMES);
    for (j = 0; j < n; j++) {
        const unsigned char *s = names + (size_t)j * SN_JOINT_NAME_MAX;
        /* stored names are NUL-terminated within 32 bytes (validated) */
        for (k = 0; s[k] && s[k] == (unsigned char)name[k]; k++) {}
        if (s[k] == (unsigned char)name[k]) return (int32_t)j;
    }
    return -1;
}

sn_status sn_get_triangle(const sn_blob *blob, uint32_t t, uint32_t idx[3]) {
    const unsigned char *p;
    if (!blob || !idx) return SN_ERR_NULL;
    if (t >= sn_rd_u32(sn_bytes(blob) + SN_H_N_TRIANGLES)) return SN_ERR_ARG;
    p = sn_section(blob, SN_SEC_TRIS) + (size_t)t * SN_ELEM_TRIS;
    idx[0] = sn_rd_u16(p);
    idx[1] = sn_rd_u16(p + 2);
    idx[2] = sn_rd_u16(p + 4);
    return SN_OK;
}

size_t sn_instance_size(const sn_blob *blob) {
    sn_view v;
    if (!blob) return 0;
    sn_view_init(&v, blob);
    return (size_t)v.instance_bytes + sn_adapt_bytes(&v) + sn_detail_bytes(&v); /* adaptation's mask, then the details' seats (sn_detail_step.c) */
}
