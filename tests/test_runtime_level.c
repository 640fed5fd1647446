/* test_runtime_level.c -- level of detail (runtime/src/sn_level.c): a blob
 * baked with 'levels 2' against the same description baked without it.
 *
 *   usage: level_runtime PLAIN.blob LOD.blob   (tests/scripts/test_level.sh)
 *
 * Level 0 of the two-level blob steps bit for bit as the plain blob; a
 * switch to the finer level does not move the surface (the coarse field is
 * interpolated onto the fine vertices: exact up to one rounding); a switch
 * back drops the detail, and the surface moves by less than a stated
 * fraction of a cell; refused levels, stats, reset, and the step's health
 * through switches. */
#include "sinew.h"
#include "sn_format.h"
#include "sn_test.h"
#include "fuzz/sn_tblob.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "level_util.h"

static double max_move(const sn_vec3 *a, const sn_vec3 *b, uint32_t n)
{
    double m = 0;
    uint32_t i;
    for (i = 0; i < n; i++) {
        double dx = D(a[i].x) - D(b[i].x), dy = D(a[i].y) - D(b[i].y), dz = D(a[i].z) - D(b[i].z);
        m = fmax(m, sqrt(dx * dx + dy * dy + dz * dz));
    }
    return m;
}

static double rms_move(const sn_vec3 *a, const sn_vec3 *b, uint32_t n)
{
    double s = 0;
    uint32_t i;
    for (i = 0; i < n; i++) {
        double dx = D(a[i].x) - D(b[i].x), dy = D(a[i].y) - D(b[i].y), dz = D(a[i].z) - D(b[i].z);
        s += dx * dx + dy * dy + dz * dz;
    }
    return sqrt(s / n);
}

static uint32_t rd16(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8; }
static uint32_t rd32(const unsigned char *p) { return rd16(p) | rd16(p + 2) << 16; }
static const unsigned char *sec_of(const unsigned char *b, int k) { return b + rd32(b + SN_H_SECTIONS + SN_SECTION_ENTRY * k); }
/* value of a map entry {cell, t Q15} over the cell's corners of the lattice `cells` */
static void interp(const unsigned char *e, const unsigned char *cells, const double *val, double out[3])
{
    const unsigned char *c = cells + 16 * (size_t)rd16(e);
    double t[3];
    int a, k;
    for (k = 0; k < 3; k++) t[k] = rd16(e + 2 + 2 * k) / 32768.0;
    out[0] = out[1] = out[2] = 0;
    for (a = 0; a < 8; a++) {
        double w = ((a & 1) ? t[0] : 1 - t[0]) * ((a & 2) ? t[1] : 1 - t[1]) * ((a & 4) ? t[2] : 1 - t[2]);
        for (k = 0; k < 3; k++) out[k] += w * val[3 * rd16(c + 2 * a) + k];
    }
}

/* Adaptation's measure (seed 000 §4.7; runtime/LEVELS.md): on level 1, the detail of each free
 * vertex, |p_i - (level-0 field sampled at the level-0 vertices, interpolated back at i)|, in
 * level-0 cells; counts the free vertices above each threshold (what an adaptive step would
 * keep active). */
static void detail_counts(const unsigned char *top, const sn_instance *q, uint32_t nv1, uint32_t nf1, uint32_t nv0, double cell,
                          const double *th, int nth, uint32_t *cnt)
{
    const unsigned char *fine = sec_of(top, SN_SEC_LEVEL_BLOB), *up = sec_of(top, SN_SEC_LEVEL_UP), *down = sec_of(top, SN_SEC_LEVEL_DOWN);
    sn_vec3 *lat = malloc(sizeof *lat * nv1);
    double *pf = malloc(sizeof(double) * 3 * nv1), *pc = malloc(sizeof(double) * 3 * nv0);
    uint32_t i;
    int k;
    sn_get_lattice(q, lat, 0, nv1);
    for (i = 0; i < nv1; i++) { pf[3 * i] = D(lat[i].x); pf[3 * i + 1] = D(lat[i].y); pf[3 * i + 2] = D(lat[i].z); }
    for (i = 0; i < nv0; i++) interp(down + 8 * (size_t)i, sec_of(fine, SN_SEC_CELLS), pf, pc + 3 * i);
    for (k = 0; k < nth; k++) cnt[k] = 0;
    for (i = 0; i < nf1; i++) {
        double b[3], d;
        interp(up + 8 * (size_t)i, sec_of(top, SN_SEC_CELLS), pc, b);
        d = sqrt((pf[3 * i] - b[0]) * (pf[3 * i] - b[0]) + (pf[3 * i + 1] - b[1]) * (pf[3 * i + 1] - b[1]) +
                 (pf[3 * i + 2] - b[2]) * (pf[3 * i + 2] - b[2])) / cell;
        for (k = 0; k < nth; k++) cnt[k] += d > th[k];
    }
    free(lat); free(pf); free(pc);
}

int main(int argc, char **argv)
{
    size_t n0, n1;
    unsigned char *b0, *b1;
    const sn_blob *plain, *lod;
    sn_blob_info i0, i1;
    void *m0, *m1, *m2;
    sn_instance *p, *q, *r;
    sn_xform *xf;
    sn_vec3 *s0, *s1;
    sn_stats st;
    double cell, up_max = 0, down_max = 0, down_rms = 0;
    int k, same = 1;
    const char *name = argc > 2 ? strrchr(argv[2], '/') : NULL;
    name = name ? name + 1 : argc > 2 ? argv[2] : "?";
    (void)t_seed;
    (void)tb_build;   /* sn_tblob.h: only its checksum helper is used here */
    if (argc < 3) { printf("usage: %s PLAIN.blob LOD.blob\n", argv[0]); return 2; }
    b0 = load(argv[1], &n0); b1 = load(argv[2], &n1);
    if (!b0 || !b1) { T_CHECK(0, "cannot read %s / %s (make them: tests/level.mk)", argv[1], argv[2]); return T_END(); }
    T_CHECK(sn_blob_validate(b0, n0, &plain) == SN_OK && sn_blob_validate(b1, n1, &lod) == SN_OK, "%s: validate", name);
    if (!plain || !lod) return T_END();
    sn_blob_get_info(plain, &i0); sn_blob_get_info(lod, &i1);
    cell = cell_of(b1);
    T_CHECK(sn_lod_levels(plain) == 1 && sn_lod_levels(lod) == 2 && sn_lod_levels(NULL) == 0, "%s: levels %u %u", name,
            sn_lod_levels(plain), sn_lod_levels(lod));
    T_CHECK(i1.vertices == i0.vertices && i1.free_vertices == i0.free_vertices && i1.instance_bytes > i0.instance_bytes,
            "%s: level 0 is the plain lattice (%u vertices); the instance is sized for level 1 (%u > %u bytes)", name,
            i1.vertices, i1.instance_bytes, i0.instance_bytes);
    T_FIGURE("%s [%s]: blob %u bytes (plain %u), instance %u bytes (plain %u)", name, FL, i1.blob_bytes, i0.blob_bytes,
             i1.instance_bytes, i0.instance_bytes);
    m0 = malloc(i0.instance_bytes); m1 = malloc(i1.instance_bytes); m2 = malloc(i1.instance_bytes);
    xf = malloc(sizeof *xf * i1.joints);
    s0 = malloc(sizeof *s0 * i1.surface_vertices); s1 = malloc(sizeof *s1 * i1.surface_vertices);
    if (sn_instance_init(m0, i0.instance_bytes, plain, &p) != SN_OK || sn_instance_init(m1, i1.instance_bytes, lod, &q) != SN_OK ||
        sn_instance_init(m2, i1.instance_bytes, lod, &r) != SN_OK) {
        T_CHECK(0, "%s: init", name);
        return T_END();
    }
    T_CHECK(sn_set_lod(p, 1) == SN_ERR_ARG && sn_set_lod(q, 2) == SN_ERR_ARG && sn_set_lod(NULL, 0) == SN_ERR_NULL,
            "%s: levels the blob does not have are refused", name);

    /* 1. level 0 steps as the plain blob, bit for bit (the finer level changes nothing there) */
    for (k = 1; k <= 40; k++) {
        pose_at(plain, i0.joints, k, xf);
        sn_set_pose(p, xf, i0.joints); sn_set_pose(q, xf, i1.joints);
        sn_step(p); sn_step(q);
        same &= sn_state_hash(p) == sn_state_hash(q);
    }
    T_CHECK(same, "%s: level 0 of the two-level blob steps as the plain blob (hash)", name);
    T_CHECK(sn_set_lod(q, 0) == SN_OK && sn_state_hash(p) == sn_state_hash(q), "%s: setting the level in force changes nothing", name);

    /* 2. up: the surface does not move at the switch */
    for (k = 41; k <= 160; k++) {
        pose_at(lod, i1.joints, k, xf);
        if (k % 40 == 1) {   /* switch before steps 41 (up), 81 (down), 121 (up) */
            uint32_t lv = (uint32_t)((k / 40) % 2);
            double mv;
            sn_get_surface(q, s0, 0, i1.surface_vertices);
            T_CHECK(sn_set_lod(q, lv) == SN_OK, "%s: sn_set_lod %u", name, lv);
            sn_get_surface(q, s1, 0, i1.surface_vertices);
            mv = max_move(s0, s1, i1.surface_vertices) / cell;
            if (lv == 1) {
                uint32_t v, nbig = 0;
                for (v = 0; v < i1.surface_vertices; v++) nbig += max_move(s0 + v, s1 + v, 1) > 2e-5 * cell;
                T_FIGURE("%s [%s]: up at step %d: %u of %u surface vertices moved more than 2e-5 cells", name, FL, k, nbig, i1.surface_vertices);
                up_max = fmax(up_max, mv);
            }
            else { down_max = fmax(down_max, mv); down_rms = fmax(down_rms, rms_move(s0, s1, i1.surface_vertices) / cell); }
            sn_get_stats(q, &st);
            T_CHECK(st.lod == lv && st.lattice_vertices == (lv ? st.lattice_vertices : i1.vertices) && (lv == 0 || st.lattice_vertices > i1.vertices),
                    "%s: stats lod %u, %u lattice vertices", name, st.lod, st.lattice_vertices);
        }
        sn_set_pose(q, xf, i1.joints);
        sn_step(q);
    }
    T_FIGURE("%s [%s]: surface move at a switch, in cells of level 0 (%g mesh units): up %.3g (max), down %.3g max, %.3g rms",
             name, FL, cell, up_max, down_max, down_rms);
    /* up: exact in real numbers (a trilinear field sampled and re-interpolated on a sub-box is itself). What is
     * left is the surface's embedding: each level stores its own trilinear coordinates in Q15, so each surface
     * point is off by up to 2^-16 of its (deformed) cell per axis, differently on the two levels: 2 x sqrt(3) x
     * 2^-16 = 5.3e-5 cells for undeformed cells, times their stretch (here up to about 3): 2e-4 of a level-0
     * cell. The values' own rounding (Q22 of a 2^len_shift unit: about 1e-6 cells) is far below. */
    T_CHECK(up_max <= 2e-4, "%s: the surface moved %.3g cells when the finer level came in (want <= 2e-4: the embeddings' Q15)", name, up_max);
    /* down: the detail the coarse lattice cannot hold, and the flesh the finer level lets move near the bones
     * (its automatic bone radii follow its cell) that level 0 carries rigidly. Measured through this violent
     * swing (largest displacement from skinning 1.7 to 2.2 cells): 0.29 (cow), 0.26 (beast) of a level-0 cell at
     * the worst vertex, 0.10 and 0.08 rms, fixed and float alike. The bound is that with a margin: a larger jump
     * means the transfer broke. It is a visible pop up close: switch down far away or when the detail is small
     * (runtime/LEVELS.md). */
    T_CHECK(down_max <= 0.35, "%s: the surface moved %.3g cells when the finer level went out (want <= 0.35)", name, down_max);
    sn_get_stats(q, &st);
    T_CHECK(st.saturations == 0, "%s: %u saturations through the switches", name, st.saturations);
    T_FIGURE("%s [%s]: after 160 steps with 3 switches: largest displacement %.3g cells, energy %.4g J (max %.4g), bound steps %u",
             name, FL, D(st.disp_max), D(st.energy), D(st.energy_max), st.bound_steps);

    /* figures for adaptation (not checks): free vertices of level 1 whose detail exceeds a threshold, over
     * 100 steps of the swing on level 1 at rest (at rest: the sag's detail) */
    {
        static const double th[3] = {0.01, 0.03, 0.1};
        uint32_t cnt[3], mx[3] = {0, 0, 0}, rest[3] = {0, 0, 0};
        double mean[3] = {0, 0, 0};
        sn_stats s1;
        sn_reset(q);
        sn_set_lod(q, 1);
        sn_get_stats(q, &s1);
        {
            const unsigned char *fine = sec_of(b1, SN_SEC_LEVEL_BLOB);
            uint32_t nv1 = rd32(fine + SN_H_N_VERTICES), nf1 = rd32(fine + SN_H_N_FREE);
            for (k = 1; k <= 100; k++) {
                int t;
                pose_at(lod, i1.joints, k <= 30 ? 0 : k, xf);
                sn_set_pose(q, xf, i1.joints);
                sn_step(q);
                detail_counts(b1, q, nv1, nf1, i1.vertices, cell, th, 3, cnt);
                if (k == 30) memcpy(rest, cnt, sizeof rest);
                for (t = 0; t < 3; t++) if (k > 30) { mx[t] = cnt[t] > mx[t] ? cnt[t] : mx[t]; mean[t] += cnt[t] / 70.0; }
            }
            T_FIGURE("%s [%s]: adaptation: of level 1's %u free vertices, detail over 0.01 / 0.03 / 0.1 level-0 cells: at rest %u / %u / %u, "
                     "swinging mean %.0f / %.0f / %.0f, max %u / %u / %u", name, FL, nf1, rest[0], rest[1], rest[2], mean[0], mean[1], mean[2],
                     mx[0], mx[1], mx[2]);
        }
    }

    /* 4. the validator's pair checks (runtime/BLOB.md "Level of detail"), checksums fixed after each change */
    {
        unsigned char *h = malloc(n1 + 8);
        const sn_blob *bb;
        unsigned char *fine, *up, *down;
        uint32_t nc0 = rd32(b1 + SN_H_N_CELLS), nc1;
#define LV_CASE(want, what, change) do { \
            memcpy(h, b1, n1); fine = h + rd32(h + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_LEVEL_BLOB); \
            up = h + rd32(h + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_LEVEL_UP); \
            down = h + rd32(h + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_LEVEL_DOWN); (void)up; (void)down; \
            change; tb_fix_crc(fine); tb_fix_crc(h); \
            T_CHECK(sn_blob_validate(h, n1, &bb) == (want), "%s: %s: got %s, want %s", name, what, \
                    sn_status_str(sn_blob_validate(h, n1, &bb)), sn_status_str(want)); } while (0)
        nc1 = rd32(sec_of(b1, SN_SEC_LEVEL_BLOB) + SN_H_N_CELLS);
        LV_CASE(SN_OK, "unchanged", (void)0);
        LV_CASE(SN_ERR_INDEX, "LEVEL_UP cell = level 0's nC", tb_u16(up, (uint16_t)nc0));
        LV_CASE(SN_ERR_INDEX, "LEVEL_DOWN cell = level 1's nC", tb_u16(down + 8, (uint16_t)nc1));
        LV_CASE(SN_ERR_INDEX, "LEVEL_DOWN t = 32769", tb_u16(down + 2, 32769));
        LV_CASE(SN_ERR_HEADER, "level 1 with another length unit", fine[SN_H_LEN_SHIFT]++);
        LV_CASE(SN_ERR_VALUE, "level 1 with another joint rest position",
                fine[rd32(fine + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_JOINTS) + 8 + SN_ELEM_JOINTS(4)] ^= 1);   /* joint 1, x (real 4 bytes in both runtime flavours) */
        LV_CASE(SN_ERR_SECTION, "level 1 with a level of its own",
                tb_u32(fine + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_LEVEL_UP + 8, 1));
        LV_CASE(SN_ERR_HEADER, "instance bytes of level 0 alone", tb_u32(h + SN_H_INSTANCE_BYTES, i0.instance_bytes));
#undef LV_CASE
        free(h);
    }

    /* 3. the level survives reset, and a reset instance steps as a fresh one set to that level */
    sn_set_lod(q, 1);
    sn_reset(q);
    sn_set_lod(r, 1);
    sn_get_stats(q, &st);
    T_CHECK(st.lod == 1, "%s: the level survives sn_reset", name);
    for (k = 1, same = 1; k <= 20; k++) {
        pose_at(lod, i1.joints, k, xf);
        sn_set_pose(q, xf, i1.joints); sn_set_pose(r, xf, i1.joints);
        sn_step(q); sn_step(r);
        same &= sn_state_hash(q) == sn_state_hash(r);
    }
    T_CHECK(same, "%s: reset at level 1 steps as a fresh instance set to level 1 (hash)", name);

    /* 4. SN_MODE_BLENDED across switches: the size query covers the larger
     * level, the mode survives a switch, and nothing is written past the
     * exact buffer (guard bytes) */
    {
        size_t nb = sn_instance_size_mode(lod, SN_MODE_BLENDED), g;
        unsigned char *mb = malloc(nb + 256);
        sn_instance *bi;
        sn_vec3 *sv = malloc(sizeof *sv * i1.surface_vertices);
        int ok = 1, fin = 1;
        uint32_t vtx;
        memset(mb, 0xA5, nb + 256);
        T_CHECK(sn_instance_init(mb, nb, lod, &bi) == SN_OK && sn_set_mode(bi, SN_MODE_BLENDED) == SN_OK, "%s: blended instance", name);
        for (k = 1; k <= 40; k++) {
            if (k == 10 || k == 30) ok &= sn_set_lod(bi, 1) == SN_OK;
            if (k == 20) ok &= sn_set_lod(bi, 0) == SN_OK;
            pose_at(lod, i1.joints, k, xf);
            ok &= sn_set_pose(bi, xf, i1.joints) == SN_OK;
            ok &= sn_step(bi) == SN_OK;
        }
        sn_get_stats(bi, &st);
        ok &= st.mode == SN_MODE_BLENDED && st.lod == 1;
        ok &= sn_get_surface(bi, sv, 0, i1.surface_vertices) == SN_OK;
#if defined(SN_FLOAT)
        for (vtx = 0; vtx < i1.surface_vertices; vtx++) fin &= isfinite(sv[vtx].x) && isfinite(sv[vtx].y) && isfinite(sv[vtx].z);
#else
        (void)vtx;
#endif
        for (g = 0; g < 256; g++) ok &= mb[nb + g] == 0xA5;
        T_CHECK(ok && fin, "%s: blended through switches 0->1->0->1 (40 steps): every call accepted, the mode kept, the surface finite, "
                "the 256 guard bytes after sn_instance_size_mode untouched", name);
        free(mb); free(sv);
    }
    free(b0); free(b1); free(m0); free(m1); free(m2); free(xf); free(s0); free(s1);
    return T_END();
}
