/* herd.c -- many instances on one core (issue 15 item 5): 1, 10, 100 cows
 * sharing one read-only blob, each with its own instance, stepped one after
 * another as a game steps a herd. Prints the per-cow step cost for each
 * herd size and the working set (N instances + the shared blob) against
 * the caches, so the scaling with the cache shows.
 *
 *   sn_herd blob [--rounds R] [--own] [N ...]   default herd sizes 1 10 100
 *
 * The cows keep only their persistent state (sn_instance_init_shared) and
 * borrow one workspace for the step's scratch (sn_step_with), as a game's
 * worker thread would: the working set is N states + one workspace + the
 * blob. --own gives each cow its whole instance (sn_instance_init, sn_step)
 * instead, for comparison. The herd hash is the same either way.
 *
 * Each cow is posed with its own phase of the bench's pose sequence (the
 * same sn_pose_from_local path as bench.c), so no two states are alike.
 * Timed per round (thread CPU time): sn_set_pose + sn_step of every cow
 * (the poses are computed before the clock starts). Figures, never a
 * pass/fail on speed. For cache-miss counts that do not depend on the
 * machine's load: valgrind --tool=cachegrind sn_herd blob --rounds 3 N.
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "sinew.h"
#include "bench_common.h" /* FLAV, LEN, DEG, bench_load, bench_cmp_d, bench_pose */

/* thread CPU time: on a shared machine a round of 100 cows spans many
 * scheduler slices, and wall time would charge the other processes' slices
 * to the herd (the single cow's 0.5 ms mostly fits in one); CPU time keeps
 * what other processes do to the caches, which is real */
static double now(void) {
    struct timespec t;
#if defined(CLOCK_THREAD_CPUTIME_ID)
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
#else
    clock_gettime(CLOCK_MONOTONIC, &t);
#endif
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* data cache sizes (glibc sysconf; 0 where unknown) */
static long cache_bytes(int level) {
#if defined(_SC_LEVEL1_DCACHE_SIZE) && defined(_SC_LEVEL2_CACHE_SIZE) && defined(_SC_LEVEL3_CACHE_SIZE)
    long v = sysconf(level == 1 ? _SC_LEVEL1_DCACHE_SIZE : level == 2 ? _SC_LEVEL2_CACHE_SIZE : _SC_LEVEL3_CACHE_SIZE);
    return v > 0 ? v : 0;
#else
    (void)level;
    return 0;
#endif
}

static int fixed_rounds = 0; /* --rounds R: R rounds, no warm-up (for cachegrind) */
static int own = 0;          /* --own: each cow its own scratch */

static int herd(const sn_blob *blob, const sn_blob_info *info, size_t blob_bytes, int n, double *base) {
    size_t need = own ? sn_instance_size(blob) : sn_instance_state_size(blob);
    size_t wsb = own ? 0 : sn_workspace_size(blob, SN_MODE_WARPED);
    void *ws = wsb ? malloc(wsb) : NULL; /* malloc: aligned for any type, so 8 */
    int rounds = n >= 100 ? 12 : (n >= 10 ? 60 : 400), warm = n >= 100 ? 2 : 10;
    if (fixed_rounds > 0) { rounds = fixed_rounds; warm = 0; }
    int budget_rounds = rounds + warm, r, c;
    void **mem = (void **)calloc((size_t)n, sizeof *mem);
    sn_instance **inst = (sn_instance **)calloc((size_t)n, sizeof *inst);
    sn_xform *xf = (sn_xform *)malloc(sizeof *xf * info->joints * (size_t)n);
    sn_quat *local = (sn_quat *)malloc(sizeof *local * info->joints);
    double *ts = (double *)malloc(sizeof *ts * (size_t)budget_rounds), med;
    unsigned long long hx = 0;
    if (!mem || !inst || !xf || !local || !ts || (wsb && !ws)) return 2;
    for (c = 0; c < n; c++) {
        if (!(mem[c] = malloc(need))) return 2;
        if ((own ? sn_instance_init(mem[c], need, blob, &inst[c])
                 : sn_instance_init_shared(mem[c], need, blob, &inst[c])) != SN_OK) return 1;
    }
    for (r = 0; r < budget_rounds; r++) {
        double t0;
        for (c = 0; c < n; c++) /* each cow its own phase: 0.37 s apart */
            bench_pose(blob, info->joints, r / 60.0 + 0.37 * c, local, xf + (size_t)c * info->joints);
        t0 = now();
        for (c = 0; c < n; c++) {
            sn_set_pose(inst[c], xf + (size_t)c * info->joints, info->joints);
            sn_step_with(inst[c], ws, wsb); /* --own: sn_step */
        }
        ts[r] = (now() - t0) / n;
    }
    qsort(ts + warm, (size_t)rounds, sizeof *ts, bench_cmp_d);
    med = ts[warm + rounds / 2];
    if (n == 1 || *base <= 0) *base = med;
    for (c = 0; c < n; c++) hx ^= (unsigned long long)sn_state_hash(inst[c]) * (unsigned long long)(2 * c + 1);
    printf("  figure: %s herd of %3d cows: median %.1f us CPU per cow step (min %.1f), %.2fx the single cow; "
           "working set %lu KiB (%d x %lu B %s + %lu B workspace + %lu B shared blob); %d rounds, herd hash %016llx\n",
           FLAV, n, 1e6 * med, 1e6 * ts[warm], med / *base,
           (unsigned long)(((size_t)n * need + wsb + blob_bytes) / 1024), n, (unsigned long)need,
           own ? "instances" : "states", (unsigned long)wsb, (unsigned long)blob_bytes, rounds, hx);
    for (c = 0; c < n; c++) free(mem[c]);
    free(mem); free(inst); free(xf); free(local); free(ts); free(ws);
    return 0;
}

int main(int argc, char **argv) {
    size_t size;
    unsigned char *bytes;
    const sn_blob *blob;
    sn_blob_info info;
    int i, rc = 0, any = 0;
    double base = 0;
    static const int def[3] = {1, 10, 100};
    if (argc < 2) { fprintf(stderr, "usage: sn_herd blob [--rounds R] [--own] [N ...]\n"); return 2; }
    if (!(bytes = bench_load(argv[1], &size))) { fprintf(stderr, "sn_herd: cannot read %s\n", argv[1]); return 1; }
    if (sn_blob_validate(bytes, size, &blob) != SN_OK) { fprintf(stderr, "sn_herd: %s: invalid blob\n", argv[1]); return 1; }
    sn_blob_get_info(blob, &info);
    for (i = 2; i < argc; i++) own |= strcmp(argv[i], "--own") == 0;
    printf("  herd: %s (%s), %s; instance %lu B with its own scratch, or %lu B of persistent state per cow "
           "+ one %lu B workspace; blob %lu B; data caches:", argv[1], FLAV,
           own ? "own scratch per cow (--own)" : "one shared workspace",
           (unsigned long)sn_instance_size(blob), (unsigned long)sn_instance_state_size(blob),
           (unsigned long)sn_workspace_size(blob, SN_MODE_WARPED), (unsigned long)size);
    for (i = 1; i <= 3; i++) {
        long b = cache_bytes(i);
        if (b > 0) { printf(" L%d %ld KiB", i, b / 1024); any = 1; }
    }
    printf("%s\n", any ? "" : " unknown");
    for (i = 2; i < argc; i++) {
        if (strcmp(argv[i], "--rounds") == 0 && i + 1 < argc) { fixed_rounds = atoi(argv[++i]); continue; }
        if (strcmp(argv[i], "--own") == 0) continue;
        rc |= herd(blob, &info, size, atoi(argv[i]), &base);
        any = 2;
    }
    if (any != 2) for (i = 0; i < 3; i++) rc |= herd(blob, &info, size, def[i], &base);
    free(bytes);
    return rc;
}
