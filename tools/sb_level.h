/* sb_level.h -- hierarchical basis over repeated subdivision of the control
 * lattice (seed 000 §3.1, appendix A.1; DESIGN.md "Hierarchical basis").
 *
 * Level 0 is the baked lattice (sb_build). Level j+1 splits every cell of
 * level j into 8 (cell edge c / 2^(j+1)): the subdivision is complete, so
 * every vertex of level j is a vertex of level j+1 and the lazy-wavelet set
 * {coarse hats} + {hats of each level's new vertices} is a basis of the
 * finest nodal space (the prolongation P below is square, unit triangular).
 * The matrices are Galerkin products over the finest cells, which carry the
 * same integrand as sb_integrate (interior weight 1, outside points `air`).
 *
 * The basis B of the paper is the subset flagged in_b: every coarse hat, and
 * each finer new vertex's hat if it is non-zero on the interior (a corner of
 * a cell of its level with interior) and zero on the skeleton (not within a
 * bone's radius, not pinned). */
#ifndef SB_LEVEL_H
#define SB_LEVEL_H

#include "sb.h"

#define SB_LEVEL_MAX 3   /* levels above the coarse one (J); memory grows 8x per level */

/* one level's nodal lattice: cells of edge c / 2^j over the coarse kept cells */
typedef struct sb_lev {
    int gn[3];              /* grid vertices per axis at this level */
    double c;               /* cell edge, mesh units */
    int nv, nc;
    int *vgrid;             /* per vertex: grid index i + gn0 (j + gn1 k) at this level */
    double *x;              /* per vertex: rest position, mesh units */
    int *cells;             /* nc x 8 vertex indices (corner k at bit offsets as sb_shape) */
    int *cell_parent;       /* per cell: the level-(j-1) cell holding it (-1 at level 0) */
    unsigned char *cell_in; /* per cell: 1 if it holds interior (some inside quadrature weight) */
    int *vold;              /* per vertex: the level-(j-1) vertex at its place, -1 for a new vertex */
    unsigned char *skel;    /* per vertex: 1 if a bone or pin moves it */
    int *vbone;             /* per skeleton vertex: bone (segment) index, -2 pinned, -1 free */
    /* nodal Galerkin matrices of this level's hats (block pattern: vertices sharing a cell) */
    int *nbptr, *nb;
    double *M;              /* kg per entry */
    double *S;              /* 9 per entry, N/m, row-major */
    double *Me, *Se;        /* per cell: 8x8 kg, 24x24 N/m (dof = corner*3 + component) */
} sb_lev;

typedef struct sb_hier {
    int J;                  /* levels above the coarse one */
    sb_lev lev[SB_LEVEL_MAX + 1];
    sb_model fine;          /* the flat nodal lattice of level J, integrated by sb_integrate_frac */
    /* hierarchical functions: the level-0 vertices (h = v), then the new vertices of level 1, 2, ... */
    int nh;
    int *hlev, *hvert;      /* level and vertex of each function */
    unsigned char *in_b;    /* 1 if in the basis B (above) */
    int nb_fun;             /* functions in B */
    int nb_lev[SB_LEVEL_MAX + 1];   /* of them per level */
    int skel_new[SB_LEVEL_MAX + 1]; /* skeleton new vertices per level */
    int skel_differ[SB_LEVEL_MAX + 1]; /* of them, where the coarser interpolation is not the bone's motion
                                        * (a parent free or on another bone): the flat fine lattice moves
                                        * them with the bone, B interpolates them */
    /* prolongation: finest nodal value n = sum P[e] coef[pidx[e]], e in pptr[n]..pptr[n+1] */
    int *pptr, *pidx;
    double *pval;
    /* hierarchical Galerkin matrices over all nh functions (block pattern) */
    int *hbptr, *hb;
    double *Mh, *Sh;
    double *gh;             /* per function: int rho phi dV (kg); gravity force = gh g */
    double mass;            /* kg, the finest integration */
} sb_hier;

/* Build levels 1..J over the built model o (baked from d and m). 0 or -1 (sb_fail). */
int sb_level_build(const sb_desc *d, const sb_mesh *m, const sb_model *o, int J, sb_hier *h);
void sb_hier_free(sb_hier *h);
/* entry of (i, j) in a block pattern, -1 if absent */
int sb_level_find(const int *ptr, const int *idx, int i, int j);
/* value of the hat of level-lv vertex v at the finest-level vertex n (exact: dyadic) */
double sb_level_hat(const sb_hier *h, int lv, int v, int n);

/* Level of detail ('levels 2', tools/DESCRIPTION.md; runtime/LEVELS.md): o built from d and m
 * with its rigs, forces, segment meshes and crease data; bakes the lattice subdivided once
 * (cell c/2 on o's grid, o's bone radii and frame blend) as a complete blob and writes b =
 * o's blob with it and the two vertex maps appended. */
typedef struct sb_lodinfo {
    int nv1, nf1, nc1;      /* the finer level's lattice */
    uint32_t size1;         /* its blob's bytes */
    int up_far, down_far;   /* vertices of one level outside every kept cell of the other (nearest cell, clamped) */
    uint32_t inst0, inst1, inst;   /* instance bytes of level 0 alone, level 1 alone, the two-level instance */
    int cut_nd;   /* 'details' on the cut level: the details written (sb_cut.h) */
    int cut_nx, cut_freed, cut_air, cut_lost;   /* 'levels 2 cut' (sb_cut.h): extras, level-0 skeleton vertices freed, air children, level-1 cells left out */
} sb_lodinfo;
/* The level-1 description of d (built as o): d shallow-copied (d2 shares d's arrays: free only one)
 * with cell o->c / 2 on o's grid corner, o's frame blend width, no crease lines, lod_level 1. */
void sb_level_desc(const sb_desc *d, const sb_model *o, sb_desc *d2);
/* level 1's model from d2 (sb_level_desc of d) and m: lattice, rigs, forces, segment meshes
 * (not the crease data: o's, shared by sb_level_bake). Errors name d's 'levels' line. 0 or -1. */
int sb_level_model(const sb_desc *d, const sb_desc *d2, const sb_mesh *m, sb_model *o2);
int sb_level_bake(const sb_desc *d, const sb_mesh *m, sb_model *o, int flavour, int quiet, sb_blob *b, sb_lodinfo *info);

#endif
