/* sn_pose.c -- pose input and forward kinematics (public API), and steps
 * 1-3 of the step: joint transforms, the origin, vertex and cell frames
 * (seed 003 §3.3, per cell as its closing remark suggests), skeleton vertices
 * (runtime/NUMERICS.md "One step"). */
#include "sn_instance.h"
#include "sn_kernels_rot.h" /* the M4's sn_k_rot */

/* A usable joint transform: a quaternion whose largest component is at least
 * 2^-10 (a shorter one has no reliable direction: normalizing it would turn a
 * rounding error into a rotation) and, in float, every value finite and every
 * translation within the fixed format's +-32768 mesh units. */
static int xform_ok(const sn_xform *x) {
    const sn_real r[4] = {x->rot.x, x->rot.y, x->rot.z, x->rot.w};
    int k, big = 0;
#if defined(SN_FLOAT)
    const sn_real t[3] = {x->pos.x, x->pos.y, x->pos.z};
    for (k = 0; k < 4; k++) {
        if (!(r[k] - r[k] == 0.0f)) return 0; /* NaN or infinite */
        big |= r[k] >= 1.0f / 1024.0f || r[k] <= -1.0f / 1024.0f;
    }
    for (k = 0; k < 3; k++)
        if (!(t[k] <= 32768.0f && t[k] >= -32768.0f)) return 0; /* also NaN */
#else
    for (k = 0; k < 4; k++) big |= r[k] >= (1 << 20) || r[k] <= -(1 << 20); /* Q30 */
#endif
    return big;
}

/* The checks sn_set_pose and sn_teleport share: the whole pose is refused,
 * changing nothing, if any joint is unusable. */
static sn_status pose_ok(sn_instance *inst, const sn_xform *joints, uint32_t n_joints) {
    uint32_t j;
    if (!inst || !joints) return SN_ERR_NULL;
    if (inst_status(inst) != SN_OK) return SN_ERR_INSTANCE;
    if (n_joints != hdr_of(inst)->v.nJ) return SN_ERR_ARG;
    for (j = 0; j < n_joints; j++)
        if (!xform_ok(&joints[j])) return SN_ERR_ARG;
    return SN_OK;
}

/* Joint j's new pose: its quaternion normalized, with the sign (q and -q are
 * one rotation) nearer ref, and its translation. */
static void store_joint(sn_ihdr *h, uint32_t j, const sn_xform *x, const sn_q ref[4]) {
    sn_q *pq = ARR(h, o_pq, sn_q), *pt = ARR(h, o_pt, sn_q), q[4];
    sn_acc dq;
    q[0] = x->rot.x; q[1] = x->rot.y; q[2] = x->rot.z; q[3] = x->rot.w;
    sn_qnormalize(q);
    dq = sn_mul(q[0], ref[0]) + sn_mul(q[1], ref[1]) + sn_mul(q[2], ref[2]) + sn_mul(q[3], ref[3]);
    if (dq < 0) { q[0] = -q[0]; q[1] = -q[1]; q[2] = -q[2]; q[3] = -q[3]; }
    memcpy(pq + 4 * j, q, sizeof q);
    pt[3 * j] = x->pos.x;
    pt[3 * j + 1] = x->pos.y;
    pt[3 * j + 2] = x->pos.z;
}

sn_status sn_set_pose(sn_instance *inst, const sn_xform *joints, uint32_t n_joints) {
    sn_status st = pose_ok(inst, joints, n_joints);
    uint32_t j;
    if (st != SN_OK) return st;
    /* track the hemisphere: keep the sign nearer the joint's previous
     * quaternion so frames interpolate the way the joint really turned
     * (NUMERICS.md step 1) */
    for (j = 0; j < n_joints; j++) {
        sn_q prev[4];
        memcpy(prev, CARR(hdr_of(inst), o_pq, sn_q) + 4 * j, sizeof prev);
        store_joint(hdr_of(inst), j, &joints[j], prev);
    }
    return SN_OK;
}

/* ---- forward kinematics (public units) ---- */
void sn_pose_from_local(const sn_blob *blob, const sn_quat *local, const sn_vec3 *root_offset,
                        sn_xform *out) {
    sn_view v;
    uint32_t j;
    sn_view_init(&v, blob);
    for (j = 0; j < v.nJ; j++) {
        sn_vec3 x, rx, d;
        int32_t p = sn_joint_parent(blob, j);
        sn_quat ql = local[j];
        (void)sn_joint_rest(blob, j, &x);
        {   /* normalize the caller's local rotation */
            sn_q q[4];
            q[0] = ql.x; q[1] = ql.y; q[2] = ql.z; q[3] = ql.w;
            sn_qnormalize(q);
            ql.x = q[0]; ql.y = q[1]; ql.z = q[2]; ql.w = q[3];
        }
        /* rotation about the joint's rest position: x -> Rl (x - xj) + xj */
        rx = sn_quat_rotate(ql, x);
        d.x = pub_sub(x.x, rx.x); d.y = pub_sub(x.y, rx.y); d.z = pub_sub(x.z, rx.z);
        if (p < 0) {
            out[j].rot = ql;
            out[j].pos = d;
            if (root_offset) {
                out[j].pos.x = pub_add(out[j].pos.x, root_offset->x);
                out[j].pos.y = pub_add(out[j].pos.y, root_offset->y);
                out[j].pos.z = pub_add(out[j].pos.z, root_offset->z);
            }
        } else {
            /* T_j = T_p o local: R = Rp Rl, t = Rp (xj - Rl xj) + tp */
            const sn_xform *tp = &out[p];
            sn_vec3 rd = sn_quat_rotate(tp->rot, d);
            out[j].rot = sn_quat_mul(tp->rot, ql);
            out[j].pos.x = pub_add(rd.x, tp->pos.x);
            out[j].pos.y = pub_add(rd.y, tp->pos.y);
            out[j].pos.z = pub_add(rd.z, tp->pos.z);
        }
    }
}

/* Origin c = (1-w) T_b1 + w T_b2 of a (b1, b2, w) frame entry in `mode`
 * (unwarped: the root's T). A convex combination of translations within the
 * state range (w <= 1 validated; each T clamped): never clamped, so it is
 * computed where it is read instead of stored. */
static void origin_of(const sn_ihdr *h, const unsigned char *f, uint32_t mode, sn_q c[3]) {
    const sn_q *jT = CARR(h, o_jT, sn_q);
    uint32_t b1 = f[0], b2 = f[1], w = sn_rd_u16(f + 2), k;
    if (mode == SN_MODE_UNWARPED) {
        for (k = 0; k < 3; k++) c[k] = jT[k];
    } else if (b1 == b2 || w == 0) {
        memcpy(c, jT + 3 * b1, 3 * sizeof(sn_q));
    } else {
#if defined(SN_FLOAT)
        sn_q t = (float)w * (1.0f / 32768.0f);
        for (k = 0; k < 3; k++) c[k] = jT[3 * b1 + k] + t * (jT[3 * b2 + k] - jT[3 * b1 + k]);
#else
        uint32_t none = 0; /* |result| <= SN_LIM: no clamp */
        for (k = 0; k < 3; k++) {
            int64_t a = jT[3 * b1 + k], b = jT[3 * b2 + k];
            c[k] = sn_out(a * 32768 + (b - a) * (int64_t)w, SN_Q_W, &none);
        }
#endif
    }
}

void sn_vertex_origin(const sn_ihdr *h, uint32_t i, sn_q c[3]) {
    origin_of(h, h->v.sec[SN_SEC_FRAMES] + 4 * (size_t)i, h->frame_mode, c);
}

/* Rotation of a vertex's or cell's frame from its (b1, b2, w) entry:
 * R = slerp_path(q_b1, q_b2, w) (seed 003 §3.3), the bone's jR when w = 0.
 * rf: FREFS (entry ri's reference: an earlier entry with the same
 * (b1, b2, w), whose frame is copied, or the pair whose slerp part sp holds),
 * or NULL; sp: this pose's pair parts, or NULL (slerped alone:
 * sn_qslerp_path is the pair part and sn_qslerp_at in a row, the same bits,
 * test_runtime_math). */
static void frame_of(const sn_ihdr *h, const unsigned char *f, sn_q *R, const unsigned char *rf, uint32_t ri,
                     const sn_slerp_pair *sp) {
    const sn_q *pq = CARR(h, o_pq, sn_q), *jR = CARR(h, o_jR, sn_q);
    uint32_t b1 = f[0], b2 = f[1], w = sn_rd_u16(f + 2), k;
    if (h->mode == SN_MODE_UNWARPED) { /* global linear: R = I */
        for (k = 0; k < 9; k++) R[k] = (k % 4 == 0) ? SN_ONE_ROT : 0;
    } else if (b1 == b2 || w == 0) {
        memcpy(R, jR + 9 * b1, 9 * sizeof(sn_q));
    } else {
        const sn_slerp_pair *p = NULL;
        sn_q q[4];
#if defined(SN_FLOAT)
        sn_q t = (float)w * (1.0f / 32768.0f);
#else
        sn_q t = (sn_q)(w << (SN_Q_ROT - SN_Q_W));
#endif
        if (rf) {
            uint32_t r = sn_rd_u32(rf + 4 * (size_t)ri);
            if (!(r & SN_FREF_PAIR)) { /* a frame is a function of its entry and the pose: the same bits */
                memcpy(R, r < h->v.nF ? CARR(h, o_R, sn_q) + 9 * r : CARR(h, o_cR, sn_q) + 9 * (r - h->v.nF),
                       9 * sizeof(sn_q));
                return;
            }
            if (sp) p = sp + (r & ~SN_FREF_PAIR);
        }
        if (p) sn_qslerp_at(pq + 4 * b1, pq + 4 * b2, p, t, q);
        else sn_qslerp_path(pq + 4 * b1, pq + 4 * b2, t, q);
        sn_qtomat(q, R);
    }
}

/* Frame references (format 6.4, BLOB.md "Frame references"): FPAIRS' pairs
 * distinct (strictly increasing), bones < nJ and different; each FREFS
 * entry SN_FREF_BONE exactly when its frame does not slerp, else a pair
 * < nFP with its entry's bones, or an earlier entry with its 4 bytes. So a
 * referenced frame holds the bits its own entry gives (frame_of), and every
 * index the step follows is in range. Both counts 0: no references. */
sn_status sn_check_frefs(const sn_view *v, uint32_t nfp, uint32_t nfr) {
    const unsigned char *pr = sn_sec(v, SN_SEC_FPAIRS), *rf = sn_sec(v, SN_SEC_FREFS);
    uint32_t i, prev = 0;
    if (nfr == 0) return nfp == 0 ? SN_OK : SN_ERR_SECTION;
    for (i = 0; i < nfp; i++) {
        uint32_t b1 = pr[2 * i], b2 = pr[2 * i + 1], key = b1 << 8 | b2;
        if (b1 >= v->nJ || b2 >= v->nJ || b1 == b2) return SN_ERR_INDEX;
        if (i > 0 && key <= prev) return SN_ERR_VALUE;
        prev = key;
    }
    for (i = 0; i < nfr; i++) {
        const unsigned char *f = i < v->nF ? v->sec[SN_SEC_FRAMES] + 4 * (size_t)i
                                           : v->sec[SN_SEC_CFRAMES] + 4 * (size_t)(i - v->nF);
        uint32_t r = sn_rd_u32(rf + 4 * (size_t)i), k;
        if (f[0] == f[1] || sn_rd_u16(f + 2) == 0) {
            if (r != SN_FREF_BONE) return SN_ERR_VALUE;
        } else if (r & SN_FREF_PAIR) {
            r &= ~SN_FREF_PAIR;
            if (r >= nfp) return SN_ERR_INDEX;
            if (pr[2 * r] != f[0] || pr[2 * r + 1] != f[1]) return SN_ERR_VALUE;
        } else {
            const unsigned char *g;
            if (r >= i) return SN_ERR_INDEX;
            g = r < v->nF ? v->sec[SN_SEC_FRAMES] + 4 * (size_t)r : v->sec[SN_SEC_CFRAMES] + 4 * (size_t)(r - v->nF);
            for (k = 0; k < 4; k++)
                if (g[k] != f[k]) return SN_ERR_VALUE;
        }
    }
    return SN_OK;
}

/* Joint rotations R_j from the pose quaternions, and the root joint's world
 * position R_0 x_root + t_0 in public units (the origin the step follows). */
static void joint_rotations(sn_ihdr *h, sn_real target[3], uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *pq = CARR(h, o_pq, sn_q), *pt = CARR(h, o_pt, sn_q);
    sn_q *jR = ARR(h, o_jR, sn_q), xroot[3], rx[3];
    uint32_t j, k;
    for (k = 0; k < 3; k++) xroot[k] = rd_real(v->sec[SN_SEC_JOINTS] + 8, k);
    for (j = 0; j < v->nJ; j++) sn_qtomat(pq + 4 * j, jR + 9 * j);
    sn_rot(jR, xroot, rx, sat);
    for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
        target[k] = pt[k] + int_to_pub(h, rx[k]);
#else
        target[k] = clamp32((int64_t)pt[k] + int_to_pub64(h, rx[k]));
#endif
    }
}

/* Effective joint translations T_j = R_j x_root + (t_j - o) (internal units),
 * then the frames of every free vertex and cell. */
static void joint_frames(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *pt = CARR(h, o_pt, sn_q), *jR = CARR(h, o_jR, sn_q), *pq = CARR(h, o_pq, sn_q);
    sn_q *jT = ARR(h, o_jT, sn_q), *R = ARR(h, o_R, sn_q);
    sn_q *cR = ARR(h, o_cR, sn_q), xroot[3], rx[3];
    const unsigned char *fr = v->sec[SN_SEC_FRAMES], *cfr = v->sec[SN_SEC_CFRAMES];
    /* FREFS (format 6.4): repeats copy an earlier frame, and each bone pair's
     * slerp part is computed once, into the step's scratch (the instance's,
     * or the workspace's: none between steps of a shared instance) */
    const unsigned char *rf = sn_level_sec_count(v, SN_SEC_FREFS) ? sn_sec(v, SN_SEC_FREFS) : NULL;
    unsigned char *ws = sn_ws(h);
    sn_slerp_pair *sp = rf && ws && h->mode != SN_MODE_UNWARPED ? (sn_slerp_pair *)(void *)(ws + h->o_sp) : NULL;
    uint32_t i, j, k;
    if (sp) {
        const unsigned char *pr = sn_sec(v, SN_SEC_FPAIRS);
        uint32_t n = sn_level_sec_count(v, SN_SEC_FPAIRS);
        for (i = 0; i < n; i++) sn_qslerp_pair(pq + 4 * pr[2 * i], pq + 4 * pr[2 * i + 1], 1, sp + i);
    }
    for (k = 0; k < 3; k++) xroot[k] = rd_real(v->sec[SN_SEC_JOINTS] + 8, k);
    for (j = 0; j < v->nJ; j++) {
        sn_rot(jR + 9 * j, xroot, rx, sat);
        for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
            jT[3 * j + k] = rx[k] + pub_to_int(h, pt[3 * j + k] - h->origin[k]);
#else
            sn_q tj = pub_to_int_sat(h, (int64_t)pt[3 * j + k] - h->origin[k], sat);
            jT[3 * j + k] = sn_add(rx[k], tj, sat);
#endif
        }
    }
    for (i = 0; i < v->nF; i++) /* free vertices only: a skeleton vertex's frame is its bone's jR */
        frame_of(h, fr + 4 * i, R + 9 * i, rf, i, sp);
    for (i = 0; i < v->nC; i++)
        frame_of(h, cfr + 4 * i, cR + 9 * i, rf, v->nF + i, sp);
    h->frame_mode = h->mode;
}

void sn_frames_refresh(sn_ihdr *h, uint32_t *sat) { joint_frames(h, sat); }

/* Steps 1-2: rigid joint transforms, the origin, and the frames of every
 * lattice vertex and cell for the current pose. */
void sn_frames(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    sn_q *pos = ARR(h, o_pos, sn_q);
    sn_real target[3];
    sn_q delta_int[3];
    uint32_t i, k;
    joint_rotations(h, target, sat);
    /* origin follows the root joint's world position */
    for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
        delta_int[k] = pub_to_int(h, target[k] - h->origin[k]);
        h->origin[k] = target[k];
#else
        int s = v->len_shift - (SN_Q_LEN - SN_LEN_FRAC);
        int64_t delta = (int64_t)target[k] - h->origin[k], exact;
        delta_int[k] = pub_to_int_sat(h, delta, sat);
        /* move the origin only by what the internal format represents exactly */
        exact = s >= 0 ? (int64_t)delta_int[k] * ((int64_t)1 << s) : sn_rshr64(delta_int[k], -s);
        h->origin[k] = clamp32((int64_t)h->origin[k] + exact);
#endif
    }
    if (!h->have_prev) { delta_int[0] = delta_int[1] = delta_int[2] = 0; }
    for (i = 0; i < v->nV; i++)
        for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
            pos[3 * i + k] = sn_add(pos[3 * i + k], -delta_int[k], sat);
#else
            pos[3 * i + k] = sn_out((int64_t)pos[3 * i + k] - delta_int[k], 0, sat);
#endif
        }
    joint_frames(h, sat);
}

/* M = A B^T of two rotations (Q30); entries of a product of unit rotations
 * stay within [-1, 1], the clamp only guards rounding (not a state clamp). */
static void mul_abt(const sn_q *A, const sn_q *B, sn_q *M) {
    uint32_t r, c;
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++) {
            sn_acc m = sn_mul(A[3 * r], B[3 * c]) + sn_mul(A[3 * r + 1], B[3 * c + 1]) +
                       sn_mul(A[3 * r + 2], B[3 * c + 2]);
#if defined(SN_FLOAT)
            M[3 * r + c] = m;
#else
            m = sn_rshr64(m, SN_Q_ROT);
            M[3 * r + c] = (sn_q)(m > SN_ONE_ROT ? SN_ONE_ROT : (m < -SN_ONE_ROT ? -SN_ONE_ROT : m));
#endif
        }
}
/* out = M a, rounded once (the product is kept at full precision) */
static void carry(const sn_q *M, const sn_q a[3], sn_q out[3], uint32_t *sat) {
    uint32_t k;
    for (k = 0; k < 3; k++)
        out[k] = sn_out(sn_mul(M[3 * k], a[0]) + sn_mul(M[3 * k + 1], a[1]) + sn_mul(M[3 * k + 2], a[2]),
                        SN_Q_ROT, sat);
}

/* Pass 1 of the teleport's carry for vertex i, with M = A B^T (A the new
 * frame, B the old; exactly I when they hold the same bits, so a pure move
 * is exact): pos <- M (p - c) with the old origin c (jT and frame_mode are
 * still the old frames'), vel <- M vel, and the warm start x of a free vertex. */
static void carry_vertex(sn_ihdr *h, uint32_t i, const sn_q *A, const sn_q *B, uint32_t *sat) {
    sn_q *pos = ARR(h, o_pos, sn_q), *vel = ARR(h, o_vel, sn_q), *x = ARR(h, o_x, sn_q);
    sn_q M[9], off[3], c[3];
    uint32_t k, diff = 0;
    mul_abt(A, B, M);
    for (k = 0; k < 9; k++) diff |= A[k] != B[k]; /* no memcmp: libc */
    if (!diff)
        for (k = 0; k < 9; k++) M[k] = (k % 4 == 0) ? SN_ONE_ROT : 0;
    sn_vertex_origin(h, i, c);
    for (k = 0; k < 3; k++) off[k] = sn_add(pos[3 * i + k], -c[k], sat);
    carry(M, off, pos + 3 * i, sat);
    memcpy(off, vel + 3 * i, sizeof off);
    carry(M, off, vel + 3 * i, sat);
    if (i < h->v.nF) {
        memcpy(off, x + 3 * i, sizeof off);
        carry(M, off, x + 3 * i, sat);
    }
}

sn_status sn_teleport(sn_instance *inst, const sn_xform *joints, uint32_t n_joints) {
    sn_ihdr *h;
    const sn_view *v;
    const unsigned char *fr;
    sn_q *pq, *R, *pos, *jR;
    sn_q d0[4], q0old[4], Rroot[9], T0old[3];
    sn_real target[3];
    uint32_t i, j, k, sat = 0;
    sn_status st = pose_ok(inst, joints, n_joints);
    if (st != SN_OK) return st;
    h = hdr_of(inst);
    if (!h->have_prev) return sn_set_pose(inst, joints, n_joints); /* nothing to carry yet */
    v = &h->v;
    fr = v->sec[SN_SEC_FRAMES];
    pq = ARR(h, o_pq, sn_q); jR = ARR(h, o_jR, sn_q);
    R = ARR(h, o_R, sn_q); pos = ARR(h, o_pos, sn_q);
    memcpy(q0old, pq, sizeof q0old);
    memcpy(Rroot, jR, sizeof Rroot); /* the root's rotation of the state's frames */
    memcpy(T0old, ARR(h, o_jT, sn_q), sizeof T0old); /* the root's internal position (segment meshes) */
    /* New quaternions. The root keeps the sign nearest its old one; every
     * other joint the sign nearest its old quaternion carried by the root's
     * turn D = q0' conj(q0), so the winding between bones is kept. */
    store_joint(h, 0, &joints[0], q0old);
    {
        sn_q cq[4];
        cq[0] = -q0old[0]; cq[1] = -q0old[1]; cq[2] = -q0old[2]; cq[3] = q0old[3];
        sn_qmul(pq, cq, d0);
    }
    for (j = 1; j < n_joints; j++) {
        sn_q ref[4];
        sn_qmul(d0, pq + 4 * j, ref); /* the old quaternion (still stored) carried by D */
        store_joint(h, j, &joints[j], ref);
    }
    /* each vertex keeps its offset from its frame, p' = M (p - c) + c', and its
     * velocity and warm start turn with it, v' = M v, with M = R' R^T (the
     * root's turn in the unwarped mode, whose frames do not rotate). Pass 1:
     * pos <- M (p - c) with the old frames; pass 2, after the new
     * translations and frames: pos += c'. Skeleton vertices first, while jR
     * still holds the old rotations: a skeleton vertex's frame is its bone's
     * (BLOB.md: bone1 = bone2, w = 0), R = old jR_b (I if the frames were
     * built unwarped), R' = the new one by joint_rotations' own conversion. */
    {
        sn_q Rn0[9], Rn[9], Rold[9];
        sn_qtomat(pq, Rn0); /* the root's new jR */
        for (i = v->nF; i < v->nV; i++) {
            uint32_t b = fr[4 * i];
            if (h->frame_mode == SN_MODE_UNWARPED)
                for (k = 0; k < 9; k++) Rold[k] = (k % 4 == 0) ? SN_ONE_ROT : 0;
            else memcpy(Rold, jR + 9 * b, sizeof Rold);
            if (h->mode == SN_MODE_UNWARPED) carry_vertex(h, i, Rn0, Rroot, &sat);
            else {
                sn_qtomat(pq + 4 * b, Rn);
                carry_vertex(h, i, Rn, Rold, &sat);
            }
        }
    }
    /* the origin jumps to the new root position exactly: nothing is shifted */
    joint_rotations(h, target, &sat);
    for (k = 0; k < 3; k++) h->origin[k] = target[k];
    for (i = 0; i < v->nF; i++) { /* free vertices: frame_of reads only the new jR for R' */
        sn_q Rn[9];
        if (h->mode == SN_MODE_UNWARPED) carry_vertex(h, i, jR, Rroot, &sat);
        else {
            frame_of(h, fr + 4 * i, Rn, NULL, 0, NULL);
            carry_vertex(h, i, Rn, R + 9 * i, &sat);
        }
    }
    joint_frames(h, &sat); /* T_j for the new origin, R', cell frames */
    for (i = 0; i < v->nV; i++) {
        sn_q c[3];
        sn_vertex_origin(h, i, c); /* c' */
        for (k = 0; k < 3; k++) pos[3 * i + k] = sn_add(pos[3 * i + k], c[k], &sat);
    }
    {   /* segment meshes: rigidly with the root (the root's turn, exactly I if unturned) */
        sn_q Mr[9];
        uint32_t diff = 0;
        for (k = 0; k < 9; k++) diff |= jR[k] != Rroot[k];
        mul_abt(jR, Rroot, Mr);
        if (!diff)
            for (k = 0; k < 9; k++) Mr[k] = (k % 4 == 0) ? SN_ONE_ROT : 0;
        sn_segments_teleport(h, Mr, T0old, ARR(h, o_jT, sn_q), &sat);
    }
    h->saturations = sn_count(h->saturations, sat);
    return SN_OK;
}

/* New skeleton positions p'_k = R_b x_k + T_b into pos, ds = v'_k - v_k,
 * vel_S = v'_k. First pose after init/reset: the flesh is placed rigidly by its
 * frames (R_i x_i + c_i) and all velocities are zero. */
void sn_skeleton(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *jR = CARR(h, o_jR, sn_q), *jT = CARR(h, o_jT, sn_q);
    const sn_q *R = CARR(h, o_R, sn_q);
    sn_q *pos = ARR(h, o_pos, sn_q), *vel = ARR(h, o_vel, sn_q), *ds = ARR(h, o_ds, sn_q); /* ds: in d's storage, live until rhs */
    const unsigned char *fr = v->sec[SN_SEC_FRAMES], *rest = v->sec[SN_SEC_REST];
    uint32_t i, k;
#if defined(SN_K_SKEL) /* x86-64 float: the loop below in lanes (sn_kernels.h) */
    if (h->have_prev) sn_k_skeleton(jR, jT, fr, rest, v->nF, v->nV, pos, vel, ds, sat);
    else
#endif
    for (i = v->nF; i < v->nV; i++) {
        uint32_t b = fr[4 * i];
        sn_q x[3], p[3];
        for (k = 0; k < 3; k++) x[k] = rd_real(rest, 3 * i + k);
#if defined(SN_KERNELS_M4)
        sn_k_rot(jR + 9 * b, x, p, sat); /* one-compare clamps: sn_rot's values and counts */
#else
        sn_rot(jR + 9 * b, x, p, sat);
#endif
        for (k = 0; k < 3; k++) {
            sn_q pn = sn_add(p[k], jT[3 * b + k], sat);
            sn_q vn = h->have_prev ? sn_add(pn, -pos[3 * i + k], sat) : 0;
            ds[3 * (i - v->nF) + k] = sn_add(vn, -vel[3 * i + k], sat);
            vel[3 * i + k] = vn;
            pos[3 * i + k] = pn;
        }
    }
    if (!h->have_prev) {
        sn_q *x = ARR(h, o_x, sn_q);
        for (i = 0; i < v->nF; i++) {
            sn_q xr[3], p[3], c[3];
            for (k = 0; k < 3; k++) xr[k] = rd_real(rest, 3 * i + k);
            sn_rot(R + 9 * i, xr, p, sat);
            sn_vertex_origin(h, i, c);
            for (k = 0; k < 3; k++) {
                pos[3 * i + k] = sn_add(p[k], c[k], sat);
                vel[3 * i + k] = 0;
                x[3 * i + k] = 0;
            }
        }
        for (i = 0; i < 3 * (v->nV - v->nF); i++) ds[i] = 0;
        h->have_prev = 1;
    }
}

