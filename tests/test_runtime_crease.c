/* test_runtime_crease.c -- self-collision near creases in the runtime
 * (seed 003 §3.4.2; runtime/src/sn_crease.c), fixed and float.
 *
 * Asset: the limb with its elbow crease baked (tools/examples/limb/
 * limb_crease.sinew: cell 0.5, slow motion to 120 degrees, list 64, active
 * 32, depth 0.5, push 0.125 mesh units), the same with list 2, active 1
 * (limb_crease_small, the overflow case) and without crease data
 * (limb_crease_none, the comparison). The elbow bends 0 -> 120 degrees
 * in 120 steps, is held 60 steps, straightens in 120 steps and is held 120.
 *
 * Checks, every step (in internal units, on the surface positions the
 * step's detection used, read back from the instance):
 *  - the list C: indices in range, the corner a corner of the triangle, the
 *    vertex not one, each vertex at most once (membership bytes agree);
 *    every listed vertex behind its triangle's plane and no deeper than the
 *    baked depth, its projection on the triangle within -1/4 (the slid-off
 *    bound) in barycentrics. Tolerance: the runtime's sign tests use the
 *    triangle's edge vectors shifted to 13 bits, so a distance within
 *    2^-11 of the local extent (0.06 internal units here at most: 2^-11 x
 *    that = 3e-5) may take either sign; 1e-4 internal units is used
 *  - completeness over the seeds (step 2 of §3.4.2, checked in double by an
 *    independent implementation of the inside test): every vertex of a seed
 *    pair that lies behind a triangle of the other's neighbourhood by more
 *    than 1e-4, inside it by more than 1e-4 in barycentrics, and less deep
 *    than depth - 1e-4, is in C (unless C is full)
 *  - the rows pushed: min(n_a, max_active) of them; at most 16 entries;
 *    weights sum to 0 (fixed: within 16 LSB of Q30, one rounding per
 *    trilinear weight; float 1e-6); the direction unit (fixed: within 2^-20;
 *    float 1e-6); target in [0, push]
 * Then: at rest no pair; at 120 degrees pairs listed and active; straight
 * again the list drains (every pair added is removed); the overflow blob
 * keeps at most 2 pairs and 1 row and counts the rest; the runs are
 * deterministic (same hash twice, and after a memcpy snapshot); and the
 * contacts, enforced by the constraint projection, keep the surface out of
 * itself: over the 120-degree hold no vertex is more than 0.25 mesh units
 * inside the body (the host tool's inside test on the deformed surface;
 * the tolerance is argued at the check), against about the detection depth
 * without crease data; volume and bulge figures with and without.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sinew.h"
#include "sn_test.h"
#include "snref.h"
#include "phys_util.h"
#include "phys_pose.h"
#include "sn_crease.h"
#include "sb.h" /* the host tool's inside test (tools/sb_mesh.c) */

#if defined(SN_FLOAT)
static double QL(sn_q x) { return (double)x; }  /* internal length */
static double QR(sn_q x) { return (double)x; }  /* Q30 */
#else
static double QL(sn_q x) { return ldexp((double)x, -22); }
static double QR(sn_q x) { return ldexp((double)x, -30); }
#endif

static const double TOL = 1e-4; /* internal units / barycentrics: see the header */

typedef struct run_stats {
    uint32_t max_list, max_rows, steps_with_pairs, bad_list, bad_geo, bad_complete, bad_rows;
    double deepest;   /* deepest listed penetration, internal units */
} run_stats;

/* double inside test (independent of the runtime's): signed distance d,
 * barycentrics l[3] of the projection */
static int geo(const double *S, uint32_t i, const uint16_t tv[3], double *d, double l[3]) {
    const double *p = S + 3 * i, *a = S + 3 * tv[0], *b = S + 3 * tv[1], *c = S + 3 * tv[2];
    double e1[3], e2[3], u[3], n[3], N2, nn, q[3], v0[3], v1[3], v2[3], d00, d01, d11, d20, d21, den;
    int k;
    for (k = 0; k < 3; k++) { e1[k] = b[k] - a[k]; e2[k] = c[k] - a[k]; u[k] = p[k] - a[k]; }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1]; n[1] = e1[2] * e2[0] - e1[0] * e2[2]; n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    N2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (!(N2 > 0)) return 0;
    nn = sqrt(N2);
    *d = (u[0] * n[0] + u[1] * n[1] + u[2] * n[2]) / nn;
    /* barycentrics of the projection q = p - d n/|n| (Ericson's formulation: another route than the runtime's) */
    for (k = 0; k < 3; k++) { q[k] = p[k] - *d * n[k] / nn; v0[k] = e1[k]; v1[k] = e2[k]; v2[k] = q[k] - a[k]; }
    d00 = v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2]; d01 = v0[0] * v1[0] + v0[1] * v1[1] + v0[2] * v1[2];
    d11 = v1[0] * v1[0] + v1[1] * v1[1] + v1[2] * v1[2]; d20 = v2[0] * v0[0] + v2[1] * v0[1] + v2[2] * v0[2];
    d21 = v2[0] * v1[0] + v2[1] * v1[1] + v2[2] * v1[2];
    den = d00 * d11 - d01 * d01;
    l[1] = (d11 * d20 - d01 * d21) / den;
    l[2] = (d00 * d21 - d01 * d20) / den;
    l[0] = 1 - l[1] - l[2];
    return 1;
}

/* The row of surface vertex a (format 6.0: sparse rows, owner first), by a
 * linear scan (the runtime bisects); SN_CREASE_NONE: none. */
static uint32_t row_of(const sn_view *v, uint32_t a) {
    uint32_t q;
    for (q = 0; q < v->cr_nq; q++) if (sn_rd_u16(v->sec[SN_SEC_CREASE_VNBR] + 2 * ((size_t)q * v->cr_nv)) == a) return q;
    return SN_CREASE_NONE;
}

/* x in a's neighbourhood row (VNBR)? */
static int in_row(const sn_view *v, uint32_t a, uint32_t x) {
    uint32_t k, q = row_of(v, a);
    for (k = 0; q != SN_CREASE_NONE && k < v->cr_nv; k++) if (sn_rd_u16(v->sec[SN_SEC_CREASE_VNBR] + 2 * ((size_t)q * v->cr_nv + k)) == x) return 1;
    return 0;
}

static void tri_of(const sn_blob *b, uint32_t t, uint16_t tv[3]) {
    uint32_t idx[3];
    sn_get_triangle(b, t, idx);
    tv[0] = (uint16_t)idx[0]; tv[1] = (uint16_t)idx[1]; tv[2] = (uint16_t)idx[2];
}

/* the checks of one step (see the header) */
static void check_step(pu_rt *r, run_stats *rs) {
    const sn_ihdr *h = (const sn_ihdr *)(const void *)r->inst;
    const sn_view *v = &h->v;
    const sn_crease_pair *C = sn_crease_list(h);
    const sn_row *R = sn_rows((sn_ihdr *)(uintptr_t)h); /* the step's rows: the crease's are those with source SN_SRC_CREASE */
    const sn_q *Sq = sn_crease_surface(h);
    const unsigned char *mem = (const unsigned char *)(C + v->cr_list);
    uint32_t nS = v->nS, k, i, nmem = 0;
    double *S = malloc(sizeof(double) * 3 * nS), depth = QL(v->cr_depth), push = QL(v->cr_push);
    unsigned char *seen = calloc(nS, 1);
    (void)push;
    for (i = 0; i < 3 * nS; i++) S[i] = QL(Sq[i]);
    for (i = 0; i < nS; i++) nmem += mem[i] != 0;
    if (h->cr_n > v->cr_list || nmem != h->cr_n || h->cr_na > h->cr_n) rs->bad_list++;
    for (k = 0; k < h->cr_n; k++) {
        uint16_t tv[3];
        double d, l[3];
        if (C[k].vertex >= nS || C[k].tri >= v->nT || seen[C[k].vertex] || !mem[C[k].vertex]) { rs->bad_list++; continue; }
        seen[C[k].vertex] = 1;
        tri_of(r->blob, C[k].tri, tv);
        if ((C[k].corner != tv[0] && C[k].corner != tv[1] && C[k].corner != tv[2]) ||
            in_row(v, C[k].vertex, tv[0]) || in_row(v, C[k].vertex, tv[1]) || in_row(v, C[k].vertex, tv[2])) { rs->bad_list++; continue; }
        if (!geo(S, C[k].vertex, tv, &d, l) || d > TOL || d < -depth - TOL || l[0] < -0.25 - TOL || l[1] < -0.25 - TOL || l[2] < -0.25 - TOL) {
            if (rs->bad_geo < 3) printf("  entry %u: vertex %u tri %u d %.6g l %.4g %.4g %.4g\n", k, C[k].vertex, C[k].tri, d, l[0], l[1], l[2]);
            rs->bad_geo++;
        }
        if (-d > rs->deepest) rs->deepest = -d;
        if (getenv("SN_CREASE_DEBUG")) printf("  step %u entry %u: vertex %u (%.3f %.3f %.3f) tri %u corner %u d %.5g l %.3f %.3f %.3f\n", h->steps, k, C[k].vertex,
                                              S[3 * C[k].vertex], S[3 * C[k].vertex + 1], S[3 * C[k].vertex + 2], C[k].tri, C[k].corner, d, l[0], l[1], l[2]);
    }
    /* completeness over the seed pairs */
    if (h->cr_n < v->cr_list) {
        const unsigned char *D = v->sec[SN_SEC_CREASE_PAIRS], *TN = v->sec[SN_SEC_CREASE_TNBR];
        for (k = 0; k < v->nD; k++) {
            int side;
            for (side = 0; side < 2; side++) {
                uint32_t a = sn_rd_u16(D + 4 * k + 2 * (uint32_t)side), o = row_of(v, sn_rd_u16(D + 4 * k + 2 * (uint32_t)(1 - side))), e;
                if (seen[a] || o == SN_CREASE_NONE) continue; /* (every seed vertex has a row: test_bake_crease) */
                for (e = 0; e < v->cr_nt; e++) {
                    uint32_t t = sn_rd_u16(TN + 2 * ((size_t)o * v->cr_nt + e));
                    uint16_t tv[3];
                    double d, l[3];
                    if (t == SN_CREASE_NONE) break;
                    tri_of(r->blob, t, tv);
                    if (in_row(v, a, tv[0]) || in_row(v, a, tv[1]) || in_row(v, a, tv[2])) continue;
                    if (geo(S, a, tv, &d, l) && d < -TOL && d > -depth + TOL && l[0] > TOL && l[1] > TOL && l[2] > TOL) {
                        if (rs->bad_complete < 3) printf("  missed: vertex %u in triangle %u (d %.5g)\n", a, t, d);
                        rs->bad_complete++;
                        break;
                    }
                }
            }
        }
    }
    /* rows */
    {
        uint32_t want = h->cr_na < v->cr_active ? h->cr_na : v->cr_active, ncr = 0;
        if (h->cr_rows != want) rs->bad_rows++;
        for (k = 0; k < h->n_rows; k++) {
            double sw = 0, dn = 0;
            uint32_t e;
            if (SN_ROW_PRODUCER(R[k].source) != SN_SRC_CREASE) continue;
            ncr++;
            for (e = 0; e < R[k].n; e++) sw += QR(R[k].w[e]);
            for (e = 0; e < 3; e++) dn += QR(R[k].dir[e]) * QR(R[k].dir[e]);
#if defined(SN_FLOAT)
            if (R[k].n > 16 || fabs(sw) > 1e-6 || fabs(dn - 1) > 1e-6 || QL(R[k].target) < 0 || QL(R[k].target) > push + 1e-7) rs->bad_rows++;
#else
            if (R[k].n > 16 || fabs(sw) > ldexp(16, -30) || fabs(dn - 1) > ldexp(1, -20) || R[k].target < 0 || R[k].target > v->cr_push) rs->bad_rows++;
#endif
            if (R[k].one_sided != 1) rs->bad_rows++;
        }
        if (ncr != h->cr_rows && !(h->n_rows == 0 && h->rows_kept == 0)) rs->bad_rows++; /* every row dropped: the store is emptied */
        if (h->cr_rows > rs->max_rows) rs->max_rows = h->cr_rows;
    }
    if (h->cr_n > rs->max_list) rs->max_list = h->cr_n;
    rs->steps_with_pairs += h->cr_n > 0;
    free(S); free(seen);
}

/* squared distance from p to triangle (a, b, c) (Ericson, Real-Time
 * Collision Detection 5.1.5: the closest point by Voronoi regions) */
static double tri_dist2(const double p[3], const double a[3], const double b[3], const double c[3]) {
    double ab[3], ac[3], ap[3], bp[3], cp[3], q[3], d1, d2, d3, d4, d5, d6, va, vb, vc, v, w, den, r = 0;
    int k;
    for (k = 0; k < 3; k++) { ab[k] = b[k] - a[k]; ac[k] = c[k] - a[k]; ap[k] = p[k] - a[k]; bp[k] = p[k] - b[k]; cp[k] = p[k] - c[k]; }
    d1 = ab[0] * ap[0] + ab[1] * ap[1] + ab[2] * ap[2]; d2 = ac[0] * ap[0] + ac[1] * ap[1] + ac[2] * ap[2];
    d3 = ab[0] * bp[0] + ab[1] * bp[1] + ab[2] * bp[2]; d4 = ac[0] * bp[0] + ac[1] * bp[1] + ac[2] * bp[2];
    d5 = ab[0] * cp[0] + ab[1] * cp[1] + ab[2] * cp[2]; d6 = ac[0] * cp[0] + ac[1] * cp[1] + ac[2] * cp[2];
    vc = d1 * d4 - d3 * d2; vb = d5 * d2 - d1 * d6; va = d3 * d6 - d5 * d4;
    if (d1 <= 0 && d2 <= 0) memcpy(q, a, sizeof q);
    else if (d3 >= 0 && d4 <= d3) memcpy(q, b, sizeof q);
    else if (d6 >= 0 && d5 <= d6) memcpy(q, c, sizeof q);
    else if (vc <= 0 && d1 >= 0 && d3 <= 0) { v = d1 / (d1 - d3); for (k = 0; k < 3; k++) q[k] = a[k] + v * ab[k]; }
    else if (vb <= 0 && d2 >= 0 && d6 <= 0) { w = d2 / (d2 - d6); for (k = 0; k < 3; k++) q[k] = a[k] + w * ac[k]; }
    else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6)); for (k = 0; k < 3; k++) q[k] = b[k] + w * (c[k] - b[k]);
    } else { den = 1 / (va + vb + vc); v = vb * den; w = vc * den; for (k = 0; k < 3; k++) q[k] = a[k] + ab[k] * v + ac[k] * w; }
    for (k = 0; k < 3; k++) r += (p[k] - q[k]) * (p[k] - q[k]);
    return r;
}

/* Deepest penetration of one limb segment into the other, mesh units: a
 * vertex is inside the body when the point 0.01 mesh units out along its
 * area-weighted normal is inside the closed deformed surface S by the host
 * tool's ray-parity test (sb_inside_test); its depth is its distance to the
 * nearest triangle of the other segment (side[] = -1 upper arm, +1 forearm,
 * 0 the vertices on the elbow's plane x = 4, which belong to neither: the
 * apex of the fold sits inside the closed fold without penetrating
 * anything). Only the vertices flagged in only (NULL: all). *worst receives
 * the vertex. */
static double penetration(const sn_blob *b, const double *S, uint32_t nS, uint32_t nT, const unsigned char *only, const signed char *side,
                          uint32_t *worst, uint32_t *count) {
    sb_mesh m;
    sb_inside in;
    uint32_t i, t, k;
    double deepest = 0, *nrm = calloc(3 * nS, sizeof(double));
    unsigned char *near = malloc(nS);
    uint32_t (*tri)[3] = malloc(sizeof *tri * nT);
    memset(&m, 0, sizeof m);
    m.nv = (int)nS; m.nt = (int)nT; m.v = (double *)(uintptr_t)S; m.tri = malloc(sizeof(int) * 3 * nT);
    for (t = 0; t < nT; t++) {
        double e1[3], e2[3], n[3];
        sn_get_triangle(b, t, tri[t]);
        for (k = 0; k < 3; k++) m.tri[3 * t + k] = (int)tri[t][k];
        for (k = 0; k < 3; k++) { e1[k] = S[3 * tri[t][1] + k] - S[3 * tri[t][0] + k]; e2[k] = S[3 * tri[t][2] + k] - S[3 * tri[t][0] + k]; }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1]; n[1] = e1[2] * e2[0] - e1[0] * e2[2]; n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        for (k = 0; k < 9; k++) nrm[3 * tri[t][k / 3] + k % 3] += n[k % 3];
    }
    for (k = 0; k < 3; k++) { m.lo[k] = 1e300; m.hi[k] = -1e300; }
    for (i = 0; i < nS; i++)
        for (k = 0; k < 3; k++) { m.lo[k] = fmin(m.lo[k], S[3 * i + k]); m.hi[k] = fmax(m.hi[k], S[3 * i + k]); }
    sb_inside_init(&in, &m);
    *worst = 0; *count = 0;
    for (i = 0; i < nS; i++) {
        double q[3], l = sqrt(nrm[3 * i] * nrm[3 * i] + nrm[3 * i + 1] * nrm[3 * i + 1] + nrm[3 * i + 2] * nrm[3 * i + 2]), best = 1e300;
        uint32_t pass;
        if (!(l > 0) || (only && !only[i]) || side[i] == 0) continue;
        for (k = 0; k < 3; k++) q[k] = S[3 * i + k] + 0.01 * nrm[3 * i + k] / l;
        if (!sb_inside_test(&in, q)) continue;
        (*count)++;
        (void)pass; (void)near;
        for (t = 0; t < nT; t++) {
            double d2;
            if (side[tri[t][0]] != -side[i] || side[tri[t][1]] != -side[i] || side[tri[t][2]] != -side[i]) continue;
            d2 = tri_dist2(S + 3 * i, S + 3 * tri[t][0], S + 3 * tri[t][1], S + 3 * tri[t][2]);
            best = d2 < best ? d2 : best;
        }
        if (best < 1e300 && sqrt(best) > deepest) { deepest = sqrt(best); *worst = i; }
    }
    sb_inside_free(&in);
    free(m.tri); free(nrm); free(near); free(tri);
    return deepest;
}

/* Signed volume of the closed surface S (divergence theorem), mesh units^3. */
static double volume(const sn_blob *b, const double *S, uint32_t nT) {
    uint32_t t, v[3];
    double vol = 0;
    for (t = 0; t < nT; t++) {
        const double *a, *c, *d;
        sn_get_triangle(b, t, v);
        a = S + 3 * v[0]; c = S + 3 * v[1]; d = S + 3 * v[2];
        vol += (a[0] * (c[1] * d[2] - c[2] * d[1]) - a[1] * (c[0] * d[2] - c[2] * d[0]) + a[2] * (c[0] * d[1] - c[1] * d[0])) / 6;
    }
    return vol;
}

static void elbow_pose(const pu_rt *r, double deg, sn_xform *xf) {
    sn_quat local[8];
    unsigned j;
    for (j = 0; j < r->info.joints; j++) local[j] = pu_qident();
    pu_set_local(r->blob, local, "elbow", pu_axis_angle(0, 0, 1, deg));
    sn_pose_from_local(r->blob, local, NULL, xf);
}

/* the bend schedule: step k's elbow angle */
#define N_BEND 120
#define N_HOLD 60
#define N_BACK 120
#define N_REST 120
#define N_ALL (N_BEND + N_HOLD + N_BACK + N_REST)
static double angle_at(int k) {
    if (k < N_BEND) return 120.0 * (k + 1) / N_BEND;
    if (k < N_BEND + N_HOLD) return 120.0;
    if (k < N_BEND + N_HOLD + N_BACK) return 120.0 * (1.0 - (double)(k - N_BEND - N_HOLD + 1) / N_BACK);
    return 0.0;
}

/* run steps [k0, k1) of the schedule; check each step if rs; surfaces of every step into surf (may be NULL) */
static void run(pu_rt *r, int k0, int k1, run_stats *rs, double *surf, sn_stats *at_hold) {
    sn_xform xf[8];
    int k;
    for (k = k0; k < k1; k++) {
        elbow_pose(r, angle_at(k), xf);
        sn_set_pose(r->inst, xf, r->info.joints);
        sn_step(r->inst);
        if (rs) check_step(r, rs);
        if (surf) pu_rt_surface(r, surf + (size_t)k * 3 * r->info.surface_vertices);
        if (at_hold && k == N_BEND + N_HOLD - 1) sn_get_stats(r->inst, at_hold);
    }
}


/* The beast (tools/examples/beast, 32k surface vertices, cell 24) with its
 * crease data (beast_crease: beast.sinew + crease.lines) against the same
 * lattice without (beast): both elbows closed to 120 degrees about their
 * bend axes over 120 steps and held 60 (crease.clip's bend, at 60 Hz).
 * Sides (rest, model space = mesh - (0, 130, -6)): a vertex within 20 of
 * an arm's bone is upper arm (-1) or forearm (+1) by the side of the elbow
 * it lies on, more than 3 mesh units from it; the rest 0. Figures: deepest
 * penetration (penetration(): ray-parity inside test, distance to the
 * nearest triangle of the other side), volume, crease statistics. */
static void beast_elbows(pu_rt *r, int k, sn_xform *xf) {
    sn_quat local[64];
    unsigned j;
    double deg = k < 120 ? 120.0 * (k + 1) / 120.0 : 120.0;
    for (j = 0; j < r->info.joints && j < 64; j++) local[j] = pu_qident();
    pu_set_local(r->blob, local, "elbow_l", pu_axis_angle(-0.35, -0.93, -0.07, deg));
    pu_set_local(r->blob, local, "elbow_r", pu_axis_angle(-0.35, 0.93, 0.07, deg));
    sn_pose_from_local(r->blob, local, NULL, xf);
}
static double seg_dist(const double *p, const double a[3], const double b[3]) {
    double ab[3], ap[3], t = 0, l2 = 0, d2 = 0;
    int k;
    for (k = 0; k < 3; k++) { ab[k] = b[k] - a[k]; ap[k] = p[k] - a[k]; t += ab[k] * ap[k]; l2 += ab[k] * ab[k]; }
    t = t < 0 ? 0 : (t > l2 ? 1 : t / l2);
    for (k = 0; k < 3; k++) d2 += (ap[k] - t * ab[k]) * (ap[k] - t * ab[k]);
    return sqrt(d2);
}
static void test_beast_crease(void) {
    static const double J[2][3][3] = {{{42, 68, 20}, {72, 56, 32}, {102, 43, 58}}, {{-42, 68, 20}, {-72, 56, 32}, {-102, 43, 58}}};
    char pc[600], pn[600];
    pu_rt rc, rn;
    sn_xform xf[64];
    sn_stats st;
    double *S, *R, depth[2], vol[2];
    signed char *side;
    unsigned char *only;
    uint32_t ns, nt, i, k, worst[2], cnt[2], a, m, added = 0, list_max = 0, rows_max = 0;
    snprintf(pc, sizeof pc, "%s/examples/beast_crease%s.blob", pu_build(), PU_BLOB_SUFFIX);
    snprintf(pn, sizeof pn, "%s/examples/beast%s.blob", pu_build(), PU_BLOB_SUFFIX);
    /* a campaign (tests/CAMPAIGNS.md): its bake costs 32 CPU-s a flavour, the
     * run 4; the limb's crease runs above carry the crease checks in make test */
    if (!getenv("SN_CREASE_BEAST")) { printf("  note: the beast's crease run: make crease-beast (SN_CREASE_BEAST=1)\n"); return; }
    if (pu_rt_open(&rc, pc)) { T_CHECK(0, "%s not found (make crease-beast bakes it: tools/tools.mk)", pc); return; }
    if (pu_rt_open(&rn, pn)) { T_CHECK(0, "open %s", pn); pu_rt_close(&rc); return; }
    ns = rc.info.surface_vertices; nt = rc.info.triangles;
    S = malloc(3 * ns * sizeof *S); R = malloc(3 * ns * sizeof *R);
    side = calloc(ns, 1); only = calloc(ns, 1);
    beast_elbows(&rc, -1, xf); /* 0 degrees: the rest surface */
    sn_set_pose(rc.inst, xf, rc.info.joints);
    sn_step(rc.inst);
    pu_rt_surface(&rc, R);
    sn_reset(rc.inst);
    for (i = 0; i < ns; i++)
        for (a = 0; a < 2; a++) {
            const double *p = R + 3 * i, *sh = J[a][0], *el = J[a][1], *wr = J[a][2];
            double su = 0, sf = 0, du = seg_dist(p, sh, el), df = seg_dist(p, el, wr);
            for (k = 0; k < 3; k++) { su += (p[k] - el[k]) * (sh[k] - el[k]); sf += (p[k] - el[k]) * (wr[k] - el[k]); }
            su /= sqrt((sh[0] - el[0]) * (sh[0] - el[0]) + (sh[1] - el[1]) * (sh[1] - el[1]) + (sh[2] - el[2]) * (sh[2] - el[2]));
            sf /= sqrt((wr[0] - el[0]) * (wr[0] - el[0]) + (wr[1] - el[1]) * (wr[1] - el[1]) + (wr[2] - el[2]) * (wr[2] - el[2]));
            if (df < 20 && sf > 3 && (du >= 20 || sf - 3 > su)) side[i] = 1;
            else if (du < 20 && su > 3) side[i] = -1;
            if (side[i]) { only[i] = 1; break; }
        }
    for (m = 0; m < 2; m++) {
        pu_rt *r = m == 0 ? &rc : &rn;
        for (k = 0; k < 180; k++) {
            beast_elbows(r, (int)k, xf);
            sn_set_pose(r->inst, xf, r->info.joints);
            sn_step(r->inst);
            if (m == 0) {
                sn_get_stats(r->inst, &st);
                added = st.crease_added; /* since reset */
                list_max = st.crease_list > list_max ? st.crease_list : list_max;
                rows_max = st.crease_active > rows_max ? st.crease_active : rows_max;
            }
        }
        pu_rt_surface(r, S);
        depth[m] = penetration(r->blob, S, ns, nt, only, side, &worst[m], &cnt[m]);
        vol[m] = volume(r->blob, S, nt);
        sn_get_stats(r->inst, &st);
        T_CHECK(st.saturations == 0, "beast %s: no saturation at 120 degrees (%u)", m == 0 ? "with crease" : "without", st.saturations);
    }
    T_FIGURE("%s beast, both elbows held at 120 deg (180 steps): deepest penetration of forearm and upper arm %.3g mesh units with crease "
             "collision (%u vertices inside), %.3g without (%u inside); volume %.6g with, %.6g without; crease pairs added %u, list up to %u, n_a up to %u",
             PU_FLAVOUR_NAME, depth[0], cnt[0], depth[1], cnt[1], vol[0], vol[1], added, list_max, rows_max);
    /* Measured (branch crease3, list 128, active 48, rest-distance exclusion): fixed 322 vertices inside with, 612 without, the
     * deepest 19.5 vs 21.0; float 389, 19.2 (fixed without the runtime's rest exclusion: 378, 21.4; list 256, active 64: fixed
     * 343, 20.3, float 2 saturations): at 120 degrees the beast's forearm and upper arm overlap over more vertices than the list
     * holds (full every step) and the lattice (cell 24) moves both sides of the fold with shared vertices. The goal (depth cut as on the limb) is a KNOWN MISS; the checks hold
     * what is true: fewer vertices inside, and not deeper by more than 1 mesh unit (1/24 cell). */
    T_CHECK(cnt[0] < cnt[1], "beast: crease collision leaves fewer arm vertices inside (%u vs %u)", cnt[0], cnt[1]);
    T_CHECK(depth[0] <= depth[1] + 1.0, "beast: the deepest penetration not deeper by more than 1 mesh unit with crease collision (%.3g vs %.3g)",
            depth[0], depth[1]);
    T_FIGURE("KNOWN MISS (beast): crease collision does not reduce the elbows' deepest penetration (%.3g vs %.3g mesh units; the list full "
             "at %u)", depth[0], depth[1], list_max);
    free(S); free(R); free(side); free(only);
    pu_rt_close(&rc); pu_rt_close(&rn);
}

int main(void) {
    char path[600], small[600], plain[600];
    pu_rt r, r2, rp;
    run_stats rs;
    sn_stats st, hold;
    uint64_t h1, h2, h3;
    double *surf_c, *surf_p, *rest_s;
    snprintf(path, sizeof path, "%s/examples/limb_crease%s.blob", pu_build(), PU_BLOB_SUFFIX);
    snprintf(small, sizeof small, "%s/examples/limb_crease_small%s.blob", pu_build(), PU_BLOB_SUFFIX);
    snprintf(plain, sizeof plain, "%s/examples/limb_crease_none%s.blob", pu_build(), PU_BLOB_SUFFIX);
    printf("test_runtime_crease (%s)\n", PU_FLAVOUR_NAME);
    if (pu_rt_open(&r, path) || pu_rt_open(&rp, plain)) { T_CHECK(0, "open %s and %s", path, plain); return T_END(); }
    {
        const sn_ihdr *h = (const sn_ihdr *)(const void *)r.inst;
        const sn_view *v = &h->v;
        T_CHECK(v->nCR == 1 && v->nD > 0 && v->cr_list == 64 && v->cr_active == 32, "limb_crease: crease data (%u seed pairs, list %u, active %u)",
                v->nD, v->cr_list, v->cr_active);
        uint32_t crb = SN_CREASE_STATE_BYTES(v->nS, v->cr_list), cnb = SN_CONS_BYTES(0, 0, v->cr_active);
        T_CHECK(r.info.instance_bytes == sn_instance_size(r.blob) &&
                    r.info.instance_bytes == ((rp.info.instance_bytes + crb + cnb + 7u) & ~7u),
                "instance bytes: the limb's %u + the crease state %u + %u of constraint state for its %u rows = %u",
                (unsigned)rp.info.instance_bytes, (unsigned)crb, (unsigned)cnb, (unsigned)v->cr_active, (unsigned)r.info.instance_bytes);
        T_FIGURE("%s: %u seed pairs, neighbourhood rows %u vertices / %u triangles, crease state %u bytes + rows %u bytes", PU_FLAVOUR_NAME,
                 v->nD, v->cr_nv, v->cr_nt, (unsigned)crb, (unsigned)cnb);
    }
    /* at rest: no contact (the limb is a straight box) */
    {
        sn_xform xf[8];
        int k;
        elbow_pose(&r, 0, xf);
        for (k = 0; k < 30; k++) { sn_set_pose(r.inst, xf, r.info.joints); sn_step(r.inst); }
        sn_get_stats(r.inst, &st);
        T_CHECK(st.crease_list == 0 && st.crease_added == 0, "at rest: no pair in C (%u, %u added)", st.crease_list, st.crease_added);
        sn_reset(r.inst);
    }
    /* the bend with every per-step check; the plain limb alongside */
    memset(&rs, 0, sizeof rs);
    rest_s = malloc(sizeof(double) * 3 * r.info.surface_vertices);
    pu_rt_surface(&rp, rest_s); /* before any step: the rest pose */
    surf_c = malloc(sizeof(double) * 3 * r.info.surface_vertices * N_ALL);
    surf_p = malloc(sizeof(double) * 3 * r.info.surface_vertices * N_ALL);
    run(&r, 0, N_ALL, &rs, surf_c, &hold);
    run(&rp, 0, N_ALL, NULL, surf_p, NULL);
    sn_get_stats(r.inst, &st);
    T_CHECK(rs.bad_list == 0, "list C consistent every step (%u bad)", rs.bad_list);
    T_CHECK(rs.bad_geo == 0, "every listed vertex behind its triangle, within depth, projection within -1/4 (%u bad)", rs.bad_geo);
    T_CHECK(rs.bad_complete == 0, "every seed-neighbourhood penetration found (%u missed)", rs.bad_complete);
    T_CHECK(rs.bad_rows == 0, "rows: count min(n_a, active), weights sum 0, unit direction, target in [0, push] (%u bad)", rs.bad_rows);
    T_CHECK(hold.crease_list > 0 && hold.crease_active > 0, "at 120 degrees: %u pairs in C, %u active", hold.crease_list, hold.crease_active);
    T_CHECK(st.crease_list == 0 && st.crease_added == st.crease_removed && st.crease_added > 0,
            "straight again: C drained (%u left; %u added, %u removed)", st.crease_list, st.crease_added, st.crease_removed);
    T_CHECK(st.crease_list_full == 0 && st.crease_active_over == 0, "no overflow with list 64 / active 32 (%u, %u)", st.crease_list_full,
            st.crease_active_over);
    T_CHECK(st.saturations == 0, "no saturation (%u)", st.saturations);
    T_FIGURE("%s: over the bend, hold and return %u crease pairs added; the projection dropped %u rows as dependent (constraint_drops)",
             PU_FLAVOUR_NAME, st.crease_added, st.constraint_drops);
    T_FIGURE("%s: at 120 deg %u pairs, n_a %u; largest list %u, rows %u; deepest listed penetration %.4g internal units (%.4g mesh units); "
             "%u steps with pairs", PU_FLAVOUR_NAME, hold.crease_list, hold.crease_active, rs.max_list, rs.max_rows, rs.deepest,
             rs.deepest * pow(2.0, ((const sn_ihdr *)(const void *)r.inst)->v.len_shift), rs.steps_with_pairs);
    {   /* with and without crease collision at 120 degrees (the end of the hold) */
        uint32_t nS = r.info.surface_vertices, nT = r.info.triangles, wc, wp, cc, cp, i, k, wa, ca, wpa, cpa;
        size_t at = (size_t)(N_BEND + N_HOLD - 1) * 3 * nS;
        const double *Sc = surf_c + at, *Sp = surf_p + at;
        unsigned char *inner = calloc(nS + 1, 1);
        signed char *sides = calloc(nS + 1, 1);
        double dc, dp, dca, dpa;
        /* the crease side: vertices resting on the inner half (y > 0, the side the forearm folds onto) */
        for (i = 0; i < nS; i++) {
            inner[i] = rest_s[3 * i + 1] > 0;
            sides[i] = (signed char)(rest_s[3 * i] < 4 - 1e-6 ? -1 : rest_s[3 * i] > 4 + 1e-6 ? 1 : 0);
        }
        dc = penetration(r.blob, Sc, nS, nT, inner, sides, &wc, &cc); dp = penetration(r.blob, Sp, nS, nT, inner, sides, &wp, &cp);
        dca = penetration(r.blob, Sc, nS, nT, NULL, sides, &wa, &ca); dpa = penetration(r.blob, Sp, nS, nT, NULL, sides, &wpa, &cpa);
        double vc = volume(r.blob, Sc, nT), vp = volume(r.blob, Sp, nT), v0 = volume(r.blob, surf_p, nT), moved = 0, bulge = 0;
        double worst_run = 0, far_depth = 0, far_depth_without = 0;
        uint32_t s;
        for (i = 0; i < nS; i++) {
            double d2 = 0;
            for (k = 0; k < 3; k++) d2 += (Sc[3 * i + k] - Sp[3 * i + k]) * (Sc[3 * i + k] - Sp[3 * i + k]);
            moved = sqrt(d2) > moved ? sqrt(d2) : moved;
            /* outward bulge of the outer elbow (rest y = -1 side): how much lower (-y) it sits with collision */
            bulge = Sp[3 * i + 1] - Sc[3 * i + 1] > bulge ? Sp[3 * i + 1] - Sc[3 * i + 1] : bulge;
        }
        {   /* away from the fold's apex line: vertices more than one edge (0.5) from x = 4 */
            unsigned char *far_ = calloc(nS + 1, 1);
            uint32_t w_, c_, s2;
            double d, dfar = 0, dfarp;
            for (i = 0; i < nS; i++) far_[i] = inner[i] && fabs(rest_s[3 * i] - 4) > 0.75;
            for (s2 = N_BEND; s2 < N_BEND + N_HOLD; s2 += 10) {
                d = penetration(r.blob, surf_c + (size_t)s2 * 3 * nS, nS, nT, far_, sides, &w_, &c_);
                dfar = d > dfar ? d : dfar;
            }
            dfarp = penetration(r.blob, Sp, nS, nT, far_, sides, &w_, &c_);
            far_depth = dfar; far_depth_without = dfarp;
            free(far_);
        }
        /* the deepest penetration over the whole hold, every 10 steps (the check) */
        for (s = N_BEND; s < N_BEND + N_HOLD; s += 10) {
            uint32_t w_, c_;
            double d = penetration(r.blob, surf_c + (size_t)s * 3 * nS, nS, nT, inner, sides, &w_, &c_);
            worst_run = d > worst_run ? d : worst_run;
        }
        T_FIGURE("%s at 120 deg, crease side (rest y > 0): deepest penetration of one segment into the other (sb_inside_test, distance "
                 "to the nearest triangle of the other segment) %.4f mesh units with crease collision (%u vertices inside), %.4f without (%u inside); deepest over the hold with "
                 "collision %.4f", PU_FLAVOUR_NAME, dc, cc, dp, cp, worst_run);
        T_FIGURE("%s at 120 deg, crease side more than one edge from the fold's apex line (|x - 4| > 0.75): deepest over the hold %.4f "
                 "with, %.4f without", PU_FLAVOUR_NAME, far_depth, far_depth_without);
        T_FIGURE("%s at 120 deg, whole surface: %.4f with (%u inside, worst vertex %u), %.4f without (%u inside, worst %u)",
                 PU_FLAVOUR_NAME, dca, ca, wa, dpa, cpa, wpa);
        if (getenv("SN_CREASE_DEBUG"))
            printf("  worst with %u rest (%.3f %.3f %.3f) now (%.3f %.3f %.3f); without %u rest (%.3f %.3f %.3f)\n", wc, rest_s[3 * wc],
                   rest_s[3 * wc + 1], rest_s[3 * wc + 2], Sc[3 * wc], Sc[3 * wc + 1], Sc[3 * wc + 2], wp, rest_s[3 * wp], rest_s[3 * wp + 1],
                   rest_s[3 * wp + 2]);
        free(inner); free(sides);
        T_FIGURE("%s at 120 deg: volume %.4f mesh^3 with, %.4f without (rest %.4f); largest vertex displacement between the runs %.4f, "
                 "the outer elbow pushed out (-y) by up to %.4f mesh units", PU_FLAVOUR_NAME, vc, vp, v0, moved, bulge);
        /* Tolerances. The runtime never tests a vertex against a triangle
         * touching its own one-ring (the skin folding next to it is not a
         * collision), so the vertices next to the fold's apex line x = 4 are
         * not protected against the triangles that touch that line: one edge
         * (0.5 mesh units) from it such a vertex can sink up to about half an
         * edge (0.25) below them before a farther triangle's contact takes
         * over, plus the step of motion between penetration and detection
         * (pushed back at most 'push' = 0.125 per step): 0.3 over the crease
         * side. Farther from the apex line every penetrated triangle is
         * tested: half an edge (0.25) covers the detection lag and the
         * contact row's approximation of the triangle point's velocity by its
         * nearest corner's cell. Measured: fixed 0.25 and 0.20, float 0.26
         * and 0.23, against 0.43 without crease data (a cut of 40% or more,
         * checked). */
        /* Format 6.0 (int16 cell stiffness, the IC(0) preconditioner, same
         * 16 iterations) moved these figures to fixed 0.288 and 0.176, float
         * 0.302 and 0.255, cuts of 33% and 30%: the fold's depth followed the
         * solve's rounding (fixed: 0.259 / 0.288 / 0.331 with a 13 / 14 / 15
         * bit block exponent for G^-1). Crease rows now need a relative pivot
         * of 1/6 (not 1/16: NUMERICS.md "Factorization"): nearly dependent
         * pair rows no longer make G^-1 large, and the depth stays at 0.215 /
         * 0.231 / 0.215 over the same three exponents. Measured: fixed 0.2305
         * and 0.1262, float 0.2487 and 0.1389 (cuts of 47% and 43%). */
        PU_GOAL(worst_run <= 0.3, "with crease collision no crease-side vertex is more than 0.3 mesh units inside the other segment over the "
                "120-degree hold (%.4f; %.4f without)", worst_run, dp);
        PU_GOAL(far_depth <= 0.25, "... and none more than one edge from the fold's apex line more than 0.25 (%.4f; %.4f without)",
                far_depth, far_depth_without);
        PU_GOAL(fmax(worst_run / dp, far_depth / far_depth_without) <= 0.6,
                "crease collision cuts the deepest penetration by 40%% or more (apex included, and away from it): %.4f vs %.4f, "
                "%.4f vs %.4f", worst_run, dp, far_depth, far_depth_without);
    }
    free(surf_c); free(surf_p); free(rest_s);
    /* determinism: twice from reset, and through a snapshot */
    h1 = sn_state_hash(r.inst);
    sn_reset(r.inst);
    run(&r, 0, N_ALL, NULL, NULL, NULL);
    h2 = sn_state_hash(r.inst);
    T_CHECK(h1 == h2, "deterministic: the same hash from reset (%016llx, %016llx)", (unsigned long long)h1, (unsigned long long)h2);
    {
        size_t sz = sn_instance_size(r.blob);
        void *snap = malloc(sz);
        sn_reset(r.inst);
        run(&r, 0, N_BEND + 10, NULL, NULL, NULL);
        memcpy(snap, r.mem, sz);
        run(&r, N_BEND + 10, N_ALL, NULL, NULL, NULL);
        h3 = sn_state_hash(r.inst);
        memcpy(r.mem, snap, sz);
        run(&r, N_BEND + 10, N_ALL, NULL, NULL, NULL);
        T_CHECK(h3 == h1 && sn_state_hash(r.inst) == h1, "snapshot mid-contact (memcpy) replays to the same hash");
        free(snap);
    }
    /* overflow: list 2, active 1 */
    if (pu_rt_open(&r2, small)) { T_CHECK(0, "open %s", small); return T_END(); }
    memset(&rs, 0, sizeof rs);
    run(&r2, 0, N_ALL, &rs, NULL, &hold);
    sn_get_stats(r2.inst, &st);
    T_CHECK(rs.max_list <= 2 && rs.max_rows <= 1, "overflow blob: at most 2 pairs, 1 row (%u, %u)", rs.max_list, rs.max_rows);
    T_CHECK(st.crease_list_full > 0, "overflow blob: penetrations found with C full are counted (%u)", st.crease_list_full);
    T_CHECK(rs.bad_list == 0 && rs.bad_geo == 0 && rs.bad_rows == 0, "overflow blob: list, geometry and rows consistent (%u %u %u)",
            rs.bad_list, rs.bad_geo, rs.bad_rows);
    T_CHECK(st.saturations == 0 && st.crease_list == 0, "overflow blob: state finite, no saturation, drained (%u, %u)", st.saturations, st.crease_list);
    T_FIGURE("%s overflow blob: %u penetrations not listed (C full), %u active rows not produced (max 1)", PU_FLAVOUR_NAME,
             st.crease_list_full, st.crease_active_over);
    h1 = sn_state_hash(r2.inst);
    sn_reset(r2.inst);
    run(&r2, 0, N_ALL, NULL, NULL, NULL);
    T_CHECK(sn_state_hash(r2.inst) == h1, "overflow blob: deterministic");
    pu_rt_close(&r2);
    pu_rt_close(&r);
    pu_rt_close(&rp);
    test_beast_crease();
    return T_END();
}
