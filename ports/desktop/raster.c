/* raster.c -- software rasterizer, see raster.h. */
#include "raster.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

int rs_image_alloc(rs_image *im, int w, int h) {
    im->w = w; im->h = h;
    im->rgb = malloc((size_t)w * (size_t)h * 3);
    im->iz = malloc((size_t)w * (size_t)h * sizeof(float));
    if (!im->rgb || !im->iz) { rs_image_free(im); return -1; }
    memset(im->rgb, 0, (size_t)w * (size_t)h * 3);
    memset(im->iz, 0, (size_t)w * (size_t)h * sizeof(float));
    return 0;
}

void rs_image_free(rs_image *im) {
    free(im->rgb); free(im->iz);
    im->rgb = NULL; im->iz = NULL;
}

static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross3(const float a[3], const float b[3], float o[3]) {
    o[0] = a[1] * b[2] - a[2] * b[1]; o[1] = a[2] * b[0] - a[0] * b[2]; o[2] = a[0] * b[1] - a[1] * b[0];
}
static void norm3(float v[3]) {
    float l = sqrtf(dot3(v, v));
    if (l > 0) { v[0] /= l; v[1] /= l; v[2] /= l; }
}

void rs_camera_frame(rs_camera *cam, const float lo[3], const float hi[3], int w, int h,
                     float azimuth_deg, float elevation_deg) {
    const float fov = 30.0f * 3.14159265f / 180.0f;   /* vertical; mild perspective */
    const float fill = 0.97f;                          /* of the half width / height */
    float c[3], r = 0, d = 0, az = azimuth_deg * 3.14159265f / 180.0f, el = elevation_deg * 3.14159265f / 180.0f;
    float worldup[3] = {0, 1, 0}, ty = tanf(0.5f * fov), tx = ty * (float)w / (float)h;
    float u0 = 0, u1 = 0, v0 = 0, v1 = 0;
    int i, k;
    for (i = 0; i < 3; i++) {
        float e = 0.5f * (hi[i] - lo[i]);
        c[i] = 0.5f * (hi[i] + lo[i]);
        r += e * e;
    }
    r = sqrtf(r);
    cam->fwd[0] = -sinf(az) * cosf(el);
    cam->fwd[1] = -sinf(el);
    cam->fwd[2] = -cosf(az) * cosf(el);
    cross3(cam->fwd, worldup, cam->right); norm3(cam->right);
    cross3(cam->right, cam->fwd, cam->up);
    /* nearest distance at which every box corner projects inside `fill` */
    for (k = 0; k < 8; k++) {
        float p[3], x, y, z, dx, dy;
        for (i = 0; i < 3; i++) p[i] = ((k >> i) & 1 ? hi[i] : lo[i]) - c[i];
        x = fabsf(dot3(p, cam->right)); y = fabsf(dot3(p, cam->up)); z = dot3(p, cam->fwd);
        dx = x / (fill * tx) - z;
        dy = y / (fill * ty) - z;
        if (dx > d) d = dx;
        if (dy > d) d = dy;
    }
    if (d < 1.05f * r) d = 1.05f * r;   /* the eye stays outside the box */
    if (!(d > 1e-6f)) d = 1;            /* an empty box */
    for (i = 0; i < 3; i++) cam->eye[i] = c[i] - d * cam->fwd[i];
    /* then zoom and shift the lens so the projected box is centred and
       fills `fill` of the width or the height (perspective makes it lopsided) */
    for (k = 0; k < 8; k++) {
        float q[3], z, u, v;
        for (i = 0; i < 3; i++) q[i] = ((k >> i) & 1 ? hi[i] : lo[i]) - cam->eye[i];
        z = dot3(q, cam->fwd);
        u = dot3(q, cam->right) / z; v = dot3(q, cam->up) / z;
        if (!k || u < u0) u0 = u;
        if (!k || u > u1) u1 = u;
        if (!k || v < v0) v0 = v;
        if (!k || v > v1) v1 = v;
    }
    cam->focal = fminf(fill * (float)w / fmaxf(u1 - u0, 1e-6f), fill * (float)h / fmaxf(v1 - v0, 1e-6f));
    cam->cx = 0.5f * (float)w - cam->focal * 0.5f * (u0 + u1);
    cam->cy = 0.5f * (float)h + cam->focal * 0.5f * (v0 + v1);
    cam->ground_y = lo[1];
    cam->scale = cam->focal / d;
}

/* World point -> screen x, y and 1/depth; returns 0 behind the camera. */
static int project(const rs_camera *cam, const float p[3], float *sx, float *sy, float *iz) {
    float v[3] = {p[0] - cam->eye[0], p[1] - cam->eye[1], p[2] - cam->eye[2]};
    float z = dot3(v, cam->fwd);
    if (z < 1e-4f) return 0;
    *iz = 1.0f / z;
    *sx = cam->cx + cam->focal * dot3(v, cam->right) * *iz;
    *sy = cam->cy - cam->focal * dot3(v, cam->up) * *iz;
    return 1;
}

/* linear [0,1] -> sRGB byte */
static uint8_t to8(float x) {
    if (x <= 0) return 0;
    if (x >= 1) return 255;
    return (uint8_t)(255.0f * powf(x, 1.0f / 2.2f) + 0.5f);
}

static const float key_dir[3] = {-0.45f, 0.80f, 0.40f};   /* towards the key light */

void rs_clear(rs_image *im, const rs_camera *cam) {
    int x, y;
    for (y = 0; y < im->h; y++)
        for (x = 0; x < im->w; x++) {
            size_t i = (size_t)y * (size_t)im->w + (size_t)x;
            float ray[3], t, col[3];
            int k;
            for (k = 0; k < 3; k++)
                ray[k] = cam->fwd[k] * cam->focal + cam->right[k] * ((float)x + 0.5f - cam->cx)
                       - cam->up[k] * ((float)y + 0.5f - cam->cy);
            t = ray[1] < 0 ? (cam->ground_y - cam->eye[1]) / ray[1] : -1;
            if (t > 0) {
                float gx = cam->eye[0] + t * ray[0], gz = cam->eye[2] + t * ray[2];
                float dist = t * sqrtf(dot3(ray, ray)) / (cam->focal / cam->scale);   /* in camera distances */
                float fade = expf(-0.25f * dist * dist), line;
                float fx = gx - floorf(gx), fz = gz - floorf(gz);
                line = (fx < 0.03f || fz < 0.03f) ? 0.06f * fade : 0.0f;   /* 1-unit grid */
                col[0] = 0.60f - line; col[1] = 0.58f - line; col[2] = 0.54f - line;
                for (k = 0; k < 3; k++) col[k] = col[k] * fade + 0.72f * (1 - fade);
                im->iz[i] = 1.0f / (t * dot3(ray, cam->fwd));
            } else {
                float s = (float)y / (float)im->h;
                col[0] = 0.50f + 0.25f * s; col[1] = 0.60f + 0.16f * s; col[2] = 0.78f - 0.04f * s;
                im->iz[i] = 0;
            }
            im->rgb[3 * i] = to8(col[0]); im->rgb[3 * i + 1] = to8(col[1]); im->rgb[3 * i + 2] = to8(col[2]);
        }
}

typedef struct { float x, y, iz, c[3]; } svert;

/* Fill a screen triangle. mode 0: z-tested Gouraud colour (linear, 0..1);
 * mode 1: shadow mask (mark[i] = 1 where the ground is). */
static void fill_tri(rs_image *im, const svert *a, const svert *b, const svert *c, int mode, uint8_t *mark) {
    float area = (b->x - a->x) * (c->y - a->y) - (b->y - a->y) * (c->x - a->x);
    int x0, x1, y0, y1, x, y;
    if (fabsf(area) < 1e-12f) return;
    x0 = (int)floorf(fminf(a->x, fminf(b->x, c->x))); x1 = (int)ceilf(fmaxf(a->x, fmaxf(b->x, c->x)));
    y0 = (int)floorf(fminf(a->y, fminf(b->y, c->y))); y1 = (int)ceilf(fmaxf(a->y, fmaxf(b->y, c->y)));
    if (x0 < 0) x0 = 0;
    if (y0 < 0) y0 = 0;
    if (x1 > im->w - 1) x1 = im->w - 1;
    if (y1 > im->h - 1) y1 = im->h - 1;
    for (y = y0; y <= y1; y++)
        for (x = x0; x <= x1; x++) {
            float px = (float)x + 0.5f, py = (float)y + 0.5f;
            float w0 = ((b->x - px) * (c->y - py) - (b->y - py) * (c->x - px)) / area;
            float w1 = ((c->x - px) * (a->y - py) - (c->y - py) * (a->x - px)) / area;
            float w2 = 1 - w0 - w1, iz;
            size_t i;
            if (w0 < 0 || w1 < 0 || w2 < 0) continue;
            i = (size_t)y * (size_t)im->w + (size_t)x;
            if (mode == 1) { mark[i] = 1; continue; }
            iz = w0 * a->iz + w1 * b->iz + w2 * c->iz;
            if (iz <= im->iz[i]) continue;
            im->iz[i] = iz;
            im->rgb[3 * i] = to8(w0 * a->c[0] + w1 * b->c[0] + w2 * c->c[0]);
            im->rgb[3 * i + 1] = to8(w0 * a->c[1] + w1 * b->c[1] + w2 * c->c[1]);
            im->rgb[3 * i + 2] = to8(w0 * a->c[2] + w1 * b->c[2] + w2 * c->c[2]);
        }
}

static void draw_mesh(rs_image *im, const rs_camera *cam, const float *pos, int nv,
                      const uint32_t *tri, int nt, const float *color, int per_vertex);

void rs_draw_mesh(rs_image *im, const rs_camera *cam, const float *pos, int nv,
                  const uint32_t *tri, int nt, const float color[3]) {
    draw_mesh(im, cam, pos, nv, tri, nt, color, 0);
}

void rs_draw_mesh_colors(rs_image *im, const rs_camera *cam, const float *pos, int nv,
                         const uint32_t *tri, int nt, const float *colors) {
    draw_mesh(im, cam, pos, nv, tri, nt, colors, 1);
}

static void draw_mesh(rs_image *im, const rs_camera *cam, const float *pos, int nv,
                      const uint32_t *tri, int nt, const float *color, int per_vertex) {
    float *nrm = calloc((size_t)nv * 3, sizeof(float));
    svert *sv = malloc((size_t)nv * sizeof(svert));
    uint8_t *mark = calloc((size_t)im->w * (size_t)im->h, 1);
    float L1[3], L2[3] = {0.7f, 0.25f, -0.5f};
    int t, v, k, *ok = malloc((size_t)nv * sizeof(int));
    size_t i;
    if (!nrm || !sv || !mark || !ok) goto out;
    memcpy(L1, key_dir, sizeof L1); norm3(L1); norm3(L2);
    for (t = 0; t < nt; t++) {   /* area-weighted normals */
        const float *p0 = pos + 3 * tri[3 * t], *p1 = pos + 3 * tri[3 * t + 1], *p2 = pos + 3 * tri[3 * t + 2];
        float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]}, n[3];
        cross3(e1, e2, n);
        for (k = 0; k < 3; k++) {
            nrm[3 * tri[3 * t] + k] += n[k]; nrm[3 * tri[3 * t + 1] + k] += n[k]; nrm[3 * tri[3 * t + 2] + k] += n[k];
        }
    }
    /* shadow: project along the key light onto the ground plane, darken the ground */
    for (v = 0; v < nv; v++) {
        const float *p = pos + 3 * v;
        float s = (p[1] - cam->ground_y) / L1[1], q[3] = {p[0] - s * L1[0], cam->ground_y, p[2] - s * L1[2]};
        ok[v] = project(cam, q, &sv[v].x, &sv[v].y, &sv[v].iz);
    }
    for (t = 0; t < nt; t++)
        if (ok[tri[3 * t]] && ok[tri[3 * t + 1]] && ok[tri[3 * t + 2]])
            fill_tri(im, &sv[tri[3 * t]], &sv[tri[3 * t + 1]], &sv[tri[3 * t + 2]], 1, mark);
    for (i = 0; i < (size_t)im->w * (size_t)im->h; i++)
        if (mark[i] && im->iz[i] > 0)
            for (k = 0; k < 3; k++) im->rgb[3 * i + (size_t)k] = (uint8_t)(im->rgb[3 * i + (size_t)k] * 0.62f);
    /* lit vertices: hemisphere ambient + key + fill + a little specular */
    for (v = 0; v < nv; v++) {
        float *n = nrm + 3 * v, view[3], hv[3], d1, d2, sp, hemi;
        const float *p = pos + 3 * v;
        norm3(n);
        ok[v] = project(cam, p, &sv[v].x, &sv[v].y, &sv[v].iz);
        for (k = 0; k < 3; k++) view[k] = cam->eye[k] - p[k];
        norm3(view);
        for (k = 0; k < 3; k++) hv[k] = view[k] + L1[k];
        norm3(hv);
        d1 = fmaxf(0, dot3(n, L1)); d2 = fmaxf(0, dot3(n, L2));
        hemi = 0.5f + 0.5f * n[1];
        sp = powf(fmaxf(0, dot3(n, hv)), 24.0f) * 0.18f;
        for (k = 0; k < 3; k++) {
            float amb = (0.10f + 0.12f * hemi);
            sv[v].c[k] = color[per_vertex ? 3 * v + k : k] * (amb + 0.85f * d1 + 0.22f * d2) + sp;
        }
    }
    for (t = 0; t < nt; t++) {
        const svert *a = &sv[tri[3 * t]], *b = &sv[tri[3 * t + 1]], *c = &sv[tri[3 * t + 2]];
        if (!ok[tri[3 * t]] || !ok[tri[3 * t + 1]] || !ok[tri[3 * t + 2]]) continue;
        /* back faces: counter-clockwise from outside is clockwise on screen (y down) */
        if ((b->x - a->x) * (c->y - a->y) - (b->y - a->y) * (c->x - a->x) > 0) continue;
        fill_tri(im, a, b, c, 0, NULL);
    }
out:
    free(nrm); free(sv); free(mark); free(ok);
}

static void blend(rs_image *im, int x, int y, const uint8_t c[3], float a) {
    uint8_t *p;
    int k;
    if (x < 0 || y < 0 || x >= im->w || y >= im->h) return;
    p = im->rgb + 3 * ((size_t)y * (size_t)im->w + (size_t)x);
    for (k = 0; k < 3; k++) p[k] = (uint8_t)((float)p[k] * (1 - a) + (float)c[k] * a + 0.5f);
}

void rs_draw_line(rs_image *im, const rs_camera *cam, const float a[3], const float b[3],
                  const uint8_t color[3], float hidden_alpha) {
    float ax, ay, az, bx, by, bz;
    int n, i;
    if (!project(cam, a, &ax, &ay, &az) || !project(cam, b, &bx, &by, &bz)) return;
    n = (int)ceilf(fmaxf(fabsf(bx - ax), fabsf(by - ay)));
    for (i = 0; i <= n; i++) {
        float t = n ? (float)i / (float)n : 0, x = ax + t * (bx - ax), y = ay + t * (by - ay);
        float iz = az + t * (bz - az);
        int xi = (int)floorf(x), yi = (int)floorf(y);
        if (xi < 0 || yi < 0 || xi >= im->w || yi >= im->h) continue;
        /* in front of whatever was drawn (with a small bias), else faint */
        blend(im, xi, yi, color, iz * 1.01f >= im->iz[(size_t)yi * (size_t)im->w + (size_t)xi] ? 1.0f : hidden_alpha);
    }
}

void rs_draw_dot(rs_image *im, const rs_camera *cam, const float p[3], float r, const uint8_t color[3]) {
    float sx, sy, iz;
    int x, y;
    if (!project(cam, p, &sx, &sy, &iz)) return;
    for (y = (int)floorf(sy - r - 1); y <= (int)ceilf(sy + r + 1); y++)
        for (x = (int)floorf(sx - r - 1); x <= (int)ceilf(sx + r + 1); x++) {
            float dx = (float)x + 0.5f - sx, dy = (float)y + 0.5f - sy, d = sqrtf(dx * dx + dy * dy);
            if (d <= r + 0.5f) blend(im, x, y, color, d <= r - 0.5f ? 1.0f : r + 0.5f - d);
        }
}

/* 5x7 glyphs (5x9 for g j p q y: two descender rows), rows top to bottom, '#' = ink */
static const struct { char c; const char *g; } font[] = {
    {'A', ".###.#...##...#######...##...##...#"}, {'B', "####.#...##...#####.#...##...#####."},
    {'C', ".###.#...##....#....#....#...#.###."}, {'D', "####.#...##...##...##...##...#####."},
    {'E', "######....#....####.#....#....#####"}, {'F', "######....#....####.#....#....#...."},
    {'G', ".###.#...##....#.####...##...#.####"}, {'H', "#...##...##...#######...##...##...#"},
    {'I', ".###...#....#....#....#....#...###."}, {'J', "..###...#....#....#....#.#..#..##.."},
    {'K', "#...##..#.#.#..##...#.#..#..#.#...#"}, {'L', "#....#....#....#....#....#....#####"},
    {'M', "#...###.###.#.##.#.##...##...##...#"}, {'N', "#...##...###..##.#.##..###...##...#"},
    {'O', ".###.#...##...##...##...##...#.###."}, {'P', "####.#...##...#####.#....#....#...."},
    {'Q', ".###.#...##...##...##.#.##..#..##.#"}, {'R', "####.#...##...#####.#.#..#..#.#...#"},
    {'S', ".#####....#.....###.....#....#####."}, {'T', "#####..#....#....#....#....#....#.."},
    {'U', "#...##...##...##...##...##...#.###."}, {'V', "#...##...##...##...##...#.#.#...#.."},
    {'W', "#...##...##...##.#.##.#.##.#.#.#.#."}, {'X', "#...##...#.#.#...#...#.#.#...##...#"},
    {'Y', "#...##...#.#.#...#....#....#....#.."}, {'Z', "#####....#...#...#...#...#....#####"},
    {'0', ".###.#...##..###.#.###..##...#.###."}, {'1', "..#...##....#....#....#....#...###."},
    {'2', ".###.#...#....#...#...#...#...#####"}, {'3', "#####...#...#.....#.....##...#.###."},
    {'4', "...#...##..#.#.#..#.#####...#....#."}, {'5', "######....####.....#....##...#.###."},
    {'6', "..##..#...#....####.#...##...#.###."}, {'7', "#####....#...#...#...#....#....#..."},
    {'8', ".###.#...##...#.###.#...##...#.###."}, {'9', ".###.#...##...#.####....#...#..##.."},
    {'.', "..........................##...##.."}, {':', "......##...##.........##...##......"},
    {'=', "..........#####.....#####.........."}, {'-', "...............#####..............."},
    {'+', "......#....#..#####..#....#........"}, {'/', ".........#...#...#...#...#........."},
    {'(', "...#...#...#....#....#.....#.....#."}, {')', ".#.....#.....#....#....#...#...#..."},
    {',', "....................##....#...#...."}, {'|', "..#....#....#....#....#....#....#.."},
    {'a', "...........###.....#.#####...#.####"}, {'b', "#....#....#.##.##..##...##...#####."},
    {'c', "...........###.#....#....#...#.###."}, {'d', "....#....#.##.##..###...##...#.####"},
    {'e', "...........###.#...#######.....###."}, {'f', "..##..#..#.#...###...#....#....#..."},
    {'g', "...........#####...##...##...#.####....#.###."}, {'h', "#....#....#.##.##..##...##...##...#"},
    {'i', "..#........##....#....#....#...###."}, {'j', "...#........##....#....#....#....#.#..#..##.."},
    {'k', "#....#....#..#.#.#..##...#.#..#..#."}, {'l', ".##....#....#....#....#....#...###."},
    {'m', "..........##.#.#.#.##.#.##...##...#"}, {'n', "..........#.##.##..##...##...##...#"},
    {'o', "...........###.#...##...##...#.###."}, {'p', "..........####.#...##...##...#####.#....#...."},
    {'q', "...........#####...##...##...#.####....#....#"}, {'r', "..........#.##.##..##....#....#...."},
    {'s', "...........#####.....###.....#####."}, {'t', ".#....#...###...#....#....#..#..##."},
    {'u', "..........#...##...##...##..##.##.#"}, {'v', "..........#...##...##...#.#.#...#.."},
    {'w', "..........#...##...##.#.##.#.#.#.#."}, {'x', "..........#...#.#.#...#...#.#.#...#"},
    {'y', "..........#...##...##...##...#.####....#.###."}, {'z', "..........#####...#...#...#...#####"},
    {'%', "##...##..#...#...#...#...#..##...##"}, {'_', "..............................#####"},
};

void rs_draw_text(rs_image *im, int x, int y, int s, const char *text, const uint8_t color[3]) {
    for (; *text; text++, x += 6 * s) {
        char c = *text;
        const char *g = NULL;
        size_t f;
        int r, q, dy, dx;
        for (f = 0; f < sizeof font / sizeof font[0]; f++) if (font[f].c == c) g = font[f].g;
        if (!g && c >= 'a' && c <= 'z')   /* no lower-case glyph: use upper case */
            for (f = 0; f < sizeof font / sizeof font[0]; f++) if (font[f].c == c - 32) g = font[f].g;
        if (!g) continue;
        for (r = 0; r < (int)strlen(g) / 5; r++)   /* 7 rows, 9 with a descender */
            for (q = 0; q < 5; q++)
                if (g[r * 5 + q] == '#')
                    for (dy = 0; dy < s; dy++)
                        for (dx = 0; dx < s; dx++) blend(im, x + q * s + dx, y + r * s + dy, color, 1.0f);
    }
}

void rs_downsample2(const rs_image *src, rs_image *dst) {
    int x, y, k;
    for (y = 0; y < dst->h; y++)
        for (x = 0; x < dst->w; x++)
            for (k = 0; k < 3; k++) {
                const uint8_t *p = src->rgb + 3 * ((size_t)(2 * y) * (size_t)src->w + (size_t)(2 * x)) + k;
                size_t row = 3 * (size_t)src->w;
                dst->rgb[3 * ((size_t)y * (size_t)dst->w + (size_t)x) + (size_t)k] =
                    (uint8_t)((p[0] + p[3] + p[row] + p[row + 3] + 2) / 4);
            }
}

void rs_blit(rs_image *dst, int x0, int y0, const rs_image *src) {
    int y;
    for (y = 0; y < src->h; y++) {
        int x, yy = y0 + y;
        if (yy < 0 || yy >= dst->h) continue;
        for (x = 0; x < src->w; x++) {
            int xx = x0 + x;
            if (xx < 0 || xx >= dst->w) continue;
            memcpy(dst->rgb + 3 * ((size_t)yy * (size_t)dst->w + (size_t)xx), src->rgb + 3 * ((size_t)y * (size_t)src->w + (size_t)x), 3);
        }
    }
}

void rs_fill(rs_image *im, int x0, int y0, int w, int h, const uint8_t color[3]) {
    int x, y;
    for (y = y0; y < y0 + h; y++)
        for (x = x0; x < x0 + w; x++) blend(im, x, y, color, 1.0f);
}

int rs_heat_panel(rs_image *out, const double *surf, const double *base, double scale, unsigned ns,
                  const unsigned *tris, unsigned nt, const float lo[3], const float hi[3], double az, double el,
                  const char *l1, const char *l2) {
    static const float flesh[3] = {0.78f, 0.60f, 0.44f}, red[3] = {0.95f, 0.12f, 0.05f};
    static const uint8_t ink[3] = {25, 28, 38};
    rs_image big;
    rs_camera cam;
    float *pos = malloc(3 * (size_t)ns * sizeof *pos + 4), *col = malloc(3 * (size_t)ns * sizeof *col + 4);
    uint32_t *tri = malloc(3 * (size_t)nt * sizeof *tri + 4);
    unsigned i, k;
    if (!pos || !col || !tri || rs_image_alloc(&big, 2 * out->w, 2 * out->h)) { free(pos); free(col); free(tri); return -1; }
    for (i = 0; i < 3 * ns; i++) pos[i] = (float)surf[i];
    for (i = 0; i < 3 * nt; i++) tri[i] = tris[i];
    for (i = 0; i < ns; i++) {
        float h = 0;
        if (base && scale > 0) {
            double d = 0;
            for (k = 0; k < 3; k++) d += (surf[3 * i + k] - base[3 * i + k]) * (surf[3 * i + k] - base[3 * i + k]);
            h = (float)(sqrt(d) / scale);
            if (h > 1) h = 1;
        }
        for (k = 0; k < 3; k++) col[3 * i + k] = flesh[k] + h * (red[k] - flesh[k]);
    }
    rs_camera_frame(&cam, lo, hi, big.w, big.h, (float)az, (float)el);
    cam.ground_y = lo[1];
    rs_clear(&big, &cam);
    rs_draw_mesh_colors(&big, &cam, pos, (int)ns, tri, (int)nt, col);
    rs_downsample2(&big, out);
    rs_image_free(&big);
    if (l1) rs_draw_text(out, 8, 8, 2, l1, ink);
    if (l2) rs_draw_text(out, 8, 28, 1, l2, ink);
    free(pos); free(col); free(tri);
    return 0;
}
