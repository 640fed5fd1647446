/* plot_csv.c -- sinew-plot: line plots (PNG) of columns of one or more CSV
 * files written by `sinew-play --stats-csv`, overlaid (e.g. energy before
 * and after a change). */
#define _POSIX_C_SOURCE 200809L
#include "plot.h"
#include "png.h"
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PROG "sinew-plot"
#define MAX_FILES 4
#define MAX_COLS 6

static void usage(FILE *f) {
    fprintf(f,
        "usage: " PROG " --out FILE.png CSV [CSV...]  (at most %d files)\n"
        "Plots columns of sinew-play --stats-csv files against t_s, one panel per column,\n"
        "the files overlaid in colours.\n"
        "  --out FILE.png     the picture (required)\n"
        "  --columns A,B      columns to plot (default energy_J,disp_cells; at most %d)\n"
        "  --labels A,B       legend entries, one per file (default: the file names)\n"
        "  --title TEXT       caption\n"
        "  --size WxH         picture size (default 800x500)\n"
        "  --log              logarithmic y axes (values <= 0 drawn at the bottom)\n"
        "  --help\n"
        "Exit status: 0 ok, 1 bad input or failed output, 2 usage.\n", MAX_FILES, MAX_COLS);
}

typedef struct { double *x, *y[MAX_COLS]; int n, has_t; } table;

/* Split s at ',' into at most max fields (s is modified). -1 if more. */
static int split(char *s, char **f, int max) {
    int n = 0;
    for (;;) {
        if (n == max) return -1;
        f[n++] = s;
        s = strchr(s, ',');
        if (!s) return n;
        *s++ = 0;
    }
}

static int read_table(const char *path, char *const *cols, int nc, table *t, char *err, size_t errlen) {
    FILE *f = fopen(path, "r");
    char line[4096], *fld[64];
    int idx[MAX_COLS], ix = -1, nf, i, cap = 0;
    long ln = 1;
    memset(t, 0, sizeof *t);
    if (!f) { snprintf(err, errlen, "cannot read %s: %s", path, strerror(errno)); return -1; }
    if (!fgets(line, sizeof line, f)) { snprintf(err, errlen, "%s: empty file", path); fclose(f); return -1; }
    line[strcspn(line, "\r\n")] = 0;
    if ((nf = split(line, fld, 64)) < 0) { snprintf(err, errlen, "%s: too many columns", path); fclose(f); return -1; }
    for (i = 0; i < nf; i++) if (!strcmp(fld[i], "t_s")) ix = i;
    t->has_t = ix >= 0;
    for (i = 0; i < nc; i++) {
        int k;
        for (idx[i] = -1, k = 0; k < nf; k++) if (!strcmp(fld[k], cols[i])) idx[i] = k;
        if (idx[i] < 0) { snprintf(err, errlen, "%s: no column '%s' in the header line", path, cols[i]); fclose(f); return -1; }
    }
    while (fgets(line, sizeof line, f)) {
        char *end;
        ln++;
        line[strcspn(line, "\r\n")] = 0;
        if (!line[0]) continue;
        if (t->n == cap) {
            cap = cap ? 2 * cap : 1024;
            for (i = -1; i < nc; i++) {
                double **a = i < 0 ? &t->x : &t->y[i], *q = realloc(*a, (size_t)cap * sizeof(double));
                if (!q) { snprintf(err, errlen, "%s: out of memory", path); fclose(f); return -1; }
                *a = q;
            }
        }
        nf = split(line, fld, 64);
        if (nf < 0) { snprintf(err, errlen, "%s:%ld: too many fields", path, ln); fclose(f); return -1; }
        t->x[t->n] = t->n;
        if (ix >= 0) {
            if (ix >= nf || !*fld[ix] || (t->x[t->n] = strtod(fld[ix], &end), *end)) goto bad;
        }
        for (i = 0; i < nc; i++)
            if (idx[i] >= nf || !*fld[idx[i]] || (t->y[i][t->n] = strtod(fld[idx[i]], &end), *end)) goto bad;
        t->n++;
        continue;
    bad:
        snprintf(err, errlen, "%s:%ld: a field is missing or not a number", path, ln); fclose(f); return -1;
    }
    fclose(f);
    if (!t->n) { snprintf(err, errlen, "%s: no data rows", path); return -1; }
    return 0;
}

static const char *panel_title(const char *col) {
    if (!strcmp(col, "energy_J")) return "energy (J)";
    if (!strcmp(col, "disp_cells")) return "largest displacement (cells)";
    return col;
}

int main(int argc, char **argv) {
    const char *out = NULL, *title = NULL, *files[MAX_FILES];
    char colbuf[512] = "energy_J,disp_cells", labbuf[512] = "", *cols[MAX_COLS], *labs[MAX_FILES], err[4200];
    int nfiles = 0, nc, nl = 0, w = 800, h = 500, log_y = 0, i, j, rc = 1;
    table t[MAX_FILES];
    plot_series s[MAX_COLS][MAX_FILES];
    plot_panel p[MAX_COLS];
    rs_image im;
    memset(t, 0, sizeof t);
    memset(&im, 0, sizeof im);
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        int valued = !strcmp(a, "--out") || !strcmp(a, "--columns") || !strcmp(a, "--labels") ||
                     !strcmp(a, "--title") || !strcmp(a, "--size");
        if (valued && i + 1 >= argc) { fprintf(stderr, PROG ": %s needs a value (try --help)\n", a); return 2; }
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { usage(stdout); return 0; }
        else if (!strcmp(a, "--out")) out = argv[++i];
        else if (!strcmp(a, "--title")) title = argv[++i];
        else if (!strcmp(a, "--columns")) snprintf(colbuf, sizeof colbuf, "%s", argv[++i]);
        else if (!strcmp(a, "--labels")) snprintf(labbuf, sizeof labbuf, "%s", argv[++i]);
        else if (!strcmp(a, "--size")) {
            char c;
            if (sscanf(argv[++i], "%dx%d%c", &w, &h, &c) != 2 || w < 160 || h < 120 || w > 4096 || h > 4096) {
                fprintf(stderr, PROG ": --size: want WxH (160x120..4096x4096), got '%s'\n", argv[i]); return 2;
            }
        } else if (!strcmp(a, "--log")) log_y = 1;
        else if (a[0] == '-' && a[1]) { fprintf(stderr, PROG ": unknown option '%s' (try --help)\n", a); return 2; }
        else if (nfiles == MAX_FILES) { fprintf(stderr, PROG ": at most %d CSV files\n", MAX_FILES); return 2; }
        else files[nfiles++] = a;
    }
    if (!out || !nfiles) { usage(stderr); return 2; }
    if ((nc = split(colbuf, cols, MAX_COLS)) < 0) { fprintf(stderr, PROG ": --columns: at most %d\n", MAX_COLS); return 2; }
    for (i = 0; i < nc; i++) if (!*cols[i]) { fprintf(stderr, PROG ": --columns: empty column name\n"); return 2; }
    if (labbuf[0] && (nl = split(labbuf, labs, MAX_FILES)) != nfiles) {
        fprintf(stderr, PROG ": --labels: want %d label%s, one per file\n", nfiles, nfiles > 1 ? "s" : ""); return 2;
    }
    for (j = 0; j < nfiles; j++)
        if (read_table(files[j], cols, nc, &t[j], err, sizeof err)) { fprintf(stderr, PROG ": %s\n", err); goto done; }
    for (i = 0; i < nc; i++) {
        for (j = 0; j < nfiles; j++) {
            const char *base = strrchr(files[j], '/');
            s[i][j].x = t[j].x; s[i][j].y = t[j].y[i]; s[i][j].n = t[j].n;
            s[i][j].label = nl ? labs[j] : nfiles > 1 ? (base ? base + 1 : files[j]) : NULL;
        }
        p[i].title = panel_title(cols[i]); p[i].s = s[i]; p[i].ns = nfiles; p[i].log_y = log_y;
    }
    if (rs_image_alloc(&im, w, h)) { fprintf(stderr, PROG ": out of memory\n"); goto done; }
    if (plot_draw(&im, title, t[0].has_t ? "time (s)" : "row", p, nc)) {
        fprintf(stderr, PROG ": %dx%d is too small for %d panels\n", w, h, nc); rc = 2; goto done;
    }
    if (png_write(out, im.rgb, im.w, im.h, err, sizeof err)) { fprintf(stderr, PROG ": %s\n", err); goto done; }
    printf("wrote %s\n", out);
    rc = 0;
done:
    rs_image_free(&im);
    for (j = 0; j < nfiles; j++) {
        free(t[j].x);
        for (i = 0; i < nc; i++) free(t[j].y[i]);
    }
    return rc;
}
