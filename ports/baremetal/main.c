/* main.c -- Sinew on a Cortex-M4 (QEMU mps2-an386): plays a clip on a blob
 * linked into flash, with the instance in a static RAM buffer, and prints
 * "hash: <16 hex>" through semihosting like `sinew-play --hash`.
 * Built per asset with:
 *   SN_BM_BLOB, SN_BM_BLOB_SIZE  the tool's C-array symbols
 *   SN_BM_CLIP                   1: link sn_bm_clip_text (generated), 0: built-in poses
 *   SN_BM_STEPS                  steps to play
 *   SN_BM_BENCH                  1: also time pose and step with CMSDK timer 0;
 *                                meaningful only under `-icount shift=0`
 *   SN_BM_INSTANCE_BYTES         the blob's instance size (inst_bytes.sh), so the
 *                                instance is a static buffer that `size` counts
 */
#include <stddef.h>
#include <stdint.h>
#include "semihost.h"
#include "sn_det.h"

#ifndef SN_BM_STEPS
#define SN_BM_STEPS 1000
#endif
#ifndef SN_BM_BENCH
#define SN_BM_BENCH 0
#endif

extern const unsigned char SN_BM_BLOB[];
extern const unsigned long SN_BM_BLOB_SIZE; /* as sinew-bake --c-array writes it */
#if SN_BM_CLIP
extern const unsigned char sn_bm_clip_text[];
extern const uint32_t sn_bm_clip_len;
#endif
#ifndef SN_BM_INSTANCE_BYTES
#error "SN_BM_INSTANCE_BYTES: see ports/baremetal/inst_bytes.sh"
#endif
uint32_t sn_bm_stack_used(void);

static sn_det det;
#if !defined(SN_BM_INSTANCE_BYTES_BLENDED) || SN_BM_BENCH
#undef SN_BM_INSTANCE_BYTES_BLENDED
#define SN_BM_INSTANCE_BYTES_BLENDED SN_BM_INSTANCE_BYTES /* no blended scenario */
#endif
static uint64_t instance_mem[(SN_BM_INSTANCE_BYTES_BLENDED + 7u) / 8u];  /* 8-byte aligned; the blended scenario's too */
#if SN_BM_CLIP
static sn_clip clip;   /* ~23 KB: only in images that play a clip */
#define CLIP_MEM (&clip)
#else
#define CLIP_MEM NULL
#endif

#if SN_BM_BENCH

static uint32_t overhead;   /* ticks of two back-to-back timer reads */

/* n steps; adds the ticks spent in pose and in sn_step */
static void time_steps(uint32_t n, uint64_t *pose_ticks, uint64_t *step_ticks) {
    uint32_t k;
    for (k = 0; k < n; k++) {
        uint32_t t0 = sn_bm_timer_now(), t1, t2;
        sn_det_pose(&det);
        t1 = sn_bm_timer_now();
        sn_det_step(&det);
        t2 = sn_bm_timer_now();
        *pose_ticks += t0 - t1 - overhead;
        *step_ticks += t1 - t2 - overhead;
    }
}
#endif

int main(void) {
    char err[SN_CLIP_ERR_LEN * 2], hex[17];
    const char *text = NULL;
    size_t text_len = 0;
    uint64_t hash;
    sn_blob_info bi;
#if SN_BM_BENCH
    uint64_t pose_ticks = 0, step_ticks = 0, more_ticks = 0, unused = 0;
    uint32_t cal_insns, cal_ticks, more_iters;
#endif
#if SN_BM_CLIP
    text = (const char *)sn_bm_clip_text;
    text_len = sn_bm_clip_len;
#endif
    if (sn_det_init(&det, SN_BM_BLOB, SN_BM_BLOB_SIZE, text, text_len, CLIP_MEM,
                    instance_mem, sizeof instance_mem, err, sizeof err)) {
        sn_bm_puts("FAIL: "); sn_bm_puts(err); sn_bm_puts("\n");
        return 1;
    }
    sn_bm_put_kv("instance_bytes: ", sn_instance_size(det.blob));
    sn_blob_get_info(det.blob, &bi);
    sn_bm_put_kv("lattice_vertices: ", bi.vertices);
    sn_bm_put_kv("free_vertices: ", bi.free_vertices);
    sn_bm_put_kv("offdiag_blocks: ", bi.offdiag_blocks);
    sn_bm_put_kv("cg_iterations: ", bi.cg_iters_default);
    sn_bm_put_kv("clip: ", SN_BM_CLIP);
#if SN_BM_BENCH
    SN_CMSDK_TIMER0[SN_TIMER_CTRL] = 0;
    SN_CMSDK_TIMER0[SN_TIMER_RELOAD] = 0xFFFFFFFFu;
    SN_CMSDK_TIMER0[SN_TIMER_VALUE] = 0xFFFFFFFFu;
    SN_CMSDK_TIMER0[SN_TIMER_CTRL] = 1u;
    cal_ticks = sn_bm_calibrate(2000000u);
    cal_insns = 2u * 2000000u;
    { uint32_t t_a = sn_bm_timer_now(); overhead = t_a - sn_bm_timer_now(); }
    if (cal_ticks == 0) { sn_bm_puts("FAIL: timer does not run\n"); return 1; }
    time_steps(SN_BM_STEPS, &pose_ticks, &step_ticks);
    hash = sn_state_hash(det.inst);
    /* cost of one CG iteration: the slope between the default count and
     * twice that (steps are fixed-cost, so a few steps suffice) */
    more_iters = bi.cg_iters_default * 2u <= bi.cg_iters_max ? bi.cg_iters_default * 2u : bi.cg_iters_max;
    if (more_iters > bi.cg_iters_default && sn_set_iterations(det.inst, more_iters) == SN_OK) {
        uint32_t n_more = SN_BM_STEPS / 4u + 1u;
        uint64_t a, b;
        time_steps(n_more, &unused, &more_ticks);
        (void)sn_set_iterations(det.inst, 0);
        a = step_ticks * cal_insns / cal_ticks / SN_BM_STEPS;
        b = more_ticks * cal_insns / cal_ticks / n_more;
        sn_bm_put_kv("cg_iterations_more: ", more_iters);
        sn_bm_put_kv("insns_per_step_more: ", b);
        sn_bm_put_kv("insns_per_cg_iteration: ", (b - a) / (more_iters - bi.cg_iters_default));
    }
    /* instructions = ticks * cal_insns / cal_ticks, per step */
    sn_bm_put_kv("bench_steps: ", SN_BM_STEPS);
    sn_bm_put_kv("insns_per_step: ", (step_ticks * cal_insns / cal_ticks) / SN_BM_STEPS);
    sn_bm_put_kv("insns_per_pose: ", (pose_ticks * cal_insns / cal_ticks) / SN_BM_STEPS);
    sn_bm_put_kv("insns_per_tick_x1000: ", (uint64_t)cal_insns * 1000u / cal_ticks);
#else
    hash = sn_det_run(&det, SN_BM_STEPS);
#endif
    {
        sn_stats st;
        sn_get_stats(det.inst, &st);
        sn_bm_put_kv("steps: ", st.steps);
        sn_bm_put_kv("saturations: ", st.saturations);
    }
    sn_bm_put_kv("stack_bytes: ", sn_bm_stack_used());
    sn_det_hex64(hash, hex);
    sn_bm_puts("hash: "); sn_bm_puts(hex); sn_bm_puts("\n");
    if (sn_det_contact(&det)) { /* the constrained scenario (issue 12) */
        sn_det_hex64(sn_det_run(&det, SN_DET_CONTACT_STEPS), hex);
        sn_bm_puts("hash-contact: "); sn_bm_puts(hex); sn_bm_puts("\n");
    }
    if (sn_det_blended(&det)) { /* SN_MODE_BLENDED (issue 13 item 4): given its memory above */
        sn_det_hex64(sn_det_run(&det, SN_DET_BLENDED_STEPS), hex);
        sn_bm_puts("hash-blended: "); sn_bm_puts(hex); sn_bm_puts("\n");
    }
    return 0;
}
