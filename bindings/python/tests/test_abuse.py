"""The binding must refuse, with a Python exception naming the argument and the expected length
or range, every input that would make the C side read past an array or get a silently
truncated integer. Each test passes one kind of abuse; before the checks they read out of
bounds, reached C with another value than the caller gave, or (a count given by hand without its
arrays) were left to the library to refuse; 47 of the 49 failed then.

    WRAPSIM_LIBRARY=$PWD/build/lib/libwrapsim.so.0 PYTHONPATH=bindings/python \
        /usr/bin/python3 -m pytest -q bindings/python/tests/test_abuse.py
"""

import numpy as np
import pytest

import wrapsim as ws

CUBE_V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1), (1, 1, 1)]
CUBE_T = [(0, 2, 3), (0, 3, 1), (4, 5, 7), (4, 7, 6), (0, 1, 5), (0, 5, 4), (2, 6, 7), (2, 7, 3),
          (0, 4, 6), (0, 6, 2), (1, 3, 7), (1, 7, 5)]


@pytest.fixture
def world():
    with ws.World() as w:
        yield w


def unchanged(w, before):
    """Nothing reached the world: no body, law, web was made and the state is as it was."""
    assert w.state_hash() == before


# --- arrays whose length the C call takes from a count --------------------------------------------
@pytest.mark.parametrize("name,dim,given,expected", [
    ("stiffness_matrix", 3, 4, 9), ("stiffness_matrix", 6, 35, 36),
    ("damping_matrix", 3, 8, 9), ("cubic_stiffnesses", 6, 5, 6), ("stiffness_matrix", 1, 2, 1),
])
def test_law_matrices_must_have_dim_squared_values(world, name, dim, given, expected):
    law_type = "cubic_elastic" if name == "cubic_stiffnesses" else "linear_viscoelastic"
    with pytest.raises(ValueError, match=rf"{name}: expected {expected} values .*got {given}"):
        world.law(law_type, dim=dim, stiffness=1.0, damping=1.0, **{name: np.ones(given)})


def test_a_good_matrix_law_is_still_made(world):
    law = world.law("linear_elastic", dim=3, stiffness_matrix=np.eye(3) * 2.0)
    F, K, _ = law.evaluate_state([0.1, 0.0, 0.0])
    assert F[0] == pytest.approx(0.2) and K[0, 0] == 2.0


@pytest.mark.parametrize("xs,ys,kind", [
    ("table_strain", "table_force", "table"),
    ("prony_stiffness", "prony_time", "relaxation"),
    ("scale_times", "scale_factors", "scaled"),
])
def test_paired_arrays_must_have_the_same_length(world, xs, ys, kind):
    extra = {"base": world.law(stiffness=1.0)} if kind == "scaled" else {}
    with pytest.raises(ValueError, match=rf"{ys}: expected 3 values \(as many as {xs}\), got 5"):
        world.law(kind, stiffness=1.0, **{xs: [0.1, 0.2, 0.3], ys: [1.0, 2.0, 3.0, 4.0, 5.0]},
                  **extra)


@pytest.mark.parametrize("count,arrays", [
    ("table_count", {"table_strain": [0.0, 0.1], "table_force": [0.0, 1.0]}),
    ("prony_count", {"prony_stiffness": [1.0], "prony_time": [0.1]}),
    ("table_count", {}),
])
def test_a_count_given_by_hand_must_match_its_arrays(world, count, arrays):
    kind = "table" if count == "table_count" else "relaxation"
    with pytest.raises(ValueError, match=rf"{count}: 1000 does not match"):
        world.law(kind, stiffness=1.0, **{count: 1000}, **arrays)


def test_term_count_must_match_the_terms(world):
    a = world.law(stiffness=1.0)
    with pytest.raises(ValueError, match=r"term_count: 16 does not match the 1 terms"):
        world.law("sum", terms=[a], term_count=16)
    with pytest.raises(ValueError, match=r"term_count: given without terms"):
        world.law("sum", term_count=4)


def web_law(w):
    return w.law("tension_compression", stiffness=100.0, compression_stiffness=1.0)


SQUARE = [(0, 0, 0), (0.1, 0, 0), (0.1, 0.1, 0), (0, 0.1, 0)]
EDGES = [(0, 1), (1, 2), (2, 3), (3, 0)]


@pytest.mark.parametrize("name,value,message", [
    ("node_masses", [1e-3] * 3, r"node_masses: expected 4 values \(one per node\), got 3"),
    ("rest_lengths", [0.1] * 2, r"rest_lengths: expected 4 values \(one per spring\), got 2"),
    ("kinds", [0] * 5, r"kinds: expected 4 values \(one per spring\), got 5"),
    ("kinds", [0, 1, 2, 7], r"kinds: index 7 is outside 0..2"),
    ("kinds", [0, 1, 2, 256], r"kinds: index 256 is outside 0..2"),
    ("pinned", [4], r"pinned: index 4 is outside 0..3"),
    ("pinned", [-1], r"pinned: index -1 is outside 0..3"),
])
def test_web_mesh_arrays_match_nodes_and_springs(world, name, value, message):
    law = web_law(world)
    before = world.state_hash()
    with pytest.raises(ValueError, match=message):
        world.web_mesh(law, SQUARE, EDGES, node_mass=1e-3, **{name: value})
    unchanged(world, before)


@pytest.mark.parametrize("springs,error,message", [
    ([(0, 1), (1, 4)], ValueError, r"springs: index 4 is outside 0..3"),
    ([(0, 1), (-1, 2)], ValueError, r"springs: index -1 is outside 0..3"),
    ([(0, 1), (1, 2 ** 32 + 2)], ValueError, r"springs: index 4294967298 is outside 0..3"),
    ([(0, 1), (1, 2 ** 70)], OverflowError, r"springs: 1180591620717411303424 is outside"),
    ([(0.0, 1.0), (1.5, 2.0)], TypeError, r"springs: expected integers, got float64"),
    ([0, 1, 2], ValueError, r"springs: expected rows of 2 values, got 3 values"),
])
def test_web_mesh_springs_are_integral_node_indices(world, springs, error, message):
    law = web_law(world)
    with pytest.raises(error, match=message):
        world.web_mesh(law, SQUARE, springs, node_mass=1e-3)


def test_a_good_web_mesh_is_still_made(world):
    web = world.web_mesh(web_law(world), SQUARE, np.array(EDGES, dtype=np.int64),
                         node_mass=1e-3, kinds=np.array([0, 1, 0, 1], dtype=np.int32),
                         pinned=[0])
    assert web.node_count == 4 and web.spring_count == 4
    assert (web.springs() == np.array(EDGES)).all()


@pytest.mark.parametrize("triangles,error,message", [
    (np.array(CUBE_T, dtype=float) + 0.25, TypeError, r"triangles: expected integers"),
    ([(0, 2, 3)] + CUBE_T[1:-1] + [(1, 7, 8)], ValueError, r"triangles: index 8 is outside 0..7"),
    ([(0, 2, 3)] + CUBE_T[1:-1] + [(1, 7, 2 ** 32 + 5)], ValueError,
     r"triangles: index 4294967301 is outside 0..7"),
    (np.ravel(CUBE_T)[:-1], ValueError, r"triangles: expected rows of 3 values, got 35"),
    (CUBE_T[:-1] + [(1, 7)], ValueError, r"mesh triangles: setting an array element"),
])
def test_mesh_triangles_are_integral_vertex_indices(world, triangles, error, message):
    with pytest.raises(error, match=message):
        world.mesh(CUBE_V, triangles)


def test_mesh_vertices_come_in_threes(world):
    with pytest.raises(ValueError, match=r"vertices: expected rows of 3 values, got 23"):
        world.mesh(np.ravel(CUBE_V)[:-1], CUBE_T)
    assert world.mesh(CUBE_V, np.array(CUBE_T, dtype=np.uint8)).info()["volume"] == 1.0


@pytest.mark.parametrize("pinned,error,message", [
    ([0, 12], ValueError, r"pinned: index 12 is outside 0..11"),
    ([-1], ValueError, r"pinned: index -1 is outside 0..11"),
    ([0.0, 1.0], TypeError, r"pinned: expected integers, got float64"),
])
def test_sheet_pins_are_node_indices(world, pinned, error, message):
    with pytest.raises(error, match=message):
        world.web_sheet(web_law(world), pinned=pinned, nx=4, ny=3, spacing_x=0.1,
                        spacing_y=0.1, node_mass=1e-3)


def test_counts_that_the_binding_sets_cannot_be_given(world):
    law = web_law(world)
    with pytest.raises(TypeError, match=r"pinned_count is set from `pinned`"):
        world.web_sheet(law, pinned=[0], pinned_count=5, nx=4, ny=3, spacing_x=0.1,
                        spacing_y=0.1, node_mass=1e-3)
    box = world.body(world.box(1, 1, 1))
    with pytest.raises(TypeError, match=r"body_count is set from `bodies`"):
        world.web_band(law, [box], body_count=4, z_bottom=0, z_top=0.5, n_around=8, n_up=2,
                       node_mass=1e-3)


# --- integers that ctypes would truncate ----------------------------------------------------------
def test_step_count_is_a_64_bit_integer(world):
    with pytest.raises(OverflowError, match=r"step count: 1180591620717411303424 is outside "
                                            r"-9223372036854775808..9223372036854775807"):
        world.step(2 ** 70)
    with pytest.raises(TypeError, match=r"step count: expected an integer, got 2.5"):
        world.step(2.5)
    assert world.time == 0.0
    world.step(np.int64(3))
    assert world.time == pytest.approx(3 * world.dt)


def test_cylinder_segments_are_a_c_int(world):
    with pytest.raises(OverflowError, match=r"segments: 4294967304 is outside "
                                            r"-2147483648..2147483647"):
        world.cylinder(0.1, 0.2, segments=2 ** 32 + 8)
    with pytest.raises(TypeError, match=r"segments: expected an integer, got 8.7"):
        world.cylinder(0.1, 0.2, segments=8.7)
    assert world.cylinder(0.1, 0.2, segments=np.int32(8)).info()["point_count"] == 16


@pytest.mark.parametrize("call,error,message", [
    (lambda w: w.web_sheet(web_law(w), nx=2 ** 32 + 8, ny=3, spacing_x=0.1, spacing_y=0.1,
                           node_mass=1e-3), OverflowError, r"SheetDef.nx: 4294967304 is outside"),
    (lambda w: w.web_sheet(web_law(w), nx=4.0, ny=3, spacing_x=0.1, spacing_y=0.1,
                           node_mass=1e-3), TypeError, r"SheetDef.nx: expected an integer"),
    (lambda w: w.law(dim=2 ** 32 + 1, stiffness=1.0), OverflowError, r"law dim: 4294967297"),
    (lambda w: w.body(w.box(1, 1, 1), type=2 ** 32 + 1), OverflowError,
     r"BodyDef.type: 4294967297 is outside"),
    (lambda w: w.law("user", user_fn=lambda u, ud, t: u, user_flags=-1), OverflowError,
     r"LawDef.user_flags: -1 is outside 0..4294967295"),
    (lambda w: w.element("rod", None, w.body(w.box(1, 1, 1)), w.law(stiffness=1.0),
                         global_attachment=2 ** 40), OverflowError,
     r"ElementDef.global_attachment: 1099511627776 is outside"),
])
def test_def_fields_are_checked_against_their_c_type(world, call, error, message):
    with pytest.raises(error, match=message):
        call(world)


def test_world_def_fields_are_checked_against_their_c_type():
    with pytest.raises(OverflowError, match=r"WorldDef.detection_interval: 1099511627777"):
        ws.World(detection_interval=2 ** 40 + 1)
    with pytest.raises(TypeError, match=r"WorldDef.use_ccd: expected an integer, got 0.5"):
        ws.World(use_ccd=0.5)


def test_ids_are_64_bit_unsigned(world):
    with pytest.raises(OverflowError, match=r"body id: -1 is outside 0..18446744073709551615"):
        world.body_by_id(-1)
    with pytest.raises(OverflowError, match=r"MaterialId: 18446744073709551616 is outside"):
        world.set_contact(2 ** 64, world.default_material, stiffness=1e5)


def test_substeps_and_containment_bands_are_checked(world):
    box = world.body(world.box(0.5, 0.5, 0.5), type="kinematic")
    web = world.web_band(web_law(world), [box], z_bottom=-0.2, z_top=0.2, n_around=12, n_up=4,
                         node_mass=1e-3)
    with pytest.raises(OverflowError, match=r"substeps: 4294967297 is outside"):
        web.substeps = 2 ** 32 + 1
    assert web.substeps == 1
    with pytest.raises(OverflowError, match=r"containment bands: -1 is outside 0.."):
        web.containment(-1)
    with pytest.raises(ValueError, match=r"containment bands: expected 1..4 \(the web's rows\), "
                                         r"got 5"):
        web.containment(5)
    with pytest.raises(TypeError, match=r"containment bands: expected an integer"):
        web.containment(2.0)
    assert len(web.containment(np.uint8(2))) == 2


def test_status_codes_are_a_c_int():
    assert ws.status_string(ws.WS_ERR_IO).startswith("WS_ERR_IO")
    with pytest.raises(OverflowError, match=r"status: 4294967306 is outside"):
        ws.status_string(2 ** 32 + ws.WS_ERR_IO)


# --- the film's rupture, stiffness scales and a wrapped load's bands -------------------------------
@pytest.mark.parametrize("value,error", [
    ("abc", ValueError), (None, TypeError), ([0.5], TypeError), (1j, TypeError),
    (2 ** 1100, OverflowError),
])
def test_rupture_strain_is_a_real_number(world, value, error):
    web = world.web_mesh(web_law(world), SQUARE, EDGES, node_mass=1e-3)
    before = world.state_hash()
    with pytest.raises(error, match=r"^rupture_strain: expected a real number"):
        web.rupture_strain = value
    with pytest.raises(error, match=r"^WebDef.rupture_strain: expected a real number"):
        world.web_mesh(web_law(world), SQUARE, EDGES, node_mass=1e-3, rupture_strain=value)
    assert web.rupture_strain == 0.0
    unchanged(world, before)


@pytest.mark.parametrize("value", [-1.0, float("nan"), float("inf"), -1e-300])
def test_rupture_strain_out_of_range_is_refused_by_the_library(world, value):
    web = world.web_mesh(web_law(world), SQUARE, EDGES, node_mass=1e-3, rupture_strain=0.2)
    before = world.state_hash()
    with pytest.raises(ws.WrapsimError, match=r"ws_web_set_rupture_strain: .*finite and >= 0"):
        web.rupture_strain = value
    with pytest.raises(ws.WrapsimError, match=r"rupture_strain must be finite and >= 0"):
        world.web_mesh(web_law(world), SQUARE, EDGES, node_mass=1e-3, rupture_strain=value)
    assert web.rupture_strain == 0.2
    unchanged(world, before)


def test_rupture_read_outs_of_a_destroyed_web_are_refused(world):
    web = world.web_mesh(web_law(world), SQUARE, EDGES, node_mass=1e-3, rupture_strain=0.2)
    web.destroy()
    for call in (web.rupture, web.broken_springs, web.peak_strain):
        with pytest.raises(ws.WrapsimError, match=r"WS_ERR_STALE_HANDLE"):
            call()
    with pytest.raises(ws.WrapsimError, match=r"WS_ERR_STALE_HANDLE"):
        web.rupture_strain = 0.1


@pytest.mark.parametrize("scales,error,message", [
    ([1.0] * 3, ValueError, r"stiffness_scales: expected 4 values \(one per spring\), got 3"),
    ([1.0] * 5, ValueError, r"stiffness_scales: expected 4 values \(one per spring\), got 5"),
    (2.0, ValueError, r"stiffness_scales: expected 4 values \(one per spring\), got 1"),
    (["a"] * 4, ValueError, r"stiffness_scales: could not convert string to float"),
    ([1.0, 1.0, [1.0, 2.0], 1.0], ValueError, r"stiffness_scales: "),
    ([1.0, 2.0, float("nan"), 1.0], ws.WrapsimError, r"spring 2 has stiffness scale nan"),
    ([1.0, 0.0, 1.0, 1.0], ws.WrapsimError, r"spring 1 has stiffness scale 0"),
    ([1.0, 1.0, 1.0, 1e7], ws.WrapsimError, r"spring 3 has stiffness scale 1e\+07: need a "
                                            r"finite value > 0 and <= 1e6"),
])
def test_stiffness_scales_are_one_real_per_spring(world, scales, error, message):
    before = world.state_hash()
    with pytest.raises(error, match=message):
        world.web_mesh(web_law(world), SQUARE, EDGES, node_mass=1e-3, stiffness_scales=scales)
    unchanged(world, before)


def test_containment_bands_of_a_load_are_checked():
    import ctypes
    from ctypes import byref

    from wrapsim import _lib as L
    from wrapsim import eumos
    lib = ws._c()
    with ws.World(detection_interval=10) as w:
        ld = L.LoadDef()
        lib.ws_load_def_init_sized(byref(ld), ctypes.sizeof(ld))
        ld.layers = 1
        load = ctypes.c_void_p()
        assert lib.ws_load_build(w.ptr, byref(ld), byref(load)) == 0, w.last_error
        try:
            for bands, error, message in [
                    (-1, OverflowError, r"containment bands: -1 is outside 0.."),
                    (2.0, TypeError, r"containment bands: expected an integer"),
                    (0, ValueError, r"containment bands: expected 1..64, got 0"),
                    (65, ValueError, r"containment bands: expected 1..64, got 65"),
                    (2 ** 70, OverflowError, r"containment bands: 1180591620717411303424")]:
                with pytest.raises(error, match=message):
                    eumos.containment_bands(w, load, bands)
            # In range but unwrapped: the library says so.
            with pytest.raises(ws.WrapsimError, match=r"the load is not wrapped"):
                eumos.containment_bands(w, load, np.uint8(3))
        finally:
            lib.ws_load_destroy(load)
