/* plot.h -- line plots of per-frame series (energy, displacement) as
 * pictures: stacked panels sharing the x axis, nice tick values labelled
 * with the rasterizer's bitmap font, optional log scale. libc + libm. */
#ifndef SN_PLOT_H
#define SN_PLOT_H
#include "raster.h"

typedef struct plot_series {
    const double *x, *y;     /* n points, x increasing */
    int n;
    const char *label;       /* legend entry, or NULL */
} plot_series;

typedef struct plot_panel {
    const char *title;       /* drawn at the panel's top left, e.g. "energy (J)" */
    const plot_series *s;
    int ns;
    int log_y;               /* log10 axis: values <= 0 are drawn at the bottom */
} plot_panel;

/// Draw np panels, one above the other, into im (already allocated; at
/// least 160 x 60 per panel). title on top, xlabel under the x axis.
/// Returns 0, or -1 when out of memory.
int plot_draw(rs_image *im, const char *title, const char *xlabel, const plot_panel *p, int np);

/// Nice tick step (1, 2 or 5 times a power of ten) giving about `want` ticks
/// over a range of span > 0.
double plot_tick_step(double span, int want);

#endif
