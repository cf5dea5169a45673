#!/usr/bin/env python3
"""bottles_wrapped.py: a product that is not a box, from a CAD file, stacked and wrapped.

Four 1 L bottles (1.1 kg each) stand 2 x 2 on a pallet; a band of stretch film goes around them,
pre-stretched 30 % around and 10 % up, and settles for 0.5 s. The bottle's shape comes from a
mesh file, as a user's product would: by default this script writes one (a revolved profile:
body 80 mm across, shoulder, neck; 250 mm tall) as a binary STL in millimetres, then reads it
back with World.mesh_from_file(path, scale=1e-3). Give your own with --shape FILE (STL, OBJ, PLY;
--scale for its unit). It prints the film's containment profile, the force the film puts on each
bottle and how far each leans, and with --vtk DIR writes the run for ParaView.

Run (from the repository root, the library built in build/; needs python3-meshio):
  PYTHONPATH=bindings/python /usr/bin/python3 examples/python/bottles_wrapped.py --vtk out
"""

import argparse
import math
import pathlib
import tempfile

import numpy as np

import wrapsim as ws

LAYER = 1e-3       # contact layer of every body and film node, m
GAP = 2e-3         # between neighbouring bottles and above the pallet: two layers, m
MASS = 1.1         # kg per bottle (1 L of water and the bottle)
FILM_K, FILM_C = 2000.0, 0.1   # spring stiffness N/m and damping kg/s, as the source paper


def bottle_profile():
    """(radius, height) in mm from the base up: a body, a shoulder, a neck."""
    return [(40.0, 0.0), (40.0, 160.0), (34.0, 185.0), (20.0, 205.0), (14.0, 215.0),
            (14.0, 250.0)]


def revolve(profile, segments=24):
    """A closed surface of revolution about z, counter-clockwise seen from outside: rings of
    `segments` points plus a centre point at each end."""
    ang = 2 * math.pi * np.arange(segments) / segments
    rings = [np.column_stack([r * np.cos(ang), r * np.sin(ang), np.full(segments, z)])
             for r, z in profile]
    pts = np.vstack(rings + [[0, 0, profile[0][1]], [0, 0, profile[-1][1]]])
    bottom, top = len(pts) - 2, len(pts) - 1
    tris = []
    for k in range(len(profile) - 1):
        a, b = k * segments, (k + 1) * segments
        for i in range(segments):
            j = (i + 1) % segments
            tris += [[a + i, a + j, b + j], [a + i, b + j, b + i]]
    last = (len(profile) - 1) * segments
    for i in range(segments):
        j = (i + 1) % segments
        tris += [[bottom, j, i], [top, last + i, last + j]]
    return pts, np.array(tris)


def write_bottle_stl(path):
    import meshio
    pts, tris = revolve(bottle_profile())
    meshio.write(str(path), meshio.Mesh(pts, [("triangle", tris)]), binary=True)


def build(shape_file, scale, n_around=64, n_up=15):
    w = ws.World(dt=2.5e-4, full_detection_until=0.2, detection_interval=5)
    pallet_mat, bottle_mat, film_mat = (w.material(n) for n in ("pallet", "bottle", "film"))
    w.set_contact(bottle_mat, bottle_mat, stiffness=2e5, damping=10.0, friction=0.3)
    w.set_contact(bottle_mat, pallet_mat, stiffness=2e5, damping=10.0, friction=0.4)
    for other in (bottle_mat, pallet_mat):
        w.set_contact(film_mat, other, stiffness=4000.0, damping=1.0, friction=0.9)
    w.body(w.box(0.6, 0.6, 0.05), type="kinematic", material=pallet_mat, contact_layer=LAYER,
           position=(0, 0, -0.025), name="pallet")
    shape = w.mesh_from_file(shape_file, scale=scale)
    info = shape.info()
    lo, hi = np.array(info["aabb_min"]), np.array(info["aabb_max"])
    size = hi - lo
    bottles = []
    for k, (i, j) in enumerate([(-1, -1), (1, -1), (-1, 1), (1, 1)]):
        centre = (i * (size[0] + GAP) / 2, j * (size[1] + GAP) / 2, GAP - lo[2])
        bottles.append(w.body(shape, mass=MASS, material=bottle_mat, contact_layer=LAYER,
                              position=centre, name=f"bottle {k + 1}"))
    # The film from 20 mm above the pallet to 40 mm below the top of the bottles' bodies.
    z0, z1 = 0.02, GAP + 0.8 * size[2]
    outline = 2 * (2 * size[0] + 2 * size[1]) / 2 + 2 * math.pi * 2 * LAYER  # about the hull
    l0_around = outline / n_around / 1.3
    l0_up = (z1 - z0) / (n_up - 1) / 1.1
    around = w.law("tension_compression", stiffness=FILM_K * l0_around,
                   compression_stiffness=0.01 * FILM_K * l0_around, damping=FILM_C * l0_around,
                   name="film around")
    up = w.law("tension_compression", stiffness=FILM_K * l0_up,
               compression_stiffness=0.01 * FILM_K * l0_up, damping=FILM_C * l0_up,
               name="film up")
    film = w.web_band(around, bottles, law_cross=up, node_mass=1e-3, contact_layer=LAYER,
                      material=film_mat, name="film", z_bottom=z0, z_top=z1, n_around=n_around,
                      n_up=n_up, prestretch_around=0.3, prestretch_up=0.1)
    return w, bottles, film


def lean_deg(body):
    """Angle between the body's axis and the vertical, degrees."""
    return math.degrees(math.acos(min(1.0, abs(body.rotation[2, 2]))))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--shape", help="the product's mesh file (default: a bottle written here)")
    p.add_argument("--scale", type=float, default=1e-3, help="file unit in m (default mm)")
    p.add_argument("--duration", type=float, default=0.5, help="s of settling")
    p.add_argument("--vtk", help="directory for a ParaView series (a frame per 0.05 s)")
    a = p.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        shape_file = a.shape
        if shape_file is None:
            shape_file = pathlib.Path(tmp) / "bottle.stl"
            write_bottle_stl(shape_file)
        w, bottles, film = build(shape_file, a.scale)
    with w:
        print(f"libwrapsim {ws.version()} - 4 products from {a.shape or 'a bottle STL'}, "
              f"{film.info()['nx']} x {film.info()['ny']} film nodes")
        steps = int(round(a.duration / w.dt))
        if a.vtk:
            pathlib.Path(a.vtk).mkdir(parents=True, exist_ok=True)
            with w.vtk_series(a.vtk, "bottles", time_stride=0.05) as series:
                for _ in range(steps + 1):
                    series.write_frame()
                    if _ < steps:
                        w.step(1)
            print(f"  VTK frames: {a.vtk}/bottles.pvd (open in ParaView)")
        else:
            w.step(steps)
        prof = film.containment(3)
        print(f"after {a.duration:.2f} s:")
        for name, band in zip(("bottom", "middle", "top"), prof):
            print(f"  film {name:6s} {band['z_low']:.3f}-{band['z_high']:.3f} m: hoop tension "
                  f"{band['hoop_tension']:.2f} N, contact force {band['contact_force']:.1f} N")
        for b in bottles:
            f, _ = film.body_force(b)
            print(f"  {b.name}: film force {np.linalg.norm(f[:2]):.2f} N sideways, "
                  f"leans {lean_deg(b):.2f} deg")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
