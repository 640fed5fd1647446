/* sb_gltf.h -- glTF 2.0 reader (.gltf with external or base64 buffers, .glb):
 * the first skinned mesh of the default scene, or the mesh named on request.
 * Every error names the JSON path in sb_error(); on error *g is left empty. */
#ifndef SB_GLTF_H
#define SB_GLTF_H
#include <stdint.h>

typedef struct {
    char *name;         /* the joint node's name ("" if it has none) */
    int node;           /* glTF node index */
    int parent;         /* index in joints[] of the nearest ancestor in the skin, -1 at a root */
    double pos[3];      /* bind-pose position in the frame of POSITION: inverse(IBM) origin (the
                           skinned mesh node's own transform is ignored, glTF 2.0 3.7.3.3); the
                           node hierarchy's world position when the skin has no IBMs */
    double node_pos[3]; /* world position from the node hierarchy (TRS or matrix) */
    double bind[16];    /* bind-pose matrix (column-major) into the frame of POSITION: inverse(IBM), or
                           the node's world matrix when the skin has no IBMs (pos is its origin) */
} sb_gltf_joint;

typedef struct sb_gltf {
    char *mesh_name;    /* meshes[mesh].name ("" if none) */
    int mesh, node, skin;  /* glTF indices of the chosen mesh, the node using it, its skin */
    int nv;             /* vertices, all primitives concatenated in glTF order */
    double *pos;        /* 3*nv: POSITION as stored (bind space; the mesh node's transform is ignored) */
    int *joint;         /* 4*nv: indices into joints[] (0 where the weight is 0) */
    double *weight;     /* 4*nv: WEIGHTS_0, each vertex summing to 1 */
    int *src_prim, *src_vert;  /* per vertex: primitive and vertex index in the glTF file */
    int nt;             /* triangles */
    int *tri;           /* 3*nt, indices into the nv vertices */
    int nj;
    sb_gltf_joint *joints;  /* skins[skin].joints order */
} sb_gltf;

/* Load path (.gltf or .glb, told apart by the GLB magic). mesh_name NULL: the
 * first skinned mesh met walking the default scene. 0, or -1 and sb_error(). */
int sb_gltf_load(sb_gltf *g, const char *path, const char *mesh_name);
void sb_gltf_free(sb_gltf *g);

/* A glTF node name as a description token (sb_desc 'gltf', clips): whitespace
 * and '#' become '_', "" becomes "joint<k>", truncated to out_len - 1 bytes. */
void sb_gltf_token(const char *name, int k, char *out, int out_len);

/* ---- animations (sb_gltf_anim.c) ---- */
/* An animation of the skin, sampled every h seconds from 0 to its end as the
 * local joint rotations and root offset Sinew poses take (sn_pose_from_local:
 * rotation of each joint about its bind position in the frame of POSITION,
 * relative to its skin parent; the skin root's translation from its bind
 * position). Samplers LINEAR (slerp for rotations), STEP, CUBICSPLINE;
 * scale channels are ignored (counted), as are translations of joints below
 * the root (Sinew bones are rigid; the largest gap is reported). */
typedef struct sb_gltf_anim {
    char name[128];         /* animations[index].name ("" if none) */
    int index;              /* animations[index] */
    int nj;                 /* skin joints (sb_gltf order) */
    int nframes;            /* samples at t = k h, k = 0 .. nframes-1 (the last at or past the end) */
    double h, end;          /* step and the animation's last key time, seconds */
    double *rot;            /* nframes x nj x 4 quaternions (x, y, z, w), w >= 0 */
    double *move;           /* nframes x 3: root offset, POSITION units */
    double *skin;           /* nframes x nj x 16: skinning matrices world(joint) x IBM, column-major */
    int *animated;          /* per joint: a rotation or translation channel targets its node */
    int n_channels, n_scale, n_other;   /* channels read; scale channels ignored; weights etc. ignored */
    int n_scale_active;     /* scale channels with a value other than 1 (the rest only key 1s) */
    double bone_gap;        /* largest distance between a joint animated by translation and where its rigid bone puts it */
} sb_gltf_anim;
/* name NULL: the first animation; else by name or decimal index. h > 0, at
 * most max_frames samples. g: the skin, as sb_gltf_load read it. */
int sb_gltf_anim_load(sb_gltf_anim *a, const char *path, const sb_gltf *g, const char *name, double h, int max_frames);
void sb_gltf_anim_free(sb_gltf_anim *a);
/* Clip text (ports/common/CLIP.md) of a sampled animation: one key per frame
 * at t = k * hq / 65536 s (hq: the blob's timestep in Q16.16, so every key is
 * a step of the clip clock), joint names by sb_gltf_token; channels that never
 * leave the identity are left out, constant ones get one key. loop yes/no.
 * malloc'ed, NULL on error (sb_error). */
char *sb_gltf_anim_clip(const sb_gltf_anim *a, const sb_gltf *g, int32_t hq, int loop, const char *source);
#endif
