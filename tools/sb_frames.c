/* sb_frames.c -- the frames of seed 003 §3.3 at rest points: the two nearest
 * bones blended by distance, 'frame' rules, or the artist's skin weights
 * ('frames skin'); the lattice build's step 10 (sb_build). */
#include "sb.h"
#include "sb_lattice_int.h"
#include "sb_gltf.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
        double dd = sb_seg_dist(p, seg_p(o, a), seg_c(o, a));
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

/* step 10 of sb_build: skeleton vertices move with their joint; free vertices
 * and cell centres by the rule in frame_at */
void sb_lattice_frames(const sb_desc *d, sb_model *o)
{
    double c = o->c, *jd, B = d->blend > 0 ? d->blend : d->cell;
    int i, a, k;
    o->fb1 = sb_alloc(sizeof(int) * (size_t)o->nv);
    o->fb2 = sb_alloc(sizeof(int) * (size_t)o->nv);
    o->fw = sb_alloc(sizeof(double) * (size_t)o->nv);
    o->cfb1 = sb_alloc(sizeof(int) * (size_t)o->nc);
    o->cfb2 = sb_alloc(sizeof(int) * (size_t)o->nc);
    o->cfw = sb_alloc(sizeof(double) * (size_t)o->nc);
    jd = sb_alloc(sizeof(double) * (size_t)o->nj);
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
    free(jd);
}
