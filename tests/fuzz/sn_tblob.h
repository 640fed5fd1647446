/* sn_tblob.h -- a tiny, independent writer of valid Sinew blobs for the
 * runtime's own tests (validator, accessors, fuzz seed). Not the host tool:
 * it shares only the layout constants of sn_format.h.
 *
 * The asset (format 2.0): 2 hexahedral cells along x (3x2x2 = 12 lattice
 * vertices), the x = 0 face (4 vertices) bound rigidly to the root joint
 * (skeleton), 8 free vertices framed by root/tip, cell frames root/tip
 * blended at the cell centres; consistent trilinear mass; per cell a
 * stiffness CELLK from axial springs between all 28 corner pairs (symmetric
 * PSD, rigid translations and rotations in its null space), the block-Jacobi
 * preconditioner of the assembled diagonal; LIMIT on every free vertex
 * (0.25 internal units on odd vertices, none on even ones); the
 * REST_MODELLED flag; 4 embedded surface vertices, 2 triangles. Rigs
 * (format 3.0): an abstract control "puff" (baked value 0.25) and a pose
 * control "bend" (the tip's angle about z); rig 0 on puff, samples
 * (-1,-1) (0,0) (1,1), pushing free vertices 1, 3, 5 along +y; rig 1 on
 * bend, samples (0 deg, 0) (90 deg, 1), pulling 0, 4, 7 along -x; rig 2 on
 * puff, one sample (eta 0.5 everywhere), on vertex 2 along +z. Segment
 * meshes (format 4.0): a chain of 5 nodes 0.1 apart hanging along -y from
 * the tip end (x = 1), node 0 pinned to the tip joint; a 3x3 sheet (2 levels,
 * shares 1/2 1/2, no gravity) in the plane y = -0.25 from surface vertex 0
 * (0.25, -0.25, 0.25), its node 0, pinned there. Crease sections (format
 * 5.0): list 4, active 2, one seed pair, two-entry neighbourhoods. Flavour
 * follows SN_FLOAT of the including file (fixed: Q formats of NUMERICS.md;
 * float: true values).
 */
#ifndef SN_TBLOB_H
#define SN_TBLOB_H
#include <math.h>
#include <stdint.h>
#include <string.h>
#include "sinew.h"
#include "sn_format.h"

#define TB_NV 12
#define TB_NF 8
#define TB_NJ 2
#define TB_NC 2
#define TB_NS 4
#define TB_NT 2
#define TB_FRAC 26   /* frac_S = frac_P */
#define TB_FRAC_M 24 /* lumped mass rows reach 3.4 */
#define TB_FRAC_E 16 /* ENERGY: 16.7 J per internal unit */
#define TB_NK 2      /* controls */
#define TB_NR 3      /* rigs */
#define TB_NRS 6     /* rig samples */
#define TB_NRE 7     /* rig entries */
#define TB_RIG_FRAC 36 /* rig forces ~2e-2 internal units: 2^30.4 at Q36 */
#define TB_NP 2      /* force share profiles */
#define TB_NFRC 4    /* force slots */
#define TB_FRAC_F 40 /* FORCE: 1/1024 rhs units per newton */
#define TB_NM 2      /* segment meshes (format 4.0): a chain and a small sheet */
#define TB_NSN 14    /* segment nodes: 5 + 3x3 */
#define TB_NSA 2     /* segment attachments */
#define TB_SEG_LEN 0.1
#define TB_NCON 2    /* constraints (format 5.0) */
#define TB_NCOL 1    /* colliders */
#define TB_NCT 3     /* contacts per step */
#define TB_NFP 1     /* frame pairs (format 6.4): (0, 1) */
#define TB_FPB (TB_NFP * SN_FPAIR_BYTES) /* their instance bytes (SN_INSTANCE_BYTES' segB) */
/* constraint state with the crease rows (TB_CR_ACTIVE, below) */
#define TB_CONB SN_CONS_BYTES(TB_NCON, TB_NCOL, SN_ROWS_CAP(TB_NCON, TB_NCT, TB_CR_ACTIVE))
#define TB_CONB_NOCR SN_CONS_BYTES(TB_NCON, TB_NCOL, SN_ROWS_CAP(TB_NCON, TB_NCT, 0))
/* segment state bytes: chain 4 segs 5 nodes; sheet side 3 levels 2: 12 + 6 segs, 9 + 4 nodes */
#define TB_SEGB (SN_SEG_SEG_BYTES * (4u + 18u) + SN_SEG_NODE_BYTES * (5u + 13u))
/* crease sections (format 5.0): list 4, active 2, rows of 2 vertices and 2
 * triangles, one seed pair (0, 2); depth 0.25, push 0.05 internal units */
#define TB_CR_LIST 4u
#define TB_CR_ACTIVE 2u
#define TB_ND 1u
#define TB_CRB SN_CREASE_STATE_BYTES(TB_NS, TB_CR_LIST)

static void tb_u16(unsigned char *p, uint32_t v) { p[0] = (unsigned char)v; p[1] = (unsigned char)(v >> 8); }
static void tb_u32(unsigned char *p, uint32_t v) {
    tb_u16(p, v & 0xFFFFu);
    tb_u16(p + 2, v >> 16);
}
static uint32_t tb_rd32(const unsigned char *p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
/* a real with value v, in Q q for the fixed flavour */
static void tb_real(unsigned char *p, double v, int q) {
#if defined(SN_FLOAT)
    float f = (float)v;
    uint32_t u;
    (void)q;
    memcpy(&u, &f, 4);
    tb_u32(p, u);
#else
    double s = floor(v * ldexp(1.0, q) + 0.5);
    tb_u32(p, (uint32_t)(int32_t)s);
#endif
}

/* one cell's CELLK record from its 24x24 stiffness K (Q TB_FRAC): float,
 * 36 upper blocks of reals; fixed (format 6.0), diagonal blocks as 6
 * symmetric int32, off-diagonal ones as int16 mantissas with the smallest
 * exponent that fits (sn_format.h) */
static void tb_cellk(unsigned char *ck, double K[24][24]) {
    int a, bb, d, e = 0;
#if defined(SN_FLOAT)
    for (a = 0; a < 8; a++)
        for (bb = a; bb < 8; bb++, e++)
            for (d = 0; d < 9; d++) tb_real(ck + (9 * e + d) * 4, K[3 * a + d / 3][3 * bb + d % 3], TB_FRAC);
#else
    static const int s6[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
    (void)e;
    for (a = 0; a < 8; a++)
        for (d = 0; d < 6; d++)
            tb_real(ck + SN_CELLK_DIAG + 24 * a + 4 * d, K[3 * a + s6[d][0]][3 * a + s6[d][1]], TB_FRAC);
    for (a = 0; a < 8; a++)
        for (bb = a + 1; bb < 8; bb++) {
            uint32_t o = SN_CELLK_OFFIDX(a, bb);
            double mx = 0;
            int x = 0;
            for (d = 0; d < 9; d++) mx = fmax(mx, fabs(ldexp(K[3 * a + d / 3][3 * bb + d % 3], TB_FRAC)));
            while (x < SN_CELLK_EXP_MAX && floor(ldexp(mx, -x) + 0.5) > SN_CELLK_M_MAX) x++;
            ck[SN_CELLK_EXP + o] = (unsigned char)x;
            for (d = 0; d < 9; d++) {
                double m = floor(ldexp(K[3 * a + d / 3][3 * bb + d % 3], TB_FRAC - x) + 0.5);
                m = fmax(-SN_CELLK_M_MAX, fmin(SN_CELLK_M_MAX, m));
                tb_u16(ck + SN_CELLK_OFF + 18 * o + 2 * (uint32_t)d, (uint32_t)(uint16_t)(int16_t)m);
            }
        }
#endif
}

static uint32_t tb_crc32(const unsigned char *p, uint32_t n) {
    uint32_t c = 0xFFFFFFFFu, i;
    int k;
    for (i = 0; i < n; i++) {
        c ^= p[i];
        for (k = 0; k < 8; k++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}
/* Recompute the checksum after editing a blob. */
static void tb_fix_crc(unsigned char *b) {
    uint32_t total = tb_rd32(b + SN_H_TOTAL_SIZE);
    tb_u32(b + SN_H_CRC32, tb_crc32(b + 16, total - 16));
}
static uint32_t tb_sec(const unsigned char *b, int k) { return tb_rd32(b + SN_H_SECTIONS + 16 * k); }

/* vertex index of grid point (ix 0..2, iy 0..1, iz 0..1): x = 0 face last */
static int tb_vid(int ix, int iy, int iz) {
    return ix == 0 ? TB_NF + iy + 2 * iz : (ix - 1) * 4 + iy + 2 * iz;
}

/* Write the blob into b (zeroed by the caller? no: written whole here);
 * returns its size. len_shift: internal unit = 2^len_shift mesh units.
 * cap must be >= 4096. */
/* FREFS (format 6.4) from FRAMES, CFRAMES and FPAIRS: each slerping entry's
 * first equal entry, else its pair (SN_FREF_PAIR | 0x7FFFFFFF, an invalid
 * index, if FPAIRS lacks it); SN_FREF_BONE for the others. No CRC. */
static void tb_fix_frefs(unsigned char *b) {
    const unsigned char *fr = b + tb_sec(b, SN_SEC_FRAMES), *cf = b + tb_sec(b, SN_SEC_CFRAMES), *pr = b + tb_sec(b, SN_SEC_FPAIRS);
    unsigned char *rf = b + tb_sec(b, SN_SEC_FREFS);
    uint32_t nF = tb_rd32(b + SN_H_N_FREE), n = tb_rd32(b + SN_H_SECTIONS + 16 * SN_SEC_FREFS + 8);
    uint32_t np = tb_rd32(b + SN_H_SECTIONS + 16 * SN_SEC_FPAIRS + 8), i, j;
    for (i = 0; i < n; i++) {
        const unsigned char *f = i < nF ? fr + 4 * i : cf + 4 * (i - nF);
        uint32_t r = SN_FREF_BONE;
        if (f[0] != f[1] && (f[2] | f[3]) != 0) {
            for (j = 0; j < i; j++)
                if (!memcmp(f, j < nF ? fr + 4 * j : cf + 4 * (j - nF), 4)) break;
            if (j < i) r = j;
            else {
                for (j = 0; j < np; j++)
                    if (pr[2 * j] == f[0] && pr[2 * j + 1] == f[1]) break;
                r = SN_FREF_PAIR | (j < np ? j : 0x7FFFFFFFu);
            }
        }
        tb_u32(rf + 4 * i, r);
    }
}

static uint32_t tb_build(unsigned char *b, uint32_t cap, int len_shift) {
    const int R = 4;
    double X[TB_NV][3], M[TB_NV][TB_NV], K[TB_NC][24][24], Sd[TB_NV][9], m0 = 0.0;
    const double a1 = 1.0 / 60.0, b1 = 0.06, k = 0.05, cell = 0.5, h = 1.0 / 60.0;
    int corner[TB_NC][8];
    uint32_t off, cnt[SN_SEC_COUNT], elem[SN_SEC_COUNT], secoff[SN_SEC_COUNT];
    int c, i, j, a, bb, d, sec, nnz = 0;
    memset(b, 0, cap);
    memset(M, 0, sizeof M);
    memset(K, 0, sizeof K);
    memset(Sd, 0, sizeof Sd);
    for (i = 0; i < 3; i++)
        for (j = 0; j < 2; j++)
            for (d = 0; d < 2; d++) {
                int v = tb_vid(i, j, d);
                X[v][0] = i * cell;
                X[v][1] = (j - 0.5) * cell;
                X[v][2] = (d - 0.5) * cell;
            }
    for (c = 0; c < TB_NC; c++)
        for (a = 0; a < 8; a++) corner[c][a] = tb_vid(c + (a & 1), (a >> 1) & 1, (a >> 2) & 1);
    /* consistent trilinear hex mass V/216 * prod(1 + [same coordinate]);
     * cell stiffness: axial springs k n n^T between every pair of corners */
    for (c = 0; c < TB_NC; c++)
        for (a = 0; a < 8; a++)
            for (bb = 0; bb < 8; bb++) {
                double m = cell * cell * cell / 216.0, n[3], l = 0;
                for (d = 0; d < 3; d++) m *= 1.0 + (((a >> d) & 1) == ((bb >> d) & 1));
                M[corner[c][a]][corner[c][bb]] += m;
                if (a == bb) continue;
                for (d = 0; d < 3; d++) { n[d] = X[corner[c][bb]][d] - X[corner[c][a]][d]; l += n[d] * n[d]; }
                for (i = 0; i < 3; i++)
                    for (j = 0; j < 3; j++) {
                        double kk = k * n[i] * n[j] / l;
                        K[c][3 * a + i][3 * bb + j] -= kk;
                        K[c][3 * a + i][3 * a + j] += kk;
                    }
            }
    for (c = 0; c < TB_NC; c++)
        for (a = 0; a < 8; a++)
            for (i = 0; i < 9; i++) Sd[corner[c][a]][i] += K[c][3 * a + i / 3][3 * a + i % 3];
    for (i = 0; i < TB_NV; i++) m0 = M[i][i] > m0 ? M[i][i] : m0;
    for (i = 0; i < TB_NV; i++)
        for (j = 0; j < TB_NV; j++) M[i][j] /= m0;
    for (i = 0; i < TB_NF; i++)
        for (j = i + 1; j < TB_NV; j++) nnz += M[i][j] != 0.0;

    cnt[SN_SEC_JOINTS] = TB_NJ;       elem[SN_SEC_JOINTS] = (uint32_t)SN_ELEM_JOINTS(R);
    cnt[SN_SEC_JOINT_NAMES] = TB_NJ;  elem[SN_SEC_JOINT_NAMES] = SN_ELEM_JOINT_NAMES;
    cnt[SN_SEC_REST] = TB_NV;         elem[SN_SEC_REST] = (uint32_t)SN_ELEM_REST(R);
    cnt[SN_SEC_FRAMES] = TB_NV;       elem[SN_SEC_FRAMES] = SN_ELEM_FRAMES;
    cnt[SN_SEC_MDIAG] = TB_NF;        elem[SN_SEC_MDIAG] = (uint32_t)SN_ELEM_MDIAG(R);
    cnt[SN_SEC_PRECOND] = TB_NF;      elem[SN_SEC_PRECOND] = (uint32_t)SN_ELEM_PRECOND(R);
    cnt[SN_SEC_MLUMP] = TB_NF;        elem[SN_SEC_MLUMP] = (uint32_t)SN_ELEM_MLUMP(R);
    cnt[SN_SEC_ROWPTR] = TB_NF + 1;   elem[SN_SEC_ROWPTR] = SN_ELEM_ROWPTR;
    cnt[SN_SEC_COLS] = (uint32_t)nnz; elem[SN_SEC_COLS] = SN_ELEM_COLS;
    cnt[SN_SEC_MOFF] = (uint32_t)nnz; elem[SN_SEC_MOFF] = (uint32_t)SN_ELEM_MOFF(R);
    cnt[SN_SEC_CELLS] = TB_NC;        elem[SN_SEC_CELLS] = SN_ELEM_CELLS;
    cnt[SN_SEC_CFRAMES] = TB_NC;      elem[SN_SEC_CFRAMES] = SN_ELEM_CFRAMES;
    cnt[SN_SEC_CELLK] = TB_NC;        elem[SN_SEC_CELLK] = (uint32_t)SN_ELEM_CELLK(SN_FLAVOUR, R);
    cnt[SN_SEC_LIMIT] = TB_NF;        elem[SN_SEC_LIMIT] = (uint32_t)SN_ELEM_LIMIT(R);
    cnt[SN_SEC_EMBED] = TB_NS;        elem[SN_SEC_EMBED] = SN_ELEM_EMBED;
    cnt[SN_SEC_TRIS] = TB_NT;         elem[SN_SEC_TRIS] = SN_ELEM_TRIS;
    cnt[SN_SEC_CONTROLS] = TB_NK;     elem[SN_SEC_CONTROLS] = (uint32_t)SN_ELEM_CONTROLS(R);
    cnt[SN_SEC_RIGS] = TB_NR;         elem[SN_SEC_RIGS] = SN_ELEM_RIGS;
    cnt[SN_SEC_RIG_SAMPLES] = TB_NRS; elem[SN_SEC_RIG_SAMPLES] = (uint32_t)SN_ELEM_RIG_SAMPLES(R);
    cnt[SN_SEC_RIG_VERTS] = TB_NRE;   elem[SN_SEC_RIG_VERTS] = SN_ELEM_RIG_VERTS;
    cnt[SN_SEC_RIG_FORCES] = TB_NRE;  elem[SN_SEC_RIG_FORCES] = (uint32_t)SN_ELEM_RIG_FORCES(R);
    cnt[SN_SEC_SHARES] = TB_NP;       elem[SN_SEC_SHARES] = (uint32_t)SN_ELEM_SHARES(R);
    cnt[SN_SEC_VSHARE] = TB_NF;       elem[SN_SEC_VSHARE] = SN_ELEM_VSHARE;
    cnt[SN_SEC_SEGMESH] = TB_NM;      elem[SN_SEC_SEGMESH] = (uint32_t)SN_ELEM_SEGMESH(R);
    cnt[SN_SEC_SEGNODES] = TB_NSN;    elem[SN_SEC_SEGNODES] = (uint32_t)SN_ELEM_SEGNODES(R);
    cnt[SN_SEC_SEGATTACH] = TB_NSA;   elem[SN_SEC_SEGATTACH] = (uint32_t)SN_ELEM_SEGATTACH(R);
    cnt[SN_SEC_CONSTRAINTS] = 1;      elem[SN_SEC_CONSTRAINTS] = SN_ELEM_CONSTRAINTS;
    cnt[SN_SEC_CREASE] = 1;           elem[SN_SEC_CREASE] = (uint32_t)SN_ELEM_CREASE(R);
    cnt[SN_SEC_CREASE_PAIRS] = TB_ND; elem[SN_SEC_CREASE_PAIRS] = SN_ELEM_CREASE_PAIRS;
    cnt[SN_SEC_CREASE_VNBR] = 2 * TB_NS; elem[SN_SEC_CREASE_VNBR] = SN_ELEM_CREASE_VNBR;
    cnt[SN_SEC_CREASE_TNBR] = 2 * TB_NS; elem[SN_SEC_CREASE_TNBR] = SN_ELEM_CREASE_TNBR;
    cnt[SN_SEC_LEVEL_BLOB] = 0;       elem[SN_SEC_LEVEL_BLOB] = SN_ELEM_LEVEL_BLOB;   /* format 6.0: no finer level */
    cnt[SN_SEC_LEVEL_UP] = 0;         elem[SN_SEC_LEVEL_UP] = SN_ELEM_LEVEL_MAP;
    cnt[SN_SEC_LEVEL_DOWN] = 0;       elem[SN_SEC_LEVEL_DOWN] = SN_ELEM_LEVEL_MAP;
    cnt[SN_SEC_ICHOL] = 0;            elem[SN_SEC_ICHOL] = SN_ELEM_ICHOL; /* block Jacobi; tb_add_ichol adds it */
    cnt[SN_SEC_ADAPT] = 0;            elem[SN_SEC_ADAPT] = SN_ELEM_ADAPT(R); /* format 6.1: no adaptation */
    cnt[SN_SEC_CELLX] = 0;            elem[SN_SEC_CELLX] = SN_ELEM_CELLX; /* format 6.3: not a cut level */
    cnt[SN_SEC_CELLXK] = 0;           elem[SN_SEC_CELLXK] = (uint32_t)SN_ELEM_CELLXK(SN_FLAVOUR, R);
    cnt[SN_SEC_FPAIRS] = TB_NFP;      elem[SN_SEC_FPAIRS] = SN_ELEM_FPAIRS; /* format 6.4: the one pair (0, 1) */
    cnt[SN_SEC_FREFS] = TB_NF + TB_NC; elem[SN_SEC_FREFS] = SN_ELEM_FREFS;
    cnt[SN_SEC_DETAILS] = 0;          elem[SN_SEC_DETAILS] = (uint32_t)SN_ELEM_DETAILS(R); /* format 6.5: no details */
    cnt[SN_SEC_DETAIL] = 0;           elem[SN_SEC_DETAIL] = (uint32_t)SN_ELEM_DETAIL(R);
    cnt[SN_SEC_CELLD] = 0;            elem[SN_SEC_CELLD] = SN_ELEM_CELLD;
    cnt[SN_SEC_CELLDK] = 0;           elem[SN_SEC_CELLDK] = (uint32_t)SN_ELEM_CELLDK(SN_FLAVOUR, R);
    off = SN_HEADER_BYTES;
    for (sec = 0; sec < SN_SEC_COUNT; sec++) {
        off = (off + 7u) & ~7u;
        secoff[sec] = off;
        tb_u32(b + SN_H_SECTIONS + 16 * sec, off);
        tb_u32(b + SN_H_SECTIONS + 16 * sec + 4, cnt[sec] * elem[sec]);
        tb_u32(b + SN_H_SECTIONS + 16 * sec + 8, cnt[sec]);
        tb_u32(b + SN_H_SECTIONS + 16 * sec + 12, elem[sec]);
        off += cnt[sec] * elem[sec];
    }
    /* constraints: maxima */
    b[secoff[SN_SEC_CONSTRAINTS]] = TB_NCON;
    b[secoff[SN_SEC_CONSTRAINTS] + 1] = TB_NCOL;
    tb_u16(b + secoff[SN_SEC_CONSTRAINTS] + 2, TB_NCT);
    /* joints: root at the origin, tip at (0.5, 0, 0) */
    tb_u16(b + secoff[SN_SEC_JOINTS], 0xFFFFu);
    tb_u16(b + secoff[SN_SEC_JOINTS] + elem[SN_SEC_JOINTS], 0);
    tb_real(b + secoff[SN_SEC_JOINTS] + elem[SN_SEC_JOINTS] + 8, cell, SN_Q_LEN);
    memcpy(b + secoff[SN_SEC_JOINT_NAMES], "root", 4);
    memcpy(b + secoff[SN_SEC_JOINT_NAMES] + 32, "tip", 3);
    for (i = 0; i < TB_NV; i++) {
        unsigned char *f = b + secoff[SN_SEC_FRAMES] + 4 * i;
        for (d = 0; d < 3; d++) tb_real(b + secoff[SN_SEC_REST] + (3 * i + d) * R, X[i][d], SN_Q_LEN);
        if (i < TB_NF) { /* blend root -> tip along x */
            f[0] = 0;
            f[1] = 1;
            tb_u16(f + 2, (uint32_t)(X[i][0] * 32768.0 + 0.5));
        }
    }
    {
        static const int sym[6] = {0, 4, 8, 1, 2, 5}; /* xx yy zz xy xz yz of a row-major 3x3 */
        uint32_t q = 0;
        for (i = 0; i < TB_NF; i++) {
            double ms = 0.0, A[9], P[9], det;
            for (d = 0; d < 9; d++) A[d] = (1.0 + b1) * Sd[i][d] + (d % 4 == 0 ? (1.0 + a1) * M[i][i] : 0.0);
            det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) + A[2] * (A[3] * A[7] - A[4] * A[6]);
            P[0] = (A[4] * A[8] - A[5] * A[7]) / det; P[1] = (A[2] * A[7] - A[1] * A[8]) / det; P[2] = (A[1] * A[5] - A[2] * A[4]) / det;
            P[4] = (A[0] * A[8] - A[2] * A[6]) / det; P[5] = (A[2] * A[3] - A[0] * A[5]) / det; P[8] = (A[0] * A[4] - A[1] * A[3]) / det;
            tb_real(b + secoff[SN_SEC_MDIAG] + i * R, M[i][i], TB_FRAC_M);
            for (d = 0; d < 6; d++) tb_real(b + secoff[SN_SEC_PRECOND] + (6 * i + d) * R, P[sym[d]], TB_FRAC);
            for (j = 0; j < TB_NV; j++) ms += M[i][j];
            tb_real(b + secoff[SN_SEC_MLUMP] + i * R, ms, TB_FRAC_M);
            tb_real(b + secoff[SN_SEC_LIMIT] + i * R, (i & 1) ? 0.25 : 0.0, SN_Q_LEN);
            tb_u32(b + secoff[SN_SEC_ROWPTR] + 4 * i, q);
            for (j = i + 1; j < TB_NV; j++) {
                if (M[i][j] == 0.0) continue;
                tb_u16(b + secoff[SN_SEC_COLS] + 2 * q, (uint32_t)j);
                tb_real(b + secoff[SN_SEC_MOFF] + q * R, M[i][j], TB_FRAC_M);
                q++;
            }
        }
        tb_u32(b + secoff[SN_SEC_ROWPTR] + 4 * TB_NF, q);
    }
    for (c = 0; c < TB_NC; c++) {
        unsigned char *f = b + secoff[SN_SEC_CFRAMES] + SN_ELEM_CFRAMES * c;
        unsigned char *ck = b + secoff[SN_SEC_CELLK] + (uint32_t)SN_ELEM_CELLK(SN_FLAVOUR, R) * (uint32_t)c;
        for (a = 0; a < 8; a++) tb_u16(b + secoff[SN_SEC_CELLS] + 16 * c + 2 * a, (uint32_t)corner[c][a]);
        f[0] = 0;
        f[1] = 1;
        tb_u16(f + 2, (uint32_t)((c + 0.5) * cell * 32768.0 + 0.5)); /* cell centre x */
        tb_cellk(ck, K[c]);
    }
    b[secoff[SN_SEC_FPAIRS]] = 0; /* frame references (format 6.4): the pair (0, 1) */
    b[secoff[SN_SEC_FPAIRS] + 1] = 1;
    {
        static const uint16_t emb[TB_NS][4] = {
            {0, 16384, 0, 32768}, {1, 32768, 0, 32768}, {1, 32768, 32768, 32768}, {0, 16384, 32768, 32768}};
        static const uint16_t tri[TB_NT][3] = {{0, 1, 2}, {0, 2, 3}};
        for (i = 0; i < TB_NS; i++)
            for (d = 0; d < 4; d++) tb_u16(b + secoff[SN_SEC_EMBED] + 8 * i + 2 * d, emb[i][d]);
        for (i = 0; i < TB_NT; i++)
            for (d = 0; d < 3; d++) tb_u16(b + secoff[SN_SEC_TRIS] + 6 * i + 2 * d, tri[i][d]);
    }
    {   /* controls and rigs */
        static const int rig_ctl[TB_NR] = {0, 1, 0}, rig_ns[TB_NR] = {3, 2, 1}, rig_ne[TB_NR] = {3, 3, 1};
        static const double smp[TB_NRS][2] = {{-1, -1}, {0, 0}, {1, 1}, {0, 0}, {90, 1}, {0, 0.5}};
        static const int vx[TB_NRE] = {1, 3, 5, 0, 4, 7, 2};
        static const double fdir[TB_NR][3] = {{0, 2e-2, 0}, {-1.5e-2, 0, 0}, {0, 0, 1e-2}};
        unsigned char *c0 = b + secoff[SN_SEC_CONTROLS], *c1 = c0 + elem[SN_SEC_CONTROLS];
        uint32_t ns = 0, ne = 0;
        memcpy(c0, "puff", 4);
        tb_real(c0 + 40 + 3 * R, 0.25, 16);
        memcpy(c1, "bend", 4);
        c1[32] = SN_CTL_ANGLE;
        c1[33] = 1;
        tb_real(c1 + 40 + 2 * R, 1.0, SN_Q_ROT); /* axis z */
        for (i = 0; i < TB_NR; i++) {
            unsigned char *r = b + secoff[SN_SEC_RIGS] + SN_ELEM_RIGS * i;
            tb_u16(r, (uint32_t)rig_ctl[i]);
            r[2] = (unsigned char)rig_ns[i];
            r[3] = SN_FLAVOUR ? 0 : TB_RIG_FRAC;
            tb_u32(r + 4, ns);
            tb_u32(r + 8, ne);
            tb_u32(r + 12, (uint32_t)rig_ne[i]);
            for (j = 0; j < rig_ns[i]; j++, ns++) {
                tb_real(b + secoff[SN_SEC_RIG_SAMPLES] + 2 * R * ns, smp[ns][0], 16);
                tb_real(b + secoff[SN_SEC_RIG_SAMPLES] + 2 * R * ns + R, smp[ns][1], SN_Q_ROT);
            }
            for (j = 0; j < rig_ne[i]; j++, ne++) {
                tb_u16(b + secoff[SN_SEC_RIG_VERTS] + 2 * ne, (uint32_t)vx[ne]);
                for (d = 0; d < 3; d++)
                    tb_real(b + secoff[SN_SEC_RIG_FORCES] + (3 * ne + d) * R, fdir[i][d], TB_RIG_FRAC);
            }
        }
    }
    {   /* force shares: profile 0 all fine, profile 1 spread (1/2, 1/4, 1/8, 0, 1/8); vertices alternate */
        static const double prof[TB_NP][SN_LEVELS] = {{1, 0, 0, 0, 0}, {0.5, 0.25, 0.125, 0, 0.125}};
        for (i = 0; i < TB_NP; i++)
            for (j = 0; j < SN_LEVELS; j++)
                tb_real(b + secoff[SN_SEC_SHARES] + (SN_LEVELS * i + j) * R, prof[i][j], SN_Q_ROT);
        for (i = 0; i < TB_NF; i++) b[secoff[SN_SEC_VSHARE] + i] = (unsigned char)(i & 1);
    }
    {   /* segment meshes: {kind, levels, sweeps, flags, side, n_attach, first_node, first_attach,
         * len, gamma, keep, inv_mass, centre, share[4]} */
        static const double sh[2][4] = {{1, 0, 0, 0}, {0.5, 0.5, 0, 0}};
        static const unsigned hd[2][6] = {{SN_SEG_CHAIN, 1, 8, 0, 5, 1}, {SN_SEG_SHEET, 2, 4, SN_SEGF_NO_GRAVITY, 3, 1}};
        unsigned char *ms = b + secoff[SN_SEC_SEGMESH], *nd = b + secoff[SN_SEC_SEGNODES];
        unsigned char *at = b + secoff[SN_SEC_SEGATTACH];
        for (i = 0; i < TB_NM; i++) {
            unsigned char *r = ms + elem[SN_SEC_SEGMESH] * (uint32_t)i;
            r[0] = (unsigned char)hd[i][0]; r[1] = (unsigned char)hd[i][1];
            r[2] = (unsigned char)hd[i][2]; r[3] = (unsigned char)hd[i][3];
            tb_u16(r + 4, hd[i][4]);
            tb_u16(r + 6, hd[i][5]);
            tb_u32(r + 8, i ? 5u : 0u);
            tb_u32(r + 12, (uint32_t)i);
            tb_real(r + 16, TB_SEG_LEN, SN_Q_LEN);
            tb_real(r + 16 + R, 0.5, SN_Q_ROT);
            tb_real(r + 16 + 2 * R, 0.99, SN_Q_ROT);
            tb_real(r + 16 + 3 * R, 4.0, 16);
            tb_real(r + 16 + 4 * R, 0.5, SN_Q_ROT);
            for (j = 0; j < 4; j++) tb_real(r + 16 + (5 + j) * R, sh[i][j], SN_Q_ROT);
            r[16 + 9 * R] = (unsigned char)(i ? 2u : hd[i][2]); /* coarse_sweeps (a one-level chain: = sweeps) */
            r[17 + 9 * R] = (unsigned char)(i ? SN_SEG_RELAX_ONE : 48u); /* relax: the chain over-relaxed (omega 1.5) */
        }
        for (i = 0; i < 5; i++) { /* chain along -y from (1, 0, 0) */
            tb_real(nd + 3 * R * i, 2 * cell, SN_Q_LEN);
            tb_real(nd + 3 * R * i + R, -TB_SEG_LEN * i, SN_Q_LEN);
        }
        for (i = 0; i < 9; i++) { /* sheet: (0.25 + 0.1 c, -0.25, 0.25 + 0.1 r), node 0 on surface vertex 0 */
            tb_real(nd + 3 * R * (5 + i), 0.5 * cell + TB_SEG_LEN * (i % 3), SN_Q_LEN);
            tb_real(nd + 3 * R * (5 + i) + R, -0.5 * cell, SN_Q_LEN);
            tb_real(nd + 3 * R * (5 + i) + 2 * R, 0.5 * cell + TB_SEG_LEN * (i / 3), SN_Q_LEN);
        }
        /* chain node 0 -> joint 1 at its rest point; sheet node 0 -> surface vertex 0 */
        at[2] = SN_SEGATT_JOINT;
        tb_u16(at + 4, 1);
        tb_real(at + 8, 2 * cell, SN_Q_LEN);
        at[elem[SN_SEC_SEGATTACH] + 2] = SN_SEGATT_SURFACE;
    }
    {   /* crease: record, the seed pair (0, 2), rows {s, s+1 mod 4} and {0, 1} */
        unsigned char *cr = b + secoff[SN_SEC_CREASE];
        tb_u16(cr, TB_CR_LIST);
        tb_u16(cr + 2, TB_CR_ACTIVE);
        cr[4] = 2;
        cr[5] = 2;
        tb_u16(cr + 6, TB_NS); /* rows (format 6.0): one per surface vertex */
        tb_real(cr + 12, 0.25, SN_Q_LEN);
        tb_real(cr + 12 + R, 0.05, SN_Q_LEN);
        tb_real(cr + 12 + 2 * R, 0.0, SN_Q_LEN); /* exclude (format 6.0): off */
        tb_u16(b + secoff[SN_SEC_CREASE_PAIRS], 0);
        tb_u16(b + secoff[SN_SEC_CREASE_PAIRS] + 2, 2);
        for (i = 0; i < TB_NS; i++) {
            tb_u16(b + secoff[SN_SEC_CREASE_VNBR] + 4 * i, (uint32_t)i);
            tb_u16(b + secoff[SN_SEC_CREASE_VNBR] + 4 * i + 2, (uint32_t)((i + 1) % TB_NS));
            tb_u16(b + secoff[SN_SEC_CREASE_TNBR] + 4 * i, 0);
            tb_u16(b + secoff[SN_SEC_CREASE_TNBR] + 4 * i + 2, 1);
        }
    }
    /* header */
    b[0] = 'S'; b[1] = 'N'; b[2] = 'W'; b[3] = 'B';
    tb_u16(b + SN_H_VER_MAJOR, SN_FORMAT_MAJOR);
    tb_u16(b + SN_H_VER_MINOR, SN_FORMAT_MINOR);
    tb_u32(b + SN_H_ENDIAN, SN_ENDIAN_MARK);
    tb_u32(b + SN_H_TOTAL_SIZE, off);
    tb_u32(b + SN_H_HEADER_SIZE, SN_HEADER_BYTES);
    b[SN_H_FLAVOUR] = SN_FLAVOUR;
    b[SN_H_REAL_SIZE] = 4;
    b[SN_H_NSECTIONS] = SN_SEC_COUNT;
    b[SN_H_FLAGS] = SN_FLAG_REST_MODELLED;
    tb_u32(b + SN_H_ONE, SN_FLAVOUR ? SN_ONE_FLOAT32 : SN_ONE_FIXED);
    tb_u32(b + SN_H_N_VERTICES, TB_NV);
    tb_u32(b + SN_H_N_FREE, TB_NF);
    tb_u32(b + SN_H_N_CELLS, TB_NC);
    tb_u32(b + SN_H_N_JOINTS, TB_NJ);
    tb_u32(b + SN_H_N_SURFACE, TB_NS);
    tb_u32(b + SN_H_N_TRIANGLES, TB_NT);
    tb_u32(b + SN_H_N_OFFDIAG, (uint32_t)nnz);
    tb_u32(b + SN_H_INSTANCE_BYTES, SN_INSTANCE_BYTES(TB_NV, TB_NF, TB_NJ, TB_NC, TB_NK, TB_NFRC, TB_SEGB + TB_CRB + TB_FPB, TB_CONB));
    b[SN_H_MAX_FORCES] = TB_NFRC;
    tb_u16(b + SN_H_CG_DEFAULT, 8);
    tb_u16(b + SN_H_CG_MAX, 32);
    b[SN_H_LEN_SHIFT] = (unsigned char)(len_shift & 0xFF);
    b[SN_H_FRAC_S] = b[SN_H_FRAC_P] = TB_FRAC;
    b[SN_H_FRAC_M] = TB_FRAC_M;
#if !defined(SN_FLOAT)
    b[SN_H_FRAC_E] = TB_FRAC_E;
    b[SN_H_FRAC_F] = TB_FRAC_F;
#endif
    tb_real(b + SN_H_REALS + SN_R_A1 * R, a1, SN_Q_COEF);
    tb_real(b + SN_H_REALS + SN_R_B1 * R, b1, SN_Q_COEF);
    tb_real(b + SN_H_REALS + SN_R_GRAV_Y * R, -9.81 / 3600.0, SN_Q_LEN);
    tb_real(b + SN_H_REALS + SN_R_TIMESTEP * R, h, 16);
    tb_real(b + SN_H_REALS + SN_R_MASS_SCALE * R, m0, 16);
    /* m0 (U unit)^2 / h^2, taking U unit = 1 m whatever len_shift is */
    tb_real(b + SN_H_REALS + SN_R_ENERGY * R, m0 / (h * h), TB_FRAC_E);
    tb_real(b + SN_H_REALS + SN_R_CELL * R, cell, SN_Q_LEN);
    tb_real(b + SN_H_REALS + SN_R_DISP_BOUND * R, 2.0, 16);
    tb_real(b + SN_H_REALS + SN_R_FORCE * R, 1.0 / 1024.0, TB_FRAC_F); /* 2^30 at Q40 */
    tb_fix_frefs(b);
    tb_fix_crc(b);
    return off;
}

/* Append an ICHOL section (format 6.0; followed by the empty ADAPT of 6.1) to a tb_build
 * blob of capacity cap: one block per free-free mass entry with mantissas
 * (7919 (n + k) mod 2001) - 1000 times 2^-frac (|U| <= 0.06 at frac 14),
 * frac = the argument; PRECOND stays (its blocks act as the pivots D^-1: any
 * U with SPD D^-1 gives an SPD preconditioner). Returns the new total size
 * (CRC recomputed), or 0 if it does not fit. */
static inline uint32_t tb_add_ichol(unsigned char *b, uint32_t cap, int frac) {
    unsigned char *e = b + SN_H_SECTIONS + 16 * SN_SEC_ICHOL, tail[512];
    const unsigned char *cols = b + tb_sec(b, SN_SEC_COLS);
    uint32_t nnz = tb_rd32(b + SN_H_N_OFFDIAG), nF = tb_rd32(b + SN_H_N_FREE), off = tb_rd32(e), i, n = 0, k, total;
    uint32_t tl = tb_rd32(b + SN_H_TOTAL_SIZE) - off, sp = tb_sec(b, SN_SEC_FPAIRS) - off, sr = tb_sec(b, SN_SEC_FREFS) - off;
    for (i = 0; i < nnz; i++) n += (uint32_t)(cols[2 * i] | cols[2 * i + 1] << 8) < nF;
    total = (off + n * SN_ELEM_ICHOL + 7u) & ~7u;
    if (total + tl > cap || tl > sizeof tail) return 0;
    memcpy(tail, b + off, tl); /* format 6.4: the frame references follow, moved after the factor */
    memset(b + off, 0, total - off);
    for (i = 0; i < n; i++) {
        unsigned char *q = b + off + i * SN_ELEM_ICHOL;
        for (k = 0; k < 9; k++) tb_u16(q + 2 * k, (uint32_t)((int32_t)((7919u * (i + k)) % 2001u) - 1000) & 0xFFFFu);
        q[18] = (unsigned char)frac;
    }
    tb_u32(e + 4, n * SN_ELEM_ICHOL);
    tb_u32(e + 8, n);
    tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_ADAPT, total); /* format 6.1: the empty ADAPT section follows */
    tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_CELLX, total); /* format 6.3: and the empty cut-level ones */
    tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_CELLXK, total);
    memcpy(b + total, tail, tl);
    tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_FPAIRS, total + sp);
    tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_FREFS, total + sr);
    total += tl;
    tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_DETAILS, total); /* format 6.5: the empty details', after the frame references */
    tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_DETAIL, total);
    tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_CELLD, total);
    tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_CELLDK, total);
    tb_u32(b + SN_H_TOTAL_SIZE, total);
    tb_fix_crc(b);
    return total;
}

/* Make the LIMIT section empty (count 0, size 0, bytes zeroed: a valid blob
 * without the limit stage); CRC recomputed. */
static inline void tb_drop_limit(unsigned char *b) {
    unsigned char *e = b + SN_H_SECTIONS + 16 * SN_SEC_LIMIT;
    memset(b + tb_sec(b, SN_SEC_LIMIT), 0, tb_rd32(e + 4));
    tb_u32(e + 4, 0);
    tb_u32(e + 8, 0);
    tb_fix_crc(b);
}
/* Empty the crease sections (bytes zeroed, count and size 0, offsets kept);
 * instance bytes without the crease state. No CRC. */
static inline void tb_drop_crease(unsigned char *b) {
    int k;
    for (k = SN_SEC_CREASE; k <= SN_SEC_CREASE_TNBR; k++) {
        unsigned char *e = b + SN_H_SECTIONS + 16 * k;
        memset(b + tb_rd32(e), 0, tb_rd32(e + 4));
        tb_u32(e + 4, 0);
        tb_u32(e + 8, 0);
    }
    tb_u32(b + SN_H_INSTANCE_BYTES, SN_INSTANCE_BYTES(TB_NV, TB_NF, TB_NJ, TB_NC, TB_NK, TB_NFRC, TB_SEGB + TB_FPB, TB_CONB_NOCR));
}
/* Empty every section after TRIS (rigs, force shares, segment meshes,
 * constraints, crease), placing them (8-aligned) at offset at (the end of
 * what the caller keeps); instance bytes follow nK = 0 and no segment state.
 * No CRC. */
static inline void tb_drop_after_tris(unsigned char *b, uint32_t at) {
    int k;
    at = (at + 7u) & ~7u;
    for (k = SN_SEC_CONTROLS; k < SN_SEC_COUNT; k++) {
        tb_u32(b + SN_H_SECTIONS + 16 * k, at);
        tb_u32(b + SN_H_SECTIONS + 16 * k + 4, 0);
        tb_u32(b + SN_H_SECTIONS + 16 * k + 8, 0);
    }
    tb_u32(b + SN_H_INSTANCE_BYTES, SN_INSTANCE_BYTES(TB_NV, TB_NF, TB_NJ, TB_NC, 0, TB_NFRC, 0, 0));
}
#endif
