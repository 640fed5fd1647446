/* sb_blob_table.c -- the blob's section table: each section's count and
 * element size for a model (runtime/src/sn_format.h, runtime/BLOB.md). */
#include "sb_blob_int.h"

/* the cut level's details: per cell nd (8 + nx) + nd (nd + 1) / 2 blocks */
static uint32_t detail_blocks(int nd, int nx) { return (uint32_t)(nd * (8 + nx) + nd * (nd + 1) / 2); }

/* counts and element sizes of every section but the frames' references (the
 * caller's, from sb_frame_refs); nnz: the mass pattern's upper blocks, nic: the
 * IC(0) factor's blocks, nlim: LIMIT's entries. -1 (with sb_fail) when a count is beyond
 * the format. */
int sb_blob_table(const sb_model *o, int flavour, int rs, int nnz, int nic, int nlim, uint32_t *cnt, uint32_t *esz)
{
    const int nF = o->nf, nV = o->nv, nJ = o->nj;
    int i, k;
    cnt[SN_SEC_JOINTS] = (uint32_t)nJ;        esz[SN_SEC_JOINTS] = SN_ELEM_JOINTS(rs);
    cnt[SN_SEC_JOINT_NAMES] = (uint32_t)nJ;   esz[SN_SEC_JOINT_NAMES] = SN_ELEM_JOINT_NAMES;
    cnt[SN_SEC_REST] = (uint32_t)nV;          esz[SN_SEC_REST] = SN_ELEM_REST(rs);
    cnt[SN_SEC_FRAMES] = (uint32_t)nV;        esz[SN_SEC_FRAMES] = SN_ELEM_FRAMES;
    cnt[SN_SEC_MDIAG] = (uint32_t)nF;         esz[SN_SEC_MDIAG] = SN_ELEM_MDIAG(rs);
    cnt[SN_SEC_PRECOND] = (uint32_t)nF;       esz[SN_SEC_PRECOND] = SN_ELEM_PRECOND(rs);
    cnt[SN_SEC_MLUMP] = (uint32_t)nF;         esz[SN_SEC_MLUMP] = SN_ELEM_MLUMP(rs);
    cnt[SN_SEC_ROWPTR] = (uint32_t)nF + 1;    esz[SN_SEC_ROWPTR] = SN_ELEM_ROWPTR;
    cnt[SN_SEC_COLS] = (uint32_t)nnz;         esz[SN_SEC_COLS] = SN_ELEM_COLS;
    cnt[SN_SEC_MOFF] = (uint32_t)nnz;         esz[SN_SEC_MOFF] = SN_ELEM_MOFF(rs);
    cnt[SN_SEC_CELLS] = (uint32_t)o->nc;      esz[SN_SEC_CELLS] = SN_ELEM_CELLS;
    cnt[SN_SEC_CFRAMES] = (uint32_t)o->nc;    esz[SN_SEC_CFRAMES] = SN_ELEM_CFRAMES;
    cnt[SN_SEC_CELLK] = (uint32_t)o->nc;      esz[SN_SEC_CELLK] = SN_ELEM_CELLK(flavour == SB_FIXED ? SN_FLAVOUR_FIXED : SN_FLAVOUR_FLOAT32, rs);
    cnt[SN_SEC_LIMIT] = (uint32_t)nlim;       esz[SN_SEC_LIMIT] = SN_ELEM_LIMIT(rs);
    cnt[SN_SEC_EMBED] = (uint32_t)o->ns;      esz[SN_SEC_EMBED] = SN_ELEM_EMBED;
    cnt[SN_SEC_TRIS] = (uint32_t)o->nt;       esz[SN_SEC_TRIS] = SN_ELEM_TRIS;
    {   /* rig sections: counts (running sums of samples and entries) */
        uint32_t nsamp = 0, nent = 0;
        for (k = 0; k < o->nrig; k++) { nsamp += (uint32_t)o->rig[k].def.ntau; nent += (uint32_t)o->rig[k].n; }
        cnt[SN_SEC_CONTROLS] = (uint32_t)o->nctl;  esz[SN_SEC_CONTROLS] = SN_ELEM_CONTROLS(rs);
        cnt[SN_SEC_RIGS] = (uint32_t)o->nrig;      esz[SN_SEC_RIGS] = SN_ELEM_RIGS;
        cnt[SN_SEC_RIG_SAMPLES] = nsamp;           esz[SN_SEC_RIG_SAMPLES] = SN_ELEM_RIG_SAMPLES(rs);
        cnt[SN_SEC_RIG_VERTS] = nent;              esz[SN_SEC_RIG_VERTS] = SN_ELEM_RIG_VERTS;
        cnt[SN_SEC_RIG_FORCES] = nent;             esz[SN_SEC_RIG_FORCES] = SN_ELEM_RIG_FORCES(rs);
        if (o->nctl > (int)SN_MAX_CONTROLS || o->nrig > (int)SN_MAX_RIGS) { return sb_fail("%d controls, %d rigs: at most %u and %u", o->nctl, o->nrig, SN_MAX_CONTROLS, SN_MAX_RIGS); }
    }
    {   /* external forces: share profiles, per-vertex profiles */
        if (o->nprof > (int)SN_MAX_PROFILES || o->max_forces < 0 || o->max_forces > (int)SN_MAX_FORCES) { return sb_fail("%d force profiles, %d force slots: at most %u and %u", o->nprof, o->max_forces, SN_MAX_PROFILES, SN_MAX_FORCES); }
        cnt[SN_SEC_SHARES] = (uint32_t)o->nprof;                 esz[SN_SEC_SHARES] = SN_ELEM_SHARES(rs);
        cnt[SN_SEC_VSHARE] = o->vprof ? (uint32_t)nF : 0u;       esz[SN_SEC_VSHARE] = SN_ELEM_VSHARE;
    }
    {   /* segment meshes (sb_segment.c) */
        uint32_t nodes = 0, natt = 0;
        sb_segment_blob_counts(o, &nodes, &natt);
        cnt[SN_SEC_SEGMESH] = (uint32_t)o->nsm;    esz[SN_SEC_SEGMESH] = SN_ELEM_SEGMESH(rs);
        cnt[SN_SEC_SEGNODES] = nodes;              esz[SN_SEC_SEGNODES] = SN_ELEM_SEGNODES(rs);
        cnt[SN_SEC_SEGATTACH] = natt;              esz[SN_SEC_SEGATTACH] = SN_ELEM_SEGATTACH(rs);
    }
    {   /* constraints and contact: one record of maxima, or none */
        int any = o->max_cons || o->max_cols || o->max_contacts;
        if (o->max_cons < 0 || o->max_cons > (int)SN_MAX_CONSTRAINTS || o->max_cols < 0 || o->max_cols > (int)SN_MAX_COLLIDERS ||
            o->max_contacts < 0 || o->max_contacts > (int)SN_MAX_CONTACTS ||
            SN_ROWS_CAP(o->max_cons, o->max_contacts, o->crease ? o->cr_active : 0) > SN_MAX_ROWS || (o->max_cols > 0 && o->max_contacts == 0)) {
            return sb_fail("constraints %d, colliders %d, contacts %d: at most %u, %u, %u, 3 constraints + contacts + crease rows <= %u, contacts >= 1 with colliders",
                           o->max_cons, o->max_cols, o->max_contacts, SN_MAX_CONSTRAINTS, SN_MAX_COLLIDERS, SN_MAX_CONTACTS, SN_MAX_ROWS);
        }
        cnt[SN_SEC_CONSTRAINTS] = any ? 1u : 0u;   esz[SN_SEC_CONSTRAINTS] = SN_ELEM_CONSTRAINTS;
    }
    {   /* self-collision near creases (sb_crease.c) */
        uint32_t on = o->crease ? 1u : 0u;
        cnt[SN_SEC_CREASE] = on;                                   esz[SN_SEC_CREASE] = SN_ELEM_CREASE(rs);
        cnt[SN_SEC_CREASE_PAIRS] = on ? (uint32_t)o->cr_nD : 0u;   esz[SN_SEC_CREASE_PAIRS] = SN_ELEM_CREASE_PAIRS;
        cnt[SN_SEC_CREASE_VNBR] = on ? (uint32_t)(o->cr_nq * o->cr_kv) : 0u; esz[SN_SEC_CREASE_VNBR] = SN_ELEM_CREASE_VNBR;
        cnt[SN_SEC_CREASE_TNBR] = on ? (uint32_t)(o->cr_nq * o->cr_kt) : 0u; esz[SN_SEC_CREASE_TNBR] = SN_ELEM_CREASE_TNBR;
    }
    /* level of detail (sb_level.c) */
    cnt[SN_SEC_LEVEL_BLOB] = o->lod_size;                      esz[SN_SEC_LEVEL_BLOB] = SN_ELEM_LEVEL_BLOB;
    cnt[SN_SEC_LEVEL_UP] = o->lod_size ? o->lod_nv1 : 0u;      esz[SN_SEC_LEVEL_UP] = SN_ELEM_LEVEL_MAP;
    cnt[SN_SEC_LEVEL_DOWN] = o->lod_size ? (uint32_t)nV : 0u;  esz[SN_SEC_LEVEL_DOWN] = SN_ELEM_LEVEL_MAP;
    cnt[SN_SEC_ICHOL] = (uint32_t)nic;           esz[SN_SEC_ICHOL] = SN_ELEM_ICHOL;
    cnt[SN_SEC_ADAPT] = o->lod_size && o->ad_on ? 1u : 0u;   esz[SN_SEC_ADAPT] = SN_ELEM_ADAPT(rs);
    {
        uint32_t nxb = 0;
        if (o->cut) for (i = 0; i < o->nc; i++) nxb += 8u * (uint32_t)o->cut->cnx[i];
        cnt[SN_SEC_CELLX] = o->cut ? (uint32_t)o->nc : 0u;   esz[SN_SEC_CELLX] = SN_ELEM_CELLX;
        cnt[SN_SEC_CELLXK] = nxb;   esz[SN_SEC_CELLXK] = SN_ELEM_CELLXK(flavour == SB_FIXED ? SN_FLAVOUR_FIXED : SN_FLAVOUR_FLOAT32, rs);
    }
    {   /* the cut level's details (sb_cut.h): per cell nd (8 + nx) + nd (nd + 1) / 2 blocks */
        uint32_t ndb = 0, on = o->cut && o->det_on ? 1u : 0u;
        if (on) for (i = 0; i < o->nc; i++) ndb += detail_blocks(o->cut->cnd[i], o->cut->cnx[i]);
        cnt[SN_SEC_DETAILS] = on;   esz[SN_SEC_DETAILS] = SN_ELEM_DETAILS(rs);
        cnt[SN_SEC_DETAIL] = on ? (uint32_t)o->cut->nd : 0u;   esz[SN_SEC_DETAIL] = SN_ELEM_DETAIL(rs);
        cnt[SN_SEC_CELLD] = on ? (uint32_t)o->nc : 0u;   esz[SN_SEC_CELLD] = SN_ELEM_CELLD;
        cnt[SN_SEC_CELLDK] = ndb;   esz[SN_SEC_CELLDK] = SN_ELEM_CELLDK(flavour == SB_FIXED ? SN_FLAVOUR_FIXED : SN_FLAVOUR_FLOAT32, rs);
    }
    return 0;
}
