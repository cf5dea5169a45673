"""The VTK series read back by VTK's own readers (Debian python3-vtk9; skipped without it).

A small wrapped stack (two cubes in a 24 x 9 band of film on a platform) is stepped 0.1 s and
written in the three forms. Each frame is read with vtkXMLMultiBlockDataReader and compared, array
by array, with what the binding reads from the world at that time: the files must carry the state,
not only parse. The last test renders a frame to PNG (tools/vtk_render_frame.py, off screen, under
xvfb-run when there is no display) and checks that the picture is not empty.
"""

import math
import os
import pathlib
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import wrapsim as ws

vtk = pytest.importorskip("vtk")
from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[3]
N_AROUND, N_UP = 24, 9
BANDS = min(ws.WS_VTK_DEFAULT_BANDS, N_UP)  # the writer caps the bands at the rows
DT = 2.5e-4


def build():
    a, layer = 0.25, 1e-3
    w = ws.World(dt=DT)
    box_mat, plane_mat, film_mat = (w.material(n) for n in ("cardboard", "platform", "film"))
    cd = dict(stiffness=2e5, damping=10.0, friction=0.3, friction_vlim=0.01)
    w.set_contact(box_mat, box_mat, **cd)
    w.set_contact(box_mat, plane_mat, **cd)
    fc = dict(stiffness=4000.0, damping=1.0, friction=0.9, friction_vlim=0.01)
    w.set_contact(film_mat, box_mat, **fc)
    w.set_contact(film_mat, plane_mat, **fc)
    cube = w.box(a, a, a)
    w.body(w.box(1.0, 1.0, 0.05), type="kinematic", material=plane_mat, contact_layer=layer,
           position=(0, 0, -0.025), name="platform")
    boxes = [w.body(cube, material=box_mat, mass=5.0, contact_layer=layer,
                    position=(0, 0, 2 * layer + a / 2 + k * (a + 2 * layer)),
                    name=("bottom", "top")[k]) for k in range(2)]
    law = w.law("tension_compression", stiffness=2000.0 * 0.03, compression_stiffness=0.6,
                damping=0.003)
    film = w.web_band(law, boxes, node_mass=1e-3, contact_layer=layer, material=film_mat,
                      name="film", z_bottom=0.03, z_top=0.48, n_around=N_AROUND, n_up=N_UP,
                      prestretch_around=0.4, prestretch_up=0.2, substeps=2)
    return w, boxes, film


def read_vtm(path):
    r = vtk.vtkXMLMultiBlockDataReader()
    r.SetFileName(str(path))
    r.Update()
    mb = r.GetOutput()
    names = [mb.GetMetaData(b).Get(vtk.vtkCompositeDataSet.NAME())
             for b in range(mb.GetNumberOfBlocks())]
    return names, mb


def arr(ds, where, name):
    data = {"point": ds.GetPointData(), "cell": ds.GetCellData(), "field": ds.GetFieldData()}
    a = data[where].GetAbstractArray(name)
    assert a is not None, f"{where} array {name!r} missing"
    if a.IsA("vtkStringArray"):
        return [a.GetValue(k) for k in range(a.GetNumberOfValues())]
    return vtk_to_numpy(a)


def run_series(tmp_path, **options):
    """Write a frame at 0, 0.05 and 0.1 s, offered every step; return the world's state at the
    frames: positions, spring tensions, contact count, containment, time."""
    w, boxes, film = build()
    states = []
    with w:
        with w.vtk_series(tmp_path, "run", time_stride=0.05, springs=1, **options) as s:
            for n in range(401):
                before = s.frame_count
                s.write_frame()
                if s.frame_count > before:
                    states.append(dict(t=w.time, x=film.positions().copy(),
                                       tension=film.tensions().copy(),
                                       springs=film.springs().copy(),
                                       contacts=len(w.contacts()),
                                       hoop=film.containment(BANDS),
                                       body=[b.position.copy() for b in boxes]))
                w.step(1)
            assert s.frame_count == 3
    return states


def quad_mean(tension, springs, around):
    """The expected cell data: each grid quad's two edge springs of one direction, averaged.
    Springs of the band: around (i, j)-(i+1, j) row by row, then up (i, j)-(i, j+1)."""
    out = np.empty(N_AROUND * (N_UP - 1))
    for j in range(N_UP - 1):
        for i in range(N_AROUND):
            if around:
                e = (j * N_AROUND + i, (j + 1) * N_AROUND + i)
            else:
                base = N_AROUND * N_UP + j * N_AROUND
                e = (base + i, base + (i + 1) % N_AROUND)
            out[j * N_AROUND + i] = 0.5 * (tension[e[0]] + tension[e[1]])
    return out


@pytest.mark.parametrize("fmt", ["compressed", "binary", "ascii"])
def test_series_reads_back_with_every_block_array_and_time(tmp_path, fmt):
    double = fmt == "binary"  # one form in Float64, where the values must match to the last bit
    states = run_series(tmp_path, format=fmt, double_precision=int(double))
    if fmt == "compressed" and not ws.build_features() & ws.WS_FEATURE_ZLIB:
        fmt = "binary"
    # Float32 keeps 7 digits: positions below 1 m to 1e-7 m, tensions (~1-10 N) to 1e-6 N.
    atol = 0.0 if double else 1e-6
    rtol = 0.0 if double else 2e-7
    pvd = ET.parse(tmp_path / "run.pvd").getroot()
    entries = list(pvd.iter("DataSet"))
    assert [float(e.get("timestep")) for e in entries] == pytest.approx(
        [s["t"] for s in states], abs=1e-12)
    assert [s["t"] for s in states] == pytest.approx([0.0, 0.05, 0.1], abs=DT / 2)
    for e, st in zip(entries, states):
        head = (tmp_path / e.get("file").replace(".vtm", "_bodies.vtp")).read_bytes()[:400]
        assert (b'format="appended"' in head) == (fmt != "ascii")
        assert (b"vtkZLibDataCompressor" in head) == (fmt == "compressed")
        names, mb = read_vtm(tmp_path / e.get("file"))
        assert names == ["bodies", "film", "contacts", "springs"]
        bodies, film_blk, contacts, springs_blk = (mb.GetBlock(k) for k in range(4))
        for ds in (bodies, contacts):
            assert arr(ds, "field", "TimeValue")[0] == pytest.approx(st["t"], abs=1e-7)
        # bodies: 3 boxes of 8 corners and 12 triangles, named in creation order
        assert (bodies.GetNumberOfPoints(), bodies.GetNumberOfCells()) == (24, 36)
        assert arr(bodies, "field", "body_name") == ["platform", "bottom", "top"]
        assert len(arr(bodies, "field", "body_id")) == 3
        assert arr(bodies, "point", "velocity").shape == (24, 3)
        assert list(np.unique(arr(bodies, "cell", "body"))) == [0, 1, 2]
        assert arr(bodies, "cell", "contact_force").shape == (36, 3)
        pts = vtk_to_numpy(bodies.GetPoints().GetData()).reshape(-1, 8, 3)
        for k in (1, 2):  # a box's corners average to its centre of mass
            np.testing.assert_allclose(pts[k].mean(axis=0), st["body"][k - 1], atol=1e-6)
        # film: a named dataset of quads carrying around and up apart
        assert film_blk.GetNumberOfBlocks() == 1
        assert film_blk.GetMetaData(0).Get(vtk.vtkCompositeDataSet.NAME()) == "film"
        film = film_blk.GetBlock(0)
        nq = N_AROUND * (N_UP - 1)
        assert (film.GetNumberOfPoints(), film.GetNumberOfCells()) == (N_AROUND * N_UP, nq)
        assert film.GetCellType(0) == vtk.VTK_QUAD
        np.testing.assert_allclose(vtk_to_numpy(film.GetPoints().GetData()), st["x"],
                                   rtol=rtol, atol=atol)
        for name, around in (("tension_around", True), ("tension_up", False)):
            np.testing.assert_allclose(arr(film, "cell", name),
                                       quad_mean(st["tension"], st["springs"], around),
                                       rtol=rtol, atol=atol)
        for name in ("strain_around", "strain_up"):
            assert arr(film, "cell", name).shape == (nq,)
        for name, comps in (("velocity", 3), ("contact_force", 3), ("tension_around", 1),
                            ("tension_up", 1)):
            a = arr(film, "point", name)
            assert a.shape == ((N_AROUND * N_UP, 3) if comps == 3 else (N_AROUND * N_UP,))
        assert arr(film, "field", "web_name") == ["film"]
        np.testing.assert_allclose(arr(film, "field", "band_hoop_tension"),
                                   st["hoop"]["hoop_tension"], rtol=rtol, atol=atol)
        for name in ("band_z_low", "band_z_high", "band_line_load", "band_contact_force"):
            assert arr(film, "field", name).shape == (BANDS,)
        # springs: every spring a line with its own tension
        springs = springs_blk.GetBlock(0)
        assert springs.GetNumberOfCells() == len(st["tension"])
        np.testing.assert_allclose(arr(springs, "cell", "tension"), st["tension"],
                                   rtol=rtol, atol=atol)
        assert set(np.unique(arr(springs, "cell", "kind"))) == {0, 1}
        # contacts: one vertex per contact of the world, with its vectors
        assert contacts.GetNumberOfPoints() == st["contacts"]
        assert contacts.GetNumberOfCells() == st["contacts"]
        for name in ("normal", "normal_force", "friction_force", "slip_velocity"):
            assert arr(contacts, "point", name).shape == (st["contacts"], 3)
        if st["contacts"]:
            n = arr(contacts, "point", "normal")
            np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-6)
            np.testing.assert_allclose(np.linalg.norm(arr(contacts, "point", "normal_force"),
                                                      axis=1),
                                       arr(contacts, "point", "normal_force_N"), rtol=1e-6)
    # Frames with and without contacts (the stack starts a layer's width above the platform and
    # bounces while it settles), so both an empty and a full contacts block were read.
    assert min(s["contacts"] for s in states) == 0 < max(s["contacts"] for s in states)


def test_compressed_is_smaller_than_ascii(tmp_path):
    sizes = {}
    for fmt in ("compressed", "ascii"):
        d = tmp_path / fmt
        d.mkdir()
        run_series(d, format=fmt)
        sizes[fmt] = sum(p.stat().st_size for p in d.iterdir())
    if ws.build_features() & ws.WS_FEATURE_ZLIB:
        assert sizes["compressed"] < 0.5 * sizes["ascii"], sizes


def display_runner():
    """The command prefix that gives a display: none when there is one, xvfb-run otherwise."""
    if os.environ.get("DISPLAY"):
        return []
    if shutil.which("xvfb-run"):
        return ["xvfb-run", "-a"]
    return None


def test_render_frame_to_png(tmp_path):
    prefix = display_runner()
    if prefix is None:
        pytest.skip("no display and no xvfb-run (Debian package xvfb)")
    run_series(tmp_path)
    png = tmp_path / "frame.png"
    r = subprocess.run(prefix + [sys.executable, str(REPO / "tools" / "vtk_render_frame.py"),
                                 str(tmp_path / "run.pvd"), str(png), "--size", "320", "240"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    rd = vtk.vtkPNGReader()
    rd.SetFileName(str(png))
    rd.Update()
    img = rd.GetOutput()
    assert img.GetDimensions()[:2] == (320, 240)
    px = vtk_to_numpy(img.GetPointData().GetScalars())[:, :3].astype(int)
    # The background is white; the bodies are grey and the film coloured. A picture with the
    # load in it has far more than 5 % of its pixels away from white; an empty one has none
    # but the colour bar's (under 3 % at this size).
    drawn = np.any(np.abs(px - 255) > 30, axis=1).mean()
    coloured = (px.max(axis=1) - px.min(axis=1) > 60).mean()  # film, not grey
    assert drawn > 0.05, drawn
    assert coloured > 0.01, coloured
    assert math.isfinite(drawn)
