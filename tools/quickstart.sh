#!/usr/bin/env bash
# Build libwrapsim from a fresh Debian machine and run a load test, the C example or every test.
#
#   tools/quickstart.sh example [LOAD] [ARGS...]
#                                           install, build the Python package into .venv/, and
#                                           run `wrapsim run LOAD -o wrapsim-out ARGS`: a load
#                                           file through its test, printing the verdict
#                                           (default examples/loads/eur_pallet_spiral.json)
#   tools/quickstart.sh tilt [ARGS...]      install, build, run build/examples/tilt_table ARGS
#   tools/quickstart.sh test [ARGS...]      install, build, meson test ARGS, then the Python
#                                           binding's pytest suite; last line
#                                           "N passed, N failed" over both
#
# The Python tests run with Debian's /usr/bin/python3 (which sees python3-numpy and
# python3-pytest) against build/lib; WS_PYTHON_TESTS=0 leaves them out.
#
# The build directory is build/ (reconfigured when it exists). MESON_EXTRA adds options to
# `meson setup`, e.g. MESON_EXTRA="-Dwerror=true -Dccd=disabled"; a reconfigured build keeps
# the options it was given before unless they are given again.
set -euo pipefail

usage() {
    awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "${BASH_SOURCE[0]}"
    exit "${1:-2}"
}

(($# >= 1)) || usage
mode=$1
shift
case $mode in
example | tilt | test) ;;
-h | --help) usage 0 ;;
*) usage ;;
esac

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
# shellcheck source=tools/count_tests.sh
source tools/count_tests.sh
# shellcheck source=tools/ensure_packages.sh
source tools/ensure_packages.sh

packages=(gcc libc6-dev meson ninja-build pkg-config check libccd-dev zlib1g-dev)
python_tests=0
if [[ $mode == example ]]; then
    packages+=(python3 python3-venv python3-mesonpy python3-numpy python3-matplotlib python3-tqdm)
fi
if [[ $mode == test ]]; then
    packages+=(valgrind)
    if [[ ${WS_PYTHON_TESTS:-1} != 0 ]]; then
        python_tests=1
        packages+=(python3 python3-numpy python3-pytest python3-tqdm python3-matplotlib
            python3-distributed python3-yaml python3-jsonschema python3-meshio chromium)
    fi
fi
ensure_packages "${packages[@]}"

if [[ $mode == example ]]; then
    load=examples/loads/eur_pallet_spiral.json
    if (($# >= 1)) && [[ $1 != -* ]]; then
        load=$1
        shift
    fi
    # The Python package, with the library built inside it, in a venv that sees Debian's
    # numpy and meson-python (offline: no build isolation).
    [[ -x .venv/bin/pip ]] || /usr/bin/python3 -m venv --system-site-packages .venv
    .venv/bin/pip install --quiet --no-build-isolation .
    exec .venv/bin/wrapsim run "$load" -o wrapsim-out "$@"
fi

read -r -a extra <<<"${MESON_EXTRA:-}"
if [[ -f build/meson-private/coredata.dat ]]; then
    meson setup --reconfigure build "${extra[@]}"
else
    meson setup build "${extra[@]}"
fi
meson compile -C build

if [[ $mode == tilt ]]; then
    exe=build/examples/tilt_table
    if [[ ! -x $exe ]]; then
        echo "$exe was not built (is examples/tilt_table.c there?)" >&2
        exit 1
    fi
    exec "$exe" "$@"
fi

log=build/meson-logs/testlog.json
rm -f "$log"
rc=0
meson test -C build --print-errorlogs "$@" || rc=$?
read -r passed failed skipped < <(count_testlog "$log")
# meson test can fail without a test failing (a rebuild error): report that as one failure.
if ((rc != 0 && failed == 0)); then
    echo "meson test exited with status $rc" >&2
    failed=1
fi
if ((python_tests)); then
    echo "Python binding: pytest bindings/python/tests"
    rc=0
    run_pytest build || rc=$?
    read -r py_passed py_failed py_skipped < <(count_junit build/python-junit.xml)
    if ((rc != 0 && py_failed == 0)); then
        echo "pytest exited with status $rc" >&2
        py_failed=1
    fi
    passed=$((passed + py_passed))
    failed=$((failed + py_failed))
    skipped=$((skipped + py_skipped))
fi
format_counts "$passed" "$failed" "$skipped"
((failed == 0))
