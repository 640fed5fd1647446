#!/bin/sh
# test_runtime_rules.sh -- the runtime's coding rules, each checked mechanically.
#   1. warning-clean with gcc AND clang: -std=c99 -Wall -Wextra -Wpedantic
#      -Wconversion -Werror, plus -Wvla (no VLAs) and -Wshadow; both flavours
#   2. no allocation, stdio or libm: every undefined symbol of every runtime
#      object (nm -u) is another runtime function, memcpy/memset/memmove, or a
#      compiler helper (__*)
#   3. no mutable globals: no .data/.bss/common symbols in runtime objects
#   4. no recursion: the call graph (gcc -fcallgraph-info at -O0, so no call
#      is inlined or turned into a loop) is acyclic; no indirect calls
#   5. sinew.h is valid C++: g++ -fsyntax-only, and a C++ TU using it links
#      against the C library
#   6. no sn_mul(a, b) - sn_mul(c, d): sn_mul_sub (a clang MIPS32 miscompile)
# Prints a worst-case stack figure per public entry point (gcc -O2).
# clang missing: "SKIPPED: install clang" (a failure when $CI is set).
BUILD=${BUILD:-build}
CC=${CC:-cc}
pass=0; fail=0
ok() { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAIL: $*"; }
tmp=$(mktemp -d /tmp/sn_rules.XXXXXX) || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM

WARN="-std=c99 -Wall -Wextra -Wpedantic -Wconversion -Werror -Wvla -Wshadow"
SRCS=$(ls runtime/src/*.c)

# ---- 1. warnings, gcc and clang, both flavours ----
compile_all() { # $1 compiler, $2 tag, $3 extra flags
    mkdir -p "$tmp/$2"
    for s in $SRCS; do
        o="$tmp/$2/$(basename "$s" .c).o"
        if "$1" $WARN -O2 $3 -Iruntime/include -c "$s" -o "$o" > "$tmp/$2.log" 2>&1; then ok
        else bad "$1 $3: $s is not warning-clean:"; sed 's/^/    /' "$tmp/$2.log" | head -n 20; fi
    done
}
# gcc fixed also writes the -O2 stack-usage call graph (.ci) for the figure in 4.
compile_all gcc gcc-fixed "-fcallgraph-info=su"
# gcc float: make's own float objects when make compiled them with this
# script's gcc and line (-g aside: it adds no symbol nm reports and no
# warning) and they are up to date: the make build is -Werror, so they are
# warning-clean; else a compile of our own
reuse_float() {
    line=$(make -s --no-print-directory BUILD="$BUILD" print-sn-float-cc 2>/dev/null) || return 1
    set -- $line
    c=$(command -v "$1" 2>/dev/null) && g=$(command -v gcc 2>/dev/null) || return 1
    [ "$(readlink -f "$c")" = "$(readlink -f "$g")" ] || return 1
    shift
    [ "$(echo $* | sed 's/ -g / /')" = "$(echo $WARN -O2 -DSN_FLOAT -Iruntime/include)" ] || return 1
    make -s --no-print-directory -q BUILD="$BUILD" "$BUILD/libsinew_float.a" 2>/dev/null || return 1
    for s in $SRCS; do [ -f "$BUILD/runtime/float/$(basename "$s" .c).o" ] || return 1; done
    mkdir -p "$tmp/gcc-float"
    for s in $SRCS; do
        b=$(basename "$s" .c); cp "$BUILD/runtime/float/$b.o" "$tmp/gcc-float/$b.o"; ok
    done
    echo "  note: gcc float: make's objects ($BUILD/runtime/float, built with -Werror by '$line')"
}
reuse_float || compile_all gcc gcc-float "-DSN_FLOAT"
# clang fixed: the determinism slice's x86_64-clang-O2 runtime objects
# (ports/baremetal/baremetal.mk det_rt_rule, -Werror) when make's line is
# this one plus the ports' include directories (no runtime source includes
# from them: the objects are byte-identical, tests/CAMPAIGNS.md) with this
# script's clang, and they are up to date; else a compile of our own
reuse_clang_fixed() {
    o1="$BUILD/cross/obj/x86_64-clang-O2/runtime/src/sn_math.o"
    line=$(make -s --no-print-directory -n -B BUILD="$BUILD" "$o1" 2>/dev/null | tail -n 1) || return 1
    set -- $line
    c=$(command -v "$1" 2>/dev/null) && g=$(command -v clang 2>/dev/null) || return 1
    [ "$(readlink -f "$c")" = "$(readlink -f "$g")" ] || return 1
    shift
    want=$(printf '%s\n' $WARN -O2 -Iruntime/include -Iports/common -Iports/cross -c runtime/src/sn_math.c -o "$o1" | sort | tr '\n' ' ')
    [ "$(printf '%s\n' "$@" | sort | tr '\n' ' ')" = "$want" ] || return 1
    # shellcheck disable=SC2046
    make -s --no-print-directory -q BUILD="$BUILD" $(for s in $SRCS; do echo "$BUILD/cross/obj/x86_64-clang-O2/${s%.c}.o"; done) \
        2>/dev/null || return 1
    mkdir -p "$tmp/clang-fixed"
    for s in $SRCS; do
        b=$(basename "$s" .c); cp "$BUILD/cross/obj/x86_64-clang-O2/runtime/src/$b.o" "$tmp/clang-fixed/$b.o"; ok
    done
    echo "  note: clang fixed: make's objects ($BUILD/cross/obj/x86_64-clang-O2, built with -Werror by '$line')"
}
if command -v clang > /dev/null 2>&1; then
    reuse_clang_fixed || compile_all clang clang-fixed ""
    compile_all clang clang-float "-DSN_FLOAT"
else
    echo "SKIPPED: install clang (clang warning check not run)"
    [ -n "$CI" ] && bad "clang missing under CI"
fi

# ---- 2. + 3. symbols ----
for tag in gcc-fixed gcc-float clang-fixed clang-float; do
    [ -d "$tmp/$tag" ] || continue
    ls "$tmp/$tag"/*.o > /dev/null 2>&1 || continue
    nm --defined-only "$tmp/$tag"/*.o | awk 'NF == 3 { print $3 }' | sort -u > "$tmp/$tag.defined"
    for o in "$tmp/$tag"/*.o; do
        und=$(nm -u "$o" | awk '{ print $NF }' | grep -v -x -F -f "$tmp/$tag.defined" |
              grep -v -E '^(memcpy|memset|memmove|__.*|_GLOBAL_OFFSET_TABLE_)$')
        if [ -z "$und" ]; then ok; else bad "$tag $(basename "$o"): forbidden external symbols:" $und; fi
        data=$(nm "$o" | awk '$2 ~ /^[DdBbCcGgSs]$/ { print $3 }')
        if [ -z "$data" ]; then ok; else bad "$tag $(basename "$o"): mutable global/static data:" $data; fi
    done
done

# ---- 4. no recursion (call graph at -O0) ----
mkdir -p "$tmp/cg"
cg_ok=1
for s in $SRCS; do
    b=$(basename "$s" .c)
    ( cd "$tmp/cg" && gcc -std=c99 -O0 -fcallgraph-info "-I$OLDPWD/runtime/include" -c "$OLDPWD/$s" -o "$b.o" ) \
        > "$tmp/cg.log" 2>&1 || { cg_ok=0; bad "gcc -fcallgraph-info failed on $s (gcc >= 12 needed)"; cat "$tmp/cg.log"; }
done
if [ "$cg_ok" = 1 ]; then
    # edges "caller callee"; node labels tell indirect calls ("__indirect_call")
    cat "$tmp/cg"/*.ci | sed -n 's/.*sourcename: "\([^"]*\)" targetname: "\([^"]*\)".*/\1 \2/p' > "$tmp/edges"
    if grep -q '__indirect_call' "$tmp/edges"; then bad "indirect call in the runtime:"; grep '__indirect_call' "$tmp/edges"; else ok; fi
    # Kahn: repeatedly drop functions that call nothing still present; leftovers lie on a cycle
    cyc=$(awk '{ out[$1]++; n[$1] = 1; n[$2] = 1; e[NR] = $0 }
        END {
            do {
                changed = 0
                for (f in n) if (!(f in gone) && out[f] + 0 == 0) {
                    gone[f] = 1; changed = 1
                    for (i = 1; i <= NR; i++) { split(e[i], p, " "); if (p[2] == f && !(i in dead)) { dead[i] = 1; out[p[1]]-- } }
                }
            } while (changed)
            for (f in n) if (!(f in gone)) print f
        }' "$tmp/edges")
    if [ -z "$cyc" ]; then ok; echo "  call graph: $(wc -l < "$tmp/edges") call edges, acyclic (no recursion)"
    else bad "recursion: these functions lie on (or call into) a call cycle:" $cyc; fi
    # worst-case stack (gcc -O2, bytes) of each public entry point: deepest path of frame sizes
    cat "$tmp/gcc-fixed"/*.ci > "$tmp/su.all"
    awk '
        /^node:/ {
            t = $0; sub(/.*title: "/, "", t); sub(/".*/, "", t)
            l = $0; if (match(l, /[0-9]+ bytes/)) { sz[t] = substr(l, RSTART, RLENGTH) + 0 } else sz[t] = 0
            if (l ~ /dynamic/) dyn[t] = 1
        }
        /^edge:/ {
            s = $0; sub(/.*sourcename: "/, "", s); sub(/".*/, "", s)
            d = $0; sub(/.*targetname: "/, "", d); sub(/".*/, "", d)
            nc[s]++; callee[s, nc[s]] = d
        }
        function depth(f,   i, m, x) {
            if (f in memo) return memo[f]
            m = 0
            for (i = 1; i <= nc[f]; i++) { x = depth(callee[f, i]); if (x > m) m = x }
            memo[f] = sz[f] + m
            return memo[f]
        }
        END {
            split("sn_blob_validate sn_instance_init sn_set_pose sn_pose_from_local sn_step sn_get_surface sn_get_normals sn_state_hash", pub, " ")
            line = ""
            for (i = 1; i in pub; i++) if (pub[i] in sz) line = line " " pub[i] "=" depth(pub[i])
            print "  figure: worst-case stack bytes (gcc -O2, x86-64):" line
            for (f in dyn) print "  note: dynamic stack in " f
        }' "$tmp/su.all"
fi

# ---- 6. no plain difference of two widened products (sn_mul(a, b) - sn_mul(c, d)):
# clang 14 for 32-bit MIPS fuses it into an msub with swapped operands (wrong
# sign); sn_mul_sub (sn_internal.h) writes it as a sum ----
if grep -n "sn_mul([^()]*) *- *sn_mul(" runtime/src/*.c runtime/src/*.h > "$tmp/msub.log"; then
    bad "sn_mul(a, b) - sn_mul(c, d) in the runtime: use sn_mul_sub (clang MIPS msub bug)"; cat "$tmp/msub.log"
else ok; fi

# ---- 5. sinew.h as C++ ----
if command -v g++ > /dev/null 2>&1; then
    for flav in "" "-DSN_FLOAT"; do
        if g++ -x c++ -std=c++98 -fsyntax-only -Wall -Wextra -Wpedantic -Werror $flav -Iruntime/include \
               runtime/include/sinew.h > "$tmp/cxx.log" 2>&1; then ok
        else bad "sinew.h is not valid C++98 ($flav)"; cat "$tmp/cxx.log"; fi
    done
    cat > "$tmp/use.cpp" <<'EOF'
#include "sinew.h"
#include <cstdio>
int main() {
    sn_vec3 axis = {0, 0, 1 << 16};
    sn_quat q = sn_quat_axis_angle(axis, 90 << 16);
    const sn_blob *blob = 0;
    sn_status s = sn_blob_validate(0, 0, &blob);
    std::printf("%s %d\n", sn_status_str(s), (int)q.w);
    return s == SN_ERR_NULL ? 0 : 1;
}
EOF
    lib="$BUILD/libsinew.a"
    if [ ! -f "$lib" ]; then # build a private copy if make has not run
        for s in $SRCS; do gcc -std=c99 -O2 -Iruntime/include -c "$s" -o "$tmp/cxx_$(basename "$s" .c).o"; done
        ar rcs "$tmp/libsinew.a" "$tmp"/cxx_*.o; lib="$tmp/libsinew.a"
    fi
    if g++ -Wall -Wextra -Werror -Iruntime/include "$tmp/use.cpp" "$lib" -o "$tmp/use" > "$tmp/cxx.log" 2>&1 &&
       "$tmp/use" > /dev/null; then ok
    else bad "a C++ program using sinew.h does not build/link/run"; cat "$tmp/cxx.log"; fi
else
    echo "SKIPPED: install g++ (C++ header check not run)"
    [ -n "$CI" ] && bad "g++ missing under CI"
fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
