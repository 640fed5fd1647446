/* test_runtime_cut.c -- the cut level (runtime/LEVELS.md §2 "The cut level"):
 * a blob baked with 'levels 2 cut' against the same description baked with
 * 'levels 2'.
 *
 *   usage: cut_runtime CUT.blob LOD.blob JOINT AXIS DEG [ITERATIONS]   (tests/level.mk)
 *
 * 1. Accuracy in motion: JOINT turns by DEG about model axis AXIS (x|y|z) in
 *    12 steps and holds to step 48 (the study's ramp, LEVELS.md §3), gravity
 *    on, the runtime's iterations; the surface of the cut level (CUT's level
 *    0), of the baked level 0 (LOD's level 0) against level 1 (LOD's level 1),
 *    the same steps. The cut level must be closer at every measure.
 * 2. The switches on CUT: up moves the surface by the embeddings' rounding
 *    only (the cut field equals level 1's nodal field interpolated at every
 *    level-1 vertex not on its skeleton, and the skeleton ones are moved by
 *    their bones on both); down drops level 1's free detail: no more than
 *    LOD's baked level 0 moves in the same run.
 * 3. No saturation, a bounded displacement.
 * 4. The validator's CELLX / CELLXK checks, each crafted change refused. */
#include "sinew.h"
#include "sn_format.h"
#include "sn_test.h"
#include "fuzz/sn_tblob.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "level_util.h"

static int b_flavour(const unsigned char *b) { return b[SN_H_FLAVOUR]; }

int main(int argc, char **argv)
{
    size_t nc, nl;
    unsigned char *bc, *bl;
    const sn_blob *cut, *lod;
    sn_blob_info ic, il;
    sn_instance *c0, *l0, *l1;
    void *m[3];
    sn_xform *xf;
    sn_vec3 *sc, *s0, *s1;
    sn_stats st;
    double cell, cmax = 0, crms = 0, bmax = 0, brms = 0, up = 0, down = 0, down_rms = 0;
    int k, axis;
    int32_t joint;
    const char *name = argc > 1 ? strrchr(argv[1], '/') : NULL;
    name = name ? name + 1 : argc > 1 ? argv[1] : "?";
    (void)t_seed;
    (void)pose_at;   /* level_util.h's swing: this test ramps one joint */
    (void)tb_build;  /* sn_tblob.h: only its checksum helper is used here */
    if (argc < 6) { printf("usage: %s CUT.blob LOD.blob JOINT x|y|z DEG\n", argv[0]); return 2; }
    bc = load(argv[1], &nc); bl = load(argv[2], &nl);
    if (!bc || !bl) { T_CHECK(0, "cannot read %s / %s (make them: tests/level.mk)", argv[1], argv[2]); return T_END(); }
    T_CHECK(sn_blob_validate(bc, nc, &cut) == SN_OK && sn_blob_validate(bl, nl, &lod) == SN_OK, "%s: validate", name);
    if (!cut || !lod) return T_END();
    sn_blob_get_info(cut, &ic); sn_blob_get_info(lod, &il);
    cell = cell_of(bl);
    axis = argv[4][0] - 'x';
    joint = sn_find_joint(cut, argv[3]);
    T_CHECK(joint > 0 && axis >= 0 && axis <= 2, "%s: joint '%s', axis '%s'", name, argv[3], argv[4]);
    if (joint <= 0 || axis < 0 || axis > 2) return T_END();
    /* level 0's cells and vertices; its free ones, and those level 1's thinner bones free; level 1's skeleton added */
    T_CHECK(ic.free_vertices >= il.free_vertices && ic.vertices > il.vertices && ic.cells == il.cells,
            "%s: the cut level is level 0's lattice (%u free >= %u, %u cells) with extra skeleton vertices (%u > %u)", name,
            ic.free_vertices, il.free_vertices, ic.cells, ic.vertices, il.vertices);
    T_FIGURE("%s [%s]: cut blob %u bytes (levels 2: %u), instance %u bytes (%u); lattice %u vertices (%u free, level 0 %u; %u extra skeleton)",
             name, FL, ic.blob_bytes, il.blob_bytes, ic.instance_bytes, il.instance_bytes, ic.vertices, ic.free_vertices,
             il.free_vertices, ic.vertices - il.vertices);
    m[0] = malloc(ic.instance_bytes); m[1] = malloc(il.instance_bytes); m[2] = malloc(il.instance_bytes);
    xf = malloc(sizeof *xf * ic.joints);
    sc = malloc(sizeof *sc * ic.surface_vertices); s0 = malloc(sizeof *s0 * ic.surface_vertices); s1 = malloc(sizeof *s1 * ic.surface_vertices);
    if (sn_instance_init(m[0], ic.instance_bytes, cut, &c0) != SN_OK || sn_instance_init(m[1], il.instance_bytes, lod, &l0) != SN_OK ||
        sn_instance_init(m[2], il.instance_bytes, lod, &l1) != SN_OK || sn_set_lod(l1, 1) != SN_OK) {
        T_CHECK(0, "%s: init", name);
        return T_END();
    }

    if (argc > 6) { /* a study: every instance at these CG iterations */
        uint32_t it = (uint32_t)atoi(argv[6]);
        sn_set_iterations(c0, it); sn_set_iterations(l0, it); sn_set_iterations(l1, it);
    }
    /* 1. accuracy against level 1 in motion */
    for (k = 1; k <= 48; k++) {
        double a, b;
        ramp_pose(cut, ic.joints, joint, axis, atof(argv[5]), k, xf);
        sn_set_pose(c0, xf, ic.joints); sn_set_pose(l0, xf, ic.joints); sn_set_pose(l1, xf, ic.joints);
        sn_step(c0); sn_step(l0); sn_step(l1);
        sn_get_surface(c0, sc, 0, ic.surface_vertices); sn_get_surface(l0, s0, 0, ic.surface_vertices);
        sn_get_surface(l1, s1, 0, ic.surface_vertices);
        surf_dist(sc, s1, ic.surface_vertices, cell, &a, &b); cmax = fmax(cmax, a); crms += b / 48;
        surf_dist(s0, s1, ic.surface_vertices, cell, &a, &b); bmax = fmax(bmax, a); brms += b / 48;
    }
    T_FIGURE("%s [%s]: %s %s %s deg, 48 steps: surface vs level 1, max over steps / mean rms (level-0 cells): cut %.3g / %.3g, "
             "baked level 0 %.3g / %.3g", name, FL, argv[3], argv[4], argv[5], cmax, crms, bmax, brms);
    /* the cut level carries level 1's skeleton: it must be nearer level 1 than the baked level 0 at both measures */
    T_CHECK(cmax < bmax && crms < brms, "%s: cut level vs level 1 %.3g / %.3g cells, not below level 0's %.3g / %.3g", name, cmax, crms,
            bmax, brms);

    /* 2. switches on the cut blob, mid-motion: up at step 49, down at 61 (the baked level 0 of LOD alike, for scale) */
    {
        double lup = 0, ldown = 0, ldown_rms = 0;
        for (k = 49; k <= 72; k++) {
            ramp_pose(cut, ic.joints, joint, axis, atof(argv[5]) * (1.0 - (k - 48) / 24.0), 12, xf);
            if (k == 49 || k == 61) {
                double a, b;
                uint32_t lv = k == 49;
                sn_get_surface(c0, s0, 0, ic.surface_vertices);
                T_CHECK(sn_set_lod(c0, lv) == SN_OK, "%s: sn_set_lod %u", name, lv);
                sn_get_surface(c0, s1, 0, ic.surface_vertices);
                surf_dist(s0, s1, ic.surface_vertices, cell, &a, &b);
                if (lv) up = a; else { down = a; down_rms = b; }
                sn_get_surface(l0, s0, 0, ic.surface_vertices);
                sn_set_lod(l0, lv);
                sn_get_surface(l0, s1, 0, ic.surface_vertices);
                surf_dist(s0, s1, ic.surface_vertices, cell, &a, &b);
                if (lv) lup = a; else { ldown = a; ldown_rms = b; }
            }
            sn_set_pose(c0, xf, ic.joints); sn_set_pose(l0, xf, ic.joints);
            sn_step(c0); sn_step(l0);
        }
        T_FIGURE("%s [%s]: switch jumps (level-0 cells): cut level up %.3g, down %.3g max / %.3g rms; baked level 0 (levels 2) up %.3g, "
                 "down %.3g / %.3g", name, FL, up, down, down_rms, lup, ldown, ldown_rms);
        /* down: the cut level shares level 1's skeleton, so going down drops only level 1's free detail: no larger
         * a jump than the baked level 0's, which also drops the flesh level 1's thinner bones let move */
        T_CHECK(down <= ldown && down_rms <= ldown_rms, "%s: down-switch %.3g / %.3g cells, the baked level 0's %.3g / %.3g", name, down,
                down_rms, ldown, ldown_rms);
    }
    /* up: as test_runtime_level.c's bound (the two embeddings' Q15 coordinates, up to 2e-4 of a stretched cell) */
    T_CHECK(up <= 2e-4, "%s: the surface moved %.3g cells when level 1 came in (want <= 2e-4)", name, up);

    /* 3. health; the blended mode steps warped on the cut level */
    T_CHECK(sn_set_mode(c0, SN_MODE_WARPED) == SN_OK, "%s: warped", name);
    sn_get_stats(c0, &st);
    T_CHECK(st.saturations == 0 && D(st.disp_max) < 4.0, "%s: %u saturations, largest displacement %.3g cells", name, st.saturations,
            D(st.disp_max));
    /* 4. the validator on CELLX / CELLXK (BLOB.md "Validation" 12c), the checksum fixed after each change */
    {
        unsigned char *h = malloc(nc + 8), *cx, *xk;
        const sn_blob *bb;
        uint32_t e, slot = 0, xsz = SN_ELEM_CELLXK(b_flavour(bc), 4);
#define CX_CASE(want, what, change) do { \
            memcpy(h, bc, nc); cx = h + tb_rd32(h + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_CELLX); \
            xk = h + tb_rd32(h + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_CELLXK); (void)xk; \
            change; tb_fix_crc(h); \
            T_CHECK(sn_blob_validate(h, nc, &bb) == (want), "%s: %s: got %s, want %s", name, what, \
                    sn_status_str(sn_blob_validate(h, nc, &bb)), sn_status_str(want)); } while (0)
        for (e = 0; e < ic.cells; e++) if (bc[tb_rd32(bc + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_CELLX) + e * SN_ELEM_CELLX + 38]) break;
        {   /* the first set entry of cell e */
            const unsigned char *r = bc + tb_rd32(bc + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_CELLX) + e * SN_ELEM_CELLX;
            while (slot < SN_CUT_MAXX && (r[2 * slot] | r[2 * slot + 1] << 8) == SN_CUT_NONE) slot++;
        }
        T_CHECK(e < ic.cells && slot < SN_CUT_MAXX, "%s: a cell with an extra", name);
        CX_CASE(SN_OK, "unchanged", (void)0);
        CX_CASE(SN_ERR_INDEX, "an extra below nF (a free vertex)", tb_u16(cx + e * SN_ELEM_CELLX + 2 * slot, ic.free_vertices - 1));
        CX_CASE(SN_ERR_INDEX, "an extra at nV", tb_u16(cx + e * SN_ELEM_CELLX + 2 * slot, ic.vertices));
        CX_CASE(SN_ERR_VALUE, "nx one short", cx[e * SN_ELEM_CELLX + 38]--);
        CX_CASE(SN_ERR_VALUE, "pad byte", cx[e * SN_ELEM_CELLX + 39] = 1);
        CX_CASE(SN_ERR_INDEX, "first off the running sum", cx[(ic.cells - 1) * SN_ELEM_CELLX + 40]++);
        CX_CASE(SN_ERR_INDEX, "an entry dropped (the later cells' first off the sum)", (tb_u16(cx + e * SN_ELEM_CELLX + 2 * slot, SN_CUT_NONE),
                                                                             cx[e * SN_ELEM_CELLX + 38]--));
#if defined(SN_FLOAT)
        CX_CASE(SN_ERR_VALUE, "a block entry 2^28", tb_u32(xk, 0x4D800000u));
#else
        CX_CASE(SN_ERR_VALUE, "a block exponent 13", xk[18] = 13);
        CX_CASE(SN_ERR_VALUE, "a mantissa -2^15", tb_u16(xk, 0x8000u));
        CX_CASE(SN_ERR_VALUE, "a block pad byte", xk[19] = 1);
#endif
        CX_CASE(SN_ERR_SECTION, "CELLX count 1", tb_u32(h + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_CELLX + 8, 1));
        (void)xsz;
#undef CX_CASE
        free(h);
    }
    free(m[0]); free(m[1]); free(m[2]); free(xf); free(sc); free(s0); free(s1); free(bc); free(bl);
    return T_END();
}
