/* test_desktop_raster.c -- the player's software rasterizer
 * (ports/desktop/raster.c): framing (also tall and flat boxes), z-buffer order, back-face culling,
 * lines hidden behind surfaces, text, downsampling. */
#include "sn_test.h"
#include "raster.h"
#include <string.h>

static const uint8_t *px(const rs_image *im, int x, int y) { return im->rgb + 3 * ((size_t)y * (size_t)im->w + (size_t)x); }

/* A quad facing +z (towards a camera on the +z side), at depth z, as 2 CCW triangles. */
static void quad(float *p, float x0, float y0, float x1, float y1, float z) {
    float v[12] = {x0, y0, z, x1, y0, z, x1, y1, z, x0, y1, z};
    memcpy(p, v, sizeof v);
}

int main(void) {
    rs_image im, small;
    rs_camera cam;
    float lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, p[12];
    const float red[3] = {0.9f, 0.05f, 0.05f}, blue[3] = {0.05f, 0.05f, 0.9f};
    uint32_t tri[6] = {0, 1, 2, 0, 2, 3}, back[6] = {0, 2, 1, 0, 3, 2};
    const uint8_t *c;
    int x, y, inked;
    (void)t_seed;

    T_CHECK(rs_image_alloc(&im, 200, 150) == 0, "alloc");
    rs_camera_frame(&cam, lo, hi, im.w, im.h, 0, 0);   /* looking along -z from +z */
    T_NEAR(cam.fwd[2], -1, 1e-6, "azimuth 0 looks along -z");
    T_NEAR(cam.ground_y, -1, 0, "ground at the bottom of the box");
    {   /* every corner of the box projects inside the image */
        int k, inside = 1;
        for (k = 0; k < 8; k++) {
            float q[3] = {k & 1 ? 1.f : -1.f, k & 2 ? 1.f : -1.f, k & 4 ? 1.f : -1.f}, v[3], z, sx, sy;
            int i;
            for (i = 0; i < 3; i++) v[i] = q[i] - cam.eye[i];
            z = v[0] * cam.fwd[0] + v[1] * cam.fwd[1] + v[2] * cam.fwd[2];
            sx = cam.cx + cam.focal * (v[0] * cam.right[0] + v[1] * cam.right[1] + v[2] * cam.right[2]) / z;
            sy = cam.cy - cam.focal * (v[0] * cam.up[0] + v[1] * cam.up[1] + v[2] * cam.up[2]) / z;
            if (sx < 0 || sx >= (float)im.w || sy < 0 || sy >= (float)im.h) inside = 0;
        }
        T_CHECK(inside, "the framed box fits in the image");
    }

    /* tall, wide and flat boxes from several views: every corner inside,
       and the box fills most of the picture's height or width (a tight fit) */
    {
        static const float boxes[3][6] = {{-0.5f, 0, -0.5f, 0.5f, 9, 0.5f}, {-6, -1, -1, 6, 1, 1}, {-3, 0, -3, 3, 0.2f, 3}};
        static const int sizes[3][2] = {{640, 480}, {240, 480}, {320, 320}};
        static const float views[4][2] = {{30, 15}, {0, 0}, {90, 60}, {-140, -30}};
        int b, sz, v, all_in = 1, tight = 1;
        float worst_fill = 1;
        for (b = 0; b < 3; b++)
            for (sz = 0; sz < 3; sz++)
                for (v = 0; v < 4; v++) {
                    float x0 = 1e9f, x1 = -1e9f, y0 = 1e9f, y1 = -1e9f, f;
                    int k;
                    rs_camera_frame(&cam, boxes[b], boxes[b] + 3, sizes[sz][0], sizes[sz][1], views[v][0], views[v][1]);
                    for (k = 0; k < 8; k++) {
                        float q[3], d[3], z, sx, sy;
                        int i;
                        for (i = 0; i < 3; i++) { q[i] = boxes[b][(k >> i) & 1 ? 3 + i : i]; d[i] = q[i] - cam.eye[i]; }
                        z = d[0] * cam.fwd[0] + d[1] * cam.fwd[1] + d[2] * cam.fwd[2];
                        sx = cam.cx + cam.focal * (d[0] * cam.right[0] + d[1] * cam.right[1] + d[2] * cam.right[2]) / z;
                        sy = cam.cy - cam.focal * (d[0] * cam.up[0] + d[1] * cam.up[1] + d[2] * cam.up[2]) / z;
                        if (z <= 0 || sx < 0 || sx > (float)sizes[sz][0] || sy < 0 || sy > (float)sizes[sz][1]) all_in = 0;
                        if (sx < x0) x0 = sx;
                        if (sx > x1) x1 = sx;
                        if (sy < y0) y0 = sy;
                        if (sy > y1) y1 = sy;
                    }
                    f = fmaxf((x1 - x0) / (float)sizes[sz][0], (y1 - y0) / (float)sizes[sz][1]);
                    if (f < worst_fill) worst_fill = f;
                    if (f < 0.95f) tight = 0;
                }
        T_CHECK(all_in, "tall/wide/flat boxes: every corner projects inside the picture");
        T_CHECK(tight, "tall/wide/flat boxes fill at least 95%% of the width or height (worst %.2f)", worst_fill);
    }
    rs_camera_frame(&cam, lo, hi, im.w, im.h, 0, 0);

    /* z-buffer: the near red quad wins whichever is drawn first */
    for (x = 0; x < 2; x++) {
        rs_clear(&im, &cam);
        if (x == 0) {
            quad(p, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f); rs_draw_mesh(&im, &cam, p, 4, tri, 2, red);
            quad(p, -0.8f, -0.8f, 0.8f, 0.8f, -0.5f); rs_draw_mesh(&im, &cam, p, 4, tri, 2, blue);
        } else {
            quad(p, -0.8f, -0.8f, 0.8f, 0.8f, -0.5f); rs_draw_mesh(&im, &cam, p, 4, tri, 2, blue);
            quad(p, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f); rs_draw_mesh(&im, &cam, p, 4, tri, 2, red);
        }
        c = px(&im, im.w / 2, im.h / 2);
        T_CHECK(c[0] > 2 * c[2], "order %d: centre is red (near) %u,%u,%u", x, c[0], c[1], c[2]);
        c = px(&im, im.w / 2 + (int)(0.65f * cam.scale), im.h / 2);
        T_CHECK(c[2] > 2 * c[0], "order %d: outside the near quad is blue %u,%u,%u", x, c[0], c[1], c[2]);
    }

    /* back faces (clockwise seen from the camera) are not drawn */
    rs_clear(&im, &cam);
    c = px(&im, im.w / 2, im.h / 2);
    {
        uint8_t bg[3];
        memcpy(bg, c, 3);
        quad(p, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f);
        rs_draw_mesh(&im, &cam, p, 4, back, 2, red);
        T_CHECK(memcmp(bg, px(&im, im.w / 2, im.h / 2), 3) == 0, "back face culled");
    }

    /* a line behind the red quad is faint, in front of it solid */
    {
        const uint8_t black[3] = {0, 0, 0};
        float a[3] = {-0.9f, 0, -0.8f}, b[3] = {0.9f, 0, -0.8f}, a2[3] = {-0.9f, 0.2f, 0.8f}, b2[3] = {0.9f, 0.2f, 0.8f};
        int yl = im.h / 2, yf;
        rs_clear(&im, &cam);
        quad(p, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f);
        rs_draw_mesh(&im, &cam, p, 4, tri, 2, red);
        rs_draw_line(&im, &cam, a, b, black, 0.3f);
        rs_draw_line(&im, &cam, a2, b2, black, 0.3f);
        c = px(&im, im.w / 2, yl);
        T_CHECK(c[0] > 60, "hidden line is faint over the quad: %u", c[0]);
        for (yf = 0, y = 0; y < im.h; y++) if (px(&im, im.w / 2, y)[0] == 0) yf = 1;
        T_CHECK(yf, "front line is solid black somewhere in the centre column");
    }

    /* text leaves ink; unknown characters are skipped */
    {
        const uint8_t ink[3] = {1, 2, 3};
        rs_clear(&im, &cam);
        rs_draw_text(&im, 2, 2, 1, "t = 0.5 s ~", ink);
        for (inked = 0, y = 2; y < 11; y++)
            for (x = 2; x < 70; x++) if (!memcmp(px(&im, x, y), ink, 3)) inked++;
        T_CHECK(inked > 20 && inked < 200, "text ink pixels: %d", inked);
    }

    /* 2x2 box filter */
    T_CHECK(rs_image_alloc(&small, 100, 75) == 0, "alloc small");
    memset(im.rgb, 0, (size_t)im.w * (size_t)im.h * 3);
    im.rgb[0] = 200; im.rgb[3] = 100; im.rgb[3 * (size_t)im.w] = 0; im.rgb[3 * (size_t)im.w + 3] = 100;
    rs_downsample2(&im, &small);
    T_CHECK(small.rgb[0] == 100 && small.rgb[3] == 0, "downsample averages 2x2: %u", small.rgb[0]);
    rs_image_free(&small);
    rs_image_free(&im);
    return T_END();
}
