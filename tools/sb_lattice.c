/* sb_lattice.c -- automatic control lattice (seed 000 §3.1) with volumetric
 * bones: an undistorted grid of cubes covering the mesh (grid vertices are
 * never moved, so no cell can fold); kept cells = those meeting the interior
 * (or holding a mesh vertex, a joint or a bone sample); skeleton vertices =
 * lattice vertices a bone captures (its rasterized chain and every vertex
 * within its radius; the nearest segment wins); frames (sb_frames.c) at
 * vertices and cell centres; surface embedding; model checks. */
#include "sb.h"
#include "sb_lattice_int.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Flesh thickness of bone a: distance from the segment to the mesh surface, the
 * smallest over 9 samples of its middle half (0 where the segment leaves the mesh). */
static double flesh_thickness(const sb_model *o, const sb_mesh *m, const sb_inside *in, int a)
{
    double best = HUGE_VAL, p[3], q[3];
    int s;
    for (s = 0; s <= 8; s++) {
        seg_point(o, a, 0.25 + 0.5 * s / 8.0, p);
        if (!sb_inside_test(in, p)) return 0;
        best = fmin(best, sb_mesh_closest(m, p, q));
    }
    return best;
}

/* every joint outside the mesh, each with its nearest surface point and a point just inside */
static int joints_outside(const sb_desc *d, const sb_model *o, const sb_mesh *m, const sb_inside *in)
{
    char msg[16384];
    size_t len = 0;
    int k, nout = 0, pass;
    for (k = 0; k < o->nj; k++) if (!sb_inside_test(in, o->joints[k].pos)) nout++;
    if (!nout) return 0;
    for (pass = 0; pass < 3; pass++) {   /* shorter entries if the message would not fit */
        len = (size_t)snprintf(msg, sizeof msg, "%d joint(s) outside the mesh (every joint must lie inside):", nout);
        for (k = 0; k < o->nj && len < sizeof msg; k++) {
            const sb_joint *J = &o->joints[k];
            double s[3], tryp[3], dist, step;
            int e, found = 0;
            if (sb_inside_test(in, J->pos)) continue;
            if (pass == 2) { len += (size_t)snprintf(msg + len, sizeof msg - len, " '%s'", J->name); continue; }
            dist = sb_mesh_closest(m, J->pos, s);
            /* just past the nearest surface point, away from the joint */
            for (step = 0.25 * o->c; step > 1e-6 * o->c && !found; step *= 0.5) {
                for (e = 0; e < 3; e++) tryp[e] = s[e] + (dist > 0 ? (s[e] - J->pos[e]) / dist * step : 0);
                found = sb_inside_test(in, tryp);
            }
            if (pass == 0 && found)
                len += (size_t)snprintf(msg + len, sizeof msg - len, "\n  %s:%d: joint '%s' at (%g, %g, %g) is %.3g outside; nearest surface point (%.4g, %.4g, %.4g): move it inside, e.g. to (%.4g, %.4g, %.4g)",
                                        d->path, J->line, J->name, J->pos[0], J->pos[1], J->pos[2], dist, s[0], s[1], s[2], tryp[0], tryp[1], tryp[2]);
            else if (pass == 0)
                len += (size_t)snprintf(msg + len, sizeof msg - len, "\n  %s:%d: joint '%s' at (%g, %g, %g) is %.3g outside; nearest surface point (%.4g, %.4g, %.4g): move it inside, past that point",
                                        d->path, J->line, J->name, J->pos[0], J->pos[1], J->pos[2], dist, s[0], s[1], s[2]);
            else
                len += (size_t)snprintf(msg + len, sizeof msg - len, " '%s' (%.4g,%.4g,%.4g)->inside past (%.4g,%.4g,%.4g);", J->name, J->pos[0], J->pos[1], J->pos[2], s[0], s[1], s[2]);
        }
        if (len < 2000) break;   /* sb_fail keeps 2047 characters */
    }
    if (nout == o->nj)
        snprintf(msg + (len < sizeof msg ? len : sizeof msg - 1), sizeof msg - (len < sizeof msg ? len : sizeof msg - 1),
                 "\n  (no joint is inside: check that the skeleton and the mesh use the same units and axes)");
    return sb_fail("%s", msg);
}

/* step 5: the surface embedding; keeps the cells it uses */
static void embed_surface(sb_model *o, const sb_mesh *m, int *keep)
{
    double c = o->c;
    int i, k;
    /* each mesh vertex in its grid cell (t = offset / c), preferring a
     * kept neighbour when the vertex lies on a cell face; that cell is kept */
    o->ns = m->nv;
    o->emb_cell = sb_alloc(sizeof(int) * (size_t)m->nv);
    o->emb_t = sb_alloc(sizeof(double) * 3 * (size_t)m->nv);
    for (i = 0; i < m->nv; i++) {
        const double *q = m->v + 3 * i;
        int gc = cell_of(o, q), nx = o->gn[0] - 1, ny = o->gn[1] - 1, g0[3], best = -1, alt;
        double t0c[3], tb[3];
        g0[0] = gc % nx; g0[1] = gc / nx % ny; g0[2] = gc / (nx * ny);
        for (k = 0; k < 3; k++) t0c[k] = (q[k] - o->gpos[3 * gidx(o, g0[0], g0[1], g0[2]) + k]) / c;
        for (alt = 0; alt < 8 && best < 0; alt++) {   /* alt bit k: the neighbour across face k the vertex lies on */
            int gi[3] = {g0[0], g0[1], g0[2]}, ok = 1, cc;
            double t[3];
            for (k = 0; k < 3; k++) {
                t[k] = t0c[k];
                if (alt >> k & 1) {
                    if (t0c[k] < 1e-12 && gi[k] > 0) { gi[k]--; t[k] = 1; }
                    else if (t0c[k] > 1 - 1e-12 && gi[k] < o->gn[k] - 2) { gi[k]++; t[k] = 0; }
                    else ok = 0;
                }
                t[k] = t[k] < 0 ? 0 : t[k] > 1 ? 1 : t[k];
            }
            if (!ok) continue;
            if (alt == 0) memcpy(tb, t, sizeof t);
            cc = gi[0] + nx * (gi[1] + ny * gi[2]);
            if (keep[cc]) { best = cc; memcpy(tb, t, sizeof t); }
        }
        if (best < 0) best = gc;   /* no kept candidate: keep its own cell (tb holds its coordinates) */
        keep[best] = 1;
        o->emb_cell[i] = best;   /* grid cell for now; renumbered below */
        memcpy(o->emb_t + 3 * i, tb, sizeof tb);
    }
}

/* step 7: each bone's radius and the lattice vertices it captures (bestd, bestseg,
 * mark: ngv entries of scratch; bestseg keeps the winner, -2 for pins) */
static void capture_bones(const sb_desc *d, sb_model *o, const sb_mesh *m, const sb_inside *in, const unsigned char *used,
                          double *bestd, int *bestseg, int *mark)
{
    double c = o->c;
    int i, k, a, ngv = o->gn[0] * o->gn[1] * o->gn[2];
    /* bones: radius (given, or automatic = half the flesh thickness, at most a quarter of
     * the bone's length), then capture (a) the rasterized chain: the grid vertex nearest each
     * sample, (b) every lattice vertex within the radius. Several claims: the nearest segment
     * wins (ties: the lower sorted joint index, i.e. the bone processed first). */
    o->seg_r = sb_alloc(sizeof(double) * (size_t)(o->nseg + 1));
    o->seg_flesh = sb_alloc(sizeof(double) * (size_t)(o->nseg + 1));
    o->seg_auto = sb_alloc(sizeof(int) * (size_t)(o->nseg + 1));
    o->seg_nv = sb_alloc(sizeof(int) * (size_t)(o->nseg + 1));
    o->seg_ncap = sb_alloc(sizeof(int) * (size_t)(o->nseg + 1));
    for (i = 0; i < ngv; i++) { bestd[i] = HUGE_VAL; bestseg[i] = -1; mark[i] = -1; }
    for (a = 0; a < o->nseg; a++) {
        const sb_joint *J = &o->joints[o->seg_child[a]];
        const double *P = seg_p(o, a), *C = seg_c(o, a);
        double r, L = 0, lo[3], hi[3];
        int s, ns = seg_samples(o, a), ilo[3], ihi[3], x, y, z;
        for (k = 0; k < 3; k++) L += (C[k] - P[k]) * (C[k] - P[k]);
        L = sqrt(L);
        o->seg_flesh[a] = flesh_thickness(o, m, in, a);
        if (J->bone_r >= 0) r = J->bone_r;
        else if (d->bone_radius >= 0) r = d->bone_radius;
        else { r = fmax(fmin(0.5 * o->seg_flesh[a], 0.25 * L), 1.25 * c); o->seg_auto[a] = 1; }
        o->seg_r[a] = r;
        for (s = 0; s <= ns; s++) {
            double p[3], dd;
            int g;
            seg_point(o, a, (double)s / ns, p);
            g = vertex_near(o, p);
            if (!used[g]) continue;
            dd = sb_seg_dist(o->gpos + 3 * g, P, C);
            if (mark[g] != a) { mark[g] = a; o->seg_ncap[a]++; }
            if (dd < bestd[g]) { bestd[g] = dd; bestseg[g] = a; }
        }
        for (k = 0; k < 3; k++) {
            lo[k] = fmin(P[k], C[k]) - r; hi[k] = fmax(P[k], C[k]) + r;
            /* clamped in double before the conversion: a huge radius must not overflow an int */
            ilo[k] = (int)fmax(0.0, fmin(o->gn[k], ceil((lo[k] - o->gorg[k]) / c - 1e-9)));
            ihi[k] = (int)fmin(o->gn[k] - 1, fmax(-1.0, floor((hi[k] - o->gorg[k]) / c + 1e-9)));
        }
        for (z = ilo[2]; z <= ihi[2]; z++) for (y = ilo[1]; y <= ihi[1]; y++) for (x = ilo[0]; x <= ihi[0]; x++) {
            int g = gidx(o, x, y, z);
            double dd;
            if (!used[g]) continue;
            dd = sb_seg_dist(o->gpos + 3 * g, P, C);
            if (!(dd <= r + 1e-9 * c)) continue;
            if (mark[g] != a) { mark[g] = a; o->seg_ncap[a]++; }
            if (dd < bestd[g]) { bestd[g] = dd; bestseg[g] = a; }
        }
    }
    for (i = 0; i < ngv; i++)
        if (bestseg[i] >= 0) o->gjoint[i] = o->joints[o->seg_child[bestseg[i]]].parent;   /* a bone moves with its parent joint */
    /* pins override */
    for (a = 0; a < d->npin; a++)
        for (i = 0; i < ngv; i++)
            if (used[i] && sb_region_has(o, &d->pins[a].r, o->gpos + 3 * i)) { o->gjoint[i] = o->desc_to_sorted[d->pins[a].joint]; bestseg[i] = -2; }
}

/* step 12: the block sparsity pattern, vertices sharing a cell (nbptr, nb) */
static void block_pattern(sb_model *o)
{
    int i, k, a;
    int *cnt = sb_alloc(sizeof(int) * (size_t)(o->nv + 1)), *tmp = sb_alloc(sizeof(int) * 27 * 8 * (size_t)o->nv);
    int *vc = sb_alloc(sizeof(int) * 8 * (size_t)o->nv);   /* cells per vertex (<= 8) */
    int *nvc = sb_alloc(sizeof(int) * (size_t)o->nv);
    for (a = 0; a < o->nc; a++) for (k = 0; k < 8; k++) { int v = o->cells[8 * a + k]; vc[8 * v + nvc[v]++] = a; }
    o->nbptr = sb_alloc(sizeof(int) * (size_t)(o->nv + 1));
    for (i = 0; i < o->nv; i++) {
        int nn = 0, *lst = tmp + 27 * 8 * i, x, y;
        for (a = 0; a < nvc[i]; a++) for (k = 0; k < 8; k++) lst[nn++] = o->cells[8 * vc[8 * i + a] + k];
        for (x = 1; x < nn; x++) { int v = lst[x]; for (y = x; y > 0 && lst[y - 1] > v; y--) lst[y] = lst[y - 1]; lst[y] = v; }
        for (x = 0, y = 0; x < nn; x++) if (y == 0 || lst[y - 1] != lst[x]) lst[y++] = lst[x];
        cnt[i] = y;
        o->nbptr[i + 1] = o->nbptr[i] + y;
    }
    o->nb = sb_alloc(sizeof(int) * (size_t)o->nbptr[o->nv]);
    for (i = 0; i < o->nv; i++) memcpy(o->nb + o->nbptr[i], tmp + 27 * 8 * i, sizeof(int) * (size_t)cnt[i]);
    free(cnt); free(tmp); free(vc); free(nvc);
}

int sb_build(const sb_desc *d, const sb_mesh *m, sb_model *o, int quiet)
{
    sb_inside in;
    int i, j, k, a, nj = d->nj, ngv, ngc;
    int *keep = NULL, *order, *bestseg = NULL, *mark = NULL, *cellno = NULL, *fidx = NULL;
    unsigned char *used = NULL;
    double *frac = NULL, c = d->cell, t0 = sb_now(), *bestd = NULL;
    int rc = -1;

    memset(o, 0, sizeof *o);
    o->quiet = quiet;
    o->unit = d->unit; o->h = d->h; o->alpha = d->alpha; o->beta = d->beta; o->cg_def = d->cg_def; o->cg_max = d->cg_max; o->precond = d->precond;
    o->rest_modelled = d->rest_modelled;
    o->mesh_volume = sb_mesh_volume(m) * d->unit * d->unit * d->unit;
    for (k = 0; k < 3; k++) o->g[k] = d->g[k];
    {
        double dd = 0;
        for (k = 0; k < 3; k++) dd += (m->hi[k] - m->lo[k]) * (m->hi[k] - m->lo[k]);
        o->bbox_diag = sqrt(dd);
    }
    sb_inside_init(&in, m);

    /* 1. joints sorted so parents precede children (stable in description order) */
    o->nj = nj;
    o->joints = sb_alloc(sizeof(sb_joint) * (size_t)nj);
    o->desc_to_sorted = sb_alloc(sizeof(int) * (size_t)nj);
    order = sb_alloc(sizeof(int) * (size_t)nj);
    for (i = 0; i < nj; i++) o->desc_to_sorted[i] = -1;
    for (k = 0; k < nj;) {
        for (i = 0; i < nj; i++)
            if (o->desc_to_sorted[i] < 0 && (d->joints[i].parent < 0 || o->desc_to_sorted[d->joints[i].parent] >= 0)) {
                o->desc_to_sorted[i] = k; order[k++] = i;
            }
    }
    for (k = 0; k < nj; k++) {
        o->joints[k] = d->joints[order[k]];
        o->joints[k].parent = d->joints[order[k]].parent < 0 ? -1 : o->desc_to_sorted[d->joints[order[k]].parent];
    }
    free(order);
    o->c = c;
    if (joints_outside(d, o, m, &in)) goto done;
    o->seg_child = sb_alloc(sizeof(int) * (size_t)nj);
    for (k = 1; k < nj; k++) o->seg_child[o->nseg++] = k;   /* segment a ends at sorted joint a + 1 */

    /* 2. grid: cubes of edge c aligned to the origin (default: the root joint), one cell of margin */
    {
        double org[3];
        for (k = 0; k < 3; k++) {
            double lo, hi;
            org[k] = d->has_origin ? d->origin[k] : o->joints[0].pos[k];
            lo = floor((m->lo[k] - org[k]) / c) - 1;
            hi = ceil((m->hi[k] - org[k]) / c) + 1;
            /* in double first: a tiny cell or a far origin must not overflow an int */
            if (!(hi - lo + 1 <= 4e6) || !(fabs(lo) <= 1e9) || !(fabs(hi) <= 1e9)) {
                sb_fail("%s: cell size %g (grid origin %g mesh units away on axis %d) gives a grid of %.3g vertices along one axis: "
                        "use a larger cell or an origin near the mesh", d->path, c, fabs(org[k] - m->lo[k]), k, hi - lo + 1);
                goto done;
            }
            o->gorg[k] = org[k] + lo * c;
            o->gn[k] = (int)(hi - lo) + 1;
        }
    }
    if ((double)o->gn[0] * o->gn[1] * o->gn[2] > 4e6) { sb_fail("%s: cell size %g is too small for this mesh (grid over 4 million vertices)", d->path, c); goto done; }
    ngv = o->gn[0] * o->gn[1] * o->gn[2];
    ngc = (o->gn[0] - 1) * (o->gn[1] - 1) * (o->gn[2] - 1);
    o->gpos = sb_alloc(sizeof(double) * 3 * (size_t)ngv);
    o->gjoint = sb_alloc(sizeof(int) * (size_t)ngv);
    o->gvert = sb_alloc(sizeof(int) * (size_t)ngv);
    for (k = 0; k < o->gn[2]; k++)
        for (j = 0; j < o->gn[1]; j++)
            for (i = 0; i < o->gn[0]; i++) {
                int g = gidx(o, i, j, k);
                o->gpos[3 * g] = o->gorg[0] + i * c;
                o->gpos[3 * g + 1] = o->gorg[1] + j * c;
                o->gpos[3 * g + 2] = o->gorg[2] + k * c;
                o->gjoint[g] = -1; o->gvert[g] = -1;
            }

    /* 3. inside fraction of every grid cell, the kept cells (sb_lattice_fill.c) */
    keep = sb_alloc(sizeof(int) * (size_t)ngc);
    fidx = sb_alloc(sizeof(int) * (size_t)ngc);
    if (sb_lattice_fill(d, m, o, &in, keep, fidx, &frac, t0)) goto done;

    /* 4. cells a bone needs: those holding a joint or a bone sample inside the mesh */
    for (a = 0; a < o->nseg; a++) {
        int s, ns = seg_samples(o, a);
        for (s = 0; s <= ns; s++) {
            double p[3];
            seg_point(o, a, (double)s / ns, p);
            if (s == 0 || s == ns || sb_inside_test(&in, p)) keep[cell_of(o, p)] = 1;
        }
    }

    /* 5. surface embedding: each mesh vertex in its grid cell, preferring a kept
     * neighbour when it lies on a cell face; that cell is kept */
    embed_surface(o, m, keep);

    /* 6. lattice vertices = corners of kept cells */
    used = sb_alloc((size_t)ngv);
    for (a = 0; a < ngc; a++)
        if (keep[a]) { int g[8]; cell_corners(o, a, g); for (k = 0; k < 8; k++) used[g[k]] = 1; }

    /* 7. bones: radii and capture; pins override */
    bestd = sb_alloc(sizeof(double) * (size_t)ngv);
    bestseg = sb_alloc(sizeof(int) * (size_t)ngv);
    mark = sb_alloc(sizeof(int) * (size_t)ngv);
    capture_bones(d, o, m, &in, used, bestd, bestseg, mark);

    /* 8. lattice vertices, free-first order */
    {
        int nskel = 0, nfree = 0;
        cellno = sb_alloc(sizeof(int) * (size_t)ngc);
        for (i = 0; i < ngv; i++) if (used[i]) { if (o->gjoint[i] < 0) nfree++; else nskel++; }
        if (nfree + nskel > 65535) {
            sb_fail("%s: %d lattice vertices (max 65535); use a larger cell (about %.3g)", d->path, nfree + nskel, c * pow((nfree + nskel) / 55000.0, 1.0 / 3.0));
            goto done;
        }
        if (nskel == 0) { sb_fail("%s: no skeleton vertices: add a bone (two joints) or a 'pin' region", d->path); goto done; }
        if (nfree == 0) {
            sb_fail("%s: no free vertices: the bones (and pins) hold every lattice vertex; use smaller bone radii ('bone_radius R') or a smaller cell (now %g)", d->path, c);
            goto done;
        }
        o->nv = nfree + nskel; o->nf = nfree;
        o->v_grid = sb_alloc(sizeof(int) * (size_t)o->nv);
        o->x = sb_alloc(sizeof(double) * 3 * (size_t)o->nv);
        o->vseg = sb_alloc(sizeof(int) * (size_t)o->nv);
        nfree = 0; nskel = o->nf;
        for (i = 0; i < ngv; i++)
            if (used[i]) {
                int v = o->gjoint[i] < 0 ? nfree++ : nskel++;
                o->gvert[i] = v; o->v_grid[v] = i;
                memcpy(o->x + 3 * v, o->gpos + 3 * i, sizeof(double) * 3);
                o->vseg[v] = o->gjoint[i] < 0 ? -1 : bestseg[i];
                if (o->vseg[v] >= 0) o->seg_nv[o->vseg[v]]++;
            }
        for (a = 0; a < ngc; a++) if (keep[a]) o->nc++;
        o->cells = sb_alloc(sizeof(int) * 8 * (size_t)o->nc);
        o->cell_grid = sb_alloc(sizeof(int) * (size_t)o->nc);
        for (a = 0, j = 0; a < ngc; a++)
            if (keep[a]) {
                int g[8];
                cell_corners(o, a, g);
                for (k = 0; k < 8; k++) o->cells[8 * j + k] = o->gvert[g[k]];
                o->cell_grid[j] = a; cellno[a] = j; j++;
            }
        for (i = 0; i < m->nv; i++) o->emb_cell[i] = cellno[o->emb_cell[i]];
        {   /* inside fraction per kept cell (was per grid cell) */
            double *fill = sb_alloc(sizeof(double) * (size_t)o->nc);
            for (j = 0; j < o->nc; j++) fill[j] = o->cell_fill[o->cell_grid[j]];
            free(o->cell_fill);
            o->cell_fill = fill;
        }
    }
    for (a = 0; a < o->nseg; a++)   /* cannot happen while the joints are inside (their cells are kept); a safety net */
        if (o->seg_ncap[a] == 0)
            fprintf(stderr, "sinew-bake: warning: %s:%d: bone '%s'->'%s' captures no lattice vertex; its flesh follows the neighbouring bones\n",
                    d->path, o->joints[o->seg_child[a]].line, o->joints[o->joints[o->seg_child[a]].parent].name, o->joints[o->seg_child[a]].name);

    /* 9. every kept cell an undistorted cube (sb_lattice_geom.c) */
    if (sb_lattice_cubes(d, o)) goto done;

    /* 10. frames (seed 003 §3.3; sb_frames.c) */
    sb_lattice_frames(d, o);

    /* 11. limits at rest positions, later rules override */
    o->limit = sb_alloc(sizeof(double) * (size_t)o->nv);
    for (a = 0; a < d->nlr; a++)
        for (i = 0; i < o->nv; i++)
            if (sb_region_has(o, &d->lrules[a].r, o->x + 3 * i)) o->limit[i] = d->lrules[a].dist;

    /* 12. block sparsity pattern: vertices sharing a cell */
    block_pattern(o);
    o->M = sb_alloc(sizeof(double) * (size_t)o->nbptr[o->nv]);
    o->S = sb_alloc(sizeof(double) * 9 * (size_t)o->nbptr[o->nv]);
    o->T = sb_alloc(sizeof(double) * (size_t)o->nbptr[o->nv]);   /* twist retired: stays 0 */
    o->Se = sb_alloc(sizeof(double) * 576 * (size_t)o->nc);
    if (d->lod_level && d->levels_cut) o->Me = sb_alloc(sizeof(double) * 64 * (size_t)o->nc);   /* the cut level's Galerkin mass (sb_cut.c) */

    /* 13. integrals */
    if (sb_integrate_frac(d, o, frac, fidx)) goto done;

    o->nt = m->nt;
    o->tri = sb_alloc(sizeof(int) * 3 * (size_t)m->nt);
    memcpy(o->tri, m->tri, sizeof(int) * 3 * (size_t)m->nt);
    rc = 0;
done:
    if (!quiet && sb_now() - t0 > 1.0) fprintf(stderr, "\n");
    sb_inside_free(&in);
    free(keep); free(frac); free(fidx); free(used); free(bestd); free(bestseg); free(mark); free(cellno);
    return rc;
}

void sb_model_free(sb_model *o)
{
    sb_rig_free(o); /* idempotent: callers that freed the rigs first are fine */
    sb_force_free(o);
    sb_segment_free(o);
    sb_crease_free(o);
    free(o->joints); free(o->desc_to_sorted); free(o->seg_child); free(o->gpos); free(o->gjoint); free(o->gvert);
    free(o->v_grid); free(o->x); free(o->cells); free(o->cell_grid); free(o->cell_fill); free(o->fb1); free(o->fb2); free(o->fw);
    free(o->nbptr); free(o->nb); free(o->M); free(o->S); free(o->T); free(o->emb_cell); free(o->emb_t); free(o->tri);
    free(o->Se); free(o->Me); free(o->cfb1); free(o->cfb2); free(o->cfw); free(o->limit); free(o->vseg);
    free(o->seg_r); free(o->seg_flesh); free(o->seg_auto); free(o->seg_nv); free(o->seg_ncap);
    sb_srcmap_free(&o->src);
    memset(o, 0, sizeof *o);
}

int sb_model_check(const sb_model *o, const sb_mesh *m, sb_check *r)
{
    double maxS = 0, maxx = 0, trans = 0, rot = 0, worst = 0;
    int i, e, k, a, b;
    memset(r, 0, sizeof *r);
    r->vol_ratio = o->mesh_volume > 0 ? o->inside_volume / o->mesh_volume : 0;
    /* embedding with t quantized to Q15 as the blob stores it */
    for (i = 0; i < o->ns && i < m->nv; i++) {
        double t[3], p[3], dd = 0;
        for (k = 0; k < 3; k++) t[k] = floor(o->emb_t[3 * i + k] * 32768.0 + 0.5) / 32768.0;
        sb_cell_point(o, o->emb_cell[i], t, p);
        for (k = 0; k < 3; k++) dd += (p[k] - m->v[3 * i + k]) * (p[k] - m->v[3 * i + k]);
        worst = fmax(worst, sqrt(dd));
    }
    r->emb_err = worst / o->bbox_diag;
    /* null space of the elastic stiffness: translations (block row sums) and rest rotations */
    for (e = 0; e < o->nbptr[o->nv]; e++) for (k = 0; k < 9; k++) maxS = fmax(maxS, fabs(o->S[9 * (size_t)e + (size_t)k]));
    for (i = 0; i < o->nv; i++) for (k = 0; k < 3; k++) maxx = fmax(maxx, fabs(o->x[3 * i + k] * o->unit));
    for (i = 0; i < o->nv; i++)
        for (a = 0; a < 3; a++) {
            double ts[3] = {0, 0, 0}, rs[3] = {0, 0, 0};
            for (e = o->nbptr[i]; e < o->nbptr[i + 1]; e++) {
                const double *x = o->x + 3 * o->nb[e], *S = o->S + 9 * (size_t)e + 3 * (size_t)a;
                for (b = 0; b < 3; b++) {   /* rotation about axis b: u = e_b x x (metres) */
                    double u[3] = {0, 0, 0}, rr[3];
                    u[b] = 1;
                    ts[b] += S[b];
                    rr[0] = u[1] * x[2] - u[2] * x[1]; rr[1] = u[2] * x[0] - u[0] * x[2]; rr[2] = u[0] * x[1] - u[1] * x[0];
                    for (k = 0; k < 3; k++) rs[b] += S[k] * rr[k] * o->unit;
                }
            }
            for (b = 0; b < 3; b++) { trans = fmax(trans, fabs(ts[b])); rot = fmax(rot, fabs(rs[b])); }
        }
    r->trans = maxS > 0 ? trans / maxS : 1;
    r->rot = maxS > 0 && maxx > 0 ? rot / (maxS * maxx) : 1;
    r->ok = fabs(r->vol_ratio - 1) <= 0.01 && r->emb_err <= 1e-5 && r->trans <= 1e-12 && r->rot <= 1e-11;
    return r->ok ? 0 : -1;
}
