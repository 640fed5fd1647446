/* sb_mesh.c -- OBJ reader (polygons fan-triangulated), closedness check,
 * volume by the divergence theorem, and a point-in-mesh test by ray parity. */
#include "sb.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Bounds on the OBJ's coordinates (mesh units).
 * SB_MESH_COORD_MAX: |coordinate| <= 1e9. Beyond it a double holds a vertex
 * no closer than 1.2e-7 mesh units (ulp(1e9)), already the Q22 resolution of
 * a one-unit model (2^-23), so the baked rest shape would be rounding noise;
 * and 1e308 made the bounding box infinite and the inside test's bins
 * (int)floor(NaN). SB_MESH_EXTENT_MAX: the mesh's extent along each axis is
 * at most 32768. A blob holds positions within 16384 mesh units of the root
 * joint (runtime/BLOB.md, Validation 7: 2^27 stored Q22 and 2^(36 - len_shift)
 * for len_shift > 9 are both 16384 mesh units, so the public Q16.16 values
 * cannot overflow), so a wider mesh can never bake into a valid blob. */
#define SB_MESH_COORD_MAX 1e9
#define SB_MESH_EXTENT_MAX 32768.0

static int parse_real(const char *s, double *out)
{
    char *end;
    errno = 0;
    *out = strtod(s, &end);
    return end != s && *end == '\0' && isfinite(*out);
}

/* "12", "12/3", "12//5", "-1/..." -> vertex index (0-based) or -1 on error */
static int parse_index(const char *s, int nv)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (end == s || (*end != '\0' && *end != '/')) return -1;
    if (v < 0) v = nv + v + 1;       /* negative = relative to the end */
    if (v < 1 || v > nv) return -1;
    return (int)(v - 1);
}

typedef struct { int a, b, face; } edge_t;
static int edge_cmp(const void *x, const void *y)
{
    const edge_t *p = x, *q = y;
    int pa = p->a < p->b ? p->a : p->b, pb = p->a < p->b ? p->b : p->a;
    int qa = q->a < q->b ? q->a : q->b, qb = q->a < q->b ? q->b : q->a;
    if (pa != qa) return pa < qa ? -1 : 1;
    if (pb != qb) return pb < qb ? -1 : 1;
    return p->face < q->face ? -1 : p->face > q->face;
}

/* edge set: open addressing on the unordered pair (a, b) */
typedef struct { uint64_t *k; size_t cap; } eset_t;
static uint64_t ekey(int a, int b) { return a < b ? ((uint64_t)(unsigned)a << 32 | (unsigned)b) : ((uint64_t)(unsigned)b << 32 | (unsigned)a); }
static size_t eslot(const eset_t *s, uint64_t key)
{
    size_t h = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 17) & (s->cap - 1);
    while (s->k[h] && s->k[h] != key + 1) h = (h + 1) & (s->cap - 1);
    return h;
}
static int ehas(const eset_t *s, int a, int b) { return s->k[eslot(s, ekey(a, b))] != 0; }
static void eadd(eset_t *s, int a, int b) { uint64_t key = ekey(a, b); s->k[eslot(s, key)] = key + 1; }

/* Triangulate polygon p[0..n) as a fan from corner s0 whose diagonals are all new
 * (neither a polygon edge of the mesh nor a diagonal made earlier): a fan whose
 * diagonal repeats an edge makes that edge shared by 4 triangles. The first such
 * start is taken (s0 = 0 when possible: a plain fan from the first corner). */
static int fan_start(const eset_t *es, const int *p, int n)
{
    int s0, k;
    for (s0 = 0; s0 < n; s0++) {
        for (k = 2; k < n - 1; k++) if (ehas(es, p[s0], p[(s0 + k) % n])) break;
        if (k >= n - 1) return s0;
    }
    return -1;
}

/* closed, consistently oriented 2-manifold: every edge in exactly two faces, once each way */
static int closed_check(const char *path, const sb_mesh *m)
{
    int i, k;
    {
        edge_t *e = sb_alloc(sizeof(edge_t) * 3 * (size_t)m->nt);
        int ne = 3 * m->nt;
        for (i = 0; i < m->nt; i++)
            for (k = 0; k < 3; k++) { e[3 * i + k].a = m->tri[3 * i + k]; e[3 * i + k].b = m->tri[3 * i + (k + 1) % 3]; e[3 * i + k].face = i; }
        qsort(e, (size_t)ne, sizeof *e, edge_cmp);
        for (i = 0; i < ne;) {
            int j = i;
            while (j < ne && edge_cmp(&(edge_t){e[i].a, e[i].b, 0}, &(edge_t){e[j].a, e[j].b, 0}) == 0) j++;
            if (j - i != 2 || e[i].a != e[i + 1].b) {
                int a = e[i].a + 1, b = e[i].b + 1, n = j - i;
                free(e);
                if (n != 2) return sb_fail("%s: mesh is not closed: edge between vertices %d and %d is used by %d face(s), want 2", path, a, b, n);
                return sb_fail("%s: mesh is not consistently oriented at the edge between vertices %d and %d", path, a, b);
            }
            i = j;
        }
        free(e);
    }
    return 0;
}

/* The checks every mesh passes once its vertices and triangles are read:
 * counts, closed and oriented, extent, positive volume. `after` qualifies
 * the vertex count ("" or " after welding"); vline_lo/hi (OBJ line of the
 * extreme vertex per axis) may be NULL when the input has no lines. */
static int mesh_finish(const char *path, sb_mesh *m, const char *after, const int *vline_lo, const int *vline_hi)
{
    int i, k;
    if (m->nv == 0 || m->nt == 0) return sb_fail("%s: mesh has no vertices or no faces", path);
    if ((unsigned)m->nv > 65535u) return sb_fail("%s: %d vertices%s; a blob holds at most 65535 surface vertices", path, m->nv, after);
    if (closed_check(path, m)) return -1;
    for (k = 0; k < 3; k++) { m->lo[k] = HUGE_VAL; m->hi[k] = -HUGE_VAL; }
    for (i = 0; i < m->nv; i++)
        for (k = 0; k < 3; k++) {
            if (m->v[3 * i + k] < m->lo[k]) m->lo[k] = m->v[3 * i + k];
            if (m->v[3 * i + k] > m->hi[k]) m->hi[k] = m->v[3 * i + k];
        }
    for (k = 0; k < 3; k++) {
        if (m->hi[k] - m->lo[k] <= SB_MESH_EXTENT_MAX) continue;
        if (vline_lo && vline_hi)
            return sb_fail("%s:%d: vertex at %c = %g is %g mesh units from the vertex at line %d (%c = %g): a mesh may span at "
                           "most %g mesh units along each axis (a blob holds positions within 16384 mesh units of the root "
                           "joint): scale the mesh down and the description's 'unit' up",
                           path, vline_hi[k], "xyz"[k], m->hi[k], m->hi[k] - m->lo[k], vline_lo[k], "xyz"[k], m->lo[k],
                           SB_MESH_EXTENT_MAX);
        return sb_fail("%s: the mesh spans %g mesh units along %c; at most %g (scale the mesh down and the description's 'unit' up)",
                       path, m->hi[k] - m->lo[k], "xyz"[k], SB_MESH_EXTENT_MAX);
    }
    if (sb_mesh_volume(m) <= 0.0)
        return sb_fail("%s: mesh encloses a non-positive volume: faces must be counter-clockwise seen from outside", path);
    return 0;
}

int sb_mesh_load_obj(const char *path, sb_mesh *m)
{
    FILE *f = fopen(path, "r");
    char line[4096];
    int lineno = 0, capv = 1024, k;
    int *pidx = NULL, *pstart = NULL, *pline = NULL, np = 0, capi = 4096, capp = 1024, ntri = 0;
    int vmin[3] = {0, 0, 0}, vmax[3] = {0, 0, 0}, vline_lo[3] = {0, 0, 0}, vline_hi[3] = {0, 0, 0};
    memset(m, 0, sizeof *m);
    if (!f) return sb_fail("%s: cannot open mesh: %s", path, strerror(errno));
    m->v = malloc(sizeof(double) * 3 * (size_t)capv);
    pidx = malloc(sizeof(int) * (size_t)capi);
    pstart = malloc(sizeof(int) * (size_t)(capp + 1));
    pline = malloc(sizeof(int) * (size_t)capp);
    if (!m->v || !pidx || !pstart || !pline) { fclose(f); free(pidx); free(pstart); free(pline); return sb_fail("out of memory"); }
    pstart[0] = 0;
#define MESH_FAIL(...) do { fclose(f); free(pidx); free(pstart); free(pline); return sb_fail(__VA_ARGS__); } while (0)
    while (fgets(line, sizeof line, f)) {
        char *tok[64], *s;
        int nt = 0;
        lineno++;
        if (!strchr(line, '\n') && !feof(f)) MESH_FAIL("%s:%d: line too long", path, lineno);
        for (s = strtok(line, " \t\r\n"); s && nt < 64; s = strtok(NULL, " \t\r\n")) tok[nt++] = s;
        if (nt == 0 || tok[0][0] == '#') continue;
        if (!strcmp(tok[0], "v")) {
            double p[3];
            if (nt < 4 || nt > 5) MESH_FAIL("%s:%d: malformed vertex (want 'v x y z')", path, lineno);
            for (k = 0; k < 3; k++)
                if (!parse_real(tok[1 + k], &p[k])) MESH_FAIL("%s:%d: malformed vertex coordinate '%s'", path, lineno, tok[1 + k]);
                else if (fabs(p[k]) > SB_MESH_COORD_MAX)
                    MESH_FAIL("%s:%d: vertex coordinate '%s' is out of range: |coordinate| must be at most %g mesh units "
                              "(move the mesh near the origin, or scale it and the description's 'unit')",
                              path, lineno, tok[1 + k], SB_MESH_COORD_MAX);
            if (m->nv == capv) { capv *= 2; m->v = realloc(m->v, sizeof(double) * 3 * (size_t)capv); if (!m->v) MESH_FAIL("out of memory"); }
            for (k = 0; k < 3; k++) {   /* lines of the extreme vertices, for the extent message */
                if (m->nv == 0 || p[k] < m->v[3 * vmin[k] + k]) { vmin[k] = m->nv; vline_lo[k] = lineno; }
                if (m->nv == 0 || p[k] > m->v[3 * vmax[k] + k]) { vmax[k] = m->nv; vline_hi[k] = lineno; }
            }
            memcpy(m->v + 3 * m->nv, p, sizeof p);
            m->nv++;
        } else if (!strcmp(tok[0], "f")) {
            int n = nt - 1, a, b;
            if (nt < 4) MESH_FAIL("%s:%d: malformed face (fewer than 3 vertices)", path, lineno);
            if (pstart[np] + n > capi) { capi = 2 * capi + n; pidx = realloc(pidx, sizeof(int) * (size_t)capi); if (!pidx) MESH_FAIL("out of memory"); }
            if (np == capp) {
                capp *= 2;
                pstart = realloc(pstart, sizeof(int) * (size_t)(capp + 1)); pline = realloc(pline, sizeof(int) * (size_t)capp);
                if (!pstart || !pline) MESH_FAIL("out of memory");
            }
            for (k = 0; k < n; k++) {
                int v = parse_index(tok[k + 1], m->nv);
                if (v < 0) MESH_FAIL("%s:%d: malformed face: bad or out-of-range vertex index '%s'", path, lineno, tok[k + 1]);
                pidx[pstart[np] + k] = v;
            }
            for (a = 0; a < n; a++)
                for (b = a + 1; b < n; b++)
                    if (pidx[pstart[np] + a] == pidx[pstart[np] + b]) MESH_FAIL("%s:%d: degenerate face (repeated vertex)", path, lineno);
            pline[np] = lineno;
            pstart[np + 1] = pstart[np] + n;
            np++;
            ntri += n - 2;
        } else if (!strcmp(tok[0], "vt") || !strcmp(tok[0], "vn") || !strcmp(tok[0], "vp") || !strcmp(tok[0], "o") ||
                   !strcmp(tok[0], "g") || !strcmp(tok[0], "s") || !strcmp(tok[0], "usemtl") || !strcmp(tok[0], "mtllib")) {
            continue;   /* attributes the bake does not need */
        } else {
            MESH_FAIL("%s:%d: malformed OBJ: unsupported statement '%s'", path, lineno, tok[0]);
        }
    }
#undef MESH_FAIL
    {   /* triangulate: every polygon edge of the mesh first, then each polygon's diagonals as they are made */
        eset_t es;
        size_t need = 2 * ((size_t)pstart[np] + (size_t)ntri) + 16;
        int p;
        es.cap = 16;
        while (es.cap < need) es.cap *= 2;
        es.k = sb_alloc(sizeof(uint64_t) * es.cap);
        for (p = 0; p < np; p++) {
            int n = pstart[p + 1] - pstart[p], *q = pidx + pstart[p];
            for (k = 0; k < n; k++) eadd(&es, q[k], q[(k + 1) % n]);
        }
        m->tri = malloc(sizeof(int) * 3 * (size_t)(ntri > 0 ? ntri : 1));
        if (!m->tri) { fclose(f); free(es.k); free(pidx); free(pstart); free(pline); return sb_fail("out of memory"); }
        for (p = 0; p < np; p++) {
            int n = pstart[p + 1] - pstart[p], *q = pidx + pstart[p], s0 = n > 3 ? fan_start(&es, q, n) : 0;
            if (s0 < 0) {
                int ln = pline[p];
                fclose(f); free(es.k); free(pidx); free(pstart); free(pline);
                return sb_fail("%s:%d: cannot triangulate this %d-sided face: from every corner, a fan would repeat an edge "
                               "that already exists (split the face in the modelling tool)", path, ln, n);
            }
            for (k = 2; k < n; k++) {   /* fan (s0, s0+k-1, s0+k): keeps the polygon's orientation */
                m->tri[3 * m->nt] = q[s0]; m->tri[3 * m->nt + 1] = q[(s0 + k - 1) % n]; m->tri[3 * m->nt + 2] = q[(s0 + k) % n];
                if (k < n - 1) eadd(&es, q[s0], q[(s0 + k) % n]);
                m->nt++;
            }
        }
        free(es.k);
    }
    free(pidx); free(pstart); free(pline);
    fclose(f);
    return mesh_finish(path, m, "", vline_lo, vline_hi);
}

void sb_mesh_free(sb_mesh *m)
{
    free(m->v); free(m->tri);
    memset(m, 0, sizeof *m);
}

/* V = 1/6 sum over triangles of a . (b x c) (divergence theorem). */
double sb_mesh_volume(const sb_mesh *m)
{
    double vol = 0.0;
    int i;
    for (i = 0; i < m->nt; i++) {
        const double *a = m->v + 3 * m->tri[3 * i], *b = m->v + 3 * m->tri[3 * i + 1], *c = m->v + 3 * m->tri[3 * i + 2];
        vol += a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return vol / 6.0;
}

/* ---- inside test ---- */
void sb_inside_init(sb_inside *in, const sb_mesh *m)
{
    int i, k, y, z, *cnt;
    memset(in, 0, sizeof *in);
    in->m = m;
    /* about one triangle per bin on average for a closed surface */
    in->ny = in->nz = (int)ceil(sqrt((double)m->nt)) + 1;
    in->y0 = m->lo[1]; in->z0 = m->lo[2];
    in->dy = (m->hi[1] - m->lo[1]) / in->ny * (1.0 + 1e-9) + 1e-30;
    in->dz = (m->hi[2] - m->lo[2]) / in->nz * (1.0 + 1e-9) + 1e-30;
    cnt = sb_alloc(sizeof(int) * (size_t)(in->ny * in->nz + 1));
    in->start = sb_alloc(sizeof(int) * (size_t)(in->ny * in->nz + 1));
    for (int pass = 0; pass < 2; pass++) {
        for (i = 0; i < m->nt; i++) {
            double ylo = HUGE_VAL, yhi = -HUGE_VAL, zlo = HUGE_VAL, zhi = -HUGE_VAL;
            int y0, y1, z0, z1;
            for (k = 0; k < 3; k++) {
                const double *p = m->v + 3 * m->tri[3 * i + k];
                ylo = fmin(ylo, p[1]); yhi = fmax(yhi, p[1]); zlo = fmin(zlo, p[2]); zhi = fmax(zhi, p[2]);
            }
            y0 = (int)floor((ylo - in->y0) / in->dy); y1 = (int)floor((yhi - in->y0) / in->dy);
            z0 = (int)floor((zlo - in->z0) / in->dz); z1 = (int)floor((zhi - in->z0) / in->dz);
            if (y0 < 0) y0 = 0;
            if (z0 < 0) z0 = 0;
            if (y1 >= in->ny) y1 = in->ny - 1;
            if (z1 >= in->nz) z1 = in->nz - 1;
            for (y = y0; y <= y1; y++)
                for (z = z0; z <= z1; z++) {
                    int b = y * in->nz + z;
                    if (pass == 0) cnt[b]++;
                    else in->tris[in->start[b] + cnt[b]++] = i;
                }
        }
        if (pass == 0) {
            for (i = 0; i < in->ny * in->nz; i++) in->start[i + 1] = in->start[i] + cnt[i];
            in->tris = sb_alloc(sizeof(int) * (size_t)(in->start[in->ny * in->nz] + 1));
            memset(cnt, 0, sizeof(int) * (size_t)(in->ny * in->nz + 1));
        }
    }
    free(cnt);
}

void sb_inside_free(sb_inside *in)
{
    free(in->start); free(in->tris);
    memset(in, 0, sizeof *in);
}

/* Signed 2-D edge function of q against edge a->b in the (y,z) plane, computed
 * with the endpoints in a canonical order so the two triangles sharing an edge
 * get exactly opposite values (watertight parity on shared edges). */
static double edge_fn(const double *a, const double *b, double qy, double qz, int *tie_pos)
{
    int swap = (a[1] > b[1]) || (a[1] == b[1] && a[2] > b[2]);
    const double *p = swap ? b : a, *r = swap ? a : b;
    double e = (r[1] - p[1]) * (qz - p[2]) - (r[2] - p[2]) * (qy - p[1]);
    /* tie rule: a point exactly on the edge belongs to one side only */
    *tie_pos = swap ? 0 : 1;
    return swap ? -e : e;
}

int sb_inside_ray(const sb_inside *in, double qy, double qz, double *xs, int max)
{
    const sb_mesh *m = in->m;
    int by, bz, b, t, n = 0;
    if (qy < m->lo[1] || qy > m->hi[1] || qz < m->lo[2] || qz > m->hi[2]) return 0;
    by = (int)floor((qy - in->y0) / in->dy); bz = (int)floor((qz - in->z0) / in->dz);
    if (by < 0 || bz < 0 || by >= in->ny || bz >= in->nz) return 0;
    b = by * in->nz + bz;
    for (t = in->start[b]; t < in->start[b + 1]; t++) {
        int i = in->tris[t], k, pos = 0, neg = 0, tie;
        const double *v[3];
        double e[3], area;
        for (k = 0; k < 3; k++) v[k] = m->v + 3 * m->tri[3 * i + k];
        for (k = 0; k < 3; k++) {
            e[k] = edge_fn(v[k], v[(k + 1) % 3], qy, qz, &tie);
            if (e[k] > 0 || (e[k] == 0 && tie)) pos++;
            if (e[k] < 0 || (e[k] == 0 && !tie)) neg++;
        }
        if (pos != 3 && neg != 3) continue;
        area = e[0] + e[1] + e[2];
        if (area == 0.0) continue;
        /* x of the ray's hit from barycentrics (e[k] weights the vertex opposite edge k) */
        if (n < max) xs[n] = (e[1] * v[0][0] + e[2] * v[1][0] + e[0] * v[2][0]) / area;
        n++;
    }
    return n;
}

int sb_inside_test(const sb_inside *in, const double q[3])
{
    const sb_mesh *m = in->m;
    double xs[256], *buf = xs;
    int n, k, crossings = 0;
    if (q[0] < m->lo[0] || q[0] > m->hi[0]) return 0;
    n = sb_inside_ray(in, q[1], q[2], xs, 256);
    if (n > 256) { buf = sb_alloc(sizeof(double) * (size_t)n); sb_inside_ray(in, q[1], q[2], buf, n); }
    for (k = 0; k < n; k++) if (buf[k] > q[0]) crossings++;
    if (buf != xs) free(buf);
    return crossings & 1;
}

/* closest point on triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5) */
static void closest_tri(const double p[3], const double a[3], const double b[3], const double c[3], double out[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3], d1 = 0, d2 = 0, d3 = 0, d4 = 0, d5 = 0, d6 = 0, va, vb, vc, v, w, den;
    int k;
    for (k = 0; k < 3; k++) { ab[k] = b[k] - a[k]; ac[k] = c[k] - a[k]; ap[k] = p[k] - a[k]; bp[k] = p[k] - b[k]; cp[k] = p[k] - c[k]; }
    for (k = 0; k < 3; k++) { d1 += ab[k] * ap[k]; d2 += ac[k] * ap[k]; d3 += ab[k] * bp[k]; d4 += ac[k] * bp[k]; d5 += ab[k] * cp[k]; d6 += ac[k] * cp[k]; }
    if (d1 <= 0 && d2 <= 0) { memcpy(out, a, sizeof(double) * 3); return; }
    if (d3 >= 0 && d4 <= d3) { memcpy(out, b, sizeof(double) * 3); return; }
    vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) { v = d1 / (d1 - d3); for (k = 0; k < 3; k++) out[k] = a[k] + v * ab[k]; return; }
    if (d6 >= 0 && d5 <= d6) { memcpy(out, c, sizeof(double) * 3); return; }
    vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) { w = d2 / (d2 - d6); for (k = 0; k < 3; k++) out[k] = a[k] + w * ac[k]; return; }
    va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (k = 0; k < 3; k++) out[k] = b[k] + w * (c[k] - b[k]);
        return;
    }
    den = 1 / (va + vb + vc);
    v = vb * den; w = vc * den;
    for (k = 0; k < 3; k++) out[k] = a[k] + ab[k] * v + ac[k] * w;
}

double sb_mesh_closest(const sb_mesh *m, const double p[3], double out[3])
{
    double best = HUGE_VAL;
    int t, k;
    for (t = 0; t < m->nt; t++) {
        const double *a = m->v + 3 * m->tri[3 * t], *b = m->v + 3 * m->tri[3 * t + 1], *c = m->v + 3 * m->tri[3 * t + 2];
        double lo, q[3], d2 = 0;
        /* cheap rejection: distance to the triangle's bounding box */
        for (k = 0, lo = 0; k < 3; k++) {
            double mn = fmin(a[k], fmin(b[k], c[k])), mx = fmax(a[k], fmax(b[k], c[k])), e = p[k] < mn ? mn - p[k] : p[k] > mx ? p[k] - mx : 0;
            lo += e * e;
        }
        if (lo >= best) continue;
        closest_tri(p, a, b, c, q);
        for (k = 0; k < 3; k++) d2 += (q[k] - p[k]) * (q[k] - p[k]);
        if (d2 < best) { best = d2; memcpy(out, q, sizeof q); }
    }
    return sqrt(best);
}

/* ---- the surface of a glTF skinned mesh (sb_gltf.h): welded by position ---- */
typedef struct { uint64_t *k; size_t cap; } pset_t;
static uint64_t pos_hash(const double *p)
{
    uint64_t h = 1469598103934665603ULL, u;
    int k;
    for (k = 0; k < 3; k++) {
        double x = p[k] == 0 ? 0 : p[k];   /* -0 welds with +0 */
        memcpy(&u, &x, sizeof u);
        h = (h ^ u) * 1099511628211ULL;
        h ^= h >> 29;
    }
    return h;
}

int sb_mesh_from_points(const char *path, int nsrc, const double *pos, int nsrc_tri, const int *src_tri, sb_mesh *m,
                        int *to_surf, int *dropped)
{
    size_t cap = 16, slot;
    int *first, i, k;
    memset(m, 0, sizeof *m);
    *dropped = 0;
    while (cap < 2 * (size_t)nsrc + 16) cap *= 2;
    first = sb_alloc(cap * sizeof *first);   /* hash slot -> surface vertex + 1 */
    m->v = sb_alloc(3 * sizeof(double) * (size_t)(nsrc > 0 ? nsrc : 1));
    m->tri = sb_alloc(3 * sizeof(int) * (size_t)(nsrc_tri > 0 ? nsrc_tri : 1));
    for (i = 0; i < nsrc; i++) {
        const double *p = pos + 3 * i;
        for (k = 0; k < 3; k++)
            if (!isfinite(p[k]) || fabs(p[k]) > SB_MESH_COORD_MAX)
                { free(first); return sb_fail("%s: vertex %d: coordinate %g is out of range (|coordinate| <= %g mesh units)", path, i, p[k], SB_MESH_COORD_MAX); }
        for (slot = pos_hash(p) & (cap - 1); first[slot]; slot = (slot + 1) & (cap - 1)) {
            const double *q = m->v + 3 * (first[slot] - 1);
            if (q[0] == p[0] && q[1] == p[1] && q[2] == p[2]) break;
        }
        if (!first[slot]) {
            memcpy(m->v + 3 * m->nv, p, 3 * sizeof(double));
            first[slot] = ++m->nv;
        }
        to_surf[i] = first[slot] - 1;
    }
    free(first);
    for (i = 0; i < nsrc_tri; i++) {
        int a = to_surf[src_tri[3 * i]], b = to_surf[src_tri[3 * i + 1]], c = to_surf[src_tri[3 * i + 2]];
        if (a == b || b == c || a == c) { (*dropped)++; continue; }   /* collapsed by the weld */
        m->tri[3 * m->nt] = a, m->tri[3 * m->nt + 1] = b, m->tri[3 * m->nt + 2] = c;
        m->nt++;
    }
    return mesh_finish(path, m, " after welding", NULL, NULL);
}
