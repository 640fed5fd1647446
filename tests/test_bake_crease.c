/* test_bake_crease.c -- the host tool's crease preprocessing (seed 003
 * §3.4.1; tools/sb_crease.c) and the crease sections it writes.
 *
 *  - sb_crease_inside on a known triangle: inside / behind / too deep /
 *    projection outside / degenerate, the distance exact to 1e-12 (a few
 *    double roundings of unit-size numbers), the nearest corner
 *  - neighbourhoods on the limb mesh (9 x 2 x 2 box, 322 vertices): VNBR
 *    row s is s then its one-ring in increasing order (edges recomputed here
 *    from the triangles), TNBR row s the triangles with a corner in it,
 *    increasing, padded with 0xFFFF
 *  - the seed set D of the limb bent to 120 degrees about +z at the elbow
 *    (x = 4): the forearm folds onto the +y side. Rigid halves of half
 *    thickness 1 meeting at 60 degrees overlap where the distance along
 *    the bone from the elbow is below 1 / tan 30 = 1.73 mesh units; so every
 *    seed vertex lies on the inner side (rest y >= 0.5: the top face y = 1
 *    and the upper half of the side faces, within a vertex spacing, 0.5,
 *    of it) and within 1.73 + 0.5 (the elastic spread of half a cell) +
 *    0.25 of the elbow along x; the pair's two vertices lie on opposite
 *    sides of the elbow (x < 4 < x' or the reverse, the fold's two faces).
 *    At 10 degrees the overlap (1 / tan 85 = 0.09) is below the vertex
 *    spacing: no pair. At 90 degrees (overlap 1) fewer pairs than at 120.
 *  - the blob: CREASE record (list, active, widths, depth and push in Q22
 *    internal units), the pairs and rows as the model holds them
 *  - determinism: two bakes give the same bytes
 *  - description errors with file:line
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sb.h"
#include "sn_format.h"
#include "sn_test.h"

static const char *dir(void) { return getenv("BUILD") ? getenv("BUILD") : "build"; }
static unsigned u16(const unsigned char *p) { return (unsigned)p[0] | (unsigned)p[1] << 8; }
static uint32_t u32(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static uint32_t sec_off(const unsigned char *b, int k) { return u32(b + SN_H_SECTIONS + 16 * k); }
static uint32_t sec_cnt(const unsigned char *b, int k) { return u32(b + SN_H_SECTIONS + 16 * k + 8); }

/* the limb description with one crease line (and settings) in $BUILD/tests/crease_<name>/ */
static int write_limb(const char *name, const char *extra, char *path, size_t pn)
{
    char d[700], cmd[1600];
    FILE *f, *in = fopen("tools/examples/limb/limb.sinew", "r");
    int c;
    snprintf(d, sizeof d, "%s/tests/crease_%s", dir(), name);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s' && cp tools/examples/limb/limb.obj '%s/limb.obj'", d, d);
    if (!in || system(cmd) != 0) { if (in) fclose(in); return -1; }
    snprintf(path, pn, "%s/limb.sinew", d);
    f = fopen(path, "w");
    if (!f) { fclose(in); return -1; }
    while ((c = fgetc(in)) != EOF) fputc(c, f);
    fclose(in);
    fputs(extra, f);
    return fclose(f);
}

static void test_inside(void)
{
    const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}; /* normal +z */
    double dist = 0;
    int corner = -1;
    const double p1[3] = {0.25, 0.25, -0.1}, p2[3] = {0.25, 0.25, 0.1}, p3[3] = {0.25, 0.25, -0.6}, p4[3] = {0.8, 0.8, -0.1};
    const double p5[3] = {0.9, 0.05, -0.2}, p6[3] = {0.02, 0.9, -0.2}, deg[3] = {2, 0, 0};
    T_CHECK(sb_crease_inside(p1, a, b, c, 0.5, &dist, &corner) == 1 && fabs(dist + 0.1) < 1e-12 && corner == 0,
            "inside: 0.1 behind the centroid side, corner a (dist %.15g, corner %d)", dist, corner);
    T_CHECK(sb_crease_inside(p2, a, b, c, 0.5, &dist, &corner) == 0 && fabs(dist - 0.1) < 1e-12, "in front: not inside (dist %g)", dist);
    T_CHECK(sb_crease_inside(p3, a, b, c, 0.5, &dist, &corner) == 0 && fabs(dist + 0.6) < 1e-12, "deeper than the depth: not inside");
    T_CHECK(sb_crease_inside(p4, a, b, c, 0.5, &dist, &corner) == 0, "projection outside the triangle: not inside");
    T_CHECK(sb_crease_inside(p5, a, b, c, 0.5, &dist, &corner) == 1 && corner == 1, "nearest corner b (%d)", corner);
    T_CHECK(sb_crease_inside(p6, a, b, c, 0.5, &dist, &corner) == 1 && corner == 2, "nearest corner c (%d)", corner);
    T_CHECK(sb_crease_inside(p1, a, b, deg, 0.5, &dist, &corner) == 0, "degenerate triangle: never inside");
}

/* bake a description; 0 on success */
static int bake(const char *path, int flavour, sb_model *o, sb_blob *b)
{
    int rc = sb_bake_file(path, flavour, 1, o, b);
    if (rc) printf("  bake %s: %s\n", path, sb_error());
    return rc;
}

static void test_limb(void)
{
    char path[800];
    sb_model o, o2;
    sb_blob b, b2;
    sb_mesh m;
    int s, k, q_, bad_v = 0, bad_t = 0, bad_side = 0, bad_where = 0, n120;
    memset(&m, 0, sizeof m);
    if (write_limb("120", "crease elbow:0,0,1,120 steps 120\ncrease_settings list 64 active 32 ring 1 depth 0.5 push 0.125\n", path, sizeof path) ||
        bake(path, SB_FIXED, &o, &b) || sb_mesh_load_obj("tools/examples/limb/limb.obj", &m)) {
        T_CHECK(0, "bake the limb with a 120-degree crease");
        return;
    }
    T_CHECK(o.crease == 1 && o.cr_nD > 0 && o.ns == m.nv, "120 degrees: %d seed pairs", o.cr_nD);
    /* neighbourhood rows (format 6.0: only for the vertices the runtime can query, owners increasing) against edges
     * recomputed from the triangles; every seed vertex has a row */
    T_CHECK(o.cr_nq >= 1 && o.cr_nq <= o.ns, "%d neighbourhood rows of %d surface vertices", o.cr_nq, o.ns);
    for (k = 0; k < 2 * o.cr_nD; k++) {
        int q;
        for (q = 0; q < o.cr_nq && o.cr_vnbr[(size_t)q * o.cr_kv] != o.cr_pairs[k]; q++) {}
        if (q == o.cr_nq) bad_v++;
    }
    T_CHECK(bad_v == 0, "every seed vertex owns a row (%d do not)", bad_v);
    for (k = 1; k < o.cr_nq; k++) if (!(o.cr_vnbr[(size_t)k * o.cr_kv] > o.cr_vnbr[(size_t)(k - 1) * o.cr_kv])) bad_v++;
    T_CHECK(bad_v == 0, "row owners strictly increasing (%d not)", bad_v);
    for (q_ = 0; q_ < o.cr_nq; q_++) {
        int ring[64], nr = 0, t, e, want_t[128], nt = 0;
        s = o.cr_vnbr[(size_t)q_ * o.cr_kv];
        for (t = 0; t < m.nt; t++)
            for (e = 0; e < 3; e++)
                if (m.tri[3 * t + e] == s) {
                    int q, x;
                    for (q = 1; q < 3; q++) {
                        x = m.tri[3 * t + (e + q) % 3];
                        for (k = 0; k < nr && ring[k] != x; k++) {}
                        if (k == nr && nr < 64) ring[nr++] = x;
                    }
                }
        /* sort the ring */
        for (k = 1; k < nr; k++) { int x = ring[k], q = k - 1; while (q >= 0 && ring[q] > x) { ring[q + 1] = ring[q]; q--; } ring[q + 1] = x; }
        for (k = 0; k < o.cr_kv; k++) {
            int want = k == 0 ? s : (k - 1 < nr ? ring[k - 1] : -1);
            if (o.cr_vnbr[(size_t)q_ * o.cr_kv + k] != want) bad_v++;
        }
        if (nr + 1 > o.cr_kv) bad_v++;
        for (t = 0; t < m.nt; t++) {
            int hit = 0;
            for (e = 0; e < 3; e++) {
                int x = m.tri[3 * t + e];
                hit |= x == s;
                for (k = 0; k < nr; k++) hit |= x == ring[k];
            }
            if (hit && nt < 128) want_t[nt++] = t;
        }
        for (k = 0; k < o.cr_kt; k++)
            if (o.cr_tnbr[(size_t)q_ * o.cr_kt + k] != (k < nt ? want_t[k] : -1)) bad_t++;
        if (nt > o.cr_kt) bad_t++;
    }
    T_CHECK(bad_v == 0, "VNBR rows: the vertex, then its one-ring increasing, padded (%d bad entries; width %d)", bad_v, o.cr_kv);
    T_CHECK(bad_t == 0, "TNBR rows: the triangles touching the row, increasing, padded (%d bad; width %d)", bad_t, o.cr_kt);
    /* where the seeds are */
    for (k = 0; k < o.cr_nD; k++) {
        const double *pi = m.v + 3 * o.cr_pairs[2 * k], *pj = m.v + 3 * o.cr_pairs[2 * k + 1];
        if (!((pi[0] - 4) * (pj[0] - 4) < 0)) bad_side++;
        if (pi[1] < 0.5 - 1e-9 || pj[1] < 0.5 - 1e-9 || fabs(pi[0] - 4) > 1.73 + 0.5 + 0.25 || fabs(pj[0] - 4) > 1.73 + 0.5 + 0.25) bad_where++;
        printf("  seed %d: vertex %d (%g %g %g) - vertex %d (%g %g %g)\n", k, o.cr_pairs[2 * k], pi[0], pi[1], pi[2], o.cr_pairs[2 * k + 1], pj[0], pj[1], pj[2]);
    }
    T_CHECK(bad_side == 0, "every seed pair spans the elbow (%d do not)", bad_side);
    T_CHECK(bad_where == 0, "every seed vertex on the inner side (y >= 0.5) within 2.48 of the elbow (%d are not)", bad_where);
    /* the blob holds what the model holds */
    {
        const unsigned char *B = b.bytes, *r = B + sec_off(B, SN_SEC_CREASE);
        int ok = sec_cnt(B, SN_SEC_CREASE) == 1 && sec_cnt(B, SN_SEC_CREASE_PAIRS) == (uint32_t)o.cr_nD &&
                 sec_cnt(B, SN_SEC_CREASE_VNBR) == (uint32_t)(o.cr_nq * o.cr_kv) && sec_cnt(B, SN_SEC_CREASE_TNBR) == (uint32_t)(o.cr_nq * o.cr_kt) &&
                 u16(r) == 64 && u16(r + 2) == 32 && r[4] == o.cr_kv && r[5] == o.cr_kt && u16(r + 6) == (unsigned)o.cr_nq && u32(r + 8) == 0;
        /* len_shift 3: 0.5 mesh units = 1/16 internal = 2^18 at Q22; push 0.125 = 2^16 */
        T_CHECK(ok && u32(r + 12) == (1u << 18) && u32(r + 16) == (1u << 16) && B[SN_H_LEN_SHIFT] == 3,
                "CREASE record: list 64, active 32, widths, depth 2^18, push 2^16 (Q22, len_shift 3): depth %u push %u", u32(r + 12), u32(r + 16));
        for (k = 0; k < o.cr_nD; k++)
            ok &= u16(B + sec_off(B, SN_SEC_CREASE_PAIRS) + 4 * k) == (unsigned)o.cr_pairs[2 * k] &&
                  u16(B + sec_off(B, SN_SEC_CREASE_PAIRS) + 4 * k + 2) == (unsigned)o.cr_pairs[2 * k + 1];
        for (k = 0; k < o.cr_nq * o.cr_kt; k++)
            ok &= u16(B + sec_off(B, SN_SEC_CREASE_TNBR) + 2 * k) == (o.cr_tnbr[k] < 0 ? 0xFFFFu : (unsigned)o.cr_tnbr[k]);
        for (k = 0; k < o.cr_nq * o.cr_kv; k++)
            ok &= u16(B + sec_off(B, SN_SEC_CREASE_VNBR) + 2 * k) == (o.cr_vnbr[k] < 0 ? 0xFFFFu : (unsigned)o.cr_vnbr[k]);
        T_CHECK(ok, "pairs and rows written as the model holds them");
        T_FIGURE("limb at 120 deg: %d seed pairs, %d of %d vertices with rows; crease sections %u bytes (CREASE %d, PAIRS %d, VNBR %d, TNBR %d), blob %lu bytes",
                 o.cr_nD, o.cr_nq, o.ns, (unsigned)(SN_ELEM_CREASE(4) + 4 * o.cr_nD + 2 * o.cr_nq * (o.cr_kv + o.cr_kt)), SN_ELEM_CREASE(4), 4 * o.cr_nD,
                 2 * o.cr_nq * o.cr_kv, 2 * o.cr_nq * o.cr_kt, (unsigned long)b.size);
    }
    n120 = o.cr_nD;
    /* determinism */
    if (!bake(path, SB_FIXED, &o2, &b2)) {
        T_CHECK(b2.size == b.size && memcmp(b2.bytes, b.bytes, b.size) == 0, "two bakes, the same bytes");
        sb_blob_free(&b2); sb_model_free(&o2);
    }
    sb_blob_free(&b); sb_model_free(&o);
    /* 10 and 90 degrees */
    if (!write_limb("10", "crease elbow:0,0,1,10 steps 60\n", path, sizeof path) && !bake(path, SB_FIXED, &o, &b)) {
        T_CHECK(o.crease == 1 && o.cr_nD == 0, "10 degrees: no seed pair (%d)", o.cr_nD);
        sb_blob_free(&b); sb_model_free(&o);
    }
    if (!write_limb("90", "crease elbow:0,0,1,90 steps 90\n", path, sizeof path) && !bake(path, SB_FIXED, &o, &b)) {
        T_CHECK(o.cr_nD < n120, "90 degrees: fewer seed pairs (%d) than 120 (%d)", o.cr_nD, n120);
        T_FIGURE("limb seed pairs: 90 deg %d, 120 deg %d", o.cr_nD, n120);
        sb_blob_free(&b); sb_model_free(&o);
    }
    /* rest-distance rules: exclude (no pair closer in the rest pose; 20 mesh
     * units covers the whole limb) and thin (one seed per patch) */
    if (!write_limb("excl", "crease elbow:0,0,1,120 steps 120\ncrease_settings exclude 20\n", path, sizeof path) && !bake(path, SB_FIXED, &o, &b)) {
        T_CHECK(o.crease == 1 && o.cr_nD == 0, "exclude 20 (beyond the limb's length): no seed pair (%d)", o.cr_nD);
        sb_blob_free(&b); sb_model_free(&o);
    }
    if (!write_limb("thin", "crease elbow:0,0,1,120 steps 120\ncrease_settings thin 1.5\n", path, sizeof path) && !bake(path, SB_FIXED, &o, &b)) {
        T_CHECK(o.cr_nD > 0 && o.cr_nD < n120, "thin 1.5: fewer seed pairs (%d) than without (%d), not none", o.cr_nD, n120);
        T_FIGURE("limb seed pairs at 120 deg: %d, thin 1.5: %d", n120, o.cr_nD);
        sb_blob_free(&b); sb_model_free(&o);
    }
    sb_mesh_free(&m);
}

static void test_errors(void)
{
    static const struct { const char *extra, *want; } E[] = {
        {"crease knee:0,0,1,90\n", "unknown joint 'knee'"},
        {"crease elbow:0,0,1\n", "want JOINT:AX,AY,AZ,DEG"},
        {"crease elbow:0,0,0,90\n", "zero axis"},
        {"crease elbow:0,0,1,90 steps 0\n", "crease steps"},
        {"crease elbow:0,0,1,90\ncrease_settings list 4 active 8\n", "exceed the list size"},
        {"crease elbow:0,0,1,90\ncrease_settings list 300\n", "1..256"},
        {"crease elbow:0,0,1,90\ncrease_settings depth 0.1 push 0.2\n", "exceeds depth"},
        {"crease elbow:0,0,1,90\ncrease_settings colour 3\n", "unknown crease setting"},
        {"crease elbow:0,0,1,90\ncrease_settings thin -1\n", "must be >= 0"},
    };
    int k;
    for (k = 0; k < (int)(sizeof E / sizeof E[0]); k++) {
        char path[800], name[16];
        sb_model o;
        sb_blob b;
        snprintf(name, sizeof name, "err%d", k);
        if (write_limb(name, E[k].extra, path, sizeof path)) { T_CHECK(0, "write %s", name); continue; }
        if (sb_bake_file(path, SB_FIXED, 1, &o, &b) == 0) {
            T_CHECK(0, "'%s' accepted", E[k].extra);
            sb_blob_free(&b); sb_model_free(&o);
            continue;
        }
        T_CHECK(strstr(sb_error(), E[k].want) != NULL && strstr(sb_error(), "limb.sinew:") != NULL,
                "'%.*s' refused with file:line: %s", (int)strcspn(E[k].extra, "\n"), E[k].extra, sb_error());
    }
}

int main(void)
{
    (void)t_seed;   /* deterministic: no random cases */
    test_inside();
    test_limb();
    test_errors();
    return T_END();
}
