/* sb_fit.c -- rig fitting (seed 003 §4.2-4.3): see sb_fit.h for the costs.
 *
 * The static equilibrium (eq. 10) at a fixed pose is linear in the rig
 * force: A q = b + R Q. The tool solves it once for the shape without the
 * fitted rig (p0) and keeps A's banded LU factor, so each optimizer
 * evaluation costs one forward and (point-drag) one adjoint back-substitution.
 * Surface rigs are optimized over the displacement z = A^-1 R eta they cause
 * (A is invertible: the same set of shapes as optimizing eta, §4 "bijection
 * between generalized forces and displacements"), which needs no solve at all
 * and keeps the problem well conditioned; eta = R^T A z at the end. */
#include "sb_fit.h"
#include "sb_static.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

void sb_rotvec_quat(const double r[3], double q[4])
{
    double th = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]), s;
    s = th > 1e-12 ? sin(0.5 * th) / th : 0.5 - th * th / 48;
    q[0] = s * r[0]; q[1] = s * r[1]; q[2] = s * r[2]; q[3] = cos(0.5 * th);
}

void sb_quat_rotvec(const double q0[4], double r[3])
{
    double q[4], sn, th;
    int k;
    for (k = 0; k < 4; k++) q[k] = q0[3] < 0 ? -q0[k] : q0[k];
    sn = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    th = 2 * atan2(sn, q[3]);
    for (k = 0; k < 3; k++) r[k] = sn > 1e-300 ? q[k] / sn * th : 2 * q[k];
}

int sb_fit_open(sb_fit *F, const char *desc, int quiet) { return sb_fit_open_level(F, desc, 0, quiet); }

int sb_fit_open_level(sb_fit *F, const char *desc, int level, int quiet)
{
    char err[300];
    unsigned c;
    memset(F, 0, sizeof *F);
    snprintf(F->desc, sizeof F->desc, "%s", desc);
    F->quiet = quiet;
    F->level = level;
    if (level ? sb_bake_level1(desc, SB_DOUBLE, &F->o, &F->b) : sb_bake_file(desc, SB_DOUBLE, 1, &F->o, &F->b)) {
        fprintf(stderr, "sinew-rig: error: %s%s\n", level ? "level 1: " : "", sb_error());
        return -1;
    }
    if (snref_load(&F->m, F->b.bytes, F->b.size, err, sizeof err)) { fprintf(stderr, "sinew-rig: reading the baked blob: %s\n", err); return -1; }
    if (snref_init(&F->s, &F->m)) { fprintf(stderr, "sinew-rig: out of memory\n"); return -1; }
    if (sb_desc_load(desc, &F->d) || sb_mesh_load_obj(F->d.mesh_path, &F->mesh)) {
        fprintf(stderr, "sinew-rig: error: %s\n", sb_error());
        return -1;
    }
    for (c = 0; c < 3; c++) F->off[c] = F->o.x[c] - F->m.rest[c] * F->m.unit;
    F->nscale = F->o.h * F->o.h / (F->b.m0 * F->m.unit * F->o.unit);
    F->p0 = calloc(3 * (size_t)F->m.nV, sizeof *F->p0);
    F->surf0 = calloc(3 * (size_t)F->m.nS, sizeof *F->surf0);
    if (!F->p0 || !F->surf0) { fprintf(stderr, "sinew-rig: out of memory\n"); return -1; }
    return 0;
}

void sb_fit_close(sb_fit *F)
{
    if (F->B) snref_factor_free(F->B);
    free(F->p0); free(F->surf0);
    if (F->s.m) snref_release(&F->s);
    snref_free(&F->m);
    sb_blob_free(&F->b);
    sb_rig_free(&F->o);
    sb_model_free(&F->o);
    sb_mesh_free(&F->mesh);
    sb_desc_free(&F->d);
    memset(F, 0, sizeof *F);
}

void sb_fit_surface_of(const sb_fit *F, const double *lat, double *surf)
{
    const snref_model *m = &F->m;
    unsigned i, k, c;
    for (i = 0; i < m->nS; i++) {
        const unsigned *cell = m->cells + 8 * m->ecell[i];
        const double *t = m->et + 3 * i;
        double p[3] = {0, 0, 0};
        for (k = 0; k < 8; k++) {
            double w = ((k & 1) ? t[0] : 1 - t[0]) * ((k >> 1 & 1) ? t[1] : 1 - t[1]) * ((k >> 2 & 1) ? t[2] : 1 - t[2]);
            for (c = 0; c < 3; c++) p[c] += w * lat[3 * cell[k] + c];
        }
        for (c = 0; c < 3; c++) surf[3 * i + c] = p[c] * m->unit + F->off[c];
    }
}

int sb_fit_set_pose(sb_fit *F, const snref_xform *pose, double rig_scale)
{
    double res;
    unsigned i;
    snref_set_pose(&F->s, pose);
    F->s.rig_scale = rig_scale;
    /* start from the skinned shape: the solve's relative residual is measured
     * against the start's (already at equilibrium it could not fall) */
    snref_get_skinned(&F->s, F->p0);
    for (i = 0; i < 3 * F->m.nF; i++) F->s.p[i] = F->p0[i] / F->m.unit;
    res = snref_static(&F->s, 0);
    if (!(res <= 1e-6)) { fprintf(stderr, "sinew-rig: the static solve did not converge (relative residual %.3g)\n", res); return -1; }
    memcpy(F->p0, F->s.p, 3 * (size_t)F->m.nV * sizeof *F->p0);
    sb_fit_surface_of(F, F->p0, F->surf0);
    if (F->B) snref_factor_free(F->B);
    F->B = snref_factor(&F->s);
    if (!F->B) { fprintf(stderr, "sinew-rig: the lattice is too large for the banded factor (%u free vertices)\n", F->m.nF); return -1; }
    return 0;
}

void sb_fit_skinned_surface(sb_fit *F, const snref_xform *pose, double *surf)
{
    double *lat = malloc(3 * (size_t)F->m.nV * sizeof *lat);
    unsigned i;
    if (!lat) return;
    snref_set_pose(&F->s, pose);
    snref_get_skinned(&F->s, lat);   /* mesh units */
    for (i = 0; i < 3 * F->m.nV; i++) lat[i] /= F->m.unit;
    sb_fit_surface_of(F, lat, surf);
    free(lat);
}

/* embedding of surface vertex v: corners and weights */
static void embed(const snref_model *m, unsigned v, unsigned cell[8], double w[8])
{
    const double *t = m->et + 3 * v;
    unsigned k;
    for (k = 0; k < 8; k++) {
        cell[k] = m->cells[8 * m->ecell[v] + k];
        w[k] = ((k & 1) ? t[0] : 1 - t[0]) * ((k >> 1 & 1) ? t[1] : 1 - t[1]) * ((k >> 2 & 1) ? t[2] : 1 - t[2]);
    }
}

/* ---------------- pose fit ---------------- */

typedef struct {
    sb_fit *F;
    const int *feat, *joints;
    int nfeat, nj;
    const double *target;
    double *local, *lat, inv_c2;
    snref_xform *pose;
} pose_ctx;

static double pose_cost(pose_ctx *P, const double *x)
{
    sb_fit *F = P->F;
    const snref_model *m = &F->m;
    double root[3] = {0, 0, 0}, C = 0;
    int a, k;
    for (a = 0; a < P->nj; a++) sb_rotvec_quat(x + 3 * a, P->local + 4 * P->joints[a]);
    sb_pose_from_local(m, P->local, root, P->pose);
    snref_set_pose(&F->s, P->pose);
    snref_get_skinned(&F->s, P->lat);
    if (F->pose_static) {   /* the static equilibrium from the skinned start, in mesh units */
        unsigned i;
        F->s.rig_scale = F->pose_rig_scale;
        for (i = 0; i < 3 * m->nF; i++) F->s.p[i] = P->lat[i] / m->unit;
        if (!(snref_static(&F->s, 0) <= 1e-6)) return NAN;
        for (i = 0; i < 3 * m->nF; i++) P->lat[i] = F->s.p[i] * m->unit;
    }
    for (a = 0; a < P->nfeat; a++) {
        unsigned cell[8];
        double w[8], p[3] = {0, 0, 0};
        embed(m, (unsigned)P->feat[a], cell, w);
        for (k = 0; k < 8; k++) { p[0] += w[k] * P->lat[3 * cell[k]]; p[1] += w[k] * P->lat[3 * cell[k] + 1]; p[2] += w[k] * P->lat[3 * cell[k] + 2]; }
        for (k = 0; k < 3; k++) { double e = p[k] + F->off[k] - P->target[3 * a + k]; C += e * e; }
    }
    return C * P->inv_c2 / P->nfeat;
}

static double pose_fn(void *ctx, const double *x, double *g)
{
    pose_ctx *P = ctx;
    double xx[3 * 64], f = pose_cost(P, x);
    int i, n = 3 * P->nj;
    memcpy(xx, x, (size_t)n * sizeof *xx);
    for (i = 0; i < n; i++) {   /* central differences */
        double h = P->F->pose_static ? 1e-5 : 1e-7, fp, fm;
        xx[i] = x[i] + h; fp = pose_cost(P, xx);
        xx[i] = x[i] - h; fm = pose_cost(P, xx);
        xx[i] = x[i];
        g[i] = (fp - fm) / (2 * h);
    }
    return f;
}

int sb_fit_pose(sb_fit *F, const int *feat, int nfeat, const double *target, const int *joints, int nj, double *local,
                const sb_opt_opts *oo, sb_opt_result *res)
{
    pose_ctx P;
    double x[3 * 64], lo[3 * 64], hi[3 * 64], cm = F->m.cell * F->m.unit;
    int a, k, st;
    if (nj < 1 || nj > 64 || nfeat < 1) { fprintf(stderr, "sinew-rig: pose fit: want 1..64 joints and at least one feature point\n"); return -1; }
    P.F = F; P.feat = feat; P.joints = joints; P.nfeat = nfeat; P.nj = nj; P.target = target; P.local = local;
    P.inv_c2 = 1 / (cm * cm);
    P.lat = malloc(3 * (size_t)F->m.nV * sizeof *P.lat);
    P.pose = malloc(F->m.nJ * sizeof *P.pose);
    if (!P.lat || !P.pose) { free(P.lat); free(P.pose); return -1; }
    for (a = 0; a < nj; a++) {
        sb_quat_rotvec(local + 4 * joints[a], x + 3 * a);
        for (k = 0; k < 3; k++) { lo[3 * a + k] = -PI; hi[3 * a + k] = PI; }
    }
    st = sb_lbfgsb(3 * nj, x, lo, hi, pose_fn, &P, oo, res, NULL);
    pose_cost(&P, x);   /* leaves local at the fit */
    free(P.lat); free(P.pose);
    return st < 0 ? -1 : 0;
}

/* ---------------- surface rig ---------------- */

typedef struct {
    sb_fit *F;
    const double *d;     /* nS x 3 target displacement from surf0 */
    double omega, inv_ns, inv_ne;
    double *r;           /* nS x 3 residual scratch */
    unsigned nfree;      /* lattice vertices that move: nF (the rig), nV (a diagnostic: skeleton vertices freed too) */
} surf_ctx;

static double surf_fn(void *ctx, const double *z, double *g)
{
    surf_ctx *S = ctx;
    const snref_model *m = &S->F->m;
    unsigned s, k, c, e, nF = S->nfree;
    static const unsigned char ed[12][2] = {{0,1},{2,3},{4,5},{6,7},{0,2},{1,3},{4,6},{5,7},{0,4},{1,5},{2,6},{3,7}};
    double cs = 0, cm = 0;
    memset(g, 0, 3 * (size_t)nF * sizeof *g);
    for (s = 0; s < m->nS; s++) {
        unsigned cell[8];
        double w[8], r[3];
        embed(m, s, cell, w);
        for (c = 0; c < 3; c++) r[c] = -S->d[3 * s + c];
        for (k = 0; k < 8; k++) if (cell[k] < nF) for (c = 0; c < 3; c++) r[c] += w[k] * z[3 * cell[k] + c];
        for (c = 0; c < 3; c++) cs += r[c] * r[c];
        for (k = 0; k < 8; k++) if (cell[k] < nF) for (c = 0; c < 3; c++) g[3 * cell[k] + c] += 2 * S->inv_ns * w[k] * r[c];
    }
    for (e = 0; e < m->nC; e++) {
        const unsigned *cell = m->cells + 8 * e;
        for (k = 0; k < 12; k++) {
            unsigned a = cell[ed[k][0]], b = cell[ed[k][1]];
            for (c = 0; c < 3; c++) {
                double za = a < nF ? z[3 * a + c] : 0, zb = b < nF ? z[3 * b + c] : 0, dz = za - zb;
                cm += dz * dz;
                if (a < nF) g[3 * a + c] += 2 * S->omega * S->inv_ne * dz;
                if (b < nF) g[3 * b + c] -= 2 * S->omega * S->inv_ne * dz;
            }
        }
    }
    return S->inv_ns * cs + S->omega * S->inv_ne * cm;
}

/* The surface cost is quadratic in z: C(z) = z^T H z - 2 b^T z + 1, the same
 * H for x, y and z (sparse, the lattice's 27-point stencil), so its minimum
 * is the solution of the normal equations H z = b. Solved by conjugate
 * gradients preconditioned by diag(H) (Jacobi): exact to rounding in a few
 * hundred iterations, where L-BFGS-B on the raw displacements needs thousands
 * (omega 1e-5 leaves the interior vertices, which only the smoothing term
 * sees, 1e5 times softer than the surface's). Products H p by surf_fn with a
 * zero target (gradient 2 H p). omega 0 is allowed (H then singular but the
 * system consistent: CG from 0 stays in H's range and reaches the
 * least-squares fit of minimum norm). Deterministic: fixed order of
 * operations. Returns the status (SB_OPT_PGTOL or SB_OPT_MAXITER). */
static int surf_cg(surf_ctx *S, double *z, const sb_opt_opts *oo, sb_opt_result *res)
{
    const snref_model *m = &S->F->m;
    static const unsigned char ed[12][2] = {{0,1},{2,3},{4,5},{6,7},{0,2},{1,3},{4,6},{5,7},{0,4},{1,5},{2,6},{3,7}};
    size_t n = 3 * (size_t)S->nfree, i;
    unsigned nF = S->nfree, s, k, e;
    double *r = malloc(n * sizeof *r), *p = malloc(n * sizeof *p), *q = malloc(n * sizeof *q), *h = calloc(nF + 1, sizeof *h);
    double *zero = calloc(3 * (size_t)m->nS + 1, sizeof *zero), rz, rz1, g0 = 0, gi = 0, f;
    const double *d = S->d;
    const char *label = oo->label ? oo->label : "cg";
    int it = 0, st = SB_OPT_MAXITER;
    if (!r || !p || !q || !h || !zero) { free(r); free(p); free(q); free(h); free(zero); return -1; }
    /* diag(H) per vertex (the same for its three components) */
    for (s = 0; s < m->nS; s++) {
        unsigned cell[8];
        double w[8];
        embed(m, s, cell, w);
        for (k = 0; k < 8; k++) if (cell[k] < nF) h[cell[k]] += S->inv_ns * w[k] * w[k];
    }
    for (e = 0; e < m->nC; e++)
        for (k = 0; k < 12; k++) {
            unsigned a = m->cells[8 * e + ed[k][0]], b = m->cells[8 * e + ed[k][1]];
            if (a < nF) h[a] += S->omega * S->inv_ne;
            if (b < nF) h[b] += S->omega * S->inv_ne;
        }
    for (i = 0; i < nF; i++) if (!(h[i] > 0)) h[i] = 1;   /* a row of zeros: its residual stays 0 */
    /* r = b - H z = -g(z) / 2 */
    f = surf_fn(S, z, r);
    for (i = 0; i < n; i++) { r[i] *= -0.5; g0 = fmax(g0, 2 * fabs(r[i])); }
    if (oo->verbose > 0) fprintf(stderr, "%s: iter %5d  f %.15g  |pg|inf %.3e\n", label, 0, f, g0);
    for (i = 0, rz = 0; i < n; i++) { p[i] = r[i] / h[i / 3]; rz += r[i] * p[i]; }
    gi = g0;
    while (gi > oo->pgtol && gi > 1e-14 * g0) {
        double pq = 0, a;
        if (it >= oo->max_iter) break;
        S->d = zero; surf_fn(S, p, q); S->d = d;   /* q = 2 H p */
        for (i = 0; i < n; i++) { q[i] *= 0.5; pq += p[i] * q[i]; }
        if (!(pq > 0)) break;
        a = rz / pq;
        for (i = 0, rz1 = 0, gi = 0; i < n; i++) {
            z[i] += a * p[i]; r[i] -= a * q[i];
            rz1 += r[i] * r[i] / h[i / 3]; gi = fmax(gi, 2 * fabs(r[i]));
        }
        for (i = 0; i < n; i++) p[i] = r[i] / h[i / 3] + rz1 / rz * p[i];
        rz = rz1;
        it++;
        if (oo->verbose > 0 && it % oo->verbose == 0)
            fprintf(stderr, "%s: iter %5d  f %.15g  |pg|inf %.3e\n", label, it, surf_fn(S, z, q), gi);
    }
    /* the true gradient at the end (not the recurrence's) */
    f = surf_fn(S, z, q);
    for (i = 0, gi = 0; i < n; i++) gi = fmax(gi, fabs(q[i]));
    if (gi <= oo->pgtol || gi <= 1e-12 * g0) st = SB_OPT_PGTOL;
    if (oo->verbose > 0)
        fprintf(stderr, "%s: conjugate gradients %s after %d iterations: f %.15g, |pg|inf %.3e\n", label,
                st == SB_OPT_PGTOL ? "converged" : "stopped at max_iter", it, f, gi);
    if (res) { res->iterations = it; res->evaluations = it + 2; res->f = f; res->pgnorm = gi; res->status = st; }
    free(r); free(p); free(q); free(h); free(zero);
    return st;
}

static int surf_setup(sb_fit *F, const double *target, double omega, surf_ctx *S, double **d)
{
    const snref_model *m = &F->m;
    double D2 = 0;
    unsigned i;
    if (!(*d = malloc(3 * (size_t)m->nS * sizeof **d))) return -1;
    for (i = 0; i < 3 * m->nS; i++) { (*d)[i] = target[i] - F->surf0[i]; D2 += (*d)[i] * (*d)[i]; }
    D2 /= m->nS;
    if (!(D2 > 0)) D2 = 1;
    S->F = F; S->d = *d; S->omega = omega; S->inv_ns = 1.0 / (m->nS * D2); S->inv_ne = 1.0 / (12.0 * m->nC * D2); S->r = NULL; S->nfree = m->nF;
    return 0;
}

/* surface of p0 + z (z in mesh units, as the optimizer's variables) */
static void surf_fit(const sb_fit *F, const double *z, unsigned nfree, double *fit)
{
    const snref_model *m = &F->m;
    unsigned s, k, c;
    for (s = 0; s < m->nS; s++) {
        unsigned cell[8];
        double w[8];
        embed(m, s, cell, w);
        for (c = 0; c < 3; c++) fit[3 * s + c] = F->surf0[3 * s + c];
        for (k = 0; k < 8; k++) if (cell[k] < nfree) for (c = 0; c < 3; c++) fit[3 * s + c] += w[k] * z[3 * cell[k] + c];
    }
}

int sb_fit_surface(sb_fit *F, const double *target, double omega, const sb_opt_opts *oo, sb_opt_result *res,
                   double *eta_rest, double *fit)
{
    const snref_model *m = &F->m;
    surf_ctx S;
    unsigned nF = m->nF, i, k;
    double *z = calloc(3 * (size_t)nF + 1, sizeof *z), *d = NULL, *eta = calloc(3 * (size_t)nF + 1, sizeof *eta);
    int st;
    if (!z || !eta || surf_setup(F, target, omega, &S, &d)) { free(z); free(d); free(eta); return -1; }
    st = F->surf_lbfgsb ? sb_lbfgsb(3 * (int)nF, z, NULL, NULL, surf_fn, &S, oo, res, NULL) : surf_cg(&S, z, oo, res);
    if (fit) surf_fit(F, z, m->nF, fit);
    /* eta = A z (internal units), then newtons in each vertex's rest frame */
    for (i = 0; i < 3 * nF; i++) z[i] /= m->unit;
    snref_hess_mul(&F->s, z, eta);
    for (i = 0; i < nF; i++) {
        const double *R = F->s.R + 9 * i, *e = eta + 3 * i;
        for (k = 0; k < 3; k++) eta_rest[3 * i + k] = (R[k] * e[0] + R[3 + k] * e[1] + R[6 + k] * e[2]) / F->nscale;
    }
    free(z); free(d); free(eta);
    return st < 0 ? -1 : 0;
}

int sb_fit_surface_reach(sb_fit *F, const double *target, const sb_opt_opts *oo, sb_surf_reach *out, double *best)
{
    const snref_model *m = &F->m;
    surf_ctx S;
    sb_opt_opts o1 = *oo;
    sb_opt_result rr;
    unsigned nF = m->nF, s, k, c;
    double *z = calloc(3 * (size_t)nF + 1, sizeof *z), *d = NULL, *fit = malloc(3 * (size_t)m->nS * sizeof *fit);
    double *fit0 = malloc(3 * (size_t)m->nS * sizeof *fit0), d2 = 0, dm = 0;
    int st = 0, pass;
    memset(out, 0, sizeof *out);
    if (!z || !fit || !fit0 || surf_setup(F, target, 0, &S, &d)) { free(z); free(d); free(fit); free(fit0); return -1; }
    for (s = 0; s < m->nS; s++) {   /* where the target's displacement sits */
        unsigned cell[8];
        double w[8], ws = 0, dd = 0;
        embed(m, s, cell, w);
        for (k = 0; k < 8; k++) if (cell[k] >= nF) ws += w[k];
        for (c = 0; c < 3; c++) dd += d[3 * s + c] * d[3 * s + c];
        d2 += dd; dm = fmax(dm, dd);
        if (ws >= 0.5) out->skel_half += dd;
        if (ws > 1 - 1e-12) out->skel_all += dd;
    }
    if (d2 > 0) { out->skel_half /= d2; out->skel_all /= d2; }
    o1.verbose = 0;
    for (pass = 0; pass < 2; pass++) {   /* 0: the free vertices (the rig); 1: every lattice vertex (as if no bone carried any) */
        double r2 = 0, rm = 0;
        if (pass == 1) {
            free(z);
            if (!(z = calloc(3 * (size_t)m->nV + 1, sizeof *z))) { free(d); free(fit); free(fit0); return -1; }
            S.nfree = m->nV;
        }
        st = surf_cg(&S, z, &o1, &rr);
        if (pass == 0) out->iterations = rr.iterations, out->status = st;
        surf_fit(F, z, S.nfree, pass ? fit : fit0);
        for (s = 0; s < m->nS; s++) {
            double r = 0;
            for (c = 0; c < 3; c++) {
                double e = (pass ? fit : fit0)[3 * s + c] - target[3 * s + c];
                r += e * e;
            }
            r2 += r; rm = fmax(rm, r);
        }
        if (pass) { out->rms_all = d2 > 0 ? sqrt(r2 / d2) : 0; out->max_all = dm > 0 ? sqrt(rm / dm) : 0; }
        else { out->rms = d2 > 0 ? sqrt(r2 / d2) : 0; out->max = dm > 0 ? sqrt(rm / dm) : 0; }
        if (st < 0) break;
    }
    if (best) memcpy(best, fit0, 3 * (size_t)m->nS * sizeof *best);
    free(z); free(d); free(fit); free(fit0);
    return st < 0 ? -1 : 0;
}

/* ---------------- point-drag template fit ---------------- */

typedef struct {
    sb_fit *F;
    const int *rigs, *vert;
    int nr, np;
    const double *target;
    double lambda, inv;
    double *g;           /* nr x nF*3: world load per unit strength */
    double *load, *x, *adj;
} pts_ctx;

static double pts_fn(void *ctx, const double *eta, double *grad)
{
    pts_ctx *P = ctx;
    sb_fit *F = P->F;
    const snref_model *m = &F->m;
    size_t n = 3 * (size_t)m->nF, i;
    int a, k, c;
    double C = 0;
    memset(P->load, 0, n * sizeof *P->load);
    for (a = 0; a < P->nr; a++) {
        double sa = F->o.rig[P->rigs[a]].def.s, f = eta[a] - sa;
        for (i = 0; i < n; i++) P->load[i] += f * P->g[(size_t)a * n + i];
    }
    snref_factor_solve(F->B, P->load, P->x);
    memset(P->adj, 0, n * sizeof *P->adj);
    for (k = 0; k < P->np; k++) {
        unsigned cell[8];
        double w[8], p[3] = {0, 0, 0}, e[3];
        embed(m, (unsigned)P->vert[k], cell, w);
        for (a = 0; a < 8; a++)
            for (c = 0; c < 3; c++) p[c] += w[a] * (F->p0[3 * cell[a] + c] + (cell[a] < m->nF ? P->x[3 * cell[a] + c] : 0));
        for (c = 0; c < 3; c++) { e[c] = p[c] * m->unit + F->off[c] - P->target[3 * k + c]; C += P->inv * e[c] * e[c]; }
        for (a = 0; a < 8; a++)
            if (cell[a] < m->nF) for (c = 0; c < 3; c++) P->adj[3 * cell[a] + c] += 2 * P->inv * e[c] * w[a] * m->unit;
    }
    if (grad) {
        snref_factor_solve(F->B, P->adj, P->x);   /* adjoint: A symmetric */
        for (a = 0; a < P->nr; a++) {
            double sa = F->o.rig[P->rigs[a]].def.s, s = 0;
            for (i = 0; i < n; i++) s += P->x[i] * P->g[(size_t)a * n + i];
            grad[a] = s + 2 * P->lambda * (eta[a] - sa) / (sa * sa);
        }
    }
    for (a = 0; a < P->nr; a++) {
        double sa = F->o.rig[P->rigs[a]].def.s;
        C += P->lambda * (eta[a] - sa) * (eta[a] - sa) / (sa * sa);
    }
    return C;
}

static int pts_setup(sb_fit *F, pts_ctx *P, const int *rigs, int nr, const int *vert, const double *target, int np, double lambda)
{
    const snref_model *m = &F->m;
    size_t n = 3 * (size_t)m->nF;
    int a;
    unsigned e, k;
    double cm = m->cell * m->unit;
    P->F = F; P->rigs = rigs; P->nr = nr; P->vert = vert; P->np = np; P->target = target; P->lambda = lambda;
    P->inv = 1.0 / (np * cm * cm);
    P->g = calloc(n * (size_t)nr + 1, sizeof *P->g);
    P->load = malloc(n * sizeof *P->load); P->x = malloc(n * sizeof *P->x); P->adj = malloc(n * sizeof *P->adj);
    if (!P->g || !P->load || !P->x || !P->adj) return -1;
    for (a = 0; a < nr; a++) {
        unsigned r = (unsigned)rigs[a];
        double tau = snref_tau(m, r, snref_get_control(&F->s, m->rctl[r])), sa = F->o.rig[r].def.s;
        for (e = m->rfe[r]; e < m->rfe[r] + m->rne[r]; e++) {
            unsigned v = m->rvert[e];
            const double *R = F->s.R + 9 * v, *q = m->rforce + 3 * e;
            for (k = 0; k < 3; k++) P->g[(size_t)a * n + 3 * v + k] = tau * (R[3 * k] * q[0] + R[3 * k + 1] * q[1] + R[3 * k + 2] * q[2]) / sa;
        }
    }
    return 0;
}

static void pts_free(pts_ctx *P) { free(P->g); free(P->load); free(P->x); free(P->adj); }

double sb_fit_points_cost(sb_fit *F, const int *rigs, int nr, const int *vert, const double *target, int np, double lambda,
                          const double *eta, double *grad)
{
    pts_ctx P;
    double C = NAN;
    if (!pts_setup(F, &P, rigs, nr, vert, target, np, lambda)) C = pts_fn(&P, eta, grad);
    pts_free(&P);
    return C;
}

int sb_fit_points(sb_fit *F, const int *rigs, int nr, const int *vert, const double *target, int np, double lambda,
                  const double *lo, const double *hi, double *eta, const sb_opt_opts *oo, sb_opt_result *res)
{
    pts_ctx P;
    int st = -1;
    if (!pts_setup(F, &P, rigs, nr, vert, target, np, lambda)) st = sb_lbfgsb(nr, eta, lo, hi, pts_fn, &P, oo, res, NULL);
    pts_free(&P);
    return st < 0 ? -1 : 0;
}

/* ---------------- point-drag with the templates' geometry ---------------- */

/* indices into sb_rigdef.p of the geometric parameters, and the size */
static int geo_idx(int tpl, int *idx)
{
    switch (tpl) {
    case SB_TPL_BUMP: idx[0] = 0; idx[1] = 1; idx[2] = 2; idx[3] = 3; return 4;
    case SB_TPL_RING: idx[0] = 0; idx[1] = 1; idx[2] = 2; idx[3] = 6; idx[4] = 7; return 5;
    case SB_TPL_MUSCLE: { int k; for (k = 0; k < 7; k++) idx[k] = k; return 7; }
    default: return 0;
    }
}
static double geo_size(const sb_rigdef *r)
{
    switch (r->tpl) {
    case SB_TPL_BUMP: return r->p[3];
    case SB_TPL_RING: return r->p[7];
    case SB_TPL_MUSCLE: return r->p[6];
    default: return 1;
    }
}

int sb_fit_template_npar(const sb_fit *F, int rig)
{
    int idx[8];
    return 1 + geo_idx(F->d.rigs[rig].tpl, idx);
}

void sb_fit_template_get(const sb_fit *F, int rig, double *par)
{
    const sb_rigdef *r = &F->d.rigs[rig];
    int idx[8], n = geo_idx(r->tpl, idx), k;
    par[0] = r->s;
    for (k = 0; k < n; k++) par[1 + k] = r->p[idx[k]];
}

void sb_fit_template_apply(const sb_fit *F, int rig, const double *par, sb_rigdef *out)
{
    int idx[8], n, k;
    *out = F->d.rigs[rig];
    n = geo_idx(out->tpl, idx);
    out->s = par[0];
    for (k = 0; k < n; k++) out->p[idx[k]] = par[1 + k];
}

void sb_fit_template_bounds(const sb_fit *F, int rig, double *lo, double *hi)
{
    const sb_rigdef *r = &F->d.rigs[rig];
    int idx[8], n = geo_idx(r->tpl, idx), k;
    double L = geo_size(r);
    lo[0] = -1e6; hi[0] = 1e6;
    for (k = 0; k < n; k++) {
        double v = r->p[idx[k]];
        int is_size = (r->tpl == SB_TPL_BUMP && idx[k] == 3) || (r->tpl == SB_TPL_RING && idx[k] >= 6) || (r->tpl == SB_TPL_MUSCLE && idx[k] == 6);
        if (is_size) { lo[1 + k] = 0.25 * v; hi[1 + k] = 4 * v; }
        else { lo[1 + k] = v - 2 * L; hi[1 + k] = v + 2 * L; }
    }
}

/* rig `rig` integrated with parameters par: its force on the free vertices
 * (nF x 3, newtons, rest axes) by the bake's quadrature. -1 if it reaches no free vertex. */
static int integrate_rig(sb_fit *F, int rig, const double *par, double *Q)
{
    sb_desc d1 = F->d;
    sb_rigdef rd;
    struct sb_rig *save_rig = F->o.rig;
    struct sb_control *save_ctl = F->o.ctl;
    int save_nrig = F->o.nrig, save_nctl = F->o.nctl, rc, i, k;
    sb_fit_template_apply(F, rig, par, &rd);
    d1.rigs = &rd; d1.nrig = 1;
    F->o.rig = NULL; F->o.ctl = NULL; F->o.nrig = F->o.nctl = 0;
    rc = sb_rig_build(&d1, &F->mesh, &F->o);
    memset(Q, 0, 3 * (size_t)F->o.nf * sizeof *Q);
    if (!rc) for (i = 0; i < F->o.rig[0].n; i++) for (k = 0; k < 3; k++) Q[3 * F->o.rig[0].vert[i] + k] = F->o.rig[0].Q[3 * i + k];
    sb_rig_free(&F->o);
    F->o.rig = save_rig; F->o.ctl = save_ctl; F->o.nrig = save_nrig; F->o.nctl = save_nctl;
    return rc;
}

typedef struct {
    sb_fit *F;
    const int *rigs, *vert;
    int nr, np, npar;
    const double *target;
    double lambda, inv;
    double *par0, *scale, *tau;   /* npar, npar, nr */
    double *Q0;                   /* nr x nF*3: world load (rhs units) at the description's parameters */
    double *Q, *Qp, *Qm, *load, *x, *adj, *dl;
} tpl_ctx;

/* world right-hand-side load of rest-frame newtons Qn (nF x 3) times t */
static void to_load(const sb_fit *F, const double *Qn, double t, double *out)
{
    unsigned i, k;
    for (i = 0; i < F->m.nF; i++) {
        const double *R = F->s.R + 9 * i, *q = Qn + 3 * i;
        for (k = 0; k < 3; k++) out[3 * i + k] = t * F->nscale * (R[3 * k] * q[0] + R[3 * k + 1] * q[1] + R[3 * k + 2] * q[2]);
    }
}

static double tpl_fn(void *ctx, const double *par, double *grad)
{
    tpl_ctx *P = ctx;
    sb_fit *F = P->F;
    const snref_model *m = &F->m;
    size_t n = 3 * (size_t)m->nF, i;
    int a, k, c, off = 0;
    double C = 0;
    memset(P->load, 0, n * sizeof *P->load);
    for (a = 0; a < P->nr; a++) {
        int na = sb_fit_template_npar(F, P->rigs[a]);
        if (integrate_rig(F, P->rigs[a], par + off, P->Q)) return NAN;
        to_load(F, P->Q, P->tau[a], P->dl);
        for (i = 0; i < n; i++) P->load[i] += P->dl[i] - P->Q0[(size_t)a * n + i];
        off += na;
    }
    snref_factor_solve(F->B, P->load, P->x);
    memset(P->adj, 0, n * sizeof *P->adj);
    for (k = 0; k < P->np; k++) {
        unsigned cell[8];
        double w[8], p[3] = {0, 0, 0}, e[3];
        embed(m, (unsigned)P->vert[k], cell, w);
        for (a = 0; a < 8; a++)
            for (c = 0; c < 3; c++) p[c] += w[a] * (F->p0[3 * cell[a] + c] + (cell[a] < m->nF ? P->x[3 * cell[a] + c] : 0));
        for (c = 0; c < 3; c++) { e[c] = p[c] * m->unit + F->off[c] - P->target[3 * k + c]; C += P->inv * e[c] * e[c]; }
        for (a = 0; a < 8; a++)
            if (cell[a] < m->nF) for (c = 0; c < 3; c++) P->adj[3 * cell[a] + c] += 2 * P->inv * e[c] * w[a] * m->unit;
    }
    for (k = 0; k < P->npar; k++) { double u = (par[k] - P->par0[k]) / P->scale[k]; C += P->lambda * u * u; }
    if (grad) {
        snref_factor_solve(F->B, P->adj, P->x);   /* adjoint (A symmetric) */
        off = 0;
        for (a = 0; a < P->nr; a++) {
            int na = sb_fit_template_npar(F, P->rigs[a]), j;
            double *pp = malloc((size_t)na * sizeof *pp);
            memcpy(pp, par + off, (size_t)na * sizeof *pp);
            for (j = 0; j < na; j++) {
                double s = 0;
                if (j == 0) {   /* strength: Q linear in s */
                    integrate_rig(F, P->rigs[a], pp, P->Q);
                    to_load(F, P->Q, P->tau[a] / pp[0], P->dl);
                } else {        /* geometry: central difference of the integration */
                    double h = 1e-4 * P->scale[off + j], v = pp[j];
                    pp[j] = v + h; if (integrate_rig(F, P->rigs[a], pp, P->Qp)) memset(P->Qp, 0, n * sizeof *P->Qp);
                    pp[j] = v - h; if (integrate_rig(F, P->rigs[a], pp, P->Qm)) memset(P->Qm, 0, n * sizeof *P->Qm);
                    pp[j] = v;
                    for (i = 0; i < n; i++) P->Q[i] = (P->Qp[i] - P->Qm[i]) / (2 * h);
                    to_load(F, P->Q, P->tau[a], P->dl);
                }
                for (i = 0; i < n; i++) s += P->x[i] * P->dl[i];
                grad[off + j] = s + 2 * P->lambda * (par[off + j] - P->par0[off + j]) / (P->scale[off + j] * P->scale[off + j]);
            }
            free(pp);
            off += na;
        }
    }
    return C;
}

static int tpl_setup(sb_fit *F, tpl_ctx *P, const int *rigs, int nr, const int *vert, const double *target, int np, double lambda)
{
    const snref_model *m = &F->m;
    size_t n = 3 * (size_t)m->nF;
    int a, off = 0, k;
    double cm = m->cell * m->unit;
    memset(P, 0, sizeof *P);
    P->F = F; P->rigs = rigs; P->nr = nr; P->vert = vert; P->np = np; P->target = target; P->lambda = lambda;
    P->inv = 1.0 / (np * cm * cm);
    for (a = 0; a < nr; a++) P->npar += sb_fit_template_npar(F, rigs[a]);
    P->par0 = malloc((size_t)P->npar * sizeof *P->par0); P->scale = malloc((size_t)P->npar * sizeof *P->scale);
    P->tau = malloc((size_t)nr * sizeof *P->tau);
    P->Q0 = calloc(n * (size_t)nr + 1, sizeof *P->Q0);
    P->Q = malloc(n * sizeof *P->Q); P->Qp = malloc(n * sizeof *P->Qp); P->Qm = malloc(n * sizeof *P->Qm);
    P->load = malloc(n * sizeof *P->load); P->x = malloc(n * sizeof *P->x); P->adj = malloc(n * sizeof *P->adj); P->dl = malloc(n * sizeof *P->dl);
    if (!P->par0 || !P->scale || !P->tau || !P->Q0 || !P->Q || !P->Qp || !P->Qm || !P->load || !P->x || !P->adj || !P->dl) return -1;
    for (a = 0; a < nr; a++) {
        unsigned r = (unsigned)rigs[a];
        int na = sb_fit_template_npar(F, rigs[a]);
        double L = geo_size(&F->d.rigs[r]);
        P->tau[a] = sb_rig_tau(&F->d.rigs[r], snref_get_control(&F->s, m->rctl[r]));   /* the description's tau (unnormalized) */
        sb_fit_template_get(F, rigs[a], P->par0 + off);
        P->scale[off] = fabs(P->par0[off]) > 0 ? fabs(P->par0[off]) : 1;
        for (k = 1; k < na; k++) P->scale[off + k] = L;
        if (integrate_rig(F, rigs[a], P->par0 + off, P->Q)) return -1;
        to_load(F, P->Q, P->tau[a], P->Q0 + (size_t)a * n);
        off += na;
    }
    return 0;
}

static void tpl_free(tpl_ctx *P)
{
    free(P->par0); free(P->scale); free(P->tau); free(P->Q0); free(P->Q); free(P->Qp); free(P->Qm);
    free(P->load); free(P->x); free(P->adj); free(P->dl);
}

double sb_fit_template_cost(sb_fit *F, const int *rigs, int nr, const int *vert, const double *target, int np, double lambda,
                            const double *par, double *grad)
{
    tpl_ctx P;
    double C = NAN;
    if (!tpl_setup(F, &P, rigs, nr, vert, target, np, lambda)) C = tpl_fn(&P, par, grad);
    tpl_free(&P);
    return C;
}

int sb_fit_template(sb_fit *F, const int *rigs, int nr, const int *vert, const double *target, int np, double lambda,
                    const double *lo, const double *hi, double *par, const sb_opt_opts *oo, sb_opt_result *res)
{
    tpl_ctx P;
    int st = -1;
    if (!tpl_setup(F, &P, rigs, nr, vert, target, np, lambda)) st = sb_lbfgsb(P.npar, par, lo, hi, tpl_fn, &P, oo, res, NULL);
    tpl_free(&P);
    return st < 0 ? -1 : 0;
}
