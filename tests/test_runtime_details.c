/* test_runtime_details.c -- the cut level's details (format 6.5: DETAILS, DETAIL,
 * CELLD, CELLDK; runtime/LEVELS.md §3 "Details on the cut level"), fixed or float:
 *
 * 1. the cow's cut level baked with and without 'details 50 0.03 0.01' has the
 *    same bytes in every section before the details' (the details add columns to
 *    the cut element, never change its corner or extra blocks), and both step the
 *    same state hash over the violent swing (no detail is active in this runtime:
 *    what stage 2's "none active" must keep); every detail's rest point is its
 *    cell's dyadic point of REST (one Q22 step; float 1e-6 of a cell);
 * 2. the validator on the limb's cut blob with 'details 8 0.03 0.01' (the fuzzers'
 *    seed): every crafted change to the four sections refused with its status,
 *    the checksum fixed after each.
 * 3. stage 2's cell product (sn_detail_cell_mul) on the cow's details blob:
 *    every cell with details, random operands, every detail active and a
 *    random half, against the cell's dense local matrix assembled here in
 *    double from CELLDK's blocks (detail rows, and the corner rows through
 *    the transposed blocks; the detail-detail blocks below the diagonal as
 *    the transposes), and the mass product (sn_detail_cell_mass, CELLDK's
 *    scalar masses, symmetric) likewise. Bounds (of each row's sum of |terms|): fixed 1e-14
 *    (the kernel is exact in int64; the double reference rounds <= 81
 *    products of <= 2^57 at 2^-53 each), float 1e-5 (<= 81 float additions,
 *    2^-24 of the partial sum each: 81 * 6e-8 = 4.8e-6). */
#include "sinew.h"
#include "sn_format.h"
#include "sn_test.h"
#include "fuzz/sn_tblob.h"
#include "level_util.h"
#include "sn_instance.h" /* sn_view_init: the kernel under test reads the validated view */
#include "sn_detail.h"   /* sn_detail_cell_mul */

#if defined(SN_FLOAT)
#define SN_TB_SUFFIX "_float"
#else
#define SN_TB_SUFFIX ""
#endif

static uint32_t rd16(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8; }
static uint32_t sec_at(const unsigned char *b, int k, int f) { return tb_rd32(b + SN_H_SECTIONS + SN_SECTION_ENTRY * (uint32_t)k + 4u * (uint32_t)f); }

static const char *path(const char *name, char *buf, size_t n)
{
    snprintf(buf, n, "%s/level/%s", getenv("BUILD") ? getenv("BUILD") : "build", name);
    return buf;
}

/* a stored real as a double in internal units (fixed Q22) */
static double real_of(const unsigned char *p)
{
#if defined(SN_FLOAT)
    float f;
    memcpy(&f, p, 4);
    return (double)f;
#else
    return ldexp((double)(int32_t)tb_rd32(p), -22);
#endif
}

/* every DETAIL's rest point is the dyadic point of its cell's corners (REST): within one Q22 step (fixed: the
 * corners' and the detail's rounding) or 1e-6 of the cell (float); the largest difference in cells */
static double rest_points(const unsigned char *b, int *bad)
{
    uint32_t nd = sec_at(b, SN_SEC_DETAIL, 2), i, k, a, de = (uint32_t)SN_ELEM_DETAIL(4);
    const unsigned char *dr = b + sec_at(b, SN_SEC_DETAIL, 0), *cl = b + sec_at(b, SN_SEC_CELLS, 0), *rest = b + sec_at(b, SN_SEC_REST, 0);
    double worst = 0, cell = real_of(b + SN_H_REALS + 4 * SN_R_CELL);
    *bad = 0;
    for (i = 0; i < nd; i++) {
        const unsigned char *d = dr + (size_t)i * de;
        uint32_t c = rd16(d), pt = d[2], u[3] = {pt % 3, pt / 3 % 3, pt / 9};
        for (k = 0; k < 3; k++) {
            double want = 0;
            for (a = 0; a < 8; a++) {
                double w = 1;
                uint32_t q;
                for (q = 0; q < 3; q++) w *= (a >> q & 1) ? 0.5 * u[q] : 1 - 0.5 * u[q];
                if (w != 0) want += w * real_of(rest + 12u * rd16(cl + (size_t)c * SN_ELEM_CELLS + 2 * a) + 4 * k);
            }
            worst = fmax(worst, fabs(real_of(d + 4 + 4 * k) - want) / cell);
#if defined(SN_FLOAT)
            *bad += fabs(real_of(d + 4 + 4 * k) - want) > 1e-6 * cell;
#else
            *bad += fabs(real_of(d + 4 + 4 * k) - want) > ldexp(1.0, -22);
#endif
        }
    }
    return worst;
}

/* 1. with and without the details: the same sections, the same steps */
static void same_cut(void)
{
    char p0[600], p1[600];
    size_t n0, n1;
    unsigned char *b0 = load(path("cow_cut" SN_TB_SUFFIX ".blob", p0, sizeof p0), &n0), *b1 = load(path("cow_details" SN_TB_SUFFIX ".blob", p1, sizeof p1), &n1);
    const sn_blob *c0 = NULL, *c1 = NULL;
    sn_blob_info i0, i1;
    void *m0 = NULL, *m1 = NULL;
    sn_instance *s0, *s1;
    sn_xform *xf;
    int k, same = 1, steps = 48, diff = -1;
    if (!b0 || !b1) { T_CHECK(0, "cannot read %s / %s (tests/level.mk)", p0, p1); free(b0); free(b1); return; }
    T_CHECK(sn_blob_validate(b0, n0, &c0) == SN_OK && sn_blob_validate(b1, n1, &c1) == SN_OK, "[%s] cow cut / details blobs validate", FL);
    if (!c0 || !c1) { free(b0); free(b1); return; }
    T_CHECK(sec_at(b0, SN_SEC_DETAILS, 2) == 0 && sec_at(b1, SN_SEC_DETAILS, 2) == 1 && sec_at(b1, SN_SEC_DETAIL, 2) > 0,
            "[%s] the details blob has them (%u details), the cut blob not", FL, sec_at(b1, SN_SEC_DETAIL, 2));
    for (k = 0; k < SN_SEC_DETAILS; k++) {
        uint32_t sz = sec_at(b0, k, 1);
        if (sz != sec_at(b1, k, 1) || memcmp(b0 + sec_at(b0, k, 0), b1 + sec_at(b1, k, 0), sz) != 0) { same = 0; break; }
    }
    T_CHECK(same, "[%s] every section before the details' is the cut blob's, byte for byte (first differing: %d)", FL, same ? -1 : k);
    {
        int bad = 0;
        double w = rest_points(b1, &bad);
        T_CHECK(bad == 0, "[%s] cow: every detail's rest point is its cell's dyadic point (%d coordinates off; worst %.2g cell)", FL, bad, w);
    }
    T_FIGURE("[%s] cow details: %u details, %u CELLDK elements (%u bytes), dshift %u; blob %lu -> %lu bytes", FL, sec_at(b1, SN_SEC_DETAIL, 2),
             sec_at(b1, SN_SEC_CELLDK, 2), sec_at(b1, SN_SEC_CELLDK, 1), b1[sec_at(b1, SN_SEC_DETAILS, 0) + 2], (unsigned long)n0,
             (unsigned long)n1);
    sn_blob_get_info(c0, &i0);
    sn_blob_get_info(c1, &i1); /* the details' seats make its instance larger (sn_detail_step.c) */
    T_CHECK(i1.instance_bytes > i0.instance_bytes && sn_instance_size(c1) == i1.instance_bytes &&
                sn_instance_state_size(c1) - sn_instance_state_size(c0) == i1.instance_bytes - i0.instance_bytes,
            "[%s] the details' seats: %lu more instance bytes (state size alike)", FL, (unsigned long)(i1.instance_bytes - i0.instance_bytes));
    m0 = malloc(i0.instance_bytes); m1 = malloc(i1.instance_bytes);
    xf = malloc(sizeof *xf * i0.joints);
    if (sn_instance_init(m0, i0.instance_bytes, c0, &s0) != SN_OK || sn_instance_init(m1, i1.instance_bytes, c1, &s1) != SN_OK) {
        T_CHECK(0, "[%s] instances", FL);
    } else {
        for (k = 1; k <= steps && diff < 0; k++) {
            pose_at(c0, i0.joints, k, xf);
            sn_set_pose(s0, xf, i0.joints); sn_set_pose(s1, xf, i0.joints);
            sn_step(s0); sn_step(s1);
            if (sn_state_hash(s0) != sn_state_hash(s1)) diff = k;
        }
        T_CHECK(diff < 0, "[%s] the cow's cut level with its details baked steps the cut level's bits (%d swing steps; first differing %d)",
                FL, steps, diff);
    }
    free(xf); free(m0); free(m1); free(b0); free(b1);
}

/* 2. the validator */
static void crafted(void)
{
    char p[600];
    size_t n;
    unsigned char *bb = load(path("limb_cut" SN_TB_SUFFIX ".blob", p, sizeof p), &n), *h, *hd, *dr, *cd, *dk, *cx;
    const sn_blob *out;
    uint32_t nd, nc, e, slot = 0, xslot = 0, kb = (uint32_t)SN_ELEM_CELLDK(SN_FLAVOUR, 4), de = (uint32_t)SN_ELEM_DETAIL(4), own = 0, ncases = 0;
    if (!bb) { T_CHECK(0, "cannot read %s (tests/level.mk)", p); return; }
    T_CHECK(sn_blob_validate(bb, n, &out) == SN_OK, "[%s] limb cut blob with details validates", FL);
    nd = sec_at(bb, SN_SEC_DETAIL, 2); nc = sec_at(bb, SN_SEC_CELLD, 2);
    T_CHECK(nd > 0 && sec_at(bb, SN_SEC_DETAILS, 2) == 1, "[%s] limb: %u details", FL, nd);
    if (nd == 0) { free(bb); return; }
    h = malloc(n + 8);
    /* a cell with a detail and an extra: its first detail's slot, an extra's slot */
    cd = bb + sec_at(bb, SN_SEC_CELLD, 0); cx = bb + sec_at(bb, SN_SEC_CELLX, 0);
    for (e = 0; e < nc; e++) if (cd[e * SN_ELEM_CELLD + 38] && cx[e * SN_ELEM_CELLX + 38]) break;
    T_CHECK(e < nc, "[%s] limb: a cell with a detail and an extra", FL);
    if (e == nc) { free(h); free(bb); return; }
    while (rd16(cd + e * SN_ELEM_CELLD + 2 * slot) == SN_CUT_NONE) slot++;
    while (rd16(cx + e * SN_ELEM_CELLX + 2 * xslot) == SN_CUT_NONE) xslot++;
    /* cell e's first detail's own block: after its 8 + nx columns */
    own = tb_rd32(cd + e * SN_ELEM_CELLD + 40) + 8u + cx[e * SN_ELEM_CELLX + 38];
#define D_CASE(want, what, change) do { \
        memcpy(h, bb, n); hd = h + sec_at(h, SN_SEC_DETAILS, 0); dr = h + sec_at(h, SN_SEC_DETAIL, 0); \
        cd = h + sec_at(h, SN_SEC_CELLD, 0); dk = h + sec_at(h, SN_SEC_CELLDK, 0); cx = h + sec_at(h, SN_SEC_CELLX, 0); \
        (void)hd; (void)dr; (void)cd; (void)dk; (void)cx; \
        change; tb_fix_crc(h); ncases++; \
        T_CHECK(sn_blob_validate(h, n, &out) == (want), "[%s] details: %s: got %s, want %s", FL, what, \
                sn_status_str(sn_blob_validate(h, n, &out)), sn_status_str(want)); } while (0)
    D_CASE(SN_OK, "unchanged", (void)0);
    D_CASE(SN_OK, "A_max = nD", tb_u16(hd, nd));
    D_CASE(SN_ERR_VALUE, "A_max = nD + 1", tb_u16(hd, nd + 1));
    D_CASE(SN_ERR_VALUE, "DETAILS pad byte", hd[3] = 1);
    D_CASE(SN_ERR_VALUE, "DETAILS pad word", hd[5] = 1);
#if defined(SN_FLOAT)
    D_CASE(SN_ERR_VALUE, "dshift 1 (float)", hd[2] = 1);
    D_CASE(SN_ERR_VALUE, "refine NaN", tb_u32(hd + 8, 0x7FC00000u));
    D_CASE(SN_ERR_VALUE, "a block entry 2^28", tb_u32(dk, 0x4D800000u));
    D_CASE(SN_ERR_VALUE, "a mass 2^28", tb_u32(dk + 36, 0x4D800000u));
    D_CASE(SN_ERR_VALUE, "a detail's own mass 0", tb_u32(dk + (size_t)own * kb + 36, 0));
#else
    D_CASE(SN_OK, "dshift 4", hd[2] = 4);
    D_CASE(SN_ERR_VALUE, "dshift 5", hd[2] = 5);
    D_CASE(SN_ERR_VALUE, "refine 2^30 + 1", tb_u32(hd + 8, (1u << 30) + 1u));
    D_CASE(SN_ERR_VALUE, "a block exponent 13", dk[18] = 13);
    D_CASE(SN_ERR_VALUE, "a mantissa -2^15", tb_u16(dk, 0x8000u));
    D_CASE(SN_ERR_VALUE, "a block pad byte", dk[19] = 1);
    D_CASE(SN_ERR_VALUE, "a mass 2^27 + 1", tb_u32(dk + 20, (1u << 27) + 1u));
    D_CASE(SN_ERR_VALUE, "a detail's own mass 0", tb_u32(dk + (size_t)own * kb + 20, 0));
    D_CASE(SN_OK, "another element's mass 0", tb_u32(dk + 20, 0));
#endif
    D_CASE(SN_ERR_VALUE, "coarsen above refine", tb_u32(hd + 8 + 4, tb_rd32(hd + 8) + 1u));
    D_CASE(SN_ERR_INDEX, "DETAIL cell nC", tb_u16(dr, nc));
    D_CASE(SN_ERR_INDEX, "DETAIL point a corner", dr[2] = 0);
    D_CASE(SN_ERR_INDEX, "DETAIL point 27", dr[2] = 27);
    D_CASE(SN_ERR_INDEX, "DETAIL pad byte", dr[3] = 1);
    D_CASE(SN_ERR_INDEX, "DETAIL naming another detail's place", tb_u16(dr, rd16(dr + de)); dr[2] = dr[de + 2]);
#if defined(SN_FLOAT)
    D_CASE(SN_ERR_VALUE, "DETAIL rest 2^28 (beyond REST's bound)", tb_u32(dr + 4, 0x4D800000u));
#else
    D_CASE(SN_ERR_VALUE, "DETAIL rest 2^31 - 1 (beyond REST's bound)", tb_u32(dr + 4, 0x7FFFFFFFu));
#endif
    D_CASE(SN_ERR_INDEX, "CELLD entry nD", tb_u16(cd + e * SN_ELEM_CELLD + 2 * slot, nd));
    D_CASE(SN_ERR_INDEX, "CELLD entry where CELLX has an extra",
           (tb_u16(cd + e * SN_ELEM_CELLD + 2 * xslot, rd16(cd + e * SN_ELEM_CELLD + 2 * slot)),
            tb_u16(cd + e * SN_ELEM_CELLD + 2 * slot, SN_CUT_NONE)));
    D_CASE(SN_ERR_VALUE, "CELLD nd one short", cd[e * SN_ELEM_CELLD + 38]--);
    D_CASE(SN_ERR_VALUE, "CELLD pad byte", cd[e * SN_ELEM_CELLD + 39] = 1);
    D_CASE(SN_ERR_INDEX, "CELLD first off the running sum", cd[(nc - 1) * SN_ELEM_CELLD + 40]++);
    {   /* refused by whichever check meets it first: the cell's blocks then read a corner column as a detail's own
         * mass (not > 0: VALUE), or the later cells' first is off the sum (INDEX; SECTION for the last cell) */
        sn_status st;
        memcpy(h, bb, n); cd = h + sec_at(h, SN_SEC_CELLD, 0);
        tb_u16(cd + e * SN_ELEM_CELLD + 2 * slot, SN_CUT_NONE); cd[e * SN_ELEM_CELLD + 38]--;
        tb_fix_crc(h); ncases++;
        st = sn_blob_validate(h, n, &out);
        T_CHECK(st == SN_ERR_VALUE || st == SN_ERR_INDEX || st == SN_ERR_SECTION, "[%s] details: a CELLD entry dropped: got %s, want refused",
                FL, sn_status_str(st));
    }
    D_CASE(SN_ERR_SECTION, "CELLD count 1", tb_u32(h + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_CELLD + 8, 1));
#undef D_CASE
    T_FIGURE("[%s] limb: %u details, %u crafted cases", FL, nd, ncases);
    free(h); free(bb);
}

/* 3. the cell product */
static unsigned long long rng3 = 99;
static double rnd3(void) { rng3 = rng3 * 6364136223846793005ULL + 1442695040888963407ULL; return (double)(rng3 >> 11) / 9007199254740992.0 - 0.5; }
/* a CELLDK entry in the kernel's units: fixed m 2^e (the integer the kernel sums), float the real */
static double blk_of(const unsigned char *b, int k)
{
#if defined(SN_FLOAT)
    return real_of(b + 4 * k);
#else
    return ldexp((double)(int16_t)rd16(b + 2 * k), b[18]);
#endif
}
static void cell_product(void)
{
    char p1[600];
    size_t n1;
    unsigned char *b = load(path("cow_details" SN_TB_SUFFIX ".blob", p1, sizeof p1), &n1);
    const sn_blob *c1 = NULL;
    sn_view v;
    const size_t KB = (size_t)SN_ELEM_CELLDK(SN_FLAVOUR, 4);
    uint32_t e, nc, cells = 0, rows = 0, sat = 0, pass;
    double worst = 0, mworst = 0;
    int ds;
    if (!b || sn_blob_validate(b, n1, &c1) != SN_OK) { T_CHECK(0, "[%s] cannot read/validate %s", FL, p1); free(b); return; }
    sn_view_init(&v, c1);
    nc = sec_at(b, SN_SEC_CELLS, 2);
    ds = b[sec_at(b, SN_SEC_DETAILS, 0) + 2];
    for (e = 0; e < nc; e++) {
        const unsigned char *cd = b + sec_at(b, SN_SEC_CELLD, 0) + (size_t)e * SN_ELEM_CELLD, *cx = b + sec_at(b, SN_SEC_CELLX, 0) + (size_t)e * SN_ELEM_CELLX;
        const unsigned char *K = b + sec_at(b, SN_SEC_CELLDK, 0) + (size_t)tb_rd32(cd + 40) * KB;
        uint32_t nd = cd[38], nx = cx[38], nl = 8 + nx + nd, j, c, i, q, r, on;
        static double D[81][81], Mm[27][27];
        if (nd == 0) continue;
        cells++;
        memset(D, 0, sizeof D); memset(Mm, 0, sizeof Mm);
        for (j = 0; j < nd; j++)   /* detail j's run: corners, extras, details k >= j */
            for (c = 0; c < 8 + nx + nd - j; c++, K += KB) {
                uint32_t col = c < 8 + nx ? c : c + j, row = 8 + nx + j;
                for (i = 0; i < 3; i++)
                    for (q = 0; q < 3; q++) {
                        D[3 * col + q][3 * row + i] = blk_of(K, (int)(3 * i + q));   /* the mirror first: the block itself wins on (j, j) */
                    }
                for (i = 0; i < 3; i++)
                    for (q = 0; q < 3; q++) D[3 * row + i][3 * col + q] = blk_of(K, (int)(3 * i + q));
#if defined(SN_FLOAT)
                Mm[row][col] = Mm[col][row] = real_of(K + 36);
#else
                Mm[row][col] = Mm[col][row] = ldexp((double)(int32_t)tb_rd32(K + 20), 0);
#endif
            }
        for (pass = 0; pass < 2; pass++) {
            sn_q yc[24], yx[SN_CUT_MAXX][3], yd[SN_CUT_MAXX][3], y[81];
            sn_acc lc[24], ld[3 * SN_CUT_MAXX], mc[24], md[3 * SN_CUT_MAXX];
            on = pass == 0 ? (1u << nd) - 1u : (uint32_t)(rnd3() * 1048576.0 + 524288.0) & ((1u << nd) - 1u);
            for (i = 0; i < 3 * nl; i++) {
#if defined(SN_FLOAT)
                y[i] = (sn_q)(32.0 * rnd3());
#else
                y[i] = (sn_q)(134217728.0 * rnd3());   /* +-2^26: 16 internal units, Q22 */
#endif
            }
            for (i = 0; i < 24; i++) { yc[i] = y[i]; lc[i] = mc[i] = 0; }
            for (j = 0; j < nx; j++) for (q = 0; q < 3; q++) yx[j][q] = y[24 + 3 * j + q];
            for (j = 0; j < nd; j++) for (q = 0; q < 3; q++) yd[j][q] = y[3 * (8 + nx + j) + q];
            sn_detail_cell_mul(&v, e, on, yc, (const sn_q(*)[3])yx, (const sn_q(*)[3])yd, lc, ld, &sat);
            sn_detail_cell_mass(&v, e, on, yc, (const sn_q(*)[3])yx, (const sn_q(*)[3])yd, mc, md);
            for (r = 0; r < 3 * (8 + nd); r++) {   /* the mass: scalar blocks, the same rows */
                uint32_t row = r < 24 ? r / 3 : 8 + nx + (r - 24) / 3, dj = r < 24 ? 0 : (r - 24) / 3;
                double want = 0, mag = 0, got = r < 24 ? (double)mc[r] : (double)md[r - 24];
                if (r >= 24 && !(on >> dj & 1u)) { mworst = fmax(mworst, got != 0 ? 1.0 : 0.0); continue; }
                for (c = 0; c < nl; c++) {
                    double t;
                    if (c >= 8 + nx && !(on >> (c - 8 - nx) & 1u)) continue;
                    if (r < 24 && c < 8 + nx) continue;
                    t = Mm[row][c] * (double)y[3 * c + r % 3];
                    want += t; mag += fabs(t);
                }
                if (mag > 0) mworst = fmax(mworst, fabs(got - want) / mag);
            }
            for (r = 0; r < 3 * (8 + nd); r++) {   /* corner rows 0..23, then the details' */
                uint32_t row = r < 24 ? r : 3 * (8 + nx) + (r - 24), dj = r < 24 ? 0 : (r - 24) / 3;
                double want = 0, mag = 0, got;
                if (r >= 24 && !(on >> dj & 1u)) { worst = fmax(worst, ld[r - 24] != 0 ? 1.0 : 0.0); continue; }
                for (c = 0; c < 3 * nl; c++) {
                    uint32_t lc_ = c / 3;
                    double t;
                    if (lc_ >= 8 + nx && !(on >> (lc_ - 8 - nx) & 1u)) continue;   /* inactive detail: no column */
                    if (r < 24 && lc_ < 8 + nx) continue;   /* corner rows: only the details' columns */
                    t = D[row][c] * (double)y[c];
                    want += t; mag += fabs(t);
                }
                got = r < 24 ? (double)lc[r] : (double)ld[r - 24];
#if !defined(SN_FLOAT)
                if (r < 24) { want = ldexp(want, ds); mag = ldexp(mag, ds); }
#endif
                if (mag > 0) worst = fmax(worst, fabs(got - want) / mag);
                rows++;
            }
        }
    }
    T_FIGURE("[%s] cow: the details' cell product on %u cells (every detail, a random half), %u rows: worst %.3g of the row's sum of |terms| "
             "(dshift %d); mass %.3g", FL, cells, rows, worst, ds, mworst);
#if defined(SN_FLOAT)
    T_CHECK(cells > 0 && worst <= 1e-5 && sat == 0, "[%s] the details' cell product vs the dense double product: %.3g (want <= 1e-5)", FL, worst);
    T_CHECK(mworst <= 1e-5, "[%s] the details' mass product vs the dense double product: %.3g (want <= 1e-5)", FL, mworst);
#else
    T_CHECK(cells > 0 && worst <= 1e-14 && sat == 0, "[%s] the details' cell product vs the dense double product: %.3g (want <= 1e-14)", FL, worst);
    T_CHECK(mworst <= 1e-14, "[%s] the details' mass product vs the dense double product: %.3g (want <= 1e-14)", FL, mworst);
#endif
    free(b);
}

/* 4. the surface's detail term: every surface vertex of the cow, a random half of the details active with
 * random coefficients, against the child's trilinear weights in double times the coefficients at the child's
 * corners that are active details (the slot: the point's rank among the 19 non-corner points). Bound: the
 * kernel's weights are sn_trilinear's (fixed Q30, <= 2 LSB each: 8 * 2^-29 of the largest coefficient; float
 * 1e-6 of it: 8 weights of float rounding 6e-8 plus their products' ). */
static void surface_term(void)
{
    char p1[600];
    size_t n1;
    unsigned char *b = load(path("cow_details" SN_TB_SUFFIX ".blob", p1, sizeof p1), &n1);
    const sn_blob *c1 = NULL;
    sn_view v;
    uint32_t nd, ns, s2, k, q, with = 0, slot_of[27];
    uint16_t *seat;
    sn_q *coef;
    double worst = 0, cmax = 0;
    if (!b || sn_blob_validate(b, n1, &c1) != SN_OK) { T_CHECK(0, "[%s] cannot read/validate %s", FL, p1); free(b); return; }
    sn_view_init(&v, c1);
    nd = sec_at(b, SN_SEC_DETAIL, 2); ns = sec_at(b, SN_SEC_EMBED, 2);
    for (k = 0, q = 0; k < 27; k++) slot_of[k] = (k % 3 != 1 && k / 3 % 3 != 1 && k / 9 != 1) ? 255u : q++;
    seat = malloc(sizeof *seat * nd); coef = malloc(sizeof *coef * 3 * nd);
    for (k = 0; k < nd; k++) {
        seat[k] = rnd3() < 0 ? (uint16_t)k : (uint16_t)0xFFFFu;
        for (q = 0; q < 3; q++) {
#if defined(SN_FLOAT)
            coef[3 * k + q] = (sn_q)(32.0 * rnd3());
#else
            coef[3 * k + q] = (sn_q)(134217728.0 * rnd3());
#endif
            cmax = fmax(cmax, fabs((double)coef[3 * k + q]));
        }
    }
    for (s2 = 0; s2 < ns; s2++) {
        const unsigned char *e = b + sec_at(b, SN_SEC_EMBED, 0) + (size_t)s2 * SN_ELEM_EMBED;
        uint32_t cell = rd16(e), t[3], up[3], any = 0;
        const unsigned char *cd = b + sec_at(b, SN_SEC_CELLD, 0) + (size_t)cell * SN_ELEM_CELLD;
        double want[3] = {0, 0, 0}, tc[3];
        sn_acc acc[3] = {0, 0, 0};
        for (q = 0; q < 3; q++) {
            t[q] = rd16(e + 2 + 2 * q);
            up[q] = t[q] >= 16384u;
            tc[q] = (2.0 * t[q] - 32768.0 * up[q]) / 32768.0;
        }
        for (k = 0; k < 8; k++) {
            uint32_t p = (up[0] + (k & 1u)) + 3u * (up[1] + (k >> 1 & 1u)) + 9u * (up[2] + (k >> 2 & 1u)), d;
            double w = 1;
            for (q = 0; q < 3; q++) w *= (k >> q & 1u) ? tc[q] : 1 - tc[q];
            if (slot_of[p] == 255u || (d = rd16(cd + 2 * slot_of[p])) == 0xFFFFu || seat[d] == 0xFFFFu) continue;
            any = 1;
            for (q = 0; q < 3; q++) want[q] += w * (double)coef[3 * seat[d] + q];
        }
        with += any;
        sn_detail_interp(&v, cell, t, seat, coef, acc);
        for (q = 0; q < 3; q++) {
#if defined(SN_FLOAT)
            double got = (double)acc[q];
#else
            double got = ldexp((double)acc[q], -30);
#endif
            worst = fmax(worst, fabs(got - want[q]) / cmax);
        }
    }
    T_FIGURE("[%s] cow: the surface's detail term at %u surface vertices (%u with an active detail in their child): worst %.3g of the "
             "largest coefficient", FL, ns, with, worst);
#if defined(SN_FLOAT)
    T_CHECK(with > 0 && worst <= 1e-6, "[%s] the surface's detail term vs double: %.3g (want <= 1e-6)", FL, worst);
#else
    T_CHECK(with > 0 && worst <= 8.0 / 536870912.0, "[%s] the surface's detail term vs double: %.3g (want <= 8 2^-29)", FL, worst);
#endif
    free(seat); free(coef); free(b);
}

int main(void)
{
    (void)t_seed; (void)cell_of; (void)tb_build;
    same_cut();
    crafted();
    cell_product();
    surface_term();
    return T_END();
}
