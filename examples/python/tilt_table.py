#!/usr/bin/env python3
"""tilt_table.py: the paper's reference case through the Python binding, with its figures.

The same scene as examples/tilt_table.c: two cubes (a = 0.25 m, 5 kg each) stacked on a
platform that is static for 1 s, then tilts at 0.1 rad/s about the y axis (downhill is +x).
Friction box-box and box-platform mu = 0.3: theory says the boxes slide at tan(theta) = 0.3,
theta = 16.70 deg, t = 3.915 s.
  Variant P (paper): as above, 6 s.
  Variant R (reference): plus a 20 mm x 20 mm stop bar on the platform along the downhill face
  of the bottom box, 7 s.
  Wrapped: a band of stretch film around both boxes (96 x 61 nodes, pre-stretch 40 % around and
  20 % up, springs of 2000 N/m, film-box contact 4000 N/m, mu 0.9). In R the wrapped stack tips
  as one over the stop when its CoG passes over the stop's edge: tan(theta) = 0.125 / 0.23,
  theta = 28.52 deg, t = 5.978 s, without the contact layers; 28.61 deg with them
  (docs/theory.md 4.1); about 29.5-29.7 deg with Coulomb friction at the base.

Definitions (the same as examples/tilt_table.c, checked on every step as it does):
  slide onset: every contact of a box with its support slips (|v_t| >= v_lim = 10 mm/s, or the
  stick anchor slides), the same way, without a break for 0.2 s; the onset is where that began.
  physical tip (wrapped R): the load's CoG (boxes and film) passes over the stop's top edge,
  interpolated between the samples around the crossing.
  The run stops when a box leaves the platform (its CoG below the platform): no floor.

Figures (PNG, in --out):
  cog_distance.png   distance between the two boxes' CoGs against time (the paper's Fig. 8)
  velocities.png     speed of each box against time (Fig. 9)
  slip.png           slip of each box along the platform against time, with the theory times
  snapshots.png      3D views of the boxes and the film at chosen times (Fig. 7)

Run (from the repository root, the library built in build/):
  PYTHONPATH=bindings/python python3 examples/python/tilt_table.py --variant R --out figs
"""

import argparse
import math
import os
import sys
import time

import numpy as np

import wrapsim as ws

try:  # the figures need matplotlib; the runs (run_case) do not
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
except ImportError:  # pragma: no cover - reported by main()
    plt = None

A = 0.25          # box edge, m
MASS = 5.0        # kg per box
LAYER = 1e-3      # contact layer, m
GAP = 2 * LAYER   # two layers just touching
DT = 2.5e-4       # s
VLIM = 0.01       # friction regularisation speed, m/s
TILT_START = 1.0  # s
TILT_RATE = 0.1   # rad/s
T_SLIDE = TILT_START + math.atan(0.3) / TILT_RATE              # 3.915 s
T_TIP = TILT_START + math.atan(0.125 / 0.23) / TILT_RATE       # 5.978 s
SLIDE_HOLD = 0.2  # s: gross slip must last this long to count as a slide
LIFT_HOLD = 0.05  # s: the uphill edge must stay off this long to count as tipping
STOP_EDGE = (-0.01, 0.0, 0.01)  # the stop's top uphill edge in the 20 x 20 mm bar's frame, m


def build(variant, wrapped, film_mass=1e-3, substeps=2):
    """The scene of examples/tilt_table.c (tilt_build + tilt_wrap). Returns a dict."""
    w = ws.World(dt=DT, full_detection_until=0.5, detection_interval=5)
    box_mat, plane_mat = w.material("cardboard"), w.material("platform")
    pair = dict(stiffness=2e5, damping=10.0, friction=0.3, friction_vlim=VLIM)
    w.set_contact(box_mat, box_mat, **pair)
    w.set_contact(box_mat, plane_mat, **pair)

    slab, cube, bar = w.box(1.5, 1.5, 0.05), w.box(A, A, A), w.box(0.02, 0.5, 0.02)
    tilt = dict(axis=(0, 1, 0), point=(0, 0, 0), start_time=TILT_START, rate=TILT_RATE)
    plane = w.body(slab, type="kinematic", material=plane_mat, contact_layer=LAYER,
                   position=(0, 0, -0.025), name="platform")
    plane.set_drive("tilt", **tilt)
    stop = None
    if variant == "R":
        stop = w.body(bar, type="kinematic", material=plane_mat, contact_layer=LAYER,
                      position=(A / 2 + GAP + 0.01, 0, 0.01), name="stop")
        stop.set_drive("tilt", **tilt)
    bottom = w.body(cube, mass=MASS, material=box_mat, contact_layer=LAYER,
                    position=(0, 0, GAP + A / 2), name="bottom")
    top = w.body(cube, mass=MASS, material=box_mat, contact_layer=LAYER,
                 position=(0, 0, GAP + A + GAP + A / 2), name="top")

    film = None
    if wrapped:
        k, c = 2000.0, 0.1          # N/m and kg/s per spring, as in the paper
        n_around, n_up = 96, 61
        z0, z1 = 0.030, 2 * A + 2 * 2 * LAYER - 0.020
        perimeter = 4 * A + 2 * math.pi * 2 * LAYER
        l0_around = perimeter / n_around / 1.4
        l0_up = (z1 - z0) / (n_up - 1) / 1.2
        # A law is per unit strain: EA = k l0, eta = c l0.
        around = w.law("tension_compression", stiffness=k * l0_around,
                       compression_stiffness=0.01 * k * l0_around, damping=c * l0_around,
                       name="film around")
        up = w.law("tension_compression", stiffness=k * l0_up,
                   compression_stiffness=0.01 * k * l0_up, damping=c * l0_up, name="film up")
        film_mat = w.material("film")
        film_pair = dict(stiffness=4000.0, damping=1.0, friction=0.9, friction_vlim=VLIM)
        w.set_contact(film_mat, box_mat, **film_pair)
        w.set_contact(film_mat, plane_mat, **film_pair)
        film = w.web_band(around, [bottom, top], law_cross=up, node_mass=film_mass,
                          contact_layer=LAYER, material=film_mat, substeps=substeps,
                          name="film", z_bottom=z0, z_top=z1, n_around=n_around, n_up=n_up,
                          prestretch_around=0.4, prestretch_up=0.2)
    return dict(world=w, plane=plane, stop=stop, boxes=(bottom, top), film=film, cube=cube,
                slab=slab, bar=bar)


def box_triangles(shape_mesh, body):
    """The 12 triangles (12, 3, 3) of a box in the global frame, from its mesh and pose."""
    verts, tris = shape_mesh
    g = verts @ body.rotation.T + body.position
    return g[tris]


def slides_on(w, box, support):
    """Gross slip of box on its support: every contact between them slips, and they slip the
    same way (|sum of slip velocities| >= half the sum of their sizes). The pair's report gives
    each slip velocity as the box's on its support, whichever body owns the face."""
    c = w.contacts_between(support, box)
    if len(c) == 0 or not np.all(c["slipping"]):
        return False
    v = c["slip_velocity"]
    return np.linalg.norm(v.sum(axis=0)) >= 0.5 * np.linalg.norm(v, axis=1).sum()


def uphill_lifted(w, plane, box, R, r0):
    """The bottom box touches the platform only downhill of its CoG, or not at all."""
    c = w.contacts_between(plane, box)
    xc = R.T @ (box.position - r0)
    return bool(np.all((c["point"] - r0) @ R[:, 0] >= xc[0]))


def load_cog(boxes, film, node_mass):
    """Centre of mass of the boxes and, when wrapped, the film's nodes."""
    m = sum(b.mass for b in boxes)
    x = sum(b.mass * b.position for b in boxes)
    if film is not None:
        p = film.positions()
        m += node_mass * len(p)
        x = x + node_mass * p.sum(axis=0)
    return x / m


def run_case(variant, wrapped, duration, snap_times, every=0.01):
    """Run one case; returns its time series, snapshots and the onsets it found."""
    sc = build(variant, wrapped)
    w, plane, (bottom, top), film = sc["world"], sc["plane"], sc["boxes"], sc["film"]
    stop = sc["stop"]
    mesh = sc["cube"].copy_mesh()
    plane_mesh = sc["slab"].copy_mesh()
    stop_mesh = sc["bar"].copy_mesh() if stop is not None else None
    chunk = int(round(every / DT))
    n_samples = int(round(duration / every)) + 1
    node_mass = film.info()["mass"] / film.node_count if film is not None else 0.0
    watch_tip = film is not None and stop is not None

    t = np.empty(n_samples)
    pos = np.empty((n_samples, 2, 3))
    vel = np.empty((n_samples, 2, 3))
    local = np.empty((n_samples, 2, 3))   # CoG in the platform's frame, m
    angle = np.empty(n_samples)           # platform angle, rad
    past = np.full(n_samples, np.nan)     # load CoG past the stop edge, horizontally downhill, m
    peak_tension = np.zeros(n_samples) if film is not None else None
    tension = np.empty(film.spring_count) if film is not None else None
    snaps = []
    snap_steps = {int(round(s / every)): s for s in snap_times if 0 <= s <= duration}

    # The slide and lift detectors of examples/tilt_table.c, run on every step's state like it.
    hold_steps, lift_steps = int(round(SLIDE_HOLD / DT)), int(round(LIFT_HOLD / DT))
    slipping_steps, slide, confirmed = [0, 0], [None, None], [False, False]
    lifted_steps, lift_confirmed, off = 0, False, [None, None]

    def observe(tn):
        nonlocal lifted_steps, lift_confirmed
        R, r0 = plane.rotation, plane.position
        q = plane.orientation
        theta = 2.0 * math.atan2(q[2], q[0])
        for k, (b, support) in enumerate(((bottom, plane), (top, bottom))):
            if off[k] is None and (R.T @ (b.position - r0))[2] < 0.0:
                off[k] = tn
            standing = not lift_confirmed and off[k] is None
            slipping_steps[k] = slipping_steps[k] + 1 if standing and slides_on(w, b, support) \
                else 0
            if slide[k] is None and tn > TILT_START and slipping_steps[k] == 1:
                slide[k] = (tn, math.degrees(theta))  # candidate onset
            if slide[k] is not None and slipping_steps[k] == 0 and not confirmed[k]:
                slide[k] = None  # it did not last
            if slipping_steps[k] >= hold_steps:
                confirmed[k] = True
        if not lift_confirmed:
            if tn > TILT_START and uphill_lifted(w, plane, bottom, R, r0):
                lifted_steps += 1
                lift_confirmed = lifted_steps >= lift_steps
            else:
                lifted_steps = 0

    t0 = time.monotonic()
    n = 0
    for n in range(n_samples):
        if n:
            for _ in range(chunk):
                w.step(1)
                observe(w.time)
                if off[0] is not None or off[1] is not None:
                    break
        else:
            observe(w.time)
        t[n] = w.time
        R, r0 = plane.rotation, plane.position
        q = plane.orientation
        angle[n] = 2.0 * math.atan2(q[2], q[0])
        for k, b in enumerate((bottom, top)):
            pos[n, k] = b.position
            vel[n, k] = b.velocity
            local[n, k] = R.T @ (pos[n, k] - r0)
        if watch_tip:
            e = stop.world_point(STOP_EDGE)
            h = np.array([R[0, 0], R[1, 0]]) / math.hypot(R[0, 0], R[1, 0])  # downhill, level
            past[n] = (load_cog((bottom, top), film, node_mass) - e)[:2] @ h
        if film is not None:
            peak_tension[n] = film.tensions(out=tension).max()
        if n in snap_steps:
            snap = dict(t=t[n], boxes=[box_triangles(mesh, b) for b in (bottom, top)],
                        plane=box_triangles(plane_mesh, plane),
                        stop=(box_triangles(stop_mesh, stop) if stop_mesh else None),
                        film=film.positions().copy() if film is not None else None,
                        film_grid=(film.info()["ny"], film.info()["nx"]) if film else None)
            snaps.append(snap)
        if n and n % 100 == 0:
            sys.stderr.write(f"\r  {variant} {'wrapped' if wrapped else 'unwrapped'}: "
                             f"t = {t[n]:.2f} s of {duration:.2f} s")
        if off[0] is not None or off[1] is not None:
            break  # a box left the platform: the world has no floor, it would only fall
    wall = time.monotonic() - t0
    sys.stderr.write(f"\r  {variant} {'wrapped' if wrapped else 'unwrapped'}: "
                     f"{t[n]:.2f} s simulated in {wall:.1f} s wall\n")
    h = w.state_hash()
    w.close()
    end = n + 1
    t, pos, vel, local, angle = t[:end], pos[:end], vel[:end], local[:end], angle[:end]
    past = past[:end]
    if peak_tension is not None:
        peak_tension = peak_tension[:end]
    slide = [sl if ok else None for sl, ok in zip(slide, confirmed)]

    # Physical tip: the first crossing of the stop edge, interpolated in the angle.
    tip = None
    if watch_tip:
        idx = np.nonzero((past[1:] >= 0) & (past[:-1] < 0))[0]
        if len(idx):
            i = idx[0]
            f = -past[i] / (past[i + 1] - past[i])
            tip = (t[i] + f * (t[i + 1] - t[i]),
                   math.degrees(angle[i] + f * (angle[i + 1] - angle[i])))
    slip = local[:, :, 0] - local[0, :, 0]
    return dict(variant=variant, wrapped=wrapped, t=t, pos=pos, vel=vel, local=local,
                slip=slip, angle=angle, dist=np.linalg.norm(pos[:, 1] - pos[:, 0], axis=1),
                speed=np.linalg.norm(vel, axis=2), peak_tension=peak_tension, snaps=snaps,
                wall=wall, hash=h, slide=slide, tip=tip, off=off)


def label(r):
    return f"{r['variant']}, {'wrapped' if r['wrapped'] else 'unwrapped'}"


def theory_lines(ax, results, variant):
    ax.axvline(T_SLIDE, color="0.4", ls="--", lw=1,
               label=f"slide theory tan θ = 0.3 (t = {T_SLIDE:.3f} s)")
    if variant == "R" and any(r["wrapped"] for r in results):
        ax.axvline(T_TIP, color="tab:red", ls=":", lw=1.2,
                   label=f"tip theory, wrapped R (t = {T_TIP:.3f} s)")


def plot_distance(results, variant, path):
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for r in results:
        ax.plot(r["t"], 1e3 * r["dist"], label=label(r))
    theory_lines(ax, results, variant)
    top = 1e3 * max(r["dist"].max() for r in results)
    if top > 600:  # the top box left the platform: keep the standing stack readable
        ax.set_ylim(200, 600)
        ax.text(0.99, 0.02, f"clipped at 600 mm (largest {top:.0f} mm)", transform=ax.transAxes,
                ha="right", va="bottom", fontsize=8, color="0.3")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("distance between the box CoGs [mm]")
    ax.set_title(f"Tilt table, variant {variant}: distance between the two boxes' CoGs")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_per_box(results, variant, path, series, scale, ylabel, title, legend, clip=None):
    """One curve per box and run (solid unwrapped, dashed wrapped) against time; `clip` caps the
    y axis so a box that left the platform does not flatten the rest."""
    fig, ax = plt.subplots(figsize=(8, 4.5))
    styles = {False: "-", True: "--"}
    colors = ("tab:blue", "tab:orange")
    for r in results:
        for k, name in enumerate(("bottom", "top")):
            ax.plot(r["t"], scale * r[series][:, k], styles[r["wrapped"]], color=colors[k],
                    label=f"{name} box, {label(r)}")
    theory_lines(ax, results, variant)
    top = max(scale * r[series].max() for r in results)
    if clip is not None and top > clip:
        low = min(scale * r[series].min() for r in results)
        ax.set_ylim(min(low, 0.0) - 0.05 * clip, clip)
        ax.text(0.99, 0.02, f"clipped at {clip:g} (largest {top:.3g})", transform=ax.transAxes,
                ha="right", va="bottom", fontsize=8, color="0.3")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(**legend)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_velocities(results, variant, path):
    plot_per_box(results, variant, path, "speed", 1.0, "box speed |v| [m/s]",
                 f"Tilt table, variant {variant}: speed of the boxes' CoGs",
                 dict(loc="upper left", fontsize=8), clip=1.0)


def plot_slip(results, variant, path):
    plot_per_box(results, variant, path, "slip", 1e3, "slip along the platform, downhill + [mm]",
                 f"Tilt table, variant {variant}: CoG slip in the platform's frame",
                 dict(loc="upper left", fontsize=8), clip=300.0)


def plot_snapshots(results, variant, path):
    rows = [r for r in results if r["snaps"]]
    ncol = max(len(r["snaps"]) for r in rows)
    fig = plt.figure(figsize=(4.2 * ncol, 4.2 * len(rows)))
    for i, r in enumerate(rows):
        for j, s in enumerate(r["snaps"]):
            ax = fig.add_subplot(len(rows), ncol, i * ncol + j + 1, projection="3d",
                                 computed_zorder=False)  # draw in order: film on top
            # The platform: only its top face region near the stack, for scale.
            ax.add_collection3d(Poly3DCollection(s["plane"], facecolor="0.85", edgecolor="0.6",
                                                 linewidths=0.3, alpha=0.35))
            if s["stop"] is not None:
                ax.add_collection3d(Poly3DCollection(s["stop"], facecolor="dimgray",
                                                     edgecolor="k", linewidths=0.3))
            for tri, col in zip(s["boxes"], ("tab:brown", "burlywood")):
                ax.add_collection3d(Poly3DCollection(tri, facecolor=col, edgecolor="k",
                                                     linewidths=0.4, alpha=0.9))
            if s["film"] is not None:
                ny, nx = s["film_grid"]
                p = s["film"].reshape(ny, nx, 3)
                p = np.concatenate([p, p[:, :1]], axis=1)  # close the band around
                ax.plot_wireframe(p[..., 0], p[..., 1], p[..., 2], rstride=4, cstride=4,
                                  color="tab:cyan", linewidth=0.5, alpha=0.8)
            ax.set_xlim(-0.45, 0.55)
            ax.set_ylim(-0.5, 0.5)
            ax.set_zlim(-0.4, 0.6)
            ax.set_box_aspect((1, 1, 1))
            ax.set_xlabel("x [m]")
            ax.set_ylabel("y [m]")
            ax.set_zlabel("z [m]")
            ax.view_init(elev=12, azim=-70)
            k = int(np.argmin(np.abs(r["t"] - s["t"])))
            ang = math.degrees(r["angle"][k])
            ax.set_title(f"{label(r)}\nt = {s['t']:.2f} s, platform {ang:.1f}°", fontsize=10)
    fig.suptitle(f"Tilt table, variant {variant}: boxes and film (cyan wireframe, every 4th "
                 f"node line)", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def summary(r):
    t = r["t"]
    print(f"{label(r)}: {r['t'][-1]:.2f} s simulated, {r['wall']:.1f} s wall, "
          f"hash 0x{r['hash']:016x}")
    print(f"  CoG distance: {1e3 * r['dist'][0]:.1f} mm at start, "
          f"{1e3 * r['dist'][-1]:.1f} mm at the end (max {1e3 * r['dist'].max():.1f} mm)")
    for k, name in enumerate(("bottom", "top")):
        sl = r["slide"][k]
        onset = (f"starts to slide at {sl[1]:.2f} deg (t = {sl[0]:.3f} s)"
                 if sl is not None else "did not slide on its support")
        print(f"  {name:6s}: {onset}; final slip {1e3 * r['slip'][-1, k]:.1f} mm; peak speed "
              f"{r['speed'][:, k].max():.3f} m/s (t = {t[np.argmax(r['speed'][:, k])]:.2f} s)")
        if r["off"][k] is not None:
            print(f"  {name:6s}: left the platform at t = {r['off'][k]:.2f} s; the run stops there")
    if r["tip"] is not None:
        print(f"  the load's CoG (boxes and film) passes over the stop's edge at "
              f"{r['tip'][1]:.2f} deg (t = {r['tip'][0]:.3f} s)")
    if r["peak_tension"] is not None:
        print(f"  film: peak spring tension {r['peak_tension'].max():.2f} N")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--variant", choices=["P", "R", "p", "r"], default="R",
                   help="P: the paper's case (6 s); R: with the stop bar (7 s). Default R.")
    p.add_argument("--wrapped", action="store_true", help="run the wrapped case")
    p.add_argument("--unwrapped", action="store_true", help="run the unwrapped case")
    p.add_argument("--out", default="tilt_table_figures", help="directory for the PNG files")
    p.add_argument("--duration", type=float, default=0.0,
                   help="simulated time, s (default 6 for P, 7 for R)")
    p.add_argument("--snapshots", type=float, nargs="+", default=None,
                   help="times (s) of the 3D views (default 1.0, 4.5, 6.2 for R; "
                        "1.0, 3.5, 4.5 for P)")
    a = p.parse_args(argv)
    if plt is None:
        p.error("the figures need matplotlib (Debian: apt-get install python3-matplotlib)")
    variant = a.variant.upper()
    duration = a.duration if a.duration > 0 else (6.0 if variant == "P" else 7.0)
    cases = []
    if a.unwrapped or not a.wrapped:
        cases.append(False)
    if a.wrapped or not a.unwrapped:
        cases.append(True)
    snaps = a.snapshots or ([1.0, 4.5, 6.2] if variant == "R" else [1.0, 3.5, 4.5])
    snaps = [min(x, duration) for x in snaps]
    os.makedirs(a.out, exist_ok=True)

    print(f"libwrapsim {ws.version()}: tilt table, variant {variant}, {duration:.2f} s")
    print(f"  theory: sliding at tan(theta) = 0.3, theta = 16.70 deg, t = {T_SLIDE:.3f} s")
    print(f"  slide onset: every contact with its support slips (|v_t| >= v_lim = "
          f"{1e3 * VLIM:.0f} mm/s) the same way, for {SLIDE_HOLD:.1f} s")
    if variant == "R" and True in cases:
        print(f"  theory, wrapped: the CoG passes over the stop's edge at 28.52 deg "
              f"(t = {T_TIP:.3f} s) without layers, 28.61 deg with them (docs/theory.md 4.1), "
              f"about 29.5-29.7 deg with Coulomb friction at the base")
    results = [run_case(variant, wr, duration, snaps) for wr in cases]
    for r in results:
        summary(r)

    files = {
        "cog_distance.png": plot_distance,
        "velocities.png": plot_velocities,
        "slip.png": plot_slip,
        "snapshots.png": plot_snapshots,
    }
    for name, fn in files.items():
        path = os.path.join(a.out, name)
        fn(results, variant, path)
        print(f"  wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
