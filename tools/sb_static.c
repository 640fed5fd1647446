/* sb_static.c -- sinew-bake --static: static equilibrium of a baked character
 * (seed 003 eq. 10) at one pose, with its rig controls set, in double precision.
 *
 * The description is baked as a float64 blob in memory (the exact matrices the
 * fixed and float blobs quantize) and the double-precision reference model
 * (tools/ref/snref.c, an independent reader of the blob and re-implementation
 * of runtime/NUMERICS.md) solves f_el + m^g^ [- m^ R g^] + f_rig = 0 with the
 * skeleton held at the pose: one linear solve (banded LU) plus refinement.
 * This is the shape the runtime settles on when the pose and controls are
 * held (tests/test_rig_runtime.c checks it), so riggers can tune against it
 * without running a clip.
 *
 * Pose: "rest"; a clip sampled at a time, "walk.clip@0.5" (ports/common/CLIP.md,
 * parsed by ports/common/sn_clip.c and sampled here in double exactly as
 * sn_clip_sample does: shorter-arc slerp between keys, first/last key held,
 * loop wraps); or joint rotations "elbow:0,0,1,90+shoulder:1,0,0,20" (local
 * rotations about the joint's rest position relative to its parent, axis in
 * model axes, degrees, as a clip's rot line). A clip's control tracks set the
 * abstract controls at that time (--controls overrides them).
 */
#include "sb.h"
#include "snref.h"
#include "sb_static.h"
#include "sn_clip.h"
#include "raster.h"
#include "png.h"
#include "sn_format.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PROG "sinew-bake"
#define PI 3.14159265358979323846

/* ---------------- pose ---------------- */

/* sb_pose_from_local (sb_static.h) lives in the tool library (sb_crease.c),
 * shared with the crease slow motion */

static int find_joint(const snref_model *m, const char *name, size_t n) {
    unsigned j;
    for (j = 0; j < m->nJ; j++) if (strlen(m->jname[j]) == n && !strncmp(m->jname[j], name, n)) return (int)j;
    return -1;
}

static void list_joints(const snref_model *m) {
    unsigned j;
    fprintf(stderr, "  joints:");
    for (j = 0; j < m->nJ; j++) fprintf(stderr, " %s", m->jname[j]);
    fprintf(stderr, "\n");
}

static char *read_text(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    long len;
    char *t;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET)) { fclose(f); return NULL; }
    t = malloc((size_t)len + 1);
    if (!t || fread(t, 1, (size_t)len, f) != (size_t)len) { fclose(f); free(t); return NULL; }
    fclose(f);
    t[len] = 0;
    *n = (size_t)len;
    return t;
}

/* a whole string as a finite number */
static int parse_num(const char *s, size_t n, double *out) {
    char buf[64], *end;
    if (n == 0 || n >= sizeof buf) return -1;
    memcpy(buf, s, n); buf[n] = 0;
    *out = strtod(buf, &end);
    return (*end || end == buf || !(*out == *out) || fabs(*out) > 1e300) ? -1 : 0;
}

/* key rotation (Q16.16 axis and degrees) as a double quaternion */
static void key_quat(const sn_clip_key *k, double q[4]) {
    double ax[3];
    ax[0] = k->v[0] / 65536.0; ax[1] = k->v[1] / 65536.0; ax[2] = k->v[2] / 65536.0;
    snref_quat_axis_angle(ax, k->v[3] / 65536.0, q);
}

/* clip file at time t (seconds): the local rotations and root offset, as
 * sn_clip_sample at the Q16.16 time round(t * 65536) (wrapped when the clip
 * loops, clamped otherwise). 0, or 2 with a message. */
static int clip_pose(const snref_model *m, const char *path, double tsec, double *local, double root[3], char *what, size_t whatn,
                     double *cval, unsigned char *cset) {
    size_t n;
    char *text = read_text(path, &n), err[SN_CLIP_ERR_LEN];
    sn_clip *clip = malloc(sizeof *clip);
    int32_t t;
    unsigned c, k;
    if (!text) { fprintf(stderr, PROG ": --static: cannot read clip '%s'\n", path); free(clip); return 2; }
    if (!clip) { free(text); fprintf(stderr, PROG ": out of memory\n"); return 2; }
    if (sn_clip_parse(clip, text, n, err, sizeof err)) {
        fprintf(stderr, PROG ": --static: %s:%s\n", path, err);
        free(text); free(clip);
        return 2;
    }
    free(text);
    if (!(tsec >= 0) || tsec * 65536.0 > 2147483647.0) {
        fprintf(stderr, PROG ": --static: clip time %g s is not in [0, 32767] s\n", tsec);
        free(clip);
        return 2;
    }
    t = (int32_t)floor(tsec * 65536.0 + 0.5);
    if (t > clip->duration) {
        if (clip->loop) t %= clip->duration;
        else {
            fprintf(stderr, PROG ": --static: clip time %g s is after the end of '%s' (%g s, loop no)\n", tsec, path, clip->duration / 65536.0);
            free(clip);
            return 2;
        }
    }
    snprintf(what, whatn, "%s at %.4g s", path, t / 65536.0);
    for (c = 0; c < clip->n_channels; c++) {
        const sn_clip_channel *ch = &clip->chan[c];
        const sn_clip_key *kk = &clip->keys[ch->first], *a, *b;
        double u = 0;
        int j = 0;
        if (!ch->count) continue;
        if (ch->kind == SN_CLIP_CONTROL) { /* a control track: its value at t, as the player sets it */
            int kc = snref_find_control(m, ch->name);
            if (kc < 0 || m->kkind[kc] != SN_CTL_ABSTRACT) {
                fprintf(stderr, PROG ": --static: warning: %s: control '%s' is not an abstract control of the description: its keys are ignored\n",
                        path, ch->name);
                continue;
            }
            cval[kc] = sn_clip_control_at(clip, c, t) / 65536.0;
            cset[kc] = 1;
            continue;
        }
        if (ch->kind != SN_CLIP_MOVE && (j = find_joint(m, ch->name, strlen(ch->name))) < 0) {
            fprintf(stderr, PROG ": --static: clip joint '%s' is not in the skeleton of the description\n", ch->name);
            list_joints(m);
            free(clip);
            return 2;
        }
        /* keys a, b around t and b's weight (Q30 as the player, then double) */
        if (t <= kk[0].t) a = b = &kk[0];
        else if (t >= kk[ch->count - 1].t) a = b = &kk[ch->count - 1];
        else {
            for (k = 0; k + 2 < ch->count && kk[k + 1].t <= t; k++) {}
            a = &kk[k]; b = &kk[k + 1];
            u = (double)(((int64_t)(t - a->t) << 30) / (b->t - a->t)) / 1073741824.0;
        }
        if (ch->kind == SN_CLIP_MOVE) {
            for (k = 0; k < 3; k++) root[k] = (a->v[k] + u * (b->v[k] - a->v[k])) / 65536.0;
        } else {
            double qa[4], qb[4];
            key_quat(a, qa);
            if (a == b || u == 0) memcpy(local + 4 * j, qa, sizeof qa);
            else { key_quat(b, qb); snref_quat_slerp(qa, qb, u, local + 4 * j); }
        }
    }
    free(clip);
    return 0;
}

/* "JOINT:AX,AY,AZ,DEG[+JOINT:...]" */
static int joint_pose(const snref_model *m, const char *s, double *local) {
    while (*s) {
        const char *colon = strchr(s, ':'), *end = strchr(s, '+'), *p;
        double v[4];
        int j, k;
        if (!end) end = s + strlen(s);
        if (!colon || colon > end) {
            fprintf(stderr, PROG ": --static: '%.*s': want JOINT:AX,AY,AZ,DEG (or rest, or FILE.clip@SECONDS)\n", (int)(end - s), s);
            return 2;
        }
        if ((j = find_joint(m, s, (size_t)(colon - s))) < 0) {
            fprintf(stderr, PROG ": --static: unknown joint '%.*s'\n", (int)(colon - s), s);
            list_joints(m);
            return 2;
        }
        for (k = 0, p = colon + 1; k < 4; k++) {
            const char *q = p;
            while (q < end && *q != ',') q++;
            if ((k < 3 && q >= end) || (k == 3 && q != end) || parse_num(p, (size_t)(q - p), &v[k])) {
                fprintf(stderr, PROG ": --static: '%.*s': want JOINT:AX,AY,AZ,DEG with four numbers\n", (int)(end - s), s);
                return 2;
            }
            p = q + 1;
        }
        if (v[0] == 0 && v[1] == 0 && v[2] == 0) { fprintf(stderr, PROG ": --static: joint '%s': zero axis\n", m->jname[j]); return 2; }
        snref_quat_axis_angle(v, v[3], local + 4 * j);
        s = *end ? end + 1 : end;
    }
    return 0;
}


static int sb_static_pose_(snref_state *s, const snref_model *m, const char *spec, double *local, double root[3], char *what, size_t whatn) {
    unsigned j, c;
    for (j = 0; j < m->nJ; j++) local[4 * j + 3] = 1;
    if (!strcmp(spec, "rest")) snprintf(what, whatn, "rest");
    else {
        const char *at = strrchr(spec, '@');
        size_t n = strlen(spec);
        int is_clip = (at && at - spec >= 5 && !strncmp(at - 5, ".clip", 5)) || (n >= 5 && !strcmp(spec + n - 5, ".clip"));
        if (is_clip) {
            char path[1024];
            double t = 0;
            size_t pl = at && !(n >= 5 && !strcmp(spec + n - 5, ".clip")) ? (size_t)(at - spec) : n;
            if (pl >= sizeof path) { fprintf(stderr, PROG ": --static: clip path too long\n"); return 2; }
            memcpy(path, spec, pl); path[pl] = 0;
            if (pl < n && parse_num(spec + pl + 1, n - pl - 1, &t)) {
                fprintf(stderr, PROG ": --static: '%s': the time after @ is not a number of seconds\n", spec + pl + 1);
                return 2;
            }
            {
                double *cval = calloc(m->nK + 1, sizeof *cval);
                unsigned char *cset = calloc(m->nK + 1, 1);
                int bad = !cval || !cset || clip_pose(m, path, t, local, root, what, whatn, cval, cset);
                for (c = 0; !bad && c < m->nK; c++) /* the clip's tracks; --controls below overrides them */
                    if (cset[c]) snref_set_control(s, c, cval[c]);
                free(cval);
                free(cset);
                if (bad) return 2;
            }
        } else {
            if (joint_pose(m, spec, local)) return 2;
            snprintf(what, whatn, "%s", spec);
        }
    }
    return 0;
}

/* POSE (as --static takes it) -> per-joint transforms (nJ) and local rotations
 * (nJ x 4, x y z w; may be NULL); a clip's control tracks set s's abstract
 * controls. 0, or 2 with a message (sb_static.h). */
int sb_static_pose(snref_state *s, const char *spec, snref_xform *pose, double *local_out, char *what, size_t whatn) {
    const snref_model *m = s->m;
    double *local = calloc(4 * (size_t)m->nJ + 4, sizeof *local), root[3] = { 0, 0, 0 };
    int rc;
    if (!local) { fprintf(stderr, PROG ": out of memory\n"); return 2; }
    rc = sb_static_pose_(s, m, spec, local, root, what, whatn);
    if (!rc) {
        sb_pose_from_local(m, local, root, pose);
        if (local_out) memcpy(local_out, local, 4 * (size_t)m->nJ * sizeof *local);
    }
    free(local);
    return rc;
}


/* ---------------- controls ---------------- */

static void list_controls(const snref_model *m) {
    unsigned c;
    if (!m->nK) { fprintf(stderr, "  (the description declares no controls)\n"); return; }
    fprintf(stderr, "  controls:");
    for (c = 0; c < m->nK; c++) fprintf(stderr, " %s%s", m->kname[c], m->kkind[c] == SN_CTL_ANGLE ? " (pose)" : "");
    fprintf(stderr, "\n");
}

/* "name=value,..." -> abstract controls of s. 0, or 2 with a message. */
static int set_controls(snref_state *s, const char *list) {
    const snref_model *m = s->m;
    const char *p = list;
    while (p && *p) {
        const char *end = strchr(p, ','), *eq;
        char name[64];
        double v;
        int c;
        if (!end) end = p + strlen(p);
        eq = memchr(p, '=', (size_t)(end - p));
        if (!eq || eq == p || (size_t)(eq - p) >= sizeof name) {
            fprintf(stderr, PROG ": --controls: '%.*s': want NAME=VALUE\n", (int)(end - p), p);
            return 2;
        }
        memcpy(name, p, (size_t)(eq - p)); name[eq - p] = 0;
        if ((c = snref_find_control(m, name)) < 0) {
            fprintf(stderr, PROG ": --controls: unknown control '%s'\n", name);
            list_controls(m);
            return 2;
        }
        if (m->kkind[c] != SN_CTL_ABSTRACT) {
            fprintf(stderr, PROG ": --controls: '%s' is a pose control: it follows joint '%s' (pose the joint instead)\n", name, m->jname[m->kjoint[c]]);
            return 2;
        }
        if (parse_num(eq + 1, (size_t)(end - eq - 1), &v) || fabs(v) >= 32768.0) {
            fprintf(stderr, PROG ": --controls: %s: '%.*s' is not a number in (-32768, 32768)\n", name, (int)(end - eq - 1), eq + 1);
            return 2;
        }
        snref_set_control(s, (unsigned)c, v);
        p = *end ? end + 1 : end;
    }
    return 0;
}

/* ---------------- output ---------------- */

static int write_obj(const char *path, const snref_model *m, const double *surf, const double off[3], const char *head) {
    size_t cap = 160 + strlen(head) + (size_t)m->nS * 64 + (size_t)m->nT * 40, n = 0;
    char *buf = malloc(cap), err[300];
    unsigned i;
    int rc;
    if (!buf) return -1;
    n += (size_t)snprintf(buf + n, cap - n, "%s", head);
    for (i = 0; i < m->nS; i++)
        n += (size_t)snprintf(buf + n, cap - n, "v %.9g %.9g %.9g\n", surf[3 * i] + off[0], surf[3 * i + 1] + off[1], surf[3 * i + 2] + off[2]);
    for (i = 0; i < m->nT; i++)
        n += (size_t)snprintf(buf + n, cap - n, "f %u %u %u\n", m->tris[3 * i] + 1, m->tris[3 * i + 1] + 1, m->tris[3 * i + 2] + 1);
    rc = write_file_atomic(path, buf, n, err, sizeof err);
    if (rc) fprintf(stderr, PROG ": %s\n", err);
    free(buf);
    return rc;
}


/* one panel: surf (mesh units), coloured by |surf - base| / scale when base */
static int panel(rs_image *out, const snref_model *m, const double *surf, const double *base, double scale,
                 const float lo[3], const float hi[3], double az, double el, const char *l1, const char *l2) {
    return rs_heat_panel(out, surf, base, scale, m->nS, m->tris, m->nT, lo, hi, az, el, l1, l2);
}

static int write_png(const char *path, const snref_model *m, const double *a, const double *b, double scale,
                     double az, double el, const char *la, const char *lb, const char *sub) {
    enum { PW = 640, PH = 480 };
    rs_image img, pane;
    float lo[3] = { 1e30f, 1e30f, 1e30f }, hi[3] = { -1e30f, -1e30f, -1e30f };
    unsigned i, k;
    char err[300];
    uint8_t line[3] = { 90, 90, 90 };
    int rc = -1;
    for (i = 0; i < m->nS; i++)
        for (k = 0; k < 3; k++) {
            float x = (float)a[3 * i + k], y = (float)b[3 * i + k];
            if (x < lo[k]) lo[k] = x;
            if (x > hi[k]) hi[k] = x;
            if (y < lo[k]) lo[k] = y;
            if (y > hi[k]) hi[k] = y;
        }
    if (rs_image_alloc(&img, 2 * PW, PH)) return -1;
    if (rs_image_alloc(&pane, PW, PH)) { rs_image_free(&img); return -1; }
    if (!panel(&pane, m, a, NULL, 0, lo, hi, az, el, la, NULL)) {
        rs_blit(&img, 0, 0, &pane);
        if (!panel(&pane, m, b, a, scale, lo, hi, az, el, lb, sub)) {
            rs_blit(&img, PW, 0, &pane);
            rs_fill(&img, PW - 1, 0, 2, PH, line);
            rc = png_write(path, img.rgb, img.w, img.h, err, sizeof err);
            if (rc) fprintf(stderr, PROG ": %s\n", err);
        }
    }
    rs_image_free(&pane); rs_image_free(&img);
    return rc;
}

/* ---------------- the command ---------------- */

static int solve(snref_state *s, const char *what, int quiet) {
    double t0 = sb_now(), res, *lat = malloc(3 * (size_t)s->m->nV * sizeof *lat);
    unsigned i;
    if (!quiet) { printf("static: solving %s (%u unknowns)...", what, 3 * s->m->nF); fflush(stdout); }
    /* start from the skinned shape: the relative residual is measured against the
     * start's, so a start already at equilibrium (rigs on = rigs off when every rig
     * is at tau 0) could not converge by that measure */
    if (!lat) { fprintf(stderr, PROG ": out of memory\n"); return 1; }
    snref_get_skinned(s, lat);
    for (i = 0; i < 3 * s->m->nF; i++) s->p[i] = lat[i] / s->m->unit;
    free(lat);
    res = snref_static(s, 0);
    if (!quiet) printf(" %.2f s, relative residual %.1e\n", sb_now() - t0, res);
    if (!(res <= 1e-6)) {
        fprintf(stderr, PROG ": --static: the solve did not converge (relative residual %.3g)\n", res);
        return 1;
    }
    return 0;
}

static double maxdist(const double *a, const double *b, unsigned n, unsigned *at) {
    double mx = 0;
    unsigned i;
    for (i = 0; i < n; i++) {
        double d = sqrt((a[3 * i] - b[3 * i]) * (a[3 * i] - b[3 * i]) + (a[3 * i + 1] - b[3 * i + 1]) * (a[3 * i + 1] - b[3 * i + 1]) +
                        (a[3 * i + 2] - b[3 * i + 2]) * (a[3 * i + 2] - b[3 * i + 2]));
        if (d > mx) { mx = d; if (at) *at = i; }
    }
    return mx;
}


/* default output name: the description's stem + suffix, in the current directory */
static void default_name(const char *desc, const char *suffix, char *out, size_t n) {
    const char *b = strrchr(desc, '/'), *dot;
    size_t len;
    b = b ? b + 1 : desc;
    dot = strrchr(b, '.');
    len = dot && dot != b ? (size_t)(dot - b) : strlen(b);
    snprintf(out, n, "%.*s%s", (int)len, b, suffix);
}

int sb_static_run(const char *desc, const sb_static_opts *opt) {
    sb_model o;
    sb_blob b;
    snref_model m;
    snref_state s;
    snref_xform *pose = NULL;
    double *local = NULL, off[3], *s_on = NULL, *s_off = NULL, *skin = NULL, t0;
    char err[300], posewhat[1200], objpath[1024], pngpath[1100], ctlline[2048], *head = NULL;
    unsigned j, c;
    int rc = 1, q = opt->quiet;
    size_t hl;
    memset(&o, 0, sizeof o); memset(&b, 0, sizeof b); memset(&m, 0, sizeof m); memset(&s, 0, sizeof s);
    /* outputs: checked before any work */
    if (opt->obj) snprintf(objpath, sizeof objpath, "%s", opt->obj);
    else default_name(desc, "_static.obj", objpath, sizeof objpath);
    if (opt->png) snprintf(pngpath, sizeof pngpath, "%s", opt->png);
    else {
        size_t n = strlen(objpath);
        if (n > 4 && !strcmp(objpath + n - 4, ".obj")) snprintf(pngpath, sizeof pngpath, "%.*s.png", (int)(n - 4), objpath);
        else snprintf(pngpath, sizeof pngpath, "%s.png", objpath);
    }
    t0 = sb_now();
    if (!q) printf("static: baking %s (float64)\n", desc);
    if (sb_bake_file(desc, SB_DOUBLE, 1, &o, &b)) { fprintf(stderr, PROG ": error: %s\n", sb_error()); return 1; }
    if (snref_load(&m, b.bytes, b.size, err, sizeof err)) {
        fprintf(stderr, PROG ": --static: reading the baked blob: %s\n", err);
        goto done;
    }
    /* model space (blob) -> the description's coordinates: the lattice's rest offset */
    for (c = 0; c < 3; c++) off[c] = o.x[c] - m.rest[c] * m.unit;
    if (!q) printf("static: baked in %.2f s: %u lattice vertices (%u free), %u cells, %u controls, %u rigs\n",
                   sb_now() - t0, m.nV, m.nF, m.nC, m.nK, m.nR);
    if (snref_init(&s, &m)) { fprintf(stderr, PROG ": out of memory\n"); goto done; }
    /* pose */
    local = calloc(4 * (size_t)m.nJ, sizeof *local);
    pose = calloc(m.nJ, sizeof *pose);
    if (!local || !pose) { fprintf(stderr, PROG ": out of memory\n"); goto done; }
    for (j = 0; j < m.nJ; j++) local[4 * j + 3] = 1;
    rc = 2;
    if (sb_static_pose(&s, opt->pose, pose, local, posewhat, sizeof posewhat)) goto done;
    if (opt->controls && set_controls(&s, opt->controls)) goto done;
    snref_set_pose(&s, pose);
    /* the control values in effect */
    ctlline[0] = 0;
    for (c = 0, hl = 0; c < m.nK && hl + 80 < sizeof ctlline; c++)
        hl += (size_t)snprintf(ctlline + hl, sizeof ctlline - hl, "%s%s=%.4g%s", c ? ", " : "", m.kname[c], snref_get_control(&s, c),
                               m.kkind[c] == SN_CTL_ANGLE ? " (pose)" : "");
    if (!q) {
        printf("static: pose %s\n", posewhat);
        if (m.nK) printf("static: controls %s\n", ctlline);
    }
    rc = 1;
    s_on = malloc(3 * (size_t)m.nS * sizeof *s_on); s_off = malloc(3 * (size_t)m.nS * sizeof *s_off);
    skin = malloc(3 * (size_t)(m.nV > m.nS ? m.nV : m.nS) * sizeof *skin);
    if (!s_on || !s_off || !skin) { fprintf(stderr, PROG ": out of memory\n"); goto done; }
    {   /* skinned surface (rigidly framed lattice) */
        double *lat = malloc(3 * (size_t)m.nV * sizeof *lat);
        if (!lat) { fprintf(stderr, PROG ": out of memory\n"); goto done; }
        snref_get_skinned(&s, lat);
        snref_surface_from_lattice(&m, lat, skin);
        free(lat);
    }
    if (m.nR) {
        s.rig_scale = 0;
        if (solve(&s, "rigs off", q)) goto done;
        snref_get_surface(&s, s_off);
        s.rig_scale = 1;
    } else memcpy(s_off, skin, 3 * (size_t)m.nS * sizeof *skin);
    if (solve(&s, m.nR ? "rigs on" : "static equilibrium", q)) goto done;
    snref_get_surface(&s, s_on);
    {
        unsigned at = 0;
        double cellmu = m.cell * m.unit, d = maxdist(s_on, s_off, m.nS, &at), v0, v1;
        v0 = snref_surface_volume(&m, s_off); v1 = snref_surface_volume(&m, s_on);
        if (!q) {
            if (m.nR) printf("static: rigs move the surface by up to %.4g mesh units (%.3g cells) at surface vertex %u; volume %+.2f%% of the rigs-off shape\n",
                             d, d / cellmu, at, 100 * (v1 / v0 - 1));
            else printf("static: largest distance from the skinned shape %.4g mesh units (%.3g cells)\n", d, d / cellmu);
        }
        hl = strlen(desc) + strlen(posewhat) + strlen(ctlline) + 200;
        head = malloc(hl);
        if (!head) goto done;
        snprintf(head, hl, "# sinew-bake --static: static equilibrium (seed 003 eq. 10) of %s\n# pose %s\n# controls %s\n",
                 desc, posewhat, m.nK ? ctlline : "(none)");
        if (write_obj(objpath, &m, s_on, off, head)) goto done;
        {
            char sub[300];
            snprintf(sub, sizeof sub, "red: %.3g mesh units from the %s shape", d, m.nR ? "rigs-off" : "skinned");
            if (write_png(pngpath, &m, s_off, s_on, d, opt->az, opt->el, m.nR ? "rigs off" : "skinned",
                          m.nR ? "rigs on" : "static", sub)) {
                remove(objpath);   /* all or nothing */
                goto done;
            }
        }
    }
    if (!q) printf("static: wrote %s and %s (%.2f s in all)\n", objpath, pngpath, sb_now() - t0);
    rc = 0;
done:
    free(head); free(s_on); free(s_off); free(skin); free(local); free(pose);
    if (s.m) snref_release(&s);
    snref_free(&m);
    sb_blob_free(&b);
    sb_rig_free(&o);
    sb_model_free(&o);
    return rc;
}
