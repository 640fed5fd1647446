/* sb_gltf_anim.c -- glTF 2.0 animations of a skin, sampled for Sinew clips
 * (issue 17 item 3; sinew-play --gltf-anim). Channels on rotation and
 * translation with LINEAR (slerp for rotations), STEP and CUBICSPLINE
 * samplers; scale channels ignored and counted. Every error names the JSON
 * path. The sampled poses become clip text (ports/common/CLIP.md) so the
 * player plays them through the existing fixed-point clip path. */
#include "sb_gltf.h"
#include "sb_gltf_int.h"
#include "sb.h"
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { CH_T = 0, CH_R = 1 };
typedef struct {
    int node, path, interp;   /* path CH_T / CH_R; interp 0 LINEAR, 1 STEP, 2 CUBICSPLINE */
    int n;                    /* keys */
    double *t, *v;            /* n times; n x (3|4) values, x3 for CUBICSPLINE (in-tangent, value, out-tangent) */
} chan;

static void qnorm(double *q)
{
    double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    int k;
    if (!(l > 0)) { q[0] = q[1] = q[2] = 0, q[3] = 1; return; }
    for (k = 0; k < 4; k++) q[k] /= l;
}

static void slerp(const double *a, const double *b0, double u, double *o)
{
    double b[4], d = a[0] * b0[0] + a[1] * b0[1] + a[2] * b0[2] + a[3] * b0[3], wa, wb;
    int k;
    for (k = 0; k < 4; k++) b[k] = d < 0 ? -b0[k] : b0[k];
    d = fabs(d);
    if (d > 0.9999995) wa = 1 - u, wb = u;
    else {
        double th = acos(d), s = sin(th);
        wa = sin((1 - u) * th) / s, wb = sin(u * th) / s;
    }
    for (k = 0; k < 4; k++) o[k] = wa * a[k] + wb * b[k];
    qnorm(o);
}

/* channel value at time t */
static void chan_eval(const chan *c, double t, double *o)
{
    int nc = c->path == CH_R ? 4 : 3, stride = c->interp == 2 ? 3 * nc : nc, off = c->interp == 2 ? nc : 0, i, k;
    int lo = 0, hi = c->n - 1;
    if (t <= c->t[0] || c->n == 1) { memcpy(o, c->v + off, (size_t)nc * sizeof *o); goto done; }
    if (t >= c->t[c->n - 1]) { memcpy(o, c->v + (size_t)(c->n - 1) * stride + off, (size_t)nc * sizeof *o); goto done; }
    while (hi - lo > 1) {   /* t[lo] <= t < t[hi] */
        int m = (lo + hi) / 2;
        if (c->t[m] <= t) lo = m; else hi = m;
    }
    i = lo;
    {
        double dt = c->t[i + 1] - c->t[i], u = (t - c->t[i]) / dt;
        const double *a = c->v + (size_t)i * stride + off, *b = c->v + (size_t)(i + 1) * stride + off;
        if (c->interp == 1) memcpy(o, a, (size_t)nc * sizeof *o);
        else if (c->interp == 0) {
            if (c->path == CH_R) slerp(a, b, u, o);
            else for (k = 0; k < nc; k++) o[k] = a[k] + (b[k] - a[k]) * u;
        } else {   /* Hermite: value a, out-tangent of i, value b, in-tangent of i+1 (glTF 2.0 Appendix C) */
            const double *ob = c->v + (size_t)i * stride + 2 * nc, *ia = c->v + (size_t)(i + 1) * stride;
            double u2 = u * u, u3 = u2 * u;
            for (k = 0; k < nc; k++)
                o[k] = (2 * u3 - 3 * u2 + 1) * a[k] + (u3 - 2 * u2 + u) * dt * ob[k] + (-2 * u3 + 3 * u2) * b[k] + (u3 - u2) * dt * ia[k];
        }
    }
done:
    if (c->path == CH_R) qnorm(o);
}

/* rotation part of an affine matrix (column-major) as a unit quaternion, w >= 0 */
static void mat_quat(const double *m, double *q)
{
    double c0[3], c1[3], c2[3], n0, n1, n2, tr;
    int k;
    for (k = 0; k < 3; k++) c0[k] = m[k], c1[k] = m[4 + k], c2[k] = m[8 + k];
    n0 = sqrt(c0[0] * c0[0] + c0[1] * c0[1] + c0[2] * c0[2]);
    n1 = sqrt(c1[0] * c1[0] + c1[1] * c1[1] + c1[2] * c1[2]);
    n2 = sqrt(c2[0] * c2[0] + c2[1] * c2[1] + c2[2] * c2[2]);
    for (k = 0; k < 3; k++) c0[k] /= n0, c1[k] /= n1, c2[k] /= n2;
    /* R[r][c] = c_c[r] */
    tr = c0[0] + c1[1] + c2[2];
    if (tr > 0) {
        double s = sqrt(tr + 1) * 2;
        q[3] = 0.25 * s, q[0] = (c1[2] - c2[1]) / s, q[1] = (c2[0] - c0[2]) / s, q[2] = (c0[1] - c1[0]) / s;
    } else if (c0[0] > c1[1] && c0[0] > c2[2]) {
        double s = sqrt(1 + c0[0] - c1[1] - c2[2]) * 2;
        q[3] = (c1[2] - c2[1]) / s, q[0] = 0.25 * s, q[1] = (c1[0] + c0[1]) / s, q[2] = (c2[0] + c0[2]) / s;
    } else if (c1[1] > c2[2]) {
        double s = sqrt(1 + c1[1] - c0[0] - c2[2]) * 2;
        q[3] = (c2[0] - c0[2]) / s, q[0] = (c1[0] + c0[1]) / s, q[1] = 0.25 * s, q[2] = (c2[1] + c1[2]) / s;
    } else {
        double s = sqrt(1 + c2[2] - c0[0] - c1[1]) * 2;
        q[3] = (c0[1] - c1[0]) / s, q[0] = (c2[0] + c0[2]) / s, q[1] = (c2[1] + c1[2]) / s, q[2] = 0.25 * s;
    }
    qnorm(q);
    if (q[3] < 0) for (k = 0; k < 4; k++) q[k] = -q[k];
}

static void qmul(const double *a, const double *b, double *o)
{
    double t[4];
    t[0] = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    t[1] = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    t[2] = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    t[3] = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
    memcpy(o, t, sizeof t);
}

static void mat_point(const double *m, const double *p, double *o)
{
    int r;
    for (r = 0; r < 3; r++) o[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
}

void sb_gltf_anim_free(sb_gltf_anim *a)
{
    free(a->rot), free(a->move), free(a->animated), free(a->skin);
    memset(a, 0, sizeof *a);
}

static void free_chans(chan *c, int n)
{
    int k;
    for (k = 0; k < n; k++) free(c[k].t), free(c[k].v);
    free(c);
}

/* read animations[ai]'s channels */
static int read_chans(gl_scene *s, int ai, chan **out, int *nout, sb_gltf_anim *a)
{
    char path[96];
    int an = gl_elem(&s->d, GA_ANIMS, ai), ca = sbj_get(&s->d.j, an, "channels"), sa = sbj_get(&s->d.j, an, "samplers");
    int c, k = 0, nsamp, n = 0;
    chan *ch;
    if (ca < 0 || s->d.j.node[ca].kind != SBJ_ARR || s->d.j.node[ca].count < 1)
        return sb_fail("animations[%d].channels: a non-empty array expected", ai);
    if (sa < 0 || s->d.j.node[sa].kind != SBJ_ARR || s->d.j.node[sa].count < 1)
        return sb_fail("animations[%d].samplers: a non-empty array expected", ai);
    nsamp = s->d.j.node[sa].count;
    ch = sb_alloc((size_t)s->d.j.node[ca].count * sizeof *ch);
    for (c = s->d.j.node[ca].child; c >= 0; c = s->d.j.node[c].next, k++) {
        long long smp, node, ia, oa;
        int tg, so, nc, cpk, i;
        const char *p, *ip;
        gl_acc in, ou;
        chan *C = &ch[n];
        snprintf(path, sizeof path, "animations[%d].channels[%d]", ai, k);
        if (s->d.j.node[c].kind != SBJ_OBJ) { free_chans(ch, n); return sb_fail("%s: an object expected", path); }
        if (gl_int(&s->d, c, "sampler", path, GL_REQUIRED, 0, nsamp - 1, &smp)) { free_chans(ch, n); return -1; }
        tg = sbj_get(&s->d.j, c, "target");
        if (tg < 0 || s->d.j.node[tg].kind != SBJ_OBJ) { free_chans(ch, n); return sb_fail("%s.target: an object expected", path); }
        snprintf(path + strlen(path), sizeof path - strlen(path), ".target");
        p = sbj_str(&s->d.j, sbj_get(&s->d.j, tg, "path"));
        if (!p) { free_chans(ch, n); return sb_fail("%s.path: a string expected", path); }
        if (gl_int(&s->d, tg, "node", path, -1, 0, s->nn - 1, &node)) { free_chans(ch, n); return -1; }
        a->n_channels++;
        if (node < 0) { a->n_other++; continue; }   /* an extension's target */
        if (!strcmp(p, "scale")) {   /* ignored; counted as scaling when a value leaves 1 (exporters key constant 1s) */
            long long so_ = -1, oa_ = -1;
            gl_acc sc_;
            int sc_o = sbj_at(&s->d.j, sa, (int)smp);
            a->n_scale++;
            if (sc_o >= 0 && s->d.j.node[sc_o].kind == SBJ_OBJ && !gl_int(&s->d, sc_o, "output", path, -1, 0, s->d.count[GA_ACCESSORS] - 1, &oa_) &&
                oa_ >= 0 && !gl_accessor(&s->d, (int)oa_, &sc_)) {
                for (so_ = 0; so_ < sc_.count * sc_.ncomp; so_++)
                    if (!(fabs(sc_.v[so_] - 1) <= 1e-5)) { a->n_scale_active++; break; }
                free(sc_.v);
            } else a->n_scale_active++;
            continue;
        }
        if (strcmp(p, "rotation") && strcmp(p, "translation")) { a->n_other++; continue; }   /* weights */
        if (s->is_matrix[node]) { free_chans(ch, n); return sb_fail("%s.node: nodes[%lld] has a matrix: it cannot be animated", path, node); }
        C->node = (int)node;
        C->path = !strcmp(p, "rotation") ? CH_R : CH_T;
        snprintf(path, sizeof path, "animations[%d].samplers[%lld]", ai, smp);
        so = sbj_at(&s->d.j, sa, (int)smp);
        if (s->d.j.node[so].kind != SBJ_OBJ) { free_chans(ch, n); return sb_fail("%s: an object expected", path); }
        ip = sbj_get(&s->d.j, so, "interpolation") >= 0 ? sbj_str(&s->d.j, sbj_get(&s->d.j, so, "interpolation")) : "LINEAR";
        if (!ip) { free_chans(ch, n); return sb_fail("%s.interpolation: a string expected", path); }
        if (!strcmp(ip, "LINEAR")) C->interp = 0;
        else if (!strcmp(ip, "STEP")) C->interp = 1;
        else if (!strcmp(ip, "CUBICSPLINE")) C->interp = 2;
        else { free_chans(ch, n); return sb_fail("%s.interpolation: \"%s\" (LINEAR, STEP or CUBICSPLINE)", path, ip); }
        if (gl_int(&s->d, so, "input", path, GL_REQUIRED, 0, s->d.count[GA_ACCESSORS] - 1, &ia) ||
            gl_int(&s->d, so, "output", path, GL_REQUIRED, 0, s->d.count[GA_ACCESSORS] - 1, &oa)) { free_chans(ch, n); return -1; }
        if (gl_accessor(&s->d, (int)ia, &in)) { free_chans(ch, n); return -1; }
        if (in.ncomp != 1 || in.ctype != 5126 || in.count < 1) {
            free(in.v), free_chans(ch, n);
            return sb_fail("%s.input: accessors[%lld] must be SCALAR float with at least one element", path, ia);
        }
        for (i = 0; i < in.count; i++)
            if (!isfinite(in.v[i]) || in.v[i] < 0 || (i > 0 && !(in.v[i] > in.v[i - 1]))) {
                double ti = in.v[i];   /* read before the free (the fuzzer's use after free) */
                free(in.v), free_chans(ch, n);
                return sb_fail("%s.input: accessors[%lld] time %d (%g) is negative, not finite or not after the one before", path, ia, i, ti);
            }
        if (in.v[in.count - 1] > 3600) {
            double last = in.v[in.count - 1];
            free(in.v), free_chans(ch, n);
            return sb_fail("%s.input: accessors[%lld] ends at %g s (at most 3600 s)", path, ia, last);
        }
        if (gl_accessor(&s->d, (int)oa, &ou)) { free(in.v), free_chans(ch, n); return -1; }
        nc = C->path == CH_R ? 4 : 3;
        cpk = C->interp == 2 ? 3 : 1;
        if (ou.ncomp != nc || ou.count != in.count * cpk || (C->path == CH_T && ou.ctype != 5126)) {
            free(in.v), free(ou.v), free_chans(ch, n);
            return sb_fail("%s.output: accessors[%lld] must be %s with %lld elements", path, oa, nc == 4 ? "VEC4" : "VEC3 float", in.count * cpk);
        }
        for (i = 0; i < ou.count * nc; i++)
            if (!isfinite(ou.v[i]) || fabs(ou.v[i]) > 1e9) {
                free(in.v), free(ou.v), free_chans(ch, n);
                return sb_fail("%s.output: accessors[%lld] value %d is not finite or beyond 1e9", path, oa, i);
            }
        C->n = (int)in.count, C->t = in.v, C->v = ou.v;
        if (in.v[in.count - 1] > a->end) a->end = in.v[in.count - 1];
        n++;
    }
    *out = ch, *nout = n;
    return 0;
}

int sb_gltf_anim_load(sb_gltf_anim *a, const char *path, const sb_gltf *g, const char *name, double h, int max_frames)
{
    gl_scene s;
    chan *ch = NULL;
    int nch = 0, ai = -1, rc = -1, f, k, i, *jn = NULL, *ord = NULL;
    double *trs = NULL, *loc = NULL, *wld = NULL, *inv_bind = NULL;
    char *sel = NULL;
    memset(a, 0, sizeof *a);
    if (!(h > 0) || h > 1) return sb_fail("%s: timestep %g s (want 0 < h <= 1)", path, h);
    if (gl_scene_open(&s, path)) goto out;
    if (s.d.count[GA_ANIMS] < 1) { sb_fail("animations: the file has none"); goto out; }
    if (!name || !name[0]) ai = 0;
    else {
        for (k = 0; k < s.d.count[GA_ANIMS] && ai < 0; k++) {
            const char *nm = sbj_str(&s.d.j, sbj_get(&s.d.j, gl_elem(&s.d, GA_ANIMS, k), "name"));
            if (nm && !strcmp(nm, name)) ai = k;
        }
        if (ai < 0) {
            char *end;
            long v = strtol(name, &end, 10);
            if (*end || end == name || v < 0 || v >= s.d.count[GA_ANIMS]) {
                sb_fail("animations: none named \"%s\" (%d animation(s))", name, s.d.count[GA_ANIMS]);
                goto out;
            }
            ai = (int)v;
        }
    }
    a->index = ai;
    snprintf(a->name, sizeof a->name, "%s", sbj_str(&s.d.j, sbj_get(&s.d.j, gl_elem(&s.d, GA_ANIMS, ai), "name")) ?
                                                sbj_str(&s.d.j, sbj_get(&s.d.j, gl_elem(&s.d, GA_ANIMS, ai), "name")) : "");
    if (read_chans(&s, ai, &ch, &nch, a)) goto out;
    if (g->nj < 1) { sb_fail("no skin joints"); goto out; }
    for (k = 0; k < g->nj; k++)
        if (g->joints[k].node < 0 || g->joints[k].node >= s.nn) { sb_fail("the skin does not belong to this file"); goto out; }
    a->nj = g->nj, a->h = h;
    {   /* frames as a double first: a tiny h must not overflow the int */
        double nf = ceil(a->end / h - 1e-9) + 1;
        if (!(nf <= max_frames)) { sb_fail("animations[%d]: %g s at %g s per step is %.0f frames, at most %d", ai, a->end, h, nf, max_frames); goto out; }
        a->nframes = nf < 1 ? 1 : (int)nf;
    }
    a->rot = sb_alloc((size_t)a->nframes * (size_t)g->nj * 4 * sizeof *a->rot);
    a->move = sb_alloc((size_t)a->nframes * 3 * sizeof *a->move);
    a->skin = sb_alloc((size_t)a->nframes * (size_t)g->nj * 16 * sizeof *a->skin);
    a->animated = sb_alloc((size_t)g->nj * sizeof *a->animated);
    /* nodes that matter: the joints and their ancestors, parents first */
    sel = sb_alloc((size_t)s.nn + 1);
    ord = sb_alloc(((size_t)s.nn + 1) * sizeof *ord);
    jn = sb_alloc(((size_t)s.nn + 1) * sizeof *jn);
    for (k = 0; k < s.nn; k++) jn[k] = -1;
    for (k = 0; k < g->nj; k++) jn[g->joints[k].node] = k;
    for (k = 0; k < g->nj; k++)
        for (i = g->joints[k].node; i >= 0 && !sel[i]; i = s.parent[i]) sel[i] = 1;
    {   /* order: parents first, linear in the nodes (walk up to a placed node, place the walk reversed) */
        int n = 0, len, *walk = sb_alloc(((size_t)s.nn + 1) * sizeof *walk);
        char *placed = sb_alloc((size_t)s.nn + 1);
        for (k = 0; k < s.nn; k++) {
            if (!sel[k] || placed[k]) continue;
            for (len = 0, i = k; i >= 0 && !placed[i]; i = s.parent[i]) walk[len++] = i;
            while (len > 0) placed[walk[--len]] = 1, ord[n++] = walk[len];
        }
        ord[n] = -1;
        free(walk), free(placed);
    }
    for (k = 0; k < nch; k++) if (jn[ch[k].node] >= 0) a->animated[jn[ch[k].node]] = 1;
    trs = sb_alloc((size_t)s.nn * 10 * sizeof *trs);
    loc = sb_alloc((size_t)s.nn * 16 * sizeof *loc);
    wld = sb_alloc((size_t)s.nn * 16 * sizeof *wld);
    inv_bind = sb_alloc((size_t)g->nj * 16 * sizeof *inv_bind);
    for (k = 0; k < g->nj; k++)
        if (gl_mat_inv_affine(g->joints[k].bind, inv_bind + 16 * k)) { sb_fail("skin joint %d: bind matrix not invertible", k); goto out; }
    if (g->nj > 256) { sb_fail("skin: %d joints, at most 256", g->nj); goto out; }
    for (f = 0; f < a->nframes; f++) {
        double t = f * h, qw[256 * 4];
        int o;
        memcpy(trs, s.trs, (size_t)s.nn * 10 * sizeof *trs);
        for (k = 0; k < nch; k++) chan_eval(&ch[k], t, trs + 10 * ch[k].node + (ch[k].path == CH_R ? 3 : 0));
        for (o = 0; ord[o] >= 0; o++) {
            int nd = ord[o];
            if (s.is_matrix[nd]) memcpy(loc + 16 * nd, s.local + 16 * nd, 16 * sizeof *loc);
            else gl_mat_trs(trs + 10 * nd, trs + 10 * nd + 3, trs + 10 * nd + 7, loc + 16 * nd);
            if (s.parent[nd] >= 0) gl_mat_mul(wld + 16 * s.parent[nd], loc + 16 * nd, wld + 16 * nd);
            else memcpy(wld + 16 * nd, loc + 16 * nd, 16 * sizeof *wld);
        }
        for (k = 0; k < g->nj && k < 256; k++) {   /* skinning matrix M = world * IBM: its rotation */
            double M[16], *q = a->rot + ((size_t)f * g->nj + k) * 4;
            int p = g->joints[k].parent;
            gl_mat_mul(wld + 16 * g->joints[k].node, inv_bind + 16 * k, M);
            memcpy(a->skin + ((size_t)f * g->nj + k) * 16, M, sizeof M);
            mat_quat(M, qw + 4 * k);
            if (p < 0) {
                double pp[3];
                memcpy(q, qw + 4 * k, 4 * sizeof *q);
                mat_point(M, g->joints[k].pos, pp);
                for (i = 0; i < 3; i++) a->move[3 * f + i] = pp[i] - g->joints[k].pos[i];
            } else {   /* local = world(parent)^-1 world(joint), rotations about bind positions */
                double inv[4] = {-qw[4 * p], -qw[4 * p + 1], -qw[4 * p + 2], qw[4 * p + 3]}, pj[3], pp[3], d[3], r[3], gap = 0;
                qmul(inv, qw + 4 * k, q);
                qnorm(q);
                if (q[3] < 0) for (i = 0; i < 4; i++) q[i] = -q[i];
                /* where the glTF puts the joint vs where the rigid parent bone puts it */
                mat_point(M, g->joints[k].pos, pj);
                {
                    double Mp[16];
                    gl_mat_mul(wld + 16 * g->joints[p].node, inv_bind + 16 * p, Mp);
                    mat_point(Mp, g->joints[k].pos, pp);
                }
                for (i = 0; i < 3; i++) d[i] = pj[i] - pp[i];
                (void)r;
                gap = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                if (gap > a->bone_gap) a->bone_gap = gap;
            }
        }
    }
    rc = 0;
out:
    if (rc) {
        char msg[1600];
        snprintf(msg, sizeof msg, "%s", sb_error());
        sb_fail("%s: %s", path, msg);
        sb_gltf_anim_free(a);
    }
    free_chans(ch, nch);
    free(trs), free(loc), free(wld), free(inv_bind), free(sel), free(ord), free(jn);
    gl_scene_close(&s);
    return rc;
}

/* append to a growing string */
typedef struct { char *p; size_t n, cap; } sbuf;
static void put(sbuf *b, const char *fmt, ...)
{
    va_list ap;
    int n;
    for (;;) {
        va_start(ap, fmt);
        n = vsnprintf(b->p + b->n, b->cap - b->n, fmt, ap);
        va_end(ap);
        if (n >= 0 && (size_t)n < b->cap - b->n) { b->n += (size_t)n; return; }
        b->cap = 2 * b->cap + (size_t)(n > 0 ? n : 64) + 64;
        b->p = realloc(b->p, b->cap);
        if (!b->p) { fprintf(stderr, "out of memory\n"); exit(1); }
    }
}

/* axis-angle of a unit quaternion with w >= 0: axis scaled so its largest
 * component is 16384 (clips read axes in Q16.16: any length), angle in degrees */
static void axis_angle(const double *q, double *ax, double *deg)
{
    double s = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]), m;
    int k;
    *deg = 2 * atan2(s, q[3]) * (180.0 / 3.14159265358979323846);
    if (!(s > 1e-15)) { ax[0] = 0, ax[1] = 0, ax[2] = 1, *deg = 0; return; }
    m = fmax(fabs(q[0]), fmax(fabs(q[1]), fabs(q[2])));
    for (k = 0; k < 3; k++) ax[k] = q[k] / m * 16384.0;
}

/* Rotations closer than this (degrees) count as equal when leaving out a
 * channel that never moves or keying a constant one once: the float noise of
 * world x inverse-bind products (~1e-5 degrees); a clip resolves 1/65536 degree. */
#define SB_ANIM_TOL_DEG 1e-4
static double qangle(const double *a, const double *b)
{
    double d = fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]);
    return d >= 1 ? 0 : 2 * acos(d) * (180.0 / 3.14159265358979323846);
}

/* a number as the clip parser reads it: no exponent, 9 decimals, -0 as 0 */
static void num(sbuf *b, double x)
{
    if (fabs(x) < 5e-10) x = 0;
    put(b, " %.9f", x);
}

char *sb_gltf_anim_clip(const sb_gltf_anim *a, const sb_gltf *g, int32_t hq, int loop, const char *source)
{
    sbuf b = {NULL, 0, 0};
    int k, f, i, nf;
    double dur;
    if (hq < 1) { sb_fail("clip timestep %d (Q16.16) must be positive", (int)hq); return NULL; }
    /* frames at the clip clock: t_k = k hq / 65536 s, up to the first at or past the end */
    nf = (int)ceil(a->end * 65536.0 / hq - 1e-9) + 1;
    if (nf < 2) nf = 2;
    dur = (double)(nf - 1) * hq / 65536.0;
    if (dur >= 32767) { sb_fail("animation of %g s: a clip lasts less than 32767 s", dur); return NULL; }
    b.cap = 4096;
    b.p = sb_alloc(b.cap);
    put(&b, "sinew-clip 1\n# %s: animation %d \"%s\", %d channel(s) (%d scale, %d of them scaling, and %d other ignored), sampled every %.9f s\n",
        source ? source : "glTF", a->index, a->name, a->n_channels, a->n_scale, a->n_scale_active, a->n_other, hq / 65536.0);
    put(&b, "duration %.9f\nloop %s\n", dur, loop ? "yes" : "no");
    (void)f;
    for (k = 0; k < a->nj; k++) {
        char nm[SB_NAME_MAX];
        int moving = 0, constant = 1, nkeys;
        double q0[4];
        static const double ident[4] = {0, 0, 0, 1};
        sb_gltf_token(g->joints[k].name, k, nm, SB_NAME_MAX);
        for (i = 0; i < nf; i++) {   /* the sample nearest each clip key (a->h may differ slightly from hq) */
            const double *q;
            int fi = (int)floor((double)i * hq / 65536.0 / a->h + 0.5);
            if (fi >= a->nframes) fi = a->nframes - 1;
            q = a->rot + ((size_t)fi * a->nj + k) * 4;
            if (i == 0) memcpy(q0, q, sizeof q0);
            if (qangle(q, ident) > SB_ANIM_TOL_DEG) moving = 1;
            if (qangle(q, q0) > SB_ANIM_TOL_DEG) constant = 0;
        }
        if (!moving) continue;
        nkeys = constant ? 1 : nf;
        for (i = 0; i < nkeys; i++) {
            int fi = (int)floor((double)i * hq / 65536.0 / a->h + 0.5);
            double ax[3], deg;
            if (fi >= a->nframes) fi = a->nframes - 1;
            axis_angle(a->rot + ((size_t)fi * a->nj + k) * 4, ax, &deg);
            put(&b, "rot %s %.9f", nm, (double)i * hq / 65536.0);
            num(&b, ax[0]), num(&b, ax[1]), num(&b, ax[2]), num(&b, deg);
            put(&b, "\n");
        }
    }
    {
        int moving = 0, constant = 1, nkeys;
        for (i = 0; i < nf; i++) {
            int fi = (int)floor((double)i * hq / 65536.0 / a->h + 0.5), c;
            if (fi >= a->nframes) fi = a->nframes - 1;
            for (c = 0; c < 3; c++) {
                if (fabs(a->move[3 * fi + c]) > 1e-9) moving = 1;
                if (fabs(a->move[3 * fi + c] - a->move[c]) > 1e-12) constant = 0;
                if (fabs(a->move[3 * fi + c]) >= 32767) { free(b.p); sb_fail("root offset %g at %g s: beyond the clip range (32767)", a->move[3 * fi + c], fi * a->h); return NULL; }
            }
        }
        nkeys = !moving ? 0 : constant ? 1 : nf;
        for (i = 0; i < nkeys; i++) {
            int fi = (int)floor((double)i * hq / 65536.0 / a->h + 0.5);
            if (fi >= a->nframes) fi = a->nframes - 1;
            put(&b, "move %.9f", (double)i * hq / 65536.0);
            num(&b, a->move[3 * fi]), num(&b, a->move[3 * fi + 1]), num(&b, a->move[3 * fi + 2]);
            put(&b, "\n");
        }
    }
    return b.p;
}
