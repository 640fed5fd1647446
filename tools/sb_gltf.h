/* sb_gltf.h -- glTF 2.0 reader (.gltf with external or base64 buffers, .glb):
 * the first skinned mesh of the default scene, or the mesh named on request.
 * Every error names the JSON path in sb_error(); on error *g is left empty. */
#ifndef SB_GLTF_H
#define SB_GLTF_H

typedef struct {
    char *name;         /* the joint node's name ("" if it has none) */
    int node;           /* glTF node index */
    int parent;         /* index in joints[] of the nearest ancestor in the skin, -1 at a root */
    double pos[3];      /* bind-pose position in the frame of POSITION: inverse(IBM) origin (the
                           skinned mesh node's own transform is ignored, glTF 2.0 3.7.3.3); the
                           node hierarchy's world position when the skin has no IBMs */
    double node_pos[3]; /* world position from the node hierarchy (TRS or matrix) */
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
#endif
