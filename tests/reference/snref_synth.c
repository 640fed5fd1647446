/* snref_synth.c -- synthetic box-lattice blobs with textbook hex elements. */
#include "snref_synth.h"
#include "snref.h"
#include "../../runtime/src/sn_format.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Solve n x n system A X = B (m right-hand sides, column-major in B rows) by
 * Gauss-Jordan with partial pivoting; A, B row-major, B is n x m. */
static int gj_solve(double *A, double *B, int n, int m) {
    int i, j, k;
    for (k = 0; k < n; k++) {
        int p = k;
        for (i = k + 1; i < n; i++) if (fabs(A[i * n + k]) > fabs(A[p * n + k])) p = i;
        if (A[p * n + k] == 0) return -1;
        if (p != k) {
            for (j = 0; j < n; j++) { double t = A[k * n + j]; A[k * n + j] = A[p * n + j]; A[p * n + j] = t; }
            for (j = 0; j < m; j++) { double t = B[k * m + j]; B[k * m + j] = B[p * m + j]; B[p * m + j] = t; }
        }
        for (i = 0; i < n; i++) {
            double l;
            if (i == k) continue;
            l = A[i * n + k] / A[k * n + k];
            for (j = 0; j < n; j++) A[i * n + j] -= l * A[k * n + j];
            for (j = 0; j < m; j++) B[i * m + j] -= l * B[k * m + j];
        }
    }
    for (k = 0; k < n; k++) for (j = 0; j < m; j++) B[k * m + j] /= A[k * n + k];
    return 0;
}

/* Strain rows (Voigt: xx yy zz xy yz xz, engineering shear) of one scalar
 * shape function gradient g for displacement component c: B[row] */
static void bcol(const double g[3], int c, double out[6]) {
    memset(out, 0, 6 * sizeof *out);
    out[c] = g[c];
    if (c == 0) { out[3] = g[1]; out[5] = g[2]; }
    if (c == 1) { out[3] = g[0]; out[4] = g[2]; }
    if (c == 2) { out[4] = g[1]; out[5] = g[0]; }
}

static double dmul(const double a[6], const double b[6], double lam, double mu, int part) {
    /* a^T D b with D = lam m m^T + mu diag(2,2,2,1,1,1); part 1: lam only, 2: mu only, 3: both */
    double r = 0;
    if (part & 1) r += lam * (a[0] + a[1] + a[2]) * (b[0] + b[1] + b[2]);
    if (part & 2) r += mu * (2 * (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]);
    return r;
}

void snsyn_hex(double dx, double dy, double dz, double lam, double mu, int integ,
               double Ke[24][24], double Me[8][8]) {
    const double gp = 1.0 / sqrt(3.0);
    const double sz[3] = { dx, dy, dz };
    double Kaa[81], Kua[24 * 9];
    int a, b, i, j, q;
    memset(Ke, 0, sizeof(double) * 576);
    memset(Me, 0, sizeof(double) * 64);
    memset(Kaa, 0, sizeof Kaa);
    memset(Kua, 0, sizeof Kua);
    for (q = 0; q < 9; q++) {
        /* q < 8: 2x2x2 Gauss points (weight 1 each); q == 8: centre point (weight 8) */
        double xi[3], wq, detJ = dx * dy * dz / 8.0;
        double N[8], G[8][3], Ginc[3][3];
        int part;
        if (q < 8) {
            xi[0] = (q & 1) ? gp : -gp; xi[1] = (q >> 1 & 1) ? gp : -gp; xi[2] = (q >> 2 & 1) ? gp : -gp;
            wq = 1.0;
            part = integ == SNSYN_SRI_VOL ? 2 : 3;
        } else {
            if (integ != SNSYN_SRI_VOL) break;
            xi[0] = xi[1] = xi[2] = 0; wq = 8.0; part = 1;
        }
        for (a = 0; a < 8; a++) {
            double s[3];
            for (i = 0; i < 3; i++) s[i] = (a >> i & 1) ? 1.0 : -1.0;
            N[a] = 0.125 * (1 + s[0] * xi[0]) * (1 + s[1] * xi[1]) * (1 + s[2] * xi[2]);
            G[a][0] = 0.125 * s[0] * (1 + s[1] * xi[1]) * (1 + s[2] * xi[2]) * 2.0 / sz[0];
            G[a][1] = 0.125 * s[1] * (1 + s[0] * xi[0]) * (1 + s[2] * xi[2]) * 2.0 / sz[1];
            G[a][2] = 0.125 * s[2] * (1 + s[0] * xi[0]) * (1 + s[1] * xi[1]) * 2.0 / sz[2];
        }
        if (q < 8)
            for (a = 0; a < 8; a++) for (b = 0; b < 8; b++) Me[a][b] += N[a] * N[b] * detJ * wq;
        for (a = 0; a < 8; a++)
            for (i = 0; i < 3; i++) {
                double Ba[6];
                bcol(G[a], i, Ba);
                for (b = 0; b < 8; b++)
                    for (j = 0; j < 3; j++) {
                        double Bb[6];
                        bcol(G[b], j, Bb);
                        Ke[3 * a + i][3 * b + j] += dmul(Ba, Bb, lam, mu, part) * detJ * wq;
                    }
            }
        if (integ == SNSYN_INCOMPATIBLE && q < 8) {
            /* bubble P_k = 1 - xi_k^2, gradient only along k */
            int k, kk, c, cc;
            memset(Ginc, 0, sizeof Ginc);
            for (k = 0; k < 3; k++) Ginc[k][k] = -2.0 * xi[k] * 2.0 / sz[k];
            for (k = 0; k < 3; k++)
                for (c = 0; c < 3; c++) {
                    double Bi[6];
                    bcol(Ginc[k], c, Bi);
                    for (kk = 0; kk < 3; kk++)
                        for (cc = 0; cc < 3; cc++) {
                            double Bj[6];
                            bcol(Ginc[kk], cc, Bj);
                            Kaa[(3 * k + c) * 9 + 3 * kk + cc] += dmul(Bi, Bj, lam, mu, 3) * detJ;
                        }
                    for (a = 0; a < 8; a++)
                        for (i = 0; i < 3; i++) {
                            double Ba[6];
                            bcol(G[a], i, Ba);
                            Kua[(3 * a + i) * 9 + 3 * k + c] += dmul(Ba, Bi, lam, mu, 3) * detJ;
                        }
                }
        }
    }
    if (integ == SNSYN_INCOMPATIBLE) {
        /* static condensation K = Kuu - Kua Kaa^-1 Kau */
        double X[9 * 24], A[81];
        memcpy(A, Kaa, sizeof A);
        for (i = 0; i < 9; i++) for (j = 0; j < 24; j++) X[i * 24 + j] = Kua[j * 9 + i];
        gj_solve(A, X, 9, 24);
        for (a = 0; a < 24; a++)
            for (b = 0; b < 24; b++) {
                double t = 0;
                for (i = 0; i < 9; i++) t += Kua[a * 9 + i] * X[i * 24 + b];
                Ke[a][b] -= t;
            }
        for (a = 0; a < 24; a++)   /* symmetrize round-off */
            for (b = a + 1; b < 24; b++) Ke[a][b] = Ke[b][a] = 0.5 * (Ke[a][b] + Ke[b][a]);
    }
}

/* ---------------- blob writer ---------------- */

typedef struct { unsigned char *d; size_t n, cap; int fl; } wbuf;

static void w_grow(wbuf *w, size_t need) {
    if (need <= w->cap) return;
    while (w->cap < need) w->cap = w->cap ? 2 * w->cap : 4096;
    w->d = realloc(w->d, w->cap);
}
static void w_u8(wbuf *w, size_t at, unsigned v) { w_grow(w, at + 1); w->d[at] = (unsigned char)v; }
static void w_u16(wbuf *w, size_t at, unsigned v) { w_u8(w, at, v & 255u); w_u8(w, at + 1, v >> 8 & 255u); }
static void w_u32(wbuf *w, size_t at, uint32_t v) { w_u16(w, at, v & 0xFFFFu); w_u16(w, at + 2, v >> 16); }
static void w_real(wbuf *w, size_t at, double v) {
    if (w->fl == SN_FLAVOUR_FLOAT32) { float f = (float)v; uint32_t u; memcpy(&u, &f, 4); w_u32(w, at, u); }
    else { uint64_t u; memcpy(&u, &v, 8); w_u32(w, at, (uint32_t)u); w_u32(w, at + 4, (uint32_t)(u >> 32)); }
}

unsigned char *snsyn_build(const snsyn_box *bx, size_t *size) {
    unsigned NX = bx->nx + 1, NY = bx->ny + 1, NZ = bx->nz + 1, nV = NX * NY * NZ, nF = 0, nC, i, k;
    unsigned *newid, *gid_of, nJ = bx->two_joints ? 2u : 1u, nnz = 0;
    double lam = bx->E * bx->nu / ((1 + bx->nu) * (1 - 2 * bx->nu)), mu = bx->E / (2 * (1 + bx->nu));
    double Ke[24][24], Me[8][8], *S, *M, m0 = 0, U = 1, root[3], tip[3], h2 = bx->h * bx->h;
    int len_shift = 0;
    unsigned R = bx->flavour == SN_FLAVOUR_FLOAT32 ? 4u : 8u;
    wbuf w = { 0, 0, 0, 0 };
    size_t off[SN_SEC_COUNT], cnt[SN_SEC_COUNT], el[SN_SEC_COUNT], pos;
    nC = bx->nx * bx->ny * bx->nz;
    if (nV > SN_MAX_VERTICES) return NULL;
    w.fl = bx->flavour;
#define GID(ix, iy, iz) ((ix) + NX * ((iy) + NY * (iz)))
    /* blocks S, M per (vertex, neighbour offset 0..26) */
    S = calloc((size_t)nV * 27 * 9, sizeof *S);
    M = calloc((size_t)nV * 27, sizeof *M);
    newid = malloc(nV * sizeof *newid);
    gid_of = malloc(nV * sizeof *gid_of);
    snsyn_hex(bx->dx, bx->dy, bx->dz, lam, mu, bx->integration, Ke, Me);
    {
        unsigned cx, cy, cz, a, b2, ii, jj;
        for (cz = 0; cz < bx->nz; cz++) for (cy = 0; cy < bx->ny; cy++) for (cx = 0; cx < bx->nx; cx++)
            for (a = 0; a < 8; a++) for (b2 = 0; b2 < 8; b2++) {
                unsigned ga = GID(cx + (a & 1), cy + (a >> 1 & 1), cz + (a >> 2 & 1));
                int ox = (int)(b2 & 1) - (int)(a & 1), oy = (int)(b2 >> 1 & 1) - (int)(a >> 1 & 1),
                    oz = (int)(b2 >> 2 & 1) - (int)(a >> 2 & 1);
                unsigned o = (unsigned)((ox + 1) + 3 * ((oy + 1) + 3 * (oz + 1)));
                M[ga * 27 + o] += bx->rho * Me[a][b2];
                for (ii = 0; ii < 3; ii++) for (jj = 0; jj < 3; jj++) S[(ga * 27 + o) * 9 + 3 * ii + jj] += Ke[3 * a + ii][3 * b2 + jj];
            }
    }
    /* ordering: free first (in grid order), then skeleton */
    for (i = 0; i < nV; i++) {
        unsigned ix = i % NX;
        int skel = ix == 0 || (bx->two_joints && ix == bx->nx);
        if (!skel) { newid[i] = nF; gid_of[nF++] = i; }
    }
    k = nF;
    for (i = 0; i < nV; i++) {
        unsigned ix = i % NX;
        if (ix == 0) { newid[i] = k; gid_of[k++] = i; }
    }
    if (bx->two_joints)
        for (i = 0; i < nV; i++)
            if (i % NX == bx->nx) { newid[i] = k; gid_of[k++] = i; }
    root[0] = 0; root[1] = 0.5 * bx->ny * bx->dy; root[2] = 0.5 * bx->nz * bx->dz;
    tip[0] = bx->nx * bx->dx; tip[1] = root[1]; tip[2] = root[2];
    for (i = 0; i < nV; i++) {
        double x[3];
        x[0] = (i % NX) * bx->dx - root[0]; x[1] = (i / NX % NY) * bx->dy - root[1]; x[2] = (i / NX / NY) * bx->dz - root[2];
        for (k = 0; k < 3; k++) while (fabs(x[k]) >= 2 * U) { U *= 2; len_shift++; }
        if (M[i * 27 + 13] > m0) m0 = M[i * 27 + 13];
    }
    /* count off-diagonal blocks of free rows: neighbours with larger new id */
    {
        unsigned *rowptr = calloc(nF + 1, sizeof *rowptr);
        unsigned *cols = NULL;
        double *moff = NULL;
        size_t cap = 0;
        for (i = 0; i < nF; i++) {
            unsigned g = gid_of[i], ix = g % NX, iy = g / NX % NY, iz = g / NX / NY, o, list[27], lo[27], nl = 0, a, b2;
            for (o = 0; o < 27; o++) {
                int ox = (int)(o % 3) - 1, oy = (int)(o / 3 % 3) - 1, oz = (int)(o / 9) - 1;
                int jx = (int)ix + ox, jy = (int)iy + oy, jz = (int)iz + oz;
                unsigned gj, nj;
                if (o == 13 || jx < 0 || jy < 0 || jz < 0 || jx >= (int)NX || jy >= (int)NY || jz >= (int)NZ) continue;
                if (M[g * 27 + o] == 0) continue;    /* no shared cell */
                gj = GID((unsigned)jx, (unsigned)jy, (unsigned)jz); nj = newid[gj];
                if (nj <= i) continue;
                list[nl] = nj; lo[nl++] = o;
            }
            for (a = 1; a < nl; a++)          /* insertion sort by column */
                for (b2 = a; b2 > 0 && list[b2 - 1] > list[b2]; b2--) {
                    unsigned t = list[b2]; list[b2] = list[b2 - 1]; list[b2 - 1] = t;
                    t = lo[b2]; lo[b2] = lo[b2 - 1]; lo[b2 - 1] = t;
                }
            if (nnz + nl > cap) {
                cap = 2 * (nnz + nl) + 64;
                cols = realloc(cols, cap * sizeof *cols); moff = realloc(moff, cap * sizeof *moff);
            }
            for (a = 0; a < nl; a++) {
                cols[nnz] = list[a];
                moff[nnz] = M[g * 27 + lo[a]] / m0;
                nnz++;
            }
            rowptr[i + 1] = nnz;
        }
        /* layout */
        cnt[SN_SEC_JOINTS] = nJ; el[SN_SEC_JOINTS] = SN_ELEM_JOINTS(R);
        cnt[SN_SEC_JOINT_NAMES] = nJ; el[SN_SEC_JOINT_NAMES] = SN_ELEM_JOINT_NAMES;
        cnt[SN_SEC_REST] = nV; el[SN_SEC_REST] = SN_ELEM_REST(R);
        cnt[SN_SEC_FRAMES] = nV; el[SN_SEC_FRAMES] = SN_ELEM_FRAMES;
        cnt[SN_SEC_MDIAG] = nF; el[SN_SEC_MDIAG] = SN_ELEM_MDIAG(R);
        cnt[SN_SEC_PRECOND] = nF; el[SN_SEC_PRECOND] = SN_ELEM_PRECOND(R);
        cnt[SN_SEC_MLUMP] = nF; el[SN_SEC_MLUMP] = SN_ELEM_MLUMP(R);
        cnt[SN_SEC_ROWPTR] = nF + 1; el[SN_SEC_ROWPTR] = SN_ELEM_ROWPTR;
        cnt[SN_SEC_COLS] = nnz; el[SN_SEC_COLS] = SN_ELEM_COLS;
        cnt[SN_SEC_MOFF] = nnz; el[SN_SEC_MOFF] = SN_ELEM_MOFF(R);
        cnt[SN_SEC_CELLS] = nC; el[SN_SEC_CELLS] = SN_ELEM_CELLS;
        cnt[SN_SEC_CFRAMES] = nC; el[SN_SEC_CFRAMES] = SN_ELEM_CFRAMES;
        cnt[SN_SEC_CELLK] = nC; el[SN_SEC_CELLK] = SN_ELEM_CELLK(SN_FLAVOUR_FLOAT32, R);
        cnt[SN_SEC_LIMIT] = bx->limit > 0 ? nF : 0; el[SN_SEC_LIMIT] = SN_ELEM_LIMIT(R);
        cnt[SN_SEC_EMBED] = nV; el[SN_SEC_EMBED] = SN_ELEM_EMBED;   /* surface = every lattice vertex */
        cnt[SN_SEC_TRIS] = 0; el[SN_SEC_TRIS] = SN_ELEM_TRIS;
        /* format 3.0: no rigs here (snsyn_with_rigs adds them) */
        cnt[SN_SEC_CONTROLS] = 0; el[SN_SEC_CONTROLS] = SN_ELEM_CONTROLS(R);
        cnt[SN_SEC_RIGS] = 0; el[SN_SEC_RIGS] = SN_ELEM_RIGS;
        cnt[SN_SEC_RIG_SAMPLES] = 0; el[SN_SEC_RIG_SAMPLES] = SN_ELEM_RIG_SAMPLES(R);
        cnt[SN_SEC_RIG_VERTS] = 0; el[SN_SEC_RIG_VERTS] = SN_ELEM_RIG_VERTS;
        cnt[SN_SEC_RIG_FORCES] = 0; el[SN_SEC_RIG_FORCES] = SN_ELEM_RIG_FORCES(R);
        /* format 4.0: no force profiles or segment meshes */
        cnt[SN_SEC_SHARES] = 0; el[SN_SEC_SHARES] = SN_ELEM_SHARES(R);
        cnt[SN_SEC_VSHARE] = 0; el[SN_SEC_VSHARE] = SN_ELEM_VSHARE;
        cnt[SN_SEC_SEGMESH] = 0; el[SN_SEC_SEGMESH] = SN_ELEM_SEGMESH(R);
        cnt[SN_SEC_SEGNODES] = 0; el[SN_SEC_SEGNODES] = SN_ELEM_SEGNODES(R);
        cnt[SN_SEC_SEGATTACH] = 0; el[SN_SEC_SEGATTACH] = SN_ELEM_SEGATTACH(R);
        cnt[SN_SEC_CONSTRAINTS] = 0; el[SN_SEC_CONSTRAINTS] = SN_ELEM_CONSTRAINTS;
        /* format 5.0: no crease sections */
        cnt[SN_SEC_CREASE] = 0; el[SN_SEC_CREASE] = SN_ELEM_CREASE(R);
        cnt[SN_SEC_CREASE_PAIRS] = 0; el[SN_SEC_CREASE_PAIRS] = SN_ELEM_CREASE_PAIRS;
        cnt[SN_SEC_CREASE_VNBR] = 0; el[SN_SEC_CREASE_VNBR] = SN_ELEM_CREASE_VNBR;
        cnt[SN_SEC_CREASE_TNBR] = 0; el[SN_SEC_CREASE_TNBR] = SN_ELEM_CREASE_TNBR;
        cnt[SN_SEC_LEVEL_BLOB] = 0; el[SN_SEC_LEVEL_BLOB] = SN_ELEM_LEVEL_BLOB;   /* format 6.0: one level */
        cnt[SN_SEC_LEVEL_UP] = 0; el[SN_SEC_LEVEL_UP] = SN_ELEM_LEVEL_MAP;
        cnt[SN_SEC_LEVEL_DOWN] = 0; el[SN_SEC_LEVEL_DOWN] = SN_ELEM_LEVEL_MAP;
        cnt[SN_SEC_ICHOL] = 0; el[SN_SEC_ICHOL] = SN_ELEM_ICHOL;   /* format 6.0: block Jacobi */
        cnt[SN_SEC_ADAPT] = 0; el[SN_SEC_ADAPT] = SN_ELEM_ADAPT(R); /* format 6.1: no adaptation */
        cnt[SN_SEC_CELLX] = 0; el[SN_SEC_CELLX] = SN_ELEM_CELLX;   /* format 6.3: not a cut level */
        cnt[SN_SEC_CELLXK] = 0; el[SN_SEC_CELLXK] = SN_ELEM_CELLXK(SN_FLAVOUR_FLOAT32, R);
        cnt[SN_SEC_FPAIRS] = 0; el[SN_SEC_FPAIRS] = SN_ELEM_FPAIRS; /* format 6.4: every frame slerped alone */
        cnt[SN_SEC_FREFS] = 0; el[SN_SEC_FREFS] = SN_ELEM_FREFS;
        cnt[SN_SEC_DETAILS] = 0; el[SN_SEC_DETAILS] = SN_ELEM_DETAILS(R);   /* format 6.5: no details */
        cnt[SN_SEC_DETAIL] = 0; el[SN_SEC_DETAIL] = SN_ELEM_DETAIL(R);
        cnt[SN_SEC_CELLD] = 0; el[SN_SEC_CELLD] = SN_ELEM_CELLD;
        cnt[SN_SEC_CELLDK] = 0; el[SN_SEC_CELLDK] = SN_ELEM_CELLDK(SN_FLAVOUR_FLOAT32, R);
        pos = SN_HEADER_BYTES;
        for (k = 0; k < SN_SEC_COUNT; k++) {
            pos = (pos + 7) & ~(size_t)7;
            off[k] = pos;
            pos += cnt[k] * el[k];
        }
        pos = (pos + 7) & ~(size_t)7;
        w_grow(&w, pos);
        memset(w.d, 0, pos);
        w.n = pos;
        w.d[0] = SN_MAGIC0; w.d[1] = SN_MAGIC1; w.d[2] = SN_MAGIC2; w.d[3] = SN_MAGIC3;
        w_u16(&w, SN_H_VER_MAJOR, SN_FORMAT_MAJOR); w_u16(&w, SN_H_VER_MINOR, SN_FORMAT_MINOR);
        w_u32(&w, SN_H_ENDIAN, SN_ENDIAN_MARK);
        w_u32(&w, SN_H_TOTAL_SIZE, (uint32_t)pos); w_u32(&w, SN_H_HEADER_SIZE, SN_HEADER_BYTES);
        w_u8(&w, SN_H_FLAVOUR, (unsigned)bx->flavour); w_u8(&w, SN_H_REAL_SIZE, R); w_u8(&w, SN_H_NSECTIONS, SN_SEC_COUNT);
        w_u8(&w, SN_H_FLAGS, bx->rest_modelled ? SN_FLAG_REST_MODELLED : 0u);
        w_u32(&w, SN_H_ONE, bx->flavour == SN_FLAVOUR_FLOAT32 ? SN_ONE_FLOAT32 : 0u);
        w_u32(&w, SN_H_ONE_HI, bx->flavour == SN_FLAVOUR_FLOAT64 ? SN_ONE_FLOAT64_HI : 0u);
        w_u32(&w, SN_H_N_VERTICES, nV); w_u32(&w, SN_H_N_FREE, nF); w_u32(&w, SN_H_N_CELLS, nC);
        w_u32(&w, SN_H_N_JOINTS, nJ); w_u32(&w, SN_H_N_SURFACE, nV); w_u32(&w, SN_H_N_TRIANGLES, 0);
        w_u32(&w, SN_H_N_OFFDIAG, nnz); w_u32(&w, SN_H_INSTANCE_BYTES, SN_INSTANCE_BYTES(nV, nF, nJ, nC, 0, 0, 0, 0));
        w_u16(&w, SN_H_CG_DEFAULT, bx->cg_default); w_u16(&w, SN_H_CG_MAX, 256);
        w_u8(&w, SN_H_LEN_SHIFT, (unsigned)(len_shift & 255));
        {
            size_t rp = SN_H_REALS;
            w_real(&w, rp + SN_R_A1 * R, bx->h * bx->alpha);
            w_real(&w, rp + SN_R_B1 * R, bx->beta / bx->h);
            for (k = 0; k < 3; k++) w_real(&w, rp + (SN_R_GRAV_X + k) * R, h2 * bx->g[k] / U);
            w_real(&w, rp + SN_R_TIMESTEP * R, bx->h);
            w_real(&w, rp + SN_R_MASS_SCALE * R, m0);
            w_real(&w, rp + SN_R_ENERGY * R, m0 * U * U / h2);          /* mesh unit = 1 m */
            w_real(&w, rp + SN_R_CELL * R, bx->dx / U);
            w_real(&w, rp + SN_R_DISP_BOUND * R, bx->disp_bound > 0 ? bx->disp_bound : 1.0);
            w_real(&w, rp + SN_R_FORCE * R, h2 / (m0 * U));              /* mesh unit = 1 m */
        }
        for (k = 0; k < SN_SEC_COUNT; k++) {
            size_t e = SN_H_SECTIONS + k * SN_SECTION_ENTRY;
            w_u32(&w, e, (uint32_t)off[k]); w_u32(&w, e + 4, (uint32_t)(cnt[k] * el[k]));
            w_u32(&w, e + 8, (uint32_t)cnt[k]); w_u32(&w, e + 12, (uint32_t)el[k]);
        }
        for (k = 0; k < nJ; k++) {
            size_t e = off[SN_SEC_JOINTS] + k * SN_ELEM_JOINTS(R);
            w_u16(&w, e, k == 0 ? 0xFFFFu : 0u);
            w_real(&w, e + 8, k == 0 ? 0.0 : (tip[0] - root[0]) / U);
            w_real(&w, e + 8 + R, 0.0); w_real(&w, e + 8 + 2 * R, 0.0);
            memcpy(w.d + off[SN_SEC_JOINT_NAMES] + 32 * k, k == 0 ? "root" : "tip", k == 0 ? 4 : 3);
        }
        for (i = 0; i < nV; i++) {
            unsigned g = gid_of[i], ix = g % NX;
            double x[3];
            size_t e = off[SN_SEC_FRAMES] + 4 * i;
            x[0] = ix * bx->dx - root[0]; x[1] = (g / NX % NY) * bx->dy - root[1]; x[2] = (g / NX / NY) * bx->dz - root[2];
            for (k = 0; k < 3; k++) w_real(&w, off[SN_SEC_REST] + (3 * i + k) * R, x[k] / U);
            if (bx->two_joints && i >= nF && ix == bx->nx) { w_u8(&w, e, 1); w_u8(&w, e + 1, 1); w_u16(&w, e + 2, 0); }
            else if (bx->two_joints && i < nF) {
                w_u8(&w, e, 0); w_u8(&w, e + 1, 1); w_u16(&w, e + 2, (unsigned)lround(32768.0 * ix / bx->nx));
            } else { w_u8(&w, e, 0); w_u8(&w, e + 1, 0); w_u16(&w, e + 2, 0); }
            /* surface vertex i sits at lattice vertex i: a cell containing it and its corner */
            {
                unsigned iy = g / NX % NY, iz = g / NX / NY;
                unsigned cx = ix < bx->nx ? ix : ix - 1, cy = iy < bx->ny ? iy : iy - 1, cz = iz < bx->nz ? iz : iz - 1;
                size_t ee = off[SN_SEC_EMBED] + 8 * i;
                w_u16(&w, ee, cx + bx->nx * (cy + bx->ny * cz));
                w_u16(&w, ee + 2, ix - cx ? 32768u : 0u); w_u16(&w, ee + 4, iy - cy ? 32768u : 0u);
                w_u16(&w, ee + 6, iz - cz ? 32768u : 0u);
            }
        }
        for (i = 0; i < nF; i++) {
            unsigned g = gid_of[i], ix = g % NX, iy = g / NX % NY, iz = g / NX / NY, o;
            double Sd[9], P[9], A[9], lump = 0, md = M[g * 27 + 13] / m0;
            static const int sym[6][2] = { { 0, 0 }, { 1, 1 }, { 2, 2 }, { 0, 1 }, { 0, 2 }, { 1, 2 } };
            for (k = 0; k < 9; k++) Sd[k] = h2 * S[(g * 27 + 13) * 9 + k] / m0;
            for (o = 0; o < 27; o++) {
                int jx = (int)ix + (int)(o % 3) - 1, jy = (int)iy + (int)(o / 3 % 3) - 1, jz = (int)iz + (int)(o / 9) - 1;
                if (jx < 0 || jy < 0 || jz < 0 || jx >= (int)NX || jy >= (int)NY || jz >= (int)NZ) continue;
                lump += M[g * 27 + o] / m0;
            }
            for (k = 0; k < 9; k++) { A[k] = (1 + bx->beta / bx->h) * Sd[k]; P[k] = 0; }
            for (k = 0; k < 3; k++) A[4 * k] += (1 + bx->h * bx->alpha) * md;
            for (k = 0; k < 9; k++) P[k] = (k % 4 == 0) ? 1.0 : 0.0;
            gj_solve(A, P, 3, 3);
            w_real(&w, off[SN_SEC_MDIAG] + i * R, md);
            w_real(&w, off[SN_SEC_MLUMP] + i * R, lump);
            for (k = 0; k < 6; k++) w_real(&w, off[SN_SEC_PRECOND] + (6 * i + k) * R, P[3 * sym[k][0] + sym[k][1]]);
            if (bx->limit > 0) w_real(&w, off[SN_SEC_LIMIT] + i * R, bx->limit / U);
        }
        for (i = 0; i <= nF; i++) w_u32(&w, off[SN_SEC_ROWPTR] + 4 * i, rowptr[i]);
        for (i = 0; i < nnz; i++) {
            w_u16(&w, off[SN_SEC_COLS] + 2 * i, cols[i]);
            w_real(&w, off[SN_SEC_MOFF] + i * R, moff[i]);
        }
        {
            unsigned cx, cy, cz, a, c = 0;
            for (cz = 0; cz < bx->nz; cz++) for (cy = 0; cy < bx->ny; cy++) for (cx = 0; cx < bx->nx; cx++, c++) {
                size_t cf = off[SN_SEC_CFRAMES] + SN_ELEM_CFRAMES * c, ck = off[SN_SEC_CELLK] + SN_ELEM_CELLK(SN_FLAVOUR_FLOAT32, R) * c;
                unsigned b2, blk = 0, q;
                for (a = 0; a < 8; a++)
                    w_u16(&w, off[SN_SEC_CELLS] + 16 * c + 2 * a,
                          newid[GID(cx + (a & 1), cy + (a >> 1 & 1), cz + (a >> 2 & 1))]);
                /* cell frame: root -> tip blended at the cell centre, as the free vertices are */
                w_u8(&w, cf, 0); w_u8(&w, cf + 1, bx->two_joints ? 1u : 0u);
                w_u16(&w, cf + 2, bx->two_joints ? (unsigned)lround(32768.0 * (cx + 0.5) / bx->nx) : 0u);
                /* S^_e = h^2 Ke / m0, upper blocks (a <= b) in order */
                for (a = 0; a < 8; a++)
                    for (b2 = a; b2 < 8; b2++, blk++)
                        for (q = 0; q < 9; q++)
                            w_real(&w, ck + (9 * blk + q) * R, h2 * Ke[3 * a + q / 3][3 * b2 + q % 3] / m0);
            }
        }
        free(rowptr); free(cols); free(moff);
    }
    w_u32(&w, SN_H_CRC32, snref_crc32(w.d + 16, w.n - 16));
    free(S); free(M); free(newid); free(gid_of);
    *size = w.n;
    return w.d;
#undef GID
}

/* ---------------- rig sections (format 3.0) ---------------- */

static uint32_t rs_u32(const unsigned char *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static void ws_u32(unsigned char *p, uint32_t v) { p[0] = (unsigned char)v; p[1] = (unsigned char)(v >> 8); p[2] = (unsigned char)(v >> 16); p[3] = (unsigned char)(v >> 24); }
static void ws_u16(unsigned char *p, unsigned v) { p[0] = (unsigned char)v; p[1] = (unsigned char)(v >> 8); }
/* one real of the flavour; fixed: round(x 2^q) to nearest (ties away from zero), clamped to int32 */
static void ws_real(unsigned char *p, int flavour, double x, int q) {
    if (flavour == SN_FLAVOUR_FIXED) {
        double v = ldexp(x, q);
        int64_t iv;
        v = v < 0 ? -floor(-v + 0.5) : floor(v + 0.5);
        if (v > 2147483647.0) v = 2147483647.0;
        if (v < -2147483648.0) v = -2147483648.0;
        iv = (int64_t)v;
        ws_u32(p, (uint32_t)iv);
    } else if (flavour == SN_FLAVOUR_FLOAT32) {
        float f = (float)x;
        uint32_t u;
        memcpy(&u, &f, 4);
        ws_u32(p, u);
    } else {
        uint64_t u;
        memcpy(&u, &x, 8);
        ws_u32(p, (uint32_t)u); ws_u32(p + 4, (uint32_t)(u >> 32));
    }
}

int snsyn_rig_frac(double maxabs) {
    int f = 30;
    if (maxabs > 0) f = (int)floor(log2(134217728.0 / maxabs));
    if (f < SN_RIG_FRAC_MIN) f = SN_RIG_FRAC_MIN;
    if (f > SN_RIG_FRAC_MAX) f = SN_RIG_FRAC_MAX;
    return f;
}

unsigned char *snsyn_with_rigs(const unsigned char *blob, size_t size, const snsyn_control *ctl, unsigned nk,
                               const snsyn_rig *rig, unsigned nr, size_t *out_size) {
    unsigned R, k, a, i, ns = 0, ne = 0;
    int flavour;
    size_t end, off[SN_SEC_COUNT], cnt[SN_SEC_COUNT], el[SN_SEC_COUNT], pos;
    unsigned char *o;
    uint32_t ib;
    if (size < SN_HEADER_BYTES || blob[SN_H_NSECTIONS] != SN_SEC_COUNT) return NULL;
    flavour = blob[SN_H_FLAVOUR];
    R = blob[SN_H_REAL_SIZE];
    for (a = 0; a < nr; a++) {
        if (rig[a].control >= nk || rig[a].n_samples < 1 || rig[a].n_samples > SN_RIG_MAX_SAMPLES) return NULL;
        ns += rig[a].n_samples; ne += rig[a].n_entries;
    }
    {   /* end of TRIS: the rig sections follow it */
        const unsigned char *e = blob + SN_H_SECTIONS + SN_SEC_TRIS * SN_SECTION_ENTRY;
        end = (size_t)rs_u32(e) + rs_u32(e + 4);
    }
    cnt[SN_SEC_CONTROLS] = nk; el[SN_SEC_CONTROLS] = SN_ELEM_CONTROLS(R);
    cnt[SN_SEC_RIGS] = nr; el[SN_SEC_RIGS] = SN_ELEM_RIGS;
    cnt[SN_SEC_RIG_SAMPLES] = ns; el[SN_SEC_RIG_SAMPLES] = SN_ELEM_RIG_SAMPLES(R);
    cnt[SN_SEC_RIG_VERTS] = ne; el[SN_SEC_RIG_VERTS] = SN_ELEM_RIG_VERTS;
    cnt[SN_SEC_RIG_FORCES] = ne; el[SN_SEC_RIG_FORCES] = SN_ELEM_RIG_FORCES(R);
    for (k = SN_SEC_SHARES; k < SN_SEC_COUNT; k++) { /* carried over as they are (copied below) */
        const unsigned char *e = blob + SN_H_SECTIONS + k * SN_SECTION_ENTRY;
        cnt[k] = rs_u32(e + 8); el[k] = rs_u32(e + 12);
        if ((size_t)rs_u32(e) + (size_t)cnt[k] * el[k] > size) return NULL;
    }
    pos = end;
    for (k = SN_SEC_CONTROLS; k < SN_SEC_COUNT; k++) {
        pos = (pos + 7) & ~(size_t)7;
        off[k] = pos;
        pos += cnt[k] * el[k];
    }
    pos = (pos + 7) & ~(size_t)7;
    o = calloc(pos + 8, 1);
    if (!o) return NULL;
    memcpy(o, blob, end);
    for (k = SN_SEC_CONTROLS; k < SN_SEC_COUNT; k++) {
        unsigned char *e = o + SN_H_SECTIONS + k * SN_SECTION_ENTRY;
        ws_u32(e, (uint32_t)off[k]); ws_u32(e + 4, (uint32_t)(cnt[k] * el[k]));
        ws_u32(e + 8, (uint32_t)cnt[k]); ws_u32(e + 12, (uint32_t)el[k]);
    }
    for (k = SN_SEC_SHARES; k < SN_SEC_COUNT; k++)
        memcpy(o + off[k], blob + rs_u32(blob + SN_H_SECTIONS + k * SN_SECTION_ENTRY), cnt[k] * el[k]);
    for (i = 0; i < nk; i++) {
        unsigned char *e = o + off[SN_SEC_CONTROLS] + el[SN_SEC_CONTROLS] * i;
        double n = sqrt(ctl[i].axis[0] * ctl[i].axis[0] + ctl[i].axis[1] * ctl[i].axis[1] + ctl[i].axis[2] * ctl[i].axis[2]);
        strncpy((char *)e, ctl[i].name, 31);
        e[32] = (unsigned char)ctl[i].kind;
        e[33] = ctl[i].kind == SN_CTL_ANGLE ? (unsigned char)ctl[i].joint : 0;
        for (k = 0; k < 3; k++) ws_real(e + 40 + k * R, flavour, ctl[i].kind == SN_CTL_ANGLE && n > 0 ? ctl[i].axis[k] / n : 0.0, 30);
        ws_real(e + 40 + 3 * R, flavour, ctl[i].kind == SN_CTL_ABSTRACT ? ctl[i].value0 : 0.0, 16);
    }
    ns = ne = 0;
    for (a = 0; a < nr; a++) {
        unsigned char *e = o + off[SN_SEC_RIGS] + SN_ELEM_RIGS * a;
        double mx = 0;
        int frac = 0;
        for (i = 0; i < 3 * rig[a].n_entries; i++) if (fabs(rig[a].force[i]) > mx) mx = fabs(rig[a].force[i]);
        if (flavour == SN_FLAVOUR_FIXED) frac = rig[a].frac ? rig[a].frac : snsyn_rig_frac(mx);
        ws_u16(e, rig[a].control); e[2] = (unsigned char)rig[a].n_samples; e[3] = (unsigned char)(frac & 255);
        ws_u32(e + 4, ns); ws_u32(e + 8, ne); ws_u32(e + 12, rig[a].n_entries);
        for (i = 0; i < rig[a].n_samples; i++, ns++) {
            unsigned char *sp = o + off[SN_SEC_RIG_SAMPLES] + el[SN_SEC_RIG_SAMPLES] * ns;
            ws_real(sp, flavour, rig[a].gamma[i], 16);
            ws_real(sp + R, flavour, rig[a].eta[i], 30);
        }
        for (i = 0; i < rig[a].n_entries; i++, ne++) {
            ws_u16(o + off[SN_SEC_RIG_VERTS] + 2 * ne, rig[a].verts[i]);
            for (k = 0; k < 3; k++) ws_real(o + off[SN_SEC_RIG_FORCES] + el[SN_SEC_RIG_FORCES] * ne + k * R, flavour, rig[a].force[3 * i + k], frac);
        }
    }
    {   /* the instance grows by the controls (force slots and segment state as the input blob had them) */
        uint32_t ib0 = rs_u32(blob + SN_H_INSTANCE_BYTES), nk0 = rs_u32(blob + SN_H_SECTIONS + SN_SEC_CONTROLS * SN_SECTION_ENTRY + 8);
        ib = SN_INSTANCE_BYTES(rs_u32(o + SN_H_N_VERTICES), rs_u32(o + SN_H_N_FREE), rs_u32(o + SN_H_N_JOINTS), rs_u32(o + SN_H_N_CELLS), nk,
                               blob[SN_H_MAX_FORCES], 0, 0);
        /* segment state: whatever the input's instance had beyond its own count formula */
        ib += ib0 - SN_INSTANCE_BYTES(rs_u32(o + SN_H_N_VERTICES), rs_u32(o + SN_H_N_FREE), rs_u32(o + SN_H_N_JOINTS), rs_u32(o + SN_H_N_CELLS),
                                      nk0, blob[SN_H_MAX_FORCES], 0, 0);
    }
    ws_u32(o + SN_H_INSTANCE_BYTES, ib);   /* the validator wants exactly the runtime's formula */
    ws_u32(o + SN_H_TOTAL_SIZE, (uint32_t)pos);
    ws_u32(o + SN_H_CRC32, snref_crc32(o + 16, pos - 16));
    *out_size = pos;
    return o;
}
