/* sb_integrate.c -- mass and elastic stiffness integrals over the interior
 * only (seed 000 §3.3; DESIGN.md "The model"). Every cell is an undistorted
 * cube (sb_lattice.c); in reference coordinates it is split into subdiv^3
 * sub-boxes with 2x2x2 Gauss points each, and points outside the mesh are
 * weighted by `air` (default 1e-3, so no kept vertex has zero mass).
 * Element `incompatible` (default) adds the 9 Wilson bubble modes and condenses
 * them out per cell: trilinear hexes lock in bending (tests/reference/README.md,
 * Findings 1). Wilson, Taylor, Doherty & Ghaboussi 1973. The twist term
 * (seed 000 eq. 25-26) is retired: bones have volume. */
#include "sb.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* strain-stress product of two scalar gradients ga (component i) and gb (component j):
 * lam ga_i gb_j + mu ga_j gb_i + mu delta_ij ga.gb (the same form as S_ab[i][j]) */
static double ss(const double ga[3], int i, const double gb[3], int j, double lam, double mu)
{
    return lam * ga[i] * gb[j] + mu * ga[j] * gb[i] + (i == j ? mu * (ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2]) : 0.0);
}

/* Se -= Kua Kaa^-1 Kua^T by Cholesky of the 9x9 Kaa. Returns -1 (Se untouched) if
 * Kaa is not numerically positive definite (a cell with almost no weight). */
static int condense(double Se[8][8][9], double Kaa[9][9], double Kua[24][9])
{
    double L[9][9], X[9][24];
    int i, j, k, a, b;
    for (j = 0; j < 9; j++) {
        double s = Kaa[j][j];
        for (k = 0; k < j; k++) s -= L[j][k] * L[j][k];
        if (!(s > 1e-10 * Kaa[j][j])) return -1;   /* also catches NaN and Kaa[j][j] <= 0 */
        L[j][j] = sqrt(s);
        for (i = j + 1; i < 9; i++) {
            double r = Kaa[i][j];
            for (k = 0; k < j; k++) r -= L[i][k] * L[j][k];
            L[i][j] = r / L[j][j];
        }
    }
    /* X = Kaa^-1 Kua^T: forward then back substitution, 24 right-hand sides */
    for (b = 0; b < 24; b++) {
        for (i = 0; i < 9; i++) {
            double r = Kua[b][i];
            for (k = 0; k < i; k++) r -= L[i][k] * X[k][b];
            X[i][b] = r / L[i][i];
        }
        for (i = 8; i >= 0; i--) {
            double r = X[i][b];
            for (k = i + 1; k < 9; k++) r -= L[k][i] * X[k][b];
            X[i][b] = r / L[i][i];
        }
    }
    for (a = 0; a < 24; a++)
        for (b = 0; b <= a; b++) {
            double t = 0, u = 0;
            for (k = 0; k < 9; k++) { t += Kua[a][k] * X[k][b]; u += Kua[b][k] * X[k][a]; }
            t = 0.5 * (t + u);   /* symmetric up to round-off: keep it exactly symmetric */
            Se[a / 3][b / 3][3 * (a % 3) + b % 3] -= t;
            if (a != b) Se[b / 3][a / 3][3 * (b % 3) + a % 3] -= t;
        }
    return 0;
}

/* 3-point Gauss-Legendre nodes on [0,1] and the Lagrange basis through them */
static const double gl3[3] = {0.11270166537925831148, 0.5, 0.88729833462074168852};
static void lag3(double t, double L[3])
{
    L[0] = (t - gl3[1]) * (t - gl3[2]) / ((gl3[0] - gl3[1]) * (gl3[0] - gl3[2]));
    L[1] = (t - gl3[0]) * (t - gl3[2]) / ((gl3[1] - gl3[0]) * (gl3[1] - gl3[2]));
    L[2] = (t - gl3[0]) * (t - gl3[1]) / ((gl3[2] - gl3[0]) * (gl3[2] - gl3[1]));
}

/* Element of one material on a cube of edge h metres from its 27 moment weights
 * mw[i + 3j + 9k] = sum_q w_q L_i(t_qx) L_j(t_qy) L_k(t_qz) over the cell's quadrature
 * points q (weights w_q in m^3, outside points scaled by air). Every integrand below
 * has degree <= 2 per axis, so it equals its tensor interpolant through the 27 nodes
 * and sum_q w_q P(t_q) = sum_ijk mw_ijk P(node_ijk) exactly: the 27-node rule gives the
 * same matrices as the full quadrature at 1/19 of the cost (moment fitting).
 * M_ab += rho sum w Na Nb;  S_ab[i][j] += sum w (lam dNa/dxi dNb/dxj + mu dNa/dxj dNb/dxi + mu dij gradNa.gradNb);
 * Kaa, Kua: the 9 bubbles P_k = 4 t_k (1 - t_k) per component (Wilson et al. 1973). */
static void element_add(const sb_material *mat, double h, const double mw[27], double Me[8][8], double Se[8][8][9],
                        double Kaa[9][9], double Kua[24][9], int inc)
{
    double lam = mat->E * mat->nu / ((1 + mat->nu) * (1 - 2 * mat->nu)), mu = mat->E / (2 * (1 + mat->nu)), rho = mat->rho;
    int q, a, b, i, j, kk, c, k, cc;
    for (q = 0; q < 27; q++) {
        double t[3], N[8], dN[8][3], G[8][3], w = mw[q];
        if (w == 0) continue;
        t[0] = gl3[q % 3]; t[1] = gl3[q / 3 % 3]; t[2] = gl3[q / 9];
        sb_shape(t, N, dN);
        for (a = 0; a < 8; a++) for (k = 0; k < 3; k++) G[a][k] = dN[a][k] / h;
        for (a = 0; a < 8; a++)
            for (b = a; b < 8; b++) {
                double gg = G[a][0] * G[b][0] + G[a][1] * G[b][1] + G[a][2] * G[b][2];
                Me[a][b] += w * rho * N[a] * N[b];
                for (i = 0; i < 3; i++)
                    for (j = 0; j < 3; j++)
                        Se[a][b][3 * i + j] += w * (lam * G[a][i] * G[b][j] + mu * G[a][j] * G[b][i] + (i == j ? mu * gg : 0.0));
            }
        if (inc) {   /* bubble kk, component c: gradient 4 (1 - 2 t_kk) / h e_kk, displacement along e_c */
            double ga[3][3];
            for (kk = 0; kk < 3; kk++) for (c = 0; c < 3; c++) ga[kk][c] = kk == c ? 4.0 * (1.0 - 2.0 * t[kk]) / h : 0.0;
            for (kk = 0; kk < 3; kk++)
                for (c = 0; c < 3; c++) {
                    for (k = 0; k < 3; k++)
                        for (cc = 0; cc < 3; cc++) Kaa[3 * kk + c][3 * k + cc] += w * ss(ga[kk], c, ga[k], cc, lam, mu);
                    for (a = 0; a < 8; a++)
                        for (i = 0; i < 3; i++) Kua[3 * a + i][3 * kk + c] += w * ss(G[a], i, ga[kk], c, lam, mu);
                }
        }
    }
}

/* complete the lower triangle (S_ba = S_ab^T) and condense; returns 1 if condensed */
static int element_finish(double Me[8][8], double Se[8][8][9], double Kaa[9][9], double Kua[24][9], int inc)
{
    int a, b, i, j;
    for (a = 0; a < 8; a++)
        for (b = 0; b < a; b++) {
            Me[a][b] = Me[b][a];
            for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) Se[a][b][3 * i + j] = Se[b][a][3 * j + i];
        }
    return inc && condense(Se, Kaa, Kua) == 0;
}

int sb_integrate(const sb_desc *d, sb_model *o, const unsigned char *inbits)
{
    int n = d->subdiv, npt = n * n * n * 8, ngc = (o->gn[0] - 1) * (o->gn[1] - 1) * (o->gn[2] - 1), a, q, ns = 0, rc;
    int *fidx = sb_alloc(sizeof(int) * (size_t)ngc);
    double *frac;
    for (a = 0; a < ngc; a++) fidx[a] = -1;
    for (a = 0; a < o->nc; a++) fidx[o->cell_grid[a]] = ns++;
    frac = sb_alloc(sizeof(double) * (size_t)npt * (size_t)(ns ? ns : 1));
    for (a = 0; a < o->nc; a++)
        for (q = 0; q < npt; q++) frac[(size_t)fidx[o->cell_grid[a]] * (size_t)npt + (size_t)q] = inbits[(size_t)o->cell_grid[a] * (size_t)npt + (size_t)q];
    rc = sb_integrate_frac(d, o, frac, fidx);
    free(fidx); free(frac);
    return rc;
}

int sb_integrate_frac(const sb_desc *d, sb_model *o, const double *frac, const int *fidx)
{
    static const double gp2[2] = {0.21132486540518711775, 0.78867513459481288225};
    int n = d->subdiv, npt = n * n * n * 8, ci, a, b, k, q, r, inc = d->element == SB_ELEM_INCOMPATIBLE, nskip = 0;
    double t0 = sb_now(), h = o->c * o->unit, w0 = h * h * h / (8.0 * n * n * n);   /* Gauss weight 1/8 per sub-box of volume 1/n^3 */
    double (*tq)[3] = sb_alloc(sizeof(double) * 3 * (size_t)npt), (*Lq)[9] = sb_alloc(sizeof(double) * 9 * (size_t)npt);
    double *mom = sb_alloc(sizeof(double) * 27 * (size_t)d->nm);
    double (*cacheS)[8][8][9] = sb_alloc(sizeof(*cacheS) * 2 * (size_t)d->nm), (*cacheM)[8][8] = sb_alloc(sizeof(*cacheM) * 2 * (size_t)d->nm);
    int *cached = sb_alloc(sizeof(int) * 2 * (size_t)d->nm), *mq = sb_alloc(sizeof(int) * (size_t)npt), *used = sb_alloc(sizeof(int) * (size_t)d->nm);
    for (q = 0; q < npt; q++) {
        int sx = q / 8 % n, sy = q / 8 / n % n, sz = q / 8 / (n * n), gp = q % 8;
        tq[q][0] = (sx + gp2[gp & 1]) / n; tq[q][1] = (sy + gp2[(gp >> 1) & 1]) / n; tq[q][2] = (sz + gp2[(gp >> 2) & 1]) / n;
        for (k = 0; k < 3; k++) lag3(tq[q][k], Lq[q] + 3 * k);
    }
    o->inside_volume = 0; o->mass = 0;
    for (ci = 0; ci < o->nc; ci++) {
        double Me[8][8], Se[8][8][9], Kaa[9][9], Kua[24][9], *Sc = o->Se + 576 * (size_t)ci;
        const double *x0 = o->x + 3 * o->cells[8 * ci];
        int fi = fidx[o->cell_grid[ci]], mat0 = 0, onemat = 1, cond, i, j;
        const double *f = fi >= 0 ? frac + (size_t)fi * (size_t)npt : NULL;
        for (q = 0; q < npt; q++) {   /* material of each point (later rules override) */
            double p[3];
            int mat = 0;
            if (d->nmr) {
                for (k = 0; k < 3; k++) p[k] = x0[k] + tq[q][k] * o->c;
                for (r = 0; r < d->nmr; r++) if (sb_region_has(o, &d->mrules[r].r, p)) mat = d->mrules[r].mat;
            }
            mq[q] = mat;
            if (q == 0) mat0 = mat; else if (mat != mat0) onemat = 0;
        }
        memset(Me, 0, sizeof Me); memset(Se, 0, sizeof Se); memset(Kaa, 0, sizeof Kaa); memset(Kua, 0, sizeof Kua);
        if (f == NULL && onemat) {   /* wholly inside or outside, one material: one shared element */
            int in = fi == -2, key = 2 * mat0 + in;
            o->inside_volume += in ? w0 * npt : 0;
            if (!cached[key]) {
                double mw[27];
                int x, y, z;
                for (x = 0; x < 3; x++) for (y = 0; y < 3; y++) for (z = 0; z < 3; z++) {
                    static const double W[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};   /* = sum_q w L: the Gauss weights */
                    mw[x + 3 * y + 9 * z] = h * h * h * W[x] * W[y] * W[z] * (in ? 1.0 : d->air);
                }
                element_add(&d->mats[mat0], h, mw, cacheM[key], cacheS[key], Kaa, Kua, inc);
                cached[key] = 1 + element_finish(cacheM[key], cacheS[key], Kaa, Kua, inc);
            }
            memcpy(Me, cacheM[key], sizeof Me); memcpy(Se, cacheS[key], sizeof Se);
            cond = cached[key] == 2;
        } else {   /* moment weights per material, then one 27-node element per material */
            for (q = 0; q < npt; q++) {
                double fq = f ? f[q] : fi == -2 ? 1.0 : 0.0, w = w0 * (fq + d->air * (1 - fq)), *mw = mom + 27 * mq[q];
                const double *L = Lq[q];
                int x, y, z;
                o->inside_volume += w0 * fq;
                if (!used[mq[q]]) { used[mq[q]] = 1; memset(mw, 0, sizeof(double) * 27); }
                if (w == 0) continue;
                for (z = 0; z < 3; z++) for (y = 0; y < 3; y++) {
                    double wyz = w * L[3 + y] * L[6 + z];
                    for (x = 0; x < 3; x++) mw[x + 3 * y + 9 * z] += wyz * L[x];
                }
            }
            for (k = 0; k < d->nm; k++)
                if (used[k]) { element_add(&d->mats[k], h, mom + 27 * k, Me, Se, Kaa, Kua, inc); used[k] = 0; }
            cond = element_finish(Me, Se, Kaa, Kua, inc);
        }
        if (inc && !cond) nskip++;   /* K_aa not positive definite: the trilinear element stays */
        for (a = 0; a < 8; a++)
            for (b = 0; b < 8; b++) {
                int e = sb_pattern_find(o, o->cells[8 * ci + a], o->cells[8 * ci + b]);
                o->M[e] += Me[a][b];
                if (o->Me) o->Me[64 * (size_t)ci + (size_t)(8 * a + b)] = Me[a][b];
                for (k = 0; k < 9; k++) o->S[9 * (size_t)e + (size_t)k] += Se[a][b][k];
                for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) Sc[24 * (3 * a + i) + 3 * b + j] = Se[a][b][3 * i + j];
                o->mass += Me[a][b];
            }
        if (!o->quiet && sb_now() - t0 > 1.0 && (ci & 15) == 0)
            fprintf(stderr, "\rsinew-bake: integrating %3d%%", (int)(100.0 * ci / o->nc));
    }
    o->n_uncondensed = nskip;
    if (nskip && !o->quiet)
        fprintf(stderr, "\rsinew-bake: %d cell(s) with almost no interior weight keep the trilinear element\n", nskip);
    free(tq); free(Lq); free(mom); free(cacheS); free(cacheM); free(cached); free(mq); free(used);
    {   /* the per-cell matrices assemble to S (they are what was summed; checked, as the blob writer relies on it) */
        size_t ne = (size_t)o->nbptr[o->nv], e;
        double *S2 = sb_alloc(sizeof(double) * 9 * ne), maxS = 0, err = 0;
        for (ci = 0; ci < o->nc; ci++)
            for (a = 0; a < 8; a++)
                for (b = 0; b < 8; b++) {
                    int pe = sb_pattern_find(o, o->cells[8 * ci + a], o->cells[8 * ci + b]), i, j;
                    for (i = 0; i < 3; i++)
                        for (j = 0; j < 3; j++) S2[9 * (size_t)pe + (size_t)(3 * i + j)] += o->Se[576 * (size_t)ci + (size_t)(24 * (3 * a + i) + 3 * b + j)];
                }
        for (e = 0; e < 9 * ne; e++) { maxS = fmax(maxS, fabs(o->S[e])); err = fmax(err, fabs(o->S[e] - S2[e])); }
        free(S2);
        if (!(err <= 1e-12 * maxS)) return sb_fail("internal error: per-cell stiffness does not assemble to S (%g of max)", err / maxS);
    }
    return 0;
}
