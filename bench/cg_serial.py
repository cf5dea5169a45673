#!/usr/bin/env python3
"""The serial part of a step with workers, from callgrind: instructions on the world's thread
outside the pool's tasks, against those in the tasks (the lanes' sweep, the move test, the
search of node candidates in pieces), per node-update, and the bound on two workers' speed-up it
implies (Amdahl). Callgrind runs the threads one at a time, so the counts do not depend on how
loaded the machine is.

Two runs of the same program that differ only in their steps (say `bench_refine window 1 FILE
80 2` and `... 480 2` from the same saved state) are subtracted, so that the build, the restore
and the first steps drop out. Serial: the inclusive count of ws_world_step less that of
ws_pool_run (the world's thread's share of the tasks and its wait for their end); tasks: the
inclusive counts of the task functions on either thread. valgrind counts each byte a `rep stosb`
writes as an instruction, so a large memset weighs more here than in time. A figure, not a test.

Usage: bench/cg_serial.py SHORT.out LONG.out NODE_UPDATES
  (callgrind output files; NODE_UPDATES: nodes x sub-steps x the steps between the two runs)
"""
import re
import subprocess
import sys

TASKS = ("lane_items", "flag_items", "search_items")


def inclusive(name):
    """Inclusive instruction counts by function name of a callgrind output file."""
    out = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", name],
                         capture_output=True, text=True, check=True).stdout
    counts = {}
    for line in out.splitlines():
        m = re.match(r"^\s*([\d,]+) \(\s*[\d.]+%\)\s+\S+:(\w+) \[", line)
        if m:
            counts[m.group(2)] = counts.get(m.group(2), 0) + int(m.group(1).replace(",", ""))
    return counts


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    short, long_, updates = inclusive(sys.argv[1]), inclusive(sys.argv[2]), float(sys.argv[3])
    diff = lambda f: long_.get(f, 0) - short.get(f, 0)
    serial = diff("ws_world_step") - diff("ws_pool_run")
    tasks = sum(diff(f) for f in TASKS)
    s = serial / (serial + tasks)
    print("per node-update: %.1f = tasks %.1f + serial %.1f; serial %.1f %%; "
          "Amdahl bound at 2 workers %.2fx" % ((serial + tasks) / updates, tasks / updates,
                                              serial / updates, 100 * s, 1 / (s + (1 - s) / 2)))


if __name__ == "__main__":
    main()
