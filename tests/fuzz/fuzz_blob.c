/* fuzz_blob.c -- hostile blobs: every single-bit flip and every truncation
 * of a real blob must be handled without an out-of-bounds access or
 * undefined behaviour (built with -fsanitize=address,undefined
 * -fno-sanitize-recover=all, so any finding aborts the run).
 *
 * For each mutated blob: validate; if accepted, initialise an instance (init
 * may refuse only with SN_ERR_INDEX, as sinew.h documents: a vertex in more
 * mass rows or cells than a hex lattice has), pose it (sn_pose_from_local +
 * sn_set_pose), step twice with 2 CG iterations (teleporting back to the rest
 * pose for the second), and read everything back (lattice, surface, normals,
 * hash, accessors, stats). Every section of format 3.0 (CFRAMES, CELLK, LIMIT
 * and the rig sections included) gets its bits flipped and its boundaries cut; crafted cases push
 * CELLK and every other matrix to the validator's bounds (see crafted_all).
 * The extreme-valid matrix (matrix_all, issue 16 item 1) sets every header
 * field, scalar and bounded section value to its minimum and its maximum
 * (and the combinations the arithmetic makes), requires the validator to
 * accept it, and steps it with violent poses in a child; the sweeps
 * (sweep_all) step every value of the integer header fields and check that
 * one past either end is refused. Prints the matrix (fields x {min, max}).
 *
 * Two builds of the same file (tests/fuzz/fuzz.mk... see runtime/runtime.mk):
 *   test_runtime_fuzz     -DSN_VALIDATE_NO_CHECKSUM: the checksum is skipped so
 *                         mutations reach every later rule and the stepper;
 *                         -DSN_FUZZ_RANDOM_ONLY: without arguments (make
 *                         test) only the cow's random flips (everything else
 *                         runs in test_runtime_fuzz_range, the same objects
 *                         plus the range checks); --full, --all or a blob
 *                         named: every case below;
 *   test_runtime_fuzz_ck  normal validator: every flip must be rejected
 *                         (CRC-32 detects every single-bit error; bytes 0..15,
 *                         outside the CRC, are magic/version/endian/CRC); by
 *                         default not the crafted cases and matrix (valid CRC:
 *                         the same objects and inputs as test_runtime_fuzz).
 *
 * Usage: test_runtime_fuzz [blob] [--all] [--full] [--per-section N] [--edge E] [--seed S] [--crafted | --matrix]
 *   blob       default $BUILD/examples/cow.blob (fixed) or cow_float.blob
 *              (float); if missing, the hand-built test blob (sn_tblob.h)
 *   --all      every bit of the blob (slow for a 200 KB blob: ~1.5 M cases)
 *   --crafted  only the crafted cases; --matrix only the extreme-valid matrix and sweeps
 *   env SN_FUZZ_TRACE=1: name each case on stderr before it runs (finds the case behind a sanitizer abort)
 *   default    every bit of the header and section table, every bit of the
 *              first and last E bytes of each section (SN_FUZZ_EDGE: 4;
 *              `make fuzz-blobs` 16), plus N (default
 *              SN_FUZZ_PER_SECTION: 100; the range-checking build 40;
 *              `make fuzz-blobs` runs 2000)
 *              random bits inside each section; truncations: every size
 *              (size only), and total_size patched to the cut for every size
 *              up to 4 KB, every section boundary +-16, and 2000 random sizes.
 *              (The truncations cost ~0: each is refused by an O(1) check,
 *              total_size > size or a section table entry past total_size,
 *              before any contents are read: 173,080 cuts of the cow < 0.1 s.)
 */
#define _POSIX_C_SOURCE 200112L /* fork, waitpid: crafted cases run in a child */
#include <stdint.h>
#include <stdio.h>
#include <sys/wait.h>
#include <unistd.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sinew.h"
#include "sn_format.h"
#include "sn_tblob.h"
#include "sn_thostile.h"
#include "sn_instance.h" /* sn_view_init: the details' kernels (stage 2, not yet in the step) read the view */
#include "sn_detail.h"

#if defined(__has_include)
#if __has_include(<sanitizer/common_interface_defs.h>)
#include <sanitizer/common_interface_defs.h>
#define HAVE_SAN_CB 1
#endif
#endif

#if defined(SN_FLOAT)
#define FLAV "float"
#define DEFAULT_BLOB "examples/cow_float.blob"
#define REAL(f, i) (f)
#else
#define FLAV "fixed"
#define DEFAULT_BLOB "examples/cow.blob"
#define REAL(f, i) (i)
#endif

#if defined(SN_VALIDATE_NO_CHECKSUM)
#define MODE "no-checksum"
#else
#define MODE "checksum"
#endif

static unsigned char *g_orig, *g_work;
static size_t g_size, g_last_end; /* end of the last non-empty section */
static void *g_mem;
static size_t g_mem_size;
static void *g_smem, *g_ws;       /* a shared instance's state and its workspace (exercise_shared) */
static size_t g_smem_size, g_ws_size;
static char g_case[128];
static uint64_t g_rng;
static int g_pose; /* 0: 25 degrees about one axis; 1: (1,1,1) onto -x, root far away;
                    * 2: 180 degrees about (1,1,0) (w = 0), root at (-30000, 30000, -30000) */
static int g_ctl_baked; /* 1: leave the controls at their baked values (default: the type's extremes) */
static int g_steps = 2, g_iters = 2; /* crafted cases: more steps, every CG iteration */
#ifndef SN_FUZZ_SHARED_EVERY
#define SN_FUZZ_SHARED_EVERY 16
#endif
static unsigned g_shared_every = 4; /* every n-th stepped case also as a shared instance (fuzz_one: SN_FUZZ_SHARED_EVERY) */
static sn_stats g_last_stats;       /* stats of the last exercise() */
static int g_finite;                /* its lattice was finite (always, in fixed) */

static struct {
    unsigned long flips, flips_ok, stepped, trunc, trunc_ok, trunc_total, trunc_total_ok, huge, init_index;
    unsigned long by_status[SN_STATUS_COUNT];
} g;

static uint64_t rnd64(void) {
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return g_rng;
}

#ifdef HAVE_SAN_CB
static void on_death(void) { fprintf(stderr, "fuzz: sanitizer finding while running case: %s\n", g_case); }
#endif

static uint32_t rd32(const unsigned char *p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static void *grow(void *p, size_t *have, size_t need) {
    if (need <= *have) return p;
    free(p);
    p = malloc(need);
    *have = need;
    if (!p) { fprintf(stderr, "out of memory\n"); exit(2); }
    return p;
}

/* Details on the cut level (stage 2, sn_detail_step.c): every detail up to
 * A_max active, so the steps on level 0 run the details' rows; stage 3's
 * adaptation on. */
static void set_details(sn_instance *inst, const sn_blob *blob) {
    static uint16_t ids[65536];
    sn_view v;
    uint32_t a, i;
    sn_view_init(&v, blob);
    if (sn_level_sec_count(&v, SN_SEC_DETAILS) == 0) return;
    a = sn_rd_u16(sn_sec(&v, SN_SEC_DETAILS)); /* <= nD (validated) */
    for (i = 0; i < a; i++) ids[i] = (uint16_t)i;
    if (sn_details_set(inst, ids, a) != SN_OK) { printf("FAIL: sn_details_set refused A_max details (%s)\n", g_case); exit(1); }
    /* stage 3 (sn_detail_adapt.c): after each step on the cut level the runtime re-chooses the set (the estimate over
     * every detail, the selection, sn_details_apply); the first step still runs every seat filled */
    if (sn_set_detail_adapt(inst, 1) != SN_OK) { printf("FAIL: sn_set_detail_adapt refused on a details blob (%s)\n", g_case); exit(1); }
}

/* The blob as an sn_instance_init_shared instance, stepped with a workspace
 * (sn_step_with) in the warped and blended modes: the sizes derive from the
 * same validated counts as sn_instance_size. Every g_shared_every-th stepped
 * case (cost): flips every 16th (gcov: the same runtime lines and branches as
 * every 4th, ~5% less time), the crafted cases every 4th. */
static void exercise_shared(const sn_blob *blob, const sn_blob_info *info, const sn_xform *xf) {
    sn_instance *si;
    sn_status st;
    size_t sb = sn_instance_state_size(blob), wb = sn_workspace_size(blob, SN_MODE_BLENDED);
    if (sb == 0 || wb == 0 || sb + wb > (32u << 20)) return;
    g_smem = grow(g_smem, &g_smem_size, sb);
    g_ws = grow(g_ws, &g_ws_size, wb);
    st = sn_instance_init_shared(g_smem, sb, blob, &si);
    if (st != SN_OK) { printf("FAIL: init_shared refused a blob init accepted (%s): %s\n", g_case, sn_status_str(st)); exit(1); }
    (void)sn_set_pose(si, xf, info->joints);
    th_hostile_contacts(si, info->surface_vertices);
    (void)sn_set_iterations(si, info->cg_iters_max < (uint32_t)g_iters ? info->cg_iters_max : (uint32_t)g_iters);
    set_details(si, blob);
    memset(g_ws, 0xA5, wb);
    if (sn_step_with(si, g_ws, wb) != SN_OK) { printf("FAIL: sn_step_with refused (%s)\n", g_case); exit(1); }
    if (sn_set_mode(si, SN_MODE_BLENDED) != SN_OK || sn_step_with(si, g_ws, wb) != SN_OK) {
        printf("FAIL: blended sn_step_with refused with sn_workspace_size bytes (%s)\n", g_case);
        exit(1);
    }
    (void)sn_state_hash(si);
}

/* The details' kernels (sn_detail.c; the step calls them with the active set:
 * set_details) on an accepted blob with details: every cell, every detail active,
 * operands all +SN_LIM, then all -SN_LIM (the state's bound), and the
 * surface term at the cell's corners, centre and child boundaries: the
 * bounds they document must hold for anything the validator accepts. */
static void exercise_details(const sn_blob *blob) {
    sn_view v;
    uint32_t e, j, k, sat = 0, nd;
    static uint16_t seat[SN_CUT_MAXX * 65536u / 16u];
    static sn_q coef[3 * (SN_CUT_MAXX * 65536u / 16u)];
    sn_q yc[24], yx[SN_CUT_MAXX][3], yd[SN_CUT_MAXX][3];
    sn_acc lc[24], ld[3 * SN_CUT_MAXX], mc[24], md[3 * SN_CUT_MAXX], acc[3];
    static const uint32_t ts[4] = {0, 16383, 16384, 32767};
    sn_view_init(&v, blob);
    if (sn_level_sec_count(&v, SN_SEC_DETAILS) == 0) return;
    nd = sn_level_sec_count(&v, SN_SEC_DETAIL);
    if (nd > sizeof seat / sizeof seat[0]) nd = sizeof seat / sizeof seat[0]; /* the validator's 19 nC <= 19 * 65535 */
    for (j = 0; j < nd; j++) {
        seat[j] = (uint16_t)j;
        for (k = 0; k < 3; k++) coef[3 * j + k] = (j + k) & 1u ? (sn_q)SN_LIM : (sn_q)-SN_LIM;
    }
    for (e = 0; e < v.nC; e++) {
        int sg;
        for (sg = 0; sg < 2; sg++) {
            for (k = 0; k < 24; k++) { yc[k] = sg ? (sn_q)-SN_LIM : (sn_q)SN_LIM; lc[k] = mc[k] = 0; } /* one sign: no cancellation */
            for (j = 0; j < SN_CUT_MAXX; j++)
                for (k = 0; k < 3; k++) yx[j][k] = yd[j][k] = sg ? (sn_q)-SN_LIM : (sn_q)SN_LIM;
            sn_detail_cell_mul(&v, e, 0x7FFFFu, yc, (const sn_q(*)[3])yx, (const sn_q(*)[3])yd, lc, ld, &sat);
            sn_detail_cell_mul(&v, e, 0x7FFFFu, yc, NULL, (const sn_q(*)[3])yd, lc, ld, &sat);
            sn_detail_cell_mass(&v, e, 0x7FFFFu, yc, (const sn_q(*)[3])yx, (const sn_q(*)[3])yd, mc, md);
        }
        if (nd == sn_level_sec_count(&v, SN_SEC_DETAIL))
            for (k = 0; k < 64; k++) {
                uint32_t t[3] = {ts[k & 3u], ts[k >> 2 & 3u], ts[k >> 4 & 3u]};
                acc[0] = acc[1] = acc[2] = 0;
                sn_detail_interp(&v, e, t, seat, coef, acc);
            }
    }
}

/* Use an accepted blob the way a game would. */
static void exercise(const sn_blob *blob) {
    sn_blob_info info;
    sn_instance *inst;
    size_t need = sn_instance_size_mode(blob, SN_MODE_BLENDED); /* the blended mode's memory too: stepped below */
    uint32_t j, idx[3];
    sn_quat *local;
    sn_xform *xf;
    sn_vec3 *surf, *nrm, *lat, root, r;
    sn_status ist;
    int s;

    sn_blob_get_info(blob, &info);
    exercise_details(blob);
    for (j = 0; j < info.joints; j++) {
        const char *n = sn_joint_name(blob, j);
        (void)sn_joint_parent(blob, j);
        (void)sn_joint_rest(blob, j, &r);
        if (n) (void)sn_find_joint(blob, n);
    }
    (void)sn_find_joint(blob, "no such joint");
    for (j = 0; j < info.controls; j++) {
        const char *n = sn_control_name(blob, j);
        (void)sn_control_kind_of(blob, j);
        if (n) (void)sn_find_control(blob, n);
    }
    for (j = 0; j < info.triangles && j < 8; j++) (void)sn_get_triangle(blob, j, idx);
    if (need > (16u << 20)) { /* a flipped high bit of instance_bytes: valid, but too big to bother */
        g.huge++;
        return;
    }
    if (need > g_mem_size) {
        free(g_mem);
        g_mem = malloc(need);
        g_mem_size = need;
        if (!g_mem) { fprintf(stderr, "out of memory\n"); exit(2); }
    }
    ist = sn_instance_init(g_mem, need, blob, &inst);
    if (ist == SN_OK && !g_ctl_baked) /* abstract controls at the extremes of their type (tau clamps) */
        for (j = 0; j < info.controls; j++) {
            sn_real cv;
            (void)sn_set_control(inst, j, (j & 1) ? REAL(-3.0e38f, -INT32_MAX) : REAL(3.0e38f, INT32_MAX));
            (void)sn_get_control(inst, j, &cv);
        }
    if (ist == SN_ERR_INDEX) { /* documented (sinew.h): a vertex in more mass rows / cells than a hex lattice allows */
        g.init_index++;
        return;
    }
    if (ist != SN_OK) {
        printf("FAIL: init refused an accepted blob (%s): %s\n", g_case, sn_status_str(ist));
        exit(1);
    }
    local = (sn_quat *)malloc(sizeof *local * info.joints);
    xf = (sn_xform *)malloc(sizeof *xf * info.joints);
    surf = (sn_vec3 *)malloc(sizeof *surf * (info.surface_vertices + 1));
    nrm = (sn_vec3 *)malloc(sizeof *nrm * (info.surface_vertices + 1));
    lat = (sn_vec3 *)malloc(sizeof *lat * info.vertices);
    if (!local || !xf || !surf || !nrm || !lat) { fprintf(stderr, "out of memory\n"); exit(2); }
    for (j = 0; j < info.joints; j++) {
        sn_vec3 ax;
        if (g_pose == 2) { /* a half turn: w = 0, the extreme quaternion */
            ax.x = ax.y = REAL(1.0f, 65536);
            ax.z = 0;
            local[j] = sn_quat_axis_angle(ax, REAL(180.0f, 180 << 16));
            continue;
        }
        ax.x = g_pose ? 0 : REAL(0.3f, 19661);
        ax.y = g_pose ? REAL(-1.0f, -65536) : REAL(1.0f, 65536);
        ax.z = g_pose ? REAL(1.0f, 65536) : REAL(-0.2f, -13107);
        /* 125.26 degrees about (0,-1,1) takes (1,1,1) to -sqrt(3) x */
        local[j] = sn_quat_axis_angle(ax, g_pose ? REAL(125.26439f, 8209327) : REAL(25.0f, 25 << 16));
    }
    root.x = g_pose == 2 ? REAL(-30000.0f, -30000 * 65536) : g_pose ? REAL(30000.0f, 30000 << 16) : REAL(0.5f, 32768);
    root.y = g_pose == 2 ? REAL(30000.0f, 30000 << 16) : REAL(-0.25f, -16384);
    root.z = g_pose == 2 ? REAL(-30000.0f, -30000 * 65536) : 0;
    sn_pose_from_local(blob, local, &root, xf);
    (void)sn_set_pose(inst, xf, info.joints);
    th_hostile_contacts(inst, info.surface_vertices); /* constraints and colliders (format 5.0) */
    (void)sn_set_iterations(inst, info.cg_iters_max < (uint32_t)g_iters ? info.cg_iters_max : (uint32_t)g_iters);
    (void)sn_set_mode(inst, SN_MODE_WARPED);
    set_details(inst, blob);
    for (s = 0; s < g_steps; s++) {
        if (s == g_steps / 2) { /* teleport back to the rest pose halfway: a second violent jump */
            for (j = 0; j < info.joints; j++) { local[j].x = local[j].y = local[j].z = 0; local[j].w = REAL(1.0f, 1 << 30); }
            sn_pose_from_local(blob, local, NULL, xf);
            (void)sn_set_pose(inst, xf, info.joints);
        }
        sn_step(inst);
        if (s == 0) { /* level of detail (format 6.0): the finer level from the second step on, if the blob has one */
            if (sn_set_lod(inst, 7) != SN_ERR_ARG) { printf("FAIL: sn_set_lod accepted level 7 (%s)\n", g_case); exit(1); }
            (void)sn_set_lod(inst, sn_lod_levels(blob) > 1 ? 1u : 0u);
        }
    }
    if (sn_lod_levels(blob) > 1) { /* and back, one more step on level 0 */
        (void)sn_set_lod(inst, 0);
        sn_step(inst);
    }
    /* SN_MODE_BLENDED (sn_blended.c) from that state: a region per joint, the same hostile matrices */
    if (sn_set_mode(inst, SN_MODE_BLENDED) != SN_OK) { printf("FAIL: blended mode refused with its memory (%s)\n", g_case); exit(1); }
    sn_step(inst);
    sn_step(inst);
    (void)sn_get_lattice(inst, lat, 0, info.vertices);
    sn_get_stats(inst, &g_last_stats);
    g_finite = 1;
    for (j = 0; j < info.vertices; j++)
        if (!(lat[j].x == lat[j].x && lat[j].y == lat[j].y && lat[j].z == lat[j].z)) g_finite = 0;
    (void)sn_get_surface(inst, surf, 0, info.surface_vertices);
    if (info.triangles) (void)sn_get_normals(inst, surf, nrm);
    (void)sn_state_hash(inst);
    if (g.stepped % g_shared_every == 0) exercise_shared(blob, &info, xf);
    g.stepped++;
    free(local); free(xf); free(surf); free(nrm); free(lat);
}

static int g_trace; /* env SN_FUZZ_TRACE: name every case on stderr before it runs (to find a sanitizer abort's case) */
static sn_status run_case(size_t size) {
    const sn_blob *blob;
    sn_status st;
    if (g_trace) fprintf(stderr, "case: %s\n", g_case);
    st = sn_blob_validate(g_work, size, &blob);
    if ((int)st >= 0 && st < SN_STATUS_COUNT) g.by_status[st]++;
    if (st == SN_OK) exercise(blob);
    return st;
}

static void flip(size_t byte, int bit) {
    sn_status st;
    sprintf(g_case, "flip byte %lu bit %d", (unsigned long)byte, bit);
    g_work[byte] ^= (unsigned char)(1u << bit);
    st = run_case(g_size);
    g_work[byte] ^= (unsigned char)(1u << bit);
    g.flips++;
    if (st == SN_OK) g.flips_ok++;
}

static void flip_byte(size_t byte) {
    int bit;
    for (bit = 0; bit < 8; bit++) flip(byte, bit);
}

/* Cut to n bytes; with_total also writes n into total_size (a consistent
 * but short blob: then the section table must catch it). */
static void truncate_to(size_t n, int with_total) {
    sn_status st;
    unsigned char save[4];
    sprintf(g_case, "truncate to %lu%s", (unsigned long)n, with_total ? " (total_size patched)" : "");
    if (with_total) {
        if (n < SN_H_TOTAL_SIZE + 4) return;
        memcpy(save, g_work + SN_H_TOTAL_SIZE, 4);
        tb_u32(g_work + SN_H_TOTAL_SIZE, (uint32_t)n);
    }
    st = run_case(n);
    if (with_total) {
        memcpy(g_work + SN_H_TOTAL_SIZE, save, 4);
        g.trunc_total++;
        /* cutting only trailing padding after the last section is legitimate */
        if (st == SN_OK && n < g_last_end) g.trunc_total_ok++;
    } else {
        g.trunc++;
        if (st == SN_OK) g.trunc_ok++;
    }
}


/* ---- crafted hostile blobs: valid by every rule, extreme on purpose ----
 * Each runs in a child process, so a sanitizer finding is reported as a
 * failure of that case and the remaining cases still run. */
/* 32 KiB: the valence case's 2,000 triangles (12,000 B) follow the hand-built
 * blob's other sections (over 4 KB in the float flavour since format 6.5) */
static union { uint64_t a; unsigned char b[32768]; } g_craft;

/* Many triangles on one vertex: vertex normals sum every face (valence 2000). */
static size_t craft_valence(void) {
    unsigned char *b = g_craft.b;
    uint32_t total = tb_build(b, sizeof g_craft.b, 0), off = tb_sec(b, SN_SEC_TRIS), t, nT = 2000;
    for (t = 0; t < nT; t++) {
        tb_u16(b + off + 6 * t, 0);
        tb_u16(b + off + 6 * t + 2, 1 + (t & 1));
        tb_u16(b + off + 6 * t + 4, 2 + (t & 1));
    }
    total = off + 6 * nT;
    tb_drop_after_tris(b, total);
    tb_u32(b + SN_H_N_TRIANGLES, nT);
    tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_TRIS + 4, 6 * nT);
    tb_u32(b + SN_H_SECTIONS + 16 * SN_SEC_TRIS + 8, nT);
    tb_u32(b + SN_H_TOTAL_SIZE, total);
    tb_fix_crc(b);
    return total;
}

/* Largest rest coordinates the validator allows (16384 mesh units per axis,
 * len_shift 24); exercise() then rotates (1,1,1) onto an axis. */
static size_t craft_far_joint(void) {
    unsigned char *b = g_craft.b;
    uint32_t total = tb_build(b, sizeof g_craft.b, 24), j1 = tb_sec(b, SN_SEC_JOINTS) + SN_ELEM_JOINTS(4) + 8;
    uint32_t rest = tb_sec(b, SN_SEC_REST), i;
    int k;
    for (k = 0; k < 3; k++) tb_real(b + j1 + 4 * k, 4096.0 / 4194304.0, SN_Q_LEN);
    for (i = 0; i < 3 * TB_NV; i++) { /* shrink the lattice into the 16384-unit box */
        unsigned char *p = b + rest + 4 * i;
#if defined(SN_FLOAT)
        float v;
        uint32_t u = rd32(p);
        memcpy(&v, &u, 4);
        tb_real(p, v / 1024.0, 0);
#else
        tb_u32(p, (uint32_t)((int32_t)rd32(p) / 1024));
#endif
    }
    tb_fix_crc(b);
    return total;
}

/* ---- extreme matrices: every entry the validator lets through at its bound ----
 * A stored matrix entry is at most 2^27 in magnitude (fixed: the integer;
 * float: the value) and the state is clamped to 2^28 (NUMERICS.md "Fixed
 * point"), so a cell row product of 24 terms is < 2^60.6 and a vertex in 8
 * cells sums < 2^63.6 unless the runtime scales: these blobs drive every
 * accumulator there under UBSan (signed overflow aborts the run). */

/* Set the n reals at p to +-2^27 by a sign pattern: 0 all +, 1 alternating, 2 pseudo-random. */
static void set_max(unsigned char *p, uint32_t n, int pattern) {
    uint32_t i, x = 12345u;
    for (i = 0; i < n; i++) {
        int neg = pattern == 1 ? (int)(i & 1u) : pattern == 2 ? (int)((x = x * 1103515245u + 12345u) >> 31) : 0;
#if defined(SN_FLOAT)
        tb_real(p + 4 * (size_t)i, neg ? -134217728.0 : 134217728.0, 0);
#else
        tb_u32(p + 4 * (size_t)i, neg ? (uint32_t)0xF8000000u : (uint32_t)0x08000000u);
#endif
    }
}
static uint32_t sec_n(const unsigned char *b, int k) { return rd32(b + SN_H_SECTIONS + 16 * k + 4) / 4; }
/* CELLK at the validator's bounds: float, every real +-2^27 as set_max;
 * fixed (format 6.0), the diagonal int32 at +-2^27 and every off-diagonal
 * entry at +-(2^15 - 1) 2^12 (the largest mantissa, the largest exponent);
 * pattern 3: every entry negative */
static void cellk_max(unsigned char *b, int pattern) {
    unsigned char *p = b + tb_sec(b, SN_SEC_CELLK);
#if defined(SN_FLOAT)
    uint32_t i, n = sec_n(b, SN_SEC_CELLK);
    if (pattern < 3) set_max(p, n, pattern);
    else for (i = 0; i < n; i++) tb_real(p + 4 * (size_t)i, -134217728.0, 0);
#else
    uint32_t c, i, x = 54321u, nC = rd32(b + SN_H_SECTIONS + 16 * SN_SEC_CELLK + 8);
    for (c = 0; c < nC; c++) {
        unsigned char *ck = p + (size_t)c * SN_CELLK_FIXED_BYTES;
        if (pattern < 3) set_max(ck + SN_CELLK_DIAG, 48, pattern);
        else for (i = 0; i < 48; i++) tb_u32(ck + SN_CELLK_DIAG + 4 * i, 0xF8000000u);
        for (i = 0; i < 28 * 9; i++) {
            int neg = pattern == 3 ? 1 : pattern == 1 ? (int)(i & 1u) : pattern == 2 ? (int)((x = x * 1103515245u + 12345u) >> 31) : 0;
            tb_u16(ck + SN_CELLK_OFF + 2 * i, neg ? 0x8001u : 0x7FFFu);
        }
        for (i = 0; i < 28; i++) ck[SN_CELLK_EXP + i] = SN_CELLK_EXP_MAX;
    }
#endif
}

static size_t craft_cellk(int pattern, int frac) {
    unsigned char *b = g_craft.b;
    uint32_t total = tb_build(b, sizeof g_craft.b, 0);
    cellk_max(b, pattern);
    b[SN_H_FRAC_S] = (unsigned char)frac;
    tb_u16(b + SN_H_CG_DEFAULT, 256);
    tb_u16(b + SN_H_CG_MAX, 256);
    tb_fix_crc(b);
    return total;
}
static size_t craft_cellk_plus(void) { return craft_cellk(0, TB_FRAC); }
static size_t craft_cellk_alt_q0(void) { return craft_cellk(1, 0); }
static size_t craft_cellk_rand_q59(void) { return craft_cellk(2, 59); }

/* Every matrix at the bound, damping and gravity at theirs, fractions 0,
 * limits at 2^28, ENERGY as large as Q(-40) allows, DISP_BOUND 1 LSB. */
static size_t craft_all_max(void) {
    unsigned char *b = g_craft.b;
    uint32_t total = tb_build(b, sizeof g_craft.b, 0);
    static const int secs[5] = {SN_SEC_MDIAG, SN_SEC_PRECOND, SN_SEC_MLUMP, SN_SEC_MOFF, SN_SEC_CELLK};
    int k;
    for (k = 0; k < 5; k++)
        if (secs[k] == SN_SEC_CELLK) cellk_max(b, 1);
        else set_max(b + tb_sec(b, secs[k]), sec_n(b, secs[k]), k & 1 ? 2 : 1);
    b[SN_H_FRAC_S] = b[SN_H_FRAC_M] = b[SN_H_FRAC_P] = 0;
    tb_real(b + SN_H_REALS + 4 * SN_R_A1, 16.0, SN_Q_COEF);
    tb_real(b + SN_H_REALS + 4 * SN_R_B1, 16.0, SN_Q_COEF);
    for (k = 0; k < 3; k++) tb_real(b + SN_H_REALS + 4 * (SN_R_GRAV_X + k), k == 1 ? -32.0 : 32.0, SN_Q_LEN);
    for (k = 0; k < TB_NF; k++) tb_real(b + tb_sec(b, SN_SEC_LIMIT) + 4 * k, 64.0, SN_Q_LEN);
#if defined(SN_FLOAT)
    tb_real(b + SN_H_REALS + 4 * SN_R_ENERGY, 2.0e9, 0); /* float: the validator's cap 2^31 */
    tb_real(b + SN_H_REALS + 4 * SN_R_DISP_BOUND, ldexp(1.0, -16), 0);
#else
    b[SN_H_FRAC_E] = (unsigned char)(256 - 40);
    tb_u32(b + SN_H_REALS + 4 * SN_R_ENERGY, 0x7FFFFFFFu);
    tb_u32(b + SN_H_REALS + 4 * SN_R_DISP_BOUND, 1);
#endif
    tb_u16(b + SN_H_CG_DEFAULT, 256);
    tb_u16(b + SN_H_CG_MAX, 256);
    tb_fix_crc(b);
    return total;
}

/* Rig values at the validator's bounds: every force at the type's extreme
 * with the smallest frac (fixed: INT32_MIN at Q5, the largest product and
 * the smallest shift), etas at +-1, gammas 1 LSB apart at +-2^30, the angle
 * axis at the 2^-8 norm tolerance; controls are then set to both extremes
 * of their type by exercise(). The step must saturate, never overflow. */
static size_t craft_rig_max(void) {
    unsigned char *b = g_craft.b;
    uint32_t total = tb_build(b, sizeof g_craft.b, 0), k;
    uint32_t smp = tb_sec(b, SN_SEC_RIG_SAMPLES), f = tb_sec(b, SN_SEC_RIG_FORCES), rg = tb_sec(b, SN_SEC_RIGS);
    uint32_t ctl = tb_sec(b, SN_SEC_CONTROLS) + SN_ELEM_CONTROLS(4);
    for (k = 0; k < 3 * TB_NRE; k++) tb_u32(b + f + 4 * k, REAL(0x49800000u /* 2^20 */, (k & 1) ? 0x80000000u : 0x7FFFFFFFu));
    for (k = 0; k < TB_NR; k++) b[rg + SN_ELEM_RIGS * k + 3] = (unsigned char)REAL(0, SN_RIG_FRAC_MIN);
    /* rig 0: gammas -2^30, -2^30 + 1 LSB, 2^30; etas -1, 1, -1 */
    tb_u32(b + smp, REAL(0xC6800000u /* -16384 */, 0xC0000000u));
    tb_u32(b + smp + 8, REAL(0xC67FFFFFu, 0xC0000001u));
    tb_u32(b + smp + 16, REAL(0x46800000u, 0x40000000u));
    for (k = 0; k < 3; k++) tb_u32(b + smp + 8 * k + 4, REAL((k & 1) ? 0x3F800000u : 0xBF800000u, (k & 1) ? 0x40000000u : 0xC0000000u));
    tb_real(b + ctl + 40, 0.0625, SN_Q_ROT); /* axis (1/16, 0, 1): |axis|^2 = 1 + 2^-8 */
    tb_fix_crc(b);
    return total;
}

/* Limits of 1 LSB on every free vertex, no REST_MODELLED: the limit stage clamps everything every step. */
static size_t craft_limits_tiny(void) {
    unsigned char *b = g_craft.b;
    uint32_t total = tb_build(b, sizeof g_craft.b, 0), k;
    for (k = 0; k < TB_NF; k++) tb_u32(b + tb_sec(b, SN_SEC_LIMIT) + 4 * k, REAL(0x34000000u /* 1.2e-7f */, 1u));
    b[SN_H_FLAGS] = 0;
    tb_fix_crc(b);
    return total;
}

/* ICHOL (format 6.0) at its bounds: every mantissa +-(2^15 - 1) (alternating
 * or random signs), frac 0 (the largest factor, 32767, and shifts down to
 * -15: products scaled up by 2^15) or 47 (the largest shift, 62 with the
 * k_i spread), odd free vertices' PRECOND at 2^27 (k 15) and even ones at
 * 1 LSB (k 0), 256 CG iterations: the sweeps must saturate, never overflow. */
static size_t craft_ichol(int frac, int pattern) {
    unsigned char *b = g_craft.b;
    uint32_t total, k, n, off, x = 777u;
    tb_build(b, sizeof g_craft.b, 0);
    total = tb_add_ichol(b, sizeof g_craft.b, frac);
    n = rd32(b + SN_H_SECTIONS + 16 * SN_SEC_ICHOL + 8);
    off = tb_sec(b, SN_SEC_ICHOL);
    for (k = 0; k < 9 * n; k++) {
        int neg = pattern ? (int)((x = x * 1103515245u + 12345u) >> 31) : (int)(k & 1u);
        tb_u16(b + off + 20 * (k / 9) + 2 * (k % 9), neg ? 0x8001u : 0x7FFFu);
    }
    for (k = 0; k < TB_NF; k++) {
        uint32_t d;
        for (d = 0; d < 6; d++)
            tb_real(b + tb_sec(b, SN_SEC_PRECOND) + 4 * (6 * k + d), (k & 1) ? 134217728.0 : d < 3 ? 1.0 : 0.0, 0);
    }
    tb_u16(b + SN_H_CG_DEFAULT, 256);
    tb_u16(b + SN_H_CG_MAX, 256);
    tb_fix_crc(b);
    return total;
}
static size_t craft_ichol_q0(void) { return craft_ichol(0, 0); }
static size_t craft_ichol_q47(void) { return craft_ichol(SN_ICHOL_FRAC_MAX, 1); }

/* expect: 0 nothing, 1 the state must reach the clamp (saturations > 0), 2 limits must clamp */
static int run_crafted(const char *name, size_t (*make)(void), int posetype, int steps, int expect) {
    pid_t pid;
    int status = 0;
    fflush(stdout);
    pid = fork();
    if (pid == 0) {
        size_t n = make();
        const sn_blob *blob;
        sn_status st;
        g_work = g_craft.b;
        sprintf(g_case, "crafted: %s", name);
        st = sn_blob_validate(g_craft.b, n, &blob);
        if (st != SN_OK) { printf("  crafted %s: rejected (%s)\n", name, sn_status_str(st)); fflush(stdout); _exit(3); }
        g_pose = posetype;
        g_steps = steps;
        g_iters = 256;
        exercise(blob);
        printf("  crafted %s: %d steps: saturations %u, bound steps %u, limit clamps %u (steps %u), disp max %g cells, energy max %g J%s\n", name,
               steps, g_last_stats.saturations, g_last_stats.bound_steps, g_last_stats.limit_clamps, g_last_stats.limit_steps,
               (double)g_last_stats.disp_max / REAL(1.0, 65536.0), (double)g_last_stats.energy_max / REAL(1.0, 65536.0),
               g_finite ? "" : ", NON-FINITE lattice");
        fflush(stdout);
        if (!g_finite) _exit(5);
        if (expect == 1 && g_last_stats.saturations == 0) _exit(4);
        if (expect == 2 && g_last_stats.limit_clamps == 0) _exit(4);
        if (expect == 3 && (g_last_stats.crease_added == 0 || g_last_stats.crease_list > 1)) _exit(4);
        _exit(0);
    }
    if (pid < 0 || waitpid(pid, &status, 0) != pid) { printf("FAIL: crafted %s: fork failed\n", name); return 1; }
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) { printf("  crafted %s: ok\n", name); return 0; }
    printf("FAIL: crafted %s: %s (exit %d, signal %d)\n", name,
           WIFEXITED(status) && WEXITSTATUS(status) == 3 ? "rejected by the validator"
           : WIFEXITED(status) && WEXITSTATUS(status) == 4 ? "did not reach the bound it was built to reach"
           : WIFEXITED(status) && WEXITSTATUS(status) == 5 ? "non-finite lattice"
           : "sanitizer finding -- see the report above",
           WIFEXITED(status) ? WEXITSTATUS(status) : -1, WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    return 1;
}

/* Crease contact (seed 003 §3.4.2): surface vertex 1 moved inside the body
 * at cell 1's (0.1, 0.9, 0.5) = (0.55, 0.2, 0) x 2^ls, 0.25 behind triangle
 * 1 = (0, 2, 3) in the plane z = 0.25 (normal +z) and inside it in the xy
 * projection; the seed (1, 3) makes the runtime test it against triangle 1;
 * neighbourhood rows {s} only (no triangle is excluded but the vertex's own).
 * Record: list, active, depth, push (internal units); instance bytes follow. */
static void crease_set(unsigned char *b, uint32_t list, uint32_t active, double depth, double push) {
    unsigned char *cr = b + tb_sec(b, SN_SEC_CREASE), *vn = b + tb_sec(b, SN_SEC_CREASE_VNBR);
    unsigned char *e1 = b + tb_sec(b, SN_SEC_EMBED) + 8;
    int i;
    tb_u16(e1, 1);
    tb_u16(e1 + 2, 3277); tb_u16(e1 + 4, 29491); tb_u16(e1 + 6, 16384);
    for (i = 0; i < TB_NS; i++) tb_u16(vn + 4 * i + 2, SN_CREASE_NONE);
    tb_u16(b + tb_sec(b, SN_SEC_CREASE_PAIRS), 1);
    tb_u16(b + tb_sec(b, SN_SEC_CREASE_PAIRS) + 2, 3);
    tb_u16(cr, list);
    tb_u16(cr + 2, active);
    tb_real(cr + 12, depth, SN_Q_LEN);
    tb_real(cr + 16, push, SN_Q_LEN);
    tb_u32(b + SN_H_INSTANCE_BYTES,
           SN_INSTANCE_BYTES(TB_NV, TB_NF, TB_NJ, TB_NC, TB_NK, TB_NFRC, TB_SEGB + SN_CREASE_STATE_BYTES(TB_NS, list) + TB_FPB,
                             SN_CONS_BYTES(TB_NCON, TB_NCOL, SN_ROWS_CAP(TB_NCON, TB_NCT, active))));
}
static size_t craft_crease(void) {
    size_t n = tb_build(g_craft.b, sizeof g_craft.b, 0);
    crease_set(g_craft.b, 1, 1, 0.5, 0.05);
    tb_fix_crc(g_craft.b);
    return n;
}

#define N_CRAFTED 9
static int crafted_all(void) {
    int fails = 0;
    fails += run_crafted("2000 triangles on one vertex (normals)", craft_valence, 0, 2, 0);
    fails += run_crafted("joint at (16384,16384,16384) mesh units rotated onto an axis (pose_from_local)",
                         craft_far_joint, 1, 2, 0);
    fails += run_crafted("CELLK all +2^27, frac_S 26, 256 CG iterations, far pose and back", craft_cellk_plus, 1, 40, 1);
    fails += run_crafted("CELLK +-2^27 alternating, frac_S 0", craft_cellk_alt_q0, 1, 40, 1);
    fails += run_crafted("CELLK +-2^27 random signs, frac_S 59", craft_cellk_rand_q59, 1, 40, 0);
    fails += run_crafted("every matrix at +-2^27, fractions 0, a1 = b1 = 16, |g| = 32, LIMIT 2^28, ENERGY max, DISP_BOUND 1 LSB",
                         craft_all_max, 1, 40, 1);
    fails += run_crafted("LIMIT 1 LSB on every free vertex", craft_limits_tiny, 0, 10, 2);
    fails += run_crafted("rig forces, etas, gammas and axes at their bounds, controls at their type's extremes",
                         craft_rig_max, 1, 20, 1);
    fails += run_crafted("crease contact: a vertex 0.25 behind the opposite triangle, list 1, active 1", craft_crease, 0, 10, 3);
    fails += run_crafted("ICHOL mantissas +-(2^15-1) alternating, frac 0, PRECOND k 0/15, 256 CG iterations, far pose", craft_ichol_q0, 1, 40, 1);
    fails += run_crafted("ICHOL mantissas +-(2^15-1) random, frac 47 (shift 62), PRECOND k 0/15", craft_ichol_q47, 1, 40, 0);
    return fails;
}

/* ---- the extreme-valid matrix (issue 16 item 1) ----
 * Every header field and scalar the validator bounds, and the section values
 * it bounds, set to its minimum and to its maximum (one row each), plus rows
 * for the combinations the arithmetic makes (shift = frac -+ k_i ...: the
 * fractions with len_shift, with the k_i spread 0/15 and with every entry of
 * the matrices they scale at +-2^27). Each cell: the hand-built blob edited,
 * CRC fixed, validated (must be accepted: the test's claim is "valid at the
 * bound"), then, in a forked child under ASan+UBSan, exercise()d twice: pose 1
 * ((1,1,1) onto -x, root 30000 mesh units away, teleport back halfway,
 * controls at their type's extremes) and pose 2 (half turns, w = 0, root at
 * (-30000, 30000, -30000), controls left at their baked values), MX_STEPS
 * steps each with every CG iteration the blob allows. Printed: ok with the
 * saturation count (state clamps over both runs), or the failure.
 * Float: the same values as true values (matrices at Q0) where the flavour
 * has them; frac_E and rig frac must be 0 there (those cells say n/a). */
#define MX_STEPS 12
#define E27 134217728.0 /* 2^27 */

/* one real: the stored integer in fixed, the value f in float */
static void put(unsigned char *p, int32_t fixed_raw, double f) {
#if defined(SN_FLOAT)
    (void)fixed_raw;
    tb_real(p, f, 0);
#else
    (void)f;
    tb_u32(p, (uint32_t)fixed_raw);
#endif
}
static unsigned char *hreal(unsigned char *b, int r) { return b + SN_H_REALS + 4 * r; }
static unsigned char *secp(unsigned char *b, int k) { return b + tb_sec(b, k); }
/* every real of section k at +-2^27 by sign pattern (0 all +, 1 alternating, 2 random, 3 all -) */
static void sec_max(unsigned char *b, int k, int pattern) {
    uint32_t i, n = sec_n(b, k);
    if (k == SN_SEC_CELLK) { cellk_max(b, pattern); return; }
    if (pattern < 3) { set_max(secp(b, k), n, pattern); return; }
    for (i = 0; i < n; i++) put(secp(b, k) + 4 * i, -(int32_t)0x08000000, -E27);
}
/* scale the n reals at p by 2^-d (rest coordinates into a smaller box) */
static void scale_down(unsigned char *p, uint32_t n, int d) {
    uint32_t i;
    for (i = 0; i < n; i++) {
#if defined(SN_FLOAT)
        float v;
        uint32_t u = rd32(p + 4 * i);
        memcpy(&v, &u, 4);
        tb_real(p + 4 * i, ldexp(v, -d), 0);
#else
        tb_u32(p + 4 * i, (uint32_t)((int32_t)rd32(p + 4 * i) / ((int32_t)1 << d)));
#endif
    }
}
/* len_shift with the coordinates scaled into the validator's box
 * |x| <= 2^(36 - ls) (Q22) when ls > 9 (the blob's largest is 1.0 = 2^22) */
static void set_ls(unsigned char *b, int ls) {
    b[SN_H_LEN_SHIFT] = (unsigned char)(ls & 0xFF);
    if (ls > 14) {
        scale_down(secp(b, SN_SEC_REST), 3 * TB_NV, ls - 14);
        scale_down(secp(b, SN_SEC_JOINTS) + SN_ELEM_JOINTS(4) + 8, 3, ls - 14);
    }
}
/* the coordinate bound of the validator for len_shift ls (stored integer, Q22; float: value) */
static int32_t xbound(int ls) { return ls > 9 ? (int32_t)1 << (36 - ls) : (int32_t)1 << 27; }
/* k_i spread: odd free vertices' preconditioner at 2^27 (trace 3 * 2^27: k = 15),
 * even ones 1 LSB on the diagonal (the smallest trace, k = 0) */
static void kspread(unsigned char *b) {
    int i, d;
    for (i = 0; i < TB_NF; i++)
        for (d = 0; d < 6; d++)
            put(secp(b, SN_SEC_PRECOND) + 4 * (6 * i + d), (i & 1) ? 0x08000000 : d < 3 ? 1 : 0,
                (i & 1) ? E27 : d < 3 ? ldexp(1.0, -40) : 0.0);
}
static void all_cg(unsigned char *b) {
    tb_u16(b + SN_H_CG_DEFAULT, 256);
    tb_u16(b + SN_H_CG_MAX, 256);
}
static void mass_max(unsigned char *b, int pat) {
    sec_max(b, SN_SEC_MDIAG, pat);
    sec_max(b, SN_SEC_MLUMP, pat);
    sec_max(b, SN_SEC_MOFF, pat == 0 || pat == 3 ? pat : 2);
}

/* ---- the edits: hi = 0 the minimum, 1 the maximum ---- */
static void e_len_shift(unsigned char *b, int hi) { set_ls(b, hi ? 24 : -24); }
static void e_frac_s(unsigned char *b, int hi) {
    b[SN_H_FRAC_S] = (unsigned char)(hi ? 59 : 0);
    sec_max(b, SN_SEC_CELLK, 2);
    kspread(b);
    all_cg(b);
}
static void e_frac_s_ls(unsigned char *b, int hi) { e_frac_s(b, hi); set_ls(b, hi ? 24 : -24); }
static void e_frac_m(unsigned char *b, int hi) {
    b[SN_H_FRAC_M] = (unsigned char)(hi ? 59 : 0);
    mass_max(b, 2);
    kspread(b);
    all_cg(b);
}
static void e_frac_p(unsigned char *b, int hi) {
    b[SN_H_FRAC_P] = (unsigned char)(hi ? 50 : 0);
    sec_max(b, SN_SEC_PRECOND, 2);
    all_cg(b);
}
static void e_frac_p_k(unsigned char *b, int hi) {
    b[SN_H_FRAC_P] = (unsigned char)(hi ? 50 : 0);
    kspread(b);
    all_cg(b);
}
static void e_fracs_all(unsigned char *b, int hi) { /* S, M, P together with every matrix at 2^27 and k 0/15 */
    b[SN_H_FRAC_S] = b[SN_H_FRAC_M] = (unsigned char)(hi ? 59 : 0);
    b[SN_H_FRAC_P] = (unsigned char)(hi ? 50 : 0);
    sec_max(b, SN_SEC_CELLK, 1);
    mass_max(b, 1);
    kspread(b);
    all_cg(b);
}
static void e_frac_e(unsigned char *b, int hi) {
#if !defined(SN_FLOAT)
    b[SN_H_FRAC_E] = (unsigned char)((hi ? 60 : -40) & 0xFF);
    tb_u32(hreal(b, SN_R_ENERGY), 0x7FFFFFFFu);
#else
    (void)b; (void)hi;
#endif
}
static void e_frac_e_1lsb(unsigned char *b, int hi) {
#if !defined(SN_FLOAT)
    b[SN_H_FRAC_E] = (unsigned char)((hi ? 60 : -40) & 0xFF);
    tb_u32(hreal(b, SN_R_ENERGY), 1u);
#else
    (void)b; (void)hi;
#endif
}
static void e_a1(unsigned char *b, int hi) {
    put(hreal(b, SN_R_A1), hi ? 1 << 28 : 0, hi ? 16.0 : 0.0);
    mass_max(b, 2);
    b[SN_H_FRAC_M] = 0;
}
static void e_b1(unsigned char *b, int hi) {
    put(hreal(b, SN_R_B1), hi ? 1 << 28 : 0, hi ? 16.0 : 0.0);
    sec_max(b, SN_SEC_CELLK, 2);
    b[SN_H_FRAC_S] = 0;
}
static void e_a1b1(unsigned char *b, int hi) {
    e_fracs_all(b, 0);
    put(hreal(b, SN_R_A1), hi ? 1 << 28 : 0, hi ? 16.0 : 0.0);
    put(hreal(b, SN_R_B1), hi ? 1 << 28 : 0, hi ? 16.0 : 0.0);
}
static void e_grav(unsigned char *b, int axis, int hi) {
    put(hreal(b, SN_R_GRAV_X + axis), hi ? 0x08000000 : -0x08000000, hi ? 32.0 : -32.0);
}
static void e_gx(unsigned char *b, int hi) { e_grav(b, 0, hi); }
static void e_gy(unsigned char *b, int hi) { e_grav(b, 1, hi); }
static void e_gz(unsigned char *b, int hi) { e_grav(b, 2, hi); }
static void e_g_mass(unsigned char *b, int hi) { /* m^ g^ with the mass at 2^27, frac_M 0, k 0/15, both flags */
    int k;
    for (k = 0; k < 3; k++) e_grav(b, k, hi);
    mass_max(b, hi ? 0 : 3);
    b[SN_H_FRAC_M] = 0;
    kspread(b);
    b[SN_H_FLAGS] = (unsigned char)(hi ? SN_FLAG_REST_MODELLED : 0);
}
static void e_timestep(unsigned char *b, int hi) {
#if defined(SN_FLOAT)
    uint32_t u = hi ? 0x47000000u /* 32768 */ : 1u /* the smallest subnormal, 1.4e-45 */;
    tb_u32(hreal(b, SN_R_TIMESTEP), u);
#else
    tb_u32(hreal(b, SN_R_TIMESTEP), hi ? 0x7FFFFFFFu : 1u);
#endif
}
static void e_mass_scale(unsigned char *b, int hi) {
    put(hreal(b, SN_R_MASS_SCALE), hi ? INT32_MAX : INT32_MIN, hi ? 2147483648.0 : -2147483648.0);
}
static void e_energy(unsigned char *b, int hi) {
#if defined(SN_FLOAT)
    tb_u32(hreal(b, SN_R_ENERGY), hi ? 0x4F000000u /* 2^31 */ : 1u /* 1.4e-45 */);
#else
    tb_u32(hreal(b, SN_R_ENERGY), hi ? 0x7FFFFFFFu : 1u);
#endif
}
static void e_cell(unsigned char *b, int hi) { put(hreal(b, SN_R_CELL), hi ? 0x08000000 : 1, hi ? 32.0 : ldexp(1.0, -22)); }
static void e_disp_bound(unsigned char *b, int hi) {
    put(hreal(b, SN_R_DISP_BOUND), hi ? INT32_MAX : 1, hi ? 32768.0 : ldexp(1.0, -16));
}
static void e_cg_default(unsigned char *b, int hi) {
    tb_u16(b + SN_H_CG_DEFAULT, hi ? 256 : 1);
    tb_u16(b + SN_H_CG_MAX, 256);
}
static void e_cg_max(unsigned char *b, int hi) {
    tb_u16(b + SN_H_CG_DEFAULT, 1);
    tb_u16(b + SN_H_CG_MAX, hi ? 256 : 1);
}
static void e_limit(unsigned char *b, int hi) {
    int i;
    for (i = 0; i < TB_NF; i++) put(secp(b, SN_SEC_LIMIT) + 4 * i, hi ? 1 << 28 : 0, hi ? 64.0 : 0.0);
}
/* rigs: every force at the type's extreme (fixed: +-INT32 alternating, or all
 * one sign; float: +-SN_RIG_FLOAT_MAX), the frac of every rig at the bound,
 * k 0/15 (shift 30 + frac - 19 - k from 1 to 61), etas +-1 */
static void rig_forces(unsigned char *b, int sign) {
    uint32_t k;
    for (k = 0; k < 3 * TB_NRE; k++) {
        int neg = sign ? sign < 0 : (int)(k & 1u);
        put(secp(b, SN_SEC_RIG_FORCES) + 4 * k, neg ? INT32_MIN : INT32_MAX,
            neg ? -(double)SN_RIG_FLOAT_MAX : (double)SN_RIG_FLOAT_MAX);
    }
}
static void rig_frac(unsigned char *b, int frac) {
    int k;
    (void)frac; /* float: the frac byte must be 0 */
    for (k = 0; k < TB_NR; k++) secp(b, SN_SEC_RIGS)[SN_ELEM_RIGS * k + 3] = (unsigned char)REAL(0, frac);
}
static void rig_etas(unsigned char *b, int pattern) { /* 0 all -1, 1 all +1, 2 alternating */
    uint32_t k;
    for (k = 0; k < TB_NRS; k++) {
        int neg = pattern == 2 ? (int)(k & 1u) : !pattern;
        put(secp(b, SN_SEC_RIG_SAMPLES) + 8 * k + 4, neg ? -(1 << 30) : 1 << 30, neg ? -1.0 : 1.0);
    }
}
static void e_rig_frac(unsigned char *b, int hi) {
    rig_frac(b, hi ? SN_RIG_FRAC_MAX : SN_RIG_FRAC_MIN);
    rig_forces(b, 0);
    rig_etas(b, 2);
    kspread(b);
}
static void e_rig_force(unsigned char *b, int hi) {
    rig_frac(b, SN_RIG_FRAC_MIN);
    rig_forces(b, hi ? 1 : -1);
    rig_etas(b, 1);
    kspread(b);
}
static void e_ctl_value(unsigned char *b, int hi) { /* the abstract control's baked value (pose 2 keeps it) */
    put(secp(b, SN_SEC_CONTROLS) + 40 + 12, hi ? 1 << 30 : -(1 << 30), hi ? 16384.0 : -16384.0);
    rig_forces(b, 0);
    rig_frac(b, SN_RIG_FRAC_MIN);
}
/* gammas: min = the first samples of each rig 1 LSB apart at -2^30, max = the
 * last ones 1 LSB apart at +2^30 (rig 1, two samples, spans -2^30..2^30 both times) */
static void e_gamma(unsigned char *b, int hi) {
    static const int ns[TB_NR] = {3, 2, 1};
    int r, j, s = 0;
    for (r = 0; r < TB_NR; r++)
        for (j = 0; j < ns[r]; j++, s++) {
            int32_t g = r == 1 ? (j ? 1 << 30 : -(1 << 30)) : hi ? (1 << 30) - (ns[r] - 1 - j) : -(1 << 30) + j;
            double gf = r == 1 ? (j ? 16384.0 : -16384.0) : hi ? 16384.0 - (ns[r] - 1 - j) / 65536.0 : -16384.0 + j / 65536.0;
#if defined(SN_FLOAT)
            if (r != 1 && ns[r] > 1) gf = hi ? 16384.0 - (ns[r] - 1 - j) / 512.0 : -16384.0 + j / 1024.0; /* float spacing at 2^14 */
#endif
            put(secp(b, SN_SEC_RIG_SAMPLES) + 8 * s, g, gf);
        }
    rig_etas(b, 2);
    rig_forces(b, 0);
    rig_frac(b, SN_RIG_FRAC_MIN);
}
static void e_eta(unsigned char *b, int hi) { rig_etas(b, hi); rig_forces(b, 0); rig_frac(b, SN_RIG_FRAC_MIN); }
/* the angle control's axis at the norm tolerance |a|^2 = 1 -+ 2^-8 (Q30:
 * 2^60 -+ 2^52). diag 0: along z; each component is also bounded by 1 (Q30:
 * 2^30), so the maximum is z = 1 plus the largest x within the tolerance
 * (2^-4); diag 1: (c, c, c) with c the smallest / largest accepted. */
static void axis_at(unsigned char *b, int hi, int diag) {
    unsigned char *ax = secp(b, SN_SEC_CONTROLS) + SN_ELEM_CONTROLS(4) + 40;
    double n2 = hi ? 1.0 + 1.0 / 256 : 1.0 - 1.0 / 256;
    int k, xz = hi && !diag; /* z = 1, solve for x */
#if defined(SN_FLOAT)
    /* float: the validator squares and sums in float; step until accepted */
    float c = xz ? 0.0625f : (float)sqrt(n2 / (diag ? 3.0 : 1.0)), z;
    for (;;) {
        float m2 = diag ? c * c + c * c + c * c : xz ? c * c + 1.0f : c * c;
        if (hi ? m2 <= 1.0f + 1.0f / 256 : m2 >= 1.0f - 1.0f / 256) break;
        c = nextafterf(c, hi ? 0.0f : 2.0f);
    }
    if (hi) { /* then the largest still accepted */
        for (;;) {
            float d = nextafterf(c, 2.0f), m2 = diag ? d * d + d * d + d * d : xz ? d * d + 1.0f : d * d;
            if (m2 > 1.0f + 1.0f / 256 || d > 1.0f) break;
            c = d;
        }
    }
    z = xz ? 1.0f : c;
    tb_real(ax, (diag || xz) ? c : 0.0f, 0);
    tb_real(ax + 4, diag ? c : 0.0f, 0);
    tb_real(ax + 8, z, 0);
    (void)k;
#else
    /* the largest (hi) / smallest (lo) component with the norm within the tolerance */
    int64_t one = (int64_t)1 << 60, tol = (int64_t)1 << 52;
    int64_t base = xz ? one : 0, n = diag ? 3 : 1;
    int64_t c = xz ? ((int64_t)1 << 26) : (int64_t)(sqrt(ldexp(n2, 60) / (double)n));
    while (base + n * c * c > one + tol) c--;
    while (base + n * c * c < one - tol) c++;
    if (hi) while (base + n * (c + 1) * (c + 1) <= one + tol && c + 1 <= ((int64_t)1 << 30)) c++;
    else while (base + n * (c - 1) * (c - 1) >= one - tol) c--;
    for (k = 0; k < 3; k++)
        tb_u32(ax + 4 * k, (uint32_t)(int32_t)(diag ? c : k == 0 ? (xz ? c : 0) : k == 2 ? (xz ? (int64_t)1 << 30 : c) : 0));
#endif
    rig_forces(b, 0);
    rig_frac(b, SN_RIG_FRAC_MIN);
}
static void e_axis_z(unsigned char *b, int hi) { axis_at(b, hi, 0); }
static void e_axis_diag(unsigned char *b, int hi) { axis_at(b, hi, 1); }
/* rest and joint coordinates at the box bound (every coordinate -X / +X, or
 * each vertex's sign kept: the largest lattice the box holds) */
static void coords(unsigned char *b, int ls, int hi, int keep_sign, int joints) {
    int32_t X = xbound(ls);
    double Xf = ldexp((double)X, -22);
    uint32_t i, n = joints ? 3 * TB_NJ : 3 * TB_NV;
    set_ls(b, ls); /* the part not set below must fit the box too */
    for (i = 0; i < n; i++) {
        unsigned char *p = joints ? secp(b, SN_SEC_JOINTS) + SN_ELEM_JOINTS(4) * (i / 3) + 8 + 4 * (i % 3)
                                  : secp(b, SN_SEC_REST) + 4 * i;
        int neg = !hi;
        if (keep_sign) {
#if defined(SN_FLOAT)
            neg = (rd32(p) >> 31) != 0 || (i % 3 == 0 && rd32(p) == 0);
#else
            neg = (int32_t)rd32(p) < 0 || (i % 3 == 0 && rd32(p) == 0);
#endif
            if (hi) neg = !neg;
        }
        put(p, neg ? -X : X, neg ? -Xf : Xf);
    }
}
static void e_rest(unsigned char *b, int hi) { coords(b, 0, hi, 0, 0); }
static void e_rest_box(unsigned char *b, int hi) { coords(b, hi ? 9 : -24, 1, 1, 0); }
static void e_rest_ls24(unsigned char *b, int hi) { coords(b, 24, hi, 1, 0); }
static void e_joint(unsigned char *b, int hi) { coords(b, 0, hi, 0, 1); }
static void e_joint_ls(unsigned char *b, int hi) { coords(b, hi ? 24 : -24, hi, 0, 1); }
/* everything at once */
static void e_crease_depth(unsigned char *b, int hi) {
    crease_set(b, TB_CR_LIST, TB_CR_ACTIVE, hi ? 16.0 : ldexp(1.0, -22), hi ? 16.0 : 0.0);
    tb_real(b + tb_sec(b, SN_SEC_CREASE) + 20, hi ? 64.0 : ldexp(1.0, -22), SN_Q_LEN); /* exclude (format 6.0) */
}
static void e_crease_list(unsigned char *b, int hi) { crease_set(b, hi ? 256 : 1, hi ? 64 : 1, 0.5, 0.05); }
static void e_all(unsigned char *b, int hi) {
    e_fracs_all(b, hi);
    e_frac_e(b, !hi);
    e_a1b1(b, hi);
    b[SN_H_FRAC_S] = b[SN_H_FRAC_M] = (unsigned char)(hi ? 59 : 0);
    b[SN_H_FRAC_P] = (unsigned char)(hi ? 50 : 0);
    e_gx(b, hi); e_gy(b, !hi); e_gz(b, hi);
    e_timestep(b, hi);
    e_cell(b, hi);
    e_disp_bound(b, hi);
    e_limit(b, hi);
    e_rig_frac(b, hi);
    e_axis_diag(b, hi);
    crease_set(b, hi ? 256 : 1, hi ? 64 : 1, hi ? 16.0 : ldexp(1.0, -22), hi ? 16.0 : 0.0);
    coords(b, hi ? 24 : -24, hi, 1, 0);
    coords(b, hi ? 24 : -24, hi, 0, 1);
}

/* ICHOL appended (tb_add_ichol): lo frac 0, hi frac 47, mantissas
 * +-(2^15 - 1) alternating, with the k_i spread; the new total in g_edit_total */
static uint32_t g_edit_total;
static void e_ichol(unsigned char *b, int hi) {
    uint32_t k, n, off;
    kspread(b);
    all_cg(b);
    g_edit_total = tb_add_ichol(b, sizeof g_craft.b, hi ? SN_ICHOL_FRAC_MAX : 0);
    n = rd32(b + SN_H_SECTIONS + 16 * SN_SEC_ICHOL + 8);
    off = tb_sec(b, SN_SEC_ICHOL);
    for (k = 0; k < 9 * n; k++) tb_u16(b + off + 20 * (k / 9) + 2 * (k % 9), (k & 1) ? 0x8001u : 0x7FFFu);
}

/* segment meshes (format 6.2): lo every mesh at relax 32 (omega 1) with gamma
 * 1 LSB and 1 coarse sweep; hi relax 63 (omega 1.97) with gamma at the
 * validator's bound omega (1 - gamma) <= 1 (fixed 2^30 - 2^35/63 rounded up,
 * float 31/63 + 1e-6) and 64 sweeps on every level */
static void e_seg_relax(unsigned char *b, int hi) {
    unsigned char *r = secp(b, SN_SEC_SEGMESH);
    uint32_t m, n = rd32(b + SN_H_SECTIONS + 16 * SN_SEC_SEGMESH + 8), es = (uint32_t)SN_ELEM_SEGMESH(4);
    for (m = 0; m < n; m++, r += es) {
        put(r + 20, hi ? 528349152 : 1, hi ? 31.0 / 63.0 + 1e-6 : ldexp(1.0, -30));
        r[2] = (unsigned char)(hi ? 64 : r[2]);
        r[52] = (unsigned char)(hi ? 64 : (r[1] > 1 ? 1 : r[2])); /* coarse_sweeps: = sweeps at one level */
        r[53] = (unsigned char)(hi ? 63 : 32);
    }
}

typedef struct {
    const char *field, *lo, *hi; /* row label; what min and max mean (fixed / float) */
    void (*edit)(unsigned char *b, int hi);
    int fixed_only;
} mx_row;
static const mx_row g_rows[] = {
    {"len_shift", "-24", "24 (coords in box)", e_len_shift, 0},
    {"frac_S, CELLK +-2^27, k 0/15", "0", "59", e_frac_s, 0},
    {"frac_S x len_shift", "0, -24", "59, 24", e_frac_s_ls, 0},
    {"frac_M, M +-2^27, k 0/15", "0", "59", e_frac_m, 0},
    {"frac_P, P +-2^27 (k 0)", "0", "50", e_frac_p, 0},
    {"frac_P, k 0/15", "0", "50", e_frac_p_k, 0},
    {"frac_S,M,P all, matrices 2^27, k 0/15", "0,0,0", "59,59,50", e_fracs_all, 0},
    {"frac_E, ENERGY max", "-40", "60", e_frac_e, 1},
    {"frac_E, ENERGY 1 LSB", "-40", "60", e_frac_e_1lsb, 1},
    {"a1, M +-2^27, frac_M 0", "0", "16", e_a1, 0},
    {"b1, CELLK +-2^27, frac_S 0", "0", "16", e_b1, 0},
    {"a1 = b1, every matrix 2^27, fracs 0", "0", "16", e_a1b1, 0},
    {"gravity x", "-32", "32", e_gx, 0},
    {"gravity y", "-32", "32", e_gy, 0},
    {"gravity z", "-32", "32", e_gz, 0},
    {"gravity xyz, M -+2^27, frac_M 0, k 0/15", "-32, no REST_MOD", "32, REST_MOD", e_g_mass, 0},
    {"timestep", "1 LSB / 1.4e-45", "max / 32768", e_timestep, 0},
    {"MASS_SCALE", "INT32_MIN", "INT32_MAX", e_mass_scale, 0},
    {"ENERGY", "1 LSB / 1.4e-45", "max / 2^31", e_energy, 0},
    {"CELL", "1 LSB / 2^-22", "2^27 / 32", e_cell, 0},
    {"DISP_BOUND", "1 LSB / 2^-16", "max / 32768", e_disp_bound, 0},
    {"cg_default (cg_max 256)", "1", "256", e_cg_default, 0},
    {"cg_max (cg_default 1)", "1", "256", e_cg_max, 0},
    {"LIMIT (all free vertices)", "0", "2^28 / 64", e_limit, 0},
    {"rig frac, forces +-INT32, k 0/15", "5", "50", e_rig_frac, 0},
    {"rig forces (frac 5, k 0/15)", "INT32_MIN", "INT32_MAX", e_rig_force, 0},
    {"control value0 (baked, abstract)", "-2^30", "2^30", e_ctl_value, 0},
    {"gammas (1 LSB apart)", "-2^30", "2^30", e_gamma, 0},
    {"etas", "-1", "1", e_eta, 0},
    {"angle axis z, |a|^2", "1 - 2^-8", "1 + 2^-8 (x 2^-4)", e_axis_z, 0},
    {"angle axis (1,1,1), |a|^2", "1 - 2^-8", "1 + 2^-8", e_axis_diag, 0},
    {"rest coords, len_shift 0", "all -2^27", "all +2^27", e_rest, 0},
    {"rest coords, box corners", "ls -24, +-2^27", "ls 9, +-2^27", e_rest_box, 0},
    {"rest coords, len_shift 24", "all -2^12", "all +2^12", e_rest_ls24, 0},
    {"joint coords, len_shift 0", "all -2^27", "all +2^27", e_joint, 0},
    {"joint coords, len_shift -+24", "-2^27, ls -24", "+2^12, ls 24", e_joint_ls, 0},
    {"crease depth, push, exclude (a contact)", "1 LSB, 0, 1 LSB", "2^26, 2^26, 2^28", e_crease_depth, 0},
    {"crease list, active (a contact)", "1, 1", "256, 64", e_crease_list, 0},
    {"ICHOL mantissas +-(2^15-1), k 0/15", "frac 0", "frac 47", e_ichol, 0},
    {"segment relax, gamma, sweeps (format 6.2)", "relax 32, gamma 1 LSB", "relax 63, gamma at omega (1-gamma) = 1, 64 sweeps", e_seg_relax, 0},
    {"everything at once", "all min", "all max", e_all, 0},
};
#define N_ROWS ((int)(sizeof g_rows / sizeof g_rows[0]))

static const mx_row *g_mx_row;
static int g_mx_hi;
static size_t craft_matrix(void) {
    unsigned char *b = g_craft.b;
    uint32_t total = tb_build(b, sizeof g_craft.b, 0);
    g_edit_total = 0;
    g_mx_row->edit(b, g_mx_hi);
    tb_fix_crc(b);
    return g_edit_total ? g_edit_total : total;
}

typedef struct {
    int rc; /* 0 ok, 3 rejected (status in st), 5 non-finite lattice, 6 non-finite stats */
    int st;
    unsigned long sat, limit_clamps, cg_clamps;
} mx_result;

/* One cell of the matrix in a child; the result through a pipe. */
static void mx_cell(const mx_row *row, int hi, char *out, size_t outn, int *fail) {
    int fd[2], status = 0;
    pid_t pid;
    mx_result r;
    memset(&r, 0, sizeof r);
    if (row->fixed_only && SN_FLAVOUR != SN_FLAVOUR_FIXED) { snprintf(out, outn, "n/a (float: 0)"); return; }
    fflush(stdout);
    if (pipe(fd) != 0) { snprintf(out, outn, "FAIL pipe"); (*fail)++; return; }
    pid = fork();
    if (pid == 0) {
        const sn_blob *blob;
        size_t n;
        int pass;
        close(fd[0]);
        g_mx_row = row;
        g_mx_hi = hi;
        n = craft_matrix();
        g_work = g_craft.b;
        sprintf(g_case, "matrix: %s at %s (%s)", row->field, hi ? "max" : "min", hi ? row->hi : row->lo);
        r.st = (int)sn_blob_validate(g_craft.b, n, &blob);
        if (r.st != SN_OK) r.rc = 3;
        for (pass = 0; pass < 2 && r.rc == 0; pass++) {
            g_pose = pass ? 2 : 1;
            g_ctl_baked = pass;
            g_steps = MX_STEPS;
            g_iters = 256;
            exercise(blob);
            r.sat += g_last_stats.saturations;
            r.limit_clamps += g_last_stats.limit_steps;
            r.cg_clamps += g_last_stats.cg_clamps;
            if (!g_finite) r.rc = 5;
#if defined(SN_FLOAT)
            else if (!(g_last_stats.disp_max - g_last_stats.disp_max == 0.0f) ||
                     !(g_last_stats.energy_max - g_last_stats.energy_max == 0.0f))
                r.rc = 6;
#endif
        }
        if (write(fd[1], &r, sizeof r) != (ssize_t)sizeof r) _exit(2);
        _exit(0);
    }
    close(fd[1]);
    if (pid < 0) { close(fd[0]); snprintf(out, outn, "FAIL fork"); (*fail)++; return; }
    if (read(fd[0], &r, sizeof r) != (ssize_t)sizeof r) r.rc = -1;
    close(fd[0]);
    waitpid(pid, &status, 0);
    if (r.rc == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        snprintf(out, outn, "FAIL sanitizer/crash (exit %d sig %d)", WIFEXITED(status) ? WEXITSTATUS(status) : -1,
                 WIFSIGNALED(status) ? WTERMSIG(status) : 0);
        (*fail)++;
    } else if (r.rc == 3) {
        snprintf(out, outn, "FAIL rejected %s", sn_status_str((sn_status)r.st));
        (*fail)++;
    } else if (r.rc == 5) {
        snprintf(out, outn, "FAIL non-finite lattice");
        (*fail)++;
    } else if (r.rc == 6) {
        snprintf(out, outn, "FAIL non-finite stats");
        (*fail)++;
    } else {
        snprintf(out, outn, "ok, sat %lu", r.sat);
    }
}

/* ---- sweep: every value of the small integer header fields, not only the
 * ends (a shift that goes negative or past 62 at an inner value would show
 * here), each with the combination that stresses it most; one child per
 * field, the same two violent runs per value ---- */
static int g_sw_val;
static void s_len_shift(unsigned char *b, int v) { set_ls(b, v); }
static void s_frac_s(unsigned char *b, int v) { e_frac_s(b, 0); b[SN_H_FRAC_S] = (unsigned char)v; }
static void s_frac_m(unsigned char *b, int v) { e_frac_m(b, 0); b[SN_H_FRAC_M] = (unsigned char)v; }
static void s_frac_p(unsigned char *b, int v) { e_frac_p_k(b, 0); b[SN_H_FRAC_P] = (unsigned char)v; }
static void s_frac_e(unsigned char *b, int v) { e_frac_e(b, 0); b[SN_H_FRAC_E] = (unsigned char)(v & 0xFF); }
static void s_rig_frac(unsigned char *b, int v) { e_rig_frac(b, 0); rig_frac(b, v); }
typedef struct {
    const char *field;
    void (*edit)(unsigned char *b, int v);
    int lo, hi, fixed_only;
} sw_row;
static const sw_row g_sweeps[] = {
    {"len_shift", s_len_shift, -24, 24, 0},
    {"frac_S (CELLK +-2^27, k 0/15)", s_frac_s, 0, 59, 1}, /* float: the fractions scale nothing (k = 0) */
    {"frac_M (M +-2^27, k 0/15)", s_frac_m, 0, 59, 1},
    {"frac_P (k 0/15)", s_frac_p, 0, 50, 1},
    {"frac_E (ENERGY max)", s_frac_e, -40, 60, 1},
    {"rig frac (forces +-INT32, k 0/15)", s_rig_frac, SN_RIG_FRAC_MIN, SN_RIG_FRAC_MAX, 1},
};
static const sw_row *g_sw;
static size_t craft_sweep(void) {
    unsigned char *b = g_craft.b;
    uint32_t total = tb_build(b, sizeof g_craft.b, 0);
    g_sw->edit(b, g_sw_val);
    tb_fix_crc(b);
    return total;
}
typedef struct {
    int rc, val, st, n;
    unsigned long sat_min, sat_max;
} sw_result;
static int sweep_one(const sw_row *row) {
    int fd[2], status = 0;
    pid_t pid;
    sw_result r;
    memset(&r, 0, sizeof r);
    if (row->fixed_only && SN_FLAVOUR != SN_FLAVOUR_FIXED) {
        printf("  %-36s %4d..%-4d n/a in float (must be 0, or scales nothing)\n", row->field, row->lo, row->hi);
        return 0;
    }
    { /* the range is the validator's: one past either end is refused */
        int ends[2], e;
        ends[0] = row->lo - 1;
        ends[1] = row->hi + 1;
        g_sw = row;
        for (e = 0; e < 2; e++) {
            const sn_blob *blob;
            size_t n;
            g_sw_val = ends[e];
            n = craft_sweep();
            if (sn_blob_validate(g_craft.b, n, &blob) == SN_OK) {
                printf("FAIL: sweep %s: the validator accepts %d, outside the range this test proves safe\n", row->field,
                       ends[e]);
                return 1;
            }
        }
    }
    fflush(stdout);
    if (pipe(fd) != 0) return 1;
    pid = fork();
    if (pid == 0) {
        close(fd[0]);
        g_sw = row;
        r.sat_min = ~0ul;
        for (g_sw_val = row->lo; g_sw_val <= row->hi && r.rc == 0; g_sw_val++) {
            const sn_blob *blob;
            size_t n = craft_sweep();
            unsigned long sat = 0;
            int pass;
            g_work = g_craft.b;
            sprintf(g_case, "sweep: %s = %d", row->field, g_sw_val);
            r.val = g_sw_val;
            r.st = (int)sn_blob_validate(g_craft.b, n, &blob);
            if (r.st != SN_OK) { r.rc = 3; break; }
            for (pass = 0; pass < 2; pass++) {
                g_pose = pass ? 2 : 1;
                g_ctl_baked = pass;
                g_steps = MX_STEPS;
                g_iters = 256;
                exercise(blob);
                sat += g_last_stats.saturations;
                if (!g_finite) r.rc = 5;
            }
            r.sat_min = sat < r.sat_min ? sat : r.sat_min;
            r.sat_max = sat > r.sat_max ? sat : r.sat_max;
            r.n++;
        }
        if (write(fd[1], &r, sizeof r) != (ssize_t)sizeof r) _exit(2);
        _exit(0);
    }
    close(fd[1]);
    if (pid < 0) { close(fd[0]); return 1; }
    if (read(fd[0], &r, sizeof r) != (ssize_t)sizeof r) r.rc = -1;
    close(fd[0]);
    waitpid(pid, &status, 0);
    if (r.rc == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        printf("FAIL: sweep %s: sanitizer finding or crash (exit %d, signal %d; the case is named above)\n", row->field,
               WIFEXITED(status) ? WEXITSTATUS(status) : -1, WIFSIGNALED(status) ? WTERMSIG(status) : 0);
        return 1;
    }
    if (r.rc == 3) {
        printf("FAIL: sweep %s = %d: rejected (%s)\n", row->field, r.val, sn_status_str((sn_status)r.st));
        return 1;
    }
    if (r.rc == 5) {
        printf("FAIL: sweep %s = %d: non-finite lattice\n", row->field, r.val);
        return 1;
    }
    printf("  %-36s %4d..%-4d %d values ok, saturations %lu..%lu\n", row->field, row->lo, row->hi, r.n, r.sat_min, r.sat_max);
    return 0;
}
static int sweep_all(void) {
    int i, fails = 0;
    printf("  sweep (%s): every value of each integer header field, %d steps x 2 violent poses per value\n", FLAV, MX_STEPS);
    for (i = 0; i < (int)(sizeof g_sweeps / sizeof g_sweeps[0]); i++) fails += sweep_one(&g_sweeps[i]);
    return fails;
}

static int matrix_all(void) {
    int i, fails = 0;
    clock_t t0 = clock();
    struct timespec w0, w1;
    clock_gettime(CLOCK_MONOTONIC, &w0);
    printf("  matrix (%s): each field at its bound, validated, stepped %d steps x 2 violent poses under ASan+UBSan\n", FLAV,
           MX_STEPS);
    printf("  %-40s %-22s %-24s | %-22s %s\n", "field", "min", "", "max", "");
    for (i = 0; i < N_ROWS; i++) {
        char lo[64], hi[64];
        mx_cell(&g_rows[i], 0, lo, sizeof lo, &fails);
        mx_cell(&g_rows[i], 1, hi, sizeof hi, &fails);
        printf("  %-40s %-22s %-24s | %-22s %s\n", g_rows[i].field, g_rows[i].lo, lo, g_rows[i].hi, hi);
    }
#if defined(SN_VALIDATE_NO_CHECKSUM) /* the _ck build steps the same code: the sweeps run once per flavour */
    fails += sweep_all();
#endif
    clock_gettime(CLOCK_MONOTONIC, &w1);
    printf("  figure: extreme-valid matrix %s: %d fields x {min, max} + sweeps, %d failed, %.1f s wall (%.2f s cpu in the parent)\n", FLAV,
           N_ROWS, fails, (double)(w1.tv_sec - w0.tv_sec) + 1e-9 * (double)(w1.tv_nsec - w0.tv_nsec),
           (double)(clock() - t0) / CLOCKS_PER_SEC);
    return fails;
}

/* Fuzz one blob (g_orig, g_size); returns the number of failed checks. */
#ifndef SN_FUZZ_EDGE
#define SN_FUZZ_EDGE 4
#endif
static size_t g_edge = SN_FUZZ_EDGE; /* bytes flipped bit by bit at each end of a section (--edge) */
/* 1: only the blob's random flips (the plain build in make test, SN_FUZZ_RANDOM_ONLY: see main) */
static int g_random_only;
/* The details' blocks at the validator's bounds (format 6.5; a blob with
 * details given): every CELLDK mantissa 2^15 - 1 at exponent 12 (float:
 * every entry 2^27), every mass 2^27 (float 1): the blob must be accepted
 * and exercise() runs the details' kernels on it at +-SN_LIM (exercise_details):
 * the rows at their stated bounds (2^61.4, the clamped corner part) under
 * UBSan and, in the range build, their assertions. */
static int details_at_bounds(const char *name) {
    unsigned char *b;
    const sn_blob *blob;
    uint32_t n, i, k, off;
    const size_t KB = (size_t)SN_ELEM_CELLDK(SN_FLAVOUR, 4);
    if (g_size < SN_H_SECTIONS + 16u * (SN_SEC_CELLDK + 1u) || rd32(g_orig + SN_H_SECTIONS + 16 * SN_SEC_DETAILS + 8) != 1u) return 0;
    b = (unsigned char *)malloc(g_size);
    if (!b) return 1;
    memcpy(b, g_orig, g_size);
    off = tb_sec(b, SN_SEC_CELLDK);
    n = rd32(b + SN_H_SECTIONS + 16 * SN_SEC_CELLDK + 8);
    for (i = 0; i < n; i++) {
        unsigned char *e = b + off + (size_t)i * KB;
#if defined(SN_FLOAT)
        for (k = 0; k < 9; k++) tb_real(e + 4 * k, 134217728.0, 0);
        tb_real(e + 36, 1.0, 0); /* float: a detail's own mass is below 2 (INT32_MAX at Q30); float sums cannot overflow */
#else
        for (k = 0; k < 9; k++) tb_u16(e + 2 * k, 0x7FFFu); /* one sign with one-signed operands: every row at its bound */
        e[18] = SN_CELLK_EXP_MAX;
        tb_u32(e + 20, 0x08000000u);
#endif
    }
    tb_fix_crc(b);
    snprintf(g_case, sizeof g_case, "%s: CELLDK at the validator's bounds", name);
    if (sn_blob_validate(b, g_size, &blob) != SN_OK) {
        printf("FAIL: %s: the details' blocks at the validator's bounds refused\n", name);
        free(b);
        return 1;
    }
    exercise(blob);
    printf("  figure: %s: the details' kernels on CELLDK at the validator's bounds (%u elements), operands +-2^28: no finding\n", name, n);
    free(b);
    return 0;
}

static int fuzz_one(const char *name, int all, unsigned long per_section) {
    size_t n;
    int i, k, fails = 0;
    clock_t t0 = clock(), t_flips;
    /* the work copy is exactly g_size bytes in its own allocation, so ASan
     * catches any read past the end */
    g_work = (unsigned char *)malloc(g_size);
    if (!g_work) exit(2);
    memcpy(g_work, g_orig, g_size);
    printf("  fuzz: %s build (%s), blob %s, %lu bytes, %s\n", FLAV, MODE, name, (unsigned long)g_size,
           all ? "every bit and every truncation" : "sampled (see header comment)");
    {
        sn_status st = run_case(g_size);
        if (st != SN_OK) {
            printf("FAIL: the unmodified blob is rejected: %s\n", sn_status_str(st));
            free(g_work);
            return 1;
        }
    }
    memset(&g, 0, sizeof g);
    g_last_end = 0;
    g_shared_every = SN_FUZZ_SHARED_EVERY;
    for (k = 0; k < SN_SEC_COUNT; k++) {
        size_t e = (size_t)rd32(g_orig + SN_H_SECTIONS + 16 * k) + rd32(g_orig + SN_H_SECTIONS + 16 * k + 4);
        g_last_end = e > g_last_end ? e : g_last_end;
    }

    /* ---- single-bit flips ---- */
    if (all) {
        for (n = 0; n < g_size; n++) flip_byte(n);
    } else {
        for (n = 0; n < SN_HEADER_BYTES && n < g_size && !g_random_only; n++) flip_byte(n);
        for (k = 0; k < SN_SEC_COUNT; k++) {
            uint32_t off = rd32(g_orig + SN_H_SECTIONS + 16 * k), sz = rd32(g_orig + SN_H_SECTIONS + 16 * k + 4);
            uint32_t end = off + sz, gap_end = k + 1 < SN_SEC_COUNT ? rd32(g_orig + SN_H_SECTIONS + 16 * (k + 1))
                                                                  : rd32(g_orig + SN_H_TOTAL_SIZE);
            unsigned long r;
            if (sz == 0) continue;
            for (n = off; n < end && n < off + g_edge && !g_random_only; n++) flip_byte(n);
            for (n = end > off + g_edge ? end - g_edge : off + g_edge; n < end && !g_random_only; n++) flip_byte(n);
            for (n = end; n < gap_end && n < g_size && !g_random_only; n++) flip_byte(n); /* padding */
            for (r = 0; r < per_section; r++) {
                uint64_t x = rnd64();
                flip(off + (size_t)(x % sz), (int)((x >> 40) & 7));
            }
        }
    }
    /* ---- truncations ---- */
    t_flips = clock();
    for (n = 0; n < g_size && !g_random_only; n++) truncate_to(n, 0);
    if (all) {
        for (n = 0; n < g_size; n++) truncate_to(n, 1);
    } else if (!g_random_only) {
        for (n = 0; n < g_size && n < 4096; n++) truncate_to(n, 1);
        for (k = 0; k < SN_SEC_COUNT; k++) {
            uint32_t off = rd32(g_orig + SN_H_SECTIONS + 16 * k), sz = rd32(g_orig + SN_H_SECTIONS + 16 * k + 4);
            int d;
            for (d = -16; d <= 16; d++) {
                if ((long)off + d > 4096 && (size_t)((long)off + d) < g_size) truncate_to((size_t)((long)off + d), 1);
                if ((long)(off + sz) + d > 4096 && (size_t)((long)(off + sz) + d) < g_size)
                    truncate_to((size_t)((long)(off + sz) + d), 1);
            }
        }
        for (i = 0; i < 2000; i++) truncate_to((size_t)(rnd64() % g_size), 1);
    }

    printf("  fuzz: flips %lu: accepted %lu (stepped %lu, instance > 16 MB %lu, init SN_ERR_INDEX %lu), rejected %lu\n", g.flips,
           g.flips_ok, g.stepped, g.huge, g.init_index, g.flips - g.flips_ok);
    printf("  fuzz: truncations (size only) %lu: accepted %lu; (total_size patched) %lu: accepted %lu\n",
           g.trunc, g.trunc_ok, g.trunc_total, g.trunc_total_ok);
    printf("  fuzz: statuses:");
    for (i = 0; i < (int)SN_STATUS_COUNT; i++)
        if (g.by_status[i]) printf(" %s=%lu", sn_status_str((sn_status)i), g.by_status[i]);
    printf("\n");
    printf("  figure: fuzz %s/%s %s: %lu flips (%lu accepted, %lu stepped), %lu truncations, %.1f s (flips %.1f s)\n", FLAV, MODE,
           name, g.flips, g.flips_ok, g.stepped, g.trunc + g.trunc_total, (double)(clock() - t0) / CLOCKS_PER_SEC,
           (double)(t_flips - t0) / CLOCKS_PER_SEC);
    if (g.trunc_ok != 0) { printf("FAIL: %s: a blob shorter than total_size was accepted\n", name); fails++; }
    if (g.trunc_total_ok != 0) { printf("FAIL: %s: a cut blob with patched total_size was accepted\n", name); fails++; }
#if !defined(SN_VALIDATE_NO_CHECKSUM)
    if (g.flips_ok != 0) { printf("FAIL: %s: %lu flipped blobs passed the checksum\n", name, g.flips_ok); fails++; }
#endif
    g_shared_every = 4;
    free(g_work);
    return fails;
}

#ifndef SN_FUZZ_PER_SECTION
#define SN_FUZZ_PER_SECTION 100
#endif

int main(int argc, char **argv) {
    const char *path = NULL, *bdir = getenv("BUILD");
    char defpath[512];
    int all = 0, i, fails = 0, runs = 0, full = 0;
    unsigned long per_section = SN_FUZZ_PER_SECTION, seed = 12345;
    static union { uint64_t a; unsigned char b[8192]; } tb;

#ifdef HAVE_SAN_CB
    __sanitizer_set_death_callback(on_death); /* before --crafted / --matrix return */
#endif
    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--all") == 0) all = 1;
        else if (strcmp(argv[i], "--crafted") == 0) { /* only the crafted cases */
            i = crafted_all();
            printf("%d passed, %d failed\n", N_CRAFTED - i, i);
            return i != 0;
        }
        else if (strcmp(argv[i], "--matrix") == 0) { /* only the extreme-valid matrix */
            i = matrix_all();
            printf("%d passed, %d failed\n", i == 0, i != 0);
            return i != 0;
        }
        else if (strcmp(argv[i], "--per-section") == 0 && i + 1 < argc) per_section = strtoul(argv[++i], NULL, 0);
        else if (strcmp(argv[i], "--edge") == 0 && i + 1 < argc) g_edge = strtoul(argv[++i], NULL, 0);
        else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) seed = strtoul(argv[++i], NULL, 0);
        else if (strcmp(argv[i], "--full") == 0) full = 1;
        else path = argv[i];
    }
    if (getenv("SN_TEST_SEED")) seed = strtoul(getenv("SN_TEST_SEED"), NULL, 0);
    g_trace = getenv("SN_FUZZ_TRACE") != NULL;
    g_rng = 0x9E3779B97F4A7C15ull ^ (uint64_t)seed;
    printf("  seed: %lu (set SN_TEST_SEED to change)\n", seed);
#if defined(SN_FUZZ_RANDOM_ONLY)
    /* The plain build's make test run: test_runtime_fuzz_range (the same
     * objects plus the range checks, the same ASan + UBSan) runs the same
     * hand-built blob, crafted cases, matrix and the cow's header, edge,
     * padding and truncation cases with strictly more checks; here only what
     * it does not: the cow's random flips (100 a section; the range build
     * draws its own 40). With a blob named, --all or --full (make
     * fuzz-blobs): everything, as the other builds. */
    g_random_only = !full && !all && !path;
    if (g_random_only) {
        printf("  the cow's random flips only (hand-built blob, crafted, matrix, header/edge flips, truncations: test_runtime_fuzz_range, same cases + range checks; --full runs them here)\n");
        sprintf(defpath, "%s/%s", bdir ? bdir : "build", DEFAULT_BLOB);
        path = defpath;
    }
#else
    (void)full;
#endif
    if (!path) { /* default: the hand-built blob exhaustively, then the cow sampled */
        g_size = tb_build(tb.b, sizeof tb.b, 3);
        g_orig = (unsigned char *)malloc(g_size);
        if (!g_orig) return 2;
        memcpy(g_orig, tb.b, g_size);
        fails += fuzz_one("hand-built (tests/fuzz/sn_tblob.h)", 1, 0);
        runs++;
#if defined(SN_VALIDATE_NO_CHECKSUM)
        fails += crafted_all();
        runs += N_CRAFTED;
        fails += matrix_all() != 0;
        runs++;
#else
        /* the crafted and matrix blobs carry a valid CRC: here they would step the
         * very objects test_runtime_fuzz steps (only sn_blob.o differs) with the same
         * inputs; the CRC-match path is the unmodified blobs' (run_case above) */
        printf("  crafted cases and matrix: not repeated (test_runtime_fuzz steps the same objects; --crafted, --matrix run them)\n");
#endif
        free(g_orig);
        sprintf(defpath, "%s/%s", bdir ? bdir : "build", DEFAULT_BLOB);
        path = defpath;
    }
    {
        FILE *f = fopen(path, "rb");
        if (f) {
            long len;
            fseek(f, 0, SEEK_END);
            len = ftell(f);
            fseek(f, 0, SEEK_SET);
            g_size = (size_t)len;
            g_orig = (unsigned char *)malloc(g_size + 8);
            if (!g_orig || fread(g_orig, 1, g_size, f) != g_size) { printf("FAIL: cannot read %s\n", path); return 1; }
            fclose(f);
            fails += fuzz_one(path, all, per_section);
            fails += details_at_bounds(path);
            runs++;
            free(g_orig);
        } else {
            printf("  SKIPPED: %s not found (make it with the host tool); fuzzed the hand-built blob only\n", path);
        }
    }
    free(g_mem); free(g_smem); free(g_ws);
    printf("%d passed, %d failed\n", runs - (fails > runs ? runs : fails) + 1, fails);
    return fails != 0;
}
