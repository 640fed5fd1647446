/* sn_det.h -- the determinism workload shared by every port: validate a blob,
 * put an instance in caller memory, and for step k = 0, 1, ... set the pose of
 * step k (from a clip, or a built-in sequence without one) and call sn_step.
 * No allocation, no stdio: the same code runs hosted and on bare metal, so a
 * hash that differs between ports can only come from the compiler or CPU.
 * Mirrors the desktop player: for k = 1..N: clip pose at step k (time k*h),
 * sn_set_pose, sn_step; hash at the end.
 */
#ifndef SN_DET_H
#define SN_DET_H

#include <stddef.h>
#include <stdint.h>
#include "sinew.h"
#include "sn_clip.h"

/// Most joints a blob may have (blob format limit).
#define SN_DET_MAX_JOINTS 255

typedef struct sn_det {
    const sn_blob *blob;
    sn_instance *inst;
    const sn_clip *clip;     ///< NULL: built-in pose sequence
    uint32_t n_joints;
    uint32_t k;              ///< next step
    void *ws;                ///< shared workspace (sn_det_init_shared), else NULL
    size_t ws_size;          ///< its bytes
    uint32_t refused;        ///< steps sn_step_with refused (must stay 0)
    sn_quat local[SN_DET_MAX_JOINTS];
    sn_xform xf[SN_DET_MAX_JOINTS];
} sn_det;

/// Validate blob, init the instance in mem, parse and bind clip_text if
/// clip_text != NULL (clip is caller storage for it). 0 on success, else 1
/// with a message in err.
int sn_det_init(sn_det *d, const void *blob, size_t blob_size,
                const char *clip_text, size_t clip_len, sn_clip *clip,
                void *mem, size_t mem_size, char *err, size_t errlen);

/// sn_det_init for a shared instance (sn_instance_init_shared: mem holds
/// sn_instance_state_size bytes, ws sn_workspace_size bytes of the mode the
/// scenarios need, 8-byte aligned): sn_det_step then calls sn_step_with, so
/// every port checks that path's hash against the player's own-scratch one.
int sn_det_init_shared(sn_det *d, const void *blob, size_t blob_size,
                       const char *clip_text, size_t clip_len, sn_clip *clip,
                       void *mem, size_t mem_size, void *ws, size_t ws_size,
                       char *err, size_t errlen);

/// Compute and set the pose for the next step (clip time (d->k + 1) * h).
void sn_det_pose(sn_det *d);

/// sn_step (sn_step_with on a shared instance) and advance d->k.
void sn_det_step(sn_det *d);

/// n times pose + step; returns sn_state_hash.
uint64_t sn_det_run(sn_det *d, uint32_t n);

/// Steps of the constrained scenario (sn_det_contact).
#define SN_DET_CONTACT_STEPS 200u

/// The constrained scenario (issue 12), for blobs that bake constraints
/// (max_constraints and max_colliders > 0; returns 0 and does nothing
/// otherwise, else 1): back to rest (sn_reset, step 0), a ground plane 0.05
/// mesh units above the lowest rest surface vertex, a sphere of radius 1
/// rising into the flesh under the middle at 0.3 mesh units a second, and
/// four surface vertices pinned 0.1 above their rest positions (one of them
/// along y only). Then run SN_DET_CONTACT_STEPS steps of the same poses.
int sn_det_contact(sn_det *d);

/// Steps of the blended scenario (sn_det_blended).
#define SN_DET_BLENDED_STEPS 200u

/// The blended scenario (issue 13 item 4): back to rest (sn_reset: no
/// constraints or colliders, step 0) in SN_MODE_BLENDED, then
/// SN_DET_BLENDED_STEPS steps of the same poses. Returns 0 and does nothing
/// if the instance lacks the mode's memory (sn_instance_size_mode), else 1.
int sn_det_blended(sn_det *d);

/// 16 lowercase hex digits of h plus NUL into out[17].
void sn_det_hex64(uint64_t h, char out[17]);

#endif /* SN_DET_H */
