/* test_runtime_constraint.c -- position constraints and colliders (issue 12
 * items 1 and 3; seed 000 §4.4, seed 003 §3.4 eq. 9), on the baked cow.
 * Built fixed and float.
 *
 *  1. rows hold: after every constrained step, every kept row's C^T x - a
 *     (white box, the runtime's own rows and coefficients) is within 1 LSB
 *     of Q22 (fixed; the final correction leaves the rounding of one
 *     weighted sum) or 1e-6 of the row's scale (float); the pinned surface
 *     points sit at their targets (public units, within the same bound
 *     plus the output's rounding);
 *  2. the unconstrained directions still converge: the runtime against the
 *     double reference's constrained solve of the same steps (same rows,
 *     same iterations, tools/ref/snref.c), surface within the runtime-vs-
 *     reference goal of test_physics_runtime (fixed 1%, float 0.1% of the
 *     largest displacement the run produces);
 *  3. QR drops: duplicate, conflicting and same-cell constraints are
 *     dropped in list order, counted in the stats, nothing non-finite, the
 *     kept ones still hold; the same list twice gives the same hash;
 *  4. ground plane under the trot: no surface vertex more than a stated
 *     depth below the plane after contact; resting on the plane, energy
 *     does not grow; a sphere pushed into the belly keeps the surface out;
 *  5. overflow of every maximum (constraints, colliders, contacts, rows):
 *     counted, state finite and deterministic;
 *  6. API: bad arguments refused with a status, nothing changes.
 */
#include "sn_test.h"
#define PU_WHITE_BOX /* pu_h, pu_qd, ...: the instance's internals */
#include "reference/phys_util.h"
#include "sn_constraint.h"
#include "sn_clip.h"

#if defined(SN_FLOAT)
#define SN_FLOAT_OR(f, x) (f)
#else
#define SN_FLOAT_OR(f, x) (x)
#endif
#if defined(SN_FLOAT)
static const double GOAL = 0.001; /* test_physics_runtime: float runtime within 0.1% */
#else
static const double GOAL = 0.01;  /* fixed within 1% */
#endif

static sn_real rl(double x) { return pu_rlen(x); }

/* squared length of a surface vertex's row over the free lattice vertices:
 * sum of phi_a^2 over its cell's free corners (the runtime drops rows below 2^-8) */
static double free_w2(const pu_rt *r, uint32_t s) {
    const sn_ihdr *h = pu_h(r);
    const unsigned char *e = h->v.sec[SN_SEC_EMBED] + (size_t)s * SN_ELEM_EMBED;
    const unsigned char *cl = h->v.sec[SN_SEC_CELLS] + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
    double t[3], w2 = 0;
    uint32_t k;
    for (k = 0; k < 3; k++) t[k] = sn_rd_u16(e + 2 + 2 * k) / 32768.0;
    for (k = 0; k < 8; k++) {
        double w = ((k & 1) ? t[0] : 1 - t[0]) * ((k >> 1 & 1) ? t[1] : 1 - t[1]) * ((k >> 2 & 1) ? t[2] : 1 - t[2]);
        if (sn_rd_u16(cl + 2 * k) < h->v.nF) w2 += w * w;
    }
    return w2;
}
/* the n-th surface vertex (in a scrambled order) whose cell is mostly free (row length^2 >= 1/4) */
static uint32_t free_vertex(const pu_rt *r, uint32_t n) {
    uint32_t i, ns = r->info.surface_vertices, found = 0;
    for (i = 0; i < ns; i++) {
        uint32_t s = (uint32_t)(((uint64_t)i * 7919u + 13u) % ns);
        if (free_w2(r, s) >= 0.25 && found++ == n) return s;
    }
    return 0;
}

static void surf_of(const pu_rt *r, uint32_t s, double out[3]) {
    sn_vec3 v;
    sn_get_surface(r->inst, &v, s, 1);
    out[0] = pu_len(v.x); out[1] = pu_len(v.y); out[2] = pu_len(v.z);
}

static int open_cow(pu_rt *r) {
    char path[512];
    pu_example(path, sizeof path, "cow" PU_BLOB_SUFFIX);
    return pu_rt_open(r, path);
}
static int open_cow_ref(snref_model *m, snref_state *s) {
    char path[512];
    pu_example(path, sizeof path, "cow" PU_BLOB_SUFFIX);
    return pu_ref_open(m, s, path);
}

/* 1. pins hold */
static void test_pins(void) {
    pu_rt r;
    sn_xform pose[64];
    sn_constraint cs[8];
    uint32_t i, step, ns, kept = 0, rows_total = 0;
    double worst = 0, worst_pos = 0;
    sn_stats st;
    if (open_cow(&r)) { T_CHECK(0, "cow blob"); return; }
    T_CHECK(r.info.max_constraints == 32 && r.info.max_colliders == 4 && r.info.max_contacts == 96 && r.info.max_rows == 192,
            "cow bakes 32 constraints, 4 colliders, 96 contacts, 192 rows (got %u %u %u %u)", r.info.max_constraints,
            r.info.max_colliders, r.info.max_contacts, r.info.max_rows);
    pu_identity(pose, r.info.joints);
    sn_set_pose(r.inst, pose, r.info.joints);
    for (step = 0; step < 30; step++) sn_step(r.inst);
    ns = r.info.surface_vertices;
    (void)ns;
    memset(cs, 0, sizeof cs);
    for (i = 0; i < 8; i++) {
        double p[3];
        uint32_t s = free_vertex(&r, 5 * i);
        surf_of(&r, s, p);
        cs[i].at = SN_AT_SURFACE;
        cs[i].vertex = s;
        cs[i].axes = i == 5 ? SN_AXIS_DIR : (i == 6 ? SN_AXIS_Y : 0);
        cs[i].dir.x = rl(1.0); cs[i].dir.y = rl(1.0); cs[i].dir.z = rl(0.0);
        cs[i].target.x = rl(p[0] + 0.05);
        cs[i].target.y = rl(p[1] + 0.1);
        cs[i].target.z = rl(p[2] - 0.05);
    }
    T_CHECK(sn_set_constraints(r.inst, cs, 8) == SN_OK, "8 constraints set");
    for (step = 0; step < 40; step++) {
        double w;
        uint32_t kp;
        sn_step(r.inst);
        w = pu_row_residual(&r, PU_ANY_PRODUCER, &kp);
        worst = w > worst ? w : worst;
        kept = kp;
        rows_total = pu_h(&r)->n_rows;
        if (step >= 1)
            for (i = 0; i < 8; i++) {
                double p[3], d;
                surf_of(&r, cs[i].vertex, p);
                if (cs[i].axes == SN_AXIS_DIR) d = fabs((p[0] - pu_len(cs[i].target.x)) + (p[1] - pu_len(cs[i].target.y))) / sqrt(2.0);
                else if (cs[i].axes == SN_AXIS_Y) d = fabs(p[1] - pu_len(cs[i].target.y));
                else d = fmax(fabs(p[0] - pu_len(cs[i].target.x)), fmax(fabs(p[1] - pu_len(cs[i].target.y)), fabs(p[2] - pu_len(cs[i].target.z))));
                if (kept == rows_total && d > worst_pos) worst_pos = d;
            }
    }
    sn_get_stats(r.inst, &st);
    T_FIGURE("pins: %u rows, %u kept, %u dropped since reset; worst row residual %.3g %s; worst pinned-point error %.3g mesh units",
             rows_total, kept, st.constraint_drops, worst, PU_FLAVOUR_NAME[1] == 'l' ? "(relative)" : "LSB of Q22", worst_pos);
    T_CHECK(rows_total == 3 * 6 + 1 + 1, "rows: 6 full pins x 3, one along a direction, one along y (%u)", rows_total);
#if defined(SN_FLOAT)
    T_CHECK(worst <= 1e-6, "every kept row holds: |C^T v - a| %.3g <= 1e-6 of its scale", worst);
#else
    T_CHECK(worst <= 1.0, "every kept row holds: |C^T v - a| %.3g <= 1 LSB (Q22)", worst);
#endif
    /* a kept pin is at its target: the row's error (above) plus the Q16.16 output and the unit's rounding */
    T_CHECK(kept < rows_total || worst_pos <= 1e-4, "pinned points at their targets within 1e-4 mesh units (%.3g)", worst_pos);
    T_CHECK(st.saturations == 0 && pu_finite_state(&r), "no saturation (%u), state finite", st.saturations);
    /* clearing: count 0 */
    T_CHECK(sn_set_constraints(r.inst, NULL, 0) == SN_OK, "constraints cleared");
    sn_step(r.inst);
    T_CHECK(pu_h(&r)->n_rows == 0 && pu_h(&r)->rows_kept == 0, "no rows after clearing");
    pu_rt_close(&r);
}

/* reference rows for a surface vertex pinned to T (mesh units), from the
 * reference's state before its step (positions p: internal units, world) */
static unsigned ref_rows_for(const snref_state *s, uint32_t sv, const double T[3], uint32_t axes, snref_row *out) {
    const snref_model *m = s->m;
    const unsigned *cell = m->cells + 8 * m->ecell[sv];
    const double *t = m->et + 3 * sv;
    double P[3] = {0, 0, 0}, w[8];
    unsigned k, c, n = 0;
    for (k = 0; k < 8; k++) {
        w[k] = ((k & 1) ? t[0] : 1 - t[0]) * ((k >> 1 & 1) ? t[1] : 1 - t[1]) * ((k >> 2 & 1) ? t[2] : 1 - t[2]);
        for (c = 0; c < 3; c++) P[c] += w[k] * s->p[3 * cell[k] + c];
    }
    for (c = 0; c < 3; c++) {
        if (!(axes & (1u << c))) continue;
        memset(out + n, 0, sizeof *out);
        out[n].n = 8;
        for (k = 0; k < 8; k++) { out[n].vtx[k] = cell[k]; out[n].w[k] = w[k]; }
        out[n].dir[c] = 1;
        out[n].target = T[c] / m->unit - P[c];
        n++;
    }
    return n;
}

/* 2. against the double reference's constrained solve */
static void test_reference(void) {
    pu_rt r;
    snref_model m;
    snref_state s;
    sn_xform pose[64];
    snref_xform rpose[64];
    sn_constraint cs[6];
    snref_row rows[18];
    double T[6][3], *a, *b, *start, err = 0, disp = 0;
    uint32_t i, step, ns;
    if (open_cow(&r) || open_cow_ref(&m, &s)) { T_CHECK(0, "cow blob and reference"); return; }
    s.iters = r.info.cg_iters_default;
    ns = r.info.surface_vertices;
    pu_identity(pose, r.info.joints);
    pu_pose_to_ref(pose, r.info.joints, rpose);
    sn_set_pose(r.inst, pose, r.info.joints);
    snref_set_pose(&s, rpose);
    a = malloc(3 * ns * sizeof *a);
    b = malloc(3 * ns * sizeof *b);
    start = malloc(3 * ns * sizeof *start);
    memset(cs, 0, sizeof cs);
    pu_rt_surface(&r, start); /* the rest surface: displacements as test_physics_runtime measures them */
    for (step = 0; step < 60; step++) {
        if (step == 20) { /* pins: 6 surface points pulled 0.15 mesh units up and sideways */
            pu_rt_surface(&r, a);
            for (i = 0; i < 6; i++) {
                uint32_t sv = free_vertex(&r, 11 * i + 3);
                cs[i].at = SN_AT_SURFACE;
                cs[i].vertex = sv;
                T[i][0] = a[3 * sv] + 0.1;
                T[i][1] = a[3 * sv + 1] + 0.15;
                T[i][2] = a[3 * sv + 2];
                cs[i].target.x = rl(T[i][0]); cs[i].target.y = rl(T[i][1]); cs[i].target.z = rl(T[i][2]);
                /* the reference pins the same target as the runtime reads it back */
                T[i][0] = pu_len(cs[i].target.x); T[i][1] = pu_len(cs[i].target.y); T[i][2] = pu_len(cs[i].target.z);
            }
            sn_set_constraints(r.inst, cs, 6);
        }
        if (step >= 20) {
            unsigned n = 0;
            for (i = 0; i < 6; i++) n += ref_rows_for(&s, cs[i].vertex, T[i], 7, rows + n);
            s.rows = rows;
            s.nrows = n;
        }
        sn_step(r.inst);
        snref_step(&s);
    }
    pu_rt_surface(&r, a);
    snref_get_surface(&s, b);
    for (i = 0; i < 3 * ns; i += 3) {
        double d = sqrt((a[i] - b[i]) * (a[i] - b[i]) + (a[i + 1] - b[i + 1]) * (a[i + 1] - b[i + 1]) + (a[i + 2] - b[i + 2]) * (a[i + 2] - b[i + 2]));
        double e = sqrt((b[i] - start[i]) * (b[i] - start[i]) + (b[i + 1] - start[i + 1]) * (b[i + 1] - start[i + 1]) +
                        (b[i + 2] - start[i + 2]) * (b[i + 2] - start[i + 2]));
        err = d > err ? d : err;
        disp = e > disp ? e : disp;
    }
    T_FIGURE("constrained cow, 40 steps with 6 pins: runtime vs double reference %.3g mesh units, largest displacement %.3g (%.3g%%); reference kept %u of %u rows, runtime %u",
             err, disp, 100 * err / disp, s.rows_kept, s.nrows, pu_h(&r)->rows_kept);
    T_CHECK(s.rows_kept == pu_h(&r)->rows_kept, "runtime and reference keep the same rows (%u, %u)", pu_h(&r)->rows_kept, s.rows_kept);
    T_CHECK(err <= GOAL * disp, "runtime within %.2g%% of the largest displacement of the reference's constrained solve (%.3g%%)",
            100 * GOAL, 100 * err / disp);
    free(a); free(b); free(start);
    snref_release(&s);
    snref_free(&m);
    pu_rt_close(&r);
}

/* 3. duplicates, conflicts, same cell: dropped deterministically */
static void test_drops(void) {
    pu_rt r, r2;
    sn_xform pose[64];
    sn_constraint cs[6];
    sn_stats st;
    double p[3], worst;
    uint32_t kept, s0 = 1000;
    if (open_cow(&r) || open_cow(&r2)) { T_CHECK(0, "cow blob"); return; }
    pu_identity(pose, r.info.joints);
    sn_set_pose(r.inst, pose, r.info.joints);
    sn_set_pose(r2.inst, pose, r2.info.joints);
    sn_step(r.inst);
    sn_step(r2.inst);
    surf_of(&r, s0, p);
    memset(cs, 0, sizeof cs);
    cs[0].at = SN_AT_SURFACE; cs[0].vertex = s0;
    cs[0].target.x = rl(p[0]); cs[0].target.y = rl(p[1] + 0.05); cs[0].target.z = rl(p[2]);
    cs[1] = cs[0];                                    /* duplicate: 3 rows dropped */
    cs[2] = cs[0]; cs[2].target.y = rl(p[1] - 0.3); /* conflicting: 3 rows dropped */
    cs[3] = cs[0]; cs[3].axes = SN_AXIS_DIR;         /* along (1,1,0): in the span of the first pin's x and y rows */
    cs[3].dir.x = rl(1); cs[3].dir.y = rl(1);
    cs[4].at = SN_AT_SURFACE; cs[4].vertex = s0 + 1; /* a neighbour: most likely in the same cell */
    surf_of(&r, s0 + 1, p);
    cs[4].target.x = rl(p[0]); cs[4].target.y = rl(p[1]); cs[4].target.z = rl(p[2]);
    T_CHECK(sn_set_constraints(r.inst, cs, 5) == SN_OK && sn_set_constraints(r2.inst, cs, 5) == SN_OK, "5 constraints set");
    sn_step(r.inst);
    sn_step(r2.inst);
    sn_get_stats(r.inst, &st);
    worst = pu_row_residual(&r, PU_ANY_PRODUCER, &kept);
    T_FIGURE("drops: %u rows, %u kept, %u dropped (duplicate 3, conflicting 3, dependent direction 1, neighbour %u)", pu_h(&r)->n_rows,
             st.constraint_rows, st.constraint_drops, st.constraint_drops - 7);
    T_CHECK(pu_h(&r)->n_rows == 13 && st.constraint_drops >= 7 && st.constraint_rows == 13 - st.constraint_drops,
            "duplicate, conflicting and dependent rows dropped and counted (%u dropped of %u)", st.constraint_drops, pu_h(&r)->n_rows);
    T_CHECK(CARR(pu_h(&r), o_rx, sn_rowx)[0].inv != 0 && CARR(pu_h(&r), o_rx, sn_rowx)[3].inv == 0 && CARR(pu_h(&r), o_rx, sn_rowx)[6].inv == 0,
            "the first of equal rows is kept, later ones dropped (list order)");
    T_CHECK(worst <= SN_FLOAT_OR(1e-6, 1.0), "the kept rows hold (%.3g)", worst);
    T_CHECK(pu_finite_state(&r) && st.saturations == 0, "state finite, no saturation");
    T_CHECK(sn_state_hash(r.inst) == sn_state_hash(r2.inst), "same list, same state hash");
    pu_rt_close(&r);
    pu_rt_close(&r2);
}

/* lowest surface y; flesh = 1: only over the vertices the flesh carries
 * (row length^2 >= 2^-8: a vertex whose cell is almost all skeleton moves
 * with the bones, and no constraint can hold it) */
static double min_y(const pu_rt *r, double *buf, uint32_t *at, int flesh) {
    uint32_t i, ns = r->info.surface_vertices;
    double y = 1e30;
    pu_rt_surface(r, buf);
    for (i = 0; i < ns; i++)
        if (buf[3 * i + 1] < y && (!flesh || free_w2(r, i) >= 1.0 / 256)) { y = buf[3 * i + 1]; if (at) *at = i; }
    return y;
}

static int load_clip_in(sn_clip *clip, const sn_blob *blob, const char *dir, const char *name) {
    char path[512], err[256];
    size_t n;
    char *text;
    snprintf(path, sizeof path, "tools/examples/%s/%s.clip", dir, name);
    text = pu_read(path, &n);
    if (!text) return -1;
    if (sn_clip_parse(clip, text, n, err, sizeof err) || sn_clip_bind(clip, blob, err, sizeof err)) { printf("  %s: %s\n", path, err); free(text); return -1; }
    free(text);
    return 0;
}

static int load_clip(sn_clip *clip, const sn_blob *blob, const char *name) { return load_clip_in(clip, blob, "cow", name); }

/* 4. ground under the trot; resting energy; a sphere in the belly */
static void test_ground(void) {
    static sn_clip clip;
    pu_rt r, f;
    sn_quat local[64];
    sn_xform pose[64];
    sn_collider g;
    sn_stats st;
    double *buf, y0, ground, below = 0, below_free = 0, below_all = 0, e_first = 0, e_last = 0, e_max = 0;
    uint32_t step, ns, low = 0, contacts_max = 0, deep = 0;
    if (open_cow(&r) || open_cow(&f)) { T_CHECK(0, "cow blob"); return; }
    if (load_clip(&clip, r.blob, "trot")) { T_CHECK(0, "trot clip"); return; }
    ns = r.info.surface_vertices;
    buf = malloc(3 * ns * sizeof *buf);
    pu_identity(pose, r.info.joints);
    sn_set_pose(r.inst, pose, r.info.joints);
    sn_step(r.inst);
    y0 = min_y(&r, buf, &low, 0);
    ground = y0 + 0.05; /* the hooves reach 0.05 mesh units below it at rest: the ground must hold them up */
    memset(&g, 0, sizeof g);
    g.kind = SN_COLLIDER_PLANE;
    g.a.y = rl(ground);
    g.b.y = rl(1);
    sn_reset(r.inst);
    sn_reset(f.inst);
    T_CHECK(sn_set_colliders(r.inst, &g, 1) == SN_OK, "ground plane set (after the reset: a reset clears colliders)");
    for (step = 0; step < 216; step++) { /* the trot clip: 3.6 s at 60 Hz */
        double y;
        sn_clip_pose(&clip, r.blob, step, local, pose);
        sn_set_pose(r.inst, pose, r.info.joints);
        sn_set_pose(f.inst, pose, f.info.joints);
        sn_clip_controls(&clip, r.blob, step, r.inst);
        sn_clip_controls(&clip, f.blob, step, f.inst);
        sn_step(r.inst);
        sn_step(f.inst);
        sn_get_stats(r.inst, &st);
        contacts_max = st.contacts > contacts_max ? st.contacts : contacts_max;
        if (step >= 2) {
            uint32_t at = 0;
            y = min_y(&r, buf, &at, 1);
            if (ground - y > below) { below = ground - y; deep = at; }
            y = min_y(&r, buf, NULL, 0);
            below_all = ground - y > below_all ? ground - y : below_all;
            y = min_y(&f, buf, NULL, 1);
            below_free = ground - y > below_free ? ground - y : below_free;
        }
    }
    sn_get_stats(r.inst, &st);
    /* depth: one step's gravity increment plus what a cell's trilinear field
     * lets the other surface vertices of a contact's cell go below its
     * deepest one while the skeleton swings the hooves (stated: 0.05 mesh
     * units = 1/24 cell, the hooves' own sink without the ground) */
    T_FIGURE("trot on a ground plane 0.05 above the resting hooves: deepest flesh-carried surface vertex %.4g below it (vertex %u; without the ground %.4g); bone-carried vertices (cell free weight^2 < 2^-8) down to %.4g; up to %u contacts a step, %u overflow, %u drops",
             below, deep, below_free, below_all, contacts_max, st.contact_overflow, st.constraint_drops);
    /* stated depth: 1/40 cell (0.03 mesh units): a vertex sharing a cell
     * with the cell's deepest contact follows the cell's trilinear field,
     * which the skeleton corners of hoof cells turn with the leg */
    T_CHECK(below <= 0.03, "no flesh-carried surface vertex more than 0.03 mesh units below the ground during the trot (%.4g)", below);
    T_CHECK(below < 0.5 * below_free, "the ground holds the flesh up (%.4g without it)", below_free);
    T_CHECK(st.saturations == 0 && pu_finite_state(&r), "no saturation, state finite");
    /* resting on the plane: energy does not grow */
    sn_reset(r.inst);
    sn_set_colliders(r.inst, &g, 1);
    pu_identity(pose, r.info.joints);
    sn_set_pose(r.inst, pose, r.info.joints);
    for (step = 0; step < 300; step++) {
        double e;
        sn_step(r.inst);
        sn_get_stats(r.inst, &st);
        e = pu_len(st.energy);
        if (step == 100) e_first = e;
        if (step > 100) e_max = e > e_max ? e : e_max;
        e_last = e;
    }
    /* after 100 steps of settling, energy stays within 1% of its level
     * (the health energy: elastic + kinetic, Q16.16 J) */
    T_FIGURE("resting on the ground: energy %.5g J at step 100, %.5g J at step 300, largest after step 100 %.5g J", e_first, e_last, e_max);
    T_CHECK(e_max <= e_first * 1.01 + 1e-4, "resting energy does not grow (%.5g -> max %.5g J)", e_first, e_max);
    free(buf);
    pu_rt_close(&r);
    pu_rt_close(&f);
}

static void test_sphere(void) {
    pu_rt r;
    sn_xform pose[64];
    sn_collider c;
    double *buf, worst = 0, cx, cy, cz, rad = 1.0, ybelly = 1e30;
    uint32_t step, i, ns, deep = 0;
    sn_stats st;
    if (open_cow(&r)) { T_CHECK(0, "cow blob"); return; }
    ns = r.info.surface_vertices;
    buf = malloc(3 * ns * sizeof *buf);
    pu_identity(pose, r.info.joints);
    sn_set_pose(r.inst, pose, r.info.joints);
    sn_step(r.inst);
    pu_rt_surface(&r, buf);
    /* the belly: the lowest surface point within 0.5 of x = 0, z = 0 */
    cx = 1.0; cz = 0; /* the belly between the legs (cow.obj: lowest at x = 1, y = -1.55) */
    for (i = 0; i < ns; i++)
        if (fabs(buf[3 * i] - cx) < 0.5 && fabs(buf[3 * i + 2]) < 0.5 && buf[3 * i + 1] < ybelly) ybelly = buf[3 * i + 1];
    memset(&c, 0, sizeof c);
    c.kind = SN_COLLIDER_SPHERE;
    c.radius = rl(rad);
    for (step = 0; step < 120; step++) { /* the sphere rises 0.3 mesh units into the belly over 60 steps, then holds */
        double d = step < 60 ? 0.3 * step / 60.0 : 0.3;
        cy = ybelly - rad + d;
        c.a.x = rl(cx); c.a.y = rl(cy); c.a.z = rl(cz);
        c.velocity.y = step < 60 ? rl(0.3 / 60.0 / (1.0 / 60.0)) : 0;
        sn_set_colliders(r.inst, &c, 1);
        sn_step(r.inst);
        if (step >= 2) {
            pu_rt_surface(&r, buf);
            for (i = 0; i < ns; i++) {
                double dx = buf[3 * i] - cx, dy = buf[3 * i + 1] - cy, dz = buf[3 * i + 2] - cz;
                double in = rad - sqrt(dx * dx + dy * dy + dz * dz);
                if (in > worst && free_w2(&r, i) >= 1.0 / 256) { worst = in; deep = i; }
            }
        }
    }
    sn_get_stats(r.inst, &st);
    T_FIGURE("sphere r=1 pressed 0.3 into the belly (at y %.3g): deepest flesh-carried surface vertex %.4g inside (vertex %u, free weight^2 %.3g); %u contacts in the last step, %u overflow, %u drops",
             ybelly, worst, deep, free_w2(&r, deep), st.contacts, st.contact_overflow, st.constraint_drops);
    /* stated depth: a vertex sharing a cell with the cell's deepest contact,
     * on a sphere of radius 1 over a cell of 1.2: 0.08 mesh units */
    /* stated depth: one contact per (collider, cell) holds the cell's
     * deepest vertex on the sphere; the cell's other vertices move with the
     * cell's trilinear field, which cannot bend to the sphere within the
     * cell: a vertex up to half a cell (0.6) from the contact can be inside
     * by the sphere's sagitta there, r - sqrt(r^2 - 0.6^2) = 0.2 for r = 1 */
    T_CHECK(worst <= 0.2, "no flesh-carried surface vertex more than the sagitta over half a cell (0.2) inside the sphere (%.4g)", worst);
    T_CHECK(st.contacts > 0 && st.saturations == 0 && pu_finite_state(&r), "contacts active, no saturation, state finite");
    free(buf);
    pu_rt_close(&r);
}


/* 4c. the beast (tools/examples/beast: upright, 32k surface vertices, cell
 * 24 cm, feet mostly bone) on a ground plane while it walks and while it
 * thrashes (violent.clip): the contacts yield to the bones (NUMERICS.md
 * "Contacts": a row asks of its cell's free corners at most a velocity
 * change of cell/2 and an end point cell/2 beyond their skinned place),
 * so nothing diverges whatever the clip drives through the plane. Model
 * space is relative to the root joint: the soles rest at y = -130.9. */
typedef struct beast_run { double below, below_free; uint32_t sat, bound_steps, contacts_max; int finite; double e_max, disp_max; } beast_run;
static void beast_go(pu_rt *r, const sn_clip *clip, uint32_t steps, int have_plane, double gy, double *buf, beast_run *o) {
    sn_quat local[64];
    sn_xform pose[64];
    sn_collider g;
    sn_stats st;
    uint32_t step, i, ns = r->info.surface_vertices;
    memset(o, 0, sizeof *o);
    sn_reset(r->inst);
    memset(&g, 0, sizeof g);
    g.kind = SN_COLLIDER_PLANE;
    g.a.y = rl(gy);
    g.b.y = rl(1);
    if (have_plane) sn_set_colliders(r->inst, &g, 1);
    for (step = 0; step < steps; step++) {
        sn_clip_pose(clip, r->blob, step, local, pose);
        sn_set_pose(r->inst, pose, r->info.joints);
        sn_clip_controls(clip, r->blob, step, r->inst);
        sn_step(r->inst);
        sn_get_stats(r->inst, &st);
        o->contacts_max = st.contacts > o->contacts_max ? st.contacts : o->contacts_max;
        if (step >= 2 && step % 4 == 0) {
            pu_rt_surface(r, buf);
            for (i = 0; i < ns; i++) {
                double d = gy - buf[3 * i + 1], w2;
                if (d <= o->below_free) continue;
                w2 = free_w2(r, i);
                if (w2 >= 1.0 / 256 && d > o->below) o->below = d;
                if (w2 >= 0.25) o->below_free = d;
            }
        }
    }
    sn_get_stats(r->inst, &st);
    o->sat = st.saturations;
    o->bound_steps = st.bound_steps;
    o->finite = pu_finite_state(r);
    o->e_max = pu_len(st.energy_max);
    o->disp_max = pu_len(st.disp_max);
}
/* The beast at rest, for 4c and 4d: its blob opened, the identity pose set
 * and stepped once, the surface (3 ns) in *buf (malloc'd, the caller frees
 * it). Returns 0, or -1 (checked as failed) without the blob. */
static int beast_open(pu_rt *r, sn_xform pose[64], double **buf) {
    char path[512];
    pu_example(path, sizeof path, "beast" PU_BLOB_SUFFIX);
    if (pu_rt_open(r, path)) { T_CHECK(0, "beast blob"); return -1; }
    *buf = malloc(3 * r->info.surface_vertices * sizeof **buf);
    pu_identity(pose, r->info.joints);
    sn_set_pose(r->inst, pose, r->info.joints);
    sn_step(r->inst);
    pu_rt_surface(r, *buf);
    return 0;
}
static void test_beast(void) {
    static sn_clip clip;
    static const char *clips[2] = {"walk", "violent"};
    pu_rt r;
    double *buf, y0 = 1e30;
    uint32_t i, c, ns;
    sn_xform pose[64];
    if (beast_open(&r, pose, &buf)) return;
    ns = r.info.surface_vertices;
    for (i = 0; i < ns; i++) y0 = buf[3 * i + 1] < y0 ? buf[3 * i + 1] : y0; /* the soles at rest */
    for (c = 0; c < 2; c++) {
        beast_run none, sole, above, hips;
        uint32_t steps = c == 0 ? 216 : 240; /* the walk's 3.6 s; 4 s of the violent clip */
        if (load_clip_in(&clip, r.blob, "beast", clips[c])) { T_CHECK(0, "beast clip %s", clips[c]); continue; }
        beast_go(&r, &clip, steps, 0, y0 + 0.07, buf, &none);
        beast_go(&r, &clip, steps, 1, y0 + 0.07, buf, &sole);
        beast_go(&r, &clip, steps, 1, y0 + 2.0, buf, &above);
        beast_go(&r, &clip, steps, 1, 0.0, buf, &hips); /* a plane through the hips: the clip drives half the body through it */
        T_FIGURE("beast %s, %u steps, soles at y %.2f: without plane %u saturations, %u bound steps, largest energy %.4g J, disp %.3g cells; "
                 "plane 0.07 above the soles: %u sat, %u bound steps, %.4g J, flesh-carried vertices down to %.3g below it (mostly free cells %.3g; "
                 "without the plane %.3g), up to %u contacts; 2 above: %u sat, %u bound steps, %.4g J, down to %.3g (%.3g); "
                 "through the hips (y = 0): %u sat, %u bound steps, %.4g J, disp %.3g cells",
                 clips[c], steps, y0, none.sat, none.bound_steps, none.e_max, none.disp_max, sole.sat, sole.bound_steps, sole.e_max, sole.below,
                 sole.below_free, none.below, sole.contacts_max, above.sat, above.bound_steps, above.e_max, above.below, above.below_free,
                 hips.sat, hips.bound_steps, hips.e_max, hips.disp_max);
        T_CHECK(none.finite && sole.finite && above.finite && hips.finite, "beast %s: every state finite", clips[c]);
        T_CHECK(sole.sat == 0 && above.sat == 0 && hips.sat == 0, "beast %s on a plane: no saturation (%u, %u, %u)", clips[c], sole.sat,
                above.sat, hips.sat);
        T_CHECK(sole.bound_steps <= none.bound_steps && above.bound_steps <= none.bound_steps,
                "beast %s on the ground: health bound steps not above the run without it (%u, %u vs %u)", clips[c], sole.bound_steps,
                above.bound_steps, none.bound_steps);
        /* energy: the ground adds at most 25% to the largest energy (the push-out work) */
        T_CHECK(sole.e_max <= 1.25 * none.e_max && above.e_max <= 1.25 * none.e_max,
                "beast %s on the ground: largest energy %.4g / %.4g J within 25%% of %.4g J without", clips[c], sole.e_max, above.e_max, none.e_max);
        /* plane through the hips: bounded, not comfortable (before the
         * yield bound: 491 saturations, energy at the 32768 J clamp, 34.6
         * cells): energy within 16x, displacement within 12 cells */
        T_CHECK(hips.e_max <= 16.0 * none.e_max && hips.disp_max <= 12.0,
                "beast %s through a plane at its hips: largest energy %.4g J (<= 16 x %.4g), disp %.3g cells (<= 12)", clips[c], hips.e_max,
                none.e_max, hips.disp_max);
        /* penetration: vertices of mostly free cells (free weight^2 >= 1/4)
         * at most cell/8 (3) below the ground. Vertices of cells the feet's
         * bones dominate yield to the bones by design (figure above) */
        T_CHECK(sole.below_free <= 3.0 && above.below_free <= 3.0,
                "beast %s: vertices of mostly free cells at most 3 (cell/8) below the ground (%.3g, %.3g)", clips[c], sole.below_free,
                above.below_free);
    }
    free(buf);
    pu_rt_close(&r);
}

/* 4d. a sphere pressed into the beast's belly (beast.sinew's belly region:
 * mesh x -24..24, y 128..168, z -2..24; model space = mesh - (0, 130, -6),
 * facing +z): the front of the belly, radius 15, pushed 6 cm in over 60
 * steps, held 60 */
static void test_beast_sphere(void) {
    pu_rt r;
    sn_xform pose[64];
    sn_collider c;
    sn_stats st;
    double *buf, bx = 0, by = 18, bz = -1e30, rad = 15.0, worst = 0;
    uint32_t i, ns, step;
    if (beast_open(&r, pose, &buf)) return;
    ns = r.info.surface_vertices;
    for (i = 0; i < ns; i++) /* the belly's front: the largest z within 4 of x = 0, y = 18 (mesh y 148) */
        if (fabs(buf[3 * i]) < 4 && fabs(buf[3 * i + 1] - by) < 4 && buf[3 * i + 2] > bz) bz = buf[3 * i + 2];
    sn_reset(r.inst);
    memset(&c, 0, sizeof c);
    c.kind = SN_COLLIDER_SPHERE;
    c.radius = rl(rad);
    for (step = 0; step < 120; step++) {
        double d = step < 60 ? 6.0 * step / 60.0 : 6.0, cz = bz + rad - d;
        sn_set_pose(r.inst, pose, r.info.joints);
        c.a.x = rl(bx); c.a.y = rl(by); c.a.z = rl(cz);
        c.velocity.z = step < 60 ? rl(-6.0) : 0; /* 6 cm/s for 1 s */
        sn_set_colliders(r.inst, &c, 1);
        sn_step(r.inst);
        if (step >= 2) {
            pu_rt_surface(&r, buf);
            for (i = 0; i < ns; i++) {
                double dx = buf[3 * i] - bx, dy = buf[3 * i + 1] - by, dz = buf[3 * i + 2] - cz;
                double in = rad - sqrt(dx * dx + dy * dy + dz * dz);
                if (in > worst && free_w2(&r, i) >= 1.0 / 256) worst = in;
            }
        }
    }
    sn_get_stats(r.inst, &st);
    T_FIGURE("beast: sphere r=15 pressed 6 into the belly's front (z %.3g): deepest flesh-carried vertex %.3g inside; largest displacement %.3g cells, energy %.4g J; %u contacts in the last step, %u saturations",
             bz, worst, pu_len(st.disp_max), pu_len(st.energy_max), st.contacts, st.saturations);
    T_CHECK(bz > 10 && bz < 60, "belly found at the front (z %.3g)", bz);
    T_CHECK(st.contacts > 0 && st.saturations == 0 && pu_finite_state(&r), "contacts active, no saturation, state finite");
    /* bounded deformation: the press is 6 = cell/4; the flesh moves at most
     * the yield bound (cell/2 beyond its skinned place) plus the solve's own */
    T_CHECK(pu_len(st.disp_max) <= 1.5, "largest displacement from the skinned place at most 1.5 cells, the walk's own (%.3g)", pu_len(st.disp_max));
    /* sagitta over half a cell (12) on r = 15: 15 - 9 = 6: a vertex beside the cell's contact can be that deep */
    T_CHECK(worst <= 6.0, "no flesh-carried vertex more than the sagitta over half a cell (6) inside (%.3g)", worst);
    free(buf);
    pu_rt_close(&r);
}

/* the step's rows after sn_step (white box; SN_TRACE_FRICTION=1): normal
 * contacts, stick and slide rows (friction rows: two-sided contact rows;
 * stick: two rows on one contact), how many the drop rule removed of each,
 * and the smallest relative pivot L_jj^2 / G_jj among the kept rows */
typedef struct fr_rows { uint32_t normal, tang, drop_normal, drop_tang; double min_piv; } fr_rows;
static fr_rows friction_rows_of(const pu_rt *r) {
    sn_ihdr *h = pu_h(r);
    const sn_row *rows = sn_rows(h);
    const sn_rowx *rx = CARR(h, o_rx, sn_rowx);
    const sn_q *L = CARR(h, o_L, sn_q);
    fr_rows o;
    uint32_t j, k;
    memset(&o, 0, sizeof o);
    o.min_piv = 1;
    for (j = 0; j < h->n_rows; j++) {
        int tang = SN_ROW_PRODUCER(rows[j].source) == SN_SRC_CONTACT && !rows[j].one_sided;
        double l;
        if (tang) o.tang++; else o.normal++;
        if (rx[j].inv == 0) { if (tang) o.drop_tang++; else o.drop_normal++; continue; }
#if defined(SN_FLOAT)
        l = L[(size_t)j * (j + 1u) / 2u + j];
#else
        l = ldexp((double)L[(size_t)j * (j + 1u) / 2u + j], -28);
#endif
        {
            double gw = 0;
            for (k = 0; k < rows[j].n; k++)
                if (rows[j].vtx[k] < h->v.nF) {
#if defined(SN_FLOAT)
                    double w = rows[j].w[k];
#else
                    double w = ldexp((double)rows[j].w[k], -30);
#endif
                    gw += w * w;
                }
            if (gw > 0 && l * l / gw < o.min_piv) o.min_piv = l * l / gw;
        }
    }
    return o;
}

/* the free corners of surface vertex s's cell (SN_TRACE_FRICTION=1): their
 * weight phi, velocity of the last step along z and displacement from the
 * skinned place (y, z), internal units */
static void trace_corners(const pu_rt *r, uint32_t s) {
    sn_ihdr *h = pu_h(r);
    const unsigned char *e = h->v.sec[SN_SEC_EMBED] + (size_t)s * SN_ELEM_EMBED;
    const unsigned char *cl = h->v.sec[SN_SEC_CELLS] + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
    const sn_q *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q);
    double t[3];
    uint32_t k, q, sat = 0;
    for (k = 0; k < 3; k++) t[k] = sn_rd_u16(e + 2 + 2 * k) / 32768.0;
    for (k = 0; k < 8; k++) {
        uint32_t a = sn_rd_u16(cl + 2 * k);
        double w = ((k & 1) ? t[0] : 1 - t[0]) * ((k >> 1 & 1) ? t[1] : 1 - t[1]) * ((k >> 2 & 1) ? t[2] : 1 - t[2]);
        sn_q sk[3];
        if (a >= h->v.nF || w == 0) continue;
        sn_skinned(h, a, sk, &sat);
        printf("      free corner %u phi %.3f: velocity z %+.5f, from its skinned place y %+.4f z %+.4f (cell %.4f)\n", a, w,
               pu_qd(vel[3 * a + 2]), pu_qd(sn_add(pos[3 * a + 1], -sk[1], &sat)), pu_qd(sn_add(pos[3 * a + 2], -sk[2], &sat)), pu_qd((sn_q)h->v.cell));
        (void)q;
    }
}

/* internal length -> mesh units */
static double i2m(const pu_rt *r, sn_q v) {
#if defined(SN_FLOAT)
    return int_to_pub(pu_h(r), v);
#else
    return pu_len((sn_real)int_to_pub64(pu_h(r), v));
#endif
}
/* the free corner of surface vertex s's cell with the largest weight (its
 * weight in *phi), and the sum of the free weights (*wsum) */
static uint32_t dominant_corner(const pu_rt *r, uint32_t s, double *phi, double *wsum) {
    const sn_ihdr *h = pu_h(r);
    const unsigned char *e = h->v.sec[SN_SEC_EMBED] + (size_t)s * SN_ELEM_EMBED;
    const unsigned char *cl = h->v.sec[SN_SEC_CELLS] + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
    double t[3];
    uint32_t k, best = 0;
    *phi = 0; *wsum = 0;
    for (k = 0; k < 3; k++) t[k] = sn_rd_u16(e + 2 + 2 * k) / 32768.0;
    for (k = 0; k < 8; k++) {
        uint32_t a = sn_rd_u16(cl + 2 * k);
        double w = ((k & 1) ? t[0] : 1 - t[0]) * ((k >> 1 & 1) ? t[1] : 1 - t[1]) * ((k >> 2 & 1) ? t[2] : 1 - t[2]);
        if (a >= h->v.nF) continue;
        *wsum += w;
        if (w > *phi) { *phi = w; best = a; }
    }
    return best;
}

/* 4b. friction: a sphere pressed into the flesh along p (depth over 60
 * steps), then dragged a distance D along q over 60 steps, mu 0 and 1; the
 * flesh vertex nearest the sphere's deepest point is measured along q over
 * the last 20 steps. Expectation (NUMERICS.md "Friction under the yield
 * bound"): the point is carried by the bones except through the free
 * corners of its cell; the yield bound lets a free corner go cell/2
 * beyond its skinned place, so a sticking contact can drag the point by at
 * most cap = (sum of its free weights) * cell/2, and a steady drag with
 * mu = 1 is min(D, cap). Measured: the mean over the last 20 steps and the
 * chatter (largest - smallest over them): the mean within 25% of
 * min(D, cap) and the chatter at most cap/2 are goals (the cow meets both
 * in both flavours; the beast's chatter too, its mean is a known miss:
 * it drags 3.95 / 4.07 against 2.72, NUMERICS.md "Friction"). */
typedef struct fr_case {
    const char *name, *blob;
    double c0[3], p[3], q[3], rad, depth, dist;
    int reset; /* the beast: reset after the probe step, the pose set every step */
    double mean_bound; /* > 0: the mean is a known miss, |mean - want| / want at most this */
} fr_case;
static void friction_case(const fr_case *fc) {
    pu_rt r[2];
    sn_xform pose[64];
    double mean[2] = {0, 0}, lo[2] = {0, 0}, hi[2] = {0, 0}, x0[2] = {0, 0}, dev_max[2] = {0, 0}, vmax[2] = {0, 0}, dev0[2] = {0, 0}, res_max = 0;
    double phi = 0, wsum = 0, cell = 0;
    uint32_t contacts[2] = {0, 0}, sat[2] = {0, 0}, tang[2] = {0, 0}, tang_drop[2] = {0, 0};
    int m;
    for (m = 0; m < 2; m++) {
        sn_collider c;
        sn_stats st;
        uint32_t step, s_at = 0, corner = 0, n = 0, q;
        double pt[3], *buf;
        char path[512];
        pu_example(path, sizeof path, fc->blob);
        if (pu_rt_open(&r[m], path)) { T_CHECK(0, "%s blob", fc->name); if (m) pu_rt_close(&r[0]); return; }
        buf = malloc(3 * r[m].info.surface_vertices * sizeof *buf);
        pu_identity(pose, r[m].info.joints);
        sn_set_pose(r[m].inst, pose, r[m].info.joints);
        if (fc->reset) { sn_step(r[m].inst); sn_reset(r[m].inst); }
        memset(&c, 0, sizeof c);
        c.kind = SN_COLLIDER_SPHERE;
        c.radius = rl(fc->rad);
        c.friction = m ? rl(1.0) : 0;
        lo[m] = 1e30; hi[m] = -1e30;
        for (step = 0; step < 120; step++) {
            double press = step < 60 ? fc->depth * step / 60.0 : fc->depth, drag = step < 60 ? 0 : fc->dist * (step - 60) / 60.0, ctr[3], vel[3];
            for (q = 0; q < 3; q++) {
                ctr[q] = fc->c0[q] + fc->p[q] * press + fc->q[q] * drag;
                vel[q] = step < 60 ? fc->p[q] * fc->depth : fc->q[q] * fc->dist; /* per second: 60 steps of 1/60 s */
            }
            if (fc->reset) sn_set_pose(r[m].inst, pose, r[m].info.joints);
            c.a.x = rl(ctr[0]); c.a.y = rl(ctr[1]); c.a.z = rl(ctr[2]);
            c.velocity.x = rl(vel[0]); c.velocity.y = rl(vel[1]); c.velocity.z = rl(vel[2]);
            sn_set_colliders(r[m].inst, &c, 1);
            sn_step(r[m].inst);
            if (step >= 60) { /* the drag: rows, the dominant corner's displacement from its skinned place along q */
                sn_ihdr *h = pu_h(&r[m]);
                const sn_q *pos = CARR(h, o_pos, sn_q), *vl = CARR(h, o_vel, sn_q);
                fr_rows fr = friction_rows_of(&r[m]);
                sn_q sk[3];
                uint32_t sat0 = 0;
                double d = 0, vq = 0, dq;
                sn_skinned(h, corner, sk, &sat0);
                surf_of(&r[m], s_at, pt);
                for (q = 0; q < 3; q++) {
                    d += fc->q[q] * i2m(&r[m], sn_add(pos[3 * corner + q], -sk[q], &sat0));
                    vq += fc->q[q] * i2m(&r[m], vl[3 * corner + q]);
                }
                dq = fc->q[0] * pt[0] + fc->q[1] * pt[1] + fc->q[2] * pt[2] - x0[m];
                if (fabs(d) > dev_max[m]) dev_max[m] = fabs(d);
                if (step == 60) dev0[m] = d;
                {   /* the rows as the yield pass left them (sn_contact_yield retargets the contact rows it moves) */
                    uint32_t kept;
                    double res = pu_row_residual(&r[m], PU_ANY_PRODUCER, &kept);
                    res_max = res > res_max ? res : res_max;
                }
                if (fabs(vq) > vmax[m]) vmax[m] = fabs(vq);
                tang[m] += fr.tang;
                tang_drop[m] += fr.drop_tang;
                if (step >= 100) {
                    mean[m] += dq; n++;
                    if (dq < lo[m]) lo[m] = dq;
                    if (dq > hi[m]) hi[m] = dq;
                }
                if (getenv("SN_TRACE_FRICTION")) {
                    printf("  trace %s mu %d step %3u sphere %.3f  vertex %u %+.4f  rows normal %u (dropped %u) tangent %u (dropped %u) min pivot/G %.3g\n",
                           fc->name, m, step, drag, s_at, dq, fr.normal, fr.drop_normal, fr.tang, fr.drop_tang, fr.min_piv);
                    trace_corners(&r[m], s_at);
                }
            }
            if (step == 59) { /* the flesh vertex nearest the sphere's deepest point */
                double best = 1e30, tip[3];
                uint32_t i;
                for (q = 0; q < 3; q++) tip[q] = ctr[q] + fc->rad * fc->p[q];
                pu_rt_surface(&r[m], buf);
                for (i = 0; i < r[m].info.surface_vertices; i++) {
                    double dx = buf[3 * i] - tip[0], dy = buf[3 * i + 1] - tip[1], dz = buf[3 * i + 2] - tip[2];
                    double dd = dx * dx + dy * dy + dz * dz;
                    if (dd < best && free_w2(&r[m], i) >= 0.05) { best = dd; s_at = i; }
                }
                surf_of(&r[m], s_at, pt);
                x0[m] = fc->q[0] * pt[0] + fc->q[1] * pt[1] + fc->q[2] * pt[2];
                corner = dominant_corner(&r[m], s_at, &phi, &wsum);
                cell = i2m(&r[m], (sn_q)pu_h(&r[m])->v.cell);
            }
        }
        mean[m] /= n ? n : 1;
        sn_get_stats(r[m].inst, &st);
        contacts[m] = st.contacts;
        sat[m] = st.saturations;
        free(buf);
    }
    {
        double cap = wsum * cell / 2, want = cap < fc->dist ? cap : fc->dist;
        T_FIGURE("friction (%s): sphere r=%g pressed %g, dragged %g; the flesh at its tip (free weight %.3f, dominant corner %.3f; cell %.3g): "
                 "yield cap %.3g, expected drag with mu 1 min(%g, cap) = %.3g", fc->name, fc->rad, fc->depth, fc->dist, wsum, phi, cell, cap, fc->dist, want);
        for (m = 0; m < 2; m++)
            T_FIGURE("friction (%s) mu %d: drag over the last 20 steps mean %+.4g, range %+.4g .. %+.4g (chatter %.3g); dominant corner %+.3g cells from its skinned place along the drag when the drag starts, up to %.3g (%.2f cells), "
                     "speed up to %.3g a step (the sphere: %.3g); tangent rows %u, dropped %u; contact rows in the last step %u",
                     fc->name, m, mean[m], lo[m], hi[m], hi[m] - lo[m], dev0[m] / cell, dev_max[m], dev_max[m] / cell, vmax[m], fc->dist / 60, tang[m], tang_drop[m], contacts[m]);
        /* the expectation (mean within 25% of min(D, cap): the cap is the
         * bound's own figure, the corner's offset from its skinned place at
         * the end of the press moves it by up to cap/4; chatter at most
         * cap/2, a quarter of the bound's range over 20 steps) */
        if (fc->mean_bound > 0)
            PU_KNOWN_MISS(fabs(mean[1] - want) / want, 0.25, fc->mean_bound,
                          "the cap ignores the corner's offset when the drag starts; the bound holds a corner where a step starts (NUMERICS.md \"Friction\")",
                          "%s: mu 1 drags the flesh %.4g, min(D, cap) = %.3g", fc->name, mean[1], want);
        else
            PU_GOAL(fabs(mean[1] - want) <= 0.25 * want, "%s: mu 1 drags the flesh min(D, cap) = %.3g within 25%% (%.4g)", fc->name, want, mean[1]);
        PU_GOAL(hi[1] - lo[1] <= cap / 2, "%s: mu 1: chatter over the last 20 steps at most cap/2 = %.3g (%.3g)", fc->name, cap / 2, hi[1] - lo[1]);
    }
    T_FIGURE("%s: worst kept-row residual during the drag %.3g %s", fc->name, res_max, PU_FLAVOUR_NAME[1] == 'l' ? "(relative)" : "LSB of Q22");
    /* the contact rows hold as retargeted by the yield pass: the pins' tolerance (test_pins) */
#if defined(SN_FLOAT)
    T_CHECK(res_max <= 1e-6, "%s: every kept row holds during the drag: |C^T v - a| %.3g <= 1e-6 of its scale", fc->name, res_max);
#else
    T_CHECK(res_max <= 1.0, "%s: every kept row holds during the drag: |C^T v - a| %.3g <= 1 LSB (Q22)", fc->name, res_max);
#endif
    T_CHECK(sat[0] == 0 && pu_finite_state(&r[0]) && pu_finite_state(&r[1]), "%s frictionless: no saturation (%u); both states finite", fc->name, sat[0]);
    /* fixed point: the slide rows of neighbouring cells can be nearly
     * dependent (above the drop rule's 1/16); the projection's block
     * exponent leaves 14 bits of headroom for G^-1's growth (NUMERICS.md),
     * so their multipliers stay within the state range (6 saturations with
     * the former 10 bits) */
    T_CHECK(sat[1] == 0, "%s with friction: no saturation (%u)", fc->name, sat[1]);
    pu_rt_close(&r[0]);
    pu_rt_close(&r[1]);
}
static void test_friction(void) {
    /* the cow: r = 1 under the belly (x 1, lowest at y -1.55), pressed 0.3 up, dragged 0.4 along z */
    static const fr_case cow = {"cow", "cow" PU_BLOB_SUFFIX, {1.0, -2.55, 0.0}, {0, 1, 0}, {0, 0, 1}, 1.0, 0.3, 0.4, 0, 0};
    fr_case beast = {"beast", "beast" PU_BLOB_SUFFIX, {0, 18, 0}, {0, 0, -1}, {1, 0, 0}, 15.0, 6.0, 8.0, 1, 0.6};
    friction_case(&cow);
    {   /* the beast (cell 24): r = 15 at the belly's front (test_beast_sphere), pressed 6 along -z, dragged 8 along x */
        pu_rt r;
        sn_xform pose[64];
        double *buf, bz = -1e30;
        uint32_t i;
        if (beast_open(&r, pose, &buf)) return;
        for (i = 0; i < r.info.surface_vertices; i++)
            if (fabs(buf[3 * i]) < 4 && fabs(buf[3 * i + 1] - 18) < 4 && buf[3 * i + 2] > bz) bz = buf[3 * i + 2];
        free(buf);
        pu_rt_close(&r);
        beast.c0[2] = bz + beast.rad;
        friction_case(&beast);
    }
}

/* 5. every maximum overflowing: counted, finite, deterministic */
static void test_overflow(void) {
    pu_rt r, r2;
    sn_xform pose[64];
    sn_constraint cs[40];
    sn_collider cl[6];
    sn_stats st;
    uint32_t i, step, ns;
    uint64_t h1, h2;
    int pass;
    {   /* the cow with 8 contacts a step (tests/physics.mk bakes it) */
        char path[512];
        snprintf(path, sizeof path, "%s/physics/cow_c8%s.blob", pu_build(), PU_BLOB_SUFFIX);
        if (pu_rt_open(&r, path) || pu_rt_open(&r2, path)) { T_CHECK(0, "cow_c8 blob"); return; }
    }
    ns = r.info.surface_vertices;
    memset(cs, 0, sizeof cs);
    for (i = 0; i < 40; i++) {
        cs[i].at = SN_AT_SURFACE;
        cs[i].vertex = (i * 977u) % ns;
        cs[i].target.y = rl(1000.0); /* far away: approached a cell per step, counted */
    }
    memset(cl, 0, sizeof cl);
    for (i = 0; i < 6; i++) { /* big spheres swallowing the cow: every cell wants a contact */
        cl[i].kind = SN_COLLIDER_SPHERE;
        cl[i].a.x = rl(-3.0 + 1.5 * i);
        cl[i].radius = rl(2.5);
    }
    for (pass = 0; pass < 2; pass++) {
        pu_rt *p = pass ? &r2 : &r;
        pu_identity(pose, p->info.joints);
        sn_set_pose(p->inst, pose, p->info.joints);
        T_CHECK(sn_set_colliders(p->inst, cl, 6) == SN_ERR_FULL, "6 colliders: SN_ERR_FULL, the first 4 set");
        for (step = 0; step < 5; step++) sn_step(p->inst);
        sn_get_stats(p->inst, &st);
        T_CHECK(st.contact_overflow > 0 && st.contacts == p->info.max_contacts, "spheres over the whole cow: %u contacts a step (the maximum), %u more counted",
                st.contacts, st.contact_overflow);
        T_CHECK(sn_set_constraints(p->inst, cs, 40) == SN_ERR_FULL, "40 constraints: SN_ERR_FULL, the first 32 set");
        for (step = 0; step < 20; step++) sn_step(p->inst);
    }
    sn_get_stats(r.inst, &st);
    h1 = sn_state_hash(r.inst);
    h2 = sn_state_hash(r2.inst);
    T_FIGURE("overflow: refused %u, contact overflow %u, row overflow %u, target clamps %u, rows kept %u, drops %u, saturations %u",
             st.constraint_refused, st.contact_overflow, st.row_overflow, st.constraint_clamps, st.constraint_rows,
             st.constraint_drops, st.saturations);
    T_CHECK(st.constraint_refused == 8 + 2, "8 constraints and 2 colliders refused (%u)", st.constraint_refused);
    T_CHECK(st.constraint_clamps > 0, "target clamps counted");
    T_CHECK(pu_finite_state(&r), "state finite");
    T_CHECK(h1 == h2, "deterministic under overflow");
    {   /* the row capacity itself: a producer pushing beyond it is refused and counted */
        sn_ihdr *h = pu_h(&r);
        sn_row row;
        uint32_t n0 = h->row_overflow, pushed = 0;
        memset(&row, 0, sizeof row);
        row.n = 1;
        row.w[0] = SN_FLOAT_OR(1.0f, (int32_t)1 << 30);
        row.dir[1] = row.w[0];
        h->n_rows = 0;
        for (i = 0; i < h->v.nRows + 5; i++) pushed += (uint32_t)sn_rows_push(h, &row);
        T_CHECK(pushed == h->v.nRows && h->row_overflow == n0 + 5, "sn_rows_push stores %u rows, refuses 5 (counted)", pushed);
        row.n = SN_ROW_MAX_ENT + 1;
        h->n_rows = 0;
        T_CHECK(sn_rows_push(h, &row) == 0, "a row with too many entries is refused");
        row.n = 2;
        row.vtx[1] = 65535;
        T_CHECK(sn_rows_push(h, &row) == 0, "a row with an out-of-range vertex is refused");
        row.vtx[1] = 0;
        row.w[1] = SN_FLOAT_OR(1.5f, (int32_t)3 << 29);
        T_CHECK(sn_rows_push(h, &row) == 0, "a row with sum |w| > 2 is refused");
        h->n_rows = 0;
    }
    pu_rt_close(&r);
    pu_rt_close(&r2);
}

/* 6. the API refuses bad input, changing nothing */
static void test_api(void) {
    pu_rt r;
    sn_constraint c;
    sn_collider k;
    uint64_t h0;
    if (open_cow(&r)) { T_CHECK(0, "cow blob"); return; }
    h0 = sn_state_hash(r.inst);
    memset(&c, 0, sizeof c);
    memset(&k, 0, sizeof k);
    T_CHECK(sn_set_constraints(NULL, &c, 1) == SN_ERR_NULL && sn_set_constraints(r.inst, NULL, 1) == SN_ERR_NULL, "NULL refused");
    c.at = 3;
    T_CHECK(sn_set_constraints(r.inst, &c, 1) == SN_ERR_ARG, "bad kind refused");
    c.at = SN_AT_SURFACE; c.vertex = r.info.surface_vertices;
    T_CHECK(sn_set_constraints(r.inst, &c, 1) == SN_ERR_ARG, "surface vertex out of range refused");
    c.at = SN_AT_LATTICE; c.vertex = r.info.free_vertices;
    T_CHECK(sn_set_constraints(r.inst, &c, 1) == SN_ERR_ARG, "skeleton lattice vertex refused (not an unknown)");
    c.vertex = 0; c.axes = 16;
    T_CHECK(sn_set_constraints(r.inst, &c, 1) == SN_ERR_ARG, "bad axes refused");
    c.axes = SN_AXIS_DIR;
    T_CHECK(sn_set_constraints(r.inst, &c, 1) == SN_ERR_ARG, "zero direction refused");
#if defined(SN_FLOAT)
    c.axes = 0; c.target.x = NAN;
    T_CHECK(sn_set_constraints(r.inst, &c, 1) == SN_ERR_ARG, "NaN target refused");
    c.target.x = 1e30f;
    T_CHECK(sn_set_constraints(r.inst, &c, 1) == SN_ERR_ARG, "huge target refused");
    k.radius = NAN;
    T_CHECK(sn_set_colliders(r.inst, &k, 1) == SN_ERR_ARG, "NaN collider refused");
    k.radius = 0;
#else
    c.axes = 0; c.target.x = INT32_MAX; c.target.y = INT32_MIN;
    T_CHECK(sn_set_constraints(r.inst, &c, 1) == SN_OK, "extreme fixed targets accepted (clamped per step, counted)");
    sn_step(r.inst);
    T_CHECK(pu_finite_state(&r), "extreme target: state finite");
    sn_set_constraints(r.inst, NULL, 0);
    sn_reset(r.inst);
#endif
    k.kind = 3;
    T_CHECK(sn_set_colliders(r.inst, &k, 1) == SN_ERR_ARG, "bad collider kind refused");
    k.kind = SN_COLLIDER_PLANE;
    T_CHECK(sn_set_colliders(r.inst, &k, 1) == SN_ERR_ARG, "zero plane normal refused");
    k.kind = SN_COLLIDER_SPHERE; k.radius = rl(-1);
    T_CHECK(sn_set_colliders(r.inst, &k, 1) == SN_ERR_ARG, "negative radius refused");
    T_CHECK(sn_state_hash(r.inst) == h0 && pu_h(&r)->n_con == 0 && pu_h(&r)->n_col == 0, "nothing changed");
    pu_rt_close(&r);
}

int main(int argc, char **argv) {
    printf("constraints and colliders (%s)\n", PU_FLAVOUR_NAME);
    if (argc > 1 && !strcmp(argv[1], "friction")) { test_friction(); return T_END(); } /* one test (tracing) */
    test_pins();
    test_drops();
    test_reference();
    test_ground();
    test_sphere();
    test_friction();
    test_beast();
    test_beast_sphere();
    test_overflow();
    test_api();
    return T_END();
}
