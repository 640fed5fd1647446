/* sb_json.h -- a small strict JSON parser (RFC 8259) for the glTF reader.
 * The tree is a flat array of nodes linked by index (no pointers to fix up
 * when it grows); strings are copied, unescaped, into one text pool. */
#ifndef SB_JSON_H
#define SB_JSON_H
#include <stddef.h>

enum { SBJ_NULL, SBJ_FALSE, SBJ_TRUE, SBJ_NUM, SBJ_STR, SBJ_ARR, SBJ_OBJ };
#define SBJ_MAX_DEPTH 64

typedef struct {
    int kind;
    int count;      /* members of an array/object */
    int child;      /* first member, -1 if none */
    int next;       /* next sibling, -1 if last */
    int key, klen;  /* object member: its key in the text pool */
    int str, slen;  /* string: offset/length in the text pool (NUL-terminated) */
    double num;
} sbj_node;

typedef struct {
    sbj_node *node;
    int nn, cap;
    char *text;
    size_t nt, tcap;
} sbj_doc;

/* Parse src[0..len). 0, or -1 with sb_error() "JSON line L (byte B): why". The
 * root is node 0. Nesting deeper than SBJ_MAX_DEPTH is refused. */
int sbj_parse(sbj_doc *d, const char *src, size_t len);
void sbj_free(sbj_doc *d);
int sbj_get(const sbj_doc *d, int obj, const char *key);    /* member or -1 */
int sbj_at(const sbj_doc *d, int arr, int i);               /* element or -1 */
const char *sbj_str(const sbj_doc *d, int n);               /* NULL unless a string */
#endif
