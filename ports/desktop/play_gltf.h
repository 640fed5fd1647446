/* play_gltf.h -- sinew-play's glTF side (issue 17 items 3-4): a glTF
 * animation as clip text (--gltf-anim) and the simulated surface written as
 * a .glb with one morph target per recorded frame (--out-gltf). Uses the host
 * tool's glTF reader (tools/sb_gltf*.c, sb_json.c). */
#ifndef PLAY_GLTF_H
#define PLAY_GLTF_H
#include <stddef.h>
#include <stdint.h>

/* FILE[:NAME] -> clip text (ports/common/CLIP.md), malloc'd, keyed at every
 * step of the clip clock (hq: the blob's timestep, Q16.16 s); NULL and err on
 * failure. Warnings (ignored scale channels, bone translations) go to
 * stderr; the summary line only unless quiet. */
char *pg_anim_clip(const char *spec, int32_t hq, int loop, int quiet, char *err, size_t errlen);

typedef struct pg_out {
    char path[4096];
    uint32_t nv, nt;          /* runtime surface */
    const uint32_t *tri;
    uint32_t frames, done;    /* recorded frames after the base one */
    double dt;                /* seconds between recorded frames */
    float *pos;               /* (frames + 1) x nv x 3, model space */
    /* the glTF vertex order (BLOB.gltfmap), if found */
    int have_map;
    uint32_t nsrc, nsrc_tri;
    uint32_t *to_surf, *src_tri;
    double root[3];
    char map_path[4200];
} pg_out;
/* frames: recorded frames after the base one (the state before the first step). */
int pg_out_begin(pg_out *g, const char *path, const char *blob_path, uint32_t nv, const uint32_t *tri, uint32_t nt,
                 uint32_t frames, double dt, char *err, size_t errlen);
/* the base frame first, then each recorded frame: nv x 3 floats, model space */
void pg_out_frame(pg_out *g, const float *pos);
/* write the .glb; 0 or -1 (err). Frees g either way. */
int pg_out_end(pg_out *g, size_t *bytes, char *err, size_t errlen);
void pg_out_free(pg_out *g);
#endif
