/* segref.c -- see segref.h. */
#include "segref.h"
#include <math.h>
#include <string.h>

static void nodes_of(const segref *r, int i, int *a, int *b) {
    int s = r->side, nh = s * (s - 1);
    if (r->kind == 0) { *a = i; *b = i + 1; return; }
    if (i < nh) { *a = (i / (s - 1)) * s + i % (s - 1); *b = *a + 1; }
    else { *a = i - nh; *b = *a + s; }
}
/* ends at node n in ring order: left/up (end, +1), right/down (start, -1) */
static int ends_of(const segref *r, int n, int seg[4], int sg[4]) {
    int k = 0, s = r->side, row, c, nh;
    if (r->kind == 0) {
        if (n > 0) { seg[k] = n - 1; sg[k++] = 1; }
        if (n + 1 < s) { seg[k] = n; sg[k++] = -1; }
        return k;
    }
    row = n / s; c = n % s; nh = s * (s - 1);
    if (c > 0) { seg[k] = row * (s - 1) + c - 1; sg[k++] = 1; }
    if (row > 0) { seg[k] = nh + n - s; sg[k++] = 1; }
    if (c + 1 < s) { seg[k] = row * (s - 1) + c; sg[k++] = -1; }
    if (row + 1 < s) { seg[k] = nh + n; sg[k++] = -1; }
    return k;
}
static void unit(double x[3]) {
    double n = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    if (n > 0) { x[0] /= n; x[1] /= n; x[2] /= n; }
}
static void cross(const double a[3], const double b[3], double o[3]) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
static double clampd(double x, double m) { return x > m ? m : (x < -m ? -m : x); }
/* u + th x u, |th_k| <= 0.25, then one Newton step towards unit length
 * x (3 - |x|^2)/2 (the runtime's multiply-only step; exact unit after the sweeps) */
static void turn(double u[3], const double th[3]) {
    double t[3], c[3], f;
    int k;
    for (k = 0; k < 3; k++) t[k] = clampd(th[k], 0.25);
    cross(t, u, c);
    for (k = 0; k < 3; k++) u[k] += c[k];
    f = 1.5 - 0.5 * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (k = 0; k < 3; k++) u[k] *= f;
}
static void endp(const segref *r, int i, int s, double P[3]) {
    int k;
    for (k = 0; k < 3; k++) P[k] = r->G[i][k] + s * 0.5 * r->len * r->u[i][k];
}
/* move segment i: centre by t, turn u + e closing rf of the perpendicular gap
 * at end s: e = s rf d_perp / h (= dTheta x u), components limited to 0.25,
 * e's part along u removed, one Newton step (the runtime's move) */
static void move(segref *r, int i, int s, const double t[3], const double d[3], double rf) {
    double e[3], h = 0.5 * r->len, du, eu, f, *u = r->u[i];
    int k;
    du = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
    for (k = 0; k < 3; k++) {
        e[k] = clampd(s * rf * (d[k] - du * u[k]) / h, 0.25);
        r->G[i][k] += t[k];
    }
    eu = e[0] * u[0] + e[1] * u[1] + e[2] * u[2];
    for (k = 0; k < 3; k++) u[k] += e[k] - eu * u[k];
    f = 1.5 - 0.5 * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (k = 0; k < 3; k++) u[k] *= f;
}
static double norm(const double d[3]) { return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]); }

void segref_init(segref *r, int kind, int side, const double *nodes, double len, double gamma, double keep,
                 double inv_mass, double centre, int sweeps, const double grav[3]) {
    int i, k, a, b;
    memset(r, 0, sizeof *r);
    r->kind = kind; r->side = side;
    r->nn = kind ? side * side : side;
    r->ns = kind ? 2 * side * (side - 1) : side - 1;
    r->len = len; r->gamma = gamma; r->keep = keep; r->inv_mass = inv_mass; r->centre = centre;
    r->sweeps = sweeps;
    r->omega = 1;
    for (k = 0; k < 3; k++) r->grav[k] = grav[k];
    for (i = 0; i < r->nn; i++)
        for (k = 0; k < 3; k++) r->N[i][k] = nodes[3 * i + k];
    for (i = 0; i < r->ns; i++) {
        nodes_of(r, i, &a, &b);
        for (k = 0; k < 3; k++) {
            r->G[i][k] = 0.5 * (r->N[a][k] + r->N[b][k]);
            r->u[i][k] = r->N[b][k] - r->N[a][k];
        }
        unit(r->u[i]);
    }
}

/* order (SEGMENTS.md "Sweep"): attachments; chain nodes up (dir 0) or down
 * (dir 1); sheet nodes row-major (dir 0) or reversed (dir 1), a node of 3 or
 * 4 ends projected towards their mean (star), a corner's 2 ends as a pair */
static void sweep(segref *r, int measure, int dir) {
    int q, n, j, k, i, seg[4], sg[4], ne;
    for (i = 0; i < r->n_att; i++) {
        ne = ends_of(r, r->att_node[i], seg, sg);
        for (j = 0; j < ne; j++) {
            double P[3], d[3], t[3];
            endp(r, seg[j], sg[j], P);
            for (k = 0; k < 3; k++) { d[k] = r->att_T[i][k] - P[k]; t[k] = r->omega * r->gamma * d[k]; }
            if (measure) { double g = norm(d) / r->len; r->gap = g > r->gap ? g : r->gap; continue; }
            move(r, seg[j], sg[j], t, d, r->omega * (1 - r->gamma));
        }
    }
    for (q = 0; q < r->nn; q++) {
        /* chain: up (dir 0) or down; sheet: row-major, reversed on odd sweeps */
        n = dir ? r->nn - 1 - q : q;
        ne = ends_of(r, n, seg, sg);
        if (r->kind && ne >= 3 && !measure) {
            /* star: every end towards the ends' mean m, as an attachment to m:
             * t = omega gamma (m - P_j), turn closing omega (1-gamma) of its
             * perpendicular part (SEGMENTS.md, node projection) */
            double P[4][3], m[3] = {0, 0, 0};
            for (j = 0; j < ne; j++) {
                endp(r, seg[j], sg[j], P[j]);
                for (k = 0; k < 3; k++) m[k] += P[j][k] / ne;
            }
            for (j = 0; j < ne; j++) {
                double d[3], t[3];
                for (k = 0; k < 3; k++) { d[k] = m[k] - P[j][k]; t[k] = r->omega * r->gamma * d[k]; }
                move(r, seg[j], sg[j], t, d, r->omega * (1 - r->gamma));
            }
            continue;
        }
        for (j = 0; j < ne && (j + 1 < ne || ne >= 3); j++) {
            int a = seg[j], sa = sg[j], b = seg[(j + 1) % ne], sb = sg[(j + 1) % ne];
            double P1[3], P2[3], d[3], nd[3], t[3], nt[3];
            endp(r, a, sa, P1); endp(r, b, sb, P2);
            for (k = 0; k < 3; k++) {
                d[k] = P2[k] - P1[k]; nd[k] = -d[k];
                t[k] = 0.5 * r->omega * r->gamma * d[k]; nt[k] = -t[k];
            }
            if (measure) { double g = norm(d) / r->len; r->gap = g > r->gap ? g : r->gap; continue; }
            move(r, a, sa, t, d, 0.5 * r->omega * (1 - r->gamma));
            move(r, b, sb, nt, nd, 0.5 * r->omega * (1 - r->gamma));
        }
    }
    if (r->floor_on && !measure)
        for (i = 0; i < r->ns; i++)
            for (j = 0; j < 2; j++) {
                int s = j ? 1 : -1;
                double P[3], d[3], t[3], pen;
                endp(r, i, s, P);
                pen = r->foff - (r->fn[0] * P[0] + r->fn[1] * P[1] + r->fn[2] * P[2]);
                if (pen < 0) pen = 0;
                for (k = 0; k < 3; k++) { d[k] = pen * r->fn[k]; t[k] = r->gamma * d[k]; }
                move(r, i, s, t, d, 1 - r->gamma);
            }
}

void segref_step(segref *r) {
    static double G0[SEGREF_MAXS][3], u0[SEGREF_MAXS][3];
    int i, k, n, j, ne, seg[4], sg[4];
    for (i = 0; i < r->ns; i++)
        for (k = 0; k < 3; k++) { r->v[i][k] = r->keep * r->v[i][k] + r->grav[k]; r->w[i][k] *= r->keep; }
    for (n = 0; n < r->nn; n++) { /* impulses: J/ne per end, all translates, (1-centre) turns */
        ne = ends_of(r, n, seg, sg);
        for (j = 0; j < ne; j++) {
            double f[3], fe[3], c[3], h = 0.5 * r->len;
            i = seg[j];
            for (k = 0; k < 3; k++) {
                f[k] = r->J[n][k] / ne * r->inv_mass;
                r->v[i][k] += f[k];
                fe[k] = (1 - r->centre) * f[k];
            }
            cross(r->u[i], fe, c);
            for (k = 0; k < 3; k++) r->w[i][k] += sg[j] * 3.0 * clampd(c[k], h) / h;
        }
    }
    for (i = 0; i < r->ns; i++) {
        for (k = 0; k < 3; k++) { G0[i][k] = r->G[i][k]; u0[i][k] = r->u[i][k]; r->G[i][k] += r->v[i][k]; }
        for (k = 0; k < 3; k++) r->w[i][k] = clampd(r->w[i][k], 0.25);
        turn(r->u[i], r->w[i]);
    }
    for (j = 0; j < r->sweeps; j++) sweep(r, 0, j & 1);
    for (i = 0; i < r->ns; i++) unit(r->u[i]);
    for (i = 0; i < r->ns; i++) {
        double w[3];
        cross(u0[i], r->u[i], w);
        for (k = 0; k < 3; k++) { r->v[i][k] = r->G[i][k] - G0[i][k]; r->w[i][k] = clampd(w[k], 0.25); }
    }
    for (n = 0; n < r->nn; n++) {
        double s[3] = {0, 0, 0};
        ne = ends_of(r, n, seg, sg);
        for (j = 0; j < ne; j++) {
            double P[3];
            endp(r, seg[j], sg[j], P);
            for (k = 0; k < 3; k++) s[k] += P[k] / ne;
        }
        for (k = 0; k < 3; k++) { r->N[n][k] = s[k]; r->J[n][k] = 0; }
    }
    r->gap = 0;
    sweep(r, 1, 0);
}
