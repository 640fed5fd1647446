/* sn_instance.h -- the instance: header, array layout, and the stages of a
 * step shared by the runtime files (runtime/NUMERICS.md "One step").
 *
 *   sn_instance.c  layout, init, reset, setters, stats, hash
 *   sn_pose.c      pose input, forward kinematics, joint and frame transforms, skeleton
 *   sn_solve.c     right-hand side, per-cell stiffness, mat-vec, preconditioner, PCG
 *   sn_rig.c       controls, tau maps, rig forces (seed 003 §4)
 *   sn_force.c     external forces and impulses, multilevel shares, joint wrench (seed 004 ch. 4)
 *   sn_segment.c   segment meshes: chains and sheets (seed 004 ch. 3-4): dynamics, the step;
 *                  sn_segment_sweep.c their constraint sweeps, sn_segment_mesh.c records,
 *                  topology, reset, teleport, hash; sn_segment_level.c levels; _api.c validator
 *   sn_crease.c    self-collision near creases: list C, detection, rows (seed 003 §3.4)
 *   sn_health.c    limits and the health report
 *   sn_embed.c     outputs: lattice, surface, normals
 *   sn_cut.c       the cut level: its validation, extras' terms, cut field (sn_cut.h)
 *   sn_constraint.c constraint rows, their factorization and the CG's projection (seed 000 §4.4)
 *   sn_contact.c   the game's colliders -> one-sided contact rows (seed 003 eq. 9)
 *   sn_step.c      the step: the stages in order
 */
#ifndef SN_INSTANCE_H
#define SN_INSTANCE_H

#include "sn_internal.h"

#define SN_INST_MAGIC 0x534E4932u /* "SNI2" */
#define SN_HDR_BYTES SN_INSTANCE_HDR_BYTES

/* Instance header; arrays follow at fixed offsets computed from the blob. */
typedef struct sn_ihdr {
    uint32_t magic;
    uint32_t steps, saturations, iterations, mode, have_prev;
    uint32_t bound_steps, limit_clamps, limit_steps, cg_clamps;
    sn_view v;
    sn_real origin[3];      /* public units: origin o of the stored positions */
    sn_real disp, disp_max, energy, energy_max; /* health, public units */
#if defined(SN_FLOAT)
    float to_int, to_pub;   /* mesh units <-> internal units */
#endif
    /* byte offsets of the arrays from the instance start */
    uint32_t o_acc, o_pq, o_pt, o_jR, o_jT, o_R, o_pos, o_vel, o_x, o_r, o_d, o_q, o_ds, /* o_ds = o_d; q, z, w share o_q */
        o_k, o_cR, o_ctl, o_wr, o_frc, o_seg, o_crs,
        o_sp;               /* the frame pairs' slerp parts (FPAIRS), scratch: of sn_ws (sn_pose.c) */
    uint32_t frame_mode;    /* the mode the frames (R, cR, jT) were last built in: the origins sn_vertex_origin derives follow it */
    uint32_t n_forces;      /* force slots filled since the last step (sn_force.c) */
    uint32_t force_drops;   /* forces refused since init/reset: slots full */
    sn_real seg_gap;        /* largest segment constraint gap after the last step's sweeps, fraction of a segment (public Q16.16 / float) */
    sn_real seg_gap_max;    /* largest seg_gap since init/reset */
    /* segment meshes (sn_segment.c) */
    sn_real seg_origin[3];  /* the origin the segment state was last expressed against (public) */
    uint32_t seg_placed;    /* 0 after init/reset: the first step places the meshes by their joint */
    uint32_t floor_on;      /* sn_set_segment_floor: a floor plane is set (a setting: survives reset) */
    sn_q floor_n[3];        /* its unit normal (Q30 / float) */
    sn_real floor_off;      /* n.p >= floor_off, world public units */
    /* self-collision near creases (sn_crease.c) */
    uint32_t cr_n;          /* entries of the collision list C (eq. 8) */
    uint32_t cr_na;         /* active prefix n_a of C after the last step's detection */
    uint32_t cr_rows;       /* rows in the temporary row buffer (sn_rows_push) */
    uint32_t cr_list_full;  /* penetrations not added since init/reset: C full */
    uint32_t cr_active_over;/* active constraints not pushed since init/reset: max_active reached or row store full */
    uint32_t cr_added, cr_removed; /* pairs added to / removed from C since init/reset */
    /* constraints and contact (sn_constraint.c, sn_contact.c) */
    uint32_t o_con, o_col, o_row, o_rx, o_L; /* user constraints, colliders, rows, row state, packed factor */
    uint32_t n_con, n_col;  /* user constraints and colliders in force (settings: kept until replaced or reset) */
    uint32_t n_rows;        /* rows collected for the current step */
    uint32_t rows_kept;     /* rows enforced in the last step (after the factorization's drops) */
    uint32_t contacts;      /* contact rows collected in the last step */
    uint32_t row_drops, contact_overflow, row_overflow, con_refused, con_clamps; /* since init/reset */
    /* level of detail (sn_level.c): the blob given to init (v is the active level's view), the active level */
    const unsigned char *lod_base;
    uint32_t lod;
    /* adaptation on level 1 (sn_adapt.c): its state (sn_adapt_state, then the mask) takes ad_bytes
     * after the layout, at v.instance_bytes (0: the blob has no ADAPT record) */
    uint32_t ad_bytes;
    /* (details on the cut level, sn_detail_step.c: their region follows adaptation's, at
     * v.instance_bytes + ad_bytes, when the blob has DETAILS; sn_detail_region) */
} sn_ihdr;

/* Adaptation's state, at v.instance_bytes (sn_adapt.c): the record's A_max and thresholds as ordered
 * keys, the switch, the counts and events; the mask (ad_n bytes, 1: in the solve) follows. */
typedef struct sn_adapt_state {
    uint32_t n, max, refine, coarsen, on;
    uint32_t active, inactive, refines, coarsens, overflow;
    uint32_t keyed, pad; /* keyed: the last solve left the inactive vertices' estimates in acc */
} sn_adapt_state;
#define SN_ADAPT_STATE_BYTES 48u
typedef char sn_adapt_state_fits_[sizeof(sn_adapt_state) == SN_ADAPT_STATE_BYTES ? 1 : -1];
SN_INLINE sn_adapt_state *sn_ad(const sn_ihdr *h) {
    return (sn_adapt_state *)(void *)((unsigned char *)(uintptr_t)h + h->v.instance_bytes);
}

typedef char sn_ihdr_fits_[sizeof(sn_ihdr) <= SN_HDR_BYTES ? 1 : -1];

#define ARR(h, off, T) ((T *)(void *)((unsigned char *)(h) + (h)->off))
#define CARR(h, off, T) ((const T *)(const void *)((const unsigned char *)(h) + (h)->off))
/* v.flags: sn_instance_init_shared's instance: its scratch lives in the workspace each
 * sn_step_with passes, whose address the state keeps right after the header for the
 * step's duration (NULL between steps: the header has no room for it); v.instance_bytes
 * is then the offset of adaptation's state */
#define SN_VIEW_SHARED 0x40000000u
#define SN_WS_SLOT SN_HDR_BYTES /* the workspace pointer's bytes in a shared instance */
#define SN_WS_SLOT_BYTES 8u
/* Base of the scratch arrays (o_acc, o_r, o_row, o_rx, o_L, the blended mode's):
 * the instance itself, or the step's workspace. Valid only inside a step
 * (written before read there: tests/test_runtime_workspace.c). */
SN_INLINE unsigned char *sn_ws(const sn_ihdr *h) {
    unsigned char *self = (unsigned char *)(uintptr_t)h;
    unsigned char *ws;
    if (!(h->v.flags & SN_VIEW_SHARED)) return self;
    memcpy(&ws, self + SN_WS_SLOT, sizeof ws);
    return ws;
}
#define WARR(h, off, T) ((T *)(void *)(sn_ws(h) + (h)->off))
#define CWARR(h, off, T) ((const T *)(const void *)(sn_ws(h) + (h)->off))

/* Force-like values of free vertex i are Q(SN_Q_FORCE + k_i), k_i in
 * [0, SN_KMAX] (see sn_instance_init): the stiffest vertex gets Q19, three
 * bits of headroom over the Q22 lengths for violent poses. */
#define SN_Q_FORCE 19
#define SN_KMAX 15
#define SN_KREL(k) ((int)(k) + SN_Q_FORCE - SN_Q_LEN) /* bits relative to Q22 */

/* A free vertex lies in at most this many cells (true of any hex lattice);
 * the unclamped per-vertex accumulation of cell forces relies on it
 * (checked by sn_instance_init). */
#define SN_MAX_VERTEX_CELLS 8u

#define RB (SN_REAL_BYTES)
SN_INLINE sn_q rd_real(const unsigned char *sec, uint32_t idx) {
    return SN_RD_REAL(sec + (size_t)idx * RB);
}

#if defined(SN_FLOAT)
#define ONE_COEF 1.0f
#else
#define ONE_COEF ((int32_t)1 << SN_Q_COEF)
#endif

/* Scale by a Q24 coefficient: v * c >> 24 */
SN_INLINE sn_q coef(sn_q v, sn_q c, uint32_t *sat) { return sn_mulq(v, c, SN_Q_COEF, sat); }

SN_INLINE sn_ihdr *hdr_of(sn_instance *inst) { return (sn_ihdr *)(void *)inst; }
SN_INLINE const sn_ihdr *chdr_of(const sn_instance *inst) {
    return (const sn_ihdr *)(const void *)inst;
}
/* The check every public call on an instance starts with: SN_ERR_NULL, or
 * SN_ERR_INSTANCE when the memory does not hold an initialised instance. */
SN_INLINE sn_status inst_status(const sn_instance *inst) {
    if (!inst) return SN_ERR_NULL;
    return chdr_of(inst)->magic == SN_INST_MAGIC ? SN_OK : SN_ERR_INSTANCE;
}
#define SN_CHECK_INST(inst) do { sn_status st_ = inst_status(inst); if (st_ != SN_OK) return st_; } while (0)

/* Saturating counter increment (stats never wrap). */
SN_INLINE uint32_t sn_count(uint32_t c, uint32_t add) {
    return c > UINT32_MAX - add ? UINT32_MAX : c + add;
}

#if !defined(SN_FLOAT)
/* number of significant bits of x (0 for 0); fixed 6-step search */
SN_INLINE int bitlen64(uint64_t x) {
    int n = 0, s;
    for (s = 32; s > 0; s >>= 1) {
        uint64_t hi = x >> s;
        int take = hi != 0;
        n += take ? s : 0;
        x = take ? hi : x;
    }
    return n + (x != 0);
}
SN_INLINE int32_t clamp32(int64_t x) {
    return x > INT32_MAX ? INT32_MAX : (x < INT32_MIN ? INT32_MIN : (int32_t)x);
}
#endif

/* ---- saturating public-vector arithmetic (fixed: int32 Q16.16 could overflow
 * for extreme but valid inputs; float: plain) ---- */
SN_INLINE sn_real pub_add(sn_real a, sn_real b) {
#if defined(SN_FLOAT)
    return a + b;
#else
    return clamp32((int64_t)a + b);
#endif
}
SN_INLINE sn_real pub_sub(sn_real a, sn_real b) {
#if defined(SN_FLOAT)
    return a - b;
#else
    return clamp32((int64_t)a - b);
#endif
}

/* ---- unit conversion between public (Q16.16 mesh) and internal (Q22 U) ---- */
#if defined(SN_FLOAT)
SN_INLINE sn_q pub_to_int(const sn_ihdr *h, float pub) { return pub * h->to_int; }
SN_INLINE sn_real int_to_pub(const sn_ihdr *h, sn_q v) { return v * h->to_pub; }
#else
sn_q pub_to_int_sat(const sn_ihdr *h, int64_t pub, uint32_t *sat);
int64_t int_to_pub64(const sn_ihdr *h, sn_q v);
#endif

/* ---- stages (NUMERICS.md "One step") ---- */
void sn_frames(sn_ihdr *h, uint32_t *sat);          /* 1-2: joints, origin, vertex and cell frames */
void sn_skeleton(sn_ihdr *h, uint32_t *sat);        /* 3: skeleton positions, first-pose placement */
/* Frame origin c of lattice vertex i (free or skeleton) from the joint
 * translations jT of the last frames, as they were built (frame_mode): not
 * stored, the same bits frame_of computed (sn_pose.c). */
void sn_vertex_origin(const sn_ihdr *h, uint32_t i, sn_q c[3]);
void sn_solve(sn_ihdr *h, uint32_t *sat);           /* 4-7: rhs, PCG, update */
#if defined(SN_FLOAT)
/* sn_solve's start apart (sn_solve.c; tests/test_runtime_fold.c): the folded
 * residual r = b - A x0 (rhs_x0), and q = A d by the mat-vec */
void sn_fold_rhs(sn_ihdr *h, sn_q *r, const sn_q *x0, uint32_t *sat);
void sn_fold_matvec(sn_ihdr *h, const sn_q *d, sn_q *q, uint32_t *sat);
#endif
/* acc += R t (t rotated back out of a cell frame, kept at full precision; sn_solve.c, sn_blended.c) */
SN_INLINE void sn_rot_acc(sn_acc acc[3], const sn_q *R, const sn_q t[3]) {
    acc[0] += sn_mul(R[0], t[0]) + sn_mul(R[1], t[1]) + sn_mul(R[2], t[2]);
    acc[1] += sn_mul(R[3], t[0]) + sn_mul(R[4], t[1]) + sn_mul(R[5], t[2]);
    acc[2] += sn_mul(R[6], t[0]) + sn_mul(R[7], t[1]) + sn_mul(R[8], t[2]);
}
void sn_precond(sn_ihdr *h, const sn_q *r, sn_q *z, uint32_t *sat); /* 6: z = C r, block Jacobi or IC(0) (sn_precond.c) */
/* the same with one frame R for every vertex, restricted to mask[i] != 0 (SN_MODE_BLENDED's region, sn_blended.c) */
void sn_precond_region(sn_ihdr *h, const sn_q *R, const uint8_t *mask, const sn_q *r, sn_q *z, uint32_t *sat);
/* with the vertex frames, restricted to mask[i] != 0 (inv 0) or mask[i] == 0 (inv 1): adaptation (sn_adapt.c);
 * sc (or NULL): z = S C S r, S the per-vertex Q30 scales of the reduced operator (sn_adapt_scales) */
void sn_precond_mask(sn_ihdr *h, const uint8_t *mask, int inv, const sn_q *sc, const sn_q *r, sn_q *z, uint32_t *sat);
void sn_limits(sn_ihdr *h, uint32_t *sat);          /* 8 */
void sn_skinned(const sn_ihdr *h, uint32_t i, sn_q s[3], uint32_t *sat); /* free vertex i carried rigidly by its frame (R x_rest + c; sn_health.c) */
void sn_rigs(sn_ihdr *h, sn_q *b, uint32_t *sat);   /* 5: pose controls, b += rig forces (sn_rig.c) */
void sn_controls_reset(sn_ihdr *h);                 /* abstract controls to their baked values */
void sn_forces_rhs(sn_ihdr *h, sn_q *b, uint32_t *sat); /* 5: b += applied forces' fine and coarse shares (sn_force.c) */
void sn_forces_clear(sn_ihdr *h);                   /* after the step: slots emptied */
void sn_segments_reset(sn_ihdr *h);                 /* segment meshes at rest (sn_segment_mesh.c) */
void sn_segments_step(sn_ihdr *h, uint32_t *sat);   /* 8b: segment meshes after the flesh (sn_segment.c) */
/* sn_teleport: every segment mesh moved rigidly with the root, x' = M (x - T0) + T1
 * (M the root's turn, Q30; T0, T1 the root's internal position before and after),
 * directions, velocities and pending impulses turned by M; expressed against h->origin */
void sn_segments_teleport(sn_ihdr *h, const sn_q M[9], const sn_q T0[3], const sn_q T1[3], uint32_t *sat);
uint64_t sn_segments_hash(const sn_ihdr *h, uint64_t hsh); /* segment state into the FNV-1a hash */
uint64_t sn_fnv_u32(uint64_t hsh, uint32_t x);       /* one little-endian word into the FNV-1a 64 hash (sn_instance.c) */
void sn_health(sn_ihdr *h, uint32_t step_clamps); /* 9: disp, bound steps (energy from sn_solve) */
void sn_crease_step(sn_ihdr *h, uint32_t *sat);    /* 3b: crease list C: detect, drop, n_a, rows (sn_crease.c) */
uint64_t sn_crease_hash(const sn_ihdr *h, uint64_t hsh); /* list C into the FNV-1a hash (unchanged without CREASE) */
void sn_cons_layout(sn_ihdr *h, uint32_t off, uint32_t row); /* records, colliders from off; rows, row state, factor from row (of h->ws; sn_constraint.c) */
uint32_t sn_blend_offset(const sn_ihdr *h);         /* the blended mode's arrays, from h->ws (sn_instance.c) */
void sn_cons_reset(sn_ihdr *h);                     /* no constraints, colliders or rows; counters 0 */

/* ---- level of detail (sn_level.c) ---- */
void sn_level_view(const unsigned char *top, uint32_t lod, sn_view *v); /* view of level lod of a validated blob */
void sn_k_table(sn_ihdr *h);                        /* per free vertex force exponents k_i of the active level (sn_instance.c) */
void sn_frames_refresh(sn_ihdr *h, uint32_t *sat);  /* joint translations, vertex and cell frames for the pose in force (sn_pose.c) */

/* ---- shared by the outputs, forces and segment meshes (sn_embed.c) ---- */
void sn_pub_point(const sn_ihdr *h, const sn_q p[3], sn_vec3 *out);  /* origin + p, public units */
void sn_trilinear(const uint32_t t[3], sn_q phi[8]);                  /* corner weights at t (Q15), Q30 */
void sn_surface_point(const sn_ihdr *h, uint32_t s, sn_q out[3]);    /* surface vertex s, internal */
#if defined(SN_FLOAT)
void sn_k_fnormals(sn_vec3 *out, uint32_t n);     /* summed normals -> unit, in place (sn_kernels_fnorm.c) */
void sn_k_fnormals_ref(sn_vec3 *out, uint32_t n); /* the same, a vertex at a time (tests) */
#endif

/* Twice the elastic + kinetic energy of the step's starting state in
 * internal units (fixed: Q32, summed with saturation at 2^62), set by
 * sn_solve; converted to joules by sn_health. */
void sn_set_energy(sn_ihdr *h, sn_acc e2);

#endif /* SN_INSTANCE_H */
