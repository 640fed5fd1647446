/* png.c -- minimal PNG writer, see png.h. */
#include "png.h"
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

uint32_t png_crc32(uint32_t crc, const uint8_t *p, size_t n) {
    static uint32_t table[256];
    static int ready;
    size_t i;
    if (!ready) {
        uint32_t k, c;
        int b;
        for (k = 0; k < 256; k++) {
            for (c = k, b = 0; b < 8; b++) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
            table[k] = c;
        }
        ready = 1;
    }
    crc = ~crc;
    for (i = 0; i < n; i++) crc = table[(crc ^ p[i]) & 0xFFu] ^ (crc >> 8);
    return ~crc;
}

uint32_t png_adler32(uint32_t a, const uint8_t *p, size_t n) {
    uint32_t s1 = a & 0xFFFFu, s2 = a >> 16;
    while (n) {
        size_t k = n < 5552 ? n : 5552;   /* largest run without uint32 overflow */
        n -= k;
        while (k--) { s1 += *p++; s2 += s1; }
        s1 %= 65521u; s2 %= 65521u;
    }
    return (s2 << 16) | s1;
}

/* ---- deflate ---- */
typedef struct { uint8_t *p; size_t n; uint64_t bits; int nbits; } bitw;

static void put_bits(bitw *w, uint32_t v, int n) {   /* LSB first */
    w->bits |= (uint64_t)v << w->nbits;
    w->nbits += n;
    while (w->nbits >= 8) { w->p[w->n++] = (uint8_t)w->bits; w->bits >>= 8; w->nbits -= 8; }
}
static void put_code(bitw *w, uint32_t code, int n) {   /* Huffman codes go MSB first */
    uint32_t r = 0;
    int i;
    for (i = 0; i < n; i++) r |= ((code >> i) & 1u) << (n - 1 - i);
    put_bits(w, r, n);
}
static void put_sym(bitw *w, int s) {   /* fixed literal/length code (RFC 1951 3.2.6) */
    if (s < 144) put_code(w, 0x30u + (uint32_t)s, 8);
    else if (s < 256) put_code(w, 0x190u + (uint32_t)(s - 144), 9);
    else if (s < 280) put_code(w, (uint32_t)(s - 256), 7);
    else put_code(w, 0xC0u + (uint32_t)(s - 280), 8);
}

static const uint16_t len_base[29] = {3,4,5,6,7,8,9,10,11,13,15,17,19,23,27,31,35,43,51,59,67,83,99,115,131,163,195,227,258};
static const uint8_t len_extra[29] = {0,0,0,0,0,0,0,0,1,1,1,1,2,2,2,2,3,3,3,3,4,4,4,4,5,5,5,5,0};
static const uint16_t dist_base[30] = {1,2,3,4,5,7,9,13,17,25,33,49,65,97,129,193,257,385,513,769,
                                       1025,1537,2049,3073,4097,6145,8193,12289,16385,24577};
static const uint8_t dist_extra[30] = {0,0,0,0,1,1,2,2,3,3,4,4,5,5,6,6,7,7,8,8,9,9,10,10,11,11,12,12,13,13};

static void put_match(bitw *w, int len, int dist) {
    int i = 28, d = 29;
    while (len_base[i] > len) i--;
    put_sym(w, 257 + i);
    put_bits(w, (uint32_t)(len - len_base[i]), len_extra[i]);
    while (dist_base[d] > dist) d--;
    put_code(w, (uint32_t)d, 5);
    put_bits(w, (uint32_t)(dist - dist_base[d]), dist_extra[d]);
}

#define HBITS 15
#define WSIZE 32768
#define CHAIN 24

/* One final fixed-Huffman block, greedy matching with short hash chains.
 * out must hold n*9/8 + 16 bytes. Returns bytes written. */
static size_t deflate_fixed(const uint8_t *in, size_t n, uint8_t *out) {
    bitw w = {0, 0, 0, 0};
    int32_t *head = malloc(sizeof(int32_t) << HBITS), *prev = malloc(sizeof(int32_t) * WSIZE);
    size_t i = 0;
    w.p = out;
    if (!head || !prev) { free(head); free(prev); return 0; }
    memset(head, 0xFF, sizeof(int32_t) << HBITS);
    put_bits(&w, 1, 1);   /* BFINAL */
    put_bits(&w, 1, 2);   /* BTYPE = 01 fixed */
    while (i < n) {
        int best = 0, bdist = 0;
        if (i + 3 <= n) {
            uint32_t h = ((uint32_t)in[i] << 10 ^ (uint32_t)in[i + 1] << 5 ^ in[i + 2]) & ((1u << HBITS) - 1);
            int32_t c = head[h];
            int chain = CHAIN;
            size_t maxl = n - i < 258 ? n - i : 258;
            while (c >= 0 && i - (size_t)c <= WSIZE - 1 && chain--) {
                size_t l = 0;
                while (l < maxl && in[(size_t)c + l] == in[i + l]) l++;
                if ((int)l > best) { best = (int)l; bdist = (int)(i - (size_t)c); if (l == maxl) break; }
                c = prev[(size_t)c & (WSIZE - 1)];
            }
            prev[i & (WSIZE - 1)] = head[h];
            head[h] = (int32_t)i;
        }
        if (best >= 3) {
            size_t k;
            put_match(&w, best, bdist);
            for (k = 1; k < (size_t)best; k++) {   /* index the skipped positions */
                size_t j = i + k;
                if (j + 3 <= n) {
                    uint32_t h = ((uint32_t)in[j] << 10 ^ (uint32_t)in[j + 1] << 5 ^ in[j + 2]) & ((1u << HBITS) - 1);
                    prev[j & (WSIZE - 1)] = head[h];
                    head[h] = (int32_t)j;
                }
            }
            i += (size_t)best;
        } else {
            put_sym(&w, in[i]);
            i++;
        }
    }
    put_sym(&w, 256);
    if (w.nbits) put_bits(&w, 0, 8 - w.nbits);
    free(head); free(prev);
    return w.n;
}

static size_t deflate_stored(const uint8_t *in, size_t n, uint8_t *out) {
    size_t o = 0, i = 0;
    do {
        size_t k = n - i < 65535 ? n - i : 65535;
        out[o++] = (uint8_t)(i + k == n);   /* BFINAL, BTYPE 00 */
        out[o++] = (uint8_t)k; out[o++] = (uint8_t)(k >> 8);
        out[o++] = (uint8_t)~k; out[o++] = (uint8_t)(~k >> 8);
        memcpy(out + o, in + i, k);
        o += k; i += k;
    } while (i < n);
    return o;
}

static void be32(uint8_t *p, uint32_t v) {
    p[0] = (uint8_t)(v >> 24); p[1] = (uint8_t)(v >> 16); p[2] = (uint8_t)(v >> 8); p[3] = (uint8_t)v;
}

static size_t chunk(uint8_t *p, const char *type, const uint8_t *data, size_t n) {
    be32(p, (uint32_t)n);
    memcpy(p + 4, type, 4);
    if (n) memcpy(p + 8, data, n);
    be32(p + 8 + n, png_crc32(0, p + 4, n + 4));
    return n + 12;
}

/* the zlib stream of w x h RGB pixels (filtered rows), malloc'd in *z */
static int png_zimage(const uint8_t *rgb, int w, int h, int compress, uint8_t **zout, size_t *zlen) {
    size_t stride, raw_n, cap, zn;
    uint8_t *raw, *z;
    int y;
    *zout = NULL; *zlen = 0;
    if (w <= 0 || h <= 0 || w > 16384 || h > 16384) return -1;
    stride = (size_t)w * 3;
    raw_n = (size_t)h * (stride + 1);
    cap = raw_n + raw_n / 8 + raw_n / 65535 * 5 + 64;
    raw = malloc(raw_n);
    z = malloc(cap);
    if (!raw || !z) { free(raw); free(z); return -1; }
    for (y = 0; y < h; y++) {
        const uint8_t *row = rgb + (size_t)y * stride, *up = y ? row - stride : NULL;
        uint8_t *dst = raw + (size_t)y * (stride + 1);
        size_t x;
        int f = 0;
        if (compress) {   /* pick the filter with the smallest sum of |residual| */
            unsigned long s[3] = {0, 0, 0};
            for (x = 0; x < stride; x++) {
                int a = x >= 3 ? row[x - 3] : 0, b = up ? up[x] : 0;
                s[0] += row[x] < 128 ? row[x] : 256u - row[x];
                s[1] += (uint8_t)(row[x] - a) < 128 ? (uint8_t)(row[x] - a) : 256u - (uint8_t)(row[x] - a);
                s[2] += (uint8_t)(row[x] - b) < 128 ? (uint8_t)(row[x] - b) : 256u - (uint8_t)(row[x] - b);
            }
            f = s[1] < s[0] ? 1 : 0;
            if (s[2] < s[f]) f = 2;
        }
        dst[0] = (uint8_t)f;
        for (x = 0; x < stride; x++) {
            int a = x >= 3 ? row[x - 3] : 0, b = up ? up[x] : 0;
            dst[1 + x] = (uint8_t)(row[x] - (f == 1 ? a : f == 2 ? b : 0));
        }
    }
    z[0] = 0x78; z[1] = 0x01;   /* deflate, 32K window, FCHECK: 0x7801 % 31 == 0 */
    zn = compress ? deflate_fixed(raw, raw_n, z + 2) : 0;
    if (!zn || zn > raw_n + raw_n / 65535 * 5 + 5) zn = deflate_stored(raw, raw_n, z + 2);
    be32(z + 2 + zn, png_adler32(1, raw, raw_n));
    zn += 6;
    free(raw);
    *zout = z; *zlen = zn;
    return 0;
}

static void png_ihdr(uint8_t *ihdr, int w, int h) {
    be32(ihdr, (uint32_t)w); be32(ihdr + 4, (uint32_t)h);
    ihdr[8] = 8; ihdr[9] = 2; ihdr[10] = 0; ihdr[11] = 0; ihdr[12] = 0;   /* 8-bit RGB */
}

int png_encode(const uint8_t *rgb, int w, int h, int compress, uint8_t **out, size_t *out_len) {
    size_t zn, o = 0;
    uint8_t *z, *png, ihdr[13];
    *out = NULL; *out_len = 0;
    if (png_zimage(rgb, w, h, compress, &z, &zn)) return -1;
    png = malloc(zn + 8 + 25 + 12 + 12);
    if (!png) { free(z); return -1; }
    memcpy(png, "\x89PNG\r\n\x1a\n", 8);
    o = 8;
    png_ihdr(ihdr, w, h);
    o += chunk(png + o, "IHDR", ihdr, 13);
    o += chunk(png + o, "IDAT", z, zn);
    o += chunk(png + o, "IEND", NULL, 0);
    free(z);
    *out = png; *out_len = o;
    return 0;
}

/* ---- APNG (animated PNG: acTL, then per frame fcTL + IDAT / fdAT) ---- */
static int anim_chunk(png_anim *a, const char *type, const uint8_t *data, size_t n) {
    uint8_t *c = malloc(n + 12);
    size_t m;
    int ok;
    if (!c) return -1;
    m = chunk(c, type, data, n);
    ok = fwrite(c, 1, m, a->f) == m;
    free(c);
    a->bytes += m;
    return ok ? 0 : -1;
}

int png_anim_begin(png_anim *a, const char *path, int w, int h, uint32_t frames, uint16_t delay_num, uint16_t delay_den,
                   char *err, size_t errlen) {
    uint8_t ihdr[13], actl[8];
    memset(a, 0, sizeof *a);
    if (w <= 0 || h <= 0 || w > 16384 || h > 16384 || frames < 1 || !delay_den) {
        snprintf(err, errlen, "%s: bad animation size %dx%d, %u frames or delay %u/%u", path, w, h, (unsigned)frames, delay_num, delay_den);
        return -1;
    }
    if (strlen(path) + 16 > sizeof a->tmp) { snprintf(err, errlen, "%s: path too long", path); return -1; }
    snprintf(a->path, sizeof a->path, "%s", path);
    snprintf(a->tmp, sizeof a->tmp, "%s.tmp%ld", path, (long)(rand() & 0xFFFF));
    if (!(a->f = fopen(a->tmp, "wb"))) { snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno)); return -1; }
    a->w = w, a->h = h, a->frames = frames, a->delay_num = delay_num, a->delay_den = delay_den;
    fwrite("\x89PNG\r\n\x1a\n", 1, 8, a->f);
    a->bytes = 8;
    png_ihdr(ihdr, w, h);
    be32(actl, frames);
    be32(actl + 4, 0);   /* plays forever */
    if (anim_chunk(a, "IHDR", ihdr, 13) || anim_chunk(a, "acTL", actl, 8)) {
        snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
        fclose(a->f); remove(a->tmp); a->f = NULL;
        return -1;
    }
    return 0;
}

int png_anim_frame(png_anim *a, const uint8_t *rgb, char *err, size_t errlen) {
    uint8_t fctl[26], *z, *d;
    size_t zn;
    int r;
    if (!a->f || a->done >= a->frames) { snprintf(err, errlen, "%s: more frames than announced (%u)", a->path, (unsigned)a->frames); return -1; }
    be32(fctl, a->seq++);
    be32(fctl + 4, (uint32_t)a->w); be32(fctl + 8, (uint32_t)a->h);
    be32(fctl + 12, 0); be32(fctl + 16, 0);   /* x, y offsets */
    fctl[20] = (uint8_t)(a->delay_num >> 8); fctl[21] = (uint8_t)a->delay_num;
    fctl[22] = (uint8_t)(a->delay_den >> 8); fctl[23] = (uint8_t)a->delay_den;
    fctl[24] = 0;   /* dispose: none */
    fctl[25] = 0;   /* blend: source */
    if (png_zimage(rgb, a->w, a->h, 1, &z, &zn)) { snprintf(err, errlen, "%s: out of memory", a->path); return -1; }
    if (a->done == 0) r = anim_chunk(a, "fcTL", fctl, 26) || anim_chunk(a, "IDAT", z, zn);   /* the default image is frame 0 */
    else {
        d = malloc(zn + 4);
        if (!d) { free(z); snprintf(err, errlen, "%s: out of memory", a->path); return -1; }
        be32(d, a->seq++);
        memcpy(d + 4, z, zn);
        r = anim_chunk(a, "fcTL", fctl, 26) || anim_chunk(a, "fdAT", d, zn + 4);
        free(d);
    }
    free(z);
    a->done++;
    if (r) { snprintf(err, errlen, "cannot write %s: %s", a->path, strerror(errno)); return -1; }
    return 0;
}

int png_anim_end(png_anim *a, char *err, size_t errlen) {
    int ok;
    if (!a->f) return -1;
    if (a->done != a->frames) {
        snprintf(err, errlen, "%s: %u of %u frames written", a->path, (unsigned)a->done, (unsigned)a->frames);
        fclose(a->f); remove(a->tmp); a->f = NULL;
        return -1;
    }
    ok = anim_chunk(a, "IEND", NULL, 0) == 0;
    ok = (fclose(a->f) == 0) && ok;
    a->f = NULL;
    if (!ok || rename(a->tmp, a->path) != 0) {
        snprintf(err, errlen, "cannot write %s: %s", a->path, strerror(errno));
        remove(a->tmp);
        return -1;
    }
    return 0;
}

void png_anim_abort(png_anim *a) {
    if (a->f) { fclose(a->f); remove(a->tmp); a->f = NULL; }
}

int write_file_atomic(const char *path, const void *data, size_t n, char *err, size_t errlen) {
    char tmp[4096];
    FILE *f;
    int ok;
    if (strlen(path) + 16 > sizeof tmp) { snprintf(err, errlen, "%s: path too long", path); return -1; }
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)(rand() & 0xFFFF));
    f = fopen(tmp, "wb");
    if (!f) { snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno)); return -1; }
    ok = fwrite(data, 1, n, f) == n;
    ok = (fclose(f) == 0) && ok;
    if (!ok) { snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno)); remove(tmp); return -1; }
    if (rename(tmp, path) != 0) {
        snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
        remove(tmp);
        return -1;
    }
    return 0;
}

int png_write(const char *path, const uint8_t *rgb, int w, int h, char *err, size_t errlen) {
    uint8_t *png;
    size_t n;
    int r;
    if (png_encode(rgb, w, h, 1, &png, &n)) { snprintf(err, errlen, "%s: cannot encode PNG (size %dx%d or memory)", path, w, h); return -1; }
    r = write_file_atomic(path, png, n, err, errlen);
    free(png);
    return r;
}
