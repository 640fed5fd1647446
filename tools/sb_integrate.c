/* sb_integrate.c -- mass, elastic stiffness and twist integrals over the
 * interior only (seed 000 §3.3; DESIGN.md "The model"). Each cell is an
 * isoparametric trilinear hex; in reference coordinates it is split into
 * subdiv^3 sub-boxes with 2x2x2 Gauss points each, and points outside the mesh
 * are weighted by `air` (default 1e-3, so no kept vertex has zero mass). */
#include "sb.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

int sb_integrate(const sb_desc *d, sb_model *o, const unsigned char *inbits)
{
    static const double gp2[2] = {0.21132486540518711775, 0.78867513459481288225};
    int n = d->subdiv, npt = n * n * n * 8, ci, a, b, k, q, r;
    double u = d->unit, t0 = sb_now();
    o->inside_volume = 0; o->mass = 0;
    for (ci = 0; ci < o->nc; ci++) {
        double Me[8][8], Te[8][8], Se[8][8][9];
        int sx, sy, sz, gp;
        const unsigned char *bits = inbits + (size_t)o->cell_grid[ci] * (size_t)npt;
        memset(Me, 0, sizeof Me); memset(Te, 0, sizeof Te); memset(Se, 0, sizeof Se);
        q = 0;
        for (sz = 0; sz < n; sz++) for (sy = 0; sy < n; sy++) for (sx = 0; sx < n; sx++)
            for (gp = 0; gp < 8; gp++, q++) {
                double t[3], N[8], dN[8][3], p[3] = {0, 0, 0}, J[3][3], Ji[3][3], D, w, G[8][3], lam, mu, rho, f, tw = 0, sd;
                int mat = 0;
                t[0] = (sx + gp2[gp & 1]) / n; t[1] = (sy + gp2[(gp >> 1) & 1]) / n; t[2] = (sz + gp2[(gp >> 2) & 1]) / n;
                sb_shape(t, N, dN);
                memset(J, 0, sizeof J);
                for (k = 0; k < 8; k++) {
                    const double *x = o->x + 3 * o->cells[8 * ci + k];
                    for (a = 0; a < 3; a++) {
                        p[a] += N[k] * x[a];
                        for (b = 0; b < 3; b++) J[a][b] += x[a] * u * dN[k][b];   /* metres */
                    }
                }
                D = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) - J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                    J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
                /* inverse Jacobian (adjugate / det) */
                Ji[0][0] = (J[1][1] * J[2][2] - J[1][2] * J[2][1]) / D; Ji[0][1] = (J[0][2] * J[2][1] - J[0][1] * J[2][2]) / D;
                Ji[0][2] = (J[0][1] * J[1][2] - J[0][2] * J[1][1]) / D; Ji[1][0] = (J[1][2] * J[2][0] - J[1][0] * J[2][2]) / D;
                Ji[1][1] = (J[0][0] * J[2][2] - J[0][2] * J[2][0]) / D; Ji[1][2] = (J[0][2] * J[1][0] - J[0][0] * J[1][2]) / D;
                Ji[2][0] = (J[1][0] * J[2][1] - J[1][1] * J[2][0]) / D; Ji[2][1] = (J[0][1] * J[2][0] - J[0][0] * J[2][1]) / D;
                Ji[2][2] = (J[0][0] * J[1][1] - J[0][1] * J[1][0]) / D;
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
            }
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
    return 0;
}
