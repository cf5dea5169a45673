#!/usr/bin/env python3
"""rubber_mounts.py: a box on four rubber mounts on a shaker table, and the load in each mount.

The Python twin of examples/rubber_mounts.c: a 15 kg carton (0.4 x 0.3 x 0.25 m) stands on four
rubber bushings, 30 mm high, under its corners, on a platform that a drive moves. Nothing moves
for 0.5 s, then the platform heaves (2 mm at 15 Hz) and rolls (1 deg at 6 Hz). Each mount is a
6D bushing with a Kelvin-Voigt law, referred to the mid frame between platform and box
(formulation 'invariant'), so the result does not depend on which body is named first.

It records every mount's force and moment on the box (one call for all four,
World.element_outputs()) and the box's height, prints the static share of each mount and its
peak force, and draws both against time into a PNG.

Run (from the repository root, the library built in build/):
  PYTHONPATH=bindings/python python3 examples/python/rubber_mounts.py --out rubber_mounts.png

Copy this file for your own load: the box, the mount law and their places are in build(); the
motion of the table is table_motion().
"""

import argparse
import math

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import wrapsim as ws  # noqa: E402

MASS, G = 15.0, 9.81                # kg, m/s^2
H = 0.030                           # mount height: the box's bottom face at z = H, m
PLATFORM_Z = -0.025                 # CoG of the 50 mm platform: its top face at z = 0
HEAVE, HEAVE_HZ = 2e-3, 15.0        # m, Hz
ROLL, ROLL_HZ = math.radians(1.0), 6.0
START, RAMP = 0.5, 0.1              # s: the shaking starts, smoothly over RAMP
K = [2e4, 2e4, 6e4, 30.0, 30.0, 20.0]  # shear x y, compression z (N/m); rocking, torsion (N m/rad)
NAMES = ["mount -x-y", "mount +x-y", "mount -x+y", "mount +x+y"]


def table_motion(t):
    """The platform's pose and velocities at time t (global): heave along z, roll about x."""
    u = min(max((t - START) / RAMP, 0.0), 1.0)
    r = 0.5 * (1.0 - math.cos(math.pi * u))                    # ramp 0 -> 1
    rr = 0.5 * math.pi * math.sin(math.pi * u) / RAMP if 0.0 < u < 1.0 else 0.0
    wh, wr, tau = 2 * math.pi * HEAVE_HZ, 2 * math.pi * ROLL_HZ, t - START
    z = HEAVE * r * math.sin(wh * tau)
    zd = HEAVE * (rr * math.sin(wh * tau) + r * wh * math.cos(wh * tau))
    phi = ROLL * r * math.sin(wr * tau)
    phid = ROLL * (rr * math.sin(wr * tau) + r * wr * math.cos(wr * tau))
    return ((0.0, 0.0, PLATFORM_Z + z), (math.cos(phi / 2), math.sin(phi / 2), 0.0, 0.0),
            (0.0, 0.0, zd), (phid, 0.0, 0.0))


def build(w):
    """The platform, the box at its static deflection and the four mounts; returns the box."""
    platform = w.body(w.box(0.8, 0.6, 0.05), type="kinematic", position=(0, 0, PLATFORM_Z),
                      name="platform")
    platform.set_drive("callback", callback=table_motion)
    box = w.body(w.box(0.4, 0.3, 0.25), mass=MASS, position=(0, 0, H + 0.125), name="carton")
    # Damping 0.8 ms times each stiffness: a loss of about 6 % at the box's bounce near 20 Hz.
    rubber = w.law("linear_viscoelastic", dim=6, stiffness_matrix=np.diag(K),
                   damping_matrix=np.diag(K) * 8e-4, name="rubber mount")
    for m, name in enumerate(NAMES):
        p = (0.17 if m & 1 else -0.17, 0.12 if m & 2 else -0.12, H / 2)  # global, mid-height
        w.element("bushing", platform, box, rubber, formulation="invariant",
                  global_attachment=1, point1=p, point2=p, name=name)
    # Start at the static deflection, m g over the mounts' compression stiffness: no bounce-in.
    box.set_pose((0, 0, H + 0.125 - MASS * G / (len(NAMES) * K[2])))
    return box


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--duration", type=float, default=1.5, help="simulated time, s")
    ap.add_argument("--out", default="rubber_mounts.png", help="the PNG to write")
    args = ap.parse_args()

    with ws.World(dt=2.5e-4) as w:
        box = build(w)
        z0 = box.position[2]
        # Sampled every millisecond: the loads on the box (body 2) are minus the force on the
        # platform (body 1) and moment2; one row per mount, in creation order (w.elements()).
        out = ws.run(w, args.duration, every=1e-3, progress=False, record={
            "force": lambda: -w.element_outputs()["force"],
            "moment": lambda: w.element_outputs()["moment2"],
            "dz": lambda: box.position[2] - z0})

    t, f, mom = out["t"], out["force"], out["moment"]
    fmag, shaking = np.linalg.norm(f, axis=2), t > START
    rest = np.argmin(abs(t - START))  # the last sample at rest
    for m, name in enumerate(NAMES):
        peak_f = fmag[shaking, m].max() if shaking.any() else 0.0
        peak_m = np.linalg.norm(mom[shaking, m], axis=1).max() if shaking.any() else 0.0
        print(f"{name}: static {f[rest, m, 2]:6.2f} N up; shaking (1 ms samples): peak |force| "
              f"{peak_f:7.2f} N, peak |moment| {peak_m:6.3f} N m")
    print(f"static check: the mounts carry {f[rest, :, 2].sum():.2f} N, m g = {MASS * G:.2f} N")

    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
    for m, name in enumerate(NAMES):  # +x mounts dashed: the roll about x loads -x and +x alike
        ax1.plot(t, fmag[:, m], lw=0.8, ls="--" if m & 1 else "-", label=name)
    ax1.axhline(MASS * G / len(NAMES), color="k", ls=":", lw=0.8, label="m g / 4")
    ax1.set_ylim(0.0, 1.3 * fmag.max())
    ax1.set_ylabel("|force| on the box, N")
    ax1.legend(fontsize=8, ncol=5, loc="upper left")
    ax2.plot(t, out["dz"] * 1e3, color="k", lw=0.8)
    ax2.set_ylabel("box height from rest, mm")
    ax2.set_xlabel("t, s")
    for ax in (ax1, ax2):
        ax.axvline(START, color="0.6", ls="--", lw=0.8)
        ax.grid(alpha=0.3)
    fig.suptitle(f"{MASS:g} kg carton on four rubber mounts: table heave {HEAVE * 1e3:g} mm at "
                 f"{HEAVE_HZ:g} Hz, roll {math.degrees(ROLL):g} deg at {ROLL_HZ:g} Hz")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"figure: {args.out}")


if __name__ == "__main__":
    main()
