/* sb_crease.c -- self-collision near creases, preprocessing (seed 003 §3.4.1).
 *
 * For each 'crease POSE [steps N]' line the character is moved in slow motion
 * from rest to the target pose (each joint's rotation angle grown linearly
 * over N steps, then N/4 steps held) with the double-precision model
 * (tools/ref/snref.c, the same blob maths as the runtime, baked in float64
 * here), and the embedded surface is tracked. A collision is a surface vertex
 * that crosses a triangle's plane from the front (signed distance >= 0 at the
 * previous step, < 0 now), its projection inside the triangle and no deeper
 * than the crease depth: the runtime's inside test (sb_crease_inside). The
 * seed set D is the sequence of (vertex, triangle corner nearest the
 * projection) pairs in the order found, each vertex once per pose, duplicates
 * over poses dropped. Triangles with a corner in the vertex's neighbourhood
 * (VNBR row, below) are never tested, as in the runtime (neighbours fold with
 * the skin and are not collisions), nor triangles with a corner closer to the
 * vertex in the rest pose than 'exclude' (default one lattice cell: on a fine
 * surface over a coarse lattice the one ring is a few mesh units wide and
 * the skin folding within a cell, which the lattice cannot resolve, gave
 * thousands of seeds).
 *
 * Unlike the paper, the slow motion runs without the contact constraints
 * (the reference model has none): after a vertex is recorded the surface
 * keeps interpenetrating, so later vertices may be recorded against deeper
 * triangles than with constraints; D is a superset of the paper's.
 *
 * The surface neighbourhoods the runtime searches (§3.4.2): VNBR row s = the
 * vertices within 'ring' edges of s (s first, then by ring, then by index, at
 * most SN_CREASE_MAX_NBR_V), TNBR row s = the triangles with a corner in
 * VNBR row s within 'tring' rings of s (default: all of the row; 0: the
 * triangles around s) (increasing, at most SN_CREASE_MAX_NBR_T; the outer
 * ring's triangles are dropped first). Output is deterministic: every loop runs in
 * index order and ties go to the lower index.
 */
#include "sb.h"
#include "ref/snref.h"
#include "sb_static.h"
#include "../runtime/src/sn_format.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void sb_crease_free(sb_model *o)
{
    free(o->cr_pairs); free(o->cr_vnbr); free(o->cr_tnbr);
    o->cr_pairs = o->cr_vnbr = o->cr_tnbr = NULL;
    o->crease = 0; o->cr_nD = 0; o->cr_nq = 0;
}

int sb_crease_inside(const double p[3], const double a[3], const double b[3], const double c[3], double depth, double *dist, int *corner)
{
    double e1[3], e2[3], u[3], n[3], x[3], N2, A, B, G, dn;
    int k;
    for (k = 0; k < 3; k++) { e1[k] = b[k] - a[k]; e2[k] = c[k] - a[k]; u[k] = p[k] - a[k]; }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1]; n[1] = e1[2] * e2[0] - e1[0] * e2[2]; n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    N2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (!(N2 > 0)) return 0;
    dn = u[0] * n[0] + u[1] * n[1] + u[2] * n[2];
    x[0] = u[1] * e2[2] - u[2] * e2[1]; x[1] = u[2] * e2[0] - u[0] * e2[2]; x[2] = u[0] * e2[1] - u[1] * e2[0];
    B = x[0] * n[0] + x[1] * n[1] + x[2] * n[2];
    x[0] = e1[1] * u[2] - e1[2] * u[1]; x[1] = e1[2] * u[0] - e1[0] * u[2]; x[2] = e1[0] * u[1] - e1[1] * u[0];
    G = x[0] * n[0] + x[1] * n[1] + x[2] * n[2];
    A = N2 - B - G;
    *dist = dn / sqrt(N2);
    *corner = (B > A && B >= G) ? 1 : ((G > A && G > B) ? 2 : 0);
    return dn < 0 && A >= 0 && B >= 0 && G >= 0 && *dist >= -depth;
}

/* ---------------- surface topology ---------------- */

typedef struct { int *ptr, *idx; } csr_t;

/* vertex -> neighbouring vertices (edges), sorted, and vertex -> triangles */
static void build_adj(const sb_model *o, csr_t *vv, csr_t *vt)
{
    int ns = o->ns, nt = o->nt, i, k, *cnt = sb_alloc(sizeof(int) * (size_t)(ns + 1));
    int *tmp = sb_alloc(sizeof(int) * (size_t)(6 * nt + 1));
    vt->ptr = sb_alloc(sizeof(int) * (size_t)(ns + 1));
    vt->idx = sb_alloc(sizeof(int) * (size_t)(3 * nt + 1));
    for (i = 0; i < 3 * nt; i++) vt->ptr[o->tri[i] + 1]++;
    for (i = 0; i < ns; i++) vt->ptr[i + 1] += vt->ptr[i];
    for (i = 0; i < nt; i++)
        for (k = 0; k < 3; k++) { int v = o->tri[3 * i + k]; vt->idx[vt->ptr[v] + cnt[v]++] = i; }
    /* edges: each triangle gives both directions of its three edges */
    vv->ptr = sb_alloc(sizeof(int) * (size_t)(ns + 1));
    memset(cnt, 0, sizeof(int) * (size_t)(ns + 1));
    for (i = 0; i < nt; i++)
        for (k = 0; k < 3; k++) { vv->ptr[o->tri[3 * i + k] + 1] += 2; }
    for (i = 0; i < ns; i++) vv->ptr[i + 1] += vv->ptr[i];
    for (i = 0; i < nt; i++)
        for (k = 0; k < 3; k++) {
            int a = o->tri[3 * i + k], b = o->tri[3 * i + (k + 1) % 3], c = o->tri[3 * i + (k + 2) % 3];
            tmp[vv->ptr[a] + cnt[a]++] = b;
            tmp[vv->ptr[a] + cnt[a]++] = c;
        }
    /* sort and dedupe each row in place (insertion sort: rows are short) */
    vv->idx = sb_alloc(sizeof(int) * (size_t)(6 * nt + 1));
    {
        int w = 0, *np = sb_alloc(sizeof(int) * (size_t)(ns + 1));
        for (i = 0; i < ns; i++) {
            int a0 = vv->ptr[i], a1 = vv->ptr[i + 1], j, start = w;
            for (j = a0 + 1; j < a1; j++) {
                int x = tmp[j], m = j - 1;
                while (m >= a0 && tmp[m] > x) { tmp[m + 1] = tmp[m]; m--; }
                tmp[m + 1] = x;
            }
            for (j = a0; j < a1; j++) if (j == a0 || tmp[j] != tmp[j - 1]) vv->idx[w++] = tmp[j];
            np[i] = start;
        }
        np[ns] = w;
        free(vv->ptr);
        vv->ptr = np;
    }
    free(cnt); free(tmp);
}

/* vertices within r rings of s: s first, then each ring in increasing index;
 * ring[] receives each one's ring; stamp/mark are scratch (ns entries). */
static int rings(const csr_t *vv, int s, int r, int *out, int *ring, int max, int *mark, int stamp)
{
    int n = 0, lo = 0, k, q;
    out[n] = s; ring[n] = 0; n++; mark[s] = stamp;
    for (k = 1; k <= r; k++) {
        int hi = n, start = n;
        for (q = lo; q < hi; q++) {
            int v = out[q], e;
            for (e = vv->ptr[v]; e < vv->ptr[v + 1]; e++) {
                int w = vv->idx[e];
                if (mark[w] == stamp) continue;
                mark[w] = stamp;
                if (n < max) { out[n] = w; ring[n] = k; n++; }
            }
        }
        /* sort the new ring by index */
        for (q = start + 1; q < n; q++) {
            int x = out[q], m = q - 1;
            while (m >= start && out[m] > x) { out[m + 1] = out[m]; m--; }
            out[m + 1] = x;
        }
        lo = start;
    }
    return n;
}

static double rdist2(const double *x, int a, int b)
{
    double d0 = x[3 * a] - x[3 * b], d1 = x[3 * a + 1] - x[3 * b + 1], d2 = x[3 * a + 2] - x[3 * b + 2];
    return d0 * d0 + d1 * d1 + d2 * d2;
}

static int cmp_int(const void *a, const void *b) { int x = *(const int *)a, y = *(const int *)b; return (x > y) - (x < y); }

/* ---------------- pose ---------------- */

/* local rotations (x,y,z,w) per blob joint -> per-joint transforms (mesh
 * units), as sn_pose_from_local, the root moved by root (sb_static.h; here in
 * the tool library so sb_static.c, sb_fit.c and the crease slow motion share it) */
void sb_pose_from_local(const snref_model *m, const double *local, const double root[3], snref_xform *out) {
    unsigned j, k;
    for (j = 0; j < m->nJ; j++) {
        double R[9], x[3], rx[3], dd[3], q[4], n = 0;
        int p = m->jparent[j];
        for (k = 0; k < 4; k++) n += local[4 * j + k] * local[4 * j + k];
        n = sqrt(n);
        for (k = 0; k < 4; k++) q[k] = local[4 * j + k] / n;
        for (k = 0; k < 3; k++) x[k] = m->jrest[3 * j + k] * m->unit;
        snref_quat_to_mat(q, R);
        for (k = 0; k < 3; k++) { rx[k] = R[3 * k] * x[0] + R[3 * k + 1] * x[1] + R[3 * k + 2] * x[2]; dd[k] = x[k] - rx[k]; }
        if (p < 0) {
            memcpy(out[j].q, q, sizeof q);
            for (k = 0; k < 3; k++) out[j].t[k] = dd[k] + root[k];
        } else {
            double Rp[9];
            snref_quat_to_mat(out[p].q, Rp);
            snref_quat_mul(out[p].q, q, out[j].q);
            for (k = 0; k < 3; k++) out[j].t[k] = Rp[3 * k] * dd[0] + Rp[3 * k + 1] * dd[1] + Rp[3 * k + 2] * dd[2] + out[p].t[k];
        }
    }
}

/* "JOINT:AX,AY,AZ,DEG[+...]" -> per blob joint axis (unit) and degrees (0: not moved) */
static int parse_pose(const snref_model *m, const char *path, int line, const char *s, double *axis, double *deg)
{
    while (*s) {
        const char *colon = strchr(s, ':'), *end = strchr(s, '+'), *p;
        double v[4], n;
        unsigned j;
        int k;
        if (!end) end = s + strlen(s);
        if (!colon || colon > end) return sb_fail("%s:%d: crease: '%.*s': want JOINT:AX,AY,AZ,DEG", path, line, (int)(end - s), s);
        for (j = 0; j < m->nJ; j++) if (strlen(m->jname[j]) == (size_t)(colon - s) && !strncmp(m->jname[j], s, (size_t)(colon - s))) break;
        if (j == m->nJ) return sb_fail("%s:%d: crease: unknown joint '%.*s'", path, line, (int)(colon - s), s);
        for (k = 0, p = colon + 1; k < 4; k++) {
            char buf[64], *e;
            const char *q = p;
            while (q < end && *q != ',') q++;
            if ((k < 3 && q >= end) || (k == 3 && q != end) || q - p <= 0 || q - p >= 63)
                return sb_fail("%s:%d: crease: '%.*s': want JOINT:AX,AY,AZ,DEG with four numbers", path, line, (int)(end - s), s);
            memcpy(buf, p, (size_t)(q - p)); buf[q - p] = 0;
            v[k] = strtod(buf, &e);
            if (*e || !(fabs(v[k]) < 1e6)) return sb_fail("%s:%d: crease: '%s' is not a number", path, line, buf);
            p = q + 1;
        }
        n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (!(n > 0)) return sb_fail("%s:%d: crease: joint '%s': zero axis", path, line, m->jname[j]);
        for (k = 0; k < 3; k++) axis[3 * j + (unsigned)k] = v[k] / n;
        deg[j] = v[3];
        s = *end ? end + 1 : end;
    }
    return 0;
}

/* (p - a).n with n = (b - a) x (c - a) of triangle tv in positions x: < 0 behind (sb_crease_inside's dn) */
static double plane_side(const double *x, const int *tv, const double *p)
{
    const double *a = x + 3 * tv[0], *b = x + 3 * tv[1], *c = x + 3 * tv[2];
    double e1[3], e2[3], u[3];
    int k;
    for (k = 0; k < 3; k++) { e1[k] = b[k] - a[k]; e2[k] = c[k] - a[k]; u[k] = p[k] - a[k]; }
    return u[0] * (e1[1] * e2[2] - e1[2] * e2[1]) + u[1] * (e1[2] * e2[0] - e1[0] * e2[2]) + u[2] * (e1[0] * e2[1] - e1[1] * e2[0]);
}

/* ---------------- uniform grid of triangles ---------------- */

typedef struct {
    double lo[3], h;
    int n[3];
    int *start, *tris, cap;
} grid_t;

static int gclamp(int x, int n) { return x < 0 ? 0 : (x >= n ? n - 1 : x); }

static void grid_build(grid_t *g, const sb_model *o, const double *p, double pad, double h)
{
    double hi[3];
    int i, k, total = 0, *cnt;
    for (k = 0; k < 3; k++) { g->lo[k] = 1e300; hi[k] = -1e300; }
    for (i = 0; i < o->ns; i++)
        for (k = 0; k < 3; k++) { g->lo[k] = fmin(g->lo[k], p[3 * i + k]); hi[k] = fmax(hi[k], p[3 * i + k]); }
    for (k = 0; k < 3; k++) { g->lo[k] -= pad; hi[k] += pad; }
    for (;;) {
        for (k = 0; k < 3; k++) g->n[k] = (int)((hi[k] - g->lo[k]) / h) + 1;
        if ((double)g->n[0] * g->n[1] * g->n[2] <= 262144.0) break;
        h *= 1.5;
    }
    g->h = h;
    free(g->start); free(g->tris);
    g->start = sb_alloc(sizeof(int) * (size_t)(g->n[0] * g->n[1] * g->n[2] + 1));
    cnt = sb_alloc(sizeof(int) * (size_t)(g->n[0] * g->n[1] * g->n[2] + 1));
    int pass;
    for (pass = 0; pass < 2; pass++) {
        for (i = 0; i < o->nt; i++) {
            int a[3], b[3], x, y, z;
            for (k = 0; k < 3; k++) {
                double mn = 1e300, mx = -1e300;
                int c;
                for (c = 0; c < 3; c++) { double v = p[3 * o->tri[3 * i + c] + k]; mn = fmin(mn, v); mx = fmax(mx, v); }
                a[k] = gclamp((int)floor((mn - pad - g->lo[k]) / h), g->n[k]);
                b[k] = gclamp((int)floor((mx + pad - g->lo[k]) / h), g->n[k]);
            }
            for (z = a[2]; z <= b[2]; z++)
                for (y = a[1]; y <= b[1]; y++)
                    for (x = a[0]; x <= b[0]; x++) {
                        int cell = x + g->n[0] * (y + g->n[1] * z);
                        if (pass == 0) g->start[cell + 1]++;
                        else g->tris[g->start[cell] + cnt[cell]++] = i;
                    }
        }
        if (pass == 0) {
            int nc = g->n[0] * g->n[1] * g->n[2];
            for (i = 0; i < nc; i++) g->start[i + 1] += g->start[i];
            total = g->start[nc];
            g->tris = sb_alloc(sizeof(int) * (size_t)(total + 1));
        }
    }
    free(cnt);
}

static int grid_cell(const grid_t *g, const double p[3])
{
    int c[3], k;
    for (k = 0; k < 3; k++) c[k] = gclamp((int)floor((p[k] - g->lo[k]) / g->h), g->n[k]);
    return c[0] + g->n[0] * (c[1] + g->n[1] * c[2]);
}

/* ---------------- sparse rows (format 6.0) ---------------- */

/* Keep the neighbourhood rows (dense, one per surface vertex, as built) only
 * for the vertices the runtime can query: those the slow motion found in a
 * collision (the penetrating vertex and its triangle's corners: hit) and the
 * 'reach' rings around them (the runtime walks a contact's neighbourhood
 * each step, a ring at a time; beyond the rows it stops: a vertex without a
 * row is never searched). Seed vertices are collision vertices. The widths
 * shrink to the widest kept row. buf, rg, mark: ns scratch entries each. */
static void compact_rows(sb_model *o, const csr_t *vv, const unsigned char *hit, int reach, int *buf, int *rg, int *mark)
{
    int ns = o->ns, s, q, nq = 0, kv = 1, kt = 1, n, *vn, *tn;
    unsigned char *keep = sb_alloc((size_t)ns);
    for (s = 0; s < ns; s++) mark[s] = -1;
    for (s = 0; s < ns; s++) {
        if (!hit[s]) continue;
        n = rings(vv, s, reach, buf, rg, ns, mark, s);
        for (q = 0; q < n; q++) keep[buf[q]] = 1;
    }
    for (q = 0; q < o->cr_nD; q++) keep[o->cr_pairs[2 * q]] = keep[o->cr_pairs[2 * q + 1]] = 1;
    for (s = 0; s < ns; s++) {
        if (!keep[s]) continue;
        nq++;
        for (q = 0; q < o->cr_kv; q++) if (o->cr_vnbr[(size_t)s * (size_t)o->cr_kv + (size_t)q] >= 0 && q + 1 > kv) kv = q + 1;
        for (q = 0; q < o->cr_kt; q++) if (o->cr_tnbr[(size_t)s * (size_t)o->cr_kt + (size_t)q] >= 0 && q + 1 > kt) kt = q + 1;
    }
    if (nq == 0) { keep[0] = 1; nq = 1; } /* a row is required (BLOB.md); no collision: vertex 0's, never reached */
    vn = sb_alloc(sizeof(int) * (size_t)nq * (size_t)kv);
    tn = sb_alloc(sizeof(int) * (size_t)nq * (size_t)kt);
    for (s = 0, n = 0; s < ns; s++) {
        if (!keep[s]) continue;
        for (q = 0; q < kv; q++) vn[(size_t)n * (size_t)kv + (size_t)q] = o->cr_vnbr[(size_t)s * (size_t)o->cr_kv + (size_t)q];
        for (q = 0; q < kt; q++) tn[(size_t)n * (size_t)kt + (size_t)q] = o->cr_tnbr[(size_t)s * (size_t)o->cr_kt + (size_t)q];
        n++;
    }
    free(o->cr_vnbr); free(o->cr_tnbr); free(keep);
    o->cr_vnbr = vn; o->cr_tnbr = tn; o->cr_nq = nq; o->cr_kv = kv; o->cr_kt = kt;
}

/* ---------------- the build ---------------- */

int sb_crease_build(const sb_desc *d, sb_model *o, int quiet)
{
    csr_t vv, vt;
    int ns = o->ns, nt = o->nt, s, rc = -1, *buf, *rg, *mark, *tb, kv = 1, kt = 1, trunc_v = 0, trunc_t = 0;
    int *excl_ptr = NULL, *excl = NULL, tring;
    unsigned char *hit = NULL;
    sb_blob b;
    snref_model m;
    snref_state st;
    double t0 = sb_now();
    char err[300];
    if (d->ncrease == 0) return 0;
    if (ns > 65534 || nt > 65534) return sb_fail("%s: crease: %d surface vertices, %d triangles: at most 65534 each", d->path, ns, nt);
    o->cr_list = d->cr_list; o->cr_active = d->cr_active;
    o->cr_depth = d->cr_depth > 0 ? d->cr_depth : 0.5 * o->c;
    o->cr_push = d->cr_push >= 0 ? d->cr_push : 0.25 * o->cr_depth;
    o->cr_exclude = d->cr_exclude >= 0 ? d->cr_exclude : o->c;
    if (o->cr_push > o->cr_depth) return sb_fail("%s: crease push %g exceeds depth %g", d->path, o->cr_push, o->cr_depth);
    tring = d->cr_tring >= 0 && d->cr_tring < d->cr_ring ? d->cr_tring : d->cr_ring;
    build_adj(o, &vv, &vt);
    buf = sb_alloc(sizeof(int) * (size_t)(ns + 1));
    rg = sb_alloc(sizeof(int) * (size_t)(ns + 1));
    mark = sb_alloc(sizeof(int) * (size_t)(ns + 1));
    tb = sb_alloc(sizeof(int) * (size_t)(3 * nt + 1));
    hit = sb_alloc((size_t)ns);
    for (s = 0; s < ns; s++) mark[s] = -1;
    /* ---- neighbourhoods ---- */
    {
        int pass;
        for (pass = 0; pass < 2; pass++) {
            for (s = 0; s < ns; s++) {
                int n = rings(&vv, s, d->cr_ring, buf, rg, ns, mark, s), nv = n, q, ntb = 0, e;
                if (nv > (int)SN_CREASE_MAX_NBR_V) { nv = (int)SN_CREASE_MAX_NBR_V; trunc_v += pass == 0; }
                /* triangles by ring: a triangle counts from the first ring that touches it; only the rings up to 'tring' */
                for (q = 0; q < nv && rg[q] <= tring; q++) {
                    int v = buf[q];
                    for (e = vt.ptr[v]; e < vt.ptr[v + 1]; e++) {
                        int t = vt.idx[e], z;
                        for (z = 0; z < ntb && tb[z] != t; z++) {}
                        if (z == ntb) tb[ntb++] = t;
                    }
                }
                if (ntb > (int)SN_CREASE_MAX_NBR_T) { ntb = (int)SN_CREASE_MAX_NBR_T; trunc_t += pass == 0; }
                qsort(tb, (size_t)ntb, sizeof(int), cmp_int);
                if (pass == 0) { kv = nv > kv ? nv : kv; kt = ntb > kt ? ntb : kt; continue; }
                for (q = 0; q < kv; q++) o->cr_vnbr[(size_t)s * (size_t)kv + (size_t)q] = q < nv ? buf[q] : -1;
                for (q = 0; q < kt; q++) o->cr_tnbr[(size_t)s * (size_t)kt + (size_t)q] = q < ntb ? tb[q] : -1;
            }
            if (pass == 0) {
                o->cr_kv = kv; o->cr_kt = kt;
                o->cr_vnbr = sb_alloc(sizeof(int) * (size_t)ns * (size_t)kv);
                o->cr_tnbr = sb_alloc(sizeof(int) * (size_t)ns * (size_t)kt);
                for (s = 0; s < ns; s++) mark[s] = -1;
            }
        }
        if ((trunc_v || trunc_t) && !quiet)
            fprintf(stderr, "sinew-bake: warning: crease: %d vertex and %d triangle neighbourhoods truncated to %u / %u entries (lower the ring)\n",
                    trunc_v, trunc_t, SN_CREASE_MAX_NBR_V, SN_CREASE_MAX_NBR_T);
    }
    /* each vertex's neighbourhood, sorted: triangles touching it are never collisions (as the runtime) */
    excl_ptr = sb_alloc(sizeof(int) * (size_t)(ns + 1));
    excl = sb_alloc(sizeof(int) * ((size_t)ns * (size_t)kv + 1));
    {
        int total = 0;
        for (s = 0; s < ns; s++) {
            int q, n0 = total;
            excl_ptr[s] = total;
            for (q = 0; q < kv; q++) if (o->cr_vnbr[(size_t)s * (size_t)kv + (size_t)q] >= 0) excl[total++] = o->cr_vnbr[(size_t)s * (size_t)kv + (size_t)q];
            qsort(excl + n0, (size_t)(total - n0), sizeof(int), cmp_int);
        }
        excl_ptr[ns] = total;
    }
    /* ---- slow motion with the double model ---- */
    memset(&b, 0, sizeof b); memset(&m, 0, sizeof m); memset(&st, 0, sizeof st);
    o->crease = 0; /* the float64 blob for the reference carries no crease sections */
    if (sb_blob_make(o, SB_DOUBLE, &b)) goto done;
    if (snref_load(&m, b.bytes, b.size, err, sizeof err)) { sb_fail("crease: reading the float64 blob: %s", err); goto done; }
    if (snref_init(&st, &m)) { sb_fail("crease: out of memory"); goto done; }
    {
        double *axis = sb_alloc(sizeof(double) * 3 * m.nJ), *deg = sb_alloc(sizeof(double) * m.nJ);
        double *local = sb_alloc(sizeof(double) * 4 * m.nJ), *cur = sb_alloc(sizeof(double) * 3 * (size_t)ns);
        double *prev = sb_alloc(sizeof(double) * 3 * (size_t)ns), *rest = sb_alloc(sizeof(double) * 3 * (size_t)ns);
        double zero3[3] = {0, 0, 0}, ex2 = o->cr_exclude * o->cr_exclude, th2 = d->cr_thin * d->cr_thin;
        int have_rest = 0;
        snref_xform *pose = sb_alloc(sizeof(snref_xform) * m.nJ);
        unsigned char *done_v = sb_alloc((size_t)ns);
        double *tn = sb_alloc(sizeof(double) * 5 * (size_t)nt);
        int *vcell = sb_alloc(sizeof(int) * (size_t)ns), *vbest = sb_alloc(sizeof(int) * (size_t)ns), *vbestc = sb_alloc(sizeof(int) * (size_t)ns);
        int cap = 64, ci, fail = 0, nhit = 0;
        double last_note = sb_now();
        grid_t g;
        double cellh = 0;
        memset(&g, 0, sizeof g);
        o->cr_pairs = sb_alloc(sizeof(int) * 2 * (size_t)cap);
        o->cr_nD = 0;
        cellh = 0; /* the grid's cell: set from the rest surface (step 0 of the first pose) */
        for (ci = 0; ci < d->ncrease && !fail; ci++) {
            const sb_creasedef *cd = &d->creases[ci];
            int N = cd->steps, hold = cd->steps / 4, step, found = 0;
            unsigned j;
            for (j = 0; j < m.nJ; j++) { deg[j] = 0; axis[3 * j] = 1; axis[3 * j + 1] = axis[3 * j + 2] = 0; }
            if (parse_pose(&m, d->path, cd->line, cd->pose, axis, deg)) { fail = 1; break; }
            snref_reset(&st);
            memset(done_v, 0, (size_t)ns);
            if (!quiet) { printf("crease: pose %d/%d %s: %d steps + %d held...", ci + 1, d->ncrease, cd->pose, N, hold); fflush(stdout); }
            for (step = 0; step <= N + hold; step++) {
                double f = step >= N ? 1.0 : (double)step / N;
                int i;
                for (j = 0; j < m.nJ; j++) snref_quat_axis_angle(axis + 3 * j, deg[j] * f, local + 4 * j);
                sb_pose_from_local(&m, local, zero3, pose);
                snref_set_pose(&st, pose);
                if (step > 0) snref_step(&st);
                memcpy(prev, cur, sizeof(double) * 3 * (size_t)ns);
                snref_get_surface(&st, cur);
                if (step == 0 && !have_rest) { memcpy(rest, cur, sizeof(double) * 3 * (size_t)ns); have_rest = 1; }
                if (step == 0 && cellh == 0) {   /* twice the mean rest edge, at least the depth (the cells hold the triangles padded by the depth) */
                    double sum = 0;
                    int t, c, k;
                    for (t = 0; t < nt; t++)
                        for (c = 0; c < 3; c++) {
                            const double *p0 = cur + 3 * o->tri[3 * t + c], *p1 = cur + 3 * o->tri[3 * t + (c + 1) % 3];
                            double d2 = 0;
                            for (k = 0; k < 3; k++) d2 += (p1[k] - p0[k]) * (p1[k] - p0[k]);
                            sum += sqrt(d2);
                        }
                    cellh = fmax(2 * sum / (3.0 * nt), o->cr_depth);
                }
                if (step == 0) continue;
                if (!quiet && sb_now() - last_note >= 5.0) { /* progress on long bakes */
                    last_note = sb_now();
                    printf("\ncrease: pose %d/%d step %d/%d: %d seed pairs, %d collisions so far (%.0f s)", ci + 1, d->ncrease, step,
                           N + hold, o->cr_nD, nhit, last_note - t0);
                    fflush(stdout);
                }
                grid_build(&g, o, cur, o->cr_depth, cellh);
                for (i = 0; i < nt; i++) { /* each triangle's plane n.x = n.a this step (the filter above) */
                    const int *tv = o->tri + 3 * i;
                    const double *a = cur + 3 * tv[0], *b2 = cur + 3 * tv[1], *c2 = cur + 3 * tv[2];
                    double e1[3], e2[3], *pn = tn + 5 * i;
                    int k;
                    for (k = 0; k < 3; k++) { e1[k] = b2[k] - a[k]; e2[k] = c2[k] - a[k]; }
                    pn[0] = e1[1] * e2[2] - e1[2] * e2[1]; pn[1] = e1[2] * e2[0] - e1[0] * e2[2]; pn[2] = e1[0] * e2[1] - e1[1] * e2[0];
                    pn[3] = pn[0] * a[0] + pn[1] * a[1] + pn[2] * a[2];
                    pn[4] = sqrt(pn[0] * pn[0] + pn[1] * pn[1] + pn[2] * pn[2]);
                }
                {   /* each vertex's deepest new collision, the vertices taken cell by cell (the cell's planes stay in cache) */
                    int nc = g.n[0] * g.n[1] * g.n[2], oi;
                    int *cs = sb_alloc(sizeof(int) * (size_t)(nc + 1)), *ord = sb_alloc(sizeof(int) * (size_t)ns + 1);
                    for (i = 0; i < ns; i++) { vcell[i] = grid_cell(&g, cur + 3 * i); cs[vcell[i] + 1]++; vbest[i] = -1; }
                    for (oi = 0; oi < nc; oi++) cs[oi + 1] += cs[oi];
                    for (i = 0; i < ns; i++) ord[cs[vcell[i]]++] = i; /* cs[c] now the end of cell c */
                    for (oi = 0; oi < ns; oi++) {
                    int cell, e, best = -1, bestc = 0;
                    double bestd = 0;
                    i = ord[oi];
                    if (done_v[i]) continue;
                    cell = vcell[i];
                    for (e = g.start[cell]; e < g.start[cell + 1]; e++) {
                        int t = g.tris[e], c, a, lo_, hi_, skip = 0, corner;
                        double dist;
                        const int *tv = o->tri + 3 * t;
                        /* cheapest rejections first (the result is the same in any order): behind the plane now and
                         * in front of it at the last step (crossed), then inside, then the exclusions */
                        {   /* the step's plane n.x = n.a, |n| (tn): a conservative filter, margin 1e-9 of the terms' size */
                            const double *pn = tn + 5 * t, *pi = cur + 3 * i;
                            double dot = pn[0] * pi[0] + pn[1] * pi[1] + pn[2] * pi[2], tol = 1e-9 * (fabs(dot) + fabs(pn[3]));
                            if (dot - pn[3] > tol || dot - pn[3] < -o->cr_depth * pn[4] * (1 + 1e-9) - tol) continue; /* in front, or deeper than depth */
                        }
                        if (!(plane_side(cur, tv, cur + 3 * i) < 0) || plane_side(prev, tv, prev + 3 * i) < 0) continue;
                        if (!sb_crease_inside(cur + 3 * i, cur + 3 * tv[0], cur + 3 * tv[1], cur + 3 * tv[2], o->cr_depth, &dist, &corner)) continue;
                        for (c = 0; c < 3 && !skip; c++) { /* corner in i's neighbourhood? (sorted list: binary search) */
                            lo_ = excl_ptr[i]; hi_ = excl_ptr[i + 1] - 1;
                            while (lo_ <= hi_) { a = (lo_ + hi_) / 2; if (excl[a] == tv[c]) { skip = 1; break; } if (excl[a] < tv[c]) lo_ = a + 1; else hi_ = a - 1; }
                        }
                        for (c = 0; c < 3 && !skip; c++) skip = rdist2(rest, i, tv[c]) < ex2; /* a corner closer than 'exclude' in the rest pose? */
                        if (skip) continue;
                        if (best < 0 || dist > bestd) { best = t; bestd = dist; bestc = corner; }
                    }
                    vbest[i] = best; vbestc[i] = bestc;
                    }
                    free(cs); free(ord);
                }
                for (i = 0; i < ns; i++) {   /* in index order: the seeds' order does not depend on the grid */
                    int best = vbest[i], bestc = vbestc[i];
                    if (best >= 0) {
                        int jv = o->tri[3 * best + bestc], q, c;
                        done_v[i] = 1;
                        hit[i] = 1; /* the runtime will query i and the triangle's corners: they get rows */
                        for (c = 0; c < 3; c++) hit[o->tri[3 * best + c]] = 1;
                        nhit++;
                        for (q = 0; q < o->cr_nD; q++) {
                            int i0 = o->cr_pairs[2 * q], j0 = o->cr_pairs[2 * q + 1];
                            if (i0 == i && j0 == jv) break;
                            if (th2 > 0 && rdist2(rest, i0, i) < th2 && rdist2(rest, j0, jv) < th2) break; /* 'thin': a seed this close already */
                        }
                        if (q < o->cr_nD) continue;
                        if (o->cr_nD >= (int)SN_CREASE_MAX_PAIRS) { if (!quiet) fprintf(stderr, "sinew-bake: warning: crease: more than %u seed pairs: the rest dropped\n", SN_CREASE_MAX_PAIRS); fail = 2; break; }
                        if (o->cr_nD == cap) { cap *= 2; o->cr_pairs = realloc(o->cr_pairs, sizeof(int) * 2 * (size_t)cap); if (!o->cr_pairs) { fprintf(stderr, "out of memory\n"); exit(1); } }
                        o->cr_pairs[2 * o->cr_nD] = i; o->cr_pairs[2 * o->cr_nD + 1] = jv;
                        o->cr_nD++; found++;
                    }
                }
                if (fail) break;
            }
            if (fail == 2) fail = 0;
            if (!quiet && !fail) printf(" %d seed pairs (%.2f s)\n", found, sb_now() - t0);
        }
        free(g.start); free(g.tris);
        if (!fail) compact_rows(o, &vv, hit, d->cr_reach, buf, rg, mark);
        free(axis); free(deg); free(local); free(cur); free(prev); free(rest); free(pose); free(done_v); free(tn); free(vcell); free(vbest); free(vbestc);
        if (fail) goto done;
    }
    o->crease = 1;
    if (!quiet) {
        uint32_t rs = 4, bytes = SN_ELEM_CREASE(rs) + SN_ELEM_CREASE_PAIRS * (uint32_t)o->cr_nD + 2u * (uint32_t)o->cr_nq * (uint32_t)(o->cr_kv + o->cr_kt);
        printf("  crease    %d seed pairs from %d pose(s); %d neighbourhood rows (reach %d), ring %d: %d vertices, %d triangles per row; list %d, active %d, "
               "depth %g, push %g, exclude %g mesh units; %u blob bytes (4-byte reals), %u instance bytes of crease state (its rows: see contact) (%.2f s)\n",
               o->cr_nD, d->ncrease, o->cr_nq, d->cr_reach, d->cr_ring, o->cr_kv, o->cr_kt, o->cr_list, o->cr_active, o->cr_depth, o->cr_push, o->cr_exclude, (unsigned)bytes,
               (unsigned)SN_CREASE_STATE_BYTES(ns, o->cr_list), sb_now() - t0);
    }
    rc = 0;
done:
    if (rc) sb_crease_free(o);
    snref_release(&st);
    snref_free(&m);
    sb_blob_free(&b);
    free(vv.ptr); free(vv.idx); free(vt.ptr); free(vt.idx);
    free(buf); free(rg); free(mark); free(tb); free(excl_ptr); free(excl); free(hit);
    return rc;
}
