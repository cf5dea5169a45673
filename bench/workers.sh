#!/bin/sh
# Workers: the wrapped reference case at 1, 2 and 4 workers and the plain loop (bench_plain, one
# core), run one after another in interleaved rounds, so that a machine whose speed drifts
# drifts across all of them alike. Prints each round's wall times, the ratios 1→2 (speed-up)
# and 2-workers / plain, and their medians; the last also per node-update (the wrapped case
# takes its film's sub-steps a step, the plain loop one). A figure, not a test: it never fails on time. The
# runs take the whole machine in turn (a run at 2 workers needs 2 free cores): say how loaded
# it was (uptime) next to the figures.
#
# Usage: bench/workers.sh [build dir] [rounds] [steps]
#   build dir  default build; rounds default 5; steps default 24000
# Needs GNU time at /usr/bin/time (Debian: time).
set -eu
dir=${1:-build}
rounds=${2:-5}
steps=${3:-24000}
w=$dir/bench/bench_wrapped
p=$dir/bench/bench_plain
for prog in "$w" "$p"; do
    [ -x "$prog" ] || { echo "workers.sh: $prog is not an executable program" >&2; exit 2; }
done
[ -x /usr/bin/time ] || { echo "workers.sh: needs GNU time at /usr/bin/time" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
subs=$("$w" 1 P 1 | sed -n 's/.* x \([0-9]*\) sub-step.*/\1/p')
echo "load before: $(uptime); the wrapped case's film takes ${subs:=1} sub-step(s) a step"
# The hand-over price between the two cores (bench_pingpong.c): it moves the 1->2 figure, and on
# a virtual machine it changes with where the host puts the cores.
pp=$dir/bench/bench_pingpong
if [ -x "$pp" ]; then echo "before: $("$pp" 500000)"; fi
r=1
while [ "$r" -le "$rounds" ]; do
    /usr/bin/time -f %e -o "$tmp/1" "$w" "$steps" P 1 >/dev/null
    /usr/bin/time -f %e -o "$tmp/2" "$w" "$steps" P 2 >/dev/null
    /usr/bin/time -f %e -o "$tmp/4" "$w" "$steps" P 4 >/dev/null
    /usr/bin/time -f %e -o "$tmp/p" "$p" "$steps" >/dev/null
    echo "$(cat "$tmp/1") $(cat "$tmp/2") $(cat "$tmp/4") $(cat "$tmp/p")"
    r=$((r + 1))
done | awk -v subs="$subs" '{ printf "round %d: 1 worker %.2f s, 2 workers %.2f s, 4 workers %.2f s, plain %.2f s;" \
                     " 1->2 %.2fx, 1->4 %.2fx, 2 workers / plain %.3f\n",
                     NR, $1, $2, $3, $4, $1 / $2, $1 / $3, $2 / $4;
              s[NR] = $1 / $2; f[NR] = $1 / $3; q[NR] = $2 / $4; o[NR] = $1 / $4; n = NR }
            function med(a, i, j, t) {
                for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++)
                    if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
                return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2 }
            END { printf "median: 1->2 speed-up %.2fx, 1->4 %.2fx, 2 workers / plain %.3f, " \
                         "1 worker / plain %.3f (%d rounds)\n", med(s), med(f), med(q), med(o), n;
                  printf "per node-update: 2 workers / plain %.3f, 1 worker / plain %.3f\n",
                         med(q) / subs, med(o) / subs }'
echo "load after: $(uptime)"
if [ -x "$pp" ]; then echo "after: $("$pp" 500000)"; fi
