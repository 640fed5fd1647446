/* test_runtime_frames.c -- the step's vertex and cell frames (sn_pose.c
 * joint_frames, format 6.4: FREFS makes an entry that repeats an earlier
 * (b1, b2, w) copy that frame, and the others slerp from their pair's part,
 * computed once a step from FPAIRS) against each frame computed alone, the
 * way the reference formula reads it: R = qtomat(slerp_path(q_b1, q_b2, w)),
 * the bone's jR when b1 = b2 or w = 0 (seed 003 §3.3). Tolerance 0: the
 * shared parts are values of the same pose, so every frame must be the same
 * bits as its own computation. Checked after 30 steps of the cow and beast
 * animations (rotated, distinct bones), every free vertex and every cell;
 * the count of repeated slerp entries (FREFS aliases) is printed and must be
 * positive on the cow (else no copy is exercised). Positive control: an
 * alias redirected to another entry after validation (the runtime follows
 * it) must make frames differ. The blob without FPAIRS/FREFS (every frame
 * slerped alone) must step to the same state hash; FPAIRS out of order or
 * repeated must be refused. */
#include "sn_test.h"
#include "reference/phys_util.h"
#include "reference/phys_pose.h"
#include "sn_instance.h"

/* R of one FRAMES/CFRAMES entry, alone */
static void frame_alone(const sn_ihdr *h, const unsigned char *f, sn_q R[9]) {
    const sn_q *pq = CARR(h, o_pq, sn_q), *jR = CARR(h, o_jR, sn_q);
    uint32_t b1 = f[0], b2 = f[1], w = (uint32_t)f[2] | (uint32_t)f[3] << 8;
    sn_q q[4], t;
    if (b1 == b2 || w == 0) {
        memcpy(R, jR + 9 * b1, 9 * sizeof(sn_q));
        return;
    }
#if defined(SN_FLOAT)
    t = (float)w * (1.0f / 32768.0f);
#else
    t = (sn_q)(w << (SN_Q_ROT - SN_Q_W));
#endif
    sn_qslerp_path(pq + 4 * b1, pq + 4 * b2, t, q);
    sn_qtomat(q, R);
}

/* entries of sec[0..n) that repeat an earlier slerp entry of either list */
static unsigned repeats(const unsigned char *a, unsigned na, const unsigned char *b, unsigned nb) {
    unsigned i, j, n = 0, tot = na + nb;
    for (i = 0; i < tot; i++) {
        const unsigned char *fi = i < na ? a + 4 * i : b + 4 * (i - na);
        if (fi[0] == fi[1] || (fi[2] | fi[3]) == 0) continue;
        for (j = 0; j < i; j++) {
            const unsigned char *fj = j < na ? a + 4 * j : b + 4 * (j - na);
            if (!memcmp(fi, fj, 4)) { n++; break; }
        }
    }
    return n;
}

/* frames that differ from their computation alone */
static unsigned frames_bad(const sn_instance *inst) {
    const sn_ihdr *hd = (const sn_ihdr *)(const void *)inst;
    const sn_view *v = &hd->v;
    const sn_q *R = CARR(hd, o_R, sn_q), *cR = CARR(hd, o_cR, sn_q);
    const unsigned char *fr = v->sec[SN_SEC_FRAMES], *cfr = v->sec[SN_SEC_CFRAMES];
    unsigned i, bad = 0;
    sn_q A[9];
    for (i = 0; i < v->nF; i++) {
        frame_alone(hd, fr + 4 * i, A);
        bad += memcmp(A, R + 9 * i, sizeof A) != 0;
    }
    for (i = 0; i < v->nC; i++) {
        frame_alone(hd, cfr + 4 * i, A);
        bad += memcmp(A, cR + 9 * i, sizeof A) != 0;
    }
    return bad;
}

/* little-endian fields and the checksum (BLOB.md "Checksum": CRC-32 of [16, total)) of an edited blob */
static uint32_t tb_rd32(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static void tb_u32(unsigned char *p, uint32_t v) { p[0] = (unsigned char)v; p[1] = (unsigned char)(v >> 8); p[2] = (unsigned char)(v >> 16); p[3] = (unsigned char)(v >> 24); }
static uint32_t tb_sec(const unsigned char *b, int k) { return tb_rd32(b + SN_H_SECTIONS + 16 * k); }
static void tb_fix_crc(unsigned char *b) {
    uint32_t c = 0xFFFFFFFFu, n = tb_rd32(b + SN_H_TOTAL_SIZE), i;
    int k;
    for (i = 16; i < n; i++) { c ^= b[i]; for (k = 0; k < 8; k++) c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1; }
    tb_u32(b + SN_H_CRC32, ~c);
}
static uint32_t cnt_of(const unsigned char *b, int k) { return tb_rd32(b + SN_H_SECTIONS + 16 * k + 8); }

typedef void (*pose_fn_t)(const sn_blob *, unsigned, unsigned, double, sn_xform *);
static void asset(const char *name, pose_fn_t pf, int need_repeats) {
    char path[512], nm[64];
    pu_rt rt, rs;
    unsigned k, i, nJ, bad, rep, alias = 0, ctl;
    sn_xform *pose;
    unsigned char *b, *rf;
    uint32_t n, np;
    double h;
    snprintf(nm, sizeof nm, "%s%s", name, PU_BLOB_SUFFIX);
    pu_example(path, sizeof path, nm);
    if (pu_rt_open(&rt, path) != 0) { T_CHECK(0, "%s: cannot open", path); return; }
    b = rt.bytes;
    n = cnt_of(b, SN_SEC_FREFS);
    np = cnt_of(b, SN_SEC_FPAIRS);
    rf = b + tb_sec(b, SN_SEC_FREFS);
    for (i = 0; i < n; i++) alias += !(tb_rd32(rf + 4 * i) & SN_FREF_PAIR);
    nJ = rt.info.joints;
    h = pu_len(rt.info.timestep);
    pose = malloc(nJ * sizeof *pose);
    for (k = 0; k < 30; k++) { pf(rt.blob, nJ, k, h, pose); sn_set_pose(rt.inst, pose, nJ); sn_step(rt.inst); }
    {
        const sn_view *v = &((const sn_ihdr *)(const void *)rt.inst)->v;
        bad = frames_bad(rt.inst);
        rep = repeats(v->sec[SN_SEC_FRAMES], v->nF, v->sec[SN_SEC_CFRAMES], v->nC);
        T_CHECK(bad == 0, "%s: %u of %u frames differ from their computation alone", name, bad, v->nF + v->nC);
        T_CHECK(n == v->nF + v->nC && alias == rep, "%s: FREFS has %u entries (want %u), %u aliases (want the %u repeats)",
                name, n, v->nF + v->nC, alias, rep);
        if (need_repeats) T_CHECK(rep > 0, "%s: no repeated frame entry (no copy exercised)", name);
        T_FIGURE("%s: %u vertex + %u cell frames, bit for bit; %u slerp entries repeat an earlier one, %u bone pairs", name, v->nF,
                 v->nC, rep, np);
    }
    {   /* the same run without FPAIRS/FREFS: every frame slerped alone, the same state */
        size_t sz = rt.size;
        unsigned char *c = malloc(sz);
        uint64_t h1, h2;
        memcpy(c, b, sz);
        memset(c + tb_sec(c, SN_SEC_FPAIRS), 0, 2 * np);
        memset(c + tb_sec(c, SN_SEC_FREFS), 0, 4 * n);
        for (k = SN_SEC_FPAIRS; k <= SN_SEC_FREFS; k++) {
            tb_u32(c + SN_H_SECTIONS + 16 * k + 4, 0);
            tb_u32(c + SN_H_SECTIONS + 16 * k + 8, 0);
        }
        tb_u32(c + SN_H_INSTANCE_BYTES, tb_rd32(c + SN_H_INSTANCE_BYTES) - np * SN_FPAIR_BYTES);
        tb_fix_crc(c);
        memset(&rs, 0, sizeof rs);
        rs.bytes = c;
        T_CHECK(sn_blob_validate(c, sz, &rs.blob) == SN_OK, "%s: the blob without frame references validates", name);
        if (rs.blob) {
            rs.mem = malloc(sn_instance_size(rs.blob) + 8);
            T_CHECK(sn_instance_size(rs.blob) + np * SN_FPAIR_BYTES == sn_instance_size(rt.blob),
                    "%s: the instance without them is %u bytes smaller", name, np * SN_FPAIR_BYTES);
            if (sn_instance_init(rs.mem, sn_instance_size(rs.blob), rs.blob, &rs.inst) == SN_OK) {
                for (k = 0; k < 30; k++) { pf(rs.blob, nJ, k, h, pose); sn_set_pose(rs.inst, pose, nJ); sn_step(rs.inst); }
                h1 = sn_state_hash(rt.inst); h2 = sn_state_hash(rs.inst);
                T_CHECK(h1 == h2, "%s: 30 steps without frame references: hash %016llx, with %016llx", name,
                        (unsigned long long)h2, (unsigned long long)h1);
                T_CHECK(frames_bad(rs.inst) == 0, "%s: frames without references bit for bit", name);
            }
            free(rs.mem);
        }
        /* FPAIRS must be strictly increasing: swapped or repeated pairs are refused */
        memcpy(c, b, sz);
        if (np >= 2) {
            unsigned char *p = c + tb_sec(c, SN_SEC_FPAIRS), t[2];
            const sn_blob *o;
            memcpy(t, p, 2); memcpy(p, p + 2, 2); memcpy(p + 2, t, 2);
            tb_fix_crc(c);
            T_CHECK(sn_blob_validate(c, sz, &o) == SN_ERR_VALUE, "%s: FPAIRS 0 and 1 swapped refused", name);
            memcpy(p, p + 2, 2); /* pair 0 = pair 1 */
            tb_fix_crc(c);
            T_CHECK(sn_blob_validate(c, sz, &o) == SN_ERR_VALUE, "%s: FPAIRS 0 repeating pair 1 refused", name);
        }
        free(c);
    }
    /* positive control: after validation, an alias redirected to the first
     * entry with other bytes (a copy of the wrong frame) must show */
    for (i = 0, ctl = 0; i < n && !ctl; i++) {
        uint32_t r = tb_rd32(rf + 4 * i), j;
        const sn_view *v = &((const sn_ihdr *)(const void *)rt.inst)->v;
        if (r & SN_FREF_PAIR) continue;
        for (j = 0; j < i; j++) {
            const unsigned char *fi = i < v->nF ? v->sec[SN_SEC_FRAMES] + 4 * i : v->sec[SN_SEC_CFRAMES] + 4 * (i - v->nF);
            const unsigned char *fj = j < v->nF ? v->sec[SN_SEC_FRAMES] + 4 * j : v->sec[SN_SEC_CFRAMES] + 4 * (j - v->nF);
            if (memcmp(fi, fj, 4) != 0 && fj[0] != fj[1] && (fj[2] | fj[3]) != 0) break;
        }
        if (j == i) continue;
        tb_u32(rf + 4 * i, j);
        pf(rt.blob, nJ, 30, h, pose); sn_set_pose(rt.inst, pose, nJ); sn_step(rt.inst);
        ctl = frames_bad(rt.inst);
        tb_u32(rf + 4 * i, r);
        T_CHECK(ctl > 0, "%s: control: entry %u's alias redirected to entry %u: %u frames differ (want > 0)", name, i, j, ctl);
        T_FIGURE("%s: control: entry %u's alias redirected to entry %u after validation: %u of %u frames differ", name, i, j, ctl, n);
    }
    if (need_repeats) T_CHECK(ctl > 0, "%s: control run (an alias to redirect)", name);
    free(pose);
    pu_rt_close(&rt);
}

int main(void) {
    asset("cow", pu_cow_pose, 1);
    asset("beast", pu_beast_pose, 0);
    return T_END();
}
