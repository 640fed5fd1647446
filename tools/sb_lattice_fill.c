/* sb_lattice_fill.c -- how much of each grid cell is inside the mesh: the
 * inside fractions of the quadrature boxes by +x rays (also the rigs'
 * integration, sb_rig.c) and the build's step 3 (which cells are kept). */
#include "sb.h"
#include "sb_lattice_int.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void progress(const sb_model *o, double t0, const char *what, int done, int total)
{
    if (!o->quiet && sb_now() - t0 > 1.0 && total > 0)
        fprintf(stderr, "\rsinew-bake: %s %3d%%", what, (int)(100.0 * done / total));
}

/* Inside fractions of the quadrature boxes (2n per cell edge) of every grid
 * cell with slot[gc] >= 0: frac[slot * 8n^3 + q] += the inside length of
 * mm x mm +x rays per box / box edge (mean over the rays; not clamped: round-off
 * can pass 1). Rays are cast once per grid row for every slotted cell in it.
 * Used by the lattice build (step 3) and the rig integration (sb_rig.c).
 * t0 >= 0: progress lines as the lattice build prints them. */
void sb_box_fractions(const sb_model *o, const sb_mesh *m, const sb_inside *in, int n, const int *slot, double *frac, double t0)
{
    int nx = o->gn[0] - 1, ny = o->gn[1] - 1, nz = o->gn[2] - 1, npt = n * n * n * 8, cap = 256, cy, cz, k, mm, a;
    double *xs = sb_alloc(sizeof(double) * (size_t)cap), hb = o->c / (2 * n), ext = 0, inv;
    unsigned char *rowsurf = sb_alloc((size_t)(ny * nz));
    for (a = 0; a < nx * ny * nz; a++) if (slot[a] >= 0) rowsurf[a / nx] = 1;
    for (k = 0; k < 3; k++) ext = fmax(ext, m->hi[k] - m->lo[k]);
    mm = (int)ceil(hb / (ext / 2000));
    mm = mm < 1 ? 1 : mm > 64 ? 64 : mm;
    inv = 1.0 / ((double)mm * mm * hb);
    for (cz = 0; cz < nz; cz++) {
        for (cy = 0; cy < ny; cy++) {
            const double *c0 = o->gpos + 3 * gidx(o, 0, cy, cz);
            int py, pz, u, v;
            if (!rowsurf[cy + ny * cz]) continue;
            for (pz = 0; pz < 2 * n; pz++) for (v = 0; v < mm; v++) for (py = 0; py < 2 * n; py++) for (u = 0; u < mm; u++) {
                double y = c0[1] + (py + (u + 0.5) / mm) * hb, z = c0[2] + (pz + (v + 0.5) / mm) * hb;
                int nxs = sb_inside_ray(in, y, z, xs, cap), e;
                if (nxs > cap) { cap = nxs; free(xs); xs = sb_alloc(sizeof(double) * (size_t)cap); sb_inside_ray(in, y, z, xs, cap); }
                for (e = 1; e < nxs; e++) {   /* sort the crossings (few) */
                    double xv = xs[e];
                    int f = e;
                    for (; f > 0 && xs[f - 1] > xv; f--) xs[f] = xs[f - 1];
                    xs[f] = xv;
                }
                /* inside = an odd number of crossings beyond x, within the mesh's x range */
                for (e = nxs - 1; e >= 1; e -= 2) {
                    double xa = xs[e - 1] > m->lo[0] ? xs[e - 1] : m->lo[0], xb = xs[e] < m->hi[0] ? xs[e] : m->hi[0];
                    int px, p0, p1, nb = 2 * n;
                    if (!(xb > xa)) continue;
                    p0 = (int)floor((xa - c0[0]) / hb); p1 = (int)floor((xb - c0[0]) / hb);
                    p0 = p0 < 0 ? 0 : p0; p1 = p1 > nb * nx - 1 ? nb * nx - 1 : p1;
                    for (px = p0; px <= p1; px++) {
                        int i = px / nb, bx = px % nb, gc = i + nx * (cy + ny * cz), qq;
                        double b0, b1, len;
                        if (slot[gc] < 0) { px = (i + 1) * nb - 1; continue; }   /* no slot: skip the cell */
                        b0 = o->gpos[3 * gidx(o, i, cy, cz)] + bx * hb; b1 = b0 + hb;
                        len = (xb < b1 ? xb : b1) - (xa > b0 ? xa : b0);
                        if (len <= 0) continue;
                        qq = (((pz >> 1) * n + (py >> 1)) * n + (bx >> 1)) * 8 + (bx & 1) + 2 * (py & 1) + 4 * (pz & 1);
                        frac[(size_t)slot[gc] * (size_t)npt + (size_t)qq] += len * inv;
                    }
                }
            }
        }
        if (t0 >= 0) progress(o, t0, "inside test", cz, nz);
    }
    free(xs); free(rowsurf);
}

/* step 3 of sb_build (keep, fidx: ngc entries each, the caller's; *fracp: the
 * caller frees it) */
int sb_lattice_fill(const sb_desc *d, const sb_mesh *m, sb_model *o, const sb_inside *in, int *keep, int *fidx,
                    double **fracp, double t0)
{
    int a, k, q, ngc = (o->gn[0] - 1) * (o->gn[1] - 1) * (o->gn[2] - 1), n = d->subdiv, npt = n * n * n * 8;
    double c = o->c, *frac;
    /* 3. inside fraction of every quadrature point's box (the octant of its sub-box,
     * edge hb = c / 2n). Cells no triangle's bounding box touches are wholly inside or
     * outside (one point test). In the others, +x rays on a grid of lines at most
     * (bbox extent)/2000 apart give the inside length along x exactly; a point's
     * fraction = mean inside length / hb over the lines through its box. */
    o->cell_fill = sb_alloc(sizeof(double) * (size_t)ngc);
    {
        int nx = o->gn[0] - 1, ny = o->gn[1] - 1, nsurf = 0, t;
        for (a = 0; a < ngc; a++) fidx[a] = -3;
        for (t = 0; t < m->nt; t++) {   /* surface cells: inside a triangle's bounding box */
            int lo3[3], hi3[3], x, y, z;
            for (k = 0; k < 3; k++) {
                const double *v0 = m->v + 3 * m->tri[3 * t], *v1 = m->v + 3 * m->tri[3 * t + 1], *v2 = m->v + 3 * m->tri[3 * t + 2];
                double l = fmin(v0[k], fmin(v1[k], v2[k])), h = fmax(v0[k], fmax(v1[k], v2[k]));
                lo3[k] = (int)floor((l - o->gorg[k]) / c - 1e-9); hi3[k] = (int)floor((h - o->gorg[k]) / c + 1e-9);
                lo3[k] = lo3[k] < 0 ? 0 : lo3[k]; hi3[k] = hi3[k] > o->gn[k] - 2 ? o->gn[k] - 2 : hi3[k];
            }
            for (z = lo3[2]; z <= hi3[2]; z++) for (y = lo3[1]; y <= hi3[1]; y++) for (x = lo3[0]; x <= hi3[0]; x++)
                fidx[x + nx * (y + ny * z)] = -4;
        }
        for (a = 0; a < ngc; a++) {
            if (fidx[a] == -4) fidx[a] = nsurf++;
            else {
                int g[8];
                double p[3];
                cell_corners(o, a, g);
                for (k = 0; k < 3; k++) p[k] = o->gpos[3 * g[0] + k] + 0.5 * c;
                fidx[a] = sb_inside_test(in, p) ? -2 : -1;
            }
        }
        for (a = 0, q = 0; a < ngc; a++) q += fidx[a] == -2;
        if (q + nsurf / 4 > 65535) {   /* more kept cells than a 65535-vertex lattice can have: stop before the costly part */
            sb_fail("%s: cell size %g is too small for this mesh (%d cells inside, %d on the surface; a lattice holds at most 65535 vertices): "
                    "use a cell of about %.3g or more", d->path, c, q, nsurf, c * pow((q + nsurf / 4) / 50000.0, 1.0 / 3.0));
            return -1;
        }
        frac = *fracp = sb_alloc(sizeof(double) * (size_t)npt * (size_t)(nsurf ? nsurf : 1));
        sb_box_fractions(o, m, in, n, fidx, frac, t0);
        for (a = 0; a < ngc; a++) {
            double sum = 0;
            if (fidx[a] >= 0) {
                double *f = frac + (size_t)fidx[a] * (size_t)npt;
                for (q = 0; q < npt; q++) { f[q] = f[q] > 1 ? 1 : f[q]; sum += f[q]; }   /* round-off */
            } else sum = fidx[a] == -2 ? npt : 0;
            o->cell_fill[a] = sum / npt;   /* cubes: equal weights */
            keep[a] = sum >= 1.0 && o->cell_fill[a] >= d->min_fill;   /* at least one quadrature point's worth inside */
        }
    }
    return 0;
}
