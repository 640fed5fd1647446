/* test_contact_per_use.c -- sn_contact_rows' fallback path.
 *
 * sn_contact_rows (runtime/src/sn_contact.c) reads each lattice vertex's
 * start point and predicted velocity from one pass per step (ct_predict);
 * when any of those sums saturates it falls back to the per-use sums of
 * the code before, so the saturation count (hashed) stays exact. No
 * scenario of the suite reaches a state that far out, so this program is
 * built with the runtime compiled with -DSN_CT_PER_USE, which takes the
 * fallback on every step, and runs the determinism driver's contact
 * scenario (ports/cross/sn_det.c: the trot, then plane, rising sphere and
 * four pins) on the cow: its hash-contact must equal the committed one
 * (tests/expected_hashes.txt fixed-contact / float-contact, made by the
 * fast path on every platform). Also the main trot's hash (no contacts:
 * untouched by the flag, a check on the harness).
 *   usage: test_contact_per_use   (blob from $BUILD, clip from tools/examples)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sn_test.h"
#include "sn_det.h"

#if defined(SN_FLOAT)
#define SUF "_float"
#define KEY_MAIN "float"
#define KEY_CONTACT "float-contact"
#else
#define SUF ""
#define KEY_MAIN "fixed"
#define KEY_CONTACT "fixed-contact"
#endif

/* the 16-digit hash after "KEY " at a line start of tests/expected_hashes.txt */
static int expected(const char *text, const char *key, char out[17]) {
    size_t n = strlen(key);
    const char *p = text;
    while (p && *p) {
        if (!strncmp(p, key, n) && p[n] == ' ') { memcpy(out, p + n + 1, 16); out[16] = 0; return 0; }
        p = strchr(p, '\n');
        if (p) p++;
    }
    return 1;
}

int main(void) {
    static sn_det det;
    static sn_clip clip;
    char path[512], err[256], hex[17], want[17];
    const char *b = getenv("BUILD");

    size_t nb = 0, nc = 0, ne = 0, mem_n;
    char *blob, *clip_text, *hashes;
    const sn_blob *bl;
    void *mem;
    (void)t_seed; /* deterministic: no random inputs */
    snprintf(path, sizeof path, "%s/examples/cow" SUF ".blob", b ? b : "build");
    blob = t_read_file(path, &nb);
    clip_text = t_read_file("tools/examples/cow/trot.clip", &nc);
    hashes = t_read_file("tests/expected_hashes.txt", &ne);
    if (hashes) hashes[ne] = 0; /* t_read_file leaves 8 spare bytes */
    if (!blob || !clip_text || !hashes) { T_CHECK(0, "cannot read %s, the trot clip or tests/expected_hashes.txt", path); return T_END(); }
    if (sn_blob_validate(blob, nb, &bl) != SN_OK) { T_CHECK(0, "%s invalid", path); return T_END(); }
    mem_n = sn_instance_size(bl);
    mem = malloc(mem_n);
    if (!mem || sn_det_init(&det, blob, nb, clip_text, nc, &clip, mem, mem_n, err, sizeof err)) {
        T_CHECK(0, "init: %s", err); return T_END();
    }
    sn_det_hex64(sn_det_run(&det, 1000), hex);
    T_CHECK(!expected(hashes, KEY_MAIN, want) && !strcmp(hex, want), "trot (no contacts): %s, tests/expected_hashes.txt %s %s",
            hex, KEY_MAIN, want);
    T_CHECK(sn_det_contact(&det), "the cow blob takes the contact scenario");
    sn_det_hex64(sn_det_run(&det, SN_DET_CONTACT_STEPS), hex);
    printf("  figure: contact scenario with sn_contact_rows' per-use sums on every step: %s\n", hex);
    T_CHECK(!expected(hashes, KEY_CONTACT, want) && !strcmp(hex, want),
            "per-use fallback %s, the fast path's (tests/expected_hashes.txt %s) %s", hex, KEY_CONTACT, want);
    free(mem); free(blob); free(clip_text); free(hashes);
    return T_END();
}
