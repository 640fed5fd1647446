/* test_runtime_cut_rows.c -- constraint, contact and crease rows on the cut
 * level (runtime/LEVELS.md §2 "The cut level"; sn_point_weights in
 * runtime/src/sn_cut.c), fixed and float.
 *
 *   usage: cut_rows [--compare] CUT.blob LOD.blob [CREASE_CUT.blob]   (tests/level.mk, tests/scripts/test_level.sh)
 *          cut_rows_fold -c CREASE_CUT.blob                         (built with -DSN_CR_FOLD_ALL)
 *
 * CUT is baked with 'levels 2 cut', LOD the same description with 'levels 2'
 * (its level 0: the baked level 0, its level 1: the fine level).
 *
 * 0. The rows' weights against an independent double-precision cut field
 *    (the child's trilinear weights, the cell's trilinear field at the
 *    child's corners except at an extra): every surface vertex's row
 *    entries and weights (fixed: within 2^-27 of one, 16 LSB of Q30 over
 *    <= 15 roundings of <= 8 terms; float 1e-6) and the rendered surface
 *    point = sum w x over the lattice (fixed: 2^-16 mesh units and 8 LSB
 *    of Q22 for the 15 products; float 1e-5 of the extent).
 * 1. Pins: 8 surface vertices of mostly free cells whose cut rows carry
 *    extras (weight >= 0.2), no two sharing a free corner (5-8), pinned 0.1 cell away while every joint swings
 *    (so the extras move): the rendered vertex meets its target. Bound
 *    fixed: the row residual (<= 1 LSB of Q22) plus the weights' rounding
 *    (16 LSB of Q30 of a point <= 2^6 internal units: 2^-20 internal) and
 *    the output's Q16.16 (2^-16 mesh units): 4 LSB Q22 + 2^-16 mesh units;
 *    float 1e-6 of the extent. The same pins on the baked level 0 and on
 *    level 1 for comparison, and the distance the rendered point keeps
 *    from the trilinear one (what a row with the cell's 8 trilinear
 *    weights would have pinned): it must exceed the bound tenfold, or the
 *    check could not tell the two fields apart. (--compare: levels 0 and
 *    1 stepped too, for the figures.)
 * 2. A sphere pressed into the body (test_runtime_constraint.c's cases:
 *    cow r = 1 by 0.3 into the belly, beast r = 15 by 6 into the belly's
 *    front): no flesh-carried rendered vertex deeper than the sagitta over
 *    half a cell (cow 0.2, beast 6: the same argument as level 0's; the cut
 *    field is trilinear in each half cell, no stiffer); levels 0 and 1 for
 *    comparison.
 * 3. Crease (CREASE_CUT, the crease limb on the cut level): the elbow to
 *    120 degrees in 120 steps, held 60: pairs listed and rows kept, state
 *    finite, no saturation; each kept crease row asks the rendered pair to
 *    separate along n at its target in [0, push]: checked on the rendered
 *    surface's motion over the step, n . (dr_i - dr_c) in [0, push] within
 *    the rounding (fixed 2^-14 internal units: 2 x 15 products and the
 *    fold; float 1e-5), so the rows whose skeleton entries were folded
 *    into the target (pairs with more than 16 entries) hold too. The
 *    limb's pairs stay within 16 entries: built with -DSN_CR_FOLD_ALL
 *    (cut_rows_fold, every pair folded) the same check covers the fold. */
#include "sn_test.h"
#define PU_WHITE_BOX /* pu_h, pu_qd, ...: the instance's internals */
#include "reference/phys_util.h"
#include "reference/phys_pose.h"
#include "sn_constraint.h"
#include "sn_crease.h"
#include "sn_cut.h"

#if defined(SN_FLOAT)
#define FL "float"
#else
#define FL "fixed"
#endif

static double cell_mesh(const pu_rt *r) { return pu_qd(pu_h(r)->v.cell) * pu_unit(r); }

/* The cut field's weights of surface vertex s, double precision, written
 * independently of sn_cut.c: plain lattice, the 8 trilinear weights; cut,
 * the child's trilinear weights phi'_k, each child corner carrying the
 * cell's trilinear field (its weights at the half-cell point) unless an
 * extra sits there (CELLX), which carries itself. Returns the entries. */
static uint32_t ref_weights(const sn_view *v, uint32_t s, uint32_t vtx[15], double w[15]) {
    const unsigned char *e = v->sec[SN_SEC_EMBED] + (size_t)s * SN_ELEM_EMBED;
    uint32_t cell = sn_rd_u16(e), k, a, n = 8, c;
    const unsigned char *cl = v->sec[SN_SEC_CELLS] + (size_t)cell * SN_ELEM_CELLS;
    double t[3];
    for (c = 0; c < 3; c++) t[c] = sn_rd_u16(e + 2 + 2 * c) / 32768.0;
    for (a = 0; a < 8; a++) { vtx[a] = sn_rd_u16(cl + 2 * a); w[a] = 0; }
    if (!v->cut) {
        for (a = 0; a < 8; a++) w[a] = ((a & 1) ? t[0] : 1 - t[0]) * ((a & 2) ? t[1] : 1 - t[1]) * ((a & 4) ? t[2] : 1 - t[2]);
        return 8;
    }
    {
        const unsigned char *cx = sn_sec(v, SN_SEC_CELLX) + (size_t)cell * SN_ELEM_CELLX;
        int b[3];
        double u[3];
        for (c = 0; c < 3; c++) { b[c] = t[c] >= 0.5; u[c] = 2 * t[c] - b[c]; }
        for (k = 0; k < 8; k++) {
            int p[3] = {b[0] + (int)(k & 1), b[1] + (int)(k >> 1 & 1), b[2] + (int)(k >> 2 & 1)};
            double ph = ((k & 1) ? u[0] : 1 - u[0]) * ((k & 2) ? u[1] : 1 - u[1]) * ((k & 4) ? u[2] : 1 - u[2]);
            int idx = p[0] + 3 * p[1] + 9 * p[2], slot = -1, q, cnt = 0;
            uint32_t x = 0xFFFFu;
            /* CELLX slots: the 27 half-cell points in order, the 8 corners skipped */
            for (q = 0; q < 27; q++) {
                int corner = (q % 3 != 1) && (q / 3 % 3 != 1) && (q / 9 != 1);
                if (corner) continue;
                if (q == idx) { slot = cnt; break; }
                cnt++;
            }
            if (slot >= 0) x = sn_rd_u16(cx + 2 * slot);
            if (x != 0xFFFFu) {
                if (ph != 0) { vtx[n] = x; w[n] = ph; n++; }
                continue;
            }
            for (a = 0; a < 8; a++) /* the cell's trilinear weight of corner a at the half-cell point p / 2 */
                w[a] += ph * ((a & 1) ? p[0] / 2.0 : 1 - p[0] / 2.0) * ((a & 2) ? p[1] / 2.0 : 1 - p[1] / 2.0) *
                        ((a & 4) ? p[2] / 2.0 : 1 - p[2] / 2.0);
        }
    }
    return n;
}
static double free_w2(const pu_rt *r, uint32_t s) {
    uint32_t vx[15], n, k;
    double w[15], f = 0;
    n = ref_weights(&pu_h(r)->v, s, vx, w);
    for (k = 0; k < n; k++) if (vx[k] < pu_h(r)->v.nF) f += w[k] * w[k];
    return f;
}
static double extra_w(const pu_rt *r, uint32_t s) {
    uint32_t vx[15], n, k;
    double w[15], f = 0;
    n = ref_weights(&pu_h(r)->v, s, vx, w);
    for (k = 8; k < n; k++) f += w[k];
    return f;
}
/* every joint but the root swings about a tilted axis, amp degrees, its own phase */
static void swing(const pu_rt *r, int step, double amp, sn_xform *xf) {
    sn_quat local[64];
    uint32_t j;
    for (j = 0; j < r->info.joints && j < 64; j++)
        local[j] = j == 0 ? pu_qident() : pu_axis_angle(1.0, 0.3, 0.2 * (j % 3), amp * sin(2 * PU_PI * step / 60.0 + 0.7 * j));
    sn_pose_from_local(r->blob, local, NULL, xf);
}

/* 0. the rows' weights and the rendered surface against the double field */
static double check_weights(const char *name, pu_rt *r) {
    sn_ihdr *h = pu_h(r);
    uint32_t ns = r->info.surface_vertices, nv = r->info.vertices, s, k, j, n, nr, vx[15], bad_ent = 0, with_x = 0, maxn = 0;
    double *lat = malloc(3 * nv * sizeof *lat), *sur = malloc(3 * ns * sizeof *sur), w[15], werr = 0, perr = 0, ext = 0, u = pu_unit(r);
    sn_xform xf[64];
    int step;
    for (step = 0; step < 20; step++) { swing(r, step, 20, xf); sn_set_pose(r->inst, xf, r->info.joints); sn_step(r->inst); }
    pu_rt_lattice(r, lat);
    pu_rt_surface(r, sur);
    for (s = 0; s < ns; s++) {
        const unsigned char *e = h->v.sec[SN_SEC_EMBED] + (size_t)s * SN_ELEM_EMBED;
        uint32_t t[3], rv_[15];
        uint16_t rv[15];
        sn_q rw[15];
        double p[3] = {0, 0, 0};
        for (k = 0; k < 3; k++) t[k] = sn_rd_u16(e + 2 + 2 * k);
        n = ref_weights(&h->v, s, vx, w);
        nr = sn_point_weights(&h->v, sn_rd_u16(e), t, rv, rw);
        (void)rv_;
        if (nr != n) { bad_ent++; continue; }
        with_x += n > 8;
        maxn = n > maxn ? n : maxn;
        for (k = 0; k < n; k++) {
            if (rv[k] != vx[k]) bad_ent++;
            werr = fmax(werr, fabs(pu_qr(rw[k]) - w[k]));
            for (j = 0; j < 3; j++) p[j] += w[k] * lat[3 * vx[k] + j];
        }
        for (j = 0; j < 3; j++) { perr = fmax(perr, fabs(p[j] - sur[3 * s + j])); ext = fmax(ext, fabs(p[j])); }
    }
    T_FIGURE("%s [%s] weights: %u surface vertices, %u with extras in their rows (up to %u entries); row weights vs double %.3g, "
             "rendered vs sum w x %.3g mesh units (extent %.3g)", name, FL, ns, with_x, maxn, werr, perr, ext);
    T_CHECK(bad_ent == 0 && with_x > 0 && maxn <= 15, "%s: row entries are the cut field's (%u mismatches, %u rows with extras, <= 15: %u)",
            name, bad_ent, with_x, maxn);
#if defined(SN_FLOAT)
    T_CHECK(werr <= 1e-6, "%s: row weights within 1e-6 of the double field (%.3g)", name, werr);
    T_CHECK(perr <= 1e-5 * ext, "%s: rendered point = sum w x within 1e-5 of the extent (%.3g)", name, perr / ext);
#else
    T_CHECK(werr <= ldexp(1, -27), "%s: row weights within 2^-27 of the double field (%.3g)", name, werr);
    T_CHECK(perr <= ldexp(1, -16) + 8 * ldexp(u, -22), "%s: rendered point = sum w x within 2^-16 + 8 LSB Q22 (%.3g mesh units)", name, perr);
#endif
    (void)u;
    free(lat); free(sur);
    return ext;
}

/* 1. pins during a swing: worst rendered-vs-target (mesh units) on r; *tri the largest distance of the rendered
 * pinned point from its trilinear point (cut only) */
static double pins(pu_rt *r, const uint32_t *sv, uint32_t npin, double off, double *tri, double *resid, uint32_t *kept_min, uint32_t *sat) {
    sn_xform xf[64];
    sn_constraint cs[8];
    double *sur = malloc(3 * r->info.surface_vertices * sizeof *sur), *lat = malloc(3 * r->info.vertices * sizeof *lat), worst = 0;
    uint32_t i, k, kept;
    int step;
    sn_stats st;
    *tri = 0; *resid = 0; *kept_min = 1000;
    for (step = 0; step < 30; step++) { swing(r, step, 0, xf); sn_set_pose(r->inst, xf, r->info.joints); sn_step(r->inst); }
    pu_rt_surface(r, sur);
    memset(cs, 0, sizeof cs);
    for (i = 0; i < npin; i++) {
        cs[i].at = SN_AT_SURFACE;
        cs[i].vertex = sv[i];
        cs[i].target.x = pu_rlen(sur[3 * sv[i]] + 0.5 * off);
        cs[i].target.y = pu_rlen(sur[3 * sv[i] + 1] + off);
        cs[i].target.z = pu_rlen(sur[3 * sv[i] + 2] - 0.5 * off);
    }
    T_CHECK(sn_set_constraints(r->inst, cs, npin) == SN_OK, "%u constraints set", npin);
    for (step = 0; step < 60; step++) {
        double res;
        swing(r, step, 12, xf);
        sn_set_pose(r->inst, xf, r->info.joints);
        sn_step(r->inst);
        res = pu_row_residual(r, SN_SRC_USER, &kept);
        *resid = fmax(*resid, res);
        *kept_min = kept < *kept_min ? kept : *kept_min;
        if (step < 10) continue; /* the approach: one cell a step at most, then held */
        pu_rt_surface(r, sur);
        if (pu_h(r)->v.cut) pu_rt_lattice(r, lat);
        for (i = 0; i < npin; i++) {
            const double *p = sur + 3 * sv[i];
            double d = fmax(fabs(p[0] - pu_len(cs[i].target.x)), fmax(fabs(p[1] - pu_len(cs[i].target.y)), fabs(p[2] - pu_len(cs[i].target.z))));
            worst = fmax(worst, d);
            if (pu_h(r)->v.cut) { /* the trilinear point of the same cell */
                const unsigned char *e = pu_h(r)->v.sec[SN_SEC_EMBED] + (size_t)sv[i] * SN_ELEM_EMBED;
                const unsigned char *cl = pu_h(r)->v.sec[SN_SEC_CELLS] + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
                double t[3], q[3] = {0, 0, 0}, dd = 0;
                for (k = 0; k < 3; k++) t[k] = sn_rd_u16(e + 2 + 2 * k) / 32768.0;
                for (k = 0; k < 8; k++) {
                    double ww = ((k & 1) ? t[0] : 1 - t[0]) * ((k & 2) ? t[1] : 1 - t[1]) * ((k & 4) ? t[2] : 1 - t[2]);
                    uint32_t a = sn_rd_u16(cl + 2 * k), c;
                    for (c = 0; c < 3; c++) q[c] += ww * lat[3 * a + c];
                }
                for (k = 0; k < 3; k++) dd += (q[k] - p[k]) * (q[k] - p[k]);
                *tri = fmax(*tri, sqrt(dd));
            }
        }
    }
    sn_get_stats(r->inst, &st);
    *sat = st.saturations + !pu_finite_state(r);
    free(sur); free(lat);
    return worst;
}

/* 2. a sphere pressed into the body: deepest flesh-carried rendered vertex (flesh: the cut blob's rows, fl[]) */
static double sphere(pu_rt *r, const unsigned char *fl, int beast, uint32_t *contacts, uint32_t *sat) {
    sn_xform xf[64];
    sn_collider c;
    sn_stats st;
    uint32_t i, ns = r->info.surface_vertices, step;
    double *buf = malloc(3 * ns * sizeof *buf), worst = 0, rad = beast ? 15.0 : 1.0, depth = beast ? 6.0 : 0.3;
    double cx = beast ? 0 : 1.0, cy = beast ? 18 : -1e30, cz = beast ? -1e30 : 0, edge = 1e30;
    swing(r, 0, 0, xf);
    sn_set_pose(r->inst, xf, r->info.joints);
    sn_step(r->inst);
    pu_rt_surface(r, buf);
    for (i = 0; i < ns; i++) {
        if (beast) { if (fabs(buf[3 * i]) < 4 && fabs(buf[3 * i + 1] - 18) < 4 && buf[3 * i + 2] > cz) cz = buf[3 * i + 2]; }
        else if (fabs(buf[3 * i] - cx) < 0.5 && fabs(buf[3 * i + 2]) < 0.5 && buf[3 * i + 1] < edge) edge = buf[3 * i + 1];
    }
    edge = beast ? cz : edge;
    memset(&c, 0, sizeof c);
    c.kind = SN_COLLIDER_SPHERE;
    c.radius = pu_rlen(rad);
    for (step = 0; step < 120; step++) { /* rises `depth` into the body over 60 steps (1 s), then holds */
        double d = step < 60 ? depth * step / 60.0 : depth;
        if (beast) cz = edge + rad - d; else cy = edge - rad + d;
        c.a.x = pu_rlen(cx); c.a.y = pu_rlen(cy); c.a.z = pu_rlen(cz);
        c.velocity.x = c.velocity.y = c.velocity.z = 0;
        if (step < 60) { if (beast) c.velocity.z = pu_rlen(-depth); else c.velocity.y = pu_rlen(depth); }
        sn_set_pose(r->inst, xf, r->info.joints);
        sn_set_colliders(r->inst, &c, 1);
        sn_step(r->inst);
        if (step < 2) continue;
        pu_rt_surface(r, buf);
        for (i = 0; i < ns; i++) {
            double dx = buf[3 * i] - cx, dy = buf[3 * i + 1] - cy, dz = buf[3 * i + 2] - cz, in = rad - sqrt(dx * dx + dy * dy + dz * dz);
            if (fl[i] && in > worst) worst = in;
        }
    }
    sn_get_stats(r->inst, &st);
    *contacts = st.contacts;
    *sat = st.saturations + !pu_finite_state(r);
    free(buf);
    return worst;
}

static void body(const char *cutp, const char *lodp, int compare) {
    pu_rt c, l0, l1;
    const char *name = strrchr(cutp, '/') ? strrchr(cutp, '/') + 1 : cutp;
    int beast = strstr(name, "beast") != NULL;
    uint32_t sv[8], npin = 0, i, ns, kept[3], sat[3], ct[3];
    double err[3], tri[3], res[3], cell, tol, pen[3], ext, sag = beast ? 6.0 : 0.2;
    unsigned char *fl;
    if (pu_rt_open(&c, cutp) || pu_rt_open(&l0, lodp) || pu_rt_open(&l1, lodp) || sn_set_lod(l1.inst, 1) != SN_OK) {
        T_CHECK(0, "open %s, %s (tests/level.mk)", cutp, lodp);
        return;
    }
    T_CHECK(pu_h(&c)->v.cut && c.info.max_constraints > 0 && c.info.max_colliders > 0, "%s: a cut level with constraint and collider slots (%u, %u)",
            name, c.info.max_constraints, c.info.max_colliders);
    ext = check_weights(name, &c);
    (void)ext;
    sn_reset(c.inst);
    /* 1. pins */
    ns = c.info.surface_vertices;
    for (i = 0; i < ns && npin < 8; i++) { /* no two sharing a free corner: their rows can be nearly dependent, one dropped */
        uint32_t s = (uint32_t)(((uint64_t)i * 7919u + 13u) % ns), vx[15], vy[15], q, a, b, clash = 0;
        double w[15];
        if (!(free_w2(&c, s) >= 0.25 && extra_w(&c, s) >= 0.2)) continue;
        ref_weights(&pu_h(&c)->v, s, vx, w);
        for (q = 0; q < npin; q++) {
            ref_weights(&pu_h(&c)->v, sv[q], vy, w);
            for (a = 0; a < 8; a++)
                for (b = 0; b < 8; b++) clash |= vx[a] == vy[b] && vx[a] < pu_h(&c)->v.nF;
        }
        if (!clash) sv[npin++] = s;
    }
    T_CHECK(npin >= 5, "%s: at least 5 surface vertices of mostly free cells with extras in their rows, apart (%u)", name, npin);
    cell = cell_mesh(&c);
    err[0] = pins(&c, sv, npin, 0.1 * cell, &tri[0], &res[0], &kept[0], &sat[0]);
    err[1] = err[2] = tri[1] = tri[2] = res[1] = res[2] = 0; kept[1] = kept[2] = sat[1] = sat[2] = 0;
    if (compare) { /* the baked level 0 and level 1, for the figures */
        err[1] = pins(&l0, sv, npin, 0.1 * cell, &tri[1], &res[1], &kept[1], &sat[1]);
        err[2] = pins(&l1, sv, npin, 0.1 * cell, &tri[2], &res[2], &kept[2], &sat[2]);
    }
#if defined(SN_FLOAT)
    tol = 4e-6 * ext; /* the kept rows hold to 1e-6 of their scale; the weights and the sums round to 2^-24 each */
#else
    tol = 4 * ldexp(pu_unit(&c), -22) + ldexp(1, -16);
#endif
    T_FIGURE("%s [%s] pins (%u surface vertices, 0.1 cell away, every joint swinging 12 deg): rendered vs target, worst over steps 10-59: "
             "cut %.3g, baked level 0 %.3g, level 1 %.3g mesh units (bound %.3g); row residual %.3g / %.3g / %.3g %s; rows kept at least %u / %u / %u of %u; "
             "the cut level's rendered point from its trilinear point up to %.3g",
             name, FL, npin, err[0], err[1], err[2], tol, res[0], res[1], res[2], PU_FLAVOUR_NAME[1] == 'l' ? "(relative)" : "LSB Q22", kept[0],
             kept[1], kept[2], 3 * npin, tri[0]);
    T_CHECK(kept[0] == 3 * npin && err[0] <= tol, "%s: cut level: every pin row kept (%u of %u) and the rendered vertices at their targets (%.3g <= %.3g)",
            name, kept[0], 3 * npin, err[0], tol);
    T_CHECK(tri[0] >= 10 * tol, "%s: the trilinear point strays %.3g from the rendered one: >= 10 x the bound (the check tells the fields apart)",
            name, tri[0]);
    T_CHECK(sat[0] == 0 && sat[1] == 0 && sat[2] == 0, "%s: pins: no saturation, state finite (%u %u %u)", name, sat[0], sat[1], sat[2]);
#if defined(SN_FLOAT)
    T_CHECK(res[0] <= 1e-6, "%s: cut level: every kept pin row holds (%.3g relative)", name, res[0]);
#else
    T_CHECK(res[0] <= 1.0, "%s: cut level: every kept pin row holds (%.3g LSB Q22)", name, res[0]);
#endif
    sn_set_constraints(c.inst, NULL, 0); sn_set_constraints(l0.inst, NULL, 0); sn_set_constraints(l1.inst, NULL, 0);
    sn_reset(c.inst); sn_reset(l0.inst); sn_reset(l1.inst);
    sn_set_lod(l1.inst, 1);
    /* 2. sphere */
    fl = malloc(ns);
    for (i = 0; i < ns; i++) fl[i] = free_w2(&c, i) >= 1.0 / 256;
    pen[0] = sphere(&c, fl, beast, &ct[0], &sat[0]);
    pen[1] = pen[2] = 0; ct[1] = ct[2] = sat[1] = sat[2] = 0;
    if (compare) {
        pen[1] = sphere(&l0, fl, beast, &ct[1], &sat[1]);
        pen[2] = sphere(&l1, fl, beast, &ct[2], &sat[2]);
    }
    T_FIGURE("%s [%s] sphere r=%g pressed %g into the body: deepest flesh-carried rendered vertex cut %.4g, baked level 0 %.4g, level 1 %.4g "
             "mesh units inside (bound %g); contacts in the last step %u / %u / %u",
             name, FL, beast ? 15.0 : 1.0, beast ? 6.0 : 0.3, pen[0], pen[1], pen[2], sag, ct[0], ct[1], ct[2]);
    T_CHECK(ct[0] > 0 && sat[0] == 0, "%s: cut level: contacts active (%u), no saturation, state finite", name, ct[0]);
    T_CHECK(pen[0] <= sag, "%s: cut level: no flesh-carried vertex more than the sagitta over half a cell (%g) inside (%.4g)", name, sag, pen[0]);
    free(fl);
    pu_rt_close(&c); pu_rt_close(&l0); pu_rt_close(&l1);
}

/* 3. crease on the cut level */
static void crease(const char *path) {
    pu_rt r;
    sn_xform xf[8];
    sn_quat local[8];
    sn_stats st;
    uint32_t ns, k, j, listed = 0, rows_max = 0, checked = 0, folded = 0, kept = 0, skel = 0;
    double *prev, *cur, worst = 0, resid = 0, push;
    const char *name = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    if (pu_rt_open(&r, path)) { T_CHECK(0, "open %s (tests/level.mk)", path); return; }
    T_CHECK(pu_h(&r)->v.cut && pu_h(&r)->v.nCR, "%s: a cut level with crease data", name);
    ns = r.info.surface_vertices;
    prev = malloc(3 * ns * sizeof *prev); cur = malloc(3 * ns * sizeof *cur);
    push = pu_qd(pu_h(&r)->v.cr_push);
    pu_rt_surface(&r, prev);
    for (k = 0; k < 180; k++) {
        double deg = k < 120 ? 120.0 * (k + 1) / 120.0 : 120.0, res;
        for (j = 0; j < r.info.joints; j++) local[j] = pu_qident();
        pu_set_local(r.blob, local, "elbow", pu_axis_angle(0, 0, 1, deg));
        sn_pose_from_local(r.blob, local, NULL, xf);
        sn_set_pose(r.inst, xf, r.info.joints);
        sn_step(r.inst);
        pu_rt_surface(&r, cur);
        res = pu_row_residual(&r, SN_SRC_CREASE, &kept);
        resid = fmax(resid, res);
        {   /* each kept crease row: the rendered pair separates along n at a target in [0, push] (internal units) */
            const sn_ihdr *h = pu_h(&r);
            const sn_row *rows = sn_rows((sn_ihdr *)(uintptr_t)h);
            const sn_rowx *rx = CARR(h, o_rx, sn_rowx);
            const sn_crease_pair *C = sn_crease_list(h);
            double u = pu_unit(&r);
            for (j = 0; j < h->n_rows; j++) {
                const sn_crease_pair *P;
                uint32_t vi[15], vc[15], ni, nc, a, b, merged, q;
                double wi[15], wc[15], dn = 0;
                if (SN_ROW_PRODUCER(rows[j].source) != SN_SRC_CREASE || rx[j].inv == 0) continue;
                P = C + (rows[j].source & 0xFFu); /* the list has <= 64 < 256 pairs */
                ni = ref_weights(&h->v, P->vertex, vi, wi);
                nc = ref_weights(&h->v, P->corner, vc, wc);
                for (merged = ni, b = 0; b < nc; b++) {
                    for (a = 0; a < ni && vi[a] != vc[b]; a++) {}
                    merged += a == ni;
                }
                folded += merged > 16;
                for (a = 0; a < ni; a++) skel += vi[a] >= h->v.nF;
                for (a = 0; a < nc; a++) skel += vc[a] >= h->v.nF;
                for (q = 0; q < 3; q++)
                    dn += pu_qr(rows[j].dir[q]) * ((cur[3 * P->vertex + q] - prev[3 * P->vertex + q]) - (cur[3 * P->corner + q] - prev[3 * P->corner + q])) / u;
                worst = fmax(worst, fmax(-dn, dn - push));
                checked++;
            }
        }
        sn_get_stats(r.inst, &st);
        listed = st.crease_list > listed ? st.crease_list : listed;
        rows_max = st.crease_active > rows_max ? st.crease_active : rows_max;
        memcpy(prev, cur, 3 * ns * sizeof *prev);
    }
    sn_get_stats(r.inst, &st);
    T_FIGURE("%s [%s] crease, elbow to 120 deg in 120 steps, held 60: list up to %u, n_a up to %u, %u kept crease rows checked (%u with "
             "more than 16 entries, skeleton folded into the target); rendered separation outside [0, push = %.3g] by at most %.3g internal "
             "units; row residual %.3g %s", name, FL, listed, rows_max, checked, folded, push, worst, resid,
             PU_FLAVOUR_NAME[1] == 'l' ? "(relative)" : "LSB Q22");
    T_CHECK(listed > 0 && checked > 0, "%s: crease pairs listed (%u) and their rows kept (%u)", name, listed, checked);
#if defined(SN_CR_FOLD_ALL)
    T_FIGURE("%s [%s] (SN_CR_FOLD_ALL: every crease row's skeleton entries folded into its target) %u skeleton entries folded", name, FL, skel);
    T_CHECK(skel > 0, "%s: folded rows among the checked ones (%u skeleton entries)", name, skel);
#endif
    T_CHECK(st.saturations == 0 && pu_finite_state(&r), "%s: no saturation (%u), state finite", name, st.saturations);
#if defined(SN_FLOAT)
    T_CHECK(worst <= 1e-5 && resid <= 1e-6, "%s: the kept crease rows move the rendered pair apart at their targets (%.3g <= 1e-5; rows %.3g)", name,
            worst, resid);
#else
    /* rows: Q22 x rounded per entry after the fix, sum |w| |d|_1 <= 2 sqrt 3 of half an LSB: 1.74 LSB (the pins' rows, sum |w| = 1: 0.87) */
    T_CHECK(worst <= ldexp(1, -14) && resid <= 1.74, "%s: the kept crease rows move the rendered pair apart at their targets (%.3g <= 2^-14; rows %.3g <= 1.74 LSB)",
            name, worst, resid);
#endif
    free(prev); free(cur);
    pu_rt_close(&r);
}

int main(int argc, char **argv) {
    (void)pu_seed;
    if (argc == 3 && strcmp(argv[1], "-c") == 0) { crease(argv[2]); return T_END(); } /* the fold-all build: crease only */
    int compare = argc > 1 && strcmp(argv[1], "--compare") == 0; /* also levels 0 and 1 (figures; make test: the cow only) */
    argv += compare; argc -= compare;
    if (argc < 3) { printf("usage: %s [--compare] CUT.blob LOD.blob [CREASE_CUT.blob] | -c CREASE_CUT.blob\n", argv[0]); return 2; }
    body(argv[1], argv[2], compare);
    if (argc > 3) crease(argv[3]);
    return T_END();
}
