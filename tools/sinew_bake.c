/* sinew_bake.c -- command line of the host tool. */
#include "sb.h"
#include "sb_static.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

static void usage(FILE *f)
{
    fprintf(f,
            "usage: sinew-bake DESCRIPTION -o OUT.blob [--c-array OUT.c [--name SYMBOL]]\n"
            "                  [--flavour fixed|float|double] [--quiet] [--check]\n"
            "       (-o may be left out when --c-array or --check is given)\n"
            "Bakes a character (OBJ mesh + text description, see tools/DESCRIPTION.md) into a\n"
            "Sinew blob (runtime/BLOB.md).\n"
            "  -o OUT.blob       binary blob (written to OUT.blob.tmp, then renamed); from a 'gltf' description\n"
            "                    also OUT.blob.gltfmap, the glTF vertex order of the surface (DESCRIPTION.md)\n"
            "  --c-array OUT.c   also write the blob as an 8-aligned C99 array\n"
            "  --name SYMBOL     C symbol of the array (default sinew_blob); SYMBOL_size holds the size\n"
            "  --flavour F       fixed (default, int32 Q formats), float (float32), double (float64, host/tests)\n"
            "  --quiet           no summary or progress (warnings still go to stderr)\n"
            "  --no-triangles    leave the surface triangles out of the blob (TRIS empty: for an engine that\n"
            "                    keeps its own index buffer; sn_get_normals and sn_get_triangle then refuse)\n"
            "  --check           check the model (interior volume within 1%% of the mesh volume, embedding\n"
            "                    error <= 1e-5 of the bbox diagonal, rigid translations and rotations in the\n"
            "                    null space of S), print one 'check:' line (also with --quiet); on failure\n"
            "                    exit 1 and write nothing\n"
            "  --help            this text\n"
            "Static equilibrium (seed 003 eq. 10; tools/DESCRIPTION.md \"Static equilibrium\"):\n"
            "       sinew-bake DESCRIPTION --static POSE [--controls NAME=VALUE,...] [-o OUT.obj] [--png OUT.png]\n"
            "                  [--view AZ,EL] [--quiet]\n"
            "  --static POSE     rest | FILE.clip@SECONDS | JOINT:AX,AY,AZ,DEG[+JOINT:...] (local rotations);\n"
            "                    solves the baked model's static shape in double precision with the rigs on\n"
            "                    (and off, for comparison) and writes the surface as OBJ (-o, default\n"
            "                    <description>_static.obj, the description's coordinates) and a picture\n"
            "                    rigs off | rigs on (--png, default the OBJ name with .png); no blob is written\n"
            "  --controls LIST   abstract control values, e.g. breath=0.5,smile=1 (pose controls follow the pose)\n"
            "  --view AZ,EL      picture azimuth, elevation in degrees (default 30,15)\n");
}

/* per bone: radius and the lattice vertices it captures and moves */
static void bone_summary(const sb_model *o)
{
    int a;
    if (!o->nseg) return;
    printf("  bones     %-24s %9s  %-20s %8s %6s\n", "(radius in mesh units)", "radius", "", "captured", "moved");
    for (a = 0; a < o->nseg; a++) {
        const sb_joint *C = &o->joints[o->seg_child[a]], *P = &o->joints[C->parent];
        char nm[2 * SB_NAME_MAX + 4], how[40];
        snprintf(nm, sizeof nm, "%s->%s", P->name, C->name);
        if (o->seg_auto[a]) snprintf(how, sizeof how, "auto (flesh %.3g)", o->seg_flesh[a]);
        else snprintf(how, sizeof how, "given");
        printf("            %-24s %9.3g  %-20s %8d %6d\n", nm, o->seg_r[a], how, o->seg_ncap[a], o->seg_nv[a]);
    }
}

/* --check: the model against the mesh it was baked from */
static int run_check(const char *desc, const sb_model *o, double secs)
{
    sb_desc d;
    sb_mesh m;
    sb_check r;
    memset(&m, 0, sizeof m);
    if (sb_desc_load(desc, &d) || sb_desc_mesh(&d, &m, NULL)) {
        fprintf(stderr, "sinew-bake: error: --check: %s\n", sb_error());
        sb_mesh_free(&m); sb_desc_free(&d);
        return -1;
    }
    sb_model_check(o, &m, &r);
    printf("check: cell %g: lattice %d vertices (%d free, %d skeleton), %d cells; volume ratio %.5f; embedding %.2e; "
           "null space: translations %.1e, rotations %.1e; %.2f s: %s\n",
           o->c, o->nv, o->nf, o->nv - o->nf, o->nc, r.vol_ratio, r.emb_err, r.trans, r.rot, secs, r.ok ? "ok" : "FAILED");
    if (!r.ok)
        fprintf(stderr, "sinew-bake: error: --check failed: %s%s%s%s\n", fabs(r.vol_ratio - 1) > 0.01 ? "interior volume off by more than 1%; " : "",
                r.emb_err > 1e-5 ? "embedding error above 1e-5 of the diagonal; " : "", r.trans > 1e-12 ? "translations not in the null space; " : "",
                r.rot > 1e-11 ? "rotations not in the null space" : "");
    sb_mesh_free(&m); sb_desc_free(&d);
    return r.ok ? 0 : -1;
}

int main(int argc, char **argv)
{
    const char *desc = NULL, *out = NULL, *carray = NULL, *name = "sinew_blob";
    char mapname[1100] = "";
    int flavour = SB_FIXED, quiet = 0, check = 0, no_tris = 0, i;
    sb_static_opts st = { NULL, NULL, NULL, NULL, 30, 15, 0 };
    double t0;
    sb_model o;
    sb_blob b;
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { usage(stdout); return 0; }
        else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) quiet = 1;
        else if (!strcmp(a, "--check")) check = 1;
        else if (!strcmp(a, "--no-triangles")) no_tris = 1;
        else if (!strcmp(a, "--static") || !strcmp(a, "--controls") || !strcmp(a, "--png") || !strcmp(a, "--view")) {
            if (i + 1 >= argc) { fprintf(stderr, "sinew-bake: %s needs a value\n", a); return 2; }
            if (!strcmp(a, "--static")) st.pose = argv[++i];
            else if (!strcmp(a, "--controls")) st.controls = argv[++i];
            else if (!strcmp(a, "--png")) st.png = argv[++i];
            else if (sscanf(argv[++i], "%lf,%lf", &st.az, &st.el) != 2) {
                fprintf(stderr, "sinew-bake: --view: want AZ,EL in degrees, got '%s'\n", argv[i]); return 2;
            }
        } else if (!strcmp(a, "-o") || !strcmp(a, "--c-array") || !strcmp(a, "--name") || !strcmp(a, "--flavour")) {
            if (i + 1 >= argc) { fprintf(stderr, "sinew-bake: %s needs a value\n", a); return 2; }
            if (!strcmp(a, "-o")) out = argv[++i];
            else if (!strcmp(a, "--c-array")) carray = argv[++i];
            else if (!strcmp(a, "--name")) name = argv[++i];
            else {
                const char *f = argv[++i];
                if (!strcmp(f, "fixed")) flavour = SB_FIXED;
                else if (!strcmp(f, "float")) flavour = SB_FLOAT;
                else if (!strcmp(f, "double")) flavour = SB_DOUBLE;
                else { fprintf(stderr, "sinew-bake: unknown flavour '%s' (fixed, float or double)\n", f); return 2; }
            }
        } else if (a[0] == '-' && a[1]) { fprintf(stderr, "sinew-bake: unknown option '%s' (try --help)\n", a); return 2; }
        else if (!desc) desc = a;
        else { fprintf(stderr, "sinew-bake: more than one description given ('%s')\n", a); return 2; }
    }
    if (st.pose || st.controls || st.png) {   /* --static: its own command (sb_static.c) */
        if (!desc || !st.pose) { fprintf(stderr, "sinew-bake: %s\n", desc ? "--controls and --png need --static POSE" : "--static needs a DESCRIPTION"); return 2; }
        if (carray || check) { fprintf(stderr, "sinew-bake: --static writes no blob: --c-array and --check do not apply\n"); return 2; }
        st.obj = out; st.quiet = quiet;
        return sb_static_run(desc, &st);
    }
    if (!desc || (!out && !carray && !check)) { usage(stderr); return 2; }
    if (carray) {   /* check the symbol before any work or output */
        const char *c;
        for (c = name; *c; c++)
            if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || *c == '_' || (c != name && *c >= '0' && *c <= '9'))) break;
        if (*c || !*name) { fprintf(stderr, "sinew-bake: --name '%s' is not a C identifier\n", name); return 2; }
    }
    t0 = sb_now();
    if (sb_bake_file(desc, flavour, quiet, &o, &b)) { fprintf(stderr, "sinew-bake: error: %s\n", sb_error()); return 1; }
    t0 = sb_now() - t0;
    if (no_tris) {   /* the same model written again with an empty TRIS section */
        int nt = o.nt;
        unsigned long with = (unsigned long)b.size;
        sb_blob_free(&b);
        o.nt = 0;
        if (sb_blob_make(&o, flavour, &b)) { fprintf(stderr, "sinew-bake: error: %s\n", sb_error()); o.nt = nt; sb_rig_free(&o); sb_model_free(&o); return 1; }
        o.nt = nt;
        if (!quiet) printf("  blob      %lu bytes without the %d triangles (--no-triangles; %lu with them)\n", (unsigned long)b.size, nt, with);
    }
    if (!quiet) bone_summary(&o);
    if (check && run_check(desc, &o, t0)) { sb_blob_free(&b); sb_rig_free(&o); sb_model_free(&o); return 1; }
    if (out && o.src.nsrc) snprintf(mapname, sizeof mapname, "%s.gltfmap", out);
    if ((out && sb_write_file(out, b.bytes, b.size)) || (carray && sb_write_c_array(carray, name, b.bytes, b.size)) ||
        (mapname[0] && sb_srcmap_write(mapname, &o.src))) {
        fprintf(stderr, "sinew-bake: error: %s\n", sb_error());
        if (out) remove(out);   /* all or nothing */
        if (mapname[0]) remove(mapname);
        sb_blob_free(&b); sb_rig_free(&o); sb_model_free(&o);
        return 1;
    }
    sb_blob_free(&b);
    sb_rig_free(&o);
    sb_model_free(&o);
    return 0;
}
