#!/usr/bin/env python3
"""bottles.py: a 2 x 2 tray of bottles from a mesh file, wrapped, on a tilting platform.

The bottle's shape comes from examples/data/bottle.stl (or .obj), a CAD-style export in mm:
World.mesh_from_file(..., scale=0.001) welds its vertices and hands the closed mesh to the
library, which re-centres it on its volume centroid; shape.centroid_offset says where that
centroid was in the file, so a bottle whose file base sits at z = 0 stands on the platform
when its body is created at centroid_offset (plus the contact layers). Four bottles stand in a
2 x 2 tray, a band of film is wrapped around their outline below the shoulders, they settle
for START s, then the platform tilts about y at RATE up to --angle and holds there.

It reports, per bottle, how far it slid along the platform and how far it leans from the
platform's normal, and whether the tray stayed (every bottle within 5 mm and 2 deg). Below the
friction angle (atan 0.3 = 16.7 deg) and the tipping angle of a lone bottle (atan(40/89) =
24 deg: its centroid is 89 mm up) it does.

Run (from the repository root, the library built in build/; needs python3-meshio):
  PYTHONPATH=bindings/python python3 examples/python/bottles.py [--angle 10] [--no-film]

Copy it for your own product: the file and its unit are MESH and SCALE, the tray is build().
"""

import argparse
import math
import pathlib

import numpy as np

import wrapsim as ws

MESH = pathlib.Path(__file__).resolve().parents[1] / "data" / "bottle.stl"
SCALE = 0.001                      # the file is in mm
SEGMENTS = 32                      # sides of the bottle's polygon (examples/data/make_bottle.py)
MASS = 1.2                         # kg per filled bottle
PITCH = 0.082                      # m between bottle axes (diameter 80 mm + 2 mm of layers)
LAYER = 1e-3                       # contact layer of every body, m
START, RATE = 0.5, 0.1             # the tilt starts at START s, at RATE rad/s
STOP_RAMP = 0.2                    # s, the gentle stop at the target angle


def build(w, film=True, path=MESH):
    """The platform, four bottles standing on it and the film; returns (platform, bottles,
    web or None)."""
    glass, pallet, wrap = w.material("glass"), w.material("pallet"), w.material("film")
    # A light bottle touches its neighbours and the platform at many points (the base alone at
    # 32): a softer penalty (N/m per point) keeps their frequencies well inside dt, and the
    # stick friction model holds them without creep. Eq. 13's regularised friction is a
    # damper of slope 2 mu N / v_lim below v_lim; under the film's squeeze that is too stiff
    # for a bottle's small inertia at dt = 0.25 ms, and the bottles chatter.
    grip = dict(stiffness=5e4, damping=10.0, friction=0.3, friction_model="stick",
                stick_stiffness=5e4, stick_damping=10.0)
    w.set_contact(glass, pallet, **grip)
    w.set_contact(glass, glass, **grip)
    w.set_contact(wrap, glass, stiffness=4000.0, damping=1.0, friction=0.9)
    w.set_contact(wrap, pallet, stiffness=4000.0, damping=1.0, friction=0.9)
    platform = w.body(w.box(0.5, 0.5, 0.04), type="kinematic", material=pallet,
                      position=(0, 0, -0.02), name="platform")        # top face at z = 0
    shape = w.mesh_from_file(path, scale=SCALE)
    # The file's base is at z = 0: lift by both layers so the bottle just touches the top.
    base = shape.centroid_offset + (0.0, 0.0, 2 * LAYER)
    # Neighbours meet a corner of one polygon against the middle of a side of the other (every
    # other bottle turned by half a side about its axis): two corners face to face would sit
    # on a knife edge and roll off it.
    half = math.pi / SEGMENTS / 2
    turned = (math.cos(half), 0.0, 0.0, math.sin(half))
    bottles = []
    for i, (sx, sy) in enumerate([(-1, -1), (1, -1), (-1, 1), (1, 1)]):
        bottles.append(w.body(shape, mass=MASS, material=glass, contact_layer=LAYER,
                              position=base + (sx * PITCH / 2, sy * PITCH / 2, 0.0),
                              orientation=turned if sx == sy else (1, 0, 0, 0),
                              name=f"bottle {i}"))
    web = None
    if film:
        law = w.law("tension_compression", stiffness=30.0, compression_stiffness=0.3,
                    damping=1e-3)
        # 2 sub-steps: 1 g nodes use 0.43 of their stable sub-step (the safety factor: 0.5)
        web = w.web_band(law, bottles, material=wrap, node_mass=1e-3, z_bottom=0.02,
                         z_top=0.14, n_around=64, n_up=13, prestretch_around=0.3,
                         prestretch_up=0.1, substeps=2)
    return platform, bottles, web


def in_platform_frame(platform, bottle):
    """The bottle's CoG in the platform's frame (m) and its lean from the platform's normal
    (deg)."""
    R = platform.rotation
    p = R.T @ (bottle.position - platform.position)
    lean = math.degrees(math.acos(min(1.0, float(R[:, 2] @ bottle.rotation[:, 2]))))
    return p, lean


def run(angle=10.0, hold=0.5, film=True, path=MESH, progress=False):
    """Settle, tilt to `angle` (deg), hold `hold` s. Returns a dict of per-bottle slide (m)
    and lean (deg), the final angle (deg), whether the tray stayed, the film's peak tension."""
    with ws.World(dt=2.5e-4) as w:
        platform, bottles, web = build(w, film, path)
        # The table eases to a stop over STOP_RAMP s centred where the free angle would reach
        # the target, so it stands at the angle STOP_RAMP / 2 after that.
        platform.set_drive("tilt", axis=(0, 1, 0), start_time=START, rate=RATE,
                           max_angle=math.radians(angle), stop_ramp_time=STOP_RAMP)
        ws.run(w, START, progress=progress)              # settle: slide is measured from here
        start = [in_platform_frame(platform, b)[0] for b in bottles]
        ws.run(w, START + math.radians(angle) / RATE + STOP_RAMP / 2 + hold,
               progress=progress)
        now = [in_platform_frame(platform, b) for b in bottles]
        slide = [float(np.linalg.norm((p - s)[:2])) for (p, _), s in zip(now, start)]
        lean = [le for _, le in now]
        R = platform.rotation
        return {"slide": slide, "lean": lean, "time": w.time,
                "angle": math.degrees(math.acos(min(1.0, R[2, 2]))),
                "stayed": max(slide) < 5e-3 and max(lean) < 2.0,
                "tension": float(web.tensions().max()) if web else 0.0}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--angle", type=float, default=10.0, help="tilt to this angle, deg")
    ap.add_argument("--hold", type=float, default=0.5, help="hold at the angle this long, s")
    ap.add_argument("--no-film", action="store_true", help="leave the film off")
    ap.add_argument("--mesh", default=str(MESH), help="the bottle's mesh file (mm)")
    args = ap.parse_args()
    r = run(args.angle, args.hold, not args.no_film, args.mesh, progress=True)
    print(f"platform at {r['angle']:.2f} deg, t = {r['time']:.2f} s"
          + (f"; peak film tension {r['tension']:.2f} N" if not args.no_film else ""))
    for i, (s, le) in enumerate(zip(r["slide"], r["lean"])):
        print(f"bottle {i}: slid {s * 1e3:6.2f} mm along the platform, leans {le:5.2f} deg")
    print("the tray stayed" if r["stayed"] else "the tray did NOT stay (5 mm / 2 deg)")


if __name__ == "__main__":
    main()
