"""A body's shape from a mesh file: STL (ASCII and binary), OBJ and PLY, read through meshio.

The C library takes no files: it takes vertices and triangles (ws_shape_create_mesh). This
module reads a file into those arrays, the way the library wants them:

- scaled to metres (`scale`: 0.001 for a file in mm; mesh files carry no unit);
- coincident vertices welded: STL stores every triangle's three corners apart, so its mesh is
  a heap of loose triangles until the copies of a vertex are made one (exact copies always;
  copies within `weld` times the mesh's size too, for writers that print a vertex differently
  in each triangle);
- quads and polygons split into triangles (a fan from the first corner: right for the convex,
  flat polygons that mesh tools write);
- unused vertices dropped, and triangles that welding shrank to a line.

World.mesh_from_file() creates the shape; a mesh the library refuses (open, not manifold,
wound inconsistently, inside out) raises MeshFileError naming the file and the offending edge's
vertex positions in the file's own units. meshio is Debian's python3-meshio.
"""

import os
import re

import numpy as np

from . import WrapsimError
from ._lib import WS_ERR_BAD_MESH, WS_ERR_INVALID_ARGUMENT, WS_ERR_IO, WS_ERR_UNSUPPORTED

__all__ = ["MeshFileError", "read_mesh", "weld"]

# The file formats read, by file name ending, with meshio's name for them.
FORMATS = {".stl": "stl", ".obj": "obj", ".ply": "ply"}

# Relative weld tolerance by default: a millionth of the mesh's size. A binary STL repeats each
# vertex bit for bit; an ASCII one may print a vertex with a different last digit in each
# triangle (float32 keeps 7 digits, about 1e-7 of the coordinate), and a mesh's own edges are
# far longer than 1e-6 of its size.
DEFAULT_WELD = 1e-6


class MeshFileError(WrapsimError):
    """A mesh file that cannot be read (status WS_ERR_IO), a reader that is missing
    (WS_ERR_UNSUPPORTED), bad arguments (WS_ERR_INVALID_ARGUMENT), or a mesh the library refuses
    (WS_ERR_BAD_MESH). `path` is the file; for a refused mesh `edge` holds the offending edge's
    two vertex positions (file units) when the library named an edge, `triangle` a degenerate
    triangle's three."""

    def __init__(self, status, detail, path, edge=None, triangle=None):
        super().__init__(status, detail)
        self.path = path
        self.edge = edge
        self.triangle = triangle


def weld(points, tol):
    """Merge points closer than about `tol` (same unit as the points; 0: exact copies only).
    Returns (unique points, index of each input point's representative). Each representative is
    the cluster's first point in input order, and they keep that order.

    Points are binned in cubes of side tol; a cube's points are one vertex, and neighbouring
    cubes whose first points lie within tol are joined too (a pair of copies straddling a
    cube's face)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    n = len(p)
    if n == 0:
        return p.copy(), np.zeros(0, dtype=np.int64)
    # Exact copies first: the whole job for a binary STL.
    u, first, inv = np.unique(p, axis=0, return_index=True, return_inverse=True)
    inv = inv.reshape(-1)
    label = np.arange(len(u))
    if tol > 0 and len(u) > 1:
        cell = np.floor((u - u.min(axis=0)) / tol).astype(np.int64)
        cells, cell_of = np.unique(cell, axis=0, return_inverse=True)
        cell_of = cell_of.reshape(-1)
        nc = len(cells)
        rep = np.full(nc, len(u))
        np.minimum.at(rep, cell_of, np.arange(len(u)))  # a cell's first unique point
        a_all, b_all = [], []
        # The 13 neighbours "ahead" of a cube (the other 13 see it as theirs).
        offsets = [(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)
                   if (i, j, k) > (0, 0, 0)]
        for off in offsets:
            moved = cells + np.array(off, dtype=np.int64)
            both = np.concatenate([cells, moved])
            _, grp = np.unique(both, axis=0, return_inverse=True)
            grp = grp.reshape(-1)
            # A group holding a cell and a moved cell: cell b lies at a + off.
            where = np.full(2 * nc + 1, -1)
            where[grp[:nc]] = np.arange(nc)
            b = where[grp[nc:]]
            a = np.nonzero(b >= 0)[0]
            b = b[a]
            near = np.linalg.norm(u[rep[a]] - u[rep[b]], axis=1) <= tol
            a_all.append(a[near])
            b_all.append(b[near])
        a = np.concatenate(a_all)
        b = np.concatenate(b_all)
        lab = np.arange(nc)
        while len(a):  # connected components by label propagation with pointer jumping
            m = np.minimum(lab[a], lab[b])
            new = lab.copy()
            np.minimum.at(new, a, m)
            np.minimum.at(new, b, m)
            new = new[new]
            if np.array_equal(new, lab):
                break
            lab = new
        label = lab[cell_of]
    # Clusters in the order of their first point in the input.
    per_point = label[inv]
    firsts = np.full(per_point.max() + 1, n)
    np.minimum.at(firsts, per_point, np.arange(n))
    used = np.nonzero(firsts < n)[0]
    order = used[np.argsort(firsts[used])]
    rank = np.empty(len(firsts), dtype=np.int64)
    rank[order] = np.arange(len(order))
    return p[firsts[order]].copy(), rank[per_point]


def _error(status, path, text):
    return MeshFileError(status, f"{path}: {text}", path)


def _read(path, file_format):
    """meshio's mesh of the file, or MeshFileError."""
    try:
        import meshio
    except ImportError:
        raise _error(WS_ERR_UNSUPPORTED, path,
                     "reading mesh files needs meshio (Debian: python3-meshio)") from None
    if not os.path.exists(path):
        raise _error(WS_ERR_IO, path, "no such file")
    if os.path.isdir(path):
        raise _error(WS_ERR_IO, path, "is a directory, not a mesh file")
    if file_format is None:
        ext = os.path.splitext(path)[1].lower()
        if ext not in FORMATS:
            raise _error(WS_ERR_IO, path,
                         f"unknown mesh file type '{ext}': the types read are .stl, .obj and "
                         ".ply (or name one with file_format=)")
        file_format = FORMATS[ext]
    try:
        return meshio.read(path, file_format=file_format)
    except Exception as e:  # noqa: BLE001 - meshio raises many kinds on a bad file
        why = str(e) or type(e).__name__
        raise _error(WS_ERR_IO, path, f"not a readable {file_format.upper()} mesh ({why})") from e


def _triangles(mesh, path):
    """The surface cells of a meshio mesh as triangles (m, 3)."""
    tris, other = [], set()
    for block in mesh.cells:
        data = np.asarray(block.data)
        if block.type in ("triangle", "quad", "polygon") and data.ndim == 2 and data.shape[1] >= 3:
            # A fan from each polygon's first corner.
            for k in range(1, data.shape[1] - 1):
                tris.append(data[:, [0, k, k + 1]])
        elif block.type not in ("vertex", "line"):
            other.add(block.type)
    if other:
        raise _error(WS_ERR_IO, path, "holds cells that are not surface polygons ("
                     + ", ".join(sorted(other)) + "): give the product's outer surface")
    if not tris:
        raise _error(WS_ERR_IO, path, "holds no triangles or polygons: not a surface mesh")
    return np.concatenate(tris).astype(np.int64)


def read_mesh(path, scale=1.0, weld_tol=DEFAULT_WELD, flip=False, file_format=None):
    """Read a mesh file into (vertices (n, 3) float64 m, triangles (m, 3) uint32), ready for
    World.mesh(). `scale` multiplies the file's coordinates into metres (0.001 for mm);
    `weld_tol` merges vertices closer than that fraction of the mesh's size (0: exact copies
    only); `flip` reverses every triangle (for a mesh wound clockwise, inside out);
    `file_format` is meshio's name ('stl', 'obj', 'ply') when the file's ending does not say.
    Raises MeshFileError."""
    path = os.fspath(path)
    scale = float(scale)
    weld_tol = float(weld_tol)
    if not (np.isfinite(scale) and scale > 0):
        raise _error(WS_ERR_INVALID_ARGUMENT, path, f"scale must be > 0 and finite, got {scale}")
    if not (np.isfinite(weld_tol) and 0 <= weld_tol < 0.01):
        raise _error(WS_ERR_INVALID_ARGUMENT, path,
                     f"weld tolerance must be in [0, 0.01) of the mesh's size, got {weld_tol}")
    mesh = _read(path, file_format)
    pts = np.asarray(mesh.points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] < 3 or len(pts) == 0:
        raise _error(WS_ERR_IO, path, "holds no 3D points: not a surface mesh")
    pts = pts[:, :3]
    tri = _triangles(mesh, path)
    bad = (tri < 0) | (tri >= len(pts))
    if bad.any():
        f = int(np.nonzero(bad.any(axis=1))[0][0])
        k = int(tri[bad][0])
        raise _error(WS_ERR_IO, path, f"a face (triangle {f} after splitting polygons) refers to "
                     f"vertex {k} counting from 0 ({k + 1} from 1), and the file has "
                     f"{len(pts)}" + (": relative (negative) indices are not read" if k < 0
                                       else ""))
    if not np.isfinite(pts).all():
        raise _error(WS_ERR_IO, path, "a vertex coordinate is not a finite number")
    pts = pts * scale
    size = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
    pts, idx = weld(pts, weld_tol * size)
    tri = idx[tri]
    # Triangles welded into a line or a point have no area and no edge that counts: drop them.
    tri = tri[(tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])]
    if flip:
        tri = tri[:, ::-1]
    # Only the vertices the triangles use, in their order.
    used = np.zeros(len(pts), dtype=bool)
    used[tri.reshape(-1)] = True
    new = np.cumsum(used) - 1
    return np.ascontiguousarray(pts[used]), np.ascontiguousarray(new[tri], dtype=np.uint32)


def _fmt(p):
    return "(" + ", ".join(f"{x:.6g}" for x in p) + ")"


def refused(path, err, vertices, triangles, scale, weld_tol):
    """The MeshFileError for a mesh of `path` that the library refused with WrapsimError `err`
    (vertices and triangles as passed to it): its text, plus the file and the positions (file
    units) of the edge or triangle it names."""
    detail = err.detail.split(": ", 1)[-1] if err.detail.startswith("ws_") else err.detail
    v = np.asarray(vertices) / scale
    edge = tri = None
    extra = ""
    m = re.search(r"edge \((\d+), (\d+)\)", detail)
    if m and max(int(m.group(1)), int(m.group(2))) < len(v):
        edge = (v[int(m.group(1))], v[int(m.group(2))])
        extra = (f"; the edge runs from {_fmt(edge[0])} to {_fmt(edge[1])} in the file's "
                 "coordinates")
    m = re.search(r"triangle (\d+) is degenerate", detail)
    if m and int(m.group(1)) < len(triangles):
        tri = tuple(v[int(k)] for k in triangles[int(m.group(1))])
        extra = ("; its corners are " + ", ".join(_fmt(c) for c in tri)
                 + " in the file's coordinates")
    if edge is not None and "not closed" in detail:
        extra += (f" (vertices closer than {weld_tol:g} of the mesh's size were welded: a larger "
                  "weld_tol closes gaps a writer left)")
    return MeshFileError(err.status if err.status else WS_ERR_BAD_MESH,
                         f"{path}: {detail}{extra}", path, edge=edge, triangle=tri)
