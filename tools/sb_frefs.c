/* sb_frefs.c -- the frames' shared work (format 6.4, runtime/BLOB.md "Frame
 * references"): over the free vertices' FRAMES entries then the CFRAMES
 * entries, as written (w quantized to Q15), each slerping entry's first
 * equal (b1, b2, w) entry, and the distinct bone pairs the first ones use. */
#include "sb.h"
#include "../runtime/src/sn_format.h"
#include <stdlib.h>

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* entry i's (b1, b2, w) as the blob stores it: b1 << 24 | b2 << 16 | w (Q15) */
static uint32_t entry_key(const sb_model *o, int i)
{
    int b1 = i < o->nf ? o->fb1[i] : o->cfb1[i - o->nf], b2 = i < o->nf ? o->fb2[i] : o->cfb2[i - o->nf];
    double w = i < o->nf ? o->fw[i] : o->cfw[i - o->nf];
    return (uint32_t)b1 << 24 | (uint32_t)b2 << 16 | sb_frame_w(w);
}

/* refs (nf + nc entries, or NULL): SN_FREF_BONE, SN_FREF_PAIR | pair, or
 * the first equal entry; pairs (or NULL): the distinct pairs, b1 << 8 | b2
 * increasing. Returns their count. */
int sb_frame_refs(const sb_model *o, uint32_t *refs, uint16_t *pairs)
{
    int n = o->nf + o->nc, i, m = 0, np = 0;
    uint64_t *s = sb_alloc(sizeof(uint64_t) * (size_t)(n > 0 ? n : 1));
    uint32_t head = 0;
    for (i = 0; i < n; i++) {   /* slerping entries, by key then index: a group's head is its first entry */
        uint32_t k = entry_key(o, i);
        if (refs) refs[i] = SN_FREF_BONE;
        if ((k >> 24) != ((k >> 16) & 255u) && (k & 0xFFFFu) != 0) s[m++] = (uint64_t)k << 32 | (uint32_t)i;
    }
    qsort(s, (size_t)m, sizeof *s, cmp_u64);
    for (i = 0; i < m; i++) {   /* keys sorted: so are their pairs (the top 16 bits) */
        uint32_t idx = (uint32_t)s[i];
        if (i == 0 || (s[i] >> 48) != (s[i - 1] >> 48)) {
            if (pairs) pairs[np] = (uint16_t)(s[i] >> 48);
            np++;
        }
        if (i == 0 || (s[i] >> 32) != (s[i - 1] >> 32)) head = idx;
        if (refs) refs[idx] = head == idx ? SN_FREF_PAIR | (uint32_t)(np - 1) : head;
    }
    free(s);
    return np;
}
