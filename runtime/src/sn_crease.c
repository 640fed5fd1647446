/* sn_crease.c -- self-collision near creases (seed 003 §3.4.2): the
 * collision list C (eq. 8) in instance memory, detection in the
 * neighbourhoods of the baked seed set D and of C, removal of pairs whose
 * vertex is back outside, the active prefix n_a, and one contact row per
 * active pair (eq. 9) for the constraint projection (sn_rows_push).
 * Model, formats and bounds: runtime/NUMERICS.md "Self-collision near creases".
 *
 * One step (called after the skeleton is posed, before the solve):
 *   0. the surface positions r_s of the surface vertices the step reaches
 *      (computed on first use, cr_pos) from the current
 *      lattice (free vertices: end of the last step; skeleton: this pose)
 *   1. maintenance: for each (i, T) in C, in order: r_i above T's plane
 *      ((r_i - r_b).n > 0, the paper's test): removed; projection slid off T
 *      (a barycentric < -1/4): moved to the triangle of the corner's
 *      neighbourhood it now lies under, kept in place (its time order), or
 *      removed; deeper than the baked depth: removed
 *   2. detection over P = D u N(C): for each seed (i, j), i against the
 *      triangles near j and j against those near i; for each (i, T) in C
 *      with corner p of T nearest b, every vertex near i against the
 *      triangles near p. A vertex enters C at most once (membership byte);
 *      C full: counted in cr_list_full, nothing written
 *   3. n_a: the smallest prefix such that every later pair separates at
 *      least at its target speed with the last step's velocities
 *      (chi_k = (v_i - v_b).n >= target_k); sn_crease_rows_push (called by
 *      the constraint projection's collection, sn_constrain_begin) pushes
 *      the rows of pairs k < n_a, at most max_active (the rest counted)
 *
 * Cost per step, with nS surface vertices, D seeds, L = max_list, Kv, Kt the
 * neighbourhood widths, A = max_active: c1 nS (clearing a byte; at most nS positions) + c2 L + Kt (2 D + L Kv) c3 +
 * L c4 + A c5, constants independent of the data (every loop bound is a
 * blob count or a baked maximum; a triangle test has no data-dependent loop).
 */
#include "sn_crease.h"
#include "sn_cut.h" /* sn_point_weights: the cut level's field */

/* ---------------- instance arrays (layout: SN_CREASE_STATE_BYTES) ---------------- */

static unsigned char *cr_base(const sn_ihdr *h) { return (unsigned char *)(uintptr_t)h + h->o_crs; }
static sn_q *cr_surf(const sn_ihdr *h) { return (sn_q *)(void *)cr_base(h); }
static sn_crease_pair *cr_pairs(const sn_ihdr *h) {
    return (sn_crease_pair *)(void *)(cr_base(h) + 12u * h->v.nS);
}
static uint8_t *cr_member(const sn_ihdr *h) { return cr_base(h) + 12u * h->v.nS + 8u * h->v.cr_list; }
static uint8_t *cr_fresh(const sn_ihdr *h) { return cr_base(h) + 13u * h->v.nS + 8u * h->v.cr_list; }

/* Surface position of vertex s this step (internal units), computed on first
 * use: the step needs only the vertices its searches reach (the rows' owners,
 * their neighbours and their triangles' corners), not all nS (format 6.0;
 * the same values as computing every one, at a cost bounded by nS). */
static const sn_q *cr_pos(const sn_ihdr *h, uint32_t s) {
    sn_q *S = cr_surf(h);
    uint8_t *f = cr_fresh(h);
    if (!f[s]) { sn_surface_point(h, s, S + 3u * s); f[s] = 1; }
    return S + 3u * s;
}

const sn_crease_pair *sn_crease_list(const sn_ihdr *h) { return h->v.nCR ? cr_pairs(h) : NULL; }
const sn_q *sn_crease_surface(const sn_ihdr *h) { return h->v.nCR ? cr_surf(h) : NULL; }

uint32_t sn_get_crease_contacts(const sn_instance *inst, uint32_t *vertices, uint32_t max) {
    const sn_ihdr *h;
    const sn_crease_pair *C;
    uint32_t k;
    if (inst_status(inst) != SN_OK) return 0;
    h = chdr_of(inst);
    if (!h->v.nCR) return 0;
    C = cr_pairs(h);
    for (k = 0; vertices && k < h->cr_n && k < max; k++) vertices[k] = C[k].vertex;
    return h->cr_n;
}

/* ---------------- geometry ---------------- */

SN_INLINE uint32_t cr_tri_corner(const sn_ihdr *h, uint32_t t, uint32_t k) {
    return sn_rd_u16(h->v.sec[SN_SEC_TRIS] + 6u * t + 2u * k);
}

/* Vertex r_i against triangle (a, b, c), counter-clockwise from outside so
 * n = (b - a) x (c - a) points out. u = r_i - a = beta e1 + gamma e2 + delta n
 * with e1 = b - a, e2 = c - a: (u x e2).n = beta |n|^2, (e1 x u).n =
 * gamma |n|^2 (the normal part drops out: the projection b of r_i on the
 * plane), alpha = 1 - beta - gamma.
 * Fixed: the nine difference components (each |.| <= 2^29, positions are
 * clamped to 2^28) are shifted right by s so the largest is <= 2^13; then the
 * cross products are <= 2^27, every triple product and |n|^2 <= 3 2^54, and
 * |n|^2 - B - G <= 9 2^54: exact in int64 (NUMERICS.md). */
typedef struct cr_geo {
    int ok;          /* non-degenerate triangle */
    int below;       /* (r_i - a).n < 0: behind the triangle's plane (the fields below only when below) */
    int inside;      /* the projection lies in the triangle (every barycentric >= 0) */
    int off;         /* the projection lies off the triangle by more than 1/4 (a barycentric < -1/4) */
    uint32_t corner; /* 0, 1, 2: the corner with the largest barycentric (ties: lowest) */
    sn_q n[4];       /* unit normal, Q30 (cr_finish) */
    sn_q d;          /* signed distance of r_i from the plane, Q22, < 0 behind (cr_finish) */
} cr_geo;

static void cr_test(const sn_q ri[3], const sn_q ra[3], const sn_q rb[3], const sn_q rc[3], cr_geo *g) {
    uint32_t k;
#if defined(SN_FLOAT)
    float e1[3], e2[3], u[3], n[3], x[3], N2, B, G, A, dn;
    for (k = 0; k < 3; k++) { e1[k] = rb[k] - ra[k]; e2[k] = rc[k] - ra[k]; u[k] = ri[k] - ra[k]; }
#else
    int64_t e1[3], e2[3], u[3], n[3], x[3], N2, B, G, A, dn, m = 0;
    int s;
    for (k = 0; k < 3; k++) {
        e1[k] = (int64_t)rb[k] - ra[k]; e2[k] = (int64_t)rc[k] - ra[k]; u[k] = (int64_t)ri[k] - ra[k];
        m |= (e1[k] < 0 ? -e1[k] : e1[k]) | (e2[k] < 0 ? -e2[k] : e2[k]) | (u[k] < 0 ? -u[k] : u[k]);
    }
    s = bitlen64((uint64_t)m) - 13; /* m < 2^bitlen: after the shift every |component| <= 2^13 */
    for (k = 0; s > 0 && k < 3; k++) { e1[k] = sn_rshr64(e1[k], s); e2[k] = sn_rshr64(e2[k], s); u[k] = sn_rshr64(u[k], s); }
#endif
    /* sums of products with the subtrahend negated (see sn_mul_sub) */
    n[0] = e1[1] * e2[2] + (-e1[2]) * e2[1];
    n[1] = e1[2] * e2[0] + (-e1[0]) * e2[2];
    n[2] = e1[0] * e2[1] + (-e1[1]) * e2[0];
    N2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    dn = u[0] * n[0] + u[1] * n[1] + u[2] * n[2];
    /* normal kept unnormalized until cr_finish (|n_k| <= 2^27 fits sn_q) */
    g->n[0] = (sn_q)n[0]; g->n[1] = (sn_q)n[1]; g->n[2] = (sn_q)n[2]; g->n[3] = 0;
    g->d = 0;
    g->ok = N2 > 0;
    g->below = g->ok && dn < 0;
    if (!g->below) { /* in front (or degenerate): nothing else is used (every caller drops such a pair) */
        g->inside = 0; g->off = 1; g->corner = 0;
        return;
    }
    x[0] = u[1] * e2[2] + (-u[2]) * e2[1]; /* u x e2 */
    x[1] = u[2] * e2[0] + (-u[0]) * e2[2];
    x[2] = u[0] * e2[1] + (-u[1]) * e2[0];
    B = x[0] * n[0] + x[1] * n[1] + x[2] * n[2];
    x[0] = e1[1] * u[2] + (-e1[2]) * u[1]; /* e1 x u */
    x[1] = e1[2] * u[0] + (-e1[0]) * u[2];
    x[2] = e1[0] * u[1] + (-e1[1]) * u[0];
    G = x[0] * n[0] + x[1] * n[1] + x[2] * n[2];
    A = N2 - B - G;
    g->inside = A >= 0 && B >= 0 && G >= 0;
    g->off = 4 * A < -N2 || 4 * B < -N2 || 4 * G < -N2;
    g->corner = (B > A && B >= G) ? 1u : ((G > A && G > B) ? 2u : 0u);
}

/* Unit normal (Q30) and the signed distance d = (r_i - a).n (Q22): one
 * normalization and three products (|r_i - a| <= 2^29, |n| <= 2^30: the sum
 * is below 3 2^59). */
static void cr_finish(const sn_q ri[3], const sn_q ra[3], cr_geo *g, uint32_t *sat) {
    sn_acc acc = 0;
    uint32_t k;
    sn_qnormalize(g->n);
    for (k = 0; k < 3; k++) acc += sn_mul(ri[k] - ra[k], g->n[k]);
    g->d = sn_out(acc, SN_Q_ROT, sat);
}

/* Test surface vertex a (position ra) against triangle t from the step's
 * surface positions; full = also normal and depth when it is behind and inside. */
static void cr_tri(const sn_ihdr *h, const sn_q ra[3], uint32_t t, cr_geo *g, int full, uint32_t *sat) {
    const sn_q *p0 = cr_pos(h, cr_tri_corner(h, t, 0)), *p1 = cr_pos(h, cr_tri_corner(h, t, 1)), *p2 = cr_pos(h, cr_tri_corner(h, t, 2));
    cr_test(ra, p0, p1, p2, g);
    if (full && g->below) cr_finish(ra, p0, g, sat);
}

/* Lattice vertices and weights (Q30) of surface vertex s: its cell's 8
 * corners (trilinear), on the cut level then its child's extras (the cut
 * field, sn_point_weights). Returns the entries (8, <= 15 cut). */
static uint32_t cr_cell(const sn_ihdr *h, uint32_t s, uint32_t vtx[SN_CUT_POINT_MAX], sn_q phi[SN_CUT_POINT_MAX]) {
    const unsigned char *e = h->v.sec[SN_SEC_EMBED] + (size_t)s * SN_ELEM_EMBED;
    const unsigned char *cell = h->v.sec[SN_SEC_CELLS] + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
    uint32_t t[3], a, n;
    uint16_t v16[SN_CUT_POINT_MAX];
    for (a = 0; a < 3; a++) t[a] = sn_rd_u16(e + 2 + 2 * a);
    if (h->v.cut) {
        n = sn_point_weights(&h->v, sn_rd_u16(e), t, v16, phi);
        for (a = 0; a < n; a++) vtx[a] = v16[a];
        return n;
    }
    sn_trilinear(t, phi);
    for (a = 0; a < 8; a++) vtx[a] = sn_rd_u16(cell + 2 * a);
    return 8;
}

/* Rest position (Q22) of surface vertex s: its cell's REST corners
 * trilinearly weighted (a convex combination of validated coordinates). */
static void cr_rest(const sn_ihdr *h, uint32_t s, sn_q out[3]) {
    const unsigned char *rest = h->v.sec[SN_SEC_REST];
    uint32_t vtx[SN_CUT_POINT_MAX], a, k, n, dummy = 0;
    sn_q phi[SN_CUT_POINT_MAX];
    sn_acc acc[3] = {0, 0, 0};
    n = cr_cell(h, s, vtx, phi);
    for (a = 0; a < n; a++)
        for (k = 0; k < 3; k++) acc[k] += sn_mul(phi[a], SN_RD_REAL(rest + (size_t)SN_REAL_BYTES * (3u * vtx[a] + k)));
    for (k = 0; k < 3; k++) out[k] = sn_out(acc[k], SN_Q_ROT, &dummy);
}

/* Is a corner of triangle t closer to rest position ra than the baked
 * 'exclude' in the rest pose (seed 003 §3.4: skin that close folds with the
 * lattice; the host tool's slow motion uses the same rule)? Fixed: the
 * differences are <= 2^29, a squared distance <= 3 2^58, exclude^2 <= 2^56:
 * exact in int64. */
static int cr_excluded(const sn_ihdr *h, const sn_q ra[3], uint32_t t) {
    sn_q ex = SN_RD_REAL(h->v.sec[SN_SEC_CREASE] + 12 + 2 * SN_REAL_BYTES), rc[3];
    uint32_t c, k;
    if (!(ex > 0)) return 0;
    for (c = 0; c < 3; c++) {
#if defined(SN_FLOAT)
        float d2 = 0;
        cr_rest(h, cr_tri_corner(h, t, c), rc);
        for (k = 0; k < 3; k++) d2 += (rc[k] - ra[k]) * (rc[k] - ra[k]);
        if (d2 < ex * ex) return 1;
#else
        int64_t d2 = 0;
        cr_rest(h, cr_tri_corner(h, t, c), rc);
        for (k = 0; k < 3; k++) d2 += ((int64_t)rc[k] - ra[k]) * ((int64_t)rc[k] - ra[k]);
        if (d2 < (int64_t)ex * ex) return 1;
#endif
    }
    return 0;
}

/* Is any of x0, x1, x2 among the n entries of nb (a's neighbourhood)? */
static int cr_near(const uint16_t *nb, uint32_t n, uint32_t x0, uint32_t x1, uint32_t x2) {
    uint32_t k, hit = 0;
    for (k = 0; k < n; k++) hit |= (uint32_t)(nb[k] == x0) | (uint32_t)(nb[k] == x1) | (uint32_t)(nb[k] == x2);
    return (int)hit;
}

/* The neighbourhood row of surface vertex s (format 6.0: rows only for the
 * vertices the host tool found the runtime can query, their owners strictly
 * increasing, validated): binary search over the rows' first entries, at most
 * bits(nQ) <= 16 probes. SN_CREASE_NONE: s has no row (never searched). */
static uint32_t cr_row_of(const sn_view *v, uint32_t s) {
    const unsigned char *VN = v->sec[SN_SEC_CREASE_VNBR];
    uint32_t lo = 0, hi = v->cr_nq; /* the row, if any, is in [lo, hi) */
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2u, x = sn_rd_u16(VN + 2u * (size_t)mid * v->cr_nv);
        if (x == s) return mid;
        if (x < s) lo = mid + 1u; else hi = mid;
    }
    return SN_CREASE_NONE;
}

/* Search the TNBR row of surface vertex nbr for a triangle that surface
 * vertex a has penetrated: no corner of it in a's
 * neighbourhood (a's VNBR row: a fold of the skin next to a is not a
 * collision), behind it, its projection inside it, no deeper than the baked
 * depth. The first such triangle of the row (increasing index) wins. Either
 * vertex without a row: nothing found. Returns 1 and *tri, *corner (surface
 * vertex). */
static int cr_search(const sn_ihdr *h, uint32_t a, uint32_t nbr, uint32_t *tri,
                     uint32_t *corner, uint32_t *sat) {
    uint32_t qa = cr_row_of(&h->v, a), qt = cr_row_of(&h->v, nbr);
    const unsigned char *row, *vrow;
    uint16_t nb[SN_CREASE_MAX_NBR_V];
    uint32_t k, nn;
    sn_q rest_a[3];
    const sn_q *ra;
    int have_rest = 0;
    if (qa == SN_CREASE_NONE || qt == SN_CREASE_NONE) return 0;
    ra = cr_pos(h, a);
    row = h->v.sec[SN_SEC_CREASE_TNBR] + 2u * (size_t)qt * h->v.cr_nt;
    vrow = h->v.sec[SN_SEC_CREASE_VNBR] + 2u * (size_t)qa * h->v.cr_nv;
    for (nn = 0; nn < h->v.cr_nv; nn++) { /* a's neighbourhood, once per search */
        nb[nn] = (uint16_t)sn_rd_u16(vrow + 2u * nn);
        if (nb[nn] == SN_CREASE_NONE) break;
    }
    for (k = 0; k < h->v.cr_nt; k++) {
        uint32_t t = sn_rd_u16(row + 2u * k);
        cr_geo g;
        if (t == SN_CREASE_NONE) break; /* the row's tail is all NONE (validated) */
        if (cr_near(nb, nn, cr_tri_corner(h, t, 0), cr_tri_corner(h, t, 1), cr_tri_corner(h, t, 2))) continue;
        cr_tri(h, ra, t, &g, 0, sat);
        if (!g.below || !g.inside) continue;
        cr_finish(ra, cr_pos(h, cr_tri_corner(h, t, 0)), &g, sat);
        if (g.d < -h->v.cr_depth) continue;
        if (!have_rest) { cr_rest(h, a, rest_a); have_rest = 1; }
        if (cr_excluded(h, rest_a, t)) continue; /* last: the rarest to get here, the dearest test */
        *tri = t;
        *corner = cr_tri_corner(h, t, g.corner);
        return 1;
    }
    return 0;
}

/* Step 2 for one candidate: vertex a against the triangles near rowv. */
static void cr_try(sn_ihdr *h, uint32_t a, uint32_t rowv, uint32_t *sat) {
    uint8_t *mem = cr_member(h);
    uint32_t t, c;
    if (mem[a]) return;
    if (!cr_search(h, a, rowv, &t, &c, sat)) return;
    if (h->cr_n >= h->v.cr_list) { h->cr_list_full = sn_count(h->cr_list_full, 1); return; }
    {
        sn_crease_pair *P = cr_pairs(h) + h->cr_n;
        P->vertex = (uint16_t)a; P->tri = (uint16_t)t; P->corner = (uint16_t)c; P->pad = 0;
    }
    mem[a] = 1;
    h->cr_n++;
    h->cr_added = sn_count(h->cr_added, 1);
}


/* The contact row of pair P (eq. 9): (v_i - v_b).n >= target with v_i the
 * velocity of vertex i (its cell's weights, +phi) and v_b that of the
 * triangle point, taken as its nearest corner's (-phi of that corner's cell),
 * so a row has at most 16 entries; shared lattice vertices merged. target =
 * min(penetration depth, push cap): the pair moves apart by the depth in one
 * step, at most by the cap. Returns chi = (v_i - v_b).n of the last step's
 * velocities (Q22).
 * The cut level: each side <= 15 entries (8 corners, the extras of its
 * child), <= 30 merged; beyond SN_ROW_MAX_ENT the skeleton entries (known
 * velocities: rows_factor would move them to the right-hand side) are folded
 * into the target now, f = sum w (n . v_x), and chi is returned less f, so
 * chi < target still compares the whole pair. The free entries (corners)
 * are <= 16, sum |w| <= 2 as before. */
static sn_q cr_row(const sn_ihdr *h, const sn_crease_pair *P, sn_row *r, uint32_t *sat) {
    const sn_q *vel = CARR(h, o_vel, sn_q);
    uint32_t vi[SN_CUT_POINT_MAX], vp[SN_CUT_POINT_MAX], ev[2 * SN_CUT_POINT_MAX], a, b, k, ni, np, ne = 0;
    sn_q pi[SN_CUT_POINT_MAX], pp[SN_CUT_POINT_MAX], ew[2 * SN_CUT_POINT_MAX], rv[3], fold = 0;
    sn_acc acc[3] = {0, 0, 0}, chi = 0;
    cr_geo g;
    cr_tri(h, cr_pos(h, P->vertex), P->tri, &g, 0, sat);
    cr_finish(cr_pos(h, P->vertex), cr_pos(h, cr_tri_corner(h, P->tri, 0)), &g, sat);
    ni = cr_cell(h, P->vertex, vi, pi);
    np = cr_cell(h, P->corner, vp, pp);
    for (a = 0; a < ni; a++) { ev[ne] = vi[a]; ew[ne] = pi[a]; ne++; }
    for (b = 0; b < np; b++) {
        for (a = 0; a < ni && vi[a] != vp[b]; a++) {}
        if (a < ni) ew[a] -= pp[b]; /* |pi - pp| <= 2^30 */
        else { ev[ne] = vp[b]; ew[ne] = -pp[b]; ne++; }
    }
    for (k = 0; k < 3; k++) r->dir[k] = g.n[k];
    for (a = 0; a < ne; a++)
        for (k = 0; k < 3; k++) acc[k] += sn_mul(ew[a], vel[3u * ev[a] + k]); /* sum |w| <= 2: 2^31 x 2^28 */
    for (k = 0; k < 3; k++) rv[k] = sn_out(acc[k], SN_Q_ROT, sat);
    for (k = 0; k < 3; k++) chi += sn_mul(rv[k], g.n[k]);
    r->n = 0;
#if defined(SN_CR_FOLD_ALL) /* test build (tests/test_runtime_cut_rows.c): every pair folded, the fold's arithmetic checked */
    if (0)
#else
    if (ne <= SN_ROW_MAX_ENT)
#endif
        for (a = 0; a < ne; a++) { r->vtx[r->n] = (uint16_t)ev[a]; r->w[r->n] = ew[a]; r->n++; }
    else { /* cut level only (a plain pair has <= 16) */
        sn_acc f = 0;
        for (a = 0; a < ne; a++) {
            if (ev[a] < h->v.nF) { r->vtx[r->n] = (uint16_t)ev[a]; r->w[r->n] = ew[a]; r->n++; continue; }
            for (k = 0; k < 3; k++) f += sn_mul(ew[a], sn_mulq(g.n[k], vel[3u * ev[a] + k], SN_Q_ROT, sat));
        }
        fold = sn_out(f, SN_Q_ROT, sat);
    }
    r->target = -g.d < h->v.cr_push ? -g.d : h->v.cr_push; /* d <= 0 for a listed pair (step 1 keeps only those) */
    r->target = r->target < 0 ? 0 : r->target;
    r->target = sn_add(r->target, -fold, sat);
    r->one_sided = 1;
    r->source = SN_ROW_SRC(SN_SRC_CREASE, P - cr_pairs(h));
    return sn_add(sn_out(chi, SN_Q_ROT, sat), -fold, sat);
}

/* ---------------- the step ---------------- */

void sn_crease_step(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    sn_crease_pair *C;
    uint8_t *mem, *F;
    const unsigned char *D, *VN;
    uint32_t s, k, w, n0, na;
    if (!v->nCR) return;
    C = cr_pairs(h); mem = cr_member(h); F = cr_fresh(h);
    D = v->sec[SN_SEC_CREASE_PAIRS]; VN = v->sec[SN_SEC_CREASE_VNBR];
    h->cr_rows = 0;
    /* 0. surface positions of this step: none computed yet */
    for (s = 0; s < v->nS; s++) F[s] = 0; /* computed on first use (cr_pos) */
    /* 1. maintenance (seed 003 §3.4.2 step 2), order kept */
    for (k = 0, w = 0; k < h->cr_n; k++) {
        sn_crease_pair P = C[k];
        const sn_q *ri = cr_pos(h, P.vertex);
        cr_geo g;
        int keep = 0;
        cr_tri(h, ri, P.tri, &g, 1, sat);
        if (g.below && !g.off) {
            keep = g.d >= -v->cr_depth;
            P.corner = (uint16_t)cr_tri_corner(h, P.tri, g.corner);
        } else if (g.below) { /* slid off T: the triangle it lies under now, near the corner */
            uint32_t t, c;
            if (cr_search(h, P.vertex, P.corner, &t, &c, sat)) {
                P.tri = (uint16_t)t; P.corner = (uint16_t)c;
                keep = 1;
            }
        }
        if (keep) C[w++] = P;
        else {
            mem[P.vertex] = 0;
            h->cr_removed = sn_count(h->cr_removed, 1);
        }
    }
    h->cr_n = w;
    /* 2. detection over P = D u N(C) (steps 1 and 3) */
    for (k = 0; k < v->nD; k++) {
        uint32_t i = sn_rd_u16(D + 4u * k), j = sn_rd_u16(D + 4u * k + 2);
        cr_try(h, i, j, sat);
        cr_try(h, j, i, sat);
    }
    n0 = h->cr_n;
    for (k = 0; k < n0; k++) {
        uint32_t q = cr_row_of(v, C[k].vertex), p = C[k].corner, a;
        const unsigned char *row = VN + 2u * (size_t)q * v->cr_nv;
        if (q == SN_CREASE_NONE) continue; /* (a listed vertex has a row: it entered through cr_search) */
        for (a = 0; a < v->cr_nv; a++) {
            uint32_t i2 = sn_rd_u16(row + 2u * a);
            if (i2 == SN_CREASE_NONE) break;
            cr_try(h, i2, p, sat);
        }
    }
    /* 3. the active prefix n_a (step 4) and its rows */
    na = 0;
    for (k = 0; k < h->cr_n; k++) {
        sn_row r;
        sn_q chi = cr_row(h, &C[k], &r, sat);
        if (chi < r.target) na = k + 1;
    }
    h->cr_na = na;
    if (na > v->cr_active) h->cr_active_over = sn_count(h->cr_active_over, na - v->cr_active);
}

/* The rows of the active pairs k < min(n_a, max_active), for the projection
 * (called by sn_constrain_begin after the other producers). */
void sn_crease_rows_push(sn_ihdr *h, uint32_t *sat) {
    const sn_crease_pair *C;
    uint32_t k, n;
    h->cr_rows = 0;
    if (!h->v.nCR) return;
    C = cr_pairs(h);
    n = h->cr_na < h->v.cr_active ? h->cr_na : h->v.cr_active;
    for (k = 0; k < n; k++) {
        sn_row r;
        (void)cr_row(h, &C[k], &r, sat);
        if (sn_rows_push(h, &r)) h->cr_rows++;
        else h->cr_active_over = sn_count(h->cr_active_over, 1); /* the step's row store full (also counted there) */
    }
}

uint64_t sn_crease_hash(const sn_ihdr *h, uint64_t hsh) {
    const sn_crease_pair *C;
    uint32_t k, x[3];
    int b, j;
    if (!h->v.nCR) return hsh;
    C = cr_pairs(h);
    x[0] = h->cr_n; x[1] = h->cr_na; x[2] = 0;
    for (j = 0; j < 2; j++)
        for (b = 0; b < 4; b++) { hsh ^= (x[j] >> (8 * b)) & 0xFFu; hsh *= 0x100000001B3ull; }
    for (k = 0; k < h->cr_n; k++) {
        x[0] = (uint32_t)C[k].vertex | ((uint32_t)C[k].tri << 16);
        x[1] = C[k].corner;
        for (j = 0; j < 2; j++)
            for (b = 0; b < 4; b++) { hsh ^= (x[j] >> (8 * b)) & 0xFFu; hsh *= 0x100000001B3ull; }
    }
    return hsh;
}

/* ---------------- validation (sn_blob.c calls it once the table is checked) ----------------
 * CREASE: reserved fields 0, depth in [1, SN_CREASE_DEPTH_MAX] (Q22: the
 * cr_finish distance is compared against it, |d| <= 2^29), push in
 * [0, depth], exclude in [0, SN_CREASE_EXCLUDE_MAX] (squared in int64); PAIRS: i != j, both < nS; VNBR rows (nQ of them, format
 * 6.0): entries < nS, SN_CREASE_NONE only as a tail, first entries (the
 * rows' owners) present and strictly increasing (cr_row_of's binary
 * search); TNBR rows: entries < nT, SN_CREASE_NONE only as a tail. The counts and widths are checked
 * with the section table (sn_blob.c). */
static int cr_rows_ok(const unsigned char *sec, uint32_t rows, uint32_t width, uint32_t lim, int owners) {
    uint32_t s, k, last = 0;
    for (s = 0; s < rows; s++) {
        const unsigned char *row = sec + 2u * (size_t)s * width;
        int tail = 0;
        for (k = 0; k < width; k++) {
            uint32_t x = sn_rd_u16(row + 2u * k);
            if (x == SN_CREASE_NONE) { tail = 1; continue; }
            if (tail || x >= lim) return 0;
        }
        if (owners) {
            uint32_t o = sn_rd_u16(row);
            if (o >= lim || (s > 0 && o <= last)) return 0; /* present (not NONE), increasing */
            last = o;
        }
    }
    return 1;
}

sn_status sn_check_crease(const sn_view *v) {
    const unsigned char *c, *D;
    uint32_t k;
    if (!v->nCR) return SN_OK;
    c = v->sec[SN_SEC_CREASE];
    if (sn_rd_u32(c + 8) != 0) return SN_ERR_VALUE;
    if (!sn_real_ok(c + 12, 1, SN_CREASE_DEPTH_MAX, SN_Q_LEN) || !(v->cr_depth > 0)) return SN_ERR_VALUE;
    if (!sn_real_ok(c + 12 + SN_REAL_BYTES, 0, SN_CREASE_DEPTH_MAX, SN_Q_LEN) || !(v->cr_push >= 0) ||
        !(v->cr_push <= v->cr_depth))
        return SN_ERR_VALUE;
    if (!sn_real_ok(c + 12 + 2 * SN_REAL_BYTES, 0, SN_CREASE_EXCLUDE_MAX, SN_Q_LEN)) return SN_ERR_VALUE;
    D = v->sec[SN_SEC_CREASE_PAIRS];
    for (k = 0; k < v->nD; k++) {
        uint32_t i = sn_rd_u16(D + 4u * k), j = sn_rd_u16(D + 4u * k + 2);
        if (i >= v->nS || j >= v->nS) return SN_ERR_INDEX;
        if (i == j) return SN_ERR_VALUE;
    }
    if (!cr_rows_ok(v->sec[SN_SEC_CREASE_VNBR], v->cr_nq, v->cr_nv, v->nS, 1)) return SN_ERR_INDEX;
    if (!cr_rows_ok(v->sec[SN_SEC_CREASE_TNBR], v->cr_nq, v->cr_nt, v->nT, 0)) return SN_ERR_INDEX;
    return SN_OK;
}
