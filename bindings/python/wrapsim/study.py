"""Parameter studies: many runs of one load file, each a task on a Dask distributed cluster.

A study varies keys of the load file (`--vary wrap.nodes_around=48,96`,
`--vary materials.carton_carton.mu=0.2:0.4` with `--samples N --seed S`). Every combination
(a grid), or every sample (Monte Carlo: a range `lo:hi` is drawn uniformly, a list picked from
at random, seeded), is one run. The runs go to a Dask scheduler: a LocalCluster on this
machine by default, or the one at `--scheduler ADDRESS`. Results are appended to
`results.csv` as runs finish, so an interrupted study keeps what it has; `resume` skips runs
whose id is already there. A run that fails (a numerical error, a bad combination) is a row
with its error, never the end of the study.
"""

import copy
import csv
import hashlib
import itertools
import json
import pathlib
import random

from .loadfile import LoadFileError, set_path, validate

RESULT_COLUMNS = ["run_id", "passed", "first_slip_angle_deg", "tip_angle_deg",
                  "elastic_displacement_mm", "permanent_displacement_mm", "k_value_g",
                  "state_hash", "error"]


def parse_vary(text):
    """`key=v1,v2` (a list), `key=lo:hi` (whole numbers lo..hi, or a range for sampling), or
    `key=lo:hi:n` (n evenly spaced values). Returns (key, values or (lo, hi))."""
    if "=" not in text:
        raise LoadFileError(f"--vary {text!r}: expected KEY=VALUES")
    key, spec = text.split("=", 1)
    try:
        if ":" in spec:
            parts = [float(p) for p in spec.split(":")]
            if len(parts) == 3:
                lo, hi, n = parts
                if n < 2 or not float(n).is_integer():
                    raise ValueError
                return key, [lo + (hi - lo) * i / (int(n) - 1) for i in range(int(n))]
            if len(parts) != 2:
                raise ValueError
            lo, hi = parts
            return key, ("range", lo, hi)
        return key, [json.loads(v) if v.strip() else v for v in spec.split(",")]
    except ValueError:
        raise LoadFileError(f"--vary {text!r}: expected KEY=v1,v2,..., KEY=lo:hi or "
                            f"KEY=lo:hi:n") from None


def _grid_values(key, values):
    if isinstance(values, tuple):
        _, lo, hi = values
        if not (float(lo).is_integer() and float(hi).is_integer()):
            raise LoadFileError(f"--vary {key}={lo:g}:{hi:g}: a grid needs whole numbers or "
                                f"lo:hi:n; a real range is for --samples")
        return list(range(int(lo), int(hi) + 1))
    return values


def plan(base, varies, samples=0, seed=0):
    """The runs of a study: a list of (run_id, {key: value}). A grid over every combination
    when samples is 0, else `samples` seeded random draws."""
    keys = [k for k, _ in varies]
    if samples:
        rng = random.Random(seed)
        combos = []
        for _ in range(samples):
            combo = []
            for key, values in varies:
                if isinstance(values, tuple):
                    combo.append(rng.uniform(values[1], values[2]))
                else:
                    combo.append(rng.choice(values))
            combos.append(combo)
    else:
        combos = itertools.product(*[_grid_values(k, v) for k, v in varies])
    runs = []
    for combo in combos:
        params = dict(zip(keys, combo))
        text = json.dumps(params, sort_keys=True)
        run_id = hashlib.sha1(text.encode()).hexdigest()[:12]
        runs.append((run_id, params))
    return runs


def run_one(base, params, kvalue=False):
    """One run of a study (executed on a worker): the base load file with `params` set; with
    `kvalue` the EUMOS k-value search instead of one run. Returns a row of RESULT_COLUMNS plus
    the parameters; never raises."""
    from . import loadrun
    row = dict.fromkeys(RESULT_COLUMNS, "")
    row.update(params)
    try:
        d = copy.deepcopy(base)
        for k, v in params.items():
            set_path(d, k, v)
        d = validate(d)
        if kvalue:
            from . import eumos
            if d["test"]["type"] != "eumos":
                raise LoadFileError("test.type: a k-value study needs 'eumos'")
            k = eumos.find_k(d)
            row.update(k_value_g=k["k_value_g"], passed=k["k_value_g"] >= d["test"]["k_g"])
            return row
        result, _ = loadrun.run(d)
        row.update(passed=result["passed"], state_hash=result["state_hash"])
        if result["test"] == "tilt":
            slips = [e["angle_deg"] for e in result["slip_events"].values() if e]
            row.update(first_slip_angle_deg=min(slips) if slips else "",
                       tip_angle_deg=(result["tip_event"]["angle_deg"]
                                      if result["tip_event"] else ""))
        else:
            c = {x["criterion"].split()[0]: x["measured"] for x in result["criteria"]}
            row.update(elastic_displacement_mm=c["largest"], permanent_displacement_mm=c["permanent"])
    except Exception as e:  # a failed run is a row, never the end of the study
        row.update(error=f"{type(e).__name__}: {e}")
    return row


def _done_ids(path):
    if not path.exists():
        return set()
    with open(path, newline="") as f:
        return {r["run_id"] for r in csv.DictReader(f)}


def sweep(base, varies, out, samples=0, seed=0, scheduler=None, workers=2, resume=False,
          progress=None, client=None, kvalue=False):
    """Run a study on Dask; append rows to out/results.csv as they finish. Returns the path.
    `progress(done, total)` is called after every run when given. `client`: a Dask client to
    use (and leave open) instead of connecting to `scheduler` or starting a LocalCluster."""
    from dask.distributed import Client, LocalCluster, as_completed

    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "results.csv"
    runs = plan(base, varies, samples, seed)
    keys = [k for k, _ in varies]
    if path.exists() and not resume:
        path.unlink()
    done = _done_ids(path)
    todo = [(rid, p) for rid, p in runs if rid not in done]
    cluster = None
    own_client = client is None
    if own_client and scheduler:
        client = Client(scheduler)
    elif own_client:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        new_file = not path.exists()
        with open(path, "a", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=RESULT_COLUMNS + keys)
            if new_file:
                writer.writeheader()
            futures = {client.submit(run_one, base, p, kvalue, pure=False): rid
                       for rid, p in todo}
            for n, fut in enumerate(as_completed(futures), 1):
                row = fut.result()
                row["run_id"] = futures[fut]
                writer.writerow(row)
                f.flush()
                if progress:
                    progress(n, len(todo))
    finally:
        if own_client:
            client.close()
        if cluster is not None:
            cluster.close()
    plot(path, keys, out / "results.png")
    return path


def plot(path, keys, png):
    """results.png: the k-value (or pass/fail) of every finished run against the first varied
    key, one marker a run (nothing without matplotlib)."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    with open(path, newline="") as f:
        rows = [r for r in csv.DictReader(f) if not r["error"]]
    if not rows or not keys:
        return

    def num(v):
        try:
            return float(v)
        except ValueError:
            return v

    x = [num(r[keys[0]]) for r in rows]
    fig, ax = plt.subplots(figsize=(7, 4))
    if all(r["k_value_g"] for r in rows):
        ax.plot(x, [float(r["k_value_g"]) for r in rows], "o")
        ax.set_ylabel("EUMOS k-value [g]")
    else:
        ok = [r["passed"] == "True" for r in rows]
        ax.plot([a for a, p in zip(x, ok) if p], [1] * sum(ok), "o", color="tab:green",
                label="pass")
        ax.plot([a for a, p in zip(x, ok) if not p], [0] * (len(ok) - sum(ok)), "x",
                color="tab:red", label="fail")
        ax.set_yticks([0, 1], ["fail", "pass"])
        ax.legend(fontsize=8)
    ax.set_xlabel(keys[0])
    ax.set_title(f"{len(rows)} runs")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
