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
    int arr[7], count[7];     /* top-level arrays (node index, length), by GA_* */
    int *elem[7];             /* their elements' JSON nodes (sbj_at walks a list) */
} gl_doc;

enum { GA_BUFFERS, GA_VIEWS, GA_ACCESSORS, GA_NODES, GA_MESHES, GA_SKINS, GA_SCENES };

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
#endif
