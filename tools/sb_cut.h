/* sb_cut.h -- the cut coarse level (issue 13; runtime/LEVELS.md §2 "The cut
 * level"): level 0's unknowns with every coarse hat cut at level 1's skeleton
 * (seed 000 §3.1 with the finer skeleton; hierarchical k = 0 of LEVELS.md §3).
 *
 * Per level-0 cell E the element is the Galerkin sum over E's kept children c
 * (level 1's cells; a child level 1 did not keep takes the air element, air x a
 * solid cube's, as sb_integrate weighs outside points) of W_c^T S_c W_c (mass alike): a child corner is E's corner
 * (weight 1), a level-1 skeleton vertex (an *extra* prescribed vertex, weight 1),
 * or a free level-1 vertex interpolated from E's corners (dyadic weights). One
 * frame per coarse cell (the parent's). */
#ifndef SB_CUT_H
#define SB_CUT_H

#include "sb.h"

#define SB_CUT_MAXX 19   /* extras per cell: the 3x3x3 points of E's closure that are not corners */
#define SB_CUT_NL (8 + SB_CUT_MAXX)

typedef struct sb_cut {
    int nx;          /* extra prescribed vertices */
    int nfreed;      /* level-0 skeleton vertices free on level 1: unknowns of the cut level (sb_cut_apply) */
    int *v1;         /* per level-0 vertex: the level-1 vertex at its place, -1 */
    int nlost;       /* kept level-1 cells in no kept level-0 cell (level 0 has no unknown there: left out) */
    int nair;        /* children of level-0 cells that level 1 did not keep: the air element (sb_integrate's outside weight) */
    int *xv;         /* per extra: its level-1 vertex */
    int *cnx;        /* per level-0 cell: its extras */
    int *cx;         /* per cell x SB_CUT_MAXX: extra ids (local 8 + k), ordered by their 3x3x3 point */
    int *csub;       /* per cell x 27: point x + 3y + 9z of E's closure (in half cells) -> extra id, -1 */
    int nd;          /* detail functions: level-1 free vertices at non-corner points of kept level-0 cells (hats of level 1) */
    int *dv;         /* per detail: its level-1 vertex */
    double *dx;      /* per detail: its point at rest (level 1's vertex: the dyadic point) */
    int *dcell, *dpoint; /* per detail: the first cell holding it and its point there (x + 3y + 9z) */
    int *cnd;        /* per level-0 cell: its details */
    int *cd;         /* per cell x SB_CUT_MAXX: detail ids (local 8 + cnx + k), ordered by their 3x3x3 point */
    int *dsub;       /* per cell x 27: point -> detail id, -1 */
    double *K;       /* per cell: (3 NL)^2, locals 0..7 = E's corners, 8.. = cx order, then cd order (N/m, rest frame); a
                      * child corner at a detail's point is the coarse field there plus the detail (the hierarchical basis) */
    double *M;       /* per cell: NL^2 (kg) */
} sb_cut;

/* E's elements from level 0 (o) and level 1 (o2, with per-cell Me); 0 or -1 (sb_fail) */
int sb_cut_build(const sb_model *o, const sb_model *o2, double air, sb_cut *cut);
void sb_cut_free(sb_cut *cut);
/* o becomes the cut level: level 0's skeleton vertices free on level 1 made unknowns (after o's free ones,
 * level 1's frame; cut->nfreed), the extras appended as skeleton vertices (index o->nv + id; rest and joint
 * from o2), o's per-cell stiffness, pattern, mass and stiffness replaced by the cut element's
 * corner blocks (and the extras' mass columns); o->cut points at cut (borrowed). */
void sb_cut_apply(const sb_desc *d, sb_model *o, const sb_model *o2, sb_cut *cut);

#endif
