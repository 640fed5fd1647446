/* lf_blob.c -- libFuzzer harness: blob validator + instance + step (issue 16
 * item 5). Built twice by tests/fuzz/fuzz.mk with the runtime sources
 * compiled in: fuzz_blob_fixed and fuzz_blob_float (-DSN_FLOAT), both with
 * -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all.
 *
 * Each input is a blob. Checksum fix-up: when the input is long enough to
 * hold a header and its total_size field (bytes 16..19) lies in
 * (16, input size], the CRC-32 of bytes [16, total_size) (runtime/BLOB.md
 * "Checksum") is written into bytes 12..15 before validating, so mutants
 * reach every structural rule after the checksum instead of all dying there.
 * The layout (offsets, section count, format version) comes from
 * runtime/src/sn_format.h, so the harness follows the format as it moves.
 *
 * An accepted blob is used the way a game would: every accessor (joints,
 * controls, triangles), an instance (init may refuse only with SN_ERR_INDEX,
 * as sinew.h documents), abstract controls set to their type's extremes, a violent
 * pose (every joint 125 degrees about (0,-1,1), the root 30000 mesh units
 * away; the angle and root come from the input's CRC so they vary), a few
 * steps at up to 8 CG iterations, a jump back to rest and a step, then every
 * read-back. The requirements the sanitizers cannot see are checked with
 * LF_REQUIRE (abort = a crash artifact): init accepts the blob, the stats are
 * finite (float), the displacement non-negative, the lattice and surface finite.
 */
#include "lf_common.h" /* first: it sets _POSIX_C_SOURCE */

#include <math.h>
#include "sinew.h"
#include "sn_format.h"
#include "sn_thostile.h"

#if defined(SN_FLOAT)
#define REAL(f, i) ((sn_real)(f))
#define FIN(x) isfinite((double)(x))
#else
#define REAL(f, i) ((sn_real)(i))
#define FIN(x) 1
#endif

#define LF_STEPS 3
#define LF_MAX_INSTANCE (16u << 20) /* a blob may ask for up to 4 GiB of instance; not worth it here */

static uint32_t rd32(const unsigned char *p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static void wr32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)v; p[1] = (unsigned char)(v >> 8); p[2] = (unsigned char)(v >> 16); p[3] = (unsigned char)(v >> 24);
}
/* CRC-32 as BLOB.md specifies: reflected 0xEDB88320, init and final xor 0xFFFFFFFF. */
static uint32_t crc32_bytes(const unsigned char *p, size_t n) {
    static uint32_t table[256];
    static int ready;
    uint32_t c = 0xFFFFFFFFu;
    size_t i;
    if (!ready) {
        uint32_t k, v;
        int b;
        for (k = 0; k < 256; k++) {
            for (v = k, b = 0; b < 8; b++) v = (v >> 1) ^ (0xEDB88320u & (0u - (v & 1u)));
            table[k] = v;
        }
        ready = 1;
    }
    for (i = 0; i < n; i++) c = table[(c ^ p[i]) & 0xFFu] ^ (c >> 8);
    return ~c;
}

static void check_vecs(const sn_vec3 *v, uint32_t n, const char *what) {
    uint32_t i;
    for (i = 0; i < n; i++) LF_REQUIRE(FIN(v[i].x) && FIN(v[i].y) && FIN(v[i].z), "%s %u is not finite", what, i);
}

static void check_stats(const sn_instance *inst) {
    sn_stats st;
    sn_get_stats(inst, &st);
    LF_REQUIRE(FIN(st.disp) && FIN(st.disp_max) && FIN(st.energy) && FIN(st.energy_max),
               "stats not finite: disp %g max %g energy %g max %g", (double)st.disp, (double)st.disp_max,
               (double)st.energy, (double)st.energy_max);
    /* a distance is never negative; nor is the energy report: the validator
     * bounds each matrix entry but cannot cheaply prove CELLK positive
     * semi-definite or the masses positive, so the runtime sums only the
     * non-negative terms (both flavours) */
    LF_REQUIRE(st.disp >= 0 && st.disp_max >= 0 && st.disp_max >= st.disp, "displacement: disp %g max %g",
               (double)st.disp, (double)st.disp_max);
    LF_REQUIRE(st.energy >= 0 && st.energy_max >= st.energy, "energy: %g max %g", (double)st.energy,
               (double)st.energy_max);
}

static void exercise(const sn_blob *blob, uint32_t seed) {
    sn_blob_info info;
    sn_instance *inst;
    size_t need = sn_instance_size_mode(blob, SN_MODE_BLENDED); /* every mode can be stepped */
    uint32_t j, idx[3], it;
    sn_quat *local;
    sn_xform *xf;
    sn_vec3 *surf, *nrm, *lat, root, r, ax;
    sn_status st;
    void *mem;
    int s;

    sn_blob_get_info(blob, &info);
    for (j = 0; j < info.joints; j++) {
        const char *n = sn_joint_name(blob, j);
        (void)sn_joint_parent(blob, j);
        (void)sn_joint_rest(blob, j, &r);
        if (n) LF_REQUIRE(sn_find_joint(blob, n) == (int32_t)j, "joint %u's name finds another joint", j);
    }
    (void)sn_find_joint(blob, "no such joint");
    for (j = 0; j < info.controls; j++) { /* format 3.0 rig controls */
        const char *n = sn_control_name(blob, j);
        (void)sn_control_kind_of(blob, j);
        if (n) LF_REQUIRE(sn_find_control(blob, n) == (int32_t)j, "control %u's name finds another control", j);
    }
    for (j = 0; j < info.triangles && j < 16; j++) (void)sn_get_triangle(blob, j, idx);
    (void)sn_get_triangle(blob, info.triangles, idx);
    if (need > LF_MAX_INSTANCE) return;
    mem = malloc(need ? need : 1);
    if (!mem) return;
    st = sn_instance_init(mem, need, blob, &inst);
    if (st == SN_ERR_INDEX) { free(mem); return; } /* documented in sinew.h */
    LF_REQUIRE(st == SN_OK, "init refused an accepted blob: %s", sn_status_str(st));

    local = (sn_quat *)malloc(sizeof *local * info.joints);
    xf = (sn_xform *)malloc(sizeof *xf * info.joints);
    surf = (sn_vec3 *)malloc(sizeof *surf * (info.surface_vertices + 1));
    nrm = (sn_vec3 *)malloc(sizeof *nrm * (info.surface_vertices + 1));
    lat = (sn_vec3 *)malloc(sizeof *lat * info.vertices);
    LF_REQUIRE(local && xf && surf && nrm && lat, "out of memory");

    /* violent pose: 95..160 degrees about (0,-1,1) (or (1,1,0)), root up to 30000 mesh units away */
    ax.x = (seed & 1) ? REAL(1.0f, 65536) : 0;
    ax.y = (seed & 1) ? REAL(1.0f, 65536) : REAL(-1.0f, -65536);
    ax.z = (seed & 1) ? 0 : REAL(1.0f, 65536);
    for (j = 0; j < info.joints; j++)
        local[j] = sn_quat_axis_angle(ax, REAL(95.0f + (float)((seed >> 1) % 66u), (95 + (int32_t)((seed >> 1) % 66u)) << 16));
    root.x = REAL(30000.0f, 30000 << 16);
    root.y = (seed & 2) ? REAL(-2000.0f, -2000 * 65536) : 0;
    root.z = REAL(0.5f, 32768);
    sn_pose_from_local(blob, local, &root, xf);
    (void)sn_set_pose(inst, xf, info.joints);
    th_hostile_contacts(inst, info.surface_vertices); /* constraints and colliders (format 5.0) */
    for (j = 0; j < info.controls; j++) { /* abstract controls at their type's extremes (pose controls refuse) */
        sn_real cv;
        (void)sn_set_control(inst, j, ((seed >> 3) + j) & 1 ? REAL(-3.0e38f, -INT32_MAX) : REAL(3.0e38f, INT32_MAX));
        (void)sn_get_control(inst, j, &cv);
    }
    it = info.cg_iters_max < 8u ? info.cg_iters_max : 8u;
    (void)sn_set_iterations(inst, it);
    LF_REQUIRE(sn_set_mode(inst, (seed & 4) ? SN_MODE_UNWARPED : (seed & 32) ? SN_MODE_BLENDED : SN_MODE_WARPED) == SN_OK,
               "a mode refused with sn_instance_size_mode(blob, SN_MODE_BLENDED) bytes");
    for (s = 0; s < LF_STEPS; s++) {
        sn_step(inst);
        check_stats(inst);
    }
    /* jump back to the rest pose: a second violent change */
    for (j = 0; j < info.joints; j++) {
        local[j].x = local[j].y = local[j].z = 0;
        local[j].w = REAL(1.0f, 1 << 30);
    }
    sn_pose_from_local(blob, local, NULL, xf);
    (void)sn_set_pose(inst, xf, info.joints);
    sn_step(inst);
    check_stats(inst);

    LF_REQUIRE(sn_get_lattice(inst, lat, 0, info.vertices) == SN_OK, "sn_get_lattice refused the whole lattice");
    check_vecs(lat, info.vertices, "lattice vertex");
    LF_REQUIRE(sn_get_surface(inst, surf, 0, info.surface_vertices) == SN_OK, "sn_get_surface refused the whole surface");
    check_vecs(surf, info.surface_vertices, "surface vertex");
    if (info.triangles) (void)sn_get_normals(inst, surf, nrm);
    (void)sn_get_lattice(inst, lat, info.vertices, 1);
    (void)sn_state_hash(inst);
    sn_reset(inst);
    sn_step(inst);
    check_stats(inst);
    free(local); free(xf); free(surf); free(nrm); free(lat); free(mem);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const sn_blob *blob;
    unsigned char *b;
    uint32_t seed = 0;
    /* exact-size copy: ASan sees any read past the end; malloc is 8-byte aligned */
    b = (unsigned char *)malloc(size ? size : 1);
    if (!b) return 0;
    if (size) memcpy(b, data, size);
    if (size >= SN_H_TOTAL_SIZE + 4) {
        uint32_t total = rd32(b + SN_H_TOTAL_SIZE);
        if (total > 16 && total <= size) {
            seed = crc32_bytes(b + 16, total - 16);
            wr32(b + SN_H_CRC32, seed);
        }
    }
    if (sn_blob_validate(b, size, &blob) == SN_OK) exercise(blob, seed);
    free(b);
    return 0;
}
