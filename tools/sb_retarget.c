/* sb_retarget.c -- rig retargeting, seed 003 §4.4 (eq. 15-16): characters, the
 * map's set-up, cost, solve and Jacobians. See sb_retarget.h for the cost terms,
 * the Jacobian estimate and the transfer chain; closest points on a surface are
 * sb_retarget_surf.c, statics at rest, the transfer and output sb_retarget_xfer.c. */
#include "sb_retarget_int.h"
#include "sb_lbfgsb.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------- characters ---------------- */

int sb_rt_char_load(const char *desc_path, sb_rt_char *c)
{
    memset(c, 0, sizeof *c);
    if (sb_desc_load(desc_path, &c->d)) { sb_desc_free(&c->d); memset(c, 0, sizeof *c); return -1; }
    if (sb_desc_mesh(&c->d, &c->m, NULL)) {   /* the OBJ, or the glTF's welded skinned mesh */
        sb_mesh_free(&c->m); sb_desc_free(&c->d); memset(c, 0, sizeof *c);
        return -1;
    }
    if (sb_build(&c->d, &c->m, &c->o, 1) || sb_rig_build(&c->d, &c->m, &c->o)) {
        sb_model_free(&c->o); sb_mesh_free(&c->m); sb_desc_free(&c->d); memset(c, 0, sizeof *c);
        return -1;
    }
    c->loaded = 1;
    return 0;
}

int sb_rt_char_load_level1(const char *desc_path, sb_rt_char *c)
{
    memset(c, 0, sizeof *c);
    /* without B's own rigs: the transfer needs the lattice only, and a one-fit
     * rig file of B has no level-1 fit yet */
    if (sb_level1_load(desc_path, 0, &c->d, &c->m, &c->o)) return -1;
    c->loaded = 1;
    return 0;
}

void sb_rt_char_free(sb_rt_char *c)
{
    if (!c->loaded) return;
    sb_model_free(&c->o);
    sb_mesh_free(&c->m);
    sb_desc_free(&c->d);
    memset(c, 0, sizeof *c);
}

void sb_rt_defaults(sb_rt_opts *o)
{
    o->w_skel = 100;
    o->w_surf = 100;
    o->corr = SB_RT_CORR_AUTO;
    o->bone_samples = 3;
    o->rounds = 12;
    o->round_tol = 1e-4;
    o->cg_max = 20000;
    o->cg_tol = 1e-10;
    o->optimizer = SB_RT_OPT_CG;
    o->verbose = 0;
    o->joint_map = NULL;
    o->skip = NULL;
}

/* ---------------- small helpers ---------------- */

static double bbox_diag(const sb_mesh *m)
{
    double d[3] = { m->hi[0] - m->lo[0], m->hi[1] - m->lo[1], m->hi[2] - m->lo[2] };
    return sqrt(dot3(d, d));
}

/* the kept cell of o holding p and its reference coordinates; -1 if none.
 * cmap: kept cell of every grid cell (-1 none), or NULL (a search) */
int sb_rt_locate(const sb_model *o, const int *cmap, const double p[3], double t[3])
{
    int gi[3], k, ci;
    for (k = 0; k < 3; k++) {
        double u = (p[k] - o->gorg[k]) / o->c;
        gi[k] = (int)floor(u);
        if (gi[k] < 0 || gi[k] > o->gn[k] - 2) return -1;
        t[k] = u - gi[k];
    }
    {
        int g = gi[0] + (o->gn[0] - 1) * (gi[1] + (o->gn[1] - 1) * gi[2]);
        if (cmap) return cmap[g];
        for (ci = 0; ci < o->nc; ci++) if (o->cell_grid[ci] == g) return ci;
    }
    return -1;
}

/* point term entries of a point at (cell, t) of A, scaled by s, appended to tm */
void sb_rt_add_point(sb_rt_term *tm, const sb_model *o, int ci, const double t[3], double s)
{
    double N[8];
    int k;
    sb_shape(t, N, NULL);
    for (k = 0; k < 8; k++) {
        if (N[k] == 0) continue;
        tm->v[tm->n] = o->cells[8 * ci + k];
        tm->w[tm->n] = s * N[k];
        tm->n++;
    }
}

static void term_eval(const sb_rt_term *tm, const double *x, double r[3])
{
    int k, a;
    r[0] = -tm->t[0]; r[1] = -tm->t[1]; r[2] = -tm->t[2];
    for (k = 0; k < tm->n; k++)
        for (a = 0; a < 3; a++) r[a] += tm->w[k] * x[3 * tm->v[k] + a];
}

/* ---------------- set-up ---------------- */

static int find_joint(const sb_model *o, const char *name)
{
    int j;
    for (j = 0; j < o->nj; j++) if (!strcmp(o->joints[j].name, name)) return j;
    return -1;
}

/* is name an item of the comma list? (for "a=b" items, the part before '=') */
static const char *list_find(const char *list, const char *name)
{
    size_t n = strlen(name);
    const char *p = list;
    while (p && *p) {
        const char *e = strchr(p, ','), *eq;
        size_t l = e ? (size_t)(e - p) : strlen(p);
        eq = memchr(p, '=', l);
        if ((size_t)((eq ? eq : p + l) - p) == n && !strncmp(p, name, n)) return p;
        p = e ? e + 1 : NULL;
    }
    return NULL;
}

/* B's joint matched to A's joint j: -1 skipped, -2 missing */
static int match_joint(const sb_model *A, const sb_model *B, const sb_rt_opts *opt, int j)
{
    const char *nm = A->joints[j].name, *it;
    char buf[SB_NAME_MAX];
    int jb;
    if (opt->skip && list_find(opt->skip, nm)) return -1;
    if (opt->joint_map && (it = list_find(opt->joint_map, nm)) != NULL) {
        const char *eq = strchr(it, '='), *e = strchr(it, ',');
        size_t l;
        if (!eq || (e && eq > e)) return -2;
        l = e ? (size_t)(e - eq - 1) : strlen(eq + 1);
        if (l >= sizeof buf) return -2;
        memcpy(buf, eq + 1, l); buf[l] = 0;
        nm = buf;
    }
    jb = find_joint(B, nm);
    return jb < 0 ? -2 : jb;
}

/* every item of a joint list names a joint of A (the part before '=') and, for a map, of B (after) */
static int check_list(const sb_model *A, const sb_model *B, const char *list, const char *what)
{
    const char *p = list;
    while (p && *p) {
        const char *e = strchr(p, ','), *eq;
        size_t l = e ? (size_t)(e - p) : strlen(p), la;
        char a[SB_NAME_MAX + 1], b[SB_NAME_MAX + 1];
        eq = memchr(p, '=', l);
        la = eq ? (size_t)(eq - p) : l;
        if (la == 0 || la > SB_NAME_MAX) return sb_fail("retarget: %s: bad item '%.*s'", what, (int)l, p);
        memcpy(a, p, la); a[la] = 0;
        if (find_joint(A, a) < 0) return sb_fail("retarget: %s: A has no joint '%s'", what, a);
        if (B && eq) {
            size_t lb = l - la - 1;
            if (lb == 0 || lb > SB_NAME_MAX) return sb_fail("retarget: %s: bad item '%.*s'", what, (int)l, p);
            memcpy(b, eq + 1, lb); b[lb] = 0;
            if (find_joint(B, b) < 0) return sb_fail("retarget: %s: B has no joint '%s'", what, b);
        } else if (B) return sb_fail("retarget: %s: '%.*s' is not A_JOINT=B_JOINT", what, (int)l, p);
        p = e ? e + 1 : NULL;
    }
    return 0;
}

/* affine least squares G p + g ~ pbar over the skeleton sample points, with a
 * small pull towards the isotropic scale s (so collinear skeletons still give
 * a unique map): rows of G independent, 4x4 normal equations per row */
static void affine_fit(int n, const double *p, const double *pb, double s, double G[9], double g[3])
{
    double M[16], rhs[3][4], cen[3] = { 0, 0, 0 }, cb[3] = { 0, 0, 0 }, spread = 0, eps;
    int i, a, b, r;
    for (i = 0; i < n; i++) for (a = 0; a < 3; a++) { cen[a] += p[3 * i + a] / n; cb[a] += pb[3 * i + a] / n; }
    for (i = 0; i < n; i++) for (a = 0; a < 3; a++) spread += (p[3 * i + a] - cen[a]) * (p[3 * i + a] - cen[a]);
    eps = 1e-6 * (spread > 0 ? spread : 1);
    memset(M, 0, sizeof M); memset(rhs, 0, sizeof rhs);
    for (i = 0; i < n; i++) {
        double u[4] = { p[3 * i] - cen[0], p[3 * i + 1] - cen[1], p[3 * i + 2] - cen[2], 1 };
        for (a = 0; a < 4; a++) {
            for (b = 0; b < 4; b++) M[4 * a + b] += u[a] * u[b];
            for (r = 0; r < 3; r++) rhs[r][a] += u[a] * (pb[3 * i + r] - cb[r]);
        }
    }
    for (a = 0; a < 3; a++) M[5 * a] += eps;
    for (r = 0; r < 3; r++) rhs[r][r] += eps * s;
    /* solve by Gaussian elimination (symmetric positive definite 4x4) for the 3 right-hand sides */
    {
        double A[16], X[3][4];
        int piv, c;
        memcpy(A, M, sizeof A);
        memcpy(X, rhs, sizeof X);
        for (c = 0; c < 4; c++) {
            double d = A[5 * c];
            if (d == 0) d = 1e-300;
            for (piv = c + 1; piv < 4; piv++) {
                double f = A[4 * piv + c] / d;
                for (b = c; b < 4; b++) A[4 * piv + b] -= f * A[4 * c + b];
                for (r = 0; r < 3; r++) X[r][piv] -= f * X[r][c];
            }
        }
        for (c = 3; c >= 0; c--)
            for (r = 0; r < 3; r++) {
                double v = X[r][c];
                for (b = c + 1; b < 4; b++) v -= A[4 * c + b] * X[r][b];
                X[r][c] = v / A[5 * c];
            }
        for (r = 0; r < 3; r++) {
            for (a = 0; a < 3; a++) G[3 * r + a] = X[r][a];
            g[r] = cb[r] + X[r][3] - (G[3 * r] * cen[0] + G[3 * r + 1] * cen[1] + G[3 * r + 2] * cen[2]);
        }
    }
}

int sb_rt_init(sb_retarget *rt, const sb_model *A, const sb_mesh *mA, const sb_model *B, const sb_mesh *mB, const sb_rt_opts *opt)
{
    int j, i, k, a, nmiss = 0, nb, cap, nsamp;
    char miss[1024];
    double *sp = NULL, *spb = NULL, G[9], g[3], s;
    memset(rt, 0, sizeof *rt);
    rt->A = A; rt->B = B; rt->mA = mA; rt->mB = mB;
    rt->opt = *opt;
    rt->nv = A->nv;
    /* inputs finite */
    for (i = 0; i < mA->nv; i++) if (!finite3(mA->v + 3 * i)) return sb_fail("retarget: character A: surface vertex %d is not finite", i);
    for (i = 0; i < mB->nv; i++) if (!finite3(mB->v + 3 * i)) return sb_fail("retarget: character B: surface vertex %d is not finite", i);
    if (!(opt->w_skel >= 0 && opt->w_surf >= 0 && isfinite(opt->w_skel) && isfinite(opt->w_surf) && opt->w_skel + opt->w_surf > 0))
        return sb_fail("retarget: the weights w_skel %g, w_surf %g must be finite, >= 0 and not both 0", opt->w_skel, opt->w_surf);
    /* joints by name: every joint of A must be in B */
    miss[0] = 0;
    rt->jA = sb_alloc(sizeof(int) * (size_t)A->nj);
    rt->jB = sb_alloc(sizeof(int) * (size_t)A->nj);
    if (check_list(A, B, opt->joint_map, "joint map") || check_list(A, NULL, opt->skip, "skipped joints")) { sb_rt_free(rt); return -1; }
    for (j = 0; j < A->nj; j++) {
        int jb = match_joint(A, B, opt, j);
        if (jb == -1) continue;
        if (jb < 0) {
            size_t l = strlen(miss);
            if (l + SB_NAME_MAX + 4 < sizeof miss) snprintf(miss + l, sizeof miss - l, "%s%s", nmiss ? ", " : "", A->joints[j].name);
            nmiss++;
            continue;
        }
        rt->jA[rt->njm] = j; rt->jB[rt->njm] = jb; rt->njm++;
    }
    if (nmiss) {
        sb_rt_free(rt);
        return sb_fail("retarget: %d joint(s) of A have no joint of the same name in B: %s (match them to other names or skip them)", nmiss, miss);
    }
    if (rt->njm < 1) { sb_rt_free(rt); return sb_fail("retarget: no joint of A is matched to B"); }
    rt->LA = bbox_diag(mA);
    rt->L = bbox_diag(mB);
    if (!(rt->L > 0 && rt->LA > 0)) { sb_rt_free(rt); return sb_fail("retarget: a character's surface has an empty bounding box"); }
    rt->cref = A->c * rt->L / rt->LA;
    rt->corr = opt->corr == SB_RT_CORR_AUTO ? (mA->nv == mB->nv ? SB_RT_CORR_VERTEX : SB_RT_CORR_CLOSEST) : opt->corr;
    if (rt->corr == SB_RT_CORR_VERTEX && mA->nv != mB->nv) {
        sb_rt_free(rt);
        return sb_fail("retarget: a vertex correspondence needs the same surface vertex count (A %d, B %d)", mA->nv, mB->nv);
    }
    /* skeleton samples: joints, then bone interiors */
    nb = opt->bone_samples > 0 ? opt->bone_samples : 0;
    cap = rt->njm * (1 + nb);
    sp = sb_alloc(sizeof(double) * 3 * (size_t)cap);
    spb = sb_alloc(sizeof(double) * 3 * (size_t)cap);
    nsamp = 0;
    for (k = 0; k < rt->njm; k++) {
        memcpy(sp + 3 * nsamp, A->joints[rt->jA[k]].pos, 3 * sizeof(double));
        memcpy(spb + 3 * nsamp, B->joints[rt->jB[k]].pos, 3 * sizeof(double));
        nsamp++;
    }
    for (k = 0; k < rt->njm; k++) {
        int pa = A->joints[rt->jA[k]].parent, pb;
        if (pa < 0) continue;
        pb = match_joint(A, B, opt, pa);
        if (pb < 0) continue;
        for (i = 1; i <= nb; i++) {
            double u = (double)i / (nb + 1);
            for (a = 0; a < 3; a++) {
                sp[3 * nsamp + a] = (1 - u) * A->joints[pa].pos[a] + u * A->joints[rt->jA[k]].pos[a];
                spb[3 * nsamp + a] = (1 - u) * B->joints[pb].pos[a] + u * B->joints[rt->jB[k]].pos[a];
            }
            nsamp++;
        }
    }
    /* terms: skeleton + surface (capacity) + distortion */
    {
        int nsurf = rt->corr == SB_RT_CORR_VERTEX ? mA->nv : mA->nv + mB->nv;
        int ndmax = A->nv * 9;
        rt->term = sb_alloc(sizeof(sb_rt_term) * (size_t)(nsamp + nsurf + ndmax));
    }
    for (i = 0; i < nsamp; i++) {
        double t[3];
        int ci = sb_rt_locate(A, NULL, sp + 3 * i, t);
        sb_rt_term *tm;
        if (ci < 0) continue;   /* a bone sample outside the lattice (cannot happen for joints) */
        tm = &rt->term[rt->nsk++];
        sb_rt_add_point(tm, A, ci, t, 1.0);
        memcpy(tm->t, spb + 3 * i, sizeof tm->t);
    }
    for (i = 0; i < rt->nsk; i++) rt->term[i].f = opt->w_skel / (rt->nsk * rt->L * rt->L);
    /* distortion stencils on A's grid (the surface terms go between, filled by sb_rt_update_surface) */
    {
        int nsurf = rt->corr == SB_RT_CORR_VERTEX ? mA->nv : mA->nv + mB->nv, d0 = rt->nsk + nsurf, ax, bx;
        int st[3] = { 1, A->gn[0], A->gn[0] * A->gn[1] };
        sb_rt_term *D = rt->term + d0;
        for (i = 0; i < A->nv; i++) {
            int gv = A->v_grid[i], gc[3];
            gc[0] = gv % A->gn[0]; gc[1] = (gv / A->gn[0]) % A->gn[1]; gc[2] = gv / (A->gn[0] * A->gn[1]);
            for (ax = 0; ax < 3; ax++) {   /* pure: i is the middle vertex */
                int lo, hi;
                if (gc[ax] < 1 || gc[ax] > A->gn[ax] - 2) continue;
                lo = A->gvert[gv - st[ax]]; hi = A->gvert[gv + st[ax]];
                if (lo < 0 || hi < 0) continue;
                D[rt->nd].n = 3;
                D[rt->nd].v[0] = lo; D[rt->nd].w[0] = 1;
                D[rt->nd].v[1] = i; D[rt->nd].w[1] = -2;
                D[rt->nd].v[2] = hi; D[rt->nd].w[2] = 1;
                rt->nd++;
            }
            for (ax = 0; ax < 3; ax++)     /* mixed: i is the low corner of a face */
                for (bx = ax + 1; bx < 3; bx++) {
                    int u, v, w;
                    if (gc[ax] > A->gn[ax] - 2 || gc[bx] > A->gn[bx] - 2) continue;
                    u = A->gvert[gv + st[ax]]; v = A->gvert[gv + st[bx]]; w = A->gvert[gv + st[ax] + st[bx]];
                    if (u < 0 || v < 0 || w < 0) continue;
                    D[rt->nd].n = 4;
                    D[rt->nd].v[0] = i; D[rt->nd].w[0] = 1;
                    D[rt->nd].v[1] = u; D[rt->nd].w[1] = -1;
                    D[rt->nd].v[2] = v; D[rt->nd].w[2] = -1;
                    D[rt->nd].v[3] = w; D[rt->nd].w[3] = 1;
                    rt->nd++;
                }
        }
        for (i = 0; i < rt->nd; i++) D[i].f = 1.0 / (rt->nd * rt->cref * rt->cref);
        rt->nsf = nsurf;   /* fixed slot count; unused slots have n = 0, f = 0 */
        rt->nterm = d0 + rt->nd;
    }
    if (rt->nsk < 1) { free(sp); free(spb); sb_rt_free(rt); return sb_fail("retarget: no skeleton sample of A lies in its lattice"); }
    /* initial map: affine fit of the skeleton samples */
    s = rt->L / rt->LA;
    affine_fit(nsamp, sp, spb, s, G, g);
    free(sp); free(spb);
    rt->h = sb_alloc(sizeof(double) * 3 * (size_t)rt->nv);
    for (i = 0; i < rt->nv; i++)
        for (a = 0; a < 3; a++) rt->h[3 * i + a] = dot3(G + 3 * a, A->x + 3 * i) + g[a];
    if (sb_rt_update_surface(rt)) { sb_rt_free(rt); return -1; }
    return 0;
}

void sb_rt_free(sb_retarget *rt)
{
    free(rt->h); free(rt->jA); free(rt->jB); free(rt->term); free(rt->J);
    memset(rt, 0, sizeof *rt);
}

/* ---------------- cost, gradient, solve ---------------- */

/* sum f |r|^2 over terms; grad += 2 f r w; with targets zero (notgt) it is the Hessian product / 2 x */
static double eval_terms(const sb_retarget *rt, const double *x, double *grad, double parts[3], int notgt)
{
    double c[3] = { 0, 0, 0 };
    int i, k, a;
    for (i = 0; i < rt->nterm; i++) {
        const sb_rt_term *tm = &rt->term[i];
        double r[3], e;
        int part = i < rt->nsk ? 0 : i < rt->nsk + rt->nsf ? 1 : 2;
        if (!tm->n || tm->f == 0) continue;
        term_eval(tm, x, r);
        if (notgt) for (a = 0; a < 3; a++) r[a] += tm->t[a];
        e = tm->f * dot3(r, r);
        c[part] += e;
        if (grad)
            for (k = 0; k < tm->n; k++)
                for (a = 0; a < 3; a++) grad[3 * tm->v[k] + a] += 2 * tm->f * tm->w[k] * r[a];
    }
    if (parts) { parts[0] = c[0]; parts[1] = c[1]; parts[2] = c[2]; }
    return c[0] + c[1] + c[2];
}

double sb_rt_cost(const sb_retarget *rt, const double *x, double *grad, double parts[3])
{
    if (grad) memset(grad, 0, sizeof(double) * 3 * (size_t)rt->nv);
    return eval_terms(rt, x, grad, parts, 0);
}

/* one round: minimize the quadratic C by Jacobi-preconditioned CG from rt->h */
static int cg_round(sb_retarget *rt, int *iters)
{
    int n = 3 * rt->nv, i, k, it;
    double *r = sb_alloc(sizeof(double) * (size_t)n), *z = sb_alloc(sizeof(double) * (size_t)n);
    double *p = sb_alloc(sizeof(double) * (size_t)n), *Hp = sb_alloc(sizeof(double) * (size_t)n);
    double *dg = sb_alloc(sizeof(double) * (size_t)rt->nv), rz, r0;
    for (i = 0; i < rt->nterm; i++) {
        const sb_rt_term *tm = &rt->term[i];
        for (k = 0; k < tm->n; k++) dg[tm->v[k]] += 2 * tm->f * tm->w[k] * tm->w[k];
    }
    sb_rt_cost(rt, rt->h, r, NULL);
    for (i = 0; i < n; i++) r[i] = -r[i];
    r0 = norm(r, n);
    rz = 0;
    for (i = 0; i < n; i++) { z[i] = dg[i / 3] > 0 ? r[i] / dg[i / 3] : r[i]; p[i] = z[i]; rz += r[i] * z[i]; }
    for (it = 0; it < rt->opt.cg_max && norm(r, n) > rt->opt.cg_tol * r0 && r0 > 0; it++) {
        double pHp = 0, al, rz1 = 0, be;
        memset(Hp, 0, sizeof(double) * (size_t)n);
        eval_terms(rt, p, Hp, NULL, 1);
        for (i = 0; i < n; i++) pHp += p[i] * Hp[i];
        if (!(pHp > 0)) break;
        al = rz / pHp;
        for (i = 0; i < n; i++) { rt->h[i] += al * p[i]; r[i] -= al * Hp[i]; }
        for (i = 0; i < n; i++) { z[i] = dg[i / 3] > 0 ? r[i] / dg[i / 3] : r[i]; rz1 += r[i] * z[i]; }
        be = rz1 / rz; rz = rz1;
        for (i = 0; i < n; i++) p[i] = z[i] + be * p[i];
    }
    *iters = it;
    free(r); free(z); free(p); free(Hp); free(dg);
    return 0;
}

static double lb_fn(void *ctx, const double *x, double *grad) { return sb_rt_cost((const sb_retarget *)ctx, x, grad, NULL); }

/* one round by L-BFGS-B (no bounds), stopping at the same relative gradient as CG */
static int lbfgsb_round(sb_retarget *rt, int *iters)
{
    sb_opt_opts o;
    sb_opt_result r;
    double *g = sb_alloc(sizeof(double) * 3 * (size_t)rt->nv), g0 = 0;
    int i;
    sb_rt_cost(rt, rt->h, g, NULL);
    for (i = 0; i < 3 * rt->nv; i++) g0 = fmax(g0, fabs(g[i]));
    free(g);
    sb_opt_defaults(&o);
    o.m = 10;
    o.max_iter = rt->opt.cg_max;
    o.pgtol = rt->opt.cg_tol * g0;
    o.ftol = 0;
    o.label = "retarget lbfgsb";
    memset(&r, 0, sizeof r);
    sb_lbfgsb(3 * rt->nv, rt->h, NULL, NULL, lb_fn, rt, &o, &r, NULL);
    *iters = r.iterations;
    return r.status < 0 ? -1 : 0;
}

static void residual_stats(sb_retarget *rt)
{
    int i;
    double s2 = 0, mx = 0;
    for (i = 0; i < rt->nsk; i++) {
        double r[3], d;
        term_eval(&rt->term[i], rt->h, r);
        d = sqrt(dot3(r, r)); s2 += d * d; if (d > mx) mx = d;
    }
    rt->skel_rms = rt->nsk ? sqrt(s2 / rt->nsk) : 0; rt->skel_max = mx;
    s2 = 0; mx = 0;
    {
        int n = 0;
        for (i = rt->nsk; i < rt->nsk + rt->nsf; i++) {
            double r[3], d;
            const sb_rt_term *tm = &rt->term[i];
            if (!tm->n) continue;
            term_eval(tm, rt->h, r);
            d = sqrt(dot3(r, r)); s2 += d * d; if (d > mx) mx = d; n++;
        }
        rt->surf_rms = n ? sqrt(s2 / n) : 0; rt->surf_max = mx;
    }
}

int sb_rt_solve(sb_retarget *rt)
{
    double t0 = sb_now(), prev = -1, parts[3];
    int round, nr = rt->corr == SB_RT_CORR_VERTEX ? 1 : (rt->opt.rounds > 0 ? rt->opt.rounds : 1);
    double *g = sb_alloc(sizeof(double) * 3 * (size_t)rt->nv);
    rt->cg_iters = 0;
    for (round = 0; round < nr; round++) {
        int it = 0;
        double c;
        if (round > 0 && sb_rt_update_surface(rt)) { free(g); return -1; }
        if (rt->opt.verbose && round == 0) {
            fflush(stdout);   /* progress goes to stderr: keep the order of the lines */
            c = sb_rt_cost(rt, rt->h, g, parts);
            fprintf(stderr, "retarget: start    cost %.6e (skel %.3e, surf %.3e, distort %.3e), |grad| %.3e\n", c, parts[0], parts[1], parts[2],
                   norm(g, 3 * rt->nv));
        }
        if (rt->opt.optimizer == SB_RT_OPT_LBFGSB) { if (lbfgsb_round(rt, &it)) { free(g); return sb_fail("retarget: L-BFGS-B refused the problem (non-finite cost?)"); } }
        else cg_round(rt, &it);
        rt->cg_iters += it;
        c = sb_rt_cost(rt, rt->h, g, parts);
        if (!isfinite(c)) { free(g); return sb_fail("retarget: the cost is not finite after round %d", round + 1); }
        rt->gnorm = norm(g, 3 * rt->nv);
        if (rt->opt.verbose)
            fprintf(stderr, "retarget: round %2d cost %.6e (skel %.3e, surf %.3e, distort %.3e), |grad| %.3e, %d %s iterations, %.2f s\n",
                   round + 1, c, parts[0], parts[1], parts[2], rt->gnorm, it, rt->opt.optimizer == SB_RT_OPT_LBFGSB ? "L-BFGS-B" : "CG", sb_now() - t0);
        rt->rounds = round + 1;
        if (prev >= 0 && prev - c <= rt->opt.round_tol * prev) break;
        prev = c;
    }
    /* final costs with the last targets */
    rt->cost = sb_rt_cost(rt, rt->h, g, parts);
    rt->c_skel = parts[0]; rt->c_surf = parts[1]; rt->c_dist = parts[2];
    rt->gnorm = norm(g, 3 * rt->nv);
    residual_stats(rt);
    rt->secs = sb_now() - t0;
    free(g);
    return 0;
}

/* ---------------- Jacobians (eq. 16) ---------------- */

int sb_rt_jacobians(sb_retarget *rt)
{
    const sb_model *A = rt->A;
    int i, p, a, b;
    free(rt->J);
    rt->J = sb_alloc(sizeof(double) * 9 * (size_t)rt->nv);
    for (i = 0; i < rt->nv; i++) {
        double EE[9] = { 0 }, BE[9] = { 0 }, inv[9];
        for (p = A->nbptr[i]; p < A->nbptr[i + 1]; p++) {
            int j = A->nb[p];
            double e[3], eb[3];
            if (j == i) continue;
            for (a = 0; a < 3; a++) { e[a] = A->x[3 * j + a] - A->x[3 * i + a]; eb[a] = rt->h[3 * j + a] - rt->h[3 * i + a]; }
            for (a = 0; a < 3; a++)
                for (b = 0; b < 3; b++) { EE[3 * a + b] += e[a] * e[b]; BE[3 * a + b] += eb[a] * e[b]; }
        }
        if (inv3(EE, inv) == 0) return sb_fail("retarget: lattice vertex %d: its neighbours do not span 3-D (no Jacobian)", i);
        for (a = 0; a < 3; a++)
            for (b = 0; b < 3; b++) rt->J[9 * i + 3 * a + b] = BE[3 * a] * inv[b] + BE[3 * a + 1] * inv[3 + b] + BE[3 * a + 2] * inv[6 + b];
    }
    return 0;
}

