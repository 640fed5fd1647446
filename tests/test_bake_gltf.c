/* test_bake_gltf.c -- the glTF 2.0 reader (tools/sb_gltf*.c, sb_json.c).
 * The test writes a two-bone skinned strip as .gltf + .bin, as .gltf with a
 * base64 data URI and as .glb, reads each back and checks every value
 * against what it wrote; then a list of broken files, each refused with the
 * JSON path (or GLB field) in the message and an empty result. */
#include "sb.h"
#include "sb_gltf.h"
#include "sb_json.h"
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

static int write_bytes(const char *path, const void *b, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    fwrite(b, 1, n, f);
    return fclose(f);
}

/* ---- the strip: 6 vertices in 3 rows, 4 triangles, bones 0 and 1 ---- */
static const float P[6][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 2, 0}, {1, 2.5f, 0.25f}};
static const unsigned short IDX[12] = {0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4};
static const unsigned char JNT[6][4] = {{0, 1, 0, 0}, {0, 1, 0, 0}, {0, 1, 0, 0}, {0, 1, 0, 0}, {0, 1, 0, 0}, {1, 0, 0, 0}};
/* row 1 vertex 3 sums to 0.5 (the reader normalises); vertex 4 has weight
 * only on its second slot */
static const float WGT[6][4] = {{1, 0, 0, 0}, {1, 0, 0, 0}, {0.5f, 0.5f, 0, 0}, {0.25f, 0.25f, 0, 0}, {0, 1, 0, 0}, {1, 0, 0, 0}};
/* world joint positions from the hierarchy (worked out by hand below) and
 * the IBM-implied ones, shifted on purpose so the two sources differ */
static const double JW[2][3] = {{-1, 0, 1}, {-3, 0, 1}};
static const double IBM_SHIFT[3] = {0.125, 0.25, -0.5};
static const double MESH_T[3] = {0.5, 0, 0};

/* buffer: positions (stride 16) 0..96, joints 96..120, weights 120..216,
 * indices 216..240, IBMs 240..368 */
#define BIN_LEN 368
static unsigned char bin[BIN_LEN];

static void put32(unsigned char *p, unsigned v)
{
    p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8), p[2] = (unsigned char)(v >> 16), p[3] = (unsigned char)(v >> 24);
}
static void putf(unsigned char *p, float f)
{
    unsigned u;
    memcpy(&u, &f, 4);
    put32(p, u);
}

static void make_bin(void)
{
    int v, k, j;
    memset(bin, 0, sizeof bin);
    for (v = 0; v < 6; v++) {
        for (k = 0; k < 3; k++) putf(bin + 16 * v + 4 * k, P[v][k]);
        putf(bin + 16 * v + 12, 99.0f);   /* padding the stride must skip */
        for (k = 0; k < 4; k++) bin[96 + 4 * v + k] = JNT[v][k];
        for (k = 0; k < 4; k++) putf(bin + 120 + 16 * v + 4 * k, WGT[v][k]);
    }
    for (k = 0; k < 12; k++) bin[216 + 2 * k] = (unsigned char)IDX[k], bin[217 + 2 * k] = (unsigned char)(IDX[k] >> 8);
    /* IBM j: translation by -(JW[j] + IBM_SHIFT - MESH_T), so that
     * inverse(IBM) * origin = JW[j] + IBM_SHIFT - MESH_T: the mesh node's
     * translation MESH_T is ignored (glTF 2.0, 3.7.3.3: a skinned mesh is
     * placed by its joints only), so it does not come back */
    for (j = 0; j < 2; j++) {
        unsigned char *m = bin + 240 + 64 * j;
        for (k = 0; k < 16; k++) putf(m + 4 * k, k % 5 == 0 ? 1.0f : 0.0f);
        for (k = 0; k < 3; k++) putf(m + 48 + 4 * k, (float)-(JW[j][k] + IBM_SHIFT[k] - MESH_T[k]));
    }
}

/* The JSON, one top-level member per line. Armature node 1: translation
 * (0,0,1), 90 degrees about z, scale 2; bone0 (node 2) at (0,0.5,0) in it:
 * world (-1,0,1); bone1 (node 3) at (0,1,0) in bone0: world (-3,0,1).
 * matrices=1 writes the same transforms as matrices. */
static char *make_json(const char *buffer, int matrices, int ibm)
{
    static char j[8192];
    const char *arm = matrices ? "\"matrix\":[0,2,0,0, -2,0,0,0, 0,0,2,0, 0,0,1,1]"
                               : "\"translation\":[0,0,1],\"rotation\":[0,0,0.70710678118654752,0.70710678118654752],\"scale\":[2,2,2]";
    const char *b0 = matrices ? "\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,0,0,0.5,0,1]" : "\"translation\":[0,0.5,0]";
    const char *b1 = matrices ? "\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,0,0,1,0,1]" : "\"translation\":[0,1,0]";
    snprintf(j, sizeof j,
             "{\n"
             "\"asset\":{\"version\":\"2.0\",\"generator\":\"test_bake_gltf \\u00e9\\ud83d\\ude00\"},\n"
             "\"scene\":0,\n"
             "\"scenes\":[{\"nodes\":[0,1,4,5]}],\n"
             "\"nodes\":[{\"name\":\"body\",\"mesh\":0,\"skin\":0,\"translation\":[0.5,0,0]},\n"
             "  {\"name\":\"armature\",%s,\"children\":[2]},\n"
             "  {\"name\":\"bone0\",%s,\"children\":[3]},\n"
             "  {\"name\":\"bone1\",%s},\n"
             "  {\"name\":\"body2\",\"mesh\":1,\"skin\":0,\"translation\":[0,0,5]},\n"
             "  {\"name\":\"body3\",\"mesh\":2,\"skin\":0}],\n"
             "\"skins\":[{\"joints\":[2,3]%s}],\n"
             "\"meshes\":[{\"name\":\"strip\",\"primitives\":[{\"attributes\":{\"POSITION\":0,\"JOINTS_0\":1,\"WEIGHTS_0\":2},\"indices\":3,\"mode\":4}]},\n"
             "  {\"name\":\"strip2\",\"primitives\":[{\"attributes\":{\"POSITION\":0,\"JOINTS_0\":1,\"WEIGHTS_0\":2},\"indices\":3}]},\n"
             "  {\"name\":\"types\",\"primitives\":[{\"attributes\":{\"POSITION\":0,\"JOINTS_0\":5,\"WEIGHTS_0\":6},\"indices\":7},\n"
             "    {\"attributes\":{\"POSITION\":0,\"JOINTS_0\":1,\"WEIGHTS_0\":9},\"indices\":8},\n"
             "    {\"attributes\":{\"POSITION\":0,\"JOINTS_0\":5,\"WEIGHTS_0\":6}}]}],\n"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"},\n"
             "  {\"bufferView\":1,\"componentType\":5121,\"count\":6,\"type\":\"VEC4\"},\n"
             "  {\"bufferView\":2,\"componentType\":5126,\"count\":6,\"type\":\"VEC4\"},\n"
             "  {\"bufferView\":3,\"componentType\":5123,\"count\":12,\"type\":\"SCALAR\"},\n"
             "  {\"bufferView\":4,\"componentType\":5126,\"count\":2,\"type\":\"MAT4\"},\n"
             "  {\"bufferView\":5,\"componentType\":5123,\"count\":6,\"type\":\"VEC4\"},\n"
             "  {\"bufferView\":6,\"componentType\":5121,\"normalized\":true,\"count\":6,\"type\":\"VEC4\"},\n"
             "  {\"bufferView\":7,\"componentType\":5125,\"count\":12,\"type\":\"SCALAR\"},\n"
             "  {\"bufferView\":8,\"componentType\":5121,\"count\":12,\"type\":\"SCALAR\"},\n"
             "  {\"bufferView\":9,\"componentType\":5123,\"normalized\":true,\"count\":6,\"type\":\"VEC4\"}],\n"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":96,\"byteStride\":16},\n"
             "  {\"buffer\":0,\"byteOffset\":96,\"byteLength\":24},\n"
             "  {\"buffer\":0,\"byteOffset\":120,\"byteLength\":96},\n"
             "  {\"buffer\":0,\"byteOffset\":216,\"byteLength\":24},\n"
             "  {\"buffer\":0,\"byteOffset\":240,\"byteLength\":128},\n"
             "  {\"buffer\":1,\"byteLength\":48},\n"
             "  {\"buffer\":1,\"byteOffset\":48,\"byteLength\":24},\n"
             "  {\"buffer\":1,\"byteOffset\":72,\"byteLength\":48},\n"
             "  {\"buffer\":1,\"byteOffset\":120,\"byteLength\":12},\n"
             "  {\"buffer\":1,\"byteOffset\":132,\"byteLength\":48}],\n"
             "\"buffers\":[%s,{\"uri\":\"types.bin\",\"byteLength\":180}]\n"
             "}\n",
             arm, b0, b1, ibm ? ",\"inverseBindMatrices\":4" : "", buffer);
    return j;
}

static char *b64(const unsigned char *b, size_t n)
{
    static const char *al = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char *o = malloc((n + 2) / 3 * 4 + 1), *p = o;
    size_t i;
    for (i = 0; i < n; i += 3) {
        unsigned v = (unsigned)b[i] << 16 | (i + 1 < n ? (unsigned)b[i + 1] << 8 : 0) | (i + 2 < n ? b[i + 2] : 0);
        *p++ = al[v >> 18 & 63], *p++ = al[v >> 12 & 63];
        *p++ = i + 1 < n ? al[v >> 6 & 63] : '=';
        *p++ = i + 2 < n ? al[v & 63] : '=';
    }
    *p = 0;
    return o;
}

/* buffer 1 (types.bin): JOINTS_0 as unsigned short 0..48, WEIGHTS_0 as
 * normalized unsigned byte 48..72, indices as unsigned int 72..120 and as
 * unsigned byte 120..132, WEIGHTS_0 as normalized unsigned short 132..180 */
static const unsigned char WB[6][4] = {{255, 0, 0, 0}, {200, 55, 0, 0}, {128, 127, 0, 0}, {1, 2, 0, 0}, {0, 255, 0, 0}, {0, 0, 0, 9}};
static const unsigned short WS[6][4] = {{65535, 0, 0, 0}, {1, 65534, 0, 0}, {300, 300, 0, 0}, {0, 7, 0, 0}, {0, 65535, 0, 0}, {65535, 0, 0, 0}};
static unsigned char tbin[180];

static void make_types_bin(void)
{
    int v, k;
    for (v = 0; v < 6; v++)
        for (k = 0; k < 4; k++) {
            tbin[8 * v + 2 * k] = JNT[v][k], tbin[8 * v + 2 * k + 1] = 0;
            tbin[48 + 4 * v + k] = WB[v][k];
            tbin[132 + 8 * v + 2 * k] = (unsigned char)WS[v][k], tbin[133 + 8 * v + 2 * k] = (unsigned char)(WS[v][k] >> 8);
        }
    tbin[8 * 5 + 2 * 3] = 1;   /* vertex 5: joint 1 in slot 3 (weight 9/255 there) */
    for (k = 0; k < 12; k++) {
        put32(tbin + 72 + 4 * k, IDX[k]);
        tbin[120 + k] = (unsigned char)IDX[11 - k];
    }
}

/* mesh "types": primitive 0 (ushort joints, ubyte weights, uint indices),
 * 1 (ubyte joints, ushort weights, ubyte indices reversed), 2 (no indices) */
static void check_types(const sb_gltf *g)
{
    int v, k, p, bad = 0;
    T_CHECK(g->nv == 18 && g->nt == 10 && g->nj == 2, "types: nv %d nt %d nj %d", g->nv, g->nt, g->nj);
    if (g->nv != 18 || g->nt != 10) return;
    for (p = 0; p < 3; p++)
        for (v = 0; v < 6; v++) {
            int o = 6 * p + v;
            double w[4], sum = 0;
            for (k = 0; k < 4; k++) w[k] = p == 1 ? WS[v][k] / 65535.0 : WB[v][k] / 255.0, sum += w[k];
            for (k = 0; k < 3; k++) bad += g->pos[3 * o + k] != (double)P[v][k];
            bad += g->src_prim[o] != p || g->src_vert[o] != v;
            for (k = 0; k < 4; k++) {
                int jw = p != 1 && v == 5 && k == 3 ? 1 : JNT[v][k];
                bad += fabs(g->weight[4 * o + k] - w[k] / sum) > 1e-15;
                bad += g->joint[4 * o + k] != (w[k] > 0 ? jw : 0);
            }
        }
    T_CHECK(bad == 0, "types: %d vertex values differ", bad);
    for (k = 0, bad = 0; k < 12; k++) bad += g->tri[k] != IDX[k] || g->tri[12 + k] != 6 + IDX[11 - k];
    for (k = 0; k < 6; k++) bad += g->tri[24 + k] != 12 + k;
    T_CHECK(bad == 0, "types: triangle indices differ");
}

/* a GLB of json + bin into buf; returns its length */
static size_t make_glb(unsigned char *buf, const char *json)
{
    size_t jl = strlen(json), jp = (jl + 3) / 4 * 4, bp = (BIN_LEN + 3) / 4 * 4, n = 12 + 8 + jp + 8 + bp;
    memcpy(buf, "glTF", 4);
    put32(buf + 4, 2);
    put32(buf + 8, (unsigned)n);
    put32(buf + 12, (unsigned)jp);
    memcpy(buf + 16, "JSON", 4);
    memset(buf + 20, ' ', jp);
    memcpy(buf + 20, json, jl);
    put32(buf + 20 + jp, (unsigned)bp);
    memcpy(buf + 24 + jp, "BIN", 4);
    buf[27 + jp] = 0;
    memset(buf + 28 + jp, 0, bp);
    memcpy(buf + 28 + jp, bin, BIN_LEN);
    return n;
}

/* replace the first `from` in s by `to` (a new string); the test fails if absent */
static char *subst(const char *s, const char *from, const char *to)
{
    const char *f = strstr(s, from);
    char *o;
    if (!f) {
        T_CHECK(0, "subst: \"%s\" not in the text", from);
        f = s + strlen(s), from = "";
    }
    o = malloc(strlen(s) + strlen(to) + 1);
    memcpy(o, s, (size_t)(f - s));
    strcpy(o + (f - s), to);
    strcat(o, f + strlen(from));
    return o;
}

/* check every decoded value against what was written */
static void check_strip(const char *what, const sb_gltf *g, const double *T, int ibm)
{
    int v, k, j, bad = 0;
    double tol = 1e-12;   /* the quaternion's sqrt(1/2) rounding, not the data */
    (void)T;   /* the mesh node's translation: ignored by a skinned mesh (glTF 2.0, 3.7.3.3) */
    T_CHECK(g->nv == 6 && g->nt == 4 && g->nj == 2, "%s: nv %d nt %d nj %d", what, g->nv, g->nt, g->nj);
    if (g->nv != 6 || g->nt != 4 || g->nj != 2) return;
    for (v = 0; v < 6; v++) {
        double sum = WGT[v][0] + WGT[v][1] + WGT[v][2] + WGT[v][3];
        for (k = 0; k < 3; k++) bad += g->pos[3 * v + k] != (double)P[v][k];   /* the mesh node's T ignored */
        bad += g->src_prim[v] != 0 || g->src_vert[v] != v;
        for (k = 0; k < 4; k++) {
            bad += fabs(g->weight[4 * v + k] - WGT[v][k] / sum) > 1e-15;
            bad += g->joint[4 * v + k] != (WGT[v][k] > 0 ? JNT[v][k] : 0);
        }
    }
    T_CHECK(bad == 0, "%s: %d vertex values differ from the written ones", what, bad);
    for (k = 0, bad = 0; k < 12; k++) bad += g->tri[k] != IDX[k];
    T_CHECK(bad == 0, "%s: triangle indices differ", what);
    T_CHECK(!strcmp(g->joints[0].name, "bone0") && !strcmp(g->joints[1].name, "bone1"), "%s: joint names", what);
    T_CHECK(g->joints[0].parent == -1 && g->joints[1].parent == 0, "%s: joint parents %d %d", what, g->joints[0].parent,
            g->joints[1].parent);
    T_CHECK(g->joints[0].node == 2 && g->joints[1].node == 3 && g->skin == 0, "%s: joint nodes", what);
    for (j = 0; j < 2; j++)
        for (k = 0; k < 3; k++) {
            double want = ibm ? JW[j][k] + IBM_SHIFT[k] - MESH_T[k] : JW[j][k];
            T_NEAR(g->joints[j].node_pos[k], JW[j][k], tol, "hierarchy");
            T_NEAR(g->joints[j].pos[k], want, tol, ibm ? "IBM (exact binary fractions in float)" : "hierarchy");
        }
}

static const double T0[3] = {0.5, 0, 0}, T4[3] = {0, 0, 5};   /* translations of nodes 0 and 4 */

static void load_ok(const char *what, const char *file, const char *mesh, const double *T, int ibm)
{
    sb_gltf g;
    int rc = sb_gltf_load(&g, file, mesh);
    T_CHECK(rc == 0, "%s: load failed: %s", what, sb_error());
    if (rc == 0) check_strip(what, &g, T, ibm);
    sb_gltf_free(&g);
}

/* the file must be refused with `expect` in the message, leaving g empty */
static void load_bad(const char *what, const char *file, const char *expect)
{
    sb_gltf g;
    int rc = sb_gltf_load(&g, file, NULL);
    T_CHECK(rc == -1 && strstr(sb_error(), expect) && g.nv == 0 && g.pos == NULL && g.joints == NULL && g.tri == NULL,
            "%s: rc %d, message \"%s\", want \"%s\"", what, rc, rc ? sb_error() : "", expect);
    sb_gltf_free(&g);
}

static void bad_json(const char *what, const char *json, const char *expect)
{
    write_bytes(at("bad.gltf"), json, strlen(json));
    load_bad(what, at("bad.gltf"), expect);
}

static void bad_glb(const char *what, const unsigned char *b, size_t n, const char *expect)
{
    write_bytes(at("bad.glb"), b, n);
    load_bad(what, at("bad.glb"), expect);
}

static void test_json(void)
{
    sbj_doc d;
    char deep[300];
    int k, s;
    T_CHECK(sbj_parse(&d, "[1, 2]", 4) == -1 && strstr(sb_error(), "(byte 4): value expected, end of text"), "reads only len bytes: %s", sb_error());
    {
        const char *t = "{\"a\":[1,-2.5e2,true,false,null],\"b\":\"x\\n\\u00e9\\ud83d\\ude00\\/\"}";
        T_CHECK(sbj_parse(&d, t, strlen(t)) == 0, "json: %s", sb_error());
        k = sbj_get(&d, 0, "a");
        T_CHECK(k > 0 && d.node[k].count == 5 && d.node[sbj_at(&d, k, 1)].num == -250 &&
                    d.node[sbj_at(&d, k, 2)].kind == SBJ_TRUE && d.node[sbj_at(&d, k, 4)].kind == SBJ_NULL,
                "json array values");
        s = sbj_get(&d, 0, "b");
        T_CHECK(s > 0 && !strcmp(sbj_str(&d, s), "x\n\xc3\xa9\xf0\x9f\x98\x80/") && d.node[s].slen == 9, "json escapes to UTF-8");
        sbj_free(&d);
    }
    {
        static const char *const bad[][2] = {
            {"{\"a\":01}", "line 1"}, {"[1,]", "unexpected"}, {"{\"a\" 1}", "':'"}, {"\"\\ud800\"", "surrogate"},
            {"\"a\nb\"", "control"}, {"[1] x", "after the JSON"}, {"{\"a\":1", "unterminated"}, {"\n\n[tru]", "line 3"},
            {"[1.]", "after '.'"}, {"\"\\x\"", "escape"}, {"", "end of text"}};
        for (k = 0; k < (int)(sizeof bad / sizeof bad[0]); k++) {
            int rc = sbj_parse(&d, bad[k][0], strlen(bad[k][0]));
            T_CHECK(rc == -1 && strstr(sb_error(), bad[k][1]) && d.node == NULL, "json bad %d: rc %d \"%s\" want \"%s\"", k, rc,
                    sb_error(), bad[k][1]);
        }
    }
    for (k = 0; k < 64; k++) deep[k] = '[', deep[64 + k] = ']';
    T_CHECK(sbj_parse(&d, deep, 128) == 0, "64 levels are allowed: %s", sb_error());
    sbj_free(&d);
    for (k = 0; k < 150; k++) deep[k] = '[', deep[150 + k] = ']';
    T_CHECK(sbj_parse(&d, deep, 300) == -1 && strstr(sb_error(), "deeper than 64"), "150 levels refused: %s", sb_error());
}

int main(void)
{
    const char *base = getenv("BUILD") ? getenv("BUILD") : "build";
    static unsigned char glb[16384], tmpb[16384];
    char *uri, *json, *j2, *data;
    size_t n;
    sb_gltf g;
    (void)t_seed;   /* sn_test.h helper this test has no use for */
    snprintf(tmp, sizeof tmp, "%s/test_bake_gltf.d", base);
    {
        char cmd[600];
        snprintf(cmd, sizeof cmd, "mkdir -p '%s'", tmp);
        if (system(cmd)) { printf("cannot create %s\n", tmp); return 1; }
    }
    test_json();
    make_bin();
    write_bytes(at("strip.bin"), bin, BIN_LEN);
    make_types_bin();
    write_bytes(at("types.bin"), tbin, sizeof tbin);

    /* valid: external .bin, TRS hierarchy, with and without IBMs, matrices */
    json = make_json("{\"uri\":\"strip.bin\",\"byteLength\":368}", 0, 1);
    write_bytes(at("trs.gltf"), json, strlen(json));
    load_ok("trs + ibm, external bin", at("trs.gltf"), NULL, T0, 1);
    load_ok("named mesh strip2", at("trs.gltf"), "strip2", T4, 1);
    if (sb_gltf_load(&g, at("trs.gltf"), "types") == 0) check_types(&g);
    else T_CHECK(0, "types: %s", sb_error());
    sb_gltf_free(&g);
    json = make_json("{\"uri\":\"strip.bin\",\"byteLength\":368}", 0, 0);
    write_bytes(at("noibm.gltf"), json, strlen(json));
    load_ok("trs, no ibm", at("noibm.gltf"), NULL, T0, 0);
    json = make_json("{\"uri\":\"strip.bin\",\"byteLength\":368}", 1, 1);
    write_bytes(at("mat.gltf"), json, strlen(json));
    load_ok("matrices + ibm", at("mat.gltf"), NULL, T0, 1);
    json = make_json("{\"uri\":\"strip.bin\",\"byteLength\":368}", 1, 0);
    write_bytes(at("mat0.gltf"), json, strlen(json));
    load_ok("matrices, no ibm", at("mat0.gltf"), NULL, T0, 0);
    write_bytes(at("strip copy.bin"), bin, BIN_LEN);
    json = make_json("{\"uri\":\"strip%20copy.bin\",\"byteLength\":368}", 0, 1);
    write_bytes(at("pct.gltf"), json, strlen(json));
    load_ok("%-escaped uri", at("pct.gltf"), NULL, T0, 1);
    T_CHECK(sb_gltf_load(&g, at("trs.gltf"), "nope") == -1 && strstr(sb_error(), "no skinned mesh named \"nope\""),
            "unknown mesh name: %s", sb_error());
    sb_gltf_free(&g);

    /* valid: base64 data URI */
    data = b64(bin, BIN_LEN);
    uri = malloc(strlen(data) + 200);
    sprintf(uri, "{\"uri\":\"data:application/octet-stream;base64,%s\",\"byteLength\":368}", data);
    json = make_json(uri, 0, 1);
    write_bytes(at("b64.gltf"), json, strlen(json));
    load_ok("base64 data URI", at("b64.gltf"), NULL, T0, 1);
    j2 = subst(json, "base64,", "base64,AB!D");
    bad_json("base64 garbage", j2, "buffers[0].uri: bad base64 character at offset 2");
    free(j2);
    j2 = subst(json, "base64,", "base64,A");
    bad_json("base64 length", j2, "buffers[0].uri: base64 data of");
    free(j2);
    j2 = subst(json, "\"byteLength\":368}", "\"byteLength\":372}");
    bad_json("data URI shorter than byteLength", j2, "buffers[0].uri: 368 bytes, but byteLength says 372");
    free(j2);

    /* valid: GLB */
    json = make_json("{\"byteLength\":368}", 0, 1);
    n = make_glb(glb, json);
    write_bytes(at("strip.glb"), glb, n);
    load_ok("glb", at("strip.glb"), NULL, T0, 1);

    /* broken GLBs */
    bad_glb("truncated glb header", glb, 10, "GLB header: the file is 10 bytes");
    bad_glb("truncated glb", glb, n - 8, "GLB header.length");
    memcpy(tmpb, glb, n), tmpb[3] = 'X';
    bad_glb("bad magic", tmpb, n, "GLB header.magic");
    memcpy(tmpb, glb, n), put32(tmpb + 4, 1);
    bad_glb("glb version 1", tmpb, n, "GLB header.version");
    memcpy(tmpb, glb, n), put32(tmpb + 12, 0x7ffffff0u);
    bad_glb("json chunk length overrun", tmpb, n, "GLB chunks[0].chunkLength");
    {
        size_t jp = (strlen(json) + 3) / 4 * 4;
        memcpy(tmpb, glb, n), put32(tmpb + 20 + jp, 0xfffffff0u);
        bad_glb("bin chunk length overrun", tmpb, n, "GLB chunks[1].chunkLength");
        memcpy(tmpb, glb, n), put32(tmpb + 20 + jp, 100);
        put32(tmpb + 8, (unsigned)(28 + jp + 100));
        bad_glb("bin chunk shorter than buffer", tmpb, 28 + jp + 100, "buffers[0].byteLength: 368, but the GLB BIN chunk has 100");
    }
    json = make_json("{\"uri\":\"strip.bin\",\"byteLength\":368}", 0, 1);
    j2 = subst(json, "\"scene\":0", "\"scene\":0 ]");
    n = make_glb(tmpb, j2);
    bad_glb("glb json syntax", tmpb, n, "JSON line 3");
    free(j2);

    /* broken .gltf: each one substitution in the good file */
    {
        static const char *const cases[][4] = {
            {"accessor overrun", "\"count\":12", "\"count\":13",
             "accessors[3].count: 13 elements of 2 bytes (stride 2, byteOffset 0) overrun bufferViews[3] (length 24)"},
            {"byteStride too small", "\"byteStride\":16", "\"byteStride\":8",
             "bufferViews[0].byteStride: 8 is smaller than the 12-byte elements of accessors[0]"},
            {"byteStride odd", "\"byteStride\":16", "\"byteStride\":14", "bufferViews[0].byteStride: 14"},
            {"sparse accessor", "{\"bufferView\":2,", "{\"sparse\":{\"count\":1},\"bufferView\":2,",
             "accessors[2].sparse: sparse accessors are not supported"},
            {"non-triangle mode", "\"mode\":4", "\"mode\":1", "meshes[0].primitives[0].mode: 1, only 4 (triangles)"},
            {"unknown componentType", "\"componentType\":5123", "\"componentType\":5124",
             "accessors[3].componentType: 5124 is not a glTF component type"},
            {"missing buffer file", "strip.bin", "missing.bin", "buffers[0].uri: cannot read"},
            {"bad %-escape", "strip.bin", "strip%2.bin", "buffers[0].uri: bad %-escape"},
            {"absolute buffer path", "strip.bin", "/etc/passwd", "buffers[0].uri: \"/etc/passwd\" is not a relative file name"},
            {"JSON syntax error", "\"scenes\":[", "\"scenes\" [", "JSON line 4"},
            {"cycle in children", "{\"name\":\"bone1\",", "{\"name\":\"bone1\",\"children\":[1],", "a cycle"},
            {"node child twice", "\"children\":[3]", "\"children\":[3,3]", "nodes[2].children[1]: node 3 is already a child of nodes[2]"},
            {"child out of range", "\"children\":[3]", "\"children\":[9]", "nodes[2].children[0]: not a node index"},
            {"view overruns buffer", "\"byteOffset\":240,\"byteLength\":128", "\"byteOffset\":244,\"byteLength\":128",
             "bufferViews[4]: byteOffset 244 + byteLength 128 overrun buffers[0]"},
            {"misaligned accessor", "{\"bufferView\":3,", "{\"bufferView\":3,\"byteOffset\":1,", "accessors[3].byteOffset: 1"},
            {"weights wrong type", "{\"bufferView\":2,\"componentType\":5126,\"count\":6,\"type\":\"VEC4\"}",
             "{\"bufferView\":2,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"}",
             "meshes[0].primitives[0].attributes.WEIGHTS_0: accessors[2] has the wrong type"},
            {"joints count", "{\"bufferView\":1,\"componentType\":5121,\"count\":6", "{\"bufferView\":1,\"componentType\":5121,\"count\":5",
             "meshes[0].primitives[0].attributes.JOINTS_0: accessors[1] has 5 elements, POSITION has 6"},
            {"no weights", ",\"WEIGHTS_0\":2},\"indices\":3,", "},\"indices\":3,", "JOINTS_0 and WEIGHTS_0 are required"},
            {"ibm not mat4", "\"count\":2,\"type\":\"MAT4\"", "\"count\":8,\"type\":\"VEC4\"", "skins[0].inverseBindMatrices"},
            {"joint not a node", "\"joints\":[2,3]", "\"joints\":[2,7]", "skins[0].joints[1]: not a node index"},
            {"joint twice", "\"joints\":[2,3]", "\"joints\":[2,2]", "skins[0].joints[1]: node 2 is listed twice"},
            {"matrix and TRS", "\"translation\":[0,0.5,0]", "\"translation\":[0,0.5,0],\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]",
             "nodes[2]: both matrix and translation"},
            {"bad scene", "\"scene\":0", "\"scene\":3", "scene:"},
            {"scene node not root", "\"nodes\":[0,1,4,5]", "\"nodes\":[0,2,4,5]", "scenes[0].nodes[1]"},
            {"asset version", "\"version\":\"2.0\"", "\"version\":\"1.0\"", "asset.version: \"1.0\""},
            {"required extension", "\"scene\":0,", "\"scene\":0,\"extensionsRequired\":[\"KHR_draco_mesh_compression\"],",
             "extensionsRequired[0]: \"KHR_draco_mesh_compression\""},
            {"count not integer", "\"count\":12", "\"count\":12.5", "accessors[3].count: an integer expected"},
            {"huge count", "\"count\":12", "\"count\":1e300", "is out of range [1, 268435456]"},
            {"joint position overflow", "\"translation\":[0,1,0]", "\"translation\":[0,1e308,0]",
             "skins[0].joints[1]: the bind position of nodes[3] is not finite"},
            {"JOINTS_1", "\"JOINTS_0\":1,", "\"JOINTS_0\":1,\"JOINTS_1\":1,", "attributes.JOINTS_1"},
        };
        int k;
        for (k = 0; k < (int)(sizeof cases / sizeof cases[0]); k++) {
            j2 = subst(json, cases[k][1], cases[k][2]);
            bad_json(cases[k][0], j2, cases[k][3]);
            free(j2);
        }
    }
    {   /* too deep nesting inside the glTF */
        char *deep = malloc(400), *j3;
        int k;
        strcpy(deep, "\"scene\":0,\"extras\":");
        for (k = 0; k < 100; k++) strcat(deep, "[");
        for (k = 0; k < 100; k++) strcat(deep, "]");
        strcat(deep, ",");
        j3 = subst(json, "\"scene\":0,", deep);
        bad_json("too-deep nesting", j3, "JSON line 3 (byte");
        T_CHECK(strstr(sb_error(), "deeper than 64") != NULL, "too deep: %s", sb_error());
        free(j3), free(deep);
    }
    {   /* weights and joints the skin does not have */
        unsigned char keep = bin[96 + 4 * 2 + 1];
        bin[96 + 4 * 2 + 1] = 7;   /* vertex 2, slot 1 (weight 0.5): joint 7 */
        write_bytes(at("strip.bin"), bin, BIN_LEN);
        load_bad("joint out of skin", at("trs.gltf"), "meshes[0].primitives[0].attributes.JOINTS_0: vertex 2 uses joint 7, skins[0] has 2");
        bin[96 + 4 * 2 + 1] = keep;
        memset(bin + 120 + 16 * 4, 0, 16);   /* vertex 4: all weights 0 */
        write_bytes(at("strip.bin"), bin, BIN_LEN);
        load_bad("zero weights", at("trs.gltf"), "WEIGHTS_0: vertex 4 has no weight");
        make_bin();
        bin[216 + 2 * 5] = 6;   /* the 6th index: vertex 6 of 6 */
        write_bytes(at("strip.bin"), bin, BIN_LEN);
        load_bad("index out of range", at("trs.gltf"), "meshes[0].primitives[0].indices: index 5 is 6, POSITION has 6 vertices");
        make_bin();
        write_bytes(at("strip.bin"), bin, BIN_LEN);
        load_ok("restored bin", at("trs.gltf"), NULL, T0, 1);
        putf(bin + 16 * 2 + 4, (float)HUGE_VAL);   /* vertex 2: y = +inf */
        write_bytes(at("strip.bin"), bin, BIN_LEN);
        load_bad("infinite position", at("trs.gltf"), "meshes[0].primitives[0].attributes.POSITION: vertex 2 is not finite");
        make_bin();
        write_bytes(at("strip.bin"), bin, BIN_LEN);
    }
    {   /* the skinned mesh node's transform is ignored (glTF 2.0, 3.7.3.3),
         * even one that would overflow every position */
        char *j2 = subst(make_json("{\"uri\":\"strip.bin\",\"byteLength\":368}", 0, 1), "\"translation\":[0.5,0,0]",
                         "\"translation\":[0.5,1e308,0],\"scale\":[1,1e308,1]");
        write_bytes(at("huge_node.gltf"), j2, strlen(j2));
        load_ok("mesh node transform ignored", at("huge_node.gltf"), NULL, T0, 1);
        free(j2);
    }
    {   /* a 50,000-node chain: read in linear time (the parent walk is not
         * redone per node), world positions summed exactly */
        enum { N = 50000 };
        size_t cap = (size_t)N * 48 + 4096, len;
        char *big = malloc(cap);
        int k;
        len = (size_t)sprintf(big, "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[");
        for (k = 0; k < N - 1; k++) len += (size_t)sprintf(big + len, "{\"translation\":[0,0,1],\"children\":[%d]},", k + 1);
        len += (size_t)sprintf(big + len, "{\"translation\":[0,0,1],\"mesh\":0,\"skin\":0}],\"skins\":[{\"joints\":[%d,%d]}],", N - 2, N - 1);
        len += (size_t)sprintf(big + len, "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"JOINTS_0\":1,\"WEIGHTS_0\":2}}]}],"
                                   "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"},"
                                   "{\"bufferView\":1,\"componentType\":5121,\"count\":6,\"type\":\"VEC4\"},"
                                   "{\"bufferView\":2,\"componentType\":5126,\"count\":6,\"type\":\"VEC4\"}],"
                                   "\"bufferViews\":[{\"buffer\":0,\"byteLength\":96,\"byteStride\":16},"
                                   "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":24},{\"buffer\":0,\"byteOffset\":120,\"byteLength\":96}],"
                                   "\"buffers\":[{\"uri\":\"strip.bin\",\"byteLength\":368}]}");
        write_bytes(at("chain.gltf"), big, len);
        k = sb_gltf_load(&g, at("chain.gltf"), NULL);
        T_CHECK(k == 0 && g.nv == 6 && g.nt == 2 && g.nj == 2 && g.joints[1].parent == 0 && g.joints[0].parent == -1 &&
                    g.joints[0].node_pos[2] == N - 1 && g.joints[1].node_pos[2] == N && g.pos[2 * 3 + 2] == 0 /* mesh node transform ignored */,
                "chain: rc %d %s", k, k ? sb_error() : "");
        sb_gltf_free(&g);
        free(big);
    }
    {   /* every byte of the GLB replaced by a few values: refused cleanly or
         * loaded with every index in range (run under ASan+UBSan too) */
        static const unsigned char vals[] = {0x00, 0xff, '9', '[', '"', '-'};
        size_t i, loads = 0, ok = 0, bad = 0;
        unsigned k;
        json = make_json("{\"byteLength\":368}", 0, 1);
        n = make_glb(glb, json);
        for (i = 0; i < n; i++)
            for (k = 0; k < sizeof vals; k++) {
                int rc, t;
                if (glb[i] == vals[k]) continue;
                memcpy(tmpb, glb, n);
                tmpb[i] = vals[k];
                write_bytes(at("mut.glb"), tmpb, n);
                rc = sb_gltf_load(&g, at("mut.glb"), NULL);
                loads++;
                if (rc == 0) {
                    ok++;
                    for (t = 0; t < 3 * g.nt; t++) bad += g.tri[t] < 0 || g.tri[t] >= g.nv;
                    for (t = 0; t < 4 * g.nv; t++) bad += g.joint[t] < 0 || g.joint[t] >= g.nj;
                    for (t = 0; t < g.nj; t++) bad += g.joints[t].parent < -1 || g.joints[t].parent >= g.nj;
                } else
                    bad += g.nv != 0 || g.pos != NULL || g.joints != NULL;
                sb_gltf_free(&g);
            }
        T_CHECK(bad == 0, "mutated GLBs: %lu bad results", (unsigned long)bad);
        T_FIGURE("%lu mutated GLBs: %lu loaded, %lu refused", (unsigned long)loads, (unsigned long)ok, (unsigned long)(loads - ok));
    }
    free(data), free(uri);
    return T_END();
}
