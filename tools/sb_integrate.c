/* sb_integrate.c -- mass, elastic stiffness and twist integrals over the
 * interior only (seed 000 §3.3; DESIGN.md "The model"). Each cell is an
 * isoparametric trilinear hex; in reference coordinates it is split into
 * subdiv^3 sub-boxes with 2x2x2 Gauss points each, and points outside the mesh
 * are weighted by `air` (default 1e-3, so no kept vertex has zero mass).
 * Element `incompatible` (default) adds the 9 Wilson bubble modes and condenses
 * them out per cell: trilinear hexes lock in bending (tests/reference/README.md,
 * Findings 1). Wilson, Taylor, Doherty & Ghaboussi 1973; Taylor, Beresford &
 * Wilson 1976 (Jacobian at the centre, so distorted cells pass the patch test). */
#include "sb.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

static double det3(double J[3][3])
{
    return J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) - J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
           J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
}

/* Jacobian dx/dt (metres) of cell ci at reference coords t; returns det, fills inverse dt/dx */
static double jac(const sb_model *o, int ci, const double t[3], double N[8], double dN[8][3], double p[3], double Ji[3][3])
{
    double J[3][3], D;
    int k, a, b;
    sb_shape(t, N, dN);
    memset(J, 0, sizeof J);
    for (a = 0; a < 3; a++) p[a] = 0;
    for (k = 0; k < 8; k++) {
        const double *x = o->x + 3 * o->cells[8 * ci + k];
        for (a = 0; a < 3; a++) {
            p[a] += N[k] * x[a];
            for (b = 0; b < 3; b++) J[a][b] += x[a] * o->unit * dN[k][b];   /* metres */
        }
    }
    D = det3(J);
    /* inverse Jacobian (adjugate / det) */
    Ji[0][0] = (J[1][1] * J[2][2] - J[1][2] * J[2][1]) / D; Ji[0][1] = (J[0][2] * J[2][1] - J[0][1] * J[2][2]) / D;
    Ji[0][2] = (J[0][1] * J[1][2] - J[0][2] * J[1][1]) / D; Ji[1][0] = (J[1][2] * J[2][0] - J[1][0] * J[2][2]) / D;
    Ji[1][1] = (J[0][0] * J[2][2] - J[0][2] * J[2][0]) / D; Ji[1][2] = (J[0][2] * J[1][0] - J[0][0] * J[1][2]) / D;
    Ji[2][0] = (J[1][0] * J[2][1] - J[1][1] * J[2][0]) / D; Ji[2][1] = (J[0][1] * J[2][0] - J[0][0] * J[2][1]) / D;
    Ji[2][2] = (J[0][0] * J[1][1] - J[0][1] * J[1][0]) / D;
    return D;
}

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

int sb_integrate(const sb_desc *d, sb_model *o, const unsigned char *inbits)
{
    static const double gp2[2] = {0.21132486540518711775, 0.78867513459481288225};
    int n = d->subdiv, npt = n * n * n * 8, ci, a, b, k, q, r, inc = d->element == SB_ELEM_INCOMPATIBLE, nskip = 0;
    double t0 = sb_now();
    o->inside_volume = 0; o->mass = 0;
    for (ci = 0; ci < o->nc; ci++) {
        double Me[8][8], Te[8][8], Se[8][8][9], Kaa[9][9], Kua[24][9], J0i[3][3], D0 = 0;
        int sx, sy, sz, gp;
        const unsigned char *bits = inbits + (size_t)o->cell_grid[ci] * (size_t)npt;
        memset(Me, 0, sizeof Me); memset(Te, 0, sizeof Te); memset(Se, 0, sizeof Se);
        memset(Kaa, 0, sizeof Kaa); memset(Kua, 0, sizeof Kua);
        if (inc) {   /* Taylor et al. 1976: bubble gradients with the centre Jacobian */
            static const double tc[3] = {0.5, 0.5, 0.5};
            double N0[8], dN0[8][3], p0[3];
            D0 = jac(o, ci, tc, N0, dN0, p0, J0i);
        }
        q = 0;
        for (sz = 0; sz < n; sz++) for (sy = 0; sy < n; sy++) for (sx = 0; sx < n; sx++)
            for (gp = 0; gp < 8; gp++, q++) {
                double t[3], N[8], dN[8][3], p[3], Ji[3][3], D, w, G[8][3], Ga[3][3], lam, mu, rho, f, tw = 0, sd;
                int mat = 0;
                t[0] = (sx + gp2[gp & 1]) / n; t[1] = (sy + gp2[(gp >> 1) & 1]) / n; t[2] = (sz + gp2[(gp >> 2) & 1]) / n;
                D = jac(o, ci, t, N, dN, p, Ji);
                /* physical gradients: dN/dx_i = sum_d dN/dt_d * dt_d/dx_i */
                for (k = 0; k < 8; k++)
                    for (a = 0; a < 3; a++) G[k][a] = dN[k][0] * Ji[0][a] + dN[k][1] * Ji[1][a] + dN[k][2] * Ji[2][a];
                w = D / (8.0 * n * n * n);          /* Gauss weight 1/8 per sub-box of volume 1/n^3 */
                f = bits[q] ? 1.0 : d->air;
                if (bits[q]) o->inside_volume += w;
                if (f == 0) continue;
                for (r = 0; r < d->nmr; r++) if (sb_region_has(o, &d->mrules[r].r, p)) mat = d->mrules[r].mat;
                {
                    double E = d->mats[mat].E, nu = d->mats[mat].nu;
                    lam = E * nu / ((1 + nu) * (1 - 2 * nu));
                    mu = E / (2 * (1 + nu));
                    rho = d->mats[mat].rho;
                }
                if (o->nseg > 0 && d->kappa > 0) {
                    sb_nearest_seg(o, p, &sd);
                    if (sd <= d->twist_r) tw = d->kappa;   /* seed 000 eq. 25-26 */
                }
                w *= f;
                for (a = 0; a < 8; a++)
                    for (b = 0; b < 8; b++) {
                        double nn = N[a] * N[b] * w, gg = G[a][0] * G[b][0] + G[a][1] * G[b][1] + G[a][2] * G[b][2];
                        int i, j;
                        Me[a][b] += rho * nn;
                        Te[a][b] += tw * nn;
                        /* S_ab[i][j] = lam dNa/dxi dNb/dxj + mu dNa/dxj dNb/dxi + mu delta_ij gradNa.gradNb */
                        for (i = 0; i < 3; i++)
                            for (j = 0; j < 3; j++)
                                Se[a][b][3 * i + j] += w * (lam * G[a][i] * G[b][j] + mu * G[a][j] * G[b][i] + (i == j ? mu * gg : 0.0));
                    }
                if (inc) {
                    /* bubble P_k = 4 t_k (1 - t_k) (= 1 - xi_k^2), one per component c (mode 3k+c);
                     * gradient 4 (1 - 2 t_k) dt_k/dx at the centre, times det J0 / det J so that
                     * its integral vanishes on any hex (constant-strain patch test) */
                    int kk, c, cc, i;
                    for (kk = 0; kk < 3; kk++)
                        for (c = 0; c < 3; c++) Ga[kk][c] = 4.0 * (1.0 - 2.0 * t[kk]) * J0i[kk][c] * (D0 / D);
                    for (kk = 0; kk < 3; kk++)
                        for (c = 0; c < 3; c++) {
                            for (k = 0; k < 3; k++)
                                for (cc = 0; cc < 3; cc++) Kaa[3 * kk + c][3 * k + cc] += w * ss(Ga[kk], c, Ga[k], cc, lam, mu);
                            for (a = 0; a < 8; a++)
                                for (i = 0; i < 3; i++) Kua[3 * a + i][3 * kk + c] += w * ss(G[a], i, Ga[kk], c, lam, mu);
                        }
                }
            }
        if (inc && !(D0 > 0 && condense(Se, Kaa, Kua) == 0)) nskip++;   /* keep the trilinear element */
        for (a = 0; a < 8; a++)
            for (b = 0; b < 8; b++) {
                int e = sb_pattern_find(o, o->cells[8 * ci + a], o->cells[8 * ci + b]);
                o->M[e] += Me[a][b];
                o->T[e] += Te[a][b];
                for (k = 0; k < 9; k++) o->S[9 * (size_t)e + (size_t)k] += Se[a][b][k];
                o->mass += Me[a][b];
            }
        if (!o->quiet && sb_now() - t0 > 1.0 && (ci & 15) == 0)
            fprintf(stderr, "\rsinew-bake: integrating %3d%%", (int)(100.0 * ci / o->nc));
    }
    o->n_uncondensed = nskip;
    if (nskip && !o->quiet)
        fprintf(stderr, "\rsinew-bake: %d cell(s) with almost no interior weight keep the trilinear element\n", nskip);
    return 0;
}
