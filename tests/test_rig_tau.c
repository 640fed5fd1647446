/* test_rig_tau.c -- the runtime's tau map (runtime/src/sn_rig.c, seed 003
 * after eq. 12) against the reference's snref_tau in double, white box: the
 * runtime source is included so its static tau() can be called on sample
 * tables built here (the library's sn_rig.o is then not linked: this
 * translation unit defines all its symbols). Built fixed and float.
 *
 * Random tables of 1..16 samples (gamma strictly increasing, |eta| <= 1,
 * stored exactly as the blob stores them: Q16.16 / Q30 in fixed, float32 in
 * float), evaluated at every sample, between samples and beyond both ends:
 *  - at a sample and beyond the ends (clamped): fixed exactly the stored eta
 *    (t is exactly 0 or 1 there, the sum telescopes in integers); float within
 *    16 float ulps of 1 (the telescoping sum rounds once per term, <= 15 terms);
 *  - between samples: fixed within 1/2 LSB of Q30 (the runtime rounds
 *    d (eta_k+1 - eta_k) / D once, to nearest; every other term of the sum
 *    is exact: 0 or a whole eta step), which meets the brief's 1 LSB. Float
 *    within 16 ulps of 1 (d / D and the sum).
 */
#include "sn_test.h"
#include "../runtime/src/sn_rig.c"
#include "snref.h"

#include <stdlib.h>
#include <string.h>

#if defined(SN_FLOAT)
#define FLAV "float"
static const double TOL_AT = 16.0 / 16777216.0, TOL_MID = 16.0 / 16777216.0;
static void put_real(unsigned char *p, double v, int q) { float f = (float)v; (void)q; memcpy(p, &f, 4); }
static double get_real(const unsigned char *p, int q) { float f; (void)q; memcpy(&f, p, 4); return f; }
static sn_real to_g(double g) { return (float)g; }
static double from_tau(sn_q t) { return (double)t; }
#else
#define FLAV "fixed"
static const double TOL_AT = 0.0, TOL_MID = 1.0 / 1073741824.0;
static void put_real(unsigned char *p, double v, int q) {
    int32_t x = (int32_t)lround(ldexp(v, q));
    uint32_t u = (uint32_t)x;
    p[0] = (unsigned char)u; p[1] = (unsigned char)(u >> 8); p[2] = (unsigned char)(u >> 16); p[3] = (unsigned char)(u >> 24);
}
static double get_real(const unsigned char *p, int q) {
    uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
    return ldexp((double)(int32_t)u, -q);
}
static sn_real to_g(double g) { return (sn_real)lround(ldexp(g, 16)); }
static double from_tau(sn_q t) { return ldexp((double)t, -30); }
#endif

static double urand(unsigned long long *st) {
    *st = *st * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*st >> 11) / 9007199254740992.0;
}

int main(void) {
    unsigned long long st = 0x51CE5EEDULL ^ (unsigned long long)T_SEED();
    unsigned trial, k;
    double worst_at = 0, worst_mid = 0, worst_end = 0, worst_excess = -1;
    unsigned char smp[16 * SMP_ELEM];
    double G[16], E[16];
    unsigned fs = 0, ns;
    snref_model m;
    printf("tau: %s runtime vs double\n", FLAV);
    memset(&m, 0, sizeof m);
    m.rgamma = G; m.reta = E; m.rfs = &fs; m.rns = &ns;
    for (trial = 0; trial < 4000; trial++) {
        double g = -100 + 50 * urand(&st), span = trial & 1 ? 200 : 2;
        ns = 1 + (unsigned)(urand(&st) * 16);
        if (ns > 16) ns = 16;
        for (k = 0; k < ns; k++) {
            put_real(smp + k * SMP_ELEM, g, 16);
            put_real(smp + k * SMP_ELEM + SN_REAL_BYTES, trial % 7 == 0 ? (k & 1 ? 1.0 : -1.0) : 2 * urand(&st) - 1, 30);
            G[k] = get_real(smp + k * SMP_ELEM, 16);                 /* the stored values, as the reference reads them */
            E[k] = get_real(smp + k * SMP_ELEM + SN_REAL_BYTES, 30);
            g += (0.001 + urand(&st)) * span / ns;
        }
        for (k = 1; k < ns; k++) if (!(G[k] > G[k - 1])) break;
        if (k < ns) continue;   /* rounding merged two samples: not a valid table */
        for (k = 0; k < ns; k++) {   /* at the samples */
            double e = fabs(from_tau(tau(smp, ns, to_g(G[k]))) - snref_tau(&m, 0, G[k]));
            if (e > worst_at) worst_at = e;
            if (k + 1 < ns) {        /* between: random points of the interval, on the Q16.16 grid in fixed */
                unsigned j;
                for (j = 0; j < 4; j++) {
                    sn_real gg = to_g(G[k] + urand(&st) * (G[k + 1] - G[k]));
#if defined(SN_FLOAT)
                    double gd = (double)gg;
#else
                    double gd = ldexp((double)gg, -16);
#endif
                    e = fabs(from_tau(tau(smp, ns, gg)) - snref_tau(&m, 0, gd));
                    if (e > worst_mid) worst_mid = e;
                    if (e - (fabs(E[k + 1] - E[k]) + 0.5) * TOL_MID > worst_excess) worst_excess = e - (fabs(E[k + 1] - E[k]) + 0.5) * TOL_MID;
                }
            }
        }
        {   /* beyond the ends: clamped */
            double e1 = fabs(from_tau(tau(smp, ns, to_g(G[0] - 1 - 100 * urand(&st)))) - E[0]);
            double e2 = fabs(from_tau(tau(smp, ns, to_g(G[ns - 1] + 1 + 100 * urand(&st)))) - E[ns - 1]);
            if (e1 > worst_end) worst_end = e1;
            if (e2 > worst_end) worst_end = e2;
        }
    }
    T_NEAR(worst_at, 0, TOL_AT, "tau at the samples: fixed exact (the sum telescopes in integers), float <= 16 ulps of 1");
    T_NEAR(worst_end, 0, TOL_AT, "tau clamped beyond the ends: fixed exact, float <= 16 ulps of 1");
#if defined(SN_FLOAT)
    T_NEAR(worst_mid, 0, TOL_MID, "tau between samples: float <= 16 ulps of 1");
#else
    (void)worst_excess;
    T_CHECK(worst_mid <= 0.5 * TOL_MID * (1 + 1e-9), "tau between samples within 1/2 LSB of Q30 (one rounding): %.3f LSB",
            worst_mid * 1073741824.0);
#endif
    T_FIGURE("tau, %s runtime vs double over 4000 random tables (1..16 samples): at samples %.3g, beyond the ends %.3g, between %.3g (%.2f LSB of Q30)",
             FLAV, worst_at, worst_end, worst_mid, worst_mid * 1073741824.0);
    return T_END();
}
