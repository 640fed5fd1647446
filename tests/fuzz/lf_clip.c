/* lf_clip.c -- libFuzzer harness: the clip parser and sampler shared by every
 * player (ports/common/sn_clip.c, sn_clip_pose.c; format CLIP.md), with the
 * fixed runtime compiled in (tests/fuzz/fuzz.mk: fuzz_clip).
 *
 * Each input is clip text, handed over in an exact-size buffer without a NUL
 * (the parser takes a length), so ASan sees any read past it. A clip that
 * parses is checked for the parser's promises (error text NUL-terminated,
 * channels and keys within their arrays, key times strictly increasing and in
 * [0, duration]) and its warnings are formatted; then it is sampled: bound to
 * the blob named by env SN_LF_BLOB (a fixed blob, e.g. build/examples/cow.blob;
 * the fuzz scripts set it) -- when a joint name is not in the blob, channel c
 * is bound to joint c mod joints by hand so unknown names still reach the
 * sampler -- and posed at step times around every key and at the extremes of
 * the time arithmetic (h = 1 LSB and h = 2^31 - 1 LSB, steps up to 2^32 - 1).
 */
#include "lf_common.h"
#include "sinew.h"
#include "sn_clip.h"

static void *g_blob_bytes;
static const sn_blob *g_blob;
static sn_blob_info g_info;
static sn_clip g_clip; /* ~23 KB: static, not on the stack */

static void load_blob(void) {
    const char *path = getenv("SN_LF_BLOB");
    FILE *f;
    long n;
    if (!path || !*path || !(f = fopen(path, "rb"))) return;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    g_blob_bytes = n > 0 ? malloc((size_t)n) : NULL;
    if (g_blob_bytes && fread(g_blob_bytes, 1, (size_t)n, f) == (size_t)n &&
        sn_blob_validate(g_blob_bytes, (size_t)n, &g_blob) == SN_OK)
        sn_blob_get_info(g_blob, &g_info);
    else
        g_blob = NULL;
    fclose(f);
    if (!g_blob) fprintf(stderr, "lf_clip: %s is not a valid fixed blob: clips are parsed, not sampled\n", path);
}

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv) {
    (void)argc; (void)argv;
    load_blob();
    return 0;
}

static void sample(sn_clip *clip) {
    static sn_quat local[256];
    static sn_xform xf[256];
    sn_vec3 root;
    char err[SN_CLIP_ERR_LEN];
    uint32_t c, k;
    int32_t h = sn_clip_timestep_q16(g_blob);
    static const uint32_t steps[] = {0, 1, 2, 7, 60, 1000, 65535, 0x7FFFFFFFu, 0xFFFFFFFFu};
    if (sn_clip_bind(clip, g_blob, err, sizeof err)) {
        LF_REQUIRE(memchr(err, 0, sizeof err) != NULL, "bind error text not NUL-terminated");
        for (c = 0; c < clip->n_channels; c++)
            clip->chan[c].joint = clip->chan[c].kind == SN_CLIP_MOVE ? 0 : (int32_t)(c % g_info.joints);
        clip->bound = 1;
    }
    for (k = 0; k < sizeof steps / sizeof steps[0]; k++) {
        int32_t t;
        sn_clip_pose(clip, g_blob, steps[k], local, xf);
        t = sn_clip_time(clip, 1, steps[k]);
        LF_REQUIRE(t >= 0 && t <= clip->duration, "clip time %d outside [0, %d] (h = 1 LSB)", t, clip->duration);
        t = sn_clip_time(clip, 0x7FFFFFFF, steps[k]);
        LF_REQUIRE(t >= 0 && t <= clip->duration, "clip time %d outside [0, %d] (h = 2^31 - 1 LSB)", t, clip->duration);
        t = sn_clip_time(clip, h, steps[k]);
        sn_clip_sample(clip, g_blob, t, local, &root);
    }
    /* every key time, one LSB either side, and the ends */
    for (k = 0; k < clip->n_keys; k++) {
        int32_t t = clip->keys[k].t;
        sn_clip_sample(clip, g_blob, t, local, &root);
        if (t > 0) sn_clip_sample(clip, g_blob, t - 1, local, &root);
        if (t < clip->duration) sn_clip_sample(clip, g_blob, t + 1, local, &root);
    }
    {   /* collider and pin channels: placements and targets at every step above */
        static sn_collider cl[SN_CLIP_MAX_CHANNELS];
        static sn_constraint cs[SN_CLIP_MAX_CHANNELS];
        static sn_clip_hold hold[SN_CLIP_MAX_CHANNELS];
        memset(hold, 0, sizeof hold);
        for (k = 0; k < sizeof steps / sizeof steps[0]; k++) {
            uint32_t n = sn_clip_colliders(clip, g_blob, steps[k], cl, SN_CLIP_MAX_CHANNELS);
            LF_REQUIRE(n <= clip->n_colliders, "%u colliders from %u channels", n, clip->n_colliders);
            n = sn_clip_constraints(clip, g_blob, steps[k], NULL, hold, cs, SN_CLIP_MAX_CHANNELS);
            LF_REQUIRE(n <= clip->n_pins, "%u constraints from %u channels", n, clip->n_pins);
        }
    }
    sn_clip_sample(clip, g_blob, -1, local, &root);
    sn_clip_sample(clip, g_blob, clip->duration, local, &root);
    sn_clip_sample(clip, g_blob, 0x7FFFFFFF, local, &root);
    sn_pose_from_local(g_blob, local, &root, xf);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char err[SN_CLIP_ERR_LEN], *text = (char *)malloc(size ? size : 1);
    uint32_t c, k;
    if (!text) return 0;
    if (size) memcpy(text, data, size);
    memset(err, 'x', sizeof err);
    if (sn_clip_parse(&g_clip, text, size, err, sizeof err)) {
        LF_REQUIRE(memchr(err, 0, sizeof err) != NULL, "parse error text not NUL-terminated");
        free(text);
        return 0;
    }
    LF_REQUIRE(g_clip.duration > 0, "parsed clip with duration %d", g_clip.duration);
    LF_REQUIRE(g_clip.n_channels <= SN_CLIP_MAX_CHANNELS && g_clip.n_keys <= SN_CLIP_MAX_KEYS, "counts %u %u",
               g_clip.n_channels, g_clip.n_keys);
    for (c = 0; c < g_clip.n_channels; c++) {
        const sn_clip_channel *ch = &g_clip.chan[c];
        LF_REQUIRE((uint32_t)ch->first + ch->count <= g_clip.n_keys, "channel %u keys [%u, +%u) past %u", c, ch->first,
                   ch->count, g_clip.n_keys);
        LF_REQUIRE(memchr(ch->name, 0, sizeof ch->name) != NULL, "channel %u name not NUL-terminated", c);
        for (k = 0; k < ch->count; k++) {
            int32_t t = g_clip.keys[ch->first + k].t;
            LF_REQUIRE(t >= 0 && t <= g_clip.duration, "key time %d outside [0, %d]", t, g_clip.duration);
            if (k) LF_REQUIRE(t > g_clip.keys[ch->first + k - 1].t, "key times of channel %u not increasing", c);
        }
    }
    for (k = 0; k <= g_clip.n_warnings && k <= SN_CLIP_MAX_WARNINGS; k++) {
        size_t n = sn_clip_warning_str(&g_clip, k, err, sizeof err);
        LF_REQUIRE(n < sizeof err && memchr(err, 0, sizeof err) != NULL, "warning text %u not NUL-terminated", k);
    }
    if (g_blob) sample(&g_clip);
    free(text);
    return 0;
}
