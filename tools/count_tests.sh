# shellcheck shell=bash
# Counting of meson test results, sourced by tools/quickstart.sh and .ci/run.
#
# meson writes <builddir>/meson-logs/testlog.json with one JSON object per test and line; its
# top-level "result" field is one of OK, EXPECTEDFAIL, SKIP, FAIL, TIMEOUT, ERROR,
# UNEXPECTEDPASS, INTERRUPT. A test's own output sits in the same line as an escaped string
# (\"result\"), which the pattern below does not match, so each line yields its one result.

# count_testlog FILE: print "PASSED FAILED SKIPPED" for FILE; "0 0 0" when FILE does not exist.
# OK and EXPECTEDFAIL count as passed, SKIP as skipped, everything else as failed.
count_testlog() {
    local log=$1
    if [[ ! -f $log ]]; then
        echo "0 0 0"
        return 0
    fi
    awk '
        match($0, /"result": *"[A-Z_]+"/) {
            r = substr($0, RSTART, RLENGTH)
            sub(/^"result": *"/, "", r)
            sub(/"$/, "", r)
            if (r == "OK" || r == "EXPECTEDFAIL") p++
            else if (r == "SKIP") s++
            else f++
        }
        END { printf "%d %d %d\n", p, f, s }
    ' "$log"
}

# format_counts PASSED FAILED SKIPPED: the plain summary line, e.g. "12 passed, 0 failed".
format_counts() {
    local line="$1 passed, $2 failed"
    if (($3 > 0)); then
        line+=", $3 skipped"
    fi
    echo "$line"
}

# count_junit FILE: print "PASSED FAILED SKIPPED" for a JUnit XML file as pytest --junitxml
# writes it (one <testsuite tests= failures= errors= skipped=> per suite, summed); "0 0 0" when
# FILE does not exist. Errors count as failures.
count_junit() {
    local xml=$1
    if [[ ! -f $xml ]]; then
        echo "0 0 0"
        return 0
    fi
    awk '
        function attr(s, name,    r) {
            if (match(s, name "=\"[0-9]+\"")) {
                r = substr(s, RSTART, RLENGTH)
                gsub(/[^0-9]/, "", r)
                return r + 0
            }
            return 0
        }
        {
            s = $0
            while (match(s, /<testsuite[ \t][^>]*>/)) {
                tag = substr(s, RSTART, RLENGTH)
                s = substr(s, RSTART + RLENGTH)
                n += attr(tag, "tests"); f += attr(tag, "failures") + attr(tag, "errors")
                k += attr(tag, "skipped")
            }
        }
        END { printf "%d %d %d\n", n - f - k, f, k }
    ' "$xml"
}

# python_for_tests: print the interpreter that sees Debian's python3-numpy and python3-pytest:
# /usr/bin/python3 when it exists (the python3 first on PATH may be another one), else python3.
python_for_tests() {
    if [[ -x /usr/bin/python3 ]]; then
        echo /usr/bin/python3
    else
        command -v python3
    fi
}

# run_pytest BUILDDIR: run the Python binding's tests against BUILDDIR/lib/libwrapsim.so.0, with
# a JUnit report in BUILDDIR/python-junit.xml; print nothing else than pytest does. Returns
# pytest's status.
run_pytest() {
    local dir=$1 py
    py=$(python_for_tests)
    rm -f "$dir/python-junit.xml"
    WRAPSIM_LIBRARY="$PWD/$dir/lib/libwrapsim.so.0" PYTHONPATH="$PWD/bindings/python" \
        "$py" -m pytest -q -p no:cacheprovider bindings/python/tests \
        --junitxml="$dir/python-junit.xml"
}
