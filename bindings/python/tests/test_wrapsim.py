"""Tests of the Python binding. Run from the repository:

    WRAPSIM_LIBRARY=$PWD/build/lib/libwrapsim.so.0 PYTHONPATH=bindings/python \
        /usr/bin/python3 -m pytest -q bindings/python/tests

Every function of the table is called at least once over the module (checked by the last test);
the tilt-table comparison compiles examples/tilt_table.c with the system C compiler (skipped
without one).
"""

import ctypes
import importlib.util
import math
import os
import pathlib
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

import wrapsim as ws
from wrapsim import _lib as L

REPO = pathlib.Path(__file__).resolve().parents[3]
HEADERS = sorted((REPO / "include" / "wrapsim").glob("*.h"))
LIB = L.lib()
LIB_PATH = LIB._wrapsim_path.split(" (")[0]

# --- count the calls of every function of the table -----------------------------------------------
CALLED = {name: 0 for name, _, _ in L.FUNCTIONS}


def _counting(name, fn):
    def call(*args):
        CALLED[name] += 1
        return fn(*args)
    call.argtypes, call.restype = fn.argtypes, fn.restype
    return call


for _name, _, _ in L.FUNCTIONS:
    setattr(LIB, _name, _counting(_name, getattr(LIB, _name)))

TESTS_RUN = set()


@pytest.fixture(autouse=True)
def _note_test(request):
    yield
    TESTS_RUN.add(request.node.name)


def header_functions():
    names = set()
    for h in HEADERS:
        text = h.read_text()
        text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
        for m in re.finditer(r"\bWS_API\b([^;{]*?)\b(ws_[a-z0-9_]+)\s*\(", text):
            names.add(m.group(2))
    return names


def c_compiler():
    for cc in (os.environ.get("CC"), "cc", "gcc", "clang"):
        if cc and shutil.which(cc):
            return cc
    return None


def include_dirs():
    """The public headers and the generated version.h next to the library in use."""
    dirs = [REPO / "include"]
    libdir = pathlib.Path(LIB_PATH).resolve().parent
    for cand in (libdir.parent / "include", REPO / "build" / "include"):
        if (cand / "wrapsim" / "version.h").exists():
            dirs.append(cand)
            return dirs
    return None


def compile_c(tmp_path, source, name="prog"):
    cc = c_compiler()
    incs = include_dirs()
    if cc is None or incs is None or not os.path.exists(LIB_PATH):
        pytest.skip("no C compiler, generated headers or library file")
    src = tmp_path / f"{name}.c"
    src.write_text(source)
    exe = tmp_path / name
    libdir = str(pathlib.Path(LIB_PATH).resolve().parent)
    cmd = [cc, "-std=c11", "-O1", "-o", str(exe), str(src)] + \
          [f"-I{d}" for d in incs] + [f"-I{REPO / 'examples'}", LIB_PATH, "-lm",
                                      f"-Wl,-rpath,{libdir}"]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    return exe


def run_c(exe, *args):
    env = dict(os.environ, LD_LIBRARY_PATH=str(pathlib.Path(LIB_PATH).resolve().parent))
    r = subprocess.run([str(exe), *map(str, args)], check=True, capture_output=True, text=True,
                       env=env)
    return r.stdout


# --- the table -----------------------------------------------------------------------------------
def test_table_covers_every_header_function():
    in_headers = header_functions()
    in_table = {name for name, _, _ in L.FUNCTIONS}
    assert len(in_headers) > 80
    assert in_headers - in_table == set(), "not wrapped"
    assert in_table - in_headers == set(), "not in the headers"
    assert len(in_table) == len(L.FUNCTIONS), "a function twice in the table"


STRUCTS = {
    "ws_vec3": L.Vec3, "ws_quat": L.Quat, "ws_mat3": L.Mat3, "ws_pose": L.Pose,
    "ws_body_id": L.BodyId, "ws_shape_id": L.ShapeId, "ws_material_id": L.MaterialId,
    "ws_law_id": L.LawId, "ws_web_id": L.WebId, "ws_allocator": L.Allocator,
    "ws_world_def": L.WorldDef, "ws_contact_def": L.ContactDef,
    "ws_material_def": L.MaterialDef, "ws_world_stats": L.WorldStats, "ws_energy": L.Energy,
    "ws_mesh_def": L.MeshDef, "ws_shape_info": L.ShapeInfo, "ws_body_def": L.BodyDef,
    "ws_drive_def": L.DriveDef, "ws_contact_info": L.ContactInfo, "ws_law_def": L.LawDef,
    "ws_web_def": L.WebDef, "ws_sheet_def": L.SheetDef, "ws_band_def": L.BandDef,
    "ws_web_mesh_def": L.WebMeshDef, "ws_web_info": L.WebInfo, "ws_law_info": L.LawInfo,
    "ws_containment_band": L.ContainmentBand,
    "ws_web_rupture": L.WebRupture, "ws_web_peak": L.WebPeak,
    "ws_element_id": L.ElementId, "ws_element_def": L.ElementDef,
    "ws_element_output": L.ElementOutput, "ws_vtk_series_def": L.VtkSeriesDef,
    "ws_load_interface": L.LoadInterface, "ws_load_def": L.LoadDef, "ws_load_info": L.LoadInfo,
    "ws_load_carton": L.LoadCarton, "ws_load_carton_state": L.LoadCartonState,
    "ws_wrap_def": L.WrapDef, "ws_loadtest_interface_state": L.LoadtestInterfaceState,
    "ws_loadtest_sample": L.LoadtestSample, "ws_eumos_def": L.EumosDef,
    "ws_loadtest_event": L.LoadtestEvent, "ws_loadtest_criterion": L.LoadtestCriterion,
    "ws_eumos_verdict": L.EumosVerdict, "ws_eumos_result": L.EumosResult,
    "ws_kvalue_def": L.KvalueDef, "ws_kvalue_result": L.KvalueResult,
}


def test_struct_layouts_match_c(tmp_path):
    """sizeof and offsetof of every field of every struct, from the C compiler."""
    lines = ["#include <stddef.h>", "#include <stdio.h>", "#include <wrapsim/wrapsim.h>",
             "int main(void) {"]
    expect = []
    for cname, st in STRUCTS.items():
        lines.append(f'printf("{cname} %zu\\n", sizeof({cname}));')
        expect.append(f"{cname} {ctypes.sizeof(st)}")
        for fname, _ in st._fields_:
            lines.append(f'printf("{cname}.{fname} %zu\\n", offsetof({cname}, {fname}));')
            expect.append(f"{cname}.{fname} {getattr(st, fname).offset}")
    lines += ["return 0;", "}"]
    exe = compile_c(tmp_path, "\n".join(lines), "layout")
    assert run_c(exe).split("\n")[:-1] == expect


def test_struct_fields_match_headers():
    """Every field named in a header's struct is in the ctypes mirror, in the same order."""
    text = "\n".join(re.sub(r"/\*.*?\*/", "", h.read_text(), flags=re.S) for h in HEADERS)
    for cname, st in STRUCTS.items():
        m = re.search(r"typedef struct " + cname + r"\s*\{(.*?)\}\s*" + cname + ";", text, re.S)
        assert m, cname
        names = []
        for decl in m.group(1).split(";"):
            decl = decl.strip()
            if not decl:
                continue
            fp = re.search(r"\(\s*\*\s*(\w+)\s*\)", decl)
            if fp:
                names.append(fp.group(1))
                continue
            decl = re.sub(r"\[[^\]]*\]", "", decl)
            parts = [p.strip() for p in decl.split(",")]
            names.append(re.findall(r"\w+", parts[0])[-1])
            names += [re.findall(r"\w+", p)[-1] for p in parts[1:]]
        assert names == [f for f, _ in st._fields_], cname


# --- loader --------------------------------------------------------------------------------------
def test_version_and_features():
    assert ws.version_number() >= L.REQUIRED_VERSION
    assert ws.version().count(".") == 2
    assert ws.build_features() & ~(ws.WS_FEATURE_CCD | ws.WS_FEATURE_ZLIB) == 0
    assert ws.status_string(ws.WS_ERR_STALE_HANDLE).startswith("WS_ERR_STALE_HANDLE")


def test_loader_honours_env(monkeypatch, tmp_path):
    monkeypatch.setenv("WRAPSIM_LIBRARY", str(tmp_path / "no-such-libwrapsim.so"))
    with pytest.raises(ws.LibraryError, match="WRAPSIM_LIBRARY"):
        L.load()
    monkeypatch.setenv("WRAPSIM_LIBRARY", LIB_PATH)
    assert L.load().ws_version_number() == ws.version_number()


def test_loader_refuses_older_library(monkeypatch):
    monkeypatch.setattr(L, "REQUIRED_VERSION", ws.version_number() + 1)
    with pytest.raises(ws.LibraryError, match="or newer"):
        L.load(LIB_PATH)


# --- errors --------------------------------------------------------------------------------------
def test_world_create_error():
    with pytest.raises(ws.WrapsimError) as e:
        ws.World(dt=-1.0)
    assert e.value.status == ws.WS_ERR_INVALID_ARGUMENT


def test_errors_carry_last_error_text():
    with ws.World() as w:
        cube = w.box(0.1, 0.1, 0.1)
        with pytest.raises(ws.WrapsimError) as e:
            w.body(cube, mass=-1.0, name="top")
        assert e.value.status == ws.WS_ERR_INVALID_ARGUMENT
        assert e.value.detail and e.value.detail == w.last_error
        assert "mass" in str(e.value)
        with pytest.raises(ws.WrapsimError) as e:
            w.box(0.1, -1, 0.1)
        assert e.value.status == ws.WS_ERR_INVALID_ARGUMENT
        # an open mesh: three faces of a tetrahedron
        v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
        with pytest.raises(ws.WrapsimError) as e:
            w.mesh(v, [[0, 2, 1], [0, 1, 3], [0, 3, 2]])
        assert e.value.status == ws.WS_ERR_BAD_MESH and e.value.detail
        b = w.body(cube, mass=1.0)
        with pytest.raises(ws.WrapsimError) as e:
            cube.destroy()
        assert e.value.status == ws.WS_ERR_IN_USE
        with pytest.raises(ws.WrapsimError):
            b.set_drive("tilt", rate=0.1)  # a dynamic body has no drive
        with pytest.raises(TypeError):
            w.body(cube, no_such_field=1)
        with pytest.raises(ValueError):
            w.body(cube, type="floating")


def test_buffer_too_small_raw():
    with ws.World() as w:
        ground = w.box(1, 1, 0.1)
        w.body(ground, type="kinematic", position=(0, 0, -0.05))
        w.body(w.box(0.1, 0.1, 0.1), mass=1.0, position=(0, 0, 0.052))
        w.step(10)
        assert w.contact_count() == 4
        buf = (L.ContactInfo * 1)()
        n = ctypes.c_size_t()
        assert LIB.ws_world_copy_contacts(w.ptr, buf, 1, ctypes.byref(n)) == \
            ws.WS_ERR_BUFFER_TOO_SMALL
        assert n.value == 4


def test_contacts_between_and_interface_stiffness():
    """Two equal 5 kg cubes on a plane, k = 2e5 N/m per point: box-plane 4 points (4k, load
    2 m g), box-box 8 points, two twins at each corner sharing its spring (4k, load m g); in
    the pair's order every normal points from a to
    b (+z from the plane to the bottom box and from it to the top one), whoever owns the face.
    Settled 2 s at 100 kg/s per point: the loads are static to far below the 1e-6 asserted."""
    mg, k, a = 5.0 * 9.81, 2e5, 0.25
    with ws.World() as w:
        w.set_default_contact(stiffness=k, damping=100.0)
        plane = w.body(w.box(1.5, 1.5, 0.05), type="kinematic", position=(0, 0, -0.025))
        cube = w.box(a, a, a)
        bottom = w.body(cube, mass=5.0, position=(0, 0, a / 2 + 0.002))
        top = w.body(cube, mass=5.0, position=(0, 0, 1.5 * a + 0.004))
        w.step(8000)
        assert w.interface_stiffness(plane, bottom) == pytest.approx((4 * k, 4))
        assert w.interface_stiffness(top, bottom) == pytest.approx((4 * k, 8))
        c = w.contacts_between(bottom, top)
        assert len(c) == 8
        assert np.all(c["normal"][:, 2] > 1 - 1e-12)
        assert sorted(c["kind"]) == [ws.WS_CONTACT_POINT_FACE] * 4 + [ws.WS_CONTACT_FACE_POINT] * 4
        assert c["normal_force"].sum() == pytest.approx(mg, rel=1e-6)
        c = w.contacts_between(bottom, plane)
        assert len(c) == 4 and np.all(c["normal"][:, 2] < -1 + 1e-12)
        assert c["normal_force"].sum() == pytest.approx(2 * mg, rel=1e-6)
        with pytest.raises(ws.WrapsimError) as e:
            w.contacts_between(top, top)
        assert e.value.status == ws.WS_ERR_INVALID_ARGUMENT


def test_friction_step_choice():
    """A 5 kg cube on a plane, gravity tilted to tan(theta) = 0.15 < mu = 0.3, at dt = 1.5 ms:
    eq. 13 holds it at the creep speed v_lim (1 - sqrt(1 - tan(theta) / mu)) = 2.929 mm/s
    (docs/theory.md section 5), a fixed point of the friction taken at the end of the step at
    any dt: to 1e-4 after 0.45 s (the start's bounce long gone). Taken explicitly
    (friction_step = WS_FRICTION_STEP_EXPLICIT), past its limit at this dt, it creeps faster
    by more than 5 % (3.44 mm/s)."""
    th, a = np.arctan(0.15), 0.25
    law = 0.01 * (1 - np.sqrt(1 - 0.15 / 0.3))
    speeds = []
    for step in (ws.WS_FRICTION_STEP_IMPLICIT, ws.WS_FRICTION_STEP_EXPLICIT):
        with ws.World(dt=1.5e-3, friction_step=step,
                      gravity=(9.81 * np.sin(th), 0, -9.81 * np.cos(th))) as w:
            w.set_default_contact(stiffness=2e5, damping=100.0, friction=0.3)
            w.body(w.box(2.0, 2.0, 0.05), type="kinematic", position=(0, 0, -0.025))
            cube = w.body(w.box(a, a, a), mass=5.0,
                          position=(0, 0, a / 2 + 0.002 - 5.0 * 9.81 * np.cos(th) / 8e5))
            w.step(300)
            speeds.append(cube.velocity[0])
    assert speeds[0] == pytest.approx(law, rel=1e-4)
    assert speeds[1] > 1.05 * law


def test_mesh_centroid_offset_places_body_where_the_mesh_was():
    """A tetrahedron given at (1, 2, 3): moved by its centroid, (1, 2, 3) + a/4 (1, 1, 1); a
    body created there puts the vertices back where they were given (1e-12 m, round-off)."""
    a = 0.5
    v = np.array([[0, 0, 0], [a, 0, 0], [0, a, 0], [0, 0, a]], dtype=float) + (1.0, 2.0, 3.0)
    with ws.World() as w:
        s = w.mesh(v, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
        off = s.centroid_offset
        assert off == pytest.approx(np.array([1, 2, 3]) + a / 4, abs=1e-12)
        b = w.body(s, mass=1.0, position=off)
        local, _ = s.copy_mesh()
        assert local @ b.rotation.T + b.position == pytest.approx(v, abs=1e-12)


def test_stale_ids_raise_never_crash():
    with ws.World() as w, ws.World() as other:
        cube = w.box(0.1, 0.1, 0.1)
        b = w.body(cube, mass=1.0, name="gone")
        assert b.valid and b.name == "gone"
        b.destroy()
        assert not b.valid
        for get in (lambda: b.position, lambda: b.velocity, lambda: b.orientation,
                    lambda: b.name, lambda: b.user_data, lambda: b.mass, b.destroy,
                    lambda: b.set_velocity((1, 0, 0))):
            with pytest.raises(ws.WrapsimError) as e:
                get()
            assert e.value.status == ws.WS_ERR_STALE_HANDLE
        with pytest.raises(ws.WrapsimError) as e:
            b.position
        assert "destroyed" in e.value.detail
        # an id of another world, a null id, a made-up id
        c = w.body(cube, mass=1.0)
        for bad in (other.body_by_id(c.id), w.body_by_id(0), w.body_by_id(0x1234567890abcdef)):
            with pytest.raises(ws.WrapsimError) as e:
                bad.position
            assert e.value.status == ws.WS_ERR_STALE_HANDLE
        law = w.law(stiffness=10.0)
        law.destroy()
        assert not law.valid
        with pytest.raises(ws.WrapsimError):
            law.evaluate(0.1)
        m = w.material("x")
        assert m.valid and not other.body_by_id(0).valid
    # the world itself closed: every handle raises
    with pytest.raises(ws.WrapsimError) as e:
        c.position
    assert e.value.status == ws.WS_ERR_STALE_HANDLE
    assert not c.valid and w.closed
    with pytest.raises(ws.WrapsimError):
        w.step()


# --- physics -------------------------------------------------------------------------------------
def test_box_rests_at_layer_gap():
    k, m, delta, g = 2e5, 5.0, 1e-3, 9.81
    with ws.World(gravity=(0, 0, -g)) as w:
        ground_mat, box_mat = w.material("ground"), w.material("box")
        w.set_contact(ground_mat, box_mat, stiffness=k, damping=50.0)
        slab = w.body(w.box(1.0, 1.0, 0.05), type="kinematic", material=ground_mat,
                      contact_layer=delta, position=(0, 0, -0.025))
        box = w.body(w.box(0.25, 0.25, 0.25), mass=m, material=box_mat, contact_layer=delta,
                     position=(0, 0, 0.125 + 2 * delta))
        rec = ws.run(w, 1.0, record={"z": lambda: box.position[2]}, every=0.1, progress=False)
        gap = rec["z"][-1] - 0.125
        assert gap == pytest.approx(2 * delta - m * g / (4 * k), abs=1e-7)
        assert rec["t"][-1] == pytest.approx(1.0)
        assert len(rec["t"]) == len(rec["z"]) == 11
        c = w.contacts()
        assert len(c) == 4
        assert np.allclose(c["normal_force"].sum(), m * g, rtol=1e-4)
        assert set(c["body_a"]) | set(c["body_b"]) == {slab.id, box.id}
        assert w.body_by_id(c["body_b"][0]) in (slab, box)
        f, _ = box.contact_force()
        assert f[2] == pytest.approx(m * g, rel=1e-4)
        assert w.energy()["kinetic"] < 1e-9
        assert w.stats()["contacts"] == 4
        # at rest: nothing slides, nothing at the friction cap, no anchor (regularised law)
        assert (c["slipping"] == 0).all() and (c["at_cap"] == 0).all()
        assert (c["anchor_deflection"] == 0).all()
        # the margin: dt over the pair's bound, 2 / sqrt(8 k / m) for a box on a slab
        assert w.stats()["body_step_use"] == pytest.approx(
            w.dt / w.estimate_stable_dt(), rel=1e-12)
        assert 0 < w.stats()["body_step_use"] < 1


def test_stick_contacts_report_their_anchors():
    # a box on a slab tilted by 10 deg of gravity, stick friction mu = 0.3: it holds, each
    # anchor spring carrying its share of m g sin(10 deg) (the deflection times stick_stiffness)
    k, m, g, th = 2e5, 5.0, 9.81, np.radians(10.0)
    with ws.World(gravity=(g * np.sin(th), 0, -g * np.cos(th))) as w:
        w.set_default_contact(stiffness=k, damping=50.0, friction=0.3, friction_model="stick")
        assert w.get_contact(w.default_material, w.default_material)["stick_damping_ratio"] == 1.0
        w.body(w.box(1.0, 1.0, 0.05), type="kinematic", position=(0, 0, -0.025))
        w.body(w.box(0.25, 0.25, 0.25), mass=m, position=(0, 0, 0.125 + 2e-3 - m * g / (4 * k)))
        w.step(4000)
        c = w.contacts()
        assert len(c) == 4 and (c["slipping"] == 0).all() and (c["at_cap"] == 0).all()
        pull = (c["anchor_deflection"][:, 0] * k).sum()  # on the box: -k d, d along +x
        assert abs(pull) == pytest.approx(m * g * np.sin(th), rel=1e-3)


def test_workers_give_the_same_state():
    # A falling 40 x 30 sheet (3 sweep blocks of 10 rows) stepped on 1, 2 and 3 workers: the lanes add every
    # force in the order one sweep does, so the state hash is the same to the bit.
    def run(workers):
        with ws.World(worker_count=workers) as w:
            law = w.law("linear_elastic", stiffness=200.0, name="film")
            w.web_sheet(law, nx=40, ny=30, spacing_x=0.01, spacing_y=0.01, prestretch_x=0.02,
                        prestretch_y=0.02, node_mass=1e-3, substeps=4, name="sheet")
            w.step(50)
            return w.state_hash()
    one = run(1)
    assert run(2) == one and run(3) == one
    with pytest.raises(Exception):
        ws.World(worker_count=0)


def test_sheet_tensions_are_ea_times_prestretch():
    ea, pre, nx, ny = 500.0, 0.1, 6, 5
    with ws.World(gravity=(0, 0, 0)) as w:
        law = w.law("linear_elastic", stiffness=ea, name="film")
        edge = [i + nx * j for j in range(ny) for i in range(nx)
                if i in (0, nx - 1) or j in (0, ny - 1)]
        web = w.web_sheet(law, nx=nx, ny=ny, spacing_x=0.01, spacing_y=0.01, prestretch_x=pre,
                          prestretch_y=pre, node_mass=1e-3, substeps=8, pinned=edge, name="sheet")
        info = web.info()
        assert (info["nx"], info["ny"], info["closed"]) == (nx, ny, 0)
        assert web.node_count == nx * ny
        assert web.spring_count == (nx - 1) * ny + nx * (ny - 1)
        w.step(200)
        assert np.allclose(web.strains(), pre, rtol=1e-9)
        t = np.empty(web.spring_count)
        assert web.tensions(out=t) is t
        assert np.allclose(t, ea * pre, rtol=1e-9)
        assert law.evaluate(pre)[0] == pytest.approx(ea * pre)
        assert law.evaluate(pre)[1] == pytest.approx(ea)
        assert law.energy(pre) == pytest.approx(ea * pre ** 2 / 2)
        p = web.positions()
        assert p.shape == (nx * ny, 3) and p[1, 0] - p[0, 0] == pytest.approx(0.01)
        assert np.abs(web.velocities()).max() < 1e-9
        assert not web.contact_forces().any()
        s = web.springs()
        assert s.dtype == np.uint32 and s.shape == (web.spring_count, 2)
        assert web.energy()["elastic"] > 0
        with pytest.raises(ValueError):
            web.tensions(out=np.empty(3))


def test_implicit_web_sags_like_a_string():
    """A pinned string of 21 nodes under gravity on the implicit film at dt 2 ms, beyond its
    explicit stable step (which it is not refused for): with drag it settles, and its mid-node
    sag is the discrete string's: H (y[i+1] - 2 y[i] + y[i-1]) / s = -P for node weights P at
    spacing s gives y[i] = P s i (N - i) / (2 H), at mid-span P s N^2 / (8 H), with H the
    middle spring's tension (its slope P / (2 H) ~ 0.004 makes T and H differ by 1e-5).
    Tolerance 2e-3: the formula takes the nodes s apart horizontally, but spring i's run is
    l0 (cos(theta_i) + H / EA), shorter by theta^2 / 2 (up to 3e-3 at the ends, theta ~ 0.08)
    where it is steep; the solves' residual (1e-9) and the settling (e^-50) are far below."""
    n, sp, pre, ea, m = 21, 0.05, 0.05, 50.0, 2e-3
    with ws.World(gravity=(0, 0, -9.81), dt=2e-3) as w:
        law = w.law("linear_viscoelastic", stiffness=ea, damping=0.02)
        web = w.web_sheet(law, nx=n, ny=1, spacing_x=sp, spacing_y=sp, prestretch_x=pre,
                          node_mass=m, node_damping=0.05, pinned=[0, n - 1],
                          integrator="implicit", solver_tolerance=1e-9, name="string")
        assert web.stable_dt < 2e-3
        w.step(2000)
        st = web.solver_stats()
        assert st["solves"] == 2000 and st["iterations"] >= 2000
        assert st["last_residual"] <= 1e-9
        p = web.positions()
        sag = -p[n // 2, 2]
        H = ea * float(web.strains()[n // 2 - 1])
        N = n - 1
        assert sag == pytest.approx(m * 9.81 * sp * N ** 2 / (8 * H), rel=2e-3)
        with pytest.raises(ValueError):
            w.web_sheet(law, nx=3, ny=1, spacing_x=sp, spacing_y=sp, node_mass=m,
                        integrator="backward")
        with pytest.raises(ws.WrapsimError):
            w.web_sheet(law, nx=3, ny=1, spacing_x=sp, spacing_y=sp, node_mass=m,
                        integrator="implicit", solver_tolerance=0.5)
        # the multigrid needs a grid of at least 17 nodes: a string of 3 is refused by name
        with pytest.raises(ws.WrapsimError, match="MULTIGRID"):
            w.web_sheet(law, nx=3, ny=1, spacing_x=sp, spacing_y=sp, node_mass=m,
                        integrator="implicit", preconditioner="multigrid")
        with pytest.raises(ValueError):
            w.web_sheet(law, nx=3, ny=1, spacing_x=sp, spacing_y=sp, node_mass=m,
                        integrator="implicit", preconditioner="lines")
        jac = w.web_sheet(law, nx=3, ny=1, spacing_x=sp, spacing_y=sp, node_mass=m,
                          integrator="implicit", preconditioner="block_jacobi")
        assert jac.solver_stats()["solves"] == 0
        with pytest.raises(ws.WrapsimError, match="hold_bodies"):
            w.web_sheet(law, nx=3, ny=1, spacing_x=sp, spacing_y=sp, node_mass=m,
                        integrator="implicit", hold_bodies=2)
        held = w.web_sheet(law, nx=3, ny=1, spacing_x=sp, spacing_y=sp, node_mass=m,
                           integrator="implicit", hold_bodies=1)
        assert held is not None


def test_drive_callback_and_its_errors():
    with ws.World(gravity=(0, 0, 0)) as w:
        b = w.body(w.box(0.1, 0.1, 0.1), type="kinematic", position=(1, 0, 0))
        assert b.type == ws.WS_BODY_KINEMATIC and b.mass == 0.0
        b.set_drive("callback", callback=lambda t: ((t, 0, 0), (1, 0, 0, 0), (1, 0, 0)))
        w.step(100)
        assert b.position[0] == pytest.approx(w.time)
        assert b.velocity[0] == pytest.approx(1.0)

        t_fail = w.time + 0.001

        def bad(t):
            if t > t_fail:
                raise KeyError("from the drive")
            return (0, 0, 0), (1, 0, 0, 0)
        b.set_drive("callback", callback=bad)
        with pytest.raises(ws.WrapsimError) as e:
            w.step(10)
        assert e.value.status == ws.WS_ERR_CALLBACK and "callback" in e.value.detail
        assert isinstance(e.value.__cause__, KeyError)
        b.set_drive("sine", direction=(0, 0, 1), amplitude=0.01, frequency=2.0)
        w.step(10)
        b.set_drive("static")
        with pytest.raises(ValueError):
            b.set_drive("callback")


def test_callbacks_may_not_change_the_world():
    """A drive callback that steps the world or destroys a body inside the step gets
    WS_ERR_IN_STEP (a WrapsimError) for that call; getters work there."""
    seen = []
    with ws.World(gravity=(0, 0, 0)) as w:
        box = w.body(w.box(0.1, 0.1, 0.1), mass=1.0, position=(0, 0, 1))
        table = w.body(w.box(0.1, 0.1, 0.1), type="kinematic")

        def drive(t):
            if t > 0.0:
                for call in (lambda: w.step(1), box.destroy):
                    try:
                        call()
                        seen.append("no error")
                    except ws.WrapsimError as e:
                        seen.append((e.status, e.detail))
                seen.append(box.position[2])
            return (0, 0, 0), (1, 0, 0, 0)
        table.set_drive("callback", callback=drive)
        w.step(1)
        assert [s[0] for s in seen[:2]] == [ws.WS_ERR_IN_STEP, ws.WS_ERR_IN_STEP]
        assert "ws_world_step called from inside ws_world_step" in seen[0][1]
        assert "ws_body_destroy called from inside ws_world_step" in seen[1][1]
        assert seen[2] == pytest.approx(1.0)
        box.destroy()  # outside the step it works


def test_def_inits_take_the_callers_size():
    """The sized inits write no more than the size passed and record it."""
    lib = ws._c()
    d = L.BodyDef()
    ctypes.memset(ctypes.byref(d), 0xA5, ctypes.sizeof(d))
    lib.ws_body_def_init_sized(ctypes.byref(d), L.BodyDef.density.offset)
    assert d.size == L.BodyDef.density.offset
    raw = bytes(ctypes.string_at(ctypes.byref(d), ctypes.sizeof(d)))
    assert set(raw[L.BodyDef.density.offset:]) == {0xA5}  # nothing past the size written


def test_platform_test_drives():
    """The packaging tests' drives through the binding: the EUMOS pulse's plateau, the impact's
    velocity change, a table back at rest, the truck spectrum's Grms and its history's
    reproducibility, and the drive state's tilt angle."""
    g0 = ws.WS_STANDARD_GRAVITY
    with ws.World(gravity=(0, 0, 0), dt=1e-3) as w:
        p = w.body(w.box(1, 1, 0.05), type="kinematic")
        p.set_drive("pulse", acceleration=0.4 * g0, start_time=0.0, coast_time=0.1)
        w.step(250)  # mid-plateau: 0.05 s rise, 0.3 s hold
        st = p.drive_state()
        assert st["type"] == ws.WS_DRIVE_PULSE and st["has_acceleration"]
        assert st["acceleration"][0] == pytest.approx(0.4 * g0, rel=1e-12)
        # The speed A (rise + hold) after the pulse, exactly.
        w.step(200)
        assert p.drive_state()["velocity"][0] == pytest.approx(0.4 * g0 * 0.35, rel=1e-12)

        q = w.body(w.box(1, 1, 0.05), type="kinematic", position=(0, 3, 0))
        q.set_drive("impact", speed=1.2, pulse_duration=0.01, gentle_acceleration=4.0,
                    coast_time=0.0, start_time=w.time)
        w.step(int(round((2 * 1.2 / 4.0) / 1e-3)))  # the run-up
        assert q.drive_state()["velocity"][0] == pytest.approx(1.2, rel=1e-9)
        w.step(12)
        assert q.drive_state()["velocity"][0] == pytest.approx(0.0, abs=1e-9)

        r = w.body(w.box(1, 1, 0.05), type="kinematic", position=(0, 6, 0))
        r.set_drive("table", table=[0.0, 2.0, 2.0, -1.0, 0.0], table_interval=0.01,
                    start_time=w.time, direction=(0, 0, 1))
        w.step(60)
        st = r.drive_state()
        assert st["velocity"][2] == pytest.approx(0.0, abs=1e-12)
        assert st["displacement"][2] == pytest.approx(0.0, abs=1e-12)

        t = w.body(w.box(1, 1, 0.05), type="kinematic", position=(0, 9, 0))
        t.set_drive("tilt", rate=0.1, start_time=w.time, max_angle=0.05)
        w.step(2000)
        assert t.drive_state()["angle"] == pytest.approx(0.05, rel=1e-12)
        assert t.drive_state()["angular_rate"] == 0.0

    f, lv = ws.truck_psd("medium")
    assert ws.vibration_grms(f, lv) == pytest.approx(0.54, rel=1e-12)
    a = ws.synthesize_vibration(f, lv, 2 ** 14, seed=3, sample_rate=512.0)
    b = ws.synthesize_vibration(f, lv, 2 ** 14, seed=3, sample_rate=512.0)
    assert np.array_equal(a, b)
    assert np.sqrt(np.mean(a ** 2)) / g0 == pytest.approx(0.54, rel=0.02)
    assert not np.array_equal(a, ws.synthesize_vibration(f, lv, 2 ** 14, seed=4,
                                                         sample_rate=512.0))
    with pytest.raises(ValueError):
        ws.synthesize_vibration(f, lv, 1000)
    with pytest.raises(ws.WrapsimError):
        ws.synthesize_vibration(f[::-1], lv, 1024)
    with ws.World() as w:
        p = w.body(w.box(1, 1, 0.05), type="kinematic")
        p.set_drive("random", psd_frequency=f, psd_level=lv, seed=1, duration=2.0,
                    sample_rate=512.0, ramp_time=0.2, direction=(0, 0, 1))
        w.step(100)
        assert p.drive_state()["type"] == ws.WS_DRIVE_RANDOM
        p.set_drive("sweep", acceleration=1.0, frequency=2.0, frequency_end=20.0, duration=5.0,
                    sweep_law="linear")
        with pytest.raises(ws.WrapsimError) as e:
            p.set_drive("sine", amplitude=0.01, frequency=1e308)
        assert e.value.status == ws.WS_ERR_INVALID_ARGUMENT and "frequency" in e.value.detail


# --- the tilt table: Python against C ------------------------------------------------------------
def build_tilt(wrapped=False):
    """examples/tilt_table.c's tilt_build() with the default options (variant R)."""
    a, m, layer = 0.25, 5.0, 1e-3
    gap = 2 * layer
    w = ws.World(dt=2.5e-4, full_detection_until=0.5, detection_interval=5, use_ccd=1,
                 profile=0, integrator="symplectic_euler")
    box_mat = w.material("cardboard")
    plane_mat = w.material("platform")
    cd = dict(stiffness=2e5, damping=10.0, friction=0.3, friction_vlim=0.01,
              friction_model="regularized", stick_stiffness=2e5, stick_damping=250.0)
    w.set_contact(box_mat, box_mat, **cd)
    w.set_contact(box_mat, plane_mat, **cd)
    slab = w.box(1.5, 1.5, 0.05)
    cube = w.box(a, a, a)
    bar = w.box(0.02, 0.5, 0.02)
    tilt = dict(axis=(0, 1, 0), point=(0, 0, 0), start_time=1.0, rate=0.1)
    plane = w.body(slab, type="kinematic", material=plane_mat, contact_layer=layer,
                   position=(0, 0, -0.025), name="platform")
    plane.set_drive("tilt", **tilt)
    stop = w.body(bar, type="kinematic", material=plane_mat, contact_layer=layer,
                  position=(a / 2 + gap + 0.01, 0, 0.01), name="stop")
    stop.set_drive("tilt", **tilt)
    bottom = w.body(cube, material=box_mat, mass=m, contact_layer=layer,
                    position=(0, 0, gap + a / 2), name="bottom")
    top = w.body(cube, material=box_mat, mass=m, contact_layer=layer,
                 position=(0, 0, gap + a + gap + a / 2), name="top")
    film = None
    if wrapped:  # tilt_wrap()
        k, c, n_around, n_up = 2000.0, 0.1, 96, 61
        z0, z1 = 0.030, 2 * a + 2 * 2 * layer - 0.020
        perimeter = 4 * a + 2 * math.pi * 2 * layer
        l0_around = perimeter / n_around / 1.4
        l0_up = (z1 - z0) / (n_up - 1) / 1.2
        around = w.law("tension_compression", stiffness=k * l0_around,
                       compression_stiffness=0.01 * k * l0_around, damping=c * l0_around,
                       name="film around")
        up = w.law("tension_compression", stiffness=k * l0_up,
                   compression_stiffness=0.01 * k * l0_up, damping=c * l0_up, name="film up")
        film_mat = w.material("film")
        fc = dict(stiffness=4000.0, damping=1.0, friction=0.9, friction_vlim=0.01)
        w.set_contact(film_mat, box_mat, **fc)
        w.set_contact(film_mat, plane_mat, **fc)
        film = w.web_band(around, [bottom, top], law_cross=up, node_mass=1e-3,
                          contact_layer=layer, material=film_mat, substeps=2, name="film",
                          z_bottom=z0, z_top=z1, n_around=n_around, n_up=n_up,
                          prestretch_around=0.4, prestretch_up=0.2)
    return w, plane, stop, bottom, top, film


TILT_MAIN = r"""
#define TILT_TABLE_NO_MAIN
#include "tilt_table.c"
int main(int argc, char **argv)
{
    tilt_options o;
    tilt_scene sc;
    uint64_t h = 0;
    tilt_default_options(&o);
    o.wrapped = argc > 2 && argv[2][0] == 'w';
    if (tilt_build(&o, &sc) != WS_OK)
        return 1;
    if (ws_world_step_n(sc.world, atol(argv[1])) != WS_OK)
        return 2;
    ws_world_get_state_hash(sc.world, &h);
    printf("%llu\n", (unsigned long long)h);
    ws_world_destroy(sc.world);
    (void)tilt_run;
    return 0;
}
"""


@pytest.fixture(scope="module")
def tilt_exe(tmp_path_factory):
    return compile_c(tmp_path_factory.mktemp("tilt"), TILT_MAIN, "tilt_hash")


def test_tilt_table_matches_c(tilt_exe):
    steps = 28000  # 7 s, variant R unwrapped: the top box slides off, the bottom one stays
    c_hash = int(run_c(tilt_exe, steps))
    w, plane, stop, bottom, top, _ = build_tilt()
    with w:
        w.step(steps)
        assert w.state_hash() == c_hash
        assert w.time == pytest.approx(7.0)
        # and the physics the example reports: the top box has left the bottom one
        assert np.linalg.norm(top.position - bottom.position) > 0.5


TILT_ONSET_MAIN = r"""
#define TILT_TABLE_NO_MAIN
#include "tilt_table.c"
int main(void)
{
    tilt_options o;
    tilt_result r;
    tilt_default_options(&o);
    o.quiet = 1;
    if (tilt_run(&o, &r) != WS_OK)
        return 1;
    printf("%.17g %.17g %.17g %.17g\n", r.slide_time[1], r.slide_angle[1], r.off_time[1],
           r.slide_time[0]);
    return 0;
}
"""


def test_tilt_examples_report_the_same_slide_onset(tmp_path):
    """examples/python/tilt_table.py and examples/tilt_table.c report slide onset by one
    definition (every contact with the support slipping the same way, |v_t| >= v_lim, for
    0.2 s), checked on every step in both: on the same steps of the same library they find the
    same onset, to round-off, and stop the run on the same step when the top box leaves the
    platform. The onset is that of the theory, tan(theta) = 0.3, within 0.3 deg (the C suite's
    tolerance: the dynamic lag of a 5 kg box starting to slip)."""
    exe = compile_c(tmp_path, TILT_ONSET_MAIN, "tilt_onset")
    c_time, c_angle, c_off, c_bottom = map(float, run_c(exe).split())
    spec = importlib.util.spec_from_file_location(
        "tilt_table_example", REPO / "examples" / "python" / "tilt_table.py")
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    r = ex.run_case("R", False, 7.0, [])
    (p_time, p_angle), p_off = r["slide"][1], r["off"][1]
    assert r["slide"][0] is None and math.isnan(c_bottom)  # the bottom box rests on the stop
    assert p_time == pytest.approx(c_time, abs=1e-9)
    assert p_angle == pytest.approx(c_angle, abs=1e-9)
    assert p_off == pytest.approx(c_off, abs=1e-9)
    assert abs(p_angle - math.degrees(math.atan(0.3))) < 0.3


def test_tilt_table_wrapped_matches_c(tilt_exe):
    steps = 400
    c_hash = int(run_c(tilt_exe, steps, "wrapped"))
    w, plane, stop, bottom, top, film = build_tilt(wrapped=True)
    with w:
        w.step(steps)
        assert w.state_hash() == c_hash
        info = film.info()
        assert (info["nx"], info["ny"], info["closed"]) == (96, 61, 1)
        assert film.stable_dt > 0
        film.substeps = 2
        assert film.substeps == 2
        prof = film.containment(4)
        assert prof.shape == (4,) and (prof["z_high"] > prof["z_low"]).all()
        assert (prof["hoop_tension"] > 0).all()
        f, mom = film.body_force(top)
        assert np.isfinite(f).all() and np.isfinite(mom).all()
        assert film.contact_forces().shape == (96 * 61, 3)
        assert film.velocities().shape == (96 * 61, 3)


# --- save and restore ----------------------------------------------------------------------------
def build_relaxing_sheet(n=8):
    """A box on the ground under a falling sheet whose springs relax (a Prony law: a history in
    every spring), full detection every 3rd step; one film sub-step near its bound (the check at
    the bound itself, as the C suite's twin)."""
    w = ws.World(dt=2.5e-4, detection_interval=3, stable_fraction=1.0)
    ground = w.body(w.box(2.0, 2.0, 0.05), type="kinematic", position=(0, 0, -0.025))
    box = w.body(w.box(0.25, 0.25, 0.25), mass=5.0, position=(0, 0, 0.126))
    law = w.law("relaxation", stiffness=100.0, prony_stiffness=[300.0, 200.0],
                prony_time=[0.02, 0.2])
    film = w.material("film")
    w.set_contact(film, w.default_material, stiffness=4000.0, damping=1.0, friction=0.9)
    sheet = w.web_sheet(law, nx=n, ny=n, spacing_x=0.36 / (n - 1), spacing_y=0.36 / (n - 1),
                        origin=(-0.18, -0.17, 0.26), prestretch_x=0.1, node_mass=5e-3,
                        node_damping=1e-3, material=film)
    return w, ground, box, sheet


def test_save_restore_continues_bit_identically(tmp_path):
    # A world restored from a save and stepped takes the saved world's steps, bit for bit: the
    # state hash compared at every step for 300 steps, in memory and through a file, restored
    # into a world that has been stepped elsewhere meanwhile.
    a = build_relaxing_sheet()[0]
    b = build_relaxing_sheet()[0]
    with a, b:
        a.step(250)
        data = a.save()
        assert isinstance(data, bytes) and data[:7] == b"WSSTATE"
        path = tmp_path / "state.wss"
        assert a.save(path) is None
        assert path.read_bytes() == data
        want = []
        for _ in range(300):
            a.step()
            want.append(a.state_hash())
        for source in (data, bytearray(data), str(path), path):
            b.step(37)
            b.restore(source)
            got = []
            for _ in range(300):
                b.step()
                got.append(b.state_hash())
            assert got == want
        assert b.save() == a.save()


def test_restore_refuses_bad_saves_and_changes_nothing():
    a = build_relaxing_sheet()[0]
    b = build_relaxing_sheet()[0]
    other = build_relaxing_sheet(10)[0]
    with a, b, other:
        a.step(100)
        data = a.save()
        b.step(20)
        before = b.save()
        newer = bytearray(data)
        newer[8] = 3
        flipped = bytearray(data)
        flipped[len(data) // 2] ^= 1
        for bad, text in ((data[:-1], "truncated"), (bytes(newer), "version 3 is newer"),
                          (bytes(flipped), "checksum mismatch"), (b"nonsense" * 8, "not a saved")):
            with pytest.raises(ws.WrapsimError) as e:
                b.restore(bad)
            assert e.value.status == ws.WS_ERR_FORMAT and text in e.value.detail
            assert b.save() == before
        with pytest.raises(ws.WrapsimError) as e:
            other.restore(data)
        assert "web 0 has 64 nodes in the file, 100 here" in e.value.detail
        with pytest.raises(ws.WrapsimError) as e:
            b.restore("/no/such/file.wss")
        assert e.value.status == ws.WS_ERR_IO
        with pytest.raises(TypeError):
            b.restore(12)
        assert b.save() == before


def test_world_cannot_be_copied():
    # A copy would share the C world and free it twice: refused, and the world stays usable.
    import copy
    import pickle
    with ws.World() as w:
        for f in (copy.copy, copy.deepcopy, pickle.dumps):
            with pytest.raises(TypeError, match="cannot be"):
                f(w)
        w.step(3)
        assert w.time == pytest.approx(3 * w.dt)


# --- the rest of the API -------------------------------------------------------------------------
def test_world_and_body_api(tmp_path):
    messages = []
    with ws.World(dt=1e-4, user_data=1234, profile=1,
                  log=lambda level, text: messages.append((level, text))) as w:
        assert w.dt == pytest.approx(1e-4)
        w.dt = 2e-4
        assert w.dt == pytest.approx(2e-4)
        assert w.stable_fraction == 0.5  # the default (world.h)
        w.set_gravity((0, 0, -9.81))
        w.gravity = (0, 0, -9.81)
        assert w.user_data == 1234
        assert w.last_error == ""
        d = w.default_material
        assert d.valid
        w.set_default_contact(stiffness=1e5, damping=20.0)
        assert w.get_contact(d, d)["stiffness"] == pytest.approx(1e5)
        rubber = w.material("rubber")
        w.set_contact(rubber, d, friction=0.8, friction_model="stick")
        cd = w.get_contact(d, rubber)
        assert cd["friction"] == pytest.approx(0.8) and cd["friction_model"] == 1
        cyl = w.cylinder(0.05, 0.2, 24)
        ci = cyl.info()
        assert ci["volume"] == pytest.approx(24 / 2 * 0.05 ** 2 * math.sin(2 * math.pi / 24)
                                             * 0.2)
        assert cyl.valid
        cyl.destroy()
        assert not cyl.valid
        box = w.box(0.2, 0.2, 0.2)
        v, t = box.copy_mesh()
        assert v.shape == (8, 3) and t.shape == (12, 3)
        meshed = w.mesh(v + 5.0, t)  # re-centred on its centroid
        mi = meshed.info()
        assert mi["volume"] == pytest.approx(0.008) and mi["convex"] == 1
        assert np.allclose(mi["centroid"], 5.0)
        ground = w.body(w.box(2, 2, 0.1), type="kinematic", position=(0, 0, -0.05),
                        material=rubber)
        body = w.body(meshed, mass=2.0, position=(0, 0, 0.102), user_data=77, name="b",
                      orientation=(1, 0, 0, 0), velocity=(0.1, 0, 0), inertia=np.eye(3) * 0.02)
        assert body.user_data == 77 and body.mass == 2.0
        assert np.allclose(body.inertia, np.eye(3) * 0.02)
        assert [b.name for b in w.bodies()] == ["", "b"]
        assert w.estimate_stable_dt() > 0
        w.step()
        w.step(50)
        assert w.stats()["steps"] == 51
        assert w.time == pytest.approx(51 * 2e-4)
        body.set_pose((0, 0, 0.2), (math.cos(0.1), 0, 0, math.sin(0.1)))
        body.set_velocity((0, 0, 0), (0, 0, 1.0))
        assert np.allclose(body.angular_velocity, (0, 0, 1))
        assert np.allclose(body.angular_velocity_local, (0, 0, 1))
        assert np.allclose(body.point_velocity(body.position + (1, 0, 0)), (0, 1, 0))
        assert np.allclose(body.world_point((0, 0, 0)), (0, 0, 0.2))
        assert np.allclose(body.rotation @ body.rotation.T, np.eye(3))
        assert body.orientation[0] == pytest.approx(math.cos(0.1))
        assert body.type == ws.WS_BODY_DYNAMIC
        e = w.energy()
        assert set(e) == {"kinetic", "potential", "contact"}
        assert isinstance(w.state_hash(), int)
        w.write_vtp(tmp_path / "bodies.vtp")
        assert (tmp_path / "bodies.vtp").stat().st_size > 0
        with pytest.raises(ws.WrapsimError) as err:
            w.write_vtp(tmp_path / "no" / "such" / "dir.vtp")
        assert err.value.status == ws.WS_ERR_IO and "dir.vtp" in err.value.detail
        ground.destroy()
        assert not ground.valid


def test_webs_laws_and_vtk_series(tmp_path):
    with ws.World(gravity=(0, 0, -9.81)) as w:
        law = w.law("linear_viscoelastic", stiffness=100.0, damping=0.1)
        shear = w.law(stiffness=10.0)
        tc = w.law(ws.WS_LAW_TENSION_COMPRESSION, stiffness=100.0, compression_stiffness=1.0,
                   transition=1e-3)
        assert tc.evaluate(-0.1)[1] == pytest.approx(1.0)
        assert law.evaluate(0.0, 2.0)[0] == pytest.approx(0.2)
        assert law.evaluate(0.0, 2.0)[2] == pytest.approx(0.1)
        sheet = w.web_sheet(law, law_shear=shear, nx=4, ny=3, spacing_x=0.05, spacing_y=0.05,
                            shear=1, node_mass=0.01, substeps=2, pinned=[0, 3])
        pos = np.array([[0, 0, 1], [0.1, 0, 1], [0.2, 0, 1]], float)
        rope = w.web_mesh(law, pos, [[0, 1], [1, 2]], node_masses=[1e-2] * 3,
                          rest_lengths=[0.09, 0.09], kinds=[0, 0], pinned=[0], node_mass=1e-3,
                          substeps=2)
        assert rope.node_count == 3 and rope.info()["nx"] == 0
        assert np.allclose(rope.strains(), 0.1 / 0.09 - 1)
        crate = w.body(w.box(0.2, 0.2, 0.2), mass=1.0, position=(1, 1, 0.1))
        band = w.web_band(law, [crate], node_mass=1e-3, substeps=12, z_bottom=0.02, z_top=0.18,
                          n_around=12, n_up=4, prestretch_around=0.2, prestretch_up=0.1)
        assert band.info()["closed"] == 1
        assert band.containment(2)["hoop_tension"].min() > 0
        assert np.isfinite(np.concatenate(band.body_force(crate))).all()
        with pytest.raises(ws.WrapsimError):
            rope.containment(1)  # a mesh web has no rows
        with w.vtk_series(tmp_path, "run") as series:
            for _ in range(3):
                w.step(10)
                series.write_frame()
            assert series.frame_count == 3
        with pytest.raises(ws.WrapsimError):
            series.write_frame()
        assert (tmp_path / "run.pvd").exists()
        sheet.write_vtp(tmp_path / "sheet.vtp")
        assert (tmp_path / "sheet.vtp").exists()
        # Strides: a call every 10 ms from t = 17.5 ms, every 2nd call offered (17.5, 37.5,
        # 57.5, 77.5, 97.5 ms) and at most one frame per 25 ms slot (slots 0, 1, 2, 3, 3).
        with w.vtk_series(tmp_path, "strided", format="ascii", frame_stride=2,
                          time_stride=0.025, springs=1) as strided:
            for _ in range(10):
                w.step(40)  # 10 ms at dt 0.25 ms
                strided.write_frame()
            assert strided.frame_count == 4
        assert (tmp_path / "strided_000000_springs1.vtp").exists()
        with pytest.raises(ws.WrapsimError) as err:
            w.vtk_series(tmp_path, "bad", frame_stride=0)
        assert err.value.status == ws.WS_ERR_INVALID_ARGUMENT
        assert "frame_stride" in err.value.detail
        open_series = w.vtk_series(tmp_path, "left-open")  # closed with the world
        open_series.write_frame()
        with pytest.raises(ws.WrapsimError) as err:
            law.destroy()
        assert err.value.status == ws.WS_ERR_IN_USE
        rope.destroy()
        band.destroy()
        sheet.destroy()
        assert not sheet.valid
        law.destroy()
        assert not law.valid
    assert open_series._ptr is None


def test_laws_of_every_kind_and_their_history():
    with ws.World() as w:
        # A 3D orthotropic Kelvin-Voigt law: F = K u + C ud.
        K = np.diag([100.0, 200.0, 300.0])
        C = np.diag([1.0, 2.0, 3.0])
        kv = w.law("linear_viscoelastic", dim=3, stiffness_matrix=K, damping_matrix=C)
        info = kv.info()
        assert info["dim"] == 3 and kv.dim == 3 and info["state_size"] == 0
        assert info["flags"] == ws.WS_LAW_FLAG_ELASTIC | ws.WS_LAW_FLAG_VISCOUS
        assert info["max_stiffness"] == pytest.approx(300.0)
        u, ud = np.array([0.01, 0.02, 0.03]), np.array([1.0, 0.0, -1.0])
        F, dFdu, dFdud = kv.evaluate_state(u, ud)
        assert F == pytest.approx(K @ u + C @ ud)
        assert np.array_equal(dFdu, K) and np.array_equal(dFdud, C)
        assert kv.energy_state(u) == pytest.approx(0.5 * u @ K @ u)
        assert kv.state_size == 0 and len(kv.init_state()) == 0
        kv.commit(None, u)  # no history: nothing to do

        # Relaxation (standard linear solid): a held step decays with tau.
        sls = w.law("relaxation", stiffness=100.0, prony_stiffness=[400.0], prony_time=[0.3])
        st = sls.init_state()
        assert st.shape == (2,) and sls.info()["state_size"] == 2
        sls.commit(st, [0.1])  # the step, within a step of zero length
        for k in range(1, 301):
            before = st.copy()
            sls.evaluate_state([0.1], t=k * 1e-3, dt=1e-3, state=st)
            assert np.array_equal(st, before)  # evaluation never changes the state
            sls.commit(st, [0.1], t=k * 1e-3, dt=1e-3)
        F, _, _ = sls.evaluate_state([0.1], state=st)
        # 300 steps of exp(-dt/tau) each: the closed form to round-off.
        assert F[0] == pytest.approx((100.0 + 400.0 * math.exp(-1.0)) * 0.1, rel=1e-12)
        assert sls.energy_state([0.1], state=st) > 0.5 * 100.0 * 0.1 ** 2
        with pytest.raises(ValueError):
            sls.evaluate_state([0.1], state=np.zeros(3))

        # Table (monotone through its points), cubic, stop, viscous; sum and scaled.
        table = w.law("table", table_strain=[0.0, 0.01, 0.02, 0.1],
                      table_force=[0.0, 10.0, 10.1, 10.3])
        assert table.evaluate(0.01)[0] == 10.0
        samples = [table.evaluate(x)[0] for x in np.linspace(0.0, 0.1, 501)]
        assert all(b >= a for a, b in zip(samples, samples[1:]))
        with pytest.raises(ws.WrapsimError) as e:
            w.law("table", table_strain=[0.0, 0.1], table_force=[1.0, 0.0])
        assert e.value.status == ws.WS_ERR_INVALID_ARGUMENT and "table_force" in e.value.detail
        cubic = w.law("cubic_elastic", stiffness=10.0, cubic_stiffness=1000.0)
        assert cubic.energy(0.1) == pytest.approx(0.5 * 10 * 0.01 + 0.25 * 1000 * 1e-4)
        stop = w.law("stop", stiffness=1000.0, stop_high=0.02, transition=0.0)
        assert stop.evaluate(0.01)[0] == 0.0 and stop.evaluate(0.03)[0] == pytest.approx(10.0)
        visc = w.law(ws.WS_LAW_LINEAR_VISCOUS, damping=2.0)
        assert visc.evaluate(0.5, 3.0) == (6.0, 0.0, 2.0)
        total = w.law("sum", terms=[cubic, stop, visc])
        assert total.evaluate(0.03, 1.0)[0] == pytest.approx(
            cubic.evaluate(0.03)[0] + stop.evaluate(0.03)[0] + 2.0)
        with pytest.raises(ws.WrapsimError) as e:
            cubic.destroy()
        assert e.value.status == ws.WS_ERR_IN_USE
        ramp = w.law("scaled", base=cubic, scale_times=[0.0, 1.0], scale_factors=[0.0, 1.0])
        assert ramp.evaluate_state([0.1], t=0.5)[0][0] == pytest.approx(
            0.5 * cubic.evaluate(0.1)[0])
        wave = w.law("scaled", base=cubic, scale_fn=lambda t: 2.0 + t)
        assert wave.evaluate_state([0.1], t=1.0)[0][0] == pytest.approx(3 * cubic.evaluate(0.1)[0])

        def broken(t):
            raise ZeroDivisionError("from the time function")
        bad = w.law("scaled", base=cubic, scale_fn=broken)
        with pytest.raises(ws.WrapsimError) as e:
            bad.evaluate(0.1)
        assert e.value.status == ws.WS_ERR_CALLBACK
        assert isinstance(e.value.__cause__, ZeroDivisionError)
        for law in (bad, wave, ramp, total):
            law.destroy()
        cubic.destroy()


def test_user_law_written_in_python():
    """A 3D law from Python through a ctypes callback: its derivatives agree with central
    differences, it sees the time, and an exception in it becomes WS_ERR_CALLBACK."""
    seen = []

    def pad(u, ud, t):
        seen.append(t)
        F = 50.0 * u + 2e4 * u ** 3 + 0.5 * ud
        return F, np.diag(50.0 + 6e4 * u ** 2), np.diag([0.5] * 3)

    with ws.World() as w:
        law = w.law("user", dim=3, user_fn=pad, stiffness=100.0, damping=0.5, name="pad")
        assert law.info()["type"] == ws.WS_LAW_USER
        u, ud = np.array([0.01, -0.02, 0.05]), np.array([0.3, 0.0, -0.1])
        F, K, C = law.evaluate_state(u, ud, t=2.5)
        assert seen[-1] == 2.5
        assert F == pytest.approx(50.0 * u + 2e4 * u ** 3 + 0.5 * ud)
        h = 1e-6
        for j in range(3):
            e = np.zeros(3)
            e[j] = h
            fd = (law.evaluate_state(u + e, ud)[0] - law.evaluate_state(u - e, ud)[0]) / (2 * h)
            # The central difference of a cubic errs by h^2 F'''/6 = 1e-12 * 1.2e5 / 6 plus the
            # round-off eps |F| / h ~ 1e-10: 1e-6 of the stiffness is ample.
            assert np.abs(fd - K[:, j]).max() < 1e-6 * 100.0
            fdr = (law.evaluate_state(u, ud + e)[0] - law.evaluate_state(u, ud - e)[0]) / (2 * h)
            assert np.abs(fdr - C[:, j]).max() < 1e-8
        with pytest.raises(ws.WrapsimError) as e:
            law.energy_state(u)
        assert e.value.status == ws.WS_ERR_UNSUPPORTED

        def broken(u, ud, t):
            raise RuntimeError("from the law")
        bad = w.law("user", user_fn=broken, name="broken")
        with pytest.raises(ws.WrapsimError) as e:
            bad.evaluate(0.1)
        assert e.value.status == ws.WS_ERR_CALLBACK and "broken" in e.value.detail
        assert isinstance(e.value.__cause__, RuntimeError)
        nan = w.law("user", user_fn=lambda u, ud, t: [float("nan")])
        with pytest.raises(ws.WrapsimError) as e:
            nan.evaluate(0.1)
        assert e.value.status == ws.WS_ERR_NUMERICAL
        law.destroy()
        assert not law.valid


def test_run_progress_text_without_tqdm(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm", None)  # import tqdm now raises ImportError
    with ws.World() as w:
        out = ws.run(w, 0.01, progress=True, desc="plain")
        assert out["t"].size == 0 and w.time == pytest.approx(0.01)
        rec = ws.run(w, 0.02, record={"t2": lambda: [w.time, 2 * w.time]}, progress=True)
    assert "plain: done (40 steps)" in capsys.readouterr().err
    assert rec["t2"].shape == (41, 2)
    assert np.allclose(rec["t2"][:, 1], 2 * rec["t"])


def test_run_with_tqdm_when_present():
    pytest.importorskip("tqdm")
    with ws.World() as w:
        out = ws.run(w, 0.005, record={"t": lambda: w.time}, every=0.001)
        assert len(out["t"]) == 6


# --- deformable elements -------------------------------------------------------------------------
def test_elements_rod_period_and_bulk_outputs():
    """A 2 kg box on a rod (EA = 250 N, l0 = 0.5 m: k = 500 N/m) to a fixed point: period
    2 pi sqrt(m/k) within the symplectic scheme's (omega h)^2/24 = 1e-7 and the zero-crossing
    sampling; bulk read-outs equal the single ones; the loads balance."""
    m, EA, l0, h = 2.0, 250.0, 0.5, 1e-4
    with ws.World(gravity=(0, 0, 0), dt=h) as w:
        box = w.body(w.box(0.1, 0.1, 0.1), mass=m, position=(0, 0, -0.52), name="mass")
        rod_law = w.law("linear_elastic", stiffness=EA)
        rod = w.element("rod", None, box, rod_law, point1=(0, 0, 0), rest_length=l0,
                        name="rod", user_data=42)
        assert rod.valid and rod.name == "rod" and rod.user_data == 42
        assert rod.strain == pytest.approx([0.02 / l0])
        assert rod.force == pytest.approx([0, 0, -EA * 0.02 / l0])  # body 1 pulled down
        strain = []
        for _ in range(int(2.0 / h)):
            w.step()
            strain.append(rod.strain[0])
        s = np.array(strain)
        up = np.nonzero((s[:-1] < 0) & (s[1:] >= 0))[0]
        tc = (up + s[up] / (s[up] - s[up + 1]) + 1) * h
        period = (tc[-1] - tc[0]) / (len(tc) - 1)
        assert period == pytest.approx(2 * math.pi * math.sqrt(m * l0 / EA), rel=1e-6)

        six = w.law("linear_viscoelastic", dim=6, stiffness_matrix=np.diag([2e4, 2e4, 6e4, 30,
                                                                             30, 20]),
                    damping=0.5)
        other = w.body(w.box(0.1, 0.1, 0.1), mass=1.0, position=(0.5, 0, 0))
        bush = w.element("bushing", box, other, six, global_attachment=1,
                         point1=(0.25, 0, -0.26), point2=(0.25, 0, -0.26),
                         formulation="potential")
        other.set_velocity((0.1, 0.2, 0.0), (1.0, 0.0, 0.5))
        w.step(50)
        els = w.elements()
        assert els == [rod, bush]
        outs = w.element_outputs()
        assert outs.dtype == ws.ELEMENT_OUTPUT_DTYPE and outs.shape == (2,)
        assert w.element_outputs(out=outs) is outs
        one = bush.output()
        assert one["dim"] == 6 and one["type"] == ws.WS_ELEMENT_BUSHING
        assert np.array_equal(outs[1]["strain"], one["strain"])
        assert np.array_equal(outs[1]["force"], one["force"])
        assert w.element_energy() == pytest.approx(outs["energy"].sum(), rel=1e-12)
        # Balance: p1 x f + m1 + p2 x (-f) + m2 = 0.
        o = outs[1]
        res = (np.cross(o["point1"], o["force"]) + o["moment"] -
               np.cross(o["point2"], o["force"]) + o["moment2"])
        assert np.abs(res).max() < 1e-12 * (1 + np.abs(o["force"]).max())
        with pytest.raises(ValueError):
            w.element_outputs(out=np.zeros(3, dtype=ws.ELEMENT_OUTPUT_DTYPE))
        with pytest.raises(ws.WrapsimError) as e:
            other.destroy()
        assert e.value.status == ws.WS_ERR_IN_USE
        with pytest.raises(ws.WrapsimError) as e:
            six.destroy()
        assert e.value.status == ws.WS_ERR_IN_USE
        with pytest.raises(ws.WrapsimError) as e:
            w.element("bushing", box, other, rod_law)  # a 1D law for a 6D element
        assert e.value.status == ws.WS_ERR_INVALID_ARGUMENT and "dim 6" in e.value.detail
        with pytest.raises(ValueError):
            w.element("hinge", box, other, six)
        bush.destroy()
        assert not bush.valid
        with pytest.raises(ws.WrapsimError) as e:
            bush.output()
        assert e.value.status == ws.WS_ERR_STALE_HANDLE
        other.destroy()
        six.destroy()
        assert len(w.elements()) == 1


def test_elements_swap_invariance():
    """An orthotropic angular spring between two turned, spinning boxes: the invariant form
    gives the same motion whichever body is first, to the last bit; the attached one does not."""
    def run(form, swap):
        with ws.World(gravity=(0, 0, 0), dt=5e-4) as w:
            a = w.body(w.box(0.2, 0.15, 0.1), mass=2.0)
            b = w.body(w.box(0.1, 0.25, 0.2), mass=3.0, position=(0.8, 0, 0))
            law = w.law("linear_elastic", dim=3, stiffness_matrix=np.diag([2.0, 4.0, 8.0]))
            w.element("angular_spring", *((b, a) if swap else (a, b)), law, formulation=form)
            b.set_pose((0.8, 0, 0), (math.cos(1.0), 0.6 * math.sin(1.0), 0.0,
                                     0.8 * math.sin(1.0)))
            a.set_velocity((0, 0, 0), (1.0, -2.0, 0.5))
            b.set_velocity((0, 0, 0), (-1.5, 0.7, 2.5))
            w.step(400)
            return np.concatenate([a.orientation, b.orientation, a.angular_velocity,
                                   b.angular_velocity])
    assert np.array_equal(run("invariant", False), run("invariant", True))
    assert np.abs(run("attached", False) - run("attached", True)).max() > 1e-3


# --- loadtest.h: unit loads and the EUMOS test (the raw calls; no wrapper yet) -------------------
def test_load_build_measure_wrap_and_eumos():
    byref = ctypes.byref
    with ws.World(detection_interval=10) as w:
        ld = L.LoadDef()
        LIB.ws_load_def_init_sized(byref(ld), ctypes.sizeof(ld))
        ld.layers, ld.count_x, ld.count_y = 1, 2, 1
        load = ctypes.c_void_p()
        assert LIB.ws_load_build(w.ptr, byref(ld), byref(load)) == 0, w.last_error
        info = L.LoadInfo()
        assert LIB.ws_load_get_info(load, byref(info)) == 0
        assert (info.layers, info.cartons) == (1, 2)
        assert LIB.ws_load_get_layer_count(load, 0) == 2
        c = L.LoadCarton()
        assert LIB.ws_load_get_carton(load, 0, 1, byref(c)) == 0 and c.ix == 1
        n = ctypes.c_size_t()
        assert LIB.ws_load_copy_cartons(load, None, 0, byref(n)) == 0 and n.value == 2
        cartons = (L.LoadCarton * 2)()
        assert LIB.ws_load_copy_cartons(load, cartons, 2, byref(n)) == 0
        k, pts = ctypes.c_double(), ctypes.c_int()
        assert LIB.ws_load_get_point_stiffness(load, 0, byref(k), byref(pts)) == 0
        assert (k.value, pts.value) == (2e6 / 4, 4)
        settled, took, drift = ctypes.c_int(), ctypes.c_double(), ctypes.c_double()
        assert LIB.ws_load_settle(w.ptr, load, 0.05, 0.2, 1e-3, byref(settled), byref(took)) == 0
        assert LIB.ws_load_get_drift(w.ptr, load, byref(drift)) == 0
        assert LIB.ws_load_set_reference(w.ptr, load) == 0
        states = (L.LoadCartonState * 2)()
        assert LIB.ws_load_measure(w.ptr, load, states, 2, byref(n)) == 0
        assert states[0].horizontal == 0.0
        wr = L.WrapDef()
        LIB.ws_wrap_def_init_sized(byref(wr), ctypes.sizeof(wr))
        web = L.WebId()
        assert LIB.ws_load_wrap_band(w.ptr, load, byref(wr), byref(web)) == 0, w.last_error
        ed = L.EumosDef()
        LIB.ws_eumos_def_init_sized(byref(ed), ctypes.sizeof(ed))
        ed.k, ed.rise_time, ed.hold_time, ed.coast_time, ed.rest_after = 0.05, 0.01, 0, 0, 0
        dd, dur = L.DriveDef(), ctypes.c_double()
        assert LIB.ws_eumos_get_drive(byref(ed), byref(dd), byref(dur)) == 0
        seen = []
        cb = L.SampleFn(lambda user, smp: seen.append(smp.contents.level) or 0)
        ed.on_sample = cb
        res = L.EumosResult()
        assert LIB.ws_loadtest_run_eumos(w.ptr, load, byref(ed), byref(res)) == 0, w.last_error
        assert abs(res.peak_level - 0.05) < 1e-9 and max(seen) == pytest.approx(0.05)
        assert getattr(res.verdict, "pass") == 1 and res.containment[1].line_load > 0
        LIB.ws_load_destroy(load)
    wd = L.WorldDef()
    LIB.ws_world_def_init_sized(byref(wd), ctypes.sizeof(wd))
    wd.detection_interval = 10
    ed.on_sample = L.SampleFn()
    kd = L.KvalueDef()
    LIB.ws_kvalue_def_init_sized(byref(kd), ctypes.sizeof(kd))
    kd.k_low, kd.k_high, kd.tolerance, kd.settle_time = 0.05, 0.1, 0.06, 0.05
    kr = L.KvalueResult()
    assert LIB.ws_loadtest_find_k(byref(wd), byref(ld), byref(ed), byref(kd), byref(kr)) == 0, \
        kr.error
    assert kr.runs == 2 and kr.k_value == 0.1


def _spring_with_weight(w, load, rupture_strain):
    """One spring of EA 100 N, rest length 0.1 m, held at node 0, a 0.1 kg node 1 pulled along
    x by `load` N (as gravity), in a world of dt 0.1 ms."""
    law = w.law("linear_viscoelastic", stiffness=100.0)
    web = w.web_mesh(law, [[0, 0, 0], [0.1, 0, 0]], [[0, 1]], node_masses=[0.1, 0.1],
                     pinned=[0], rupture_strain=rupture_strain, name="strand")
    w.gravity = (load / 0.1, 0.0, 0.0)
    return web


def test_film_rupture():
    # A load F put on at once swings the spring's strain between 0 and 2 F / EA (undamped):
    # 14 N reaches 0.28 and never passes a rupture strain of 0.3; 20 N passes it when
    # 0.2 (1 - cos(omega t)) = 0.3, omega t = 2 pi / 3, omega = sqrt(EA / (l0 m)) = 100 rad/s:
    # t = 20.94 ms. The break is seen at the end of a step and the integrator's phase error
    # is (omega dt)^2 / 24 a radian: within 2 dt.
    with ws.World(dt=1e-4, gravity=(0, 0, 0)) as w:
        web = _spring_with_weight(w, 14.0, 0.3)
        w.step(1000)
        r = web.rupture()
        assert r["broken_count"] == 0 and not r["ruptured"] and r["first_spring"] is None
        assert len(web.broken_springs()) == 0
        peak = web.peak_strain()
        assert peak["spring"] == 0 and peak["node_a"] == 0 and peak["node_b"] == 1
        assert peak["strain"] == pytest.approx(web.strains()[0], abs=1e-15)
        assert peak["tension"] == pytest.approx(100.0 * peak["strain"], rel=1e-12)
    with ws.World(dt=1e-4, gravity=(0, 0, 0)) as w:
        web = _spring_with_weight(w, 20.0, 0.3)
        assert web.rupture_strain == 0.3
        broke = None
        for k in range(400):
            w.step()
            if web.rupture()["broken_last_step"]:
                broke = k
                break
        assert broke is not None
        r = web.rupture()
        assert r["ruptured"] and r["broken_count"] == 1 and r["first_spring"] == 0
        assert r["first_time"] == pytest.approx(2 * math.pi / 3 / 100.0, abs=2e-4)
        assert r["first_strain"] > 0.3
        assert list(web.broken_springs()) == [0]
        assert web.tensions()[0] == 0.0 and web.peak_strain() is None
        # Free: node 1 gains g dt a step, as a free mass (F / m = 200 m/s^2).
        v0 = web.velocities()[1, 0]
        w.step()
        assert web.velocities()[1, 0] - v0 == pytest.approx(200.0 * 1e-4, rel=1e-12)
        with pytest.raises(ws.WrapsimError, match="finite and >= 0"):
            web.rupture_strain = -0.5
        with pytest.raises(ws.WrapsimError, match="finite and >= 0"):
            web.rupture_strain = float("nan")
        assert web.rupture_strain == 0.3
        web.rupture_strain = 0.0  # no more breaks; the broken one stays
        assert web.rupture()["broken_count"] == 1
        with pytest.raises(ws.WrapsimError, match="rupture_strain"):
            _spring_with_weight(w, 1.0, -1.0)


def test_load_tilt_impact_and_vibration_runs():
    """The other platform tests through the table: each gives its verdict of named criteria and
    leaves the world's state as it was (the hash before and after)."""
    byref = ctypes.byref
    with ws.World(detection_interval=10) as w:
        ld = L.LoadDef()
        LIB.ws_load_def_init_sized(byref(ld), ctypes.sizeof(ld))
        ld.layers, ld.count_x, ld.count_y = 1, 1, 1
        load = ctypes.c_void_p()
        assert LIB.ws_load_build(w.ptr, byref(ld), byref(load)) == 0, w.last_error
        assert LIB.ws_world_step_n(w.ptr, 1200) == 0  # settle 0.3 s
        h0, h1 = ctypes.c_uint64(), ctypes.c_uint64()
        assert LIB.ws_world_get_state_hash(w.ptr, byref(h0)) == 0
        res = L.LoadtestResult()
        td = L.TiltTestDef()
        LIB.ws_tilt_test_def_init_sized(byref(td), ctypes.sizeof(td))
        td.target_angle, td.stop_time, td.hold_time = 0.1, 0.5, 0.0  # the default 0.05 rad/s
        angles = []
        td.on_sample = L.SampleFn(lambda user, smp: angles.append(smp.contents.angle) or 0)
        assert LIB.ws_loadtest_run_tilt(w.ptr, load, byref(td), byref(res)) == 0, w.last_error
        assert res.kind == L.LOADTEST_TILT
        assert getattr(res.verdict, "pass") == 1, [(e.type, e.layer, e.time, e.level)
                                                   for e in res.events[:res.event_count]]
        assert max(angles) == pytest.approx(0.1) and res.failure_event == -1
        names = [LIB.ws_loadtest_check_name(res.verdict.check[i].id)
                 for i in range(res.verdict.count)]
        assert names == [b"stable_angle", b"cartons_lost"]
        im = L.ImpactTestDef()
        LIB.ws_impact_test_def_init_sized(byref(im), ctypes.sizeof(im))
        im.speed, im.pulse_duration, im.gentle_acceleration = 0.3, 0.05, 2.0
        im.coast_time, im.rest_after = 0.0, 0.0
        assert LIB.ws_loadtest_run_impact(w.ptr, load, byref(im), byref(res)) == 0, w.last_error
        assert res.velocity_change == pytest.approx(0.3, rel=1e-3)
        vd = L.VibrationTestDef()
        LIB.ws_vibration_test_def_init_sized(byref(vd), ctypes.sizeof(vd))
        vd.sweep, vd.sweep_level, vd.frequency_start, vd.frequency_end = 1, 0.02, 5.0, 20.0
        vd.duration, vd.ramp_time, vd.rest_after = 1.0, 0.1, 0.0
        assert LIB.ws_loadtest_run_vibration(w.ptr, load, byref(vd), byref(res)) == 0, \
            w.last_error
        assert res.kind == L.LOADTEST_SWEEP and res.response_bins == L.LOADTEST_RESPONSE_BINS
        assert LIB.ws_world_get_state_hash(w.ptr, byref(h1)) == 0 and h0.value == h1.value
        LIB.ws_load_destroy(load)


# --- last: the whole table was exercised ---------------------------------------------------------
def test_zz_every_function_was_called():
    others = {n for n in globals() if n.startswith("test_") and n != "test_zz_every_function_was_called"}
    if not others <= TESTS_RUN:
        pytest.skip("only meaningful after the whole module ran")
    never = sorted(n for n, k in CALLED.items() if k == 0)
    assert never == [], f"never called: {never}"
