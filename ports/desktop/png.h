/* png.h -- minimal PNG writer (8-bit RGB), C library only.
 * Deflate is either stored blocks or one fixed-Huffman block with a greedy
 * LZ77 (rendered frames are mostly flat background, so this is ~20x smaller
 * than stored). CRC-32 and Adler-32 are computed here. */
#ifndef SN_PNG_H
#define SN_PNG_H
#include <stddef.h>
#include <stdint.h>

/// CRC-32 (IEEE, as in PNG and zlib); start with crc = 0.
uint32_t png_crc32(uint32_t crc, const uint8_t *p, size_t n);
/// Adler-32 (zlib); start with a = 1.
uint32_t png_adler32(uint32_t a, const uint8_t *p, size_t n);

/// Encode w x h RGB pixels (rows top to bottom, 3 bytes per pixel) as a PNG
/// in a malloc'd buffer (*out, *out_len). compress = 0: stored deflate
/// blocks, filter 0; 1: fixed-Huffman LZ77 with per-row filters None/Sub/Up.
/// Returns 0, or -1 when out of memory or the size is out of range.
int png_encode(const uint8_t *rgb, int w, int h, int compress, uint8_t **out, size_t *out_len);

/// Write bytes to path atomically: a temp file next to it, then rename.
/// Returns 0, or -1 with a message (naming path and the reason) in err.
int write_file_atomic(const char *path, const void *data, size_t n, char *err, size_t errlen);

/// png_encode (compressed) + write_file_atomic.
int png_write(const char *path, const uint8_t *rgb, int w, int h, char *err, size_t errlen);

/// Animated PNG (APNG 1.0: acTL, per frame fcTL + IDAT (frame 0, also the
/// still image) or fdAT, sequence numbers from 0), 8-bit RGB, full-size
/// frames, dispose none, blend source, played forever, streamed to a temp
/// file renamed at png_anim_end. Each frame's delay is num/den seconds.
#include <stdio.h>
typedef struct png_anim {
    FILE *f;
    char path[4096], tmp[4096];
    int w, h;
    uint32_t frames, done, seq;
    uint16_t delay_num, delay_den;
    size_t bytes;   /* written so far */
} png_anim;
int png_anim_begin(png_anim *a, const char *path, int w, int h, uint32_t frames, uint16_t delay_num, uint16_t delay_den,
                   char *err, size_t errlen);
int png_anim_frame(png_anim *a, const uint8_t *rgb, char *err, size_t errlen);
/// Checks that every announced frame was written; 0, or -1 (nothing left behind).
int png_anim_end(png_anim *a, char *err, size_t errlen);
void png_anim_abort(png_anim *a);

#endif
