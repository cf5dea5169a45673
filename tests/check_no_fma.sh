#!/bin/sh
# The library holds no fused multiply-add: a fused a * b + c rounds once where the source rounds
# twice, so one instruction of it in any code path (a vector clone chosen on one CPU and not on
# another, an -march a build adds) would make results depend on the machine. Counts them in the
# disassembly of the shared library given as $1; skips (exit 77) where objdump is missing or the
# library is not x86-64.
lib=$1
command -v objdump >/dev/null 2>&1 || { echo "no objdump: skipped"; exit 77; }
objdump -f "$lib" | grep -q 'x86-64' || { echo "not x86-64: skipped"; exit 77; }
fused=$(objdump -d --no-show-raw-insn "$lib" | grep -cE '[[:space:]]vfn?m(add|sub)' || true)
clones=$(objdump -d "$lib" | grep -cE '^[0-9a-f]+ <[a-z_0-9]+\.(avx2|avx512f)>:' || true)
echo "$clones vector clones, $fused fused multiply-add instructions"
[ "$fused" -eq 0 ]
