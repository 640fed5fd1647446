/* sb_segment.c -- segment meshes (seed 004 ch. 3-4): chains and
 * (2^n+1)^2 sheets of equal rigid segments joined by point-to-point
 * displacement constraints, declared in the description ('chain', 'sheet',
 * 'attach'; tools/DESCRIPTION.md "Segment meshes"), attached to the
 * character's surface or joints, and written to the SEGMESH, SEGNODES and
 * SEGATTACH sections (runtime/src/sn_format.h). */
#include "sb.h"
#include "../runtime/src/sn_format.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* nearest mesh (= surface) vertex to p; ties: the lowest index */
static int nearest_vertex(const sb_mesh *m, const double p[3], double *dist)
{
    int i, best = -1;
    double bd = 0;
    for (i = 0; i < m->nv; i++) {
        const double *v = m->v + 3 * (size_t)i;
        double d2 = (v[0] - p[0]) * (v[0] - p[0]) + (v[1] - p[1]) * (v[1] - p[1]) + (v[2] - p[2]) * (v[2] - p[2]);
        if (best < 0 || d2 < bd) { best = i; bd = d2; }
    }
    *dist = sqrt(bd);
    return best;
}

static int cmp_att(const void *a, const void *b)
{
    int x = ((const sb_segatt *)a)->node, y = ((const sb_segatt *)b)->node;
    return (x > y) - (x < y);
}

static int build_one(const sb_desc *d, const sb_mesh *m, const sb_model *o, const sb_segdef *g, sb_segmesh *s)
{
    const char *what = g->kind ? "sheet" : "chain";
    int side = g->side, i, k, nsurf = 0;
    sb_segatt *att;
    double lu = sqrt(g->u[0] * g->u[0] + g->u[1] * g->u[1] + g->u[2] * g->u[2]);
    s->def = *g;
    s->def.att = NULL;   /* owned by the description */
    strcpy(s->path, d->path);
    s->nodes = g->kind ? side * side : side;
    s->segs = g->kind ? 2 * side * (side - 1) : side - 1;
    sn_seg_counts(g->kind ? SN_SEG_SHEET : SN_SEG_CHAIN, (unsigned)side, (unsigned)g->levels, &s->segs_all, &s->nodes_all);
    s->seg_len = lu / (side - 1);
    s->seg_mass = g->mass / s->segs;
    s->keep = exp(-g->damping * o->h);
    /* evenly spaced rest nodes, sheets row-major: node (r, c) = p0 + c/(side-1) u + r/(side-1) v */
    s->x = sb_alloc(sizeof(double) * 3 * (size_t)s->nodes);
    for (i = 0; i < s->nodes; i++) {
        double c = g->kind ? (double)(i % side) : (double)i, r = g->kind ? (double)(i / side) : 0.0;
        for (k = 0; k < 3; k++) s->x[3 * i + k] = g->p0[k] + c / (side - 1) * g->u[k] + r / (side - 1) * g->v[k];
    }
    /* attachments in node order (the parser refused duplicates) */
    att = sb_alloc(sizeof *att * (size_t)(g->natt ? g->natt : 1));
    if (g->natt) memcpy(att, g->att, sizeof *att * (size_t)g->natt);
    qsort(att, (size_t)g->natt, sizeof *att, cmp_att);
    s->natt = g->natt;
    s->att_node = sb_alloc(sizeof(int) * (size_t)(g->natt + 1));
    s->att_kind = sb_alloc(sizeof(int) * (size_t)(g->natt + 1));
    s->att_target = sb_alloc(sizeof(int) * (size_t)(g->natt + 1));
    s->att_dist = sb_alloc(sizeof(double) * (size_t)(g->natt + 1));
    /* The runtime holds a surface-attached node on its vertex. Every node must
     * lie within 'within' of the surface as declared; then the whole mesh moves
     * rigidly by the mean offset of its surface nodes to their vertices (one
     * attachment: exactly onto it), which keeps every segment its rest length
     * (a node snapped alone would not be seg_len from its neighbours). */
    for (i = 0; i < g->natt; i++) {
        const double *p = s->x + 3 * att[i].node;
        double dist, within = att[i].within >= 0 ? att[i].within : 0.5 * s->seg_len;
        int v;
        if (att[i].kind != SB_SEGATT_SURFACE) continue;
        v = nearest_vertex(m, p, &dist);
        if (v < 0) { sb_fail("%s:%d: %s '%s': no surface vertex to attach to", d->path, att[i].line, what, g->name); free(att); return -1; }
        if (dist > within) {
            sb_fail("%s:%d: %s '%s' node %d at (%g, %g, %g) is %g from the nearest surface vertex %d at (%g, %g, %g), more than %g%s: "
                    "move the %s onto the surface or give 'within D'", d->path, att[i].line, what, g->name, att[i].node,
                    p[0], p[1], p[2], dist, v, m->v[3 * v], m->v[3 * v + 1], m->v[3 * v + 2], within, att[i].within >= 0 ? "" : " (half a segment)", what);
            free(att);
            return -1;
        }
        for (k = 0; k < 3; k++) s->shift[k] += m->v[3 * v + k] - p[k];
        nsurf++;
    }
    if (nsurf) {
        for (k = 0; k < 3; k++) s->shift[k] /= nsurf;
        for (i = 0; i < s->nodes; i++) for (k = 0; k < 3; k++) s->x[3 * i + k] += s->shift[k];
    }
    for (i = 0; i < g->natt; i++) {
        const double *p = s->x + 3 * att[i].node;
        s->att_node[i] = att[i].node;
        s->att_kind[i] = att[i].kind;
        if (att[i].kind == SB_SEGATT_JOINT) {
            s->att_target[i] = o->desc_to_sorted[att[i].joint];
            s->att_dist[i] = 0;
        } else {
            double dist, within = att[i].within >= 0 ? att[i].within : 0.5 * s->seg_len;
            int v = nearest_vertex(m, p, &dist);
            if (v > 65535) { sb_fail("%s:%d: %s '%s': surface vertex %d beyond 65535", d->path, att[i].line, what, g->name, v); free(att); return -1; }
            if (dist > within) {
                sb_fail("%s:%d: %s '%s' node %d is %g from the nearest surface vertex %d after the %s moved by (%g, %g, %g) (the mean offset of "
                        "its surface attachments), more than %g%s: attach fewer nodes, reshape the %s or give 'within D'",
                        d->path, att[i].line, what, g->name, att[i].node, dist, v, what, s->shift[0], s->shift[1], s->shift[2],
                        within, att[i].within >= 0 ? "" : " (half a segment)", what);
                free(att);
                return -1;
            }
            s->att_target[i] = v;
            s->att_dist[i] = dist;
        }
    }
    free(att);
    return 0;
}

int sb_segment_build(const sb_desc *d, const sb_mesh *m, sb_model *o)
{
    int i;
    o->nsm = 0; o->sm = NULL;
    if (d->nseg > (int)SN_SEG_MAX_MESHES) return sb_fail("%s: %d segment meshes, at most %u", d->path, d->nseg, SN_SEG_MAX_MESHES);
    if (!d->nseg) return 0;
    o->sm = sb_alloc(sizeof *o->sm * (size_t)d->nseg);
    for (i = 0; i < d->nseg; i++) {
        o->nsm = i + 1;   /* so sb_segment_free releases a half-built mesh */
        if (build_one(d, m, o, &d->segs[i], &o->sm[i])) { sb_segment_free(o); return -1; }
    }
    return 0;
}

void sb_segment_free(sb_model *o)
{
    int i;
    for (i = 0; i < o->nsm && o->sm; i++) {
        sb_segmesh *s = &o->sm[i];
        free(s->x); free(s->att_node); free(s->att_kind); free(s->att_target); free(s->att_dist);
    }
    free(o->sm);
    o->nsm = 0; o->sm = NULL;
}

uint32_t sb_segment_state_bytes(const sb_model *o)
{
    uint32_t b = 0;
    int i;
    for (i = 0; i < o->nsm; i++) b += SN_SEG_SEG_BYTES * o->sm[i].segs_all + SN_SEG_NODE_BYTES * o->sm[i].nodes_all;
    return b;
}

void sb_segment_blob_counts(const sb_model *o, uint32_t *nodes, uint32_t *attach)
{
    int i;
    *nodes = 0; *attach = 0;
    for (i = 0; i < o->nsm; i++) { *nodes += (uint32_t)o->sm[i].nodes; *attach += (uint32_t)o->sm[i].natt; }
}

/* little-endian stores and one real (fixed: round(x 2^frac), ties away from zero) */
static void put16(unsigned char *p, unsigned v) { p[0] = (unsigned char)(v & 255u); p[1] = (unsigned char)(v >> 8 & 255u); }
static void put32(unsigned char *p, uint32_t v) { int k; for (k = 0; k < 4; k++) p[k] = (unsigned char)(v >> (8 * k) & 255u); }
static double rnd(double x) { return x < 0 ? -floor(-x + 0.5) : floor(x + 0.5); }
static int put_real(unsigned char *p, int flavour, double x, int frac)
{
    if (flavour == SB_FIXED) {
        double q = rnd(ldexp(x, frac));
        if (!(q >= -2147483648.0 && q <= 2147483647.0)) return -1;
        put32(p, (uint32_t)(int32_t)q);
    } else if (flavour == SB_FLOAT) {
        float f = (float)x;
        uint32_t u;
        memcpy(&u, &f, 4);
        put32(p, u);
    } else {
        uint64_t u;
        int k;
        memcpy(&u, &x, 8);
        for (k = 0; k < 8; k++) p[k] = (unsigned char)(u >> (8 * k) & 255u);
    }
    return 0;
}

/* Largest |rest node - root| in internal units: the runtime's lengths are Q22
 * (|x| < 512) and its state clamps at 64 units (NUMERICS.md); half that leaves
 * the mesh room to swing. */
#define SB_SEG_MAX_COORD 32.0

int sb_segment_blob_write(const sb_model *o, unsigned char *blob, const uint32_t *off, int flavour, int rs, int len_shift, double m0)
{
    const double *root = o->joints[0].pos;
    double U = ldexp(1.0, len_shift);
    uint32_t fn = 0, fa = 0;
    int i, j, k;
    for (i = 0; i < o->nsm; i++) {
        const sb_segmesh *s = &o->sm[i];
        const sb_segdef *g = &s->def;
        unsigned char *r = blob + off[SN_SEC_SEGMESH] + (size_t)i * (size_t)SN_ELEM_SEGMESH(rs);
        const char *what = g->kind ? "sheet" : "chain";
        double inv = m0 / s->seg_mass, sh[4];
        int bad = 0;
        /* Q16.16 of m0 / segment mass: at least one LSB, below 2^15 */
        if (!(inv >= 1.0 / 65536 && inv <= 32767.0))
            return sb_fail("%s:%d: %s '%s': segment mass %g kg is out of range against the blob's mass unit m0 = %g kg (m0 / segment mass = %g, "
                           "want 2^-16..32767): change its 'mass'", s->path, g->line, what, g->name, s->seg_mass, m0, inv);
        r[0] = (unsigned char)(g->kind ? SN_SEG_SHEET : SN_SEG_CHAIN);
        r[1] = (unsigned char)g->levels;
        r[2] = (unsigned char)g->sweeps;
        r[3] = (unsigned char)(g->gravity ? 0u : SN_SEGF_NO_GRAVITY);
        put16(r + 4, (unsigned)g->side);
        put16(r + 6, (unsigned)s->natt);
        put32(r + 8, fn);
        put32(r + 12, fa);
        /* shares Q30: the finest level takes the rounding so they sum to exactly 2^30 */
        for (k = 0; k < 4; k++) sh[k] = k < g->levels ? g->share[k] : 0.0;
        if (flavour == SB_FIXED) {
            double rest = 1073741824.0;
            for (k = 1; k < 4; k++) { sh[k] = rnd(sh[k] * 1073741824.0); rest -= sh[k]; }
            sh[0] = rest;
            for (k = 0; k < 4; k++) sh[k] = ldexp(sh[k], -30);   /* exact: put_real restores the integers */
        }
        bad |= put_real(r + 16, flavour, s->seg_len / U, SN_Q_LEN);
        bad |= put_real(r + 16 + (size_t)rs, flavour, g->gamma, SN_Q_ROT);
        bad |= put_real(r + 16 + 2 * (size_t)rs, flavour, s->keep, SN_Q_ROT);
        bad |= put_real(r + 16 + 3 * (size_t)rs, flavour, inv, 16);
        bad |= put_real(r + 16 + 4 * (size_t)rs, flavour, g->centre, SN_Q_ROT);
        for (k = 0; k < 4; k++) bad |= put_real(r + 16 + (size_t)(5 + k) * (size_t)rs, flavour, sh[k], SN_Q_ROT);
        /* format 6.2: coarse_sweeps (= sweeps unless given), relax, u16 0 */
        r[16 + 9 * (size_t)rs] = (unsigned char)(g->coarse_sweeps ? g->coarse_sweeps : g->sweeps);
        r[17 + 9 * (size_t)rs] = (unsigned char)g->relax;
        put16(r + 18 + 9 * (size_t)rs, 0);
        if (flavour == SB_FIXED && !(rnd(ldexp(s->seg_len / U, SN_Q_LEN)) >= 1))
            return sb_fail("%s:%d: %s '%s': segments of %g mesh units are below the blob's length resolution", s->path, g->line, what, g->name, s->seg_len);
        for (j = 0; j < s->nodes; j++) {
            unsigned char *p = blob + off[SN_SEC_SEGNODES] + (size_t)(fn + (uint32_t)j) * (size_t)SN_ELEM_SEGNODES(rs);
            for (k = 0; k < 3; k++) {
                double x = (s->x[3 * j + k] - root[k]) / U;
                if (!(fabs(x) <= SB_SEG_MAX_COORD))
                    return sb_fail("%s:%d: %s '%s' node %d lies %g mesh units from the root joint: at most %g (%g internal units)",
                                   s->path, g->line, what, g->name, j, fabs(s->x[3 * j + k] - root[k]), SB_SEG_MAX_COORD * U, SB_SEG_MAX_COORD);
                bad |= put_real(p + (size_t)k * (size_t)rs, flavour, x, SN_Q_LEN);
            }
        }
        for (j = 0; j < s->natt; j++) {
            unsigned char *p = blob + off[SN_SEC_SEGATTACH] + (size_t)(fa + (uint32_t)j) * (size_t)SN_ELEM_SEGATTACH(rs);
            const double *x = s->x + 3 * s->att_node[j];
            put16(p, (unsigned)s->att_node[j]);
            p[2] = (unsigned char)(s->att_kind[j] == SB_SEGATT_JOINT ? SN_SEGATT_JOINT : SN_SEGATT_SURFACE);
            p[3] = 0;
            put16(p + 4, (unsigned)s->att_target[j]);
            put16(p + 6, 0);
            for (k = 0; k < 3; k++)
                bad |= put_real(p + 8 + (size_t)k * (size_t)rs, flavour, s->att_kind[j] == SB_SEGATT_JOINT ? (x[k] - root[k]) / U : 0.0, SN_Q_LEN);
        }
        if (bad) return sb_fail("%s:%d: %s '%s': a value does not fit its fixed-point format", s->path, g->line, what, g->name);
        fn += (uint32_t)s->nodes;
        fa += (uint32_t)s->natt;
    }
    return 0;
}
