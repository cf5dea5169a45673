#!/usr/bin/env bash
# Results must not depend on the instruction set a build targets: builds the library and
# bench_wrapped for the default x86-64, x86-64-v3 (AVX2, FMA) and x86-64-v4 (AVX-512) where this
# CPU runs them, each in build-flags-<name>/, and compares the wrapped reference case's state
# hash after 400 steps with the default build's. Prints one line a build; exit status 1 on a
# difference. About a minute a build on two cores (not in .ci/run for that reason).
# Usage: tools/check_flags.sh [steps]   (default 400)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
steps=${1:-400}
flags=(default "")
grep -qw avx2 /proc/cpuinfo && grep -qw fma /proc/cpuinfo && flags+=(v3 "-march=x86-64-v3")
grep -qw avx512f /proc/cpuinfo && grep -qw avx512vl /proc/cpuinfo && flags+=(v4 "-march=x86-64-v4")
want=""
bad=0
for ((i = 0; i < ${#flags[@]}; i += 2)); do
    name=${flags[i]} args=${flags[i + 1]} dir=build-flags-${flags[i]}
    if [[ -f $dir/meson-private/coredata.dat ]]; then
        meson setup --reconfigure "$dir" -Dtests=false -Dc_args="$args" >/dev/null 2>&1
    else
        meson setup "$dir" -Dtests=false -Dc_args="$args" >/dev/null 2>&1
    fi
    meson compile -C "$dir" bench/bench_wrapped >/dev/null
    hash=$("$dir/bench/bench_wrapped" "$steps" P | sed -n 's/.*state hash \([0-9a-f]*\).*/\1/p')
    fused=$(objdump -d "$dir"/lib/libwrapsim.so.*.p/*.o | grep -cE 'vfn?m(add|sub)' || true)
    [[ -z $want ]] && want=$hash
    verdict=same
    [[ $hash == "$want" ]] || { verdict=DIFFERENT; bad=1; }
    printf '%-8s %-22s state hash %s (%s), %s fused multiply-adds in the library\n' \
        "$name" "${args:-(none)}" "$hash" "$verdict" "$fused"
done
exit $bad
