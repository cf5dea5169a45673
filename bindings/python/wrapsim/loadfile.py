"""Load files: a description of a load, its wrap and its test, in JSON (or YAML).

Every quantity is in SI units, or in the unit its key names (`_percent`, `_deg`, `_deg_per_s`);
the unit of each key is in SPEC below, from which the JSON Schema (`wrapsim/load.schema.json`,
`json_schema()`) is made, so the two cannot disagree. `load()` reads a file, fills the
defaults and checks every value; a bad file raises LoadFileError whose message names the exact
path and what is wrong, e.g. "wrap.prestretch_around_percent: -20 is below 0 %".

Two forms of load: a column of cartons (`stack`) on a tilt table (`platform`, optionally with a
stop bar on its downhill side; `materials`, an optional film band `wrap`), or a unit load
(`unit_load`: a pallet with layers of cartons, the interfaces, an optional wrap) for the EUMOS
40509 test, the tilt, the horizontal impact or vibration, which the C library's load-test
module builds and judges. `test` says which test.
"""

import copy
import json
import math
import pathlib

FORMAT = "wrapsim-load 1"


class LoadFileError(ValueError):
    """A load file that cannot be used; the message names the path of the bad value."""


def _num(unit, default=None, minimum=None, maximum=None, exclusive_min=False, doc=""):
    return dict(kind="number", unit=unit, default=default, minimum=minimum, maximum=maximum,
                exclusive_min=exclusive_min, doc=doc)


def _int(default=None, minimum=None, maximum=None, doc=""):
    return dict(kind="integer", unit="", default=default, minimum=minimum, maximum=maximum,
                exclusive_min=False, doc=doc)


def _str(choices, default=None, doc=""):
    return dict(kind="string", choices=choices, default=default, doc=doc)


def _bool(default, doc=""):
    return dict(kind="boolean", unit="", default=default, minimum=None, maximum=None,
                exclusive_min=False, doc=doc)


def _pairs(doc=""):
    """A list of [x, y] pairs of positive numbers, x increasing (PSD breakpoints); [] for
    none."""
    return dict(kind="pairs", default=[], doc=doc)


def _section(fields, optional=False, doc=""):
    return dict(kind="object", fields=fields, optional=optional, doc=doc)


def _interface(mu, stiffness, damping, model="regularized", per="per contact point"):
    return _section({
        "friction_model": _str(["regularized", "stick"], model,
                               doc="regularized Coulomb (eq. 13; creeps below vlim) or the "
                                   "stick model (a tangential spring anchored at the contact)"),
        "mu": _num("", mu, 0.0, 10.0, doc="Coulomb friction coefficient"),
        "vlim_m_per_s": _num("m/s", 0.01, 0.0, 10.0, True,
                             doc="friction regularisation speed (eq. 13)"),
        "stiffness_N_per_m": _num("N/m", stiffness, 0.0, 1e12, True,
                                  doc=f"normal penalty stiffness, {per}"),
        "damping_kg_per_s": _num("kg/s", damping, 0.0, 1e9, doc=f"normal damping, {per}"),
    })


#: The load file's fields: kind, unit, default (None: required), range, and what it means.
SPEC = _section({
    "format": _str([FORMAT], FORMAT, doc="the format and its version"),
    "name": dict(kind="string", choices=None, default="load", doc="a name for the report"),
    "simulation": _section({
        "dt_s": _num("s", 2.5e-4, 0.0, 0.01, True, doc="time step"),
        "full_detection_until_s": _num("s", 0.5, 0.0, 1e6,
                                       doc="full contact detection every step until then"),
        "detection_interval": _int(5, 1, 1000, doc="then full detection every Nth step"),
    }),
    "platform": _section({
        "length_m": _num("m", 1.5, 0.0, 100.0, True, doc="extent along x (the tilt's downhill)"),
        "width_m": _num("m", 1.5, 0.0, 100.0, True, doc="extent along y"),
        "thickness_m": _num("m", 0.05, 0.0, 10.0, True),
        "stop": _section({
            "height_m": _num("m", 0.02, 0.0, 10.0, True, doc="height above the platform"),
            "thickness_m": _num("m", 0.02, 0.0, 10.0, True, doc="extent along x"),
        }, optional=True, doc="a bar along the downhill face of the bottom carton"),
    }),
    "unit_load": _section({
        "pallet": _section({
            "length_m": _num("m", 1.2, 0.0, 10.0, True, doc="along x, the test's direction"),
            "width_m": _num("m", 0.8, 0.0, 10.0, True),
            "height_m": _num("m", 0.144, 0.0, 10.0, True),
            "mass_kg": _num("kg", 25.0, 0.0, 1e4, True),
        }, doc="EUR 1200 x 800 x 144 mm by default"),
        "carton": _section({
            "length_m": _num("m", 0.3, 0.0, 10.0, True, doc="along the pallet's length"),
            "width_m": _num("m", 0.4, 0.0, 10.0, True),
            "height_m": _num("m", 0.25, 0.0, 10.0, True),
            "mass_kg": _num("kg", 10.0, 0.0, 1e5, True),
        }),
        "layers": _int(4, 1, 32),
        "count_x": _int(4, 1, 256, doc="cartons along the pallet's length in a layer"),
        "count_y": _int(2, 1, 256, doc="cartons across it"),
        "pattern": _str(["column", "brick", "turned"], "column",
                        doc="column stacking, or interlocked: bricks, or every second layer "
                            "turned"),
        "gap_m": _num("m", 0.003, 0.0, 1.0, doc="clear gap between neighbouring cartons"),
        "contact_layer_m": _num("m", 1e-3, 0.0, 0.1, True),
        "settle_s": _num("s", 4.0, 0.0, 100.0, True,
                         doc="the load settles until it stands still (drift under 0.1 mm/s), "
                             "at most this long (and again after wrapping)"),
        "interfaces": _section({
            "carton_carton": _interface(0.4, 2e6, 2000.0, "stick", "per interface"),
            "carton_pallet": _interface(0.45, 2e6, 2000.0, "stick", "per interface"),
            "pallet_platform": _interface(0.8, 2e7, 2e4, "stick", "per interface"),
            "film_carton": _interface(0.9, 4000.0, 1.0, "regularized", "per film node"),
        }, doc="stiffness and damping of a whole face pair, spread over its contact points"),
        "wrap": _section({
            "gauge_um": _num("um", 20.0, 0.0, 1000.0, True, doc="film thickness"),
            "modulus_MPa": _num("MPa", 150.0, 0.0, 1e5, True),
            "density_kg_per_m3": _num("kg/m^3", 920.0, 0.0, 1e4, True),
            "layers": _int(3, 1, 100, doc="film layers on top of each other"),
            "strain_around_percent": _num("%", 10.0, -99.0, 1000.0,
                                          doc="the strain the film holds on the load around"),
            "strain_up_percent": _num("%", 2.0, -99.0, 1000.0),
            "z_bottom_m": _num("m", 0.03, 0.0, 100.0, doc="lowest row above the platform"),
            "top_margin_m": _num("m", 0.03, 0.0, 100.0),
            "node_pitch_m": _num("m", 0.05, 0.0, 10.0, True),
            "node_mass_kg": _num("kg", 2e-3, 0.0, 10.0,
                                 doc="per node; 0 for the film's real mass"),
            "elongation_at_break_percent": _num("%", 400.0, 0.0, 10000.0,
                                                doc="from unstretched; 0: the film never breaks"),
            "powered_prestretch_percent": _num("%", 250.0, 0.0, 10000.0,
                                               doc="the pre-stretch before the film is laid"),
            "rupture_strain_percent": _num("%", 0.0, 0.0, 10000.0,
                                           doc="the film's rupture strain from its rest length; "
                                               "0: from the two above"),
            "integrator": _str(["explicit", "implicit"], "explicit",
                               doc="the film's: implicit is stable at any node mass in one "
                                   "sub-step (the film's real mass, its inertia on a sled, "
                                   "impact or vibration test)"),
        }, optional=True, doc="a band of film around the load (absent: unwrapped)"),
        "spiral_wrap": _section({
            "width_m": _num("m", 0.5, 0.0, 10.0, True, doc="film width off the roll"),
            "gauge_um": _num("um", 20.0, 0.0, 1000.0, True, doc="film thickness off the roll"),
            "modulus_MPa": _num("MPa", 150.0, 0.0, 1e5, True,
                                doc="Young's modulus of the film as it lies on the load"),
            "density_kg_per_m3": _num("kg/m^3", 920.0, 0.0, 1e4, True),
            "prestretch_percent": _num("%", 200.0, 0.0, 1000.0,
                                       doc="powered pre-stretch (plastic: thins the film)"),
            "neck_in_percent": _num("%", 15.0, 0.0, 90.0,
                                    doc="width the pre-stretch takes away"),
            "load_strain_percent": _num("%", 10.0, 0.0, 99.0, True,
                                        doc="elastic strain the film holds on the load"),
            "revolutions_bottom": _num("", 2.0, 0.0, 1000.0, doc="revolutions at the bottom"),
            "revolutions_top": _num("", 2.0, 0.0, 1000.0, doc="revolutions at the top"),
            "overlap_percent": _num("%", 50.0, 0.0, 95.0,
                                    doc="of the laid width, between spiral revolutions"),
            "passes": _int(2, 1, 2, doc="1: spiral up; 2: up and down"),
            "pallet_lock": _bool(True, doc="the film's lower edge goes down onto the pallet"),
            "lock_height_m": _num("m", 0.05, 0.0, 100.0,
                                  doc="the film's lower edge above the platform (with the "
                                      "lock) or above the deck (without)"),
            "top_margin_m": _num("m", 0.02, 0.0, 100.0,
                                 doc="the film's upper edge below the load's top"),
            "rope_revolutions": _num("", 0.0, 0.0, 1000.0,
                                     doc="revolutions of film rolled into a cable (0: none)"),
            "rope_height_m": _num("m", 0.2, 0.0, 100.0, True,
                                  doc="height of the rope above the platform"),
            "top_sheet": _bool(False, doc="a loose sheet of film over the top face, held by "
                                          "the top revolutions"),
            "top_sheet_gauge_um": _num("um", 50.0, 0.0, 5000.0, True,
                                       doc="thickness of the top sheet"),
            "node_pitch_m": _num("m", 0.05, 0.0, 10.0, True),
            "node_mass_min_kg": _num("kg", 0.0, 0.0, 10.0,
                                     doc="smallest node mass (0: the film's real mass)"),
            "elongation_at_break_percent": _num("%", 400.0, 0.0, 10000.0,
                                                doc="from the film off the roll; 0: the film "
                                                    "never breaks"),
            "rupture_strain_percent": _num("%", 0.0, 0.0, 10000.0,
                                           doc="the film's rupture strain from its rest length "
                                               "on the load; 0: from the elongation at break "
                                               "and the pre-stretch"),
            "integrator": _str(["explicit", "implicit"], "explicit",
                               doc="the film's: implicit is stable at any node mass in one "
                                   "sub-step (the film's real mass, its inertia on a sled, "
                                   "impact or vibration test)"),
        }, optional=True, doc="the spiral wrap of a stretch-wrapping machine (absent: none)"),
    }, optional=True, doc="a pallet with layers of cartons (the EUMOS test)"),
    "stack": _section({
        "carton": _section({
            "length_m": _num("m", None, 0.0, 10.0, True),
            "width_m": _num("m", None, 0.0, 10.0, True),
            "height_m": _num("m", None, 0.0, 10.0, True),
            "mass_kg": _num("kg", None, 0.0, 1e5, True),
        }),
        "layers": _int(None, 1, 50, doc="cartons stacked in one column"),
        "contact_layer_m": _num("m", 1e-3, 0.0, 0.1, True, doc="contact layer of every body"),
    }, optional=True, doc="a column of cartons on a tilt table"),
    "materials": _section({
        "carton_carton": _interface(0.3, 2e5, 10.0),
        "carton_platform": _interface(0.3, 2e5, 10.0),
        "film_carton": _interface(0.9, 4000.0, 1.0),
    }),
    "wrap": _section({
        "z_bottom_m": _num("m", 0.03, 0.0, 100.0, doc="band's lower edge above the platform"),
        "top_margin_m": _num("m", 0.02, 0.0, 100.0, doc="band's upper edge below the top"),
        "nodes_around": _int(96, 8, 100000),
        "nodes_up": _int(61, 2, 100000),
        "prestretch_around_percent": _num("%", 40.0, 0.0, 1000.0),
        "prestretch_up_percent": _num("%", 20.0, 0.0, 1000.0),
        "spring_stiffness_N_per_m": _num("N/m", 2000.0, 0.0, 1e9, True),
        "spring_damping_kg_per_s": _num("kg/s", 0.1, 0.0, 1e6),
        "node_mass_kg": _num("kg", 1e-3, 0.0, 10.0, True),
        "integrator": _str(["explicit", "implicit"], "explicit",
                           doc="the film's: implicit is stable at any node mass in one "
                               "sub-step (the film's real mass, its inertia on a sled, "
                               "impact or vibration test)"),
    }, optional=True, doc="a band of film around the stack (absent: unwrapped)"),
    "test": _section({
        "type": _str(["tilt", "eumos", "impact", "vibration"], "tilt",
                     doc="tilt table (ISO 10531; a stack or a unit_load), EUMOS 40509, "
                         "horizontal impact (ASTM D4003 / D5414, ISTA 3E) or vibration (ASTM "
                         "D4169 truck random, or a sine sweep); the last three need a unit_load"),
        "k_g": _num("g", 0.3, 0.0, 10.0, True, doc="eumos: the plateau acceleration"),
        "mode": _str(["accelerate", "brake"], "accelerate",
                     doc="eumos: a pulse from rest, or a run-up then braking at k g"),
        "rise_s": _num("s", 0.04, 0.0, 1.0, True, doc="eumos: the rise to k g (<= 0.05)"),
        "hold_s": _num("s", 0.35, 0.0, 100.0, doc="eumos: the plateau (>= 0.3)"),
        "speed_m_per_s": _num("m/s", 1.2, 0.0, 20.0, True,
                              doc="impact: the platform's speed at the impact (1.2, 1.75)"),
        "pulse_ms": _num("ms", 10.0, 0.0, 1000.0, True,
                         doc="impact: the programmer's half-sine deceleration"),
        "coast_s": _num("s", 0.2, 0.0, 100.0, doc="impact: at speed before the impact"),
        "rest_s": _num("s", 0.5, 0.0, 100.0,
                       doc="impact, vibration: at rest after, before the permanent state"),
        "vibration": _str(["random", "sweep"], "random",
                          doc="vibration: random from a PSD, or a sine sweep (resonance)"),
        "grms_g": _num("g", 0.54, 0.0, 20.0,
                       doc="vibration, random: the PSD scaled to this Grms (D4169 truck: 0.40, "
                           "0.54, 0.70); 0 plays the PSD as given"),
        "psd": _pairs(doc="vibration, random: breakpoints [Hz, g^2/Hz], log-log between; "
                          "[] (default): the library's truck spectrum"),
        "seed": _int(1, 0, 2 ** 53, doc="vibration, random: the same seed, the same history"),
        "sweep_g": _num("g", 0.25, 0.0, 10.0, True, doc="vibration, sweep: amplitude"),
        "sweep_from_hz": _num("Hz", 2.0, 0.0, 1e4, True, doc="vibration, sweep: start"),
        "sweep_to_hz": _num("Hz", 40.0, 0.0, 1e4, True, doc="vibration, sweep: end (log law)"),
        "resonance_min_hz": _num("Hz", 0.0, 0.0, 1e4,
                                 doc="vibration, sweep: the resonance must be at least this"),
        "start_s": _num("s", 1.0, 0.0, 1e6, doc="the tilt starts (smoothly) at this time"),
        "rate_deg_per_s": _num("deg/s", math.degrees(0.1), 0.0, 90.0, True),
        "duration_s": _num("s", 7.0, 0.0, 1e6, True,
                           doc="tilt of a stack: simulated time; vibration: the shaking"),
        "target_angle_deg": _num("deg", 20.0, 0.0, 89.0, True,
                                 doc="tilt: the load passes when nothing slips or tips below "
                                     "it"),
        "slip_limit_mm": _num("mm", 5.0, 0.0, 1e4, True,
                              doc="relative slip that counts as slipping"),
    }),
    "output": _section({
        "sample_interval_s": _num("s", 0.01, 0.0, 10.0, True, doc="time series sampling"),
        "paraview_interval_s": _num("s", 0.05, 0.0, 100.0,
                                    doc="time between ParaView frames (wrapsim run); 0: none"),
    }),
})


def _unit_text(unit):
    return f" {unit}" if unit else ""


def _check_value(spec, value, path):
    kind = spec["kind"]
    if kind == "boolean":
        if not isinstance(value, bool):
            raise LoadFileError(f"{path}: {value!r} is not true or false")
        return value
    if kind in ("number", "integer"):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise LoadFileError(f"{path}: {value!r} is not a number")
        if kind == "integer" and not (isinstance(value, int) or float(value).is_integer()):
            raise LoadFileError(f"{path}: {value!r} is not a whole number")
        if not math.isfinite(value):
            raise LoadFileError(f"{path}: {value!r} is not finite")
        lo, hi, unit = spec["minimum"], spec["maximum"], _unit_text(spec["unit"])
        if lo is not None and (value < lo or (spec["exclusive_min"] and value == lo)):
            word = "not above" if spec["exclusive_min"] else "below"
            raise LoadFileError(f"{path}: {value:g} is {word} {lo:g}{unit}")
        if hi is not None and value > hi:
            raise LoadFileError(f"{path}: {value:g} is above {hi:g}{unit}")
        return int(value) if kind == "integer" else float(value)
    if kind == "pairs":
        if not isinstance(value, list):
            raise LoadFileError(f"{path}: {value!r} is not a list of [x, y] pairs")
        out = []
        for i, pair in enumerate(value):
            if (not isinstance(pair, list) or len(pair) != 2 or
                    any(isinstance(x, bool) or not isinstance(x, (int, float)) or
                        not math.isfinite(x) or x <= 0 for x in pair)):
                raise LoadFileError(f"{path}[{i}]: {pair!r} is not a pair of numbers > 0")
            if out and pair[0] <= out[-1][0]:
                raise LoadFileError(f"{path}[{i}]: {pair[0]:g} does not increase on "
                                    f"{out[-1][0]:g}")
            out.append([float(pair[0]), float(pair[1])])
        if len(out) == 1:
            raise LoadFileError(f"{path}: one breakpoint; give at least two, or none")
        return out
    if kind == "string":
        if not isinstance(value, str):
            raise LoadFileError(f"{path}: {value!r} is not a string")
        if spec["choices"] is not None and value not in spec["choices"]:
            raise LoadFileError(f"{path}: {value!r} is not one of {', '.join(spec['choices'])}")
        return value
    return _check_section(spec, value, path)


def _check_section(spec, value, path):
    if not isinstance(value, dict):
        raise LoadFileError(f"{path or 'the file'}: expected an object (a section), "
                            f"got {type(value).__name__}")
    unknown = sorted(set(value) - set(spec["fields"]))
    if unknown:
        where = f"{path}." if path else ""
        raise LoadFileError(f"{where}{unknown[0]}: unknown key (known: "
                            f"{', '.join(spec['fields'])})")
    out = {}
    for key, sub in spec["fields"].items():
        sub_path = f"{path}.{key}" if path else key
        if key not in value or value[key] is None:
            if sub["kind"] == "object":
                if sub["optional"]:
                    out[key] = None
                else:
                    out[key] = _check_section(sub, {}, sub_path)
            elif sub["default"] is None:
                raise LoadFileError(f"{sub_path}: missing (a required value"
                                    f"{', in ' + sub['unit'] if sub.get('unit') else ''})")
            else:
                out[key] = copy.deepcopy(sub["default"])
        else:
            out[key] = _check_value(sub, value[key], sub_path)
    return out


def _film_breaks(path, elongation, prestretch, prestretch_key, rupture, laid, laid_key):
    """The library's rule for a film's rupture (ws_wrap_def, ws_spiral_wrap_def), in percent:
    the pre-stretch below the elongation at break, and the rupture strain above the strain the
    film is laid with (it would break as it is laid)."""
    if rupture == 0 and elongation > 0 and not prestretch < elongation:
        raise LoadFileError(f"{path}.elongation_at_break_percent: {elongation:g} % is not above "
                            f"{prestretch_key} ({prestretch:g} %): the film has no elongation "
                            f"left")
    strain = rupture if rupture > 0 else (
        0.0 if elongation == 0 else 100 * ((1 + elongation / 100) / (1 + prestretch / 100) - 1))
    if strain != 0 and not strain > laid:
        key = "rupture_strain_percent" if rupture > 0 else "elongation_at_break_percent"
        raise LoadFileError(f"{path}.{key}: the film's rupture strain ({strain:g} %) is not above "
                            f"{laid_key} ({laid:g} %): it would break as it is laid")


def _spiral_checks(sp, low, high, perimeter):
    """The spiral's figures the library checks against each other and the film's height on the
    load (low .. high, m above the platform; the pallet's perimeter, m)."""
    path = "unit_load.spiral_wrap"
    _film_breaks(path, sp["elongation_at_break_percent"], sp["prestretch_percent"],
                 "prestretch_percent", sp["rupture_strain_percent"], sp["load_strain_percent"],
                 "load_strain_percent")
    if not sp["node_pitch_m"] < 0.25 * (high - low):
        raise LoadFileError(f"{path}.node_pitch_m: {sp['node_pitch_m']:g} m is not under a "
                            f"quarter of the film's height on the load ({high - low:g} m)")
    nodes = (high - low) * perimeter / sp["node_pitch_m"] ** 2
    if nodes > 1e6:
        raise LoadFileError(f"{path}.node_pitch_m: {sp['node_pitch_m']:g} m makes about "
                            f"{nodes:.3g} film nodes, at most 1e6")
    if sp["rope_revolutions"] > 0 and not low <= sp["rope_height_m"] <= high:
        raise LoadFileError(f"{path}.rope_height_m: {sp['rope_height_m']:g} m is not on the film "
                            f"({low:g} .. {high:g} m above the platform)")
    # The spiral climbs its laid width less the overlap a revolution; the library lays at most
    # 1e4 revolutions.
    pitch = sp["width_m"] * (1 - sp["neck_in_percent"] / 100) * (1 - sp["overlap_percent"] / 100)
    revolutions = (sp["revolutions_bottom"] + sp["revolutions_top"] + sp["rope_revolutions"] +
                   sp["passes"] * (high - low) / pitch)
    if revolutions > 1e4:
        raise LoadFileError(f"{path}.width_m: {sp['width_m']:g} m climbs {pitch:g} m a "
                            f"revolution: about {revolutions:.3g} revolutions, at most 10000")


def _unit_load_test_checks(t):
    """The limits of the library's runs (ws_loadtest_run_tilt, _impact, _vibration) that the
    keys, shared with the stack's tilt, do not hold."""
    kind = t["type"]
    if kind == "tilt":
        rate = math.radians(t["rate_deg_per_s"])
        if rate > 1:
            raise LoadFileError(f"test.rate_deg_per_s: {t['rate_deg_per_s']:g} deg/s is above "
                                f"{math.degrees(1):.4g} (1 rad/s) for a unit load")
        if math.radians(t["target_angle_deg"]) / rate > 1e4:
            raise LoadFileError(f"test.rate_deg_per_s: {t['rate_deg_per_s']:g} deg/s takes more "
                                f"than 1e4 s to reach the target angle")
    if kind == "vibration":
        if t["duration_s"] > 1e4:
            raise LoadFileError(f"test.duration_s: {t['duration_s']:g} s is above 1e4 s for a "
                                f"vibration")
        if len(t["psd"]) > 10000:
            raise LoadFileError(f"test.psd: {len(t['psd'])} breakpoints, at most 10000")
        for i, (f, g) in enumerate(t["psd"]):
            # The history is sampled at 1024 Hz (ws_vibration_test_def.sample_rate).
            if f >= 512:
                raise LoadFileError(f"test.psd[{i}]: {f:g} Hz is not below 512 Hz (half the "
                                    f"1024 Hz the history is sampled at)")
            if g >= 1e12:
                raise LoadFileError(f"test.psd[{i}]: {g:g} g^2/Hz is not below 1e12")


def _cross_checks(d):
    """What one key alone cannot say."""
    if (d["stack"] is None) == (d["unit_load"] is None):
        raise LoadFileError("stack: give either a stack (a column on a tilt table) or a "
                            "unit_load (a pallet with layers of cartons), not both or neither")
    t = d["test"]
    kind = t["type"]
    if kind in ("eumos", "impact", "vibration") and d["unit_load"] is None:
        raise LoadFileError(f"test.type: '{kind}' needs a unit_load section")
    if t["sweep_to_hz"] <= t["sweep_from_hz"]:
        raise LoadFileError(f"test.sweep_to_hz: {t['sweep_to_hz']:g} Hz is not above "
                            f"sweep_from_hz ({t['sweep_from_hz']:g} Hz)")
    u = d["unit_load"]
    if u is not None and u["wrap"] is not None and u["spiral_wrap"] is not None:
        raise LoadFileError("unit_load.spiral_wrap: give a band (unit_load.wrap) or a spiral "
                            "(unit_load.spiral_wrap), not both")
    sp = u["spiral_wrap"] if u is not None else None
    if sp is not None:
        height = (u["pallet"]["height_m"] + u["layers"] * u["carton"]["height_m"])
        low = sp["lock_height_m"] + (0.0 if sp["pallet_lock"] else u["pallet"]["height_m"])
        if low + sp["top_margin_m"] >= height:
            raise LoadFileError(f"unit_load.spiral_wrap.lock_height_m: the film ({low:g} m "
                                f"above the platform to {sp['top_margin_m']:g} m below the "
                                f"top) has no height on a load {height:g} m high")
        _spiral_checks(sp, low, height - sp["top_margin_m"],
                       2 * (u["pallet"]["length_m"] + u["pallet"]["width_m"]))
    if u is not None and u["wrap"] is not None:
        w = u["wrap"]
        _film_breaks("unit_load.wrap", w["elongation_at_break_percent"],
                     w["powered_prestretch_percent"], "powered_prestretch_percent",
                     w["rupture_strain_percent"],
                     max(w["strain_around_percent"], w["strain_up_percent"]),
                     "strain_around_percent and strain_up_percent")
    if u is not None:
        _unit_load_test_checks(t)
    if d["stack"] is None:
        return
    c = d["stack"]["carton"]
    height = d["stack"]["layers"] * c["height_m"]
    w = d["wrap"]
    if w is not None and w["z_bottom_m"] + w["top_margin_m"] >= height:
        raise LoadFileError(f"wrap.z_bottom_m: the band ({w['z_bottom_m']:g} m from the bottom, "
                            f"{w['top_margin_m']:g} m below the top) has no height on a stack "
                            f"{height:g} m high")
    p = d["platform"]
    if max(c["length_m"], c["width_m"]) > min(p["length_m"], p["width_m"]):
        raise LoadFileError(f"platform.length_m: the platform ({p['length_m']:g} x "
                            f"{p['width_m']:g} m) is smaller than the carton")


def validate(data):
    """Check a parsed load file and fill its defaults; return the complete copy.
    Raise LoadFileError naming the path of the first bad value."""
    d = _check_section(SPEC, copy.deepcopy(data), "")
    _cross_checks(d)
    return d


def parse(path):
    """The raw content of a JSON (or, with PyYAML installed, YAML) load file."""
    p = pathlib.Path(path)
    try:
        text = p.read_text()
    except OSError as e:
        raise LoadFileError(f"{path}: cannot read: {e.strerror}") from None
    if p.suffix.lower() in (".yaml", ".yml"):
        try:
            import yaml
        except ImportError:
            raise LoadFileError(f"{path}: YAML needs PyYAML (Debian: python3-yaml)") from None
        try:
            return yaml.safe_load(text)
        except yaml.YAMLError as e:
            raise LoadFileError(f"{path}: not valid YAML: {e}") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as e:
        raise LoadFileError(f"{path}: not valid JSON: line {e.lineno}, column {e.colno}: "
                            f"{e.msg}") from None


def load(path):
    """Read, check and complete a load file (see validate)."""
    return validate(parse(path))


def set_path(d, dotted, value):
    """Set `a.b.c` in a nested dict (creating sections), as `--vary` does; return d."""
    keys = dotted.split(".")
    node = d
    for k in keys[:-1]:
        if node.get(k) is None:
            node[k] = {}
        node = node[k]
    node[keys[-1]] = value
    return d


def _schema_of(spec):
    kind = spec["kind"]
    if kind == "object":
        props = {k: _schema_of(v) for k, v in spec["fields"].items()}
        required = [k for k, v in spec["fields"].items()
                    if v["kind"] != "object" and v.get("default") is None]
        out = {"type": "object", "properties": props, "additionalProperties": False}
        if required:
            out["required"] = required
        if spec.get("optional"):
            out = {"anyOf": [out, {"type": "null"}]}
        if spec.get("doc"):
            out["description"] = spec["doc"]
        return out
    if kind == "pairs":
        out = {"type": "array", "items": {"type": "array", "minItems": 2, "maxItems": 2,
                                          "items": {"type": "number", "exclusiveMinimum": 0}}}
    elif kind == "string":
        out = {"type": "string"}
        if spec["choices"]:
            out["enum"] = list(spec["choices"])
    else:
        out = {"type": kind}
        if spec["minimum"] is not None:
            out["exclusiveMinimum" if spec["exclusive_min"] else "minimum"] = spec["minimum"]
        if spec["maximum"] is not None:
            out["maximum"] = spec["maximum"]
    desc = spec.get("doc", "")
    if spec.get("unit"):
        desc = f"{desc} [{spec['unit']}]".strip()
    if desc:
        out["description"] = desc
    if spec.get("default") is not None:
        out["default"] = spec["default"]
    return out


def json_schema():
    """The JSON Schema (draft 2020-12) of a load file, made from SPEC."""
    s = _schema_of(SPEC)
    s["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    s["title"] = f"libwrapsim load file ({FORMAT})"
    return s
