"""Run a checked load file (see loadfile) and judge it.

The tilt test (ISO 10531 style): the platform is level until `test.start_s`, then tilts about
the y axis at `test.rate_deg_per_s` (downhill is +x). The load passes when, below
`test.target_angle_deg`, counting from the settled load at the tilt's start,
  - no carton slips by more than `test.slip_limit_mm` along the platform relative to what it
    stands on (the platform for the bottom carton, the carton below for the others), and
  - the load does not tip: its centre of mass does not pass over the edge it pivots about
    (the stop's top edge when there is a stop, else the bottom carton's downhill edge).
The angles where slip and tip happened are reported as measured; theory for a rigid column
without a stop: slip at tan(theta) = mu, tip at tan(theta) = (a/2) / (h_CoG).
"""

import math

import numpy as np

from . import World, _make
from . import _lib as L
from ._run import _progress


def world_params(d, threads=1):
    """The ws_world_def fields a load file's `simulation` section sets, and the step's
    workers (`threads`: the run's answers are the same to the bit for any count)."""
    s = d["simulation"]
    return dict(dt=s["dt_s"], full_detection_until=s["full_detection_until_s"],
                detection_interval=s["detection_interval"], worker_count=threads)


def build(d, threads=1):
    """A world with the platform, the stack and the film of a checked load file, stepped on
    `threads` workers. Returns a dict: world, platform, stop (or None), cartons (bottom first),
    film (or None), pivot (x, z) of the tip edge in the platform's frame."""
    plat, stack, mats = d["platform"], d["stack"], d["materials"]
    c = stack["carton"]
    layer = stack["contact_layer_m"]
    gap = 2 * layer
    w = World(**world_params(d, threads))
    carton_mat, plat_mat = w.material("carton"), w.material("platform")

    def pair(m):
        return dict(stiffness=m["stiffness_N_per_m"], damping=m["damping_kg_per_s"],
                    friction=m["mu"], friction_vlim=m["vlim_m_per_s"],
                    friction_model=m["friction_model"])

    w.set_contact(carton_mat, carton_mat, **pair(mats["carton_carton"]))
    w.set_contact(carton_mat, plat_mat, **pair(mats["carton_platform"]))
    test = d["test"]
    tilt = dict(axis=(0, 1, 0), point=(0, 0, 0), start_time=test["start_s"],
                rate=math.radians(test["rate_deg_per_s"]))
    slab = w.box(plat["length_m"], plat["width_m"], plat["thickness_m"])
    platform = w.body(slab, type="kinematic", material=plat_mat, contact_layer=layer,
                      position=(0, 0, -plat["thickness_m"] / 2), name="platform")
    platform.set_drive("tilt", **tilt)
    a_x, a_y, h = c["length_m"], c["width_m"], c["height_m"]
    stop = None
    pivot = (a_x / 2, 0.0)
    if plat["stop"] is not None:
        s = plat["stop"]
        bar = w.box(s["thickness_m"], min(plat["width_m"], 2 * a_y), s["height_m"])
        x = a_x / 2 + gap + s["thickness_m"] / 2
        stop = w.body(bar, type="kinematic", material=plat_mat, contact_layer=layer,
                      position=(x, 0, s["height_m"] / 2), name="stop")
        stop.set_drive("tilt", **tilt)
        pivot = (a_x / 2 + gap, s["height_m"])
    cube = w.box(a_x, a_y, h)
    cartons = []
    for k in range(stack["layers"]):
        z = gap + h / 2 + k * (h + gap)
        cartons.append(w.body(cube, mass=c["mass_kg"], material=carton_mat, contact_layer=layer,
                              position=(0, 0, z), name=f"carton {k + 1}"))
    film = None
    wr = d["wrap"]
    if wr is not None:
        film_mat = w.material("film")
        w.set_contact(film_mat, carton_mat, **pair(mats["film_carton"]))
        w.set_contact(film_mat, plat_mat, **pair(mats["film_carton"]))
        top = stack["layers"] * (h + gap)
        z0, z1 = wr["z_bottom_m"], top - wr["top_margin_m"]
        n_around, n_up = wr["nodes_around"], wr["nodes_up"]
        around_x = 1 + wr["prestretch_around_percent"] / 100
        up_x = 1 + wr["prestretch_up_percent"] / 100
        perimeter = 2 * (a_x + a_y) + 2 * math.pi * gap
        l0_around = perimeter / n_around / around_x
        l0_up = (z1 - z0) / (n_up - 1) / up_x
        k_s, c_s = wr["spring_stiffness_N_per_m"], wr["spring_damping_kg_per_s"]
        # A law is per unit strain: EA = k l0, eta = c l0; 1 % of it in compression.
        law_a = w.law("tension_compression", stiffness=k_s * l0_around,
                      compression_stiffness=0.01 * k_s * l0_around, damping=c_s * l0_around,
                      name="film around")
        law_u = w.law("tension_compression", stiffness=k_s * l0_up,
                      compression_stiffness=0.01 * k_s * l0_up, damping=c_s * l0_up,
                      name="film up")
        film = w.web_band(law_a, cartons, law_cross=law_u, node_mass=wr["node_mass_kg"],
                          contact_layer=layer, material=film_mat, name="film", z_bottom=z0,
                          z_top=z1, n_around=n_around, n_up=n_up,
                          prestretch_around=around_x - 1, prestretch_up=up_x - 1,
                          integrator=wr["integrator"])
        # Sub-steps within the film check's safety factor (stable_fraction, world.h): 1 g
        # nodes at the default dt use 0.685 of their stable sub-step alone, 0.34 in two. An
        # implicit film takes one at any mass.
        f = _make(L.WorldDef, {}).stable_fraction
        if wr["integrator"] == "explicit":
            film.substeps = max(1, math.ceil(w.stats()["web_step_use"] / f))
    return dict(world=w, platform=platform, stop=stop, cartons=cartons, film=film, pivot=pivot)


#: Columns of the time series, with their units.
def series_columns(n_cartons, wrapped):
    cols = ["t_s", "platform_angle_deg"]
    for k in range(n_cartons):
        cols += [f"carton{k + 1}_slip_mm", f"carton{k + 1}_relative_slip_mm",
                 f"carton{k + 1}_lift_mm"]
    cols += ["cog_beyond_pivot_mm"]
    if wrapped:
        cols += ["film_peak_tension_N"]
    return cols


def _first(t, angle, mask):
    idx = np.nonzero(mask)[0]
    if not len(idx):
        return None
    return dict(t_s=float(t[idx[0]]), angle_deg=float(angle[idx[0]]))


def paraview_series(w, d, folder):
    """A ParaView collection of the run in `folder` (None, or an interval of 0: none), frames
    every output.paraview_interval_s."""
    every = d["output"]["paraview_interval_s"]
    if folder is None or every <= 0:
        return None
    import os
    os.makedirs(folder, exist_ok=True)
    return w.vtk_series(folder, "run", time_stride=every)


def run(d, progress=False, desc="wrapsim", paraview=None, threads=1):
    """Run a checked load file's test. Returns (result, series): result is a JSON-able dict
    with the measured values, the criteria and the verdict; series a dict of numpy columns
    (for the tilt, named by series_columns()). `paraview`: a folder for a ParaView collection
    of the run (run.pvd), or None. `threads`: the world's workers (the same answers for any
    count)."""
    if d["test"]["type"] == "eumos":
        from . import eumos
        return eumos.run(d, progress, desc, paraview, threads)
    if d["unit_load"] is not None:
        from . import loadtests
        return loadtests.run(d, progress, desc, paraview, threads)
    sc = build(d, threads)
    w, platform, cartons, film = sc["world"], sc["platform"], sc["cartons"], sc["film"]
    test = d["test"]
    every = d["output"]["sample_interval_s"]
    chunk = max(int(round(every / w.dt)), 1)
    total = int(round(test["duration_s"] / w.dt))
    n_samples = total // chunk + 1
    masses = np.array([d["stack"]["carton"]["mass_kg"]] * len(cartons))
    cols = series_columns(len(cartons), film is not None)
    out = {c: np.empty(n_samples) for c in cols}
    start = None
    tension = np.empty(film.spring_count) if film is not None else None
    px, pz = sc["pivot"]
    vtk = paraview_series(w, d, paraview)
    bar = _progress(total, desc, progress)
    try:
        for n in range(n_samples):
            if n:
                w.step(chunk)
                if bar is not None:
                    bar.update(chunk)
            R, r0 = platform.rotation, platform.position
            local = np.array([R.T @ (b.position - r0) for b in cartons])
            # Slip counts from the settled load at the tilt's start (the film may have moved
            # it while it settled), and from t = 0 before that.
            if start is None or w.time <= test["start_s"] + 0.5 * w.dt:
                start = local.copy()
            q = platform.orientation
            out["t_s"][n] = w.time
            out["platform_angle_deg"][n] = math.degrees(2.0 * math.atan2(q[2], q[0]))
            slip = local[:, 0] - start[:, 0]
            rel = slip - np.concatenate([[0.0], slip[:-1]])
            for k in range(len(cartons)):
                out[f"carton{k + 1}_slip_mm"][n] = 1e3 * slip[k]
                out[f"carton{k + 1}_relative_slip_mm"][n] = 1e3 * rel[k]
                out[f"carton{k + 1}_lift_mm"][n] = 1e3 * (local[k, 2] - start[k, 2])
            # Gravity in the platform's frame; the CoG is past the pivot edge when the
            # vertical through it falls downhill of the edge.
            g = R.T @ np.array([0.0, 0.0, -1.0])
            cog = masses @ local / masses.sum()
            beyond = (cog[0] - px) - (cog[2] - pz) * g[0] / g[2]
            out["cog_beyond_pivot_mm"][n] = 1e3 * beyond
            if film is not None:
                out["film_peak_tension_N"][n] = film.tensions(out=tension).max()
            if vtk is not None:
                vtk.write_frame()
    finally:
        if bar is not None:
            bar.close()
        if vtk is not None:
            vtk.close()
    state_hash = w.state_hash()
    w.close()

    t, angle = out["t_s"], out["platform_angle_deg"]
    limit = test["slip_limit_mm"]
    slips = {}
    for k in range(len(cartons)):
        name = "carton 1 on platform" if k == 0 else f"carton {k + 1} on carton {k}"
        slips[name] = _first(t, angle, np.abs(out[f"carton{k + 1}_relative_slip_mm"]) > limit)
    tip = _first(t, angle, out["cog_beyond_pivot_mm"] > 0.0)
    target = test["target_angle_deg"]
    reached = float(angle.max())
    criteria = []
    for name, ev in slips.items():
        measured = ev["angle_deg"] if ev else None
        criteria.append(dict(
            criterion=f"no slip over {limit:g} mm, {name}, below {target:g} deg",
            measured=measured, unit="deg", limit=target,
            passed=(measured is None and reached >= target) or
                   (measured is not None and measured >= target)))
    criteria.append(dict(
        criterion=f"no tip (CoG past the pivot edge) below {target:g} deg",
        measured=tip["angle_deg"] if tip else None, unit="deg", limit=target,
        passed=(tip is None and reached >= target) or (tip is not None and
                                                       tip["angle_deg"] >= target)))
    criteria.append(dict(criterion=f"the platform reached {target:g} deg", measured=reached,
                         unit="deg", limit=target, passed=reached >= target))
    result = dict(name=d["name"], test="tilt", target_angle_deg=target,
                  slip_events=slips, tip_event=tip, criteria=criteria,
                  passed=all(c["passed"] for c in criteria), state_hash=f"{state_hash:016x}",
                  simulated_s=float(t[-1]))
    return result, out
