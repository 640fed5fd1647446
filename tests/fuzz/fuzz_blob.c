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
 *
 * Two builds of the same file (tests/fuzz/fuzz.mk... see runtime/runtime.mk):
 *   test_runtime_fuzz     -DSN_VALIDATE_NO_CHECKSUM: the checksum is skipped so
 *                         mutations reach every later rule and the stepper;
 *   test_runtime_fuzz_ck  normal validator: every flip must be rejected
 *                         (CRC-32 detects every single-bit error; bytes 0..15,
 *                         outside the CRC, are magic/version/endian/CRC).
 *
 * Usage: test_runtime_fuzz [blob] [--all] [--per-section N] [--seed S]
 *   blob       default $BUILD/examples/cow.blob (fixed) or cow_float.blob
 *              (float); if missing, the hand-built test blob (sn_tblob.h)
 *   --all      every bit of the blob (slow for a 200 KB blob: ~1.5 M cases)
 *   env SN_FUZZ_TRACE=1: name each case on stderr before it runs (finds the case behind a sanitizer abort)
 *   default    every bit of the header and section table, every bit of the
 *              first and last 16 bytes of each section, plus N (default 600)
 *              random bits inside each section; truncations: every size
 *              (size only), and total_size patched to the cut for every size
 *              up to 4 KB, every section boundary +-16, and 2000 random sizes.
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
static char g_case[128];
static uint64_t g_rng;
static int g_pose; /* 0: 25 degrees about one axis; 1: (1,1,1) onto -x, root far away;
                    * 2: 180 degrees about (1,1,0) (w = 0), root at (-30000, 30000, -30000) */
static int g_ctl_baked; /* 1: leave the controls at their baked values (default: the type's extremes) */
static int g_steps = 2, g_iters = 2; /* crafted cases: more steps, every CG iteration */
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

/* Use an accepted blob the way a game would. */
static void exercise(const sn_blob *blob) {
    sn_blob_info info;
    sn_instance *inst;
    size_t need = sn_instance_size(blob);
    uint32_t j, idx[3];
    sn_quat *local;
    sn_xform *xf;
    sn_vec3 *surf, *nrm, *lat, root, r;
    sn_status ist;
    int s;

    sn_blob_get_info(blob, &info);
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
    (void)sn_set_iterations(inst, info.cg_iters_max < (uint32_t)g_iters ? info.cg_iters_max : (uint32_t)g_iters);
    (void)sn_set_mode(inst, SN_MODE_WARPED);
    for (s = 0; s < g_steps; s++) {
        if (s == g_steps / 2) { /* teleport back to the rest pose halfway: a second violent jump */
            for (j = 0; j < info.joints; j++) { local[j].x = local[j].y = local[j].z = 0; local[j].w = REAL(1.0f, 1 << 30); }
            sn_pose_from_local(blob, local, NULL, xf);
            (void)sn_set_pose(inst, xf, info.joints);
        }
        sn_step(inst);
    }
    (void)sn_get_lattice(inst, lat, 0, info.vertices);
    sn_get_stats(inst, &g_last_stats);
    g_finite = 1;
    for (j = 0; j < info.vertices; j++)
        if (!(lat[j].x == lat[j].x && lat[j].y == lat[j].y && lat[j].z == lat[j].z)) g_finite = 0;
    (void)sn_get_surface(inst, surf, 0, info.surface_vertices);
    if (info.triangles) (void)sn_get_normals(inst, surf, nrm);
    (void)sn_state_hash(inst);
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
static union { uint64_t a; unsigned char b[16384]; } g_craft;

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
    tb_drop_rigs(b, total);
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

static size_t craft_cellk(int pattern, int frac) {
    unsigned char *b = g_craft.b;
    uint32_t total = tb_build(b, sizeof g_craft.b, 0);
    set_max(b + tb_sec(b, SN_SEC_CELLK), sec_n(b, SN_SEC_CELLK), pattern);
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
    for (k = 0; k < 5; k++) set_max(b + tb_sec(b, secs[k]), sec_n(b, secs[k]), k & 1 ? 2 : 1);
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

#define N_CRAFTED 8
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
    return fails;
}

/* Fuzz one blob (g_orig, g_size); returns the number of failed checks. */
static int fuzz_one(const char *name, int all, unsigned long per_section) {
    size_t n;
    int i, k, fails = 0;
    clock_t t0 = clock();
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
    for (k = 0; k < SN_SEC_COUNT; k++) {
        size_t e = (size_t)rd32(g_orig + SN_H_SECTIONS + 16 * k) + rd32(g_orig + SN_H_SECTIONS + 16 * k + 4);
        g_last_end = e > g_last_end ? e : g_last_end;
    }

    /* ---- single-bit flips ---- */
    if (all) {
        for (n = 0; n < g_size; n++) flip_byte(n);
    } else {
        for (n = 0; n < SN_HEADER_BYTES && n < g_size; n++) flip_byte(n);
        for (k = 0; k < SN_SEC_COUNT; k++) {
            uint32_t off = rd32(g_orig + SN_H_SECTIONS + 16 * k), sz = rd32(g_orig + SN_H_SECTIONS + 16 * k + 4);
            uint32_t end = off + sz, gap_end = k + 1 < SN_SEC_COUNT ? rd32(g_orig + SN_H_SECTIONS + 16 * (k + 1))
                                                                  : rd32(g_orig + SN_H_TOTAL_SIZE);
            unsigned long r;
            if (sz == 0) continue;
            for (n = off; n < end && n < off + 16; n++) flip_byte(n);
            for (n = end > off + 16 ? end - 16 : off + 16; n < end; n++) flip_byte(n);
            for (n = end; n < gap_end && n < g_size; n++) flip_byte(n); /* padding */
            for (r = 0; r < per_section; r++) {
                uint64_t x = rnd64();
                flip(off + (size_t)(x % sz), (int)((x >> 40) & 7));
            }
        }
    }
    /* ---- truncations ---- */
    for (n = 0; n < g_size; n++) truncate_to(n, 0);
    if (all) {
        for (n = 0; n < g_size; n++) truncate_to(n, 1);
    } else {
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
    printf("  figure: fuzz %s/%s %s: %lu flips (%lu accepted, %lu stepped), %lu truncations, %.1f s\n", FLAV, MODE,
           name, g.flips, g.flips_ok, g.stepped, g.trunc + g.trunc_total, (double)(clock() - t0) / CLOCKS_PER_SEC);
    if (g.trunc_ok != 0) { printf("FAIL: %s: a blob shorter than total_size was accepted\n", name); fails++; }
    if (g.trunc_total_ok != 0) { printf("FAIL: %s: a cut blob with patched total_size was accepted\n", name); fails++; }
#if !defined(SN_VALIDATE_NO_CHECKSUM)
    if (g.flips_ok != 0) { printf("FAIL: %s: %lu flipped blobs passed the checksum\n", name, g.flips_ok); fails++; }
#endif
    free(g_work);
    return fails;
}

int main(int argc, char **argv) {
    const char *path = NULL, *bdir = getenv("BUILD");
    char defpath[512];
    int all = 0, i, fails = 0, runs = 0;
    unsigned long per_section = 400, seed = 12345;
    static union { uint64_t a; unsigned char b[8192]; } tb;

    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--all") == 0) all = 1;
        else if (strcmp(argv[i], "--crafted") == 0) { /* only the crafted cases */
            i = crafted_all();
            printf("%d passed, %d failed\n", N_CRAFTED - i, i);
            return i != 0;
        }
        else if (strcmp(argv[i], "--per-section") == 0 && i + 1 < argc) per_section = strtoul(argv[++i], NULL, 0);
        else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) seed = strtoul(argv[++i], NULL, 0);
        else path = argv[i];
    }
    if (getenv("SN_TEST_SEED")) seed = strtoul(getenv("SN_TEST_SEED"), NULL, 0);
    g_trace = getenv("SN_FUZZ_TRACE") != NULL;
    g_rng = 0x9E3779B97F4A7C15ull ^ (uint64_t)seed;
    printf("  seed: %lu (set SN_TEST_SEED to change)\n", seed);
#ifdef HAVE_SAN_CB
    __sanitizer_set_death_callback(on_death);
#endif
    if (!path) { /* default: the hand-built blob exhaustively, then the cow sampled */
        g_size = tb_build(tb.b, sizeof tb.b, 3);
        g_orig = (unsigned char *)malloc(g_size);
        if (!g_orig) return 2;
        memcpy(g_orig, tb.b, g_size);
        fails += fuzz_one("hand-built (tests/fuzz/sn_tblob.h)", 1, 0);
        runs++;
        fails += crafted_all();
        runs += N_CRAFTED;
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
            runs++;
            free(g_orig);
        } else {
            printf("  SKIPPED: %s not found (make it with the host tool); fuzzed the hand-built blob only\n", path);
        }
    }
    free(g_mem);
    printf("%d passed, %d failed\n", runs - (fails > runs ? runs : fails) + 1, fails);
    return fails != 0;
}
