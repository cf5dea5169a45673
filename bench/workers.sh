#!/bin/sh
# Workers: the wrapped reference case at 1, 2 and 4 workers and the plain loop (bench_plain, one
# core), without and with contacts, run one after another in interleaved rounds, so that a
# machine whose speed drifts drifts across all of them alike. Prints each round's wall times,
# the ratios 1→2 (speed-up) and 2-workers / plain, and their medians; the last also per
# node-update (the wrapped case takes its film's sub-steps a step, the plain loop one; the
# plain loop with contacts takes them too, so its node-updates are the case's). A figure, not a test: it never fails on time. The
# runs take the whole machine in turn (a run at 2 workers needs 2 free cores): say how loaded
# it was (uptime) next to the figures.
#
# With a second build directory, each round runs both builds, in turn first (A B, then B A),
# and the figures of each are printed apart, with the median over the rounds of the second's
# 2-worker time over the first's: a change measured against the build it changes. Each round
# starts with the load (the last minute's) and the hand-over price between the cores
# (bench_pingpong, when built), since a round whose second core was busy says nothing of either.
#
# Usage: bench/workers.sh [build dir] [rounds] [steps] [second build dir]
#   build dir  default build; rounds default 5; steps default 24000
# Needs GNU time at /usr/bin/time (Debian: time).
set -eu
dir=${1:-build}
rounds=${2:-5}
steps=${3:-24000}
other=${4:-}
for d in "$dir" $other; do
    for prog in "$d/bench/bench_wrapped" "$d/bench/bench_plain"; do
        [ -x "$prog" ] || { echo "workers.sh: $prog is not an executable program" >&2; exit 2; }
    done
done
[ -x /usr/bin/time ] || { echo "workers.sh: needs GNU time at /usr/bin/time" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
w=$dir/bench/bench_wrapped
subs=$("$w" 1 P 1 | sed -n 's/.* x \([0-9]*\) sub-step.*/\1/p')
echo "load before: $(uptime); the wrapped case's film takes ${subs:=1} sub-step(s) a step"
# The hand-over price between the two cores (bench_pingpong.c): it moves the 1->2 figure, and on
# a virtual machine it changes with where the host puts the cores.
pp=$dir/bench/bench_pingpong
handover() {
    if [ -x "$pp" ]; then "$pp" "$1" | sed -n 's/.*round trip \([0-9.]*\) ns.*/\1/p'; else echo -; fi
}
echo "hand-over before: $(handover 500000) ns"
# One build's five runs: prints their wall times.
runs() {
    /usr/bin/time -f %e -o "$tmp/1" "$1/bench/bench_wrapped" "$steps" P 1 >/dev/null
    /usr/bin/time -f %e -o "$tmp/2" "$1/bench/bench_wrapped" "$steps" P 2 >/dev/null
    /usr/bin/time -f %e -o "$tmp/4" "$1/bench/bench_wrapped" "$steps" P 4 >/dev/null
    /usr/bin/time -f %e -o "$tmp/p" "$1/bench/bench_plain" "$steps" >/dev/null
    /usr/bin/time -f %e -o "$tmp/c" "$1/bench/bench_plain" "$steps" law 1 contacts >/dev/null
    echo "$(cat "$tmp/1") $(cat "$tmp/2") $(cat "$tmp/4") $(cat "$tmp/p") $(cat "$tmp/c")"
}
r=1
while [ "$r" -le "$rounds" ]; do
    state="$(cut -d' ' -f1 /proc/loadavg) $(handover 100000)"
    if [ -z "$other" ]; then
        echo "A $state $(runs "$dir")"
    elif [ $((r % 2)) -eq 1 ]; then
        a=$(runs "$dir")
        echo "A $state $a"
        echo "B $state $(runs "$other")"
    else
        b=$(runs "$other")
        echo "A $state $(runs "$dir")"
        echo "B $state $b"
    fi
    r=$((r + 1))
done | awk -v subs="$subs" -v a="$dir" -v b="$other" '
    { k = $1; n[k]++; i = n[k];
      printf "round %d %s: load %s, hand-over %s ns; 1 worker %.2f s, 2 workers %.2f s, " \
             "4 workers %.2f s, plain %.2f s, plain with contacts %.2f s; 1->2 %.2fx, " \
             "1->4 %.2fx, 2 workers / plain %.3f\n",
             i, (k == "A" ? a : b), $2, $3, $4, $5, $6, $7, $8, $4 / $5, $4 / $6, $5 / $7;
      s[k, i] = $4 / $5; f[k, i] = $4 / $6; q[k, i] = $5 / $7; o[k, i] = $4 / $7; t2[k, i] = $5
      qc[k, i] = $5 / $8; oc[k, i] = $4 / $8 }
    function med(a, k, m, i, j, t, v) {
        for (i = 1; i <= m; i++) v[i] = a[k, i];
        for (i = 1; i <= m; i++) for (j = i + 1; j <= m; j++)
            if (v[j] < v[i]) { t = v[i]; v[i] = v[j]; v[j] = t }
        return m % 2 ? v[(m + 1) / 2] : (v[m / 2] + v[m / 2 + 1]) / 2 }
    END {
        for (kk = 1; kk <= 2; kk++) {
            k = kk == 1 ? "A" : "B";
            if (!n[k]) continue;
            m = n[k];
            printf "median %s: 1->2 speed-up %.2fx, 1->4 %.2fx, 2 workers / plain %.3f, " \
                   "1 worker / plain %.3f (%d rounds)\n", (k == "A" ? a : b),
                   med(s, k, m), med(f, k, m), med(q, k, m), med(o, k, m), m;
            printf "per node-update %s: 2 workers / plain %.3f, 1 worker / plain %.3f\n",
                   (k == "A" ? a : b), med(q, k, m) / subs, med(o, k, m) / subs
            printf "per node-update %s: 2 workers / plain with contacts %.3f, 1 worker / " \
                   "plain with contacts %.3f\n", (k == "A" ? a : b), med(qc, k, m),
                   med(oc, k, m) }
        if (n["B"]) {
            for (i = 1; i <= n["B"]; i++) rr["R", i] = t2["B", i] / t2["A", i];
            printf "median of the rounds %s / %s, 2 workers: %.3f\n", b, a, med(rr, "R", n["B"]) } }'
echo "load after: $(uptime)"
echo "hand-over after: $(handover 500000) ns"
