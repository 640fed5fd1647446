/* sn_format.h -- byte layout of a Sinew blob (format 6.5).
 *
 * Shared by the runtime (reader), the host tool (writer) and the tests'
 * double-precision reference (reader). Prose spec: runtime/BLOB.md.
 * Everything is little-endian; offsets are from the first byte of the blob.
 * Scalars called "real" are 4 bytes (int32 fixed point in flavour 0, IEEE
 * float32 in flavour 1) or 8 bytes (IEEE float64, flavour 2, host/tests only).
 */
#ifndef SN_FORMAT_H
#define SN_FORMAT_H

#include <stdint.h>

#define SN_MAGIC0 'S'
#define SN_MAGIC1 'N'
#define SN_MAGIC2 'W'
#define SN_MAGIC3 'B'
#define SN_FORMAT_MAJOR 6
#define SN_FORMAT_MINOR 5
#define SN_ENDIAN_MARK 0x01020304u   /* stored LE: bytes 04 03 02 01 */
#define SN_ONE_FIXED 0x40000000u     /* 1.0 in Q30 */
#define SN_ONE_FLOAT32 0x3F800000u   /* 1.0f */
/* flavour 2 (float64) stores the low 32 bits of 1.0 (0) and the high 32 bits
 * (0x3FF00000) in the reserved word at SN_H_ONE_HI. */
#define SN_ONE_FLOAT64_HI 0x3FF00000u

#define SN_FLAVOUR_FIXED 0
#define SN_FLAVOUR_FLOAT32 1
#define SN_FLAVOUR_FLOAT64 2

/* ---- header: SN_HEADER_BYTES bytes, then the sections ---- */
#define SN_H_MAGIC          0   /* u8[4] "SNWB" */
#define SN_H_VER_MAJOR      4   /* u16 */
#define SN_H_VER_MINOR      6   /* u16 */
#define SN_H_ENDIAN         8   /* u32 SN_ENDIAN_MARK */
#define SN_H_CRC32         12   /* u32 CRC-32 (IEEE/zlib) of bytes [16, total_size) */
#define SN_H_TOTAL_SIZE    16   /* u32 size of the whole blob in bytes */
#define SN_H_HEADER_SIZE   20   /* u32 == SN_HEADER_BYTES */
#define SN_H_FLAVOUR       24   /* u8  SN_FLAVOUR_* */
#define SN_H_REAL_SIZE     25   /* u8  4 or 8: bytes per real */
#define SN_H_NSECTIONS     26   /* u8  == SN_SEC_COUNT */
#define SN_H_FLAGS         27   /* u8  SN_FLAG_* bits; others 0 */
#define SN_H_ONE           28   /* u32 1.0 in the flavour (SN_ONE_*; 0 for float64) */
#define SN_H_N_VERTICES    32   /* u32 lattice vertices nV (free first, then skeleton) */
#define SN_H_N_FREE        36   /* u32 free vertices nF, 1 <= nF < nV */
#define SN_H_N_CELLS       40   /* u32 nC */
#define SN_H_N_JOINTS      44   /* u32 nJ, 1..255 */
#define SN_H_N_SURFACE     48   /* u32 nS surface vertices, <= 65535 */
#define SN_H_N_TRIANGLES   52   /* u32 nT */
#define SN_H_N_OFFDIAG     56   /* u32 nnz off-diagonal mass blocks */
#define SN_H_INSTANCE_BYTES 60  /* u32 instance memory the runtime needs */
#define SN_H_CG_DEFAULT    64   /* u16 default CG iterations, >= 1 */
#define SN_H_CG_MAX        66   /* u16 max CG iterations, >= default, <= 256 */
#define SN_H_LEN_SHIFT     68   /* i8  internal length unit = 2^len_shift mesh units */
#define SN_H_FRAC_S        69   /* u8  fractional bits of stiffness entries (fixed) */
#define SN_H_FRAC_M        70   /* u8  fractional bits of mass entries (fixed) */
#define SN_H_FRAC_P        71   /* u8  fractional bits of preconditioner entries (fixed) */
#define SN_H_ONE_HI        72   /* u32 high word of 1.0 for float64, else 0 */
#define SN_H_FRAC_E        76   /* i8  fractional bits of the ENERGY real (fixed flavour; 0 otherwise), -40..60 */
#define SN_H_FRAC_F        77   /* i8  fractional bits of the FORCE real (fixed flavour; 0 otherwise), -40..60 */
#define SN_H_MAX_FORCES    78   /* u8  external force slots per step (sn_apply_force), 0..SN_MAX_FORCES */
#define SN_H_RESERVED1     79   /* u8  0 */
/* physics scalars: SN_H_NREALS reals, at SN_H_REALS + i*real_size */
#define SN_H_REALS         80
#define SN_R_A1             0   /* h*alpha (Rayleigh mass term), fixed Q24, >= 0 */
#define SN_R_B1             1   /* beta/h (Rayleigh stiffness term), fixed Q24, >= 0 */
#define SN_R_GRAV_X         2   /* h^2 g in internal length units, fixed Q22 */
#define SN_R_GRAV_Y         3
#define SN_R_GRAV_Z         4
#define SN_R_TIMESTEP       5   /* h in seconds, fixed Q16.16 */
#define SN_R_MASS_SCALE     6   /* m0 in kg (informational), fixed Q16.16 */
#define SN_R_ENERGY         7   /* joules per internal energy unit, m0 (U unit)^2 / h^2, fixed Q frac_E, > 0 */
#define SN_R_CELL           8   /* lattice cell edge in internal length units, fixed Q22, > 0 */
#define SN_R_DISP_BOUND     9   /* health bound on the distance of a free vertex from its skinned position, cells, fixed Q16.16, > 0 */
#define SN_R_FORCE         10   /* right-hand-side units per newton, h^2 / (m0 U unit), fixed Q frac_F, > 0 */
#define SN_R_RESERVED11    11   /* 0 */
#define SN_H_NREALS        12
#define SN_H_SECTIONS     176   /* section table: SN_SEC_COUNT x {u32 offset, u32 size, u32 count, u32 elem_size} */
#define SN_SECTION_ENTRY   16

/* header flags */
#define SN_FLAG_REST_MODELLED 1u /* the modelled shape is the rest-pose equilibrium: the runtime adds -m^_i R_i g^ (NUMERICS.md) */
#define SN_HEADER_BYTES   (SN_H_SECTIONS + SN_SEC_COUNT * SN_SECTION_ENTRY)

/* ---- sections, in this order; each starts 8-byte aligned; size = count*elem_size
 * (elem_size as listed, with R = real size); padding bytes between sections are 0.
 * Sections appear in ascending offset order and do not overlap. ---- */
enum {
    SN_SEC_JOINTS = 0,   /* nJ  x {u16 parent (0xFFFF root; else < own index), u16 0, u32 0, R rest[3]} ; rest Q22 internal, model space = relative to the root joint (joint 0 rests at 0) */
    SN_SEC_JOINT_NAMES,  /* nJ  x char[32], NUL-terminated, NUL-padded, unique, non-empty */
    SN_SEC_REST,         /* nV  x R[3] rest position, Q22 internal units, model space (relative to root joint rest) */
    SN_SEC_FRAMES,       /* nV  x {u8 bone1, u8 bone2, u16 w Q15 (0..32768)}; R_i = slerp(R_b1, R_b2, w), c_i = (1-w)t_b1 + w t_b2
                            skeleton vertices: bone1 = the joint whose transform moves them, bone2 = bone1, w = 0 */
    SN_SEC_MDIAG,        /* nF  x R      M^_ii (Q frac_M) */
    SN_SEC_PRECOND,      /* nF  x R[6]   inverse of (1+a1) M^_ii I + (1+b1) S^_ii, symmetric xx yy zz xy xz yz (Q frac_P); S^_ii = sum over cells of S^_e,ii */
    SN_SEC_MLUMP,        /* nF  x R      row sums of M^ over all nV columns (Q frac_M) */
    SN_SEC_ROWPTR,       /* (nF+1) x u32 row i's off-diagonal blocks are [rowptr[i], rowptr[i+1]); rowptr[0]=0, rowptr[nF]=nnz */
    SN_SEC_COLS,         /* nnz x u16   column vertex; within a row strictly increasing, > i (upper triangle + all skeleton columns) of the mass pattern */
    SN_SEC_MOFF,         /* nnz x R     M^_ij (Q frac_M) */
    SN_SEC_CELLS,        /* nC  x u16[8] corner vertices, corner k at (k&1, k>>1&1, k>>2&1) of the cell box; distinct */
    SN_SEC_CFRAMES,      /* nC  x {u8 bone1, u8 bone2, u16 w Q15}: cell frame R_e = slerp(R_b1, R_b2, w) (seed 003 end of 3.3) */
    SN_SEC_CELLK,        /* nC  x the cell's stiffness S^_e, block (a,b)[3i+j] = S^_e[3a+i][3b+j], S^_e,ba = S^_e,ab^T.
                            float flavours: 36 x R[9], upper blocks (a <= b) in order (0,0) (0,1) .. (0,7) (1,1) .. (7,7).
                            fixed (format 6.0, SN_CELLK_FIXED_BYTES): i32 diag[8][6] (blocks (a,a), symmetric xx yy zz xy
                            xz yz, Q frac_S, |.| <= 2^27), i16 m[28][9] (blocks (a,b), a < b, in order (0,1) .. (0,7)
                            (1,2) .. (6,7), |m| <= 2^15 - 1), u8 e[28] (their exponents, <= 12): entry = m 2^e (Q frac_S) */
    SN_SEC_LIMIT,        /* nF x R, or count 0 (no limits): largest distance of free vertex i from its skinned position, internal units (Q22), 0 = none */
    SN_SEC_EMBED,        /* nS  x {u16 cell, u16 t[3] Q15 (0..32768)} trilinear coordinates in the cell */
    SN_SEC_TRIS,         /* nT  x u16[3] surface vertex indices, counter-clockwise seen from outside */
    /* ---- rig forces (seed 003 §4, eq. 11-12), format 3.0; all five may have count 0 ---- */
    SN_SEC_CONTROLS,     /* nK x {char name[32] (NUL-terminated, NUL-padded, unique, non-empty), u8 kind (SN_CTL_*),
                            u8 joint (ANGLE: < nJ; ABSTRACT: 0), u16 0, u32 0,
                            R axis[3] (ANGLE: unit axis in rest model axes, fixed Q30; ABSTRACT: 0),
                            R value0 (ABSTRACT: value after init/reset, public units; ANGLE: 0)}; nK <= SN_MAX_CONTROLS */
    SN_SEC_RIGS,         /* nR x {u16 control (< nK), u8 n_samples (1..SN_RIG_MAX_SAMPLES), i8 frac (fixed: SN_RIG_FRAC_MIN..MAX, else 0),
                            u32 first_sample, u32 first_entry, u32 n_entries}; rig a's samples and entries follow rig a-1's
                            (first_sample/first_entry are running sums starting at 0; the totals are the next sections' counts) */
    SN_SEC_RIG_SAMPLES,  /* sum of n_samples x {R gamma (public control units: fixed Q16.16), R eta (fixed Q30, |eta| <= 1)};
                            gamma strictly increasing within a rig. tau_a(gamma) = piecewise-linear eta, clamped at the ends */
    SN_SEC_RIG_VERTS,    /* sum of n_entries x u16 free vertex (< nF), strictly increasing within a rig */
    SN_SEC_RIG_FORCES,   /* sum of n_entries x R[3]: the rig's generalized force Q^a_i at eta = 1 in the vertex's rest frame,
                            in the units of the right-hand side (h^2 Q / (m0 U), NUMERICS.md) (fixed: Q frac of the rig;
                            float: |.| <= SN_RIG_FLOAT_MAX) */
    /* ---- external forces (seed 004 ch. 4 on the lattice), format 4.0; both may have count 0 ---- */
    SN_SEC_SHARES,       /* nP x R[SN_LEVELS] share profile: the part of an applied force taken by the fine lattice, the coarse
                            levels 1..SN_LEVELS-2 (regions of 2^k cells) and the rigid level (the joint wrench), fixed Q30,
                            each >= 0, summing to exactly 2^30 (float: within 2^-20 of 1); nP <= SN_MAX_PROFILES.
                            Count 0: every force goes to the fine lattice */
    SN_SEC_VSHARE,       /* nF x u8 profile of free vertex i (< nP), or count 0 (profile 0, or all-fine without profiles) */
    /* ---- segment meshes (seed 004 ch. 3-4), format 4.0; all three may have count 0 ---- */
    SN_SEC_SEGMESH,      /* nM x {u8 kind (SN_SEG_*), u8 levels, u8 sweeps (1..SN_SEG_MAX_SWEEPS), u8 flags (SN_SEGF_*), u16 side,
                            u16 n_attach, u32 first_node, u32 first_attach, R seg_len (Q22 internal, > 0),
                            R gamma (translation factor, Q30, (0, 1]), R keep (velocity kept per step, Q30, [0, 1]),
                            R inv_mass (m0 / segment mass, Q16.16, > 0), R centre (share of a node force applied at the
                            segments' centres, seed 004 §3.2.2, Q30, [0, 1]), R share[4] (force share per level, finest
                            first, Q30, sum 2^30), u8 coarse_sweeps (levels l >= 1, 1..SN_SEG_MAX_SWEEPS),
                            u8 relax (over-relaxation of the sweeps' corrections, omega = relax/32,
                            SN_SEG_RELAX_ONE..SN_SEG_RELAX_MAX, omega (1 - gamma) <= 1), u16 0 (format 6.2)};
                            nM <= SN_SEG_MAX_MESHES.
                            chain: side = nodes (2..SN_SEG_MAX_SIDE), levels 1; sheet: side = 2^n + 1 (3..SN_SEG_MAX_SHEET),
                            levels 1..min(n+1, 4). first_node / first_attach are running sums from 0 */
    SN_SEC_SEGNODES,     /* sum of nodes x R[3]: rest node positions, model space, Q22 (sheets row-major) */
    SN_SEC_SEGATTACH,    /* sum of n_attach x {u16 node (< the mesh's nodes), u8 kind (SN_SEGATT_*), u8 0, u16 target, u16 0,
                            R point[3] (JOINT: attachment point at rest, model space Q22; SURFACE: 0)} */
    /* ---- constraints and contact (seed 000 §4.4, seed 003 §3.4 eq. 9), format 5.0; count 0 or 1 ---- */
    SN_SEC_CONSTRAINTS,  /* 0 or 1 x {u8 max_constraints (0..SN_MAX_CONSTRAINTS), u8 max_colliders (0..SN_MAX_COLLIDERS),
                            u16 max_contacts (0..SN_MAX_CONTACTS), u32 0}; 3 max_constraints + max_contacts (+ CREASE's
                            max_active) <= SN_MAX_ROWS. Count 0: no constraints, colliders or contacts */
    /* ---- self-collision near creases (seed 003 §3.4), format 5.0; all four have count 0, or CREASE has count 1 ---- */
    SN_SEC_CREASE,       /* 0 or 1 x {u16 max_list (1..SN_CREASE_MAX_LIST), u16 max_active (1..min(max_list, SN_CREASE_MAX_ACTIVE)),
                            u8 nbr_v (1..SN_CREASE_MAX_NBR_V), u8 nbr_t (1..SN_CREASE_MAX_NBR_T), u16 rows (nQ, 1..nS; format 6.0), u32 0,
                            R depth (deepest detected penetration, Q22 internal, [1, SN_CREASE_DEPTH_MAX]),
                            R push (push-out cap per step, Q22, [0, depth]),
                            R exclude (format 6.0: a triangle with a corner closer than this to the vertex in the rest
                            pose is no collision, Q22, [0, SN_CREASE_EXCLUDE_MAX])} */
    SN_SEC_CREASE_PAIRS, /* nD x {u16 i, u16 j}: the seed set D, surface vertices i != j (< nS), in the order found; nD <= SN_CREASE_MAX_PAIRS */
    SN_SEC_CREASE_VNBR,  /* nQ * nbr_v x u16 (format 6.0: only the vertices the runtime can query, sparse): row q = the surface
                            vertices near its owner s (s itself first, then by ring, then index), unused tail entries
                            SN_CREASE_NONE; every entry < nS; owners (first entries) strictly increasing over q */
    SN_SEC_CREASE_TNBR,  /* nQ * nbr_t x u16: row q = the triangles touching a vertex of VNBR row q, increasing, unused tail
                            entries SN_CREASE_NONE; every entry < nT */
    /* ---- level of detail (issue 13; runtime/LEVELS.md), format 6.0; all three have count 0, or LEVEL_BLOB holds the
       finer level and the two maps carry the state between the levels (sn_set_lod) ---- */
    SN_SEC_LEVEL_BLOB,   /* n x u8: the finer level (level 1): a complete blob of this format, flavour and length unit (its own
                            lattice, cells, matrices, embedding, rigs), whose three LEVEL sections have count 0 and whose
                            joints, surface, controls, segment meshes, crease and constraint sections equal this blob's */
    SN_SEC_LEVEL_UP,     /* nV(level 1) x {u16 cell, u16 t[3] Q15}: each level-1 lattice vertex in a cell of this (level 0) lattice */
    SN_SEC_LEVEL_DOWN,   /* nV(level 0) x {u16 cell, u16 t[3] Q15}: each level-0 lattice vertex in a cell of the level-1 lattice */
    /* ---- IC(0) preconditioner (issue 15 item 3, runtime/SOLVER_STUDY.md §1), format 6.0; count 0 or nFF ---- */
    SN_SEC_ICHOL,        /* nFF x {i16 m[9], u8 frac, u8 0}: the unit upper factor U = (I + L^)^T - I of the rest-frame
                            A0 = (1+a1) M^ + (1+b1) sum_e S^_e ~ (I + L^) D (I + L^)^T, block U_ji = L^_ij^T (row j < column i),
                            entry [3a+b] = m[3a+b] 2^-frac, |m| <= 2^15-1, frac <= SN_ICHOL_FRAC_MAX; one element per
                            free-free entry of the mass pattern (COLS j < nF), in ROWPTR/COLS order, skeleton columns skipped;
                            nFF = those entries' count. With ICHOL, PRECOND holds D^-1 (same format); count 0: block Jacobi */
    /* ---- adaptation (seed 000 §4.7, runtime/LEVELS.md §3), format 6.1; count 0, or 1 in a blob with LEVEL_BLOB ---- */
    SN_SEC_ADAPT,        /* 0 or 1 x {u16 max_active (A_max, 0..nF of level 1), u16 0, u32 0, R refine, R coarsen (Q22 internal,
                            0 <= coarsen <= refine <= SN_ADAPT_MAX)}: level 1's detail vertices (free, at no level-0 vertex) are
                            active while their detail stays >= coarsen, join at >= refine, at most A_max of them (sn_adapt.c) */
    /* ---- the cut level (issue 13; runtime/LEVELS.md §2 "The cut level"), format 6.3; both count 0, or CELLX has
       count nC: level 0's hats cut at level 1's skeleton, whose vertices are extra skeleton vertices of this lattice ---- */
    SN_SEC_CELLX,        /* nC x {u16 x[19]: the extra skeleton vertex (nF..nV-1) at each non-corner point of the cell's closure
                            (half-cell points p + 3q + 9r, p, q, r in 0..2, corners skipped, in that order), SN_CUT_NONE where
                            the cut field is the cell's trilinear one; u8 nx (the entries not SN_CUT_NONE), u8 0,
                            u32 first (its first CELLXK block: 8 nx blocks per cell, running sum from 0)} */
    SN_SEC_CELLXK,       /* sum of 8 nx blocks: for each cell, each extra in x[] order, corners 0..7: the cut element's block
                            [corner rows x extra columns], entry [3i+j] = K_E[3a+i][3x+j] (Q frac_S, as CELLK).
                            fixed: {i16 m[9], u8 e (<= SN_CELLK_EXP_MAX), u8 0}, entry = m 2^e, |m| <= 2^15 - 1;
                            float: R[9], |entry| <= 2^27 */
    /* ---- the frames' shared work (issue 15; BLOB.md "Frame references"), format 6.4; both count 0 (every frame
       computed alone), or FREFS has count nF + nC ---- */
    SN_SEC_FPAIRS,       /* nFP x {u8 bone1, u8 bone2}: the distinct bone pairs the frames slerp between, bone1 != bone2 (< nJ),
                            strictly increasing as bone1 << 8 | bone2 (so nFP <= nJ (nJ - 1)); their slerp parts are computed
                            once a step (sn_qslerp_pair) */
    SN_SEC_FREFS,        /* nF + nC x u32, the free vertices' FRAMES entries then the CFRAMES entries (one index i over both):
                            SN_FREF_BONE for an entry that does not slerp (bone1 = bone2 or w = 0: the bone's rotation);
                            SN_FREF_PAIR | p for the first entry of its (bone1, bone2, w), slerped from pair p (< nFP, the
                            same bones); a < i for a repeat: the frame of entry a (the same 4 bytes), copied */
    /* ---- details on the cut level (issue 13 item 2; runtime/LEVELS.md §3 "Details on the cut level"), format 6.5; all
       four count 0, or (with CELLX) DETAILS 1, DETAIL nD >= 1, CELLD nC: level 1's free vertices at the non-corner
       points of the cut level's cells, each a level-1 hat added to the cut field (the hierarchical basis) ---- */
    SN_SEC_DETAILS,      /* 0 or 1 x {u16 max_active (A_max, 0..nD), u8 dshift (fixed: CELLDK's blocks are in
                            Q(frac_S - dshift), 0..SN_DETAIL_SHIFT_MAX; float 0), u8 0, u32 0, R refine, R coarsen (Q22 internal,
                            0 <= coarsen <= refine <= SN_ADAPT_MAX)}: at most A_max details active, joining at an estimate
                            >= refine, staying while their coefficient >= coarsen */
    SN_SEC_DETAIL,       /* nD x {u16 cell (< nC), u8 point (its half-cell point p + 3q + 9r in that cell's closure, not a
                            corner), u8 0, R rest[3] (Q22 internal, as REST: the point at rest)}: CELLD of that cell names
                            this detail at that point */
    SN_SEC_CELLD,        /* nC x {u16 d[19]: the detail (< nD) at each non-corner point of the cell's closure (CELLX's
                            order), SN_CUT_NONE where none (and wherever CELLX has an extra); u8 nd (entries set), u8 0,
                            u32 first (its first CELLDK element: nd (8 + nx) + nd (nd + 1) / 2 per cell, running sum)} */
    SN_SEC_CELLDK,       /* per cell, per detail j in d[] order, columns: corners 0..7, the cell's extras in x[] order, the
                            details k >= j in d[] order: the cut element's block [detail row x column], entry [3i+j] =
                            K_E[3d+i][3col+j] (Q frac_S - dshift), and the mass M_E[d][col] / m0 (Q frac_M, as MOFF;
                            > 0 for k = j). fixed: {i16 m[9], u8 e (<= SN_CELLK_EXP_MAX), u8 0, i32 mass}, entry = m 2^e,
                            |m| <= 2^15 - 1; float: {R[9], R mass}; |entry|, |mass| <= 2^27 */
    SN_SEC_COUNT
};

/* Sizes of section elements in bytes, given the real size R (4 or 8). */
#define SN_ELEM_JOINTS(R)  (8 + 3 * (R))
#define SN_ELEM_JOINT_NAMES 32
#define SN_ELEM_REST(R)    (3 * (R))
#define SN_ELEM_FRAMES      4
#define SN_ELEM_MDIAG(R)   (R)
#define SN_ELEM_PRECOND(R) (6 * (R))
#define SN_ELEM_MLUMP(R)   (R)
#define SN_ELEM_ROWPTR      4
#define SN_ELEM_COLS        2
#define SN_ELEM_MOFF(R)    (R)
#define SN_ELEM_CELLS       16
#define SN_ELEM_CFRAMES      4
/* CELLK: the fixed flavour stores int16 mantissas with a per-block exponent
 * for the 28 off-diagonal blocks and the 8 diagonal blocks as 6 int32 (the
 * null-space rule's exact row sums, runtime/NUMERICS.md "Stiffness storage") */
#define SN_ELEM_CELLK(flavour, R) ((flavour) == SN_FLAVOUR_FIXED ? SN_CELLK_FIXED_BYTES : 36 * 9 * (R))
#define SN_CELLK_FIXED_BYTES 724    /* 8 x 6 x 4 + 28 x 9 x 2 + 28 */
#define SN_CELLK_DIAG 0             /* fixed: i32 diag[8][6] */
#define SN_CELLK_OFF 192            /* fixed: i16 m[28][9] */
#define SN_CELLK_EXP 696            /* fixed: u8 e[28] */
#define SN_CELLK_EXP_MAX 12         /* m 2^e <= (2^15 - 1) 2^12 < 2^27, the entry bound */
#define SN_CELLK_M_MAX 32767
/* index of off-diagonal block (a,b), a < b: row r holds the 7 - r blocks (r,r+1)..(r,7) */
#define SN_CELLK_OFFIDX(a, b) ((uint32_t)(a) * 7u - ((uint32_t)(a) * ((uint32_t)(a) - 1u)) / 2u + (uint32_t)(b) - (uint32_t)(a) - 1u)
#define SN_ELEM_LIMIT(R)   (R)
#define SN_CELL_BLOCKS      36
#define SN_ELEM_EMBED       8
#define SN_ELEM_TRIS        6
#define SN_ELEM_CONTROLS(R) (40 + 4 * (R))
#define SN_ELEM_RIGS        16
#define SN_ELEM_RIG_SAMPLES(R) (2 * (R))
#define SN_ELEM_RIG_VERTS   2
#define SN_ELEM_RIG_FORCES(R) (3 * (R))
#define SN_ELEM_SHARES(R)   (SN_LEVELS * (R))
#define SN_ELEM_VSHARE      1
#define SN_ELEM_SEGMESH(R)  (20 + 9 * (R))
#define SN_ELEM_SEGNODES(R) (3 * (R))
#define SN_ELEM_SEGATTACH(R) (8 + 3 * (R))
#define SN_ELEM_CONSTRAINTS 8
#define SN_ELEM_CREASE(R)   (12 + 3 * (R))
#define SN_ELEM_CREASE_PAIRS 4
#define SN_ELEM_CREASE_VNBR  2
#define SN_ELEM_CREASE_TNBR  2
#define SN_ELEM_LEVEL_BLOB   1
#define SN_ELEM_LEVEL_MAP    8
#define SN_ELEM_ADAPT(R)   (8 + 2 * (R))
#define SN_ADAPT_MAX ((int32_t)1 << 30) /* Q22: 256 internal units, beyond any detail (|p| <= SN_LIM = 2^28) */
#define SN_ELEM_CELLX       44
#define SN_CUT_MAXX         19   /* non-corner points of a cell's closure at half cells */
#define SN_CUT_NONE         0xFFFFu
#define SN_ELEM_CELLXK(flavour, R) ((flavour) == SN_FLAVOUR_FIXED ? 20 : 9 * (R))
#define SN_ELEM_FPAIRS       2
#define SN_ELEM_FREFS        4
#define SN_FREF_BONE        0xFFFFFFFFu
#define SN_FREF_PAIR        0x80000000u
/* instance bytes per frame pair: its slerp part (sn_slerp_pair, sn_internal.h), the step's scratch */
#define SN_FPAIR_BYTES      40u
#define SN_ELEM_DETAILS(R)  (8 + 2 * (R))
#define SN_ELEM_DETAIL(R)   (4 + 3 * (R))
#define SN_ELEM_CELLD       44
#define SN_ELEM_CELLDK(flavour, R) ((flavour) == SN_FLAVOUR_FIXED ? 24 : 10 * (R))
#define SN_DETAIL_SHIFT_MAX 4    /* a detail's own block is at most 2^4 of the largest corner block's scale */
#define SN_DETAIL_CELL_MAX  342u /* CELLDK elements of one cell: nd (8 + nx) + nd (nd + 1) / 2, nd + nx <= 19 */
#define SN_ELEM_ICHOL       20   /* every flavour: int16 mantissas, one exponent per block */
#define SN_ICHOL_FRAC_MAX   47   /* forward sweep shift frac + k_j - k_i <= 62 (k <= 15) */

/* self-collision near creases (seed 003 §3.4; sn_crease.c, NUMERICS.md "Self-collision") */
#define SN_CREASE_MAX_LIST   256u   /* collision list C entries (eq. 8) */
#define SN_CREASE_MAX_ACTIVE 64u    /* active constraints pushed per step */
#define SN_CREASE_MAX_NBR_V  32u    /* vertices per neighbourhood row */
#define SN_CREASE_MAX_NBR_T  64u    /* triangles per neighbourhood row */
#define SN_CREASE_MAX_PAIRS  4096u  /* seed pairs D */
#define SN_CREASE_DEPTH_MAX  ((int32_t)1 << 26) /* Q22: 16 internal units */
#define SN_CREASE_EXCLUDE_MAX ((int32_t)1 << 28) /* Q22: 64 internal units (its square <= 2^56, NUMERICS.md) */
#define SN_CREASE_NONE       0xFFFFu
/* crease state bytes (multiple of 8): the step's surface positions (3 reals
 * per surface vertex), the list (8 bytes per entry), one membership byte and
 * (format 6.0) one byte "position computed this step" per surface vertex;
 * 0 without CREASE. Its max_active rows per step are part of the constraint
 * rows (SN_ROWS_CAP, SN_CONS_BYTES). */
#define SN_CREASE_STATE_BYTES(nS, max_list) \
    ((14u * (uint32_t)(nS) + 8u * (uint32_t)(max_list) + 7u) & ~7u)

/* external forces: levels fine, coarse 1..3 (2, 4, 8 cells), rigid */
#define SN_LEVELS 5
#define SN_MAX_PROFILES 255u
#define SN_MAX_FORCES 32u
#define SN_FORCE_SLOT_BYTES 64u   /* instance bytes per force slot */
#define SN_WRENCH_BYTES 48u       /* instance bytes per joint: force and torque (fixed: int64 sums; float: 6 floats) */

/* segment meshes */
#define SN_SEG_CHAIN 0
#define SN_SEG_SHEET 1
#define SN_SEGF_NO_GRAVITY 1u      /* the mesh feels no gravity (the thesis' experiments) */
#define SN_SEG_MAX_LEVELS 4u
#define SN_SEGATT_SURFACE 0       /* target = surface vertex: follows the deformed surface */
#define SN_SEGATT_JOINT 1         /* target = joint: point moves with the joint's transform */
#define SN_SEG_MAX_MESHES 64u
#define SN_SEG_MAX_SIDE 256u
#define SN_SEG_MAX_SHEET 65u
#define SN_SEG_MAX_SWEEPS 64u
#define SN_SEG_RELAX_ONE 32u   /* relax byte of omega = 1 (plain Gauss-Seidel) */
#define SN_SEG_RELAX_MAX 63u   /* omega < 2: SOR converges for omega in (0, 2) */
#define SN_SEG_SEG_BYTES 64u      /* instance bytes per segment (state of every level) */
#define SN_SEG_NODE_BYTES 24u     /* instance bytes per node (every level) */
/* Segments and nodes of a mesh over all its levels (sheet level l has side
 * (side-1)/2^l + 1; a 2x2 coarsest level carries two braces, seed 004 fig. 4.4).
 * Arguments must be validated (kind, side, levels). */
static inline void sn_seg_counts(unsigned kind, unsigned side, unsigned levels, uint32_t *segs, uint32_t *nodes) {
    unsigned l;
    *segs = 0; *nodes = 0;
    if (kind == SN_SEG_CHAIN) { *segs = side - 1u; *nodes = side; return; }
    for (l = 0; l < levels; l++) {
        uint32_t s = ((side - 1u) >> l) + 1u;
        *segs += 2u * s * (s - 1u) + (s == 2u ? 2u : 0u);
        *nodes += s * s;
    }
}

/* constraints and contact (runtime/NUMERICS.md "Constraints and contact") */
#define SN_MAX_CONSTRAINTS 64u   /* user constraints (sn_set_constraints), up to 3 rows each */
#define SN_MAX_COLLIDERS 16u     /* world colliders (sn_set_colliders) */
#define SN_MAX_CONTACTS 256u     /* contact rows per step */
#define SN_MAX_ROWS 512u         /* constraint rows per step, every producer together */
#define SN_CON_BYTES 80u         /* instance bytes per user constraint */
#define SN_COL_BYTES 64u         /* instance bytes per collider */
#define SN_ROW_BYTES 120u        /* instance bytes per row (sn_row, runtime/src/sn_constraint.h) */
#define SN_ROWAUX_BYTES 16u      /* instance bytes per row of factorization state */
/* Rows per step: the sum of every producer's baked maximum (user constraints
 * give up to 3 rows each, a contact one, crease collision its max_active). */
#define SN_ROWS_CAP(ncon, ncontacts, ncrease) (3u * (uint32_t)(ncon) + (uint32_t)(ncontacts) + (uint32_t)(ncrease))
/* Instance bytes of the constraint state: records, rows, per-row state and the
 * packed lower-triangular Cholesky factor of the rows' Gram matrix (int32/float). */
#define SN_CONS_BYTES(ncon, ncol, nrows) \
    ((uint32_t)(ncon) * SN_CON_BYTES + (uint32_t)(ncol) * SN_COL_BYTES + \
     (uint32_t)(nrows) * (SN_ROW_BYTES + SN_ROWAUX_BYTES) + 4u * ((uint32_t)(nrows) * ((uint32_t)(nrows) + 1u) / 2u))

/* control kinds (CONTROLS.kind) */
#define SN_CTL_ABSTRACT 0   /* set by the game: sn_set_control */
#define SN_CTL_ANGLE    1   /* read from the pose each step: angle (degrees) of joint's rotation relative to its parent about axis */
#define SN_CONTROL_NAME_MAX 32
#define SN_MAX_CONTROLS 256u
#define SN_MAX_RIGS 4096u
#define SN_RIG_MAX_SAMPLES 16u
/* fixed: eta (Q30) x Q (Q frac) >> (30 + frac - 19 - k_i), k_i in [0,15]: the shift stays in [1, 61] */
#define SN_RIG_FRAC_MIN 5
#define SN_RIG_FRAC_MAX 50
/* float: |Q| bound so eta * Q summed over every rig stays finite */
#define SN_RIG_FLOAT_MAX 1048576.0f

#define SN_JOINT_NAME_MAX 32
#define SN_MAX_JOINTS 255
#define SN_MAX_SURFACE 65535u
#define SN_MAX_VERTICES 65535u
#define SN_MAX_CG_ITERS 256u
/* A stored row holds only neighbours j > i of a hex lattice vertex: at most 26.
 * The runtime relies on it to sum a row's own blocks without clamping. */
#define SN_MAX_ROW_BLOCKS 26u
/* The cut level (CELLX): a free vertex's row also holds the extra skeleton vertices on its
 * cells' closures, at most the 5^3 - 3^3 = 98 half-cell points of its 8 cells with an odd
 * coordinate; the mass pass's row sum (1 + 124 products < 2^55) and a free vertex's accumulator
 * (its row plus <= 26 transposed free blocks: 151 products) stay < 2^62.3. */
#define SN_MAX_ROW_BLOCKS_CUT 124u

/* Fixed-point formats of the internal state (flavour 0). */
#define SN_Q_LEN 22   /* internal lengths, velocities per step (h*v), forces (m0 * unit) */
#define SN_Q_ROT 30   /* quaternions, rotation matrices */
#define SN_Q_W   15   /* frame weights, trilinear coordinates */
#define SN_Q_COEF 24  /* a1, b1 */

/* Instance memory the runtime needs for a blob (bytes, multiple of 8), for
 * writers (the host tool, the tests' blob writers). The runtime's layout
 * (sn_instance.c, sn_instance_bytes) is the source; the validator requires
 * the header to equal it, and test_runtime_blob checks this macro against it. */
#define SN_INSTANCE_HDR_BYTES 832u /* the instance header before the arrays (format 6.0: 768 before; the level of detail, the four level and ICHOL section pointers) */
/* nFrc: force slots (header MAX_FORCES); segB: the extra state bytes before
 * the constraint state: the segment state, the sum over meshes of
 * SN_SEG_SEG_BYTES segs + SN_SEG_NODE_BYTES nodes (sn_seg_counts), plus the
 * crease state SN_CREASE_STATE_BYTES (0 without a CREASE section; a multiple
 * of 8, so the sum rounds as the runtime's separate arrays do);
 * plus the frame pairs' scratch, SN_FPAIR_BYTES per FPAIRS entry (format 6.4;
 * the largest level's count; 0 without: the runtime places it after the
 * constraint state, a multiple of 8, so the total is the same);
 * conB: constraint state bytes, SN_CONS_BYTES of the CONSTRAINTS record and
 * the crease rows (0 without either). Per vertex 24 (position, velocity),
 * per free vertex 96 + 1 (accumulators, frame, CG vectors x r q -- z and w
 * share q's storage; k_i), and 12 max(nF, nV - nF) for d, whose storage the
 * skeleton's velocity change shares. */
#define SN_INSTANCE_BYTES(nV, nF, nJ, nC, nK, nFrc, segB, conB) \
    ((((SN_INSTANCE_HDR_BYTES + (76u + SN_WRENCH_BYTES) * (uint32_t)(nJ) + 24u * (uint32_t)(nV) + 96u * (uint32_t)(nF) + \
      12u * ((uint32_t)(nV) - (uint32_t)(nF) > (uint32_t)(nF) ? (uint32_t)(nV) - (uint32_t)(nF) : (uint32_t)(nF)) + \
      (uint32_t)(nF) + 36u * (uint32_t)(nC) + 4u * (uint32_t)(nK) + \
      SN_FORCE_SLOT_BYTES * (uint32_t)(nFrc) + (uint32_t)(segB) + 7u) & ~7u) + (uint32_t)(conB) + 7u) & ~7u)

#endif /* SN_FORMAT_H */
