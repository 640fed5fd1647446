/* sb_rig.c -- rig forces (seed 003 §4.1-4.2, eq. 4 and 11-12): force-field
 * templates integrated into generalized forces on the free lattice vertices,
 *
 *     Q^a_i = int_Omega phi_i(x) f_a(x) dV        (newtons, at eta = 1)
 *
 * over the interior only, at the rest shape, in model axes (= the vertex's
 * rest frame: the runtime turns it by R_i). The quadrature is the one of
 * sb_integrate_frac: each kept cell split into subdiv^3 sub-boxes with 2x2x2
 * Gauss points, point q weighted w0 * frac_q where frac_q is the inside
 * fraction of the point's box (sb_lattice_fill.c, the build's step 3, recomputed here the same
 * way for the partially inside cells a rig touches); points outside weigh 0
 * (no `air`: a force field acts on flesh, not on the padding).
 *
 * Templates (tools/DESCRIPTION.md "Rigs and controls"): with the falloff
 * w(u) = (1 - u^2)^3 (u < 1, else 0; 1 at the centre, C2 at the rim) and the
 * radial profile g(u) u_hat with g(u) = (25 sqrt 5 / 16) u (1 - u^2)^2
 * (0 on the centre, peak 1 at u = 1/sqrt 5, 0 at the rim), force densities
 * in N/m^3 with amp = s E_ref / (L_ref unit):
 *   bump    c, R [, d]:     amp w(|x-c|/R) d_hat, or radial amp G (x-c)/R (1-u^2)^2
 *   ring    c, a, Rr, W:    amp w(delta/W) rho_hat (delta: distance to the ring circle; rho_hat: away from the axis)
 *   muscle  a, b, R, k:     amp [ m(t) g(u) perp_hat + k h(t) w(u) e ], t along a->b, u = dist/R,
 *                           m(t) = 16 t^2 (1-t)^2, h(t) = 25 sqrt 5 t^2 (1-t)^2 (1-2t)
 *   uniform d, REGION:      amp d_hat inside REGION
 */
#include "sb.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define G_NORM 3.4938562148434216   /* 25 sqrt(5) / 16: peak of u (1-u^2)^2 is 16 / (25 sqrt 5) */
#define H_NORM 55.901699437494742   /* 25 sqrt(5): peak of t^2 (1-t)^2 (1-2t) is 1 / (25 sqrt 5) */

const char *sb_rig_tpl_name(int tpl)
{
    static const char *n[5] = {"bump", "ring", "muscle", "uniform", "file"};
    return tpl >= 0 && tpl < 5 ? n[tpl] : "?";
}

double sb_rig_tau(const sb_rigdef *r, double g)
{
    int k;
    if (r->ntau <= 0) return 0;
    if (g <= r->tau_g[0]) return r->tau_e[0];
    for (k = 0; k + 1 < r->ntau; k++)
        if (g <= r->tau_g[k + 1])
            return r->tau_e[k] + (r->tau_e[k + 1] - r->tau_e[k]) * ((g - r->tau_g[k]) / (r->tau_g[k + 1] - r->tau_g[k]));
    return r->tau_e[r->ntau - 1];
}

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double wfall(double u) { double v = 1 - u * u; return u < 1 ? v * v * v : 0; }

void sb_rig_field(const sb_model *o, const sb_rig *rg, const double x[3], double f[3])
{
    const sb_rigdef *r = &rg->def;
    const double *p = r->p;
    double d[3], A = rg->amp;
    int k;
    f[0] = f[1] = f[2] = 0;
    for (k = 0; k < 3; k++) if (x[k] < rg->lo[k] || x[k] > rg->hi[k]) return;
    switch (r->tpl) {
    case SB_TPL_BUMP: {
        double u2;
        for (k = 0; k < 3; k++) d[k] = (x[k] - p[k]) / p[3];
        u2 = dot3(d, d);
        if (u2 >= 1) return;
        if (r->has_dir) { double w = wfall(sqrt(u2)); for (k = 0; k < 3; k++) f[k] = A * w * p[4 + k]; }
        else { double v = 1 - u2; for (k = 0; k < 3; k++) f[k] = A * G_NORM * d[k] * v * v; }
        return;
    }
    case SB_TPL_RING: {
        double z, rv[3], rho, del2, W = p[7], Rr = p[6];
        for (k = 0; k < 3; k++) d[k] = x[k] - p[k];
        z = dot3(d, p + 3);
        for (k = 0; k < 3; k++) rv[k] = d[k] - z * p[3 + k];
        rho = sqrt(dot3(rv, rv));
        del2 = ((rho - Rr) * (rho - Rr) + z * z) / (W * W);
        if (del2 >= 1 || !(rho > 0)) return;
        {
            double w = wfall(sqrt(del2));
            for (k = 0; k < 3; k++) f[k] = A * w * rv[k] / rho;
        }
        return;
    }
    case SB_TPL_MUSCLE: {
        double e[3], L = 0, t, pv[3], u2, R = p[6], m, h, v;
        for (k = 0; k < 3; k++) { e[k] = p[3 + k] - p[k]; L += e[k] * e[k]; }
        L = sqrt(L);
        for (k = 0; k < 3; k++) { e[k] /= L; d[k] = x[k] - p[k]; }
        t = dot3(d, e) / L;
        if (t <= 0 || t >= 1) return;
        for (k = 0; k < 3; k++) pv[k] = (d[k] - t * L * e[k]) / R;
        u2 = dot3(pv, pv);
        if (u2 >= 1) return;
        v = 1 - u2;
        m = 16 * t * t * (1 - t) * (1 - t);
        h = H_NORM * t * t * (1 - t) * (1 - t) * (1 - 2 * t);
        for (k = 0; k < 3; k++) f[k] = A * (m * G_NORM * pv[k] * v * v + p[7] * h * v * v * v * e[k]);
        return;
    }
    case SB_TPL_UNIFORM:
        if (!sb_region_has(o, &r->r, x)) return;
        for (k = 0; k < 3; k++) f[k] = A * p[k];
        return;
    }
}

/* smallest length over which a rig's field varies (mesh units): sets the quadrature refinement */
static double rig_feature(const sb_rig *rg)
{
    const double *p = rg->def.p;
    switch (rg->def.tpl) {
    case SB_TPL_BUMP: return p[3];
    case SB_TPL_RING: return p[7];
    case SB_TPL_MUSCLE: {
        double L = sqrt((p[3] - p[0]) * (p[3] - p[0]) + (p[4] - p[1]) * (p[4] - p[1]) + (p[5] - p[2]) * (p[5] - p[2]));
        return fmin(p[6], 0.5 * L);
    }
    default: return HUGE_VAL;   /* constant field: the lattice's own rule is exact for it */
    }
}

/* support bounding box (mesh units), reference size L_ref and centre of a rig */
static void rig_geometry(const sb_model *o, sb_rig *rg, double centre[3])
{
    const sb_rigdef *r = &rg->def;
    const double *p = r->p;
    int k, i;
    switch (r->tpl) {
    case SB_TPL_BUMP:
        for (k = 0; k < 3; k++) { rg->lo[k] = p[k] - p[3]; rg->hi[k] = p[k] + p[3]; centre[k] = p[k]; }
        rg->L_ref = p[3];
        break;
    case SB_TPL_RING:
        for (k = 0; k < 3; k++) { rg->lo[k] = p[k] - p[6] - p[7]; rg->hi[k] = p[k] + p[6] + p[7]; centre[k] = p[k]; }
        rg->L_ref = p[7];
        break;
    case SB_TPL_MUSCLE:
        for (k = 0; k < 3; k++) {
            rg->lo[k] = fmin(p[k], p[3 + k]) - p[6]; rg->hi[k] = fmax(p[k], p[3 + k]) + p[6];
            centre[k] = 0.5 * (p[k] + p[3 + k]);
        }
        rg->L_ref = p[6];
        break;
    default: {   /* uniform: the region's box (bone and all: the lattice's box) */
        double llo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, lhi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
        for (i = 0; i < o->nv; i++) for (k = 0; k < 3; k++) { llo[k] = fmin(llo[k], o->x[3 * i + k]); lhi[k] = fmax(lhi[k], o->x[3 * i + k]); }
        if (r->r.kind == SB_RG_BOX) {
            rg->L_ref = HUGE_VAL;
            for (k = 0; k < 3; k++) {
                rg->lo[k] = r->r.a[k]; rg->hi[k] = r->r.a[3 + k]; centre[k] = 0.5 * (r->r.a[k] + r->r.a[3 + k]);
                rg->L_ref = fmin(rg->L_ref, 0.5 * (r->r.a[3 + k] - r->r.a[k]));
            }
        } else if (r->r.kind == SB_RG_SPHERE) {
            for (k = 0; k < 3; k++) { rg->lo[k] = r->r.a[k] - r->r.a[3]; rg->hi[k] = r->r.a[k] + r->r.a[3]; centre[k] = r->r.a[k]; }
            rg->L_ref = r->r.a[3];
        } else if (r->r.kind == SB_RG_BONE) {
            int j = o->desc_to_sorted[r->r.bone], s;
            const double *a = o->joints[o->joints[j].parent].pos, *b = o->joints[j].pos;
            for (k = 0; k < 3; k++) { rg->lo[k] = llo[k]; rg->hi[k] = lhi[k]; centre[k] = 0.5 * (a[k] + b[k]); }
            rg->L_ref = o->c;
            for (s = 0; s < o->nseg; s++) if (o->seg_child[s] == j) rg->L_ref = o->seg_r[s] > 0 ? o->seg_r[s] : o->c;
        } else {
            rg->L_ref = HUGE_VAL;
            for (k = 0; k < 3; k++) { rg->lo[k] = llo[k]; rg->hi[k] = lhi[k]; centre[k] = o->joints[0].pos[k]; rg->L_ref = fmin(rg->L_ref, 0.5 * (lhi[k] - llo[k])); }
        }
        break;
    }
    }
}

/* Inside fractions of the quadrature point boxes of the kept cells a rig
 * needs, by the lattice build's own routine (sb_box_fractions; the build frees
 * its fractions once the matrices are integrated). Cells with fill 0 or 1 need
 * no rays. */
typedef struct {
    int npt;
    int *slot;        /* per kept cell: -1 (use fill), or index into frac */
    double *frac;     /* nslot x npt */
} fracs_t;

static void fracs_build(const sb_desc *d, const sb_mesh *m, const sb_model *o, const unsigned char *need, fracs_t *F)
{
    int n = d->subdiv, npt = n * n * n * 8, ngc = (o->gn[0] - 1) * (o->gn[1] - 1) * (o->gn[2] - 1);
    int ci, ns = 0, k, *gslot = sb_alloc(sizeof(int) * (size_t)ngc);
    sb_inside in;
    F->npt = npt;
    F->slot = sb_alloc(sizeof(int) * (size_t)(o->nc ? o->nc : 1));
    for (k = 0; k < ngc; k++) gslot[k] = -1;
    for (ci = 0; ci < o->nc; ci++) {
        F->slot[ci] = -1;
        if (need[ci] && o->cell_fill[ci] > 0 && o->cell_fill[ci] < 1) {
            F->slot[ci] = ns++;
            gslot[o->cell_grid[ci]] = F->slot[ci];
        }
    }
    F->frac = sb_alloc(sizeof(double) * (size_t)npt * (size_t)(ns ? ns : 1));
    if (ns) {
        sb_inside_init(&in, m);
        sb_box_fractions(o, m, &in, n, gslot, F->frac, -1);
        sb_inside_free(&in);
    }
    for (k = 0; k < ns * npt; k++) F->frac[k] = F->frac[k] > 1 ? 1 : F->frac[k];
    free(gslot);
}

void sb_rig_free(sb_model *o)
{
    int a;
    for (a = 0; a < o->nrig; a++) { free(o->rig[a].vert); free(o->rig[a].Q); }
    free(o->rig); free(o->ctl);
    o->rig = NULL; o->ctl = NULL; o->nrig = o->nctl = 0;
}

static const char *where(const sb_rig *rg, char *buf, size_t n)
{
    const double *p = rg->def.p;
    switch (rg->def.tpl) {
    case SB_TPL_BUMP: snprintf(buf, n, "bump centre (%g, %g, %g), radius %g", p[0], p[1], p[2], p[3]); break;
    case SB_TPL_RING: snprintf(buf, n, "ring centre (%g, %g, %g), radius %g, width %g", p[0], p[1], p[2], p[6], p[7]); break;
    case SB_TPL_MUSCLE: snprintf(buf, n, "muscle (%g, %g, %g) -> (%g, %g, %g), radius %g", p[0], p[1], p[2], p[3], p[4], p[5], p[6]); break;
    default: snprintf(buf, n, "uniform region"); break;
    }
    return buf;
}

int sb_rig_build(const sb_desc *d, const sb_mesh *m, sb_model *o)
{
    static const double gp2[2] = {0.21132486540518711775, 0.78867513459481288225};
    int n = d->subdiv, npt = n * n * n * 8, a, ci, q, k, i;
    double h = o->c * o->unit, w0 = h * h * h / (8.0 * n * n * n);   /* volume of one point's box, m^3 */
    unsigned char *need;
    fracs_t F;
    sb_rig_free(o);
    o->nctl = d->nctl;
    o->ctl = sb_alloc(sizeof(sb_control) * (size_t)(d->nctl ? d->nctl : 1));
    for (a = 0; a < d->nctl; a++) {
        o->ctl[a] = d->ctls[a];
        if (o->ctl[a].joint >= 0) o->ctl[a].joint = o->desc_to_sorted[o->ctl[a].joint];
    }
    o->nrig = d->nrig;
    o->rig = sb_alloc(sizeof(sb_rig) * (size_t)(d->nrig ? d->nrig : 1));
    if (d->nrig == 0) return 0;
    /* geometry, reference modulus; cells each rig's support box touches */
    need = sb_alloc((size_t)(o->nc ? o->nc : 1));
    for (a = 0; a < d->nrig; a++) {
        sb_rig *rg = &o->rig[a];
        double centre[3];
        int mat = 0, r;
        rg->def = d->rigs[a];
        if (rg->def.tpl == SB_TPL_FILE) continue;   /* a fitted field: read below */
        rig_geometry(o, rg, centre);
        for (r = 0; r < d->nmr; r++) if (sb_region_has(o, &d->mrules[r].r, centre)) mat = d->mrules[r].mat;
        rg->E_ref = d->mats[mat].E;
        rg->amp = rg->def.s * rg->E_ref / (rg->L_ref * o->unit);
        for (ci = 0; ci < o->nc; ci++) {
            const double *x0 = o->x + 3 * o->cells[8 * ci];
            int hit = 1;
            for (k = 0; k < 3; k++) if (x0[k] > rg->hi[k] || x0[k] + o->c < rg->lo[k]) hit = 0;
            need[ci] |= (unsigned char)hit;
        }
    }
    fracs_build(d, m, o, need, &F);
    for (a = 0; a < d->nrig; a++) {
        sb_rig *rg = &o->rig[a];
        double *Qv = sb_alloc(sizeof(double) * 3 * (size_t)o->nv), qmax = 0, qall = 0, hb = o->c / (2 * n), lmin = rig_feature(rg);
        int ne = 0, rr;
        if (rg->def.tpl == SB_TPL_FILE) {   /* 'rig_file': a fitted force field (sb_rigfile.c) */
            sb_rigfile rf;
            int drop = 0;
            free(Qv);
            rg->vert = sb_alloc(sizeof(int) * (size_t)(o->nf ? o->nf : 1));
            rg->Q = sb_alloc(sizeof(double) * 3 * (size_t)(o->nf ? o->nf : 1));
            if (sb_rigfile_read(rg->def.file, &rf) || sb_rigfile_apply(&rf, rg->def.file, o, m, d->lod_level, rg->vert, rg->Q, &rg->n, &drop)) {
                char msg[2048];
                snprintf(msg, sizeof msg, "%s", sb_error());
                sb_rigfile_free(&rf); free(need); free(F.slot); free(F.frac);
                return sb_fail("%s:%d: rig '%s': %s", d->path, rg->def.line, rg->def.name, msg);
            }
            if (drop)
                fprintf(stderr, "sinew-bake: warning: %s:%d: rig '%s': %d of the %d forces of '%s' fall on no free lattice vertex "
                        "(skeleton or outside this lattice) and are dropped%s\n", d->path, rg->def.line, rg->def.name, drop,
                        sb_rigfile_pick(&rf, o->c)->n, rg->def.file, d->lod_level ? " (level 1 of 'levels 2')" : "");
            for (i = 0; i < rg->n; i++) {
                rg->qmax = fmax(rg->qmax, sqrt(dot3(rg->Q + 3 * i, rg->Q + 3 * i)));
                for (k = 0; k < 3; k++) rg->total[k] += rg->Q[3 * i + k];
            }
            rg->E_ref = 0; rg->L_ref = 0; rg->amp = 0; rg->refine = 0;
            sb_rigfile_free(&rf);
            continue;
        }
        /* refinement: each quadrature box (edge hb = c/2n, inside fraction frac_q) split
         * into rr^3 mini-boxes with 2x2x2 Gauss points each so that the mini-box edge is
         * <= lmin/8: a rig can be much smaller than a cell (the cow's nostrils) */
        rr = (int)fmin(8.0, fmax(1.0, ceil(hb / (lmin / 8) - 1e-9))); /* clamped before the int conversion */
        rg->refine = rr;
        for (ci = 0; ci < o->nc; ci++) {
            const double *x0 = o->x + 3 * o->cells[8 * ci], *fr = F.slot[ci] >= 0 ? F.frac + (size_t)F.slot[ci] * (size_t)npt : NULL;
            double Qc[8][3];
            int hit = 1;
            if (o->cell_fill[ci] <= 0) continue;
            for (k = 0; k < 3; k++) if (x0[k] > rg->hi[k] || x0[k] + o->c < rg->lo[k]) hit = 0;
            if (!hit) continue;
            memset(Qc, 0, sizeof Qc);
            for (q = 0; q < npt; q++) {
                double wq = w0 * (fr ? fr[q] : 1.0), bl[3], mw;
                int sx = q / 8 % n, sy = q / 8 / n % n, sz = q / 8 / (n * n), gp = q % 8, mx, my, mz, g;
                if (wq == 0) continue;
                /* the box of point q: the octant of its sub-box holding it (sb_lattice_fill.c, step 3) */
                bl[0] = (sx + 0.5 * (gp & 1)) / n; bl[1] = (sy + 0.5 * ((gp >> 1) & 1)) / n; bl[2] = (sz + 0.5 * ((gp >> 2) & 1)) / n;
                hit = 1;
                for (k = 0; k < 3; k++) if (x0[k] + bl[k] * o->c > rg->hi[k] || x0[k] + (bl[k] + 0.5 / n) * o->c < rg->lo[k]) hit = 0;
                if (!hit) continue;
                mw = wq / (8.0 * rr * rr * rr);
                for (mz = 0; mz < rr; mz++) for (my = 0; my < rr; my++) for (mx = 0; mx < rr; mx++)
                    for (g = 0; g < 8; g++) {
                        double t[3], p[3], f[3], N[8];
                        t[0] = bl[0] + (mx + gp2[g & 1]) / rr * (0.5 / n);
                        t[1] = bl[1] + (my + gp2[(g >> 1) & 1]) / rr * (0.5 / n);
                        t[2] = bl[2] + (mz + gp2[(g >> 2) & 1]) / rr * (0.5 / n);
                        for (k = 0; k < 3; k++) p[k] = x0[k] + t[k] * o->c;
                        sb_rig_field(o, rg, p, f);
                        if (f[0] == 0 && f[1] == 0 && f[2] == 0) continue;
                        for (i = 0; i < 8; i++) N[i] = mw * ((i & 1) ? t[0] : 1 - t[0]) * ((i & 2) ? t[1] : 1 - t[1]) * ((i & 4) ? t[2] : 1 - t[2]);
                        for (i = 0; i < 8; i++) for (k = 0; k < 3; k++) Qc[i][k] += N[i] * f[k];
                    }
            }
            for (i = 0; i < 8; i++) for (k = 0; k < 3; k++) Qv[3 * o->cells[8 * ci + i] + k] += Qc[i][k];
        }
        for (i = 0; i < o->nv; i++) {
            double qn = sqrt(dot3(Qv + 3 * i, Qv + 3 * i));
            for (k = 0; k < 3; k++) rg->total[k] += Qv[3 * i + k];
            qall = fmax(qall, qn);
            if (i < o->nf) qmax = fmax(qmax, qn);
        }
        if (!(qmax > 0)) {
            char buf[256];
            free(Qv); free(need); free(F.slot); free(F.frac);
            if (!(qall > 0))
                return sb_fail("%s:%d: rig '%s' touches no free lattice vertex: its support (%s) holds no flesh inside the mesh "
                               "(centre outside the flesh, or a region missing the mesh?)", d->path, rg->def.line, rg->def.name, where(rg, buf, sizeof buf));
            return sb_fail("%s:%d: rig '%s' touches no free lattice vertex: all the flesh in its support (%s) is carried rigidly by bones "
                           "(skeleton vertices); move or widen it, or thin the bones ('bone JOINT R')", d->path, rg->def.line, rg->def.name, where(rg, buf, sizeof buf));
        }
        rg->qmax = qmax;
        for (i = 0; i < o->nf; i++) if (sqrt(dot3(Qv + 3 * i, Qv + 3 * i)) >= 1e-9 * qmax) ne++;
        rg->vert = sb_alloc(sizeof(int) * (size_t)ne);
        rg->Q = sb_alloc(sizeof(double) * 3 * (size_t)ne);
        for (i = 0; i < o->nf; i++)
            if (sqrt(dot3(Qv + 3 * i, Qv + 3 * i)) >= 1e-9 * qmax) {
                rg->vert[rg->n] = i;
                for (k = 0; k < 3; k++) rg->Q[3 * rg->n + k] = Qv[3 * i + k];
                rg->n++;
            }
        free(Qv);
    }
    free(need); free(F.slot); free(F.frac);
    return 0;
}
