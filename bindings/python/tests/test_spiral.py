"""The spiral wrap of a machine through the binding's table: the Def's layout, the layers the
recipe lays, a wrapped load's containment by height band and its film's peak strain."""

import ctypes
from ctypes import byref

from wrapsim import World, _c
from wrapsim import _lib as L


def _init(struct, name):
    d = struct()
    getattr(_c(), name)(byref(d), ctypes.sizeof(d))
    return d


def test_spiral_wrap_through_the_table():
    lib = _c()
    sd = _init(L.SpiralWrapDef, "ws_spiral_wrap_def_init_sized")
    # The library's defaults land in the binding's fields: the layout agrees.
    assert sd.size == ctypes.sizeof(sd)
    assert (sd.width, sd.prestretch, sd.passes, sd.substeps) == (0.5, 2.0, 2, 0)
    # The default recipe on the default load: 4 layers in the middle (two passes of two).
    n = ctypes.c_int()
    assert lib.ws_spiral_wrap_layers(byref(sd), 1.154, 0.146, 4.0, 1.3, 0.6, byref(n)) == 0
    assert n.value == 4
    with World(detection_interval=10) as w:
        ld = _init(L.LoadDef, "ws_load_def_init_sized")
        ld.layers = 1
        load = ctypes.c_void_p()
        assert lib.ws_load_build(w.ptr, byref(ld), byref(load)) == 0, w.last_error
        try:
            sd.node_mass_min = 1e-3
            web = L.WebId()
            assert lib.ws_load_wrap_spiral(w.ptr, load, byref(sd), byref(web)) == 0, \
                w.last_error
            assert lib.ws_world_step_n(w.ptr, 200) == 0, w.last_error
            bands = (L.LoadContainment * 3)()
            assert lib.ws_load_get_containment(w.ptr, load, bands, 3) == 0, w.last_error
            for b in bands:
                assert b.force > 0 and b.hoop_tension > 0 and b.rows > 0
                assert abs(b.line_load - b.force / (b.z_high - b.z_low)) < 1e-9
            peak, spring, height = ctypes.c_double(), ctypes.c_uint32(), ctypes.c_double()
            assert lib.ws_load_get_film_peak(w.ptr, load, byref(peak), byref(spring),
                                             byref(height)) == 0
            assert 0.05 < peak.value < 0.3
            assert 0.0 < height.value < 0.5
        finally:
            lib.ws_load_destroy(load)
