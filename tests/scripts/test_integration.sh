#!/bin/sh
# Engine integration (issue 18): every way a game build can take Sinew in
# gives the same cow, and the runtime is safe to step on many threads.
#   reference   ports/cross/det_main.c (the determinism driver, no clip: its
#               built-in pose sequence) over the Makefile's libraries
#   consumers   tests/integration/consumer/main.c built against
#               make's libsinew{,_float}.a; `make install` + pkg-config;
#               CMake add_subdirectory; CMake find_package after cmake --install
#               into a temporary prefix; the amalgamation (make amalgamation)
#   C++         runtime sources checked as C++ (g++ -x c++ -Wall -Wextra
#               -Werror -fsyntax-only: the front end's errors and warnings,
#               each source alone), the amalgamation compiled as C++ (code
#               generated), and the RAII example
#               tests/integration/cpp/sinew_example.cpp at -std=c++11 and c++17
#   threads     tests/integration/threads/threads.c: 8 instances of one blob on
#               8 pthreads = one after another = as shared instances on 2 threads
#               with one workspace each; again under ThreadSanitizer
#               (clang, over the runtime sources) with a racy positive control
# Every consumer steps the cow $STEPS steps and prints its state hash: all
# fixed-flavour hashes must equal the reference, float likewise. Also: the
# amalgamation is byte-identical when regenerated from shuffled inputs, the
# CMake library holds the same objects as make's, and the sinew-bake of each
# build path bakes the same blob. cmake, pkg-config, g++ are required (make
# deps); clang (TSan) is optional: a loud SKIPPED line, a failure under CI.
# Two sizes: `make test` (default) builds the CMake project with
# -DSINEW_BUILD_TOOLS=OFF -DSINEW_BUILD_PLAYER=OFF (configure, both runtime
# libraries, install, find_package and add_subdirectory consumers: every
# consumer path); SN_INTEGRATION_FULL=1 (`make integration-full`) builds the
# whole project (sinew-bake, sinew-rig, both players) and checks that its
# sinew-bake bakes the cow byte for byte, its sinew-play gives make's hash,
# the install carries sinew-bake and find_package sees sinew::bake; it also
# builds and runs the float amalgamation consumer (make test: the fixed one).
. ports/cross/port_lib.sh

STEPS=${SN_INTEGRATION_STEPS:-300}
TSAN_STEPS=${SN_INTEGRATION_TSAN_STEPS:-30}
FULL=${SN_INTEGRATION_FULL:-0}
CC=${CC:-cc}
CXX=${CXX:-g++}
[ "$CC" = cc ] && have gcc && CC=gcc
ROOT=$(pwd)
D=$BUILD/integration
case $D in /*) ;; *) D=$ROOT/$D ;; esac
L=$D/logs
rm -rf "$D"; mkdir -p "$L"
t0=$(date +%s)
IT=tests/integration
RUNTIME_WARN="-std=c99 -Wall -Wextra -Wpedantic -Wconversion -Wvla -Wshadow -Werror"
CXX_WARN="-Wall -Wextra -Wpedantic -Werror"
fixed=""; float=""

# log NAME CMD...: run quietly into $L/NAME.log; on failure show its tail
# (sh has no locals: helpers use their own _x names)
log() {
    _ln=$1; shift
    if "$@" > "$L/$_ln.log" 2>&1; then return 0; fi
    bad "$_ln: '$*' failed (log $L/$_ln.log)"; tail -n 15 "$L/$_ln.log" | sed 's/^/    /'
    return 1
}
# got NAME fixed|float CMD...: run a consumer (log run_NAME_FLAVOUR), file its hash
got() {
    _gn=$1; _gf=$2; shift 2
    _gl=run_${_gn}_$_gf
    if log "$_gl" "$@" && _gh=$(hash_of "$L/$_gl.log") && [ -n "$_gh" ]; then
        echo "integration: $_gn ($_gf) $_gh"
        if [ "$_gf" = float ]; then float="$float$_gn $_gh
"; else fixed="$fixed$_gn $_gh
"; fi
    elif [ -f "$L/$_gl.log" ] && [ -z "$(hash_of "$L/$_gl.log")" ]; then bad "$_gn ($_gf): no hash line"; fi
}
need() { have "$1" || { bad "required tool missing: $1 ($2; make deps installs it)"; return 1; }; }
need "$CC" "C compiler"; need "$CXX" "C++ compiler"; need cmake "CMake"; need pkg-config "pkg-config"
have_cmake=0; have cmake && have_cmake=1
have_pc=0; have pkg-config && have_pc=1
have_cxx=0; have "$CXX" && have_cxx=1

# ---- what make builds: libraries, tool, blobs, amalgamation ----
set -- $(pmake print-integration-vars)
LIB=$1; LIBF=$2; BAKE=$3; AMAL=$4
BLOB=$BUILD/examples/cow.blob
BLOBF=$BUILD/examples/cow_float.blob
log make pmake "$LIB" "$LIBF" "$BAKE" "$BUILD/sinew-play" "$BLOB" "$BLOBF" "$AMAL/sinew.c" || { finish; exit 1; }

# ---- reference: the determinism driver (built-in poses) over make's libraries ----
DET_SRCS="ports/cross/det_main.c ports/cross/sn_det.c ports/common/sn_clip.c ports/common/sn_clip_pose.c"
if log build_det $CC $RUNTIME_WARN -O2 -Iruntime/include -Iports/common -Iports/cross $DET_SRCS "$LIB" -o "$D/det" &&
   log build_det_float $CC $RUNTIME_WARN -O2 -DSN_FLOAT -ffp-contract=off -Iruntime/include -Iports/common -Iports/cross \
        $DET_SRCS "$LIBF" -o "$D/det_float"; then
    got det-driver fixed "$D/det" "$BLOB" --steps "$STEPS"
    got det-driver float "$D/det_float" "$BLOBF" --steps "$STEPS"
fi
ref=$(printf '%s' "$fixed" | awk 'NR==1 {print $2}')
reff=$(printf '%s' "$float" | awk 'NR==1 {print $2}')

# ---- (1) the Makefile's libraries, linked by hand ----
CONS="$IT/consumer/main.c"
log build_make $CC $RUNTIME_WARN -O2 -Iruntime/include -I$IT "$CONS" "$LIB" -o "$D/consumer_make" &&
    got make-lib fixed "$D/consumer_make" "$BLOB" "$STEPS"
log build_make_float $CC $RUNTIME_WARN -O2 -DSN_FLOAT -DSINEW_CONSUMER_EXPECT_FLOAT -Iruntime/include -I$IT "$CONS" "$LIBF" \
    -o "$D/consumer_make_float" && got make-lib float "$D/consumer_make_float" "$BLOBF" "$STEPS"

# ---- (2) make install PREFIX=... + pkg-config ----
PM=$D/prefix-make
if log make_install pmake install PREFIX="$PM"; then
    miss=""
    for f in include/sinew.h lib/$(basename "$LIB") lib/$(basename "$LIBF") bin/sinew-bake \
             lib/pkgconfig/sinew.pc lib/pkgconfig/sinew-float.pc; do
        [ -f "$PM/$f" ] || miss="$miss $f"
    done
    if [ -z "$miss" ]; then ok "make install: header, both libraries, sinew-bake, sinew.pc, sinew-float.pc"
    else bad "make install: missing$miss"; fi
    if log bake_make_install "$PM/bin/sinew-bake" tools/examples/cow/cow.sinew -o "$D/cow_installed.blob" --quiet &&
       cmp -s "$D/cow_installed.blob" "$BLOB"; then ok "installed sinew-bake bakes the cow byte for byte"
    else bad "installed sinew-bake: blob differs from $BLOB"; fi
    if [ $have_pc = 1 ]; then
        # shellcheck disable=SC2046
        log build_pkgconfig sh -c "PKG_CONFIG_PATH='$PM/lib/pkgconfig' && export PKG_CONFIG_PATH &&
            $CC $RUNTIME_WARN -O2 -I$IT \$(pkg-config --cflags sinew) $CONS \$(pkg-config --libs sinew) -o '$D/consumer_pc' &&
            $CC $RUNTIME_WARN -O2 -I$IT -DSINEW_CONSUMER_EXPECT_FLOAT \$(pkg-config --cflags sinew-float) $CONS \
                \$(pkg-config --libs sinew-float) -o '$D/consumer_pc_float'" &&
        { got pkg-config fixed "$D/consumer_pc" "$BLOB" "$STEPS"; got pkg-config float "$D/consumer_pc_float" "$BLOBF" "$STEPS"; }
    fi
fi

# ---- (3) CMake: the project itself from scratch, install, find_package ----
if [ $have_cmake = 1 ]; then
    CB=$D/cmake-build; PC=$D/prefix-cmake
    c0=$(date +%s)
    # make test: the libraries only (the tools and players: make integration-full)
    if [ "$FULL" = 1 ]; then cm_opts=""; cm_what="runtime x2, sinew-bake, players"
    else cm_opts="-DSINEW_BUILD_TOOLS=OFF -DSINEW_BUILD_PLAYER=OFF"; cm_what="runtime x2; tools and players: make integration-full"; fi
    # shellcheck disable=SC2086
    if log cmake_configure cmake -S . -B "$CB" -DCMAKE_BUILD_TYPE=Release -DSINEW_WERROR=ON $cm_opts &&
       log cmake_build cmake --build "$CB" -j 2; then
        echo "figure: CMake configure + build ($cm_what), from scratch: $(( $(date +%s) - c0 ))s"
        ok "CMake: configure and build (-DSINEW_WERROR=ON $cm_opts)"
        # the same objects as make's libraries: the source lists agree
        a=$(ar t "$LIB" | sed 's/\.c\.o$/.o/' | sort | tr '\n' ' ')
        b=$(ar t "$CB/libsinew.a" | sed 's/\.c\.o$/.o/' | sort | tr '\n' ' ')
        if [ "$a" = "$b" ]; then ok "CMake libsinew.a holds make's objects: $a"
        else bad "CMake and make libraries differ: make [$a] cmake [$b]"; fi
        if [ "$FULL" = 1 ]; then  # the tools and players: built only in the full run
            if log bake_cmake "$CB/sinew-bake" tools/examples/cow/cow.sinew -o "$D/cow_cmake.blob" --quiet &&
               cmp -s "$D/cow_cmake.blob" "$BLOB"; then ok "CMake sinew-bake bakes the cow byte for byte"
            else bad "CMake sinew-bake: blob differs from $BLOB"; fi
            clip=tools/examples/cow/trot.clip
            if log play_make "$BUILD/sinew-play" "$BLOB" --clip $clip --frames 50 --hash --quiet &&
               log play_cmake "$CB/sinew-play" "$BLOB" --clip $clip --frames 50 --hash --quiet &&
               [ -n "$(hash_of "$L/play_make.log")" ] && [ "$(hash_of "$L/play_make.log")" = "$(hash_of "$L/play_cmake.log")" ]; then
                ok "CMake sinew-play = make's sinew-play ($(hash_of "$L/play_make.log"), trot, 50 frames)"
            else bad "CMake sinew-play differs from make's (see $L/play_*.log)"; fi
        fi
        if log cmake_install cmake --install "$CB" --prefix "$PC"; then
            miss=""
            bake_f=""; [ "$FULL" = 1 ] && bake_f=bin/sinew-bake
            for f in include/sinew.h lib/libsinew.a lib/libsinew_float.a $bake_f lib/cmake/sinew/sinew-config.cmake \
                     lib/cmake/sinew/sinew-config-version.cmake lib/cmake/sinew/sinew-targets.cmake \
                     lib/pkgconfig/sinew.pc lib/pkgconfig/sinew-float.pc; do
                [ -f "$PC/$f" ] || miss="$miss $f"
            done
            if [ -z "$miss" ]; then ok "cmake --install: header, libraries,${bake_f:+ sinew-bake,} package config, pkg-config"
            else bad "cmake --install: missing$miss"; fi
            if log consumer_package_configure cmake -S $IT/consumer -B "$D/consumer-package" -DCMAKE_PREFIX_PATH="$PC" &&
               log consumer_package_build cmake --build "$D/consumer-package" -j 2; then
                [ "$FULL" = 1 ] && ! grep -q 'sinew::bake is available' "$L/consumer_package_configure.log" &&
                    bad "find_package: no sinew::bake target"
                got find_package fixed "$D/consumer-package/consumer" "$BLOB" "$STEPS"
                got find_package float "$D/consumer-package/consumer_float" "$BLOBF" "$STEPS"
            fi
            # the relocatable .pc files of the CMake install
            if [ $have_pc = 1 ] && log build_cmake_pc sh -c "PKG_CONFIG_PATH='$PC/lib/pkgconfig' && export PKG_CONFIG_PATH &&
                    $CC $RUNTIME_WARN -O2 -I$IT \$(pkg-config --cflags sinew) $CONS \$(pkg-config --libs sinew) -o '$D/consumer_cmake_pc'"; then
                got cmake-install-pkg-config fixed "$D/consumer_cmake_pc" "$BLOB" "$STEPS"
            fi
        fi
    fi
    if log consumer_subdir_configure cmake -S $IT/consumer -B "$D/consumer-subdir" -DSINEW_SOURCE_DIR="$ROOT" -DSINEW_WERROR=ON &&
       log consumer_subdir_build cmake --build "$D/consumer-subdir" -j 2; then
        got add_subdirectory fixed "$D/consumer-subdir/consumer" "$BLOB" "$STEPS"
        got add_subdirectory float "$D/consumer-subdir/consumer_float" "$BLOBF" "$STEPS"
    fi
fi

# ---- (4) the amalgamation ----
if [ -f "$AMAL/sinew.c" ]; then
    # shellcheck disable=SC2046
    sh tools/amalgamate.sh "$D/amal2" $(ls runtime/src/*.c | sort -r) > "$L/amal2.log" 2>&1
    if cmp -s "$AMAL/sinew.c" "$D/amal2/sinew.c" && cmp -s "$AMAL/sinew.h" runtime/include/sinew.h; then
        ok "amalgamation: deterministic (same bytes from shuffled inputs), header = runtime/include/sinew.h"
    else bad "amalgamation: regenerating it gives other bytes (or a stale sinew.h)"; fi
    # absolute paths only: a relative BUILD (CI's "build") is also an ordinary word in comments
    if grep -q -e "$ROOT" -e "$(cd "$BUILD" && pwd)" "$AMAL/sinew.c"; then bad "amalgamation: contains a local path"; fi
    echo "figure: amalgamation $(wc -c < "$AMAL/sinew.c" | tr -d ' ') bytes, $(wc -l < "$AMAL/sinew.c" | tr -d ' ') lines, from $(ls runtime/src/*.c | wc -l | tr -d ' ') sources"
    log build_amal $CC $RUNTIME_WARN -O2 -I"$AMAL" -I$IT "$CONS" "$AMAL/sinew.c" -o "$D/consumer_amal" &&
        got amalgamation fixed "$D/consumer_amal" "$BLOB" "$STEPS"
    # the float one (14 CPU-s: the whole runtime as one TU at -O2) in the full run; make test
    # compiles the float amalgamation as C++17 below and runs the float library four other ways
    if [ "$FULL" = 1 ]; then
        log build_amal_float $CC $RUNTIME_WARN -O2 -DSN_FLOAT -DSINEW_CONSUMER_EXPECT_FLOAT -I"$AMAL" -I$IT "$CONS" "$AMAL/sinew.c" \
            -o "$D/consumer_amal_float" && got amalgamation float "$D/consumer_amal_float" "$BLOBF" "$STEPS"
    fi
else bad "amalgamation: $AMAL/sinew.c not built"; fi

# ---- (5) C++: runtime sources, amalgamation, the RAII example ----
if [ $have_cxx = 1 ]; then
    nbad=0; n=0
    for f in runtime/src/*.c; do
        for fl in "" -DSN_FLOAT; do
            n=$((n + 1))
            $CXX -x c++ -std=c++11 $CXX_WARN $fl -Iruntime/include -fsyntax-only "$f" > "$L/cxx_src.log" 2>&1 ||
                { nbad=$((nbad + 1)); bad "runtime as C++: $f $fl"; sed 's/^/    /' "$L/cxx_src.log" | head -n 20; }
        done
    done
    [ $nbad -eq 0 ] && ok "runtime as C++: $n compiles (every runtime/src/*.c, fixed and float, g++ -x c++ -std=c++11 $CXX_WARN -fsyntax-only)"
    if log cxx_amal $CXX -x c++ -std=c++17 $CXX_WARN -I"$AMAL" -c "$AMAL/sinew.c" -o "$D/amal_cxx.o" &&
       log cxx_amal_float $CXX -x c++ -std=c++17 $CXX_WARN -DSN_FLOAT -I"$AMAL" -c "$AMAL/sinew.c" -o "$D/amal_cxx_float.o"; then
        ok "amalgamation as C++17: fixed and float"
    fi
    EX=$IT/cpp/sinew_example.cpp
    for std in c++11 c++17; do
        log "build_cpp_$std" $CXX -std=$std $CXX_WARN -O2 -Iruntime/include -I$IT "$EX" "$LIB" -o "$D/example_$std" &&
            got "cpp-example-$std" fixed "$D/example_$std" "$BLOB" "$STEPS"
    done
    log build_cpp_float $CXX -std=c++17 $CXX_WARN -O2 -DSN_FLOAT -Iruntime/include -I$IT "$EX" "$LIBF" -o "$D/example_float" &&
        got cpp-example-c++17 float "$D/example_float" "$BLOBF" "$STEPS"
fi

# ---- (6) threads: 8 instances on 8 pthreads = one after another ----
# statically: no writable data in the runtime at all (no .data/.bss/TLS symbol or bytes)
if have nm && have size; then
    w=$(nm "$LIB" "$LIBF" 2>/dev/null | grep -E ' [BbDdCGgSsVv] ')
    sz=$(size -A "$LIB" "$LIBF" 2>/dev/null | awk '$1 ~ /^\.(data|bss|tdata|tbss)/ && $2 > 0')
    if [ -z "$w$sz" ]; then ok "no mutable global state: the runtime libraries have no writable data"
    else bad "writable data in the runtime (threading contract of sinew.h):"; printf '%s\n%s\n' "$w" "$sz" | sed 's/^/    /'; fi
else bad "required tool missing: nm/size (binutils)"; fi
TH=$IT/threads/threads.c
if log build_threads $CC $RUNTIME_WARN -O2 -pthread -Iruntime/include -I$IT "$TH" "$LIB" -o "$D/threads"; then
    got threads-8 fixed "$D/threads" "$BLOB" "$STEPS" && grep -q '^threads: ' "$L/run_threads-8_fixed.log" &&
        ok "threads (fixed): $(sed -n 's/^threads: //p' "$L/run_threads-8_fixed.log")"
fi
if log build_threads_float $CC $RUNTIME_WARN -O2 -pthread -DSN_FLOAT -Iruntime/include -I$IT "$TH" "$LIBF" -o "$D/threads_float"; then
    got threads-8 float "$D/threads_float" "$BLOBF" "$STEPS" && grep -q '^threads: ' "$L/run_threads-8_float.log" &&
        ok "threads (float): $(sed -n 's/^threads: //p' "$L/run_threads-8_float.log")"
fi
# ThreadSanitizer over the runtime sources themselves (instrumented)
tsan_run() {  # LOG CMD...: run; with a fresh kernel's ASLR, TSan may need it off
    _tl=$1; shift
    TSAN_OPTIONS="halt_on_error=1 exitcode=66 ${TSAN_OPTIONS:-}" "$@" > "$_tl" 2>&1
    _trc=$?
    if grep -q 'unexpected memory mapping\|FATAL: ThreadSanitizer' "$_tl" && have setarch; then
        echo "note: TSan cannot map its shadow memory with ASLR on; rerun under setarch -R"
        TSAN_OPTIONS="halt_on_error=1 exitcode=66 ${TSAN_OPTIONS:-}" setarch "$(uname -m)" -R "$@" > "$_tl" 2>&1
        _trc=$?
    fi
    return $_trc
}
if have clang; then
    TS="clang -std=c99 -O1 -g -fsanitize=thread -pthread"
    # positive control: a racy program must be reported, else the run proves nothing
    cat > "$D/race.c" <<'EOF'
#include <pthread.h>
static int shared;
static void *bump(void *p) { int i; for (i = 0; i < 1000; i++) shared++; return p; }
int main(void) { pthread_t a, b; pthread_create(&a, 0, bump, 0); pthread_create(&b, 0, bump, 0);
                 pthread_join(a, 0); pthread_join(b, 0); return shared == 0; }
EOF
    if log build_tsan_race $TS "$D/race.c" -o "$D/race_tsan" &&
       log build_tsan $TS -Wall -Wextra -Werror -Iruntime/include -I$IT "$TH" runtime/src/*.c -o "$D/threads_tsan"; then
        tsan_run "$L/race_tsan.log" "$D/race_tsan"
        if grep -q 'WARNING: ThreadSanitizer: data race' "$L/race_tsan.log"; then
            if tsan_run "$L/threads_tsan.log" "$D/threads_tsan" "$BLOB" "$TSAN_STEPS" &&
               ! grep -q 'ThreadSanitizer' "$L/threads_tsan.log" && grep -q '^threads: ' "$L/threads_tsan.log"; then
                ok "ThreadSanitizer: no report, 8 threads x $TSAN_STEPS steps (control: the racy program is reported)"
                echo "figure: TSan clean: 8 instances of the cow on 8 threads, $TSAN_STEPS steps, runtime instrumented"
            else bad "ThreadSanitizer on threads.c:"; grep -A12 'ThreadSanitizer\|FAIL' "$L/threads_tsan.log" | head -n 30 | sed 's/^/    /'; fi
        else bad "ThreadSanitizer does not work here: the racy control was not reported"; tail -n 5 "$L/race_tsan.log" | sed 's/^/    /'; fi
    fi
else
    skip "ThreadSanitizer: no clang (make deps)"
fi

# ---- every path agrees with the reference ----
agree() {  # label list reference
    n=$(printf '%s' "$2" | grep -c .)
    odd=$(printf '%s' "$2" | awk -v r="$3" '$2 != r')
    if [ -z "$3" ]; then bad "$1: no reference hash (det driver failed)"
    elif [ -n "$odd" ]; then bad "$1: differs from the reference $3:"; printf '%s\n' "$odd" | sed 's/^/    /'
    else ok "$1: $n paths agree: $3 after $STEPS steps"
        echo "figure: $1 hash $3 ($STEPS steps): $(printf '%s' "$2" | awk '{print $1}' | tr '\n' ' ')"; fi
}
agree "fixed flavour" "$fixed" "$ref"
agree "float flavour" "$float" "$reff"
echo "figure: integration test $(( $(date +%s) - t0 ))s"
finish
