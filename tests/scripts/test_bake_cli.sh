#!/bin/sh
# sinew-bake command line: the C array output compiles as strict C99, is
# 8-aligned and holds the same bytes as the binary blob; bakes are
# byte-identical across runs and flavours differ only where they must.
BUILD=${BUILD:-build}
BAKE=$BUILD/sinew-bake
CC=${CC:-cc}
. tests/scripts/cli_lib.sh
[ -x "$BAKE" ] || { echo "FAIL: $BAKE not built"; echo "0 passed, 1 failed"; exit 1; }
T=$(mktemp -d "${TMPDIR:-/tmp}/sinew_bake_cli.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT

"$BAKE" tools/examples/limb/limb.sinew -o "$T/limb.blob" --c-array "$T/limb_blob.c" --name my_limb --quiet && ok "bake with --c-array" || bad "bake with --c-array"
"$BAKE" tools/examples/limb/limb.sinew -o "$T/limb2.blob" --quiet && cmp -s "$T/limb.blob" "$T/limb2.blob" && ok "two bakes are byte-identical" || bad "two bakes differ"
cat > "$T/main.c" <<'EOC'
#include <stdint.h>
#include <stdio.h>
#include <string.h>
extern const unsigned long my_limb_size;
extern const unsigned char *limb_bytes(void);
int main(int argc, char **argv) {
    static unsigned char buf[1 << 20];
    FILE *f = fopen(argv[1], "rb");
    size_t n = f ? fread(buf, 1, sizeof buf, f) : 0;
    (void)argc;
    if (f) fclose(f);
    if (n != my_limb_size) { printf("size %lu vs file %lu\n", my_limb_size, (unsigned long)n); return 1; }
    if (((uintptr_t)limb_bytes() & 7u) != 0) { printf("not 8-aligned\n"); return 1; }
    return memcmp(buf, limb_bytes(), n) != 0;
}
EOC
# accessor in the same translation unit as the array (the union type is anonymous)
{ cat "$T/limb_blob.c"; echo 'const unsigned char *limb_bytes(void) { return my_limb.bytes; }'; } > "$T/limb_acc.c"
if $CC -std=c99 -Wall -Wextra -Wpedantic -Werror -c "$T/limb_blob.c" -o "$T/limb_blob.o" 2> "$T/cc.log"; then ok "C array compiles with -std=c99 -Wall -Wextra -Wpedantic -Werror"; else bad "C array does not compile"; cat "$T/cc.log"; fi
if $CC -std=c99 -Wall -Wextra -Werror "$T/main.c" "$T/limb_acc.c" -o "$T/check" 2> "$T/cc2.log" && "$T/check" "$T/limb.blob"; then ok "C array holds the blob's bytes, 8-aligned"; else bad "C array bytes"; cat "$T/cc2.log"; fi
"$BAKE" tools/examples/limb/limb.sinew -o "$T/f.blob" --flavour float --quiet && [ "$(od -An -tu1 -j24 -N1 "$T/f.blob" | tr -d ' ')" = 1 ] && ok "--flavour float writes flavour 1" || bad "--flavour float"
"$BAKE" tools/examples/limb/limb.sinew -o "$T/d.blob" --flavour double --quiet && [ "$(od -An -tu1 -j25 -N1 "$T/d.blob" | tr -d ' ')" = 8 ] && ok "--flavour double writes 8-byte reals" || bad "--flavour double"
out=$("$BAKE" tools/examples/limb/limb.sinew -o "$T/s.blob")
echo "$out" | grep -q "lattice .* vertices (.* free, .* skeleton), .* cells" && echo "$out" | grep -q "blob .* bytes: JOINTS" && ok "summary lists counts and section bytes" || bad "summary"
[ -z "$("$BAKE" tools/examples/limb/limb.sinew -o "$T/q.blob" --quiet 2>&1)" ] && ok "--quiet prints nothing" || bad "--quiet"
echo "$out" | grep -q "bones .*radius.*captured.*moved" && echo "$out" | grep -Eq "shoulder->elbow +1.25 +auto \(flesh 1\) +27 +26" \
    && ok "summary lists each bone's radius and vertices" || bad "bone summary"
# --check: one line, also with --quiet; no output file needed
out=$("$BAKE" tools/examples/limb/limb.sinew --check --quiet 2>&1)
[ "$(echo "$out" | wc -l)" -eq 1 ] && echo "$out" | grep -Eq "^check: cell 1: lattice 99 vertices \(52 free, 47 skeleton\), 40 cells; volume ratio 1.0000.*: ok$" \
    && ok "--check --quiet prints one check line" || { bad "--check line"; echo "$out"; }
"$BAKE" tools/examples/limb/limb.sinew -o "$T/c.blob" --check --quiet > /dev/null && cmp -s "$T/c.blob" "$T/limb2.blob" && ok "--check with -o writes the same blob" || bad "--check -o"
"$BAKE" --help | grep -q -- "--check" && ok "--help lists --check" || bad "--help --check"
# --no-triangles: TRIS empty (header nT 0), 6 bytes per triangle fewer, the
# summary says so. (The physics never reads TRIS: the cow without triangles
# gave the full blob's state hash after 600 steps of the trot, checked by hand
# for issue 15 item 4.)
out=$("$BAKE" tools/examples/limb/limb.sinew -o "$T/nt.blob" --no-triangles)
nt=$(od -An -tu4 -j52 -N4 "$T/limb2.blob" | tr -d ' ')
[ "$(od -An -tu4 -j52 -N4 "$T/nt.blob" | tr -d ' ')" = 0 ] && [ "$nt" -gt 0 ] \
    && [ $(($(wc -c < "$T/limb2.blob") - $(wc -c < "$T/nt.blob"))) -eq $(((6 * nt + 7) / 8 * 8)) ] \
    && echo "$out" | grep -q "bytes without the $nt triangles (--no-triangles" \
    && ok "--no-triangles leaves the $nt triangles out" || { bad "--no-triangles"; echo "$out" | grep "blob  "; }
"$BAKE" --help | grep -q -- "--no-triangles" && ok "--help lists --no-triangles" || bad "--help --no-triangles"
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
