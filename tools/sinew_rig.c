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
#include "sinew_rig_int.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* ---------------- options ---------------- */

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

FILE *sr_check_readable(const char *path, const char *what)
{
    FILE *f = fopen(path, "r");
    if (!f) fprintf(stderr, PROG ": cannot open %s '%s'\n", what, path);
    return f;
}
int main(int argc, char **argv)
{
    opts_t o;
    int rc;
    if (argc >= 2 && !strcmp(argv[1], "retarget")) return sb_retarget_cli(argc - 1, argv + 1, PROG " retarget");
    rc = parse(argc, argv, &o);
    if (rc) return rc == 1 ? 0 : rc;
    {   FILE *f = sr_check_readable(o.desc, "description"); if (!f) return 2; fclose(f); }
    if (!strcmp(o.cmd, "export")) return sr_cmd_export(&o);
    if (!strcmp(o.cmd, "fit-pose")) return sr_cmd_fit_pose(&o);
    if (!strcmp(o.cmd, "fit-points")) return sr_cmd_fit_points(&o);
    return sr_cmd_fit_surface(&o);
}
