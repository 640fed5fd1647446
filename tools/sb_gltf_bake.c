/* sb_gltf_bake.c -- a character from a glTF 2.0 skinned mesh (issue 17 item 2;
 * tools/DESCRIPTION.md 'gltf'): the description's 'gltf FILE [MESH]' line
 * declares the skin's joints (names, hierarchy, bind positions from the
 * inverse bind matrices); the surface is the skinned mesh's primitives with
 * vertices welded by position, and the glTF vertex order is kept beside the
 * blob (sb_srcmap) so the runtime's output can drive the original mesh. */
#include "sb.h"
#include "sb_gltf.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int sb_desc_gltf(sb_desc *d, const char *file, const char *mesh, int line)
{
    const char *slash = strrchr(d->path, '/');
    size_t dl = slash ? (size_t)(slash - d->path + 1) : 0;
    sb_gltf *g;
    int k, i;
    if (file[0] == '/') dl = 0;
    if (dl + strlen(file) + 1 > sizeof d->mesh_path) return sb_fail("%s:%d: glTF path too long", d->path, line);
    memcpy(d->mesh_path, d->path, dl);
    strcpy(d->mesh_path + dl, file);
    d->mesh_line = line;
    if (mesh && strlen(mesh) >= sizeof d->gltf_mesh) return sb_fail("%s:%d: mesh name too long", d->path, line);
    snprintf(d->gltf_mesh, sizeof d->gltf_mesh, "%s", mesh ? mesh : "");
    g = sb_alloc(sizeof *g);
    if (sb_gltf_load(g, d->mesh_path, mesh)) {
        char msg[1800];
        snprintf(msg, sizeof msg, "%s", sb_error());
        free(g);
        return sb_fail("%s:%d: %s", d->path, line, msg);
    }
    d->gltf = g;
    if (g->nj > 255) return sb_fail("%s:%d: %s: the skin has %d joints, at most 255", d->path, line, d->mesh_path, g->nj);
    d->joints = sb_alloc((size_t)g->nj * sizeof *d->joints);
    for (k = 0; k < g->nj; k++) {
        sb_joint *j = &d->joints[k];
        if (strlen(g->joints[k].name) >= SB_NAME_MAX)
            return sb_fail("%s:%d: %s: skins[%d].joints[%d]: node name \"%s\" is longer than %d characters", d->path, line,
                           d->mesh_path, g->skin, k, g->joints[k].name, SB_NAME_MAX - 1);
        sb_gltf_token(g->joints[k].name, k, j->name, SB_NAME_MAX);
        if (!strcmp(j->name, "-")) strcpy(j->name, "_");
        for (i = 0; i < k; i++)
            if (!strcmp(d->joints[i].name, j->name))
                return sb_fail("%s:%d: %s: skins[%d].joints[%d] and [%d] are both named \"%s\" (joint names must differ)", d->path,
                               line, d->mesh_path, g->skin, i, k, j->name);
        memcpy(j->pos, g->joints[k].pos, sizeof j->pos);
        j->line = line;
        j->parent = -1;
        j->bone_r = -1;
    }
    for (k = 0; k < g->nj; k++)
        strcpy(d->joints[k].parent_name, g->joints[k].parent < 0 ? "-" : d->joints[g->joints[k].parent].name);
    d->nj = g->nj;
    return 0;
}

void sb_srcmap_free(sb_srcmap *s)
{
    free(s->to_surf), free(s->prim), free(s->vert), free(s->src_tri);
    memset(s, 0, sizeof *s);
}

int sb_desc_mesh(const sb_desc *d, sb_mesh *m, sb_srcmap *map)
{
    const sb_gltf *g = d->gltf;
    sb_srcmap s;
    int k;
    if (map) memset(map, 0, sizeof *map);
    if (!g) {
        if (sb_mesh_load_obj(d->mesh_path, m)) {
            char msg[1800];
            snprintf(msg, sizeof msg, "%s", sb_error());
            return sb_fail("%s (mesh named at %s:%d)", msg, d->path, d->mesh_line);
        }
        return 0;
    }
    memset(&s, 0, sizeof s);
    s.to_surf = sb_alloc((size_t)(g->nv > 0 ? g->nv : 1) * sizeof(int));
    if (sb_mesh_from_points(d->mesh_path, g->nv, g->pos, g->nt, g->tri, m, s.to_surf, &s.dropped)) {
        char msg[1800];
        snprintf(msg, sizeof msg, "%s", sb_error());
        free(s.to_surf);
        return sb_fail("%s (the skinned mesh of the glTF named at %s:%d, vertices welded by position)", msg, d->path, d->mesh_line);
    }
    if (!map) { free(s.to_surf); return 0; }
    snprintf(s.path, sizeof s.path, "%s", d->mesh_path);
    snprintf(s.mesh, sizeof s.mesh, "%s", g->mesh_name);
    s.nsrc = g->nv, s.nsurf = m->nv, s.nsrc_tri = g->nt;
    s.prim = sb_alloc((size_t)(g->nv > 0 ? g->nv : 1) * sizeof(int));
    s.vert = sb_alloc((size_t)(g->nv > 0 ? g->nv : 1) * sizeof(int));
    s.src_tri = sb_alloc((size_t)(3 * g->nt > 0 ? 3 * g->nt : 1) * sizeof(int));
    memcpy(s.prim, g->src_prim, (size_t)g->nv * sizeof(int));
    memcpy(s.vert, g->src_vert, (size_t)g->nv * sizeof(int));
    memcpy(s.src_tri, g->tri, (size_t)g->nt * 3 * sizeof(int));
    for (k = 0; k < g->nv; k++) s.nprim = g->src_prim[k] + 1 > s.nprim ? g->src_prim[k] + 1 : s.nprim;
    *map = s;
    return 0;
}

int sb_srcmap_write(const char *path, const sb_srcmap *s)
{
    char tmp[1100];
    FILE *f;
    int k, ok;
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    if (!(f = fopen(tmp, "w"))) return sb_fail("%s: cannot write", tmp);
    fprintf(f, "sinew-gltf-map 1\n");
    fprintf(f, "source %s\n", s->path);
    fprintf(f, "mesh %s\n", s->mesh[0] ? s->mesh : "-");
    fprintf(f, "counts %d %d %d %d %d\n", s->nsrc, s->nsurf, s->nprim, s->nsrc_tri, s->dropped);
    fprintf(f, "root %.17g %.17g %.17g\n", s->root[0], s->root[1], s->root[2]);
    for (k = 0; k < s->nsrc; k++) fprintf(f, "v %d %d %d\n", s->prim[k], s->vert[k], s->to_surf[k]);
    for (k = 0; k < s->nsrc_tri; k++) fprintf(f, "t %d %d %d\n", s->src_tri[3 * k], s->src_tri[3 * k + 1], s->src_tri[3 * k + 2]);
    ok = !ferror(f);
    if (fclose(f) || !ok) { remove(tmp); return sb_fail("%s: write failed", tmp); }
    if (rename(tmp, path)) { remove(tmp); return sb_fail("%s: cannot rename to %s", tmp, path); }
    return 0;
}
