"""A body's shape from a mesh file (World.mesh_from_file, wrapsim.meshfile). Skipped without
meshio (Debian: python3-meshio).

The known answers: a box whose corners are exact in float32 (every format stores them exactly,
so volume, inertia and centroid come out as for the box built in memory, to round-off: 1e-12
relative), and a 64-sided cylinder prism, whose volume is (n/2) r^2 sin(2 pi/n) h exactly and
differs from the round cylinder's pi r^2 h by the faceting factor sin(2 pi/n) n/(2 pi), 1.6e-3
low at n = 64. Binary STL stores float32: a coordinate moves by up to 6e-8 of its size, and
the volume by a few times that (1e-6 is the tolerance).
"""

import math
import pathlib
import sys

import numpy as np
import pytest

import wrapsim as ws

meshio = pytest.importorskip("meshio")
from wrapsim import meshfile  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[3]
RT = 1e-12  # round-off of a sum over a few hundred tetrahedra, with headroom
LX, LY, LZ = 0.5, 0.25, 0.125  # m, exact in float32
CENTRE = np.array([1.0, 2.0, 3.0])

# (file name, meshio keyword arguments) of every format read.
FORMATS = [("box.stl", {"binary": True}), ("box_ascii.stl", {"binary": False}),
           ("box.obj", {}), ("box.ply", {"binary": True}), ("box_ascii.ply", {"binary": False})]


def box_mesh(w, lx=LX, ly=LY, lz=LZ, centre=CENTRE):
    v, t = w.box(lx, ly, lz).copy_mesh()
    return v + centre, t


def write(path, v, t, **kw):
    meshio.write(str(path), meshio.Mesh(np.asarray(v, dtype=float), [("triangle", t)]), **kw)
    return path


def rel(a, b):
    return abs(a - b) / abs(b)


@pytest.mark.parametrize("name,kw", FORMATS)
def test_every_format_gives_the_known_box(tmp_path, name, kw):
    """Volume, inertia, point count and the centroid offset of the box in each format equal
    those of the box built in memory; the STL's 36 loose corners are welded back into 8."""
    with ws.World() as w:
        v, t = box_mesh(w)
        path = write(tmp_path / name, v, t, **kw)
        ref = w.box(LX, LY, LZ).info()
        s = w.mesh_from_file(path)
        i = s.info()
        assert i["point_count"] == 8 and i["triangle_count"] == 12
        assert rel(i["volume"], LX * LY * LZ) < RT
        J = np.array(i["inertia_unit"]).reshape(3, 3)
        Jref = np.array(ref["inertia_unit"]).reshape(3, 3)
        assert np.abs(J - Jref).max() < RT * np.abs(Jref).max()
        assert np.allclose(s.centroid_offset, CENTRE, rtol=0, atol=1e-12)


def test_a_cylinder_prism_in_binary_stl(tmp_path):
    """A 64-sided prism through float32: its volume is the prism's within 1e-6 (float32), which
    is the round cylinder's times the faceting factor; its inertia is that of the prism built
    in doubles within 1e-6."""
    r, h, n = 0.04, 0.2, 64
    with ws.World() as w:
        cyl = w.cylinder(r, h, n)
        v, t = cyl.copy_mesh()
        path = write(tmp_path / "cyl.stl", v, t, binary=True)
        s = w.mesh_from_file(path)
        i, ref = s.info(), cyl.info()
        prism = n / 2 * r * r * math.sin(2 * math.pi / n) * h
        assert rel(i["volume"], prism) < 1e-6
        facet = math.sin(2 * math.pi / n) * n / (2 * math.pi)
        assert rel(i["volume"], math.pi * r * r * h * facet) < 1e-6
        assert 1.5e-3 < 1 - i["volume"] / (math.pi * r * r * h) < 1.7e-3
        J = np.array(i["inertia_unit"]).reshape(3, 3)
        Jref = np.array(ref["inertia_unit"]).reshape(3, 3)
        assert np.abs(J - Jref).max() < 1e-6 * np.abs(Jref).max()
        assert (i["point_count"], i["triangle_count"]) == (ref["point_count"],
                                                           ref["triangle_count"])


def test_scale_turns_millimetres_into_metres(tmp_path):
    """The same box in mm with scale=0.001: the same volume (to float round-off of the
    scaling, 1e-12) and the centroid offset in metres."""
    with ws.World() as w:
        v, t = box_mesh(w)
        path = write(tmp_path / "box_mm.stl", v * 1000.0, t, binary=True)
        s = w.mesh_from_file(path, scale=0.001)
        assert rel(s.info()["volume"], LX * LY * LZ) < RT
        assert np.allclose(s.centroid_offset, CENTRE, rtol=0, atol=1e-12)
        unscaled = w.mesh_from_file(path)
        assert rel(unscaled.info()["volume"], LX * LY * LZ * 1e9) < RT
        for bad in (0.0, -1.0, float("nan")):
            with pytest.raises(meshfile.MeshFileError, match="scale must be > 0") as e:
                w.mesh_from_file(path, scale=bad)
            assert e.value.status == ws.WS_ERR_INVALID_ARGUMENT


def ascii_stl(path, v, t, jitter=0.0, seed=1):
    """An ASCII STL as a writer that prints each triangle's corners on its own may leave it:
    every copy of a vertex moved by up to `jitter` (m) at random."""
    rng = np.random.default_rng(seed)
    lines = ["solid jittered"]
    for tri in t:
        lines.append("facet normal 0 0 0\nouter loop")
        for k in tri:
            p = v[k] + rng.uniform(-jitter, jitter, 3)
            lines.append("vertex %.17g %.17g %.17g" % tuple(p))
        lines.append("endloop\nendfacet")
    lines.append("endsolid jittered")
    path.write_text("\n".join(lines) + "\n")
    return path


def test_welding_within_the_tolerance(tmp_path):
    """Copies of a vertex 1e-8 of the size apart (a writer printing each copy with different
    last digits) are welded by the default tolerance (1e-6 of the size) and the mesh is closed;
    with exact welding only (weld_tol=0) it is open, and the error says so with the hint."""
    with ws.World() as w:
        v, t = w.cylinder(0.04, 0.2, 48).copy_mesh()
        size = np.linalg.norm(v.max(axis=0) - v.min(axis=0))
        path = ascii_stl(tmp_path / "jitter.stl", v, t, jitter=1e-8 * size)
        s = w.mesh_from_file(path)
        assert s.info()["point_count"] == len(v)
        assert rel(s.info()["volume"], w.cylinder(0.04, 0.2, 48).info()["volume"]) < 1e-7
        with pytest.raises(meshfile.MeshFileError, match="not closed.*repair") as e:
            w.mesh_from_file(path, weld_tol=0.0)
        assert e.value.status == ws.WS_ERR_BAD_MESH


def test_weld_joins_copies_straddling_a_cell_face():
    """Two copies 0.2 tol apart on either side of a binning cube's face (the cubes start at the
    lowest coordinates, here 0) are one vertex; points 3 tol apart stay two; the
    representatives keep the input order."""
    tol = 1e-3
    pts = np.array([[0.0, 0, 0], [5 * tol - 0.1 * tol, 0, 0], [7.0, 0, 0],
                    [5 * tol + 0.1 * tol, 0, 0], [5 * tol + 3 * tol, 0, 0]])
    assert np.floor(pts[1, 0] / tol) != np.floor(pts[3, 0] / tol)  # they straddle a face
    u, idx = meshfile.weld(pts, tol)
    assert len(u) == 4 and list(idx) == [0, 1, 2, 1, 3]
    assert np.array_equal(u[1], pts[1]) and np.array_equal(u[3], pts[4])
    u, idx = meshfile.weld(pts, 0.0)
    assert len(u) == 5 and list(idx) == [0, 1, 2, 3, 4]


def edge_of(err):
    assert err.edge is not None, str(err)
    return [tuple(p) for p in err.edge]


def test_an_open_mesh_names_the_file_and_the_edge(tmp_path):
    """A box with one triangle removed: WS_ERR_BAD_MESH, the file's name, 'not closed', the
    repair hint, and an edge whose two ends are corners of the removed triangle (file units:
    the file is in mm)."""
    with ws.World() as w:
        v, t = box_mesh(w)
        v = v * 1000.0
        path = write(tmp_path / "open_box.stl", v, t[1:], binary=True)
        with pytest.raises(meshfile.MeshFileError) as e:
            w.mesh_from_file(path, scale=0.001)
        err = e.value
        assert isinstance(err, ws.WrapsimError) and err.status == ws.WS_ERR_BAD_MESH
        text = str(err)
        for word in ("open_box.stl", "not closed", "repair", "fill holes", "runs from"):
            assert word in text
        removed = {tuple(v[k]) for k in t[0]}
        assert set(edge_of(err)) <= removed and len(set(edge_of(err))) == 2


def test_a_non_manifold_mesh_names_the_edge(tmp_path):
    """Two tetrahedra sharing one edge (four triangles on it): 'not manifold', the hint, and
    the shared edge's ends."""
    a, b = np.array([0.0, 0, 0]), np.array([0.0, 0, 1])
    v = np.array([a, b, [1, 0, 0.5], [0, 1, 0.5], [-1, 0, 0.5], [0, -1, 0.5]])

    def tet(p, q, r, s):  # outward winding for a positive volume
        tris = [(p, r, q), (p, q, s), (p, s, r), (q, r, s)]
        if np.dot(np.cross(v[q] - v[p], v[r] - v[p]), v[s] - v[p]) > 0:
            tris = [(x, z, y) for x, y, z in tris]
        return tris

    t = np.array(tet(0, 1, 2, 3) + tet(0, 1, 4, 5), dtype=np.uint32)
    with ws.World() as w:
        path = write(tmp_path / "two_tets.obj", v, t)
        with pytest.raises(meshfile.MeshFileError, match="not manifold.*repair") as e:
            w.mesh_from_file(path)
        assert "two_tets.obj" in str(e.value) and "4 triangles" in str(e.value)
        assert set(edge_of(e.value)) == {tuple(a), tuple(b)}


def test_inconsistent_winding_and_inside_out(tmp_path):
    """One triangle of the box turned: 'inconsistent winding' at an edge of that triangle,
    with the hint. Every triangle turned: 'volume is not positive' with the hint, and flip=True
    loads it as the box."""
    with ws.World() as w:
        v, t = box_mesh(w)
        turned = t.copy()
        turned[3] = turned[3][::-1]
        path = write(tmp_path / "turned.ply", v, turned)
        with pytest.raises(meshfile.MeshFileError, match="inconsistent winding.*repair") as e:
            w.mesh_from_file(path)
        assert set(edge_of(e.value)) <= {tuple(v[k]) for k in t[3]}
        path = write(tmp_path / "inside_out.ply", v, t[:, ::-1])
        with pytest.raises(meshfile.MeshFileError, match="inside out.*repair"):
            w.mesh_from_file(path)
        assert rel(w.mesh_from_file(path, flip=True).info()["volume"], LX * LY * LZ) < RT


def test_a_degenerate_triangle_names_its_corners(tmp_path):
    """A closed, consistently wound box with a sliver: triangle (a, b, c) split at the midpoint
    m of a-b into (a, m, c) and (m, b, c), the gap closed by (m, a, b), which has no area. The
    error names the sliver's three corners (file units) and the hint."""
    with ws.World() as w:
        v, t = box_mesh(w)
        a, b, c = (int(k) for k in t[0])
        m = len(v)
        v = np.vstack([v, (v[a] + v[b]) / 2])
        t = np.vstack([[[a, m, c], [m, b, c]], t[1:], [[m, a, b]]]).astype(np.uint32)
        path = write(tmp_path / "sliver.obj", v, t)
        with pytest.raises(meshfile.MeshFileError, match="degenerate.*repair.*corners") as e:
            w.mesh_from_file(path)
        assert {tuple(p) for p in e.value.triangle} == {tuple(v[k]) for k in (a, b, m)}


def test_quads_are_split_into_triangles(tmp_path):
    """An OBJ of six quads (a mesh tool's box) loads as the box."""
    v = np.array([[x, y, z] for z in (0, LZ) for y in (0, LY) for x in (0, LX)])
    quads = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2],
                      [1, 3, 7, 5]])
    path = tmp_path / "quads.obj"
    meshio.write(str(path), meshio.Mesh(v.astype(float), [("quad", quads)]))
    with ws.World() as w:
        s = w.mesh_from_file(path)
        assert s.info()["triangle_count"] == 12
        assert rel(s.info()["volume"], LX * LY * LZ) < RT


def test_files_that_are_not_meshes(tmp_path, monkeypatch):
    """A missing file, a directory, text in an .stl, an OBJ without faces, a file type not
    read, an OBJ with relative indices: WS_ERR_IO naming the file. Without meshio:
    WS_ERR_UNSUPPORTED naming the package."""
    (tmp_path / "junk.stl").write_text("this is not a mesh\n")
    (tmp_path / "points.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    (tmp_path / "notes.txt").write_text("v 0 0 0\n")
    (tmp_path / "relative.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                           "f -4 -2 -3\nf -4 -3 -1\nf -4 -1 -2\nf -3 -2 -1\n")
    cases = [("missing.stl", "no such file"), (".", "directory"),
             ("junk.stl", "not a readable STL"), ("points.obj", "no triangles"),
             ("notes.txt", "unknown mesh file type"),
             ("relative.obj", "relative \\(negative\\) indices are not read")]
    with ws.World() as w:
        for name, words in cases:
            path = tmp_path / name
            with pytest.raises(meshfile.MeshFileError, match=words) as e:
                w.mesh_from_file(path)
            assert e.value.status == ws.WS_ERR_IO and str(path) in str(e.value)
        monkeypatch.setitem(sys.modules, "meshio", None)
        with pytest.raises(meshfile.MeshFileError, match="python3-meshio") as e:
            w.mesh_from_file(tmp_path / "junk.stl")
        assert e.value.status == ws.WS_ERR_UNSUPPORTED


@pytest.mark.parametrize("name", ["bottle.stl", "bottle.obj"])
def test_the_shipped_bottle(name):
    """examples/data's bottle (mm) loads in both formats to the same shape: a closed solid of
    revolution whose volume lies between the inscribed polygon's and the round profile's."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("make_bottle",
                                                  REPO / "examples" / "data" / "make_bottle.py")
    mb = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mb)
    with ws.World() as w:
        s = w.mesh_from_file(REPO / "examples" / "data" / name, scale=0.001)
        i = s.info()
        round_volume = mb.round_volume() * 1e-9
        facet = math.sin(2 * math.pi / mb.SEGMENTS) * mb.SEGMENTS / (2 * math.pi)
        assert rel(i["volume"], round_volume * facet) < 1e-6
        # The base (z = 0 in the file) lies below the centroid by the offset's z.
        assert i["aabb_min"][2] == pytest.approx(-s.centroid_offset[2], abs=1e-9)
        assert i["convex"] == 0  # the neck makes it non-convex


def test_bottles_example_smoke():
    """examples/python/bottles.py, short: the wrapped 2 x 2 tray settles and tilts to 2 deg
    (0.95 s simulated, about 1 s of CPU). Far below the friction angle (16.7 deg) with the
    stick model, the bottles neither slide nor lean: under 1 mm and 0.5 deg."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("bottles_example",
                                                  REPO / "examples" / "python" / "bottles.py")
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    r = ex.run(angle=2.0, hold=0.1)
    assert r["angle"] == pytest.approx(2.0, abs=0.01)
    assert len(r["slide"]) == 4 and max(r["slide"]) < 1e-3 and max(r["lean"]) < 0.5
    assert r["stayed"] and 0 < r["tension"] < 100


def test_the_c_example_reads_stl_as_python_does(tmp_path):
    """examples/stl_shape.c (built in build/examples/) reads the bottle as binary STL and as
    ASCII STL (the same float32 corners printed in full) to the volume mesh_from_file gives,
    to its 10 printed digits; an open copy exits with status 1 and names the edge's ends."""
    import subprocess
    exe = REPO / "build" / "examples" / "stl_shape"
    if not exe.exists():
        pytest.skip("build/examples/stl_shape is not built")
    binary = REPO / "examples" / "data" / "bottle.stl"
    m = meshio.read(str(binary))
    pts, tri = np.asarray(m.points, dtype=np.float64), m.cells_dict["triangle"]
    ascii_path = write(tmp_path / "bottle_ascii.stl", pts, tri, binary=False)
    with ws.World() as w:
        want = w.mesh_from_file(binary, scale=0.001).info()["volume"]
        for path in (binary, ascii_path):
            out = subprocess.run([str(exe), str(path), "--scale", "0.001"], capture_output=True,
                                 text=True, timeout=60)
            assert out.returncode == 0, out.stderr
            got = float(out.stdout.split("volume ")[1].split()[0])
            assert rel(got, want) < 1e-9
            assert "1536 corners welded into 258 vertices" in out.stdout
    open_path = write(tmp_path / "open.stl", pts, tri[1:], binary=True)
    out = subprocess.run([str(exe), str(open_path)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 1 and "not closed" in out.stderr and "the edge runs from" in out.stderr
