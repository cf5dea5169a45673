#!/bin/sh
# Compares two builds of a benchmark on a machine whose speed drifts (shared or virtual): runs
# them at the same time, one on each of two cores, swapping the cores every round, so that both
# see the same drift. Prints each round's user seconds and their ratio B / A, then the median
# ratio and how many rounds B was faster. A figure, not a test: it never fails on time.
#
# Usage: bench/compare.sh A B [rounds] [args...]
#   A, B     two benchmark programs (say, build/bench/bench_wrapped of two checkouts)
#   rounds   default 8
#   args     passed to both (say, 24000 for bench_wrapped's steps)
# Needs two cores, taskset (util-linux) and GNU time at /usr/bin/time (Debian: time).
set -eu
if [ $# -lt 2 ]; then
    sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
a=$1
b=$2
rounds=${3:-8}
if [ $# -ge 3 ]; then shift 3; else shift 2; fi
for prog in "$a" "$b"; do
    [ -x "$prog" ] || { echo "compare.sh: $prog is not an executable program" >&2; exit 2; }
done
command -v taskset >/dev/null || { echo "compare.sh: needs taskset (util-linux)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "compare.sh: needs GNU time at /usr/bin/time" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
r=1
while [ "$r" -le "$rounds" ]; do
    if [ $((r % 2)) -eq 1 ]; then ca=0; cb=1; else ca=1; cb=0; fi
    /usr/bin/time -f %U -o "$tmp/a" taskset -c $ca "$a" "$@" >/dev/null 2>&1 &
    pa=$!
    /usr/bin/time -f %U -o "$tmp/b" taskset -c $cb "$b" "$@" >/dev/null 2>&1 &
    pb=$!
    wait $pa || { echo "compare.sh: $a failed" >&2; exit 1; }
    wait $pb || { echo "compare.sh: $b failed" >&2; exit 1; }
    echo "$(cat "$tmp/a") $(cat "$tmp/b")"
    r=$((r + 1))
done | awk '$1 <= 0 || $2 <= 0 { printf "round %d: too short to time\n", NR; next }
            { q = $2 / $1; printf "round %d: A %.2f s, B %.2f s, B/A %.3f\n", NR, $1, $2, q;
              ratio[++n] = q; faster += (q < 1) }
            END { if (n == 0) { print "no round could be timed: give more steps"; exit 1 }
                  for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++)
                      if (ratio[j] < ratio[i]) { t = ratio[i]; ratio[i] = ratio[j]; ratio[j] = t }
                  med = n % 2 ? ratio[(n + 1) / 2] : (ratio[n / 2] + ratio[n / 2 + 1]) / 2;
                  printf "median B/A %.3f (%.3f to %.3f); B faster in %d of %d rounds\n",
                         med, ratio[1], ratio[n], faster, n }'
