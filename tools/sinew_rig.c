/* sinew_rig.c -- sinew-rig: rig fitting on the command line (seed 003
 * §4.2-4.3, issue 11; tools/DESCRIPTION.md "Rig fitting (sinew-rig)").
 *
 *   fit-surface  a surface rig from a target mesh (pose from feature points or given)
 *   fit-pose     the pose of a target mesh from feature points
 *   fit-points   template rig strengths from dragged surface points
 *   export       a description rig's baked forces as a rig file
 *
 * Every output is written only after everything before it succeeded, and
 * depends only on the inputs (no times or paths of temporaries in files). */
#include "sb.h"
#include "sb_fit.h"
#include "sb_static.h"
#include "raster.h"
#include "png.h"
#include "sn_format.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PROG "sinew-rig"
#define PI 3.14159265358979323846

static void usage(FILE *f)
{
    fprintf(f,
        "usage: sinew-rig COMMAND DESCRIPTION [options]\n"
        "Rig fitting (seed 003 4.2-4.3) at the static equilibrium of eq. 10, double precision, L-BFGS-B\n"
        "(the surface rig: conjugate gradients on its quadratic cost).\n"
        "Commands:\n"
        "  fit-surface DESC --target T.obj[@GAMMA] [--target ...] --control NAME -o OUT.rig\n"
        "              [--pose POSE | --features V1,V2,... [--joints J1,J2,...]] [--controls N=V,...]\n"
        "              [--omega W] [--rigs-off] [--name RIG] [--png PIC.png] [--view AZ,EL] [--max-iter N]\n"
        "              [--optimizer cg|lbfgsb]\n"
        "      a surface rig: the generalized force whose equilibrium matches the target mesh (same\n"
        "      vertices as the description's mesh), stored as a rig file (DESCRIPTION.md 'Rig files')\n"
        "      for 'rig_file RIG OUT.rig CONTROL tau ...' (the line is printed). GAMMA: the control's\n"
        "      value the target shows (default 1 for an abstract control, the fitted pose's angle for a\n"
        "      pose control); several targets at several GAMMA become tau samples. The pose: --pose, or\n"
        "      fitted to the feature vertices (0-based indices of the mesh) over --joints (default every\n"
        "      non-root joint) on the static equilibrium (--pose-skinned: on the rigidly skinned shape,\n"
        "      faster, ignores sag); --omega: smoothness weight (default 1e-5); --rigs-off: the description's\n"
        "      rigs off during the fit (default on at the controls' values); --png: rest | unrigged | rigged\n"
        "      | target; the rig is solved exactly (conjugate gradients on the normal equations; --optimizer\n"
        "      lbfgsb: L-BFGS-B, --max-iter iterations); then what any rig at the pose could reach: the\n"
        "      target's share on bone-carried surface and the best fit by the free lattice vertices alone\n"
        "  fit-pose DESC --target T.obj --features V1,V2,... [--joints J1,...] [--pose-skinned]\n"
        "              [--controls N=V,...] [--rigs-off] [-o POSE.txt]\n"
        "      the pose (local joint rotations, as --static/--pose take them) whose static shape (or\n"
        "      skinned shape) puts the feature vertices nearest their target positions\n"
        "  fit-points DESC --points FILE --rigs R1,R2,... [--geometry] [--pose POSE] [--controls N=V,...]\n"
        "              [--lambda L] [--bounds LO,HI] [-o OUT.sinew]\n"
        "      template rigs' strengths (--geometry: also centres/ends and sizes, re-integrated at every\n"
        "      evaluation) so that surface points reach dragged positions; FILE lines 'VERTEX X Y Z'\n"
        "      (0-based mesh vertex, target in the mesh's coordinates); --bounds: the strengths' range;\n"
        "      writes the rig lines with the fitted parameters (to replace the description's)\n"
        "  export DESC RIG -o OUT.rig\n"
        "      a rig of the description (template or file) as a rig file\n"
        "  retarget A.sinew B.sinew --rig R1,R2,... -o OUT.rig [options]\n"
        "      rigs of character A carried to character B (seed 003 4.4): a map of A's lattice onto B,\n"
        "      its Jacobians, the rig moved as a displacement; written as a rig file of B\n"
        "      (sinew-rig retarget --help)\n"
        "Two levels: with 'levels 2' in DESC (retarget: in B), fit-surface, export and retarget write a fit\n"
        "per level ('sinew-rig 2' files: level 1's computed on level 1's own lattice; tools/DESCRIPTION.md\n"
        "'Rig files').\n"
        "Common options: --quiet (no progress or summary), --progress N (a progress line every N\n"
        "iterations, default 10), --help.\n"
        "Progress lines (stderr): LABEL: iter N  f COST  |pg|inf PROJECTED-GRADIENT. Exit status: 0, 1 (a\n"
        "bake or solve failed), 2 (bad command line or input); nothing is written on failure.\n");
}

/* ---------------- small parsers ---------------- */

static int parse_ints(const char *s, int *out, int max, const char *what)
{
    int n = 0;
    while (*s) {
        char *e;
        long v = strtol(s, &e, 10);
        if (e == s || v < 0 || v > 2000000000L || (*e && *e != ',')) { fprintf(stderr, PROG ": %s: '%s' is not a list of vertex indices\n", what, s); return -1; }
        if (n >= max) { fprintf(stderr, PROG ": %s: more than %d entries\n", what, max); return -1; }
        out[n++] = (int)v;
        s = *e ? e + 1 : e;
    }
    return n;
}

/* OBJ vertex positions: count must equal want; non-finite refused */
static double *read_obj_vertices(const char *path, int want)
{
    FILE *f = fopen(path, "r");
    char line[4096];
    int n = 0, ln = 0, cap = want > 0 ? want : 1;
    double *v;
    if (!f) { fprintf(stderr, PROG ": cannot open target '%s'\n", path); return NULL; }
    v = malloc(3 * (size_t)cap * sizeof *v);
    if (!v) { fclose(f); fprintf(stderr, PROG ": out of memory\n"); return NULL; }
    while (fgets(line, sizeof line, f)) {
        double x[3];
        char *p = line, *e;
        int k;
        ln++;
        while (*p == ' ' || *p == '\t') p++;
        if (p[0] != 'v' || (p[1] != ' ' && p[1] != '\t')) continue;
        p += 2;
        for (k = 0; k < 3; k++) {
            x[k] = strtod(p, &e);
            if (e == p) { fprintf(stderr, PROG ": %s:%d: a vertex needs three numbers\n", path, ln); fclose(f); free(v); return NULL; }
            if (!isfinite(x[k])) { fprintf(stderr, PROG ": %s:%d: non-finite vertex coordinate\n", path, ln); fclose(f); free(v); return NULL; }
            p = e;
        }
        if (n < cap) memcpy(v + 3 * n, x, sizeof x);
        n++;
    }
    fclose(f);
    if (n != want) {
        fprintf(stderr, PROG ": target '%s' has %d vertices, the character's mesh has %d (a target must have the same vertices, same order)\n", path, n, want);
        free(v);
        return NULL;
    }
    return v;
}

static int find_joint(const snref_model *m, const char *name)
{
    unsigned j;
    for (j = 0; j < m->nJ; j++) if (!strcmp(m->jname[j], name)) return (int)j;
    return -1;
}

static int parse_joints(const snref_model *m, const char *s, int *out, int max)
{
    int n = 0;
    char buf[256];
    while (s && *s) {
        const char *e = strchr(s, ',');
        size_t l = e ? (size_t)(e - s) : strlen(s);
        int j;
        if (l >= sizeof buf) l = sizeof buf - 1;
        memcpy(buf, s, l); buf[l] = 0;
        if ((j = find_joint(m, buf)) < 0) {
            unsigned k;
            fprintf(stderr, PROG ": --joints: unknown joint '%s'; joints:", buf);
            for (k = 0; k < m->nJ; k++) fprintf(stderr, " %s", m->jname[k]);
            fprintf(stderr, "\n");
            return -1;
        }
        if (n >= max) { fprintf(stderr, PROG ": --joints: at most %d\n", max); return -1; }
        out[n++] = j;
        s = e ? e + 1 : s + l;
    }
    return n;
}

static int set_controls(snref_state *s, const char *list)
{
    const char *p = list;
    while (p && *p) {
        const char *end = strchr(p, ','), *eq;
        char name[64], *e;
        double v;
        int c;
        if (!end) end = p + strlen(p);
        eq = memchr(p, '=', (size_t)(end - p));
        if (!eq || eq == p || (size_t)(eq - p) >= sizeof name) { fprintf(stderr, PROG ": --controls: '%.*s': want NAME=VALUE\n", (int)(end - p), p); return -1; }
        memcpy(name, p, (size_t)(eq - p)); name[eq - p] = 0;
        if ((c = snref_find_control(s->m, name)) < 0 || s->m->kkind[c] != SN_CTL_ABSTRACT) {
            fprintf(stderr, PROG ": --controls: '%s' is not an abstract control of the description\n", name);
            return -1;
        }
        v = strtod(eq + 1, &e);
        if (e != end || !isfinite(v) || fabs(v) >= 32768) { fprintf(stderr, PROG ": --controls: %s: not a number in (-32768, 32768)\n", name); return -1; }
        snref_set_control(s, (unsigned)c, v);
        p = *end ? end + 1 : end;
    }
    return 0;
}

/* local rotations -> "J:ax,ay,az,deg+..." (non-identity joints; "rest" if none) */
static void pose_string(const snref_model *m, const double *local, char *out, size_t n)
{
    size_t l = 0;
    unsigned j;
    out[0] = 0;
    for (j = 0; j < m->nJ; j++) {
        double r[3], th;
        sb_quat_rotvec(local + 4 * j, r);
        th = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        if (th < 1e-12) continue;
        l += (size_t)snprintf(out + l, l < n ? n - l : 0, "%s%s:%.9g,%.9g,%.9g,%.9g", l ? "+" : "", m->jname[j], r[0] / th, r[1] / th, r[2] / th, th * 180 / PI);
    }
    if (!l) snprintf(out, n, "rest");
}

/* ---------------- picture ---------------- */


/* one panel: surf coloured red by |surf - ref| / scale (ref NULL: flesh) */
static int panel(rs_image *out, const snref_model *m, const double *surf, const double *ref, double scale, const float lo[3], const float hi[3],
                 double az, double el, const char *l1, const char *l2)
{
    return rs_heat_panel(out, surf, ref, scale, m->nS, m->tris, m->nT, lo, hi, az, el, l1, l2);
}

static int picture(const char *path, const snref_model *m, int np, const double *const *surf, const double *const *ref, const double *scale,
                   const char *const *l1, const char *const *l2, double az, double el)
{
    enum { PW = 480, PH = 400 };
    rs_image img, pane;
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    unsigned i, k;
    int p, rc = 0;
    char err[300];
    const uint8_t line[3] = {90, 90, 90};
    for (p = 0; p < np; p++)
        for (i = 0; i < m->nS; i++)
            for (k = 0; k < 3; k++) {
                float x = (float)surf[p][3 * i + k];
                if (x < lo[k]) lo[k] = x;
                if (x > hi[k]) hi[k] = x;
            }
    if (rs_image_alloc(&img, np * PW, PH)) return -1;
    if (rs_image_alloc(&pane, PW, PH)) { rs_image_free(&img); return -1; }
    for (p = 0; p < np && !rc; p++) {
        rc = panel(&pane, m, surf[p], ref[p], scale[p], lo, hi, az, el, l1[p], l2[p]);
        if (!rc) { rs_blit(&img, p * PW, 0, &pane); if (p) rs_fill(&img, p * PW - 1, 0, 2, PH, line); }
    }
    if (!rc) { rc = png_write(path, img.rgb, img.w, img.h, err, sizeof err); if (rc) fprintf(stderr, PROG ": %s\n", err); }
    rs_image_free(&pane); rs_image_free(&img);
    return rc;
}

/* ---------------- figures ---------------- */

/* residual of a against target, as fractions of target's displacement from base: rms and max */
static unsigned worst_at;
static void residual(const double *a, const double *target, const double *base, unsigned n, double *rms, double *mx, double *dmax)
{
    double r2 = 0, d2 = 0, rm = 0, dm = 0;
    unsigned i, k;
    worst_at = 0;
    for (i = 0; i < n; i++) {
        double r = 0, d = 0;
        for (k = 0; k < 3; k++) {
            r += (a[3 * i + k] - target[3 * i + k]) * (a[3 * i + k] - target[3 * i + k]);
            d += (target[3 * i + k] - base[3 * i + k]) * (target[3 * i + k] - base[3 * i + k]);
        }
        r2 += r; d2 += d; dm = fmax(dm, sqrt(d));
        if (sqrt(r) > rm) { rm = sqrt(r); worst_at = i; }
    }
    *rms = d2 > 0 ? sqrt(r2 / d2) : 0;
    *mx = dm > 0 ? rm / dm : 0;
    if (dmax) *dmax = dm;
}

/* ---------------- options ---------------- */

typedef struct {
    const char *cmd, *desc, *out, *pose, *features, *joints, *controls, *control, *points, *rigs, *png, *name, *bounds, *export_rig;
    const char *target[SB_TAU_MAX];
    int ntarget, quiet, rigs_off, max_iter, progress, geometry, pose_skinned, lbfgsb;
    double omega, lambda, az, el;
} opts_t;

static int parse(int argc, char **argv, opts_t *o)
{
    int i;
    memset(o, 0, sizeof *o);
    o->omega = 1e-5; o->lambda = 1e-3; o->az = 30; o->el = 15; o->max_iter = 3000; o->progress = 10;
    if (argc < 2) { usage(stderr); return 2; }
    for (i = 1; i < argc; i++) if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) { usage(stdout); return 1; }
    o->cmd = argv[1];
    if (strcmp(o->cmd, "fit-surface") && strcmp(o->cmd, "fit-pose") && strcmp(o->cmd, "fit-points") && strcmp(o->cmd, "export")) {
        fprintf(stderr, PROG ": unknown command '%s' (fit-surface, fit-pose, fit-points, export, retarget; --help)\n", o->cmd);
        return 2;
    }
    for (i = 2; i < argc; i++) {
        const char *a = argv[i];
        int more = i + 1 < argc;
#define ARG(name, field) if (!strcmp(a, name)) { if (!more) { fprintf(stderr, PROG ": %s needs a value\n", name); return 2; } field = argv[++i]; continue; }
        ARG("-o", o->out) ARG("--pose", o->pose) ARG("--features", o->features) ARG("--joints", o->joints) ARG("--controls", o->controls)
        ARG("--control", o->control) ARG("--points", o->points) ARG("--rigs", o->rigs) ARG("--png", o->png) ARG("--name", o->name)
        ARG("--bounds", o->bounds)
#undef ARG
        if (!strcmp(a, "--target")) {
            if (!more) { fprintf(stderr, PROG ": --target needs a value\n"); return 2; }
            if (o->ntarget >= SB_TAU_MAX - 1) { fprintf(stderr, PROG ": at most %d targets\n", SB_TAU_MAX - 1); return 2; }
            o->target[o->ntarget++] = argv[++i];
            continue;
        }
        if (!strcmp(a, "--omega") || !strcmp(a, "--lambda") || !strcmp(a, "--max-iter") || !strcmp(a, "--progress")) {
            char *e;
            double v;
            if (!more) { fprintf(stderr, PROG ": %s needs a value\n", a); return 2; }
            v = strtod(argv[++i], &e);
            if (*e || e == argv[i] || !isfinite(v) || v < 0) { fprintf(stderr, PROG ": %s: '%s' is not a non-negative number\n", a, argv[i]); return 2; }
            if (!strcmp(a, "--omega")) o->omega = v;
            else if (!strcmp(a, "--lambda")) o->lambda = v;
            else if (!strcmp(a, "--max-iter")) o->max_iter = (int)fmin(v, 1e8);
            else o->progress = (int)fmin(v, 1e8);
            continue;
        }
        if (!strcmp(a, "--view")) {
            if (!more || sscanf(argv[++i], "%lf,%lf", &o->az, &o->el) != 2) { fprintf(stderr, PROG ": --view AZ,EL\n"); return 2; }
            continue;
        }
        if (!strcmp(a, "--quiet")) { o->quiet = 1; continue; }
        if (!strcmp(a, "--rigs-off")) { o->rigs_off = 1; continue; }
        if (!strcmp(a, "--geometry")) { o->geometry = 1; continue; }
        if (!strcmp(a, "--pose-skinned")) { o->pose_skinned = 1; continue; }
        if (!strcmp(a, "--optimizer")) {   /* fit-surface: cg (default, exact) or lbfgsb */
            if (!more || (strcmp(argv[i + 1], "cg") && strcmp(argv[i + 1], "lbfgsb"))) { fprintf(stderr, PROG ": --optimizer cg|lbfgsb\n"); return 2; }
            o->lbfgsb = !strcmp(argv[++i], "lbfgsb");
            continue;
        }
        if (a[0] == '-') { fprintf(stderr, PROG ": unknown option '%s' (--help)\n", a); return 2; }
        if (!o->desc) o->desc = a;
        else if (!strcmp(o->cmd, "export") && !o->export_rig) o->export_rig = a;
        else { fprintf(stderr, PROG ": unexpected argument '%s'\n", a); return 2; }
    }
    if (!o->desc) { fprintf(stderr, PROG ": %s: missing DESCRIPTION\n", o->cmd); return 2; }
    return 0;
}

static FILE *check_readable(const char *path, const char *what)
{
    FILE *f = fopen(path, "r");
    if (!f) fprintf(stderr, PROG ": cannot open %s '%s'\n", what, path);
    return f;
}

/* ---------------- commands ---------------- */

static int cmd_export(const opts_t *o)
{
    sb_fit F[2];
    int a[2], i, k, l, nl, rc = 1;
    double *Q[2] = {NULL, NULL};
    const sb_model *om[2];
    const double *Qc[2];
    char note[1200];
    if (!o->export_rig || !o->out) { fprintf(stderr, PROG ": export DESC RIG -o OUT.rig\n"); return 2; }
    memset(F, 0, sizeof F);
    if (sb_fit_open(&F[0], o->desc, 1)) return 1;
    nl = F[0].d.levels > 1 ? 2 : 1;   /* 'levels 2': level 1's rig too, integrated on its own lattice */
    if (nl > 1 && sb_fit_open_level(&F[1], o->desc, 1, 1)) { sb_fit_close(&F[0]); return 1; }
    for (l = 0; l < nl; l++) {
        for (a[l] = 0; a[l] < F[l].o.nrig && strcmp(F[l].o.rig[a[l]].def.name, o->export_rig); a[l]++) {}
        if (a[l] == F[l].o.nrig) { fprintf(stderr, PROG ": the description has no rig '%s'\n", o->export_rig); rc = 2; goto done; }
        Q[l] = calloc(3 * (size_t)F[l].o.nf + 3, sizeof *Q[l]);
        for (i = 0; i < F[l].o.rig[a[l]].n; i++) for (k = 0; k < 3; k++) Q[l][3 * F[l].o.rig[a[l]].vert[i] + k] = F[l].o.rig[a[l]].Q[3 * i + k];
        om[l] = &F[l].o; Qc[l] = Q[l];
    }
    snprintf(note, sizeof note, "exported by sinew-rig from rig '%s' of %s (template %s, strength %g): forces at eta = 1%s", o->export_rig, o->desc,
             sb_rig_tpl_name(F[0].o.rig[a[0]].def.tpl), F[0].o.rig[a[0]].def.s, nl > 1 ? "\nlevels 2: a fit on each level's lattice (level 0, then level 1)" : "");
    if (sb_rigfile_write_fits(o->out, nl, om, &F[0].mesh, Qc, note)) fprintf(stderr, PROG ": %s\n", sb_error());
    else {
        rc = 0;
        if (!o->quiet && nl == 1) printf("sinew-rig: wrote %s (%d forces of rig '%s')\n", o->out, F[0].o.rig[a[0]].n, o->export_rig);
        if (!o->quiet && nl > 1)
            printf("sinew-rig: wrote %s (%d forces of rig '%s' on level 0, cell %g; %d on level 1, cell %g)\n", o->out, F[0].o.rig[a[0]].n, o->export_rig,
                   F[0].o.c, F[1].o.rig[a[1]].n, F[1].o.c);
    }
done:
    free(Q[0]); free(Q[1]);
    sb_fit_close(&F[0]);
    if (nl > 1) sb_fit_close(&F[1]);
    return rc;
}

/* the pose for fit-surface / fit-pose: --pose, or fitted to --features on the (first) target */
static int get_pose(sb_fit *F, const opts_t *o, const double *target, double *local, snref_xform *pose, char *what, size_t whatn, double *secs, int *iters)
{
    const snref_model *m = &F->m;
    unsigned j;
    *secs = 0; *iters = 0;
    for (j = 0; j < 4 * m->nJ; j++) local[j] = (j % 4 == 3);
    if (o->pose && sb_static_pose(&F->s, o->pose, pose, local, what, whatn)) return 2;
    if (o->features) {
        int feat[4096], nf, joints[64], nj = 0, k;
        double *tg, t0 = sb_now(), root[3] = {0, 0, 0};
        sb_opt_opts oo;
        sb_opt_result rr;
        if ((nf = parse_ints(o->features, feat, 4096, "--features")) < 0) return 2;
        for (k = 0; k < nf; k++)
            if (feat[k] >= (int)m->nS) { fprintf(stderr, PROG ": --features: vertex %d out of range (the mesh has %u)\n", feat[k], m->nS); return 2; }
        if (o->joints) { if ((nj = parse_joints(m, o->joints, joints, 64)) < 0) return 2; }
        else for (j = 0; j < m->nJ && nj < 64; j++) if (m->jparent[j] >= 0) joints[nj++] = (int)j;
        if (nj == 0) { fprintf(stderr, PROG ": no joints to fit\n"); return 2; }
        if (3 * nj > 3 * nf) fprintf(stderr, PROG ": warning: %d feature points for %d joint rotations (%d unknowns): the pose is underdetermined\n", nf, nj, 3 * nj);
        tg = malloc(3 * (size_t)nf * sizeof *tg);
        for (k = 0; k < nf; k++) memcpy(tg + 3 * k, target + 3 * feat[k], 3 * sizeof *tg);
        sb_opt_defaults(&oo);
        oo.pgtol = 1e-10; oo.max_iter = o->max_iter; oo.verbose = o->quiet ? 0 : o->progress; oo.label = "fit-pose";
        F->pose_static = !o->pose_skinned;
        F->pose_rig_scale = o->rigs_off ? 0 : 1;
        if (sb_fit_pose(F, feat, nf, tg, joints, nj, local, &oo, &rr)) { free(tg); return 1; }
        free(tg);
        sb_pose_from_local(m, local, root, pose);
        pose_string(m, local, what, whatn);
        *secs = sb_now() - t0; *iters = rr.iterations;
        if (!o->quiet) printf("fit-pose: %d feature points, %d joints: rms feature distance %.4g mesh units (%.3g cells), %d iterations, %.2f s\n",
                              nf, nj, sqrt(rr.f) * m->cell * m->unit, sqrt(rr.f), rr.iterations, *secs);
    } else if (!o->pose) {
        double root[3] = {0, 0, 0};
        sb_pose_from_local(m, local, root, pose);
        snprintf(what, whatn, "rest");
    }
    return 0;
}

static int cmd_fit_pose(const opts_t *o)
{
    sb_fit F;
    double *target, *local, secs;
    snref_xform *pose;
    char what[4096];
    int rc, it;
    if (o->ntarget != 1 || !o->features) { fprintf(stderr, PROG ": fit-pose DESC --target T.obj --features V1,V2,... [--joints ...]\n"); return 2; }
    {   FILE *f = check_readable(o->target[0], "target"); if (!f) return 2; fclose(f); }
    if (sb_fit_open(&F, o->desc, 1)) return 1;
    if (!(target = read_obj_vertices(o->target[0], F.mesh.nv))) { sb_fit_close(&F); return 2; }
    if (o->controls && set_controls(&F.s, o->controls)) { free(target); sb_fit_close(&F); return 2; }
    local = malloc(4 * (size_t)F.m.nJ * sizeof *local);
    pose = malloc(F.m.nJ * sizeof *pose);
    rc = get_pose(&F, o, target, local, pose, what, sizeof what, &secs, &it);
    if (!rc) {
        printf("pose %s\n", what);
        if (o->out) {
            char buf[4200];
            int n = snprintf(buf, sizeof buf, "%s\n", what);
            if (sb_write_file(o->out, (const unsigned char *)buf, (size_t)n)) { fprintf(stderr, PROG ": %s\n", sb_error()); rc = 1; }
        }
    }
    free(target); free(local); free(pose);
    sb_fit_close(&F);
    return rc;
}

static int cmp_gamma(const void *a, const void *b)
{
    double x = ((const double *)a)[0], y = ((const double *)b)[0];
    return (x > y) - (x < y);
}

/* fit-surface on level 1 of 'levels 2' (F1 opened by sb_fit_open_level): the same target,
 * pose (--pose re-read on level 1's model, else the fitted or rest rotations local), controls
 * and omega on level 1's own lattice; eta1 (F1->o.nf x 3) the fit, a summary in sum. 0, 1, 2 */
static int fit_level1(sb_fit *F1, const opts_t *o, const double *target, const double *local, sb_opt_opts oo, double *eta1, char *sum, size_t sumn)
{
    const snref_model *m = &F1->m;
    snref_xform *pose = malloc(m->nJ * sizeof *pose);
    double *base = malloc(3 * (size_t)m->nS * sizeof *base), *fit = malloc(3 * (size_t)m->nS * sizeof *fit), *best = malloc(3 * (size_t)m->nS * sizeof *best);
    double root[3] = {0, 0, 0}, rms, mx, rrms, rmx, t0 = sb_now();
    char what[4096];
    sb_opt_result rr;
    sb_surf_reach reach;
    int rc = 2;
    if (o->controls && set_controls(&F1->s, o->controls)) goto done;
    if (o->pose) { if (sb_static_pose(&F1->s, o->pose, pose, NULL, what, sizeof what)) goto done; }
    else sb_pose_from_local(m, local, root, pose);
    rc = 1;
    if (sb_fit_set_pose(F1, pose, o->rigs_off ? 0 : 1)) goto done;
    memcpy(base, F1->surf0, 3 * (size_t)m->nS * sizeof *base);
    oo.label = "fit-surface level 1";
    if (sb_fit_surface(F1, target, o->omega, &oo, &rr, eta1, fit)) goto done;
    residual(fit, target, base, m->nS, &rms, &mx, NULL);
    if (sb_fit_surface_reach(F1, target, &oo, &reach, best)) goto done;
    residual(fit, best, base, m->nS, &rrms, &rmx, NULL);
    snprintf(sum, sumn, "level 1 (cell %g, %u free lattice vertices): residual rms %.3g%%, max %.3g%% of the target's displacement; "
             "best reachable rms %.3g%%, max %.3g%%; the fit against it rms %.3g%%, max %.3g%%; %d iterations",
             m->cell * m->unit, m->nF, 100 * rms, 100 * mx, 100 * reach.rms, 100 * reach.max, 100 * rrms, 100 * rmx, rr.iterations);
    if (!o->quiet) printf("fit-surface: %s (%s), %.2f s\n", sum, rr.status <= 1 ? "converged" : rr.status == 2 ? "max-iter" : "line search failed", sb_now() - t0);
    rc = 0;
done:
    free(pose); free(base); free(fit); free(best);
    return rc;
}

static int cmd_fit_surface(const opts_t *o)
{
    sb_fit F, F1;
    const snref_model *m;
    double *tg[SB_TAU_MAX], gam[SB_TAU_MAX], *local = NULL, *eta = NULL, *eta1 = NULL, *fit = NULL, *base = NULL, *rest = NULL, *best = NULL, secs_pose, t0, rms, mx, dmax;
    double rrms = 0, rmx = 0;
    sb_surf_reach reach;
    double samples[2 * SB_TAU_MAX];
    snref_xform *pose = NULL;
    char what[4096], tau[512], *comment = NULL, sum1[512] = "";
    int i, k, rc = 2, ctl, primary = 0, it_pose, ns = 0, have_g[SB_TAU_MAX];
    sb_opt_opts oo;
    sb_opt_result rr;
    size_t cl;
    memset(tg, 0, sizeof tg);
    memset(&F1, 0, sizeof F1);
    if (!o->ntarget || !o->control || !o->out) { fprintf(stderr, PROG ": fit-surface DESC --target T.obj --control NAME -o OUT.rig (--help)\n"); return 2; }
    if (o->pose && o->features && 0) return 2;
    for (i = 0; i < o->ntarget; i++) {   /* TARGET[@GAMMA] */
        const char *at = strrchr(o->target[i], '@');
        have_g[i] = 0; gam[i] = 0;
        if (at && !strchr(at, '/')) {
            char *e;
            gam[i] = strtod(at + 1, &e);
            if (*e || e == at + 1 || !isfinite(gam[i]) || fabs(gam[i]) > 16384) { fprintf(stderr, PROG ": --target %s: the value after @ is not a control value\n", o->target[i]); return 2; }
            have_g[i] = 1;
        }
    }
    if (sb_fit_open(&F, o->desc, 1)) return 1;
    m = &F.m;
    rc = 2;
    if ((ctl = snref_find_control(m, o->control)) < 0) {
        unsigned c;
        fprintf(stderr, PROG ": --control: the description has no control '%s' (declare it: 'control %s' or 'control %s angle JOINT AX AY AZ'); controls:",
                o->control, o->control, o->control);
        for (c = 0; c < m->nK; c++) fprintf(stderr, " %s", m->kname[c]);
        fprintf(stderr, "\n");
        goto done;
    }
    for (i = 0; i < o->ntarget; i++) {
        char path[1024];
        const char *at = strrchr(o->target[i], '@');
        size_t l = have_g[i] ? (size_t)(at - o->target[i]) : strlen(o->target[i]);
        snprintf(path, sizeof path, "%.*s", (int)l, o->target[i]);
        if (!(tg[i] = read_obj_vertices(path, F.mesh.nv))) goto done;
    }
    if ((unsigned)F.mesh.nv != m->nS) { fprintf(stderr, PROG ": the baked surface has %u vertices, the mesh %d\n", m->nS, F.mesh.nv); rc = 1; goto done; }
    if (o->controls && set_controls(&F.s, o->controls)) goto done;
    /* the primary target: the largest |gamma| (the first if none given) */
    for (i = 1; i < o->ntarget; i++) if (have_g[i] && (!have_g[primary] || fabs(gam[i]) > fabs(gam[primary]))) primary = i;
    local = malloc(4 * (size_t)m->nJ * sizeof *local);
    pose = malloc(m->nJ * sizeof *pose);
    eta = calloc(3 * (size_t)F.o.nf + 3, sizeof *eta);
    fit = malloc(3 * (size_t)m->nS * sizeof *fit);
    base = malloc(3 * (size_t)m->nS * sizeof *base);
    rest = malloc(3 * (size_t)m->nS * sizeof *rest);
    best = malloc(3 * (size_t)m->nS * sizeof *best);
    if ((rc = get_pose(&F, o, tg[primary], local, pose, what, sizeof what, &secs_pose, &it_pose))) goto done;
    rc = 1;
    {   /* the rest shape for the picture */
        snref_xform *id = malloc(m->nJ * sizeof *id);
        double root[3] = {0, 0, 0}, *l0 = malloc(4 * (size_t)m->nJ * sizeof *l0);
        unsigned j;
        for (j = 0; j < 4 * m->nJ; j++) l0[j] = (j % 4 == 3);
        sb_pose_from_local(m, l0, root, id);
        if (sb_fit_set_pose(&F, id, o->rigs_off ? 0 : 1)) { free(id); free(l0); goto done; }
        memcpy(rest, F.surf0, 3 * (size_t)m->nS * sizeof *rest);
        free(id); free(l0);
    }
    if (sb_fit_set_pose(&F, pose, o->rigs_off ? 0 : 1)) goto done;
    memcpy(base, F.surf0, 3 * (size_t)m->nS * sizeof *base);
    if (!have_g[primary]) gam[primary] = m->kkind[ctl] == SN_CTL_ABSTRACT ? 1.0 : snref_get_control(&F.s, (unsigned)ctl);
    if (!(fabs(gam[primary]) > 1e-9)) {
        fprintf(stderr, PROG ": the target's control value is 0 (the rig Q(gamma) = tau(gamma) eta would be off there): give TARGET@GAMMA%s\n",
                m->kkind[ctl] == SN_CTL_ABSTRACT ? "" : " or pose the joint");
        rc = 2;
        goto done;
    }
    if (!o->quiet) printf("fit-surface: %s: pose %s; control %s = %g at the target; %u free lattice vertices (%u unknowns), omega %g\n",
                          o->desc, what, o->control, gam[primary], m->nF, 3 * m->nF, o->omega);
    sb_opt_defaults(&oo);
    oo.pgtol = 1e-10; oo.ftol = 1e-15; oo.max_iter = o->max_iter; oo.verbose = o->quiet ? 0 : o->progress; oo.label = "fit-surface";
    oo.max_iter = o->lbfgsb ? o->max_iter : 100000;   /* the CG solve is exact: the cap only guards against a broken system */
    F.surf_lbfgsb = o->lbfgsb;
    t0 = sb_now();
    if (sb_fit_surface(&F, tg[primary], o->omega, &oo, &rr, eta, fit)) goto done;
    residual(fit, tg[primary], base, m->nS, &rms, &mx, &dmax);
    if (!o->quiet) printf("fit-surface: %d iterations (%s, %s), %.2f s: residual rms %.3g%%, max %.3g%% of the target's displacement (largest %.4g mesh units); "
                          "worst at mesh vertex %u (%.4g, %.4g, %.4g)\n",
                          rr.iterations, o->lbfgsb ? "L-BFGS-B" : "conjugate gradients",
                          rr.status == 0 ? "converged" : rr.status == 1 ? "converged (ftol)" : rr.status == 2 ? "max-iter" : "line search failed",
                          sb_now() - t0, 100 * rms, 100 * mx, dmax, worst_at, tg[primary][3 * worst_at], tg[primary][3 * worst_at + 1], tg[primary][3 * worst_at + 2]);
    /* what any rig at this pose can reach: the target's share on bone-carried surface, the best fit by the free vertices alone */
    if (sb_fit_surface_reach(&F, tg[primary], &oo, &reach, best)) goto done;
    residual(fit, best, base, m->nS, &rrms, &rmx, NULL);
    if (!o->quiet) {
        printf("fit-surface: target on bone-carried surface: %.2g%% of its sum |d|^2 on vertices with at least half their embedding weight on skeleton vertices (%.2g%% all)\n",
               100 * reach.skel_half, 100 * reach.skel_all);
        printf("fit-surface: best reachable (free lattice vertices alone, omega 0; a lower bound): residual rms %.3g%%, max %.3g%% of the target's displacement\n",
               100 * reach.rms, 100 * reach.max);
        printf("fit-surface: the fit against that best (the reachable part): rms %.3g%%, max %.3g%% of its displacement\n", 100 * rrms, 100 * rmx);
        printf("fit-surface: with the skeleton vertices free too (as if no bone carried any; the lattice's resolution): best rms %.3g%%, max %.3g%%\n",
               100 * reach.rms_all, 100 * reach.max_all);
    }
    if (F.d.levels > 1) {   /* 'levels 2': level 1's own fit on its own lattice (its rigs are not level 0's spread: runtime/LEVELS.md §2) */
        if (sb_fit_open_level(&F1, o->desc, 1, 1)) goto done;
        eta1 = calloc(3 * (size_t)F1.o.nf + 3, sizeof *eta1);
        if ((rc = fit_level1(&F1, o, tg[primary], local, oo, eta1, sum1, sizeof sum1))) goto done;
        rc = 1;
    }
    /* tau samples: (0, 0), the primary at 1, the others by least squares on the rig's shape (level 0's) */
    samples[ns * 2] = gam[primary]; samples[ns * 2 + 1] = 1; ns++;
    for (i = 0; i < o->ntarget; i++) {
        double num = 0, den = 0;
        unsigned s;
        if (i == primary) continue;
        if (!have_g[i]) { fprintf(stderr, PROG ": with several targets each needs its control value: TARGET@GAMMA\n"); rc = 2; goto done; }
        for (s = 0; s < 3 * m->nS; s++) { double u = fit[s] - base[s]; num += u * (tg[i][s] - base[s]); den += u * u; }
        samples[ns * 2] = gam[i]; samples[ns * 2 + 1] = den > 0 ? num / den : 0; ns++;
        if (!o->quiet) printf("fit-surface: target %s at %s = %g: tau %.6g (least squares on the fitted shape)\n", o->target[i], o->control, gam[i], samples[ns * 2 - 1]);
    }
    {   int has0 = 0; for (i = 0; i < ns; i++) has0 |= samples[2 * i] == 0; if (!has0) { samples[2 * ns] = 0; samples[2 * ns + 1] = 0; ns++; } }
    qsort(samples, (size_t)ns, 2 * sizeof(double), cmp_gamma);
    for (i = 1; i < ns; i++) if (samples[2 * i] == samples[2 * i - 2]) { fprintf(stderr, PROG ": two targets at %s = %g\n", o->control, samples[2 * i]); rc = 2; goto done; }
    for (i = 0, k = 0; i < ns; i++) k += snprintf(tau + k, sizeof tau - (size_t)k, "%s%.9g %.9g", i ? "  " : "", samples[2 * i], samples[2 * i + 1]);
    /* outputs: picture first (so a failed picture leaves no rig file), then the rig file */
    if (o->png) {
        const double *S[4], *R[4];
        double sc[4];
        const char *l1[4] = {"rest", "unrigged", "rigged (fit)", "target"}, *l2[4];
        char s2[160], s3[160], s4[160];
        S[0] = rest; S[1] = base; S[2] = fit; S[3] = tg[primary];
        R[0] = NULL; R[1] = tg[primary]; R[2] = tg[primary]; R[3] = base;
        sc[0] = 0; sc[1] = sc[2] = sc[3] = dmax;
        snprintf(s2, sizeof s2, "red: distance to the target (%.3g = full red)", dmax);
        snprintf(s3, sizeof s3, "residual rms %.2g%%, max %.2g%%", 100 * rms, 100 * mx);
        snprintf(s4, sizeof s4, "red: displacement from unrigged");
        l2[0] = NULL; l2[1] = s2; l2[2] = s3; l2[3] = s4;
        if (picture(o->png, m, 4, S, R, sc, l1, l2, o->az, o->el)) goto done;
    }
    cl = strlen(o->desc) + strlen(what) + sizeof sum1 + 2048;
    comment = malloc(cl);
    {
        size_t n = 0;
        n += (size_t)snprintf(comment + n, cl - n, "surface rig fitted by sinew-rig fit-surface (seed 003 eq. 13-14) from %s\n", o->desc);
        for (i = 0; i < o->ntarget && n < cl; i++) n += (size_t)snprintf(comment + n, cl - n, "target %s\n", o->target[i]);
        n += (size_t)snprintf(comment + n, cl - n, "pose %s\ncontrol %s, omega %g%s\n", what, o->control, o->omega, o->rigs_off ? ", description rigs off" : "");
        n += (size_t)snprintf(comment + n, cl - n, "residual rms %.3g%%, max %.3g%% of the target displacement; %d iterations\n", 100 * rms, 100 * mx, rr.iterations);
        n += (size_t)snprintf(comment + n, cl - n, "best reachable (free lattice vertices alone): rms %.3g%%, max %.3g%%; the fit against it: rms %.3g%%, max %.3g%%\n"
                              "best with the skeleton vertices free too: rms %.3g%%, max %.3g%%\n",
                              100 * reach.rms, 100 * reach.max, 100 * rrms, 100 * rmx, 100 * reach.rms_all, 100 * reach.max_all);
        if (sum1[0]) n += (size_t)snprintf(comment + n, cl - n, "levels 2: a fit on each level's lattice (level 0 above, then level 1); %s\n", sum1);
        {   /* the file's own name (not its directory): the bytes depend on the inputs only */
            const char *b = strrchr(o->out, '/');
            snprintf(comment + n, cl - n, "use: rig_file %s %s %s tau %s", o->name ? o->name : o->control, b ? b + 1 : o->out, o->control, tau);
        }
    }
    {
        const sb_model *om[2];
        const double *Qs[2];
        om[0] = &F.o; om[1] = &F1.o; Qs[0] = eta; Qs[1] = eta1;
        if (sb_rigfile_write_fits(o->out, eta1 ? 2 : 1, om, &F.mesh, Qs, comment)) { fprintf(stderr, PROG ": %s\n", sb_error()); if (o->png) remove(o->png); goto done; }
    }
    rc = 0;
    if (!o->quiet) {
        printf("fit-surface: wrote %s%s%s\n", o->out, o->png ? " and " : "", o->png ? o->png : "");
        printf("rig_file %s %s %s tau %s\n", o->name ? o->name : o->control, o->out, o->control, tau);
    }
done:
    for (i = 0; i < o->ntarget; i++) free(tg[i]);
    free(local); free(pose); free(eta); free(eta1); free(fit); free(base); free(rest); free(best); free(comment);
    sb_fit_close(&F);
    if (F1.m.nV || F1.o.nv) sb_fit_close(&F1);
    return rc;
}

/* fit-points with 'levels 2': the strengths eta (the rigs' own geometry) evaluated on level 1's
 * lattice at the same pose and controls (the bake integrates the fitted templates on each level
 * itself, so there is no level-1 output: this reports what level 1 makes of them). 0, 1, 2 */
static int points_level1(const sb_fit *F, const opts_t *o, const int *rigs, int nr, const int *vert, const double *tgt, int np, const double *eta)
{
    sb_fit F1;
    snref_xform *pose;
    double s0[64], cm, cm0 = F->m.cell * F->m.unit, c1, c1s, cl0;
    char what[4096];
    int a, rc = 2;
    if (sb_fit_open_level(&F1, o->desc, 1, 1)) return 1;
    pose = malloc(F1.m.nJ * sizeof *pose);
    cm = F1.m.cell * F1.m.unit;
    if (o->controls && set_controls(&F1.s, o->controls)) goto done;
    if (sb_static_pose(&F1.s, o->pose ? o->pose : "rest", pose, NULL, what, sizeof what)) goto done;
    if (o->controls && set_controls(&F1.s, o->controls)) goto done;
    rc = 1;
    if (sb_fit_set_pose(&F1, pose, 1.0)) goto done;
    for (a = 0; a < nr; a++) s0[a] = F->o.rig[rigs[a]].def.s;
    c1 = sb_fit_points_cost(&F1, rigs, nr, vert, tgt, np, 0, eta, NULL);
    c1s = sb_fit_points_cost(&F1, rigs, nr, vert, tgt, np, 0, s0, NULL);
    cl0 = sb_fit_points_cost((sb_fit *)F, rigs, nr, vert, tgt, np, 0, eta, NULL);
    if (!isfinite(c1) || !isfinite(c1s) || !isfinite(cl0)) { fprintf(stderr, PROG ": fit-points: level 1: the evaluation failed\n"); goto done; }
    if (!o->quiet)
        printf("fit-points: rms point distance at the fitted strengths: level 0 %.4g mesh units, level 1 (cell %g) %.4g (%.4g at the description's strengths)\n",
               sqrt(cl0) * cm0, cm, sqrt(c1) * cm, sqrt(c1s) * cm);
    rc = 0;
done:
    free(pose);
    sb_fit_close(&F1);
    return rc;
}

static int cmd_fit_points(const opts_t *o)
{
    sb_fit F;
    const snref_model *m;
    int rigs[64], nr = 0, vert[1024], np = 0, rc = 2, a;
    double tgt[3 * 1024], eta[64], lo[64], hi[64], blo = -1e6, bhi = 1e6, t0;
    static sb_rigdef fitted[64];
    snref_xform *pose = NULL;
    char what[4096];
    sb_opt_opts oo;
    sb_opt_result rr;
    if (!o->points || !o->rigs) { fprintf(stderr, PROG ": fit-points DESC --points FILE --rigs R1,... (--help)\n"); return 2; }
    if (o->bounds && (sscanf(o->bounds, "%lf,%lf", &blo, &bhi) != 2 || !(blo <= bhi))) { fprintf(stderr, PROG ": --bounds LO,HI with LO <= HI\n"); return 2; }
    {   /* points file */
        FILE *f = check_readable(o->points, "points file");
        char line[512];
        int ln = 0;
        if (!f) return 2;
        while (fgets(line, sizeof line, f)) {
            char *h = strchr(line, '#');
            int v, nn;
            double x[3];
            ln++;
            if (h) *h = 0;
            if (sscanf(line, " %d %lf %lf %lf %n", &v, &x[0], &x[1], &x[2], &nn) != 4) {
                if (strspn(line, " \t\r\n") == strlen(line)) continue;
                fprintf(stderr, PROG ": %s:%d: want 'VERTEX X Y Z'\n", o->points, ln); fclose(f); return 2;
            }
            if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2])) { fprintf(stderr, PROG ": %s:%d: non-finite coordinate\n", o->points, ln); fclose(f); return 2; }
            if (np >= 1024) { fprintf(stderr, PROG ": %s: more than 1024 points\n", o->points); fclose(f); return 2; }
            vert[np] = v; memcpy(tgt + 3 * np, x, sizeof x); np++;
        }
        fclose(f);
        if (!np) { fprintf(stderr, PROG ": %s: no points\n", o->points); return 2; }
    }
    if (sb_fit_open(&F, o->desc, 1)) return 1;
    m = &F.m;
    for (a = 0; a < np; a++) if (vert[a] < 0 || vert[a] >= (int)m->nS) { fprintf(stderr, PROG ": %s: vertex %d out of range (the mesh has %u)\n", o->points, vert[a], m->nS); goto done; }
    {
        const char *s = o->rigs;
        while (*s) {
            const char *e = strchr(s, ',');
            size_t l = e ? (size_t)(e - s) : strlen(s);
            for (a = 0; a < F.o.nrig && !(strlen(F.o.rig[a].def.name) == l && !strncmp(F.o.rig[a].def.name, s, l)); a++) {}
            if (a == F.o.nrig) { fprintf(stderr, PROG ": --rigs: the description has no rig '%.*s'\n", (int)l, s); goto done; }
            if (F.o.rig[a].def.tpl == SB_TPL_FILE) { fprintf(stderr, PROG ": --rigs: '%.*s' is a file rig (its strength is not a template parameter)\n", (int)l, s); goto done; }
            if (nr >= 64) { fprintf(stderr, PROG ": --rigs: at most 64\n"); goto done; }
            rigs[nr] = a; eta[nr] = F.o.rig[a].def.s; lo[nr] = blo; hi[nr] = bhi; nr++;
            s = e ? e + 1 : s + l;
        }
    }
    pose = malloc(m->nJ * sizeof *pose);
    if (o->controls && set_controls(&F.s, o->controls)) goto done;
    if (sb_static_pose(&F.s, o->pose ? o->pose : "rest", pose, NULL, what, sizeof what)) goto done;
    if (o->controls && set_controls(&F.s, o->controls)) goto done;   /* over a clip's tracks */
    rc = 1;
    if (sb_fit_set_pose(&F, pose, 1.0)) goto done;
    for (a = 0; a < nr; a++) {
        unsigned r = (unsigned)rigs[a];
        if (snref_tau(m, r, snref_get_control(&F.s, m->rctl[r])) == 0)
            fprintf(stderr, PROG ": warning: rig '%s' is off at its control's value (tau = 0): its strength cannot move the points\n", F.o.rig[r].def.name);
    }
    sb_opt_defaults(&oo);
    oo.pgtol = 1e-12; oo.max_iter = o->max_iter; oo.verbose = o->quiet ? 0 : o->progress; oo.label = "fit-points";
    t0 = sb_now();
    {
        double c0, par[64 * 8], plo[64 * 8], phi[64 * 8];
        int npar = 0;
        if (o->geometry) {
            for (a = 0; a < nr; a++) {
                int na = sb_fit_template_npar(&F, rigs[a]);
                sb_fit_template_get(&F, rigs[a], par + npar);
                sb_fit_template_bounds(&F, rigs[a], plo + npar, phi + npar);
                plo[npar] = blo; phi[npar] = bhi;
                npar += na;
            }
            c0 = sb_fit_template_cost(&F, rigs, nr, vert, tgt, np, o->lambda, par, NULL);
            if (sb_fit_template(&F, rigs, nr, vert, tgt, np, o->lambda, plo, phi, par, &oo, &rr)) goto done;
            for (a = 0, npar = 0; a < nr; a++) {   /* back into the strengths and rigdefs */
                eta[a] = par[npar];
                sb_fit_template_apply(&F, rigs[a], par + npar, &fitted[a]);
                npar += sb_fit_template_npar(&F, rigs[a]);
            }
        } else {
            c0 = sb_fit_points_cost(&F, rigs, nr, vert, tgt, np, o->lambda, eta, NULL);
            if (sb_fit_points(&F, rigs, nr, vert, tgt, np, o->lambda, lo, hi, eta, &oo, &rr)) goto done;
            for (a = 0; a < nr; a++) { fitted[a] = F.d.rigs[rigs[a]]; fitted[a].s = eta[a]; }
        }
        if (!o->quiet) printf("fit-points: %d points, %d rigs%s, pose %s: cost %.6g -> %.6g (C_points: mean squared distance / cell^2), %d iterations, %d evaluations, %.3f s\n",
                              np, nr, o->geometry ? " (strengths and geometry)" : " (strengths)", what, c0, rr.f, rr.iterations, rr.evaluations, sb_now() - t0);
    }
    if (F.d.levels > 1) {   /* 'levels 2': what level 1 makes of the fitted strengths */
        if (o->geometry) { if (!o->quiet) printf("fit-points: level 1 not evaluated with --geometry (the bake integrates the fitted templates on its lattice)\n"); }
        else if ((rc = points_level1(&F, o, rigs, nr, vert, tgt, np, eta))) goto done;
        rc = 1;
    }
    {   /* the description's rig lines with the fitted strengths */
        FILE *f = fopen(o->desc, "r");
        char line[4096], *buf = malloc(64 * 4096 + 256);
        int ln = 0;
        size_t n = 0;
        n += (size_t)sprintf(buf + n, "# sinew-rig fit-points: %d points of %s at pose %s, lambda %g\n", np, o->points, what, o->lambda);
        while (f && fgets(line, sizeof line, f)) {
            ln++;
            for (a = 0; a < nr; a++)
                if (F.o.rig[rigs[a]].def.line == ln) {   /* tokens 5.. (strength, parameters) replaced by the fit */
                    const sb_rigdef *r = &fitted[a];
                    char *p = line;
                    int t, idx[8], ng = 0, g;
                    if (o->geometry) {
                        if (r->tpl == SB_TPL_BUMP) { idx[0] = 0; idx[1] = 1; idx[2] = 2; idx[3] = 3; ng = 4; }
                        else if (r->tpl == SB_TPL_RING) { idx[0] = 0; idx[1] = 1; idx[2] = 2; idx[3] = 6; idx[4] = 7; ng = 5; }
                        else if (r->tpl == SB_TPL_MUSCLE) { for (g = 0; g < 7; g++) idx[g] = g; ng = 7; }
                    }
                    for (t = 0; t < 4; t++) { p += strspn(p, " \t"); p += strcspn(p, " \t"); }
                    n += (size_t)sprintf(buf + n, "%.*s", (int)(p - line), line);
                    for (t = 4; *p && *p != '\n' && *p != '\r'; t++) {   /* token t (0-based) */
                        size_t sp = strspn(p, " \t"), len;
                        int j = -1;
                        n += (size_t)sprintf(buf + n, "%.*s", (int)sp, p);
                        p += sp;
                        len = strcspn(p, " \t\r\n");
                        if (!len) break;
                        for (g = 0; g < ng; g++) if (5 + idx[g] == t) j = idx[g];
                        if (t == 4) n += (size_t)sprintf(buf + n, "%.9g", r->s);
                        else if (j >= 0) n += (size_t)sprintf(buf + n, "%.9g", r->p[j]);
                        else n += (size_t)sprintf(buf + n, "%.*s", (int)len, p);
                        p += len;
                    }
                    n += (size_t)sprintf(buf + n, "%s", p);
                    if (!o->quiet) printf("rig %-14s strength %.9g -> %.9g\n", F.o.rig[rigs[a]].def.name, F.o.rig[rigs[a]].def.s, eta[a]);
                }
        }
        if (f) fclose(f);
        if (o->out && sb_write_file(o->out, (const unsigned char *)buf, n)) { fprintf(stderr, PROG ": %s\n", sb_error()); free(buf); goto done; }
        if (o->out && !o->quiet) printf("fit-points: wrote %s\n", o->out);
        free(buf);
    }
    rc = 0;
done:
    free(pose);
    sb_fit_close(&F);
    return rc;
}

int sb_retarget_cli(int argc, char **argv, const char *prog);   /* tools/sb_retarget_cli.c */

int main(int argc, char **argv)
{
    opts_t o;
    int rc;
    if (argc >= 2 && !strcmp(argv[1], "retarget")) return sb_retarget_cli(argc - 1, argv + 1, PROG " retarget");
    rc = parse(argc, argv, &o);
    if (rc) return rc == 1 ? 0 : rc;
    {   FILE *f = check_readable(o.desc, "description"); if (!f) return 2; fclose(f); }
    if (!strcmp(o.cmd, "export")) return cmd_export(&o);
    if (!strcmp(o.cmd, "fit-pose")) return cmd_fit_pose(&o);
    if (!strcmp(o.cmd, "fit-points")) return cmd_fit_points(&o);
    return cmd_fit_surface(&o);
}
