/* sb_desc_sim.c -- the simulation keywords: damping, timestep, solver, gravity, levels, budgets, crease, element. */
#include "sb_desc_int.h"
#include "../runtime/src/sn_format.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* solver, level-of-detail, runtime budget and crease keywords; 1 when the line is not one of them */
int sbd_sim_line(sb_dctx *c, sb_desc *d)
{
    const char *kw = c->tok[0];
    int k;
    if (!strcmp(kw, "rayleigh")) {
        if (sbd_nargs(c, 2) || sbd_num(c, 1, &d->alpha) || sbd_num(c, 2, &d->beta)) return -1;
        if (d->alpha < 0 || d->beta < 0) return sb_fail("%s:%d: Rayleigh coefficients must be >= 0", c->path, c->line);
    } else if (!strcmp(kw, "timestep")) {
        if (sbd_nargs(c, 1) || sbd_num(c, 1, &d->h)) return -1;
        /* below 2^-16 s the players' Q16.16 clip clock cannot step it */
        if (d->h < 1.0 / 65536 || d->h > 1) return sb_fail("%s:%d: timestep must be in [1/65536, 1] seconds", c->path, c->line);
    } else if (!strcmp(kw, "iterations")) {
        if (sbd_nargs(c, 2) || sbd_inum(c, 1, 1, 256, &d->cg_def) || sbd_inum(c, 2, 1, 256, &d->cg_max)) return -1;
        if (d->cg_max < d->cg_def) return sb_fail("%s:%d: max iterations below the default", c->path, c->line);
    } else if (!strcmp(kw, "precond")) {
        if (sbd_nargs(c, 1)) return -1;
        if (!strcmp(c->tok[1], "ichol")) d->precond = SB_PRECOND_ICHOL;
        else if (!strcmp(c->tok[1], "jacobi")) d->precond = SB_PRECOND_JACOBI;
        else return sb_fail("%s:%d: precond '%s': one of ichol (incomplete Cholesky, the default) or jacobi (block Jacobi)", c->path, c->line, c->tok[1]);
    } else if (!strcmp(kw, "gravity")) {
        if (sbd_nargs(c, 3)) return -1;
        for (k = 0; k < 3; k++) {
            if (sbd_num(c, 1 + k, &d->g[k])) return -1;
            if (fabs(d->g[k]) > 1e4) return sb_fail("%s:%d: gravity component '%s' is beyond 1e4 m/s^2", c->path, c->line, c->tok[1 + k]);
        }
    } else if (!strcmp(kw, "levels")) {   /* level of detail: the lattice and its subdivision (sb_level.c) */
        double n_;
        if (c->nt == 3 && !strcmp(c->tok[2], "cut")) d->levels_cut = 1;   /* 'levels 2 cut': level 0 cut at level 1's skeleton */
        else if (sbd_nargs(c, 1)) return -1;
        if (sbd_num(c, 1, &n_)) return -1;
        if (!(n_ >= 1 && n_ <= 2 && n_ == floor(n_))) return sb_fail("%s:%d: levels: 1 (the lattice) or 2 (and the lattice subdivided once)", c->path, c->line);
        if (d->levels_cut && n_ != 2) return sb_fail("%s:%d: levels %g cut: the cut level needs 'levels 2 cut' (level 1's skeleton)", c->path, c->line, n_);
        d->levels = (int)n_;
        d->levels_line = c->line;
    } else if (!strcmp(kw, "adapt")) {   /* adaptation on level 1 (runtime/LEVELS.md §3): thresholds in level-0 cells */
        double r_, c_, m_;
        if (sbd_nargs(c, 3) || sbd_num(c, 1, &r_) || sbd_num(c, 2, &c_) || sbd_num(c, 3, &m_)) return -1;
        if (!(r_ >= 0 && c_ >= 0 && c_ <= r_))
            return sb_fail("%s:%d: adapt REFINE COARSEN MAX_ACTIVE: thresholds in level-0 cells, 0 <= COARSEN <= REFINE (got %g %g)", c->path, c->line, r_, c_);
        if (!(m_ >= 0 && m_ <= 65535 && m_ == floor(m_)))
            return sb_fail("%s:%d: adapt: MAX_ACTIVE must be a whole number in 0..65535 (at most level 1's free vertices)", c->path, c->line);
        d->adapt_refine = r_; d->adapt_coarsen = c_; d->adapt_max = (int)m_;
        d->adapt_line = c->line;
    } else if (!strcmp(kw, "details")) {   /* details on the cut level (runtime/LEVELS.md §3): thresholds in level-0 cells */
        double m_, r_, c_;
        if (sbd_nargs(c, 3) || sbd_num(c, 1, &m_) || sbd_num(c, 2, &r_) || sbd_num(c, 3, &c_)) return -1;
        if (!(m_ >= 0 && m_ <= 65535 && m_ == floor(m_)))
            return sb_fail("%s:%d: details A_MAX REFINE COARSEN: A_MAX must be a whole number in 0..65535 (at most the details)", c->path, c->line);
        if (!(r_ >= 0 && c_ >= 0 && c_ <= r_ && r_ <= 64))
            return sb_fail("%s:%d: details A_MAX REFINE COARSEN: thresholds in level-0 cells, 0 <= COARSEN <= REFINE <= 64 (got %g %g)", c->path, c->line, r_, c_);
        d->details_max = (int)m_; d->details_refine = r_; d->details_coarsen = c_;
        d->details_line = c->line;
    } else if (!strcmp(kw, "forces")) {
        double n_;
        if (sbd_nargs(c, 1) || sbd_num(c, 1, &n_)) return -1;
        if (!(n_ >= 0 && n_ <= 32 && n_ == floor(n_))) return sb_fail("%s:%d: forces: slots per step must be a whole number in 0..32", c->path, c->line);
        d->force_slots = (int)n_;
    } else if (!strcmp(kw, "constraints")) {
        double n_;
        if (sbd_nargs(c, 1) || sbd_num(c, 1, &n_)) return -1;
        if (!(n_ >= 0 && n_ <= SN_MAX_CONSTRAINTS && n_ == floor(n_)))
            return sb_fail("%s:%d: constraints: the maximum must be a whole number in 0..%u", c->path, c->line, SN_MAX_CONSTRAINTS);
        d->max_cons = (int)n_;
    } else if (!strcmp(kw, "colliders")) {
        double n_, k_;
        if (sbd_nargs(c, 2) || sbd_num(c, 1, &n_) || sbd_num(c, 2, &k_)) return -1;
        if (!(n_ >= 0 && n_ <= SN_MAX_COLLIDERS && n_ == floor(n_)))
            return sb_fail("%s:%d: colliders: the maximum must be a whole number in 0..%u", c->path, c->line, SN_MAX_COLLIDERS);
        if (!(k_ >= (n_ > 0 ? 1 : 0) && k_ <= SN_MAX_CONTACTS && k_ == floor(k_)))
            return sb_fail("%s:%d: colliders: contacts per step must be a whole number in %d..%u", c->path, c->line, n_ > 0 ? 1 : 0, SN_MAX_CONTACTS);
        d->max_cols = (int)n_;
        d->max_contacts = (int)k_;
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
            if (sbd_num(c, 3, &n_)) return -1;
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
                if (sbd_len(c, k + 1, &x)) return -1;
                if (!(x >= 0)) return sb_fail("%s:%d: crease %s must be >= 0", c->path, c->line, o_);
                if (!strcmp(o_, "thin")) d->cr_thin = x; else d->cr_exclude = x;
                continue;
            }
            if (!strcmp(o_, "depth") || !strcmp(o_, "push")) {
                if (sbd_len(c, k + 1, &x)) return -1;
                if (!(x > 0) && !(x == 0 && !strcmp(o_, "push"))) return sb_fail("%s:%d: crease %s must be %s", c->path, c->line, o_, !strcmp(o_, "push") ? ">= 0" : "> 0");
                if (!strcmp(o_, "depth")) d->cr_depth = x; else d->cr_push = x;
                continue;
            }
            if (sbd_num(c, k + 1, &x)) return -1;
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
        if (sbd_nargs(c, 1)) return -1;
        if (!strcmp(c->tok[1], "modelled")) d->rest_modelled = 1;
        else if (!strcmp(c->tok[1], "sag")) d->rest_modelled = 0;
        else return sb_fail("%s:%d: unknown rest shape '%s' (want modelled or sag)", c->path, c->line, c->tok[1]);
    } else if (!strcmp(kw, "element")) {
        if (sbd_nargs(c, 1)) return -1;
        if (!strcmp(c->tok[1], "incompatible")) d->element = SB_ELEM_INCOMPATIBLE;
        else if (!strcmp(c->tok[1], "trilinear")) d->element = SB_ELEM_TRILINEAR;
        else return sb_fail("%s:%d: unknown element '%s' (want incompatible or trilinear)", c->path, c->line, c->tok[1]);
    } else {
        return 1;
    }
    return 0;
}
