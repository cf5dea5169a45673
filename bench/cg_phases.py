#!/usr/bin/env python3
"""Instructions and cache misses per node-update by phase of the film's step, from cachegrind.

Two runs of the same program that differ only in their steps (say, `bench_refine window` of
80 and 480 steps from the same saved state) are subtracted, so the build, the restore and the
first steps drop out and what is left is the settled window alone; each event is divided by
the window's node-updates (nodes x sub-steps x steps). Functions are grouped into the phases
of a step by name. A figure, not a test.

Usage: bench/cg_phases.py SHORT.out LONG.out NODE_UPDATES [SHORT.out LONG.out NODE_UPDATES]
  (the cachegrind output files of the two runs, --cache-sim=yes for the miss columns; with a
  second triple, the two cases side by side and their ratio)
"""
import sys

PHASES = [
    "springs", "node contacts", "integration", "move test, candidates",
    "loads on the bodies", "memset, memcpy", "bodies, the step, other",
]


def phase(path, fn):
    """The phase of a function by its file and name (the clone suffix dropped)."""
    f = fn.split(".")[0]
    if f in ("advance_same", "advance_each", "advance_of", "ws_web_integrate_block"):
        return "integration"
    if f == "ws_node_loads":
        return "loads on the bodies"
    if path.endswith("contact/node.c") or f in ("in_wedge", "ws_node_prepare"):
        return "move test, candidates"
    if path.endswith("node_force.c") or f in (
            "ws_node_contacts", "contacts_general", "run_flush", "run_depth", "shallowest"):
        return "node contacts"
    if path.endswith("web/web.c"):
        return "springs"
    if "mem" in f and ("cpy" in f or "set" in f or "move" in f):
        return "memset, memcpy"
    return "bodies, the step, other"


def load(name):
    """Events by (file, function) of a cachegrind output file, and the event names."""
    rows, events, fl, fn = {}, [], "", ""
    with open(name) as f:
        for line in f:
            if line.startswith("events:"):
                events = line.split()[1:]
            elif line.startswith("fl="):
                fl = line[3:].strip()
            elif line.startswith("fn="):
                fn = line[3:].strip()
            elif line[:1].isdigit():
                v = [int(x) for x in line.split()[1:]]
                v += [0] * (len(events) - len(v))
                acc = rows.setdefault((fl, fn), [0] * len(events))
                for i, x in enumerate(v):
                    acc[i] += x
    return rows, events


def per_phase(short, long_, updates):
    a, events = load(short)
    b, _ = load(long_)
    out = {p: [0.0] * len(events) for p in PHASES}
    for key, v in b.items():
        w = a.get(key, [0] * len(v))
        acc = out[phase(*key)]
        for i in range(len(v)):
            acc[i] += (v[i] - w[i]) / updates
    return out, events


def columns(events):
    """Ir, D1 misses (read + write) and LL misses (read + write), as far as recorded."""
    ix = {e: i for i, e in enumerate(events)}
    cols = [("Ir", lambda v: v[ix["Ir"]])]
    if "D1mr" in ix:
        cols.append(("D1 miss", lambda v: v[ix["D1mr"]] + v[ix["D1mw"]]))
        cols.append(("LL miss", lambda v: v[ix["DLmr"]] + v[ix["DLmw"]]))
    return cols


def main(argv):
    if len(argv) not in (4, 7):
        sys.stderr.write(__doc__)
        return 2
    cases = [per_phase(argv[1], argv[2], float(argv[3]))]
    if len(argv) == 7:
        cases.append(per_phase(argv[4], argv[5], float(argv[6])))
    cols = columns(cases[0][1])
    head = "%-26s" % "per node-update"
    for name, _ in cols:
        head += " | " + " ".join("%9s" % (name if len(cases) == 1 else name + " " + c)
                                  for c in "AB"[:len(cases)])
        if len(cases) == 2:
            head += " %6s" % "B/A"
    print(head)
    for p in PHASES + ["total"]:
        line = "%-26s" % p
        for _, get in cols:
            vals = []
            for out, _ in cases:
                v = ([sum(x) for x in zip(*out.values())] if p == "total" else out[p])
                vals.append(get(v))
            line += " | " + " ".join("%9.3f" % x for x in vals)
            if len(cases) == 2:
                line += " %6.2f" % (vals[1] / vals[0] if vals[0] else float("nan"))
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
