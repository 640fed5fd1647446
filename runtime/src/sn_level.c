/* sn_level.c -- level of detail (issue 13; runtime/LEVELS.md): a blob may
 * carry a finer level, a complete blob of its own (LEVEL_BLOB) on the lattice
 * subdivided once (tools/sb_level.c), and two maps that place each level's
 * lattice vertices in the other's cells (LEVEL_UP, LEVEL_DOWN). The instance
 * is laid out for the larger counts of the two; sn_set_lod points its view
 * at the other level and carries the state (positions, velocities, the CG's
 * warm start) through the map: trilinear interpolation of the coarse field
 * onto the fine vertices (exact: the finer functions start at zero, seed 000
 * §3.1), and the fine field sampled at the coarse vertices (the detail
 * dropped). A step then costs what the active level's counts say. */
#include "sn_blended.h" /* SN_VIEW_BLENDED */
#include "sn_instance.h"
#include "sn_adapt.h"
#include "sn_cut.h" /* sn_cut_interp */

uint32_t sn_level_sec_count(const sn_view *v, int sec) {
    return sn_rd_u32(v->base + SN_H_SECTIONS + (size_t)sec * SN_SECTION_ENTRY + 8);
}

static int bytes_equal(const sn_view *a, const sn_view *b, int sec) {
    uint32_t na = sn_rd_u32(a->base + SN_H_SECTIONS + (size_t)sec * SN_SECTION_ENTRY + 4);
    uint32_t nb = sn_rd_u32(b->base + SN_H_SECTIONS + (size_t)sec * SN_SECTION_ENTRY + 4), i;
    if (na != nb) return 0;
    for (i = 0; i < na; i++) /* no memcmp: libc */
        if (a->sec[sec][i] != b->sec[sec][i]) return 0;
    return 1;
}

/* a map's entries: cell < nC of the lattice they point into, t in [0, 1] (Q15) */
static int map_ok(const unsigned char *m, uint32_t n, uint32_t nC) {
    uint32_t i, k;
    for (i = 0; i < n; i++) {
        if (sn_rd_u16(m + (size_t)i * SN_ELEM_LEVEL_MAP) >= nC) return 0;
        for (k = 1; k < 4; k++)
            if (sn_rd_u16(m + (size_t)i * SN_ELEM_LEVEL_MAP + 2 * k) > 32768u) return 0;
    }
    return 1;
}

sn_status sn_check_levels(const sn_view *c, const sn_view *f) {
    static const int same[] = {SN_SEC_JOINTS, SN_SEC_JOINT_NAMES, SN_SEC_TRIS, SN_SEC_CONTROLS, SN_SEC_SHARES,
                               SN_SEC_SEGNODES, SN_SEC_SEGATTACH, SN_SEC_CONSTRAINTS, SN_SEC_CREASE,
                               SN_SEC_CREASE_PAIRS, SN_SEC_CREASE_VNBR, SN_SEC_CREASE_TNBR};
    uint32_t k, i;
    /* one finer level: the nested blob has none of its own, and fills its section exactly */
    if (sn_level_sec_count(f, SN_SEC_LEVEL_BLOB) != 0 || sn_level_sec_count(f, SN_SEC_LEVEL_UP) != 0 ||
        sn_level_sec_count(f, SN_SEC_LEVEL_DOWN) != 0 || f->total != sn_level_sec_count(c, SN_SEC_LEVEL_BLOB))
        return SN_ERR_SECTION;
    /* the same character: joints, surface, controls, force slots, units and physics, and every
     * state the instance keeps outside the lattice (segment meshes, crease list, constraints) */
    if (f->nJ != c->nJ || f->nS != c->nS || f->nT != c->nT || f->nK != c->nK || f->nFrc != c->nFrc ||
        f->flags != c->flags || f->len_shift != c->len_shift || f->a1 != c->a1 || f->b1 != c->b1 ||
        f->grav[0] != c->grav[0] || f->grav[1] != c->grav[1] || f->grav[2] != c->grav[2] || f->timestep != c->timestep ||
        f->segB != c->segB || f->crB != c->crB || f->conB != c->conB)
        return SN_ERR_HEADER;
    for (k = 0; k < sizeof same / sizeof same[0]; k++)
        if (!bytes_equal(c, f, same[k])) return SN_ERR_VALUE;
    /* segment meshes: the same shapes (the reals differ: inverse masses are in each level's mass unit) */
    if (f->nM != c->nM) return SN_ERR_VALUE;
    for (k = 0; k < c->nM; k++)
        for (i = 0; i < 16u; i++)
            if (c->sec[SN_SEC_SEGMESH][(size_t)k * SN_ELEM_SEGMESH(SN_REAL_BYTES) + i] !=
                f->sec[SN_SEC_SEGMESH][(size_t)k * SN_ELEM_SEGMESH(SN_REAL_BYTES) + i])
                return SN_ERR_VALUE;
    /* the maps: every vertex of each level in a cell of the other */
    if (sn_level_sec_count(c, SN_SEC_LEVEL_UP) != f->nV || sn_level_sec_count(c, SN_SEC_LEVEL_DOWN) != c->nV)
        return SN_ERR_SECTION;
    if (!map_ok(c->sec[SN_SEC_LEVEL_UP], f->nV, c->nC) || !map_ok(c->sec[SN_SEC_LEVEL_DOWN], c->nV, f->nC))
        return SN_ERR_INDEX;
    return SN_OK;
}

/* the view of level lod (0: the blob itself) of a validated blob */
void sn_level_view(const unsigned char *top, uint32_t lod, sn_view *v) {
    sn_view_init(v, (const sn_blob *)(const void *)top);
    if (lod) sn_view_init(v, (const sn_blob *)(const void *)v->sec[SN_SEC_LEVEL_BLOB]);
}

void sn_level_counts(const sn_view *v, uint32_t *nV, uint32_t *nF, uint32_t *nC) {
    *nV = v->nV; *nF = v->nF; *nC = v->nC;
    if (sn_level_sec_count(v, SN_SEC_LEVEL_BLOB) != 0) {
        sn_view f;
        uint32_t sk = v->nV - v->nF;
        sn_view_init(&f, (const sn_blob *)(const void *)v->sec[SN_SEC_LEVEL_BLOB]);
        if (f.nF > *nF) *nF = f.nF;
        if (f.nV - f.nF > sk) sk = f.nV - f.nF;
        if (f.nC > *nC) *nC = f.nC;
        *nV = *nF + sk; /* room for the free and the skeleton vertices of either level */
    }
}

uint32_t sn_level_fpairs(const sn_view *v) {
    uint32_t n = sn_level_sec_count(v, SN_SEC_FPAIRS);
    if (sn_level_sec_count(v, SN_SEC_LEVEL_BLOB) != 0) { /* the nested blob's table (no view: init's stack) */
        uint32_t m = sn_rd_u32(v->sec[SN_SEC_LEVEL_BLOB] + SN_H_SECTIONS + SN_SEC_FPAIRS * SN_SECTION_ENTRY + 8);
        if (m > n) n = m;
    }
    return n;
}

uint32_t sn_lod_levels(const sn_blob *blob) {
    sn_view v;
    if (!blob) return 0;
    sn_view_init(&v, blob);
    return sn_level_sec_count(&v, SN_SEC_LEVEL_BLOB) != 0 ? 2u : 1u;
}

sn_status sn_set_lod(sn_instance *inst, uint32_t level) {
    sn_ihdr *h;
    sn_view top, dst;
    const unsigned char *map, *cells;
    sn_q *Sf, *Ss, *arr[3];
    uint32_t i, a, k, q, sat = 0, nsrc, nfsrc;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    sn_view_init(&top, (const sn_blob *)(const void *)h->lod_base);
    if (level >= 2u || (level == 1u && sn_level_sec_count(&top, SN_SEC_LEVEL_BLOB) == 0)) return SN_ERR_ARG;
    if (level == h->lod) return SN_OK;
    sn_level_view(h->lod_base, level, &dst);
    /* the map places each vertex of the new level in a cell of the old one */
    map = top.sec[level == 1u ? SN_SEC_LEVEL_UP : SN_SEC_LEVEL_DOWN];
    cells = h->v.sec[SN_SEC_CELLS];
    /* one quantity at a time (positions, velocities, warm start): the old
     * values into dead storage - free vertices into the vertex frames' array
     * (9 nF words, recomputed below from the pose), skeleton vertices into
     * d's (3 max(nF, nV - nF), a CG direction rebuilt by the next solve);
     * both are laid out for the larger level (sn_level_counts) - then each
     * new vertex from the old cell it lies in. Per component the sums are
     * the same whatever the pass order. */
    Sf = ARR(h, o_R, sn_q); Ss = ARR(h, o_d, sn_q);
    arr[0] = ARR(h, o_pos, sn_q); arr[1] = ARR(h, o_vel, sn_q); arr[2] = ARR(h, o_x, sn_q);
    nsrc = h->v.nV; nfsrc = h->v.nF;
    for (q = 0; q < 3; q++) {
        sn_q *val = arr[q];
        uint32_t ndst = q == 2 ? dst.nF : dst.nV;
        for (i = 0; i < nsrc; i++)
            for (k = 0; k < 3; k++) {
                if (i < nfsrc) Sf[3 * i + k] = val[3 * i + k];
                else Ss[3 * (i - nfsrc) + k] = q == 2 ? 0 : val[3 * i + k]; /* skeleton: no warm start */
            }
        for (i = 0; i < ndst; i++) {
            const unsigned char *e = map + (size_t)i * SN_ELEM_LEVEL_MAP, *cell = cells + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
            uint32_t t[3];
            sn_q phi[8];
            sn_acc acc[3] = {0, 0, 0};
            for (k = 0; k < 3; k++) t[k] = sn_rd_u16(e + 2 + 2 * k);
            sn_trilinear(t, phi);
            for (a = 0; a < 8; a++) {
                uint32_t vtx = sn_rd_u16(cell + 2 * a);
                const sn_q *src = vtx < nfsrc ? Sf + 3 * vtx : Ss + 3 * (vtx - nfsrc);
                for (k = 0; k < 3; k++) acc[k] += sn_mul(phi[a], src[k]);
            }
            if (h->v.cut) sn_cut_interp(&h->v, sn_rd_u16(e), t, Sf, Ss, acc); /* from the cut level: its field (sn_cut.c) */
            /* convex weights: no result exceeds its sources (the conversion never clamps; the cut level's may, counted) */
            for (k = 0; k < 3; k++) val[3 * i + k] = sn_out(acc[k], SN_Q_ROT, &sat);
        }
    }
    /* the instance keeps its size and its blended memory (sn_blended.c sits
     * after the top blob's instance_bytes, sized for the larger level) */
    dst.instance_bytes = h->v.instance_bytes;
    dst.flags |= h->v.flags & (SN_VIEW_BLENDED | SN_VIEW_SHARED);
    h->v = dst;
    h->lod = level;
    sn_k_table(h);
    sn_forces_clear(h);   /* pending forces name vertices of the old level */
    h->n_con = 0;         /* so may constraints (SN_AT_LATTICE, SN_AT_POINT): set them again */
    sn_frames_refresh(h, &sat); /* the new level's vertex and cell frames for the pose in force */
    sn_adapt_begin(h, &sat);    /* level 1: the first active set, the others onto the coarse field (sn_adapt.c) */
    h->saturations = sn_count(h->saturations, sat);
    return SN_OK;
}
