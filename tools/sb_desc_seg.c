/* sb_desc_seg.c -- the segment-mesh keywords: chain, sheet, attach. */
#include "sb_desc_int.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int find_seg(const sb_desc *d, const char *name)
{
    int i;
    for (i = 0; i < d->nseg; i++) if (!strcmp(d->segs[i].name, name)) return i;
    return -1;
}

/* Options of a 'chain' / 'sheet' line from tok[first] on: KEY VALUE pairs
 * (shares takes one value per level). */
static int seg_options(sb_dctx *c, sb_segdef *g, int first)
{
    int i = first, k, nsh = 0, sheet = g->kind == 1;
    while (i < c->nt) {
        const char *key = c->tok[i];
        if (!strcmp(key, "shares")) {
            if (!sheet) return sb_fail("%s:%d: 'shares' is for sheets (a chain has one level)", c->path, c->line);
            for (k = 0, i++; i < c->nt && k < 5; k++, i++) {
                char *end;
                strtod(c->tok[i], &end);
                if (end == c->tok[i] || *end) break;   /* the next option */
                if (k == 4) return sb_fail("%s:%d: 'shares' takes at most 4 values (one per level, finest first)", c->path, c->line);
                if (sbd_num(c, i, &g->share[k])) return -1;
                if (g->share[k] < 0 || g->share[k] > 1) return sb_fail("%s:%d: share '%s' must be in [0, 1]", c->path, c->line, c->tok[i]);
            }
            if (k == 0) return sb_fail("%s:%d: missing value: 'shares F0 [F1 F2 F3]' (one per level, finest first)", c->path, c->line);
            nsh = k;
            continue;
        }
        if (i + 1 >= c->nt) {
            static const char *known[] = {"mass", "sweeps", "gamma", "damping", "centre", "gravity", "levels", "relax", "coarse_sweeps"};
            for (k = 0; k < 9; k++) if (!strcmp(key, known[k])) return sb_fail("%s:%d: missing value after '%s'", c->path, c->line, key);
            return sb_fail("%s:%d: unknown %s option '%s' (want mass, sweeps, relax, gamma, damping, centre, gravity%s)", c->path, c->line,
                           sheet ? "sheet" : "chain", key, sheet ? ", levels, shares, coarse_sweeps" : "");
        }
        if (!strcmp(key, "mass")) {
            if (sbd_num(c, i + 1, &g->mass)) return -1;
            if (!(g->mass > 0 && g->mass <= 1e6)) return sb_fail("%s:%d: mass must be in (0, 1e6] kg (got %g)", c->path, c->line, g->mass);
        } else if (!strcmp(key, "sweeps")) {
            if (sbd_inum(c, i + 1, 1, 64, &g->sweeps)) return -1;
        } else if (!strcmp(key, "coarse_sweeps")) {
            if (!sheet) return sb_fail("%s:%d: 'coarse_sweeps' is for sheets (a chain has one level)", c->path, c->line);
            if (sbd_inum(c, i + 1, 1, 64, &g->coarse_sweeps)) return -1;
        } else if (!strcmp(key, "relax")) {
            double w, k32;
            if (sbd_num(c, i + 1, &w)) return -1;
            if (!(w >= 1 && w <= 63.0 / 32))
                return sb_fail("%s:%d: relax (over-relaxation omega) must be in [1, 1.96875] (got %g)", c->path, c->line, w);
            k32 = floor(w * 32 + 0.5);
            if (fabs(w * 32 - k32) > 1e-9)
                return sb_fail("%s:%d: relax %g is not a multiple of 1/32 (the blob stores 32 omega): use %g or %g", c->path, c->line, w,
                               floor(w * 32) / 32, ceil(w * 32) / 32);
            g->relax = (int)k32;
        } else if (!strcmp(key, "gamma")) {
            if (sbd_num(c, i + 1, &g->gamma)) return -1;
            /* gamma = 0 only rotates: the constraints do not converge (seed 004 §3.2.2) */
            if (!(g->gamma > 0 && g->gamma <= 1)) return sb_fail("%s:%d: gamma (translation factor) must be in (0, 1] (got %g)", c->path, c->line, g->gamma);
        } else if (!strcmp(key, "damping")) {
            if (sbd_num(c, i + 1, &g->damping)) return -1;
            if (!(g->damping >= 0 && g->damping <= 1e4)) return sb_fail("%s:%d: damping must be in [0, 1e4] per second (got %g)", c->path, c->line, g->damping);
        } else if (!strcmp(key, "centre")) {
            if (sbd_num(c, i + 1, &g->centre)) return -1;
            if (!(g->centre >= 0 && g->centre <= 1)) return sb_fail("%s:%d: centre share must be in [0, 1] (got %g)", c->path, c->line, g->centre);
        } else if (!strcmp(key, "gravity")) {
            if (!strcmp(c->tok[i + 1], "on")) g->gravity = 1;
            else if (!strcmp(c->tok[i + 1], "off")) g->gravity = 0;
            else return sb_fail("%s:%d: gravity must be 'on' or 'off' (got '%s')", c->path, c->line, c->tok[i + 1]);
        } else if (!strcmp(key, "levels")) {
            if (!sheet) return sb_fail("%s:%d: 'levels' is for sheets (a chain has one level)", c->path, c->line);
            if (sbd_inum(c, i + 1, 1, 4, &g->levels)) return -1;
        } else {
            return sb_fail("%s:%d: unknown %s option '%s' (want mass, sweeps, relax, gamma, damping, centre, gravity%s)", c->path, c->line,
                           sheet ? "sheet" : "chain", key, sheet ? ", levels, shares, coarse_sweeps" : "");
        }
        i += 2;
    }
    /* omega (1 - gamma) <= 1: a turn closes at most all of the gap's
     * perpendicular part, and the runtime's turn factors keep their int32
     * bound (the validator's check, sn_segment_api.c) */
    if (g->relax * (1 - g->gamma) > 32 + 1e-9)
        return sb_fail("%s:%d: %s '%s': relax %g with gamma %g over-relaxes the turns: want relax (1 - gamma) <= 1 (relax <= %g)", c->path,
                       c->line, sheet ? "sheet" : "chain", g->name, g->relax / 32.0, g->gamma, floor(32 / (1 - g->gamma)) / 32);
    if (sheet) {
        int n = 0, maxl;
        double sum = 0;
        while ((1 << n) + 1 < g->side) n++;
        maxl = n + 1 < 4 ? n + 1 : 4;
        if (g->levels == 0) g->levels = nsh ? nsh : 1;
        if (g->levels > maxl)
            return sb_fail("%s:%d: sheet '%s': %d levels, at most %d for side %d (= 2^%d + 1; levels <= min(n + 1, 4))", c->path, c->line, g->name, g->levels, maxl, g->side, n, n);
        if (nsh && nsh != g->levels)
            return sb_fail("%s:%d: sheet '%s': %d share(s) for %d level(s): give one per level, finest first", c->path, c->line, g->name, nsh, g->levels);
        if (g->coarse_sweeps && g->levels == 1)
            return sb_fail("%s:%d: sheet '%s': 'coarse_sweeps' needs levels >= 2 (one level takes 'sweeps')", c->path, c->line, g->name);
        if (!nsh) g->share[0] = 1;   /* all on the finest level: Gascuel's original method (seed 004 fig. 4.9) */
        for (k = 0; k < 4; k++) sum += g->share[k];
        if (fabs(sum - 1) > 1e-6) return sb_fail("%s:%d: sheet '%s': shares sum to %.9g, want 1", c->path, c->line, g->name, sum);
    } else {
        g->levels = 1; g->share[0] = 1;
    }
    return 0;
}

/* 'chain' / 'sheet' line */
static int seg_line(sb_dctx *c, sb_desc *d)
{
    sb_segdef g;
    int sheet = !strcmp(c->tok[0], "sheet"), k, first;
    static const char *usage[2] = {"'chain NAME nodes N from X Y Z to X Y Z [OPTIONS]'", "'sheet NAME side S corner X Y Z u X Y Z v X Y Z [OPTIONS]'"};
    memset(&g, 0, sizeof g);
    g.kind = sheet; g.line = c->line;
    g.mass = 1; g.sweeps = 8; g.relax = 32; g.gamma = 0.5; g.damping = 0.5; g.centre = 0.5; g.gravity = 1;
    if (c->nt < (sheet ? 16 : 12)) return sb_fail("%s:%d: missing value: %s", c->path, c->line, usage[sheet]);
    if (strlen(c->tok[1]) >= SB_NAME_MAX) return sb_fail("%s:%d: segment mesh names are at most %d characters", c->path, c->line, SB_NAME_MAX - 1);
    if (find_seg(d, c->tok[1]) >= 0) return sb_fail("%s:%d: segment mesh '%s' declared twice", c->path, c->line, c->tok[1]);
    if (d->nseg >= 64) return sb_fail("%s:%d: more than 64 segment meshes", c->path, c->line);
    strcpy(g.name, c->tok[1]);
    if (strcmp(c->tok[2], sheet ? "side" : "nodes"))
        return sb_fail("%s:%d: expected '%s' after the name: %s", c->path, c->line, sheet ? "side" : "nodes", usage[sheet]);
    if (sheet) {
        if (sbd_inum(c, 3, 3, 65, &g.side)) return -1;
        if (((g.side - 1) & (g.side - 2)) != 0)
            return sb_fail("%s:%d: sheet side %d is not 2^n + 1 (3, 5, 9, 17, 33 or 65; seed 004 §4.2)", c->path, c->line, g.side);
        if (strcmp(c->tok[4], "corner") || strcmp(c->tok[8], "u") || strcmp(c->tok[12], "v"))
            return sb_fail("%s:%d: %s", c->path, c->line, usage[1]);
        for (k = 0; k < 3; k++)
            if (sbd_len(c, 5 + k, &g.p0[k]) || sbd_len(c, 9 + k, &g.u[k]) || sbd_len(c, 13 + k, &g.v[k])) return -1;
        first = 16;
    } else {
        double e[3];
        if (sbd_inum(c, 3, 2, 256, &g.side)) return -1;
        if (strcmp(c->tok[4], "from") || strcmp(c->tok[8], "to")) return sb_fail("%s:%d: %s", c->path, c->line, usage[0]);
        for (k = 0; k < 3; k++) {
            if (sbd_len(c, 5 + k, &g.p0[k]) || sbd_len(c, 9 + k, &e[k])) return -1;
            g.u[k] = e[k] - g.p0[k];
        }
        first = 12;
    }
    {   /* equal segment lengths: a chain's ends apart; a sheet's edges equal and orthogonal */
        double lu = sqrt(g.u[0] * g.u[0] + g.u[1] * g.u[1] + g.u[2] * g.u[2]);
        double lv = sqrt(g.v[0] * g.v[0] + g.v[1] * g.v[1] + g.v[2] * g.v[2]);
        double dot = g.u[0] * g.v[0] + g.u[1] * g.v[1] + g.u[2] * g.v[2];
        if (!(lu > 1e-9)) return sb_fail("%s:%d: %s '%s' has zero length", c->path, c->line, sheet ? "sheet" : "chain", g.name);
        if (sheet) {
            if (!(lv > 1e-9)) return sb_fail("%s:%d: sheet '%s': edge v is the zero vector", c->path, c->line, g.name);
            if (fabs(lu - lv) > 1e-6 * lu)
                return sb_fail("%s:%d: sheet '%s': edges u and v have lengths %g and %g: a sheet is square (equal segments)", c->path, c->line, g.name, lu, lv);
            if (fabs(dot) > 1e-6 * lu * lv)
                return sb_fail("%s:%d: sheet '%s': edges u and v are not perpendicular (angle %.6g degrees)", c->path, c->line, g.name,
                               acos(fmax(-1.0, fmin(1.0, dot / (lu * lv)))) * 180.0 / 3.14159265358979323846);
        }
    }
    if (seg_options(c, &g, first)) return -1;
    GROW(d->segs, d->nseg);
    d->segs[d->nseg++] = g;
    return 0;
}

/* 'attach MESH NODES surface [within D]' / 'attach MESH NODES joint JOINT' */
static int attach_line(sb_dctx *c, sb_desc *d)
{
    sb_segdef *g;
    int gi, nodes[260], nn = 0, i = 3, k, j, sheet, side, idx = 0, kind, joint = -1;
    double within = -1;
    const char *sel;
    if (c->nt < 4) return sb_fail("%s:%d: missing value: 'attach MESH NODES surface [within D]' or 'attach MESH NODES joint JOINT'", c->path, c->line);
    gi = find_seg(d, c->tok[1]);
    if (gi < 0) return sb_fail("%s:%d: unknown segment mesh '%s' (declare the chain or sheet before attaching it)", c->path, c->line, c->tok[1]);
    g = &d->segs[gi];
    sheet = g->kind == 1; side = g->side;
    sel = c->tok[2];
    if (!strcmp(sel, "node") || !strcmp(sel, "row") || !strcmp(sel, "col")) {
        int hi = !strcmp(sel, "node") ? (sheet ? side * side : side) - 1 : side - 1;
        if (!sheet && strcmp(sel, "node")) return sb_fail("%s:%d: '%s' is for sheets (chains: first, last or node I)", c->path, c->line, sel);
        if (sbd_inum(c, 3, 0, hi, &idx)) return -1;
        i = 4;
    } else if (strcmp(sel, "first") && strcmp(sel, "last") && strcmp(sel, "corners")) {
        return sb_fail("%s:%d: unknown node selection '%s' (want first, last, node I%s)", c->path, c->line, sel, sheet ? ", row R, col C, corners" : "");
    } else if (!sheet && !strcmp(sel, "corners")) {
        return sb_fail("%s:%d: 'corners' is for sheets (chains: first, last or node I)", c->path, c->line);
    }
    if (!strcmp(sel, "first")) nodes[nn++] = 0;
    else if (!strcmp(sel, "last")) nodes[nn++] = sheet ? side * side - 1 : side - 1;
    else if (!strcmp(sel, "node")) nodes[nn++] = idx;
    else if (!strcmp(sel, "row")) for (k = 0; k < side; k++) nodes[nn++] = idx * side + k;
    else if (!strcmp(sel, "col")) for (k = 0; k < side; k++) nodes[nn++] = k * side + idx;
    else { nodes[0] = 0; nodes[1] = side - 1; nodes[2] = (side - 1) * side; nodes[3] = side * side - 1; nn = 4; }
    if (i >= c->nt) return sb_fail("%s:%d: missing value: the target after the nodes ('surface [within D]' or 'joint JOINT')", c->path, c->line);
    if (!strcmp(c->tok[i], "surface")) {
        kind = SB_SEGATT_SURFACE;
        if (c->nt == i + 3 && !strcmp(c->tok[i + 1], "within")) {
            if (sbd_len(c, i + 2, &within)) return -1;
            if (!(within >= 0)) return sb_fail("%s:%d: 'within' distance must be >= 0", c->path, c->line);
        } else if (c->nt != i + 1) {
            return sb_fail("%s:%d: %s: 'attach MESH NODES surface [within D]'", c->path, c->line, c->nt == i + 2 && !strcmp(c->tok[i + 1], "within") ? "missing value" : "too many values");
        }
    } else if (!strcmp(c->tok[i], "joint")) {
        kind = SB_SEGATT_JOINT;
        if (c->nt != i + 2) return sb_fail("%s:%d: %s: 'attach MESH NODES joint JOINT'", c->path, c->line, c->nt < i + 2 ? "missing value" : "too many values");
        joint = sbd_find_joint(d, c->tok[i + 1]);
        if (joint < 0) return sb_fail("%s:%d: unknown joint '%s' (declare joints before using them)", c->path, c->line, c->tok[i + 1]);
    } else {
        return sb_fail("%s:%d: unknown attachment target '%s' (want surface or joint)", c->path, c->line, c->tok[i]);
    }
    for (k = 0; k < nn; k++) {
        for (j = 0; j < g->natt; j++)
            if (g->att[j].node == nodes[k])
                return sb_fail("%s:%d: %s '%s': node %d is already attached (line %d)", c->path, c->line, sheet ? "sheet" : "chain", g->name, nodes[k], g->att[j].line);
        GROW(g->att, g->natt);
        g->att[g->natt].node = nodes[k];
        g->att[g->natt].kind = kind;
        g->att[g->natt].joint = joint;
        g->att[g->natt].within = within;
        g->att[g->natt].line = c->line;
        g->natt++;
    }
    return 0;
}
/* 'chain', 'sheet' and 'attach' lines; 1 when the line is not one of them */
int sbd_seg_line(sb_dctx *c, sb_desc *d)
{
    const char *kw = c->tok[0];

    if (!strcmp(kw, "chain") || !strcmp(kw, "sheet")) {
        if (seg_line(c, d)) return -1;
    } else if (!strcmp(kw, "attach")) {
        if (attach_line(c, d)) return -1;
    } else {
        return 1;
    }
    return 0;
}
