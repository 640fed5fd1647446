/* sb_blob_records.c -- the blob's small records: force share profiles,
 * the constraints' maxima, adaptation, crease (seed pairs, neighbourhoods)
 * and the level-of-detail pair's maps (sn_format.h, runtime/BLOB.md). */
#include "sb_blob_int.h"

/* -1 (sb_fail) for a length beyond its record's format */
int sb_blob_write_records(const sb_model *o, wr_t *w, const uint32_t *off, const uint32_t *cnt, double U)
{
    const int flavour = w->flavour, rs = w->rs, nF = o->nf, nV = o->nv;
    int i, k;
    for (i = 0; i < o->nprof; i++)   /* share profiles: Q30, the fine share takes the rounding so each sums to 2^30 */
        for (k = 0; k < SN_LEVELS; k++) {
            size_t at = off[SN_SEC_SHARES] + ((size_t)i * SN_LEVELS + (size_t)k) * (size_t)rs;
            if (flavour == SB_FIXED) {
                int32_t q = 0, rest = (int32_t)1 << 30;
                int kk;
                for (kk = 1; kk < SN_LEVELS; kk++) rest -= (int32_t)rnd(o->prof[i][kk] * 1073741824.0);
                q = k == 0 ? rest : (int32_t)rnd(o->prof[i][k] * 1073741824.0);
                put_u32(w, at, (uint32_t)q);
            } else put_real(w, at, o->prof[i][k], 0);
        }
    if (o->vprof) for (i = 0; i < nF; i++) put_u8(w, off[SN_SEC_VSHARE] + (size_t)i, o->vprof[i]);
    if (cnt[SN_SEC_CONSTRAINTS]) {
        put_u8(w, off[SN_SEC_CONSTRAINTS], (unsigned)o->max_cons);
        put_u8(w, off[SN_SEC_CONSTRAINTS] + 1, (unsigned)o->max_cols);
        put_u16(w, off[SN_SEC_CONSTRAINTS] + 2, (unsigned)o->max_contacts);
    }
    if (cnt[SN_SEC_ADAPT]) {   /* ADAPT record (sn_adapt.c): A_max, refine, coarsen (internal units, Q22) */
        size_t at = off[SN_SEC_ADAPT];
        if (o->ad_refine / U * 4194304.0 > (double)SN_ADAPT_MAX) { return sb_fail("adapt refine %g mesh units out of range (0..%g)", o->ad_refine, U * 256); }
        put_u16(w, at, (unsigned)o->ad_max);
        put_real(w, at + 8, o->ad_refine / U, SN_Q_LEN);
        put_real(w, at + 8 + (size_t)rs, fmin(o->ad_coarsen, o->ad_refine) / U, SN_Q_LEN);
    }
    if (o->crease) {   /* CREASE record, seed pairs, neighbourhood rows (SN_CREASE_NONE for -1) */
        size_t at = off[SN_SEC_CREASE];
        double dep = o->cr_depth / U, push = o->cr_push / U;
        if (dep * 4194304.0 < 1 || dep * 4194304.0 > (double)SN_CREASE_DEPTH_MAX) { return sb_fail("crease depth %g mesh units out of range (%g..%g)", o->cr_depth, U / 4194304.0, U * 16); }
        put_u16(w, at, (unsigned)o->cr_list); put_u16(w, at + 2, (unsigned)o->cr_active);
        put_u8(w, at + 4, (unsigned)o->cr_kv); put_u8(w, at + 5, (unsigned)o->cr_kt); put_u16(w, at + 6, (unsigned)o->cr_nq);
        put_real(w, at + 12, dep, SN_Q_LEN);
        put_real(w, at + 12 + (size_t)rs, fmin(push, dep), SN_Q_LEN);
        if (o->cr_exclude / U * 4194304.0 > (double)SN_CREASE_EXCLUDE_MAX) { return sb_fail("crease exclude %g mesh units out of range (0..%g)", o->cr_exclude, U * 64); }
        put_real(w, at + 12 + 2 * (size_t)rs, o->cr_exclude / U, SN_Q_LEN);
        for (i = 0; i < o->cr_nD; i++) {
            put_u16(w, off[SN_SEC_CREASE_PAIRS] + 4 * (size_t)i, (unsigned)o->cr_pairs[2 * i]);
            put_u16(w, off[SN_SEC_CREASE_PAIRS] + 4 * (size_t)i + 2, (unsigned)o->cr_pairs[2 * i + 1]);
        }
        for (i = 0; i < o->cr_nq * o->cr_kv; i++)
            put_u16(w, off[SN_SEC_CREASE_VNBR] + 2 * (size_t)i, o->cr_vnbr[i] < 0 ? SN_CREASE_NONE : (unsigned)o->cr_vnbr[i]);
        for (i = 0; i < o->cr_nq * o->cr_kt; i++)
            put_u16(w, off[SN_SEC_CREASE_TNBR] + 2 * (size_t)i, o->cr_tnbr[i] < 0 ? SN_CREASE_NONE : (unsigned)o->cr_tnbr[i]);
    }
    if (o->lod_size) {   /* the finer level verbatim, then the two maps */
        memcpy(w->p + off[SN_SEC_LEVEL_BLOB], o->lod_blob, o->lod_size);
        for (i = 0; i < 4 * (int)o->lod_nv1; i++) put_u16(w, off[SN_SEC_LEVEL_UP] + 2 * (size_t)i, o->lod_up[i]);
        for (i = 0; i < 4 * nV; i++) put_u16(w, off[SN_SEC_LEVEL_DOWN] + 2 * (size_t)i, o->lod_down[i]);
    }
    return 0;
}
