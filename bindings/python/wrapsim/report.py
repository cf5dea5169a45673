"""What `wrapsim run` leaves in its output folder: verdict.json, timeseries.csv (units in every
header), PNG plots (with matplotlib) and report.html, one page to file."""

import html
import json
import pathlib

import numpy as np


def _unit_header(col):
    """`carton1_slip_mm` -> `carton1_slip [mm]`: the unit in every header."""
    if col.endswith(("_friction_use", "_tan_theta")):
        return f"{col} [1]"
    for suffix, unit in (("_mm_per_s", "mm/s"), ("_mm", "mm"), ("_deg", "deg"),
                         ("_m_per_s", "m/s"), ("_g", "g"),
                         ("_s", "s"), ("_N", "N")):
        if col.endswith(suffix):
            return f"{col[:-len(suffix)]} [{unit}]"
    return col


def write_series(path, series):
    cols = list(series)
    data = np.column_stack([series[c] for c in cols])
    header = ",".join(_unit_header(c) for c in cols)
    np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.9g")


def _finish(plt, fig, ax, path, labels, legend=True):
    """Label, grid, legend, save and close one plot; `labels` = (x, y, title)."""
    ax.set_xlabel(labels[0])
    if labels[1]:
        ax.set_ylabel(labels[1])
    ax.set_title(labels[2])
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path.name


def _eumos_plots(plt, folder, d, result, series):
    t = series["t_s"]
    H = 1e3 * result["load_height_m"]
    names = []
    fig, ax = plt.subplots(figsize=(8, 4.5))
    k = 1
    while f"layer{k}_displacement_mm" in series:
        ax.plot(t, series[f"layer{k}_displacement_mm"], label=f"layer {k}")
        k += 1
    for sign in (1, -1):
        ax.axhline(sign * 0.10 * H, color="tab:red", ls="--", lw=1,
                   label="elastic limit 10 % H" if sign > 0 else None)
        ax.axhline(sign * 0.05 * H, color="tab:orange", ls=":", lw=1,
                   label="permanent limit 5 % H" if sign > 0 else None)
    for e in result["events"]:
        ax.axvline(e["t_s"], color="0.6", lw=0.6)
    names.append(_finish(plt, fig, ax, folder / "displacement.png", (
        "time [s]", "layer displacement relative to the pallet [mm]",
        f"EUMOS 40509 at {result['k_g']:g} g: layers against the pallet "
        f"(grey: slip, tip and loss events)")))

    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot(t, series["platform_acceleration_g"], label="delivered")
    ax.axhline(result["k_g"], color="0.3", ls=":", lw=1, label=f"k = {result['k_g']:g} g")
    names.append(_finish(plt, fig, ax, folder / "drive.png", (
        "time [s]", "platform acceleration [g]",
        f"The drive as delivered: rise {1e3 * result['rise_measured_s']:.1f} ms, "
        f"held {result['time_at_level_s']:.3f} s within 1 %")))

    if any(c["line_load_N_per_m"] > 0 for c in result["containment"]):
        fig, ax = plt.subplots(figsize=(6, 4))
        bands = [c["band"] for c in result["containment"]]
        ax.barh(bands, [c["line_load_N_per_m"] for c in result["containment"]])
        names.append(_finish(plt, fig, ax, folder / "containment.png",
                             ("containment [N/m]", "", "Film containment by height"),
                             legend=False))
    return names


_EVENT_COLOURS = {"slip onset": "tab:orange", "tip onset": "tab:red", "carton lost": "black",
                  "film rupture": "tab:purple"}


def _mark_events(ax, events):
    """A vertical line at each event, coloured by its kind, each kind once in the legend."""
    seen = set()
    for e in events:
        kind = e["event"]
        ax.axvline(e["t_s"], color=_EVENT_COLOURS.get(kind, "0.5"), lw=0.8, ls="--",
                   label=kind if kind not in seen else None)
        seen.add(kind)


def _loadtest_plots(plt, folder, d, result, series):
    """Tilt (of a unit load), impact and vibration: the layers' displacement with the events,
    the drive as delivered, the interfaces' friction use, and a sweep's response."""
    t = series["t_s"]
    H = 1e3 * result["load_height_m"]
    kind = result["test"]
    title = {"tilt": "Tilt (ISO 10531)", "impact": "Horizontal impact",
             "vibration": f"Vibration ({result.get('vibration', '')})"}[kind]
    names = []
    fig, ax = plt.subplots(figsize=(8, 4.5))
    k = 1
    while f"layer{k}_displacement_mm" in series:
        ax.plot(t, series[f"layer{k}_displacement_mm"], label=f"layer {k}")
        k += 1
    if kind == "impact":
        ax.axhline(0.05 * H, color="tab:orange", ls=":", lw=1, label="permanent limit 5 % H")
    _mark_events(ax, result["events"])
    along = "vertical" if kind == "vibration" else "along the drive"
    names.append(_finish(plt, fig, ax, folder / "displacement.png", (
        "time [s]", f"layer displacement relative to the pallet, {along} [mm]",
        f"{title}: layers against the pallet, with the events")))

    fig, ax = plt.subplots(figsize=(8, 4.5))
    if kind == "tilt":
        ax.plot(t, series["platform_angle_deg"], label="platform angle")
        ax.axhline(result["target_angle_deg"], color="0.3", ls=":", lw=1,
                   label=f"target {result['target_angle_deg']:g}°")
        _mark_events(ax, result["events"])
        labels = ("time [s]", "platform angle [deg]", "The tilt as delivered")
    else:
        ax.plot(t, series["platform_acceleration_g"], lw=0.8, label="delivered")
        if kind == "impact":
            sub = (f"velocity change {result['velocity_change_m_per_s']:.4f} m/s of "
                   f"{result['impact_speed_m_per_s']:.4f}, peak "
                   f"{result['peak_deceleration_g']:.2f} g")
        elif result.get("vibration") == "random":
            sub = (f"{result['grms_delivered_g']:.3f} Grms delivered of "
                   f"{result['grms_target_g']:.3f}")
        else:
            sub = f"sweep {d['test']['sweep_from_hz']:g}-{d['test']['sweep_to_hz']:g} Hz"
        labels = ("time [s]", "platform acceleration [g]", f"The drive as delivered: {sub}")
    names.append(_finish(plt, fig, ax, folder / "drive.png", labels))

    fig, ax = plt.subplots(figsize=(8, 4.5))
    i = 0
    while f"interface{i}_friction_use" in series:
        name = "pallet on platform" if i == 0 else (
            "layer 1 on pallet" if i == 1 else f"layer {i} on layer {i - 1}")
        ax.plot(t, series[f"interface{i}_friction_use"], lw=0.8, label=name)
        i += 1
    names.append(_finish(plt, fig, ax, folder / "friction_use.png", (
        "time [s]", "friction use |Ft| / (mu Fn)", "Friction use of each interface")))

    if result.get("vibration") == "sweep":
        fig, ax = plt.subplots(figsize=(8, 4.5))
        ax.semilogx(result["response_hz"], result["response_transmissibility"], "o-", ms=3,
                    label="top layer / platform")
        if result["resonance_hz"] > 0:
            ax.axvline(result["resonance_hz"], color="tab:red", ls="--", lw=1,
                       label=f"resonance {result['resonance_hz']:.2f} Hz")
        names.append(_finish(plt, fig, ax, folder / "response.png", (
            "frequency [Hz]", "transmissibility", "The load's response to the sweep")))
    return names


def write_plots(folder, d, result, series):
    """The plots as PNG files; returns their names (none without matplotlib)."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return []
    if result["test"] == "eumos":
        return _eumos_plots(plt, folder, d, result, series)
    if result.get("form") == "unit_load":
        return _loadtest_plots(plt, folder, d, result, series)
    t, angle = series["t_s"], series["platform_angle_deg"]
    n = d["stack"]["layers"]
    target = result["target_angle_deg"]
    names = []

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for k in range(n):
        ax.plot(angle, series[f"carton{k + 1}_relative_slip_mm"],
                label=f"carton {k + 1}, relative to what it stands on")
    lim = d["test"]["slip_limit_mm"]
    ax.axhline(lim, color="tab:red", ls="--", lw=1, label=f"slip limit {lim:g} mm")
    ax.axvline(target, color="0.3", ls=":", lw=1, label=f"target {target:g}°")
    for name, ev in result["slip_events"].items():
        if ev:
            ax.axvline(ev["angle_deg"], color="tab:orange", lw=0.8)
    ax.set_ylim(min(-1.0, ax.get_ylim()[0]), max(3 * lim, 1.0))
    names.append(_finish(plt, fig, ax, folder / "slip.png", (
        "platform angle [deg]", "slip along the platform [mm]",
        "Slip of each carton against the platform angle")))

    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot(t, angle, label="platform angle")
    if result["tip_event"]:
        ax.axvline(result["tip_event"]["t_s"], color="tab:red", ls="--", lw=1,
                   label=f"tip at {result['tip_event']['angle_deg']:.2f}°")
    ax.axhline(target, color="0.3", ls=":", lw=1, label=f"target {target:g}°")
    names.append(_finish(plt, fig, ax, folder / "drive.png",
                         ("time [s]", "platform angle [deg]", "The drive as delivered")))
    return names


def write_report(folder, d, result, plots):
    rows = []
    for c in result["criteria"]:
        m = "—" if c["measured"] is None else f"{c['measured']:.2f} {c['unit']}".strip()
        verdict = "pass" if c["passed"] else "FAIL"
        limit = f"{c['limit']:.4g} {c['unit']}".strip()
        rows.append(f"<tr class='{verdict.lower()}'><td>{html.escape(c['criterion'])}</td>"
                    f"<td>{m}</td><td>{limit}</td><td>{verdict}</td></tr>")
    imgs = "".join(f"<figure><img src='{p}' alt='{p}'><figcaption>{p}</figcaption></figure>"
                   for p in plots)
    keys = ("unit_load",) if d.get("unit_load") else ("platform", "stack", "materials", "wrap")
    load = html.escape(json.dumps({k: d[k] for k in keys}, indent=2))
    test = html.escape(json.dumps(d["test"], indent=2))
    overall = "PASS" if result["passed"] else "FAIL"
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(d['name'])}: {overall}</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}
table{{border-collapse:collapse}}td,th{{border:1px solid #999;padding:.3em .6em}}
tr.fail td{{background:#fdd}}tr.pass td{{background:#dfd}}img{{max-width:100%}}
pre{{background:#f4f4f4;padding:.5em}}</style></head>
<body><h1>{html.escape(d['name'])}</h1>
<p id="verdict">Verdict: <strong>{overall}</strong> ({html.escape(result['test'])} test,
{result['simulated_s']:.2f} s simulated, state hash {result['state_hash']})</p>
<h2>Criteria</h2>
<table id="criteria"><tr><th>criterion</th><th>measured</th><th>limit</th><th>verdict</th></tr>
{''.join(rows)}</table>
<h2>Plots</h2>{imgs}
<h2>The load and its wrap</h2><pre>{load}</pre>
<h2>The test</h2><pre>{test}</pre>
<script>
// For a headless check: mark the page once every plot has loaded with a non-empty size.
window.addEventListener("load", function () {{
  var imgs = Array.prototype.slice.call(document.images);
  var ok = imgs.every(function (i) {{ return i.complete && i.naturalWidth > 0; }});
  document.body.setAttribute("data-plots", ok ? imgs.length + " loaded" : "missing");
}});
</script>
</body></html>
"""
    (folder / "report.html").write_text(page)


def write_all(folder, d, result, series):
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "verdict.json").write_text(json.dumps(result, indent=2) + "\n")
    write_series(folder / "timeseries.csv", series)
    plots = write_plots(folder, d, result, series)
    write_report(folder, d, result, plots)
    return plots
