/* sb_json.c -- strict JSON parser into a flat tree (see sb_json.h). */
#include "sb_json.h"
#include "sb.h"
#include <stdlib.h>
#include <string.h>

typedef struct {
    sbj_doc *d;
    const char *s;
    size_t len, pos;
} psr;

static int perr(const psr *p, const char *why)
{
    size_t i, line = 1;
    for (i = 0; i < p->pos && i < p->len; i++)
        line += p->s[i] == '\n';
    return sb_fail("JSON line %lu (byte %lu): %s", (unsigned long)line, (unsigned long)p->pos, why);
}

static int new_node(psr *p, int kind)
{
    sbj_doc *d = p->d;
    if (d->nn == d->cap) {
        int cap = d->cap ? 2 * d->cap : 64;
        sbj_node *n;
        if (cap > (1 << 26)) return perr(p, "too many values");
        n = realloc(d->node, (size_t)cap * sizeof *n);
        if (!n) return perr(p, "out of memory");
        d->node = n;
        d->cap = cap;
    }
    memset(&d->node[d->nn], 0, sizeof d->node[0]);
    d->node[d->nn].kind = kind;
    d->node[d->nn].child = d->node[d->nn].next = -1;
    return d->nn++;
}

static int put_bytes(psr *p, const char *b, size_t n)
{
    sbj_doc *d = p->d;
    if (d->nt + n + 1 > d->tcap) {
        size_t cap = d->tcap ? d->tcap : 256;
        char *t;
        while (cap < d->nt + n + 1) cap *= 2;
        if (cap > ((size_t)1 << 30)) return perr(p, "strings too long");
        t = realloc(d->text, cap);
        if (!t) return perr(p, "out of memory");
        d->text = t;
        d->tcap = cap;
    }
    memcpy(d->text + d->nt, b, n);
    d->nt += n;
    return 0;
}

static void skip_ws(psr *p)
{
    while (p->pos < p->len && (p->s[p->pos] == ' ' || p->s[p->pos] == '\t' ||
                               p->s[p->pos] == '\n' || p->s[p->pos] == '\r'))
        p->pos++;
}

static int hex4(psr *p, unsigned *out)
{
    unsigned v = 0;
    int i;
    if (p->len - p->pos < 4) return perr(p, "truncated \\u escape");
    for (i = 0; i < 4; i++) {
        char c = p->s[p->pos++];
        v <<= 4;
        if (c >= '0' && c <= '9') v |= (unsigned)(c - '0');
        else if (c >= 'a' && c <= 'f') v |= (unsigned)(c - 'a' + 10);
        else if (c >= 'A' && c <= 'F') v |= (unsigned)(c - 'A' + 10);
        else { p->pos--; return perr(p, "bad hex digit in \\u escape"); }
    }
    *out = v;
    return 0;
}

static int put_utf8(psr *p, unsigned c)
{
    char b[4];
    size_t n;
    if (c < 0x80) { b[0] = (char)c; n = 1; }
    else if (c < 0x800) { b[0] = (char)(0xC0 | c >> 6); b[1] = (char)(0x80 | (c & 63)); n = 2; }
    else if (c < 0x10000) {
        b[0] = (char)(0xE0 | c >> 12); b[1] = (char)(0x80 | (c >> 6 & 63)); b[2] = (char)(0x80 | (c & 63)); n = 3;
    } else {
        b[0] = (char)(0xF0 | c >> 18); b[1] = (char)(0x80 | (c >> 12 & 63));
        b[2] = (char)(0x80 | (c >> 6 & 63)); b[3] = (char)(0x80 | (c & 63)); n = 4;
    }
    return put_bytes(p, b, n);
}

/* string at p->pos (the opening quote); its pool offset and length into off, n */
static int parse_string(psr *p, int *off, int *n)
{
    size_t start;
    p->pos++;
    start = p->d->nt;
    for (;;) {
        unsigned char c;
        if (p->pos >= p->len) return perr(p, "unterminated string");
        c = (unsigned char)p->s[p->pos];
        if (c == '"') { p->pos++; break; }
        if (c < 0x20) return perr(p, "control character in string");
        if (c != '\\') {
            size_t run = p->pos;
            while (run < p->len && p->s[run] != '"' && p->s[run] != '\\' && (unsigned char)p->s[run] >= 0x20) run++;
            if (put_bytes(p, p->s + p->pos, run - p->pos)) return -1;
            p->pos = run;
            continue;
        }
        if (++p->pos >= p->len) return perr(p, "unterminated string");
        c = (unsigned char)p->s[p->pos++];
        switch (c) {
        case '"': case '\\': case '/': if (put_bytes(p, (const char *)&c, 1)) return -1; break;
        case 'b': if (put_bytes(p, "\b", 1)) return -1; break;
        case 'f': if (put_bytes(p, "\f", 1)) return -1; break;
        case 'n': if (put_bytes(p, "\n", 1)) return -1; break;
        case 'r': if (put_bytes(p, "\r", 1)) return -1; break;
        case 't': if (put_bytes(p, "\t", 1)) return -1; break;
        case 'u': {
            unsigned u, lo;
            if (hex4(p, &u)) return -1;
            if (u >= 0xDC00 && u <= 0xDFFF) return perr(p, "lone low surrogate in \\u escape");
            if (u >= 0xD800 && u <= 0xDBFF) {
                if (p->len - p->pos < 6 || p->s[p->pos] != '\\' || p->s[p->pos + 1] != 'u')
                    return perr(p, "high surrogate without its low half");
                p->pos += 2;
                if (hex4(p, &lo)) return -1;
                if (lo < 0xDC00 || lo > 0xDFFF) return perr(p, "high surrogate without its low half");
                u = 0x10000 + ((u - 0xD800) << 10) + (lo - 0xDC00);
            }
            if (put_utf8(p, u)) return -1;
            break;
        }
        default: p->pos--; return perr(p, "unknown escape in string");
        }
    }
    if (p->d->nt - start > 0x7fffffff) return perr(p, "string too long");
    *off = (int)start;
    *n = (int)(p->d->nt - start);
    return put_bytes(p, "", 1); /* the terminating NUL stays in the pool */
}

static int parse_number(psr *p, double *out)
{
    size_t st = p->pos, i = p->pos;
    char buf[64];
    const char *s = p->s;
    if (i < p->len && s[i] == '-') i++;
    if (i < p->len && s[i] == '0') i++;
    else if (i < p->len && s[i] >= '1' && s[i] <= '9') while (i < p->len && s[i] >= '0' && s[i] <= '9') i++;
    else { p->pos = i; return perr(p, "bad number"); }
    if (i < p->len && s[i] == '.') {
        i++;
        if (!(i < p->len && s[i] >= '0' && s[i] <= '9')) { p->pos = i; return perr(p, "bad number: digit expected after '.'"); }
        while (i < p->len && s[i] >= '0' && s[i] <= '9') i++;
    }
    if (i < p->len && (s[i] == 'e' || s[i] == 'E')) {
        i++;
        if (i < p->len && (s[i] == '+' || s[i] == '-')) i++;
        if (!(i < p->len && s[i] >= '0' && s[i] <= '9')) { p->pos = i; return perr(p, "bad number: digit expected in exponent"); }
        while (i < p->len && s[i] >= '0' && s[i] <= '9') i++;
    }
    if (i - st >= sizeof buf) return perr(p, "number too long");
    memcpy(buf, s + st, i - st);
    buf[i - st] = 0;
    *out = strtod(buf, NULL);
    p->pos = i;
    return 0;
}

static int parse_value(psr *p, int depth);

/* members of an array or object; n is the container's node */
static int parse_members(psr *p, int n, int depth, int is_obj)
{
    int last = -1;
    char close = is_obj ? '}' : ']';
    p->pos++;
    skip_ws(p);
    if (p->pos < p->len && p->s[p->pos] == close) { p->pos++; return 0; }
    for (;;) {
        int key = 0, klen = 0, v;
        skip_ws(p);
        if (is_obj) {
            if (p->pos >= p->len || p->s[p->pos] != '"') return perr(p, "object key (a string) expected");
            if (parse_string(p, &key, &klen)) return -1;
            skip_ws(p);
            if (p->pos >= p->len || p->s[p->pos] != ':') return perr(p, "':' expected after object key");
            p->pos++;
        }
        v = parse_value(p, depth + 1);
        if (v < 0) return -1;
        p->d->node[v].key = key;
        p->d->node[v].klen = klen;
        if (last < 0) p->d->node[n].child = v;
        else p->d->node[last].next = v;
        last = v;
        p->d->node[n].count++;
        skip_ws(p);
        if (p->pos >= p->len) return perr(p, is_obj ? "unterminated object" : "unterminated array");
        if (p->s[p->pos] == ',') { p->pos++; continue; }
        if (p->s[p->pos] == close) { p->pos++; return 0; }
        return perr(p, is_obj ? "',' or '}' expected" : "',' or ']' expected");
    }
}

static int lit(psr *p, const char *w, int kind)
{
    size_t n = strlen(w);
    if (p->len - p->pos < n || memcmp(p->s + p->pos, w, n)) return perr(p, "unexpected character");
    p->pos += n;
    return new_node(p, kind);
}

/* returns the node index or -1 */
static int parse_value(psr *p, int depth)
{
    int n;
    char c;
    if (depth > SBJ_MAX_DEPTH) return perr(p, "nesting deeper than 64");
    skip_ws(p);
    if (p->pos >= p->len) return perr(p, "value expected, end of text found");
    c = p->s[p->pos];
    switch (c) {
    case '{': case '[':
        n = new_node(p, c == '{' ? SBJ_OBJ : SBJ_ARR);
        if (n < 0 || parse_members(p, n, depth, c == '{')) return -1;
        return n;
    case '"': {
        int off, len;
        n = new_node(p, SBJ_STR);
        if (n < 0 || parse_string(p, &off, &len)) return -1;
        p->d->node[n].str = off;
        p->d->node[n].slen = len;
        return n;
    }
    case 't': return lit(p, "true", SBJ_TRUE);
    case 'f': return lit(p, "false", SBJ_FALSE);
    case 'n': return lit(p, "null", SBJ_NULL);
    default: {
        double v = 0;
        if (c != '-' && (c < '0' || c > '9')) return perr(p, "unexpected character");
        if (parse_number(p, &v)) return -1;
        n = new_node(p, SBJ_NUM);
        if (n >= 0) p->d->node[n].num = v;
        return n;
    }
    }
}

int sbj_parse(sbj_doc *d, const char *src, size_t len)
{
    psr p;
    memset(d, 0, sizeof *d);
    p.d = d;
    p.s = src;
    p.len = len;
    p.pos = 0;
    if (put_bytes(&p, "", 1)) goto fail; /* offset 0: the empty key */
    if (parse_value(&p, 1) != 0) goto fail;
    skip_ws(&p);
    if (p.pos != len) { perr(&p, "text after the JSON value"); goto fail; }
    return 0;
fail:
    sbj_free(d);
    return -1;
}

void sbj_free(sbj_doc *d)
{
    free(d->node);
    free(d->text);
    memset(d, 0, sizeof *d);
}

int sbj_get(const sbj_doc *d, int obj, const char *key)
{
    int c;
    size_t kl = strlen(key);
    if (obj < 0 || d->node[obj].kind != SBJ_OBJ) return -1;
    for (c = d->node[obj].child; c >= 0; c = d->node[c].next)
        if ((size_t)d->node[c].klen == kl && !memcmp(d->text + d->node[c].key, key, kl)) return c;
    return -1;
}

int sbj_at(const sbj_doc *d, int arr, int i)
{
    int c;
    if (arr < 0 || d->node[arr].kind != SBJ_ARR || i < 0 || i >= d->node[arr].count) return -1;
    for (c = d->node[arr].child; i > 0; i--) c = d->node[c].next;
    return c;
}

const char *sbj_str(const sbj_doc *d, int n)
{
    return n >= 0 && d->node[n].kind == SBJ_STR ? d->text + d->node[n].str : NULL;
}
