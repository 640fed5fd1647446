/* lf_seed_blob.c -- writes the blob harnesses' generated seeds (built and run
 * by tests/fuzz/fuzz.mk at build time, so they always follow the format of
 * runtime/src/sn_format.h): blobs of the independent test writer
 * tests/fuzz/sn_tblob.h in this build's flavour (-DSN_FLOAT for float):
 * len_shift -24, 0, 3 and 9, and without the LIMIT section. Each is validated
 * first; an invalid one is reported and not written (exit 1), so a writer
 * that has fallen behind the format is noticed.
 * Usage: lf_seed_blob DIR */
#include <stdio.h>
#include <stdlib.h>

#include "sinew.h"
#include "sn_format.h"
#include "sn_tblob.h"

static union { uint64_t a; unsigned char b[16384]; } g;

static int put(const char *dir, const char *name, uint32_t n) {
    char path[1024];
    FILE *f;
    const sn_blob *blob;
    sn_status st = sn_blob_validate(g.b, n, &blob);
    if (st != SN_OK) {
        fprintf(stderr, "lf_seed_blob: %s: the test writer's blob is rejected (%s): not written\n", name, sn_status_str(st));
        return 1;
    }
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "wb");
    if (!f || fwrite(g.b, 1, n, f) != n) { fprintf(stderr, "lf_seed_blob: cannot write %s\n", path); if (f) fclose(f); return 1; }
    fclose(f);
    return 0;
}

int main(int argc, char **argv) {
    int bad = 0;
    uint32_t n;
    if (argc != 2) { fprintf(stderr, "usage: lf_seed_blob DIR\n"); return 2; }
    n = tb_build(g.b, sizeof g.b, 0);  bad += put(argv[1], "tblob_ls0.blob", n);
    n = tb_build(g.b, sizeof g.b, 3);  bad += put(argv[1], "tblob_ls3.blob", n);
    n = tb_build(g.b, sizeof g.b, 9);  bad += put(argv[1], "tblob_ls9.blob", n); /* largest: coordinates <= 16384 mesh units */
    n = tb_build(g.b, sizeof g.b, -24); bad += put(argv[1], "tblob_lsm24.blob", n);
    n = tb_build(g.b, sizeof g.b, 0); tb_drop_limit(g.b); bad += put(argv[1], "tblob_nolimit.blob", n);
    return bad != 0;
}
