/* sb_lattice.c -- automatic control lattice (seed 000 §3.1) with volumetric
 * bones: an undistorted grid of cubes covering the mesh (grid vertices are
 * never moved, so no cell can fold); kept cells = those meeting the interior
 * (or holding a mesh vertex, a joint or a bone sample); skeleton vertices =
 * lattice vertices a bone captures (its rasterized chain and every vertex
 * within its radius; the nearest segment wins); frames (seed 003 §3.3) at
 * vertices and cell centres; surface embedding; model checks. */
#include "sb.h"
#include "sb_gltf.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void sb_shape(const double t[3], double N[8], double dN[8][3])
{
    int k, a;
    for (k = 0; k < 8; k++) {
        double f[3], df[3];
        for (a = 0; a < 3; a++) {
            int bit = (k >> a) & 1;
            f[a] = bit ? t[a] : 1.0 - t[a];
            df[a] = bit ? 1.0 : -1.0;
        }
        N[k] = f[0] * f[1] * f[2];
        if (dN) {
            dN[k][0] = df[0] * f[1] * f[2];
            dN[k][1] = f[0] * df[1] * f[2];
            dN[k][2] = f[0] * f[1] * df[2];
        }
    }
}

static void corners_point(const double *const xc[8], const double t[3], double p[3], double J[3][3])
{
    double N[8], dN[8][3];
    int k, a, b;
    sb_shape(t, N, dN);
    for (a = 0; a < 3; a++) {
        p[a] = 0;
        for (b = 0; b < 3; b++) J[a][b] = 0;
    }
    for (k = 0; k < 8; k++)
        for (a = 0; a < 3; a++) {
            p[a] += N[k] * xc[k][a];
            for (b = 0; b < 3; b++) J[a][b] += xc[k][a] * dN[k][b];
        }
}

void sb_cell_point(const sb_model *o, int ci, const double t[3], double p[3])
{
    const double *xc[8];
    double J[3][3];
    int k;
    for (k = 0; k < 8; k++) xc[k] = o->x + 3 * o->cells[8 * ci + k];
    corners_point(xc, t, p, J);
}

static double det3(double J[3][3])
{
    return J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) - J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
           J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
}


/* distance from p to segment a-b */
static double seg_dist(const double p[3], const double a[3], const double b[3])
{
    double ab[3], ap[3], L2 = 0, s = 0, d2 = 0;
    int k;
    for (k = 0; k < 3; k++) { ab[k] = b[k] - a[k]; ap[k] = p[k] - a[k]; L2 += ab[k] * ab[k]; s += ab[k] * ap[k]; }
    s = L2 > 0 ? s / L2 : 0;
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    for (k = 0; k < 3; k++) { double e = ap[k] - s * ab[k]; d2 += e * e; }
    return sqrt(d2);
}

static int gidx(const sb_model *o, int i, int j, int k) { return i + o->gn[0] * (j + o->gn[1] * k); }

/* corner grid vertices of grid cell (i,j,k) */
static void cell_corners(const sb_model *o, int gc, int g[8])
{
    int nx = o->gn[0] - 1, ny = o->gn[1] - 1;
    int i = gc % nx, j = (gc / nx) % ny, k = gc / (nx * ny), c;
    for (c = 0; c < 8; c++) g[c] = gidx(o, i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
}

/* Segment distances for region/frame rules: nearest segment index, or -1. */
int sb_nearest_seg(const sb_model *o, const double p[3], double *dist)
{
    int s, best = -1;
    double bd = HUGE_VAL;
    for (s = 0; s < o->nseg; s++) {
        int c = o->seg_child[s];
        double dd = seg_dist(p, o->joints[o->joints[c].parent].pos, o->joints[c].pos);
        if (dd < bd) { bd = dd; best = s; }
    }
    if (dist) *dist = bd;
    return best;
}

/* does region r (joint indices in sorted order) contain p? */
int sb_region_has(const sb_model *o, const sb_region *r, const double p[3])
{
    int k;
    double d2 = 0;
    switch (r->kind) {
    case SB_RG_ALL: return 1;
    case SB_RG_BOX:
        for (k = 0; k < 3; k++) if (p[k] < r->a[k] || p[k] > r->a[k + 3]) return 0;
        return 1;
    case SB_RG_SPHERE:
        for (k = 0; k < 3; k++) d2 += (p[k] - r->a[k]) * (p[k] - r->a[k]);
        return d2 <= r->a[3] * r->a[3];
    case SB_RG_BONE: {
        int s = sb_nearest_seg(o, p, NULL);
        return s >= 0 && o->seg_child[s] == o->desc_to_sorted[r->bone];
    }
    }
    return 0;
}

int sb_pattern_find(const sb_model *o, int i, int j)
{
    int lo = o->nbptr[i], hi = o->nbptr[i + 1] - 1;
    while (lo <= hi) {
        int mid = (lo + hi) / 2;
        if (o->nb[mid] == j) return mid;
        if (o->nb[mid] < j) lo = mid + 1; else hi = mid - 1;
    }
    return -1;
}

static void progress(const sb_model *o, double t0, const char *what, int done, int total)
{
    if (!o->quiet && sb_now() - t0 > 1.0 && total > 0)
        fprintf(stderr, "\rsinew-bake: %s %3d%%", what, (int)(100.0 * done / total));
}


/* grid cell (clamped) containing p, and the grid vertex nearest p */
static int cell_of(const sb_model *o, const double p[3])
{
    int k, gi[3];
    for (k = 0; k < 3; k++) {
        gi[k] = (int)floor((p[k] - o->gorg[k]) / o->c);
        gi[k] = gi[k] < 0 ? 0 : gi[k] > o->gn[k] - 2 ? o->gn[k] - 2 : gi[k];
    }
    return gi[0] + (o->gn[0] - 1) * (gi[1] + (o->gn[1] - 1) * gi[2]);
}
static int vertex_near(const sb_model *o, const double p[3])
{
    int k, gi[3];
    for (k = 0; k < 3; k++) {
        gi[k] = (int)floor((p[k] - o->gorg[k]) / o->c + 0.5);
        gi[k] = gi[k] < 0 ? 0 : gi[k] > o->gn[k] - 1 ? o->gn[k] - 1 : gi[k];
    }
    return gidx(o, gi[0], gi[1], gi[2]);
}

static const double *seg_p(const sb_model *o, int a) { return o->joints[o->joints[o->seg_child[a]].parent].pos; }
static const double *seg_c(const sb_model *o, int a) { return o->joints[o->seg_child[a]].pos; }

/* samples along segment a every cell/8 or finer, ends included */
static int seg_samples(const sb_model *o, int a)
{
    double L = 0;
    int k;
    for (k = 0; k < 3; k++) L += (seg_c(o, a)[k] - seg_p(o, a)[k]) * (seg_c(o, a)[k] - seg_p(o, a)[k]);
    L = sqrt(L);
    return (int)ceil(L / (o->c / 8)) > 1 ? (int)ceil(L / (o->c / 8)) : 1;
}
static void seg_point(const sb_model *o, int a, double t, double p[3])
{
    int k;
    for (k = 0; k < 3; k++) p[k] = seg_p(o, a)[k] + t * (seg_c(o, a)[k] - seg_p(o, a)[k]);
}

/* Frame at rest point p (seed 003 §3.3): bone1/bone2 = the two nearest joints that
 * move a bone (distance to the nearest of their child segments), w = 1/2 where they
 * are equally near, falling smoothly (smoothstep) to 0 when bone2 is B farther
 * (continuous where the nearest bone changes); 'frame' rules override. */
static void frame_at(const sb_desc *d, const sb_model *o, const double p[3], double B, double *jd, int *fb1, int *fb2, double *fw)
{
    int j, a, b1 = 0, b2 = 0;
    double d1 = HUGE_VAL, d2 = HUGE_VAL, w = 0;
    for (j = 0; j < o->nj; j++) jd[j] = HUGE_VAL;
    for (a = 0; a < o->nseg; a++) {
        int pa = o->joints[o->seg_child[a]].parent;
        double dd = seg_dist(p, seg_p(o, a), seg_c(o, a));
        if (dd < jd[pa]) jd[pa] = dd;
    }
    for (j = 0; j < o->nj; j++) {
        if (jd[j] < d1) { d2 = d1; b2 = b1; d1 = jd[j]; b1 = j; }
        else if (jd[j] < d2) { d2 = jd[j]; b2 = j; }
    }
    if (d2 < HUGE_VAL) {
        double s = 1.0 - (d2 - d1) / B;
        s = s < 0 ? 0 : s > 1 ? 1 : s;
        w = 0.5 * s * s * (3 - 2 * s);
    } else b2 = b1;
    if (w == 0) b2 = b1;
    for (a = 0; a < d->nfr; a++)
        if (sb_region_has(o, &d->frules[a].r, p)) {
            b1 = o->desc_to_sorted[d->frules[a].j1]; b2 = o->desc_to_sorted[d->frules[a].j2]; w = d->frules[a].w;
        }
    *fb1 = b1; *fb2 = b2; *fw = w;
}

static int frame_ruled(const sb_desc *d, const sb_model *o, const double p[3])
{
    int a;
    for (a = 0; a < d->nfr; a++) if (sb_region_has(o, &d->frules[a].r, p)) return 1;
    return 0;
}

/* 'frames skin' (issue 17): the frame at p from the artist's skin weights of
 * the glTF vertices within one cell of p (weighted (1 - r/c)^2), or of the
 * nearest glTF vertex when none is that close: bone1/bone2 = the two joints
 * with the largest summed weight, w = a2 / (a1 + a2). glTF joint k is
 * description joint k (sb_desc_gltf). 'frame' rules still override. */
static void skin_frame(const sb_desc *d, const sb_model *o, const double p[3], double *acc, int *fb1, int *fb2, double *fw)
{
    const sb_gltf *g = d->gltf;
    double R = o->c, best = HUGE_VAL, a1 = 0, a2 = 0;
    int v, k, j, nearest = 0, any = 0, b1 = 0, b2 = 0;
    for (j = 0; j < g->nj; j++) acc[j] = 0;
    for (v = 0; v < g->nv; v++) {
        const double *q = g->pos + 3 * v;
        double dd = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) + (q[2] - p[2]) * (q[2] - p[2]), r, f;
        if (dd < best) best = dd, nearest = v;
        if (dd >= R * R) continue;
        r = sqrt(dd) / R, f = (1 - r) * (1 - r);
        for (k = 0; k < 4; k++) acc[g->joint[4 * v + k]] += f * g->weight[4 * v + k];
        any = 1;
    }
    if (!any)
        for (k = 0; k < 4; k++) acc[g->joint[4 * nearest + k]] += g->weight[4 * nearest + k];
    for (j = 0; j < g->nj; j++) {
        if (acc[j] > a1) { a2 = a1; b2 = b1; a1 = acc[j]; b1 = j; }
        else if (acc[j] > a2) { a2 = acc[j]; b2 = j; }
    }
    *fb1 = o->desc_to_sorted[b1];
    *fb2 = a2 > 0 ? o->desc_to_sorted[b2] : *fb1;
    *fw = a2 > 0 ? a2 / (a1 + a2) : 0;
}

/* The frame rule of sb_build step 10 at any rest point p (tools/sb_level.h, the
 * hierarchical study's per-child frames): frame_at, or the skin's when 'frames skin'. */
void sb_frame_point(const sb_desc *d, const sb_model *o, const double p[3], int *fb1, int *fb2, double *fw)
{
    double B = d->blend > 0 ? d->blend : d->cell, *jd = sb_alloc(sizeof(double) * (size_t)(o->nj > 1 ? o->nj : 1));
    frame_at(d, o, p, B, jd, fb1, fb2, fw);
    if (d->skin_frames && !frame_ruled(d, o, p)) skin_frame(d, o, p, jd, fb1, fb2, fw);
    free(jd);
}

/* Flesh thickness of bone a: distance from the segment to the mesh surface, the
 * smallest over 9 samples of its middle half (0 where the segment leaves the mesh). */
static double flesh_thickness(const sb_model *o, const sb_mesh *m, const sb_inside *in, int a)
{
    double best = HUGE_VAL, p[3], q[3];
    int s;
    for (s = 0; s <= 8; s++) {
        seg_point(o, a, 0.25 + 0.5 * s / 8.0, p);
        if (!sb_inside_test(in, p)) return 0;
        best = fmin(best, sb_mesh_closest(m, p, q));
    }
    return best;
}

/* every joint outside the mesh, each with its nearest surface point and a point just inside */
static int joints_outside(const sb_desc *d, const sb_model *o, const sb_mesh *m, const sb_inside *in)
{
    char msg[16384];
    size_t len = 0;
    int k, nout = 0, pass;
    for (k = 0; k < o->nj; k++) if (!sb_inside_test(in, o->joints[k].pos)) nout++;
    if (!nout) return 0;
    for (pass = 0; pass < 3; pass++) {   /* shorter entries if the message would not fit */
        len = (size_t)snprintf(msg, sizeof msg, "%d joint(s) outside the mesh (every joint must lie inside):", nout);
        for (k = 0; k < o->nj && len < sizeof msg; k++) {
            const sb_joint *J = &o->joints[k];
            double s[3], tryp[3], dist, step;
            int e, found = 0;
            if (sb_inside_test(in, J->pos)) continue;
            if (pass == 2) { len += (size_t)snprintf(msg + len, sizeof msg - len, " '%s'", J->name); continue; }
            dist = sb_mesh_closest(m, J->pos, s);
            /* just past the nearest surface point, away from the joint */
            for (step = 0.25 * o->c; step > 1e-6 * o->c && !found; step *= 0.5) {
                for (e = 0; e < 3; e++) tryp[e] = s[e] + (dist > 0 ? (s[e] - J->pos[e]) / dist * step : 0);
                found = sb_inside_test(in, tryp);
            }
            if (pass == 0 && found)
                len += (size_t)snprintf(msg + len, sizeof msg - len, "\n  %s:%d: joint '%s' at (%g, %g, %g) is %.3g outside; nearest surface point (%.4g, %.4g, %.4g): move it inside, e.g. to (%.4g, %.4g, %.4g)",
                                        d->path, J->line, J->name, J->pos[0], J->pos[1], J->pos[2], dist, s[0], s[1], s[2], tryp[0], tryp[1], tryp[2]);
            else if (pass == 0)
                len += (size_t)snprintf(msg + len, sizeof msg - len, "\n  %s:%d: joint '%s' at (%g, %g, %g) is %.3g outside; nearest surface point (%.4g, %.4g, %.4g): move it inside, past that point",
                                        d->path, J->line, J->name, J->pos[0], J->pos[1], J->pos[2], dist, s[0], s[1], s[2]);
            else
                len += (size_t)snprintf(msg + len, sizeof msg - len, " '%s' (%.4g,%.4g,%.4g)->inside past (%.4g,%.4g,%.4g);", J->name, J->pos[0], J->pos[1], J->pos[2], s[0], s[1], s[2]);
        }
        if (len < 2000) break;   /* sb_fail keeps 2047 characters */
    }
    if (nout == o->nj)
        snprintf(msg + (len < sizeof msg ? len : sizeof msg - 1), sizeof msg - (len < sizeof msg ? len : sizeof msg - 1),
                 "\n  (no joint is inside: check that the skeleton and the mesh use the same units and axes)");
    return sb_fail("%s", msg);
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

int sb_build(const sb_desc *d, const sb_mesh *m, sb_model *o, int quiet)
{
    sb_inside in;
    int i, j, k, a, nj = d->nj, ngv, ngc, n = d->subdiv, npt = n * n * n * 8;
    int *keep = NULL, *order, *bestseg = NULL, *mark = NULL, *cellno = NULL, *fidx = NULL, q;
    unsigned char *used = NULL;
    double *frac = NULL, c = d->cell, t0 = sb_now(), *bestd = NULL, *jd = NULL, B = d->blend > 0 ? d->blend : d->cell;
    int rc = -1;

    memset(o, 0, sizeof *o);
    o->quiet = quiet;
    o->unit = d->unit; o->h = d->h; o->alpha = d->alpha; o->beta = d->beta; o->cg_def = d->cg_def; o->cg_max = d->cg_max; o->precond = d->precond;
    o->rest_modelled = d->rest_modelled;
    o->mesh_volume = sb_mesh_volume(m) * d->unit * d->unit * d->unit;
    for (k = 0; k < 3; k++) o->g[k] = d->g[k];
    {
        double dd = 0;
        for (k = 0; k < 3; k++) dd += (m->hi[k] - m->lo[k]) * (m->hi[k] - m->lo[k]);
        o->bbox_diag = sqrt(dd);
    }
    sb_inside_init(&in, m);

    /* 1. joints sorted so parents precede children (stable in description order) */
    o->nj = nj;
    o->joints = sb_alloc(sizeof(sb_joint) * (size_t)nj);
    o->desc_to_sorted = sb_alloc(sizeof(int) * (size_t)nj);
    order = sb_alloc(sizeof(int) * (size_t)nj);
    for (i = 0; i < nj; i++) o->desc_to_sorted[i] = -1;
    for (k = 0; k < nj;) {
        for (i = 0; i < nj; i++)
            if (o->desc_to_sorted[i] < 0 && (d->joints[i].parent < 0 || o->desc_to_sorted[d->joints[i].parent] >= 0)) {
                o->desc_to_sorted[i] = k; order[k++] = i;
            }
    }
    for (k = 0; k < nj; k++) {
        o->joints[k] = d->joints[order[k]];
        o->joints[k].parent = d->joints[order[k]].parent < 0 ? -1 : o->desc_to_sorted[d->joints[order[k]].parent];
    }
    free(order);
    o->c = c;
    if (joints_outside(d, o, m, &in)) goto done;
    o->seg_child = sb_alloc(sizeof(int) * (size_t)nj);
    for (k = 1; k < nj; k++) o->seg_child[o->nseg++] = k;   /* segment a ends at sorted joint a + 1 */

    /* 2. grid: cubes of edge c aligned to the origin (default: the root joint), one cell of margin */
    {
        double org[3];
        for (k = 0; k < 3; k++) {
            double lo, hi;
            org[k] = d->has_origin ? d->origin[k] : o->joints[0].pos[k];
            lo = floor((m->lo[k] - org[k]) / c) - 1;
            hi = ceil((m->hi[k] - org[k]) / c) + 1;
            /* in double first: a tiny cell or a far origin must not overflow an int */
            if (!(hi - lo + 1 <= 4e6) || !(fabs(lo) <= 1e9) || !(fabs(hi) <= 1e9)) {
                sb_fail("%s: cell size %g (grid origin %g mesh units away on axis %d) gives a grid of %.3g vertices along one axis: "
                        "use a larger cell or an origin near the mesh", d->path, c, fabs(org[k] - m->lo[k]), k, hi - lo + 1);
                goto done;
            }
            o->gorg[k] = org[k] + lo * c;
            o->gn[k] = (int)(hi - lo) + 1;
        }
    }
    if ((double)o->gn[0] * o->gn[1] * o->gn[2] > 4e6) { sb_fail("%s: cell size %g is too small for this mesh (grid over 4 million vertices)", d->path, c); goto done; }
    ngv = o->gn[0] * o->gn[1] * o->gn[2];
    ngc = (o->gn[0] - 1) * (o->gn[1] - 1) * (o->gn[2] - 1);
    o->gpos = sb_alloc(sizeof(double) * 3 * (size_t)ngv);
    o->gjoint = sb_alloc(sizeof(int) * (size_t)ngv);
    o->gvert = sb_alloc(sizeof(int) * (size_t)ngv);
    for (k = 0; k < o->gn[2]; k++)
        for (j = 0; j < o->gn[1]; j++)
            for (i = 0; i < o->gn[0]; i++) {
                int g = gidx(o, i, j, k);
                o->gpos[3 * g] = o->gorg[0] + i * c;
                o->gpos[3 * g + 1] = o->gorg[1] + j * c;
                o->gpos[3 * g + 2] = o->gorg[2] + k * c;
                o->gjoint[g] = -1; o->gvert[g] = -1;
            }

    /* 3. inside fraction of every quadrature point's box (the octant of its sub-box,
     * edge hb = c / 2n). Cells no triangle's bounding box touches are wholly inside or
     * outside (one point test). In the others, +x rays on a grid of lines at most
     * (bbox extent)/2000 apart give the inside length along x exactly; a point's
     * fraction = mean inside length / hb over the lines through its box. */
    o->cell_fill = sb_alloc(sizeof(double) * (size_t)ngc);
    keep = sb_alloc(sizeof(int) * (size_t)ngc);
    fidx = sb_alloc(sizeof(int) * (size_t)ngc);
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
                fidx[a] = sb_inside_test(&in, p) ? -2 : -1;
            }
        }
        for (a = 0, q = 0; a < ngc; a++) q += fidx[a] == -2;
        if (q + nsurf / 4 > 65535) {   /* more kept cells than a 65535-vertex lattice can have: stop before the costly part */
            sb_fail("%s: cell size %g is too small for this mesh (%d cells inside, %d on the surface; a lattice holds at most 65535 vertices): "
                    "use a cell of about %.3g or more", d->path, c, q, nsurf, c * pow((q + nsurf / 4) / 50000.0, 1.0 / 3.0));
            goto done;
        }
        frac = sb_alloc(sizeof(double) * (size_t)npt * (size_t)(nsurf ? nsurf : 1));
        sb_box_fractions(o, m, &in, n, fidx, frac, t0);
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

    /* 4. cells a bone needs: those holding a joint or a bone sample inside the mesh */
    for (a = 0; a < o->nseg; a++) {
        int s, ns = seg_samples(o, a);
        for (s = 0; s <= ns; s++) {
            double p[3];
            seg_point(o, a, (double)s / ns, p);
            if (s == 0 || s == ns || sb_inside_test(&in, p)) keep[cell_of(o, p)] = 1;
        }
    }

    /* 5. surface embedding: each mesh vertex in its grid cell (t = offset / c), preferring a
     * kept neighbour when the vertex lies on a cell face; that cell is kept */
    o->ns = m->nv;
    o->emb_cell = sb_alloc(sizeof(int) * (size_t)m->nv);
    o->emb_t = sb_alloc(sizeof(double) * 3 * (size_t)m->nv);
    for (i = 0; i < m->nv; i++) {
        const double *q = m->v + 3 * i;
        int gc = cell_of(o, q), nx = o->gn[0] - 1, ny = o->gn[1] - 1, g0[3], best = -1, alt;
        double t0c[3], tb[3];
        g0[0] = gc % nx; g0[1] = gc / nx % ny; g0[2] = gc / (nx * ny);
        for (k = 0; k < 3; k++) t0c[k] = (q[k] - o->gpos[3 * gidx(o, g0[0], g0[1], g0[2]) + k]) / c;
        for (alt = 0; alt < 8 && best < 0; alt++) {   /* alt bit k: the neighbour across face k the vertex lies on */
            int gi[3] = {g0[0], g0[1], g0[2]}, ok = 1, cc;
            double t[3];
            for (k = 0; k < 3; k++) {
                t[k] = t0c[k];
                if (alt >> k & 1) {
                    if (t0c[k] < 1e-12 && gi[k] > 0) { gi[k]--; t[k] = 1; }
                    else if (t0c[k] > 1 - 1e-12 && gi[k] < o->gn[k] - 2) { gi[k]++; t[k] = 0; }
                    else ok = 0;
                }
                t[k] = t[k] < 0 ? 0 : t[k] > 1 ? 1 : t[k];
            }
            if (!ok) continue;
            if (alt == 0) memcpy(tb, t, sizeof t);
            cc = gi[0] + nx * (gi[1] + ny * gi[2]);
            if (keep[cc]) { best = cc; memcpy(tb, t, sizeof t); }
        }
        if (best < 0) best = gc;   /* no kept candidate: keep its own cell (tb holds its coordinates) */
        keep[best] = 1;
        o->emb_cell[i] = best;   /* grid cell for now; renumbered below */
        memcpy(o->emb_t + 3 * i, tb, sizeof tb);
    }

    /* 6. lattice vertices = corners of kept cells */
    used = sb_alloc((size_t)ngv);
    for (a = 0; a < ngc; a++)
        if (keep[a]) { int g[8]; cell_corners(o, a, g); for (k = 0; k < 8; k++) used[g[k]] = 1; }

    /* 7. bones: radius (given, or automatic = half the flesh thickness, at most a quarter of
     * the bone's length), then capture (a) the rasterized chain: the grid vertex nearest each
     * sample, (b) every lattice vertex within the radius. Several claims: the nearest segment
     * wins (ties: the lower sorted joint index, i.e. the bone processed first). */
    o->seg_r = sb_alloc(sizeof(double) * (size_t)(o->nseg + 1));
    o->seg_flesh = sb_alloc(sizeof(double) * (size_t)(o->nseg + 1));
    o->seg_auto = sb_alloc(sizeof(int) * (size_t)(o->nseg + 1));
    o->seg_nv = sb_alloc(sizeof(int) * (size_t)(o->nseg + 1));
    o->seg_ncap = sb_alloc(sizeof(int) * (size_t)(o->nseg + 1));
    bestd = sb_alloc(sizeof(double) * (size_t)ngv);
    bestseg = sb_alloc(sizeof(int) * (size_t)ngv);
    mark = sb_alloc(sizeof(int) * (size_t)ngv);
    for (i = 0; i < ngv; i++) { bestd[i] = HUGE_VAL; bestseg[i] = -1; mark[i] = -1; }
    for (a = 0; a < o->nseg; a++) {
        const sb_joint *J = &o->joints[o->seg_child[a]];
        const double *P = seg_p(o, a), *C = seg_c(o, a);
        double r, L = 0, lo[3], hi[3];
        int s, ns = seg_samples(o, a), ilo[3], ihi[3], x, y, z;
        for (k = 0; k < 3; k++) L += (C[k] - P[k]) * (C[k] - P[k]);
        L = sqrt(L);
        o->seg_flesh[a] = flesh_thickness(o, m, &in, a);
        if (J->bone_r >= 0) r = J->bone_r;
        else if (d->bone_radius >= 0) r = d->bone_radius;
        else { r = fmax(fmin(0.5 * o->seg_flesh[a], 0.25 * L), 1.25 * c); o->seg_auto[a] = 1; }
        o->seg_r[a] = r;
        for (s = 0; s <= ns; s++) {
            double p[3], dd;
            int g;
            seg_point(o, a, (double)s / ns, p);
            g = vertex_near(o, p);
            if (!used[g]) continue;
            dd = seg_dist(o->gpos + 3 * g, P, C);
            if (mark[g] != a) { mark[g] = a; o->seg_ncap[a]++; }
            if (dd < bestd[g]) { bestd[g] = dd; bestseg[g] = a; }
        }
        for (k = 0; k < 3; k++) {
            lo[k] = fmin(P[k], C[k]) - r; hi[k] = fmax(P[k], C[k]) + r;
            /* clamped in double before the conversion: a huge radius must not overflow an int */
            ilo[k] = (int)fmax(0.0, fmin(o->gn[k], ceil((lo[k] - o->gorg[k]) / c - 1e-9)));
            ihi[k] = (int)fmin(o->gn[k] - 1, fmax(-1.0, floor((hi[k] - o->gorg[k]) / c + 1e-9)));
        }
        for (z = ilo[2]; z <= ihi[2]; z++) for (y = ilo[1]; y <= ihi[1]; y++) for (x = ilo[0]; x <= ihi[0]; x++) {
            int g = gidx(o, x, y, z);
            double dd;
            if (!used[g]) continue;
            dd = seg_dist(o->gpos + 3 * g, P, C);
            if (!(dd <= r + 1e-9 * c)) continue;
            if (mark[g] != a) { mark[g] = a; o->seg_ncap[a]++; }
            if (dd < bestd[g]) { bestd[g] = dd; bestseg[g] = a; }
        }
    }
    for (i = 0; i < ngv; i++)
        if (bestseg[i] >= 0) o->gjoint[i] = o->joints[o->seg_child[bestseg[i]]].parent;   /* a bone moves with its parent joint */
    /* pins override */
    for (a = 0; a < d->npin; a++)
        for (i = 0; i < ngv; i++)
            if (used[i] && sb_region_has(o, &d->pins[a].r, o->gpos + 3 * i)) { o->gjoint[i] = o->desc_to_sorted[d->pins[a].joint]; bestseg[i] = -2; }

    /* 8. lattice vertices, free-first order */
    {
        int nskel = 0, nfree = 0;
        cellno = sb_alloc(sizeof(int) * (size_t)ngc);
        for (i = 0; i < ngv; i++) if (used[i]) { if (o->gjoint[i] < 0) nfree++; else nskel++; }
        if (nfree + nskel > 65535) {
            sb_fail("%s: %d lattice vertices (max 65535); use a larger cell (about %.3g)", d->path, nfree + nskel, c * pow((nfree + nskel) / 55000.0, 1.0 / 3.0));
            goto done;
        }
        if (nskel == 0) { sb_fail("%s: no skeleton vertices: add a bone (two joints) or a 'pin' region", d->path); goto done; }
        if (nfree == 0) {
            sb_fail("%s: no free vertices: the bones (and pins) hold every lattice vertex; use smaller bone radii ('bone_radius R') or a smaller cell (now %g)", d->path, c);
            goto done;
        }
        o->nv = nfree + nskel; o->nf = nfree;
        o->v_grid = sb_alloc(sizeof(int) * (size_t)o->nv);
        o->x = sb_alloc(sizeof(double) * 3 * (size_t)o->nv);
        o->vseg = sb_alloc(sizeof(int) * (size_t)o->nv);
        nfree = 0; nskel = o->nf;
        for (i = 0; i < ngv; i++)
            if (used[i]) {
                int v = o->gjoint[i] < 0 ? nfree++ : nskel++;
                o->gvert[i] = v; o->v_grid[v] = i;
                memcpy(o->x + 3 * v, o->gpos + 3 * i, sizeof(double) * 3);
                o->vseg[v] = o->gjoint[i] < 0 ? -1 : bestseg[i];
                if (o->vseg[v] >= 0) o->seg_nv[o->vseg[v]]++;
            }
        for (a = 0; a < ngc; a++) if (keep[a]) o->nc++;
        o->cells = sb_alloc(sizeof(int) * 8 * (size_t)o->nc);
        o->cell_grid = sb_alloc(sizeof(int) * (size_t)o->nc);
        for (a = 0, j = 0; a < ngc; a++)
            if (keep[a]) {
                int g[8];
                cell_corners(o, a, g);
                for (k = 0; k < 8; k++) o->cells[8 * j + k] = o->gvert[g[k]];
                o->cell_grid[j] = a; cellno[a] = j; j++;
            }
        for (i = 0; i < m->nv; i++) o->emb_cell[i] = cellno[o->emb_cell[i]];
        {   /* inside fraction per kept cell (was per grid cell) */
            double *fill = sb_alloc(sizeof(double) * (size_t)o->nc);
            for (j = 0; j < o->nc; j++) fill[j] = o->cell_fill[o->cell_grid[j]];
            free(o->cell_fill);
            o->cell_fill = fill;
        }
    }
    for (a = 0; a < o->nseg; a++)   /* cannot happen while the joints are inside (their cells are kept); a safety net */
        if (o->seg_ncap[a] == 0)
            fprintf(stderr, "sinew-bake: warning: %s:%d: bone '%s'->'%s' captures no lattice vertex; its flesh follows the neighbouring bones\n",
                    d->path, o->joints[o->seg_child[a]].line, o->joints[o->joints[o->seg_child[a]].parent].name, o->joints[o->seg_child[a]].name);

    /* 9. sanity check: every kept cell is an undistorted cube (Jacobian c^3 at its centre
     * and corners); the grid is never moved, so a failure is an internal error */
    o->min_jac = HUGE_VAL;
    for (a = 0; a < o->nc; a++) {
        const double *xc[8];
        for (k = 0; k < 8; k++) xc[k] = o->x + 3 * o->cells[8 * a + k];
        for (k = 0; k < 9; k++) {
            double t[3], p[3], J[3][3], D;
            int e;
            for (e = 0; e < 3; e++) t[e] = k == 8 ? 0.5 : (k >> e & 1);
            corners_point(xc, t, p, J);
            D = det3(J) / (c * c * c);
            if (D < o->min_jac) o->min_jac = D;
            if (!(fabs(D - 1) < 1e-6)) { sb_fail("%s: internal error: lattice cell %d is not a cube (Jacobian %g of c^3)", d->path, a, D); goto done; }
        }
    }

    /* 10. frames (seed 003 §3.3): skeleton vertices move with their joint; free vertices
     * and cell centres by the rule in frame_at */
    o->fb1 = sb_alloc(sizeof(int) * (size_t)o->nv);
    o->fb2 = sb_alloc(sizeof(int) * (size_t)o->nv);
    o->fw = sb_alloc(sizeof(double) * (size_t)o->nv);
    o->cfb1 = sb_alloc(sizeof(int) * (size_t)o->nc);
    o->cfb2 = sb_alloc(sizeof(int) * (size_t)o->nc);
    o->cfw = sb_alloc(sizeof(double) * (size_t)o->nc);
    jd = sb_alloc(sizeof(double) * (size_t)nj);
    for (i = 0; i < o->nv; i++) {
        if (i >= o->nf) { o->fb1[i] = o->fb2[i] = o->gjoint[o->v_grid[i]]; o->fw[i] = 0; continue; }
        frame_at(d, o, o->x + 3 * i, B, jd, &o->fb1[i], &o->fb2[i], &o->fw[i]);
        if (d->skin_frames && !frame_ruled(d, o, o->x + 3 * i)) skin_frame(d, o, o->x + 3 * i, jd, &o->fb1[i], &o->fb2[i], &o->fw[i]);
    }
    for (a = 0; a < o->nc; a++) {
        double p[3];
        for (k = 0; k < 3; k++) p[k] = o->x[3 * o->cells[8 * a] + k] + 0.5 * c;
        frame_at(d, o, p, B, jd, &o->cfb1[a], &o->cfb2[a], &o->cfw[a]);
        if (d->skin_frames && !frame_ruled(d, o, p)) skin_frame(d, o, p, jd, &o->cfb1[a], &o->cfb2[a], &o->cfw[a]);
    }

    /* 11. limits at rest positions, later rules override */
    o->limit = sb_alloc(sizeof(double) * (size_t)o->nv);
    for (a = 0; a < d->nlr; a++)
        for (i = 0; i < o->nv; i++)
            if (sb_region_has(o, &d->lrules[a].r, o->x + 3 * i)) o->limit[i] = d->lrules[a].dist;

    /* 12. block sparsity pattern: vertices sharing a cell */
    {
        int *cnt = sb_alloc(sizeof(int) * (size_t)(o->nv + 1)), *tmp = sb_alloc(sizeof(int) * 27 * 8 * (size_t)o->nv);
        int *vc = sb_alloc(sizeof(int) * 8 * (size_t)o->nv);   /* cells per vertex (<= 8) */
        int *nvc = sb_alloc(sizeof(int) * (size_t)o->nv);
        for (a = 0; a < o->nc; a++) for (k = 0; k < 8; k++) { int v = o->cells[8 * a + k]; vc[8 * v + nvc[v]++] = a; }
        o->nbptr = sb_alloc(sizeof(int) * (size_t)(o->nv + 1));
        for (i = 0; i < o->nv; i++) {
            int nn = 0, *lst = tmp + 27 * 8 * i, x, y;
            for (a = 0; a < nvc[i]; a++) for (k = 0; k < 8; k++) lst[nn++] = o->cells[8 * vc[8 * i + a] + k];
            for (x = 1; x < nn; x++) { int v = lst[x]; for (y = x; y > 0 && lst[y - 1] > v; y--) lst[y] = lst[y - 1]; lst[y] = v; }
            for (x = 0, y = 0; x < nn; x++) if (y == 0 || lst[y - 1] != lst[x]) lst[y++] = lst[x];
            cnt[i] = y;
            o->nbptr[i + 1] = o->nbptr[i] + y;
        }
        o->nb = sb_alloc(sizeof(int) * (size_t)o->nbptr[o->nv]);
        for (i = 0; i < o->nv; i++) memcpy(o->nb + o->nbptr[i], tmp + 27 * 8 * i, sizeof(int) * (size_t)cnt[i]);
        free(cnt); free(tmp); free(vc); free(nvc);
    }
    o->M = sb_alloc(sizeof(double) * (size_t)o->nbptr[o->nv]);
    o->S = sb_alloc(sizeof(double) * 9 * (size_t)o->nbptr[o->nv]);
    o->T = sb_alloc(sizeof(double) * (size_t)o->nbptr[o->nv]);   /* twist retired: stays 0 */
    o->Se = sb_alloc(sizeof(double) * 576 * (size_t)o->nc);
    if (d->lod_level && d->levels_cut) o->Me = sb_alloc(sizeof(double) * 64 * (size_t)o->nc);   /* the cut level's Galerkin mass (sb_cut.c) */

    /* 13. integrals */
    if (sb_integrate_frac(d, o, frac, fidx)) goto done;

    o->nt = m->nt;
    o->tri = sb_alloc(sizeof(int) * 3 * (size_t)m->nt);
    memcpy(o->tri, m->tri, sizeof(int) * 3 * (size_t)m->nt);
    rc = 0;
done:
    if (!quiet && sb_now() - t0 > 1.0) fprintf(stderr, "\n");
    sb_inside_free(&in);
    free(keep); free(frac); free(fidx); free(used); free(bestd); free(bestseg); free(mark); free(cellno); free(jd);
    return rc;
}

void sb_model_free(sb_model *o)
{
    sb_rig_free(o); /* idempotent: callers that freed the rigs first are fine */
    sb_force_free(o);
    sb_segment_free(o);
    sb_crease_free(o);
    free(o->joints); free(o->desc_to_sorted); free(o->seg_child); free(o->gpos); free(o->gjoint); free(o->gvert);
    free(o->v_grid); free(o->x); free(o->cells); free(o->cell_grid); free(o->cell_fill); free(o->fb1); free(o->fb2); free(o->fw);
    free(o->nbptr); free(o->nb); free(o->M); free(o->S); free(o->T); free(o->emb_cell); free(o->emb_t); free(o->tri);
    free(o->Se); free(o->Me); free(o->cfb1); free(o->cfb2); free(o->cfw); free(o->limit); free(o->vseg);
    free(o->seg_r); free(o->seg_flesh); free(o->seg_auto); free(o->seg_nv); free(o->seg_ncap);
    sb_srcmap_free(&o->src);
    memset(o, 0, sizeof *o);
}

int sb_model_check(const sb_model *o, const sb_mesh *m, sb_check *r)
{
    double maxS = 0, maxx = 0, trans = 0, rot = 0, worst = 0;
    int i, e, k, a, b;
    memset(r, 0, sizeof *r);
    r->vol_ratio = o->mesh_volume > 0 ? o->inside_volume / o->mesh_volume : 0;
    /* embedding with t quantized to Q15 as the blob stores it */
    for (i = 0; i < o->ns && i < m->nv; i++) {
        double t[3], p[3], dd = 0;
        for (k = 0; k < 3; k++) t[k] = floor(o->emb_t[3 * i + k] * 32768.0 + 0.5) / 32768.0;
        sb_cell_point(o, o->emb_cell[i], t, p);
        for (k = 0; k < 3; k++) dd += (p[k] - m->v[3 * i + k]) * (p[k] - m->v[3 * i + k]);
        worst = fmax(worst, sqrt(dd));
    }
    r->emb_err = worst / o->bbox_diag;
    /* null space of the elastic stiffness: translations (block row sums) and rest rotations */
    for (e = 0; e < o->nbptr[o->nv]; e++) for (k = 0; k < 9; k++) maxS = fmax(maxS, fabs(o->S[9 * (size_t)e + (size_t)k]));
    for (i = 0; i < o->nv; i++) for (k = 0; k < 3; k++) maxx = fmax(maxx, fabs(o->x[3 * i + k] * o->unit));
    for (i = 0; i < o->nv; i++)
        for (a = 0; a < 3; a++) {
            double ts[3] = {0, 0, 0}, rs[3] = {0, 0, 0};
            for (e = o->nbptr[i]; e < o->nbptr[i + 1]; e++) {
                const double *x = o->x + 3 * o->nb[e], *S = o->S + 9 * (size_t)e + 3 * (size_t)a;
                for (b = 0; b < 3; b++) {   /* rotation about axis b: u = e_b x x (metres) */
                    double u[3] = {0, 0, 0}, rr[3];
                    u[b] = 1;
                    ts[b] += S[b];
                    rr[0] = u[1] * x[2] - u[2] * x[1]; rr[1] = u[2] * x[0] - u[0] * x[2]; rr[2] = u[0] * x[1] - u[1] * x[0];
                    for (k = 0; k < 3; k++) rs[b] += S[k] * rr[k] * o->unit;
                }
            }
            for (b = 0; b < 3; b++) { trans = fmax(trans, fabs(ts[b])); rot = fmax(rot, fabs(rs[b])); }
        }
    r->trans = maxS > 0 ? trans / maxS : 1;
    r->rot = maxS > 0 && maxx > 0 ? rot / (maxS * maxx) : 1;
    r->ok = fabs(r->vol_ratio - 1) <= 0.01 && r->emb_err <= 1e-5 && r->trans <= 1e-12 && r->rot <= 1e-11;
    return r->ok ? 0 : -1;
}
