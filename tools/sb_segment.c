/* sb_segment.c -- segment meshes (seed 004 ch. 3-4): chains and sheets
 * declared in the description, attached to the character. Placeholder. */
#include "sb.h"
#include "../runtime/src/sn_format.h"

int sb_segment_build(const sb_desc *d, const sb_mesh *m, sb_model *o) {
    (void)d; (void)m;
    o->nsm = 0; o->sm = NULL;
    return 0;
}
void sb_segment_free(sb_model *o) { o->nsm = 0; o->sm = NULL; }
uint32_t sb_segment_state_bytes(const sb_model *o) { (void)o; return 0; }
void sb_segment_blob_counts(const sb_model *o, uint32_t *nodes, uint32_t *attach) { (void)o; *nodes = 0; *attach = 0; }
int sb_segment_blob_write(const sb_model *o, unsigned char *blob, const uint32_t *off, int flavour, int rs, int len_shift) {
    (void)o; (void)blob; (void)off; (void)flavour; (void)rs; (void)len_shift;
    return 0;
}
