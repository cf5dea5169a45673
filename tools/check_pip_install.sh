#!/usr/bin/env bash
# Install the Python package as a new user would and use it from outside the repository:
# a fresh venv over Debian's Python (--system-site-packages: numpy from Debian), pip install
# of the repository offline (no build isolation: meson-python and meson come from Debian),
# then `import wrapsim`, a short simulation, the `wrapsim` console script and
# `python3 -m wrapsim`, all run from an empty folder with no WRAPSIM_LIBRARY.
# Exit status 0 when everything works. Needs python3-venv, python3-mesonpy, python3-numpy.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
unset WRAPSIM_LIBRARY PYTHONPATH
/usr/bin/python3 -m venv --system-site-packages "$work/venv"
"$work/venv/bin/pip" install --quiet --no-build-isolation "$root" >"$work/pip.log" 2>&1 || {
    cat "$work/pip.log" >&2
    echo "pip install failed" >&2
    exit 1
}
mkdir "$work/elsewhere"
cd "$work/elsewhere"
"$work/venv/bin/python" - <<'PY'
import pathlib
import wrapsim as ws
from wrapsim import _lib
path = pathlib.Path(_lib.lib()._wrapsim_path.split(" ")[0])
assert "site-packages" in str(path), f"the library came from {path}, not the package"
# A box set on a kinematic slab rests on the two 1 mm contact layers: its centre at
# 0.125 + 0.002 m, less the static overlap m g / (4 k) = 49 / 8e5 = 0.06 mm.
w = ws.World()
slab = w.box(2.0, 2.0, 0.1)
cube = w.box(0.25, 0.25, 0.25)
w.body(shape=slab, type="kinematic", position=(0, 0, -0.05))
b = w.body(shape=cube, mass=5.0, position=(0, 0, 0.127))
w.step(4000)
z = b.position[2]
assert abs(z - (0.127 - 49.05 / 8e5)) < 1e-4, z
print(f"import wrapsim from {path}: box at rest at z = {z:.4f} m")
PY
"$work/venv/bin/wrapsim" info
"$work/venv/bin/python" -m wrapsim info >/dev/null
echo "pip install: OK"
