/* main_level.c -- the level-of-detail and adaptation scenarios of
 * tests/scripts/test_determinism.sh on the Cortex-M4 (issue 13): what
 *   det_main BLOB --clip trot.clip --steps N --lod K:L,.. --main-only [--shared]
 * does, with the blob linked in flash and the memory static. Prints the
 * same "hash: <16 hex>" plus the figures test_determinism.sh checks
 * (saturations, refused steps, stack peak, level and adaptation counters).
 * Built per scenario (baremetal.mk, bm_level_image) with:
 *   SN_BM_BLOB, SN_BM_BLOB_SIZE  the tool's C-array symbols
 *   SN_BM_STEPS                  steps to play
 *   SN_BM_LOD                    switches K,L,K,L..: sn_set_lod(L) before step K
 *                                (undefined: no switch)
 *   SN_BM_DETAILS, SN_BM_ITERS   details 0..N-1 active on the cut level and
 *                                the CG iterations from the first step, as
 *                                det_main --details N --iterations K (0: none)
 *   SN_BM_DETAIL_ADAPT           1: the details chosen by the runtime from the
 *                                first step (sn_set_detail_adapt), as det_main
 *                                --detail-adapt
 *   SN_BM_SHARED                 1: shared instance stepped by sn_step_with
 *   SN_BM_BENCH                  1: also time each step with CMSDK timer 0 and
 *                                print instructions per step on each level;
 *                                meaningful only under `-icount shift=0`
 *   SN_BM_INSTANCE_BYTES, SN_BM_STATE_BYTES, SN_BM_WS_BYTES
 *                                the blob's sizes (mem_bytes.c, on the host)
 * The clip is always linked (sn_bm_clip_text): the scenarios are the trot's.
 */
#include <stddef.h>
#include <stdint.h>
#include "semihost.h"
#include "sn_det.h"

#if !defined(SN_BM_STEPS) || !defined(SN_BM_SHARED)
#error "SN_BM_STEPS, SN_BM_SHARED: see baremetal.mk bm_level_image"
#endif
#ifndef SN_BM_DETAILS
#define SN_BM_DETAILS 0
#endif
#ifndef SN_BM_ITERS
#define SN_BM_ITERS 0
#endif
#ifndef SN_BM_DETAIL_ADAPT
#define SN_BM_DETAIL_ADAPT 0
#endif
#if !defined(SN_BM_INSTANCE_BYTES) || !defined(SN_BM_STATE_BYTES) || !defined(SN_BM_WS_BYTES)
#error "SN_BM_*_BYTES: see ports/baremetal/mem_bytes.c"
#endif

extern const unsigned char SN_BM_BLOB[];
extern const unsigned long SN_BM_BLOB_SIZE; /* as sinew-bake --c-array writes it */
extern const unsigned char sn_bm_clip_text[];
extern const uint32_t sn_bm_clip_len;
uint32_t sn_bm_stack_used(void);

#ifndef SN_BM_BENCH
#define SN_BM_BENCH 0
#endif

#ifdef SN_BM_LOD
static const uint32_t lod_sw[] = { SN_BM_LOD };
#define N_SW (sizeof lod_sw / sizeof lod_sw[0] / 2u)
#endif
#if SN_BM_DETAILS
static uint16_t detail_ids[SN_BM_DETAILS];
#endif

static sn_det det;
static sn_clip clip;
/* 8-byte aligned static memory, exactly what the scenario needs, so that
 * arm-none-eabi-size counts it: the state then the workspace (shared), or
 * the whole instance (own scratch) */
#if SN_BM_SHARED
#define STATE_WORDS ((SN_BM_STATE_BYTES + 7u) / 8u)
static uint64_t state_mem[STATE_WORDS];
static uint64_t ws_mem[(SN_BM_WS_BYTES + 7u) / 8u];
#else
static uint64_t state_mem[(SN_BM_INSTANCE_BYTES + 7u) / 8u];
#endif


static int fail(const char *what) {
    sn_bm_puts("FAIL: "); sn_bm_puts(what); sn_bm_puts("\n");
    return 1;
}

int main(void) {
    char err[SN_CLIP_ERR_LEN * 2], hex[17];
    uint32_t k, j;
    sn_stats st;
    const sn_blob *b;
#if SN_BM_BENCH
    uint32_t lod = 0;   /* the level in force */
    uint64_t ticks[2] = { 0, 0 };
    uint32_t n_lvl[2] = { 0, 0 }, cal_ticks, overhead, t0;
    SN_CMSDK_TIMER0[SN_TIMER_CTRL] = 0;
    SN_CMSDK_TIMER0[SN_TIMER_RELOAD] = 0xFFFFFFFFu;
    SN_CMSDK_TIMER0[SN_TIMER_VALUE] = 0xFFFFFFFFu;
    SN_CMSDK_TIMER0[SN_TIMER_CTRL] = 1u;
    cal_ticks = sn_bm_calibrate(2000000u);
    t0 = sn_bm_timer_now(); overhead = t0 - sn_bm_timer_now();
    if (cal_ticks == 0) return fail("timer does not run");
#endif
    (void)j;   /* unused in an image with neither switches nor a detail list */
    /* the host's sizes must be the target's: the figures below are exact */
    if (sn_blob_validate(SN_BM_BLOB, SN_BM_BLOB_SIZE, &b) != SN_OK) return fail("blob does not validate");
    if (sn_instance_size(b) != SN_BM_INSTANCE_BYTES || sn_instance_state_size(b) != SN_BM_STATE_BYTES ||
        sn_workspace_size(b, SN_MODE_WARPED) != SN_BM_WS_BYTES)
        return fail("sizes differ from mem_bytes' (stale generated header?)");
#if SN_BM_SHARED
    if (sn_det_init_shared(&det, SN_BM_BLOB, SN_BM_BLOB_SIZE, (const char *)sn_bm_clip_text, sn_bm_clip_len,
                           &clip, state_mem, sizeof state_mem, ws_mem, sizeof ws_mem, err, sizeof err))
        return fail(err);
    sn_bm_put_kv("state_bytes: ", SN_BM_STATE_BYTES);
    sn_bm_put_kv("workspace_bytes: ", SN_BM_WS_BYTES);
#else
    if (sn_det_init(&det, SN_BM_BLOB, SN_BM_BLOB_SIZE, (const char *)sn_bm_clip_text, sn_bm_clip_len,
                    &clip, state_mem, sizeof state_mem, err, sizeof err))
        return fail(err);
#endif
    sn_bm_put_kv("instance_bytes: ", SN_BM_INSTANCE_BYTES);
    sn_bm_put_kv("shared: ", SN_BM_SHARED);
    sn_bm_put_kv("levels: ", sn_lod_levels(det.blob));
#if SN_BM_DETAILS   /* ids 0..N-1, as det_main --details N */
    for (j = 0; j < SN_BM_DETAILS; j++) detail_ids[j] = (uint16_t)j;
    if (sn_details_set(det.inst, detail_ids, SN_BM_DETAILS) != SN_OK) return fail("sn_details_set refused");
    sn_bm_put_kv("details: ", SN_BM_DETAILS);
#endif
#if SN_BM_DETAIL_ADAPT
    if (sn_set_detail_adapt(det.inst, 1) != SN_OK) return fail("sn_set_detail_adapt refused");
    sn_bm_put_kv("detail_adapt: ", 1);
#endif
#if SN_BM_ITERS
    if (sn_set_iterations(det.inst, SN_BM_ITERS) != SN_OK) return fail("sn_set_iterations refused");
    sn_bm_put_kv("iterations: ", SN_BM_ITERS);
#endif
    for (k = 0; k < SN_BM_STEPS; k++) {
        sn_det_pose(&det);
#ifdef SN_BM_LOD
        for (j = 0; j < N_SW; j++)   /* before step k + 1, as det_main --lod */
            if (lod_sw[2u * j] == k + 1u) {
                if (sn_set_lod(det.inst, lod_sw[2u * j + 1u]) != SN_OK) return fail("sn_set_lod refused");
#if SN_BM_BENCH
                lod = lod_sw[2u * j + 1u] ? 1u : 0u;
#endif
                (void)sn_get_stats(det.inst, &st);   /* the level's lattice: evidence the switch acted */
                sn_bm_puts("switch: step "); sn_bm_put_u64(k + 1u); sn_bm_puts(" level "); sn_bm_put_u64(st.lod);
                sn_bm_puts(" lattice_vertices "); sn_bm_put_u64(st.lattice_vertices); sn_bm_puts("\n");
            }
#endif
#if SN_BM_BENCH
        t0 = sn_bm_timer_now();
        sn_det_step(&det);
        ticks[lod] += t0 - sn_bm_timer_now() - overhead;
        n_lvl[lod]++;
#else
        sn_det_step(&det);
#endif
    }
#if SN_BM_BENCH   /* instructions = ticks * 4,000,000 / cal_ticks, per step */
    for (j = 0; j < 2u; j++)
        if (n_lvl[j]) {
            sn_bm_puts(j ? "insns_per_step_level1: " : "insns_per_step_level0: ");
            sn_bm_put_u64(ticks[j] * 4000000u / cal_ticks / n_lvl[j]);
            sn_bm_puts(" (mean of "); sn_bm_put_u64(n_lvl[j]); sn_bm_puts(" steps)\n");
        }
#endif
    sn_bm_put_kv("refused: ", det.refused);
    (void)sn_get_stats(det.inst, &st);
    sn_bm_put_kv("steps: ", st.steps);
    sn_bm_put_kv("saturations: ", st.saturations);
    sn_bm_put_kv("lod: ", st.lod);
    sn_bm_put_kv("lattice_vertices: ", st.lattice_vertices);
    sn_bm_put_kv("adapt_on: ", st.adapt_on);
    sn_bm_put_kv("adapt_active: ", st.adapt_active);
    sn_bm_put_kv("adapt_refines: ", st.adapt_refines);
    sn_bm_put_kv("adapt_coarsens: ", st.adapt_coarsens);
    sn_bm_put_kv("stack_bytes: ", sn_bm_stack_used());
    sn_det_hex64(sn_state_hash(det.inst), hex);
    sn_bm_puts("hash: "); sn_bm_puts(hex); sn_bm_puts("\n");
    return det.refused ? fail("sn_step_with refused steps") : 0;
}
