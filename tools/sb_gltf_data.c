/* sb_gltf_data.c -- glTF 2.0 reader, the data layer: the file, the GLB
 * container, buffers (external, base64 data URI, GLB BIN), bufferViews and
 * accessors. Every length from the file is checked before use, in 64-bit
 * arithmetic on values already bounded (so the sums cannot wrap). */
#include "sb_gltf_int.h"
#include "sb.h"
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_FILE ((size_t)1 << 30)
#define MAX_LEN (1LL << 40)      /* any byte length or offset in the JSON */

static const char *const top_names[GA_COUNT] = {"buffers", "bufferViews", "accessors", "nodes", "meshes", "skins", "scenes", "animations"};

int gl_read_file(const char *path, unsigned char **data, size_t *len)
{
    FILE *f = fopen(path, "rb");
    long n;
    *data = NULL;
    *len = 0;
    if (!f) return sb_fail("cannot open %s", path);
    if (fseek(f, 0, SEEK_END) || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET)) {
        fclose(f);
        return sb_fail("cannot read %s", path);
    }
    if ((size_t)n > MAX_FILE) { fclose(f); return sb_fail("%s: larger than 1 GiB", path); }
    *data = malloc((size_t)n + 1);
    if (!*data) { fclose(f); return sb_fail("%s: out of memory", path); }
    if (fread(*data, 1, (size_t)n, f) != (size_t)n) {
        fclose(f);
        free(*data);
        *data = NULL;
        return sb_fail("cannot read %s", path);
    }
    fclose(f);
    *len = (size_t)n;
    return 0;
}

int gl_elem(const gl_doc *d, int which, int i)
{
    return i >= 0 && i < d->count[which] ? d->elem[which][i] : -1;
}

int gl_int(const gl_doc *d, int obj, const char *key, const char *path,
           long long dflt, long long lo, long long hi, long long *out)
{
    int n = sbj_get(&d->j, obj, key);
    double v;
    if (n < 0) {
        if (dflt == GL_REQUIRED) return sb_fail("%s.%s: missing", path, key);
        *out = dflt;
        return 0;
    }
    v = d->j.node[n].num;
    if (d->j.node[n].kind != SBJ_NUM || v != floor(v))
        return sb_fail("%s.%s: an integer expected", path, key);
    if (v < (double)lo || v > (double)hi)
        return sb_fail("%s.%s: %.17g is out of range [%lld, %lld]", path, key, v, lo, hi);
    *out = (long long)v;
    return 0;
}

/* 1 if present (n numbers into out), 0 if absent, -1 on error */
int gl_nums(const gl_doc *d, int obj, const char *key, const char *path, int n, double *out)
{
    int a = sbj_get(&d->j, obj, key), c, i = 0;
    if (a < 0) return 0;
    if (d->j.node[a].kind != SBJ_ARR || d->j.node[a].count != n)
        return sb_fail("%s.%s: an array of %d numbers expected", path, key, n);
    for (c = d->j.node[a].child; c >= 0; c = d->j.node[c].next, i++) {
        if (d->j.node[c].kind != SBJ_NUM) return sb_fail("%s.%s[%d]: a number expected", path, key, i);
        out[i] = d->j.node[c].num;
    }
    return 1;
}

static unsigned rd32(const unsigned char *p)
{
    return (unsigned)p[0] | (unsigned)p[1] << 8 | (unsigned)p[2] << 16 | (unsigned)p[3] << 24;
}

/* GLB: 12-byte header, JSON chunk, optional BIN chunk; sets the JSON text and length */
static int open_glb(gl_doc *d, const char **json, size_t *jlen)
{
    const unsigned char *f = d->file;
    size_t n = d->file_len, len, at, clen;
    if (n < 12) return sb_fail("GLB header: the file is %lu bytes, shorter than the 12-byte header", (unsigned long)n);
    if (rd32(f) != 0x46546C67u) return sb_fail("GLB header.magic: not \"glTF\"");
    if (rd32(f + 4) != 2) return sb_fail("GLB header.version: %u, only 2 is read", rd32(f + 4));
    len = rd32(f + 8);
    if (len != n) return sb_fail("GLB header.length: %lu, but the file is %lu bytes", (unsigned long)len, (unsigned long)n);
    if (n - 12 < 8) return sb_fail("GLB chunks[0]: truncated chunk header (the JSON chunk is required)");
    clen = rd32(f + 12);
    if (rd32(f + 16) != 0x4E4F534Au) return sb_fail("GLB chunks[0].chunkType: not JSON");
    if (clen > n - 20)
        return sb_fail("GLB chunks[0].chunkLength: %lu overruns the file (%lu bytes left)", (unsigned long)clen, (unsigned long)(n - 20));
    *json = (const char *)f + 20;
    *jlen = clen;
    at = 20 + clen;
    at += (4 - at % 4) % 4;   /* chunks start 4-byte aligned */
    if (at < n) {
        if (n - at < 8) return sb_fail("GLB chunks[1]: truncated chunk header");
        clen = rd32(f + at);
        if (clen > n - at - 8)
            return sb_fail("GLB chunks[1].chunkLength: %lu overruns the file (%lu bytes left)", (unsigned long)clen, (unsigned long)(n - at - 8));
        if (rd32(f + at + 4) == 0x004E4942u) {
            d->bin = f + at + 8;
            d->bin_len = clen;
        }
    }
    return 0;
}

static int b64val(int c)
{
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}

/* strict base64 (length a multiple of 4, '=' only as the last padding) */
static int b64_decode(const char *s, size_t n, const char *path, unsigned char **out, size_t *olen)
{
    size_t i, o = 0;
    unsigned char *b;
    if (n % 4) return sb_fail("%s: base64 data of %lu characters, not a multiple of 4", path, (unsigned long)n);
    b = malloc(n / 4 * 3 + 1);
    if (!b) return sb_fail("%s: out of memory", path);
    for (i = 0; i < n; i += 4) {
        int v[4], k, pad = 0;
        for (k = 0; k < 4; k++) {
            char c = s[i + k];
            if (c == '=' && i + 4 == n && (k == 3 || (k == 2 && s[i + 3] == '='))) { v[k] = 0; pad++; continue; }
            v[k] = b64val((unsigned char)c);
            if (v[k] < 0 || pad) {
                free(b);
                return sb_fail("%s: bad base64 character at offset %lu", path, (unsigned long)(i + k));
            }
        }
        b[o++] = (unsigned char)(v[0] << 2 | v[1] >> 4);
        if (pad < 2) b[o++] = (unsigned char)((v[1] & 15) << 4 | v[2] >> 2);
        if (pad < 1) b[o++] = (unsigned char)((v[2] & 3) << 6 | v[3]);
    }
    *out = b;
    *olen = o;
    return 0;
}

/* a relative URI's %XX escapes (exporters write "a%20b.bin"); -1 if malformed */
static int pct_decode(char *o, const char *u)
{
    for (; *u; u++, o++) {
        char hx[3];
        if (*u != '%') {
            *o = *u;
            continue;
        }
        if (!isxdigit((unsigned char)u[1]) || !isxdigit((unsigned char)u[2])) return -1;
        hx[0] = u[1], hx[1] = u[2], hx[2] = 0;
        if (!(*o = (char)strtol(hx, NULL, 16))) return -1;
        u += 2;
    }
    *o = 0;
    return 0;
}

static int load_buffer(gl_doc *d, int i)
{
    char path[64], file[2048];
    int b = gl_elem(d, GA_BUFFERS, i), u;
    long long blen;
    const char *uri;
    unsigned char *data = NULL;
    size_t dlen = 0;
    snprintf(path, sizeof path, "buffers[%d]", i);
    if (gl_int(d, b, "byteLength", path, GL_REQUIRED, 1, MAX_LEN, &blen)) return -1;
    u = sbj_get(&d->j, b, "uri");
    if (u < 0) {
        if (i != 0 || !d->bin) return sb_fail("%s: no uri, and not the GLB's BIN chunk", path);
        if ((unsigned long long)blen > (unsigned long long)d->bin_len)
            return sb_fail("%s.byteLength: %lld, but the GLB BIN chunk has %lu bytes", path, blen, (unsigned long)d->bin_len);
        d->buf[i] = (unsigned char *)d->bin;
        d->buf_len[i] = (size_t)blen;
        return 0;
    }
    if (!(uri = sbj_str(&d->j, u))) return sb_fail("%s.uri: a string expected", path);
    strcat(path, ".uri");
    if (!strncmp(uri, "data:", 5)) {
        const char *c = strstr(uri, ";base64,");
        if (!c) return sb_fail("%s: a data URI without ';base64,'", path);
        c += 8;
        if (b64_decode(c, (size_t)d->j.node[u].slen - (size_t)(c - uri), path, &data, &dlen)) return -1;
    } else {
        if (uri[0] == '/' || strstr(uri, "://") || strlen(d->dir) + strlen(uri) + 1 > sizeof file)
            return sb_fail("%s: \"%s\" is not a relative file name", path, uri);
        strcpy(file, d->dir);
        if (pct_decode(file + strlen(file), uri)) return sb_fail("%s: bad %%-escape in \"%s\"", path, uri);
        if (gl_read_file(file, &data, &dlen)) return sb_fail("%s: cannot read \"%s\"", path, file);
    }
    d->buf[i] = data;
    d->buf_owned[i] = 1;
    d->buf_len[i] = (size_t)blen;
    if ((unsigned long long)dlen < (unsigned long long)blen)
        return sb_fail("%s: %lu bytes, but byteLength says %lld", path, (unsigned long)dlen, blen);
    return 0;
}

int gl_open(gl_doc *d, const char *path)
{
    const char *json = NULL, *slash;
    size_t jlen = 0, k;
    int w;
    memset(d, 0, sizeof *d);
    if (gl_read_file(path, &d->file, &d->file_len)) return -1;
    slash = strrchr(path, '/');
    k = slash ? (size_t)(slash - path + 1) : 0;
    if (k >= sizeof d->dir) return sb_fail("%s: path too long", path);
    memcpy(d->dir, path, k);
    d->dir[k] = 0;
    k = strlen(path);
    if ((d->file_len >= 4 && !memcmp(d->file, "glTF", 4)) || (k >= 4 && !strcmp(path + k - 4, ".glb"))) {
        if (open_glb(d, &json, &jlen)) return -1;
    } else {
        json = (const char *)d->file;
        jlen = d->file_len;
        if (jlen >= 3 && !memcmp(json, "\xEF\xBB\xBF", 3)) json += 3, jlen -= 3;
    }
    if (sbj_parse(&d->j, json, jlen)) return -1;
    if (d->j.node[0].kind != SBJ_OBJ) return sb_fail("the JSON root is not an object");
    {
        int a = sbj_get(&d->j, 0, "asset"), v = sbj_get(&d->j, a, "version");
        const char *s = sbj_str(&d->j, v);
        if (a < 0) return sb_fail("asset: missing");
        if (!s) return sb_fail("asset.version: missing");
        if (strncmp(s, "2.", 2)) return sb_fail("asset.version: \"%s\", only 2.x is read", s);
    }
    {
        int r = sbj_get(&d->j, 0, "extensionsRequired");
        if (r >= 0 && d->j.node[r].count > 0) {
            const char *e = sbj_str(&d->j, d->j.node[r].child);
            return sb_fail("extensionsRequired[0]: \"%s\" is not supported", e ? e : "?");
        }
    }
    for (w = 0; w < GA_COUNT; w++) {
        int a = sbj_get(&d->j, 0, top_names[w]), c, i = 0;
        d->arr[w] = a;
        if (a < 0) continue;
        if (d->j.node[a].kind != SBJ_ARR) return sb_fail("%s: an array expected", top_names[w]);
        d->count[w] = d->j.node[a].count;
        d->elem[w] = sb_alloc((size_t)d->count[w] * sizeof *d->elem[w]);
        for (c = d->j.node[a].child; c >= 0; c = d->j.node[c].next, i++) {
            if (d->j.node[c].kind != SBJ_OBJ) return sb_fail("%s[%d]: an object expected", top_names[w], i);
            d->elem[w][i] = c;
        }
    }
    d->nbuf = d->count[GA_BUFFERS];
    d->buf = sb_alloc((size_t)d->nbuf * sizeof *d->buf);
    d->buf_len = sb_alloc((size_t)d->nbuf * sizeof *d->buf_len);
    d->buf_owned = sb_alloc((size_t)d->nbuf * sizeof *d->buf_owned);
    for (w = 0; w < d->nbuf; w++)
        if (load_buffer(d, w)) return -1;
    return 0;
}

void gl_close(gl_doc *d)
{
    int i;
    for (i = 0; i < d->nbuf; i++)
        if (d->buf_owned[i]) free(d->buf[i]);
    free(d->buf);
    free(d->buf_len);
    free(d->buf_owned);
    for (i = 0; i < GA_COUNT; i++) free(d->elem[i]);
    free(d->file);
    sbj_free(&d->j);
    memset(d, 0, sizeof *d);
}

static int comp_size(long long t)
{
    switch (t) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
    }
}

static double comp_value(const unsigned char *p, int t, int norm)
{
    unsigned u;
    float f;
    switch (t) {
    case 5120: return norm ? fmax((signed char)p[0] / 127.0, -1.0) : (signed char)p[0];
    case 5121: return norm ? p[0] / 255.0 : p[0];
    case 5122: {
        short s = (short)(p[0] | p[1] << 8);
        return norm ? fmax(s / 32767.0, -1.0) : s;
    }
    case 5123: u = (unsigned)(p[0] | p[1] << 8); return norm ? u / 65535.0 : u;
    case 5125: return rd32(p);
    default: u = rd32(p); memcpy(&f, &u, 4); return f;
    }
}

int gl_accessor(const gl_doc *d, int a, gl_acc *out)
{
    static const char *const types[] = {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT4"};
    static const int ncomps[] = {1, 2, 3, 4, 16};
    char path[64], vpath[64];
    int acc = gl_elem(d, GA_ACCESSORS, a), vn, t, csize, elem, nt = -1, norm = 0, nb;
    long long ctype = 0, count = 0, off = 0, view = 0, voff = 0, vlen = 0, stride = 0, buf = 0, k; /* set before use; -O3 cannot tell */
    const char *type;
    memset(out, 0, sizeof *out);
    snprintf(path, sizeof path, "accessors[%d]", a);
    if (acc < 0) return sb_fail("%s: no such accessor", path);
    if (sbj_get(&d->j, acc, "sparse") >= 0)
        return sb_fail("%s.sparse: sparse accessors are not supported (export them dense)", path);
    if (gl_int(d, acc, "componentType", path, GL_REQUIRED, 0, 1LL << 31, &ctype)) return -1;
    if (!(csize = comp_size(ctype))) return sb_fail("%s.componentType: %lld is not a glTF component type", path, ctype);
    if ((nb = sbj_get(&d->j, acc, "normalized")) >= 0) {
        if (d->j.node[nb].kind != SBJ_TRUE && d->j.node[nb].kind != SBJ_FALSE)
            return sb_fail("%s.normalized: true or false expected", path);
        norm = d->j.node[nb].kind == SBJ_TRUE;
        if (norm && (ctype == 5125 || ctype == 5126))
            return sb_fail("%s.normalized: not allowed with componentType %lld", path, ctype);
    }
    type = sbj_str(&d->j, sbj_get(&d->j, acc, "type"));
    if (!type) return sb_fail("%s.type: missing", path);
    for (t = 0; t < 5; t++)
        if (!strcmp(type, types[t])) nt = t;
    if (nt < 0) return sb_fail("%s.type: \"%s\" is not read (SCALAR, VEC2, VEC3, VEC4, MAT4)", path, type);
    if (nt == 4 && ctype != 5126) return sb_fail("%s.type: MAT4 is read only with float components", path);
    if (gl_int(d, acc, "count", path, GL_REQUIRED, 1, 1LL << 28, &count)) return -1;
    if (gl_int(d, acc, "byteOffset", path, 0, 0, MAX_LEN, &off)) return -1;
    /* no bufferView means all zeros (or sparse): never what a skin needs */
    if (gl_int(d, acc, "bufferView", path, GL_REQUIRED, 0, d->count[GA_VIEWS] - 1, &view)) return -1;
    elem = csize * ncomps[nt];
    vn = gl_elem(d, GA_VIEWS, (int)view);
    snprintf(vpath, sizeof vpath, "bufferViews[%lld]", view);
    if (gl_int(d, vn, "buffer", vpath, GL_REQUIRED, 0, d->nbuf - 1, &buf) ||
        gl_int(d, vn, "byteOffset", vpath, 0, 0, MAX_LEN, &voff) ||
        gl_int(d, vn, "byteLength", vpath, GL_REQUIRED, 1, MAX_LEN, &vlen) ||
        gl_int(d, vn, "byteStride", vpath, 0, 0, 252, &stride))
        return -1;
    if (stride && (stride < 4 || stride % 4)) {
        sb_fail("%s.byteStride: %lld, glTF allows 4..252 in steps of 4", vpath, stride);
        return -1;
    }
    if ((unsigned long long)voff + (unsigned long long)vlen > d->buf_len[buf]) {
        sb_fail("%s: byteOffset %lld + byteLength %lld overrun buffers[%lld] (byteLength %lu)", vpath, voff, vlen, buf,
                (unsigned long)d->buf_len[buf]);
        return -1;
    }
    if (stride && stride < elem) {
        sb_fail("%s.byteStride: %lld is smaller than the %d-byte elements of %s", vpath, stride, elem, path);
        return -1;
    }
    if (!stride) stride = elem;
    if ((voff + off) % csize) {
        sb_fail("%s.byteOffset: %lld (+ %s.byteOffset %lld) is not a multiple of the %d-byte component", path, off, vpath, voff, csize);
        return -1;
    }
    /* count <= 2^28, stride <= 252, off <= 2^40: no wrap */
    if ((unsigned long long)off + (unsigned long long)stride * (unsigned long long)(count - 1) + (unsigned long long)elem >
        (unsigned long long)vlen) {
        sb_fail("%s.count: %lld elements of %d bytes (stride %lld, byteOffset %lld) overrun %s (length %lld)", path, count, elem,
                stride, off, vpath, vlen);
        return -1;
    }
    out->count = count;
    out->ncomp = ncomps[nt];
    out->ctype = (int)ctype;
    out->normalized = norm;
    out->v = sb_alloc((size_t)count * (size_t)ncomps[nt] * sizeof *out->v);
    for (k = 0; k < count; k++) {
        const unsigned char *p = d->buf[buf] + voff + off + k * stride;
        int c;
        for (c = 0; c < ncomps[nt]; c++) out->v[k * ncomps[nt] + c] = comp_value(p + c * csize, (int)ctype, norm);
    }
    return 0;
}
