/* sinew_rig_export.c -- sinew-rig export: a description rig's baked forces as a rig file. */
#include "sinew_rig_int.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int sr_cmd_export(const opts_t *o)
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
