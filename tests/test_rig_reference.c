/* test_rig_reference.c -- rig controls and forces in the double-precision
 * reference (tools/ref/snref.c, blob format 3.0; issue 10), no runtime.
 *
 * Blobs: a synthetic two-joint box (tests/reference/snref_synth.c, float64)
 * and the tool's limb (fixed and float64) with two controls and two rigs
 * written by the tests' own writer (snsyn_with_rigs, tests/rig_common.h).
 *
 *  1. reading: the rig sections round-trip (float64 exactly; fixed within half
 *     an LSB of each field's format);
 *  2. tau (seed 003 after eq. 12): exact at the samples, linear between,
 *     clamped at the ends;
 *  3. the pose control formula: swing-twist compositions give back the twist,
 *     through a posed skeleton (conj(q_parent) q_J, either quaternion sign);
 *  4. bijection (seed 003 eq. 10): rig force Q -> static q -> the recovered
 *     A q - b equals Q; the static displacement is linear in Q;
 *  5. rig forces turn with the frames: a rigidly moved skeleton gives the
 *     rigidly moved rig shape;
 *  6. the step's right-hand side carries the rig force: damped exact steps
 *     settle on the static solve with the rigs on.
 */
#include "sn_test.h"
#include "snref.h"
#include "reference/snref_synth.h"
#include "../runtime/src/sn_format.h"
#include "rig_common.h"

#include <stdio.h>
#include <string.h>

#define PI 3.14159265358979323846

static snsyn_box box(void) {
    snsyn_box b;
    memset(&b, 0, sizeof b);
    b.nx = 6; b.ny = 2; b.nz = 2; b.dx = b.dy = b.dz = 0.05;
    b.E = 3e4; b.nu = 0.3; b.rho = 1000; b.h = 1.0 / 60; b.g[1] = -9.81;
    b.flavour = 2; b.cg_default = 16; b.two_joints = 1; b.integration = SNSYN_INCOMPATIBLE;
    return b;
}

static rc_spec box_spec(void) {
    rc_spec sp;
    memset(&sp, 0, sizeof sp);
    sp.bend_joint = 1; sp.bend_axis[2] = 1;
    sp.c0[0] = 0.1; sp.c1[0] = 0.2; sp.rad = 0.06; sp.amp = 3; sp.dir[1] = 1;
    return sp;
}

/* blob -> blob with the rigs of rig_common.h, loaded into m */
static unsigned char *with_rigs(const unsigned char *b0, size_t n0, const rc_spec *sp, snref_model *m, size_t *n) {
    snref_model m0;
    char err[200];
    unsigned char *b;
    if (snref_load(&m0, b0, n0, err, sizeof err)) { T_CHECK(0, "load: %s", err); return NULL; }
    b = rc_add_rigs(b0, n0, &m0, sp, n);
    snref_free(&m0);
    T_CHECK(b != NULL, "snsyn_with_rigs");
    if (!b) return NULL;
    if (snref_load(m, b, *n, err, sizeof err)) { T_CHECK(0, "load with rigs: %s", err); free(b); return NULL; }
    return b;
}

static unsigned char *box_blob(const snsyn_box *bx, snref_model *m, size_t *n) {
    size_t n0;
    unsigned char *b0 = snsyn_build(bx, &n0), *b;
    rc_spec sp = box_spec();
    b = with_rigs(b0, n0, &sp, m, n);
    free(b0);
    return b;
}

static void *read_file(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    long len;
    double *buf;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END); len = ftell(f); fseek(f, 0, SEEK_SET);
    buf = malloc((size_t)len + 8);
    if (!buf || len <= 0 || fread(buf, 1, (size_t)len, f) != (size_t)len) { fclose(f); free(buf); return NULL; }
    fclose(f);
    *n = (size_t)len;
    return buf;
}

static double norm(const double *x, unsigned n) {
    double s = 0;
    unsigned i;
    for (i = 0; i < n; i++) s += x[i] * x[i];
    return sqrt(s);
}

static void identity_pose(snref_xform *p, unsigned n) {
    unsigned j;
    memset(p, 0, n * sizeof *p);
    for (j = 0; j < n; j++) p[j].q[3] = 1;
}

/* box pose: root at G (quaternion g, translation tr), tip bent by deg about z
 * at its rest position (model space, mesh units) */
static void box_pose(const snref_model *m, const double g[4], const double tr[3], double deg, snref_xform *p) {
    double ax[3] = { 0, 0, 1 }, ql[4], R[9], x[3], rx[3], Rg[9], d[3];
    unsigned k;
    identity_pose(p, m->nJ);
    memcpy(p[0].q, g, 4 * sizeof *g);
    memcpy(p[0].t, tr, 3 * sizeof *tr);
    snref_quat_axis_angle(ax, deg, ql);
    snref_quat_mul(g, ql, p[1].q);
    snref_quat_to_mat(ql, R);
    snref_quat_to_mat(g, Rg);
    for (k = 0; k < 3; k++) x[k] = m->jrest[3 + k] * m->unit;
    for (k = 0; k < 3; k++) rx[k] = x[k] - (R[3 * k] * x[0] + R[3 * k + 1] * x[1] + R[3 * k + 2] * x[2]);
    for (k = 0; k < 3; k++) d[k] = Rg[3 * k] * rx[0] + Rg[3 * k + 1] * rx[1] + Rg[3 * k + 2] * rx[2];
    for (k = 0; k < 3; k++) p[1].t[k] = d[k] + tr[k];
}

static void test_read(void) {
    snsyn_box bx = box();
    snref_model m;
    size_t n, n0, nf;
    unsigned char *b = box_blob(&bx, &m, &n), *b0, *bf;
    char path[600], p64[600], err[200];
    const char *build = getenv("BUILD");
    unsigned i, a;
    if (!b) return;
    T_CHECK(m.nK == 2 && m.nR == 2 && m.nRS == 8 && m.nRE > 10, "box: %u controls, %u rigs, %u samples, %u entries", m.nK, m.nR, m.nRS, m.nRE);
    T_CHECK(snref_find_control(&m, "breath") == 0 && snref_find_control(&m, "bend") == 1 && snref_find_control(&m, "nose") == -1, "find_control");
    T_CHECK(m.kkind[0] == SN_CTL_ABSTRACT && m.kkind[1] == SN_CTL_ANGLE && m.kjoint[1] == 1 && m.kaxis[5] == 1, "control kinds, joint, axis");
    T_CHECK(m.rgamma[2] == 90 && m.reta[1] == 0.4 && m.rgamma[4] == -1 && m.reta[6] == 0.25, "float64 samples read back exactly");
    free(b); snref_free(&m);

    /* the tool's fixed limb: every field within half an LSB of its float64 twin */
    snprintf(path, sizeof path, "%s/examples/limb.blob", build && *build ? build : "build");
    snprintf(p64, sizeof p64, "%s/examples/limb_double.blob", build && *build ? build : "build");
    b0 = read_file(path, &n0);
    bf = read_file(p64, &nf);
    if (!b0 || !bf) { T_CHECK(0, "missing %s / %s (make the examples)", path, p64); free(b0); free(bf); return; }
    {
        snref_model m64, mx;
        rc_spec sp;
        unsigned char *r64, *rx;
        size_t s64, sx;
        double worst_q = 0, worst_g = 0, worst_e = 0;
        memset(&sp, 0, sizeof sp);
        if (snref_load(&m64, bf, nf, err, sizeof err)) { T_CHECK(0, "%s", err); return; }
        sp.bend_joint = (unsigned)(m64.nJ > 1 ? 1 : 0); sp.bend_axis[2] = 1;
        sp.c0[0] = 2; sp.c1[0] = 3.5; sp.rad = 1.6; sp.amp = 2; sp.dir[1] = 1;
        /* the same forces into both (from the float64 model's masses and gravity) */
        r64 = rc_add_rigs(bf, nf, &m64, &sp, &s64);
        rx = rc_add_rigs(b0, n0, &m64, &sp, &sx);
        snref_free(&m64);
        if (!r64 || !rx || snref_load(&m64, r64, s64, err, sizeof err) || snref_load(&mx, rx, sx, err, sizeof err)) {
            T_CHECK(0, "limb with rigs: %s", err);
            return;
        }
        T_CHECK(m64.nRE == mx.nRE && m64.nRE > 0, "limb rig entries %u (float64) %u (fixed)", m64.nRE, mx.nRE);
        for (a = 0; a < mx.nR; a++)
            for (i = mx.rfe[a]; i < mx.rfe[a] + mx.rne[a] && i < m64.nRE; i++) {
                unsigned c;
                for (c = 0; c < 3; c++) {
                    double e = fabs(mx.rforce[3 * i + c] - m64.rforce[3 * i + c]) / ldexp(1.0, -mx.rfrac[a]);
                    if (e > worst_q) worst_q = e;
                }
            }
        for (i = 0; i < mx.nRS; i++) {
            if (fabs(mx.rgamma[i] - m64.rgamma[i]) * 65536 > worst_g) worst_g = fabs(mx.rgamma[i] - m64.rgamma[i]) * 65536;
            if (fabs(mx.reta[i] - m64.reta[i]) * 1073741824.0 > worst_e) worst_e = fabs(mx.reta[i] - m64.reta[i]) * 1073741824.0;
        }
        /* round to nearest: at most half an LSB of each format */
        T_CHECK(worst_q <= 0.5 && worst_g <= 0.5 && worst_e <= 0.5, "fixed rig fields off their float64 values by %g (forces), %g (gamma), %g (eta) LSB; want <= 0.5",
                worst_q, worst_g, worst_e);
        T_CHECK(mx.rfrac[0] >= SN_RIG_FRAC_MIN && mx.rfrac[0] <= SN_RIG_FRAC_MAX, "fixed rig frac %d", mx.rfrac[0]);
        T_FIGURE("fixed limb rigs: largest quantization %.3f LSB (forces Q%d/Q%d), gamma %.3f LSB Q16.16, eta %.3f LSB Q30",
                 worst_q, mx.rfrac[0], mx.rfrac[1], worst_g, worst_e);
        free(r64); free(rx); snref_free(&m64); snref_free(&mx);
    }
    free(b0); free(bf);
}

static void test_tau(void) {
    snsyn_box bx = box();
    snref_model m;
    size_t n;
    unsigned char *b = box_blob(&bx, &m, &n);
    unsigned a, k, bad = 0;
    double worst = 0;
    if (!b) return;
    for (a = 0; a < m.nR; a++) {
        const double *G = m.rgamma + m.rfs[a], *E = m.reta + m.rfs[a];
        unsigned ns = m.rns[a];
        for (k = 0; k < ns; k++) bad += snref_tau(&m, a, G[k]) != E[k];           /* exact at the samples */
        bad += snref_tau(&m, a, G[0] - 1000) != E[0] || snref_tau(&m, a, G[0] - 1e-9) != E[0];
        bad += snref_tau(&m, a, G[ns - 1] + 1000) != E[ns - 1] || snref_tau(&m, a, G[ns - 1] + 1e-9) != E[ns - 1];
        for (k = 0; k + 1 < ns; k++) {
            unsigned j;
            for (j = 1; j < 10; j++) {
                double u = j / 10.0, g = G[k] + u * (G[k + 1] - G[k]), want = E[k] + u * (E[k + 1] - E[k]);
                double e = fabs(snref_tau(&m, a, g) - want);
                if (e > worst) worst = e;
            }
        }
    }
    T_CHECK(bad == 0, "tau: %u values not exact at a sample or at the clamped ends", bad);
    /* between samples: one division and one multiply-add of O(1) values: a few ulps of 1 */
    T_NEAR(worst, 0, 1e-15, "tau linear between samples: double round-off of (g - g_k)/(g_k+1 - g_k)");
    free(b); snref_free(&m);
}

static void test_pose_control(void) {
    snsyn_box bx = box();
    snref_model m;
    snref_state s;
    size_t n;
    unsigned char *b = box_blob(&bx, &m, &n);
    unsigned long long st = 0x9E3779B97F4A7C15ULL ^ (unsigned long long)T_SEED();
    unsigned trial, k;
    double worst = 0, worst_pose = 0;
    if (!b) return;
    snref_init(&s, &m);
    for (trial = 0; trial < 2000; trial++) {
        double A[3], u[3], t, q[4], qs[4], qt[4], sw, tw, rnd[6], nA = 0, d = 0, nu = 0;
        for (k = 0; k < 6; k++) { st = st * 6364136223846793005ULL + 1442695040888963407ULL; rnd[k] = (double)(st >> 11) / 9007199254740992.0; }
        for (k = 0; k < 3; k++) { A[k] = 2 * rnd[k] - 1; nA += A[k] * A[k]; }
        nA = sqrt(nA) + 1e-3;
        for (k = 0; k < 3; k++) A[k] /= nA;
        nA = sqrt(A[0] * A[0] + A[1] * A[1] + A[2] * A[2]);
        for (k = 0; k < 3; k++) A[k] /= nA;
        /* swing axis: a random direction made perpendicular to A */
        u[0] = A[1] + 0.3; u[1] = A[2] - 0.7 * rnd[3]; u[2] = A[0] + rnd[4];
        for (k = 0; k < 3; k++) d += u[k] * A[k];
        for (k = 0; k < 3; k++) { u[k] -= d * A[k]; nu += u[k] * u[k]; }
        nu = sqrt(nu);
        for (k = 0; k < 3; k++) u[k] /= nu;
        tw = -179 + 358 * rnd[5];
        sw = -170 + 340 * rnd[3];
        snref_quat_axis_angle(A, tw, qt);
        snref_quat_axis_angle(u, sw, qs);
        snref_quat_mul(qs, qt, q);
        if (trial & 1) for (k = 0; k < 4; k++) q[k] = -q[k];
        t = snref_twist_angle(q, A);
        if (fabs(t - tw) > worst) worst = fabs(t - tw);
        if (trial < 200) {   /* through a posed skeleton: parent at a random rotation, tip = parent * q */
            snref_xform p[2];
            double g[4], ax[3] = { rnd[0] - 0.5, rnd[1] - 0.5, rnd[2] + 0.1 };
            snref_quat_axis_angle(ax, 300 * rnd[4] - 150, g);
            identity_pose(p, 2);
            memcpy(p[0].q, g, sizeof g);
            snref_quat_mul(g, q, p[1].q);
            if (trial & 2) for (k = 0; k < 4; k++) p[1].q[k] = -p[1].q[k];
            /* the box's control axis is z: measure the twist about z */
            snref_reset(&s);
            snref_set_pose(&s, p);
            {
                double z[3] = { 0, 0, 1 }, e = fabs(snref_get_control(&s, 1) - snref_twist_angle(q, z));
                if (e > worst_pose) worst_pose = e;
            }
        }
    }
    /* atan2 of operands with ~1e-16 relative error: ~1e-14 degrees; 1e-9 leaves room for sums of squares */
    T_NEAR(worst, 0, 1e-9, "swing-twist: 2 atan2(v.A, w) recovers the twist angle (double round-off)");
    T_NEAR(worst_pose, 0, 1e-9, "pose control = twist of conj(q_parent) q_J about the axis, either sign of q_J (round-off of one quaternion product)");
    T_FIGURE("pose control formula over 2000 random swing-twist rotations: largest error %.2e deg; through the posed skeleton %.2e deg", worst, worst_pose);
    snref_release(&s);
    free(b); snref_free(&m);
}

/* static shape (lattice, internal units) at pose p with the rigs scaled by sc */
static double static_at(snref_state *s, const snref_xform *p, double sc, double *lat) {
    double res;
    s->rig_scale = sc;
    snref_reset(s);
    snref_set_pose(s, p);
    snref_set_control(s, 0, 0.8);
    res = snref_static(s, 0);
    memcpy(lat, s->p, 3 * s->m->nV * sizeof *lat);
    return res;
}

static void test_bijection(void) {
    snsyn_box bx = box();
    snref_model m;
    snref_state s;
    size_t n;
    unsigned char *b = box_blob(&bx, &m, &n);
    snref_xform p[2];
    double g[4] = { 0, 0, 0, 1 }, tr[3] = { 0, 0, 0 };
    double *p0, *p1, *p2, *r0, *fr, e, dmax = 0, lin = 0, res[3];
    unsigned i, nF3;
    if (!b) return;
    snref_init(&s, &m);
    nF3 = 3 * m.nF;
    p0 = malloc(3 * m.nV * sizeof *p0); p1 = malloc(3 * m.nV * sizeof *p1); p2 = malloc(3 * m.nV * sizeof *p2);
    r0 = calloc(nF3, sizeof *r0); fr = calloc(nF3, sizeof *fr);
    box_pose(&m, g, tr, 60, p);   /* bent tip: frames off the identity, "bend" = 60 -> eta 0.6 */
    res[0] = static_at(&s, p, 0, p0);
    res[1] = static_at(&s, p, 2, p2);
    res[2] = static_at(&s, p, 1, p1);
    T_NEAR(snref_get_control(&s, 1), 60, 1e-9, "bend control of the posed box");
    T_NEAR(snref_tau(&m, 0, 60), 0.6, 1e-15, "tau of the bulge at 60 degrees");
    T_CHECK(res[0] < 1e-12 && res[1] < 1e-12 && res[2] < 1e-12, "static solves converged: %.1e %.1e %.1e", res[0], res[1], res[2]);
    /* recovered: at the rigs-on solution, A q - b (the rigs-off residual, negated) = the rig force */
    s.rig_scale = 0;
    snref_residual(&s, r0);
    s.rig_scale = 1;
    snref_rig_add(&s, fr);
    for (i = 0; i < nF3; i++) r0[i] += fr[i];
    e = norm(r0, nF3) / norm(fr, nF3);
    /* the residual after refinement is at the round-off of the force sum (each term
     * ~ |S| |d|, |d| ~ the displacement): ~1e-15 of the force; 1e-9 is a wide margin */
    T_NEAR(e, 0, 1e-9, "bijection: A q - b recovers the rig force Q (relative, double round-off)");
    for (i = 0; i < 3 * m.nV; i++) {
        double d1 = fabs(p1[i] - p0[i]);
        if (d1 > dmax) dmax = d1;
        if (fabs((p2[i] - p0[i]) - 2 * (p1[i] - p0[i])) > lin) lin = fabs((p2[i] - p0[i]) - 2 * (p1[i] - p0[i]));
    }
    T_CHECK(dmax * m.unit > 1e-3 * m.cell * m.unit, "the rigs move the box: %g mesh units", dmax * m.unit);
    /* three solves each at round-off (1e-15 relative): differences of O(|p|) values */
    T_NEAR(lin / dmax, 0, 1e-9, "static displacement linear in the rig force: q(2Q) - q0 = 2 (q(Q) - q0)");
    T_FIGURE("bijection on the bent box: |A q - b - Q| / |Q| = %.2e; linearity %.2e of the rig displacement (%.4g mesh units)",
             e, lin / dmax, dmax * m.unit);
    free(p0); free(p1); free(p2); free(r0); free(fr);
    snref_release(&s);
    free(b); snref_free(&m);
}

static void test_turns(void) {
    snsyn_box bx = box();
    snref_model m;
    snref_state s;
    size_t n;
    unsigned char *b;
    snref_xform p[2];
    double g0[4] = { 0, 0, 0, 1 }, t0[3] = { 0, 0, 0 }, ax[3] = { 0.3, 1, -0.4 }, g[4], tr[3] = { 0.7, -0.2, 1.5 }, R[9];
    double *a, *c, worst = 0, size, moved = 0;
    unsigned i, k;
    bx.g[1] = 0;   /* rigid invariance needs no gravity (it does not turn with the body) */
    b = box_blob(&bx, &m, &n);
    if (!b) return;
    snref_init(&s, &m);
    a = malloc(3 * m.nV * sizeof *a); c = malloc(3 * m.nV * sizeof *c);
    box_pose(&m, g0, t0, 70, p);
    static_at(&s, p, 1, a);
    snref_quat_axis_angle(ax, 130, g);
    snref_quat_to_mat(g, R);
    box_pose(&m, g, tr, 70, p);
    static_at(&s, p, 1, c);
    size = bx.nx * bx.dx / m.unit;
    for (i = 0; i < m.nV; i++) {
        double y[3], d = 0;
        for (k = 0; k < 3; k++) y[k] = R[3 * k] * a[3 * i] + R[3 * k + 1] * a[3 * i + 1] + R[3 * k + 2] * a[3 * i + 2] + tr[k] / m.unit;
        for (k = 0; k < 3; k++) d += (c[3 * i + k] - y[k]) * (c[3 * i + k] - y[k]);
        if (sqrt(d) > worst) worst = sqrt(d);
    }
    {   /* how much the rig moves the box at all */
        static_at(&s, p, 0, a);
        for (i = 0; i < 3 * m.nV; i++) if (fabs(a[i] - c[i]) > moved) moved = fabs(a[i] - c[i]);
    }
    T_NEAR(worst / size, 0, 1e-4, "rig shape turns with the skeleton: test_physics_rigid's rigid-invariance tolerance, 1e-4 of the size");
    T_CHECK(worst <= 1e-9 * moved, "double: rigidly moved rig shape within round-off (%.2e of the rig displacement)", worst / moved);
    T_FIGURE("box rotated 130 deg and moved, tip bent 70 deg, rigs on: static shape off the rigidly moved one by %.2e of the size (%.2e of the rig displacement)",
             worst / size, worst / moved);
    free(a); free(c);
    snref_release(&s);
    free(b); snref_free(&m);
}

static void test_step(void) {
    snsyn_box bx = box();
    snref_model m;
    snref_state s;
    size_t n;
    unsigned char *b;
    snref_xform p[2];
    double g[4] = { 0, 0, 0, 1 }, tr[3] = { 0, 0, 0 }, *st, *p0, e = 0, d = 0;
    unsigned i, k;
    bx.alpha = 20;   /* mass damping about critical for the first mode: settles in a few hundred steps */
    b = box_blob(&bx, &m, &n);
    if (!b) return;
    snref_init(&s, &m);
    st = malloc(3 * m.nV * sizeof *st); p0 = malloc(3 * m.nV * sizeof *p0);
    box_pose(&m, g, tr, 50, p);
    static_at(&s, p, 0, p0);
    static_at(&s, p, 1, st);
    snref_reset(&s);
    s.exact = 1;
    snref_set_pose(&s, p);
    snref_set_control(&s, 0, 0.8);
    for (k = 0; k < 3000; k++) snref_step(&s);
    for (i = 0; i < 3 * m.nF; i++) {
        if (fabs(s.p[i] - st[i]) > e) e = fabs(s.p[i] - st[i]);
        if (fabs(st[i] - p0[i]) > d) d = fabs(st[i] - p0[i]);
    }
    /* 3000 steps of a damped linear system converge geometrically to its fixed point, the static solve */
    T_NEAR(e / d, 0, 1e-6, "exact damped steps with the rigs on settle on the static solve with the rigs on (relative to the rig displacement)");
    T_FIGURE("box, tip bent 50 deg, breath 0.8: stepped 3000 exact steps vs static %.2e of the rig displacement (%.4g mesh units)", e / d, d * m.unit);
    free(st); free(p0);
    snref_release(&s);
    free(b); snref_free(&m);
}

int main(void) {
    printf("rig reference (format 3.0 rig sections, double precision)\n");
    test_read();
    test_tau();
    test_pose_control();
    test_bijection();
    test_turns();
    test_step();
    return T_END();
}
