/* sb_blob.c -- baked units (runtime/NUMERICS.md) and the byte layout
 * (runtime/src/sn_format.h, prose in runtime/BLOB.md). */
#include "sb_blob_int.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

uint16_t sb_frame_w(double w) { return (uint16_t)rnd(w * 32768.0); }

/* symmetric 3x3 storage order of PRECOND: xx yy zz xy xz yz */
/* health bound on the distance from the skinned position, cells */
#define SB_DISP_BOUND 2.0
static const int sym6[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};

/* CELLDK elements of a cell with nd details and nx extras (sn_format.h) */

/* fractional bits so that the largest |entry| lands in [2^26, 2^27] */
static int pick_frac(double maxabs)
{
    int e;
    if (!(maxabs > 0)) return 0;
    frexp(maxabs, &e);          /* maxabs in [2^(e-1), 2^e) */
    return 26 - (e - 1);
}

static void inv3sym(const double A[3][3], double R[3][3])
{
    double D = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
               A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    R[0][0] = (A[1][1] * A[2][2] - A[1][2] * A[2][1]) / D; R[0][1] = (A[0][2] * A[2][1] - A[0][1] * A[2][2]) / D;
    R[0][2] = (A[0][1] * A[1][2] - A[0][2] * A[1][1]) / D; R[1][0] = R[0][1];
    R[1][1] = (A[0][0] * A[2][2] - A[0][2] * A[2][0]) / D; R[1][2] = (A[0][2] * A[1][0] - A[0][0] * A[1][2]) / D;
    R[2][0] = R[0][2]; R[2][1] = R[1][2];
    R[2][2] = (A[0][0] * A[1][1] - A[0][1] * A[1][0]) / D;
}

int sb_blob_make(const sb_model *o, int flavour, sb_blob *b)
{
    const int nF = o->nf, nV = o->nv, nJ = o->nj;
    int i, j, k, e, nnz = 0, rs = flavour == SB_DOUBLE ? 8 : 4, s;
    double m0 = 0, maxS = 0, maxM = 0, maxP = 0, maxx = 0, h = o->h, a1, b1, U, *P, *lump;
    sb_ichol_t ic = {0, NULL, NULL, 0, 0};
    const double *root = o->joints[0].pos;
    uint32_t cnt[SN_SEC_COUNT], esz[SN_SEC_COUNT], off[SN_SEC_COUNT], total, *frefs;
    uint16_t *fpairs;
    int nfp;
    wr_t w;

    int nlim = 0, efrac = 0, ffrac = 0;
    double escale, fscale;
    memset(b, 0, sizeof *b);
    for (i = 0; i < nF; i++) if (o->limit && o->limit[i] > 0) nlim = nF;
    for (i = 0; i < nV; i++) { e = sb_pattern_find(o, i, i); if (o->M[e] > m0) m0 = o->M[e]; }
    if (!(m0 > 0)) return sb_fail("lattice has no mass");
    a1 = h * o->alpha;
    b1 = o->beta / h;
    if (a1 > 16 || b1 > 16) return sb_fail("Rayleigh damping out of range: h*alpha = %g and beta/h = %g must be <= 16", a1, b1);
    /* len_shift: smallest s with every |rest coordinate - root| < 2 * 2^s mesh units */
    for (i = 0; i < nV; i++) for (k = 0; k < 3; k++) maxx = fmax(maxx, fabs(o->x[3 * i + k] - root[k]));
    for (i = 0; i < nJ; i++) for (k = 0; k < 3; k++) maxx = fmax(maxx, fabs(o->joints[i].pos[k] - root[k]));
    for (s = -60; s < 100 && !(maxx < ldexp(2.0, s)); s++) {}
    if (o->lshift_set && s < o->lshift) s = o->lshift;   /* levels of detail share the length unit */
    if (s < -128 || s > 127) return sb_fail("model size out of range (len_shift %d)", s);
    U = ldexp(1.0, s);   /* internal unit in mesh units */
    /* joules per internal energy unit: m0 (U unit)^2 / h^2 (NUMERICS.md) */
    escale = m0 * (U * o->unit) * (U * o->unit) / (h * h);
    if (!(escale > 0)) return sb_fail("energy scale %g J per internal unit is not positive", escale);
    b->len_shift = s;
    b->m0 = m0;

    /* baked scalars and matrices: M^ = M/m0, S^_e = h^2 S_e/m0 (NUMERICS.md) */
    for (i = 0; i < 576 * o->nc; i++) maxS = fmax(maxS, fabs(h * h * o->Se[i] / m0));
    P = sb_alloc(sizeof(double) * 6 * (size_t)nF);
    lump = sb_alloc(sizeof(double) * (size_t)nF);
    for (i = 0; i < nF; i++) {
        double A[3][3], R[3][3], mii;
        e = sb_pattern_find(o, i, i);
        mii = o->M[e] / m0;
        for (j = o->nbptr[i]; j < o->nbptr[i + 1]; j++) {
            lump[i] += o->M[j] / m0;
            if (o->nb[j] > i) {
                nnz++;
                maxM = fmax(maxM, fabs(o->M[j] / m0));
            }
        }
        maxM = fmax(maxM, fmax(mii, fabs(lump[i])));
        for (j = 0; j < 3; j++)
            for (k = 0; k < 3; k++) {
                double sv = h * h * 0.5 * (o->S[9 * (size_t)e + (size_t)(3 * j + k)] + o->S[9 * (size_t)e + (size_t)(3 * k + j)]) / m0;
                A[j][k] = (1 + b1) * sv + (j == k ? (1 + a1) * mii : 0);
            }
        inv3sym((const double (*)[3])A, R);
        for (k = 0; k < 6; k++) { P[6 * i + k] = R[sym6[k][0]][sym6[k][1]]; maxP = fmax(maxP, fabs(P[6 * i + k])); }
    }
    if (o->precond == SB_PRECOND_ICHOL) { /* PRECOND holds the IC(0) pivots D^-1 (sb_ichol.c) */
        if (sb_ichol(o, m0, a1, b1, &ic) != 0) { free(P); free(lump); return -1; }
        maxP = 0;
        for (i = 0; i < nF; i++)
            for (k = 0; k < 6; k++) {
                P[6 * i + k] = 0.5 * (ic.Dinv[9 * i + 3 * sym6[k][0] + sym6[k][1]] + ic.Dinv[9 * i + 3 * sym6[k][1] + sym6[k][0]]);
                maxP = fmax(maxP, fabs(P[6 * i + k]));
            }
        b->ichol_n = ic.n;
        b->ichol_max = ic.maxU;
    }
    if (flavour == SB_FIXED) {
        b->frac_S = pick_frac(maxS); b->frac_M = pick_frac(maxM); b->frac_P = pick_frac(maxP);
        if (b->frac_S < 0 || b->frac_S > 60) { free(P); free(lump); return sb_fail("stiffness out of fixed-point range (largest S^ entry %g): change the timestep or E", maxS); }
        if (b->frac_M < 0 || b->frac_M > 60 || b->frac_P < 0 || b->frac_P > 60) { free(P); free(lump); return sb_fail("mass/preconditioner out of fixed-point range"); }
    }

    /* section table (sb_blob_table.c) */
    if (sb_blob_table(o, flavour, rs, nnz, ic.n, nlim, cnt, esz) != 0) { sb_ichol_free(&ic); free(P); free(lump); return -1; }
    /* the frames' references (format 6.4): every entry's, and the distinct pairs */
    frefs = sb_alloc(sizeof(uint32_t) * (size_t)(nF + o->nc));
    fpairs = sb_alloc(sizeof(uint16_t) * (size_t)(nF + o->nc));
    nfp = sb_frame_refs(o, frefs, fpairs);
    cnt[SN_SEC_FPAIRS] = (uint32_t)nfp;              esz[SN_SEC_FPAIRS] = SN_ELEM_FPAIRS;
    cnt[SN_SEC_FREFS] = (uint32_t)(nF + o->nc);      esz[SN_SEC_FREFS] = SN_ELEM_FREFS;
    total = SN_HEADER_BYTES;
    for (k = 0; k < SN_SEC_COUNT; k++) {
        total = (total + 7u) & ~7u;
        off[k] = total;
        total += cnt[k] * esz[k];
        b->sec_off[k] = off[k]; b->sec_size[k] = cnt[k] * esz[k];
    }
    total = (total + 7u) & ~7u;
    b->size = total;
    b->bytes = sb_alloc(total);
    w.p = b->bytes; w.flavour = flavour; w.rs = rs; w.err = 0;

    /* header */
    w.p[SN_H_MAGIC] = SN_MAGIC0; w.p[SN_H_MAGIC + 1] = SN_MAGIC1; w.p[SN_H_MAGIC + 2] = SN_MAGIC2; w.p[SN_H_MAGIC + 3] = SN_MAGIC3;
    put_u16(&w, SN_H_VER_MAJOR, SN_FORMAT_MAJOR);
    put_u16(&w, SN_H_VER_MINOR, SN_FORMAT_MINOR);
    put_u32(&w, SN_H_ENDIAN, SN_ENDIAN_MARK);
    put_u32(&w, SN_H_TOTAL_SIZE, total);
    put_u32(&w, SN_H_HEADER_SIZE, SN_HEADER_BYTES);
    put_u8(&w, SN_H_FLAVOUR, (unsigned)flavour);
    put_u8(&w, SN_H_REAL_SIZE, (unsigned)rs);
    put_u8(&w, SN_H_NSECTIONS, SN_SEC_COUNT);
    put_u32(&w, SN_H_ONE, flavour == SB_FIXED ? SN_ONE_FIXED : flavour == SB_FLOAT ? SN_ONE_FLOAT32 : 0u);
    put_u32(&w, SN_H_ONE_HI, flavour == SB_DOUBLE ? SN_ONE_FLOAT64_HI : 0u);
    put_u32(&w, SN_H_N_VERTICES, (uint32_t)nV);
    put_u32(&w, SN_H_N_FREE, (uint32_t)nF);
    put_u32(&w, SN_H_N_CELLS, (uint32_t)o->nc);
    put_u32(&w, SN_H_N_JOINTS, (uint32_t)nJ);
    put_u32(&w, SN_H_N_SURFACE, (uint32_t)o->ns);
    put_u32(&w, SN_H_N_TRIANGLES, (uint32_t)o->nt);
    put_u32(&w, SN_H_N_OFFDIAG, (uint32_t)nnz);
    put_u32(&w, SN_H_INSTANCE_BYTES, SN_INSTANCE_BYTES(nV, nF, nJ, o->nc, (uint32_t)o->nctl, (uint32_t)o->max_forces,
                                                       sb_segment_state_bytes(o) +
                                                       (o->crease ? SN_CREASE_STATE_BYTES(o->ns, o->cr_list) : 0u) +
                                                       (uint32_t)nfp * SN_FPAIR_BYTES,
                                                       (o->max_cons || o->max_cols || o->max_contacts || o->crease)
                                                           ? SN_CONS_BYTES(o->max_cons, o->max_cols,
                                                                           SN_ROWS_CAP(o->max_cons, o->max_contacts, o->crease ? o->cr_active : 0))
                                                           : 0u));
    if (o->lod_size) put_u32(&w, SN_H_INSTANCE_BYTES, o->lod_inst_bytes);   /* laid out for the larger level */
    put_u8(&w, SN_H_MAX_FORCES, (unsigned)o->max_forces);
    put_u8(&w, SN_H_FLAGS, o->rest_modelled ? SN_FLAG_REST_MODELLED : 0u);
    put_u16(&w, SN_H_CG_DEFAULT, (unsigned)o->cg_def);
    put_u16(&w, SN_H_CG_MAX, (unsigned)o->cg_max);
    put_u8(&w, SN_H_LEN_SHIFT, (unsigned)(s & 255));
    put_u8(&w, SN_H_FRAC_S, (unsigned)b->frac_S);
    put_u8(&w, SN_H_FRAC_M, (unsigned)b->frac_M);
    put_u8(&w, SN_H_FRAC_P, (unsigned)b->frac_P);
    {   /* ENERGY in [2^29, 2^30) in fixed */
        int fe = 0;
        if (flavour == SB_FIXED) { frexp(escale, &fe); fe = 30 - fe; }
        if (fe < -40 || fe > 60) { sb_blob_free(b); free(P); free(lump); return sb_fail("energy scale %g J per internal unit out of range", escale); }
        put_u8(&w, SN_H_FRAC_E, (unsigned)(fe & 255));
        efrac = fe;
    }
    {   /* FORCE = h^2 / (m0 U unit) rhs units per newton, in [2^29, 2^30) in fixed */
        int ff = 0;
        fscale = h * h / (m0 * U * o->unit);
        if (flavour == SB_FIXED) { frexp(fscale, &ff); ff = 30 - ff; }
        if (!(fscale > 0) || ff < -40 || ff > 60) { sb_blob_free(b); free(P); free(lump); return sb_fail("force scale %g per newton out of range", fscale); }
        put_u8(&w, SN_H_FRAC_F, (unsigned)(ff & 255));
        ffrac = ff;
    }
    {
        size_t R0 = SN_H_REALS;
        double gs = h * h / (U * o->unit);   /* g^ = h^2 g / U, U in metres */
        put_real(&w, R0 + SN_R_A1 * (size_t)rs, a1, SN_Q_COEF);
        put_real(&w, R0 + SN_R_B1 * (size_t)rs, b1, SN_Q_COEF);
        for (k = 0; k < 3; k++) put_real(&w, R0 + (size_t)(SN_R_GRAV_X + k) * (size_t)rs, gs * o->g[k], SN_Q_LEN);
        put_real(&w, R0 + SN_R_TIMESTEP * (size_t)rs, h, 16);
        put_real(&w, R0 + SN_R_MASS_SCALE * (size_t)rs, fmin(m0, 32767.0), 16);
        put_real(&w, R0 + SN_R_ENERGY * (size_t)rs, escale, efrac);
        put_real(&w, R0 + SN_R_CELL * (size_t)rs, o->c / U, SN_Q_LEN);
        put_real(&w, R0 + SN_R_DISP_BOUND * (size_t)rs, SB_DISP_BOUND, 16);
        put_real(&w, R0 + SN_R_FORCE * (size_t)rs, fscale, ffrac);
        put_real(&w, R0 + SN_R_RESERVED11 * (size_t)rs, 0.0, 0);
    }
    for (k = 0; k < SN_SEC_COUNT; k++) {
        size_t at = SN_H_SECTIONS + (size_t)k * SN_SECTION_ENTRY;
        put_u32(&w, at, off[k]); put_u32(&w, at + 4, cnt[k] * esz[k]); put_u32(&w, at + 8, cnt[k]); put_u32(&w, at + 12, esz[k]);
    }

    /* sections */
    for (j = 0; j < nJ; j++) {
        size_t at = off[SN_SEC_JOINTS] + (size_t)j * esz[SN_SEC_JOINTS];
        put_u16(&w, at, o->joints[j].parent < 0 ? 0xFFFFu : (unsigned)o->joints[j].parent);
        for (k = 0; k < 3; k++) put_real(&w, at + 8 + (size_t)(k * rs), (o->joints[j].pos[k] - root[k]) / U, SN_Q_LEN);
        memcpy(w.p + off[SN_SEC_JOINT_NAMES] + 32 * (size_t)j, o->joints[j].name, strlen(o->joints[j].name));
    }
    for (i = 0; i < nV; i++) {
        size_t at = off[SN_SEC_FRAMES] + 4 * (size_t)i;
        for (k = 0; k < 3; k++) put_real(&w, off[SN_SEC_REST] + (size_t)(3 * i + k) * (size_t)rs, (o->x[3 * i + k] - root[k]) / U, SN_Q_LEN);
        put_u8(&w, at, (unsigned)o->fb1[i]);
        put_u8(&w, at + 1, (unsigned)o->fb2[i]);
        put_u16(&w, at + 2, sb_frame_w(o->fw[i]));
    }
    nnz = 0;
    for (i = 0; i < nF; i++) {
        e = sb_pattern_find(o, i, i);
        put_real(&w, off[SN_SEC_MDIAG] + (size_t)i * (size_t)rs, o->M[e] / m0, b->frac_M);
        for (k = 0; k < 6; k++)
            put_real(&w, off[SN_SEC_PRECOND] + (size_t)(6 * i + k) * (size_t)rs, P[6 * i + k], b->frac_P);
        put_real(&w, off[SN_SEC_MLUMP] + (size_t)i * (size_t)rs, lump[i], b->frac_M);
        put_u32(&w, off[SN_SEC_ROWPTR] + 4 * (size_t)i, (uint32_t)nnz);
        for (j = o->nbptr[i]; j < o->nbptr[i + 1]; j++) {
            if (o->nb[j] <= i) continue;
            put_u16(&w, off[SN_SEC_COLS] + 2 * (size_t)nnz, (unsigned)o->nb[j]);
            put_real(&w, off[SN_SEC_MOFF] + (size_t)nnz * (size_t)rs, o->M[j] / m0, b->frac_M);
            nnz++;
        }
    }
    put_u32(&w, off[SN_SEC_ROWPTR] + 4 * (size_t)nF, (uint32_t)nnz);
    {   /* ICHOL: int16 mantissas, one frac per block, in every flavour (SB_ICHOL_BITS: fewer mantissa bits, a measurement aid) */
        const char *eb = getenv("SB_ICHOL_BITS");
        int bits = eb ? atoi(eb) : 15;
        if (bits < 2 || bits > 15) bits = 15;
        for (k = 0; k < ic.n; k++) {
            int mm[9], fr, r;
            size_t at = off[SN_SEC_ICHOL] + (size_t)k * SN_ELEM_ICHOL;
            if (sb_ichol_quant(ic.U + 9 * (size_t)k, bits, mm, &fr) != 0) {
                sb_ichol_free(&ic); free(P); free(lump); sb_blob_free(b);
                return sb_fail("IC(0) preconditioner: a factor entry beyond 2^15 (largest %g): bake with 'precond jacobi'", ic.maxU);
            }
            for (r = 0; r < 9; r++) put_u16(&w, at + 2 * (size_t)r, (unsigned)(mm[r] & 0xFFFF));
            put_u8(&w, at + 18, (unsigned)fr);
        }
        sb_ichol_free(&ic);
    }
    sb_blob_write_cells(o, &w, off, esz, h, m0, b);
    for (k = 0; k < nfp; k++) {
        put_u8(&w, off[SN_SEC_FPAIRS] + 2 * (size_t)k, (unsigned)(fpairs[k] >> 8));
        put_u8(&w, off[SN_SEC_FPAIRS] + 2 * (size_t)k + 1, (unsigned)(fpairs[k] & 255u));
    }
    for (i = 0; i < nF + o->nc; i++) put_u32(&w, off[SN_SEC_FREFS] + 4 * (size_t)i, frefs[i]);
    free(frefs);
    free(fpairs);
    if (cnt[SN_SEC_DETAILS] && sb_blob_write_details(o, &w, off, esz, h, m0, U, root, b) != 0) {
        free(P); free(lump); sb_blob_free(b);
        return -1;
    }
    {   /* beyond 64 internal units the state clamps anyway (NUMERICS.md): say so once */
        int beyond = 0;
        for (i = 0; i < nlim; i++) {
            beyond |= o->limit[i] / U > 64.0;
            put_real(&w, off[SN_SEC_LIMIT] + (size_t)i * (size_t)rs, fmin(o->limit[i] / U, 64.0), SN_Q_LEN);
        }
        if (beyond && !o->quiet)
            fprintf(stderr, "sinew-bake: warning: a limit beyond %g mesh units (64 internal units, the state's range) acts as that bound\n",
                    64.0 * U);
    }
    for (i = 0; i < o->ns; i++) {
        size_t at = off[SN_SEC_EMBED] + 8 * (size_t)i;
        put_u16(&w, at, (unsigned)o->emb_cell[i]);
        for (k = 0; k < 3; k++) put_u16(&w, at + 2 + 2 * (size_t)k, (unsigned)rnd(o->emb_t[3 * i + k] * 32768.0));
    }
    for (i = 0; i < o->nt; i++)
        for (k = 0; k < 3; k++) put_u16(&w, off[SN_SEC_TRIS] + 6 * (size_t)i + 2 * (size_t)k, (unsigned)o->tri[3 * i + k]);
    free(P); free(lump);
    if (!w.err && sb_blob_write_rigs(o, &w, off, U * o->unit, m0, b) != 0) { sb_blob_free(b); return -1; }
    if (!w.err && sb_segment_blob_write(o, b->bytes, off, flavour, rs, s, m0) != 0) { sb_blob_free(b); return -1; }
    if (sb_blob_write_records(o, &w, off, cnt, U) != 0) { sb_blob_free(b); return -1; }
    if (w.err) { sb_blob_free(b); return sb_fail("a baked value does not fit its fixed-point format (check timestep, gravity, damping)"); }
    if (o->nc > 65535) { sb_blob_free(b); return sb_fail("%d cells: at most 65535", o->nc); }
    put_u32(&w, SN_H_CRC32, sb_crc32(b->bytes + 16, total - 16));
    return 0;
}

void sb_blob_free(sb_blob *b)
{
    free(b->bytes);
    free(b->rig_frac);
    memset(b, 0, sizeof *b);
}
