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

int sb_fit_open(sb_fit *F, const char *desc, int quiet)
{
    char err[300];
    sb_desc d;
    unsigned c;
    memset(F, 0, sizeof *F);
    snprintf(F->desc, sizeof F->desc, "%s", desc);
    F->quiet = quiet;
    if (sb_bake_file(desc, SB_DOUBLE, 1, &F->o, &F->b)) { fprintf(stderr, "sinew-rig: error: %s\n", sb_error()); return -1; }
    if (snref_load(&F->m, F->b.bytes, F->b.size, err, sizeof err)) { fprintf(stderr, "sinew-rig: reading the baked blob: %s\n", err); return -1; }
    if (snref_init(&F->s, &F->m)) { fprintf(stderr, "sinew-rig: out of memory\n"); return -1; }
    memset(&d, 0, sizeof d);
    if (sb_desc_load(desc, &d) || sb_mesh_load_obj(d.mesh_path, &F->mesh)) {
        fprintf(stderr, "sinew-rig: error: %s\n", sb_error());
        sb_desc_free(&d);
        return -1;
    }
    sb_desc_free(&d);
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
        double h = 1e-7, fp, fm;
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
} surf_ctx;

static double surf_fn(void *ctx, const double *z, double *g)
{
    surf_ctx *S = ctx;
    const snref_model *m = &S->F->m;
    unsigned s, k, c, e, nF = m->nF;
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

int sb_fit_surface(sb_fit *F, const double *target, double omega, const sb_opt_opts *oo, sb_opt_result *res,
                   double *eta_rest, double *fit)
{
    const snref_model *m = &F->m;
    surf_ctx S;
    unsigned nF = m->nF, i, s, k, c;
    double *z = calloc(3 * (size_t)nF + 1, sizeof *z), *d = malloc(3 * (size_t)m->nS * sizeof *d), *eta = calloc(3 * (size_t)nF + 1, sizeof *eta);
    double D2 = 0;
    int st;
    if (!z || !d || !eta) { free(z); free(d); free(eta); return -1; }
    for (i = 0; i < 3 * m->nS; i++) { d[i] = target[i] - F->surf0[i]; D2 += d[i] * d[i]; }
    D2 /= m->nS;
    if (!(D2 > 0)) D2 = 1;
    S.F = F; S.d = d; S.omega = omega; S.inv_ns = 1.0 / (m->nS * D2); S.inv_ne = 1.0 / (12.0 * m->nC * D2); S.r = NULL;
    st = sb_lbfgsb(3 * (int)nF, z, NULL, NULL, surf_fn, &S, oo, res, NULL);
    /* eta = A z (internal units), then newtons in each vertex's rest frame */
    for (i = 0; i < 3 * nF; i++) z[i] /= m->unit;
    snref_hess_mul(&F->s, z, eta);
    for (i = 0; i < nF; i++) {
        const double *R = F->s.R + 9 * i, *e = eta + 3 * i;
        for (k = 0; k < 3; k++) eta_rest[3 * i + k] = (R[k] * e[0] + R[3 + k] * e[1] + R[6 + k] * e[2]) / F->nscale;
    }
    if (fit) {
        for (s = 0; s < m->nS; s++) {
            unsigned cell[8];
            double w[8];
            embed(m, s, cell, w);
            for (c = 0; c < 3; c++) fit[3 * s + c] = F->surf0[3 * s + c];
            for (k = 0; k < 8; k++) if (cell[k] < nF) for (c = 0; c < 3; c++) fit[3 * s + c] += w[k] * z[3 * cell[k] + c] * m->unit;
        }
    }
    free(z); free(d); free(eta);
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
