/* sinew_rig_report.c -- sinew-rig's figures and pictures: residuals against the target, heat-map panels (PNG). */
#include "sinew_rig_int.h"
#include "raster.h"
#include "png.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* one panel: surf coloured red by |surf - ref| / scale (ref NULL: flesh) */
static int panel(rs_image *out, const snref_model *m, const double *surf, const double *ref, double scale, const float lo[3], const float hi[3],
                 double az, double el, const char *l1, const char *l2)
{
    return rs_heat_panel(out, surf, ref, scale, m->nS, m->tris, m->nT, lo, hi, az, el, l1, l2);
}

int sr_picture(const char *path, const snref_model *m, int np, const double *const *surf, const double *const *ref, const double *scale,
                   const char *const *l1, const char *const *l2, double az, double el)
{
    enum { PW = 480, PH = 400 };
    rs_image img, pane;
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    unsigned i, k;
    int p, rc = 0;
    char err[300];
    const uint8_t line[3] = {90, 90, 90};
    for (p = 0; p < np; p++)
        for (i = 0; i < m->nS; i++)
            for (k = 0; k < 3; k++) {
                float x = (float)surf[p][3 * i + k];
                if (x < lo[k]) lo[k] = x;
                if (x > hi[k]) hi[k] = x;
            }
    if (rs_image_alloc(&img, np * PW, PH)) return -1;
    if (rs_image_alloc(&pane, PW, PH)) { rs_image_free(&img); return -1; }
    for (p = 0; p < np && !rc; p++) {
        rc = panel(&pane, m, surf[p], ref[p], scale[p], lo, hi, az, el, l1[p], l2[p]);
        if (!rc) { rs_blit(&img, p * PW, 0, &pane); if (p) rs_fill(&img, p * PW - 1, 0, 2, PH, line); }
    }
    if (!rc) { rc = png_write(path, img.rgb, img.w, img.h, err, sizeof err); if (rc) fprintf(stderr, PROG ": %s\n", err); }
    rs_image_free(&pane); rs_image_free(&img);
    return rc;
}

/* ---------------- figures ---------------- */

/* residual of a against target, as fractions of target's displacement from base: rms and max */
unsigned sr_worst_at;
void sr_residual(const double *a, const double *target, const double *base, unsigned n, double *rms, double *mx, double *dmax)
{
    double r2 = 0, d2 = 0, rm = 0, dm = 0;
    unsigned i, k;
    sr_worst_at = 0;
    for (i = 0; i < n; i++) {
        double r = 0, d = 0;
        for (k = 0; k < 3; k++) {
            r += (a[3 * i + k] - target[3 * i + k]) * (a[3 * i + k] - target[3 * i + k]);
            d += (target[3 * i + k] - base[3 * i + k]) * (target[3 * i + k] - base[3 * i + k]);
        }
        r2 += r; d2 += d; dm = fmax(dm, sqrt(d));
        if (sqrt(r) > rm) { rm = sqrt(r); sr_worst_at = i; }
    }
    *rms = d2 > 0 ? sqrt(r2 / d2) : 0;
    *mx = dm > 0 ? rm / dm : 0;
    if (dmax) *dmax = dm;
}
