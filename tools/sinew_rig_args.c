/* sinew_rig_args.c -- sinew-rig's inputs: index and joint lists, control values, target OBJ vertices, pose strings. */
#include "sinew_rig_int.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int sr_parse_ints(const char *s, int *out, int max, const char *what)
{
    int n = 0;
    while (*s) {
        char *e;
        long v = strtol(s, &e, 10);
        if (e == s || v < 0 || v > 2000000000L || (*e && *e != ',')) { fprintf(stderr, PROG ": %s: '%s' is not a list of vertex indices\n", what, s); return -1; }
        if (n >= max) { fprintf(stderr, PROG ": %s: more than %d entries\n", what, max); return -1; }
        out[n++] = (int)v;
        s = *e ? e + 1 : e;
    }
    return n;
}

/* OBJ vertex positions: count must equal want; non-finite refused */
double *sr_read_obj_vertices(const char *path, int want)
{
    FILE *f = fopen(path, "r");
    char line[4096];
    int n = 0, ln = 0, cap = want > 0 ? want : 1;
    double *v;
    if (!f) { fprintf(stderr, PROG ": cannot open target '%s'\n", path); return NULL; }
    v = malloc(3 * (size_t)cap * sizeof *v);
    if (!v) { fclose(f); fprintf(stderr, PROG ": out of memory\n"); return NULL; }
    while (fgets(line, sizeof line, f)) {
        double x[3];
        char *p = line, *e;
        int k;
        ln++;
        while (*p == ' ' || *p == '\t') p++;
        if (p[0] != 'v' || (p[1] != ' ' && p[1] != '\t')) continue;
        p += 2;
        for (k = 0; k < 3; k++) {
            x[k] = strtod(p, &e);
            if (e == p) { fprintf(stderr, PROG ": %s:%d: a vertex needs three numbers\n", path, ln); fclose(f); free(v); return NULL; }
            if (!isfinite(x[k])) { fprintf(stderr, PROG ": %s:%d: non-finite vertex coordinate\n", path, ln); fclose(f); free(v); return NULL; }
            p = e;
        }
        if (n < cap) memcpy(v + 3 * n, x, sizeof x);
        n++;
    }
    fclose(f);
    if (n != want) {
        fprintf(stderr, PROG ": target '%s' has %d vertices, the character's mesh has %d (a target must have the same vertices, same order)\n", path, n, want);
        free(v);
        return NULL;
    }
    return v;
}

static int find_joint(const snref_model *m, const char *name)
{
    unsigned j;
    for (j = 0; j < m->nJ; j++) if (!strcmp(m->jname[j], name)) return (int)j;
    return -1;
}

int sr_parse_joints(const snref_model *m, const char *s, int *out, int max)
{
    int n = 0;
    char buf[256];
    while (s && *s) {
        const char *e = strchr(s, ',');
        size_t l = e ? (size_t)(e - s) : strlen(s);
        int j;
        if (l >= sizeof buf) l = sizeof buf - 1;
        memcpy(buf, s, l); buf[l] = 0;
        if ((j = find_joint(m, buf)) < 0) {
            unsigned k;
            fprintf(stderr, PROG ": --joints: unknown joint '%s'; joints:", buf);
            for (k = 0; k < m->nJ; k++) fprintf(stderr, " %s", m->jname[k]);
            fprintf(stderr, "\n");
            return -1;
        }
        if (n >= max) { fprintf(stderr, PROG ": --joints: at most %d\n", max); return -1; }
        out[n++] = j;
        s = e ? e + 1 : s + l;
    }
    return n;
}

int sr_set_controls(snref_state *s, const char *list)
{
    const char *p = list;
    while (p && *p) {
        const char *end = strchr(p, ','), *eq;
        char name[64], *e;
        double v;
        int c;
        if (!end) end = p + strlen(p);
        eq = memchr(p, '=', (size_t)(end - p));
        if (!eq || eq == p || (size_t)(eq - p) >= sizeof name) { fprintf(stderr, PROG ": --controls: '%.*s': want NAME=VALUE\n", (int)(end - p), p); return -1; }
        memcpy(name, p, (size_t)(eq - p)); name[eq - p] = 0;
        if ((c = snref_find_control(s->m, name)) < 0 || s->m->kkind[c] != SN_CTL_ABSTRACT) {
            fprintf(stderr, PROG ": --controls: '%s' is not an abstract control of the description\n", name);
            return -1;
        }
        v = strtod(eq + 1, &e);
        if (e != end || !isfinite(v) || fabs(v) >= 32768) { fprintf(stderr, PROG ": --controls: %s: not a number in (-32768, 32768)\n", name); return -1; }
        snref_set_control(s, (unsigned)c, v);
        p = *end ? end + 1 : end;
    }
    return 0;
}

/* local rotations -> "J:ax,ay,az,deg+..." (non-identity joints; "rest" if none) */
void sr_pose_string(const snref_model *m, const double *local, char *out, size_t n)
{
    size_t l = 0;
    unsigned j;
    out[0] = 0;
    for (j = 0; j < m->nJ; j++) {
        double r[3], th;
        sb_quat_rotvec(local + 4 * j, r);
        th = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        if (th < 1e-12) continue;
        l += (size_t)snprintf(out + l, l < n ? n - l : 0, "%s%s:%.9g,%.9g,%.9g,%.9g", l ? "+" : "", m->jname[j], r[0] / th, r[1] / th, r[2] / th, th * 180 / PI);
    }
    if (!l) snprintf(out, n, "rest");
}
