/* sb_desc_int.h -- internal to the description reader (sb_desc*.c): one line's tokens and their readers. */
#ifndef SB_DESC_INT_H
#define SB_DESC_INT_H
#include "sb.h"

typedef struct {
    const char *path;
    int line;
    char *tok[64];
    int nt;
} sb_dctx;

#define SB_MAX_LEN 1e9   /* lengths in mesh units: see sbd_len */
#define GROW(arr, n) do { arr = realloc(arr, sizeof(*(arr)) * (size_t)((n) + 1)); if (!(arr)) return sb_fail("out of memory"); memset(&(arr)[n], 0, sizeof(*(arr))); } while (0)

/* value readers (sb_desc_args.c): 0 or -1 (sb_fail with the file and line) */
int sbd_num(sb_dctx *c, int i, double *out);
int sbd_len(sb_dctx *c, int i, double *out);
int sbd_inum(sb_dctx *c, int i, int lo, int hi, int *out);
int sbd_nargs(sb_dctx *c, int n);
int sbd_vec3(sb_dctx *c, int i, const char *what, int unit, double v[3]);
int sbd_find_joint(const sb_desc *d, const char *name);
int sbd_region(sb_dctx *c, const sb_desc *d, int first, int tail, sb_region *r);   /* tokens used, or -1 */

/* keyword groups: 0 parsed, -1 error, 1 not one of the group's keywords */
int sbd_body_line(sb_dctx *c, sb_desc *d, int *seen);   /* sb_desc_body.c */
int sbd_sim_line(sb_dctx *c, sb_desc *d);               /* sb_desc_sim.c */
int sbd_rig_line(sb_dctx *c, sb_desc *d);               /* sb_desc_rig.c */
int sbd_seg_line(sb_dctx *c, sb_desc *d);               /* sb_desc_seg.c */
#endif
