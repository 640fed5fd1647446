/* test_runtime_health.c -- the health report, distance limits and the
 * rest-shape option (issue 9 items 4-6; runtime/NUMERICS.md steps 8-9).
 *
 *   test_runtime_health COW COW_LIMIT COW_FARLIMIT COW_REST
 *
 * COW is the bundled cow; COW_LIMIT adds `limit all 0.3`, COW_FARLIMIT
 * `limit all 100` (never reached), COW_REST `rest_shape modelled`. Built fixed
 * and float (the blobs must be of the same flavour). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sinew.h"
#include "sn_format.h"
#include "sn_test.h"
#include "reference/phys_util.h"

#if defined(SN_FLOAT)
#define R2D(x) ((double)(x))
#define D2R(x) ((sn_real)(x))
#define QR2D(x) ((double)(x))
#else
#define R2D(x) ((double)(x) / 65536.0)
#define D2R(x) ((sn_real)((x) * 65536.0))
#define QR2D(x) ((double)(x) / 1073741824.0)
#endif

typedef struct {
    unsigned char *bytes;
    size_t size;
    const sn_blob *blob;
    sn_blob_info info;
    void *mem;
    sn_instance *inst;
} ch_t;

static unsigned char *load(const char *path, size_t *size) { return pu_read(path, size); }

static int open_ch(ch_t *c, unsigned char *bytes, size_t size) {
    memset(c, 0, sizeof *c);
    c->bytes = bytes;
    c->size = size;
    if (sn_blob_validate(bytes, size, &c->blob) != SN_OK) return -1;
    sn_blob_get_info(c->blob, &c->info);
    c->mem = malloc(sn_instance_size(c->blob) + 8); /* malloc aligns for any type: >= 8 */
    return sn_instance_init(c->mem, sn_instance_size(c->blob), c->blob, &c->inst) == SN_OK ? 0 : -1;
}
static void close_ch(ch_t *c) { free(c->mem); }

/* Pose: joint `jn` (local) rotated by deg(t) about axis, others at rest. */
static void set_pose(ch_t *c, int32_t jn, sn_vec3 axis, double deg) {
    sn_quat local[256];
    sn_xform xf[256];
    uint32_t j;
    for (j = 0; j < c->info.joints; j++) {
        sn_vec3 a = {D2R(0), D2R(1), D2R(0)};
        local[j] = sn_quat_axis_angle(a, D2R(0));
    }
    if (jn >= 0) local[jn] = sn_quat_axis_angle(axis, D2R(deg));
    sn_pose_from_local(c->blob, local, NULL, xf);
    sn_set_pose(c->inst, xf, c->info.joints);
}

/* The violent clip of the issue: a joint turned 180 degrees in 0.1 s, then held. */
static double violent(int step, double h) {
    double t = step * h;
    return t >= 0.1 ? 180.0 : 1800.0 * t;
}

static uint32_t rd32(const unsigned char *p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static void wr32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)v; p[1] = (unsigned char)(v >> 8); p[2] = (unsigned char)(v >> 16); p[3] = (unsigned char)(v >> 24);
}

/* Double-precision elastic energy from the public state: 1/2 sum_e d^T S^_e d
 * times ENERGY, with d_a = R_e^T (p_a - p_a0) - (x_a - x_a0); at the rest pose
 * R_e = I. Positions from sn_get_lattice (mesh units) -> internal units. */
static double elastic_rest_energy(const ch_t *c, const sn_vec3 *lat) {
    const unsigned char *b = c->bytes;
    unsigned rs = b[SN_H_REAL_SIZE];
    int len_shift = (signed char)b[SN_H_LEN_SHIFT], frac_S = b[SN_H_FRAC_S], frac_E = (signed char)b[SN_H_FRAC_E];
    const unsigned char *cells = b + rd32(b + SN_H_SECTIONS + 16 * SN_SEC_CELLS);
    const unsigned char *K = b + rd32(b + SN_H_SECTIONS + 16 * SN_SEC_CELLK);
    const unsigned char *rest = b + rd32(b + SN_H_SECTIONS + 16 * SN_SEC_REST);
    double U = ldexp(1.0, len_shift), E = 0, escale;
    uint32_t e;
#if defined(SN_FLOAT)
    float f;
    memcpy(&f, b + SN_H_REALS + SN_R_ENERGY * rs, 4);
    escale = f;
    (void)frac_E; (void)frac_S;
#else
    escale = ldexp((double)(int32_t)rd32(b + SN_H_REALS + SN_R_ENERGY * rs), -frac_E);
#endif
    for (e = 0; e < c->info.cells; e++) {
        double d[24], y[24] = {0};
        int a, bb, i, j, n = 0;
        unsigned a0 = (unsigned)(cells[16 * e] | (cells[16 * e + 1] << 8));
        for (a = 0; a < 8; a++) {
            unsigned v = (unsigned)(cells[16 * e + 2 * a] | (cells[16 * e + 2 * a + 1] << 8));
            for (i = 0; i < 3; i++) {
                double pv = (i == 0 ? R2D(lat[v].x) : i == 1 ? R2D(lat[v].y) : R2D(lat[v].z)) / U;
                double p0 = (i == 0 ? R2D(lat[a0].x) : i == 1 ? R2D(lat[a0].y) : R2D(lat[a0].z)) / U;
                uint32_t xv = rd32(rest + (3 * v + (unsigned)i) * rs), x0 = rd32(rest + (3 * a0 + (unsigned)i) * rs);
#if defined(SN_FLOAT)
                float fx, f0;
                memcpy(&fx, &xv, 4); memcpy(&f0, &x0, 4);
                d[3 * a + i] = (pv - p0) - ((double)fx - (double)f0);
#else
                d[3 * a + i] = (pv - p0) - ldexp((double)(int32_t)xv - (double)(int32_t)x0, -SN_Q_LEN);
#endif
            }
        }
        for (a = 0; a < 8; a++)
            for (bb = a; bb < 8; bb++, n++)
                for (i = 0; i < 3; i++)
                    for (j = 0; j < 3; j++) {
#if defined(SN_FLOAT)
                        uint32_t raw = rd32(K + ((size_t)e * 324 + (size_t)(9 * n + 3 * i + j)) * rs);
                        float fk;
                        double k;
                        memcpy(&fk, &raw, 4);
                        k = fk;
#else   /* format 6.0 CELLK: diagonal int32 xx yy zz xy xz yz, off-diagonal int16 m 2^e */
                        const unsigned char *ck = K + (size_t)e * SN_CELLK_FIXED_BYTES;
                        double k;
                        if (a == bb) {
                            static const int s6[9] = {0, 3, 4, 3, 1, 5, 4, 5, 2};
                            k = ldexp((double)(int32_t)rd32(ck + SN_CELLK_DIAG + 24 * a + 4 * s6[3 * i + j]), -frac_S);
                        } else {
                            uint32_t o = SN_CELLK_OFFIDX(a, bb);
                            const unsigned char *m = ck + SN_CELLK_OFF + 18 * o + 2 * (3 * i + j);
                            k = ldexp((double)(int16_t)(uint16_t)(m[0] | (m[1] << 8)), ck[SN_CELLK_EXP + o] - frac_S);
                        }
#endif
                        y[3 * a + i] += k * d[3 * bb + j];
                        if (bb != a) y[3 * bb + j] += k * d[3 * a + i];
                    }
        for (a = 0; a < 24; a++) E += 0.5 * d[a] * y[a];
    }
    return E * escale;
}

int main(int argc, char **argv) {
    ch_t c;
    unsigned char *bytes;
    size_t size;
    sn_stats st;
    int s;
    double h, bound;
    int32_t neck;
    sn_vec3 ax = {D2R(1), D2R(0), D2R(0)};
    (void)t_seed;
    if (argc < 5) { fprintf(stderr, "usage: %s COW COW_LIMIT COW_FARLIMIT COW_REST\n", argv[0]); return 2; }

    /* 1. A healthy run reports nothing; energy matches a double evaluation. */
    bytes = load(argv[1], &size);
    T_CHECK(bytes && open_ch(&c, bytes, size) == 0, "open %s", argv[1]);
    if (!bytes) return T_END();
    h = R2D(c.info.timestep);
#if !defined(SN_FLOAT)
    bound = R2D((int32_t)rd32(bytes + SN_H_REALS + SN_R_DISP_BOUND * 4));
#else
    { float f; uint32_t u = rd32(bytes + SN_H_REALS + SN_R_DISP_BOUND * 4); memcpy(&f, &u, 4); bound = f; }
#endif
    neck = sn_find_joint(c.blob, "neck");
    T_CHECK(neck >= 0, "cow has a neck joint");
    for (s = 0; s < 600; s++) { set_pose(&c, -1, ax, 0); sn_step(c.inst); }
    sn_get_stats(c.inst, &st);
    T_CHECK(st.saturations == 0 && st.bound_steps == 0, "rest: saturations %u, bound steps %u", st.saturations, st.bound_steps);
    T_CHECK(R2D(st.energy) > 0 && R2D(st.energy) < 1e6, "rest energy %g J positive and finite", R2D(st.energy));
    T_CHECK(R2D(st.disp_max) > 0 && R2D(st.disp_max) < bound, "rest disp_max %g cells in (0, %g)", R2D(st.disp_max), bound);
    {
        sn_vec3 *lat = malloc(sizeof *lat * c.info.vertices);
        double eref;
        sn_get_lattice(c.inst, lat, 0, c.info.vertices);
        eref = elastic_rest_energy(&c, lat);
        T_FIGURE("settled cow at rest: energy %.4f J (runtime), elastic %.4f J (double from the state)", R2D(st.energy), eref);
        /* settled for 10 s with damping: kinetic energy and the change over the
         * last step are < 0.1% of the elastic energy; fixed: Q16.16 joules and
         * Q22 positions leave ~1e-4 relative */
        T_NEAR(R2D(st.energy), eref, 2e-3 * eref, "settled: kinetic ~0, one step of drift, quantization");
        free(lat);
    }
    close_ch(&c);

    /* 2. A blow-up is reported: the same cow with its stiffness negated
     * (valid, but not positive definite) diverges. */
    {
        unsigned char *bad = malloc(size + 8);
        const unsigned char *K;
        uint32_t i, n, rs = bytes[SN_H_REAL_SIZE];
        memcpy(bad, bytes, size);
        K = bad + rd32(bad + SN_H_SECTIONS + 16 * SN_SEC_CELLK);
#if defined(SN_FLOAT)
        n = rd32(bad + SN_H_SECTIONS + 16 * SN_SEC_CELLK + 4) / rs;
        for (i = 0; i < n; i++) ((unsigned char *)K)[(size_t)i * rs + 3] ^= 0x80u; /* sign bit */
#else   /* format 6.0: negate the diagonal int32 and the int16 mantissas (never -2^15) */
        n = rd32(bad + SN_H_SECTIONS + 16 * SN_SEC_CELLK + 8); /* cells */
        (void)rs;
        for (i = 0; i < n; i++) {
            unsigned char *ck = (unsigned char *)K + (size_t)i * SN_CELLK_FIXED_BYTES;
            uint32_t k;
            for (k = 0; k < 48; k++) wr32(ck + SN_CELLK_DIAG + 4 * k, (uint32_t)(-(int32_t)rd32(ck + SN_CELLK_DIAG + 4 * k)));
            for (k = 0; k < 28 * 9; k++) {
                unsigned char *m = ck + SN_CELLK_OFF + 2 * k;
                uint16_t v = (uint16_t)(0u - (unsigned)(m[0] | (m[1] << 8)));
                m[0] = (unsigned char)v; m[1] = (unsigned char)(v >> 8);
            }
        }
#endif
        wr32(bad + SN_H_CRC32, snref_crc32(bad + 16, size - 16));
        T_CHECK(open_ch(&c, bad, size) == 0, "negated-stiffness blob validates");
        for (s = 0; s < 300; s++) { set_pose(&c, -1, ax, 0); sn_step(c.inst); }
        sn_get_stats(c.inst, &st);
        T_FIGURE("negated stiffness, 300 steps: saturations %u, bound steps %u, largest displacement %g cells",
                 st.saturations, st.bound_steps, R2D(st.disp_max));
        T_CHECK(st.bound_steps > 0 && R2D(st.disp_max) > bound, "blow-up reported (bound steps %u, disp_max %g)",
                st.bound_steps, R2D(st.disp_max));
        {   /* the output stays finite (float) / in range (fixed) */
            sn_vec3 *sv = malloc(sizeof *sv * c.info.surface_vertices);
            uint32_t k, finite = 1;
            sn_get_surface(c.inst, sv, 0, c.info.surface_vertices);
            for (k = 0; k < c.info.surface_vertices; k++)
                finite &= R2D(sv[k].x) == R2D(sv[k].x) && R2D(sv[k].y) == R2D(sv[k].y) && R2D(sv[k].z) == R2D(sv[k].z);
            T_CHECK(finite, "surface finite after a blow-up");
            free(sv);
        }
        close_ch(&c);
        free(bad);
    }

    /* 3. Limits: the violent neck turn with `limit all 0.3` stays within it. */
    {
        unsigned char *lb = load(argv[2], &size);
        double worst = 0, lim_cells;
        uint32_t steps_with = 0;
        T_CHECK(lb && open_ch(&c, lb, size) == 0, "open %s", argv[2]);
        if (lb) {
            lim_cells = 0.3 / 1.2; /* the cow's cell is 1.2 mesh units */
            for (s = 0; s < 240; s++) {
                set_pose(&c, neck, ax, violent(s, h));
                sn_step(c.inst);
                sn_get_stats(c.inst, &st);
                worst = R2D(st.disp) > worst ? R2D(st.disp) : worst;
                steps_with += st.limit_clamps > 0;
            }
            T_FIGURE("violent neck turn with limit 0.3 mesh units (%.3f cells): largest displacement %.4f cells, "
                     "%u steps with clamps, saturations %u", lim_cells, worst, steps_with, st.saturations);
            /* the health pass measures after the limits: one rounding of p = s + dL/|d| (1 LSB of Q22) */
            T_CHECK(worst <= lim_cells + 1e-4, "within the limit: %g <= %g cells", worst, lim_cells);
            T_CHECK(st.limit_steps == steps_with && steps_with > 0, "limit steps counted (%u, %u)", st.limit_steps, steps_with);
            close_ch(&c);
            free(lb);
        }
    }

    /* 4. A limit never reached changes nothing, bit for bit. */
    {
        unsigned char *fb = load(argv[3], &size);
        uint64_t h1 = 0, h2 = 0;
        size_t size0;
        unsigned char *b0 = load(argv[1], &size0);
        ch_t c0;
        T_CHECK(fb && b0 && open_ch(&c, fb, size) == 0 && open_ch(&c0, b0, size0) == 0, "open far-limit and plain cow");
        if (fb && b0) {
            for (s = 0; s < 240; s++) {
                set_pose(&c, neck, ax, violent(s, h));
                set_pose(&c0, neck, ax, violent(s, h));
                sn_step(c.inst);
                sn_step(c0.inst);
            }
            h1 = sn_state_hash(c.inst);
            h2 = sn_state_hash(c0.inst);
            sn_get_stats(c.inst, &st);
            T_CHECK(st.limit_steps == 0, "far limit never clamps (%u)", st.limit_steps);
            T_CHECK(h1 == h2, "far limit: state hash %016llx == plain %016llx", (unsigned long long)h1, (unsigned long long)h2);
            close_ch(&c);
            close_ch(&c0);
        }
        free(fb);
        free(b0);
    }

    /* 5. Rest shape = modelled shape: 600 steps at rest keep the surface
     * within 1e-3 of the character's height of the mesh. */
    {
        const char *paths[2];
        int k;
        paths[0] = argv[4];
        paths[1] = argv[1];
        for (k = 0; k < 2; k++) {
            unsigned char *rb = load(paths[k], &size);
            sn_vec3 *s0, *s1;
            double lo = 1e30, hi = -1e30, worst = 0;
            uint32_t i;
            T_CHECK(rb && open_ch(&c, rb, size) == 0, "open %s", paths[k]);
            if (!rb) continue;
            s0 = malloc(sizeof *s0 * c.info.surface_vertices);
            s1 = malloc(sizeof *s1 * c.info.surface_vertices);
            set_pose(&c, -1, ax, 0);
            sn_step(c.inst); /* the first pose places the flesh rigidly: the mesh */
            sn_get_surface(c.inst, s0, 0, c.info.surface_vertices);
            for (s = 1; s < 600; s++) { set_pose(&c, -1, ax, 0); sn_step(c.inst); }
            sn_get_surface(c.inst, s1, 0, c.info.surface_vertices);
            for (i = 0; i < c.info.surface_vertices; i++) {
                double dx = R2D(s1[i].x) - R2D(s0[i].x), dy = R2D(s1[i].y) - R2D(s0[i].y), dz = R2D(s1[i].z) - R2D(s0[i].z);
                double d = sqrt(dx * dx + dy * dy + dz * dz);
                worst = d > worst ? d : worst;
                lo = R2D(s0[i].y) < lo ? R2D(s0[i].y) : lo;
                hi = R2D(s0[i].y) > hi ? R2D(s0[i].y) : hi;
            }
            T_FIGURE("%s: 600 steps at rest: largest surface drift %.5f mesh units = %.2e of the height %.3f",
                     k == 0 ? "rest_shape modelled" : "rest_shape sag (default)", worst, worst / (hi - lo), hi - lo);
            if (k == 0) T_CHECK(worst <= 1e-3 * (hi - lo), "modelled rest shape drifts %g <= 1e-3 x height", worst);
            else T_CHECK(worst > 1e-3 * (hi - lo), "control: the default sags (%g)", worst);
            free(s0);
            free(s1);
            close_ch(&c);
            free(rb);
        }
    }
    /* 6. Unusable poses are refused whole and change nothing: a (near-)zero
     * quaternion in both flavours; NaN, infinity and translations beyond the
     * fixed range in float. */
    {
        sn_quat local[256];
        sn_xform xf[256], bad[256];
        uint64_t h0, h1;
        uint32_t j, k;
        int cases = 0;
        T_CHECK(open_ch(&c, bytes, size) == 0, "open cow for pose checks");
        for (j = 0; j < c.info.joints; j++) {
            sn_vec3 a = {D2R(0), D2R(1), D2R(0)};
            local[j] = sn_quat_axis_angle(a, D2R(10.0 * j));
        }
        sn_pose_from_local(c.blob, local, NULL, xf);
        T_CHECK(sn_set_pose(c.inst, xf, c.info.joints) == SN_OK, "a good pose is taken");
        for (s = 0; s < 5; s++) sn_step(c.inst);
        h0 = sn_state_hash(c.inst);
        for (k = 0; k < 6; k++) {
            memcpy(bad, xf, sizeof(sn_xform) * c.info.joints);
            j = c.info.joints - 1;
            switch (k) {
            case 0: bad[j].rot.x = bad[j].rot.y = bad[j].rot.z = bad[j].rot.w = 0; break;
#if defined(SN_FLOAT)
            case 1: bad[j].rot.x = bad[j].rot.y = bad[j].rot.z = 0; bad[j].rot.w = 1e-30f; break;
            case 2: bad[j].rot.w = (float)NAN; break;
            case 3: bad[j].pos.x = (float)INFINITY; break;
            case 4: bad[j].pos.y = 3.4e38f; break;
            case 5: bad[j].pos.z = (float)NAN; break;
#else
            case 1: bad[j].rot.x = bad[j].rot.y = bad[j].rot.z = 0; bad[j].rot.w = 1; break; /* 1 LSB of Q30 */
            default: continue;
#endif
            }
            cases++;
            T_CHECK(sn_set_pose(c.inst, bad, c.info.joints) == SN_ERR_ARG, "bad pose %u refused", k);
            sn_step(c.inst);
            sn_set_pose(c.inst, xf, c.info.joints);
        }
        /* the refused poses changed nothing: the same number of steps with the
         * good pose gives the same state as a clean run */
        h1 = sn_state_hash(c.inst);
        {
            ch_t c2;
            T_CHECK(open_ch(&c2, bytes, size) == 0, "second instance");
            sn_set_pose(c2.inst, xf, c.info.joints);
            for (s = 0; s < 5 + cases; s++) sn_step(c2.inst);
            T_CHECK(sn_state_hash(c2.inst) == h1, "refused poses left no trace (hash %016llx vs %016llx)",
                    (unsigned long long)sn_state_hash(c2.inst), (unsigned long long)h1);
            close_ch(&c2);
        }
        T_CHECK(h0 != h1, "the instance kept stepping");
        close_ch(&c);
    }
    free(bytes);
    return T_END();
}
