#!/bin/sh
# Issue 9 item 1's closing figure: energy over 60 s of a held 180-degree twist
# with Rayleigh 0 0 (limb elbow, cow neck, beast neck), before and after the
# per-cell model.   sh tests/scripts/plot_held.sh [BUILD] [OUT] [OLD_WORKTREE]
# AFTER: test_physics_held's figure mode (per-step CSV, fixed and float) and
# sinew-play --stats-csv/--plot on the same ramp as a clip.
# BEFORE, when OLD_WORKTREE exists (`git worktree add /tmp/old_wt <commit>`
# of the pre-change code): its runtime and reference built there, its tool
# re-baking the descriptions with Rayleigh 0 0, the same ramp; energy by that
# reference's formulas (consistent-mass kinetic + elastic incl. twist).
# Needs `make BUILD=$BUILD all test` (or the held blobs) first. Not part of
# make test (only tests/scripts/test_*.sh are).
set -e
BUILD=${1:-build}
OUT=${2:-/tmp/held_figs}
OLD=${3:-/tmp/old_wt}
SRC=$OUT/src
mkdir -p "$SRC"
CC=${CC:-cc}

for t in test_physics_held test_physics_held_float; do
    [ -x "$BUILD/tests/$t" ] || { echo "plot_held: build $BUILD/tests/$t first" >&2; exit 1; }
    BUILD=$BUILD "$BUILD/tests/$t" figure "$OUT" | grep -E 'figure|SKIPPED|FAIL'
done

# cases: asset joint twist-axis (child joint - joint, rest) metres-per-mesh-unit
CASES="limb:elbow:1,0,0:0.05 cow:neck:1.8,0.3,0:0.2 beast:neck:0,26,12:0.01"

# --- AFTER through the player: the ramp as a clip (smoothstep keyed every 0.05 s) ---
for c in $CASES; do
    IFS=: read -r n j ax um <<EOF
$c
EOF
    b=$BUILD/physics/held/${n}_undamped.blob
    [ -f "$b" ] || { echo "plot_held: no $b, $n skipped"; continue; }
    echo "$ax" | awk -F, -v j="$j" '{ print "sinew-clip 1\nduration 61\nloop no";
        for (i = 0; i <= 20; i++) { s = i / 20; printf "rot %s %.2f %s %s %s %.6f\n", j, s, $1, $2, $3, 180 * s * s * (3 - 2 * s) } }' \
        > "$SRC/${n}_${j}_twist180.clip"
    "$BUILD/sinew-play" "$b" --clip "$SRC/${n}_${j}_twist180.clip" --frames 3660 --quiet \
        --stats-csv "$OUT/${n}_${j}_twist180_player.csv" --plot "$OUT/${n}_${j}_twist180_after_player.png" \
        --title "AFTER $n $j twist 180 held, Rayleigh 0 0 (sinew-play)" | grep -v '^$' || true
done

# --- BEFORE: the pre-change runtime, tool and reference ---
cat > "$SRC/before.c" <<'EOF'
/* Old runtime: joint ramped to DEG about AXIS over 1 s (smoothstep), held.
 * CSV: step, t, energy by the old reference's formulas (J), saturations. */
#include "phys_util.h"
#include "phys_pose.h"
int main(int argc, char **argv) {
    pu_rt r; snref_model m; snref_state s;
    sn_xform pose[64]; snref_xform rp[64]; sn_quat local[64];
    double ax[3], deg, secs, um, h, *lat, *prev, J;
    unsigned k, j, nJ, nV, steps;
    int32_t jn;
    if (argc != 9) { fprintf(stderr, "usage: before BLOB JOINT AX AY AZ DEG SECONDS METRES_PER_MESH_UNIT\n"); return 2; }
    ax[0] = atof(argv[3]); ax[1] = atof(argv[4]); ax[2] = atof(argv[5]);
    deg = atof(argv[6]); secs = atof(argv[7]); um = atof(argv[8]);
    if (pu_rt_open(&r, argv[1]) || pu_ref_open(&m, &s, argv[1])) return 1;
    nJ = r.info.joints; nV = r.info.vertices; jn = sn_find_joint(r.blob, argv[2]);
    if (jn < 0 || nJ > 64) return 1;
    h = m.h; steps = (unsigned)ceil(secs / h - 1e-9);
    J = m.m0 * (m.unit * um) * (m.unit * um) / (h * h);   /* joules per baked energy unit */
    lat = malloc(24 * nV); prev = malloc(24 * nV);
    pu_rt_lattice(&r, prev);
    printf("step,t_s,energy_ref_J,saturations\n");
    for (k = 0; k < steps; k++) {
        double u = k * h / 1.0, ek, ee;
        sn_stats st;
        u = u >= 1 ? 1 : u * u * (3 - 2 * u);
        for (j = 0; j < nJ; j++) local[j] = pu_qident();
        local[jn] = pu_axis_angle(ax[0], ax[1], ax[2], deg * u);
        sn_pose_from_local(r.blob, local, NULL, pose);
        sn_set_pose(r.inst, pose, nJ);
        sn_step(r.inst);
        sn_get_stats(r.inst, &st);
        pu_rt_lattice(&r, lat);
        pu_pose_to_ref(pose, nJ, rp);
        snref_set_pose(&s, rp);
        for (j = 0; j < 3 * nV; j++) { s.p[j] = lat[j] / m.unit; s.v[j] = (lat[j] - prev[j]) / m.unit; }
        snref_energy(&s, &ek, &ee);
        memcpy(prev, lat, 24 * nV);
        printf("%u,%.6f,%.9g,%u\n", k + 1, (k + 1) * h, (ek + ee) * J, st.saturations);
    }
    return 0;
}
EOF
if [ -d "$OLD/runtime" ]; then
    ( cd "$OLD" && make BUILD="$OLD/build" all ) > "$SRC/old_build.log" 2>&1 || { echo "plot_held: old build failed: $SRC/old_build.log" >&2; exit 1; }
    for f in "" _float; do
        D=""; [ -z "$f" ] || D=-DSN_FLOAT
        $CC -std=c99 -O2 $D -I"$OLD/runtime/include" -I"$OLD/tests/reference" -I"$OLD/tests" -o "$SRC/before$f" \
            "$SRC/before.c" "$OLD/tests/reference/snref.c" "$OLD/build/libsinew$f.a" -lm
    done
    for c in $CASES; do
        IFS=: read -r n j ax um <<EOF
$c
EOF
        d=$SRC/old_${n}_undamped
        [ -f "$OLD/tools/examples/$n/$n.sinew" ] && desc=$OLD/tools/examples/$n/$n.sinew || desc=tools/examples/$n/$n.sinew
        mkdir -p "$d"
        # the old tool knows no 'bone' lines (bones as volumes are the new lattice builder's)
        sed -e '/^[[:space:]]*rayleigh[[:space:]]/d' -e '/^[[:space:]]*bone[[:space:]]/d' "$desc" > "$d/asset.sinew"
        echo 'rayleigh 0 0' >> "$d/asset.sinew"
        for o in tools/examples/$n/*.obj; do ln -sf "$(pwd)/$o" "$d/"; done
        for f in "" _float; do
            fl=fixed; [ -z "$f" ] || fl=float
            if "$OLD/build/sinew-bake" "$d/asset.sinew" -o "$d/$n$f.blob" --flavour $fl --quiet > "$d/bake$f.log" 2>&1; then
                "$SRC/before$f" "$d/$n$f.blob" "$j" $(echo "$ax" | tr , ' ') 180 61 "$um" > "$OUT/${n}_${j}_twist180_before$f.csv"
            else
                echo "plot_held: the old tool cannot bake $n: $(tail -n 1 "$d/bake$f.log")"
            fi
        done
    done
else
    echo "plot_held: no old worktree at $OLD: no BEFORE figures"
fi

# --- plots: CSV columns as line series (ports/desktop/plot.c) ---
cat > "$SRC/plotcsv.c" <<'EOF'
/* plotcsv OUT.png TITLE PANEL... ; PANEL = [log:]TITLE=FILE@COLUMN@LABEL[+FILE@COLUMN@LABEL...] */
#define _POSIX_C_SOURCE 200809L
#include "plot.h"
#include "png.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
static int load(const char *path, const char *col, double **x, double **y) {
    FILE *f = fopen(path, "r");
    char line[4096], *tok;
    int ci = -1, ti = -1, i, n = 0, cap = 4096;
    if (!f) return -1;
    if (!fgets(line, sizeof line, f)) { fclose(f); return -1; }
    line[strcspn(line, "\r\n")] = 0;
    for (i = 0, tok = strtok(line, ","); tok; tok = strtok(NULL, ","), i++) {
        if (!strcmp(tok, col)) ci = i;
        if (!strcmp(tok, "t_s")) ti = i;
    }
    if (ci < 0 || ti < 0) { fclose(f); return -1; }
    *x = malloc(cap * sizeof **x); *y = malloc(cap * sizeof **y);
    while (fgets(line, sizeof line, f)) {
        if (n == cap) { cap *= 2; *x = realloc(*x, cap * sizeof **x); *y = realloc(*y, cap * sizeof **y); }
        for (i = 0, tok = strtok(line, ","); tok; tok = strtok(NULL, ","), i++) {
            if (i == ci) (*y)[n] = atof(tok);
            if (i == ti) (*x)[n] = atof(tok);
        }
        n++;
    }
    fclose(f);
    return n;
}
int main(int argc, char **argv) {
    plot_panel p[4]; plot_series s[4][4];
    rs_image im; char err[256];
    int np = 0, i;
    if (argc < 4 || argc > 7) { fprintf(stderr, "usage: plotcsv OUT.png TITLE PANEL...\n"); return 2; }
    for (i = 3; i < argc; i++, np++) {
        char *a = strdup(argv[i]), *eq = strchr(a, '='), *spec, *save = NULL;
        p[np].log_y = !strncmp(a, "log:", 4);
        if (!eq) return 2;
        *eq = 0; p[np].title = a + (p[np].log_y ? 4 : 0); p[np].s = s[np]; p[np].ns = 0;
        for (spec = strtok_r(eq + 1, "+", &save); spec && p[np].ns < 4; spec = strtok_r(NULL, "+", &save)) {
            char *c1 = strchr(spec, '@'), *c2 = c1 ? strchr(c1 + 1, '@') : NULL;
            plot_series *ps = &s[np][p[np].ns];
            double *x, *y;
            if (!c2) return 2;
            *c1 = 0; *c2 = 0;
            ps->n = load(spec, c1 + 1, &x, &y);
            if (ps->n <= 0) { fprintf(stderr, "plotcsv: %s: no column %s\n", spec, c1 + 1); continue; }
            ps->x = x; ps->y = y; ps->label = c2 + 1;
            p[np].ns++;
        }
    }
    if (rs_image_alloc(&im, 1000, 300 * np + 60) || plot_draw(&im, argv[2], "time (s)", p, np)) return 1;
    if (png_write(argv[1], im.rgb, im.w, im.h, err, sizeof err)) { fprintf(stderr, "%s\n", err); return 1; }
    return 0;
}
EOF
$CC -std=c99 -O2 -Iports/desktop -o "$SRC/plotcsv" "$SRC/plotcsv.c" ports/desktop/plot.c ports/desktop/raster.c ports/desktop/png.c -lm
for c in $CASES; do
    IFS=: read -r n j ax um <<EOF
$c
EOF
    base=$OUT/${n}_${j}_twist180
    [ -f "$base.csv" ] || continue
    before=""
    [ -s "${base}_before.csv" ] && before="+${base}_before.csv@energy_ref_J@before fx+${base}_before_float.csv@energy_ref_J@before fl"
    "$SRC/plotcsv" "${base}_before_after.png" "$n $j twist 180 deg (ramp 1 s), held, Rayleigh 0 0" \
        "log:J (log)=$base.csv@energy_ref_J@after fx+${base}_float.csv@energy_ref_J@after fl$before" \
        "J, after=$base.csv@energy_J@stats fx+${base}_float.csv@energy_J@stats fl+$base.csv@energy_ref_J@ref fx"
    # numbers: max energy over [1,2] s, after 2 s, at the end; saturations
    for f in "$base.csv" "${base}_float.csv" "${base}_before.csv" "${base}_before_float.csv"; do
        [ -s "$f" ] || continue
        awk -F, -v f="$(basename "$f")" 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
            { t = $c["t_s"]; e = $c["energy_ref_J"]; s = $c["saturations"];
              if (e ~ /nan|inf/) e = 1e300;
              if (t >= 1 && t <= 2 && e + 0 > a) a = e + 0; if (t > 2 && e + 0 > b) b = e + 0; last = e; sat = s }
            END { printf "%-36s energy (reference formulas): max [1,2] s %.4g J, max after 2 s %.4g J (x%.4f), at %.0f s %.4g J; saturations %d\n", f, a, b, (a > 0 ? b / a : 0), t, last, sat }' "$f"
    done
done
ls "$OUT"/*.png
