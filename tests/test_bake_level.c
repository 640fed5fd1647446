/* test_bake_level.c -- the hierarchical basis of tools/sb_level.c (seed 000
 * §3.1, appendix A.1) on the cow and the beast: the prolongation against hats
 * evaluated here from rest positions, partition of unity where it holds,
 * the hierarchical matrices with every function active against the flat
 * finest lattice's (P^T M P, and back through the inverse transform), each
 * level's nodal matrices against the finest ones, and the basis B's counts. */
#include "sb_level.h"
#include "sn_test.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* the hat of a vertex at p0 on a lattice of edge c, at p: from positions, not grid indices */
static double hat(const double p0[3], double c, const double p[3])
{
    double w = 1;
    int k;
    for (k = 0; k < 3; k++) {
        double t = 1 - fabs(p[k] - p0[k]) / c;
        if (t <= 0) return 0;
        w *= t;
    }
    return w;
}

static unsigned long rng = 12345;
static double rnd(void) { rng = rng * 6364136223846793005UL + 1442695040888963407UL; return (double)(rng >> 11) / 9007199254740992.0 - 0.5; }

/* y = A x for a block-pattern matrix (ncomp 1: scalar entries on 3-vectors' components taken alike; 9: blocks) */
static void matvec(int n, const int *ptr, const int *idx, const double *A, int ncomp, const double *x, double *y)
{
    int i, e, a, b;
    for (i = 0; i < 3 * n; i++) y[i] = 0;
    for (i = 0; i < n; i++)
        for (e = ptr[i]; e < ptr[i + 1]; e++)
            for (a = 0; a < 3; a++)
                for (b = 0; b < 3; b++)
                    if (ncomp == 9) y[3 * i + a] += A[9 * (size_t)e + (size_t)(3 * a + b)] * x[3 * idx[e] + b];
                    else if (a == b) y[3 * i + a] += A[e] * x[3 * idx[e] + b];
}

static double dot(int n, const double *a, const double *b) { double s = 0; int i; for (i = 0; i < n; i++) s += a[i] * b[i]; return s; }

static double maxabs(size_t n, const double *a) { double m = 0; size_t i; for (i = 0; i < n; i++) m = fmax(m, fabs(a[i])); return m; }

static void check_model(const char *desc, int J, int element)
{
    sb_desc d;
    sb_mesh m;
    sb_model o;
    sb_hier h;
    const sb_lev *F;
    const sb_model *fm;
    int n, e, i, j, k, bad;
    double t0 = sb_now(), err, ref;
    char what[256];
    if (sb_desc_load(desc, &d) || sb_mesh_load_obj(d.mesh_path, &m)) { T_CHECK(0, "load %s: %s", desc, sb_error()); return; }
    d.element = element;
    if (sb_build(&d, &m, &o, 1)) { T_CHECK(0, "build %s: %s", desc, sb_error()); return; }
    snprintf(what, sizeof what, "%s J=%d%s", strrchr(desc, '/') + 1, J, element == SB_ELEM_TRILINEAR ? " trilinear" : "");
    if (sb_level_build(&d, &m, &o, J, &h)) { T_CHECK(0, "%s: levels: %s", what, sb_error()); return; }
    F = &h.lev[J]; fm = &h.fine;
    printf("%s: %.1f s\n", what, sb_now() - t0);
    for (j = 0; j <= J; j++) {
        int nfree = 0;
        for (i = 0; i < h.lev[j].nv; i++) nfree += !h.lev[j].skel[i];
        T_FIGURE("%s level %d: cell %g, %d vertices (%d free), %d cells; B: %d functions; new skeleton vertices %d, %d of them not moved by their bone under interpolation",
                 what, j, h.lev[j].c, h.lev[j].nv, nfree, h.lev[j].nc, h.nb_lev[j], h.skel_new[j], h.skel_differ[j]);
    }

    /* 1. complete subdivision: P is square and unit triangular (each finest vertex carries
     * exactly one function with value 1 at its own place, the others are coarser) */
    T_CHECK(h.nh == F->nv, "%s: %d functions for %d finest vertices", what, h.nh, F->nv);
    for (n = 0, bad = 0; n < F->nv; n++) {
        int own = 0;
        for (e = h.pptr[n]; e < h.pptr[n + 1]; e++) {
            int lv = h.hlev[h.pidx[e]], v = h.hvert[h.pidx[e]];
            const double *pv = h.lev[lv].x + 3 * v, *pn = F->x + 3 * n;
            int same = fabs(pv[0] - pn[0]) + fabs(pv[1] - pn[1]) + fabs(pv[2] - pn[2]) < 1e-9 * h.lev[J].c;
            if (same) { own++; if (h.pval[e] != 1) bad++; }
            /* the value against the hat evaluated from positions (round-off of the positions only) */
            if (fabs(h.pval[e] - hat(pv, h.lev[lv].c, pn)) > 1e-12) bad++;
        }
        if (own != 1) bad++;
    }
    T_CHECK(bad == 0, "%s: %d prolongation entries off the hats (1e-12: the positions' round-off) or rows without their own function", what, bad);

    /* 2. partition of unity: the coarse hats sum to 1 at every finest vertex (dyadic values:
     * exact); hence each row block of S_h summed over the coarse columns is 0 (translation),
     * and int rho phi_i = sum over coarse k of M_h(i,k) */
    for (n = 0, bad = 0; n < F->nv; n++) {
        double s = 0;
        for (e = h.pptr[n]; e < h.pptr[n + 1]; e++) if (h.hlev[h.pidx[e]] == 0) s += h.pval[e];
        if (s != 1) bad++;
    }
    T_CHECK(bad == 0, "%s: the coarse hats do not sum to 1 at %d finest vertices", what, bad);
    {
        double maxS = maxabs(9 * (size_t)h.hbptr[h.nh], h.Sh), maxM = maxabs((size_t)h.hbptr[h.nh], h.Mh), et = 0, eg = 0, ed = 0;
        for (i = 0; i < h.nh; i++) {
            double rs[9] = {0}, rm = 0, rd = 0;
            for (e = h.hbptr[i]; e < h.hbptr[i + 1]; e++) {
                if (h.hlev[h.hb[e]] == 0) { for (k = 0; k < 9; k++) rs[k] += h.Sh[9 * (size_t)e + (size_t)k]; rm += h.Mh[e]; }
                rd += h.Mh[e];
            }
            et = fmax(et, maxabs(9, rs)); eg = fmax(eg, fabs(rm - h.gh[i]));
            if (h.hlev[i] > 0) ed = fmax(ed, fabs(rd - h.gh[i]));
        }
        /* 1e-12: sums of at most a few hundred products of round-off 1e-16 relative */
        T_CHECK(et <= 1e-12 * maxS, "%s: S_h times a translation = %g of max|S_h| (want <= 1e-12)", what, et / maxS);
        T_CHECK(eg <= 1e-12 * maxM, "%s: gravity integral vs coarse row sums of M_h: %g of max|M_h| (want <= 1e-12)", what, eg / maxM);
        /* and the detail hats are not a partition of unity: summing every column differs */
        T_CHECK(ed > 1e-6 * maxM, "%s: full row sums of M_h equal the gravity integral (%g): the details would sum to 0", what, ed / maxM);
    }

    /* 3. with every function active: M_h = P^T M_f P and S_h = P^T S_f P, P from the hats here */
    {
        int ne = h.hbptr[h.nh];
        double *RM = calloc((size_t)ne, sizeof(double)), *RS = calloc(9 * (size_t)ne, sizeof(double));
        int *qi = malloc(sizeof(int) * 4096);
        double *qm = malloc(sizeof(double) * 4096), *qs = malloc(sizeof(double) * 9 * 4096);
        int missing = 0;
        for (n = 0; n < F->nv; n++) {   /* row n of Q = M_f P, then R += P(n,:)^T Q(n,:) */
            int nq = 0, f, a;
            for (e = fm->nbptr[n]; e < fm->nbptr[n + 1]; e++) {
                int mm = fm->nb[e], e2;
                for (e2 = h.pptr[mm]; e2 < h.pptr[mm + 1]; e2++) {
                    int fi = h.pidx[e2], lv = h.hlev[fi];
                    double w = hat(h.lev[lv].x + 3 * h.hvert[fi], h.lev[lv].c, F->x + 3 * mm);
                    for (a = 0; a < nq && qi[a] != fi; a++) {}
                    if (a == nq) { qi[nq] = fi; qm[nq] = 0; for (k = 0; k < 9; k++) qs[9 * nq + k] = 0; nq++; }
                    qm[a] += fm->M[e] * w;
                    for (k = 0; k < 9; k++) qs[9 * a + k] += fm->S[9 * (size_t)e + (size_t)k] * w;
                }
            }
            for (e = h.pptr[n]; e < h.pptr[n + 1]; e++) {
                int fk = h.pidx[e], lv = h.hlev[fk];
                double w = hat(h.lev[lv].x + 3 * h.hvert[fk], h.lev[lv].c, F->x + 3 * n);
                for (f = 0; f < nq; f++) {
                    int pe = sb_level_find(h.hbptr, h.hb, fk, qi[f]);
                    if (pe < 0) { missing++; continue; }
                    RM[pe] += w * qm[f];
                    for (k = 0; k < 9; k++) RS[9 * (size_t)pe + (size_t)k] += w * qs[9 * f + k];
                }
            }
        }
        T_CHECK(missing == 0, "%s: %d products outside the hierarchical pattern", what, missing);
        err = 0; ref = maxabs((size_t)ne, h.Mh);
        for (e = 0; e < ne; e++) err = fmax(err, fabs(RM[e] - h.Mh[e]));
        T_FIGURE("%s: |M_h - P^T M_f P| = %.2e of max|M_h|", what, err / ref);
        /* 1e-13: double round-off of sums of at most ~2000 products (27 neighbours x 8 x 8 terms) */
        T_CHECK(err <= 1e-13 * ref, "%s: M_h vs P^T M_f P: %g of max (want <= 1e-13)", what, err / ref);
        err = 0; ref = maxabs(9 * (size_t)ne, h.Sh);
        for (e = 0; e < 9 * ne; e++) err = fmax(err, fabs(RS[e] - h.Sh[e]));
        T_FIGURE("%s: |S_h - P^T S_f P| = %.2e of max|S_h|", what, err / ref);
        T_CHECK(err <= 1e-13 * ref, "%s: S_h vs P^T S_f P: %g of max (want <= 1e-13)", what, err / ref);
        free(RM); free(RS); free(qi); free(qm); free(qs);
    }

    /* 4. back through the inverse (lazy-wavelet analysis: a detail = the nodal value minus the
     * coarser functions' sum there): u^T K_f v = c(u)^T K_h c(v) for random nodal u, v */
    {
        int nv = F->nv, lv;
        double *u = malloc(sizeof(double) * 3 * (size_t)nv), *v = malloc(sizeof(double) * 3 * (size_t)nv);
        double *cu = calloc(3 * (size_t)h.nh, sizeof(double)), *cv = calloc(3 * (size_t)h.nh, sizeof(double));
        double *y = malloc(sizeof(double) * 3 * (size_t)(nv > h.nh ? nv : h.nh)), *back = malloc(sizeof(double) * 3 * (size_t)nv);
        int *node_of = malloc(sizeof(int) * (size_t)h.nh);
        for (n = 0; n < 3 * nv; n++) { u[n] = rnd(); v[n] = rnd(); }
        for (n = 0; n < nv; n++)
            for (e = h.pptr[n]; e < h.pptr[n + 1]; e++) if (h.pval[e] == 1) node_of[h.pidx[e]] = n;
        for (lv = 0; lv <= J; lv++)   /* coarse first: every coarser coefficient is known when a level's are computed */
            for (i = 0; i < h.nh; i++) {
                if (h.hlev[i] != lv) continue;
                n = node_of[i];
                for (k = 0; k < 3; k++) {
                    double su = u[3 * n + k], sv = v[3 * n + k];
                    for (e = h.pptr[n]; e < h.pptr[n + 1]; e++) {
                        int f = h.pidx[e];
                        if (f == i) continue;
                        su -= hat(h.lev[h.hlev[f]].x + 3 * h.hvert[f], h.lev[h.hlev[f]].c, F->x + 3 * n) * cu[3 * f + k];
                        sv -= hat(h.lev[h.hlev[f]].x + 3 * h.hvert[f], h.lev[h.hlev[f]].c, F->x + 3 * n) * cv[3 * f + k];
                    }
                    cu[3 * i + k] = su; cv[3 * i + k] = sv;
                }
            }
        for (n = 0, err = 0; n < nv; n++)   /* synthesis returns u */
            for (k = 0; k < 3; k++) {
                double s = 0;
                for (e = h.pptr[n]; e < h.pptr[n + 1]; e++) s += h.pval[e] * cu[3 * h.pidx[e] + k];
                err = fmax(err, fabs(s - u[3 * n + k]));
            }
        T_CHECK(err <= 1e-14, "%s: synthesis of the analysis is off by %g (want <= 1e-14: a few roundings of values <= 2)", what, err);
        {
            double a, b, sa;
            matvec(nv, fm->nbptr, fm->nb, fm->M, 1, v, y); a = dot(3 * nv, u, y);
            matvec(h.nh, h.hbptr, h.hb, h.Mh, 1, cv, y); b = dot(3 * h.nh, cu, y);
            sa = maxabs((size_t)fm->nbptr[nv], fm->M) * 27 * nv;   /* a bound on sum |u_i M_ij v_j| (|u|,|v| <= 1/2) */
            T_FIGURE("%s: u^T M_f v = %.9g, c(u)^T M_h c(v) = %.9g", what, a, b);
            T_CHECK(fabs(a - b) <= 1e-13 * sa, "%s: mass forms differ by %g of their scale", what, fabs(a - b) / sa);
            matvec(nv, fm->nbptr, fm->nb, fm->S, 9, v, y); a = dot(3 * nv, u, y);
            matvec(h.nh, h.hbptr, h.hb, h.Sh, 9, cv, y); b = dot(3 * h.nh, cu, y);
            sa = maxabs(9 * (size_t)fm->nbptr[nv], fm->S) * 81 * nv;
            T_FIGURE("%s: u^T S_f v = %.9g, c(u)^T S_h c(v) = %.9g", what, a, b);
            T_CHECK(fabs(a - b) <= 1e-13 * sa, "%s: stiffness forms differ by %g of their scale", what, fabs(a - b) / sa);
        }
        free(u); free(v); free(cu); free(cv); free(y); free(back); free(node_of);
    }

    /* 5. each level's nodal matrices: u_j^T K_j v_j = (P_j u_j)^T K_f (P_j v_j), the per-cell
     * matrices assemble to them, constants are reproduced (mass, zero stiffness) */
    for (j = 0; j <= J; j++) {
        const sb_lev *Lj = &h.lev[j];
        int nv = Lj->nv, nf = F->nv, c, a;
        double *u = malloc(sizeof(double) * 3 * (size_t)nv), *v = malloc(sizeof(double) * 3 * (size_t)nv);
        double *pu = calloc(3 * (size_t)nf, sizeof(double)), *pv = calloc(3 * (size_t)nf, sizeof(double)), *y = malloc(sizeof(double) * 3 * (size_t)(nf > nv ? nf : nv));
        unsigned char *done = calloc((size_t)nf, 1);
        double x1, x2, sa, tot = 0, tr = 0, maxS = maxabs(9 * (size_t)Lj->nbptr[nv], Lj->S), asm_err = 0;
        for (n = 0; n < 3 * nv; n++) { u[n] = rnd(); v[n] = rnd(); }
        for (c = 0; c < F->nc; c++) {   /* prolong: each finest vertex from the corners of its level-j ancestor */
            int C = c, l;
            for (l = J; l > j; l--) C = h.lev[l].cell_parent[C];
            for (a = 0; a < 8; a++) {
                int fn = F->cells[8 * c + a];
                if (done[fn]) continue;
                done[fn] = 1;
                for (l = 0; l < 8; l++) {
                    int cv = Lj->cells[8 * C + l];
                    double w = hat(Lj->x + 3 * cv, Lj->c, F->x + 3 * fn);
                    for (k = 0; k < 3; k++) { pu[3 * fn + k] += w * u[3 * cv + k]; pv[3 * fn + k] += w * v[3 * cv + k]; }
                }
            }
        }
        matvec(nf, fm->nbptr, fm->nb, fm->S, 9, pv, y); x1 = dot(3 * nf, pu, y);
        matvec(nv, Lj->nbptr, Lj->nb, Lj->S, 9, v, y); x2 = dot(3 * nv, u, y);
        sa = maxabs(9 * (size_t)fm->nbptr[nf], fm->S) * 81 * nf;
        T_CHECK(fabs(x1 - x2) <= 1e-13 * sa, "%s level %d: nodal stiffness vs prolonged finest: %g of scale", what, j, fabs(x1 - x2) / sa);
        matvec(nf, fm->nbptr, fm->nb, fm->M, 1, pv, y); x1 = dot(3 * nf, pu, y);
        matvec(nv, Lj->nbptr, Lj->nb, Lj->M, 1, v, y); x2 = dot(3 * nv, u, y);
        sa = maxabs((size_t)fm->nbptr[nf], fm->M) * 27 * nf;
        T_CHECK(fabs(x1 - x2) <= 1e-13 * sa, "%s level %d: nodal mass vs prolonged finest: %g of scale", what, j, fabs(x1 - x2) / sa);
        for (i = 0; i < nv; i++) {
            double rs[9] = {0};
            for (e = Lj->nbptr[i]; e < Lj->nbptr[i + 1]; e++) { tot += Lj->M[e]; for (k = 0; k < 9; k++) rs[k] += Lj->S[9 * (size_t)e + (size_t)k]; }
            tr = fmax(tr, maxabs(9, rs));
        }
        /* 1e-11: a sum of ~1e5 positive terms in double (N eps) */
        T_NEAR(tot / h.mass, 1.0, 1e-11, "the level's hats sum to 1: its mass is the finest mass (round-off of the sum)");
        T_CHECK(tr <= 1e-12 * maxS, "%s level %d: S_j times a translation = %g of max (want <= 1e-12)", what, j, tr / maxS);
        {   /* per-cell assembly */
            double *S2 = calloc(9 * (size_t)Lj->nbptr[nv], sizeof(double));
            for (c = 0; c < Lj->nc; c++)
                for (a = 0; a < 8; a++)
                    for (n = 0; n < 8; n++) {
                        int pe = sb_level_find(Lj->nbptr, Lj->nb, Lj->cells[8 * c + a], Lj->cells[8 * c + n]), r, s;
                        for (r = 0; r < 3; r++) for (s = 0; s < 3; s++) S2[9 * (size_t)pe + (size_t)(3 * r + s)] += Lj->Se[576 * (size_t)c + (size_t)(24 * (3 * a + r) + 3 * n + s)];
                    }
            for (e = 0; e < 9 * Lj->nbptr[nv]; e++) asm_err = fmax(asm_err, fabs(S2[e] - Lj->S[e]));
            free(S2);
            T_CHECK(asm_err <= 1e-13 * maxS, "%s level %d: per-cell matrices do not assemble to S_j (%g)", what, j, asm_err / maxS);
        }
        free(u); free(v); free(pu); free(pv); free(y); free(done);
    }

    /* 6. the coarse level against the baked lattice: the same cells and integrand, a finer
     * quadrature (sub-boxes per coarse edge 2^J times as many), so close but not equal */
    {
        const sb_lev *L0 = &h.lev[0];
        double dm = 0, ds = 0, mS = maxabs(9 * (size_t)o.nbptr[o.nv], o.S), mM = maxabs((size_t)o.nbptr[o.nv], o.M);
        for (i = 0; i < o.nv; i++)
            for (e = o.nbptr[i]; e < o.nbptr[i + 1]; e++) {
                int pe = sb_level_find(L0->nbptr, L0->nb, i, o.nb[e]);
                dm = fmax(dm, fabs(L0->M[pe] - o.M[e]));
                for (k = 0; k < 9; k++) ds = fmax(ds, fabs(L0->S[9 * (size_t)pe + (size_t)k] - o.S[9 * (size_t)e + (size_t)k]));
            }
        T_FIGURE("%s: level 0 vs the baked lattice: mass %.6g vs %.6g kg, max entry difference M %.2e, S %.2e of max", what, h.mass, o.mass, dm / mM, ds / mS);
        if (d.element == SB_ELEM_TRILINEAR) {   /* nested spaces: a coarse trilinear field is exact on the finer cells, so on a
                                                  * cell wholly inside, of one material, the product is the coarse element itself */
            int full = 0, same = 0, c;
            for (c = 0; c < o.nc; c++) {
                double e1 = 0, m1 = maxabs(576, o.Se + 576 * (size_t)c);
                if (o.cell_fill[c] < 1) continue;
                full++;
                for (k = 0; k < 576; k++) e1 = fmax(e1, fabs(o.Se[576 * (size_t)c + (size_t)k] - L0->Se[576 * (size_t)c + (size_t)k]));
                same += e1 <= 1e-12 * m1;
            }
            T_FIGURE("%s: %d of %d wholly inside coarse cells have the Galerkin element = the baked element (1e-12)", what, same, full);
            if (full) T_CHECK(same >= full / 2, "%s: only %d of %d inside cells reproduce the coarse element", what, same, full);
        }
        /* 1%: the bake's own interior-volume check (sb_check.vol_ratio) allows 1% */
        T_NEAR(h.mass / o.mass, 1.0, 0.01, "finer quadrature of the same cells: within the bake's 1% volume check");
    }

    /* 7. B: every coarse hat; finer hats only off the skeleton and on the interior */
    for (i = 0, bad = 0; i < h.nh; i++) {
        int lv = h.hlev[i], vv = h.hvert[i];
        if (lv == 0 && !h.in_b[i]) bad++;
        if (lv > 0 && h.in_b[i] && h.lev[lv].skel[vv]) bad++;
    }
    T_CHECK(bad == 0, "%s: %d functions wrongly in or out of B", what, bad);
    T_CHECK(h.nb_fun > h.lev[0].nv && h.nb_fun < h.nh, "%s: B has %d functions (coarse %d, all %d)", what, h.nb_fun, h.lev[0].nv, h.nh);

    sb_hier_free(&h);
    sb_model_free(&o); sb_mesh_free(&m); sb_desc_free(&d);
}

int main(void)
{
    (void)t_seed;
    check_model("tools/examples/cow/cow.sinew", 1, SB_ELEM_INCOMPATIBLE);
    check_model("tools/examples/cow/cow.sinew", 2, SB_ELEM_INCOMPATIBLE);
    check_model("tools/examples/beast/beast.sinew", 1, SB_ELEM_INCOMPATIBLE);
    check_model("tools/examples/cow/cow.sinew", 1, SB_ELEM_TRILINEAR);
    check_model("tools/examples/beast/beast.sinew", 1, SB_ELEM_TRILINEAR);
    return T_END();
}
