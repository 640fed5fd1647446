/* sb_lattice_int.h -- what the lattice build's files share (sb_lattice.c,
 * sb_lattice_geom.c, sb_lattice_fill.c, sb_frames.c): grid indexing, the bones
 * as segments, the build's steps kept in their own files. Host tool only. */
#ifndef SB_LATTICE_INT_H
#define SB_LATTICE_INT_H
#include "sb.h"
#include <math.h>

static inline int gidx(const sb_model *o, int i, int j, int k) { return i + o->gn[0] * (j + o->gn[1] * k); }

/* corner grid vertices of grid cell (i,j,k) */
static inline void cell_corners(const sb_model *o, int gc, int g[8])
{
    int nx = o->gn[0] - 1, ny = o->gn[1] - 1;
    int i = gc % nx, j = (gc / nx) % ny, k = gc / (nx * ny), c;
    for (c = 0; c < 8; c++) g[c] = gidx(o, i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
}

/* grid cell (clamped) containing p, and the grid vertex nearest p */
static inline int cell_of(const sb_model *o, const double p[3])
{
    int k, gi[3];
    for (k = 0; k < 3; k++) {
        gi[k] = (int)floor((p[k] - o->gorg[k]) / o->c);
        gi[k] = gi[k] < 0 ? 0 : gi[k] > o->gn[k] - 2 ? o->gn[k] - 2 : gi[k];
    }
    return gi[0] + (o->gn[0] - 1) * (gi[1] + (o->gn[1] - 1) * gi[2]);
}
static inline int vertex_near(const sb_model *o, const double p[3])
{
    int k, gi[3];
    for (k = 0; k < 3; k++) {
        gi[k] = (int)floor((p[k] - o->gorg[k]) / o->c + 0.5);
        gi[k] = gi[k] < 0 ? 0 : gi[k] > o->gn[k] - 1 ? o->gn[k] - 1 : gi[k];
    }
    return gidx(o, gi[0], gi[1], gi[2]);
}

static inline const double *seg_p(const sb_model *o, int a) { return o->joints[o->joints[o->seg_child[a]].parent].pos; }
static inline const double *seg_c(const sb_model *o, int a) { return o->joints[o->seg_child[a]].pos; }

/* samples along segment a every cell/8 or finer, ends included */
static inline int seg_samples(const sb_model *o, int a)
{
    double L = 0;
    int k;
    for (k = 0; k < 3; k++) L += (seg_c(o, a)[k] - seg_p(o, a)[k]) * (seg_c(o, a)[k] - seg_p(o, a)[k]);
    L = sqrt(L);
    return (int)ceil(L / (o->c / 8)) > 1 ? (int)ceil(L / (o->c / 8)) : 1;
}
static inline void seg_point(const sb_model *o, int a, double t, double p[3])
{
    int k;
    for (k = 0; k < 3; k++) p[k] = seg_p(o, a)[k] + t * (seg_c(o, a)[k] - seg_p(o, a)[k]);
}

/* distance from p to segment a-b (sb_lattice_geom.c) */
double sb_seg_dist(const double p[3], const double a[3], const double b[3]);
/* step 3: the inside fraction of every grid cell (o->cell_fill), keep[] the cells
 * at least one quadrature point's worth inside, fidx[] / *frac the surface cells'
 * per-point fractions as sb_integrate_frac reads them (sb_lattice_fill.c) */
int sb_lattice_fill(const sb_desc *d, const sb_mesh *m, sb_model *o, const sb_inside *in, int *keep, int *fidx,
                    double **frac, double t0);
/* step 9: every kept cell an undistorted cube (sb_lattice_geom.c) */
int sb_lattice_cubes(const sb_desc *d, sb_model *o);
/* step 10: the frames of the lattice vertices and cell centres (sb_frames.c) */
void sb_lattice_frames(const sb_desc *d, sb_model *o);

#endif
