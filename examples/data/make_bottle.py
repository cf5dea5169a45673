#!/usr/bin/env python3
"""make_bottle.py: writes bottle.stl (binary) and bottle.obj, a bottle as a closed triangle mesh.

A solid of revolution in millimetres, standing on z = 0: a body of radius 40 mm up to 150 mm, a
rounded shoulder to a neck of radius 14 mm at 185 mm, the neck up to 220 mm; SEGMENTS sides
around, flat bottom and top each closed by a fan from its centre. Triangles run
counter-clockwise seen from outside. The files are what a CAD export gives: units in mm (load
with scale=0.001), the STL with every vertex repeated in each of its triangles.

Run from anywhere (needs meshio, Debian python3-meshio); it writes next to itself:
  python3 examples/data/make_bottle.py
"""

import math
import pathlib

import numpy as np

SEGMENTS = 32
# The profile, bottom to top: (radius, height), mm.
BODY_R, BODY_H = 40.0, 150.0
NECK_R, SHOULDER_TOP, TOP = 14.0, 185.0, 220.0
SHOULDER_STEPS = 5


def profile():
    """(radius, z) rings from bottom to top, mm."""
    rings = [(BODY_R, 0.0), (BODY_R, BODY_H)]
    for i in range(1, SHOULDER_STEPS + 1):
        s = i / SHOULDER_STEPS  # r falls as 1 - s^2: level with the body where it starts
        rings.append((NECK_R + (BODY_R - NECK_R) * (1.0 - s * s),
                      BODY_H + (SHOULDER_TOP - BODY_H) * s))
    rings.append((NECK_R, TOP))
    return rings


def round_volume():
    """The volume of the round (not faceted) profile, mm^3: a sum of frustums. The mesh's is
    this times sin(2 pi/n) n/(2 pi): each ring is an inscribed n-gon, and similar polygons
    scale a frustum's volume by the ratio of their areas to the circles'."""
    rings = profile()
    return sum(math.pi * (z1 - z0) / 3.0 * (r0 * r0 + r0 * r1 + r1 * r1)
               for (r0, z0), (r1, z1) in zip(rings, rings[1:]))


def bottle_mesh(n=SEGMENTS):
    """Vertices (m, 3) mm and triangles (k, 3) of the bottle."""
    rings = profile()
    th = 2.0 * math.pi * np.arange(n) / n
    verts = [np.column_stack([r * np.cos(th), r * np.sin(th), np.full(n, z)]) for r, z in rings]
    nr = len(rings)
    bottom, top = nr * n, nr * n + 1
    verts.append([[0.0, 0.0, 0.0], [0.0, 0.0, TOP]])
    tris = []
    for k in range(n):
        k1 = (k + 1) % n
        tris.append((bottom, k1, k))                            # faces down
        tris.append((top, (nr - 1) * n + k, (nr - 1) * n + k1))  # faces up
        for j in range(nr - 1):
            a, b = j * n + k, j * n + k1
            tris.append((a, b, b + n))
            tris.append((a, b + n, a + n))
    return np.vstack(verts), np.array(tris, dtype=np.int64)


def main():
    import meshio
    here = pathlib.Path(__file__).resolve().parent
    v, t = bottle_mesh()
    mesh = meshio.Mesh(v, [("triangle", t)])
    meshio.write(str(here / "bottle.stl"), mesh, binary=True)
    obj = here / "bottle.obj"
    meshio.write(str(obj), mesh)
    # meshio's first line carries the time of writing: a fixed one keeps the file reproducible.
    lines = obj.read_text().split("\n", 1)
    obj.write_text("# a bottle in mm, written by make_bottle.py\n" + lines[1])
    print(f"bottle: {len(v)} vertices, {len(t)} triangles, {round_volume() / 1e3:.1f} cm^3 "
          f"round; wrote {here / 'bottle.stl'} and {here / 'bottle.obj'}")


if __name__ == "__main__":
    main()
