/* test_runtime_surface.c -- sn_get_surface (sn_embed.c): on the plain
 * lattice a loop of its own (surface_plain: the level tests out of the
 * loop, the weights and products written out). Checked after 30 steps of
 * the cow's and the beast's animations (rotated, moving cells):
 * - against the general path, a vertex at a time (sn_surface_point then
 *   sn_pub_point, what the cut level still runs): tolerance 0 (the same
 *   integers; float: each component's sum in the same order), for the whole
 *   surface and for a run in the middle (first > 0);
 * - against the double-precision embedding of seed 000 §3.1,
 *   x = origin + sum_a phi_a(t) p_a with phi_a exact from t (Q15) and p_a the
 *   internal lattice positions. Fixed tolerance, in public units: each
 *   Q30 weight is within 2^-31 of its exact value, so the sum is within
 *   2^-31 sum_a |p_a| internal units, plus 1/2 for rounding it to an
 *   internal unit; times 2^sh (sh = len_shift - (22 - LEN_FRAC)) and 1/2
 *   more when sh < 0 rounds it. Float: 2^-20 of max(|origin|, sum |p_a|
 *   scaled): at most 16 roundings of 2^-24 relative reach the result (a
 *   weight's two products, its product with p_a, 8 sums, the scale and the
 *   origin's sum).
 * - a positive control: one corner position changed in the instance moves
 *   the vertices it carries (so a loop that ignored positions would fail).
 * sn_get_normals on that surface against the double-precision area-weighted
 * normal (the sum of the triangles' cross products at each vertex, then
 * unit length), per vertex within a bound derived from the arithmetic: the
 * direction moves by at most 2 E / |S| for an error E of the sum S, plus
 * the unit step's own (fixed: 2^-28, float: 2^-20). Fixed: each face's
 * cross product is exact in int64 and rounded once to the mesh's shift
 * (2^shift <= 2^-23 of the largest component, so E <= k sqrt 3 2^-24 max
 * for k faces at the vertex). Float: each edge difference and cross product
 * term rounds (E <= sum_f 6 2^-24 |e1||e2|) and the k sums add
 * k 2^-24 sum_f |n_f|. Fixed also: the surface moved by 2^30 (positions
 * beyond 2^29 take the edge-clamping loop) gives the same normals. Float also: the 4-lane unit step (sn_kernels_fnorm.c)
 * against the scalar one bit for bit on crafted sums: zero, -0, tiny
 * (below the 1e-30 cut), subnormal, huge, infinite and NaN components, a
 * count that leaves a tail.
 */
#include "sn_test.h"
#include "reference/phys_util.h"
#include "reference/phys_pose.h"
#include "sn_instance.h"

typedef void (*pose_fn_t)(const sn_blob *, unsigned, unsigned, double, sn_xform *);

static unsigned rd16(const unsigned char *p) { return (unsigned)p[0] | (unsigned)p[1] << 8; }

static int same_vec(const sn_vec3 *a, const sn_vec3 *b) {
    return memcmp(&a->x, &b->x, sizeof a->x) == 0 && memcmp(&a->y, &b->y, sizeof a->y) == 0 &&
           memcmp(&a->z, &b->z, sizeof a->z) == 0;
}

/* vertices of out[0..n) (surface vertices first..) not equal to the general path's */
static unsigned general_bad(const sn_ihdr *h, const sn_vec3 *out, uint32_t first, uint32_t n) {
    unsigned s, bad = 0;
    for (s = 0; s < n; s++) {
        sn_q p[3];
        sn_vec3 g;
        sn_surface_point(h, first + s, p);
        sn_pub_point(h, p, &g);
        bad += !same_vec(&g, out + s);
    }
    return bad;
}

/* sn_get_normals against the double area-weighted normals (bound above);
 * returns the vertices beyond it, *worst the largest error / bound */
static unsigned normals_bad(const sn_ihdr *h, const sn_vec3 *pos, const sn_vec3 *nrm, double *worst) {
    const unsigned char *tris = h->v.sec[SN_SEC_TRIS];
    const unsigned nS = h->v.nS, nT = h->v.nT;
    double *S = calloc(3u * nS, sizeof *S), *E = calloc(nS, sizeof *E), *A = calloc(nS, sizeof *A), maxn = 0;
    unsigned *k = calloc(nS, sizeof *k), t, i, bad = 0;
    for (t = 0; t < nT; t++) {
        const unsigned v[3] = {rd16(tris + 6 * t), rd16(tris + 6 * t + 2), rd16(tris + 6 * t + 4)};
        double e1[3], e2[3], n[3], l1, l2, an;
        unsigned q;
        e1[0] = (double)pos[v[1]].x - pos[v[0]].x; e1[1] = (double)pos[v[1]].y - pos[v[0]].y; e1[2] = (double)pos[v[1]].z - pos[v[0]].z;
        e2[0] = (double)pos[v[2]].x - pos[v[0]].x; e2[1] = (double)pos[v[2]].y - pos[v[0]].y; e2[2] = (double)pos[v[2]].z - pos[v[0]].z;
        n[0] = e1[1] * e2[2] - e1[2] * e2[1]; n[1] = e1[2] * e2[0] - e1[0] * e2[2]; n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]); l2 = sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]);
        an = fabs(n[0]) + fabs(n[1]) + fabs(n[2]);
        for (q = 0; q < 3; q++) if (fabs(n[q]) > maxn) maxn = fabs(n[q]);
        for (q = 0; q < 3; q++) {
            S[3 * v[q]] += n[0]; S[3 * v[q] + 1] += n[1]; S[3 * v[q] + 2] += n[2];
            E[v[q]] += 6.0 * ldexp(l1 * l2, -24); A[v[q]] += an; k[v[q]]++;
        }
    }
    for (i = 0; i < nS; i++) {
        const double len = sqrt(S[3 * i] * S[3 * i] + S[3 * i + 1] * S[3 * i + 1] + S[3 * i + 2] * S[3 * i + 2]);
#if defined(SN_FLOAT)
        const double err = E[i] + k[i] * ldexp(A[i], -24), own = ldexp(1.0, -20), one = 1.0;
#else
        const double err = k[i] * sqrt(3.0) * ldexp(maxn, -24), own = ldexp(1.0, -28), one = 1073741824.0;
#endif
        double tol, d = 0, g[3];
        unsigned q;
        if (k[i] == 0 || !(len > 0)) continue; /* no face, or a degenerate sum: no direction to compare */
        tol = 2.0 * err / len + own;
        g[0] = (double)nrm[i].x / one; g[1] = (double)nrm[i].y / one; g[2] = (double)nrm[i].z / one;
        for (q = 0; q < 3; q++) d += (g[q] - S[3 * i + q] / len) * (g[q] - S[3 * i + q] / len);
        d = sqrt(d);
        if (d / tol > *worst) *worst = d / tol;
        bad += !(d <= tol);
    }
    free(S); free(E); free(A); free(k);
    return bad;
}

#if defined(SN_FLOAT)
static void fnormals_lanes(void) {
    static const float sp[] = {0.0f, -0.0f, 1e-31f, 1e-30f, 1.1e-30f, 1e-40f, 1e-20f, 1.0f, -3.5f, 1e30f, 3e38f, -3e38f};
    enum { N = 4003 };
    sn_vec3 *a = malloc(N * sizeof *a), *b = malloc(N * sizeof *b);
    unsigned i, bad = 0;
    uint32_t r = 12345u;
    for (i = 0; i < N; i++) {
        float c[3];
        unsigned q;
        for (q = 0; q < 3; q++) {
            r = r * 1664525u + 1013904223u;
            if (i % 5 == 0) c[q] = sp[(r >> 8) % (sizeof sp / sizeof sp[0])];
            else c[q] = ((float)(r >> 8) / 8388608.0f - 1.0f) * ((i % 7 == 0) ? 1e-25f : (i % 11 == 0) ? 1e25f : 1.0f);
        }
        if (i % 97 == 0) c[r % 3u] = (float)(HUGE_VAL - HUGE_VAL); /* NaN */
        if (i % 89 == 0) c[r % 3u] = (float)HUGE_VAL;
        a[i].x = b[i].x = c[0]; a[i].y = b[i].y = c[1]; a[i].z = b[i].z = c[2];
    }
    sn_k_fnormals(a, N);
    sn_k_fnormals_ref(b, N);
    for (i = 0; i < N; i++) bad += !same_vec(a + i, b + i);
    T_CHECK(bad == 0, "normals' unit step: %u of %u vertices differ from the scalar reference", bad, (unsigned)N);
    T_FIGURE("normals' unit step: %u crafted sums bit for bit with the scalar reference", (unsigned)N);
    free(a); free(b);
}
#endif

#if !defined(SN_FLOAT)
#include "sn_kernels_xnorm.h" /* sn_k_xnormals: crafted meshes */
/* The fixed normals as sn_embed.c computed them before issue 15 (the
 * reference for sn_kernels_xnorm.c, bit for bit): edges clamped to +-2^30
 * when a position lies beyond +-2^29, a pass for the largest |n_k|, the
 * shift bitlen - 24, the rounded terms summed saturating, sn_qnormalize. */
static int64_t ref_clamp30(int64_t v) { return v > (1 << 30) ? (1 << 30) : (v < -(1 << 30) ? -(1 << 30) : v); }
static int32_t ref_sat(int64_t v) { return v > INT32_MAX ? INT32_MAX : (v < INT32_MIN ? INT32_MIN : (int32_t)v); }
static void ref_face(const sn_vec3 *p, unsigned a, unsigned b, unsigned c, int clamp, int64_t n[3]) {
    int64_t e1[3], e2[3];
    int k;
    e1[0] = (int64_t)p[b].x - p[a].x; e1[1] = (int64_t)p[b].y - p[a].y; e1[2] = (int64_t)p[b].z - p[a].z;
    e2[0] = (int64_t)p[c].x - p[a].x; e2[1] = (int64_t)p[c].y - p[a].y; e2[2] = (int64_t)p[c].z - p[a].z;
    if (clamp)
        for (k = 0; k < 3; k++) { e1[k] = ref_clamp30(e1[k]); e2[k] = ref_clamp30(e2[k]); }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
}
static void ref_xnormals(const unsigned char *tris, uint32_t nT, const sn_vec3 *p, uint32_t nS, sn_vec3 *out) {
    int64_t maxn = 0;
    int pass, shift = 0, wide = 0, k;
    uint32_t i, t;
    memset(out, 0, nS * sizeof *out);
    for (i = 0; i < nS; i++)
        wide |= p[i].x > (1 << 29) || p[i].x < -(1 << 29) || p[i].y > (1 << 29) || p[i].y < -(1 << 29) ||
                p[i].z > (1 << 29) || p[i].z < -(1 << 29);
    for (pass = 0; pass < 2; pass++) {
        for (t = 0; t < nT; t++) {
            const unsigned a = rd16(tris + 6 * t), b = rd16(tris + 6 * t + 2), c = rd16(tris + 6 * t + 4);
            int64_t n[3];
            ref_face(p, a, b, c, wide, n);
            if (pass == 0) {
                for (k = 0; k < 3; k++) maxn = (n[k] < 0 ? -n[k] : n[k]) > maxn ? (n[k] < 0 ? -n[k] : n[k]) : maxn;
            } else {
                int32_t sv[3];
                for (k = 0; k < 3; k++) sv[k] = (int32_t)(shift ? (n[k] + ((int64_t)1 << (shift - 1))) >> shift : n[k]);
                out[a].x = ref_sat((int64_t)out[a].x + sv[0]); out[a].y = ref_sat((int64_t)out[a].y + sv[1]); out[a].z = ref_sat((int64_t)out[a].z + sv[2]);
                out[b].x = ref_sat((int64_t)out[b].x + sv[0]); out[b].y = ref_sat((int64_t)out[b].y + sv[1]); out[b].z = ref_sat((int64_t)out[b].z + sv[2]);
                out[c].x = ref_sat((int64_t)out[c].x + sv[0]); out[c].y = ref_sat((int64_t)out[c].y + sv[1]); out[c].z = ref_sat((int64_t)out[c].z + sv[2]);
            }
        }
        if (pass == 0) {
            uint64_t m = (uint64_t)maxn;
            int bl = 0;
            while (m) { bl++; m >>= 1; }
            shift = bl - 24 < 0 ? 0 : bl - 24;
        }
    }
    for (i = 0; i < nS; i++) {
        sn_q q[4];
        q[0] = out[i].x; q[1] = out[i].y; q[2] = out[i].z; q[3] = 0;
        if (q[0] == 0 && q[1] == 0 && q[2] == 0) { out[i].z = SN_ONE_ROT; continue; }
        sn_qnormalize(q);
        out[i].x = q[0]; out[i].y = q[1]; out[i].z = q[2];
    }
}
static unsigned xn_diff(const unsigned char *tris, uint32_t nT, const sn_vec3 *p, uint32_t nS, sn_vec3 *a, sn_vec3 *b) {
    unsigned i, d = 0;
    sn_k_xnormals(tris, nT, p, nS, a);
    ref_xnormals(tris, nT, p, nS, b);
    for (i = 0; i < nS; i++) d += !same_vec(a + i, b + i);
    return d;
}
static uint32_t xr_rng = 777u;
static int32_t xr_rnd(int32_t lim) { /* in [-lim, lim] */
    xr_rng = xr_rng * 1664525u + 1013904223u;
    return (int32_t)((int64_t)((xr_rng ^ (xr_rng >> 15)) % (2u * (uint32_t)lim + 1u)) - lim);
}
/* sn_k_xnormals against the reference on the asset's triangles: random
 * positions within +-2^29 (the non-wide path, shift > 0), within +-2^10
 * (shift 0), beyond (+-2^31: the clamped path), one point for all (zero
 * sums), within +-2^29 but one vertex of face 0 near -2^31 (the clamped
 * path, found by the position check), 1 - 8 triangles (the lanes' tail) */
static void xnormals_random(const char *name, const sn_view *v) {
    const uint32_t nS = v->nS, nT = v->nT;
    sn_vec3 *p = malloc(nS * sizeof *p), *a = malloc(nS * sizeof *a), *b = malloc(nS * sizeof *b);
    static const int32_t lims[] = {1 << 29, 1 << 10, INT32_MAX, 0, 1 << 29};
    unsigned r, i, d = 0, cases = 0;
    for (r = 0; r < 15; r++) {
        const int32_t lim = lims[r % 5];
        for (i = 0; i < nS; i++) { p[i].x = lim ? xr_rnd(lim) : 5; p[i].y = lim ? xr_rnd(lim) : -7; p[i].z = lim ? xr_rnd(lim) : 9; }
        if (r % 5 == 4) p[rd16(v->sec[SN_SEC_TRIS] + 2 * (r % 3))].y = INT32_MIN + (int32_t)r; /* one vertex of face 0 beyond: clamped */
        d += xn_diff(v->sec[SN_SEC_TRIS], nT, p, nS, a, b); cases++;
        d += xn_diff(v->sec[SN_SEC_TRIS], 1 + r % 8, p, nS, a, b); cases++;
    }
    T_CHECK(d == 0, "%s: sn_k_xnormals on random positions: %u normals differ from the reference", name, d);
    T_FIGURE("%s: %u random meshes' normals bit for bit with the reference", name, cases);
    free(p); free(a); free(b);
}
/* a vertex of k faces, each (0,0,0), (18631,0,0), (0,1801,0): n_z = 18631
 * 1801 = 2^25 - 1, shift 1, each term 2^24: 127 faces sum to 127 2^24 (the
 * plain sums), 128 to 2^31 (saturates at 2^31 - 1; a plain int32 sum
 * would wrap negative), 200 saturate well before the end; the centre is
 * each face's first, third and second corner in turn */
static void xnormals_fan(void) {
    static const unsigned ks[] = {127, 128, 200};
    static unsigned char tris[6 * 200];
    static sn_vec3 p[401], a[401], b[401];
    unsigned j, t, d = 0;
    for (j = 0; j < 3; j++) {
        const unsigned k = ks[j], nS = 2 * k + 1;
        for (t = 0; t < k; t++) {
            const unsigned v1 = 2 * t + 1, v2 = 2 * t + 2;
            const unsigned cyc[3] = {0, v1, v2}, r0 = t % 3; /* the centre as a, c, b in turn (the same orientation) */
            unsigned q;
            for (q = 0; q < 3; q++) {
                tris[6 * t + 2 * q] = (unsigned char)cyc[(q + r0) % 3];
                tris[6 * t + 2 * q + 1] = (unsigned char)(cyc[(q + r0) % 3] >> 8);
            }
            p[v1].x = 18631; p[v1].y = 0; p[v1].z = 0;
            p[v2].x = 0; p[v2].y = 1801; p[v2].z = 0;
        }
        p[0].x = p[0].y = p[0].z = 0;
        d += xn_diff(tris, k, p, nS, a, b);
        T_CHECK(a[0].x == 0 && a[0].y == 0 && a[0].z == SN_ONE_ROT, "fan of %u faces: the centre's normal (0, 0, 1), got (%d, %d, %d)",
                k, (int)a[0].x, (int)a[0].y, (int)a[0].z);
    }
    T_CHECK(d == 0, "fans of 127, 128, 200 faces: %u normals differ from the reference", d);
}
#endif

static void asset(const char *name, pose_fn_t pf) {
    char path[512], nm[64];
    pu_rt rt;
    unsigned k, s, nJ, bad, nS, far = 0, moved = 0;
    sn_xform *pose;
    sn_vec3 *out, *mid;
    double h, worst = 0;
    snprintf(nm, sizeof nm, "%s%s", name, PU_BLOB_SUFFIX);
    pu_example(path, sizeof path, nm);
    if (pu_rt_open(&rt, path) != 0) { T_CHECK(0, "%s: cannot open", path); return; }
    nJ = rt.info.joints;
    nS = rt.info.surface_vertices;
    h = pu_len(rt.info.timestep);
    pose = malloc(nJ * sizeof *pose);
    out = malloc(nS * sizeof *out);
    mid = malloc(nS * sizeof *mid);
    for (k = 0; k < 30; k++) { pf(rt.blob, nJ, k, h, pose); sn_set_pose(rt.inst, pose, nJ); sn_step(rt.inst); }
    {
        const sn_ihdr *hd = (const sn_ihdr *)(const void *)rt.inst;
        const sn_view *v = &hd->v;
        const sn_q *pos = CARR(hd, o_pos, sn_q);
        const uint32_t first = nS / 3, cnt = nS / 2;
        T_CHECK(!v->cut, "%s: a plain lattice (the fast path)", name);
        T_CHECK(sn_get_surface(rt.inst, out, 0, nS) == SN_OK, "%s: sn_get_surface", name);
        bad = general_bad(hd, out, 0, nS);
        T_CHECK(bad == 0, "%s: %u of %u surface vertices differ from the general path", name, bad, nS);
        T_CHECK(sn_get_surface(rt.inst, mid, first, cnt) == SN_OK, "%s: sn_get_surface from %u", name, first);
        for (s = 0, bad = 0; s < cnt; s++) bad += !same_vec(mid + s, out + first + s);
        T_CHECK(bad == 0, "%s: a run from vertex %u: %u of %u differ from the whole surface's", name, first, bad, cnt);
        for (s = 0; s < nS; s++) { /* the double-precision embedding */
            const unsigned char *e = v->sec[SN_SEC_EMBED] + (size_t)s * SN_ELEM_EMBED;
            const unsigned char *cell = v->sec[SN_SEC_CELLS] + (size_t)rd16(e) * SN_ELEM_CELLS;
            double t[3], ref[3] = {0, 0, 0}, mag = 0, tol, got[3];
            unsigned a, q;
            for (q = 0; q < 3; q++) t[q] = rd16(e + 2 + 2 * q) / 32768.0;
            for (a = 0; a < 8; a++) {
                const double phi = ((a & 1) ? t[0] : 1 - t[0]) * ((a & 2) ? t[1] : 1 - t[1]) * ((a & 4) ? t[2] : 1 - t[2]);
                const unsigned vx = rd16(cell + 2 * a);
                for (q = 0; q < 3; q++) { ref[q] += phi * (double)pos[3 * vx + q]; mag += fabs((double)pos[3 * vx + q]); }
            }
            got[0] = (double)out[s].x; got[1] = (double)out[s].y; got[2] = (double)out[s].z;
#if defined(SN_FLOAT)
            mag = mag * fabs((double)hd->to_pub);
            for (q = 0; q < 3; q++) {
                const double o = (double)hd->origin[q], r = o + ref[q] * (double)hd->to_pub, d = fabs(got[q] - r);
                tol = ldexp(fabs(o) > mag ? fabs(o) : mag, -20);
                if (d / tol > worst) worst = d / tol;
                far += !(d <= tol);
            }
#else
            {
                const int sh = v->len_shift - (SN_Q_LEN - SN_LEN_FRAC);
                tol = (ldexp(mag, -31) + 0.5) * ldexp(1.0, sh) + (sh < 0 ? 0.5 : 0.0);
                for (q = 0; q < 3; q++) {
                    const double r = (double)hd->origin[q] + ldexp(ref[q], sh), d = fabs(got[q] - r);
                    if (d / tol > worst) worst = d / tol;
                    far += !(d <= tol);
                }
            }
#endif
        }
        T_CHECK(far == 0, "%s: %u components beyond the tolerance of the double embedding (worst %.3f of it)", name, far, worst);
        T_FIGURE("%s: %u surface vertices bit for bit with the general path; against double, worst %.3f of the tolerance",
                 name, nS, worst);
        if (v->nT) {
            sn_vec3 *nrm = malloc(nS * sizeof *nrm);
            double nw = 0;
            unsigned nb;
            T_CHECK(sn_get_normals(rt.inst, out, nrm) == SN_OK, "%s: sn_get_normals", name);
            nb = normals_bad(hd, out, nrm, &nw);
            T_CHECK(nb == 0, "%s: %u of %u normals beyond the bound of the double normals (worst %.3f of it)", name, nb, nS, nw);
            T_FIGURE("%s: %u normals against double, worst %.3f of the bound", name, nS, nw);
#if !defined(SN_FLOAT)
            {   /* bit for bit with the reference (the loop before issue 15) */
                sn_vec3 *rn = malloc(nS * sizeof *rn);
                unsigned d = 0;
                ref_xnormals(v->sec[SN_SEC_TRIS], v->nT, out, nS, rn);
                for (s = 0; s < nS; s++) d += !same_vec(rn + s, nrm + s);
                T_CHECK(d == 0, "%s: %u of %u normals differ from the reference", name, d, nS);
                free(rn);
                xnormals_random(name, v);
            }
            {   /* the surface moved by 2^30 in x: positions beyond +-2^29 take the clamped edge path, whose
                 * edges here are the same (well inside 2^30), so every normal must be the same bits */
                sn_vec3 *far = malloc(nS * sizeof *far), *nf = malloc(nS * sizeof *nf);
                unsigned d = 0;
                for (s = 0; s < nS; s++) { far[s] = out[s]; far[s].x = out[s].x + (1 << 30); }
                T_CHECK(sn_get_normals(rt.inst, far, nf) == SN_OK, "%s: sn_get_normals (moved)", name);
                for (s = 0; s < nS; s++) d += !same_vec(nf + s, nrm + s);
                T_CHECK(d == 0, "%s: the surface moved by 2^30 (clamped edge path): %u of %u normals differ", name, d, nS);
                free(far); free(nf);
            }
#endif
            free(nrm);
        }
        {   /* control: one lattice corner moved by 2^-4 of a cell moves the vertices it carries */
            sn_q *pw = (sn_q *)(void *)(uintptr_t)(const void *)pos;
            const unsigned vx = rd16(v->sec[SN_SEC_CELLS] + (size_t)rd16(v->sec[SN_SEC_EMBED]) * SN_ELEM_CELLS);
            const sn_q keep = pw[3 * vx];
            pw[3 * vx] = keep + (sn_q)(v->cell / 16);
            sn_get_surface(rt.inst, mid, 0, nS);
            for (s = 0; s < nS; s++) moved += !same_vec(mid + s, out + s);
            pw[3 * vx] = keep;
            T_CHECK(moved > 0, "%s: control: a corner moved, %u surface vertices follow (want > 0)", name, moved);
            T_CHECK(general_bad(hd, mid, 0, nS) > 0 || moved == 0, "%s: control: the general path sees the restored corner", name);
        }
    }
    free(pose); free(out); free(mid);
    pu_rt_close(&rt);
}

int main(void) {
#if defined(SN_FLOAT)
    fnormals_lanes();
#else
    xnormals_fan();
#endif
    asset("cow", pu_cow_pose);
    asset("beast", pu_beast_pose);
    return T_END();
}
