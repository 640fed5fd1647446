/* sn_contact.c -- the game's colliders (plane, sphere, capsule) as one-sided
 * velocity constraints on the surface, like seed 003 eq. 9 against a moving
 * world solid: n . v_point >= n . v_solid - gap, enforced through the rows
 * of sn_constraint.c (runtime/NUMERICS.md "Constraints and contact").
 *
 * Active set (decided before the solve, once per step): surface vertex s
 * touches collider c when it is inside (gap g < 0), or when its predicted
 * motion, its velocity at the start of the step plus gravity's increment,
 * would end inside: g + n . (v_pred - v_c) < 0. An active contact is
 * enforced as the equality n . v = n . v_c - g (it lands on the surface;
 * a vertex inside is pushed out by at most an eighth of a cell per step).
 * Vertices the bones carry (their cell's free corners' squared weights sum
 * below 2^-8) take no contact: no velocity of the flesh can hold them.
 * A contact yields to the bones (ct_yield): it asks its cell's free corners
 * for no more than a velocity change of cell/2 and an end point cell/2
 * beyond their skinned place along n (minimum-norm share), so a vertex the
 * skeleton drives through a collider is left behind, not fought.
 * One contact per (collider, dominant free corner: the cell's free corner
 * with the largest weight): the vertex with the smallest g + n . (v_pred -
 * v_c) (rows of several contacts over one corner's three unknowns are
 * nearly dependent and leave no room for friction). Up to max_contacts per
 * step, in surface-vertex order; more are counted in contact_overflow.
 * After the CG, sn_contact_yield keeps the bound on the combined solve.
 *
 * Friction (mu > 0; a velocity-level Coulomb rule decided before the
 * solve, NUMERICS.md): after every normal contact is collected, each
 * contact of a collider with mu > 0 compares its predicted tangential slip
 * relative to the solid, s = (v_pred - u) - n n.(v_pred - u), with mu times
 * the contact's pressure, the normal velocity change it asks before the
 * yield bound or its push-out depth, whichever is larger (a contact the
 * bones hold in stays pressed).
 * |s| <= mu dn: it sticks (two tangential rows: it moves with the solid);
 * else it slides, its slip reduced by mu dn (one row along s). Friction
 * rows share the contacts' baked rows (max_contacts), after the normal ones.
 */
#include "sn_constraint.h"
#include "sn_cut.h" /* sn_point_weights: the cut level's field */
#include "sn_kernels_surf.h" /* sn_k_ct8: the plain lattice's point */
/* 1: the plain lattice's exact point by sn_k_ct8 in lanes (the scalar
 * builds keep ct_sum: sn_k_ct8_ref there cost 0.13 M more a cow step) */
#if defined(SN_KERNELS_AVX2) || defined(SN_KERNELS_FAVX2)
#define SN_CT_LANES 1
#else
#define SN_CT_LANES 0
#endif

typedef struct sn_col {
    uint32_t kind;
    sn_real a[3], b[3];  /* public units, world */
    sn_real radius;      /* public units */
    sn_real vel[3];      /* public units per second */
    sn_real mu;          /* Q16.16 / float */
    sn_q n[3];           /* plane: unit outward normal, Q30 */
} sn_col;
typedef char sn_col_fits_[sizeof(sn_col) <= SN_COL_BYTES ? 1 : -1];

#if defined(SN_FLOAT)
#define CT_ONE30 1.0f
#define SN_LIM_OR_BIG 1.0e30f
#else
#define CT_ONE30 ((int32_t)1 << 30)
#define SN_LIM_OR_BIG SN_LIM
#endif

/* world public point -> internal (relative to the origin) */
static sn_q ct_to_int(const sn_ihdr *h, sn_real p, sn_real o, uint32_t *sat) {
#if defined(SN_FLOAT)
    (void)sat;
    return pub_to_int(h, p - o);
#else
    return pub_to_int_sat(h, (int64_t)p - o, sat);
#endif
}

/* a unit vector (Q30) along d (Q22 internal); *len = |d| (Q22). d = 0: +y. */
static void ct_unit(const sn_q d[3], sn_q n[3], sn_q *len) {
#if defined(SN_FLOAT)
    float l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    int c;
    if (!(l2 > 1e-20f)) { n[0] = 0; n[1] = 1.0f; n[2] = 0; *len = 0; return; }
    {
        float il = sn_frsqrt(l2);
        for (c = 0; c < 3; c++) n[c] = d[c] * il;
        *len = l2 * il;
    }
#else
    int64_t l2 = 0;
    uint32_t l;
    int c;
    for (c = 0; c < 3; c++) l2 += (int64_t)d[c] * d[c]; /* |d| <= 2^29.6: < 2^59.2 */
    l = sn_isqrt64((uint64_t)l2);
    *len = (int32_t)(l > (uint32_t)SN_LIM ? (uint32_t)SN_LIM : l);
    if (l == 0) { n[0] = 0; n[1] = CT_ONE30; n[2] = 0; return; }
    for (c = 0; c < 3; c++) {
        int64_t num = (int64_t)d[c] * ((int64_t)1 << 30); /* < 2^59 */
        uint64_t q = sn_udiv64((uint64_t)(num < 0 ? -num : num) + (l >> 1), l);
        n[c] = (int32_t)(num < 0 ? -(int64_t)q : (int64_t)q);
    }
#endif
}

/* gap g (Q22) and outward normal n (Q30) of internal point P against a
 * collider given internally (A, B, R); 0 when P is far: farther than
 * reach beyond the surface (no contact possible this step). */
static int ct_gap(const sn_col *cl, const sn_q A[3], const sn_q B[3], sn_q R, const sn_q P[3], sn_q reach,
                  sn_q *g, sn_q n[3], uint32_t *sat) {
    sn_q d[3], C[3], len;
    int c;
    if (cl->kind == SN_COLLIDER_PLANE) {
        sn_acc s = 0;
        for (c = 0; c < 3; c++) s += sn_mul(cl->n[c], sn_add(P[c], -A[c], sat));
        *g = sn_out(s, 30, sat);
        for (c = 0; c < 3; c++) n[c] = cl->n[c];
        return *g <= reach;
    }
    for (c = 0; c < 3; c++) C[c] = A[c];
    if (cl->kind == SN_COLLIDER_CAPSULE) { /* closest point of the axis */
        sn_q ab[3], ap[3];
        sn_acc dt = 0, ab2 = 0;
        for (c = 0; c < 3; c++) {
            ab[c] = sn_add(B[c], -A[c], sat);
            ap[c] = sn_add(P[c], -A[c], sat);
            dt += sn_mul(ab[c], ap[c]);
            ab2 += sn_mul(ab[c], ab[c]);
        }
        if (dt >= ab2) for (c = 0; c < 3; c++) C[c] = B[c];
        else if (dt > 0) {
#if defined(SN_FLOAT)
            float t = dt / ab2;
            for (c = 0; c < 3; c++) C[c] = A[c] + t * ab[c];
#else
            int sh = bitlen64((uint64_t)ab2) - 32;
            uint64_t num, den, t;
            sh = sh < 0 ? 0 : sh;
            num = (uint64_t)dt >> sh;
            den = (uint64_t)ab2 >> sh;
            t = den ? sn_udiv64(num << 30, den) : 0; /* Q30, <= 2^30 */
            for (c = 0; c < 3; c++) C[c] = sn_add(A[c], sn_mulq((int32_t)t, ab[c], 30, sat), sat);
#endif
        }
    }
    for (c = 0; c < 3; c++) d[c] = sn_add(P[c], -C[c], sat);
    {   /* far: |d| > R + reach, tested on squares before any root */
        sn_acc d2 = sn_mul(d[0], d[0]) + sn_mul(d[1], d[1]) + sn_mul(d[2], d[2]);
        sn_acc rr = (sn_acc)R + (sn_acc)(reach > 0 ? reach : 0);
        if (d2 > rr * rr) return 0;
    }
    ct_unit(d, n, &len);
    *g = sn_add(len, -R, sat);
    return 1;
}

/* Vertex a's predicted velocity (free: v + h^2 g; skeleton: v) and start
 * point (free: pos; skeleton: pos - v, where it was), component q: from
 * ct_predict's arrays when they hold (vpre, pst not NULL), else summed here
 * with the per-use clamp count. */
SN_INLINE sn_q ct_vel(const sn_ihdr *h, const sn_q *vpre, uint32_t a, uint32_t q, uint32_t *sat) {
    const sn_q *vel = CARR(h, o_vel, sn_q);
    if (a >= h->v.nF) return vel[3 * a + q];
    return vpre ? vpre[3 * a + q] : sn_add(vel[3 * a + q], h->v.grav[q], sat);
}
SN_INLINE sn_q ct_start(const sn_ihdr *h, const sn_q *pst, uint32_t a, uint32_t q, uint32_t *sat) {
    const sn_q *pos = CARR(h, o_pos, sn_q);
    if (a < h->v.nF) return pos[3 * a + q];
    return pst ? pst[3 * (a - h->v.nF) + q] : sn_add(pos[3 * a + q], -CARR(h, o_vel, sn_q)[3 * a + q], sat);
}

static void friction_rows(sn_ihdr *h, uint32_t first, uint32_t end, const sn_q V[][3], const sn_q *vpre, uint32_t *sat);

static int ct_gap(const sn_col *cl, const sn_q A[3], const sn_q B[3], sn_q R, const sn_q P[3], sn_q reach, sn_q *g, sn_q n[3], uint32_t *sat);
SN_INLINE void ct_sum(uint32_t nF, const sn_q *pos, const sn_q *pst, const sn_q *vel, const sn_q *vpre, const uint16_t *vx,
                      const sn_q *phi, uint32_t ne, sn_acc sp[3], sn_acc sv[3]);
/* The cut level's prefilter (exact: it drops only vertices sn_contact_rows
 * would drop): a vertex's cut point and predicted velocity differ from its
 * cell's trilinear ones by at most the step's largest extra deviations Dp,
 * Dv (sn_cut_dev: phi' >= 0 sums to one), so its gap by <= sqrt 3 Dp and
 * its reach (a 1-norm) by <= 3 Dv. 0: no collider within the trilinear
 * point's reach + margin (2 Dp + 3 Dv + cell/64 for the roundings), the
 * vertex can take no contact. Its own clamp count (the real pass counts). */
static int ct_near(const sn_ihdr *h, const sn_col *cols, const sn_q A[][3], const sn_q B[][3], const sn_q *R, const sn_q V[][3],
                   const uint16_t vx[8], const uint32_t t[3], const sn_q *pst, const sn_q *vpre, sn_q margin) {
    const sn_q *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q);
    sn_acc sp[3] = {0, 0, 0}, sv[3] = {0, 0, 0};
    sn_q phi[8], P[3], Vp[3], g, n[3];
    uint32_t c, q, ds = 0;
    sn_trilinear(t, phi);
    ct_sum(h->v.nF, pos, pst, vel, vpre, vx, phi, 8u, sp, sv);
    for (q = 0; q < 3; q++) { P[q] = sn_out(sp[q], 30, &ds); Vp[q] = sn_out(sv[q], 30, &ds); }
    for (c = 0; c < h->n_col; c++) {
        sn_acc r = margin;
        for (q = 0; q < 3; q++) {
            sn_q rel = sn_add(Vp[q], -V[c][q], &ds);
            r += rel < 0 ? -(sn_acc)rel : (sn_acc)rel;
        }
        if (!(r < (sn_acc)SN_LIM)) return 1; /* too far out to bound: the real test decides */
        if (ct_gap(cols + c, A[c], B[c], R[c], P, (sn_q)r, &g, n, &ds)) return 1;
    }
    return 0;
}

/* sp += sum phi_k p_k (start points), sv += sum phi_k v_k (predicted velocities) over ne entries, from
 * ct_predict's arrays; inlined with ne = 8 for the plain lattice (its loop unrolled as before the cut level) */
SN_INLINE void ct_sum(uint32_t nF, const sn_q *pos, const sn_q *pst, const sn_q *vel, const sn_q *vpre, const uint16_t *vx,
                      const sn_q *phi, uint32_t ne, sn_acc sp[3], sn_acc sv[3]) {
    uint32_t k;
    for (k = 0; k < ne; k++) {
        const uint32_t a = vx[k];
        const sn_q *pp = a < nF ? pos + 3 * a : pst + 3 * (a - nF), *vv = a < nF ? vpre + 3 * a : vel + 3 * a;
        sp[0] += sn_mul(phi[k], pp[0]); sp[1] += sn_mul(phi[k], pp[1]); sp[2] += sn_mul(phi[k], pp[2]);
        sv[0] += sn_mul(phi[k], vv[0]); sv[1] += sn_mul(phi[k], vv[1]); sv[2] += sn_mul(phi[k], vv[2]);
    }
}

/* The yield bound (NUMERICS.md "Contacts"): the most normal velocity change
 * a contact row may ask of its point so that no free corner of its cell
 * changes its velocity by more than cell/2 this step or ends more than
 * cell/2 beyond its skinned position along n (the bones' place for it).
 * The row's minimum-norm free change moves corner a by phi_a dn / S2
 * (S2 = sum of the free phi^2), so dn <= S2 min_a room_a / phi_a with
 * room_a = min(cell/2, cell/2 - n.(p_a + v_a + g^ - skin_a)). Skeleton
 * corners are the bones' own: the row never moves them. Returns the bound
 * (<= 0: no room, no row). Q22; S2 Q60 (fixed). */
static sn_q ct_yield(sn_ihdr *h, const uint16_t *vx, const sn_q *phi, uint32_t ne, const sn_q n[3], sn_acc S2, const sn_q *vp,
                     uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *pos = CARR(h, o_pos, sn_q);
    const sn_q dv = (sn_q)(v->cell / 2), dmax = (sn_q)(v->cell / 2);
    sn_q m = SN_LIM_OR_BIG;
    uint32_t k, q;
    for (k = 0; k < ne; k++) {
        uint32_t a = vx[k];
        sn_q sk[3], dev, room, ratio;
        sn_acc d = 0;
        if (a >= v->nF || !(phi[k] > 0)) continue;
        sn_skinned(h, a, sk, sat);
        for (q = 0; q < 3; q++)
            d += sn_mul(n[q], sn_add(sn_add(pos[3 * a + q], ct_vel(h, vp, a, q, sat), sat), -sk[q], sat));
        dev = sn_out(d, 30, sat);
        room = sn_add(dmax, -dev, sat);
        if (room > dv) room = dv;
        if (!(room > 0)) return 0;
#if defined(SN_FLOAT)
        ratio = room / phi[k];
#else
        {   /* room (Q22) / phi (Q30) in Q22, at most the state range */
            uint64_t t = sn_udiv64((uint64_t)room << 30, (uint64_t)phi[k]);
            ratio = t > (uint64_t)SN_LIM ? SN_LIM : (sn_q)t;
        }
#endif
        if (ratio < m) m = ratio;
    }
#if defined(SN_FLOAT)
    return S2 * m;
#else
    return sn_out(sn_mul((sn_q)(S2 >> 30), m), 30, sat); /* S2 <= 2^60: Q30 <= 2^30 */
#endif
}

/* the free corner with the largest weight (first on ties); SN_NO_DOM: not yet */
#define SN_NO_DOM 0xFFFFFFFFu
static uint32_t ct_dom(const uint16_t *vx16, const sn_q *phi, uint32_t ne, uint32_t nF) {
    uint32_t k, best = 0xFFFFu;
    sn_q m = 0;
    for (k = 0; k < ne; k++)
        if (vx16[k] < nF && phi[k] > m) { m = phi[k]; best = vx16[k]; }
    return best;
}

/* The step's start point and predicted velocity of every lattice vertex,
 * once a step instead of once per surface vertex using it as a corner (~8):
 * free vertices' v + h^2 g into q's storage (nF rows), skeleton vertices'
 * pos - v (where they were) into d's (nDS >= nV - nF rows); both are dead
 * between sn_rhs and the PCG (sn_instance.c). Returns 1 when no sum
 * saturated: the arrays then stand for the per-use sums, whose saturation
 * counts were all 0; else 0 and the callers compute per use as before (the
 * same counts; a state that far out is rare). */
static int ct_predict(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q);
    sn_q *vp = ARR(h, o_q, sn_q), *ps = ARR(h, o_d, sn_q);
    uint32_t a, q, s0 = 0;
    for (a = 0; a < 3 * v->nF; a += 3)
        for (q = 0; q < 3; q++) vp[a + q] = sn_add(vel[a + q], v->grav[q], &s0);
    for (; a < 3 * v->nV; a++) ps[a - 3 * v->nF] = sn_add(pos[a], -vel[a], &s0);
    (void)sat;
    return s0 == 0;
}

void sn_contact_rows(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_col *cols = CARR(h, o_col, sn_col);
    const sn_q *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q);
    sn_rowx *rx = WARR(h, o_rx, sn_rowx);
    sn_row *rows = sn_rows(h);
    sn_q A[SN_MAX_COLLIDERS][3], B[SN_MAX_COLLIDERS][3], R[SN_MAX_COLLIDERS], V[SN_MAX_COLLIDERS][3];
    sn_q cap = (sn_q)(v->cell / 8);
    const sn_q *pst, *vpre; /* ct_predict's (vpre NULL: not holding) */
    uint32_t c, s, k, first = h->n_rows, ncol = h->n_col;
    uint32_t q;
    sn_q margin = 0;
    int exact;
    if (ncol == 0) return;
    for (c = 0; c < ncol; c++) { /* the solids at the start of the step, internal units; velocity per step */
        const sn_col *cl = cols + c;
        for (q = 0; q < 3; q++) {
            A[c][q] = ct_to_int(h, cl->a[q], h->origin[q], sat);
            B[c][q] = cl->kind == SN_COLLIDER_CAPSULE ? ct_to_int(h, cl->b[q], h->origin[q], sat) : 0; /* a plane's b is its normal */
#if defined(SN_FLOAT)
            V[c][q] = pub_to_int(h, cl->vel[q] * v->timestep);
#else
            V[c][q] = pub_to_int_sat(h, sn_rshr64((int64_t)cl->vel[q] * v->timestep, 16), sat);
#endif
        }
        R[c] = ct_to_int(h, cl->radius, 0, sat);
    }
    exact = ct_predict(h, sat);
#if defined(SN_CT_PER_USE) /* test build: always the per-use sums (tests/test_contact_per_use.c) */
    exact = 0;
#endif
    vpre = exact ? CARR(h, o_q, sn_q) : NULL;
    pst = CARR(h, o_d, sn_q);
    if (v->cut && exact) { /* the cut level's prefilter margin (ct_near) */
        sn_acc m = 2 * (sn_acc)sn_cut_dev(v, pos, pst) + 3 * (sn_acc)sn_cut_dev(v, vpre, vel + 3 * v->nF) + (sn_acc)(v->cell / 64);
        margin = m < (sn_acc)SN_LIM ? (sn_q)m : 0; /* 0: no prefilter (a state that far out is rare) */
    }
    for (s = 0; s < v->nS; s++) {
        const unsigned char *e = v->sec[SN_SEC_EMBED] + (size_t)s * SN_ELEM_EMBED;
        const unsigned char *cell = v->sec[SN_SEC_CELLS] + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
        uint32_t t[3], dom = SN_NO_DOM, anyf = 0, ne = 8;
        uint16_t vx[8], cvx[SN_CUT_POINT_MAX];
        sn_q phi[8], cw[SN_CUT_POINT_MAX], P[3], Vp[3];
        const uint16_t *X = vx; /* the row's entries: the cell's corners, or (cut level) cvx: the corners, then the extras of the child */
        const sn_q *W = phi;
        sn_acc sp[3] = {0, 0, 0}, sv[3] = {0, 0, 0}, fw = 0;
        for (k = 0; k < 8; k++) {
            vx[k] = (uint16_t)sn_rd_u16(cell + 2 * k);
            anyf |= vx[k] < v->nF;
        }
        if (!anyf) continue; /* no free corner (fw = 0): the bones carry it, whatever t */
        for (k = 0; k < 3; k++) t[k] = sn_rd_u16(e + 2 + 2 * k);
        if (margin > 0 && !ct_near(h, cols, (const sn_q (*)[3])A, (const sn_q (*)[3])B, R, (const sn_q (*)[3])V, vx, t, pst, vpre, margin))
            continue; /* beyond every collider's reach, whatever the extras: the weights below not needed */
        if (v->cut) { /* the rendered point's field (extras: skeleton entries) */
            ne = sn_point_weights(v, sn_rd_u16(e), t, cvx, cw);
            X = cvx;
            W = cw;
        } else if (SN_CT_LANES && exact) /* AVX2: weights, fw and both sums in one kernel, in lanes (sn_kernels_surf.h) */
            sn_k_ct8(t, vx, v->nF, pos, pst, vel, vpre, phi, &fw, sp, sv);
        else
            sn_trilinear(t, phi);
        /* a vertex the bones carry (its row's squared length over free
         * corners below 2^-8: sn_constraint.c would drop it) takes no contact */
        if (!(SN_CT_LANES && exact && !v->cut))
            for (k = 0; k < 8; k++) /* the free vertices are corners */
                if (X[k] < v->nF) fw += sn_mul(W[k], W[k]);
#if defined(SN_FLOAT)
        if (fw < 1.0f / 256.0f) continue;
#else
        if (fw < (int64_t)1 << 52) continue; /* 2^-8 in Q60 */
#endif
        /* the point at the start of the step (skeleton corners where they
         * were) and its predicted velocity (free corners: v + h^2 g) */
        if (SN_CT_LANES && exact && !v->cut)
            ; /* sp, sv from sn_k_ct8 above */
        else if (exact && !v->cut) /* the hot loop: each corner's two rows read straight from the arrays (8: unrolled) */
            ct_sum(v->nF, pos, pst, vel, vpre, vx, phi, 8u, sp, sv);
        else if (exact)
            ct_sum(v->nF, pos, pst, vel, vpre, X, W, ne, sp, sv);
        else
            for (k = 0; k < ne; k++)
                for (q = 0; q < 3; q++) {
                    sp[q] += sn_mul(W[k], ct_start(h, NULL, X[k], q, sat));
                    sv[q] += sn_mul(W[k], ct_vel(h, NULL, X[k], q, sat));
                }
        for (q = 0; q < 3; q++) {
            P[q] = sn_out(sp[q], 30, sat);
            Vp[q] = sn_out(sv[q], 30, sat);
        }
        for (c = 0; c < ncol; c++) {
            sn_q g, n[3], rel[3], reach, vr, score, vcn, target, want, dn, lim;
            uint32_t j;
            for (q = 0; q < 3; q++) rel[q] = sn_add(Vp[q], -V[c][q], sat);
            /* |rel| <= its 1-norm: how far the point can come this step */
#if defined(SN_FLOAT)
            reach = (rel[0] < 0 ? -rel[0] : rel[0]) + (rel[1] < 0 ? -rel[1] : rel[1]) + (rel[2] < 0 ? -rel[2] : rel[2]);
#else
            reach = clamp32((int64_t)(rel[0] < 0 ? -(int64_t)rel[0] : rel[0]) + (rel[1] < 0 ? -(int64_t)rel[1] : rel[1]) +
                            (rel[2] < 0 ? -(int64_t)rel[2] : rel[2]));
#endif
            if (!ct_gap(cols + c, A[c], B[c], R[c], P, reach, &g, n, sat)) continue;
            vr = sn_out(sn_mul(n[0], rel[0]) + sn_mul(n[1], rel[1]) + sn_mul(n[2], rel[2]), 30, sat);
            score = sn_add(g, vr, sat);
            if (!(score < 0) && !(g < 0)) continue;
            /* what the contact wants relative to the solid: approach by at
             * most g (outside), move out by min(-g, cap) (inside); dn, the
             * normal velocity change beyond the prediction it asks of the
             * flesh, at most the yield bound (bone-aware: ct_yield) */
            want = g >= 0 ? (sn_q)-g : (-g > cap ? cap : (sn_q)-g);
            dn = sn_add(want, -vr, sat);
            vcn = sn_out(sn_mul(n[0], V[c][0]) + sn_mul(n[1], V[c][1]) + sn_mul(n[2], V[c][2]), 30, sat);
            target = sn_add(vcn, want, sat);
            if (dn > 0) {
                lim = ct_yield(h, X, W, ne, n, fw, vpre, sat);
                if (!(lim > 0)) continue; /* the free corners are already as far out as the bound lets them: no row */
                if (dn > lim) {           /* yield: ask only what the free corners can give within the bound */
                    target = sn_add(sn_add(vcn, vr, sat), lim, sat);
                    h->con_clamps = sn_count(h->con_clamps, 1);
                }
            }
            /* one contact per (collider, dominant free corner): rows on one
             * corner's three unknowns from several contacts are nearly
             * dependent (their normals 30-60 deg apart) and leave no room for
             * the contact's friction rows */
            if (dom == SN_NO_DOM) dom = ct_dom(X, W, ne, v->nF); /* once a vertex, and only for a contact */
            for (j = first; j < h->n_rows; j++) /* every row since first is a contact's (one-sided) */
                if (rows[j].source == SN_ROW_SRC(SN_SRC_CONTACT, c) && (uint32_t)rx[j].a == dom) break;
            if (j < h->n_rows && !(score < rx[j].spare)) continue;
            if (j == h->n_rows && h->contacts >= v->nCt) {
                h->contact_overflow = sn_count(h->contact_overflow, 1);
                continue;
            }
            {
                sn_row r;
                memset(&r, 0, sizeof r);
                r.n = (uint8_t)ne;
                for (k = 0; k < ne; k++) { r.vtx[k] = X[k]; r.w[k] = W[k]; }
                for (q = 0; q < 3; q++) r.dir[q] = n[q];
                r.target = target;
                r.one_sided = 1;
                r.source = SN_ROW_SRC(SN_SRC_CONTACT, c);
                if (j < h->n_rows) rows[j] = r;
                else if (sn_rows_push(h, &r)) h->contacts++;
                else continue;
                rx[j].spare = score;
                rx[j].a = (sn_q)dom; /* the row's dominant corner (collection scratch: rows_factor sets a) */
                rx[j].s = dn > want ? dn : want; /* friction's pressure: the normal change asked before the yield, or the push-out depth (scratch until the factorization) */
            }
        }
    }
    friction_rows(h, first, h->n_rows, (const sn_q (*)[3])V, vpre, sat);
}

/* one tangential row of contact row r along t (Q30) with target t.u + extra */
static void push_tangent(sn_ihdr *h, const sn_row *r, const sn_q t[3], const sn_q u[3], sn_q extra, uint32_t *sat) {
    sn_row f = *r;
    uint32_t q;
    for (q = 0; q < 3; q++) f.dir[q] = t[q];
    f.target = sn_add(sn_out(sn_mul(t[0], u[0]) + sn_mul(t[1], u[1]) + sn_mul(t[2], u[2]), 30, sat), extra, sat);
    f.one_sided = 0;
    if (sn_rows_push(h, &f)) h->contacts++;
}
/* a x b for unit vectors (Q30, |.| <= 1: beyond the state clamp, rounded without it) */
static void cross30(const sn_q a[3], const sn_q b[3], sn_q o[3], uint32_t *sat) {
#if defined(SN_FLOAT)
    (void)sat;
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
#else
    (void)sat;
    o[0] = clamp32(sn_rshr64(sn_mul(a[1], b[2]) + sn_mul(-a[2], b[1]), 30));
    o[1] = clamp32(sn_rshr64(sn_mul(a[2], b[0]) + sn_mul(-a[0], b[2]), 30));
    o[2] = clamp32(sn_rshr64(sn_mul(a[0], b[1]) + sn_mul(-a[1], b[0]), 30));
#endif
}

/* Friction rows for the normal contacts rows[first .. end) (see the top). */
static void friction_rows(sn_ihdr *h, uint32_t first, uint32_t end, const sn_q V[][3], const sn_q *vpre, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_col *cols = CARR(h, o_col, sn_col);
    const sn_rowx *rx = CWARR(h, o_rx, sn_rowx);
    uint32_t j, k, q;
    for (j = first; j < end; j++) {
        sn_row r = sn_rows(h)[j];
        uint32_t c = r.source & 0xFFu;
        const sn_col *cl = cols + c;
        sn_acc sv[3] = {0, 0, 0};
        sn_q vp[3], rel[3], s[3], t1[3], t2[3], slen, dn, vn, limit;
#if defined(SN_FLOAT)
        if (!(cl->mu > 0.0f)) continue;
#else
        if (cl->mu <= 0) continue;
#endif
        if (h->contacts + 1u > v->nCt) { h->contact_overflow = sn_count(h->contact_overflow, 1); continue; }
        for (k = 0; k < r.n; k++)
            for (q = 0; q < 3; q++) sv[q] += sn_mul(r.w[k], ct_vel(h, vpre, r.vtx[k], q, sat));
        for (q = 0; q < 3; q++) {
            vp[q] = sn_out(sv[q], 30, sat);
            rel[q] = sn_add(vp[q], -V[c][q], sat);
        }
        vn = sn_out(sn_mul(r.dir[0], vp[0]) + sn_mul(r.dir[1], vp[1]) + sn_mul(r.dir[2], vp[2]), 30, sat);
        dn = sn_add(r.target, -vn, sat); /* the normal velocity change the contact imposes */
        if (rx[j].s > dn) dn = rx[j].s; /* or would ask without the yield (the pressure the bones take) */
        if (!(dn > 0)) continue;
        {
            sn_q rn = sn_out(sn_mul(r.dir[0], rel[0]) + sn_mul(r.dir[1], rel[1]) + sn_mul(r.dir[2], rel[2]), 30, sat);
            for (q = 0; q < 3; q++) s[q] = sn_add(rel[q], -sn_mulq(r.dir[q], rn, 30, sat), sat);
        }
#if defined(SN_FLOAT)
        limit = cl->mu * dn;
#else
        limit = sn_out((int64_t)cl->mu * dn, 16, sat); /* mu Q16.16 */
#endif
        ct_unit(s, t1, &slen);
#if defined(SN_FLOAT)
        if (!(slen > 1e-6f)) {
#else
        if (slen < 16) { /* no slip to speak of: any tangent pair */
#endif
            sn_q e[3] = {0, 0, 0};
            e[(r.dir[0] < 0 ? -r.dir[0] : r.dir[0]) < CT_ONE30 / 2 ? 0 : 1] = CT_ONE30;
            cross30(r.dir, e, s, sat);
            ct_unit(s, t1, &slen);
            slen = 0;
        }
        if (!(slen > limit)) { /* stick: both tangents move with the solid */
            cross30(r.dir, t1, t2, sat);
            if (h->contacts + 2u > v->nCt) { h->contact_overflow = sn_count(h->contact_overflow, 1); continue; }
            push_tangent(h, &r, t1, V[c], 0, sat);
            push_tangent(h, &r, t2, V[c], 0, sat);
        } else /* slide: the slip along t1, reduced by mu dn */
            push_tangent(h, &r, t1, V[c], sn_add(slen, -limit, sat), sat);
    }
}

/* The yield bound kept by the combined solve (NUMERICS.md "Friction"):
 * ct_yield bounds each row as if it were alone; rows sharing a free corner
 * (normals 30-60 deg apart, tangent rows beside a neighbour's normal) move
 * it 1/sin(angle) times further. After the CG, along each kept contact
 * row's direction (normal or tangent), each free corner of the row ends at
 * most B = max(cell/2, |dir . (pos_a - skin_a)|) from its skinned place: a
 * slab, so the press along n does not use up the drag's budget, and never
 * further out than the corner starts the step (a corner the bound holds
 * stays held: releasing it is the relay). A corner beyond is moved back
 * onto the slab (x_a -= excess dir) and each contact row's required value
 * follows the change of c_j^T x, so the rows hold as stated (the bones
 * win). The fixes after it keep the other rows. Cost: the contact rows'
 * entries (at most SN_ROW_MAX_ENT each), two row products a row. */
void sn_contact_yield(sn_ihdr *h, sn_q *x, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_row *rows = sn_rows(h);
    const sn_q *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q);
    sn_rowx *rx = WARR(h, o_rx, sn_rowx);
    const sn_q half = (sn_q)(v->cell / 2);
    uint32_t j, k, q, m = h->n_rows;
#define CT_MINE(j) (SN_ROW_PRODUCER(rows[j].source) == SN_SRC_CONTACT && rx[j].inv != 0)
    for (j = 0; j < m; j++) rx[j].s = CT_MINE(j) ? sn_row_dot(h, rows + j, x, sat) : 0;
    for (j = 0; j < m; j++) {
        if (!CT_MINE(j)) continue;
        for (k = 0; k < rows[j].n; k++) {
            uint32_t a = rows[j].vtx[k];
            const sn_q *n = rows[j].dir;
            sn_q sk[3], d0[3], d[3], e0, e, b;
            if (a >= v->nF || rows[j].w[k] == 0) continue;
            sn_skinned(h, a, sk, sat);
            for (q = 0; q < 3; q++) {
                d0[q] = sn_add(pos[3 * a + q], -sk[q], sat);
                d[q] = sn_add(sn_add(d0[q], vel[3 * a + q], sat), x[3 * a + q], sat);
            }
            e0 = sn_out(sn_mul(n[0], d0[0]) + sn_mul(n[1], d0[1]) + sn_mul(n[2], d0[2]), 30, sat);
            e = sn_out(sn_mul(n[0], d[0]) + sn_mul(n[1], d[1]) + sn_mul(n[2], d[2]), 30, sat);
            if (e0 < 0) e0 = (sn_q)-e0;
            b = e0 > half ? e0 : half;
            if (e > b) e = sn_add(e, -b, sat);
            else if (e < -b) e = sn_add(e, b, sat);
            else continue;
            for (q = 0; q < 3; q++) /* back onto the slab |dir . d| <= b */
                x[3 * a + q] = sn_add(x[3 * a + q], -sn_mulq(n[q], e, 30, sat), sat);
            h->con_clamps = sn_count(h->con_clamps, 1);
        }
    }
    for (j = 0; j < m; j++)
        if (CT_MINE(j)) rx[j].a = sn_add(rx[j].a, sn_add(sn_row_dot(h, rows + j, x, sat), -rx[j].s, sat), sat);
#undef CT_MINE
}

/* ---- public API ---- */
#if defined(SN_FLOAT)
static int ct_fin(float x) { return x >= -1.0e9f && x <= 1.0e9f; }
#endif

sn_status sn_set_colliders(sn_instance *inst, const sn_collider *list, uint32_t count) {
    sn_ihdr *h;
    sn_col *cs;
    uint32_t i, n;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    if (count && !list) return SN_ERR_NULL;
    n = count < h->v.nCol ? count : h->v.nCol;
    for (i = 0; i < n; i++) {
        const sn_collider *q = list + i;
        if (q->kind > SN_COLLIDER_CAPSULE || q->radius < 0 || q->friction < 0) return SN_ERR_ARG;
        if (q->kind == SN_COLLIDER_PLANE && q->b.x == 0 && q->b.y == 0 && q->b.z == 0) return SN_ERR_ARG;
#if defined(SN_FLOAT)
        if (!ct_fin(q->a.x) || !ct_fin(q->a.y) || !ct_fin(q->a.z) || !ct_fin(q->b.x) || !ct_fin(q->b.y) || !ct_fin(q->b.z) ||
            !ct_fin(q->radius) || !ct_fin(q->velocity.x) || !ct_fin(q->velocity.y) || !ct_fin(q->velocity.z) || !ct_fin(q->friction))
            return SN_ERR_ARG;
#endif
    }
    cs = ARR(h, o_col, sn_col);
    for (i = 0; i < n; i++) {
        const sn_collider *q = list + i;
        sn_col *cl = cs + i;
        memset(cl, 0, sizeof *cl);
        cl->kind = q->kind;
        cl->a[0] = q->a.x; cl->a[1] = q->a.y; cl->a[2] = q->a.z;
        cl->b[0] = q->b.x; cl->b[1] = q->b.y; cl->b[2] = q->b.z;
        cl->radius = q->radius;
        cl->vel[0] = q->velocity.x; cl->vel[1] = q->velocity.y; cl->vel[2] = q->velocity.z;
        cl->mu = q->friction;
        if (q->kind == SN_COLLIDER_PLANE) {
            sn_q d[3], len;
#if defined(SN_FLOAT)
            d[0] = q->b.x; d[1] = q->b.y; d[2] = q->b.z;
            {   /* scale into a safe range before squaring */
                float m = 0.0f;
                int c;
                for (c = 0; c < 3; c++) m = (d[c] < 0 ? -d[c] : d[c]) > m ? (d[c] < 0 ? -d[c] : d[c]) : m;
                for (c = 0; c < 3; c++) d[c] /= m;
            }
#else
            /* Q16.16 normal scaled so its largest component has 28 bits */
            int64_t m = 0;
            int c, b;
            const int32_t nb[3] = {q->b.x, q->b.y, q->b.z};
            for (c = 0; c < 3; c++) m |= nb[c] < 0 ? -(int64_t)nb[c] : nb[c];
            b = bitlen64((uint64_t)m) - 28;
            for (c = 0; c < 3; c++) d[c] = (int32_t)(b > 0 ? sn_rshr64(nb[c], b) : (int64_t)nb[c] * ((int64_t)1 << -b));
#endif
            ct_unit(d, cl->n, &len);
            (void)len;
        }
    }
    h->n_col = n;
    if (count > n) {
        h->con_refused = sn_count(h->con_refused, count - n);
        return SN_ERR_FULL;
    }
    return SN_OK;
}
