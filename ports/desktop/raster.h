/* raster.h -- small software rasterizer for the desktop player's pictures:
 * perspective camera, z-buffer, Gouraud-shaded triangles with two lights and
 * a ground plane with a projected shadow, depth-aware lines and dots (lattice
 * overlay), 2x2 supersampling, a 5x7 bitmap font for labels. libc + libm. */
#ifndef SN_RASTER_H
#define SN_RASTER_H
#include <stdint.h>

typedef struct rs_image {
    int w, h;
    uint8_t *rgb;    /* w*h*3 */
    float *iz;       /* w*h, 1/depth, 0 = nothing drawn (infinitely far) */
} rs_image;

typedef struct rs_camera {
    float eye[3], right[3], up[3], fwd[3];
    float focal, cx, cy;     /* pixels */
    float ground_y;          /* height of the ground plane (world y) */
    float scale;             /* pixels per world unit at the target, for line widths */
} rs_camera;

int  rs_image_alloc(rs_image *im, int w, int h);   /* 0 or -1 (memory) */
void rs_image_free(rs_image *im);

/// Camera looking at the centre of box [lo, hi] from azimuth / elevation
/// (degrees; azimuth 0 looks along -z, y is up; vertical field of view 30
/// degrees or a little less), the projected box centred and filling 97% of
/// the width or the height.
/// The ground plane is put at lo[1]. Use one box for every frame.
void rs_camera_frame(rs_camera *cam, const float lo[3], const float hi[3], int w, int h,
                     float azimuth_deg, float elevation_deg);

/// Sky gradient, ground plane (with a faint grid) and its depth.
void rs_clear(rs_image *im, const rs_camera *cam);

/// Shadow of the mesh on the ground plane (light from above), then the mesh:
/// Gouraud shading from area-weighted vertex normals. pos: nv*3 floats,
/// tri: nt*3 indices, counter-clockwise seen from outside.
void rs_draw_mesh(rs_image *im, const rs_camera *cam, const float *pos, int nv,
                  const uint32_t *tri, int nt, const float color[3]);
/// The same with one colour per vertex (nv*3 floats, linear 0..1).
void rs_draw_mesh_colors(rs_image *im, const rs_camera *cam, const float *pos, int nv,
                         const uint32_t *tri, int nt, const float *colors);

/// Line a-b, solid where in front of the surface, faint (alpha) where hidden.
void rs_draw_line(rs_image *im, const rs_camera *cam, const float a[3], const float b[3],
                  const uint8_t color[3], float hidden_alpha);
/// Dot of radius r pixels at p, drawn over everything.
void rs_draw_dot(rs_image *im, const rs_camera *cam, const float p[3], float r, const uint8_t color[3]);

/// Text at pixel (x, y) (top-left), 5x7 glyphs scaled by s: letters, digits,
/// . : = - + / ( ) , | % _ and space; other characters are skipped.
void rs_draw_text(rs_image *im, int x, int y, int s, const char *text, const uint8_t color[3]);

/// Box-filter src (2w x 2h) into dst (w x h).
void rs_downsample2(const rs_image *src, rs_image *dst);
/// Copy src into dst at (x0, y0), clipped.
void rs_blit(rs_image *dst, int x0, int y0, const rs_image *src);
/// Fill a rectangle.
void rs_fill(rs_image *im, int x0, int y0, int w, int h, const uint8_t color[3]);

/// One picture panel of a surface (ns vertices as doubles, nt triangles):
/// drawn at twice out's size from (az, el) degrees framing [lo, hi] (ground
/// at lo[1]), downsampled into out; flesh-coloured, shaded towards red by
/// |surf - base| / scale (clamped at 1; base NULL or scale <= 0: plain
/// flesh); label l1 (large) and l2 (small) at the top left when not NULL.
/// The heat pictures of sinew-bake --static, sinew-rig and test_nonlinear.
/// Returns 0, or -1 when out of memory (out untouched).
int rs_heat_panel(rs_image *out, const double *surf, const double *base, double scale, unsigned ns,
                  const unsigned *tris, unsigned nt, const float lo[3], const float hi[3], double az, double el,
                  const char *l1, const char *l2);

#endif
