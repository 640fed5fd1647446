/* sb_blob_rigs.c -- the rig sections of a blob: forces, tau samples, controls (format 3.0, sn_format.h). */
#include "sb_blob_int.h"
#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Rig sections (format 3.0, sn_format.h). Forces in the units of the right-hand
 * side b (NUMERICS.md): Q^ = h^2 Q / (m0 Um), Q in newtons, Um = U * unit metres,
 * exactly as gravity is baked (m^ g^ = (m/m0) h^2 g / Um = h^2 (m g) / (m0 Um)).
 * The eta samples are normalized to max |eta| = 1 and the scale folded into Q^.
 * Fixed: per rig frac so that the largest |Q^ component| * 2^frac is in
 * [2^29, 2^30) (error below SN_RIG_FRAC_MIN: an absurd force; clamped to
 * SN_RIG_FRAC_MAX with a warning when tiny); gamma Q16.16, eta Q30, axis Q30,
 * abstract default Q16.16. Float32: |Q^| <= SN_RIG_FLOAT_MAX. */
int sb_blob_write_rigs(const sb_model *o, wr_t *w, const uint32_t *off, double Um, double m0, sb_blob *b)
{
    int a, k, i;
    uint32_t fs = 0, fe = 0;
    double sc = o->h * o->h / (m0 * Um);
    int rs = w->rs;
    b->rig_frac = sb_alloc(sizeof(int) * (size_t)(o->nrig ? o->nrig : 1));
    for (a = 0; a < o->nctl; a++) {
        const sb_control *c = &o->ctl[a];
        size_t at = off[SN_SEC_CONTROLS] + (size_t)a * (size_t)SN_ELEM_CONTROLS(rs);
        memcpy(w->p + at, c->name, strlen(c->name));
        put_u8(w, at + 32, c->kind == SB_CTL_ABSTRACT ? SN_CTL_ABSTRACT : SN_CTL_ANGLE);
        put_u8(w, at + 33, c->kind == SB_CTL_ABSTRACT ? 0u : (unsigned)c->joint);
        for (k = 0; k < 3; k++) put_real(w, at + 40 + (size_t)(k * rs), c->kind == SB_CTL_ABSTRACT ? 0.0 : c->axis[k], SN_Q_ROT);
        put_real(w, at + 40 + (size_t)(3 * rs), c->kind == SB_CTL_ABSTRACT ? c->value0 : 0.0, 16);
    }
    for (a = 0; a < o->nrig; a++) {
        const sb_rig *r = &o->rig[a];
        size_t at = off[SN_SEC_RIGS] + (size_t)a * SN_ELEM_RIGS;
        double emax = 0, maxc = 0, fold;
        int frac = 0;
        for (k = 0; k < r->def.ntau; k++) emax = fmax(emax, fabs(r->def.tau_e[k]));
        if (!(emax > 0)) return sb_fail("rig '%s': every tau eta is 0", r->def.name);
        fold = sc * emax;
        for (i = 0; i < 3 * r->n; i++) maxc = fmax(maxc, fabs(fold * r->Q[i]));
        if (w->flavour == SB_FIXED) {
            int e;
            frexp(maxc, &e);   /* maxc in [2^(e-1), 2^e) */
            frac = 30 - e;
            if (frac < SN_RIG_FRAC_MIN)
                return sb_fail("rig '%s' (line %d): force out of range (largest generalized force %g N = %g internal units, needs < 2^%d): "
                               "lower its strength", r->def.name, r->def.line, r->qmax * emax, maxc, 30 - SN_RIG_FRAC_MIN);
            if (frac > SN_RIG_FRAC_MAX) {
                fprintf(stderr, "sinew-bake: warning: rig '%s' (line %d) is tiny (largest generalized force %g N): its forces are stored with %d "
                                "fractional bits, the largest as %.3g (%.1f significant bits instead of 30)\n", r->def.name, r->def.line, r->qmax * emax,
                        SN_RIG_FRAC_MAX, ldexp(maxc, SN_RIG_FRAC_MAX), log2(ldexp(maxc, SN_RIG_FRAC_MAX)));
                frac = SN_RIG_FRAC_MAX;
            }
        } else if (w->flavour == SB_FLOAT && !(maxc <= SN_RIG_FLOAT_MAX)) {
            return sb_fail("rig '%s' (line %d): force out of range for float32 (largest %g internal units, at most %g): lower its strength",
                           r->def.name, r->def.line, maxc, (double)SN_RIG_FLOAT_MAX);
        }
        b->rig_frac[a] = frac;
        put_u16(w, at, (unsigned)r->def.control);
        put_u8(w, at + 2, (unsigned)r->def.ntau);
        put_u8(w, at + 3, (unsigned)(frac & 255));
        put_u32(w, at + 4, fs);
        put_u32(w, at + 8, fe);
        put_u32(w, at + 12, (uint32_t)r->n);
        for (k = 0; k < r->def.ntau; k++) {
            size_t sat = off[SN_SEC_RIG_SAMPLES] + (size_t)(fs + (uint32_t)k) * (size_t)SN_ELEM_RIG_SAMPLES(rs);
            double g = r->def.tau_g[k];
            if (k > 0) {   /* strictly increasing as stored */
                double g0 = r->def.tau_g[k - 1];
                int same = w->flavour == SB_FIXED ? rnd(ldexp(g, 16)) <= rnd(ldexp(g0, 16)) : w->flavour == SB_FLOAT ? !((float)g > (float)g0) : 0;
                if (same) return sb_fail("rig '%s' (line %d): tau gammas %.9g and %.9g are equal in the blob's precision", r->def.name, r->def.line, g0, g);
            }
            put_real(w, sat, g, 16);
            put_real(w, sat + (size_t)rs, r->def.tau_e[k] / emax, 30);
        }
        for (i = 0; i < r->n; i++) {
            put_u16(w, off[SN_SEC_RIG_VERTS] + 2 * (size_t)(fe + (uint32_t)i), (unsigned)r->vert[i]);
            for (k = 0; k < 3; k++)
                put_real(w, off[SN_SEC_RIG_FORCES] + (size_t)(3 * (fe + (uint32_t)i) + (uint32_t)k) * (size_t)rs, fold * r->Q[3 * i + k], frac);
        }
        fs += (uint32_t)r->def.ntau;
        fe += (uint32_t)r->n;
    }
    return 0;
}
