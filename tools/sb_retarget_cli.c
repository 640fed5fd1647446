/* sb_retarget_cli.c -- 'sinew-rig retarget' (seed 003 §4.4), in its own file:
 * tools/sinew_rig.c's main hands it argv from the sub-command's name on.
 *
 *   sinew-rig retarget A.sinew B.sinew --rig NAME[,NAME...] -o OUT.rig [options]
 *
 * Loads both characters, maps A's lattice onto B (eq. 15), estimates J_i
 * (eq. 16), transfers the named rigs of A (summed at eta = 1) to B and writes
 * the generalized-force rig of B (sb_rt_write_rig). Nothing is written unless
 * everything before the writing succeeded. */
#include "sb.h"
#include "sb_retarget.h"
#include "raster.h"
#include "png.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void usage(FILE *f, const char *prog)
{
    fprintf(f,
            "usage: %s A.sinew B.sinew --rig NAME[,NAME...] -o OUT.rig [options]\n"
            "Carries rigs of character A to character B (seed 003 §4.4): maps A's control lattice onto B\n"
            "by minimizing w_skel C_skel + w_surf C_surf + C_distort (eq. 15; joints matched by name, every\n"
            "joint of A must exist in B unless --joints/--skip say otherwise), estimates the map's Jacobian\n"
            "J_i at every lattice vertex (eq. 16),\n"
            "and transfers the rigs' generalized force: Q_A -> q_A (static equilibrium at rest, eq. 10) ->\n"
            "J_i q_A,i -> B's lattice -> Q_B = K_B q_B. Writes Q_B as a rig file (tools/DESCRIPTION.md \"Rig\n"
            "files\") that B's description includes with 'rig_file NAME FILE CONTROL'. B with 'levels 2': a fit\n"
            "per level (the same transfer onto level 1's own lattice; tools/DESCRIPTION.md \"Retargeting\").\n"
            "  --rig LIST        rigs of A, comma-separated, summed at eta = 1 (e.g. smile_l,smile_r)\n"
            "  -o OUT.rig        the rig of B (written to OUT.rig.tmp, then renamed)\n"
            "  --name NAME       the rig's name in the printed rig_file line (default: the first rig's name)\n"
            "  --control NAME    control of B driving it (default: the first rig's control in A)\n"
            "  --joints LIST     A_JOINT=B_JOINT,... : joints of A matched to B joints of other names\n"
            "  --skip LIST       A_JOINT,... : joints of A left out of the skeleton match\n"
            "  --w-skel W        weight of C_skel (default 100)\n"
            "  --w-surf W        weight of C_surf (default 100)\n"
            "  --corr MODE       auto | vertex | closest: surface correspondence (auto: vertex when A and B\n"
            "                    have the same vertex count, else closest points)\n"
            "  --rounds N        closest-point rounds (default 12)\n"
            "  --optimizer O     cg (default; the cost is quadratic within a round) or lbfgsb\n"
            "  --png OUT.png     picture: A rest | A rigged | B rest | B rigged (static equilibria at rest,\n"
            "                    displacement times --gain, coloured by its size) | A's surface under the map\n"
            "  --gain G          picture displacement multiplier (default 1)\n"
            "  --view-a AZ,EL    camera of A's panels (degrees, default 60,15); --view-b for B's\n"
            "  --frame-a X0,Y0,Z0,X1,Y1,Z1  camera box of A's panels (mesh units; default the surface's\n"
            "                    bounds); --frame-b for B's\n"
            "  --map-obj OUT.obj A's surface under the map h (to compare with B's in a viewer)\n"
            "  --quiet           no progress lines or summary\n"
            "Progress (stderr): one line per closest-point round: cost, its three terms, gradient norm,\n"
            "inner iterations. Summary (stdout): residuals, det J_i range, transfer figures. Exit status 0,\n"
            "1 (a bake, the map or the transfer failed), 2 (bad command line); nothing written on failure.\n"
            "  --help            this text\n",
            prog);
}

static const uint8_t ink[3] = { 25, 28, 38 };

static const double *frame_box;   /* the panel's camera box (mesh units), NULL: the surface's bounds */

static int panel(rs_image *out, const double *surf, int ns, const int *tris, int nt, const double *base, double scale,
                 double az, double el, const char *l1, const char *l2)
{
    rs_image big;
    rs_camera cam;
    float *pos = malloc(3 * (size_t)ns * sizeof *pos), *col = malloc(3 * (size_t)ns * sizeof *col);
    float lo[3] = { 1e30f, 1e30f, 1e30f }, hi[3] = { -1e30f, -1e30f, -1e30f };
    uint32_t *tri = malloc(3 * (size_t)nt * sizeof *tri + 4);
    int i, k;
    if (!pos || !col || !tri || rs_image_alloc(&big, 2 * out->w, 2 * out->h)) { free(pos); free(col); free(tri); return -1; }
    for (i = 0; i < 3 * ns; i++) pos[i] = (float)surf[i];
    for (i = 0; i < 3 * nt; i++) tri[i] = (uint32_t)tris[i];
    for (i = 0; i < ns; i++) {
        float h = 0;
        for (k = 0; k < 3; k++) {
            float x = (float)(base ? base[3 * i + k] : surf[3 * i + k]);
            if (x < lo[k]) lo[k] = x;
            if (x > hi[k]) hi[k] = x;
        }
        if (base && scale > 0) {
            double d = 0;
            for (k = 0; k < 3; k++) d += (surf[3 * i + k] - base[3 * i + k]) * (surf[3 * i + k] - base[3 * i + k]);
            h = (float)(sqrt(d) / scale);
            if (h > 1) h = 1;
        }
        col[3 * i] = 0.78f + h * (0.95f - 0.78f);
        col[3 * i + 1] = 0.60f + h * (0.12f - 0.60f);
        col[3 * i + 2] = 0.44f + h * (0.05f - 0.44f);
    }
    if (frame_box) {
        float ground = lo[1];
        for (k = 0; k < 3; k++) { lo[k] = (float)frame_box[k]; hi[k] = (float)frame_box[3 + k]; }
        rs_camera_frame(&cam, lo, hi, big.w, big.h, (float)az, (float)el);
        cam.ground_y = ground;
    } else {
        rs_camera_frame(&cam, lo, hi, big.w, big.h, (float)az, (float)el);
        cam.ground_y = lo[1];
    }
    rs_clear(&big, &cam);
    rs_draw_mesh_colors(&big, &cam, pos, ns, tri, nt, col);
    rs_downsample2(&big, out);
    rs_image_free(&big);
    if (l1) rs_draw_text(out, 8, 8, 2, l1, ink);
    if (l2) rs_draw_text(out, 8, 28, 1, l2, ink);
    free(pos); free(col); free(tri);
    return 0;
}

static double maxdisp(const double *a, const double *b, int n)
{
    double m = 0;
    int i;
    for (i = 0; i < n; i++) {
        double d = sqrt((a[3 * i] - b[3 * i]) * (a[3 * i] - b[3 * i]) + (a[3 * i + 1] - b[3 * i + 1]) * (a[3 * i + 1] - b[3 * i + 1]) +
                        (a[3 * i + 2] - b[3 * i + 2]) * (a[3 * i + 2] - b[3 * i + 2]));
        if (d > m) m = d;
    }
    return m;
}

static int parse_pair(const char *s, double *a, double *b)
{
    char *e;
    *a = strtod(s, &e);
    if (*e != ',') return -1;
    *b = strtod(e + 1, &e);
    return *e || !isfinite(*a) || !isfinite(*b) ? -1 : 0;
}

static int parse_box(const char *s, double *b)
{
    int k;
    char *e;
    for (k = 0; k < 6; k++) {
        b[k] = strtod(s, &e);
        if (e == s || !isfinite(b[k]) || (k < 5 && *e != ',') || (k == 5 && *e)) return -1;
        s = e + 1;
    }
    return b[0] < b[3] && b[1] < b[4] && b[2] < b[5] ? 0 : -1;
}

static int parse_pos(const char *s, double *v)
{
    char *e;
    *v = strtod(s, &e);
    return *e || e == s || !isfinite(*v) || *v < 0 ? -1 : 0;
}

/* B's level 1 ('levels 2'): the same map and transfer of A's rig force QA onto level 1's own
 * lattice (sb_rt_char_load_level1: built as the bake builds it), so that B's rig file carries
 * a fit per level. QB1 (B1->o.nf x 3) out. 0 or -1 (the message printed) */
static int level1_transfer(const char *prog, const char *pb, const sb_rt_char *A, const sb_rt_opts *opt0, const double *QA, double db0, int quiet,
                           sb_rt_char *B1, double **QB1)
{
    sb_retarget rt1;
    sb_rt_opts opt = *opt0;
    sb_rt_transfer_stats st;
    double *qB1 = NULL, *s0 = NULL, *s1 = NULL, res, db, t0 = sb_now();
    int rc = -1;
    memset(&rt1, 0, sizeof rt1);
    opt.verbose = 0;
    if (sb_rt_char_load_level1(pb, B1)) { fprintf(stderr, "%s: error: B level 1: %s\n", prog, sb_error()); return -1; }
    *QB1 = calloc(3 * (size_t)B1->o.nf + 3, sizeof **QB1);
    qB1 = calloc(3 * (size_t)B1->o.nv + 3, sizeof *qB1);
    s0 = malloc(sizeof(double) * 3 * (size_t)(B1->o.ns + 1)); s1 = malloc(sizeof(double) * 3 * (size_t)(B1->o.ns + 1));
    if (!*QB1 || !qB1 || !s0 || !s1) { fprintf(stderr, "%s: out of memory\n", prog); goto done; }
    if (sb_rt_init(&rt1, &A->o, &A->m, &B1->o, &B1->m, &opt) || sb_rt_solve(&rt1) || sb_rt_jacobians(&rt1) || sb_rt_transfer(&rt1, QA, *QB1, NULL, qB1, &st)) {
        fprintf(stderr, "%s: error: B level 1: %s\n", prog, sb_error());
        goto done;
    }
    res = sb_rt_static(&B1->o, *QB1, qB1);
    sb_rt_surface(&B1->o, NULL, s0); sb_rt_surface(&B1->o, qB1, s1); db = maxdisp(s0, s1, B1->o.ns);
    if (!quiet)
        printf("retarget: B level 1 (cell %g, lattice %d (%d free)): map surface rms %.4g max %.4g; the rig moves B's surface by up to %.4g mesh units "
               "(level 0: %.4g); %d of its free vertices sampled, %d smoothed; static residual %.1e (%.2f s)\n",
               B1->o.c, B1->o.nv, B1->o.nf, rt1.surf_rms, rt1.surf_max, db, db0, st.inside, st.outside, res, sb_now() - t0);
    rc = 0;
done:
    free(qB1); free(s0); free(s1);
    sb_rt_free(&rt1);
    return rc;
}

int sb_retarget_cli(int argc, char **argv, const char *prog)
{
    const char *pa = NULL, *pb = NULL, *rigs = NULL, *out = NULL, *name = NULL, *control = NULL, *png = NULL, *mapobj = NULL;
    double gain = 1, aza = 60, ela = 15, azb = 60, elb = 15, boxa[6], boxb[6];
    int has_boxa = 0, has_boxb = 0;
    int i, quiet = 0, rc = 1, ctl = -1;
    sb_rt_opts opt;
    sb_rt_char A, B, B1;
    sb_retarget rt;
    double *QA = NULL, *QB = NULL, *qA = NULL, *qB = NULL, *QB1 = NULL, t0 = sb_now(), db0 = 0;
    sb_rt_defaults(&opt);
    memset(&A, 0, sizeof A); memset(&B, 0, sizeof B); memset(&B1, 0, sizeof B1); memset(&rt, 0, sizeof rt);
    for (i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int bad = 0;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { usage(stdout, prog); return 0; }
        if (!strcmp(a, "--quiet")) { quiet = 1; continue; }
        if (a[0] == '-' && !v) { fprintf(stderr, "%s: %s needs a value\n", prog, a); return 2; }
        if (!strcmp(a, "--rig")) rigs = v;
        else if (!strcmp(a, "-o")) out = v;
        else if (!strcmp(a, "--name")) name = v;
        else if (!strcmp(a, "--control")) control = v;
        else if (!strcmp(a, "--png")) png = v;
        else if (!strcmp(a, "--joints")) opt.joint_map = v;
        else if (!strcmp(a, "--skip")) opt.skip = v;
        else if (!strcmp(a, "--map-obj")) mapobj = v;
        else if (!strcmp(a, "--w-skel")) bad = parse_pos(v, &opt.w_skel);
        else if (!strcmp(a, "--w-surf")) bad = parse_pos(v, &opt.w_surf);
        else if (!strcmp(a, "--gain")) bad = parse_pos(v, &gain);
        else if (!strcmp(a, "--rounds")) { double r; bad = parse_pos(v, &r) || r < 1 || r > 1000; opt.rounds = (int)r; }
        else if (!strcmp(a, "--view-a")) bad = parse_pair(v, &aza, &ela);
        else if (!strcmp(a, "--view-b")) bad = parse_pair(v, &azb, &elb);
        else if (!strcmp(a, "--frame-a")) { bad = parse_box(v, boxa); has_boxa = 1; }
        else if (!strcmp(a, "--frame-b")) { bad = parse_box(v, boxb); has_boxb = 1; }
        else if (!strcmp(a, "--corr")) {
            if (!strcmp(v, "auto")) opt.corr = SB_RT_CORR_AUTO;
            else if (!strcmp(v, "vertex")) opt.corr = SB_RT_CORR_VERTEX;
            else if (!strcmp(v, "closest")) opt.corr = SB_RT_CORR_CLOSEST;
            else bad = 1;
        } else if (!strcmp(a, "--optimizer")) {
            if (!strcmp(v, "cg")) opt.optimizer = SB_RT_OPT_CG;
            else if (!strcmp(v, "lbfgsb")) opt.optimizer = SB_RT_OPT_LBFGSB;
            else bad = 1;
        } else if (a[0] == '-') { fprintf(stderr, "%s: unknown option '%s' (--help)\n", prog, a); return 2; }
        else {
            if (!pa) pa = a;
            else if (!pb) pb = a;
            else { fprintf(stderr, "%s: more than two descriptions ('%s')\n", prog, a); return 2; }
            continue;
        }
        if (bad) { fprintf(stderr, "%s: %s: bad value '%s'\n", prog, a, v); return 2; }
        i++;
    }
    if (!pa || !pb || !rigs || !out) { usage(stderr, prog); return 2; }
    opt.verbose = !quiet;
    if (sb_rt_char_load(pa, &A)) { fprintf(stderr, "%s: error: A: %s\n", prog, sb_error()); goto done; }
    if (sb_rt_char_load(pb, &B)) { fprintf(stderr, "%s: error: B: %s\n", prog, sb_error()); goto done; }
    if (!quiet)
        printf("retarget: A %s: %d surface vertices, lattice %d (%d free), %d joints; B %s: %d surface vertices, lattice %d (%d free), %d joints (%.2f s)\n",
               pa, A.m.nv, A.o.nv, A.o.nf, A.o.nj, pb, B.m.nv, B.o.nv, B.o.nf, B.o.nj, sb_now() - t0);
    QA = calloc(3 * (size_t)A.o.nf, sizeof *QA); QB = calloc(3 * (size_t)B.o.nf, sizeof *QB);
    qA = calloc(3 * (size_t)A.o.nv, sizeof *qA); qB = calloc(3 * (size_t)B.o.nv, sizeof *qB);
    if (!QA || !QB || !qA || !qB) { fprintf(stderr, "%s: out of memory\n", prog); goto done; }
    if (sb_rt_rig_force(&A.o, rigs, QA, &ctl)) { fprintf(stderr, "%s: error: %s\n", prog, sb_error()); goto done; }
    if (!control) control = A.o.ctl[ctl].name;
    if (!name) {
        static char nm[SB_NAME_MAX];
        size_t l = strcspn(rigs, ",");
        snprintf(nm, sizeof nm, "%.*s", (int)(l < SB_NAME_MAX - 1 ? l : SB_NAME_MAX - 1), rigs);
        name = nm;
    }
    if (sb_rt_init(&rt, &A.o, &A.m, &B.o, &B.m, &opt)) { fprintf(stderr, "%s: error: %s\n", prog, sb_error()); goto done; }
    if (!quiet)
        printf("retarget: %d joints matched by name, %d skeleton samples, %s correspondence, %d distortion stencils\n", rt.njm, rt.nsk,
               rt.corr == SB_RT_CORR_VERTEX ? "vertex" : "closest-point", rt.nd);
    if (sb_rt_solve(&rt) || sb_rt_jacobians(&rt)) { fprintf(stderr, "%s: error: %s\n", prog, sb_error()); goto done; }
    {
        double jmin = 1e300, jmax = -1e300;
        int k;
        for (k = 0; k < rt.nv; k++) {
            const double *J = rt.J + 9 * k;
            double det = J[0] * (J[4] * J[8] - J[5] * J[7]) - J[1] * (J[3] * J[8] - J[5] * J[6]) + J[2] * (J[3] * J[7] - J[4] * J[6]);
            jmin = fmin(jmin, det); jmax = fmax(jmax, det);
        }
        if (!quiet) {
            printf("retarget: map: %d rounds, %d inner iterations, %.2f s; cost %.4e = skel %.3e + surf %.3e + distort %.3e, |grad| %.2e\n",
                   rt.rounds, rt.cg_iters, rt.secs, rt.cost, rt.c_skel, rt.c_surf, rt.c_dist, rt.gnorm);
            printf("retarget: residuals (B mesh units, B's size %.4g): skeleton rms %.4g max %.4g; surface rms %.4g max %.4g\n", rt.L, rt.skel_rms,
                   rt.skel_max, rt.surf_rms, rt.surf_max);
            printf("retarget: det J_i in [%.4g, %.4g] (volume ratio B/A of the map at the lattice vertices)\n", jmin, jmax);
        }
        if (!(jmin > 0)) fprintf(stderr, "%s: warning: the map folds (det J_i %.3g <= 0 at some lattice vertex): raise the distortion weight\n", prog, jmin);
    }
    {
        sb_rt_transfer_stats st;
        double res;
        if (sb_rt_transfer(&rt, QA, QB, qA, qB, &st)) { fprintf(stderr, "%s: error: %s\n", prog, sb_error()); goto done; }
        res = sb_rt_static(&B.o, QB, qB);
        {   /* the rigs' surface displacement on A and B (static equilibria at rest) */
            double *s0 = malloc(sizeof(double) * 3 * (size_t)(A.o.ns > B.o.ns ? A.o.ns : B.o.ns));
            double *s1 = malloc(sizeof(double) * 3 * (size_t)(A.o.ns > B.o.ns ? A.o.ns : B.o.ns)), da, db;
            if (!s0 || !s1) { free(s0); free(s1); fprintf(stderr, "%s: out of memory\n", prog); goto done; }
            sb_rt_surface(&A.o, NULL, s0); sb_rt_surface(&A.o, qA, s1); da = maxdisp(s0, s1, A.o.ns);
            sb_rt_surface(&B.o, NULL, s0); sb_rt_surface(&B.o, qB, s1); db = maxdisp(s0, s1, B.o.ns); db0 = db;
            if (!quiet)
                printf("retarget: the rig moves the surface by up to %.4g mesh units on A (%.3g%% of its size), %.4g on B (%.3g%%)\n", da,
                       100 * da / rt.LA, db, 100 * db / rt.L);
            free(s0); free(s1);
        }
        if (!quiet)
            printf("retarget: transfer: |q_A| max %.4g (A units), |q_B| max %.4g (B units); B's surface vertices: %d in A's mapped lattice, %d "
                   "outside (closest mapped surface point); %d of B's %d free vertices sampled, %d smoothed; static residuals A %.1e, B %.1e\n",
                   st.qA_max, st.qB_max, st.surf_inside, st.surf_outside, st.inside, B.o.nf, st.outside, st.static_res, res);
    }
    if (B.d.levels > 1 && level1_transfer(prog, pb, &A, &opt, QA, db0, quiet, &B1, &QB1)) goto done;   /* 'levels 2': a fit per level */
    /* outputs */
    {
        char head[4096];
        snprintf(head, sizeof head,
                 "retargeted (sinew-rig retarget, seed 003 §4.4): rigs %s of %s carried to %s\n"
                 "include in B's description: rig_file %s FILE %s\n"
                 "w_skel %g, w_surf %g, %s correspondence, %d rounds\n"
                 "map residuals (B mesh units): skeleton rms %.6g max %.6g, surface rms %.6g max %.6g; distortion %.6g",
                 rigs, pa, pb, name, control, opt.w_skel, opt.w_surf, rt.corr == SB_RT_CORR_VERTEX ? "vertex" : "closest-point", rt.rounds,
                 rt.skel_rms, rt.skel_max, rt.surf_rms, rt.surf_max, rt.c_dist);
        const sb_model *Bl[2];
        const double *Ql[2];
        Bl[0] = &B.o; Bl[1] = &B1.o; Ql[0] = QB; Ql[1] = QB1;
        if (QB1) snprintf(head + strlen(head), sizeof head - strlen(head), "\nlevels 2: a fit on each of B's levels (level 0, then level 1: the same map onto its lattice)");
        if (sb_rt_write_rig_levels(out, QB1 ? 2 : 1, Bl, &B.m, Ql, head)) { fprintf(stderr, "%s: error: %s\n", prog, sb_error()); goto done; }
    }
    if (mapobj) {
        FILE *f = fopen(mapobj, "w");
        int k, c, a;
        if (!f) { fprintf(stderr, "%s: cannot write %s\n", prog, mapobj); remove(out); goto done; }
        fprintf(f, "# %s under the retargeting map onto %s\n", pa, pb);
        for (k = 0; k < A.m.nv; k++) {
            double N[8], p[3] = { 0, 0, 0 };
            sb_shape(A.o.emb_t + 3 * k, N, NULL);
            for (c = 0; c < 8; c++)
                for (a = 0; a < 3; a++) p[a] += N[c] * rt.h[3 * A.o.cells[8 * A.o.emb_cell[k] + c] + a];
            fprintf(f, "v %.9g %.9g %.9g\n", p[0], p[1], p[2]);
        }
        for (k = 0; k < A.o.nt; k++) fprintf(f, "f %d %d %d\n", A.o.tri[3 * k] + 1, A.o.tri[3 * k + 1] + 1, A.o.tri[3 * k + 2] + 1);
        fclose(f);
    }
    if (png) {
        enum { PW = 400, PH = 300 };
        rs_image img, pane;
        double *a0 = malloc(sizeof(double) * 3 * (size_t)A.o.ns), *a1 = malloc(sizeof(double) * 3 * (size_t)A.o.ns);
        double *b0 = malloc(sizeof(double) * 3 * (size_t)B.o.ns), *b1 = malloc(sizeof(double) * 3 * (size_t)B.o.ns);
        double da, db;
        char la[128], lb[128], err[300];
        const uint8_t line[3] = { 90, 90, 90 };
        int k, ok = a0 && a1 && b0 && b1 && !rs_image_alloc(&img, 5 * PW, PH) && !rs_image_alloc(&pane, PW, PH);
        if (ok) {
            for (k = 0; k < 3 * A.o.nv; k++) qA[k] *= gain;
            for (k = 0; k < 3 * B.o.nv; k++) qB[k] *= gain;
            sb_rt_surface(&A.o, NULL, a0); sb_rt_surface(&A.o, qA, a1);
            sb_rt_surface(&B.o, NULL, b0); sb_rt_surface(&B.o, qB, b1);
            da = maxdisp(a0, a1, A.o.ns); db = maxdisp(b0, b1, B.o.ns);
            snprintf(la, sizeof la, "red: %.3g (x%g)", da, gain);
            snprintf(lb, sizeof lb, "red: %.3g (x%g)", db, gain);
            frame_box = has_boxa ? boxa : NULL;
            ok = !panel(&pane, a0, A.o.ns, A.o.tri, A.o.nt, NULL, 0, aza, ela, "A rest", pa);
            if (ok) rs_blit(&img, 0, 0, &pane);
            ok = ok && !panel(&pane, a1, A.o.ns, A.o.tri, A.o.nt, a0, da, aza, ela, "A rig (source)", la);
            if (ok) rs_blit(&img, PW, 0, &pane);
            frame_box = has_boxb ? boxb : NULL;
            ok = ok && !panel(&pane, b0, B.o.ns, B.o.tri, B.o.nt, NULL, 0, azb, elb, "B rest", pb);
            if (ok) rs_blit(&img, 2 * PW, 0, &pane);
            ok = ok && !panel(&pane, b1, B.o.ns, B.o.tri, B.o.nt, b0, db, azb, elb, "B rig (retargeted)", lb);
            if (ok) rs_blit(&img, 3 * PW, 0, &pane);
            /* A's surface under the map h, seen like B */
            for (k = 0; k < A.o.ns; k++) {
                double N[8];
                int c, x;
                sb_shape(A.o.emb_t + 3 * k, N, NULL);
                for (x = 0; x < 3; x++) a1[3 * k + x] = 0;
                for (c = 0; c < 8; c++)
                    for (x = 0; x < 3; x++) a1[3 * k + x] += N[c] * rt.h[3 * A.o.cells[8 * A.o.emb_cell[k] + c] + x];
            }
            snprintf(la, sizeof la, "surface rms %.3g max %.3g", rt.surf_rms, rt.surf_max);
            ok = ok && !panel(&pane, a1, A.o.ns, A.o.tri, A.o.nt, NULL, 0, azb, elb, "h(A): A mapped onto B", la);
            if (ok) rs_blit(&img, 4 * PW, 0, &pane);
            for (k = 1; k < 5; k++) rs_fill(&img, k * PW - 1, 0, 2, PH, line);
            if (ok && png_write(png, img.rgb, img.w, img.h, err, sizeof err)) { fprintf(stderr, "%s: %s\n", prog, err); ok = 0; }
            rs_image_free(&img); rs_image_free(&pane);
        }
        free(a0); free(a1); free(b0); free(b1);
        if (!ok) { remove(out); if (mapobj) remove(mapobj); fprintf(stderr, "%s: the picture failed: nothing kept\n", prog); goto done; }
    }
    if (!quiet) printf("retarget: include it in %s with: rig_file %s %s %s\n", pb, name, out, control);
    if (!quiet) printf("retarget: wrote %s%s%s%s%s (%.2f s in all)\n", out, png ? " and " : "", png ? png : "", mapobj ? " and " : "", mapobj ? mapobj : "",
                       sb_now() - t0);
    rc = 0;
done:
    free(QA); free(QB); free(qA); free(qB); free(QB1);
    sb_rt_free(&rt);
    sb_rt_char_free(&A); sb_rt_char_free(&B); sb_rt_char_free(&B1);
    return rc;
}
