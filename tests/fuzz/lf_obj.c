/* lf_obj.c -- libFuzzer harness: the host tool's OBJ reader (tools/sb_mesh.c,
 * sb_mesh_load_obj) and what the bake does next with a mesh it accepted:
 * the volume, the inside test's bins (sb_inside_init: (int)floor of
 * coordinates over bin sizes) and rays through them, the closest-point
 * query. Built by tests/fuzz/fuzz.mk as fuzz_obj. sb_mesh_load_obj takes a
 * path, so each input is written to a temp file first (lf_common.h).
 * Checks besides the sanitizers: an error leaves a message; an accepted mesh
 * is closed (nv, nt >= 1, indices in range), its coordinates finite and
 * within the reader's bound, its bounding box holds every vertex and its
 * volume is positive.
 */
#include "lf_common.h" /* first: it sets _POSIX_C_SOURCE */

#include <math.h>
#include "sb.h"

/* the reader's bound on |coordinate| (tools/sb_mesh.c SB_MESH_COORD_MAX, with its reason) */
#define SB_MESH_COORD_MAX 1e9

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    sb_mesh m;
    sb_inside in;
    const char *path = lf_tmp_write(data, size);
    int i, k;
    double q[3], c[3], xs[8];
    if (sb_mesh_load_obj(path, &m) != 0) {
        LF_REQUIRE(sb_error() && sb_error()[0], "sb_mesh_load_obj failed without a message");
        sb_mesh_free(&m);
        return 0;
    }
    LF_REQUIRE(m.nv >= 1 && m.nt >= 1, "nv %d nt %d", m.nv, m.nt);
    for (i = 0; i < 3 * m.nt; i++) LF_REQUIRE(m.tri[i] >= 0 && m.tri[i] < m.nv, "triangle index %d", m.tri[i]);
    for (i = 0; i < 3 * m.nv; i++)
        LF_REQUIRE(isfinite(m.v[i]) && fabs(m.v[i]) <= SB_MESH_COORD_MAX, "coordinate %g", m.v[i]);
    for (i = 0; i < m.nv; i++)
        for (k = 0; k < 3; k++) LF_REQUIRE(m.v[3 * i + k] >= m.lo[k] && m.v[3 * i + k] <= m.hi[k], "bounding box");
    LF_REQUIRE(sb_mesh_volume(&m) > 0, "volume %g", sb_mesh_volume(&m));
    sb_inside_init(&in, &m);
    for (k = 0; k < 3; k++) q[k] = 0.5 * (m.lo[k] + m.hi[k]);
    (void)sb_inside_test(&in, q);
    (void)sb_inside_test(&in, m.lo);
    (void)sb_inside_test(&in, m.hi);
    (void)sb_inside_ray(&in, m.v[1], m.v[2], xs, 8);
    (void)sb_mesh_closest(&m, q, c);
    sb_inside_free(&in);
    sb_mesh_free(&m);
    return 0;
}
