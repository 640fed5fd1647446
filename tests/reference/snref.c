/* snref.c -- double-precision reference of runtime/NUMERICS.md.
 * Shares no arithmetic with the runtime: only sn_format.h constants. */
#include "snref.h"
#include "../../runtime/src/sn_format.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct snref_band snref_band;
static snref_band *band_build(snref_state *s, int which, size_t max_doubles);
static void band_solve(const snref_band *B, const double *r, double *x);
static void band_free(snref_band *B);
static const double *band_key(const snref_band *B);

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
static void mat_mul_(const double A[9], const double B[9], double C[9]) {
    int i, j;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}
/* C = A B^T */
static void mat_mulT_(const double A[9], const double B[9], double C[9]) {
    int i, j;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
            C[3 * i + j] = A[3 * i] * B[3 * j] + A[3 * i + 1] * B[3 * j + 1] + A[3 * i + 2] * B[3 * j + 2];
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
/* Shorter arc; sin formula, linear blend when nearly parallel. */
void snref_quat_slerp(const double a[4], const double b[4], double t, double o[4]) {
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], bb[4], wa, wb, n;
    int k;
    for (k = 0; k < 4; k++) bb[k] = d < 0 ? -b[k] : b[k];
    d = fabs(d);
    if (d > 1.0 - 1e-12) { wa = 1.0 - t; wb = t; }
    else {
        double th = acos(d), st = sin(th);
        wa = sin((1.0 - t) * th) / st; wb = sin(t * th) / st;
    }
    for (k = 0; k < 4; k++) o[k] = wa * a[k] + wb * bb[k];
    n = sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2] + o[3] * o[3]);
    for (k = 0; k < 4; k++) o[k] /= n;
}
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

/* Read real number idx of an array at p; fixed values are scaled by 2^-q. */
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

int snref_load(snref_model *m, const void *data, size_t size, char *err, size_t errn) {
    const unsigned char *d = (const unsigned char *)data;
    rdr r;
    unsigned sec_off[SN_SEC_COUNT], sec_cnt[SN_SEC_COUNT], i, k;
    uint32_t total;
    unsigned R;
    memset(m, 0, sizeof *m);
    if (size < SN_HEADER_BYTES) FAIL("truncated header");
    if (d[0] != SN_MAGIC0 || d[1] != SN_MAGIC1 || d[2] != SN_MAGIC2 || d[3] != SN_MAGIC3) FAIL("bad magic");
    if (rd_u16(d + SN_H_VER_MAJOR) != SN_FORMAT_MAJOR) FAIL("version");
    if (rd_u32(d + SN_H_ENDIAN) != SN_ENDIAN_MARK) FAIL("endian");
    total = rd_u32(d + SN_H_TOTAL_SIZE);
    if (total > size || total < SN_HEADER_BYTES) FAIL("total size %u > %zu", (unsigned)total, size);
    if (snref_crc32(d + 16, total - 16) != rd_u32(d + SN_H_CRC32)) FAIL("crc mismatch");
    m->flavour = d[SN_H_FLAVOUR];
    m->real_size = R = d[SN_H_REAL_SIZE];
    if (m->flavour > 2 || R != (m->flavour == 2 ? 8u : 4u)) FAIL("flavour %d real size %u", m->flavour, R);
    r.d = d; r.flavour = m->flavour; r.rs = R;
    m->nV = rd_u32(d + SN_H_N_VERTICES); m->nF = rd_u32(d + SN_H_N_FREE);
    m->nC = rd_u32(d + SN_H_N_CELLS); m->nJ = rd_u32(d + SN_H_N_JOINTS);
    m->nS = rd_u32(d + SN_H_N_SURFACE); m->nT = rd_u32(d + SN_H_N_TRIANGLES);
    m->nnz = rd_u32(d + SN_H_N_OFFDIAG);
    m->cg_default = rd_u16(d + SN_H_CG_DEFAULT); m->cg_max = rd_u16(d + SN_H_CG_MAX);
    m->len_shift = (int)(signed char)d[SN_H_LEN_SHIFT];
    m->frac_S = d[SN_H_FRAC_S]; m->frac_M = d[SN_H_FRAC_M]; m->frac_P = d[SN_H_FRAC_P];
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
    }
    {
        const unsigned expect_cnt[SN_SEC_COUNT] = { m->nJ, m->nJ, m->nV, m->nV, m->nF, m->nF, m->nF, m->nF,
            m->nF + 1, m->nnz, m->nnz, m->nnz, m->nC, m->nS, m->nT };
        const unsigned expect_el[SN_SEC_COUNT] = { SN_ELEM_JOINTS(R), SN_ELEM_JOINT_NAMES, SN_ELEM_REST(R),
            SN_ELEM_FRAMES, SN_ELEM_MDIAG(R), SN_ELEM_SDIAG(R), SN_ELEM_PRECOND(R), SN_ELEM_MLUMP(R),
            SN_ELEM_ROWPTR, SN_ELEM_COLS, SN_ELEM_MOFF(R), SN_ELEM_SOFF(R), SN_ELEM_CELLS, SN_ELEM_EMBED,
            SN_ELEM_TRIS };
        for (i = 0; i < SN_SEC_COUNT; i++) {
            const unsigned char *e = d + SN_H_SECTIONS + i * SN_SECTION_ENTRY;
            uint32_t off = rd_u32(e), sz = rd_u32(e + 4), cnt = rd_u32(e + 8), el = rd_u32(e + 12);
            if (cnt != expect_cnt[i] || el != expect_el[i] || (uint64_t)cnt * el != sz
                || (uint64_t)off + sz > total)
                FAIL("section %u: off %u size %u count %u elem %u", i, (unsigned)off, (unsigned)sz,
                     (unsigned)cnt, (unsigned)el);
            sec_off[i] = off; sec_cnt[i] = cnt;
        }
    }
    (void)sec_cnt;
#define ALLOC(p, n) do { p = calloc((size_t)(n) + 1, sizeof *(p)); if (!p) FAIL("out of memory"); } while (0)
    ALLOC(m->jparent, m->nJ); ALLOC(m->jrest, 3 * m->nJ); ALLOC(m->jname, m->nJ);
    ALLOC(m->rest, 3 * m->nV); ALLOC(m->fb1, m->nV); ALLOC(m->fb2, m->nV); ALLOC(m->fw, m->nV);
    ALLOC(m->mdiag, m->nF); ALLOC(m->sdiag, 9 * m->nF); ALLOC(m->precond, 9 * m->nF); ALLOC(m->mlump, m->nF);
    ALLOC(m->rowptr, m->nF + 1); ALLOC(m->cols, m->nnz); ALLOC(m->moff, m->nnz); ALLOC(m->soff, 9 * m->nnz);
    ALLOC(m->cells, 8 * m->nC); ALLOC(m->ecell, m->nS); ALLOC(m->et, 3 * m->nS); ALLOC(m->tris, 3 * m->nT);
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
        if ((unsigned)m->fb1[i] >= m->nJ || (unsigned)m->fb2[i] >= m->nJ) FAIL("frame bones of vertex %u", i);
    }
    for (i = 0; i < m->nF; i++) {
        static const int sym[6][2] = { { 0, 0 }, { 1, 1 }, { 2, 2 }, { 0, 1 }, { 0, 2 }, { 1, 2 } };
        m->mdiag[i] = rd_real(&r, d + sec_off[SN_SEC_MDIAG] + i * R, (int)m->frac_M);
        m->mlump[i] = rd_real(&r, d + sec_off[SN_SEC_MLUMP] + i * R, (int)m->frac_M);
        for (k = 0; k < 6; k++) {
            double s = rd_real(&r, d + sec_off[SN_SEC_SDIAG] + (6 * i + k) * R, (int)m->frac_S);
            double p = rd_real(&r, d + sec_off[SN_SEC_PRECOND] + (6 * i + k) * R, (int)m->frac_P);
            int a = sym[k][0], b = sym[k][1];
            m->sdiag[9 * i + 3 * a + b] = m->sdiag[9 * i + 3 * b + a] = s;
            m->precond[9 * i + 3 * a + b] = m->precond[9 * i + 3 * b + a] = p;
        }
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
    for (i = 0; i < m->nnz; i++) {
        m->moff[i] = rd_real(&r, d + sec_off[SN_SEC_MOFF] + i * R, (int)m->frac_M);
        for (k = 0; k < 9; k++) m->soff[9 * i + k] = rd_real(&r, d + sec_off[SN_SEC_SOFF] + (9 * i + k) * R, (int)m->frac_S);
    }
    for (i = 0; i < 8 * m->nC; i++) {
        m->cells[i] = rd_u16(d + sec_off[SN_SEC_CELLS] + 2 * i);
        if (m->cells[i] >= m->nV) FAIL("cell corner");
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
    free(m->mdiag); free(m->sdiag); free(m->precond); free(m->mlump); free(m->rowptr); free(m->cols);
    free(m->moff); free(m->soff); free(m->cells); free(m->ecell); free(m->et); free(m->tris);
    memset(m, 0, sizeof *m);
}

/* ---------------- state ---------------- */

/* scratch layout in s->work (each nV*3 unless noted) */
enum { W_F, W_B, W_R, W_Z, W_D, W_AD, W_T1, W_T2, W_WV, W_X, W_PRE /* nF*9 */, W_COUNT = 20 };
#define WK(s, k) ((s)->work + (size_t)(k) * 3 * (s)->m->nV)

int snref_init(snref_state *s, const snref_model *m) {
    memset(s, 0, sizeof *s);
    s->m = m;
    s->p = calloc(3 * (size_t)m->nV, sizeof *s->p);
    s->v = calloc(3 * (size_t)m->nV, sizeof *s->v);
    s->dv = calloc(3 * (size_t)m->nV, sizeof *s->dv);
    s->R = calloc(9 * (size_t)m->nV, sizeof *s->R);
    s->c = calloc(3 * (size_t)m->nV, sizeof *s->c);
    s->jq = calloc(4 * (size_t)m->nJ, sizeof *s->jq);
    s->jt = calloc(3 * (size_t)m->nJ, sizeof *s->jt);
    s->work = calloc(3 * (size_t)m->nV * W_COUNT, sizeof *s->work);
    if (!s->p || !s->v || !s->dv || !s->R || !s->c || !s->jq || !s->jt || !s->work) { snref_release(s); return -1; }
    s->iters = m->cg_default;
    s->warm = 1;
    s->gscale = 1.0;
    s->hscale = 1.0;
    s->first_pose_moves_free = 1;
    snref_reset(s);
    return 0;
}

void snref_release(snref_state *s) {
    band_free(s->band);
    free(s->p); free(s->v); free(s->dv); free(s->R); free(s->c); free(s->jq); free(s->jt); free(s->work);
    memset(s, 0, sizeof *s);
}

static void compute_frames(snref_state *s) {
    const snref_model *m = s->m;
    unsigned i, root = 0, k;
    for (i = 0; i < m->nJ; i++) if (m->jparent[i] < 0) { root = i; break; }
    for (i = 0; i < m->nV; i++) {
        double q[4], w = m->fw[i];
        int b1 = m->fb1[i], b2 = m->fb2[i];
        if (s->mode == SNREF_UNWARPED) {
            static const double I[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
            memcpy(s->R + 9 * i, I, sizeof I);
            for (k = 0; k < 3; k++) s->c[3 * i + k] = s->jt[3 * root + k];
            continue;
        }
        snref_quat_slerp(s->jq + 4 * b1, s->jq + 4 * b2, w, q);
        snref_quat_to_mat(q, s->R + 9 * i);
        for (k = 0; k < 3; k++) s->c[3 * i + k] = (1.0 - w) * s->jt[3 * b1 + k] + w * s->jt[3 * b2 + k];
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
    unsigned j;
    unsigned root = 0;
    for (j = 0; j < m->nJ; j++) if (m->jparent[j] < 0) { root = j; break; }
    for (j = 0; j < 3 * m->nV; j++) s->p[j] = m->rest[j] + m->jrest[3 * root + j % 3];
    memset(s->v, 0, 3 * m->nV * sizeof *s->v);
    memset(s->dv, 0, 3 * m->nV * sizeof *s->dv);
    for (j = 0; j < m->nJ; j++) {
        s->jq[4 * j] = s->jq[4 * j + 1] = s->jq[4 * j + 2] = 0; s->jq[4 * j + 3] = 1;
        s->jt[3 * j] = s->jt[3 * j + 1] = s->jt[3 * j + 2] = 0;
    }
    s->posed = 0;
    s->steps = 0;
    compute_frames(s);
}

void snref_set_pose(snref_state *s, const snref_xform *pose) {
    const snref_model *m = s->m;
    unsigned j, k;
    unsigned root = 0;
    for (j = 0; j < m->nJ; j++) if (m->jparent[j] < 0) { root = j; break; }
    /* Poses act on model space; internal positions are relative to the root
     * joint's rest x0, so in internal units x -> R x + (R x0 + t)/U. */
    for (j = 0; j < m->nJ; j++) {
        double Rj[9], y[3];
        for (k = 0; k < 4; k++) s->jq[4 * j + k] = pose[j].q[k];
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

/* Baked coefficients after the optional time-step rescale. */
static double sscale(const snref_state *s) { return s->hscale * s->hscale; }
static double a1_of(const snref_state *s) { return s->m->a1 * s->hscale; }
static double b1_of(const snref_state *s) { return s->m->b1 / s->hscale; }

/* y_F = sum_j R_i S^_ij R_j^T x_j over j in F (and S if with_skel), free rows only. */
static void ktilde_mul(const snref_state *s, const double *x, double *y, int with_skel) {
    const snref_model *m = s->m;
    double *loc = WK(s, W_T1);
    unsigned i, e, n = with_skel ? m->nV : m->nF;
    double sc = sscale(s);
    for (i = 0; i < n; i++) matT_vec(s->R + 9 * i, x + 3 * i, loc + 3 * i);
    memset(y, 0, 3 * m->nF * sizeof *y);
    {
        double *acc = WK(s, W_T2);
        memset(acc, 0, 3 * m->nF * sizeof *acc);
        for (i = 0; i < m->nF; i++) {
            double t[3];
            mat_vec(m->sdiag + 9 * i, loc + 3 * i, t);
            acc[3 * i] += t[0]; acc[3 * i + 1] += t[1]; acc[3 * i + 2] += t[2];
            for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++) {
                unsigned j = m->cols[e];
                if (j >= n) continue;
                mat_vec(m->soff + 9 * e, loc + 3 * j, t);
                acc[3 * i] += t[0]; acc[3 * i + 1] += t[1]; acc[3 * i + 2] += t[2];
                if (j < m->nF) {
                    matT_vec(m->soff + 9 * e, loc + 3 * i, t);
                    acc[3 * j] += t[0]; acc[3 * j + 1] += t[1]; acc[3 * j + 2] += t[2];
                }
            }
        }
        for (i = 0; i < m->nF; i++) {
            mat_vec(s->R + 9 * i, acc + 3 * i, y + 3 * i);
            y[3 * i] *= sc; y[3 * i + 1] *= sc; y[3 * i + 2] *= sc;
        }
    }
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

/* Warped elastic force (seed 003 eq. 7), free rows, at positions p. */
static void warped_force(const snref_state *s, const double *p, double *f) {
    const snref_model *m = s->m;
    double *acc = WK(s, W_T2);
    unsigned i, e, k;
    double sc = sscale(s);
    memset(acc, 0, 3 * m->nF * sizeof *acc);
    for (i = 0; i < m->nF; i++) {
        const double *Ri = s->R + 9 * i, *ci = s->c + 3 * i;
        double dd[3], t[3], u[3];
        for (k = 0; k < 3; k++) u[k] = p[3 * i + k] - ci[k];
        matT_vec(Ri, u, dd);
        for (k = 0; k < 3; k++) dd[k] -= m->rest[3 * i + k];
        mat_vec(m->sdiag + 9 * i, dd, t);
        for (k = 0; k < 3; k++) acc[3 * i + k] += t[k];
        for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++) {
            unsigned j = m->cols[e];
            for (k = 0; k < 3; k++) u[k] = p[3 * j + k] - ci[k];
            matT_vec(Ri, u, dd);                       /* d_ij */
            for (k = 0; k < 3; k++) dd[k] -= m->rest[3 * j + k];
            mat_vec(m->soff + 9 * e, dd, t);
            for (k = 0; k < 3; k++) acc[3 * i + k] += t[k];
            if (j < m->nF) {
                const double *Rj = s->R + 9 * j, *cj = s->c + 3 * j;
                for (k = 0; k < 3; k++) u[k] = p[3 * i + k] - cj[k];
                matT_vec(Rj, u, dd);                   /* d_ji */
                for (k = 0; k < 3; k++) dd[k] -= m->rest[3 * i + k];
                matT_vec(m->soff + 9 * e, dd, t);
                for (k = 0; k < 3; k++) acc[3 * j + k] += t[k];
            }
        }
    }
    for (i = 0; i < m->nF; i++) {
        mat_vec(s->R + 9 * i, acc + 3 * i, f + 3 * i);
        for (k = 0; k < 3; k++) f[3 * i + k] *= -sc;
    }
}

static void gravity_add(const snref_state *s, double *f) {
    const snref_model *m = s->m;
    unsigned i, k;
    double g = s->gscale * sscale(s);
    for (i = 0; i < m->nF; i++)
        for (k = 0; k < 3; k++) f[3 * i + k] += m->mlump[i] * m->grav[k] * g;
}

void snref_residual(const snref_state *s, double *out) {
    warped_force(s, s->p, out);
    gravity_add(s, out);
}

static double dot(const double *a, const double *b, unsigned n) {
    double r = 0;
    unsigned i;
    for (i = 0; i < n; i++) r += a[i] * b[i];
    return r;
}

/* A x = (1+a1) M^_FF x + (1+b1) K~_FF x */
static void a_mul(const snref_state *s, const double *x, double *y) {
    const snref_model *m = s->m;
    double *t = WK(s, W_X);
    unsigned i, n = 3 * m->nF;
    double ca = 1.0 + a1_of(s), cb = 1.0 + b1_of(s);
    mass_mul(s, x, y, 0);
    ktilde_mul(s, x, t, 0);
    for (i = 0; i < n; i++) y[i] = ca * y[i] + cb * t[i];
}

/* Preconditioner blocks P_i (rest frame), from the blob unless h is rescaled. */
static const double *precond_blocks(snref_state *s) {
    const snref_model *m = s->m;
    double *P = WK(s, W_PRE);
    unsigned i, k;
    if (s->hscale == 1.0) return m->precond;
    for (i = 0; i < m->nF; i++) {
        double A[9];
        for (k = 0; k < 9; k++) A[k] = (1.0 + b1_of(s)) * sscale(s) * m->sdiag[9 * i + k];
        A[0] += (1.0 + a1_of(s)) * m->mdiag[i]; A[4] += (1.0 + a1_of(s)) * m->mdiag[i]; A[8] += (1.0 + a1_of(s)) * m->mdiag[i];
        mat_inv(A, P + 9 * i);
    }
    return P;
}

static void precond_apply(const snref_state *s, const double *P, const double *r, double *z) {
    unsigned i;
    for (i = 0; i < s->m->nF; i++) {
        double a[3], b[3];
        matT_vec(s->R + 9 * i, r + 3 * i, a);
        mat_vec(P + 9 * i, a, b);
        mat_vec(s->R + 9 * i, b, z + 3 * i);
    }
}

/* PCG, exactly `iters` iterations (or to convergence if iters == 0). x in/out. */
static double pcg(snref_state *s, const double *b, double *x, unsigned iters) {
    const snref_model *m = s->m;
    unsigned n = 3 * m->nF, it, i, maxit = iters ? iters : 20 * n + 100;
    double *r = WK(s, W_R), *z = WK(s, W_Z), *d = WK(s, W_D), *Ad = WK(s, W_AD);
    const double *P = precond_blocks(s);
    double rz, bn = sqrt(dot(b, b, n));
    a_mul(s, x, Ad);
    for (i = 0; i < n; i++) r[i] = b[i] - Ad[i];
    precond_apply(s, P, r, z);
    memcpy(d, z, n * sizeof *d);
    rz = dot(r, z, n);
    for (it = 0; it < maxit; it++) {
        double dAd, alpha, rz2, beta;
        if (!iters && sqrt(dot(r, r, n)) <= 1e-14 * bn) break;
        a_mul(s, d, Ad);
        dAd = dot(d, Ad, n);
        alpha = dAd > 0 ? rz / dAd : 0.0;
        for (i = 0; i < n; i++) { x[i] += alpha * d[i]; r[i] -= alpha * Ad[i]; }
        precond_apply(s, P, r, z);
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
    a_mul(s, x, Ad);
    for (i = 0; i < n; i++) r[i] = b[i] - Ad[i];
    return bn > 0 ? sqrt(dot(r, r, n)) / bn : 0.0;
}


/* Exact step solve by a banded LU of A, cached while the frames (pose, mode,
 * time-step scale) are unchanged. Returns -1 if the band is too large. */
static int exact_direct(snref_state *s, const double *b, double *x) {
    const snref_model *m = s->m;
    double key[64];
    unsigned j, k = 0;
    memset(key, 0, sizeof key);
    /* A depends on the joint rotations only (frames), the mode and the h scale */
    for (j = 0; j < m->nJ && k + 4 <= 60; j++) {
        unsigned c;
        for (c = 0; c < 4; c++) key[k++] = s->jq[4 * j + c];
    }
    key[60] = s->mode; key[61] = s->hscale; key[62] = m->nJ; key[63] = (double)m->nF;
    if (m->nJ * 4 > 60) { band_free(s->band); s->band = NULL; } /* too many joints to key: no caching */
    if (s->band && memcmp(band_key(s->band), key, sizeof key) == 0) { band_solve(s->band, b, x); return 0; }
    band_free(s->band);
    s->band = band_build(s, 1, (size_t)60000000);
    if (!s->band) return -1;
    memcpy((double *)band_key(s->band), key, sizeof key);
    band_solve(s->band, b, x);
    return 0;
}

void snref_step(snref_state *s) {
    const snref_model *m = s->m;
    unsigned i, k, nF = m->nF, nV = m->nV;
    double *f = WK(s, W_F), *b = WK(s, W_B), *vstar = WK(s, W_T1), *tmp = WK(s, W_Z);
    double *w = WK(s, W_WV), *vnewS, *pnewS, *dvS;
    double a1 = a1_of(s), b1 = b1_of(s);
    if (!s->posed) { /* stepping at the rest pose without set_pose: identity pose */
        snref_xform *id = calloc(m->nJ, sizeof *id);
        for (i = 0; i < m->nJ; i++) id[i].q[3] = 1;
        snref_set_pose(s, id);
        free(id);
    }
    /* 3. skeleton: new positions and velocities (kept in the upper part of scratch arrays) */
    pnewS = WK(s, W_D); vnewS = WK(s, W_AD); dvS = WK(s, W_R);
    for (k = nF; k < nV; k++) {
        skeleton_pos(s, k, pnewS + 3 * k);
        for (i = 0; i < 3; i++) {
            vnewS[3 * k + i] = pnewS[3 * k + i] - s->p[3 * k + i];
            dvS[3 * k + i] = vnewS[3 * k + i] - s->v[3 * k + i];
        }
    }
    /* 4. warped force at current free positions and new skeleton positions */
    {
        double *pp = WK(s, W_X);
        memcpy(pp, s->p, 3 * nF * sizeof *pp);
        memcpy(pp + 3 * nF, pnewS + 3 * nF, 3 * (nV - nF) * sizeof *pp);
        warped_force(s, pp, f);
    }
    gravity_add(s, f);
    /* 5. rhs */
    for (i = 0; i < 3 * nF; i++) { vstar[i] = s->v[i]; w[i] = (1.0 + b1) * s->v[i]; }
    for (i = 3 * nF; i < 3 * nV; i++) { vstar[i] = vnewS[i]; w[i] = b1 * vnewS[i]; }
    memcpy(b, f, 3 * nF * sizeof *b);
    mass_mul(s, vstar, tmp, 1);
    for (i = 0; i < 3 * nF; i++) b[i] -= a1 * tmp[i];
    {
        double *kw = WK(s, W_F); /* f already consumed */
        double *loc2 = calloc(3 * (size_t)nV, sizeof *loc2);
        memcpy(loc2, w, 3 * nV * sizeof *loc2);
        ktilde_mul(s, loc2, kw, 1);
        for (i = 0; i < 3 * nF; i++) b[i] -= kw[i];
        /* M^_FS (v'_S - v_S): mass product with free part zeroed */
        memset(loc2, 0, 3 * nF * sizeof *loc2);
        memcpy(loc2 + 3 * nF, dvS + 3 * nF, 3 * (nV - nF) * sizeof *loc2);
        mass_mul(s, loc2, kw, 1);
        for (i = 0; i < 3 * nF; i++) b[i] -= kw[i];
        /* keep skeleton update before pcg reuses the scratch */
        for (i = 3 * nF; i < 3 * nV; i++) { s->p[i] = pnewS[i]; s->v[i] = vnewS[i]; }
        free(loc2);
    }
    /* 6. solve */
    {
        double *x = s->dv;
        if (!s->warm) memset(x, 0, 3 * nF * sizeof *x);
        if (s->exact && exact_direct(s, b, x) == 0) s->last_cg_relres = 0;
        else s->last_cg_relres = pcg(s, b, x, s->exact ? 0u : s->iters);
    }
    /* 7. update */
    for (i = 0; i < 3 * nF; i++) { s->v[i] += s->dv[i]; s->p[i] += s->v[i]; }
    s->steps++;
}

void snref_get_lattice(const snref_state *s, double *out) {
    const snref_model *m = s->m;
    unsigned i;
    for (i = 0; i < 3 * m->nV; i++) out[i] = s->p[i] * m->unit;
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

void snref_get_surface(const snref_state *s, double *out) {
    double *lat = malloc(3 * (size_t)s->m->nV * sizeof *lat);
    snref_get_lattice(s, lat);
    snref_surface_from_lattice(s->m, lat, out);
    free(lat);
}

/* ---------------- static equilibrium (seed 003 eq. 10) ---------------- */

/* J y over free rows: -R_i sum_j S^_ij R_i^T y_j (exact Jacobian of eq. 7). */
static void jac_mul(const snref_state *s, const double *y, double *out) {
    const snref_model *m = s->m;
    double *acc = WK(s, W_T2);
    unsigned i, e, k;
    double sc = sscale(s);
    memset(acc, 0, 3 * m->nF * sizeof *acc);
    for (i = 0; i < m->nF; i++) {
        double a[3], t[3];
        matT_vec(s->R + 9 * i, y + 3 * i, a);
        mat_vec(m->sdiag + 9 * i, a, t);
        for (k = 0; k < 3; k++) acc[3 * i + k] += t[k];
        for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++) {
            unsigned j = m->cols[e];
            if (j >= m->nF) continue;
            matT_vec(s->R + 9 * i, y + 3 * j, a);      /* row i uses R_i on both sides */
            mat_vec(m->soff + 9 * e, a, t);
            for (k = 0; k < 3; k++) acc[3 * i + k] += t[k];
            matT_vec(s->R + 9 * j, y + 3 * i, a);      /* row j uses R_j */
            matT_vec(m->soff + 9 * e, a, t);
            for (k = 0; k < 3; k++) acc[3 * j + k] += t[k];
        }
    }
    for (i = 0; i < m->nF; i++) {
        mat_vec(s->R + 9 * i, acc + 3 * i, out + 3 * i);
        for (k = 0; k < 3; k++) out[3 * i + k] *= -sc;
    }
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

/* BiCGSTAB for -J x = r, right block-Jacobi preconditioning with (R_i S^_ii R_i^T)^-1. */
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
        mat_inv(A, Pi + 9 * i);
    }
#define PREC(in, out) precond_apply(s, Pi, in, out)
    jac_mul(s, x, t);
    for (i = 0; i < n; i++) r[i] = rhs[i] + t[i];   /* rhs - (-J) x */
    memcpy(r0, r, n * sizeof *r);
    for (it = 0; it < 20 * n + 1000; it++) {
        double rho1 = dot(r0, r, n), beta, tt;
        if (sqrt(dot(r, r, n)) <= tol * bn) break;
        beta = (rho1 / rho) * (alpha / omega);
        for (i = 0; i < n; i++) pv[i] = r[i] + beta * (pv[i] - omega * v[i]);
        PREC(pv, ph);
        jac_mul(s, ph, v);
        for (i = 0; i < n; i++) v[i] = -v[i];
        alpha = rho1 / dot(r0, v, n);
        for (i = 0; i < n; i++) sv[i] = r[i] - alpha * v[i];
        PREC(sv, sh);
        jac_mul(s, sh, t);
        for (i = 0; i < n; i++) t[i] = -t[i];
        tt = dot(t, t, n);
        omega = tt > 0 ? dot(t, sv, n) / tt : 0;
        for (i = 0; i < n; i++) { x[i] += alpha * ph[i] + omega * sh[i]; r[i] = sv[i] - omega * t[i]; }
        rho = rho1;
        if (omega == 0) break;
    }
#undef PREC
    free(r); free(r0); free(pv); free(v); free(ph); free(sv); free(sh); free(t); free(Pi);
}

/* Reverse Cuthill-McKee order of the free vertices (bandwidth reduction for
 * the banded direct solve). perm[new] = old, inv[old] = new. */
static void rcm(const snref_model *m, unsigned *perm, unsigned *inv) {
    unsigned nF = m->nF, i, e, head = 0, tail = 0, *deg = calloc(nF, sizeof *deg), *adjp = calloc(nF + 1, sizeof *adjp), *adj;
    unsigned char *seen = calloc(nF, 1);
    for (i = 0; i < nF; i++)
        for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++)
            if (m->cols[e] < nF) { deg[i]++; deg[m->cols[e]]++; }
    for (i = 0; i < nF; i++) adjp[i + 1] = adjp[i] + deg[i];
    adj = malloc((adjp[nF] + 1) * sizeof *adj);
    memset(deg, 0, nF * sizeof *deg);
    for (i = 0; i < nF; i++)
        for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++) {
            unsigned j = m->cols[e];
            if (j >= nF) continue;
            adj[adjp[i] + deg[i]++] = j; adj[adjp[j] + deg[j]++] = i;
        }
    while (tail < nF) {
        /* new component: start at a min-degree vertex, then move to the last BFS level twice (pseudo-peripheral) */
        unsigned start = nF, pass, k;
        for (i = 0; i < nF; i++) if (!seen[i] && (start == nF || deg[i] < deg[start])) start = i;
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
                for (b = a; b > first && deg[perm[b - 1]] > deg[perm[b]]; b--) { unsigned t = perm[b]; perm[b] = perm[b - 1]; perm[b - 1] = t; }
        }
    }
    for (i = 0; i < nF / 2; i++) { unsigned t = perm[i]; perm[i] = perm[nF - 1 - i]; perm[nF - 1 - i] = t; }
    for (i = 0; i < nF; i++) inv[perm[i]] = i;
    free(deg); free(adjp); free(adj); free(seen);
}

/* Banded LU of a free-free system in RCM order. which = 0: -J (exact static
 * Jacobian, row i: R_i S^_ij R_i^T); which = 1: the step matrix A =
 * (1+a1) M^_FF + (1+b1) R_i S^_ij R_j^T. No pivoting: both are close to (or
 * congruent to) SPD matrices. */
struct snref_band {
    unsigned n, nF, bw;
    size_t W;
    double *A;
    unsigned *inv;
    double key[64]; /* pose of a cached step matrix */
};

static void band_free(snref_band *B) { if (B) { free(B->A); free(B->inv); free(B); } }
static const double *band_key(const snref_band *B) { return B->key; }

static snref_band *band_build(snref_state *s, int which, size_t max_doubles) {
    const snref_model *m = s->m;
    unsigned nF = m->nF, n = 3 * nF, i, e, bw = 0, *perm = malloc(nF * sizeof *perm), *inv = malloc(nF * sizeof *inv);
    size_t W, row, col;
    double *A, sc = sscale(s), ca = 1.0 + a1_of(s), cb = which ? 1.0 + b1_of(s) : 1.0;
    snref_band *B;
    rcm(m, perm, inv);
    free(perm);
    for (i = 0; i < nF; i++)
        for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++)
            if (m->cols[e] < nF) {
                unsigned d = inv[i] > inv[m->cols[e]] ? inv[i] - inv[m->cols[e]] : inv[m->cols[e]] - inv[i];
                if (d > bw) bw = d;
            }
    bw = 3 * bw + 2;
    W = 2 * (size_t)bw + 1;
    if ((size_t)n * W > max_doubles) { free(inv); return NULL; }
    A = calloc((size_t)n * W, sizeof *A);
    if (!A) { free(inv); return NULL; }
#define AB(rr, cc) A[(size_t)(rr) * W + (cc) + bw - (rr)]
    for (i = 0; i < nF; i++) {
        double RS[9], Bk[9], St[9];
        unsigned a, b;
        const double *Ri = s->R + 9 * i;
        mat_mulT_(m->sdiag + 9 * i, Ri, RS); mat_mul_(Ri, RS, Bk);
        for (a = 0; a < 3; a++) for (b = 0; b < 3; b++) AB(3 * inv[i] + a, 3 * inv[i] + b) += cb * sc * Bk[3 * a + b];
        if (which) for (a = 0; a < 3; a++) AB(3 * inv[i] + a, 3 * inv[i] + a) += ca * m->mdiag[i];
        for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++) {
            unsigned j = m->cols[e];
            const double *Rj = s->R + 9 * j;
            if (j >= nF) continue;
            for (a = 0; a < 3; a++) for (b = 0; b < 3; b++) St[3 * a + b] = m->soff[9 * e + 3 * b + a];
            /* row i */
            mat_mulT_(m->soff + 9 * e, which ? Rj : Ri, RS); mat_mul_(Ri, RS, Bk);
            for (a = 0; a < 3; a++) for (b = 0; b < 3; b++) AB(3 * inv[i] + a, 3 * inv[j] + b) += cb * sc * Bk[3 * a + b];
            /* row j */
            mat_mulT_(St, which ? Ri : Rj, RS); mat_mul_(Rj, RS, Bk);
            for (a = 0; a < 3; a++) for (b = 0; b < 3; b++) AB(3 * inv[j] + a, 3 * inv[i] + b) += cb * sc * Bk[3 * a + b];
            if (which)
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

double snref_static(snref_state *s, unsigned dense_max) {
    const snref_model *m = s->m;
    unsigned n = 3 * m->nF, i, k, pass;
    double *r = malloc(n * sizeof *r), *dx = malloc(n * sizeof *dx), g0, res = 0;
    if (!s->posed) {
        snref_xform *id = calloc(m->nJ, sizeof *id);
        for (i = 0; i < m->nJ; i++) id[i].q[3] = 1;
        snref_set_pose(s, id);
        free(id);
    }
    for (k = m->nF; k < m->nV; k++) { skeleton_pos(s, k, s->p + 3 * k); s->v[3 * k] = s->v[3 * k + 1] = s->v[3 * k + 2] = 0; }
    snref_residual(s, r);
    g0 = sqrt(dot(r, r, n));
    for (pass = 0; pass < 2; pass++) {   /* second pass: one step of iterative refinement */
        snref_residual(s, r);
        memset(dx, 0, n * sizeof *dx);
        if (n <= dense_max) {
            double *A = malloc((size_t)n * n * sizeof *A), *e = calloc(n, sizeof *e), *col = malloc(n * sizeof *col);
            for (i = 0; i < n; i++) {           /* columns of -J */
                e[i] = 1; jac_mul(s, e, col); e[i] = 0;
                for (k = 0; k < n; k++) A[(size_t)k * n + i] = -col[k];
            }
            memcpy(dx, r, n * sizeof *dx);
            dense_solve(A, dx, n);
            free(A); free(e); free(col);
        } else {
            snref_band *B = band_build(s, 0, (size_t)60000000);
            if (B) band_solve(B, r, dx); else bicgstab(s, r, dx, 1e-13);
            band_free(B);
        }
        for (i = 0; i < n; i++) s->p[i] += dx[i];
    }
    snref_residual(s, r);
    res = g0 > 0 ? sqrt(dot(r, r, n)) / g0 : 0;
    memset(s->v, 0, 3 * m->nF * sizeof *s->v);
    memset(s->dv, 0, 3 * m->nF * sizeof *s->dv);
    free(r); free(dx);
    return res;
}

void snref_energy(const snref_state *s, double *kinetic, double *elastic) {
    const snref_model *m = s->m;
    unsigned n = 3 * m->nF, i, k;
    double *t = malloc(3 * (size_t)m->nV * sizeof *t), *u = calloc(3 * (size_t)m->nV, sizeof *u);
    mass_mul(s, s->v, t, 0);
    *kinetic = 0.5 * dot(s->v, t, n);
    for (i = 0; i < m->nF; i++) {
        double a[3];
        for (k = 0; k < 3; k++) a[k] = s->p[3 * i + k] - s->c[3 * i + k];
        matT_vec(s->R + 9 * i, a, u + 3 * i);
        for (k = 0; k < 3; k++) u[3 * i + k] -= m->rest[3 * i + k];
    }
    /* skeleton u_k = R_b^T (t_b - c_k) = 0 by construction (w = 0), so only the FF block counts */
    {
        snref_state tmp = *s;
        static const double I[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
        double *Rsave = malloc(9 * (size_t)m->nV * sizeof *Rsave);
        for (i = 0; i < m->nV; i++) memcpy(Rsave + 9 * i, I, sizeof I);
        tmp.R = Rsave;
        ktilde_mul(&tmp, u, t, 0);
        *elastic = 0.5 * dot(u, t, n);
        free(Rsave);
    }
    free(t); free(u);
}


/* Solve the static system for an arbitrary load: -J x = load (free rows,
 * internal units), i.e. x = K^-1 load at the current frames; banded LU, or
 * BiCGSTAB if the band is too large. */
void snref_solve_load(snref_state *s, const double *load, double *x) {
    snref_band *B = band_build(s, 0, (size_t)60000000);
    memset(x, 0, 3 * s->m->nF * sizeof *x);
    if (B) band_solve(B, load, x); else bicgstab(s, load, x, 1e-13);
    band_free(B);
}

/* y = M^_FF x (free rows, free columns). */
void snref_mass_mul(const snref_state *s, const double *x, double *y) { mass_mul(s, x, y, 0); }
