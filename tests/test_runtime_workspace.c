/* test_runtime_workspace.c -- the shared workspace (sn_instance_init_shared,
 * sn_step_with; issue 15 items 4-5): an instance whose memory is only its
 * persistent state, stepped with scratch borrowed from a workspace that any
 * number of instances share.
 *
 *   usage: test_runtime_workspace   (blobs from $BUILD, clips from tools/examples)
 *
 * The reference is the instance with its own scratch (sn_instance_init,
 * sn_step), whose hashes tests/expected_hashes.txt pins: the shared instance
 * must give the same sn_state_hash after every phase, on the cow's trot with
 * and without constraints and contact (ports/cross/sn_det.c's scenarios),
 * in the blended mode, on the limb with crease collision, on the two-level
 * cow across sn_set_lod switches and with adaptation on level 1.
 * Poison: the workspace is filled with a pattern (0xA5, 0x5A, then bytes
 * that change every step) before every step, so a value kept in it from one
 * step to the next, or read before the step wrote it, would change the hash;
 * between steps the shared instance has no workspace at all, so a call that
 * touched scratch outside a step would crash here. Three instances
 * interleaved on one workspace give their alone hashes; guard bytes after
 * the exact-size state and workspace stay intact; a workspace one byte
 * short is refused (SN_ERR_MEMORY) and nothing happens. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sinew.h"
#include "sn_test.h"
#include "sn_det.h"
#include "sn_clip.h"

#if defined(SN_FLOAT)
#define SUF "_float"
#define FL "float"
#else
#define SUF ""
#define FL "fixed"
#endif

#define GUARD 64u
#define GUARD_BYTE 0xEEu

static const char *build_dir(void) {
    const char *b = getenv("BUILD");
    return b && *b ? b : "build";
}

/* One asset: blob bytes and clip text, loaded once. */
typedef struct asset {
    char *blob, *clip;
    size_t nb, nc;
    const char *name;
} asset;

static int asset_load(asset *a, const char *blob_rel, const char *clip, const char *name) {
    char p[512];
    snprintf(p, sizeof p, "%s/%s", build_dir(), blob_rel);
    a->name = name;
    a->blob = t_read_file(p, &a->nb);
    a->clip = t_read_file(clip, &a->nc);
    if (!a->blob || !a->clip) { T_CHECK(0, "cannot read %s or %s (make them: tests/tests.mk)", p, clip); return -1; }
    return 0;
}

/* A driven instance: the determinism driver's poses (sn_det), stepped with its
 * own scratch (shared 0) or with the workspace given to step() (shared 1). */
typedef struct drv {
    sn_det det;
    sn_clip *clip;
    unsigned char *own;  /* sn_det_init's instance (the reference keeps using it) */
    unsigned char *mem;  /* the shared instance's state (+ GUARD bytes) */
    size_t state;
    int shared;
} drv;

static int drv_open(drv *d, const asset *a, int shared) {
    char err[256];
    sn_instance *si;
    size_t own;
    sn_blob_info info;
    const sn_blob *b;
    memset(d, 0, sizeof *d);
    d->shared = shared;
    d->clip = malloc(sizeof *d->clip);
    if (sn_blob_validate(a->blob, a->nb, &b) != SN_OK) { T_CHECK(0, "%s: blob invalid", a->name); return -1; }
    sn_blob_get_info(b, &info);
    own = sn_instance_size_mode(b, SN_MODE_BLENDED); /* the blended scenario needs it */
    d->own = malloc(own);
    if (!d->clip || !d->own || sn_det_init(&d->det, a->blob, a->nb, a->clip, a->nc, d->clip, d->own, own, err, sizeof err)) {
        T_CHECK(0, "%s: %s", a->name, err);
        return -1;
    }
    if (!shared) return 0;
    d->state = sn_instance_state_size(d->det.blob);
    d->mem = malloc(d->state + GUARD);
    if (!d->mem) return -1;
    memset(d->mem, 0x3C, d->state);
    memset(d->mem + d->state, GUARD_BYTE, GUARD);
    if (sn_instance_init_shared(d->mem, d->state, d->det.blob, &si) != SN_OK) { T_CHECK(0, "%s: init_shared", a->name); return -1; }
    d->det.inst = si;
    return 0;
}

static void drv_close(drv *d) {
    free(d->clip); free(d->own); free(d->mem);
}

static int guard_ok(const unsigned char *p, size_t n) {
    size_t i;
    for (i = 0; i < GUARD; i++)
        if (p[n + i] != GUARD_BYTE) return 0;
    return 1;
}

/* The workspace every shared instance of the test borrows (+ GUARD bytes). */
static unsigned char *g_ws;
static size_t g_ws_bytes;
static int g_poison;   /* 0: untouched; 1: 0xA5; 2: 0x5A; 3: a different byte every step */
static uint32_t g_tick;
static int g_step_err;

static void poison(void) {
    uint32_t i;
    g_tick++;
    if (g_poison == 1) memset(g_ws, 0xA5, g_ws_bytes);
    else if (g_poison == 2) memset(g_ws, 0x5A, g_ws_bytes);
    else if (g_poison == 3)
        for (i = 0; i < g_ws_bytes; i++) g_ws[i] = (unsigned char)((i * 2654435761u + g_tick * 40503u) >> 13);
}

static void drv_steps(drv *d, uint32_t n) {
    uint32_t i;
    for (i = 0; i < n; i++) {
        sn_det_pose(&d->det);
        if (d->shared) {
            poison();
            g_step_err += sn_step_with(d->det.inst, g_ws, g_ws_bytes) != SN_OK;
        } else {
            g_step_err += sn_step(d->det.inst) != SN_OK;
        }
        d->det.k++;
    }
}

/* The phases of one asset; hashes after each into h[]. Returns the count. */
enum { PH_TROT, PH_CONTACT, PH_BLENDED, PH_LOD, PH_ADAPT };
static int run_phases(drv *d, const int *phases, int np, uint32_t steps, uint64_t *h) {
    int i;
    for (i = 0; i < np; i++) {
        switch (phases[i]) {
        case PH_TROT: drv_steps(d, steps); break;
        case PH_CONTACT:
            if (!sn_det_contact(&d->det)) { T_CHECK(0, "contact scenario refused"); return i; }
            drv_steps(d, steps);
            break;
        case PH_BLENDED:
            if (!sn_det_blended(&d->det)) { T_CHECK(0, "blended scenario refused"); return i; }
            drv_steps(d, steps / 2);
            (void)sn_set_mode(d->det.inst, SN_MODE_WARPED);
            break;
        case PH_LOD: /* up to the finer level and back, mid-clip */
            T_CHECK(sn_set_lod(d->det.inst, 1) == SN_OK, "sn_set_lod 1");
            drv_steps(d, steps / 4);
            T_CHECK(sn_set_lod(d->det.inst, 0) == SN_OK, "sn_set_lod 0");
            drv_steps(d, steps / 4);
            break;
        case PH_ADAPT: /* level 1 with adaptation choosing its active set; a reset there too */
            T_CHECK(sn_set_lod(d->det.inst, 1) == SN_OK, "sn_set_lod 1 (adapt)");
            T_CHECK(sn_set_adapt(d->det.inst, 1) == SN_OK, "sn_set_adapt 1");
            drv_steps(d, steps / 4);
            {   /* adaptation really ran: part of level 1 out of the solve (its projection uses d and q) */
                sn_stats st;
                sn_get_stats(d->det.inst, &st);
                T_CHECK(st.adapt_on && st.adapt_refines + st.adapt_coarsens > 0, "adaptation ran (refines %u, coarsens %u)",
                        st.adapt_refines, st.adapt_coarsens);
            }
            (void)sn_reset(d->det.inst);
            drv_steps(d, steps / 4);
            T_CHECK(sn_set_adapt(d->det.inst, 0) == SN_OK, "sn_set_adapt 0");
            drv_steps(d, steps / 8);
            break;
        }
        h[i] = sn_state_hash(d->det.inst);
    }
    return np;
}

static const char *phase_name(int p) {
    static const char *n[] = {"trot", "contact", "blended", "lod switches", "adaptation"};
    return n[p];
}

/* Shared vs own scratch, for each poison pattern. */
static void compare(const asset *a, const int *phases, int np, uint32_t steps) {
    uint64_t ref[8], got[8];
    drv r, s;
    int pz, i;
    if (drv_open(&r, a, 0) != 0) return;
    run_phases(&r, phases, np, steps, ref);
    for (pz = 0; pz <= 3; pz++) {
        if (drv_open(&s, a, 1) != 0) { drv_close(&r); return; }
        g_poison = pz;
        g_step_err = 0;
        run_phases(&s, phases, np, steps, got);
        T_CHECK(g_step_err == 0, "%s: sn_step_with refused %d steps", a->name, g_step_err);
        for (i = 0; i < np; i++)
            T_CHECK(got[i] == ref[i], "%s %s, poison %d: shared hash %016llx, own scratch %016llx", a->name,
                    phase_name(phases[i]), pz, (unsigned long long)got[i], (unsigned long long)ref[i]);
        T_CHECK(guard_ok(s.mem, s.state), "%s: guard bytes after the state intact", a->name);
        T_CHECK(guard_ok(g_ws, g_ws_bytes), "%s: guard bytes after the workspace intact", a->name);
        drv_close(&s);
    }
    printf("  %s: %d phases x 4 poison patterns, shared == own scratch\n", a->name, np);
    drv_close(&r);
}

/* Three instances interleaved step by step on the one workspace vs each alone. */
static void interleave(const asset *cow, const asset *limb) {
    const asset *as[3];
    uint64_t alone[3], mixed[3];
    drv d[3];
    uint32_t k, i;
    as[0] = cow; as[1] = cow; as[2] = limb;
    g_poison = 1;
    for (i = 0; i < 3; i++) { /* alone (shared, so the same code path as mixed) */
        if (drv_open(&d[i], as[i], 1) != 0) return;
        if (i == 1) { (void)sn_det_contact(&d[1].det); }
        drv_steps(&d[i], 150);
        alone[i] = sn_state_hash(d[i].det.inst);
        drv_close(&d[i]);
    }
    for (i = 0; i < 3; i++) {
        if (drv_open(&d[i], as[i], 1) != 0) return;
        if (i == 1) { (void)sn_det_contact(&d[1].det); }
    }
    g_poison = 0; /* each leaves its scratch for the next: the worst case for a stale read */
    for (k = 0; k < 150; k++)
        for (i = 0; i < 3; i++) drv_steps(&d[(i + k) % 3], 1);
    for (i = 0; i < 3; i++) {
        mixed[i] = sn_state_hash(d[i].det.inst);
        T_CHECK(mixed[i] == alone[i], "interleaved instance %u: %016llx, alone %016llx", i,
                (unsigned long long)mixed[i], (unsigned long long)alone[i]);
        drv_close(&d[i]);
    }
    {   /* and each alone equals its own-scratch twin */
        drv r;
        if (drv_open(&r, cow, 0) == 0) {
            drv_steps(&r, 150);
            T_CHECK(sn_state_hash(r.det.inst) == alone[0], "cow alone on the workspace == own scratch");
            drv_close(&r);
        }
    }
}

/* Refusals, byte copies, sizes. */
static void api(const asset *cow) {
    drv s, c;
    sn_instance *x;
    unsigned char *ws = g_ws, *mem, *copy;
    size_t need, nb;
    uint64_t h0;
    sn_stats st;
    if (drv_open(&s, cow, 1) != 0) return;
    need = sn_workspace_size(s.det.blob, SN_MODE_WARPED);
    nb = sn_workspace_size(s.det.blob, SN_MODE_BLENDED);
    T_CHECK(need > 0 && nb > need && g_ws_bytes >= nb, "workspace sizes %zu, blended %zu", need, nb);
    T_CHECK(sn_step(s.det.inst) == SN_ERR_MEMORY, "sn_step refuses a shared instance");
    sn_det_pose(&s.det);
    h0 = sn_state_hash(s.det.inst);
    T_CHECK(sn_step_with(s.det.inst, ws, need - 1) == SN_ERR_MEMORY, "a workspace one byte short: SN_ERR_MEMORY");
    T_CHECK(sn_step_with(s.det.inst, NULL, need) == SN_ERR_NULL, "NULL workspace: SN_ERR_NULL");
    T_CHECK(sn_step_with(s.det.inst, ws + 4, need) == SN_ERR_ALIGN, "misaligned workspace: SN_ERR_ALIGN");
    sn_get_stats(s.det.inst, &st);
    T_CHECK(st.steps == 0 && sn_state_hash(s.det.inst) == h0, "nothing happened on a refusal");
    T_CHECK(sn_step_with(s.det.inst, ws, need) == SN_OK, "exactly sn_workspace_size bytes steps");
    T_CHECK(sn_set_mode(s.det.inst, SN_MODE_BLENDED) == SN_OK, "blended mode on a shared instance");
    T_CHECK(sn_step_with(s.det.inst, ws, nb - 1) == SN_ERR_MEMORY, "blended: a workspace one byte short of its size refused");
    T_CHECK(sn_step_with(s.det.inst, ws, nb) == SN_OK, "blended: exactly its size steps");
    (void)sn_set_mode(s.det.inst, SN_MODE_WARPED);
    mem = malloc(s.state);
    T_CHECK(sn_instance_init_shared(mem, s.state - 1, s.det.blob, &x) == SN_ERR_MEMORY, "init_shared: state one byte short");
    T_CHECK(sn_instance_init_shared(mem + 4, s.state, s.det.blob, &x) == SN_ERR_ALIGN, "init_shared: misaligned");
    T_CHECK(sn_instance_init_shared(NULL, s.state, s.det.blob, &x) == SN_ERR_NULL, "init_shared: NULL");
    /* a byte copy of the state is a snapshot: stepped, it follows the original */
    drv_steps(&s, 40);
    copy = malloc(s.state);
    memcpy(copy, s.mem, s.state);
    if (drv_open(&c, cow, 1) == 0) {
        c.det = s.det; /* same poses from here */
        c.det.inst = (sn_instance *)(void *)copy;
        g_poison = 3;
        drv_steps(&s, 60);
        drv_steps(&c, 60);
        T_CHECK(sn_state_hash(c.det.inst) == sn_state_hash(s.det.inst), "a byte copy of the state steps as the original");
        drv_close(&c);
    }
    /* an own-scratch instance ignores the workspace */
    {
        drv r;
        if (drv_open(&r, cow, 0) == 0) {
            T_CHECK(sn_step_with(r.det.inst, NULL, 0) == SN_OK, "sn_instance_init's instance: sn_step_with steps with its own scratch");
            drv_close(&r);
        }
    }
    free(copy); free(mem);
    drv_close(&s);
}

static void figures(const asset *a) {
    const sn_blob *b;
    if (sn_blob_validate(a->blob, a->nb, &b) != SN_OK) return;
    T_FIGURE("%s " FL ": own-scratch instance %zu B; shared: state %zu B + workspace %zu B (blended %zu B)", a->name,
             sn_instance_size(b), sn_instance_state_size(b), sn_workspace_size(b, SN_MODE_WARPED),
             sn_workspace_size(b, SN_MODE_BLENDED));
    T_CHECK(sn_instance_state_size(b) < sn_instance_size(b), "%s: the state is smaller than the whole instance", a->name);
    if (strcmp(a->name, "cow") == 0) /* issue 15's goal: a cow instance within 32 KB (its scratch shared) */
        T_CHECK(sn_instance_state_size(b) <= 32768u, "cow: persistent state %zu B <= 32 KB", sn_instance_state_size(b));
}

int main(void) {
    asset cow, limb, lod, adapt, beast;
    size_t ws = 0;
    const sn_blob *b;
    const asset *all[5];
    int i;
    static const int cow_ph[] = {PH_TROT, PH_CONTACT, PH_BLENDED};
    static const int limb_ph[] = {PH_TROT};
    static const int lod_ph[] = {PH_TROT, PH_LOD, PH_BLENDED};
    static const int adapt_ph[] = {PH_TROT, PH_ADAPT};
    (void)t_seed; /* deterministic: no random inputs */
    if (asset_load(&cow, "examples/cow" SUF ".blob", "tools/examples/cow/trot.clip", "cow") ||
        asset_load(&limb, "examples/limb_crease" SUF ".blob", "tools/examples/limb/crease.clip", "limb_crease") ||
        asset_load(&lod, "level/cow_lod" SUF ".blob", "tools/examples/cow/trot.clip", "cow levels 2") ||
        asset_load(&adapt, "level/cow_adapt" SUF ".blob", "tools/examples/cow/trot.clip", "cow adapt") ||
        asset_load(&beast, "examples/beast" SUF ".blob", "tools/examples/beast/walk.clip", "beast"))
        return T_END();
    all[0] = &cow; all[1] = &limb; all[2] = &lod; all[3] = &adapt; all[4] = &beast;
    for (i = 0; i < 5; i++) { /* one workspace for all: the largest */
        size_t w;
        if (sn_blob_validate(all[i]->blob, all[i]->nb, &b) != SN_OK) continue;
        w = sn_workspace_size(b, SN_MODE_BLENDED);
        ws = w > ws ? w : ws;
        figures(all[i]);
    }
    g_ws = malloc(ws + GUARD + 8);
    g_ws_bytes = ws;
    memset(g_ws + ws, GUARD_BYTE, GUARD);
    compare(&cow, cow_ph, 3, 300);
    compare(&limb, limb_ph, 1, 200);
    compare(&lod, lod_ph, 3, 160);
    compare(&adapt, adapt_ph, 2, 160);
    compare(&beast, cow_ph, 3, 160);   /* the humanoid: a character the scratch sizes were not tuned on */
    interleave(&cow, &limb);
    api(&cow);
    T_CHECK(guard_ok(g_ws, g_ws_bytes), "guard bytes after the workspace intact at the end");
    free(g_ws);
    return T_END();
}
