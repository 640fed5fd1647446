/* test_bake_rig.c -- host tool, rig forces (issue 10; seed 003 §4.1-4.2, eq. 4,
 * 11-12): each force-field template integrated over one fully inside cell
 * against an independent double reference (the template formulas of
 * tools/DESCRIPTION.md re-implemented here, integrated by a 64-point-per-axis
 * composite Gauss-Legendre rule; the uniform field analytically), partition of
 * unity, a bump's peak and sign, the tau map, the five blob sections read back
 * byte by byte (sn_format.h layout, not the writer's code) for the fixed,
 * float32 and float64 cow, the limb's pose control, and description errors. */
#include "sb.h"
#include "sn_format.h"
#include "blob_seg.h"
#include "sn_test.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *dir(void) { return getenv("BUILD") ? getenv("BUILD") : "build"; }

/* closed box [0,s]^3, 12 triangles, counter-clockwise outward */
static int write_cube_obj(const char *path, double s)
{
    static const int f[12][3] = {{1, 3, 4}, {1, 4, 2}, {5, 6, 8}, {5, 8, 7}, {1, 2, 6}, {1, 6, 5},
                                 {3, 7, 8}, {3, 8, 4}, {1, 5, 7}, {1, 7, 3}, {2, 4, 8}, {2, 8, 6}};
    FILE *o = fopen(path, "w");
    int k;
    if (!o) return -1;
    for (k = 0; k < 8; k++) fprintf(o, "v %g %g %g\n", (k >> 2 & 1) * s, (k >> 1 & 1) * s, (k & 1) * s);
    for (k = 0; k < 12; k++) fprintf(o, "f %d %d %d\n", f[k][0], f[k][2], f[k][1]);
    return fclose(o);
}

/* bake description text (written to BUILD/tests/NAME.sinew) into a model with rigs */
static int build_text(const char *name, const char *text, sb_model *o, char *path, size_t pn)
{
    sb_desc d;
    sb_mesh m;
    FILE *f;
    int rc;
    snprintf(path, pn, "%s/tests/%s.sinew", dir(), name);
    f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    fclose(f);
    memset(&m, 0, sizeof m);
    memset(o, 0, sizeof *o);
    if (sb_desc_load(path, &d)) return -1;
    rc = sb_mesh_load_obj(d.mesh_path, &m) || sb_build(&d, &m, o, 1) || sb_rig_build(&d, &m, o) ? -1 : 0;
    sb_mesh_free(&m);
    sb_desc_free(&d);
    return rc;
}

/* ---- independent reference fields (tools/DESCRIPTION.md "Rigs and controls") ---- */
typedef struct { int tpl; double s, E, unit, p[10]; int dir; } ref_rig;
static double nrm(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
static void ref_field(const ref_rig *r, const double x[3], double f[3])
{
    const double *p = r->p;
    double d[3], u, L;
    int k;
    f[0] = f[1] = f[2] = 0;
    if (r->tpl == SB_TPL_BUMP) {
        double amp = r->s * r->E / (p[3] * r->unit);
        for (k = 0; k < 3; k++) d[k] = x[k] - p[k];
        u = nrm(d) / p[3];
        if (u >= 1) return;
        if (r->dir) {
            double dn = nrm(p + 4);
            for (k = 0; k < 3; k++) f[k] = amp * pow(1 - u * u, 3) * p[4 + k] / dn;
        } else {   /* radial: g(u) (x-c)/|x-c|, g(u) = (25 sqrt5 / 16) u (1-u^2)^2 */
            if (u == 0) return;
            for (k = 0; k < 3; k++) f[k] = amp * (25 * sqrt(5.0) / 16) * u * pow(1 - u * u, 2) * d[k] / nrm(d);
        }
    } else if (r->tpl == SB_TPL_RING) {
        double a[3], an = nrm(p + 3), z = 0, rv[3], rho, del, amp = r->s * r->E / (p[7] * r->unit);
        for (k = 0; k < 3; k++) { a[k] = p[3 + k] / an; d[k] = x[k] - p[k]; z += d[k] * a[k]; }
        for (k = 0; k < 3; k++) rv[k] = d[k] - z * a[k];
        rho = nrm(rv);
        del = sqrt((rho - p[6]) * (rho - p[6]) + z * z) / p[7];
        if (del >= 1 || rho == 0) return;
        for (k = 0; k < 3; k++) f[k] = amp * pow(1 - del * del, 3) * rv[k] / rho;
    } else if (r->tpl == SB_TPL_MUSCLE) {
        double e[3], t = 0, pv[3], amp = r->s * r->E / (p[6] * r->unit), m, h;
        for (k = 0; k < 3; k++) e[k] = p[3 + k] - p[k];
        L = nrm(e);
        for (k = 0; k < 3; k++) { e[k] /= L; d[k] = x[k] - p[k]; t += d[k] * e[k]; }
        t /= L;
        if (t <= 0 || t >= 1) return;
        for (k = 0; k < 3; k++) pv[k] = d[k] - t * L * e[k];
        u = nrm(pv) / p[6];
        if (u >= 1) return;
        m = 16 * pow(t * (1 - t), 2);
        h = 25 * sqrt(5.0) * pow(t * (1 - t), 2) * (1 - 2 * t);
        for (k = 0; k < 3; k++)
            f[k] = amp * ((u > 0 ? m * (25 * sqrt(5.0) / 16) * u * pow(1 - u * u, 2) * pv[k] / nrm(pv) : 0) + p[7] * h * pow(1 - u * u, 3) * e[k]);
    } else {
        double amp = r->s * r->E / (p[3] * r->unit), dn = nrm(p);   /* p[3]: the reference size */
        for (k = 0; k < 3; k++) f[k] = amp * p[k] / dn;
    }
}

/* Q_a = int_cell N_a f dV over the cube [0,a]^3 (mesh units, a*unit metres): composite
 * Gauss-Legendre, 8 intervals x 8 points per axis (nodes from Newton on P_8). */
static void ref_integrate(const ref_rig *r, double a, double Q[8][3], double tot[3])
{
    double x8[8], w8[8], X[64], W[64];
    int i, j, k, c, n = 8;
    for (i = 0; i < n; i++) {   /* Legendre roots on [-1,1] */
        double z = cos(3.14159265358979323846 * (i + 0.75) / (n + 0.5)), p0, p1, dp;
        int it, l;
        for (it = 0; it < 100; it++) {
            p0 = 1; p1 = z;
            for (l = 2; l <= n; l++) { double p2 = ((2 * l - 1) * z * p1 - (l - 1) * p0) / l; p0 = p1; p1 = p2; }
            dp = n * (z * p1 - p0) / (z * z - 1);
            z -= p1 / dp;
        }
        p0 = 1; p1 = z;
        { int l2; for (l2 = 2; l2 <= n; l2++) { double p2 = ((2 * l2 - 1) * z * p1 - (l2 - 1) * p0) / l2; p0 = p1; p1 = p2; } }
        dp = n * (z * p1 - p0) / (z * z - 1);
        x8[i] = 0.5 * (z + 1); w8[i] = 1.0 / ((1 - z * z) * dp * dp);   /* on [0,1]: w = 2/((1-z^2)P'^2) / 2 */
    }
    for (i = 0; i < 8; i++) for (j = 0; j < 8; j++) { X[8 * i + j] = (i + x8[j]) / 8; W[8 * i + j] = w8[j] / 8; }
    memset(Q, 0, sizeof(double) * 24);
    tot[0] = tot[1] = tot[2] = 0;
    for (i = 0; i < 64; i++)
        for (j = 0; j < 64; j++)
            for (k = 0; k < 64; k++) {
                double t[3] = {X[i], X[j], X[k]}, x[3], f[3], w = W[i] * W[j] * W[k] * pow(a * r->unit, 3);
                int q;
                for (q = 0; q < 3; q++) x[q] = t[q] * a;
                ref_field(r, x, f);
                if (f[0] == 0 && f[1] == 0 && f[2] == 0) continue;
                for (c = 0; c < 8; c++) {
                    double N = 1;
                    for (q = 0; q < 3; q++) N *= (c >> q & 1) ? t[q] : 1 - t[q];
                    for (q = 0; q < 3; q++) Q[c][q] += w * N * f[q];
                }
                for (q = 0; q < 3; q++) tot[q] += w * f[q];
            }
}

/* 1. templates on one fully inside cell (default subdiv 4). Tolerance of the
 * non-uniform templates, 2e-4 of the largest |Q_i|: the tool integrates with
 * 2x2x2 Gauss points on boxes of edge <= (template feature)/8 (sb_rig.c); the
 * profiles are degree <= 7 polynomials inside their support with a C1/C2 rim,
 * and without the refinement the error measured on these fields fell as
 * h^4..h^5 (bump: 6e-3, 3e-4, 8e-6 of the peak at 4, 8, 16 sub-boxes per
 * cell edge; ring 1e-1, 2e-3, 8e-5), i.e. ~1e-5 at a box edge of feature/8
 * (measured with it: 1e-6..6e-6, so 5e-5 leaves a margin of 8); the reference
 * (64 Gauss-Legendre points per axis, 8 per box of 1/8 cell) is ~1e-7. */
#define RIG_WHY "2x2x2 Gauss on boxes <= feature/8: h^4..h^5 convergence puts it near 1e-5 of the peak (measured <= 6e-6); reference ~1e-7"
static void test_templates(void)
{
    static const struct { const char *line; ref_rig r; double tol; const char *why; } T[] = {
        {"rig u c uniform 0.2   1 2 -2   all", {SB_TPL_UNIFORM, 0.2, 2e5, 0.3, {1, 2, -2, 1.0}, 0}, 1e-11,
         "analytic Q_i = f V/8; the 2-point Gauss rule integrates constant x trilinear exactly: round-off of the 2.6e5-term reference sums"},
        {"rig bd c bump 0.15   0.8 1.1 0.9   0.7   0.3 -1 0.5", {SB_TPL_BUMP, 0.15, 2e5, 0.3, {0.8, 1.1, 0.9, 0.7, 0.3, -1, 0.5}, 1}, 5e-5, RIG_WHY},
        {"rig br c bump -0.1   1 1 1   0.9", {SB_TPL_BUMP, -0.1, 2e5, 0.3, {1, 1, 1, 0.9}, 0}, 5e-5, RIG_WHY},
        {"rig rg c ring 0.3   1.0 0.9 1.1   1 1 0   0.5 0.35", {SB_TPL_RING, 0.3, 2e5, 0.3, {1.0, 0.9, 1.1, 1, 1, 0, 0.5, 0.35}, 0}, 5e-5, RIG_WHY},
        {"rig ms c muscle 0.25   0.4 0.6 0.7   1.6 1.3 1.2   0.5 0.7", {SB_TPL_MUSCLE, 0.25, 2e5, 0.3, {0.4, 0.6, 0.7, 1.6, 1.3, 1.2, 0.5, 0.7}, 0}, 5e-5,
         RIG_WHY " (the muscle's ends reach outside the cell: cut off by the interior restriction in both)"},
    };
    char obj[512], text[4096], path[600];
    int t;
    snprintf(obj, sizeof obj, "%s/tests/rig_cube.obj", dir());
    T_CHECK(write_cube_obj(obj, 2.0) == 0, "write %s", obj);
    for (t = 0; t < (int)(sizeof T / sizeof T[0]); t++) {
        sb_model o;
        double Qr[8][3], tot[3], peak = 0, err = 0, terr = 0;
        int a, k, c;
        snprintf(text, sizeof text, "mesh rig_cube.obj\nunit 0.3\ncell 2\norigin 0 0 0\njoint root - 1 1 1\n"
                                    "material m 2e5 0.3 900\npin box -1 -1 -1 0.001 0.001 0.001 root\ncontrol c\n%s\n", T[t].line);
        if (build_text("rig_cube", text, &o, path, sizeof path)) { T_CHECK(0, "%s: build: %s", T[t].line, sb_error()); continue; }
        T_CHECK(o.nc == 1 && o.nf == 7 && o.nrig == 1, "one cell, 7 free vertices, one rig (got %d, %d, %d)", o.nc, o.nf, o.nrig);
        if (o.nc != 1 || o.nrig != 1) { sb_rig_free(&o); sb_model_free(&o); continue; }
        ref_integrate(&T[t].r, 2.0, Qr, tot);
        for (c = 0; c < 8; c++) peak = fmax(peak, nrm(Qr[c]));
        for (c = 0; c < 8; c++) {   /* cell corner c -> lattice vertex; the tool's entry (free) */
            int v = o.cells[c], e = -1;
            for (a = 0; a < o.rig[0].n; a++) if (o.rig[0].vert[a] == v) e = a;
            if (v >= o.nf) continue;   /* the pinned corner: no entry */
            T_CHECK(e >= 0 || nrm(Qr[c]) < 1e-9 * peak, "%s: free corner %d has an entry", T[t].line, c);
            for (k = 0; k < 3; k++) err = fmax(err, fabs((e >= 0 ? o.rig[0].Q[3 * e + k] : 0) - Qr[c][k]));
        }
        for (k = 0; k < 3; k++) terr = fmax(terr, fabs(o.rig[0].total[k] - tot[k]));
        T_CHECK(err <= T[t].tol * peak, "%s: |Q - reference| = %.3g of the peak %.4g N, want <= %.0e (%s)", T[t].line, err / peak, peak, T[t].tol, T[t].why);
        /* partition of unity: sum_i Q_i (all 8 corners, pinned one included) = int f dV */
        T_CHECK(terr <= T[t].tol * peak, "%s: sum_i Q_i vs int f dV: %.3g of the peak (|int f dV| = %.4g N; the shape functions sum to 1, "
                "so only the quadrature error above remains)", T[t].line, terr / peak, nrm(tot));
        {   /* the tool's own sum equals its entries' sum plus the pinned corner's share, to round-off */
            double s[3] = {0, 0, 0}, pin[3], pe = 0;
            for (a = 0; a < o.rig[0].n; a++) for (k = 0; k < 3; k++) s[k] += o.rig[0].Q[3 * a + k];
            for (c = 0; c < 8; c++) if (o.cells[c] >= o.nf) for (k = 0; k < 3; k++) pin[k] = Qr[c][k];
            for (k = 0; k < 3; k++) pe = fmax(pe, fabs(s[k] + pin[k] - o.rig[0].total[k]));
            T_CHECK(pe <= T[t].tol * peak, "%s: free entries + pinned share = total (%.3g of the peak)", T[t].line, pe / peak);
        }
        T_FIGURE("rig template %-7s on one cell: max |Q_i - reference| / peak %.2e (tolerance %.0e), |sum_i Q_i - int f dV| / peak %.2e, refinement %d",
                 sb_rig_tpl_name(o.rig[0].def.tpl), err / peak, T[t].tol, terr / peak, o.rig[0].refine);
        sb_rig_free(&o);
        sb_model_free(&o);
    }
}

/* 2. a bump on a 3x3x3 block peaks at the nearest lattice vertex; -s and tau flip it */
static void test_bump_peak(void)
{
    static const char *base = "mesh rig_block.obj\nunit 0.1\ncell 2\norigin 0 0 0\njoint root - 0.2 0.2 0.2\n"
                              "material m 1e5 0.3 1000\npin box -1 -1 -1 0.5 0.5 0.5 root\ncontrol c\ncontrol d\n";
    char obj[512], text[4096], path[600];
    sb_model o;
    int a, k, best = -1, nearest = -1;
    double bq = 0, bd = 1e30, c[3] = {2.3, 3.8, 2.25};
    snprintf(obj, sizeof obj, "%s/tests/rig_block.obj", dir());
    T_CHECK(write_cube_obj(obj, 6.0) == 0, "write %s", obj);
    snprintf(text, sizeof text, "%srig up c bump 0.2  %g %g %g  2.5  0 1 0  tau -1 -1  1 1\nrig dn d bump -0.2  %g %g %g  2.5  0 1 0\n", base, c[0], c[1], c[2], c[0], c[1], c[2]);
    if (build_text("rig_block", text, &o, path, sizeof path)) { T_CHECK(0, "build block: %s", sb_error()); return; }
    for (a = 0; a < o.rig[0].n; a++) {
        double q = nrm(o.rig[0].Q + 3 * a);
        if (q > bq) { bq = q; best = o.rig[0].vert[a]; }
    }
    for (a = 0; a < o.nv; a++) {
        double d[3];
        for (k = 0; k < 3; k++) d[k] = o.x[3 * a + k] - c[k];
        if (nrm(d) < bd) { bd = nrm(d); nearest = a; }
    }
    T_CHECK(nearest >= 0 && nearest < o.nf, "the vertex nearest the bump centre is free");
    T_CHECK(best == nearest, "largest |Q_i| at vertex %d (%g %g %g), the nearest to the centre is %d", best,
            best >= 0 ? o.x[3 * best] : 0, best >= 0 ? o.x[3 * best + 1] : 0, best >= 0 ? o.x[3 * best + 2] : 0, nearest);
    T_CHECK(best < 0 || o.rig[0].Q[3 * 0 + 1] != 0, "bump has a force");
    {   /* strength -s: every entry exactly negated (same vertices) */
        int same = o.rig[0].n == o.rig[1].n, b;
        for (b = 0; same && b < o.rig[0].n; b++) {
            same &= o.rig[0].vert[b] == o.rig[1].vert[b];
            for (k = 0; k < 3; k++) same &= o.rig[0].Q[3 * b + k] == -o.rig[1].Q[3 * b + k];
        }
        T_CHECK(same, "strength -s gives exactly -Q on the same vertices");
        for (b = 0; b < o.rig[0].n; b++) {   /* along +y for s > 0: every entry's y component >= 0 */
            if (o.rig[0].Q[3 * b + 1] < 0) { T_CHECK(0, "entry %d pushes against the bump direction", b); break; }
        }
    }
    /* tau: exact at and between samples, clamped; negative eta flips the force */
    T_CHECK(sb_rig_tau(&o.rig[0].def, -1) == -1 && sb_rig_tau(&o.rig[0].def, 1) == 1 && sb_rig_tau(&o.rig[0].def, 0) == 0, "tau at the samples");
    T_CHECK(sb_rig_tau(&o.rig[0].def, -5) == -1 && sb_rig_tau(&o.rig[0].def, 7) == 1, "tau clamped at the ends");
    T_CHECK(sb_rig_tau(&o.rig[0].def, 0.25) == 0.25 && sb_rig_tau(&o.rig[0].def, -0.5) == -0.5, "tau linear between samples");
    T_CHECK(o.rig[1].def.ntau == 2 && sb_rig_tau(&o.rig[1].def, 0) == 0 && sb_rig_tau(&o.rig[1].def, 1) == 1 && sb_rig_tau(&o.rig[1].def, -3) == 0,
            "default tau of an abstract control: (0,0) (1,1)");
    for (a = 0; a < o.rig[0].n; a++) {
        int v = o.rig[0].vert[a];
        T_CHECK(v < o.nf && (a == 0 || v > o.rig[0].vert[a - 1]), "entries are free vertices, strictly increasing");
        T_CHECK(nrm(o.rig[0].Q + 3 * a) >= 1e-9 * o.rig[0].qmax, "no entry below 1e-9 of the peak");
    }
    sb_rig_free(&o);
    sb_model_free(&o);
}

/* ---- blob reader (sn_format.h offsets; independent of sb_blob.c) ---- */
static uint32_t u32(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static unsigned u16(const unsigned char *p) { return (unsigned)p[0] | (unsigned)p[1] << 8; }
static double real(const unsigned char *p, int flavour, int frac)
{
    if (flavour == SN_FLAVOUR_FIXED) return ldexp((double)(int32_t)u32(p), -frac);
    if (flavour == SN_FLAVOUR_FLOAT32) { uint32_t u = u32(p); float f; memcpy(&f, &u, 4); return f; }
    {
        uint64_t u = (uint64_t)u32(p) | (uint64_t)u32(p + 4) << 32;
        double d;
        memcpy(&d, &u, 8);
        return d;
    }
}

static void check_blob(const char *desc, int flavour, int print)
{
    static const char *fl[3] = {"fixed", "float32", "float64"};
    sb_model o;
    sb_blob b;
    const unsigned char *B;
    uint32_t off[SN_SEC_COUNT], cnt[SN_SEC_COUNT], es[SN_SEC_COUNT];
    int rs, k, a, i, bad = 0;
    double Um, sc, worst = 0;
    if (sb_bake_file(desc, flavour, 1, &o, &b)) { T_CHECK(0, "bake %s: %s", desc, sb_error()); return; }
    B = b.bytes;
    rs = B[SN_H_REAL_SIZE];
    for (k = 0; k < SN_SEC_COUNT; k++) {
        off[k] = u32(B + SN_H_SECTIONS + 16 * k); cnt[k] = u32(B + SN_H_SECTIONS + 16 * k + 8); es[k] = u32(B + SN_H_SECTIONS + 16 * k + 12);
    }
    T_CHECK(u16(B + SN_H_VER_MAJOR) == SN_FORMAT_MAJOR, "%s %s: format %d", desc, fl[flavour], SN_FORMAT_MAJOR);
    T_CHECK(cnt[SN_SEC_CONTROLS] == (uint32_t)o.nctl && cnt[SN_SEC_RIGS] == (uint32_t)o.nrig, "%s: %u controls, %u rigs", desc, cnt[SN_SEC_CONTROLS], cnt[SN_SEC_RIGS]);
    T_CHECK(es[SN_SEC_CONTROLS] == 40u + 4u * (uint32_t)rs && es[SN_SEC_RIGS] == 16 && es[SN_SEC_RIG_SAMPLES] == 2u * (uint32_t)rs &&
                es[SN_SEC_RIG_VERTS] == 2 && es[SN_SEC_RIG_FORCES] == 3u * (uint32_t)rs, "%s: element sizes", desc);
    T_CHECK(u32(B + SN_H_INSTANCE_BYTES) == SN_INSTANCE_BYTES(u32(B + SN_H_N_VERTICES), u32(B + SN_H_N_FREE), u32(B + SN_H_N_JOINTS),
                                                              u32(B + SN_H_N_CELLS), cnt[SN_SEC_CONTROLS], B[SN_H_MAX_FORCES], seg_state_bytes(B) + crease_state_bytes(B) + cnt[SN_SEC_FPAIRS] * SN_FPAIR_BYTES, cons_state_bytes(B)), "%s: instance bytes count the controls", desc);
    for (k = SN_SEC_CONTROLS; k <= SN_SEC_RIG_FORCES; k++) T_CHECK(off[k] % 8 == 0 && off[k] + cnt[k] * es[k] <= b.size, "%s: section %d placed", desc, k);
    for (a = 0; a < (int)cnt[SN_SEC_CONTROLS]; a++) {
        const unsigned char *c = B + off[SN_SEC_CONTROLS] + (size_t)a * es[SN_SEC_CONTROLS];
        const sb_control *t = &o.ctl[a];
        double ax[3], v0 = real(c + 40 + 3 * rs, flavour, 16);
        for (k = 0; k < 3; k++) ax[k] = real(c + 40 + k * rs, flavour, 30);
        T_CHECK(memchr(c, 0, 32) && !strncmp((const char *)c, t->name, 32) && c[0], "%s: control %d named '%s'", desc, a, t->name);
        T_CHECK(c[32] == (t->kind == SB_CTL_ABSTRACT ? SN_CTL_ABSTRACT : SN_CTL_ANGLE) && u16(c + 34) == 0 && u32(c + 36) == 0, "%s: control %d kind", desc, a);
        if (t->kind == SB_CTL_ABSTRACT) T_CHECK(c[33] == 0 && ax[0] == 0 && ax[1] == 0 && ax[2] == 0 && fabs(v0 - t->value0) <= ldexp(1, -16), "%s: abstract control %d", desc, a);
        else {
            T_CHECK(c[33] < u32(B + SN_H_N_JOINTS) && !strcmp(o.joints[c[33]].name, o.joints[t->joint].name), "%s: control %d joint (sorted order)", desc, a);
            T_CHECK(fabs(nrm(ax) - 1) <= 4 * ldexp(1, -30) + (flavour == 1 ? 1e-7 : 0), "%s: control %d unit axis", desc, a);
            for (k = 0; k < 3; k++) T_CHECK(fabs(ax[k] - t->axis[k]) <= ldexp(1, -30) + (flavour == 1 ? 1e-7 : 0), "%s: control %d axis", desc, a);
        }
    }
    Um = ldexp(1.0, (int8_t)B[SN_H_LEN_SHIFT]) * o.unit;
    sc = o.h * o.h / (b.m0 * Um);   /* h^2 Q / (m0 U): as gravity, m^ g^ = (m/m0) h^2 g / U */
    {
        uint32_t fs = 0, fe = 0;
        for (a = 0; a < (int)cnt[SN_SEC_RIGS]; a++) {
            const unsigned char *r = B + off[SN_SEC_RIGS] + 16 * (size_t)a;
            const sb_rig *t = &o.rig[a];
            unsigned ns = r[2], ne = u32(r + 12);
            int frac = (int8_t)r[3];
            double emax = 0, etamax = 0, qmaxc = 0, fold;
            T_CHECK(u16(r) == (unsigned)t->def.control && u16(r) < cnt[SN_SEC_CONTROLS], "%s: rig %d control", desc, a);
            T_CHECK(ns >= 1 && ns <= SN_RIG_MAX_SAMPLES && ns == (unsigned)t->def.ntau, "%s: rig %d samples %u", desc, a, ns);
            T_CHECK(u32(r + 4) == fs && u32(r + 8) == fe && ne == (unsigned)t->n, "%s: rig %d running sums", desc, a);
            if (flavour == SN_FLAVOUR_FIXED) T_CHECK(frac >= SN_RIG_FRAC_MIN && frac <= SN_RIG_FRAC_MAX, "%s: rig %d frac %d in range", desc, a, frac);
            else T_CHECK(frac == 0, "%s: rig %d frac 0 when not fixed", desc, a);
            for (k = 0; k < t->def.ntau; k++) emax = fmax(emax, fabs(t->def.tau_e[k]));
            for (k = 0; k < (int)ns && fs + (uint32_t)k < cnt[SN_SEC_RIG_SAMPLES]; k++) {
                const unsigned char *s = B + off[SN_SEC_RIG_SAMPLES] + (size_t)(fs + (uint32_t)k) * es[SN_SEC_RIG_SAMPLES];
                double g = real(s, flavour, 16), e = real(s + rs, flavour, 30);
                if (k > 0) T_CHECK(g > real(s - es[SN_SEC_RIG_SAMPLES], flavour, 16), "%s: rig %d gammas strictly increasing", desc, a);
                T_CHECK(fabs(g - t->def.tau_g[k]) <= (flavour == 0 ? ldexp(1, -17) : flavour == 1 ? 1e-7 * fabs(g) : 0), "%s: rig %d gamma %d", desc, a, k);
                T_CHECK(fabs(e - t->def.tau_e[k] / emax) <= (flavour == 0 ? ldexp(1, -31) : flavour == 1 ? 1e-7 : 0), "%s: rig %d eta %d", desc, a, k);
                etamax = fmax(etamax, fabs(e));
            }
            T_CHECK(etamax == 1.0, "%s: rig %d eta normalized (max |eta| = %.17g)", desc, a, etamax);
            fold = sc * emax;
            for (i = 0; i < (int)ne && fe + (uint32_t)i < cnt[SN_SEC_RIG_VERTS]; i++) {
                const unsigned char *f = B + off[SN_SEC_RIG_FORCES] + (size_t)(fe + (uint32_t)i) * es[SN_SEC_RIG_FORCES];
                unsigned v = u16(B + off[SN_SEC_RIG_VERTS] + 2 * (size_t)(fe + (uint32_t)i));
                if (v >= u32(B + SN_H_N_FREE) || (i > 0 && v <= u16(B + off[SN_SEC_RIG_VERTS] + 2 * (size_t)(fe + (uint32_t)i - 1))) || v != (unsigned)t->vert[i]) bad++;
                for (k = 0; k < 3; k++) {
                    double got = real(f + k * rs, flavour, frac), want = fold * t->Q[3 * i + k];
                    double step = flavour == 0 ? ldexp(1, -frac) : flavour == 1 ? ldexp(fabs(want), -23) : 0;
                    qmaxc = fmax(qmaxc, fabs(got));
                    if (fabs(got - want) > step) bad++;
                    if (step > 0) worst = fmax(worst, fabs(got - want) / step);
                }
            }
            if (flavour == SN_FLAVOUR_FIXED) T_CHECK(ldexp(qmaxc, frac) >= ldexp(1, 29) && ldexp(qmaxc, frac) < ldexp(1, 30), "%s: rig %d largest |Q| x 2^frac in [2^29, 2^30)", desc, a);
            if (flavour == SN_FLAVOUR_FLOAT32) T_CHECK(qmaxc <= SN_RIG_FLOAT_MAX, "%s: rig %d |Q| <= SN_RIG_FLOAT_MAX", desc, a);
            fs += ns; fe += ne;
        }
        T_CHECK(fs == cnt[SN_SEC_RIG_SAMPLES] && fe == cnt[SN_SEC_RIG_VERTS] && fe == cnt[SN_SEC_RIG_FORCES], "%s: section counts are the sums", desc);
    }
    T_CHECK(bad == 0, "%s %s: %d rig entries wrong (vertex order/range, or dequantized Q more than one quantization step from the tool's h^2 Q/(m0 U))", desc, fl[flavour], bad);
    if (print)
        T_FIGURE("%s %s: rig sections CONTROLS %u, RIGS %u, RIG_SAMPLES %u, RIG_VERTS %u, RIG_FORCES %u bytes; worst |stored - exact| %.2f quantization steps",
                 desc, fl[flavour], cnt[SN_SEC_CONTROLS] * es[SN_SEC_CONTROLS], cnt[SN_SEC_RIGS] * es[SN_SEC_RIGS], cnt[SN_SEC_RIG_SAMPLES] * es[SN_SEC_RIG_SAMPLES],
                 cnt[SN_SEC_RIG_VERTS] * es[SN_SEC_RIG_VERTS], cnt[SN_SEC_RIG_FORCES] * es[SN_SEC_RIG_FORCES], worst);
    sb_blob_free(&b);
    sb_rig_free(&o);
    sb_model_free(&o);
}

/* the cow's rigs: tau(0) = 0 (so default controls give no force), the right controls */
static void test_examples(void)
{
    sb_model o;
    sb_blob b;
    int a;
    if (sb_bake_file("tools/examples/cow/cow.sinew", SB_FIXED, 1, &o, &b)) { T_CHECK(0, "bake cow: %s", sb_error()); return; }
    T_CHECK(o.nctl == 4 && o.nrig == 6, "cow: 4 controls (breath, smile, nostrils, belly), 6 rigs: got %d, %d", o.nctl, o.nrig);
    for (a = 0; a < o.nrig; a++) {
        const sb_rigdef *r = &o.rig[a].def;
        T_CHECK(sb_rig_tau(r, o.ctl[r->control].value0) == 0, "cow rig '%s': tau(default) = 0: the cow's other tests see no rig force", r->name);
    }
    sb_blob_free(&b); sb_rig_free(&o); sb_model_free(&o);
    if (sb_bake_file("tools/examples/limb/limb.sinew", SB_FIXED, 1, &o, &b)) { T_CHECK(0, "bake limb: %s", sb_error()); return; }
    T_CHECK(o.nctl == 1 && o.ctl[0].kind == SB_CTL_ANGLE && !strcmp(o.joints[o.ctl[0].joint].name, "elbow") && o.ctl[0].axis[2] == 1,
            "limb: control elbow_bend = angle of 'elbow' about +z");
    T_CHECK(o.nrig == 1 && o.rig[0].def.tpl == SB_TPL_MUSCLE && sb_rig_tau(&o.rig[0].def, 0) == 0 && sb_rig_tau(&o.rig[0].def, 90) == 1,
            "limb: one muscle rig, tau(0 deg) = 0, tau(90 deg) = 1");
    sb_blob_free(&b); sb_rig_free(&o); sb_model_free(&o);
}

/* 5. description errors: file:line, non-zero exit, no output file */
static void test_errors(void)
{
    static const char *base = "mesh rig_block.obj\nunit 0.1\ncell 2\norigin 0 0 0\njoint root - 0.2 0.2 0.2\njoint tip root 4 0.2 0.2\n"
                              "material m 1e5 0.3 1000\npin box -1 -1 -1 0.5 0.5 0.5 root\ncontrol c\n";   /* 9 lines */
    static const struct { const char *lines; const char *msg; } E[] = {
        {"rig r nope bump 0.1  3 3 3 1", "unknown control 'nope'"},
        {"control e angle nobody 0 0 1", "unknown joint 'nobody'"},
        {"rig r c blob 0.1  3 3 3 1", "unknown rig template 'blob'"},
        {"rig r c bump 0.1  3 3 3 1\ntau r 0 0  1 1  1 2", "strictly increasing"},
        {"rig r c bump 0.1  3 3 3 1  tau 1 0 0 1", "strictly increasing"},
        {"rig r c bump 0.1  3 3 3 1  tau 0 0 1 1 2 1 3 1 4 1 5 1 6 1 7 1 8 1 9 1 10 1 11 1 12 1 13 1 14 1 15 1 16 1", "at most 16"},
        {"control c", "declared twice"},
        {"rig r c bump 0.1  3 3 3 1\nrig r c bump 0.1  3 3 3 1", "declared twice"},
        {"control e angle root 0 0 0", "zero vector"},
        {"rig r c bump 0.1  3 3 3 1  0 0 0", "zero vector"},
        {"rig r c ring 0.1  3 3 3  0 0 0  1 0.5", "zero vector"},
        {"rig r c bump 0.1  30 30 30 1", "touches no free lattice vertex.*no flesh"},
        {"pin box -1 -1 -1 2.5 2.5 2.5 root\nrig r c bump 0.1  1 1 1 0.5", "touches no free lattice vertex.*carried rigidly by bones"},
        {"rig r c bump 0.1  3 3 3", "missing value"},
        {"rig r c bump 0.1  3 3 3 -1", "radius must be positive"},
        {"rig r c muscle 0.1  1 1 1  1 1 1  1", "zero-length"},
        {"rig r c uniform 0.1  0 1 0  sphere 3 3 3", "missing value"},
        {"control e angle root 0 0 1\nrig r e bump 0.1  3 3 3 1", "needs tau samples"},
        {"control e twist tip", "twist needs joint 'tip' to have exactly one child"},
        {"tau zz 0 0 1 1", "unknown rig 'zz'"},
        {"rig r c bump 0.1  3 3 3 1  tau 0 0 1 0", "every tau eta is 0"},
        {"rig r c bump 0.1  3 3 3 1  tau 0 0 1", "pairs"},
    };
    char path[600], text[4096], cmd[2400], out[700], bake[600];
    int t, have;
    snprintf(bake, sizeof bake, "%s/sinew-bake", dir());
    have = access(bake, X_OK) == 0;
    T_CHECK(have, "%s is built (the no-output checks run it)", bake);
    for (t = 0; t < (int)(sizeof E / sizeof E[0]); t++) {
        sb_model o;
        sb_blob b;
        FILE *f;
        char want[700];
        int line = 10, k;
        for (k = 0; E[t].lines[k]; k++) line += E[t].lines[k] == '\n';   /* the error is on the last line given */
        if (strstr(E[t].msg, "declared twice") && !strchr(E[t].lines, '\n')) line = 10;
        if (strstr(E[t].msg, "twist needs")) line = 10;
        snprintf(path, sizeof path, "%s/tests/rig_err.sinew", dir());
        snprintf(text, sizeof text, "%s%s\n", base, E[t].lines);
        f = fopen(path, "w");
        if (!f) { T_CHECK(0, "write %s", path); continue; }
        fputs(text, f);
        fclose(f);
        snprintf(want, sizeof want, "%s:%d:", path, line);
        if (sb_bake_file(path, SB_FIXED, 1, &o, &b) == 0) { T_CHECK(0, "'%s' bakes (want an error)", E[t].lines); sb_blob_free(&b); sb_rig_free(&o); sb_model_free(&o); continue; }
        {
            const char *m = sb_error();
            int match = 0;
            /* message regex-lite: "a.*b" = a then b */
            const char *dot = strstr(E[t].msg, ".*");
            if (dot) {
                char first[200];
                const char *p1;
                snprintf(first, sizeof first, "%.*s", (int)(dot - E[t].msg), E[t].msg);
                p1 = strstr(m, first);
                match = p1 && strstr(p1, dot + 2);
            } else match = strstr(m, E[t].msg) != NULL;
            T_CHECK(strstr(m, want) && match, "'%s': error '%s' names %s and says '%s'", E[t].lines, m, want, E[t].msg);
        }
        if (have) {
            int rc;
            snprintf(out, sizeof out, "%s/tests/rig_err.blob", dir());
            remove(out);
            snprintf(cmd, sizeof cmd, "%s %s -o %s --quiet 2>/dev/null", bake, path, out);
            rc = system(cmd);
            T_CHECK(rc != 0 && access(out, F_OK) != 0, "'%s': sinew-bake exits non-zero and writes no output", E[t].lines);
        }
    }
}

int main(void)
{
    char obj[512];
    (void)t_seed;   /* harness helper unused here (no random tests) */
    test_templates();
    test_bump_peak();
    snprintf(obj, sizeof obj, "%s/tests/rig_block.obj", dir());
    T_CHECK(access(obj, F_OK) == 0, "block mesh written");
    check_blob("tools/examples/cow/cow.sinew", SB_FIXED, 1);
    check_blob("tools/examples/cow/cow.sinew", SB_FLOAT, 0);
    check_blob("tools/examples/cow/cow.sinew", SB_DOUBLE, 0);
    check_blob("tools/examples/limb/limb.sinew", SB_FIXED, 1);
    check_blob("tools/examples/limb/limb.sinew", SB_FLOAT, 0);
    test_examples();
    test_errors();
    return T_END();
}
