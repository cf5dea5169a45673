"""World.mesh_from_file: a product's shape from STL (ASCII and binary), OBJ and PLY through meshio
(Debian python3-meshio; skipped without it).

The files are written here by meshio from shapes whose answers are known: a 0.3 x 0.2 x 0.1 m
box (volume 6e-3 m^3, centroid its centre) and a regular octahedron of circumradius r (volume
4 r^3 / 3). Read back they must give those volumes to 1e-12 relative (the mesh is exact; only
rounding in the divergence-theorem sums remains) and a body of the box must come to rest on a
plane. Broken meshes must fail with the offending edge and a repair hint.
"""

import numpy as np
import pytest

import wrapsim as ws

meshio = pytest.importorskip("meshio")

BOX = (0.3, 0.2, 0.1)
# Unit cube corners, index = x + 2 y + 4 z; faces as quads, counter-clockwise seen from outside.
CUBE_QUADS = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4],
                       [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]])


def cube_points(size, origin=(0.0, 0.0, 0.0)):
    c = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], float)
    return c * np.asarray(size) + np.asarray(origin)


def quads_to_tris(q):
    return np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])


def octahedron(r):
    p = np.array([[r, 0, 0], [-r, 0, 0], [0, r, 0], [0, -r, 0], [0, 0, r], [0, 0, -r]], float)
    t = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    return p, t


def write(tmp_path, name, points, cells, **kw):
    path = tmp_path / name
    meshio.write(str(path), meshio.Mesh(points, cells), **kw)
    return path


@pytest.mark.parametrize("kind", ["stl-ascii", "stl-binary", "obj", "ply"])
def test_box_from_each_format(tmp_path, kind):
    # In millimetres, as CAD exports: scale 1e-3 gives metres.
    pts = cube_points(np.array(BOX) * 1e3, origin=(100.0, -50.0, 0.0))
    if kind.startswith("stl"):  # STL holds triangles only, each with its own three corners
        path = write(tmp_path, "box.stl", pts, [("triangle", quads_to_tris(CUBE_QUADS))],
                     binary=kind == "stl-binary")
        head = path.read_bytes()[:5]
        assert (head == b"solid") == (kind == "stl-ascii")
    elif kind == "obj":
        path = write(tmp_path, "box.obj", pts, [("quad", CUBE_QUADS)])
    else:
        path = write(tmp_path, "box.ply", pts, [("quad", CUBE_QUADS)])
    with ws.World() as w:
        shape = w.mesh_from_file(path, scale=1e-3)
        info = shape.info()
        assert info["volume"] == pytest.approx(np.prod(BOX), rel=1e-12)
        np.testing.assert_allclose(info["centroid"], np.array([100.0, -50.0, 0.0]) * 1e-3
                                   + np.array(BOX) / 2, atol=1e-15)
        assert info["point_count"] == 8 and info["triangle_count"] == 12
        assert info["convex"] == 1
        # A body of it dropped 5 mm onto a plane (a slab whose top is z = 0) comes to rest on
        # its face: its centre at half its height, within the two contact layers (1 mm each).
        w.body(w.box(1.0, 1.0, 0.05), type="kinematic", position=(0, 0, -0.025))
        body = w.body(shape, mass=2.0, position=(0, 0, BOX[2] / 2 + 0.005))
        w.step(4000)  # 1 s
        assert np.linalg.norm(body.velocity) < 1e-2
        assert body.position[2] == pytest.approx(BOX[2] / 2, abs=2.5e-3)


def test_octahedron_inside_out_is_turned(tmp_path):
    r = 0.1
    p, t = octahedron(r)
    path = write(tmp_path, "octa.stl", p, [("triangle", t[:, ::-1])], binary=True)  # inside out
    with ws.World() as w:
        shape = w.mesh_from_file(path)
        r32 = float(np.float32(r))  # binary STL holds float32 coordinates
        assert shape.info()["volume"] == pytest.approx(4 * r32 ** 3 / 3, rel=1e-12)


def broken(kind):
    p, t = octahedron(0.1)
    if kind == "open":
        return p, t[:-1]
    if kind == "winding":
        t = t.copy()
        t[0] = t[0, ::-1]
        return p, t
    # non-manifold: a second octahedron sharing the edge (4, 0) of the first
    q, u = octahedron(0.1)
    q = q + np.array([0.1, 0.0, 0.1]) - q[1]  # its vertex 1 onto (0.1, 0, 0.1)...
    return np.vstack([p, q]), np.vstack([t, u + 6])


@pytest.mark.parametrize("kind,words", [("open", "not closed"),
                                        ("winding", "inconsistent winding")])
def test_broken_mesh_names_its_edge_and_says_repair(tmp_path, kind, words):
    p, t = broken(kind)
    path = write(tmp_path, f"{kind}.obj", p, [("triangle", t)])
    with ws.World() as w:
        with pytest.raises(ws.WrapsimError) as err:
            w.mesh_from_file(path)
    e = err.value
    assert e.status == ws.WS_ERR_BAD_MESH
    assert words in e.detail and "edge (" in e.detail
    assert "Repair" in e.detail and str(path) in e.detail


def test_non_manifold_mesh_is_refused(tmp_path):
    # Two tetrahedra glued along one edge, plus a third triangle fan on it: an edge with four
    # triangles.
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0, -1, 0], [0, 0, -1]], float)
    t = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3],     # tetra A on edge (0, 1)
                  [0, 1, 4], [0, 5, 1], [0, 4, 5], [1, 5, 4]])    # tetra B on edge (0, 1)
    path = write(tmp_path, "two.ply", p, [("triangle", t)])
    with ws.World() as w:
        with pytest.raises(ws.WrapsimError) as err:
            w.mesh_from_file(path)
    assert err.value.status == ws.WS_ERR_BAD_MESH
    assert "not manifold" in err.value.detail and "edge (" in err.value.detail


def test_file_without_faces_is_refused(tmp_path):
    path = tmp_path / "lines.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n")
    with ws.World() as w:
        with pytest.raises(ws.WrapsimError) as err:
            w.mesh_from_file(path)
    assert err.value.status == ws.WS_ERR_BAD_MESH and "no surface faces" in err.value.detail


def test_bottles_example_wraps_a_product_from_a_file(capsys):
    """examples/python/bottles_wrapped.py: four bottles read from an STL it writes, wrapped.
    After 0.5 s of settling the film presses every bottle inward (a hoop tension above zero) and
    they stand (each leans < 1 deg; while the film first draws them together they lean some
    4 deg, then right themselves)."""
    import importlib.util
    import pathlib
    import re
    src = pathlib.Path(__file__).resolve().parents[3] / "examples" / "python" / "bottles_wrapped.py"
    spec = importlib.util.spec_from_file_location("bottles_wrapped", src)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--duration", "0.5"]) == 0
    out = capsys.readouterr().out
    hoops = [float(x) for x in re.findall(r"hoop tension ([-\d.]+) N", out)]
    leans = [float(x) for x in re.findall(r"leans ([-\d.]+) deg", out)]
    forces = [float(x) for x in re.findall(r"film force ([-\d.]+) N", out)]
    assert len(hoops) == 3 and min(hoops) > 0
    assert len(leans) == 4 and max(leans) < 1.0
    assert len(forces) == 4 and min(forces) > 0
