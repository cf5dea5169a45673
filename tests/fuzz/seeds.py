#!/usr/bin/env python3
"""Write seed inputs for fuzz_api into a directory: each one a small scene that reaches another
part of the API (boxes on a ground, a band around a stack, a sheet, a mesh web, every law type,
elements, drives, materials, bad numbers, stale ids, a failing allocation). The encoding mirrors
the decoder of fuzz_api.c; the fuzzer's -merge=1 then keeps those that add coverage.

    python3 tests/fuzz/seeds.py DIR
"""
import os
import sys

SHAPE, BODY, DRIVE, BODY_SET, MATERIAL, LAW, ELEMENT, WEB, WORLD, LAW_USE, WEB_USE, STEP, READ, \
    STEP_N = range(14)
NAN, INF, HUGE = 29, 27, 21  # indices into special[] of fuzz_api.c
EXTRA = 0xE0  # op codes 0xE0 .. 0xEF: the load (+0 .. +7) and the rupture calls (+8 .. +10)


def sane(x):
    return max(0, min(254, round(x * 32 + 128)))


def pos(x):
    return max(0, min(254, round(x * 32 - 1)))


def box(lx, ly, lz):
    return [SHAPE, 0, pos(lx), pos(ly), pos(lz)]


def body(shape, z, kinematic=False, x=0.0, extra=()):
    # type, bad-type, shape, material?, mass?, density?, inertia, layer?, position, orientation?,
    # velocity?, angular velocity?, name?
    b = [BODY, 1 if kinematic else 0, 0, shape, 0, 0, 0, 0, 0, sane(x), sane(0), sane(z), 0, 0,
         0, 1]
    return b + list(extra)


def steps(n):
    out = []
    while n > 0:
        out += [STEP, min(n, 16) - 1]
        n -= 16
    return out


def world(flags=0, tail=()):
    return [flags] + list(tail) + [1]


def law(kind, dim_code=0, stiffness=1.0, extra=()):
    # type, dim, stiffness, compression?, damping?, transition?, cubic?, flags, ..., name?
    return [LAW, kind, dim_code, pos(stiffness), 0, 0, 0, 0, 0] + list(extra) + [0]


def ground_and_box():
    return box(4.0, 4.0, 0.05) + box(0.25, 0.25, 0.25) + body(0, -0.025, kinematic=True) + \
        body(1, 0.13)


def web_common(law_index, mass=True):
    # node_mass?, value, areal?, layer?, material?, damping?, law, cross?, shear?, substeps, name?
    return [1, pos(2.0), 0, 0, 0, 0, law_index, 0, 0, 0, 1]


def seeds():
    s = {}
    s['box_on_ground'] = world() + ground_and_box() + steps(64) + [READ, 0, 0, 1] + \
        [READ, 2, 8]
    s['stack'] = world() + ground_and_box() + [SHAPE, 0, 7, 7, 7] + body(1, 0.39) + steps(48) + \
        [READ, 2, 8] + [READ, 5, 5]
    s['paper_integrator'] = world(2, [1]) + ground_and_box() + steps(32)
    s['detection_interval'] = world(4, [sane(0.01), 4, 0, pos(2.0)]) + ground_and_box() + \
        steps(48)
    s['band'] = world() + ground_and_box() + law(2, 0, 4.0) + \
        [WEB, 1] + web_common(0) + [2, 0, 1, 200, sane(0.02), sane(0.2), 7, 2, sane(0.05),
                                     sane(0.02), 0, 0] + steps(32) + \
        [WEB_USE, 0, 2] + [WEB_USE, 64, 6, 2] + [WEB_USE, 0, 7] + [WEB_USE, 0, 9]
    s['sheet'] = world() + ground_and_box() + law(0, 0, 2.0) + \
        [WEB, 0] + web_common(0) + [5, 5, sane(-0.3), sane(-0.3), sane(0.5), 0, pos(0.15 * 16),
                                    pos(0.15 * 16), sane(0.05 * 8), sane(0.05 * 8), 0, 2, 0, 3,
                                    1] + law(0, 0, 1.0) + steps(32) + [WEB_USE, 0, 3, 20] + \
        [WEB_USE, 0, 4, 20] + [WEB_USE, 0, 5, 1, 1]
    mesh = [WEB, 2] + web_common(0) + [4] + [sane(v) for v in
                                             (0, 0, 1, 0.2, 0, 1, 0.2, 0.2, 1, 0, 0.2, 1)]
    mesh += [pos(0.5)] * 4 + [5]
    for a, b in ((0, 1), (1, 2), (2, 3), (3, 0), (0, 2)):
        mesh += [0, a, 0, b]
    s['mesh_web'] = world() + ground_and_box() + law(0) + mesh + [pos(0.2 * 8), 1] * 5 + \
        [0x3F, 1, 0, 0] + steps(32)
    for kind in range(11):
        extra = []
        if kind == 5:
            extra = [4] + [1, 40, 160] * 4 + [1]
        elif kind == 6:
            extra = [1, sane(-0.05 * 4), 1, sane(0.05 * 4)]
        elif kind == 7:
            extra = [2, pos(1.0), pos(0.5), pos(2.0), pos(1.0), 1]
        elif kind in (8, 9):
            extra = [2, 0, 1, 0, 2, 1]
        elif kind == 10:
            extra = [1, 0, 3]
        pre = law(0) + law(1, 0, 1.0) if kind in (8, 9) else []
        s['law_%d' % kind] = world() + pre + law(kind, 0, 2.0, extra) + \
            [LAW_USE, len(pre) // 10] + [sane(0.1)] * 12 + [1, 0] + \
            [LAW_USE, len(pre) // 10] + [sane(0.1)] * 12 + [0]
    s['law_matrix_6'] = world() + [LAW, 1, 2, pos(2.0), 0, 1, pos(0.1), 0, 0, 3] + \
        [pos(1.0) if i % 7 == 0 else sane(0.01) for i in range(36)] * 2 + [0] + \
        [LAW_USE, 0] + [sane(0.1)] * 12 + [1, 0]
    for et, dim in ((0, 0), (1, 1), (2, 1), (3, 2)):
        s['element_%d' % et] = world() + ground_and_box() + [SHAPE, 0, 7, 7, 7] + \
            body(2, 0.6) + law(1, dim, 3.0) + \
            [ELEMENT, 200, et, 0, 1, 2, 0, sane(0), sane(0), sane(0.1), sane(0), sane(0),
             sane(-0.1), 0, 0, 0, 0] + steps(48) + [READ, 3, 0, 0, 0] + [READ, 4, 4]
    s['tilt_drive'] = world() + ground_and_box() + \
        [DRIVE, 1, sane(0.01), sane(0.05), sane(0), sane(1), sane(0), sane(0), sane(0), sane(0),
         sane(0.5), sane(0), sane(1), sane(0), sane(0), sane(0), sane(0), sane(0), 0] + steps(64)
    s['sine_drive'] = world() + ground_and_box() + \
        [DRIVE, 2, sane(0), sane(0.05), sane(0), sane(1), sane(0), sane(0), sane(0), sane(0),
         sane(0), sane(0), sane(1), sane(0), sane(0), sane(0.01), sane(2), sane(0), 0] + \
        steps(64)
    for mode in range(3):
        s['callback_drive_%d' % mode] = world() + ground_and_box() + \
            [DRIVE, 3] + [sane(0)] * 16 + [1, mode, 0] + steps(16)
    s['materials'] = world() + [MATERIAL, 1, MATERIAL, 1] + box(4, 4, 0.05) + box(0.25, 0.25,
                                                                                 0.25) + \
        [BODY, 1, 0, 0, 1, 0, 0, 0, 0, 0, sane(0), sane(0), sane(-0.025), 0, 0, 0, 1] + \
        [BODY, 0, 0, 1, 1, 1, 0, 0, 0, 0, sane(0), sane(0), sane(0.13), 0, 1, sane(0.2),
         sane(0), sane(0), 0, 1] + \
        [MATERIAL, 0, 2, 2, pos(0.5), 3, pos(0.02), 1, 0, 0, 1] + steps(48)
    s['bad_numbers'] = world(1, [1, NAN]) + [SHAPE, 0, 255, NAN, 7, 7] + \
        [SHAPE, 1, 7, 7, 250] + [WORLD, 0, 1, INF]
    s['bad_body'] = world() + box(0.25, 0.25, 0.25) + \
        [BODY, 0, 0, 0, 0, 1, NAN, 0, 1] + [0, 0, 0, 0, sane(0), sane(0), sane(0), 0, 0, 0, 1] + \
        [BODY, 0, 0, 0, 0, 1, HUGE, 0, 0, 0, 0, 0, sane(0), 0, 0, 0, 1]
    s['destroy_then_use'] = world() + ground_and_box() + [WORLD, 3, 1] + [BODY_SET, 1, 1] + \
        [sane(0)] * 7 + [1] + [READ, 0, 1] + [WORLD, 2, 1] + steps(16)
    s['alloc_fail_step'] = world() + ground_and_box() + steps(16) + [0xF0, 3, STEP, 3] + \
        [0xF0, 0, SHAPE, 0, 7, 7, 7]
    s['alloc_fail_create'] = world(32, [5])
    s['mesh_shape'] = world() + [SHAPE, 2, 0] + [SHAPE, 2, 1, 1, 3, 200] + \
        [SHAPE, 2, 1, 0, 5, 128]
    s['cylinder'] = world() + box(4, 4, 0.05) + [SHAPE, 1, 7, 7, 13] + \
        body(0, -0.025, kinematic=True) + body(1, 0.2) + steps(32)
    s['set_dt_gravity'] = world() + ground_and_box() + [WORLD, 0, 0, 3] + \
        [WORLD, 1, 1, sane(1), sane(0), sane(-9)] + steps(32) + [STEP_N, 7]
    s['vtp'] = world() + ground_and_box() + steps(4) + [READ, 0, 7]
    # A load of one carton, spiral-wrapped (node pitch 0.05 m), read, its film given a low
    # rupture strain and stepped; then each platform test, stopped at its first sample.
    load = [EXTRA + 0, 0, 0, 0, 0]
    spiral = [EXTRA + 1, 64, 50, 0, 1]
    s['load_spiral'] = world() + load + spiral + steps(8) + [EXTRA + 2, 1, 3, 1, 1] + \
        [EXTRA + 8, 0, 0, 0, 39] + steps(16) + [EXTRA + 9, 0, 0, 1, 1] + \
        [EXTRA + 10, 0, 16, 1, 1] + [EXTRA + 10, 0, 1, 1, 1]
    s['load_spiral_alloc_fail'] = world() + load + [0xF0, 5] + spiral + [0xF0, 20] + spiral
    s['load_runs'] = world() + load + steps(8) + \
        [EXTRA + 3, 0, 12, 187, 160, 128, 128, 3] + \
        [EXTRA + 4, 0, 37, 0, 63, 19, 160, 128, 128, 3] + \
        [EXTRA + 5, 1, 0, 145, 0, 63, 250, 31, 50, 128, 128, 160, 3] + \
        [EXTRA + 7, 1] + [EXTRA + 7, 0] + spiral + [EXTRA + 3, 0, 12, 187, 160, 128, 128, 0]
    s['load_destroyed_pallet'] = world() + load + [WORLD, 3, 0] + spiral + \
        [EXTRA + 3, 0, 12, 187, 160, 128, 128, 3] + [EXTRA + 0]
    return s


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    for name, data in seeds().items():
        with open(os.path.join(out, name), 'wb') as f:
            f.write(bytes(data))


if __name__ == '__main__':
    main()
