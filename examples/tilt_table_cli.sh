#!/bin/sh
# The tilt table example's command line as a user meets it: --help succeeds, a bad value is an
# error with status 2 and a message, --vtk creates its directory with its parents.
# Usage: tilt_table_cli.sh path/to/tilt_table
exe="$1"
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fail=0

expect() { # expect STATUS ARGS...: run the example, compare its exit status
    want="$1"
    shift
    "$exe" "$@" >"$tmp/out" 2>"$tmp/err"
    got=$?
    if [ "$got" -ne "$want" ]; then
        echo "FAIL: tilt_table $* exited $got, expected $want"
        cat "$tmp/err"
        fail=1
    elif [ "$want" -eq 2 ] && ! grep -q . "$tmp/err"; then
        echo "FAIL: tilt_table $* exited 2 without a message"
        fail=1
    else
        echo "ok: tilt_table $* -> $got"
    fi
}

expect 0 --help
grep -q "usage: tilt_table" "$tmp/out" || { echo "FAIL: --help printed no usage"; fail=1; }
expect 2 --duration abc
expect 2 --duration -5
expect 2 --duration 1x
expect 2 --duration
expect 2 --film-mass 0
expect 2 --substeps 2.5
expect 2 --variant Q
expect 2 --no-such-option
expect 2 stray
expect 0 --quiet --duration 0.01 --vtk "$tmp/a/b/c"
[ -f "$tmp/a/b/c/tilt_table.pvd" ] || { echo "FAIL: --vtk did not create $tmp/a/b/c"; fail=1; }
: >"$tmp/file"
expect 1 --quiet --duration 0.01 --vtk "$tmp/file/sub"
exit $fail
