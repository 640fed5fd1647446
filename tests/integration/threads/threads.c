/* threads.c -- the runtime has no mutable global state: 8 instances of one
 * blob (shared, read-only) stepped on 8 pthreads at once give exactly the
 * hashes of stepping them one after another on one thread.
 *   threads BLOB [STEPS]   (default 100)
 * Instance i follows the wiggle sequence shifted by 5*i steps, so every
 * instance has its own hash and cross-talk between instances would show.
 * Each thread also compares its hash every 10 steps with the sequential run.
 * Then the same 8 motions as shared instances (sn_instance_init_shared):
 * 2 threads, each stepping 4 of them in turn with its one workspace
 * (sn_step_with), the engine's per-thread scratch: again the same hashes.
 * Prints "hash: <hex>" of instance 0 (phase 0: the consumers' hash) and
 * "threads: 8 instances agree" or a FAIL line; exit 0 only when all agree.
 * Built by tests/scripts/test_integration.sh with gcc, and with clang
 * -fsanitize=thread over the runtime sources themselves. */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sinew.h"
#include "sn_wiggle.h"

#define N_INST 8
#define MAX_JOINTS 255
#define TRACE_EVERY 10u
#define MAX_TRACE 1024

typedef struct job {
    const sn_blob *blob;       /* shared by all jobs, never written */
    uint32_t joints, steps, phase;
    void *mem;                 /* this job's instance memory */
    size_t mem_size;
    sn_quat local[MAX_JOINTS];
    sn_xform xf[MAX_JOINTS];
    uint64_t trace[MAX_TRACE]; /* hash every TRACE_EVERY steps */
    uint64_t hash;
    int failed;
} job;

/* a thread stepping several shared instances with its one workspace */
typedef struct group {
    job *jobs[N_INST];
    int n;
    void *ws;
    size_t ws_size;
} group;

static pthread_barrier_t start_line;
static int use_barrier;

static void *run(void *arg) {
    job *jb = (job *)arg;
    sn_instance *inst;
    uint32_t k;
    if (use_barrier) pthread_barrier_wait(&start_line);   /* all step at once */
    if (sn_instance_init(jb->mem, jb->mem_size, jb->blob, &inst) != SN_OK) { jb->failed = 1; return NULL; }
    for (k = 0; k < jb->steps; k++) {
        sn_wiggle_pose(jb->blob, jb->joints, k, jb->phase, jb->local, jb->xf);
        if (sn_set_pose(inst, jb->xf, jb->joints) != SN_OK) { jb->failed = 1; return NULL; }
        sn_step(inst);
        if ((k + 1) % TRACE_EVERY == 0 && (k + 1) / TRACE_EVERY <= MAX_TRACE)
            jb->trace[(k + 1) / TRACE_EVERY - 1] = sn_state_hash(inst);
    }
    jb->hash = sn_state_hash(inst);
    return NULL;
}

static void *run_group(void *arg) {
    group *g = (group *)arg;
    sn_instance *inst[N_INST];
    uint32_t k;
    int i;
    pthread_barrier_wait(&start_line);
    for (i = 0; i < g->n; i++)
        if (sn_instance_init_shared(g->jobs[i]->mem, g->jobs[i]->mem_size, g->jobs[i]->blob, &inst[i]) != SN_OK) {
            g->jobs[i]->failed = 1;
            return NULL;
        }
    for (k = 0; k < g->jobs[0]->steps; k++)
        for (i = 0; i < g->n; i++) {
            job *jb = g->jobs[i];
            sn_wiggle_pose(jb->blob, jb->joints, k, jb->phase, jb->local, jb->xf);
            if (sn_set_pose(inst[i], jb->xf, jb->joints) != SN_OK) { jb->failed = 1; return NULL; }
            if (sn_step_with(inst[i], g->ws, g->ws_size) != SN_OK) { jb->failed = 1; return NULL; }
            if ((k + 1) % TRACE_EVERY == 0 && (k + 1) / TRACE_EVERY <= MAX_TRACE)
                jb->trace[(k + 1) / TRACE_EVERY - 1] = sn_state_hash(inst[i]);
        }
    for (i = 0; i < g->n; i++) g->jobs[i]->hash = sn_state_hash(inst[i]);
    return NULL;
}

int main(int argc, char **argv) {
    static job seq[N_INST], par[N_INST], shr[N_INST];
    static group grp[2];
    pthread_t tid[N_INST];
    const sn_blob *blob;
    sn_blob_info info;
    FILE *f;
    long n;
    void *bytes;
    size_t need;
    uint32_t steps = argc > 2 ? (uint32_t)strtoul(argv[2], NULL, 10) : 100u, ntr;
    int i, bad = 0, distinct = 1;
    char hex[17];
    if (argc < 2) { fprintf(stderr, "usage: threads BLOB [STEPS]\n"); return 2; }
    f = fopen(argv[1], "rb");
    if (!f || fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) <= 0 || fseek(f, 0, SEEK_SET) != 0) {
        fprintf(stderr, "threads: cannot read %s\n", argv[1]); return 2;
    }
    bytes = malloc((size_t)n);
    if (!bytes || fread(bytes, 1, (size_t)n, f) != (size_t)n) return 2;
    fclose(f);
    if (sn_blob_validate(bytes, (size_t)n, &blob) != SN_OK) { fprintf(stderr, "threads: bad blob\n"); return 1; }
    sn_blob_get_info(blob, &info);
    if (info.joints > MAX_JOINTS) return 1;
    need = sn_instance_size(blob);
    for (i = 0; i < N_INST; i++) {
        job *pair[2];
        int w;
        pair[0] = &seq[i]; pair[1] = &par[i];
        for (w = 0; w < 2; w++) {
            pair[w]->blob = blob; pair[w]->joints = info.joints; pair[w]->steps = steps;
            pair[w]->phase = 5u * (uint32_t)i; pair[w]->mem_size = need;
            pair[w]->mem = malloc(need);
            if (!pair[w]->mem) return 2;
        }
    }
    /* one after another on this thread */
    for (i = 0; i < N_INST; i++) run(&seq[i]);
    /* all at once on 8 threads */
    use_barrier = 1;
    if (pthread_barrier_init(&start_line, NULL, N_INST) != 0) return 2;
    for (i = 0; i < N_INST; i++)
        if (pthread_create(&tid[i], NULL, run, &par[i]) != 0) { fprintf(stderr, "threads: pthread_create failed\n"); return 2; }
    for (i = 0; i < N_INST; i++) pthread_join(tid[i], NULL);
    pthread_barrier_destroy(&start_line);
    /* shared instances: 2 threads, 4 each, one workspace per thread */
    if (pthread_barrier_init(&start_line, NULL, 2) != 0) return 2;
    for (i = 0; i < N_INST; i++) {
        shr[i] = seq[i];
        shr[i].hash = 0; shr[i].failed = 0;
        memset(shr[i].trace, 0, sizeof shr[i].trace);
        shr[i].mem_size = sn_instance_state_size(blob);
        shr[i].mem = malloc(shr[i].mem_size);
        if (!shr[i].mem) return 2;
        grp[i % 2].jobs[grp[i % 2].n++] = &shr[i];
    }
    for (i = 0; i < 2; i++) {
        grp[i].ws_size = sn_workspace_size(blob, SN_MODE_WARPED);
        if (!(grp[i].ws = malloc(grp[i].ws_size))) return 2;
        if (pthread_create(&tid[i], NULL, run_group, &grp[i]) != 0) { fprintf(stderr, "threads: pthread_create failed\n"); return 2; }
    }
    for (i = 0; i < 2; i++) pthread_join(tid[i], NULL);
    pthread_barrier_destroy(&start_line);

    ntr = steps / TRACE_EVERY < MAX_TRACE ? steps / TRACE_EVERY : MAX_TRACE;
    for (i = 0; i < N_INST; i++) {
        char hs[17], hp[17];
        sn_wiggle_hex(seq[i].hash, hs);
        sn_wiggle_hex(par[i].hash, hp);
        printf("instance %d (phase %2u): sequential %s  threaded %s\n", i, seq[i].phase, hs, hp);
        if (seq[i].failed || par[i].failed) { printf("FAIL: instance %d: init or pose refused\n", i); bad = 1; continue; }
        if (seq[i].hash != par[i].hash || memcmp(seq[i].trace, par[i].trace, ntr * sizeof seq[i].trace[0]) != 0) {
            printf("FAIL: instance %d: threaded run differs from the sequential one\n", i); bad = 1;
        }
        if (shr[i].failed || shr[i].hash != seq[i].hash || memcmp(seq[i].trace, shr[i].trace, ntr * sizeof seq[i].trace[0]) != 0) {
            printf("FAIL: instance %d: shared instance (2 threads, one workspace each) differs from the sequential one\n", i); bad = 1;
        }
        if (i > 0 && seq[i].hash == seq[0].hash) distinct = 0;
    }
    if (!distinct) { printf("FAIL: instances with different motions gave equal hashes (the test would not see cross-talk)\n"); bad = 1; }
    sn_wiggle_hex(seq[0].hash, hex);
    printf("hash: %s\n", hex);
    if (!bad) printf("threads: %d instances, %u steps each: threaded hashes = sequential hashes = shared instances' "
                     "(2 threads, one workspace each)\n", N_INST, steps);
    for (i = 0; i < N_INST; i++) { free(seq[i].mem); free(par[i].mem); free(shr[i].mem); }
    free(grp[0].ws); free(grp[1].ws);
    free(bytes);
    return bad;
}
