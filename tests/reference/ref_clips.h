/* ref_clips.h -- step double-reference states through clips in lockstep,
 * shared by tests/precond_study.c and tests/ichol_count.c (the measurement
 * programs that compare preconditioners over whole clips). Needs sn_clip.h,
 * snref.h and reference/phys_util.h included first; defines one static
 * function, so each program that includes it gets its own copy. */
#ifndef SN_REF_CLIPS_H
#define SN_REF_CLIPS_H

/* Step every state through the clips in lockstep (reset at each clip);
 * err[j] (if non-NULL): max over steps of the max surface distance of state
 * j from state 0, mesh units; err[n] gets the max elastic displacement of
 * state 0 (surface minus the surface of the skinned lattice). */
static int pu_drive_clips(const pu_rt *rt, const snref_model *m, const char **clips, unsigned nclip, snref_state **st, unsigned ns,
                          double *err) {
    unsigned c, k, j, i, q;
    double *s0 = err ? malloc(sizeof(double) * 3 * m->nS) : NULL, *sj = err ? malloc(sizeof(double) * 3 * m->nS) : NULL;
    double *skin = err ? malloc(sizeof(double) * 3 * m->nV) : NULL, *ss = err ? malloc(sizeof(double) * 3 * m->nS) : NULL;
    if (err) for (j = 0; j <= ns; j++) err[j] = 0;
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
            if (err) {
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
        }
        free(text); free(clip); free(local); free(xf); free(rx);
    }
    free(s0); free(sj); free(skin); free(ss);
    return 0;
}

#endif
