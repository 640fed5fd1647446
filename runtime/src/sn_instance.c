/* sn_instance.c -- instance memory: layout, init, reset, settings, stats and
 * the determinism hash. The layout is the single source of the instance
 * size: the validator asks sn_instance_bytes for it, and writers' macro
 * SN_INSTANCE_BYTES (sn_format.h) is tested against it. */
#include "sn_blended.h" /* sn_instance.h, SN_VIEW_BLENDED */
#include "sn_adapt.h"
#include "sn_detail.h" /* the details' seats (sn_detail_step.c) */

/* hdr | acc nF*3 acc | per joint: wrench | force slots | segment state |
 * per joint: pose q4 t3, R9, T3 | per vertex: pos3 vel3 |
 * per free: R9 x3 r3 | d3 (max(nF, nV-nF) rows: ds shares it) | per free: q3 (z and w share it) |
 * per cell: R9 | per control: value |
 * crease state (crB: surface positions, list, membership; sn_crease.c) | per free: k (u8) |
 * (8-aligned) constraint state: records, colliders, rows, row state, factor (sn_cons_layout) |
 * (8-aligned) per frame pair: its slerp part (the step's scratch, sn_pose.c joint_frames)
 * Only free vertices keep a frame: a skeleton vertex's is its bone's jR
 * (BLOB.md: bone1 = bone2, w = 0), and every frame origin c is computed
 * where it is read (sn_vertex_origin). ds (skeleton velocity change) is live
 * from sn_skeleton to rhs's mass pass, d only inside the PCG loop: one
 * storage. q (the mat-vec's output) is dead from r -= alpha q to the next
 * mat-vec, z (the preconditioned residual) from d = z + beta d to the next
 * preconditioner call, and w (rhs's velocity term, over free vertices;
 * cell_forces computes the skeleton part) outside the PCG: one storage.
 * Between rhs and the PCG both are free: sn_contact_rows keeps its per-step
 * predictions there (free vertices' in q, skeleton vertices' in d).
 * The 8-byte arrays come first (the header and each of them are multiples
 * of 8). Array offsets into off[] in the order of SN_LAYOUT_ARRAYS; returns
 * the total, rounded up to 8. Counts are validated (nV <= 65535 ...): no wrap. */
#define SN_LAYOUT_ARRAYS 21
static uint32_t layout_offsets(uint32_t nV, uint32_t nF, uint32_t nJ, uint32_t nC, uint32_t nK,
                               uint32_t nFrc, uint32_t segB, uint32_t crB, uint32_t conB, uint32_t nFP,
                               uint32_t off[SN_LAYOUT_ARRAYS]) {
    const uint32_t nDS = nV - nF > nF ? nV - nF : nF; /* rows of d's storage: d (nF) or ds (nV - nF) */
    const uint32_t bytes[SN_LAYOUT_ARRAYS] = {
        nF * 3u * 8u, /* acc: 8 bytes per accumulator in both flavours */
        nJ * SN_WRENCH_BYTES, nFrc * SN_FORCE_SLOT_BYTES, segB,          /* wrench frc seg */
        nJ * 4u * 4u, nJ * 3u * 4u, nJ * 9u * 4u, nJ * 3u * 4u,          /* pq pt jR jT */
        nV * 3u * 4u, nV * 3u * 4u,                                      /* pos vel */
        nF * 9u * 4u, nF * 3u * 4u, nF * 3u * 4u,                       /* R x r */
        nDS * 3u * 4u, nF * 3u * 4u,                                     /* d (and ds) q */
        nC * 9u * 4u, nK * 4u, crB, nF,                                  /* cR ctl crease k */
        conB, nFP * SN_FPAIR_BYTES};                                      /* constraint state (sn_constraint.c), frame pairs: 8-aligned */
    uint32_t o = SN_HDR_BYTES, i;
    for (i = 0; i < SN_LAYOUT_ARRAYS; i++) {
        if (i >= SN_LAYOUT_ARRAYS - 2) o = (o + 7u) & ~7u;
        off[i] = o;
        o += bytes[i];
    }
    return (o + 7u) & ~7u;
}

uint32_t sn_instance_bytes(uint32_t nV, uint32_t nF, uint32_t nJ, uint32_t nC, uint32_t nK,
                           uint32_t nFrc, uint32_t segB, uint32_t crB, uint32_t conB, uint32_t nFP) {
    uint32_t off[SN_LAYOUT_ARRAYS];
    return layout_offsets(nV, nF, nJ, nC, nK, nFrc, segB, crB, conB, nFP, off);
}

/* sn_instance_init_shared's layout: the same arrays, the scratch ones
 * (frame pairs, acc, r, rows, row state, factor: written before read in every step) moved
 * to the workspace sn_step_with passes. State: hdr | workspace address | wrench frc seg | pq pt
 * jR jT | pos vel | R x | d q | cR ctl crease k | (8-aligned) records
 * colliders | (8-aligned) adaptation's state and mask. Workspace: frame pairs | acc | r |
 * rows | row state | factor | (8-aligned) the blended mode's arrays. (Frames
 * refreshed between steps, without a workspace, slerp each pair alone: sn_pose.c.)
 * d and q stay in the state: sn_set_lod and adaptation's sn_adapt_begin
 * (sn_reset, sn_set_adapt) use them between steps. Offsets into off[] in the
 * order of SN_LAYOUT_ARRAYS (off[19]: the records; *row: the rows in the
 * workspace; off[20]: the frame pairs, at the workspace's start); returns the
 * state bytes before adaptation's, *ws the workspace bytes before the blended mode's. */
static uint32_t shared_offsets(const sn_view *v, uint32_t off[SN_LAYOUT_ARRAYS], uint32_t *row, uint32_t *ws) {
    uint32_t nV, nF, nC, nDS, o = SN_HDR_BYTES + SN_WS_SLOT_BYTES, i; /* the workspace's address (sn_ws) */
    uint32_t bytes[SN_LAYOUT_ARRAYS], spB = sn_level_fpairs(v) * SN_FPAIR_BYTES;
    sn_level_counts(v, &nV, &nF, &nC); /* the largest level, as layout() */
    nDS = nV - nF > nF ? nV - nF : nF;
    bytes[0] = 0; bytes[12] = 0;      /* acc, r: in the workspace */
    bytes[1] = v->nJ * SN_WRENCH_BYTES; bytes[2] = v->nFrc * SN_FORCE_SLOT_BYTES; bytes[3] = v->segB;
    bytes[4] = v->nJ * 16u; bytes[5] = v->nJ * 12u; bytes[6] = v->nJ * 36u; bytes[7] = v->nJ * 12u;
    bytes[8] = nV * 12u; bytes[9] = nV * 12u; bytes[10] = nF * 36u; bytes[11] = nF * 12u;
    bytes[13] = nDS * 12u; bytes[14] = nF * 12u;
    bytes[15] = nC * 36u; bytes[16] = v->nK * 4u; bytes[17] = v->crB; bytes[18] = nF;
    bytes[19] = v->nCon * SN_CON_BYTES + v->nCol * SN_COL_BYTES;
    for (i = 1; i < SN_LAYOUT_ARRAYS - 1; i++) {
        if (i == 12) continue;
        if (i == SN_LAYOUT_ARRAYS - 2) o = (o + 7u) & ~7u;
        off[i] = o;
        o += bytes[i];
    }
    off[20] = 0;              /* the frame pairs first (8-byte fields, 40 bytes each), */
    off[0] = spB;             /* then acc: 8-byte accumulators, 8-aligned */
    off[12] = spB + nF * 24u;
    *row = off[12] + nF * 12u;
    *ws = (*row + v->nRows * (SN_ROW_BYTES + SN_ROWAUX_BYTES) + 4u * (v->nRows * (v->nRows + 1u) / 2u) + 7u) & ~7u;
    return (o + 7u) & ~7u;
}

static void set_offsets(sn_ihdr *h, const uint32_t off[SN_LAYOUT_ARRAYS], uint32_t row) {
    h->o_acc = off[0]; h->o_wr = off[1]; h->o_frc = off[2]; h->o_seg = off[3];
    h->o_pq = off[4]; h->o_pt = off[5]; h->o_jR = off[6]; h->o_jT = off[7];
    h->o_pos = off[8]; h->o_vel = off[9]; h->o_R = off[10]; h->o_x = off[11]; h->o_r = off[12];
    h->o_d = off[13]; h->o_ds = off[13]; h->o_q = off[14];
    h->o_cR = off[15]; h->o_ctl = off[16]; h->o_crs = off[17]; h->o_k = off[18];
    h->o_sp = off[20];
    sn_cons_layout(h, off[19], row);
}

/* The instance's own layout (sn_instance_init: scratch inside, at the offsets
 * of the format's SN_INSTANCE_BYTES), or the shared one (v.flags SN_VIEW_SHARED:
 * v.instance_bytes becomes the state's end, where adaptation's state goes). */
static void layout(sn_ihdr *h) {
    uint32_t off[SN_LAYOUT_ARRAYS], nV, nF, nC, row, ws;
    if (h->v.flags & SN_VIEW_SHARED) {
        h->v.instance_bytes = shared_offsets(&h->v, off, &row, &ws);
        set_offsets(h, off, row);
        return;
    }
    sn_level_counts(&h->v, &nV, &nF, &nC); /* the largest level (sn_level.c): one layout for every level */
    (void)layout_offsets(nV, nF, h->v.nJ, nC, h->v.nK, h->v.nFrc, h->v.segB, h->v.crB, h->v.conB, sn_level_fpairs(&h->v), off);
    set_offsets(h, off, off[19] + h->v.nCon * SN_CON_BYTES + h->v.nCol * SN_COL_BYTES);
}

size_t sn_instance_state_size(const sn_blob *blob) {
    sn_view v;
    uint32_t off[SN_LAYOUT_ARRAYS], row, ws;
    if (!blob) return 0;
    sn_view_init(&v, blob);
    return (size_t)shared_offsets(&v, off, &row, &ws) + sn_adapt_bytes(&v) + sn_detail_bytes(&v);
}

size_t sn_workspace_size(const sn_blob *blob, sn_mode mode) {
    sn_view v;
    uint32_t off[SN_LAYOUT_ARRAYS], row, ws, nV, nF, nC;
    if (!blob) return 0;
    sn_view_init(&v, blob);
    (void)shared_offsets(&v, off, &row, &ws);
    if (mode != SN_MODE_BLENDED) return ws;
    sn_level_counts(&v, &nV, &nF, &nC);
    return (size_t)ws + sn_blended_bytes(nF, nC);
}

uint32_t sn_blend_offset(const sn_ihdr *h) {
    if (h->v.flags & SN_VIEW_SHARED) /* after the factor (shared_offsets' *ws) */
        return (h->o_L + 4u * (h->v.nRows * (h->v.nRows + 1u) / 2u) + 7u) & ~7u;
    {
        const sn_dstate *ds = sn_detail_region(h); /* past adaptation's mask and the details' seats (sn_instance_size_mode) */
        return h->v.instance_bytes + h->ad_bytes + (ds ? ds->bytes : 0u);
    }
}

#if !defined(SN_FLOAT)
/* raw_pub = raw_int * 2^s with s = len_shift - 6 (fixed) */
sn_q pub_to_int_sat(const sn_ihdr *h, int64_t pub, uint32_t *sat) {
    int s = h->v.len_shift - (SN_Q_LEN - SN_LEN_FRAC);
    if (s >= 0) {
        if (pub > SN_ACC_LIM) pub = SN_ACC_LIM;
        if (pub < -SN_ACC_LIM) pub = -SN_ACC_LIM;
        return sn_out(pub, s, sat);
    } else {
        int64_t lim = (int64_t)SN_LIM >> -s;
        if (pub > lim) { (*sat)++; pub = lim; }
        if (pub < -lim) { (*sat)++; pub = -lim; }
        return (int32_t)(pub * ((int64_t)1 << -s));
    }
}
int64_t int_to_pub64(const sn_ihdr *h, sn_q v) {
    int s = h->v.len_shift - (SN_Q_LEN - SN_LEN_FRAC);
    return s >= 0 ? (int64_t)v * ((int64_t)1 << s) : sn_rshr64(v, -s);
}
#endif

/* Structural limits the unclamped sums rely on (NUMERICS.md, overflow
 * freedom), counted in the positions' and velocities' arrays (24 bytes per
 * vertex, rewritten by sn_reset; acc may be in a workspace):
 * each free vertex is the column of at most SN_MAX_ROW_BLOCKS mass rows and a
 * corner of at most SN_MAX_VERTEX_CELLS cells. */
static int structure_ok(sn_ihdr *h) {
    uint16_t *cnt = ARR(h, o_pos, uint16_t);
    const unsigned char *cols = h->v.sec[SN_SEC_COLS], *cells = h->v.sec[SN_SEC_CELLS];
    uint32_t e, nF = h->v.nF;
    memset(cnt, 0, 2u * nF * sizeof *cnt);
    for (e = 0; e < h->v.nnz; e++) {
        uint32_t j = sn_rd_u16(cols + 2 * e);
        if (j < nF && ++cnt[j] > SN_MAX_ROW_BLOCKS) return 0;
    }
    for (e = 0; e < 8u * h->v.nC; e++) {
        uint32_t a = sn_rd_u16(cells + 2 * e);
        if (a < nF && ++cnt[nF + a] > SN_MAX_VERTEX_CELLS) return 0;
    }
    return 1;
}

static sn_status init(void *mem, size_t mem_size, const sn_blob *blob, sn_instance **out, int shared) {
    sn_ihdr *h;
    if (!mem || !blob || !out) return SN_ERR_NULL;
    if (((uintptr_t)mem & 7u) != 0) return SN_ERR_ALIGN;
    if (mem_size < (shared ? sn_instance_state_size(blob) : sn_instance_size(blob))) return SN_ERR_MEMORY;
    memset(mem, 0, sizeof(sn_ihdr));
    h = (sn_ihdr *)mem;
    sn_view_init(&h->v, blob);
    if (shared) h->v.flags |= SN_VIEW_SHARED;
    layout(h);
    h->lod_base = h->v.base;
    if (sn_level_sec_count(&h->v, SN_SEC_LEVEL_BLOB) != 0) { /* the finer level's structure too, then level 0 */
        sn_level_view(h->lod_base, 1, &h->v);
        if (!structure_ok(h)) return SN_ERR_INDEX;
        sn_view_init(&h->v, blob);
        if (shared) {
            h->v.flags |= SN_VIEW_SHARED;
            layout(h); /* v.instance_bytes again: the state's end */
        }
    }
    if (!structure_ok(h)) return SN_ERR_INDEX;
    h->magic = SN_INST_MAGIC;
    /* blended mode: its arrays are in the instance (sized by sn_instance_size_mode), or in every workspace */
    if (shared || mem_size >= sn_instance_size_mode(blob, SN_MODE_BLENDED)) h->v.flags |= SN_VIEW_BLENDED;
    h->iterations = h->v.cg_default;
    h->mode = SN_MODE_WARPED;
    sn_adapt_init(h); /* the mask after the layout, before the blended arrays (sn_instance_size) */
    sn_detail_init(h); /* the details' seats after it */
#if defined(SN_FLOAT)
    {
        int k;
        h->to_pub = 1.0f;
        for (k = 0; k < h->v.len_shift; k++) h->to_pub *= 2.0f;
        for (k = 0; k < -h->v.len_shift; k++) h->to_pub *= 0.5f;
        h->to_int = 1.0f / h->to_pub;
    }
#endif
    sn_k_table(h);
    *out = (sn_instance *)mem;
    (void)sn_reset(*out);
    return SN_OK;
}

sn_status sn_instance_init(void *mem, size_t mem_size, const sn_blob *blob, sn_instance **out) {
    return init(mem, mem_size, blob, out, 0);
}

sn_status sn_instance_init_shared(void *mem, size_t mem_size, const sn_blob *blob, sn_instance **out) {
    return init(mem, mem_size, blob, out, 1);
}

void sn_k_table(sn_ihdr *h) {
    {   /* Force-like CG vectors (b, r, q) of free vertex i carry k_i extra
         * fractional bits. A row's forces scale with its diagonal block of A
         * (mass + stiffness of the vertex's support), so a barely-inside vertex
         * would otherwise have forces of a few LSBs that the preconditioner
         * amplifies, while a stiff one needs the range. k_i = bits between
         * this vertex's P_i = A_ii^-1 (trace) and the smallest, at most SN_KMAX. */
        uint8_t *kk = ARR(h, o_k, uint8_t);
        const unsigned char *P = h->v.sec[SN_SEC_PRECOND];
        uint32_t i;
#if !defined(SN_FLOAT)
        int bmin = 64;
        for (i = 0; i < h->v.nF; i++) {
            int64_t tr = (int64_t)rd_real(P, 6 * i) + rd_real(P, 6 * i + 1) + rd_real(P, 6 * i + 2);
            int b = bitlen64(tr > 0 ? (uint64_t)tr : 0u);
            bmin = b < bmin ? b : bmin;
        }
#endif
        for (i = 0; i < h->v.nF; i++) {
#if defined(SN_FLOAT)
            kk[i] = 0;
            (void)P;
#else
            int64_t tr = (int64_t)rd_real(P, 6 * i) + rd_real(P, 6 * i + 1) + rd_real(P, 6 * i + 2);
            int k = bitlen64(tr > 0 ? (uint64_t)tr : 0u) - bmin;
            k = k < 0 ? 0 : (k > SN_KMAX ? SN_KMAX : k);
            kk[i] = (uint8_t)k;
#endif
        }
    }
}

static void set_identity(sn_q *R, uint32_t n) {
    uint32_t i, k;
    for (i = 0; i < n; i++)
        for (k = 0; k < 9; k++) R[9 * i + k] = (k % 4 == 0) ? SN_ONE_ROT : 0;
}

sn_status sn_reset(sn_instance *inst) {
    sn_ihdr *h;
    const sn_view *v;
    uint32_t i, k, nV, nJ;
    sn_q *pq, *pt, *pos;
    const unsigned char *j0;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    v = &h->v;
    nV = v->nV;
    nJ = v->nJ;
    pq = ARR(h, o_pq, sn_q);
    pt = ARR(h, o_pt, sn_q);
    pos = ARR(h, o_pos, sn_q);
    j0 = v->sec[SN_SEC_JOINTS];
    /* zero the state (everything after the header, before the k table) */
    memset((unsigned char *)h + SN_HDR_BYTES, 0, h->o_k - SN_HDR_BYTES);
    h->steps = h->saturations = h->have_prev = 0;
    h->bound_steps = h->limit_clamps = h->limit_steps = h->cg_clamps = 0;
    h->disp = h->disp_max = h->energy = h->energy_max = 0;
    h->n_forces = h->force_drops = 0;
    h->seg_gap = h->seg_gap_max = 0;
    h->cr_n = h->cr_na = h->cr_rows = 0;
    h->cr_list_full = h->cr_active_over = h->cr_added = h->cr_removed = 0;
    /* rest pose: identity rotations (the quaternion tracking starts here), zero translations */
    for (i = 0; i < nJ; i++) {
        pq[4 * i + 3] = SN_ONE_ROT;
        pt[3 * i] = pt[3 * i + 1] = pt[3 * i + 2] = 0;
    }
    /* origin = root joint rest position (model space) */
    for (k = 0; k < 3; k++) {
        sn_q x = rd_real(j0 + 8, k);
#if defined(SN_FLOAT)
        h->origin[k] = int_to_pub(h, x);
#else
        h->origin[k] = clamp32(int_to_pub64(h, x));
#endif
    }
    for (i = 0; i < nV; i++)
        for (k = 0; k < 3; k++) pos[3 * i + k] = rd_real(v->sec[SN_SEC_REST], 3 * i + k);
    /* rest-pose frames so getters work before the first step */
    set_identity(ARR(h, o_R, sn_q), v->nF);
    set_identity(ARR(h, o_cR, sn_q), v->nC);
    sn_controls_reset(h);
    sn_segments_reset(h);
    sn_cons_reset(h);
    sn_detail_reset(h);
    if (h->ad_bytes) sn_ad(h)->refines = sn_ad(h)->coarsens = sn_ad(h)->overflow = 0;
    {
        uint32_t sat = 0; /* interpolation with convex weights: never clamps */
        sn_adapt_begin(h, &sat);
    }
    return SN_OK;
}

sn_status sn_set_adapt(sn_instance *inst, int on) {
    sn_ihdr *h;
    uint32_t sat = 0;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    if (!h->ad_bytes) return on ? SN_ERR_ARG : SN_OK;
    if ((uint32_t)(on != 0) == sn_ad(h)->on) return SN_OK;
    sn_ad(h)->on = on != 0;
    sn_adapt_begin(h, &sat);
    h->saturations = sn_count(h->saturations, sat);
    return SN_OK;
}

sn_status sn_set_iterations(sn_instance *inst, uint32_t iterations) {
    sn_ihdr *h;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    if (iterations > h->v.cg_max) return SN_ERR_ARG;
    h->iterations = iterations ? iterations : h->v.cg_default;
    return SN_OK;
}

sn_status sn_set_mode(sn_instance *inst, sn_mode mode) {
    sn_ihdr *h;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    if (mode != SN_MODE_WARPED && mode != SN_MODE_UNWARPED && mode != SN_MODE_BLENDED) return SN_ERR_ARG;
    if (mode == SN_MODE_BLENDED && !(h->v.flags & SN_VIEW_BLENDED)) return SN_ERR_MEMORY; /* init was not given sn_instance_size_mode bytes */
    h->mode = (uint32_t)mode;
    return SN_OK;
}

sn_status sn_get_stats(const sn_instance *inst, sn_stats *out) {
    const sn_ihdr *h;
    if (!inst || !out) return SN_ERR_NULL;
    h = chdr_of(inst);
    memset(out, 0, sizeof *out);
    if (h->magic != SN_INST_MAGIC) return SN_ERR_INSTANCE;
    out->steps = h->steps;
    out->saturations = h->saturations;
    out->iterations = h->iterations;
    out->mode = h->mode;
    out->bound_steps = h->bound_steps;
    out->limit_clamps = h->limit_clamps;
    out->limit_steps = h->limit_steps;
    out->cg_clamps = h->cg_clamps;
    out->disp = h->disp;
    out->disp_max = h->disp_max;
    out->energy = h->energy;
    out->energy_max = h->energy_max;
    out->force_drops = h->force_drops;
    out->seg_gap = h->seg_gap;
    out->seg_gap_max = h->seg_gap_max;
    out->crease_list = h->cr_n;
    out->crease_active = h->cr_na;
    out->crease_list_full = h->cr_list_full;
    out->crease_active_over = h->cr_active_over;
    out->crease_added = h->cr_added;
    out->crease_removed = h->cr_removed;
    out->constraint_rows = h->rows_kept;
    out->constraint_drops = h->row_drops;
    out->contacts = h->contacts;
    out->contact_overflow = h->contact_overflow;
    out->row_overflow = h->row_overflow;
    out->constraint_refused = h->con_refused;
    out->constraint_clamps = h->con_clamps;
    out->lod = h->lod;
    out->lattice_vertices = h->v.nV;
    if (h->ad_bytes) {
        const sn_adapt_state *a = sn_ad(h);
        out->adapt_active = a->active;
        out->adapt_refines = a->refines;
        out->adapt_coarsens = a->coarsens;
        out->adapt_overflow = a->overflow;
        out->adapt_on = a->on && h->lod == 1u;
    }
    {
        const sn_dstate *d = sn_detail_region(h);
        if (d && d->on && h->lod == 0u) { /* the details' adaptation on the cut level (sn_detail_adapt.c) */
            out->adapt_on = 1;
            out->adapt_active = d->n;
            out->adapt_refines = d->refines;
            out->adapt_coarsens = d->coarsens;
            out->adapt_overflow = d->overflow;
        }
    }
    return SN_OK;
}

/* ---- determinism hash: FNV-1a 64 over little-endian bytes ---- */
uint64_t sn_fnv_u32(uint64_t hsh, uint32_t x) {
    int b;
    for (b = 0; b < 4; b++) {
        hsh ^= (x >> (8 * b)) & 0xFFu;
        hsh *= 0x100000001B3ull;
    }
    return hsh;
}
static uint64_t fnv_q(uint64_t hsh, sn_q x) {
    uint32_t u;
    memcpy(&u, &x, 4);
    return sn_fnv_u32(hsh, u);
}

uint64_t sn_state_hash(const sn_instance *inst) {
    const sn_ihdr *h;
    const sn_q *pos, *vel, *x, *pq;
    uint64_t hsh = 0xCBF29CE484222325ull;
    uint32_t i;
    if (!inst || chdr_of(inst)->magic != SN_INST_MAGIC) return 0;
    h = chdr_of(inst);
    pos = CARR(h, o_pos, sn_q); vel = CARR(h, o_vel, sn_q); x = CARR(h, o_x, sn_q); pq = CARR(h, o_pq, sn_q);
    hsh = sn_fnv_u32(hsh, h->steps);
    hsh = sn_fnv_u32(hsh, h->saturations);
    hsh = sn_fnv_u32(hsh, h->bound_steps);
    hsh = sn_fnv_u32(hsh, h->limit_steps);
    for (i = 0; i < 3; i++) hsh = fnv_q(hsh, h->origin[i]);
    hsh = fnv_q(hsh, h->energy);
    for (i = 0; i < 4 * h->v.nJ; i++) hsh = fnv_q(hsh, pq[i]); /* tracked hemispheres */
    for (i = 0; i < 3 * h->v.nV; i++) hsh = fnv_q(hsh, pos[i]);
    for (i = 0; i < 3 * h->v.nV; i++) hsh = fnv_q(hsh, vel[i]);
    for (i = 0; i < 3 * h->v.nF; i++) hsh = fnv_q(hsh, x[i]);
    for (i = 0; i < h->v.nK; i++) hsh = fnv_q(hsh, CARR(h, o_ctl, sn_q)[i]); /* control values (none: unchanged) */
    hsh = sn_segments_hash(h, hsh); /* no segment meshes: unchanged */
    {   /* adaptation: the inactive set (no ADAPT section, or everything in the solve: unchanged) */
        uint32_t na;
        const uint8_t *m = sn_adapt_mask_bytes(h, &na);
        for (i = 0; i < na; i++)
            if (!m[i]) hsh = sn_fnv_u32(hsh, i);
    }
    hsh = sn_detail_hash(h, hsh); /* no seat filled: unchanged */
    return sn_crease_hash(h, hsh);   /* no crease sections: unchanged */
}
