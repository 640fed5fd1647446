/* play_gltf.c -- see play_gltf.h. Output layout (--out-gltf, documented in
 * ports/common/CLIP.md "glTF in and out"): one node, one mesh, one triangle
 * primitive whose POSITION is the surface before the first step (the base)
 * and one morph target per recorded frame (POSITION displacement from the
 * base, named frame_NNNN in mesh.extras.targetNames), driven by one
 * animation "sinew" on the node's weights: at time 0 every weight is 0, at
 * the time of recorded frame i weight i is 1 and the others 0, LINEAR
 * between (so playback blends consecutive frames). Blender imports the
 * targets as shape keys and the weights as their animation. With the bake's
 * BLOB.gltfmap beside the blob, the vertices and triangles are the original
 * glTF's (every glTF vertex takes its welded surface vertex's position) and
 * positions are moved back into the glTF's frame (the root joint's rest
 * position added); otherwise the runtime's surface in model space. The mesh
 * is skinned to one identity joint (sinew_root, every weight on it) so that
 * skinned-mesh readers, ours included (sb_gltf_load), read it as they read
 * the input. */
#include "play_gltf.h"
#include "png.h"
#include "sb.h"
#include "sb_gltf.h"
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

char *pg_anim_clip(const char *spec, int32_t hq, int loop, int quiet, char *err, size_t errlen)
{
    char file[4096], *colon, *text;
    const char *name = NULL;
    sb_gltf g;
    sb_gltf_anim a;
    snprintf(file, sizeof file, "%s", spec);
    colon = strrchr(file, ':');
    if (colon && (strstr(colon, ".gltf") == NULL && strstr(colon, ".glb") == NULL)) *colon = '\0', name = colon + 1;
    if (sb_gltf_load(&g, file, NULL)) { snprintf(err, errlen, "%s", sb_error()); return NULL; }
    if (sb_gltf_anim_load(&a, file, &g, name, hq / 65536.0, 20000)) {   /* 20000 steps: 5.5 min at 60 Hz */
        snprintf(err, errlen, "%s", sb_error());
        sb_gltf_free(&g);
        return NULL;
    }
    {   /* warnings also under --quiet (the player's rule) */
        int k, n = 0;
        for (k = 0; k < a.nj; k++) n += a.animated[k];
        if (!quiet)
            fprintf(stderr, "sinew-play: %s: animation %d \"%s\": %.3f s, %d channel(s) on %d of %d skin joints\n", file, a.index,
                    a.name, a.end, a.n_channels, n, a.nj);
        if (a.n_scale_active)
            fprintf(stderr, "sinew-play: warning: %s: %d scale channel(s) that scale ignored (Sinew bones do not scale)\n", file, a.n_scale_active);
        else if (a.n_scale && !quiet)
            fprintf(stderr, "sinew-play: %s: %d scale channel(s) keying only 1 ignored\n", file, a.n_scale);
        if (a.n_other) fprintf(stderr, "sinew-play: warning: %s: %d channel(s) on morph weights or extensions ignored\n", file, a.n_other);
        if (a.bone_gap > 1e-4)
            fprintf(stderr, "sinew-play: warning: %s: joints below the root translated by up to %.4g units: ignored "
                    "(Sinew bones are rigid; only the root translates)\n", file, a.bone_gap);
    }
    text = sb_gltf_anim_clip(&a, &g, hq, loop, file);
    if (!text) snprintf(err, errlen, "%s: %s", file, sb_error());
    sb_gltf_anim_free(&a);
    sb_gltf_free(&g);
    return text;
}

void pg_out_free(pg_out *g)
{
    free(g->pos), free(g->to_surf), free(g->src_tri);
    memset(g, 0, sizeof *g);
}

/* BLOB.gltfmap (tools/DESCRIPTION.md): 0 read, 1 absent, -1 bad */
static int read_map(pg_out *g, const char *blob_path, char *err, size_t errlen)
{
    FILE *f;
    char line[4300];
    unsigned nsrc, nsurf, nprim, ntri, drop, v = 0, t = 0;
    snprintf(g->map_path, sizeof g->map_path, "%s.gltfmap", blob_path);
    if (!(f = fopen(g->map_path, "r"))) return 1;
    if (!fgets(line, sizeof line, f) || strncmp(line, "sinew-gltf-map 1", 16)) goto bad;
    while (fgets(line, sizeof line, f)) {
        unsigned a, b, c;
        if (!strncmp(line, "counts ", 7)) {
            if (sscanf(line + 7, "%u %u %u %u %u", &nsrc, &nsurf, &nprim, &ntri, &drop) != 5 || nsurf != g->nv || nsrc > 50000000u ||
                ntri > 50000000u)
                goto bad;
            g->nsrc = nsrc, g->nsrc_tri = ntri;
            g->to_surf = calloc((size_t)nsrc + 1, sizeof *g->to_surf);
            g->src_tri = calloc(3 * (size_t)ntri + 1, sizeof *g->src_tri);
            if (!g->to_surf || !g->src_tri) goto bad;
        } else if (!strncmp(line, "root ", 5)) {
            if (sscanf(line + 5, "%lf %lf %lf", &g->root[0], &g->root[1], &g->root[2]) != 3) goto bad;
        } else if (line[0] == 'v' && line[1] == ' ') {
            if (!g->to_surf || v >= g->nsrc || sscanf(line + 2, "%u %u %u", &a, &b, &c) != 3 || c >= g->nv) goto bad;
            g->to_surf[v++] = c;
        } else if (line[0] == 't' && line[1] == ' ') {
            if (!g->src_tri || t >= g->nsrc_tri || sscanf(line + 2, "%u %u %u", &a, &b, &c) != 3 || a >= g->nsrc || b >= g->nsrc || c >= g->nsrc)
                goto bad;
            g->src_tri[3 * t] = a, g->src_tri[3 * t + 1] = b, g->src_tri[3 * t + 2] = c;
            t++;
        }
    }
    fclose(f);
    if (!g->to_surf || v != g->nsrc || t != g->nsrc_tri) goto bad2;
    g->have_map = 1;
    return 0;
bad:
    fclose(f);
bad2:
    snprintf(err, errlen, "%s: not a glTF vertex map for this blob (%u surface vertices)", g->map_path, (unsigned)g->nv);
    return -1;
}

int pg_out_begin(pg_out *g, const char *path, const char *blob_path, uint32_t nv, const uint32_t *tri, uint32_t nt,
                 uint32_t frames, double dt, char *err, size_t errlen)
{
    memset(g, 0, sizeof *g);
    snprintf(g->path, sizeof g->path, "%s", path);
    g->nv = nv, g->tri = tri, g->nt = nt, g->frames = frames, g->dt = dt;
    if (frames < 1 || frames > 1000) { snprintf(err, errlen, "%s: %u frames (1..1000)", path, (unsigned)frames); return -1; }
    if (read_map(g, blob_path, err, errlen) < 0) { pg_out_free(g); return -1; }
    g->pos = malloc(((size_t)frames + 1) * nv * 3 * sizeof *g->pos);
    if (!g->pos) { snprintf(err, errlen, "%s: out of memory", path); pg_out_free(g); return -1; }
    return 0;
}

void pg_out_frame(pg_out *g, const float *pos)
{
    if (g->done > g->frames) return;
    memcpy(g->pos + (size_t)g->done * g->nv * 3, pos, (size_t)g->nv * 3 * sizeof *pos);
    g->done++;
}

typedef struct { char *p; size_t n, cap; } sbuf;
static void put(sbuf *b, const char *fmt, ...)
{
    va_list ap;
    int n;
    for (;;) {
        va_start(ap, fmt);
        n = vsnprintf(b->p ? b->p + b->n : NULL, b->p ? b->cap - b->n : 0, fmt, ap);
        va_end(ap);
        if (b->p && n >= 0 && (size_t)n < b->cap - b->n) { b->n += (size_t)n; return; }
        b->cap = 2 * b->cap + (size_t)(n > 0 ? n : 64) + 256;
        b->p = realloc(b->p, b->cap);
        if (!b->p) { fprintf(stderr, "sinew-play: out of memory\n"); exit(1); }
    }
}

static void le32(unsigned char *p, uint32_t v) { p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8), p[2] = (unsigned char)(v >> 16), p[3] = (unsigned char)(v >> 24); }
static void putf(unsigned char *p, float f) { uint32_t u; memcpy(&u, &f, 4); le32(p, u); }

int pg_out_end(pg_out *g, size_t *bytes, char *err, size_t errlen)
{
    uint32_t nvo = g->have_map ? g->nsrc : g->nv, nto = g->have_map ? g->nsrc_tri : g->nt, F = g->frames, f, v, c, i;
    size_t off_idx = 0, off_pos, off_jw, off_tgt, off_time, off_w, len, jlen, total;
    unsigned char *bin, *glb;
    float *lo, *hi;
    sbuf j = {NULL, 0, 0};
    int rc;
    if (g->done != F + 1) { snprintf(err, errlen, "%s: %u of %u frames recorded", g->path, (unsigned)g->done, (unsigned)F + 1); pg_out_free(g); return -1; }
    off_pos = off_idx + 12 * (size_t)nto;
    off_jw = off_pos + 12 * (size_t)nvo;   /* JOINTS_0 (u8 x 4, all joint 0) then WEIGHTS_0 (float x 4, 1 0 0 0) */
    off_tgt = off_jw + 20 * (size_t)nvo;
    off_time = off_tgt + 12 * (size_t)nvo * F;
    off_w = off_time + 4 * ((size_t)F + 1);
    len = off_w + 4 * ((size_t)F + 1) * F;
    bin = calloc(len + 4, 1);
    lo = malloc(((size_t)F + 1) * 3 * sizeof *lo);
    hi = malloc(((size_t)F + 1) * 3 * sizeof *hi);
    if (!bin || !lo || !hi) { free(bin), free(lo), free(hi); snprintf(err, errlen, "%s: out of memory", g->path); pg_out_free(g); return -1; }
    for (i = 0; i < nto; i++)
        for (c = 0; c < 3; c++) le32(bin + off_idx + 12 * (size_t)i + 4 * c, g->have_map ? g->src_tri[3 * i + c] : g->tri[3 * i + c]);
    for (f = 0; f <= F; f++) {   /* f = 0: base positions; f >= 1: target f-1 = frame f - base */
        const float *P = g->pos + (size_t)f * g->nv * 3, *B = g->pos;
        unsigned char *dst = f == 0 ? bin + off_pos : bin + off_tgt + 12 * (size_t)nvo * (f - 1);
        for (c = 0; c < 3; c++) lo[3 * f + c] = HUGE_VALF, hi[3 * f + c] = -HUGE_VALF;
        for (v = 0; v < nvo; v++) {
            uint32_t s = g->have_map ? g->to_surf[v] : v;
            for (c = 0; c < 3; c++) {
                float x = f == 0 ? (float)(P[3 * s + c] + g->root[c]) : P[3 * s + c] - B[3 * s + c];
                putf(dst + 12 * (size_t)v + 4 * c, x);
                if (x < lo[3 * f + c]) lo[3 * f + c] = x;
                if (x > hi[3 * f + c]) hi[3 * f + c] = x;
            }
        }
    }
    for (v = 0; v < nvo; v++) putf(bin + off_jw + 4 * (size_t)nvo + 16 * (size_t)v, 1.0f);
    for (f = 0; f <= F; f++) {
        putf(bin + off_time + 4 * (size_t)f, (float)(f * g->dt));
        for (i = 0; i < F; i++) putf(bin + off_w + 4 * ((size_t)f * F + i), f >= 1 && i == f - 1 ? 1.0f : 0.0f);
    }
    put(&j, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"sinew-play --out-gltf\"},\"scene\":0,\n");
    put(&j, "\"nodes\":[{\"name\":\"sinew_surface\",\"mesh\":0,\"skin\":0},{\"name\":\"sinew_root\"}],\n");
    put(&j, "\"scenes\":[{\"nodes\":[0,1]}],\"skins\":[{\"joints\":[1]}],\n");
    put(&j, "\"meshes\":[{\"name\":\"sinew_surface\",\"primitives\":[{\"attributes\":{\"POSITION\":1,\"JOINTS_0\":%u,\"WEIGHTS_0\":%u},"
            "\"indices\":0,\"mode\":4,\"targets\":[", 4 + F, 5 + F);
    for (i = 0; i < F; i++) put(&j, "%s{\"POSITION\":%u}", i ? "," : "", 2 + i);
    put(&j, "]}],\"weights\":[");
    for (i = 0; i < F; i++) put(&j, "%s0", i ? "," : "");
    put(&j, "],\"extras\":{\"targetNames\":[");
    for (i = 0; i < F; i++) put(&j, "%s\"frame_%04u\"", i ? "," : "", i + 1);
    put(&j, "]}}],\n\"animations\":[{\"name\":\"sinew\",\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"weights\"}}],"
            "\"samplers\":[{\"input\":%u,\"output\":%u,\"interpolation\":\"LINEAR\"}]}],\n", 2 + F, 3 + F);
    put(&j, "\"accessors\":[{\"bufferView\":0,\"componentType\":5125,\"count\":%u,\"type\":\"SCALAR\"},\n", 3 * nto);
    for (f = 0; f <= F; f++)
        put(&j, "{\"bufferView\":%d,\"byteOffset\":%lu,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\",\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},\n",
            f ? 2 : 1, f ? (unsigned long)(12 * (size_t)nvo * (f - 1)) : 0UL, nvo, lo[3 * f], lo[3 * f + 1], lo[3 * f + 2], hi[3 * f],
            hi[3 * f + 1], hi[3 * f + 2]);
    put(&j, "{\"bufferView\":3,\"componentType\":5126,\"count\":%u,\"type\":\"SCALAR\",\"min\":[0],\"max\":[%.9g]},\n", F + 1, (double)(float)(F * g->dt));
    put(&j, "{\"bufferView\":4,\"componentType\":5126,\"count\":%lu,\"type\":\"SCALAR\"},\n", (unsigned long)((size_t)(F + 1) * F));
    put(&j, "{\"bufferView\":5,\"componentType\":5121,\"count\":%u,\"type\":\"VEC4\"},\n", nvo);
    put(&j, "{\"bufferView\":5,\"byteOffset\":%lu,\"componentType\":5126,\"count\":%u,\"type\":\"VEC4\"}],\n", (unsigned long)(4 * (size_t)nvo), nvo);
    put(&j, "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu,\"target\":34963},"
            "{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu,\"target\":34962},{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu,\"target\":34962},"
            "{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu},{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu},"
            "{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu}],\n",
            (unsigned long)off_idx, (unsigned long)(off_pos - off_idx), (unsigned long)off_pos, (unsigned long)(off_tgt - off_pos),
            (unsigned long)off_tgt, (unsigned long)(off_time - off_tgt), (unsigned long)off_time, (unsigned long)(off_w - off_time),
            (unsigned long)off_w, (unsigned long)(len - off_w), (unsigned long)off_jw, (unsigned long)(off_tgt - off_jw));
    put(&j, "\"buffers\":[{\"byteLength\":%lu}]}", (unsigned long)len);
    while (j.n % 4) put(&j, " ");
    jlen = j.n;
    total = 12 + 8 + jlen + 8 + len;
    glb = malloc(total);
    if (!glb) { free(bin), free(lo), free(hi), free(j.p); snprintf(err, errlen, "%s: out of memory", g->path); pg_out_free(g); return -1; }
    memcpy(glb, "glTF", 4), le32(glb + 4, 2), le32(glb + 8, (uint32_t)total);
    le32(glb + 12, (uint32_t)jlen), memcpy(glb + 16, "JSON", 4), memcpy(glb + 20, j.p, jlen);
    le32(glb + 20 + jlen, (uint32_t)len), memcpy(glb + 24 + jlen, "BIN\0", 4), memcpy(glb + 28 + jlen, bin, len);
    rc = write_file_atomic(g->path, glb, total, err, errlen);
    if (bytes) *bytes = total;
    free(glb), free(bin), free(lo), free(hi), free(j.p);
    pg_out_free(g);
    return rc;
}
