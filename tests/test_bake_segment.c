/* test_bake_segment.c -- host tool, segment meshes (seed 004 ch. 3-4;
 * tools/DESCRIPTION.md "Segment meshes"): a chain, a shifted chain and a
 * three-level sheet on a 4-unit cube baked in the three flavours; the SEGMESH,
 * SEGNODES and SEGATTACH sections read back byte by byte from the
 * sn_format.h layout and compared with values re-derived here from the
 * description text (evenly spaced nodes, nearest cube corner, sorted joint
 * order from JOINT_NAMES, level counts from the spec prose), equal segment
 * lengths as stored, determinism, the instance size, and description errors
 * with file:line. */
#include "sb.h"
#include "sn_format.h"
#include "sn_test.h"
#include "blob_seg.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *dir(void) { return getenv("BUILD") ? getenv("BUILD") : "build"; }
static uint32_t u32(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static unsigned u16(const unsigned char *p) { return (unsigned)p[0] | (unsigned)p[1] << 8; }
static uint32_t sec_off(const unsigned char *b, int k) { return u32(b + SN_H_SECTIONS + 16 * k); }
static uint32_t sec_cnt(const unsigned char *b, int k) { return u32(b + SN_H_SECTIONS + 16 * k + 8); }
static uint32_t sec_esz(const unsigned char *b, int k) { return u32(b + SN_H_SECTIONS + 16 * k + 12); }
/* one real at p (flavour of the blob), fixed decoded with q fractional bits */
static double real(const unsigned char *b, const unsigned char *p, int q)
{
    int fl = b[SN_H_FLAVOUR];
    if (fl == 0) return ldexp((double)(int32_t)u32(p), -q);
    if (fl == 1) { float f; uint32_t u = u32(p); memcpy(&f, &u, 4); return f; }
    { double d; uint64_t u = (uint64_t)u32(p) | (uint64_t)u32(p + 4) << 32; memcpy(&d, &u, 8); return d; }
}

/* cube [0,4]^3: 8 corners, 12 triangles counter-clockwise outward */
static const double S = 4.0;
static int write_cube(const char *path)
{
    static const int f[12][3] = {{1, 3, 4}, {1, 4, 2}, {5, 6, 8}, {5, 8, 7}, {1, 2, 6}, {1, 6, 5},
                                 {3, 7, 8}, {3, 8, 4}, {1, 5, 7}, {1, 7, 3}, {2, 4, 8}, {2, 8, 6}};
    FILE *o = fopen(path, "w");
    int k;
    if (!o) return -1;
    for (k = 0; k < 8; k++) fprintf(o, "v %g %g %g\n", (k >> 2 & 1) * S, (k >> 1 & 1) * S, (k & 1) * S);
    for (k = 0; k < 12; k++) fprintf(o, "f %d %d %d\n", f[k][0], f[k][2], f[k][1]);
    return fclose(o);
}
static void corner(int k, double p[3]) { p[0] = (k >> 2 & 1) * S; p[1] = (k >> 1 & 1) * S; p[2] = (k & 1) * S; }
static int nearest_corner(const double p[3])
{
    int k, best = 0;
    double bd = 1e300;
    for (k = 0; k < 8; k++) {
        double c[3], d;
        corner(k, c);
        d = (c[0] - p[0]) * (c[0] - p[0]) + (c[1] - p[1]) * (c[1] - p[1]) + (c[2] - p[2]) * (c[2] - p[2]);
        if (d < bd) { bd = d; best = k; }
    }
    return best;
}

static int write_text(const char *name, const char *text, char *path, size_t pn)
{
    FILE *f;
    snprintf(path, pn, "%s/tests/%s.sinew", dir(), name);
    f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    return fclose(f);
}

/* The description under test. Joint 'tip' is declared before its parent
 * 'mid', so the blob's (sorted) order differs from the description's. */
#define HEAD "mesh cube.obj\nunit 0.05\ncell 2\nsubdiv 2\n" \
             "joint root - 2 2 2\njoint tip mid 3.2 2 2\njoint mid root 2.6 2 2\nmaterial flesh 1e5 0.3 1000\n"
static const char *DESC = HEAD
    "chain tail nodes 9 from 4 4 4 to 4 8 4 mass 0.4 sweeps 12 gamma 0.7 damping 3 centre 0.25 relax 1.5\n"
    "attach tail first surface\n"
    "attach tail last joint tip\n"
    "chain off nodes 2 from 4.1 3.9 4.05 to 4.1 3.9 6.05 gravity off\n"
    "attach off first surface within 0.2\n"
    "sheet cape side 5 corner 0 4 0 u 4 0 0 v 0 0 4 shares 0.5 0.3 0.2 mass 2 coarse_sweeps 3\n"
    "attach cape corners surface\n"
    "attach cape node 12 joint mid\n";

/* what the description says, transcribed */
typedef struct {
    int kind, side, levels, sweeps, gravity;
    double p0[3], u[3], v[3], mass, gamma, damping, centre, share[4];
    int coarse_sweeps, relax; /* format 6.2: = sweeps unless given; 32 omega */
} expect_mesh;
static const expect_mesh EM[3] = {
    {0, 9, 1, 12, 1, {4, 4, 4}, {0, 4, 0}, {0, 0, 0}, 0.4, 0.7, 3, 0.25, {1, 0, 0, 0}, 12, 48},
    {0, 2, 1, 8, 0, {4.1, 3.9, 4.05}, {0, 0, 2}, {0, 0, 0}, 1, 0.5, 0.5, 0.5, {1, 0, 0, 0}, 8, 32},
    {1, 5, 3, 8, 1, {0, 4, 0}, {4, 0, 0}, {0, 0, 4}, 2, 0.5, 0.5, 0.5, {0.5, 0.3, 0.2, 0}, 3, 32},
};
/* attachments, node order: node, kind, joint name or NULL (surface) */
typedef struct { int mesh, node, kind; const char *joint; } expect_att;
static const expect_att EA[] = {
    {0, 0, SN_SEGATT_SURFACE, NULL}, {0, 8, SN_SEGATT_JOINT, "tip"},
    {1, 0, SN_SEGATT_SURFACE, NULL},
    {2, 0, SN_SEGATT_SURFACE, NULL}, {2, 4, SN_SEGATT_SURFACE, NULL}, {2, 12, SN_SEGATT_JOINT, "mid"},
    {2, 20, SN_SEGATT_SURFACE, NULL}, {2, 24, SN_SEGATT_SURFACE, NULL},
};
#define NEA ((int)(sizeof EA / sizeof EA[0]))
/* spec prose: chain N nodes -> N-1 segments; sheet level l side s_l = (side-1)/2^l + 1,
 * 2 s (s-1) segments, s^2 nodes, plus 2 braces when s = 2: 5x5 / 3x3 / 2x2 */
static const uint32_t SEGS_ALL[3] = {8, 1, 40 + 12 + (4 + 2)}, NODES_ALL[3] = {9, 2, 25 + 9 + 4};

static void node_pos(const expect_mesh *e, int i, const double shift[3], double p[3])
{
    int k, c = e->kind ? i % e->side : i, r = e->kind ? i / e->side : 0;
    for (k = 0; k < 3; k++) p[k] = e->p0[k] + (double)c / (e->side - 1) * e->u[k] + (double)r / (e->side - 1) * e->v[k] + shift[k];
}

static void check_blob(const sb_blob *bl, int flavour, double h)
{
    const unsigned char *b = bl->bytes;
    const char *fname = flavour == 0 ? "fixed" : flavour == 1 ? "float" : "double";
    int rs = flavour == SB_DOUBLE ? 8 : 4, m, i, k, ai = 0;
    int s = (int8_t)b[SN_H_LEN_SHIFT];
    double U = ldexp(1.0, s), root[3] = {2, 2, 2};
    /* tolerance on a decoded length (internal units): half an LSB of Q22, float32 rounding, exact */
    double tl = flavour == 0 ? ldexp(1.0, -23) * 1.0001 : flavour == 1 ? 64 * ldexp(1.0, -24) : 1e-12;
    double tq = flavour == 0 ? ldexp(1.0, -31) * 1.0001 : flavour == 1 ? ldexp(1.0, -24) : 1e-15;   /* Q30 fraction */
    uint32_t fn = 0, fa = 0, segB = 0, jn = sec_cnt(b, SN_SEC_JOINTS);
    T_CHECK(sec_cnt(b, SN_SEC_SEGMESH) == 3 && sec_esz(b, SN_SEC_SEGMESH) == 20u + 9u * (uint32_t)rs, "%s: SEGMESH 3 records of 20 + 9R bytes", fname);
    T_CHECK(sec_cnt(b, SN_SEC_SEGNODES) == 9 + 2 + 25 && sec_esz(b, SN_SEC_SEGNODES) == 3u * (uint32_t)rs, "%s: SEGNODES 36 x 3R", fname);
    T_CHECK(sec_cnt(b, SN_SEC_SEGATTACH) == (uint32_t)NEA && sec_esz(b, SN_SEC_SEGATTACH) == 8u + 3u * (uint32_t)rs, "%s: SEGATTACH %d x (8 + 3R)", fname, NEA);
    for (m = 0; m < 3; m++) {
        const expect_mesh *e = &EM[m];
        const unsigned char *r = b + sec_off(b, SN_SEC_SEGMESH) + (size_t)m * sec_esz(b, SN_SEC_SEGMESH);
        int nodes = e->kind ? e->side * e->side : e->side, segs = e->kind ? 2 * e->side * (e->side - 1) : e->side - 1, na = 0, ns;
        double L = sqrt(e->u[0] * e->u[0] + e->u[1] * e->u[1] + e->u[2] * e->u[2]) / (e->side - 1);
        double shift[3] = {0, 0, 0}, c[3], p0[3], sum = 0, q[4], inv = bl->m0 / (e->mass / segs), worst = 0;
        for (i = 0; i < NEA; i++) na += EA[i].mesh == m;
        /* the mesh moves by the mean offset of its surface nodes to their nearest corners */
        for (i = 0, ns = 0; i < NEA; i++) {
            double z[3] = {0, 0, 0};
            if (EA[i].mesh != m || EA[i].kind != SN_SEGATT_SURFACE) continue;
            node_pos(e, EA[i].node, z, p0);
            corner(nearest_corner(p0), c);
            for (k = 0; k < 3; k++) shift[k] += c[k] - p0[k];
            ns++;
        }
        for (k = 0; k < 3; k++) shift[k] /= ns;
        T_CHECK(r[0] == (e->kind ? SN_SEG_SHEET : SN_SEG_CHAIN) && r[1] == e->levels && r[2] == e->sweeps &&
                r[3] == (e->gravity ? 0 : SN_SEGF_NO_GRAVITY) && u16(r + 4) == (unsigned)e->side && u16(r + 6) == (unsigned)na,
                "%s mesh %d: kind %u levels %u sweeps %u flags %u side %u n_attach %u", fname, m, r[0], r[1], r[2], r[3], u16(r + 4), u16(r + 6));
        T_CHECK(r[16 + 9 * rs] == e->coarse_sweeps && r[17 + 9 * rs] == e->relax && u16(r + 18 + 9 * rs) == 0,
                "%s mesh %d: coarse_sweeps %u (want %d) relax %u (want %d), then u16 0", fname, m, r[16 + 9 * rs], e->coarse_sweeps,
                r[17 + 9 * rs], e->relax);
        T_CHECK(u32(r + 8) == fn && u32(r + 12) == fa, "%s mesh %d: first_node %u first_attach %u (running sums %u %u)", fname, m, u32(r + 8), u32(r + 12), fn, fa);
        T_NEAR(real(b, r + 16, SN_Q_LEN), L / U, tl, "seg_len: rounding of the stored real");
        T_NEAR(real(b, r + 16 + rs, SN_Q_ROT), e->gamma, tq, "gamma Q30 rounding");
        T_NEAR(real(b, r + 16 + 2 * rs, SN_Q_ROT), exp(-e->damping * h), tq, "keep = exp(-damping h), Q30 rounding");
        T_NEAR(real(b, r + 16 + 3 * rs, 16), inv, flavour == 0 ? ldexp(1.0, -17) * 1.0001 : inv * 1e-7, "inv_mass = m0 / (mass / segments), Q16.16 rounding");
        T_NEAR(real(b, r + 16 + 4 * rs, SN_Q_ROT), e->centre, tq, "centre Q30 rounding");
        for (k = 0; k < 4; k++) {
            q[k] = real(b, r + 16 + (5 + k) * rs, SN_Q_ROT);
            sum += q[k];
            T_NEAR(q[k], e->share[k], 2 * tq, "share Q30 (the finest takes the others' rounding)");
        }
        if (flavour == 0) {
            int64_t isum = 0;
            for (k = 0; k < 4; k++) isum += (int32_t)u32(r + 16 + (5 + k) * rs);
            T_CHECK(isum == ((int64_t)1 << 30), "fixed mesh %d: shares sum to exactly 2^30 (got %lld)", m, (long long)isum);
        } else T_NEAR(sum, 1.0, 1e-6, "shares sum to 1 within float rounding");
        for (i = 0; i < nodes; i++) {
            const unsigned char *p = b + sec_off(b, SN_SEC_SEGNODES) + (size_t)(fn + (uint32_t)i) * sec_esz(b, SN_SEC_SEGNODES);
            double x[3];
            node_pos(e, i, shift, x);
            for (k = 0; k < 3; k++) worst = fmax(worst, fabs(real(b, p + k * rs, SN_Q_LEN) - (x[k] - root[k]) / U));
        }
        T_CHECK(worst <= tl, "%s mesh %d: rest nodes (evenly spaced, shifted by (%g %g %g)) off by %g internal units", fname, m, shift[0], shift[1], shift[2], worst);
        {   /* what the runtime validator requires: neighbours exactly seg_len apart as stored */
            double sl = real(b, r + 16, SN_Q_LEN), dev = 0;
            int nb = 0;
            for (i = 0; i < nodes; i++) {
                int dirs[2], nd = 0, t;
                if (e->kind) { if (i % e->side + 1 < e->side) dirs[nd++] = i + 1; if (i / e->side + 1 < e->side) dirs[nd++] = i + e->side; }
                else if (i + 1 < nodes) dirs[nd++] = i + 1;
                for (t = 0; t < nd; t++) {
                    const unsigned char *pa = b + sec_off(b, SN_SEC_SEGNODES) + (size_t)(fn + (uint32_t)i) * sec_esz(b, SN_SEC_SEGNODES);
                    const unsigned char *pb = b + sec_off(b, SN_SEC_SEGNODES) + (size_t)(fn + (uint32_t)dirs[t]) * sec_esz(b, SN_SEC_SEGNODES);
                    double d2 = 0;
                    for (k = 0; k < 3; k++) { double dd = real(b, pb + k * rs, SN_Q_LEN) - real(b, pa + k * rs, SN_Q_LEN); d2 += dd * dd; }
                    dev = fmax(dev, fabs(sqrt(d2) - sl) / sl);
                    nb++;
                }
            }
            T_CHECK(nb == segs && dev <= 1e-5, "%s mesh %d: %d stored segments, lengths within %g of seg_len (want 1e-5)", fname, m, nb, dev);
        }
        segB += SN_SEG_SEG_BYTES * SEGS_ALL[m] + SN_SEG_NODE_BYTES * NODES_ALL[m];
        for (i = 0; i < na; i++, ai++) {
            const expect_att *ea = &EA[ai];
            const unsigned char *p = b + sec_off(b, SN_SEC_SEGATTACH) + (size_t)(fa + (uint32_t)i) * sec_esz(b, SN_SEC_SEGATTACH);
            double x[3];
            node_pos(e, ea->node, shift, x);
            T_CHECK(u16(p) == (unsigned)ea->node && p[2] == ea->kind && p[3] == 0 && u16(p + 6) == 0,
                    "%s mesh %d attachment %d: node %u kind %u (want %d %d)", fname, m, i, u16(p), p[2], ea->node, ea->kind);
            if (ea->kind == SN_SEGATT_JOINT) {
                uint32_t j, want = 0xFFFF;
                for (j = 0; j < jn; j++) if (!strcmp((const char *)b + sec_off(b, SN_SEC_JOINT_NAMES) + 32 * j, ea->joint)) want = j;
                T_CHECK(u16(p + 4) == want, "%s mesh %d attachment %d: joint target %u, want '%s' = blob joint %u", fname, m, i, u16(p + 4), ea->joint, (unsigned)want);
                for (k = 0; k < 3; k++) T_NEAR(real(b, p + 8 + k * rs, SN_Q_LEN), (x[k] - root[k]) / U, tl, "joint point = the node's rest position");
            } else {
                int want = nearest_corner(x);
                /* sb_mesh_load_obj keeps the OBJ's vertex order: surface vertex k = corner k */
                T_CHECK(u16(p + 4) == (unsigned)want, "%s mesh %d attachment %d: surface vertex %u, want nearest corner %d", fname, m, i, u16(p + 4), want);
                for (k = 0; k < 3; k++) T_CHECK(real(b, p + 8 + k * rs, SN_Q_LEN) == 0, "%s: SURFACE point is 0", fname);
            }
        }
        fn += (uint32_t)nodes;
        fa += (uint32_t)na;
    }
    T_CHECK(segB == 728 + (64 + 48) + (58 * 64 + 38 * 24), "segment state bytes by hand");
    T_CHECK(u32(b + SN_H_INSTANCE_BYTES) == SN_INSTANCE_BYTES(u32(b + SN_H_N_VERTICES), u32(b + SN_H_N_FREE), u32(b + SN_H_N_JOINTS),
                                                            u32(b + SN_H_N_CELLS), sec_cnt(b, SN_SEC_CONTROLS), b[SN_H_MAX_FORCES], segB + crease_state_bytes(b) + sec_cnt(b, SN_SEC_FPAIRS) * SN_FPAIR_BYTES, cons_state_bytes(b)),
            "%s: instance bytes include %u segment state bytes", fname, (unsigned)segB);
}

/* description errors: each bad line appended to HEAD (line 9) */
static void check_errors(void)
{
    static const struct { const char *line, *msg; } bad[] = {
        {"chain t nodes 1 from 0 0 0 to 1 0 0", ":9: '1' must be an integer in 2..256"},
        {"chain t nodes 4 from 0 0 0 to 0 0 0", ":9: chain 't' has zero length"},
        {"chain t nodes 4 from 0 0 0", ":9: missing value: 'chain NAME nodes N from X Y Z to X Y Z [OPTIONS]'"},
        {"chain t nodes 4 from 0 0 0 to 1 0 x", ":9: 'x' is not a number"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 gamma 0", ":9: gamma (translation factor) must be in (0, 1]"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 gamma 1.5", ":9: gamma (translation factor) must be in (0, 1]"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 damping -1", ":9: damping must be in [0, 1e4] per second"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 centre 2", ":9: centre share must be in [0, 1]"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 mass 0", ":9: mass must be in (0, 1e6] kg"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 sweeps 0", ":9: '0' must be an integer in 1..64"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 gravity maybe", ":9: gravity must be 'on' or 'off'"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 wobble 3", ":9: unknown chain option 'wobble'"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 mass", ":9: missing value after 'mass'"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 levels 2", ":9: 'levels' is for sheets"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 coarse_sweeps 2", ":9: 'coarse_sweeps' is for sheets"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 relax 0.9", ":9: relax (over-relaxation omega) must be in [1, 1.96875] (got 0.9)"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 relax 2", ":9: relax (over-relaxation omega) must be in [1, 1.96875] (got 2)"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 relax 1.7", ":9: relax 1.7 is not a multiple of 1/32 (the blob stores 32 omega): use 1.6875 or 1.71875"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 relax 1.5 gamma 0.25", ":9: chain 't': relax 1.5 with gamma 0.25 over-relaxes the turns: want relax (1 - gamma) <= 1 (relax <= 1.3125)"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 relax", ":9: missing value after 'relax'"},
        {"sheet s side 9 corner 0 0 0 u 1 0 0 v 0 1 0 coarse_sweeps 2", ":9: sheet 's': 'coarse_sweeps' needs levels >= 2"},
        {"sheet s side 9 corner 0 0 0 u 1 0 0 v 0 1 0 levels 2 coarse_sweeps 65", ":9: '65' must be an integer in 1..64"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0 shares 1", ":9: 'shares' is for sheets"},
        {"sheet s side 4 corner 0 0 0 u 1 0 0 v 0 1 0", ":9: sheet side 4 is not 2^n + 1"},
        {"sheet s side 9 corner 0 0 0 u 1 0 0 v 0 2 0", ":9: sheet 's': edges u and v have lengths 1 and 2"},
        {"sheet s side 9 corner 0 0 0 u 1 0 0 v 1 1 0", ":9: sheet 's': edges u and v have lengths"},
        {"sheet s side 9 corner 0 0 0 u 1 0 0 v 0.6 0.8 0", ":9: sheet 's': edges u and v are not perpendicular"},
        {"sheet s side 3 corner 0 0 0 u 1 0 0 v 0 1 0 levels 3", ":9: sheet 's': 3 levels, at most 2 for side 3"},
        {"sheet s side 65 corner 0 0 0 u 1 0 0 v 0 1 0 levels 5", ":9: '5' must be an integer in 1..4"},
        {"sheet s side 9 corner 0 0 0 u 1 0 0 v 0 1 0 shares 0.5 0.4", ":9: sheet 's': shares sum to 0.9"},
        {"sheet s side 9 corner 0 0 0 u 1 0 0 v 0 1 0 levels 3 shares 0.5 0.5", ":9: sheet 's': 2 share(s) for 3 level(s)"},
        {"sheet s side 9 corner 0 0 0 u 1 0 0 v 0 1 0 shares 0.2 0.2 0.2 0.2 0.2", ":9: 'shares' takes at most 4 values"},
        {"sheet s side 9 corner 0 0 0 u 1 0 0 v 0 1 0 shares 1.5 -0.5", ":9: share '1.5' must be in [0, 1]"},
        {"sheet s side 9 corner 0 0 0 x 1 0 0 v 0 1 0", ":9: 'sheet NAME side S corner"},
        {"attach nothing first surface", ":9: unknown segment mesh 'nothing'"},
    };
    static const struct { const char *lines, *msg; } bad2[] = {   /* two lines: the second is line 10 */
        {"chain t nodes 4 from 0 0 0 to 1 0 0\nchain t nodes 4 from 0 0 0 to 1 0 0", ":10: segment mesh 't' declared twice"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0\nattach t row 0 surface", ":10: 'row' is for sheets"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0\nattach t corners surface", ":10: 'corners' is for sheets"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0\nattach t node 4 surface", ":10: '4' must be an integer in 0..3"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0\nattach t first bone", ":10: unknown attachment target 'bone' (want surface or joint)"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0\nattach t first joint nose", ":10: unknown joint 'nose'"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0\nattach t first", ":10: missing value: 'attach MESH NODES surface [within D]' or"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0\nattach t first surface within", ":10: missing value: 'attach MESH NODES surface [within D]'"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0\nattach t first surface within -1", ":10: 'within' distance must be >= 0"},
        {"chain t nodes 4 from 0 0 0 to 1 0 0\nattach t first joint root extra", ":10: too many values"},
        {"sheet s side 5 corner 0 0 0 u 1 0 0 v 0 1 0\nattach s corners blah", ":10: unknown attachment target 'blah'"},
        {"sheet s side 5 corner 0 0 0 u 1 0 0 v 0 1 0\nattach s col 5 surface", ":10: '5' must be an integer in 0..4"},
        {"sheet s side 5 corner 0 0 0 u 4 0 0 v 0 4 0\nattach s corners surface\nattach s first joint root", ":11: sheet 's': node 0 is already attached (line 10)"},
    };
    char path[512], text[2048];
    unsigned i;
    for (i = 0; i < sizeof bad / sizeof bad[0] + sizeof bad2 / sizeof bad2[0]; i++) {
        sb_desc d;
        int rc;
        const char *line = i < sizeof bad / sizeof bad[0] ? bad[i].line : bad2[i - sizeof bad / sizeof bad[0]].lines;
        const char *msg = i < sizeof bad / sizeof bad[0] ? bad[i].msg : bad2[i - sizeof bad / sizeof bad[0]].msg;
        snprintf(text, sizeof text, "%s%s\n", HEAD, line);
        if (write_text("seg_err", text, path, sizeof path)) { T_CHECK(0, "cannot write %s", path); return; }
        rc = sb_desc_load(path, &d);
        T_CHECK(rc != 0 && strstr(sb_error(), msg) != NULL, "'%s': want error containing \"%s\", got %s \"%s\"", line, msg, rc ? "error" : "success", rc ? sb_error() : "");
        sb_desc_free(&d);
    }
    /* build-time errors: a surface attachment too far from the surface (file:line of the attach) */
    {
        static const struct { const char *lines, *msg; } far[] = {
            {"chain t nodes 3 from 2 2 2 to 2 3 2\nattach t first surface", ":10: chain 't' node 0 at (2, 2, 2) is 3.4641 from the nearest surface vertex 0"},
            {"chain t nodes 3 from 0 4.3 0 to 0 6.3 0\nattach t first surface within 0.2", ":10: chain 't' node 0 at (0, 4.3, 0) is 0.3 from the nearest surface vertex 2 at (0, 4, 0), more than 0.2"},
            {"sheet s side 3 corner 0 4 0 u 3 0 0 v 0 0 3\nattach s corners surface", ":10: sheet 's' node 2 at (3, 4, 0) is 1 from the nearest surface vertex 6 at (4, 4, 0), more than 0.75 (half a segment)"},
            {"chain t nodes 2 from 0 4 0 to 0 400 0", ":9: chain 't' node 1 lies"},
            /* node 0 is 0.5 off (within 0.6), node 2 is 1 off (within 2): the mean move (-0.25, 0, 0) leaves node 0 0.75 off */
            {"sheet s side 3 corner -0.5 4 0 u 5.5 0 0 v 0 0 5.5\nattach s node 0 surface within 0.6\nattach s node 2 surface within 2",
             ":10: sheet 's' node 0 is 0.75 from the nearest surface vertex 2 after the sheet moved by (-0.25, 0, 0)"},
        };
        for (i = 0; i < sizeof far / sizeof far[0]; i++) {
            sb_model o;
            sb_blob bl;
            int rc;
            snprintf(text, sizeof text, "%s%s\n", HEAD, far[i].lines);
            if (write_text("seg_far", text, path, sizeof path)) { T_CHECK(0, "cannot write %s", path); return; }
            rc = sb_bake_file(path, SB_FIXED, 1, &o, &bl);
            T_CHECK(rc != 0 && strstr(sb_error(), far[i].msg) != NULL, "'%s': want error containing \"%s\", got %s \"%s\"", far[i].lines, far[i].msg,
                    rc ? "error" : "success", rc ? sb_error() : "");
            if (rc == 0) { sb_blob_free(&bl); sb_model_free(&o); }
        }
    }
}

int main(void)
{
    char cube[512], path[512];
    int fl;
    (void)t_seed;   /* deterministic: no random cases */
    snprintf(cube, sizeof cube, "%s/tests/cube.obj", dir());
    if (write_cube(cube) || write_text("seg_ok", DESC, path, sizeof path)) { printf("cannot write under %s/tests\n", dir()); return 1; }
    for (fl = 0; fl < 3; fl++) {
        sb_model o, o2;
        sb_blob b, b2;
        if (sb_bake_file(path, fl, 1, &o, &b)) { T_CHECK(0, "bake flavour %d: %s", fl, sb_error()); continue; }
        check_blob(&b, fl, 1.0 / 60.0);
        if (sb_bake_file(path, fl, 1, &o2, &b2) == 0) {
            T_CHECK(b.size == b2.size && memcmp(b.bytes, b2.bytes, b.size) == 0, "flavour %d: two bakes give identical bytes", fl);
            sb_blob_free(&b2); sb_model_free(&o2);
        }
        sb_blob_free(&b); sb_model_free(&o);
    }
    {   /* no segment lines: the three sections are empty and add no state */
        sb_model o;
        sb_blob b;
        if (write_text("seg_none", HEAD, path, sizeof path) == 0 && sb_bake_file(path, SB_FIXED, 1, &o, &b) == 0) {
            T_CHECK(sec_cnt(b.bytes, SN_SEC_SEGMESH) == 0 && sec_cnt(b.bytes, SN_SEC_SEGNODES) == 0 && sec_cnt(b.bytes, SN_SEC_SEGATTACH) == 0,
                    "no segment meshes: empty sections");
            sb_blob_free(&b); sb_model_free(&o);
        } else T_CHECK(0, "bake without segments: %s", sb_error());
    }
    check_errors();
    return T_END();
}
