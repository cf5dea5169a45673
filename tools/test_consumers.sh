#!/usr/bin/env bash
# Use libwrapsim as another project would, and check it works:
#   cmake  meson install BUILDDIR into a temporary prefix, then a CMake project
#          (tests/consumers/cmake) finds it with find_package(wrapsim), builds and runs
#   meson  a meson project (tests/consumers/meson) with this repository as its subproject
#          subprojects/wrapsim (a copy of the committed and working files), builds and runs
# Both compile tests/consumers/consumer.c. Usage: tools/test_consumers.sh [BUILDDIR]
# (default build). Last line: "N passed, N failed". Exit status 0 when both pass.
set -uo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-build}
[[ $build = /* ]] || build=$root/$build
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0
failed=0

verdict() { # NAME STATUS LOG
    if (($2 == 0)); then
        echo "    $1: OK"
        passed=$((passed + 1))
    else
        echo "    $1: FAILED (log follows)"
        sed 's/^/      /' "$3"
        failed=$((failed + 1))
    fi
}

# CMake: install into $tmp/prefix (DESTDIR, so the build's own prefix stays), find it there.
rc=0
{
    meson install -C "$build" --destdir "$tmp/dest" --quiet &&
        prefix=$(find "$tmp/dest" -name wrapsimConfig.cmake -printf '%h\n' | head -n 1) &&
        [[ -n $prefix ]] &&
        mkdir -p "$tmp/cmake" &&
        cp "$root/tests/consumers/cmake/CMakeLists.txt" "$root/tests/consumers/consumer.c" \
            "$tmp/cmake/" &&
        cmake -S "$tmp/cmake" -B "$tmp/cmake/build" -Dwrapsim_DIR="$prefix" &&
        cmake --build "$tmp/cmake/build" &&
        libdir=$(dirname "$(find "$tmp/dest" -name 'libwrapsim.so.0' | head -n 1)") &&
        LD_LIBRARY_PATH=$libdir "$tmp/cmake/build/consumer"
} >"$tmp/cmake.log" 2>&1 || rc=$?
verdict "CMake find_package(wrapsim) -> wrapsim::wrapsim" "$rc" "$tmp/cmake.log"

# meson: this repository (its files, not its build directories) as subprojects/wrapsim.
rc=0
{
    mkdir -p "$tmp/meson/subprojects/wrapsim" &&
        cp "$root/tests/consumers/meson/meson.build" "$root/tests/consumers/consumer.c" \
            "$tmp/meson/" &&
        (cd "$root" && git ls-files -z --cached --others --exclude-standard |
            xargs -0 cp --parents -t "$tmp/meson/subprojects/wrapsim" 2>/dev/null ||
            tar --exclude-vcs --exclude='./build*' -cf - . |
            tar -C "$tmp/meson/subprojects/wrapsim" -xf -) &&
        meson setup "$tmp/meson/build" "$tmp/meson" >"$tmp/meson-setup.log" 2>&1 &&
        ! grep -q WARNING "$tmp/meson-setup.log" &&
        meson compile -C "$tmp/meson/build" &&
        "$tmp/meson/build/consumer"
} >"$tmp/meson.log" 2>&1 || rc=$?
[[ -f $tmp/meson-setup.log ]] && cat "$tmp/meson-setup.log" >>"$tmp/meson.log"
verdict "meson subproject dependency('wrapsim')" "$rc" "$tmp/meson.log"

echo "$passed passed, $failed failed"
((failed == 0))
