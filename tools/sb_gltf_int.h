/* sb_gltf_int.h -- shared between the glTF reader's files: the loaded
 * document, its buffers, and the JSON field readers that name their path. */
#ifndef SB_GLTF_INT_H
#define SB_GLTF_INT_H
#include "sb_json.h"
#include <stddef.h>

#define GL_REQUIRED (-0x7fffffffffffffffLL)   /* jint default: the field must be present */

typedef struct {
    sbj_doc j;
    char dir[1024];           /* directory of the .gltf, with trailing '/' (or "") */
    unsigned char *file;      /* the whole file (the GLB BIN chunk points into it) */
    size_t file_len;
    const unsigned char *bin; /* GLB BIN chunk or NULL */
    size_t bin_len;
    int nbuf;
    unsigned char **buf;      /* buffers[i] bytes (owned, or pointing at bin) */
    size_t *buf_len;          /* declared byteLength (the bytes hold at least this) */
    int *buf_owned;
    int arr[8], count[8];     /* top-level arrays (node index, length), by GA_* */
    int *elem[8];             /* their elements' JSON nodes (sbj_at walks a list) */
} gl_doc;

enum { GA_BUFFERS, GA_VIEWS, GA_ACCESSORS, GA_NODES, GA_MESHES, GA_SKINS, GA_SCENES, GA_ANIMS, GA_COUNT };

/* an accessor decoded to doubles (normalized if its flag says so) */
typedef struct {
    long long count;
    int ncomp, ctype, normalized;
    double *v;                /* count*ncomp */
} gl_acc;

int gl_elem(const gl_doc *d, int which, int i);      /* JSON node of e.g. accessors[i], or -1 */
int gl_int(const gl_doc *d, int obj, const char *key, const char *path,
           long long dflt, long long lo, long long hi, long long *out);
int gl_nums(const gl_doc *d, int obj, const char *key, const char *path, int n, double *out);
int gl_read_file(const char *path, unsigned char **data, size_t *len);
int gl_open(gl_doc *d, const char *path);            /* file, GLB container, JSON, buffers */
void gl_close(gl_doc *d);
int gl_accessor(const gl_doc *d, int a, gl_acc *out);

/* the scene layer (sb_gltf.c): nodes with their local and world matrices */
typedef struct {
    gl_doc d;
    int nn;
    int *parent;     /* per node, -1 for a root */
    double *local, *world;   /* 16 per node, column-major */
    double *trs;     /* 10 per node: translation, rotation (x y z w), scale (identity for a matrix node) */
    char *is_matrix; /* the node gave a matrix (not an animation target) */
    char *done;
    int *mesh, *skin;
} gl_scene;
/* open the file and read every node; 0 or -1 (sb_error); gl_scene_close either way */
int gl_scene_open(gl_scene *s, const char *path);
void gl_scene_close(gl_scene *s);
/* the skinned mesh node (sb_gltf_load's choice) or -1 (sb_error) */
int gl_scene_pick(gl_scene *s, const char *mesh_name);
void gl_mat_mul(const double *a, const double *b, double *o);
void gl_mat_trs(const double *t, const double *q, const double *sc, double *m);
int gl_mat_inv_affine(const double *m, double *o);
#endif
