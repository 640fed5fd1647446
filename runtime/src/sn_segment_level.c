/* sn_segment_level.c -- the multilevel transfers of a segment sheet (seed
 * 004 ch. 4): restriction of node positions and impulses to the coarser
 * levels (§4.2.1, eq. 4.1-4.2) and prolongation of a solved level's
 * positions to the next finer one with rotated offsets (§4.2.2, fig. 4.8).
 * Each level keeps its own velocities; nothing else passes between levels.
 *
 * Cost: restriction (levels - 1) N_0 impulse transfers + sum_l N_l copies;
 * prolongation N_(l-1) nodes, each at most one quaternion (one isqrt and one
 * division) and one 3x3 product. No loop exits on a value.
 */
#include "sn_segment.h"

/* Impulse shares and coarse positions. A fine node's impulse goes to level
 * l with share[l]; a fine node between level-l nodes splits it evenly over
 * the 2 or 4 neighbouring ones (seed 004 fig. 4.5). Coarse node (r, c) is at
 * the position of finer node (2r, 2c); coarse segments are rebuilt from
 * their nodes (centre = midpoint, u = direction). */
void seg_restrict(const seg_mesh *M, uint32_t *sat) {
    seg_lvl F, L;
    uint32_t n, i;
    unsigned l, k;
    seg_level(M, 0, &F);
    for (l = 1; l < M->levels; l++) {
        uint32_t msk = (1u << l) - 1u;
        seg_level(M, l, &L);
        for (n = 0; n < F.nn; n++) {
            uint32_t r = n / F.side, c = n % F.side, r0 = r >> l, c0 = c >> l;
            uint32_t nr = (r & msk) ? 2u : 1u, nc = (c & msk) ? 2u : 1u, a, b;
            sn_q part[3];
            for (k = 0; k < 3; k++) { /* share[l] J / (nr nc): a rounding shift by 30 + log2(nr nc) */
#if defined(SN_FLOAT)
                part[k] = F.N[NODE_W * n + 3 + k] * M->share[l] / (float)(nr * nc);
#else
                part[k] = sn_mulq(F.N[NODE_W * n + 3 + k], M->share[l], SN_Q_ROT + (int)(nr + nc) - 2, sat);
#endif
            }
            for (a = 0; a < nr; a++)
                for (b = 0; b < nc; b++) {
                    sn_q *J = L.N + NODE_W * ((r0 + a) * L.side + c0 + b) + 3;
                    for (k = 0; k < 3; k++) J[k] = sn_add(J[k], part[k], sat);
                }
        }
    }
    for (n = 0; n < F.nn; n++) /* level 0 keeps share[0] */
        for (k = 0; k < 3; k++) F.N[NODE_W * n + 3 + k] = sn_mulq(F.N[NODE_W * n + 3 + k], M->share[0], SN_Q_ROT, sat);
    for (l = 1; l < M->levels; l++) {
        seg_level(M, l - 1, &F);
        seg_level(M, l, &L);
        for (i = 0; i < L.nn; i++) {
            uint32_t f = 2u * (i / L.side) * F.side + 2u * (i % L.side);
            for (k = 0; k < 3; k++) L.N[NODE_W * i + k] = F.N[NODE_W * f + k];
        }
        seg_from_nodes(&L, 1, sat);
    }
}

/* Rotation matrix (Q30) of the shortest turn from unit a to unit b:
 * q = (a x b, 1 + a.b) normalized (fixed: halved so w fits int32). */
static void turn(const sn_q a[3], const sn_q b[3], sn_q R[9], uint32_t *sat) {
    sn_q q[4];
#if defined(SN_FLOAT)
    (void)sat;
    q[0] = a[1] * b[2] - a[2] * b[1];
    q[1] = a[2] * b[0] - a[0] * b[2];
    q[2] = a[0] * b[1] - a[1] * b[0];
    q[3] = 1.0f + a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
#else
    int64_t w = ((int64_t)1 << 60) + (int64_t)a[0] * b[0] + (int64_t)a[1] * b[1] + (int64_t)a[2] * b[2];
    /* (a x b)/2: each component <= 2^61 in Q60 -> 2^29 in Q30, beyond the
     * state clamp (a turn of more than 30 degrees would count): no sn_out */
    (void)sat;
    q[0] = (sn_q)sn_rshr64(sn_mul_sub(a[1], b[2], a[2], b[1]), SN_Q_ROT + 1);
    q[1] = (sn_q)sn_rshr64(sn_mul_sub(a[2], b[0], a[0], b[2]), SN_Q_ROT + 1);
    q[2] = (sn_q)sn_rshr64(sn_mul_sub(a[0], b[1], a[1], b[0]), SN_Q_ROT + 1);
    w = sn_rshr64(w < 0 ? 0 : w, SN_Q_ROT + 1); /* (1 + a.b)/2 in [0, 2^30] */
    q[3] = (sn_q)w;
#endif
    sn_qnormalize(q); /* opposite directions (q = 0): identity */
    sn_qtomat(q, R);
}

/* Fine level l-1 from solved level l. A fine node between two coarse nodes
 * (in a row or a column) keeps its offset h from their midpoint, turned by
 * the coarse segment's rotation during the level's step (fig. 4.8); a node
 * at a cell centre keeps its offset from the mean of the cell's 4 corners,
 * turned by the rotation of the cell's first-row segment; a fine node on a
 * coarse node takes its new position. Then the fine segments are rebuilt. */
void seg_prolong(const seg_mesh *M, unsigned l, uint32_t *sat) {
    seg_lvl C, F;
    uint32_t n, pass;
    unsigned k;
    seg_level(M, l, &C);
    seg_level(M, l - 1, &F);
    for (pass = 0; pass < 2; pass++) /* odd nodes first: they read the old even ones */
        for (n = 0; n < F.nn; n++) {
            uint32_t r = n / F.side, c = n % F.side, R0 = r >> 1, C0 = c >> 1, sc = C.side, j;
            sn_acc s0[3] = {0, 0, 0}, s1[3] = {0, 0, 0};
            uint32_t fn[4], cn[4], cnt = 0;
            sn_q Rm[9], h[3], hr[3];
            const sn_q *Sc;
            int odd = (int)((r | c) & 1u);
#if !defined(SN_FLOAT)
            int cs = 1; /* set in the first loop; some optimisation levels cannot tell */
#endif
            if (!odd) {
                if (pass == 1)
                    for (k = 0; k < 3; k++) F.N[NODE_W * n + k] = C.N[NODE_W * (R0 * sc + C0) + k];
                continue;
            }
            if (pass == 1) continue;
            if (!(r & 1u)) { /* in a row: coarse segment H(R0, C0) */
                fn[0] = n - 1u; fn[1] = n + 1u; cn[0] = R0 * sc + C0; cn[1] = cn[0] + 1u; cnt = 2;
                Sc = C.S + SEG_W * (R0 * (sc - 1u) + C0);
            } else if (!(c & 1u)) { /* in a column: V(R0, C0) */
                fn[0] = n - F.side; fn[1] = n + F.side; cn[0] = R0 * sc + C0; cn[1] = cn[0] + sc; cnt = 2;
                Sc = C.S + SEG_W * (sc * (sc - 1u) + R0 * sc + C0);
            } else { /* cell centre: corners, turned with H(R0, C0) */
                fn[0] = n - F.side - 1u; fn[1] = n - F.side + 1u; fn[2] = n + F.side - 1u; fn[3] = n + F.side + 1u;
                cn[0] = R0 * sc + C0; cn[1] = cn[0] + 1u; cn[2] = cn[0] + sc; cn[3] = cn[2] + 1u; cnt = 4;
                Sc = C.S + SEG_W * (R0 * (sc - 1u) + C0);
            }
            for (j = 0; j < cnt; j++)
                for (k = 0; k < 3; k++) { s0[k] += F.N[NODE_W * fn[j] + k]; s1[k] += C.N[NODE_W * cn[j] + k]; }
            turn(Sc + 9, Sc + 3, Rm, sat); /* the level's start direction (w words) to its solution */
            for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
                h[k] = F.N[NODE_W * n + k] - s0[k] / (float)cnt;
#else
                cs = cnt == 2 ? 1 : 2;
                h[k] = sn_add(F.N[NODE_W * n + k], -sn_out(s0[k], cs, sat), sat);
#endif
            }
            sn_rot(Rm, h, hr, sat);
            for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
                F.N[NODE_W * n + k] = sn_add(s1[k] / (float)cnt, hr[k], sat);
#else
                F.N[NODE_W * n + k] = sn_add(sn_out(s1[k], cs, sat), hr[k], sat);
#endif
            }
        }
    seg_from_nodes(&F, 0, sat);
}
