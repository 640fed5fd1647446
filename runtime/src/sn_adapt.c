/* sn_adapt.c -- adaptation on level 1 (seed 000 §4.7; runtime/LEVELS.md §3).
 *
 * Level 1's free vertices that lie at no level-0 vertex (a LEVEL_UP entry
 * with some t strictly inside (0, 1)) are the detail vertices: each carries
 * the one finer function of the hierarchical basis (seed 000 §3.1). The
 * coarse field is the level-1 field sampled at the level-0 vertices
 * (LEVEL_DOWN) and interpolated back (LEVEL_UP); a detail vertex's detail is
 * its position minus that, max-norm, internal units. An inactive vertex has
 * a zero detail coefficient: its position and velocity are the coarse
 * field's (exact, LEVELS.md §3), and the step's solve takes it as a
 * prescribed value (dv = 0, like the skeleton of seed 000 eq. 17-18) while
 * the CG and the preconditioner run over the others (sn_solve.c's mask).
 *
 * After the step: an active vertex stays while its detail is >= coarsen; an
 * inactive one joins when the detail it would take is >= refine, estimated
 * by the preconditioner applied to the step's residual on the inactive rows
 * (the displacement one relaxation of its own equation would give: its rhs
 * row is the force left at the coarse position). At most A_max are active:
 * the largest keys win, ties by index (a threshold found by bisection over
 * the 32-bit keys, then one ordered pass). Then the inactive ones are
 * projected again, so the surface between active regions is the coarse
 * field's.
 *
 * Cost per step, fixed by the blob: one preconditioner application, the
 * sampling 8 (nV0 + nF1) weighted sums of 3 x 2 values, at most 33 nF1
 * compares for the selection; the solve is the plain one minus the inactive
 * corners. Storage: sn_adapt_state, the mask (nF1 bytes) and the
 * preconditioner's scales (4 nF1 bytes, recomputed with the mask) after the
 * instance's layout (sn_instance_size counts them); the rest reuses the step's dead arrays: keys in acc,
 * samples in d and q (nV0 <= nF1, validated). */
#include "sn_adapt.h"

/* the top blob's view (level 0, holding ADAPT and the maps) */
static void top_view(const sn_ihdr *h, sn_view *t) { sn_view_init(t, (const sn_blob *)(const void *)h->lod_base); }

sn_status sn_check_adapt(const sn_view *top, const sn_view *fine) {
    const unsigned char *r;
    if (sn_level_sec_count(top, SN_SEC_ADAPT) == 0) return SN_OK;
    if (!fine) return SN_ERR_SECTION; /* one level, or a nested blob: nothing to adapt */
    r = top->sec[SN_SEC_ADAPT];
    if (sn_rd_u16(r + 2) != 0 || sn_rd_u32(r + 4) != 0) return SN_ERR_VALUE;
    if (sn_rd_u16(r) > fine->nF || top->nV > fine->nF) return SN_ERR_VALUE; /* A_max; samples fit level 1's free arrays */
    if (!sn_real_ok(r + 8, 0, SN_ADAPT_MAX, SN_Q_LEN) || !sn_real_ok(r + 8 + RB, 0, SN_ADAPT_MAX, SN_Q_LEN)) return SN_ERR_VALUE;
    if (SN_RD_REAL(r + 8 + RB) > SN_RD_REAL(r + 8)) return SN_ERR_VALUE; /* coarsen <= refine */
    { /* every level-0 vertex is a level-1 vertex (LEVEL_DOWN at a cell corner): the coarse field's sources */
        uint32_t i, k;
        for (i = 0; i < top->nV; i++)
            for (k = 1; k < 4; k++) {
                uint32_t tq = sn_rd_u16(top->sec[SN_SEC_LEVEL_DOWN] + (size_t)i * SN_ELEM_LEVEL_MAP + 2 * k);
                if (tq != 0 && tq != 32768u) return SN_ERR_VALUE;
            }
    }
    return SN_OK;
}

uint32_t sn_adapt_bytes(const sn_view *top) {
    sn_view f;
    if (sn_level_sec_count(top, SN_SEC_ADAPT) == 0) return 0;
    sn_view_init(&f, (const sn_blob *)(const void *)top->sec[SN_SEC_LEVEL_BLOB]);
    return (SN_ADAPT_STATE_BYTES + ((f.nF + 3u) & ~3u) + 4u * f.nF + 7u) & ~7u; /* state, mask, scales */
}

static uint8_t *mask_of(const sn_ihdr *h) { return (uint8_t *)(sn_ad(h) + 1); }
/* the preconditioner's scales per level-1 free vertex, after the mask (4-aligned) */
static sn_q *scales_of(const sn_ihdr *h) { return (sn_q *)(void *)(mask_of(h) + ((sn_ad(h)->n + 3u) & ~3u)); }

/* max-norm of a - b (fixed: |a|, |b| <= 2^31: the difference in int64, < 2^32) */
SN_INLINE uint32_t dist_key(const sn_q *a, const sn_q *b) {
    uint32_t k, m = 0;
    for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
        uint32_t u = sn_key_of(a[k] - b[k]);
#else
        int64_t d = (int64_t)a[k] - b[k];
        uint32_t u = (uint32_t)(d < 0 ? -d : d);
#endif
        m = u > m ? u : m;
    }
    return m > 0x7FFFFFFFu ? 0x7FFFFFFFu : m; /* bit 31 marks the incumbents (choose) */
}

void sn_adapt_init(sn_ihdr *h) {
    sn_view t;
    const unsigned char *r;
    top_view(h, &t);
    h->ad_bytes = sn_adapt_bytes(&t);
    if (!h->ad_bytes) return;
    memset(sn_ad(h), 0, SN_ADAPT_STATE_BYTES);
    sn_ad(h)->on = 1;
    r = t.sec[SN_SEC_ADAPT];
    sn_ad(h)->max = sn_rd_u16(r);
    sn_ad(h)->refine = sn_key_of(SN_RD_REAL(r + 8));
    sn_ad(h)->coarsen = sn_key_of(SN_RD_REAL(r + 8 + RB));
    {
        sn_view f;
        sn_view_init(&f, (const sn_blob *)(const void *)t.sec[SN_SEC_LEVEL_BLOB]);
        sn_ad(h)->n = f.nF;
    }
}

static int running(const sn_ihdr *h) { return h->ad_bytes && sn_ad(h)->on && h->lod == 1u; }

const uint8_t *sn_adapt_mask(const sn_ihdr *h) {
    if (!running(h) || h->mode == SN_MODE_BLENDED || sn_ad(h)->inactive == 0) return NULL;
    return mask_of(h);
}

/* a level-1 vertex at no level-0 vertex: some coordinate strictly inside its level-0 cell */
SN_INLINE int is_detail(const unsigned char *up, uint32_t i) {
    const unsigned char *e = up + (size_t)i * SN_ELEM_LEVEL_MAP;
    uint32_t k;
    for (k = 1; k < 4; k++) {
        uint32_t t = sn_rd_u16(e + 2 * k);
        if (t != 0 && t != 32768u) return 1;
    }
    return 0;
}

/* value at map entry e over the corners of a cell of `cells` (sn_set_lod's interpolation) */
static void interp(const unsigned char *e, const unsigned char *cells, const sn_q *val, sn_q out[3], uint32_t *sat) {
    const unsigned char *cell = cells + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
    uint32_t t[3], a, k;
    sn_q phi[8];
    sn_acc acc[3] = {0, 0, 0};
    for (k = 0; k < 3; k++) t[k] = sn_rd_u16(e + 2 + 2 * k);
    sn_trilinear(t, phi);
    for (a = 0; a < 8; a++) {
        const sn_q *s = val + 3 * (size_t)sn_rd_u16(cell + 2 * a);
        for (k = 0; k < 3; k++) acc[k] += sn_mul(phi[a], s[k]);
    }
    for (k = 0; k < 3; k++) out[k] = sn_out(acc[k], SN_Q_ROT, sat); /* convex weights: never clamps */
}

/* the level-1 field val (nV1 vertices) sampled at the level-0 vertices into s */
static void sample(const sn_ihdr *h, const sn_view *t, const sn_q *val, sn_q *s, uint32_t *sat) {
    const unsigned char *down = t->sec[SN_SEC_LEVEL_DOWN], *cells = h->v.sec[SN_SEC_CELLS];
    uint32_t i;
    for (i = 0; i < t->nV; i++) interp(down + (size_t)i * SN_ELEM_LEVEL_MAP, cells, val, s + 3 * i, sat);
}

/* level-1 vertex at level-0 vertex v0 (LEVEL_DOWN at a corner of a level-1 cell: validated) */
SN_INLINE uint32_t fine_of(const unsigned char *down, const unsigned char *cells1, uint32_t v0) {
    const unsigned char *e = down + (size_t)v0 * SN_ELEM_LEVEL_MAP;
    uint32_t corner = (sn_rd_u16(e + 2) ? 1u : 0u) | (sn_rd_u16(e + 4) ? 2u : 0u) | (sn_rd_u16(e + 6) ? 4u : 0u);
    return sn_rd_u16(cells1 + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS + 2 * corner);
}

/* w's 8 interpolation sources: level-1 vertex c[a] (>= nF: skeleton) and weight phi[a] (Q30) */
static void sources(const sn_ihdr *h, const sn_view *t, uint32_t w, uint32_t c[8], sn_q phi[8]) {
    const unsigned char *e = t->sec[SN_SEC_LEVEL_UP] + (size_t)w * SN_ELEM_LEVEL_MAP;
    const unsigned char *cell = t->sec[SN_SEC_CELLS] + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
    uint32_t tt[3], a;
    for (a = 0; a < 3; a++) tt[a] = sn_rd_u16(e + 2 + 2 * a);
    sn_trilinear(tt, phi);
    for (a = 0; a < 8; a++) c[a] = fine_of(t->sec[SN_SEC_LEVEL_DOWN], h->v.sec[SN_SEC_CELLS], sn_rd_u16(cell + 2 * a));
}

/* A detail vertex may leave the solve when every level-0 corner with a weight
 * at it is exactly a level-1 vertex (LEVEL_DOWN at a cell corner whose
 * LEVEL_UP is that level-0 vertex again): then its coarse value is a
 * combination of vertices that never leave, and P below is the hierarchical
 * basis' (seed 000 §3.1). Level-0 corners outside level 1's lattice (air
 * corners, clamped by the maps) make the others stay in. */
static int eligible(const sn_ihdr *h, const sn_view *t, uint32_t w) {
    const unsigned char *up = t->sec[SN_SEC_LEVEL_UP], *cells0 = t->sec[SN_SEC_CELLS];
    uint32_t c[8], a;
    sn_q phi[8];
    if (!is_detail(up, w)) return 0;
    sources(h, t, w, c, phi);
    for (a = 0; a < 8; a++) {
        const unsigned char *e = up + (size_t)c[a] * SN_ELEM_LEVEL_MAP, *cell = cells0 + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
        uint32_t v0 = sn_rd_u16(cells0 + (size_t)sn_rd_u16(up + (size_t)w * SN_ELEM_LEVEL_MAP) * SN_ELEM_CELLS + 2 * a), corner;
        if (phi[a] == 0) continue;
        if (is_detail(up, c[a])) return 0;
        corner = (sn_rd_u16(e + 2) ? 1u : 0u) | (sn_rd_u16(e + 4) ? 2u : 0u) | (sn_rd_u16(e + 6) ? 4u : 0u);
        if (sn_rd_u16(cell + 2 * corner) != v0) return 0;
    }
    return 1;
}

/* new activity from the keys (NULL: all 0, and nothing counts as active
 * before: the first selection), events counted; returns the active count */
/* Fixed point: a source row of the reduced system also carries its inactive
 * vertices' forces (restrict), so it takes the smallest force exponent
 * among them (k_c = min(k_c, k_w): the stiffer vertex's range, sn_k_table's
 * rule); the plain table otherwise (all active: the plain step's bits). */
static void k_reduced(sn_ihdr *h, const sn_view *t) {
    uint8_t *kk = ARR(h, o_k, uint8_t);
    const uint8_t *m = mask_of(h);
    uint32_t w, a, c[8], nF = h->v.nF;
    sn_q phi[8];
    sn_k_table(h);
    for (w = 0; w < sn_ad(h)->n; w++) {
        if (m[w]) continue;
        sources(h, t, w, c, phi);
        for (a = 0; a < 8; a++)
            if (c[a] < nF && phi[a] != 0 && kk[w] < kk[c[a]]) kk[c[a]] = kk[w];
    }
}

/* fixed: the masses summed in units of 2^5 (each |m| <= 2^27, validated -> 2^22; on a baked
 * lattice a source takes itself and at most 26 inactive neighbours with sum phi <= 7: < 2^26).
 * A hostile blob's LEVEL_UP may send every level-1 vertex to one cell (up to 2^16 terms, 2^38):
 * the sum saturates at the int32 range there instead of overflowing; float: as they are
 * (< 2^43, finite) */
#if defined(SN_FLOAT)
#define M_SH(x, s) (x)
SN_INLINE sn_q m_add(sn_q a, sn_q b) { return a + b; }
#else
#define M_SH(x, s) ((sn_q)sn_rshr64((x), (s)))
SN_INLINE sn_q m_add(sn_q a, sn_q b) {
    int64_t t = (int64_t)a + b;
    return (sn_q)(t > INT32_MAX ? INT32_MAX : (t < INT32_MIN ? INT32_MIN : t));
}
#endif
/* The reduced operator's preconditioner scales (NUMERICS.md "Adaptation"). A
 * source row c of P^T A P carries its inactive vertices' functions: its lumped
 * mass is (P^T m)_c = m_c + sum_w phi_wc m_w (MLUMP), where the masked IC(0)
 * is the lattice's at m_c. On the beast a source at a cut cell has m_c
 * hundreds of times below what it carries (diagonal ratio up to 760): the
 * masked IC(0) oversteps there and the PCG stalls (16 iterations left rz
 * within 10x of its start; divergence through the swing). Stiffness scales
 * with the same cut volume, so s_c = sqrt(m_c / (P^T m)_c) in (0, 1] and
 * z = S C S r (SPD) restores the diagonal's scale; s = 1 where no inactive
 * vertex folds in. Cost 8 per inactive vertex + nF square roots, bounded by
 * the blob, run whenever the mask changes (k_reduced's places, also outside
 * a step: no workspace scratch, the sums are kept in the scales' array). */
static void scales(sn_ihdr *h, const sn_view *t) {
    const unsigned char *ml = h->v.sec[SN_SEC_MLUMP];
    const uint8_t *m = mask_of(h);
    sn_q *M = scales_of(h), phi[8]; /* first (P^T m)_c, then the scales in place */
    uint32_t w, a, c[8], n = sn_ad(h)->n, nF = h->v.nF;
    for (w = 0; w < n; w++) M[w] = M_SH(rd_real(ml, w), 5);
    for (w = 0; w < n; w++) {
        if (m[w]) continue;
        sources(h, t, w, c, phi);
        for (a = 0; a < 8; a++) /* Q30 x m rounded to M's units (sum bound above) */
            if (c[a] < nF) M[c[a]] = m_add(M[c[a]], M_SH(sn_mul(phi[a], rd_real(ml, w)), SN_Q_ROT + 5));
    }
    for (w = 0; w < n; w++) {
        sn_q mw = M_SH(rd_real(ml, w), 5);
#if defined(SN_FLOAT)
        M[w] = (mw > 0.0f && M[w] > mw) ? sn_frsqrt(M[w] / mw) : 1.0f; /* sqrt(m / M) */
#else
        if (mw > 0 && M[w] > mw) { /* q = m / M in Q30, s = sqrt(q 2^30) in Q30, < 2^30 */
            uint64_t q = ((uint64_t)mw << 30) / (uint64_t)M[w];
            M[w] = (sn_q)sn_isqrt64(q << 30);
        } else M[w] = SN_ONE_ROT;
#endif
    }
}

const sn_q *sn_adapt_scales(const sn_ihdr *h) { return scales_of(h); }

/* The smallest T with at most max of the wanted entries (bit 1 of m[i]) keyed
 * above it: 32 halvings of [0, 2^32), each one pass (key NULL: all 0). Shared
 * by level 1's adaptation (choose) and the details' (sn_detail_adapt.c). */
uint32_t sn_select_threshold(const uint8_t *m, const uint32_t *key, uint32_t n, uint32_t max) {
    uint32_t lo = 0, hi = 0xFFFFFFFFu, i;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2u, c = 0;
        for (i = 0; i < n; i++) c += (m[i] >> 1) & (uint32_t)((key ? key[i] : 0u) > mid);
        if (c <= max) hi = mid; else lo = mid + 1u;
    }
    return lo;
}

static void choose(sn_ihdr *h, uint32_t *key, int fresh) {
    uint8_t *m = mask_of(h);
    uint32_t i, n = sn_ad(h)->n, want = 0, above, room, act = 0, T = 0;
    for (i = 0; i < n; i++) {
        uint32_t was, k = key ? key[i] : 0u;
        if (m[i] & 0x40u) continue; /* not eligible: always in */
        was = fresh ? 0u : (m[i] & 1u);
        m[i] = (uint8_t)(was | (k >= (was ? sn_ad(h)->coarsen : sn_ad(h)->refine) ? 2u : 0u));
        want += m[i] >> 1;
        /* the vertices in the solve keep their seats before any newcomer (keys < 2^31): without
         * it an estimate and a measured detail would trade seats every step (a pop each time) */
        if (key && was) key[i] |= 0x80000000u;
    }
    if (want > sn_ad(h)->max) { /* the smallest T with at most A_max wanted keys above it */
        sn_ad(h)->overflow = sn_count(sn_ad(h)->overflow, want - sn_ad(h)->max);
        T = sn_select_threshold(m, key, n, sn_ad(h)->max);
    }
    for (i = 0, above = 0; i < n; i++) above += (m[i] >> 1) & (uint32_t)((key ? key[i] : 0u) > T);
    room = sn_ad(h)->max - (above < sn_ad(h)->max ? above : sn_ad(h)->max);
    for (i = 0; i < n; i++) {
        uint32_t k = key ? key[i] : 0u, take, was;
        if (m[i] & 0x40u) continue;
        take = 0;
        if (m[i] >> 1) {
            if (want <= sn_ad(h)->max || k > T) take = 1;
            else if (k == T && room) { take = 1; room--; }
        }
        was = m[i] & 1u;
        if (take && !was && !fresh) sn_ad(h)->refines = sn_count(sn_ad(h)->refines, 1);
        if (!take && was) sn_ad(h)->coarsens = sn_count(sn_ad(h)->coarsens, 1);
        m[i] = (uint8_t)take;
        act += take;
    }
    sn_ad(h)->active = act;
    sn_ad(h)->inactive = 0;
    for (i = 0; i < n; i++) sn_ad(h)->inactive += m[i] == 0;
}

/* inactive detail vertices onto the coarse field: positions and velocities
 * (samples of both in ps, vs), warm start 0 */
static void project(sn_ihdr *h, const sn_view *t, const sn_q *ps, const sn_q *vs, uint32_t *sat) {
    const unsigned char *up = t->sec[SN_SEC_LEVEL_UP], *cells = t->sec[SN_SEC_CELLS];
    const uint8_t *m = mask_of(h);
    sn_q *pos = ARR(h, o_pos, sn_q), *vel = ARR(h, o_vel, sn_q), *x = ARR(h, o_x, sn_q);
    uint32_t i;
    for (i = 0; i < sn_ad(h)->n; i++) {
        const unsigned char *e = up + (size_t)i * SN_ELEM_LEVEL_MAP;
        if (m[i]) continue;
        interp(e, cells, ps, pos + 3 * i, sat);
        interp(e, cells, vs, vel + 3 * i, sat);
        x[3 * i] = x[3 * i + 1] = x[3 * i + 2] = 0;
    }
}

void sn_adapt_begin(sn_ihdr *h, uint32_t *sat) {
    sn_view t;
    uint8_t *m;
    uint32_t i;
    if (!h->ad_bytes) return;
    m = mask_of(h);
    sn_ad(h)->active = sn_ad(h)->inactive = 0;
    if (!running(h)) { /* every vertex in the solve */
        for (i = 0; i < sn_ad(h)->n; i++) m[i] = 1;
        if (h->lod == 1u) sn_k_table(h);
        return;
    }
    top_view(h, &t);
    for (i = 0; i < sn_ad(h)->n; i++) m[i] = eligible(h, &t, i) ? 0u : 0x41u; /* 0x41: in the solve for good */
    choose(h, NULL, 1);
    k_reduced(h, &t);
    scales(h, &t);
    if (sn_ad(h)->inactive) {
        sn_q *ps = ARR(h, o_d, sn_q), *vs = ARR(h, o_q, sn_q);
        sample(h, &t, CARR(h, o_pos, sn_q), ps, sat);
        sample(h, &t, CARR(h, o_vel, sn_q), vs, sat);
        project(h, &t, ps, vs, sat);
    }
}

void sn_adapt_expand(sn_ihdr *h, const uint8_t *mask, sn_q *v, uint32_t *sat) {
    sn_view t;
    uint32_t w, a, k, c[8], nF = h->v.nF;
    sn_q phi[8];
    top_view(h, &t);
    for (w = 0; w < sn_ad(h)->n; w++) {
        sn_acc acc[3] = {0, 0, 0};
        if (mask[w]) continue;
        sources(h, &t, w, c, phi);
        for (a = 0; a < 8; a++)
            if (c[a] < nF)
                for (k = 0; k < 3; k++) acc[k] += sn_mul(phi[a], v[3 * c[a] + k]);
        for (k = 0; k < 3; k++) v[3 * w + k] = sn_out(acc[k], SN_Q_ROT, sat); /* convex: never clamps */
    }
}

void sn_adapt_restrict(sn_ihdr *h, const uint8_t *mask, sn_q *v, uint32_t *sat) {
    sn_view t;
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t w, a, k, c[8], nF = h->v.nF;
    sn_q phi[8];
    top_view(h, &t);
    for (w = 0; w < sn_ad(h)->n; w++) {
        if (mask[w]) continue;
        sources(h, &t, w, c, phi);
        for (a = 0; a < 8; a++) {
            if (c[a] >= nF || phi[a] == 0) continue;
            /* Q30 x Q(19 + k_w) -> Q(19 + k_c): shift 30 + k_w - k_c in [15, 45] (fixed) */
            for (k = 0; k < 3; k++)
                v[3 * c[a] + k] = sn_add(v[3 * c[a] + k], sn_out(sn_mul(phi[a], v[3 * w + k]), SN_Q_ROT + SN_KREL(kk[w]) - SN_KREL(kk[c[a]]), sat), sat);
        }
        v[3 * w] = v[3 * w + 1] = v[3 * w + 2] = 0;
    }
    (void)kk;
}

void sn_adapt_estimate(sn_ihdr *h, const uint8_t *mask, const sn_q *r, sn_q *z, sn_q *x, uint32_t *sat) {
    static const sn_q zero[3] = {0, 0, 0};
    uint32_t w;
    sn_precond_mask(h, mask, 1, NULL, r, z, sat);
    for (w = 0; w < sn_ad(h)->n; w++) {
        if (mask[w]) continue;
#if defined(SN_FLOAT)
        {
            sn_q m = 0;
            uint32_t k;
            for (k = 0; k < 3; k++) {
                sn_q a = z[3 * w + k] < 0 ? -z[3 * w + k] : z[3 * w + k];
                m = a > m ? a : m;
            }
            x[3 * w] = m < SN_FLIM ? m : SN_FLIM; /* a state value: the CG's x += 0 d keeps it */
        }
#else
        {
            uint32_t u = dist_key(z + 3 * w, zero);
            x[3 * w] = u < (uint32_t)SN_LIM ? (sn_q)u : SN_LIM; /* within the state range: x += 0 d keeps it, no clamp */
        }
#endif
        x[3 * w + 1] = x[3 * w + 2] = 0;
    }
    (void)zero;
}

uint32_t sn_adapt_iterations(const sn_ihdr *h) {
    uint32_t it = h->iterations < SN_ADAPT_MIN_ITERATIONS ? SN_ADAPT_MIN_ITERATIONS : h->iterations;
    return it > h->v.cg_max ? h->v.cg_max : it;
}

void sn_adapt_keys(sn_ihdr *h, const uint8_t *mask, const sn_q *x) {
    uint32_t *key = WARR(h, o_acc, uint32_t), w;
    for (w = 0; w < sn_ad(h)->n; w++) key[w] = mask[w] ? 0u : sn_key_of(x[3 * w]);
    sn_ad(h)->keyed = 1;
}

void sn_adapt_step(sn_ihdr *h, uint32_t *sat) {
    sn_view t;
    const unsigned char *up, *cells;
    uint8_t *m;
    uint32_t *key, i;
    sn_q *ps, *vs;
    const sn_q *pos;
    if (!running(h) || h->mode == SN_MODE_BLENDED) return;
    top_view(h, &t);
    up = t.sec[SN_SEC_LEVEL_UP]; cells = t.sec[SN_SEC_CELLS];
    m = mask_of(h);
    key = WARR(h, o_acc, uint32_t); /* 24 nF bytes: the preconditioner's scratch is done with first */
    ps = ARR(h, o_d, sn_q); vs = ARR(h, o_q, sn_q);
    pos = CARR(h, o_pos, sn_q);
    /* inactive rows: the estimate the solve left in acc (sn_adapt_keys), or none (a step with rows) */
    if (!sn_ad(h)->keyed)
        for (i = 0; i < sn_ad(h)->n; i++) key[i] = 0;
    sn_ad(h)->keyed = 0;
    sample(h, &t, pos, ps, sat);
    sample(h, &t, CARR(h, o_vel, sn_q), vs, sat);
    for (i = 0; i < sn_ad(h)->n; i++) {
        sn_q c[3];
        if (m[i] != 1u) continue; /* active and eligible: its measured detail */
        interp(up + (size_t)i * SN_ELEM_LEVEL_MAP, cells, ps, c, sat);
        key[i] = dist_key(pos + 3 * i, c);
    }
    choose(h, key, 0);
    k_reduced(h, &t);
    scales(h, &t);
    if (sn_ad(h)->inactive) project(h, &t, ps, vs, sat);
}

const uint8_t *sn_adapt_mask_bytes(const sn_ihdr *h, uint32_t *n) {
    if (!h->ad_bytes) { *n = 0; return NULL; }
    *n = sn_ad(h)->n;
    return mask_of(h);
}
