/* plot.c -- line plots, see plot.h. Lines and grid are drawn at 2x and box
 * filtered down; text goes on afterwards, crisp. */
#include "plot.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

static const uint8_t frame_c[3] = {60, 60, 70}, grid_c[3] = {222, 224, 230},
                     text_c[3] = {25, 28, 38};
static const uint8_t palette[4][3] = {{200, 60, 40}, {40, 90, 200}, {30, 140, 60}, {150, 60, 170}};

double plot_tick_step(double span, int want) {
    double raw = span / (want > 0 ? want : 1), mag = pow(10.0, floor(log10(raw))), n = raw / mag;
    return (n < 1.5 ? 1 : n < 3 ? 2 : n < 7 ? 5 : 10) * mag;
}

typedef struct { double lo, hi, step; int log_y; } axis;

static void tick_label(char *buf, size_t n, double v, const axis *a) {
    if (a->log_y) snprintf(buf, n, "%g", pow(10.0, v));
    else snprintf(buf, n, "%.6g", fabs(v) < a->step * 1e-6 ? 0.0 : v);
}

/* i-th tick of an axis, i = 0.. while <= hi (no accumulated rounding) */
static int y_tick(const axis *a, int i, double *v) {
    *v = a->lo + i * a->step;
    return *v <= a->hi + a->step * 1e-6;
}
static int x_tick(const axis *a, int i, double *v) {
    *v = (ceil(a->lo / a->step - 1e-9) + i) * a->step;
    return *v <= a->hi + a->step * 1e-9;
}

static int ok_value(double v, int log_y) { return v == v && fabs(v) <= 1e300 && (!log_y || v > 0); }

/* y range of a panel: nice linear ticks (from 0 when nothing is negative) or decades */
static void y_axis(const plot_panel *p, axis *a) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    int i, k;
    a->log_y = p->log_y;
    for (i = 0; i < p->ns; i++)
        for (k = 0; k < p->s[i].n; k++) {
            double v = p->s[i].y[k];
            if (!ok_value(v, p->log_y)) continue;
            if (p->log_y) v = log10(v);
            if (v < lo) lo = v;
            if (v > hi) hi = v;
        }
    if (lo > hi) { lo = 0; hi = 1; }
    if (p->log_y) {
        a->lo = floor(lo); a->hi = ceil(hi);
        if (a->hi <= a->lo) a->hi = a->lo + 1;
        a->step = ceil((a->hi - a->lo) / 8);
        return;
    }
    if (lo > 0) lo = 0;
    if (hi <= lo) hi = lo + (lo < 0 ? -lo : 1);
    a->step = plot_tick_step(hi - lo, 5);
    a->lo = floor(lo / a->step + 1e-9) * a->step;
    a->hi = ceil(hi / a->step - 1e-9) * a->step;
}

/* Square of side 2r at (x, y), clipped to [x0, x1) x [y0, y1). */
static void stamp(rs_image *im, double x, double y, double r, const uint8_t c[3], int x0, int y0, int x1, int y1) {
    int a = (int)floor(x - r + 0.5), b = (int)floor(x + r + 0.5), u = (int)floor(y - r + 0.5), v = (int)floor(y + r + 0.5);
    if (a < x0) a = x0;
    if (u < y0) u = y0;
    if (b > x1) b = x1;
    if (v > y1) v = y1;
    for (; u < v; u++) {
        int q;
        for (q = a; q < b; q++) memcpy(im->rgb + 3 * ((size_t)u * (size_t)im->w + (size_t)q), c, 3);
    }
}

static void segment(rs_image *im, double ax, double ay, double bx, double by, double r, const uint8_t c[3],
                    int x0, int y0, int x1, int y1) {
    double dx = bx - ax, dy = by - ay, len = fabs(dx) > fabs(dy) ? fabs(dx) : fabs(dy);
    int n = (int)ceil(len), i;
    if (n > 100000) n = 100000;
    for (i = 0; i <= n; i++) {
        double t = n ? (double)i / n : 0;
        stamp(im, ax + t * dx, ay + t * dy, r, c, x0, y0, x1, y1);
    }
}

int plot_draw(rs_image *im, const char *title, const char *xlabel, const plot_panel *p, int np) {
    rs_image big;
    axis ax[8], xa;
    char lab[64];
    int ts = im->w >= 640 && im->h >= 360 ? 2 : 1, ch = 7 * ts, cw = 6 * ts;
    int i, k, j, lw = 0, L, R, T, B, hb, ph, legend = 0;
    double xlo = HUGE_VAL, xhi = -HUGE_VAL;
    if (np < 1 || np > 8) return -1;
    /* axes and margins (1x pixels) */
    for (j = 0; j < np; j++) {
        double v;
        y_axis(&p[j], &ax[j]);
        for (k = 0; y_tick(&ax[j], k, &v); k++) {
            tick_label(lab, sizeof lab, v, &ax[j]);
            if ((int)strlen(lab) > lw) lw = (int)strlen(lab);
        }
        for (i = 0; i < p[j].ns; i++) {
            if (p[j].s[i].label) legend = 1;
            for (k = 0; k < p[j].s[i].n; k++) {
                double x = p[j].s[i].x[k];
                if (!ok_value(x, 0)) continue;
                if (x < xlo) xlo = x;
                if (x > xhi) xhi = x;
            }
        }
    }
    if (xlo > xhi) { xlo = 0; xhi = 1; }
    if (xhi <= xlo) xhi = xlo + 1;
    if (xlo > 0 && xlo <= 0.05 * (xhi - xlo)) xlo = 0;   /* time series from (nearly) 0 */
    xa.log_y = 0;
    xa.step = plot_tick_step(xhi - xlo, im->w >= 480 ? 8 : 4);
    xa.lo = xlo; xa.hi = xhi;
    L = 8 + lw * cw + 6; R = 14 + cw;
    T = title ? ch + 14 : 4;
    hb = ch + ch / 2 + 10;                         /* panel title band */
    B = ch + 10 + (xlabel ? ch + 8 : 0) + 6;
    ph = (im->h - T - B - np * hb) / np;
    if (ph < 20 || im->w - L - R < 40) return -1;
    if (rs_image_alloc(&big, 2 * im->w, 2 * im->h)) return -1;
    memset(big.rgb, 255, (size_t)big.w * (size_t)big.h * 3);
    for (j = 0; j < np; j++) {
        int y0 = T + j * (ph + hb) + hb, y1 = y0 + ph, x0 = L, x1 = im->w - R;
        double v;
        /* grid: x ticks, y ticks */
        for (k = 0; x_tick(&xa, k, &v); k++) {
            int gx = x0 + (int)floor((v - xlo) / (xhi - xlo) * (x1 - x0) + 0.5);
            rs_fill(&big, 2 * gx, 2 * y0, 2, 2 * ph, grid_c);
        }
        for (k = 0; y_tick(&ax[j], k, &v); k++) {
            int gy = y1 - (int)floor((v - ax[j].lo) / (ax[j].hi - ax[j].lo) * ph + 0.5);
            rs_fill(&big, 2 * x0, 2 * gy, 2 * (x1 - x0), 2, grid_c);
        }
        /* series */
        for (i = 0; i < p[j].ns; i++) {
            const plot_series *s = &p[j].s[i];
            double px = 0, py = 0;
            int have = 0;
            for (k = 0; k < s->n; k++) {
                double x = s->x[k], y = s->y[k], qx, qy;
                if (!ok_value(x, 0) || !(y == y)) { have = 0; continue; }
                if (ax[j].log_y) y = y > 0 ? log10(y) : ax[j].lo;
                if (y > ax[j].hi) y = ax[j].hi;
                if (y < ax[j].lo) y = ax[j].lo;
                qx = 2 * (x0 + (x - xlo) / (xhi - xlo) * (x1 - x0));
                qy = 2 * (y1 - (y - ax[j].lo) / (ax[j].hi - ax[j].lo) * ph);
                if (have) segment(&big, px, py, qx, qy, 1.5, palette[i & 3], 2 * x0, 2 * y0 - 2, 2 * x1, 2 * y1 + 2);
                else stamp(&big, qx, qy, 1.5, palette[i & 3], 2 * x0, 2 * y0 - 2, 2 * x1, 2 * y1 + 2);
                px = qx; py = qy; have = 1;
            }
        }
        /* frame */
        rs_fill(&big, 2 * x0 - 2, 2 * y0 - 2, 2 * (x1 - x0) + 4, 2, frame_c);
        rs_fill(&big, 2 * x0 - 2, 2 * y1, 2 * (x1 - x0) + 4, 2, frame_c);
        rs_fill(&big, 2 * x0 - 2, 2 * y0 - 2, 2, 2 * ph + 4, frame_c);
        rs_fill(&big, 2 * x1, 2 * y0 - 2, 2, 2 * ph + 4, frame_c);
    }
    rs_downsample2(&big, im);
    rs_image_free(&big);
    /* text */
    if (title) rs_draw_text(im, L, 6, ts, title, text_c);
    for (j = 0; j < np; j++) {
        int y0 = T + j * (ph + hb) + hb, y1 = y0 + ph, x0 = L, x1 = im->w - R;
        double v;
        if (p[j].title) rs_draw_text(im, x0, y0 - ch - 6, ts, p[j].title, text_c);
        if (legend) {   /* right-aligned in the title band */
            int x = x1;
            for (i = p[j].ns - 1; i >= 0; i--) {
                const char *t = p[j].s[i].label ? p[j].s[i].label : "";
                x -= (int)strlen(t) * cw;
                rs_draw_text(im, x, y0 - ch - 6, ts, t, text_c);
                x -= 3 * cw;
                rs_fill(im, x, y0 - ch - 6 + ch / 2 - ts, 2 * cw, 2 * ts, palette[i & 3]);
                x -= 2 * cw;
            }
        }
        for (k = 0; y_tick(&ax[j], k, &v); k++) {
            int gy = y1 - (int)floor((v - ax[j].lo) / (ax[j].hi - ax[j].lo) * ph + 0.5);
            tick_label(lab, sizeof lab, v, &ax[j]);
            rs_draw_text(im, x0 - 6 - (int)strlen(lab) * cw, gy - ch / 2, ts, lab, text_c);
        }
        if (j == np - 1) {
            for (k = 0; x_tick(&xa, k, &v); k++) {
                int gx = x0 + (int)floor((v - xlo) / (xhi - xlo) * (x1 - x0) + 0.5);
                tick_label(lab, sizeof lab, v, &xa);
                rs_draw_text(im, gx - (int)strlen(lab) * cw / 2, y1 + 6, ts, lab, text_c);
            }
            if (xlabel) rs_draw_text(im, x0 + (x1 - x0) / 2 - (int)strlen(xlabel) * cw / 2, y1 + ch + 14, ts, xlabel, text_c);
        }
    }
    return 0;
}
