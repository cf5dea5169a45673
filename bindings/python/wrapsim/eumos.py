"""The EUMOS 40509 acceleration test of a unit load, from a checked load file (see loadfile).

The load (a pallet with layers of cartons), its wrap, the test run, the measurements, the
events, the verdict and the k-value search are the C library's (include/wrapsim/loadtest.h):
this module only fills its Defs from the load file and turns its results into the command's
verdict.json, time series and plots, so C programs and this command give the same verdict.
"""

import ctypes
from ctypes import byref

import numpy as np

from . import World, WrapsimError, _c, _int
from . import _lib as L
from ._run import _progress
from .loadrun import paraview_series, world_params

_PATTERNS = {"column": 0, "brick": 1, "turned": 2}
_MODELS = {"regularized": L.WS_FRICTION_REGULARIZED, "stick": L.WS_FRICTION_STICK}
_MODES = {"accelerate": 0, "brake": 1}
_EVENTS = {0: "slip onset", 1: "tip onset", 2: "carton lost", 3: "film rupture"}


def _init(struct, name):
    d = struct()
    getattr(_c(), name)(byref(d), ctypes.sizeof(d))
    return d


def _interface(dst, src):
    dst.stiffness = src["stiffness_N_per_m"]
    dst.damping = src["damping_kg_per_s"]
    dst.friction = src["mu"]
    dst.friction_vlim = src["vlim_m_per_s"]
    dst.friction_model = _MODELS[src["friction_model"]]


def load_def(d):
    """The ws_load_def of a load file's unit_load section."""
    u = d["unit_load"]
    ld = _init(L.LoadDef, "ws_load_def_init_sized")
    p, c = u["pallet"], u["carton"]
    ld.pallet_size = L.Vec3(p["length_m"], p["width_m"], p["height_m"])
    ld.pallet_mass = p["mass_kg"]
    ld.carton_size = L.Vec3(c["length_m"], c["width_m"], c["height_m"])
    ld.carton_mass = c["mass_kg"]
    ld.layers, ld.count_x, ld.count_y = u["layers"], u["count_x"], u["count_y"]
    ld.pattern = _PATTERNS[u["pattern"]]
    ld.gap = u["gap_m"]
    ld.contact_layer = u["contact_layer_m"]
    for name in ("carton_carton", "carton_pallet", "pallet_platform", "film_carton"):
        _interface(getattr(ld, name), u["interfaces"][name])
    return ld


#: ws_web_integrator by its load file name.
_INTEGRATORS = {"explicit": 0, "implicit": 1}


def wrap_def(d):
    """The ws_wrap_def of a load file's unit_load.wrap section, or None when unwrapped."""
    w = d["unit_load"]["wrap"]
    if w is None:
        return None
    wd = _init(L.WrapDef, "ws_wrap_def_init_sized")
    wd.gauge = w["gauge_um"] * 1e-6
    wd.modulus = w["modulus_MPa"] * 1e6
    wd.density = w["density_kg_per_m3"]
    wd.layers = w["layers"]
    wd.strain_around = w["strain_around_percent"] / 100
    wd.strain_up = w["strain_up_percent"] / 100
    wd.z_bottom = w["z_bottom_m"]
    wd.top_margin = w["top_margin_m"]
    wd.node_pitch = w["node_pitch_m"]
    wd.node_mass = w["node_mass_kg"]
    wd.elongation_at_break = w["elongation_at_break_percent"] / 100
    wd.powered_prestretch = w["powered_prestretch_percent"] / 100
    wd.rupture_strain = w["rupture_strain_percent"] / 100
    wd.integrator = _INTEGRATORS[w["integrator"]]
    return wd


def spiral_def(d):
    """The ws_spiral_wrap_def of a load file's unit_load.spiral_wrap section, or None."""
    w = d["unit_load"]["spiral_wrap"]
    if w is None:
        return None
    sd = _init(L.SpiralWrapDef, "ws_spiral_wrap_def_init_sized")
    sd.width = w["width_m"]
    sd.gauge = w["gauge_um"] * 1e-6
    sd.modulus = w["modulus_MPa"] * 1e6
    sd.density = w["density_kg_per_m3"]
    sd.prestretch = w["prestretch_percent"] / 100
    sd.neck_in = w["neck_in_percent"] / 100
    sd.load_strain = w["load_strain_percent"] / 100
    sd.revolutions_bottom = w["revolutions_bottom"]
    sd.revolutions_top = w["revolutions_top"]
    sd.overlap = w["overlap_percent"] / 100
    sd.passes = w["passes"]
    sd.pallet_lock = 1 if w["pallet_lock"] else 0
    sd.lock_height = w["lock_height_m"]
    sd.top_margin = w["top_margin_m"]
    sd.rope_revolutions = w["rope_revolutions"]
    sd.rope_height = w["rope_height_m"]
    sd.top_sheet = 1 if w["top_sheet"] else 0
    sd.top_sheet_gauge = w["top_sheet_gauge_um"] * 1e-6
    sd.node_pitch = w["node_pitch_m"]
    sd.node_mass_min = w["node_mass_min_kg"]
    sd.elongation_at_break = w["elongation_at_break_percent"] / 100
    sd.rupture_strain = w["rupture_strain_percent"] / 100
    sd.integrator = _INTEGRATORS[w["integrator"]]
    return sd


def containment_bands(w, load, bands=3):
    """The containment of a wrapped load by height band, bottom first
    (ws_load_get_containment): a list of dicts in N, N/m and m. `bands`: 1 .. 64."""
    bands = _int(bands, ctypes.c_size_t, "containment bands")
    if not 1 <= bands <= 64:
        raise ValueError(f"containment bands: expected 1..64, got {bands}")
    out = (L.LoadContainment * bands)()
    _check(w, _c().ws_load_get_containment(w.ptr, load, out, bands), "ws_load_get_containment")
    return [dict(z_low_m=b.z_low, z_high_m=b.z_high, force_N=b.force,
                 hoop_tension_N=b.hoop_tension, line_load_N_per_m=b.line_load, rows=b.rows)
            for b in out]


def eumos_def(d, k=None):
    t = d["test"]
    ed = _init(L.EumosDef, "ws_eumos_def_init_sized")
    ed.k = t["k_g"] if k is None else k
    ed.rise_time = t["rise_s"]
    ed.hold_time = t["hold_s"]
    ed.mode = _MODES[t["mode"]]
    ed.sample_interval = max(1, round(d["output"]["sample_interval_s"] / d["simulation"]["dt_s"]))
    return ed


def _check(w, status, what):
    if status != L.WS_OK:
        raise WrapsimError(status, f"{what}: {w.last_error}")


def _criteria(v):
    out = []
    for key, text in (("elastic", "largest displacement during the test <= 10 % of H"),
                      ("permanent", "permanent displacement after the test <= 5 % of H"),
                      ("bottom", "permanent displacement in the lowest 20 cm <= 40 mm"),
                      ("layer_shift", "layer shift < 2 % of H"),
                      ("rupture", "no film rupture")):
        c = getattr(v, key)
        unit = "" if key == "rupture" else "mm"
        scale = 1.0 if key == "rupture" else 1e3
        out.append(dict(criterion=text, measured=scale * c.value, unit=unit,
                        limit=scale * c.limit, passed=bool(getattr(c, "pass"))))
    return out


def _result_dict(d, res, state_hash):
    v = res.verdict
    events = [dict(event=_EVENTS.get(e.type, str(e.type)), layer=e.layer, index=e.index,
                   t_s=e.time, level_g=e.level, value=e.value)
              for e in res.events[:res.event_count]]
    containment = [dict(band=name, hoop_tension_N=b.hoop_tension, line_load_N_per_m=b.line_load)
                   for name, b in zip(("bottom", "middle", "top"), res.containment)]
    return dict(name=d["name"], test="eumos", k_g=res.k, load_height_m=v.load_height,
                peak_level_g=res.peak_level, rise_measured_s=res.rise_measured,
                time_at_level_s=res.time_at_level, cartons_lost=res.cartons_lost,
                layer_max_mm=[1e3 * x for x in res.layer_max[:res.layers]],
                layer_permanent_mm=[1e3 * x for x in res.layer_permanent[:res.layers]],
                events=events, containment=containment,
                film_peak_strain=res.film_peak_strain, criteria=_criteria(v),
                passed=bool(getattr(v, "pass")), state_hash=f"{state_hash:016x}",
                simulated_s=res.duration)


def prepare(w, d):
    """Build the load file's unit load in world `w`, let it settle, wrap it (then settle again)
    when the file has a wrap. Each settling lasts until the load stands still (drift under
    0.1 mm/s for 0.1 s), at most settle_s. Returns the ws_load pointer; destroy it with
    ws_load_destroy."""
    u = d["unit_load"]
    lib = _c()
    ld = load_def(d)
    load = ctypes.c_void_p()
    _check(w, lib.ws_load_build(w.ptr, byref(ld), byref(load)), "ws_load_build")
    try:
        settled, taken = ctypes.c_int(), ctypes.c_double()
        wd, sd = wrap_def(d), spiral_def(d)
        if wd is not None or sd is not None:
            _check(w, lib.ws_load_settle(w.ptr, load, min(0.2, u["settle_s"]), u["settle_s"],
                                         1e-4, byref(settled), byref(taken)), "ws_load_settle")
            web = L.WebId()
            if wd is not None:
                _check(w, lib.ws_load_wrap_band(w.ptr, load, byref(wd), byref(web)),
                       "ws_load_wrap_band")
            else:
                _check(w, lib.ws_load_wrap_spiral(w.ptr, load, byref(sd), byref(web)),
                       "ws_load_wrap_spiral")
        _check(w, lib.ws_load_settle(w.ptr, load, min(0.2, u["settle_s"]), u["settle_s"],
                                     1e-4, byref(settled), byref(taken)), "ws_load_settle")
    except BaseException:
        lib.ws_load_destroy(load)
        raise
    return load


def run(d, progress=False, desc="wrapsim", paraview=None, threads=1):
    """Build the unit load, wrap it, let it settle, run the EUMOS test on `threads` workers.
    Returns (result, series) like loadrun.run: the verdict as a JSON-able dict and the sampled
    time series."""
    lib = _c()
    with World(**world_params(d, threads)) as w:
        load = prepare(w, d)
        try:
            info = L.LoadInfo()
            _check(w, lib.ws_load_get_info(load, byref(info)), "ws_load_get_info")
            rows = []
            ed = eumos_def(d)
            dd, duration = L.DriveDef(), ctypes.c_double()
            _check(w, lib.ws_eumos_get_drive(byref(ed), byref(dd), byref(duration)),
                   "ws_eumos_get_drive")
            total = int(round(duration.value / d["simulation"]["dt_s"]))
            bar = _progress(total, desc, progress)
            vtk = paraview_series(w, d, paraview)

            def sample(user, smp):
                s = smp.contents
                if bar is not None:
                    bar.update(ed.sample_interval)
                if vtk is not None:
                    vtk.write_frame()
                rows.append([s.time, s.level, s.platform_velocity, s.platform_position] +
                            [s.layer_displacement[i] for i in range(s.layers)])
                return 0

            cb = L.SampleFn(sample)
            ed.on_sample = cb
            res = L.EumosResult()
            try:
                _check(w, lib.ws_loadtest_run_eumos(w.ptr, load, byref(ed), byref(res)),
                       "ws_loadtest_run_eumos")
            finally:
                if bar is not None:
                    bar.close()
                if vtk is not None:
                    vtk.close()
            result = _result_dict(d, res, w.state_hash())
        finally:
            lib.ws_load_destroy(load)
    data = np.array(rows)
    series = {"t_s": data[:, 0], "platform_acceleration_g": data[:, 1],
              "platform_velocity_m_per_s": data[:, 2], "platform_position_mm": 1e3 * data[:, 3]}
    for i in range(data.shape[1] - 4):
        series[f"layer{i + 1}_displacement_mm"] = 1e3 * data[:, 4 + i]
    return result, series


def find_k(d, k_low=0.05, k_high=1.0, tolerance=0.01, threads=1):
    """The EUMOS k-value of the load file's load (ws_loadtest_find_k), each run stepped on
    `threads` workers: every run starts from one settled (and wrapped) state. Returns a dict: k_value, k_fail (g), runs, settled (the
    load stood still before the runs) and settle_s (how long it settled)."""
    lib = _c()
    wdef = _init(L.WorldDef, "ws_world_def_init_sized")
    for field, value in world_params(d, threads).items():
        setattr(wdef, field, value)
    ld = load_def(d)
    ed = eumos_def(d)
    kd = _init(L.KvalueDef, "ws_kvalue_def_init_sized")
    kd.k_low, kd.k_high, kd.tolerance = k_low, k_high, tolerance
    kd.settle_time = d["unit_load"]["settle_s"]
    wd, sd = wrap_def(d), spiral_def(d)
    if wd is not None:
        kd.wrap = ctypes.pointer(wd)
    if sd is not None:
        kd.spiral = ctypes.pointer(sd)
    res = L.KvalueResult()
    st = lib.ws_loadtest_find_k(byref(wdef), byref(ld), byref(ed), byref(kd), byref(res))
    if st != L.WS_OK:
        raise WrapsimError(st, res.error.decode(errors="replace"))
    return dict(name=d["name"], k_value_g=res.k_value, k_fail_g=res.k_fail, runs=res.runs,
                settled=bool(res.settled), settle_s=res.settle_taken,
                error=res.error.decode(errors="replace"))
