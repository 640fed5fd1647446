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

int main(void)
{
    (void)t_seed;
    heads("cow", "tools/examples/cow_gltf/cow.glb", "tools/examples/cow_gltf/cow_heads.txt");
    heads("beast", "tools/examples/beast_gltf/beast.glb", "tools/examples/beast_gltf/beast_heads.txt");
    throughput();
    bake("cow", "tools/examples/cow_gltf/cow_gltf.sinew", "tools/examples/cow/cow.sinew");
    bake("beast", "tools/examples/beast_gltf/beast_gltf.sinew", "tools/examples/beast/beast.sinew");
    return T_END();
}
