/* bench.c -- speed, memory and arithmetic figures of one Sinew step.
 *
 *   sn_bench [blob ...]        time sn_step over a clip-like pose sequence
 *   sn_bench --steps N blob    set one pose, run N steps, nothing else (for
 *                              callgrind: instructions per step =
 *                              (N-step run - 0-step run) / N; the cost of a
 *                              step is fixed by the blob, not by the pose)
 *   sn_bench --contact --steps N blob
 *                              the same with the determinism driver's contact
 *                              scenario (ports/cross/sn_det.c sn_det_contact:
 *                              ground plane, rising sphere, four pins) set
 *                              before the first step; its cost follows the
 *                              active contacts, so compare equal N only
 *   sn_bench --details N [--iterations K] --steps S blob
 *                              details on the cut level (runtime/LEVELS.md
 *                              §3): ids 0..N-1 active (N <= the blob's
 *                              A_max), K CG iterations (0: the blob's);
 *                              --detail-adapt: the runtime re-chooses them
 *                              after each step (sn_set_detail_adapt)
 *   sn_bench --lod L --steps S blob   level L of a 'levels 2' blob
 *   sn_bench --surface N --steps S blob / --normals N --steps S blob
 *                              after the S steps, N calls of sn_get_surface
 *                              (all surface vertices) or of sn_get_normals
 *                              (on one sn_get_surface's output): for
 *                              callgrind, instructions per call = (N-call
 *                              run - 0-call run) / N
 *
 * Built against the shipping library (libsinew.a / libsinew_float.a).
 * The pose sequence: every joint swings about its own axis with its own
 * period and phase (sn_quat_axis_angle), the root walks and bobs, all fed
 * through sn_pose_from_local, as a game would every frame.
 * Never fails on speed: exit status reports only errors.
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sinew.h"
#include "bench_common.h" /* FLAV, LEN, DEG, bench_load, bench_cmp_d, bench_pose */
#include "sn_det.h"          /* sn_det_contact: --contact */
#include "sn_format.h"
#include "sn_kernels.h" /* sn_kernels_name: the library's SIMD path */

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Arithmetic of one sn_step, in scalar multiply-adds, counted from the code
 * of runtime/src/sn_solve.c (format 2.0, per-cell stiffness) and the blob's
 * counts (nC cells, fc free cell corners, fc2 the sum over cells of the
 * square of their free corners, nnz mass blocks, nnzFF of them free-free):
 *   cell product   576 = 8 diagonal + 2 x 28 off-diagonal 3x3 blocks (rhs);
 *                  9 f^2 over a cell's f free corners (matvec, format 6.0)
 *   rhs            nC (16*9 + 2*576 + 24) + 9 fc  + mass 3 nF + 3 nnz + 3 nnzFF
 *                  + gravity 9 nF + kinetic energy 6 nF + w 3 nV
 *   skeleton       9 (nV - nF)
 *   matvec         9 fc2 + 18 fc + mass 3 nF + 6 nnzFF + combine 6 nF
 *   CG start       matvec + precondition 27 nF + 1 dot 3 nF
 *   CG iteration   matvec + 27 nF + 2 dots + 2 axpys + direction 3 nF
 *   health         9 nF (skinned positions) + 3 nF
 * A "block multiply-add" is one 3x3 block times a 3-vector = 9 multiply-adds.
 * Not counted: the frames (nJ quaternion->matrix, one slerp per blended
 * vertex or cell) and the O(n) adds/clamps/shifts. */
static double step_macs(uint32_t nV, uint32_t nF, uint32_t nC, uint32_t fc, uint32_t fc2, uint32_t nnz, uint32_t nnzff,
                        uint32_t iters) {
    double mv = 9.0 * fc2 + 18.0 * fc + 3.0 * nF + 6.0 * nnzff + 6.0 * nF;
    double rhs = nC * (144.0 + 1152.0 + 24.0) + 9.0 * fc + 3.0 * nF + 3.0 * nnz + 3.0 * nnzff + 15.0 * nF + 3.0 * nV;
    return rhs + 9.0 * (nV - nF) + mv + 30.0 * nF + (double)iters * (mv + 27.0 * nF + 21.0 * nF) + 12.0 * nF;
}

static uint32_t rd32(const unsigned char *p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static int g_details, g_iters, g_lod, g_dadapt, g_surface, g_normals; /* --details N, --iterations K, --lod L, --detail-adapt (--steps only) */

static int bench_blob(const char *path, int only_steps, int contact) {
    size_t size, need;
    unsigned char *bytes = bench_load(path, &size);
    const sn_blob *blob;
    sn_blob_info info;
    sn_instance *inst;
    void *mem;
    sn_quat *local;
    sn_xform *xf;
    sn_vec3 *surf, *nrm;
    sn_status st;
    uint32_t nnzff = 0, e, blended = 0, i, fc = 0, fc2 = 0;
    int k, warm = 30, n = 400;
    double *ts, sum = 0, macs;
    if (!bytes) { fprintf(stderr, "sn_bench: cannot read %s\n", path); return 1; }
    st = sn_blob_validate(bytes, size, &blob);
    if (st != SN_OK) { fprintf(stderr, "sn_bench: %s: %s\n", path, sn_status_str(st)); return 1; }
    sn_blob_get_info(blob, &info);
    if (only_steps < 0) { /* load-time cost: full validation incl. CRC-32 */
        double tv[21];
        for (k = 0; k < 21; k++) {
            double t0 = now();
            (void)sn_blob_validate(bytes, size, &blob);
            tv[k] = now() - t0;
        }
        qsort(tv, 21, sizeof tv[0], bench_cmp_d);
        printf("  figure: %s sn_blob_validate: median %.0f us for %lu bytes (%.1f ns/byte)\n", FLAV, 1e6 * tv[10],
               (unsigned long)size, 1e9 * tv[10] / (double)size);
    }
    need = sn_instance_size(blob);
    mem = malloc(need);
    local = (sn_quat *)malloc(sizeof *local * info.joints);
    xf = (sn_xform *)malloc(sizeof *xf * info.joints);
    surf = (sn_vec3 *)malloc(sizeof *surf * info.surface_vertices);
    nrm = (sn_vec3 *)malloc(sizeof *nrm * info.surface_vertices);
    ts = (double *)malloc(sizeof *ts * (size_t)n);
    if (!mem || !local || !xf || !surf || !nrm || !ts) return 2;
    if (sn_instance_init(mem, need, blob, &inst) != SN_OK) return 1;
    if (only_steps >= 0) { /* one pose, then N steps: a step's cost does not depend on the pose */
        if (contact) { /* the determinism driver's scenario itself (back to rest, then its colliders and pins) */
            sn_det d;
            memset(&d, 0, sizeof d);
            d.blob = blob;
            d.inst = inst;
            if (!sn_det_contact(&d)) fprintf(stderr, "sn_bench: --contact: %s has no room for the contact scenario\n", path);
        }
        if (g_details > 0) {
            uint16_t *ids = (uint16_t *)malloc(sizeof *ids * (size_t)g_details);
            for (k = 0; ids && k < g_details; k++) ids[k] = (uint16_t)k;
            if (!ids || sn_details_set(inst, ids, (uint32_t)g_details) != SN_OK) {
                fprintf(stderr, "sn_bench: --details %d refused by %s\n", g_details, path);
                return 1;
            }
            free(ids);
        }
        if (g_dadapt && sn_set_detail_adapt(inst, 1) != SN_OK) return 1;
        if (g_iters > 0 && sn_set_iterations(inst, (uint32_t)g_iters) != SN_OK) return 1;
        if (g_lod > 0 && sn_set_lod(inst, (uint32_t)g_lod) != SN_OK) return 1;
        bench_pose(blob, info.joints, 7 / 60.0, local, xf);
        sn_set_pose(inst, xf, info.joints);
        for (k = 0; k < only_steps; k++) sn_step(inst);
        if (g_dadapt) {
            sn_stats st;
            sn_get_stats(inst, &st);
            fprintf(stderr, "sn_bench: details active %u, refines %u, coarsens %u\n", st.adapt_active, st.adapt_refines, st.adapt_coarsens);
        }
        if (g_normals > 0) sn_get_surface(inst, surf, 0, info.surface_vertices);
        for (k = 0; k < g_surface; k++) sn_get_surface(inst, surf, 0, info.surface_vertices);
        for (k = 0; k < g_normals && info.triangles; k++) sn_get_normals(inst, surf, nrm);
        printf("%016llx\n", (unsigned long long)sn_state_hash(inst));
        return 0;
    }
    {   /* free-free blocks and blended vertices, from the blob */
        const unsigned char *cols = bytes + rd32(bytes + SN_H_SECTIONS + 16 * SN_SEC_COLS);
        const unsigned char *fr = bytes + rd32(bytes + SN_H_SECTIONS + 16 * SN_SEC_FRAMES);
        for (e = 0; e < info.offdiag_blocks; e++) nnzff += (uint32_t)(cols[2 * e] | (cols[2 * e + 1] << 8)) < info.free_vertices;
        const unsigned char *cl = bytes + rd32(bytes + SN_H_SECTIONS + 16 * SN_SEC_CELLS);
        for (i = 0; i < info.vertices; i++) blended += fr[4 * i] != fr[4 * i + 1] && (fr[4 * i + 2] | fr[4 * i + 3]);
        for (e = 0; e < info.cells; e++) {
            uint32_t f = 0;
            for (i = 8 * e; i < 8 * e + 8; i++) f += (uint32_t)(cl[2 * i] | (cl[2 * i + 1] << 8)) < info.free_vertices;
            fc += f;
            fc2 += f * f;
        }
    }
    for (k = 0; k < warm + n; k++) {
        double t0;
        bench_pose(blob, info.joints, k / 60.0, local, xf);
        sn_set_pose(inst, xf, info.joints);
        t0 = now();
        sn_step(inst);
        if (k >= warm) ts[k - warm] = now() - t0;
    }
    for (k = 0; k < n; k++) sum += ts[k];
    qsort(ts, (size_t)n, sizeof *ts, bench_cmp_d);
    {
        double t0 = now(), t_surf, t_nrm = -1.0;
        int rep = 50;
        for (k = 0; k < rep; k++) sn_get_surface(inst, surf, 0, info.surface_vertices);
        t_surf = (now() - t0) / rep;
        if (info.triangles) { /* the engine's other per-frame output: lighting normals */
            t0 = now();
            for (k = 0; k < rep; k++) sn_get_normals(inst, surf, nrm);
            t_nrm = (now() - t0) / rep;
        }
        macs = step_macs(info.vertices, info.free_vertices, info.cells, fc, fc2, info.offdiag_blocks, nnzff,
                         info.cg_iters_default);
        printf("  blob %s (%s): %u B blob, %u B instance; nV %u (free %u), nJ %u, cells %u, surface %u, "
               "tris %u, off-diagonal blocks %u (free-free %u), blended vertices %u, CG iterations %u; kernels %s\n",
               path, FLAV, info.blob_bytes, (unsigned)need, info.vertices, info.free_vertices, info.joints,
               info.cells, info.surface_vertices, info.triangles, info.offdiag_blocks, nnzff, blended,
               info.cg_iters_default, sn_kernels_name());
        printf("  figure: %s step time: median %.1f us, min %.1f us, mean %.1f us, p90 %.1f us (%d steps); "
               "get_surface %.1f us, get_normals %.1f us\n", FLAV, 1e6 * ts[n / 2], 1e6 * ts[0], 1e6 * sum / n,
               1e6 * ts[n * 9 / 10], n, 1e6 * t_surf, 1e6 * t_nrm);
        printf("  figure: %s memory: instance %u B with its own scratch, or %u B persistent state + a %u B workspace "
               "shared by every instance a thread steps (sn_instance_init_shared, sn_step_with)\n", FLAV, (unsigned)need,
               (unsigned)sn_instance_state_size(blob), (unsigned)sn_workspace_size(blob, SN_MODE_WARPED));
        printf("  figure: %s arithmetic per step: %.0f multiply-adds = %.0f block multiply-adds (3x3 block x 3-vector)\n",
               FLAV, macs, macs / 9.0);
        printf("  macs: %.0f\n", macs / 9.0);
    }
    {
        sn_stats s;
        sn_get_stats(inst, &s);
        printf("  %s after %d steps: saturations %u, state hash %016llx\n", FLAV, warm + n, s.saturations,
               (unsigned long long)sn_state_hash(inst));
    }
    free(mem); free(local); free(xf); free(surf); free(nrm); free(ts); free(bytes);
    return 0;
}

int main(int argc, char **argv) {
    int i, steps = -1, rc = 0, any = 0, contact = 0;
    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--details") == 0 && i + 1 < argc) { g_details = atoi(argv[++i]); continue; }
        if (strcmp(argv[i], "--iterations") == 0 && i + 1 < argc) { g_iters = atoi(argv[++i]); continue; }
        if (strcmp(argv[i], "--lod") == 0 && i + 1 < argc) { g_lod = atoi(argv[++i]); continue; }
        if (strcmp(argv[i], "--detail-adapt") == 0) { g_dadapt = 1; continue; }
        if (strcmp(argv[i], "--surface") == 0 && i + 1 < argc) { g_surface = atoi(argv[++i]); continue; }
        if (strcmp(argv[i], "--normals") == 0 && i + 1 < argc) { g_normals = atoi(argv[++i]); continue; }
        if (strcmp(argv[i], "--steps") == 0 && i + 1 < argc) { steps = atoi(argv[++i]); continue; }
        if (strcmp(argv[i], "--contact") == 0) { contact = 1; continue; }
        rc |= bench_blob(argv[i], steps, contact);
        any = 1;
    }
    if (!any) { fprintf(stderr, "usage: sn_bench [--contact] [--steps N] blob...\n"); return 2; }
    return rc;
}
