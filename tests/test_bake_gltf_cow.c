/* test_bake_gltf_cow.c -- baking from glTF (issue 17 item 2; the 'gltf' line
 * of tools/DESCRIPTION.md). The test writes the cow (tools/examples/cow: its
 * OBJ and its description's joints) as a glTF 2.0 skinned mesh: joints as a
 * node hierarchy with inverse bind matrices, the surface as two primitives
 * (the first holds every vertex in OBJ order and half the triangles, the
 * second a split copy of every vertex, as flat normals or UV seams would
 * make, and the other half), the mesh node moved and rotated (a skinned mesh
 * ignores it). It writes the same geometry rounded to float32 as an OBJ +
 * 'joint' description, bakes both and wants equal blobs (so matrices equal
 * far within 1e-9 relative), the glTF vertex order map, and 'region bone'
 * with the glTF's joint names. It adds two animations to the file and checks
 * the sampler (tools/sb_gltf_anim.c) against their definitions (LINEAR, STEP,
 * CUBICSPLINE) and its refusals; tests/scripts/test_gltf.sh plays them. */
#include "sb.h"
#include "sb_gltf.h"
#include "sn_test.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char tmp[512];
static const char *at(const char *name)
{
    static char p[4][700];
    static int k;
    k = (k + 1) % 4;
    snprintf(p[k], sizeof p[k], "%s/%s", tmp, name);
    return p[k];
}

static void putf(unsigned char *p, float f)
{
    unsigned u;
    memcpy(&u, &f, 4);
    p[0] = (unsigned char)u, p[1] = (unsigned char)(u >> 8), p[2] = (unsigned char)(u >> 16), p[3] = (unsigned char)(u >> 24);
}
static void put32(unsigned char *p, unsigned u)
{
    p[0] = (unsigned char)u, p[1] = (unsigned char)(u >> 8), p[2] = (unsigned char)(u >> 16), p[3] = (unsigned char)(u >> 24);
}

/* ---- animations (issue 17 item 3): keyed so that the clip clock's steps
 * (HQ = the cow's timestep in Q16.16, 1092) land on whole degrees and
 * 1/64 mesh units, values a clip holds exactly, so the hand-written clip
 * (hand.clip, one key per step computed here from the same definition) and
 * the glTF animation resampled by sinew-play --gltf-anim must give the same
 * state hash (tests/scripts/gltf_play.sh). ---- */
#define HQ 1092
static float anim[4096];
static int nanim;
static char acc_json[8192], anim_json[4096];
static int nacc_extra;
/* append count elements as an accessor of the given type; returns its index (9 + k) */
static int anim_acc(const float *v, int count, int ncomp, const char *type, int with_minmax)
{
    size_t o = strlen(acc_json);
    int k;
    snprintf(acc_json + o, sizeof acc_json - o, ",\n{\"bufferView\":6,\"byteOffset\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"%s\"",
             4 * nanim, count, type);
    if (with_minmax) {
        o = strlen(acc_json);
        snprintf(acc_json + o, sizeof acc_json - o, ",\"min\":[%.9g],\"max\":[%.9g]", (double)v[0], (double)v[count - 1]);
    }
    strcat(acc_json, "}");
    for (k = 0; k < count * ncomp; k++) anim[nanim++] = v[k];
    return 9 + nacc_extra++;
}
static void quat_axis(float *q, int axis, double deg)
{
    double h = deg * 3.14159265358979323846 / 360.0;
    q[0] = q[1] = q[2] = 0, q[axis] = (float)sin(h), q[3] = (float)cos(h);
}
/* the test animation's values at step k (definitions shared with hand.clip) */
static double neck_deg(int k) { return k <= 30 ? k : k <= 60 ? 30 - 2 * (k - 30) : -30; }   /* LINEAR 0 -> 30 -> -30 about z */
static double hip_deg(int k) { return k < 20 ? 10 : k < 40 ? -15 : 5; }                      /* STEP 10, -15, 5 about x */
static double move_x(int k) { return (k < 40 ? k : 40) / 64.0; }                              /* LINEAR 0 -> 0.625 in x */

/* cow.gltf + cow.bin, cow_f.obj, cow_gltf.sinew, cow_obj.sinew in tmp; 0 ok */
static int write_cow(void)
{
    sb_desc d;
    sb_mesh m;
    FILE *f, *in;
    unsigned char *bin;
    size_t nv, nt0, nt1, off_pos, off_jw, off_i0, off_i1, off_ibm, len, k;
    int i, j, c;
    char line[4096];
    memset(&m, 0, sizeof m);
    if (sb_desc_load("tools/examples/cow/cow.sinew", &d) || sb_mesh_load_obj(d.mesh_path, &m)) {
        T_CHECK(0, "cow: %s", sb_error());
        return -1;
    }
    nv = (size_t)m.nv, nt0 = (size_t)m.nt / 2, nt1 = (size_t)m.nt - nt0;
    /* layout: POSITION 2nv (prim 0: 0..nv-1, prim 1: nv..2nv-1), JOINTS_0 u8 x4 2nv,
     * WEIGHTS_0 f32 x4 2nv, indices u32 (prim 0, prim 1), IBMs */
    off_pos = 0;
    off_jw = off_pos + 24 * nv;          /* joints: 4 bytes per vertex, 2nv */
    len = off_jw + 8 * nv + 32 * nv;     /* weights: 16 bytes per vertex */
    off_i0 = len;
    off_i1 = off_i0 + 12 * nt0;
    off_ibm = off_i1 + 12 * nt1;
    len = off_ibm + 64 * (size_t)d.nj;
    bin = calloc(len, 1);
    for (k = 0; k < 2 * nv; k++) {
        const double *p = m.v + 3 * (k % nv);
        int best = 0;
        double bd = HUGE_VAL;
        for (c = 0; c < 3; c++) putf(bin + off_pos + 12 * k + (size_t)c * 4, (float)p[c]);
        for (j = 0; j < d.nj; j++) {   /* weight 1 on the nearest joint */
            double dd = 0;
            for (c = 0; c < 3; c++) dd += (p[c] - d.joints[j].pos[c]) * (p[c] - d.joints[j].pos[c]);
            if (dd < bd) bd = dd, best = j;
        }
        bin[off_jw + 4 * k] = (unsigned char)best;
        putf(bin + off_jw + 8 * nv + 16 * k, 1.0f);
    }
    for (k = 0; k < nt0; k++)
        for (c = 0; c < 3; c++) put32(bin + off_i0 + 12 * k + 4 * (size_t)c, (unsigned)m.tri[3 * k + (size_t)c]);
    for (k = 0; k < nt1; k++)   /* prim 1's own vertices: the split copies */
        for (c = 0; c < 3; c++) put32(bin + off_i1 + 12 * k + 4 * (size_t)c, (unsigned)m.tri[3 * (nt0 + k) + (size_t)c]);
    for (j = 0; j < d.nj; j++) {
        unsigned char *q = bin + off_ibm + 64 * (size_t)j;
        for (c = 0; c < 16; c++) putf(q + 4 * c, c % 5 == 0 ? 1.0f : 0.0f);
        for (c = 0; c < 3; c++) putf(q + 48 + 4 * c, -(float)d.joints[j].pos[c]);
    }
    f = fopen(at("cow.bin"), "wb");
    fwrite(bin, 1, len, f);
    fclose(f);
    free(bin);
    /* nodes: 0 the mesh node (moved, rotated, scaled: ignored), 1 an armature root at the origin,
     * 2.. the joints, each translated from its parent (float differences of float positions) */
    {   /* animations: "test" (LINEAR rotation, STEP rotation, LINEAR root translation, an ignored scale)
         * and "spline" (CUBICSPLINE rotation and translation) */
        float t3[3] = {0, 30 * HQ / 65536.0f, 60 * HQ / 65536.0f}, ts[3] = {0, 20 * HQ / 65536.0f, 40 * HQ / 65536.0f};
        float t2[2] = {0, 40 * HQ / 65536.0f}, q[12], tr[6], sc[9] = {1, 1, 1, 1.5f, 1, 1, 1, 1, 1}, cq[24], ct[18];
        int hips = -1, neck = -1, hip_l = -1, chest = -1, a[16], k;
        for (j = 0; j < d.nj; j++) {
            if (!strcmp(d.joints[j].name, "hips")) hips = j;
            if (!strcmp(d.joints[j].name, "neck")) neck = j;
            if (!strcmp(d.joints[j].name, "hip_l")) hip_l = j;
            if (!strcmp(d.joints[j].name, "chest")) chest = j;
        }
        acc_json[0] = 0, nanim = 0, nacc_extra = 0;
        a[0] = anim_acc(t3, 3, 1, "SCALAR", 1);
        quat_axis(q, 2, 0), quat_axis(q + 4, 2, 30), quat_axis(q + 8, 2, -30);
        a[1] = anim_acc(q, 3, 4, "VEC4", 0);
        a[2] = anim_acc(ts, 3, 1, "SCALAR", 1);
        quat_axis(q, 0, 10), quat_axis(q + 4, 0, -15), quat_axis(q + 8, 0, 5);
        a[3] = anim_acc(q, 3, 4, "VEC4", 0);
        a[4] = anim_acc(t2, 2, 1, "SCALAR", 1);
        for (c = 0; c < 3; c++) tr[c] = (float)d.joints[hips].pos[c], tr[3 + c] = (float)((double)(float)d.joints[hips].pos[c] + (c == 0 ? 0.625 : 0));
        a[5] = anim_acc(tr, 2, 3, "VEC3", 0);
        a[6] = anim_acc(sc, 3, 3, "VEC3", 0);
        /* spline: keys at 0 and 30 steps; (in-tangent, value, out-tangent) per key */
        memset(cq, 0, sizeof cq);
        quat_axis(cq + 4, 2, 0), quat_axis(cq + 16, 2, 30);
        cq[8 + 2] = 0.5f, cq[12 + 0] = 0.25f;   /* out-tangent of key 0 (z), in-tangent of key 1 (x) */
        a[7] = anim_acc(t3, 2, 1, "SCALAR", 1);
        a[8] = anim_acc(cq, 6, 4, "VEC4", 0);
        memset(ct, 0, sizeof ct);
        for (c = 0; c < 3; c++) ct[3 + c] = (float)d.joints[hips].pos[c], ct[12 + c] = (float)d.joints[hips].pos[c];
        ct[12 + 1] += 0.5f, ct[6 + 1] = 2.0f;   /* rise 0.5 with out-tangent 2 per second */
        a[9] = anim_acc(ct, 6, 3, "VEC3", 0);
        f = fopen(at("anim.bin"), "wb");
        fwrite(anim, 4, (size_t)nanim, f);
        fclose(f);
        k = sprintf(anim_json, ",\n\"animations\":[{\"name\":\"test\",\"channels\":["
                               "{\"sampler\":0,\"target\":{\"node\":%d,\"path\":\"rotation\"}},{\"sampler\":1,\"target\":{\"node\":%d,\"path\":\"rotation\"}},"
                               "{\"sampler\":2,\"target\":{\"node\":%d,\"path\":\"translation\"}},{\"sampler\":3,\"target\":{\"node\":%d,\"path\":\"scale\"}}],"
                               "\"samplers\":[{\"input\":%d,\"output\":%d},{\"input\":%d,\"output\":%d,\"interpolation\":\"STEP\"},"
                               "{\"input\":%d,\"output\":%d,\"interpolation\":\"LINEAR\"},{\"input\":%d,\"output\":%d}]},\n",
                    2 + neck, 2 + hip_l, 2 + hips, 2 + chest, a[0], a[1], a[2], a[3], a[4], a[5], a[2], a[6]);
        sprintf(anim_json + k, " {\"name\":\"spline\",\"channels\":[{\"sampler\":0,\"target\":{\"node\":%d,\"path\":\"rotation\"}},"
                               "{\"sampler\":1,\"target\":{\"node\":%d,\"path\":\"translation\"}}],"
                               "\"samplers\":[{\"input\":%d,\"output\":%d,\"interpolation\":\"CUBICSPLINE\"},{\"input\":%d,\"output\":%d,\"interpolation\":\"CUBICSPLINE\"}]}]",
                2 + neck, 2 + hips, a[7], a[8], a[7], a[9]);
        /* the hand-written equivalent of "test": one key per step, from the same definitions */
        f = fopen(at("hand.clip"), "w");
        fprintf(f, "sinew-clip 1\n# hand-written twin of cow.gltf's animation \"test\" (test_bake_gltf_cow.c)\nduration %.9f\nloop yes\n", 60 * HQ / 65536.0);
        for (k = 0; k <= 60; k++) fprintf(f, "rot neck %.9f 0 0 1 %g\n", k * HQ / 65536.0, neck_deg(k));
        for (k = 0; k <= 60; k++) fprintf(f, "rot hip_l %.9f 1 0 0 %g\n", k * HQ / 65536.0, hip_deg(k));
        for (k = 0; k <= 60; k++) fprintf(f, "move %.9f %.9f 0 0\n", k * HQ / 65536.0, move_x(k));
        fclose(f);
    }
    f = fopen(at("cow.gltf"), "w");
    fprintf(f, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"test_bake_gltf_cow\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],\n\"nodes\":[\n");
    fprintf(f, " {\"name\":\"cow\",\"mesh\":0,\"skin\":0,\"translation\":[7,-3,2],\"rotation\":[0,0.6,0,0.8],\"scale\":[2,2,2]},\n");
    fprintf(f, " {\"name\":\"armature\",\"children\":[");
    for (j = 0, c = 0; j < d.nj; j++)
        if (!strcmp(d.joints[j].parent_name, "-")) fprintf(f, "%s%d", c++ ? "," : "", 2 + j);
    fprintf(f, "]}");
    for (j = 0; j < d.nj; j++) {
        int p = -1, n = 0;
        for (i = 0; i < d.nj; i++) if (!strcmp(d.joints[i].name, d.joints[j].parent_name)) p = i;
        /* node translations: the exact world position comes from the IBMs anyway */
        fprintf(f, ",\n {\"name\":\"%s\",\"translation\":[%.9g,%.9g,%.9g]", d.joints[j].name,
                (double)((float)d.joints[j].pos[0] - (p >= 0 ? (float)d.joints[p].pos[0] : 0.0f)),
                (double)((float)d.joints[j].pos[1] - (p >= 0 ? (float)d.joints[p].pos[1] : 0.0f)),
                (double)((float)d.joints[j].pos[2] - (p >= 0 ? (float)d.joints[p].pos[2] : 0.0f)));
        for (i = 0; i < d.nj; i++)
            if (!strcmp(d.joints[i].parent_name, d.joints[j].name)) fprintf(f, "%s%d", n++ ? "," : ",\"children\":[", 2 + i);
        fprintf(f, "%s}", n ? "]" : "");
    }
    fprintf(f, "],\n\"skins\":[{\"inverseBindMatrices\":6,\"joints\":[");
    for (j = 0; j < d.nj; j++) fprintf(f, "%s%d", j ? "," : "", 2 + j);
    fprintf(f, "]}],\n\"meshes\":[{\"name\":\"cow\",\"primitives\":[");
    fprintf(f, "{\"attributes\":{\"POSITION\":0,\"JOINTS_0\":2,\"WEIGHTS_0\":4},\"indices\":7},");
    fprintf(f, "{\"attributes\":{\"POSITION\":1,\"JOINTS_0\":3,\"WEIGHTS_0\":5},\"indices\":8}]}],\n");
    {
        double lo[3], hi[3];
        for (c = 0; c < 3; c++) lo[c] = (float)m.lo[c], hi[c] = (float)m.hi[c];
        fprintf(f, "\"accessors\":[");
        for (i = 0; i < 2; i++)
            fprintf(f, "{\"bufferView\":0,\"byteOffset\":%lu,\"componentType\":5126,\"count\":%lu,\"type\":\"VEC3\","
                       "\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},\n", (unsigned long)(12 * nv * (size_t)i), (unsigned long)nv,
                    lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
        for (i = 0; i < 2; i++)
            fprintf(f, "{\"bufferView\":1,\"byteOffset\":%lu,\"componentType\":5121,\"count\":%lu,\"type\":\"VEC4\"},\n",
                    (unsigned long)(4 * nv * (size_t)i), (unsigned long)nv);
        for (i = 0; i < 2; i++)
            fprintf(f, "{\"bufferView\":2,\"byteOffset\":%lu,\"componentType\":5126,\"count\":%lu,\"type\":\"VEC4\"},\n",
                    (unsigned long)(16 * nv * (size_t)i), (unsigned long)nv);
        fprintf(f, "{\"bufferView\":3,\"componentType\":5126,\"count\":%d,\"type\":\"MAT4\"},\n", d.nj);
        fprintf(f, "{\"bufferView\":4,\"componentType\":5125,\"count\":%lu,\"type\":\"SCALAR\"},\n", (unsigned long)(3 * nt0));
        fprintf(f, "{\"bufferView\":5,\"componentType\":5125,\"count\":%lu,\"type\":\"SCALAR\"}%s],\n", (unsigned long)(3 * nt1), acc_json);
    }
    fprintf(f, "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu},{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu},"
               "{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu},{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu},"
               "{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu},{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu}],\n",
            (unsigned long)off_pos, (unsigned long)(24 * nv), (unsigned long)off_jw, (unsigned long)(8 * nv),
            (unsigned long)(off_jw + 8 * nv), (unsigned long)(32 * nv), (unsigned long)off_ibm, (unsigned long)(64 * (size_t)d.nj),
            (unsigned long)off_i0, (unsigned long)(12 * nt0), (unsigned long)off_i1, (unsigned long)(12 * nt1));
    fseek(f, -3, SEEK_CUR);   /* reopen the bufferViews list: the animation data's view */
    fprintf(f, ",{\"buffer\":1,\"byteLength\":%d}],\n", 4 * nanim);
    fprintf(f, "\"buffers\":[{\"uri\":\"cow.bin\",\"byteLength\":%lu},{\"uri\":\"anim.bin\",\"byteLength\":%d}]%s}\n", (unsigned long)len,
            4 * nanim, anim_json);
    fclose(f);
    /* the same geometry as OBJ + joints, float-rounded, and the two descriptions */
    f = fopen(at("cow_f.obj"), "w");
    for (k = 0; k < nv; k++) fprintf(f, "v %.17g %.17g %.17g\n", (double)(float)m.v[3 * k], (double)(float)m.v[3 * k + 1], (double)(float)m.v[3 * k + 2]);
    for (k = 0; k < (size_t)m.nt; k++) fprintf(f, "f %d %d %d\n", m.tri[3 * k] + 1, m.tri[3 * k + 1] + 1, m.tri[3 * k + 2] + 1);
    fclose(f);
    {
        FILE *fo = fopen(at("cow_obj.sinew"), "w"), *fg = fopen(at("cow_gltf.sinew"), "w");
        int first = 1;
        fprintf(fo, "mesh cow_f.obj\n");
        for (j = 0; j < d.nj; j++)
            fprintf(fo, "joint %s %s %.17g %.17g %.17g\n", d.joints[j].name, d.joints[j].parent_name, (double)(float)d.joints[j].pos[0],
                    (double)(float)d.joints[j].pos[1], (double)(float)d.joints[j].pos[2]);
        fprintf(fg, "gltf cow.gltf\n");
        in = fopen("tools/examples/cow/cow.sinew", "r");
        while (fgets(line, sizeof line, in)) {
            char w[32] = "";
            sscanf(line, "%31s", w);
            if (!strcmp(w, "mesh") || !strcmp(w, "joint")) continue;
            fputs(line, fo), fputs(line, fg);
            first = 0;
        }
        (void)first;
        fclose(in), fclose(fo), fclose(fg);
    }
    sb_mesh_free(&m);
    sb_desc_free(&d);
    return 0;
}

static double rel_diff(const double *a, const double *b, size_t n)
{
    double mx = 0, d = 0;
    size_t k;
    for (k = 0; k < n; k++) mx = fmax(mx, fabs(a[k])), d = fmax(d, fabs(a[k] - b[k]));
    return mx > 0 ? d / mx : d;
}

static void compare(const char *what, int flavour, double *t_gltf, double *t_obj)
{
    sb_model og, oo;
    sb_blob bg, bo;
    double t;
    int rg, ro;
    t = sb_now();
    rg = sb_bake_file(at("cow_gltf.sinew"), flavour, 1, &og, &bg);
    *t_gltf = sb_now() - t;
    T_CHECK(rg == 0, "%s: glTF bake: %s", what, rg ? sb_error() : "");
    t = sb_now();
    ro = sb_bake_file(at("cow_obj.sinew"), flavour, 1, &oo, &bo);
    *t_obj = sb_now() - t;
    T_CHECK(ro == 0, "%s: OBJ bake: %s", what, ro ? sb_error() : "");
    if (rg || ro) return;
    T_CHECK(og.nv == oo.nv && og.nc == oo.nc && og.ns == oo.ns && og.nt == oo.nt, "%s: sizes", what);
    if (og.nv == oo.nv && og.nbptr[og.nv] == oo.nbptr[oo.nv]) {
        size_t ne = (size_t)og.nbptr[og.nv];
        double dS = rel_diff(oo.S, og.S, 9 * ne), dM = rel_diff(oo.M, og.M, ne), dx = rel_diff(oo.x, og.x, 3 * (size_t)og.nv);
        T_CHECK(dS <= 1e-9 && dM <= 1e-9 && dx <= 1e-9, "%s: S %.3g M %.3g rest %.3g relative", what, dS, dM, dx);
        T_FIGURE("%s: glTF vs OBJ + joints: S differs by %.3g, M by %.3g, rest positions by %.3g (relative)", what, dS, dM, dx);
    }
    T_CHECK(bg.size == bo.size && !memcmp(bg.bytes, bo.bytes, bg.size), "%s: blobs differ (%lu vs %lu bytes)", what,
            (unsigned long)bg.size, (unsigned long)bo.size);
    if (flavour == SB_FIXED) {   /* the map: prim 0 = the OBJ order, prim 1's copies welded onto it */
        int k, bad = 0, nv = og.ns;
        T_CHECK(og.src.nsrc == 2 * nv && og.src.nsurf == nv && og.src.nprim == 2 && og.src.dropped == 0 && oo.src.nsrc == 0,
                "map counts: %d %d %d %d", og.src.nsrc, og.src.nsurf, og.src.nprim, og.src.dropped);
        for (k = 0; k < og.src.nsrc && og.src.nsrc == 2 * nv; k++)
            bad += og.src.to_surf[k] != k % nv || og.src.prim[k] != k / nv || og.src.vert[k] != k % nv;
        T_CHECK(bad == 0, "map: %d vertices mapped wrong", bad);
        T_CHECK(sb_srcmap_write(at("cow.blob.gltfmap"), &og.src) == 0, "map write: %s", sb_error());
    }
    sb_blob_free(&bg), sb_blob_free(&bo);
    sb_model_free(&og), sb_model_free(&oo);
}

/* descriptions that mix 'gltf' with 'mesh' / 'joint', or name unknown joints */
static void refusals(void)
{
    static const char *const cases[][2] = {
        {"gltf cow.gltf\njoint x - 0 0 0\n", "the joints come from the glTF skin"},
        {"joint x - 0 0 0\ngltf cow.gltf\n", "no 'joint' lines before it"},
        {"gltf cow.gltf\nmesh cow_f.obj\n", "'mesh' after 'gltf'"},
        {"gltf cow.gltf nosuchmesh\n", "no skinned mesh named \"nosuchmesh\""},
        {"gltf missing.gltf\n", "missing.gltf"},
        {"gltf cow.gltf\nunit 0.2\ncell 1.2\nmaterial flesh 5e4 0.3 1000\nregion bone elbow flesh\n", "unknown joint 'elbow'"},
        {"gltf cow.gltf\nunit 0.2\ncell 1.2\nmaterial flesh 5e4 0.3 1000\nregion bone hips flesh\n", "'hips' is the root"},
        {"frames skin\ngltf cow.gltf\n", "'frames skin' takes the frames from a glTF's skin weights: put it after a 'gltf' line"},
        {"gltf cow.gltf\nframes artist\n", "'frames' takes 'skin' or 'auto'"},
    };
    size_t k;
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        sb_desc d;
        FILE *f = fopen(at("bad.sinew"), "w");
        int rc;
        fputs(cases[k][0], f);
        fclose(f);
        rc = sb_desc_load(at("bad.sinew"), &d);
        T_CHECK(rc == -1 && strstr(sb_error(), cases[k][1]), "refusal %lu: rc %d \"%s\", want \"%s\"", (unsigned long)k, rc,
                rc ? sb_error() : "", cases[k][1]);
        sb_desc_free(&d);
    }
}

/* the animation sampler (tools/sb_gltf_anim.c) on cow.gltf's "test" and
 * "spline", against the definitions they were written from */
static double qang_about(const double *q, int axis)   /* signed angle (degrees) of q about a coordinate axis */
{
    return 2 * atan2(q[axis], q[3]) * 180 / 3.14159265358979323846;
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    long n;
    char *s;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END), n = ftell(f), fseek(f, 0, SEEK_SET);
    s = calloc((size_t)n + 1, 1);
    if (fread(s, 1, (size_t)n, f) != (size_t)n) n = 0;
    fclose(f);
    return s;
}

static void anim_checks(void)
{
    sb_gltf g;
    sb_gltf_anim a;
    int k, neck = -1, hip_l = -1, hips = -1, bad = 0, rc;
    double h = HQ / 65536.0;
    if (sb_gltf_load(&g, at("cow.gltf"), NULL)) { T_CHECK(0, "cow.gltf: %s", sb_error()); return; }
    for (k = 0; k < g.nj; k++) {
        if (!strcmp(g.joints[k].name, "neck")) neck = k;
        if (!strcmp(g.joints[k].name, "hip_l")) hip_l = k;
        if (!strcmp(g.joints[k].name, "hips")) hips = k;
    }
    rc = sb_gltf_anim_load(&a, at("cow.gltf"), &g, "test", h, 1000);
    T_CHECK(rc == 0, "test: %s", rc ? sb_error() : "");
    if (rc == 0) {
        double worst_r = 0, worst_t = 0;
        T_CHECK(a.nframes == 61 && a.n_channels == 4 && a.n_scale == 1 && a.animated[neck] && a.animated[hip_l] && a.animated[hips],
                "test: %d frames, %d channels, %d scale", a.nframes, a.n_channels, a.n_scale);
        for (k = 0; k < a.nframes && a.nframes == 61; k++) {
            const double *qn = a.rot + ((size_t)k * a.nj + neck) * 4, *qh = a.rot + ((size_t)k * a.nj + hip_l) * 4;
            worst_r = fmax(worst_r, fabs(qang_about(qn, 2) - neck_deg(k)));
            worst_r = fmax(worst_r, fabs(qang_about(qh, 0) - hip_deg(k)));
            bad += fabs(qn[0]) + fabs(qn[1]) > 1e-12 || fabs(qh[1]) + fabs(qh[2]) > 1e-12;
            worst_t = fmax(worst_t, fabs(a.move[3 * k] - move_x(k)) + fabs(a.move[3 * k + 1]) + fabs(a.move[3 * k + 2]));
        }
        /* float32 keys: ~4e-6 degrees, ~2e-7 units; a clip resolves 1.5e-5 */
        T_CHECK(bad == 0 && worst_r < 5e-6 && worst_t < 5e-7, "test: rotation off by %.3g degrees, translation by %.3g, %d off-axis",
                worst_r, worst_t, bad);
        T_FIGURE("sampled 'test' (LINEAR, STEP rotations, LINEAR translation) vs its definition: %.2g degrees, %.2g units", worst_r, worst_t);
        sb_gltf_anim_free(&a);
    }
    rc = sb_gltf_anim_load(&a, at("cow.gltf"), &g, "spline", h, 1000);
    T_CHECK(rc == 0, "spline: %s", rc ? sb_error() : "");
    if (rc == 0) {   /* frame 15: halfway between the keys (0 and 30 steps): Hermite by hand */
        double dt = (double)(30 * HQ / 65536.0f), u = 15 * h / dt, u2 = u * u, u3 = u2 * u;
        double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2, q[4], n, d = 0, ty;
        float v1z = (float)sin(15 * 3.14159265358979323846 / 180), v1w = (float)cos(15 * 3.14159265358979323846 / 180);
        const double *got = a.rot + ((size_t)15 * a.nj + neck) * 4;
        q[0] = h11 * dt * 0.25, q[1] = 0, q[2] = h10 * dt * 0.5 + h01 * v1z, q[3] = h00 + h01 * v1w;
        n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        for (k = 0; k < 4; k++) d = fmax(d, fabs(q[k] / n - got[k]));
        ty = h10 * dt * 2.0 + h01 * 0.5;   /* the root's rise above its bind position */
        T_CHECK(d < 1e-12 && fabs(a.move[3 * 15 + 1] - ty) < 1e-6, "spline at frame 15: quaternion off by %.3g, rise %.9g want %.9g", d,
                a.move[3 * 15 + 1], ty);
        sb_gltf_anim_free(&a);
    }
    {   /* refusals, each naming its JSON path */
        static const char *const cases[][4] = {
            {"unknown name", NULL, NULL, "animations: none named \"nosuch\""},
            {"bad interpolation", "\"interpolation\":\"STEP\"", "\"interpolation\":\"SMOOTH\"", "animations[0].samplers[1].interpolation: \"SMOOTH\""},
            {"cubic count", "\"interpolation\":\"STEP\"", "\"interpolation\":\"CUBICSPLINE\"", "animations[0].samplers[1].output: accessors[12] must be VEC4 with 9"},
            {"rotation from vec3", "\"path\":\"scale\"", "\"path\":\"rotation\"", "animations[0].samplers[3].output"},
            {"no animations", "\"animations\":[", "\"unused\":[", "animations: the file has none"},
            {"bad target node", "\"node\":4,\"path\":\"rotation\"}},{\"sampler\":1", "\"node\":999,\"path\":\"rotation\"}},{\"sampler\":1",
             "animations[0].channels[0].target.node"},
        };
        char *text = slurp(at("cow.gltf"));
        size_t c;
        for (c = 0; text && c < sizeof cases / sizeof cases[0]; c++) {
            char *t2 = text, *hit;
            FILE *f;
            if (cases[c][1]) {
                hit = strstr(text, cases[c][1]);
                if (!hit) { T_CHECK(0, "%s: '%s' not in cow.gltf", cases[c][0], cases[c][1]); continue; }
                t2 = malloc(strlen(text) + strlen(cases[c][2]) + 1);
                memcpy(t2, text, (size_t)(hit - text));
                strcpy(t2 + (hit - text), cases[c][2]);
                strcat(t2, hit + strlen(cases[c][1]));
            }
            f = fopen(at("bad_anim.gltf"), "w");
            fputs(t2, f);
            fclose(f);
            rc = sb_gltf_anim_load(&a, at("bad_anim.gltf"), &g, cases[c][1] ? NULL : "nosuch", h, 1000);
            T_CHECK(rc == -1 && strstr(sb_error(), cases[c][3]) && a.rot == NULL, "%s: rc %d \"%s\", want \"%s\"", cases[c][0], rc,
                    rc ? sb_error() : "", cases[c][3]);
            sb_gltf_anim_free(&a);
            if (t2 != text) free(t2);
        }
        free(text);
    }
    sb_gltf_free(&g);
}

/* --read FILE: our reader on a file (tests/scripts/test_gltf.sh re-reads
 * sinew-play --out-gltf results): "read: NV NT NJ lo.. hi.." of POSITION */
static int read_mode(const char *path)
{
    sb_gltf g;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    int v, c;
    if (sb_gltf_load(&g, path, NULL)) { printf("read: error: %s\n", sb_error()); return 1; }
    for (v = 0; v < g.nv; v++)
        for (c = 0; c < 3; c++) lo[c] = fmin(lo[c], g.pos[3 * v + c]), hi[c] = fmax(hi[c], g.pos[3 * v + c]);
    printf("read: %d %d %d %.9g %.9g %.9g %.9g %.9g %.9g\n", g.nv, g.nt, g.nj, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    sb_gltf_free(&g);
    return 0;
}

int main(int argc, char **argv)
{
    const char *base = getenv("BUILD") ? getenv("BUILD") : "build";
    char cmd[700];
    double tg, to, tg2, to2;
    (void)t_seed;
    if (argc == 3 && !strcmp(argv[1], "--read")) return read_mode(argv[2]);
    snprintf(tmp, sizeof tmp, "%s/test_bake_gltf_cow.d", base);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", tmp);
    if (system(cmd)) { printf("cannot create %s\n", tmp); return 1; }
    if (write_cow()) return T_END();
    {   /* the joints as declared: names, parents, positions from the IBMs */
        sb_desc dg, dc;
        int rc = sb_desc_load(at("cow_gltf.sinew"), &dg), j, bad = 0;
        T_CHECK(rc == 0, "glTF description: %s", rc ? sb_error() : "");
        if (rc == 0 && sb_desc_load("tools/examples/cow/cow.sinew", &dc) == 0) {
            T_CHECK(dg.nj == dc.nj, "joints %d vs %d", dg.nj, dc.nj);
            for (j = 0; j < dg.nj && dg.nj == dc.nj; j++) {
                int c;
                bad += strcmp(dg.joints[j].name, dc.joints[j].name) != 0 || strcmp(dg.joints[j].parent_name, dc.joints[j].parent_name) != 0 ||
                       dg.joints[j].parent != dc.joints[j].parent;
                for (c = 0; c < 3; c++) bad += dg.joints[j].pos[c] != (double)(float)dc.joints[j].pos[c];
            }
            T_CHECK(bad == 0, "joints from the glTF skin: %d differences", bad);
            sb_desc_free(&dc);
        }
        sb_desc_free(&dg);
    }
    compare("fixed", SB_FIXED, &tg, &to);
    compare("double", SB_DOUBLE, &tg2, &to2);
    T_FIGURE("bake time (fixed): from glTF %.2f s, from OBJ + joints %.2f s; (double) %.2f s vs %.2f s", tg, to, tg2, to2);
    refusals();
    anim_checks();
    return T_END();
}
