/* sb_static.h -- sinew-bake --static: the static equilibrium (seed 003 eq. 10)
 * of a baked character at one pose with its rigs' controls set, in double
 * precision, written as an OBJ surface and a PNG picture (tools/DESCRIPTION.md,
 * "Static equilibrium (--static)"). */
#ifndef SB_STATIC_H
#define SB_STATIC_H

typedef struct sb_static_opts {
    const char *pose;       /* "rest", "FILE.clip[@SECONDS]" or "JOINT:AX,AY,AZ,DEG[+JOINT:...]" */
    const char *controls;   /* "name=value,..." (abstract controls), or NULL */
    const char *obj;        /* output OBJ (NULL: <description stem>_static.obj) */
    const char *png;        /* output PNG (NULL: the OBJ path with .png) */
    double az, el;          /* picture view, degrees */
    int quiet;
} sb_static_opts;

/* Bake desc in float64, pose it, set the controls, solve, write. Returns the
 * process exit status: 0, 1 (bake, solve or write failed), 2 (bad pose or
 * controls). Nothing is written unless everything before the writing succeeded. */
int sb_static_run(const char *desc, const sb_static_opts *opt);

/* Shared with sinew-rig (tools/sb_fit.c); need snref.h. POSE as --static takes
 * it -> per-joint transforms pose (nJ) and the local rotations (nJ x 4, x y z w,
 * may be NULL); a clip's control tracks set s's abstract controls. 0, or 2
 * with a message on stderr. */
#ifdef SNREF_H
int sb_static_pose(snref_state *s, const char *spec, snref_xform *pose, double *local, char *what, size_t whatn);
/* local rotations (nJ x 4) and a root offset (mesh units) -> per-joint transforms, as sn_pose_from_local */
void sb_pose_from_local(const snref_model *m, const double *local, const double root[3], snref_xform *out);
#endif

#endif
