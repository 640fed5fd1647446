/* play.c -- sinew-play: desktop player for Sinew blobs.
 * Loads a blob, plays a clip through the runtime, times sn_step, writes OBJ
 * frames and PNG pictures. Same source for the fixed (sinew-play) and the
 * float (sinew-play-float, -DSN_FLOAT) runtime. */
#define _POSIX_C_SOURCE 200809L
#include "sinew.h"
#include "sn_format.h"
#include "sn_clip.h"
#include "raster.h"
#include "png.h"
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
#else
#define PROG "sinew-play"
static float F(sn_real v) { return (float)v / 65536.0f; }
#endif

static void usage(FILE *f) {
    fprintf(f,
        "usage: " PROG " BLOB [options]\n"
        "Plays a clip on a baked Sinew character and reports the step time.\n"
        "  --clip CLIP        keyframed skeleton clip (ports/common/CLIP.md); default: rest pose\n"
        "  --frames N         steps to run (default: one clip length, or 60 without a clip)\n"
        "  --iterations N     CG iterations per step (1..blob maximum; default: blob's)\n"
        "  --unwarped         global linear FEM (all frames R = I), seed 000 fig. 5\n"
        "  --obj-dir DIR      write DIR/frame_NNNN.obj after every step (deformed surface)\n"
        "  --png FILE         picture of the last frame\n"
        "  --sheet FILE       contact sheet: 12 frames over the run, 4x3 grid\n"
        "  --compare FILE     rest | unwarped | warped at the last frame, side by side\n"
        "  --lattice          draw the control lattice (skeleton vertices in red)\n"
        "  --heat D           colour the flesh by its distance from rigid skinning (red at D mesh units)\n"
        "  --size WxH         picture size for --png (default 640x480)\n"
        "  --view AZ,EL       camera azimuth, elevation in degrees (default 30,15)\n"
        "  --frame-box X0,Y0,Z0,X1,Y1,Z1  box the camera frames, model space (mesh units relative to the root joint; default: rest surface)\n"
        "  --title TEXT       caption on the pictures\n"
        "  --hash             end with 'hash: <16 hex>' (sn_state_hash of the final state)\n"
        "  --quiet            only errors, timing and hash\n"
        "  --help\n"
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
    float lo[3], hi[3];         /* rest surface box: the camera's frame */
    float flo[3], fhi[3];       /* box the camera frames (default: lo, hi) */
    float az, el;
    int lattice;
    /* --heat: colour by distance from the rigidly skinned lattice */
    float heat;                 /* mesh units drawn at full colour; 0 = off */
    float *rest;                /* lattice rest positions, model space, mesh units */
    const unsigned char *frames, *cells, *embed;
    float *dev, *col;           /* per lattice vertex (3), per surface vertex (3) */
    const sn_xform *pose;       /* pose of the state being drawn */
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
    uint32_t i;
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

static const unsigned char *section(const unsigned char *bytes, int sec, uint32_t *count) {
    const unsigned char *ent = bytes + SN_H_SECTIONS + (size_t)sec * SN_SECTION_ENTRY;
    if (count) *count = rd_u32(ent + 8);
    return bytes + rd_u32(ent);
}

/* Rest lattice, frames, cells and embedding from the validated blob
 * (runtime/BLOB.md). Reals are little-endian like this host. */
static int heat_setup(scene *s, const unsigned char *bytes) {
    const unsigned char *rest = section(bytes, SN_SEC_REST, NULL);
    float unit = (float)ldexp(1.0, (int)(signed char)bytes[SN_H_LEN_SHIFT]);
    uint32_t i;
    s->frames = section(bytes, SN_SEC_FRAMES, NULL);
    s->cells = section(bytes, SN_SEC_CELLS, NULL);
    s->embed = section(bytes, SN_SEC_EMBED, NULL);
    s->rest = malloc((size_t)s->info.vertices * 3 * sizeof(float));
    s->dev = malloc((size_t)s->info.vertices * 3 * sizeof(float));
    s->col = malloc(((size_t)s->info.surface_vertices + 1) * 3 * sizeof(float));
    if (!s->rest || !s->dev || !s->col) return -1;
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

/* Per surface vertex: how far the simulated flesh is from where rigid
 * skinning by the lattice frames (R_i x_i + c_i, BLOB.md FRAMES) would put it:
 * the secondary motion (plus the static sag under gravity). */
static void heat_colours(scene *s) {
    uint32_t i, k;
    for (i = 0; i < s->info.vertices; i++) {
        const unsigned char *f = s->frames + 4 * (size_t)i;
        const sn_xform *b1 = &s->pose[f[0]], *b2 = &s->pose[f[1]];
        float w = (float)(f[2] | f[3] << 8) / 32768.0f, r[3];
        fq q = fq_slerp(to_fq(b1->rot), to_fq(b2->rot), w);
        fq_rotate(q, s->rest + 3 * i, r);
        s->dev[3 * i] = s->lpos[3 * i] - (r[0] + (1 - w) * F(b1->pos.x) + w * F(b2->pos.x));
        s->dev[3 * i + 1] = s->lpos[3 * i + 1] - (r[1] + (1 - w) * F(b1->pos.y) + w * F(b2->pos.y));
        s->dev[3 * i + 2] = s->lpos[3 * i + 2] - (r[2] + (1 - w) * F(b1->pos.z) + w * F(b2->pos.z));
    }
    for (i = 0; i < s->info.surface_vertices; i++) {
        const unsigned char *e = s->embed + 8 * (size_t)i;
        const unsigned char *cell = s->cells + SN_ELEM_CELLS * (size_t)(e[0] | e[1] << 8);
        float t[3], d[3] = {0, 0, 0}, m;
        for (k = 0; k < 3; k++) t[k] = (float)(e[2 + 2 * k] | e[3 + 2 * k] << 8) / 32768.0f;
        for (k = 0; k < 8; k++) {
            uint32_t v = cell[2 * k] | (uint32_t)cell[2 * k + 1] << 8;
            float n = (k & 1 ? t[0] : 1 - t[0]) * (k & 2 ? t[1] : 1 - t[1]) * (k & 4 ? t[2] : 1 - t[2]);
            d[0] += n * s->dev[3 * v]; d[1] += n * s->dev[3 * v + 1]; d[2] += n * s->dev[3 * v + 2];
        }
        m = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / s->heat;
        if (m > 1) m = 1;
        s->col[3 * i] = cow_colour[0] + m * (0.95f - cow_colour[0]);
        s->col[3 * i + 1] = cow_colour[1] + m * (0.12f - cow_colour[1]);
        s->col[3 * i + 2] = cow_colour[2] + m * (0.05f - cow_colour[2]);
    }
}
static const uint8_t ink[3] = {25, 28, 38};

/* Render the instance into out (w x h) at 2x2 supersampling. */
static int render(scene *s, const sn_instance *inst, rs_image *out, const char *label, const char *label2) {
    rs_image big;
    rs_camera cam;
    uint32_t e, v;
    if (rs_image_alloc(&big, 2 * out->w, 2 * out->h)) return -1;
    fetch(s, inst);
    if (s->heat > 0) heat_colours(s);
    rs_camera_frame(&cam, s->flo, s->fhi, big.w, big.h, s->az, s->el);
    cam.ground_y = s->lo[1];   /* the ground stays under the hooves */
    rs_clear(&big, &cam);
    if (s->heat > 0) rs_draw_mesh_colors(&big, &cam, s->pos, (int)s->info.surface_vertices, s->tri, (int)s->info.triangles, s->col);
    else rs_draw_mesh(&big, &cam, s->pos, (int)s->info.surface_vertices, s->tri, (int)s->info.triangles, cow_colour);
    if (s->lattice) {
        const uint8_t lc[3] = {30, 60, 140}, sc[3] = {200, 30, 30};
        float r = (float)big.w / 320.0f;
        for (e = 0; e < s->n_edges; e++)
            rs_draw_line(&big, &cam, s->lpos + 3 * s->edges[2 * e], s->lpos + 3 * s->edges[2 * e + 1], lc, 0.3f);
        for (v = s->info.free_vertices; v < s->info.vertices; v++) rs_draw_dot(&big, &cam, s->lpos + 3 * v, r, sc);
    }
    rs_downsample2(&big, out);
    rs_image_free(&big);
    if (label) rs_draw_text(out, 8, 8, out->w >= 480 ? 2 : 1, label, ink);
    if (label2) rs_draw_text(out, 8, out->w >= 480 ? 28 : 18, out->w >= 480 ? 2 : 1, label2, ink);
    return 0;
}

typedef struct {
    const char *blob_path, *clip_path, *obj_dir, *png, *sheet, *compare, *title;
    long frames, iterations;
    int unwarped, hash, lattice, quiet, w, h;
    float az, el, box[6], heat;
    int have_box;
} options;

static int parse_args(int argc, char **argv, options *o) {
    static const char *const valued[] = {"--clip", "--obj-dir", "--png", "--sheet", "--compare", "--title",
                                         "--frames", "--iterations", "--size", "--view", "--frame-box", "--heat", NULL};
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
        else if (!strcmp(a, "--obj-dir")) o->obj_dir = v;
        else if (!strcmp(a, "--png")) o->png = v;
        else if (!strcmp(a, "--sheet")) o->sheet = v;
        else if (!strcmp(a, "--compare")) o->compare = v;
        else if (!strcmp(a, "--title")) o->title = v;
        else if (!strcmp(a, "--frames") || !strcmp(a, "--iterations")) {
            long n = strtol(v, &end, 10);
            if (!*v || *end || n < 0 || n > 10000000L || (a[2] == 'i' && n < 1)) {
                fprintf(stderr, PROG ": %s: bad number '%s'\n", a, v); return 2;
            }
            if (a[2] == 'f') o->frames = n; else o->iterations = n;
        } else if (!strcmp(a, "--size")) {
            if (sscanf(v, "%dx%d", &o->w, &o->h) != 2 || o->w < 16 || o->h < 16 || o->w > 4096 || o->h > 4096) {
                fprintf(stderr, PROG ": --size: want WxH (16..4096), got '%s'\n", v); return 2;
            }
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
        else if (!strcmp(a, "--unwarped")) o->unwarped = 1;
        else if (!strcmp(a, "--hash")) o->hash = 1;
        else if (!strcmp(a, "--lattice")) o->lattice = 1;
        else if (!strcmp(a, "--quiet")) o->quiet = 1;
        else if (a[0] == '-' && a[1]) { fprintf(stderr, PROG ": unknown option '%s' (try --help)\n", a); return 2; }
        else if (!o->blob_path) o->blob_path = a;
        else { fprintf(stderr, PROG ": more than one blob given ('%s')\n", a); return 2; }
    }
    if (!o->blob_path) { usage(stderr); return 2; }
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

int main(int argc, char **argv) {
    options o;
    scene s;
    char err[8192], path[4200];
    void *bytes = NULL, *mem = NULL, *mem2 = NULL;
    size_t nbytes = 0, need;
    sn_status st;
    sn_instance *inst = NULL, *inst2 = NULL;
    static sn_clip clip;
    int have_clip = 0, rc = 1;
    sn_quat *local = NULL;
    sn_xform *xf = NULL, *rest_xf = NULL;
    double *times = NULL, *cpu = NULL, h_s;
    long k, n_frames;
    uint32_t i, t;
    rs_image sheet, panel, cmp;
    long sheet_at[SHEET_COLS * SHEET_ROWS];
    int r = parse_args(argc, argv, &o);
    if (r) return r;
    srand((unsigned)getpid());   /* distinct temp-file names for concurrent players */
    memset(&s, 0, sizeof s);
    memset(&sheet, 0, sizeof sheet); memset(&panel, 0, sizeof panel); memset(&cmp, 0, sizeof cmp);

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

    /* clip */
    if (o.clip_path) {
        size_t cn;
        char *text = read_file(o.clip_path, &cn, err, sizeof err);
        if (!text) { die("%s", err); goto done; }
        if (sn_clip_parse(&clip, text, cn, err, sizeof err)) { free(text); die("%s: %s", o.clip_path, err); goto done; }
        free(text);
        if (sn_clip_bind(&clip, s.blob, err, sizeof err)) {
            fprintf(stderr, PROG ": %s does not fit %s: %s\n", o.clip_path, o.blob_path, err);
            goto done;
        }
        have_clip = 1;
    }
    n_frames = o.frames >= 0 ? o.frames
             : have_clip ? (long)((((int64_t)clip.duration + sn_clip_timestep_q16(s.blob) - 1) / sn_clip_timestep_q16(s.blob)))
             : 60;
    if (o.iterations && (uint32_t)o.iterations > s.info.cg_iters_max) {
        fprintf(stderr, PROG ": --iterations %ld: this blob allows 1..%u\n", o.iterations, s.info.cg_iters_max);
        goto done;
    }

    /* outputs: check up front so a bad path fails before the run, not after */
    if (o.png && probe_writable(o.png, err, sizeof err)) { die("%s", err); goto done; }
    if (o.sheet && probe_writable(o.sheet, err, sizeof err)) { die("%s", err); goto done; }
    if (o.compare && probe_writable(o.compare, err, sizeof err)) { die("%s", err); goto done; }
    if (o.obj_dir) {
        snprintf(path, sizeof path, "%s/frame_0000.obj", o.obj_dir);
        if (probe_writable(path, err, sizeof err)) { die("%s", err); goto done; }
    }

    /* instance(s) in our own memory */
    need = sn_instance_size(s.blob);
    mem = malloc(need);
    if (!mem) { die("out of memory (%zu bytes of instance)", need); goto done; }
    if ((st = sn_instance_init(mem, need, s.blob, &inst)) != SN_OK) {
        fprintf(stderr, PROG ": sn_instance_init: %s\n", sn_status_str(st)); goto done;
    }
    if (o.iterations) sn_set_iterations(inst, (uint32_t)o.iterations);
    if (o.unwarped) sn_set_mode(inst, SN_MODE_UNWARPED);
    if (o.compare) {   /* a second instance, stepped in lockstep in the other mode */
        mem2 = malloc(need);
        if (!mem2 || sn_instance_init(mem2, need, s.blob, &inst2) != SN_OK) { die("cannot create the comparison instance"); goto done; }
        if (o.iterations) sn_set_iterations(inst2, (uint32_t)o.iterations);
        sn_set_mode(inst2, o.unwarped ? SN_MODE_WARPED : SN_MODE_UNWARPED);
    }

    /* scratch */
    s.lattice = o.lattice; s.az = o.az; s.el = o.el; s.heat = o.heat;
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
    for (t = 0; t < s.info.triangles; t++) sn_get_triangle(s.blob, t, s.tri + 3 * t);
    if (o.lattice && lattice_edges(&s, bytes)) { die("out of memory"); goto done; }
    if (o.heat > 0 && heat_setup(&s, bytes)) { die("out of memory"); goto done; }
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
    if ((o.png || o.sheet || o.compare) && !s.info.triangles) {
        fprintf(stderr, PROG ": %s has no triangles: cannot draw pictures\n", o.blob_path); goto done;
    }
    /* the camera frames the rest surface, the same for every frame */
    {
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
        for (k = 0; k < 3; k++) {
            s.flo[k] = o.have_box ? o.box[k] : s.lo[k];
            s.fhi[k] = o.have_box ? o.box[3 + k] : s.hi[k];
        }
    }
    if (!o.quiet)
        printf("%s: %u lattice vertices (%u free), %u cells, %u joints, %u surface vertices, %u triangles, "
               "h = %.4f s, CG %u iterations, %s, instance %zu bytes, blob %u bytes\n",
               o.blob_path, s.info.vertices, s.info.free_vertices, s.info.cells, s.info.joints,
               s.info.surface_vertices, s.info.triangles, h_s,
               o.iterations ? (uint32_t)o.iterations : s.info.cg_iters_default,
               o.unwarped ? "unwarped" : "warped", need, s.info.blob_bytes);

    /* contact sheet: 12 frames spread over the run */
    if (o.sheet) {
        int pw = 320, ph = 240;
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

    /* run */
    for (k = 1; k <= n_frames; k++) {
        double t0, t1, c0, c1;
        if (have_clip) sn_clip_pose(&clip, s.blob, (uint32_t)k, local, xf);
        else memcpy(xf, rest_xf, s.info.joints * sizeof *xf);
        s.pose = xf;
        sn_set_pose(inst, xf, s.info.joints);
        c0 = now_us(CLOCK_THREAD_CPUTIME_ID);
        t0 = now_us(CLOCK_MONOTONIC);
        sn_step(inst);
        t1 = now_us(CLOCK_MONOTONIC);
        c1 = now_us(CLOCK_THREAD_CPUTIME_ID);
        times[k - 1] = t1 - t0;
        cpu[k - 1] = c1 - c0;
        if (inst2) { sn_set_pose(inst2, xf, s.info.joints); sn_step(inst2); }
        if (o.obj_dir) {
            snprintf(path, sizeof path, "%s/frame_%04ld.obj", o.obj_dir, k);
            fetch(&s, inst);
            if (write_obj(&s, path, err, sizeof err)) { die("%s", err); goto done; }
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
        if (stats.saturations)
            fprintf(stderr, PROG ": warning: %u fixed-point values were clamped (saturated) in this run; "
                    "the motion is not trustworthy\n", stats.saturations);
    } else printf("step: no steps run\n");

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
        render(&s, unwarped, &pane, "unwarped (global linear)", lab);
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
    if (o.hash) printf("hash: %016llx\n", (unsigned long long)sn_state_hash(inst));
    rc = 0;
done:
    rs_image_free(&sheet); rs_image_free(&panel); rs_image_free(&cmp);
    free(bytes); free(mem); free(mem2); free(local); free(xf); free(rest_xf); free(times); free(cpu);
    free(s.surf); free(s.latt); free(s.pos); free(s.lpos); free(s.tri); free(s.edges);
    free(s.rest); free(s.dev); free(s.col);
    return rc;
}
