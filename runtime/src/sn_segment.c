/* sn_segment.c -- segment meshes: chains and sheets of rigid segments joined
 * by displacement constraints (seed 004 ch. 3, Gascuel and Gascuel's method
 * as Palazzi applies it to surfaces), with the multilevel force distribution
 * of seed 004 ch. 4 on sheets (transfers in sn_segment_level.c). Model,
 * units and bounds: runtime/SEGMENTS.md.
 * This file: the dynamics, the velocities and the step's order; the sweeps
 * are sn_segment_sweep.c, records, topology, reset, teleport and hash
 * sn_segment_mesh.c.
 *
 * Step of one mesh (seed 004 fig. 3.1, fig. 4.3): restriction of positions
 * and impulses to the coarser levels; then from the coarsest level to the
 * finest: dynamics (damping, gravity and impulses by the level's share,
 * Euler-Cromer, seed 004 appendix A), a FIXED number of constraint sweeps
 * (no error-driven exit, unlike seed 004 fig. 3.8: `sweeps` on level 0,
 * `coarse_sweeps` on the coarser ones), velocities from the displacements,
 * prolongation to the next finer level. The sweeps' corrections may be
 * over-relaxed by omega = relax/32 (SOR on Palazzi's projection; omega 1
 * is seed 004 §3.2 as written; SEGMENTS.md).
 *
 * Cost per step, with S_l, N_l, E_l the segments, nodes and rod ends moved
 * at the nodes of level l (a pair 2, a star k), A the attachments, F = 1
 * if a floor is set, W_l the sweeps of level l (sweeps, coarse_sweeps for
 * l >= 1):
 *   sum_l [ c1 S_l + c2 N_l + W_l (c3 E_l + c4 A + F c5 2 S_l) ] + c6 N_0 levels
 * with constants c_i independent of the data: every loop runs over counts
 * fixed by the blob and the settings; no loop exits on a value.
 */
#include "sn_segment.h"

#if defined(SN_FLOAT)
#define THREE 3.0f
#else
#define THREE 3
#endif
/* A rotation angle from a lever: f c/half, with c (Q22) limited to +-half
 * and f a factor (fixed: f >> fs, |f >> fs| <= 3), the result limited to
 * +-ROT_MAX. Both limits are designed limiters of the small-angle update
 * (a turn of more than 0.25 rad per constraint or per step is not
 * followed), not overflows: not counted in sat. Fixed: |c| r <= 2^(b+30)
 * < 2^57, shift b - 1: the quotient c/half (Q30) <= 2^30; times |f| <= 2^31:
 * < 2^62 (before the shift fs). */
static sn_q lever(sn_q c, sn_q hl, sn_q r, int sh, sn_q f, int fs) {
    sn_q ck = c > hl ? hl : (c < -hl ? -hl : c);
#if defined(SN_FLOAT)
    sn_q t = ck * r * f;
    (void)sh; (void)fs;
#else
    /* the quotient (<= 2^30) as an int32 (NARROW: a 32 x 32 product with f
     * on a 32-bit target), its variable shift on the two words there
     * (sn_rshr64_var): the same value */
    int64_t t = sn_rshr64(MUL(NARROW(sn_rshr64_var((int64_t)ck * r, sh)), f), fs);
#endif
    return (sn_q)(t > ROT_MAX ? ROT_MAX : (t < -ROT_MAX ? -ROT_MAX : t));
}

/* u + theta x u (the dynamics' turn by w, |theta_k| <= ROT_MAX, limited by
 * the caller), brought back towards unit length by newton_unit. */
SN_INLINE void rotate_u(sn_q u[3], const sn_q t[3]) {
    sn_acc x[3];
    /* each term of t x u <= 2^58, a component <= 2^59 -> 2^29 in Q30 (beyond
     * the state clamp 2^28, so not through sn_out): u + t x u < 1.5 2^30 */
    x[0] = u[0] + shr30(sn_mul_sub(t[1], u[2], t[2], u[1]));
    x[1] = u[1] + shr30(sn_mul_sub(t[2], u[0], t[0], u[2]));
    x[2] = u[2] + shr30(sn_mul_sub(t[0], u[1], t[1], u[0]));
    newton_unit(x, u);
}

/* ---------------- dynamics and velocities ---------------- */

/* Level l's dynamics: save G, u (into v, w's words after the velocities are
 * read), damping, gravity and the node impulses (J at the centres' share
 * `centre`, the rest at the endpoints with torque), Euler-Cromer. */
static void dynamics(seg_ctx *C, const seg_lvl *L, sn_q inv_mass, uint32_t *sat) {
    const seg_mesh *M = C->M;
    sn_q g[3];
    uint32_t i, n, seg[5];
    int sgn[5];
    unsigned j, k, ne;
    for (k = 0; k < 3; k++)
        g[k] = (M->flags & SN_SEGF_NO_GRAVITY) ? 0 : sn_mulq(C->h->v.grav[k], M->share[L->l], SN_Q_ROT, sat);
    for (i = 0; i < L->ns; i++) { /* damping and gravity: v = keep v + g; w = keep w */
        sn_q *S = L->S + SEG_W * i;
        for (k = 0; k < 3; k++) {
            S[6 + k] = sn_add(sn_mulq(S[6 + k], M->keep, SN_Q_ROT, sat), g[k], sat);
            S[9 + k] = sn_mulq(S[9 + k], M->keep, SN_Q_ROT, sat);
        }
    }
    /* impulses: node J split evenly over its k ends; dv = J/k inv_mass
     * (an end force translates too); dw = s 6 inv_mass (u x J_end)/L
     * = s 3 (u x f)/half with f = (1 - centre) J/k inv_mass, the thin rod's
     * J = m L^2/12 about the perpendicular axes (seed 004 §3.2.2, app. A) */
    for (n = 0; n < L->nn; n++) {
        const sn_q *J = L->N + NODE_W * n + 3;
        sn_q f[3], fe[3];
        uint32_t ls = 0;
        ne = seg_node_ends(L, n, seg, sgn);
        /* f and fe are the node's, the same at each of its ends: formed once,
         * their clamps counted once per end as when formed per end */
        for (k = 0; k < 3; k++) {
            f[k] = sn_mulq(mean_k(J[k], ne, &ls), inv_mass, 16, &ls);
            fe[k] = sn_add(f[k], -sn_mulq(f[k], M->centre, SN_Q_ROT, &ls), &ls);
        }
        *sat += ls * ne;
        for (j = 0; j < ne; j++) {
            sn_q *S = L->S + SEG_W * seg[j], c[3];
            sn_q rr;
            int rs;
            sn_q hl = seg_half(L, seg[j], &rr, &rs);
            for (k = 0; k < 3; k++) S[6 + k] = sn_add(S[6 + k], f[k], sat);
            c[0] = sn_out(sn_mul_sub(S[4], fe[2], S[5], fe[1]), SN_Q_ROT, sat);
            c[1] = sn_out(sn_mul_sub(S[5], fe[0], S[3], fe[2]), SN_Q_ROT, sat);
            c[2] = sn_out(sn_mul_sub(S[3], fe[1], S[4], fe[0]), SN_Q_ROT, sat);
            for (k = 0; k < 3; k++) { /* 3 (u x f)/half, limited to 0.25 rad/step */
                sn_q dw = lever(c[k], hl, rr, rs, THREE, 0);
#if defined(SN_FLOAT)
                S[9 + k] = sn_add(S[9 + k], sgn[j] > 0 ? dw : -dw, sat);
#else
                /* w is Q30 rad/step and ROT_MAX = SN_LIM: a sum beyond it is
                 * the designed 0.25 rad/step cap (float applies it below), not
                 * an overflow, so it is not counted in sat; same value */
                int64_t w = (int64_t)S[9 + k] + (sgn[j] > 0 ? dw : -dw);
                S[9 + k] = (sn_q)(w > ROT_MAX ? ROT_MAX : (w < -ROT_MAX ? -ROT_MAX : w));
#endif
            }
        }
    }
    for (i = 0; i < L->ns; i++) { /* Euler-Cromer: G += v; u turned by w; save the start */
        sn_q *S = L->S + SEG_W * i, G0[3], u0[3], w[3];
        for (k = 0; k < 3; k++) {
            G0[k] = S[k];
            u0[k] = S[3 + k];
            S[k] = sn_add(S[k], S[6 + k], sat);
            /* |w_k| <= 0.25 rad (fixed: already, the state clamp is 2^28) */
            w[k] = S[9 + k] > ROT_MAX ? ROT_MAX : (S[9 + k] < -ROT_MAX ? -ROT_MAX : S[9 + k]);
        }
        rotate_u(S + 3, w);
        for (k = 0; k < 3; k++) { S[6 + k] = G0[k]; S[9 + k] = u0[k]; }
    }
}

/* A Q60 product sum (|.| <= 2^61) to Q30 limited to +-ROT_MAX: the
 * per-step rotation cap, a designed limiter (not counted in sat). */
static sn_q rot_cap(sn_acc a) {
#if defined(SN_FLOAT)
    sn_q t = a;
#else
    int64_t t = sn_rshr64(a, SN_Q_ROT);
#endif
    return (sn_q)(t > ROT_MAX ? ROT_MAX : (t < -ROT_MAX ? -ROT_MAX : t));
}

/* Velocities from the displacements (seed 004 fig. 3.1 step 4):
 * v = G - G_start (exact: the sum of v changes only by external terms),
 * w = u_start x u (small angle), clamped to 0.25 rad per step. */
static void velocities(const seg_lvl *L, uint32_t *sat) {
    uint32_t i;
    unsigned k;
    for (i = 0; i < L->ns; i++) {
        sn_q *S = L->S + SEG_W * i, w[3];
        const sn_q *u0 = S + 9, *u = S + 3;
        w[0] = rot_cap(sn_mul_sub(u0[1], u[2], u0[2], u[1]));
        w[1] = rot_cap(sn_mul_sub(u0[2], u[0], u0[0], u[2]));
        w[2] = rot_cap(sn_mul_sub(u0[0], u[1], u0[1], u[0]));
        for (k = 0; k < 3; k++) {
            S[6 + k] = sn_add(S[k], -S[6 + k], sat);
            S[9 + k] = w[k];
        }
    }
}

static void ctx_init(seg_ctx *C, sn_ihdr *h, const seg_mesh *M, uint32_t *sat) {
    unsigned k;
    C->h = h;
    C->M = M;
#if defined(SN_FLOAT)
    {
        float om = (float)M->relax / 32.0f;
        C->gb = 0.5f * M->gamma;
        C->rfu = 1.0f - M->gamma;
        C->gh = C->gb * om;
        C->rf1 = C->rfu * om;
        C->rf2 = 0.5f * C->rf1;
        C->g1 = M->gamma * om;
    }
#else
    C->gb = M->gamma >> 1; /* gamma/2 rounded down: the pair's translation is t = d gamma/2 */
    C->rfu = ((int32_t)1 << 30) - M->gamma;
    /* relax <= 63, gamma <= 2^30: gamma relax < 2^36; the validator keeps
     * omega (1 - gamma) <= 1, so rf1 <= 2^30 and the turn factors keep
     * their bounds (seg_kf); omega gamma < 2^31 needs int64 (pin) */
    C->g1 = ((int64_t)M->gamma * M->relax) >> 5;
    C->gh = (sn_q)(((int64_t)M->gamma * M->relax) >> 6);
    C->rf1 = (sn_q)(((int64_t)C->rfu * M->relax) >> 5);
    C->rf2 = C->rf1 >> 1;
#endif
    C->g1n = NARROW(C->g1);
    (void)sat;
    C->floor_on = (int)h->floor_on;
    C->gap2 = 0;
    C->foff = 0;
    for (k = 0; k < 3; k++) C->fn[k] = h->floor_n[k];
    if (h->floor_on) { /* n.(origin + p) >= off  <=>  n.p >= off - n.origin */
#if defined(SN_FLOAT)
        float no = C->fn[0] * h->origin[0] + C->fn[1] * h->origin[1] + C->fn[2] * h->origin[2];
        C->foff = pub_to_int(h, h->floor_off - no);
#else
        int64_t no = sn_rshr64((int64_t)C->fn[0] * h->origin[0] + (int64_t)C->fn[1] * h->origin[1] +
                                   (int64_t)C->fn[2] * h->origin[2], SN_Q_ROT); /* |.| < 2^32.6 */
        C->foff = pub_to_int_sat(h, (int64_t)h->floor_off - no, sat);
#endif
    }
}

/* The mesh's node-impulse accumulators of every level to zero. */
static void clear_impulses(const seg_mesh *M) {
    uint32_t n;
    for (n = 0; n < M->nodes; n++) M->N[NODE_W * n + 3] = M->N[NODE_W * n + 4] = M->N[NODE_W * n + 5] = 0;
}

/* First step after init/reset: the rest mesh (model space) placed by the
 * transform of the joint of its first JOINT attachment (else the root),
 * as the skeleton's rest positions are (p = R_j x + T_j). */
static void place(sn_ihdr *h, const seg_mesh *M, uint32_t *sat) {
    const sn_q *jR = CARR(h, o_jR, sn_q), *jT = CARR(h, o_jT, sn_q);
    uint32_t j = 0, i;
    unsigned k;
    for (i = M->n_attach; i-- > 0;) {
        const unsigned char *rec = h->v.sec[SN_SEC_SEGATTACH] + (size_t)(M->first_attach + i) * ATT_REC;
        if (rec[2] == SN_SEGATT_JOINT) j = sn_rd_u16(rec + 4);
    }
    for (i = 0; i < M->segs; i++) {
        sn_q *S = M->S + SEG_W * i, x[3], y[3];
        memcpy(x, S, sizeof x);
        sn_rot(jR + 9 * j, x, S, sat);
        for (k = 0; k < 3; k++) S[k] = sn_add(S[k], jT[3 * j + k], sat);
        for (k = 0; k < 3; k++) x[k] = S[3 + k] / 4; /* Q28 (sn_rot clamps at 2^28), then unit again */
        sn_rot(jR + 9 * j, x, y, sat);
        seg_unit(y, S + 3);
    }
    for (i = 0; i < M->nodes; i++) {
        sn_q *N = M->N + NODE_W * i, x[3];
        memcpy(x, N, sizeof x);
        sn_rot(jR + 9 * j, x, N, sat);
        for (k = 0; k < 3; k++) N[k] = sn_add(N[k], jT[3 * j + k], sat);
    }
}

void sn_segments_step(sn_ihdr *h, uint32_t *sat) {
    uint32_t m, i, s;
    sn_q shift[3] = {0, 0, 0};
    sn_real gap = 0;
    unsigned k;
    if (h->v.nM == 0) return;
    /* the origin moved with the root since the last step: positions are kept
     * in the world by shifting them, as sn_frames shifts the flesh */
    for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
        shift[k] = h->seg_placed ? pub_to_int(h, h->origin[k] - h->seg_origin[k]) : 0;
#else
        shift[k] = h->seg_placed ? pub_to_int_sat(h, (int64_t)h->origin[k] - h->seg_origin[k], sat) : 0;
#endif
        h->seg_origin[k] = h->origin[k];
    }
    for (m = 0; m < h->v.nM; m++) {
        seg_mesh M;
        seg_ctx C;
        seg_lvl L;
        unsigned l;
        seg_mesh_get(h, m, &M);
        if (!h->seg_placed) place(h, &M, sat);
        for (i = 0; i < M.segs; i++)
            for (k = 0; k < 3; k++) M.S[SEG_W * i + k] = sn_add(M.S[SEG_W * i + k], -shift[k], sat);
        for (i = 0; i < M.nodes; i++)
            for (k = 0; k < 3; k++) M.N[NODE_W * i + k] = sn_add(M.N[NODE_W * i + k], -shift[k], sat);
        ctx_init(&C, h, &M, sat);
        for (i = 0; i < M.n_attach && i < SEG_TCACHE; i++) {
            C.Tsat[i] = 0;
            seg_attach_target(h, h->v.sec[SN_SEC_SEGATTACH] + (size_t)(M.first_attach + i) * ATT_REC, C.T[i], &C.Tsat[i]);
        }
        if (M.levels > 1) seg_restrict(&M, sat); /* positions and impulse shares of the coarse levels */
        else {
            seg_level(&M, 0, &L);
            for (i = 0; i < L.nn; i++) /* one level: share[0] is 1 (validated) */
                for (k = 0; k < 3; k++)
                    L.N[NODE_W * i + 3 + k] = sn_mulq(L.N[NODE_W * i + 3 + k], M.share[0], SN_Q_ROT, sat);
        }
        for (l = M.levels; l-- > 0;) {
            sn_q im;
            seg_level(&M, l, &L);
            {   /* equal total mass on every level (seed 004 §4.2.1): m_l = m_0 S_0 / S_l */
                seg_lvl L0;
                seg_level(&M, 0, &L0);
#if defined(SN_FLOAT)
                im = M.inv_mass * (float)L.ns / (float)L0.ns;
#else
                im = (sn_q)(((int64_t)M.inv_mass * L.ns) / L0.ns); /* S_l <= S_0: <= inv_mass */
                im = im < 1 ? 1 : im;
#endif
            }
            dynamics(&C, &L, im, sat);
            /* level 0 takes `sweeps`, the coarser ones `coarse_sweeps`: a
             * coarse level starts each step with its constraints met
             * (restriction), its sweeps only pin it and follow its dynamics */
            seg_sweep_prep(&C, &L);
            for (s = 0; s < (l ? M.coarse_sweeps : M.sweeps); s++) seg_sweep(&C, &L, 0, s & 1u, sat);
            seg_renormalize(&L); /* the Newton steps of the moves leave |u| within 2% of 1 */
            seg_node_means(&L, sat);
            if (l > 0) seg_prolong(&M, l, sat); /* reads this level's start (v, w words) */
            velocities(&L, sat);
        }
        seg_level(&M, 0, &L);
        seg_sweep_prep(&C, &L);
        seg_sweep(&C, &L, 1, 0, sat); /* measure the gaps left (no displacement) */
        {
            sn_real g = seg_gap(C.gap2, &L);
            gap = g > gap ? g : gap;
        }
        clear_impulses(&M);
    }
    h->seg_placed = 1;
    h->seg_gap = gap;
    h->seg_gap_max = gap > h->seg_gap_max ? gap : h->seg_gap_max;
}

