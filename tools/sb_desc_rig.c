/* sb_desc_rig.c -- the force-rig keywords: share profiles, controls, rigs, rig files, tau. */
#include "sb_desc_int.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>


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


/* tau samples: n pairs at tok[first..first+2n) */
static int tau_samples(sb_dctx *c, int first, sb_rigdef *r)
{
    int n = c->nt - first, k;
    if (n <= 0) return sb_fail("%s:%d: 'tau' needs samples: GAMMA1 ETA1 [GAMMA2 ETA2 ...]", c->path, c->line);
    if (n % 2) return sb_fail("%s:%d: tau samples come in pairs GAMMA ETA (got %d values)", c->path, c->line, n);
    if (n / 2 > SB_TAU_MAX) return sb_fail("%s:%d: rig '%s': %d tau samples, at most %d", c->path, c->line, r->name, n / 2, SB_TAU_MAX);
    for (k = 0; k < n / 2; k++) {
        if (sbd_num(c, first + 2 * k, &r->tau_g[k]) || sbd_num(c, first + 2 * k + 1, &r->tau_e[k])) return -1;
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

/* share, control and rig keywords (seed 003 §4); 1 when the line is not one of them */
int sbd_rig_line(sb_dctx *c, sb_desc *d)
{
    const char *kw = c->tok[0];
    int k, n;
    if (!strcmp(kw, "shares")) {
        sb_shares *p_;
        double sum = 0;
        if (sbd_nargs(c, 6)) return -1;
        if (strlen(c->tok[1]) >= SB_NAME_MAX) return sb_fail("%s:%d: share profile names are at most %d characters", c->path, c->line, SB_NAME_MAX - 1);
        for (k = 0; k < d->nshares; k++)
            if (!strcmp(d->shares[k].name, c->tok[1])) return sb_fail("%s:%d: share profile '%s' declared twice (first at line %d)", c->path, c->line, c->tok[1], d->shares[k].line);
        if (d->nshares >= 255) return sb_fail("%s:%d: more than 255 share profiles", c->path, c->line);
        GROW(d->shares, d->nshares);
        p_ = &d->shares[d->nshares];
        strcpy(p_->name, c->tok[1]);
        p_->line = c->line;
        for (k = 0; k < 5; k++) {
            if (sbd_num(c, 2 + k, &p_->s[k])) return -1;
            if (!(p_->s[k] >= 0 && p_->s[k] <= 1)) return sb_fail("%s:%d: share %g out of [0, 1] (shares: FINE COARSE2 COARSE4 COARSE8 RIGID)", c->path, c->line, p_->s[k]);
            sum += p_->s[k];
        }
        if (fabs(sum - 1) > 1e-6) return sb_fail("%s:%d: shares of '%s' sum to %.9g: they must sum to 1 (the force is split, not scaled)", c->path, c->line, c->tok[1], sum);
        d->nshares++;
    } else if (!strcmp(kw, "shares_region")) {
        sb_sharerule r;
        if ((n = sbd_region(c, d, 1, 1, &r.r)) < 0) return -1;
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
            k_->joint = sbd_find_joint(d, c->tok[3]);
            if (k_->joint < 0) return sb_fail("%s:%d: unknown joint '%s' (declare joints before using them)", c->path, c->line, c->tok[3]);
            k_->kind = tw ? SB_CTL_TWIST : SB_CTL_ANGLE;
            if (!tw && sbd_vec3(c, 4, "angle axis", 1, k_->axis)) return -1;
        } else {
            if (c->nt > 3) return sb_fail("%s:%d: too many values: 'control NAME [DEFAULT]' (or 'control NAME angle|twist ...'), extra '%s'", c->path, c->line, c->tok[3]);
            k_->kind = SB_CTL_ABSTRACT;
            if (c->nt == 3) {
                if (sbd_num(c, 2, &k_->value0)) return sb_fail("%s:%d: '%s' is neither a default value nor 'angle'/'twist'", c->path, c->line, c->tok[2]);
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
        if (sbd_num(c, 4, &r.s)) { c->nt = nt_all; return -1; }
        if (fabs(r.s) > 1e6) { c->nt = nt_all; return sb_fail("%s:%d: rig strength %g out of range (|s| <= 1e6)", c->path, c->line, r.s); }
        np = c->nt - 5;
        if (r.tpl == SB_TPL_UNIFORM) {
            if (np < 4) { c->nt = nt_all; return sb_fail("%s:%d: missing value: 'rig NAME CONTROL uniform STRENGTH DX DY DZ REGION'", c->path, c->line); }
            if (sbd_vec3(c, 5, "force direction", 1, r.p)) { c->nt = nt_all; return -1; }
            if (sbd_region(c, d, 8, 0, &r.r) < 0) { c->nt = nt_all; return -1; }
        } else {
            static const char *usage[3] = {"CX CY CZ RADIUS [DX DY DZ]", "CX CY CZ AX AY AZ RADIUS WIDTH", "AX AY AZ BX BY BZ RADIUS [SHORTEN]"};
            if (np != want && np != want + opt) {
                c->nt = nt_all;
                return sb_fail("%s:%d: %s: 'rig NAME CONTROL %s STRENGTH %s' (got %d parameter(s) after the strength)", c->path, c->line,
                               np < want ? "missing value" : "wrong number of values", t, usage[r.tpl], np);
            }
            for (k = 0; k < np; k++) if (sbd_len(c, 5 + k, &r.p[k])) { c->nt = nt_all; return -1; }
            if (r.tpl == SB_TPL_BUMP) {
                if (!(r.p[3] > 0)) { c->nt = nt_all; return sb_fail("%s:%d: bump radius must be positive (got %g)", c->path, c->line, r.p[3]); }
                if (np == 7) { r.has_dir = 1; if (sbd_vec3(c, 9, "bump direction", 1, r.p + 4)) { c->nt = nt_all; return -1; } }
            } else if (r.tpl == SB_TPL_RING) {
                if (sbd_vec3(c, 8, "ring axis", 1, r.p + 3)) { c->nt = nt_all; return -1; }
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
    } else {
        return 1;
    }
    return 0;
}
