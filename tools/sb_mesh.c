/* sb_mesh.c -- OBJ reader (polygons fan-triangulated), closedness check,
 * volume by the divergence theorem, and a point-in-mesh test by ray parity. */
#include "sb.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

int sb_mesh_load_obj(const char *path, sb_mesh *m)
{
    FILE *f = fopen(path, "r");
    char line[4096];
    int lineno = 0, capv = 1024, capt = 1024, k, i;
    memset(m, 0, sizeof *m);
    if (!f) return sb_fail("%s: cannot open mesh: %s", path, strerror(errno));
    m->v = malloc(sizeof(double) * 3 * (size_t)capv);
    m->tri = malloc(sizeof(int) * 3 * (size_t)capt);
    if (!m->v || !m->tri) { fclose(f); return sb_fail("out of memory"); }
    while (fgets(line, sizeof line, f)) {
        char *tok[64], *s;
        int nt = 0;
        lineno++;
        if (!strchr(line, '\n') && !feof(f)) { fclose(f); return sb_fail("%s:%d: line too long", path, lineno); }
        for (s = strtok(line, " \t\r\n"); s && nt < 64; s = strtok(NULL, " \t\r\n")) tok[nt++] = s;
        if (nt == 0 || tok[0][0] == '#') continue;
        if (!strcmp(tok[0], "v")) {
            double p[3];
            if (nt < 4 || nt > 5) { fclose(f); return sb_fail("%s:%d: malformed vertex (want 'v x y z')", path, lineno); }
            for (k = 0; k < 3; k++)
                if (!parse_real(tok[1 + k], &p[k])) { fclose(f); return sb_fail("%s:%d: malformed vertex coordinate '%s'", path, lineno, tok[1 + k]); }
            if (m->nv == capv) { capv *= 2; m->v = realloc(m->v, sizeof(double) * 3 * (size_t)capv); if (!m->v) { fclose(f); return sb_fail("out of memory"); } }
            memcpy(m->v + 3 * m->nv, p, sizeof p);
            m->nv++;
        } else if (!strcmp(tok[0], "f")) {
            int idx[64];
            if (nt < 4) { fclose(f); return sb_fail("%s:%d: malformed face (fewer than 3 vertices)", path, lineno); }
            for (k = 1; k < nt; k++) {
                idx[k - 1] = parse_index(tok[k], m->nv);
                if (idx[k - 1] < 0) { fclose(f); return sb_fail("%s:%d: malformed face: bad or out-of-range vertex index '%s'", path, lineno, tok[k]); }
            }
            for (k = 2; k < nt - 1; k++) {   /* fan keeps the polygon's orientation */
                if (m->nt == capt) { capt *= 2; m->tri = realloc(m->tri, sizeof(int) * 3 * (size_t)capt); if (!m->tri) { fclose(f); return sb_fail("out of memory"); } }
                m->tri[3 * m->nt] = idx[0]; m->tri[3 * m->nt + 1] = idx[k - 1]; m->tri[3 * m->nt + 2] = idx[k];
                if (idx[0] == idx[k - 1] || idx[k] == idx[k - 1] || idx[0] == idx[k]) { fclose(f); return sb_fail("%s:%d: degenerate face (repeated vertex)", path, lineno); }
                m->nt++;
            }
        } else if (!strcmp(tok[0], "vt") || !strcmp(tok[0], "vn") || !strcmp(tok[0], "vp") || !strcmp(tok[0], "o") ||
                   !strcmp(tok[0], "g") || !strcmp(tok[0], "s") || !strcmp(tok[0], "usemtl") || !strcmp(tok[0], "mtllib")) {
            continue;   /* attributes the bake does not need */
        } else {
            fclose(f);
            return sb_fail("%s:%d: malformed OBJ: unsupported statement '%s'", path, lineno, tok[0]);
        }
    }
    fclose(f);
    if (m->nv == 0 || m->nt == 0) return sb_fail("%s: mesh has no vertices or no faces", path);
    if ((unsigned)m->nv > 65535u) return sb_fail("%s: %d vertices; a blob holds at most 65535 surface vertices", path, m->nv);
    /* closed, consistently oriented 2-manifold: every edge in exactly two faces, once each way */
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
    for (k = 0; k < 3; k++) { m->lo[k] = HUGE_VAL; m->hi[k] = -HUGE_VAL; }
    for (i = 0; i < m->nv; i++)
        for (k = 0; k < 3; k++) {
            if (m->v[3 * i + k] < m->lo[k]) m->lo[k] = m->v[3 * i + k];
            if (m->v[3 * i + k] > m->hi[k]) m->hi[k] = m->v[3 * i + k];
        }
    if (sb_mesh_volume(m) <= 0.0)
        return sb_fail("%s: mesh encloses a non-positive volume: faces must be counter-clockwise seen from outside", path);
    return 0;
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
    /* about 4 triangles per bin on average for a closed surface */
    in->ny = in->nz = (int)ceil(sqrt((double)m->nt / 4.0)) + 1;
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

int sb_inside_test(const sb_inside *in, const double q[3])
{
    const sb_mesh *m = in->m;
    int by, bz, b, t, crossings = 0;
    if (q[0] < m->lo[0] || q[0] > m->hi[0] || q[1] < m->lo[1] || q[1] > m->hi[1] || q[2] < m->lo[2] || q[2] > m->hi[2]) return 0;
    by = (int)floor((q[1] - in->y0) / in->dy); bz = (int)floor((q[2] - in->z0) / in->dz);
    if (by < 0 || bz < 0 || by >= in->ny || bz >= in->nz) return 0;
    b = by * in->nz + bz;
    for (t = in->start[b]; t < in->start[b + 1]; t++) {
        int i = in->tris[t], k, pos = 0, neg = 0, tie;
        const double *v[3];
        double e[3], area, xh;
        for (k = 0; k < 3; k++) v[k] = m->v + 3 * m->tri[3 * i + k];
        for (k = 0; k < 3; k++) {
            e[k] = edge_fn(v[k], v[(k + 1) % 3], q[1], q[2], &tie);
            if (e[k] > 0 || (e[k] == 0 && tie)) pos++;
            if (e[k] < 0 || (e[k] == 0 && !tie)) neg++;
        }
        if (pos != 3 && neg != 3) continue;
        area = e[0] + e[1] + e[2];
        if (area == 0.0) continue;
        /* x of the ray's hit from barycentrics (e[k] weights the vertex opposite edge k) */
        xh = (e[1] * v[0][0] + e[2] * v[1][0] + e[0] * v[2][0]) / area;
        if (xh > q[0]) crossings++;
    }
    return crossings & 1;
}
