/* sb_retarget.c -- rig retargeting, seed 003 §4.4 (eq. 15-16). See sb_retarget.h
 * for the cost terms, the Jacobian estimate and the transfer chain. */
#include "sb_retarget.h"
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

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static int finite3(const double *p) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]); }

/* 3x3 inverse (row-major); returns the determinant (0: singular, out untouched) */
static double inv3(const double *a, double *o)
{
    double c[9], det;
    int k;
    c[0] = a[4] * a[8] - a[5] * a[7]; c[1] = a[2] * a[7] - a[1] * a[8]; c[2] = a[1] * a[5] - a[2] * a[4];
    c[3] = a[5] * a[6] - a[3] * a[8]; c[4] = a[0] * a[8] - a[2] * a[6]; c[5] = a[2] * a[3] - a[0] * a[5];
    c[6] = a[3] * a[7] - a[4] * a[6]; c[7] = a[1] * a[6] - a[0] * a[7]; c[8] = a[0] * a[4] - a[1] * a[3];
    det = a[0] * c[0] + a[1] * c[3] + a[2] * c[6];
    if (det == 0 || !isfinite(det)) return 0;
    for (k = 0; k < 9; k++) o[k] = c[k] / det;
    return det;
}

static double bbox_diag(const sb_mesh *m)
{
    double d[3] = { m->hi[0] - m->lo[0], m->hi[1] - m->lo[1], m->hi[2] - m->lo[2] };
    return sqrt(dot3(d, d));
}

/* the kept cell of o holding p and its reference coordinates; -1 if none.
 * cmap: kept cell of every grid cell (-1 none), or NULL (a search) */
static int locate(const sb_model *o, const int *cmap, const double p[3], double t[3])
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
static void add_point(sb_rt_term *tm, const sb_model *o, int ci, const double t[3], double s)
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
        int ci = locate(A, NULL, sp + 3 * i, t);
        sb_rt_term *tm;
        if (ci < 0) continue;   /* a bone sample outside the lattice (cannot happen for joints) */
        tm = &rt->term[rt->nsk++];
        add_point(tm, A, ci, t, 1.0);
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

/* ---------------- closest points ---------------- */

/* closest point of triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5):
 * barycentric weights out, returns the squared distance */
static double closest_tri(const double *p, const double *a, const double *b, const double *c, double bw[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3], d1, d2, d3, d4, d5, d6, va, vb, vc, v, w, q[3];
    int k;
    for (k = 0; k < 3; k++) { ab[k] = b[k] - a[k]; ac[k] = c[k] - a[k]; ap[k] = p[k] - a[k]; }
    d1 = dot3(ab, ap); d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) { bw[0] = 1; bw[1] = 0; bw[2] = 0; goto done; }
    for (k = 0; k < 3; k++) bp[k] = p[k] - b[k];
    d3 = dot3(ab, bp); d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) { bw[0] = 0; bw[1] = 1; bw[2] = 0; goto done; }
    vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) { v = d1 / (d1 - d3); bw[0] = 1 - v; bw[1] = v; bw[2] = 0; goto done; }
    for (k = 0; k < 3; k++) cp[k] = p[k] - c[k];
    d5 = dot3(ab, cp); d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) { bw[0] = 0; bw[1] = 0; bw[2] = 1; goto done; }
    vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) { w = d2 / (d2 - d6); bw[0] = 1 - w; bw[1] = 0; bw[2] = w; goto done; }
    va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6)); bw[0] = 0; bw[1] = 1 - w; bw[2] = w; goto done;
    }
    {
        double den = 1 / (va + vb + vc);
        v = vb * den; w = vc * den; bw[0] = 1 - v - w; bw[1] = v; bw[2] = w;
    }
done:
    for (k = 0; k < 3; k++) q[k] = bw[0] * a[k] + bw[1] * b[k] + bw[2] * c[k] - p[k];
    return dot3(q, q);
}

/* closest point of a triangle soup (positions P, nt triangles): a uniform grid
 * of buckets over the triangles' bounding boxes, searched in shells of cells
 * around the query until the best distance is below the shell's reach */
typedef struct tri_index {
    int nt;
    const int *tri;
    const double *P;
    double *box;            /* nt x 6 bounding boxes */
    double lo[3], h;        /* grid corner and cell edge */
    int n[3];               /* cells per axis */
    int *start, *items;     /* CSR: triangles of each cell */
} tri_index;

static int gclamp(int v, int n) { return v < 0 ? 0 : v >= n ? n - 1 : v; }

static void tri_index_make(tri_index *x, const double *P, const int *tri, int nt)
{
    double hi[3], ext = 0, vol = 1;
    int t, k, a, ncell, *cnt;
    memset(x, 0, sizeof *x);
    x->nt = nt; x->tri = tri; x->P = P;
    x->box = sb_alloc(sizeof(double) * 6 * (size_t)nt);
    for (a = 0; a < 3; a++) { x->lo[a] = 1e300; hi[a] = -1e300; }
    for (t = 0; t < nt; t++)
        for (a = 0; a < 3; a++) {
            double lo = 1e300, hh = -1e300;
            for (k = 0; k < 3; k++) { double v = P[3 * tri[3 * t + k] + a]; if (v < lo) lo = v; if (v > hh) hh = v; }
            x->box[6 * t + a] = lo; x->box[6 * t + 3 + a] = hh;
            if (lo < x->lo[a]) x->lo[a] = lo;
            if (hh > hi[a]) hi[a] = hh;
        }
    for (a = 0; a < 3; a++) { ext = fmax(ext, hi[a] - x->lo[a]); vol *= fmax(hi[a] - x->lo[a], 1e-300); }
    /* about one triangle per cell, at most 64 cells per axis */
    x->h = fmax(cbrt(vol / (nt > 0 ? nt : 1)), ext / 64);
    if (!(x->h > 0)) x->h = 1;
    for (a = 0; a < 3; a++) x->n[a] = gclamp((int)((hi[a] - x->lo[a]) / x->h) + 1, 65);
    ncell = x->n[0] * x->n[1] * x->n[2];
    x->start = sb_alloc(sizeof(int) * (size_t)(ncell + 1));
    cnt = sb_alloc(sizeof(int) * (size_t)(ncell + 1));
    for (k = 0; k < 2; k++) {   /* count, then fill */
        for (t = 0; t < nt; t++) {
            int c0[3], c1[3], i, j, l;
            for (a = 0; a < 3; a++) {
                c0[a] = gclamp((int)floor((x->box[6 * t + a] - x->lo[a]) / x->h), x->n[a]);
                c1[a] = gclamp((int)floor((x->box[6 * t + 3 + a] - x->lo[a]) / x->h), x->n[a]);
            }
            for (l = c0[2]; l <= c1[2]; l++)
                for (j = c0[1]; j <= c1[1]; j++)
                    for (i = c0[0]; i <= c1[0]; i++) {
                        int c = i + x->n[0] * (j + x->n[1] * l);
                        if (k == 0) x->start[c + 1]++;
                        else x->items[x->start[c] + cnt[c]++] = t;
                    }
        }
        if (k == 0) {
            for (t = 0; t < ncell; t++) x->start[t + 1] += x->start[t];
            x->items = sb_alloc(sizeof(int) * (size_t)(x->start[ncell] + 1));
        }
    }
    free(cnt);
}

static void tri_index_free(tri_index *x)
{
    free(x->box); free(x->start); free(x->items);
    memset(x, 0, sizeof *x);
}

static void tri_test(const tri_index *x, int t, const double p[3], double *best, int *bt, double bw[3])
{
    const double *bx = x->box + 6 * t;
    double d = 0, e, w[3], dd;
    int a;
    for (a = 0; a < 3; a++) {
        e = p[a] < bx[a] ? bx[a] - p[a] : p[a] > bx[3 + a] ? p[a] - bx[3 + a] : 0;
        d += e * e;
    }
    if (d > *best) return;
    dd = closest_tri(p, x->P + 3 * x->tri[3 * t], x->P + 3 * x->tri[3 * t + 1], x->P + 3 * x->tri[3 * t + 2], w);
    /* ties: the lower triangle index, so the answer does not depend on the visiting order */
    if (dd < *best || (dd == *best && t < *bt)) { *best = dd; *bt = t; memcpy(bw, w, 3 * sizeof(double)); }
}

static int tri_closest(const tri_index *x, const double p[3], double bw[3])
{
    double best = 1e300;
    int bt = -1, c[3], a, r, rmax = 0;
    for (a = 0; a < 3; a++) {
        c[a] = gclamp((int)floor((p[a] - x->lo[a]) / x->h), x->n[a]);
        rmax = c[a] > rmax ? c[a] : rmax;
        rmax = x->n[a] - 1 - c[a] > rmax ? x->n[a] - 1 - c[a] : rmax;
    }
    for (r = 0; r <= rmax; r++) {
        int i, j, l;
        for (l = c[2] - r; l <= c[2] + r; l++) {
            if (l < 0 || l >= x->n[2]) continue;
            for (j = c[1] - r; j <= c[1] + r; j++) {
                if (j < 0 || j >= x->n[1]) continue;
                for (i = c[0] - r; i <= c[0] + r; i++) {
                    int cc, q;
                    if (i < 0 || i >= x->n[0]) continue;
                    if (abs(i - c[0]) != r && abs(j - c[1]) != r && abs(l - c[2]) != r) continue;   /* the shell only */
                    cc = i + x->n[0] * (j + x->n[1] * l);
                    for (q = x->start[cc]; q < x->start[cc + 1]; q++) tri_test(x, x->items[q], p, &best, &bt, bw);
                }
            }
        }
        /* every triangle not yet seen lies in cells at least r cells away: farther than r h */
        if (bt >= 0 && best < (r * x->h) * (r * x->h)) break;
    }
    return bt;
}

/* mapped position of A's surface vertex k */
static void mapped_surface_point(const sb_retarget *rt, int k, double out[3])
{
    const sb_model *A = rt->A;
    double N[8];
    int c, a;
    sb_shape(A->emb_t + 3 * k, N, NULL);
    out[0] = out[1] = out[2] = 0;
    for (c = 0; c < 8; c++)
        for (a = 0; a < 3; a++) out[a] += N[c] * rt->h[3 * A->cells[8 * A->emb_cell[k] + c] + a];
}

int sb_rt_update_surface(sb_retarget *rt)
{
    const sb_model *A = rt->A;
    const sb_mesh *mA = rt->mA, *mB = rt->mB;
    sb_rt_term *S = rt->term + rt->nsk;
    double L2 = rt->L * rt->L;
    int k;
    memset(S, 0, sizeof(sb_rt_term) * (size_t)rt->nsf);
    if (rt->corr == SB_RT_CORR_VERTEX) {
        for (k = 0; k < mA->nv; k++) {
            add_point(&S[k], A, A->emb_cell[k], A->emb_t + 3 * k, 1.0);
            memcpy(S[k].t, mB->v + 3 * k, sizeof S[k].t);
            S[k].f = rt->opt.w_surf / (mA->nv * L2);
        }
        rt->nsa = mA->nv;
        return 0;
    }
    {
        double *hs = sb_alloc(sizeof(double) * 3 * (size_t)mA->nv);
        tri_index tb, ta;
        for (k = 0; k < mA->nv; k++) {
            mapped_surface_point(rt, k, hs + 3 * k);
            if (!finite3(hs + 3 * k)) { free(hs); return sb_fail("retarget: the map is not finite (surface vertex %d of A)", k); }
        }
        tri_index_make(&tb, mB->v, mB->tri, mB->nt);
        tri_index_make(&ta, hs, A->tri, A->nt);
        /* A -> B: mapped A vertex to its closest point on B */
        for (k = 0; k < mA->nv; k++) {
            double bw[3];
            int t = tri_closest(&tb, hs + 3 * k, bw), c, a;
            add_point(&S[k], A, A->emb_cell[k], A->emb_t + 3 * k, 1.0);
            for (a = 0; a < 3; a++) {
                S[k].t[a] = 0;
                for (c = 0; c < 3; c++) S[k].t[a] += bw[c] * mB->v[3 * mB->tri[3 * t + c] + a];
            }
            S[k].f = 0.5 * rt->opt.w_surf / (mA->nv * L2);
        }
        /* B -> A: B vertex to the closest point of the mapped A surface (fixed triangle and weights) */
        for (k = 0; k < mB->nv; k++) {
            double bw[3];
            int t = tri_closest(&ta, mB->v + 3 * k, bw), c;
            sb_rt_term *tm = &S[mA->nv + k];
            for (c = 0; c < 3; c++) {
                int sv = A->tri[3 * t + c];
                if (bw[c] != 0) add_point(tm, A, A->emb_cell[sv], A->emb_t + 3 * sv, bw[c]);
            }
            memcpy(tm->t, mB->v + 3 * k, sizeof tm->t);
            tm->f = 0.5 * rt->opt.w_surf / (mB->nv * L2);
        }
        rt->nsa = mA->nv;
        free(hs); tri_index_free(&tb); tri_index_free(&ta);
    }
    return 0;
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

static double norm(const double *v, int n)
{
    double s = 0;
    int i;
    for (i = 0; i < n; i++) s += v[i] * v[i];
    return sqrt(s);
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

/* ---------------- static equilibrium at rest (eq. 10) ---------------- */

/* y = S_FF x over free rows (x, y: nf x 3) */
static void sff_mul(const sb_model *o, const double *x, double *y)
{
    int i, p, a, b;
    for (i = 0; i < o->nf; i++) {
        double s[3] = { 0, 0, 0 };
        for (p = o->nbptr[i]; p < o->nbptr[i + 1]; p++) {
            int j = o->nb[p];
            const double *S = o->S + 9 * (size_t)p;
            if (j >= o->nf) continue;
            for (a = 0; a < 3; a++)
                for (b = 0; b < 3; b++) s[a] += S[3 * a + b] * x[3 * j + b];
        }
        for (a = 0; a < 3; a++) y[3 * i + a] = s[a];
    }
}

void sb_rt_force_of(const sb_model *o, const double *q, double *Q)
{
    double *x = sb_alloc(sizeof(double) * 3 * (size_t)o->nf);
    int i;
    for (i = 0; i < 3 * o->nf; i++) x[i] = q[i] * o->unit;   /* metres */
    sff_mul(o, x, Q);
    free(x);
}

double sb_rt_static(const sb_model *o, const double *Q, double *q)
{
    int n = 3 * o->nf, i, it, p;
    double *x = sb_alloc(sizeof(double) * (size_t)n), *r = sb_alloc(sizeof(double) * (size_t)n);
    double *z = sb_alloc(sizeof(double) * (size_t)n), *d = sb_alloc(sizeof(double) * (size_t)n), *Ad = sb_alloc(sizeof(double) * (size_t)n);
    double *Pinv = sb_alloc(sizeof(double) * 9 * (size_t)o->nf), rz = 0, bn, res;
    /* block-Jacobi preconditioner */
    for (i = 0; i < o->nf; i++) {
        p = sb_pattern_find(o, i, i);
        if (p < 0 || inv3(o->S + 9 * (size_t)p, Pinv + 9 * (size_t)i) == 0) { Pinv[9 * i] = Pinv[9 * i + 4] = Pinv[9 * i + 8] = 1; }
    }
    for (i = 0; i < n; i++) r[i] = Q[i];
    bn = norm(r, n);
    for (i = 0; i < o->nf; i++) {
        int a;
        for (a = 0; a < 3; a++) z[3 * i + a] = dot3(Pinv + 9 * i + 3 * a, r + 3 * i);
    }
    for (i = 0; i < n; i++) { d[i] = z[i]; rz += r[i] * z[i]; }
    for (it = 0; it < 20 * n + 100 && bn > 0 && norm(r, n) > 1e-13 * bn; it++) {
        double dAd = 0, al, rz1 = 0;
        int a;
        sff_mul(o, d, Ad);
        for (i = 0; i < n; i++) dAd += d[i] * Ad[i];
        if (!(dAd > 0)) break;
        al = rz / dAd;
        for (i = 0; i < n; i++) { x[i] += al * d[i]; r[i] -= al * Ad[i]; }
        for (i = 0; i < o->nf; i++)
            for (a = 0; a < 3; a++) z[3 * i + a] = dot3(Pinv + 9 * i + 3 * a, r + 3 * i);
        for (i = 0; i < n; i++) rz1 += r[i] * z[i];
        for (i = 0; i < n; i++) d[i] = z[i] + rz1 / rz * d[i];
        rz = rz1;
    }
    /* true residual */
    sff_mul(o, x, Ad);
    for (i = 0; i < n; i++) r[i] = Q[i] - Ad[i];
    res = bn > 0 ? norm(r, n) / bn : 0;
    memset(q, 0, sizeof(double) * 3 * (size_t)o->nv);
    for (i = 0; i < n; i++) q[i] = x[i] / o->unit;   /* mesh units */
    free(x); free(r); free(z); free(d); free(Ad); free(Pinv);
    return isfinite(res) ? res : -1;
}

/* rest position of o's surface vertex k from its embedding */
static void sb_rt_surface_point(const sb_model *o, int k, double y[3])
{
    double N[8];
    int c, a;
    sb_shape(o->emb_t + 3 * k, N, NULL);
    y[0] = y[1] = y[2] = 0;
    for (c = 0; c < 8; c++)
        for (a = 0; a < 3; a++) y[a] += N[c] * o->x[3 * o->cells[8 * o->emb_cell[k] + c] + a];
}

void sb_rt_surface(const sb_model *o, const double *q, double *s)
{
    int k, c, a;
    for (k = 0; k < o->ns; k++) {
        double N[8];
        sb_shape(o->emb_t + 3 * k, N, NULL);
        for (a = 0; a < 3; a++) s[3 * k + a] = 0;
        for (c = 0; c < 8; c++) {
            int v = o->cells[8 * o->emb_cell[k] + c];
            for (a = 0; a < 3; a++) s[3 * k + a] += N[c] * (o->x[3 * v + a] + (q ? q[3 * v + a] : 0));
        }
    }
}

int sb_rt_rig_force(const sb_model *o, const char *names, double *Q, int *control)
{
    const char *p = names;
    int nsel = 0;
    memset(Q, 0, sizeof(double) * 3 * (size_t)o->nf);
    if (control) *control = -1;
    while (p && *p) {
        const char *e = strchr(p, ',');
        size_t l = e ? (size_t)(e - p) : strlen(p);
        int r, k, found = -1;
        for (r = 0; r < o->nrig; r++)
            if (strlen(o->rig[r].def.name) == l && !strncmp(o->rig[r].def.name, p, l)) { found = r; break; }
        if (found < 0) {
            char list[2048];
            size_t n = 0;
            list[0] = 0;
            for (r = 0; r < o->nrig && n + SB_NAME_MAX + 3 < sizeof list; r++) n += (size_t)snprintf(list + n, sizeof list - n, " %s", o->rig[r].def.name);
            return sb_fail("retarget: character A has no rig '%.*s' (rigs:%s)", (int)l, p, o->nrig ? list : " none");
        }
        for (k = 0; k < o->rig[found].n; k++) {
            int v = o->rig[found].vert[k], a;
            for (a = 0; a < 3; a++) Q[3 * v + a] += o->rig[found].Q[3 * k + a];
        }
        if (control && *control < 0) *control = o->rig[found].def.control;
        nsel++;
        p = e ? e + 1 : NULL;
    }
    if (!nsel) return sb_fail("retarget: no rig named");
    return 0;
}

/* ---------------- transfer ---------------- */

/* The resample's weights, measured on test_bake_retarget (the limb onto a
 * sheared copy, two bump rigs; A onto itself): interior samples on a 2x2x2
 * grid per cell of A at weight 0.01 against 1 for each surface vertex of B,
 * and the second-difference smoothing at 1e-6: surface error max 0.26% /
 * 0.15% (rms 0.02% / 0.02%) of the largest displacement for the two rigs, A
 * onto itself 0.12%. Cell centres and A's surface vertices at weight 1 with
 * smoothing 1e-4 (the first version): 1.0% / 16%, and 10.8% onto itself. */
#define RS_PER_CELL 2
#define RS_WINT 0.01
#define RS_MU 1e-6

/* a sample of the transferred field: B cell, reference coordinates, value */
typedef struct rs_sample { int cell; double t[3]; double v[3]; double w; } rs_sample;

static void add_sample(const sb_model *B, const int *cmap, rs_sample *S, int *ns, const double y[3], const double v[3], double w)
{
    double t[3];
    int ci = locate(B, cmap, y, t);
    if (ci < 0) return;
    S[*ns].cell = ci;
    S[*ns].w = w;
    memcpy(S[*ns].t, t, sizeof t);
    memcpy(S[*ns].v, v, 3 * sizeof(double));
    (*ns)++;
}

/* point of A's cell ci at reference coordinates t under the map h, and its derivative d/dt */
static void mapped_cell_point(const sb_retarget *rt, int ci, const double t[3], double p[3], double D[9])
{
    const sb_model *A = rt->A;
    double N[8], dN[8][3];
    int k, a, b;
    sb_shape(t, N, dN);
    for (a = 0; a < 3; a++) p[a] = 0;
    for (a = 0; a < 9; a++) D[a] = 0;
    for (k = 0; k < 8; k++) {
        const double *hv = rt->h + 3 * A->cells[8 * ci + k];
        for (a = 0; a < 3; a++) {
            p[a] += N[k] * hv[a];
            for (b = 0; b < 3; b++) D[3 * a + b] += dN[k][b] * hv[a];
        }
    }
}

/* reference coordinates of y in A's mapped cell ci (Newton from the centre); 0 if y is inside it */
static int invert_cell(const sb_retarget *rt, int ci, const double y[3], double t[3])
{
    int it, a;
    t[0] = t[1] = t[2] = 0.5;
    for (it = 0; it < 40; it++) {
        double p[3], D[9], Di[9], r[3], dt[3];
        mapped_cell_point(rt, ci, t, p, D);
        for (a = 0; a < 3; a++) r[a] = y[a] - p[a];
        if (inv3(D, Di) == 0) return -1;
        for (a = 0; a < 3; a++) dt[a] = dot3(Di + 3 * a, r);
        for (a = 0; a < 3; a++) t[a] = fmin(fmax(t[a] + dt[a], -1.0), 2.0);
        if (sqrt(dot3(dt, dt)) < 1e-12) break;
    }
    for (a = 0; a < 3; a++) if (!(t[a] >= -1e-9 && t[a] <= 1 + 1e-9)) return -1;
    for (a = 0; a < 3; a++) t[a] = fmin(fmax(t[a], 0.0), 1.0);
    return 0;
}

/* the transferred field at A's cell ci, reference coordinates t */
static void field_at(const sb_model *A, const double *qbar, int ci, const double t[3], double v[3])
{
    double N[8];
    int c, a;
    sb_shape(t, N, NULL);
    v[0] = v[1] = v[2] = 0;
    for (c = 0; c < 8; c++)
        for (a = 0; a < 3; a++) v[a] += N[c] * qbar[3 * A->cells[8 * ci + c] + a];
}

/* y (nf_B x 3) = (sum_s phi phi^T + mu D^T D) x over B's free vertices (skeleton values 0) */
static void rs_mul(const sb_model *B, const rs_sample *S, int ns, const int (*st)[4], const double *stw, int nst, double mu,
                   const double *x, double *y)
{
    int s, k, a, c;
    memset(y, 0, sizeof(double) * 3 * (size_t)B->nf);
    for (s = 0; s < ns; s++) {
        double N[8], r[3] = { 0, 0, 0 };
        sb_shape(S[s].t, N, NULL);
        for (k = 0; k < 8; k++) {
            int v = B->cells[8 * S[s].cell + k];
            if (v < B->nf) for (a = 0; a < 3; a++) r[a] += N[k] * x[3 * v + a];
        }
        for (k = 0; k < 8; k++) {
            int v = B->cells[8 * S[s].cell + k];
            if (v < B->nf) for (a = 0; a < 3; a++) y[3 * v + a] += S[s].w * N[k] * r[a];
        }
    }
    for (s = 0; s < nst; s++) {
        double r[3] = { 0, 0, 0 };
        for (c = 0; c < 4; c++) if (st[s][c] >= 0 && st[s][c] < B->nf) for (a = 0; a < 3; a++) r[a] += stw[4 * s + c] * x[3 * st[s][c] + a];
        for (c = 0; c < 4; c++) if (st[s][c] >= 0 && st[s][c] < B->nf) for (a = 0; a < 3; a++) y[3 * st[s][c] + a] += mu * stw[4 * s + c] * r[a];
    }
}

static int resample(const sb_retarget *rt, const double *qbar, double *qB, sb_rt_transfer_stats *stt)
{
    const sb_model *A = rt->A, *B = rt->B;
    int cap = A->nv + A->nc * RS_PER_CELL * RS_PER_CELL * RS_PER_CELL + B->ns, ns = 0, i, k, a, nst = 0, it, n = 3 * B->nf;
    rs_sample *S = sb_alloc(sizeof(rs_sample) * (size_t)cap);
    int (*st)[4] = sb_alloc(sizeof(int) * 4 * 6 * (size_t)B->nv);
    double *stw = sb_alloc(sizeof(double) * 4 * 6 * (size_t)B->nv), mu;
    double *b = sb_alloc(sizeof(double) * (size_t)n), *x = sb_alloc(sizeof(double) * (size_t)n), *r = sb_alloc(sizeof(double) * (size_t)n);
    double *d = sb_alloc(sizeof(double) * (size_t)n), *Ad = sb_alloc(sizeof(double) * (size_t)n), *dg = sb_alloc(sizeof(double) * (size_t)B->nf);
    double *z = sb_alloc(sizeof(double) * (size_t)n), rz = 0, bn;
    unsigned char *has = sb_alloc((size_t)B->nv);
    size_t ngc = (size_t)(B->gn[0] - 1) * (size_t)(B->gn[1] - 1) * (size_t)(B->gn[2] - 1);
    int *cmap = sb_alloc(sizeof(int) * ngc);
    sb_inside in;
    for (i = 0; i < (int)ngc; i++) cmap[i] = -1;
    for (i = 0; i < B->nc; i++) cmap[B->cell_grid[i]] = i;
    /* samples: B's surface vertices (weight 1) with the transferred field at
     * their preimage under h (the mapped cell of A holding the vertex; a
     * vertex outside A's mapped lattice takes the field at the closest point
     * of A's mapped surface), and, inside A's mesh only (lattice vertices and
     * cell points outside it carry the 'air' displacement, not flesh), A's
     * mapped lattice vertices and RS_PER_CELL^3 points per cell (weight
     * RS_WINT) */
    stt->surf_inside = stt->surf_outside = 0;
    sb_inside_init(&in, rt->mA);
    for (i = 0; i < A->nv; i++) if (sb_inside_test(&in, A->x + 3 * i)) add_sample(B, cmap, S, &ns, rt->h + 3 * i, qbar + 3 * i, RS_WINT);
    for (k = 0; k < A->nc * RS_PER_CELL * RS_PER_CELL * RS_PER_CELL; k++) {
        int q = k % (RS_PER_CELL * RS_PER_CELL * RS_PER_CELL), ci = k / (RS_PER_CELL * RS_PER_CELL * RS_PER_CELL);
        double t[3], xc[3], y[3], v[3], D[9];
        t[0] = (2 * (q % RS_PER_CELL) + 1) / (2.0 * RS_PER_CELL);
        t[1] = (2 * ((q / RS_PER_CELL) % RS_PER_CELL) + 1) / (2.0 * RS_PER_CELL);
        t[2] = (2 * (q / (RS_PER_CELL * RS_PER_CELL)) + 1) / (2.0 * RS_PER_CELL);
        sb_cell_point(A, ci, t, xc);
        if (!sb_inside_test(&in, xc)) continue;
        mapped_cell_point(rt, ci, t, y, D);
        field_at(A, qbar, ci, t, v);
        add_sample(B, cmap, S, &ns, y, v, RS_WINT);
    }
    {
        double *cbox = sb_alloc(sizeof(double) * 6 * (size_t)A->nc), *hs = sb_alloc(sizeof(double) * 3 * (size_t)A->ns);
        tri_index ta;
        int c;
        for (c = 0; c < A->nc; c++)
            for (a = 0; a < 3; a++) {
                double lo = 1e300, hi = -1e300;
                int j;
                for (j = 0; j < 8; j++) { double w = rt->h[3 * A->cells[8 * c + j] + a]; lo = fmin(lo, w); hi = fmax(hi, w); }
                cbox[6 * c + a] = lo; cbox[6 * c + 3 + a] = hi;
            }
        for (k = 0; k < A->ns; k++) mapped_surface_point(rt, k, hs + 3 * k);
        tri_index_make(&ta, hs, A->tri, A->nt);
        for (k = 0; k < B->ns; k++) {
            double y[3], t[3], v[3], tol = 1e-9 * rt->L;
            int found = 0;
            sb_rt_surface_point(B, k, y);
            for (c = 0; c < A->nc && !found; c++) {
                if (y[0] < cbox[6 * c] - tol || y[0] > cbox[6 * c + 3] + tol || y[1] < cbox[6 * c + 1] - tol || y[1] > cbox[6 * c + 4] + tol ||
                    y[2] < cbox[6 * c + 2] - tol || y[2] > cbox[6 * c + 5] + tol)
                    continue;
                if (invert_cell(rt, c, y, t)) continue;
                field_at(A, qbar, c, t, v);
                found = 1;
            }
            if (found) stt->surf_inside++;
            else {          /* the closest point of A's mapped surface */
                stt->surf_outside++;
                double bw[3], vv[3];
                int tr = tri_closest(&ta, y, bw), j;
                v[0] = v[1] = v[2] = 0;
                for (j = 0; j < 3; j++) {
                    int sv = A->tri[3 * tr + j];
                    field_at(A, qbar, A->emb_cell[sv], A->emb_t + 3 * sv, vv);
                    for (a = 0; a < 3; a++) v[a] += bw[j] * vv[a];
                }
            }
            add_sample(B, cmap, S, &ns, y, v, 1.0);
        }
        tri_index_free(&ta);
        free(cbox); free(hs);
    }
    if (!stt->surf_inside) {
        sb_inside_free(&in); free(cmap);
        free(S); free(st); free(stw); free(b); free(x); free(r); free(d); free(Ad); free(dg); free(z); free(has);
        return sb_fail("retarget: empty overlap: none of B's %d surface vertices lies in A's mapped lattice (the map does not cover B)", B->ns);
    }
    sb_inside_free(&in);
    free(cmap);
    if (!ns) {
        free(S); free(st); free(stw); free(b); free(x); free(r); free(d); free(Ad); free(dg); free(z); free(has);
        return sb_fail("retarget: empty overlap: no point of A's mapped lattice or surface lies in B's lattice (the map does not cover B)");
    }
    for (i = 0; i < ns; i++) for (k = 0; k < 8; k++) has[B->cells[8 * S[i].cell + k]] = 1;
    stt->inside = stt->outside = 0;
    for (i = 0; i < B->nf; i++) { if (has[i]) stt->inside++; else stt->outside++; }
    /* second-difference stencils on B's grid */
    {
        int stp[3] = { 1, B->gn[0], B->gn[0] * B->gn[1] }, ax, bx;
        for (i = 0; i < B->nv; i++) {
            int gv = B->v_grid[i], gc[3];
            gc[0] = gv % B->gn[0]; gc[1] = (gv / B->gn[0]) % B->gn[1]; gc[2] = gv / (B->gn[0] * B->gn[1]);
            for (ax = 0; ax < 3; ax++) {
                int lo, hi;
                if (gc[ax] < 1 || gc[ax] > B->gn[ax] - 2) continue;
                lo = B->gvert[gv - stp[ax]]; hi = B->gvert[gv + stp[ax]];
                if (lo < 0 || hi < 0) continue;
                st[nst][0] = lo; st[nst][1] = i; st[nst][2] = hi; st[nst][3] = -1;
                stw[4 * nst] = 1; stw[4 * nst + 1] = -2; stw[4 * nst + 2] = 1; stw[4 * nst + 3] = 0;
                nst++;
            }
            for (ax = 0; ax < 3; ax++)
                for (bx = ax + 1; bx < 3; bx++) {
                    int u, v, w;
                    if (gc[ax] > B->gn[ax] - 2 || gc[bx] > B->gn[bx] - 2) continue;
                    u = B->gvert[gv + stp[ax]]; v = B->gvert[gv + stp[bx]]; w = B->gvert[gv + stp[ax] + stp[bx]];
                    if (u < 0 || v < 0 || w < 0) continue;
                    st[nst][0] = i; st[nst][1] = u; st[nst][2] = v; st[nst][3] = w;
                    stw[4 * nst] = 1; stw[4 * nst + 1] = -1; stw[4 * nst + 2] = -1; stw[4 * nst + 3] = 1;
                    nst++;
                }
        }
    }
    mu = RS_MU;
    /* right-hand side sum_s phi v_s, Jacobi diagonal */
    for (i = 0; i < ns; i++) {
        double N[8];
        sb_shape(S[i].t, N, NULL);
        for (k = 0; k < 8; k++) {
            int v = B->cells[8 * S[i].cell + k];
            if (v >= B->nf) continue;
            for (a = 0; a < 3; a++) b[3 * v + a] += S[i].w * N[k] * S[i].v[a];
            dg[v] += S[i].w * N[k] * N[k];
        }
    }
    for (i = 0; i < nst; i++) for (k = 0; k < 4; k++) if (st[i][k] >= 0 && st[i][k] < B->nf) dg[st[i][k]] += mu * stw[4 * i + k] * stw[4 * i + k];
    bn = norm(b, n);
    memcpy(r, b, sizeof(double) * (size_t)n);
    for (i = 0; i < n; i++) { z[i] = dg[i / 3] > 0 ? r[i] / dg[i / 3] : r[i]; d[i] = z[i]; rz += r[i] * z[i]; }
    for (it = 0; it < 20 * n + 100 && bn > 0 && norm(r, n) > 1e-12 * bn; it++) {
        double dAd = 0, al, rz1 = 0;
        rs_mul(B, S, ns, (const int (*)[4])st, stw, nst, mu, d, Ad);
        for (i = 0; i < n; i++) dAd += d[i] * Ad[i];
        if (!(dAd > 0)) break;
        al = rz / dAd;
        for (i = 0; i < n; i++) { x[i] += al * d[i]; r[i] -= al * Ad[i]; }
        for (i = 0; i < n; i++) { z[i] = dg[i / 3] > 0 ? r[i] / dg[i / 3] : r[i]; rz1 += r[i] * z[i]; }
        for (i = 0; i < n; i++) d[i] = z[i] + rz1 / rz * d[i];
        rz = rz1;
    }
    memset(qB, 0, sizeof(double) * 3 * (size_t)B->nv);
    memcpy(qB, x, sizeof(double) * (size_t)n);
    free(S); free(st); free(stw); free(b); free(x); free(r); free(d); free(Ad); free(dg); free(z); free(has);
    return 0;
}

int sb_rt_transfer(const sb_retarget *rt, const double *QA, double *QB, double *qA_out, double *qB_out, sb_rt_transfer_stats *st)
{
    const sb_model *A = rt->A, *B = rt->B;
    double *qA = sb_alloc(sizeof(double) * 3 * (size_t)A->nv), *qbar = sb_alloc(sizeof(double) * 3 * (size_t)A->nv);
    double *qB = sb_alloc(sizeof(double) * 3 * (size_t)B->nv), res;
    int i, a;
    sb_rt_transfer_stats s;
    memset(&s, 0, sizeof s);
    if (!rt->J) { free(qA); free(qbar); free(qB); return sb_fail("retarget: transfer before the Jacobians"); }
    for (i = 0; i < 3 * A->nf; i++)
        if (!isfinite(QA[i])) { free(qA); free(qbar); free(qB); return sb_fail("retarget: the source rig force is not finite"); }
    /* Q_A -> q_A (eq. 10 on A) */
    res = sb_rt_static(A, QA, qA);
    s.static_res = res;
    if (!(res >= 0 && res < 1e-8)) {
        free(qA); free(qbar); free(qB);
        return sb_fail("retarget: the static solve on A did not converge (relative residual %.3g)", res);
    }
    /* q_bar_i = J_i q_A,i */
    for (i = 0; i < A->nv; i++) {
        for (a = 0; a < 3; a++) qbar[3 * i + a] = dot3(rt->J + 9 * i + 3 * a, qA + 3 * i);
        s.qA_max = fmax(s.qA_max, sqrt(dot3(qA + 3 * i, qA + 3 * i)));
    }
    /* resample: fit B's trilinear field (free vertices; skeleton vertices
     * held at 0) to the transferred field by least squares over samples of
     * the overlap: every mapped lattice vertex h(x_i) of A (value J_i q_A,i,
     * the transferred coefficient of eq. 16), every mapped cell centre and
     * surface vertex of A (value: the trilinear interpolation of the J_i q_A,i),
     * each located in B's lattice; plus mu times the squared second
     * differences of q_B on B's grid (vertices without samples nearby follow
     * their neighbours smoothly). */
    if (resample(rt, qbar, qB, &s)) { free(qA); free(qbar); free(qB); return -1; }
    for (i = 0; i < B->nf; i++) s.qB_max = fmax(s.qB_max, sqrt(dot3(qB + 3 * i, qB + 3 * i)));
    /* Q_B = S_FF q_B (eq. 10 on B, skeleton held: q_S = 0) */
    sb_rt_force_of(B, qB, QB);
    for (i = 0; i < 3 * B->nf; i++)
        if (!isfinite(QB[i])) { free(qA); free(qbar); free(qB); return sb_fail("retarget: the transferred force is not finite"); }
    if (qA_out) memcpy(qA_out, qA, sizeof(double) * 3 * (size_t)A->nv);
    if (qB_out) memcpy(qB_out, qB, sizeof(double) * 3 * (size_t)B->nv);
    if (st) *st = s;
    free(qA); free(qbar); free(qB);
    return 0;
}

/* ---------------- output ---------------- */

int sb_rt_write_rig_levels(const char *path, int nlev, const sb_model *const *B, const sb_mesh *mB, const double *const *Q, const char *comment)
{
    int i, l;
    for (l = 0; l < nlev; l++) {
        double qmax = 0;
        for (i = 0; i < 3 * B[l]->nf; i++) {
            if (!isfinite(Q[l][i])) return sb_fail("retarget: the rig force%s is not finite: nothing written", l ? " on B's level 1" : "");
            qmax = fmax(qmax, fabs(Q[l][i]));
        }
        if (!(qmax > 0)) return sb_fail("retarget: the rig force%s is zero: nothing written", l ? " on B's level 1" : "");
    }
    return sb_rigfile_write_fits(path, nlev, B, mB, Q, comment);
}

int sb_rt_write_rig(const char *path, const sb_model *B, const sb_mesh *mB, const double *Q, const char *comment)
{
    return sb_rt_write_rig_levels(path, 1, &B, mB, &Q, comment);
}
