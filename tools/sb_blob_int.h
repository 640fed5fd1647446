/* sb_blob_int.h -- internal to the blob writer (sb_blob*.c): the byte writer and the sections built apart. */
#ifndef SB_BLOB_INT_H
#define SB_BLOB_INT_H
#include "sb.h"
#include "sb_cut.h"
#include "../runtime/src/sn_format.h"
#include <math.h>
#include <string.h>

typedef struct {
    unsigned char *p;
    int flavour, rs;   /* real size */
    int err;
} wr_t;

static inline void put_u8(wr_t *w, size_t at, unsigned v) { w->p[at] = (unsigned char)v; }
static inline void put_u16(wr_t *w, size_t at, unsigned v) { w->p[at] = (unsigned char)(v & 255u); w->p[at + 1] = (unsigned char)((v >> 8) & 255u); }
static inline void put_u32(wr_t *w, size_t at, uint32_t v)
{
    int k;
    for (k = 0; k < 4; k++) w->p[at + (size_t)k] = (unsigned char)((v >> (8 * k)) & 255u);
}
static inline void put_u64(wr_t *w, size_t at, uint64_t v)
{
    int k;
    for (k = 0; k < 8; k++) w->p[at + (size_t)k] = (unsigned char)((v >> (8 * k)) & 255u);
}

/* round to nearest, ties away from zero */
static inline double rnd(double x) { return x < 0 ? -floor(-x + 0.5) : floor(x + 0.5); }


/* one real: fixed = round(x * 2^frac) as int32, float32, or float64 */
static inline void put_real(wr_t *w, size_t at, double x, int frac)
{
    if (w->flavour == SB_FIXED) {
        double q = rnd(ldexp(x, frac));
        if (!(q >= -2147483648.0 && q <= 2147483647.0)) { w->err = 1; q = 0; }
        put_u32(w, at, (uint32_t)(int32_t)q);
    } else if (w->flavour == SB_FLOAT) {
        float f = (float)x;
        uint32_t u;
        memcpy(&u, &f, 4);
        put_u32(w, at, u);
    } else {
        uint64_t u;
        memcpy(&u, &x, 8);
        put_u64(w, at, u);
    }
}

/* symmetric 3x3 storage order of PRECOND: xx yy zz xy xz yz */

/* sb_blob_cells.c: a cell's quantized stiffness blocks (format 6.0 CELLK) and the cut level's extras */
int sb_blob_cell_blocks(const sb_model *o, int ci, double h, double m0, int flavour, int frac, double out[36 * 9],
                        int exps[28]);
int sb_blob_cut_blocks(const sb_model *o, int ci, double sc, int flavour, int frac, double *out, int *xe);
/* sb_blob_rigs.c: the rig sections (format 3.0) */
int sb_blob_write_rigs(const sb_model *o, wr_t *w, const uint32_t *off, double Um, double m0, sb_blob *b);
/* sb_blob_cells.c: CELLS, CFRAMES, CELLK, CELLX, CELLXK written */
void sb_blob_write_cells(const sb_model *o, wr_t *w, const uint32_t *off, const uint32_t *esz, double h, double m0,
                         const sb_blob *b);
/* sb_blob_table.c: every section's count and element size but FPAIRS / FREFS */
int sb_blob_table(const sb_model *o, int flavour, int rs, int nnz, int nic, int nlim, uint32_t *cnt, uint32_t *esz);
/* sb_blob_details.c: the cut level's details (format 6.5) */
int sb_blob_write_details(const sb_model *o, wr_t *w, const uint32_t *off, const uint32_t *esz, double h, double m0,
                          double U, const double *root, const sb_blob *b);
/* sb_blob_records.c: shares, constraints, adaptation, crease records, the level maps */
int sb_blob_write_records(const sb_model *o, wr_t *w, const uint32_t *off, const uint32_t *cnt, double U);
#endif
