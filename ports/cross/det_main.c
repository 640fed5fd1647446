/* det_main.c -- headless determinism driver, built by every compiler and
 * cross compiler of tests/scripts/test_determinism.sh.
 *   det_main [BLOB] [--clip CLIP] [--steps N] [--trace K] [--lod K:L[,K:L..]]
 *            [--shared] [--main-only] [--details N] [--iterations K] [--detail-adapt]
 * --lod: sn_set_lod(L) before step K (a blob baked with 'levels 2', runtime/LEVELS.md).
 * --shared: a shared instance stepped by sn_step_with on a separate workspace
 * (sinew.h "Shared workspace"); its hash must equal the own-scratch one.
 * --main-only: leave out the contact and blended scenarios after the run.
 * --details N: details 0..N-1 active on the cut level (sn_details_set, runtime/LEVELS.md §3);
 * --iterations K: K CG iterations (sn_set_iterations) from the first step.
 * --detail-adapt: the runtime chooses the details after each step (sn_set_detail_adapt, stage 3).
 * Without BLOB it uses the array linked in with -DSN_DET_BLOB=sym
 * -DSN_DET_BLOB_SIZE=sym (the host tool's C-array output), copied to
 * malloc memory because the runtime wants 8-byte alignment.
 * Prints "hash: <16 hex>" after N steps (default 1000); --trace K also prints
 * "step <k> <hash>" every K steps, to find the first step where ports differ. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sn_det.h"

#ifdef SN_DET_BLOB
extern const unsigned char SN_DET_BLOB[];
extern const unsigned long SN_DET_BLOB_SIZE; /* as sinew-bake --c-array writes it */
#endif

/* Whole file into malloc memory (8-byte aligned, as the runtime needs). */
static char *slurp(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    long sz;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (sz = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
        buf = malloc((size_t)sz + 1);
        if (buf && fread(buf, 1, (size_t)sz, f) != (size_t)sz) { free(buf); buf = NULL; }
        if (buf) { buf[sz] = 0; *n = (size_t)sz; }
    }
    fclose(f);
    return buf;
}

int main(int argc, char **argv) {
    static sn_det det;
    static sn_clip clip;
    char err[SN_CLIP_ERR_LEN * 2], hex[17];
    const char *blob_path = NULL, *clip_path = NULL;
    char *blob, *clip_text = NULL;
    size_t blob_n = 0, clip_n = 0, mem_n;
    unsigned long steps = 1000, trace = 0, k, lod_k[16], n_det = 0, iters = 0;
    unsigned lod_l[16];
    void *mem, *ws = NULL;
    size_t ws_n = 0;
    int i, n_lod = 0, j, shared = 0, main_only = 0, dadapt = 0;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--clip") && i + 1 < argc) clip_path = argv[++i];
        else if (!strcmp(argv[i], "--steps") && i + 1 < argc) steps = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--trace") && i + 1 < argc) trace = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--lod") && i + 1 < argc) {
            char *q = argv[++i], *e;
            for (;;) {
                if (n_lod >= 16) { fprintf(stderr, "det_main: --lod: at most 16 switches\n"); return 2; }
                lod_k[n_lod] = strtoul(q, &e, 10);
                if (e == q || *e != ':') { fprintf(stderr, "det_main: --lod: want K:L[,K:L..]\n"); return 2; }
                q = e + 1;
                lod_l[n_lod] = (unsigned)strtoul(q, &e, 10);
                if (e == q || (*e && *e != ',')) { fprintf(stderr, "det_main: --lod: want K:L[,K:L..]\n"); return 2; }
                n_lod++;
                if (!*e) break;
                q = e + 1;
            }
        }
        else if (!strcmp(argv[i], "--shared")) shared = 1;
        else if (!strcmp(argv[i], "--main-only")) main_only = 1;
        else if (!strcmp(argv[i], "--details") && i + 1 < argc) n_det = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--iterations") && i + 1 < argc) iters = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--detail-adapt")) dadapt = 1;
        else if (argv[i][0] != '-' && !blob_path) blob_path = argv[i];
        else { fprintf(stderr, "usage: det_main BLOB [--clip CLIP] [--steps N] [--trace K] [--lod K:L[,K:L..]] [--shared] [--main-only] [--details N] [--iterations K] [--detail-adapt]\n"); return 2; }
    }
    if (blob_path) {
        blob = slurp(blob_path, &blob_n);
        if (!blob) { fprintf(stderr, "det_main: cannot read %s\n", blob_path); return 2; }
    } else {
#ifdef SN_DET_BLOB
        blob_n = SN_DET_BLOB_SIZE;
        blob = malloc(blob_n ? blob_n : 1);
        if (!blob) { fprintf(stderr, "det_main: out of memory\n"); return 2; }
        memcpy(blob, SN_DET_BLOB, blob_n);
        blob_path = "(linked blob)";
#else
        fprintf(stderr, "det_main: no blob\n"); return 2;
#endif
    }
    if (clip_path && !(clip_text = slurp(clip_path, &clip_n))) {
        fprintf(stderr, "det_main: cannot read %s\n", clip_path); return 2;
    }
    /* size from a throwaway validate: sn_det_init validates again */
    {
        const sn_blob *b;
        sn_status s = sn_blob_validate(blob, blob_n, &b);
        if (s != SN_OK) { fprintf(stderr, "det_main: %s: %s\n", blob_path, sn_status_str(s)); return 1; }
        if (shared) { /* the blended scenario's workspace is the larger */
            size_t w0 = sn_workspace_size(b, SN_MODE_WARPED), w1 = sn_workspace_size(b, SN_MODE_BLENDED);
            mem_n = sn_instance_state_size(b);
            ws_n = w0 > w1 ? w0 : w1;
        } else mem_n = sn_instance_size_mode(b, SN_MODE_BLENDED); /* also the blended scenario's */
    }
    mem = malloc(mem_n);
    if (shared) ws = malloc(ws_n ? ws_n : 1);
    if (!mem || (shared && !ws)) { fprintf(stderr, "det_main: out of memory\n"); return 2; }
    if (shared ? sn_det_init_shared(&det, blob, blob_n, clip_text, clip_n, clip_text ? &clip : NULL,
                                    mem, mem_n, ws, ws_n, err, sizeof err)
               : sn_det_init(&det, blob, blob_n, clip_text, clip_n, clip_text ? &clip : NULL,
                             mem, mem_n, err, sizeof err)) {
        fprintf(stderr, "det_main: %s\n", err); return 1;
    }
    if (n_det) { /* details on the cut level: ids 0..n_det-1 */
        uint16_t *ids = malloc(sizeof *ids * n_det);
        for (j = 0; ids && (unsigned long)j < n_det; j++) ids[j] = (uint16_t)j;
        if (n_det > 65535u || !ids || sn_details_set(det.inst, ids, (uint32_t)n_det) != SN_OK) { fprintf(stderr, "det_main: --details %lu refused\n", n_det); return 1; }
        free(ids);
    }
    if (dadapt && sn_set_detail_adapt(det.inst, 1) != SN_OK) { fprintf(stderr, "det_main: --detail-adapt refused\n"); return 1; }
    if (iters && sn_set_iterations(det.inst, (uint32_t)iters) != SN_OK) { fprintf(stderr, "det_main: --iterations %lu refused\n", iters); return 1; }
    for (k = 0; k < steps; k++) {
        sn_det_pose(&det);
        for (j = 0; j < n_lod; j++)   /* level switches before step k + 1 (as sinew-play --lod) */
            if (lod_k[j] == k + 1 && sn_set_lod(det.inst, lod_l[j]) != SN_OK) { fprintf(stderr, "det_main: sn_set_lod %u refused\n", lod_l[j]); return 1; }
        sn_det_step(&det);
        if (trace && (k + 1) % trace == 0) {
            sn_det_hex64(sn_state_hash(det.inst), hex);
            printf("step %lu %s\n", k + 1, hex);
        }
    }
    if (det.refused) { fprintf(stderr, "det_main: sn_step_with refused %u steps\n", (unsigned)det.refused); return 1; }
    sn_det_hex64(sn_state_hash(det.inst), hex);
    printf("hash: %s\n", hex);
    {
        sn_stats st;
        sn_get_stats(det.inst, &st);
        printf("steps: %" PRIu32 " saturations: %" PRIu32 "\n", st.steps, st.saturations);
    }
    if (!main_only && sn_det_contact(&det)) { /* the constrained scenario: every platform checks it too */
        sn_stats st;
        sn_det_hex64(sn_det_run(&det, SN_DET_CONTACT_STEPS), hex);
        printf("hash-contact: %s\n", hex);
        sn_get_stats(det.inst, &st);
        printf("contact steps: %" PRIu32 " rows: %" PRIu32 " contacts: %" PRIu32 " drops: %" PRIu32 " saturations: %" PRIu32 "\n",
               st.steps, st.constraint_rows, st.contacts, st.constraint_drops, st.saturations);
    }
    if (!main_only && sn_det_blended(&det)) { /* blended local linearization (seed 000 §4.5): every platform checks it too */
        sn_stats st;
        sn_det_hex64(sn_det_run(&det, SN_DET_BLENDED_STEPS), hex);
        printf("hash-blended: %s\n", hex);
        sn_get_stats(det.inst, &st);
        printf("blended steps: %" PRIu32 " saturations: %" PRIu32 "\n", st.steps, st.saturations);
    }
    free(ws); free(mem); free(blob); free(clip_text);
    return 0;
}
