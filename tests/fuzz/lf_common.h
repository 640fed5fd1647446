/* lf_common.h -- small helpers shared by the libFuzzer harnesses
 * (tests/fuzz/lf_*.c, built by tests/fuzz/fuzz.mk with
 * clang -fsanitize=fuzzer,address,undefined). Header-only. */
#ifndef LF_COMMON_H
#define LF_COMMON_H
#define _POSIX_C_SOURCE 200809L /* mkstemp, close; include this header first */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* A finding the sanitizers cannot see (a broken promise): print and abort,
 * so libFuzzer saves the input as a crash artifact. */
#define LF_REQUIRE(cond, ...) do { if (!(cond)) { \
    fprintf(stderr, "lf: %s:%d: requirement failed: %s: ", __FILE__, __LINE__, #cond); \
    fprintf(stderr, __VA_ARGS__); fprintf(stderr, "\n"); abort(); } } while (0)

/* Write the input into one temp file per process (created once, rewritten
 * each run) for the readers that take a path (the host tool's description
 * and OBJ readers). Returns the path; the file is removed at exit. */
static char lf_tmp_path[64];
static void lf_tmp_remove(void) { if (lf_tmp_path[0]) remove(lf_tmp_path); }
static const char *lf_tmp_write(const uint8_t *data, size_t size) {
    FILE *f;
    if (!lf_tmp_path[0]) {
        const char *dir = getenv("TMPDIR");
        int fd;
        snprintf(lf_tmp_path, sizeof lf_tmp_path, "%s/sinew_lf_XXXXXX", dir && *dir && strlen(dir) < 40 ? dir : "/tmp");
        fd = mkstemp(lf_tmp_path);
        if (fd < 0) { perror("lf: mkstemp"); abort(); }
        close(fd);
        atexit(lf_tmp_remove);
    }
    f = fopen(lf_tmp_path, "wb");
    if (!f) { perror("lf: temp file"); abort(); }
    if (size && fwrite(data, 1, size, f) != size) { perror("lf: write"); abort(); }
    fclose(f);
    return lf_tmp_path;
}
#endif
