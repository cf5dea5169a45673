"""Python binding of libwrapsim (ctypes, no compiled extension).

Thin classes over the C API with its names and SI units: World, Shape, Material, Body, Law,
Web, VtkSeries; bulk data (web nodes and springs, contacts) as numpy arrays filled by the
library's bulk-copy calls. Every failing call raises WrapsimError with the world's last-error
text. See README.md next to this package.
"""

import ctypes
import operator
import os
from ctypes import byref, c_double, c_int, c_size_t, c_uint32, c_uint64, POINTER

import numpy as np

from . import _lib as L
from ._lib import LibraryError, BINDING_VERSION as __version__  # noqa: F401
from ._lib import (  # noqa: F401  (re-exported constants)
    WS_OK, WS_ERR_INVALID_ARGUMENT, WS_ERR_UNINITIALIZED_DEF, WS_ERR_STALE_HANDLE,
    WS_ERR_OUT_OF_MEMORY, WS_ERR_NUMERICAL, WS_ERR_BAD_MESH, WS_ERR_IN_USE, WS_ERR_CALLBACK,
    WS_ERR_BUFFER_TOO_SMALL, WS_ERR_IO, WS_ERR_UNSUPPORTED, WS_ERR_IN_STEP, WS_ERR_FORMAT,
    WS_LOG_DEBUG, WS_LOG_INFO, WS_LOG_WARNING, WS_LOG_ERROR, WS_FEATURE_CCD,
    WS_INTEGRATOR_SYMPLECTIC_EULER,
    WS_INTEGRATOR_PAPER_EXPLICIT, WS_FRICTION_REGULARIZED, WS_FRICTION_STICK,
    WS_FRICTION_STEP_IMPLICIT, WS_FRICTION_STEP_EXPLICIT, WS_BODY_DYNAMIC,
    WS_BODY_KINEMATIC, WS_DRIVE_STATIC, WS_DRIVE_TILT, WS_DRIVE_SINE, WS_DRIVE_CALLBACK,
    WS_CONTACT_POINT_FACE, WS_CONTACT_EDGE_EDGE, WS_CONTACT_FACE_POINT, WS_LAW_LINEAR_ELASTIC,
    WS_LAW_LINEAR_VISCOELASTIC, WS_LAW_TENSION_COMPRESSION, WS_LAW_LINEAR_VISCOUS,
    WS_LAW_CUBIC_ELASTIC, WS_LAW_TABLE, WS_LAW_STOP, WS_LAW_RELAXATION, WS_LAW_SUM,
    WS_LAW_SCALED, WS_LAW_USER, WS_LAW_FLAG_ELASTIC, WS_LAW_FLAG_VISCOUS, WS_SPRING_AROUND,
    WS_SPRING_UP, WS_SPRING_SHEAR)
from ._lib import (  # noqa: F401  (re-exported constants)
    WS_ELEMENT_ROD, WS_ELEMENT_LINEAR_SPRING, WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_BUSHING,
    WS_ELEMENT_INVARIANT, WS_ELEMENT_ATTACHED, WS_ELEMENT_POTENTIAL)
from ._lib import (  # noqa: F401  (re-exported constants)
    WS_DRIVE_PULSE, WS_DRIVE_IMPACT, WS_DRIVE_TABLE, WS_DRIVE_RANDOM, WS_DRIVE_SWEEP,
    WS_PULSE_ACCELERATE, WS_PULSE_BRAKE, WS_SWEEP_LOG, WS_SWEEP_LINEAR, WS_TRUCK_LOW,
    WS_TRUCK_MEDIUM, WS_TRUCK_HIGH, WS_STANDARD_GRAVITY)
from ._lib import (  # noqa: F401  (re-exported constants)
    WS_FEATURE_ZLIB, WS_VTK_COMPRESSED, WS_VTK_BINARY, WS_VTK_ASCII, WS_VTK_DEFAULT_BANDS,
    WS_VTK_MAX_BANDS)
from ._run import run  # noqa: F401

__all__ = ["World", "Shape", "Material", "Body", "Law", "Web", "VtkSeries", "WrapsimError",
           "LibraryError", "run", "version", "version_number", "build_features",
           "status_string", "CONTACT_DTYPE", "CONTAINMENT_DTYPE"]
__all__ += ["Element", "ELEMENT_OUTPUT_DTYPE"]
__all__ += ["synthesize_vibration", "vibration_grms", "truck_psd"]


class WrapsimError(RuntimeError):
    """A ws_status other than WS_OK. `status` is the code, `detail` the world's last-error
    text ("" when there was no world or no detail)."""

    def __init__(self, status, detail=""):
        self.status = int(status)
        self.detail = detail
        text = status_string(self.status)
        super().__init__(f"{text}: {detail}" if detail else text)


def _c():
    return L.lib()


def status_string(status):
    """The library's text for a status, e.g. "WS_ERR_STALE_HANDLE: ..."."""
    return _c().ws_status_string(_int(status, c_int, "status")).decode()


def version():
    """Runtime library version as text, e.g. "0.1.0"."""
    return _c().ws_version_string().decode()


def version_number():
    """Runtime library version as major*10000 + minor*100 + patch."""
    return _c().ws_version_number()


def build_features():
    """Bit set of WS_FEATURE_* compiled into the library."""
    return _c().ws_build_features()


# --- Def filling ---------------------------------------------------------------------------------
_ENUMS = {
    (L.WorldDef, "integrator"): {"symplectic_euler": 0, "paper_explicit": 1},
    (L.ContactDef, "friction_model"): {"regularized": 0, "stick": 1},
    (L.WebDef, "integrator"): {"explicit": 0, "implicit": 1},
    (L.WebDef, "preconditioner"): {"auto": 0, "block_jacobi": 1, "multigrid": 2},
    (L.BodyDef, "type"): {"dynamic": 0, "kinematic": 1},
    (L.DriveDef, "type"): {"static": 0, "tilt": 1, "sine": 2, "callback": 3, "pulse": 4,
                           "impact": 5, "table": 6, "random": 7, "sweep": 8},
    (L.DriveDef, "pulse_mode"): {"accelerate": 0, "brake": 1},
    (L.DriveDef, "sweep_law"): {"log": 0, "linear": 1},
    (L.LawDef, "type"): {"linear_elastic": 0, "linear_viscoelastic": 1,
                         "tension_compression": 2, "linear_viscous": 3, "cubic_elastic": 4,
                         "table": 5, "stop": 6, "relaxation": 7, "sum": 8, "scaled": 9,
                         "user": 10},
}


def _vec3(v):
    a = np.asarray(v, dtype=float).reshape(-1)
    if a.shape != (3,):
        raise ValueError(f"expected 3 numbers, got {v!r}")
    return L.Vec3(*a)


def _quat(v):
    a = np.asarray(v, dtype=float).reshape(-1)
    if a.shape != (4,):
        raise ValueError(f"expected 4 numbers (e0, e1, e2, e3), got {v!r}")
    return L.Quat(*a)


def _mat3(v):
    a = np.asarray(v, dtype=float).reshape(-1)
    if a.shape != (9,):
        raise ValueError(f"expected a 3x3 matrix, got {v!r}")
    m = L.Mat3()
    m.m[:] = list(a)
    return m


# --- argument checks ----------------------------------------------------------------------------
# ctypes truncates integers silently (a c_int given 2**32 + 8 gets 8) and a C call reads as many
# items as the count it is given, whatever the array holds. Every integer and every array that
# crosses into C goes through one of the two checks below first.

def _c_range(ctype):
    """(lowest, highest) value of a ctypes integer type."""
    bits = 8 * ctypes.sizeof(ctype)
    if ctype is ctypes.c_void_p or ctype(-1).value != -1:
        return 0, (1 << bits) - 1
    return -(1 << (bits - 1)), (1 << (bits - 1)) - 1


def _int(value, ctype, what):
    """`value` as a Python int that fits the C type: TypeError when it is not an integer (a
    float is not taken: it would be truncated), OverflowError when it is out of the type's
    range; the message names `what`."""
    try:
        v = operator.index(value)
    except TypeError:
        raise TypeError(f"{what}: expected an integer, got {value!r} "
                        f"({type(value).__name__})") from None
    lo, hi = _c_range(ctype)
    if not lo <= v <= hi:
        raise OverflowError(f"{what}: {v} is outside {lo}..{hi} (C {ctype.__name__})")
    return v


def _real(value, what):
    """`value` as a Python float for a C double, the message naming `what`: TypeError when it is
    not a number (None, a sequence, a complex), ValueError for a string that is not one,
    OverflowError for an integer too large for a double."""
    try:
        return float(value)
    except (TypeError, ValueError, OverflowError) as e:
        raise type(e)(f"{what}: expected a real number, got {value!r} "
                      f"({type(value).__name__})") from None


def _array(value, what, dtype, cols=None, length=None, per=None, bound=None):
    """`value` as a C-contiguous numpy array of `dtype` for a C call.

    cols: rows of that many values (a flat sequence is cut into rows). length: the number of
    rows (or values) the C call will read for it, `per` saying of what ("one per spring");
    ValueError when it has another. Integer dtypes take integers only (TypeError for floats,
    which would be truncated), each in 0..bound-1 when `bound` is given (ValueError) and in the
    dtype's range (OverflowError)."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError) as e:  # ragged rows and the like: say which argument
        raise type(e)(f"{what}: {e}") from None
    dt = np.dtype(dtype)
    if dt.kind in "iu":
        if a.size and a.dtype.kind not in "iuO":
            raise TypeError(f"{what}: expected integers, got {a.dtype} values")
        if a.size:
            if a.dtype.kind == "O":
                flat = [_int(x, ctypes.c_int64 if dt.kind == "i" else ctypes.c_uint64, what)
                        for x in a.reshape(-1)]
                lo, hi = min(flat), max(flat)
            else:
                lo, hi = int(a.min()), int(a.max())
            info = np.iinfo(dt)
            if bound is not None and (lo < 0 or hi >= bound):
                bad = lo if lo < 0 else hi
                raise ValueError(f"{what}: index {bad} is outside 0..{bound - 1}")
            if lo < info.min or hi > info.max:
                bad = lo if lo < info.min else hi
                raise OverflowError(f"{what}: {bad} is outside {info.min}..{info.max} ({dt})")
        a = np.asarray(a, dtype=dt) if a.dtype.kind != "O" else np.array(a.tolist(), dtype=dt)
    else:
        try:
            a = np.asarray(a, dtype=dt)
        except (TypeError, ValueError) as e:
            raise type(e)(f"{what}: {e}") from None
    if cols is not None:
        if a.size % cols:
            raise ValueError(f"{what}: expected rows of {cols} values, got {a.size} values")
        a = a.reshape(-1, cols)
    else:
        a = a.reshape(-1)
    if length is not None and len(a) != length:
        unit = "rows" if cols is not None else "values"
        raise ValueError(f"{what}: expected {length} {unit}"
                         + (f" ({per})" if per else "") + f", got {len(a)}")
    return np.ascontiguousarray(a)


def _id_of(v, idtype):
    if v is None:
        return idtype(0)
    if isinstance(v, _Handle):
        return idtype(v._id.bits)
    if isinstance(v, L._Id):
        return idtype(v.bits)
    return idtype(_int(v, c_uint64, f"{idtype.__name__}"))


def _convert(struct, name, ftype, value):
    if ftype is L.Vec3:
        return _vec3(value)
    if ftype is L.Quat:
        return _quat(value)
    if ftype is L.Mat3:
        return _mat3(value)
    if isinstance(ftype, type) and issubclass(ftype, L._Id):
        return _id_of(value, ftype)
    if ftype is ctypes.c_char_p:
        return None if value is None else str(value).encode()
    if isinstance(ftype, type) and issubclass(ftype, ctypes._Pointer):
        return value  # a pointer the caller made (arrays kept alive by it), or None
    if ftype is c_double:
        return _real(value, f"{type(struct).__name__}.{name}")
    if isinstance(value, str):
        names = _ENUMS.get((type(struct), name))
        if not names or value.lower() not in names:
            raise ValueError(f"{type(struct).__name__}.{name}: unknown value {value!r}"
                             + (f" (one of {', '.join(names)})" if names else ""))
        return names[value.lower()]
    if ftype is ctypes.c_void_p and value is None:
        return None
    if isinstance(ftype, type) and issubclass(ftype, ctypes._SimpleCData):
        return _int(value, ftype, f"{type(struct).__name__}.{name}")
    return int(value)


def _fill(struct, kwargs):
    """Set the fields of a Def (already filled by its C init) from keyword arguments."""
    fields = dict(struct._fields_)
    for k, v in kwargs.items():
        if k in ("size", "magic") or k not in fields:
            raise TypeError(f"{type(struct).__name__} has no parameter {k!r}")
        setattr(struct, k, _convert(struct, k, fields[k], v))
    return struct


def _make(struct_type, kwargs):
    d = struct_type()
    init = {s: n for n, s in L.DEF_INITS}[struct_type]
    getattr(_c(), init)(byref(d), ctypes.sizeof(d))
    return _fill(d, kwargs)


def _split(kwargs, *struct_types):
    """Route keyword arguments to the Def that has a field of that name."""
    out = [dict() for _ in struct_types]
    for k, v in kwargs.items():
        for i, st in enumerate(struct_types):
            if k in dict(st._fields_) and k not in ("size", "magic"):
                out[i][k] = v
                break
        else:
            raise TypeError(f"unknown parameter {k!r}")
    return out


def _struct_dict(s, skip=()):
    out = {}
    for name, _ in s._fields_:
        if name in skip:
            continue
        v = getattr(s, name)
        if isinstance(v, L.Vec3):
            v = np.array([v.x, v.y, v.z])
        elif isinstance(v, L.Quat):
            v = np.array([v.e0, v.e1, v.e2, v.e3])
        elif isinstance(v, L.Mat3):
            v = np.array(v.m[:]).reshape(3, 3)
        elif isinstance(v, L._Id):
            v = v.bits
        elif isinstance(v, bytes):
            v = v.decode()
        out[name] = v
    return out


def _np(v):
    return np.array([v.x, v.y, v.z])


def _ptr(a, ctype):
    return a.ctypes.data_as(POINTER(ctype))


#: numpy layout of ws_contact_info (body ids as their 64 bits).
CONTACT_DTYPE = np.dtype([
    ("body_a", np.uint64), ("body_b", np.uint64), ("point", np.float64, 3),
    ("normal", np.float64, 3), ("overlap", np.float64), ("normal_force", np.float64),
    ("friction_force", np.float64, 3), ("slip_velocity", np.float64, 3), ("kind", np.int32),
    ("slipping", np.int32), ("at_cap", np.int32), ("reserved_", np.int32),
    ("anchor_deflection", np.float64, 3)])
assert CONTACT_DTYPE.itemsize == ctypes.sizeof(L.ContactInfo)

#: numpy layout of ws_containment_band.
CONTAINMENT_DTYPE = np.dtype([
    ("z_low", np.float64), ("z_high", np.float64), ("hoop_tension", np.float64),
    ("line_load", np.float64), ("contact_force", np.float64)])
assert CONTAINMENT_DTYPE.itemsize == ctypes.sizeof(L.ContainmentBand)

# Element types and formulations by name (ws_element_def).
_ENUMS[(L.ElementDef, "type")] = {"rod": 0, "linear_spring": 1, "angular_spring": 2,
                                  "bushing": 3}
_ENUMS[(L.ElementDef, "formulation")] = {"invariant": 0, "attached": 1, "potential": 2}

#: numpy layout of ws_element_output: strain, strain_rate, law_force (6 each, the first `dim`
#: used), force (on body 1, N), moment (on body 1 about point1, N m), moment2 (on body 2 about
#: point2), point1, point2 (m), frame (law frame, e0..e3), energy (J); all global.
ELEMENT_OUTPUT_DTYPE = np.dtype([
    ("type", np.int32), ("dim", np.int32), ("strain", np.float64, 6),
    ("strain_rate", np.float64, 6), ("law_force", np.float64, 6), ("force", np.float64, 3),
    ("moment", np.float64, 3), ("moment2", np.float64, 3), ("point1", np.float64, 3),
    ("point2", np.float64, 3), ("frame", np.float64, 4), ("energy", np.float64)])
assert ELEMENT_OUTPUT_DTYPE.itemsize == ctypes.sizeof(L.ElementOutput)


# --- World ---------------------------------------------------------------------------------------
def _doubles(value, what):
    a = np.ascontiguousarray(np.asarray(value, dtype=float).reshape(-1))
    if a.size == 0:
        raise ValueError(f"{what}: no values")
    return a


def _psd_def(psd_frequency, psd_level, kwargs):
    """A DriveDef holding a PSD (the arrays returned too: they must outlive the call)."""
    f = _doubles(psd_frequency, "psd_frequency")
    g = _doubles(psd_level, "psd_level")
    if f.size != g.size:
        raise ValueError(f"psd_frequency has {f.size} values, psd_level {g.size}")
    d = _make(L.DriveDef, kwargs)
    d.psd_frequency = _ptr(f, c_double)
    d.psd_level = _ptr(g, c_double)
    d.psd_count = f.size
    return d, (f, g)


def synthesize_vibration(psd_frequency, psd_level, count, seed=0, sample_rate=1024.0):
    """The random vibration history (m/s^2, numpy array of `count` samples, a power of two) that
    a 'random' drive with these parameters plays (before its taper): the one-sided PSD
    (g^2/Hz at the breakpoints, Hz; log-log between) by the inverse FFT with phases from
    `seed`. The same arguments give the same history to the bit."""
    count = int(count)
    if count < 16 or count & (count - 1):
        raise ValueError(f"count must be a power of two >= 16, got {count}")
    d, keep = _psd_def(psd_frequency, psd_level, {"seed": int(seed),
                                                  "sample_rate": float(sample_rate)})
    out = np.empty(count)
    s = _c().ws_vibration_synthesize(None, byref(d), _ptr(out, c_double), count)
    if s != WS_OK:
        raise WrapsimError(s, "ws_vibration_synthesize: bad PSD, sample rate or count")
    del keep
    return out


def vibration_grms(psd_frequency, psd_level):
    """The Grms (g) of a PSD given by breakpoints (Hz, g^2/Hz, log-log between them)."""
    f = _doubles(psd_frequency, "psd_frequency")
    g = _doubles(psd_level, "psd_level")
    if f.size != g.size:
        raise ValueError(f"psd_frequency has {f.size} values, psd_level {g.size}")
    out = c_double()
    s = _c().ws_vibration_grms(_ptr(f, c_double), _ptr(g, c_double), f.size, byref(out))
    if s != WS_OK:
        raise WrapsimError(s, "ws_vibration_grms: frequencies must be > 0 and increasing, "
                              "levels > 0, at least 2")
    return out.value


def truck_psd(level="medium"):
    """The library's ASTM D4169 truck spectrum at a level ('low' 0.40, 'medium' 0.54, 'high'
    0.70 Grms, or 1, 2, 3): (frequencies Hz, levels g^2/Hz) as numpy arrays."""
    levels = {"low": 1, "medium": 2, "high": 3}
    lv = levels.get(level, level) if isinstance(level, str) else int(level)
    if lv not in (1, 2, 3):
        raise ValueError(f"unknown truck level {level!r} (low, medium, high)")
    n = ctypes.c_size_t()
    f, g = np.empty(64), np.empty(64)
    s = _c().ws_vibration_truck_psd(lv, _ptr(f, c_double), _ptr(g, c_double), 64, byref(n))
    if s != WS_OK:
        raise WrapsimError(s)
    return f[:n.value].copy(), g[:n.value].copy()


class World:
    """A world: owner of every shape, body, material, law and web. Use as a context manager, or
    call close(). Keyword arguments are the fields of ws_world_def (dt, gravity, integrator,
    full_detection_until, detection_interval, contact_margin, max_speed, max_angular_speed,
    use_ccd, profile, user_data, stable_fraction, worker_count, friction_step); `log` may be a
    callable(level, message)."""

    def __init__(self, log=None, **kwargs):
        self._ptr = None
        self._callbacks = {}  # body id bits -> the ctypes drive callbacks, kept alive
        self._series = []
        self._bodies = {}
        self._pending = None  # an exception raised inside a callback
        d = _make(L.WorldDef, kwargs)
        if log is not None:
            def _log(user, level, message, _fn=log):
                try:
                    _fn(int(level), message.decode(errors="replace"))
                except Exception:  # noqa: BLE001 - never let an exception cross into C
                    pass
            self._log = L.LogFn(_log)
            d.log = self._log
        p = L.World_p()
        s = _c().ws_world_create(byref(d), byref(p))
        if s != WS_OK:
            raise WrapsimError(s, "ws_world_create")
        self._ptr = p

    # lifetime
    def close(self):
        """Destroy the world and everything in it (open VTK series first)."""
        for series in self._series:
            series.close()
        self._series = []
        if self._ptr:
            _c().ws_world_destroy(self._ptr)
        self._ptr = None
        self._callbacks.clear()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass

    # A World owns its C world: a copy would share it, and closing one would free it under the
    # other. Copying and pickling are refused; save() and restore() carry a state across.
    def __copy__(self):
        raise TypeError("a wrapsim.World cannot be copied (the copy would share its C world); "
                        "build another World and restore() a save() into it")

    def __deepcopy__(self, memo):
        self.__copy__()

    def __reduce_ex__(self, protocol):
        raise TypeError("a wrapsim.World cannot be pickled or copied; save() gives its state as "
                        "bytes, which restore() takes in a World built the same way")

    @property
    def closed(self):
        return not self._ptr

    @property
    def ptr(self):
        """The ws_world pointer; WrapsimError once the world is closed."""
        if not self._ptr:
            raise WrapsimError(WS_ERR_STALE_HANDLE, "the world was closed")
        return self._ptr

    def _call(self, name, *args):
        s = getattr(_c(), name)(self.ptr, *args)
        if s != WS_OK:
            detail = _c().ws_world_last_error(self._ptr).decode(errors="replace")
            pending, self._pending = self._pending, None
            err = WrapsimError(s, detail)
            if pending is not None:
                raise err from pending
            raise err
        return s

    @property
    def last_error(self):
        """The detail of the last error in this world ("" when none)."""
        return _c().ws_world_last_error(self.ptr).decode(errors="replace")

    @property
    def user_data(self):
        """The user_data pointer of the Def, as an int (or None)."""
        return _c().ws_world_get_user_data(self.ptr)

    # stepping and state
    def step(self, n=1):
        """Take n steps of dt (one ws_world_step for n == 1, else ws_world_step_n)."""
        n = _int(n, ctypes.c_int64, "step count")
        if n == 1:
            self._call("ws_world_step")
        else:
            self._call("ws_world_step_n", n)

    @property
    def time(self):
        """Simulated time, s."""
        t = c_double()
        self._call("ws_world_get_time", byref(t))
        return t.value

    @property
    def dt(self):
        """Time step, s (settable between steps)."""
        t = c_double()
        self._call("ws_world_get_dt", byref(t))
        return t.value

    @dt.setter
    def dt(self, value):
        self._call("ws_world_set_dt", float(value))

    @property
    def stable_fraction(self):
        """The film's stable-step safety factor (a web runs while dt / substeps is at most
        this times its stable sub-step)."""
        f = c_double()
        self._call("ws_world_get_stable_fraction", byref(f))
        return f.value

    def set_gravity(self, g):
        """Gravity, m/s^2."""
        self._call("ws_world_set_gravity", byref(_vec3(g)))

    gravity = property(None, set_gravity)

    def stats(self):
        """Counters and figures (ws_world_stats) as a dict."""
        st = L.WorldStats()
        self._call("ws_world_get_stats", byref(st))
        return _struct_dict(st, skip=("reserved",))

    def energy(self):
        """Energy of the dynamic bodies, J: dict of kinetic, potential, contact."""
        e = L.Energy()
        self._call("ws_world_get_energy", byref(e))
        return _struct_dict(e)

    def state_hash(self):
        """64-bit hash of the whole dynamic state."""
        h = c_uint64()
        self._call("ws_world_get_state_hash", byref(h))
        return h.value

    def save(self, path=None):
        """The world's state (ws_world_save): as bytes when `path` is None, else written to the
        file `path` (ws_world_save_file; then None is returned). It holds the state, not the
        structure: restore() it into a World built the same way."""
        if path is not None:
            self._call("ws_world_save_file", os.fsencode(path))
            return None
        n = c_size_t()
        self._call("ws_world_save", None, 0, byref(n))
        buf = ctypes.create_string_buffer(n.value)
        self._call("ws_world_save", buf, n.value, byref(n))
        return buf.raw[:n.value]

    def restore(self, data_or_path):
        """Restore a state from save(): bytes (or a bytearray, memoryview) or a file path. The
        world must have been built as the saved one was; a save that is truncated, corrupted,
        newer or of another structure raises WrapsimError (WS_ERR_FORMAT) and changes nothing."""
        if isinstance(data_or_path, (bytes, bytearray, memoryview)):
            data = bytes(data_or_path)
            self._call("ws_world_restore", data, len(data))
        elif isinstance(data_or_path, (str, os.PathLike)):
            self._call("ws_world_restore_file", os.fsencode(data_or_path))
        else:
            raise TypeError("restore() takes bytes from save() or a path, got %s"
                            % type(data_or_path).__name__)

    def estimate_stable_dt(self):
        """Largest stable dt (s) estimated for the bodies and contact pairs now in the world."""
        t = c_double()
        self._call("ws_world_estimate_stable_dt", byref(t))
        return t.value

    # materials and contact pairs
    @property
    def default_material(self):
        out = L.MaterialId()
        self._call("ws_world_get_default_material", byref(out))
        return Material(self, out, "default")

    def material(self, name=None):
        """Create a material (only a name; parameters belong to pairs)."""
        d = _make(L.MaterialDef, {"name": name})
        out = L.MaterialId()
        self._call("ws_material_create", byref(d), byref(out))
        return Material(self, out, name)

    def set_contact(self, a, b, **params):
        """Contact parameters between materials a and b: ws_contact_def fields (stiffness N/m,
        damping kg/s, friction, friction_vlim m/s, friction_model, stick_stiffness,
        stick_damping kg/s, or 0 for stick_damping_ratio of critical); the others keep
        ws_contact_def_init's defaults."""
        d = _make(L.ContactDef, params)
        self._call("ws_world_set_contact", _id_of(a, L.MaterialId), _id_of(b, L.MaterialId),
                   byref(d))

    def get_contact(self, a, b):
        """The parameters that apply between materials a and b, as a dict."""
        d = L.ContactDef()
        self._call("ws_world_get_contact", _id_of(a, L.MaterialId), _id_of(b, L.MaterialId),
                   byref(d))
        return _struct_dict(d, skip=("size", "magic"))

    def set_default_contact(self, **params):
        """Parameters for every pair not set explicitly."""
        d = _make(L.ContactDef, params)
        self._call("ws_world_set_default_contact", byref(d))

    # shapes
    def box(self, lx, ly, lz):
        """A box shape with full edge lengths lx, ly, lz (m), centred on the origin."""
        out = L.ShapeId()
        self._call("ws_shape_create_box", float(lx), float(ly), float(lz), byref(out))
        return Shape(self, out)

    shape_box = box

    def cylinder(self, radius, height, segments=32):
        """A prism approximating a cylinder along z (m), `segments` sides."""
        out = L.ShapeId()
        self._call("ws_shape_create_cylinder", float(radius), float(height),
                   _int(segments, c_int, "cylinder segments"), byref(out))
        return Shape(self, out)

    def mesh(self, vertices, triangles):
        """A closed mesh shape: vertices (n, 3) in m, triangles (m, 3) indices, counter-
        clockwise seen from outside."""
        v = _array(vertices, "mesh vertices", np.float64, cols=3)
        t = _array(triangles, "mesh triangles", np.uint32, cols=3, bound=len(v))
        d = _make(L.MeshDef, {})
        d.vertices = _ptr(v, c_double)
        d.vertex_count = len(v)
        d.triangles = _ptr(t, c_uint32)
        d.triangle_count = len(t)
        out = L.ShapeId()
        self._call("ws_shape_create_mesh", byref(d), byref(out))
        return Shape(self, out)

    def mesh_from_file(self, path, scale=1.0, weld_tol=1e-6, flip=False, file_format=None):
        """A closed mesh shape read from an STL (ASCII or binary), OBJ or PLY file (needs
        meshio). `scale` turns the file's numbers into metres (0.001 for a file in mm);
        vertices closer than `weld_tol` times the mesh's size are welded into one (STL repeats
        every vertex in each of its triangles); `flip` reverses an inside-out mesh. Like every
        mesh, the shape is re-centred on its volume centroid: create its body at
        `shape.centroid_offset` (identity orientation) to put it where the file had it. Raises
        wrapsim.meshfile.MeshFileError (a WrapsimError) naming the file, and for a mesh the
        library refuses, the offending edge's vertex positions in the file's units."""
        from . import meshfile
        v, t = meshfile.read_mesh(path, scale=scale, weld_tol=weld_tol, flip=flip,
                                  file_format=file_format)
        try:
            return self.mesh(v, t)
        except WrapsimError as e:
            if e.status != WS_ERR_BAD_MESH:
                raise
            raise meshfile.refused(str(path), e, v, t, float(scale), float(weld_tol)) from e

    # bodies
    def body(self, shape, **kwargs):
        """Create a body: ws_body_def fields as keywords (type 'dynamic'/'kinematic', material,
        mass kg, density kg/m^3, inertia 3x3, contact_layer m, position m, orientation
        (e0..e3), velocity m/s, angular_velocity rad/s, name, user_data)."""
        kwargs["shape"] = shape
        d = _make(L.BodyDef, kwargs)
        out = L.BodyId()
        self._call("ws_body_create", byref(d), byref(out))
        b = Body(self, out)
        self._bodies[out.bits] = b
        return b

    def bodies(self):
        """Every live body, in creation order."""
        n = c_size_t()
        self._call("ws_world_copy_body_ids", None, 0, byref(n))
        buf = (L.BodyId * max(n.value, 1))()
        self._call("ws_world_copy_body_ids", buf, n.value, byref(n))
        return [self.body_by_id(buf[i].bits) for i in range(n.value)]

    def body_by_id(self, bits):
        """The Body for a body id's 64 bits (e.g. from contacts()['body_a'])."""
        bits = _int(bits, c_uint64, "body id")
        b = self._bodies.get(bits)
        if b is None:
            b = self._bodies[bits] = Body(self, L.BodyId(bits))
        return b

    # contacts
    def contact_count(self):
        n = c_size_t()
        self._call("ws_world_get_contact_count", byref(n))
        return n.value

    def contacts(self):
        """Active contacts of the last step as a numpy structured array (CONTACT_DTYPE): body_a,
        body_b (id bits; see body_by_id), point, normal, overlap, normal_force, friction_force,
        slip_velocity, kind, slipping (sliding), at_cap (friction at mu N this step),
        anchor_deflection (stick model, m). Forces are those on body_b."""
        n = c_size_t()
        self._call("ws_world_copy_contacts", None, 0, byref(n))
        buf = np.zeros(n.value, dtype=CONTACT_DTYPE)
        if n.value:
            self._call("ws_world_copy_contacts", _ptr(buf, L.ContactInfo), len(buf), byref(n))
        return buf[: n.value]

    def contacts_between(self, a, b):
        """Active contacts between Bodies a and b, in that order: body_a is a, the normal points
        from a to b, the forces and slip velocity are b's, whichever body owns the face (kind
        WS_CONTACT_FACE_POINT: a point of a in a face of b). Same dtype as contacts()."""
        n = c_size_t()
        self._call("ws_world_copy_contacts_between", a._id, b._id, None, 0, byref(n))
        buf = np.zeros(n.value, dtype=CONTACT_DTYPE)
        if n.value:
            self._call("ws_world_copy_contacts_between", a._id, b._id,
                       _ptr(buf, L.ContactInfo), len(buf), byref(n))
        return buf[: n.value]

    def interface_stiffness(self, a, b):
        """(stiffness N/m, points): the summed normal stiffness of the active contact points
        between Bodies a and b (each one's share of k) and their number (4 for a box on a larger
        plane, 4k; 8 for two equal boxes face to face, twins at each corner, 4k)."""
        k, n = c_double(), c_size_t()
        self._call("ws_world_get_interface_stiffness", a._id, b._id, byref(k), byref(n))
        return k.value, n.value

    # laws and webs
    def law(self, type="linear_elastic", **kwargs):
        """A constitutive law: ws_law_def fields (type, dim, stiffness N, compression_stiffness
        N, damping N s, transition, name, cubic_stiffness, stop_low, stop_high, scale,
        user_flags). Arrays are given as sequences and their counts are set from them:
        stiffness_matrix and damping_matrix (dim x dim), cubic_stiffnesses (dim), table_strain
        and table_force, prony_stiffness and prony_time (N, s), terms (Laws of a sum), base (the
        Law of a scaled law), scale_times and scale_factors. Callables: scale_fn(t) -> factor
        for a scaled law; user_fn(u, ud, t) -> (F, dF/du, dF/dud) for a user law (numpy arrays
        of dim, dim x dim; the derivatives may be left out, they are then zero). An exception in
        a callable fails the evaluation with WS_ERR_CALLBACK, chained to the WrapsimError."""
        kwargs["type"] = type
        keep = []  # arrays and callbacks that must live through (or beyond) the create call

        def arr(name, length=None, per=None):
            a = _array(kwargs[name], f"law {name}", np.float64, length=length, per=per)
            keep.append(a)
            kwargs[name] = _ptr(a, c_double)
            return len(a)

        # The library reads dim x dim matrices and dim stiffnesses; a dim it refuses reads none.
        dim = _int(kwargs.get("dim", 1), c_int, "law dim")
        known = dim if dim in (1, 3, 6) else None
        for name, length, per in (("stiffness_matrix", known and known * known, "dim x dim"),
                                  ("damping_matrix", known and known * known, "dim x dim"),
                                  ("cubic_stiffnesses", known, "one per component")):
            if kwargs.get(name) is not None:
                arr(name, length, per)
        # Each pair of arrays shares one count, which the binding sets from their length.
        for xs, ys, count in (("table_strain", "table_force", "table_count"),
                              ("prony_stiffness", "prony_time", "prony_count"),
                              ("scale_times", "scale_factors", "scale_count")):
            n = None
            for name in (xs, ys):
                if kwargs.get(name) is not None:
                    n = arr(name, n, f"as many as {xs}" if name == ys and n is not None
                            else None)
            if count in kwargs:
                given = _int(kwargs[count], c_size_t, f"law {count}")
                if given != (n or 0):
                    raise ValueError(f"law {count}: {given} does not match the arrays "
                                     f"{xs}, {ys} ({n or 0} values); leave it out")
            if n is not None:
                kwargs[count] = n
        if kwargs.get("terms") is not None:
            terms = list(kwargs["terms"])
            ids = (L.LawId * max(1, len(terms)))(*[_id_of(t, L.LawId) for t in terms])
            keep.append(ids)
            if "term_count" in kwargs and _int(kwargs["term_count"], c_size_t,
                                               "law term_count") != len(terms):
                raise ValueError(f"law term_count: {kwargs['term_count']} does not match the "
                                 f"{len(terms)} terms; leave it out")
            kwargs["term_count"] = len(terms)
            kwargs["terms"] = ctypes.cast(ids, POINTER(L.LawId))
        elif kwargs.get("term_count"):
            raise ValueError("law term_count: given without terms")
        callbacks = []
        scale_fn = kwargs.pop("scale_fn", None)
        user_fn = kwargs.pop("user_fn", None)
        d = _make(L.LawDef, kwargs)
        if scale_fn is not None:
            def _time(user, t, factor, _fn=scale_fn, _world=self):
                try:
                    factor[0] = float(_fn(t))
                    return 0
                except Exception as e:  # noqa: BLE001 - reported through the call's error
                    _world._pending = e
                    return 1
            cb = L.LawTimeFn(_time)
            callbacks.append(cb)
            d.scale_fn = cb
        if user_fn is not None:
            def _user(user, dim, u, ud, t, F, K, C, _fn=user_fn, _world=self):
                try:
                    r = _fn(np.ctypeslib.as_array(u, shape=(dim,)).copy(),
                            np.ctypeslib.as_array(ud, shape=(dim,)).copy(), t)
                    if not isinstance(r, (tuple, list)):
                        r = (r,)
                    np.ctypeslib.as_array(F, shape=(dim,))[:] = np.asarray(
                        r[0], dtype=float).reshape(dim)
                    for out, val in zip((K, C), r[1:3]):
                        if val is not None:
                            np.ctypeslib.as_array(out, shape=(dim * dim,))[:] = np.asarray(
                                val, dtype=float).reshape(dim * dim)
                    return 0
                except Exception as e:  # noqa: BLE001 - reported through the call's error
                    _world._pending = e
                    return 1
            cb = L.LawUserFn(_user)
            callbacks.append(cb)
            d.user_fn = cb
        out = L.LawId()
        self._call("ws_law_create", byref(d), byref(out))
        if callbacks:
            # The library calls them for as long as the law lives.
            self._callbacks.setdefault(out.bits, []).extend(callbacks)
        return Law(self, out)

    def _web_def(self, kw):
        return _make(L.WebDef, kw)

    def web_sheet(self, law, pinned=None, **kwargs):
        """A rectangular sheet: ws_web_def fields (law, law_cross, law_shear, node_mass,
        areal_density, contact_layer, material, node_damping, substeps, name, rupture_strain,
        integrator ("explicit" or "implicit"), solver_tolerance (each row's residual over its
        own weight m g h, default 1e-3), solver_max_iterations,
        preconditioner ("auto", "block_jacobi" or "multigrid"), hold_bodies) and
        ws_sheet_def
        fields (nx, ny, origin, axis_x, axis_y, spacing_x, spacing_y, prestretch_x,
        prestretch_y, shear); `pinned` a sequence of node indices i + nx j."""
        wk, sk = _split(kwargs, L.WebDef, L.SheetDef)
        if "pinned_count" in sk:
            raise TypeError("web_sheet: pinned_count is set from `pinned`; leave it out")
        wk["law"] = law
        wd = self._web_def(wk)
        sd = _make(L.SheetDef, sk)
        pins = None
        if pinned is not None:
            # Node indices i + nx j: below nx ny when the grid is one the library takes.
            nodes = sd.nx * sd.ny if sd.nx >= 1 and sd.ny >= 1 else None
            pins = _array(pinned, "web_sheet pinned", np.uint32, bound=nodes)
        if pins is not None and len(pins):
            sd.pinned = _ptr(pins, c_uint32)
            sd.pinned_count = len(pins)
        out = L.WebId()
        self._call("ws_web_create_sheet", byref(wd), byref(sd), byref(out))
        return Web(self, out)

    def web_band(self, law, bodies, **kwargs):
        """A band wrapped around `bodies` (as they are now): ws_web_def fields (as web_sheet,
        rupture_strain among them) and ws_band_def fields (z_bottom, z_top m, n_around, n_up,
        prestretch_around, prestretch_up, gap m, shear)."""
        wk, bk = _split(kwargs, L.WebDef, L.BandDef)
        if "body_count" in bk:
            raise TypeError("web_band: body_count is set from `bodies`; leave it out")
        bodies = list(bodies)
        wk["law"] = law
        wd = self._web_def(wk)
        bd = _make(L.BandDef, bk)
        ids = (L.BodyId * max(len(bodies), 1))(*[_id_of(b, L.BodyId) for b in bodies])
        bd.bodies = ctypes.cast(ids, POINTER(L.BodyId))
        bd.body_count = len(bodies)
        out = L.WebId()
        self._call("ws_web_create_band", byref(wd), byref(bd), byref(out))
        return Web(self, out)

    def web_mesh(self, law, positions, springs, node_masses=None, rest_lengths=None,
                 kinds=None, pinned=None, stiffness_scales=None, **kwargs):
        """A web of raw nodes (positions (n, 3) m) and springs ((m, 2) node indices), with
        optional node_masses (kg), rest_lengths (m), kinds (ws_spring_kind), pinned nodes and
        stiffness_scales (each spring's force as a multiple of its law's, e.g. its film
        layers); other keywords are ws_web_def fields."""
        kwargs["law"] = law
        wd = self._web_def(kwargs)
        md = _make(L.WebMeshDef, {})
        keep = []

        def arr(a, what, dtype, ctype, **check):
            a = _array(a, f"web_mesh {what}", dtype, **check)
            keep.append(a)
            return a, _ptr(a, ctype)

        pos, md.positions = arr(positions, "positions", np.float64, c_double, cols=3)
        n = md.node_count = len(pos)
        spr, md.springs = arr(springs, "springs", np.uint32, c_uint32, cols=2, bound=n)
        m = md.spring_count = len(spr)
        if node_masses is not None:
            _, md.node_masses = arr(node_masses, "node_masses", np.float64, c_double,
                                    length=n, per="one per node")
        if rest_lengths is not None:
            _, md.rest_lengths = arr(rest_lengths, "rest_lengths", np.float64, c_double,
                                     length=m, per="one per spring")
        if kinds is not None:
            _, md.kinds = arr(kinds, "kinds", np.uint8, ctypes.c_uint8, length=m,
                              per="one per spring", bound=3)
        if stiffness_scales is not None:
            _, md.stiffness_scales = arr(stiffness_scales, "stiffness_scales", np.float64,
                                         c_double, length=m, per="one per spring")
        if pinned is not None:
            pins, ptr = arr(pinned, "pinned", np.uint32, c_uint32, bound=n)
            if len(pins):
                md.pinned, md.pinned_count = ptr, len(pins)
        out = L.WebId()
        self._call("ws_web_create_mesh", byref(wd), byref(md), byref(out))
        return Web(self, out)

    # deformable elements
    def element(self, type, body1, body2, law, **kwargs):
        """A deformable element between body1 and body2 (a Body, or None for the fixed world
        frame): type 'rod', 'linear_spring', 'angular_spring' or 'bushing'; `law` of dim 1, 3
        or 6 to match. Other keywords are ws_element_def fields: formulation ('invariant'
        (default), 'attached', 'potential'), point1, point2 (m, in the bodies' frames),
        frame1, frame2 (e0..e3; zero = automatic), global_attachment (1: points and frames are
        global, at the poses now), rest_length (m, rods; <= 0: the distance now), name,
        user_data."""
        kwargs.update(type=type, body1=body1, body2=body2, law=law)
        d = _make(L.ElementDef, kwargs)
        out = L.ElementId()
        self._call("ws_element_create", byref(d), byref(out))
        return Element(self, out)

    def elements(self):
        """Every live element, in the order of element_outputs()."""
        n = c_size_t()
        self._call("ws_world_copy_element_ids", None, 0, byref(n))
        buf = (L.ElementId * max(n.value, 1))()
        self._call("ws_world_copy_element_ids", buf, n.value, byref(n))
        return [Element(self, L.ElementId(buf[i].bits)) for i in range(n.value)]

    def element_outputs(self, out=None):
        """The output of every element now as a numpy structured array (ELEMENT_OUTPUT_DTYPE),
        one C call; `out` (an array of that dtype, as long as elements()) is reused if given."""
        n = c_size_t()
        self._call("ws_world_copy_element_outputs", None, 0, byref(n))
        if out is None:
            out = np.zeros(n.value, dtype=ELEMENT_OUTPUT_DTYPE)
        elif (out.dtype != ELEMENT_OUTPUT_DTYPE or out.shape != (n.value,)
              or not out.flags.c_contiguous or not out.flags.writeable):
            raise ValueError(f"out must be a writeable ELEMENT_OUTPUT_DTYPE array ({n.value},)")
        if n.value:
            self._call("ws_world_copy_element_outputs", _ptr(out, L.ElementOutput), len(out),
                       byref(n))
        return out

    def element_energy(self):
        """Elastic energy stored in all elements now, J."""
        e = c_double()
        self._call("ws_world_get_element_energy", byref(e))
        return e.value

    # output
    def write_vtp(self, path):
        """Write the bodies as one VTK PolyData file."""
        self._call("ws_world_write_vtp", str(path).encode())

    def vtk_series(self, directory, basename, **kwargs):
        """Start a time series for ParaView in `directory` (must exist): a .pvd over per-frame
        .vtm multiblocks with the blocks bodies, film, contacts (and springs). Keyword arguments
        are ws_vtk_series_def fields: format (WS_VTK_COMPRESSED, WS_VTK_BINARY, WS_VTK_ASCII or
        "compressed", "binary", "ascii"), frame_stride, time_stride (s), springs, contacts,
        containment_bands, double_precision. A context manager."""
        if isinstance(kwargs.get("format"), str):
            kwargs["format"] = {"compressed": L.WS_VTK_COMPRESSED, "binary": L.WS_VTK_BINARY,
                                "ascii": L.WS_VTK_ASCII}[kwargs["format"].lower()]
        d = _make(L.VtkSeriesDef, kwargs)
        directory, basename = str(directory).encode(), str(basename).encode()
        d.directory, d.basename = directory, basename
        p = L.Series_p()
        if kwargs:
            self._call("ws_vtk_series_create_def", byref(d), byref(p))
        else:
            self._call("ws_vtk_series_create", directory, basename, byref(p))
        s = VtkSeries(self, p)
        self._series.append(s)
        return s


# --- handles -------------------------------------------------------------------------------------
class _Handle:
    _valid_fn = None

    def __init__(self, world, id_):
        self.world = world
        self._id = id_

    @property
    def id(self):
        """The id's 64 bits."""
        return self._id.bits

    def _call(self, name, *args):
        return self.world._call(name, self._id, *args)

    @property
    def valid(self):
        """True while the id names a live object of its world."""
        if self.world.closed:
            return False
        return bool(getattr(_c(), self._valid_fn)(self.world.ptr, self._id))

    def __eq__(self, other):
        return type(other) is type(self) and other.world is self.world and other.id == self.id

    def __hash__(self):
        return hash((type(self), self.id))

    def __repr__(self):
        return f"<{type(self).__name__} 0x{self.id:016x}>"


class Material(_Handle):
    """A contact material."""
    _valid_fn = "ws_material_is_valid"

    def __init__(self, world, id_, name=None):
        super().__init__(world, id_)
        self.name = name


class Shape(_Handle):
    """A closed triangle mesh in its body frame."""
    _valid_fn = "ws_shape_is_valid"

    def info(self):
        """Volume (m^3), centroid, aabb_min/max (m), inertia_unit, feature counts, convex."""
        i = L.ShapeInfo()
        self._call("ws_shape_get_info", byref(i))
        return _struct_dict(i)

    @property
    def centroid_offset(self):
        """How far the mesh was moved when created (its volume centroid in the frame its
        vertices were given in), m: create the body at this position to put it where the mesh
        was."""
        v = L.Vec3()
        self._call("ws_shape_get_centroid_offset", byref(v))
        return np.array([v.x, v.y, v.z])

    def copy_mesh(self):
        """The re-centred vertices (n, 3) m and triangles (m, 3)."""
        nv, nt = c_size_t(), c_size_t()
        self._call("ws_shape_copy_mesh", None, 0, byref(nv), None, 0, byref(nt))
        v = np.empty((nv.value, 3))
        t = np.empty((nt.value, 3), dtype=np.uint32)
        self._call("ws_shape_copy_mesh", _ptr(v, c_double), nv.value, byref(nv),
                   _ptr(t, c_uint32), nt.value, byref(nt))
        return v, t

    def destroy(self):
        """Destroy the shape (WrapsimError WS_ERR_IN_USE while a body uses it)."""
        self._call("ws_shape_destroy")


class Law(_Handle):
    """A constitutive law: force (N) of strain and strain rate."""
    _valid_fn = "ws_law_is_valid"

    def evaluate(self, eps, eps_dot=0.0):
        """(F N, dF/deps N, dF/deps_dot N s) at strain eps and strain rate eps_dot (1/s)."""
        f, k, c = c_double(), c_double(), c_double()
        self._call("ws_law_evaluate", float(eps), float(eps_dot), byref(f), byref(k), byref(c))
        return f.value, k.value, c.value

    def energy(self, eps):
        """Elastic energy per unit rest length (J/m) at strain eps."""
        e = c_double()
        self._call("ws_law_energy", float(eps), byref(e))
        return e.value

    def info(self):
        """type, dim, flags (WS_LAW_FLAG_*), state_size, users, max_stiffness, max_damping."""
        i = L.LawInfo()
        self._call("ws_law_get_info", byref(i))
        return _struct_dict(i)

    @property
    def dim(self):
        """1, 3 or 6."""
        return self.info()["dim"]

    @property
    def state_size(self):
        """Doubles of history each user keeps (0: none)."""
        n = c_size_t()
        self._call("ws_law_get_state_size", byref(n))
        return n.value

    def init_state(self):
        """A new history: the initial state as a numpy array (empty for a law without one)."""
        st = np.zeros(self.state_size)
        self._call("ws_law_init_state", _ptr(st, c_double) if len(st) else None)
        return st

    def _vec(self, v, dim, what):
        a = np.ascontiguousarray(np.asarray(v, dtype=float).reshape(-1))
        if a.shape != (dim,):
            raise ValueError(f"{what}: expected {dim} numbers, got {v!r}")
        return a

    def _state(self, state, n):
        if state is None:
            return None
        if not (isinstance(state, np.ndarray) and state.dtype == np.float64 and
                state.flags.c_contiguous and state.shape == (n,)):
            raise ValueError(f"state: expected a float64 numpy array of {n} (from init_state())")
        return _ptr(state, c_double) if n else None

    def evaluate_state(self, u, ud=None, t=0.0, dt=0.0, state=None):
        """(F, dF/du, dF/dud) at strain u (dim values) and rate ud (1/s; None: zero), at time t
        (s), dt (s) after the committed `state` (None: the initial state), which is not
        changed. F has dim values (N), the derivatives are dim x dim arrays."""
        info = self.info()
        n = info["dim"]
        uu = self._vec(u, n, "u")
        uv = None if ud is None else self._vec(ud, n, "ud")
        F, K, C = np.empty(n), np.empty((n, n)), np.empty((n, n))
        self._call("ws_law_evaluate_state", self._state(state, info["state_size"]),
                   _ptr(uu, c_double), None if uv is None else _ptr(uv, c_double), float(t),
                   float(dt), _ptr(F, c_double), _ptr(K, c_double), _ptr(C, c_double))
        return F, K, C

    def commit(self, state, u, ud=None, t=0.0, dt=0.0):
        """Commit a step accepted at strain u and rate ud (None: zero) at time t, dt after the
        previous commit: `state` (from init_state()) is updated in place."""
        info = self.info()
        n = info["dim"]
        uu = self._vec(u, n, "u")
        uv = None if ud is None else self._vec(ud, n, "ud")
        self._call("ws_law_commit_state", self._state(state, info["state_size"]),
                   _ptr(uu, c_double), None if uv is None else _ptr(uv, c_double), float(t),
                   float(dt))

    def energy_state(self, u, state=None, t=0.0):
        """Elastic energy (J per unit of the strain's scale) at strain u from `state` (None:
        the initial one) at time t."""
        info = self.info()
        uu = self._vec(u, info["dim"], "u")
        e = c_double()
        self._call("ws_law_energy_state", self._state(state, info["state_size"]),
                   _ptr(uu, c_double), float(t), byref(e))
        return e.value

    def destroy(self):
        """Destroy the law (WrapsimError WS_ERR_IN_USE while a web, element or law uses it)."""
        self._call("ws_law_destroy")
        self.world._callbacks.pop(self.id, None)


def _vec_getter(fn, doc):
    def get(self):
        v = L.Vec3()
        self._call(fn, byref(v))
        return _np(v)
    return property(get, doc=doc)


class Body(_Handle):
    """A rigid body or a kinematic world element. Vectors are numpy arrays, global frame."""
    _valid_fn = "ws_body_is_valid"

    position = _vec_getter("ws_body_get_position", "CoG position, m.")
    velocity = _vec_getter("ws_body_get_velocity", "CoG velocity, m/s.")
    angular_velocity = _vec_getter("ws_body_get_angular_velocity",
                                   "Angular velocity, global frame, rad/s.")
    angular_velocity_local = _vec_getter("ws_body_get_angular_velocity_local",
                                         "Angular velocity, body frame, rad/s.")

    @property
    def orientation(self):
        """Euler parameters (e0, e1, e2, e3)."""
        q = L.Quat()
        self._call("ws_body_get_orientation", byref(q))
        return np.array([q.e0, q.e1, q.e2, q.e3])

    @property
    def rotation(self):
        """Rotation matrix A (body to global), 3x3."""
        m = L.Mat3()
        self._call("ws_body_get_rotation", byref(m))
        return np.array(m.m[:]).reshape(3, 3)

    @property
    def inertia(self):
        """Inertia about the CoG in the body frame, kg m^2, 3x3."""
        m = L.Mat3()
        self._call("ws_body_get_inertia", byref(m))
        return np.array(m.m[:]).reshape(3, 3)

    @property
    def mass(self):
        """kg (0 for kinematic bodies)."""
        m = c_double()
        self._call("ws_body_get_mass", byref(m))
        return m.value

    @property
    def type(self):
        """WS_BODY_DYNAMIC or WS_BODY_KINEMATIC."""
        t = c_int()
        self._call("ws_body_get_type", byref(t))
        return t.value

    def _check_live(self):
        if not self.valid:
            raise WrapsimError(WS_ERR_STALE_HANDLE, f"body id 0x{self.id:016x} is not live")

    @property
    def name(self):
        """The name given when created ("" if none)."""
        self._check_live()
        n = _c().ws_body_get_name(self.world.ptr, self._id)
        return n.decode() if n else ""

    @property
    def user_data(self):
        """The user_data pointer of the Def, as an int (or None)."""
        self._check_live()
        return _c().ws_body_get_user_data(self.world.ptr, self._id)

    def point_velocity(self, point):
        """Velocity (m/s) of the body point now at global `point` (m)."""
        v = L.Vec3()
        self._call("ws_body_get_point_velocity", byref(_vec3(point)), byref(v))
        return _np(v)

    def world_point(self, local):
        """Global position (m) of a point given in the body frame."""
        v = L.Vec3()
        self._call("ws_body_get_world_point", byref(_vec3(local)), byref(v))
        return _np(v)

    def contact_force(self):
        """(force N, moment N m about the CoG) of the last step's contacts, global."""
        f, m = L.Vec3(), L.Vec3()
        self._call("ws_body_get_contact_force", byref(f), byref(m))
        return _np(f), _np(m)

    def set_pose(self, position, orientation=(1.0, 0.0, 0.0, 0.0)):
        """Set the pose of a dynamic body between steps."""
        pose = L.Pose(_vec3(position), _quat(orientation))
        self._call("ws_body_set_pose", byref(pose))

    def set_velocity(self, velocity, angular_velocity=(0.0, 0.0, 0.0)):
        """Set the velocities (m/s, rad/s global) of a dynamic body between steps."""
        self._call("ws_body_set_velocity", byref(_vec3(velocity)), byref(_vec3(angular_velocity)))

    def set_drive(self, type="static", callback=None, table=None, psd_frequency=None,
                  psd_level=None, **kwargs):
        """Set the drive of a kinematic body: type 'static', 'tilt' (axis, point, rate rad/s,
        start_time s, ramp_time s, max_angle rad, stop_ramp_time s), 'sine' (direction,
        amplitude m, frequency Hz, phase rad, start_time, ramp_time), 'pulse' (EUMOS 40509:
        direction, acceleration m/s^2, rise_time, hold_time, pulse_mode 'accelerate' or 'brake',
        gentle_acceleration, coast_time), 'impact' (direction, speed m/s, pulse_duration s,
        gentle_acceleration, coast_time), 'table' (direction, table: accelerations m/s^2,
        table_interval s, table_end_at_rest), 'random' (direction, psd_frequency Hz, psd_level
        g^2/Hz, seed, duration s, sample_rate Hz, ramp_time: the taper), 'sweep' (direction,
        acceleration m/s^2, frequency Hz, frequency_end Hz, duration s, sweep_law 'log' or
        'linear', ramp_time) or 'callback' with `callback(t)` returning
        (position, orientation[, velocity[, angular_velocity]]) in the global frame. An exception
        in the callback fails the step with WS_ERR_CALLBACK and is chained to the WrapsimError.
        The library copies the table and the PSD."""
        keep = []
        if psd_frequency is not None or psd_level is not None:
            kwargs["type"] = type
            d, arrays = _psd_def(psd_frequency if psd_frequency is not None else [],
                                 psd_level if psd_level is not None else [], kwargs)
            keep.append(arrays)
            kwargs = {}
        else:
            d = None
        if table is not None:
            t = _doubles(table, "table")
            keep.append(t)
            if d is None:
                kwargs["type"] = type
                d = _make(L.DriveDef, kwargs)
                kwargs = {}
            d.table = _ptr(t, c_double)
            d.table_count = t.size
        if d is not None:
            self._set_drive_def(d, callback)
            return
        kwargs["type"] = type
        self._set_drive_def(_make(L.DriveDef, kwargs), callback)

    def _set_drive_def(self, d, callback):
        cfn = None
        if callback is not None:
            world = self.world

            def _drive(user, t, pose, vel, omega, _fn=callback):
                try:
                    r = _fn(t)
                    pose[0].position = _vec3(r[0])
                    pose[0].orientation = _quat(r[1])
                    vel[0] = _vec3(r[2]) if len(r) > 2 else L.Vec3()
                    omega[0] = _vec3(r[3]) if len(r) > 3 else L.Vec3()
                    return 0
                except Exception as e:  # noqa: BLE001 - reported through the step's error
                    world._pending = e
                    return 1
            cfn = L.DriveFn(_drive)
            d.callback = cfn
        elif d.type == WS_DRIVE_CALLBACK:
            raise ValueError("a 'callback' drive needs callback=")
        if cfn is not None:
            # Kept until the body or the world goes: the library calls it from now on (and may
            # have kept it even when the call below fails).
            self.world._callbacks.setdefault(self.id, []).append(cfn)
        self._call("ws_body_set_drive", byref(d))

    def drive_state(self):
        """What the body's drive delivers now, a dict: time s, type (int), position,
        displacement (since the drive was set) m, velocity m/s, acceleration m/s^2 (of the
        CoG, global), angular_velocity rad/s, and for a tilt angle rad, angular_rate rad/s,
        angular_acceleration rad/s^2; has_acceleration is False for a callback drive."""
        st = L.DriveState()
        self._call("ws_body_get_drive_state", byref(st))
        d = _struct_dict(st)
        d["has_acceleration"] = bool(d["has_acceleration"])
        return d

    def destroy(self):
        """Destroy the body; its contacts go with it."""
        self._call("ws_body_destroy")
        self.world._callbacks.pop(self.id, None)


class Element(_Handle):
    """A deformable element (rod, linear spring, angular spring, bushing). Read-outs are at the
    world's current state: the loads the next step applies."""
    _valid_fn = "ws_element_is_valid"

    def output(self):
        """dict: type, dim, strain, strain_rate, law_force (numpy arrays of dim), force (on body
        1, N), moment (on body 1 about point1, N m), moment2 (on body 2 about point2), point1,
        point2 (m), frame (law frame, e0..e3), energy (J); vectors global."""
        o = L.ElementOutput()
        self._call("ws_element_get_output", byref(o))
        d = _struct_dict(o)
        dim = d["dim"]
        for k in ("strain", "strain_rate", "law_force"):
            d[k] = np.array(d[k][:dim])
        return d

    @property
    def strain(self):
        """The strain fed to the law (dim values): eps, m, rad."""
        return self.output()["strain"]

    @property
    def force(self):
        """Force on body 1, N, global (body 2 gets the opposite)."""
        return self.output()["force"]

    @property
    def name(self):
        return _c().ws_element_get_name(self.world.ptr, self._id).decode()

    @property
    def user_data(self):
        """The user_data pointer of the Def, as an int (or None)."""
        return _c().ws_element_get_user_data(self.world.ptr, self._id)

    def destroy(self):
        """Destroy the element (its bodies and law stay)."""
        self._call("ws_element_destroy")


class Web(_Handle):
    """A film: nodes joined by springs. Bulk read-outs fill numpy arrays in one C call each;
    pass `out` (preallocated, right shape and dtype, C-contiguous) to reuse a buffer."""
    _valid_fn = "ws_web_is_valid"

    def __init__(self, world, id_):
        super().__init__(world, id_)
        i = self.info()
        self.node_count = i["node_count"]
        self.spring_count = i["spring_count"]

    def info(self):
        """node_count, spring_count, nx, ny, closed, substeps, mass kg, min_node_mass kg."""
        i = L.WebInfo()
        self._call("ws_web_get_info", byref(i))
        return _struct_dict(i)

    @property
    def stable_dt(self):
        """Largest stable sub-step, s."""
        t = c_double()
        self._call("ws_web_get_stable_dt", byref(t))
        return t.value

    def solver_stats(self):
        """The implicit film's solves: solves, iterations (CG, all of them), last_iterations,
        last_residual (over its scale); zeros for an explicit web."""
        st = L.WebSolverStats()
        self._call("ws_web_get_solver_stats", byref(st))
        return _struct_dict(st)

    @property
    def substeps(self):
        return self.info()["substeps"]

    @substeps.setter
    def substeps(self, n):
        self._call("ws_web_set_substeps", _int(n, c_int, "substeps"))

    def _bulk(self, fn, n, shape, dtype, ctype, out):
        if out is None:
            out = np.empty(shape, dtype=dtype)
        elif (out.shape != shape or out.dtype != dtype or not out.flags.c_contiguous
              or not out.flags.writeable):
            raise ValueError(f"out must be a writeable C-contiguous {dtype} array {shape}")
        count = c_size_t()
        self._call(fn, _ptr(out, ctype), n, byref(count))
        return out

    def positions(self, out=None):
        """Node positions (n, 3), m."""
        return self._bulk("ws_web_copy_positions", self.node_count, (self.node_count, 3),
                          np.float64, c_double, out)

    def velocities(self, out=None):
        """Node velocities (n, 3), m/s."""
        return self._bulk("ws_web_copy_velocities", self.node_count, (self.node_count, 3),
                          np.float64, c_double, out)

    def contact_forces(self, out=None):
        """Force of the bodies on each node in the last step (n, 3), N."""
        return self._bulk("ws_web_copy_contact_forces", self.node_count, (self.node_count, 3),
                          np.float64, c_double, out)

    def springs(self, out=None):
        """Spring end nodes (m, 2), uint32."""
        return self._bulk("ws_web_copy_springs", self.spring_count, (self.spring_count, 2),
                          np.uint32, c_uint32, out)

    def strains(self, out=None):
        """Spring strains l/l0 - 1 (m,)."""
        return self._bulk("ws_web_copy_spring_strains", self.spring_count,
                          (self.spring_count,), np.float64, c_double, out)

    def tensions(self, out=None):
        """Spring tensions (m,), N; negative in compression."""
        return self._bulk("ws_web_copy_spring_tensions", self.spring_count,
                          (self.spring_count,), np.float64, c_double, out)

    @property
    def rupture_strain(self):
        """Strain l/l0 - 1 past which a spring breaks for good (0: none)."""
        return self.rupture()["rupture_strain"]

    @rupture_strain.setter
    def rupture_strain(self, strain):
        self._call("ws_web_set_rupture_strain", _real(strain, "rupture_strain"))

    def rupture(self):
        """dict: rupture_strain, broken_count, broken_last_step (> 0: springs broke in the
        last step), ruptured, and the first break: first_spring (None before), first_time s,
        first_strain, first_position (3,) m."""
        r = L.WebRupture()
        self._call("ws_web_get_rupture", byref(r))
        d = _struct_dict(r)
        d["ruptured"] = bool(d["ruptured"])
        if not d["ruptured"]:
            d["first_spring"] = None
        return d

    def broken_springs(self):
        """Indices of the broken springs, ascending (uint32 array)."""
        count = c_size_t()
        self._call("ws_web_copy_broken_springs", None, 0, byref(count))
        out = np.zeros(count.value, dtype=np.uint32)
        if count.value:
            self._call("ws_web_copy_broken_springs", _ptr(out, c_uint32), len(out),
                       byref(count))
        return out

    def peak_strain(self):
        """The most strained intact spring now: dict of spring, strain, tension N, node_a,
        node_b, position_a, position_b (3,) m; None when no spring is intact."""
        p = L.WebPeak()
        self._call("ws_web_get_peak_strain", byref(p))
        if not p.found:
            return None
        return _struct_dict(p, skip=("found",))

    def body_force(self, body):
        """(force N, moment N m about the CoG) the web put on `body` in the last step."""
        f, m = L.Vec3(), L.Vec3()
        self._call("ws_web_get_body_force", _id_of(body, L.BodyId), byref(f), byref(m))
        return _np(f), _np(m)

    def containment(self, bands):
        """Containment profile in `bands` equal height bands: structured array
        (CONTAINMENT_DTYPE: z_low, z_high m, hoop_tension N, line_load N/m, contact_force N)."""
        n = _int(bands, c_size_t, "containment bands")
        rows = self.info()["ny"]
        if rows and not 1 <= n <= rows:
            raise ValueError(f"containment bands: expected 1..{rows} (the web's rows), got {n}")
        # A mesh web has no rows: the library refuses it, with room for one band meanwhile.
        out = np.zeros(n if rows else 1, dtype=CONTAINMENT_DTYPE)
        self._call("ws_web_get_containment", _ptr(out, L.ContainmentBand), len(out))
        return out

    def energy(self):
        """dict of kinetic, elastic and gravity energy of the web, J."""
        k, e, g = c_double(), c_double(), c_double()
        self._call("ws_web_get_energy", byref(k), byref(e), byref(g))
        return {"kinetic": k.value, "elastic": e.value, "gravity": g.value}

    def write_vtp(self, path):
        """Write the web as a VTK PolyData file."""
        self._call("ws_web_write_vtp", str(path).encode())

    def destroy(self):
        self._call("ws_web_destroy")


class VtkSeries:
    """A time series of .vtp frames with a .pvd collection. Context manager; closed with its
    world at the latest."""

    def __init__(self, world, ptr):
        self.world = world
        self._ptr = ptr

    def _check(self, s):
        if s != WS_OK:
            raise WrapsimError(s, _c().ws_world_last_error(self.world.ptr).decode())

    def write_frame(self):
        """Offer the world now as the next frame: written when the series' strides allow it."""
        if not self._ptr:
            raise WrapsimError(WS_ERR_STALE_HANDLE, "the VTK series was closed")
        self._check(_c().ws_vtk_series_write_frame(self._ptr))

    @property
    def frame_count(self):
        if not self._ptr:
            raise WrapsimError(WS_ERR_STALE_HANDLE, "the VTK series was closed")
        n = c_size_t()
        self._check(_c().ws_vtk_series_get_frame_count(self._ptr, byref(n)))
        return n.value

    def close(self):
        if self._ptr:
            _c().ws_vtk_series_destroy(self._ptr)
        self._ptr = None
        if self in self.world._series:
            self.world._series.remove(self)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
