"""The `wrapsim` command (also `python3 -m wrapsim`).

  wrapsim run LOAD.json [-o DIR] [--threads N]
                                      run a load file's test; the verdict on stdout, and in DIR
                                      verdict.json, timeseries.csv, PNG plots, report.html
  wrapsim kvalue LOAD.json [-o DIR] [--threads N]
                                      the EUMOS k-value search of a unit load
  wrapsim check LOAD.json             check a load file without running it
  wrapsim sweep LOAD.json --vary KEY=VALUES [...] [--samples N --seed S]
                [--scheduler ADDRESS] [--workers N] [-o DIR] [--resume]
                                      a study on a Dask cluster; rows in DIR/results.csv
  wrapsim schema                      the load file's JSON Schema
  wrapsim info                        the library in use: path, version, build features
A run steps on --threads workers, by default every core the command may use; its answers are
the same to the bit for any count. A sweep's runs take one each (the cluster's workers are the
cores).
Exit status: 0 pass (or success), 1 fail, 2 bad input.
"""

import argparse
import json
import sys

from . import _lib as L
from .loadfile import LoadFileError, json_schema, load, parse, validate


def _err(text):
    print(f"wrapsim: {text}", file=sys.stderr)
    return 2


# The library's bound on a world's workers (WS_MAX_WORKERS).
MAX_THREADS = 64


def default_threads():
    """The cores this process may run on (its affinity where the system says it), at most
    MAX_THREADS."""
    import os
    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        n = os.cpu_count() or 1
    return max(1, min(n, MAX_THREADS))


def _threads(args):
    """The run's workers from --threads, or None (with the message printed) when out of
    range."""
    n = default_threads() if args.threads is None else args.threads
    if not 1 <= n <= MAX_THREADS:
        _err(f"--threads: {n} is not between 1 and {MAX_THREADS}")
        return None
    return n


def _info(args):
    try:
        lib = L.lib()
    except L.LibraryError as e:
        return _err(e)
    features = lib.ws_build_features()
    names = [name for bit, name in ((L.WS_FEATURE_CCD, "libccd"), (L.WS_FEATURE_ZLIB, "zlib"))
             if features & bit]
    print(f"libwrapsim {lib.ws_version_string().decode()}")
    print(f"library:  {lib._wrapsim_path}")
    print(f"binding:  {L.BINDING_VERSION}")
    print(f"features: {', '.join(names) if names else 'none'}")
    return 0


def _check(args):
    try:
        d = load(args.load)
    except LoadFileError as e:
        return _err(e)
    print(f"{args.load}: a valid load file ({d['name']}, {d['test']['type']} test)")
    return 0


def _run(args):
    from . import loadrun, report
    try:
        d = load(args.load)
    except LoadFileError as e:
        return _err(e)
    threads = _threads(args)
    if threads is None:
        return 2
    out = args.output or "wrapsim-out"
    import os
    # The bar's label stays short so that the bar keeps to one line of a terminal.
    desc = d["name"] if len(d["name"]) <= 32 else d["name"][:31] + "…"
    result, series = loadrun.run(d, progress=not args.quiet, desc=desc,
                                 paraview=os.path.join(out, "paraview"), threads=threads)
    report.write_all(out, d, result, series)
    print(f"{d['name']}: {'PASS' if result['passed'] else 'FAIL'}")
    for c in result["criteria"]:
        m = "none" if c["measured"] is None else f"{c['measured']:.2f} {c['unit']}".rstrip()
        print(f"  {'pass' if c['passed'] else 'FAIL'}  {c['criterion']}: measured {m}")
    print(f"  outputs in {out}/ (report.html, verdict.json, timeseries.csv, paraview/run.pvd)")
    return 0 if result["passed"] else 1


def _sweep(args):
    from . import study
    try:
        base = parse(args.load)
        validate(base)
        varies = [study.parse_vary(v) for v in args.vary]
        runs = study.plan(base, varies, args.samples, args.seed)
    except LoadFileError as e:
        return _err(e)
    out = args.output or "wrapsim-sweep"

    def progress(n, total):
        if not args.quiet:
            sys.stderr.write(f"\rsweep: {n} of {total} runs")
            sys.stderr.flush()

    path = study.sweep(base, varies, out, args.samples, args.seed, args.scheduler,
                       args.workers, args.resume, progress, kvalue=args.kvalue)
    if not args.quiet:
        sys.stderr.write("\n")
    print(f"sweep: {len(runs)} runs; results in {path}")
    return 0


def _kvalue(args):
    from . import eumos
    try:
        d = load(args.load)
        if d["test"]["type"] != "eumos":
            raise LoadFileError("test.type: the k-value search needs 'eumos'")
    except LoadFileError as e:
        return _err(e)
    threads = _threads(args)
    if threads is None:
        return 2
    if not args.quiet:
        print(f"{d['name']}: EUMOS k-value search from {args.k_low:g} to {args.k_high:g} g "
              f"(to {args.tolerance:g} g)", file=sys.stderr)
    k = eumos.find_k(d, args.k_low, args.k_high, args.tolerance, threads)
    print(f"{d['name']}: k-value {k['k_value_g']:.3f} g (fails at {k['k_fail_g']:.3f} g; "
          f"{k['runs']} runs)")
    if args.output:
        import pathlib
        out = pathlib.Path(args.output)
        out.mkdir(parents=True, exist_ok=True)
        (out / "kvalue.json").write_text(json.dumps(k, indent=2) + "\n")
    return 0


def _schema(args):
    print(json.dumps(json_schema(), indent=2))
    return 0


def build_parser():
    """The argument parser of the command (exposed for the tests and the docs)."""
    parser = argparse.ArgumentParser(
        prog="wrapsim",
        description="Simulation of stretch-wrapped loads: run a load file through its test.")
    parser.add_argument("--version", action="version",
                        version=f"wrapsim (binding) {L.BINDING_VERSION}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    p = sub.add_parser("run", help="run a load file's test; write the verdict and a report")
    p.add_argument("load", help="the load file (JSON, or YAML with python3-yaml)")
    p.add_argument("-o", "--output", help="output folder (default wrapsim-out)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.add_argument("--threads", type=int, metavar="N",
                   help="workers a step uses (default: every core this command may use)")
    p.set_defaults(func=_run)
    p = sub.add_parser("kvalue", help="the EUMOS k-value: the largest k g the load passes")
    p.add_argument("load")
    p.add_argument("--k-low", type=float, default=0.05, help="lowest k tried, g")
    p.add_argument("--k-high", type=float, default=1.0, help="highest k tried, g")
    p.add_argument("--tolerance", type=float, default=0.01, help="bracket width, g")
    p.add_argument("-o", "--output", help="folder for kvalue.json")
    p.add_argument("-q", "--quiet", action="store_true")
    p.add_argument("--threads", type=int, metavar="N",
                   help="workers a step uses (default: every core this command may use)")
    p.set_defaults(func=_kvalue)
    p = sub.add_parser("check", help="check a load file without running it")
    p.add_argument("load")
    p.set_defaults(func=_check)
    p = sub.add_parser("sweep", help="a parameter study on a Dask cluster")
    p.add_argument("load")
    p.add_argument("--vary", action="append", required=True, metavar="KEY=VALUES",
                   help="a key of the load file and its values: v1,v2,... or lo:hi (whole "
                        "numbers; a uniform range with --samples) or lo:hi:n")
    p.add_argument("--samples", type=int, default=0, help="Monte Carlo: this many draws")
    p.add_argument("--seed", type=int, default=0, help="seed of the draws")
    p.add_argument("--scheduler", help="address of a Dask scheduler (default: a LocalCluster)")
    p.add_argument("--workers", type=int, default=2, help="workers of the LocalCluster")
    p.add_argument("-o", "--output", help="output folder (default wrapsim-sweep)")
    p.add_argument("--resume", action="store_true", help="skip the runs already in results.csv")
    p.add_argument("--kvalue", action="store_true",
                   help="each run is an EUMOS k-value search (eumos load files)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress")
    p.set_defaults(func=_sweep)
    p = sub.add_parser("schema", help="print the load file's JSON Schema")
    p.set_defaults(func=_schema)
    p = sub.add_parser("info", help="the library in use: path, version, build features")
    p.set_defaults(func=_info)
    return parser


def main(argv=None):
    """Run the command with `argv` (default sys.argv[1:]); return the exit status."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:  # argparse: 0 for --help/--version, 2 for bad arguments
        return e.code
    if not getattr(args, "func", None):
        parser.print_help(sys.stderr)
        return 2
    return args.func(args)
