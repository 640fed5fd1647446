/* sb_desc.c -- the text character description (format: tools/DESCRIPTION.md): the line reader,
 * the keyword dispatch (sb_desc_*.c) and the checks of the whole description. */
#include "sb_desc_int.h"
#include "sb_gltf.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int parse_line(sb_dctx *c, sb_desc *d, int *seen)
{
    int r;
    if ((r = sbd_body_line(c, d, seen)) != 1) return r;
    if ((r = sbd_sim_line(c, d)) != 1) return r;
    if ((r = sbd_rig_line(c, d)) != 1) return r;
    if ((r = sbd_seg_line(c, d)) != 1) return r;
    return sb_fail("%s:%d: unknown keyword '%s'", c->path, c->line, c->tok[0]);
}

int sb_desc_load(const char *path, sb_desc *d)
{
    FILE *f;
    char buf[4096];
    sb_dctx c;
    int seen[3] = {0, 0, 0}, i, j;
    memset(d, 0, sizeof *d);
    if (strlen(path) >= sizeof d->path) return sb_fail("%s: path too long", path);
    strcpy(d->path, path);
    d->subdiv = 4; d->air = 1e-3; d->min_fill = 0.0;
    d->h = 1.0 / 60.0; d->cg_def = 16; d->cg_max = 64;
    d->g[1] = -9.81;
    d->element = SB_ELEM_INCOMPATIBLE;
    d->bone_radius = -1;
    d->force_slots = 8;
    d->levels = 1;
    d->cr_list = 64; d->cr_active = 32; d->cr_ring = 1; d->cr_reach = 2; d->cr_tring = -1; d->cr_depth = -1; d->cr_push = -1; d->cr_exclude = -1; d->cr_thin = 0;
    f = fopen(path, "r");
    if (!f) return sb_fail("%s: cannot open description: %s", path, strerror(errno));
    memset(&c, 0, sizeof c);
    c.path = path;
    while (fgets(buf, sizeof buf, f)) {
        char *s, *hash;
        c.line++;
        if (!strchr(buf, '\n') && !feof(f)) { fclose(f); return sb_fail("%s:%d: line too long", path, c.line); }
        if ((hash = strchr(buf, '#'))) *hash = '\0';
        c.nt = 0;
        for (s = strtok(buf, " \t\r\n"); s; s = strtok(NULL, " \t\r\n")) {
            if (c.nt == 64) { fclose(f); return sb_fail("%s:%d: too many values", path, c.line); }
            c.tok[c.nt++] = s;
        }
        if (c.nt == 0) continue;
        if (parse_line(&c, d, seen)) { fclose(f); return -1; }
    }
    fclose(f);
    if (!seen[0]) return sb_fail("%s: missing 'mesh PATH' (or 'gltf FILE [MESH]')", path);
    if (!seen[1]) return sb_fail("%s: missing 'unit METRES_PER_MESH_UNIT'", path);
    if (!seen[2]) return sb_fail("%s: missing 'cell SIZE'", path);
    if (d->nj == 0) return sb_fail("%s: no joints", path);
    if (d->nm == 0) return sb_fail("%s: no materials", path);
    if (d->adapt_line && d->levels < 2) return sb_fail("%s:%d: adapt needs 'levels 2' (it adapts the finer level)", path, d->adapt_line);
    if (d->details_line && !d->levels_cut) return sb_fail("%s:%d: details need 'levels 2 cut' (they refine the cut level)", path, d->details_line);
    if (d->cr_active > d->cr_list) return sb_fail("%s:%d: crease active rows (%d) exceed the list size (%d)", path, d->cr_line, d->cr_active, d->cr_list);
    if (d->cr_depth > 0 && d->cr_push > d->cr_depth) return sb_fail("%s:%d: crease push (%g) exceeds depth (%g)", path, d->cr_line, d->cr_push, d->cr_depth);
    /* resolve parents (they may be declared after their children) */
    for (i = 0, j = 0; i < d->nj; i++) {
        sb_joint *jt = &d->joints[i];
        if (!strcmp(jt->parent_name, "-")) { jt->parent = -1; j++; continue; }
        jt->parent = sbd_find_joint(d, jt->parent_name);
        if (jt->parent < 0) return sb_fail("%s:%d: joint '%s': unknown parent '%s'", path, jt->line, jt->name, jt->parent_name);
        if (jt->parent == i) return sb_fail("%s:%d: joint '%s' is its own parent", path, jt->line, jt->name);
    }
    if (j != 1) return sb_fail("%s: want exactly one root joint (parent '-'), got %d", path, j);
    for (i = 0; i < d->nj; i++)
        if (d->joints[i].bone_line && d->joints[i].parent < 0)
            return sb_fail("%s:%d: '%s' is the root: a bone is named by its child joint", path, d->joints[i].bone_line, d->joints[i].name);
    for (i = 0; i < d->nctl; i++) {   /* twist axis: JOINT -> its only child */
        sb_control *k_ = &d->ctls[i];
        int nch = 0, ch = -1, k;
        double n = 0;
        if (k_->kind != SB_CTL_TWIST) continue;
        for (j = 0; j < d->nj; j++) if (d->joints[j].parent == k_->joint) { nch++; ch = j; }
        if (nch != 1)
            return sb_fail("%s:%d: control '%s': twist needs joint '%s' to have exactly one child (it has %d); use 'control %s angle %s AX AY AZ'",
                           path, k_->line, k_->name, d->joints[k_->joint].name, nch, k_->name, d->joints[k_->joint].name);
        for (k = 0; k < 3; k++) { k_->axis[k] = d->joints[ch].pos[k] - d->joints[k_->joint].pos[k]; n += k_->axis[k] * k_->axis[k]; }
        n = sqrt(n);
        if (!(n > 1e-12)) return sb_fail("%s:%d: control '%s': joint '%s' and its child '%s' coincide: no twist axis", path, k_->line, k_->name, d->joints[k_->joint].name, d->joints[ch].name);
        for (k = 0; k < 3; k++) k_->axis[k] /= n;
    }
    for (i = 0; i < d->nrig; i++) {   /* tau: angle controls need explicit samples; abstract default (0,0) (1,1) */
        sb_rigdef *r = &d->rigs[i];
        if (r->ntau) continue;
        if (d->ctls[r->control].kind != SB_CTL_ABSTRACT)
            return sb_fail("%s:%d: rig '%s' is driven by the pose control '%s' and needs tau samples (angles in degrees): "
                           "'tau %s G1 E1 G2 E2 ...' or '... tau G1 E1 ...' at the end of the rig line", path, r->line, r->name, d->ctls[r->control].name, r->name);
        r->ntau = 2; r->tau_g[0] = 0; r->tau_e[0] = 0; r->tau_g[1] = 1; r->tau_e[1] = 1;
    }
    for (i = 0; i < d->nrig; i++) {
        double m = 0;
        int k;
        for (k = 0; k < d->rigs[i].ntau; k++) m = fmax(m, fabs(d->rigs[i].tau_e[k]));
        if (!(m > 0)) return sb_fail("%s:%d: rig '%s': every tau eta is 0 (the rig would never act)", path, d->rigs[i].tau_line ? d->rigs[i].tau_line : d->rigs[i].line, d->rigs[i].name);
    }
    for (i = 0; i < d->nj; i++) {   /* cycle check: walking up must reach the root within nj steps */
        int p = i, steps = 0;
        while (p >= 0 && steps <= d->nj) { p = d->joints[p].parent; steps++; }
        if (p >= 0) return sb_fail("%s:%d: joint '%s' is in a parent cycle", path, d->joints[i].line, d->joints[i].name);
    }
    return 0;
}

void sb_desc_free(sb_desc *d)
{
    int i;
    if (d->gltf) { sb_gltf_free(d->gltf); free(d->gltf); }
    free(d->joints); free(d->mats); free(d->mrules); free(d->frules); free(d->pins); free(d->lrules); free(d->shares); free(d->srules);
    free(d->ctls); free(d->rigs);
    for (i = 0; i < d->nseg; i++) free(d->segs[i].att);
    free(d->segs);
    free(d->creases);
    memset(d, 0, sizeof *d);
}