/* test_physics_headturn.c -- head-turn acceptance (issue 9 item 2). On the cow
 * and on the beast the neck joint's local rotation is keyed to 90 degrees about
 * the neck bone's own axis (neck joint -> head joint), ramped in over 1 s and
 * held for 7 s with the asset's damping. The head's surface vertices must then
 * have turned 90 degrees about that axis through the neck joint: least-squares
 * angle and mean within 3 degrees (the worst vertex, where the head meets the
 * neck skin, is printed). Checked on the asset baked
 * without gravity: with gravity a turned head hangs off the axis and gravity
 * turns it further about the axis (a soft neck's physics, not the runtime's
 * error); those figures are printed beside it. */
#include "sn_test.h"
#include "reference/phys_util.h"
#include "reference/phys_pose.h"

#define TURN_DEG 90.0
#define GOAL_DEG 3.0
#define RAMP_S 1.0      /* smoothstep ramp of the rotation */
#define SETTLE_S 8.0    /* total simulated time */
#define NEAR_AXIS 0.25  /* per-vertex angles only at radii >= this x the largest */

typedef struct {
    unsigned n, nsmall;      /* head vertices in the per-vertex figures; left out (near the axis) */
    double ls, mean, worst;  /* least-squares, mean and worst (farthest from want) angle, degrees */
    double moving;           /* change of ls over the last 1 s */
    unsigned saturations;
} turn_t;

typedef struct {   /* one asset: joints, axis, head vertices */
    pu_rt r;
    int32_t jn;
    double neck[3], ax[3], *rest;
    unsigned char *mask;
    unsigned nhead;
} head_t;

static void v3(const sn_vec3 *v, double o[3]) { o[0] = pu_len(v->x); o[1] = pu_len(v->y); o[2] = pu_len(v->z); }
static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* distance from p to segment a-b */
static double seg_dist(const double *p, const double *a, const double *b) {
    double ab[3], ap[3], t, d[3];
    int k;
    for (k = 0; k < 3; k++) { ab[k] = b[k] - a[k]; ap[k] = p[k] - a[k]; }
    t = dot3(ab, ab) > 0 ? dot3(ap, ab) / dot3(ab, ab) : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    for (k = 0; k < 3; k++) d[k] = ap[k] - t * ab[k];
    return sqrt(dot3(d, d));
}

/* Rotation of the head vertices from rest to cur about the neck axis through
 * the neck joint, on the components perpendicular to the axis: least-squares
 * angle atan2(sum a.(p0 x p1), sum p0.p1); mean and worst of the per-vertex
 * angles away from the axis (near it a small displacement is a large angle). */
static turn_t measure(const head_t *h, const double *cur, double want) {
    turn_t r;
    double rmax = 0, sc = 0, ss = 0, sum = 0;
    unsigned i, pass, k, nS = h->r.info.surface_vertices;
    memset(&r, 0, sizeof r);
    r.worst = want;
    for (pass = 0; pass < 2; pass++)
        for (i = 0; i < nS; i++) {
            double p0[3], p1[3], c[3], a0, a1, r0, th;
            if (!h->mask[i]) continue;
            for (k = 0; k < 3; k++) { p0[k] = h->rest[3 * i + k] - h->neck[k]; p1[k] = cur[3 * i + k] - h->neck[k]; }
            a0 = dot3(p0, h->ax); a1 = dot3(p1, h->ax);
            for (k = 0; k < 3; k++) { p0[k] -= a0 * h->ax[k]; p1[k] -= a1 * h->ax[k]; }
            r0 = sqrt(dot3(p0, p0));
            if (pass == 0) { if (r0 > rmax) rmax = r0; continue; }
            c[0] = p0[1] * p1[2] - p0[2] * p1[1]; c[1] = p0[2] * p1[0] - p0[0] * p1[2]; c[2] = p0[0] * p1[1] - p0[1] * p1[0];
            ss += dot3(h->ax, c); sc += dot3(p0, p1);
            if (r0 < NEAR_AXIS * rmax) { r.nsmall++; continue; }
            th = atan2(dot3(h->ax, c), dot3(p0, p1)) * 180 / PU_PI;
            sum += th; r.n++;
            if (fabs(th - want) > fabs(r.worst - want)) r.worst = th;
        }
    r.ls = atan2(ss, sc) * 180 / PU_PI;
    r.mean = r.n ? sum / r.n : 0;
    return r;
}

/* Open name(+flavour suffix) from $BUILD/dir and find the head. 0 on success. */
static int head_open(head_t *h, const char *dir, const char *name) {
    char path[512];
    sn_vec3 jv;
    double head[3], len, *b0, *b1, d[3];
    int32_t jh;
    unsigned nJ, nS, i, j, k;
    memset(h, 0, sizeof *h);
    snprintf(path, sizeof path, "%s/%s/%s%s.blob", pu_build(), dir, name, PU_BLOB_SUFFIX);
    if (pu_rt_open(&h->r, path) != 0) { T_CHECK(0, "%s: cannot open %s (bake it first)", name, path); return -1; }
    nJ = h->r.info.joints; nS = h->r.info.surface_vertices;
    h->jn = sn_find_joint(h->r.blob, "neck"); jh = sn_find_joint(h->r.blob, "head");
    if (nJ > 256 || h->jn < 0 || jh < 0 || sn_joint_parent(h->r.blob, (uint32_t)jh) != h->jn) {
        T_CHECK(0, "%s: want joints neck and head (a child of neck), at most 256 joints", name);
        pu_rt_close(&h->r);
        return -1;
    }
    sn_joint_rest(h->r.blob, (uint32_t)h->jn, &jv); v3(&jv, h->neck);
    sn_joint_rest(h->r.blob, (uint32_t)jh, &jv); v3(&jv, head);
    for (k = 0; k < 3; k++) h->ax[k] = head[k] - h->neck[k];
    len = sqrt(dot3(h->ax, h->ax));
    for (k = 0; k < 3; k++) h->ax[k] /= len;
    /* head vertices: nearest bone is a child bone of the head joint, and
     * beyond the head joint along the neck axis */
    h->rest = malloc(3 * nS * sizeof *h->rest); h->mask = calloc(nS, 1);
    b0 = malloc(3 * nJ * sizeof *b0); b1 = malloc(3 * nJ * sizeof *b1);
    for (j = 0; j < nJ; j++) {
        int32_t p = sn_joint_parent(h->r.blob, j);
        sn_joint_rest(h->r.blob, j, &jv); v3(&jv, b1 + 3 * j);
        sn_joint_rest(h->r.blob, p >= 0 ? (uint32_t)p : j, &jv); v3(&jv, b0 + 3 * j);
    }
    pu_rt_surface(&h->r, h->rest);   /* a fresh instance is at rest */
    for (i = 0; i < nS; i++) {
        double best = HUGE_VAL;
        int bj = -1;
        for (j = 0; j < nJ; j++) {
            double dd;
            if (sn_joint_parent(h->r.blob, j) < 0) continue;
            dd = seg_dist(h->rest + 3 * i, b0 + 3 * j, b1 + 3 * j);
            if (dd < best) { best = dd; bj = (int)j; }
        }
        for (k = 0; k < 3; k++) d[k] = h->rest[3 * i + k] - h->neck[k];
        h->mask[i] = bj >= 0 && sn_joint_parent(h->r.blob, (uint32_t)bj) == jh && dot3(d, h->ax) >= len;
        h->nhead += h->mask[i];
    }
    free(b0); free(b1);
    T_CHECK(h->nhead >= 20, "%s: %u head surface vertices", name, h->nhead);
    return 0;
}

static void head_close(head_t *h) { free(h->rest); free(h->mask); pu_rt_close(&h->r); }

/* neck pose: deg about the neck axis */
static void neck_pose(const head_t *h, double deg, sn_xform *pose) {
    sn_quat local[256];
    unsigned j;
    for (j = 0; j < h->r.info.joints; j++) local[j] = pu_qident();
    local[h->jn] = pu_axis_angle(h->ax[0], h->ax[1], h->ax[2], deg);
    sn_pose_from_local(h->r.blob, local, NULL, pose);
}

/* ramp the neck to deg over RAMP_S, hold until SETTLE_S; measure */
static turn_t run(head_t *h, sn_mode mode, double deg) {
    sn_xform pose[256];
    sn_stats st;
    turn_t t, t1;
    unsigned k, nS = h->r.info.surface_vertices;
    double secs = pu_len(h->r.info.timestep);   /* Q16.16 seconds, as lengths */
    unsigned steps = (unsigned)ceil(SETTLE_S / secs), mark = steps - (unsigned)(1.0 / secs);
    double *cur = malloc(3 * nS * sizeof *cur);
    memset(&t1, 0, sizeof t1);
    sn_reset(h->r.inst);
    sn_set_mode(h->r.inst, mode);
    for (k = 0; k < steps; k++) {
        double s = k * secs / RAMP_S;
        s = s >= 1 ? 1 : s * s * (3 - 2 * s);
        neck_pose(h, deg * s, pose);
        sn_set_pose(h->r.inst, pose, h->r.info.joints);
        sn_step(h->r.inst);
        if (k + 1 == mark) { pu_rt_surface(&h->r, cur); t1 = measure(h, cur, deg); }
    }
    pu_rt_surface(&h->r, cur);
    t = measure(h, cur, deg);
    t.moving = fabs(t.ls - t1.ls);
    sn_get_stats(h->r.inst, &st);
    t.saturations = st.saturations;
    free(cur);
    return t;
}

/* a settled warped run: figure, and with check the goal checks */
static void judge(const char *name, const char *what, const head_t *h, const turn_t *t, int check) {
    T_FIGURE("%s %s%s: head (%u vertices) turned %.2f deg (least squares), mean %.2f, worst %.2f (%u near the axis not in mean/worst); last 1 s changed it %.3f deg; saturations %u",
             name, PU_FLAVOUR_NAME, what, h->nhead, t->ls, t->mean, t->worst, t->nsmall, t->moving, t->saturations);
    T_CHECK(t->saturations == 0, "%s%s: saturations %u", name, what, t->saturations);
    if (!check) return;
    T_CHECK(t->moving < 0.5, "%s%s: not settled: the angle moved %.3f deg over the last 1 s", name, what, t->moving);
    T_CHECK(fabs(t->ls - TURN_DEG) <= GOAL_DEG && fabs(t->mean - TURN_DEG) <= GOAL_DEG,
            "%s %s%s: head turned %.2f deg (least squares; mean %.2f) for %.0f keyed: goal within %.0f deg",
            name, PU_FLAVOUR_NAME, what, t->ls, t->mean, TURN_DEG, GOAL_DEG);
    /* the goal is the head's turn (least squares and mean over its surface);
     * single vertices where the head meets the neck twist with the neck skin
     * (the worst one is printed above) */
}

static void asset(const char *name) {
    head_t h;
    turn_t t;
    unsigned i, nS;
    double *rigid;
    char nm[64];
    sn_xform pose[256];
    if (head_open(&h, "examples", name) != 0) return;
    nS = h.r.info.surface_vertices;
    /* the measure itself: the neck transform applied rigidly gives 90 */
    rigid = malloc(3 * nS * sizeof *rigid);
    neck_pose(&h, TURN_DEG, pose);
    for (i = 0; i < nS; i++) {
        sn_vec3 p, q;
        const sn_xform *x = &pose[h.jn];
        p.x = pu_rlen(h.rest[3 * i]); p.y = pu_rlen(h.rest[3 * i + 1]); p.z = pu_rlen(h.rest[3 * i + 2]);
        q = sn_quat_rotate(x->rot, p);
        rigid[3 * i] = pu_len(q.x) + pu_len(x->pos.x);
        rigid[3 * i + 1] = pu_len(q.y) + pu_len(x->pos.y);
        rigid[3 * i + 2] = pu_len(q.z) + pu_len(x->pos.z);
    }
    t = measure(&h, rigid, TURN_DEG);
    T_CHECK(fabs(t.ls - TURN_DEG) < 0.05 && fabs(t.worst - TURN_DEG) < 0.2,
            "%s: rigidly turned head measures %.3f (worst %.3f) degrees", name, t.ls, t.worst);
    free(rigid);

    t = run(&h, SN_MODE_WARPED, TURN_DEG);
    judge(name, " with gravity", &h, &t, 0);
    t = run(&h, SN_MODE_WARPED, 0);
    T_FIGURE("%s %s, no turn (gravity sag alone): least squares %.2f, worst %.2f deg", name, PU_FLAVOUR_NAME, t.ls, t.worst);
    t = run(&h, SN_MODE_UNWARPED, TURN_DEG);
    T_FIGURE("%s %s UNWARPED (global linear FEM): %.2f deg (least squares), mean %.2f, worst %.2f", name, PU_FLAVOUR_NAME, t.ls, t.mean, t.worst);
    head_close(&h);

    snprintf(nm, sizeof nm, "%s_nograv", name);
    if (head_open(&h, "physics", nm) != 0) return;
    t = run(&h, SN_MODE_WARPED, TURN_DEG);
    judge(name, " without gravity", &h, &t, 1);
    head_close(&h);
}

int main(void) {
    printf("head turn: neck 90 deg about its own axis (%s runtime)\n", PU_FLAVOUR_NAME);
    asset("cow");
    asset("beast");
    return T_END();
}
