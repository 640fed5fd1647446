#!/bin/sh
# profile_m4.sh ASSET [LINES] -- `make profile-m4`: Cortex-M4 instructions per
# step per function (inlined code counts to the function it is inlined in).
# The image is run twice under QEMU mps2-an386 with insn_plugin.so, which
# counts the instructions executed at every address; the images differ only
# in the number of steps played (PROF_M4_STEPS, default 2 and 10; a step's
# cost is fixed at init), so the per-address difference divided by the step
# difference is one step (pose + sn_step), without init, CRC and the final
# hash. With LINES > 0 it also prints the LINES hottest source lines
# (addr2line: the innermost inlined line of each address).
. ports/cross/port_lib.sh
a=${1:-cow}; nlines=${2:-0}
if ! have arm-none-eabi-gcc || ! have qemu-system-arm; then
    echo "profile-m4: needs arm-none-eabi-gcc and qemu-system-arm (make deps)"; exit 1
fi
B=$BUILD/baremetal
mkdir -p "$B"
set -- $(pmake print-prof-m4-steps)
na=$1; nb=$2
pmake "$B/insn_plugin.so" "$B/prof_${a}_a.elf" "$B/prof_${a}_b.elf" > "$B/prof_build.log" 2>&1 || {
    echo "profile-m4: build failed ($B/prof_build.log):"; tail -n 20 "$B/prof_build.log"; exit 1; }
for v in a b; do
    rm -f "$B/prof_${a}_$v.counts"
    # shellcheck disable=SC2086
    timeout 300 $BM_QEMU_RUN -plugin "$B/insn_plugin.so,out=$B/prof_${a}_$v.counts" \
        -kernel "$B/prof_${a}_$v.elf" < /dev/null > "$B/prof_${a}_$v.log" 2>&1 || {
        echo "profile-m4: image prof_${a}_$v.elf failed:"; tail -n 5 "$B/prof_${a}_$v.log"; exit 1; }
    [ -s "$B/prof_${a}_$v.counts" ] || { echo "profile-m4: the plugin wrote no counts ($B/prof_${a}_$v.counts)"; exit 1; }
done
# The two images' main differs, so addresses are mapped per image, and the
# per-step difference is taken per function (or per source line).
per_fn() {   # ELF COUNTS -> "function count" lines
    arm-none-eabi-nm -n -S -t d --defined-only "$1" | awk '$3 ~ /^[tTwW]$/ && NF == 4 { print $1 + 0, $2 + 0, $4 }' > "$1.syms"
    awk '
    FNR == NR { n++; lo[n] = $1 - $1 % 2; hi[n] = lo[n] + $2; nm[n] = $3; next }
    { c[$1] += $2 }
    END {
        for (x in c) {
            ad = x + 0; l = 1; h = n; f = 0
            while (l <= h) { m = int((l + h) / 2); if (lo[m] <= ad) { f = m; l = m + 1 } else h = m - 1 }
            name = (f && ad < hi[f]) ? nm[f] : sprintf("?0x%x", ad)
            s[name] += c[x]
        }
        for (k in s) print k, s[k]
    }' "$1.syms" "$2"
}
per_line() {   # ELF COUNTS -> "file:line count" lines (innermost inlined location)
    awk '{ c[$1] += $2 } END { for (x in c) print x, c[x] }' "$2" > "$2.sum"
    awk '{ printf "0x%x\n", $1 }' "$2.sum" | arm-none-eabi-addr2line -e "$1" | sed 's|^.*/||; s| .*||' > "$2.where"
    paste -d' ' "$2.sum" "$2.where" | awk '{ s[$3] += $2 } END { for (k in s) print k, s[k] }'
}
# A B -> per-step difference, top 30 by count, then the total
per_step() {
    awk -v d=$((nb - na)) '
    FNR == NR { A[$1] = $2; next }
    { B[$1] = $2 }
    END {
        for (k in B) { v = (B[k] - A[k]) / d; if (v != 0) { r[k] = v; tot += v } }
        for (k in A) if (!(k in B)) { r[k] = -A[k] / d; tot += r[k] }
        for (k in r) printf "%10d %6.2f%% %s\n", r[k], 100 * r[k] / tot, k
        printf "%10d total\n", tot
    }' "$1" "$2" | sort -rn | awk -v n="$3" '/ total$/ { t = $0; next } NR <= n + 1 { print } END { print t }'
}
for v in a b; do per_fn "$B/prof_${a}_$v.elf" "$B/prof_${a}_$v.counts" > "$B/prof_${a}_$v.fn"; done
echo "profile-m4: cortex-m4 $a, instructions per step (pose + sn_step) by function, (steps $nb - steps $na) / $((nb - na))"
per_step "$B/prof_${a}_a.fn" "$B/prof_${a}_b.fn" 30
if [ "$nlines" -gt 0 ] 2>/dev/null; then
    for v in a b; do per_line "$B/prof_${a}_$v.elf" "$B/prof_${a}_$v.counts" > "$B/prof_${a}_$v.ln"; done
    echo "profile-m4: cortex-m4 $a, the $nlines hottest source lines per step"
    per_step "$B/prof_${a}_a.ln" "$B/prof_${a}_b.ln" "$nlines"
fi
