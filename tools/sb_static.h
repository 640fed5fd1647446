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

#endif
