#!/bin/sh
# profile.sh -- `make profile-baremetal`: where the Cortex-M4 instructions of
# the cow go, per function (inlined code counts to its caller). QEMU logs
# every translated block (in_asm) and every block executed (exec, nochain);
# awk multiplies executions by block length. Image: prof_cow.elf, 2 steps
# after init (init, blob CRC included, shows up as sn_blob_validate).
. ports/cross/port_lib.sh
B=$BUILD/baremetal
mkdir -p "$B"   # a fresh build directory has none yet
pmake "$B/prof_cow.elf" > "$B/prof_build.log" 2>&1 || { tail -n 20 "$B/prof_build.log"; exit 1; }
log=$B/prof_qemu.log
# shellcheck disable=SC2086
$BM_QEMU_RUN -d in_asm,exec,nochain -D "$log" -kernel "$B/prof_cow.elf" < /dev/null > /dev/null 2>&1 || {
    echo "profile-baremetal: image failed"; exit 1; }
awk '
/^IN:/ { inblk = 1; pc = ""; n = 0; next }
inblk && /^0x[0-9a-f]+:/ { if (pc == "") pc = substr($1, 3, 8); n++; next }
inblk && (/^$/ || /^Trace/) { if (pc != "") len[pc] = n; inblk = 0 }
/^Trace/ {
    split($0, a, "/"); p = a[2]; f = $NF
    if (f ~ /\]$/) f = "?"
    ins[f] += len[p]; tot += len[p]
}
END {
    for (f in ins) printf "%10d %6.2f%% %s\n", ins[f], 100 * ins[f] / tot, f
    printf "%10d total\n", tot
}' "$log" | sort -rn | head -n 25
rm -f "$log"
