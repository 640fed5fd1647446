/* sb_desc.c -- the text character description (format: tools/DESCRIPTION.md). */
#include "sb.h"
#include "sb_gltf.h"
#include "../runtime/src/sn_format.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const char *path;
    int line;
    char *tok[64];
    int nt;
} ctx_t;

static int num(ctx_t *c, int i, double *out)
{
    char *end;
    if (i >= c->nt) return sb_fail("%s:%d: missing value after '%s'", c->path, c->line, c->tok[c->nt - 1]);
    *out = strtod(c->tok[i], &end);
    if (end == c->tok[i] || *end) return sb_fail("%s:%d: '%s' is not a number", c->path, c->line, c->tok[i]);
    if (!isfinite(*out)) return sb_fail("%s:%d: '%s' is not a finite number", c->path, c->line, c->tok[i]);
    return 0;
}

/* A length or a position in mesh units. A mesh spans at most 32768 units
 * and lies within 1e9 of its origin (sb_mesh.c), so anything farther is a
 * typo; the bound also keeps every grid index the lattice computes from it in
 * int range. */
#define SB_MAX_LEN 1e9
static int len_num(ctx_t *c, int i, double *out)
{
    if (num(c, i, out)) return -1;
    if (fabs(*out) > SB_MAX_LEN) return sb_fail("%s:%d: '%s' is beyond %g mesh units", c->path, c->line, c->tok[i], SB_MAX_LEN);
    return 0;
}

static int inum(ctx_t *c, int i, int lo, int hi, int *out)
{
    double v = 0;
    if (num(c, i, &v)) return -1;
    if (v != floor(v) || v < lo || v > hi) return sb_fail("%s:%d: '%s' must be an integer in %d..%d", c->path, c->line, c->tok[i], lo, hi);
    *out = (int)v;
    return 0;
}

static int nargs(ctx_t *c, int n)
{
    if (c->nt - 1 < n) return sb_fail("%s:%d: missing value: '%s' takes %d value(s), got %d", c->path, c->line, c->tok[0], n, c->nt - 1);
    if (c->nt - 1 > n) return sb_fail("%s:%d: '%s' takes %d value(s), got %d (extra '%s')", c->path, c->line, c->tok[0], n, c->nt - 1, c->tok[n + 1]);
    return 0;
}

static int find_joint(const sb_desc *d, const char *name)
{
    int i;
    for (i = 0; i < d->nj; i++) if (!strcmp(d->joints[i].name, name)) return i;
    return -1;
}
static int find_mat(const sb_desc *d, const char *name)
{
    int i;
    for (i = 0; i < d->nm; i++) if (!strcmp(d->mats[i].name, name)) return i;
    return -1;
}

static int find_ctl(const sb_desc *d, const char *name)
{
    int i;
    for (i = 0; i < d->nctl; i++) if (!strcmp(d->ctls[i].name, name)) return i;
    return -1;
}
static int find_rig(const sb_desc *d, const char *name)
{
    int i;
    for (i = 0; i < d->nrig; i++) if (!strcmp(d->rigs[i].name, name)) return i;
    return -1;
}

/* three numbers at tok[i..i+2] forming a non-zero vector, normalized if unit */
static int vec3(ctx_t *c, int i, const char *what, int unit, double v[3])
{
    double n;
    int k;
    for (k = 0; k < 3; k++) if (num(c, i + k, &v[k])) return -1;
    n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (unit) {
        if (!(n > 1e-12)) return sb_fail("%s:%d: %s (%s %s %s) is the zero vector", c->path, c->line, what, c->tok[i], c->tok[i + 1], c->tok[i + 2]);
        for (k = 0; k < 3; k++) v[k] /= n;
    }
    return 0;
}

/* tau samples: n pairs at tok[first..first+2n) */
static int tau_samples(ctx_t *c, int first, sb_rigdef *r)
{
    int n = c->nt - first, k;
    if (n <= 0) return sb_fail("%s:%d: 'tau' needs samples: GAMMA1 ETA1 [GAMMA2 ETA2 ...]", c->path, c->line);
    if (n % 2) return sb_fail("%s:%d: tau samples come in pairs GAMMA ETA (got %d values)", c->path, c->line, n);
    if (n / 2 > SB_TAU_MAX) return sb_fail("%s:%d: rig '%s': %d tau samples, at most %d", c->path, c->line, r->name, n / 2, SB_TAU_MAX);
    for (k = 0; k < n / 2; k++) {
        if (num(c, first + 2 * k, &r->tau_g[k]) || num(c, first + 2 * k + 1, &r->tau_e[k])) return -1;
        /* the runtime validates |gamma| <= 16384 (sn_blob.c: differences fit 2^31 in Q16.16) */
        if (fabs(r->tau_g[k]) > 16384.0) return sb_fail("%s:%d: tau gamma %g out of range (|gamma| <= 16384)", c->path, c->line, r->tau_g[k]);
        if (fabs(r->tau_e[k]) > 1e6) return sb_fail("%s:%d: tau eta %g out of range (|eta| <= 1e6)", c->path, c->line, r->tau_e[k]);
        if (k > 0 && !(r->tau_g[k] > r->tau_g[k - 1]))
            return sb_fail("%s:%d: rig '%s': tau gammas must be strictly increasing (%g after %g)", c->path, c->line, r->name, r->tau_g[k], r->tau_g[k - 1]);
    }
    r->ntau = n / 2;
    r->tau_line = c->line;
    return 0;
}

/* region at tok[first]: all | box x0 y0 z0 x1 y1 z1 | sphere cx cy cz r | bone JOINT.
 * Returns the number of tokens used, -1 on error. */
static int region(ctx_t *c, const sb_desc *d, int first, int tail, sb_region *r)
{
    int k, n;
    const char *kind;
    memset(r, 0, sizeof *r);
    r->line = c->line;
    if (first >= c->nt) return sb_fail("%s:%d: missing region (all, box, sphere or bone)", c->path, c->line);
    kind = c->tok[first];
    if (!strcmp(kind, "all")) { r->kind = SB_RG_ALL; n = 1; }
    else if (!strcmp(kind, "box")) { r->kind = SB_RG_BOX; n = 7; }
    else if (!strcmp(kind, "sphere")) { r->kind = SB_RG_SPHERE; n = 5; }
    else if (!strcmp(kind, "bone")) { r->kind = SB_RG_BONE; n = 2; }
    else return sb_fail("%s:%d: unknown region '%s' (want all, box, sphere or bone)", c->path, c->line, kind);
    if (c->nt != first + n + tail)
        return sb_fail("%s:%d: %s: '%s %s' takes %d value(s) followed by %d more", c->path, c->line,
                       c->nt < first + n + tail ? "missing value" : "too many values", c->tok[0], kind, n - 1, tail);
    if (r->kind == SB_RG_BOX || r->kind == SB_RG_SPHERE)
        for (k = 0; k < n - 1; k++) if (len_num(c, first + 1 + k, &r->a[k])) return -1;
    if (r->kind == SB_RG_BOX)
        for (k = 0; k < 3; k++) if (r->a[k] > r->a[k + 3]) return sb_fail("%s:%d: box lower corner above upper corner", c->path, c->line);
    if (r->kind == SB_RG_SPHERE && r->a[3] <= 0) return sb_fail("%s:%d: sphere radius must be positive", c->path, c->line);
    if (r->kind == SB_RG_BONE) {
        r->bone = find_joint(d, c->tok[first + 1]);
        if (r->bone < 0) return sb_fail("%s:%d: unknown joint '%s' (declare joints before using them)", c->path, c->line, c->tok[first + 1]);
        if (!strcmp(d->joints[r->bone].parent_name, "-")) /* parents resolve after the last line */ return sb_fail("%s:%d: '%s' is the root: a bone is named by its child joint", c->path, c->line, c->tok[first + 1]);
    }
    return n;
}

#define GROW(arr, n) do { arr = realloc(arr, sizeof(*(arr)) * (size_t)((n) + 1)); if (!(arr)) return sb_fail("out of memory"); memset(&(arr)[n], 0, sizeof(*(arr))); } while (0)

static int find_seg(const sb_desc *d, const char *name)
{
    int i;
    for (i = 0; i < d->nseg; i++) if (!strcmp(d->segs[i].name, name)) return i;
    return -1;
}

/* Options of a 'chain' / 'sheet' line from tok[first] on: KEY VALUE pairs
 * (shares takes one value per level). */
static int seg_options(ctx_t *c, sb_segdef *g, int first)
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
                if (num(c, i, &g->share[k])) return -1;
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
            if (num(c, i + 1, &g->mass)) return -1;
            if (!(g->mass > 0 && g->mass <= 1e6)) return sb_fail("%s:%d: mass must be in (0, 1e6] kg (got %g)", c->path, c->line, g->mass);
        } else if (!strcmp(key, "sweeps")) {
            if (inum(c, i + 1, 1, 64, &g->sweeps)) return -1;
        } else if (!strcmp(key, "coarse_sweeps")) {
            if (!sheet) return sb_fail("%s:%d: 'coarse_sweeps' is for sheets (a chain has one level)", c->path, c->line);
            if (inum(c, i + 1, 1, 64, &g->coarse_sweeps)) return -1;
        } else if (!strcmp(key, "relax")) {
            double w, k32;
            if (num(c, i + 1, &w)) return -1;
            if (!(w >= 1 && w <= 63.0 / 32))
                return sb_fail("%s:%d: relax (over-relaxation omega) must be in [1, 1.96875] (got %g)", c->path, c->line, w);
            k32 = floor(w * 32 + 0.5);
            if (fabs(w * 32 - k32) > 1e-9)
                return sb_fail("%s:%d: relax %g is not a multiple of 1/32 (the blob stores 32 omega): use %g or %g", c->path, c->line, w,
                               floor(w * 32) / 32, ceil(w * 32) / 32);
            g->relax = (int)k32;
        } else if (!strcmp(key, "gamma")) {
            if (num(c, i + 1, &g->gamma)) return -1;
            /* gamma = 0 only rotates: the constraints do not converge (seed 004 §3.2.2) */
            if (!(g->gamma > 0 && g->gamma <= 1)) return sb_fail("%s:%d: gamma (translation factor) must be in (0, 1] (got %g)", c->path, c->line, g->gamma);
        } else if (!strcmp(key, "damping")) {
            if (num(c, i + 1, &g->damping)) return -1;
            if (!(g->damping >= 0 && g->damping <= 1e4)) return sb_fail("%s:%d: damping must be in [0, 1e4] per second (got %g)", c->path, c->line, g->damping);
        } else if (!strcmp(key, "centre")) {
            if (num(c, i + 1, &g->centre)) return -1;
            if (!(g->centre >= 0 && g->centre <= 1)) return sb_fail("%s:%d: centre share must be in [0, 1] (got %g)", c->path, c->line, g->centre);
        } else if (!strcmp(key, "gravity")) {
            if (!strcmp(c->tok[i + 1], "on")) g->gravity = 1;
            else if (!strcmp(c->tok[i + 1], "off")) g->gravity = 0;
            else return sb_fail("%s:%d: gravity must be 'on' or 'off' (got '%s')", c->path, c->line, c->tok[i + 1]);
        } else if (!strcmp(key, "levels")) {
            if (!sheet) return sb_fail("%s:%d: 'levels' is for sheets (a chain has one level)", c->path, c->line);
            if (inum(c, i + 1, 1, 4, &g->levels)) return -1;
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
static int seg_line(ctx_t *c, sb_desc *d)
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
        if (inum(c, 3, 3, 65, &g.side)) return -1;
        if (((g.side - 1) & (g.side - 2)) != 0)
            return sb_fail("%s:%d: sheet side %d is not 2^n + 1 (3, 5, 9, 17, 33 or 65; seed 004 §4.2)", c->path, c->line, g.side);
        if (strcmp(c->tok[4], "corner") || strcmp(c->tok[8], "u") || strcmp(c->tok[12], "v"))
            return sb_fail("%s:%d: %s", c->path, c->line, usage[1]);
        for (k = 0; k < 3; k++)
            if (len_num(c, 5 + k, &g.p0[k]) || len_num(c, 9 + k, &g.u[k]) || len_num(c, 13 + k, &g.v[k])) return -1;
        first = 16;
    } else {
        double e[3];
        if (inum(c, 3, 2, 256, &g.side)) return -1;
        if (strcmp(c->tok[4], "from") || strcmp(c->tok[8], "to")) return sb_fail("%s:%d: %s", c->path, c->line, usage[0]);
        for (k = 0; k < 3; k++) {
            if (len_num(c, 5 + k, &g.p0[k]) || len_num(c, 9 + k, &e[k])) return -1;
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
static int attach_line(ctx_t *c, sb_desc *d)
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
        if (inum(c, 3, 0, hi, &idx)) return -1;
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
            if (len_num(c, i + 2, &within)) return -1;
            if (!(within >= 0)) return sb_fail("%s:%d: 'within' distance must be >= 0", c->path, c->line);
        } else if (c->nt != i + 1) {
            return sb_fail("%s:%d: %s: 'attach MESH NODES surface [within D]'", c->path, c->line, c->nt == i + 2 && !strcmp(c->tok[i + 1], "within") ? "missing value" : "too many values");
        }
    } else if (!strcmp(c->tok[i], "joint")) {
        kind = SB_SEGATT_JOINT;
        if (c->nt != i + 2) return sb_fail("%s:%d: %s: 'attach MESH NODES joint JOINT'", c->path, c->line, c->nt < i + 2 ? "missing value" : "too many values");
        joint = find_joint(d, c->tok[i + 1]);
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

static int parse_line(ctx_t *c, sb_desc *d, int *seen)
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
        if (nargs(c, 1)) return -1;
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
        if (nargs(c, 1) || num(c, 1, &d->unit)) return -1;
        if (!(d->unit >= 1e-9 && d->unit <= 1e9)) return sb_fail("%s:%d: unit (metres per mesh unit) must be in [1e-9, 1e9]", c->path, c->line);
        seen[1] = 1;
    } else if (!strcmp(kw, "cell")) {
        if (nargs(c, 1) || len_num(c, 1, &d->cell)) return -1;
        if (d->cell <= 0) return sb_fail("%s:%d: cell size must be positive", c->path, c->line);
        seen[2] = 1;
    } else if (!strcmp(kw, "origin")) {
        if (nargs(c, 3)) return -1;
        for (k = 0; k < 3; k++) if (len_num(c, 1 + k, &d->origin[k])) return -1;
        d->has_origin = 1;
    } else if (!strcmp(kw, "subdiv")) {
        if (nargs(c, 1) || inum(c, 1, 1, 16, &d->subdiv)) return -1;
    } else if (!strcmp(kw, "air")) {
        if (nargs(c, 1) || num(c, 1, &d->air)) return -1;
        if (d->air < 0 || d->air > 1) return sb_fail("%s:%d: air must be in [0, 1]", c->path, c->line);
    } else if (!strcmp(kw, "min_fill")) {
        if (nargs(c, 1) || num(c, 1, &d->min_fill)) return -1;
        if (d->min_fill < 0 || d->min_fill >= 1) return sb_fail("%s:%d: min_fill must be in [0, 1)", c->path, c->line);
    } else if (!strcmp(kw, "frames")) {   /* 'frames skin' | 'frames auto' */
        if (nargs(c, 1)) return -1;
        if (!strcmp(c->tok[1], "skin")) {
            if (!d->gltf) return sb_fail("%s:%d: 'frames skin' takes the frames from a glTF's skin weights: put it after a 'gltf' line", c->path, c->line);
            d->skin_frames = 1;
        } else if (!strcmp(c->tok[1], "auto")) d->skin_frames = 0;
        else return sb_fail("%s:%d: 'frames' takes 'skin' or 'auto' (got '%s')", c->path, c->line, c->tok[1]);
        d->skin_frames_line = c->line;
    } else if (!strcmp(kw, "blend")) {
        if (nargs(c, 1) || len_num(c, 1, &d->blend)) return -1;
        if (d->blend <= 0) return sb_fail("%s:%d: blend width must be positive", c->path, c->line);
    } else if (!strcmp(kw, "joint")) {
        sb_joint *j;
        if (d->gltf) return sb_fail("%s:%d: the joints come from the glTF skin ('gltf' at line %d): no 'joint' lines", c->path, c->line, d->mesh_line);
        if (nargs(c, 5)) return -1;
        if (strlen(c->tok[1]) >= SB_NAME_MAX || strlen(c->tok[2]) >= SB_NAME_MAX)
            return sb_fail("%s:%d: joint names are at most %d characters", c->path, c->line, SB_NAME_MAX - 1);
        if (find_joint(d, c->tok[1]) >= 0) return sb_fail("%s:%d: joint '%s' declared twice", c->path, c->line, c->tok[1]);
        if (!strcmp(c->tok[1], "-")) return sb_fail("%s:%d: '-' is not a joint name", c->path, c->line);
        if (d->nj >= 255) return sb_fail("%s:%d: more than 255 joints", c->path, c->line);
        GROW(d->joints, d->nj);
        j = &d->joints[d->nj];
        strcpy(j->name, c->tok[1]);
        strcpy(j->parent_name, c->tok[2]);
        for (k = 0; k < 3; k++) if (len_num(c, 3 + k, &j->pos[k])) return -1;
        j->line = c->line;
        j->parent = -1;
        j->bone_r = -1;
        d->nj++;
    } else if (!strcmp(kw, "material")) {
        sb_material *m;
        if (nargs(c, 4)) return -1;
        if (strlen(c->tok[1]) >= SB_NAME_MAX) return sb_fail("%s:%d: material name too long", c->path, c->line);
        if (find_mat(d, c->tok[1]) >= 0) return sb_fail("%s:%d: material '%s' declared twice", c->path, c->line, c->tok[1]);
        GROW(d->mats, d->nm);
        m = &d->mats[d->nm];
        strcpy(m->name, c->tok[1]);
        if (num(c, 2, &m->E) || num(c, 3, &m->nu) || num(c, 4, &m->rho)) return -1;
        if (m->E <= 0) return sb_fail("%s:%d: Young's modulus E must be positive (got %g)", c->path, c->line, m->E);
        if (m->nu >= 0.5 || m->nu <= -1.0) return sb_fail("%s:%d: Poisson ratio must be in (-1, 0.5) (got %g)", c->path, c->line, m->nu);
        if (m->rho <= 0) return sb_fail("%s:%d: density must be positive (got %g)", c->path, c->line, m->rho);
        m->line = c->line;
        d->nm++;
    } else if (!strcmp(kw, "region")) {
        sb_matrule r;
        if ((n = region(c, d, 1, 1, &r.r)) < 0) return -1;
        r.mat = find_mat(d, c->tok[1 + n]);
        if (r.mat < 0) return sb_fail("%s:%d: unknown material '%s' (declare materials before regions)", c->path, c->line, c->tok[1 + n]);
        GROW(d->mrules, d->nmr);
        d->mrules[d->nmr++] = r;
    } else if (!strcmp(kw, "frame")) {
        sb_framerule r;
        if ((n = region(c, d, 1, 3, &r.r)) < 0) return -1;
        r.j1 = find_joint(d, c->tok[1 + n]);
        r.j2 = find_joint(d, c->tok[2 + n]);
        if (r.j1 < 0 || r.j2 < 0) return sb_fail("%s:%d: unknown joint '%s'", c->path, c->line, c->tok[r.j1 < 0 ? 1 + n : 2 + n]);
        if (num(c, 3 + n, &r.w)) return -1;
        if (r.w < 0 || r.w > 1) return sb_fail("%s:%d: frame weight must be in [0, 1]", c->path, c->line);
        GROW(d->frules, d->nfr);
        d->frules[d->nfr++] = r;
    } else if (!strcmp(kw, "pin")) {
        sb_pin p;
        if ((n = region(c, d, 1, 1, &p.r)) < 0) return -1;
        p.joint = find_joint(d, c->tok[1 + n]);
        if (p.joint < 0) return sb_fail("%s:%d: unknown joint '%s'", c->path, c->line, c->tok[1 + n]);
        GROW(d->pins, d->npin);
        d->pins[d->npin++] = p;
    } else if (!strcmp(kw, "rayleigh")) {
        if (nargs(c, 2) || num(c, 1, &d->alpha) || num(c, 2, &d->beta)) return -1;
        if (d->alpha < 0 || d->beta < 0) return sb_fail("%s:%d: Rayleigh coefficients must be >= 0", c->path, c->line);
    } else if (!strcmp(kw, "timestep")) {
        if (nargs(c, 1) || num(c, 1, &d->h)) return -1;
        /* below 2^-16 s the players' Q16.16 clip clock cannot step it */
        if (d->h < 1.0 / 65536 || d->h > 1) return sb_fail("%s:%d: timestep must be in [1/65536, 1] seconds", c->path, c->line);
    } else if (!strcmp(kw, "iterations")) {
        if (nargs(c, 2) || inum(c, 1, 1, 256, &d->cg_def) || inum(c, 2, 1, 256, &d->cg_max)) return -1;
        if (d->cg_max < d->cg_def) return sb_fail("%s:%d: max iterations below the default", c->path, c->line);
    } else if (!strcmp(kw, "precond")) {
        if (nargs(c, 1)) return -1;
        if (!strcmp(c->tok[1], "ichol")) d->precond = SB_PRECOND_ICHOL;
        else if (!strcmp(c->tok[1], "jacobi")) d->precond = SB_PRECOND_JACOBI;
        else return sb_fail("%s:%d: precond '%s': one of ichol (incomplete Cholesky, the default) or jacobi (block Jacobi)", c->path, c->line, c->tok[1]);
    } else if (!strcmp(kw, "gravity")) {
        if (nargs(c, 3)) return -1;
        for (k = 0; k < 3; k++) {
            if (num(c, 1 + k, &d->g[k])) return -1;
            if (fabs(d->g[k]) > 1e4) return sb_fail("%s:%d: gravity component '%s' is beyond 1e4 m/s^2", c->path, c->line, c->tok[1 + k]);
        }
    } else if (!strcmp(kw, "twist")) {
        /* seed 000 eq. 25-26 stood in for 3-D bones; bones have volume now (DESCRIPTION.md) */
        return sb_fail("%s:%d: 'twist' is retired: bones now have volume (every lattice vertex within a bone's radius moves "
                       "rigidly with it), which stops flesh spinning around them; delete this line and, to thicken or thin "
                       "the bones, use 'bone JOINT R' or 'bone_radius R'", c->path, c->line);
    } else if (!strcmp(kw, "bone")) {
        int j;
        double r = -1;
        if (nargs(c, 2)) return -1;
        j = find_joint(d, c->tok[1]);
        if (j < 0) return sb_fail("%s:%d: unknown joint '%s' (declare joints before using them)", c->path, c->line, c->tok[1]);
        if (!strcmp(c->tok[2], "auto")) r = -1;
        else {
            if (len_num(c, 2, &r)) return -1;
            if (r < 0) return sb_fail("%s:%d: bone radius must be >= 0 (or 'auto')", c->path, c->line);
        }
        d->joints[j].bone_r = r;
        d->joints[j].bone_line = c->line;
    } else if (!strcmp(kw, "bone_radius")) {
        if (nargs(c, 1)) return -1;
        if (!strcmp(c->tok[1], "auto")) d->bone_radius = -1;
        else {
            if (len_num(c, 1, &d->bone_radius)) return -1;
            if (d->bone_radius < 0) return sb_fail("%s:%d: bone radius must be >= 0 (or 'auto')", c->path, c->line);
        }
    } else if (!strcmp(kw, "limit")) {
        sb_limitrule r;
        if ((n = region(c, d, 1, 1, &r.r)) < 0) return -1;
        if (len_num(c, 1 + n, &r.dist)) return -1;
        if (r.dist < 0) return sb_fail("%s:%d: limit distance must be >= 0 (0 = no limit)", c->path, c->line);
        GROW(d->lrules, d->nlr);
        d->lrules[d->nlr++] = r;
    } else if (!strcmp(kw, "levels")) {   /* level of detail: the lattice and its subdivision (sb_level.c) */
        double n_;
        if (c->nt == 3 && !strcmp(c->tok[2], "cut")) d->levels_cut = 1;   /* 'levels 2 cut': level 0 cut at level 1's skeleton */
        else if (nargs(c, 1)) return -1;
        if (num(c, 1, &n_)) return -1;
        if (!(n_ >= 1 && n_ <= 2 && n_ == floor(n_))) return sb_fail("%s:%d: levels: 1 (the lattice) or 2 (and the lattice subdivided once)", c->path, c->line);
        if (d->levels_cut && n_ != 2) return sb_fail("%s:%d: levels %g cut: the cut level needs 'levels 2 cut' (level 1's skeleton)", c->path, c->line, n_);
        d->levels = (int)n_;
        d->levels_line = c->line;
    } else if (!strcmp(kw, "adapt")) {   /* adaptation on level 1 (runtime/LEVELS.md §3): thresholds in level-0 cells */
        double r_, c_, m_;
        if (nargs(c, 3) || num(c, 1, &r_) || num(c, 2, &c_) || num(c, 3, &m_)) return -1;
        if (!(r_ >= 0 && c_ >= 0 && c_ <= r_))
            return sb_fail("%s:%d: adapt REFINE COARSEN MAX_ACTIVE: thresholds in level-0 cells, 0 <= COARSEN <= REFINE (got %g %g)", c->path, c->line, r_, c_);
        if (!(m_ >= 0 && m_ <= 65535 && m_ == floor(m_)))
            return sb_fail("%s:%d: adapt: MAX_ACTIVE must be a whole number in 0..65535 (at most level 1's free vertices)", c->path, c->line);
        d->adapt_refine = r_; d->adapt_coarsen = c_; d->adapt_max = (int)m_;
        d->adapt_line = c->line;
    } else if (!strcmp(kw, "details")) {   /* details on the cut level (runtime/LEVELS.md §3): thresholds in level-0 cells */
        double m_, r_, c_;
        if (nargs(c, 3) || num(c, 1, &m_) || num(c, 2, &r_) || num(c, 3, &c_)) return -1;
        if (!(m_ >= 0 && m_ <= 65535 && m_ == floor(m_)))
            return sb_fail("%s:%d: details A_MAX REFINE COARSEN: A_MAX must be a whole number in 0..65535 (at most the details)", c->path, c->line);
        if (!(r_ >= 0 && c_ >= 0 && c_ <= r_ && r_ <= 64))
            return sb_fail("%s:%d: details A_MAX REFINE COARSEN: thresholds in level-0 cells, 0 <= COARSEN <= REFINE <= 64 (got %g %g)", c->path, c->line, r_, c_);
        d->details_max = (int)m_; d->details_refine = r_; d->details_coarsen = c_;
        d->details_line = c->line;
    } else if (!strcmp(kw, "forces")) {
        double n_;
        if (nargs(c, 1) || num(c, 1, &n_)) return -1;
        if (!(n_ >= 0 && n_ <= 32 && n_ == floor(n_))) return sb_fail("%s:%d: forces: slots per step must be a whole number in 0..32", c->path, c->line);
        d->force_slots = (int)n_;
    } else if (!strcmp(kw, "constraints")) {
        double n_;
        if (nargs(c, 1) || num(c, 1, &n_)) return -1;
        if (!(n_ >= 0 && n_ <= SN_MAX_CONSTRAINTS && n_ == floor(n_)))
            return sb_fail("%s:%d: constraints: the maximum must be a whole number in 0..%u", c->path, c->line, SN_MAX_CONSTRAINTS);
        d->max_cons = (int)n_;
    } else if (!strcmp(kw, "colliders")) {
        double n_, k_;
        if (nargs(c, 2) || num(c, 1, &n_) || num(c, 2, &k_)) return -1;
        if (!(n_ >= 0 && n_ <= SN_MAX_COLLIDERS && n_ == floor(n_)))
            return sb_fail("%s:%d: colliders: the maximum must be a whole number in 0..%u", c->path, c->line, SN_MAX_COLLIDERS);
        if (!(k_ >= (n_ > 0 ? 1 : 0) && k_ <= SN_MAX_CONTACTS && k_ == floor(k_)))
            return sb_fail("%s:%d: colliders: contacts per step must be a whole number in %d..%u", c->path, c->line, n_ > 0 ? 1 : 0, SN_MAX_CONTACTS);
        d->max_cols = (int)n_;
        d->max_contacts = (int)k_;
    } else if (!strcmp(kw, "shares")) {
        sb_shares *p_;
        double sum = 0;
        if (nargs(c, 6)) return -1;
        if (strlen(c->tok[1]) >= SB_NAME_MAX) return sb_fail("%s:%d: share profile names are at most %d characters", c->path, c->line, SB_NAME_MAX - 1);
        for (k = 0; k < d->nshares; k++)
            if (!strcmp(d->shares[k].name, c->tok[1])) return sb_fail("%s:%d: share profile '%s' declared twice (first at line %d)", c->path, c->line, c->tok[1], d->shares[k].line);
        if (d->nshares >= 255) return sb_fail("%s:%d: more than 255 share profiles", c->path, c->line);
        GROW(d->shares, d->nshares);
        p_ = &d->shares[d->nshares];
        strcpy(p_->name, c->tok[1]);
        p_->line = c->line;
        for (k = 0; k < 5; k++) {
            if (num(c, 2 + k, &p_->s[k])) return -1;
            if (!(p_->s[k] >= 0 && p_->s[k] <= 1)) return sb_fail("%s:%d: share %g out of [0, 1] (shares: FINE COARSE2 COARSE4 COARSE8 RIGID)", c->path, c->line, p_->s[k]);
            sum += p_->s[k];
        }
        if (fabs(sum - 1) > 1e-6) return sb_fail("%s:%d: shares of '%s' sum to %.9g: they must sum to 1 (the force is split, not scaled)", c->path, c->line, c->tok[1], sum);
        d->nshares++;
    } else if (!strcmp(kw, "shares_region")) {
        sb_sharerule r;
        if ((n = region(c, d, 1, 1, &r.r)) < 0) return -1;
        for (r.prof = 0; r.prof < d->nshares && strcmp(d->shares[r.prof].name, c->tok[1 + n]); r.prof++) {}
        if (r.prof == d->nshares) return sb_fail("%s:%d: unknown share profile '%s' (declare it with 'shares' first)", c->path, c->line, c->tok[1 + n]);
        GROW(d->srules, d->nsr);
        d->srules[d->nsr++] = r;
    } else if (!strcmp(kw, "control")) {
        sb_control *k_;
        if (c->nt < 2) return sb_fail("%s:%d: missing value: 'control NAME [DEFAULT]', 'control NAME angle JOINT AX AY AZ' or 'control NAME twist JOINT'", c->path, c->line);
        if (strlen(c->tok[1]) >= SB_NAME_MAX) return sb_fail("%s:%d: control names are at most %d characters", c->path, c->line, SB_NAME_MAX - 1);
        if (find_ctl(d, c->tok[1]) >= 0) return sb_fail("%s:%d: control '%s' declared twice", c->path, c->line, c->tok[1]);
        if (d->nctl >= 256) return sb_fail("%s:%d: more than 256 controls", c->path, c->line);
        GROW(d->ctls, d->nctl);
        k_ = &d->ctls[d->nctl];
        strcpy(k_->name, c->tok[1]);
        k_->line = c->line;
        k_->joint = -1;
        if (c->nt >= 3 && (!strcmp(c->tok[2], "angle") || !strcmp(c->tok[2], "twist"))) {
            int tw = !strcmp(c->tok[2], "twist");
            if (c->nt != (tw ? 4 : 7))
                return sb_fail("%s:%d: %s: 'control NAME %s' takes %s", c->path, c->line, c->nt < (tw ? 4 : 7) ? "missing value" : "too many values",
                               c->tok[2], tw ? "JOINT" : "JOINT AX AY AZ");
            k_->joint = find_joint(d, c->tok[3]);
            if (k_->joint < 0) return sb_fail("%s:%d: unknown joint '%s' (declare joints before using them)", c->path, c->line, c->tok[3]);
            k_->kind = tw ? SB_CTL_TWIST : SB_CTL_ANGLE;
            if (!tw && vec3(c, 4, "angle axis", 1, k_->axis)) return -1;
        } else {
            if (c->nt > 3) return sb_fail("%s:%d: too many values: 'control NAME [DEFAULT]' (or 'control NAME angle|twist ...'), extra '%s'", c->path, c->line, c->tok[3]);
            k_->kind = SB_CTL_ABSTRACT;
            if (c->nt == 3) {
                if (num(c, 2, &k_->value0)) return sb_fail("%s:%d: '%s' is neither a default value nor 'angle'/'twist'", c->path, c->line, c->tok[2]);
                if (fabs(k_->value0) > 16384.0) return sb_fail("%s:%d: control default %g out of range (|value| <= 16384)", c->path, c->line, k_->value0);
            }
        }
        d->nctl++;
    } else if (!strcmp(kw, "rig")) {
        sb_rigdef r;
        int nt_all = c->nt, tau_at = -1, np, want, opt;
        const char *t;
        memset(&r, 0, sizeof r);
        for (k = 1; k < c->nt; k++) if (!strcmp(c->tok[k], "tau")) { tau_at = k; break; }
        if (tau_at >= 0) c->nt = tau_at;   /* parse the rig part first */
        if (c->nt < 5) { c->nt = nt_all; return sb_fail("%s:%d: missing value: 'rig NAME CONTROL TEMPLATE STRENGTH PARAMS... [tau G1 E1 ...]'", c->path, c->line); }
        if (strlen(c->tok[1]) >= SB_NAME_MAX) { c->nt = nt_all; return sb_fail("%s:%d: rig names are at most %d characters", c->path, c->line, SB_NAME_MAX - 1); }
        if (find_rig(d, c->tok[1]) >= 0) { c->nt = nt_all; return sb_fail("%s:%d: rig '%s' declared twice", c->path, c->line, c->tok[1]); }
        if (d->nrig >= 4096) { c->nt = nt_all; return sb_fail("%s:%d: more than 4096 rigs", c->path, c->line); }
        strcpy(r.name, c->tok[1]);
        r.line = c->line;
        r.control = find_ctl(d, c->tok[2]);
        if (r.control < 0) { c->nt = nt_all; return sb_fail("%s:%d: unknown control '%s' (declare controls before the rigs that use them)", c->path, c->line, c->tok[2]); }
        t = c->tok[3];
        if (!strcmp(t, "bump")) { r.tpl = SB_TPL_BUMP; want = 4; opt = 3; }
        else if (!strcmp(t, "ring")) { r.tpl = SB_TPL_RING; want = 8; opt = 0; }
        else if (!strcmp(t, "muscle")) { r.tpl = SB_TPL_MUSCLE; want = 7; opt = 1; }
        else if (!strcmp(t, "uniform")) { r.tpl = SB_TPL_UNIFORM; want = 3; opt = -1; }
        else { c->nt = nt_all; return sb_fail("%s:%d: unknown rig template '%s' (want bump, ring, muscle or uniform)", c->path, c->line, t); }
        if (num(c, 4, &r.s)) { c->nt = nt_all; return -1; }
        if (fabs(r.s) > 1e6) { c->nt = nt_all; return sb_fail("%s:%d: rig strength %g out of range (|s| <= 1e6)", c->path, c->line, r.s); }
        np = c->nt - 5;
        if (r.tpl == SB_TPL_UNIFORM) {
            if (np < 4) { c->nt = nt_all; return sb_fail("%s:%d: missing value: 'rig NAME CONTROL uniform STRENGTH DX DY DZ REGION'", c->path, c->line); }
            if (vec3(c, 5, "force direction", 1, r.p)) { c->nt = nt_all; return -1; }
            if (region(c, d, 8, 0, &r.r) < 0) { c->nt = nt_all; return -1; }
        } else {
            static const char *usage[3] = {"CX CY CZ RADIUS [DX DY DZ]", "CX CY CZ AX AY AZ RADIUS WIDTH", "AX AY AZ BX BY BZ RADIUS [SHORTEN]"};
            if (np != want && np != want + opt) {
                c->nt = nt_all;
                return sb_fail("%s:%d: %s: 'rig NAME CONTROL %s STRENGTH %s' (got %d parameter(s) after the strength)", c->path, c->line,
                               np < want ? "missing value" : "wrong number of values", t, usage[r.tpl], np);
            }
            for (k = 0; k < np; k++) if (len_num(c, 5 + k, &r.p[k])) { c->nt = nt_all; return -1; }
            if (r.tpl == SB_TPL_BUMP) {
                if (!(r.p[3] > 0)) { c->nt = nt_all; return sb_fail("%s:%d: bump radius must be positive (got %g)", c->path, c->line, r.p[3]); }
                if (np == 7) { r.has_dir = 1; if (vec3(c, 9, "bump direction", 1, r.p + 4)) { c->nt = nt_all; return -1; } }
            } else if (r.tpl == SB_TPL_RING) {
                if (vec3(c, 8, "ring axis", 1, r.p + 3)) { c->nt = nt_all; return -1; }
                if (!(r.p[6] > 0) || !(r.p[7] > 0)) { c->nt = nt_all; return sb_fail("%s:%d: ring radius and width must be positive (got %g, %g)", c->path, c->line, r.p[6], r.p[7]); }
            } else {
                double L2 = 0;
                for (k = 0; k < 3; k++) L2 += (r.p[3 + k] - r.p[k]) * (r.p[3 + k] - r.p[k]);
                if (!(L2 > 1e-24)) { c->nt = nt_all; return sb_fail("%s:%d: muscle ends coincide (a zero-length segment)", c->path, c->line); }
                if (!(r.p[6] > 0)) { c->nt = nt_all; return sb_fail("%s:%d: muscle radius must be positive (got %g)", c->path, c->line, r.p[6]); }
                if (np == 7) r.p[7] = 0.5;
                if (r.p[7] < 0) { c->nt = nt_all; return sb_fail("%s:%d: muscle SHORTEN must be >= 0 (got %g)", c->path, c->line, r.p[7]); }
            }
        }
        c->nt = nt_all;
        if (tau_at >= 0 && tau_samples(c, tau_at + 1, &r)) return -1;
        GROW(d->rigs, d->nrig);
        d->rigs[d->nrig++] = r;
    } else if (!strcmp(kw, "rig_file")) {   /* a fitted force field (sinew-rig; "Rig files") */
        sb_rigdef r;
        int nt_all = c->nt, tau_at = -1;
        const char *slash;
        size_t dl;
        memset(&r, 0, sizeof r);
        for (k = 1; k < c->nt; k++) if (!strcmp(c->tok[k], "tau")) { tau_at = k; break; }
        if (tau_at >= 0) c->nt = tau_at;
        if (c->nt != 4) {
            int bad = c->nt;
            c->nt = nt_all;
            return sb_fail("%s:%d: %s: 'rig_file NAME FILE CONTROL [tau G1 E1 ...]'", c->path, c->line, bad < 4 ? "missing value" : "too many values");
        }
        c->nt = nt_all;
        if (strlen(c->tok[1]) >= SB_NAME_MAX) return sb_fail("%s:%d: rig names are at most %d characters", c->path, c->line, SB_NAME_MAX - 1);
        if (find_rig(d, c->tok[1]) >= 0) return sb_fail("%s:%d: rig '%s' declared twice", c->path, c->line, c->tok[1]);
        if (d->nrig >= 4096) return sb_fail("%s:%d: more than 4096 rigs", c->path, c->line);
        strcpy(r.name, c->tok[1]);
        r.line = c->line;
        r.tpl = SB_TPL_FILE;
        r.s = 1;
        slash = strrchr(d->path, '/');
        dl = slash ? (size_t)(slash - d->path + 1) : 0;
        if (c->tok[2][0] == '/') dl = 0;
        if (dl + strlen(c->tok[2]) + 1 > sizeof r.file) return sb_fail("%s:%d: rig file path too long", c->path, c->line);
        memcpy(r.file, d->path, dl);
        strcpy(r.file + dl, c->tok[2]);
        r.control = find_ctl(d, c->tok[3]);
        if (r.control < 0) return sb_fail("%s:%d: unknown control '%s' (declare controls before the rigs that use them)", c->path, c->line, c->tok[3]);
        if (tau_at >= 0 && tau_samples(c, tau_at + 1, &r)) return -1;
        GROW(d->rigs, d->nrig);
        d->rigs[d->nrig++] = r;
    } else if (!strcmp(kw, "tau")) {
        int ri;
        if (c->nt < 2) return sb_fail("%s:%d: missing value: 'tau RIG GAMMA1 ETA1 [GAMMA2 ETA2 ...]'", c->path, c->line);
        ri = find_rig(d, c->tok[1]);
        if (ri < 0) return sb_fail("%s:%d: unknown rig '%s' (declare the rig before its tau)", c->path, c->line, c->tok[1]);
        if (tau_samples(c, 2, &d->rigs[ri])) return -1;
    } else if (!strcmp(kw, "chain") || !strcmp(kw, "sheet")) {
        if (seg_line(c, d)) return -1;
    } else if (!strcmp(kw, "attach")) {
        if (attach_line(c, d)) return -1;
    } else if (!strcmp(kw, "crease")) {
        sb_creasedef cd;
        memset(&cd, 0, sizeof cd);
        cd.steps = 120;
        cd.line = c->line;
        if (c->nt != 2 && c->nt != 4) return sb_fail("%s:%d: %s: 'crease JOINT:AX,AY,AZ,DEG[+JOINT:...] [steps N]'", c->path, c->line, c->nt < 2 ? "missing value" : "wrong number of values");
        if (strlen(c->tok[1]) >= sizeof cd.pose) return sb_fail("%s:%d: crease pose too long", c->path, c->line);
        strcpy(cd.pose, c->tok[1]);
        if (c->nt == 4) {
            double n_;
            if (strcmp(c->tok[2], "steps")) return sb_fail("%s:%d: unknown crease option '%s' (want steps N)", c->path, c->line, c->tok[2]);
            if (num(c, 3, &n_)) return -1;
            if (!(n_ >= 1 && n_ <= 100000 && n_ == floor(n_))) return sb_fail("%s:%d: crease steps must be a whole number in 1..100000", c->path, c->line);
            cd.steps = (int)n_;
        }
        if (d->ncrease >= 64) return sb_fail("%s:%d: more than 64 crease poses", c->path, c->line);
        GROW(d->creases, d->ncrease);
        d->creases[d->ncrease++] = cd;
    } else if (!strcmp(kw, "crease_settings")) {
        if (d->cr_line) return sb_fail("%s:%d: crease_settings given twice (first at line %d)", c->path, c->line, d->cr_line);
        if (c->nt < 3 || (c->nt - 1) % 2) return sb_fail("%s:%d: 'crease_settings [list N] [active N] [ring K] [tring K] [reach K] [depth D] [push P] [exclude R] [thin R]'", c->path, c->line);
        d->cr_line = c->line;
        for (k = 1; k + 1 < c->nt; k += 2) {
            double x;
            const char *o_ = c->tok[k];
            if (!strcmp(o_, "exclude") || !strcmp(o_, "thin")) {
                if (len_num(c, k + 1, &x)) return -1;
                if (!(x >= 0)) return sb_fail("%s:%d: crease %s must be >= 0", c->path, c->line, o_);
                if (!strcmp(o_, "thin")) d->cr_thin = x; else d->cr_exclude = x;
                continue;
            }
            if (!strcmp(o_, "depth") || !strcmp(o_, "push")) {
                if (len_num(c, k + 1, &x)) return -1;
                if (!(x > 0) && !(x == 0 && !strcmp(o_, "push"))) return sb_fail("%s:%d: crease %s must be %s", c->path, c->line, o_, !strcmp(o_, "push") ? ">= 0" : "> 0");
                if (!strcmp(o_, "depth")) d->cr_depth = x; else d->cr_push = x;
                continue;
            }
            if (num(c, k + 1, &x)) return -1;
            if (!strcmp(o_, "list")) {
                if (!(x >= 1 && x <= 256 && x == floor(x))) return sb_fail("%s:%d: crease list size must be a whole number in 1..256", c->path, c->line);
                d->cr_list = (int)x;
            } else if (!strcmp(o_, "active")) {
                if (!(x >= 1 && x <= 64 && x == floor(x))) return sb_fail("%s:%d: crease active rows must be a whole number in 1..64", c->path, c->line);
                d->cr_active = (int)x;
            } else if (!strcmp(o_, "ring")) {
                if (!(x >= 1 && x <= 3 && x == floor(x))) return sb_fail("%s:%d: crease ring must be 1, 2 or 3", c->path, c->line);
                d->cr_ring = (int)x;
            } else if (!strcmp(o_, "tring")) {
                if (!(x >= 0 && x <= 3 && x == floor(x))) return sb_fail("%s:%d: crease tring must be 0, 1, 2 or 3 (at most ring)", c->path, c->line);
                d->cr_tring = (int)x;
            } else if (!strcmp(o_, "reach")) {
                if (!(x >= 0 && x <= 16 && x == floor(x))) return sb_fail("%s:%d: crease reach must be a whole number of rings in 0..16", c->path, c->line);
                d->cr_reach = (int)x;
            } else return sb_fail("%s:%d: unknown crease setting '%s' (want list, active, ring, tring, reach, depth, push, exclude or thin)", c->path, c->line, o_);
        }
    } else if (!strcmp(kw, "rest_shape")) {
        if (nargs(c, 1)) return -1;
        if (!strcmp(c->tok[1], "modelled")) d->rest_modelled = 1;
        else if (!strcmp(c->tok[1], "sag")) d->rest_modelled = 0;
        else return sb_fail("%s:%d: unknown rest shape '%s' (want modelled or sag)", c->path, c->line, c->tok[1]);
    } else if (!strcmp(kw, "element")) {
        if (nargs(c, 1)) return -1;
        if (!strcmp(c->tok[1], "incompatible")) d->element = SB_ELEM_INCOMPATIBLE;
        else if (!strcmp(c->tok[1], "trilinear")) d->element = SB_ELEM_TRILINEAR;
        else return sb_fail("%s:%d: unknown element '%s' (want incompatible or trilinear)", c->path, c->line, c->tok[1]);
    } else {
        return sb_fail("%s:%d: unknown keyword '%s'", c->path, c->line, kw);
    }
    return 0;
}

int sb_desc_load(const char *path, sb_desc *d)
{
    FILE *f;
    char buf[4096];
    ctx_t c;
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
        jt->parent = find_joint(d, jt->parent_name);
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
