/* test_bake_mesh.c -- host tool: OBJ triangulation keeps a closed polygon mesh
 * closed. A fan from each polygon's first corner can create a diagonal that
 * another polygon also creates (an edge of 4 triangles: "mesh is not closed");
 * the reader picks, per polygon, a fan whose diagonals are all new. */
#include "sb.h"
#include "sn_test.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *dir(void) { return getenv("BUILD") ? getenv("BUILD") : "build"; }

static int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    return fclose(f);
}

/* edges (unordered) of the triangles, each used exactly twice, once each way */
static int closed(const sb_mesh *m)
{
    int t, k, u, bad = 0;
    for (t = 0; t < m->nt; t++)
        for (k = 0; k < 3; k++) {
            int a = m->tri[3 * t + k], b = m->tri[3 * t + (k + 1) % 3], fwd = 0, back = 0;
            for (u = 0; u < m->nt; u++) {
                int j;
                for (j = 0; j < 3; j++) {
                    int c = m->tri[3 * u + j], d = m->tri[3 * u + (j + 1) % 3];
                    fwd += c == a && d == b;
                    back += c == b && d == a;
                }
            }
            if (fwd != 1 || back != 1) bad++;
        }
    return bad == 0;
}

/* the tetrahedron (0,0,0) (1,0,0) (0,1,0) (0,0,1) written as two quads that
 * share all four boundary edges: both fans from the first corner split along
 * the same diagonal 2-4 (the beast's muzzle has this case). The only closed
 * result: the first quad along 2-4, the second along 1-3. */
static void test_shared_diagonal(void)
{
    char path[512];
    sb_mesh m;
    snprintf(path, sizeof path, "%s/tests/bake_two_quads.obj", dir());
    T_CHECK(write_file(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 2 3 4 1\nf 4 3 2 1\n") == 0, "write %s", path);
    if (sb_mesh_load_obj(path, &m)) { T_CHECK(0, "two quads sharing a fan diagonal: %s", sb_error()); return; }
    T_CHECK(m.nt == 4 && closed(&m), "two quads -> 4 triangles, closed and consistently oriented (nt %d)", m.nt);
    T_NEAR(sb_mesh_volume(&m), 1.0 / 6.0, 1e-15, "the tetrahedron's volume, exact in double");
    sb_mesh_free(&m);
}

/* a cube of 6 quads in which every second face's first-corner fan is fine:
 * the plain fan from the first corner is kept when its diagonal is new */
static void test_quad_cube(void)
{
    char path[512];
    sb_mesh m;
    snprintf(path, sizeof path, "%s/tests/bake_quad_cube.obj", dir());
    T_CHECK(write_file(path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                             "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n") == 0, "write %s", path);
    if (sb_mesh_load_obj(path, &m)) { T_CHECK(0, "quad cube: %s", sb_error()); return; }
    T_CHECK(m.nt == 12 && closed(&m), "6 quads -> 12 triangles, closed");
    T_CHECK(m.tri[0] == 0 && m.tri[1] == 3 && m.tri[2] == 2 && m.tri[3] == 0 && m.tri[4] == 2 && m.tri[5] == 1,
            "first face split as a fan from its first corner (a b c, a c d)");
    T_NEAR(sb_mesh_volume(&m), 1.0, 1e-15, "unit cube volume");
    sb_mesh_free(&m);
}

/* two pentagons sharing all five boundary edges (a closed "pillow", lifted so it has
 * volume): the first takes the fan from corner 1 (diagonals 1-3, 1-4); the second,
 * listed from the same corner, must pick a start whose two diagonals are both new */
static void test_two_pentagons(void)
{
    char path[512];
    sb_mesh m;
    snprintf(path, sizeof path, "%s/tests/bake_pillow.obj", dir());
    T_CHECK(write_file(path, "v 0 0 0\nv 2 0 0.5\nv 3 2 0\nv 1 3 0.5\nv -1 2 0\n"
                             "f 1 5 4 3 2\nf 1 2 3 4 5\n") == 0, "write %s", path);
    if (sb_mesh_load_obj(path, &m)) { T_CHECK(0, "two pentagons: %s", sb_error()); return; }
    T_CHECK(m.nt == 6 && closed(&m), "two pentagons -> 6 triangles, no repeated diagonal (nt %d)", m.nt);
    sb_mesh_free(&m);
}

/* impossible: two triangles and a quad whose both diagonals already exist */
static void test_impossible(void)
{
    char path[512];
    sb_mesh m;
    snprintf(path, sizeof path, "%s/tests/bake_bad_quad.obj", dir());
    T_CHECK(write_file(path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 3 2\nf 2 4 3\n") == 0, "write %s", path);
    T_CHECK(sb_mesh_load_obj(path, &m) != 0 && strstr(sb_error(), "bake_bad_quad.obj:5: cannot triangulate this 4-sided face"),
            "a quad whose both diagonals exist: error at file:line (got '%s')", sb_error());
    sb_mesh_free(&m);
}

/* the cow (triangles only) loads exactly as before: no polygon to split */
static void test_cow_unchanged(void)
{
    sb_mesh m;
    if (sb_mesh_load_obj("tools/examples/cow/cow.obj", &m)) { T_CHECK(0, "cow: %s", sb_error()); return; }
    T_CHECK(m.nv == 2903 && m.nt == 5804, "cow: 2903 vertices, 5804 triangles");
    sb_mesh_free(&m);
}

int main(void)
{
    (void)t_seed;
    test_shared_diagonal();
    test_quad_cube();
    test_two_pentagons();
    test_impossible();
    test_cow_unchanged();
    return T_END();
}
