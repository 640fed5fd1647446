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
/* The crease record (format 5.0) or NULL. */
static inline const unsigned char *crease_record(const unsigned char *b) {
    const unsigned char *e = b + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_CREASE;
    return bs_u32(e + 8) == 1u ? b + bs_u32(e) : NULL;
}
/* The crease state bytes (SN_CREASE_STATE_BYTES; 0 without CREASE): the
 * tests add them to the segment state bytes (SN_INSTANCE_BYTES' segB). */
static inline uint32_t crease_state_bytes(const unsigned char *b) {
    const unsigned char *r = crease_record(b);
    return r ? SN_CREASE_STATE_BYTES(bs_u32(b + SN_H_N_SURFACE), (uint32_t)r[0] | (uint32_t)r[1] << 8) : 0u;
}
/* The constraint state bytes (format 5.0): SN_CONS_BYTES of the CONSTRAINTS
 * record's maxima and the crease's max_active rows, 0 without either. */
static inline uint32_t cons_state_bytes(const unsigned char *b) {
    const unsigned char *e = b + SN_H_SECTIONS + SN_SECTION_ENTRY * SN_SEC_CONSTRAINTS;
    const unsigned char *r = b + bs_u32(e), *cr = crease_record(b);
    uint32_t ct = 0, con = 0, col = 0, act = cr ? ((uint32_t)cr[2] | (uint32_t)cr[3] << 8) : 0u;
    if (bs_u32(e + 8) == 1u) { con = r[0]; col = r[1]; ct = (uint32_t)r[2] | (uint32_t)r[3] << 8; }
    if (!con && !col && !ct && !act) return 0;
    return SN_CONS_BYTES(con, col, SN_ROWS_CAP(con, ct, act));
}
#endif
