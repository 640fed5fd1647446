/* blob_seg.h -- the segment state bytes of a baked blob (format 4.0), for
 * the tests that check instance_bytes against SN_INSTANCE_BYTES: every
 * SEGMESH record's segments and nodes over its levels (sn_seg_counts), 0
 * without segment meshes. Reads the little-endian table itself. */
#ifndef BLOB_SEG_H
#define BLOB_SEG_H
#include <stdint.h>
#include "sn_format.h"

static inline uint32_t bs_u32(const unsigned char *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static inline uint32_t seg_state_bytes(const unsigned char *b) {
    const unsigned char *e = b + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_SEGMESH;
    uint32_t off = bs_u32(e), n = bs_u32(e + 8), es = bs_u32(e + 12), m, tot = 0;
    for (m = 0; m < n; m++) {
        const unsigned char *r = b + off + m * es;
        uint32_t segs, nodes;
        sn_seg_counts(r[0], (unsigned)r[4] | (unsigned)r[5] << 8, r[1], &segs, &nodes);
        tot += SN_SEG_SEG_BYTES * segs + SN_SEG_NODE_BYTES * nodes;
    }
    return tot;
}
/* The constraint state bytes (format 5.0): SN_CONS_BYTES of the CONSTRAINTS
 * record's maxima, 0 without the record. */
static inline uint32_t cons_state_bytes(const unsigned char *b) {
    const unsigned char *e = b + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_CONSTRAINTS;
    const unsigned char *r = b + bs_u32(e);
    uint32_t ct;
    if (bs_u32(e + 8) != 1u) return 0;
    ct = (uint32_t)r[2] | (uint32_t)r[3] << 8;
    if (!r[0] && !r[1] && !ct) return 0;
    return SN_CONS_BYTES(r[0], r[1], SN_ROWS_CAP(r[0], ct));
}
#endif
