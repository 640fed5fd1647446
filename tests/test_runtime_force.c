/* test_runtime_force.c -- external forces and impulses (issue 14, seed 004
 * ch. 4 on the lattice): the runtime against double-precision references
 * written here from NUMERICS.md "External forces", on the baked limb and
 * cow (their descriptions carry share profiles). Built fixed and float.
 *
 *  1. distribution: the forces step 5 adds (white box: sn_forces_rhs on a
 *     zero b) against a double implementation of the same distribution,
 *     per vertex; total force and moment about the origin against the
 *     applied ones, for every profile and several points;
 *  2. wrench: the rigid level's share (and the parts on skeleton corners)
 *     sum to the applied force exactly, and each joint's torque is the
 *     exact (point - joint) x force, rounded once (fixed);
 *  3. response: a force held until the limb settles moves the flesh as the
 *     double static solve under the double distribution's load (fine and
 *     coarse profiles; seed 003 eq. 10 with an external load);
 *  4. the thesis' ordering (seed 004 fig. 4.9-4.11): an impulse on the
 *     limb moves a point 3 cells away relative to the hit point more as the
 *     coarse share grows, and the widest region moves the hit point least;
 *  5. impulses = force / h for one step; world-point forces find the flesh
 *     under the point; full slots, bad arguments: refused, counted, no change.
 */
#include "sn_test.h"
#define PU_WHITE_BOX /* pu_h, pu_qd, ...: the instance's internals */
#include "reference/phys_util.h"
#include "reference/phys_pose.h"
#include "sn_instance.h"

#if defined(SN_FLOAT)
static const double GOAL = 0.001;   /* as test_rig_runtime: float runtime within 0.1% of the response */
#else
static const double GOAL = 0.01;    /* fixed within 1% */
#endif

/* ---- blob facts the tests need (read from the header, not the runtime) ---- */
static double force_scale(const pu_rt *r) {
    const unsigned char *b = (const unsigned char *)r->bytes;
    uint32_t u = (uint32_t)b[SN_H_REALS + 4 * SN_R_FORCE] | ((uint32_t)b[SN_H_REALS + 4 * SN_R_FORCE + 1] << 8) |
                 ((uint32_t)b[SN_H_REALS + 4 * SN_R_FORCE + 2] << 16) | ((uint32_t)b[SN_H_REALS + 4 * SN_R_FORCE + 3] << 24);
#if defined(SN_FLOAT)
    float f;
    memcpy(&f, &u, 4);
    return f;
#else
    return ldexp((double)(int32_t)u, -(signed char)b[SN_H_FRAC_F]);
#endif
}
static double shares(const snref_model *m, const pu_rt *r, unsigned prof, unsigned k) {
    const unsigned char *b = (const unsigned char *)r->bytes;
    uint32_t off = (uint32_t)b[SN_H_SECTIONS + 16 * SN_SEC_SHARES] | ((uint32_t)b[SN_H_SECTIONS + 16 * SN_SEC_SHARES + 1] << 8) |
                   ((uint32_t)b[SN_H_SECTIONS + 16 * SN_SEC_SHARES + 2] << 16);
    const unsigned char *p = b + off + 4 * (SN_LEVELS * prof + k);
    uint32_t u = (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
    (void)m;
#if defined(SN_FLOAT)
    { float f; memcpy(&f, &u, 4); return f; }
#else
    return ldexp((double)(int32_t)u, -30);
#endif
}

/* ---- the double reference of the distribution (NUMERICS.md "External forces") ----
 * out: per free vertex, rhs units; returns the share that went to the flesh. */
static double ref_distribute(const snref_model *m, const pu_rt *r, const double *pos, unsigned cell, const double t[3],
                             unsigned prof, const double F[3], double *out, double mom[3]) {
    double phi[8], x[3] = {0, 0, 0}, p[3] = {0, 0, 0}, fine, flesh = 0;
    unsigned a, d, k, nF = m->nF;
    memset(out, 0, 3 * nF * sizeof *out);
    mom[0] = mom[1] = mom[2] = 0;
    for (a = 0; a < 8; a++) {
        phi[a] = ((a & 1) ? t[0] : 1 - t[0]) * ((a & 2) ? t[1] : 1 - t[1]) * ((a & 4) ? t[2] : 1 - t[2]);
        for (d = 0; d < 3; d++) {
            x[d] += phi[a] * m->rest[3 * m->cells[8 * cell + a] + d];
            p[d] += phi[a] * pos[3 * m->cells[8 * cell + a] + d];
        }
    }
    fine = shares(m, r, prof, 0);
    for (k = 1; k <= 3; k++) {
        double s = shares(m, r, prof, k), R = m->cell * (double)(1 << k), W = 0, c[3] = {0, 0, 0}, I[3][3] = {{0}}, *w, det;
        double adj[3][3], rp[3], cr[3], beta[3], tr;
        if (s == 0) continue;
        w = calloc(nF, sizeof *w);
        for (a = 0; a < nF; a++) {
            double hat = 1;
            for (d = 0; d < 3; d++) { double u = fabs(m->rest[3 * a + d] - x[d]) / R; hat *= u < 1 ? 1 - u : 0; }
            w[a] = hat * m->mlump[a];
            W += w[a];
        }
        if (!(W > 0)) { fine += s; free(w); continue; }
        for (a = 0; a < nF; a++) { w[a] /= W; for (d = 0; d < 3; d++) c[d] += w[a] * pos[3 * a + d]; }
        for (a = 0; a < nF; a++) {
            double rr[3], r2;
            for (d = 0; d < 3; d++) rr[d] = (pos[3 * a + d] - c[d]) / R;
            r2 = rr[0] * rr[0] + rr[1] * rr[1] + rr[2] * rr[2];
            for (d = 0; d < 3; d++) { unsigned e; for (e = 0; e < 3; e++) I[d][e] += w[a] * ((d == e ? r2 : 0) - rr[d] * rr[e]); }
        }
        adj[0][0] = I[1][1] * I[2][2] - I[1][2] * I[2][1]; adj[0][1] = I[0][2] * I[2][1] - I[0][1] * I[2][2];
        adj[0][2] = I[0][1] * I[1][2] - I[0][2] * I[1][1]; adj[1][0] = adj[0][1];
        adj[1][1] = I[0][0] * I[2][2] - I[0][2] * I[2][0]; adj[1][2] = I[0][2] * I[1][0] - I[0][0] * I[1][2];
        adj[2][0] = adj[0][2]; adj[2][1] = adj[1][2]; adj[2][2] = I[0][0] * I[1][1] - I[0][1] * I[1][0];
        det = I[0][0] * adj[0][0] + I[0][1] * adj[1][0] + I[0][2] * adj[2][0];
        tr = I[0][0] + I[1][1] + I[2][2];
        if (!(det > ldexp(1, -32)) || det * 2048 < tr * tr * tr) { fine += s; free(w); continue; } /* the runtime's fallback */
        for (d = 0; d < 3; d++) rp[d] = (p[d] - c[d]) / R;
        cr[0] = rp[1] * F[2] - rp[2] * F[1]; cr[1] = rp[2] * F[0] - rp[0] * F[2]; cr[2] = rp[0] * F[1] - rp[1] * F[0];
        for (d = 0; d < 3; d++) beta[d] = (adj[d][0] * cr[0] + adj[d][1] * cr[1] + adj[d][2] * cr[2]) / det;
        for (a = 0; a < nF; a++) {
            double rr[3];
            for (d = 0; d < 3; d++) rr[d] = (pos[3 * a + d] - c[d]) / R;
            out[3 * a] += s * w[a] * (F[0] + beta[1] * rr[2] - beta[2] * rr[1]);
            out[3 * a + 1] += s * w[a] * (F[1] + beta[2] * rr[0] - beta[0] * rr[2]);
            out[3 * a + 2] += s * w[a] * (F[2] + beta[0] * rr[1] - beta[1] * rr[0]);
        }
        flesh += s;
        mom[0] += s * (p[1] * F[2] - p[2] * F[1]); mom[1] += s * (p[2] * F[0] - p[0] * F[2]); mom[2] += s * (p[0] * F[1] - p[1] * F[0]);
        free(w);
    }
    for (a = 0; a < 8; a++) {
        unsigned vx = m->cells[8 * cell + a];
        const double *pa = pos + 3 * vx;
        double g = fine * phi[a];
        if (vx >= nF) continue; /* a skeleton corner: its bone's wrench */
        for (d = 0; d < 3; d++) out[3 * vx + d] += g * F[d];
        flesh += g;
        mom[0] += g * (pa[1] * F[2] - pa[2] * F[1]); mom[1] += g * (pa[2] * F[0] - pa[0] * F[2]); mom[2] += g * (pa[0] * F[1] - pa[1] * F[0]);
    }
    (void)r;
    return flesh;
}

/* the runtime's distribution alone: b from sn_forces_rhs on a zero b (rhs units) */
static void rt_distribute(pu_rt *r, const sn_force *f, double *out, double *lsb, uint32_t *sat) {
    sn_ihdr *h = hdr_of(r->inst);
    unsigned n3 = 3 * r->info.free_vertices, i;
    sn_q *b = calloc(n3, sizeof *b);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    *sat = 0;
    T_CHECK(sn_apply_force(r->inst, f) == SN_OK, "apply force");
    sn_forces_rhs(h, b, sat);
    sn_forces_clear(h);
    for (i = 0; i < n3; i++) {
#if defined(SN_FLOAT)
        out[i] = b[i]; lsb[i] = 0; (void)kk;
#else
        out[i] = ldexp((double)b[i], -(SN_Q_FORCE + kk[i / 3]));
        lsb[i] = ldexp(0.5, -(SN_Q_FORCE + kk[i / 3]));
#endif
    }
    free(b);
}

static void state_pos(const pu_rt *r, double *pos) {
    const sn_ihdr *h = chdr_of(r->inst);
    unsigned i;
    for (i = 0; i < 3 * r->info.vertices; i++) pos[i] = pu_qd(CARR(h, o_pos, sn_q)[i]);
}

/* surface vertices whose cell has at least 4 free corners, spread over the mesh */
static unsigned flesh_vertices(const snref_model *m, unsigned *out, unsigned max) {
    unsigned s, n = 0, a;
    for (s = 0; s < m->nS && n < max; s += 1 + m->nS / (8 * max)) {
        unsigned nfree = 0;
        for (a = 0; a < 8; a++) nfree += m->cells[8 * m->ecell[s] + a] < m->nF;
        if (nfree >= 4) out[n++] = s;
    }
    return n;
}

/* 1. distribution: per vertex, totals and moments */
/* example blob of this build's flavour */
static void example(char *path, size_t n, const char *name) {
    char full[256];
    snprintf(full, sizeof full, "%s%s", name, PU_BLOB_SUFFIX);
    pu_example(path, n, full);
}

static void test_distribution(const char *name, int bend) {
    char path[512];
    pu_rt r;
    snref_model m;
    snref_state st;
    unsigned vs[8], nv, i, prof, a, d;
    double worst_v = 0, worst_F = 0, worst_M = 0, fs;
    sn_xform pose[64];
    example(path, sizeof path, name);
    if (pu_rt_open(&r, path)) { T_CHECK(0, "open %s", path); return; }
    if (pu_ref_open(&m, &st, path)) { T_CHECK(0, "reference %s", path); return; }
    T_CHECK(r.info.force_slots > 0 && r.info.force_profiles >= 4, "%s: %u force slots, %u profiles", name, r.info.force_slots, r.info.force_profiles);
    fs = force_scale(&r);
    {   /* a rigidly turned and moved pose (and a bent one) so world and rest frames differ */
        sn_quat lq[64];
        sn_vec3 off = {pu_rlen(1.5), pu_rlen(-0.5), pu_rlen(2.0)};
        for (i = 0; i < r.info.joints; i++) lq[i] = sn_quat_axis_angle((sn_vec3){0, 0, pu_rlen(1)}, 0);
        lq[0] = sn_quat_axis_angle((sn_vec3){pu_rlen(0.3), pu_rlen(1), 0}, pu_rang(35));
        if (bend && r.info.joints > 1) lq[1] = sn_quat_axis_angle((sn_vec3){0, 0, pu_rlen(1)}, pu_rang(40));
        sn_pose_from_local(r.blob, lq, &off, pose);
        sn_set_pose(r.inst, pose, r.info.joints);
        for (i = 0; i < 20; i++) sn_step(r.inst);
    }
    nv = flesh_vertices(&m, vs, 8);
    T_CHECK(nv >= 3, "%s: %u surface vertices in cells with 4 free corners or more", name, nv);
    for (prof = 0; prof < r.info.force_profiles; prof++)
        for (i = 0; i < nv; i++) {
            double *pos = malloc(3 * r.info.vertices * sizeof *pos), *fr = malloc(3 * m.nF * sizeof *fr);
            double *fb = malloc(3 * m.nF * sizeof *fb), *lsb = malloc(3 * m.nF * sizeof *lsb);
            double F[3] = {2000.0 * (i % 3 == 0 ? 1 : 0.3), -1500.0, 700.0 * (i % 2 ? 1 : -1)}, Fr[3], t[3], p[3] = {0, 0, 0};
            double tot[3] = {0, 0, 0}, mom[3] = {0, 0, 0}, want[3], wmom[3], rtot[3] = {0, 0, 0}, rmom[3] = {0, 0, 0}, tolF = 0, tolM = 0, dv = 0, fbig = 0, flesh;
            sn_force f;
            uint32_t sat;
            unsigned cell = m.ecell[vs[i]];
            memset(&f, 0, sizeof f);
            f.at = SN_AT_SURFACE; f.vertex = vs[i]; f.profile = (int32_t)prof;
            f.force.x = pu_rlen(F[0]); f.force.y = pu_rlen(F[1]); f.force.z = pu_rlen(F[2]);
            for (d = 0; d < 3; d++) { F[d] = pu_len(pu_rlen(F[d])); Fr[d] = F[d] * fs; t[d] = m.et[3 * vs[i] + d]; }
            state_pos(&r, pos);
            rt_distribute(&r, &f, fb, lsb, &sat);
            flesh = ref_distribute(&m, &r, pos, cell, t, prof, Fr, fr, wmom);
            for (a = 0; a < 8; a++) {
                double ph = ((a & 1) ? t[0] : 1 - t[0]) * ((a & 2) ? t[1] : 1 - t[1]) * ((a & 4) ? t[2] : 1 - t[2]);
                for (d = 0; d < 3; d++) p[d] += ph * pos[3 * m.cells[8 * cell + a] + d];
            }
            for (a = 0; a < m.nF; a++) {
                const double *pa = pos + 3 * a, *fa = fb + 3 * a;
                for (d = 0; d < 3; d++) {
                    tot[d] += fa[d];
                    dv = fmax(dv, fabs(fa[d] - fr[3 * a + d]));
                    fbig = fmax(fbig, fabs(fr[3 * a + d]));
                    if (fa[d] != 0 || fr[3 * a + d] != 0) { tolF += lsb[3 * a + d]; tolM += lsb[3 * a + d] * (fabs(pa[0]) + fabs(pa[1]) + fabs(pa[2])); }
                }
                mom[0] += pa[1] * fa[2] - pa[2] * fa[1]; mom[1] += pa[2] * fa[0] - pa[0] * fa[2]; mom[2] += pa[0] * fa[1] - pa[1] * fa[0];
                for (d = 0; d < 3; d++) rtot[d] += fr[3 * a + d];
                rmom[0] += pa[1] * fr[3 * a + 2] - pa[2] * fr[3 * a + 1]; rmom[1] += pa[2] * fr[3 * a] - pa[0] * fr[3 * a + 2];
                rmom[2] += pa[0] * fr[3 * a + 1] - pa[1] * fr[3 * a];
            }
            for (d = 0; d < 3; d++) want[d] = flesh * Fr[d];   /* the flesh's part (skeleton corners and the rigid level go to the bones) */
            {
                double eF = 0, eM = 0, nF_ = sqrt(Fr[0] * Fr[0] + Fr[1] * Fr[1] + Fr[2] * Fr[2]);
                double pn = fabs(p[0]) + fabs(p[1]) + fabs(p[2]) + 1;
                /* beyond the output rounding (tolF, tolM: 1/2 LSB of every touched vertex's force format),
                 * the Q28 weights and 30-bit mantissa: 2^-24 of the force (fixed); float: 1e-5 relative */
#if defined(SN_FLOAT)
                double rel = 1e-5, relM = 1e-5;
#else
                /* fixed: the 21-bit arms (force total, |beta| 2^-21 with |beta| a few |F|) and the 19-bit Î block
                 * times its condition (at most 2^11 by the runtime's test, ~2^4 in these regions) for the moment */
                double rel = ldexp(1, -18), relM = ldexp(1, -14);
#endif
                double rF = 0, rM = 0;
                for (d = 0; d < 3; d++) { eF = fmax(eF, fabs(tot[d] - want[d])); eM = fmax(eM, fabs(mom[d] - wmom[d])); }
                for (d = 0; d < 3; d++) { rF = fmax(rF, fabs(rtot[d] - want[d])); rM = fmax(rM, fabs(rmom[d] - wmom[d])); }
                /* the double distribution keeps force and moment to round-off: the claim the runtime is held to */
                T_CHECK(rF <= 1e-12 * nF_ && rM <= 1e-12 * nF_ * pn, "%s profile %u vertex %u: double distribution keeps force (%.2g) and moment (%.2g)", name, prof, vs[i], rF, rM);
                worst_F = fmax(worst_F, eF / nF_); worst_M = fmax(worst_M, eM / (nF_ * pn));
                worst_v = fmax(worst_v, dv / fbig);
                T_CHECK(eF <= tolF + rel * nF_, "%s profile %u vertex %u: total force off by %.3g (tolerance %.3g, force %.3g)", name, prof, vs[i], eF, tolF + rel * nF_, nF_);
                T_CHECK(eM <= tolM + relM * nF_ * pn, "%s profile %u vertex %u: moment off by %.3g (tolerance %.3g)", name, prof, vs[i], eM, tolM + relM * nF_ * pn);
                /* per vertex: the fixed hats are Q16 per axis (3 2^-16 relative), the rest as above */
                T_CHECK(dv <= 4 * ldexp(1, -16) * fbig + 2 * tolF / 3 + rel * nF_, "%s profile %u vertex %u: per-vertex force %.3g off the double distribution (largest %.3g)", name, prof, vs[i], dv, fbig);
                T_CHECK(sat == 0, "%s profile %u: %u clamps", name, prof, sat);
            }
            free(pos); free(fr); free(fb); free(lsb);
        }
    T_FIGURE("%s %s%s: distribution vs double over %u profiles x %u points: total force %.2e, moment %.2e (relative), per vertex %.2e of the largest",
             PU_FLAVOUR_NAME, name, bend ? " bent" : "", r.info.force_profiles, nv, worst_F, worst_M, worst_v);
    snref_release(&st); snref_free(&m);
    pu_rt_close(&r);
}

/* 2. wrench: the rigid profile's force and torques (rest pose: the origin stays put) */
static void test_wrench(const char *name) {
    char path[512];
    pu_rt r;
    snref_model m;
    snref_state st;
    unsigned s, j, tested = 0, exact = 0;
    int rigid = -1;
    example(path, sizeof path, name);
    if (pu_rt_open(&r, path) || pu_ref_open(&m, &st, path)) { T_CHECK(0, "open %s", path); return; }
    for (j = 0; j < r.info.force_profiles; j++) if (shares(&m, &r, j, SN_LEVELS - 1) == 1.0) rigid = (int)j;
    T_CHECK(rigid >= 0, "%s has an all-rigid profile", name);
    if (rigid < 0) { pu_rt_close(&r); return; }
    for (s = 0; s < m.nS; s += 1 + m.nS / 12) {
        sn_force f;
        sn_vec3 P, F, T, A;
        double sumF[3] = {0, 0, 0};
        unsigned d;
        memset(&f, 0, sizeof f);
        f.at = SN_AT_SURFACE; f.vertex = s; f.profile = rigid;
        f.force.x = pu_rlen(123.25); f.force.y = pu_rlen(-456.5); f.force.z = pu_rlen(78.125 + s);
        sn_get_surface(r.inst, &P, s, 1);   /* the point the step uses (positions at its start) */
        T_CHECK(sn_apply_force(r.inst, &f) == SN_OK, "apply");
        sn_step(r.inst);
        tested++;
        for (j = 0; j < r.info.joints; j++) {
            int ok = 1;
            sn_get_joint_wrench(r.inst, j, &F, &T, &A);
            sumF[0] += pu_len(F.x); sumF[1] += pu_len(F.y); sumF[2] += pu_len(F.z);
#if !defined(SN_FLOAT)
            {   /* exact: (P - A) x F in Q32, rounded once to Q16.16 (ties up, as the runtime's shifts) */
                int64_t rx = (int64_t)P.x - A.x, ry = (int64_t)P.y - A.y, rz = (int64_t)P.z - A.z;
                int64_t t0 = ry * F.z - rz * F.y, t1 = rz * F.x - rx * F.z, t2 = rx * F.y - ry * F.x;
                ok = T.x == (int32_t)((t0 + 32768) >> 16) && T.y == (int32_t)((t1 + 32768) >> 16) && T.z == (int32_t)((t2 + 32768) >> 16);
            }
#else
            {
                double rx = P.x - A.x, ry = P.y - A.y, rz = P.z - A.z, e;
                e = fabs(T.x - (ry * F.z - rz * F.y)) + fabs(T.y - (rz * F.x - rx * F.z)) + fabs(T.z - (rx * F.y - ry * F.x));
                ok = e <= 1e-5 * (fabs(rx) + fabs(ry) + fabs(rz) + 1) * (fabs(F.x) + fabs(F.y) + fabs(F.z));
            }
#endif
            T_CHECK(ok, "%s vertex %u joint %u: torque = (point - joint) x force", name, s, j);
            exact += ok;
        }
        for (d = 0; d < 3; d++) {
            double want = d == 0 ? 123.25 : d == 1 ? -456.5 : 78.125 + s;
#if defined(SN_FLOAT)
            T_CHECK(fabs(sumF[d] - want) <= 1e-5 * 500, "%s vertex %u: joint forces sum to the applied one (%g vs %g)", name, s, sumF[d], want);
#else
            T_CHECK(sumF[d] == want, "%s vertex %u: joint forces sum exactly to the applied one (%.6f vs %.6f)", name, s, sumF[d], want);
#endif
        }
    }
    {   /* a step without forces leaves every wrench zero */
        sn_vec3 F, T;
        int zero = 1;
        sn_step(r.inst);
        for (j = 0; j < r.info.joints; j++) {
            sn_get_joint_wrench(r.inst, j, &F, &T, NULL);
            zero &= F.x == 0 && F.y == 0 && F.z == 0 && T.x == 0 && T.y == 0 && T.z == 0;
        }
        T_CHECK(zero, "%s: wrenches zero after a step without forces", name);
    }
    T_FIGURE("%s %s: rigid profile at %u points: joint forces sum to the applied force, %u joint torques equal (point - joint) x force%s",
             PU_FLAVOUR_NAME, name, tested, exact, SN_FLAVOUR == 0 ? " exactly (Q32 rounded once)" : " within 1e-5");
    snref_release(&st); snref_free(&m);
    pu_rt_close(&r);
}

/* 3. response: a force held until the limb settles = the double static solve
 * under the double distribution's load (difference with and without it, so
 * gravity's own sag cancels) */
static void test_response(const char *name, const char *profname) {
    char path[512];
    pu_rt r;
    snref_model m;
    snref_state st;
    unsigned nV, nF, i, d, s, k;
    int prof = -1;
    double *pos, *load, *x, *lat0, *lat1, fs, worst = 0, big = 0;
    double F[3] = {0, 40.0, 25.0};
    sn_force f;
    example(path, sizeof path, name);
    if (pu_rt_open(&r, path) || pu_ref_open(&m, &st, path)) { T_CHECK(0, "open %s", path); return; }
    {   /* profile by name is not in the blob: the limb's order is arm, local, region2, region4, rigid */
        static const char *names[] = {"arm", "local", "region2", "region4", "rigid"};
        for (i = 0; i < 5; i++) if (!strcmp(names[i], profname)) prof = (int)i;
    }
    nV = r.info.vertices; nF = r.info.free_vertices;
    fs = force_scale(&r);
    pos = malloc(3 * nV * sizeof *pos); load = malloc(3 * nF * sizeof *load); x = calloc(3 * nF, sizeof *x);
    lat0 = malloc(3 * nV * sizeof *lat0); lat1 = malloc(3 * nV * sizeof *lat1);
    s = m.nS / 3;   /* a surface vertex on the upper arm's side */
    memset(&f, 0, sizeof f);
    f.at = SN_AT_SURFACE; f.vertex = s; f.profile = prof;
    f.force.x = pu_rlen(F[0]); f.force.y = pu_rlen(F[1]); f.force.z = pu_rlen(F[2]);
    /* settle at rest without, then with the force held */
    for (k = 0; k < 900; k++) sn_step(r.inst);
    pu_rt_lattice(&r, lat0);
    for (k = 0; k < 1500; k++) { sn_apply_force(r.inst, &f); sn_step(r.inst); }
    pu_rt_lattice(&r, lat1);
    {   /* the coarse levels spread the force over the region as it is now: the settled state's load */
        double Fr[3], t[3], mm[3];
        state_pos(&r, pos);
        Fr[0] = pu_len(f.force.x) * fs; Fr[1] = pu_len(f.force.y) * fs; Fr[2] = pu_len(f.force.z) * fs;
        for (d = 0; d < 3; d++) t[d] = m.et[3 * s + d];
        ref_distribute(&m, &r, pos, m.ecell[s], t, (unsigned)prof, Fr, load, mm);
    }
    snref_solve_load(&st, load, x);   /* rest pose: the reference's frames are the identity */
    for (i = 0; i < nF; i++)
        for (d = 0; d < 3; d++) {
            double got = lat1[3 * i + d] - lat0[3 * i + d], want = x[3 * i + d] * m.unit;
            worst = fmax(worst, fabs(got - want));
            big = fmax(big, fabs(want));
        }
    T_FIGURE("%s %s: force (0, 40, 25) N held on surface vertex %u with profile '%s': settled response vs double static solve %.2e of the largest (%.4f mesh units)",
             PU_FLAVOUR_NAME, name, s, profname, worst / big, big);
    PU_GOAL(worst <= GOAL * big, "%s %s profile %s: response within %.1f%% of the double static solve (got %.3f%%)", PU_FLAVOUR_NAME, name, profname,
            100 * GOAL, 100 * worst / big);
    T_CHECK(worst <= 0.05 * big && big > 0, "%s %s profile %s: response %.3g off (largest %.3g)", PU_FLAVOUR_NAME, name, profname, worst, big);
    free(pos); free(load); free(x); free(lat0); free(lat1);
    snref_release(&st); snref_free(&m);
    pu_rt_close(&r);
}

/* 4. seed 004 fig. 4.9-4.11 on the limb: an impulse on the upper arm's side;
 * the ratio of the largest displacement of the surface point 3 cells along
 * the arm to the hit point's grows with the coarse share (local -> 2 cells
 * -> 4 cells), and the local share dents the hit point most */
static void test_ordering(void) {
    char path[512];
    pu_rt r;
    snref_model m;
    snref_state st;
    static const int profs[3] = {1, 2, 3};   /* limb: local, region2, region4 */
    double ratio[3], near_[3], cell, *s0, *s1, best = 1e30, bd = 1e30;
    unsigned s, far = 0, hit = 0, i, k, nS;
    example(path, sizeof path, "limb");
    if (pu_rt_open(&r, path) || pu_ref_open(&m, &st, path)) { T_CHECK(0, "open limb"); return; }
    nS = r.info.surface_vertices;
    s0 = malloc(3 * nS * sizeof *s0); s1 = malloc(3 * nS * sizeof *s1);
    pu_rt_surface(&r, s0);
    cell = m.cell * m.unit;
    /* the hit: on the +y face at x = 1.5, z = 0.5 (upper arm, half its cell on flesh: the bone holds z = 0); far: 3 cells along */
    for (s = 0; s < nS; s++) {
        double d1 = fabs(s0[3 * s] - 1.5) + fabs(s0[3 * s + 1] - 1) + fabs(s0[3 * s + 2] - 0.5);
        double d2 = fabs(s0[3 * s] - 1.5 - 3 * cell) + fabs(s0[3 * s + 1] - 1) + fabs(s0[3 * s + 2] - 0.5);
        if (d1 < best) { best = d1; hit = s; }
        if (d2 < bd) { bd = d2; far = s; }
    }
    for (i = 0; i < 3; i++) {
        sn_force f;
        double mn = 0, mf = 0;
        sn_reset(r.inst);
        for (k = 0; k < 300; k++) sn_step(r.inst);
        pu_rt_surface(&r, s0);
        memset(&f, 0, sizeof f);
        f.at = SN_AT_SURFACE; f.vertex = hit; f.profile = profs[i];
        f.force.y = pu_rlen(0.2);   /* an upward 0.2 N s tap */
        T_CHECK(sn_apply_impulse(r.inst, &f) == SN_OK, "impulse");
        for (k = 0; k < 40; k++) {
            unsigned c;
            double dn = 0, df = 0;
            sn_step(r.inst);
            pu_rt_surface(&r, s1);
            for (c = 0; c < 3; c++) {
                dn += (s1[3 * hit + c] - s0[3 * hit + c]) * (s1[3 * hit + c] - s0[3 * hit + c]);
                df += (s1[3 * far + c] - s0[3 * far + c]) * (s1[3 * far + c] - s0[3 * far + c]);
            }
            mn = fmax(mn, sqrt(dn)); mf = fmax(mf, sqrt(df));
        }
        near_[i] = mn;
        ratio[i] = mf / mn;
    }
    T_FIGURE("%s limb impulse 0.2 N s up at surface vertex %u, far point %u (%.2f mesh units along): hit moves %.4f / %.4f / %.4f, far/hit %.3f / %.3f / %.3f (local / 2 cells / 4 cells)",
             PU_FLAVOUR_NAME, hit, far, s0[3 * far] - s0[3 * hit], near_[0], near_[1], near_[2], ratio[0], ratio[1], ratio[2]);
    T_CHECK(ratio[0] < ratio[1] && ratio[1] < ratio[2], "far/hit displacement ratio grows with the coarse share: %.3f < %.3f < %.3f",
            ratio[0], ratio[1], ratio[2]);
    /* the 2-cell region (on a limb 2 cells thick: the whole section) can lift the hit point as much as a dent does;
     * the 4-cell one spreads the push over the arm */
    T_CHECK(near_[0] > near_[2] && near_[1] > near_[2], "the widest region moves the hit point least: %.4f, %.4f > %.4f", near_[0], near_[1], near_[2]);
    free(s0); free(s1);
    snref_release(&st); snref_free(&m);
    pu_rt_close(&r);
}

/* 5. impulses, world points, refusals */
static void test_api(void) {
    char path[512];
    pu_rt r, r2;
    snref_model m;
    snref_state st;
    sn_force f;
    sn_stats sts;
    uint64_t h0;
    unsigned k, s;
    double *a, *b, worst = 0, big = 0;
    example(path, sizeof path, "limb");
    if (pu_rt_open(&r, path) || pu_rt_open(&r2, path) || pu_ref_open(&m, &st, path)) { T_CHECK(0, "open limb"); return; }
    a = malloc(3 * r.info.vertices * sizeof *a); b = malloc(3 * r.info.vertices * sizeof *b);
    /* an impulse J is the force J/h for one step */
    memset(&f, 0, sizeof f);
    f.at = SN_AT_SURFACE; f.vertex = 7; f.profile = 0;
    f.force.y = pu_rlen(0.5);
    T_CHECK(sn_apply_impulse(r.inst, &f) == SN_OK, "impulse");
    f.force.y = pu_rlen(0.5 / pu_len(r.info.timestep));
    T_CHECK(sn_apply_force(r2.inst, &f) == SN_OK, "force");
    for (k = 0; k < 20; k++) { sn_step(r.inst); sn_step(r2.inst); }
    pu_rt_lattice(&r, a); pu_rt_lattice(&r2, b);
    sn_reset(r2.inst);
    for (k = 0; k < 20; k++) sn_step(r2.inst);
    {
        double *c = malloc(3 * r.info.vertices * sizeof *c);
        pu_rt_lattice(&r2, c);
        for (k = 0; k < 3 * r.info.vertices; k++) { worst = fmax(worst, fabs(a[k] - b[k])); big = fmax(big, fabs(a[k] - c[k])); }
        free(c);
    }
    /* the force J/h is itself rounded to Q16.16 newtons: 2^-17 relative at most */
    T_CHECK(worst <= 1e-4 * big + 1e-6, "impulse J = force J/h for one step: %.3g off (response %.3g)", worst, big);
    /* world point: the flesh under a surface vertex's current position is that vertex's cell and point */
    sn_reset(r.inst);
    {
        sn_xform pose[64];
        sn_quat lq[64];
        sn_vec3 off = {pu_rlen(3), pu_rlen(1), pu_rlen(-2)}, P;
        unsigned okc = 0, n = 0;
        double werr = 0;
        for (k = 0; k < r.info.joints; k++) lq[k] = sn_quat_axis_angle((sn_vec3){0, 0, pu_rlen(1)}, 0);
        lq[0] = sn_quat_axis_angle((sn_vec3){pu_rlen(1), pu_rlen(1), 0}, pu_rang(50));
        sn_pose_from_local(r.blob, lq, &off, pose);
        sn_teleport(r.inst, pose, r.info.joints);   /* rigidly carried: frames map world to rest exactly */
        for (s = 0; s < m.nS; s += 5) {
            sn_ihdr *h = hdr_of(r.inst);
            const sn_q *pos = CARR(h, o_pos, sn_q);
            sn_q phi[8];
            double q[3] = {0, 0, 0}, e = 0;
            unsigned c, d;
            const struct { uint32_t cell; uint16_t t[3]; } *slot;
            sn_get_surface(r.inst, &P, s, 1);
            memset(&f, 0, sizeof f);
            f.at = SN_AT_POINT; f.point = P; f.profile = 1;
            T_CHECK(sn_apply_force(r.inst, &f) == SN_OK, "apply at point");
            slot = (const void *)CARR(h, o_frc, unsigned char);
            for (c = 0; c < 8; c++) {
                uint32_t wx = (c & 1u) ? slot->t[0] : 32768u - slot->t[0], wy = (c & 2u) ? slot->t[1] : 32768u - slot->t[1];
                uint32_t wz = (c & 4u) ? slot->t[2] : 32768u - slot->t[2];
                phi[c] = 0;
                for (d = 0; d < 3; d++) q[d] += (double)wx * wy * wz / 35184372088832.0 * pu_qd(pos[3 * m.cells[8 * slot->cell + c] + d]);
            }
            (void)phi;
            for (d = 0; d < 3; d++) {
                double pd = (d == 0 ? pu_len(P.x) : d == 1 ? pu_len(P.y) : pu_len(P.z)) - pu_len(h->origin[d]);
                e = fmax(e, fabs(q[d] * m.unit - pd));
            }
            werr = fmax(werr, e);
            okc += slot->cell == m.ecell[s] || e < 1e-3 * m.cell * m.unit;
            n++;
            sn_forces_clear(h);
        }
        T_FIGURE("%s limb turned 50 deg and moved: forces at the world positions of %u surface vertices land on material points within %.2e mesh units of them",
                 PU_FLAVOUR_NAME, n, werr);
        T_CHECK(werr <= 2e-3 * m.cell * m.unit && okc == n, "world points found the flesh under them: %.3g mesh units (cell %.3g), %u/%u", werr, m.cell * m.unit, okc, n);
    }
    /* refusals change nothing */
    sn_reset(r.inst);
    for (k = 0; k < 5; k++) sn_step(r.inst);
    h0 = sn_state_hash(r.inst);
    memset(&f, 0, sizeof f);
    f.at = SN_AT_SURFACE; f.vertex = r.info.surface_vertices; f.profile = -1;
    T_CHECK(sn_apply_force(r.inst, &f) == SN_ERR_ARG, "surface vertex out of range refused");
    f.vertex = 0; f.profile = (int32_t)r.info.force_profiles;
    T_CHECK(sn_apply_force(r.inst, &f) == SN_ERR_ARG, "profile out of range refused");
    f.profile = -2;
    T_CHECK(sn_apply_force(r.inst, &f) == SN_ERR_ARG, "profile -2 refused");
    f.profile = -1; f.at = 7;
    T_CHECK(sn_apply_impulse(r.inst, &f) == SN_ERR_ARG, "unknown kind refused");
    T_CHECK(sn_apply_force(r.inst, NULL) == SN_ERR_NULL && sn_apply_force(NULL, &f) == SN_ERR_NULL, "NULL refused");
#if defined(SN_FLOAT)
    f.at = SN_AT_SURFACE; f.force.x = 0.0f / 0.0f;
    T_CHECK(sn_apply_force(r.inst, &f) == SN_ERR_ARG, "NaN force refused");
    f.force.x = 2e9f;
    T_CHECK(sn_apply_force(r.inst, &f) == SN_ERR_ARG, "force beyond 1e9 refused");
#endif
    T_CHECK(sn_state_hash(r.inst) == h0 && hdr_of(r.inst)->n_forces == 0, "refused calls change nothing");
    memset(&f, 0, sizeof f);
    f.at = SN_AT_SURFACE; f.vertex = 3; f.profile = -1; f.force.z = pu_rlen(1);
    for (k = 0; k < r.info.force_slots; k++) T_CHECK(sn_apply_force(r.inst, &f) == SN_OK, "slot %u", k);
    T_CHECK(sn_apply_force(r.inst, &f) == SN_ERR_FULL && sn_apply_impulse(r.inst, &f) == SN_ERR_FULL, "full slots: SN_ERR_FULL");
    sn_get_stats(r.inst, &sts);
    T_CHECK(sts.force_drops == 2, "refusals counted: %u", sts.force_drops);
    sn_step(r.inst);
    T_CHECK(sn_apply_force(r.inst, &f) == SN_OK, "slots free again after the step");
    sn_reset(r.inst);
    sn_get_stats(r.inst, &sts);
    T_CHECK(sts.force_drops == 0 && hdr_of(r.inst)->n_forces == 0, "reset clears forces and their count");
    {   /* a wrench of a joint out of range / NULL outputs */
        sn_vec3 F, T;
        T_CHECK(sn_get_joint_wrench(r.inst, r.info.joints, &F, &T, NULL) == SN_ERR_ARG, "wrench joint out of range");
        T_CHECK(sn_get_joint_wrench(r.inst, 0, NULL, &T, NULL) == SN_ERR_NULL, "wrench NULL force");
    }
    free(a); free(b);
    snref_release(&st); snref_free(&m);
    pu_rt_close(&r); pu_rt_close(&r2);
}

int main(void) {
    test_distribution("limb", 0);
    test_distribution("limb", 1);
    test_distribution("cow", 1);
    test_wrench("limb");
    test_wrench("cow");
    test_response("limb", "local");
    test_response("limb", "region2");
    test_response("limb", "region4");
    test_ordering();
    test_api();
    return T_END();
}
