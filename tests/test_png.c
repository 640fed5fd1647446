/* test_png.c -- the PNG writer (ports/desktop/png.c) against an independent
 * minimal reader written here: chunk walk with a bitwise CRC-32, inflate of
 * stored and fixed-Huffman blocks, Adler-32, un-filtering (None/Sub/Up).
 * Decoded pixels must equal the input exactly. */
#include "sn_test.h"
#include "png.h"
#include <string.h>

static uint32_t rd32(const uint8_t *p) { return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]; }

static uint32_t crc_bitwise(const uint8_t *p, size_t n) {   /* no table: independent of png.c */
    uint32_t c = 0xFFFFFFFFu;
    size_t i;
    int b;
    for (i = 0; i < n; i++)
        for (c ^= p[i], b = 0; b < 8; b++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    return ~c;
}

typedef struct { const uint8_t *p; size_t n, pos; int bit; int err; } bitr;
static uint32_t getbit(bitr *r) {
    uint32_t v;
    if (r->pos >= r->n) { r->err = 1; return 0; }
    v = (r->p[r->pos] >> r->bit) & 1u;
    if (++r->bit == 8) { r->bit = 0; r->pos++; }
    return v;
}
static uint32_t getbits(bitr *r, int n) { uint32_t v = 0; int i; for (i = 0; i < n; i++) v |= getbit(r) << i; return v; }
/* fixed literal/length symbol: read the code MSB first, bit by bit (RFC 1951 3.2.6) */
static int getsym(bitr *r) {
    uint32_t c = 0;
    int i;
    for (i = 0; i < 7; i++) c = c << 1 | getbit(r);
    if (c <= 0x17) return 256 + (int)c;
    c = c << 1 | getbit(r);
    if (c >= 0x30 && c <= 0xBF) return (int)c - 0x30;
    if (c >= 0xC0 && c <= 0xC7) return 280 + (int)c - 0xC0;
    c = c << 1 | getbit(r);
    if (c >= 0x190 && c <= 0x1FF) return 144 + (int)c - 0x190;
    r->err = 1;
    return -1;
}

/* Inflate zlib stream z into out (capacity cap). Returns bytes, -1 on error. */
static long inflate_min(const uint8_t *z, size_t zn, uint8_t *out, size_t cap, int *saw_stored, int *saw_fixed) {
    static const int lb[29] = {3,4,5,6,7,8,9,10,11,13,15,17,19,23,27,31,35,43,51,59,67,83,99,115,131,163,195,227,258};
    static const int le[29] = {0,0,0,0,0,0,0,0,1,1,1,1,2,2,2,2,3,3,3,3,4,4,4,4,5,5,5,5,0};
    static const int db[30] = {1,2,3,4,5,7,9,13,17,25,33,49,65,97,129,193,257,385,513,769,1025,1537,2049,3073,4097,6145,8193,12289,16385,24577};
    static const int de[30] = {0,0,0,0,1,1,2,2,3,3,4,4,5,5,6,6,7,7,8,8,9,9,10,10,11,11,12,12,13,13};
    bitr r;
    size_t o = 0;
    uint32_t fin = 0, s1 = 1, s2 = 0, i;
    if (zn < 6 || (z[0] & 0x0F) != 8 || ((z[0] << 8) | z[1]) % 31 != 0 || (z[1] & 0x20)) return -1;
    r.p = z; r.n = zn - 4; r.pos = 2; r.bit = 0; r.err = 0;
    while (!fin) {
        uint32_t type;
        fin = getbit(&r);
        type = getbits(&r, 2);
        if (type == 0) {
            uint32_t len, nlen;
            *saw_stored = 1;
            if (r.bit) { r.bit = 0; r.pos++; }
            if (r.pos + 4 > r.n) return -1;
            len = r.p[r.pos] | (uint32_t)r.p[r.pos + 1] << 8;
            nlen = r.p[r.pos + 2] | (uint32_t)r.p[r.pos + 3] << 8;
            r.pos += 4;
            if ((len ^ 0xFFFFu) != nlen || r.pos + len > r.n || o + len > cap) return -1;
            memcpy(out + o, r.p + r.pos, len);
            o += len; r.pos += len;
        } else if (type == 1) {
            *saw_fixed = 1;
            for (;;) {
                int s = getsym(&r), len, d, dist;
                if (r.err) return -1;
                if (s < 256) { if (o >= cap) return -1; out[o++] = (uint8_t)s; continue; }
                if (s == 256) break;
                if (s > 285) return -1;
                len = lb[s - 257] + (int)getbits(&r, le[s - 257]);
                for (d = 0, i = 0; i < 5; i++) d = d << 1 | (int)getbit(&r);
                if (d > 29) return -1;
                dist = db[d] + (int)getbits(&r, de[d]);
                if (r.err || (size_t)dist > o || o + (size_t)len > cap) return -1;
                while (len--) { out[o] = out[o - (size_t)dist]; o++; }
            }
        } else return -1;   /* the writer never emits dynamic blocks */
        if (r.err) return -1;
    }
    if (r.bit) r.pos++;
    if (r.pos != r.n) return -1;   /* exactly 4 bytes of Adler-32 must follow */
    for (i = 0; i < o; i++) { s1 = (s1 + out[i]) % 65521u; s2 = (s2 + s1) % 65521u; }
    if (rd32(z + zn - 4) != (s2 << 16 | s1)) return -1;
    return (long)o;
}

/* Decode a PNG from png.c; returns 0 and fills rgb (w*h*3) on success. */
static int decode(const uint8_t *p, size_t n, int w, int h, uint8_t *rgb, int *stored, int *fixed) {
    static uint8_t idat[1 << 22], raw[1 << 22];
    size_t pos = 8, zn = 0, stride = (size_t)w * 3;
    int seen_ihdr = 0, seen_iend = 0, y;
    long rn;
    if (n < 8 || memcmp(p, "\x89PNG\r\n\x1a\n", 8)) return 1;
    while (pos + 12 <= n && !seen_iend) {
        uint32_t len = rd32(p + pos);
        const uint8_t *type = p + pos + 4, *data = p + pos + 8;
        if (pos + 12 + len > n) return 2;
        if (crc_bitwise(type, len + 4) != rd32(data + len)) return 3;
        if (!memcmp(type, "IHDR", 4)) {
            if (len != 13 || (int)rd32(data) != w || (int)rd32(data + 4) != h || data[8] != 8 || data[9] != 2 ||
                data[10] || data[11] || data[12]) return 4;
            seen_ihdr = 1;
        } else if (!memcmp(type, "IDAT", 4)) {
            if (!seen_ihdr || zn + len > sizeof idat) return 5;
            memcpy(idat + zn, data, len); zn += len;
        } else if (!memcmp(type, "IEND", 4)) {
            seen_iend = len == 0;
        } else return 6;
        pos += 12 + len;
    }
    if (!seen_iend || pos != n) return 7;
    rn = inflate_min(idat, zn, raw, sizeof raw, stored, fixed);
    if (rn != (long)((stride + 1) * (size_t)h)) return 8;
    for (y = 0; y < h; y++) {
        const uint8_t *src = raw + (size_t)y * (stride + 1);
        uint8_t *dst = rgb + (size_t)y * stride;
        size_t x;
        if (src[0] > 2) return 9;
        for (x = 0; x < stride; x++) {
            int a = x >= 3 ? dst[x - 3] : 0, b = y ? dst[x - stride] : 0;
            dst[x] = (uint8_t)(src[1 + x] + (src[0] == 1 ? a : src[0] == 2 ? b : 0));
        }
    }
    return 0;
}

static uint8_t img[600 * 500 * 3], back[600 * 500 * 3];

static void roundtrip(int w, int h, int compress, const char *what) {
    uint8_t *png;
    size_t n;
    int st = 0, fx = 0, r;
    memset(back, 0xAB, sizeof back);
    T_CHECK(png_encode(img, w, h, compress, &png, &n) == 0, "%s: encode", what);
    r = decode(png, n, w, h, back, &st, &fx);
    T_CHECK(r == 0, "%s: decode error %d", what, r);
    T_CHECK(memcmp(img, back, (size_t)w * (size_t)h * 3) == 0, "%s: pixels differ", what);
    if (!compress) T_CHECK(st && !fx, "%s: stored blocks only", what);
    T_FIGURE("%s %dx%d: %zu bytes (%.1f%% of raw)", what, w, h, n, 100.0 * (double)n / ((double)w * h * 3));
    free(png);
}

int main(void) {
    unsigned long seed = T_SEED();
    int x, y, i;
    uint8_t *png;
    size_t n;
    char err[256];
    FILE *f;

    /* check values of the sums themselves */
    T_CHECK(png_crc32(0, (const uint8_t *)"123456789", 9) == 0xCBF43926u, "CRC-32 check value");
    T_CHECK(png_crc32(png_crc32(0, (const uint8_t *)"1234", 4), (const uint8_t *)"56789", 5) == 0xCBF43926u, "CRC-32 chained");
    T_CHECK(png_adler32(1, (const uint8_t *)"Wikipedia", 9) == 0x11E60398u, "Adler-32 check value");
    for (i = 0; i < (int)sizeof img; i++) img[i] = 0xFF;
    T_CHECK(png_adler32(1, img, sizeof img) == png_adler32(png_adler32(1, img, 7777), img + 7777, sizeof img - 7777),
            "Adler-32 chained over long runs");

    /* a picture-like image: flat background, gradient disc, random noise patch */
    srand((unsigned)seed);
    for (y = 0; y < 500; y++)
        for (x = 0; x < 600; x++) {
            uint8_t *p = img + ((size_t)y * 600 + (size_t)x) * 3;
            int dx = x - 300, dy = y - 250;
            if (dx * dx + dy * dy < 150 * 150) { p[0] = (uint8_t)(x / 3); p[1] = (uint8_t)(y / 2); p[2] = 90; }
            else { p[0] = 235; p[1] = 238; p[2] = 242; }
            if (x > 500 && y > 400) { p[0] = (uint8_t)rand(); p[1] = (uint8_t)rand(); p[2] = (uint8_t)rand(); }
        }
    roundtrip(600, 500, 0, "stored");   /* > 65535 bytes: several stored blocks */
    roundtrip(600, 500, 1, "fixed-Huffman");
    roundtrip(1, 1, 0, "1x1 stored");
    roundtrip(1, 1, 1, "1x1 fixed");
    for (i = 0; i < 600 * 500 * 3; i++) img[i] = (uint8_t)rand();
    roundtrip(300, 200, 1, "noise (falls back or stays <= 9/8)");
    roundtrip(7, 3, 1, "noise 7x3");
    T_CHECK(png_encode(img, 0, 5, 1, &png, &n) == -1 && png == NULL, "zero width rejected");

    /* atomic write: good path, then an unwritable one leaves nothing behind */
    {
        const char *dir = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
        char path[512];
        snprintf(path, sizeof path, "%s/sn_test_png_%ld.png", dir, (long)seed);
        T_CHECK(png_write(path, img, 7, 3, err, sizeof err) == 0, "png_write: %s", err);
        f = fopen(path, "rb");
        T_CHECK(f != NULL, "written file exists");
        if (f) { fseek(f, 0, SEEK_END); T_CHECK(ftell(f) > 57, "written file size %ld", ftell(f)); fclose(f); }
        remove(path);
        T_CHECK(png_write("/nonexistent-dir/x.png", img, 7, 3, err, sizeof err) == -1 && strstr(err, "/nonexistent-dir/x.png"),
                "unwritable path reported: %s", err);
    }
    return T_END();
}
