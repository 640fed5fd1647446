/* sn_segment_mesh.c -- segment meshes (seed 004 ch. 3-4): the mesh records,
 * each level's segments and nodes, which ends meet at a node, node means,
 * segments rebuilt from nodes; the state's reset, teleport and hash. No
 * per-step work beyond node means and restriction's rebuild. SEGMENTS.md.
 */
#include "sn_segment.h"

/* ---------------- mesh records and topology ---------------- */

void seg_mesh_get(const sn_ihdr *h, uint32_t m, seg_mesh *M) {
    const unsigned char *r = h->v.sec[SN_SEC_SEGMESH];
    sn_q *base = (sn_q *)(void *)((unsigned char *)(uintptr_t)h + h->o_seg);
    uint32_t i, k;
    for (i = 0; i <= m; i++, r += SEG_REC) {
        M->kind = r[0]; M->levels = r[1]; M->sweeps = r[2]; M->flags = r[3];
        M->side = sn_rd_u16(r + 4); M->n_attach = sn_rd_u16(r + 6);
        M->first_node = sn_rd_u32(r + 8); M->first_attach = sn_rd_u32(r + 12);
        M->coarse_sweeps = r[16 + 9 * SN_REAL_BYTES]; M->relax = r[17 + 9 * SN_REAL_BYTES];
        sn_seg_counts(M->kind, M->side, M->levels, &M->segs, &M->nodes);
        M->S = base;
        M->N = base + SEG_W * M->segs;
        base = M->N + NODE_W * M->nodes;
        if (i == m) {
            M->len = rd_real(r + 16, 0); M->gamma = rd_real(r + 16, 1); M->keep = rd_real(r + 16, 2);
            M->inv_mass = rd_real(r + 16, 3); M->centre = rd_real(r + 16, 4);
            for (k = 0; k < SN_SEG_MAX_LEVELS; k++) M->share[k] = rd_real(r + 16, 5 + k);
        }
    }
}

/* reciprocal of a half length x: fixed r = 2^(29+b)/x in (2^29, 2^30] with
 * b = bits of x, so y/x (Q30) = y r >> (b - 1); float 1/x */
static void recip(sn_q x, sn_q *r, int *s) {
#if defined(SN_FLOAT)
    *r = 1.0f / x;
    *s = 0;
#else
    /* 2^(29+b)/x = 2^61/(x 2^(32-b)) with the divisor normalized: a 64/32
     * division (no library 64-bit divide on a 32-bit core), same quotient */
    int b = bitlen64((uint64_t)x);
    *r = (sn_q)sn_div64n((uint64_t)1 << 61, (uint32_t)x << (32 - b));
    *s = b - 1;
#endif
}

void seg_level(const seg_mesh *M, unsigned l, seg_lvl *L) {
    unsigned k;
    uint32_t so = 0, no = 0;
    L->kind = M->kind;
    L->l = l;
    for (k = 0; k <= l; k++) {
        uint32_t s = M->kind == SN_SEG_CHAIN ? M->side : ((M->side - 1u) >> k) + 1u;
        uint32_t ns = M->kind == SN_SEG_CHAIN ? s - 1u : 2u * s * (s - 1u) + (s == 2u ? 2u : 0u);
        uint32_t nn = M->kind == SN_SEG_CHAIN ? s : s * s;
        if (k == l) { L->side = s; L->ns = ns; L->nn = nn; }
        else { so += ns; no += nn; }
    }
    L->S = M->S + SEG_W * so;
    L->N = M->N + NODE_W * no;
#if defined(SN_FLOAT)
    L->half = M->len * (float)(1u << l) * 0.5f;
    L->bhalf = L->half * 1.41421356237f;
#else
    /* (side-1) len <= 2^27 (validated) and 2^l <= side-1: no overflow */
    L->half = (sn_q)(((int64_t)M->len << l) >> 1);
    L->half = L->half < 1 ? 1 : L->half;
#endif
    recip(L->half, &L->rh, &L->sh);
}

/* sheet of side s: horizontal (r,c)-(r,c+1) first, r(s-1)+c; vertical
 * (r,c)-(r+1,c) next, s(s-1)+rs+c; at s = 2 the braces (0,0)-(1,1), (0,1)-(1,0) */
void seg_nodes(const seg_lvl *L, uint32_t i, uint32_t *a, uint32_t *b) {
    uint32_t s = L->side, nh = s * (s - 1u);
    if (L->kind == SN_SEG_CHAIN) { *a = i; *b = i + 1u; return; }
    if (i < nh) { *a = (i / (s - 1u)) * s + i % (s - 1u); *b = *a + 1u; }
    else if (i < 2u * nh) { *a = i - nh; *b = *a + s; }
    else if (i == 2u * nh) { *a = 0; *b = 3; }
    else { *a = 1; *b = 2; }
}

/* in ring order: left (end), up (end), right (start), down (start), brace */
unsigned seg_node_ends(const seg_lvl *L, uint32_t n, uint32_t seg[5], int sgn[5]) {
    unsigned k = 0;
    uint32_t s = L->side, nh = s * (s - 1u);
    if (L->kind == SN_SEG_CHAIN) {
        if (n > 0) { seg[k] = n - 1u; sgn[k++] = 1; }
        if (n + 1u < s) { seg[k] = n; sgn[k++] = -1; }
        return k;
    }
    k = sheet_ends(s, n / s, n % s, seg, sgn);
    if (s == 2u) { seg[k] = 2u * nh + (n == 0 || n == 3 ? 0u : 1u); sgn[k++] = (n == 0 || n == 1) ? -1 : 1; }
    return k;
}

void seg_end(const seg_lvl *L, uint32_t i, int s, sn_q P[3], uint32_t *sat) { end_of(L, i, s, P, sat); }

void seg_unit(const sn_q x[3], sn_q u[3]) {
    sn_q q[4];
    q[0] = x[0]; q[1] = x[1]; q[2] = x[2]; q[3] = 0;
    sn_qnormalize(q);
    if (q[3] != 0) return; /* zero vector: keep u */
    u[0] = q[0]; u[1] = q[1]; u[2] = q[2];
}

void seg_node_means(const seg_lvl *L, uint32_t *sat) {
    uint32_t n, seg[5];
    int sgn[5];
    unsigned j, k, c;
    for (n = 0; n < L->nn; n++) {
        sn_acc sum[3] = {0, 0, 0};
        k = seg_node_ends(L, n, seg, sgn);
        for (j = 0; j < k; j++) {
            sn_q P[3];
            seg_end(L, seg[j], sgn[j], P, sat);
            for (c = 0; c < 3; c++) sum[c] += P[c];
        }
        for (c = 0; c < 3; c++) L->N[NODE_W * n + c] = mean_k(sum[c], k, sat);
    }
}

void seg_from_nodes(const seg_lvl *L, int lens, uint32_t *sat) {
    uint32_t i, a, b;
    unsigned k;
    for (i = 0; i < L->ns; i++) {
        sn_q *S = L->S + SEG_W * i, d[3];
        seg_nodes(L, i, &a, &b);
        for (k = 0; k < 3; k++) {
            sn_q pa = L->N[NODE_W * a + k], pb = L->N[NODE_W * b + k];
            S[k] = mean_k((sn_acc)pa + pb, 2, sat);
            d[k] = sn_add(pb, -pa, sat);
        }
        seg_unit(d, S + 3);
        if (lens && L->l > 0) { /* a coarse segment's length: its restricted nodes' distance */
            int sh;
#if defined(SN_FLOAT)
            float n2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            S[12] = n2 > 1e-12f ? 0.5f * n2 * sn_frsqrt(n2) : (is_brace(L, i) ? L->bhalf : L->half);
#else
            /* |d_k| <= 2^29 (differences of clamped Q22 values): sum of squares < 2^60 */
            uint64_t n2 = 0;
            for (k = 0; k < 3; k++) n2 += (uint64_t)((int64_t)d[k] * d[k]);
            S[12] = (sn_q)(sn_isqrt64(n2) >> 1); /* <= 2^29 */
            S[12] = S[12] < 1 ? 1 : S[12];
#endif
            recip(S[12], &S[13], &sh);
            S[14] = (sn_q)sh;
        }
    }
}

/* M a (Q30 rotation times a value of any Q) without the state clamp: |M a|
 * <= 1.74 |a|_max (rows of a rotation, rounded), each product <= 2^61 */
static void turn_raw(const sn_q M[9], const sn_q a[3], sn_q out[3]) {
    unsigned k;
    for (k = 0; k < 3; k++) out[k] = shr30(sn_mul(M[3 * k], a[0]) + sn_mul(M[3 * k + 1], a[1]) + sn_mul(M[3 * k + 2], a[2]));
}

void sn_segments_teleport(sn_ihdr *h, const sn_q M[9], const sn_q T0[3], const sn_q T1[3], uint32_t *sat) {
    uint32_t m, i;
    unsigned k;
    if (h->v.nM == 0) return;
    for (k = 0; k < 3; k++) h->seg_origin[k] = h->origin[k];
    if (!h->seg_placed) return; /* the first step places the meshes by their joint */
    for (m = 0; m < h->v.nM; m++) {
        seg_mesh Ms;
        seg_mesh_get(h, m, &Ms);
        for (i = 0; i < Ms.segs; i++) {
            sn_q *S = Ms.S + SEG_W * i, a[3], b[3];
            for (k = 0; k < 3; k++) a[k] = sn_add(S[k], -T0[k], sat);
            sn_rot(M, a, b, sat); /* Q22 positions: within the state range */
            for (k = 0; k < 3; k++) S[k] = sn_add(b[k], T1[k], sat);
            turn_raw(M, S + 3, a); /* Q30 unit: <= 1.74 2^30 */
            seg_unit(a, S + 3);
            memcpy(a, S + 6, sizeof a);
            sn_rot(M, a, S + 6, sat);
            turn_raw(M, S + 9, a); /* w: each |w_k| <= 2^28, limited again */
            for (k = 0; k < 3; k++) S[9 + k] = a[k] > ROT_MAX ? ROT_MAX : (a[k] < -ROT_MAX ? -ROT_MAX : a[k]);
        }
        for (i = 0; i < Ms.nodes; i++) {
            sn_q *N = Ms.N + NODE_W * i, a[3];
            for (k = 0; k < 3; k++) a[k] = sn_add(N[k], -T0[k], sat);
            sn_rot(M, a, N, sat);
            for (k = 0; k < 3; k++) N[k] = sn_add(N[k], T1[k], sat);
            memcpy(a, N + 3, sizeof a);
            sn_rot(M, a, N + 3, sat);
        }
    }
}

/* Rest state: level 0 from the rest nodes, coarser levels restricted; all
 * velocities and impulses zero. */
void sn_segments_reset(sn_ihdr *h) {
    uint32_t m, i, sat = 0;
    unsigned k, l;
    h->seg_placed = 0;
    for (k = 0; k < 3; k++) h->seg_origin[k] = h->origin[k];
    for (m = 0; m < h->v.nM; m++) {
        seg_mesh M;
        seg_lvl L;
        seg_mesh_get(h, m, &M);
        memset(M.S, 0, (size_t)SN_SEG_SEG_BYTES * M.segs + (size_t)SN_SEG_NODE_BYTES * M.nodes);
        seg_level(&M, 0, &L);
        for (i = 0; i < L.nn; i++)
            for (k = 0; k < 3; k++) L.N[NODE_W * i + k] = rd_real(h->v.sec[SN_SEC_SEGNODES], 3 * (M.first_node + i) + k);
        for (i = 0; i < M.segs; i++) M.S[SEG_W * i + 3] = SN_ONE_ROT; /* any unit u before seg_from_nodes */
        seg_from_nodes(&L, 0, &sat);
        for (l = 1; l < M.levels; l++) {
            seg_lvl Lc;
            seg_level(&M, l, &Lc);
            for (i = 0; i < Lc.nn; i++) { /* coarse node (r,c) = finer node (2r, 2c), eq. 4.1-4.2 */
                uint32_t r = i / Lc.side, c = i % Lc.side, f;
                seg_level(&M, l - 1, &L);
                f = 2u * r * L.side + 2u * c;
                for (k = 0; k < 3; k++) Lc.N[NODE_W * i + k] = L.N[NODE_W * f + k];
            }
            seg_from_nodes(&Lc, 1, &sat);
        }
    }
}

/* ---- determinism hash: every word of the segment state, little-endian ---- */
uint64_t sn_segments_hash(const sn_ihdr *h, uint64_t hsh) {
    const unsigned char *p = (const unsigned char *)h + h->o_seg;
    uint32_t i;
    for (i = 0; i < h->v.segB / 4u; i++) {
        sn_q x;
        uint32_t u;
        int b;
        memcpy(&x, p + 4u * i, 4);
        memcpy(&u, &x, 4);
        for (b = 0; b < 4; b++) {
            hsh ^= (u >> (8 * b)) & 0xFFu;
            hsh *= 0x100000001B3ull;
        }
    }
    return hsh;
}
