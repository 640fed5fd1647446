/* sn_clip.c -- clip text parser (format: CLIP.md). string.h only: runs on
 * bare metal; numbers go straight to Q16.16 with our own decimal reader. */
#include "sn_clip.h"
#include <string.h>

#define Q16_ONE 65536

/* ---- error text without stdio ---- */
typedef struct { char *buf; size_t cap, len; } msgbuf;

static void m_str(msgbuf *m, const char *s, size_t n) {
    size_t i;
    for (i = 0; i < n && s[i]; i++)
        if (m->len + 1 < m->cap) m->buf[m->len++] = s[i];
    if (m->cap) m->buf[m->len] = 0;
}
static void m_cstr(msgbuf *m, const char *s) { m_str(m, s, (size_t)-1); }
static void m_uint(msgbuf *m, uint32_t v) {
    char d[12]; int n = 0;
    do { d[n++] = (char)('0' + v % 10u); v /= 10u; } while (v);
    while (n) { char c = d[--n]; m_str(m, &c, 1); }
}

int sn_clip_parse_q16(const char *s, size_t n, int32_t *out) {
    size_t i = 0;
    int neg = 0, nint = 0, nfrac = 0;
    uint32_t ip = 0, fp = 0, scale = 1;
    uint64_t q;
    if (i < n && (s[i] == '+' || s[i] == '-')) { neg = s[i] == '-'; i++; }
    for (; i < n && s[i] >= '0' && s[i] <= '9'; i++, nint++) {
        if (ip >= 32768u) return 2;     /* stop before it can wrap */
        ip = ip * 10u + (uint32_t)(s[i] - '0');
    }
    if (i < n && s[i] == '.') {
        for (i++; i < n && s[i] >= '0' && s[i] <= '9'; i++, nfrac++)
            if (nfrac < 9) { fp = fp * 10u + (uint32_t)(s[i] - '0'); scale *= 10u; }
    }
    if (i != n || nint + nfrac == 0) return 1;
    /* round(fp / scale * 2^16), half away from zero (applied to the magnitude) */
    q = ((uint64_t)ip << 16) + (((uint64_t)fp << 16) + scale / 2u) / scale;
    if (q >= (uint64_t)32768 << 16) return 2;
    *out = neg ? -(int32_t)q : (int32_t)q;
    return 0;
}

/* ---- keys more than 180 degrees apart (integer only) ---- */
#define Q30 ((int64_t)1 << 30)
#define DEG(d) ((int64_t)(d) << 16)

static int64_t mul30(int64_t a, int64_t b) { return a * b / Q30; }

/* sin, cos of half of deg (Q16.16 degrees) in Q30: quadrant + Taylor series */
static void half_sincos(int64_t deg, int64_t *s, int64_t *c) {
    int64_t r = deg % DEG(720), f, x, x2, ts, tc, ss = 0, cc = 0;
    int q, n;
    if (r < 0) r += DEG(720);
    q = (int)(r / DEG(180));
    f = r % DEG(180);
    x = f * 1686629713 / DEG(180);   /* radians of the half angle in [0, pi/2), Q30 */
    x2 = mul30(x, x);
    ts = x; tc = Q30;
    for (n = 0; n < 7; n++) {
        ss += ts; cc += tc;
        ts = -mul30(ts, x2) / ((2 * n + 2) * (2 * n + 3));
        tc = -mul30(tc, x2) / ((2 * n + 1) * (2 * n + 2));
    }
    switch (q) {
    case 0: *s = ss; *c = cc; break;
    case 1: *s = cc; *c = -ss; break;
    case 2: *s = -ss; *c = -cc; break;
    default: *s = -cc; *c = ss; break;
    }
}

static uint64_t isqrt64(uint64_t v) {
    uint64_t r = 0, b = (uint64_t)1 << 62;
    while (b > v) b >>= 2;
    for (; b; b >>= 2)
        if (v >= r + b) { v -= r + b; r = (r >> 1) + b; } else r >>= 1;
    return r;
}

/* Unit axis in Q30 (the axis is non-zero). */
static void unit_axis(const int32_t v[3], int64_t n[3]) {
    int64_t a[3], m = 0, l;
    int i;
    for (i = 0; i < 3; i++) { a[i] = v[i]; if ((a[i] < 0 ? -a[i] : a[i]) > m) m = a[i] < 0 ? -a[i] : a[i]; }
    while (m < ((int64_t)1 << 28)) { for (i = 0; i < 3; i++) a[i] *= 2; m *= 2; }
    while (m >= ((int64_t)1 << 29)) { for (i = 0; i < 3; i++) a[i] /= 2; m /= 2; }
    l = (int64_t)isqrt64((uint64_t)(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]));
    for (i = 0; i < 3; i++) n[i] = a[i] * Q30 / l;
}

/* Turn between keys a and b as written (Q16.16 degrees) and the turn the
 * shorter-arc slerp makes; 1 when they differ (written turn > 180), also when
 * it is 180 (the way round is then up to rounding). */
static int long_turn(const sn_clip_key *a, const sn_clip_key *b, int64_t *apart, int64_t *taken) {
    int64_t na[3], nb[3], cosax, sa, ca, sb, cb, d, lo, hi;
    unit_axis(a->v, na); unit_axis(b->v, nb);
    cosax = (na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2]) / Q30;
    if (a->v[3] == 0 || b->v[3] == 0 || cosax > Q30 - 64 || cosax < -(Q30 - 64)) {
        /* one axis (a zero angle has any axis): exact in degrees */
        d = (int64_t)b->v[3] - (cosax < -(Q30 - 64) && a->v[3] && b->v[3] ? -(int64_t)a->v[3] : (int64_t)a->v[3]);
        *apart = d < 0 ? -d : d;
        *taken = *apart % DEG(360);
        if (*taken > DEG(180)) *taken = DEG(360) - *taken;
        return *apart >= DEG(180);
    }
    /* q_a . q_b = cos(turn / 2); below 0 the slerp flips q_b */
    half_sincos(a->v[3], &sa, &ca); half_sincos(b->v[3], &sb, &cb);
    d = mul30(ca, cb) + mul30(cosax, mul30(sa, sb));
    if (d > Q30 >> 14) return 0;
    if (d >= -(Q30 >> 14)) { *apart = *taken = DEG(180); return 1; }   /* 180 to ~0.01 degree */
    lo = DEG(180); hi = DEG(360);       /* turn with cos(turn / 2) = d, by bisection */
    while (hi - lo > 1) {
        int64_t mid = (lo + hi) / 2, s, c;
        half_sincos(mid, &s, &c);
        if (c > d) lo = mid; else hi = mid;
    }
    *apart = lo;
    *taken = DEG(360) - lo;
    return 1;
}

/* ---- tokens of one line ---- */
#define MAX_TOK 17   /* the longest line: a capsule collider with vel and mu */
typedef struct { const char *p[MAX_TOK]; size_t n[MAX_TOK]; int count; } toks;

/* Splits at blanks, stops at '#'. Returns the token count, MAX_TOK+1 if too many. */
static int tokenize(const char *s, size_t n, toks *t) {
    size_t i = 0;
    t->count = 0;
    for (;;) {
        while (i < n && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) i++;
        if (i >= n || s[i] == '#') break;
        if (t->count == MAX_TOK) return MAX_TOK + 1;
        t->p[t->count] = s + i;
        while (i < n && s[i] != ' ' && s[i] != '\t' && s[i] != '\r' && s[i] != '#') i++;
        t->n[t->count] = (size_t)(s + i - t->p[t->count]);
        t->count++;
    }
    return t->count;
}

static int tok_is(const toks *t, int k, const char *w) {
    size_t wl = strlen(w);
    return t->n[k] == wl && memcmp(t->p[k], w, wl) == 0;
}

typedef struct {
    sn_clip *clip;
    msgbuf m;
    uint32_t line;
    int have_header, have_duration, have_loop;
} pstate;

static int fail(pstate *ps, const char *what, const char *tok, size_t tokn) {
    ps->m.len = 0;
    m_cstr(&ps->m, "line "); m_uint(&ps->m, ps->line); m_cstr(&ps->m, ": ");
    m_cstr(&ps->m, what);
    if (tok) { m_cstr(&ps->m, " '"); m_str(&ps->m, tok, tokn < 40 ? tokn : 40); m_cstr(&ps->m, "'"); }
    ps->clip->error_line = ps->line;
    return 1;
}

static int num(pstate *ps, const toks *t, int k, const char *what, int32_t *out) {
    int r = sn_clip_parse_q16(t->p[k], t->n[k], out);
    if (r == 1) return fail(ps, what, t->p[k], t->n[k]);
    if (r == 2) return fail(ps, "number out of range (|x| < 32768):", t->p[k], t->n[k]);
    return 0;
}

/* Channel for (kind, name), created on first use. -1 when full. */
static int channel(sn_clip *c, uint8_t kind, const char *name, size_t n) {
    int i;
    for (i = 0; i < c->n_channels; i++)
        if (c->chan[i].kind == kind && strlen(c->chan[i].name) == n &&
            memcmp(c->chan[i].name, name, n) == 0) return i;
    if (c->n_channels >= SN_CLIP_MAX_CHANNELS) return -1;
    i = c->n_channels++;
    memset(&c->chan[i], 0, sizeof c->chan[i]);
    memcpy(c->chan[i].name, name, n);
    c->chan[i].joint = -1;
    c->chan[i].kind = kind;
    c->chan[i].first = c->n_keys;
    return i;
}

/* Append a key to channel ci, keeping every channel's keys contiguous. */
static int add_key(pstate *ps, int ci, const sn_clip_key *k, const char *tok, size_t tokn) {
    sn_clip *c = ps->clip;
    sn_clip_channel *ch = &c->chan[ci];
    uint16_t at = (uint16_t)(ch->first + ch->count);
    int i;
    if (k->t < 0) return fail(ps, "key time is negative:", tok, tokn);
    if (k->t > c->duration) return fail(ps, "key time is after the clip duration:", tok, tokn);
    if (ch->count && k->t <= c->keys[at - 1].t)
        return fail(ps, "key times of a channel must strictly increase; not after the previous key:", tok, tokn);
    if (c->n_keys >= SN_CLIP_MAX_KEYS) return fail(ps, "too many keys (limit SN_CLIP_MAX_KEYS)", 0, 0);
    if (ch->kind == SN_CLIP_ROT && ch->count) {
        int64_t apart, taken;
        if (long_turn(&c->keys[at - 1], k, &apart, &taken)) {
            if (c->n_warnings < SN_CLIP_MAX_WARNINGS) {
                sn_clip_warning *w = &c->warn[c->n_warnings];
                w->line = ps->line;
                w->channel = (uint16_t)ci;
                w->t_a = c->keys[at - 1].t; w->t_b = k->t;
                w->apart = apart > INT32_MAX ? INT32_MAX : (int32_t)apart;
                w->taken = (int32_t)taken;
            }
            if (c->n_warnings < UINT32_MAX) c->n_warnings++;
        }
    }
    memmove(&c->keys[at + 1], &c->keys[at], (size_t)(c->n_keys - at) * sizeof c->keys[0]);
    c->keys[at] = *k;
    c->n_keys++;
    ch->count++;
    for (i = 0; i < c->n_channels; i++)
        if (i != ci && c->chan[i].first >= at && c->chan[i].count) c->chan[i].first++;
    return 0;
}

static int parse_line(pstate *ps, const char *s, size_t n) {
    sn_clip *c = ps->clip;
    toks t;
    int nt = tokenize(s, n, &t);
    if (nt == 0) return 0;
    if (nt > MAX_TOK) return fail(ps, "too many fields", 0, 0);
    if (!ps->have_header) {
        if (!tok_is(&t, 0, "sinew-clip"))
            return fail(ps, "a clip must start with the line 'sinew-clip 1', found", t.p[0], t.n[0]);
        if (nt != 2 || !tok_is(&t, 1, "1"))
            return fail(ps, "unsupported clip format version (this reader knows 'sinew-clip 1')", 0, 0);
        ps->have_header = 1;
        return 0;
    }
    if (tok_is(&t, 0, "duration")) {
        if (nt != 2) return fail(ps, "usage: duration <seconds>", 0, 0);
        if (ps->have_duration) return fail(ps, "duration given twice", 0, 0);
        if (num(ps, &t, 1, "duration is not a number:", &c->duration)) return 1;
        if (c->duration <= 0) return fail(ps, "duration must be > 0:", t.p[1], t.n[1]);
        ps->have_duration = 1;
        return 0;
    }
    if (tok_is(&t, 0, "loop")) {
        if (nt != 2) return fail(ps, "usage: loop yes|no", 0, 0);
        if (ps->have_loop) return fail(ps, "loop given twice", 0, 0);
        if (tok_is(&t, 1, "yes")) c->loop = 1;
        else if (tok_is(&t, 1, "no")) c->loop = 0;
        else return fail(ps, "loop must be yes or no, found", t.p[1], t.n[1]);
        ps->have_loop = 1;
        return 0;
    }
    if (tok_is(&t, 0, "rot") || tok_is(&t, 0, "move")) {
        int rot = tok_is(&t, 0, "rot"), ci, k0 = rot ? 2 : 1;
        sn_clip_key key;
        memset(&key, 0, sizeof key);
        if (!ps->have_duration) return fail(ps, "'duration' must come before the first key", 0, 0);
        if (rot && nt != 7) return fail(ps, "usage: rot <joint> <time> <axis x> <axis y> <axis z> <angle degrees>", 0, 0);
        if (!rot && nt != 5) return fail(ps, "usage: move <time> <x> <y> <z>", 0, 0);
        if (rot && t.n[1] > SN_CLIP_NAME_MAX) return fail(ps, "joint name longer than 31 bytes:", t.p[1], t.n[1]);
        if (num(ps, &t, k0, "key time is not a number:", &key.t)) return 1;
        if (num(ps, &t, k0 + 1, "not a number:", &key.v[0])) return 1;
        if (num(ps, &t, k0 + 2, "not a number:", &key.v[1])) return 1;
        if (num(ps, &t, k0 + 3, "not a number:", &key.v[2])) return 1;
        if (rot) {
            if (num(ps, &t, 6, "angle is not a number:", &key.v[3])) return 1;
            if (!key.v[0] && !key.v[1] && !key.v[2]) return fail(ps, "rotation axis is zero", 0, 0);
        }
        ci = rot ? channel(c, SN_CLIP_ROT, t.p[1], t.n[1]) : channel(c, SN_CLIP_MOVE, "", 0);
        if (ci < 0) return fail(ps, "too many channels (limit SN_CLIP_MAX_CHANNELS)", 0, 0);
        return add_key(ps, ci, &key, t.p[k0], t.n[k0]);
    }
    if (tok_is(&t, 0, "control")) {
        int ci;
        sn_clip_key key;
        memset(&key, 0, sizeof key);
        if (!ps->have_duration) return fail(ps, "'duration' must come before the first key", 0, 0);
        if (nt != 4) return fail(ps, "usage: control <name> <time> <value>", 0, 0);
        if (t.n[1] > SN_CLIP_NAME_MAX) return fail(ps, "control name longer than 31 bytes:", t.p[1], t.n[1]);
        if (num(ps, &t, 2, "key time is not a number:", &key.t)) return 1;
        if (num(ps, &t, 3, "control value is not a number:", &key.v[0])) return 1;
        ci = channel(c, SN_CLIP_CONTROL, t.p[1], t.n[1]);
        if (ci < 0) return fail(ps, "too many channels (limit SN_CLIP_MAX_CHANNELS)", 0, 0);
        return add_key(ps, ci, &key, t.p[2], t.n[2]);
    }
    if (tok_is(&t, 0, "impulse")) { /* impulse <time> <surface vertex> <jx> <jy> <jz> [profile] */
        int ci, k;
        sn_clip_key key;
        int32_t vq, pq = -65536;
        char pname[12];
        size_t pn = 0;
        memset(&key, 0, sizeof key);
        if (!ps->have_duration) return fail(ps, "'duration' must come before the first key", 0, 0);
        if (nt != 6 && nt != 7) return fail(ps, "usage: impulse <time> <surface vertex> <jx> <jy> <jz> [profile]", 0, 0);
        if (num(ps, &t, 1, "key time is not a number:", &key.t)) return 1;
        if (num(ps, &t, 2, "surface vertex is not a number:", &vq)) return 1;
        if (vq < 0 || (vq & 0xFFFF) != 0) return fail(ps, "surface vertex must be a whole number >= 0:", t.p[2], t.n[2]);
        key.v[3] = vq >> 16;
        for (k = 0; k < 3; k++)
            if (num(ps, &t, 3 + k, "impulse (newton-seconds) is not a number:", &key.v[k])) return 1;
        if (nt == 7) {
            if (num(ps, &t, 6, "profile is not a number:", &pq)) return 1;
            if (pq < 0 || (pq & 0xFFFF) != 0 || pq > (254 << 16)) return fail(ps, "profile must be a whole number in 0..254:", t.p[6], t.n[6]);
        }
        {   /* the channel is named by the profile ("-1": the flesh's own) */
            int32_t pv = pq >> 16;
            char tmp[12];
            size_t nd = 0;
            if (pv < 0) { pname[pn++] = '-'; pv = 1; }
            do { tmp[nd++] = (char)('0' + pv % 10); pv /= 10; } while (pv);
            while (nd) pname[pn++] = tmp[--nd];
        }
        ci = channel(c, SN_CLIP_IMPULSE, pname, pn);
        if (ci < 0) return fail(ps, "too many channels (limit SN_CLIP_MAX_CHANNELS)", 0, 0);
        return add_key(ps, ci, &key, t.p[1], t.n[1]);
    }

    if (tok_is(&t, 0, "collider")) {
        /* collider <name> <time> plane|sphere|capsule <numbers> [vel <vx> <vy> <vz>] [mu <f>]
           collider <name> <time> off */
        int ci, k, nf, i;
        sn_clip_key key;
        sn_clip_shape sh;
        memset(&key, 0, sizeof key);
        memset(&sh, 0, sizeof sh);
        if (!ps->have_duration) return fail(ps, "'duration' must come before the first key", 0, 0);
        if (nt < 4) return fail(ps, "usage: collider <name> <time> plane|sphere|capsule <numbers> [vel <vx> <vy> <vz>] [mu <f>], or collider <name> <time> off", 0, 0);
        if (t.n[1] > SN_CLIP_NAME_MAX) return fail(ps, "collider name longer than 31 bytes:", t.p[1], t.n[1]);
        if (num(ps, &t, 2, "key time is not a number:", &key.t)) return 1;
        if (tok_is(&t, 3, "off")) {
            if (nt != 4) return fail(ps, "usage: collider <name> <time> off (nothing after 'off')", 0, 0);
            key.v[0] = -1;
        } else {
            if (tok_is(&t, 3, "plane")) { sh.kind = 0; nf = 6; }
            else if (tok_is(&t, 3, "sphere")) { sh.kind = 1; nf = 4; }
            else if (tok_is(&t, 3, "capsule")) { sh.kind = 2; nf = 7; }
            else return fail(ps, "collider shape must be plane, sphere, capsule or off, found", t.p[3], t.n[3]);
            if (nt < 4 + nf)
                return fail(ps, sh.kind == 0 ? "usage: collider <name> <time> plane <px> <py> <pz> <nx> <ny> <nz> [vel <vx> <vy> <vz>] [mu <f>]"
                              : sh.kind == 1 ? "usage: collider <name> <time> sphere <cx> <cy> <cz> <radius> [vel <vx> <vy> <vz>] [mu <f>]"
                              : "usage: collider <name> <time> capsule <ax> <ay> <az> <bx> <by> <bz> <radius> [vel <vx> <vy> <vz>] [mu <f>]", 0, 0);
            for (k = 0; k < 3; k++)
                if (num(ps, &t, 4 + k, "collider coordinate is not a number:", &sh.a[k])) return 1;
            if (sh.kind != 1)
                for (k = 0; k < 3; k++)
                    if (num(ps, &t, 7 + k, sh.kind == 0 ? "plane normal is not a number:" : "collider coordinate is not a number:", &sh.b[k])) return 1;
            if (sh.kind == 0 && !sh.b[0] && !sh.b[1] && !sh.b[2]) return fail(ps, "plane normal is zero: give the outward normal, e.g. 0 1 0", 0, 0);
            if (sh.kind != 0) {
                i = sh.kind == 1 ? 7 : 10;
                if (num(ps, &t, i, "radius is not a number:", &sh.radius)) return 1;
                if (sh.radius < 0) return fail(ps, "radius must be >= 0:", t.p[i], t.n[i]);
            }
            for (i = 4 + nf; i < nt;) {   /* options, each at most once, in either order */
                if (tok_is(&t, i, "vel")) {
                    if (sh.reserved[0]) return fail(ps, "'vel' given twice", 0, 0);
                    if (i + 4 > nt) return fail(ps, "usage: vel <vx> <vy> <vz> (mesh units per second)", 0, 0);
                    for (k = 0; k < 3; k++)
                        if (num(ps, &t, i + 1 + k, "velocity is not a number:", &sh.vel[k])) return 1;
                    sh.reserved[0] = 1; i += 4;
                } else if (tok_is(&t, i, "mu")) {
                    if (sh.reserved[1]) return fail(ps, "'mu' given twice", 0, 0);
                    if (i + 2 > nt) return fail(ps, "usage: mu <friction coefficient >= 0>", 0, 0);
                    if (num(ps, &t, i + 1, "friction coefficient is not a number:", &sh.mu)) return 1;
                    if (sh.mu < 0) return fail(ps, "friction coefficient must be >= 0:", t.p[i + 1], t.n[i + 1]);
                    sh.reserved[1] = 1; i += 2;
                } else return fail(ps, "expected 'vel <vx> <vy> <vz>' or 'mu <f>' after the collider's numbers, found", t.p[i], t.n[i]);
            }
            sh.reserved[0] = sh.reserved[1] = 0;
            if (c->n_shapes >= SN_CLIP_MAX_SHAPES) return fail(ps, "too many collider placements (limit SN_CLIP_MAX_SHAPES)", 0, 0);
            key.v[0] = c->n_shapes;
        }
        ci = channel(c, SN_CLIP_COLLIDER, t.p[1], t.n[1]);
        if (ci < 0) return fail(ps, "too many channels (limit SN_CLIP_MAX_CHANNELS)", 0, 0);
        if (add_key(ps, ci, &key, t.p[2], t.n[2])) return 1;
        if (key.v[0] >= 0) c->shapes[c->n_shapes++] = sh;   /* only once the key is in */
        return 0;
    }
    if (tok_is(&t, 0, "pin")) {
        /* pin <name> <time> surface|lattice <vertex> hold|<x> <y> <z> [axes <xyz>]
           pin <name> <time> off */
        int ci, k, i;
        int32_t vq;
        uint32_t axes = 0;
        sn_clip_key key;
        memset(&key, 0, sizeof key);
        if (!ps->have_duration) return fail(ps, "'duration' must come before the first key", 0, 0);
        if (nt < 4) return fail(ps, "usage: pin <name> <time> surface|lattice <vertex> hold|<x> <y> <z> [axes <xyz>], or pin <name> <time> off", 0, 0);
        if (t.n[1] > SN_CLIP_NAME_MAX) return fail(ps, "pin name longer than 31 bytes:", t.p[1], t.n[1]);
        if (num(ps, &t, 2, "key time is not a number:", &key.t)) return 1;
        if (tok_is(&t, 3, "off")) {
            if (nt != 4) return fail(ps, "usage: pin <name> <time> off (nothing after 'off')", 0, 0);
            key.v[3] = SN_CLIP_PIN_OFF;
        } else {
            if (tok_is(&t, 3, "lattice")) key.v[3] = SN_CLIP_PIN_LATTICE;
            else if (!tok_is(&t, 3, "surface")) return fail(ps, "pin point must be surface, lattice or off, found", t.p[3], t.n[3]);
            if (nt < 6) return fail(ps, "usage: pin <name> <time> surface|lattice <vertex> hold|<x> <y> <z> [axes <xyz>]", 0, 0);
            if (num(ps, &t, 4, "vertex is not a number:", &vq)) return 1;
            if (vq < 0 || (vq & 0xFFFF) != 0) return fail(ps, "vertex must be a whole number >= 0:", t.p[4], t.n[4]);
            key.v[3] |= vq >> 16;
            if (tok_is(&t, 5, "hold")) { key.v[3] |= SN_CLIP_PIN_HOLD; i = 6; }
            else {
                if (nt < 8) return fail(ps, "usage: pin <name> <time> surface|lattice <vertex> hold|<x> <y> <z> [axes <xyz>]", 0, 0);
                for (k = 0; k < 3; k++)
                    if (num(ps, &t, 5 + k, "pin target is not a number:", &key.v[k])) return 1;
                i = 8;
            }
            if (i < nt) {
                size_t j;
                if (!tok_is(&t, i, "axes") || i + 2 != nt)
                    return fail(ps, "expected 'axes <xyz>' (or nothing) after the pin's target, found", t.p[i], t.n[i]);
                for (j = 0; j < t.n[i + 1]; j++) {
                    char ch = t.p[i + 1][j];
                    uint32_t bit = ch == 'x' ? SN_AXIS_X : ch == 'y' ? SN_AXIS_Y : ch == 'z' ? SN_AXIS_Z : 0;
                    if (!bit || (axes & bit)) return fail(ps, "axes must be x, y and/or z, each at most once, e.g. 'axes yz'; found", t.p[i + 1], t.n[i + 1]);
                    axes |= bit;
                }
            } else axes = SN_AXIS_ALL;
            key.v[3] |= (int32_t)(axes << SN_CLIP_PIN_AXES_SHIFT);
        }
        ci = channel(c, SN_CLIP_PIN, t.p[1], t.n[1]);
        if (ci < 0) return fail(ps, "too many channels (limit SN_CLIP_MAX_CHANNELS)", 0, 0);
        return add_key(ps, ci, &key, t.p[2], t.n[2]);
    }
    return fail(ps, "unknown keyword (expected duration, loop, rot, move, control, impulse, collider, pin):", t.p[0], t.n[0]);
}

int32_t sn_clip_control_at(const sn_clip *clip, uint32_t c, int32_t t) {
    const sn_clip_channel *ch;
    const sn_clip_key *k;
    uint32_t i, n;
    int64_t d, p;
    int32_t u;
    if (c >= clip->n_channels || c >= SN_CLIP_MAX_CHANNELS) return 0;
    ch = &clip->chan[c];
    n = ch->count;
    if (ch->kind != SN_CLIP_CONTROL || !n || (uint32_t)ch->first + n > clip->n_keys ||
        (uint32_t)ch->first + n > SN_CLIP_MAX_KEYS) return 0;
    k = &clip->keys[ch->first];
    if (t <= k[0].t) return k[0].v[0];
    if (t >= k[n - 1].t) return k[n - 1].v[0];
    for (i = 0; i + 2 < n && k[i + 1].t <= t; i++) {}
    /* as the root translation (sn_clip_pose.c): weight of key i+1 in Q30, then
       a + (b - a) u rounded half away from zero */
    u = (int32_t)(((int64_t)(t - k[i].t) << 30) / ((int64_t)k[i + 1].t - k[i].t));
    d = (int64_t)k[i + 1].v[0] - k[i].v[0];
    p = d * u;
    p = p >= 0 ? (p + (1 << 29)) / (1 << 30) : -((-p + (1 << 29)) / (1 << 30));
    return (int32_t)(k[i].v[0] + p);
}

/* Q16.16 v >= 0 as a decimal with at most `dec` places, trailing zeros cut. */
static void m_q16(msgbuf *m, int64_t v, int dec) {
    int64_t scale = 1, f;
    int i;
    char d[12];
    for (i = 0; i < dec; i++) scale *= 10;
    v = (v * scale + 32768) >> 16;          /* rounded, in units of 10^-dec */
    m_uint(m, (uint32_t)(v / scale));
    f = v % scale;
    if (!f) return;
    for (i = dec; i-- > 0; f /= 10) d[i] = (char)('0' + f % 10);
    for (i = dec; i > 0 && d[i - 1] == '0'; i--) {}
    m_str(m, ".", 1); m_str(m, d, (size_t)i);
}

size_t sn_clip_warning_str(const sn_clip *clip, uint32_t i, char *buf, size_t len) {
    msgbuf m;
    const sn_clip_warning *w;
    m.buf = buf; m.cap = buf ? len : 0; m.len = 0;
    if (m.cap) buf[0] = 0;
    if (i >= clip->n_warnings || i >= SN_CLIP_MAX_WARNINGS) return 0;
    w = &clip->warn[i];
    m_cstr(&m, "joint '"); m_cstr(&m, w->channel < SN_CLIP_MAX_CHANNELS ? clip->chan[w->channel].name : "?");
    m_cstr(&m, "': keys at "); m_q16(&m, w->t_a, 4);
    m_cstr(&m, " s and "); m_q16(&m, w->t_b, 4);
    m_cstr(&m, " s are "); m_q16(&m, w->apart, 2);
    if (w->apart == DEG(180) && w->taken == DEG(180)) {
        m_cstr(&m, " degrees apart; which way the interpolation turns is up to rounding; add an intermediate key");
        return m.len;
    }
    m_cstr(&m, " degrees apart; the interpolation takes the short way (a turn of ");
    m_q16(&m, w->taken, 2);
    m_cstr(&m, " degrees); add an intermediate key to turn the long way");
    return m.len;
}

int sn_clip_parse(sn_clip *clip, const char *text, size_t len, char *err, size_t errlen) {
    pstate ps;
    size_t i = 0;
    memset(clip, 0, sizeof *clip);
    memset(&ps, 0, sizeof ps);
    ps.clip = clip;
    ps.m.buf = err; ps.m.cap = err ? errlen : 0;
    if (ps.m.cap) err[0] = 0;
    while (i < len) {
        size_t j = i;
        while (j < len && text[j] != '\n') j++;
        ps.line++;
        if (memchr(text + i, 0, j - i)) return fail(&ps, "NUL byte in clip text", 0, 0);
        if (parse_line(&ps, text + i, j - i)) return 1;
        i = j + 1;
    }
    if (!ps.have_header) return fail(&ps, "empty clip: missing the line 'sinew-clip 1'", 0, 0);
    if (!ps.have_duration) return fail(&ps, "missing 'duration <seconds>'", 0, 0);
    for (i = 0; i < clip->n_channels; i++) {
        if (clip->chan[i].kind == SN_CLIP_COLLIDER) clip->n_colliders++;
        if (clip->chan[i].kind == SN_CLIP_PIN) clip->n_pins++;
    }
    return 0;
}
