/* test_bake_fem.c -- host tool: integrals and lattice against independent
 * references (closed-form trilinear hex element, with condensed incompatible
 * modes, patch test, null spaces, volume by the divergence theorem), the
 * volumetric bones (chain, radius, nearest-bone ownership), per-cell
 * matrices and frames, and the description's newer statements. */
#include "sb.h"
#include "sn_test.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *COW = "tools/examples/cow/cow.sinew";

/* write a closed box [0,s]^3 (12 triangles, CCW outward; vertex k at (bit2, bit1, bit0) * s) */
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

/* 1-D integrals over [0,a] of products of the linear functions l0 = 1-x/a, l1 = x/a
 * and their derivatives (closed form, independent of the tool's quadrature). */
static double i_ll(int p, int q, double a) { return p == q ? a / 3 : a / 6; }
static double i_dd(int p, int q, double a) { return (p == q ? 1.0 : -1.0) / a; }
static double i_dl(int p, double a) { (void)a; return p ? 0.5 : -0.5; }   /* int l_p' l_q dx = +-1/2 for any q */
/* int dNa/dx_i dNb/dx_j over the cube of edge a; corner k has bit d = coordinate d */
static double i_grad(int A, int B, int i, int j, double a)
{
    double r = 1;
    int d;
    for (d = 0; d < 3; d++) {
        int p = A >> d & 1, q = B >> d & 1;
        if (d == i && d == j) r *= i_dd(p, q, a);
        else if (d == i) r *= i_dl(p, a);
        else if (d == j) r *= i_dl(q, a);
        else r *= i_ll(p, q, a);
    }
    return r;
}

/* int over [0,a] of l_p P' with the bubble P = 4 (x/a)(1 - x/a): -int l_p' P = -/+ (1/a)(2a/3) */
static double i_lb(int p) { return p ? -2.0 / 3.0 : 2.0 / 3.0; }
/* int dN_A/dx_d dP_k/dx_k over the cube: zero for d == k (int l' P' = l' [P] = 0) */
static double i_gb(int A, int d, int k, double a)
{
    if (d == k) return 0;
    return ((A >> d & 1) ? 1.0 : -1.0) * i_lb(A >> k & 1) * (a / 2);   /* int l_p' = +-1, int l = a/2 */
}

/* closed-form element of the cube of edge a: trilinear K (24x24, dof 3A+i) and, if inc,
 * with the 9 bubble modes (Wilson et al. 1973) condensed out: K - Kua Kaa^-1 Kua^T.
 * On a cube Kaa is diagonal: int (P')^2 dV = 16a/3 times lam+2mu (c = k) or mu. */
static void ref_element(double a, double lam, double mu, int inc, double K[24][24])
{
    int A, B, i, j, k, c, dd;
    for (A = 0; A < 8; A++)
        for (B = 0; B < 8; B++) {
            double gg = 0;
            for (dd = 0; dd < 3; dd++) gg += i_grad(A, B, dd, dd, a);
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++)
                    K[3 * A + i][3 * B + j] = lam * i_grad(A, B, i, j, a) + mu * i_grad(A, B, j, i, a) + (i == j ? mu * gg : 0);
        }
    if (!inc) return;
    {
        double Kua[24][9], Kaa[9];
        for (k = 0; k < 3; k++)
            for (c = 0; c < 3; c++) {
                Kaa[3 * k + c] = 16 * a / 3 * (c == k ? lam + 2 * mu : mu);
                for (A = 0; A < 8; A++)
                    for (i = 0; i < 3; i++)   /* lam dNa/dx_i g_c + mu dNa/dx_c g_i + delta_ic mu gradNa.g, g = P_k' e_k */
                        Kua[3 * A + i][3 * k + c] = (c == k ? lam * i_gb(A, i, k, a) : 0) + (i == k ? mu * i_gb(A, c, k, a) : 0) +
                                                    (i == c ? mu * i_gb(A, k, k, a) : 0);
            }
        for (i = 0; i < 24; i++)
            for (j = 0; j < 24; j++)
                for (k = 0; k < 9; k++) K[i][j] -= Kua[i][k] * Kua[j][k] / Kaa[k];
    }
}

/* eigenvalues of a symmetric 24x24 matrix (cyclic Jacobi), ascending in ev */
static void eig24(double K[24][24], double ev[24])
{
    double A[24][24];
    int sweep, p, q, k;
    memcpy(A, K, sizeof A);
    for (sweep = 0; sweep < 100; sweep++) {
        double off = 0, dg = 0;
        for (p = 0; p < 24; p++) for (q = 0; q < 24; q++) { if (p != q) off += A[p][q] * A[p][q]; else dg += A[p][p] * A[p][p]; }
        if (off <= 1e-30 * dg) break;
        for (p = 0; p < 23; p++)
            for (q = p + 1; q < 24; q++) {
                double th, t, cs, sn;
                if (A[p][q] == 0) continue;
                th = (A[q][q] - A[p][p]) / (2 * A[p][q]);
                t = (th >= 0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1));
                cs = 1 / sqrt(t * t + 1); sn = t * cs;
                for (k = 0; k < 24; k++) {   /* A <- A R (columns p, q) */
                    double akp = A[k][p], akq = A[k][q];
                    A[k][p] = cs * akp - sn * akq; A[k][q] = sn * akp + cs * akq;
                }
                for (k = 0; k < 24; k++) {   /* A <- R^T A (rows p, q) */
                    double apk = A[p][k], aqk = A[q][k];
                    A[p][k] = cs * apk - sn * aqk; A[q][k] = sn * apk + cs * aqk;
                }
            }
    }
    for (p = 0; p < 24; p++) ev[p] = A[p][p];
    for (p = 1; p < 24; p++) for (q = p; q > 0 && ev[q] < ev[q - 1]; q--) { double t = ev[q]; ev[q] = ev[q - 1]; ev[q - 1] = t; }
}

/* one full cube cell [0,2]^3, unit 0.3 m: the tool's element against the closed form */
static void test_single_cell(int inc)
{
    const char *dir = getenv("BUILD") ? getenv("BUILD") : "build";
    const char *el = inc ? "incompatible" : "trilinear";
    char obj[512], desc[512];
    FILE *f;
    sb_desc d;
    sb_mesh m;
    sb_model o;
    const double s = 2.0, unit = 0.3, a = s * unit, E = 2e5, nu = 0.3, rho = 900;
    const double lam = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    double maxS = 0, errS = 0, errM = 0, Kref[24][24], K[24][24];
    int va, vb, A, B, i, j;
    ref_element(a, lam, mu, inc, Kref);
    snprintf(obj, sizeof obj, "%s/tests/bake_cube.obj", dir);
    snprintf(desc, sizeof desc, "%s/tests/bake_cube_%s.sinew", dir, el);
    T_CHECK(write_cube_obj(obj, s) == 0, "write %s", obj);
    f = fopen(desc, "w");
    T_CHECK(f != NULL, "write %s", desc);
    if (!f) return;
    fprintf(f, "mesh bake_cube.obj\nunit %g\ncell %g\norigin 0 0 0\njoint root - 1 1 1\n"
               "material m %g %g %g\npin box -1 -1 -1 0.001 0.001 0.001 root\nelement %s\n", unit, s, E, nu, rho, el);
    fclose(f);
    T_CHECK(sb_desc_load(desc, &d) == 0, "load: %s", sb_error());
    T_CHECK(sb_mesh_load_obj(d.mesh_path, &m) == 0, "mesh: %s", sb_error());
    if (sb_build(&d, &m, &o, 1)) { T_CHECK(0, "build: %s", sb_error()); return; }
    T_CHECK(o.nc == 1 && o.nv == 8 && o.nf == 7, "one cell, 8 vertices, 7 free: got %d cells %d vertices %d free", o.nc, o.nv, o.nf);
    T_CHECK(o.n_uncondensed == 0, "%s: every cell condensed (got %d left trilinear)", el, o.n_uncondensed);
    if (o.nc != 1) return;
    for (A = 0; A < 8; A++)
        for (B = 0; B < 8; B++) {
            int e;
            va = o.cells[A]; vb = o.cells[B];
            e = sb_pattern_find(&o, va, vb);
            T_CHECK(e >= 0, "pattern has (%d,%d)", va, vb);
            if (e < 0) continue;
            {
                double Mref = rho;
                int dd;
                for (dd = 0; dd < 3; dd++) Mref *= i_ll(A >> dd & 1, B >> dd & 1, a);
                errM = fmax(errM, fabs(o.M[e] - Mref) / (rho * a * a * a));
                for (i = 0; i < 3; i++)
                    for (j = 0; j < 3; j++) {
                        K[3 * A + i][3 * B + j] = o.S[9 * e + 3 * i + j];
                        errS = fmax(errS, fabs(o.S[9 * e + 3 * i + j] - Kref[3 * A + i][3 * B + j]));
                        maxS = fmax(maxS, fabs(Kref[3 * A + i][3 * B + j]));
                    }
            }
        }
    /* Gauss 2x2x2 per sub-box integrates the (bi)quadratic products exactly: only round-off remains */
    T_NEAR(errM, 0, 1e-12, "mass: exact quadrature of degree-2 polynomials, double round-off");
    T_NEAR(errS / maxS, 0, 1e-12, "stiffness: exact quadrature (and a 9x9 condensation with condition ~3.5), double round-off");
    T_NEAR(o.mass, rho * a * a * a, 1e-12 * rho * a * a * a, "total mass of a full cell, round-off");
    T_FIGURE("single cell, %s element: max |S - S_ref| / max|S_ref| = %.2e, max |M - M_ref| / (rho a^3) = %.2e", el, errS / maxS, errM);
    if (inc) {   /* the comparison discriminates: the condensation changes the element by far more than round-off */
        double Kt[24][24], dk = 0;
        ref_element(a, lam, mu, 0, Kt);
        for (i = 0; i < 24; i++) for (j = 0; j < 24; j++) dk = fmax(dk, fabs(Kt[i][j] - Kref[i][j]));
        T_CHECK(dk > 0.01 * maxS, "condensed element differs from the trilinear one (max diff %.3g of max entry)", dk / maxS);
        T_FIGURE("single cell: condensation changes the element by up to %.3f of its largest entry", dk / maxS);
    }
    {   /* symmetric, translations and infinitesimal rotations in the null space, PSD with exactly 6 zero modes */
        double asym = 0, trans = 0, rot = 0, ev[24];
        int nzero = 0;
        for (i = 0; i < 24; i++) {
            double tr[3] = {0, 0, 0}, rr[3] = {0, 0, 0};
            for (j = 0; j < 24; j++) {
                const double *x = o.x + 3 * o.cells[j / 3];
                int c = j % 3, b;
                asym = fmax(asym, fabs(K[i][j] - K[j][i]));
                tr[c] += K[i][j];
                for (b = 0; b < 3; b++) {   /* rotation about axis b: u = e_b x x (metres), component c */
                    double r = b == c ? 0 : ((c - b + 3) % 3 == 1 ? 1.0 : -1.0) * x[3 - b - c] * unit;
                    rr[b] += K[i][j] * r;
                }
            }
            for (j = 0; j < 3; j++) { trans = fmax(trans, fabs(tr[j])); rot = fmax(rot, fabs(rr[j])); }
        }
        eig24(K, ev);
        for (i = 0; i < 24; i++) if (fabs(ev[i]) <= 1e-10 * ev[23]) nzero++;
        T_NEAR(asym / maxS, 0, 1e-15, "symmetric (the tool symmetrizes exactly)");
        T_NEAR(trans / maxS, 0, 1e-12, "translations in the null space: sums of 8 blocks, round-off");
        T_NEAR(rot / (maxS * a), 0, 1e-12, "infinitesimal rotations in the null space: 8 blocks times coordinates up to a, round-off");
        T_CHECK(ev[0] >= -1e-12 * ev[23] && nzero == 6, "%s: PSD with exactly the 6 rigid zero modes: smallest eigenvalues %.3g %.3g, %d near zero",
                el, ev[0] / ev[23], ev[6] / ev[23], nzero);
        T_FIGURE("single cell, %s element: eigenvalues / largest: rigid max %.1e, smallest elastic %.4f", el,
                 fmax(fabs(ev[0]), fabs(ev[5])) / ev[23], ev[6] / ev[23]);
    }
    sb_model_free(&o); sb_mesh_free(&m); sb_desc_free(&d);
}

/* constant-strain patch test on the cow's cells (the bubble gradients integrate to zero over a
 * cell). With uniform material and air 1 (constant weight in every cell) a linear field u = A x
 * gives zero bubble forces, so the condensed S u equals the trilinear S u (round-off). */
static void test_cow_patch(void)
{
    sb_model o[2];
    sb_desc d;
    sb_mesh m;
    double Ag[3][3] = {{0.3, -0.7, 0.2}, {0.5, 0.1, -0.4}, {-0.6, 0.8, 0.25}}, err = 0, fmaxv = 0, maxS = 0;
    int el, i, e, a, b, k, built = 0;
    for (el = 0; el < 2; el++) {
        if (sb_desc_load(COW, &d) || sb_mesh_load_obj(d.mesh_path, &m)) { T_CHECK(0, "load cow: %s", sb_error()); return; }
        for (i = 0; i < d.nm; i++) d.mats[i] = d.mats[0];
        d.air = 1;
        d.element = el ? SB_ELEM_TRILINEAR : SB_ELEM_INCOMPATIBLE;
        if (sb_build(&d, &m, &o[el], 1)) { T_CHECK(0, "build cow: %s", sb_error()); sb_mesh_free(&m); sb_desc_free(&d); break; }
        built++;
        sb_mesh_free(&m); sb_desc_free(&d);
    }
    if (built < 2) { if (built) sb_model_free(&o[0]); return; }
    T_CHECK(o[0].nv == o[1].nv && o[0].nbptr[o[0].nv] == o[1].nbptr[o[1].nv], "same lattice");
    /* the lattice is never moved: every cell is a cube (the old construction distorted cells here) */
    T_NEAR(o[0].min_jac, 1.0, 1e-12, "every cell an undistorted cube: Jacobian / c^3 = 1 up to round-off");
    T_CHECK(o[0].n_uncondensed == 0, "air 1: every cell condensed (got %d left trilinear)", o[0].n_uncondensed);
    for (e = 0; e < o[0].nbptr[o[0].nv]; e++) for (k = 0; k < 9; k++) maxS = fmax(maxS, fabs(o[0].S[9 * e + k]));
    for (i = 0; i < o[0].nv; i++)
        for (a = 0; a < 3; a++) {
            double fv[2] = {0, 0};
            for (el = 0; el < 2; el++)
                for (e = o[el].nbptr[i]; e < o[el].nbptr[i + 1]; e++) {
                    const double *x = o[el].x + 3 * o[el].nb[e];
                    for (b = 0; b < 3; b++) {
                        double u = 0;
                        for (k = 0; k < 3; k++) u += Ag[b][k] * x[k] * o[el].unit;
                        fv[el] += o[el].S[9 * e + 3 * a + b] * u;
                    }
                }
            err = fmax(err, fabs(fv[0] - fv[1]));
            fmaxv = fmax(fmaxv, fabs(fv[1]));
        }
    /* scale: ~27 blocks of size maxS times displacements up to |A| * |x| ~ one metre-ish extent */
    {
        double maxx = 0;
        for (i = 0; i < o[0].nv; i++) for (k = 0; k < 3; k++) maxx = fmax(maxx, fabs(o[0].x[3 * i + k] * o[0].unit));
        T_NEAR(err / (maxS * maxx), 0, 1e-11, "patch test: condensed = trilinear forces for a linear field on distorted cells, round-off");
        T_FIGURE("cow patch test (air 1, one material): max |f_inc - f_tri| = %.2e of maxS*maxx (boundary forces up to %.2e)",
                 err / (maxS * maxx), fmaxv / (maxS * maxx));
    }
    sb_model_free(&o[0]); sb_model_free(&o[1]);
}

/* inside test on a cube whose rays hit triangle edges and vertices exactly:
 * the watertight edge rule must count every such ray once */
static void test_inside_edges(void)
{
    const char *dir = getenv("BUILD") ? getenv("BUILD") : "build";
    char obj[512];
    sb_mesh m;
    sb_inside in;
    int iy, iz, ix, wrong = 0, n = 0;
    snprintf(obj, sizeof obj, "%s/tests/bake_cube_in.obj", dir);
    T_CHECK(write_cube_obj(obj, 2.0) == 0, "write %s", obj);
    if (sb_mesh_load_obj(obj, &m)) { T_CHECK(0, "load: %s", sb_error()); return; }
    sb_inside_init(&in, &m);
    for (iy = 1; iy < 8; iy++)
        for (iz = 1; iz < 8; iz++)
            for (ix = -3; ix <= 11; ix++) {
                double p[3];
                int want;
                if (ix == 0 || ix == 8) continue;   /* on the surface */
                p[0] = ix * 0.25; p[1] = iy * 0.25; p[2] = iz * 0.25;   /* (y,z) on face diagonals when iy == iz or iy + iz == 8 */
                want = ix > 0 && ix < 8;
                if (sb_inside_test(&in, p) != want) wrong++;
                n++;
            }
    T_CHECK(wrong == 0, "inside test on edge-grazing rays: %d of %d wrong", wrong, n);
    sb_inside_free(&in);
    sb_mesh_free(&m);
}

/* material rules: later rules override earlier ones */
static void test_material_rules(void)
{
    const char *dir = getenv("BUILD") ? getenv("BUILD") : "build";
    char desc[512];
    FILE *f;
    sb_desc d;
    sb_mesh m;
    sb_model o;
    const double unit = 0.5, a = 2 * unit;
    snprintf(desc, sizeof desc, "%s/tests/bake_cube_rules.sinew", dir);
    f = fopen(desc, "w");
    T_CHECK(f != NULL, "write %s", desc);
    if (!f) return;
    /* the default is overridden everywhere by 'heavy', then the half x < 1 by 'light';
     * x = 1 is a sub-box boundary, so no quadrature point straddles it */
    fprintf(f, "mesh bake_cube.obj\nunit %g\ncell 2\norigin 0 0 0\njoint root - 1 1 1\n"
               "material dflt 1e5 0.3 500\nmaterial heavy 1e5 0.3 3000\nmaterial light 1e5 0.3 1000\n"
               "region all heavy\nregion box -1 -1 -1 1 3 3 light\npin box -1 -1 -1 0.001 0.001 0.001 root\n", unit);
    fclose(f);
    if (sb_desc_load(desc, &d) || sb_mesh_load_obj(d.mesh_path, &m)) { T_CHECK(0, "load: %s", sb_error()); return; }
    if (sb_build(&d, &m, &o, 1)) { T_CHECK(0, "build: %s", sb_error()); return; }
    T_NEAR(o.mass, 0.5 * (3000 + 1000) * a * a * a, 1e-9 * 3000 * a * a * a, "half light, half heavy: exact quadrature, round-off");
    sb_model_free(&o); sb_mesh_free(&m); sb_desc_free(&d);
}

/* distance from p to segment a-b (written here, independently of the tool) */
static double dseg(const double *p, const double *a, const double *b)
{
    double ab[3], ap[3], L2 = 0, t = 0, d2 = 0;
    int k;
    for (k = 0; k < 3; k++) { ab[k] = b[k] - a[k]; ap[k] = p[k] - a[k]; L2 += ab[k] * ab[k]; t += ab[k] * ap[k]; }
    t = L2 > 0 ? fmin(1, fmax(0, t / L2)) : 0;
    for (k = 0; k < 3; k++) d2 += (ap[k] - t * ab[k]) * (ap[k] - t * ab[k]);
    return sqrt(d2);
}

/* lattice vertex at grid position p, or -1 */
static int vert_at(const sb_model *o, const double *p)
{
    int gi[3], k;
    for (k = 0; k < 3; k++) {
        gi[k] = (int)floor((p[k] - o->gorg[k]) / o->c + 0.5);
        if (gi[k] < 0 || gi[k] >= o->gn[k]) return -1;
    }
    return o->gvert[gi[0] + o->gn[0] * (gi[1] + o->gn[1] * gi[2])];
}

/* Volumetric bones (DESCRIPTION.md "Skeleton"), checked from the definitions:
 * (a) the grid vertex nearest each sample of a bone (ceil(L / (c/8)) equal steps, ends included)
 *     is a skeleton vertex when it is a lattice vertex;
 * (b) every lattice vertex within a bone's radius of its segment is a skeleton vertex;
 * a captured vertex moves with the parent joint of the nearest capturing bone;
 * every vertex is a grid vertex (cells are cubes); frames of skeleton vertices are rigid. */
static void check_bones(const sb_model *o, const char *what)
{
    int i, a, k, bad_chain = 0, bad_radius = 0, bad_owner = 0, bad_grid = 0, nchain = 0, ncap = 0;
    for (a = 0; a < o->nseg; a++) {
        const double *P = o->joints[o->joints[o->seg_child[a]].parent].pos, *C = o->joints[o->seg_child[a]].pos;
        double L = 0;
        int s, ns;
        for (k = 0; k < 3; k++) L += (C[k] - P[k]) * (C[k] - P[k]);
        ns = (int)ceil(sqrt(L) / (o->c / 8));
        if (ns < 1) ns = 1;
        for (s = 0; s <= ns; s++) {
            double p[3];
            int v;
            for (k = 0; k < 3; k++) p[k] = P[k] + (C[k] - P[k]) * s / ns;
            v = vert_at(o, p);
            if (v < 0) continue;   /* not a lattice vertex (bone outside the kept cells) */
            nchain++;
            if (v < o->nf) bad_chain++;
        }
    }
    for (i = 0; i < o->nv; i++) {
        const double *x = o->x + 3 * i;
        double best = HUGE_VAL;
        int owner = -1, captured = 0;
        for (k = 0; k < 3; k++) {
            double u = (x[k] - o->gorg[k]) / o->c;
            if (fabs(u - floor(u + 0.5)) > 1e-9) bad_grid++;
        }
        for (a = 0; a < o->nseg; a++) {
            double d = dseg(x, o->joints[o->joints[o->seg_child[a]].parent].pos, o->joints[o->seg_child[a]].pos);
            if (d <= o->seg_r[a]) { captured = 1; if (d < best) { best = d; owner = a; } }
        }
        if (captured) {
            ncap++;
            if (i < o->nf) bad_radius++;
            /* the owner is the nearest capturing bone unless a nearer bone's chain took the vertex */
            else if (o->vseg[i] >= 0 && o->vseg[i] != owner) {
                double dv = dseg(x, o->joints[o->joints[o->seg_child[o->vseg[i]]].parent].pos, o->joints[o->seg_child[o->vseg[i]]].pos);
                if (dv > best) bad_owner++;
            }
        }
        if (i >= o->nf) {
            T_CHECK(o->fb1[i] == o->fb2[i] && o->fw[i] == 0, "%s: skeleton vertex %d: bone1 == bone2, w = 0", what, i);
            if (o->vseg[i] >= 0 && o->fb1[i] != o->joints[o->seg_child[o->vseg[i]]].parent) bad_owner++;
        }
    }
    T_CHECK(bad_grid == 0, "%s: every lattice vertex on the undistorted grid (%d coordinates off)", what, bad_grid);
    T_CHECK(bad_chain == 0, "%s: rasterized chain: %d of %d bone points have a free nearest vertex", what, bad_chain, nchain);
    T_CHECK(bad_radius == 0, "%s: %d of %d vertices within a bone radius are free", what, bad_radius, ncap);
    T_CHECK(bad_owner == 0, "%s: %d skeleton vertices not moved by the nearest capturing bone's parent joint", what, bad_owner);
    for (a = 0; a < o->nseg; a++) T_CHECK(o->seg_ncap[a] > 0, "%s: bone %d captures a vertex", what, a);
}

/* per-cell data: Se assembles to S exactly, is symmetric with the rigid null space;
 * twist entries are all zero; cell frames are valid; limits default to none */
static void check_cells(const sb_model *o, const char *what)
{
    size_t ne = (size_t)o->nbptr[o->nv], e;
    double *S2 = calloc(9 * ne, sizeof *S2), maxS = 0, err = 0, asym = 0, tr = 0;
    int ci, a, b, i, j, tz = 0;
    for (ci = 0; ci < o->nc; ci++) {
        const double *K = o->Se + 576 * (size_t)ci;
        for (a = 0; a < 8; a++)
            for (b = 0; b < 8; b++) {
                int pe = sb_pattern_find(o, o->cells[8 * ci + a], o->cells[8 * ci + b]);
                for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) S2[9 * (size_t)pe + (size_t)(3 * i + j)] += K[24 * (3 * a + i) + 3 * b + j];
            }
        for (i = 0; i < 24; i++) {
            double rs[3] = {0, 0, 0};
            for (j = 0; j < 24; j++) { asym = fmax(asym, fabs(K[24 * i + j] - K[24 * j + i])); rs[j % 3] += K[24 * i + j]; }
            for (j = 0; j < 3; j++) tr = fmax(tr, fabs(rs[j]));
        }
        T_CHECK(o->cfb1[ci] >= 0 && o->cfb1[ci] < o->nj && o->cfb2[ci] >= 0 && o->cfb2[ci] < o->nj && o->cfw[ci] >= 0 && o->cfw[ci] <= 1,
                "%s: cell %d frame valid", what, ci);
    }
    for (e = 0; e < 9 * ne; e++) { maxS = fmax(maxS, fabs(o->S[e])); err = fmax(err, fabs(S2[e] - o->S[e])); }
    for (e = 0; e < ne; e++) if (o->T[e] != 0) tz++;
    free(S2);
    T_NEAR(err / maxS, 0, 1e-12, "assembled per-cell Se = S (the same numbers summed)");
    T_NEAR(asym / maxS, 0, 1e-15, "per-cell Se symmetric (the tool symmetrizes exactly)");
    T_NEAR(tr / maxS, 0, 1e-12, "per-cell Se: translations in the null space, round-off");
    T_CHECK(tz == 0, "%s: twist retired: %d non-zero T entries", what, tz);
    for (i = 0; i < o->nv; i++) if (o->limit[i] != 0) break;
    T_CHECK(i == o->nv, "%s: no 'limit' rules: every limit 0", what);
}

/* frames on the straight limb (shoulder (0,0,0) -> elbow (4,0,0) -> wrist (8,0,0), blend width
 * B = cell = 1): bone1/bone2 = the joints of the nearer/farther bone, w from the documented rule
 * s = clamp(1 - (d2 - d1)/B, 0, 1), w = s^2 (3 - 2s) / 2 (distances computed here, in closed form) */
static double dist_seg_x(const double *p, double x0, double x1)
{
    double dx = p[0] < x0 ? x0 - p[0] : p[0] > x1 ? p[0] - x1 : 0;
    return sqrt(dx * dx + p[1] * p[1] + p[2] * p[2]);
}
static void test_limb_frames(void)
{
    sb_desc d;
    sb_mesh m;
    sb_model o;
    int i, bad = 0, n_half = 0, n_zero = 0;
    if (sb_desc_load("tools/examples/limb/limb.sinew", &d) || sb_mesh_load_obj(d.mesh_path, &m)) { T_CHECK(0, "load limb: %s", sb_error()); return; }
    if (sb_build(&d, &m, &o, 1)) { T_CHECK(0, "build limb: %s", sb_error()); return; }
    for (i = 0; i < o.nf; i++) {
        const double *p = o.x + 3 * i;
        double da = dist_seg_x(p, 0, 4), db = dist_seg_x(p, 4, 8), d1 = fmin(da, db), d2 = fmax(da, db), sc, w;
        int near = da <= db ? 0 : 1;   /* sorted joints: shoulder 0, elbow 1, wrist 2 */
        sc = 1 - (d2 - d1) / 1.0;
        sc = sc < 0 ? 0 : sc > 1 ? 1 : sc;
        w = 0.5 * sc * sc * (3 - 2 * sc);
        if (fabs(o.fw[i] - w) > 1e-12) bad++;
        else if (w > 0 && da != db && (o.fb1[i] != near || o.fb2[i] != 1 - near)) bad++;
        else if (w == 0 && (o.fb1[i] != near || o.fb2[i] != near)) bad++;
        if (w == 0.5) n_half++;
        if (w == 0) n_zero++;
    }
    T_CHECK(bad == 0, "limb frames follow the documented blend rule: %d of %d free vertices differ", bad, o.nf);
    T_CHECK(n_half > 0 && n_zero > 0, "both blended (%d at w = 1/2) and single-bone (%d) vertices exist", n_half, n_zero);
    for (i = 0, bad = 0; i < o.nc; i++) {   /* cell frames: the same rule at the cell centre */
        double p[3], da, db, d1, d2, sc, w;
        int k, near;
        for (k = 0; k < 3; k++) p[k] = o.x[3 * o.cells[8 * i] + k] + 0.5 * o.c;
        da = dist_seg_x(p, 0, 4); db = dist_seg_x(p, 4, 8); d1 = fmin(da, db); d2 = fmax(da, db); near = da <= db ? 0 : 1;
        sc = 1 - (d2 - d1) / 1.0;
        sc = sc < 0 ? 0 : sc > 1 ? 1 : sc;
        w = 0.5 * sc * sc * (3 - 2 * sc);
        if (fabs(o.cfw[i] - w) > 1e-12) bad++;
        else if (w > 0 && da != db && (o.cfb1[i] != near || o.cfb2[i] != 1 - near)) bad++;
        else if (w == 0 && (o.cfb1[i] != near || o.cfb2[i] != near)) bad++;
    }
    T_CHECK(bad == 0, "limb cell frames follow the blend rule at the cell centres: %d of %d cells differ", bad, o.nc);
    check_cells(&o, "limb");
    sb_model_free(&o); sb_mesh_free(&m); sb_desc_free(&d);
}

/* volume by the divergence theorem, written here independently of the tool */
static double volume(const sb_mesh *m)
{
    double v = 0;
    int t;
    for (t = 0; t < m->nt; t++) {
        const double *a = m->v + 3 * m->tri[3 * t], *b = m->v + 3 * m->tri[3 * t + 1], *c = m->v + 3 * m->tri[3 * t + 2];
        /* signed tetrahedron (0, a, b, c): det[a b c] / 6 */
        v += (a[0] * b[1] * c[2] + a[1] * b[2] * c[0] + a[2] * b[0] * c[1] - a[2] * b[1] * c[0] - a[1] * b[0] * c[2] - a[0] * b[2] * c[1]) / 6;
    }
    return v;
}

static void test_cow(void)
{
    sb_desc d;
    sb_mesh m;
    sb_model o;
    int i, j, e, k, a, b;
    double maxS = 0, maxx = 0, trans = 0, rot = 0, vol, unit;
    T_CHECK(sb_desc_load(COW, &d) == 0, "load cow: %s", sb_error());
    T_CHECK(sb_mesh_load_obj(d.mesh_path, &m) == 0, "cow mesh: %s", sb_error());
    /* uniform density and no air so that mass = rho * vol(Omega) exactly up to quadrature */
    for (i = 0; i < d.nm; i++) d.mats[i].rho = 1000;
    d.air = 0;
    if (sb_build(&d, &m, &o, 1)) { T_CHECK(0, "build cow: %s", sb_error()); return; }
    unit = d.unit;
    T_FIGURE("cow lattice: %d vertices (%d free, %d skeleton), %d cells (air 0: %d left trilinear, K_aa not positive definite)",
             o.nv, o.nf, o.nv - o.nf, o.nc, o.n_uncondensed);
    T_CHECK(o.nv >= 150 && o.nv <= 360, "cow lattice size %d in the target range (~150-300)", o.nv);
    vol = volume(&m) * unit * unit * unit;
    T_NEAR(o.mass / (1000 * vol), 1.0, 0.01, "inside fractions exact along x, sampled in y and z at <= 1/2000 of the extent");
    T_FIGURE("cow: lattice mass %.4f kg vs rho*vol %.4f kg (ratio %.5f)", o.mass, 1000 * vol, o.mass / (1000 * vol));
    /* null space of the elastic stiffness (no twist): translations, infinitesimal rotations */
    for (e = 0; e < o.nbptr[o.nv]; e++) for (k = 0; k < 9; k++) maxS = fmax(maxS, fabs(o.S[9 * e + k]));
    for (i = 0; i < o.nv; i++) for (k = 0; k < 3; k++) maxx = fmax(maxx, fabs(o.x[3 * i + k] * unit));
    for (i = 0; i < o.nv; i++) {
        for (a = 0; a < 3; a++) {
            double tsum[3] = {0, 0, 0}, rsum[3] = {0, 0, 0};
            for (e = o.nbptr[i]; e < o.nbptr[i + 1]; e++) {
                j = o.nb[e];
                for (b = 0; b < 3; b++) {
                    double u[3] = {0, 0, 0}, r[3];
                    const double *x = o.x + 3 * j;
                    u[b] = 1;
                    tsum[b] += o.S[9 * e + 3 * a + b];
                    /* rotation about axis b: u = e_b x x (metres) */
                    r[0] = u[1] * x[2] - u[2] * x[1]; r[1] = u[2] * x[0] - u[0] * x[2]; r[2] = u[0] * x[1] - u[1] * x[0];
                    for (k = 0; k < 3; k++) rsum[b] += o.S[9 * e + 3 * a + k] * r[k] * unit;
                }
            }
            for (b = 0; b < 3; b++) { trans = fmax(trans, fabs(tsum[b])); rot = fmax(rot, fabs(rsum[b])); }
        }
    }
    T_NEAR(trans / maxS, 0, 1e-12, "block row sums: sum of ~27 blocks of size maxS, double round-off");
    T_NEAR(rot / (maxS * maxx), 0, 1e-11, "rotations: ~27 blocks times coordinates up to maxx, double round-off");
    T_FIGURE("cow null space: translations %.2e, rotations %.2e (relative)", trans / maxS, rot / (maxS * maxx));
    check_bones(&o, "cow");
    T_CHECK(o.nseg == 14, "cow has 14 bones (got %d)", o.nseg);
    check_cells(&o, "cow");
    for (i = 0; i < o.nj; i++) T_CHECK(o.joints[i].parent < i, "joint %d's parent precedes it", i);
    for (i = 0; i < o.nf; i++) T_CHECK(o.fw[i] >= 0 && o.fw[i] <= 0.5, "free vertex %d: w in [0, 1/2]", i);
    /* embedding reproduces the mesh, with t quantized to Q15 as stored in the blob */
    {
        double worst = 0;
        for (i = 0; i < o.ns; i++) {
            double t[3], p[3], dd = 0;
            for (k = 0; k < 3; k++) t[k] = floor(o.emb_t[3 * i + k] * 32768.0 + 0.5) / 32768.0;
            sb_cell_point(&o, o.emb_cell[i], t, p);
            for (k = 0; k < 3; k++) dd += (p[k] - m.v[3 * i + k]) * (p[k] - m.v[3 * i + k]);
            worst = fmax(worst, sqrt(dd));
        }
        T_NEAR(worst / o.bbox_diag, 0, 1e-5, "Q15 coordinates: <= 2^-16 cell per axis ~ 2e-6 of the diagonal");
        T_FIGURE("cow embedding: max error %.3g mesh units = %.2e of bbox diagonal %.3f", worst, worst / o.bbox_diag, o.bbox_diag);
    }
    sb_model_free(&o); sb_mesh_free(&m); sb_desc_free(&d);
}


/* write a description next to the limb mesh (absolute mesh path) with extra lines */
static int limb_variant(const char *path, const char *extra)
{
    FILE *f = fopen(path, "w");
    char cwd[1024];
    if (!f || !getcwd(cwd, sizeof cwd)) { if (f) fclose(f); return -1; }
    fprintf(f, "mesh %s/tools/examples/limb/limb.obj\nunit 0.05\ncell 1.0\njoint shoulder - 0 0 0\njoint elbow shoulder 4 0 0\n"
               "joint wrist elbow 8 0 0\nmaterial flesh 3e4 0.3 1000\n%s", cwd, extra);
    return fclose(f);
}

/* radius capture in closed form: limb bones along the x axis through grid vertices (cell 1),
 * bone_radius 1: the axis x = 0..8 (9 vertices), the ring at distance 1 around it (4 x 9)
 * and the two vertices one cell beyond the ends: 47 skeleton vertices. The nearest bone
 * wins; at x = 4 both are at the same distance: the lower joint index (the upper arm,
 * moved by the shoulder). 'bone wrist 0' then leaves the forearm its chain only. */
static void test_radius(void)
{
    const char *dir = getenv("BUILD") ? getenv("BUILD") : "build";
    char path[512];
    int pass;
    snprintf(path, sizeof path, "%s/tests/bake_limb_radius.sinew", dir);
    for (pass = 0; pass < 2; pass++) {
        sb_desc d;
        sb_mesh m;
        sb_model o;
        int i, bad = 0, want = pass ? 9 + 4 * 5 + 1 : 47;
        T_CHECK(limb_variant(path, pass ? "bone_radius 1\nbone wrist 0\n" : "bone_radius 1\n") == 0, "write %s", path);
        if (sb_desc_load(path, &d) || sb_mesh_load_obj(d.mesh_path, &m)) { T_CHECK(0, "load: %s", sb_error()); return; }
        if (sb_build(&d, &m, &o, 1)) { T_CHECK(0, "build: %s", sb_error()); sb_mesh_free(&m); sb_desc_free(&d); return; }
        /* pass 1: the axis (9), the upper arm's ring x = 0..4 (4 x 5) and (-1,0,0); the forearm keeps its chain */
        T_CHECK(o.nv - o.nf == want, "bone_radius 1%s: %d skeleton vertices, want %d", pass ? ", bone wrist 0" : "", o.nv - o.nf, want);
        T_NEAR(o.seg_r[0], 1.0, 0, "upper arm radius as given");
        T_NEAR(o.seg_r[1], pass ? 0.0 : 1.0, 0, "forearm radius as given");
        for (i = o.nf; i < o.nv; i++) {
            const double *x = o.x + 3 * i;
            int want_j = x[0] <= 4 ? 0 : 1;   /* shoulder moves the upper arm, elbow the forearm */
            if (o.fb1[i] != want_j) bad++;
        }
        T_CHECK(bad == 0, "nearest bone wins, ties to the lower joint index: %d skeleton vertices moved by the wrong joint", bad);
        sb_model_free(&o); sb_mesh_free(&m); sb_desc_free(&d);
    }
}

/* the statements added with volumetric bones; 'twist' is an error now */
static void test_statements(void)
{
    const char *dir = getenv("BUILD") ? getenv("BUILD") : "build";
    char path[512];
    sb_desc d;
    sb_mesh m;
    sb_model o;
    int i, bad = 0, n3 = 0, n5 = 0;
    snprintf(path, sizeof path, "%s/tests/bake_limb_stmt.sinew", dir);
    limb_variant(path, "twist 4e5 0.5\n");
    T_CHECK(sb_desc_load(path, &d) != 0 && strstr(sb_error(), ":8: 'twist' is retired") && strstr(sb_error(), "bone_radius"),
            "twist: a file:line error naming the replacement (got '%s')", sb_error());
    sb_desc_free(&d);
    limb_variant(path, "bone shoulder 1\n");
    T_CHECK(sb_desc_load(path, &d) != 0 && strstr(sb_error(), "is the root"), "bone radius of the root: error (got '%s')", sb_error());
    sb_desc_free(&d);
    limb_variant(path, "bone elbow -1\n");
    T_CHECK(sb_desc_load(path, &d) != 0 && strstr(sb_error(), ":8: bone radius must be >= 0"), "negative radius: error (got '%s')", sb_error());
    sb_desc_free(&d);
    limb_variant(path, "limit all -1\n");
    T_CHECK(sb_desc_load(path, &d) != 0 && strstr(sb_error(), ":8: limit distance must be >= 0"), "negative limit: error (got '%s')", sb_error());
    sb_desc_free(&d);
    limb_variant(path, "rest_shape relaxed\n");
    T_CHECK(sb_desc_load(path, &d) != 0 && strstr(sb_error(), ":8: unknown rest shape 'relaxed'"), "bad rest shape: error (got '%s')", sb_error());
    sb_desc_free(&d);
    limb_variant(path, "rest_shape sag\nrest_shape modelled\nlimit all 3\nlimit box 5.5 -9 -9 9 9 9 5\nlimit sphere 8 0 0 0.5 0\n");
    if (sb_desc_load(path, &d) || sb_mesh_load_obj(d.mesh_path, &m)) { T_CHECK(0, "load: %s", sb_error()); return; }
    if (sb_build(&d, &m, &o, 1)) { T_CHECK(0, "build: %s", sb_error()); return; }
    T_CHECK(o.rest_modelled == 1, "rest_shape modelled (the later statement) reaches the model");
    for (i = 0; i < o.nv; i++) {   /* later rules override, evaluated at rest positions */
        const double *x = o.x + 3 * i;
        double want = x[0] >= 5.5 ? 5 : 3;
        if ((x[0] - 8) * (x[0] - 8) + x[1] * x[1] + x[2] * x[2] <= 0.25) want = 0;
        if (o.limit[i] != want) bad++;
        n3 += o.limit[i] == 3; n5 += o.limit[i] == 5;
    }
    T_CHECK(bad == 0 && n3 > 0 && n5 > 0, "limit rules: %d of %d vertices wrong (%d at 3, %d at 5)", bad, o.nv, n3, n5);
    sb_model_free(&o); sb_mesh_free(&m); sb_desc_free(&d);
}

/* the synthetic character with bones at 30, 45 and 60 degrees (and along (1,1,1)):
 * the old construction folded cells here; now it bakes at any cell size and every check holds */
static void test_diag(void)
{
    static const double cells[3] = {0.5, 1.0, 2.5};
    int ci;
    for (ci = 0; ci < 3; ci++) {
        sb_desc d;
        sb_mesh m;
        sb_model o;
        sb_check r;
        char what[64];
        if (sb_desc_load("tools/examples/diag/diag.sinew", &d) || sb_mesh_load_obj(d.mesh_path, &m)) { T_CHECK(0, "load diag: %s", sb_error()); return; }
        d.cell = cells[ci];
        snprintf(what, sizeof what, "diag cell %g", cells[ci]);
        if (sb_build(&d, &m, &o, 1)) { T_CHECK(0, "%s: build: %s", what, sb_error()); sb_mesh_free(&m); sb_desc_free(&d); continue; }
        T_NEAR(o.min_jac, 1.0, 1e-12, "undistorted cubes");
        T_CHECK(sb_model_check(&o, &m, &r) == 0, "%s: checks: volume ratio %.5f, embedding %.2e, translations %.1e, rotations %.1e",
                what, r.vol_ratio, r.emb_err, r.trans, r.rot);
        T_FIGURE("%s: %d vertices (%d free), %d cells, volume ratio %.5f", what, o.nv, o.nf, o.nc, r.vol_ratio);
        T_CHECK(o.nseg == 16, "%s: 16 bones", what);
        check_bones(&o, what);
        check_cells(&o, what);
        sb_model_free(&o); sb_mesh_free(&m); sb_desc_free(&d);
    }
}

int main(void)
{
    (void)t_seed;   /* harness helper unused here (no random tests) */
    test_single_cell(0);
    test_single_cell(1);
    test_cow_patch();
    test_inside_edges();
    test_material_rules();
    test_limb_frames();
    test_cow();
    test_radius();
    test_statements();
    test_diag();
    return T_END();
}
