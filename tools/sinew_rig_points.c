/* sinew_rig_points.c -- sinew-rig fit-points: template rig strengths from dragged surface points (seed 003 §4.3). */
#include "sinew_rig_int.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    if (o->controls && sr_set_controls(&F1.s, o->controls)) goto done;
    if (sb_static_pose(&F1.s, o->pose ? o->pose : "rest", pose, NULL, what, sizeof what)) goto done;
    if (o->controls && sr_set_controls(&F1.s, o->controls)) goto done;
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

int sr_cmd_fit_points(const opts_t *o)
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
        FILE *f = sr_check_readable(o->points, "points file");
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
    if (o->controls && sr_set_controls(&F.s, o->controls)) goto done;
    if (sb_static_pose(&F.s, o->pose ? o->pose : "rest", pose, NULL, what, sizeof what)) goto done;
    if (o->controls && sr_set_controls(&F.s, o->controls)) goto done;   /* over a clip's tracks */
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
