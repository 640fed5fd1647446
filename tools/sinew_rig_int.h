/* sinew_rig_int.h -- internal to sinew-rig (sinew_rig*.c): its options and the pieces its commands share. */
#ifndef SINEW_RIG_INT_H
#define SINEW_RIG_INT_H
#include "sb.h"
#include "sb_fit.h"
#include "sb_static.h"
#include "sn_format.h"
#include <stdio.h>

#define PROG "sinew-rig"
#define PI 3.14159265358979323846

typedef struct {
    const char *cmd, *desc, *out, *pose, *features, *joints, *controls, *control, *points, *rigs, *png, *name, *bounds, *export_rig;
    const char *target[SB_TAU_MAX];
    int ntarget, quiet, rigs_off, max_iter, progress, geometry, pose_skinned, lbfgsb;
    double omega, lambda, az, el;
} opts_t;

/* inputs (sinew_rig_args.c) */
int sr_parse_ints(const char *s, int *out, int max, const char *what);
double *sr_read_obj_vertices(const char *path, int want);
int sr_parse_joints(const snref_model *m, const char *s, int *out, int max);
int sr_set_controls(snref_state *s, const char *list);
void sr_pose_string(const snref_model *m, const double *local, char *out, size_t n);
FILE *sr_check_readable(const char *path, const char *what);   /* sinew_rig.c */

/* figures and pictures (sinew_rig_report.c) */
extern unsigned sr_worst_at;   /* the vertex of sr_residual's max */
void sr_residual(const double *a, const double *target, const double *base, unsigned n, double *rms, double *mx, double *dmax);
int sr_picture(const char *path, const snref_model *m, int np, const double *const *surf, const double *const *ref, const double *scale,
               const char *const *l1, const char *const *l2, double az, double el);

/* the commands: exit codes */
int sr_get_pose(sb_fit *F, const opts_t *o, const double *target, double *local, snref_xform *pose, char *what, size_t whatn, double *secs, int *iters);
int sr_cmd_export(const opts_t *o);        /* sinew_rig_export.c */
int sr_cmd_fit_pose(const opts_t *o);      /* sinew_rig_pose.c */
int sr_cmd_fit_surface(const opts_t *o);   /* sinew_rig_surface.c */
int sr_cmd_fit_points(const opts_t *o);    /* sinew_rig_points.c */
int sb_retarget_cli(int argc, char **argv, const char *prog);   /* sb_retarget_cli.c */
#endif
