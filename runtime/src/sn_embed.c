/* sn_embed.c -- outputs: deformed lattice, embedded surface (trilinear in
 * each cell, seed 000 §3.1) and area-weighted normals. */
#include "sn_cut.h" /* sn_cut_interp: the cut level's field */
#include "sn_detail.h" /* sn_detail_interp: the active details on the surface */
#include "sn_kernels_surf.h" /* sn_k_tri_w, sn_k_surf1 */
#include "sn_kernels_xnorm.h" /* sn_k_xnormals */

/* ---- outputs ---- */

/* Public (world, mesh units) position of an internal point p: origin + p. */
void sn_pub_point(const sn_ihdr *h, const sn_q p[3], sn_vec3 *out) {
#if defined(SN_FLOAT)
    out->x = h->origin[0] + int_to_pub(h, p[0]);
    out->y = h->origin[1] + int_to_pub(h, p[1]);
    out->z = h->origin[2] + int_to_pub(h, p[2]);
#else
    out->x = clamp32((int64_t)h->origin[0] + int_to_pub64(h, p[0]));
    out->y = clamp32((int64_t)h->origin[1] + int_to_pub64(h, p[1]));
    out->z = clamp32((int64_t)h->origin[2] + int_to_pub64(h, p[2]));
#endif
}

/* Trilinear weights phi_a of a cell's 8 corners (sn_kernels_surf.h). */
void sn_trilinear(const uint32_t t[3], sn_q phi[8]) { sn_k_tri_w(t, phi); }

/* Current position (internal) of surface vertex s: trilinear in its cell
 * (seed 000 §3.1); on the cut level, in its child (cut_point). A convex
 * combination (the cut level: plus differences, clamped). */
void sn_surface_point(const sn_ihdr *h, uint32_t s, sn_q out[3]) {
    const unsigned char *e = h->v.sec[SN_SEC_EMBED] + (size_t)s * SN_ELEM_EMBED;
    const unsigned char *cell = h->v.sec[SN_SEC_CELLS] + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
    const sn_q *pos = CARR(h, o_pos, sn_q);
    uint32_t t[3], a, k, dummy = 0;
    sn_q phi[8];
    sn_acc acc[3] = {0, 0, 0};
    for (k = 0; k < 3; k++) t[k] = sn_rd_u16(e + 2 + 2 * k);
    sn_trilinear(t, phi);
    for (a = 0; a < 8; a++) {
        uint32_t vtx = sn_rd_u16(cell + 2 * a);
        for (k = 0; k < 3; k++) acc[k] += sn_mul(phi[a], pos[3 * vtx + k]);
    }
    if (h->v.cut) sn_cut_interp(&h->v, sn_rd_u16(e), t, pos, pos + 3 * h->v.nF, acc);
    if (h->v.cut && h->lod == 0u) { /* the active details' hats (LEVELS.md §3; none active: no term) */
        const sn_dstate *ds = sn_detail_region(h);
        if (ds && ds->n) sn_detail_interp(&h->v, sn_rd_u16(e), t, DT(ds, o_of, const uint16_t), DT(ds, o_coef, const sn_q), acc);
    }
    for (k = 0; k < 3; k++) out[k] = sn_out(acc[k], SN_Q_ROT, &dummy);
}

/* sn_surface_point and sn_pub_point for the plain lattice (no cut level, so
 * no details), a run of vertices at a time: the level tests leave the loop,
 * the weights and the 24 products go to sn_k_surf1 (sn_kernels_surf.h: the
 * same sums; AVX2 the corners in lanes) and the public scale is read once. x86-64 cow_fem: 273 instructions a
 * vertex against 477 (fixed), 193 against 391 (float); test_runtime_surface. */
static void surface_plain(const sn_ihdr *h, uint32_t first, uint32_t count, sn_vec3 *out) {
    const unsigned char *emb = h->v.sec[SN_SEC_EMBED], *cells = h->v.sec[SN_SEC_CELLS];
    const sn_q *pos = CARR(h, o_pos, sn_q);
#if defined(SN_FLOAT)
    const float o0 = h->origin[0], o1 = h->origin[1], o2 = h->origin[2], sc = h->to_pub;
#else
    const int sh = h->v.len_shift - (SN_Q_LEN - SN_LEN_FRAC);
    const int64_t o0 = h->origin[0], o1 = h->origin[1], o2 = h->origin[2];
#endif
    uint32_t i, dummy = 0;
    for (i = 0; i < count; i++) {
        const unsigned char *e = emb + (size_t)(first + i) * SN_ELEM_EMBED;
        uint32_t t[3];
        sn_q p0, p1, p2;
        sn_acc acc[3];
        t[0] = sn_rd_u16(e + 2); t[1] = sn_rd_u16(e + 4); t[2] = sn_rd_u16(e + 6);
        sn_k_surf1(t, cells + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS, pos, acc);
        p0 = sn_out(acc[0], SN_Q_ROT, &dummy); p1 = sn_out(acc[1], SN_Q_ROT, &dummy); p2 = sn_out(acc[2], SN_Q_ROT, &dummy);
#if defined(SN_FLOAT)
        out[i].x = o0 + p0 * sc; out[i].y = o1 + p1 * sc; out[i].z = o2 + p2 * sc;
#else
        if (sh >= 0) {
            out[i].x = clamp32(o0 + (int64_t)p0 * ((int64_t)1 << sh));
            out[i].y = clamp32(o1 + (int64_t)p1 * ((int64_t)1 << sh));
            out[i].z = clamp32(o2 + (int64_t)p2 * ((int64_t)1 << sh));
        } else {
            out[i].x = clamp32(o0 + sn_rshr64(p0, -sh));
            out[i].y = clamp32(o1 + sn_rshr64(p1, -sh));
            out[i].z = clamp32(o2 + sn_rshr64(p2, -sh));
        }
#endif
    }
}

sn_status sn_get_lattice(const sn_instance *inst, sn_vec3 *out, uint32_t first, uint32_t count) {
    const sn_ihdr *h;
    const sn_q *pos;
    uint32_t i;
    if (!inst || !out) return SN_ERR_NULL;
    h = chdr_of(inst);
    if (h->magic != SN_INST_MAGIC) return SN_ERR_INSTANCE;
    if (first > h->v.nV || count > h->v.nV - first) return SN_ERR_ARG;
    pos = CARR(h, o_pos, sn_q);
    for (i = 0; i < count; i++) sn_pub_point(h, pos + 3 * (first + i), out + i);
    return SN_OK;
}

sn_status sn_get_surface(const sn_instance *inst, sn_vec3 *out, uint32_t first, uint32_t count) {
    const sn_ihdr *h;
    uint32_t s;
    if (!inst || !out) return SN_ERR_NULL;
    h = chdr_of(inst);
    if (h->magic != SN_INST_MAGIC) return SN_ERR_INSTANCE;
    if (first > h->v.nS || count > h->v.nS - first) return SN_ERR_ARG;
    if (h->v.cut) {
        for (s = 0; s < count; s++) {
            sn_q p[3];
            sn_surface_point(h, first + s, p);
            sn_pub_point(h, p, out + s);
        }
    } else
        surface_plain(h, first, count, out);
    return SN_OK;
}

sn_status sn_get_normals(const sn_instance *inst, const sn_vec3 *positions, sn_vec3 *out) {
    const sn_ihdr *h;
    const unsigned char *tris;
    uint32_t nS;
    if (!inst || !positions || !out) return SN_ERR_NULL;
    h = chdr_of(inst);
    if (h->magic != SN_INST_MAGIC) return SN_ERR_INSTANCE;
    if (h->v.nT == 0) return SN_ERR_ARG;
    tris = h->v.sec[SN_SEC_TRIS];
    nS = h->v.nS;
#if defined(SN_FLOAT)
    uint32_t t;
    memset(out, 0, (size_t)nS * sizeof *out);
    for (t = 0; t < h->v.nT; t++) {
        uint32_t a = sn_rd_u16(tris + 6 * t), b = sn_rd_u16(tris + 6 * t + 2), c = sn_rd_u16(tris + 6 * t + 4);
        float e1[3], e2[3], n[3];
        e1[0] = positions[b].x - positions[a].x; e1[1] = positions[b].y - positions[a].y; e1[2] = positions[b].z - positions[a].z;
        e2[0] = positions[c].x - positions[a].x; e2[1] = positions[c].y - positions[a].y; e2[2] = positions[c].z - positions[a].z;
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        out[a].x += n[0]; out[a].y += n[1]; out[a].z += n[2];
        out[b].x += n[0]; out[b].y += n[1]; out[b].z += n[2];
        out[c].x += n[0]; out[c].y += n[1]; out[c].z += n[2];
    }
    /* normalize via the quaternion normalizer's arithmetic on (x,y,z,0) */
    sn_k_fnormals(out, nS);
#else
    /* sn_kernels_xnorm.c: the face normals summed at one shift for the mesh, then unit length */
    sn_k_xnormals(tris, h->v.nT, positions, nS, out);
#endif
    return SN_OK;
}

