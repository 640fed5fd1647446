/* snref.c -- double-precision reference of runtime/NUMERICS.md (blob format 3.0:
 * format 2.0's step plus rig controls and forces).
 * Shares no arithmetic with the runtime: only sn_format.h constants. Host-tool
 * code since sinew-bake --static solves with it; the tests use it as their reference. */
#include "snref.h"
#include "../../runtime/src/sn_format.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct snref_band snref_band;
static snref_band *band_build(snref_state *s, int which, double reg, size_t max_doubles);
static void band_solve(const snref_band *B, const double *r, double *x);
static void band_free(snref_band *B);
static double sscale(const snref_state *s);

/* ---------------- small linear algebra ---------------- */

static void mat_vec(const double A[9], const double x[3], double y[3]) {
    y[0] = A[0] * x[0] + A[1] * x[1] + A[2] * x[2];
    y[1] = A[3] * x[0] + A[4] * x[1] + A[5] * x[2];
    y[2] = A[6] * x[0] + A[7] * x[1] + A[8] * x[2];
}
static void matT_vec(const double A[9], const double x[3], double y[3]) {
    y[0] = A[0] * x[0] + A[3] * x[1] + A[6] * x[2];
    y[1] = A[1] * x[0] + A[4] * x[1] + A[7] * x[2];
    y[2] = A[2] * x[0] + A[5] * x[1] + A[8] * x[2];
}
static int mat_inv(const double A[9], double B[9]) {
    double d = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6])
             + A[2] * (A[3] * A[7] - A[4] * A[6]);
    if (d == 0.0) return -1;
    B[0] = (A[4] * A[8] - A[5] * A[7]) / d; B[1] = (A[2] * A[7] - A[1] * A[8]) / d; B[2] = (A[1] * A[5] - A[2] * A[4]) / d;
    B[3] = (A[5] * A[6] - A[3] * A[8]) / d; B[4] = (A[0] * A[8] - A[2] * A[6]) / d; B[5] = (A[2] * A[3] - A[0] * A[5]) / d;
    B[6] = (A[3] * A[7] - A[4] * A[6]) / d; B[7] = (A[1] * A[6] - A[0] * A[7]) / d; B[8] = (A[0] * A[4] - A[1] * A[3]) / d;
    return 0;
}
static double dot(const double *a, const double *b, unsigned n) {
    double r = 0;
    unsigned i;
    for (i = 0; i < n; i++) r += a[i] * b[i];
    return r;
}

/* ---------------- quaternions ---------------- */

void snref_quat_axis_angle(const double axis[3], double deg, double q[4]) {
    double n = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    double a = deg * (3.14159265358979323846 / 180.0) * 0.5, s = sin(a) / n;
    q[0] = axis[0] * s; q[1] = axis[1] * s; q[2] = axis[2] * s; q[3] = cos(a);
}
void snref_quat_mul(const double a[4], const double b[4], double o[4]) {
    double r[4];
    r[0] = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    r[1] = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    r[2] = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    r[3] = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
    memcpy(o, r, sizeof r);
}
/* Slerp of unit-normalized a, b; shorter = 1: always the shorter arc; 0:
 * along the path a -> b unless a.b < -cos 30 deg (NUMERICS step 2). Sin
 * formula; linear blend when nearly parallel. */
static void slerp_(const double ai[4], const double bi[4], double t, int shorter, double o[4]) {
    double a[4], b[4], na = 0, nb = 0, d = 0, wa, wb, n;
    int k;
    for (k = 0; k < 4; k++) { na += ai[k] * ai[k]; nb += bi[k] * bi[k]; }
    na = sqrt(na); nb = sqrt(nb);
    for (k = 0; k < 4; k++) { a[k] = ai[k] / na; b[k] = bi[k] / nb; d += a[k] * b[k]; }
    if (d < 0 && (shorter || d < -0.86602540378443865)) {
        for (k = 0; k < 4; k++) b[k] = -b[k];
        d = -d;
    }
    if (d > 1.0 - 1e-12) { wa = 1.0 - t; wb = t; }
    else {
        double th = acos(d), st = sin(th);
        wa = sin((1.0 - t) * th) / st; wb = sin(t * th) / st;
    }
    for (k = 0; k < 4; k++) o[k] = wa * a[k] + wb * b[k];
    n = sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2] + o[3] * o[3]);
    for (k = 0; k < 4; k++) o[k] /= n;
}
void snref_quat_slerp(const double a[4], const double b[4], double t, double o[4]) { slerp_(a, b, t, 1, o); }
void snref_quat_slerp_path(const double a[4], const double b[4], double t, double o[4]) { slerp_(a, b, t, 0, o); }
/* Normalizes first, so a quantized input quaternion gives an orthonormal R. */
void snref_quat_to_mat(const double qi[4], double R[9]) {
    double n = sqrt(qi[0] * qi[0] + qi[1] * qi[1] + qi[2] * qi[2] + qi[3] * qi[3]);
    double x = qi[0] / n, y = qi[1] / n, z = qi[2] / n, w = qi[3] / n;
    R[0] = 1 - 2 * (y * y + z * z); R[1] = 2 * (x * y - w * z); R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z); R[4] = 1 - 2 * (x * x + z * z); R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y); R[7] = 2 * (y * z + w * x); R[8] = 1 - 2 * (x * x + y * y);
}

/* ---------------- blob reader ---------------- */

static uint32_t rd_u32(const unsigned char *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static unsigned rd_u16(const unsigned char *p) { return (unsigned)p[0] | (unsigned)p[1] << 8; }

uint32_t snref_crc32(const unsigned char *p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    size_t i;
    int k;
    for (i = 0; i < n; i++) {
        c ^= p[i];
        for (k = 0; k < 8; k++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}

typedef struct { const unsigned char *d; int flavour; unsigned rs; } rdr;

/* Read the real at p; fixed values are scaled by 2^-q. */
static double rd_real(const rdr *r, const unsigned char *p, int q) {
    if (r->flavour == SN_FLAVOUR_FIXED) {
        uint32_t u = rd_u32(p);
        int32_t v = (int32_t)(u ^ 0x80000000u) - (int32_t)0x7FFFFFFF - 1; /* portable u32 -> i32 */
        return ldexp((double)v, -q);
    } else if (r->flavour == SN_FLAVOUR_FLOAT32) {
        uint32_t u = rd_u32(p);
        float f;
        memcpy(&f, &u, 4);
        return (double)f;
    } else {
        uint64_t u = (uint64_t)rd_u32(p) | (uint64_t)rd_u32(p + 4) << 32;
        double f;
        memcpy(&f, &u, 8);
        return f;
    }
}

#define FAIL(...) do { if (err) snprintf(err, errn, __VA_ARGS__); snref_free(m); return -1; } while (0)

/* Free-free neighbour graph from CELLS (for the band ordering). */
static int build_adjacency(snref_model *m) {
    unsigned nF = m->nF, e, a, b, i, *cnt = calloc(nF + 1, sizeof *cnt), *list;
    size_t tot = 0;
    if (!cnt) return -1;
    for (e = 0; e < m->nC; e++)
        for (a = 0; a < 8; a++)
            if (m->cells[8 * e + a] < nF) cnt[m->cells[8 * e + a]] += 7;
    m->adjp = calloc(nF + 1, sizeof *m->adjp);
    for (i = 0; i < nF; i++) tot += cnt[i];
    list = malloc((tot + 1) * sizeof *list);
    if (!m->adjp || !list) { free(cnt); free(list); return -1; }
    for (i = 0; i < nF; i++) m->adjp[i + 1] = m->adjp[i] + cnt[i];
    memset(cnt, 0, nF * sizeof *cnt);
    for (e = 0; e < m->nC; e++)
        for (a = 0; a < 8; a++) {
            unsigned va = m->cells[8 * e + a];
            if (va >= nF) continue;
            for (b = 0; b < 8; b++) {
                unsigned vb = m->cells[8 * e + b];
                if (b != a && vb < nF) list[m->adjp[va] + cnt[va]++] = vb;
            }
        }
    /* sort and dedupe each row in place */
    m->adj = malloc((tot + 1) * sizeof *m->adj);
    if (!m->adj) { free(cnt); free(list); return -1; }
    {
        unsigned w = 0, start;
        for (i = 0; i < nF; i++) {
            unsigned k, j, *row = list + m->adjp[i], n = cnt[i];
            for (k = 1; k < n; k++)
                for (j = k; j > 0 && row[j - 1] > row[j]; j--) { unsigned t = row[j]; row[j] = row[j - 1]; row[j - 1] = t; }
            start = w;
            for (k = 0; k < n; k++) if (k == 0 || row[k] != row[k - 1]) m->adj[w++] = row[k];
            m->adjp[i] = start;
        }
        m->adjp[nF] = w;
    }
    free(cnt); free(list);
    return 0;
}

/* Format 3.0 rig sections (sn_format.h): controls, rigs, tau samples, vertex
 * lists and forces, all converted to double (fixed: gamma and value0 Q16.16,
 * eta and the axis Q30, forces Q frac of their rig). Structural checks only:
 * enough that the reference never reads out of bounds. */
static int load_rigs(snref_model *m, const rdr *r, const unsigned *sec_off, char *err, size_t errn) {
    const unsigned char *d = r->d;
    unsigned R = r->rs, i, k, fixed = m->flavour == SN_FLAVOUR_FIXED;
    unsigned long tot_s = 0, tot_e = 0;
#define ALLOC(p, n) do { p = calloc((size_t)(n) + 1, sizeof *(p)); if (!p) FAIL("out of memory"); } while (0)
    ALLOC(m->kname, m->nK); ALLOC(m->kkind, m->nK); ALLOC(m->kjoint, m->nK); ALLOC(m->kaxis, 3 * m->nK); ALLOC(m->kvalue0, m->nK);
    ALLOC(m->rctl, m->nR); ALLOC(m->rns, m->nR); ALLOC(m->rfrac, m->nR); ALLOC(m->rfs, m->nR); ALLOC(m->rfe, m->nR); ALLOC(m->rne, m->nR);
    ALLOC(m->rgamma, m->nRS); ALLOC(m->reta, m->nRS); ALLOC(m->rvert, m->nRE); ALLOC(m->rforce, 3 * (size_t)m->nRE);
#undef ALLOC
    for (i = 0; i < m->nK; i++) {
        const unsigned char *e = d + sec_off[SN_SEC_CONTROLS] + (size_t)SN_ELEM_CONTROLS(R) * i;
        unsigned j;
        memcpy(m->kname[i], e, 32);
        if (!m->kname[i][0] || m->kname[i][31]) FAIL("control %u: name", i);
        for (j = 0; j < i; j++) if (!strcmp(m->kname[i], m->kname[j])) FAIL("control %u: repeated name '%s'", i, m->kname[i]);
        m->kkind[i] = e[32];
        m->kjoint[i] = e[33];
        if (m->kkind[i] != SN_CTL_ABSTRACT && m->kkind[i] != SN_CTL_ANGLE) FAIL("control %u: kind %d", i, m->kkind[i]);
        if (m->kkind[i] == SN_CTL_ANGLE && (unsigned)m->kjoint[i] >= m->nJ) FAIL("control %u: joint %d", i, m->kjoint[i]);
        for (k = 0; k < 3; k++) m->kaxis[3 * i + k] = rd_real(r, e + 40 + k * R, 30);
        m->kvalue0[i] = rd_real(r, e + 40 + 3 * R, 16);
        if (m->kkind[i] == SN_CTL_ANGLE) {
            double n = sqrt(dot(m->kaxis + 3 * i, m->kaxis + 3 * i, 3));
            if (!(n > 0.5 && n < 2)) FAIL("control %u: axis length %g", i, n);
            for (k = 0; k < 3; k++) m->kaxis[3 * i + k] /= n;   /* unit (fixed: Q30 rounding) */
        }
    }
    for (i = 0; i < m->nR; i++) {
        const unsigned char *e = d + sec_off[SN_SEC_RIGS] + SN_ELEM_RIGS * i;
        m->rctl[i] = rd_u16(e); m->rns[i] = e[2]; m->rfrac[i] = (int)(signed char)e[3];
        m->rfs[i] = rd_u32(e + 4); m->rfe[i] = rd_u32(e + 8); m->rne[i] = rd_u32(e + 12);
        if (m->rctl[i] >= m->nK) FAIL("rig %u: control %u", i, m->rctl[i]);
        if (m->rns[i] < 1 || m->rns[i] > SN_RIG_MAX_SAMPLES) FAIL("rig %u: %u samples", i, m->rns[i]);
        if (m->rfs[i] != tot_s || m->rfe[i] != tot_e) FAIL("rig %u: first sample/entry not the running sums", i);
        if (fixed && (m->rfrac[i] < SN_RIG_FRAC_MIN || m->rfrac[i] > SN_RIG_FRAC_MAX)) FAIL("rig %u: frac %d", i, m->rfrac[i]);
        tot_s += m->rns[i]; tot_e += m->rne[i];
        if (tot_s > m->nRS || tot_e > m->nRE) FAIL("rig %u: samples/entries beyond their sections", i);
    }
    if (tot_s != m->nRS || tot_e != m->nRE) FAIL("rig totals %lu samples, %lu entries; sections hold %u, %u", tot_s, tot_e, m->nRS, m->nRE);
    for (i = 0; i < m->nR; i++) {
        unsigned a = m->rfs[i], e2 = m->rfe[i];
        for (k = a; k < a + m->rns[i]; k++) {
            const unsigned char *e = d + sec_off[SN_SEC_RIG_SAMPLES] + (size_t)SN_ELEM_RIG_SAMPLES(R) * k;
            m->rgamma[k] = rd_real(r, e, 16);
            m->reta[k] = rd_real(r, e + R, 30);
            if (k > a && !(m->rgamma[k] > m->rgamma[k - 1])) FAIL("rig %u: gamma samples not increasing", i);
        }
        for (k = e2; k < e2 + m->rne[i]; k++) {
            const unsigned char *e = d + sec_off[SN_SEC_RIG_FORCES] + (size_t)SN_ELEM_RIG_FORCES(R) * k;
            unsigned c;
            m->rvert[k] = rd_u16(d + sec_off[SN_SEC_RIG_VERTS] + 2 * k);
            if (m->rvert[k] >= m->nF || (k > e2 && m->rvert[k] <= m->rvert[k - 1])) FAIL("rig %u: vertex list", i);
            for (c = 0; c < 3; c++) m->rforce[3 * k + c] = rd_real(r, e + c * R, fixed ? m->rfrac[i] : 0);
        }
    }
    return 0;
}

int snref_load(snref_model *m, const void *data, size_t size, char *err, size_t errn) {
    const unsigned char *d = (const unsigned char *)data;
    rdr r;
    unsigned sec_off[SN_SEC_COUNT], i, k;
    uint32_t total;
    unsigned R;
    memset(m, 0, sizeof *m);
    if (size < SN_HEADER_BYTES) FAIL("truncated header");
    if (d[0] != SN_MAGIC0 || d[1] != SN_MAGIC1 || d[2] != SN_MAGIC2 || d[3] != SN_MAGIC3) FAIL("bad magic");
    if (rd_u16(d + SN_H_VER_MAJOR) != SN_FORMAT_MAJOR) FAIL("version %u", rd_u16(d + SN_H_VER_MAJOR));
    if (rd_u32(d + SN_H_ENDIAN) != SN_ENDIAN_MARK) FAIL("endian");
    if (rd_u32(d + SN_H_HEADER_SIZE) != SN_HEADER_BYTES || d[SN_H_NSECTIONS] != SN_SEC_COUNT) FAIL("header size / sections");
    total = rd_u32(d + SN_H_TOTAL_SIZE);
    if (total > size || total < SN_HEADER_BYTES) FAIL("total size %u > %zu", (unsigned)total, size);
    if (snref_crc32(d + 16, total - 16) != rd_u32(d + SN_H_CRC32)) FAIL("crc mismatch");
    m->flavour = d[SN_H_FLAVOUR];
    m->real_size = R = d[SN_H_REAL_SIZE];
    if (m->flavour > 2 || R != (m->flavour == 2 ? 8u : 4u)) FAIL("flavour %d real size %u", m->flavour, R);
    m->flags = d[SN_H_FLAGS];
    if (m->flags & ~SN_FLAG_REST_MODELLED) FAIL("unknown flags 0x%x", m->flags);
    r.d = d; r.flavour = m->flavour; r.rs = R;
    m->nV = rd_u32(d + SN_H_N_VERTICES); m->nF = rd_u32(d + SN_H_N_FREE);
    m->nC = rd_u32(d + SN_H_N_CELLS); m->nJ = rd_u32(d + SN_H_N_JOINTS);
    m->nS = rd_u32(d + SN_H_N_SURFACE); m->nT = rd_u32(d + SN_H_N_TRIANGLES);
    m->nnz = rd_u32(d + SN_H_N_OFFDIAG);
    m->cg_default = rd_u16(d + SN_H_CG_DEFAULT); m->cg_max = rd_u16(d + SN_H_CG_MAX);
    m->len_shift = (int)(signed char)d[SN_H_LEN_SHIFT];
    m->frac_S = d[SN_H_FRAC_S]; m->frac_M = d[SN_H_FRAC_M]; m->frac_P = d[SN_H_FRAC_P];
    m->frac_E = (int)(signed char)d[SN_H_FRAC_E];
    m->unit = ldexp(1.0, m->len_shift);
    if (m->nF < 1 || m->nF >= m->nV || m->nV > SN_MAX_VERTICES || m->nJ < 1 || m->nJ > SN_MAX_JOINTS)
        FAIL("counts nV %u nF %u nJ %u", m->nV, m->nF, m->nJ);
    {
        const unsigned char *rp = d + SN_H_REALS;
        m->a1 = rd_real(&r, rp + SN_R_A1 * R, SN_Q_COEF);
        m->b1 = rd_real(&r, rp + SN_R_B1 * R, SN_Q_COEF);
        m->grav[0] = rd_real(&r, rp + SN_R_GRAV_X * R, SN_Q_LEN);
        m->grav[1] = rd_real(&r, rp + SN_R_GRAV_Y * R, SN_Q_LEN);
        m->grav[2] = rd_real(&r, rp + SN_R_GRAV_Z * R, SN_Q_LEN);
        m->h = rd_real(&r, rp + SN_R_TIMESTEP * R, 16);
        m->m0 = rd_real(&r, rp + SN_R_MASS_SCALE * R, 16);
        m->energy = rd_real(&r, rp + SN_R_ENERGY * R, m->frac_E);
        m->cell = rd_real(&r, rp + SN_R_CELL * R, SN_Q_LEN);
        m->disp_bound = rd_real(&r, rp + SN_R_DISP_BOUND * R, 16);
        if (!(m->energy > 0) || !(m->cell > 0) || !(m->disp_bound > 0))
            FAIL("health scalars energy %g cell %g disp_bound %g", m->energy, m->cell, m->disp_bound);
    }
    {
        /* the rig sections' counts are their own (RIGS' running sums are checked below) */
#define SEC_CNT(k) rd_u32(d + SN_H_SECTIONS + (k) * SN_SECTION_ENTRY + 8)
        const unsigned expect_cnt[SN_SEC_COUNT] = { m->nJ, m->nJ, m->nV, m->nV, m->nF, m->nF, m->nF,
            m->nF + 1, m->nnz, m->nnz, m->nC, m->nC, m->nC, m->nF, m->nS, m->nT,
            SEC_CNT(SN_SEC_CONTROLS), SEC_CNT(SN_SEC_RIGS), SEC_CNT(SN_SEC_RIG_SAMPLES),
            SEC_CNT(SN_SEC_RIG_VERTS), SEC_CNT(SN_SEC_RIG_VERTS), SEC_CNT(SN_SEC_SHARES), m->nF,
            SEC_CNT(SN_SEC_SEGMESH), SEC_CNT(SN_SEC_SEGNODES), SEC_CNT(SN_SEC_SEGATTACH), 1u,
            SEC_CNT(SN_SEC_CREASE), SEC_CNT(SN_SEC_CREASE_PAIRS), SEC_CNT(SN_SEC_CREASE_VNBR), SEC_CNT(SN_SEC_CREASE_TNBR),
            SEC_CNT(SN_SEC_LEVEL_BLOB), SEC_CNT(SN_SEC_LEVEL_UP), SEC_CNT(SN_SEC_LEVEL_DOWN),
            SEC_CNT(SN_SEC_ICHOL), SEC_CNT(SN_SEC_ADAPT), SEC_CNT(SN_SEC_CELLX), SEC_CNT(SN_SEC_CELLXK),
            SEC_CNT(SN_SEC_FPAIRS), SEC_CNT(SN_SEC_FREFS),
            SEC_CNT(SN_SEC_DETAILS), SEC_CNT(SN_SEC_DETAIL), SEC_CNT(SN_SEC_CELLD), SEC_CNT(SN_SEC_CELLDK) };
        const unsigned expect_el[SN_SEC_COUNT] = { SN_ELEM_JOINTS(R), SN_ELEM_JOINT_NAMES, SN_ELEM_REST(R),
            SN_ELEM_FRAMES, SN_ELEM_MDIAG(R), SN_ELEM_PRECOND(R), SN_ELEM_MLUMP(R), SN_ELEM_ROWPTR,
            SN_ELEM_COLS, SN_ELEM_MOFF(R), SN_ELEM_CELLS, SN_ELEM_CFRAMES, SN_ELEM_CELLK(m->flavour, R),
            SN_ELEM_LIMIT(R), SN_ELEM_EMBED, SN_ELEM_TRIS, SN_ELEM_CONTROLS(R), SN_ELEM_RIGS,
            SN_ELEM_RIG_SAMPLES(R), SN_ELEM_RIG_VERTS, SN_ELEM_RIG_FORCES(R), SN_ELEM_SHARES(R), SN_ELEM_VSHARE,
            SN_ELEM_SEGMESH(R), SN_ELEM_SEGNODES(R), SN_ELEM_SEGATTACH(R), SN_ELEM_CONSTRAINTS,
            SN_ELEM_CREASE(R), SN_ELEM_CREASE_PAIRS, SN_ELEM_CREASE_VNBR, SN_ELEM_CREASE_TNBR,
            SN_ELEM_LEVEL_BLOB, SN_ELEM_LEVEL_MAP, SN_ELEM_LEVEL_MAP, SN_ELEM_ICHOL, SN_ELEM_ADAPT(R),
            SN_ELEM_CELLX, SN_ELEM_CELLXK(m->flavour, R), SN_ELEM_FPAIRS, SN_ELEM_FREFS, SN_ELEM_DETAILS(R), SN_ELEM_DETAIL(R),
            SN_ELEM_CELLD, SN_ELEM_CELLDK(m->flavour, R) };
#undef SEC_CNT
        typedef char sec_count_check[SN_SEC_COUNT == 44 ? 1 : -1];   /* format 6.5 (DETAILS, DETAIL, CELLD, CELLDK: not read, the reference models the cut level without its details); 6.4 (FPAIRS, FREFS: the frames' shared work, not read: the reference slerps every frame); 6.3 (CELLX, CELLXK: the cut level, read below); 6.1 (ADAPT, not read: the reference models level 0): update the tables above (the crease sections are not read: the reference has no crease contact; the level sections neither: the reference models level 0) */
        (void)sizeof(sec_count_check);
        {   /* the cut level: CELLX 0 or nC, CELLXK its running sum (checked when read) */
            uint32_t ncx = rd_u32(d + SN_H_SECTIONS + SN_SEC_CELLX * SN_SECTION_ENTRY + 8);
            if (ncx != 0 && ncx != m->nC) FAIL("CELLX count %u, want 0 or nC", (unsigned)ncx);
        }
        for (i = 0; i < SN_SEC_COUNT; i++) {
            const unsigned char *e = d + SN_H_SECTIONS + i * SN_SECTION_ENTRY;
            uint32_t off = rd_u32(e), sz = rd_u32(e + 4), cnt = rd_u32(e + 8), el = rd_u32(e + 12);
            int cnt_ok = cnt == expect_cnt[i] || ((i == SN_SEC_LIMIT || i == SN_SEC_VSHARE || i == SN_SEC_CONSTRAINTS) && cnt == 0);
            if (!cnt_ok || el != expect_el[i] || (uint64_t)cnt * el != sz || (uint64_t)off + sz > total)
                FAIL("section %u: off %u size %u count %u elem %u", i, (unsigned)off, (unsigned)sz,
                     (unsigned)cnt, (unsigned)el);
            sec_off[i] = off;
            if (i == SN_SEC_LIMIT) m->nlimit = cnt;
            if (i == SN_SEC_ICHOL) m->nIC = cnt;
        }
        m->nK = expect_cnt[SN_SEC_CONTROLS]; m->nR = expect_cnt[SN_SEC_RIGS];
        m->nRS = expect_cnt[SN_SEC_RIG_SAMPLES]; m->nRE = expect_cnt[SN_SEC_RIG_VERTS];
        if (m->nK > SN_MAX_CONTROLS || m->nR > SN_MAX_RIGS || (m->nR && !m->nK))
            FAIL("rig counts: %u controls, %u rigs", m->nK, m->nR);
    }
#define ALLOC(p, n) do { p = calloc((size_t)(n) + 1, sizeof *(p)); if (!p) FAIL("out of memory"); } while (0)
    ALLOC(m->jparent, m->nJ); ALLOC(m->jrest, 3 * m->nJ); ALLOC(m->jname, m->nJ);
    ALLOC(m->rest, 3 * m->nV); ALLOC(m->fb1, m->nV); ALLOC(m->fb2, m->nV); ALLOC(m->fw, m->nV);
    ALLOC(m->mdiag, m->nF); ALLOC(m->precond, 9 * m->nF); ALLOC(m->mlump, m->nF);
    ALLOC(m->rowptr, m->nF + 1); ALLOC(m->cols, m->nnz); ALLOC(m->moff, m->nnz);
    ALLOC(m->cells, 8 * m->nC); ALLOC(m->cb1, m->nC); ALLOC(m->cb2, m->nC); ALLOC(m->cw, m->nC);
    ALLOC(m->cellk, (size_t)576 * m->nC); ALLOC(m->sdiag, 9 * m->nF);
    ALLOC(m->ecell, m->nS); ALLOC(m->et, 3 * m->nS); ALLOC(m->tris, 3 * m->nT);
    if (m->nlimit) ALLOC(m->limit, m->nF);
    for (i = 0; i < m->nJ; i++) {
        const unsigned char *e = d + sec_off[SN_SEC_JOINTS] + i * SN_ELEM_JOINTS(R);
        unsigned par = rd_u16(e);
        m->jparent[i] = par == 0xFFFFu ? -1 : (int)par;
        if (par != 0xFFFFu && par >= i) FAIL("joint %u parent %u", i, par);
        for (k = 0; k < 3; k++) m->jrest[3 * i + k] = rd_real(&r, e + 8 + k * R, SN_Q_LEN);
        memcpy(m->jname[i], d + sec_off[SN_SEC_JOINT_NAMES] + 32 * i, 32);
        m->jname[i][31] = 0;
    }
    for (i = 0; i < m->nV; i++) {
        const unsigned char *e = d + sec_off[SN_SEC_FRAMES] + 4 * i;
        for (k = 0; k < 3; k++) m->rest[3 * i + k] = rd_real(&r, d + sec_off[SN_SEC_REST] + (3 * i + k) * R, SN_Q_LEN);
        m->fb1[i] = e[0]; m->fb2[i] = e[1]; m->fw[i] = rd_u16(e + 2) / 32768.0;
        if ((unsigned)m->fb1[i] >= m->nJ || (unsigned)m->fb2[i] >= m->nJ || rd_u16(e + 2) > 32768u)
            FAIL("frame of vertex %u", i);
    }
    for (i = 0; i < m->nF; i++) {
        static const int sym[6][2] = { { 0, 0 }, { 1, 1 }, { 2, 2 }, { 0, 1 }, { 0, 2 }, { 1, 2 } };
        m->mdiag[i] = rd_real(&r, d + sec_off[SN_SEC_MDIAG] + i * R, (int)m->frac_M);
        m->mlump[i] = rd_real(&r, d + sec_off[SN_SEC_MLUMP] + i * R, (int)m->frac_M);
        for (k = 0; k < 6; k++) {
            double p = rd_real(&r, d + sec_off[SN_SEC_PRECOND] + (6 * i + k) * R, (int)m->frac_P);
            int a = sym[k][0], b = sym[k][1];
            m->precond[9 * i + 3 * a + b] = m->precond[9 * i + 3 * b + a] = p;
        }
        if (m->limit) m->limit[i] = rd_real(&r, d + sec_off[SN_SEC_LIMIT] + i * R, SN_Q_LEN);
    }
    for (i = 0; i <= m->nF; i++) m->rowptr[i] = rd_u32(d + sec_off[SN_SEC_ROWPTR] + 4 * i);
    if (m->rowptr[0] != 0 || m->rowptr[m->nF] != m->nnz) FAIL("rowptr ends");
    for (i = 0; i < m->nF; i++) {
        unsigned e;
        if (m->rowptr[i] > m->rowptr[i + 1]) FAIL("rowptr order");
        for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++) {
            m->cols[e] = rd_u16(d + sec_off[SN_SEC_COLS] + 2 * e);
            if (m->cols[e] <= i || m->cols[e] >= m->nV || (e > m->rowptr[i] && m->cols[e] <= m->cols[e - 1]))
                FAIL("column %u of row %u", m->cols[e], i);
        }
    }
    for (i = 0; i < m->nnz; i++) m->moff[i] = rd_real(&r, d + sec_off[SN_SEC_MOFF] + i * R, (int)m->frac_M);
    if (m->nIC) { /* IC(0) blocks: int16 mantissas times 2^-frac in every flavour (sn_format.h) */
        unsigned nff = 0, k;
        for (i = 0; i < m->nnz; i++) nff += m->cols[i] < m->nF;
        if (m->nIC != nff) FAIL("ICHOL count %u, free-free mass entries %u", m->nIC, nff);
        ALLOC(m->ichol, 9 * (size_t)m->nIC);
        for (i = 0; i < m->nIC; i++) {
            const unsigned char *b = d + sec_off[SN_SEC_ICHOL] + (size_t)SN_ELEM_ICHOL * i;
            if (b[18] > SN_ICHOL_FRAC_MAX || b[19]) FAIL("ICHOL block %u frac %u", i, b[18]);
            for (k = 0; k < 9; k++) {
                unsigned u = rd_u16(b + 2 * k);
                m->ichol[9 * (size_t)i + k] = ldexp((double)((int)u - (int)((u & 0x8000u) << 1)), -(int)b[18]);
            }
        }
    }
    if (rd_u32(d + SN_H_SECTIONS + SN_SEC_CELLX * SN_SECTION_ENTRY + 8) != 0) {
        /* the cut level (BLOB.md "CELLX, CELLXK"): per cell its extra skeleton vertices and their [corner x extra] blocks */
        uint32_t nxk = rd_u32(d + SN_H_SECTIONS + SN_SEC_CELLXK * SN_SECTION_ENTRY + 8), first = 0, xsz = SN_ELEM_CELLXK(m->flavour, R);
        ALLOC(m->cutx, (size_t)SN_CUT_MAXX * m->nC); ALLOC(m->cutk, (size_t)SN_CUT_MAXX * 72 * m->nC); ALLOC(m->cutn, m->nC);
        for (i = 0; i < m->nC; i++) {
            const unsigned char *c = d + sec_off[SN_SEC_CELLX] + SN_ELEM_CELLX * i;
            unsigned k2, a, q, nx = 0;
            if (rd_u32(c + 40) != first) FAIL("CELLX %u: first %u, want %u", i, (unsigned)rd_u32(c + 40), (unsigned)first);
            for (k2 = 0; k2 < SN_CUT_MAXX; k2++) {
                unsigned x = rd_u16(c + 2 * k2);
                if (x == SN_CUT_NONE) continue;
                if (x < m->nF || x >= m->nV || first + 8 * nx + 8 > nxk) FAIL("CELLX %u: extra %u", i, x);
                m->cutx[SN_CUT_MAXX * i + nx] = x;
                for (a = 0; a < 8; a++) {
                    const unsigned char *b = d + sec_off[SN_SEC_CELLXK] + (size_t)xsz * (first + 8 * nx + a);
                    for (q = 0; q < 9; q++) {
                        double v;
                        if (m->flavour != SN_FLAVOUR_FIXED) v = rd_real(&r, b + q * R, (int)m->frac_S);
                        else {
                            int mm = (int)rd_u16(b + 2 * q);
                            if (mm >= 32768) mm -= 65536;
                            v = ldexp((double)mm, (int)b[18] - (int)m->frac_S);
                        }
                        m->cutk[(size_t)72 * (SN_CUT_MAXX * i + nx) + 9 * a + q] = v;
                    }
                }
                nx++;
            }
            m->cutn[i] = nx;
            first += 8 * nx;
        }
        if (first != nxk) FAIL("CELLXK count %u, want %u", (unsigned)nxk, (unsigned)first);
    }
    for (i = 0; i < m->nC; i++) {
        const unsigned char *cf = d + sec_off[SN_SEC_CFRAMES] + SN_ELEM_CFRAMES * i;
        const unsigned char *ck = d + sec_off[SN_SEC_CELLK] + (size_t)SN_ELEM_CELLK(m->flavour, R) * i;
        double *K = m->cellk + (size_t)576 * i;
        unsigned a, b, blk = 0, q;
        for (a = 0; a < 8; a++) {
            m->cells[8 * i + a] = rd_u16(d + sec_off[SN_SEC_CELLS] + 16 * i + 2 * a);
            if (m->cells[8 * i + a] >= m->nV) FAIL("cell %u corner", i);
            for (b = 0; b < a; b++) if (m->cells[8 * i + a] == m->cells[8 * i + b]) FAIL("cell %u repeats a corner", i);
        }
        m->cb1[i] = cf[0]; m->cb2[i] = cf[1]; m->cw[i] = rd_u16(cf + 2) / 32768.0;
        if ((unsigned)m->cb1[i] >= m->nJ || (unsigned)m->cb2[i] >= m->nJ || rd_u16(cf + 2) > 32768u) FAIL("cell %u frame", i);
        /* upper blocks (a <= b) in row order; block (a,b)[3i+j] = S[3a+i][3b+j], S_ba = S_ab^T */
        for (a = 0; a < 8; a++)
            for (b = a; b < 8; b++, blk++)
                for (q = 0; q < 9; q++) {
                    double x;
                    if (m->flavour != SN_FLAVOUR_FIXED) x = rd_real(&r, ck + (9 * blk + q) * R, (int)m->frac_S);
                    else if (a == b) { /* format 6.0 fixed CELLK: diagonal int32 xx yy zz xy xz yz */
                        static const unsigned s6[9] = {0, 3, 4, 3, 1, 5, 4, 5, 2};
                        x = rd_real(&r, ck + SN_CELLK_DIAG + 24 * a + 4 * s6[q], (int)m->frac_S);
                    } else { /* off-diagonal int16 mantissa times 2^e */
                        unsigned o = SN_CELLK_OFFIDX(a, b), e = ck[SN_CELLK_EXP + o];
                        int mm = (int)rd_u16(ck + SN_CELLK_OFF + 18 * o + 2 * q);
                        if (mm >= 32768) mm -= 65536;
                        if (e > SN_CELLK_EXP_MAX || mm < -SN_CELLK_M_MAX) FAIL("cell %u block (%u,%u) mantissa/exponent", i, a, b);
                        x = ldexp((double)mm, (int)e - (int)m->frac_S);
                    }
                    K[24 * (3 * a + q / 3) + 3 * b + q % 3] = x;
                    K[24 * (3 * b + q % 3) + 3 * a + q / 3] = x;
                }
        for (a = 0; a < 8; a++) {
            unsigned va = m->cells[8 * i + a];
            if (va >= m->nF) continue;
            for (q = 0; q < 9; q++) m->sdiag[9 * va + q] += K[24 * (3 * a + q / 3) + 3 * a + q % 3];
        }
    }
    for (i = 0; i < m->nS; i++) {
        const unsigned char *e = d + sec_off[SN_SEC_EMBED] + 8 * i;
        m->ecell[i] = rd_u16(e);
        if (m->ecell[i] >= m->nC) FAIL("embed cell");
        for (k = 0; k < 3; k++) m->et[3 * i + k] = rd_u16(e + 2 + 2 * k) / 32768.0;
    }
    for (i = 0; i < 3 * m->nT; i++) {
        m->tris[i] = rd_u16(d + sec_off[SN_SEC_TRIS] + 2 * i);
        if (m->tris[i] >= m->nS) FAIL("triangle index");
    }
    if (load_rigs(m, &r, sec_off, err, errn) != 0) return -1;
    if (build_adjacency(m) != 0) FAIL("out of memory");
    return 0;
#undef ALLOC
}

int snref_load_file(snref_model *m, const char *path, char *err, size_t errn) {
    FILE *f = fopen(path, "rb");
    long n;
    void *buf;
    int rc;
    memset(m, 0, sizeof *m);
    if (!f) { if (err) snprintf(err, errn, "cannot open %s", path); return -1; }
    fseek(f, 0, SEEK_END); n = ftell(f); fseek(f, 0, SEEK_SET);
    buf = malloc(n > 0 ? (size_t)n : 1);
    if (!buf || n <= 0 || fread(buf, 1, (size_t)n, f) != (size_t)n) {
        fclose(f); free(buf);
        if (err) snprintf(err, errn, "cannot read %s", path);
        return -1;
    }
    fclose(f);
    rc = snref_load(m, buf, (size_t)n, err, errn);
    free(buf);
    return rc;
}

void snref_free(snref_model *m) {
    free(m->jparent); free(m->jrest); free(m->jname); free(m->rest); free(m->fb1); free(m->fb2); free(m->fw);
    free(m->mdiag); free(m->precond); free(m->ichol); free(m->mlump); free(m->rowptr); free(m->cols); free(m->moff);
    free(m->cutx); free(m->cutk); free(m->cutn); free(m->cells); free(m->cb1); free(m->cb2); free(m->cw); free(m->cellk); free(m->limit); free(m->sdiag);
    free(m->adjp); free(m->adj); free(m->ecell); free(m->et); free(m->tris);
    free(m->kname); free(m->kkind); free(m->kjoint); free(m->kaxis); free(m->kvalue0);
    free(m->rctl); free(m->rns); free(m->rfrac); free(m->rfs); free(m->rfe); free(m->rne);
    free(m->rgamma); free(m->reta); free(m->rvert); free(m->rforce);
    memset(m, 0, sizeof *m);
}

/* ---------------- state ---------------- */

/* scratch arrays in s->work, each 3*nV doubles (S_PRE spans three: 9 nF) */
enum { S_B, S_VSTAR, S_W, S_TMP, S_PP, S_PNEW, S_VNEW, S_DVS, S_R, S_Z, S_D, S_AD, S_X, S_PRE, S_COUNT = S_PRE + 3 };
#define WK(s, k) ((s)->work + (size_t)(k) * 3 * (s)->m->nV)

static const double I3[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };

int snref_init(snref_state *s, const snref_model *m) {
    memset(s, 0, sizeof *s);
    s->m = m;
    s->p = calloc(3 * (size_t)m->nV, sizeof *s->p);
    s->v = calloc(3 * (size_t)m->nV, sizeof *s->v);
    s->dv = calloc(3 * (size_t)m->nV, sizeof *s->dv);
    s->R = calloc(9 * (size_t)m->nV, sizeof *s->R);
    s->c = calloc(3 * (size_t)m->nV, sizeof *s->c);
    s->Rc = calloc(9 * (size_t)m->nC + 1, sizeof *s->Rc);
    s->jq = calloc(4 * (size_t)m->nJ, sizeof *s->jq);
    s->jt = calloc(3 * (size_t)m->nJ, sizeof *s->jt);
    s->work = calloc(3 * (size_t)m->nV * S_COUNT, sizeof *s->work);
    s->ctl = calloc((size_t)m->nK + 1, sizeof *s->ctl);
    if (!s->p || !s->v || !s->dv || !s->R || !s->c || !s->Rc || !s->jq || !s->jt || !s->work || !s->ctl) { snref_release(s); return -1; }
    s->rig_scale = 1.0;
    s->iters = m->cg_default;
    s->warm = 1;
    s->gscale = 1.0;
    s->hscale = 1.0;
    s->dscale = 1.0;
    s->path_slerp = 1;
    s->first_pose_moves_free = 1;
    if (snref_set_regions(s, 0, NULL, NULL)) { snref_release(s); return -1; }
    snref_reset(s);
    return 0;
}

void snref_release(snref_state *s) {
    band_free(s->band);
    free(s->p); free(s->v); free(s->dv); free(s->R); free(s->c); free(s->Rc); free(s->jq); free(s->jt); free(s->work);
    free(s->ctl);
    free(s->rbone); free(s->rw);
    memset(s, 0, sizeof *s);
}

static unsigned root_joint(const snref_model *m) {
    unsigned j;
    for (j = 0; j < m->nJ; j++) if (m->jparent[j] < 0) return j;
    return 0;
}

/* NUMERICS step 2: vertex frames (R_i, c_i) and cell frames R_e from the pose. */
static void compute_frames(snref_state *s) {
    const snref_model *m = s->m;
    unsigned i, root = root_joint(m), k;
    double q[4];
    for (i = 0; i < m->nV; i++) {
        double w = m->fw[i];
        int b1 = m->fb1[i], b2 = m->fb2[i];
        if (s->mode == SNREF_UNWARPED) {
            memcpy(s->R + 9 * i, I3, sizeof I3);
            for (k = 0; k < 3; k++) s->c[3 * i + k] = s->jt[3 * root + k];
            continue;
        }
        slerp_(s->jq + 4 * b1, s->jq + 4 * b2, w, !s->path_slerp, q);
        snref_quat_to_mat(q, s->R + 9 * i);
        for (k = 0; k < 3; k++) s->c[3 * i + k] = (1.0 - w) * s->jt[3 * b1 + k] + w * s->jt[3 * b2 + k];
    }
    for (i = 0; i < m->nC; i++) {
        if (s->mode == SNREF_UNWARPED) { memcpy(s->Rc + 9 * i, I3, sizeof I3); continue; }
        slerp_(s->jq + 4 * m->cb1[i], s->jq + 4 * m->cb2[i], m->cw[i], !s->path_slerp, q);
        snref_quat_to_mat(q, s->Rc + 9 * i);
    }
    /* pose controls (alpha) follow the pose, whatever the stepping mode */
    for (i = 0; i < m->nK; i++) {
        int j = m->kjoint[i], p;
        double rel[4], cq[4];
        if (m->kkind[i] != SN_CTL_ANGLE) continue;
        p = m->jparent[j];
        if (p < 0) memcpy(rel, s->jq + 4 * j, sizeof rel);
        else {
            cq[0] = -s->jq[4 * p]; cq[1] = -s->jq[4 * p + 1]; cq[2] = -s->jq[4 * p + 2]; cq[3] = s->jq[4 * p + 3];
            snref_quat_mul(cq, s->jq + 4 * j, rel);
        }
        s->ctl[i] = snref_twist_angle(rel, m->kaxis + 3 * i);
    }
}

/* ---------------- rig controls and forces (seed 003 eq. 11-12) ---------------- */

double snref_twist_angle(const double q[4], const double axis[3]) {
    double va = q[0] * axis[0] + q[1] * axis[1] + q[2] * axis[2], w = q[3];
    if (w < 0 || (w == 0 && va < 0)) { w = -w; va = -va; }   /* the sign with w >= 0 (w = 0: v.A >= 0) */
    return 2.0 * atan2(va, w) * (180.0 / 3.14159265358979323846);
}

int snref_find_control(const snref_model *m, const char *name) {
    unsigned i;
    for (i = 0; i < m->nK; i++) if (!strcmp(m->kname[i], name)) return (int)i;
    return -1;
}

int snref_set_control(snref_state *s, unsigned c, double value) {
    if (c >= s->m->nK || s->m->kkind[c] != SN_CTL_ABSTRACT || !(value == value) || fabs(value) > 1e300) return -1;
    s->ctl[c] = value;
    return 0;
}

double snref_get_control(const snref_state *s, unsigned c) { return c < s->m->nK ? s->ctl[c] : 0.0; }

/* tau_a (seed 003 after eq. 12): eta_0 at or below the first sample, the last
 * eta at or above the last, linear in between. */
double snref_tau(const snref_model *m, unsigned a, double g) {
    const double *G = m->rgamma + m->rfs[a], *E = m->reta + m->rfs[a];
    unsigned n = m->rns[a], k;
    if (g <= G[0]) return E[0];
    if (g >= G[n - 1]) return E[n - 1];
    for (k = 0; k + 1 < n && g > G[k + 1]; k++) {}
    return E[k] + (E[k + 1] - E[k]) * ((g - G[k]) / (G[k + 1] - G[k]));
}

/* out (free rows) += rig_scale * h'^2/h^2 * R_i sum_a tau_a(gamma_c(a)) Q^a_i (NUMERICS step 5). */
void snref_rig_add(const snref_state *s, double *out) {
    const snref_model *m = s->m;
    unsigned a, k, c;
    double sc = s->rig_scale * sscale(s);
    if (sc == 0) return;
    for (a = 0; a < m->nR; a++) {
        double t = sc * snref_tau(m, a, s->ctl[m->rctl[a]]);
        if (t == 0) continue;
        for (k = m->rfe[a]; k < m->rfe[a] + m->rne[a]; k++) {
            unsigned i = m->rvert[k];
            double y[3];
            mat_vec(s->R + 9 * i, m->rforce + 3 * k, y);
            for (c = 0; c < 3; c++) out[3 * i + c] += t * y[c];
        }
    }
}

/* Skeleton vertex positions for the current pose (bone1 of each vertex). */
static void skeleton_pos(const snref_state *s, unsigned k, double out[3]) {
    const snref_model *m = s->m;
    double R[9], y[3];
    int b = m->fb1[k];
    snref_quat_to_mat(s->jq + 4 * b, R);
    mat_vec(R, m->rest + 3 * k, y);
    out[0] = y[0] + s->jt[3 * b]; out[1] = y[1] + s->jt[3 * b + 1]; out[2] = y[2] + s->jt[3 * b + 2];
}

void snref_reset(snref_state *s) {
    const snref_model *m = s->m;
    unsigned j, root = root_joint(m);
    for (j = 0; j < 3 * m->nV; j++) s->p[j] = m->rest[j] + m->jrest[3 * root + j % 3];
    memset(s->v, 0, 3 * m->nV * sizeof *s->v);
    memset(s->dv, 0, 3 * m->nV * sizeof *s->dv);
    for (j = 0; j < m->nJ; j++) {   /* identity: also the tracking reference of the first pose */
        s->jq[4 * j] = s->jq[4 * j + 1] = s->jq[4 * j + 2] = 0; s->jq[4 * j + 3] = 1;
        s->jt[3 * j] = s->jt[3 * j + 1] = s->jt[3 * j + 2] = 0;
    }
    s->posed = 0;
    s->steps = 0;
    s->e_el = s->e_kin = s->energy = s->energy_max = s->disp = s->disp_max = 0;
    s->limit_clamps = s->limit_steps = s->bound_steps = 0;
    for (j = 0; j < m->nK; j++) s->ctl[j] = m->kkind[j] == SN_CTL_ABSTRACT ? m->kvalue0[j] : 0.0;
    compute_frames(s);
}

void snref_set_pose(snref_state *s, const snref_xform *pose) {
    const snref_model *m = s->m;
    unsigned j, k, root = root_joint(m);
    /* Poses act on model space; internal positions are relative to the root
     * joint's rest x0, so in internal units x -> R x + (R x0 + t)/U. */
    for (j = 0; j < m->nJ; j++) {
        double Rj[9], y[3], d = 0, sg;
        for (k = 0; k < 4; k++) d += pose[j].q[k] * s->jq[4 * j + k];
        sg = (s->path_slerp && d < 0) ? -1.0 : 1.0;   /* step 1: track the previous pose's sign */
        for (k = 0; k < 4; k++) s->jq[4 * j + k] = sg * pose[j].q[k];
        snref_quat_to_mat(pose[j].q, Rj);
        mat_vec(Rj, m->jrest + 3 * root, y);
        for (k = 0; k < 3; k++) s->jt[3 * j + k] = pose[j].t[k] / m->unit + y[k];
    }
    if (!s->posed) {
        /* First pose is also the previous pose: skeleton state jumps with zero velocity. */
        int saved = s->mode;
        for (k = m->nF; k < m->nV; k++) skeleton_pos(s, k, s->p + 3 * k);
        if (s->first_pose_moves_free) {
            s->mode = SNREF_WARPED;
            compute_frames(s);
            for (k = 0; k < m->nF; k++) {
                double y[3];
                mat_vec(s->R + 9 * k, m->rest + 3 * k, y);
                for (j = 0; j < 3; j++) s->p[3 * k + j] = y[j] + s->c[3 * k + j];
            }
            s->mode = saved;
        }
        s->posed = 1;
    }
    compute_frames(s);
}

/* Baked coefficients after the optional time-step and damping rescale. */
static double sscale(const snref_state *s) { return s->hscale * s->hscale; }
static double a1_of(const snref_state *s) { return s->m->a1 * s->hscale * s->dscale; }
static double b1_of(const snref_state *s) { return s->m->b1 / s->hscale * s->dscale; }

/* ---------------- elastic terms, per cell ---------------- */

#define KE(m, e) ((m)->cellk + (size_t)576 * (e))

/* Cell model, NUMERICS step 4-5. For every cell: d_b = R_e^T (p_b - p_b0) -
 * (x_b - x_b0), g = S^_e (d + R_e^T (w_b - w_b0)) (w may be NULL: 0), and
 * out_a -= R_e g_a for free corners a (out may be NULL). Returns
 * E_el = 1/2 sum_e d^T S^_e d. */
static double cell_terms(const snref_state *s, const double *p, const double *w, double *out) {
    const snref_model *m = s->m;
    double E = 0, sc = sscale(s);
    unsigned e, a, i, k;
    for (e = 0; e < m->nC; e++) {
        const unsigned *cv = m->cells + 8 * e;
        const double *Re = s->Rc + 9 * e, *K = KE(m, e);
        double dd[24], dw[24], g[24];
        for (a = 0; a < 8; a++) {
            double u[3], x[3];
            for (k = 0; k < 3; k++) u[k] = p[3 * cv[a] + k] - p[3 * cv[0] + k];
            matT_vec(Re, u, x);
            for (k = 0; k < 3; k++) dd[3 * a + k] = x[k] - (m->rest[3 * cv[a] + k] - m->rest[3 * cv[0] + k]);
            if (w) {
                for (k = 0; k < 3; k++) u[k] = w[3 * cv[a] + k] - w[3 * cv[0] + k];
                matT_vec(Re, u, dw + 3 * a);
            } else dw[3 * a] = dw[3 * a + 1] = dw[3 * a + 2] = 0;
        }
        for (i = 0; i < 24; i++) {
            double t = 0, tw = 0;
            for (k = 0; k < 24; k++) { t += K[24 * i + k] * dd[k]; tw += K[24 * i + k] * dw[k]; }
            E += 0.5 * sc * dd[i] * t;
            g[i] = sc * (t + tw);
        }
        if (m->cutn) {   /* the cut level's extras: g_a += K_ax (d_x + R^T (w_x - w_0)) (the energy keeps the corner block, as the runtime's) */
            unsigned x;
            for (x = 0; x < m->cutn[e]; x++) {
                unsigned vx = m->cutx[SN_CUT_MAXX * e + x];
                const double *B = m->cutk + (size_t)72 * (SN_CUT_MAXX * e + x);
                double u[3], y[3], yw[3] = { 0, 0, 0 };
                for (k = 0; k < 3; k++) u[k] = p[3 * vx + k] - p[3 * cv[0] + k];
                matT_vec(Re, u, y);
                for (k = 0; k < 3; k++) y[k] -= m->rest[3 * vx + k] - m->rest[3 * cv[0] + k];
                if (w) { for (k = 0; k < 3; k++) u[k] = w[3 * vx + k] - w[3 * cv[0] + k]; matT_vec(Re, u, yw); }
                for (a = 0; a < 8; a++)
                    for (i = 0; i < 3; i++)
                        for (k = 0; k < 3; k++) g[3 * a + i] += sc * B[9 * a + 3 * i + k] * (y[k] + yw[k]);
            }
        }
        if (out)
            for (a = 0; a < 8; a++) {
                double y[3];
                if (cv[a] >= m->nF) continue;
                mat_vec(Re, g + 3 * a, y);
                for (k = 0; k < 3; k++) out[3 * cv[a] + k] -= y[k];
            }
    }
    return E;
}

/* VERTEX model force (seed 003 eq. 7): out_i -= R_i sum_j S_ij (R_i^T (p_j - c_i) - x_j), S = sum_e S^_e. */
static void vertex_force(const snref_state *s, const double *p, double *out) {
    const snref_model *m = s->m;
    double sc = sscale(s);
    unsigned e, a, b, k, i;
    for (e = 0; e < m->nC; e++) {
        const unsigned *cv = m->cells + 8 * e;
        const double *K = KE(m, e);
        for (a = 0; a < 8; a++) {
            unsigned va = cv[a];
            const double *Ri = s->R + 9 * va, *ci = s->c + 3 * va;
            double u[24], t[3] = { 0, 0, 0 }, y[3];
            if (va >= m->nF) continue;
            for (b = 0; b < 8; b++) {
                double q[3];
                for (k = 0; k < 3; k++) q[k] = p[3 * cv[b] + k] - ci[k];
                matT_vec(Ri, q, u + 3 * b);
                for (k = 0; k < 3; k++) u[3 * b + k] -= m->rest[3 * cv[b] + k];
            }
            for (i = 0; i < 3; i++)
                for (k = 0; k < 24; k++) t[i] += K[24 * (3 * a + i) + k] * u[k];
            mat_vec(Ri, t, y);
            for (k = 0; k < 3; k++) out[3 * va + k] -= sc * y[k];
        }
    }
}

/* y (free rows) += c * sum_e Rl(a) S^_e,ab Rr(b)^T x_b.
 * kind 0: step-matrix stiffness (CELL: Rl = Rr = R_e; VERTEX: R_a, R_b);
 * kind 1: negated Jacobian of the static force (CELL: as kind 0; VERTEX: Rl = Rr = R_a).
 * Skeleton columns only if with_skel. */
static void stiff_mul(const snref_state *s, const double *x, double *y, int with_skel, int kind, double c) {
    const snref_model *m = s->m;
    unsigned e, a, b, k, i;
    double sc = sscale(s) * c;
    for (e = 0; e < m->nC; e++) {
        const unsigned *cv = m->cells + 8 * e;
        const double *K = KE(m, e);
        double loc[24];
        int any = 0;
        for (a = 0; a < 8; a++) any |= cv[a] < m->nF;
        if (!any) continue;
        if (s->force == SNREF_FORCE_CELL || kind == 0) {
            for (b = 0; b < 8; b++) {
                const double *Rr = s->force == SNREF_FORCE_CELL ? s->Rc + 9 * e : s->R + 9 * cv[b];
                if (cv[b] >= m->nF && !with_skel) { loc[3 * b] = loc[3 * b + 1] = loc[3 * b + 2] = 0; continue; }
                matT_vec(Rr, x + 3 * cv[b], loc + 3 * b);
            }
        }
        for (a = 0; a < 8; a++) {
            const double *Rl = s->force == SNREF_FORCE_CELL ? s->Rc + 9 * e : s->R + 9 * cv[a];
            double t[3] = { 0, 0, 0 }, z[3];
            if (cv[a] >= m->nF) continue;
            if (s->force == SNREF_FORCE_VERTEX && kind == 1)
                for (b = 0; b < 8; b++) {
                    if (cv[b] >= m->nF && !with_skel) { loc[3 * b] = loc[3 * b + 1] = loc[3 * b + 2] = 0; continue; }
                    matT_vec(Rl, x + 3 * cv[b], loc + 3 * b);
                }
            for (i = 0; i < 3; i++)
                for (k = 0; k < 24; k++) t[i] += K[24 * (3 * a + i) + k] * loc[k];
            mat_vec(Rl, t, z);
            for (k = 0; k < 3; k++) y[3 * cv[a] + k] += sc * z[k];
        }
    }
}

void snref_kmul(const snref_state *s, const double *x, double *y, int with_skel) {
    memset(y, 0, 3 * s->m->nF * sizeof *y);
    stiff_mul(s, x, y, with_skel, 0, 1.0);
}

/* y_F = M^ x over free rows; columns F (and S if with_skel). */
static void mass_mul(const snref_state *s, const double *x, double *y, int with_skel) {
    const snref_model *m = s->m;
    unsigned i, e, k, n = with_skel ? m->nV : m->nF;
    for (i = 0; i < m->nF; i++)
        for (k = 0; k < 3; k++) y[3 * i + k] = m->mdiag[i] * x[3 * i + k];
    for (i = 0; i < m->nF; i++)
        for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++) {
            unsigned j = m->cols[e];
            if (j >= n) continue;
            for (k = 0; k < 3; k++) y[3 * i + k] += m->moff[e] * x[3 * j + k];
            if (j < m->nF)
                for (k = 0; k < 3; k++) y[3 * j + k] += m->moff[e] * x[3 * i + k];
        }
}

/* External load of step 5: m^_i g^ [- m^_i R_i g^ with REST_MODELLED]. */
static void gravity_add(const snref_state *s, double *f) {
    const snref_model *m = s->m;
    unsigned i, k;
    double g = s->gscale * sscale(s), rg[3];
    for (i = 0; i < m->nF; i++) {
        for (k = 0; k < 3; k++) f[3 * i + k] += m->mlump[i] * m->grav[k] * g;
        if (m->flags & SN_FLAG_REST_MODELLED) {
            mat_vec(s->R + 9 * i, m->grav, rg);
            for (k = 0; k < 3; k++) f[3 * i + k] -= m->mlump[i] * rg[k] * g;
        }
    }
}

void snref_force(const snref_state *s, const double *p, double *out) {
    memset(out, 0, 3 * s->m->nF * sizeof *out);
    if (s->force == SNREF_FORCE_CELL) cell_terms(s, p, NULL, out);
    else vertex_force(s, p, out);
}

double snref_elastic(const snref_state *s, const double *p) { return cell_terms(s, p, NULL, NULL); }

void snref_residual(const snref_state *s, double *out) {
    snref_force(s, s->p, out);
    gravity_add(s, out);
    snref_rig_add(s, out);
}

/* A x = (1+a1) M^_FF x + (1+b1) K_FF x */
static void a_mul(const snref_state *s, const double *x, double *y) {
    unsigned i, n = 3 * s->m->nF;
    double ca = 1.0 + a1_of(s);
    mass_mul(s, x, y, 0);
    for (i = 0; i < n; i++) y[i] *= ca;
    stiff_mul(s, x, y, 0, 0, 1.0 + b1_of(s));
}

/* Preconditioner blocks P_i (rest frame), from the blob unless h or damping is rescaled. */
static const double *precond_blocks(snref_state *s) {
    const snref_model *m = s->m;
    double *P = WK(s, S_PRE);
    unsigned i, k;
    if (s->hscale == 1.0 && s->dscale == 1.0) return m->precond;
    for (i = 0; i < m->nF; i++) {
        double A[9];
        for (k = 0; k < 9; k++) A[k] = (1.0 + b1_of(s)) * sscale(s) * m->sdiag[9 * i + k];
        for (k = 0; k < 3; k++) A[4 * k] += (1.0 + a1_of(s)) * m->mdiag[i];
        mat_inv(A, P + 9 * i);
    }
    return P;
}

/* IC(0): z = R (I + L^)^-T D^-1 (I + L^)^-1 R^T r, ICHOL's U_ji = L^_ij^T
 * in the mass pattern's free-free upper entries (runtime/src/sn_precond.c) */
/* frame of vertex i at R + rs i (rs 0: one frame, the blended region's);
 * with mask, only the vertices mask[i] != 0 (r taken as 0, z set to 0 elsewhere) */
static void ichol_apply_f(const snref_model *m, const double *R, size_t rs, const unsigned char *mask, const double *r, double *z) {
    unsigned i, j, e, n, c, nF = m->nF;
    for (i = 0; i < nF; i++) {
        if (mask && !mask[i]) z[3 * i] = z[3 * i + 1] = z[3 * i + 2] = 0;
        else matT_vec(R + rs * i, r + 3 * i, z + 3 * i);
    }
    for (j = 0, n = 0; j < nF; j++) /* forward: y_i -= U_ji^T y_j */
        for (e = m->rowptr[j]; e < m->rowptr[j + 1] && m->cols[e] < nF; e++, n++) {
            const double *U = m->ichol + 9 * (size_t)n;
            i = m->cols[e];
            for (c = 0; c < 3; c++) z[3 * i + c] -= U[c] * z[3 * j] + U[3 + c] * z[3 * j + 1] + U[6 + c] * z[3 * j + 2];
        }
    for (i = 0; i < nF; i++) {
        double t[3] = { z[3 * i], z[3 * i + 1], z[3 * i + 2] };
        mat_vec(m->precond + 9 * i, t, z + 3 * i);
    }
    for (j = nF; j-- > 0;) { /* backward: z_j -= sum_i U_ji z_i */
        unsigned f = m->rowptr[j];
        while (f < m->rowptr[j + 1] && m->cols[f] < nF) f++;
        n -= f - m->rowptr[j];
        for (e = m->rowptr[j]; e < f; e++) {
            const double *U = m->ichol + 9 * (size_t)(n + e - m->rowptr[j]);
            i = m->cols[e];
            for (c = 0; c < 3; c++) z[3 * j + c] -= U[3 * c] * z[3 * i] + U[3 * c + 1] * z[3 * i + 1] + U[3 * c + 2] * z[3 * i + 2];
        }
    }
    for (i = 0; i < nF; i++) {
        double t[3] = { z[3 * i], z[3 * i + 1], z[3 * i + 2] };
        if (mask && !mask[i]) { z[3 * i] = z[3 * i + 1] = z[3 * i + 2] = 0; continue; }
        mat_vec(R + rs * i, t, z + 3 * i);
    }
}

static void ichol_apply(const snref_state *s, const double *r, double *z) { ichol_apply_f(s->m, s->R, 9, NULL, r, z); }

/* z_i = R_i P_i R_i^T r_i (step 6: the vertex frame); the IC(0) of an ICHOL
 * blob instead when P is the blob's own (no rescaled h or damping) */
static void precond_apply(const snref_state *s, const double *P, const double *r, double *z) {
    unsigned i;
    if (s->m->nIC && P == s->m->precond) { ichol_apply(s, r, z); return; }
    for (i = 0; i < s->m->nF; i++) {
        double a[3], b[3];
        matT_vec(s->R + 9 * i, r + 3 * i, a);
        mat_vec(P + 9 * i, a, b);
        mat_vec(s->R + 9 * i, b, z + 3 * i);
    }
}

/* ---- constraint rows (runtime/NUMERICS.md "Constraints and contact") ----
 * Dense: C (3nF x m, column j the row's coefficients over free vertices),
 * G = C^T C = L L^T by Cholesky with the runtime's drop rule (a row whose
 * squared length is below 2^-8, or whose part orthogonal to the kept rows
 * before it has less than 2^-4 of that or less than 2^-10, is dropped). */
typedef struct snref_rowsys { unsigned m, n3; double *C, *L, *a, *t; int *kept; } rowsys;
static void rows_build(const snref_state *s, rowsys *q, const double *vstar) {
    unsigned j, l, p, k, c, nF = s->m->nF;
    q->m = s->nrows; q->n3 = 3 * nF;
    q->C = calloc((size_t)q->n3 * q->m + 1, sizeof *q->C);
    q->L = calloc((size_t)q->m * q->m + 1, sizeof *q->L);
    q->a = calloc(q->m + 1, sizeof *q->a);
    q->t = calloc(q->m + 1, sizeof *q->t);
    q->kept = calloc(q->m + 1, sizeof *q->kept);
    for (j = 0; j < q->m; j++) {
        const snref_row *r = s->rows + j;
        double sv = 0, g, piv;
        for (k = 0; k < r->n; k++)
            for (c = 0; c < 3; c++) {
                sv += r->w[k] * r->dir[c] * vstar[3 * r->vtx[k] + c];
                if (r->vtx[k] < nF) q->C[(size_t)j * q->n3 + 3 * r->vtx[k] + c] += r->w[k] * r->dir[c];
            }
        q->a[j] = r->target - sv;
        for (l = 0; l <= j; l++) {
            g = dot(q->C + (size_t)j * q->n3, q->C + (size_t)l * q->n3, q->n3);
            if (l == j) break;
            if (!q->kept[l]) continue;
            for (p = 0; p < l; p++) g -= q->L[j * q->m + p] * q->L[l * q->m + p];
            q->L[j * q->m + l] = g / q->L[l * q->m + l];
        }
        piv = g;
        for (p = 0; p < j; p++) piv -= q->L[j * q->m + p] * q->L[j * q->m + p];
        if (g < ldexp(1.0, -8) || piv <= g * ldexp(1.0, -4) || piv < ldexp(1.0, -10)) {
            for (p = 0; p < j; p++) q->L[j * q->m + p] = 0;
            continue;
        }
        q->kept[j] = 1;
        q->L[j * q->m + j] = sqrt(piv);
    }
}
static void rows_free(rowsys *q) { free(q->C); free(q->L); free(q->a); free(q->t); free(q->kept); }
/* t = G^-1 t over the kept rows */
static void rows_gsolve(const rowsys *q) {
    unsigned j, l;
    for (j = 0; j < q->m; j++) {
        double u = q->t[j];
        if (!q->kept[j]) { q->t[j] = 0; continue; }
        for (l = 0; l < j; l++) u -= q->L[j * q->m + l] * q->t[l];
        q->t[j] = u / q->L[j * q->m + j];
    }
    for (j = q->m; j-- > 0;) {
        double u = q->t[j];
        if (!q->kept[j]) continue;
        for (l = j + 1; l < q->m; l++) u -= q->L[l * q->m + j] * q->t[l];
        q->t[j] = u / q->L[j * q->m + j];
    }
}
/* y -= C G^-1 C^T y (fix = 0) or y += C G^-1 (a - C^T y) (fix = 1) */
static void rows_apply(const rowsys *q, double *y, int fix) {
    unsigned j, i;
    for (j = 0; j < q->m; j++) {
        double d = q->kept[j] ? dot(q->C + (size_t)j * q->n3, y, q->n3) : 0;
        q->t[j] = fix ? q->a[j] - d : d;
    }
    rows_gsolve(q);
    for (j = 0; j < q->m; j++)
        for (i = 0; i < q->n3; i++) y[i] += (fix ? 1.0 : -1.0) * q->C[(size_t)j * q->n3 + i] * q->t[j];
}

/* PCG, exactly `iters` iterations (or to convergence if iters == 0). x in/out. */
static double pcg(snref_state *s, const double *b, double *x, unsigned iters) {
    const snref_model *m = s->m;
    unsigned n = 3 * m->nF, it, i, maxit = iters ? iters : 20 * n + 100;
    double *r = WK(s, S_R), *z = WK(s, S_Z), *d = WK(s, S_D), *Ad = WK(s, S_AD);
    const double *P = precond_blocks(s);
    double rz, bn = sqrt(dot(b, b, n));
    const rowsys *cr = s->cg_rows; /* the step's rows (NULL: none) */
    if (cr) rows_apply(cr, x, 1);
    a_mul(s, x, Ad);
    for (i = 0; i < n; i++) r[i] = b[i] - Ad[i];
    if (cr) rows_apply(cr, r, 0);
    if (s->precond_hook) s->precond_hook(s->hook_ctx, s, r, z); else precond_apply(s, P, r, z);
    if (cr) rows_apply(cr, z, 0);
    memcpy(d, z, n * sizeof *d);
    rz = dot(r, z, n);
    if (cr) bn = sqrt(dot(r, r, n)); /* converged relative to the filtered start */
    for (it = 0; it < maxit; it++) {
        double dAd, alpha, rz2, beta;
        if (!iters && sqrt(dot(r, r, n)) <= 1e-14 * bn) break;
        a_mul(s, d, Ad);
        dAd = dot(d, Ad, n);
        alpha = dAd > 0 ? rz / dAd : 0.0;
        for (i = 0; i < n; i++) { x[i] += alpha * d[i]; r[i] -= alpha * Ad[i]; }
        if (cr) rows_apply(cr, r, 0);
        if (s->precond_hook) s->precond_hook(s->hook_ctx, s, r, z); else precond_apply(s, P, r, z);
        if (cr) rows_apply(cr, z, 0);
        rz2 = dot(r, z, n);
        beta = rz > 0 ? rz2 / rz : 0.0;
        for (i = 0; i < n; i++) d[i] = z[i] + beta * d[i];
        rz = rz2;
#ifdef SNREF_TRACE  /* magnitudes a fixed-point CG must hold (debugging aid) */
        {
            double md = 0, mad = 0, mx = 0, mr = 0;
            for (i = 0; i < n; i++) {
                if (fabs(d[i]) > md) md = fabs(d[i]);
                if (fabs(Ad[i]) > mad) mad = fabs(Ad[i]);
                if (fabs(x[i]) > mx) mx = fabs(x[i]);
                if (fabs(r[i]) > mr) mr = fabs(r[i]);
            }
            fprintf(stderr, "  cg %u: alpha %.3g beta %.3g |d| %.3g |Ad| %.3g |x| %.3g |r| %.3g\n", it, alpha, beta, md, mad, mx, mr);
        }
#endif
    }
    if (cr) rows_apply(cr, x, 1);
    a_mul(s, x, Ad);
    for (i = 0; i < n; i++) r[i] = b[i] - Ad[i];
    if (cr) rows_apply(cr, r, 0);
    return bn > 0 ? sqrt(dot(r, r, n)) / bn : 0.0;
}

/* ---------------- banded direct solver ---------------- */

/* Reverse Cuthill-McKee order of the free vertices (bandwidth reduction for
 * the banded direct solve). perm[new] = old, inv[old] = new. */
static void rcm(const snref_model *m, unsigned *perm, unsigned *inv) {
    unsigned nF = m->nF, i, head, tail = 0;
    const unsigned *adjp = m->adjp, *adj = m->adj;
    unsigned char *seen = calloc(nF, 1);
#define DEG(u) (adjp[(u) + 1] - adjp[u])
    while (tail < nF) {
        /* new component: start at a min-degree vertex, then move to the last BFS level twice (pseudo-peripheral) */
        unsigned start = nF, pass, k;
        for (i = 0; i < nF; i++) if (!seen[i] && (start == nF || DEG(i) < DEG(start))) start = i;
        for (pass = 0; pass < 2; pass++) {
            unsigned h2 = tail, t2 = tail;
            perm[t2++] = start; seen[start] = 1;
            while (h2 < t2) {
                unsigned u = perm[h2++];
                for (k = adjp[u]; k < adjp[u + 1]; k++) if (!seen[adj[k]]) { seen[adj[k]] = 1; perm[t2++] = adj[k]; }
            }
            for (k = tail; k < t2; k++) seen[perm[k]] = 0;
            start = perm[t2 - 1];
        }
        head = tail;
        perm[tail++] = start; seen[start] = 1;
        while (head < tail) {
            unsigned u = perm[head++], first = tail, a, b;
            for (k = adjp[u]; k < adjp[u + 1]; k++) if (!seen[adj[k]]) { seen[adj[k]] = 1; perm[tail++] = adj[k]; }
            for (a = first + 1; a < tail; a++)     /* neighbours by increasing degree */
                for (b = a; b > first && DEG(perm[b - 1]) > DEG(perm[b]); b--) { unsigned t = perm[b]; perm[b] = perm[b - 1]; perm[b - 1] = t; }
        }
    }
#undef DEG
    for (i = 0; i < nF / 2; i++) { unsigned t = perm[i]; perm[i] = perm[nF - 1 - i]; perm[nF - 1 - i] = t; }
    for (i = 0; i < nF; i++) inv[perm[i]] = i;
    free(seen);
}

/* Banded LU of a free-free system in RCM order. which = 0: the static
 * matrix H (CELL: K~_FF; VERTEX: -J, row i R_i S^_ij R_i^T); which = 1: the
 * step matrix A = (1+a1) M^_FF + (1+b1) K_FF. Assembled per cell. No
 * pivoting: both are SPD or close to it. The frames and coefficients it was
 * built from are kept, so a cached step factor is reused only while they hold. */
struct snref_band {
    unsigned n, nF, bw;
    size_t W;
    double *A;
    unsigned *inv;
    double *key;    /* R (nV*9), Rc (nC*9), coefficients */
    size_t nkey;
};

static void band_free(snref_band *B) { if (B) { free(B->A); free(B->inv); free(B->key); free(B); } }

static size_t band_key_len(const snref_state *s) { return 9 * (size_t)s->m->nV + 9 * (size_t)s->m->nC + 5; }
static void band_key_fill(const snref_state *s, int which, double *key) {
    size_t nV9 = 9 * (size_t)s->m->nV, nC9 = 9 * (size_t)s->m->nC;
    memcpy(key, s->R, nV9 * sizeof *key);
    memcpy(key + nV9, s->Rc, nC9 * sizeof *key);
    key[nV9 + nC9] = which; key[nV9 + nC9 + 1] = s->force;
    key[nV9 + nC9 + 2] = sscale(s); key[nV9 + nC9 + 3] = a1_of(s); key[nV9 + nC9 + 4] = b1_of(s);
}

static snref_band *band_build(snref_state *s, int which, double reg, size_t max_doubles) {
    const snref_model *m = s->m;
    unsigned nF = m->nF, n = 3 * nF, i, e, bw = 0, *perm = malloc(nF * sizeof *perm), *inv = malloc(nF * sizeof *inv);
    size_t W, row, col;
    double *A, sc = sscale(s), ca = 1.0 + a1_of(s), cb = which ? 1.0 + b1_of(s) : 1.0;
    snref_band *B;
    rcm(m, perm, inv);
    free(perm);
    for (i = 0; i < nF; i++)
        for (e = m->adjp[i]; e < m->adjp[i + 1]; e++) {
            unsigned j = m->adj[e], d = inv[i] > inv[j] ? inv[i] - inv[j] : inv[j] - inv[i];
            if (d > bw) bw = d;
        }
    bw = 3 * bw + 2;
    W = 2 * (size_t)bw + 1;
    if ((size_t)n * W > max_doubles) { free(inv); return NULL; }
    A = calloc((size_t)n * W, sizeof *A);
    if (!A) { free(inv); return NULL; }
#define AB(rr, cc) A[(size_t)(rr) * W + (cc) + bw - (rr)]
    for (e = 0; e < m->nC; e++) {
        const unsigned *cv = m->cells + 8 * e;
        const double *K = KE(m, e);
        unsigned a, b, p, q, r2;
        for (a = 0; a < 8; a++) {
            const double *Rl = s->force == SNREF_FORCE_CELL ? s->Rc + 9 * e : s->R + 9 * cv[a];
            if (cv[a] >= nF) continue;
            for (b = 0; b < 8; b++) {
                const double *Rr = s->force == SNREF_FORCE_CELL ? s->Rc + 9 * e : which ? s->R + 9 * cv[b] : Rl;
                double T[9], Bk[9];
                if (cv[b] >= nF) continue;
                for (p = 0; p < 3; p++)      /* T = S^_ab Rr^T */
                    for (q = 0; q < 3; q++) {
                        double t = 0;
                        for (r2 = 0; r2 < 3; r2++) t += K[24 * (3 * a + p) + 3 * b + r2] * Rr[3 * q + r2];
                        T[3 * p + q] = t;
                    }
                for (p = 0; p < 3; p++)      /* Bk = Rl T */
                    for (q = 0; q < 3; q++) Bk[3 * p + q] = Rl[3 * p] * T[q] + Rl[3 * p + 1] * T[3 + q] + Rl[3 * p + 2] * T[6 + q];
                for (p = 0; p < 3; p++)
                    for (q = 0; q < 3; q++) AB(3 * inv[cv[a]] + p, 3 * inv[cv[b]] + q) += cb * sc * Bk[3 * p + q];
            }
        }
    }
    if (!which && reg > 0)   /* proximal term of the static solve */
        for (i = 0; i < nF; i++) { unsigned a; for (a = 0; a < 3; a++) AB(3 * inv[i] + a, 3 * inv[i] + a) += reg * m->mdiag[i]; }
    if (which)
        for (i = 0; i < nF; i++) {
            unsigned a;
            for (a = 0; a < 3; a++) AB(3 * inv[i] + a, 3 * inv[i] + a) += ca * m->mdiag[i];
            for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++) {
                unsigned j = m->cols[e];
                if (j >= nF) continue;
                for (a = 0; a < 3; a++) {
                    AB(3 * inv[i] + a, 3 * inv[j] + a) += ca * m->moff[e];
                    AB(3 * inv[j] + a, 3 * inv[i] + a) += ca * m->moff[e];
                }
            }
        }
    for (row = 0; row < n; row++) {              /* in-place LU (L unit, multipliers below) */
        double piv = AB(row, row);
        size_t end = row + bw < n - 1 ? row + bw : n - 1;
        for (col = row + 1; col <= end; col++) {
            double l = AB(col, row) / piv;
            size_t k;
            AB(col, row) = l;
            if (l == 0) continue;
            for (k = row + 1; k <= end; k++) AB(col, k) -= l * AB(row, k);
        }
    }
#undef AB
    B = calloc(1, sizeof *B);
    B->n = n; B->nF = nF; B->bw = bw; B->W = W; B->A = A; B->inv = inv;
    B->nkey = band_key_len(s);
    B->key = malloc(B->nkey * sizeof *B->key);
    band_key_fill(s, which, B->key);
    return B;
}

static void band_solve(const snref_band *B, const double *r, double *x) {
    size_t n = B->n, bw = B->bw, W = B->W, row, k;
    unsigned i, e;
    double *y = malloc(n * sizeof *y);
    const double *A = B->A;
#define AB(rr, cc) A[(size_t)(rr) * W + (cc) + bw - (rr)]
    for (i = 0; i < B->nF; i++) for (e = 0; e < 3; e++) y[3 * B->inv[i] + e] = r[3 * i + e];
    for (row = 0; row < n; row++) {
        size_t end = row + bw < n - 1 ? row + bw : n - 1;
        for (k = row + 1; k <= end; k++) y[k] -= AB(k, row) * y[row];
    }
    for (row = n; row-- > 0;) {
        size_t end = row + bw < n - 1 ? row + bw : n - 1;
        double t = y[row];
        for (k = row + 1; k <= end; k++) t -= AB(row, k) * y[k];
        y[row] = t / AB(row, row);
    }
#undef AB
    for (i = 0; i < B->nF; i++) for (e = 0; e < 3; e++) x[3 * i + e] = y[3 * B->inv[i] + e];
    free(y);
}

/* Exact step solve by a banded LU of A, cached while the frames and
 * coefficients are unchanged. Returns -1 if the band is too large. */
static int exact_direct(snref_state *s, const double *b, double *x) {
    double *key = malloc(band_key_len(s) * sizeof *key);
    int hit;
    band_key_fill(s, 1, key);
    hit = s->band && memcmp(s->band->key, key, s->band->nkey * sizeof *key) == 0;
    free(key);
    if (!hit) {
        band_free(s->band);
        s->band = band_build(s, 1, 0.0, (size_t)60000000);
        if (!s->band) return -1;
    }
    band_solve(s->band, b, x);
    return 0;
}

/* ---------------- the step ---------------- */

/* Step 8-9: limits, then the health report (disp over free vertices with m^_i >= 1/16). */
static void limits_and_health(snref_state *s) {
    const snref_model *m = s->m;
    unsigned i, k, clamps = 0;
    double dmax = 0;
    for (i = 0; i < m->nF; i++) {
        double sk[3], dl[3], n2 = 0, n;
        mat_vec(s->R + 9 * i, m->rest + 3 * i, sk);
        for (k = 0; k < 3; k++) { sk[k] += s->c[3 * i + k]; dl[k] = s->p[3 * i + k] - sk[k]; n2 += dl[k] * dl[k]; }
        n = sqrt(n2);
        if (m->limit && m->limit[i] > 0 && n > m->limit[i]) {
            for (k = 0; k < 3; k++) {
                double np = sk[k] + dl[k] * m->limit[i] / n;
                s->v[3 * i + k] += np - s->p[3 * i + k];
                s->p[3 * i + k] = np;
            }
            n = m->limit[i];
            clamps++;
        }
        if (m->mlump[i] >= 1.0 / 16 && n > dmax) dmax = n;   /* step 9: vertices that carry flesh */
    }
    s->limit_clamps = clamps;
    if (clamps) s->limit_steps++;
    s->disp = dmax / m->cell;
    if (s->disp > s->disp_max) s->disp_max = s->disp;
    if (s->disp > m->disp_bound) s->bound_steps++;
    s->energy = (s->e_el + s->e_kin) * m->energy / sscale(s);
    if (s->energy > s->energy_max) s->energy_max = s->energy;
}

/* ---------------- blended local linearization (SNREF_BLENDED, seed 000 sec. 4.5) ---------------- */

int snref_set_regions(snref_state *s, unsigned nreg, const int *rbone, const double *W) {
    const snref_model *m = s->m;
    unsigned r, a;
    int *nb;
    double *nw;
    if (!W) nreg = m->nJ;
    if (nreg == 0 && !W) { free(s->rbone); free(s->rw); s->rbone = NULL; s->rw = NULL; s->nreg = 0; return 0; }   /* no joints: no regions */
    if (nreg == 0) return -1;
    nb = malloc(nreg * sizeof *nb);
    nw = calloc((size_t)nreg * m->nV, sizeof *nw);
    if (!nb || !nw) { free(nb); free(nw); return -1; }
    if (!W) {   /* one region per joint; W from the vertex frames (FRAMES: a partition of unity over bones) */
        for (r = 0; r < nreg; r++) nb[r] = (int)r;
        for (a = 0; a < m->nV; a++) {
            nw[(size_t)m->fb1[a] * m->nV + a] += 1.0 - m->fw[a];
            nw[(size_t)m->fb2[a] * m->nV + a] += m->fw[a];
        }
    } else {
        for (r = 0; r < nreg; r++)
            if (rbone[r] < 0 || (unsigned)rbone[r] >= m->nJ) { free(nb); free(nw); return -1; }
        memcpy(nb, rbone, nreg * sizeof *nb);
        memcpy(nw, W, (size_t)nreg * m->nV * sizeof *nw);
        for (a = 0; a < m->nF; a++) {
            double sum = 0;
            for (r = 0; r < nreg; r++) {
                double x = nw[(size_t)r * m->nV + a];
                if (!(x >= 0)) { free(nb); free(nw); return -1; }
                sum += x;
            }
            if (fabs(sum - 1.0) > 1e-9) { free(nb); free(nw); return -1; }
        }
    }
    free(s->rbone); free(s->rw);
    s->rbone = nb; s->rw = nw; s->nreg = nreg;
    return 0;
}

/* One region at the current pose: frame R^r of its bone, its cells (a free
 * vertex of positive weight), its unknowns (free vertices of those cells; with
 * blend_hold only those of positive weight). */
typedef struct { double R[9]; const double *W; unsigned char *cm, *vm; unsigned nc, nu; } blend_region;

static int region_setup(const snref_state *s, unsigned r, blend_region *g) {
    const snref_model *m = s->m;
    unsigned e, a;
    g->W = s->rw + (size_t)r * m->nV;
    g->cm = calloc(m->nC + 1, 1);
    g->vm = calloc(m->nV + 1, 1);
    g->nc = g->nu = 0;
    if (!g->cm || !g->vm) return -1;
    snref_quat_to_mat(s->jq + 4 * s->rbone[r], g->R);
    for (e = 0; e < m->nC; e++) {
        const unsigned *cv = m->cells + 8 * e;
        for (a = 0; a < 8; a++)
            if (cv[a] < m->nF && g->W[cv[a]] > 0) { g->cm[e] = 1; break; }
        if (!g->cm[e]) continue;
        g->nc++;
        for (a = 0; a < 8; a++)
            if (cv[a] < m->nF && (!s->blend_hold || g->W[cv[a]] > 0)) g->vm[cv[a]] = 1;
    }
    for (a = 0; a < m->nF; a++) g->nu += g->vm[a];
    return 0;
}

static void region_release(blend_region *g) { free(g->cm); free(g->vm); g->cm = g->vm = NULL; }

/* cell_terms over the region's cells with every cell frame = R^r: out_a -= R^r g_a (free a). */
static double region_terms(const snref_state *s, const blend_region *g, const double *p, const double *w, double *out) {
    const snref_model *m = s->m;
    double E = 0, sc = sscale(s);
    unsigned e, a, i, k;
    for (e = 0; e < m->nC; e++) {
        const unsigned *cv = m->cells + 8 * e;
        const double *K = KE(m, e);
        double dd[24], dw[24], gg[24];
        if (!g->cm[e]) continue;
        for (a = 0; a < 8; a++) {
            double u[3], x[3];
            for (k = 0; k < 3; k++) u[k] = p[3 * cv[a] + k] - p[3 * cv[0] + k];
            matT_vec(g->R, u, x);
            for (k = 0; k < 3; k++) dd[3 * a + k] = x[k] - (m->rest[3 * cv[a] + k] - m->rest[3 * cv[0] + k]);
            if (w) {
                for (k = 0; k < 3; k++) u[k] = w[3 * cv[a] + k] - w[3 * cv[0] + k];
                matT_vec(g->R, u, dw + 3 * a);
            } else dw[3 * a] = dw[3 * a + 1] = dw[3 * a + 2] = 0;
        }
        for (i = 0; i < 24; i++) {
            double t = 0, tw = 0;
            for (k = 0; k < 24; k++) { t += K[24 * i + k] * dd[k]; tw += K[24 * i + k] * dw[k]; }
            E += 0.5 * sc * dd[i] * t;
            gg[i] = sc * (t + tw);
        }
        if (out)
            for (a = 0; a < 8; a++) {
                double y[3];
                if (cv[a] >= m->nF) continue;
                mat_vec(g->R, gg + 3 * a, y);
                for (k = 0; k < 3; k++) out[3 * cv[a] + k] -= y[k];
            }
    }
    return E;
}

/* y = A^r x on the region's unknowns: (1+a1) M^ x + (1+b1) K^r x, x zero off the unknowns, other rows 0. */
static void region_amul(const snref_state *s, const blend_region *g, const double *x, double *y) {
    const snref_model *m = s->m;
    unsigned e, a, b, i, k;
    double ca = 1.0 + a1_of(s), sc = sscale(s) * (1.0 + b1_of(s));
    mass_mul(s, x, y, 0);
    for (i = 0; i < 3 * m->nF; i++) y[i] *= ca;
    for (e = 0; e < m->nC; e++) {
        const unsigned *cv = m->cells + 8 * e;
        const double *K = KE(m, e);
        double loc[24];
        if (!g->cm[e]) continue;
        for (b = 0; b < 8; b++) {
            if (cv[b] >= m->nF || !g->vm[cv[b]]) { loc[3 * b] = loc[3 * b + 1] = loc[3 * b + 2] = 0; continue; }
            matT_vec(g->R, x + 3 * cv[b], loc + 3 * b);
        }
        for (a = 0; a < 8; a++) {
            double t[3] = { 0, 0, 0 }, z[3];
            if (cv[a] >= m->nF || !g->vm[cv[a]]) continue;
            for (i = 0; i < 3; i++)
                for (k = 0; k < 24; k++) t[i] += K[24 * (3 * a + i) + k] * loc[k];
            mat_vec(g->R, t, z);
            for (k = 0; k < 3; k++) y[3 * cv[a] + k] += sc * z[k];
        }
    }
    for (i = 0; i < m->nF; i++)
        if (!g->vm[i]) y[3 * i] = y[3 * i + 1] = y[3 * i + 2] = 0;
}

/* PCG on the region's system (block Jacobi R^r P_i R^rT), `iters` iterations or to convergence (0). */
static double region_pcg(snref_state *s, const blend_region *g, const double *b, double *x, unsigned iters) {
    const snref_model *m = s->m;
    unsigned n = 3 * m->nF, it, i, maxit = iters ? iters : 20 * n + 100;
    double *r = malloc(n * sizeof *r), *z = malloc(n * sizeof *z), *d = malloc(n * sizeof *d), *Ad = malloc(n * sizeof *Ad);
    const double *P = precond_blocks(s);
    double rz, bn = sqrt(dot(b, b, n)), res;
#define REGION_PRE(rr, zz) \
    if (m->nIC && P == m->precond) ichol_apply_f(m, g->R, 0, g->vm, rr, zz); /* the runtime's region IC(0) */ \
    else for (i = 0; i < m->nF; i++) { \
        double a_[3], b_[3]; \
        if (!g->vm[i]) { zz[3 * i] = zz[3 * i + 1] = zz[3 * i + 2] = 0; continue; } \
        matT_vec(g->R, rr + 3 * i, a_); mat_vec(P + 9 * i, a_, b_); mat_vec(g->R, b_, zz + 3 * i); \
    }
    region_amul(s, g, x, Ad);
    for (i = 0; i < n; i++) r[i] = b[i] - Ad[i];
    REGION_PRE(r, z)
    memcpy(d, z, n * sizeof *d);
    rz = dot(r, z, n);
    for (it = 0; it < maxit; it++) {
        double dAd, alpha, rz2, beta;
        if (!iters && sqrt(dot(r, r, n)) <= 1e-14 * bn) break;
        region_amul(s, g, d, Ad);
        dAd = dot(d, Ad, n);
        alpha = dAd > 0 ? rz / dAd : 0.0;
        for (i = 0; i < n; i++) { x[i] += alpha * d[i]; r[i] -= alpha * Ad[i]; }
        REGION_PRE(r, z)
        rz2 = dot(r, z, n);
        beta = rz > 0 ? rz2 / rz : 0.0;
        for (i = 0; i < n; i++) d[i] = z[i] + beta * d[i];
        rz = rz2;
    }
#undef REGION_PRE
    region_amul(s, g, x, Ad);
    for (i = 0; i < n; i++) r[i] = b[i] - Ad[i];
    res = bn > 0 ? sqrt(dot(r, r, n)) / bn : 0.0;
    free(r); free(z); free(d); free(Ad);
    return res;
}

/* Steps 5-6 of the blended step: bc = the step's right-hand side without the
 * elastic terms (gravity, rigs, mass terms; free rows); per region add
 * -K^r-terms (force and damping w), solve, merge dv = sum_r W^r dv^r. */
static void blended_solve(snref_state *s, const double *pp, const double *w, const double *bc, double *dv) {
    const snref_model *m = s->m;
    unsigned n = 3 * m->nF, r, a, k;
    double *br = malloc(n * sizeof *br), *x = malloc(n * sizeof *x), *acc = calloc(n, sizeof *acc), worst = 0;
    for (r = 0; r < s->nreg; r++) {
        blend_region g;
        double res;
        if (region_setup(s, r, &g) || g.nu == 0) { region_release(&g); continue; }
        memcpy(br, bc, n * sizeof *br);
        region_terms(s, &g, pp, w, br);
        for (a = 0; a < m->nF; a++)
            for (k = 0; k < 3; k++) {
                if (!g.vm[a]) br[3 * a + k] = 0;
                x[3 * a + k] = (s->warm && g.vm[a]) ? dv[3 * a + k] : 0.0;
            }
        res = region_pcg(s, &g, br, x, s->exact ? 0u : s->iters);
        if (res > worst) worst = res;
        for (a = 0; a < m->nF; a++)
            for (k = 0; k < 3; k++) acc[3 * a + k] += g.W[a] * x[3 * a + k];
        region_release(&g);
    }
    memcpy(dv, acc, n * sizeof *dv);
    s->last_cg_relres = worst;
    free(br); free(x); free(acc);
}

/* Dense LU with partial pivoting (in place), and its solve. */
static int lu_factor(double *A, unsigned *piv, unsigned n) {
    unsigned i, j, k;
    for (k = 0; k < n; k++) {
        unsigned p = k;
        double mx = fabs(A[(size_t)k * n + k]);
        for (i = k + 1; i < n; i++)
            if (fabs(A[(size_t)i * n + k]) > mx) { mx = fabs(A[(size_t)i * n + k]); p = i; }
        piv[k] = p;
        if (mx == 0) return -1;
        if (p != k)
            for (j = 0; j < n; j++) { double t = A[(size_t)k * n + j]; A[(size_t)k * n + j] = A[(size_t)p * n + j]; A[(size_t)p * n + j] = t; }
        for (i = k + 1; i < n; i++) {
            double l = A[(size_t)i * n + k] / A[(size_t)k * n + k];
            A[(size_t)i * n + k] = l;
            if (l != 0)
                for (j = k + 1; j < n; j++) A[(size_t)i * n + j] -= l * A[(size_t)k * n + j];
        }
    }
    return 0;
}
static void lu_solve(const double *A, const unsigned *piv, unsigned n, double *b) {
    unsigned i, j, k;
    for (k = 0; k < n; k++)   /* all row swaps first: lu_factor swaps whole rows, L included */
        if (piv[k] != k) { double t = b[k]; b[k] = b[piv[k]]; b[piv[k]] = t; }
    for (k = 0; k < n; k++)
        for (i = k + 1; i < n; i++) b[i] -= A[(size_t)i * n + k] * b[k];
    for (i = n; i-- > 0;) {
        double t = b[i];
        for (j = i + 1; j < n; j++) t -= A[(size_t)i * n + j] * b[j];
        b[i] = t / A[(size_t)i * n + i];
    }
}

/* snref_static in SNREF_BLENDED: the steady state of the blended step at the
 * fixed pose. With v = 0 the step's merged update is
 *     G(p) = sum_r W^r (A^r)^-1 rr(p),  rr = region force + gravity + rigs
 * (region unknowns), affine in p_F with dG/dp_F = -sum_r W^r (A^r)^-1 K^r.
 * Built densely per region (A^r, K^r assembled from S^_e and M^), one dense
 * LU of J (+ 1e-10 I), then refinement passes (G re-evaluated with the stored region
 * factors) until |G| stops falling. Returns |G(p)| / max(|G(p_start)|, |G of the load
 * alone|) (0 if both are 0). */
typedef struct { unsigned N, *u, *piv; double *A; } blend_fac;

static void region_rhs(snref_state *s, const blend_region *g, const blend_fac *f, double *full, double *loc, int with_force) {
    const snref_model *m = s->m;
    unsigned i, k;
    memset(full, 0, 3 * m->nF * sizeof *full);
    if (with_force) region_terms(s, g, s->p, NULL, full);
    gravity_add(s, full);
    snref_rig_add(s, full);
    for (i = 0; i < f->N / 3; i++)
        for (k = 0; k < 3; k++) loc[3 * i + k] = full[3 * f->u[i] + k];
    lu_solve(f->A, f->piv, f->N, loc);
}

static double blended_static(snref_state *s) {
    const snref_model *m = s->m;
    unsigned n = 3 * m->nF, r, i, j, k, a, b, e, pass, nr = s->nreg;
    double *J = calloc((size_t)n * n, sizeof *J), *G = calloc(n, sizeof *G), *full = malloc(n * sizeof *full), *dx = malloc(n * sizeof *dx);
    unsigned *piv = malloc(n * sizeof *piv);
    int *loc = malloc(m->nV * sizeof *loc), *cloc = malloc(m->nV * sizeof *cloc);
    unsigned *cu = malloc(m->nV * sizeof *cu);
    memset(dx, 0, n * sizeof *dx);
    blend_fac *F = calloc(nr + 1, sizeof *F);
    blend_region *Rg = calloc(nr + 1, sizeof *Rg);
    double g0 = 0, gn = 0, prev = HUGE_VAL, ca = 1.0 + a1_of(s), cb = 1.0 + b1_of(s), sc = sscale(s);
    if (!s->posed) {
        snref_xform *id = calloc(m->nJ, sizeof *id);
        for (i = 0; i < m->nJ; i++) id[i].q[3] = 1;
        snref_set_pose(s, id);
        free(id);
    }
    for (k = m->nF; k < m->nV; k++) { skeleton_pos(s, k, s->p + 3 * k); s->v[3 * k] = s->v[3 * k + 1] = s->v[3 * k + 2] = 0; }
    /* per region: A^r (LU) and the rows W^r (A^r)^-1 K^r of -J */
    for (r = 0; r < nr; r++) {
        blend_fac *f = F + r;
        blend_region *g = Rg + r;
        double *K, *col;
        unsigned N, Nc = 0;
        if (region_setup(s, r, g) || g->nu == 0) continue;
        N = f->N = 3 * g->nu;
        f->u = malloc(g->nu * sizeof *f->u);
        f->piv = malloc(N * sizeof *f->piv);
        f->A = calloc((size_t)N * N, sizeof *f->A);
        for (i = 0; i < m->nV; i++) loc[i] = cloc[i] = -1;
        for (i = 0, j = 0; i < m->nF; i++) if (g->vm[i]) { f->u[j] = i; loc[i] = (int)j++; }
        /* G's columns: every free vertex of the region's cells (with blend_hold the held ones move rr too) */
        for (e = 0; e < m->nC; e++)
            if (g->cm[e])
                for (a = 0; a < 8; a++) {
                    unsigned v = m->cells[8 * e + a];
                    if (v < m->nF && cloc[v] < 0) { cu[Nc] = v; cloc[v] = (int)Nc++; }
                }
        Nc *= 3;
        K = calloc((size_t)N * Nc, sizeof *K);
        col = malloc(N * sizeof *col);
        for (i = 0; i < m->nF; i++) {   /* mass, restricted */
            if (loc[i] < 0) continue;
            for (k = 0; k < 3; k++) f->A[(size_t)(3 * loc[i] + k) * N + 3 * loc[i] + k] += ca * m->mdiag[i];
            for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++) {
                unsigned jj = m->cols[e];
                if (jj >= m->nF || loc[jj] < 0) continue;
                for (k = 0; k < 3; k++) {
                    f->A[(size_t)(3 * loc[i] + k) * N + 3 * loc[jj] + k] += ca * m->moff[e];
                    f->A[(size_t)(3 * loc[jj] + k) * N + 3 * loc[i] + k] += ca * m->moff[e];
                }
            }
        }
        for (e = 0; e < m->nC; e++) {   /* K^r = sum R^r S^_e R^rT over the region's cells */
            const unsigned *cv = m->cells + 8 * e;
            const double *Ke = KE(m, e);
            if (!g->cm[e]) continue;
            for (a = 0; a < 8; a++) {
                if (cv[a] >= m->nF || loc[cv[a]] < 0) continue;
                for (b = 0; b < 8; b++) {
                    double B[9], T[9], C[9];
                    unsigned p, q, t;
                    if (cv[b] >= m->nF) continue;
                    for (p = 0; p < 3; p++) for (q = 0; q < 3; q++) B[3 * p + q] = Ke[24 * (3 * a + p) + 3 * b + q];
                    for (p = 0; p < 3; p++) for (q = 0; q < 3; q++) { T[3 * p + q] = 0; for (t = 0; t < 3; t++) T[3 * p + q] += g->R[3 * p + t] * B[3 * t + q]; }
                    for (p = 0; p < 3; p++) for (q = 0; q < 3; q++) { C[3 * p + q] = 0; for (t = 0; t < 3; t++) C[3 * p + q] += T[3 * p + t] * g->R[3 * q + t]; }
                    for (p = 0; p < 3; p++)
                        for (q = 0; q < 3; q++) {
                            K[(size_t)(3 * loc[cv[a]] + p) * Nc + 3 * (unsigned)cloc[cv[b]] + q] += sc * C[3 * p + q];
                            if (loc[cv[b]] >= 0) f->A[(size_t)(3 * loc[cv[a]] + p) * N + 3 * loc[cv[b]] + q] += cb * sc * C[3 * p + q];
                        }
                }
            }
        }
        if (lu_factor(f->A, f->piv, N)) { free(K); free(col); continue; }
        for (j = 0; j < Nc; j++) {      /* column j of (A^r)^-1 K^r, scattered with W^r into -J */
            unsigned gj = 3 * cu[j / 3] + j % 3;
            for (i = 0; i < N; i++) col[i] = K[(size_t)i * Nc + j];
            lu_solve(f->A, f->piv, N, col);
            for (i = 0; i < N; i++) {
                double wv = g->W[f->u[i / 3]];
                if (wv > 0) J[(size_t)(3 * f->u[i / 3] + i % 3) * n + gj] += wv * col[i];
            }
        }
        free(K); free(col);
    }
    /* J can be singular where K^r is: free flesh that spins about a straight chain of skeleton vertices at no
     * cost (see snref_static). Factor J + 1e-10 I (J is dimensionless, eigenvalues in [0, 1]); the refinement
     * passes converge to the exact fixed point where J is regular, to the one nearest the start where it is not. */
    for (i = 0; i < n; i++) J[(size_t)i * n + i] += 1e-10;
    if (lu_factor(J, piv, n) == 0)
        for (pass = 0; pass < 16; pass++) {
            memset(G, 0, n * sizeof *G);
            for (r = 0; r < nr; r++) {
                double *lv;
                if (!F[r].N) continue;
                lv = malloc(F[r].N * sizeof *lv);
                region_rhs(s, Rg + r, F + r, full, lv, 1);
                for (i = 0; i < F[r].N; i++) G[3 * F[r].u[i / 3] + i % 3] += Rg[r].W[F[r].u[i / 3]] * lv[i];
                if (pass == 0) {   /* the scale: the merged update of the load alone */
                    region_rhs(s, Rg + r, F + r, full, lv, 0);
                    for (i = 0; i < F[r].N; i++) dx[3 * F[r].u[i / 3] + i % 3] += Rg[r].W[F[r].u[i / 3]] * lv[i];
                }
                free(lv);
            }
            gn = sqrt(dot(G, G, n));
#ifdef SNREF_TRACE
            fprintf(stderr, "blended static pass %u: |G| %.3g\n", pass, gn);
#endif
            if (pass == 0) { g0 = fmax(gn, sqrt(dot(dx, dx, n))); if (g0 == 0) break; }
            if (gn <= 1e-15 * g0 || (pass >= 2 && gn >= 0.5 * prev)) break;
            prev = gn;
            memcpy(dx, G, n * sizeof *dx);      /* -J dx = G  (J stored negated) */
            lu_solve(J, piv, n, dx);
            for (i = 0; i < n; i++) s->p[i] += dx[i];
        }
    else gn = g0 = 1;
    memset(s->v, 0, 3 * m->nF * sizeof *s->v);
    memset(s->dv, 0, 3 * m->nF * sizeof *s->dv);
    for (r = 0; r < nr; r++) { free(F[r].u); free(F[r].piv); free(F[r].A); region_release(Rg + r); }
    free(F); free(Rg); free(J); free(G); free(full); free(dx); free(piv); free(loc); free(cloc); free(cu);
    s->blend_fixres = g0 > 0 ? gn / g0 : 0;
    return s->blend_fixres;
}

void snref_step(snref_state *s) {
    const snref_model *m = s->m;
    unsigned i, k, nF = m->nF, nV = m->nV;
    double *b = WK(s, S_B), *vstar = WK(s, S_VSTAR), *w = WK(s, S_W), *tmp = WK(s, S_TMP), *pp = WK(s, S_PP);
    double *pnewS = WK(s, S_PNEW), *vnewS = WK(s, S_VNEW), *dvS = WK(s, S_DVS);
    double a1 = a1_of(s), b1 = b1_of(s);
    if (!s->posed) { /* stepping at the rest pose without set_pose: identity pose */
        snref_xform *id = calloc(m->nJ, sizeof *id);
        for (i = 0; i < m->nJ; i++) id[i].q[3] = 1;
        snref_set_pose(s, id);
        free(id);
    }
    /* 3. skeleton: new positions and velocities */
    for (k = nF; k < nV; k++) {
        skeleton_pos(s, k, pnewS + 3 * k);
        for (i = 0; i < 3; i++) {
            vnewS[3 * k + i] = pnewS[3 * k + i] - s->p[3 * k + i];
            dvS[3 * k + i] = vnewS[3 * k + i] - s->v[3 * k + i];
        }
    }
    memcpy(pp, s->p, 3 * nF * sizeof *pp);
    memcpy(pp + 3 * nF, pnewS + 3 * nF, 3 * (nV - nF) * sizeof *pp);
    /* 4-5. elastic force and -K~ w, per cell; w_F = (1+b1) v_F, w_S = b1 v'_S */
    for (i = 0; i < 3 * nF; i++) { vstar[i] = s->v[i]; w[i] = (1.0 + b1) * s->v[i]; }
    for (i = 3 * nF; i < 3 * nV; i++) { vstar[i] = vnewS[i]; w[i] = b1 * vnewS[i]; }
    memset(b, 0, 3 * nF * sizeof *b);
    if (s->mode == SNREF_BLENDED) s->e_el = cell_terms(s, pp, NULL, NULL);   /* the elastic terms come per region in step 6; E_el (health) at the warped frames */
    else if (s->force == SNREF_FORCE_CELL) s->e_el = cell_terms(s, pp, w, b);
    else {
        vertex_force(s, pp, b);
        stiff_mul(s, w, b, 1, 0, -1.0);
        s->e_el = cell_terms(s, pp, NULL, NULL);   /* the element energy as a measure only */
    }
    gravity_add(s, b);
    snref_rig_add(s, b);
    mass_mul(s, vstar, tmp, 1);
    for (i = 0; i < 3 * nF; i++) b[i] -= a1 * tmp[i];
    /* M^_FS (v'_S - v_S): mass product with the free part zeroed */
    memset(dvS, 0, 3 * nF * sizeof *dvS);
    mass_mul(s, dvS, tmp, 1);
    for (i = 0; i < 3 * nF; i++) b[i] -= tmp[i];
    /* health: kinetic energy of the starting v, lumped mass (step 9) */
    s->e_kin = 0;
    for (i = 0; i < nF; i++) s->e_kin += 0.5 * m->mlump[i] * dot(s->v + 3 * i, s->v + 3 * i, 3);
    for (i = 3 * nF; i < 3 * nV; i++) { s->p[i] = pnewS[i]; s->v[i] = vnewS[i]; }
    /* 6. solve */
    {
        double *x = s->dv;
        if (!s->warm) memset(x, 0, 3 * nF * sizeof *x);
        if (s->solve_hook) s->solve_hook(s->hook_ctx, s, b, x);
        if (s->mode == SNREF_BLENDED) blended_solve(s, pp, w, b, x);   /* rows and precond_hook not applied (snref.h) */
        else if (s->nrows) {   /* constrained: the filtered PCG (to convergence in exact mode) */
            rowsys q;
            unsigned j;
            rows_build(s, &q, vstar);
            for (s->rows_kept = 0, j = 0; j < q.m; j++) s->rows_kept += (unsigned)q.kept[j];
            s->cg_rows = &q;
            s->last_cg_relres = pcg(s, b, x, s->exact ? 0u : s->iters);
            s->cg_rows = NULL;
            rows_free(&q);
        } else if (s->exact && exact_direct(s, b, x) == 0) s->last_cg_relres = 0;
        else s->last_cg_relres = pcg(s, b, x, s->exact ? 0u : s->iters);
    }
    /* 7. update */
    for (i = 0; i < 3 * nF; i++) { s->v[i] += s->dv[i]; s->p[i] += s->v[i]; }
    limits_and_health(s);
    s->steps++;
}

void snref_get_lattice(const snref_state *s, double *out) {
    const snref_model *m = s->m;
    unsigned i;
    for (i = 0; i < 3 * m->nV; i++) out[i] = s->p[i] * m->unit;
}

void snref_get_skinned(const snref_state *s, double *out) {
    const snref_model *m = s->m;
    unsigned i, k;
    for (i = 0; i < m->nV; i++) {
        double y[3];
        mat_vec(s->R + 9 * i, m->rest + 3 * i, y);
        for (k = 0; k < 3; k++) out[3 * i + k] = (y[k] + s->c[3 * i + k]) * m->unit;
    }
}

void snref_surface_from_lattice(const snref_model *m, const double *lat, double *out) {
    unsigned i, k, c;
    for (i = 0; i < m->nS; i++) {
        const unsigned *cell = m->cells + 8 * m->ecell[i];
        const double *t = m->et + 3 * i;
        out[3 * i] = out[3 * i + 1] = out[3 * i + 2] = 0;
        for (k = 0; k < 8; k++) {
            double w = ((k & 1) ? t[0] : 1 - t[0]) * ((k >> 1 & 1) ? t[1] : 1 - t[1]) * ((k >> 2 & 1) ? t[2] : 1 - t[2]);
            for (c = 0; c < 3; c++) out[3 * i + c] += w * lat[3 * cell[k] + c];
        }
    }
}

double snref_surface_volume(const snref_model *m, const double *p) {
    double v = 0;
    unsigned t;
    for (t = 0; t < m->nT; t++) {
        const double *a = p + 3 * m->tris[3 * t], *b = p + 3 * m->tris[3 * t + 1], *c = p + 3 * m->tris[3 * t + 2];
        v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return v / 6;
}

double snref_cells_volume(const snref_model *m, const double *lat, const double e[3], double rad) {
    static const int tet[6][2] = { { 1, 3 }, { 3, 2 }, { 2, 6 }, { 6, 4 }, { 4, 5 }, { 5, 1 } };
    double v = 0;
    unsigned c, k;
    for (c = 0; c < m->nC; c++) {
        const unsigned *cv = m->cells + 8 * c;
        double ctr[3] = { 0, 0, 0 }, d2 = 0;
        for (k = 0; k < 8; k++) { int q; for (q = 0; q < 3; q++) ctr[q] += (m->rest[3 * cv[k] + q] + m->jrest[q]) * m->unit / 8; }
        for (k = 0; k < 3; k++) d2 += (ctr[k] - e[k]) * (ctr[k] - e[k]);
        if (d2 > rad * rad) continue;
        for (k = 0; k < 6; k++) {
            const double *p0 = lat + 3 * cv[0], *p1 = lat + 3 * cv[tet[k][0]], *p2 = lat + 3 * cv[tet[k][1]], *p3 = lat + 3 * cv[7];
            double a[3], b[3], d[3];
            int q;
            for (q = 0; q < 3; q++) { a[q] = p1[q] - p0[q]; b[q] = p2[q] - p0[q]; d[q] = p3[q] - p0[q]; }
            v += (a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) + a[2] * (b[0] * d[1] - b[1] * d[0])) / 6;
        }
    }
    return v;
}

void snref_get_surface(const snref_state *s, double *out) {
    double *lat = malloc(3 * (size_t)s->m->nV * sizeof *lat);
    snref_get_lattice(s, lat);
    snref_surface_from_lattice(s->m, lat, out);
    free(lat);
}

/* ---------------- static equilibrium (seed 003 eq. 10) ---------------- */

/* y = H x over free rows and columns (H: which = 0 of band_build). */
static void hess_mul(const snref_state *s, const double *x, double *y) {
    memset(y, 0, 3 * s->m->nF * sizeof *y);
    stiff_mul(s, x, y, 0, 1, 1.0);
}

/* Dense LU with partial pivoting, solve A x = b in place (b -> x). */
static int dense_solve(double *A, double *b, unsigned n) {
    unsigned i, j, k;
    for (k = 0; k < n; k++) {
        unsigned piv = k;
        double mx = fabs(A[(size_t)k * n + k]);
        for (i = k + 1; i < n; i++)
            if (fabs(A[(size_t)i * n + k]) > mx) { mx = fabs(A[(size_t)i * n + k]); piv = i; }
        if (mx == 0) return -1;
        if (piv != k) {
            for (j = 0; j < n; j++) { double t = A[(size_t)k * n + j]; A[(size_t)k * n + j] = A[(size_t)piv * n + j]; A[(size_t)piv * n + j] = t; }
            { double t = b[k]; b[k] = b[piv]; b[piv] = t; }
        }
        for (i = k + 1; i < n; i++) {
            double l = A[(size_t)i * n + k] / A[(size_t)k * n + k];
            if (l == 0) continue;
            A[(size_t)i * n + k] = l;
            for (j = k + 1; j < n; j++) A[(size_t)i * n + j] -= l * A[(size_t)k * n + j];
            b[i] -= l * b[k];
        }
    }
    for (i = n; i-- > 0;) {
        double t = b[i];
        for (j = i + 1; j < n; j++) t -= A[(size_t)i * n + j] * b[j];
        b[i] = t / A[(size_t)i * n + i];
    }
    return 0;
}

/* BiCGSTAB for H x = r, right block-Jacobi preconditioning with R_i (S^_ii)^-1 R_i^T. */
static void bicgstab(snref_state *s, const double *rhs, double *x, double tol) {
    const snref_model *m = s->m;
    unsigned n = 3 * m->nF, i, it;
    double *r = malloc(n * sizeof *r), *r0 = malloc(n * sizeof *r), *pv = calloc(n, sizeof *r),
           *v = calloc(n, sizeof *r), *ph = malloc(n * sizeof *r), *sv = malloc(n * sizeof *r),
           *sh = malloc(n * sizeof *r), *t = malloc(n * sizeof *r), *Pi = malloc(9 * (size_t)m->nF * sizeof *r);
    double rho = 1, alpha = 1, omega = 1, bn = sqrt(dot(rhs, rhs, n));
    for (i = 0; i < m->nF; i++) {
        double A[9];
        unsigned k;
        for (k = 0; k < 9; k++) A[k] = sscale(s) * m->sdiag[9 * i + k];
        if (mat_inv(A, Pi + 9 * i) != 0) memcpy(Pi + 9 * i, I3, sizeof I3);
    }
    hess_mul(s, x, t);
    for (i = 0; i < n; i++) r[i] = rhs[i] - t[i];
    memcpy(r0, r, n * sizeof *r);
    for (it = 0; it < 20 * n + 1000; it++) {
        double rho1 = dot(r0, r, n), beta, tt;
        if (sqrt(dot(r, r, n)) <= tol * bn) break;
        beta = (rho1 / rho) * (alpha / omega);
        for (i = 0; i < n; i++) pv[i] = r[i] + beta * (pv[i] - omega * v[i]);
        precond_apply(s, Pi, pv, ph);
        hess_mul(s, ph, v);
        alpha = rho1 / dot(r0, v, n);
        for (i = 0; i < n; i++) sv[i] = r[i] - alpha * v[i];
        precond_apply(s, Pi, sv, sh);
        hess_mul(s, sh, t);
        tt = dot(t, t, n);
        omega = tt > 0 ? dot(t, sv, n) / tt : 0;
        for (i = 0; i < n; i++) { x[i] += alpha * ph[i] + omega * sh[i]; r[i] = sv[i] - omega * t[i]; }
        rho = rho1;
        if (omega == 0) break;
    }
    free(r); free(r0); free(pv); free(v); free(ph); free(sv); free(sh); free(t); free(Pi);
}

/* The static solve. CELL model: with the skeleton fixed and the frames fixed
 * by the pose, d_e is affine in p, so Pi(p_F) = E_el - load.p_F is exactly
 * quadratic; its gradient vanishes where
 *     K~_FF p_F = -K~_FS p_S + sum_e (R_e S^_e (x_b - x_b0))_F + load_F,
 * (K~ = sum_e R_e S^_e R_e^T when S^_e's null space holds the translations:
 * then R_e^T p_b0 drops out), i.e. one Newton step from any p_F,
 * H delta = f(p) + load with H = K~_FF, is the exact minimum. VERTEX model:
 * eq. 7 is affine in p_F too; H = -J (row i: R_i S^_ij R_i^T).
 * H can be singular: free flesh around a straight chain of skeleton vertices
 * spins about it at no cost (no twist term since format 2.0). So each pass
 * solves (H + eps D) delta = f + load, D = the mass diagonal, eps = 1e-10 of
 * H's scale: iterative refinement converges to the exact minimum where H is
 * regular (rate ~ eps cond H), and among the minimizers to the one nearest
 * the start (the skinned shape) instead of one picked by round-off. */
double snref_static(snref_state *s, unsigned dense_max) {
    const snref_model *m = s->m;
    unsigned n = 3 * m->nF, i, k, pass;
    double *r = malloc(n * sizeof *r), *dx = malloc(n * sizeof *dx), g0, res = 0, prev = HUGE_VAL;
    double *A = NULL, hs = 0, ms = 0, reg;
    snref_band *B = NULL;
    if (s->mode == SNREF_BLENDED) { free(r); free(dx); return blended_static(s); }
    if (!s->posed) {
        snref_xform *id = calloc(m->nJ, sizeof *id);
        for (i = 0; i < m->nJ; i++) id[i].q[3] = 1;
        snref_set_pose(s, id);
        free(id);
    }
    for (i = 0; i < m->nF; i++) {
        double t = sscale(s) * (m->sdiag[9 * i] + m->sdiag[9 * i + 4] + m->sdiag[9 * i + 8]) / 3;
        if (t > hs) hs = t;
        if (m->mdiag[i] > ms) ms = m->mdiag[i];
    }
    reg = ms > 0 ? 1e-10 * hs / ms : 0;
    for (k = m->nF; k < m->nV; k++) { skeleton_pos(s, k, s->p + 3 * k); s->v[3 * k] = s->v[3 * k + 1] = s->v[3 * k + 2] = 0; }
    snref_residual(s, r);
    g0 = sqrt(dot(r, r, n));
    if (n <= dense_max) {
        double *e = calloc(n, sizeof *e), *col = malloc(n * sizeof *col);
        A = malloc((size_t)n * n * sizeof *A);
        for (i = 0; i < n; i++) {           /* columns of H + eps D */
            e[i] = 1; hess_mul(s, e, col); e[i] = 0;
            for (k = 0; k < n; k++) A[(size_t)k * n + i] = col[k];
            A[(size_t)i * n + i] += reg * m->mdiag[i / 3];
        }
        free(e); free(col);
    } else B = band_build(s, 0, reg, (size_t)60000000);
    for (pass = 0; pass < 12; pass++) {
        double rn;
        snref_residual(s, r);
        rn = sqrt(dot(r, r, n));
        if (rn <= 1e-15 * g0 || (pass >= 3 && rn >= 0.5 * prev)) break;   /* converged, or refinement stopped helping */
        prev = rn;
        memset(dx, 0, n * sizeof *dx);
        if (A) {
            double *Ac = malloc((size_t)n * n * sizeof *Ac);
            memcpy(Ac, A, (size_t)n * n * sizeof *Ac);
            memcpy(dx, r, n * sizeof *dx);
            dense_solve(Ac, dx, n);
            free(Ac);
        } else if (B) band_solve(B, r, dx);
        else bicgstab(s, r, dx, 1e-13);
        for (i = 0; i < n; i++) s->p[i] += dx[i];
    }
    snref_residual(s, r);
    res = g0 > 0 ? sqrt(dot(r, r, n)) / g0 : 0;
    memset(s->v, 0, 3 * m->nF * sizeof *s->v);
    memset(s->dv, 0, 3 * m->nF * sizeof *s->dv);
    free(A); band_free(B);
    free(r); free(dx);
    return res;
}

void snref_energy(const snref_state *s, double *kinetic, double *elastic) {
    const snref_model *m = s->m;
    double *t = malloc(3 * (size_t)m->nV * sizeof *t);
    mass_mul(s, s->v, t, 0);
    *kinetic = 0.5 * dot(s->v, t, 3 * m->nF);
    *elastic = cell_terms(s, s->p, NULL, NULL);
    free(t);
}

/* Solve the static system for an arbitrary load: H x = load (free rows,
 * internal units) at the current frames; banded LU, or BiCGSTAB if the band is too large. */
void snref_solve_load(snref_state *s, const double *load, double *x) {
    snref_band *B = band_build(s, 0, 0.0, (size_t)60000000);
    memset(x, 0, 3 * s->m->nF * sizeof *x);
    if (B) band_solve(B, load, x); else bicgstab(s, load, x, 1e-13);
    band_free(B);
}

struct snref_band *snref_factor(snref_state *s) { return band_build(s, 0, 0.0, (size_t)60000000); }
void snref_factor_solve(const struct snref_band *B, const double *load, double *x) {
    memset(x, 0, 3 * (size_t)B->nF * sizeof *x);
    band_solve(B, load, x);
}
void snref_factor_free(struct snref_band *B) { band_free(B); }
void snref_hess_mul(const snref_state *s, const double *x, double *y) { hess_mul(s, x, y); }

/* y = M^_FF x (free rows, free columns). */
void snref_mass_mul(const snref_state *s, const double *x, double *y) { mass_mul(s, x, y, 0); }
