/* sn_segment.h -- segment meshes (seed 004 ch. 3-4), shared by the solver
 * (sn_segment.c) and the multilevel transfers (sn_segment_level.c).
 *
 * Instance state (h->o_seg), per mesh in blob order: every level's segments
 * (finest first, SEG_W words each), then every level's nodes (NODE_W words).
 *   segment: G[3] centre (Q22), u[3] unit direction start->end (Q30),
 *            v[3] velocity per step (Q22), w[3] angular velocity per step
 *            (Q30 rad); on coarse levels (l > 0) the segment's half
 *            length (Q22), its reciprocal and shift (recip), then 0; on
 *            the finest level 4 words 0. Between the dynamics and the velocity
 *            update v holds the centre and w the direction before the step.
 *   node:    p[3] position (Q22: mean of the endpoints meeting there),
 *            J[3] impulse accumulated for the next step (Q22 per step,
 *            the velocity change of a segment of mass m0).
 */
#ifndef SN_SEGMENT_H
#define SN_SEGMENT_H
#include "sn_instance.h"

#define SEG_W (SN_SEG_SEG_BYTES / 4u)
#define NODE_W (SN_SEG_NODE_BYTES / 4u)
#define SEG_REC SN_ELEM_SEGMESH(SN_REAL_BYTES)
#define ATT_REC SN_ELEM_SEGATTACH(SN_REAL_BYTES)

/* One mesh, decoded from its (validated) record. */
typedef struct seg_mesh {
    unsigned kind, levels, sweeps, coarse_sweeps, relax, flags, side, n_attach;
    uint32_t first_node, first_attach, segs, nodes; /* segs, nodes: all levels */
    sn_q len, gamma, keep, inv_mass, centre, share[SN_SEG_MAX_LEVELS];
    sn_q *S, *N; /* state: segments, nodes of level 0 (coarser levels follow) */
} seg_mesh;

/* One level of a mesh. */
typedef struct seg_lvl {
    sn_q *S, *N;
    uint32_t ns, nn;   /* segments, nodes */
    unsigned kind, side, l;
    sn_q half;         /* half length of a segment (Q22) */
#if defined(SN_FLOAT)
    sn_q bhalf;        /* of a brace: the length of a degenerate coarse brace */
#endif
    sn_q rh;           /* 1/half: fixed Q(29 + bits of half) reciprocal, float 1/x */
    int sh;            /* shift of that reciprocal (fixed) */
} seg_lvl;

void seg_mesh_get(const sn_ihdr *h, uint32_t m, seg_mesh *M);
void seg_level(const seg_mesh *M, unsigned l, seg_lvl *L);
/* nodes of segment i: start a, end b */
void seg_nodes(const seg_lvl *L, uint32_t i, uint32_t *a, uint32_t *b);
/* segment ends meeting at node n: segment index and sign (+1 end, -1 start) */
unsigned seg_node_ends(const seg_lvl *L, uint32_t n, uint32_t seg[5], int sgn[5]);
/* segments of a level rebuilt from its node positions: G = mean, u = unit(b - a);
 * lens (coarse levels): also the segment's half length |b - a|/2 (words 12-14) */
void seg_from_nodes(const seg_lvl *L, int lens, uint32_t *sat);
/* node positions = mean of the endpoints meeting there */
void seg_node_means(const seg_lvl *L, uint32_t *sat);
/* endpoint of segment i (sign s) */
void seg_end(const seg_lvl *L, uint32_t i, int s, sn_q P[3], uint32_t *sat);
/* multilevel (sn_segment_level.c) */
void seg_restrict(const seg_mesh *M, uint32_t *sat);
void seg_prolong(const seg_mesh *M, unsigned l, uint32_t *sat);
/* unit vector of x (any scale) into u; unchanged if x = 0 */
void seg_unit(const sn_q x[3], sn_q u[3]);
#endif
