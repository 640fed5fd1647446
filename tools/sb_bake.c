/* sb_bake.c -- the whole bake: description -> mesh -> model -> blob, with a summary. */
#include "sb.h"
#include "sb_level.h"
#include "../runtime/src/sn_format.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *sec_name[] = {"JOINTS", "JOINT_NAMES", "REST", "FRAMES", "MDIAG", "PRECOND", "MLUMP",
                                             "ROWPTR", "COLS", "MOFF", "CELLS", "CFRAMES", "CELLK", "LIMIT", "EMBED", "TRIS",
                                             "CONTROLS", "RIGS", "RIG_SAMPLES", "RIG_VERTS", "RIG_FORCES",
                                             "SHARES", "VSHARE", "SEGMESH", "SEGNODES", "SEGATTACH", "CONSTRAINTS",
                                             "CREASE", "CREASE_PAIRS", "CREASE_VNBR", "CREASE_TNBR",
                                             "LEVEL_BLOB", "LEVEL_UP", "LEVEL_DOWN", "ICHOL", "ADAPT", "CELLX", "CELLXK", "FPAIRS", "FREFS",
                                             "DETAILS", "DETAIL", "CELLD", "CELLDK"};
/* one name per section: a new section without its name fails to compile
 * (format 6.1's ADAPT printed as "(null)", a NULL through %s) */
typedef char sb_sec_name_count_[sizeof sec_name / sizeof sec_name[0] == SN_SEC_COUNT ? 1 : -1];

int sb_bake_file(const char *desc_path, int flavour, int quiet, sb_model *o, sb_blob *b)
{
    sb_desc d;
    sb_mesh m;
    sb_srcmap src;
    sb_lodinfo lod;
    double t0 = sb_now(), vol;
    int k;
    memset(o, 0, sizeof *o);
    memset(b, 0, sizeof *b);
    memset(&m, 0, sizeof m);
    if (sb_desc_load(desc_path, &d)) { sb_desc_free(&d); return -1; }
    if (sb_desc_mesh(&d, &m, &src)) {   /* the OBJ, or the glTF's welded skinned mesh */
        sb_mesh_free(&m); sb_desc_free(&d);
        return -1;
    }
    memset(&lod, 0, sizeof lod);
    if (sb_build(&d, &m, o, quiet) || sb_rig_build(&d, &m, o) || sb_force_build(&d, o) ||
        sb_segment_build(&d, &m, o) || sb_crease_build(&d, o, quiet) ||
        (d.levels > 1 ? sb_level_bake(&d, &m, o, flavour, quiet, b, &lod) : sb_blob_make(o, flavour, b))) {
        sb_model_free(o); sb_mesh_free(&m); sb_desc_free(&d); sb_srcmap_free(&src);
        return -1;
    }
    o->src = src;   /* sb_build cleared the model: the glTF vertex order goes in afterwards */
    if (o->src.nsrc) memcpy(o->src.root, o->joints[0].pos, sizeof o->src.root);
    vol = sb_mesh_volume(&m) * d.unit * d.unit * d.unit;
    if (!quiet) {
        double fmin_ = 1, fsum = 0;
        for (k = 0; k < o->nc; k++) { fsum += o->cell_fill[k]; if (o->cell_fill[k] < fmin_) fmin_ = o->cell_fill[k]; }
        printf("sinew-bake: %s (%s)\n", desc_path, flavour == 0 ? "fixed" : flavour == 1 ? "float" : "double");
        printf("  mesh      %d vertices, %d triangles, volume %.6g m^3\n", m.nv, m.nt, vol);
        if (src.nsrc)
            printf("  glTF      %s: mesh \"%s\", %d vertices in %d primitive(s) welded by position into %d (%d triangle(s) collapsed)\n",
                   src.path, src.mesh, src.nsrc, src.nprim, src.nsurf, src.dropped);
        printf("  skeleton  %d joints, %d bones; model-space origin = root joint '%s' at (%g, %g, %g) mesh units\n",
               o->nj, o->nseg, o->joints[0].name, o->joints[0].pos[0], o->joints[0].pos[1], o->joints[0].pos[2]);
        printf("  lattice   %d vertices (%d free, %d skeleton), %d cells (mean fill %.2f, min %.3f), cell %g mesh units\n",
               o->nv, o->nf, o->nv - o->nf, o->nc, fsum / o->nc, fmin_, o->c);
        if (d.levels > 1)
            printf("  levels    2: level 1 (cell %g) %d vertices (%d free), %d cells, %u blob bytes; instance %u bytes (level 0 alone %u, level 1 alone %u); "
                   "%d level-1 vertices outside the level-0 cells, %d level-0 vertices outside the level-1 cells (nearest cell)\n",
                   0.5 * o->c, lod.nv1, lod.nf1, lod.nc1, (unsigned)lod.size1, (unsigned)lod.inst, (unsigned)lod.inst0, (unsigned)lod.inst1,
                   lod.up_far, lod.down_far);
        if (d.levels_cut)
            printf("  cut       level 0 cut at level 1's skeleton (runtime/LEVELS.md): %d extra skeleton vertices, %d of level 0's skeleton "
                   "vertices free on level 1 made unknowns, %d children with the air element, %d level-1 cells in no level-0 cell left out\n",
                   lod.cut_nx, lod.cut_freed, lod.cut_air, lod.cut_lost);
        if (d.details_line)
            printf("  details   %d on the cut level (level 1's free vertices inside level-0 cells), at most %d active\n", lod.cut_nd,
                   d.details_max < lod.cut_nd ? d.details_max : lod.cut_nd);
        printf("  quality   smallest Jacobian / cell volume %.3g (1: every cell an undistorted cube)\n", o->min_jac);
        printf("  mass      %.6g kg (interior volume %.6g m^3 = %.4f x mesh volume), m0 %.6g kg\n",
               o->mass, o->inside_volume, o->inside_volume / vol, b->m0);
        printf("  units     len_shift %d, frac_S %d, frac_M %d, frac_P %d\n", b->len_shift, b->frac_S, b->frac_M, b->frac_P);
        printf("  blob      %lu bytes:", (unsigned long)b->size);
        for (k = 0; k < SN_SEC_COUNT; k++) printf("%s %s %u", k ? "," : "", sec_name[k], (unsigned)b->sec_size[k]);
        printf("\n");
        if (o->nctl || o->nrig) {
            int nab = 0;
            for (k = 0; k < o->nctl; k++) nab += o->ctl[k].kind == SB_CTL_ABSTRACT;
            printf("  controls  %d (%d abstract, %d pose):", o->nctl, nab, o->nctl - nab);
            for (k = 0; k < o->nctl; k++) printf(" %s", o->ctl[k].name);
            printf("\n");
        }
        for (k = 0; k < o->nrig; k++) {
            const sb_rig *r = &o->rig[k];
            char fr[16];
            if (flavour == SB_FIXED) snprintf(fr, sizeof fr, "%d", b->rig_frac[k]); else snprintf(fr, sizeof fr, "-");
            printf("  rig       %-14s control %-12s %-7s s %-6g %4d entries, peak |Q_i| %.4g N (at eta 1), total |int f dV| %.4g N, frac %s\n",
                   r->def.name, o->ctl[r->def.control].name, sb_rig_tpl_name(r->def.tpl), r->def.s, r->n, r->qmax,
                   sqrt(r->total[0] * r->total[0] + r->total[1] * r->total[1] + r->total[2] * r->total[2]), fr);
        }
        if (o->max_cons || o->max_cols || o->crease)
            printf("  contact   %d constraints, %d colliders, %d contacts, %d crease rows per step: %u rows, %u instance bytes\n", o->max_cons,
                   o->max_cols, o->max_contacts, o->crease ? o->cr_active : 0,
                   SN_ROWS_CAP(o->max_cons, o->max_contacts, o->crease ? o->cr_active : 0),
                   SN_CONS_BYTES(o->max_cons, o->max_cols, SN_ROWS_CAP(o->max_cons, o->max_contacts, o->crease ? o->cr_active : 0)));
        printf("  forces    %d per step (sn_apply_force), %d share profile%s (fine, 2, 4, 8 cells, rigid)%s\n", o->max_forces, o->nprof,
               o->nprof == 1 ? "" : "s", o->nprof ? ":" : "");
        for (k = 0; k < o->nprof; k++) {
            int nv = 0, i;
            for (i = 0; i < o->nf; i++) nv += o->vprof && o->vprof[i] == k;
            printf("            %d %-14s %.3g %.3g %.3g %.3g %.3g  (%d free vertices)\n", k, d.shares[k].name, o->prof[k][0], o->prof[k][1],
                   o->prof[k][2], o->prof[k][3], o->prof[k][4], nv);
        }
        for (k = 0; k < o->nsm; k++) {   /* segment meshes (seed 004 ch. 3-4) */
            const sb_segmesh *g = &o->sm[k];
            int a, ns = 0, nj = 0;
            for (a = 0; a < g->natt; a++) { ns += g->att_kind[a] == SB_SEGATT_SURFACE; nj += g->att_kind[a] == SB_SEGATT_JOINT; }
            printf("  segment   %-14s %-5s %4d nodes, %4d segments (%u nodes, %u segments over %d level(s)), segment %.4g mesh units, "
                   "%d attachment(s) (%d surface, %d joint), gravity %s, state %u bytes\n",
                   g->def.name, g->def.kind ? "sheet" : "chain", g->nodes, g->segs, (unsigned)g->nodes_all, (unsigned)g->segs_all, g->def.levels,
                   g->seg_len, g->natt, ns, nj, g->def.gravity ? "on" : "off",
                   (unsigned)(SN_SEG_SEG_BYTES * g->segs_all + SN_SEG_NODE_BYTES * g->nodes_all));
            if (ns) {
                double gap = 0;
                for (a = 0; a < g->natt; a++) gap = g->att_dist[a] > gap ? g->att_dist[a] : gap;
                printf("            moved by (%.4g, %.4g, %.4g) mesh units onto its surface attachments (mean offset); largest node-to-vertex gap %.4g\n",
                       g->shift[0], g->shift[1], g->shift[2], gap);
            }
        }
        printf("  time      %.2f s\n", sb_now() - t0);
    }
    sb_mesh_free(&m);
    sb_desc_free(&d);
    return 0;
}

int sb_level1_load(const char *desc_path, int rigs, sb_desc *d, sb_mesh *m, sb_model *o)
{
    sb_desc d2;
    sb_model o0;
    memset(d, 0, sizeof *d); memset(m, 0, sizeof *m); memset(o, 0, sizeof *o); memset(&o0, 0, sizeof o0);
    if (sb_desc_load(desc_path, d)) goto fail;
    if (d->levels < 2) { sb_fail("%s: no 'levels 2': the description has no level 1", desc_path); goto fail; }
    if (sb_desc_mesh(d, m, NULL)) goto fail;
    /* level 0's lattice fixes level 1's (cell, grid corner), exactly as sb_level_bake derives it */
    if (sb_build(d, m, &o0, 1)) goto fail;
    sb_level_desc(d, &o0, &d2);
    sb_model_free(&o0);
    if (!rigs) d2.nrig = 0;
    if (sb_level_model(d, &d2, m, o)) goto fail;
    return 0;
fail:
    sb_model_free(&o0); sb_model_free(o); sb_mesh_free(m); sb_desc_free(d);
    memset(d, 0, sizeof *d); memset(m, 0, sizeof *m); memset(o, 0, sizeof *o);
    return -1;
}

int sb_bake_level1(const char *desc_path, int flavour, sb_model *o, sb_blob *b)
{
    sb_desc d;
    sb_mesh m;
    int rc;
    memset(b, 0, sizeof *b);
    if (sb_level1_load(desc_path, 1, &d, &m, o)) return -1;
    rc = sb_blob_make(o, flavour, b);
    if (rc) sb_model_free(o);
    sb_mesh_free(&m); sb_desc_free(&d);
    return rc ? -1 : 0;
}
