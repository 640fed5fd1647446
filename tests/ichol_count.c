/* ichol_count.c -- the iteration count of an ICHOL blob by the whole-clip
 * criterion of runtime/SOLVER_STUDY.md §1 (issue 15 item 3): the double
 * reference steps the clips with exact solves, with block Jacobi at the
 * count N it is compared with (the Jacobi blob), and with the ICHOL blob's
 * IC(0) (its int16 factor as stored) at 1..16 iterations, all in lockstep;
 * error = max over the clips of the max surface distance from the exact run,
 * relative to the max elastic displacement. The count is the smallest k whose
 * error is at most block Jacobi's at N, plus one iteration of margin.
 * Not a test: a measurement (make ichol-counts), its numbers go into the
 * examples' descriptions (tools/DESCRIPTION.md "Preconditioner").
 *
 * Usage: ichol_count JACOBI_BLOB ICHOL_BLOB N CLIP [CLIP...]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sinew.h"
#include "sn_clip.h"
#include "snref.h"
#include "reference/phys_util.h"

#define KMAX 16

/* Step every state through the clips in lockstep (reset at each clip), as
 * tests/precond_study.c's drive_clips: err[j] = max surface distance of state
 * j from state 0; err[ns] = the max elastic displacement of state 0. */
static int drive(const pu_rt *rt, const snref_model *m, const char **clips, unsigned nclip, snref_state **st, unsigned ns, double *err) {
    unsigned c, k, j, i, q;
    double *s0 = malloc(sizeof(double) * 3 * m->nS), *sj = malloc(sizeof(double) * 3 * m->nS);
    double *skin = malloc(sizeof(double) * 3 * m->nV), *ss = malloc(sizeof(double) * 3 * m->nS);
    for (j = 0; j <= ns; j++) err[j] = 0;
    for (c = 0; c < nclip; c++) {
        char *text; size_t n; char e[SN_CLIP_ERR_LEN];
        sn_clip *clip = malloc(sizeof *clip);
        sn_quat *local = malloc(sizeof(sn_quat) * rt->info.joints);
        sn_xform *xf = malloc(sizeof(sn_xform) * rt->info.joints);
        snref_xform *rx = malloc(sizeof(snref_xform) * rt->info.joints);
        unsigned steps;
        text = pu_read(clips[c], &n);
        if (!text || sn_clip_parse(clip, text, n, e, sizeof e) || sn_clip_bind(clip, rt->blob, e, sizeof e)) {
            fprintf(stderr, "%s: %s\n", clips[c], text ? e : "cannot read"); return 1;
        }
        for (j = 0; j < ns; j++) snref_reset(st[j]);
        steps = (unsigned)ceil((clip->duration / 65536.0) / (m->h > 0 ? m->h : 1.0 / 60));
        for (k = 0; k < steps; k++) {
            unsigned ch;
            sn_clip_pose(clip, rt->blob, k, local, xf);
            pu_pose_to_ref(xf, rt->info.joints, rx);
            for (j = 0; j < ns; j++) {
                snref_set_pose(st[j], rx);
                for (ch = 0; ch < clip->n_channels; ch++)
                    if (clip->chan[ch].kind == SN_CLIP_CONTROL && clip->chan[ch].joint >= 0) {
                        int kc = snref_find_control(m, clip->chan[ch].name);
                        if (kc >= 0) snref_set_control(st[j], (unsigned)kc, sn_clip_control_at(clip, ch, sn_clip_time(clip, sn_clip_timestep_q16(rt->blob), k)) / 65536.0);
                    }
                snref_step(st[j]);
            }
            snref_get_surface(st[0], s0);
            for (j = 1; j < ns; j++) {
                double d;
                snref_get_surface(st[j], sj);
                d = pu_maxdist(s0, sj, m->nS);
                if (d > err[j]) err[j] = d;
            }
            for (i = 0; i < m->nV; i++) {
                const double *R = st[0]->R + 9 * i, *x = m->rest + 3 * i;
                for (q = 0; q < 3; q++) skin[3 * i + q] = (R[3 * q] * x[0] + R[3 * q + 1] * x[1] + R[3 * q + 2] * x[2] + st[0]->c[3 * i + q]) * m->unit;
            }
            snref_surface_from_lattice(m, skin, ss);
            { double d = pu_maxdist(ss, s0, m->nS); if (d > err[ns]) err[ns] = d; }
        }
        free(text); free(clip); free(local); free(xf); free(rx);
    }
    free(s0); free(sj); free(skin); free(ss);
    return 0;
}

int main(int argc, char **argv) {
    pu_rt rt;
    snref_model mj, mi;
    snref_state sj0, ex, bj, ic[KMAX], *st[KMAX + 2];
    double er[KMAX + 3];
    unsigned n, j, ns = 0;
    if (argc < 5) { fprintf(stderr, "usage: ichol_count JACOBI_BLOB ICHOL_BLOB N CLIP...\n"); return 2; }
    n = (unsigned)atoi(argv[3]);
    if (pu_rt_open(&rt, argv[1]) || pu_ref_open(&mj, &sj0, argv[1]) || pu_ref_open(&mi, &ic[0], argv[2])) return 1;
    if (mj.nIC || !mi.nIC) { fprintf(stderr, "%s must be a block-Jacobi blob and %s an ICHOL blob\n", argv[1], argv[2]); return 1; }
    snref_init(&ex, &mj); ex.exact = 1; st[ns++] = &ex;
    snref_init(&bj, &mj); bj.iters = n; st[ns++] = &bj;
    for (j = 0; j < KMAX; j++) { if (j) snref_init(&ic[j], &mi); ic[j].iters = j + 1; st[ns++] = &ic[j]; }
    if (drive(&rt, &mj, (const char **)argv + 4, (unsigned)argc - 4, st, ns, er)) return 1;
    printf("%s: whole clips, max surface error against exact solves / max elastic displacement (%.4g mesh units)\n", argv[2], er[ns]);
    printf("  block Jacobi %u it.: %.3e\n  IC(0):", n, er[1] / er[ns]);
    for (j = 0; j < KMAX; j++) printf(" %u it. %.3e%s", j + 1, er[2 + j] / er[ns], j + 1 < KMAX ? "," : "\n");
    for (j = 0; j < KMAX && er[2 + j] > er[1]; j++) {}
    if (j < KMAX) printf("  => IC(0) reaches block Jacobi's %u-iteration accuracy at %u iterations; with one of margin: iterations %u\n", n, j + 1, j + 2);
    else printf("  => IC(0) does not reach block Jacobi's accuracy within %u iterations\n", KMAX);
    pu_rt_close(&rt);
    return 0;
}
