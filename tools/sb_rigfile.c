/* sb_rigfile.c -- rig files: a fitted generalized force field (seed 003
 * §4.3, eq. 13: Q(gamma) = gamma eta) on a character's lattice, as text,
 * keyed by the rest positions of the lattice vertices so that it survives
 * re-baking (a changed bone radius, pins or materials change which vertices
 * are free or their numbering, not where the grid's vertices are).
 * Format: tools/DESCRIPTION.md "Rig files".
 *
 *   sinew-rig 1        (2: several fits follow, one per lattice)
 *   # free comment lines
 *   mesh NV CRC        identity: the mesh's vertex count and the CRC-32 (hex)
 *                      of its vertex coordinates as little-endian IEEE doubles
 *   cell C             lattice cell edge (mesh units) of the keys
 *   origin X Y Z       the lattice grid's corner (mesh units)
 *   forces N
 *   f X Y Z QX QY QZ   N lines: a lattice vertex's rest position (mesh units,
 *                      the mesh's axes) and its force at eta = 1 (newtons,
 *                      rest model axes)
 *   end
 *   cell C2 ... end    'sinew-rig 2' only: the fit on another lattice (level 1
 *                      of 'levels 2': cell C / 2), a distinct cell each
 */
#include "sb.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

uint32_t sb_mesh_crc(const sb_mesh *m)
{
    size_t n = 24 * (size_t)m->nv, i;
    unsigned char *b = sb_alloc(n ? n : 1);
    uint32_t c;
    for (i = 0; i < 3 * (size_t)m->nv; i++) {
        uint64_t u;
        int k;
        memcpy(&u, &m->v[i], 8);
        for (k = 0; k < 8; k++) b[8 * i + (size_t)k] = (unsigned char)(u >> (8 * k));
    }
    c = sb_crc32(b, n);
    free(b);
    return c;
}

void sb_rigfile_free(sb_rigfile *rf)
{
    int i;
    for (i = 0; i < SB_RIGFILE_FITS; i++) { free(rf->fit[i].x); free(rf->fit[i].Q); }
    memset(rf, 0, sizeof *rf);
}

const sb_rigfit *sb_rigfile_pick(const sb_rigfile *rf, double cell)
{
    int i;
    for (i = 0; i < rf->nfit; i++) if (fabs(rf->fit[i].cell - cell) <= 1e-9 * cell) return &rf->fit[i];
    return NULL;
}

/* next non-empty, non-comment line: its tokens (in place) */
static int next_line(char **p, int *line, char **tok, int maxtok)
{
    while (**p) {
        char *s = *p, *e = strchr(s, '\n');
        int nt = 0;
        if (e) { *e = 0; *p = e + 1; } else *p = s + strlen(s);
        (*line)++;
        { char *h = strchr(s, '#'); if (h) *h = 0; }
        while (*s) {
            while (*s == ' ' || *s == '\t' || *s == '\r') *s++ = 0;
            if (!*s) break;
            if (nt < maxtok) tok[nt] = s;
            nt++;
            while (*s && *s != ' ' && *s != '\t' && *s != '\r') s++;
        }
        if (nt) return nt;
    }
    return 0;
}

static int fnum(const char *s, double *v)
{
    char *e;
    *v = strtod(s, &e);
    return (*e || e == s || !isfinite(*v)) ? -1 : 0;
}

int sb_rigfile_read(const char *path, sb_rigfile *rf)
{
    FILE *f = fopen(path, "rb");
    long len;
    char *text, *p, *tok[8];
    int line = 0, nt, i, k, version;
    double v;
    memset(rf, 0, sizeof *rf);
    if (!f) return sb_fail("cannot open rig file '%s'", path);
    if (fseek(f, 0, SEEK_END) || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET)) { fclose(f); return sb_fail("cannot read rig file '%s'", path); }
    text = sb_alloc((size_t)len + 1);
    if (fread(text, 1, (size_t)len, f) != (size_t)len) { fclose(f); free(text); return sb_fail("cannot read rig file '%s'", path); }
    fclose(f);
    p = text;
    /* the message first: it reads the tokens (in text) and the fit's counts */
#define BAD(...) do { sb_fail(__VA_ARGS__); free(text); sb_rigfile_free(rf); return -1; } while (0)
    nt = next_line(&p, &line, tok, 8);
    if (nt != 2 || strcmp(tok[0], "sinew-rig") || (strcmp(tok[1], "1") && strcmp(tok[1], "2")))
        BAD("%s:%d: not a rig file (want the first line 'sinew-rig 1', or 'sinew-rig 2' for several fits)", path, line);
    version = tok[1][0] - '0';
    nt = next_line(&p, &line, tok, 8);
    {
        char *e;
        unsigned long c;
        if (nt != 3 || strcmp(tok[0], "mesh") || fnum(tok[1], &v) || v < 1 || v != floor(v) || v > 2e9) BAD("%s:%d: want 'mesh VERTICES CRC32'", path, line);
        rf->mesh_nv = (int)v;
        c = strtoul(tok[2], &e, 16);
        if (*e || e == tok[2] || c > 0xffffffffUL) BAD("%s:%d: want 'mesh VERTICES CRC32' (CRC in hex)", path, line);
        rf->mesh_crc = (uint32_t)c;
    }
    nt = next_line(&p, &line, tok, 8);
    do {   /* one fit: cell, origin, forces, f lines, end */
        sb_rigfit *ft = &rf->fit[rf->nfit];
        const sb_rigfit *dup;
        if (nt != 2 || strcmp(tok[0], "cell") || fnum(tok[1], &ft->cell) || !(ft->cell > 0)) BAD("%s:%d: want 'cell SIZE' (positive)", path, line);
        ft->line = line;
        if ((dup = sb_rigfile_pick(rf, ft->cell)) != NULL) BAD("%s:%d: a second fit for cell %.9g (the first at line %d)", path, line, ft->cell, dup->line);
        rf->nfit++;
        nt = next_line(&p, &line, tok, 8);
        if (nt != 4 || strcmp(tok[0], "origin") || fnum(tok[1], &ft->origin[0]) || fnum(tok[2], &ft->origin[1]) || fnum(tok[3], &ft->origin[2]))
            BAD("%s:%d: want 'origin X Y Z'", path, line);
        nt = next_line(&p, &line, tok, 8);
        if (nt != 2 || strcmp(tok[0], "forces") || fnum(tok[1], &v) || v < 0 || v != floor(v) || v > 1e8) BAD("%s:%d: want 'forces COUNT'", path, line);
        ft->n = (int)v;
        ft->x = sb_alloc(sizeof(double) * 3 * (size_t)(ft->n ? ft->n : 1));
        ft->Q = sb_alloc(sizeof(double) * 3 * (size_t)(ft->n ? ft->n : 1));
        for (i = 0; i < ft->n; i++) {
            nt = next_line(&p, &line, tok, 8);
            if (nt == 0 || (nt == 1 && !strcmp(tok[0], "end"))) BAD("%s:%d: %d force lines, the header says %d", path, line, i, ft->n);
            if (nt != 7 || strcmp(tok[0], "f")) BAD("%s:%d: want 'f X Y Z QX QY QZ'", path, line);
            for (k = 0; k < 3; k++)
                if (fnum(tok[1 + k], &ft->x[3 * i + k]) || fnum(tok[4 + k], &ft->Q[3 * i + k]))
                    BAD("%s:%d: '%s %s %s %s %s %s' are not six finite numbers", path, line, tok[1], tok[2], tok[3], tok[4], tok[5], tok[6]);
        }
        nt = next_line(&p, &line, tok, 8);
        if (nt != 1 || strcmp(tok[0], "end")) BAD("%s:%d: want 'end' after the %d force lines", path, line, ft->n);
        nt = next_line(&p, &line, tok, 8);
        if (nt && version == 1) BAD("%s:%d: text after 'end' (a file with several fits starts 'sinew-rig 2')", path, line);
        if (nt && rf->nfit == SB_RIGFILE_FITS) BAD("%s:%d: more than %d fits", path, line, SB_RIGFILE_FITS);
    } while (nt);
#undef BAD
    free(text);
    return 0;
}

/* one fit's forces: the rows above 1e-12 of the largest (cnt: how many) */
static int keep_row(const double *q, double qmax) { return fabs(q[0]) + fabs(q[1]) + fabs(q[2]) > 1e-12 * qmax && qmax > 0; }

int sb_rigfile_write_fits(const char *path, int nfit, const sb_model *const *o, const sb_mesh *m, const double *const *Q, const char *comment)
{
    size_t cap = 512 + (comment ? 2 * strlen(comment) : 0), n = 0;
    char *t;
    int i, j, rc, cnt[SB_RIGFILE_FITS];
    double qmax[SB_RIGFILE_FITS];
    if (nfit < 1 || nfit > SB_RIGFILE_FITS) return sb_fail("rig file '%s': %d fits (1..%d)", path, nfit, SB_RIGFILE_FITS);
    for (j = 0; j < nfit; j++) {
        qmax[j] = 0; cnt[j] = 0;
        for (i = 0; i < o[j]->nf; i++) qmax[j] = fmax(qmax[j], fabs(Q[j][3 * i]) + fabs(Q[j][3 * i + 1]) + fabs(Q[j][3 * i + 2]));
        for (i = 0; i < o[j]->nf; i++) cnt[j] += keep_row(Q[j] + 3 * i, qmax[j]);
        cap += 256 + (size_t)cnt[j] * 140;
    }
    t = sb_alloc(cap);
    n += (size_t)snprintf(t + n, cap - n, "sinew-rig %d\n", nfit > 1 ? 2 : 1);
    if (comment) {   /* every line of the comment as '# ...' */
        const char *c = comment;
        while (*c) {
            const char *e = strchr(c, '\n');
            size_t l = e ? (size_t)(e - c) : strlen(c);
            n += (size_t)snprintf(t + n, cap - n, "# %.*s\n", (int)l, c);
            c += l + (e ? 1 : 0);
        }
    }
    n += (size_t)snprintf(t + n, cap - n, "mesh %d %08lx\n", m->nv, (unsigned long)sb_mesh_crc(m));
    for (j = 0; j < nfit; j++) {
        n += (size_t)snprintf(t + n, cap - n, "cell %.17g\norigin %.17g %.17g %.17g\nforces %d\n", o[j]->c, o[j]->gorg[0], o[j]->gorg[1], o[j]->gorg[2], cnt[j]);
        for (i = 0; i < o[j]->nf; i++) {
            const double *q = Q[j] + 3 * i, *x = o[j]->x + 3 * i;
            if (!keep_row(q, qmax[j])) continue;
            n += (size_t)snprintf(t + n, cap - n, "f %.10g %.10g %.10g %.12g %.12g %.12g\n", x[0], x[1], x[2], q[0], q[1], q[2]);
        }
        n += (size_t)snprintf(t + n, cap - n, "end\n");
    }
    rc = sb_write_file(path, (const unsigned char *)t, n);
    free(t);
    return rc;
}

int sb_rigfile_write(const char *path, const sb_model *o, const sb_mesh *m, const double *Q, const char *comment)
{
    return sb_rigfile_write_fits(path, 1, &o, m, &Q, comment);
}

int sb_rigfile_apply(const sb_rigfile *rfile, const char *path, const sb_model *o, const sb_mesh *m, int level, int *vert, double *Q, int *nout, int *ndrop)
{
    uint32_t crc = sb_mesh_crc(m);
    int i, k, n = 0, drop = 0;
    double tol = 1e-6 * o->c;
    const sb_rigfit *rf = sb_rigfile_pick(rfile, o->c);
    if (rfile->mesh_nv != m->nv || rfile->mesh_crc != crc)
        return sb_fail("rig file '%s' was fitted to another character: its mesh has %d vertices (CRC %08lx), this description's mesh has %d (CRC %08lx)",
                       path, rfile->mesh_nv, (unsigned long)rfile->mesh_crc, m->nv, (unsigned long)crc);
    if (!rf) {
        char cells[256];
        size_t l = 0;
        for (i = 0; i < rfile->nfit; i++)
            l += (size_t)snprintf(cells + l, sizeof cells - l, "%s%.9g (line %d)", i ? ", " : "", rfile->fit[i].cell, rfile->fit[i].line);
        if (level > 0)
            return sb_fail("rig file '%s' has fits for lattice cell %s, none for level %d of 'levels 2' (cell %.9g): refit it on the description "
                           "with 'levels 2' (sinew-rig fit-surface, export or retarget: they write a fit per level)",
                           path, cells, level, o->c);
        return sb_fail("rig file '%s' has fits for lattice cell %s, this description's lattice has cell %.9g: refit it", path, cells, o->c);
    }
    for (i = 0; i < o->nf; i++) for (k = 0; k < 3; k++) Q[3 * i + k] = 0;
    for (i = 0; i < rf->n; i++) {
        int g[3], gi, v;
        for (k = 0; k < 3; k++) {
            double u = (rf->x[3 * i + k] - o->gorg[k]) / o->c;
            g[k] = (int)floor(u + 0.5);
            if (fabs(u - g[k]) * o->c > tol)
                return sb_fail("rig file '%s': force %d at (%g, %g, %g) is not on this lattice's grid (origin %g %g %g, cell %g; the file's origin %g %g %g): refit it",
                               path, i + 1, rf->x[3 * i], rf->x[3 * i + 1], rf->x[3 * i + 2], o->gorg[0], o->gorg[1], o->gorg[2], o->c,
                               rf->origin[0], rf->origin[1], rf->origin[2]);
        }
        if (g[0] < 0 || g[1] < 0 || g[2] < 0 || g[0] >= o->gn[0] || g[1] >= o->gn[1] || g[2] >= o->gn[2]) { drop++; continue; }
        gi = g[0] + o->gn[0] * (g[1] + o->gn[1] * g[2]);
        v = o->gvert[gi];
        if (v < 0 || v >= o->nf) { drop++; continue; }   /* not in the lattice, or carried by a bone */
        for (k = 0; k < 3; k++) Q[3 * v + k] += rf->Q[3 * i + k];
    }
    for (i = 0; i < o->nf; i++)
        if (Q[3 * i] != 0 || Q[3 * i + 1] != 0 || Q[3 * i + 2] != 0) {
            vert[n] = i;
            for (k = 0; k < 3; k++) Q[3 * n + k] = Q[3 * i + k];
            n++;
        }
    *nout = n;
    *ndrop = drop;
    if (!n) return sb_fail("rig file '%s': none of its %d forces falls on a free lattice vertex of this description", path, rf->n);
    return 0;
}
