/* test_bake_gltf_blender.c -- files from a real exporter (issue 17 item 5):
 * tools/examples/cow_gltf/cow.glb and beast_gltf/beast.glb, made by Blender's own glTF exporter
 * (tools/blender/make_gltf.py, Blender 3.4.1). The joint rest positions our
 * reader takes from the inverse bind matrices must match the armature's bone
 * heads Blender wrote beside them (cow_heads.txt, beast_heads.txt) within 1e-5 of the model's
 * size; both descriptions bake. Figures: the reader's throughput on the
 * 32k-vertex humanoid (.glb vs the OBJ reader on the same surface) and the
 * bake time from glTF vs OBJ + joints. */
#include "sb.h"
#include "sb_gltf.h"
#include "sn_test.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char tmpdir[512];

static void heads(const char *what, const char *glb, const char *txt)
{
    sb_gltf g;
    FILE *f;
    char line[512];
    double worst = 0, diag = 0, lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    int n = 0, found = 0, v, c;
    if (sb_gltf_load(&g, glb, NULL)) { T_CHECK(0, "%s: %s", what, sb_error()); return; }
    for (v = 0; v < g.nv; v++)
        for (c = 0; c < 3; c++) lo[c] = fmin(lo[c], g.pos[3 * v + c]), hi[c] = fmax(hi[c], g.pos[3 * v + c]);
    for (c = 0; c < 3; c++) diag += (hi[c] - lo[c]) * (hi[c] - lo[c]);
    diag = sqrt(diag);
    f = fopen(txt, "r");
    T_CHECK(f != NULL, "%s: cannot open %s", what, txt);
    while (f && fgets(line, sizeof line, f)) {
        char name[128];
        double p[3];
        int k;
        if (line[0] == '#' || sscanf(line, "%127s %lf %lf %lf", name, &p[0], &p[1], &p[2]) != 4) continue;
        n++;
        for (k = 0; k < g.nj; k++)
            if (!strcmp(g.joints[k].name, name)) {
                double d = 0;
                for (c = 0; c < 3; c++) d += (g.joints[k].pos[c] - p[c]) * (g.joints[k].pos[c] - p[c]);
                worst = fmax(worst, sqrt(d));
                found++;
            }
    }
    if (f) fclose(f);
    T_CHECK(n == g.nj && found == n, "%s: %d heads, %d skin joints, %d matched", what, n, g.nj, found);
    T_CHECK(worst <= 1e-5 * diag, "%s: joint vs bone head %.3g (model size %.4g: %.3g relative)", what, worst, diag, worst / diag);
    T_FIGURE("%s: %d joints from the inverse bind matrices vs Blender's bone heads: largest gap %.3g units (%.3g of the model's %.4g)",
             what, g.nj, worst, worst / diag, diag);
    sb_gltf_free(&g);
}

static void throughput(void)
{
    const char *glb = "tools/examples/beast_gltf/beast.glb", *obj = "tools/examples/beast/beast.obj";
    double t, tg = 1e30, to = 1e30;
    int r, nv = 0;
    FILE *f = fopen(glb, "rb");
    long bytes = 0;
    if (f) { fseek(f, 0, SEEK_END); bytes = ftell(f); fclose(f); }
    for (r = 0; r < 3; r++) {
        sb_gltf g;
        sb_mesh m;
        t = sb_now();
        if (sb_gltf_load(&g, glb, NULL)) { T_CHECK(0, "beast.glb: %s", sb_error()); return; }
        tg = fmin(tg, sb_now() - t);
        nv = g.nv;
        sb_gltf_free(&g);
        t = sb_now();
        if (sb_mesh_load_obj(obj, &m)) { T_CHECK(0, "beast.obj: %s", sb_error()); return; }
        to = fmin(to, sb_now() - t);
        sb_mesh_free(&m);
    }
    T_CHECK(nv == 32311, "beast.glb: %d vertices", nv);
    T_FIGURE("reader: beast.glb (%d vertices, %ld bytes) in %.1f ms = %.1f M vertices/s, %.0f MB/s; the OBJ reader on beast.obj %.1f ms",
             nv, bytes, 1e3 * tg, nv / tg / 1e6, bytes / tg / 1e6, 1e3 * to);
}

static void bake(const char *what, const char *gdesc, const char *odesc)
{
    sb_model o;
    sb_blob b;
    double t = sb_now(), tg, to;
    int rc = sb_bake_file(gdesc, SB_FIXED, 1, &o, &b);
    tg = sb_now() - t;
    T_CHECK(rc == 0, "%s: %s", gdesc, rc ? sb_error() : "");
    if (rc == 0) {
        T_CHECK(o.src.nsrc >= o.ns && o.src.nsurf == o.ns, "%s: map %d -> %d", what, o.src.nsrc, o.src.nsurf);
        sb_blob_free(&b), sb_model_free(&o);
    }
    t = sb_now();
    rc = sb_bake_file(odesc, SB_FIXED, 1, &o, &b);
    to = sb_now() - t;
    if (rc == 0) sb_blob_free(&b), sb_model_free(&o);
    T_FIGURE("%s: bake from Blender's .glb %.2f s, from OBJ + joints %.2f s", what, tg, to);
}

/* 'frames skin' vs the automatic frames (issue 17 item 2, optional part):
 * over every frame of the Blender walk, the surface skinned by the lattice
 * frames (each lattice vertex moved by its two joints' skinning matrices,
 * blended by its weight; each surface vertex the trilinear blend of its
 * cell's corners) against the artist's own linear blend skinning of the same
 * vertices with the same matrices (what Blender shows). RMS and largest gap,
 * relative to the model's size: the quasi-static shape each choice of frames
 * gives, before any dynamics. */
static void frame_gap(const char *what, const char *glb, const char *desc_src, double *rms_out, double *max_out)
{
    sb_desc d;
    sb_mesh m;
    sb_model o;
    sb_gltf_anim a;
    const sb_gltf *g;
    double sum = 0, mx = 0, diag = 0, emb = 0;
    long cnt = 0;
    int f, v, i, k, c, *sorted_to_desc;
    memset(&m, 0, sizeof m);
    if (sb_desc_load(desc_src, &d) || sb_desc_mesh(&d, &m, NULL) || sb_build(&d, &m, &o, 1)) {
        T_CHECK(0, "%s: %s", what, sb_error());
        sb_mesh_free(&m), sb_desc_free(&d);
        return;
    }
    g = d.gltf;
    sorted_to_desc = malloc(sizeof(int) * (size_t)o.nj);
    for (k = 0; k < o.nj; k++) sorted_to_desc[o.desc_to_sorted[k]] = k;
    for (c = 0; c < 3; c++) diag += (m.hi[c] - m.lo[c]) * (m.hi[c] - m.lo[c]);
    diag = sqrt(diag);
    if (sb_gltf_anim_load(&a, glb, g, "walk", 1.0 / 60, 10000)) {
        T_CHECK(0, "%s: %s", what, sb_error());
    } else {
        double *y = malloc(sizeof(double) * 3 * (size_t)o.nv);
        for (f = 0; f < a.nframes; f++) {
            const double *M = a.skin + (size_t)f * a.nj * 16;
            for (i = 0; i < o.nv; i++) {   /* lattice vertices by their frames */
                const double *x = o.x + 3 * i, *A = M + 16 * sorted_to_desc[o.fb1[i]], *B = M + 16 * sorted_to_desc[o.fb2[i]];
                for (c = 0; c < 3; c++) {
                    double pa = A[c] * x[0] + A[4 + c] * x[1] + A[8 + c] * x[2] + A[12 + c];
                    double pb = B[c] * x[0] + B[4 + c] * x[1] + B[8 + c] * x[2] + B[12 + c];
                    y[3 * i + c] = (1 - o.fw[i]) * pa + o.fw[i] * pb;
                }
            }
            for (v = 0; v < g->nv; v += 1) {
                double N[8], dN[8][3], s[3] = {0, 0, 0}, l[3] = {0, 0, 0}, e = 0;
                int sv = v < m.nv ? v : 0;   /* Blender's export: one primitive, no split vertices (checked below) */
                sb_shape(o.emb_t + 3 * sv, N, dN);
                for (k = 0; k < 8; k++)
                    for (c = 0; c < 3; c++) s[c] += N[k] * y[3 * o.cells[8 * o.emb_cell[sv] + k] + c];
                for (k = 0; k < 4; k++) {
                    const double *W = M + 16 * g->joint[4 * v + k], *p = g->pos + 3 * v, w = g->weight[4 * v + k];
                    for (c = 0; c < 3; c++) l[c] += w * (W[c] * p[0] + W[4 + c] * p[1] + W[8 + c] * p[2] + W[12 + c]);
                }
                if (f == 0) {   /* at the rest frame the embedding must give the vertex back */
                    double r[3] = {0, 0, 0};
                    for (k = 0; k < 8; k++)
                        for (c = 0; c < 3; c++) r[c] += N[k] * o.x[3 * o.cells[8 * o.emb_cell[sv] + k] + c];
                    for (c = 0; c < 3; c++) emb = fmax(emb, fabs(r[c] - g->pos[3 * v + c]));
                }
                for (c = 0; c < 3; c++) e += (s[c] - l[c]) * (s[c] - l[c]);
                sum += e, cnt++, mx = fmax(mx, sqrt(e));
            }
        }
        free(y);
        sb_gltf_anim_free(&a);
    }
    T_CHECK(g->nv == m.nv && emb < 1e-6 * diag, "%s: %d glTF vs %d surface vertices, embedding %.3g", what, g->nv, m.nv, emb);
    *rms_out = sqrt(sum / (cnt ? cnt : 1)) / diag, *max_out = mx / diag;
    free(sorted_to_desc);
    sb_model_free(&o), sb_mesh_free(&m), sb_desc_free(&d);
}

static void frames_skin(const char *what, const char *dir, const char *glb_name, const char *desc_name)
{
    char cwd[2048], src[4096], auto_p[4200], skin_p[4200], glb[4200], line[4096];
    FILE *in, *fa, *fs;
    double r_auto = 0, m_auto = 0, r_skin = 0, m_skin = 0;
    if (!getcwd(cwd, sizeof cwd)) return;
    snprintf(src, sizeof src, "%s/%s", dir, desc_name);
    snprintf(glb, sizeof glb, "%s/%s/%s", cwd, dir, glb_name);
    snprintf(auto_p, sizeof auto_p, "%s/%s_frames_auto.sinew", tmpdir, what);
    snprintf(skin_p, sizeof skin_p, "%s/%s_frames_skin.sinew", tmpdir, what);
    in = fopen(src, "r"), fa = fopen(auto_p, "w"), fs = fopen(skin_p, "w");
    if (!in || !fa || !fs) { T_CHECK(0, "%s: cannot write the variants", what); return; }
    while (fgets(line, sizeof line, in)) {
        if (!strncmp(line, "gltf ", 5)) {
            fprintf(fa, "gltf %s\n", glb);
            fprintf(fs, "gltf %s\nframes skin\n", glb);
        } else fputs(line, fa), fputs(line, fs);
    }
    fclose(in), fclose(fa), fclose(fs);
    frame_gap(what, glb, auto_p, &r_auto, &m_auto);
    frame_gap(what, glb, skin_p, &r_skin, &m_skin);
    T_FIGURE("%s walk, surface skinned by the lattice frames vs Blender's skinning (RMS / largest, of the model's size): "
             "automatic frames %.4f / %.4f, 'frames skin' %.4f / %.4f", what, r_auto, m_auto, r_skin, m_skin);
}

int main(void)
{
    (void)t_seed;
    heads("cow", "tools/examples/cow_gltf/cow.glb", "tools/examples/cow_gltf/cow_heads.txt");
    heads("beast", "tools/examples/beast_gltf/beast.glb", "tools/examples/beast_gltf/beast_heads.txt");
    throughput();
    bake("cow", "tools/examples/cow_gltf/cow_gltf.sinew", "tools/examples/cow/cow.sinew");
    bake("beast", "tools/examples/beast_gltf/beast_gltf.sinew", "tools/examples/beast/beast.sinew");
    {
        const char *base = getenv("BUILD") ? getenv("BUILD") : "build";
        char cmd[600];
        snprintf(tmpdir, sizeof tmpdir, "%s/test_bake_gltf_blender.d", base);
        snprintf(cmd, sizeof cmd, "mkdir -p '%s'", tmpdir);
        if (system(cmd)) return T_END();
    }
    frames_skin("cow", "tools/examples/cow_gltf", "cow.glb", "cow_gltf.sinew");
    frames_skin("beast", "tools/examples/beast_gltf", "beast.glb", "beast_gltf.sinew");
    return T_END();
}
