/* sb_cut.c -- the cut coarse level's elements (sb_cut.h; runtime/LEVELS.md §2 "The cut level"). */
#include "sb_cut.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* integer grid coordinates of a lattice vertex in half cells of o (the level-1 grid shares o's corner) */
static int half_coords(const sb_model *o, const sb_model *L, int v, int q[3])
{
    int k, bad = 0;
    for (k = 0; k < 3; k++) {
        double t = (L->gpos[3 * L->v_grid[v] + k] - o->gorg[k]) / (0.5 * o->c);
        q[k] = (int)floor(t + 0.5);
        bad |= fabs(t - q[k]) > 1e-6;
    }
    return bad ? -1 : 0;
}

int sb_cut_build(const sb_model *o, const sb_model *o2, double air, sb_cut *cut)
{
    const int NL = SB_CUT_NL, N3 = 3 * SB_CUT_NL;
    const int hn[3] = {2 * o->gn[0] - 1, 2 * o->gn[1] - 1, 2 * o->gn[2] - 1};
    const size_t nh = (size_t)hn[0] * (size_t)hn[1] * (size_t)hn[2];
    int E, cc, a, b, k, i, j, ch, *hv = NULL, *hc = NULL, *xid = NULL, *did = NULL, rc = -1, full = -1;
    double *Sair = NULL, *Mair = NULL;
    memset(cut, 0, sizeof *cut);
    if (!o2->Me) return sb_fail("internal error: the cut level needs level 1's per-cell mass");
    if (o2->nj != o->nj) return sb_fail("internal error: the levels' skeletons differ");
    for (j = 0; j < o->nj; j++)
        if (strcmp(o->joints[j].name, o2->joints[j].name)) return sb_fail("internal error: the levels' joint orders differ");
    /* level 1 on the half-cell grid of level 0: its vertex at each point, its cell at each corner-0 point */
    hv = sb_alloc(sizeof(int) * nh); hc = sb_alloc(sizeof(int) * nh);
    for (i = 0; i < (int)nh; i++) hv[i] = hc[i] = -1;
    for (i = 0; i < o2->nv; i++) {
        int q[3];
        if (half_coords(o, o2, i, q)) { sb_fail("internal error: level 1's vertex off the half-cell grid"); goto done; }
        if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= hn[0] || q[1] >= hn[1] || q[2] >= hn[2]) continue;   /* outside level 0's grid */
        hv[q[0] + hn[0] * (q[1] + hn[1] * q[2])] = i;
    }
    for (cc = 0; cc < o2->nc; cc++) {
        int q[3];
        half_coords(o, o2, o2->cells[8 * cc], q);
        if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= hn[0] - 1 || q[1] >= hn[1] - 1 || q[2] >= hn[2] - 1) continue;
        hc[q[0] + hn[0] * (q[1] + hn[1] * q[2])] = cc;
        if (full < 0 || o2->cell_fill[cc] > o2->cell_fill[full]) full = cc;
    }
    /* the air element of a child level 1 did not keep (no interior worth a cell): the sb_integrate weight of
     * outside points, air x the solid cube's (exact for one material: the condensed element scales with it;
     * with material regions, the material of level 1's fullest cell) */
    if (full < 0 || !(o2->cell_fill[full] >= 1.0)) { sb_fail("the cut level: level 1 has no cell wholly inside"); goto done; }
    Sair = sb_alloc(sizeof(double) * 576); Mair = sb_alloc(sizeof(double) * 64);
    for (i = 0; i < 576; i++) Sair[i] = air * o2->Se[576 * (size_t)full + (size_t)i];
    for (i = 0; i < 64; i++) Mair[i] = air * o2->Me[64 * (size_t)full + (size_t)i];
    xid = sb_alloc(sizeof(int) * (size_t)o2->nv); did = sb_alloc(sizeof(int) * (size_t)o2->nv);
    for (i = 0; i < o2->nv; i++) xid[i] = did[i] = -1;
    cut->nlost = o2->nc;   /* less each kept level-1 cell a kept level-0 cell claims below */
    cut->xv = sb_alloc(sizeof(int) * (size_t)o2->nv);
    cut->cnx = sb_alloc(sizeof(int) * (size_t)o->nc);
    cut->cx = sb_alloc(sizeof(int) * SB_CUT_MAXX * (size_t)o->nc);
    cut->csub = sb_alloc(sizeof(int) * 27 * (size_t)o->nc);
    cut->dv = sb_alloc(sizeof(int) * (size_t)o2->nv); cut->dcell = sb_alloc(sizeof(int) * (size_t)o2->nv);
    cut->dpoint = sb_alloc(sizeof(int) * (size_t)o2->nv); cut->dx = sb_alloc(sizeof(double) * 3 * (size_t)o2->nv);
    cut->cnd = sb_alloc(sizeof(int) * (size_t)o->nc);
    cut->cd = sb_alloc(sizeof(int) * SB_CUT_MAXX * (size_t)o->nc);
    cut->dsub = sb_alloc(sizeof(int) * 27 * (size_t)o->nc);
    cut->K = sb_alloc(sizeof(double) * (size_t)(N3 * N3) * (size_t)o->nc);
    cut->M = sb_alloc(sizeof(double) * (size_t)(NL * NL) * (size_t)o->nc);
    cut->v1 = sb_alloc(sizeof(int) * (size_t)o->nv);   /* each level-0 vertex's level-1 vertex (-1: none) */
    for (i = 0; i < o->nv; i++) {
        int q[3];
        half_coords(o, o, i, q);
        cut->v1[i] = hv[q[0] + hn[0] * (q[1] + hn[1] * q[2])];
    }
    for (E = 0; E < o->nc; E++) {
        int q0[3], lid[27], dlid[27];
        double *KE = cut->K + (size_t)(N3 * N3) * (size_t)E, *ME = cut->M + (size_t)(NL * NL) * (size_t)E;
        half_coords(o, o, o->cells[8 * E], q0);
        /* the extras: level-1 skeleton vertices at the non-corner points of E's closure, in point order */
        for (k = 0; k < 27; k++) {
            int u[3] = {k % 3, k / 3 % 3, k / 9}, n;
            cut->csub[27 * E + k] = -1; cut->dsub[27 * E + k] = -1; lid[k] = -1;
            if (!(u[0] & 1) && !(u[1] & 1) && !(u[2] & 1)) { lid[k] = (u[0] >> 1) | (u[1] >> 1) << 1 | (u[2] >> 1) << 2; continue; }
            n = hv[(q0[0] + u[0]) + hn[0] * ((q0[1] + u[1]) + hn[1] * (q0[2] + u[2]))];
            if (n < o2->nf) continue;   /* no level-1 vertex there, or a free one: the coarse field (+ a detail, below) */
            if (xid[n] < 0) { xid[n] = cut->nx; cut->xv[cut->nx++] = n; }
            cut->csub[27 * E + k] = xid[n];
            lid[k] = 8 + cut->cnx[E];
            cut->cx[SB_CUT_MAXX * E + cut->cnx[E]++] = xid[n];
        }
        /* the details: level-1 free vertices at the other non-corner points, locals after the extras; a child
         * corner there is the coarse field plus the detail (dlid), so the blocks above are not touched */
        for (k = 0; k < 27; k++) {
            int u[3] = {k % 3, k / 3 % 3, k / 9}, n;
            dlid[k] = -1;
            if (!(u[0] & 1) && !(u[1] & 1) && !(u[2] & 1)) continue;
            n = hv[(q0[0] + u[0]) + hn[0] * ((q0[1] + u[1]) + hn[1] * (q0[2] + u[2]))];
            if (n < 0 || n >= o2->nf) continue;
            if (did[n] < 0) { did[n] = cut->nd; cut->dv[cut->nd] = n; cut->dcell[cut->nd] = E; cut->dpoint[cut->nd] = k;
                for (j = 0; j < 3; j++) cut->dx[3 * cut->nd + j] = o2->x[3 * n + j];
                cut->nd++; }
            cut->dsub[27 * E + k] = did[n];
            dlid[k] = 8 + cut->cnx[E] + cut->cnd[E];
            cut->cd[SB_CUT_MAXX * E + cut->cnd[E]++] = did[n];
        }
        /* each child: W_c^T S_c W_c (the kept cell's, or the air element), mass alike */
        for (ch = 0; ch < 8; ch++) {
            int c0[3] = {ch & 1, ch >> 1 & 1, ch >> 2 & 1}, wl[8][9], nw[8];
            double ww[8][9];
            const double *Sc, *Mc;
            cc = hc[(q0[0] + c0[0]) + hn[0] * ((q0[1] + c0[1]) + hn[1] * (q0[2] + c0[2]))];
            Sc = cc >= 0 ? o2->Se + 576 * (size_t)cc : Sair;
            Mc = cc >= 0 ? o2->Me + 64 * (size_t)cc : Mair;
            for (a = 0; a < 8; a++) {
                int u[3] = {c0[0] + (a & 1), c0[1] + (a >> 1 & 1), c0[2] + (a >> 2 & 1)}, s = u[0] + 3 * u[1] + 9 * u[2];
                if (cc >= 0) {   /* the kept cell's corner a is at that point */
                    int q[3];
                    half_coords(o, o2, o2->cells[8 * cc + a], q);
                    if (q[0] != q0[0] + u[0] || q[1] != q0[1] + u[1] || q[2] != q0[2] + u[2]) { sb_fail("internal error: level 1's corner order"); goto done; }
                }
                nw[a] = 0;
                if (lid[s] >= 0) { wl[a][0] = lid[s]; ww[a][0] = 1; nw[a] = 1; continue; }   /* E's corner or an extra */
                for (b = 0; b < 8; b++) {   /* the coarse field there: dyadic weights, exact */
                    double w = 1;
                    for (k = 0; k < 3; k++) w *= (b >> k & 1) ? 0.5 * u[k] : 1 - 0.5 * u[k];
                    if (w != 0) { wl[a][nw[a]] = b; ww[a][nw[a]] = w; nw[a]++; }
                }
                if (dlid[s] >= 0) { wl[a][nw[a]] = dlid[s]; ww[a][nw[a]] = 1; nw[a]++; }   /* + the detail there (last) */
            }
            for (a = 0; a < 8; a++)
                for (b = 0; b < 8; b++)
                    for (i = 0; i < nw[a]; i++)
                        for (j = 0; j < nw[b]; j++) {
                            int la = wl[a][i], lb = wl[b][j], r, s2;
                            double w = ww[a][i] * ww[b][j];
                            ME[NL * la + lb] += w * Mc[8 * a + b];
                            for (r = 0; r < 3; r++)
                                for (s2 = 0; s2 < 3; s2++)
                                    KE[(size_t)N3 * (size_t)(3 * la + r) + (size_t)(3 * lb + s2)] += w * Sc[24 * (3 * a + r) + 3 * b + s2];
                        }
            if (cc < 0) cut->nair++; else cut->nlost--;   /* claimed by a kept level-0 cell */
        }
    }
    rc = 0;
done:
    free(hv); free(hc); free(xid); free(did); free(Sair); free(Mair);
    if (rc) sb_cut_free(cut);
    return rc;
}

void sb_cut_free(sb_cut *cut)
{
    free(cut->v1); free(cut->xv); free(cut->cnx); free(cut->cx); free(cut->csub); free(cut->K); free(cut->M);
    free(cut->dv); free(cut->dx); free(cut->dcell); free(cut->dpoint); free(cut->cnd); free(cut->cd); free(cut->dsub);
    memset(cut, 0, sizeof *cut);
}

#define GROWV(p, n) ((p) = realloc((p), (n)))
#define PERM(T, arr, w) do { T *t_ = sb_alloc(sizeof(T) * (size_t)(w) * (size_t)nv0); \
    for (i = 0; i < nv0; i++) memcpy(t_ + (size_t)(w) * (size_t)perm[i], (arr) + (size_t)(w) * (size_t)i, sizeof(T) * (size_t)(w)); \
    memcpy((arr), t_, sizeof(T) * (size_t)(w) * (size_t)nv0); free(t_); } while (0)
/* Level 1's skeleton at level 0's vertices too: a level-0 skeleton vertex that is free on level 1 (its thinner
 * bones) becomes an unknown, after level 0's free ones (their indices, and the rigs', stay), with level 1's frame */
static void repartition(const sb_desc *d, sb_model *o, const sb_model *o2, sb_cut *cut)
{
    const int nv0 = o->nv;
    int i, k, nf = o->nf, *perm = sb_alloc(sizeof(int) * (size_t)nv0), n = 0;
    for (i = 0; i < o->nf; i++) perm[i] = n++;
    for (i = o->nf; i < nv0; i++) if (cut->v1[i] >= 0 && cut->v1[i] < o2->nf) { perm[i] = n++; nf++; }
    for (i = o->nf; i < nv0; i++) if (!(cut->v1[i] >= 0 && cut->v1[i] < o2->nf)) perm[i] = n++;
    for (i = o->nf; i < nv0; i++)
        if (perm[i] < nf) { int n1 = cut->v1[i]; o->fb1[i] = o2->fb1[n1]; o->fb2[i] = o2->fb2[n1]; o->fw[i] = o2->fw[n1]; o->vseg[i] = -1; }
    PERM(int, o->v_grid, 1); PERM(double, o->x, 3); PERM(int, o->fb1, 1); PERM(int, o->fb2, 1); PERM(double, o->fw, 1);
    PERM(int, o->vseg, 1); PERM(int, cut->v1, 1);
    if (o->limit) PERM(double, o->limit, 1);
    for (i = 0; i < 8 * o->nc; i++) o->cells[i] = perm[o->cells[i]];
    for (i = 0; i < o->gn[0] * o->gn[1] * o->gn[2]; i++) if (o->gvert[i] >= 0) o->gvert[i] = perm[o->gvert[i]];
    if (o->vprof) {   /* the force profile of the new unknowns, by the description's rules (sb_force.c) */
        o->vprof = realloc(o->vprof, (size_t)nf);
        if (!o->vprof) abort();
        for (i = o->nf; i < nf; i++) {
            o->vprof[i] = 0;
            for (k = 0; k < d->nsr; k++) if (sb_region_has(o, &d->srules[k].r, o->x + 3 * i)) o->vprof[i] = (unsigned char)d->srules[k].prof;
        }
    }
    cut->nfreed = nf - o->nf;
    o->nf = nf;
    free(perm);
}

void sb_cut_apply(const sb_desc *d, sb_model *o, const sb_model *o2, sb_cut *cut)
{
    const int NL = SB_CUT_NL, N3 = 3 * SB_CUT_NL, nv0 = o->nv, nv = o->nv + cut->nx;
    int i, j, E, a, b, k, *map, *cnt, ne;
    repartition(d, o, o2, cut);
    GROWV(o->v_grid, sizeof(int) * (size_t)nv);
    GROWV(o->x, sizeof(double) * 3 * (size_t)nv);
    GROWV(o->fb1, sizeof(int) * (size_t)nv); GROWV(o->fb2, sizeof(int) * (size_t)nv); GROWV(o->fw, sizeof(double) * (size_t)nv);
    GROWV(o->vseg, sizeof(int) * (size_t)nv);
    if (o->limit) GROWV(o->limit, sizeof(double) * (size_t)nv);
    if (!o->v_grid || !o->x || !o->fb1 || !o->fb2 || !o->fw || !o->vseg) abort();   /* out of memory, as sb_alloc */
    for (i = 0; i < cut->nx; i++) {
        int n = cut->xv[i], v = nv0 + i;
        o->v_grid[v] = -1;
        for (k = 0; k < 3; k++) o->x[3 * v + k] = o2->x[3 * n + k];
        o->fb1[v] = o2->fb1[n]; o->fb2[v] = o2->fb2[n]; o->fw[v] = 0;
        o->vseg[v] = o2->vseg[n];
        if (o->limit) o->limit[v] = 0;
    }
    o->nv = nv;
    /* the pattern: vertices sharing a cut element (corners and extras) */
    map = sb_alloc(sizeof(int) * (size_t)nv * (size_t)nv);
    cnt = sb_alloc(sizeof(int) * (size_t)nv);
    for (i = 0; i < nv * nv; i++) map[i] = -1;
    for (E = 0; E < o->nc; E++) {
        int vl[SB_CUT_NL], nl = 8 + cut->cnx[E];
        for (a = 0; a < 8; a++) vl[a] = o->cells[8 * E + a];
        for (a = 0; a < cut->cnx[E]; a++) vl[8 + a] = nv0 + cut->cx[SB_CUT_MAXX * E + a];
        for (a = 0; a < nl; a++) for (b = 0; b < nl; b++) map[(size_t)vl[a] * (size_t)nv + (size_t)vl[b]] = 0;
    }
    free(o->nbptr); free(o->nb); free(o->M); free(o->S); free(o->T);
    o->nbptr = sb_alloc(sizeof(int) * (size_t)(nv + 1));
    for (i = 0; i < nv; i++) {
        for (j = 0; j < nv; j++) if (map[(size_t)i * (size_t)nv + (size_t)j] >= 0) cnt[i]++;
        o->nbptr[i + 1] = o->nbptr[i] + cnt[i];
    }
    ne = o->nbptr[nv];
    o->nb = sb_alloc(sizeof(int) * (size_t)ne);
    o->M = sb_alloc(sizeof(double) * (size_t)ne);
    o->S = sb_alloc(sizeof(double) * 9 * (size_t)ne);
    o->T = sb_alloc(sizeof(double) * (size_t)ne);
    for (i = 0, k = 0; i < nv; i++)
        for (j = 0; j < nv; j++)
            if (map[(size_t)i * (size_t)nv + (size_t)j] >= 0) { map[(size_t)i * (size_t)nv + (size_t)j] = k; o->nb[k++] = j; }
    o->mass = 0;
    for (E = 0; E < o->nc; E++) {
        int vl[SB_CUT_NL], nl = 8 + cut->cnx[E], r, s;
        const double *KE = cut->K + (size_t)(N3 * N3) * (size_t)E, *ME = cut->M + (size_t)(NL * NL) * (size_t)E;
        double *Se = o->Se + 576 * (size_t)E;
        for (a = 0; a < 8; a++) vl[a] = o->cells[8 * E + a];
        for (a = 0; a < cut->cnx[E]; a++) vl[8 + a] = nv0 + cut->cx[SB_CUT_MAXX * E + a];
        for (a = 0; a < nl; a++)
            for (b = 0; b < nl; b++) {
                int e = map[(size_t)vl[a] * (size_t)nv + (size_t)vl[b]];
                o->M[e] += ME[NL * a + b];
                o->mass += ME[NL * a + b];
                for (r = 0; r < 3; r++) for (s = 0; s < 3; s++) o->S[9 * (size_t)e + (size_t)(3 * r + s)] += KE[(size_t)N3 * (size_t)(3 * a + r) + (size_t)(3 * b + s)];
            }
        for (r = 0; r < 24; r++) for (s = 0; s < 24; s++) Se[24 * r + s] = KE[(size_t)N3 * (size_t)r + (size_t)s];
    }
    free(map); free(cnt);
    free(o->Me); o->Me = NULL;
    o->cut = cut; o->cut_nv0 = nv0;
}
