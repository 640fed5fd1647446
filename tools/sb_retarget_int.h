/* sb_retarget_int.h -- helpers shared by the retargeting's files (sb_retarget.c:
 * characters, set-up, cost, solve, Jacobians; sb_retarget_surf.c: closest points;
 * sb_retarget_xfer.c: statics at rest, transfer, output). Not the tool's interface:
 * that is sb_retarget.h. */
#ifndef SB_RETARGET_INT_H
#define SB_RETARGET_INT_H
#include "sb_retarget.h"
#include <math.h>

static inline double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static inline int finite3(const double *p) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]); }

/* 3x3 inverse (row-major); returns the determinant (0: singular, out untouched) */
static inline double inv3(const double *a, double *o)
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

static inline double norm(const double *v, int n)
{
    double s = 0;
    int i;
    for (i = 0; i < n; i++) s += v[i] * v[i];
    return sqrt(s);
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

/* the kept cell of o holding p and its reference coordinates; -1 if none.
 * cmap: kept cell of every grid cell (-1 none), or NULL (a search) */
int sb_rt_locate(const sb_model *o, const int *cmap, const double p[3], double t[3]);
/* point term entries of a point at (cell, t) of A, scaled by s, appended to tm */
void sb_rt_add_point(sb_rt_term *tm, const sb_model *o, int ci, const double t[3], double s);
/* closest-triangle index over positions P (nt triangles tri); freed by sb_rt_tri_index_free */
void sb_rt_tri_index_make(tri_index *x, const double *P, const int *tri, int nt);
void sb_rt_tri_index_free(tri_index *x);
/* the triangle of x closest to p and its barycentric weights */
int sb_rt_tri_closest(const tri_index *x, const double p[3], double bw[3]);
/* surface vertex k of o embedded in lattice positions P (its cell's trilinear weights) */
void sb_rt_embed_point(const sb_model *o, const double *P, int k, double out[3]);
/* mapped position of A's surface vertex k */
void sb_rt_mapped_surface_point(const sb_retarget *rt, int k, double out[3]);
#endif
