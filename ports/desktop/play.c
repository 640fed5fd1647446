/* play.c -- sinew-play: desktop player for Sinew blobs.
 * Loads a blob, plays a clip through the runtime, times sn_step, writes OBJ
 * frames and PNG pictures. Same source for the fixed (sinew-play) and the
 * float (sinew-play-float, -DSN_FLOAT) runtime. */
#define _POSIX_C_SOURCE 200809L
#include "sinew.h"
#include "sn_format.h"
#include "sn_clip.h"
#include "play_gltf.h"
#include "raster.h"
#include "png.h"
#include "plot.h"
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>

#ifdef SN_FLOAT
#define PROG "sinew-play-float"
static float F(sn_real v) { return v; }
static double D(sn_real v) { return v; }
static sn_real R(double v) { return (sn_real)v; }
#else
#define PROG "sinew-play"
static float F(sn_real v) { return (float)v / 65536.0f; }
static double D(sn_real v) { return (double)v / 65536.0; }
static sn_real R(double v) { return (sn_real)floor(v * 65536.0 + 0.5); }
#endif

static void usage(FILE *f) {
    fprintf(f,
        "usage: " PROG " BLOB [options]\n"
        "Plays a clip on a baked Sinew character and reports the step time.\n"
        "  --clip CLIP        keyframed skeleton clip (ports/common/CLIP.md); default: rest pose\n");
    fprintf(f,
        "  --gltf-anim FILE[:NAME]  play a glTF 2.0 animation (by name or index; default the first) of the skin\n"
        "                     the blob was baked from: resampled at every step into a clip (CLIP.md \"glTF in and out\")\n"
        "  --gltf-loop yes|no with --gltf-anim: loop (default yes) or hold the end\n"
        "  --clip-out FILE    with --gltf-anim: also write the clip it became\n"
        "  --out-gltf FILE.glb  the simulated surface over the run as glTF: one morph target per recorded frame\n"
        "                     (every step, at most 120; a longer run records every Nth) driven by a weights\n"
        "                     animation; the original glTF's vertex order when BLOB.gltfmap is beside the blob\n"
        "  --apng FILE.png    animated PNG of the run (every step, at most 120 frames; --size, default 320x240)\n");
    fprintf(f,
        "  --control NAME=V   hold abstract rig control NAME at V for the whole run, over the clip's track\n"
        "                     (repeatable; V a decimal as in clips, |V| < 32768)\n"
        "  --rigs on|off      off: every abstract control held at 0, the clip's control tracks ignored\n"
        "                     (pose-driven rigs stay on: bake the description without its rig lines for those)\n"
        "  --frames N         steps to run (default: one clip length, or 60 without a clip)\n"
        "  --ground Y         a ground plane y = Y (mesh units) the surface may not enter (sn_set_colliders);\n"
        "                     model space: relative to the root joint's rest position (the beast's soles at -130.9)\n"
        "  --sphere X,Y,Z,R[@VX,VY,VZ]  a sphere collider (repeatable), moving at V mesh units per second\n"
        "  --pin V[,V..]      pin surface vertices where they are before the first step (sn_set_constraints)\n"
        "  --belt X[,W]       pin (in y and z) the surface vertices within W (default 0.08) of the plane x = X:\n"
        "                     a belt around the body, at most the blob's max_constraints of them, evenly spread\n"
        "  --iterations N     CG iterations per step (1..blob maximum; default: blob's)\n"
        "  --lod K:L[,K:L..]  level of detail L (0 coarse, 1 fine; sn_set_lod) from step K on (blob baked with 'levels 2')\n"
        "  --adapt on|off     adaptation on level 1 (sn_set_adapt; blob baked with 'adapt'): on by default\n"
        "  --details N|all    details 0..N-1 active on the cut level from the first step (sn_details_set; blob baked\n"
        "                     with 'levels 2 cut' and 'details'); all: as many as the blob's A_max allows\n"
        "  --unwarped         global linear FEM (all frames R = I), seed 000 fig. 5 (= --mode unwarped)\n"
        "  --mode M           warped (default), unwarped, or blended: blended local linearization, seed 000 sec. 4.5\n"
        "  --obj-dir DIR      write DIR/frame_NNNN.obj after every step (deformed surface)\n"
        "  --obj-frames LIST  with --obj-dir: only these frames, e.g. 0,10,20-30 (0: before the first step)\n"
        "  --png FILE         picture of the last frame\n"
        "  --sheet FILE       contact sheet: 12 frames over the run, 4x3 grid of 320x240 (or --size) cells\n"
        "  --compare FILE     rest | unwarped | warped at the last frame, side by side\n");
    fprintf(f,
        "  --compare-hits FILE  rest | no hit | hit at the last frame: a second instance steps the clip without its\n"
        "                     impulse lines; with --heat D the hit panel is coloured by its distance from it\n"
        "  --compare-rigs FILE  rest | rigs off | rigs on at the last frame; rigs off = a second instance with\n"
        "                     every abstract control at 0, of --rig-off-blob if given; with --heat D the rigs-on\n"
        "                     panel is coloured by its distance from the rigs-off one (red at D mesh units)\n"
        "  --rig-off-blob B   the same character baked without its rigs (same lattice and surface), for\n"
        "                     the rigs-off panel of --compare-rigs (pose-driven rigs cannot be switched off)\n"
        "  --compare-details FILE  cut level | cut + details | level 1 at the last frame (with --details; two more\n"
        "                     instances: no details, and level 1 from the first step); with --heat D the first two\n"
        "                     panels are coloured by their distance from level 1 (red at D mesh units)\n"
        "  --level1-blob B    the level-1 panel of --compare-details from blob B (same skeleton and surface; its\n"
        "                     level 1 if it has two), for a blob that carries no level 1\n"
        "  --lattice          draw the control lattice (skeleton vertices in red)\n"
        "  --seg-impulse M:N:X,Y,Z[@K]  impulse (newton-seconds, world axes) at node N of segment mesh M\n"
        "                     during step K (default 1); repeatable (at most 16)\n"
        "  --seg-floor Y      floor under the segment meshes at height Y (world mesh units, normal +y)\n"
        "  --segments off     do not draw the segment meshes (drawn over the surface by default)\n"
        "  --heat D           colour the flesh by its distance from rigid skinning (red at D mesh units)\n"
        "  --size WxH         size of --png (default 640x480), of the sheet's cells (320x240), of --plot (800x500)\n"
        "  --view AZ,EL       camera azimuth, elevation in degrees (default 30,15)\n"
        "  --frame-box X0,Y0,Z0,X1,Y1,Z1  box the camera frames, model space (mesh units relative to the root joint;\n"
        "                     default: the skinned surface over the whole run)\n"
        "  --title TEXT       caption on the pictures\n"
        "  --health N         every N steps a line: frame, displacement (cells), energy (J), saturations\n");
    fprintf(f,   /* a second string: C99 compilers need only take 4095 characters in one */
        "  --crease-marks     draw the surface vertices in the crease collision list (seed 003 §3.4) in red\n"
        "  --stats-csv FILE   per step: frame,t_s,disp_cells,energy_J,saturations,bound_steps,limit_clamps,\n"
        "                     then ctl_NAME per rig control (abstract: value; pose: degrees, as measured)\n"
        "  --plot FILE        line plot (PNG) of energy, displacement and the rig controls per step (see also sinew-plot)\n"
        "  --hash             end with 'hash: <16 hex>' (sn_state_hash of the final state)\n"
        "  --quiet            only errors, warnings, timing, health and hash\n"
        "  --help\n"
        "The run ends with a health line (saturations, bound steps, limit clamps, largest displacement and energy).\n"
        "Exit status: 0 ok, 1 bad input or failed output (nothing partial written), 2 usage.\n");
}

static int die(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, PROG ": ");
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return 1;
}

/* Whole file into malloc'd memory (8-byte aligned: malloc's guarantee). */
static void *read_file(const char *path, size_t *n, char *err, size_t errlen) {
    FILE *f;
    long len;
    void *buf;
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "cannot read %s: not a regular file", path); return NULL;
    }
    f = fopen(path, "rb");
    if (!f) { snprintf(err, errlen, "cannot read %s: %s", path, strerror(errno)); return NULL; }
    if (fseek(f, 0, SEEK_END) || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET)) {
        snprintf(err, errlen, "cannot read %s: not a regular file", path); fclose(f); return NULL;
    }
    buf = malloc(len ? (size_t)len : 1);
    if (!buf || fread(buf, 1, (size_t)len, f) != (size_t)len) {
        snprintf(err, errlen, "cannot read %s: %s", path, buf ? "read error" : "out of memory");
        free(buf); fclose(f); return NULL;
    }
    fclose(f);
    *n = (size_t)len;
    return buf;
}

/* Fail early rather than after a long run: can we create a file next to path? */
static int probe_writable(const char *path, char *err, size_t errlen) {
    char tmp[4200];
    FILE *f;
    snprintf(tmp, sizeof tmp, "%s.probe%ld", path, (long)getpid());
    f = fopen(tmp, "wb");
    if (!f) { snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno)); return -1; }
    fclose(f);
    remove(tmp);
    return 0;
}

/* Wall clock; the thread's CPU clock too, which leaves out time the OS gave
 * to other processes (stabler figures on a busy machine). */
static double now_us(clockid_t which) {
    struct timespec ts;
    clock_gettime(which, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}
static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* ---- scene ---- */
typedef struct {
    const sn_blob *blob;
    sn_blob_info info;
    uint32_t *tri;              /* triangles */
    uint32_t *edges, n_edges;   /* lattice cell edges (vertex pairs) */
    sn_vec3 *surf, *latt;       /* scratch outputs */
    float *pos, *lpos;          /* float copies */
    float lo[3], hi[3];         /* skinned surface box over the run (ground at lo[1]) */
    float flo[3], fhi[3];       /* box the camera frames (default: lo, hi plus a margin) */
    float az, el;
    int lattice;
    int marks;                  /* --crease-marks: surface vertices in the crease collision list drawn red */
    uint32_t *cr_list;          /* their indices (scratch) */
    /* rigid skinning by the lattice frames: --heat and the camera's box */
    float heat;                 /* mesh units drawn at full colour; 0 = off */
    float *rest, *skin;         /* lattice rest / skinned positions, model space, mesh units */
    const unsigned char *frames, *cells, *embed;
    float *dev, *col;           /* per lattice vertex (3), per surface vertex (3) */
    const sn_xform *pose;       /* pose of the state being drawn */
    const float *ref;           /* --compare-rigs --heat: colour by the distance from this surface */
    /* segment meshes (seed 004 ch. 3-4): nodes of every mesh, drawn over the surface */
    uint32_t n_sm, n_snodes;
    sn_segment_info *sm;
    sn_vec3 *snode;
    float *spos;                /* n_snodes x 3, mesh m's nodes from sm_first[m] */
    uint32_t *sm_first;
    int segments;               /* draw them */
    /* constraints and colliders to draw */
    int have_ground;
    float ground_y;
    int n_sph;
    float sph[4][4];            /* current centre and radius */
    uint32_t n_pins, *pins;     /* pinned surface vertices */
} scene;

static int cmp_edge(const void *a, const void *b) {
    const uint32_t *x = a, *y = b;
    return x[0] != y[0] ? (x[0] > y[0]) - (x[0] < y[0]) : (x[1] > y[1]) - (x[1] < y[1]);
}

static uint32_t rd_u32(const unsigned char *p) { return p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }

/* Cell edges from the blob's cell section (documented in runtime/BLOB.md);
 * the blob was validated, so the section and its indices are in range. */
static int lattice_edges(scene *s, const unsigned char *bytes) {
    const unsigned char *ent = bytes + SN_H_SECTIONS + SN_SEC_CELLS * SN_SECTION_ENTRY;
    uint32_t off = rd_u32(ent), count = rd_u32(ent + 8), c, n = 0, k, i;
    s->edges = malloc((size_t)count * 12 * 2 * sizeof(uint32_t) + 8);
    if (!s->edges) return -1;
    for (c = 0; c < count; c++) {
        const unsigned char *cell = bytes + off + (size_t)c * SN_ELEM_CELLS;
        for (k = 0; k < 8; k++)
            for (i = 1; i < 8; i <<= 1)
                if (!(k & i)) {
                    uint32_t a = cell[2 * k] | (uint32_t)cell[2 * k + 1] << 8;
                    uint32_t b = cell[2 * (k | i)] | (uint32_t)cell[2 * (k | i) + 1] << 8;
                    s->edges[2 * n] = a < b ? a : b;
                    s->edges[2 * n + 1] = a < b ? b : a;
                    n++;
                }
    }
    qsort(s->edges, n, 2 * sizeof(uint32_t), cmp_edge);
    for (i = 0, k = 0; i < n; i++)
        if (!k || cmp_edge(&s->edges[2 * i], &s->edges[2 * (k - 1)])) {
            s->edges[2 * k] = s->edges[2 * i]; s->edges[2 * k + 1] = s->edges[2 * i + 1]; k++;
        }
    s->n_edges = k;
    return 0;
}

static void fetch(scene *s, const sn_instance *inst) {
    uint32_t i, m;
    for (m = 0; m < s->n_sm; m++) {
        uint32_t f = s->sm_first[m];
        if (sn_get_segment_nodes(inst, m, s->snode + f, 0, s->sm[m].nodes) != SN_OK) continue;
        for (i = f; i < f + s->sm[m].nodes; i++) {
            s->spos[3 * i] = F(s->snode[i].x); s->spos[3 * i + 1] = F(s->snode[i].y); s->spos[3 * i + 2] = F(s->snode[i].z);
        }
    }
    sn_get_surface(inst, s->surf, 0, s->info.surface_vertices);
    for (i = 0; i < s->info.surface_vertices; i++) {
        s->pos[3 * i] = F(s->surf[i].x); s->pos[3 * i + 1] = F(s->surf[i].y); s->pos[3 * i + 2] = F(s->surf[i].z);
    }
    if (s->lattice || s->heat > 0) {
        sn_get_lattice(inst, s->latt, 0, s->info.vertices);
        for (i = 0; i < s->info.vertices; i++) {
            s->lpos[3 * i] = F(s->latt[i].x); s->lpos[3 * i + 1] = F(s->latt[i].y); s->lpos[3 * i + 2] = F(s->latt[i].z);
        }
    }
}

static const float cow_colour[3] = {0.78f, 0.60f, 0.44f};

/* Segment a-b as a thick line: 3x3 copies offset across the view by about a
 * pixel of the (supersampled) picture; faint where the flesh hides it. */
static void thick_line(rs_image *im, const rs_camera *cam, const float *a, const float *b, const uint8_t c[3]) {
    int i, j, k;
    float d = 0.9f / (cam->scale > 0 ? cam->scale : 1.0f), pa[3], pb[3];
    for (i = -1; i <= 1; i++)
        for (j = -1; j <= 1; j++) {
            for (k = 0; k < 3; k++) {
                float o = d * ((float)i * cam->right[k] + (float)j * cam->up[k]);
                pa[k] = a[k] + o; pb[k] = b[k] + o;
            }
            rs_draw_line(im, cam, pa, pb, c, 0.35f);
        }
}

/* Every segment mesh: chains along their nodes, sheets along rows and columns
 * (the finest level, seed 004 fig. 3.7), with a dot per node. */
static void draw_segments(const scene *s, rs_image *im, const rs_camera *cam) {
    static const uint8_t chain_c[3] = {120, 40, 20}, sheet_c[3] = {30, 60, 160}, node_c[3] = {20, 20, 20};
    uint32_t m, i;
    float r = (float)im->w / 700.0f;
    for (m = 0; m < s->n_sm; m++) {
        const float *p = s->spos + 3 * (size_t)s->sm_first[m];
        uint32_t n = s->sm[m].side;
        if (s->sm[m].kind == SN_SEGMENT_CHAIN) {
            for (i = 0; i + 1 < n; i++) thick_line(im, cam, p + 3 * i, p + 3 * (i + 1), chain_c);
        } else {
            for (i = 0; i < n * n; i++) {
                if (i % n + 1 < n) thick_line(im, cam, p + 3 * i, p + 3 * (i + 1), sheet_c);
                if (i / n + 1 < n) thick_line(im, cam, p + 3 * i, p + 3 * (i + n), sheet_c);
            }
        }
        for (i = 0; i < s->sm[m].nodes; i++) rs_draw_dot(im, cam, p + 3 * i, r, node_c);
    }
}

static const unsigned char *section(const unsigned char *bytes, int sec, uint32_t *count) {
    const unsigned char *ent = bytes + SN_H_SECTIONS + (size_t)sec * SN_SECTION_ENTRY;
    if (count) *count = rd_u32(ent + 8);
    return bytes + rd_u32(ent);
}

/* Rest lattice, frames, cells and embedding from the validated blob
 * (runtime/BLOB.md). Reals are little-endian like this host. */
static int skin_setup(scene *s, const unsigned char *bytes) {
    const unsigned char *rest = section(bytes, SN_SEC_REST, NULL);
    float unit = (float)ldexp(1.0, (int)(signed char)bytes[SN_H_LEN_SHIFT]);
    uint32_t i;
    s->frames = section(bytes, SN_SEC_FRAMES, NULL);
    s->cells = section(bytes, SN_SEC_CELLS, NULL);
    s->embed = section(bytes, SN_SEC_EMBED, NULL);
    s->rest = malloc((size_t)s->info.vertices * 3 * sizeof(float));
    s->skin = malloc((size_t)s->info.vertices * 3 * sizeof(float));
    s->dev = malloc((size_t)s->info.vertices * 3 * sizeof(float));
    s->col = malloc(((size_t)s->info.surface_vertices + 1) * 3 * sizeof(float));
    if (!s->rest || !s->skin || !s->dev || !s->col) return -1;
    for (i = 0; i < 3 * s->info.vertices; i++) {
#ifdef SN_FLOAT
        float v;
        memcpy(&v, rest + 4 * (size_t)i, 4);
        s->rest[i] = v * unit;
#else
        int32_t v;
        memcpy(&v, rest + 4 * (size_t)i, 4);
        s->rest[i] = (float)ldexp((double)v, -SN_Q_LEN) * unit;
#endif
    }
    return 0;
}

typedef struct { float x, y, z, w; } fq;
static fq to_fq(sn_quat q) {
#ifdef SN_FLOAT
    fq r = {q.x, q.y, q.z, q.w};
#else
    fq r = {(float)q.x / 1073741824.0f, (float)q.y / 1073741824.0f, (float)q.z / 1073741824.0f, (float)q.w / 1073741824.0f};
#endif
    return r;
}
static fq fq_slerp(fq a, fq b, float u) {
    float c = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w, wa = 1 - u, wb = u, l;
    fq r;
    if (c < 0) { c = -c; b.x = -b.x; b.y = -b.y; b.z = -b.z; b.w = -b.w; }
    if (c < 0.9995f) {
        float th = acosf(c);
        wa = sinf((1 - u) * th) / sinf(th); wb = sinf(u * th) / sinf(th);
    }
    r.x = wa * a.x + wb * b.x; r.y = wa * a.y + wb * b.y; r.z = wa * a.z + wb * b.z; r.w = wa * a.w + wb * b.w;
    l = sqrtf(r.x * r.x + r.y * r.y + r.z * r.z + r.w * r.w);
    r.x /= l; r.y /= l; r.z /= l; r.w /= l;
    return r;
}
static void fq_rotate(fq q, const float v[3], float o[3]) {   /* v + 2w(u x v) + 2u x (u x v) */
    float tx = 2 * (q.y * v[2] - q.z * v[1]), ty = 2 * (q.z * v[0] - q.x * v[2]), tz = 2 * (q.x * v[1] - q.y * v[0]);
    o[0] = v[0] + q.w * tx + (q.y * tz - q.z * ty);
    o[1] = v[1] + q.w * ty + (q.z * tx - q.x * tz);
    o[2] = v[2] + q.w * tz + (q.x * ty - q.y * tx);
}

/* Lattice rigidly skinned by its frames under pose (R_i x_i + c_i, BLOB.md
 * FRAMES) into s->skin. */
static void skin_lattice(scene *s, const sn_xform *pose) {
    uint32_t i;
    for (i = 0; i < s->info.vertices; i++) {
        const unsigned char *f = s->frames + 4 * (size_t)i;
        const sn_xform *b1 = &pose[f[0]], *b2 = &pose[f[1]];
        float w = (float)(f[2] | f[3] << 8) / 32768.0f, r[3];
        fq q = fq_slerp(to_fq(b1->rot), to_fq(b2->rot), w);
        fq_rotate(q, s->rest + 3 * i, r);
        s->skin[3 * i] = r[0] + (1 - w) * F(b1->pos.x) + w * F(b2->pos.x);
        s->skin[3 * i + 1] = r[1] + (1 - w) * F(b1->pos.y) + w * F(b2->pos.y);
        s->skin[3 * i + 2] = r[2] + (1 - w) * F(b1->pos.z) + w * F(b2->pos.z);
    }
}

/* Surface vertex i interpolated from per-lattice-vertex vectors v (3 each). */
static void embed_vec(const scene *s, const float *v, uint32_t i, float out[3]) {
    const unsigned char *e = s->embed + 8 * (size_t)i;
    const unsigned char *cell = s->cells + SN_ELEM_CELLS * (size_t)(e[0] | e[1] << 8);
    float t[3];
    uint32_t k;
    out[0] = out[1] = out[2] = 0;
    for (k = 0; k < 3; k++) t[k] = (float)(e[2 + 2 * k] | e[3 + 2 * k] << 8) / 32768.0f;
    for (k = 0; k < 8; k++) {
        uint32_t c = cell[2 * k] | (uint32_t)cell[2 * k + 1] << 8;
        float n = (k & 1 ? t[0] : 1 - t[0]) * (k & 2 ? t[1] : 1 - t[1]) * (k & 4 ? t[2] : 1 - t[2]);
        out[0] += n * v[3 * c]; out[1] += n * v[3 * c + 1]; out[2] += n * v[3 * c + 2];
    }
}

/* Grow lo, hi by the surface rigidly skinned under pose. */
static void skinned_box(scene *s, const sn_xform *pose, float lo[3], float hi[3]) {
    uint32_t i, k;
    skin_lattice(s, pose);
    for (i = 0; i < s->info.surface_vertices; i++) {
        float p[3];
        embed_vec(s, s->skin, i, p);
        for (k = 0; k < 3; k++) {
            if (p[k] < lo[k]) lo[k] = p[k];
            if (p[k] > hi[k]) hi[k] = p[k];
        }
    }
}

/* Per surface vertex: how far the simulated flesh is from where rigid
 * skinning by the lattice frames would put it: the secondary motion (plus
 * the static sag under gravity). */
static void heat_colours(scene *s) {
    uint32_t i;
    skin_lattice(s, s->pose);
    for (i = 0; i < 3 * s->info.vertices; i++) s->dev[i] = s->lpos[i] - s->skin[i];
    for (i = 0; i < s->info.surface_vertices; i++) {
        float d[3], m;
        embed_vec(s, s->dev, i, d);
        m = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / s->heat;
        if (m > 1) m = 1;
        s->col[3 * i] = cow_colour[0] + m * (0.95f - cow_colour[0]);
        s->col[3 * i + 1] = cow_colour[1] + m * (0.12f - cow_colour[1]);
        s->col[3 * i + 2] = cow_colour[2] + m * (0.05f - cow_colour[2]);
    }
}
/* Per surface vertex: distance from s->ref (the rigs-off surface). */
static void ref_colours(scene *s) {
    uint32_t i;
    for (i = 0; i < s->info.surface_vertices; i++) {
        float dx = s->pos[3 * i] - s->ref[3 * i], dy = s->pos[3 * i + 1] - s->ref[3 * i + 1];
        float dz = s->pos[3 * i + 2] - s->ref[3 * i + 2], m = sqrtf(dx * dx + dy * dy + dz * dz) / s->heat;
        if (m > 1) m = 1;
        s->col[3 * i] = cow_colour[0] + m * (0.95f - cow_colour[0]);
        s->col[3 * i + 1] = cow_colour[1] + m * (0.12f - cow_colour[1]);
        s->col[3 * i + 2] = cow_colour[2] + m * (0.05f - cow_colour[2]);
    }
}
static const uint8_t ink[3] = {25, 28, 38};

/* A sphere (centre, radius) as a 12 x 24 triangle mesh. */
static void draw_sphere(rs_image *im, const rs_camera *cam, const float c[4], const float colour[3]) {
    enum { NLAT = 12, NLON = 24 };
    float pos[(NLAT + 1) * NLON * 3];
    uint32_t tri[NLAT * NLON * 6];
    int a, b, nt = 0;
    for (a = 0; a <= NLAT; a++)
        for (b = 0; b < NLON; b++) {
            float th = 3.14159265f * (float)a / NLAT, ph = 6.2831853f * (float)b / NLON;
            float *p = pos + 3 * (a * NLON + b);
            p[0] = c[0] + c[3] * sinf(th) * cosf(ph);
            p[1] = c[1] + c[3] * cosf(th);
            p[2] = c[2] + c[3] * sinf(th) * sinf(ph);
        }
    for (a = 0; a < NLAT; a++)
        for (b = 0; b < NLON; b++) {
            uint32_t i00 = (uint32_t)(a * NLON + b), i01 = (uint32_t)(a * NLON + (b + 1) % NLON);
            uint32_t i10 = i00 + NLON, i11 = i01 + NLON;
            tri[3 * nt] = i00; tri[3 * nt + 1] = i01; tri[3 * nt + 2] = i10; nt++;
            tri[3 * nt] = i01; tri[3 * nt + 1] = i11; tri[3 * nt + 2] = i10; nt++;
        }
    rs_draw_mesh(im, cam, pos, (NLAT + 1) * NLON, tri, nt, colour);
}

/* Render the instance into out (w x h) at 2x2 supersampling. */
static int render(scene *s, const sn_instance *inst, rs_image *out, const char *label, const char *label2) {
    rs_image big;
    rs_camera cam;
    uint32_t e, v;
    if (rs_image_alloc(&big, 2 * out->w, 2 * out->h)) return -1;
    fetch(s, inst);
    if (s->heat > 0 && s->ref) ref_colours(s);
    else if (s->heat > 0) heat_colours(s);
    if (s->marks && s->col && s->cr_list) {   /* crease contacts (seed 003 §3.4) in red over the flesh */
        uint32_t n = sn_get_crease_contacts(inst, s->cr_list, s->info.surface_vertices), i;
        if (s->heat <= 0)
            for (i = 0; i < s->info.surface_vertices; i++) memcpy(s->col + 3 * i, cow_colour, sizeof cow_colour);
        for (i = 0; i < n && i < s->info.surface_vertices; i++) {
            s->col[3 * s->cr_list[i]] = 0.85f; s->col[3 * s->cr_list[i] + 1] = 0.05f; s->col[3 * s->cr_list[i] + 2] = 0.05f;
        }
    }
    rs_camera_frame(&cam, s->flo, s->fhi, big.w, big.h, s->az, s->el);
    cam.ground_y = s->have_ground ? s->ground_y : s->lo[1];   /* the ground stays under the feet (or is the collider) */
    rs_clear(&big, &cam);
    if (s->heat > 0 || (s->marks && s->col && s->cr_list)) rs_draw_mesh_colors(&big, &cam, s->pos, (int)s->info.surface_vertices, s->tri, (int)s->info.triangles, s->col);
    else rs_draw_mesh(&big, &cam, s->pos, (int)s->info.surface_vertices, s->tri, (int)s->info.triangles, cow_colour);
    if (s->lattice) {
        const uint8_t lc[3] = {30, 60, 140}, sc[3] = {200, 30, 30};
        float r = (float)big.w / 320.0f;
        for (e = 0; e < s->n_edges; e++)
            rs_draw_line(&big, &cam, s->lpos + 3 * s->edges[2 * e], s->lpos + 3 * s->edges[2 * e + 1], lc, 0.3f);
        for (v = s->info.free_vertices; v < s->info.vertices; v++) rs_draw_dot(&big, &cam, s->lpos + 3 * v, r, sc);
    }
    if (s->segments) draw_segments(s, &big, &cam);
    if (s->marks && s->cr_list) {   /* contacts as dots over everything: most lie inside the other surface */
        const uint8_t mc[3] = {215, 20, 20};
        uint32_t n = sn_get_crease_contacts(inst, s->cr_list, s->info.surface_vertices), i;
        for (i = 0; i < n && i < s->info.surface_vertices; i++) rs_draw_dot(&big, &cam, s->pos + 3 * s->cr_list[i], (float)big.w / 220.0f, mc);
    }
    {   /* colliders and pins */
        static const float sphere_colour[3] = {0.55f, 0.62f, 0.75f};
        static const uint8_t pin_colour[3] = {200, 30, 30};
        int q;
        for (q = 0; q < s->n_sph; q++) draw_sphere(&big, &cam, s->sph[q], sphere_colour);
        for (v = 0; v < s->n_pins; v++) rs_draw_dot(&big, &cam, s->pos + 3 * s->pins[v], (float)big.w / 240.0f, pin_colour);
    }
    rs_downsample2(&big, out);
    rs_image_free(&big);
    if (label) rs_draw_text(out, 8, 8, out->w >= 480 ? 2 : 1, label, ink);
    if (label2) rs_draw_text(out, 8, out->w >= 480 ? 28 : 18, out->w >= 480 ? 2 : 1, label2, ink);
    return 0;
}

#define MAX_HELD 64
typedef struct {
    const char *blob_path, *clip_path, *obj_dir, *obj_frames, *png, *sheet, *compare, *title, *stats_csv, *plot;
    const char *compare_rigs, *rig_off_blob, *compare_hits;
    const char *compare_details, *level1_blob;   /* issue 13's details: cut | cut + details | level 1 */
    long details_n;     /* --details N; -1: all (up to A_max); 0: none */
    const char *gltf_anim, *clip_out, *out_gltf, *apng;   /* issue 17: glTF in and out */
    int gltf_noloop;
    const char *held[MAX_HELD];   /* --control NAME=VALUE, as given */
    int n_held, rigs_off;
    long frames, iterations, health;
    int unwarped, hash, lattice, marks, quiet, w, h, have_size;
    float az, el, box[6], heat;
    int have_box;
    /* segment meshes: --seg-impulse, --seg-floor, --segments */
    int n_imp, have_floor, no_segments;
    struct { unsigned mesh, node; long step; double j[3]; } imp[16];
    double floor_y;
    /* constraints and colliders: --ground, --sphere, --pin, --belt */
    int have_ground, n_sph, n_pin, have_belt;
    double ground_y, sph[4][7], belt_x, belt_w;
    uint32_t pin[64];
    /* --lod: level switches before steps */
    int n_lod;
    int adapt_off;      /* --adapt off */
    long lod_step[16];
    unsigned lod_level[16];
} options;

#define MAX_FRAMES 10000000L

/* --obj-frames list "0,10,20-30": checks the syntax and, when sel is given,
 * that every frame is in 0..n and marks it in sel[0..n]. 0 or -1 (err). */
static int frame_list(const char *v, long n, unsigned char *sel, char *err, size_t errlen) {
    const char *p = v;
    if (!*v) { snprintf(err, errlen, "empty list (want e.g. 0,10,20-30)"); return -1; }
    for (;;) {
        long a, b, k;
        char *end;
        const char *item = p;
        size_t len = strcspn(p, ",");
        if (!len) { snprintf(err, errlen, "empty item in '%s' (want e.g. 0,10,20-30)", v); return -1; }
        if (*p < '0' || *p > '9') goto syntax;
        a = strtol(p, &end, 10);
        b = a;
        if (*end == '-') {
            if (end[1] < '0' || end[1] > '9') goto syntax;
            b = strtol(end + 1, &end, 10);
        }
        if (end != p + len) goto syntax;
        if (a > MAX_FRAMES || b > MAX_FRAMES) { snprintf(err, errlen, "frame number too large in '%.*s'", (int)len, item); return -1; }
        if (b < a) { snprintf(err, errlen, "range '%.*s' runs backwards", (int)len, item); return -1; }
        if (sel) {
            if (b > n) {
                snprintf(err, errlen, "frame %ld is after the last frame of this run (%ld; see --frames)", b, n);
                return -1;
            }
            for (k = a; k <= b; k++) sel[k] = 1;
        }
        p += len;
        if (!*p) return 0;
        p++;
        continue;
    syntax:
        snprintf(err, errlen, "bad item '%.*s' (want N or A-B, e.g. 0,10,20-30)", (int)len, item);
        return -1;
    }
}

static int parse_args(int argc, char **argv, options *o) {
    static const char *const valued[] = {"--clip", "--obj-dir", "--obj-frames", "--png", "--sheet", "--compare", "--title",
                                         "--frames", "--iterations", "--health", "--size", "--view", "--frame-box", "--heat",
                                         "--stats-csv", "--plot", "--control", "--rigs", "--compare-rigs", "--rig-off-blob", "--compare-hits",
                                         "--seg-impulse", "--seg-floor", "--segments", "--ground", "--sphere", "--pin", "--belt",
                                         "--gltf-anim", "--gltf-loop", "--clip-out", "--out-gltf", "--apng", "--lod", "--mode", "--adapt",
                                         "--details", "--compare-details", "--level1-blob", NULL};
    int i, j;
    memset(o, 0, sizeof *o);
    o->frames = -1; o->w = 640; o->h = 480; o->az = 30; o->el = 15;
    for (i = 1; i < argc; i++) {
        const char *a = argv[i], *v = NULL;
        char *end;
        for (j = 0; valued[j]; j++)
            if (!strcmp(a, valued[j])) {
                if (i + 1 >= argc) { fprintf(stderr, PROG ": %s needs a value (try --help)\n", a); return 2; }
                v = argv[++i];
            }
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { usage(stdout); exit(0); }
        else if (!strcmp(a, "--clip")) o->clip_path = v;
        else if (!strcmp(a, "--gltf-anim")) o->gltf_anim = v;
        else if (!strcmp(a, "--clip-out")) o->clip_out = v;
        else if (!strcmp(a, "--out-gltf")) o->out_gltf = v;
        else if (!strcmp(a, "--apng")) o->apng = v;
        else if (!strcmp(a, "--gltf-loop")) {
            if (strcmp(v, "yes") && strcmp(v, "no")) { fprintf(stderr, PROG ": --gltf-loop: want yes or no, got '%s'\n", v); return 2; }
            o->gltf_noloop = !strcmp(v, "no");
        }
        else if (!strcmp(a, "--obj-dir")) o->obj_dir = v;
        else if (!strcmp(a, "--obj-frames")) {
            char e[256];
            if (frame_list(v, 0, NULL, e, sizeof e)) { fprintf(stderr, PROG ": --obj-frames: %s\n", e); return 2; }
            o->obj_frames = v;
        }
        else if (!strcmp(a, "--stats-csv")) o->stats_csv = v;
        else if (!strcmp(a, "--plot")) o->plot = v;
        else if (!strcmp(a, "--png")) o->png = v;
        else if (!strcmp(a, "--sheet")) o->sheet = v;
        else if (!strcmp(a, "--compare")) o->compare = v;
        else if (!strcmp(a, "--compare-rigs")) o->compare_rigs = v;
        else if (!strcmp(a, "--compare-hits")) o->compare_hits = v;
        else if (!strcmp(a, "--rig-off-blob")) o->rig_off_blob = v;
        else if (!strcmp(a, "--compare-details")) o->compare_details = v;
        else if (!strcmp(a, "--level1-blob")) o->level1_blob = v;
        else if (!strcmp(a, "--details")) {
            long n = strtol(v, &end, 10);
            if (!strcmp(v, "all")) o->details_n = -1;
            else if (!*v || *end || n < 1 || n > 65535) { fprintf(stderr, PROG ": --details: want N (1..65535) or all, got '%s'\n", v); return 2; }
            else o->details_n = n;
        }
        else if (!strcmp(a, "--rigs")) {
            if (strcmp(v, "on") && strcmp(v, "off")) { fprintf(stderr, PROG ": --rigs: want on or off, got '%s'\n", v); return 2; }
            o->rigs_off = !strcmp(v, "off");
        } else if (!strcmp(a, "--control")) {
            const char *eq = strchr(v, '=');
            int32_t q;
            if (!eq || eq == v || (size_t)(eq - v) > SN_CLIP_NAME_MAX) {
                fprintf(stderr, PROG ": --control: want NAME=VALUE (name 1..%d bytes), got '%s'\n", SN_CLIP_NAME_MAX, v); return 2;
            }
            if (sn_clip_parse_q16(eq + 1, strlen(eq + 1), &q)) {
                fprintf(stderr, PROG ": --control %s: the value must be a decimal with |x| < 32768 (as in clips), got '%s'\n", v, eq + 1);
                return 2;
            }
            if (o->n_held >= MAX_HELD) { fprintf(stderr, PROG ": --control: at most %d\n", MAX_HELD); return 2; }
            o->held[o->n_held++] = v;
        }
        else if (!strcmp(a, "--seg-impulse")) {
            unsigned m, n;
            double x, y, z;
            long k = 1;
            int used = 0, used2 = 0;
            if (sscanf(v, "%u:%u:%lf,%lf,%lf%n", &m, &n, &x, &y, &z, &used) != 5 || !isfinite(x) || !isfinite(y) || !isfinite(z) ||
                (v[used] && (sscanf(v + used, "@%ld%n", &k, &used2) != 1 || v[used + used2] || k < 1 || k > MAX_FRAMES))) {
                fprintf(stderr, PROG ": --seg-impulse: want MESH:NODE:X,Y,Z[@STEP] (newton-seconds, step >= 1), got '%s'\n", v); return 2;
            }
            if (o->n_imp >= 16) { fprintf(stderr, PROG ": --seg-impulse: at most 16\n"); return 2; }
            o->imp[o->n_imp].mesh = m; o->imp[o->n_imp].node = n; o->imp[o->n_imp].step = k;
            o->imp[o->n_imp].j[0] = x; o->imp[o->n_imp].j[1] = y; o->imp[o->n_imp].j[2] = z;
            o->n_imp++;
        } else if (!strcmp(a, "--seg-floor")) {
            o->floor_y = strtod(v, &end);
            if (!*v || *end || !isfinite(o->floor_y) || fabs(o->floor_y) > 16384) { fprintf(stderr, PROG ": --seg-floor: want a height in mesh units, got '%s'\n", v); return 2; }
            o->have_floor = 1;
        } else if (!strcmp(a, "--ground")) {
            o->ground_y = strtod(v, &end);
            if (!*v || *end || !isfinite(o->ground_y) || fabs(o->ground_y) > 16384) { fprintf(stderr, PROG ": --ground: want a height in mesh units, got '%s'\n", v); return 2; }
            o->have_ground = 1;
        } else if (!strcmp(a, "--sphere")) {
            double *q;
            int used = 0, used2 = 0;
            if (o->n_sph >= 4) { fprintf(stderr, PROG ": --sphere: at most 4\n"); return 2; }
            q = o->sph[o->n_sph];
            q[4] = q[5] = q[6] = 0;
            if (sscanf(v, "%lf,%lf,%lf,%lf%n", &q[0], &q[1], &q[2], &q[3], &used) != 4 || q[3] < 0 ||
                (v[used] && (sscanf(v + used, "@%lf,%lf,%lf%n", &q[4], &q[5], &q[6], &used2) != 3 || v[used + used2]))) {
                fprintf(stderr, PROG ": --sphere: want X,Y,Z,R[@VX,VY,VZ] (mesh units, R >= 0), got '%s'\n", v); return 2;
            }
            for (j = 0; j < 7; j++) if (!isfinite(q[j]) || fabs(q[j]) > 16384) { fprintf(stderr, PROG ": --sphere: value out of range in '%s'\n", v); return 2; }
            o->n_sph++;
        } else if (!strcmp(a, "--pin")) {
            const char *p = v;
            while (*p) {
                unsigned long n = strtoul(p, &end, 10);
                if (end == p || (*end && *end != ',') || n > 65535) { fprintf(stderr, PROG ": --pin: want surface vertices V[,V..], got '%s'\n", v); return 2; }
                if (o->n_pin >= 64) { fprintf(stderr, PROG ": --pin: at most 64 vertices\n"); return 2; }
                o->pin[o->n_pin++] = (uint32_t)n;
                p = *end ? end + 1 : end;
            }
        } else if (!strcmp(a, "--belt")) {
            int used = 0;
            o->belt_w = 0.08;
            if (sscanf(v, "%lf%n", &o->belt_x, &used) != 1 || (v[used] && (sscanf(v + used, ",%lf", &o->belt_w) != 1)) ||
                !isfinite(o->belt_x) || !isfinite(o->belt_w) || o->belt_w <= 0) { fprintf(stderr, PROG ": --belt: want X[,W] (mesh units, W > 0), got '%s'\n", v); return 2; }
            o->have_belt = 1;
        } else if (!strcmp(a, "--lod")) {
            const char *q = v;
            for (;;) {
                long kk, ll;
                char *e2;
                kk = strtol(q, &e2, 10);
                if (e2 == q || *e2 != ':' || kk < 1 || kk > MAX_FRAMES || o->n_lod >= 16) { fprintf(stderr, PROG ": --lod: want K:L[,K:L..] (step K >= 1, at most 16), got '%s'\n", v); return 2; }
                q = e2 + 1;
                ll = strtol(q, &e2, 10);
                if (e2 == q || ll < 0 || ll > 1 || (*e2 && *e2 != ',')) { fprintf(stderr, PROG ": --lod: level 0 or 1, got '%s'\n", v); return 2; }
                o->lod_step[o->n_lod] = kk; o->lod_level[o->n_lod] = (unsigned)ll; o->n_lod++;
                if (!*e2) break;
                q = e2 + 1;
            }
        } else if (!strcmp(a, "--adapt")) {
            if (strcmp(v, "on") && strcmp(v, "off")) { fprintf(stderr, PROG ": --adapt: want on or off, got '%s'\n", v); return 2; }
            o->adapt_off = !strcmp(v, "off");
        } else if (!strcmp(a, "--segments")) {
            if (strcmp(v, "on") && strcmp(v, "off")) { fprintf(stderr, PROG ": --segments: want on or off, got '%s'\n", v); return 2; }
            o->no_segments = !strcmp(v, "off");
        }
        else if (!strcmp(a, "--title")) o->title = v;
        else if (!strcmp(a, "--frames") || !strcmp(a, "--iterations") || !strcmp(a, "--health")) {
            long n = strtol(v, &end, 10);
            if (!*v || *end || n < 0 || n > MAX_FRAMES || (a[2] != 'f' && n < 1)) {
                fprintf(stderr, PROG ": %s: bad number '%s'\n", a, v); return 2;
            }
            if (a[2] == 'f') o->frames = n; else if (a[2] == 'i') o->iterations = n; else o->health = n;
        } else if (!strcmp(a, "--size")) {
            char c;
            if (sscanf(v, "%dx%d%c", &o->w, &o->h, &c) != 2 || o->w < 16 || o->h < 16 || o->w > 4096 || o->h > 4096) {
                fprintf(stderr, PROG ": --size: want WxH (16..4096), got '%s'\n", v); return 2;
            }
            o->have_size = 1;
        } else if (!strcmp(a, "--frame-box")) {
            float *b = o->box;
            if (sscanf(v, "%f,%f,%f,%f,%f,%f", b, b + 1, b + 2, b + 3, b + 4, b + 5) != 6 ||
                !(b[0] < b[3] && b[1] < b[4] && b[2] < b[5])) {
                fprintf(stderr, PROG ": --frame-box: want X0,Y0,Z0,X1,Y1,Z1 with X0<X1 etc., got '%s'\n", v); return 2;
            }
            o->have_box = 1;
        } else if (!strcmp(a, "--heat")) {
            o->heat = strtof(v, &end);
            if (!*v || *end || !(o->heat > 0)) { fprintf(stderr, PROG ": --heat: want a distance > 0 in mesh units, got '%s'\n", v); return 2; }
        } else if (!strcmp(a, "--view")) {
            if (sscanf(v, "%f,%f", &o->az, &o->el) != 2 || o->el < -89 || o->el > 89) {
                fprintf(stderr, PROG ": --view: want AZ,EL in degrees, got '%s'\n", v); return 2;
            }
        }
        else if (!strcmp(a, "--unwarped")) o->unwarped = SN_MODE_UNWARPED;
        else if (!strcmp(a, "--mode")) {   /* o->unwarped holds the sn_mode */
            if (!strcmp(v, "warped")) o->unwarped = SN_MODE_WARPED;
            else if (!strcmp(v, "unwarped")) o->unwarped = SN_MODE_UNWARPED;
            else if (!strcmp(v, "blended")) o->unwarped = SN_MODE_BLENDED;
            else { fprintf(stderr, PROG ": --mode: want warped, unwarped or blended, got '%s'\n", v); return 2; }
        }
        else if (!strcmp(a, "--hash")) o->hash = 1;
        else if (!strcmp(a, "--lattice")) o->lattice = 1;
        else if (!strcmp(a, "--crease-marks")) o->marks = 1;
        else if (!strcmp(a, "--quiet")) o->quiet = 1;
        else if (a[0] == '-' && a[1]) { fprintf(stderr, PROG ": unknown option '%s' (try --help)\n", a); return 2; }
        else if (!o->blob_path) o->blob_path = a;
        else { fprintf(stderr, PROG ": more than one blob given ('%s')\n", a); return 2; }
    }
    if (!o->blob_path) { usage(stderr); return 2; }
    if (o->gltf_anim && o->clip_path) { fprintf(stderr, PROG ": --gltf-anim and --clip: one at a time\n"); return 2; }
    if (o->clip_out && !o->gltf_anim) { fprintf(stderr, PROG ": --clip-out needs --gltf-anim\n"); return 2; }
    if (o->plot && o->have_size && (o->w < 240 || o->h < 180)) {
        fprintf(stderr, PROG ": --size: the plot needs at least 240x180\n"); return 2;
    }
    if (o->obj_frames && !o->obj_dir) { fprintf(stderr, PROG ": --obj-frames needs --obj-dir\n"); return 2; }
    if (o->rigs_off && o->n_held) { fprintf(stderr, PROG ": --rigs off holds every control at 0: it cannot go with --control\n"); return 2; }
    if (o->rig_off_blob && !o->compare_rigs) { fprintf(stderr, PROG ": --rig-off-blob needs --compare-rigs\n"); return 2; }
    if (o->compare && o->compare_rigs) { fprintf(stderr, PROG ": --compare and --compare-rigs: one at a time\n"); return 2; }
    if (o->compare_hits && (o->compare || o->compare_rigs)) { fprintf(stderr, PROG ": --compare-hits and --compare/--compare-rigs: one at a time\n"); return 2; }
    if (o->compare_hits && !o->clip_path) { fprintf(stderr, PROG ": --compare-hits needs a --clip with impulse lines\n"); return 2; }
    if (o->compare_details && (o->compare || o->compare_rigs || o->compare_hits)) {
        fprintf(stderr, PROG ": --compare-details and --compare/--compare-rigs/--compare-hits: one at a time\n"); return 2;
    }
    if (o->compare_details && !o->details_n) { fprintf(stderr, PROG ": --compare-details needs --details N|all (the middle panel)\n"); return 2; }
    if (o->compare_details && o->n_lod) { fprintf(stderr, PROG ": --compare-details runs each panel on one level: not with --lod\n"); return 2; }
    if (o->level1_blob && !o->compare_details) { fprintf(stderr, PROG ": --level1-blob needs --compare-details\n"); return 2; }
    if (o->compare_rigs && o->rigs_off) { fprintf(stderr, PROG ": --compare-rigs shows rigs off next to rigs on: not with --rigs off\n"); return 2; }
    if (o->sheet && o->have_size && (o->w > 2048 || o->h > 2048)) {
        fprintf(stderr, PROG ": --size: sheet cells are at most 2048x2048 (the sheet is 4x3 cells)\n"); return 2;
    }
    return 0;
}

/* Write the surface as OBJ (mesh units) atomically. */
static int write_obj(scene *s, const char *path, char *err, size_t errlen) {
    size_t cap = (size_t)s->info.surface_vertices * 48 + (size_t)s->info.triangles * 24 + 64, n = 0;
    char *buf = malloc(cap);
    uint32_t i;
    int r;
    if (!buf) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
    n += (size_t)snprintf(buf + n, cap - n, "# sinew-play frame\n");
    for (i = 0; i < s->info.surface_vertices; i++)
        n += (size_t)snprintf(buf + n, cap - n, "v %.6g %.6g %.6g\n", s->pos[3 * i], s->pos[3 * i + 1], s->pos[3 * i + 2]);
    for (i = 0; i < s->info.triangles; i++)
        n += (size_t)snprintf(buf + n, cap - n, "f %u %u %u\n", s->tri[3 * i] + 1, s->tri[3 * i + 1] + 1, s->tri[3 * i + 2] + 1);
    r = write_file_atomic(path, buf, n, err, errlen);
    free(buf);
    return r;
}

#define SHEET_COLS 4
#define SHEET_ROWS 3

/* Health of one step (sn_stats after it). */
typedef struct { double disp, energy; uint32_t saturations, bound_steps, limit_clamps; } frame_stat;

/* --stats-csv: one row per step, atomically. */
static int write_stats_csv(const char *path, const frame_stat *f, long n, double h, const sn_blob *blob,
                           uint32_t nc, const double *ctl, char *err, size_t errlen) {
    size_t cap = (size_t)n * (120 + 20 * (size_t)nc) + 128 + 40 * (size_t)nc, len = 0;
    char *buf = malloc(cap);
    long k;
    uint32_t c;
    int r;
    if (!buf) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
    len += (size_t)snprintf(buf, cap, "frame,t_s,disp_cells,energy_J,saturations,bound_steps,limit_clamps");
    for (c = 0; c < nc; c++) len += (size_t)snprintf(buf + len, cap - len, ",ctl_%s", sn_control_name(blob, c));
    len += (size_t)snprintf(buf + len, cap - len, "\n");
    for (k = 0; k < n; k++) {
        len += (size_t)snprintf(buf + len, cap - len, "%ld,%.6f,%.9g,%.9g,%u,%u,%u", k + 1, (double)(k + 1) * h,
                                f[k].disp, f[k].energy, f[k].saturations, f[k].bound_steps, f[k].limit_clamps);
        for (c = 0; c < nc; c++) len += (size_t)snprintf(buf + len, cap - len, ",%.9g", ctl[(size_t)k * nc + c]);
        len += (size_t)snprintf(buf + len, cap - len, "\n");
    }
    r = write_file_atomic(path, buf, len, err, errlen);
    free(buf);
    return r;
}

/* --plot: energy above displacement, per step. */
static int write_plot(const char *path, const frame_stat *f, long n, double h, int w, int hh, const char *title,
                      const sn_blob *blob, uint32_t nc, const double *ctl, char *err, size_t errlen) {
    double *x = malloc(((size_t)n + 1) * (3 + (size_t)nc) * sizeof(double)), *e = x ? x + n + 1 : NULL, *d = x ? x + 2 * (n + 1) : NULL;
    plot_series se, sd, *sc = nc ? malloc(nc * sizeof *sc) : NULL;
    plot_panel p[4];
    rs_image im;
    long k;
    uint32_t c, na = 0, np = 0;
    int r = -1, npan = 2;
    memset(&im, 0, sizeof im);
    if (!x || (nc && !sc) || rs_image_alloc(&im, w, hh)) { snprintf(err, errlen, "%s: out of memory", path); free(x); free(sc); return -1; }
    for (k = 0; k < n; k++) { x[k] = (double)(k + 1) * h; e[k] = f[k].energy; d[k] = f[k].disp; }
    se.x = sd.x = x; se.n = sd.n = (int)n; se.y = e; sd.y = d; se.label = sd.label = NULL;
    p[0].title = "energy (J)"; p[0].s = &se; p[0].ns = 1; p[0].log_y = 0;
    p[1].title = "largest displacement (cells)"; p[1].s = &sd; p[1].ns = 1; p[1].log_y = 0;
    /* rig controls: abstract ones (unitless) in one panel, pose ones (degrees) in another */
    for (c = 0; c < nc; c++) na += sn_control_kind_of(blob, c) == SN_CONTROL_ABSTRACT;
    np = nc - na;
    for (c = 0; c < nc; c++) {
        int abstract = sn_control_kind_of(blob, c) == SN_CONTROL_ABSTRACT;
        uint32_t at = abstract ? 0 : na;
        double *y = x + (size_t)(3 + c) * (size_t)(n + 1);
        uint32_t m;
        for (m = 0; m < c; m++) if ((sn_control_kind_of(blob, m) == SN_CONTROL_ABSTRACT) == abstract) at++;
        for (k = 0; k < n; k++) y[k] = ctl[(size_t)k * nc + c];
        sc[at].x = x; sc[at].y = y; sc[at].n = (int)n; sc[at].label = sn_control_name(blob, c);
    }
    if (na) { p[npan].title = "abstract rig controls"; p[npan].s = sc; p[npan].ns = (int)na; p[npan].log_y = 0; npan++; }
    if (np) { p[npan].title = "pose rig controls (degrees)"; p[npan].s = sc + na; p[npan].ns = (int)np; p[npan].log_y = 0; npan++; }
    if (plot_draw(&im, title, "time (s)", p, npan)) snprintf(err, errlen, "%s: picture too small for the plot or out of memory", path);
    else r = png_write(path, im.rgb, im.w, im.h, err, errlen);
    rs_image_free(&im);
    free(x);
    free(sc);
    return r;
}

/* --control NAME=VALUE resolved against the blob. */
typedef struct { uint32_t c; int32_t q16; } held_control;

/* "a b c" list of the blob's controls for messages. */
static void control_list(const sn_blob *blob, uint32_t nc, char *buf, size_t len) {
    uint32_t c;
    size_t n = 0;
    buf[0] = 0;
    if (!nc) { snprintf(buf, len, "it has none"); return; }
    n += (size_t)snprintf(buf, len, "controls:");
    for (c = 0; c < nc && n < len; c++)
        n += (size_t)snprintf(buf + n, len - n, " %s%s", sn_control_name(blob, c),
                              sn_control_kind_of(blob, c) == SN_CONTROL_ABSTRACT ? "" : " (pose)");
}

static sn_real real_of_q16(int32_t v) {
#ifdef SN_FLOAT
    return (sn_real)v / 65536.0f;
#else
    return v;
#endif
}

/* Every abstract control of inst to 0. */
static void controls_zero(sn_instance *in, const sn_blob *blob, uint32_t nc) {
    uint32_t c;
    for (c = 0; c < nc; c++)
        if (sn_control_kind_of(blob, c) == SN_CONTROL_ABSTRACT) sn_set_control(in, c, 0);
}

/* Controls for step k: the clip's tracks, then the held values over them. */
static void controls_step(sn_instance *in, const sn_blob *blob, const sn_clip *clip, uint32_t k,
                          const held_control *held, int n_held, int hits) {
    int i;
    if (clip) sn_clip_controls(clip, blob, k, in);
    if (clip && hits) sn_clip_impulses(clip, blob, k, in); /* hits on the flesh (clip impulse events) */
    for (i = 0; i < n_held; i++) sn_set_control(in, held[i].c, real_of_q16(held[i].q16));
}

/* --compare-details: cut level | cut + details | level 1 at the last frame
 * (runtime/LEVELS.md §3 "Details on the cut level"). Each of the first two
 * panels is labelled with its surface's distance from level 1's (largest
 * and rms over the surface vertices, mesh units; also printed) and, with
 * --heat, coloured by it. 0, or -1 after a message. */
static int compare_details(scene *s, const options *o, const sn_instance *with, const sn_instance *cut,
                           const sn_instance *l1, long n_details, double t_end, rs_image *cmp) {
    const sn_instance *panel[2];
    const uint8_t line[3] = {255, 255, 255};
    rs_image pane;
    float heat = s->heat, *ref;
    uint32_t nv = s->info.surface_vertices, i;
    int pw = o->w * 3 / 4 > 240 ? o->w * 3 / 4 : 240, ph = pw * 3 / 4, p;
    char lab[64], title[64], dist[96], err[512];
    panel[0] = cut; panel[1] = with;
    memset(&pane, 0, sizeof pane);
    ref = malloc(((size_t)nv + 1) * 3 * sizeof(float));
    if (!ref || rs_image_alloc(cmp, 3 * pw, ph) || rs_image_alloc(&pane, pw, ph)) { free(ref); rs_image_free(&pane); die("out of memory"); return -1; }
    snprintf(lab, sizeof lab, "t = %.2f s", t_end);
    s->heat = 0; s->ref = NULL;
    if (render(s, l1, &pane, "level 1", lab)) goto oom;
    rs_blit(cmp, 2 * pw, 0, &pane);
    memcpy(ref, s->pos, (size_t)nv * 3 * sizeof(float));   /* render fetched level 1's surface */
    for (p = 0; p < 2; p++) {
        double mx = 0, ss = 0;
        fetch(s, panel[p]);
        for (i = 0; i < nv; i++) {
            double dx = s->pos[3 * i] - ref[3 * i], dy = s->pos[3 * i + 1] - ref[3 * i + 1], dz = s->pos[3 * i + 2] - ref[3 * i + 2];
            double d2 = dx * dx + dy * dy + dz * dz;
            ss += d2;
            if (d2 > mx) mx = d2;
        }
        mx = sqrt(mx); ss = nv ? sqrt(ss / nv) : 0;
        if (p == 0) snprintf(title, sizeof title, "cut level");
        else snprintf(title, sizeof title, "cut + %ld details", n_details);
        snprintf(dist, sizeof dist, "from level 1: max %.2f, rms %.3f", mx, ss);
        if (!o->quiet) printf("compare-details: %s: surface from level 1 max %.4g rms %.4g mesh units (t = %.2f s)\n", title, mx, ss, t_end);
        if (heat > 0) { s->ref = ref; s->heat = heat; }
        if (render(s, panel[p], &pane, title, dist)) goto oom;
        s->ref = NULL; s->heat = 0;
        rs_blit(cmp, p * pw, 0, &pane);
    }
    s->heat = heat;
    rs_fill(cmp, pw - 1, 0, 2, ph, line);
    rs_fill(cmp, 2 * pw - 1, 0, 2, ph, line);
    rs_image_free(&pane);
    free(ref);
    if (png_write(o->compare_details, cmp->rgb, cmp->w, cmp->h, err, sizeof err)) { die("%s", err); return -1; }
    if (!o->quiet) printf("wrote %s\n", o->compare_details);
    return 0;
oom:
    s->heat = heat; s->ref = NULL;
    rs_image_free(&pane);
    free(ref);
    die("out of memory");
    return -1;
}

/* --details: details 0..n-1 active (sn_details_set; runtime/LEVELS.md §3).
 * n < 0: as many as the blob takes. The most it takes (A_max, at most its
 * detail count) is not in sn_blob_info: found as the largest set
 * sn_details_set accepts, then sn_reset empties the set again (keeping
 * iterations and mode) and the chosen one is set on the state at rest.
 * Returns the count set, or -1 with err. */
static long details_apply(sn_instance *inst, long n, const char *blob_path, char *err, size_t errlen) {
    uint16_t *ids = malloc(65536 * sizeof *ids);
    long k, most = 0;
    if (!ids) { snprintf(err, errlen, "out of memory"); return -1; }
    for (k = 0; k < 65536; k++) ids[k] = (uint16_t)k;
    while (most < 65535 && sn_details_set(inst, ids, (uint32_t)(most + 1)) == SN_OK) most++;
    sn_reset(inst);
    if (!most) snprintf(err, errlen, "--details: %s has no details (bake it with 'levels 2 cut' and 'details A_MAX REFINE COARSEN')", blob_path);
    else if (n > most) snprintf(err, errlen, "--details %ld: %s takes at most %ld at once (its A_max, or its detail count)", n, blob_path, most);
    else {
        if (n < 0) n = most;
        if (sn_details_set(inst, ids, (uint32_t)n) == SN_OK) { free(ids); return n; }
        snprintf(err, errlen, "--details %ld: sn_details_set refused", n);
    }
    free(ids);
    return -1;
}

int main(int argc, char **argv) {
    options o;
    scene s;
    char err[8192], path[4200];
    void *bytes = NULL, *mem = NULL, *mem2 = NULL;
    size_t nbytes = 0, need;
    sn_status st;
    sn_instance *inst = NULL, *inst2 = NULL;
    sn_instance *inst3 = NULL;       /* --compare-details: level 1 */
    void *mem3 = NULL, *bytes3 = NULL;
    long n_details = 0;              /* --details: active on inst */
    static sn_clip clip;
    char *gltf_clip = NULL;          /* --gltf-anim: the clip text */
    pg_out gout;                     /* --out-gltf */
    png_anim apng;                   /* --apng */
    rs_image aframe;
    long out_stride = 1, apng_stride = 1;
    int have_clip = 0, rc = 1;
    static sn_clip_hold clip_hold[SN_CLIP_MAX_CHANNELS];   /* 'pin ... hold' targets */
    sn_constraint *flag_cs = NULL, *all_cs = NULL;         /* --pin/--belt, then the clip's pins */
    uint32_t flag_nc = 0;
    sn_quat *local = NULL;
    sn_xform *xf = NULL, *rest_xf = NULL;
    double *times = NULL, *cpu = NULL, h_s, ad_sum = 0;
    long k, n_frames, ad_steps = 0;
    uint32_t ad_max = 0;
    uint32_t i, t;
    rs_image sheet, panel, cmp;
    long sheet_at[SHEET_COLS * SHEET_ROWS];
    unsigned char *obj_sel = NULL;   /* --obj-frames: frames to write, 0..n_frames */
    frame_stat *fst = NULL;          /* per step, for --stats-csv and --plot */
    int pictures = 0;
    held_control held[MAX_HELD];     /* --control, resolved */
    uint32_t n_ctl = 0, n_ctl2 = 0;  /* rig controls of the blob, of the rigs-off instance's blob */
    double *fctl = NULL;             /* per step and control, for --stats-csv and --plot */
    void *bytes2 = NULL;             /* --rig-off-blob */
    const sn_blob *blob2 = NULL;
    float *refpos = NULL;            /* --compare-rigs --heat: the rigs-off surface */
    int hc;
    int r = parse_args(argc, argv, &o);
    if (r) return r;
    srand((unsigned)getpid());   /* distinct temp-file names for concurrent players */
    memset(&s, 0, sizeof s);
    memset(&sheet, 0, sizeof sheet); memset(&panel, 0, sizeof panel); memset(&cmp, 0, sizeof cmp);
    memset(&gout, 0, sizeof gout); memset(&apng, 0, sizeof apng); memset(&aframe, 0, sizeof aframe);

    /* blob */
    if (!(bytes = read_file(o.blob_path, &nbytes, err, sizeof err))) return die("%s", err);
    st = sn_blob_validate(bytes, nbytes, &s.blob);
    if (st != SN_OK) {
        fprintf(stderr, PROG ": %s: invalid blob: %s%s\n", o.blob_path, sn_status_str(st),
                st == SN_ERR_FLAVOUR ? (SN_FLAVOUR ? " (this is the float player; use sinew-play for fixed blobs)"
                                                   : " (this is the fixed player; use sinew-play-float for float blobs)") : "");
        goto done;
    }
    sn_blob_get_info(s.blob, &s.info);
    h_s = (double)F(s.info.timestep);

    /* clip (or a glTF animation turned into one) */
    if (o.gltf_anim) {
        int32_t hq0 = sn_clip_timestep_q16(s.blob);
        if (hq0 < 1) { die("%s: its timestep cannot step a clip", o.blob_path); goto done; }
        if (!(gltf_clip = pg_anim_clip(o.gltf_anim, hq0, !o.gltf_noloop, o.quiet, err, sizeof err))) { die("--gltf-anim: %s", err); goto done; }
        if (o.clip_out && write_file_atomic(o.clip_out, gltf_clip, strlen(gltf_clip), err, sizeof err)) { die("%s", err); goto done; }
        o.clip_path = o.gltf_anim;
    }
    if (o.clip_path) {
        size_t cn;
        char *text = gltf_clip ? gltf_clip : read_file(o.clip_path, &cn, err, sizeof err);
        if (gltf_clip) cn = strlen(gltf_clip), gltf_clip = NULL;
        if (!text) { die("%s", err); goto done; }
        if (sn_clip_parse(&clip, text, cn, err, sizeof err)) { free(text); die("%s: %s", o.clip_path, err); goto done; }
        free(text);
        for (i = 0; i < clip.n_warnings && i < SN_CLIP_MAX_WARNINGS; i++) {
            sn_clip_warning_str(&clip, i, err, sizeof err);
            fprintf(stderr, PROG ": warning: %s:%u: %s\n", o.clip_path, clip.warn[i].line, err);
        }
        if (clip.n_warnings > SN_CLIP_MAX_WARNINGS)
            fprintf(stderr, PROG ": warning: %s: %u more keys 180 degrees or more apart\n", o.clip_path,
                    clip.n_warnings - SN_CLIP_MAX_WARNINGS);
        if (sn_clip_bind(&clip, s.blob, err, sizeof err)) {
            fprintf(stderr, PROG ": %s does not fit %s: %s\n", o.clip_path, o.blob_path, err);
            goto done;
        }
        have_clip = 1;
    }

    /* rig controls: --control values, the clip's control tracks, --rigs off */
    n_ctl = s.info.controls;
    for (hc = 0; hc < o.n_held; hc++) {
        const char *eq = strchr(o.held[hc], '=');
        char name[SN_CLIP_NAME_MAX + 1], cl[1024];
        int32_t c;
        memcpy(name, o.held[hc], (size_t)(eq - o.held[hc]));
        name[eq - o.held[hc]] = 0;
        sn_clip_parse_q16(eq + 1, strlen(eq + 1), &held[hc].q16);   /* checked by parse_args */
        c = sn_find_control(s.blob, name);
        if (c < 0) {
            control_list(s.blob, n_ctl, cl, sizeof cl);
            fprintf(stderr, PROG ": --control %s: %s has no control '%s' (%s)\n", o.held[hc], o.blob_path, name, cl);
            goto done;
        }
        if (sn_control_kind_of(s.blob, (uint32_t)c) != SN_CONTROL_ABSTRACT) {
            fprintf(stderr, PROG ": --control %s: '%s' is a pose control of %s (degrees, read from the pose by sn_step): "
                    "it cannot be held; pose its joint instead\n", o.held[hc], name, o.blob_path);
            goto done;
        }
        held[hc].c = (uint32_t)c;
    }
    if (have_clip)
        for (i = 0; i < clip.n_channels; i++)
            if (clip.chan[i].kind == SN_CLIP_CONTROL && clip.chan[i].joint < 0) {
                char cl[1024];
                control_list(s.blob, n_ctl, cl, sizeof cl);
                fprintf(stderr, PROG ": warning: %s: control '%s' is not in %s (%s): its keys are ignored\n",
                        o.clip_path, clip.chan[i].name, o.blob_path, cl);
            }
    if ((o.rigs_off || (o.compare_rigs && !o.rig_off_blob)) && s.info.rigs) {
        char cl[512];
        size_t n = 0;
        cl[0] = 0;
        for (i = 0; i < n_ctl && n < sizeof cl; i++)
            if (sn_control_kind_of(s.blob, i) != SN_CONTROL_ABSTRACT)
                n += (size_t)snprintf(cl + n, sizeof cl - n, "%s%s", n ? ", " : "", sn_control_name(s.blob, i));
        if (n)
            fprintf(stderr, PROG ": note: %s: rigs driven by the pose controls (%s) stay on with every abstract control "
                    "at 0%s\n", o.blob_path, cl, o.compare_rigs ? "; for a rig-free panel give --rig-off-blob (the description "
                    "baked without its rig lines)" : "; for a rig-free run bake the description without its rig lines");
    }
    n_frames = o.frames >= 0 ? o.frames
             : have_clip ? (long)((((int64_t)clip.duration + sn_clip_timestep_q16(s.blob) - 1) / sn_clip_timestep_q16(s.blob)))
             : 60;
    if (o.iterations && (uint32_t)o.iterations > s.info.cg_iters_max) {
        fprintf(stderr, PROG ": --iterations %ld: this blob allows 1..%u\n", o.iterations, s.info.cg_iters_max);
        goto done;
    }

    if (o.obj_frames) {
        if (!(obj_sel = calloc((size_t)n_frames + 1, 1))) { die("out of memory"); goto done; }
        if (frame_list(o.obj_frames, n_frames, obj_sel, err, sizeof err)) { die("--obj-frames: %s", err); rc = 2; goto done; }
    }

    /* outputs: check up front so a bad path fails before the run, not after */
    if (o.png && probe_writable(o.png, err, sizeof err)) { die("%s", err); goto done; }
    if (o.stats_csv && probe_writable(o.stats_csv, err, sizeof err)) { die("%s", err); goto done; }
    if (o.plot && probe_writable(o.plot, err, sizeof err)) { die("%s", err); goto done; }
    if (o.sheet && probe_writable(o.sheet, err, sizeof err)) { die("%s", err); goto done; }
    if (o.compare && probe_writable(o.compare, err, sizeof err)) { die("%s", err); goto done; }
    if (o.compare_rigs && probe_writable(o.compare_rigs, err, sizeof err)) { die("%s", err); goto done; }
    if (o.compare_hits && probe_writable(o.compare_hits, err, sizeof err)) { die("%s", err); goto done; }
    if (o.compare_details && probe_writable(o.compare_details, err, sizeof err)) { die("%s", err); goto done; }
    if (o.obj_dir) {
        snprintf(path, sizeof path, "%s/frame_0000.obj", o.obj_dir);
        if (probe_writable(path, err, sizeof err)) { die("%s", err); goto done; }
    }

    /* instance(s) in our own memory */
    need = sn_instance_size_mode(s.blob, (sn_mode)o.unwarped); /* blended needs more */
    mem = malloc(need);
    if (!mem) { die("out of memory (%zu bytes of instance)", need); goto done; }
    if ((st = sn_instance_init(mem, need, s.blob, &inst)) != SN_OK) {
        fprintf(stderr, PROG ": sn_instance_init: %s\n", sn_status_str(st)); goto done;
    }
    if (o.details_n && (n_details = details_apply(inst, o.details_n, o.blob_path, err, sizeof err)) < 0) { die("%s", err); goto done; }
    if (n_details && !o.quiet) printf("details: %ld active on the cut level (ids 0..%ld)\n", n_details, n_details - 1);
    if (o.iterations) sn_set_iterations(inst, (uint32_t)o.iterations);
    if (o.adapt_off) sn_set_adapt(inst, 0);
    if (o.unwarped && (st = sn_set_mode(inst, (sn_mode)o.unwarped)) != SN_OK) {
        fprintf(stderr, PROG ": sn_set_mode: %s\n", sn_status_str(st)); goto done;
    }
    if (o.compare) {   /* a second instance, stepped in lockstep in the other mode */
        mem2 = malloc(need);
        if (!mem2 || sn_instance_init(mem2, need, s.blob, &inst2) != SN_OK) { die("cannot create the comparison instance"); goto done; }
        if (o.iterations) sn_set_iterations(inst2, (uint32_t)o.iterations);
        sn_set_mode(inst2, o.unwarped ? SN_MODE_WARPED : SN_MODE_UNWARPED);
        if (o.rigs_off) controls_zero(inst2, s.blob, n_ctl);
    }
    if (o.rigs_off) controls_zero(inst, s.blob, n_ctl);
    if (o.compare_hits) {   /* the no-hit instance, stepped in lockstep: the clip without its impulses */
        mem2 = malloc(need);
        if (!mem2 || sn_instance_init(mem2, need, s.blob, &inst2) != SN_OK) { die("cannot create the no-hit instance"); goto done; }
        if (o.iterations) sn_set_iterations(inst2, (uint32_t)o.iterations);
        if (o.unwarped) sn_set_mode(inst2, (sn_mode)o.unwarped);
    }
    if (o.compare_rigs) {   /* the rigs-off instance, stepped in lockstep: abstract controls 0 */
        const sn_blob *b2 = s.blob;
        size_t need2 = need;
        n_ctl2 = n_ctl;
        if (o.rig_off_blob) {
            size_t n2 = 0;
            sn_blob_info i2;
            if (!(bytes2 = read_file(o.rig_off_blob, &n2, err, sizeof err))) { die("%s", err); goto done; }
            if ((st = sn_blob_validate(bytes2, n2, &blob2)) != SN_OK) {
                fprintf(stderr, PROG ": %s: invalid blob: %s\n", o.rig_off_blob, sn_status_str(st)); goto done;
            }
            sn_blob_get_info(blob2, &i2);
            if (i2.joints != s.info.joints || i2.vertices != s.info.vertices || i2.free_vertices != s.info.free_vertices ||
                i2.surface_vertices != s.info.surface_vertices || i2.triangles != s.info.triangles ||
                i2.timestep != s.info.timestep) {
                fprintf(stderr, PROG ": --rig-off-blob %s is not %s without its rigs: the skeleton, lattice, surface or "
                        "timestep differ\n", o.rig_off_blob, o.blob_path);
                goto done;
            }
            b2 = blob2;
            need2 = sn_instance_size_mode(blob2, (sn_mode)o.unwarped);
            n_ctl2 = i2.controls;
        }
        mem2 = malloc(need2);
        if (!mem2 || sn_instance_init(mem2, need2, b2, &inst2) != SN_OK) { die("cannot create the rigs-off instance"); goto done; }
        if (o.iterations) sn_set_iterations(inst2, (uint32_t)o.iterations);
        if (o.unwarped) sn_set_mode(inst2, (sn_mode)o.unwarped);
        controls_zero(inst2, b2, n_ctl2);
    }

    if (o.compare_details) {   /* the cut level without details and level 1, stepped in lockstep */
        const sn_blob *b3 = s.blob;
        size_t need3 = need;
        mem2 = malloc(need);
        if (!mem2 || sn_instance_init(mem2, need, s.blob, &inst2) != SN_OK) { die("cannot create the cut-level instance"); goto done; }
        if (o.iterations) sn_set_iterations(inst2, (uint32_t)o.iterations);
        if (o.unwarped) sn_set_mode(inst2, (sn_mode)o.unwarped);
        if (o.level1_blob) {
            size_t n3 = 0;
            sn_blob_info i3;
            if (!(bytes3 = read_file(o.level1_blob, &n3, err, sizeof err))) { die("%s", err); goto done; }
            if ((st = sn_blob_validate(bytes3, n3, &b3)) != SN_OK) {
                fprintf(stderr, PROG ": %s: invalid blob: %s\n", o.level1_blob, sn_status_str(st)); goto done;
            }
            sn_blob_get_info(b3, &i3);
            if (i3.joints != s.info.joints || i3.surface_vertices != s.info.surface_vertices ||
                i3.triangles != s.info.triangles || i3.timestep != s.info.timestep) {
                fprintf(stderr, PROG ": --level1-blob %s is not the character of %s: the skeleton, surface or timestep differ\n",
                        o.level1_blob, o.blob_path);
                goto done;
            }
            need3 = sn_instance_size_mode(b3, (sn_mode)o.unwarped);
        } else if (sn_lod_levels(s.blob) < 2) {
            fprintf(stderr, PROG ": --compare-details: %s carries one level; give the level-1 panel's blob with --level1-blob B\n", o.blob_path);
            goto done;
        }
        mem3 = malloc(need3);
        if (!mem3 || sn_instance_init(mem3, need3, b3, &inst3) != SN_OK) { die("cannot create the level-1 instance"); goto done; }
        if (o.iterations) sn_set_iterations(inst3, (uint32_t)o.iterations);
        if (o.unwarped) sn_set_mode(inst3, (sn_mode)o.unwarped);
        if (sn_lod_levels(b3) >= 2 && sn_set_lod(inst3, 1) != SN_OK) { die("sn_set_lod(level 1) refused"); goto done; }
        if (o.rigs_off) {
            sn_blob_info i3;
            sn_blob_get_info(b3, &i3);
            controls_zero(inst2, s.blob, n_ctl);
            controls_zero(inst3, b3, i3.controls);
        }
    }

    /* scratch */
    s.lattice = o.lattice; s.az = o.az; s.el = o.el; s.heat = o.heat; s.marks = o.marks;
    local = malloc(s.info.joints * sizeof *local);
    xf = malloc(s.info.joints * sizeof *xf);
    rest_xf = malloc(s.info.joints * sizeof *rest_xf);
    s.surf = malloc((s.info.surface_vertices + 1) * sizeof *s.surf);
    s.latt = malloc(s.info.vertices * sizeof *s.latt);
    s.pos = malloc((s.info.surface_vertices + 1) * 3 * sizeof(float));
    s.lpos = malloc(s.info.vertices * 3 * sizeof(float));
    s.tri = malloc((s.info.triangles + 1) * 3 * sizeof(uint32_t));
    times = malloc(((size_t)n_frames + 1) * sizeof(double));
    cpu = malloc(((size_t)n_frames + 1) * sizeof(double));
    if (!local || !xf || !rest_xf || !s.surf || !s.latt || !s.pos || !s.lpos || !s.tri || !times || !cpu) { die("out of memory"); goto done; }
    if ((o.stats_csv || o.plot) && !(fst = malloc(((size_t)n_frames + 1) * sizeof *fst))) { die("out of memory"); goto done; }
    if ((o.stats_csv || o.plot) && n_ctl && !(fctl = malloc(((size_t)n_frames + 1) * n_ctl * sizeof *fctl))) { die("out of memory"); goto done; }
    for (t = 0; t < s.info.triangles; t++) sn_get_triangle(s.blob, t, s.tri + 3 * t);
    /* segment meshes: node buffers, the floor, impulses checked against the blob */
    s.segments = !o.no_segments;
    s.n_sm = sn_segment_mesh_count(s.blob);
    s.sm = malloc((s.n_sm + 1) * sizeof *s.sm);
    s.sm_first = malloc((s.n_sm + 1) * sizeof *s.sm_first);
    if (!s.sm || !s.sm_first) { die("out of memory"); goto done; }
    for (i = 0; i < s.n_sm; i++) {
        sn_segment_mesh_info(s.blob, i, &s.sm[i]);
        s.sm_first[i] = s.n_snodes;
        s.n_snodes += s.sm[i].nodes;
    }
    s.snode = malloc((s.n_snodes + 1) * sizeof *s.snode);
    s.spos = calloc((size_t)s.n_snodes * 3 + 3, sizeof(float));
    if (!s.snode || !s.spos) { die("out of memory"); goto done; }
    for (i = 0; i < (uint32_t)o.n_imp; i++)
        if (o.imp[i].mesh >= s.n_sm || o.imp[i].node >= s.sm[o.imp[i].mesh].nodes) {
            fprintf(stderr, PROG ": --seg-impulse: %s has %u segment mesh(es): no node %u of mesh %u\n", o.blob_path, s.n_sm,
                    o.imp[i].node, o.imp[i].mesh);
            goto done;
        }
    if (o.have_floor) {
        sn_vec3 up;
        up.x = 0; up.y = R(1.0); up.z = 0;
        if (sn_set_segment_floor(inst, up, R(o.floor_y)) != SN_OK) { die("--seg-floor: refused"); goto done; }
        if (inst2) sn_set_segment_floor(inst2, up, R(o.floor_y));
        if (inst3) sn_set_segment_floor(inst3, up, R(o.floor_y));
    }
    /* constraints and colliders: pins where the surface is before the first step */
    s.have_ground = o.have_ground;
    s.ground_y = (float)o.ground_y;
    if (o.n_pin || o.have_belt) {
        sn_constraint *cs;
        uint32_t nc = 0, cap = s.info.max_constraints, nb = 0;
        if (!cap) { fprintf(stderr, PROG ": --pin/--belt: %s bakes no constraints (description line 'constraints N')\n", o.blob_path); goto done; }
        if (have_clip && clip.n_pins) {   /* the clip's pin channels come after the flags' */
            if ((uint32_t)o.n_pin + clip.n_pins > cap) {
                fprintf(stderr, PROG ": --pin and %s: %u pinned vertices and %u clip pin channel(s) exceed the blob's max_constraints %u\n",
                        o.clip_path, (unsigned)o.n_pin, (unsigned)clip.n_pins, cap);
                goto done;
            }
            cap -= clip.n_pins;   /* the belt takes what is left */
        }
        cs = calloc(cap + 1, sizeof *cs);
        s.pins = calloc(cap + 1, sizeof *s.pins);
        if (!cs || !s.pins) { free(cs); die("out of memory"); goto done; }
        sn_get_surface(inst, s.surf, 0, s.info.surface_vertices);
        for (i = 0; i < (uint32_t)o.n_pin && nc < cap; i++) {
            if (o.pin[i] >= s.info.surface_vertices) {
                fprintf(stderr, PROG ": --pin %u: %s has %u surface vertices\n", o.pin[i], o.blob_path, s.info.surface_vertices);
                free(cs); goto done;
            }
            cs[nc].at = SN_AT_SURFACE; cs[nc].vertex = o.pin[i]; cs[nc].target = s.surf[o.pin[i]];
            s.pins[nc] = o.pin[i];
            nc++;
        }
        if (o.have_belt) {   /* the vertices near the plane x = X, evenly picked up to the remaining constraints */
            uint32_t left = cap - nc, taken = 0, seen = 0;
            for (i = 0; i < s.info.surface_vertices; i++) if (fabs(D(s.surf[i].x) - o.belt_x) < o.belt_w) nb++;
            for (i = 0; i < s.info.surface_vertices && taken < left; i++) {
                if (!(fabs(D(s.surf[i].x) - o.belt_x) < o.belt_w)) continue;
                seen++;
                if (nb > left && (uint64_t)seen * left / nb == (uint64_t)(seen - 1) * left / nb) continue; /* every nb/left-th */
                cs[nc].at = SN_AT_SURFACE; cs[nc].vertex = i; cs[nc].target = s.surf[i]; cs[nc].axes = SN_AXIS_Y | SN_AXIS_Z;
                s.pins[nc++] = i;
                taken++;
            }
            if (!o.quiet) printf("belt: %u of %u surface vertices within %.3g of x = %.3g pinned in y and z\n", taken, nb, o.belt_w, o.belt_x);
        }
        s.n_pins = nc;
        st = sn_set_constraints(inst, cs, nc);
        if (inst2) sn_set_constraints(inst2, cs, nc);
        if (inst3) sn_set_constraints(inst3, cs, nc);
        flag_cs = cs; flag_nc = nc;   /* kept: set again with the clip's pins each step */
        if (st != SN_OK) { fprintf(stderr, PROG ": sn_set_constraints: %s\n", sn_status_str(st)); goto done; }
    }
    if ((o.have_ground || o.n_sph) && !s.info.max_colliders) {
        fprintf(stderr, PROG ": --ground/--sphere: %s bakes no colliders (description line 'colliders N CONTACTS')\n", o.blob_path); goto done;
    }
    if (have_clip && clip.n_colliders && (uint32_t)(o.have_ground + o.n_sph) + clip.n_colliders > s.info.max_colliders) {
        fprintf(stderr, PROG ": --ground/--sphere and %s: %d flag collider(s) and %u clip collider channel(s) exceed the blob's max_colliders %u\n",
                o.clip_path, o.have_ground + o.n_sph, (unsigned)clip.n_colliders, s.info.max_colliders);
        goto done;
    }
    if (have_clip && clip.n_pins && !(all_cs = calloc((size_t)flag_nc + clip.n_pins + 1, sizeof *all_cs))) { die("out of memory"); goto done; }
    memset(clip_hold, 0, sizeof clip_hold);
    s.n_sph = o.n_sph;
    pictures = o.png || o.sheet || o.compare || o.compare_rigs || o.compare_hits || o.compare_details || o.apng;
    if (o.lattice && lattice_edges(&s, bytes)) { die("out of memory"); goto done; }
    if ((pictures || o.heat > 0) && skin_setup(&s, bytes)) { die("out of memory"); goto done; }
    if (o.marks && !(s.cr_list = malloc(((size_t)s.info.surface_vertices + 1) * sizeof *s.cr_list))) { die("out of memory"); goto done; }
    /* rest pose: identity local rotations */
    for (i = 0; i < s.info.joints; i++) {
        local[i].x = local[i].y = local[i].z = 0;
#ifdef SN_FLOAT
        local[i].w = 1.0f;
#else
        local[i].w = (sn_real)1 << SN_QUAT_FRAC;
#endif
    }
    sn_pose_from_local(s.blob, local, NULL, rest_xf);
    s.pose = rest_xf;
    if (pictures && !s.info.triangles) {
        fprintf(stderr, PROG ": %s has no triangles: cannot draw pictures\n", o.blob_path); goto done;
    }
    /* the camera frames the surface at rest and rigidly skinned in every
       pose of the run (each distinct clip time once), the same for every frame */
    if (pictures) {
        long n_pose = 0;
        float m = 0;
        int lat = s.lattice;
        s.lattice = 0;
        fetch(&s, inst);
        s.lattice = lat;
        for (k = 0; k < 3; k++) { s.lo[k] = 1e30f; s.hi[k] = -1e30f; }
        for (i = 0; i < s.info.surface_vertices; i++)
            for (k = 0; k < 3; k++) {
                if (s.pos[3 * i + (uint32_t)k] < s.lo[k]) s.lo[k] = s.pos[3 * i + (uint32_t)k];
                if (s.pos[3 * i + (uint32_t)k] > s.hi[k]) s.hi[k] = s.pos[3 * i + (uint32_t)k];
            }
        for (i = 0; s.segments && i < s.n_snodes; i++)   /* and the segment meshes at rest */
            for (k = 0; k < 3; k++) {
                if (s.spos[3 * i + (uint32_t)k] < s.lo[k]) s.lo[k] = s.spos[3 * i + (uint32_t)k];
                if (s.spos[3 * i + (uint32_t)k] > s.hi[k]) s.hi[k] = s.spos[3 * i + (uint32_t)k];
            }
        if (have_clip && !o.have_box) {
            int32_t hq = sn_clip_timestep_q16(s.blob);
            n_pose = (long)(((int64_t)clip.duration + hq - 1) / hq);
            if (n_pose > n_frames) n_pose = n_frames;
            for (k = 1; k <= n_pose; k++) {
                sn_clip_pose(&clip, s.blob, (uint32_t)k, local, xf);
                skinned_box(&s, xf, s.lo, s.hi);
            }
        }
        /* a margin for the flesh's lag and sag: 3% of the largest extent */
        for (k = 0; k < 3; k++) if (s.hi[k] - s.lo[k] > m) m = s.hi[k] - s.lo[k];
        for (k = 0; k < 3; k++) {
            s.flo[k] = o.have_box ? o.box[k] : s.lo[k] - 0.03f * m;
            s.fhi[k] = o.have_box ? o.box[3 + k] : s.hi[k] + 0.03f * m;
        }
        if (!o.quiet && !o.have_box)
            printf("camera box: %.3g,%.3g,%.3g,%.3g,%.3g,%.3g (surface at rest and in %ld clip poses, plus 3%%)\n",
                   s.flo[0], s.flo[1], s.flo[2], s.fhi[0], s.fhi[1], s.fhi[2], n_pose);
    }
    if (!o.quiet)
        printf("%s: %u lattice vertices (%u free), %u cells, %u joints, %u surface vertices, %u triangles, "
               "h = %.4f s, CG %u iterations, %s, instance %zu bytes, blob %u bytes\n",
               o.blob_path, s.info.vertices, s.info.free_vertices, s.info.cells, s.info.joints,
               s.info.surface_vertices, s.info.triangles, h_s,
               o.iterations ? (uint32_t)o.iterations : s.info.cg_iters_default,
               o.unwarped == SN_MODE_BLENDED ? "blended" : o.unwarped ? "unwarped" : "warped", need, s.info.blob_bytes);

    /* contact sheet: 12 frames spread over the run */
    if (o.sheet) {
        int pw = o.have_size ? o.w : 320, ph = o.have_size ? o.h : 240;
        if (rs_image_alloc(&sheet, SHEET_COLS * pw, SHEET_ROWS * ph) || rs_image_alloc(&panel, pw, ph)) { die("out of memory"); goto done; }
        for (k = 0; k < SHEET_COLS * SHEET_ROWS; k++)
            sheet_at[k] = (long)(((double)k + 1) * (double)n_frames / (SHEET_COLS * SHEET_ROWS) + 0.5);
        /* fewer steps than panels: some show step 0, the rest state */
        for (k = 0; k < SHEET_COLS * SHEET_ROWS; k++)
            if (sheet_at[k] == 0) {
                if (render(&s, inst, &panel, "t = 0.00 s", k == 0 ? o.title : NULL)) { die("out of memory"); goto done; }
                rs_blit(&sheet, (int)(k % SHEET_COLS) * panel.w, (int)(k / SHEET_COLS) * panel.h, &panel);
            }
    }

    /* --out-gltf: the state before the first step, then every out_stride-th step;
       --apng: every apng_stride-th step (at most 120 frames each) */
    if (o.out_gltf) {
        out_stride = n_frames > 120 ? (n_frames + 119) / 120 : 1;
        if (n_frames < 1) { die("--out-gltf needs at least one step"); goto done; }
        if (pg_out_begin(&gout, o.out_gltf, o.blob_path, s.info.surface_vertices, s.tri, s.info.triangles,
                         (uint32_t)(n_frames / out_stride), (double)out_stride * h_s, err, sizeof err)) { die("%s", err); goto done; }
        fetch(&s, inst);
        pg_out_frame(&gout, s.pos);
    }
    if (o.apng) {
        int pw = o.have_size ? o.w : 320, ph = o.have_size ? o.h : 240;
        double dl;
        apng_stride = n_frames > 120 ? (n_frames + 119) / 120 : 1;
        dl = (double)apng_stride * h_s * 6000.0 + 0.5;
        if (n_frames < 1) { die("--apng needs at least one step"); goto done; }
        if (rs_image_alloc(&aframe, pw, ph)) { die("out of memory"); goto done; }
        if (png_anim_begin(&apng, o.apng, pw, ph, (uint32_t)(n_frames / apng_stride), dl < 65535 ? (uint16_t)dl : 65535,
                           dl < 65535 ? 6000 : 1000, err, sizeof err)) { die("%s", err); goto done; }
    }

    /* frame 0 (the state before the first step) only when asked for */
    if (obj_sel && obj_sel[0]) {
        snprintf(path, sizeof path, "%s/frame_%04d.obj", o.obj_dir, 0);
        fetch(&s, inst);
        if (write_obj(&s, path, err, sizeof err)) { die("%s", err); goto done; }
    }

    /* run */
    for (k = 1; k <= n_frames; k++) {
        double t0, t1, c0, c1;
        if (have_clip) sn_clip_pose(&clip, s.blob, (uint32_t)k, local, xf);
        else memcpy(xf, rest_xf, s.info.joints * sizeof *xf);
        s.pose = xf;
        sn_set_pose(inst, xf, s.info.joints);
        if (!o.rigs_off) controls_step(inst, s.blob, have_clip ? &clip : NULL, (uint32_t)k, held, o.n_held, 1);
        for (i = 0; i < (uint32_t)o.n_imp; i++)
            if (o.imp[i].step == k) {
                sn_vec3 j;
                j.x = R(o.imp[i].j[0]); j.y = R(o.imp[i].j[1]); j.z = R(o.imp[i].j[2]);
                if (sn_apply_segment_impulse(inst, o.imp[i].mesh, o.imp[i].node, j) != SN_OK) { die("--seg-impulse: refused"); goto done; }
                if (inst2) sn_apply_segment_impulse(inst2, o.imp[i].mesh, o.imp[i].node, j);
                if (inst3) sn_apply_segment_impulse(inst3, o.imp[i].mesh, o.imp[i].node, j);
            }
        if (o.have_ground || o.n_sph || (have_clip && clip.n_colliders)) {
            /* the colliders at the start of step k (spheres moved since step 1): the flags', then the clip's */
            sn_collider cl[5 + SN_CLIP_MAX_CHANNELS];
            int q, nq = 0;
            memset(cl, 0, sizeof cl);
            if (o.have_ground) { cl[0].kind = SN_COLLIDER_PLANE; cl[0].a.y = R(o.ground_y); cl[0].b.y = R(1.0); nq = 1; }
            for (q = 0; q < o.n_sph; q++, nq++) {
                double tk = (double)(k - 1) * h_s;
                cl[nq].kind = SN_COLLIDER_SPHERE;
                cl[nq].a.x = R(o.sph[q][0] + o.sph[q][4] * tk); cl[nq].a.y = R(o.sph[q][1] + o.sph[q][5] * tk);
                cl[nq].a.z = R(o.sph[q][2] + o.sph[q][6] * tk);
                cl[nq].radius = R(o.sph[q][3]);
                cl[nq].velocity.x = R(o.sph[q][4]); cl[nq].velocity.y = R(o.sph[q][5]); cl[nq].velocity.z = R(o.sph[q][6]);
                s.sph[q][0] = (float)(o.sph[q][0] + o.sph[q][4] * (double)k * h_s); /* drawn where it is after the step */
                s.sph[q][1] = (float)(o.sph[q][1] + o.sph[q][5] * (double)k * h_s);
                s.sph[q][2] = (float)(o.sph[q][2] + o.sph[q][6] * (double)k * h_s);
                s.sph[q][3] = (float)o.sph[q][3];
            }
            if (have_clip) nq += (int)sn_clip_colliders(&clip, s.blob, (uint32_t)k, cl + nq, SN_CLIP_MAX_CHANNELS);
            if (sn_set_colliders(inst, cl, (uint32_t)nq) != SN_OK) { die("sn_set_colliders: refused (the blob's max_colliders is %u)", s.info.max_colliders); goto done; }
            if (inst2) sn_set_colliders(inst2, cl, (uint32_t)nq);
            if (inst3) sn_set_colliders(inst3, cl, (uint32_t)nq);
        }
        if (all_cs) {   /* the clip's pins (targets at the end of step k) after --pin/--belt */
            uint32_t nc = flag_nc;
            if (flag_nc) memcpy(all_cs, flag_cs, flag_nc * sizeof *all_cs);
            nc += sn_clip_constraints(&clip, s.blob, (uint32_t)k, inst, clip_hold, all_cs + nc, clip.n_pins);
            if ((st = sn_set_constraints(inst, all_cs, nc)) != SN_OK) { die("sn_set_constraints (%s pins): %s", o.clip_path, sn_status_str(st)); goto done; }
            if (inst2) sn_set_constraints(inst2, all_cs, nc);
            if (inst3) sn_set_constraints(inst3, all_cs, nc);
        }
        for (i = 0; i < (uint32_t)o.n_lod; i++)   /* level switches before this step */
            if (o.lod_step[i] == k && sn_set_lod(inst, o.lod_level[i]) != SN_OK) { die("--lod %ld:%u: sn_set_lod refused (the blob has %u level(s): bake with 'levels 2')", k, o.lod_level[i], sn_lod_levels(s.blob)); goto done; }
        c0 = now_us(CLOCK_THREAD_CPUTIME_ID);
        t0 = now_us(CLOCK_MONOTONIC);
        sn_step(inst);
        t1 = now_us(CLOCK_MONOTONIC);
        c1 = now_us(CLOCK_THREAD_CPUTIME_ID);
        times[k - 1] = t1 - t0;
        cpu[k - 1] = c1 - c0;
        {   /* adaptation: active detail vertices per step (sn_stats) */
            sn_stats as;
            if (sn_get_stats(inst, &as) == SN_OK && as.adapt_on) {
                ad_sum += as.adapt_active; ad_steps++;
                if (as.adapt_active > ad_max) ad_max = as.adapt_active;
            }
        }
        if (inst2) {
            if ((o.compare && !o.rigs_off) || o.compare_hits || (o.compare_details && !o.rigs_off))
                controls_step(inst2, s.blob, have_clip ? &clip : NULL, (uint32_t)k, held, o.n_held, !o.compare_hits);
            sn_set_pose(inst2, xf, s.info.joints);
            sn_step(inst2);
        }
        if (inst3) {   /* level 1: the clip's controls only on the same blob (another blob's indices differ) */
            if (!o.rigs_off && !o.level1_blob) controls_step(inst3, s.blob, have_clip ? &clip : NULL, (uint32_t)k, held, o.n_held, 1);
            sn_set_pose(inst3, xf, s.info.joints);
            sn_step(inst3);
        }
        if (fst || (o.health && k % o.health == 0)) {
            sn_stats hs;
            sn_get_stats(inst, &hs);
            if (fst) {
                fst[k - 1].disp = D(hs.disp); fst[k - 1].energy = D(hs.energy);
                fst[k - 1].saturations = hs.saturations; fst[k - 1].bound_steps = hs.bound_steps;
                fst[k - 1].limit_clamps = hs.limit_clamps;
            }
            if (fctl)
                for (i = 0; i < n_ctl; i++) {
                    sn_real v = 0;
                    sn_get_control(inst, i, &v);
                    fctl[(size_t)(k - 1) * n_ctl + i] = D(v);
                }
            if (o.health && k % o.health == 0)
                printf("health frame %ld: t %.3f s, disp %.4g cells, energy %.4g J, saturations %u\n",
                       k, (double)k * h_s, F(hs.disp), F(hs.energy), hs.saturations);
        }
        if (o.obj_dir && (!obj_sel || obj_sel[k])) {
            snprintf(path, sizeof path, "%s/frame_%04ld.obj", o.obj_dir, k);
            fetch(&s, inst);
            if (write_obj(&s, path, err, sizeof err)) { die("%s", err); goto done; }
        }
        if (o.out_gltf && k % out_stride == 0 && k / out_stride <= (long)gout.frames) {
            fetch(&s, inst);
            pg_out_frame(&gout, s.pos);
        }
        if (o.apng && k % apng_stride == 0 && (uint32_t)(k / apng_stride) <= apng.frames) {
            char lab[64];
            snprintf(lab, sizeof lab, "t = %.2f s", (double)k * h_s);
            if (render(&s, inst, &aframe, lab, o.title)) { die("out of memory"); goto done; }
            if (png_anim_frame(&apng, aframe.rgb, err, sizeof err)) { die("%s", err); goto done; }
        }
        if (o.sheet) {
            int p;
            for (p = 0; p < SHEET_COLS * SHEET_ROWS; p++)
                if (sheet_at[p] == k) {
                    char lab[64];
                    snprintf(lab, sizeof lab, "t = %.2f s", (double)k * h_s);
                    if (render(&s, inst, &panel, lab, p == 0 ? o.title : NULL)) { die("out of memory"); goto done; }
                    rs_blit(&sheet, (p % SHEET_COLS) * panel.w, (p / SHEET_COLS) * panel.h, &panel);
                }
        }
    }

    /* timing: sn_step only */
    if (n_frames > 0) {
        sn_stats stats;
        long p99 = (long)(0.99 * (double)(n_frames - 1) + 0.5);
        qsort(times, (size_t)n_frames, sizeof(double), cmp_double);
        qsort(cpu, (size_t)n_frames, sizeof(double), cmp_double);
        sn_get_stats(inst, &stats);
        printf("step: median %.1f us, p99 %.1f us, max %.1f us over %ld steps (%s, %u CG iterations, %u saturations); "
               "thread CPU time: median %.1f us, p99 %.1f us\n",
               times[n_frames / 2], times[p99], times[n_frames - 1], n_frames,
               SN_FLAVOUR ? "float" : "fixed", stats.iterations, stats.saturations, cpu[n_frames / 2], cpu[p99]);
        if (ad_steps)
            printf("adapt: active detail vertices mean %.1f, max %u over %ld steps; refines %u, coarsens %u, overflow %u\n",
                   ad_sum / (double)ad_steps, ad_max, ad_steps, stats.adapt_refines, stats.adapt_coarsens, stats.adapt_overflow);
        printf("health: saturations %u, bound steps %u, limit clamps %u (last step; %u steps with clamps), "
               "largest displacement %.4g cells, largest energy %.4g J (last %.4g J)\n",
               stats.saturations, stats.bound_steps, stats.limit_clamps, stats.limit_steps,
               F(stats.disp_max), F(stats.energy_max), F(stats.energy));
        if (stats.saturations)
            fprintf(stderr, PROG ": warning: %u %s values were clamped (saturated) in this run; "
                    "the motion is not trustworthy\n", stats.saturations, SN_FLAVOUR ? "runaway float" : "fixed-point");
        if (stats.bound_steps)
            fprintf(stderr, PROG ": warning: a baked bound was exceeded in %u of %ld steps\n", stats.bound_steps, n_frames);
    } else printf("step: no steps run\n");
    if (o.out_gltf) {
        size_t nb = 0;
        int mapped = gout.have_map;
        uint32_t nfr = gout.frames;
        if (pg_out_end(&gout, &nb, err, sizeof err)) { die("%s", err); goto done; }
        if (!o.quiet) printf("wrote %s (%u morph-target frames every %ld step(s), %s vertex order, %zu bytes)\n", o.out_gltf, nfr,
                             out_stride, mapped ? "the original glTF's" : "the runtime surface's", nb);
    }
    if (o.apng) {
        size_t nb;
        uint32_t nfr = apng.frames;
        if (png_anim_end(&apng, err, sizeof err)) { die("%s", err); goto done; }
        nb = apng.bytes;
        if (!o.quiet) printf("wrote %s (%u frames of %dx%d, %u/%u s each, %zu bytes)\n", o.apng, nfr, aframe.w, aframe.h,
                             apng.delay_num, apng.delay_den, nb);
    }
    if (o.stats_csv) {
        if (write_stats_csv(o.stats_csv, fst, n_frames, h_s, s.blob, n_ctl, fctl, err, sizeof err)) { die("%s", err); goto done; }
        if (!o.quiet) printf("wrote %s\n", o.stats_csv);
    }
    if (o.plot) {
        char ttl[160];
        snprintf(ttl, sizeof ttl, "%s", o.title ? o.title : o.clip_path ? o.clip_path : o.blob_path);
        if (write_plot(o.plot, fst, n_frames, h_s, o.have_size ? o.w : 800, o.have_size ? o.h : 500, ttl,
                       s.blob, n_ctl, fctl, err, sizeof err)) {
            die("%s", err); goto done;
        }
        if (!o.quiet) printf("wrote %s\n", o.plot);
    }

    /* pictures */
    if (o.png) {
        char lab[64];
        if (rs_image_alloc(&cmp, o.w, o.h)) { die("out of memory"); goto done; }
        snprintf(lab, sizeof lab, "t = %.2f s", (double)n_frames * h_s);
        if (render(&s, inst, &cmp, o.title ? o.title : lab, o.title ? lab : NULL) ||
            png_write(o.png, cmp.rgb, cmp.w, cmp.h, err, sizeof err)) { die("%s", err); goto done; }
        rs_image_free(&cmp);
        if (!o.quiet) printf("wrote %s\n", o.png);
    }
    if (o.sheet) {
        const uint8_t line[3] = {255, 255, 255};
        for (k = 1; k < SHEET_COLS; k++) rs_fill(&sheet, (int)k * panel.w - 1, 0, 2, sheet.h, line);
        for (k = 1; k < SHEET_ROWS; k++) rs_fill(&sheet, 0, (int)k * panel.h - 1, sheet.w, 2, line);
        if (png_write(o.sheet, sheet.rgb, sheet.w, sheet.h, err, sizeof err)) { die("%s", err); goto done; }
        if (!o.quiet) printf("wrote %s\n", o.sheet);
    }
    if (o.compare) {
        rs_image pane;
        void *mem0 = malloc(need);
        sn_instance *rest = NULL;
        const sn_instance *warped = o.unwarped ? inst2 : inst, *unwarped = o.unwarped ? inst : inst2;
        const uint8_t line[3] = {255, 255, 255};
        char lab[64];
        int pw = o.w * 3 / 4 > 240 ? o.w * 3 / 4 : 240, ph = pw * 3 / 4;
        if (!mem0 || sn_instance_init(mem0, need, s.blob, &rest) != SN_OK ||
            rs_image_alloc(&cmp, 3 * pw, ph) || rs_image_alloc(&pane, pw, ph)) { free(mem0); die("out of memory"); goto done; }
        snprintf(lab, sizeof lab, "t = %.2f s", (double)n_frames * h_s);
        s.pose = rest_xf;
        render(&s, rest, &pane, "rest", NULL);
        s.pose = xf;
        rs_blit(&cmp, 0, 0, &pane);
        render(&s, unwarped, &pane, o.unwarped == SN_MODE_BLENDED ? "blended (local linear)" : "unwarped (global linear)", lab);
        rs_blit(&cmp, pw, 0, &pane);
        render(&s, warped, &pane, "warped", lab);
        rs_blit(&cmp, 2 * pw, 0, &pane);
        rs_fill(&cmp, pw - 1, 0, 2, ph, line);
        rs_fill(&cmp, 2 * pw - 1, 0, 2, ph, line);
        rs_image_free(&pane);
        free(mem0);
        if (png_write(o.compare, cmp.rgb, cmp.w, cmp.h, err, sizeof err)) { die("%s", err); goto done; }
        if (!o.quiet) printf("wrote %s\n", o.compare);
    }
    if (o.compare_rigs || o.compare_hits) {
        const char *out_path = o.compare_hits ? o.compare_hits : o.compare_rigs;
        rs_image pane;
        void *mem0 = malloc(need);
        sn_instance *rest = NULL;
        const uint8_t line[3] = {255, 255, 255};
        char lab[64], lab_on[160];
        float heat = s.heat;
        size_t n = 0;
        int pw = o.w * 3 / 4 > 240 ? o.w * 3 / 4 : 240, ph = pw * 3 / 4;
        memset(&pane, 0, sizeof pane);
        if (!mem0 || sn_instance_init(mem0, need, s.blob, &rest) != SN_OK ||
            rs_image_alloc(&cmp, 3 * pw, ph) || rs_image_alloc(&pane, pw, ph) ||
            (heat > 0 && !(refpos = malloc(((size_t)s.info.surface_vertices + 1) * 3 * sizeof(float))))) {
            free(mem0); rs_image_free(&pane); die("out of memory"); goto done;
        }
        snprintf(lab, sizeof lab, "t = %.2f s", (double)n_frames * h_s);
        lab_on[0] = 0;   /* the controls that are not 0 */
        for (i = 0; i < n_ctl && n < sizeof lab_on; i++) {
            sn_real v = 0;
            sn_get_control(inst, i, &v);
            if (D(v) != 0)
                n += (size_t)snprintf(lab_on + n, sizeof lab_on - n, "%s%s %.3g", n ? ", " : "", sn_control_name(s.blob, i), D(v));
        }
        if (!n) snprintf(lab_on, sizeof lab_on, "controls 0");
        s.heat = 0;
        s.pose = rest_xf;
        render(&s, rest, &pane, "rest", NULL);
        rs_blit(&cmp, 0, 0, &pane);
        s.pose = xf;
        render(&s, inst2, &pane, o.compare_hits ? "no hit" : o.rig_off_blob ? "rigs off (baked without)" : "rigs off (controls 0)", lab);
        rs_blit(&cmp, pw, 0, &pane);
        if (heat > 0) {   /* colour the rigs-on flesh by how far the rigs moved it */
            memcpy(refpos, s.pos, (size_t)s.info.surface_vertices * 3 * sizeof(float));
            s.ref = refpos;
            s.heat = heat;
        }
        render(&s, inst, &pane, o.compare_hits ? "hit" : "rigs on", o.compare_hits ? NULL : lab_on);
        rs_blit(&cmp, 2 * pw, 0, &pane);
        s.ref = NULL;
        s.heat = heat;
        rs_fill(&cmp, pw - 1, 0, 2, ph, line);
        rs_fill(&cmp, 2 * pw - 1, 0, 2, ph, line);
        rs_image_free(&pane);
        free(mem0);
        if (png_write(out_path, cmp.rgb, cmp.w, cmp.h, err, sizeof err)) { die("%s", err); goto done; }
        if (!o.quiet) printf("wrote %s\n", out_path);
    }
    if (o.compare_details && compare_details(&s, &o, inst, inst2, inst3, n_details, (double)n_frames * h_s, &cmp)) goto done;
    if (o.hash) printf("hash: %016llx\n", (unsigned long long)sn_state_hash(inst));
    rc = 0;
done:
    rs_image_free(&sheet); rs_image_free(&panel); rs_image_free(&cmp); rs_image_free(&aframe);
    pg_out_free(&gout); png_anim_abort(&apng); free(gltf_clip);
    free(bytes); free(mem); free(mem2); free(local); free(xf); free(rest_xf); free(times); free(cpu);
    free(s.surf); free(s.latt); free(s.pos); free(s.lpos); free(s.tri); free(s.edges); free(s.pins);
    free(s.sm); free(s.sm_first); free(s.snode); free(s.spos);
    free(s.rest); free(s.skin); free(s.dev); free(s.col); free(obj_sel); free(fst);
    free(fctl); free(bytes2); free(mem3); free(bytes3); free(refpos); free(s.cr_list); free(flag_cs); free(all_cs);
    return rc;
}
