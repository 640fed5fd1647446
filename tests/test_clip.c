/* test_clip.c -- clip parser (ports/common/sn_clip.c): the decimal reader
 * against strtod, good clips, and every error case with its line number.
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
    bad(H "rot a 0 0 1 0 5 # fine\nrot a 1 0 1 0 5 6 7 8 9 10\n", 4, "too many fields");
    bad(H "rot a 0 0 1 0 99999\n", 3, "number out of range");
    {
        static const char nul[] = "sinew-clip 1\nduration 1\nrot a\0 0 0 1 0 5\n";
        T_CHECK(sn_clip_parse(&clip, nul, sizeof nul - 1, err, sizeof err) == 1 && clip.error_line == 3 &&
                strstr(err, "NUL byte"), "NUL byte: %s", err);
    }
    return T_END();
}
