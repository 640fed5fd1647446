/* sb_desc_body.c -- the character's keywords: surface, lattice, skeleton, bones, materials, frames, pins, limits. */
#include "sb_desc_int.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int find_mat(const sb_desc *d, const char *name)
{
    int i;
    for (i = 0; i < d->nm; i++) if (!strcmp(d->mats[i].name, name)) return i;
    return -1;
}

/* surface, lattice, skeleton and material keywords (DESCRIPTION.md); 1 when the line is not one of them */
int sbd_body_line(sb_dctx *c, sb_desc *d, int *seen)
{
    const char *kw = c->tok[0];
    int k, n;
    if (!strcmp(kw, "gltf")) {   /* surface and skeleton from a glTF skin (sb_gltf_bake.c) */
        if (c->nt < 2 || c->nt > 3)
            return sb_fail("%s:%d: 'gltf' takes a file and an optional mesh name: 'gltf FILE [MESH]'", c->path, c->line);
        if (seen[0]) return sb_fail("%s:%d: a second 'mesh' or 'gltf' line (the first at line %d)", c->path, c->line, d->mesh_line);
        if (d->nj) return sb_fail("%s:%d: 'gltf' declares the joints from the file's skin: no 'joint' lines before it (line %d)", c->path, c->line, d->joints[0].line);
        if (sb_desc_gltf(d, c->tok[1], c->nt == 3 ? c->tok[2] : NULL, c->line)) return -1;
        seen[0] = 1;
    } else if (!strcmp(kw, "mesh")) {
        const char *slash;
        size_t dl;
        if (sbd_nargs(c, 1)) return -1;
        if (d->gltf) return sb_fail("%s:%d: 'mesh' after 'gltf' (line %d): the surface comes from the glTF", c->path, c->line, d->mesh_line);
        slash = strrchr(d->path, '/');
        dl = slash ? (size_t)(slash - d->path + 1) : 0;
        if (c->tok[1][0] == '/') dl = 0;
        if (dl + strlen(c->tok[1]) + 1 > sizeof d->mesh_path) return sb_fail("%s:%d: mesh path too long", c->path, c->line);
        memcpy(d->mesh_path, d->path, dl);
        strcpy(d->mesh_path + dl, c->tok[1]);
        d->mesh_line = c->line;
        seen[0] = 1;
    } else if (!strcmp(kw, "unit")) {
        if (sbd_nargs(c, 1) || sbd_num(c, 1, &d->unit)) return -1;
        if (!(d->unit >= 1e-9 && d->unit <= 1e9)) return sb_fail("%s:%d: unit (metres per mesh unit) must be in [1e-9, 1e9]", c->path, c->line);
        seen[1] = 1;
    } else if (!strcmp(kw, "cell")) {
        if (sbd_nargs(c, 1) || sbd_len(c, 1, &d->cell)) return -1;
        if (d->cell <= 0) return sb_fail("%s:%d: cell size must be positive", c->path, c->line);
        seen[2] = 1;
    } else if (!strcmp(kw, "origin")) {
        if (sbd_nargs(c, 3)) return -1;
        for (k = 0; k < 3; k++) if (sbd_len(c, 1 + k, &d->origin[k])) return -1;
        d->has_origin = 1;
    } else if (!strcmp(kw, "subdiv")) {
        if (sbd_nargs(c, 1) || sbd_inum(c, 1, 1, 16, &d->subdiv)) return -1;
    } else if (!strcmp(kw, "air")) {
        if (sbd_nargs(c, 1) || sbd_num(c, 1, &d->air)) return -1;
        if (d->air < 0 || d->air > 1) return sb_fail("%s:%d: air must be in [0, 1]", c->path, c->line);
    } else if (!strcmp(kw, "min_fill")) {
        if (sbd_nargs(c, 1) || sbd_num(c, 1, &d->min_fill)) return -1;
        if (d->min_fill < 0 || d->min_fill >= 1) return sb_fail("%s:%d: min_fill must be in [0, 1)", c->path, c->line);
    } else if (!strcmp(kw, "frames")) {   /* 'frames skin' | 'frames auto' */
        if (sbd_nargs(c, 1)) return -1;
        if (!strcmp(c->tok[1], "skin")) {
            if (!d->gltf) return sb_fail("%s:%d: 'frames skin' takes the frames from a glTF's skin weights: put it after a 'gltf' line", c->path, c->line);
            d->skin_frames = 1;
        } else if (!strcmp(c->tok[1], "auto")) d->skin_frames = 0;
        else return sb_fail("%s:%d: 'frames' takes 'skin' or 'auto' (got '%s')", c->path, c->line, c->tok[1]);
        d->skin_frames_line = c->line;
    } else if (!strcmp(kw, "blend")) {
        if (sbd_nargs(c, 1) || sbd_len(c, 1, &d->blend)) return -1;
        if (d->blend <= 0) return sb_fail("%s:%d: blend width must be positive", c->path, c->line);
    } else if (!strcmp(kw, "joint")) {
        sb_joint *j;
        if (d->gltf) return sb_fail("%s:%d: the joints come from the glTF skin ('gltf' at line %d): no 'joint' lines", c->path, c->line, d->mesh_line);
        if (sbd_nargs(c, 5)) return -1;
        if (strlen(c->tok[1]) >= SB_NAME_MAX || strlen(c->tok[2]) >= SB_NAME_MAX)
            return sb_fail("%s:%d: joint names are at most %d characters", c->path, c->line, SB_NAME_MAX - 1);
        if (sbd_find_joint(d, c->tok[1]) >= 0) return sb_fail("%s:%d: joint '%s' declared twice", c->path, c->line, c->tok[1]);
        if (!strcmp(c->tok[1], "-")) return sb_fail("%s:%d: '-' is not a joint name", c->path, c->line);
        if (d->nj >= 255) return sb_fail("%s:%d: more than 255 joints", c->path, c->line);
        GROW(d->joints, d->nj);
        j = &d->joints[d->nj];
        strcpy(j->name, c->tok[1]);
        strcpy(j->parent_name, c->tok[2]);
        for (k = 0; k < 3; k++) if (sbd_len(c, 3 + k, &j->pos[k])) return -1;
        j->line = c->line;
        j->parent = -1;
        j->bone_r = -1;
        d->nj++;
    } else if (!strcmp(kw, "material")) {
        sb_material *m;
        if (sbd_nargs(c, 4)) return -1;
        if (strlen(c->tok[1]) >= SB_NAME_MAX) return sb_fail("%s:%d: material name too long", c->path, c->line);
        if (find_mat(d, c->tok[1]) >= 0) return sb_fail("%s:%d: material '%s' declared twice", c->path, c->line, c->tok[1]);
        GROW(d->mats, d->nm);
        m = &d->mats[d->nm];
        strcpy(m->name, c->tok[1]);
        if (sbd_num(c, 2, &m->E) || sbd_num(c, 3, &m->nu) || sbd_num(c, 4, &m->rho)) return -1;
        if (m->E <= 0) return sb_fail("%s:%d: Young's modulus E must be positive (got %g)", c->path, c->line, m->E);
        if (m->nu >= 0.5 || m->nu <= -1.0) return sb_fail("%s:%d: Poisson ratio must be in (-1, 0.5) (got %g)", c->path, c->line, m->nu);
        if (m->rho <= 0) return sb_fail("%s:%d: density must be positive (got %g)", c->path, c->line, m->rho);
        m->line = c->line;
        d->nm++;
    } else if (!strcmp(kw, "region")) {
        sb_matrule r;
        if ((n = sbd_region(c, d, 1, 1, &r.r)) < 0) return -1;
        r.mat = find_mat(d, c->tok[1 + n]);
        if (r.mat < 0) return sb_fail("%s:%d: unknown material '%s' (declare materials before regions)", c->path, c->line, c->tok[1 + n]);
        GROW(d->mrules, d->nmr);
        d->mrules[d->nmr++] = r;
    } else if (!strcmp(kw, "frame")) {
        sb_framerule r;
        if ((n = sbd_region(c, d, 1, 3, &r.r)) < 0) return -1;
        r.j1 = sbd_find_joint(d, c->tok[1 + n]);
        r.j2 = sbd_find_joint(d, c->tok[2 + n]);
        if (r.j1 < 0 || r.j2 < 0) return sb_fail("%s:%d: unknown joint '%s'", c->path, c->line, c->tok[r.j1 < 0 ? 1 + n : 2 + n]);
        if (sbd_num(c, 3 + n, &r.w)) return -1;
        if (r.w < 0 || r.w > 1) return sb_fail("%s:%d: frame weight must be in [0, 1]", c->path, c->line);
        GROW(d->frules, d->nfr);
        d->frules[d->nfr++] = r;
    } else if (!strcmp(kw, "pin")) {
        sb_pin p;
        if ((n = sbd_region(c, d, 1, 1, &p.r)) < 0) return -1;
        p.joint = sbd_find_joint(d, c->tok[1 + n]);
        if (p.joint < 0) return sb_fail("%s:%d: unknown joint '%s'", c->path, c->line, c->tok[1 + n]);
        GROW(d->pins, d->npin);
        d->pins[d->npin++] = p;
    } else if (!strcmp(kw, "twist")) {
        /* seed 000 eq. 25-26 stood in for 3-D bones; bones have volume now (DESCRIPTION.md) */
        return sb_fail("%s:%d: 'twist' is retired: bones now have volume (every lattice vertex within a bone's radius moves "
                       "rigidly with it), which stops flesh spinning around them; delete this line and, to thicken or thin "
                       "the bones, use 'bone JOINT R' or 'bone_radius R'", c->path, c->line);
    } else if (!strcmp(kw, "bone")) {
        int j;
        double r = -1;
        if (sbd_nargs(c, 2)) return -1;
        j = sbd_find_joint(d, c->tok[1]);
        if (j < 0) return sb_fail("%s:%d: unknown joint '%s' (declare joints before using them)", c->path, c->line, c->tok[1]);
        if (!strcmp(c->tok[2], "auto")) r = -1;
        else {
            if (sbd_len(c, 2, &r)) return -1;
            if (r < 0) return sb_fail("%s:%d: bone radius must be >= 0 (or 'auto')", c->path, c->line);
        }
        d->joints[j].bone_r = r;
        d->joints[j].bone_line = c->line;
    } else if (!strcmp(kw, "bone_radius")) {
        if (sbd_nargs(c, 1)) return -1;
        if (!strcmp(c->tok[1], "auto")) d->bone_radius = -1;
        else {
            if (sbd_len(c, 1, &d->bone_radius)) return -1;
            if (d->bone_radius < 0) return sb_fail("%s:%d: bone radius must be >= 0 (or 'auto')", c->path, c->line);
        }
    } else if (!strcmp(kw, "limit")) {
        sb_limitrule r;
        if ((n = sbd_region(c, d, 1, 1, &r.r)) < 0) return -1;
        if (sbd_len(c, 1 + n, &r.dist)) return -1;
        if (r.dist < 0) return sb_fail("%s:%d: limit distance must be >= 0 (0 = no limit)", c->path, c->line);
        GROW(d->lrules, d->nlr);
        d->lrules[d->nlr++] = r;
    } else {
        return 1;
    }
    return 0;
}
