/* sn_segment_api.c -- segment meshes: the validator of the three segment
 * sections (runtime/BLOB.md, bounds derived in SEGMENTS.md) and the public calls (sinew.h, end). */
#include "sn_segment.h"

/* |x_a - x_b| within len/1024 + 2 LSB of len (fixed; float: len/1024 + 2^-20 len):
 * a writer rounding exact positions to the nearest LSB errs by <= sqrt(3) LSB */
static int spacing_ok(const unsigned char *nodes, uint32_t a, uint32_t b, const unsigned char *lenp) {
    unsigned k;
#if defined(SN_FLOAT)
    float n2 = 0.0f, len = sn_rd_f32(lenp), d;
    for (k = 0; k < 3; k++) {
        float x = sn_rd_f32(nodes + (3u * a + k) * 4u) - sn_rd_f32(nodes + (3u * b + k) * 4u);
        n2 += x * x;
    }
    d = n2 * sn_frsqrt(n2) - len;
    return d <= len * (1.0f / 1024 + 1.0f / 1048576) && d >= -len * (1.0f / 1024 + 1.0f / 1048576);
#else
    uint64_t n2 = 0;
    int64_t len = sn_rd_i32(lenp), d;
    for (k = 0; k < 3; k++) { /* |x| <= 2^27: |dx| <= 2^28, sum < 2^58 */
        int64_t x = (int64_t)sn_rd_i32(nodes + (3u * a + k) * 4u) - sn_rd_i32(nodes + (3u * b + k) * 4u);
        n2 += (uint64_t)(x * x);
    }
    d = (int64_t)sn_isqrt64(n2) - len;
    return d <= len / 1024 + 2 && d >= -(len / 1024 + 2);
#endif
}

sn_status sn_check_segments(const sn_view *v, uint32_t *segB) {
    uint32_t m, i, nsum = 0, asum = 0, bytes = 0;
    *segB = 0;
    for (m = 0; m < v->nM; m++) {
        const unsigned char *r = v->sec[SN_SEC_SEGMESH] + (size_t)m * SEG_REC, *R = r + 16;
        const unsigned char *nd = v->sec[SN_SEC_SEGNODES];
        unsigned kind = r[0], levels = r[1], sweeps = r[2], flags = r[3], side = sn_rd_u16(r + 4), na = sn_rd_u16(r + 6);
        uint32_t nodes, segs, alln, k, n = 0;
        int64_t ssum = 0;
        if (kind > SN_SEG_SHEET || sweeps < 1 || sweeps > SN_SEG_MAX_SWEEPS || (flags & ~SN_SEGF_NO_GRAVITY))
            return SN_ERR_VALUE;
        if (kind == SN_SEG_CHAIN) {
            if (side < 2 || side > SN_SEG_MAX_SIDE || levels != 1) return SN_ERR_VALUE;
            nodes = side;
        } else {
            if (side < 3 || side > SN_SEG_MAX_SHEET || ((side - 1u) & (side - 2u)) != 0) return SN_ERR_VALUE;
            while ((1u << n) < side - 1u) n++; /* side = 2^n + 1 */
            if (levels < 1 || levels > n + 1u || levels > SN_SEG_MAX_LEVELS) return SN_ERR_VALUE;
            nodes = side * side;
        }
        if (na > nodes) return SN_ERR_VALUE;
        if (sn_rd_u32(r + 8) != nsum || sn_rd_u32(r + 12) != asum) return SN_ERR_SECTION;
        if (nodes > v->nSN - nsum || na > v->nSA - asum) return SN_ERR_SECTION;
        /* seg_len: >= 2^-14 internal units (reciprocals keep 8+ bits), a
         * stretched mesh (side-1) len <= 2^27 (32 units): every node and
         * coarse length stays within the Q22 state range 2^28 */
        if (!sn_real_ok(R, 256, (int32_t)(((uint32_t)1 << 27) / (side - 1u)), SN_Q_LEN) ||
            !sn_real_ok(R + 4, 1, (int32_t)1 << 30, 30) ||        /* gamma (0, 1] */
            !sn_real_ok(R + 8, 0, (int32_t)1 << 30, 30) ||        /* keep [0, 1] */
            !sn_real_ok(R + 12, 1, INT32_MAX, 16) ||              /* inv_mass (0, 32768) */
            !sn_real_ok(R + 16, 0, (int32_t)1 << 30, 30))         /* centre [0, 1] */
            return SN_ERR_VALUE;
        {   /* format 6.2: coarse_sweeps (a one-level mesh: = sweeps), relax,
             * u16 0. omega = relax/32 in [1, 2) (SOR converges below 2), and
             * omega (1 - gamma) <= 1: the turn factors (sn_segment_sweep.c seg_kf,
             * move_seg) keep their int32 bound, a turn closes at most all of
             * the gap's perpendicular part */
            const unsigned char *X = R + 9 * SN_REAL_BYTES;
            unsigned cs = X[0], rx = X[1];
            if (cs < 1 || cs > SN_SEG_MAX_SWEEPS || (levels == 1 && cs != sweeps) || rx < SN_SEG_RELAX_ONE ||
                rx > SN_SEG_RELAX_MAX || sn_rd_u16(X + 2) != 0)
                return SN_ERR_VALUE;
#if defined(SN_FLOAT)
            if ((1.0f - sn_rd_f32(R + 4)) * (float)rx > 32.0f) return SN_ERR_VALUE;
#else
            if ((((int64_t)1 << 30) - sn_rd_i32(R + 4)) * (int64_t)rx > ((int64_t)1 << 35)) return SN_ERR_VALUE;
#endif
        }
        for (k = 0; k < SN_SEG_MAX_LEVELS; k++) {
            const unsigned char *p = R + 20 + 4 * k;
            if (!sn_real_ok(p, 0, (int32_t)1 << 30, 30)) return SN_ERR_VALUE;
            if (k >= levels && sn_rd_u32(p) != 0) return SN_ERR_VALUE;
#if defined(SN_FLOAT)
            ssum += (int64_t)(sn_rd_f32(p) * 1073741824.0f); /* within 2^-20: 1024 Q30 LSB */
#else
            ssum += sn_rd_i32(p);
#endif
        }
#if defined(SN_FLOAT)
        if (ssum < ((int64_t)1 << 30) - 1024 || ssum > ((int64_t)1 << 30) + 1024) return SN_ERR_VALUE;
#else
        if (ssum != (int64_t)1 << 30) return SN_ERR_VALUE;
#endif
        for (i = 0; i < 3u * nodes; i++)
            if (!sn_real_ok(nd + 4u * (3u * nsum + i), -((int32_t)1 << 27), (int32_t)1 << 27, SN_Q_LEN)) return SN_ERR_VALUE;
        for (i = 0; i < nodes; i++) { /* rest neighbours seg_len apart */
            uint32_t a = nsum + i;
            if (kind == SN_SEG_CHAIN) {
                if (i + 1u < nodes && !spacing_ok(nd, a, a + 1u, R)) return SN_ERR_VALUE;
            } else {
                if (i % side + 1u < side && !spacing_ok(nd, a, a + 1u, R)) return SN_ERR_VALUE;
                if (i / side + 1u < side && !spacing_ok(nd, a, a + side, R)) return SN_ERR_VALUE;
            }
        }
        for (i = 0; i < na; i++) {
            const unsigned char *at = v->sec[SN_SEC_SEGATTACH] + (size_t)(asum + i) * ATT_REC;
            unsigned ak = at[2];
            uint32_t tgt = sn_rd_u16(at + 4);
            if (sn_rd_u16(at) >= nodes || at[3] != 0 || sn_rd_u16(at + 6) != 0) return SN_ERR_INDEX;
            if (ak == SN_SEGATT_SURFACE) {
                if (tgt >= v->nS) return SN_ERR_INDEX;
                for (k = 0; k < 3; k++)
                    if (sn_rd_u32(at + 8 + 4 * k) != 0) return SN_ERR_VALUE;
            } else if (ak == SN_SEGATT_JOINT) {
                if (tgt >= v->nJ) return SN_ERR_INDEX;
                for (k = 0; k < 3; k++)
                    if (!sn_real_ok(at + 8 + 4 * k, -((int32_t)1 << 27), (int32_t)1 << 27, SN_Q_LEN)) return SN_ERR_VALUE;
            } else {
                return SN_ERR_VALUE;
            }
        }
        sn_seg_counts(kind, side, levels, &segs, &alln);
        bytes += SN_SEG_SEG_BYTES * segs + SN_SEG_NODE_BYTES * alln; /* < 2^20 per mesh, 64 meshes */
        nsum += nodes;
        asum += na;
    }
    if (nsum != v->nSN || asum != v->nSA) return SN_ERR_SECTION;
    *segB = bytes;
    return SN_OK;
}

/* ---------------- public calls ---------------- */

uint32_t sn_segment_mesh_count(const sn_blob *blob) {
    sn_view v;
    if (!blob) return 0;
    sn_view_init(&v, blob);
    return v.nM;
}

sn_status sn_segment_mesh_info(const sn_blob *blob, uint32_t mesh, sn_segment_info *out) {
    sn_view v;
    const unsigned char *r;
    uint32_t segs, nodes;
    if (!blob || !out) return SN_ERR_NULL;
    sn_view_init(&v, blob);
    if (mesh >= v.nM) return SN_ERR_ARG;
    r = v.sec[SN_SEC_SEGMESH] + (size_t)mesh * SEG_REC;
    out->kind = r[0];
    out->side = sn_rd_u16(r + 4);
    out->levels = r[1];
    out->attachments = sn_rd_u16(r + 6);
    sn_seg_counts(r[0], out->side, 1, &segs, &nodes);
    out->segments = segs;
    out->nodes = nodes;
    return SN_OK;
}

/* mesh m's level 0, or an error for bad arguments */
static sn_status level0(const sn_instance *inst, uint32_t mesh, const void *out, uint32_t first, uint32_t count,
                        int nodes, seg_mesh *M, seg_lvl *L) {
    const sn_ihdr *h;
    uint32_t n;
    SN_CHECK_INST(inst);
    if (!out) return SN_ERR_NULL;
    h = chdr_of(inst);
    if (mesh >= h->v.nM) return SN_ERR_ARG;
    seg_mesh_get(h, mesh, M);
    seg_level(M, 0, L);
    n = nodes ? L->nn : L->ns;
    if (first > n || count > n - first) return SN_ERR_ARG;
    return SN_OK;
}

sn_status sn_get_segment_nodes(const sn_instance *inst, uint32_t mesh, sn_vec3 *out, uint32_t first,
                               uint32_t count) {
    seg_mesh M;
    seg_lvl L;
    uint32_t i;
    sn_status st = level0(inst, mesh, out, first, count, 1, &M, &L);
    if (st != SN_OK) return st;
    for (i = 0; i < count; i++) sn_pub_point(chdr_of(inst), L.N + NODE_W * (first + i), out + i);
    return SN_OK;
}

/* Per segment: q = the shortest turn from the rest direction u0 to u (roll
 * about the segment is not tracked), pos = G_world - q G0_world, so that
 * q p + pos maps a rest-pose (model space, world units at reset) point p
 * rigidly with the segment. */
sn_status sn_get_segment_xforms(const sn_instance *inst, uint32_t mesh, sn_xform *out, uint32_t first,
                                uint32_t count) {
    seg_mesh M;
    seg_lvl L;
    const sn_ihdr *h;
    const unsigned char *j0, *nd;
    uint32_t i, a, b;
    unsigned k;
    sn_status st = level0(inst, mesh, out, first, count, 0, &M, &L);
    if (st != SN_OK) return st;
    h = chdr_of(inst);
    j0 = h->v.sec[SN_SEC_JOINTS] + 8;
    nd = h->v.sec[SN_SEC_SEGNODES];
    for (i = 0; i < count; i++) {
        const sn_q *S = L.S + SEG_W * (first + i);
        sn_q d[3], u0[3] = {SN_ONE_ROT, 0, 0}, q[4], Rm[9], G0[3];
        sn_vec3 g;
        uint32_t dummy = 0;
        seg_nodes(&L, first + i, &a, &b);
        for (k = 0; k < 3; k++) {
            sn_q pa = rd_real(nd, 3 * (M.first_node + a) + k), pb = rd_real(nd, 3 * (M.first_node + b) + k);
            d[k] = pb - pa; /* |x| <= 2^27: no overflow */
            /* the rest centre in the reset frame: its public position at reset is
             * pub(root rest + centre) (sn_reset: origin = the root's rest) */
#if defined(SN_FLOAT)
            G0[k] = 0.5f * (pa + pb) + rd_real(j0, k);
#else
            G0[k] = sn_add((sn_q)(((int64_t)pa + pb) >> 1), rd_real(j0, k), &dummy);
#endif
        }
        seg_unit(d, u0);
#if defined(SN_FLOAT)
        q[0] = u0[1] * S[5] - u0[2] * S[4];
        q[1] = u0[2] * S[3] - u0[0] * S[5];
        q[2] = u0[0] * S[4] - u0[1] * S[3];
        q[3] = 1.0f + u0[0] * S[3] + u0[1] * S[4] + u0[2] * S[5];
#else
        q[0] = sn_out(sn_mul_sub(u0[1], S[5], u0[2], S[4]), SN_Q_ROT + 1, &dummy);
        q[1] = sn_out(sn_mul_sub(u0[2], S[3], u0[0], S[5]), SN_Q_ROT + 1, &dummy);
        q[2] = sn_out(sn_mul_sub(u0[0], S[4], u0[1], S[3]), SN_Q_ROT + 1, &dummy);
        {
            int64_t w = ((int64_t)1 << 60) + sn_mul(u0[0], S[3]) + sn_mul(u0[1], S[4]) + sn_mul(u0[2], S[5]);
            q[3] = (sn_q)sn_rshr64(w < 0 ? 0 : w, SN_Q_ROT + 1);
        }
#endif
        sn_qnormalize(q);
        sn_qtomat(q, Rm);
        sn_pub_point(h, S, &g);
        {   /* pos = G_world - R G0_world */
            sn_q rr[3];
            sn_rot(Rm, G0, rr, &dummy);
#if defined(SN_FLOAT)
            out[i].pos.x = g.x - int_to_pub(h, rr[0]);
            out[i].pos.y = g.y - int_to_pub(h, rr[1]);
            out[i].pos.z = g.z - int_to_pub(h, rr[2]);
#else
            out[i].pos.x = clamp32((int64_t)g.x - int_to_pub64(h, rr[0]));
            out[i].pos.y = clamp32((int64_t)g.y - int_to_pub64(h, rr[1]));
            out[i].pos.z = clamp32((int64_t)g.z - int_to_pub64(h, rr[2]));
#endif
        }
        out[i].rot.x = q[0]; out[i].rot.y = q[1]; out[i].rot.z = q[2]; out[i].rot.w = q[3];
    }
    return SN_OK;
}

sn_status sn_apply_segment_impulse(sn_instance *inst, uint32_t mesh, uint32_t node, sn_vec3 impulse) {
    sn_ihdr *h;
    seg_mesh M;
    seg_lvl L;
    const sn_real J[3] = {impulse.x, impulse.y, impulse.z};
    sn_q *acc;
    uint32_t sat = 0;
    unsigned k;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    if (mesh >= h->v.nM) return SN_ERR_ARG;
#if defined(SN_FLOAT)
    for (k = 0; k < 3; k++)
        if (!(J[k] - J[k] == 0.0f)) return SN_ERR_ARG; /* NaN or infinite */
#endif
    seg_mesh_get(h, mesh, &M);
    seg_level(&M, 0, &L);
    if (node >= L.nn) return SN_ERR_ARG;
    acc = L.N + NODE_W * node + 3;
    /* velocity change per step of a segment of mass m0: dv~ = J FORCE / h
     * (SEGMENTS.md: FORCE F is the per-step velocity
     * change of mass m0 under F newtons for one step, and J = F h) */
    for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
        acc[k] = sn_add(acc[k], J[k] * h->v.force / h->v.timestep, &sat);
#else
        /* J Q16.16 x FORCE Q frac_F (< 2^62) / h Q16.16 (> 0) = Q frac_F, then to Q22 */
        int64_t x = ((int64_t)J[k] * h->v.force) / h->v.timestep;
        int s = h->v.frac_F - SN_Q_LEN;
        if (s > 0) x = sn_rshr64(x, s);
        else if (s < 0) {
            int64_t lim = s <= -31 ? 0 : ((int64_t)SN_LIM >> -s);
            if (x > lim) { x = lim; sat++; }
            if (x < -lim) { x = -lim; sat++; }
            x *= (int64_t)1 << -s;
        }
        acc[k] = sn_out((int64_t)acc[k] + sn_out(x > SN_ACC_LIM ? SN_ACC_LIM : (x < -SN_ACC_LIM ? -SN_ACC_LIM : x), 0, &sat), 0, &sat);
#endif
    }
    h->saturations = sn_count(h->saturations, sat);
    return SN_OK;
}

sn_status sn_set_segment_floor(sn_instance *inst, sn_vec3 normal, sn_real offset) {
    sn_ihdr *h;
    sn_q q[4];
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
#if defined(SN_FLOAT)
    if (!(normal.x - normal.x == 0.0f && normal.y - normal.y == 0.0f && normal.z - normal.z == 0.0f &&
          offset - offset == 0.0f))
        return SN_ERR_ARG;
#endif
    if (normal.x == 0 && normal.y == 0 && normal.z == 0) { h->floor_on = 0; return SN_OK; }
    q[0] = normal.x; q[1] = normal.y; q[2] = normal.z; q[3] = 0;
    sn_qnormalize(q);
    h->floor_n[0] = q[0]; h->floor_n[1] = q[1]; h->floor_n[2] = q[2];
    h->floor_off = offset;
    h->floor_on = 1;
    return SN_OK;
}
