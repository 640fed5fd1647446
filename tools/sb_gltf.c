/* sb_gltf.c -- glTF 2.0 reader, the scene layer: node hierarchy (TRS or
 * matrix, checked for cycles), the default scene, the chosen skinned mesh
 * and its skin. Matrices are column-major as in glTF: m[col*4 + row]. */
#include "sb_gltf.h"
#include "sb_gltf_int.h"
#include "sb.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef gl_scene scene;

void gl_mat_mul(const double *a, const double *b, double *o)
{
    double t[16];
    int r, c, k;
    for (c = 0; c < 4; c++)
        for (r = 0; r < 4; r++) {
            double s = 0;
            for (k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
            t[c * 4 + r] = s;
        }
    memcpy(o, t, sizeof t);
}

static void mat_point(const double *m, const double *p, double *o)
{
    double t[3];
    int r;
    for (r = 0; r < 3; r++) t[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
    memcpy(o, t, sizeof t);
}

/* inverse of an affine matrix (last row 0 0 0 1); -1 if not affine or singular */
int gl_mat_inv_affine(const double *m, double *o)
{
    double a[9], det, inv[9];
    int r, c;
    if (fabs(m[3]) > 1e-6 || fabs(m[7]) > 1e-6 || fabs(m[11]) > 1e-6 || fabs(m[15] - 1) > 1e-6) return -1;
    for (c = 0; c < 3; c++)
        for (r = 0; r < 3; r++) a[r * 3 + c] = m[c * 4 + r];
    inv[0] = a[4] * a[8] - a[5] * a[7];
    inv[1] = a[2] * a[7] - a[1] * a[8];
    inv[2] = a[1] * a[5] - a[2] * a[4];
    inv[3] = a[5] * a[6] - a[3] * a[8];
    inv[4] = a[0] * a[8] - a[2] * a[6];
    inv[5] = a[2] * a[3] - a[0] * a[5];
    inv[6] = a[3] * a[7] - a[4] * a[6];
    inv[7] = a[1] * a[6] - a[0] * a[7];
    inv[8] = a[0] * a[4] - a[1] * a[3];
    det = a[0] * inv[0] + a[1] * inv[3] + a[2] * inv[6];
    if (!(fabs(det) > 1e-300)) return -1;
    memset(o, 0, 16 * sizeof *o);
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++) o[c * 4 + r] = inv[r * 3 + c] / det;
    for (r = 0; r < 3; r++) o[12 + r] = -(o[r] * m[12] + o[4 + r] * m[13] + o[8 + r] * m[14]);
    o[15] = 1;
    return 0;
}

/* T * R * S, column-major; q a unit quaternion (x, y, z, w) */
void gl_mat_trs(const double *t, const double *q, const double *sc, double *m)
{
    double x = q[0], y = q[1], z = q[2], w = q[3];
    m[0] = (1 - 2 * (y * y + z * z)) * sc[0], m[1] = 2 * (x * y + z * w) * sc[0], m[2] = 2 * (x * z - y * w) * sc[0];
    m[4] = 2 * (x * y - z * w) * sc[1], m[5] = (1 - 2 * (x * x + z * z)) * sc[1], m[6] = 2 * (y * z + x * w) * sc[1];
    m[8] = 2 * (x * z + y * w) * sc[2], m[9] = 2 * (y * z - x * w) * sc[2], m[10] = (1 - 2 * (x * x + y * y)) * sc[2];
    m[3] = m[7] = m[11] = 0;
    m[12] = t[0], m[13] = t[1], m[14] = t[2], m[15] = 1;
}

/* one node: local matrix, mesh, skin; children get their parent set */
static int read_node(scene *s, int i)
{
    char path[48];
    int n = gl_elem(&s->d, GA_NODES, i), ch, c, k = 0, has_m, has_t, has_r, has_s;
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, sc[3] = {1, 1, 1}, len, *m = s->local + 16 * i;
    long long v;
    snprintf(path, sizeof path, "nodes[%d]", i);
    if ((has_m = gl_nums(&s->d, n, "matrix", path, 16, m)) < 0 || (has_t = gl_nums(&s->d, n, "translation", path, 3, t)) < 0 ||
        (has_r = gl_nums(&s->d, n, "rotation", path, 4, q)) < 0 || (has_s = gl_nums(&s->d, n, "scale", path, 3, sc)) < 0)
        return -1;
    if (has_m && (has_t || has_r || has_s)) return sb_fail("%s: both matrix and translation/rotation/scale", path);
    s->is_matrix[i] = (char)has_m;
    if (!has_m) {
        len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (!(len > 1e-6)) return sb_fail("%s.rotation: not a unit quaternion", path);
        q[0] /= len, q[1] /= len, q[2] /= len, q[3] /= len;
        gl_mat_trs(t, q, sc, m);
    }
    memcpy(s->trs + 10 * i, t, sizeof t), memcpy(s->trs + 10 * i + 3, q, sizeof q), memcpy(s->trs + 10 * i + 7, sc, sizeof sc);
    if (gl_int(&s->d, n, "mesh", path, -1, 0, s->d.count[GA_MESHES] - 1, &v)) return -1;
    s->mesh[i] = (int)v;
    if (gl_int(&s->d, n, "skin", path, -1, 0, s->d.count[GA_SKINS] - 1, &v)) return -1;
    s->skin[i] = (int)v;
    if ((ch = sbj_get(&s->d.j, n, "children")) < 0) return 0;
    if (s->d.j.node[ch].kind != SBJ_ARR) return sb_fail("%s.children: an array expected", path);
    for (c = s->d.j.node[ch].child; c >= 0; c = s->d.j.node[c].next, k++) {
        double x = s->d.j.node[c].num;
        int j;
        if (s->d.j.node[c].kind != SBJ_NUM || x != floor(x) || x < 0 || x >= s->nn)
            return sb_fail("%s.children[%d]: not a node index", path, k);
        j = (int)x;
        if (j == i) return sb_fail("%s.children[%d]: the node is its own child (a cycle)", path, k);
        if (s->parent[j] >= 0)
            return sb_fail("%s.children[%d]: node %d is already a child of nodes[%d]", path, k, j, s->parent[j]);
        s->parent[j] = i;
    }
    return 0;
}

static int read_nodes(scene *s)
{
    int i, *chain;
    s->nn = s->d.count[GA_NODES];
    s->parent = sb_alloc((size_t)s->nn * sizeof *s->parent);
    s->local = sb_alloc((size_t)s->nn * 16 * sizeof *s->local);
    s->world = sb_alloc((size_t)s->nn * 16 * sizeof *s->world);
    s->done = sb_alloc((size_t)s->nn);
    s->mesh = sb_alloc((size_t)s->nn * sizeof *s->mesh);
    s->skin = sb_alloc((size_t)s->nn * sizeof *s->skin);
    s->trs = sb_alloc((size_t)s->nn * 10 * sizeof *s->trs);
    s->is_matrix = sb_alloc((size_t)s->nn + 1);
    for (i = 0; i < s->nn; i++) s->parent[i] = -1;
    for (i = 0; i < s->nn; i++)
        if (read_node(s, i)) return -1;
    /* world matrices, parents first: walk up to a finished node (done 2)
     * marking the walk (done 1); meeting a marked node is a cycle. Linear. */
    chain = sb_alloc((size_t)s->nn * sizeof *chain + 1);
    for (i = 0; i < s->nn; i++) {
        int j = i, len = 0;
        while (j >= 0 && !s->done[j]) s->done[j] = 1, chain[len++] = j, j = s->parent[j];
        if (j >= 0 && s->done[j] == 1) {
            free(chain);
            return sb_fail("nodes[%d].children: a cycle through node %d", s->parent[j], j);
        }
        while (len > 0) {
            int k = chain[--len];
            if (s->parent[k] >= 0) gl_mat_mul(s->world + 16 * s->parent[k], s->local + 16 * k, s->world + 16 * k);
            else memcpy(s->world + 16 * k, s->local + 16 * k, 16 * sizeof(double));
            s->done[k] = 2;
        }
    }
    free(chain);
    return 0;
}

/* the node that uses the wanted skinned mesh, walking the default scene depth first */
static int pick_node(scene *s, const char *want)
{
    int sc = -1, nodes = -1, *stack, top = 0, i, found = -1, named = -1;
    char *seen;
    long long v;
    if (gl_int(&s->d, 0, "scene", "", s->d.count[GA_SCENES] ? 0 : -1, 0, s->d.count[GA_SCENES] - 1, &v))
        return sb_fail("scene: not an index into scenes (%d)", s->d.count[GA_SCENES]);
    sc = (int)v;
    /* each node is pushed at most once (scene roots distinct, one parent each) */
    stack = sb_alloc(((size_t)s->nn + 1) * sizeof *stack);
    seen = sb_alloc((size_t)s->nn + 1);
    if (sc >= 0) {
        int c, k = 0;
        nodes = sbj_get(&s->d.j, gl_elem(&s->d, GA_SCENES, sc), "nodes");
        if (nodes >= 0 && s->d.j.node[nodes].kind != SBJ_ARR) {
            free(stack), free(seen);
            return sb_fail("scenes[%d].nodes: an array expected", sc);
        }
        for (c = nodes < 0 ? -1 : s->d.j.node[nodes].child; c >= 0; c = s->d.j.node[c].next, k++) {
            double x = s->d.j.node[c].num;
            if (s->d.j.node[c].kind != SBJ_NUM || x != floor(x) || x < 0 || x >= s->nn || s->parent[(int)x] >= 0 ||
                seen[(int)x]) {
                free(stack), free(seen);
                return sb_fail("scenes[%d].nodes[%d]: not a root node index, or listed twice", sc, k);
            }
            seen[(int)x] = 1;
            stack[top++] = (int)x;
        }
        for (c = top - 1, k = 0; k < c; k++, c--) {   /* reversed: the walk meets them in order */
            int t = stack[k];
            stack[k] = stack[c], stack[c] = t;
        }
    } else
        for (i = s->nn - 1; i >= 0; i--)
            if (s->parent[i] < 0) stack[top++] = i;
    while (top > 0 && found < 0) {
        int n = stack[--top], ch, c, k;
        if (s->mesh[n] >= 0) {
            const char *name = sbj_str(&s->d.j, sbj_get(&s->d.j, gl_elem(&s->d, GA_MESHES, s->mesh[n]), "name"));
            int match = !want || (name && !strcmp(name, want));
            if (match && s->skin[n] >= 0) found = n;
            else if (match) named = n;
        }
        ch = sbj_get(&s->d.j, gl_elem(&s->d, GA_NODES, n), "children");
        k = top;   /* pushed in order, then reversed: the walk meets them in order */
        for (c = ch < 0 ? -1 : s->d.j.node[ch].child; c >= 0; c = s->d.j.node[c].next) stack[top++] = (int)s->d.j.node[c].num;
        for (c = top - 1; k < c; k++, c--) {
            int t = stack[k];
            stack[k] = stack[c], stack[c] = t;
        }
    }
    free(stack), free(seen);
    if (found >= 0) return found;
    if (want && named >= 0) return sb_fail("nodes[%d]: uses mesh \"%s\" without a skin", named, want);
    if (want) return sb_fail("meshes: no skinned mesh named \"%s\" in the scene", want);
    return sb_fail("scenes[%d]: no skinned mesh", sc < 0 ? 0 : sc);
}

static char *dup_str(const char *s)
{
    char *d = sb_alloc(strlen(s ? s : "") + 1);
    strcpy(d, s ? s : "");
    return d;
}

/* huge TRS values or IBMs can overflow: refuse rather than pass infinities on */
static int joints_finite(const sb_gltf *g, const char *path)
{
    int k, c;
    for (k = 0; k < g->nj; k++)
        for (c = 0; c < 3; c++)
            if (!isfinite(g->joints[k].pos[c]) || !isfinite(g->joints[k].node_pos[c]))
                return sb_fail("%s.joints[%d]: the bind position of nodes[%d] is not finite", path, k, g->joints[k].node);
    return 0;
}

static int read_skin(scene *s, sb_gltf *g)
{
    char path[48];
    int sk = gl_elem(&s->d, GA_SKINS, g->skin), ja = sbj_get(&s->d.j, sk, "joints"), c, k = 0, *of_node;
    long long ibm_acc;
    gl_acc ibm;
    snprintf(path, sizeof path, "skins[%d]", g->skin);
    if (ja < 0 || s->d.j.node[ja].kind != SBJ_ARR || s->d.j.node[ja].count < 1)
        return sb_fail("%s.joints: a non-empty array expected", path);
    g->nj = s->d.j.node[ja].count;
    g->joints = sb_alloc((size_t)g->nj * sizeof *g->joints);
    of_node = sb_alloc((size_t)s->nn * sizeof *of_node);
    for (c = 0; c < s->nn; c++) of_node[c] = -1;
    for (c = s->d.j.node[ja].child; c >= 0; c = s->d.j.node[c].next, k++) {
        double x = s->d.j.node[c].num;
        sb_gltf_joint *J = &g->joints[k];
        if (s->d.j.node[c].kind != SBJ_NUM || x != floor(x) || x < 0 || x >= s->nn) {
            free(of_node);
            return sb_fail("%s.joints[%d]: not a node index", path, k);
        }
        J->node = (int)x;
        if (of_node[J->node] >= 0) {
            free(of_node);
            return sb_fail("%s.joints[%d]: node %d is listed twice", path, k, J->node);
        }
        of_node[J->node] = k;
        J->name = dup_str(sbj_str(&s->d.j, sbj_get(&s->d.j, gl_elem(&s->d, GA_NODES, J->node), "name")));
        J->node_pos[0] = s->world[16 * J->node + 12];
        J->node_pos[1] = s->world[16 * J->node + 13];
        J->node_pos[2] = s->world[16 * J->node + 14];
        memcpy(J->pos, J->node_pos, sizeof J->pos);
        memcpy(J->bind, s->world + 16 * J->node, sizeof J->bind);
    }
    for (k = 0; k < g->nj; k++) {
        int p = s->parent[g->joints[k].node];
        while (p >= 0 && of_node[p] < 0) p = s->parent[p];
        g->joints[k].parent = p >= 0 ? of_node[p] : -1;
    }
    free(of_node);
    if (gl_int(&s->d, sk, "inverseBindMatrices", path, -1, 0, s->d.count[GA_ACCESSORS] - 1, &ibm_acc)) return -1;
    if (ibm_acc < 0) return joints_finite(g, path);
    if (gl_accessor(&s->d, (int)ibm_acc, &ibm)) return -1;
    if (ibm.ncomp != 16 || ibm.count < g->nj) {
        free(ibm.v);
        return sb_fail("%s.inverseBindMatrices: accessors[%lld] must be MAT4 with at least %d elements", path, ibm_acc, g->nj);
    }
    for (k = 0; k < g->nj; k++) {
        double inv[16], o[3] = {0, 0, 0};
        if (gl_mat_inv_affine(ibm.v + 16 * k, inv)) {
            free(ibm.v);
            return sb_fail("%s.inverseBindMatrices: matrix %d is not an invertible affine matrix", path, k);
        }
        /* glTF 2.0 (3.7.3.3 Skins): the skinned mesh node's own transform is
         * ignored; inverse(IBM) takes the joint's origin into the space of POSITION */
        mat_point(inv, o, g->joints[k].pos);
        memcpy(g->joints[k].bind, inv, sizeof inv);
    }
    free(ibm.v);
    return joints_finite(g, path);
}

/* read an attribute/indices accessor, checking its shape; path names the use */
static int prim_acc(scene *s, int prim, const char *key, int in_attr, const char *path, int ncomp, const int *ctypes,
                    int norm_ok, long long want_count, gl_acc *a)
{
    long long idx;
    int obj = in_attr ? sbj_get(&s->d.j, prim, "attributes") : prim, k, ok = 0;
    char p2[96];
    snprintf(p2, sizeof p2, "%s%s", path, in_attr ? ".attributes" : "");
    memset(a, 0, sizeof *a);
    if (gl_int(&s->d, obj, key, p2, in_attr && !strcmp(key, "POSITION") ? GL_REQUIRED : -1, 0,
               s->d.count[GA_ACCESSORS] - 1, &idx))
        return -1;
    if (idx < 0) return 0;
    if (gl_accessor(&s->d, (int)idx, a)) return -1;
    for (k = 0; ctypes[k]; k++) ok |= a->ctype == ctypes[k];
    if (a->ncomp != ncomp || !ok || (a->normalized && !norm_ok) || (want_count >= 0 && a->count != want_count)) {
        free(a->v);
        a->v = NULL;
        if (want_count >= 0 && a->count != want_count)
            return sb_fail("%s.%s: accessors[%lld] has %lld elements, POSITION has %lld", p2, key, idx, a->count, want_count);
        return sb_fail("%s.%s: accessors[%lld] has the wrong type or componentType for %s", p2, key, idx, key);
    }
    return 1;
}

/* realloc keeping the old block on failure (sb_gltf_free still frees it) */
static int grow(void **p, size_t n)
{
    void *q = realloc(*p, n ? n : 1);
    if (!q) return -1;
    *p = q;
    return 0;
}

static int read_prim(scene *s, sb_gltf *g, int m, int pi, int prim)
{
    static const int t_pos[] = {5126, 0}, t_joint[] = {5121, 5123, 0}, t_weight[] = {5126, 5121, 5123, 0},
                     t_index[] = {5121, 5123, 5125, 0};
    char path[80];
    long long mode, nv, ni, v, k;
    gl_acc P, J, W, I;
    int nv0 = g->nv, nt0 = g->nt, rc = -1, c;
    snprintf(path, sizeof path, "meshes[%d].primitives[%d]", m, pi);
    memset(&J, 0, sizeof J), memset(&W, 0, sizeof W), memset(&I, 0, sizeof I);
    if (gl_int(&s->d, prim, "mode", path, 4, 0, 6, &mode)) return -1;
    if (mode != 4) return sb_fail("%s.mode: %lld, only 4 (triangles) is read", path, mode);
    if (sbj_get(&s->d.j, prim, "attributes") < 0) return sb_fail("%s.attributes: missing", path);
    if (sbj_get(&s->d.j, sbj_get(&s->d.j, prim, "attributes"), "JOINTS_1") >= 0)
        return sb_fail("%s.attributes.JOINTS_1: more than 4 joints per vertex are not read", path);
    if (prim_acc(s, prim, "POSITION", 1, path, 3, t_pos, 0, -1, &P) < 0) return -1;
    nv = P.count;
    if ((c = prim_acc(s, prim, "JOINTS_0", 1, path, 4, t_joint, 0, nv, &J)) <= 0 ||
        (c = prim_acc(s, prim, "WEIGHTS_0", 1, path, 4, t_weight, 1, nv, &W)) <= 0) {
        if (c == 0) sb_fail("%s.attributes: JOINTS_0 and WEIGHTS_0 are required in a skinned mesh", path);
        goto out;
    }
    if ((c = prim_acc(s, prim, "indices", 0, path, 1, t_index, 0, -1, &I)) < 0) goto out;
    ni = c ? I.count : nv;
    if (ni % 3) { sb_fail("%s: %lld indices, not a multiple of 3", path, ni); goto out; }
    if ((long long)g->nv + nv > (1LL << 28) || (long long)g->nt + ni / 3 > (1LL << 28)) { sb_fail("%s: too many vertices", path); goto out; }
    if (grow((void **)&g->pos, (size_t)(g->nv + nv) * 3 * sizeof *g->pos) ||
        grow((void **)&g->joint, (size_t)(g->nv + nv) * 4 * sizeof *g->joint) ||
        grow((void **)&g->weight, (size_t)(g->nv + nv) * 4 * sizeof *g->weight) ||
        grow((void **)&g->src_prim, (size_t)(g->nv + nv) * sizeof *g->src_prim) ||
        grow((void **)&g->src_vert, (size_t)(g->nv + nv) * sizeof *g->src_vert) ||
        grow((void **)&g->tri, (size_t)(g->nt + ni / 3) * 3 * sizeof *g->tri)) {
        sb_fail("%s: out of memory", path);
        goto out;
    }
    for (v = 0; v < nv; v++) {
        double sum = 0, *w = g->weight + 4 * (nv0 + v);
        int *j = g->joint + 4 * (nv0 + v);
        /* POSITION as stored: a skinned mesh ignores its node's transform (glTF 2.0, 3.7.3.3) */
        memcpy(g->pos + 3 * (nv0 + v), P.v + 3 * v, 3 * sizeof(double));
        if (!isfinite(g->pos[3 * (nv0 + v)]) || !isfinite(g->pos[3 * (nv0 + v) + 1]) || !isfinite(g->pos[3 * (nv0 + v) + 2])) {
            sb_fail("%s.attributes.POSITION: vertex %lld is not finite", path, v);
            goto out;
        }
        g->src_prim[nv0 + v] = pi;
        g->src_vert[nv0 + v] = (int)v;
        for (k = 0; k < 4; k++) {
            w[k] = W.v[4 * v + k];
            j[k] = (int)J.v[4 * v + k];
            if (!(w[k] >= 0) || !isfinite(w[k])) {
                sb_fail("%s.attributes.WEIGHTS_0: vertex %lld has a negative or non-finite weight", path, v);
                goto out;
            }
            if (w[k] > 0 && j[k] >= g->nj) {
                sb_fail("%s.attributes.JOINTS_0: vertex %lld uses joint %d, skins[%d] has %d", path, v, j[k], g->skin, g->nj);
                goto out;
            }
            if (w[k] == 0) j[k] = 0;
            sum += w[k];
        }
        if (!(sum > 0)) { sb_fail("%s.attributes.WEIGHTS_0: vertex %lld has no weight", path, v); goto out; }
        for (k = 0; k < 4; k++) w[k] /= sum;
    }
    for (k = 0; k < ni; k++) {
        long long x = c ? (long long)I.v[k] : k;
        if (x >= nv) { sb_fail("%s.indices: index %lld is %lld, POSITION has %lld vertices", path, k, x, nv); goto out; }
        g->tri[3 * nt0 + k] = nv0 + (int)x;
    }
    g->nv += (int)nv;
    g->nt += (int)(ni / 3);
    rc = 0;
out:
    free(P.v), free(J.v), free(W.v), free(I.v);
    return rc;
}

static int read_mesh(scene *s, sb_gltf *g)
{
    int mn = gl_elem(&s->d, GA_MESHES, g->mesh), pa = sbj_get(&s->d.j, mn, "primitives"), c, k = 0;
    g->mesh_name = dup_str(sbj_str(&s->d.j, sbj_get(&s->d.j, mn, "name")));
    if (pa < 0 || s->d.j.node[pa].kind != SBJ_ARR || s->d.j.node[pa].count < 1)
        return sb_fail("meshes[%d].primitives: a non-empty array expected", g->mesh);
    for (c = s->d.j.node[pa].child; c >= 0; c = s->d.j.node[c].next, k++) {
        if (s->d.j.node[c].kind != SBJ_OBJ) return sb_fail("meshes[%d].primitives[%d]: an object expected", g->mesh, k);
        if (read_prim(s, g, g->mesh, k, c)) return -1;
    }
    return 0;
}

void sb_gltf_token(const char *in, int k, char *out, int out_len)
{
    int i;
    if (!in[0]) { snprintf(out, (size_t)out_len, "joint%d", k); return; }
    for (i = 0; in[i] && i < out_len - 1; i++)
        out[i] = (in[i] == ' ' || in[i] == '\t' || in[i] == '\r' || in[i] == '\n' || in[i] == '#') ? '_' : in[i];
    out[i] = '\0';
}

int gl_scene_open(gl_scene *s, const char *path)
{
    memset(s, 0, sizeof *s);
    return gl_open(&s->d, path) || read_nodes(s) ? -1 : 0;
}

int gl_scene_pick(gl_scene *s, const char *mesh_name) { return pick_node(s, mesh_name); }

void gl_scene_close(gl_scene *s)
{
    free(s->parent), free(s->local), free(s->world), free(s->done), free(s->mesh), free(s->skin), free(s->trs), free(s->is_matrix);
    gl_close(&s->d);
    memset(s, 0, sizeof *s);
}

void sb_gltf_free(sb_gltf *g)
{
    int k;
    for (k = 0; k < g->nj && g->joints; k++) free(g->joints[k].name);
    free(g->joints), free(g->mesh_name), free(g->pos), free(g->joint), free(g->weight);
    free(g->src_prim), free(g->src_vert), free(g->tri);
    memset(g, 0, sizeof *g);
}

int sb_gltf_load(sb_gltf *g, const char *path, const char *mesh_name)
{
    scene s;
    int rc = -1, n;
    memset(g, 0, sizeof *g);
    if (gl_scene_open(&s, path) || (n = pick_node(&s, mesh_name)) < 0) goto out;
    g->node = n;
    g->mesh = s.mesh[n];
    g->skin = s.skin[n];
    if (read_skin(&s, g) || read_mesh(&s, g)) goto out;
    rc = 0;
out:
    if (rc) {
        char msg[512];
        snprintf(msg, sizeof msg, "%s", sb_error());
        sb_fail("%s: %s", path, msg);
        sb_gltf_free(g);
    }
    gl_scene_close(&s);
    return rc;
}
