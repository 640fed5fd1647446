/* hier_picture.c -- the picture of the hierarchical-solve study (runtime/LEVELS.md §3, "A true
 * hierarchical solve, measured"): per row a character at a pose (the cow's head turn 90, the
 * beast's neck turn 60), per column the embedded surface of the baked level 0 (c'), the cut
 * hierarchy with no detail (d, k = 0), with the estimate's 50 largest details (d, k = 50, parent
 * frames) and level 1 nodal (a), each coloured by its distance from (a)'s surface on one scale.
 * The solves are hier_study.c's own (included); the printed errors are its table's.
 * Usage: hier_picture OUT.png [COW.sinew BEAST.sinew]; `make hier-picture`. */
#define HIER_PICTURE
#include "hier_study.c"
#include "raster.h"
#include "png.h"

enum { NCOL = 4, NROW = 2, PW = 240, PH = 200, LEGH = 56 };
static const char *col_name[NCOL] = {"baked level 0", "cut, k = 0", "adaptive k = 50", "level 1"};
static const int col_k[NCOL] = {-1, 0, 50, -1};

typedef struct {
    study S;
    const char *who;        /* caption: character, pose */
    double az, el;          /* view */
    pose_spec pose;
    double *surf[NCOL];     /* embedded surface, mesh units */
    double emax[NCOL], erms[NCOL];   /* vs level 1, level-0 cells */
    float lo[3], hi[3];     /* the row's framing: every column's surface */
} row;

/* the row's four surfaces at its pose; 0 or -1 (a solve failed) */
static int row_solve(row *R)
{
    study *S = &R->S;
    const sb_hier *h = &S->h;
    const sb_lev *L = S->L1;
    lproblem P;
    unsigned char *act = xalloc((size_t)h->nh);
    int *ufun = xalloc(sizeof(int) * (size_t)h->nh), *ord, *sel, N, nco, nd, c, i, k, rc = -1;
    double *p1 = xalloc(sizeof(double) * 3 * (size_t)L->nv), *p0 = xalloc(sizeof(double) * 3 * (size_t)S->o.nv),
           *Me0 = xalloc(sizeof(double) * 64 * (size_t)S->o.nc), *Hb = NULL, *gb = NULL, *est;
    for (c = 0; c < NCOL; c++) R->surf[c] = xalloc(sizeof(double) * 3 * (size_t)S->m.nv);
    set_pose(S, &R->pose);
    lp_nodal1(S, &P, 1);                              /* (a) level 1, own frames */
    if (solve_lp(&P, p1, NULL, NULL, NULL)) goto fail;
    surface(S, 1, p1, R->surf[3]);
    lp_free(&P);
    lp_level0(S, &P, Me0);                            /* (c') the baked level 0 */
    if (solve_lp(&P, p0, NULL, NULL, NULL)) goto fail;
    surface(S, 0, p0, R->surf[0]);
    lp_free(&P);
    memset(act, 1, (size_t)h->nh);                   /* (d) cut basis, parent frames: as adaptive() */
    lp_hier(S, &P, act, 0, 1, ufun, NULL);
    if (solve_lp(&P, p1, &Hb, &gb, NULL)) goto fail;
    N = 3 * P.nu;
    for (nco = 0; nco < P.nu && h->hlev[ufun[nco]] == 0; nco++) {}
    nd = P.nu - nco;
    est = xalloc(sizeof(double) * (size_t)(nd + 1)); ord = xalloc(sizeof(int) * (size_t)(nd + 1)); sel = xalloc(sizeof(int) * (size_t)(P.nu + 1));
    if (!rank_details(S, Hb, gb, N, nco, est, ord)) {
        for (c = 1; c <= 2; c++) {
            int kk = col_k[c] > nd ? nd : col_k[c], Nk = 3 * (nco + kk);
            double *Hk = xalloc(sizeof(double) * (size_t)Nk * Nk), *gk = xalloc(sizeof(double) * (size_t)Nk),
                   *uk = xalloc(sizeof(double) * (size_t)Nk), *uf = xalloc(sizeof(double) * (size_t)N);
            for (i = 0; i < nco; i++) sel[i] = i;
            for (i = 0; i < kk; i++) sel[nco + i] = nco + ord[i];
            subsys(Hb, gb, N, sel, nco + kk, Hk, gk);
            k = dense_solve(Hk, Nk, gk, uk);
            for (i = 0; i < Nk; i++) uf[3 * sel[i / 3] + i % 3] = uk[i];
            expand(&P, uf, p1); surface(S, 1, p1, R->surf[c]);
            free(Hk); free(gk); free(uk); free(uf);
            if (k) break;
        }
        rc = c == 3 ? 0 : -1;
    }
    free(est); free(ord); free(sel);
fail:
    lp_free(&P);
    free(act); free(ufun); free(p1); free(p0); free(Me0); free(Hb); free(gb);
    if (rc) return -1;
    for (k = 0; k < 3; k++) { R->lo[k] = 1e30f; R->hi[k] = -1e30f; }
    for (c = 0; c < NCOL; c++) {
        surf_err(S, R->surf[c], R->surf[3], &R->emax[c], &R->erms[c]);
        for (i = 0; i < 3 * S->m.nv; i++) {
            float x = (float)R->surf[c][i];
            if (x < R->lo[i % 3]) R->lo[i % 3] = x;
            if (x > R->hi[i % 3]) R->hi[i % 3] = x;
        }
    }
    R->hi[1] += 0.2f * (R->hi[1] - R->lo[1]);   /* headroom for the captions */
    return 0;
}

/* flesh to red as rs_heat_panel, unshaded, in sRGB bytes */
static void heat_rgb(double t, uint8_t out[3])
{
    static const float flesh[3] = {0.78f, 0.60f, 0.44f}, red[3] = {0.95f, 0.12f, 0.05f};
    int k;
    for (k = 0; k < 3; k++) out[k] = (uint8_t)(255.0 * pow(flesh[k] + t * (red[k] - flesh[k]), 1 / 2.2) + 0.5);
}

static int render(row *rows, double scale, const char *path)
{
    static const uint8_t ink[3] = {25, 28, 38}, rule[3] = {90, 90, 90}, paper[3] = {240, 240, 236};
    rs_image img, pane;
    unsigned *tri = NULL;
    int r, c, i, x, rc = -1;
    char l1[64], l2[64], l3[64], err[300];
    if (rs_image_alloc(&img, NCOL * PW, NROW * PH + LEGH)) return -1;
    if (rs_image_alloc(&pane, PW, PH)) { rs_image_free(&img); return -1; }
    rs_fill(&img, 0, 0, img.w, img.h, paper);
    for (r = 0; r < NROW; r++) {
        study *S = &rows[r].S;
        free(tri);
        tri = xalloc(sizeof(unsigned) * 3 * (size_t)S->m.nt);
        for (i = 0; i < 3 * S->m.nt; i++) tri[i] = (unsigned)S->m.tri[i];
        for (c = 0; c < NCOL; c++) {
            snprintf(l1, sizeof l1, "%s", col_name[c]);
            snprintf(l2, sizeof l2, "%s", rows[r].who);
            if (c == NCOL - 1) snprintf(l3, sizeof l3, "the reference");
            else snprintf(l3, sizeof l3, "max %.3f, rms %.4f cell", rows[r].emax[c], rows[r].erms[c]);
            if (rs_heat_panel(&pane, rows[r].surf[c], rows[r].surf[NCOL - 1], scale * S->o.c, (unsigned)S->m.nv, tri, (unsigned)S->m.nt,
                              rows[r].lo, rows[r].hi, rows[r].az, rows[r].el, l1, l2)) goto out;
            rs_draw_text(&pane, 8, 40, 1, l3, ink);
            rs_blit(&img, c * PW, r * PH, &pane);
        }
    }
    for (c = 1; c < NCOL; c++) rs_fill(&img, c * PW - 1, 0, 2, NROW * PH, rule);
    for (r = 1; r <= NROW; r++) rs_fill(&img, 0, r * PH - 1, img.w, 2, rule);
    {   /* legend: the one scale of every panel */
        int bx = 8, by = NROW * PH + 8, bw = 280, bh = 14;
        for (x = 0; x < bw; x++) { uint8_t col[3]; heat_rgb((double)x / (bw - 1), col); rs_fill(&img, bx + x, by, 1, bh, col); }
        rs_draw_text(&img, bx, by + bh + 6, 1, "0", ink);
        snprintf(l1, sizeof l1, "%.2f cell", scale);
        rs_draw_text(&img, bx + bw - 6 * (int)strlen(l1), by + bh + 6, 1, l1, ink);
        rs_draw_text(&img, bx + bw + 14, by, 1, "distance of the surface from level 1 (a), level-0 cells: one scale, every panel.", ink);
        rs_draw_text(&img, bx + bw + 14, by + 13, 1, "Static warped equilibria (no gravity), solved as hier_study: the baked level 0,", ink);
        rs_draw_text(&img, bx + bw + 14, by + 26, 1, "coarse hats cut at the level-1 skeleton with no detail (k = 0) and with the", ink);
        rs_draw_text(&img, bx + bw + 14, by + 39, 1, "50 details the estimate ranks first (parent frames). make hier-picture", ink);
    }
    rc = png_write(path, img.rgb, img.w, img.h, err, sizeof err);
    if (rc) fprintf(stderr, "hier_picture: %s\n", err);
out:
    free(tri); rs_image_free(&pane); rs_image_free(&img);
    return rc;
}

int main(int argc, char **argv)
{
    row rows[NROW];
    const char *desc[NROW];
    double scale = 0;
    int r, c, rc = 1;
    (void)t_seed; (void)run;
    if (argc != 2 && argc != 4) { fprintf(stderr, "usage: hier_picture OUT.png [COW.sinew BEAST.sinew]\n"); return 2; }
    desc[0] = argc == 4 ? argv[2] : "tools/examples/cow/cow.sinew";
    desc[1] = argc == 4 ? argv[3] : "tools/examples/beast/beast.sinew";
    memset(rows, 0, sizeof rows);
    /* the study's poses (hier_study.c main): the cow's head turn, the beast's neck turn */
    rows[0].who = "cow, head turn 90"; rows[0].az = 40; rows[0].el = 30;
    rows[0].pose.name = "head turn 90 (neck about y)"; rows[0].pose.n = 1;
    rows[0].pose.r[0].joint = "neck"; rows[0].pose.r[0].axis[1] = 1; rows[0].pose.r[0].deg = 90;
    rows[1].who = "beast, neck turn 60"; rows[1].az = 40; rows[1].el = 30;
    rows[1].pose.name = "neck turn 60 (neck about y)"; rows[1].pose.n = 1;
    rows[1].pose.r[0].joint = "neck"; rows[1].pose.r[0].axis[1] = 1; rows[1].pose.r[0].deg = 60;
    for (r = 0; r < NROW; r++) {
        if (study_load(&rows[r].S, desc[r]) || study_prepare(&rows[r].S, desc[r])) goto out;
        if (row_solve(&rows[r])) { fprintf(stderr, "hier_picture: %s: a system is not positive definite\n", desc[r]); goto out; }
        printf("%s, %s: vs level 1 max / rms (level-0 cells):", desc[r], rows[r].pose.name);
        for (c = 0; c < NCOL - 1; c++) {
            printf(" %s %.4f / %.4f;", col_name[c], rows[r].emax[c], rows[r].erms[c]);
            scale = fmax(scale, rows[r].emax[c]);
        }
        printf("\n");
    }
    scale = ceil(scale * 100) / 100;   /* the largest error, rounded up: nothing clamps */
    rc = render(rows, scale, argv[1]) ? 1 : 0;
    if (!rc) printf("hier_picture: wrote %s (scale 0 to %.2f level-0 cells)\n", argv[1], scale);
out:
    for (r = 0; r < NROW; r++) { for (c = 0; c < NCOL; c++) free(rows[r].surf[c]); study_free(&rows[r].S); }
    return rc;
}
