/* sn_step.c -- instances: pose, step, outputs (runtime/NUMERICS.md).
 *
 * The step is the linearized backward Euler of seed 000 §4.2 with the
 * skeleton vertices eliminated (seed 000 eq. 17-18) and the skeletally warped
 * elastic force of seed 003 eq. 7. The matrix uses K~ = R S R^T (congruent to
 * S, so symmetric positive definite) while the right-hand side keeps the exact
 * warped force; the equilibrium is unchanged (DESIGN.md).
 *
 * Every loop is bounded by blob counts or the iteration count: the cost of a
 * step is known before it runs.
 */
#include "sn_internal.h"

#define SN_INST_MAGIC 0x534E4931u /* "SNI1" */
#define SN_HDR_BYTES 512u

/* Instance header; arrays follow at fixed offsets computed from the blob. */
typedef struct sn_ihdr {
    uint32_t magic;
    uint32_t steps, saturations, iterations, mode, have_prev;
    sn_view v;
    sn_real origin[3];      /* public units: origin o of the stored positions */
#if defined(SN_FLOAT)
    float to_int, to_pub;   /* mesh units <-> internal units */
#endif
    /* byte offsets of the arrays from the instance start */
    uint32_t o_acc, o_pq, o_pt, o_jR, o_jT, o_R, o_c, o_pos, o_vel, o_u, o_x, o_r, o_d, o_q, o_ds, o_k;
} sn_ihdr;

typedef char sn_ihdr_fits_[sizeof(sn_ihdr) <= SN_HDR_BYTES ? 1 : -1];

/* Layout (must match SN_INSTANCE_BYTES in sn_format.h):
 * hdr | acc nF*3 acc | per joint: pose q4 t3, R9, T3 | per vertex: R9 c3 pos3 vel3 u3 |
 * per free: x3 r3 d3 q3 | per skeleton: ds3 | per free: k (u8) */
static void layout(sn_ihdr *h) {
    uint32_t nV = h->v.nV, nF = h->v.nF, nJ = h->v.nJ, o = SN_HDR_BYTES;
#define SN_TAKE_(field, bytes) do { h->field = o; o += (bytes); } while (0)
    SN_TAKE_(o_acc, nF * 3u * 8u); /* 8 bytes per accumulator in both flavours */
    SN_TAKE_(o_pq, nJ * 4u * 4u);
    SN_TAKE_(o_pt, nJ * 3u * 4u);
    SN_TAKE_(o_jR, nJ * 9u * 4u);
    SN_TAKE_(o_jT, nJ * 3u * 4u);
    SN_TAKE_(o_R, nV * 9u * 4u);
    SN_TAKE_(o_c, nV * 3u * 4u);
    SN_TAKE_(o_pos, nV * 3u * 4u);
    SN_TAKE_(o_vel, nV * 3u * 4u);
    SN_TAKE_(o_u, nV * 3u * 4u);
    SN_TAKE_(o_x, nF * 3u * 4u);
    SN_TAKE_(o_r, nF * 3u * 4u);
    SN_TAKE_(o_d, nF * 3u * 4u);
    SN_TAKE_(o_q, nF * 3u * 4u);
    SN_TAKE_(o_ds, (nV - nF) * 3u * 4u);
    SN_TAKE_(o_k, nF);
#undef SN_TAKE_
}

#if !defined(SN_FLOAT)
/* number of significant bits of x (0 for 0); fixed 6-step search */
static int bitlen64(uint64_t x) {
    int n = 0, s;
    for (s = 32; s > 0; s >>= 1) {
        uint64_t hi = x >> s;
        int take = hi != 0;
        n += take ? s : 0;
        x = take ? hi : x;
    }
    return n + (x != 0);
}
#endif

/* Force-like values of free vertex i are Q(SN_Q_FORCE + k_i), k_i in
 * [0, SN_KMAX] (see sn_instance_init): the stiffest vertex gets Q19, three
 * bits of headroom over the Q22 lengths for violent poses. */
#define SN_Q_FORCE 19
#define SN_KMAX 15
#define SN_KREL(k) ((int)(k) + SN_Q_FORCE - SN_Q_LEN) /* bits relative to Q22 */

#define ARR(h, off, T) ((T *)(void *)((unsigned char *)(h) + (h)->off))
#define CARR(h, off, T) ((const T *)(const void *)((const unsigned char *)(h) + (h)->off))

/* ---- blob element access ---- */
#define RB (SN_REAL_BYTES)
SN_INLINE sn_q rd_real(const unsigned char *sec, uint32_t idx) {
    return SN_RD_REAL(sec + (size_t)idx * RB);
}

/* ---- unit conversion between public (Q16.16 mesh) and internal (Q22 U) ----
 * raw_pub = raw_int * 2^s with s = len_shift - 6 (fixed). */
#if defined(SN_FLOAT)
static sn_q pub_to_int(const sn_ihdr *h, float pub) { return pub * h->to_int; }
static sn_real int_to_pub(const sn_ihdr *h, sn_q v) { return v * h->to_pub; }
#else
static sn_q pub_to_int_sat(const sn_ihdr *h, int64_t pub, uint32_t *sat) {
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
static int64_t int_to_pub64(const sn_ihdr *h, sn_q v) {
    int s = h->v.len_shift - (SN_Q_LEN - SN_LEN_FRAC);
    return s >= 0 ? (int64_t)v * ((int64_t)1 << s) : sn_rshr64(v, -s);
}
static int32_t clamp32(int64_t x) {
    return x > INT32_MAX ? INT32_MAX : (x < INT32_MIN ? INT32_MIN : (int32_t)x);
}
#endif

/* ---- instance lifetime ---- */

static sn_ihdr *hdr_of(sn_instance *inst) { return (sn_ihdr *)(void *)inst; }
static const sn_ihdr *chdr_of(const sn_instance *inst) {
    return (const sn_ihdr *)(const void *)inst;
}

sn_status sn_instance_init(void *mem, size_t mem_size, const sn_blob *blob, sn_instance **out) {
    sn_ihdr *h;
    if (!mem || !blob || !out) return SN_ERR_NULL;
    if (((uintptr_t)mem & 7u) != 0) return SN_ERR_ALIGN;
    if (mem_size < sn_instance_size(blob)) return SN_ERR_MEMORY;
    memset(mem, 0, sizeof(sn_ihdr));
    h = (sn_ihdr *)mem;
    sn_view_init(&h->v, blob);
    layout(h);
    {   /* each free vertex may be the column of at most SN_MAX_ROW_BLOCKS rows
         * (true of any hex lattice); the unclamped accumulation relies on it.
         * The accumulator array (24 bytes per free vertex) serves as counters. */
        uint16_t *cnt = ARR(h, o_acc, uint16_t);
        const unsigned char *cols = h->v.sec[SN_SEC_COLS];
        uint32_t e, nF = h->v.nF;
        memset(cnt, 0, nF * sizeof *cnt);
        for (e = 0; e < h->v.nnz; e++) {
            uint32_t j = sn_rd_u16(cols + 2 * e);
            if (j < nF && ++cnt[j] > SN_MAX_ROW_BLOCKS) return SN_ERR_INDEX;
        }
    }
    h->magic = SN_INST_MAGIC;
    h->iterations = h->v.cg_default;
    h->mode = SN_MODE_WARPED;
#if defined(SN_FLOAT)
    {
        int k;
        h->to_pub = 1.0f;
        for (k = 0; k < h->v.len_shift; k++) h->to_pub *= 2.0f;
        for (k = 0; k < -h->v.len_shift; k++) h->to_pub *= 0.5f;
        h->to_int = 1.0f / h->to_pub;
    }
#endif
    {   /* Force-like CG vectors (b, r, q) of free vertex i carry k_i extra
         * fractional bits. A row's forces scale with its diagonal block of A
         * (mass + stiffness of the vertex's support), so a barely-inside vertex
         * would otherwise have forces of a few LSBs that the preconditioner
         * amplifies, while a stiff one needs the range. k_i = bits between
         * this vertex's P_i = A_ii^-1 (trace) and the smallest, at most SN_KMAX. */
        /* (format: SN_Q_FORCE + k_i fractional bits) */
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
    *out = (sn_instance *)mem;
    sn_reset(*out);
    return SN_OK;
}

void sn_reset(sn_instance *inst) {
    sn_ihdr *h = hdr_of(inst);
    const sn_view *v = &h->v;
    uint32_t i, k, nV = v->nV, nJ = v->nJ;
    sn_q *pq = ARR(h, o_pq, sn_q), *pt = ARR(h, o_pt, sn_q);
    sn_q *pos = ARR(h, o_pos, sn_q);
    const unsigned char *j0 = v->sec[SN_SEC_JOINTS];
    /* zero the state (everything after the header, before the k table) */
    memset((unsigned char *)h + SN_HDR_BYTES, 0, h->o_k - SN_HDR_BYTES);
    h->steps = 0;
    h->saturations = 0;
    h->have_prev = 0;
    /* rest pose: identity rotations, zero translations */
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
    {   /* rest-pose frames so getters work before the first step */
        sn_q *R = ARR(h, o_R, sn_q);
        for (i = 0; i < nV; i++) {
            for (k = 0; k < 9; k++) R[9 * i + k] = (k % 4 == 0) ? SN_ONE_ROT : 0;
        }
    }
}

sn_status sn_set_pose(sn_instance *inst, const sn_xform *joints, uint32_t n_joints) {
    sn_ihdr *h;
    uint32_t j;
    sn_q *pq, *pt;
    if (!inst || !joints) return SN_ERR_NULL;
    h = hdr_of(inst);
    if (h->magic != SN_INST_MAGIC) return SN_ERR_INSTANCE;
    if (n_joints != h->v.nJ) return SN_ERR_ARG;
    pq = ARR(h, o_pq, sn_q);
    pt = ARR(h, o_pt, sn_q);
    for (j = 0; j < n_joints; j++) {
        sn_q q[4];
        q[0] = joints[j].rot.x; q[1] = joints[j].rot.y; q[2] = joints[j].rot.z; q[3] = joints[j].rot.w;
        sn_qnormalize(q);
        memcpy(pq + 4 * j, q, sizeof q);
        pt[3 * j] = joints[j].pos.x;
        pt[3 * j + 1] = joints[j].pos.y;
        pt[3 * j + 2] = joints[j].pos.z;
    }
    return SN_OK;
}

sn_status sn_set_iterations(sn_instance *inst, uint32_t iterations) {
    sn_ihdr *h;
    if (!inst) return SN_ERR_NULL;
    h = hdr_of(inst);
    if (h->magic != SN_INST_MAGIC) return SN_ERR_INSTANCE;
    if (iterations > h->v.cg_max) return SN_ERR_ARG;
    h->iterations = iterations ? iterations : h->v.cg_default;
    return SN_OK;
}

sn_status sn_set_mode(sn_instance *inst, sn_mode mode) {
    sn_ihdr *h;
    if (!inst) return SN_ERR_NULL;
    h = hdr_of(inst);
    if (h->magic != SN_INST_MAGIC) return SN_ERR_INSTANCE;
    if (mode != SN_MODE_WARPED && mode != SN_MODE_UNWARPED) return SN_ERR_ARG;
    h->mode = (uint32_t)mode;
    return SN_OK;
}

void sn_get_stats(const sn_instance *inst, sn_stats *out) {
    const sn_ihdr *h = chdr_of(inst);
    out->steps = h->steps;
    out->saturations = h->saturations;
    out->iterations = h->iterations;
    out->mode = h->mode;
}

/* ---- saturating public-vector arithmetic (fixed: int32 Q16.16 could overflow
 * for extreme but valid inputs; float: plain) ---- */
static sn_real pub_add(sn_real a, sn_real b) {
#if defined(SN_FLOAT)
    return a + b;
#else
    return clamp32((int64_t)a + b);
#endif
}
static sn_real pub_sub(sn_real a, sn_real b) {
#if defined(SN_FLOAT)
    return a - b;
#else
    return clamp32((int64_t)a - b);
#endif
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

/* ---- the step ---- */

/* Overflow freedom without clamps: entries |e| <= 2^27 (validator), operands
 * |x| <= 2^28 (every sn_q is clamped), so one block row is < 3*2^55 = 2^56.6.
 * A free vertex's accumulator receives its own row (diagonal + at most 26
 * blocks, validator) and at most 26 transposed blocks (checked by
 * sn_instance_init): 53 * 2^56.6 < 2^62.4 < 2^63. */
SN_INLINE void blk_row(sn_acc l[3], const unsigned char *b, const sn_q e[3]) {
    l[0] += sn_mul(rd_real(b, 0), e[0]) + sn_mul(rd_real(b, 1), e[1]) + sn_mul(rd_real(b, 2), e[2]);
    l[1] += sn_mul(rd_real(b, 3), e[0]) + sn_mul(rd_real(b, 4), e[1]) + sn_mul(rd_real(b, 5), e[2]);
    l[2] += sn_mul(rd_real(b, 6), e[0]) + sn_mul(rd_real(b, 7), e[1]) + sn_mul(rd_real(b, 8), e[2]);
}
/* l += D e, D symmetric stored xx yy zz xy xz yz */
SN_INLINE void sym_row(sn_acc l[3], const unsigned char *b, const sn_q e[3]) {
    sn_q xx = rd_real(b, 0), yy = rd_real(b, 1), zz = rd_real(b, 2);
    sn_q xy = rd_real(b, 3), xz = rd_real(b, 4), yz = rd_real(b, 5);
    l[0] += sn_mul(xx, e[0]) + sn_mul(xy, e[1]) + sn_mul(xz, e[2]);
    l[1] += sn_mul(xy, e[0]) + sn_mul(yy, e[1]) + sn_mul(yz, e[2]);
    l[2] += sn_mul(xz, e[0]) + sn_mul(yz, e[1]) + sn_mul(zz, e[2]);
}
SN_INLINE void sca_row(sn_acc l[3], sn_q m, const sn_q e[3]) {
    l[0] += sn_mul(m, e[0]);
    l[1] += sn_mul(m, e[1]);
    l[2] += sn_mul(m, e[2]);
}
/* acc_i += l at the end of row i */
SN_INLINE void row_done(sn_acc *acc, const sn_acc l[3]) {
    acc[0] += l[0];
    acc[1] += l[1];
    acc[2] += l[2];
}

/* acc += B^T e (scatter of the transposed block) */
SN_INLINE void blk_mac_t(sn_acc acc[3], const unsigned char *b, const sn_q e[3]) {
    acc[0] += sn_mul(rd_real(b, 0), e[0]) + sn_mul(rd_real(b, 3), e[1]) + sn_mul(rd_real(b, 6), e[2]);
    acc[1] += sn_mul(rd_real(b, 1), e[0]) + sn_mul(rd_real(b, 4), e[1]) + sn_mul(rd_real(b, 7), e[2]);
    acc[2] += sn_mul(rd_real(b, 2), e[0]) + sn_mul(rd_real(b, 5), e[1]) + sn_mul(rd_real(b, 8), e[2]);
}
/* acc += m e (scalar block) */
SN_INLINE void sca_mac(sn_acc acc[3], sn_q m, const sn_q e[3]) {
    acc[0] += sn_mul(m, e[0]);
    acc[1] += sn_mul(m, e[1]);
    acc[2] += sn_mul(m, e[2]);
}

static void acc_zero(sn_acc *acc, uint32_t n3) {
    uint32_t i;
    for (i = 0; i < n3; i++) acc[i] = 0;
}

/* Scale by a Q24 coefficient: v * c >> 24 */
SN_INLINE sn_q coef(sn_q v, sn_q c, uint32_t *sat) { return sn_mulq(v, c, SN_Q_COEF, sat); }

#if defined(SN_FLOAT)
#define ONE_COEF 1.0f
#else
#define ONE_COEF ((int32_t)1 << SN_Q_COEF)
#endif

/* Force rows out_i (Q(19+k_i)) = R_i (acc_i >> (frac - k_i + 3)) for free rows */
static void rows_out_rot(const sn_ihdr *h, const sn_acc *acc, int frac, sn_q *out, uint32_t *sat) {
    const sn_q *R = CARR(h, o_R, sn_q);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t i;
    for (i = 0; i < h->v.nF; i++) {
        sn_q t[3];
        int s = frac - SN_KREL(kk[i]);
        t[0] = sn_out(acc[3 * i], s, sat);
        t[1] = sn_out(acc[3 * i + 1], s, sat);
        t[2] = sn_out(acc[3 * i + 2], s, sat);
        sn_rot(R + 9 * i, t, out + 3 * i, sat);
    }
}

/* Symmetric stiffness pass over free-free blocks: acc = S^ u (u over free). */
static void pass_S_ff(const sn_ihdr *h, const sn_q *u, sn_acc *acc) {
    const sn_view *v = &h->v;
    const unsigned char *rp = v->sec[SN_SEC_ROWPTR], *cols = v->sec[SN_SEC_COLS];
    const unsigned char *sd = v->sec[SN_SEC_SDIAG], *so = v->sec[SN_SEC_SOFF];
    uint32_t i, nF = v->nF;
    acc_zero(acc, 3 * nF);
    for (i = 0; i < nF; i++) {
        uint32_t e = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
        sn_acc l[3] = {0, 0, 0};
        sym_row(l, sd + (size_t)i * 6 * RB, u + 3 * i);
        /* columns ascend and skeleton columns (>= nF) come last: a blob-fixed prefix */
        for (; e < end; e++) {
            uint32_t j = sn_rd_u16(cols + 2 * e);
            const unsigned char *b = so + (size_t)e * 9 * RB;
            if (j >= nF) break;
            blk_row(l, b, u + 3 * j);
            blk_mac_t(acc + 3 * j, b, u + 3 * i);
        }
        row_done(acc + 3 * i, l);
    }
}

/* Symmetric mass pass over free-free blocks: acc = M^ y (y over free). */
static void pass_M_ff(const sn_ihdr *h, const sn_q *y, sn_acc *acc) {
    const sn_view *v = &h->v;
    const unsigned char *rp = v->sec[SN_SEC_ROWPTR], *cols = v->sec[SN_SEC_COLS];
    const unsigned char *md = v->sec[SN_SEC_MDIAG], *mo = v->sec[SN_SEC_MOFF];
    uint32_t i, nF = v->nF;
    acc_zero(acc, 3 * nF);
    for (i = 0; i < nF; i++) {
        uint32_t e = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
        sn_acc l[3] = {0, 0, 0};
        sca_row(l, rd_real(md, i), y + 3 * i);
        for (; e < end; e++) {
            uint32_t j = sn_rd_u16(cols + 2 * e);
            sn_q m;
            if (j >= nF) break;
            m = rd_real(mo, e);
            sca_row(l, m, y + 3 * j);
            sca_mac(acc + 3 * j, m, y + 3 * i);
        }
        row_done(acc + 3 * i, l);
    }
}

/* q = A d = (1+a1) M^ d + (1+b1) R S^ R^T d  (free rows) */
static void matvec(sn_ihdr *h, const sn_q *d, sn_q *q, uint32_t *sat) {
    const sn_view *v = &h->v;
    sn_acc *acc = ARR(h, o_acc, sn_acc);
    sn_q *u = ARR(h, o_u, sn_q);
    const sn_q *R = CARR(h, o_R, sn_q);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t i, k, nF = v->nF;
    sn_q cm = (sn_q)(ONE_COEF + v->a1), ck = (sn_q)(ONE_COEF + v->b1);
    for (i = 0; i < nF; i++) sn_rot_t(R + 9 * i, d + 3 * i, u + 3 * i, sat);
    pass_S_ff(h, u, acc);
    rows_out_rot(h, acc, v->frac_S, q, sat);
    pass_M_ff(h, d, acc);
    for (i = 0; i < nF; i++)
        for (k = 0; k < 3; k++) {
            sn_q mk = sn_out(acc[3 * i + k], v->frac_M - SN_KREL(kk[i]), sat);
            sn_acc s = sn_mul(q[3 * i + k], ck) + sn_mul(mk, cm);
            q[3 * i + k] = sn_out(s, SN_Q_COEF, sat);
        }
}

/* z_i = R_i P_i R_i^T r_i  (rest-frame block Jacobi, rotated) */
static void precond(sn_ihdr *h, const sn_q *r, sn_q *z, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *R = CARR(h, o_R, sn_q);
    const unsigned char *P = v->sec[SN_SEC_PRECOND];
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t i;
    for (i = 0; i < v->nF; i++) {
        sn_q t[3], s[3];
        sn_acc a[3] = {0, 0, 0};
        int sh = v->frac_P + SN_KREL(kk[i]); /* r is Q(19+k_i), z is Q22 */
        sn_rot_t(R + 9 * i, r + 3 * i, t, sat);
        sym_row(a, P + (size_t)i * 6 * RB, t);
        s[0] = sn_out(a[0], sh, sat);
        s[1] = sn_out(a[1], sh, sat);
        s[2] = sn_out(a[2], sh, sat);
        sn_rot(R + 9 * i, s, z + 3 * i, sat);
    }
}

/* ---- CG scalars ---- */
#if defined(SN_FLOAT)
typedef struct { float m; } sn_dotv;
static sn_dotv dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n) {
    sn_dotv r;
    uint32_t i;
    float s = 0.0f;
    (void)kk;
    for (i = 0; i < n; i++) s += a[i] * b[i];
    r.m = s;
    return r;
}
/* num/den, 0 when den <= 0 or num <= 0 (constant cost, no convergence branch) */
static float ratio(sn_dotv num, sn_dotv den) {
    return (den.m > 0.0f && num.m > 0.0f) ? num.m / den.m : 0.0f;
}
#define SN_Q_SCAL 0
#else
/* Block floating point dot product: value = m * 2^e. */
typedef struct { int64_t m; int e; } sn_dotv;
#define SN_Q_SCAL 28 /* alpha, beta in Q28 */

/* a force-like (Q(19+k_i) per vertex), b velocity-like (Q22): sum of a.b in
 * Q41, times 2^e. The bound uses the OR of the magnitudes (same bit length as
 * their maximum, no compares); products are shifted right by s + k_i. */
static sn_dotv dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n) {
    sn_dotv r;
    uint32_t i, k, oa = 0, ob = 0, nv = n / 3;
    int s;
    int64_t sum = 0;
    for (i = 0; i < n; i++) {
        oa |= a[i] < 0 ? (uint32_t)-(int64_t)a[i] : (uint32_t)a[i];
        ob |= b[i] < 0 ? (uint32_t)-(int64_t)b[i] : (uint32_t)b[i];
    }
    /* n * max|a| * max|b| < 2^62 after shifting each product right by s */
    s = bitlen64(oa) + bitlen64(ob) + bitlen64(n) - 62;
    s = s < 0 ? 0 : s;
    for (i = 0; i < nv; i++) {
        int sh = s + kk[i];
        int64_t half = sh > 0 ? (int64_t)1 << (sh - 1) : 0;
        for (k = 3 * i; k < 3 * i + 3; k++) sum += ((int64_t)a[k] * b[k] + half) >> sh;
    }
    r.m = sum;
    r.e = s;
    return r;
}
/* num/den in Q28, 0 when den <= 0 or num <= 0; saturates at INT32_MAX. */
static int32_t ratio(sn_dotv num, sn_dotv den) {
    int e, bn, bd;
    uint64_t n, d, q;
    if (den.m <= 0 || num.m <= 0) return 0;
    n = (uint64_t)num.m;
    d = (uint64_t)den.m;
    e = SN_Q_SCAL + num.e - den.e;
    /* normalize den to [2^30, 2^31) and num to [2^61, 2^62) */
    bd = bitlen64(d); /* den = d * 2^(bd-31): a larger true den lowers the exponent */
    if (bd > 31) { d >>= (bd - 31); e -= bd - 31; } else { d <<= (31 - bd); e += 31 - bd; }
    bn = bitlen64(n);
    if (bn > 62) { n >>= (bn - 62); e += bn - 62; } else { n <<= (62 - bn); e -= 62 - bn; }
    q = n / d; /* in [2^30, 2^32) */
    if (e >= 0) return e > 0 || q > (uint64_t)INT32_MAX ? INT32_MAX : (int32_t)q;
    if (e < -40) return 0;
    q = (q + ((uint64_t)1 << (-e - 1))) >> -e;
    return q > (uint64_t)INT32_MAX ? INT32_MAX : (int32_t)q;
}
#endif

/* y += s * x (s in Q28 fixed) over n values */
static void axpy(sn_q *y, sn_q s, const sn_q *x, uint32_t n, uint32_t *sat) {
    uint32_t i;
    for (i = 0; i < n; i++) y[i] = sn_add(y[i], sn_mulq(s, x[i], SN_Q_SCAL, sat), sat);
}

/* Rigid joint transforms and per-vertex frames for the current pose. */
static void frames(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *pq = CARR(h, o_pq, sn_q), *pt = CARR(h, o_pt, sn_q);
    sn_q *jR = ARR(h, o_jR, sn_q), *jT = ARR(h, o_jT, sn_q);
    sn_q *R = ARR(h, o_R, sn_q), *c = ARR(h, o_c, sn_q), *pos = ARR(h, o_pos, sn_q);
    const unsigned char *fr = v->sec[SN_SEC_FRAMES];
    sn_q xroot[3], rx[3], delta_int[3];
    uint32_t i, j, k;
    for (k = 0; k < 3; k++) xroot[k] = rd_real(v->sec[SN_SEC_JOINTS] + 8, k);
    for (j = 0; j < v->nJ; j++) sn_qtomat(pq + 4 * j, jR + 9 * j);
    /* origin follows the root joint's world position R_0 x_root + t_0 */
    sn_rot(jR, xroot, rx, sat);
    for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
        float target = pt[k] + int_to_pub(h, rx[k]);
        delta_int[k] = pub_to_int(h, target - h->origin[k]);
        h->origin[k] = target;
#else
        int s = v->len_shift - (SN_Q_LEN - SN_LEN_FRAC);
        int64_t target = (int64_t)pt[k] + int_to_pub64(h, rx[k]);
        int64_t delta = target - h->origin[k], exact;
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
    /* effective translations: T_j = R_j x_root + (t_j - o), internal units */
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
    for (i = 0; i < v->nV; i++) {
        uint32_t b1 = fr[4 * i], b2 = fr[4 * i + 1], w = sn_rd_u16(fr + 4 * i + 2);
        if (h->mode == SN_MODE_UNWARPED) { /* global linear: R = I, c = root */
            for (k = 0; k < 9; k++) R[9 * i + k] = (k % 4 == 0) ? SN_ONE_ROT : 0;
            for (k = 0; k < 3; k++) c[3 * i + k] = jT[k];
        } else if (b1 == b2 || w == 0) {
            memcpy(R + 9 * i, jR + 9 * b1, 9 * sizeof(sn_q));
            memcpy(c + 3 * i, jT + 3 * b1, 3 * sizeof(sn_q));
        } else {
            sn_q q[4];
#if defined(SN_FLOAT)
            sn_q t = (float)w * (1.0f / 32768.0f);
            sn_qslerp(pq + 4 * b1, pq + 4 * b2, t, q);
            for (k = 0; k < 3; k++)
                c[3 * i + k] = jT[3 * b1 + k] + t * (jT[3 * b2 + k] - jT[3 * b1 + k]);
#else
            sn_q t = (sn_q)(w << (SN_Q_ROT - SN_Q_W));
            sn_qslerp(pq + 4 * b1, pq + 4 * b2, t, q);
            for (k = 0; k < 3; k++) {
                int64_t a = jT[3 * b1 + k], b = jT[3 * b2 + k];
                c[3 * i + k] = sn_out(a * 32768 + (b - a) * (int64_t)w, SN_Q_W, sat);
            }
#endif
            sn_qtomat(q, R + 9 * i);
        }
    }
}

/* New skeleton positions p'_k = R_b x_k + T_b into pos, ds = v'_k - v_k,
 * vel_S = v'_k. First pose after init/reset: the flesh is placed rigidly by its
 * frames (R_i x_i + c_i) and all velocities are zero. */
static void skeleton(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *jR = CARR(h, o_jR, sn_q), *jT = CARR(h, o_jT, sn_q);
    const sn_q *R = CARR(h, o_R, sn_q), *c = CARR(h, o_c, sn_q);
    sn_q *pos = ARR(h, o_pos, sn_q), *vel = ARR(h, o_vel, sn_q), *ds = ARR(h, o_ds, sn_q);
    const unsigned char *fr = v->sec[SN_SEC_FRAMES], *rest = v->sec[SN_SEC_REST];
    uint32_t i, k;
    for (i = v->nF; i < v->nV; i++) {
        uint32_t b = fr[4 * i];
        sn_q x[3], p[3];
        for (k = 0; k < 3; k++) x[k] = rd_real(rest, 3 * i + k);
        sn_rot(jR + 9 * b, x, p, sat);
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
            sn_q xr[3], p[3];
            for (k = 0; k < 3; k++) xr[k] = rd_real(rest, 3 * i + k);
            sn_rot(R + 9 * i, xr, p, sat);
            for (k = 0; k < 3; k++) {
                pos[3 * i + k] = sn_add(p[k], c[3 * i + k], sat);
                vel[3 * i + k] = 0;
                x[3 * i + k] = 0;
            }
        }
        for (i = 0; i < 3 * (v->nV - v->nF); i++) ds[i] = 0;
        h->have_prev = 1;
    }
}

/* d_ij + u_j with d_ij = R_i^T (p_j - c_i) - x_j  (seed 003 eq. 7 argument) */
SN_INLINE void warp_arg(const sn_q *Ri, const sn_q *ci, const sn_q *pj, const unsigned char *xj,
                        const sn_q *uj, sn_q out[3], uint32_t *sat) {
    sn_q t[3], l[3];
    int k;
    for (k = 0; k < 3; k++) t[k] = sn_add(pj[k], -ci[k], sat);
    sn_rot_t(Ri, t, l, sat);
    for (k = 0; k < 3; k++) out[k] = sn_add(sn_add(l[k], -rd_real(xj, (uint32_t)k), sat), uj[k], sat);
}

/* Right-hand side b (into r):
 * b = f + m^ g^ - a1 M^ v* - K~ w - M^_FS (v'_S - v_S)   (NUMERICS.md step 5) */
static void rhs(sn_ihdr *h, sn_q *b, uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *rp = v->sec[SN_SEC_ROWPTR], *cols = v->sec[SN_SEC_COLS];
    const unsigned char *sd = v->sec[SN_SEC_SDIAG], *so = v->sec[SN_SEC_SOFF];
    const unsigned char *md = v->sec[SN_SEC_MDIAG], *mo = v->sec[SN_SEC_MOFF];
    const unsigned char *ml = v->sec[SN_SEC_MLUMP], *rest = v->sec[SN_SEC_REST];
    const sn_q *R = CARR(h, o_R, sn_q), *c = CARR(h, o_c, sn_q);
    const sn_q *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q);
    const sn_q *ds = CARR(h, o_ds, sn_q);
    sn_q *u = ARR(h, o_u, sn_q);
    sn_acc *acc = ARR(h, o_acc, sn_acc);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t i, k, nF = v->nF, nV = v->nV;
    sn_q ck = (sn_q)(ONE_COEF + v->b1);

    /* u_j = R_j^T w_j: w = (1+b1) v (free), b1 v' (skeleton) -- stiffness damping + implicit h K v */
    for (i = 0; i < nV; i++) {
        sn_q w[3];
        for (k = 0; k < 3; k++) w[k] = coef(vel[3 * i + k], i < nF ? ck : v->b1, sat);
        sn_rot_t(R + 9 * i, w, u + 3 * i, sat);
    }
    /* stiffness pass: acc_i = S^_ij (d_ij + u_j) over all stored blocks */
    acc_zero(acc, 3 * nF);
    for (i = 0; i < nF; i++) {
        uint32_t e = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
        sn_q a[3];
        sn_acc l[3] = {0, 0, 0};
        warp_arg(R + 9 * i, c + 3 * i, pos + 3 * i, rest + (size_t)3 * i * RB, u + 3 * i, a, sat);
        sym_row(l, sd + (size_t)i * 6 * RB, a);
        for (; e < end; e++) {
            uint32_t j = sn_rd_u16(cols + 2 * e);
            const unsigned char *blk = so + (size_t)e * 9 * RB;
            warp_arg(R + 9 * i, c + 3 * i, pos + 3 * j, rest + (size_t)3 * j * RB, u + 3 * j, a, sat);
            blk_row(l, blk, a);
            if (j < nF) {
                warp_arg(R + 9 * j, c + 3 * j, pos + 3 * i, rest + (size_t)3 * i * RB, u + 3 * i, a, sat);
                blk_mac_t(acc + 3 * j, blk, a);
            }
        }
        row_done(acc + 3 * i, l);
    }
    rows_out_rot(h, acc, v->frac_S, b, sat);
    for (i = 0; i < 3 * nF; i++) b[i] = (sn_q)-b[i]; /* |b| <= SN_LIM: negation is safe */

    /* mass pass: acc_i = M^_ij y_j, y = a1 v (free), a1 v' + (v' - v) (skeleton) */
    acc_zero(acc, 3 * nF);
    for (i = 0; i < nF; i++) {
        uint32_t e = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
        sn_q yi[3], yj[3];
        sn_acc l[3] = {0, 0, 0};
        for (k = 0; k < 3; k++) yi[k] = coef(vel[3 * i + k], v->a1, sat);
        sca_row(l, rd_real(md, i), yi);
        for (; e < end; e++) {
            uint32_t j = sn_rd_u16(cols + 2 * e);
            sn_q m = rd_real(mo, e);
            for (k = 0; k < 3; k++) {
                yj[k] = coef(vel[3 * j + k], v->a1, sat);
                if (j >= nF) yj[k] = sn_add(yj[k], ds[3 * (j - nF) + k], sat);
            }
            sca_row(l, m, yj);
            if (j < nF) sca_mac(acc + 3 * j, m, yi);
        }
        row_done(acc + 3 * i, l);
    }
    for (i = 0; i < nF; i++) {
        sn_q mi = rd_real(ml, i);
        for (k = 0; k < 3; k++) {
            sn_q g = sn_mulq(mi, v->grav[k], v->frac_M - SN_KREL(kk[i]), sat);
            sn_q ma = sn_out(acc[3 * i + k], v->frac_M - SN_KREL(kk[i]), sat);
            b[3 * i + k] = sn_add(sn_add(b[3 * i + k], g, sat), -ma, sat);
        }
    }
}

void sn_step(sn_instance *inst) {
    sn_ihdr *h = hdr_of(inst);
    const sn_view *v = &h->v;
    uint32_t sat = h->saturations;
    uint32_t it, i, n3 = 3 * v->nF;
    sn_q *x = ARR(h, o_x, sn_q), *r = ARR(h, o_r, sn_q), *d = ARR(h, o_d, sn_q);
    sn_q *q = ARR(h, o_q, sn_q), *z = ARR(h, o_u, sn_q); /* z shares u: never live together */
    sn_q *pos = ARR(h, o_pos, sn_q), *vel = ARR(h, o_vel, sn_q);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    sn_dotv rz;

    frames(h, &sat);
    skeleton(h, &sat);
    rhs(h, r, &sat);

    /* PCG, warm-started from the previous step's solution, fixed iterations */
    matvec(h, x, q, &sat);
    for (i = 0; i < n3; i++) r[i] = sn_add(r[i], -q[i], &sat);
    precond(h, r, z, &sat);
    memcpy(d, z, n3 * sizeof(sn_q));
    rz = dot(r, z, kk, n3);
    for (it = 0; it < h->iterations; it++) {
        sn_dotv dq, rz1;
        sn_q alpha, beta, nalpha;
        matvec(h, d, q, &sat);
        dq = dot(q, d, kk, n3);
        alpha = ratio(rz, dq);
        nalpha = (sn_q)-alpha;
        axpy(x, alpha, d, n3, &sat);
        axpy(r, nalpha, q, n3, &sat);
        precond(h, r, z, &sat);
        rz1 = dot(r, z, kk, n3);
        beta = ratio(rz1, rz);
        for (i = 0; i < n3; i++) d[i] = sn_add(z[i], sn_mulq(beta, d[i], SN_Q_SCAL, &sat), &sat);
        rz = rz1;
    }
    /* v += dv, p += h v  (velocities are per step: h folded in) */
    for (i = 0; i < n3; i++) {
        vel[i] = sn_add(vel[i], x[i], &sat);
        pos[i] = sn_add(pos[i], vel[i], &sat);
    }
    h->saturations = sat;
    h->steps++;
}

/* ---- outputs ---- */

static void to_public(const sn_ihdr *h, const sn_q p[3], sn_vec3 *out) {
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

sn_status sn_get_lattice(const sn_instance *inst, sn_vec3 *out, uint32_t first, uint32_t count) {
    const sn_ihdr *h;
    const sn_q *pos;
    uint32_t i;
    if (!inst || !out) return SN_ERR_NULL;
    h = chdr_of(inst);
    if (h->magic != SN_INST_MAGIC) return SN_ERR_INSTANCE;
    if (first > h->v.nV || count > h->v.nV - first) return SN_ERR_ARG;
    pos = CARR(h, o_pos, sn_q);
    for (i = 0; i < count; i++) to_public(h, pos + 3 * (first + i), out + i);
    return SN_OK;
}

sn_status sn_get_surface(const sn_instance *inst, sn_vec3 *out, uint32_t first, uint32_t count) {
    const sn_ihdr *h;
    const sn_q *pos;
    const unsigned char *emb, *cells;
    uint32_t s, k, a;
    if (!inst || !out) return SN_ERR_NULL;
    h = chdr_of(inst);
    if (h->magic != SN_INST_MAGIC) return SN_ERR_INSTANCE;
    if (first > h->v.nS || count > h->v.nS - first) return SN_ERR_ARG;
    pos = CARR(h, o_pos, sn_q);
    emb = h->v.sec[SN_SEC_EMBED];
    cells = h->v.sec[SN_SEC_CELLS];
    for (s = 0; s < count; s++) {
        const unsigned char *e = emb + (size_t)(first + s) * SN_ELEM_EMBED;
        const unsigned char *cell = cells + (size_t)sn_rd_u16(e) * SN_ELEM_CELLS;
        uint32_t t[3];
        sn_q p[3];
        sn_acc acc[3] = {0, 0, 0};
        for (k = 0; k < 3; k++) t[k] = sn_rd_u16(e + 2 + 2 * k);
        /* trilinear basis phi_a at (t) over the 8 corners, corner a at bits (x, y, z) */
        for (a = 0; a < 8; a++) {
            uint32_t vtx = sn_rd_u16(cell + 2 * a);
            uint32_t wx = (a & 1u) ? t[0] : 32768u - t[0];
            uint32_t wy = (a & 2u) ? t[1] : 32768u - t[1];
            uint32_t wz = (a & 4u) ? t[2] : 32768u - t[2];
#if defined(SN_FLOAT)
            float w = (float)wx * (float)wy * (float)wz * (1.0f / 35184372088832.0f); /* 2^45 */
            for (k = 0; k < 3; k++) acc[k] += w * pos[3 * vtx + k];
#else
            /* Q30 weight: (wx*wy) Q30, times wz Q15, >> 15 */
            int64_t w = (int64_t)(((uint64_t)wx * wy * wz + (1u << 14)) >> 15);
            for (k = 0; k < 3; k++) acc[k] += w * pos[3 * vtx + k];
#endif
        }
        {
            uint32_t dummy = 0;
            for (k = 0; k < 3; k++) p[k] = sn_out(acc[k], SN_Q_ROT, &dummy);
        }
        to_public(h, p, out + s);
    }
    return SN_OK;
}

sn_status sn_get_normals(const sn_instance *inst, const sn_vec3 *positions, sn_vec3 *out) {
    const sn_ihdr *h;
    const unsigned char *tris;
    uint32_t t, i, nS;
    if (!inst || !positions || !out) return SN_ERR_NULL;
    h = chdr_of(inst);
    if (h->magic != SN_INST_MAGIC) return SN_ERR_INSTANCE;
    if (h->v.nT == 0) return SN_ERR_ARG;
    tris = h->v.sec[SN_SEC_TRIS];
    nS = h->v.nS;
    memset(out, 0, (size_t)nS * sizeof *out);
#if defined(SN_FLOAT)
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
    for (i = 0; i < nS; i++) {
        sn_q q[4];
        /* normalize via the quaternion normalizer's vector path: (x,y,z,0) */
        q[0] = out[i].x; q[1] = out[i].y; q[2] = out[i].z; q[3] = 0.0f;
        if (q[0] == 0.0f && q[1] == 0.0f && q[2] == 0.0f) { out[i].z = 1.0f; continue; }
        sn_qnormalize(q);
        out[i].x = q[0]; out[i].y = q[1]; out[i].z = q[2];
    }
#else
    {
        /* area-weighted sums in int32: a pre-pass picks one shift for the mesh
         * so the largest face normal is <= 2^24 (128 faces per vertex fit);
         * beyond that the sums saturate instead of overflowing */
        int64_t maxn = 0;
        int pass, shift = 0;
        for (pass = 0; pass < 2; pass++) {
            for (t = 0; t < h->v.nT; t++) {
                uint32_t a = sn_rd_u16(tris + 6 * t), b = sn_rd_u16(tris + 6 * t + 2), c = sn_rd_u16(tris + 6 * t + 4);
                int64_t e1[3], e2[3], n[3];
                int k;
                e1[0] = (int64_t)positions[b].x - positions[a].x; e1[1] = (int64_t)positions[b].y - positions[a].y;
                e1[2] = (int64_t)positions[b].z - positions[a].z;
                e2[0] = (int64_t)positions[c].x - positions[a].x; e2[1] = (int64_t)positions[c].y - positions[a].y;
                e2[2] = (int64_t)positions[c].z - positions[a].z;
                for (k = 0; k < 3; k++) { /* |e| <= 2^30 keeps cross products < 2^62 */
                    e1[k] = e1[k] > (1 << 30) ? (1 << 30) : (e1[k] < -(1 << 30) ? -(1 << 30) : e1[k]);
                    e2[k] = e2[k] > (1 << 30) ? (1 << 30) : (e2[k] < -(1 << 30) ? -(1 << 30) : e2[k]);
                }
                n[0] = e1[1] * e2[2] - e1[2] * e2[1];
                n[1] = e1[2] * e2[0] - e1[0] * e2[2];
                n[2] = e1[0] * e2[1] - e1[1] * e2[0];
                if (pass == 0) {
                    for (k = 0; k < 3; k++) {
                        int64_t m = n[k] < 0 ? -n[k] : n[k];
                        maxn = m > maxn ? m : maxn;
                    }
                } else {
                    int32_t s0 = (int32_t)sn_rshr64(n[0], shift), s1 = (int32_t)sn_rshr64(n[1], shift),
                            s2 = (int32_t)sn_rshr64(n[2], shift);
                    out[a].x = pub_add(out[a].x, s0); out[a].y = pub_add(out[a].y, s1); out[a].z = pub_add(out[a].z, s2);
                    out[b].x = pub_add(out[b].x, s0); out[b].y = pub_add(out[b].y, s1); out[b].z = pub_add(out[b].z, s2);
                    out[c].x = pub_add(out[c].x, s0); out[c].y = pub_add(out[c].y, s1); out[c].z = pub_add(out[c].z, s2);
                }
            }
            if (pass == 0) {
                shift = bitlen64((uint64_t)maxn) - 24;
                shift = shift < 0 ? 0 : shift;
            }
        }
    }
    for (i = 0; i < nS; i++) {
        sn_q q[4];
        q[0] = out[i].x; q[1] = out[i].y; q[2] = out[i].z; q[3] = 0;
        if (q[0] == 0 && q[1] == 0 && q[2] == 0) { out[i].z = SN_ONE_ROT; continue; }
        /* scale up to use the normalizer's precision, then normalize to Q30 */
        sn_qnormalize(q);
        out[i].x = q[0]; out[i].y = q[1]; out[i].z = q[2];
    }
#endif
    return SN_OK;
}

/* ---- determinism hash: FNV-1a 64 over little-endian bytes ---- */
static uint64_t fnv_u32(uint64_t hsh, uint32_t x) {
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
    return fnv_u32(hsh, u);
}

uint64_t sn_state_hash(const sn_instance *inst) {
    const sn_ihdr *h = chdr_of(inst);
    const sn_q *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q), *x = CARR(h, o_x, sn_q);
    uint64_t hsh = 0xCBF29CE484222325ull;
    uint32_t i;
    hsh = fnv_u32(hsh, h->steps);
    hsh = fnv_u32(hsh, h->saturations);
    for (i = 0; i < 3; i++) hsh = fnv_q(hsh, h->origin[i]);
    for (i = 0; i < 3 * h->v.nV; i++) hsh = fnv_q(hsh, pos[i]);
    for (i = 0; i < 3 * h->v.nV; i++) hsh = fnv_q(hsh, vel[i]);
    for (i = 0; i < 3 * h->v.nF; i++) hsh = fnv_q(hsh, x[i]);
    return hsh;
}
