/* test_bake_fem.c -- host tool: integrals and lattice against independent
 * references (closed-form trilinear hex element, null spaces, volume by the
 * divergence theorem, bones on lattice edges). */
#include "sb.h"
#include "sn_test.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

static void test_single_cell(void)
{
    const char *dir = getenv("BUILD") ? getenv("BUILD") : "build";
    char obj[512], desc[512];
    FILE *f;
    sb_desc d;
    sb_mesh m;
    sb_model o;
    const double s = 2.0, unit = 0.3, a = s * unit, E = 2e5, nu = 0.3, rho = 900;
    const double lam = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    double maxS = 0, errS = 0, errM = 0;
    int va, vb, A, B, i, j;
    snprintf(obj, sizeof obj, "%s/tests/bake_cube.obj", dir);
    snprintf(desc, sizeof desc, "%s/tests/bake_cube.sinew", dir);
    T_CHECK(write_cube_obj(obj, s) == 0, "write %s", obj);
    f = fopen(desc, "w");
    T_CHECK(f != NULL, "write %s", desc);
    if (!f) return;
    fprintf(f, "mesh bake_cube.obj\nunit %g\ncell %g\norigin 0 0 0\njoint root - 1 1 1\n"
               "material m %g %g %g\npin box -1 -1 -1 0.001 0.001 0.001 root\n", unit, s, E, nu, rho);
    fclose(f);
    T_CHECK(sb_desc_load(desc, &d) == 0, "load: %s", sb_error());
    T_CHECK(sb_mesh_load_obj(d.mesh_path, &m) == 0, "mesh: %s", sb_error());
    if (sb_build(&d, &m, &o, 1)) { T_CHECK(0, "build: %s", sb_error()); return; }
    T_CHECK(o.nc == 1 && o.nv == 8 && o.nf == 7, "one cell, 8 vertices, 7 free: got %d cells %d vertices %d free", o.nc, o.nv, o.nf);
    if (o.nc != 1) return;
    for (A = 0; A < 8; A++)
        for (B = 0; B < 8; B++) {
            int e;
            va = o.cells[A]; vb = o.cells[B];
            e = sb_pattern_find(&o, va, vb);
            T_CHECK(e >= 0, "pattern has (%d,%d)", va, vb);
            if (e < 0) continue;
            {
                double Mref = rho, gg = 0;
                int dd;
                for (dd = 0; dd < 3; dd++) Mref *= i_ll(A >> dd & 1, B >> dd & 1, a);
                errM = fmax(errM, fabs(o.M[e] - Mref) / (rho * a * a * a));
                for (dd = 0; dd < 3; dd++) gg += i_grad(A, B, dd, dd, a);
                for (i = 0; i < 3; i++)
                    for (j = 0; j < 3; j++) {
                        double Sref = lam * i_grad(A, B, i, j, a) + mu * i_grad(A, B, j, i, a) + (i == j ? mu * gg : 0);
                        errS = fmax(errS, fabs(o.S[9 * e + 3 * i + j] - Sref));
                        maxS = fmax(maxS, fabs(Sref));
                    }
            }
        }
    /* Gauss 2x2x2 per sub-box integrates the trilinear products exactly: only round-off remains */
    T_NEAR(errM, 0, 1e-12, "mass: exact quadrature of degree-2 polynomials, double round-off");
    T_NEAR(errS / maxS, 0, 1e-12, "stiffness: exact quadrature, double round-off");
    T_NEAR(o.mass, rho * a * a * a, 1e-12 * rho * a * a * a, "total mass of a full cell, round-off");
    T_FIGURE("single cell: max |S - S_ref| / max|S_ref| = %.2e, max |M - M_ref| / (rho a^3) = %.2e", errS / maxS, errM);
    sb_model_free(&o); sb_mesh_free(&m); sb_desc_free(&d);
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
    T_FIGURE("cow lattice: %d vertices (%d free, %d skeleton), %d cells", o.nv, o.nf, o.nv - o.nf, o.nc);
    T_CHECK(o.nv >= 150 && o.nv <= 360, "cow lattice size %d in the target range (~150-300)", o.nv);
    vol = volume(&m) * unit * unit * unit;
    T_NEAR(o.mass / (1000 * vol), 1.0, 0.01, "interior quadrature (4^3 sub-boxes x 8 points per cell) resolves the surface to ~1/8 cell");
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
    /* bones: skeleton vertices on bones lie exactly on their segment */
    {
        double worst = 0;
        for (i = o.nf; i < o.nv; i++) {
            double best = HUGE_VAL;
            for (k = 0; k < o.nseg; k++) {
                const double *P = o.joints[o.joints[o.seg_child[k]].parent].pos, *C = o.joints[o.seg_child[k]].pos, *x = o.x + 3 * i;
                double ab[3], ap[3], L2 = 0, t = 0, d2 = 0;
                for (a = 0; a < 3; a++) { ab[a] = C[a] - P[a]; ap[a] = x[a] - P[a]; L2 += ab[a] * ab[a]; t += ab[a] * ap[a]; }
                t = fmin(1, fmax(0, t / L2));
                for (a = 0; a < 3; a++) d2 += (ap[a] - t * ab[a]) * (ap[a] - t * ab[a]);
                best = fmin(best, sqrt(d2));
            }
            worst = fmax(worst, best);
            T_CHECK(o.fb1[i] == o.fb2[i] && o.fw[i] == 0, "skeleton vertex %d: bone1 == bone2, w = 0", i);
        }
        T_NEAR(worst, 0, 1e-12 * o.bbox_diag, "skeleton vertices are placed on the segment: interpolation round-off");
        T_CHECK(o.nseg == 14, "cow has 14 bones (got %d)", o.nseg);
    }
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

int main(void)
{
    (void)t_seed;   /* harness helper unused here (no random tests) */
    test_single_cell();
    test_inside_edges();
    test_material_rules();
    test_limb_frames();
    test_cow();
    return T_END();
}
