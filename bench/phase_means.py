#!/usr/bin/env python3
"""Case R's phases from `bench_implicit phases` logs, side by side.

Usage: bench/phase_means.py LOG [LOG...]

Each log holds lines `r R  t T s  CG X it/step  most M  C s CPU per simulated s` (with
WS_BENCH_WORKERS, `C s CPU and W s wall per simulated s`), one per 50 ms window. Prints, per phase of case R (the band's pull-in, the settling, the rest before the tilt,
the first tilt, the later tilt, the whole run), the windows' mean CG iterations a step and CPU
seconds a simulated second for each log, and each later log's ratios to the first (iterations,
CPU), and a last row over the range every log reached when one stopped early. A phase a log did not finish is left blank; a log that stopped partway says how far it got.
A figure, not a test: the CPU columns are only comparable between runs made side by side.
"""
import re
import sys

PHASES = [("pull-in", 0.0, 0.05), ("settling", 0.05, 0.7), ("0.7-1.0 s", 0.7, 1.0),
          ("tilt", 1.0, 2.6), ("later tilt", 2.6, 5.9), ("whole run", 0.0, 5.9)]
LINE = re.compile(r"r (\d+)\s+t ([\d.]+) s\s+CG ([\d.]+) it/step.*?([\d.]+) s CPU"
                  r"(?: and [\d.]+ s wall)? per simulated s")


def read(path):
    rows, r = [], None
    with open(path) as f:
        for text in f:
            m = LINE.search(text)
            if m:
                r = int(m.group(1))
                rows.append(tuple(float(g) for g in m.groups()[1:]))
    return r, rows


def means(rows, lo, hi):
    if not rows or rows[-1][0] < hi - 1e-9:
        return None  # the log did not reach the phase's end
    w = [row for row in rows if lo + 1e-9 < row[0] <= hi + 1e-9]
    if not w:
        return None
    return sum(x[1] for x in w) / len(w), sum(x[2] for x in w) / len(w), len(w)


def main(paths):
    if not paths:
        print(__doc__.strip())
        return 2
    logs = [read(p) for p in paths]
    logs = [(r if r is not None else "?", rows) for r, rows in logs]  # "?": no window yet
    head = "%-12s" % "phase"
    for r, _ in logs:
        head += "  %9s %9s" % ("r%s it" % r, "CPU")
    for r, _ in logs[1:]:
        head += "  %13s" % ("r%s/r%s it,CPU" % (r, logs[0][0]))
    print(head)
    end = min(rows[-1][0] for _, rows in logs if rows) if all(rows for _, rows in logs) else 0.0
    phases = list(PHASES)
    if 0.0 < end < PHASES[-1][2] - 1e-9:
        phases.append(("to %.2f s" % end, 0.0, end))  # the range every log reached
    for name, lo, hi in phases:
        line = "%-12s" % name
        got = [means(rows, lo, hi) for _, rows in logs]
        for g in got:
            line += "  %9.2f %9.1f" % g[:2] if g else "  %9s %9s" % ("", "")
        for g in got[1:]:
            b = got[0]
            line += "  %6.2f %6.2f" % (g[0] / b[0], g[1] / b[1]) if g and b else "  %13s" % ""
        print(line)
    for path, (r, rows) in zip(paths, logs):
        if rows and rows[-1][0] < PHASES[-1][2] - 1e-9:
            print("%s: r %s stopped at t = %.2f s" % (path, r, rows[-1][0]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
