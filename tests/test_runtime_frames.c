/* test_runtime_frames.c -- the step's vertex and cell frames (sn_pose.c
 * joint_frames: the per-pair cache of slerp parts and the memo of whole
 * frames, which copies a frame whose (b1, b2, w) entry repeats an earlier
 * one) against each frame computed alone, without either cache, the way
 * the reference formula reads it: R = qtomat(slerp_path(q_b1, q_b2, w)),
 * the bone's jR when b1 = b2 or w = 0 (seed 003 §3.3). Tolerance 0: the
 * caches reuse values of the same pose, so every frame must be the same
 * bits as its own computation. Checked after 30 steps of the cow and beast
 * animations (rotated, distinct bones), every free vertex and every cell;
 * the count of repeated slerp entries (the memo's hits) is printed and must
 * be positive on the cow (else the test exercises no memo hit). */
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

typedef void (*pose_fn_t)(const sn_blob *, unsigned, unsigned, double, sn_xform *);
static void asset(const char *name, pose_fn_t pf, int need_repeats) {
    char path[512], nm[64];
    pu_rt rt;
    unsigned k, i, nJ, bad = 0, rep;
    sn_xform *pose;
    double h;
    snprintf(nm, sizeof nm, "%s%s", name, PU_BLOB_SUFFIX);
    pu_example(path, sizeof path, nm);
    if (pu_rt_open(&rt, path) != 0) { T_CHECK(0, "%s: cannot open", path); return; }
    nJ = rt.info.joints;
    h = pu_len(rt.info.timestep);
    pose = malloc(nJ * sizeof *pose);
    for (k = 0; k < 30; k++) { pf(rt.blob, nJ, k, h, pose); sn_set_pose(rt.inst, pose, nJ); sn_step(rt.inst); }
    {
        const sn_ihdr *hd = (const sn_ihdr *)(const void *)rt.inst;
        const sn_view *v = &hd->v;
        const sn_q *R = CARR(hd, o_R, sn_q), *cR = CARR(hd, o_cR, sn_q);
        const unsigned char *fr = v->sec[SN_SEC_FRAMES], *cfr = v->sec[SN_SEC_CFRAMES];
        sn_q A[9];
        for (i = 0; i < v->nF; i++) {
            frame_alone(hd, fr + 4 * i, A);
            bad += memcmp(A, R + 9 * i, sizeof A) != 0;
        }
        for (i = 0; i < v->nC; i++) {
            frame_alone(hd, cfr + 4 * i, A);
            bad += memcmp(A, cR + 9 * i, sizeof A) != 0;
        }
        rep = repeats(fr, v->nF, cfr, v->nC);
        T_CHECK(bad == 0, "%s: %u of %u frames differ from their computation alone", name, bad, v->nF + v->nC);
        if (need_repeats) T_CHECK(rep > 0, "%s: no repeated frame entry (the memo is not exercised)", name);
        T_FIGURE("%s: %u vertex + %u cell frames, bit for bit; %u slerp entries repeat an earlier one", name, v->nF,
                 v->nC, rep);
    }
    free(pose);
    pu_rt_close(&rt);
}

int main(void) {
    asset("cow", pu_cow_pose, 1);
    asset("beast", pu_beast_pose, 0);
    return T_END();
}
