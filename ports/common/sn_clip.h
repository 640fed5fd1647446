/* sn_clip.h -- keyframed skeleton clips for Sinew players (format: CLIP.md):
 * joint rotations, the root translation and rig control tracks.
 *
 * Portable C99 for desktop and bare metal: no allocation, no stdio, no libm,
 * no strtod; only <string.h>. Numbers are parsed by our own decimal reader
 * straight into Q16.16 and all time arithmetic is integer, so the fixed
 * flavour gives bit-identical poses on every platform.
 *
 *   sn_clip clip;                    // caller storage (~25 KB with defaults)
 *   char err[SN_CLIP_ERR_LEN];
 *   if (sn_clip_parse(&clip, text, len, err, sizeof err)) fail(err);
 *   if (sn_clip_bind(&clip, blob, err, sizeof err)) fail(err);
 *   per step k: sn_clip_pose(&clip, blob, k, local_scratch, xforms);
 *               sn_set_pose(inst, xforms, n_joints);
 *               sn_clip_controls(&clip, blob, k, inst);   // control tracks
 *
 * sn_clip_parse needs nothing else; sn_clip_bind / sn_clip_pose call the
 * runtime (sn_find_joint, sn_quat_axis_angle, sn_quat_slerp,
 * sn_pose_from_local, sn_find_control, sn_set_control) and live in
 * sn_clip_pose.c.
 */
#ifndef SN_CLIP_H
#define SN_CLIP_H

#include <stddef.h>
#include <stdint.h>
#include "sinew.h"

#ifndef SN_CLIP_MAX_CHANNELS
/// Most channels in one clip (rotation channels + the root translation channel
/// + control channels).
#define SN_CLIP_MAX_CHANNELS 64
#endif
#ifndef SN_CLIP_MAX_KEYS
/// Most keys in one clip, all channels together.
#define SN_CLIP_MAX_KEYS 1024
#endif
/// Longest joint or control name (bytes, without the NUL), as in the blob.
#define SN_CLIP_NAME_MAX 31
#ifndef SN_CLIP_MAX_WARNINGS
/// Most warnings kept in a parsed clip (more are only counted).
#define SN_CLIP_MAX_WARNINGS 8
#endif
#ifndef SN_CLIP_MAX_SHAPES
/// Most collider placements (collider lines other than 'off') in one clip.
#define SN_CLIP_MAX_SHAPES 32
#endif
/// A good size for the error buffer (and for sn_clip_warning_str).
#define SN_CLIP_ERR_LEN 256

/// Channel kinds: a joint's rotation, the root translation, a rig control,
/// impulses on the flesh (one channel per share profile, named by it), a
/// named collider, a named pin (position constraint).
enum { SN_CLIP_ROT = 0, SN_CLIP_MOVE = 1, SN_CLIP_CONTROL = 2, SN_CLIP_IMPULSE = 3,
       SN_CLIP_COLLIDER = 4, SN_CLIP_PIN = 5 };

/// Pin keys (kind SN_CLIP_PIN): v[0..2] the target (Q16.16 mesh units; unused
/// for HOLD and OFF), v[3] these bits: the vertex, the constrained axes
/// (SN_AXIS_X/Y/Z << SN_CLIP_PIN_AXES_SHIFT), and the flags.
#define SN_CLIP_PIN_VERTEX     0x00FFFFFF  ///< surface or free lattice vertex index
#define SN_CLIP_PIN_AXES_SHIFT 24          ///< 3 bits of SN_AXIS_* (never 0 in a parsed key)
#define SN_CLIP_PIN_LATTICE    (1 << 27)   ///< a free lattice vertex (else a surface vertex)
#define SN_CLIP_PIN_HOLD       (1 << 28)   ///< target: where the point is when the key comes into force
#define SN_CLIP_PIN_OFF        (1 << 29)   ///< the pin is released

/// A collider placement (a collider key's v[0] indexes clip.shapes; -1: off).
/// Q16.16 mesh units (velocity: per second); kind is an sn_collider_kind.
typedef struct sn_clip_shape {
    int32_t a[3], b[3], radius, vel[3], mu;
    uint8_t kind, reserved[3];
} sn_clip_shape;

/// What sn_clip_constraints remembers per pin channel between steps (the
/// target of a 'hold' key). Zero it before the first step and after sn_reset.
typedef struct sn_clip_hold {
    uint32_t key_plus1;   ///< 1 + the key whose position is held (0: none yet)
    sn_vec3  at;          ///< the held position (world, mesh units)
} sn_clip_hold;

/// One key. Q16.16 throughout: t seconds; v = axis x,y,z + angle degrees
/// (rotation), x,y,z mesh units (root translation, v[3] = 0), or the
/// control's value in v[0] (control, v[1..3] = 0), or an impulse's
/// newton-seconds in v[0..2] and its surface vertex in v[3] (impulse), or
/// a shape index in v[0] (collider, -1: off), or a pin (SN_CLIP_PIN_*).
typedef struct sn_clip_key { int32_t t; int32_t v[4]; } sn_clip_key;

/// One channel: keys[first .. first+count) with strictly increasing t.
typedef struct sn_clip_channel {
    char     name[SN_CLIP_NAME_MAX + 1]; ///< joint or control name ("" for the root translation)
    int32_t  joint;                      ///< after sn_clip_bind: joint index (ROT, MOVE: 0) or
                                         ///< control index (CONTROL; -1: not in the blob); else -1
    uint16_t first, count;
    uint8_t  kind;                       ///< SN_CLIP_ROT, _MOVE, _CONTROL, _IMPULSE, _COLLIDER or _PIN
} sn_clip_channel;

/// Two consecutive keys of a rotation channel more than 180 degrees apart as
/// written: the slerp takes the short way, not the turn the text describes.
/// Also exactly 180 apart (apart == taken == 180): the way round is up to rounding.
typedef struct sn_clip_warning {
    uint32_t line;       ///< line of the second key
    uint16_t channel;    ///< index into chan[]
    uint16_t reserved;
    int32_t  t_a, t_b;   ///< the two key times, Q16.16 s
    int32_t  apart;      ///< turn as written, Q16.16 degrees (> 180)
    int32_t  taken;      ///< turn the interpolation makes, Q16.16 degrees (<= 180)
} sn_clip_warning;

/// A parsed clip. Plain data: may be copied, or stored in ROM once parsed.
typedef struct sn_clip {
    int32_t  duration;        ///< Q16.16 seconds, > 0
    uint8_t  loop;            ///< 1: time wraps at duration; 0: holds the end
    uint8_t  bound;           ///< set by sn_clip_bind
    uint16_t n_channels, n_keys;
    uint16_t n_shapes;        ///< collider placements in shapes[]
    uint16_t n_colliders;     ///< collider channels (at most this many in force at once)
    uint16_t n_pins;          ///< pin channels (at most this many constraints at once)
    uint16_t reserved;
    uint32_t error_line;      ///< line of the last parse error (0: none / not line-specific)
    uint32_t n_warnings;      ///< warnings found (the first SN_CLIP_MAX_WARNINGS are in warn[])
    sn_clip_warning warn[SN_CLIP_MAX_WARNINGS];
    sn_clip_channel chan[SN_CLIP_MAX_CHANNELS];
    sn_clip_key     keys[SN_CLIP_MAX_KEYS];
    sn_clip_shape   shapes[SN_CLIP_MAX_SHAPES];
} sn_clip;

/// Parse clip text (len bytes, need not be NUL-terminated) into *clip.
/// Returns 0 on success; otherwise 1 with "line N: what" in err (always
/// NUL-terminated when errlen > 0) and clip->error_line = N. A clip that
/// parses may still carry warnings (clip->n_warnings, sn_clip_warning_str).
int sn_clip_parse(sn_clip *clip, const char *text, size_t len, char *err, size_t errlen);

/// Text of warning i (< min(n_warnings, SN_CLIP_MAX_WARNINGS)) without its
/// line: "joint 'J': keys at A s and B s are D degrees apart; ...". Always
/// NUL-terminated when len > 0; returns the text length (0 for a bad i).
size_t sn_clip_warning_str(const sn_clip *clip, uint32_t i, char *buf, size_t len);

/// Resolve joint names against a blob's skeleton and control names against
/// its controls. Refuses (1, message) a blob whose timestep clip time cannot
/// step (sn_clip_timestep_q16 0). Returns 0, or 1 with a message naming the first joint the
/// blob lacks or the first control channel that names a pose control (read
/// from the pose by sn_step; a clip keys its joint instead). A control the
/// blob lacks is not an error: its channel keeps joint = -1 and is ignored
/// (sn_clip_unbound_controls counts them; players warn).
int sn_clip_bind(sn_clip *clip, const sn_blob *blob, char *err, size_t errlen);

/// Control channels of a bound clip whose control is not in the blob.
uint32_t sn_clip_unbound_controls(const sn_clip *clip);

/// Clip time of step k in Q16.16 seconds: k*h (h = the blob timestep rounded
/// to Q16.16), wrapped (loop) or clamped to the duration. Integer only.
int32_t sn_clip_time(const sn_clip *clip, int32_t h_q16, uint32_t step);

/// Blob timestep as Q16.16 seconds (either flavour), rounded; 0 when clip
/// time cannot step it (h < 2^-17 s rounds to 0, h >= 32768 s overflows
/// Q16.16; the float validator accepts both). sn_clip_bind refuses such a
/// blob, so after a successful bind it is >= 1 and safe to divide by.
int32_t sn_clip_timestep_q16(const sn_blob *blob);

/// Local joint rotations at clip time t (Q16.16 s): slerp between the two
/// surrounding keys, first/last key held outside them, identity for joints
/// without a channel. local has one entry per blob joint. *root gets the
/// root translation (zero without a move channel). Clip must be bound.
void sn_clip_sample(const sn_clip *clip, const sn_blob *blob, int32_t t,
                    sn_quat *local, sn_vec3 *root);

/// Everything for step k: sample at sn_clip_time, then sn_pose_from_local.
/// local (scratch) and out have one entry per blob joint.
void sn_clip_pose(const sn_clip *clip, const sn_blob *blob, uint32_t step,
                  sn_quat *local, sn_xform *out);

/// Value of control channel c (kind SN_CLIP_CONTROL, with keys) at clip time
/// t (Q16.16 s), Q16.16: linear between the two surrounding keys (weight in
/// Q30, rounded half away from zero, as the root translation), the first /
/// last key held outside them. 0 for a channel that is not a control channel
/// or has no keys. Integer only; needs no runtime (in sn_clip.c).
int32_t sn_clip_control_at(const sn_clip *clip, uint32_t c, int32_t t);

/// Control tracks for step k: every bound control channel's value at
/// sn_clip_time(k), set with sn_set_control (fixed: the Q16.16 value as is;
/// float: value / 65536). Returns the number of controls set.
uint32_t sn_clip_controls(const sn_clip *clip, const sn_blob *blob, uint32_t step, sn_instance *inst);

/// Impulse events for step k: every impulse key whose time lies in the step's
/// clip-time interval (sn_clip_time(k-1), sn_clip_time(k)] (across the wrap
/// of a looping clip; none at k = 0), applied with sn_apply_impulse at its
/// surface vertex and profile (-1: the blob's for the flesh there). Returns
/// the number the runtime accepted (a full step's slots refuse the rest).
uint32_t sn_clip_impulses(const sn_clip *clip, const sn_blob *blob, uint32_t step, sn_instance *inst);

/// Colliders in force in step k (the clip's 'collider' channels; CLIP.md
/// "Colliders and pins"): each channel's last key at or before the step's
/// start t = sn_clip_time(k-1), unless it is 'off'; none before a channel's
/// first key. A placement keyed at t_key with velocity v is at p + v (t -
/// t_key) (integer Q16.16, rounded half away from zero). Writes at most max
/// to out in channel order (first appearance in the file); returns how many.
/// Needs no instance: the caller appends them to its own and calls
/// sn_set_colliders.
uint32_t sn_clip_colliders(const sn_clip *clip, const sn_blob *blob, uint32_t step,
                           sn_collider *out, uint32_t max);

/// Position constraints in force in step k (the clip's 'pin' channels): each
/// channel's last key at or before t = sn_clip_time(k) (the step's end, where
/// the runtime puts the point), unless it is 'off'; between that key and the
/// next one of the channel, both with targets and naming the same point and
/// axes, the target is interpolated linearly (as control tracks). A 'hold'
/// key's target is where the point is (sn_get_surface / sn_get_lattice of
/// inst) at the first call the key is in force, kept in hold[] (one entry per
/// channel, SN_CLIP_MAX_CHANNELS, zeroed by the caller before the first
/// step; inst NULL or a vertex it refuses: the origin). Writes at most max
/// to out in channel order; returns how many.
uint32_t sn_clip_constraints(const sn_clip *clip, const sn_blob *blob, uint32_t step,
                             const sn_instance *inst, sn_clip_hold *hold,
                             sn_constraint *out, uint32_t max);

/// Own decimal reader (exported for tests): optional sign, digits, optional
/// '.' and digits; no exponent. Rounds to nearest Q16.16 (half away from
/// zero; digits after the 9th decimal ignored). Returns 0 on success, 1 if
/// not a number, 2 if |value| >= 32768.
int sn_clip_parse_q16(const char *s, size_t n, int32_t *out);

#endif /* SN_CLIP_H */
