/* insn_plugin.c -- QEMU TCG plugin for `make profile-m4`: counts the guest
 * instructions executed at each address and writes "addr count" lines (both
 * decimal, for any awk; nonzero counts only) to the file named by its argument
 * out=PATH when QEMU exits. Each translated block gets one inline 64-bit
 * add per execution (no callback, so a run costs about what plain TCG
 * does); at exit a block's count is credited to each of its instructions.
 * A block cut short by an exception is still counted whole: bare-metal
 * Sinew takes none inside its step.
 *
 * Host code, built with the host compiler against the plugin API of the
 * installed qemu-system-arm (Debian 7.2, API version 1). Debian ships no
 * qemu-plugin.h, so the few entry points used are declared here from the
 * API's documented signatures; the functions are exported by the QEMU
 * binary itself and resolved when QEMU loads this object. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef uint64_t qemu_plugin_id_t;
struct qemu_plugin_tb;
struct qemu_plugin_insn;
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 };
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void *userdata);
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
void qemu_plugin_register_vcpu_tb_exec_inline(struct qemu_plugin_tb *tb, enum qemu_plugin_op op, void *ptr,
                                              uint64_t imm);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void *userdata);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *tb, size_t idx);
uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *insn);

#define EXPORT __attribute__((visibility("default")))
EXPORT int qemu_plugin_version = 1;

/* one translation: its instructions' addresses and the execution counter
 * the generated code increments (blocks are never freed: a translation
 * flushed and made again gets a second record, both summed at exit) */
struct block {
    struct block *next;
    uint64_t count;
    size_t n;
    uint64_t addr[];
};
static struct block *blocks;
static char out_path[4096];

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb) {
    size_t i, n = qemu_plugin_tb_n_insns(tb);
    struct block *b = malloc(sizeof *b + n * sizeof b->addr[0]);
    (void)id;
    if (!b) abort();
    b->count = 0;
    b->n = n;
    for (i = 0; i < n; i++) b->addr[i] = qemu_plugin_insn_vaddr(qemu_plugin_tb_get_insn(tb, i));
    b->next = blocks;
    blocks = b;
    qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &b->count, 1);
}

static void write_counts(qemu_plugin_id_t id, void *p) {
    struct block *b;
    size_t i;
    FILE *f = fopen(out_path, "w");
    (void)id;
    (void)p;
    if (!f) {
        fprintf(stderr, "insn_plugin: cannot write %s\n", out_path);
        return;
    }
    /* one line per instruction per translation; the caller sums duplicates */
    for (b = blocks; b; b = b->next)
        if (b->count)
            for (i = 0; i < b->n; i++) fprintf(f, "%llu %llu\n", (unsigned long long)b->addr[i],
                                               (unsigned long long)b->count);
    if (fclose(f) != 0) fprintf(stderr, "insn_plugin: error writing %s\n", out_path);
}

EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const void *info, int argc, char **argv) {
    (void)info;
    if (argc != 1 || strncmp(argv[0], "out=", 4) != 0 || strlen(argv[0] + 4) >= sizeof out_path) {
        fprintf(stderr, "insn_plugin: usage: -plugin insn_plugin.so,out=PATH\n");
        return -1;
    }
    strcpy(out_path, argv[0] + 4);
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    qemu_plugin_register_atexit_cb(id, write_counts, NULL);
    return 0;
}
