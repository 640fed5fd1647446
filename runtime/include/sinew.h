/* sinew.h -- Sinew runtime: skeleton-driven elastic secondary motion.
 *
 * One header, prefix sn_. C99, compiles as C++. The runtime never allocates,
 * performs no I/O, uses no libm and no recursion.
 *
 * Flavours. By default the runtime is built in fixed point (integers only,
 * bit-identical on every platform). Define SN_FLOAT when building the runtime
 * AND when including this header to get the float flavour of the same source.
 * A blob is baked for one flavour; loading it into the other is an error
 * (SN_ERR_FLAVOUR).
 *
 * Threads. The runtime has no mutable global state (no statics written, no
 * locks, no thread-local storage): everything a call changes is in the
 * instance passed to it. So:
 *   - one instance is used by one thread at a time (calls on the same
 *     instance from two threads at once need the caller's own lock);
 *   - different instances can be stepped on different threads at once, with
 *     no synchronisation, and give exactly the results of stepping them one
 *     after another;
 *   - a blob is shared read-only by any number of instances and threads
 *     (it is never written after sn_blob_validate; it can sit in ROM).
 * tests/integration/threads checks this (8 threads, also under ThreadSanitizer).
 *
 * Units and number formats of the public API (fixed flavour / float flavour):
 *   lengths      sn_real, Q16.16 mesh units        / float mesh units
 *   quaternions  sn_real, Q30 (1.0 = 1<<30)         / float
 *   angles       sn_real, Q16.16 degrees            / float degrees
 *   normals      sn_real, Q30 unit vectors          / float unit vectors
 * "Mesh units" are the units of the OBJ the asset was baked from. "Model
 * space" is the OBJ's frame with its origin moved to the root joint's rest
 * position (the host tool does this so internal numbers stay small): add that
 * position (printed by sinew-bake) to outputs to draw them in OBJ coordinates.
 *
 * Typical use:
 *   const sn_blob *blob;
 *   if (sn_blob_validate(bytes, nbytes, &blob) != SN_OK) ...;   // once
 *   size_t need = sn_instance_size(blob);                        // caller owns memory
 *   sn_instance *inst;
 *   sn_instance_init(mem, need, blob, &inst);
 *   each frame: sn_pose_from_local(...) or your own bone transforms,
 *               sn_set_pose(inst, xforms, n_joints); sn_step(inst);
 *               sn_get_surface(inst, out, 0, n_surface);
 * Many instances on a thread: sn_instance_init_shared with
 * sn_instance_state_size(blob) bytes each, stepped by sn_step_with with one
 * workspace of sn_workspace_size(blob, mode) bytes (see "Shared workspace").
 */
#ifndef SINEW_H
#define SINEW_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// Version of this header and of the blob format it reads (major.minor).
#define SN_VERSION_MAJOR 4
#define SN_VERSION_MINOR 0

#if defined(SN_FLOAT)
/// Scalar type of the public API: float in the float flavour.
typedef float sn_real;
/// Flavour code stored in blobs: 0 fixed (int32), 1 float32, 2 float64 (host/reference only).
#define SN_FLAVOUR 1
#else
/// Scalar type of the public API: int32 fixed point in the fixed flavour (see Q formats above).
typedef int32_t sn_real;
/// Flavour code stored in blobs: 0 fixed (int32), 1 float32, 2 float64 (host/reference only).
#define SN_FLAVOUR 0
#endif

/// Fractional bits of public lengths in the fixed flavour (Q16.16 mesh units).
#define SN_LEN_FRAC 16
/// Fractional bits of public quaternion components and normals in the fixed flavour (Q30).
#define SN_QUAT_FRAC 30
/// Fractional bits of public angles in the fixed flavour (Q16.16 degrees).
#define SN_ANGLE_FRAC 16

/// Three-component vector (position in mesh units, or a unit normal).
typedef struct sn_vec3 { sn_real x, y, z; } sn_vec3;
/// Unit quaternion (x, y, z vector part; w scalar part).
typedef struct sn_quat { sn_real x, y, z, w; } sn_quat;
/// Rigid bone motion x -> R(rot) x + pos, mapping rest (model) space to the current pose.
typedef struct sn_xform { sn_quat rot; sn_vec3 pos; } sn_xform;

/// Every status code and its message, in one list (X-macro).
#define SN_STATUS_LIST(X) \
    X(SN_OK,            "ok") \
    X(SN_ERR_NULL,      "a required pointer argument is NULL") \
    X(SN_ERR_ALIGN,     "pointer is not 8-byte aligned") \
    X(SN_ERR_TRUNCATED, "blob is shorter than its header or its stated size") \
    X(SN_ERR_MAGIC,     "not a Sinew blob (bad magic)") \
    X(SN_ERR_VERSION,   "unsupported blob format version") \
    X(SN_ERR_ENDIAN,    "blob byte-order marker is wrong (corrupt or other endianness)") \
    X(SN_ERR_FLAVOUR,   "blob flavour (fixed/float) does not match this runtime build") \
    X(SN_ERR_CHECKSUM,  "blob checksum mismatch (corrupt)") \
    X(SN_ERR_HEADER,    "blob header field out of range") \
    X(SN_ERR_SECTION,   "blob section offset/size/count inconsistent or out of bounds") \
    X(SN_ERR_INDEX,     "an index stored in the blob is out of range") \
    X(SN_ERR_VALUE,     "a number stored in the blob is out of its allowed range") \
    X(SN_ERR_MEMORY,    "instance memory is smaller than sn_instance_size() (workspace: sn_workspace_size())") \
    X(SN_ERR_ARG,       "argument out of range") \
    X(SN_ERR_INSTANCE,  "instance memory does not hold an initialised instance") \
    X(SN_ERR_FULL,      "every slot the blob provides for this step is taken")

/// Status code returned by every fallible call. Never mixed with data.
typedef enum sn_status {
#define SN_STATUS_ENUM_(name, msg) name,
    SN_STATUS_LIST(SN_STATUS_ENUM_)
#undef SN_STATUS_ENUM_
    SN_STATUS_COUNT
} sn_status;

/// Human-readable message for a status code; never NULL.
const char *sn_status_str(sn_status s);

/// A validated, read-only blob. The handle points at the caller's bytes, which
/// must stay valid and unchanged while any instance uses them (ROM is fine).
typedef struct sn_blob sn_blob;

/// An instance: all mutable simulation state, living in caller memory.
/// The handle equals the memory pointer given to sn_instance_init(). The memory
/// holds no pointers into itself, so a byte copy (memcpy) of sn_instance_size()
/// bytes (sn_instance_state_size() for an sn_instance_init_shared instance) to
/// another 8-byte aligned buffer is a snapshot that can be stepped or copied
/// back (rollback, replay). It does point at its blob.
typedef struct sn_instance sn_instance;

/// Counts and settings of a blob.
typedef struct sn_blob_info {
    uint32_t vertices;          ///< lattice vertices (free + skeleton)
    uint32_t free_vertices;     ///< simulated lattice vertices
    uint32_t cells;             ///< hexahedral lattice cells
    uint32_t joints;            ///< skeleton joints (one rigid transform each)
    uint32_t surface_vertices;  ///< embedded mesh vertices
    uint32_t triangles;         ///< surface triangles (may be 0)
    uint32_t offdiag_blocks;    ///< stored off-diagonal 3x3 stiffness blocks
    uint32_t cg_iters_default;  ///< CG iterations per step unless overridden
    uint32_t cg_iters_max;      ///< largest accepted override
    uint32_t instance_bytes;    ///< == sn_instance_size()
    uint32_t blob_bytes;        ///< total blob size
    uint32_t controls;          ///< control parameters (sn_find_control), abstract and pose-driven
    uint32_t rigs;              ///< rig force fields driven by the controls
    uint32_t rig_entries;       ///< (rig, free vertex) force entries: the rigs' per-step cost
    uint32_t force_slots;       ///< external forces (sn_apply_force / sn_apply_impulse) accepted per step
    uint32_t force_profiles;    ///< share profiles baked for them (0: every force acts on the fine lattice)
    uint32_t max_constraints;   ///< position constraints sn_set_constraints accepts (0: none)
    uint32_t max_colliders;     ///< colliders sn_set_colliders accepts (0: none)
    uint32_t max_contacts;      ///< contact rows enforced per step (surface points touching colliders)
    uint32_t max_rows;          ///< constraint rows per step, every producer together (3 per constraint + contacts)
    sn_real  timestep;          ///< h in seconds (fixed: Q16.16)
} sn_blob_info;

/// Validate untrusted blob bytes once: header, checksum, every offset, size,
/// count, index and numeric range. On SN_OK *out is the handle; after that no
/// call re-checks the blob. data must be 8-byte aligned.
sn_status sn_blob_validate(const void *data, size_t size, const sn_blob **out);

/// Fill *info from a validated blob.
void sn_blob_get_info(const sn_blob *blob, sn_blob_info *info);

/// Name of joint j (NUL-terminated, at most 31 chars), or NULL if j is out of range.
const char *sn_joint_name(const sn_blob *blob, uint32_t j);
/// Parent of joint j, or -1 for the root (and for j out of range). Parents precede children.
int32_t sn_joint_parent(const sn_blob *blob, uint32_t j);
/// Rest position of joint j in mesh units (model space). Returns SN_ERR_ARG if j is out of range.
sn_status sn_joint_rest(const sn_blob *blob, uint32_t j, sn_vec3 *out);
/// Index of the joint called name, or -1.
int32_t sn_find_joint(const sn_blob *blob, const char *name);

/// Bytes of instance memory the blob needs (8-byte aligned buffer).
size_t sn_instance_size(const sn_blob *blob);

/// Initialise an instance in caller memory (mem 8-byte aligned, mem_size >=
/// sn_instance_size(blob)); the instance starts at rest with the rest pose.
/// SN_ERR_INDEX if a free lattice vertex has more than 26 stored mass
/// neighbours or is a corner of more than 8 cells (properties of hex lattices
/// the overflow-free arithmetic relies on).
sn_status sn_instance_init(void *mem, size_t mem_size, const sn_blob *blob, sn_instance **out);

/// Back to rest: rest pose, zero displacement and velocity, cleared warm start
/// and counters, abstract controls at their baked values. Keeps iteration
/// count and mode. SN_ERR_NULL / SN_ERR_INSTANCE (nothing happens) if inst is
/// not an initialised instance.
sn_status sn_reset(sn_instance *inst);

/// Set the pose for the next sn_step: one transform per joint (rest model space
/// to world). The first pose after init/reset also becomes the previous pose,
/// so it causes no velocity jump.
/// SN_ERR_ARG, and nothing changes, if any joint's quaternion is shorter than
/// 2^-10 in its largest component (no reliable direction) or, in float, any
/// value is not finite or a translation is beyond +-32768 mesh units.
/// Quaternion signs are tracked (q is negated when it is nearer -q_previous),
/// so frames between two bones interpolate the way the joint really turned,
/// past 180° too: feed poses continuously, a joint turning less than 180° per
/// step. A pose far from the last one (a teleport, a cut) goes through
/// sn_teleport (keeps the motion) or sn_reset (back to rest).
sn_status sn_set_pose(sn_instance *inst, const sn_xform *joints, uint32_t n_joints);

/// Teleport: a discontinuous pose change (respawn, camera cut, root snapped
/// across the map). Like sn_set_pose, but the flesh is carried rigidly with
/// the skeleton: every lattice vertex keeps its offset from its frame
/// (p' = R'_i R_i^T (p - c_i) + c'_i), its velocity and warm start turn by the
/// same rotation, and the instance's origin jumps to the new root position,
/// so local deformation and jiggle survive the jump with no saturation and
/// no velocity spike (from a healthy state, whose flesh lies within the
/// format's range of its frames; a state already torn apart by clamped
/// steps clamps again, counted, as any step would). The new pose is also the previous pose of the next step
/// (call sn_set_pose with the following pose as usual). Before the first
/// step after init/reset it is sn_set_pose. Refusals as sn_set_pose.
/// Without it, sn_set_pose with a large jump is bounded but not rigid: the
/// origin moves at most 64 internal units per step, clamping (counted) the rest.
sn_status sn_teleport(sn_instance *inst, const sn_xform *joints, uint32_t n_joints);

/// Forward kinematics: local joint rotations (each about the joint's rest
/// position, axes of the rest/model frame, relative to its parent) plus a
/// translation of the root joint -> per-joint transforms for sn_set_pose.
/// local[j] and out[j] have sn_blob_info.joints entries. root_offset may be NULL.
void sn_pose_from_local(const sn_blob *blob, const sn_quat *local,
                        const sn_vec3 *root_offset, sn_xform *out);

/// Advance one timestep h with the current pose. Cost is fixed by the blob and
/// the iteration count: no data-dependent loop exits (its bound includes, in
/// the float flavour, one zeroing of the solver's warm start, 12 bytes a free
/// lattice vertex, in a step whose right-hand side clamps). Stack: under 3 KB
/// on the Cortex-M4 (peaks 2,568 B for the cow, 2,512 B on its cut level);
/// x86-64 worst case 3,552 B (gcc -O2), which tests/scripts/test_runtime_rules.sh
/// prints per entry point: the frames' shared work is in the blob (format 6.4). SN_ERR_NULL or
/// SN_ERR_INSTANCE (nothing happens) if inst is not an initialised instance;
/// SN_ERR_MEMORY (nothing happens) for an sn_instance_init_shared instance,
/// which steps with sn_step_with.
sn_status sn_step(sn_instance *inst);

/// Override the CG iteration count (1..cg_iters_max); 0 restores the blob default.
sn_status sn_set_iterations(sn_instance *inst, uint32_t iterations);

/// Stepping modes.
typedef enum sn_mode {
    SN_MODE_WARPED = 0,   ///< skeletally warped linear FEM (seed 003 eq. 7), the default
    SN_MODE_UNWARPED = 1, ///< global linear FEM, all frames R = I (seed 000 fig. 5), for comparison
    SN_MODE_BLENDED = 2   ///< blended local linearization (seed 000 §4.5, eq. 18, 22-24), for comparison: one
                          ///< linear solve per bone carrying flesh, in that bone's frame, merged with the skinning
                          ///< weights; constraint and contact rows are not applied. Needs the larger
                          ///< sn_instance_size_mode(blob, SN_MODE_BLENDED) at sn_instance_init.
} sn_mode;
/// Select the stepping mode; takes effect at the next step. SN_ERR_ARG for an
/// unknown mode; SN_ERR_MEMORY for SN_MODE_BLENDED if the instance was
/// initialised with less than sn_instance_size_mode(blob, SN_MODE_BLENDED) bytes.
sn_status sn_set_mode(sn_instance *inst, sn_mode mode);
/// Bytes of instance memory for stepping in this mode: sn_instance_size(blob)
/// for warped and unwarped; more for SN_MODE_BLENDED (its per-region solve's
/// vectors, scratch only). Pass it as mem_size to sn_instance_init; a byte copy
/// of such an instance needs this many bytes too. 0 if blob is NULL.
size_t sn_instance_size_mode(const sn_blob *blob, sn_mode mode);

/* ---- Shared workspace: many instances, one copy of the step's scratch ----
 * Part of an instance is scratch: written before it is read within every
 * step (CG vectors, the step's constraint rows and their packed Cholesky
 * factor, the blended mode's vectors). An instance made by
 * sn_instance_init_shared holds only its persistent state; each
 * sn_step_with borrows the scratch from a workspace the caller passes.
 * One workspace per thread serves every instance that thread steps, one
 * after another, of any blob it is large enough for (the largest
 * sn_workspace_size). The instance stores no pointer to the workspace, so a
 * byte copy of its sn_instance_state_size() bytes is a snapshot as before,
 * and the workspace's contents between steps mean nothing (tests fill it
 * with garbage before every step). Every other call (getters, setters,
 * sn_reset, sn_teleport, sn_set_lod, sn_set_adapt, hash, stats) works on
 * the state alone, as for sn_instance_init's instances.
 *
 *   size_t ws = sn_workspace_size(blob, SN_MODE_WARPED);  // per thread
 *   size_t st = sn_instance_state_size(blob);             // per instance
 *   sn_instance_init_shared(mem[i], st, blob, &cow[i]);
 *   for (i...) { sn_set_pose(cow[i], ...); sn_step_with(cow[i], work, ws); }
 */

/// Bytes of persistent state of one sn_instance_init_shared instance of this
/// blob: what survives between steps (positions, velocities, warm start,
/// frames, pose tracking, controls, forces, segment and crease state,
/// constraint settings, adaptation, counters). 0 if blob is NULL.
size_t sn_instance_state_size(const sn_blob *blob);

/// Bytes of workspace sn_step_with needs for this blob in this mode (the
/// blended mode needs more). Its memory is 8-byte aligned. 0 if blob is NULL.
size_t sn_workspace_size(const sn_blob *blob, sn_mode mode);

/// sn_instance_init for an instance without its own scratch: mem_size >=
/// sn_instance_state_size(blob), mem 8-byte aligned; same errors. It steps
/// with sn_step_with (sn_step refuses it); SN_MODE_BLENDED needs no larger
/// state, only sn_workspace_size(blob, SN_MODE_BLENDED) at each step.
sn_status sn_instance_init_shared(void *mem, size_t mem_size, const sn_blob *blob, sn_instance **out);

/// sn_step using workspace (bytes long, 8-byte aligned) for the step's scratch:
/// the same state, bit for bit, as sn_step on an sn_instance_init instance.
/// The workspace may be shared by any number of instances stepped one at a
/// time (one per thread); its contents before and after the call are
/// irrelevant. SN_ERR_NULL for a NULL workspace, SN_ERR_ALIGN if misaligned,
/// SN_ERR_MEMORY if bytes < sn_workspace_size(blob, mode in force): nothing
/// happens then. An sn_instance_init instance ignores workspace and steps
/// with its own scratch (sn_step).
sn_status sn_step_with(sn_instance *inst, void *workspace, size_t bytes);

/// Deformed lattice vertex positions (mesh units, world), vertices [first, first+count).
/// Vertex order is the blob's: free vertices first, then skeleton vertices.
sn_status sn_get_lattice(const sn_instance *inst, sn_vec3 *out, uint32_t first, uint32_t count);

/// Deformed surface (mesh) vertex positions, vertices [first, first+count), in mesh order.
sn_status sn_get_surface(const sn_instance *inst, sn_vec3 *out, uint32_t first, uint32_t count);

/// Area-weighted unit vertex normals of the deformed surface, from positions
/// produced by sn_get_surface for all surface vertices. SN_ERR_ARG if the
/// blob has no triangles. out has sn_blob_info.surface_vertices entries.
sn_status sn_get_normals(const sn_instance *inst, const sn_vec3 *positions, sn_vec3 *out);

/// Surface triangle t as three surface vertex indices; SN_ERR_ARG if out of range.
sn_status sn_get_triangle(const sn_blob *blob, uint32_t t, uint32_t idx[3]);

/// Diagnostics of an instance: a health report per step and since init/reset.
/// Counters saturate at UINT32_MAX instead of wrapping.
typedef struct sn_stats {
    uint32_t steps;        ///< steps since init/reset
    uint32_t saturations;  ///< values clamped to their format since init/reset (fixed: format range; float: runaway guard); 0 in a healthy run
    uint32_t iterations;   ///< CG iterations per step in force
    uint32_t mode;         ///< sn_mode in force
    uint32_t bound_steps;  ///< steps since init/reset in which a baked bound was exceeded (a clamp, or displacement over the blob's bound)
    uint32_t limit_clamps; ///< lattice vertices pulled back to their baked distance limit in the last step
    uint32_t limit_steps;  ///< steps since init/reset with at least one limit clamp
    sn_real  disp;         ///< largest free-vertex distance from its skinned (rigidly warped) position after the last step, in cells (Q16.16 / float)
    sn_real  disp_max;     ///< largest disp since init/reset
    sn_real  energy;       ///< elastic + kinetic energy after the last step, joules (Q16.16 / float); kinetic uses the lumped mass
    sn_real  energy_max;   ///< largest energy since init/reset
    uint32_t cg_clamps;    ///< CG step ratios (alpha, beta) clamped at 8 since init/reset (fixed; 0 in float): rounding-floor noise of a converged solve, not a fault
    uint32_t force_drops;  ///< sn_apply_force / sn_apply_impulse calls refused since init/reset because the step's force slots were full
    sn_real  seg_gap;      ///< largest segment-mesh constraint gap left after the last step's fixed sweeps, in segment lengths (Q16.16 / float)
    sn_real  seg_gap_max;  ///< largest seg_gap since init/reset
    uint32_t crease_list;        ///< self-collision near creases (seed 003 §3.4): pairs in the collision list C after the last step's detection (0 without crease data)
    uint32_t crease_active;      ///< active prefix n_a of C after the last step's detection (constraints produced: at most the blob's max_active)
    uint32_t crease_list_full;   ///< penetrations found but not added since init/reset because C was full (the blob's max_list); lost detections: a vertex counts again each step it stays out, once per search reaching it (NUMERICS.md)
    uint32_t crease_active_over; ///< active constraints not produced since init/reset because max_active was reached or the row store was full
    uint32_t crease_added;       ///< pairs added to C since init/reset
    uint32_t crease_removed;     ///< pairs removed from C since init/reset (vertex back outside, or slid off its triangle)
    uint32_t constraint_rows;    ///< constraint and contact rows enforced in the last step (after drops)
    uint32_t constraint_drops;   ///< rows dropped since init/reset as (nearly) dependent on earlier rows: duplicate, conflicting or rank-deficient constraints (runtime/NUMERICS.md)
    uint32_t contacts;           ///< contact rows collected in the last step
    uint32_t contact_overflow;   ///< contacts not enforced since init/reset because the step's max_contacts were taken
    uint32_t row_overflow;       ///< rows refused since init/reset because the step's rows were full
    uint32_t constraint_refused; ///< constraints or colliders beyond the blob's maxima refused by the setters since init/reset
    uint32_t constraint_clamps;  ///< row targets clamped since init/reset: a constraint to one lattice cell per step (a far or fast target is approached at that speed), a contact to its yield bound (runtime/NUMERICS.md "Contacts")
    uint32_t lod;                ///< level of detail in force (sn_set_lod): 0 the baked lattice, 1 the finer one
    uint32_t lattice_vertices;   ///< lattice vertices of that level (free and skeleton): sn_get_lattice's range
    uint32_t adapt_on;           ///< 1 while adaptation runs (blob with 'adapt', level 1, sn_set_adapt on; or a details blob on the cut level with sn_set_detail_adapt on: the adapt_* fields then count its details; runtime/LEVELS.md §3)
    uint32_t adapt_active;       ///< level-1 detail vertices in the last step's solve (at most the blob's max_active)
    uint32_t adapt_refines;      ///< detail vertices that joined the solve since init/reset (detail estimate >= refine)
    uint32_t adapt_coarsens;     ///< detail vertices that left it since init/reset (detail < coarsen, or pushed out by larger ones)
    uint32_t adapt_overflow;     ///< since init/reset, the sum over steps of the vertices wanting in beyond max_active (the largest details won)
} sn_stats;
/// Self-collision near creases (seed 003 §3.4): the surface vertices in the
/// collision list after the last step's detection, in the order they entered
/// it (the first crease_active of them produced contact constraints). Writes
/// at most max of them into vertices (may be NULL when max is 0) and returns
/// the list's length (0 without crease data or for an invalid instance).
uint32_t sn_get_crease_contacts(const sn_instance *inst, uint32_t *vertices, uint32_t max);

/// Read the diagnostics. SN_ERR_NULL, or SN_ERR_INSTANCE with *out zeroed,
/// if inst is not an initialised instance.
sn_status sn_get_stats(const sn_instance *inst, sn_stats *out);

/// Levels of detail the blob carries (description 'levels N', tools/DESCRIPTION.md;
/// runtime/LEVELS.md): 1, or 2 when it also holds the lattice subdivided once.
/// 0 for a NULL blob.
uint32_t sn_lod_levels(const sn_blob *blob);

/// Switch the level of detail: 0 runs the baked (coarse) lattice, 1 the finer
/// one. The instance was sized for the larger level at init; a step costs
/// what the active level's counts say. The state is carried through the
/// blob's maps: coarse to fine interpolates the coarse displacement field
/// (the surface does not move), fine to coarse samples the fine field at the
/// coarse vertices (the finer detail is dropped). Pending forces and the
/// constraints in force are cleared (they name vertices of the old level);
/// colliders stay. The level survives sn_reset. SN_OK (nothing happens if
/// the level is in force), SN_ERR_ARG for a level the blob does not have.
sn_status sn_set_lod(sn_instance *inst, uint32_t level);

/// Adaptation (seed 000 §4.7; description 'adapt REFINE COARSEN MAX_ACTIVE',
/// runtime/LEVELS.md §3): on level 1, only the detail vertices (those at no
/// level-0 vertex) whose detail is large are simulated, at most the blob's
/// max_active; the others follow the coarse (level-0) field exactly. On by
/// default in a blob baked with 'adapt'; on = 0 simulates every vertex (plain
/// level 1), on = 1 starts again from the first selection (the inactive
/// vertices jump onto the coarse field). Survives sn_reset. SN_OK, or
/// SN_ERR_ARG turning it on in a blob without adaptation data.
sn_status sn_set_adapt(sn_instance *inst, int on);

/// Details on the cut level (description 'details A_MAX REFINE COARSEN' with
/// 'levels 2 cut'; runtime/LEVELS.md §3): the active set, n ids (< the
/// blob's detail count, no repeat), at most the blob's A_max. Each active
/// detail (a level-1 hat on top of the cut field) is stepped while the cut
/// level is in force (not in SN_MODE_BLENDED). A detail already active keeps
/// its state; one entering starts at coefficient 0 and velocity 0 (the surface
/// does not move); one leaving drops its coefficient. sn_reset empties the
/// set. SN_ERR_ARG (nothing changes) for n > A_max, an id out of range or
/// repeated, or n > 0 on a blob without details; SN_ERR_NULL for ids NULL with n > 0.
/// The details' rows are preconditioned by their own diagonal only (for now):
/// they need more CG iterations than the cut level: while at most 25 details
/// are active the step runs at least 8 CG iterations, above that at least 32
/// (within the blob's maximum; below these the runs drift from the converged
/// ones by more than 0.01 cell, LEVELS.md §3 "The floor, measured").
sn_status sn_details_set(sn_instance *inst, const uint16_t *ids, uint32_t n);

/// Details chosen by the runtime (stage 3, runtime/LEVELS.md §3; off by default): after each step on the cut level an active detail stays while |c| >= coarsen, an inactive one joins when its static estimate >= refine, at most A_max (the blob's `details A_MAX REFINE COARSEN`); sn_stats' adapt_* fields report it; SN_ERR_ARG turning it on in a blob without details.
sn_status sn_set_detail_adapt(sn_instance *inst, int on);

/// 64-bit FNV-1a hash of a little-endian serialization of the simulation state
/// (free positions, velocities, warm start, skeleton state, step count, control
/// values), the same on every platform. Used by the determinism tests. 0 if
/// inst is NULL or not an initialised instance.
uint64_t sn_state_hash(const sn_instance *inst);

/* ---- rig controls (seed 003 §3-4: Theta = (alpha, beta), rig forces eq. 11-12) ----
 * A rig is a force field on the flesh, baked by the host tool, whose strength
 * follows one control through a piecewise-linear map (clamped at its first
 * and last sample). Abstract controls (beta: "breath", "smile") are set by
 * the game; pose controls (alpha) are read from the pose inside sn_step: the
 * angle of a joint's rotation relative to its parent about a baked axis (the
 * twist part of a swing-twist decomposition, in (-180, 180] degrees), so a
 * biceps can bulge as the elbow bends with nothing to drive. Rig forces turn
 * with the skeleton (each vertex's frame) and cost the same every step. */

/// Kinds of control parameter.
typedef enum sn_control_kind {
    SN_CONTROL_ABSTRACT = 0, ///< set by the game with sn_set_control (fixed: Q16.16, unitless / float)
    SN_CONTROL_ANGLE = 1     ///< read from the pose by sn_step: degrees (fixed: Q16.16 / float)
} sn_control_kind;
/// Index of the control called name, or -1.
int32_t sn_find_control(const sn_blob *blob, const char *name);
/// Name of control c (NUL-terminated, at most 31 chars), or NULL if c is out of range.
const char *sn_control_name(const sn_blob *blob, uint32_t c);
/// Kind of control c (sn_control_kind), or -1 if c is out of range.
int32_t sn_control_kind_of(const sn_blob *blob, uint32_t c);
/// Set abstract control c for the following steps (kept until set again or
/// sn_reset restores the baked value). SN_ERR_ARG, and nothing changes, if c
/// is out of range, is a pose control, or (float) value is not finite.
sn_status sn_set_control(sn_instance *inst, uint32_t c, sn_real value);
/// Current value of control c: an abstract control as set, a pose control as
/// the last step measured it (0 before the first step). SN_ERR_ARG if c is out of range.
sn_status sn_get_control(const sn_instance *inst, uint32_t c, sn_real *value);

/* ---- external forces and impulses (seed 004 ch. 4 applied to the lattice) ----
 * A force acts on a material point of the flesh during the next sn_step
 * (then its slot empties). Its share profile (baked per region of the
 * character, or chosen per call) splits it over levels: the fine lattice
 * (a local dent), coarse levels of 2, 4 and 8 cells (the region around the
 * point moves and turns as one piece: the force a rigid body of that region
 * would feel, keeping the total force and moment), and a rigid level that
 * the flesh does not feel, returned to the game per joint by
 * sn_get_joint_wrench (stagger, lean). Every distribution keeps the applied
 * force and moment (runtime/NUMERICS.md "External forces"). The step's cost
 * grows by a fixed amount per applied force (a few passes over the free
 * vertices for each coarse level the profile uses): the caller knows it
 * before stepping; sn_blob_info.force_slots bounds it. */

/// Where an external force acts.
typedef enum sn_force_at {
    SN_AT_SURFACE = 0, ///< surface vertex `vertex`, wherever the flesh carries it
    SN_AT_POINT = 1,   ///< world point `point`: the flesh under it now (the cell whose rest box holds the point, carried back to rest by the nearest lattice vertex's frame; clamped to the nearest cell when outside)
    SN_AT_LATTICE = 2  ///< free lattice vertex `vertex` (sn_set_constraints only; forces refuse it)
} sn_force_at;

/// An external force or impulse on the flesh.
typedef struct sn_force {
    uint32_t at;       ///< sn_force_at
    uint32_t vertex;   ///< SN_AT_SURFACE: surface vertex index
    sn_vec3  point;    ///< SN_AT_POINT: world point, mesh units
    sn_vec3  force;    ///< world axes: newtons (sn_apply_force) or newton-seconds (sn_apply_impulse); fixed: Q16.16
    int32_t  profile;  ///< share profile index (< force_profiles), or -1: the profile baked for the flesh at the point
} sn_force;

/// Apply a force during the next sn_step (one step long). SN_ERR_ARG for a
/// bad vertex, kind or profile (float: non-finite or beyond 1e9);
/// SN_ERR_FULL, counted in sn_stats.force_drops, when the step's
/// force_slots are taken. Nothing changes on an error.
sn_status sn_apply_force(sn_instance *inst, const sn_force *f);
/// Apply an impulse (newton-seconds) in the next sn_step: the force J/h for one step.
sn_status sn_apply_impulse(sn_instance *inst, const sn_force *f);
/// The rigid level's share of the last step's forces (and the parts that fell
/// on skeleton lattice vertices) on joint j: force (newtons) and torque about
/// the joint's current position (newton x mesh units; multiply by metres per
/// mesh unit for N m), summed over the step's forces, split between the two
/// bones of the cell's frame by its weight. about (may be NULL) receives that
/// position (world, mesh units). Fixed: the torque is the exact sum of
/// (point - about) x force in Q32, rounded once to Q16.16. Zero after a step
/// without forces. SN_ERR_ARG if j is out of range.
sn_status sn_get_joint_wrench(const sn_instance *inst, uint32_t joint, sn_vec3 *force, sn_vec3 *torque,
                              sn_vec3 *about);

/* ---- small math helpers (integer-only in the fixed flavour, deterministic) ---- */

/// Unit quaternion for a rotation of angle (degrees) about axis (need not be unit, must be non-zero).
sn_quat sn_quat_axis_angle(sn_vec3 axis, sn_real angle_degrees);
/// Quaternion product a*b (apply b first, then a).
sn_quat sn_quat_mul(sn_quat a, sn_quat b);
/// Spherical linear interpolation along the shorter arc; t in [0,1] (fixed: Q30).
sn_quat sn_quat_slerp(sn_quat a, sn_quat b, sn_real t);
/// Rotate vector v (mesh units) by unit quaternion q.
sn_vec3 sn_quat_rotate(sn_quat q, sn_vec3 v);

/* ---- segment meshes (seed 004 ch. 3-4: Palazzi's displacement constraints) ----
 * Chains (hair, straps, tails) and square sheets (cloth, flags) of rigid
 * segments joined at their ends by displacement constraints: each step the
 * segments move freely under gravity and impulses, then a fixed number of
 * sweeps (baked per mesh) translates and turns them to close the gaps at the
 * nodes. Nodes may be pinned to a surface vertex of the flesh or to a joint.
 * Sheets may spread every force over coarser levels (seed 004 ch. 4): the
 * more goes to the coarse levels, the stiffer the sheet reacts as a whole.
 * The meshes step inside sn_step, after the flesh; their cost is fixed by the
 * blob (runtime/SEGMENTS.md). */

/// Kinds of segment mesh.
typedef enum sn_segment_kind {
    SN_SEGMENT_CHAIN = 0, ///< nodes 0..side-1 in a row, side-1 segments
    SN_SEGMENT_SHEET = 1  ///< side x side nodes (side = 2^n + 1), row-major, segments along rows and columns
} sn_segment_kind;

/// Description of one segment mesh of a blob (finest level).
typedef struct sn_segment_info {
    uint32_t kind;        ///< sn_segment_kind
    uint32_t side;        ///< chain: nodes; sheet: nodes per row
    uint32_t nodes;       ///< nodes (chain: side; sheet: side * side)
    uint32_t segments;    ///< segments (chain: side - 1; sheet: 2 side (side - 1))
    uint32_t levels;      ///< multilevel levels (1: single level; chains always 1)
    uint32_t attachments; ///< nodes pinned to the flesh surface or a joint
} sn_segment_info;

/// Number of segment meshes in a validated blob (0 if blob is NULL).
uint32_t sn_segment_mesh_count(const sn_blob *blob);
/// Describe mesh `mesh`. SN_ERR_NULL for NULL pointers, SN_ERR_ARG if mesh is out of range.
sn_status sn_segment_mesh_info(const sn_blob *blob, uint32_t mesh, sn_segment_info *out);
/// Node positions first .. first+count-1 of mesh `mesh` after the last step
/// (the mean of the segment ends meeting at each node), in world mesh units like
/// sn_get_lattice. Before the first step: the rest positions (model space).
/// SN_ERR_ARG, writing nothing, if mesh or the range is out of range.
sn_status sn_get_segment_nodes(const sn_instance *inst, uint32_t mesh, sn_vec3 *out, uint32_t first,
                               uint32_t count);
/// Per segment first .. first+count-1 of mesh `mesh`: the rigid transform
/// taking the segment's rest placement (model space at rest, in mesh units)
/// to its current world placement, p_world = rot * p_rest + pos, so an
/// artist's mesh can be skinned to the segments as bones. rot is the shortest
/// turn of the segment's direction (the roll about a segment is not
/// simulated). SN_ERR_ARG, writing nothing, if mesh or the range is out of range.
sn_status sn_get_segment_xforms(const sn_instance *inst, uint32_t mesh, sn_xform *out, uint32_t first,
                                uint32_t count);
/// Apply an impulse (newton-seconds, world axes) at node `node` of mesh
/// `mesh` during the next sn_step, shared evenly by the segments meeting at
/// the node (the baked `centre` share at their centres, the rest at their
/// ends, turning them). Impulses add up per node until the step (no slots to
/// run out of; a sum beyond the state range is clamped and counted in
/// sn_stats.saturations). SN_ERR_ARG, and nothing changes, if mesh or node
/// is out of range or (float) a component is not finite.
sn_status sn_apply_segment_impulse(sn_instance *inst, uint32_t mesh, uint32_t node,
                                   sn_vec3 impulse_newton_seconds);
/// Set the floor every segment end of every mesh stays above: the world
/// half-space normal . p >= offset (normal: any length, mesh units; offset:
/// mesh units). Enforced inside the sweeps as a one-sided displacement
/// constraint (a penetrating end is pushed out along the normal, no bounce,
/// no friction). A zero normal removes the floor. A setting: kept by
/// sn_reset. SN_ERR_ARG, and nothing changes, if (float) a value is not finite.
sn_status sn_set_segment_floor(sn_instance *inst, sn_vec3 normal, sn_real offset);

/* ---- position constraints and colliders (seed 000 §4.4, seed 003 §3.4 eq. 9) ----
 * The game pins points of the flesh to world positions and puts world
 * solids (ground, a hand, a rail) in its way. Both become scalar velocity
 * constraints on the lattice ("rows") that the step enforces inside its CG
 * (Baraff-Witkin filtered PCG): at the start of the solve the velocity is
 * made to satisfy them, the CG moves only in the directions they leave free,
 * and its rounding is corrected at the end (runtime/NUMERICS.md "Constraints
 * and contact"). Rows that are (nearly) dependent on earlier ones
 * (duplicates, conflicting targets for the same point, two pins in one cell
 * along one axis) are dropped in list order and counted in
 * sn_stats.constraint_drops. The blob bakes the maxima (sn_blob_info
 * max_constraints, max_colliders, max_contacts), so the instance memory and
 * the step's cost bound are fixed: a step costs O(rows^3 / 6) for the
 * factorization plus O(rows^2 + 16 rows) per CG iteration over the rows in
 * force. Both settings are kept until replaced (a call with count 0 clears)
 * or sn_reset. */

/// sn_constraint.axes: bit per world axis, or SN_AXIS_DIR for one direction.
#define SN_AXIS_X 1u
#define SN_AXIS_Y 2u
#define SN_AXIS_Z 4u
#define SN_AXIS_ALL 7u
#define SN_AXIS_DIR 8u

/// A position constraint: at the end of every step the point is at `target`
/// (along the chosen axes, or along `dir` only). A target farther than one
/// lattice cell from where the point is is approached at one cell per step
/// (counted in sn_stats.constraint_clamps).
typedef struct sn_constraint {
    uint32_t at;      ///< sn_force_at: SN_AT_SURFACE (surface vertex), SN_AT_LATTICE (free lattice vertex), SN_AT_POINT (the flesh under a world point now)
    uint32_t vertex;  ///< SN_AT_SURFACE: surface vertex; SN_AT_LATTICE: free lattice vertex (< free_vertices)
    sn_vec3  point;   ///< SN_AT_POINT: world point, mesh units (the material point there is found once, at the call)
    sn_vec3  target;  ///< world position, mesh units
    uint32_t axes;    ///< SN_AXIS_* bits (0 = all three), or SN_AXIS_DIR
    sn_vec3  dir;     ///< SN_AXIS_DIR: the constrained direction, any length > 0 (normalized); otherwise ignored
} sn_constraint;

/// Replace the constraints in force by list[0 .. count-1] (count 0, list may
/// be NULL: none). Kept until replaced or sn_reset. SN_ERR_ARG, and nothing
/// changes, for a bad kind, vertex (a skeleton lattice vertex is not an
/// unknown), axes or zero direction, or (float) a non-finite value or one
/// beyond 1e9. SN_ERR_FULL if count exceeds max_constraints: the first
/// max_constraints are set and the rest counted in sn_stats.constraint_refused.
sn_status sn_set_constraints(sn_instance *inst, const sn_constraint *list, uint32_t count);

/// Collider shapes.
typedef enum sn_collider_kind {
    SN_COLLIDER_PLANE = 0,   ///< half-space behind the plane through `a` with outward normal `b`
    SN_COLLIDER_SPHERE = 1,  ///< ball of `radius` about `a`
    SN_COLLIDER_CAPSULE = 2  ///< points within `radius` of the segment a-b
} sn_collider_kind;

/// A world solid the surface may not enter.
typedef struct sn_collider {
    uint32_t kind;      ///< sn_collider_kind
    sn_vec3  a;         ///< plane: a point on it; sphere: centre; capsule: one end of its axis (world, mesh units)
    sn_vec3  b;         ///< plane: outward normal (any length > 0); capsule: the other end; sphere: ignored
    sn_real  radius;    ///< sphere, capsule: radius (mesh units, >= 0); plane: ignored
    sn_vec3  velocity;  ///< the solid's velocity, mesh units per second (it moves rigidly, without turning)
    sn_real  friction;  ///< Coulomb coefficient mu >= 0 (0: frictionless): a contact sticks to the solid when its predicted slip is at most mu times the normal velocity change it takes, else slides with its slip reduced by that (runtime/NUMERICS.md; uses contact rows)
} sn_collider;

/// Replace the colliders in force by list[0 .. count-1] (count 0: none).
/// Kept until replaced or sn_reset: set them every frame with the solids'
/// current placement. Each step, every surface vertex is tested against them
/// at the start of the step; a vertex inside, or whose predicted motion
/// (its velocity plus gravity's) would end inside, is held on the surface
/// by a one-sided contact row: the deepest such vertex per (collider,
/// lattice cell), up to max_contacts per step (more: counted in
/// sn_stats.contact_overflow). SN_ERR_ARG, and nothing changes, for a bad
/// kind, a zero plane normal, a negative radius or friction, or (float) a
/// non-finite value or one beyond 1e9. SN_ERR_FULL if count exceeds
/// max_colliders: the first max_colliders are set, the rest counted in
/// sn_stats.constraint_refused.
sn_status sn_set_colliders(sn_instance *inst, const sn_collider *list, uint32_t count);

#ifdef __cplusplus
}
#endif
#endif /* SINEW_H */
