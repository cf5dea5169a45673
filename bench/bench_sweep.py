#!/usr/bin/env python3
"""bench_sweep.py: throughput of `wrapsim sweep` on a Dask LocalCluster at 1 and 2 workers.

A study of N runs of the shipped load file examples/loads/two_cubes_R.json, each shortened to
DURATION simulated seconds and made distinct by its carton-carton friction (0.25..0.35), run
first on one worker and then on two (alternating, ROUNDS times, since this machine's speed
drifts), printing runs per minute (the cluster's start left out) for each and the ratio. A figure, never a test.

  PYTHONPATH=bindings/python WRAPSIM_LIBRARY=build/lib/libwrapsim.so.0 \\
      /usr/bin/python3 bench/bench_sweep.py [N] [DURATION] [ROUNDS]
"""

import json
import pathlib
import statistics
import sys
import tempfile
import time

from wrapsim import study

ROOT = pathlib.Path(__file__).resolve().parents[1]


def one(base, varies, workers):
    """Wall time of the study's runs on a LocalCluster of `workers` processes, the cluster's
    start and a warm-up run on every worker left out."""
    from dask.distributed import Client, LocalCluster
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client, \
            tempfile.TemporaryDirectory() as out:
        client.run(lambda: __import__("wrapsim").version())  # load the library everywhere
        t0 = time.monotonic()
        study.sweep(base, varies, out, client=client)
        return time.monotonic() - t0


def main(argv):
    n = int(argv[1]) if len(argv) > 1 else 16
    duration = float(argv[2]) if len(argv) > 2 else 2.0
    rounds = int(argv[3]) if len(argv) > 3 else 2
    base = json.loads((ROOT / "examples/loads/two_cubes_R.json").read_text())
    base["test"]["duration_s"] = duration
    values = ",".join(f"{0.25 + 0.1 * i / max(n - 1, 1):.6f}" for i in range(n))
    varies = [study.parse_vary(f"materials.carton_carton.mu={values}")]
    times = {1: [], 2: []}
    for _ in range(rounds):
        for workers in (1, 2):
            times[workers].append(one(base, varies, workers))
    rate = {k: 60.0 * n / statistics.median(v) for k, v in times.items()}
    print(f"sweep of {n} runs of {duration:g} s simulated each, {rounds} rounds")
    for k in (1, 2):
        print(f"  {k} worker{'s' if k > 1 else ''}: {rate[k]:.1f} runs/min "
              f"(times {', '.join(f'{t:.1f}' for t in times[k])} s)")
    print(f"  speed-up 1 -> 2 workers: {rate[2] / rate[1]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
