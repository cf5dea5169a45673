"""The tilt, horizontal impact and vibration tests of a unit load, from a checked load file.

As for EUMOS (eumos.py), the runs, measurements, events and verdicts are the C library's
(ws_loadtest_run_tilt, ws_loadtest_run_impact, ws_loadtest_run_vibration): this module fills
their Defs from the load file and turns their results into the command's verdict.json, time
series and plots.
"""

import ctypes
import math
from ctypes import byref

import numpy as np

from . import World, _c
from . import _lib as L
from ._run import _progress
from .eumos import _EVENTS, _check, _init, prepare
from .loadrun import paraview_series, world_params

#: Each criterion of the C verdict: its text, the unit shown and the factor to it.
_CHECKS = {
    1: ("the load stands to the target angle (first slip, tip or loss)", "deg", math.degrees(1)),
    2: ("no carton leaves the load", "", 1.0),
    3: ("permanent displacement after the test <= 5 % of H", "mm", 1e3),
    4: ("layer shift after the test < 2 % of H", "mm", 1e3),
    5: ("velocity change delivered within 1 % of the speed", "%", 100.0),
    6: ("Grms delivered within 10 % of the level asked", "%", 100.0),
    7: ("resonance at least the minimum", "Hz", 1.0),
    8: ("no film rupture", "", 1.0),
}


def _sample_interval(d):
    return max(1, round(d["output"]["sample_interval_s"] / d["simulation"]["dt_s"]))


def _tilt(d):
    t = d["test"]
    td = _init(L.TiltTestDef, "ws_tilt_test_def_init_sized")
    td.rate = math.radians(t["rate_deg_per_s"])
    td.target_angle = math.radians(t["target_angle_deg"])
    duration = td.rest_before + 0.5 * td.ramp_time + td.target_angle / td.rate + \
        0.5 * td.stop_time + td.hold_time
    return td, "ws_loadtest_run_tilt", duration, None


def _impact(d):
    t = d["test"]
    im = _init(L.ImpactTestDef, "ws_impact_test_def_init_sized")
    im.speed = t["speed_m_per_s"]
    im.pulse_duration = t["pulse_ms"] * 1e-3
    im.coast_time = t["coast_s"]
    im.rest_after = t["rest_s"]
    duration = im.rest_before + 2 * im.speed / im.gentle_acceleration + im.coast_time + \
        im.pulse_duration + im.rest_after
    return im, "ws_loadtest_run_impact", duration, None


def _vibration(d):
    t = d["test"]
    vd = _init(L.VibrationTestDef, "ws_vibration_test_def_init_sized")
    vd.sweep = 1 if t["vibration"] == "sweep" else 0
    vd.duration = t["duration_s"]
    vd.ramp_time = min(vd.ramp_time, 0.25 * vd.duration)
    vd.rest_after = t["rest_s"]
    vd.grms = t["grms_g"]
    vd.seed = t["seed"]
    vd.sweep_level = t["sweep_g"]
    vd.frequency_start = t["sweep_from_hz"]
    vd.frequency_end = t["sweep_to_hz"]
    vd.resonance_min = t["resonance_min_hz"]
    keep = None
    if t["psd"]:
        f = (ctypes.c_double * len(t["psd"]))(*[p[0] for p in t["psd"]])
        g = (ctypes.c_double * len(t["psd"]))(*[p[1] for p in t["psd"]])
        vd.psd_frequency = ctypes.cast(f, ctypes.POINTER(ctypes.c_double))
        vd.psd_level = ctypes.cast(g, ctypes.POINTER(ctypes.c_double))
        vd.psd_count = len(t["psd"])
        keep = (f, g)
    # `keep`: the breakpoint arrays must live as long as the Def that points at them.
    return vd, "ws_loadtest_run_vibration", vd.rest_before + vd.duration + vd.rest_after, keep


def _criteria(v):
    out = []
    for c in v.check[:v.count]:
        text, unit, scale = _CHECKS.get(c.id, (str(c.id), "", 1.0))
        out.append(dict(criterion=text, id=_c().ws_loadtest_check_name(c.id).decode(),
                        measured=scale * c.value, unit=unit, limit=scale * c.limit,
                        at_least=bool(c.at_least), passed=bool(getattr(c, "pass"))))
    return out


def _result_dict(d, res, state_hash):
    kind = d["test"]["type"]
    v = res.verdict
    events = [dict(event=_EVENTS.get(e.type, str(e.type)), layer=e.layer, index=e.index,
                   t_s=e.time, level=e.level, value=e.value)
              for e in res.events[:res.event_count]]
    out = dict(name=d["name"], test=kind, form="unit_load", load_height_m=v.load_height,
               peak_level=res.peak_level, cartons_lost=res.cartons_lost,
               layer_max_mm=[1e3 * x for x in res.layer_max[:res.layers]],
               layer_permanent_mm=[1e3 * x for x in res.layer_permanent[:res.layers]],
               interface_slip_max_mm_per_s=[1e3 * x for x in
                                            res.interface_slip_max[:res.layers + 1]],
               interface_use_max=list(res.interface_use_max[:res.layers + 1]),
               events=events, events_dropped=res.events_dropped,
               film_peak_strain=res.film_peak_strain, criteria=_criteria(v),
               passed=bool(getattr(v, "pass")), state_hash=f"{state_hash:016x}",
               simulated_s=res.duration)
    if kind == "tilt":
        out.update(target_angle_deg=d["test"]["target_angle_deg"],
                   angle_reached_deg=math.degrees(res.angle_reached),
                   failure_angle_deg=(math.degrees(res.failure_angle)
                                      if res.failure_event >= 0 else None))
    elif kind == "impact":
        out.update(impact_speed_m_per_s=res.impact_speed,
                   velocity_change_m_per_s=res.velocity_change,
                   peak_deceleration_g=res.peak_deceleration)
    elif res.kind == L.LOADTEST_SWEEP:
        n = res.response_bins
        out.update(vibration="sweep", resonance_hz=res.resonance_frequency,
                   resonance_transmissibility=res.resonance_transmissibility,
                   response_hz=list(res.response_frequency[:n]),
                   response_transmissibility=list(res.response_transmissibility[:n]))
    else:
        out.update(vibration="random", grms_target_g=res.grms_target,
                   grms_delivered_g=res.grms_delivered)
    return out


def run(d, progress=False, desc="wrapsim", paraview=None, threads=1):
    """Build the unit load (wrapped when the file says so), let it settle and run its tilt,
    impact or vibration test on `threads` workers. Returns (result, series) like loadrun.run."""
    kind = d["test"]["type"]
    lib = _c()
    make = {"tilt": _tilt, "impact": _impact, "vibration": _vibration}[kind]
    with World(**world_params(d, threads)) as w:
        load = prepare(w, d)
        try:
            td, fn, duration, keep = make(d)
            td.sample_interval = _sample_interval(d)
            rows, cartons = [], []
            bar = _progress(int(round(duration / d["simulation"]["dt_s"])), desc, progress)
            vtk = paraview_series(w, d, paraview)

            def sample(user, smp):
                s = smp.contents
                if bar is not None:
                    bar.update(td.sample_interval)
                if vtk is not None:
                    vtk.write_frame()
                rows.append([s.time, s.level, s.angle, s.platform_velocity,
                             s.platform_position] +
                            [s.layer_displacement[i] for i in range(s.layers)] +
                            [s.interface[i].slip_speed for i in range(s.interfaces)] +
                            [s.interface[i].friction_use for i in range(s.interfaces)])
                cartons.append([(c.horizontal, c.tilt, b.slip_speed, b.friction_use)
                                for c, b in zip(s.carton[:s.cartons], s.carton_base[:s.cartons])])
                return 0

            cb = L.SampleFn(sample)
            td.on_sample = cb
            res = L.LoadtestResult()
            try:
                _check(w, getattr(lib, fn)(w.ptr, load, byref(td), byref(res)), fn)
            finally:
                if bar is not None:
                    bar.close()
                if vtk is not None:
                    vtk.close()
            del keep
            result = _result_dict(d, res, w.state_hash())
            n = ctypes.c_size_t()
            lib.ws_load_copy_cartons(load, None, 0, byref(n))
            places = (L.LoadCarton * n.value)()
            _check(w, lib.ws_load_copy_cartons(load, places, n.value, byref(n)),
                   "ws_load_copy_cartons")
        finally:
            lib.ws_load_destroy(load)
    layers = d["unit_load"]["layers"]
    data = np.array(rows).reshape(len(rows), 5 + layers + 2 * (layers + 1))
    series = {"t_s": data[:, 0]}
    if kind == "tilt":
        series["platform_angle_deg"] = np.degrees(data[:, 2])
        series["platform_tan_theta"] = data[:, 1]
    else:
        series["platform_acceleration_g"] = data[:, 1]
        series["platform_velocity_m_per_s"] = data[:, 3]
        series["platform_position_mm"] = 1e3 * data[:, 4]
    for i in range(layers):
        series[f"layer{i + 1}_displacement_mm"] = 1e3 * data[:, 5 + i]
    for i in range(layers + 1):
        series[f"interface{i}_slip_mm_per_s"] = 1e3 * data[:, 5 + layers + i]
    for i in range(layers + 1):
        series[f"interface{i}_friction_use"] = data[:, 6 + 2 * layers + i]
    # Per carton (layer l, place i): horizontal displacement against the pallet, tilt, and the
    # slip speed and friction use of the contacts under it.
    per = np.array(cartons).reshape(len(cartons), -1, 4)
    names = [(c.layer + 1, c.index + 1) for c in places]
    for k, (layer, index) in enumerate(names):
        stem = f"carton_l{layer}_{index}"
        series[f"{stem}_horizontal_mm"] = 1e3 * per[:, k, 0]
        series[f"{stem}_tilt_deg"] = np.degrees(per[:, k, 1])
        series[f"{stem}_base_slip_mm_per_s"] = 1e3 * per[:, k, 2]
        series[f"{stem}_base_friction_use"] = per[:, k, 3]
    return result, series
