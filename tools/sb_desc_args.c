/* sb_desc_args.c -- a description line's values: numbers, lengths, vectors, regions, joint names. */
#include "sb_desc_int.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

int sbd_num(sb_dctx *c, int i, double *out)
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
int sbd_len(sb_dctx *c, int i, double *out)
{
    if (sbd_num(c, i, out)) return -1;
    if (fabs(*out) > SB_MAX_LEN) return sb_fail("%s:%d: '%s' is beyond %g mesh units", c->path, c->line, c->tok[i], SB_MAX_LEN);
    return 0;
}

int sbd_inum(sb_dctx *c, int i, int lo, int hi, int *out)
{
    double v = 0;
    if (sbd_num(c, i, &v)) return -1;
    if (v != floor(v) || v < lo || v > hi) return sb_fail("%s:%d: '%s' must be an integer in %d..%d", c->path, c->line, c->tok[i], lo, hi);
    *out = (int)v;
    return 0;
}

int sbd_nargs(sb_dctx *c, int n)
{
    if (c->nt - 1 < n) return sb_fail("%s:%d: missing value: '%s' takes %d value(s), got %d", c->path, c->line, c->tok[0], n, c->nt - 1);
    if (c->nt - 1 > n) return sb_fail("%s:%d: '%s' takes %d value(s), got %d (extra '%s')", c->path, c->line, c->tok[0], n, c->nt - 1, c->tok[n + 1]);
    return 0;
}

int sbd_find_joint(const sb_desc *d, const char *name)
{
    int i;
    for (i = 0; i < d->nj; i++) if (!strcmp(d->joints[i].name, name)) return i;
    return -1;
}

/* three numbers at tok[i..i+2] forming a non-zero vector, normalized if unit */
int sbd_vec3(sb_dctx *c, int i, const char *what, int unit, double v[3])
{
    double n;
    int k;
    for (k = 0; k < 3; k++) if (sbd_num(c, i + k, &v[k])) return -1;
    n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (unit) {
        if (!(n > 1e-12)) return sb_fail("%s:%d: %s (%s %s %s) is the zero vector", c->path, c->line, what, c->tok[i], c->tok[i + 1], c->tok[i + 2]);
        for (k = 0; k < 3; k++) v[k] /= n;
    }
    return 0;
}

/* region at tok[first]: all | box x0 y0 z0 x1 y1 z1 | sphere cx cy cz r | bone JOINT.
 * Returns the number of tokens used, -1 on error. */
int sbd_region(sb_dctx *c, const sb_desc *d, int first, int tail, sb_region *r)
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
        for (k = 0; k < n - 1; k++) if (sbd_len(c, first + 1 + k, &r->a[k])) return -1;
    if (r->kind == SB_RG_BOX)
        for (k = 0; k < 3; k++) if (r->a[k] > r->a[k + 3]) return sb_fail("%s:%d: box lower corner above upper corner", c->path, c->line);
    if (r->kind == SB_RG_SPHERE && r->a[3] <= 0) return sb_fail("%s:%d: sphere radius must be positive", c->path, c->line);
    if (r->kind == SB_RG_BONE) {
        r->bone = sbd_find_joint(d, c->tok[first + 1]);
        if (r->bone < 0) return sb_fail("%s:%d: unknown joint '%s' (declare joints before using them)", c->path, c->line, c->tok[first + 1]);
        if (!strcmp(d->joints[r->bone].parent_name, "-")) /* parents resolve after the last line */ return sb_fail("%s:%d: '%s' is the root: a bone is named by its child joint", c->path, c->line, c->tok[first + 1]);
    }
    return n;
}
