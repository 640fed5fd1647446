/* sinew_rig_pose.c -- sinew-rig fit-pose: the pose of a target mesh, given or fitted to feature points (seed 003 §4.2). */
#include "sinew_rig_int.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* the pose for fit-surface / fit-pose: --pose, or fitted to --features on the (first) target */
int sr_get_pose(sb_fit *F, const opts_t *o, const double *target, double *local, snref_xform *pose, char *what, size_t whatn, double *secs, int *iters)
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
        if ((nf = sr_parse_ints(o->features, feat, 4096, "--features")) < 0) return 2;
        for (k = 0; k < nf; k++)
            if (feat[k] >= (int)m->nS) { fprintf(stderr, PROG ": --features: vertex %d out of range (the mesh has %u)\n", feat[k], m->nS); return 2; }
        if (o->joints) { if ((nj = sr_parse_joints(m, o->joints, joints, 64)) < 0) return 2; }
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
        sr_pose_string(m, local, what, whatn);
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

int sr_cmd_fit_pose(const opts_t *o)
{
    sb_fit F;
    double *target, *local, secs;
    snref_xform *pose;
    char what[4096];
    int rc, it;
    if (o->ntarget != 1 || !o->features) { fprintf(stderr, PROG ": fit-pose DESC --target T.obj --features V1,V2,... [--joints ...]\n"); return 2; }
    {   FILE *f = sr_check_readable(o->target[0], "target"); if (!f) return 2; fclose(f); }
    if (sb_fit_open(&F, o->desc, 1)) return 1;
    if (!(target = sr_read_obj_vertices(o->target[0], F.mesh.nv))) { sb_fit_close(&F); return 2; }
    if (o->controls && sr_set_controls(&F.s, o->controls)) { free(target); sb_fit_close(&F); return 2; }
    local = malloc(4 * (size_t)F.m.nJ * sizeof *local);
    pose = malloc(F.m.nJ * sizeof *pose);
    rc = sr_get_pose(&F, o, target, local, pose, what, sizeof what, &secs, &it);
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
