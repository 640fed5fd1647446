/* test_clip.c -- clip parser (ports/common/sn_clip.c): the decimal reader
 * against strtod, good clips, warnings for keys more than 180 degrees apart,
 * and every error case with its line number.
 * Needs no runtime (pose sampling is tested in test_clip_pose.c). */
#include "sn_test.h"
#include "sn_clip.h"
#include <string.h>

static sn_clip clip;
static char err[SN_CLIP_ERR_LEN];

static int parse(const char *text) { return sn_clip_parse(&clip, text, strlen(text), err, sizeof err); }

static void num_ok(const char *s, int32_t want) {
    int32_t v = 12345;
    int r = sn_clip_parse_q16(s, strlen(s), &v);
    T_CHECK(r == 0 && v == want, "parse_q16(\"%s\") = %d (r=%d), want %d", s, v, r, want);
}
static void num_bad(const char *s, int want_r) {
    int32_t v = 0;
    int r = sn_clip_parse_q16(s, strlen(s), &v);
    T_CHECK(r == want_r, "parse_q16(\"%s\") returned %d, want %d", s, r, want_r);
}

/* Parse must fail at `line` with a message containing `frag`. */
static void bad(const char *text, uint32_t line, const char *frag) {
    char want[32];
    int r = parse(text);
    sprintf(want, "line %u:", line);
    T_CHECK(r == 1 && clip.error_line == line && strstr(err, frag) && strncmp(err, want, strlen(want)) == 0,
            "clip %.40s...: r=%d line=%u err='%s', want line %u containing '%s'",
            text, r, clip.error_line, err, line, frag);
}

#define H "sinew-clip 1\nduration 2\n"

/* Parses text; must give n warnings, the first (if any) on `line` with the
   written and taken turns (degrees, to 0.01). */
static void warns(const char *text, uint32_t n, uint32_t line, double apart, double taken) {
    int r = parse(text);
    T_CHECK(r == 0 && clip.n_warnings == n, "clip %.60s...: r=%d warnings %u, want %u (%s)", text, r, clip.n_warnings, n, err);
    if (r || !n || !clip.n_warnings) return;
    T_CHECK(clip.warn[0].line == line && fabs(clip.warn[0].apart / 65536.0 - apart) < 0.01 &&
            fabs(clip.warn[0].taken / 65536.0 - taken) < 0.01,
            "clip %.60s...: warning on line %u, %.4f apart, %.4f taken; want %u, %.2f, %.2f", text,
            clip.warn[0].line, clip.warn[0].apart / 65536.0, clip.warn[0].taken / 65536.0, line, apart, taken);
}

typedef struct { double x, y, z, w; } dq;
static dq axis_angle(double ax, double ay, double az, double deg) {
    double l = sqrt(ax * ax + ay * ay + az * az), h = deg * 3.14159265358979323846 / 360.0, s = sin(h) / l;
    dq q = {ax * s, ay * s, az * s, cos(h)};
    return q;
}

int main(void) {
    unsigned long seed = T_SEED();
    int i;

    /* decimal reader */
    num_ok("1", 65536); num_ok("-1.5", -98304); num_ok(".5", 32768); num_ok("2.", 131072);
    num_ok("+0.25", 16384); num_ok("0", 0); num_ok("-0", 0); num_ok("0.00001", 1);
    num_ok("0.000007", 0); num_ok("-0.00001", -1); num_ok("32767.99999", 32767 * 65536 + 65535);
    num_ok("-32767.99999", -(32767 * 65536 + 65535)); num_ok("007.000", 7 * 65536);
    num_ok("0.1234567891234", 8091);   /* digits after the 9th ignored: round(0.123456789*65536) */
    num_bad("", 1); num_bad("-", 1); num_bad(".", 1); num_bad("+.", 1); num_bad("1e5", 1);
    num_bad("1.2.3", 1); num_bad("abc", 1); num_bad("1-", 1); num_bad("--1", 1); num_bad("0x10", 1);
    num_bad("32768", 2); num_bad("-32768", 2); num_bad("32767.99999999", 2); num_bad("99999999999999999999", 2);
    /* random decimals with 6 places: must equal round(strtod * 65536) exactly
       (a 6-place decimal times 65536 is never a tie, so rounding is unambiguous) */
    srand((unsigned)seed);
    for (i = 0; i < 20000; i++) {
        char s[32];
        long n = ((long)rand() * 32768L + rand()) % 32767000000L;
        double d;
        int32_t v = 0;
        if (rand() & 1) n = -n;
        sprintf(s, "%s%ld.%06ld", n < 0 ? "-" : "", labs(n) / 1000000L, labs(n) % 1000000L);
        d = strtod(s, NULL);
        if (sn_clip_parse_q16(s, strlen(s), &v) != 0 || (double)v != floor(fabs(d) * 65536.0 + 0.5) * (d < 0 ? -1 : 1)) {
            T_CHECK(0, "parse_q16(\"%s\") = %d, want %.1f", s, v, d * 65536.0);
            break;
        }
    }
    T_CHECK(i == 20000, "random decimals vs strtod");

    /* a good clip: comments, CRLF, blank lines, interleaved channels */
    T_CHECK(parse("# comment\r\n\r\nsinew-clip 1   # header\r\nduration 1.5\nloop yes\n"
                  "rot head 0 0 1 0 0\n rot\ttail 0 1 0 0 10\nrot head 0.5 0 1 0 30\n"
                  "move 0 0 0 0\nrot head 1.5 0 1 0 -30\nmove 0.75 0 0.25 0\nrot tail 1 1 0 0 -10\n") == 0,
            "good clip: %s", err);
    T_CHECK(clip.duration == 98304 && clip.loop == 1, "duration %d loop %d", clip.duration, clip.loop);
    T_CHECK(clip.n_channels == 3 && clip.n_keys == 7, "channels %u keys %u", clip.n_channels, clip.n_keys);
    T_CHECK(strcmp(clip.chan[0].name, "head") == 0 && clip.chan[0].count == 3 && clip.chan[0].first == 0 &&
            clip.chan[0].kind == SN_CLIP_ROT && clip.chan[0].joint == -1, "head channel");
    T_CHECK(strcmp(clip.chan[1].name, "tail") == 0 && clip.chan[1].count == 2 && clip.chan[1].first == 3,
            "tail channel first %u count %u", clip.chan[1].first, clip.chan[1].count);
    T_CHECK(clip.chan[2].kind == SN_CLIP_MOVE && clip.chan[2].count == 2 && clip.chan[2].first == 5, "move channel");
    T_CHECK(clip.keys[2].t == 98304 && clip.keys[2].v[3] == -30 * 65536, "head key 3");
    T_CHECK(clip.keys[4].t == 65536 && clip.keys[4].v[0] == 65536 && clip.keys[4].v[3] == -10 * 65536, "tail key 2");
    T_CHECK(clip.keys[6].t == 49152 && clip.keys[6].v[1] == 16384, "move key 2");
    T_CHECK(parse("sinew-clip 1\nduration 3") == 0 && clip.loop == 0 && clip.n_keys == 0, "minimal clip (no trailing newline): %s", err);
    T_CHECK(parse(H "loop no\nrot a 2 0 0 1 5") == 0 && clip.keys[0].t == 131072, "key at duration: %s", err);
    T_CHECK(sn_clip_parse(&clip, H "rot a 0 0 0 1 5\nGARBAGE", strlen(H) + 16, err, sizeof err) == 0,
            "length limits the text: %s", err);
    T_CHECK(sn_clip_parse(&clip, "x", 1, NULL, 0) == 1, "NULL error buffer tolerated");
    {   /* tiny error buffer: truncated, still NUL-terminated */
        char small[8];
        memset(small, 'x', sizeof small);
        T_CHECK(sn_clip_parse(&clip, "x", 1, small, sizeof small) == 1 && small[7] == 0 &&
                strcmp(small, "line 1:") == 0, "small buffer '%s'", small);
    }
    {   /* limits: the most channels and keys fit, one more does not */
        static char big[200000];
        size_t n = 0;
        n += (size_t)sprintf(big + n, "sinew-clip 1\nduration 30000\n");
        for (i = 0; i < SN_CLIP_MAX_KEYS; i++)
            n += (size_t)sprintf(big + n, "rot j%d %d 0 0 1 1\n", i % SN_CLIP_MAX_CHANNELS, i / SN_CLIP_MAX_CHANNELS);
        T_CHECK(sn_clip_parse(&clip, big, n, err, sizeof err) == 0 && clip.n_keys == SN_CLIP_MAX_KEYS &&
                clip.n_channels == SN_CLIP_MAX_CHANNELS, "full clip: %s", err);
        for (i = 0; i < SN_CLIP_MAX_CHANNELS; i++)   /* interleaved keys ended up grouped and ordered */
            if (clip.chan[i].first != i * (SN_CLIP_MAX_KEYS / SN_CLIP_MAX_CHANNELS) ||
                clip.keys[clip.chan[i].first + 1].t != 65536) break;
        T_CHECK(i == SN_CLIP_MAX_CHANNELS, "grouping of channel %d", i);
        sprintf(big + n, "rot j0 29999 0 0 1 1\n");
        T_CHECK(sn_clip_parse(&clip, big, strlen(big), err, sizeof err) == 1 && strstr(err, "too many keys") &&
                clip.error_line == SN_CLIP_MAX_KEYS + 3, "one key too many: %s", err);
        n = (size_t)sprintf(big, "sinew-clip 1\nduration 1\n");
        for (i = 0; i <= SN_CLIP_MAX_CHANNELS; i++) n += (size_t)sprintf(big + n, "rot j%d 0 0 0 1 1\n", i);
        T_CHECK(sn_clip_parse(&clip, big, n, err, sizeof err) == 1 && strstr(err, "too many channels") &&
                clip.error_line == SN_CLIP_MAX_CHANNELS + 3, "one channel too many: %s", err);
    }

    /* control tracks: own channels (a control may share a joint's name),
       interleaved with rotations, linear between keys, held outside them */
    T_CHECK(parse(H "control breath 0.5 -1\nrot breath 0 0 1 0 10\ncontrol smile 0 0.25\n"
                  "control breath 1.5 1 # inhale\ncontrol breath 2 0\nrot breath 1 0 1 0 20\n") == 0, "controls: %s", err);
    T_CHECK(clip.n_channels == 3 && clip.n_keys == 6 && clip.chan[0].kind == SN_CLIP_CONTROL &&
            clip.chan[1].kind == SN_CLIP_ROT && clip.chan[2].kind == SN_CLIP_CONTROL &&
            strcmp(clip.chan[0].name, "breath") == 0 && strcmp(clip.chan[1].name, "breath") == 0 &&
            clip.chan[0].count == 3 && clip.chan[1].count == 2 && clip.chan[2].count == 1 && clip.chan[0].joint == -1,
            "control channels: %u channels, %u keys", clip.n_channels, clip.n_keys);
    T_CHECK(clip.keys[clip.chan[0].first + 1].v[0] == 65536 && clip.keys[clip.chan[0].first + 1].t == 98304 &&
            clip.keys[clip.chan[0].first + 1].v[1] == 0 && clip.keys[clip.chan[0].first + 1].v[3] == 0 &&
            clip.keys[clip.chan[2].first].v[0] == 16384, "control keys");
    T_CHECK(clip.n_warnings == 0, "control keys are never warned (%u)", clip.n_warnings);
    {   /* interpolation, exactly: before/at/between/after keys, rounding half away from zero */
        static const struct { int32_t t, want; } at[] = {
            {-5, -65536}, {0, -65536}, {32768, -65536}, {32769, -65536 + 2}, {65536, 0}, {81920, 32768},
            {98304, 65536}, {114688, 32768}, {131072, 0}, {0x7FFFFFFF, 0},
        };
        int k;
        for (k = 0; k < (int)(sizeof at / sizeof at[0]); k++) {
            int32_t v = sn_clip_control_at(&clip, 0, at[k].t);
            T_CHECK(v == at[k].want, "control_at(breath, %d) = %d, want %d", at[k].t, v, at[k].want);
        }
        T_CHECK(sn_clip_control_at(&clip, 2, 0) == 16384 && sn_clip_control_at(&clip, 2, 131072) == 16384,
                "one key: held everywhere");
        T_CHECK(sn_clip_control_at(&clip, 1, 0) == 0 && sn_clip_control_at(&clip, 3, 0) == 0 &&
                sn_clip_control_at(&clip, 9999, 0) == 0, "not a control channel: 0");
        /* a random track against double: |error| <= 1 LSB (two roundings) */
        for (k = 0, i = 0; i < 2000; i++) {
            char text[256];
            double v0 = (rand() % 200001 - 100000) / 100.0, v1 = (rand() % 200001 - 100000) / 100.0;
            double t0 = (rand() % 1000) / 1000.0, t1 = t0 + (rand() % 1000 + 1) / 1000.0, d;
            int32_t t = (int32_t)(t0 * 65536.0) + rand() % ((int32_t)((t1 - t0) * 65536.0) + 1), v;
            sprintf(text, "sinew-clip 1\nduration 2\ncontrol c %.3f %.2f\ncontrol c %.3f %.2f\n", t0, v0, t1, v1);
            if (parse(text)) { k++; continue; }
            v = sn_clip_control_at(&clip, 0, t);
            d = clip.keys[0].v[0] + (double)(clip.keys[1].v[0] - clip.keys[0].v[0]) *
                (t <= clip.keys[0].t ? 0 : t >= clip.keys[1].t ? 1 : (double)(t - clip.keys[0].t) / (clip.keys[1].t - clip.keys[0].t));
            if (fabs(v - d) > 1.0) k++;
        }
        T_CHECK(k == 0, "random control tracks: %d of 2000 off by more than 1 LSB from double", k);
    }
    /* more controls than channels: the shared channel limit */
    {
        static char big[8192];
        size_t n = (size_t)sprintf(big, "sinew-clip 1\nduration 1\n");
        for (i = 0; i <= SN_CLIP_MAX_CHANNELS; i++) n += (size_t)sprintf(big + n, "control c%d 0 1\n", i);
        T_CHECK(sn_clip_parse(&clip, big, n, err, sizeof err) == 1 && strstr(err, "too many channels") &&
                clip.error_line == SN_CLIP_MAX_CHANNELS + 3, "one control channel too many: %s", err);
    }

    /* keys more than 180 degrees apart: warned, the clip still parses */
    warns(H "rot a 0 0 1 0 0\nrot a 1 0 1 0 270\n", 1, 4, 270, 90);
    warns(H "rot a 0 0 1 0 0\nrot a 1 0 1 0 180\n", 1, 4, 180, 180);      /* exactly 180: either way */
    warns(H "rot a 0 0 1 0 0\nrot a 1 0 1 0 179.99\n", 0, 0, 0, 0);
    warns(H "rot a 0 1 0 0 90\nrot a 1 0 1 0 -90\n", 0, 0, 0, 0);        /* 120 apart */
    warns(H "rot a 0 1 0 0 180\nrot a 1 0 1 0 180\n", 1, 4, 180, 180);    /* different axes, 180 apart */
    warns(H "rot a 0 0 1 0 10\nrot a 1 0 1 0 190.5\n", 1, 4, 180.5, 179.5);
    warns(H "rot a 0 0 1 0 10\nrot a 1 0 -1 0 170.5\n", 1, 4, 180.5, 179.5); /* opposite axis */
    warns(H "rot a 0 1 0 0 170\nrot a 1 -1 0 0 170\n", 1, 4, 340, 20);
    warns(H "rot a 0 1 0 0 170\nrot a 1 -1 0.01 0 170\n", 1, 4, 339.967, 20.033); /* nearly opposite */
    warns(H "rot a 0 1 0 0 90\nrot a 0.5 0 1 0 90\nrot a 1 1 0 0 -100\n", 0, 0, 0, 0);
    warns(H "rot a 0 1 0 0 0\nrot a 1 0 0 1 720\n", 1, 4, 720, 0);        /* a zero angle has any axis */
    warns(H "rot a 0 1 0 0 30\nrot a 1 0 2 1 300\n", 1, 4, 293.55, 66.45);
    warns(H "rot a 0 0 1 0 -100\nrot b 0.5 0 1 0 0\nrot a 1 0 1 0 100\nrot b 1 0 1 0 90\n", 1, 5, 200, 160);
    warns(H "move 0 0 0 0\nmove 1 30000 0 0\n", 0, 0, 0, 0);                /* translations never */
    warns(H "rot a 0 0 1 0 0\nrot a 0.5 0 1 0 120\nrot a 1 0 1 0 240\nrot a 1.5 0 1 0 360\n", 0, 0, 0, 0);
    {   /* the text names the joint, both key times, the short way and the fix */
        char w[SN_CLIP_ERR_LEN];
        size_t n;
        parse(H "rot a 0 0 1 0 0\nrot head 0.25 0 1 0 -30\nrot head 1.5 0 1 0 200.125\n");
        n = sn_clip_warning_str(&clip, 0, w, sizeof w);
        T_CHECK(n == strlen(w) && strcmp(w, "joint 'head': keys at 0.25 s and 1.5 s are 230.13 degrees apart; the "
                "interpolation takes the short way (a turn of 129.88 degrees); add an intermediate key to turn the long way") == 0,
                "warning text '%s'", w);
        T_CHECK(sn_clip_warning_str(&clip, 1, w, sizeof w) == 0 && w[0] == 0, "no warning 1: '%s'", w);
        T_CHECK(sn_clip_warning_str(&clip, 0, w, 8) == 7 && strcmp(w, "joint '") == 0, "small buffer '%s'", w);
        parse(H "rot a 0 0 1 0 0\nrot a 2 0 1 0 180\n");
        sn_clip_warning_str(&clip, 0, w, sizeof w);
        T_CHECK(strcmp(w, "joint 'a': keys at 0 s and 2 s are 180 degrees apart; which way the interpolation turns "
                "is up to rounding; add an intermediate key") == 0, "180 text '%s'", w);
    }
    {   /* more warnings than the list holds: all counted, the first kept */
        static char many[4096];
        size_t n = (size_t)sprintf(many, "sinew-clip 1\nduration 30\n");
        for (i = 0; i < SN_CLIP_MAX_WARNINGS + 3; i++) n += (size_t)sprintf(many + n, "rot j %d 1 0 0 %d\n", i, i & 1 ? 100 : -100);
        T_CHECK(sn_clip_parse(&clip, many, n, err, sizeof err) == 0 && clip.n_warnings == SN_CLIP_MAX_WARNINGS + 2 &&
                clip.warn[SN_CLIP_MAX_WARNINGS - 1].line == SN_CLIP_MAX_WARNINGS + 3, "many: %u warnings", clip.n_warnings);
    }
    {   /* random key pairs: the integer check against double quaternions */
        int disagree = 0, n_warn = 0;
        double worst = 0;
        for (i = 0; i < 20000; i++) {
            double k[2][4], c;
            char text[256];
            dq a, b;
            int j, m, want;
            for (j = 0; j < 2; j++) {
                for (m = 0; m < 3; m++) k[j][m] = (rand() % 2001 - 1000) / 100.0;
                if (k[j][0] == 0 && k[j][1] == 0 && k[j][2] == 0) k[j][0] = 1;
                k[j][3] = (rand() % 144001 - 72000) / 100.0;
            }
            if (i % 4 == 0) for (m = 0; m < 3; m++) k[1][m] = k[0][m] * (i % 8 ? 2 : -1);   /* parallel axes (exact in the text) */
            sprintf(text, H "rot a 0 %.2f %.2f %.2f %.2f\nrot a 1 %.2f %.2f %.2f %.2f\n",
                    k[0][0], k[0][1], k[0][2], k[0][3], k[1][0], k[1][1], k[1][2], k[1][3]);
            a = axis_angle(k[0][0], k[0][1], k[0][2], k[0][3]);
            b = axis_angle(k[1][0], k[1][1], k[1][2], k[1][3]);
            c = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
            if (i % 4 == 0) {   /* one axis: the written turn is exact */
                double d = fabs(k[1][3] - (i % 8 ? 1 : -1) * k[0][3]);
                want = d >= 180;
                if (fabs(d - 180) < 1e-3) continue;
                if (parse(text) || (int)clip.n_warnings != want ||
                    (want && fabs(clip.warn[0].apart / 65536.0 - d) > 1e-3)) { if (disagree++ < 5) printf("  %s -> %u\n", text, clip.n_warnings); }
            } else {
                if (fabs(c) < 1e-3) continue;   /* too near 180 to call */
                want = c < 0;
                if (parse(text) || (int)clip.n_warnings != want) { if (disagree++ < 5) printf("  c=%g %s -> %u\n", c, text, clip.n_warnings); }
                else if (want && fabs(clip.warn[0].apart / 65536.0 - 2 * acos(c) * 180 / 3.14159265358979323846) > worst)
                    worst = fabs(clip.warn[0].apart / 65536.0 - 2 * acos(c) * 180 / 3.14159265358979323846);
            }
            n_warn += want;
        }
        T_CHECK(disagree == 0 && n_warn > 1000, "random keys: %d disagree with double, %d warned", disagree, n_warn);
        T_NEAR(worst, 0, 0.01, "written turn vs double, degrees (bisection to 1/65536, Taylor to ~1e-7)");
        T_FIGURE("clip >180 degree check: %d random key pairs warned, written turn within %.2e degrees of double", n_warn, worst);
    }

    /* every error, with its line */
    bad("", 0, "missing the line 'sinew-clip 1'");
    bad("# only a comment\n\n", 2, "missing the line 'sinew-clip 1'");
    bad("duration 1\n", 1, "must start with the line 'sinew-clip 1'");
    bad("sinew-clip 2\n", 1, "unsupported clip format version");
    bad("sinew-clip\n", 1, "unsupported clip format version");
    bad("sinew-clip 1\n", 1, "missing 'duration");
    bad("sinew-clip 1\nloop yes\n\n", 3, "missing 'duration");
    bad(H "spin head 0 1\n", 3, "unknown keyword");
    bad(H "duration 3\n", 3, "duration given twice");
    bad("sinew-clip 1\nduration 0\n", 2, "duration must be > 0");
    bad("sinew-clip 1\nduration -1\n", 2, "duration must be > 0");
    bad("sinew-clip 1\nduration soon\n", 2, "duration is not a number");
    bad("sinew-clip 1\nduration 1 2\n", 2, "usage: duration");
    bad("sinew-clip 1\nduration 40000\n", 2, "number out of range");
    bad(H "loop maybe\n", 3, "loop must be yes or no");
    bad(H "loop\n", 3, "usage: loop");
    bad(H "loop yes\nloop no\n", 4, "loop given twice");
    bad("sinew-clip 1\nrot head 0 0 1 0 5\nduration 1\n", 2, "'duration' must come before");
    bad(H "rot head 0 0 1 0\n", 3, "usage: rot");
    bad(H "rot head 0 0 1 0 5 6\n", 3, "usage: rot");
    bad(H "move 0 0 1\n", 3, "usage: move");
    bad(H "move 0 x 1 2\n", 3, "not a number: 'x'");
    bad(H "rot head zero 0 1 0 5\n", 3, "key time is not a number: 'zero'");
    bad(H "rot head 0 0 1 0 5deg\n", 3, "angle is not a number: '5deg'");
    bad(H "rot head 0 0 0 0 5\n", 3, "rotation axis is zero");
    bad(H "rot head -0.5 0 1 0 5\n", 3, "key time is negative");
    bad(H "rot head 2.01 0 1 0 5\n", 3, "after the clip duration");
    bad(H "rot head 1 0 1 0 5\nrot tail 0.5 0 1 0 5\nrot head 1 0 1 0 6\n", 5, "strictly increase");
    bad(H "move 1 0 0 0\nmove 0.5 0 0 0\n", 4, "strictly increase");
    bad(H "rot a_joint_name_that_is_much_too_long 0 0 1 0 5\n", 3, "longer than 31 bytes");
    bad(H "rot a 0 0 1 0 5 # fine\nrot a 1 0 1 0 5 6 7 8 9 10 11 12 13 14 15 16 17 18\n", 4, "too many fields");
    bad(H "rot a 1 0 1 0 5 6 7 8 9 10\n", 3, "usage: rot");
    bad(H "rot a 0 0 1 0 99999\n", 3, "number out of range");
    /* control lines */
    bad(H "control breath 0\n", 3, "usage: control <name> <time> <value>");
    bad(H "control breath 0 1 2\n", 3, "usage: control");
    bad(H "control\n", 3, "usage: control");
    bad(H "control breath 0 deep\n", 3, "control value is not a number: 'deep'");
    bad(H "control breath soon 1\n", 3, "key time is not a number: 'soon'");
    bad(H "control breath 0 40000\n", 3, "number out of range");
    bad(H "control breath -1 1\n", 3, "key time is negative");
    bad(H "control breath 3 1\n", 3, "after the clip duration");
    bad(H "control breath 1 1\nrot breath 0 0 1 0 5\ncontrol breath 1 0\n", 5, "strictly increase");
    bad(H "control a_control_name_that_is_much_too_long 0 1\n", 3, "longer than 31 bytes");
    bad("sinew-clip 1\ncontrol breath 0 1\nduration 1\n", 2, "'duration' must come before");
    bad(H "controls breath 0 1\n", 3, "unknown keyword (expected duration, loop, rot, move, control, impulse, collider, pin)");
    /* impulse lines: impulse <time> <surface vertex> <jx> <jy> <jz> [profile] */
    bad(H "impulse 0 3 0 1\n", 3, "usage: impulse");
    bad(H "impulse 0 3 0 1 0 0 9\n", 3, "usage: impulse");
    bad(H "impulse 0 -3 0 1 0\n", 3, "surface vertex must be a whole number");
    bad(H "impulse 0 3.5 0 1 0\n", 3, "surface vertex must be a whole number");
    bad(H "impulse 0 3 0 hard 0\n", 3, "impulse (newton-seconds) is not a number: 'hard'");
    bad(H "impulse 0 3 0 1 0 255\n", 3, "profile must be a whole number in 0..254");
    bad(H "impulse 0 3 0 1 0 -1\n", 3, "profile must be a whole number");
    bad(H "impulse 3 3 0 1 0\n", 3, "after the clip duration");
    bad(H "impulse 1 3 0 1 0\nimpulse 1 4 0 1 0\n", 4, "strictly increase");
    {
        static const char ok[] = H "impulse 0.5 3 0 10 0\nimpulse 1 7 1 2 3 2\nimpulse 1 9 0 0 1\n";
        T_CHECK(sn_clip_parse(&clip, ok, sizeof ok - 1, err, sizeof err) == 0 && clip.n_channels == 2 &&
                clip.chan[0].kind == SN_CLIP_IMPULSE && !strcmp(clip.chan[0].name, "-1") && clip.chan[0].count == 2 &&
                !strcmp(clip.chan[1].name, "2") && clip.keys[clip.chan[1].first].v[3] == 7 &&
                clip.keys[clip.chan[1].first].v[2] == 3 * 65536, "impulse channels per profile: %s", err);
    }

    /* collider lines: collider <name> <time> plane|sphere|capsule <numbers> [vel vx vy vz] [mu f] | off */
    {
        static const char ok[] = H
            "collider ground 0 plane 0 -1.25 0 0 1 0 mu 0.5\n"
            "collider ball 0.5 sphere 1 2 3 0.75 vel 0 -2 0.5\n"
            "collider arm 0 capsule 0 0 0 1 1 1 0.25 mu 1 vel 1 0 0\n"      /* options in either order */
            "collider ball 1 off\n"
            "collider ball 1.5 sphere 0 0 0 0\n"                              /* radius 0: a point */
            "collider ground 2 off   # until the end\n";
        const sn_clip_shape *sh;
        T_CHECK(sn_clip_parse(&clip, ok, sizeof ok - 1, err, sizeof err) == 0, "collider lines: %s", err);
        T_CHECK(clip.n_channels == 3 && clip.n_colliders == 3 && clip.n_pins == 0 && clip.n_shapes == 4 &&
                clip.chan[0].kind == SN_CLIP_COLLIDER && !strcmp(clip.chan[0].name, "ground") && clip.chan[0].count == 2 &&
                !strcmp(clip.chan[1].name, "ball") && clip.chan[1].count == 3 && !strcmp(clip.chan[2].name, "arm"),
                "collider channels: %u channels, %u colliders, %u shapes", clip.n_channels, clip.n_colliders, clip.n_shapes);
        T_CHECK(clip.keys[clip.chan[0].first].v[0] == 0 && clip.keys[clip.chan[0].first + 1].v[0] == -1 &&
                clip.keys[clip.chan[0].first + 1].t == 2 * 65536 && clip.keys[clip.chan[1].first + 1].v[0] == -1 &&
                clip.keys[clip.chan[1].first + 2].v[0] == 3, "collider keys: shape indices and off");
        sh = &clip.shapes[0];
        T_CHECK(sh->kind == SN_COLLIDER_PLANE && sh->a[1] == -81920 && sh->b[1] == 65536 && sh->mu == 32768 &&
                !sh->vel[0] && !sh->vel[1], "plane shape");
        sh = &clip.shapes[1];
        T_CHECK(sh->kind == SN_COLLIDER_SPHERE && sh->a[0] == 65536 && sh->a[2] == 3 * 65536 && sh->radius == 49152 &&
                sh->vel[1] == -2 * 65536 && sh->vel[2] == 32768 && !sh->mu, "sphere shape");
        sh = &clip.shapes[2];
        T_CHECK(sh->kind == SN_COLLIDER_CAPSULE && sh->b[0] == 65536 && sh->b[2] == 65536 && sh->radius == 16384 &&
                sh->vel[0] == 65536 && sh->mu == 65536, "capsule shape");
    }
    bad(H "collider g 0\n", 3, "usage: collider <name> <time> plane|sphere|capsule");
    bad(H "collider g soon plane 0 0 0 0 1 0\n", 3, "key time is not a number: 'soon'");
    bad(H "collider g 0 box 0 0 0 1\n", 3, "collider shape must be plane, sphere, capsule or off, found 'box'");
    bad(H "collider g 0 plane 0 0 0 0 1\n", 3, "usage: collider <name> <time> plane <px>");
    bad(H "collider g 0 sphere 0 0 0\n", 3, "usage: collider <name> <time> sphere <cx>");
    bad(H "collider g 0 capsule 0 0 0 1 1 1\n", 3, "usage: collider <name> <time> capsule <ax>");
    bad(H "collider g 0 plane 0 y 0 0 1 0\n", 3, "collider coordinate is not a number: 'y'");
    bad(H "collider g 0 plane 0 0 0 0 up 0\n", 3, "plane normal is not a number: 'up'");
    bad(H "collider g 0 plane 0 0 0 0 0 0\n", 3, "plane normal is zero");
    bad(H "collider g 0 sphere 0 0 0 big\n", 3, "radius is not a number: 'big'");
    bad(H "collider g 0 sphere 0 0 0 -1\n", 3, "radius must be >= 0: '-1'");
    bad(H "collider g 0 capsule 0 0 0 1 1 1 -0.5\n", 3, "radius must be >= 0");
    bad(H "collider g 0 sphere 0 0 0 1 vel 1 2\n", 3, "usage: vel <vx> <vy> <vz>");
    bad(H "collider g 0 sphere 0 0 0 1 vel 1 2 fast\n", 3, "velocity is not a number: 'fast'");
    bad(H "collider g 0 sphere 0 0 0 1 vel 1 2 3 vel 1 2 3\n", 3, "'vel' given twice");
    bad(H "collider g 0 sphere 0 0 0 1 mu\n", 3, "usage: mu");
    bad(H "collider g 0 sphere 0 0 0 1 mu -0.1\n", 3, "friction coefficient must be >= 0: '-0.1'");
    bad(H "collider g 0 sphere 0 0 0 1 mu x\n", 3, "friction coefficient is not a number: 'x'");
    bad(H "collider g 0 sphere 0 0 0 1 mu 1 mu 1\n", 3, "'mu' given twice");
    bad(H "collider g 0 sphere 0 0 0 1 spin 3\n", 3, "expected 'vel <vx> <vy> <vz>' or 'mu <f>' after the collider's numbers, found 'spin'");
    bad(H "collider g 0 off 1\n", 3, "nothing after 'off'");
    bad(H "collider g -1 off\n", 3, "key time is negative");
    bad(H "collider g 3 off\n", 3, "after the clip duration");
    bad(H "collider g 1 off\ncollider g 1 sphere 0 0 0 1\n", 4, "strictly increase");
    bad(H "collider a_collider_name_that_is_much_too_long 0 off\n", 3, "collider name longer than 31 bytes");
    bad("sinew-clip 1\ncollider g 0 off\nduration 1\n", 2, "'duration' must come before");
    bad(H "collider g 0 sphere 0 0 0 40000\n", 3, "number out of range");
    /* shape limit: SN_CLIP_MAX_SHAPES placements parse, one more does not; 'off' takes none */
    {
        static char big[16384];
        size_t n = (size_t)sprintf(big, "sinew-clip 1\nduration 1000\n");
        for (i = 0; i < SN_CLIP_MAX_SHAPES; i++) n += (size_t)sprintf(big + n, "collider c %d sphere 0 0 0 1\ncollider c %d.5 off\n", i, i);
        T_CHECK(sn_clip_parse(&clip, big, n, err, sizeof err) == 0 && clip.n_shapes == SN_CLIP_MAX_SHAPES &&
                clip.n_colliders == 1 && clip.chan[0].count == 2 * SN_CLIP_MAX_SHAPES, "full shapes: %s", err);
        n += (size_t)sprintf(big + n, "collider c %d sphere 0 0 0 1\n", SN_CLIP_MAX_SHAPES);
        T_CHECK(sn_clip_parse(&clip, big, n, err, sizeof err) == 1 && strstr(err, "too many collider placements (limit SN_CLIP_MAX_SHAPES)") &&
                clip.error_line == 2 * SN_CLIP_MAX_SHAPES + 3, "one shape too many: line %u %s", clip.error_line, err);
        n = (size_t)sprintf(big, "sinew-clip 1\nduration 1\n");
        for (i = 0; i <= SN_CLIP_MAX_CHANNELS; i++) n += (size_t)sprintf(big + n, "%s c%d 0 off\n", i & 1 ? "pin" : "collider", i);
        T_CHECK(sn_clip_parse(&clip, big, n, err, sizeof err) == 1 && strstr(err, "too many channels") &&
                clip.error_line == SN_CLIP_MAX_CHANNELS + 3, "one collider/pin channel too many: %s", err);
    }
    /* the longest line: a capsule with vel and mu is 17 fields */
    {
        static const char ok[] = H "collider c 0 capsule 0 0 0 1 1 1 0.5 vel 0 0 1 mu 0.25\n";
        T_CHECK(sn_clip_parse(&clip, ok, sizeof ok - 1, err, sizeof err) == 0 && clip.n_shapes == 1, "17-field capsule: %s", err);
    }
    bad(H "collider c 0 capsule 0 0 0 1 1 1 0.5 vel 0 0 1 mu 0.25 x\n", 3, "too many fields");

    /* pin lines: pin <name> <time> surface|lattice <vertex> hold|<x> <y> <z> [axes xyz] | off */
    {
        static const char ok[] = H
            "pin hoof 0 surface 120 hold\n"
            "pin hoof 1 surface 120 0.5 -1 2 axes y\n"
            "pin hoof 1.5 surface 120 0.5 0 2 axes y\n"
            "pin hoof 2 off\n"
            "pin core 0.25 lattice 7 1 2 3 axes zx\n";
        const sn_clip_key *k;
        T_CHECK(sn_clip_parse(&clip, ok, sizeof ok - 1, err, sizeof err) == 0 && clip.n_pins == 2 && clip.n_colliders == 0 &&
                clip.n_channels == 2 && clip.chan[0].kind == SN_CLIP_PIN && clip.chan[0].count == 4 &&
                !strcmp(clip.chan[1].name, "core"), "pin lines: %s", err);
        k = &clip.keys[clip.chan[0].first];
        T_CHECK(k[0].v[3] == (120 | SN_CLIP_PIN_HOLD | (int32_t)(SN_AXIS_ALL << SN_CLIP_PIN_AXES_SHIFT)) &&
                k[1].v[3] == (120 | (int32_t)(SN_AXIS_Y << SN_CLIP_PIN_AXES_SHIFT)) && k[1].v[0] == 32768 &&
                k[1].v[1] == -65536 && k[1].v[2] == 2 * 65536 && k[2].v[3] == k[1].v[3] && k[3].v[3] == SN_CLIP_PIN_OFF,
                "pin keys: %x %x %x %x", (unsigned)k[0].v[3], (unsigned)k[1].v[3], (unsigned)k[2].v[3], (unsigned)k[3].v[3]);
        k = &clip.keys[clip.chan[1].first];
        T_CHECK(k[0].v[3] == (7 | SN_CLIP_PIN_LATTICE | (int32_t)((SN_AXIS_X | SN_AXIS_Z) << SN_CLIP_PIN_AXES_SHIFT)) &&
                k[0].t == 16384, "lattice pin key %x", (unsigned)k[0].v[3]);
    }
    bad(H "pin p 0\n", 3, "usage: pin <name> <time> surface|lattice");
    bad(H "pin p 0 bone 3 hold\n", 3, "pin point must be surface, lattice or off, found 'bone'");
    bad(H "pin p 0 surface 3\n", 3, "usage: pin <name> <time> surface|lattice <vertex>");
    bad(H "pin p 0 surface 3 1 2\n", 3, "usage: pin <name> <time> surface|lattice <vertex>");
    bad(H "pin p 0 surface v3 hold\n", 3, "vertex is not a number: 'v3'");
    bad(H "pin p 0 surface 3.5 hold\n", 3, "vertex must be a whole number >= 0: '3.5'");
    bad(H "pin p 0 lattice -3 hold\n", 3, "vertex must be a whole number >= 0");
    bad(H "pin p 0 surface 3 1 two 3\n", 3, "pin target is not a number: 'two'");
    bad(H "pin p 0 surface 3 hold yz\n", 3, "expected 'axes <xyz>' (or nothing) after the pin's target, found 'yz'");
    bad(H "pin p 0 surface 3 1 2 3 axes\n", 3, "expected 'axes <xyz>'");
    bad(H "pin p 0 surface 3 1 2 3 axes y z\n", 3, "expected 'axes <xyz>'");
    bad(H "pin p 0 surface 3 hold axes yy\n", 3, "axes must be x, y and/or z, each at most once");
    bad(H "pin p 0 surface 3 hold axes w\n", 3, "axes must be x, y and/or z");
    bad(H "pin p 0 off now\n", 3, "nothing after 'off'");
    bad(H "pin p -0.5 off\n", 3, "key time is negative");
    bad(H "pin p 2.5 surface 1 hold\n", 3, "after the clip duration");
    bad(H "pin p 1 surface 1 hold\npin q 0 off\npin p 0.5 off\n", 5, "strictly increase");
    bad(H "pin a_pin_name_that_is_much_too_long_yes 0 off\n", 3, "pin name longer than 31 bytes");
    bad("sinew-clip 1\npin p 0 off\nduration 1\n", 2, "'duration' must come before");
    bad(H "pin p 0 surface 40000 hold\n", 3, "number out of range");
    /* pins and colliders share the channel pool with everything else and their
       names live apart from joints and controls */
    {
        static const char ok[] = H "rot head 0 0 1 0 5\ncontrol head 0 1\ncollider head 0 off\npin head 0 off\n";
        T_CHECK(sn_clip_parse(&clip, ok, sizeof ok - 1, err, sizeof err) == 0 && clip.n_channels == 4, "same name, four kinds: %s", err);
    }
    bad(H "control breath 0 1e3\n", 3, "control value is not a number: '1e3'");
    {
        static const char nul[] = "sinew-clip 1\nduration 1\nrot a\0 0 0 1 0 5\n";
        T_CHECK(sn_clip_parse(&clip, nul, sizeof nul - 1, err, sizeof err) == 1 && clip.error_line == 3 &&
                strstr(err, "NUL byte"), "NUL byte: %s", err);
    }
    return T_END();
}
